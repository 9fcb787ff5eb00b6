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

// Fraction of the light reaching p (normal n), PCF over (2 pcf_radius + 1)^2 bilinear
// depth compares. `extra_offset` moves p further along n (voxel centres lie up to half a
// voxel inside their surface).
float shadow_visibility(GpuLight light, vec3 p, vec3 n, float extra_offset, int pcf_radius) {
    if (light.shadow_view_count == 0u) {
        return 1.0;
    }
    ShadowView view = shadow_views[shadow_view_for(light, p)];
    // Normal offset of about two texels at p's distance keeps a surface from shadowing
    // itself without the light leaking through thin walls.
    float texel_world = shadow_texel_world(view, p);
    vec4 clip = view.view_proj * vec4(p + n * (2.0 * texel_world + extra_offset), 1.0);
    vec3 ndc = clip.xyz / clip.w;
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
            vec2 uv = clamp(at + vec2(x, y), lo, hi) / layer_texels;
            sum += texture(shadow_map, vec4(uv, float(view.layer), ndc.z));
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

// Irradiance at a surface point p (normal n) from one light, shadowed (5x5 PCF), and the
// unit vector towards it.
vec3 light_irradiance(GpuLight light, vec3 p, vec3 n, out vec3 to_light) {
    float dist;
    vec3 e = light_incident(light, p, n, to_light, dist);
    if (all(equal(e, vec3(0.0)))) {
        return e;
    }
    return e * shadow_visibility(light, p, n, 0.0, 2);
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
