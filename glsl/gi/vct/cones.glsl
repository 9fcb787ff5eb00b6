// Cone marching through the voxel radiance (Crassin et al. 2011), shared by the screen
// gather and the voxel bounce.
#ifndef CONES_GLSL
#define CONES_GLSL
#include "common/frame.glsl"
#include "common/diffuse_cones.glsl"
#include "gi/vct/sampling.glsl"

// Per axis, the share of a cell of directional `level` centred at `uvw` (two cells
// wide: the trilinear tent) that lies inside the grid.
vec3 cross_section_inside(vec3 uvw, float level) {
    float h = exp2(max(level, 0.0)) / float(vct.resolution);
    return clamp((min(uvw + h, 1.0) - max(uvw - h, 0.0)) / (2.0 * h), 0.0, 1.0);
}

// The voxels at `uvw` as a cone travelling along `dir` meets them, from three values
// read along the three axes (sx for travel along x, and so on), weighted by the squared
// direction components w. The optical depths add up, weighted by w, so the
// transmittance is the product of the three raised to w: a wall opaque along one axis
// stays opaque to any cone that crosses it, where a weighted mean of the opacities would
// let a cone at 45 degrees see half through it (and light leave the room). The colour
// is the opacity-weighted mean of the three.
vec4 along_axes(vec4 sx, vec4 sy, vec4 sz, vec3 dir) {
    vec3 w = dir * dir;
    vec4 mean = w.x * sx + w.y * sy + w.z * sz;
    vec3 transmittance = 1.0 - clamp(vec3(sx.a, sy.a, sz.a), 0.0, 0.9999);
    float alpha = 1.0 - exp2(dot(w, log2(transmittance)));
    return mean.a > 1e-4 ? vec4(mean.rgb * (alpha / mean.a), alpha) : vec4(0.0);
}

// The base voxels at `uvw` as a cone travelling along `dir` meets them, from the three
// values read across the three axes (sample_base_snapped: opaque across the covered share
// of each voxel's cross-section). A ray crosses the planes across axis a at |dir.a| per
// unit length, so a surface across a that covers a share c of the voxels' cross-section
// stops 1 - (1 - c) of the rays that cross it at any slope when the optical depths are
// weighted by |dir| (along_axes's squares gave a surface half covering its voxels 0.29 of
// the rays crossing it at 45 degrees). Voxels wholly covered are opaque either way.
vec4 across_axes(vec4 sx, vec4 sy, vec4 sz, vec3 dir) {
    vec3 w = abs(dir);
    vec4 mean = (w.x * sx + w.y * sy + w.z * sz) / max(w.x + w.y + w.z, 1e-6);
    vec3 transmittance = 1.0 - clamp(vec3(sx.a, sy.a, sz.a), 0.0, 0.9999);
    float alpha = 1.0 - exp2(dot(w, log2(transmittance)));
    return mean.a > 1e-4 ? vec4(mean.rgb * (alpha / mean.a), alpha) : vec4(0.0);
}

// Voxel radiance at `uvw` for a cone travelling along `dir`, from the three directional
// volumes facing the cone at mip `level` (along_axes).
// Each volume is weighted by the share of the cell's cross-section across its axis that
// lies inside the grid: the grid covers the scene, so nothing lies beyond its faces,
// where the clamped lookup would repeat the edge cells (the walls and floor at an open
// side of the scene, as if they went on).
vec4 sample_directional_volumes(vec3 uvw, vec3 dir, float level) {
    vec4 sx;
    vec4 sy;
    vec4 sz;
    sample_facing(uvw, dir, level, sx, sy, sz);
    vec3 inside = cross_section_inside(uvw, level);
    sx *= inside.y * inside.z;
    sy *= inside.x * inside.z;
    sz *= inside.x * inside.y;
    return along_axes(sx, sy, sz, dir);
}

// Voxel radiance at `uvw` for a cone travelling along `dir` with footprint `lod` (0 = one
// voxel): the base level below lod 1, blended into the directional volumes above.
// With `--snapped-cones` the base level too is read whole along each axis (its voxel's
// centre along x for the x part, and so on), as the directional volumes are: read
// trilinearly, a wall one voxel thick is a tent of opacity along the cone, whose optical
// depth integrates to only 2 (e^-2 = 0.135 of the light through it), so the narrow
// cones that test the sampled emitters' visibility passed 12 % of the light through
// such a wall at 64³ (`thin_wall_passes_little_light`).
vec4 sample_voxels(vec3 uvw, vec3 dir, float lod) {
    vec4 base;
    if (SNAPPED_CONES) {
        vec4 bx;
        vec4 by;
        vec4 bz;
        sample_base_snapped(uvw, bx, by, bz);
        base = across_axes(bx, by, bz, dir);
    } else {
        base = sample_base(uvw);
    }
    if (lod <= 0.0) {
        return base;
    }
    vec4 aniso = sample_directional_volumes(uvw, dir, max(lod - 1.0, 0.0));
    return lod < 1.0 ? mix(base, aniso, lod) : aniso;
}

