#version 460
// The probes' gather (Sedláček 2019, 3.3.2): at each reduced-resolution pixel, the
// lightmap read bilinearly at the uv of the G-buffer's triangle there. The receivers
// cover every texel a chart's bilinear footprint reaches (`receivers.rs`), so no seam
// reads an empty texel. Moving meshes have no lightmap: they get no indirect light
// here.
#include "gi/screen/screen.glsl"
#include "gi/probes/probes.glsl"

layout(local_size_x = SCREEN_GROUP_SIZE, local_size_y = SCREEN_GROUP_SIZE) in;
layout(set = SET_SCREEN, binding = BINDING_SCREEN_INDIRECT, rgba16f) uniform writeonly image2D indirect;
layout(set = SET_GI, binding = BINDING_PROBE_LIGHTMAP_SAMPLED) uniform sampler2D lightmap;

// Barycentrics of point p (on it, up to float error) in triangle `tri`.
vec2 barycentrics(RayTriangle tri, vec3 p) {
    vec3 d = p - tri.v0.xyz;
    vec3 e1 = tri.e1.xyz;
    vec3 e2 = tri.e2.xyz;
    float d00 = dot(e1, e1);
    float d01 = dot(e1, e2);
    float d11 = dot(e2, e2);
    float d20 = dot(d, e1);
    float d21 = dot(d, e2);
    float det = d00 * d11 - d01 * d01;
    if (det <= 0.0) {
        return vec2(1.0 / 3.0);
    }
    vec2 bary = vec2(d11 * d20 - d01 * d21, d00 * d21 - d01 * d20) / det;
    // A pixel's centre can lie just past its triangle's edge (the rasterizer's coverage
    // is of the sample point, the depth interpolated): clamp into the triangle.
    bary = max(bary, vec2(0.0));
    float sum = bary.x + bary.y;
    return sum > 1.0 ? bary / sum : bary;
}

void main() {
    ivec2 low = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(low, imageSize(indirect)))) {
        return;
    }
    ivec2 pixel = representative(low);
    float depth = texelFetch(gbuffer_depth, pixel, 0).r;
    uint triangle = imageLoad(gbuffer_triangle, pixel).r;
    vec3 e = vec3(0.0);
    if (!is_sky(depth) && triangle != 0u) {
        uint i = triangle - 1u;
        vec2 bary = barycentrics(ray_triangle(i), pixel_position(pixel, depth));
        vec2 at = lightmap_uv(i, bary);
        if (at.x >= 0.0) {
            e = textureLod(lightmap, at, 0.0).rgb;
        }
    }
    imageStore(indirect, low, vec4(e, 1.0));
}
