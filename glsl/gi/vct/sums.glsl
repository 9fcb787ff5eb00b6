// A voxel's fragment sums (Dřínovský 2013, 5.4.1), the same for the dense grid and the
// octree's leaves: each fragment adds its albedo, normal (xyz * 0.5 + 0.5) and emission
// (over `VctUniforms.emission_range`) and coverage across x, y and z
// (gi/vct/voxelize/coverage.glsl), each channel quantized to 0..255, and 1 to the count,
// VOXEL_SUM_WORDS words in all (albedo RGB, normal XYZ, emission RGB, coverage XYZ,
// count). Integer atomic adds are exact and commutative, so the means do not depend on
// the order in which the fragments arrive: a running average in RGBA8 (Crassin & Green
// 2012) rounds differently in every order, and its compare-and-swap loop serializes the
// fragments of a voxel (on an H100 the dense grid's voxelization of Sponza took 370 ms
// with it).
#ifndef SUMS_GLSL
#define SUMS_GLSL
#include "gi/vct/voxels.glsl"

#define SUM_COUNT (VOXEL_SUM_WORDS - 1u)
// The first of the coverage's three words.
#define SUM_COVERAGE 9u

// What a fragment adds to words 3a..3a+2 for attribute a (0 albedo, 1 normal, 2
// emission, 3 coverage), from its `channels` in 0..1.
uvec3 sum_terms(vec3 channels) {
    return uvec3(clamp(round(channels * 255.0), 0.0, 255.0));
}

// The RGBA8 mean of an attribute's sums (channels 0..255; alpha the fragment count up to
// 255, as every voxel attribute volume stores them), zero for a voxel without fragments.
uint packed_mean(uvec3 sum, uint count) {
    if (count == 0u) {
        return 0u;
    }
    return pack_rgba8(vec4(vec3(sum) / float(count), float(min(count, 255u))));
}

// A voxel's coverage across x, y and z from its sums: its fragments' covered shares added
// up (overlapping surfaces, or a slab's two faces, cover the voxel once), as stored in the
// coverage volume (RGBA8, alpha 1 where the voxel is occupied). Where nothing reads the
// coverage (VOXEL_COVERAGE), none is summed, and an occupied voxel counts as covered
// across every axis.
vec4 coverage_of(uvec3 sum, uint count) {
    if (count == 0u) {
        return vec4(0.0);
    }
    return VOXEL_COVERAGE ? vec4(min(vec3(sum) / 255.0, vec3(1.0)), 1.0) : vec4(1.0);
}

// The dense grid's sums image holds word w of voxel v at texel
// (v.x + n * (w % 2), v.y, v.z + n * (w / 2)): 2n x n x 7n texels, within lavapipe's 2048
// texels per axis at n = 256.
ivec3 sum_texel(ivec3 voxel, uint word) {
    int n = int(vct.resolution);
    return voxel + ivec3(n * int(word & 1u), 0, n * int(word >> 1));
}
#endif