// Where a cone leaving the surface at `surface` with normal `n` samples at distance
// `dist` from `origin` (texture coordinates), with the cone `diameter` there (which sets
// the step) and the `footprint` the sample reads at (mip `lod`).
// A cone 57.5 degrees off the normal with a 30 degree half-angle nearly grazes the
// surface's own plane, and the trilinear lookup blends cells up to one cell size from
// the sample point: the surface would occlude and light itself (its lit voxels seen
// edge-on).
// So the footprint is capped at the sample's height above the plane, and a sample less
// than 1.125 footprints above it (where the coarsest level, min_lod, still blends from
// the plane) is lifted to that height along n: an eighth of a cell more than the
// footprint keeps more of the plane's own cell out of the blend, where a quarter cell
// bends the ring cones too far, and lifting every sample a whole cone diameter bends the
// slanted cones towards the normal, far off their axis (BENCHMARKS.md, the dense grid's
// quality history).
vec3 cone_sample(vec3 origin, vec3 dir, float dist, float tan_half, float min_lod, vec3 surface, vec3 n,
                 out float lod, out float diameter, out float footprint) {
    float voxel = vct.origin.w;
    vec3 x = origin + dir * dist;
    float height = dot(x - surface, n);
    diameter = max(voxel, 2.0 * tan_half * dist);
    lod = max(log2(min(diameter, max(height, voxel)) / voxel), min_lod);
    // The cell size at that mip, also where min_lod holds the mip above what the cone
    // asks for (its opacity was filtered over that path).
    footprint = voxel * exp2(lod);
    x += n * max(1.125 * footprint - height, 0.0);
    return (x - vct.origin.xyz) / (voxel * float(vct.resolution));
}

bool inside_grid(vec3 uvw) {
    return all(greaterThanEqual(uvw, vec3(0.0))) && all(lessThanEqual(uvw, vec3(1.0)));
}

// Where the segment from `a` (inside the grid) to `b` (outside) crosses the grid's
// faces, as a fraction of the segment.
float grid_exit(vec3 a, vec3 b) {
    vec3 span = b - a;
    vec3 low = mix(vec3(1e9), -a / span, lessThan(b, vec3(0.0)));
    vec3 high = mix(vec3(1e9), (1.0 - a) / span, greaterThan(b, vec3(1.0)));
    vec3 t = min(low, high);
    return clamp(min(t.x, min(t.y, t.z)), 0.0, 1.0);
}

// The path, in footprints, that the grid's face counts where a cone leaves the grid.
// The scene's bounds often lie on a wall (a room's), whose voxels fill the grid's last
// layer; with linear interpolation of opacity the march integrates only the inner half
// of that layer's tent, and the wall would let about a tenth of the light through. Half
// a footprint stands for the outer half; 0.65 is the best of a sweep with the screen's
// ring cones traced as sub-cones (BENCHMARKS.md, the dense grid's quality history,
// sessions 10 and 11).
const float GRID_FACE_PATH = 0.65;

// The axis along which `m` (non-negative) is largest, x before y before z on ties.
int major_axis(vec3 m) {
    return m.x >= m.y && m.x >= m.z ? 0 : (m.y >= m.z ? 1 : 2);
}

// One sample `s` of a cone's march, its opacity filtered for a path of one footprint,
// composited behind `acc` for a path of `footprints`; with `ao_volume` (0..5), the
// ambient occlusion's own opacity from that volume at `uvw`, weighted down with the
// distance `dist` (trace_cone).
// With the planes (PLANE_OCCLUSION, march_cells): `limit` (plane_increment: x the most
// opacity a surface plane allows here, y how planar the cells are) caps the sample's
// opacity in that proportion, (1, 0) for none; and it is raised to at least `least`, that
// part with the radiance `beyond` (a plane the cone has crossed, whose rays meet it
// further on). Returns the opacity composited.
float composite(vec4 s, float footprints, vec2 limit, float least, vec3 beyond, int ao_volume, vec3 uvw, float lod,
                float dist, inout vec4 acc, inout float ao, inout float ao_alpha) {
    float own = 1.0 - pow(1.0 - clamp(s.a, 0.0, 0.9999), footprints);
    own -= limit.y * max(own - limit.x, 0.0);
    float a = max(own, least);
    vec3 rgb = (s.a > 1e-4 ? s.rgb * (own / s.a) : vec3(0.0)) + beyond * (a - own);
    acc.rgb += (1.0 - acc.a) * rgb;
    acc.a += (1.0 - acc.a) * a;
    if (ao_volume >= 0) {
        float o = sample_directional(ao_volume, uvw, max(lod - 1.0, 0.0)).a;
        o = 1.0 - pow(1.0 - clamp(o, 0.0, 0.9999), footprints);
        ao += (1.0 - ao_alpha) * o / (1.0 + dist / vct.ao_distance);
        ao_alpha += (1.0 - ao_alpha) * o;
    }
    return a;
}

// The least opacity at which a cell shows its plane's colour (s.rgb / s.a) well enough
// for a held plane to take it (plane_increment, march_cells).
const float PLANE_SHOWN = 0.05;

// A surface plane a snapped cone has met (PLANE_OCCLUSION, plane_increment): xyz its
// normal and w its constant (in grid units less 0.5), the share of the cone's disc
// counted as blocked by it so far, its radiance as the cone saw it, and whether the
// cone's axis has crossed it.
struct HeldPlane {
    vec4 plane;
    float share;
    vec3 radiance;
    bool crossed;
};

