#version 460
// One invocation, before a bounce in a static octree: the bounce runs over the voxel list
// while anything changed since the last one (a node on an update list, a voxel's direct
// light), and not at all once the bounces have converged: it would store the same light.
#define OCTREE
#include "gi/vct/octree/octree.glsl"
#include "gi/vct/voxel_list.glsl"

layout(local_size_x = 1) in;

void main() {
    bounce_dispatch.groups_x = bounce_dispatch.changed != 0u ? list.groups_x : 0u;
    bounce_dispatch.groups_y = 1u;
    bounce_dispatch.groups_z = 1u;
    bounce_dispatch.changed = 0u;
}
