#version 460
// Per leaf: each voxel's fragment sums (fill.comp) become its mean albedo, normal and
// emission in the leaf attribute bricks (RGBA8, alpha the fragment count up to 255, as
// the dense grid stores them; zero for a voxel without fragments) and its coverage in
// the leaf coverage bricks (laid out as the radiance bricks, whose borders it shares),
// and the occupied voxels are listed with their leaf's brick, so that voxel shading and
// bounces run one invocation per voxel, dispatched indirectly from the list's head as in the dense grid
// (gi/vct/dense/compact.comp). Bricks of the static part (before
// `counters.static_leaf_bricks`) keep the attributes their build wrote; later ones, given
// in this build or frame (every brick, in a build), are written, and their radiance
// voxels zeroed (the brick may have held another leaf last frame; voxel shading writes
// only the listed voxels, and the border transfer writes the border of every new brick
// before the filter reads it). The pools are not cleared: clears of these 3D
// images ran at about 50 GB/s on an H100 (65 ms of the depth-10 Sponza build), and only
// the bricks in use are ever read.
#define OCTREE
#define VOXEL_LIST_WRITER
#include "gi/vct/octree/nodes/level.glsl"
#include "gi/vct/voxel_list.glsl"
#include "gi/vct/sums.glsl"

layout(set = SET_GI, binding = BINDING_VCT_ALBEDO, r32ui) uniform writeonly uimage3D leaf_albedo;
layout(set = SET_GI, binding = BINDING_VCT_NORMAL, r32ui) uniform writeonly uimage3D leaf_normal;
layout(set = SET_GI, binding = BINDING_VCT_EMISSION, r32ui) uniform writeonly uimage3D leaf_emission;
layout(set = SET_GI, binding = BINDING_VCT_RADIANCE, rgba16f) uniform writeonly image3D leaf_radiance;
layout(set = SET_GI, binding = BINDING_VCT_COVERAGE, rgba8) uniform writeonly image3D leaf_coverage;

// Writes the means of `node`'s voxels into a brick given in this build or frame (and
// zeroes their radiance); returns the mask of its voxels with fragments.
uint take_means(uint node) {
    uint brick = node_bricks[node];
    ivec3 origin = brick_origin(brick, counters.leaf_pool_side, OCTREE_ATTRIBUTE_BRICK);
    bool fresh = brick >= counters.static_leaf_bricks;
    ivec3 radiance_origin = brick_origin(brick, counters.leaf_pool_side, OCTREE_RADIANCE_BRICK) + 1;
    uint entry = node_children[node];
    uint listed = 0u;
    for (int i = 0; i < 8; i++) {
        ivec3 k = ivec3(i & 1, (i >> 1) & 1, i >> 2);
        bool occupied = (entry & (1u << uint(i))) != 0u;
        uint base = occupied ? leaf_sum_base(entry, uint(i)) : 0u;
        uint count = occupied ? leaf_sums[base + SUM_COUNT] : 0u;
        if (count != 0u) {
            listed |= 1u << uint(i);
        }
        if (!fresh) {
            continue;
        }
        uvec3 sums[4] = uvec3[4](uvec3(0u), uvec3(0u), uvec3(0u), uvec3(0u));
        for (uint a = 0u; a < (VOXEL_COVERAGE ? 4u : 3u); a++) {
            sums[a] = uvec3(leaf_sums[base + 3u * a], leaf_sums[base + 3u * a + 1u], leaf_sums[base + 3u * a + 2u]);
        }
        uint means[3];
        for (uint a = 0u; a < 3u; a++) {
            means[a] = packed_mean(sums[a], count);
        }
        imageStore(leaf_albedo, origin + k, uvec4(means[0]));
        imageStore(leaf_normal, origin + k, uvec4(means[1]));
        imageStore(leaf_emission, origin + k, uvec4(means[2]));
        imageStore(leaf_radiance, radiance_origin + k, vec4(0.0));
        imageStore(leaf_coverage, radiance_origin + k, coverage_of(sums[3], count));
    }
    return listed;
}

void main() {
    uint node;
    bool leaf = level_node(node) && node_bricks[node] != OCTREE_NO_BRICK;
    uint listed = leaf ? take_means(node) : 0u;
    // Every invocation takes its entries together with its subgroup (none without a leaf).
    uint index = take_list_entries(uint(bitCount(listed)));
    if (listed == 0u) {
        return;
    }
    ivec3 first = ivec3(unpack_coord(node_coords[node])) * 2;
    for (int i = 0; i < 8; i++) {
        if ((listed & (1u << uint(i))) != 0u) {
            list_voxels[2u * index] = pack_voxel(first + ivec3(i & 1, (i >> 1) & 1, i >> 2));
            list_voxels[2u * index + 1u] = node_bricks[node];
            index++;
        }
    }
}
