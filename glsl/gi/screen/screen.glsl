// Set 2 of the GI passes that work on the screen: the screen contract (`gi::screen`). A
// technique's gather writes the reduced-resolution terms from the G-buffer; the upsample
// reads them and adds them to the screen radiance.
#ifndef SCREEN_GLSL
#define SCREEN_GLSL
#include "common/frame.glsl"

layout(set = SET_SCREEN, binding = BINDING_SCREEN_UNIFORMS) uniform ScreenBlock {
    ScreenUniforms screen;
};
layout(set = SET_SCREEN, binding = BINDING_SCREEN_ALBEDO, rgba16f) uniform readonly image2D gbuffer_albedo;
layout(set = SET_SCREEN, binding = BINDING_SCREEN_NORMAL, rgba16f) uniform readonly image2D gbuffer_normal;
layout(set = SET_SCREEN, binding = BINDING_SCREEN_DEPTH) uniform sampler2D gbuffer_depth;
layout(set = SET_SCREEN, binding = BINDING_SCREEN_TRANSMISSION, rg16f) uniform readonly image2D gbuffer_transmission;
layout(set = SET_SCREEN, binding = BINDING_SCREEN_TRIANGLE, r32ui) uniform readonly uimage2D gbuffer_triangle;

// The full-resolution pixel that stands for reduced-resolution pixel `low`.
ivec2 representative(ivec2 low) {
    ivec2 full = low * int(screen.indirect_scale) + int(screen.indirect_scale) / 2;
    return min(full, ivec2(frame.width, frame.height) - 1);
}

// Where reduced-resolution pixel `low` keeps the visibility of lights 4 band .. 4 band + 3
// (`BINDING_SCREEN_SHADOW`).
ivec2 shadow_texel(ivec2 low, uint band) {
    int height = (int(frame.height) + int(screen.indirect_scale) - 1) / int(screen.indirect_scale);
    return low + ivec2(0, int(band) * height);
}
#endif
