// Scene ray casting (`src/ray/`): the first bindings of a set 3 that casts rays. Two
// compressed eight-wide BVHs (CWBVH) over the scene's triangles (the static meshes',
// built once, and the moving meshes', built every frame), traversed here: the closest
// hit, or any hit for visibility. Cut-out materials (map_d; d < 1 where the light passes
// straight) let rays through where their coverage is below one half, as the shadow maps
// and voxels count them; or, for a ray given a `cut_seed`, with the probability
// 1 - coverage, as the path-traced references' Mitsuba masks do, or never (`RAY_OPAQUE`:
// the references' shadow rays ignore the masks).
#ifndef RAYS_GLSL
#define RAYS_GLSL
#include "gpu_layout.glsl"
#include "common/random.glsl"
#include "ray/surfaces.glsl"

// The scene's features (`RayFeatures`): without cut-outs the traversal has no coverage to
// look up, without moving meshes no second BVH to walk.
layout(constant_id = SPEC_RAY_CUT_OUTS) const bool RAY_CUT_OUTS = true;
layout(constant_id = SPEC_RAY_MOVING) const bool RAY_MOVING_MESHES = true;

layout(set = SET_GI, binding = BINDING_RAY_UNIFORMS) uniform RayBlock {
    RayUniforms rays;
};
layout(set = SET_GI, binding = BINDING_RAY_NODES) uniform usamplerBuffer ray_node_texels;
layout(set = SET_GI, binding = BINDING_RAY_EMITTERS) uniform usamplerBuffer ray_emitter_texels;

RayEmitter ray_emitter(uint i) {
    uvec4 texel = texelFetch(ray_emitter_texels, int(i));
    return RayEmitter(texel.x, uintBitsToFloat(texel.y), texel.z, texel.w);
}

BvhNode bvh_node(uint i) {
    int at = int(5u * i);
    return BvhNode(texelFetch(ray_node_texels, at), texelFetch(ray_node_texels, at + 1),
                   texelFetch(ray_node_texels, at + 2), texelFetch(ray_node_texels, at + 3),
                   texelFetch(ray_node_texels, at + 4));
}

// Where a ray met a triangle: the triangle (its index for `ray_triangle`), the distance, and the
// barycentric coordinates of its second and third vertices.
struct Hit {
    uint triangle;
    float t;
    vec2 bary;
};

// Whether triangle `i` (`tri`), hit at `bary`, lets the ray through: a cut-out material with its
// coverage (d x map_d, map_d alone where it refracts) below one half there (`cut_seed`
// 0), below a number drawn for this ray and triangle (another seed), or never
// (`RAY_OPAQUE`).
bool cut_out(uint i, RayTriangle tri, vec2 bary, uint cut_seed) {
    if ((floatBitsToUint(tri.e2.w) & RAY_CUT_OUT) == 0u || cut_seed == RAY_OPAQUE) {
        return false;
    }
    GpuMaterial m = ray_material(floatBitsToUint(tri.v0.w));
    float coverage = material_refracts(m) ? 1.0 : m.albedo.a;
    if (m.coverage_texture != NO_TEXTURE) {
        coverage *= texture_bilinear(m.coverage_texture, triangle_uv(i, bary), false).r;
    }
    // Drawn for the triangle's index in the scene, not in the BVH's leaf order: the same
    // decisions whatever the BVH's build (the moving meshes' is rebuilt every frame).
    uint scene_index = floatBitsToUint(tri.e1.w);
    float threshold = cut_seed == 0u ? 0.5 : float(pcg_hash(cut_seed ^ scene_index) >> 8u) * (1.0 / 16777216.0);
    return coverage < threshold;
}

// Moeller-Trumbore: the distance to triangle `tri` along the ray and the barycentric
// coordinates of the hit, if it lies in (tmin, tmax). The CPU twin (`src/ray/tests.rs`)
// computes the same expressions.
bool intersect_triangle(RayTriangle tri, vec3 origin, vec3 dir, float tmin, float tmax, out float t,
                        out vec2 bary) {
    vec3 e1 = tri.e1.xyz;
    vec3 e2 = tri.e2.xyz;
    vec3 p = cross(dir, e2);
    float det = dot(e1, p);
    if (det == 0.0) {
        return false;
    }
    float inv = 1.0 / det;
    vec3 s = origin - tri.v0.xyz;
    float u = dot(s, p) * inv;
    if (u < 0.0 || u > 1.0) {
        return false;
    }
    vec3 q = cross(s, e1);
    float v = dot(dir, q) * inv;
    if (v < 0.0 || u + v > 1.0) {
        return false;
    }
    t = dot(e2, q) * inv;
    bary = vec2(u, v);
    return t > tmin && t < tmax;
}

