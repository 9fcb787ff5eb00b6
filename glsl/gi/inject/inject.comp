#version 460
// Deferred voxel shading (Villegas 2018): per occupied voxel, outgoing radiance =
// albedo / pi * direct irradiance (shadow maps, the surface shading's units) + emission,
// stored premultiplied by opacity.
#include "common/frame.glsl"
#include "common/direct_light.glsl"
#include "gi/voxels.glsl"

layout(local_size_x = VOXEL_GROUP_SIZE, local_size_y = VOXEL_GROUP_SIZE, local_size_z = VOXEL_GROUP_SIZE) in;
layout(set = SET_PASS, binding = BINDING_GI_ALBEDO, r32ui) uniform readonly uimage3D voxel_albedo;
layout(set = SET_PASS, binding = BINDING_GI_NORMAL, r32ui) uniform readonly uimage3D voxel_normal;
layout(set = SET_PASS, binding = BINDING_GI_EMISSION, r32ui) uniform readonly uimage3D voxel_emission;
layout(set = SET_PASS, binding = BINDING_GI_RADIANCE, rgba16f) uniform writeonly image3D voxel_radiance;
layout(set = SET_PASS, binding = BINDING_GI_DIRECT, rgba16f) uniform writeonly image3D voxel_direct;

void main() {
    ivec3 voxel = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(voxel, ivec3(gi.resolution)))) {
        return;
    }
    vec4 albedo = unpack_rgba8(imageLoad(voxel_albedo, voxel).r);
    if (albedo.a == 0.0) {
        imageStore(voxel_radiance, voxel, vec4(0.0));
        imageStore(voxel_direct, voxel, vec4(0.0));
        return;
    }
    vec3 rho = albedo.rgb / 255.0;
    vec3 n = unpack_rgba8(imageLoad(voxel_normal, voxel).r).xyz / 255.0 * 2.0 - 1.0;
    float len = length(n);
    // Opposite normals averaged in one voxel cancel; such a voxel faces every way.
    n = len > 0.2 ? n / len : vec3(0.0, 1.0, 0.0);
    vec3 p = voxel_center(voxel);
    float half_voxel = 0.5 * gi.origin.w;
    vec3 e = vec3(0.0);
    for (uint i = 0u; i < frame.light_count; i++) {
        vec3 l;
        // Surfaces are two-sided: light arriving on either face is reflected.
        vec3 front = light_irradiance(lights[i], p, n, half_voxel, l);
        vec3 back = light_irradiance(lights[i], p, -n, half_voxel, l);
        e += (len > 0.2) ? max(front, back) : front + back;
    }
    vec3 emission = unpack_rgba8(imageLoad(voxel_emission, voxel).r).rgb / 255.0 * gi.emission_range;
    vec4 radiance = vec4(rho / PI * e + emission, 1.0);
    imageStore(voxel_radiance, voxel, radiance);
    imageStore(voxel_direct, voxel, radiance);
}
