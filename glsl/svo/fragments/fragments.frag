#version 460
// Rasterized voxelization into the octree's voxel-fragment list.
#include "svo/fragments/store_fragment.glsl"
#include "gi/voxelize/coverage.glsl"

void main() {
    cover_voxels();
}
