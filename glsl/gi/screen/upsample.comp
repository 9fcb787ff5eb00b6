#version 460
// The composite of the GI terms a technique gathered at reduced resolution (the screen
// contract, `gi::screen`), per pixel at full resolution:
// - indirect diffuse: a depth- and normal-aware upsample of the gathered light (each
//   pixel blends the four nearest reduced-resolution samples bilinearly, down-weighting
//   those whose surface lies off its plane or faces another way), times albedo;
// - indirect specular: the reflected light gathered for glossy pixels (Ks > 0),
//   upsampled like the diffuse light, times Ks;
// - when the technique shades the direct light (soft-shadow cones instead of shadow
//   maps), the whole shading: emission and the direct light (each light's visibility
//   upsampled like the indirect light), as the lighting pass does not run then;
// - ambient occlusion on the indirect terms;
// - transmission: transmissive pixels (d < 1) pass 1 - d of the refracted light,
//   upsampled from the transmissive samples.
// Each term follows its FLAG_*; the debug views show the indirect light, the cone
// tracer's sampled emitters' light (which it gathers with its indirect light) or AO alone.
// Nothing here reads a technique's own data, so one pipeline serves every technique.
#include "common/direct_light.glsl"
#include "gi/screen/screen.glsl"

layout(local_size_x = SCREEN_GROUP_SIZE, local_size_y = SCREEN_GROUP_SIZE) in;
layout(set = SET_SCREEN, binding = BINDING_SCREEN_INDIRECT, rgba16f) uniform readonly image2D indirect;
layout(set = SET_SCREEN, binding = BINDING_SCREEN_SHADOW, rgba16f) uniform readonly image2D shadow;
layout(set = SET_SCREEN, binding = BINDING_SCREEN_SPECULAR, rgba16f) uniform readonly image2D specular_low;
layout(set = SET_SCREEN, binding = BINDING_SCREEN_RADIANCE, rgba32f) uniform image2D screen_radiance;
layout(set = SET_SCREEN, binding = BINDING_SCREEN_EMISSION, rgba16f) uniform readonly image2D gbuffer_emission;
layout(set = SET_SCREEN, binding = BINDING_SCREEN_TRANSMITTED, rgba16f) uniform readonly image2D transmitted_low;

// The four reduced-resolution samples around a pixel and their upsampling weights.
struct Taps {
    ivec2 low[4];
    float weight[4];
    float total;
};

// Each pixel blends the four nearest reduced-resolution samples bilinearly, down-weighting
// those whose surface lies at another depth or faces another way.
Taps upsample_taps(ivec2 pixel, vec3 p, vec3 n) {
    Taps taps;
    taps.total = 0.0;
    float scale = float(screen.indirect_scale);
    // Position in reduced-resolution pixel units, relative to sample centres.
    vec2 at = (vec2(pixel) + 0.5) / scale - 0.5;
    ivec2 base = ivec2(floor(at));
    vec2 f = at - vec2(base);
    ivec2 size = imageSize(indirect);
    float tolerance = screen.plane_tolerance;
    for (int k = 0; k < 4; k++) {
        ivec2 corner = ivec2(k & 1, k >> 1);
        ivec2 low = clamp(base + corner, ivec2(0), size - 1);
        taps.low[k] = low;
        taps.weight[k] = 0.0;
        ivec2 sample_pixel = representative(low);
        float sample_depth = texelFetch(gbuffer_depth, sample_pixel, 0).r;
        if (is_sky(sample_depth)) {
            continue;
        }
        vec3 q = pixel_position(sample_pixel, sample_depth);
        vec3 m = normalize(imageLoad(gbuffer_normal, sample_pixel).xyz);
        float bilinear = (corner.x == 0 ? 1.0 - f.x : f.x) * (corner.y == 0 ? 1.0 - f.y : f.y);
        // Off the pixel's plane by more than the technique's tolerance, or turned away:
        // another surface.
        float plane = exp(-abs(dot(q - p, n)) / tolerance);
        float facing = max(dot(n, m), 0.0);
        facing *= facing;
        facing *= facing;
        taps.weight[k] = max(bilinear, 1e-3) * plane * facing * facing;
        taps.total += taps.weight[k];
    }
    return taps;
}

