// Where voxel shading and the bounces leave each listed voxel's radiance. In the octree a
// store that would change the radiance by less than `RADIANCE_CHANGE` (relative, per
// channel) is skipped, and a voxel whose radiance changes puts its leaf on the filter's
// update list (Dřínovský 2013, 5.5): only what changed is filtered again up the tree.
// The stored value stays within that tolerance of the shaded one, and the filtered levels
// always match the stored leaves. The frame after a build stores every change
// (`OctreeCounters.exact_stores`): it computes every bounce from scratch, as the dense grid
// does, and the two then agree exactly (the tolerance alone left the octree's Sibenik
// 0.03 % darker, its bounces converging upwards).
#ifndef INJECT_RADIANCE_GLSL
#define INJECT_RADIANCE_GLSL
#include "gi/vct/voxel_list.glsl"

layout(set = SET_GI, binding = BINDING_VCT_RADIANCE, rgba16f) uniform image3D shaded_radiance;

// Above one half-float step (2^-10 relative), so that a converged voxel stays unchanged.
const float RADIANCE_CHANGE = 1.0 / 512.0;

// Whether `now` differs from `stored` (a half float) by more than the half floats hold:
// `RADIANCE_CHANGE` relative, and below the smallest normal half float (2^-14), where the
// store may flush to zero, not at all.
bool radiance_changed(vec4 now, vec4 stored) {
    vec4 tolerance = max(max(abs(stored), abs(now)) * RADIANCE_CHANGE, vec4(1.0 / 16384.0));
    return any(greaterThan(abs(now - stored), tolerance));
}

void store_radiance(ListedVoxel entry, vec4 radiance) {
#ifdef OCTREE
    vec4 stored = imageLoad(shaded_radiance, entry.radiance_texel);
    bool changed = counters.exact_stores != 0u ? any(notEqual(radiance, stored)) : radiance_changed(radiance, stored);
    if (!changed) {
        return;
    }
    imageStore(shaded_radiance, entry.radiance_texel, radiance);
    uint level = octree_depth() - 1u;
    uint node = find_node_gridded(uvec3(entry.voxel), level);
    if (node != OCTREE_NO_NODE) {
        mark_node(node, entry.brick, level, OCTREE_CHANGED, changed_list(level));
    }
#else
    imageStore(shaded_radiance, entry.radiance_texel, radiance);
#endif
}
#endif
