#version 460
// Each voxel fragment adds its albedo, normal and emission to its voxel in its leaf's
// brick, as RGBA8 moving averages (Dřínovský 2013, 5.4.1). A leaf brick holds the leaf's
// 2x2x2 voxels of the effective grid, voxel (v & 1) of the brick.
#include "gi/average.glsl"
#include "svo/octree.glsl"

layout(local_size_x = SVO_GROUP_SIZE) in;
layout(set = SET_PASS, binding = BINDING_GI_ALBEDO, r32ui) uniform coherent volatile uimage3D brick_albedo;
layout(set = SET_PASS, binding = BINDING_GI_NORMAL, r32ui) uniform coherent volatile uimage3D brick_normal;
layout(set = SET_PASS, binding = BINDING_GI_EMISSION, r32ui) uniform coherent volatile uimage3D brick_emission;

DEFINE_AVERAGE(average_albedo, brick_albedo)
DEFINE_AVERAGE(average_normal, brick_normal)
DEFINE_AVERAGE(average_emission, brick_emission)

void main() {
    uint index = gl_GlobalInvocationID.x;
    if (index >= min(counters.fragment_count, counters.fragment_capacity)) {
        return;
    }
    VoxelFragment f = fragments[index];
    uvec3 v = unpack_coord(f.position);
    uint leaf = find_node(v, svo_depth() - 1u);
    if (leaf == SVO_NO_NODE || node_bricks[leaf] == SVO_NO_BRICK) {
        return;
    }
    ivec3 texel = brick_origin(node_bricks[leaf], counters.leaf_pool_side, SVO_ATTRIBUTE_BRICK) + ivec3(v & 1u);
    average_albedo(texel, unpack_rgba8(f.albedo).rgb);
    average_normal(texel, unpack_rgba8(f.normal).rgb);
    average_emission(texel, unpack_rgba8(f.emission).rgb);
}