// Defines `vec4 NAME(Taps taps, ivec2 offset)`: IMAGE upsampled (its samples at
// `offset` from the reduced-resolution pixels), or `EMPTY` where no sample is on the
// pixel's surface. Each image is read only where it is needed: on a CPU driver every load
// counts. A tap of zero weight is not read at all: a sample that sees the sky writes only
// the indirect image, and 0 times the stale NaN bits another image may hold there is NaN
// (the Stanford bunny with --shadow-cones showed such pixels). GLSL cannot pass an image
// to a function, hence one function per image.
#define DEFINE_UPSAMPLED(NAME, IMAGE, EMPTY)                        \
    vec4 NAME(Taps taps, ivec2 offset) {                            \
        if (taps.total <= 1e-6) {                                   \
            return EMPTY;                                           \
        }                                                           \
        vec4 sum = vec4(0.0);                                       \
        for (int k = 0; k < 4; k++) {                               \
            if (taps.weight[k] > 0.0) {                             \
                sum += taps.weight[k] * imageLoad(IMAGE, taps.low[k] + offset); \
            }                                                       \
        }                                                           \
        return sum / taps.total;                                    \
    }

DEFINE_UPSAMPLED(upsampled_indirect, indirect, vec4(0.0, 0.0, 0.0, 1.0))
DEFINE_UPSAMPLED(upsampled_visibility, shadow, vec4(1.0))
DEFINE_UPSAMPLED(upsampled_specular, specular_low, vec4(0.0))
DEFINE_UPSAMPLED(upsampled_transmitted, transmitted_low, vec4(0.0))

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
    if (is_sky(depth)) {
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
    float specular = albedo_specular.a;
    bool glossy = specular > 0.0 && enabled(FLAG_INDIRECT_SPECULAR);

    Taps taps = upsample_taps(pixel, p, n);
    vec4 gathered = upsampled_indirect(taps, ivec2(0));
    float ao = enabled(FLAG_AO) ? gathered.a : 1.0;
    vec3 indirect_light = vec3(0.0);
    if (enabled(FLAG_INDIRECT_DIFFUSE)) {
        indirect_light += albedo_specular.rgb * gathered.rgb;
    }
    if (glossy) {
        indirect_light += specular * upsampled_specular(taps, ivec2(0)).rgb;
    }
    indirect_light *= ao;

    vec3 surface;
    if (!shades) {
        surface = imageLoad(screen_radiance, pixel).rgb;
    } else {
        surface = enabled(FLAG_EMISSION) ? imageLoad(gbuffer_emission, pixel).rgb : vec3(0.0);
    }
    if (shades && enabled(FLAG_DIRECT)) {
        vec4 visibility = vec4(1.0);
        uint band = ~0u;
        for (uint i = 0u; i < frame.light_count; i++) {
            vec3 l;
            float dist;
            vec3 e = light_incident(lights[i], p, n, l, dist);
            if (all(equal(e, vec3(0.0)))) {
                continue;
            }
            if (i / 4u != band) {
                band = i / 4u;
                visibility = upsampled_visibility(taps, shadow_texel(ivec2(0), band));
            }
            surface += surface_brdf(albedo_specular.rgb, specular, roughness, n, v, l) * e * visibility[i % 4u];
        }
    }
    surface += indirect_light;

    vec2 transmission = imageLoad(gbuffer_transmission, pixel).rg;
    vec3 transmitted = vec3(0.0);
    if (transmission.r > 0.0 && enabled(FLAG_TRANSMISSION)) {
        // The refraction cones of the transmissive samples among the four (alpha: their
        // share of the weights); where none is, the surface is drawn opaque.
        vec4 refracted = upsampled_transmitted(taps, ivec2(0));
        if (refracted.a > 0.0) {
            transmitted = transmission.r * refracted.rgb / refracted.a;
            surface = (1.0 - transmission.r) * surface + transmitted;
        }
    }

    vec3 result = surface;
    if (frame.debug_view == DEBUG_INDIRECT) {
        result = indirect_light + transmitted;
    } else if (frame.debug_view == DEBUG_EMITTER_LIGHT) {
        result = albedo_specular.rgb * gathered.rgb;
    } else if (frame.debug_view == DEBUG_AO) {
        result = vec3(gathered.a);
    }
    imageStore(screen_radiance, pixel, vec4(result, 1.0));
}
