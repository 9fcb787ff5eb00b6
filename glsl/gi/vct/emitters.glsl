// The emitters whose light the cone tracer samples (src/gi/vct/emitters.rs): planar
// groups of triangles of constant radiance L. Their unoccluded irradiance on a surface
// with normal n is exact: L n . Phi, where Phi, the integral of the direction over the
// solid angle the emitter covers above the surface's horizon, is Lambert's sum over the
// edges of the polygon clipped to that hemisphere (Arvo 1994): 1/2 of the sum of each
// edge's angle times the unit normal of the plane through it and the surface point.
// Phi also points where the light comes from (the axis of the cone whose visibility
// stands for the emitter's), and its length is about the solid angle the emitter covers
// (exactly for a small one).
#ifndef EMITTERS_GLSL
#define EMITTERS_GLSL
#include "gi/vct/voxels.glsl"

layout(set = SET_GI, binding = BINDING_VCT_EMITTERS, std430) readonly buffer VctEmitterBlock {
    VctEmitter vct_emitters[];
};
layout(set = SET_GI, binding = BINDING_VCT_EMITTER_TRIANGLES, std430) readonly buffer VctEmitterTriangleBlock {
    VctEmitterTriangle vct_emitter_triangles[];
};

// Phi of the triangle a, b, c (relative to the surface point) clipped to the hemisphere
// about n, pointing towards the triangle.
vec3 clipped_triangle_phi(vec3 a, vec3 b, vec3 c, vec3 n) {
    vec3 corners[3] = vec3[3](a, b, c);
    vec3 polygon[4];
    int count = 0;
    for (int i = 0; i < 3; i++) {
        vec3 p = corners[i];
        vec3 q = corners[(i + 1) % 3];
        float hp = dot(p, n);
        float hq = dot(q, n);
        if (hp >= 0.0) {
            polygon[count++] = p;
        }
        if ((hp >= 0.0) != (hq >= 0.0)) {
            polygon[count++] = p + (q - p) * (hp / (hp - hq));
        }
    }
    vec3 phi = vec3(0.0);
    vec3 towards = vec3(0.0);
    for (int i = 0; i < count; i++) {
        towards += polygon[i];
        vec3 p = normalize(polygon[i]);
        vec3 q = normalize(polygon[(i + 1) % count]);
        vec3 edge_normal = cross(p, q);
        float s = length(edge_normal);
        // atan(s, cos) keeps the small angles of a far emitter's edges exact, where acos
        // of their cosine would round them to zero.
        if (s > 1e-12) {
            phi += atan(s, dot(p, q)) / s * edge_normal;
        }
    }
    phi *= 0.5;
    return dot(phi, towards) < 0.0 ? -phi : phi;
}

// Phi of emitter `e` at the surface point p with normal n (zero where p lies behind its
// plane: emitters are one-sided).
vec3 emitter_phi(VctEmitter e, vec3 p, vec3 n) {
    if (dot(e.plane.xyz, p) <= e.plane.w) {
        return vec3(0.0);
    }
    vec3 phi = vec3(0.0);
    for (uint i = 0u; i < e.triangle_count; i++) {
        VctEmitterTriangle t = vct_emitter_triangles[e.first_triangle + i];
        phi += clipped_triangle_phi(t.v0.xyz - p, t.v1.xyz - p, t.v2.xyz - p, n);
    }
    return phi;
}
#endif
