// The dense grid's `store_voxel` for the voxelization (gi/voxelize/coverage.glsl): adds
// the fragment's albedo, normal and emission to the voxel's fragment sums (gi/sums.glsl);
// the compact pass takes their means.
#ifndef STORE_SUMS_GLSL
#define STORE_SUMS_GLSL
#include "gi/vct/sums.glsl"

layout(set = SET_GI, binding = BINDING_DENSE_SUMS, r32ui) uniform uimage3D voxel_sums;

void store_voxel(ivec3 voxel, vec3 albedo, vec3 normal, vec3 emission) {
    uvec3 terms[3] = uvec3[3](sum_terms(albedo), sum_terms(normal), sum_terms(emission));
    for (uint a = 0u; a < 3u; a++) {
        for (uint c = 0u; c < 3u; c++) {
            if (terms[a][c] != 0u) {
                imageAtomicAdd(voxel_sums, sum_texel(voxel, 3u * a + c), terms[a][c]);
            }
        }
    }
    imageAtomicAdd(voxel_sums, sum_texel(voxel, SUM_COUNT), 1u);
}
#endif
