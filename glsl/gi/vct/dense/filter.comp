#version 460
// One level of the dense grid's anisotropic mip chain (gi/vct/anisotropic.glsl). The
// first level reads the isotropic base; the six directions sit side by side along x,
// direction d's cube of edge `edge` in the middle of a slot 2 * edge wide, starting at
// x = (2d + 1/2) * edge, and with the planes (PLANE_OCCLUSION) the cells' planes and
// coverage after them. The voxel just outside each x face repeats the face's voxel:
// trilinear filtering reads no further (gi/sampling.glsl).
#include "gpu_layout.glsl"
#include "gi/vct/anisotropic.glsl"

layout(local_size_x = VOXEL_GROUP_SIZE, local_size_y = VOXEL_GROUP_SIZE, local_size_z = VOXEL_GROUP_SIZE) in;
layout(set = SET_PASS, binding = BINDING_FILTER_BASE, rgba16f) uniform readonly image3D base_level;
layout(set = SET_PASS, binding = BINDING_FILTER_SRC, rgba16f) uniform readonly image3D src;
layout(set = SET_PASS, binding = BINDING_FILTER_DST, rgba16f) uniform writeonly image3D dst;
layout(set = SET_PASS, binding = BINDING_FILTER_NORMAL, r32ui) uniform readonly uimage3D voxel_normal;
layout(push_constant) uniform Push {
    FilterPush push;
};

// Child voxel `child` (cube coordinates at the level below) as seen along direction d.
vec4 load(ivec3 child, int d, int child_edge) {
    if (push.level == 0u) {
        return facing(imageLoad(voxel_normal, child).r, imageLoad(base_level, child), d);
    }
    return imageLoad(src, child + ivec3((4 * d + 1) * child_edge / 2, 0, 0));
}

// The cell's surface plane and coverage (PLANE_SLOT, COVERAGE_SLOT): the
// mean over its eight children, from the base voxels' opacity, normal and centre at the
// first level. Premultiplied by opacity, so that a plane read between cells, or between
// levels, is the same plane whatever the blend: plane.xyz / |plane.xyz| its normal and
// plane.w / |plane.xyz| its constant.
void filter_plane(ivec3 first, int edge, out vec4 plane, out float coverage) {
    plane = vec4(0.0);
    coverage = 0.0;
    float n = float(imageSize(base_level).y);
    for (int i = 0; i < 8; i++) {
        ivec3 child = first + ivec3(i & 1, (i >> 1) & 1, i >> 2);
        if (push.level == 0u) {
            float a = imageLoad(base_level, child).a;
            plane += voxel_plane(a, imageLoad(voxel_normal, child).r, child, n);
            coverage += a;
        } else {
            plane += imageLoad(src, child + ivec3((4 * int(PLANE_SLOT) + 1) * edge, 0, 0));
            coverage += imageLoad(src, child + ivec3((4 * int(COVERAGE_SLOT) + 1) * edge, 0, 0)).r;
        }
    }
    plane *= 0.125;
    coverage *= 0.125;
}

// Stores `value` at `parent` of slot `slot`, and in the margin beside the cube's x faces.
void store_slot(ivec3 parent, int edge, int slot, vec4 value) {
    ivec3 at = parent + ivec3((4 * slot + 1) * edge / 2, 0, 0);
    imageStore(dst, at, value);
    if (parent.x == 0) {
        imageStore(dst, at - ivec3(1, 0, 0), value);
    }
    if (parent.x == edge - 1) {
        imageStore(dst, at + ivec3(1, 0, 0), value);
    }
}

void main() {
    int edge = imageSize(dst).y;
    ivec3 parent = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(parent, ivec3(edge)))) {
        return;
    }
    ivec3 first = parent * 2;
    for (int d = 0; d < 6; d++) {
        vec4 children[8];
        for (int i = 0; i < 8; i++) {
            children[i] = load(first + ivec3(i & 1, (i >> 1) & 1, i >> 2), d, edge * 2);
        }
        store_slot(parent, edge, d, filter_children(children, d));
    }
    if (push.planes != 0u) {
        vec4 plane;
        float coverage;
        filter_plane(first, edge, plane, coverage);
        store_slot(parent, edge, int(PLANE_SLOT), plane);
        store_slot(parent, edge, int(COVERAGE_SLOT), vec4(coverage, 0.0, 0.0, 0.0));
    }
}
