// Direct light from the scene's lights, in the units of the references:
// point/spot intensity I [W/sr] gives irradiance E = I cos(theta) / d^2, a directional
// light gives E = irradiance cos(theta), and a Lambertian surface returns rho/pi * E.
#ifndef DIRECT_LIGHT_GLSL
#define DIRECT_LIGHT_GLSL
#include "common/frame.glsl"

// Which shadow view of a light covers p: point lights have six cube faces, chosen by the
// major axis of the light-to-point vector in the order +X -X +Y -Y +Z -Z.
uint shadow_view_for(GpuLight light, vec3 p) {
    if (light.shadow_view_count < 6u) {
        return light.first_shadow_view;
    }
    vec3 d = p - light.position.xyz;
    vec3 a = abs(d);
    uint face;
    if (a.x >= a.y && a.x >= a.z) {
        face = d.x >= 0.0 ? 0u : 1u;
    } else if (a.y >= a.z) {
        face = d.y >= 0.0 ? 2u : 3u;
    } else {
        face = d.z >= 0.0 ? 4u : 5u;
    }
    return light.first_shadow_view + face;
}

// World size of one texel of shadow view `view` at p.
float shadow_texel_world(ShadowView view, vec3 p) {
    bool ortho = view.origin.w > 0.5;
    return ortho ? view.texel_size : view.texel_size * distance(p, view.origin.xyz);
}

// The normal offset, in shadow texels, of a point on a surface (shadow_visibility).
const float SURFACE_SHADOW_OFFSET = 0.5;

// Where q lands in shadow view `view`, in normalized device coordinates.
vec3 shadow_ndc(ShadowView view, vec3 q) {
    vec4 clip = view.view_proj * vec4(q, 1.0);
    return clip.xyz / clip.w;
}

// Two directions along the plane with normal n (shadow_visibility's t1 and t2).
void plane_directions(vec3 n, out vec3 t1, out vec3 t2) {
    t1 = normalize(cross(n, abs(n.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0)));
    t2 = cross(n, t1);
}

// Fraction of the light reaching p (normal n), PCF over (2 pcf_radius + 1)^2 bilinear
// depth compares, p moved `offset_texels` shadow texels and `extra_offset` along n.
//
// Each tap compares the depth of p's own plane, along the directions t1 and t2 (not
// parallel; their lengths do not matter), where that tap lies (receiver plane depth bias,
// Isidoro 2006): the taps reach pcf_radius texels from p, where a plane tilted to the
// light lies deeper or shallower than p by the plane's slope, which one depth for every
// tap would take for a shadow (acne) or, offset enough to avoid that, for light. The
// plane is the surface the shadow map rasterized, not the shading normal's: a normal map
// tilts that far off it (the direct light of a normal-mapped floor 16.5 % off the path
// tracer's, `normal_maps_and_lobe_match_the_rasterized_direct_light`).
// What is left, the bilinear footprint of each tap reaching a texel beyond it, is the
// rasterizer's slope-scaled bias's (ShadowPass, 1.5 texels' worth of slope), so a point
// on a surface moves only half a texel along n (SURFACE_SHADOW_OFFSET; a whole texel
// scored worse against the path tracer's direct light on all four references tried). A
// constant two texels, without the plane, lit the rim of Sponza's planters through the
// leaves lying on it (its direct light 3.45 times the path tracer's with the sun's map at
// 8192; 2.06 with half a texel and the plane; BENCHMARKS.md, session 40).
float shadow_visibility(GpuLight light, vec3 p, vec3 n, vec3 t1, vec3 t2, float offset_texels, float extra_offset,
                        int pcf_radius) {
    if (light.shadow_view_count == 0u) {
        return 1.0;
    }
    ShadowView view = shadow_views[shadow_view_for(light, p)];
    float texel_world = shadow_texel_world(view, p);
    vec3 q = p + n * (offset_texels * texel_world + extra_offset);
    vec3 ndc = shadow_ndc(view, q);
    // The plane's depth per texel across the view, from a step of a texel along each
    // direction: the depth's change over the texels' change (one tap needs none). The
    // changes are taken in the view's own coordinates, not the atlas layer's, whose
    // larger values would round them (by up to 5e-4 of a texel in a layer of 4096).
    vec2 slope = vec2(0.0);
    if (pcf_radius > 0) {
        vec3 texels = vec3(vec2(0.5 * float(view.resolution)), 1.0);
        vec3 d1 = (shadow_ndc(view, q + normalize(t1) * texel_world) - ndc) * texels;
        vec3 d2 = (shadow_ndc(view, q + normalize(t2) * texel_world) - ndc) * texels;
        float det = d1.x * d2.y - d2.x * d1.y;
        // Seen edge-on (the plane's texels collapse to a line) the light arrives at a
        // grazing angle, where the slope is unbounded: the taps keep p's depth.
        if (abs(det) > 1e-3) {
            slope = vec2(d1.z * d2.y - d2.z * d1.y, d2.z * d1.x - d1.z * d2.x) / det;
        }
    }
    // The view is a tile of its layer (ShadowAtlas); its neighbours are other views, so
    // every tap's bilinear footprint is clamped half a texel inside the tile.
    vec2 layer_texels = vec2(textureSize(shadow_map, 0).xy);
    vec2 corner = vec2(view.offset_x, view.offset_y);
    vec2 at = corner + (ndc.xy * 0.5 + 0.5) * float(view.resolution);
    vec2 lo = corner + 0.5;
    vec2 hi = corner + float(view.resolution) - 0.5;
    float sum = 0.0;
    for (int y = -pcf_radius; y <= pcf_radius; y++) {
        for (int x = -pcf_radius; x <= pcf_radius; x++) {
            vec2 offset = vec2(x, y);
            vec2 tap = clamp(at + offset, lo, hi);
            float depth = ndc.z + dot(slope, offset);
            sum += texture(shadow_map, vec4(tap / layer_texels, float(view.layer), depth));
        }
    }
    float taps = float(2 * pcf_radius + 1);
    return sum / (taps * taps);
}

