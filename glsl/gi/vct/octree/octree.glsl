// Set 3 of the octree store's passes, after the bindings every store shares
// (`gi/vct/voxels.glsl`): the sparse voxel octree's pools (Crassin & Green 2012;
// Dřínovský 2013, 5.2). Level 0 is the root; a node at level l covers 2^(depth - l)
// voxels of the effective 2^depth grid along each axis; the leaves, at level depth - 1,
// hold 2x2x2 voxels in their bricks.
#ifndef OCTREE_GLSL
#define OCTREE_GLSL
#include "gi/vct/voxels.glsl"

layout(set = SET_GI, binding = BINDING_OCTREE_COUNTERS, std430) buffer CountersBlock {
    OctreeCounters counters;
    OctreeLevel levels[OCTREE_MAX_LEVELS];
};
// Fragment i: its voxel in fragment_voxels[i] and its albedo in
// fragment_voxels[counters.fragment_capacity + i] (the octree's passes read only the
// voxels, contiguous), normal and emission in fragment_shading[i].
layout(set = SET_GI, binding = BINDING_OCTREE_FRAGMENTS, std430) buffer FragmentsBlock {
    uint fragment_voxels[];
};
layout(set = SET_GI, binding = BINDING_OCTREE_FRAGMENT_SHADING, std430) buffer ShadingBlock {
    uvec2 fragment_shading[];
};
layout(set = SET_GI, binding = BINDING_OCTREE_NODES, std430) buffer NodesBlock {
    uint node_children[];
};
layout(set = SET_GI, binding = BINDING_OCTREE_NODE_COORDS, std430) buffer CoordsBlock {
    uint node_coords[];
};
layout(set = SET_GI, binding = BINDING_OCTREE_NODE_BRICKS, std430) buffer BricksBlock {
    uint node_bricks[];
};
layout(set = SET_GI, binding = BINDING_OCTREE_NEIGHBOURS, std430) buffer NeighboursBlock {
    uint node_neighbours[];
};
layout(set = SET_GI, binding = BINDING_OCTREE_SUMS, std430) buffer SumsBlock {
    uint leaf_sums[];
};
layout(set = SET_GI, binding = BINDING_OCTREE_CARRY, std430) buffer CarryBlock {
    uint carry[];
};
layout(set = SET_GI, binding = BINDING_OCTREE_STATIC_NODES, std430) readonly buffer StaticBlock {
    uint static_children[];
};
layout(set = SET_GI, binding = BINDING_OCTREE_CHANGES, std430) buffer ChangesBlock {
    uint brick_changes[];
};
layout(set = SET_GI, binding = BINDING_OCTREE_NODE_GRID, std430) buffer NodeGridBlock {
    uint node_grid[];
};
layout(set = SET_GI, binding = BINDING_OCTREE_UPDATES, std430) buffer UpdatesBlock {
    OctreeUpdateList update_lists[OCTREE_UPDATE_LISTS];
    OctreeBounceDispatch bounce_dispatch;
    uint update_nodes[];
};

// Mask of a child entry's tile index.
#define OCTREE_CHILD_MASK (~OCTREE_SUBDIVIDE)

// findMSB(vct.resolution), fixed when the pipeline is made (see SPEC_OCTREE_DEPTH).
layout(constant_id = SPEC_OCTREE_DEPTH) const uint OCTREE_DEPTH = 0u;

uint octree_depth() {
    return OCTREE_DEPTH;
}

uint pack_coord(uvec3 c) {
    return c.x | (c.y << 10) | (c.z << 20);
}

uvec3 unpack_coord(uint p) {
    return uvec3(p & 0x3ffu, (p >> 10) & 0x3ffu, p >> 20);
}

// Which child of its level-`level` ancestor holds voxel `v` (x | y << 1 | z << 2).
uint child_octant(uvec3 v, uint level) {
    uvec3 bit = (v >> (octree_depth() - level - 1u)) & 1u;
    return bit.x | (bit.y << 1) | (bit.z << 2);
}

