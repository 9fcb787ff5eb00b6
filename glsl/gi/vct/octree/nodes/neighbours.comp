#version 460
// The six neighbours of every node of `push.level` at the same level, found by descending
// from the root (Dřínovský 2013, 5.2.2: a separate pass once the level is complete).
#include "gi/vct/octree/nodes/level.glsl"

void main() {
    uint node;
    if (!level_node(node)) {
        return;
    }
    ivec3 c = ivec3(unpack_coord(node_coords[node]));
    int side = 1 << push.level;
    uint shift = octree_depth() - push.level;
    for (int d = 0; d < 6; d++) {
        ivec3 step = ivec3(0);
        step[d / 2] = (d % 2 == 0) ? 1 : -1;
        ivec3 n = c + step;
        uint neighbour = OCTREE_NO_NODE;
        if (all(greaterThanEqual(n, ivec3(0))) && all(lessThan(n, ivec3(side)))) {
            neighbour = find_node(uvec3(n) << shift, push.level);
        }
        node_neighbours[6u * node + uint(d)] = neighbour;
    }
}
