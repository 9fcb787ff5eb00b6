// Set 3 of the irradiance probes' passes (`src/gi/probes/frame.rs`): the scene's
// triangles in its own order (`ray/surfaces.glsl`), the bake's tables, the probes'
// harmonics, the clusters' basis vectors and the lightmap.
#ifndef PROBES_GLSL
#define PROBES_GLSL
#include "ray/surfaces.glsl"

layout(set = SET_GI, binding = BINDING_PROBE_UNIFORMS) uniform ProbeBlock {
    ProbeUniforms probes;
};
layout(set = SET_GI, binding = BINDING_PROBE_CORNER_UVS) uniform samplerBuffer corner_uvs;

// The lightmap uv of scene triangle `i` at barycentrics `bary`; negative where the
// triangle has none (a moving mesh's).
vec2 lightmap_uv(uint i, vec2 bary) {
    int at = int(3u * i);
    vec2 a = texelFetch(corner_uvs, at).xy;
    vec2 b = texelFetch(corner_uvs, at + 1).xy;
    vec2 c = texelFetch(corner_uvs, at + 2).xy;
    return a * (1.0 - bary.x - bary.y) + b * bary.x + c * bary.y;
}
#endif
