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

// A lightmap uv meaning "none" in the packed probe surfaces (`surfaces.comp`).
const uint NO_LIGHTMAP_UV = 0xFFFFFFFFu;

// A unit vector in two 16-bit signed components, by the octahedral map.
uint pack_normal(vec3 n) {
    n /= abs(n.x) + abs(n.y) + abs(n.z);
    vec2 e = n.z >= 0.0 ? n.xy : (1.0 - abs(n.yx)) * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
    return packSnorm2x16(e);
}

vec3 unpack_normal(uint packed) {
    vec2 e = unpackSnorm2x16(packed);
    vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
    float t = max(-n.z, 0.0);
    n.xy += vec2(n.x >= 0.0 ? -t : t, n.y >= 0.0 ? -t : t);
    return normalize(n);
}

// The grid of spatial receivers' active lists (`BINDING_PROBE_GRID_ACTIVE`): the counts of
// the vectors and of the receivers listed, then the vectors' indices and the receivers'.
#define GRID_ACTIVE_VECTORS 0u
#define GRID_ACTIVE_RECEIVERS 1u
#define GRID_ACTIVE_LIST 2u

#ifdef PROBE_RECEIVERS
// A receiver's irradiance (Sedláček 2019, 3.3.1.3): its row of U_k times its cluster's
// basis vectors, plus the sky it sees past every probe (the bake's sky factor × the sky's
// radiance). Needs `common/frame.glsl`.
layout(set = SET_GI, binding = BINDING_PROBE_RECEIVERS) uniform usamplerBuffer receivers;
layout(set = SET_GI, binding = BINDING_PROBE_COORDINATES) uniform samplerBuffer coordinates;
layout(set = SET_GI, binding = BINDING_PROBE_BASIS, std430) readonly buffer BasisBlock {
    vec4 basis[];
};

vec3 receiver_irradiance(uint r) {
    uvec4 receiver = texelFetch(receivers, int(r));
    vec3 e = frame.sky_radiance.rgb * texelFetch(coordinates, int(probes.sky_offset + r)).r;
    for (uint k = 0u; k < receiver.w; k++) {
        e += texelFetch(coordinates, int(receiver.y + k)).r * basis[receiver.z + k].rgb;
    }
    return max(e, vec3(0.0));
}
#endif
#endif
