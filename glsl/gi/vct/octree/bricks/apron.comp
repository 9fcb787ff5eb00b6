#version 460
// Border transfer (Dřínovský 2013, 5.4.2; Crassin's brick borders): the one-voxel border
// of every brick of level `push.level` gets the values of the neighbouring bricks'
// voxels there, so that trilinear filtering anywhere inside a node reads what the dense
// grid would. The neighbour holding a border voxel is reached through the neighbour
// pointers (one to three hops); where a hop meets no node, the octree is searched from
// the root (a diagonal neighbour can exist beside missing face neighbours). At the grid's
// edge the border repeats the edge voxel, as the dense sampler clamps to its edge. Over
// an update list, the node's change bits are cleared for the next filter.
#include "gi/vct/octree/nodes/level.glsl"

layout(set = SET_GI, binding = BINDING_VCT_RADIANCE, rgba16f) uniform image3D leaf_radiance;
// The leaves' coverage shares their radiance's bricks and borders.
layout(set = SET_GI, binding = BINDING_VCT_COVERAGE, rgba8) uniform image3D leaf_coverage;
layout(set = SET_GI, binding = BINDING_OCTREE_DIRECTIONAL_STORAGE, rgba16f) uniform image3D directional;

void main() {
    uint node;
    if (!level_node(node) || node_bricks[node] == OCTREE_NO_BRICK) {
        return;
    }
    bool leaf = push.level + 1u == octree_depth();
    uint side = leaf ? counters.leaf_pool_side : counters.interior_pool_side;
    int direction_stride = int(side * OCTREE_RADIANCE_BRICK);
    ivec3 origin = brick_origin(node_bricks[node], side, OCTREE_RADIANCE_BRICK) + 1;
    ivec3 coords = ivec3(unpack_coord(node_coords[node]));
    int last = (2 << push.level) - 1;
    for (int i = first_item(); i < 64; i += item_step()) {
        ivec3 t = ivec3(i & 3, (i >> 2) & 3, i >> 4) - 1;
        if (all(greaterThanEqual(t, ivec3(0))) && all(lessThanEqual(t, ivec3(1)))) {
            continue;
        }
        ivec3 g = clamp(coords * 2 + t, ivec3(0), ivec3(last));
        ivec3 step = (g >> 1) - coords;
        uint owner = all(equal(step, ivec3(0))) ? node : offset_node(node, coords, step, push.level);
        uint brick = owner == OCTREE_NO_NODE ? OCTREE_NO_BRICK : node_bricks[owner];
        ivec3 from = brick == OCTREE_NO_BRICK ? ivec3(0) : brick_origin(brick, side, OCTREE_RADIANCE_BRICK) + 1 + (g & 1);
        if (leaf) {
            vec4 value = brick == OCTREE_NO_BRICK ? vec4(0.0) : imageLoad(leaf_radiance, from);
            imageStore(leaf_radiance, origin + t, value);
            vec4 coverage = brick == OCTREE_NO_BRICK ? vec4(0.0) : imageLoad(leaf_coverage, from);
            imageStore(leaf_coverage, origin + t, coverage);
        } else {
            for (int d = 0; d < int(directional_slots()); d++) {
                ivec3 shift = ivec3(d * direction_stride, 0, 0);
                vec4 value = brick == OCTREE_NO_BRICK ? vec4(0.0) : imageLoad(directional, from + shift);
                imageStore(directional, origin + t + shift, value);
            }
        }
    }
    if (first_item() == 0) {
        brick_changes[change_slot(node_bricks[node], push.level)] = 0u;
    }
}
