#version 460
// Takes each voxel's attribute means from its fragment sums (gi/sums.glsl; with moving
// meshes, this frame's sums plus the static meshes') into the albedo, normal and emission
// volumes and its coverage into the coverage volume, zeroes this frame's sums for the next
// voxelization and the voxel's radiance and direct light (injection writes those of the
// listed voxels only); a voxel empty now
// and before keeps its zeros untouched. It lists the occupied voxels, so that voxel
// shading and bounces run one invocation per occupied voxel instead of one per grid cell
// (a wall fills a quarter to a half of the cells of the workgroups it crosses, and idle
// lanes cost as much as busy ones). The list head doubles as the indirect dispatch
// arguments. Zeroing here instead of clearing the images: clears and copies of these 3D
// images ran at about 50 GB/s on an H100.
#include "gi/vct/sums.glsl"
#define VOXEL_LIST_WRITER
#include "gi/vct/voxel_list.glsl"

layout(local_size_x = VOXEL_GROUP_SIZE, local_size_y = VOXEL_GROUP_SIZE, local_size_z = VOXEL_GROUP_SIZE) in;
layout(set = SET_GI, binding = BINDING_DENSE_SUMS, r32ui) uniform uimage3D voxel_sums;
layout(set = SET_GI, binding = BINDING_DENSE_STATIC_SUMS, r32ui) uniform readonly uimage3D static_sums;
layout(set = SET_GI, binding = BINDING_VCT_ALBEDO, r32ui) uniform uimage3D voxel_albedo;
layout(set = SET_GI, binding = BINDING_VCT_NORMAL, r32ui) uniform writeonly uimage3D voxel_normal;
layout(set = SET_GI, binding = BINDING_VCT_EMISSION, r32ui) uniform writeonly uimage3D voxel_emission;
layout(set = SET_GI, binding = BINDING_VCT_COVERAGE, rgba8) uniform writeonly image3D voxel_coverage;
layout(set = SET_GI, binding = BINDING_VCT_RADIANCE, rgba16f) uniform writeonly image3D voxel_radiance;
layout(set = SET_GI, binding = BINDING_VCT_DIRECT, rgba16f) uniform writeonly image3D voxel_direct;

// Word w of the voxel's sums: this frame's where it has fragments, plus the static ones'.
uint sum_word(ivec3 voxel, uint w, bool fresh, bool kept) {
    ivec3 texel = sum_texel(voxel, w);
    uint sum = fresh ? imageLoad(voxel_sums, texel).r : 0u;
    return kept ? sum + imageLoad(static_sums, texel).r : sum;
}

void main() {
    // The grid's edge is a multiple of the workgroup's: every invocation has a voxel.
    ivec3 voxel = ivec3(gl_GlobalInvocationID);
    ivec3 count_texel = sum_texel(voxel, SUM_COUNT);
    uint fresh_count = imageLoad(voxel_sums, count_texel).r;
    uint kept_count = vct.static_sums != 0u ? imageLoad(static_sums, count_texel).r : 0u;
    bool fresh = fresh_count != 0u;
    bool kept = kept_count != 0u;
    uint count = fresh_count + kept_count;
    // Alpha counts the fragments: zero for a voxel that was empty.
    if (count == 0u && imageLoad(voxel_albedo, voxel).r == 0u) {
        return;
    }
    uint means[3] = uint[3](0u, 0u, 0u);
    uvec3 sums[4] = uvec3[4](uvec3(0u), uvec3(0u), uvec3(0u), uvec3(0u));
    if (count != 0u) {
        for (uint a = 0u; a < (VOXEL_COVERAGE ? 4u : 3u); a++) {
            sums[a] = uvec3(sum_word(voxel, 3u * a, fresh, kept),
                            sum_word(voxel, 3u * a + 1u, fresh, kept),
                            sum_word(voxel, 3u * a + 2u, fresh, kept));
        }
        for (uint a = 0u; a < 3u; a++) {
            means[a] = packed_mean(sums[a], count);
        }
    }
    if (fresh) {
        for (uint w = 0u; w < VOXEL_SUM_WORDS; w++) {
            imageStore(voxel_sums, sum_texel(voxel, w), uvec4(0u));
        }
    }
    imageStore(voxel_albedo, voxel, uvec4(means[0]));
    imageStore(voxel_normal, voxel, uvec4(means[1]));
    imageStore(voxel_emission, voxel, uvec4(means[2]));
    imageStore(voxel_coverage, voxel, coverage_of(sums[3], count));
    imageStore(voxel_radiance, voxel, vec4(0.0));
    imageStore(voxel_direct, voxel, vec4(0.0));

    bool occupied = count != 0u;
    uint index = take_list_entries(occupied ? 1u : 0u);
    if (occupied) {
        list_voxels[index] = pack_voxel(voxel);
    }
}
