#version 460
// One invocation: enters the nodes that the allocation over level `push.level - 1`
// appended into the level table as level `push.level`'s appended run (first node,
// count, indirect dispatches). The level's static run, if any, stays as the host wrote it.
#include "svo/octree.glsl"

layout(local_size_x = 1) in;
layout(push_constant) uniform PushBlock {
    SvoPush push;
};

uint groups(uint nodes) {
    return (nodes + SVO_GROUP_SIZE - 1u) / SVO_GROUP_SIZE;
}

void main() {
    SvoLevel above = levels[push.level - 1u];
    uint first = above.appended_first + above.appended_count;
    uint end = min(counters.node_count, counters.node_capacity);
    uint count = end > first ? end - first : 0u;
    SvoLevel level = levels[push.level];
    level.appended_first = first;
    level.appended_count = count;
    level.groups_x = groups(level.count + count);
    level.appended_groups_x = groups(count);
    levels[push.level] = level;
}
