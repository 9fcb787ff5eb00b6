// The occupied-voxel list (compact.comp builds it; inject and bounce run over it, one
// invocation per entry, dispatched indirectly from its head).
#ifndef VOXEL_LIST_GLSL
#define VOXEL_LIST_GLSL
#include "gpu_layout.glsl"

#ifndef VOXEL_LIST_WRITER
readonly
#endif
layout(set = SET_PASS, binding = BINDING_GI_VOXEL_LIST, std430) buffer VoxelListBlock {
    VoxelListHeader list;
    uint list_voxels[];
};

uint pack_voxel(ivec3 v) {
    return uint(v.x) | (uint(v.y) << 10) | (uint(v.z) << 20);
}

// The voxel of this invocation's entry; false past the end of the list.
bool listed_voxel(out ivec3 voxel) {
    uint index = gl_GlobalInvocationID.x;
    if (index >= list.count) {
        voxel = ivec3(0);
        return false;
    }
    uint v = list_voxels[index];
    voxel = ivec3(v & 0x3ffu, (v >> 10) & 0x3ffu, v >> 20);
    return true;
}
#endif
