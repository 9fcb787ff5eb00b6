#version 460
// The path-traced reference (`--gi path`): a unidirectional path tracer with next-event
// estimation and multiple importance sampling (Veach 1997), as the references' Mitsuba 3
// integrator: two-sided surfaces of albedo Kd x map_Kd (Lambertian, plus the lighting
// pass's normalised Blinn-Phong lobe where Ks > 0, with its normal maps), transmissive
// surfaces (d < 1) passing 1 - d of the light refracted by Ni, one-sided emitters
// (MTL Ke, along the winding normal), cut-outs passing rays with the probability 1 -
// coverage (and, under the references' conventions, stopping every shadow ray: the
// references' next-event estimation ignores Mitsuba's masks), the scene's point, spot and
// directional lights in the lighting pass's units, a constant sky, a box pixel filter,
// Russian roulette from `rr_depth` on. Each invocation adds `samples_now` samples to its
// pixel's running mean and writes it to the screen radiance.
#include "common/diffuse_cones.glsl"
#include "common/direct_light.glsl"
#include "common/random.glsl"
#include "common/subgroup_add.glsl"
#include "ray/rays.glsl"

layout(local_size_x = SCREEN_GROUP_SIZE, local_size_y = SCREEN_GROUP_SIZE) in;
layout(set = SET_GI, binding = BINDING_PATH_UNIFORMS) uniform PathBlock {
    PathUniforms path;
};
layout(set = SET_GI, binding = BINDING_PATH_MEAN, rgba32f) uniform image2D path_mean;
layout(set = SET_GI, binding = BINDING_PATH_RAYS, std430) buffer PathRayBlock {
    uint rays_cast;
};
layout(set = SET_SCREEN, binding = BINDING_SCREEN_RADIANCE, rgba32f) uniform writeonly image2D screen_radiance;
layout(push_constant) uniform Push {
    PathPush push;
};
// The scene's materials' features and the cone component (`PathTracer::constants`): the
// code of what the scene lacks is left out, as `RAY_CUT_OUTS` leaves the coverage out.
layout(constant_id = SPEC_PATH_TEXTURES) const bool PATH_TEXTURES = true;
layout(constant_id = SPEC_PATH_NORMAL_MAPS) const bool PATH_NORMAL_MAPS = true;
layout(constant_id = SPEC_PATH_SPECULAR) const bool PATH_SPECULAR = true;
layout(constant_id = SPEC_PATH_TRANSMISSION) const bool PATH_TRANSMISSION = true;
layout(constant_id = SPEC_PATH_EMITTERS) const bool PATH_EMITTERS = true;
layout(constant_id = SPEC_PATH_CONE) const bool PATH_CONE = true;

// Rays this invocation cast.
uint rays_here = 0u;

// Where a path met a surface, as the next vertex sees it.
struct Surface {
    vec3 p;
    // The geometric normal on the side the ray came from.
    vec3 ng;
    // The shading normal, turned to that side too (two-sided shading), normal-mapped.
    vec3 ns;
    // Towards the ray's origin.
    vec3 v;
    vec3 albedo;
    // The lighting pass's specular weight (mean Ks) and roughness (from Ns).
    float specular;
    float roughness;
    // The share of light passing a refracting surface (1 - d; 0 elsewhere) and the
    // relative index of refraction along the ray (Ni entering the front, 1 / Ni leaving).
    float transmit;
    float eta;
    // Emitted radiance towards the ray's origin (zero from the back of an emitter).
    vec3 emitted;
};

