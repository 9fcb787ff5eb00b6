#version 460
// Deferred direct lighting: G-buffer + lights + shadow maps -> HDR radiance.
#include "common/frame.glsl"
#include "common/direct_light.glsl"

layout(local_size_x = SCREEN_GROUP_SIZE, local_size_y = SCREEN_GROUP_SIZE) in;
layout(set = SET_PASS, binding = BINDING_LIGHTING_ALBEDO, rgba16f) uniform readonly image2D gbuffer_albedo;
layout(set = SET_PASS, binding = BINDING_LIGHTING_NORMAL, rgba16f) uniform readonly image2D gbuffer_normal;
layout(set = SET_PASS, binding = BINDING_LIGHTING_EMISSION, rgba16f) uniform readonly image2D gbuffer_emission;
layout(set = SET_PASS, binding = BINDING_LIGHTING_DEPTH) uniform sampler2D gbuffer_depth;
layout(set = SET_PASS, binding = BINDING_LIGHTING_OUT, rgba32f) uniform writeonly image2D radiance_out;

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (pixel.x >= int(frame.width) || pixel.y >= int(frame.height)) {
        return;
    }
    float depth = texelFetch(gbuffer_depth, pixel, 0).r;
    if (depth >= 1.0) {
        imageStore(radiance_out, pixel, vec4(frame.sky_radiance.rgb, 1.0));
        return;
    }
    vec4 albedo = imageLoad(gbuffer_albedo, pixel);
    vec4 normal_roughness = imageLoad(gbuffer_normal, pixel);
    vec3 p = pixel_position(pixel, depth);
    vec3 n = normalize(normal_roughness.xyz);
    vec3 v = normalize(frame.camera_position.xyz - p);
    // Normalised Blinn-Phong with the exponent matching the roughness.
    float roughness = max(normal_roughness.w, 0.02);
    float exponent = 2.0 / (roughness * roughness) - 2.0;
    vec3 radiance = imageLoad(gbuffer_emission, pixel).rgb;
    for (uint i = 0u; i < frame.light_count; i++) {
        vec3 l;
        vec3 e = light_irradiance(lights[i], p, n, 0.0, l);
        if (all(equal(e, vec3(0.0)))) {
            continue;
        }
        vec3 brdf = albedo.rgb / PI;
        if (albedo.a > 0.0) {
            vec3 h = normalize(l + v);
            brdf += albedo.a * (exponent + 8.0) / (8.0 * PI) * pow(max(dot(n, h), 0.0), exponent);
        }
        radiance += brdf * e;
    }
    imageStore(radiance_out, pixel, vec4(radiance, 1.0));
}
