#version 460
// Initialises the nodes just appended to a level: no children, not flagged, no brick (the
// pool is not cleared between builds; `alloc.comp` already wrote their coordinates).
#include "gi/vct/octree/nodes/level.glsl"

void main() {
    uint node;
    if (!level_node(node)) {
        return;
    }
    node_children[node] = 0u;
    node_bricks[node] = OCTREE_NO_BRICK;
}
