#version 460
// What each probe ray met, decoded once when the technique starts (the scene's static
// surfaces do not change): an invocation per ray writes the hit's position, its shading
// normal turned towards the probe, its albedo (Kd × map_Kd), its lightmap uv and what it
// emits towards the probe (one-sided emitters: zero from the back), so that the
// per-frame relight reads two texels per ray instead of the triangle, its shading, its
// material and its textures. A ray that left the scene is marked a miss.
#include "gi/probes/probes.glsl"

layout(local_size_x = PROBE_GROUP_SIZE) in;

layout(set = SET_GI, binding = BINDING_PROBE_HITS) uniform usamplerBuffer probe_hits;
layout(set = SET_GI, binding = BINDING_PROBE_POSITIONS) uniform samplerBuffer probe_positions;
layout(set = SET_GI, binding = BINDING_PROBE_SURFACES, rgba32ui) uniform writeonly uimageBuffer surfaces;

void main() {
    // Rows of at most 65,535 workgroups.
    uint ray = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * PROBE_GROUP_SIZE;
    if (ray >= probes.probe_count * probes.rays_per_probe) {
        return;
    }
    uvec4 hit = texelFetch(probe_hits, int(ray));
    if (hit.x == RAY_NONE) {
        imageStore(surfaces, int(2u * ray), uvec4(0u));
        imageStore(surfaces, int(2u * ray + 1u), uvec4(0u));
        return;
    }
    vec3 origin = texelFetch(probe_positions, int(ray / probes.rays_per_probe)).xyz;
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
    vec3 emitted = vec3(0.0);
    if (front) {
        emitted = m.emission.rgb;
        if (m.emission_texture != NO_TEXTURE) {
            emitted *= texture_bilinear(m.emission_texture, uv, true).rgb;
        }
    }
    vec2 at = lightmap_uv(hit.x, bary);
    imageStore(surfaces, int(2u * ray), uvec4(floatBitsToUint(p), packUnorm4x8(vec4(albedo, 1.0))));
    imageStore(surfaces, int(2u * ray + 1u),
               uvec4(pack_normal(n), at.x >= 0.0 ? packUnorm2x16(at) : NO_LIGHTMAP_UV,
                     packHalf2x16(emitted.rg), packHalf2x16(vec2(emitted.b, 0.0))));
}