// The shading normal `n` perturbed by tangent-space normal map `map` of triangle `i` at
// `uv`, in the G-buffer's cotangent frame (Schüler) with the triangle's edges for the
// screen-space derivatives: both give the same frame, the edges exactly. The sign of
// n . (e1 x e2) keeps the frame the gradients of u and v from the back side too.
vec3 apply_normal_map(uint i, vec3 n, uint map, vec2 uv) {
    RayTriangle tri = ray_triangle(i);
    RayShading sh = ray_shading(i);
    vec2 uv0 = vec2(sh.n0.w, sh.n1.w);
    vec2 duv1 = vec2(sh.n2.w, sh.uv.x) - uv0;
    vec2 duv2 = sh.uv.yz - uv0;
    vec3 dp2perp = cross(tri.e2.xyz, n);
    vec3 dp1perp = cross(n, tri.e1.xyz);
    vec3 t = dp2perp * duv1.x + dp1perp * duv2.x;
    vec3 b = dp2perp * duv1.y + dp1perp * duv2.y;
    float len = max(dot(t, t), dot(b, b));
    // No uv change along the triangle (relative to its edges, as in the G-buffer).
    if (len <= 1e-20 * max(dot(tri.e1.xyz, tri.e1.xyz), dot(tri.e2.xyz, tri.e2.xyz))) {
        return n;
    }
    float scale = dot(n, cross(tri.e1.xyz, tri.e2.xyz)) < 0.0 ? -inversesqrt(len) : inversesqrt(len);
    vec3 m = texture_bilinear(map, uv, false).xyz * 2.0 - 1.0;
    // Our v runs down the image, the map's green axis up it (as the G-buffer).
    m.y = -m.y;
    vec3 mapped = normalize(mat3(t * scale, b * scale, n) * m);
    return any(isnan(mapped)) ? n : mapped;
}

Surface surface_at(Hit hit, vec3 dir) {
    RayTriangle tri = ray_triangle(hit.triangle);
    RayShading sh = ray_shading(hit.triangle);
    GpuMaterial m = ray_material(floatBitsToUint(tri.v0.w));
    float w = 1.0 - hit.bary.x - hit.bary.y;
    Surface s;
    s.p = tri.v0.xyz + tri.e1.xyz * hit.bary.x + tri.e2.xyz * hit.bary.y;
    vec3 winding = normalize(cross(tri.e1.xyz, tri.e2.xyz));
    bool front = dot(winding, dir) < 0.0;
    s.ng = front ? winding : -winding;
    vec3 ns = sh.n0.xyz * w + sh.n1.xyz * hit.bary.x + sh.n2.xyz * hit.bary.y;
    ns = dot(ns, ns) > 1e-12 ? normalize(ns) : s.ng;
    s.ns = dot(ns, s.ng) < 0.0 ? -ns : ns;
    vec2 uv = triangle_uv(hit.triangle, hit.bary);
    if (PATH_NORMAL_MAPS && m.normal_texture != NO_TEXTURE) {
        s.ns = apply_normal_map(hit.triangle, s.ns, m.normal_texture, uv);
    }
    s.v = -dir;
    s.albedo = m.albedo.rgb;
    if (PATH_TEXTURES && m.albedo_texture != NO_TEXTURE) {
        s.albedo *= texture_bilinear(m.albedo_texture, uv, true).rgb;
    }
    s.specular = dot(m.specular.rgb, vec3(1.0 / 3.0));
    s.roughness = m.specular.a;
    s.transmit = PATH_TRANSMISSION && material_refracts(m) ? 1.0 - m.albedo.a : 0.0;
    s.eta = front ? m.emission.a : 1.0 / m.emission.a;
    s.emitted = front ? m.emission.rgb : vec3(0.0);
    if (PATH_TEXTURES && front && m.emission_texture != NO_TEXTURE) {
        s.emitted *= texture_bilinear(m.emission_texture, uv, true).rgb;
    }
    return s;
}

// The power heuristic (beta = 2) for a sample drawn with density `a` against another
// technique's density `b` for the same direction, as Mitsuba's path integrator weighs.
float mis_weight(float a, float b) {
    a *= a;
    b *= b;
    return a + b > 0.0 ? a / (a + b) : 0.0;
}

