#version 460
// The grid of spatial receivers (Sedláček 2019, 4.1 and 4.2.3), an invocation per
// receiver the host listed this frame (the points whose trilinear lookups a moving mesh's
// box reaches): its irradiance / π into its direction's slab of the grid.
#include "common/frame.glsl"
#define PROBE_RECEIVERS
#include "gi/probes/probes.glsl"

layout(local_size_x = PROBE_GROUP_SIZE) in;

layout(set = SET_GI, binding = BINDING_PROBE_GRID_ACTIVE, std430) readonly buffer ActiveBlock {
    uint grid_active[];
};
layout(set = SET_GI, binding = BINDING_PROBE_GRID, rgba16f) uniform writeonly image3D grid;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= grid_active[GRID_ACTIVE_RECEIVERS]) {
        return;
    }
    uint r = grid_active[GRID_ACTIVE_LIST + grid_active[GRID_ACTIVE_VECTORS] + i];
    uint s = r - probes.receiver_count;
    uvec3 size = probes.grid_size.xyz;
    uint d = s / probes.grid_size.w;
    uint p = s % probes.grid_size.w;
    ivec3 texel = ivec3(p % size.x, p / size.x % size.y, p / (size.x * size.y) + d * size.z);
    imageStore(grid, texel, vec4(receiver_irradiance(r) / PI, 1.0));
}
