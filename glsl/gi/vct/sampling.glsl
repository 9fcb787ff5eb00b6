// How cones read the filtered voxel radiance: the base level (one voxel wide) and the
// six directional levels above it, from the dense grid's 3D textures or, with
// OCTREE, from the octree's bricks (Dřínovský 2013, 5.6). Both give the same values:
// a brick holds its node's 2x2x2 voxels, at voxel centres as in the dense grid, with a
// border copied from the neighbours, so trilinear filtering inside a node, or up to half
// a voxel outside it, reads what the dense texture would.
#ifndef SAMPLING_GLSL
#define SAMPLING_GLSL
#include "gi/vct/voxels.glsl"

layout(set = SET_GI, binding = BINDING_VCT_RADIANCE_SAMPLED) uniform sampler3D voxel_radiance;
layout(set = SET_GI, binding = BINDING_VCT_DIRECTIONAL) uniform sampler3D voxel_directional;
// Each base voxel's coverage across x, y and z (gi/vct/voxelize/coverage.glsl), alpha its
// occupancy.
layout(set = SET_GI, binding = BINDING_VCT_COVERAGE_SAMPLED) uniform sampler3D voxel_coverage;

// Along one axis, the index of the cell, of `cells` across the grid, that holds the
// texture coordinate `u` (`--snapped-cones`).
float cell_holding(float u, float cells) {
    return min(floor(clamp(u, 0.0, 1.0) * cells), cells - 1.0);
}

// A base-level sample `s` (radiance premultiplied by occupancy) as a cone crossing its
// voxels along an axis meets them: opaque across `covered`, the covered share of their
// cross-section (sampled as `s` was), where occupancy counts every voxel a surface
// touches as opaque however little of it the surface covers.
vec4 across_covered(vec4 s, float covered) {
    return s.a > 1e-4 ? vec4(s.rgb * (covered / s.a), covered) : vec4(0.0);
}

#ifndef OCTREE

// The base level at `uvw`.
vec4 sample_base(vec3 uvw) {
    return textureLod(voxel_radiance, uvw, 0.0);
}

// Along one axis, the centre of the cell, of `cells` across the grid, that holds the
// texture coordinate `u`.
float cell_centre(float u, float cells) {
    return (cell_holding(u, cells) + 0.5) / cells;
}

// The base level at `uvw` read three times, each at the centre of the voxel that holds
// uvw along one axis (sx along x, and so on) and trilinearly across it, opaque across
// the voxels' coverage across that axis (`--snapped-cones`).
void sample_base_snapped(vec3 uvw, out vec4 sx, out vec4 sy, out vec4 sz) {
    float cells = float(vct.resolution);
    vec3 at[3] = vec3[3](vec3(cell_centre(uvw.x, cells), uvw.yz), vec3(uvw.x, cell_centre(uvw.y, cells), uvw.z),
                         vec3(uvw.xy, cell_centre(uvw.z, cells)));
    sx = across_covered(textureLod(voxel_radiance, at[0], 0.0), textureLod(voxel_coverage, at[0], 0.0).x);
    sy = across_covered(textureLod(voxel_radiance, at[1], 0.0), textureLod(voxel_coverage, at[1], 0.0).y);
    sz = across_covered(textureLod(voxel_radiance, at[2], 0.0), textureLod(voxel_coverage, at[2], 0.0).z);
}

// Where `uvw` of the directional volume d (+X -X +Y -Y +Z -Z, with the planes
// (PLANE_OCCLUSION) then the planes and coverage) lies in their texture. They sit side by
// side along x, each in the middle of a slot twice its width whose margins repeat its edge
// voxels (filter.comp), so that filtering clamps at the cube's faces as at the texture's
// and never mixes two directions, at every level alike.
vec3 directional_slot(int d, vec3 uvw) {
    return vec3((float(d) + 0.25 + 0.5 * clamp(uvw.x, 0.0, 1.0)) / float(directional_slots()), uvw.yz);
}

// The directional volume d at `uvw` and mip `level`, one trilinear fetch blending two
// levels.
vec4 sample_directional(int d, vec3 uvw, float level) {
    float l = clamp(level, 0.0, float(vct.directional_levels) - 1.0);
    return textureLod(voxel_directional, directional_slot(d, uvw), l);
}

// The surface plane and coverage of the cells at `uvw` and whole mip `level`
// (PLANE_SLOT, dense/filter.comp), trilinear: the plane premultiplied by coverage.
void sample_plane(vec3 uvw, float level, out vec4 plane, out float coverage) {
    plane = textureLod(voxel_directional, directional_slot(int(PLANE_SLOT), uvw), level);
    coverage = textureLod(voxel_directional, directional_slot(int(COVERAGE_SLOT), uvw), level).r;
}

// The directional volume d at `uvw` and whole mip `level`, read at the centre of the cell
// that holds uvw along d's axis and trilinearly across it (`--snapped-cones`).
vec4 fetch_snapped(int d, vec3 uvw, float level) {
    int axis = d / 2;
    uvw[axis] = cell_centre(uvw[axis], float(vct.resolution >> (int(level) + 1u)));
    return textureLod(voxel_directional, directional_slot(d, uvw), level);
}