// A direction about `n` with density cos(theta) / pi.
vec3 sample_cosine(vec3 n, inout uint rng) {
    float r = sqrt(random_next(rng));
    float phi = 6.2831853 * random_next(rng);
    vec3 t = perpendicular(n);
    vec3 b = cross(n, t);
    return normalize(r * cos(phi) * t + r * sin(phi) * b + sqrt(max(1.0 - r * r, 0.0)) * n);
}

// A direction uniform in solid angle within the cone about `axis` of half-angle
// acos(cos_half).
vec3 sample_cone(vec3 axis, float cos_half, inout uint rng) {
    float c = 1.0 - random_next(rng) * (1.0 - cos_half);
    float s = sqrt(max(1.0 - c * c, 0.0));
    float phi = 6.2831853 * random_next(rng);
    vec3 t = perpendicular(axis);
    vec3 b = cross(axis, t);
    return normalize(s * cos(phi) * t + s * sin(phi) * b + c * axis);
}

// The Blinn-Phong exponent of the lighting pass's lobe for `roughness`.
float phong_exponent(float roughness) {
    float r = max(roughness, 0.02);
    return 2.0 / (r * r) - 2.0;
}

// The probability of sampling the specular lobe rather than the cosine at `s`: the
// lobe's share of the two weights.
float lobe_choice(Surface s) {
    float diffuse = dot(s.albedo, vec3(1.0 / 3.0));
    return PATH_SPECULAR && s.specular > 0.0 ? s.specular / (s.specular + diffuse) : 0.0;
}

// The density of direction `l` under the sampling of `sample_bsdf` at `s`: cos / pi
// mixed with the Blinn-Phong half-vector density (e + 1) / (2 pi) cos^e(theta_h),
// carried to `l` by 1 / (4 v.h).
float bsdf_pdf(Surface s, vec3 l) {
    float cos_l = dot(s.ns, l);
    if (cos_l <= 0.0) {
        return 0.0;
    }
    float pdf = cos_l / PI;
    float lobe = lobe_choice(s);
    if (lobe > 0.0) {
        float e = phong_exponent(s.roughness);
        vec3 h = normalize(l + s.v);
        float vh = max(dot(s.v, h), 1e-6);
        float lobe_pdf = (e + 1.0) / (2.0 * PI) * pow(max(dot(s.ns, h), 0.0), e) / (4.0 * vh);
        pdf = mix(pdf, lobe_pdf, lobe);
    }
    return pdf;
}

// A direction from `s` for the next vertex, by `lobe_choice`: the cosine or a half-vector
// about the shading normal from the Blinn-Phong lobe, the view mirrored about it.
vec3 sample_bsdf(Surface s, inout uint rng) {
    if (random_next(rng) >= lobe_choice(s) || !PATH_SPECULAR) {
        return sample_cosine(s.ns, rng);
    }
    float e = phong_exponent(s.roughness);
    float cos_h = pow(random_next(rng), 1.0 / (e + 1.0));
    float sin_h = sqrt(max(1.0 - cos_h * cos_h, 0.0));
    float phi = 6.2831853 * random_next(rng);
    vec3 t = perpendicular(s.ns);
    vec3 b = cross(s.ns, t);
    vec3 h = sin_h * cos(phi) * t + sin_h * sin(phi) * b + cos_h * s.ns;
    return reflect(-s.v, h);
}

// The BRDF at `s` for light arriving from `l`: the lighting pass's `surface_brdf`.
vec3 brdf(Surface s, vec3 l) {
    return PATH_SPECULAR ? surface_brdf(s.albedo, s.specular, s.roughness, s.ns, s.v, l) : s.albedo / PI;
}

// The density, in solid angle at a point `dist` away, with which next-event estimation
// picks a point of an emitter of largest radiance `largest` seen at `cos_light`: emitters
// are picked by power (area x largest radiance) and points uniformly by area, so the
// area cancels.
float emitter_pdf(float largest, float dist, float cos_light) {
    return largest / rays.emitter_power * dist * dist / max(cos_light, 1e-12);
}

