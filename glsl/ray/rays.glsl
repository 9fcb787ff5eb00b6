// Scene ray casting (`src/ray/`): the first bindings of a set 3 that casts rays. Two BVH2s
// over the scene's triangles (the static meshes', built once, and the moving meshes',
// built every frame), traversed here: the closest hit, or any hit for visibility. Cut-out
// materials (map_d; d < 1 where the light passes straight) let rays through where their coverage is below one half, as
// the shadow maps and voxels count them; or, for a ray given a `cut_seed`, with the
// probability 1 - coverage, as the path-traced references' Mitsuba masks do, or never
// (`RAY_OPAQUE`: the references' shadow rays ignore the masks).
#ifndef RAYS_GLSL
#define RAYS_GLSL
#include "gpu_layout.glsl"
#include "common/random.glsl"

layout(set = SET_GI, binding = BINDING_RAY_UNIFORMS) uniform RayBlock {
    RayUniforms rays;
};
layout(set = SET_GI, binding = BINDING_RAY_NODES, std430) readonly buffer RayNodeBlock {
    BvhNode bvh_nodes[];
};
layout(set = SET_GI, binding = BINDING_RAY_TRIANGLES, std430) readonly buffer RayTriangleBlock {
    RayTriangle ray_triangles[];
};
layout(set = SET_GI, binding = BINDING_RAY_SHADING, std430) readonly buffer RayShadingBlock {
    RayShading ray_shading[];
};
layout(set = SET_GI, binding = BINDING_RAY_MATERIALS, std430) readonly buffer RayMaterialBlock {
    GpuMaterial ray_materials[];
};
layout(set = SET_GI, binding = BINDING_RAY_ATLAS) uniform sampler2D texture_atlas;
layout(set = SET_GI, binding = BINDING_RAY_TEXTURES, std430) readonly buffer RayTextureBlock {
    uvec4 texture_rects[];
};
layout(set = SET_GI, binding = BINDING_RAY_EMITTERS, std430) readonly buffer RayEmitterBlock {
    RayEmitter emitters[];
};

// Where a ray met a triangle: the triangle (in `ray_triangles`), the distance, and the
// barycentric coordinates of its second and third vertices.
struct Hit {
    uint triangle;
    float t;
    vec2 bary;
};

// One texel of a texture, wrapping around its edges (the materials' sampler repeats).
vec4 texture_texel(uvec4 rect, ivec2 p) {
    ivec2 size = ivec2(rect.zw);
    ivec2 q = ((p % size) + size) % size;
    return texelFetch(texture_atlas, ivec2(rect.xy) + q, 0);
}

// The exact sRGB decoding of the materials' hardware sampler.
vec3 srgb_to_linear(vec3 c) {
    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));
}

// Texture `index` at `uv`, bilinear between texel centres, wrapping around; sRGB-decoded
// before the blend where `srgb` (albedo), as hardware sampling of an sRGB image does.
vec4 texture_bilinear(uint index, vec2 uv, bool srgb) {
    uvec4 rect = texture_rects[index];
    vec2 at = uv * vec2(rect.zw) - 0.5;
    ivec2 base = ivec2(floor(at));
    vec2 f = at - vec2(base);
    vec4 sum = vec4(0.0);
    for (int k = 0; k < 4; k++) {
        ivec2 corner = ivec2(k & 1, k >> 1);
        vec4 texel = texture_texel(rect, base + corner);
        if (srgb) {
            texel.rgb = srgb_to_linear(texel.rgb);
        }
        float w = (corner.x == 0 ? 1.0 - f.x : f.x) * (corner.y == 0 ? 1.0 - f.y : f.y);
        sum += w * texel;
    }
    return sum;
}

// The uv of triangle `i` at barycentric coordinates `bary`.
vec2 triangle_uv(uint i, vec2 bary) {
    RayShading s = ray_shading[i];
    vec2 uv0 = vec2(s.n0.w, s.n1.w);
    vec2 uv1 = vec2(s.n2.w, s.uv.x);
    vec2 uv2 = s.uv.yz;
    return uv0 * (1.0 - bary.x - bary.y) + uv1 * bary.x + uv2 * bary.y;
}

// Whether light passing a material bends (d < 1, Ni > 1; `Material::refracts`): its
// d is then left to the shading, which refracts the light that passes.
bool material_refracts(GpuMaterial m) {
    return m.albedo.a < 1.0 && m.emission.a > 1.0;
}

