#version 460
// The receivers' irradiance into the lightmap (Sedláček 2019, 3.3.1.3), an invocation
// per receiver: its row of U_k times its cluster's basis vectors, plus the sky it sees
// past every probe (the bake's sky factor × the sky's radiance), stored / π: the
// radiance a white Lambertian surface there reflects.
#include "common/frame.glsl"
#include "gi/probes/probes.glsl"

layout(local_size_x = PROBE_GROUP_SIZE) in;

layout(set = SET_GI, binding = BINDING_PROBE_RECEIVERS) uniform usamplerBuffer receivers;
layout(set = SET_GI, binding = BINDING_PROBE_COORDINATES) uniform samplerBuffer coordinates;
layout(set = SET_GI, binding = BINDING_PROBE_BASIS, std430) readonly buffer BasisBlock {
    vec4 basis[];
};
layout(set = SET_GI, binding = BINDING_PROBE_LIGHTMAP, rgba16f) uniform writeonly image2D lightmap;

void main() {
    uint r = gl_GlobalInvocationID.x;
    if (r >= probes.receiver_count) {
        return;
    }
    uvec4 receiver = texelFetch(receivers, int(r));
    vec3 e = frame.sky_radiance.rgb * texelFetch(coordinates, int(probes.sky_offset + r)).r;
    for (uint k = 0u; k < receiver.w; k++) {
        e += texelFetch(coordinates, int(receiver.y + k)).r * basis[receiver.z + k].rgb;
    }
    ivec2 texel = ivec2(receiver.x & 0xFFFFu, receiver.x >> 16u);
    imageStore(lightmap, texel, vec4(max(e, vec3(0.0)) / PI, 1.0));
}
