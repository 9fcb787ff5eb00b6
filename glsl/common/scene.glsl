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

// Kd x map_Kd.
vec3 material_albedo(GpuMaterial m, vec2 uv) {
    vec3 albedo = m.albedo.rgb;
    if (m.albedo_texture != NO_TEXTURE) {
        albedo *= texture(albedo_texture, uv).rgb;
    }
    return albedo;
}

// Cut-out mask: map_d (coverage textures hold it in every channel), 1 without one.
float material_cutout(GpuMaterial m, vec2 uv) {
    return m.coverage_texture != NO_TEXTURE ? texture(coverage_texture, uv).r : 1.0;
}

// Opacity: map_d times d. Shadow maps and voxels hold the surfaces at least half opaque;
// the G-buffer draws the rest too, as transmissive surfaces.
float material_coverage(GpuMaterial m, vec2 uv) {
    return m.albedo.a * material_cutout(m, uv);
}

// Fragments below this coverage are cut out.
const float CUTOUT_THRESHOLD = 0.5;
#endif
