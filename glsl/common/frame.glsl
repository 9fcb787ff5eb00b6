// Set 0: per-frame uniforms, lights and shadow maps.
#ifndef FRAME_GLSL
#define FRAME_GLSL
#include "gpu_layout.glsl"

layout(set = SET_FRAME, binding = BINDING_FRAME_UNIFORMS) uniform FrameBlock {
    FrameUniforms frame;
};
layout(set = SET_FRAME, binding = BINDING_LIGHTS, std430) readonly buffer LightBlock {
    GpuLight lights[];
};
layout(set = SET_FRAME, binding = BINDING_SHADOW_VIEWS, std430) readonly buffer ShadowViewBlock {
    ShadowView shadow_views[];
};
layout(set = SET_FRAME, binding = BINDING_SHADOW_MAP) uniform sampler2DArrayShadow shadow_map;

const float PI = 3.14159265358979;

// Whether a depth-buffer value is the sky: reverse Z clears to 0, the depth at infinity
// (Camera::proj, gbuffer::DEPTH_CLEAR).
bool is_sky(float depth) {
    return depth <= 0.0;
}

// World position of the surface seen through `pixel` at depth-buffer value `depth`.
vec3 pixel_position(ivec2 pixel, float depth) {
    vec2 ndc = (vec2(pixel) + 0.5) / vec2(frame.width, frame.height) * 2.0 - 1.0;
    vec4 world = frame.inv_view_proj * vec4(ndc, depth, 1.0);
    return world.xyz / world.w;
}
#endif
