#version 460
// The interior bricks of level `push.level`, bottom-up (Dřínovský 2013, 5.4.3): brick
// voxel o of a node is its child o filtered to one voxel along each of the six
// directions (gi/vct/anisotropic.glsl), from the child's brick: the leaves' isotropic
// radiance seen through their normals' facing weight, or an interior child's directional
// radiance. Empty children count as empty space. With the planes (PLANE_OCCLUSION) the
// two slots after the six directions get the child's surface plane and coverage, as the
// dense grid's filter computes them (dense/filter.comp, filter_plane).
#include "gi/vct/octree/nodes/level.glsl"
#include "gi/vct/anisotropic.glsl"

layout(set = SET_GI, binding = BINDING_VCT_NORMAL, r32ui) uniform readonly uimage3D leaf_normal;
layout(set = SET_GI, binding = BINDING_VCT_RADIANCE, rgba16f) uniform readonly image3D leaf_radiance;
layout(set = SET_GI, binding = BINDING_OCTREE_DIRECTIONAL_STORAGE, rgba16f) uniform image3D directional;

// Child o's plane and coverage (PLANE_SLOT, COVERAGE_SLOT): the mean over its eight
// voxels, from the leaves' opacity, normal and centre where the children are leaves.
// `child` is the child's node coordinates at the level below.
void filter_plane(bool leaf_children, ivec3 radiance_origin, ivec3 normal_origin, ivec3 child,
                  int direction_stride, out vec4 plane, out float coverage) {
    plane = vec4(0.0);
    coverage = 0.0;
    float n = float(vct.resolution);
    for (int i = 0; i < 8; i++) {
        ivec3 k = ivec3(i & 1, (i >> 1) & 1, i >> 2);
        if (leaf_children) {
            float a = imageLoad(leaf_radiance, radiance_origin + k).a;
            plane += voxel_plane(a, imageLoad(leaf_normal, normal_origin + k).r, child * 2 + k, n);
            coverage += a;
        } else {
            plane += imageLoad(directional, radiance_origin + k + ivec3(int(PLANE_SLOT) * direction_stride, 0, 0));
            coverage += imageLoad(directional, radiance_origin + k + ivec3(int(COVERAGE_SLOT) * direction_stride, 0, 0)).r;
        }
    }
    plane *= 0.125;
    coverage *= 0.125;
}

void main() {
    uint node;
    if (!level_node(node) || node_bricks[node] == OCTREE_NO_BRICK) {
        return;
    }
    uint interior_side = counters.interior_pool_side;
    int direction_stride = int(interior_side * OCTREE_RADIANCE_BRICK);
    ivec3 out_origin = brick_origin(node_bricks[node], interior_side, OCTREE_RADIANCE_BRICK) + 1;
    uint tile = node_children[node] & OCTREE_CHILD_MASK;
    bool leaf_children = push.level + 2u == octree_depth();
    for (int o = first_item(); o < 8; o += item_step()) {
        ivec3 voxel = ivec3(o & 1, (o >> 1) & 1, o >> 2);
        uint brick = node_bricks[tile + uint(o)];
        if (brick == OCTREE_NO_BRICK) {
            for (int d = 0; d < int(directional_slots()); d++) {
                imageStore(directional, out_origin + voxel + ivec3(d * direction_stride, 0, 0), vec4(0.0));
            }
            continue;
        }
        ivec3 radiance_origin = brick_origin(brick, leaf_children ? counters.leaf_pool_side : interior_side, OCTREE_RADIANCE_BRICK) + 1;
        ivec3 normal_origin = brick_origin(brick, counters.leaf_pool_side, OCTREE_ATTRIBUTE_BRICK);
        for (int d = 0; d < 6; d++) {
            vec4 children[8];
            for (int i = 0; i < 8; i++) {
                ivec3 k = ivec3(i & 1, (i >> 1) & 1, i >> 2);
                if (leaf_children) {
                    children[i] = facing(imageLoad(leaf_normal, normal_origin + k).r, imageLoad(leaf_radiance, radiance_origin + k), d);
                } else {
                    children[i] = imageLoad(directional, radiance_origin + k + ivec3(d * direction_stride, 0, 0));
                }
            }
            imageStore(directional, out_origin + voxel + ivec3(d * direction_stride, 0, 0), filter_children(children, d));
        }
        if (PLANE_OCCLUSION) {
            ivec3 child = ivec3(unpack_coord(node_coords[node])) * 2 + voxel;
            vec4 plane;
            float coverage;
            filter_plane(leaf_children, radiance_origin, normal_origin, child, direction_stride, plane, coverage);
            imageStore(directional, out_origin + voxel + ivec3(int(PLANE_SLOT) * direction_stride, 0, 0), plane);
            imageStore(directional, out_origin + voxel + ivec3(int(COVERAGE_SLOT) * direction_stride, 0, 0),
                       vec4(coverage, 0.0, 0.0, 0.0));
        }
    }
}
