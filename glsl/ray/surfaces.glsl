// The scene's triangles and materials as the GPU passes that shade a point of a triangle
// read them (`src/ray/surfaces.rs`): set 3's bindings `BINDING_RAY_TRIANGLES` to
// `BINDING_RAY_TEXTURES`.
// Triangle i is texel 3i of the triangle buffer and 4i of the shading buffer, in the order
// of the set's buffers: the BVH's leaf order where rays are cast (`ray/rays.glsl`), the
// scene's own where a pass looks triangles up by their index in the scene (the probes).
#ifndef SURFACES_GLSL
#define SURFACES_GLSL
#include "gpu_layout.glsl"

// Every buffer rays read is a texel buffer, each struct a few uvec4 texels: traversal
// reads them at every step, and a CPU driver fetches texels for all SIMD lanes at once,
// where it loads a storage buffer one lane and one word at a time (Mesa's gallivm
// bounds-checks each); GPUs cache texel fetches well too (Aila & Laine 2009).
layout(set = SET_GI, binding = BINDING_RAY_TRIANGLES) uniform usamplerBuffer ray_triangle_texels;
layout(set = SET_GI, binding = BINDING_RAY_SHADING) uniform usamplerBuffer ray_shading_texels;
layout(set = SET_GI, binding = BINDING_RAY_MATERIALS) uniform usamplerBuffer ray_material_texels;
layout(set = SET_GI, binding = BINDING_RAY_ATLAS) uniform sampler2D texture_atlas;
layout(set = SET_GI, binding = BINDING_RAY_TEXTURES) uniform usamplerBuffer texture_rects;

GpuMaterial ray_material(uint i) {
    int at = int(4u * i);
    uvec4 textures = texelFetch(ray_material_texels, at + 3);
    return GpuMaterial(uintBitsToFloat(texelFetch(ray_material_texels, at)),
                       uintBitsToFloat(texelFetch(ray_material_texels, at + 1)),
                       uintBitsToFloat(texelFetch(ray_material_texels, at + 2)), textures.x,
                       textures.y, textures.z, textures.w);
}

RayTriangle ray_triangle(uint i) {
    int at = int(3u * i);
    return RayTriangle(uintBitsToFloat(texelFetch(ray_triangle_texels, at)),
                       uintBitsToFloat(texelFetch(ray_triangle_texels, at + 1)),
                       uintBitsToFloat(texelFetch(ray_triangle_texels, at + 2)));
}

RayShading ray_shading(uint i) {
    int at = int(4u * i);
    return RayShading(uintBitsToFloat(texelFetch(ray_shading_texels, at)),
                      uintBitsToFloat(texelFetch(ray_shading_texels, at + 1)),
                      uintBitsToFloat(texelFetch(ray_shading_texels, at + 2)),
                      uintBitsToFloat(texelFetch(ray_shading_texels, at + 3)));
}

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
    uvec4 rect = texelFetch(texture_rects, int(index));
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
    RayShading s = ray_shading(i);
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

#endif
