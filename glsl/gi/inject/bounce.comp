#version 460
// One more bounce of light between voxels (Villegas 2018 §4): each occupied voxel gathers
// the filtered radiance over the hemisphere of its lit face (injection turned the normal
// to it) and adds albedo times it to its direct radiance.
// Cones read only the directional levels (lod >= 1), never the base level rewritten here.
#include "gi/cones.glsl"

layout(local_size_x = VOXEL_GROUP_SIZE, local_size_y = VOXEL_GROUP_SIZE, local_size_z = VOXEL_GROUP_SIZE) in;
layout(set = SET_PASS, binding = BINDING_GI_ALBEDO, r32ui) uniform readonly uimage3D voxel_albedo;
layout(set = SET_PASS, binding = BINDING_GI_NORMAL, r32ui) uniform readonly uimage3D voxel_normal;
layout(set = SET_PASS, binding = BINDING_GI_DIRECT, rgba16f) uniform readonly image3D voxel_direct;
layout(set = SET_PASS, binding = BINDING_GI_RADIANCE, rgba16f) uniform writeonly image3D voxel_radiance_out;

void main() {
    ivec3 voxel = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(voxel, ivec3(gi.resolution)))) {
        return;
    }
    vec4 albedo = unpack_rgba8(imageLoad(voxel_albedo, voxel).r);
    if (albedo.a == 0.0) {
        return;
    }
    vec3 n = unpack_rgba8(imageLoad(voxel_normal, voxel).r).xyz / 255.0 * 2.0 - 1.0;
    n = length(n) > 0.2 ? normalize(n) : vec3(0.0, 1.0, 0.0);
    vec3 p = voxel_center(voxel);
    float offset = 1.5 * gi.origin.w;
    vec3 gathered = gather_diffuse(p, p + n * offset, n, 1.0);
    vec4 direct = imageLoad(voxel_direct, voxel);
    imageStore(voxel_radiance_out, voxel, vec4(direct.rgb + albedo.rgb / 255.0 * gathered, direct.a));
}
