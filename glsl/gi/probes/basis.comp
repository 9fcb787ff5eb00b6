#version 460
// The clusters' basis vectors (Sedláček 2019, 3.3.1.3), an invocation per vector: row i
// of a cluster's (Σ V^T)_k times its probes' harmonics stacked, b_i = Σ_p Σ_j P_i,pj λ_pj.
// Every vector of the lightmap's clusters, then those of the grid's clusters the host
// listed this frame (4.2.3: only the grid near moving meshes is computed).
#include "gi/probes/probes.glsl"

layout(local_size_x = PROBE_GROUP_SIZE) in;
layout(constant_id = 0) const uint COEFFICIENTS = 16u;

layout(set = SET_GI, binding = BINDING_PROBE_VECTORS) uniform usamplerBuffer vectors;
layout(set = SET_GI, binding = BINDING_PROBE_CLUSTER_PROBES) uniform usamplerBuffer cluster_probes;
layout(set = SET_GI, binding = BINDING_PROBE_PROJECTIONS) uniform samplerBuffer projections;
layout(set = SET_GI, binding = BINDING_PROBE_LAMBDA_TEXELS) uniform samplerBuffer lambda;
layout(set = SET_GI, binding = BINDING_PROBE_BASIS, std430) writeonly buffer BasisBlock {
    vec4 basis[];
};
layout(set = SET_GI, binding = BINDING_PROBE_GRID_ACTIVE, std430) readonly buffer ActiveBlock {
    uint grid_active[];
};
layout(set = SET_GI, binding = BINDING_PROBE_LOD, std430) readonly buffer LodBlock {
    uint lod[];
};

void main() {
    uint v = gl_GlobalInvocationID.x;
    if (v >= probes.vector_count) {
        uint listed = v - probes.vector_count;
        if (listed >= grid_active[GRID_ACTIVE_VECTORS]) {
            return;
        }
        v = grid_active[GRID_ACTIVE_LIST + listed];
    }
    uvec4 vector = texelFetch(vectors, int(v));
    // The level of detail (4.2.2): the cluster's first coefficients of each probe, no
    // more than the probe's relight projected this frame (the rest of its λ is stale).
    uint wanted = lod[probes.probe_count + vector.w];
    vec3 b = vec3(0.0);
    for (uint k = 0u; k < vector.y; k++) {
        uint probe = texelFetch(cluster_probes, int(vector.x + k)).r;
        uint count = min(wanted, lod[probe] & 0xFFFFu);
        uint first = probe * COEFFICIENTS;
        int at = int(vector.z + k * COEFFICIENTS);
        for (uint j = 0u; j < count; j++) {
            b += texelFetch(projections, at + int(j)).r * texelFetch(lambda, int(first + j)).rgb;
        }
    }
    basis[v] = vec4(b, 0.0);
}
