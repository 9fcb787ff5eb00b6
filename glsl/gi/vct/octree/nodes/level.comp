#version 460
// One invocation: enters the nodes that the allocation over level `push.level - 1`
// appended into the level table as level `push.level`'s appended run (first node,
// count, indirect dispatches). The level's static run, if any, stays as the host wrote it.
#include "gi/vct/octree/octree.glsl"

layout(local_size_x = 1) in;
layout(push_constant) uniform PushBlock {
    OctreePush push;
};

uint groups(uint nodes) {
    return (nodes + OCTREE_GROUP_SIZE - 1u) / OCTREE_GROUP_SIZE;
}

void main() {
    OctreeLevel above = levels[push.level - 1u];
    uint first = above.appended_first + above.appended_count;
    uint end = min(counters.node_count, counters.node_capacity);
    uint count = end > first ? end - first : 0u;
    OctreeLevel level = levels[push.level];
    level.appended_first = first;
    level.appended_count = count;
    level.groups_x = groups(level.count + count);
    level.appended_groups_x = groups(count);
    levels[push.level] = level;
}
