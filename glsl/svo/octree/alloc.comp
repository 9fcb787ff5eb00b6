#version 460
// Each flagged node of `push.level` takes a brick and, above the leaf level, a tile of 8
// children from the node pool through atomic counters (Crassin & Green 2012); a leaf
// takes the sums of its occupied voxels instead. The new
// children are all appended in this pass, so each level's nodes are contiguous. A pool
// that runs out is reported in `counters.overflow`; the host grows it and builds again.
#include "svo/octree/level.glsl"

void main() {
    uint node;
    if (!level_node(node)) {
        return;
    }
    if ((node_children[node] & SVO_SUBDIVIDE) == 0u) {
        node_bricks[node] = SVO_NO_BRICK;
        return;
    }
    bool leaf = push.level + 1u == svo_depth();
    uint brick;
    if (leaf) {
        brick = atomicAdd(counters.leaf_bricks, 1u);
        if (brick >= counters.leaf_brick_capacity) {
            atomicOr(counters.overflow, SVO_OVERFLOW_LEAF_BRICKS);
            brick = SVO_NO_BRICK;
        }
    } else {
        brick = atomicAdd(counters.interior_bricks, 1u);
        if (brick >= counters.interior_brick_capacity) {
            atomicOr(counters.overflow, SVO_OVERFLOW_INTERIOR_BRICKS);
            brick = SVO_NO_BRICK;
        }
    }
    node_bricks[node] = brick;
    if (leaf) {
        uint mask = node_children[node] & 0xffu;
        uint voxels = uint(bitCount(mask));
        uint first = atomicAdd(counters.leaf_voxels, voxels);
        if (first + voxels > counters.leaf_voxel_capacity) {
            atomicOr(counters.overflow, SVO_OVERFLOW_LEAF_VOXELS);
            // No voxels: fill.comp skips the leaf (the build runs again).
            node_children[node] = 0u;
        } else {
            node_children[node] = (first << 8) | mask;
        }
        return;
    }
    uint tile = atomicAdd(counters.node_count, 8u);
    if (tile + 8u > counters.node_capacity) {
        atomicOr(counters.overflow, SVO_OVERFLOW_NODES);
        node_children[node] = 0u;
        return;
    }
    node_children[node] = tile;
    uvec3 c = unpack_coord(node_coords[node]) * 2u;
    for (uint o = 0u; o < 8u; o++) {
        node_coords[tile + o] = pack_coord(c + uvec3(o & 1u, (o >> 1) & 1u, o >> 2));
    }
}