// Irradiance at p on a surface facing the light, the unit vector towards it and the
// distance to it (infinite for a directional light).
vec3 light_arriving(GpuLight light, vec3 p, out vec3 to_light, out float dist) {
    vec3 e;
    if (light.kind == LIGHT_DIRECTIONAL) {
        to_light = -light.direction.xyz;
        dist = 1e30;
        e = light.intensity.rgb;
    } else {
        vec3 d = light.position.xyz - p;
        // Only a light exactly on the point is clamped: no floor in scene units.
        float dist2 = max(dot(d, d), 1e-30);
        dist = sqrt(dist2);
        to_light = d / dist;
        e = light.intensity.rgb / dist2;
        if (light.kind == LIGHT_SPOT) {
            float cos_axis = dot(-to_light, light.direction.xyz);
            e *= smoothstep(light.direction.w, light.cos_inner, cos_axis);
        }
    }
    return e;
}

// Irradiance at p (normal n) from one light, unshadowed, the unit vector towards it and
// the distance to it (infinite for a directional light).
vec3 light_incident(GpuLight light, vec3 p, vec3 n, out vec3 to_light, out float dist) {
    return light_arriving(light, p, to_light, dist) * max(dot(n, to_light), 0.0);
}

// Irradiance at a surface point p (normal n, its plane along t1 and t2: shadow_visibility)
// from one light, shadowed (5x5 PCF), and the unit vector towards it.
vec3 light_irradiance(GpuLight light, vec3 p, vec3 n, vec3 t1, vec3 t2, out vec3 to_light) {
    float dist;
    vec3 e = light_incident(light, p, n, to_light, dist);
    if (all(equal(e, vec3(0.0)))) {
        return e;
    }
    return e * shadow_visibility(light, p, n, t1, t2, SURFACE_SHADOW_OFFSET, 0.0, 2);
}

// The BRDF for light arriving from l, seen from v: Lambertian albedo / pi plus, where
// `specular` > 0, normalised Blinn-Phong with the exponent matching the roughness.
vec3 surface_brdf(vec3 albedo, float specular, float roughness, vec3 n, vec3 v, vec3 l) {
    vec3 brdf = albedo / PI;
    if (specular > 0.0) {
        float r = max(roughness, 0.02);
        float exponent = 2.0 / (r * r) - 2.0;
        vec3 h = normalize(l + v);
        brdf += specular * (exponent + 8.0) / (8.0 * PI) * pow(max(dot(n, h), 0.0), exponent);
    }
    return brdf;
}
#endif
