#version 460
// Rasterized voxelization into the dense grid: every voxel the (dilated) triangle covers
// gets the fragment's attributes added to its sums.
#include "gi/vct/voxelize/store_sums.glsl"
#include "gi/vct/voxelize/coverage.glsl"

void main() {
    cover_voxels();
}
