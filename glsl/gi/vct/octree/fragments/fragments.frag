#version 460
// Rasterized voxelization into the octree's voxel-fragment list.
#include "gi/vct/octree/fragments/store_fragment.glsl"
#include "gi/vct/voxelize/coverage.glsl"

void main() {
    cover_voxels();
}
