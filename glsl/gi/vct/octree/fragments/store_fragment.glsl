// The octree's `store_voxel` for the voxelization (gi/voxelize/coverage.glsl): appends
// one record per voxel fragment to the voxel-fragment list, through an atomic counter
// (Dřínovský 2013, 5.2.1). Past the list's capacity fragments are counted but not
// stored: the host sees the overflow, grows the list and builds again. The invocation
// that opens a workgroup's worth of records raises the indirect dispatch of the passes
// over the fragments (those from `counters.fragment_base` on).
#ifndef STORE_FRAGMENT_GLSL
#define STORE_FRAGMENT_GLSL
#include "gi/vct/octree/octree.glsl"

#ifdef SUBGROUP_APPEND
#include "common/subgroup_add.glsl"
// The compute voxelizer's lanes take their records together with their subgroup.
uint append_fragment() {
    uint index;
    SUBGROUP_ATOMIC_ADD(counters.fragment_count, 1u, index)
    return index;
}
#else
uint append_fragment() {
    return atomicAdd(counters.fragment_count, 1u);
}
#endif

// The coverage across x, y and z rides in the alpha of the albedo, normal and emission.
void store_voxel(ivec3 voxel, vec3 albedo, vec3 normal, vec3 emission, vec3 coverage) {
    uint index = append_fragment();
    if (index >= counters.fragment_capacity) {
        atomicOr(counters.overflow, OCTREE_OVERFLOW_FRAGMENTS);
        return;
    }
    fragment_voxels[index] = pack_coord(uvec3(voxel));
    vec3 c = clamp(coverage, 0.0, 1.0) * 255.0;
    fragment_voxels[counters.fragment_capacity + index] = pack_rgba8(vec4(albedo * 255.0, c.x));
    fragment_shading[index] = uvec2(pack_rgba8(vec4(normal * 255.0, c.y)), pack_rgba8(vec4(emission * 255.0, c.z)));
    uint read = index - counters.fragment_base;
    if (read % OCTREE_GROUP_SIZE == 0u) {
        atomicMax(counters.fragment_groups_x, read / OCTREE_GROUP_SIZE + 1u);
    }
}
#endif
