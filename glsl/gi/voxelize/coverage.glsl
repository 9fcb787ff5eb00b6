// The voxels a fragment of the dilated, axis-projected triangle covers (voxelize.geom),
// shared by the dense voxelization and the octree's voxel-fragment list. The includer
// defines `void store_voxel(ivec3 voxel, vec3 albedo, vec3 normal, vec3 emission)`
// (albedo, normal * 0.5 + 0.5 and emission / range, all in 0..1) before including this.
#ifndef COVERAGE_GLSL
#define COVERAGE_GLSL
#include "common/scene.glsl"
#include "common/mesh_push.glsl"
#include "gi/voxels.glsl"

layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;
layout(location = 3) flat in vec4 in_bounds;
layout(location = 4) flat in uint in_axis;
layout(location = 5) flat in vec3 in_plane;
layout(location = 6) flat in vec2 in_depth_range;

ivec3 unswizzle(ivec3 s, uint axis) {
    return axis == 0u ? s.zxy : (axis == 1u ? s.yzx : s.xyz);
}

// Calls store_voxel for every voxel of the grid this fragment covers.
void cover_voxels() {
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
    vec3 emission = clamp(m.emission.rgb / max(gi.emission_range, 1e-6), 0.0, 1.0);

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
        store_voxel(voxel, albedo, n * 0.5 + 0.5, emission);
    }
}
#endif
