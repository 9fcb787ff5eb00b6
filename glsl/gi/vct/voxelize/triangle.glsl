// A triangle projected along its dominant axis onto the grid-sized viewport of the
// voxelization, its edges dilated by half a pixel diagonal for conservative coverage
// (Hasselgren et al., GPU Gems 2 ch. 42): the geometry shader rasterizes it
// (voxelize.geom), the compute voxelizer walks its pixels itself (voxelize.comp).
#ifndef TRIANGLE_GLSL
#define TRIANGLE_GLSL
#include "gi/vct/voxels.glsl"

struct ProjectedTriangle {
    // Grid coordinates (voxels) with the dominant axis as z, counter-clockwise in xy.
    vec3 q[3];
    // The input vertex each of q is.
    int order[3];
    // Depth (voxels) = dot(plane, (x, y, 1)).
    vec3 plane;
    // Dilated edge lines, in pixel units: inside where dot(edge, (x, y, 1)) > 0.
    vec3 edge[3];
    // Pixel-space xy min, xy max: the triangle's box grown by half a pixel.
    vec4 bounds;
    // The triangle's depth extent in voxels.
    vec2 depth_range;
    uint axis;
    // Twice the projection's area (pixels², positive: counter-clockwise).
    float area;
};

// A projection without area: the rasterizer draws nothing of it.
const float DEGENERATE_AREA = 1e-12;

// Grid coordinates with the dominant axis moved to z.
vec3 swizzle(vec3 g, uint axis) {
    return axis == 0u ? g.yzx : (axis == 1u ? g.zxy : g.xyz);
}

ProjectedTriangle project_triangle(vec3 world[3]) {
    ProjectedTriangle t;
    vec3 face = abs(cross(world[1] - world[0], world[2] - world[0]));
    t.axis = (face.x >= face.y && face.x >= face.z) ? 0u : (face.y >= face.z ? 1u : 2u);
    vec3 p[3];
    for (int i = 0; i < 3; i++) {
        p[i] = swizzle((world[i] - vct.origin.xyz) / vct.origin.w, t.axis);
    }
    // Counter-clockwise in the projection: inside an edge line l is dot(l, (x, y, 1)) > 0,
    // so raising l.z moves the edge outwards.
    t.order = int[3](0, 1, 2);
    vec2 e1 = p[1].xy - p[0].xy;
    vec2 e2 = p[2].xy - p[0].xy;
    if (e1.x * e2.y - e1.y * e2.x < 0.0) {
        t.order = int[3](0, 2, 1);
    }
    t.q = vec3[3](p[t.order[0]], p[t.order[1]], p[t.order[2]]);

    vec3 pn = cross(t.q[1] - t.q[0], t.q[2] - t.q[0]);
    t.plane = vec3(-pn.x / pn.z, -pn.y / pn.z, t.q[0].z + (pn.x * t.q[0].x + pn.y * t.q[0].y) / pn.z);
    for (int i = 0; i < 3; i++) {
        vec3 line = cross(vec3(t.q[i].xy, 1.0), vec3(t.q[(i + 1) % 3].xy, 1.0));
        line.z += 0.5 * (abs(line.x) + abs(line.y));
        t.edge[i] = line;
    }
    t.bounds = vec4(min(min(t.q[0].xy, t.q[1].xy), t.q[2].xy) - 0.5,
                    max(max(t.q[0].xy, t.q[1].xy), t.q[2].xy) + 0.5);
    t.depth_range = vec2(min(min(t.q[0].z, t.q[1].z), t.q[2].z), max(max(t.q[0].z, t.q[1].z), t.q[2].z));
    vec3 q0 = t.q[0], q1 = t.q[1], q2 = t.q[2];
    t.area = (q1.x - q0.x) * (q2.y - q0.y) - (q1.y - q0.y) * (q2.x - q0.x);
    return t;
}

