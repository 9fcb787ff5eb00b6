#version 460
// Each flagged node of `push.level` takes a brick and, above the leaf level, a tile of 8
// children from the node pool through atomic counters (Crassin & Green 2012); a leaf
// takes the sums of its occupied voxels instead. The new children are all appended in
// this pass, so each level's appended nodes are contiguous. A static leaf that a frame's
// moving meshes reach is copied on write (Dřínovský 2013, 5.7, keeps the static part
// intact): a new brick and new sums, which start from its static voxels' sums, so the
// static brick and sums stay as built and the next frame finds them again. A pool that
// runs out is reported in `counters.overflow`; the host grows it and builds again.
#include "gi/vct/octree/nodes/level.glsl"
#include "common/subgroup_add.glsl"

void main() {
    uint node;
    if (!level_node(node)) {
        return;
    }
    uint entry = node_children[node];
    bool leaf = push.level + 1u == octree_depth();
    if (leaf) {
        uint coords = node_coords[node];
        if ((coords & OCTREE_LEAF_FLAGGED) == 0u) {
            return;
        }
        node_coords[node] = coords & ~OCTREE_LEAF_FLAGGED;
    } else if ((entry & OCTREE_SUBDIVIDE) == 0u) {
        return;
    }
    uint brick;
    if (leaf) {
        // All invocations here are leaves (the level is the push constant's).
        SUBGROUP_ATOMIC_ADD(counters.leaf_bricks, 1u, brick)
        if (brick >= counters.leaf_brick_capacity) {
            atomicOr(counters.overflow, OCTREE_OVERFLOW_LEAF_BRICKS);
            brick = OCTREE_NO_BRICK;
        }
    } else {
        brick = atomicAdd(counters.interior_bricks, 1u);
        if (brick >= counters.interior_brick_capacity) {
            atomicOr(counters.overflow, OCTREE_OVERFLOW_INTERIOR_BRICKS);
            brick = OCTREE_NO_BRICK;
        }
    }
    node_bricks[node] = brick;
    if (leaf) {
        uint mask = entry & 0xffu;
        uint voxels = uint(bitCount(mask));
        uint first;
        SUBGROUP_ATOMIC_ADD(counters.leaf_voxels, voxels, first)
        if (first + voxels > counters.leaf_voxel_capacity) {
            atomicOr(counters.overflow, OCTREE_OVERFLOW_LEAF_VOXELS);
            // No voxels: fill.comp skips the leaf (the build runs again).
            node_children[node] = 0u;
            return;
        }
        uint fresh = (first << 8) | mask;
        node_children[node] = fresh;
        if (node < counters.static_node_count) {
            uint kept = static_children[node];
            for (uint o = 0u; o < 8u; o++) {
                if ((kept & (1u << o)) == 0u) {
                    continue;
                }
                uint from = leaf_sum_base(kept, o);
                uint to = leaf_sum_base(fresh, o);
                for (uint w = 0u; w < VOXEL_SUM_WORDS; w++) {
                    leaf_sums[to + w] = leaf_sums[from + w];
                }
            }
        }
        return;
    }
    uint tile = atomicAdd(counters.node_count, 8u);
    if (tile + 8u > counters.node_capacity) {
        atomicOr(counters.overflow, OCTREE_OVERFLOW_NODES);
        node_children[node] = 0u;
        return;
    }
    node_children[node] = tile;
    uvec3 c = unpack_coord(node_coords[node]) * 2u;
    for (uint o = 0u; o < 8u; o++) {
        node_coords[tile + o] = pack_coord(c + uvec3(o & 1u, (o >> 1) & 1u, o >> 2));
    }
}
