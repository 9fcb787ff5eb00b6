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
    if (is_sky(depth)) {
        vec3 sky = (frame.flags & FLAG_EMISSION) != 0u ? frame.sky_radiance.rgb : vec3(0.0);
        imageStore(radiance_out, pixel, vec4(sky, 1.0));
        return;
    }
    vec3 radiance = (frame.flags & FLAG_EMISSION) != 0u ? imageLoad(gbuffer_emission, pixel).rgb : vec3(0.0);
    // (With soft-shadow cones this pass does not run: the GI's upsample shades.)
    if ((frame.flags & FLAG_DIRECT) != 0u) {
        vec4 albedo = imageLoad(gbuffer_albedo, pixel);
        vec4 normal_roughness = imageLoad(gbuffer_normal, pixel);
        vec3 p = pixel_position(pixel, depth);
        vec3 n = normalize(normal_roughness.xyz);
        vec3 v = normalize(frame.camera_position.xyz - p);
        for (uint i = 0u; i < frame.light_count; i++) {
            vec3 l;
            vec3 e = light_irradiance(lights[i], p, n, l);
            if (all(equal(e, vec3(0.0)))) {
                continue;
            }
            radiance += surface_brdf(albedo.rgb, albedo.a, normal_roughness.w, n, v, l) * e;
        }
    }
    imageStore(radiance_out, pixel, vec4(radiance, 1.0));
}