// The node at `level` whose cube holds voxel `v` of the effective grid, descending from
// `node` at level `from`, or OCTREE_NO_NODE where the octree has no node there; `empty` is
// then the level of the childless node where the descent stopped, whose whole cube is
// empty.
uint find_node_below(uint node, uint from, uvec3 v, uint level, out uint empty) {
    for (uint l = from; l < level; l++) {
        uint tile = node_children[node] & OCTREE_CHILD_MASK;
        if (tile == 0u) {
            empty = l;
            return OCTREE_NO_NODE;
        }
        node = tile + child_octant(v, l);
    }
    empty = level;
    return node;
}

// The same from the root.
uint find_node_or_gap(uvec3 v, uint level, out uint empty) {
    return find_node_below(0u, 0u, v, level, empty);
}

uint find_node(uvec3 v, uint level) {
    uint empty;
    return find_node_or_gap(v, level, empty);
}

// The level of the node grid (`BINDING_OCTREE_NODE_GRID`).
uint node_grid_level() {
    return octree_depth() - 1u - OCTREE_NODE_GRID_ABOVE_LEAVES;
}

// As find_node_or_gap, from the node grid at and below its level: for the passes after
// the octree's levels and the grid are built (brick fill, voxel list on, every pass of a
// frame's shading, filtering and tracing); the build's own passes descend from the root.
uint find_node_or_gap_gridded(uvec3 v, uint level, out uint empty) {
    uint g = node_grid_level();
    uint node = 0u;
    uint from = 0u;
    if (level >= g) {
        uvec3 cell = v >> (octree_depth() - g);
        uint side = 1u << g;
        node = node_grid[cell.x + side * (cell.y + side * cell.z)];
        if (node >= OCTREE_GRID_GAP) {
            empty = node - OCTREE_GRID_GAP;
            return OCTREE_NO_NODE;
        }
        from = g;
    }
    return find_node_below(node, from, v, level, empty);
}

uint find_node_gridded(uvec3 v, uint level) {
    uint empty;
    return find_node_or_gap_gridded(v, level, empty);
}

// Which of its leaf's 8 voxels voxel v is (x | y << 1 | z << 2).
uint leaf_octant(uvec3 v) {
    uvec3 k = v & 1u;
    return k.x | (k.y << 1) | (k.z << 2);
}

// The first word of the sums of voxel `octant` of a leaf whose child entry is `entry`
// (its occupied voxels' mask and first sum); the voxel must be occupied.
uint leaf_sum_base(uint entry, uint octant) {
    uint before = bitCount(entry & ((1u << octant) - 1u) & 0xffu);
    return VOXEL_SUM_WORDS * ((entry >> 8) + uint(before));
}

// The texel of voxel v in its leaf's attribute bricks; false where no leaf holds it.
bool leaf_texel(uvec3 v, out ivec3 texel) {
    uint leaf = find_node_gridded(v, octree_depth() - 1u);
    uint brick = leaf == OCTREE_NO_NODE ? OCTREE_NO_BRICK : node_bricks[leaf];
    texel = ivec3(0);
    if (brick == OCTREE_NO_BRICK) {
        return false;
    }
    uint side = counters.leaf_pool_side;
    texel = ivec3(brick % side, (brick / side) % side, brick / (side * side)) * int(OCTREE_ATTRIBUTE_BRICK) + ivec3(v & 1u);
    return true;
}