// The share of a cone's disc beyond `plane` (xyz normal, w constant), a circular segment:
// the disc of `radius` about the axis point `axis`, the cone leaving `origin` along `dir`
// (grid units less 0.5).
float disc_segment(vec4 plane, vec3 axis, vec3 origin, vec3 dir, float radius) {
    float start_side = dot(plane.xyz, origin) - plane.w;
    float offset = (dot(plane.xyz, axis) - plane.w) * (start_side < 0.0 ? -1.0 : 1.0);
    float across = radius * sqrt(max(1.0 - dot(plane.xyz, dir) * dot(plane.xyz, dir), 1e-4));
    float u = clamp(offset / max(across, 1e-6), -1.0, 1.0);
    return (acos(u) - u * sqrt(1.0 - u * u)) / 3.14159265;
}

// Surface planes seen by a snapped cone (PLANE_OCCLUSION): a plane beside the cone
// blocks the share of its disc beyond the plane, a circular segment that grows as the
// disc widens, and it is the same rays in every cell that holds the plane. Composited cell
// after cell as if uncorrelated, an edge-on floor beside the cone closed it entirely
// (Loubet & Neyret 2018; the corner of BENCHMARKS.md, sessions 36 and 37). So a cell's
// plane (PLANE_SLOT, read at `uvw` and `level`) adds at most what its segment grew
// since the cone last met the same plane (`held`); `axis` is the cone's axis point at the
// end of the cell's stretch, `radius` the cone's there, `origin` its start, `cell` the
// level's cell (grid units less 0.5). Returns (the most opacity the plane allows, the
// cells' planarity: |mean opacity x normal| / mean opacity, 1 where the cells' plane is
// the held one).
vec3 plane_increment(vec3 uvw, float level, vec3 axis, vec3 origin, vec3 dir, float radius, float cell,
                     float opacity, inout HeldPlane held) {
    vec4 plane;
    float coverage;
    sample_plane(uvw, level, plane, coverage);
    float len = length(plane.xyz);
    if (len < 1e-4 || coverage < 1e-4) {
        return vec3(1.0, 0.0, 0.0);
    }
    float planarity = clamp(len / coverage, 0.0, 1.0);
    plane /= len;
    float share = disc_segment(plane, axis, origin, dir, radius);
    // The axis crosses the plane where the cells along it hold the surface (`opacity`,
    // the sample's), not past a surface's edge, and the cone sees its face: seen from
    // behind, a surface hides from the cone (anisotropic.glsl, facing).
    bool crossing = share >= 0.5 && opacity >= 0.5 && dot(plane.xyz, dir) < 0.125;
    // The same plane as the held one: normals within 26 degrees, constants within a cell.
    if (dot(plane.xyz, held.plane.xyz) <= 0.9 || abs(plane.w - held.plane.w) >= cell) {
        // A plane met for the first time is composited as it is (nothing before blocked
        // the same rays), and what it blocks is held for the cells after.
        // A crossed plane stays held: the rest of its rays still meet it.
        // A plane is held from a cell that shows it (PLANE_SHOWN), whose colour the
        // rays that meet it further on take (march_cells): held where it barely showed,
        // its colour was unknown, and they took black.
        if (planarity <= 0.5 || held.crossed || opacity <= PLANE_SHOWN) {
            return vec3(1.0, 0.0, 0.0);
        }
        held = HeldPlane(plane, 0.0, vec3(0.0), crossing);
        return vec3(1.0, 0.0, 1.0);
    }
    if (share >= 0.5) {
        // The axis crosses the plane by the cell's end: the cells composite as they are,
        // and the rest of the disc, which crosses the plane further on where the cells
        // beyond need not hold it (empty space behind a wall, the grid's face), is
        // counted as its segment grows (march_cells).
        held.crossed = held.crossed || crossing;
        return vec3(1.0, 0.0, 0.0);
    }
    // Only a plane the cone runs beside, within 30 degrees of its axis, is read in cell
    // after cell before the axis reaches it: the disc meets it r s / |n . dir| before the
    // axis does, in cells of at most r, so more than 1.7 cells there. A plane met more
    // steeply is crossed within a cell or two, and capping those cells by the segment
    // left the cells past the crossing, often empty, to stop the rest: a closed box
    // inside the grid gathered 0.953 of its walls' light at 256³ (0.995 without the cap).
    float grazing = abs(dot(plane.xyz, dir)) < 0.5 ? planarity : 0.0;
    return vec3(max(share - held.share, 0.0) / max(1.0 - held.share, 1e-4), grazing, 1.0);
}

// The whole level a snapped cone reads at `dist` along its axis, `height` above its
// surface's plane (march_cells), at most `top`.
float snapped_level(float dist, float tan_half, float height, bool clear, float min_lod, float top) {
    float voxel = vct.origin.w;
    float wide = floor(log2(max(tan_half * dist, voxel) / voxel));
    float high = round(log2(max(height / 3.0, voxel) / voxel));
    return min(max(clear ? min(wide, high) : wide, min_lod), top);
}

