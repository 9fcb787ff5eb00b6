#version 460
// Projects each triangle along its dominant axis onto a grid-sized viewport and dilates
// it by half a pixel diagonal for conservative coverage (gi/voxelize/triangle.glsl), as
// lavapipe has no VK_EXT_conservative_rasterization. The fragment shader clips to the
// triangle's pixel bounding box.
#include "gi/vct/voxelize/triangle.glsl"

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
layout(location = 7) flat out vec3 out_lines[3];    // the undilated edge lines

void main() {
    ProjectedTriangle t = project_triangle(vec3[3](in_world[0], in_world[1], in_world[2]));
    float n = float(vct.resolution);
    // The dilated vertices, where neighbouring dilated edges meet; their weights
    // extrapolate the attributes.
    for (int i = 0; i < 3; i++) {
        vec3 h = cross(t.edge[(i + 2) % 3], t.edge[i]);
        vec2 v = abs(h.z) > 1e-12 ? h.xy / h.z : t.q[i].xy;
        vec3 w = projected_weights(t, v, i);
        out_normal = w.x * in_normal[0] + w.y * in_normal[1] + w.z * in_normal[2];
        out_uv = w.x * in_uv[0] + w.y * in_uv[1] + w.z * in_uv[2];
        out_bounds = t.bounds;
        out_axis = t.axis;
        out_plane = t.plane;
        out_depth_range = t.depth_range;
        out_lines = vec3[3](undilated(t.edge[0]), undilated(t.edge[1]), undilated(t.edge[2]));
        float depth = clamp(dot(t.plane, vec3(v, 1.0)) / n, 0.0, 1.0);
        gl_Position = vec4(v / n * 2.0 - 1.0, depth, 1.0);
        EmitVertex();
    }
    EndPrimitive();
}
