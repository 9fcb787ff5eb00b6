#version 460
// Initialises the nodes of a new level: no children, not flagged (the pool is not
// cleared between builds; `alloc.comp` already wrote their coordinates).
#include "svo/octree/level.glsl"

void main() {
    uint node;
    if (!level_node(node)) {
        return;
    }
    node_children[node] = 0u;
}
