#version 460
// Projects each triangle along its dominant axis onto a grid-sized viewport and dilates
// it by half a pixel diagonal for conservative coverage (Hasselgren et al., GPU Gems 2
// ch. 42), as lavapipe has no VK_EXT_conservative_rasterization. The fragment shader
// clips to the triangle's pixel bounding box.
#include "gi/voxels.glsl"

layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;
layout(location = 0) in vec3 in_world[];
layout(location = 1) in vec3 in_normal[];
layout(location = 2) in vec2 in_uv[];
layout(location = 1) out vec3 out_normal;
layout(location = 2) out vec2 out_uv;
layout(location = 3) flat out vec4 out_bounds;     // pixel-space xy min, xy max
layout(location = 4) flat out uint out_axis;
layout(location = 5) flat out vec3 out_plane;      // depth (voxels) = dot(plane, (x, y, 1))
layout(location = 6) flat out vec2 out_depth_range; // triangle's depth extent in voxels

// Grid coordinates (voxels) with the dominant axis moved to z.
vec3 swizzle(vec3 g, uint axis) {
    return axis == 0u ? g.yzx : (axis == 1u ? g.zxy : g.xyz);
}

void main() {
    vec3 face = abs(cross(in_world[1] - in_world[0], in_world[2] - in_world[0]));
    uint axis = (face.x >= face.y && face.x >= face.z) ? 0u : (face.y >= face.z ? 1u : 2u);
    float n = float(gi.resolution);
    vec3 p[3];
    for (int i = 0; i < 3; i++) {
        p[i] = swizzle((in_world[i] - gi.origin.xyz) / gi.origin.w, axis);
    }
    // Counter-clockwise in the projection: inside an edge line l is dot(l, (x, y, 1)) > 0,
    // so raising l.z moves the edge outwards.
    int order[3] = int[3](0, 1, 2);
    vec2 e1 = p[1].xy - p[0].xy;
    vec2 e2 = p[2].xy - p[0].xy;
    if (e1.x * e2.y - e1.y * e2.x < 0.0) {
        order = int[3](0, 2, 1);
    }
    vec3 q[3] = vec3[3](p[order[0]], p[order[1]], p[order[2]]);

    // Depth as a function of (x, y) on the triangle's plane, in voxels.
    vec3 pn = cross(q[1] - q[0], q[2] - q[0]);
    vec3 plane = vec3(-pn.x / pn.z, -pn.y / pn.z, q[0].z + (pn.x * q[0].x + pn.y * q[0].y) / pn.z);

    // Edge lines offset outwards by half a pixel diagonal, in pixel units.
    vec3 edge[3];
    for (int i = 0; i < 3; i++) {
        vec2 a = q[i].xy;
        vec2 b = q[(i + 1) % 3].xy;
        vec3 line = cross(vec3(a, 1.0), vec3(b, 1.0));
        line.z += 0.5 * (abs(line.x) + abs(line.y));
        edge[i] = line;
    }
    vec2 lo = min(min(q[0].xy, q[1].xy), q[2].xy) - 0.5;
    vec2 hi = max(max(q[0].xy, q[1].xy), q[2].xy) + 0.5;
    vec2 depth_range = vec2(min(min(q[0].z, q[1].z), q[2].z), max(max(q[0].z, q[1].z), q[2].z));

    // Barycentrics of the dilated vertices extrapolate the attributes.
    float area = (q[1].x - q[0].x) * (q[2].y - q[0].y) - (q[1].y - q[0].y) * (q[2].x - q[0].x);
    for (int i = 0; i < 3; i++) {
        vec3 h = cross(edge[(i + 2) % 3], edge[i]);
        vec2 v = abs(h.z) > 1e-12 ? h.xy / h.z : q[i].xy;
        float b1 = ((v.x - q[0].x) * (q[2].y - q[0].y) - (v.y - q[0].y) * (q[2].x - q[0].x)) / area;
        float b2 = ((q[1].x - q[0].x) * (v.y - q[0].y) - (q[1].y - q[0].y) * (v.x - q[0].x)) / area;
        vec3 bary = vec3(1.0 - b1 - b2, b1, b2);
        if (abs(area) < 1e-12) {
            bary = vec3(i == 0, i == 1, i == 2);
        }
        int s0 = order[0], s1 = order[1], s2 = order[2];
        out_normal = bary.x * in_normal[s0] + bary.y * in_normal[s1] + bary.z * in_normal[s2];
        out_uv = bary.x * in_uv[s0] + bary.y * in_uv[s1] + bary.z * in_uv[s2];
        out_bounds = vec4(lo, hi);
        out_axis = axis;
        out_plane = plane;
        out_depth_range = depth_range;
        float depth = clamp(dot(plane, vec3(v, 1.0)) / n, 0.0, 1.0);
        gl_Position = vec4(v / n * 2.0 - 1.0, depth, 1.0);
        EmitVertex();
    }
    EndPrimitive();
}
