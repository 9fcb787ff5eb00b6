#version 460
// Writes albedo, normal and emission of every voxel the (dilated) triangle covers, as
// RGBA8 moving averages (Crassin & Green 2012), so overlapping triangles average.
#include "common/scene.glsl"
#include "common/mesh_push.glsl"
#include "gi/voxels.glsl"

layout(set = SET_PASS, binding = BINDING_GI_ALBEDO, r32ui) uniform coherent volatile uimage3D voxel_albedo;
layout(set = SET_PASS, binding = BINDING_GI_NORMAL, r32ui) uniform coherent volatile uimage3D voxel_normal;
layout(set = SET_PASS, binding = BINDING_GI_EMISSION, r32ui) uniform coherent volatile uimage3D voxel_emission;

layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;
layout(location = 3) flat in vec4 in_bounds;
layout(location = 4) flat in uint in_axis;
layout(location = 5) flat in vec3 in_plane;
layout(location = 6) flat in vec2 in_depth_range;

// Adds `value` (channels 0..255) to the running average in IMAGE; alpha counts the
// samples, saturating at 255. The retry loop is bounded: under heavy contention on a GPU a
// sample may be dropped rather than hang. GLSL cannot pass an r32ui image with its format
// to a function, hence one function per image.
#define DEFINE_AVERAGE(NAME, IMAGE)                                          \
    void NAME(ivec3 voxel, vec3 value) {                                     \
        uint written = pack_rgba8(vec4(value, 1.0));                         \
        uint expected = 0u;                                                  \
        for (int attempt = 0; attempt < 256; attempt++) {                    \
            uint found = imageAtomicCompSwap(IMAGE, voxel, expected, written); \
            if (found == expected) {                                         \
                return;                                                      \
            }                                                                \
            expected = found;                                                \
            vec4 current = unpack_rgba8(found);                              \
            float count = min(current.a + 1.0, 255.0);                       \
            vec3 mean = current.rgb + (value - current.rgb) / count;         \
            written = pack_rgba8(vec4(mean, count));                         \
        }                                                                    \
    }

DEFINE_AVERAGE(average_albedo, voxel_albedo)
DEFINE_AVERAGE(average_normal, voxel_normal)
DEFINE_AVERAGE(average_emission, voxel_emission)

ivec3 unswizzle(ivec3 s, uint axis) {
    return axis == 0u ? s.zxy : (axis == 1u ? s.yzx : s.xyz);
}

void main() {
    vec2 pixel = gl_FragCoord.xy;
    if (any(lessThan(pixel, in_bounds.xy)) || any(greaterThan(pixel, in_bounds.zw))) {
        discard;
    }
    GpuMaterial m = materials[draw.material];
    if (material_coverage(m, in_uv) < CUTOUT_THRESHOLD) {
        discard;
    }
    vec3 albedo = material_albedo(m, in_uv);
    vec3 n = normalize(in_normal);
    vec3 emission = m.emission.rgb / max(gi.emission_range, 1e-6);

    // The triangle's depth over this pixel's footprint: a slope up to 1 (dominant axis)
    // spans up to two voxels, and every one of them is covered.
    float center = dot(in_plane, vec3(pixel, 1.0));
    float spread = 0.5 * (abs(in_plane.x) + abs(in_plane.y));
    float z0 = max(center - spread, in_depth_range.x);
    float z1 = min(center + spread, in_depth_range.y);
    int first = int(floor(z0));
    int last = int(floor(z1));
    int res = int(gi.resolution);
    for (int z = first; z <= last; z++) {
        ivec3 voxel = unswizzle(ivec3(ivec2(pixel), z), in_axis);
        if (any(lessThan(voxel, ivec3(0))) || any(greaterThanEqual(voxel, ivec3(res)))) {
            continue;
        }
        average_albedo(voxel, albedo * 255.0);
        average_normal(voxel, (n * 0.5 + 0.5) * 255.0);
        average_emission(voxel, clamp(emission, 0.0, 1.0) * 255.0);
    }
}
