#version 460
// The receivers' irradiance into the lightmap (Sedláček 2019, 3.3.1.3), an invocation
// per receiver this frame computes (`BINDING_PROBE_WORK`; all of them without the level of
// detail), stored / π: the radiance a white Lambertian surface there reflects.
#include "common/frame.glsl"
#define PROBE_RECEIVERS
#include "gi/probes/probes.glsl"

layout(local_size_x = PROBE_GROUP_SIZE) in;

layout(set = SET_GI, binding = BINDING_PROBE_LIGHTMAP, rgba16f) uniform writeonly image2D lightmap;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= work[0]) {
        return;
    }
    uint r = work[2u + i];
    uint texel = texelFetch(receivers, int(r)).x;
    imageStore(lightmap, ivec2(texel & 0xFFFFu, texel >> 16u), vec4(receiver_irradiance(r) / PI, 1.0));
}
