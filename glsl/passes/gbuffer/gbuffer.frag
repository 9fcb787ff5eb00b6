#version 460
// variant: NORMAL_MAPS
// variant: TRIANGLE_IDS
// variant: NORMAL_MAPS TRIANGLE_IDS
// Writes the surface attributes the lighting pass needs; position comes from depth.
#include "common/frame.glsl"
#include "common/scene.glsl"
#include "common/mesh_push.glsl"

layout(location = 0) in vec3 in_world;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;
layout(location = 0) out vec4 out_albedo;   // rgb albedo, a specular (mean Ks)
layout(location = 1) out vec4 out_normal;   // xyz world normal facing the camera, w roughness
layout(location = 2) out vec4 out_emission; // rgb emitted radiance
layout(location = 3) out vec2 out_transmission; // transmittance (1 - d), index of refraction
layout(location = 4) out uint out_triangle;     // the triangle's index in the scene + 1 (0: none)

#ifdef NORMAL_MAPS
// Perturbs n by a tangent-space normal map with a cotangent frame from screen-space
// derivatives (Schüler, "Normal mapping without precomputed tangents"), so meshes need
// no tangents. The frame's two vectors are the gradients of u and v only up to the sign
// of n . (dp1 x dp2), which the normalisation drops: with Vulkan's framebuffer y running
// down, a surface facing the camera has it negative, and without the sign the map's
// tilts came out mirrored (the path tracer, which takes the triangle's edges, showed it).
vec3 apply_normal_map(vec3 n) {
    vec3 dp1 = dFdx(in_world);
    vec3 dp2 = dFdy(in_world);
    vec2 duv1 = dFdx(in_uv);
    vec2 duv2 = dFdy(in_uv);
    vec3 dp2perp = cross(dp2, n);
    vec3 dp1perp = cross(n, dp1);
    vec3 t = dp2perp * duv1.x + dp1perp * duv2.x;
    vec3 b = dp2perp * duv1.y + dp1perp * duv2.y;
    float len = max(dot(t, t), dot(b, b));
    // No uv change across the pixel (len is |dp|^2 |duv|^2: relative to |dp|^2, so that
    // the test does not depend on the scene's units).
    if (len <= 1e-20 * max(dot(dp1, dp1), dot(dp2, dp2))) {
        return n;
    }
    float scale = dot(n, cross(dp1, dp2)) < 0.0 ? -inversesqrt(len) : inversesqrt(len);
    vec3 m = texture(normal_texture, in_uv).xyz * 2.0 - 1.0;
    // Our v runs down the image (Vertex.uv), the map's green axis runs up it.
    m.y = -m.y;
    vec3 mapped = normalize(mat3(t * scale, b * scale, n) * m);
    return any(isnan(mapped)) ? n : mapped;
}
#endif

void main() {
    GpuMaterial m = materials[draw.material];
    // Cut-outs come from map_d. With transmission (it needs the voxels), a surface with a
    // uniform d < 1 is drawn and the GI passes the rest of the light through it; without,
    // it counts as a cut-out below half opacity, like in the shadow maps.
    bool transmission = (frame.flags & FLAG_TRANSMISSION) != 0u;
    float coverage = transmission ? material_cutout(m, in_uv) : material_coverage(m, in_uv);
    if (coverage < CUTOUT_THRESHOLD) {
        discard;
    }
    vec3 to_camera = frame.camera_position.xyz - in_world;
    vec3 n = normalize(in_normal);
    // Emitters are one-sided along the winding normal, surfaces are two-sided.
    bool front = dot(n, to_camera) >= 0.0;
    if (!front) {
        n = -n;
    }
    // Normal mapping has its own variant: lavapipe draws the G-buffer 15 % slower with
    // the code merely compiled in.
#ifdef NORMAL_MAPS
    if (m.normal_texture != NO_TEXTURE) {
        n = apply_normal_map(n);
    }
#endif
    float specular = (frame.flags & FLAG_SPECULAR) != 0u ? dot(m.specular.rgb, vec3(1.0 / 3.0)) : 0.0;
    out_albedo = vec4(material_albedo(m, in_uv), specular);
    out_normal = vec4(n, m.specular.a);
    out_emission = vec4(front ? material_emission(m, in_uv) : vec3(0.0), 0.0);
    out_transmission = vec2(transmission ? 1.0 - m.albedo.a : 0.0, m.emission.a);
    // The scene's meshes lie in its index buffer in order, so a mesh's first triangle is a
    // third of its first index. gl_PrimitiveID needs the geometry-shader feature: without
    // it, the variant without TRIANGLE_IDS writes 0, no triangle.
#ifdef TRIANGLE_IDS
    out_triangle = draw.first_index / 3u + uint(gl_PrimitiveID) + 1u;
#else
    out_triangle = 0u;
#endif
}
