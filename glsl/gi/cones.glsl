// Cone marching through the voxel radiance (Crassin et al. 2011), shared by the screen
// gather and the voxel bounce.
#ifndef CONES_GLSL
#define CONES_GLSL
#include "common/frame.glsl"
#include "gi/voxels.glsl"

layout(set = SET_PASS, binding = BINDING_GI_RADIANCE_SAMPLED) uniform sampler3D voxel_radiance;
layout(set = SET_PASS, binding = BINDING_GI_DIRECTIONAL) uniform sampler3D voxel_directional;

// The directional volume d (+X -X +Y -Y +Z -Z) at `uvw` and mip `level`. The six sit side
// by side along x; x is kept half a texel (of the coarser level filtered) inside the
// volume so that filtering never mixes two directions.
vec4 sample_directional(int d, vec3 uvw, float level) {
    float edge = float(max(int(gi.resolution) >> (int(ceil(level)) + 1), 1));
    float margin = 0.5 / edge;
    vec3 packed_uvw = vec3((float(d) + clamp(uvw.x, margin, 1.0 - margin)) / 6.0, uvw.yz);
    return textureLod(voxel_directional, packed_uvw, level);
}

// Voxel radiance at `uvw` for a cone travelling along `dir` with footprint `lod` (0 = one
// voxel): the base level below lod 1, blended into the three directional volumes facing
// the cone, weighted by the squared direction components.
vec4 sample_voxels(vec3 uvw, vec3 dir, float lod) {
    vec4 base = textureLod(voxel_radiance, uvw, 0.0);
    if (lod <= 0.0) {
        return base;
    }
    vec3 w = dir * dir;
    float level = max(lod - 1.0, 0.0);
    vec4 aniso = w.x * sample_directional(dir.x >= 0.0 ? 0 : 1, uvw, level)
        + w.y * sample_directional(dir.y >= 0.0 ? 2 : 3, uvw, level)
        + w.z * sample_directional(dir.z >= 0.0 ? 4 : 5, uvw, level);
    return lod < 1.0 ? mix(base, aniso, lod) : aniso;
}

// Front-to-back accumulation along one cone; returns premultiplied radiance (rgb) with
// the sky behind whatever the cone leaves open, and (a) the occlusion that ambient
// occlusion counts, each occluder weighted down with its distance d by
// 1 / (1 + d / gi.ao_distance). Ambient occlusion reads opacity from the one
// directional volume `ao_volume` (0..5, or -1: none) travelling away from the surface
// along the axis closest to its normal: the surface's own voxels are hidden from it by
// the filter's facing weight, whereas the three volumes a slanted cone blends see them
// edge-on, so an open plane would occlude itself.
vec4 trace_cone(vec3 origin, vec3 dir, float tan_half, float min_lod, int ao_volume) {
    float voxel = gi.origin.w;
    float grid_size = voxel * float(gi.resolution);
    vec4 acc = vec4(0.0);
    float ao = 0.0;
    float ao_alpha = 0.0;
    float dist = voxel;
    while (acc.a < 0.99 && dist < gi.max_distance) {
        float diameter = max(voxel, 2.0 * tan_half * dist);
        float lod = max(log2(diameter / voxel), min_lod);
        vec3 uvw = (origin + dir * dist - gi.origin.xyz) / grid_size;
        if (any(lessThan(uvw, vec3(0.0))) || any(greaterThan(uvw, vec3(1.0)))) {
            break;
        }
        vec4 s = sample_voxels(uvw, dir, lod);
        float step_length = diameter * gi.step_factor;
        // Opacity was filtered for a step of one sample diameter; correct it to this step.
        float a = 1.0 - pow(1.0 - clamp(s.a, 0.0, 0.9999), step_length / diameter);
        vec3 rgb = s.a > 1e-4 ? s.rgb * (a / s.a) : vec3(0.0);
        acc.rgb += (1.0 - acc.a) * rgb;
        acc.a += (1.0 - acc.a) * a;
        if (ao_volume >= 0) {
            float o = sample_directional(ao_volume, uvw, max(lod - 1.0, 0.0)).a;
            o = 1.0 - pow(1.0 - clamp(o, 0.0, 0.9999), gi.step_factor);
            ao += (1.0 - ao_alpha) * o / (1.0 + dist / gi.ao_distance);
            ao_alpha += (1.0 - ao_alpha) * o;
        }
        dist += step_length;
    }
    acc.rgb += (1.0 - acc.a) * frame.sky_radiance.rgb;
    return vec4(acc.rgb, ao);
}

// Fraction of the light from `dir` that reaches `origin` through the voxels within
// `max_dist`: a soft-shadow cone, accumulating opacity only.
float cone_visibility(vec3 origin, vec3 dir, float tan_half, float max_dist) {
    float voxel = gi.origin.w;
    float grid_size = voxel * float(gi.resolution);
    float occlusion = 0.0;
    float dist = voxel;
    while (occlusion < 0.99 && dist < max_dist) {
        float diameter = max(voxel, 2.0 * tan_half * dist);
        vec3 uvw = (origin + dir * dist - gi.origin.xyz) / grid_size;
        if (any(lessThan(uvw, vec3(0.0))) || any(greaterThan(uvw, vec3(1.0)))) {
            break;
        }
        float s = sample_voxels(uvw, dir, log2(diameter / voxel)).a;
        float step_length = diameter * gi.step_factor;
        occlusion += (1.0 - occlusion) * (1.0 - pow(1.0 - clamp(s, 0.0, 0.9999), gi.step_factor));
        dist += step_length;
    }
    return 1.0 - occlusion;
}

// Cosine-weighted mean radiance over the hemisphere around n from `cones` cones from
// `origin`: one along n, the others in a ring 60 degrees from it. With `with_ao`, alpha
// is the ambient occlusion (1 where nothing near occludes); else 1.
vec4 gather_diffuse(vec3 origin, vec3 n, int cones, float min_lod, bool with_ao) {
    vec3 t = normalize(abs(n.y) < 0.9 ? cross(n, vec3(0.0, 1.0, 0.0)) : cross(n, vec3(1.0, 0.0, 0.0)));
    vec3 b = cross(n, t);
    int ao_volume = -1;
    if (with_ao) {
        vec3 m = abs(n);
        int axis = m.x >= m.y && m.x >= m.z ? 0 : (m.y >= m.z ? 1 : 2);
        ao_volume = 2 * axis + (n[axis] >= 0.0 ? 0 : 1);
    }
    vec4 sum = trace_cone(origin, n, gi.diffuse_tan_half, min_lod, ao_volume);
    float weight = 1.0;
    int ring = cones - 1;
    for (int i = 0; i < ring; i++) {
        float phi = 6.2831853 * float(i) / float(ring);
        vec3 dir = normalize(0.5 * n + 0.8660254 * (cos(phi) * t + sin(phi) * b));
        sum += trace_cone(origin, dir, gi.diffuse_tan_half, min_lod, ao_volume) * 0.5;
        weight += 0.5;
    }
    sum /= weight;
    return vec4(sum.rgb, 1.0 - sum.a);
}
#endif