// The snapped cones' march (`--snapped-cones`, SNAPPED_CONES): as trace_cone, but cell by
// cell through the level it reads, each cell counted for the path the cone's axis runs
// inside it.
//
// Each directional volume is read whole along its axis (sampling.glsl). A cell's value
// along its axis is its children composited front to back, so a wall anywhere in a
// crossed cell stops the cone whatever the step's phase, where a lookup between two cells
// along the axis averaged the wall's cell with the empty one beside it: a wall one voxel
// thick passed 31 % of the light at 64³, and a closed room lost what its walls let
// through to the empty space beyond them. Across the cone the lookup stays linear: there
// interpolated opacity is the covered share. The cells are those of the whole level at
// most half the diameter (no blend with the next level), so that the tent across them
// reaches no further than the cone: a coarser cell holding the end of a wall that the cone
// meets face-on (a room's far wall where it meets a side wall) is only partly covered,
// the rest lying beyond the side wall where none of the cone's rays go, and blended in by
// its centre's distance it let a tenth of the light out through the far wall (a closed
// box inside the grid, the cone along the normal: 0.90 of the walls' light at 256³, 0.99
// with whole levels; BENCHMARKS.md, session 32). A cone more than 26 degrees off the
// normal reads its own plane in the volumes it crosses edge-on, and gathers its own
// light: its cells are those of the whole level nearest a third of its height above the
// plane, and it is lifted until it is 1.5 cells above it, where no lookup reaches the
// plane's cells (a cell of size c blends cells reaching 1.5 c from the sample). That
// bound only sets how often the lift bends the cone towards the normal, so the nearest
// level, not the one below it: the level below reads a pencil as little as a sixth of the
// cone's width, whose streaks across the indirect light the cone's own integral does not
// have (BENCHMARKS.md, session 32). The cone along the normal sees its plane only from
// behind, which the facing weights hide (anisotropic.glsl).
//
// Why cell by cell: a whole cell's value stands for all of its length along the axis, so
// the march must count each stretch of the axis once, in the cell that holds it. Samples
// a step apart count the step in the cell at its start, and a step that reached the next
// level counted that level's cell whole, though the finer cells before it had counted its
// first part already: a small emitter facing the receiver, met where the cones change
// level, was gathered twice (BENCHMARKS.md, session 35). So the march runs from face to
// face of the cells it reads, samples each in the middle of its chord, counts the chord,
// and takes up a coarser level only where it enters a new cell of that level through a
// face across its dominant axis, whose volume carries most of the optical depth (a face
// across another axis leaves the part of the coarse cell it has crossed along the
// dominant axis counted twice). A finer level is taken up at once: every face of a cell
// is a face of the finer cells. No step factor: the cells set the steps.
vec4 march_cells(vec3 origin, vec3 dir, float tan_half, float min_lod, vec3 surface, vec3 n, int ao_volume) {
    float voxel = vct.origin.w;
    float cells = float(vct.resolution);
    float top = float(vct.directional_levels);
    float rise = dot(dir, n);
    float start_height = dot(origin - surface, n);
    bool clear = rise < 0.9;
    vec3 m = abs(dir);
    int dominant = major_axis(m);
    // Where the axis starts, in voxels from the grid's corner; 1/dir per axis, huge
    // where the axis runs along the faces; which faces the axis leaves cells by, and the
    // nudge that puts a point on a face into the cell ahead.
    vec3 start = (origin - vct.origin.xyz) / voxel;
    vec3 inv = 1.0 / mix(vec3(1e-9), dir, greaterThan(m, vec3(1e-9)));
    vec3 ahead = step(0.0, dir);
    vec3 nudge = (2.0 * ahead - 1.0) * 1e-4;
    vec4 acc = vec4(0.0);
    float ao = 0.0;
    float ao_alpha = 0.0;
    float grid = voxel * cells;
    HeldPlane held = HeldPlane(vec4(0.0), 0.0, vec3(0.0), false);
    float dist = voxel;
    float lod = snapped_level(dist, tan_half, rise * dist + start_height, clear, min_lod, top);
    bool at_face = false;
    vec3 p = start + dir * (dist / voxel);
    while (acc.a < 0.99 && dist < vct.max_distance && all(greaterThanEqual(p, vec3(0.0))) &&
           all(lessThanEqual(p, vec3(cells)))) {
        float cell = exp2(lod);
        vec3 q = p / cell;
        // The cell the axis enters at p (on a face, the one ahead), and its exit face.
        vec3 face = floor(q + nudge) + ahead;
        vec3 t3 = (face - q) * inv;
        float chord = max(min(t3.x, min(t3.y, t3.z)), 1e-4);
        int exit_axis = t3.x <= t3.y && t3.x <= t3.z ? 0 : (t3.y <= t3.z ? 1 : 2);
        float footprints = at_face ? GRID_FACE_PATH : chord;
        vec3 x = vct.origin.xyz + voxel * (at_face ? p : p + dir * (0.5 * chord * cell));
        float height = dot(x - surface, n);
        x += n * max((clear ? 1.5 : 1.125) * cell * voxel - height, 0.0);
        vec3 uvw = clamp((x - vct.origin.xyz) / (voxel * cells), 0.0, 1.0);
        // Cones that never read the base level (min_lod >= 1, the diffuse ones) skip its
        // fetches: the branch is on a constant once inlined.
        vec4 s = min_lod >= 1.0 ? sample_directional_volumes(uvw, dir, lod - 1.0) : sample_voxels(uvw, dir, lod);
        vec3 limit = vec3(1.0, 0.0, 0.0);
        float least = 0.0;
        if (PLANE_OCCLUSION && !at_face && lod >= 1.0) {
            // What the plane blocks by the end of the cell's stretch of the axis.
            float end = dist + chord * cell * voxel;
            vec3 axis = (origin + dir * end - vct.origin.xyz) / grid - 0.5;
            vec3 start_point = (origin - vct.origin.xyz) / grid - 0.5;
            float radius = tan_half * end / grid;
            limit = plane_increment(uvw, lod - 1.0, axis, start_point, dir, radius, cell / cells, s.a, held);
            // The held plane's colour, read before it stops any rays: a plane crossed in
            // the cell where the cone first meets it stops the rest of the disc in this
            // very cell. Read after compositing, that first stop was black: in a world
            // of uniform radiance the cones gathered 0.989 of it
            // (`uniform_world_gathers_its_radiance_whatever_the_cones_cross`).
            if (limit.z > 0.0 && s.a > PLANE_SHOWN) {
                held.radiance = s.rgb / s.a;
            }
            if (held.crossed) {
                float share = disc_segment(held.plane, axis, start_point, dir, radius);
                least = max(share - held.share, 0.0) / max(1.0 - held.share, 1e-4);
            }
        }
        float added = composite(s, footprints, limit.xy, least, held.radiance, ao_volume, uvw, lod, dist, acc, ao,
                                ao_alpha);
        if (limit.z > 0.0 || held.crossed) {
            // The held plane's segment grows by what this cell added of it.
            held.share += (1.0 - held.share) * (held.crossed ? least : min(added, limit.x));
        }
        if (at_face) {
            break;
        }
        dist += chord * cell * voxel;
        p = start + dir * (dist / voxel);
        float exit_face = face[exit_axis] * cell;
        if (exit_face <= 0.0 || exit_face >= cells) {
            // The grid's face: one more sample, as trace_cone's, in the same loop.
            at_face = true;
            p = clamp(p, vec3(0.0), vec3(cells));
            lod = max(lod - 1.0, min_lod);
            continue;
        }
        float want = snapped_level(dist, tan_half, rise * dist + start_height, clear, min_lod, top);
        if (want < lod) {
            lod = want;
        }
        float crossed = face[exit_axis];
        while (want > lod && exit_axis == dominant && mod(crossed, 2.0) == 0.0) {
            crossed *= 0.5;
            lod += 1.0;
        }
    }
    acc.rgb += (1.0 - acc.a) * frame.sky_radiance.rgb;
    return vec4(acc.rgb, ao);
}

