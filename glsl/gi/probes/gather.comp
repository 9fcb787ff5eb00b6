#version 460
// The probes' gather (Sedláček 2019, 3.3.2): at each reduced-resolution pixel, the
// lightmap read bilinearly at the uv of the G-buffer's triangle there, at the level its
// distance from the camera gives (4.2.4). The receivers
// cover every texel a chart's bilinear footprint reaches (`receivers.rs`), so no seam
// reads an empty texel. Moving meshes have no lightmap: they read the grid of spatial
// receivers (4.1.2) at their position, its six directions weighted by the normal. The
// probes' own debug views write the screen radiance instead (at scale 1, each
// reduced-resolution pixel is a pixel).
#include "gi/screen/screen.glsl"
#include "gi/probes/probes.glsl"

layout(local_size_x = SCREEN_GROUP_SIZE, local_size_y = SCREEN_GROUP_SIZE) in;
layout(set = SET_SCREEN, binding = BINDING_SCREEN_INDIRECT, rgba16f) uniform writeonly image2D indirect;
layout(set = SET_GI, binding = BINDING_PROBE_LIGHTMAP_SAMPLED) uniform sampler2D lightmap;
layout(set = SET_GI, binding = BINDING_PROBE_GRID_SAMPLED) uniform sampler3D grid;
layout(set = SET_SCREEN, binding = BINDING_SCREEN_RADIANCE, rgba32f) uniform writeonly image2D screen_radiance;
layout(set = SET_GI, binding = BINDING_PROBE_TEXEL_CLUSTERS) uniform usamplerBuffer texel_clusters;
layout(set = SET_GI, binding = BINDING_PROBE_POSITIONS) uniform samplerBuffer probe_positions;
layout(set = SET_GI, binding = BINDING_PROBE_LAMBDA, std430) readonly buffer LambdaBlock {
    vec4 lambda[];
};

// Y_00, the constant harmonic: λ_00 Y_00 is the mean radiance a probe sees.
const float Y00 = 0.28209479;

// A colour of its own for index i.
vec3 index_colour(uint i) {
    uint h = i * 2654435761u;
    return vec3((h >> 8u) & 255u, (h >> 16u) & 255u, (h >> 24u) & 255u) / 255.0 * 0.8 + 0.2;
}

// The mean radiance of the nearest probe sphere the camera ray through `pixel` meets
// before distance `t_max`, if any.
bool probe_on_ray(ivec2 pixel, float t_max, out vec3 radiance) {
    vec3 origin = frame.camera_position.xyz;
    vec3 dir = normalize(pixel_position(pixel, 0.5) - origin);
    float r2 = probes.debug_radius * probes.debug_radius;
    float nearest = t_max;
    for (uint p = 0u; p < probes.probe_count; p++) {
        vec3 oc = texelFetch(probe_positions, int(p)).xyz - origin;
        float b = dot(oc, dir);
        float h = b * b - (dot(oc, oc) - r2);
        if (h >= 0.0 && b - sqrt(h) > 0.0 && b - sqrt(h) < nearest) {
            nearest = b - sqrt(h);
            radiance = lambda[p * probes.coefficients].rgb * Y00;
        }
    }
    return nearest < t_max;
}

// The irradiance / π at a surface of unit normal n at p from the grid: each axis's slab
// facing n read trilinearly (z clamped within the slab, x and y by the sampler), weighted
// by n_a², the ambient cube of `grid.rs`.
vec3 grid_irradiance(vec3 p, vec3 n) {
    vec3 uvw = clamp((p - probes.grid_min.xyz) * probes.grid_inverse_extent.xyz, 0.0, 1.0);
    float slab = float(probes.grid_size.z);
    float z = clamp(uvw.z * slab, 0.5, slab - 0.5);
    vec3 e = vec3(0.0);
    for (int a = 0; a < 3; a++) {
        float d = float(2 * a + (n[a] < 0.0 ? 1 : 0));
        e += n[a] * n[a] * textureLod(grid, vec3(uvw.xy, (z + d * slab) / (6.0 * slab)), 0.0).rgb;
    }
    return e;
}

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
    vec3 debug = vec3(0.0);
    float t_max = 1e30;
    if (!is_sky(depth) && triangle != 0u) {
        uint i = triangle - 1u;
        vec3 p = pixel_position(pixel, depth);
        t_max = distance(p, frame.camera_position.xyz);
        vec2 bary = barycentrics(ray_triangle(i), p);
        vec2 at = lightmap_uv(i, bary);
        if (at.x >= 0.0) {
            float level = lightmap_level(p, view.camera, view.forward);
            e = textureLod(lightmap, at, level).rgb;
            ivec2 size = textureSize(lightmap, 0);
            ivec2 texel = clamp(ivec2(at * vec2(size)), ivec2(0), size - 1);
            if (frame.debug_view == DEBUG_LIGHTMAP) {
                int mip = int(level);
                ivec2 mip_size = textureSize(lightmap, mip);
                debug = texelFetch(lightmap, clamp(ivec2(at * vec2(mip_size)), ivec2(0), mip_size - 1), mip).rgb;
            } else if (frame.debug_view == DEBUG_CLUSTERS) {
                uint c = texelFetch(texel_clusters, texel.y * size.x + texel.x).r;
                debug = c == RAY_NONE ? vec3(0.0) : index_colour(c);
            } else {
                debug = 0.5 * imageLoad(gbuffer_albedo, pixel).rgb * e;
            }
        } else if (probes.grid_size.w > 0u) {
            e = grid_irradiance(p, normalize(imageLoad(gbuffer_normal, pixel).xyz));
            debug = frame.debug_view == DEBUG_LIGHTMAP ? e : 0.5 * imageLoad(gbuffer_albedo, pixel).rgb * e;
        }
    }
    if (frame.debug_view == DEBUG_PROBES) {
        vec3 radiance;
        if (probe_on_ray(pixel, t_max, radiance)) {
            debug = radiance;
        }
    }
    if (frame.debug_view == DEBUG_LIGHTMAP || frame.debug_view == DEBUG_CLUSTERS
        || frame.debug_view == DEBUG_PROBES) {
        imageStore(screen_radiance, pixel, vec4(debug, 1.0));
    } else {
        imageStore(indirect, low, vec4(e, 1.0));
    }
}