// The three directional volumes facing a cone travelling along `dir`. With
// `--snapped-cones` each is read snapped along its own axis (SNAPPED_CONES in cones.glsl),
// one fetch per level of the two a fractional level blends.
void sample_facing(vec3 uvw, vec3 dir, float level, out vec4 sx, out vec4 sy, out vec4 sz) {
    ivec3 d = ivec3(dir.x >= 0.0 ? 0 : 1, dir.y >= 0.0 ? 2 : 3, dir.z >= 0.0 ? 4 : 5);
    if (SNAPPED_CONES) {
        float l = clamp(level, 0.0, float(vct.directional_levels) - 1.0);
        float fine = floor(l);
        float t = l - fine;
        sx = fetch_snapped(d.x, uvw, fine);
        sy = fetch_snapped(d.y, uvw, fine);
        sz = fetch_snapped(d.z, uvw, fine);
        if (t > 0.0) {
            float coarse = fine + 1.0;
            sx = mix(sx, fetch_snapped(d.x, uvw, coarse), t);
            sy = mix(sy, fetch_snapped(d.y, uvw, coarse), t);
            sz = mix(sz, fetch_snapped(d.z, uvw, coarse), t);
        }
        return;
    }
    sx = sample_directional(d.x, uvw, level);
    sy = sample_directional(d.y, uvw, level);
    sz = sample_directional(d.z, uvw, level);
}

#else
#include "gi/vct/octree/octree.glsl"

// A place in a brick: the brick and the position in texels of its interior (0..2).
struct BrickSample {
    uint brick;
    vec3 local;
};

// The brick of the node at `level` whose cube holds `uvw` (clamped to the grid, as the
// dense sampler clamps to its edge), and where `uvw` lies in it; false where trilinear
// filtering there reads only empty voxels. Where the node is missing or empty but the
// 2x2x2 voxels the dense sampler would blend reach into a neighbouring node, that node's
// brick is read instead: its border holds those voxels (zero where empty). Inside a
// large empty cube the descent stops at its top and nothing more is looked up.
bool locate(vec3 uvw, uint level, out BrickSample s) {
    float voxels = float(2u << level);
    vec3 q = clamp(uvw, 0.0, 1.0) * voxels;
    uvec3 node_coords = min(uvec3(q * 0.5), uvec3((1u << level) - 1u));
    uint empty;
    uint node = find_node_or_gap_gridded(node_coords << (octree_depth() - level), level, empty);
    s.brick = node == OCTREE_NO_NODE ? OCTREE_NO_BRICK : node_bricks[node];
    s.local = q - vec3(node_coords * 2u);
    if (s.brick != OCTREE_NO_BRICK) {
        return true;
    }
    ivec3 last = ivec3(int(2u << level) - 1);
    ivec3 lo = clamp(ivec3(floor(q - 0.5)), ivec3(0), last);
    ivec3 hi = min(lo + 1, last);
    // The empty cube around q, in voxels of this level.
    int size = 2 << (level - empty);
    ivec3 start = (ivec3(node_coords) >> (level - empty)) * size;
    if (all(greaterThanEqual(lo, start)) && all(lessThan(hi, start + size))) {
        return false;
    }
    ivec3 first = lo >> 1;
    ivec3 span = (hi >> 1) - first;
    for (int i = 0; i < 8; i++) {
        ivec3 step = ivec3(i & 1, (i >> 1) & 1, i >> 2);
        ivec3 c = first + step;
        if (any(greaterThan(step, span)) || all(equal(c, ivec3(node_coords)))) {
            continue;
        }
        uint n = find_node_gridded(uvec3(c) << (octree_depth() - level), level);
        uint brick = n == OCTREE_NO_NODE ? OCTREE_NO_BRICK : node_bricks[n];
        if (brick != OCTREE_NO_BRICK) {
            s.brick = brick;
            s.local = q - vec3(c * 2);
            return true;
        }
    }
    return false;
}

// Where a located place lies in the leaf radiance pool (and the coverage pool, laid out
// alike), in texture coordinates.
vec3 leaf_texel(BrickSample s) {
    float edge = float(counters.leaf_pool_side * OCTREE_RADIANCE_BRICK);
    vec3 texel = vec3(brick_origin(s.brick, counters.leaf_pool_side, OCTREE_RADIANCE_BRICK)) + 1.0 + s.local;
    return texel / edge;
}

// Leaf radiance, trilinear, at a located place.
vec4 read_leaf(BrickSample s) {
    return textureLod(voxel_radiance, leaf_texel(s), 0.0);
}

// Leaf radiance at a located place as a cone crossing it along `axis` meets it
// (across_covered).
vec4 read_leaf_across(BrickSample s, int axis) {
    vec3 at = leaf_texel(s);
    return across_covered(textureLod(voxel_radiance, at, 0.0), textureLod(voxel_coverage, at, 0.0)[axis]);
}