// Front-to-back accumulation along one cone leaving the surface at `surface` with normal
// `n`; returns premultiplied radiance (rgb) with the sky behind whatever the cone leaves
// open, and (a) the occlusion that ambient occlusion counts, each occluder weighted down
// with its distance d by 1 / (1 + d / vct.ao_distance). Ambient occlusion reads opacity
// from the one directional volume `ao_volume` (0..5, or -1: none) travelling away from
// the surface along the axis closest to its normal: the surface's own voxels are hidden
// from it by the filter's facing weight, whereas the three volumes a slanted cone blends
// see them edge-on, so an open plane would occlude itself. Each step is `step_factor` of
// the cone's diameter there.
vec4 trace_cone(vec3 origin, vec3 dir, float tan_half, float min_lod, vec3 surface, vec3 n, int ao_volume,
                float step_factor) {
    if (SNAPPED_CONES) {
        return march_cells(origin, dir, tan_half, min_lod, surface, n, ao_volume);
    }
    vec4 acc = vec4(0.0);
    float ao = 0.0;
    float ao_alpha = 0.0;
    float dist = vct.origin.w;
    float lod;
    float diameter;
    float footprint;
    vec3 uvw = cone_sample(origin, dir, dist, tan_half, min_lod, surface, n, lod, diameter, footprint);
    bool at_face = false;
    while (acc.a < 0.99 && dist < vct.max_distance && inside_grid(uvw)) {
        // Cones that never sample below lod 1 (the diffuse ones) skip the base level: the
        // branch is on a constant once inlined, where testing lod per sample cost more
        // than the fetch it saves.
        vec4 s;
        if (min_lod >= 1.0) {
            s = sample_directional_volumes(uvw, dir, lod - 1.0);
        } else {
            s = sample_voxels(uvw, dir, lod);
        }
        // Wide cones may instead step level by level: each sample at twice the last's
        // distance, so twice as wide, reading the next coarser level (min_lod marks them).
        float step_length = (vct.wide_steps_by_level != 0u && min_lod >= 1.0) ? max(dist, diameter * step_factor)
                                                                              : diameter * step_factor;
        float next_lod;
        float next_diameter;
        float next_footprint;
        vec3 next_uvw = cone_sample(origin, dir, dist + step_length, tan_half, min_lod, surface, n, next_lod,
                                    next_diameter, next_footprint);
        // Opacity was filtered for a path of one footprint; correct it to the path from
        // this sample to the next: the step, longer where the lift bends it. The last
        // step inside the grid ends at its face, so that what a cone gathers changes
        // smoothly as its origin moves (a whole step there drew bands in the indirect
        // light wherever one more sample fell inside the grid).
        bool leaving = !inside_grid(next_uvw);
        float exit_fraction = leaving ? grid_exit(uvw, next_uvw) : 1.0;
        float path = distance(next_uvw, uvw) * vct.origin.w * float(vct.resolution) * exit_fraction;
        float footprints = at_face ? GRID_FACE_PATH : path / footprint;
        composite(s, footprints, vec2(1.0, 0.0), 0.0, vec3(0.0), ao_volume, uvw, lod, dist, acc, ao, ao_alpha);
        if (at_face) {
            break;
        }
        if (leaving) {
            // One more sample, in the same loop (a separate fetch after it cost lavapipe
            // as much as a step for every lane, on each step where any lane left): the
            // face itself, what lies in it (a wall on the scene's bounds) for
            // GRID_FACE_PATH footprints, read one level finer than the cone, so that
            // walls running along the cone to an open face (a corridor's) count as the
            // small share of the cell they are.
            at_face = true;
            uvw = clamp(mix(uvw, next_uvw, exit_fraction), 0.0, 1.0);
            lod = max(lod - 1.0, min_lod);
            continue;
        }
        dist += step_length;
        uvw = next_uvw;
        lod = next_lod;
        diameter = next_diameter;
        footprint = next_footprint;
    }
    acc.rgb += (1.0 - acc.a) * frame.sky_radiance.rgb;
    return vec4(acc.rgb, ao);
}

