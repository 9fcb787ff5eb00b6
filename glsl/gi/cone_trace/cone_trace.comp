#version 460
// Indirect diffuse light by voxel cone tracing (Crassin et al. 2011): for one G-buffer
// pixel of each indirect_scale² block, cosine-weighted cones over the normal's hemisphere
// are marched front to back through the voxel radiance, the sky filling what they leave
// unoccluded. The upsample pass spreads the result to every pixel.
#include "gi/cones.glsl"
#include "gi/cone_trace/screen.glsl"

layout(local_size_x = SCREEN_GROUP_SIZE, local_size_y = SCREEN_GROUP_SIZE) in;
layout(set = SET_PASS, binding = BINDING_GI_INDIRECT, rgba16f) uniform writeonly image2D indirect;

void main() {
    ivec2 low = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(low, imageSize(indirect)))) {
        return;
    }
    ivec2 pixel = representative(low);
    float depth = texelFetch(gbuffer_depth, pixel, 0).r;
    if (depth >= 1.0) {
        imageStore(indirect, low, vec4(0.0));
        return;
    }
    vec3 p = pixel_position(pixel, depth);
    vec3 n = normalize(imageLoad(gbuffer_normal, pixel).xyz);
    // Start two voxels off the surface so the cones do not gather their own voxels, and
    // sample no finer than 2-voxel cells (the base level adds nothing measurable here:
    // Cornell box LDR-FLIP 0.1801 either way).
    vec3 gathered = gather_diffuse(p, p + n * (2.0 * gi.origin.w), n, 1.0);
    imageStore(indirect, low, vec4(gathered, 1.0));
}
