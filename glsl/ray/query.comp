#version 460
// Batched ray queries: one invocation per `RayQuery`, its closest or any hit into `RayHit`
// (a triangle's index in the scene, the distance and the barycentric coordinates).
#include "ray/rays.glsl"

layout(local_size_x = RAY_GROUP_SIZE) in;
layout(set = SET_GI, binding = BINDING_QUERY_RAYS, std430) readonly buffer QueryBlock {
    RayQuery queries[];
};
layout(set = SET_GI, binding = BINDING_QUERY_HITS, std430) writeonly buffer HitBlock {
    RayHit hits[];
};
layout(push_constant) uniform Push {
    uint query_count;
};

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= query_count) {
        return;
    }
    RayQuery q = queries[i];
    RayHit answer = RayHit(RAY_NONE, q.direction_tmax.w, 0.0, 0.0);
    if (q.kind == RAY_ANY) {
        if (trace_any(q.origin_tmin.xyz, q.direction_tmax.xyz, q.origin_tmin.w, q.direction_tmax.w, 0u)) {
            answer.triangle = 0u;
        }
    } else {
        Hit hit;
        if (trace_closest(q.origin_tmin.xyz, q.direction_tmax.xyz, q.origin_tmin.w, q.direction_tmax.w, 0u, hit)) {
            answer = RayHit(floatBitsToUint(ray_triangle(hit.triangle).e1.w), hit.t, hit.bary.x, hit.bary.y);
        }
    }
    hits[i] = answer;
}