// Fraction of the light from `dir` that reaches `origin` through the voxels within
// `max_dist`: a soft-shadow cone, accumulating opacity only, stepping by
// vct.shadow_step_factor of its diameter.
float cone_visibility(vec3 origin, vec3 dir, float tan_half, float max_dist) {
    float voxel = vct.origin.w;
    float grid_size = voxel * float(vct.resolution);
    float occlusion = 0.0;
    float dist = voxel;
    while (occlusion < 0.99 && dist < max_dist) {
        float diameter = max(voxel, 2.0 * tan_half * dist);
        vec3 uvw = (origin + dir * dist - vct.origin.xyz) / grid_size;
        if (!inside_grid(uvw)) {
            break;
        }
        float s = sample_voxels(uvw, dir, log2(diameter / voxel)).a;
        float step_length = diameter * vct.shadow_step_factor;
        occlusion += (1.0 - occlusion) * (1.0 - pow(1.0 - clamp(s, 0.0, 0.9999), vct.shadow_step_factor));
        dist += step_length;
    }
    return 1.0 - occlusion;
}

// Fraction of a sampled emitter's light (gi/vct/emitters.glsl) that reaches the surface
// at `surface` (normal n) through the voxels along `dir`, up to the emitter's `plane`: a
// soft-shadow cone as narrow as the lights' (vct.shadow_tan_half). A cone as wide as the
// emitter would soften its shadows as a penumbra does, but reads coarse cells, whose
// prefiltered opacity blends an occluder's one-voxel faces with the empty space around
// them: it passed 18 % of the light in a block's full shadow at 64³ and 29 % at 128³,
// where the narrow cone passes 3 % (`floor_under_an_emitter_takes_its_irradiance_and_shadow`).
// Its shadow is as hard as from the emitter's centre; an emitter cut into pieces, each
// with its own cone (src/gi/vct/emitters.rs), casts the mean of theirs. No sample blends
// the voxels of either end's surface, which would shadow the light with the emitter
// itself or the receiver: a lookup in cells of size f blends cells reaching 1.5 f from
// it, and a surface's voxels reach a voxel from it (dilated by the voxelization), so a
// sample at height h above either plane reads cells no larger than (h - voxel) / 1.5;
// samples too near the receiver for a voxel are skipped, and the march stops where one
// would reach the emitter. Each step is `vct.shadow_step_factor` of the cells read. The
// directional volumes are read as a ray from the emitter meets them (along -dir): they
// hide a surface from behind (gi/vct/anisotropic.glsl), and an occluder between the two
// is lit on the emitter's side, which a cone from the receiver would see from behind and
// pass.
float emitter_visibility(vec3 origin, vec3 surface, vec3 n, vec3 dir, vec4 plane) {
    float voxel = vct.origin.w;
    float grid_size = voxel * float(vct.resolution);
    float cos_plane = -dot(plane.xyz, dir);
    float plane_dist = (dot(plane.xyz, origin) - plane.w) / max(cos_plane, 1e-6);
    float occlusion = 0.0;
    float dist = voxel;
    while (occlusion < 0.99 && dist < vct.max_distance) {
        vec3 x = origin + dir * dist;
        float to_receiver = (dot(x - surface, n) - voxel) / 1.5;
        float to_emitter = ((plane_dist - dist) * cos_plane - voxel) / 1.5;
        vec3 uvw = (x - vct.origin.xyz) / grid_size;
        if (to_emitter < voxel || !inside_grid(uvw)) {
            break;
        }
        float footprint = voxel;
        if (to_receiver >= voxel) {
            footprint = min(max(voxel, 2.0 * vct.shadow_tan_half * dist), min(to_receiver, to_emitter));
            float s = sample_voxels(uvw, -dir, log2(footprint / voxel)).a;
            occlusion += (1.0 - occlusion) * (1.0 - pow(1.0 - clamp(s, 0.0, 0.9999), vct.shadow_step_factor));
        }
        dist += footprint * vct.shadow_step_factor;
    }
    return 1.0 - occlusion;
}

