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
layout(set = SET_GI, binding = BINDING_PROBE_VIEW) uniform ViewBlock {
    ProbeView view;
};

// How much farther than it is a point counts for the level of detail, by the zone around
// the camera it lies in (Sedláček 2019, 4.2.1, Figure 4.8), from the cosine of its angle
// to the view direction and that of the cone holding the view frustum: 1 inside that
// cone, 2 beside it in front of the camera, 4 behind. Surfaces out of view reach the
// image only through the probes' bounces, so they take coarser levels sooner.
// `LevelsOfDetail::entries` (frame.rs) gives the clusters the same zones.
float zone_scale(float cos_angle, float cos_frustum) {
    return cos_angle >= cos_frustum ? 1.0 : (cos_angle >= 0.0 ? 2.0 : 4.0);
}

// The lightmap level a lookup at `p` reads for a camera at `camera` (xyz; w: the level of
// detail is on) looking along `forward` (xyz; w: the frustum's cone), fractional (Sedláček
// 2019, 4.2.4): level k from distance k on (scaled by the point's zone), blended in from
// the finer level over the last quarter of the span before it. The clusters' levels
// (`frame.rs`) step at the same distances, and a surface is no nearer the camera than its
// cluster's box, nor in a nearer zone than the nearest part of the box, so a lookup never
// reads a level finer than its cluster computed: the blend only ever reaches towards the
// coarser level (the thesis's smoothing), and it ends where the coarser level begins (its
// shifted distance for fragments).
float lightmap_level(vec3 p, vec4 camera, vec4 forward) {
    if (camera.w == 0.0) {
        return 0.0;
    }
    float d = distance(p, camera.xyz);
    d *= d > 0.0 ? zone_scale(dot(p - camera.xyz, forward.xyz) / d, forward.w) : 1.0;
    float level = 0.0;
    float start = 0.0;
    for (int k = 0; k < 3; k++) {
        float begins = view.distances[k];
        float width = 0.25 * (begins - start);
        level += clamp((d - begins + width) / width, 0.0, 1.0);
        start = begins;
    }
    return level;
}

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

// What this frame computes of the lightmap (`BINDING_PROBE_WORK`).
layout(set = SET_GI, binding = BINDING_PROBE_WORK, std430) readonly buffer WorkBlock {
    uint work[];
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
