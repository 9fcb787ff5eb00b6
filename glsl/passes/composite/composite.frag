#version 460
// HDR radiance -> display. The target is an sRGB format, so the hardware applies the
// sRGB OETF; with the default clamp tonemap and exposure 0 this is exactly the
// reference PNG convention (clamp(x), sRGB).
#include "common/frame.glsl"

layout(set = SET_PASS, binding = BINDING_COMPOSITE_HDR) uniform sampler2D hdr;
layout(location = 0) out vec4 out_color;

// Narkowicz's fit of the ACES filmic curve.
vec3 aces(vec3 x) {
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

void main() {
    vec3 radiance = texelFetch(hdr, ivec2(gl_FragCoord.xy), 0).rgb * frame.sky_radiance.w;
    vec3 color = (frame.flags & FLAG_TONEMAP_ACES) != 0u ? aces(radiance) : clamp(radiance, 0.0, 1.0);
    out_color = vec4(color, 1.0);
}