// The screen's ring cones are each traced as sub-cones, narrower cones around their
// axis that read finer levels: a 60-degree cone leaving a surface blends, in its coarse
// cells, the surface's own lit voxels and walls seen edge-on that its rays never meet,
// and a narrower cone blends less of them (per cone against the exact cone integrals,
// BENCHMARKS.md, session 11). About 20 sub-cones go round the ring whatever its count
// (the ring cones overlap more as there are more of them): four per cone up to five
// cones (each 0.53 as wide, 0.47 of the half-angle off the axis, in a square around
// it), two up to ten (0.63 as wide, 0.4 off), else none. They step as far as the cone
// they stand for, so a sub-cone costs about one cone (stepping by their own width is
// slightly better and twice as slow; the counts, widths and what is split are the best
// of the sweeps in BENCHMARKS.md, session 11).
// With `--cosine-cones`: a ring cone spans 27.5 to 87.5 degrees from the normal, where
// the cosine falls from 0.89 to 0.04, and stands for the cosine-weighted irradiance
// integral over its part of the hemisphere. Its sub-cones lie towards and away from the
// normal (two up to ten ring cones: one each way), and each counts by the cosine of its
// axis, so that the cone's grazing side counts as little as it does in the integral;
// the path tracer's cone component weighs its rays the same way. Without it the
// sub-cones lie in a frame fixed to the world's y axis (laid out along and across the
// ring they score no better) and count alike.
vec4 trace_ring_cone(vec3 origin, vec3 dir, int parts, float min_lod, vec3 surface, vec3 n, float step_factor,
                     int ao_volume) {
    if (parts == 1) {
        return trace_cone(origin, dir, vct.diffuse_tan_half, min_lod, surface, n, ao_volume, step_factor);
    }
    float offset = atan(vct.diffuse_tan_half) * (parts == 4 ? 0.467 : 0.4);
    float tan_half = vct.diffuse_tan_half * (parts == 4 ? 0.53 : 0.63);
    // (The cone along the normal, split with `--snapped-cones`, has no meridian: its
    // sub-cones lie at one cosine, so they count alike in the fixed frame.)
    bool cosine = vct.cosine_cones != 0u && dot(dir, n) < 0.999;
    vec3 u;
    vec3 v;
    if (cosine) {
        // u across the ring, v along its meridian, towards n.
        v = normalize(n - dot(n, dir) * dir);
        u = cross(v, dir);
    } else {
        u = perpendicular(dir);
        v = cross(dir, u);
    }
    vec4 sum = vec4(0.0);
    float weights = 0.0;
    for (int i = 0; i < parts; i++) {
        float phi = 6.2831853 * (float(i) + 0.5) / float(parts);
        vec3 d = normalize(cos(offset) * dir + sin(offset) * (cos(phi) * u + sin(phi) * v));
        float w = cosine ? max(dot(d, n), 0.0) : 1.0;
        sum += w * trace_cone(origin, d, tan_half, min_lod, surface, n, ao_volume,
                              step_factor * vct.diffuse_tan_half / tan_half);
        weights += w;
    }
    return weights > 0.0 ? sum / weights : vec4(0.0);
}

// The lattice gather (`--lattice-cones`, LATTICE_CONES > 0, with snapped lookups):
// the cosine-weighted mean radiance over the hemisphere around n as the plain mean of N
// narrow cones whose axes are spread evenly over the cosine-weighted hemisphere: a
// Fibonacci spiral over the unit disc, lifted onto the hemisphere (Malley's method), so
// that every cone stands for the same share of the integral and counts 1/N.
// Why: a snapped lookup reads cells at most the cone's radius, so each cone responds to a
// small bright feature as a tent about as wide as those cells, a pencil of its disc, not
// the disc. The ring's cones (their sub-cones four to a cone) left the gather's response
// to a small source 0 to 3.9 times the cosine's share across the hemisphere, 3.6 along
// the normal (BENCHMARKS.md, session 34). Tents of half-width c set c apart sum to a
// constant, so cones set about one cell apart give a response that follows the
// lattice's density, which is the cosine's. The cells lie between half the radius and
// the radius (whole levels), so a cone's half-angle is sqrt(2) times the lattice's
// spacing, sqrt(pi / N) radians near the normal: their geometric mean is the spacing.
// Towards the horizon the lifted lattice stretches along the meridian by 1 / cos(theta),
// so the cones widen by its square root there (the stretch's mean over the two
// directions), up to a cosine of 0.2. The cones near the normal must stay within 17
// degrees, as the sub-cones that keep a closed room closed: at 72 cones they are 16.8
// degrees; 48 (20.5 degrees) let a tenth of a closed box's light out.
// The screen's gather only: the voxels' bounce keeps the ring, whose light the screen's
// gather then reads through the lattice. 72 cones from every voxel made a bounce at 256^3
// take 25 s in one dispatch on lavapipe, which crashed when other work shared its cores.
// Returns cones first..first + count - 1's share of the mean (rgb radiance, a occlusion),
// so that the gather may be split over dispatches (cone_trace.rs says why).
layout(constant_id = SPEC_LATTICE_CONES) const uint LATTICE_CONES = 0u;

