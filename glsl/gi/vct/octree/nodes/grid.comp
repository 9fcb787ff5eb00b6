#version 460
// The node grid (`BINDING_OCTREE_NODE_GRID`), after the octree's levels: per cell of level
// `node_grid_level()`, the node there or the level from which its cube is empty, so that
// a cone sample's descent starts there instead of at the root (at depth 10, three levels
// above the leaves instead of nine).
#include "gi/vct/octree/octree.glsl"

layout(local_size_x = OCTREE_GROUP_SIZE) in;

void main() {
    uint g = node_grid_level();
    uint side = 1u << g;
    uint i = gl_GlobalInvocationID.x;
    if (i >= side * side * side) {
        return;
    }
    uvec3 cell = uvec3(i % side, (i / side) % side, i / (side * side));
    uint empty;
    uint node = find_node_or_gap(cell << (octree_depth() - g), g, empty);
    node_grid[i] = node == OCTREE_NO_NODE ? OCTREE_GRID_GAP + empty : node;
}
