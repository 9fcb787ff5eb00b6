#version 460
// variant: OCTREE
// variant: AMBIENT_OCCLUSION
// variant: OCTREE AMBIENT_OCCLUSION
// Voxel cone tracing (Crassin et al. 2011) for one G-buffer pixel of each
// indirect_scale² block: cosine-weighted diffuse cones over the normal's hemisphere are
// marched front to back through the voxel radiance, the sky filling what they leave
// unoccluded (alpha: ambient occlusion), and the sampled emitters' light is added; then
// the soft-shadow cones towards the lights, the specular cone along the reflected view
// ray and, on transmissive surfaces, the refraction cone (each with the sampled
// emitters' share of it). The upsample pass spreads the results to every pixel. Every
// cone is traced here: a cone march compiled into the full-resolution upsample pass
// made it twice as slow on lavapipe even where it never ran.
#include "common/direct_light.glsl"
#include "gi/vct/cones.glsl"
#include "gi/vct/emitters.glsl"
#include "gi/screen/screen.glsl"

layout(local_size_x = SCREEN_GROUP_SIZE, local_size_y = SCREEN_GROUP_SIZE) in;
layout(set = SET_SCREEN, binding = BINDING_SCREEN_INDIRECT, rgba16f) uniform image2D indirect;
layout(set = SET_SCREEN, binding = BINDING_SCREEN_SHADOW, rgba16f) uniform writeonly image2D shadow;
layout(set = SET_SCREEN, binding = BINDING_SCREEN_SPECULAR, rgba16f) uniform image2D specular;
layout(set = SET_SCREEN, binding = BINDING_SCREEN_TRANSMITTED, rgba16f) uniform image2D transmitted;
layout(push_constant) uniform Push {
    ConeTracePush push;
};

// Irradiance at the surface point p (normal n) from `count` sampled emitters from `first`,
// each shadowed by a soft-shadow cone from `origin` along its phi.
vec3 sampled_emitter_light(vec3 p, vec3 origin, vec3 n, uint first, uint count) {
    vec3 e = vec3(0.0);
    for (uint i = first; i < first + count; i++) {
        VctEmitter emitter = vct_emitters[i];
        vec3 phi = emitter_phi(emitter, p, n);
        float cosine = dot(n, phi);
        if (cosine > 0.0) {
            e += emitter.radiance.rgb * cosine * emitter_visibility(origin, p, n, normalize(phi), emitter.plane);
        }
    }
    return e;
}

// The area of the intersection of two discs of radii a and b whose centres lie d apart.
float disc_overlap(float a, float b, float d) {
    if (d >= a + b) {
        return 0.0;
    }
    if (d <= abs(a - b)) {
        return PI * min(a, b) * min(a, b);
    }
    float lens = sqrt(max((-d + a + b) * (d + a - b) * (d - a + b) * (d + a + b), 0.0));
    return a * a * acos(clamp((d * d + a * a - b * b) / (2.0 * d * a), -1.0, 1.0))
         + b * b * acos(clamp((d * d + b * b - a * a) / (2.0 * d * b), -1.0, 1.0)) - 0.5 * lens;
}

// The radiance of the sampled emitters whose first pieces lie among the `count` from
// `first` (each emitter whole, its pieces' phi summed: a piece's disc would miss a narrow
// cone aimed where pieces meet) averaged over the cone from `origin` along `dir` of
// half-angle atan(tan_half) (a specular or refraction cone leaving the surface at p on
// its `side`): the voxels the cone marches do not hold it. Each emitter covers the share
// of the cone that a disc of its solid angle |phi| about phi's direction (phi over the
// hemisphere about dir) covers of the cone's disc, both taken flat across dir (exact in
// the limits of an emitter filling the cone or missing it); times its visibility along
// the cone.
vec3 sampled_emitter_radiance(vec3 p, vec3 origin, vec3 side, vec3 dir, float tan_half, uint first, uint count) {
    float cone = atan(tan_half);
    vec3 radiance = vec3(0.0);
    for (uint i = first; i < first + count; i++) {
        VctEmitter emitter = vct_emitters[i];
        vec3 phi = vec3(0.0);
        for (uint k = 0u; k < emitter.group_pieces; k++) {
            phi += emitter_phi(vct_emitters[i + k], p, dir);
        }
        float solid = length(phi);
        if (solid <= 0.0) {
            continue;
        }
        float apart = acos(clamp(dot(dir, phi / solid), -1.0, 1.0));
        float share = disc_overlap(sqrt(solid / PI), cone, apart) / (PI * cone * cone);
        if (share > 0.0) {
            radiance += emitter.radiance.rgb * share * emitter_visibility(origin, p, side, dir, emitter.plane);
        }
    }
    return radiance;
}

void main() {
    ivec2 low = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(low, imageSize(indirect)))) {
        return;
    }
    ivec2 pixel = representative(low);
    float depth = texelFetch(gbuffer_depth, pixel, 0).r;
    if (is_sky(depth)) {
        imageStore(indirect, low, vec4(0.0, 0.0, 0.0, 1.0));
        return;
    }
    vec3 p = pixel_position(pixel, depth);
    vec4 normal_roughness = imageLoad(gbuffer_normal, pixel);
    vec3 n = normalize(normal_roughness.xyz);
    // Start two voxels off the surface so the cones do not gather their own voxels, and
    // sample no finer than 2-voxel cells (the base level adds nothing measurable here:
    // BENCHMARKS.md, the dense grid's quality history).
    // Ambient occlusion costs one more sample per step: only when shown or applied, in
    // its own variant (lavapipe runs this pass 15 % slower with the sampling code merely
    // compiled in).