vec4 gather_lattice(vec3 surface, vec3 origin, vec3 n, float min_lod, int ao_volume, int first, int count) {
    int total = int(LATTICE_CONES);
    vec3 t = perpendicular(n);
    vec3 b = cross(n, t);
    float spacing = sqrt(3.14159265 / float(total));
    vec4 sum = vec4(0.0);
    for (int i = first; i < first + count; i++) {
        float r = sqrt((float(i) + 0.5) / float(total));
        float phi = float(i) * 2.39996323;
        vec3 d = normalize(r * cos(phi) * t + r * sin(phi) * b + sqrt(max(1.0 - r * r, 0.0)) * n);
        float tan_half = tan(1.41421356 * spacing / sqrt(max(dot(d, n), 0.2)));
        sum += march_cells(origin, d, tan_half, min_lod, surface, n, ao_volume);
    }
    return sum / float(total);
}

// The one directional volume ambient occlusion reads opacity from (trace_cone), or -1
// without it.
int ao_volume_facing(vec3 n, bool with_ao) {
    if (!with_ao) {
        return -1;
    }
    int axis = major_axis(abs(n));
    return 2 * axis + (n[axis] >= 0.0 ? 0 : 1);
}

// Cosine-weighted mean radiance over the hemisphere around n of the surface at `surface`
// from `cones` cones starting at `origin` (diffuse_cone_axis), each stepping
// `step_factor` of its diameter, the ring's traced as sub-cones where `split_ring` (the
// screen's). With `with_ao`, alpha is the ambient occlusion (1 where nothing near
// occludes); else 1. With `only` (0..cones-1), the radiance that cone alone gathers
// instead (`--cone`: a component against the path tracer's exact cone integral).
vec4 gather_diffuse(vec3 surface, vec3 origin, vec3 n, int cones, float min_lod, bool with_ao, float step_factor,
                    bool split_ring, int only) {
    int ao_volume = ao_volume_facing(n, with_ao);
    vec3 t = perpendicular(n);
    vec3 b = cross(n, t);
    int ring = cones - 1;
    int parts = split_ring ? (ring <= 5 ? 4 : (ring <= 10 ? 2 : 1)) : 1;
    // One call site per kind of cone, also for `only`: each is inlined, and lavapipe ran
    // the gather 2 % slower with a second copy of each for the single cone.
    // With `--snapped-cones` the cone along the normal is traced as four sub-cones, in
    // the screen's gather and in the voxels' bounce alike: whole, its lookups reach past
    // a closed room's far wall into the empty space beyond, where its outer rays would
    // meet the walls beside it (edge-on to the cone). In a closed emissive box whose
    // walls lie inside the grid it gathered 0.84 of the walls' radiance at 64³ and 0.67
    // at 256³; as sub-cones 0.97 and 0.997.
    vec4 centre = vec4(0.0);
    if (only <= 0) {
        centre = SNAPPED_CONES
                     ? trace_ring_cone(origin, n, 4, min_lod, surface, n, step_factor, ao_volume)
                     : trace_cone(origin, n, vct.diffuse_tan_half, min_lod, surface, n, ao_volume, step_factor);
    }
    if (only == 0) {
        return vec4(centre.rgb, 1.0);
    }
    if (ring == 0) {
        return vec4(centre.rgb, 1.0 - centre.a);
    }
    vec4 around = vec4(0.0);
    for (int i = only > 0 ? only : 1; i <= (only > 0 ? only : ring); i++) {
        around += trace_ring_cone(origin, diffuse_cone_axis(n, t, b, i, ring), parts, min_lod, surface, n, step_factor,
                                  ao_volume);
    }
    if (only > 0) {
        return vec4(around.rgb, 1.0);
    }
    // With `--cosine-cones` each cone stands for its part of the hemisphere, weighted by
    // that part's share of the cosine-weighted integral: the cone along n for the cap it
    // covers, of half-angle h, which holds sin^2(h) of it (1/4 at the default 60
    // degrees), the ring's cones evenly for the band from h to the horizon, gaps and
    // overlaps included.
    // Without it, cosine weights of the cones themselves: a cone of half-angle 30
    // degrees at angle a from n holds pi sin^2(30) cos(a) of the cosine-weighted
    // hemisphere: pi/4 along n, about pi/8 in the ring. Five such cones fill the ring;
    // more overlap and share the ring's pi * 5/8, so its share does not grow with the
    // count (the gaps towards the horizon are filled in proportion).
    float t2 = vct.diffuse_tan_half * vct.diffuse_tan_half;
    float ring_share = 0.5 * float(min(ring, 5));
    float cap_share = vct.cosine_cones != 0u ? t2 / (1.0 + t2) : 1.0 / (1.0 + ring_share);
    vec4 sum = cap_share * centre + (1.0 - cap_share) * around / float(ring);
    return vec4(sum.rgb, 1.0 - sum.a);
}
#endif
