#version 460
// Renders depth from one light's view (one shadow map layer).
#include "common/frame.glsl"
#include "common/mesh_push.glsl"

layout(location = 0) in vec3 in_position;
layout(location = 2) in vec2 in_uv;
layout(location = 0) out vec2 out_uv;

void main() {
    out_uv = in_uv;
    gl_Position = shadow_views[draw.shadow_view].view_proj * (draw.model * vec4(in_position, 1.0));
}
