#version 460
// Probe relight and projection (Sedláček 2019, 3.3.1.1 and 3.3.1.2), a workgroup per
// probe: the radiance each of its rays meets, projected onto the real harmonics,
// λ_j = Σ_rays L Y_j dω over the rays of one of its relight maps (`RelightRays`: an
// equal-area octahedral map's texels, so dω is 4π over its texels; BINDING_PROBE_SH holds
// Y_j dω). The radiance at a hit is what a Lambertian surface sends back towards the
// probe, in the lighting pass's units and model:
// - the direct light of every light, shadowed by the frame's shadow maps, × albedo / π;
// - the emission, from the front of an emitter only (one-sided, as the G-buffer);
// - last frame's lightmap (irradiance / π) × albedo: each frame adds a bounce, as the
//   cone tracer's voxel bounces do; read at the coarser of the levels this frame's and
//   last frame's camera give the hit (4.2.1's first solution), so that it reads what the
//   frame that wrote it computed, whichever camera that was;
// and the sky where a ray leaves the scene. Normal maps and specular lobes are not
// seen by the probes (their lightmap is diffuse irradiance). What each ray met was
// decoded once (`surfaces.comp`).
#include "common/direct_light.glsl"
#include "gi/probes/probes.glsl"

layout(local_size_x = PROBE_GROUP_SIZE) in;
// Harmonic coefficients per channel, (order + 1)².
layout(constant_id = 0) const uint COEFFICIENTS = 16u;

layout(set = SET_GI, binding = BINDING_PROBE_SURFACES_READ) uniform usamplerBuffer probe_surfaces;
layout(set = SET_GI, binding = BINDING_PROBE_SH) uniform samplerBuffer ray_harmonics;
layout(set = SET_GI, binding = BINDING_PROBE_LAMBDA, std430) writeonly buffer LambdaBlock {
    vec4 lambda[];
};
layout(set = SET_GI, binding = BINDING_PROBE_LIGHTMAP_PREVIOUS) uniform sampler2D previous_lightmap;
layout(set = SET_GI, binding = BINDING_PROBE_LOD, std430) readonly buffer LodBlock {
    uint lod[];
};

// The sums are reduced a block of coefficients at a time: the whole of band 7 (64
// coefficients × 64 invocations × RGB) would not fit the 16 KiB of shared memory every
// device has.
const uint BLOCK = 16u;
shared vec3 partial[BLOCK * PROBE_GROUP_SIZE];

// The radiance arriving at the probe along ray `ray` (its surface decoded by
// `surfaces.comp`).
vec3 radiance_along(uint ray) {
    uvec4 a = texelFetch(probe_surfaces, int(2u * ray));
    if ((a.w >> 24u) == 0u) {
        return frame.sky_radiance.rgb;
    }
    uvec4 b = texelFetch(probe_surfaces, int(2u * ray + 1u));
    vec3 p = uintBitsToFloat(a.xyz);
    vec3 albedo = unpackUnorm4x8(a.w).rgb;
    vec3 n = unpack_normal(b.x);
    vec3 irradiance = vec3(0.0);
    for (uint i = 0u; i < frame.light_count; i++) {
        GpuLight light = lights[i];
        vec3 to_light;
        float dist;
        vec3 e = light_incident(light, p, n, to_light, dist);
        if (any(greaterThan(e, vec3(0.0)))) {
            // 3 × 3 taps: the probes' rays average over many hits, and the frame's
            // lighting pass keeps its 5 × 5 for what the camera sees.
            vec3 t1;
            vec3 t2;
            plane_directions(n, t1, t2);
            irradiance += e * shadow_visibility(light, p, n, t1, t2, SURFACE_SHADOW_OFFSET, 0.0, 1);
        }
    }
    vec3 radiance = albedo / PI * irradiance + vec3(unpackHalf2x16(b.z), unpackHalf2x16(b.w).x);
    if (probes.bounces != 0u && b.y != NO_LIGHTMAP_UV) {
        float level = max(lightmap_level(p, view.camera, view.forward),
                            lightmap_level(p, view.previous_camera, view.previous_forward));
        radiance += albedo * textureLod(previous_lightmap, unpackUnorm2x16(b.y), level).rgb;
    }
    return radiance;
}

void main() {
    uint probe = gl_WorkGroupID.x;
    uint lane = gl_LocalInvocationID.x;
    // The level of detail (4.2.1): the first `count` coefficients (the low bands are the
    // same functions whatever the order), from the rays of the level's relight map
    // (BINDING_PROBE_SH holds each ray's solid angle, its map's).
    uint count = min(lod[probe] & 0xFFFFu, COEFFICIENTS);
    uint level = lod[probe] >> 16u;
    uint side = probes.relight_side[level];
    uint first = probes.relight_first[level];
    vec3 sums[COEFFICIENTS];
    for (uint j = 0u; j < COEFFICIENTS; j++) {
        sums[j] = vec3(0.0);
    }
    for (uint i = lane; i < side * side; i += PROBE_GROUP_SIZE) {
        uint ray = first + i;
        vec3 l = radiance_along(probe * probes.rays_per_probe + ray);
        if (all(equal(l, vec3(0.0)))) {
            continue;
        }
        int at = int(ray * COEFFICIENTS);
        for (uint j = 0u; j < count; j++) {
            sums[j] += l * texelFetch(ray_harmonics, at + int(j)).r;
        }
    }
    for (uint block = 0u; block < count; block += BLOCK) {
        for (uint k = 0u; k < BLOCK; k++) {
            uint j = block + k;
            partial[k * PROBE_GROUP_SIZE + lane] = j < count ? sums[j] : vec3(0.0);
        }
        barrier();
        uint j = block + lane;
        if (lane < BLOCK && j < count) {
            vec3 total = vec3(0.0);
            for (uint i = 0u; i < PROBE_GROUP_SIZE; i++) {
                total += partial[lane * PROBE_GROUP_SIZE + i];
            }
            lambda[probe * COEFFICIENTS + j] = vec4(total, 0.0);
        }
        barrier();
    }
}
