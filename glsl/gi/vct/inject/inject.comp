#version 460
// variant: OCTREE
// Deferred voxel shading (Villegas 2018), over the list of occupied voxels (the others
// were cleared to zero): per occupied voxel, outgoing radiance =
// albedo / pi * direct irradiance (the surface shading's units) + emission, stored
// premultiplied by opacity. The sampled emitters' irradiance (gi/vct/emitters.glsl) joins
// the lights', their emission being left out of the voxels. The lights' visibility comes
// from the shadow maps (one bilinear compare: a voxel is wider than the PCF kernel), or
// with soft-shadow cones, which make the shadow maps unnecessary, from a ray marched
// through the voxels towards the light; the emitters' always from such a ray.
// With OCTREE the voxels are the octree's leaf voxels, in their bricks. The radiance
// is stored only where a bounce does not rewrite it before the next filter. Around
// moving meshes (`push.cull`) only the voxels whose light can have changed are shaded
// again: those in bricks given out this frame, and those a light or a sampled emitter
// reaches past where the moving meshes were or are (`push.region_*`); the others keep
// their light.
#include "common/frame.glsl"
#include "common/direct_light.glsl"
#include "gi/vct/voxels.glsl"
#include "gi/vct/inject/radiance.glsl"
#include "gi/vct/emitters.glsl"

layout(local_size_x = VOXEL_LIST_GROUP_SIZE) in;
layout(set = SET_GI, binding = BINDING_VCT_ALBEDO, r32ui) uniform readonly uimage3D voxel_albedo;
layout(set = SET_GI, binding = BINDING_VCT_NORMAL, r32ui) uniform uimage3D voxel_normal;
layout(set = SET_GI, binding = BINDING_VCT_EMISSION, r32ui) uniform readonly uimage3D voxel_emission;
layout(push_constant) uniform PushBlock {
    InjectPush push;
};
layout(set = SET_GI, binding = BINDING_VCT_DIRECT, rgba16f) uniform image3D voxel_direct;

// Whether voxel v of the grid holds a surface.
bool voxel_occupied(ivec3 v) {
#ifdef OCTREE
    ivec3 texel;
    return leaf_texel(uvec3(v), texel) && (imageLoad(voxel_albedo, texel).r >> 24) != 0u;
#else
    return (imageLoad(voxel_albedo, v).r >> 24) != 0u;
#endif
}

// Whether the segment from p offset two voxels along n, towards the light, up to `end`
// from there, passes no occupied voxel: one sample per voxel length.
float voxel_visibility(vec3 p, vec3 n, vec3 to_light, float end) {
    float voxel = vct.origin.w;
    vec3 start = p + n * (2.0 * voxel);
    end = min(end, vct.max_distance);
    for (float t = 0.0; t < end; t += voxel) {
        ivec3 v = ivec3(floor((start + to_light * t - vct.origin.xyz) / voxel));
        if (any(lessThan(v, ivec3(0))) || any(greaterThanEqual(v, ivec3(vct.resolution)))) {
            break;
        }
        if (voxel_occupied(v)) {
            return 0.0;
        }
    }
    return 1.0;
}

// The axis across a slab through voxel v: the axis whose plane through v holds the most
// of v's 26 occupied neighbours, where one holds more than the other two (a one-voxel
// rod, a solid block or a lone voxel have no such axis: zero).
vec3 slab_axis(ivec3 v) {
    ivec3 in_plane = ivec3(0);
    for (int k = 0; k < 27; k++) {
        ivec3 o = ivec3(k % 3, (k / 3) % 3, k / 9) - 1;
        ivec3 u = v + o;
        bool inside = all(greaterThanEqual(u, ivec3(0))) && all(lessThan(u, ivec3(vct.resolution)));
        if (o != ivec3(0) && inside && voxel_occupied(u)) {
            in_plane += ivec3(equal(o, ivec3(0)));
        }
    }
    int most = max(in_plane.x, max(in_plane.y, in_plane.z));
    ivec3 top = ivec3(equal(in_plane, ivec3(most)));
    return top.x + top.y + top.z == 1 ? vec3(top) : vec3(0.0);
}

// The axis faces' shares of a voxel whose surfaces' mean normal is along the unit n
// (voxel_attenuation).
vec3 face_shares(vec3 n) {
    return abs(n) / (abs(n.x) + abs(n.y) + abs(n.z));
}

