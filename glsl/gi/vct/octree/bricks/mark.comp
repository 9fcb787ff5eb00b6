#version 460
// Around moving meshes: puts every node of `push.level` within one node of the region
// where they were last frame or are now on the level's changed list. A frame appends
// their nodes anew and drops last frame's, so the light there changed even where voxel
// shading finds the same values; the neighbours of a node that vanished with its brick
// must copy their borders again, hence the margin of one node.
#include "gi/vct/octree/nodes/level.glsl"

void main() {
    uint node;
    if (!level_node(node)) {
        return;
    }
    uint brick = node_bricks[node];
    if (brick == OCTREE_NO_BRICK) {
        return;
    }
    int size = 1 << (octree_depth() - push.level);
    ivec3 first = ivec3(unpack_coord(node_coords[node])) * size;
    ivec3 last = first + size - 1;
    if (any(lessThan(last, push.region_min.xyz - size)) || any(greaterThan(first, push.region_max.xyz + size))) {
        return;
    }
    mark_node(node, brick, push.level, OCTREE_CHANGED, changed_list(push.level));
}
