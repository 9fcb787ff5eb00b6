// The occupied-voxel list (dense: compact.comp; octree: octree/bricks/compact.comp), one
// invocation per entry of the passes that run over it, dispatched indirectly from its
// head. An entry gives the voxel and where its values live: in the dense grid at the
// voxel itself; in the octree in its leaf's bricks.
#ifndef VOXEL_LIST_GLSL
#define VOXEL_LIST_GLSL
#include "gpu_layout.glsl"
#ifdef OCTREE
#include "gi/vct/octree/octree.glsl"
#endif

#ifndef VOXEL_LIST_WRITER
readonly
#endif
layout(set = SET_GI, binding = BINDING_VCT_VOXEL_LIST, std430) buffer VoxelListBlock {
    VoxelListHeader list;
    // Dense: the voxel (x | y << 10 | z << 20). Octree: the voxel, then its leaf's brick.
    uint list_voxels[];
};

#ifdef OCTREE
#define VOXEL_LIST_STRIDE 2u
#else
#define VOXEL_LIST_STRIDE 1u
#endif

#ifdef VOXEL_LIST_WRITER
#include "common/subgroup_add.glsl"
// Where this invocation's `entries` entries start (its subgroup takes them with one
// atomic add); raises the indirect dispatch to cover them.
uint take_list_entries(uint entries) {
    uint first;
    SUBGROUP_ATOMIC_ADD(list.count, entries, first)
    if (entries != 0u) {
        atomicMax(list.groups_x, (first + entries + VOXEL_LIST_GROUP_SIZE - 1u) / VOXEL_LIST_GROUP_SIZE);
    }
    return first;
}
#endif

uint pack_voxel(ivec3 v) {
    return uint(v.x) | (uint(v.y) << 10) | (uint(v.z) << 20);
}

struct ListedVoxel {
    // In the effective grid.
    ivec3 voxel;
    // Of its albedo, normal, emission and direct light.
    ivec3 texel;
    // Of its radiance.
    ivec3 radiance_texel;
#ifdef OCTREE
    // Its leaf's brick.
    uint brick;
#endif
};

// The voxel of this invocation's entry; false past the end of the list.
bool listed_voxel(out ListedVoxel entry) {
    uint index = gl_GlobalInvocationID.x;
    if (index >= list.count) {
        return false;
    }
    uint v = list_voxels[VOXEL_LIST_STRIDE * index];
    entry.voxel = ivec3(v & 0x3ffu, (v >> 10) & 0x3ffu, v >> 20);
#ifdef OCTREE
    uint brick = list_voxels[VOXEL_LIST_STRIDE * index + 1u];
    entry.brick = brick;
    ivec3 within = entry.voxel & 1;
    entry.texel = brick_origin(brick, counters.leaf_pool_side, OCTREE_ATTRIBUTE_BRICK) + within;
    entry.radiance_texel = brick_origin(brick, counters.leaf_pool_side, OCTREE_RADIANCE_BRICK) + 1 + within;
#else
    entry.texel = entry.voxel;
    entry.radiance_texel = entry.voxel;
#endif
    return true;
}

#ifdef OCTREE
// Whether the entry's brick was given out in this frame's insertion of moving meshes (with
// `--full-update`, every brick): its radiance started from zero.
bool fresh_brick(ListedVoxel entry) {
    return counters.carry_capacity > 0u && entry.brick >= counters.static_leaf_bricks;
}
#endif
#endif
