#version 460
// Compute voxelization: workgroups along x for the triangles of the mesh in the push
// constants, along y for shares of a large triangle's pixels (the host sizes them by the
// mesh's longest edge). The lanes walk the pixels of the triangle's dilated axis
// projection (gi/voxelize/triangle.glsl) and cover each pixel whose centre lies inside,
// as the rasterizer's fragments do (gi/voxelize/coverage.glsl), with the attributes
// interpolated there and the textures sampled over the pixel's footprint. On GPUs that
// draw with few units (an H100) this is much faster than the rasterizer. The dense grid
// adds to its fragment sums, the octree appends to its voxel-fragment list.
// variant: OCTREE
#define MATERIAL_GRADIENTS
#define SUBGROUP_APPEND
#ifdef OCTREE
#include "gi/vct/octree/fragments/store_fragment.glsl"
#else
#include "gi/vct/voxelize/store_sums.glsl"
#endif
#include "gi/vct/voxelize/triangle.glsl"
#include "gi/vct/voxelize/coverage.glsl"

layout(local_size_x = VOXELIZE_GROUP_SIZE) in;
// The scene's vertices (position, normal, uv: 8 floats each) and indices.
layout(set = SET_GI, binding = BINDING_VCT_VERTICES, std430) readonly buffer VertexBlock {
    float vertex_data[];
};
layout(set = SET_GI, binding = BINDING_VCT_INDICES, std430) readonly buffer IndexBlock {
    uint vertex_indices[];
};

void main() {
    vec3 world[3];
    vec3 normal[3];
    vec2 uv[3];
    mat3 normal_matrix = transpose(inverse(mat3(draw.model)));
    for (int i = 0; i < 3; i++) {
        uint v = 8u * (vertex_indices[draw.first_index + 3u * gl_WorkGroupID.x + uint(i)] + draw.vertex_offset);
        world[i] = (draw.model * vec4(vertex_data[v], vertex_data[v + 1u], vertex_data[v + 2u], 1.0)).xyz;
        normal[i] = normal_matrix * vec3(vertex_data[v + 3u], vertex_data[v + 4u], vertex_data[v + 5u]);
        uv[i] = vec2(vertex_data[v + 6u], vertex_data[v + 7u]);
    }
    ProjectedTriangle t = project_triangle(world);
    if (abs(t.area) < DEGENERATE_AREA) {
        return;
    }
    // The weights are affine in the pixel position: uv changes by these per pixel.
    vec3 w0 = projected_weights(t, vec2(0.0), 0);
    vec3 wx = projected_weights(t, vec2(1.0, 0.0), 0) - w0;
    vec3 wy = projected_weights(t, vec2(0.0, 1.0), 0) - w0;
    material_dx = wx.x * uv[0] + wx.y * uv[1] + wx.z * uv[2];
    material_dy = wy.x * uv[0] + wy.y * uv[1] + wy.z * uv[2];

    // The pixels whose centres lie in the bounds, on the grid.
    ivec2 lo = max(ivec2(ceil(t.bounds.xy - 0.5)), ivec2(0));
    ivec2 hi = min(ivec2(floor(t.bounds.zw - 0.5)), ivec2(int(vct.resolution) - 1));
    if (any(lessThan(hi, lo))) {
        return;
    }
    vec3 lines[3] = vec3[3](undilated(t.edge[0]), undilated(t.edge[1]), undilated(t.edge[2]));
    uint width = uint(hi.x - lo.x + 1);
    uint pixels = width * uint(hi.y - lo.y + 1);
    // A large triangle's pixels are shared among the workgroups along y.
    uint lanes = VOXELIZE_GROUP_SIZE * gl_NumWorkGroups.y;
    for (uint k = gl_WorkGroupID.y * VOXELIZE_GROUP_SIZE + gl_LocalInvocationID.x; k < pixels; k += lanes) {
        vec2 pixel = vec2(lo + ivec2(k % width, k / width)) + 0.5;
        vec3 p = vec3(pixel, 1.0);
        // Centres on an edge count (the rasterizer takes some by its tie rule).
        if (dot(t.edge[0], p) < 0.0 || dot(t.edge[1], p) < 0.0 || dot(t.edge[2], p) < 0.0) {
            continue;
        }
        vec3 w = projected_weights(t, pixel, 0);
        cover_pixel(pixel, w.x * normal[0] + w.y * normal[1] + w.z * normal[2],
                    w.x * uv[0] + w.y * uv[1] + w.z * uv[2], t.bounds, t.axis, t.plane, t.depth_range, lines);
    }
}
