// Set 1: the scene's materials and textures.
#ifndef SCENE_GLSL
#define SCENE_GLSL
#include "gpu_layout.glsl"

layout(set = SET_SCENE, binding = BINDING_MATERIALS, std430) readonly buffer MaterialBlock {
    GpuMaterial materials[];
};
// Separate images and one sampler: combined image samplers count against a limit of
// 32 samplers per stage on lavapipe.
layout(set = SET_SCENE, binding = BINDING_TEXTURES) uniform texture2D textures[MAX_TEXTURES];
layout(set = SET_SCENE, binding = BINDING_MATERIAL_SAMPLER) uniform sampler material_sampler;

vec4 sample_texture(uint index, vec2 uv) {
    return texture(sampler2D(textures[index], material_sampler), uv);
}

// Kd x map_Kd. The material index is uniform per draw, so indexing the array needs no
// non-uniform qualifier.
vec3 material_albedo(GpuMaterial m, vec2 uv) {
    vec3 albedo = m.albedo.rgb;
    if (m.albedo_texture != NO_TEXTURE) {
        albedo *= sample_texture(m.albedo_texture, uv).rgb;
    }
    return albedo;
}

// Cut-out opacity: map_d times d (Coverage textures hold it in every channel).
float material_coverage(GpuMaterial m, vec2 uv) {
    float coverage = m.albedo.a;
    if (m.coverage_texture != NO_TEXTURE) {
        coverage *= sample_texture(m.coverage_texture, uv).r;
    }
    return coverage;
}

// Fragments below this coverage are cut out.
const float CUTOUT_THRESHOLD = 0.5;
#endif
