// The passes that run over the nodes of one level (`push.level`), dispatched indirectly
// from that level's entry in the level table.
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
    node = level.first + gl_GlobalInvocationID.x;
    return gl_GlobalInvocationID.x < level.count;
}
#endif