#ifdef AMBIENT_OCCLUSION
    const bool with_ao = true;
#else
    const bool with_ao = false;
#endif
    vec3 start = p + n * (2.0 * vct.origin.w);
    bool emitters_alone = frame.debug_view == DEBUG_EMITTER_LIGHT;
    // A later dispatch, a share of the lattice or of the sampled emitters (cone_trace.rs
    // says why they are split), adds to the earlier ones', the lattice's occlusion taken
    // from alpha (the ambient occlusion). The ring has one dispatch: its shader keeps no
    // branch for later ones. One call site per kind of gather: each is inlined.
    bool later_share = LATTICE_CONES > 0u && (push.first_cone > 0u || push.first_emitter > 0u);
    vec4 gathered = later_share ? imageLoad(indirect, low) : vec4(0.0, 0.0, 0.0, 1.0);
    if (!emitters_alone) {
        if (LATTICE_CONES > 0u) {
            if (push.cone_count > 0u) {
                vec4 share = gather_lattice(p, start, n, 1.0, ao_volume_facing(n, with_ao), int(push.first_cone),
                                            int(push.cone_count));
                gathered += vec4(share.rgb, -share.a);
            }
        } else if (!later_share) {
            gathered = gather_diffuse(p, start, n, int(vct.diffuse_cones), 1.0, with_ao, vct.step_factor, true,
                                      int(vct.only_cone));
        }
    }
    // The sampled emitters' light, which the voxels do not hold, joins the gathered
    // radiance as the cosine-weighted mean it adds: E / pi (not with `--cone`, a cone's
    // gather alone; alone in its debug view).
    if (push.emitter_count > 0u && vct.only_cone == 0xffffffffu) {
        gathered.rgb += sampled_emitter_light(p, start, n, push.first_emitter, push.emitter_count) / PI;
    }
    imageStore(indirect, low, gathered);
    if (later_share && push.emitter_count == 0u) {
        return;
    }
    // Soft shadows change at the scale of the voxels, like the indirect light: their
    // cones are traced here too, four lights to a band of rows.
    if (!later_share && (frame.flags & FLAG_SHADOW_CONES) != 0u) {
        for (uint band = 0u; band * 4u < frame.light_count; band++) {
            vec4 visibility = vec4(1.0);
            for (uint i = 0u; i < 4u && band * 4u + i < frame.light_count; i++) {
                vec3 l;
                float dist;
                if (any(greaterThan(light_incident(lights[band * 4u + i], p, n, l, dist), vec3(0.0)))) {
                    visibility[i] = cone_visibility(start, l, vct.shadow_tan_half, dist - vct.origin.w);
                }
            }
            imageStore(shadow, shadow_texel(low, band), visibility);
        }
    }
    // The specular and refraction cones too: at 64^3 voxels a reflection is no sharper
    // than a few voxels. Their half-angle follows the roughness: tan(half) ~ roughness.
    // One call site for both keeps the shader small (lavapipe inlines every call). The
    // first dispatch traces them; each share of the emitters adds their light to them.
    vec3 v = normalize(frame.camera_position.xyz - p);
    float roughness = clamp(normal_roughness.w, 0.02, 1.0);
    vec2 transmission = imageLoad(gbuffer_transmission, pixel).rg;
    bool traced[2] = bool[2](
        imageLoad(gbuffer_albedo, pixel).a > 0.0 && (frame.flags & FLAG_INDIRECT_SPECULAR) != 0u,
        transmission.r > 0.0 && (frame.flags & FLAG_TRANSMISSION) != 0u);
    // n faces the camera: the refracted ray enters the surface (relative index 1 / Ni).
    vec3 refracted = refract(-v, n, 1.0 / max(transmission.g, 1.0));
    vec3 dirs[2] = vec3[2](reflect(-v, n), dot(refracted, refracted) > 0.0 ? refracted : reflect(-v, n));
    vec4 radiance[2] = later_share ? vec4[2](imageLoad(specular, low), imageLoad(transmitted, low))
                                   : vec4[2](vec4(0.0), vec4(0.0));
    for (int c = 0; c < 2; c++) {
        if (traced[c]) {
            // The cone leaves the surface on the side it points to.
            vec3 side = dot(dirs[c], n) < 0.0 ? -n : n;
            vec3 origin = p + side * (2.0 * vct.origin.w);
            vec3 cone = later_share ? radiance[c].rgb
                                    : trace_cone(origin, dirs[c], roughness, 0.0, p, side, -1, vct.step_factor).rgb;
            radiance[c] = vec4(cone + sampled_emitter_radiance(p, origin, side, dirs[c], roughness,
                                                               push.first_emitter, push.emitter_count),
                               1.0);
        }
    }
    imageStore(specular, low, radiance[0]);
    imageStore(transmitted, low, radiance[1]);
}
