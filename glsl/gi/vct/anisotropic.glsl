// One voxel of an anisotropic level from its 2x2x2 children (Crassin 2011; Dřínovský
// 2013, 5.4.3), shared by the dense mip chain and the octree's interior bricks: for each
// direction a cone can travel (+X -X +Y -Y +Z -Z), the children are composited front to
// back along that axis in pairs and the four pairs averaged. Values are premultiplied
// by opacity.
#ifndef ANISOTROPIC_GLSL
#define ANISOTROPIC_GLSL

// The unit normal of a base voxel's packed RGBA8 normal (xyz * 127.5 + 127.5), zero
// where the averaged normals disagree so much that it is shorter than 0.2.
vec3 unit_voxel_normal(uint packed_normal) {
    vec3 n = vec3(float(packed_normal & 0xffu), float((packed_normal >> 8) & 0xffu), float((packed_normal >> 16) & 0xffu)) / 127.5 - 1.0;
    return length(n) < 0.2 ? vec3(0.0) : normalize(n);
}

// A base voxel's surface plane premultiplied by its opacity `a` (PLANE_SLOT): a times
// (unit normal, normal . centre), the voxel `v` of a grid of `n` per axis, its centre in
// grid units less 0.5. Both stores' filters sum these over a cell.
vec4 voxel_plane(float a, uint packed_normal, ivec3 v, float n) {
    vec3 normal = unit_voxel_normal(packed_normal);
    return a * vec4(normal, dot(normal, (vec3(v) + 0.5) / n - 0.5));
}

// Of a base voxel with packed RGBA8 normal `packed_normal`, the part a cone travelling
// along `d` sees: all of it when the cone looks at the voxel's lit face, half of it
// edge-on, none from behind. Opacity is weighted too: without this, a cone leaving a
// surface is lit and occluded by the surface itself from the coarse cell around its
// start. Edge-on, the voxelized slab would cover the whole voxel where the surface
// itself covers none; half stands between. A wall seen edge-on along one axis still
// stops the cones that cross it: they see it face-on along another axis, and
// sample_voxels adds up the optical depths. (With a weighted mean of the opacities
// there, the half weight let light leave rooms.) Nothing edge-on at all (weight 0)
// loses too much: Cornell box LDR-FLIP 0.27.
// A two-sided voxel (its normal's alpha 0, where other voxels count their fragments: a
// slab thinner than the voxel, both of whose faces it holds, inject.comp) blocks cones from either side and shows its light
// only to those that look at its lit face: from behind it is the slab's unlit underside.
vec4 facing(uint packed_normal, vec4 value, int d) {
    vec3 n = unit_voxel_normal(packed_normal);
    if (n == vec3(0.0)) {
        return value;
    }
    vec3 towards_viewer = vec3(0.0);
    towards_viewer[d / 2] = (d % 2 == 0) ? -1.0 : 1.0;
    float c = dot(n, towards_viewer);
    float w = clamp(0.5 + 4.0 * c, 0.0, 1.0);
    if ((packed_normal >> 24) == 0u) {
        return vec4(value.rgb * w, value.a * clamp(0.5 + 4.0 * abs(c), 0.0, 1.0));
    }
    return value * w;
}

vec4 over(vec4 front, vec4 back) {
    return front + (1.0 - front.a) * back;
}

// The children as seen along d, indexed x | y << 1 | z << 2, filtered to one voxel.
vec4 filter_children(vec4 children[8], int d) {
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
            sum += over(children[f.x | (f.y << 1) | (f.z << 2)], children[b.x | (b.y << 1) | (b.z << 2)]);
        }
    }
    return sum * 0.25;
}
#endif