// A seed for one ray's random cut-out decisions (neither 0, the fixed threshold, nor
// `RAY_OPAQUE`).
uint cut_seed(inout uint rng) {
    return (pcg_hash(uint(random_next(rng) * 16777216.0)) | 1u) & ~2u;
}

// Whether nothing lies between `origin` and the point `dist` along `dir`; under the
// references' conventions cut-outs stop these rays whatever their coverage.
bool visible(vec3 origin, vec3 dir, float dist, inout uint rng) {
    rays_here++;
    uint seed = path.opaque_shadow_cut_outs != 0u ? RAY_OPAQUE : cut_seed(rng);
    return !trace_any(origin, dir, 0.0, dist, seed);
}

// Radiance from the scene's point, spot and directional lights scattered at `s` towards
// the path, shadowed by rays.
vec3 delta_lights(Surface s, vec3 origin, inout uint rng) {
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < frame.light_count; i++) {
        vec3 l;
        float dist;
        vec3 e = light_arriving(lights[i], s.p, l, dist);
        float cos_s = dot(s.ns, l);
        if (cos_s <= 0.0 || dot(s.ng, l) <= 0.0 || all(equal(e, vec3(0.0)))) {
            continue;
        }
        float reach = lights[i].kind == LIGHT_DIRECTIONAL ? 1e30 : dist - 2.0 * rays.epsilon;
        if (visible(origin, l, reach, rng)) {
            sum += brdf(s, l) * e * cos_s;
        }
    }
    return sum;
}

