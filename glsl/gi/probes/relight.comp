#version 460
// Probe relight and projection (Sedláček 2019, 3.3.1.1 and 3.3.1.2), a workgroup per
// probe: the radiance each of its rays meets, projected onto the real harmonics,
// λ_j = Σ_rays L Y_j dω (the octahedral map's texels are equal in solid angle, and
// BINDING_PROBE_SH holds Y_j dω). The radiance at a hit is what a Lambertian surface
// sends back towards the probe, in the lighting pass's units and model:
// - the direct light of every light, shadowed by the frame's shadow maps, × albedo / π;
// - the emission, from the front of an emitter only (one-sided, as the G-buffer);
// - last frame's lightmap (irradiance / π) × albedo: each frame adds a bounce, as the
//   cone tracer's voxel bounces do;
// and the sky where a ray leaves the scene. Normal maps and specular lobes are not
// seen by the probes (their lightmap is diffuse irradiance).
#include "common/direct_light.glsl"
#include "gi/probes/probes.glsl"

layout(local_size_x = PROBE_GROUP_SIZE) in;
// Harmonic coefficients per channel, (order + 1)².
layout(constant_id = 0) const uint COEFFICIENTS = 16u;

layout(set = SET_GI, binding = BINDING_PROBE_HITS) uniform usamplerBuffer probe_hits;
layout(set = SET_GI, binding = BINDING_PROBE_SH) uniform samplerBuffer ray_harmonics;
layout(set = SET_GI, binding = BINDING_PROBE_POSITIONS) uniform samplerBuffer probe_positions;
layout(set = SET_GI, binding = BINDING_PROBE_LAMBDA, std430) writeonly buffer LambdaBlock {
    vec4 lambda[];
};
layout(set = SET_GI, binding = BINDING_PROBE_LIGHTMAP_PREVIOUS) uniform sampler2D previous_lightmap;

// The sums are reduced a block of coefficients at a time: the whole of band 7 (64
// coefficients × 64 invocations × RGB) would not fit the 16 KiB of shared memory every
// device has.
const uint BLOCK = 16u;
shared vec3 partial[BLOCK * PROBE_GROUP_SIZE];

// The radiance arriving at probe position `origin` along the ray that met `hit`.
vec3 radiance_along(uvec4 hit, vec3 origin) {
    if (hit.x == RAY_NONE) {
        return frame.sky_radiance.rgb;
    }
    RayTriangle tri = ray_triangle(hit.x);
    RayShading sh = ray_shading(hit.x);
    vec2 bary = uintBitsToFloat(hit.zw);
    GpuMaterial m = ray_material(floatBitsToUint(tri.v0.w));
    vec3 p = tri.v0.xyz + tri.e1.xyz * bary.x + tri.e2.xyz * bary.y;
    vec3 winding = normalize(cross(tri.e1.xyz, tri.e2.xyz));
    bool front = dot(winding, origin - p) > 0.0;
    vec3 ng = front ? winding : -winding;
    float w = 1.0 - bary.x - bary.y;
    vec3 n = sh.n0.xyz * w + sh.n1.xyz * bary.x + sh.n2.xyz * bary.y;
    n = dot(n, n) > 1e-12 ? normalize(n) : ng;
    n = dot(n, ng) < 0.0 ? -n : n;
    vec2 uv = triangle_uv(hit.x, bary);
    vec3 albedo = m.albedo.rgb;
    if (m.albedo_texture != NO_TEXTURE) {
        albedo *= texture_bilinear(m.albedo_texture, uv, true).rgb;
    }
    vec3 irradiance = vec3(0.0);
    for (uint i = 0u; i < frame.light_count; i++) {
        GpuLight light = lights[i];
        vec3 to_light;
        float dist;
        vec3 e = light_incident(light, p, n, to_light, dist);
        // A light behind the surface (the interpolated normal may still face it) sends
        // nothing.
        if (dot(ng, to_light) > 0.0 && any(greaterThan(e, vec3(0.0)))) {
            // 3 × 3 taps: the probes' rays average over many hits, and the frame's
            // lighting pass keeps its 5 × 5 for what the camera sees.
            irradiance += e * shadow_visibility(light, p, ng, 0.0, 1);
        }
    }
    vec3 radiance = albedo / PI * irradiance;
    if (front) {
        vec3 emitted = m.emission.rgb;
        if (m.emission_texture != NO_TEXTURE) {
            emitted *= texture_bilinear(m.emission_texture, uv, true).rgb;
        }
        radiance += emitted;
    }
    if (probes.bounces != 0u) {
        vec2 at = lightmap_uv(hit.x, bary);
        if (at.x >= 0.0) {
            radiance += albedo * textureLod(previous_lightmap, at, 0.0).rgb;
        }
    }
    return radiance;
}

void main() {
    uint probe = gl_WorkGroupID.x;
    uint lane = gl_LocalInvocationID.x;
    vec3 origin = texelFetch(probe_positions, int(probe)).xyz;
    vec3 sums[COEFFICIENTS];
    for (uint j = 0u; j < COEFFICIENTS; j++) {
        sums[j] = vec3(0.0);
    }
    uint first = probe * probes.rays_per_probe;
    for (uint ray = lane; ray < probes.rays_per_probe; ray += PROBE_GROUP_SIZE) {
        vec3 l = radiance_along(texelFetch(probe_hits, int(first + ray)), origin);
        if (all(equal(l, vec3(0.0)))) {
            continue;
        }
        int at = int(ray * COEFFICIENTS);
        for (uint j = 0u; j < COEFFICIENTS; j++) {
            sums[j] += l * texelFetch(ray_harmonics, at + int(j)).r;
        }
    }
    for (uint block = 0u; block < COEFFICIENTS; block += BLOCK) {
        for (uint k = 0u; k < BLOCK; k++) {
            uint j = block + k;
            partial[k * PROBE_GROUP_SIZE + lane] = j < COEFFICIENTS ? sums[j] : vec3(0.0);
        }
        barrier();
        uint j = block + lane;
        if (lane < BLOCK && j < COEFFICIENTS) {
            vec3 total = vec3(0.0);
            for (uint i = 0u; i < PROBE_GROUP_SIZE; i++) {
                total += partial[lane * PROBE_GROUP_SIZE + i];
            }
            lambda[probe * COEFFICIENTS + j] = vec4(total, 0.0);
        }
        barrier();
    }
}
