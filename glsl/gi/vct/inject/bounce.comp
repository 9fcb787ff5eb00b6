#version 460
// variant: OCTREE
// One more bounce of light between voxels (Villegas 2018 §4), over the list of occupied
// voxels (compact.comp): each gathers the filtered radiance over the hemisphere of its
// lit face (injection turned the normal to it) and adds albedo times it to its direct
// radiance.
// Cones read only the directional levels (lod >= 1), never the base level rewritten here.
#include "gi/vct/cones.glsl"
#include "gi/vct/inject/radiance.glsl"

layout(local_size_x = VOXEL_LIST_GROUP_SIZE) in;
layout(set = SET_GI, binding = BINDING_VCT_ALBEDO, r32ui) uniform readonly uimage3D voxel_albedo;
layout(set = SET_GI, binding = BINDING_VCT_NORMAL, r32ui) uniform readonly uimage3D voxel_normal;
layout(set = SET_GI, binding = BINDING_VCT_DIRECT, rgba16f) uniform readonly image3D voxel_direct;

// Cones per voxel gather, whatever --diffuse-cones asks of the screen: six cover the
// hemisphere well enough for light that is filtered again before anyone sees it. The
// ring's cones stay whole; with `--snapped-cones` the cone along the normal is four
// sub-cones, as the screen's is (cones.glsl). On `conference_main` that raised every
// bounce after the first from 0.994 / 0.750 of the path tracer's at 64³ / 256³ to
// 1.082 / 0.907; splitting the ring as well, as the screen does, gathered less at 2.7
// times the cones (1.054 / 0.856; BENCHMARKS.md, session 31).
const int BOUNCE_CONES = 6;

void main() {
    ListedVoxel entry;
    if (!listed_voxel(entry)) {
        return;
    }
    ivec3 voxel = entry.texel;
    vec4 albedo = unpack_rgba8(imageLoad(voxel_albedo, voxel).r);
    vec3 n = unpack_normal(imageLoad(voxel_normal, voxel).r);
    n = length(n) > 0.2 ? normalize(n) : vec3(0.0, 1.0, 0.0);
    vec3 p = voxel_center(entry.voxel);
    float offset = 1.5 * vct.origin.w;
    vec3 gathered = gather_diffuse(p, p + n * offset, n, BOUNCE_CONES, 1.0, false, vct.bounce_step_factor, false, -1).rgb;
    vec4 direct = imageLoad(voxel_direct, voxel);
#ifdef OCTREE
    if (fresh_brick(entry)) {
        carry_store(uvec3(entry.voxel), gathered);
    }
#endif
    store_radiance(entry, vec4(direct.rgb + albedo.rgb / 255.0 * gathered, direct.a));
}