// The weights of the input vertices at point v of the projection, extrapolated outside
// the triangle; a degenerate projection weighs vertex q[i] alone at q[i].
vec3 projected_weights(ProjectedTriangle t, vec2 v, int i) {
    vec3 q0 = t.q[0], q1 = t.q[1], q2 = t.q[2];
    vec3 bary = vec3(i == 0, i == 1, i == 2);
    if (abs(t.area) >= DEGENERATE_AREA) {
        float b1 = ((v.x - q0.x) * (q2.y - q0.y) - (v.y - q0.y) * (q2.x - q0.x)) / t.area;
        float b2 = ((q1.x - q0.x) * (v.y - q0.y) - (q1.y - q0.y) * (v.x - q0.x)) / t.area;
        bary = vec3(1.0 - b1 - b2, b1, b2);
    }
    vec3 w;
    for (int k = 0; k < 3; k++) {
        w[t.order[k]] = bary[k];
    }
    return w;
}
// Edge line `edge` of `project_triangle` moved back onto the triangle's own edge.
vec3 undilated(vec3 edge) {
    return edge - vec3(0.0, 0.0, 0.5 * (abs(edge.x) + abs(edge.y)));
}

// The share of the square pixel centred at `pixel` on the inner side of the edge line
// `line` (dot(line, (x, y, 1)) > 0): over the square, dot(line, .) is the value at its
// centre plus two uniform spreads of widths |line.x| and |line.y|, whose sum has a
// trapezoidal density; the share is its distribution function at the centre's value.
float half_plane_coverage(vec3 line, vec2 pixel) {
    float d = dot(line, vec3(pixel, 1.0));
    float a = 0.5 * max(abs(line.x), abs(line.y));
    float b = 0.5 * min(abs(line.x), abs(line.y));
    if (d <= b - a) {
        float t = max(d + a + b, 0.0);
        return b > 0.0 ? t * t / (8.0 * a * b) : 0.0;
    }
    if (d >= a - b) {
        float t = max(a + b - d, 0.0);
        return b > 0.0 ? 1.0 - t * t / (8.0 * a * b) : 1.0;
    }
    return 0.5 + d / (2.0 * a);
}

// The share of the pixel centred at `pixel` that the triangle with (undilated) edge lines
// `lines` covers: the pixel's square clipped by the three edges (Sutherland-Hodgman; at
// most seven corners), its area by the shoelace formula. A pixel of the dilated
// triangle's conservative coverage that the triangle only touches covers nothing.
float pixel_coverage(vec3 lines[3], vec2 pixel) {
    // Beyond half the square's extent across an edge, the square lies wholly on one side.
    int crossing = 0;
    int crossed = 0;
    for (int e = 0; e < 3; e++) {
        float d = dot(lines[e], vec3(pixel, 1.0));
        float reach = 0.5 * (abs(lines[e].x) + abs(lines[e].y));
        if (d <= -reach) {
            return 0.0;
        }
        if (d < reach) {
            crossing++;
            crossed = e;
        }
    }
    if (crossing == 0) {
        return 1.0;
    }
    if (crossing == 1) {
        return half_plane_coverage(lines[crossed], pixel);
    }
    vec2 poly[8];
    poly[0] = pixel + vec2(-0.5, -0.5);
    poly[1] = pixel + vec2(0.5, -0.5);
    poly[2] = pixel + vec2(0.5, 0.5);
    poly[3] = pixel + vec2(-0.5, 0.5);
    int count = 4;
    for (int e = 0; e < 3; e++) {
        vec2 clipped[8];
        int kept = 0;
        for (int i = 0; i < count; i++) {
            vec2 a = poly[i];
            vec2 b = poly[(i + 1) % count];
            float da = dot(lines[e], vec3(a, 1.0));
            float db = dot(lines[e], vec3(b, 1.0));
            if (da >= 0.0 && kept < 8) {
                clipped[kept++] = a;
            }
            if ((da >= 0.0) != (db >= 0.0) && kept < 8) {
                clipped[kept++] = mix(a, b, da / (da - db));
            }
        }
        count = kept;
        for (int i = 0; i < count; i++) {
            poly[i] = clipped[i];
        }
    }
    float area = 0.0;
    for (int i = 0; i < count; i++) {
        vec2 a = poly[i];
        vec2 b = poly[(i + 1) % count];
        area += a.x * b.y - a.y * b.x;
    }
    return clamp(0.5 * area, 0.0, 1.0);
}
#endif
