// The voxels a pixel of the dilated, axis-projected triangle (gi/voxelize/triangle.glsl)
// covers, shared by the dense voxelization and the octree's voxel-fragment list, and by
// the rasterized (fragment shader) and the compute voxelizer. The includer defines
// `void store_voxel(ivec3 voxel, vec3 albedo, vec3 normal, vec3 emission, vec3 coverage)`
// (albedo, normal * 0.5 + 0.5, emission / range and the coverage along x, y and z, all in
// 0..1) before including this.
#ifndef COVERAGE_GLSL
#define COVERAGE_GLSL
#include "common/scene.glsl"
#include "common/mesh_push.glsl"
#include "gi/vct/voxels.glsl"
#include "gi/vct/voxelize/triangle.glsl"

layout(set = SET_GI, binding = BINDING_VCT_SAMPLED_MATERIALS, std430) readonly buffer SampledMaterialBlock {
    uint vct_sampled_materials[];
};

ivec3 unswizzle(ivec3 s, uint axis) {
    return axis == 0u ? s.zxy : (axis == 1u ? s.yzx : s.xyz);
}

vec3 unswizzle(vec3 s, uint axis) {
    return axis == 0u ? s.zxy : (axis == 1u ? s.yzx : s.xyz);
}

// Calls store_voxel for every voxel of the grid that the pixel centred at `pixel` covers,
// with the triangle's `normal` and `uv` there (textures are sampled over the pixel's
// footprint, which is the voxel's), and the share of the voxel's cross-section across
// each axis that the triangle's part in it covers seen along that axis: the pixel's
// covered share (`lines`, the undilated edges) along the dominant axis, times the slope
// (|n.x| / |n.z| in the projection's frame) along the others, shared among the voxels
// the part spans in depth by their share of its depth range. Where a surface ends inside
// a voxel, a cone crossing that voxel meets it only across the covered share (its edge
// voxels, counted whole, cast shadows up to a voxel too wide; BENCHMARKS.md, session 47).
void cover_pixel(vec2 pixel, vec3 normal, vec2 uv, vec4 bounds, uint axis, vec3 plane, vec2 depth_range,
                 vec3 lines[3]) {
    if (any(lessThan(pixel, bounds.xy)) || any(greaterThan(pixel, bounds.zw))) {
        return;
    }
    GpuMaterial m = materials[draw.material];
    if (material_coverage(m, uv) < CUTOUT_THRESHOLD) {
        return;
    }
    vec3 albedo = material_albedo(m, uv);
    vec3 n = normalize(normal);
    // The sampled emitters' light reaches the surfaces by sampling (gi/vct/emitters.glsl):
    // in the voxels their emission would be gathered a second time.
    bool sampled = ((vct_sampled_materials[draw.material / 32u] >> (draw.material % 32u)) & 1u) != 0u;
    vec3 emission = sampled ? vec3(0.0) : clamp(material_emission(m, uv) / max(vct.emission_range, 1e-6), 0.0, 1.0);

    // The triangle's depth over this pixel's footprint: a slope up to 1 (dominant axis)
    // spans up to two voxels, and every one of them is covered.
    float center = dot(plane, vec3(pixel, 1.0));
    float spread = 0.5 * (abs(plane.x) + abs(plane.y));
    float z0 = max(center - spread, depth_range.x);
    float z1 = min(center + spread, depth_range.y);
    int first = int(floor(z0));
    int last = int(floor(z1));
    int res = int(vct.resolution);
    // Where no cone reads the coverage (VOXEL_COVERAGE; the ring's never do) the clipping
    // and the sums' adds are skipped: the clipping took eight times the voxelization's
    // time in the speed case on lavapipe.
    vec3 across = vec3(0.0);
    if (VOXEL_COVERAGE) {
        across = unswizzle(pixel_coverage(lines, pixel) * vec3(abs(plane.x), abs(plane.y), 1.0), axis);
    }
    for (int z = first; z <= last; z++) {
        ivec3 voxel = unswizzle(ivec3(ivec2(pixel), z), axis);
        if (any(lessThan(voxel, ivec3(0))) || any(greaterThanEqual(voxel, ivec3(res)))) {
            continue;
        }
        float share = z1 > z0 ? (min(z1, float(z + 1)) - max(z0, float(z))) / (z1 - z0) : 1.0;
        store_voxel(voxel, albedo, n * 0.5 + 0.5, emission, across * share);
    }
}

#ifndef MATERIAL_GRADIENTS
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;
layout(location = 3) flat in vec4 in_bounds;
layout(location = 4) flat in uint in_axis;
layout(location = 5) flat in vec3 in_plane;
layout(location = 6) flat in vec2 in_depth_range;
layout(location = 7) flat in vec3 in_lines[3];

// The rasterizer's fragment: its pixel of the triangle that voxelize.geom projected.
void cover_voxels() {
    cover_pixel(gl_FragCoord.xy, in_normal, in_uv, in_bounds, in_axis, in_plane, in_depth_range, in_lines);
}
#endif
#endif
