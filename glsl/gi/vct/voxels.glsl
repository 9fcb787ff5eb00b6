// Set 3 of the voxel cone tracer's passes: the voxel grid and the cone settings, and the
// packed formats of the voxel attributes, shared by both voxel stores (the dense grid:
// Präntare 2016, Villegas 2018; the octree: Dřínovský 2013).
#ifndef VOXELS_GLSL
#define VOXELS_GLSL
#include "gpu_layout.glsl"

layout(set = SET_GI, binding = BINDING_VCT_UNIFORMS) uniform VctBlock {
    VctUniforms vct;
};

// `--snapped-cones` (SNAPPED_CONES in cones.glsl), fixed when the pipeline is made: as a
// uniform tested in branches, lavapipe inlined it and compiled the passes anew at every
// bind (see SPEC_SNAPPED_CONES).
layout(constant_id = SPEC_SNAPPED_CONES) const bool SNAPPED_CONES = false;

// Whether the voxelization takes each voxel's coverage (gi/vct/voxelize/coverage.glsl),
// where some cone reads it (`reads_coverage` in src/gi/vct/mod.rs; SPEC_VOXEL_COVERAGE).
layout(constant_id = SPEC_VOXEL_COVERAGE) const bool VOXEL_COVERAGE = false;

// Whether the cells keep their surface planes (cones.glsl, plane_increment; PLANE_SLOT of
// the directional volumes; `--no-plane-occlusion`), fixed when the pipeline is made, for
// the reason SNAPPED_CONES is.
layout(constant_id = SPEC_PLANE_OCCLUSION) const bool PLANE_OCCLUSION = false;

// Slots of the directional volumes side by side along x (DIRECTIONAL_SLOTS).
uint directional_slots() {
    return DIRECTIONAL_SLOTS + (PLANE_OCCLUSION ? PLANE_SLOTS : 0u);
}

// RGBA8 packed as r | g << 8 | b << 16 | a << 24, channels in 0..255.
vec4 unpack_rgba8(uint v) {
    return vec4(float(v & 0xffu), float((v >> 8) & 0xffu), float((v >> 16) & 0xffu), float(v >> 24));
}

uint pack_rgba8(vec4 v) {
    uvec4 u = uvec4(clamp(round(v), 0.0, 255.0));
    return u.x | (u.y << 8) | (u.z << 16) | (u.w << 24);
}

// A packed normal (xyz * 127.5 + 127.5) as a vector of length up to 1 (shorter where
// the averaged normals disagree); `flip_normal` negates it exactly.
vec3 unpack_normal(uint v) {
    return (unpack_rgba8(v).xyz * 2.0 - 255.0) / 255.0;
}

// The packed normal turned around (each of x, y, z becomes 255 minus it), its alpha kept.
uint flip_normal(uint v) {
    return v ^ 0x00ffffffu;
}

// World position of the centre of voxel `v`.
vec3 voxel_center(ivec3 v) {
    return vct.origin.xyz + (vec3(v) + 0.5) * vct.origin.w;
}
#endif
