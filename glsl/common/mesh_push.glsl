// Push constants of every mesh draw.
#ifndef MESH_PUSH_GLSL
#define MESH_PUSH_GLSL
#include "gpu_layout.glsl"

layout(push_constant) uniform PushBlock {
    DrawPush draw;
};
#endif
