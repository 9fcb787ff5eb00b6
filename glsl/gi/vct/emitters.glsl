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

// Lambert's term of the edge from p to q (relative to the surface point): its angle
// times the unit normal of the plane through it and the point. atan(s, cos) keeps the
// small angles of a far emitter's edges exact, where acos of their cosine would round
// them to zero.
vec3 edge_phi(vec3 p, vec3 q) {
    p = normalize(p);
    q = normalize(q);
    vec3 edge_normal = cross(p, q);
    float s = length(edge_normal);
    return s > 1e-12 ? atan(s, dot(p, q)) / s * edge_normal : vec3(0.0);
}

// Phi of the triangle a, b, c (relative to the surface point) clipped to the hemisphere
// about n, pointing towards the triangle. The clipped polygon is written out case by
// case: with it in an array lavapipe ran voxel shading ten times as long.
vec3 clipped_triangle_phi(vec3 a, vec3 b, vec3 c, vec3 n) {
    vec3 h = vec3(dot(a, n), dot(b, n), dot(c, n));
    bvec3 up = greaterThanEqual(h, vec3(0.0));
    int above = int(up.x) + int(up.y) + int(up.z);
    if (above == 0) {
        return vec3(0.0);
    }
    vec3 phi;
    vec3 towards;
    if (above == 3) {
        phi = edge_phi(a, b) + edge_phi(b, c) + edge_phi(c, a);
        towards = a + b + c;
    } else {
        // Turn the corners, keeping their order, so that `a` is the one alone on its
        // side of the horizon.
        bool alone_up = above == 1;
        if (up.y == alone_up) {
            vec3 t = a;
            a = b;
            b = c;
            c = t;
            h = h.yzx;
        } else if (up.z == alone_up) {
            vec3 t = c;
            c = b;
            b = a;
            a = t;
            h = h.zxy;
        }
        vec3 ab = a + (b - a) * (h.x / (h.x - h.y));
        vec3 ca = c + (a - c) * (h.z / (h.z - h.x));
        if (alone_up) {
            phi = edge_phi(a, ab) + edge_phi(ab, ca) + edge_phi(ca, a);
            towards = a + ab + ca;
        } else {
            phi = edge_phi(ab, b) + edge_phi(b, c) + edge_phi(c, ca) + edge_phi(ca, ab);
            towards = ab + b + c + ca;
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
