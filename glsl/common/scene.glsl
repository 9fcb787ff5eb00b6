// Set 1: the scene's materials and textures.
#ifndef SCENE_GLSL
#define SCENE_GLSL
#include "gpu_layout.glsl"

layout(set = SET_SCENE, binding = BINDING_MATERIALS, std430) readonly buffer MaterialBlock {
    GpuMaterial materials[];
};
// The drawn material's textures: one descriptor set per material, so that shaders index
// no texture arrays (dynamic indexing is an optional feature that lavapipe lacks).
layout(set = SET_SCENE, binding = BINDING_ALBEDO_TEXTURE) uniform sampler2D albedo_texture;
layout(set = SET_SCENE, binding = BINDING_COVERAGE_TEXTURE) uniform sampler2D coverage_texture;
layout(set = SET_SCENE, binding = BINDING_NORMAL_TEXTURE) uniform sampler2D normal_texture;
layout(set = SET_SCENE, binding = BINDING_EMISSION_TEXTURE) uniform sampler2D emission_texture;

// How the material textures are sampled: implicitly over the fragment's footprint, or,
// where a shader defines MATERIAL_GRADIENTS (compute shaders have no implicit
// derivatives), over the footprint with uv gradients `material_dx` and `material_dy`,
// which it sets before sampling.
#ifdef MATERIAL_GRADIENTS
vec2 material_dx;
vec2 material_dy;
#define SAMPLE_MATERIAL(TEXTURE, UV) textureGrad(TEXTURE, UV, material_dx, material_dy)
#else
#define SAMPLE_MATERIAL(TEXTURE, UV) texture(TEXTURE, UV)
#endif

// Kd x map_Kd.
vec3 material_albedo(GpuMaterial m, vec2 uv) {
    vec3 albedo = m.albedo.rgb;
    if (m.albedo_texture != NO_TEXTURE) {
        albedo *= SAMPLE_MATERIAL(albedo_texture, uv).rgb;
    }
    return albedo;
}

// Ke x map_Ke: the radiance a surface emits along its winding normal.
vec3 material_emission(GpuMaterial m, vec2 uv) {
    vec3 emission = m.emission.rgb;
    if (m.emission_texture != NO_TEXTURE) {
        emission *= SAMPLE_MATERIAL(emission_texture, uv).rgb;
    }
    return emission;
}

// Cut-out mask: map_d (coverage textures hold it in every channel), 1 without one.
float material_cutout(GpuMaterial m, vec2 uv) {
    return m.coverage_texture != NO_TEXTURE ? SAMPLE_MATERIAL(coverage_texture, uv).r : 1.0;
}

// Opacity: map_d times d. Shadow maps and voxels hold the surfaces at least half opaque;
// the G-buffer draws the rest too, as transmissive surfaces.
float material_coverage(GpuMaterial m, vec2 uv) {
    return m.albedo.a * material_cutout(m, uv);
}

// Fragments below this coverage are cut out.
const float CUTOUT_THRESHOLD = 0.5;
#endif
