// The passes that run over the nodes of one level (`push.level`), dispatched indirectly
// from that level's entry in the level table (over both of its runs of nodes, static then
// appended, or over the appended run only) or from an update list's head.
#ifndef OCTREE_LEVEL_GLSL
#define OCTREE_LEVEL_GLSL
#include "gi/vct/octree/octree.glsl"

layout(local_size_x = OCTREE_GROUP_SIZE) in;
layout(push_constant) uniform PushBlock {
    OctreePush push;
};

// This invocation's node; false past the end of the level or list.
bool level_node(out uint node) {
    uint i = gl_GlobalInvocationID.x;
    if (push.over == OCTREE_OVER_LIST) {
        node = i < counters.update_capacity ? update_nodes[push.list * counters.update_capacity + i] : OCTREE_NO_NODE;
        return i < min(update_lists[push.list].count, counters.update_capacity);
    }
    OctreeLevel level = levels[push.level];
    uint statics = push.over == OCTREE_OVER_APPENDED ? 0u : level.count;
    if (i < statics) {
        node = level.first + i;
        return true;
    }
    node = level.appended_first + (i - statics);
    return i - statics < level.appended_count;
}

// This workgroup's share of each node's `items` items (texels, children, neighbours): over
// an update list `OCTREE_LIST_SLICES` workgroups share a node's work, over a level one does
// it all. Use as `for (int i = first_item(); i < items; i += item_step())`.
int first_item() {
    return int(gl_WorkGroupID.y);
}

int item_step() {
    return int(gl_NumWorkGroups.y);
}
#endif
