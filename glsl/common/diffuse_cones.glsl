// The layout of the cone tracer's diffuse gather, shared with the path tracer's cone
// component (`--cone`), which integrates one of these cones exactly.
#ifndef DIFFUSE_CONES_GLSL
#define DIFFUSE_CONES_GLSL

// A unit vector perpendicular to the unit vector `axis` (from the world's y axis, or x
// where `axis` nearly is y): with cross(axis, it), the frame that cones are laid out in.
vec3 perpendicular(vec3 axis) {
    return normalize(abs(axis.y) < 0.9 ? cross(axis, vec3(0.0, 1.0, 0.0)) : cross(axis, vec3(1.0, 0.0, 0.0)));
}

// The axis of diffuse cone `k` about the normal n, in the frame n, t = perpendicular(n),
// b = cross(n, t) (taken once for all the cones): 0 along n, 1..ring evenly round a ring
// 57.5 degrees from it, the first towards t.
// The ring at 57.5 degrees: with the exact cone integrals the best ring is 50-55 degrees
// (the cosine-weighted mean direction of the band it stands for is 54.7), but the traced
// cones read their ring best at 57.5 (a sweep of 54.7 to 60 degrees with sub-cones,
// BENCHMARKS.md, session 11).
vec3 diffuse_cone_axis(vec3 n, vec3 t, vec3 b, int k, int ring) {
    if (k == 0) {
        return n;
    }
    float phi = 6.2831853 * float(k - 1) / float(ring);
    return normalize(0.5373 * n + 0.8434 * (cos(phi) * t + sin(phi) * b));
}
#endif