// How much voxel_attenuation takes the axis faces' light rather than the plane's.
float faces_weight(float coherence) {
    return clamp((1.0 - coherence) / (1.0 - sqrt(0.5)), 0.0, 1.0);
}

// How much of a voxel's surfaces face along the unit vector l, from their mean normal:
// unit n, its length `coherence` (1: one plane; shorter where the surfaces' normals
// disagree).
// - One plane takes the light at its cosine, n . l.
// - A floor meeting a wall averages to 45 degrees (length 0.71), and the cosine would
//   catch the light of both at that slant; Villegas' normal-weighted attenuation (2018,
//   section 2.1) lets each axis face on n's side take the light at its own cosine,
//   exactly right for faces along the axes. The faces' shares are n's components over
//   their sum (what a mixture of axis faces averages to); Villegas' squared components
//   are those shares only for two faces of equal area.
// The two blend by how far the mean falls short of one plane's, wholly the faces' at two
// perpendicular faces of equal area or shorter. The faces' weighting alone took a plane
// at 45 degrees to two axes for 0.71 of its light (0.58 at 55 degrees to all three,
// 0.91 turned 16 degrees as Cornell's short block; lit along its normal); Sibenik's
// first bounce was 0.905 of the path tracer's (BENCHMARKS.md, session 40).
float voxel_attenuation(vec3 n, float coherence, vec3 l) {
    vec3 share = face_shares(n);
    float faces = dot(share, max(sign(n) * l, vec3(0.0)));
    float plane = max(dot(n, l), 0.0);
    return mix(plane, faces, faces_weight(coherence));
}

#ifdef OCTREE
// Whether the segment from p along the unit vector d, up to `dist`, meets the box
// [lo, hi].
bool segment_meets_box(vec3 p, vec3 d, float dist, vec3 lo, vec3 hi) {
    vec3 inverse = 1.0 / mix(d, vec3(1e-12), lessThan(abs(d), vec3(1e-12)));
    vec3 t0 = (lo - p) * inverse;
    vec3 t1 = (hi - p) * inverse;
    vec3 near = min(t0, t1);
    vec3 far = max(t0, t1);
    float enter = max(max(near.x, near.y), max(near.z, 0.0));
    float exit = min(min(far.x, far.y), min(far.z, dist));
    return enter <= exit;
}

// Whether the direct light of the voxel at p can differ from when it was last shaded
// (the lights and shadow views are the same): only where the path to a light passes
// the region where moving meshes were or are. The region grows by what the lookups
// reach beyond that path: the shadow lookup's normal offset (two texels and up to 0.87
// of a voxel) and its bilinear taps (a texel and a half), or the voxel ray-march's start
// two voxels out and its cells around the ray; at p's distance a shadow texel is at
// least as wide as where the path meets the region.
bool light_may_change(vec3 p) {
    float voxel = vct.origin.w;
    vec3 lo = vct.origin.xyz + vec3(push.region_min.xyz) * voxel;
    vec3 hi = vct.origin.xyz + vec3(push.region_max.xyz + 1) * voxel;
    if (any(greaterThan(lo, hi))) {
        return false;
    }
    for (uint i = 0u; i < frame.light_count; i++) {
        GpuLight light = lights[i];
        vec3 l;
        float dist;
        light_arriving(light, p, l, dist);
        float texel = light.shadow_view_count == 0u ? 0.0 : shadow_texel_world(shadow_views[shadow_view_for(light, p)], p);
        float margin = 4.0 * voxel + 4.0 * texel;
        if (segment_meets_box(p, l, dist, lo - margin, hi + margin)) {
            return true;
        }
    }
    // The paths to a sampled emitter fill the hull of p and its triangles; their bounds
    // hold it.
    for (uint i = 0u; i < vct.emitter_count; i++) {
        VctEmitter emitter = vct_emitters[i];
        vec3 low = p;
        vec3 high = p;
        for (uint k = 0u; k < emitter.triangle_count; k++) {
            VctEmitterTriangle t = vct_emitter_triangles[emitter.first_triangle + k];
            low = min(low, min(t.v0.xyz, min(t.v1.xyz, t.v2.xyz)));
            high = max(high, max(t.v0.xyz, max(t.v1.xyz, t.v2.xyz)));
        }
        float margin = 4.0 * voxel;
        if (all(lessThanEqual(low, hi + margin)) && all(greaterThanEqual(high, lo - margin))) {
            return true;
        }
    }
    return false;
}
#endif

