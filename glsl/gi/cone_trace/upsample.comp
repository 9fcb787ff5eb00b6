#version 460
// variant: VOXELS_SVO
// The composite of the GI terms, per pixel at full resolution:
// - indirect diffuse: a depth- and normal-aware upsample of the gathered light (each
//   pixel blends the four nearest reduced-resolution samples bilinearly, down-weighting
//   those whose surface lies at another depth or faces another way), times albedo;
// - indirect specular: the cone along the reflection traced for glossy pixels (Ks > 0)
//   at reduced resolution, upsampled like the diffuse light, times Ks;
// - with soft-shadow cones instead of shadow maps, the whole shading: emission and the
//   direct light (the first lights' visibility upsampled like the indirect light), as the
//   lighting pass does not run then;
// - ambient occlusion on the indirect terms;
// - transmission: transmissive pixels (d < 1) pass 1 - d of the light from one cone
//   along the refracted ray.
// Each term follows its FLAG_*; the debug views show the indirect light or AO alone.
#include "gi/cones.glsl"
#include "common/direct_light.glsl"
#include "gi/cone_trace/screen.glsl"

layout(local_size_x = SCREEN_GROUP_SIZE, local_size_y = SCREEN_GROUP_SIZE) in;
layout(set = SET_PASS, binding = BINDING_GI_INDIRECT, rgba16f) uniform readonly image2D indirect;
layout(set = SET_PASS, binding = BINDING_GI_SHADOW, rgba16f) uniform readonly image2D shadow;
layout(set = SET_PASS, binding = BINDING_GI_SPECULAR, rgba16f) uniform readonly image2D specular_low;
layout(set = SET_PASS, binding = BINDING_GI_SCREEN, rgba32f) uniform image2D screen_radiance;
layout(set = SET_PASS, binding = BINDING_GI_GBUFFER_EMISSION, rgba16f) uniform readonly image2D gbuffer_emission;

// The gathered indirect light (rgb) and ambient occlusion (a) at `pixel`, upsampled;
// with `glossy` also the specular cone's radiance and, with soft-shadow cones, the first
// lights' visibility (each image is read only where it is needed: on a CPU driver every
// load counts).
vec4 upsampled_indirect(ivec2 pixel, vec3 p, vec3 n, bool glossy, out vec4 visibility, out vec3 specular) {
    bool cones = (frame.flags & FLAG_SHADOW_CONES) != 0u;
    vec4 visibility_sum = vec4(0.0);
    vec3 specular_sum = vec3(0.0);
    float scale = float(gi.indirect_scale);
    // Position in reduced-resolution pixel units, relative to sample centres.
    vec2 at = (vec2(pixel) + 0.5) / scale - 0.5;
    ivec2 base = ivec2(floor(at));
    vec2 f = at - vec2(base);
    ivec2 size = imageSize(indirect);
    float tolerance = 2.0 * gi.origin.w;
    vec4 sum = vec4(0.0);
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
            sum += w * imageLoad(indirect, low);
            if (cones) {
                visibility_sum += w * imageLoad(shadow, low);
            }
            if (glossy) {
                specular_sum += w * imageLoad(specular_low, low).rgb;
            }
            weight += w;
        }
    }
    visibility = weight > 1e-6 ? visibility_sum / weight : vec4(1.0);
    specular = weight > 1e-6 ? specular_sum / weight : vec3(0.0);
    return weight > 1e-6 ? sum / weight : vec4(0.0, 0.0, 0.0, 1.0);
}

bool enabled(uint flag) {
    return (frame.flags & flag) != 0u;
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (pixel.x >= int(frame.width) || pixel.y >= int(frame.height)) {
        return;
    }
    // With soft-shadow cones this pass shades the pixels from scratch (the lighting pass
    // does not run); otherwise it adds to the lighting pass's direct light.
    bool shades = enabled(FLAG_SHADOW_CONES);
    float depth = texelFetch(gbuffer_depth, pixel, 0).r;
    if (depth >= 1.0) {
        if (frame.debug_view != DEBUG_NONE) {
            imageStore(screen_radiance, pixel, vec4(frame.debug_view == DEBUG_AO ? vec3(1.0) : vec3(0.0), 1.0));
        } else if (shades) {
            imageStore(screen_radiance, pixel, vec4(enabled(FLAG_EMISSION) ? frame.sky_radiance.rgb : vec3(0.0), 1.0));
        }
        return;
    }
    vec3 p = pixel_position(pixel, depth);
    vec4 normal_roughness = imageLoad(gbuffer_normal, pixel);
    vec3 n = normalize(normal_roughness.xyz);
    vec3 v = normalize(frame.camera_position.xyz - p);
    vec4 albedo_specular = imageLoad(gbuffer_albedo, pixel);
    float roughness = clamp(normal_roughness.w, 0.02, 1.0);
    vec3 start = p + n * (2.0 * gi.origin.w);
    float specular = albedo_specular.a;
    bool glossy = specular > 0.0 && enabled(FLAG_INDIRECT_SPECULAR);

    vec4 cone_visibility_low;
    vec3 reflected;
    vec4 gathered = upsampled_indirect(pixel, p, n, glossy, cone_visibility_low, reflected);
    float ao = enabled(FLAG_AO) ? gathered.a : 1.0;
    vec3 indirect_light = vec3(0.0);
    if (enabled(FLAG_INDIRECT_DIFFUSE)) {
        indirect_light += albedo_specular.rgb * gathered.rgb;
    }
    if (glossy) {
        indirect_light += specular * reflected;
    }
    indirect_light *= ao;

    vec3 surface;
    if (!shades) {
        surface = imageLoad(screen_radiance, pixel).rgb;
    } else {
        surface = enabled(FLAG_EMISSION) ? imageLoad(gbuffer_emission, pixel).rgb : vec3(0.0);
    }
    if (shades && enabled(FLAG_DIRECT)) {
        for (uint i = 0u; i < frame.light_count; i++) {
            vec3 l;
            float dist;
            vec3 e = light_incident(lights[i], p, n, l, dist);
            if (all(equal(e, vec3(0.0)))) {
                continue;
            }
            float visibility = i < CONE_SHADOW_LIGHTS
                ? cone_visibility_low[i]
                : cone_visibility(start, l, gi.shadow_tan_half, dist - gi.origin.w);
            surface += surface_brdf(albedo_specular.rgb, specular, roughness, n, v, l) * e * visibility;
        }
    }
    surface += indirect_light;

    vec2 transmission = imageLoad(gbuffer_transmission, pixel).rg;
    vec3 transmitted = vec3(0.0);
    if (transmission.r > 0.0 && enabled(FLAG_TRANSMISSION)) {
        // n faces the camera: the ray enters the surface (relative index 1 / Ni).
        vec3 t = refract(-v, n, 1.0 / max(transmission.g, 1.0));
        vec3 dir = dot(t, t) > 0.0 ? t : reflect(-v, n);
        // The cone leaves the surface on the side it points to.
        vec3 side = dot(dir, n) < 0.0 ? -n : n;
        transmitted = transmission.r * trace_cone(p + side * (2.0 * gi.origin.w), dir, roughness, 0.0, p, side, -1).rgb;
        surface = (1.0 - transmission.r) * surface + transmitted;
    }

    vec3 result = surface;
    if (frame.debug_view == DEBUG_INDIRECT) {
        result = indirect_light + transmitted;
    } else if (frame.debug_view == DEBUG_AO) {
        result = vec3(gathered.a);
    }
    imageStore(screen_radiance, pixel, vec4(result, 1.0));
}
