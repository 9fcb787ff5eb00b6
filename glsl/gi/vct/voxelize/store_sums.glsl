// The dense grid's `store_voxel` for the voxelization (gi/voxelize/coverage.glsl): adds
// the fragment's albedo, normal, emission and coverage to the voxel's fragment sums
// (gi/sums.glsl); the compact pass takes their means (the coverage's sum).
#ifndef STORE_SUMS_GLSL
#define STORE_SUMS_GLSL
#include "gi/vct/sums.glsl"

layout(set = SET_GI, binding = BINDING_DENSE_SUMS, r32ui) uniform uimage3D voxel_sums;

void store_voxel(ivec3 voxel, vec3 albedo, vec3 normal, vec3 emission, vec3 coverage) {
    uvec3 terms[4] = uvec3[4](sum_terms(albedo), sum_terms(normal), sum_terms(emission), sum_terms(coverage));
    for (uint a = 0u; a < 4u; a++) {
        for (uint c = 0u; c < 3u; c++) {
            if (terms[a][c] != 0u) {
                imageAtomicAdd(voxel_sums, sum_texel(voxel, 3u * a + c), terms[a][c]);
            }
        }
    }
    imageAtomicAdd(voxel_sums, sum_texel(voxel, SUM_COUNT), 1u);
}
#endif
