#version 460
// Builds the filter's update lists one level up (Dřínovský 2013, 5.5), over the nodes of
// `push.level` whose radiance changed (voxel shading lists the leaves whose voxels it
// changed; this pass lists their parents): each such node and its 26 neighbours get their
// borders copied again, and its parent is filtered again and changes in turn.
#include "gi/vct/octree/nodes/level.glsl"

void main() {
    uint node;
    if (!level_node(node)) {
        return;
    }
    ivec3 coords = ivec3(unpack_coord(node_coords[node]));
    for (int i = first_item(); i < 27; i += item_step()) {
        ivec3 step = ivec3(i % 3, (i / 3) % 3, i / 9) - 1;
        uint n = all(equal(step, ivec3(0))) ? node : offset_node(node, coords, step, push.level);
        uint brick = n == OCTREE_NO_NODE ? OCTREE_NO_BRICK : node_bricks[n];
        if (brick != OCTREE_NO_BRICK) {
            mark_node(n, brick, push.level, OCTREE_BORDER, border_list(push.level));
        }
    }
    if (push.level == 0u || first_item() != 0) {
        return;
    }
    uint parent_level = push.level - 1u;
    uint parent = find_node_gridded(uvec3(coords) << (octree_depth() - push.level), parent_level);
    uint brick = parent == OCTREE_NO_NODE ? OCTREE_NO_BRICK : node_bricks[parent];
    if (brick != OCTREE_NO_BRICK) {
        mark_node(parent, brick, parent_level, OCTREE_CHANGED, changed_list(parent_level));
    }
}
