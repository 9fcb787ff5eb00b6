#version 460
// Writes albedo, normal and emission of every voxel the (dilated) triangle covers, as
// RGBA8 moving averages, so overlapping triangles average.
#include "gi/average.glsl"

layout(set = SET_PASS, binding = BINDING_GI_ALBEDO, r32ui) uniform coherent volatile uimage3D voxel_albedo;
layout(set = SET_PASS, binding = BINDING_GI_NORMAL, r32ui) uniform coherent volatile uimage3D voxel_normal;
layout(set = SET_PASS, binding = BINDING_GI_EMISSION, r32ui) uniform coherent volatile uimage3D voxel_emission;

DEFINE_AVERAGE(average_albedo, voxel_albedo)
DEFINE_AVERAGE(average_normal, voxel_normal)
DEFINE_AVERAGE(average_emission, voxel_emission)

void store_voxel(ivec3 voxel, vec3 albedo, vec3 normal, vec3 emission) {
    average_albedo(voxel, albedo * 255.0);
    average_normal(voxel, normal * 255.0);
    average_emission(voxel, emission * 255.0);
}

#include "gi/voxelize/coverage.glsl"

void main() {
    cover_voxels();
}
