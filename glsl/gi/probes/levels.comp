#version 460
// The lightmap's coarser levels (Sedláček 2019, 4.2.3): each texel of mips 1 to 3 this
// frame computes (`BINDING_PROBE_WORK`, `src/gi/probes/levels.rs`) takes the irradiance its
// receiver's texel holds at mip 0, which `probe_receivers` wrote this frame.
#include "common/frame.glsl"
#define PROBE_RECEIVERS
#include "gi/probes/probes.glsl"

layout(local_size_x = PROBE_GROUP_SIZE) in;

layout(set = SET_GI, binding = BINDING_PROBE_LIGHTMAP, rgba16f) uniform readonly image2D lightmap;
layout(set = SET_GI, binding = BINDING_PROBE_LIGHTMAP_LEVELS, rgba16f) uniform writeonly image2D levels[3];

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= work[1]) {
        return;
    }
    uint at = 2u + work[0] + 2u * i;
    uint texel = work[at];
    uint r = work[at + 1u] & 0x3FFFFFFFu;
    uint level = work[at + 1u] >> 30u;
    uint source = texelFetch(receivers, int(r)).x;
    vec4 e = imageLoad(lightmap, ivec2(source & 0xFFFFu, source >> 16u));
    ivec2 to = ivec2(texel & 0xFFFFu, texel >> 16u);
    // Constant indices: the array needs no dynamic indexing.
    if (level == 1u) {
        imageStore(levels[0], to, e);
    } else if (level == 2u) {
        imageStore(levels[1], to, e);
    } else {
        imageStore(levels[2], to, e);
    }
}
