// G-buffer access for the screen-space GI passes.
#ifndef SCREEN_GLSL
#define SCREEN_GLSL
#include "common/frame.glsl"
#include "gi/voxels.glsl"

layout(set = SET_PASS, binding = BINDING_GI_GBUFFER_ALBEDO, rgba16f) uniform readonly image2D gbuffer_albedo;
layout(set = SET_PASS, binding = BINDING_GI_GBUFFER_NORMAL, rgba16f) uniform readonly image2D gbuffer_normal;
layout(set = SET_PASS, binding = BINDING_GI_GBUFFER_DEPTH) uniform sampler2D gbuffer_depth;
layout(set = SET_PASS, binding = BINDING_GI_GBUFFER_TRANSMISSION, rg16f) uniform readonly image2D gbuffer_transmission;

// The full-resolution pixel that stands for reduced-resolution pixel `low`.
ivec2 representative(ivec2 low) {
    ivec2 full = low * int(gi.indirect_scale) + int(gi.indirect_scale) / 2;
    return min(full, ivec2(frame.width, frame.height) - 1);
}

// Where reduced-resolution pixel `low` keeps the soft-shadow visibility of lights
// 4 band .. 4 band + 3 (`BINDING_GI_SHADOW`).
ivec2 shadow_texel(ivec2 low, uint band) {
    int height = (int(frame.height) + int(gi.indirect_scale) - 1) / int(gi.indirect_scale);
    return low + ivec2(0, int(band) * height);
}
#endif
