#version 460
// Each voxel fragment adds its albedo, normal, emission and coverage (0..255 per channel;
// the coverage in the alpha of the other three, where it is taken: VOXEL_COVERAGE) and a
// count to its voxel's sums (Dřínovský 2013, 5.4.1). Integer atomic adds are exact and
// commutative, so the averages that compact.comp takes do not depend on the order in
// which the fragments were listed (a running average would, and the list's order
// changes from build to build). A leaf brick holds the leaf's 2x2x2 voxels of the
// effective grid, voxel (v & 1) of the brick. Fragments from `counters.fragment_base` on:
// a frame adds only the moving meshes' (a static leaf they reach has new sums that start
// from its static ones).
#include "gi/vct/octree/octree.glsl"
#include "gi/vct/sums.glsl"

layout(local_size_x = OCTREE_GROUP_SIZE) in;

void main() {
    uint index = counters.fragment_base + gl_GlobalInvocationID.x;
    if (index >= min(counters.fragment_count, counters.fragment_capacity)) {
        return;
    }
    uvec2 shading = fragment_shading[index];
    uvec3 v = unpack_coord(fragment_voxels[index]);
    uint empty;
    uint leaf = find_node_or_gap_gridded(v, octree_depth() - 1u, empty);
    if (leaf == OCTREE_NO_NODE || node_bricks[leaf] == OCTREE_NO_BRICK) {
        return;
    }
    uint entry = node_children[leaf];
    uint octant = leaf_octant(v);
    if ((entry & (1u << octant)) == 0u) {
        return;
    }
    uint base = leaf_sum_base(entry, octant);
    uint words[3] = uint[3](fragment_voxels[counters.fragment_capacity + index], shading.x, shading.y);
    for (uint a = 0u; a < 3u; a++) {
        for (uint c = 0u; c < 3u; c++) {
            atomicAdd(leaf_sums[base + 3u * a + c], (words[a] >> (8u * c)) & 0xffu);
        }
        if (VOXEL_COVERAGE) {
            atomicAdd(leaf_sums[base + SUM_COVERAGE + a], words[a] >> 24u);
        }
    }
    atomicAdd(leaf_sums[base + SUM_COUNT], 1u);
}
