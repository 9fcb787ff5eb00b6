#version 460
// Lists the occupied leaf voxels (those with fragments), with their leaf's brick, so that
// voxel shading and bounces run one invocation per voxel, dispatched indirectly from the
// list's head as in the dense grid (gi/compact/compact.comp).
#define VOXELS_SVO
#define VOXEL_LIST_WRITER
#include "svo/octree/level.glsl"
#include "gi/voxel_list.glsl"

layout(set = SET_PASS, binding = BINDING_GI_ALBEDO, r32ui) uniform readonly uimage3D leaf_albedo;

void main() {
    uint node;
    if (!level_node(node) || node_bricks[node] == SVO_NO_BRICK) {
        return;
    }
    uint brick = node_bricks[node];
    ivec3 origin = brick_origin(brick, counters.leaf_pool_side, SVO_ATTRIBUTE_BRICK);
    ivec3 first = ivec3(unpack_coord(node_coords[node])) * 2;
    for (int i = 0; i < 8; i++) {
        ivec3 k = ivec3(i & 1, (i >> 1) & 1, i >> 2);
        if ((imageLoad(leaf_albedo, origin + k).r >> 24) == 0u) {
            continue;
        }
        uint index = atomicAdd(list.count, 1u);
        list_voxels[2u * index] = pack_voxel(first + k);
        list_voxels[2u * index + 1u] = brick;
        if (index % VOXEL_LIST_GROUP_SIZE == 0u) {
            atomicMax(list.groups_x, index / VOXEL_LIST_GROUP_SIZE + 1u);
        }
    }
}
