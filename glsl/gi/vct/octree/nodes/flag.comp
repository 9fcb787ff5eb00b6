#version 460
// Each voxel fragment from `counters.fragment_base` on descends the octree built so far
// to its node at `push.level` and flags it for subdivision, unless it has children
// already (a static node, when a frame inserts the moving meshes' fragments); at the leaf
// level, it marks its own voxel in the leaf's mask and flags the leaf in its coordinates
// (`OCTREE_LEAF_FLAGGED`: the leaf's child entry needs all its bits for the mask and sums).
#include "gi/vct/octree/octree.glsl"

layout(local_size_x = OCTREE_GROUP_SIZE) in;
layout(push_constant) uniform PushBlock {
    OctreePush push;
};

void main() {
    uint index = counters.fragment_base + gl_GlobalInvocationID.x;
    if (index >= min(counters.fragment_count, counters.fragment_capacity)) {
        return;
    }
    uvec3 v = unpack_coord(fragment_voxels[index]);
    uint node = find_node(v, push.level);
    // Every ancestor holds this fragment, so it was subdivided, unless the node pool
    // overflowed (reported; the host builds again with a larger pool).
    if (node == OCTREE_NO_NODE) {
        return;
    }
    bool leaf = push.level + 1u == octree_depth();
    if (!leaf && (node_children[node] & OCTREE_CHILD_MASK) != 0u) {
        return;
    }
    if (leaf) {
        uint bit = 1u << leaf_octant(v);
        if ((node_children[node] & bit) == 0u) {
            atomicOr(node_children[node], bit);
        }
        if ((node_coords[node] & OCTREE_LEAF_FLAGGED) == 0u) {
            atomicOr(node_coords[node], OCTREE_LEAF_FLAGGED);
        }
    } else if ((node_children[node] & OCTREE_SUBDIVIDE) == 0u) {
        atomicOr(node_children[node], OCTREE_SUBDIVIDE);
    }
}
