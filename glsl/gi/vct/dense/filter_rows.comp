#version 460
// One level of one direction of the dense grid's directional volumes, filtered by rows
// (`--directional-filter rows`). A cell's value along an axis is what rays along that
// axis see of its voxels: each row of voxels along the axis composited front to back,
// then the rows averaged. The pairs filter (filter.comp, anisotropic.glsl) averages each
// level's children before compositing the next, as if what lies behind were
// uncorrelated with what lies in front; a surface seen edge-on blocks the same rows in
// every child, so it came out 1.3 to 3.6 times as opaque as its voxels at levels 2 to 4,
// whatever the voxels' size (Loubet & Neyret 2018; BENCHMARKS.md, sessions 36 and 37).
// The rows of a level are the rows of the level below composited in pairs along the
// axis, kept in `rows_dst` for the next: rows image texel (c, u, v) is the row at
// across-coordinates (u, v) (the axes after the direction's, in order) through cell c
// along the axis. The directional level is laid out as filter.comp's.
#include "gpu_layout.glsl"
#include "gi/vct/anisotropic.glsl"

layout(local_size_x = VOXEL_GROUP_SIZE, local_size_y = VOXEL_GROUP_SIZE, local_size_z = VOXEL_GROUP_SIZE) in;
layout(set = SET_PASS, binding = BINDING_FILTER_BASE, rgba16f) uniform readonly image3D base_level;
layout(set = SET_PASS, binding = BINDING_FILTER_NORMAL, r32ui) uniform readonly uimage3D voxel_normal;
layout(set = SET_PASS, binding = BINDING_FILTER_ROWS_SRC, rgba16f) uniform readonly image3D rows_src;
layout(set = SET_PASS, binding = BINDING_FILTER_ROWS_DST, rgba16f) uniform writeonly image3D rows_dst;
layout(set = SET_PASS, binding = BINDING_FILTER_DST, rgba16f) uniform writeonly image3D dst;
layout(push_constant) uniform Push {
    FilterRowsPush push;
};

// The half of row `across` through cell `c` (at the level below) at `half_index` along
// the axis: a base voxel seen along direction d, or a row of the level below.
vec4 row_half(int c, ivec2 across, int half_index, int d) {
    int axis = d / 2;
    if (push.level == 0u) {
        ivec3 voxel;
        voxel[axis] = 2 * c + half_index;
        voxel[(axis + 1) % 3] = across.x;
        voxel[(axis + 2) % 3] = across.y;
        return facing(imageLoad(voxel_normal, voxel).r, imageLoad(base_level, voxel), d);
    }
    return imageLoad(rows_src, ivec3(2 * c + half_index, across));
}

void main() {
    int edge = imageSize(dst).y;
    ivec3 cell = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(cell, ivec3(edge)))) {
        return;
    }
    int d = int(push.direction);
    int axis = d / 2;
    // Travelling along +axis meets the half at the lower coordinate first.
    int front = d % 2;
    int width = 2 << push.level;
    int c = cell[axis];
    ivec2 first = ivec2(cell[(axis + 1) % 3], cell[(axis + 2) % 3]) * width;
    vec4 sum = vec4(0.0);
    for (int v = 0; v < width; v++) {
        for (int u = 0; u < width; u++) {
            ivec2 across = first + ivec2(u, v);
            vec4 row = over(row_half(c, across, front, d), row_half(c, across, 1 - front, d));
            imageStore(rows_dst, ivec3(c, across), row);
            sum += row;
        }
    }
    vec4 value = sum / float(width * width);
    ivec3 at = cell + ivec3((4 * d + 1) * edge / 2, 0, 0);
    imageStore(dst, at, value);
    if (cell.x == 0) {
        imageStore(dst, at - ivec3(1, 0, 0), value);
    }
    if (cell.x == edge - 1) {
        imageStore(dst, at + ivec3(1, 0, 0), value);
    }
}
