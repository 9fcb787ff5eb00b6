#version 460
// Takes each voxel's attribute means from its fragment sums (gi/sums.glsl) into the
// albedo, normal and emission volumes (zero for a voxel without fragments), and lists the
// occupied voxels, so that voxel shading and bounces run one invocation per occupied voxel
// instead of one per grid cell (a wall fills a quarter to a half of the cells of the
// workgroups it crosses, and idle lanes cost as much as busy ones). The list head doubles
// as the indirect dispatch arguments.
#include "gi/sums.glsl"
#define VOXEL_LIST_WRITER
#include "gi/voxel_list.glsl"

layout(local_size_x = VOXEL_GROUP_SIZE, local_size_y = VOXEL_GROUP_SIZE, local_size_z = VOXEL_GROUP_SIZE) in;
layout(set = SET_PASS, binding = BINDING_GI_SUMS, r32ui) uniform readonly uimage3D voxel_sums;
layout(set = SET_PASS, binding = BINDING_GI_ALBEDO, r32ui) uniform writeonly uimage3D voxel_albedo;
layout(set = SET_PASS, binding = BINDING_GI_NORMAL, r32ui) uniform writeonly uimage3D voxel_normal;
layout(set = SET_PASS, binding = BINDING_GI_EMISSION, r32ui) uniform writeonly uimage3D voxel_emission;

uvec3 sums(ivec3 voxel, uint kind) {
    uint w = 3u * kind;
    return uvec3(imageLoad(voxel_sums, sum_texel(voxel, w)).r,
                 imageLoad(voxel_sums, sum_texel(voxel, w + 1u)).r,
                 imageLoad(voxel_sums, sum_texel(voxel, w + 2u)).r);
}

void main() {
    // The grid's edge is a multiple of the workgroup's: every invocation has a voxel.
    ivec3 voxel = ivec3(gl_GlobalInvocationID);
    uint count = imageLoad(voxel_sums, sum_texel(voxel, SUM_COUNT)).r;
    bool occupied = count != 0u;
    imageStore(voxel_albedo, voxel, uvec4(occupied ? packed_mean(sums(voxel, 0u), count) : 0u));
    imageStore(voxel_normal, voxel, uvec4(occupied ? packed_mean(sums(voxel, 1u), count) : 0u));
    imageStore(voxel_emission, voxel, uvec4(occupied ? packed_mean(sums(voxel, 2u), count) : 0u));

    uint index = take_list_entries(occupied ? 1u : 0u);
    if (occupied) {
        list_voxels[index] = pack_voxel(voxel);
    }
}
