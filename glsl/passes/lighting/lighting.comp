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

// The surface's step across one pixel along `axis` at p, seen through `pixel`, from the
// points seen through the two neighbouring pixels, where they and p lie on one line (a
// flat stretch of surface, to within 5 degrees and 10 % in length); zero elsewhere (an
// edge, a crease, the sky or the image's border on either side).
vec3 plane_step(ivec2 pixel, ivec2 axis, vec3 p) {
    ivec2 lo = pixel - axis;
    ivec2 hi = pixel + axis;
    if (any(lessThan(lo, ivec2(0))) || hi.x >= int(frame.width) || hi.y >= int(frame.height)) {
        return vec3(0.0);
    }
    float depth_lo = texelFetch(gbuffer_depth, lo, 0).r;
    float depth_hi = texelFetch(gbuffer_depth, hi, 0).r;
    if (is_sky(depth_lo) || is_sky(depth_hi)) {
        return vec3(0.0);
    }
    vec3 before = p - pixel_position(lo, depth_lo);
    vec3 after = pixel_position(hi, depth_hi) - p;
    float a = length(before);
    float b = length(after);
    bool in_line = dot(before, after) >= cos(radians(5.0)) * a * b && abs(a - b) <= 0.1 * max(a, b);
    return in_line ? before + after : vec3(0.0);
}

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
        // The shadow maps' receiver plane is the surface as rasterized, which the depth
        // buffer holds where it is flat across the neighbouring pixels (plane_step); else
        // the plane of the shading normal.
        vec3 t1 = plane_step(pixel, ivec2(1, 0), p);
        vec3 t2 = plane_step(pixel, ivec2(0, 1), p);
        vec3 across = cross(t1, t2);
        if (dot(across, across) <= 1e-12 * dot(t1, t1) * dot(t2, t2)) {
            plane_directions(n, t1, t2);
        }
        for (uint i = 0u; i < frame.light_count; i++) {
            vec3 l;
            vec3 e = light_irradiance(lights[i], p, n, t1, t2, l);
            if (all(equal(e, vec3(0.0)))) {
                continue;
            }
            radiance += surface_brdf(albedo.rgb, albedo.a, normal_roughness.w, n, v, l) * e;
        }
    }
    imageStore(radiance_out, pixel, vec4(radiance, 1.0));
}
