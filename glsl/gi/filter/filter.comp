#version 460
// One level of the anisotropic mip chain (Crassin 2011; Dřínovský 2013 §5.5): for each
// direction a cone can travel (+X -X +Y -Y +Z -Z), the 2x2x2 children are composited
// front to back along that axis in pairs and the four pairs averaged. Values are
// premultiplied by opacity. The first level reads the isotropic base; the six directions
// sit side by side along x, direction d's cube at x offset d * edge.
#include "gpu_layout.glsl"

layout(local_size_x = VOXEL_GROUP_SIZE, local_size_y = VOXEL_GROUP_SIZE, local_size_z = VOXEL_GROUP_SIZE) in;
layout(set = SET_PASS, binding = BINDING_FILTER_BASE, rgba16f) uniform readonly image3D base_level;
layout(set = SET_PASS, binding = BINDING_FILTER_SRC, rgba16f) uniform readonly image3D src;
layout(set = SET_PASS, binding = BINDING_FILTER_DST, rgba16f) uniform writeonly image3D dst;
layout(set = SET_PASS, binding = BINDING_FILTER_NORMAL, r32ui) uniform readonly uimage3D voxel_normal;
layout(push_constant) uniform FilterPush {
    uint level;
};

// Of a base voxel, the part a cone travelling along `d` sees: all of it when the cone
// looks at the voxel's lit face, half of it edge-on, none from behind. Opacity is
// weighted too: without this, a cone leaving a surface is lit and occluded by the
// surface itself from the coarse cell around its start. Edge-on, the voxelized slab
// would cover the whole voxel where the surface itself covers none; half stands between.
// A wall seen edge-on along one axis still stops the cones that cross it: they see it
// face-on along another axis, and sample_voxels adds up the optical depths. (With a
// weighted mean of the opacities there, the half weight let light leak out of rooms.)
// Nothing edge-on at all (weight 0) loses too much: Cornell box LDR-FLIP 0.27.
vec4 facing(ivec3 voxel, vec4 value, int d) {
    uint packed_normal = imageLoad(voxel_normal, voxel).r;
    vec3 n = vec3(float(packed_normal & 0xffu), float((packed_normal >> 8) & 0xffu), float((packed_normal >> 16) & 0xffu)) / 127.5 - 1.0;
    if (length(n) < 0.2) {
        return value;
    }
    vec3 towards_viewer = vec3(0.0);
    towards_viewer[d / 2] = (d % 2 == 0) ? -1.0 : 1.0;
    float w = clamp(0.5 + 4.0 * dot(normalize(n), towards_viewer), 0.0, 1.0);
    return value * w;
}

vec4 over(vec4 front, vec4 back) {
    return front + (1.0 - front.a) * back;
}

// Child voxel `child` (cube coordinates at the level below) as seen along direction d.
vec4 load(ivec3 child, int d, int child_edge) {
    if (level == 0u) {
        return facing(child, imageLoad(base_level, child), d);
    }
    return imageLoad(src, child + ivec3(d * child_edge, 0, 0));
}

void main() {
    int edge = imageSize(dst).y;
    ivec3 parent = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(parent, ivec3(edge)))) {
        return;
    }
    ivec3 first = parent * 2;
    for (int d = 0; d < 6; d++) {
        int axis = d / 2;
        // Travelling along +axis meets the child at offset 0 first.
        int front = (d % 2 == 0) ? 0 : 1;
        vec4 sum = vec4(0.0);
        for (int u = 0; u < 2; u++) {
            for (int v = 0; v < 2; v++) {
                ivec3 f = ivec3(0);
                f[(axis + 1) % 3] = u;
                f[(axis + 2) % 3] = v;
                ivec3 b = f;
                f[axis] = front;
                b[axis] = 1 - front;
                sum += over(load(first + f, d, edge * 2), load(first + b, d, edge * 2));
            }
        }
        imageStore(dst, parent + ivec3(d * edge, 0, 0), sum * 0.25);
    }
}
