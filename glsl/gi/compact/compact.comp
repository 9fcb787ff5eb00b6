#version 460
// Lists the occupied voxels, so that voxel shading and bounces run one invocation per
// occupied voxel instead of one per grid cell (a wall fills a quarter to a half of the cells of
// the workgroups it crosses, and idle lanes cost as much as busy ones). The list head
// doubles as the indirect dispatch arguments: the invocation that opens a workgroup's
// worth of entries raises the workgroup count.
#include "gi/voxels.glsl"
#define VOXEL_LIST_WRITER
#include "gi/voxel_list.glsl"

layout(local_size_x = VOXEL_GROUP_SIZE, local_size_y = VOXEL_GROUP_SIZE, local_size_z = VOXEL_GROUP_SIZE) in;
layout(set = SET_PASS, binding = BINDING_GI_ALBEDO, r32ui) uniform readonly uimage3D voxel_albedo;

void main() {
    ivec3 voxel = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(voxel, ivec3(gi.resolution)))) {
        return;
    }
    if ((imageLoad(voxel_albedo, voxel).r >> 24) == 0u) {
        return;
    }
    uint index = atomicAdd(list.count, 1u);
    list_voxels[index] = pack_voxel(voxel);
    if (index % VOXEL_LIST_GROUP_SIZE == 0u) {
        atomicMax(list.groups_x, index / VOXEL_LIST_GROUP_SIZE + 1u);
    }
}