// Directional radiance d of an interior brick, trilinear, at a located place. The six
// directions of a brick sit side by side along x, one pool width apart, and with
// the planes (PLANE_OCCLUSION) the plane and coverage after them (directional_slots).
vec4 read_interior(BrickSample s, int d) {
    float edge = float(counters.interior_pool_side * OCTREE_RADIANCE_BRICK);
    vec3 texel = vec3(brick_origin(s.brick, counters.interior_pool_side, OCTREE_RADIANCE_BRICK)) + 1.0 + s.local;
    texel.x += float(d) * edge;
    return textureLod(voxel_directional, texel / vec3(float(directional_slots()) * edge, edge, edge), 0.0);
}

vec4 sample_base(vec3 uvw) {
    BrickSample s;
    return locate(uvw, octree_depth() - 1u, s) ? read_leaf(s) : vec4(0.0);
}

// A located place `s` at `level` moved along `axis` to the centre of the voxel of that
// level that holds `uvw`, as the dense grid's cell_centre (`--snapped-cones`): the
// brick's border holds that voxel where it lies in a neighbouring node.
BrickSample snapped(BrickSample s, int axis, vec3 uvw, uint level) {
    float voxels = float(2u << level);
    s.local[axis] += cell_holding(uvw[axis], voxels) + 0.5 - clamp(uvw[axis], 0.0, 1.0) * voxels;
    return s;
}

void sample_base_snapped(vec3 uvw, out vec4 sx, out vec4 sy, out vec4 sz) {
    uint level = octree_depth() - 1u;
    BrickSample s;
    if (!locate(uvw, level, s)) {
        sx = vec4(0.0);
        sy = vec4(0.0);
        sz = vec4(0.0);
        return;
    }
    sx = read_leaf_across(snapped(s, 0, uvw, level), 0);
    sy = read_leaf_across(snapped(s, 1, uvw, level), 1);
    sz = read_leaf_across(snapped(s, 2, uvw, level), 2);
}

// Directional level `level` (0: voxels twice the leaves' size) is held by the interior
// nodes at depth - 2 - level; a fractional level blends two (quadrilinear). The root's
// bricks are the coarsest level (the dense chain goes one further, to a single voxel).
void level_pair(float level, out uint fine, out uint coarse, out float t) {
    float top = float(octree_depth()) - 2.0;
    float l = clamp(level, 0.0, top);
    float below = floor(l);
    t = l - below;
    fine = uint(top - below);
    coarse = fine > 0u ? fine - 1u : 0u;
}

vec4 sample_directional(int d, vec3 uvw, float level) {
    uint fine;
    uint coarse;
    float t;
    level_pair(level, fine, coarse, t);
    BrickSample a;
    BrickSample b;
    vec4 near = locate(uvw, fine, a) ? read_interior(a, d) : vec4(0.0);
    vec4 far = (t > 0.0 && locate(uvw, coarse, b)) ? read_interior(b, d) : vec4(0.0);
    return mix(near, far, t);
}

// The surface plane and coverage of the cells at `uvw` and whole level `level` (the
// march's cells; PLANE_SLOT, octree/bricks/filter.comp), as the dense grid's: the plane
// premultiplied by coverage.
void sample_plane(vec3 uvw, float level, out vec4 plane, out float coverage) {
    uint fine;
    uint coarse;
    float t;
    level_pair(level, fine, coarse, t);
    BrickSample s;
    plane = vec4(0.0);
    coverage = 0.0;
    if (locate(uvw, fine, s)) {
        plane = read_interior(s, int(PLANE_SLOT));
        coverage = read_interior(s, int(COVERAGE_SLOT)).r;
    }
}

// Directional radiance d of an interior brick at a located place at `level`, with
// `--snapped-cones` snapped along d's axis, as the dense grid's fetch_snapped.
vec4 read_interior_facing(BrickSample s, int d, vec3 uvw, uint level) {
    return read_interior(SNAPPED_CONES ? snapped(s, d / 2, uvw, level) : s, d);
}

void sample_facing(vec3 uvw, vec3 dir, float level, out vec4 sx, out vec4 sy, out vec4 sz) {
    uint fine;
    uint coarse;
    float t;
    level_pair(level, fine, coarse, t);
    ivec3 d = ivec3(dir.x >= 0.0 ? 0 : 1, dir.y >= 0.0 ? 2 : 3, dir.z >= 0.0 ? 4 : 5);
    sx = vec4(0.0);
    sy = vec4(0.0);
    sz = vec4(0.0);
    BrickSample s;
    if (locate(uvw, fine, s)) {
        sx = read_interior_facing(s, d.x, uvw, fine);
        sy = read_interior_facing(s, d.y, uvw, fine);
        sz = read_interior_facing(s, d.z, uvw, fine);
    }
    if (t > 0.0) {
        vec4 cx = vec4(0.0);
        vec4 cy = vec4(0.0);
        vec4 cz = vec4(0.0);
        if (locate(uvw, coarse, s)) {
            cx = read_interior_facing(s, d.x, uvw, coarse);
            cy = read_interior_facing(s, d.y, uvw, coarse);
            cz = read_interior_facing(s, d.z, uvw, coarse);
        }
        sx = mix(sx, cx, t);
        sy = mix(sy, cy, t);
        sz = mix(sz, cz, t);
    }
}
#endif
#endif