// Whether triangle `i`, hit at `bary`, lets the ray through: a cut-out material with its
// coverage (d x map_d, map_d alone where it refracts) below one half there (`cut_seed` 0), below a number drawn for this
// ray and triangle (another seed), or never (`RAY_OPAQUE`).
bool cut_out(uint i, vec2 bary, uint cut_seed) {
    RayTriangle tri = ray_triangles[i];
    if ((floatBitsToUint(tri.e2.w) & RAY_CUT_OUT) == 0u || cut_seed == RAY_OPAQUE) {
        return false;
    }
    GpuMaterial m = ray_materials[floatBitsToUint(tri.v0.w)];
    float coverage = material_refracts(m) ? 1.0 : m.albedo.a;
    if (m.coverage_texture != NO_TEXTURE) {
        coverage *= texture_bilinear(m.coverage_texture, triangle_uv(i, bary), false).r;
    }
    float threshold = cut_seed == 0u ? 0.5 : float(pcg_hash(cut_seed ^ i) >> 8u) * (1.0 / 16777216.0);
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

// The distance at which the ray enters box `n` within (tmin, tmax) (slab test), infinity
// where it does not.
float enter_box(BvhNode n, vec3 origin, vec3 inv_dir, float tmin, float tmax) {
    vec3 lo = (n.min_escape.xyz - origin) * inv_dir;
    vec3 hi = (n.max_leaf.xyz - origin) * inv_dir;
    vec3 near = min(lo, hi);
    vec3 far = max(lo, hi);
    float enter = max(max(near.x, near.y), max(near.z, tmin));
    float leave = min(min(far.x, far.y), min(far.z, tmax));
    return enter <= leave ? enter : uintBitsToFloat(0x7f800000u);
}

// Walks the BVH rooted at `root`, the nearer child first (an inner node's first child
// follows it, and its second is the node after the first's subtree: the first's
// escape), the farther ones on a stack: the closest hit before `hit.t` (which it lowers),
// or with `any`, the first one found. Returns whether it found one.
bool traverse(uint root, vec3 origin, vec3 dir, float tmin, bool any, uint cut_seed, inout Hit hit) {
    if (root == RAY_NONE) {
        return false;
    }
    // A direction component of exactly zero divides to an infinity of the right sign.
    vec3 inv_dir = 1.0 / dir;
    uint stack[RAY_STACK_SIZE];
    float stack_t[RAY_STACK_SIZE];
    int top = 0;
    bool found = false;
    uint node = root;
    BvhNode n = bvh_nodes[node];
    if (enter_box(n, origin, inv_dir, tmin, hit.t) > hit.t) {
        return false;
    }
    while (true) {
        uint leaf = floatBitsToUint(n.max_leaf.w);
        if (leaf != 0u) {
            uint first = leaf & ((1u << RAY_LEAF_FIRST_BITS) - 1u);
            uint count = leaf >> RAY_LEAF_FIRST_BITS;
            for (uint i = first; i < first + count; i++) {
                float t;
                vec2 bary;
                if (intersect_triangle(ray_triangles[i], origin, dir, tmin, hit.t, t, bary) && !cut_out(i, bary, cut_seed)) {
                    hit.triangle = i;
                    hit.t = t;
                    hit.bary = bary;
                    found = true;
                    if (any) {
                        return true;
                    }
                }
            }
        } else {
            uint a = node + 1u;
            BvhNode na = bvh_nodes[a];
            uint b = floatBitsToUint(na.min_escape.w);
            BvhNode nb = bvh_nodes[b];
            float ta = enter_box(na, origin, inv_dir, tmin, hit.t);
            float tb = enter_box(nb, origin, inv_dir, tmin, hit.t);
            if (tb < ta) {
                uint swap_node = a;
                a = b;
                b = swap_node;
                BvhNode swap_box = na;
                na = nb;
                nb = swap_box;
                float swap_t = ta;
                ta = tb;
                tb = swap_t;
            }
            if (ta <= hit.t) {
                // The BVHs are shallower than the stack (checked when built).
                if (tb <= hit.t) {
                    stack[top] = b;
                    stack_t[top] = tb;
                    top++;
                }
                node = a;
                n = na;
                continue;
            }
        }
        // The next box on the stack the ray still enters before the closest hit so far.
        bool next = false;
        while (top > 0) {
            top--;
            if (stack_t[top] <= hit.t) {
                node = stack[top];
                n = bvh_nodes[node];
                next = true;
                break;
            }
        }
        if (!next) {
            break;
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
    found = traverse(rays.moving_root, origin, dir, tmin, false, cut_seed, hit) || found;
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
           traverse(rays.moving_root, origin, dir, tmin, true, cut_seed, hit);
}
#endif