// How far a plane with unit normal n that crosses a voxel can lie from the voxel's
// centre along n: half the voxel's extent along n, (|n.x| + |n.y| + |n.z|) / 2 voxels
// (half a voxel for a plane along the axes, 0.71 at 45 degrees to two, 0.87 to all
// three). The shadow lookup moves the centre that far out, so that it lies in front of
// its own surface: half a voxel left most centres of a plane at 45 degrees behind it, in
// its own shadow (`turned_planes_light_their_voxels_as_planes_along_the_axes`: its
// voxels' light 0.05 of a plane's along the axes at 64³, 0.71 with this, the rest
// voxel_attenuation's; BENCHMARKS.md, session 40).
float voxel_depth(vec3 n) {
    return 0.5 * (abs(n.x) + abs(n.y) + abs(n.z)) * vct.origin.w;
}

// The normal offset, in shadow texels, of a voxel's centre (voxel_irradiance).
const float VOXEL_SHADOW_OFFSET = 2.0;

// Irradiance at the voxel p on its side with (averaged) normal n, of length `coherence`
// before it was made unit (voxel_attenuation), from one light, shadowed.
vec3 voxel_irradiance(GpuLight light, vec3 p, vec3 n, float coherence) {
    vec3 l;
    float dist;
    vec3 e = light_arriving(light, p, l, dist) * voxel_attenuation(n, coherence, l);
    if (all(equal(e, vec3(0.0)))) {
        return e;
    }
    bool cones = (frame.flags & FLAG_SHADOW_CONES) != 0u;
    // A voxel's centre, moved out of its surfaces along their mean normal (voxel_depth),
    // lies on no one plane and takes one tap, so the receiver plane's reason for half a
    // texel (shadow_visibility) does not hold for it: it keeps the two texels it had.
    // (Half a texel darkens Sibenik's image by 0.2 %; BENCHMARKS.md, session 40.)
    return e * (cones ? voxel_visibility(p, n, l, dist - vct.origin.w)
                      : shadow_visibility(light, p, n, vec3(0.0), vec3(0.0), VOXEL_SHADOW_OFFSET,
                                          voxel_depth(n), 0));
}

// Irradiance at the voxel p on its side with (averaged) normal n, of length `coherence`,
// from sampled emitter `emitter` (gi/vct/emitters.glsl), taken by the plane and the axis
// faces as the lights' (voxel_attenuation), and shadowed by a ray through the voxels
// along its phi that stops 1.5 voxels short of its plane, where the emitter's own voxels
// begin. None within a voxel of its plane: a voxel's centre lies up to a voxel from its
// surfaces, and there it stands for the emitter itself or the surface behind it that
// holds it (a ceiling), which would see the emitter from a hair's breadth and take nearly
// pi times its radiance.
vec3 voxel_emitter_irradiance(VctEmitter emitter, vec3 p, vec3 n, float coherence) {
    if (dot(emitter.plane.xyz, p) - emitter.plane.w < vct.origin.w) {
        return vec3(0.0);
    }
    float t = faces_weight(coherence);
    vec3 phi = vec3(0.0);
    float cosine = 0.0;
    if (t < 1.0) {
        vec3 f = emitter_phi(emitter, p, n);
        cosine += (1.0 - t) * max(dot(n, f), 0.0);
        phi += (1.0 - t) * f;
    }
    if (t > 0.0) {
        vec3 share = face_shares(n);
        for (int a = 0; a < 3; a++) {
            if (share[a] > 0.0) {
                vec3 axis = vec3(0.0);
                axis[a] = sign(n[a]);
                vec3 f = emitter_phi(emitter, p, axis);
                cosine += t * share[a] * dot(axis, f);
                phi += t * share[a] * f;
            }
        }
    }
    if (cosine <= 0.0) {
        return vec3(0.0);
    }
    vec3 dir = normalize(phi);
    float cos_plane = max(-dot(emitter.plane.xyz, dir), 1e-3);
    vec3 start = p + n * (2.0 * vct.origin.w);
    float end = (dot(emitter.plane.xyz, start) - emitter.plane.w - 1.5 * vct.origin.w) / cos_plane;
    return emitter.radiance.rgb * cosine * voxel_visibility(p, n, dir, end);
}

