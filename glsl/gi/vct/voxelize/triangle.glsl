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
#endif
