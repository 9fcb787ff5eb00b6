#version 460
// Each voxel fragment descends the octree built so far to its node at `push.level` and
// flags it for subdivision (at the leaf level: as holding voxels).
#include "svo/octree.glsl"

layout(local_size_x = SVO_GROUP_SIZE) in;
layout(push_constant) uniform PushBlock {
    SvoPush push;
};

void main() {
    uint index = gl_GlobalInvocationID.x;
    if (index >= min(counters.fragment_count, counters.fragment_capacity)) {
        return;
    }
    uint node = find_node(unpack_coord(fragments[index].position), push.level);
    // Every ancestor holds this fragment, so it was subdivided, unless the node pool
    // overflowed (reported; the host builds again with a larger pool).
    if (node == SVO_NO_NODE) {
        return;
    }
    if ((node_children[node] & SVO_SUBDIVIDE) == 0u) {
        atomicOr(node_children[node], SVO_SUBDIVIDE);
    }
}