// The ray's octant, a bit per axis where the direction is not negative, in each byte:
// it orders a node's children near to far (obvhs orders each node's slots by octant).
uint octant_inv4(vec3 dir) {
    return (dir.x < 0.0 ? 0u : 0x04040404u) | (dir.y < 0.0 ? 0u : 0x02020202u) |
           (dir.z < 0.0 ? 0u : 0x01010101u);
}

// Byte `k` of the eight in `pair`.
uint byte_of(uvec2 pair, uint k) {
    return ((k < 4u ? pair.x : pair.y) >> (8u * (k & 3u))) & 0xffu;
}

// The children of node `n` the ray enters within (tmin, tmax), as the CWBVH traversal
// takes them (Ylitie et al. 2017, obvhs's `CwBvhNode::intersect_ray`): for an inner child
// a bit in the top byte, at its slot + 24 permuted by the octant (higher: nearer); for a
// leaf its triangles' bits in the low 24, from its first one's offset. The quantized
// boxes enclose the exact ones, so no hit is lost.
uint intersect_children(BvhNode n, vec3 origin, vec3 inv_dir, float tmin, float tmax, uint oct_inv4) {
    uvec3 exponents = (uvec3(n.origin_scale.w) >> uvec3(0u, 8u, 16u)) & 0xffu;
    vec3 scale = uintBitsToFloat(exponents << 23u) * inv_dir;
    vec3 shift = (uintBitsToFloat(n.origin_scale.xyz) - origin) * inv_dir;
    bvec3 negative = lessThan(inv_dir, vec3(0.0));
    uint hits = 0u;
    for (uint part = 0u; part < 2u; part++) {
        uint meta4 = part == 0u ? n.children.z : n.children.w;
        // An inner child's meta byte is 001 then its slot + 24: the only bytes with both
        // bits 4 and 3 set.
        uint inner4 = ((meta4 & (meta4 << 1u)) & 0x10101010u) >> 4u;
        uint bit_index4 = (meta4 ^ (oct_inv4 & (inner4 * 0xffu))) & 0x1f1f1f1fu;
        uint child_bits4 = (meta4 >> 5u) & 0x07070707u;
        for (uint j = 0u; j < 4u; j++) {
            uint k = 4u * part + j;
            vec3 lo = vec3(byte_of(n.bounds_x.xy, k), byte_of(n.bounds_y.xy, k), byte_of(n.bounds_z.xy, k));
            vec3 hi = vec3(byte_of(n.bounds_x.zw, k), byte_of(n.bounds_y.zw, k), byte_of(n.bounds_z.zw, k));
            vec3 near = mix(lo, hi, negative) * scale + shift;
            vec3 far = mix(hi, lo, negative) * scale + shift;
            float enter = max(max(near.x, near.y), max(near.z, tmin));
            float leave = min(min(far.x, far.y), min(far.z, tmax));
            if (enter <= leave) {
                uint shift_by = 8u * j;
                hits |= ((child_bits4 >> shift_by) & 0xffu) << ((bit_index4 >> shift_by) & 0xffu);
            }
        }
    }
    return hits;
}