// The node at `level` at offset `step` (each -1, 0 or 1) from `node` at `coords`: through
// the neighbour pointers (one to three hops), or searched from the node grid where a hop
// meets no link (a diagonal neighbour can exist beside missing face neighbours; a static node
// has no links to the nodes a frame appends).
uint offset_node(uint node, ivec3 coords, ivec3 step, uint level) {
    uint n = node;
    for (int axis = 0; axis < 3 && n != OCTREE_NO_NODE; axis++) {
        if (step[axis] != 0) {
            n = node_neighbours[6u * n + uint(2 * axis + (step[axis] > 0 ? 0 : 1))];
        }
    }
    if (n == OCTREE_NO_NODE) {
        ivec3 at = coords + step;
        int side = 1 << level;
        if (any(lessThan(at, ivec3(0))) || any(greaterThanEqual(at, ivec3(side)))) {
            return OCTREE_NO_NODE;
        }
        n = find_node_gridded(uvec3(at) << (octree_depth() - level), level);
    }
    return n;
}

// The filter's update lists (Dřínovský 2013, 5.5), by level parity: which nodes changed
// (`OCTREE_CHANGED`) and whose borders must be copied again (`OCTREE_BORDER`). A brick's change
// word records the bits already given, so each node enters a list once.
uint changed_list(uint level) {
    return level & 1u;
}

uint border_list(uint level) {
    return 2u + (level & 1u);
}

uint change_slot(uint brick, uint level) {
    return level + 1u == octree_depth() ? brick : counters.leaf_brick_capacity + brick;
}

// Gives `node` (of `level`, with `brick`) `bit`, and appends it to `list` the first time.
void mark_node(uint node, uint brick, uint level, uint bit, uint list) {
    if ((atomicOr(brick_changes[change_slot(brick, level)], bit) & bit) != 0u) {
        return;
    }
    bounce_dispatch.changed = 1u;
    uint i = atomicAdd(update_lists[list].count, 1u);
    if (i >= counters.update_capacity) {
        return;
    }
    update_nodes[list * counters.update_capacity + i] = node;
    if (i % OCTREE_GROUP_SIZE == 0u) {
        atomicMax(update_lists[list].groups_x, i / OCTREE_GROUP_SIZE + 1u);
    }
}

// The carried light tables (open addressing, linear probing; 4 words an entry): the
// light a voxel gathered last frame, found by its coordinates after the octree was rebuilt.
uint carry_slot(uint key, uint probe) {
    uint h = key * 2654435761u;
    return (h ^ (h >> 15)) + probe & (counters.carry_capacity - 1u);
}

// Records what voxel v gathered this frame.
void carry_store(uvec3 v, vec3 gathered) {
    uint key = pack_coord(v) + 1u;
    uint base = counters.carry_parity * counters.carry_capacity;
    for (uint probe = 0u; probe < counters.carry_capacity; probe++) {
        uint entry = base + carry_slot(key, probe);
        uint found = atomicCompSwap(carry[4u * entry], 0u, key);
        if (found == 0u || found == key) {
            carry[4u * entry + 1u] = floatBitsToUint(gathered.r);
            carry[4u * entry + 2u] = floatBitsToUint(gathered.g);
            carry[4u * entry + 3u] = floatBitsToUint(gathered.b);
            return;
        }
    }
}

// What voxel v gathered last frame (zero if it was not there).
vec3 carry_load(uvec3 v) {
    uint key = pack_coord(v) + 1u;
    uint base = (counters.carry_parity ^ 1u) * counters.carry_capacity;
    for (uint probe = 0u; probe < counters.carry_capacity; probe++) {
        uint entry = base + carry_slot(key, probe);
        uint found = carry[4u * entry];
        if (found == key) {
            return uintBitsToFloat(uvec3(carry[4u * entry + 1u], carry[4u * entry + 2u], carry[4u * entry + 3u]));
        }
        if (found == 0u) {
            break;
        }
    }
    return vec3(0.0);
}

// The corner texel of brick `slot` in a pool of `side`³ bricks of `edge`³ texels.
ivec3 brick_origin(uint slot, uint side, uint edge) {
    return ivec3(slot % side, (slot / side) % side, slot / (side * side)) * int(edge);
}
#endif