void main() {
    ListedVoxel entry;
    if (!listed_voxel(entry)) {
        return;
    }
    ivec3 voxel = entry.texel;
    vec3 p = voxel_center(entry.voxel);
#ifdef OCTREE
    bool fresh = fresh_brick(entry);
    if (push.cull != 0u && !fresh && !light_may_change(p)) {
        return;
    }
#endif
    vec4 albedo = unpack_rgba8(imageLoad(voxel_albedo, voxel).r);
    vec3 rho = albedo.rgb / 255.0;
    uint packed_normal = imageLoad(voxel_normal, voxel).r;
    vec3 n = unpack_normal(packed_normal);
    float len = length(n);
    vec3 emission = unpack_rgba8(imageLoad(voxel_emission, voxel).r).rgb / 255.0 * vct.emission_range;
    // Opposite normals averaged in one voxel cancel. Where the voxel lies in a slab (a
    // table top thinner than the voxel, both of whose faces it holds), it takes the slab's
    // axis and is marked two-sided (alpha 0), once: below, it keeps its lit face like any
    // surface, and the filter shows that face's light only to cones that look at it, where
    // a voxel facing every way showed the lit top to the floor under the table. Emitters
    // keep facing every way (which face emits is lost in the mean).
    if (len <= 0.2 && all(equal(emission, vec3(0.0)))) {
        vec3 axis = slab_axis(entry.voxel);
        if (axis != vec3(0.0)) {
            packed_normal = pack_rgba8(vec4(axis * 127.5 + 127.5, 0.0));
            imageStore(voxel_normal, voxel, uvec4(packed_normal));
            n = unpack_normal(packed_normal);
            len = length(n);
        }
    }
    // Other voxels whose normals cancel face every way.
    n = len > 0.2 ? n / len : vec3(0.0, 1.0, 0.0);
    float coherence = min(len, 1.0);
    // Surfaces are two-sided: the voxel keeps the face that receives more light (emitters
    // their winding face), and its normal is turned to that face so that the filter
    // shows this radiance only to cones that look at the face. Turned exactly, so that
    // shading the voxel again gives the same light.
    vec3 front = vec3(0.0);
    vec3 back = vec3(0.0);
    for (uint i = 0u; i < frame.light_count; i++) {
        front += voxel_irradiance(lights[i], p, n, coherence);
        back += voxel_irradiance(lights[i], p, -n, coherence);
    }
    for (uint i = 0u; i < vct.emitter_count; i++) {
        front += voxel_emitter_irradiance(vct_emitters[i], p, n, coherence);
        back += voxel_emitter_irradiance(vct_emitters[i], p, -n, coherence);
    }
    bool back_lit = dot(back, vec3(1.0)) > dot(front, vec3(1.0)) && all(equal(emission, vec3(0.0)));
    vec3 e = len > 0.2 ? (back_lit ? back : front) : front + back;
    if (len > 0.2 && back_lit) {
        imageStore(voxel_normal, voxel, uvec4(flip_normal(packed_normal)));
    }
    vec4 radiance = vec4(rho / PI * e + emission, 1.0);
#ifdef OCTREE
    vec4 direct_before = imageLoad(voxel_direct, voxel);
    // A light that moved: the bounces must run again (octree/bricks/bounce_dispatch.comp).
    if (radiance_changed(radiance, direct_before)) {
        bounce_dispatch.changed = 1u;
    }
#endif
    imageStore(voxel_direct, voxel, radiance);
#ifdef OCTREE
    // Around moving meshes a voxel keeps the light its bounces gathered, as the dense
    // grid's bounces start from last frame's filtered light: a voxel in a brick kept
    // from last frame has it in its radiance beside the direct light it replaces; one in
    // a new brick finds it in the carried light, by voxel.
    if (push.keep_indirect != 0u && push.store_radiance != 0u) {
        if (fresh) {
            radiance.rgb += rho * carry_load(uvec3(entry.voxel));
        } else {
            radiance.rgb += max(imageLoad(shaded_radiance, entry.radiance_texel).rgb - direct_before.rgb, vec3(0.0));
        }
    }
#endif
    if (push.store_radiance != 0u) {
        store_radiance(entry, radiance);
    }
}
