#version 460
// One invocation: enters level `push.level`, which the last allocation appended after
// level `push.level - 1`, into the level table (first node, count, indirect dispatch).
#include "svo/octree.glsl"

layout(local_size_x = 1) in;
layout(push_constant) uniform PushBlock {
    SvoPush push;
};

void main() {
    SvoLevel above = levels[push.level - 1u];
    uint first = above.first + above.count;
    uint end = min(counters.node_count, counters.node_capacity);
    uint count = end > first ? end - first : 0u;
    levels[push.level] = SvoLevel((count + SVO_GROUP_SIZE - 1u) / SVO_GROUP_SIZE, 1u, 1u, first, count, 0u, 0u, 0u);
}