// Walks the CWBVH rooted at `root` (obvhs's `traverse!`): a group is a node's children
// the ray enters (x: the first inner child, y: their hit bits and the inner mask), taken
// nearest first; the rest of a group waits on the stack while one child is walked. The
// closest hit before `hit.t` (which it lowers), or with `any`, the first one found.
// Returns whether it found one.
bool traverse(uint root, vec3 origin, vec3 dir, float tmin, bool any, uint cut_seed, inout Hit hit) {
    if (root == RAY_NONE) {
        return false;
    }
    // A direction component of exactly zero divides to an infinity of the right sign.
    vec3 inv_dir = 1.0 / dir;
    uint oct_inv4 = octant_inv4(dir);
    uvec2 stack[RAY_STACK_SIZE];
    int top = 0;
    bool found = false;
    // The root as the only inner child of a group at `root`.
    uvec2 nodes = uvec2(root, 0x80000000u);
    uvec2 triangles = uvec2(0u);
    // A cut-out triangle the ray meets leaves the walk, to have its coverage looked up
    // outside it and the walk resumed where it left off: a CPU driver runs the lookup's
    // code at every step of the loop it sits in, whether any lane needs it or not (in the
    // walk's loop it took half of Sponza's path-tracing time).
    while (true) {
        bool pending = false;
        Hit candidate;
        while (true) {
            while (triangles.y != 0u) {
                uint k = uint(findMSB(triangles.y));
                triangles.y &= ~(1u << k);
                uint i = triangles.x + k;
                float t;
                vec2 bary;
                RayTriangle tri = ray_triangle(i);
                if (intersect_triangle(tri, origin, dir, tmin, hit.t, t, bary)) {
                    if (RAY_CUT_OUTS && (floatBitsToUint(tri.e2.w) & RAY_CUT_OUT) != 0u) {
                        candidate = Hit(i, t, bary);
                        pending = true;
                        break;
                    }
                    hit = Hit(i, t, bary);
                    found = true;
                    if (any) {
                        return true;
                    }
                }
            }
            if (RAY_CUT_OUTS && pending) {
                break;
            }
            if ((nodes.y & 0xff000000u) != 0u) {
                uint group = nodes.y;
                uint bit = uint(findMSB(group));
                nodes.y &= ~(1u << bit);
                if ((nodes.y & 0xff000000u) != 0u) {
                    // The BVHs are shallower than the stack (checked when built).
                    stack[top] = nodes;
                    top++;
                }
                // The child's slot, and its place among the node's inner children.
                uint slot = (bit - 24u) ^ (oct_inv4 & 0xffu);
                uint child = nodes.x + bitCount(group & ~(0xffffffffu << slot));
                BvhNode n = bvh_node(child);
                uint hits = intersect_children(n, origin, inv_dir, tmin, hit.t, oct_inv4);
                nodes = uvec2(n.children.x, (hits & 0xff000000u) | (n.origin_scale.w >> 24u));
                triangles = uvec2(n.children.y, hits & 0x00ffffffu);
            } else {
                nodes = uvec2(0u);
            }
            if (triangles.y == 0u && (nodes.y & 0xff000000u) == 0u) {
                if (top == 0) {
                    break;
                }
                top--;
                nodes = stack[top];
            }
        }
        if (!RAY_CUT_OUTS || !pending) {
            break;
        }
        // Met before any hit since: still the nearest.
        if (!cut_out(candidate.triangle, ray_triangle(candidate.triangle), candidate.bary, cut_seed)) {
            hit = candidate;
            found = true;
            if (any) {
                return true;
            }
        }
    }
    return found;
}

// The closest hit along the ray within (tmin, tmax); `cut_seed` as `cut_out` takes it.
bool trace_closest(vec3 origin, vec3 dir, float tmin, float tmax, uint cut_seed, out Hit hit) {
    hit.triangle = RAY_NONE;
    hit.t = tmax;
    hit.bary = vec2(0.0);
    bool found = traverse(rays.static_root, origin, dir, tmin, false, cut_seed, hit);
    if (RAY_MOVING_MESHES) {
        found = traverse(rays.moving_root, origin, dir, tmin, false, cut_seed, hit) || found;
    }
    return found;
}

// Whether anything lies along the ray within (tmin, tmax); `cut_seed` as `cut_out` takes
// it.
bool trace_any(vec3 origin, vec3 dir, float tmin, float tmax, uint cut_seed) {
    Hit hit;
    hit.triangle = RAY_NONE;
    hit.t = tmax;
    hit.bary = vec2(0.0);
    return traverse(rays.static_root, origin, dir, tmin, true, cut_seed, hit) ||
           (RAY_MOVING_MESHES && traverse(rays.moving_root, origin, dir, tmin, true, cut_seed, hit));
}
#endif