// Radiance from one emitter point picked by power, weighted against cosine sampling.
vec3 emitter_light(Surface s, vec3 origin, inout uint rng) {
    if (!PATH_EMITTERS || rays.emitter_count == 0u) {
        return vec3(0.0);
    }
    float pick = random_next(rng);
    uint lo = 0u;
    uint hi = rays.emitter_count - 1u;
    while (lo < hi) {
        uint mid = (lo + hi) / 2u;
        if (ray_emitter(mid).cdf < pick) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    uint emitter = ray_emitter(lo).triangle;
    RayTriangle tri = ray_triangle(emitter);
    float su = sqrt(random_next(rng));
    float r = random_next(rng);
    vec3 q = tri.v0.xyz + su * (1.0 - r) * tri.e1.xyz + su * r * tri.e2.xyz;
    vec3 to = q - origin;
    float dist = length(to);
    vec3 l = to / dist;
    vec3 winding = normalize(cross(tri.e1.xyz, tri.e2.xyz));
    float cos_light = -dot(winding, l);
    float cos_s = dot(s.ns, l);
    if (cos_light <= 0.0 || cos_s <= 0.0 || dot(s.ng, l) <= 0.0 || !visible(origin, l, dist * (1.0 - 1e-4), rng)) {
        return vec3(0.0);
    }
    // Emitters are picked by their factor's power (src/ray/mod.rs), which the density
    // follows; the texture only scales what the sample carries.
    GpuMaterial em = ray_material(floatBitsToUint(tri.v0.w));
    vec3 radiance = em.emission.rgb;
    float light_pdf = emitter_pdf(max(radiance.r, max(radiance.g, radiance.b)), dist, cos_light);
    if (PATH_TEXTURES && em.emission_texture != NO_TEXTURE) {
        radiance *= texture_bilinear(em.emission_texture, triangle_uv(emitter, vec2(su * (1.0 - r), su * r)), true).rgb;
    }
    float weight = mis_weight(light_pdf, bsdf_pdf(s, l));
    return brdf(s, l) * radiance * cos_s * weight / light_pdf;
}

// A path under way: where it goes next and what it has gathered.
struct Path {
    vec3 origin;
    vec3 dir;
    vec3 radiance;
    vec3 throughput;
    // The density of the direction the path took last, 0 for the camera ray (whose hit
    // of an emitter no other technique samples).
    float bsdf_pdf;
    // The vertex the next hit will be (1: the camera ray's).
    uint depth;
    uint rng;
};

// Sample `index` of `pixel`: its camera ray jittered over the pixel (a box filter).
Path start_path(uvec2 pixel, uint index) {
    Path p;
    p.rng = random_seed(pixel, index, path.seed);
    vec2 at = (vec2(pixel) + vec2(random_next(p.rng), random_next(p.rng))) / vec2(frame.width, frame.height);
    // From the projection's focal lengths and the view's rotation, not by unprojecting a
    // point through inv_view_proj: that point lies a few near-plane distances (a
    // thousandth of the scene) from the eye, and in 32 bits it scaled the Cornell box's
    // image by 1.5e-4 against Mitsuba's, a 3 % error along the light's sharp edge.
    vec2 ndc = at * 2.0 - 1.0;
    vec3 view_dir = vec3(ndc.x / frame.proj[0][0], ndc.y / frame.proj[1][1], -1.0);
    p.origin = frame.camera_position.xyz;
    p.dir = normalize(transpose(mat3(frame.view)) * view_dir);
    p.radiance = vec3(0.0);
    p.throughput = vec3(1.0);
    p.bsdf_pdf = 0.0;
    p.depth = 1u;
    return p;
}

// The cone component (`--cone`): the camera's hit gathers albedo times the radiance
// from one cone of the cone tracer's gather, instead of its own light.
bool cone_component(Path p) {
    return PATH_CONE && p.depth == 1u && path.cone != 0xffffffffu;
}

// Russian roulette from `rr_depth` on: whether the path goes on, its throughput raised
// by the chance it had.
bool survives(inout Path p) {
    if (p.depth < path.rr_depth) {
        return true;
    }
    float survive = min(max(p.throughput.r, max(p.throughput.g, p.throughput.b)), 0.95);
    if (random_next(p.rng) >= survive) {
        return false;
    }
    p.throughput /= survive;
    return true;
}

// Extends the path by one vertex; returns whether it goes on.
bool extend(inout Path p) {
    Hit hit;
    rays_here++;
    if (!trace_closest(p.origin, p.dir, 0.0, 1e30, cut_seed(p.rng), hit)) {
        p.radiance += p.throughput * frame.sky_radiance.rgb;
        return false;
    }
    Surface s = surface_at(hit, p.dir);
    if (any(greaterThan(s.emitted, vec3(0.0))) && !cone_component(p)) {
        float weight = 1.0;
        RayTriangle tri = ray_triangle(hit.triangle);
        bool sampled = PATH_EMITTERS && (floatBitsToUint(tri.e2.w) & RAY_MOVING) == 0u && rays.emitter_count > 0u;
        if (p.bsdf_pdf > 0.0 && sampled) {
            vec3 factor = ray_material(floatBitsToUint(tri.v0.w)).emission.rgb;
            float largest = max(factor.r, max(factor.g, factor.b));
            weight = mis_weight(p.bsdf_pdf, emitter_pdf(largest, hit.t, dot(s.ng, -p.dir)));
        }
        p.radiance += p.throughput * s.emitted * weight;
    }
    uint max_depth = path.max_depth == 0u ? 0xffffffffu : path.max_depth;
    if (p.depth >= max_depth) {
        return false;
    }
    if (cone_component(p)) {
        vec3 t = perpendicular(s.ns);
        vec3 axis = diffuse_cone_axis(s.ns, t, cross(s.ns, t), int(path.cone), int(path.ring));
        vec3 next = sample_cone(axis, path.cone_cos_half, p.rng);
        if (dot(s.ng, next) <= 0.0) {
            return false;
        }
        // Uniform within the cone: the mean radiance over it, times albedo as the
        // composite multiplies the gathered light. With `--cosine-cones` each ray
        // counts by its cosine to the normal over the cosine's mean over the cone,
        // cos(axis) (1 + cos(half-angle)) / 2: the cosine-weighted mean radiance in
        // the cone, which the gather's cone then stands for.
        float weight = 1.0;
        if (path.cone_cosine != 0u) {
            weight = max(dot(s.ns, next), 0.0) / (dot(s.ns, axis) * 0.5 * (1.0 + path.cone_cos_half));
        }
        p.throughput *= s.albedo * weight;
        p.bsdf_pdf = 0.0;
        p.origin = s.p + s.ng * rays.epsilon;
        p.dir = next;
        p.depth++;
        return true;
    }
    if (PATH_TRANSMISSION && s.transmit > 0.0 && random_next(p.rng) < s.transmit) {
        // The light passing the surface, refracted (reflected where it cannot leave):
        // a direction no other technique samples, so an emitter it reaches counts whole.
        vec3 bent = refract(p.dir, s.ng, 1.0 / s.eta);
        bool through = dot(bent, bent) > 0.0;
        p.dir = through ? normalize(bent) : reflect(p.dir, s.ng);
        p.origin = s.p + (through ? -s.ng : s.ng) * rays.epsilon;
        p.bsdf_pdf = 0.0;
        bool goes_on = survives(p);
        p.depth++;
        return goes_on;
    }
    vec3 from = s.p + s.ng * rays.epsilon;
    p.radiance += p.throughput * (delta_lights(s, from, p.rng) + emitter_light(s, from, p.rng));
    vec3 next = sample_bsdf(s, p.rng);
    float cos_next = dot(s.ns, next);
    float pdf = bsdf_pdf(s, next);
    if (cos_next <= 0.0 || dot(s.ng, next) <= 0.0 || pdf <= 0.0) {
        return false;
    }
    p.throughput *= brdf(s, next) * cos_next / pdf;
    p.bsdf_pdf = pdf;
    if (!survives(p)) {
        return false;
    }
    p.origin = from;
    p.dir = next;
    p.depth++;
    return true;
}

void main() {
    uvec2 pixel = gl_GlobalInvocationID.xy;
    bool inside = pixel.x < frame.width && pixel.y < frame.height;
    if (inside) {
        vec4 mean = push.samples_done > 0u ? imageLoad(path_mean, ivec2(pixel)) : vec4(0.0);
        vec3 batch = vec3(0.0);
        // One loop over the vertices of all this pixel's samples, the next path started
        // where one ends: neighbouring invocations run in SIMD lanes on a CPU driver, and
        // a loop per sample would hold every lane until the longest path of each ended.
        uint started = 0u;
        Path p;
        if (push.samples_now > 0u) {
            p = start_path(pixel, push.samples_done);
            started = 1u;
        }
        // The samples finished: a CPU driver may cut a long-running invocation's loops
        // short (`PathTracer`'s batches), and a cut sample is not counted.
        uint finished = 0u;
        while (started > 0u) {
            if (!extend(p)) {
                // A sample lost to a numerical failure counts as black rather than
                // poisoning the pixel's mean.
                bool failed = any(isnan(p.radiance)) || any(isinf(p.radiance));
                batch += failed ? vec3(0.0) : p.radiance;
                finished++;
                if (started == push.samples_now) {
                    break;
                }
                p = start_path(pixel, push.samples_done + started);
                started++;
            }
        }
        if (finished > 0u) {
            float n = float(finished);
            float count = mean.a + n;
            mean = vec4(mean.rgb + (batch - n * mean.rgb) / count, count);
            imageStore(path_mean, ivec2(pixel), mean);
        }
        imageStore(screen_radiance, ivec2(pixel), vec4(mean.rgb, 1.0));
    }
    uint first;
    SUBGROUP_ATOMIC_ADD(rays_cast, rays_here, first)
}
