// The passes that run over the nodes of one level (`push.level`), dispatched indirectly
// from that level's entry in the level table: over both of its runs of nodes (static,
// then appended), or over the appended run only (`push.appended_only`).
#ifndef SVO_LEVEL_GLSL
#define SVO_LEVEL_GLSL
#include "svo/octree.glsl"

layout(local_size_x = SVO_GROUP_SIZE) in;
layout(push_constant) uniform PushBlock {
    SvoPush push;
};

// This invocation's node; false past the end of the level.
bool level_node(out uint node) {
    SvoLevel level = levels[push.level];
    uint i = gl_GlobalInvocationID.x;
    uint statics = push.appended_only != 0u ? 0u : level.count;
    if (i < statics) {
        node = level.first + i;
        return true;
    }
    node = level.appended_first + (i - statics);
    return i - statics < level.appended_count;
}
#endif
