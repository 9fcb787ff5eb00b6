#version 460
// Depth- and normal-aware upsampling of the gathered indirect light: each pixel blends
// the four nearest reduced-resolution samples, bilinearly, down-weighting those whose
// surface lies at another depth or faces another way, then adds albedo x gathered to
// the direct light. Glossy pixels (Ks > 0) also trace one specular cone here, at full
// resolution, as reflections are sharper than the diffuse light.
#include "gi/cones.glsl"
#include "gi/cone_trace/screen.glsl"

layout(local_size_x = SCREEN_GROUP_SIZE, local_size_y = SCREEN_GROUP_SIZE) in;
layout(set = SET_PASS, binding = BINDING_GI_INDIRECT, rgba16f) uniform readonly image2D indirect;
layout(set = SET_PASS, binding = BINDING_GI_SCREEN, rgba32f) uniform image2D screen_radiance;

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (pixel.x >= int(frame.width) || pixel.y >= int(frame.height)) {
        return;
    }
    float depth = texelFetch(gbuffer_depth, pixel, 0).r;
    if (depth >= 1.0) {
        return;
    }
    vec3 p = pixel_position(pixel, depth);
    vec3 n = normalize(imageLoad(gbuffer_normal, pixel).xyz);
    float scale = float(gi.indirect_scale);
    // Position in reduced-resolution pixel units, relative to sample centres.
    vec2 at = (vec2(pixel) + 0.5) / scale - 0.5;
    ivec2 base = ivec2(floor(at));
    vec2 f = at - vec2(base);
    ivec2 size = imageSize(indirect);
    float tolerance = 2.0 * gi.origin.w;
    vec3 sum = vec3(0.0);
    float weight = 0.0;
    for (int j = 0; j < 2; j++) {
        for (int i = 0; i < 2; i++) {
            ivec2 low = clamp(base + ivec2(i, j), ivec2(0), size - 1);
            ivec2 sample_pixel = representative(low);
            float sample_depth = texelFetch(gbuffer_depth, sample_pixel, 0).r;
            if (sample_depth >= 1.0) {
                continue;
            }
            vec3 q = pixel_position(sample_pixel, sample_depth);
            vec3 m = normalize(imageLoad(gbuffer_normal, sample_pixel).xyz);
            float bilinear = (i == 0 ? 1.0 - f.x : f.x) * (j == 0 ? 1.0 - f.y : f.y);
            // Off the pixel's plane by more than two voxels, or turned away: another surface.
            float plane = exp(-abs(dot(q - p, n)) / tolerance);
            float w = max(bilinear, 1e-3) * plane * pow(max(dot(n, m), 0.0), 8.0);
            sum += w * imageLoad(indirect, low).rgb;
            weight += w;
        }
    }
    vec3 gathered = weight > 1e-6 ? sum / weight : vec3(0.0);
    vec4 albedo_specular = imageLoad(gbuffer_albedo, pixel);
    vec3 indirect_light = albedo_specular.rgb * gathered;
    float specular = albedo_specular.a;
    if (specular > 0.0) {
        // The cone's half-angle follows the roughness: tan(half) ~ roughness.
        float roughness = clamp(imageLoad(gbuffer_normal, pixel).w, 0.02, 1.0);
        vec3 v = normalize(frame.camera_position.xyz - p);
        vec3 r = reflect(-v, n);
        indirect_light += specular * trace_cone(p + n * (2.0 * gi.origin.w), r, roughness, 0.0, p, n).rgb;
    }
    vec4 direct = imageLoad(screen_radiance, pixel);
    imageStore(screen_radiance, pixel, vec4(direct.rgb + indirect_light, direct.a));
}
