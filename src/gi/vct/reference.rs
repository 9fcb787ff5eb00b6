//! CPU reference implementations (test oracles) of the dense-grid GI passes: voxelization
//! and the anisotropic mip filter. Simple and slow on purpose: they state what the GPU
//! passes must produce, so the GPU output can be checked against them.

use glam::{UVec3, Vec3};

pub use super::Grid;

fn linear(n: u32, c: UVec3) -> usize {
    let n = n as usize;
    c.x as usize + n * (c.y as usize + n * c.z as usize)
}

/// Akenine-Möller's separating-axis test of a triangle against the closed box
/// `center` ± `half`: the 3 box normals, the triangle normal and the 9 cross products of
/// the box axes with the triangle edges. No epsilon: touching counts as overlapping.
/// Degenerate triangles work too: a zero axis never separates, and the remaining axes
/// are those of the segment or point the triangle collapses to.
pub fn tri_box_overlap(center: Vec3, half: Vec3, tri: [Vec3; 3]) -> bool {
    let v = tri.map(|p| p - center);
    let edges = [v[1] - v[0], v[2] - v[1], v[0] - v[2]];
    let units = [Vec3::X, Vec3::Y, Vec3::Z];
    let normal = edges[0].cross(edges[1]);
    let mut axes = units
        .into_iter()
        .chain([normal])
        .chain(edges.into_iter().flat_map(|e| units.map(|u| u.cross(e))));
    !axes.any(|axis| separates(axis, &v, half))
}

/// Whether `axis` separates the triangle `v` (relative to the box centre) from the box of
/// half-extent `half`. All three vertices are projected, even on the normal where they
/// agree in exact arithmetic, so that the rounded normal cannot make the test miss.
fn separates(axis: Vec3, v: &[Vec3; 3], half: Vec3) -> bool {
    let p = v.map(|p| axis.dot(p));
    let r = half.dot(axis.abs());
    p[0].min(p[1]).min(p[2]) > r || p[0].max(p[1]).max(p[2]) < -r
}

/// N³ occupancy: true where some triangle intersects the closed voxel box.
pub fn voxelize(triangles: &[[Vec3; 3]], grid: &Grid) -> Vec<bool> {
    mark(triangles, grid, 0.0)
}

/// N³ set of the voxels whose box, grown by one voxel on every side, overlaps some
/// triangle: the most a voxelization may mark without adding a voxel farther than one
/// voxel from a triangle. Always a superset of [`voxelize`].
pub fn within_one_voxel(triangles: &[[Vec3; 3]], grid: &Grid) -> Vec<bool> {
    mark(triangles, grid, 1.0)
}

/// Marks the voxels whose closed box, grown by `grow` voxels on every side, overlaps a
/// triangle, testing each triangle only against the voxels of its clamped bounds.
fn mark(triangles: &[[Vec3; 3]], grid: &Grid, grow: f32) -> Vec<bool> {
    let n = grid.resolution;
    let mut marked = vec![false; (n as usize).pow(3)];
    if n == 0 {
        return marked;
    }
    let half = Vec3::splat(0.5 + grow);
    let top = Vec3::splat((n - 1) as f32);
    for tri in triangles {
        // In grid units voxel i spans [i, i + 1] exactly, so the box corners carry no
        // rounding and the bounds below agree with the box test.
        let t = tri.map(|p| (p - grid.origin) / grid.voxel_size);
        let lo = t[0].min(t[1]).min(t[2]);
        let hi = t[0].max(t[1]).max(t[2]);
        // The grown box [i - grow, i + 1 + grow] meets [lo, hi] iff
        // lo - 1 - grow <= i <= hi + grow.
        let first = (lo - 1.0 - grow).ceil().max(Vec3::ZERO);
        let last = (hi + grow).floor().min(top);
        // Also skips triangles with NaN coordinates, for which no comparison holds.
        if !first.cmple(last).all() {
            continue;
        }
        let (first, last) = (first.as_uvec3(), last.as_uvec3());
        for k in first.z..=last.z {
            for j in first.y..=last.y {
                for i in first.x..=last.x {
                    let index = grid.index(i, j, k);
                    if !marked[index] {
                        let center = UVec3::new(i, j, k).as_vec3() + 0.5;
                        marked[index] = tri_box_overlap(center, half, t);
                    }
                }
            }
        }
    }
    marked
}

/// What `glsl/gi/vct/anisotropic.glsl`'s `facing` shows of a base voxel of premultiplied
/// radiance `value` with packed RGBA8 normal `packed` (turned to its lit side) to cones
/// travelling along `direction`: all of it facing the cone, half edge-on, none from
/// behind; a two-sided voxel (alpha 0) keeps its opacity from behind (half edge-on).
pub fn seen_facing(packed: u32, value: [f32; 4], direction: usize) -> [f32; 4] {
    let n = unpacked_normal(packed);
    if n == Vec3::ZERO {
        return value;
    }
    let mut towards_viewer = Vec3::ZERO;
    towards_viewer[direction / 2] = if direction % 2 == 0 { -1.0 } else { 1.0 };
    let c = n.dot(towards_viewer);
    let w = (0.5 + 4.0 * c).clamp(0.0, 1.0);
    let cover = if packed >> 24 == 0 {
        (0.5 + 4.0 * c.abs()).clamp(0.0, 1.0)
    } else {
        w
    };
    [value[0] * w, value[1] * w, value[2] * w, value[3] * cover]
}

/// The unit normal of a packed RGBA8 voxel normal, zero where it is shorter than 0.2 (no
/// single direction), as `glsl/gi/vct/anisotropic.glsl` and `dense/filter.comp` read it.
fn unpacked_normal(packed: u32) -> Vec3 {
    let n = Vec3::new(
        (packed & 0xff) as f32,
        ((packed >> 8) & 0xff) as f32,
        ((packed >> 16) & 0xff) as f32,
    ) / 127.5
        - 1.0;
    if n.length() < 0.2 {
        Vec3::ZERO
    } else {
        n.normalize()
    }
}

/// The first level of the cells' surface planes and coverage (`Store::planes`) from
/// the base level's opacity and packed normals (resolution n): per cell of 2x2x2 voxels,
/// the mean of opacity times (normal, normal . centre), the centre in grid units less 0.5,
/// and the mean opacity.
pub fn filter_planes_base(opacity: &[f32], normals: &[u32], n: u32) -> (Vec<[f32; 4]>, Vec<f32>) {
    let children =
        |p: UVec3| (0..8u32).map(move |i| p * 2 + UVec3::new(i & 1, (i >> 1) & 1, i >> 2));
    let half = n / 2;
    let mut planes = Vec::new();
    let mut coverage = Vec::new();
    for z in 0..half {
        for y in 0..half {
            for x in 0..half {
                let mut plane = [0.0f32; 4];
                let mut cover = 0.0;
                for c in children(UVec3::new(x, y, z)) {
                    let a = opacity[linear(n, c)];
                    let normal = unpacked_normal(normals[linear(n, c)]);
                    let centre = (c.as_vec3() + 0.5) / n as f32 - 0.5;
                    plane[0] += a * normal.x;
                    plane[1] += a * normal.y;
                    plane[2] += a * normal.z;
                    plane[3] += a * normal.dot(centre);
                    cover += a;
                }
                planes.push(plane.map(|v| v / 8.0));
                coverage.push(cover / 8.0);
            }
        }
    }
    (planes, coverage)
}

/// The next level of the planes (or the coverage, in the first channel) from the level
/// below (resolution n -> n/2): the mean of each cell's 2x2x2 children.
pub fn filter_mean(level: &[[f32; 4]], n: u32) -> Vec<[f32; 4]> {
    let half = n / 2;
    let mut out = Vec::new();
    for z in 0..half {
        for y in 0..half {
            for x in 0..half {
                let mut sum = [0.0f32; 4];
                for i in 0..8u32 {
                    let c = UVec3::new(x, y, z) * 2 + UVec3::new(i & 1, (i >> 1) & 1, i >> 2);
                    let v = level[linear(n, c)];
                    for k in 0..4 {
                        sum[k] += v[k];
                    }
                }
                out.push(sum.map(|v| v / 8.0));
            }
        }
    }
    out
}

/// Premultiplied RGBA `front` composited over `back`: what a ray sees passing through
/// `front` first, then `back`.
pub fn over(front: [f32; 4], back: [f32; 4]) -> [f32; 4] {
    let transmittance = 1.0 - front[3];
    std::array::from_fn(|c| front[c] + transmittance * back[c])
}

/// Level 1 of all six directions (+X, -X, +Y, -Y, +Z, -Z, the way a cone travels) from
/// the isotropic base level (resolution n, n even): six volumes of resolution n/2.
pub fn filter_base(base: &[[f32; 4]], n: u32) -> [Vec<[f32; 4]>; 6] {
    std::array::from_fn(|direction| filter_directional(base, n, direction))
}

/// Next level of one direction from the level below (same direction), resolution
/// n -> n/2. The 8 children of a parent pair up along the direction's axis; each pair is
/// composited front to back in the order a cone travelling that way meets them, and the
/// parent is the plain mean of the 4 pairs.
pub fn filter_directional(level: &[[f32; 4]], n: u32, direction: usize) -> Vec<[f32; 4]> {
    assert!(n >= 2 && n % 2 == 0, "resolution {n} is not even");
    assert_eq!(
        level.len(),
        (n as usize).pow(3),
        "level size for resolution {n}"
    );
    assert!(direction < 6, "direction {direction} is not one of the six");
    let axis = direction / 2;
    let others = [(axis + 1) % 3, (axis + 2) % 3];
    // Travelling towards +, a cone meets the child at the lower coordinate first.
    let front_offset = (direction % 2) as u32;
    let m = n / 2;
    let mut out = Vec::with_capacity((m as usize).pow(3));
    for k in 0..m {
        for j in 0..m {
            for i in 0..m {
                let corner = 2 * UVec3::new(i, j, k);
                let mut sum = [0.0; 4];
                for pair in 0..4 {
                    let mut front = corner;
                    front[others[0]] += pair & 1;
                    front[others[1]] += pair >> 1;
                    let mut back = front;
                    front[axis] += front_offset;
                    back[axis] += 1 - front_offset;
                    let seen = over(level[linear(n, front)], level[linear(n, back)]);
                    for (s, c) in sum.iter_mut().zip(seen) {
                        *s += c;
                    }
                }
                out.push(sum.map(|s| s * 0.25));
            }
        }
    }
    out
}

/// `--directional-filter rows` by its definition: the cells `width` voxels wide (a power
/// of two dividing `n`) of the base `voxels` (each as seen along `direction`, `n`³), each
/// cell's rows of voxels along the direction's axis composited front to back, then
/// averaged.
pub fn filter_rows(voxels: &[[f32; 4]], n: u32, width: u32, direction: usize) -> Vec<[f32; 4]> {
    assert_eq!(
        voxels.len(),
        (n as usize).pow(3),
        "voxels for resolution {n}"
    );
    assert!(
        width.is_power_of_two() && n % width == 0,
        "cells of {width} in {n}"
    );
    let axis = direction / 2;
    let others = [(axis + 1) % 3, (axis + 2) % 3];
    let m = n / width;
    let mut out = Vec::with_capacity((m as usize).pow(3));
    for k in 0..m {
        for j in 0..m {
            for i in 0..m {
                let corner = width * UVec3::new(i, j, k);
                let mut sum = [0.0; 4];
                for v in 0..width {
                    for u in 0..width {
                        let mut row = [0.0; 4];
                        for t in 0..width {
                            // Travelling towards +, a cone meets the lower coordinate first.
                            let along = if direction % 2 == 0 { t } else { width - 1 - t };
                            let mut voxel = corner;
                            voxel[axis] += along;
                            voxel[others[0]] += u;
                            voxel[others[1]] += v;
                            row = over(row, voxels[linear(n, voxel)]);
                        }
                        for (s, c) in sum.iter_mut().zip(row) {
                            *s += c;
                        }
                    }
                }
                out.push(sum.map(|s| s / (width * width) as f32));
            }
        }
    }
    out
}

/// Every triangle of `scene` at time 0, in world space.
pub fn world_triangles(scene: &crate::scene::Scene) -> Vec<[Vec3; 3]> {
    world_triangles_where(scene, |_| true)
}

/// The triangles of `scene` at time 0, in world space, whose material `keep` accepts.
pub fn world_triangles_where(
    scene: &crate::scene::Scene,
    keep: impl Fn(&crate::scene::Material) -> bool,
) -> Vec<[Vec3; 3]> {
    let mut triangles = Vec::new();
    for (m, mesh) in scene.meshes.iter().enumerate() {
        if !keep(&scene.materials[mesh.material as usize]) {
            continue;
        }
        let model = scene.mesh_transform(m, 0.0);
        for t in mesh.indices.chunks_exact(3) {
            triangles.push(
                [t[0], t[1], t[2]].map(|i| {
                    model.transform_point3(Vec3::from(mesh.vertices[i as usize].position))
                }),
            );
        }
    }
    triangles
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Deterministic xorshift64* so that the random cases never change between runs.
    struct Rng(u64);

    impl Rng {
        /// Uniform in [0, 1).
        fn unit(&mut self) -> f32 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40) as f32 / (1u32 << 24) as f32
        }

        /// Uniform in [lo, hi) on every axis.
        fn vec3(&mut self, lo: f32, hi: f32) -> Vec3 {
            Vec3::new(self.unit(), self.unit(), self.unit()) * (hi - lo) + lo
        }
    }

    /// Random triangles inside `grid` (at least half a voxel from its faces), with
    /// vertices up to `spread` voxels from a random centre.
    fn soup(rng: &mut Rng, grid: &Grid, count: usize, spread: f32) -> Vec<[Vec3; 3]> {
        let n = grid.resolution as f32;
        (0..count)
            .map(|_| {
                let c = rng.vec3(spread + 0.5, n - spread - 0.5);
                [(); 3].map(|_| grid.origin + (c + rng.vec3(-spread, spread)) * grid.voxel_size)
            })
            .collect()
    }

    fn coords(grid: &Grid) -> impl Iterator<Item = UVec3> {
        let n = grid.resolution;
        (0..n).flat_map(move |k| (0..n).flat_map(move |j| (0..n).map(move |i| UVec3::new(i, j, k))))
    }

    /// The occupied voxels, as coordinates.
    fn occupied(set: &[bool], grid: &Grid) -> Vec<UVec3> {
        coords(grid)
            .filter(|c| set[grid.index(c.x, c.y, c.z)])
            .collect()
    }

    /// The Chebyshev distance between two voxels.
    fn chebyshev(a: UVec3, b: UVec3) -> u32 {
        (a.as_ivec3() - b.as_ivec3()).abs().max_element() as u32
    }

    /// Whether the occupied voxels form one 26-connected set (flood fill from the first).
    fn connected(set: &[bool], grid: &Grid) -> bool {
        let voxels = occupied(set, grid);
        let Some(&start) = voxels.first() else {
            return true;
        };
        let mut reached = vec![false; set.len()];
        reached[grid.index(start.x, start.y, start.z)] = true;
        let mut stack = vec![start];
        let mut count = 1;
        while let Some(v) = stack.pop() {
            for &w in &voxels {
                let index = grid.index(w.x, w.y, w.z);
                if !reached[index] && chebyshev(v, w) == 1 {
                    reached[index] = true;
                    count += 1;
                    stack.push(w);
                }
            }
        }
        count == voxels.len()
    }

    const UNIT_BOX: (Vec3, Vec3) = (Vec3::ZERO, Vec3::ONE);

    #[test]
    fn triangle_through_centre_overlaps() {
        let (c, h) = UNIT_BOX;
        let tri = [
            Vec3::new(-2.0, -2.0, 0.3),
            Vec3::new(2.0, -2.0, -0.1),
            Vec3::new(0.0, 2.0, 0.0),
        ];
        assert!(tri_box_overlap(c, h, tri));
    }

    #[test]
    fn triangle_a_hair_outside_a_face_does_not_overlap() {
        let (c, h) = UNIT_BOX;
        let hair = f32::from_bits(1.0f32.to_bits() + 1);
        let at = |z: f32| {
            [
                Vec3::new(-5.0, -5.0, z),
                Vec3::new(5.0, -5.0, z),
                Vec3::new(0.0, 5.0, z),
            ]
        };
        assert!(!tri_box_overlap(c, h, at(hair)));
        assert!(!tri_box_overlap(c, h, at(-hair)));
        // Touching the closed face counts.
        assert!(tri_box_overlap(c, h, at(1.0)));
        assert!(tri_box_overlap(c, h, at(-1.0)));
    }

    #[test]
    fn triangle_whose_plane_cuts_the_box_but_which_misses_it_does_not_overlap() {
        let (c, h) = UNIT_BOX;
        // Every point of the triangle has z >= 0 and x + y >= 2.3, while the box has
        // x + y <= 2: only the edge axis z x (b - a), along (1, 1, 0), separates them.
        let tri = [
            Vec3::new(2.5, -0.2, 0.0),
            Vec3::new(-0.2, 2.5, 0.0),
            Vec3::new(10.0, 10.0, 10.0),
        ];
        let normal = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
        let side = |p: Vec3| normal.dot(p - tri[0]);
        let corners: Vec<f32> = (0..8)
            .map(|b| {
                side(Vec3::new((b & 1) as f32, ((b >> 1) & 1) as f32, (b >> 2) as f32) * 2.0 - 1.0)
            })
            .collect();
        assert!(corners.iter().any(|&s| s > 0.0) && corners.iter().any(|&s| s < 0.0));
        let lo = tri[0].min(tri[1]).min(tri[2]);
        let hi = tri[0].max(tri[1]).max(tri[2]);
        assert!(lo.cmple(h).all() && hi.cmpge(-h).all());
        assert!(!tri_box_overlap(c, h, tri));
    }

    #[test]
    fn triangle_past_a_corner_is_separated_by_its_normal() {
        let (c, h) = UNIT_BOX;
        // In the plane x + y + z = s: the box reaches s = 3 at its corner (1, 1, 1), and
        // the triangle's projection along each box axis covers the box's, so neither the
        // box normals nor the edge axes separate them.
        let at = |s: f32| {
            let o = (s - 10.0) / 2.0;
            [
                Vec3::new(10.0, o, o),
                Vec3::new(o, 10.0, o),
                Vec3::new(o, o, 10.0),
            ]
        };
        assert!(!tri_box_overlap(c, h, at(3.1)));
        assert!(tri_box_overlap(c, h, at(3.0)));
    }

    #[test]
    fn big_triangle_containing_the_box_overlaps() {
        let c = Vec3::new(3.0, -2.0, 0.5);
        let h = Vec3::new(0.5, 0.25, 0.125);
        let tri = [
            Vec3::new(-100.0, -100.0, 0.55),
            Vec3::new(100.0, -100.0, 0.5),
            Vec3::new(0.0, 100.0, 0.45),
        ];
        assert!(tri_box_overlap(c, h, tri));
    }

    #[test]
    fn degenerate_triangles() {
        let (c, h) = UNIT_BOX;
        let a = Vec3::new(1.0, 0.3, -0.2);
        let b = Vec3::new(3.0, 0.3, -0.2);
        // A segment touching the face x = 1 at one point.
        assert!(tri_box_overlap(c, h, [a, b, a]));
        assert!(tri_box_overlap(c, h, [a, a, a]));
        let off = Vec3::new(f32::from_bits(1.0f32.to_bits() + 1), 0.3, -0.2);
        assert!(!tri_box_overlap(c, h, [off, b, off]));
        // A segment past the corner (x + y = 2.3 > 2) whose bounds overlap the box.
        let (p, q) = (Vec3::new(2.5, -0.2, 0.0), Vec3::new(-0.2, 2.5, 0.0));
        assert!(!tri_box_overlap(c, h, [p, q, q]));
        // A segment along x + y = 2 touches the corner edge at (1, 1, 0).
        let (p, q) = (Vec3::new(2.5, -0.5, 0.0), Vec3::new(-0.5, 2.5, 0.0));
        assert!(tri_box_overlap(c, h, [p, q, q]));
    }

    /// 8³ grid of 0.25-sized voxels, at an origin where every coordinate used is exact.
    const GRID8: Grid = Grid {
        origin: Vec3::new(-1.0, -2.0, 0.5),
        voxel_size: 0.25,
        resolution: 8,
    };

    /// Two triangles covering the plane z = `z` (world) over more than the whole grid.
    fn quad_at(grid: &Grid, z: f32) -> [[Vec3; 3]; 2] {
        let (lo, hi) = (
            grid.origin - 2.0 * grid.voxel_size,
            grid.origin + 10.0 * grid.voxel_size,
        );
        let p = |x: f32, y: f32| Vec3::new(x, y, z);
        [
            [p(lo.x, lo.y), p(hi.x, lo.y), p(hi.x, hi.y)],
            [p(lo.x, lo.y), p(hi.x, hi.y), p(lo.x, hi.y)],
        ]
    }

    /// The z layers holding an occupied voxel, and whether each such layer is full.
    fn layers(set: &[bool], grid: &Grid) -> Vec<(u32, bool)> {
        let n = grid.resolution;
        (0..n)
            .filter_map(|k| {
                let count = coords(grid)
                    .filter(|c| c.z == k && set[grid.index(c.x, c.y, c.z)])
                    .count();
                (count > 0).then_some((k, count == (n * n) as usize))
            })
            .collect()
    }

    #[test]
    fn quad_inside_a_layer_marks_exactly_that_layer() {
        let g = GRID8;
        let set = voxelize(&quad_at(&g, g.origin.z + 0.5 * g.voxel_size), &g);
        assert_eq!(layers(&set, &g), [(0, true)]);
        assert_eq!(set.iter().filter(|&&v| v).count(), 64);
    }

    #[test]
    fn quad_on_a_boundary_plane_marks_both_layers() {
        let g = GRID8;
        let set = voxelize(&quad_at(&g, g.origin.z + 4.0 * g.voxel_size), &g);
        assert_eq!(layers(&set, &g), [(3, true), (4, true)]);
        // On the grid's own faces only the layer inside exists.
        let set = voxelize(&quad_at(&g, g.origin.z), &g);
        assert_eq!(layers(&set, &g), [(0, true)]);
        let set = voxelize(&quad_at(&g, g.origin.z + 8.0 * g.voxel_size), &g);
        assert_eq!(layers(&set, &g), [(7, true)]);
        let set = voxelize(&quad_at(&g, g.origin.z + 9.0 * g.voxel_size), &g);
        assert_eq!(layers(&set, &g), []);
    }

    #[test]
    fn slivers_give_connected_sets() {
        let g = Grid {
            origin: Vec3::new(0.3, -1.7, 2.1),
            voxel_size: 0.37,
            resolution: 16,
        };
        let at = |p: Vec3| g.origin + p * g.voxel_size;
        let a = Vec3::new(1.3, 2.1, 0.7);
        let b = Vec3::new(14.6, 12.9, 13.4);
        let mut slivers = vec![[at(a), at(b), at(b + Vec3::new(0.01, -0.02, 0.015))]];
        let mut rng = Rng(0x5eed);
        for _ in 0..50 {
            let (a, b) = (rng.vec3(0.5, 15.5), rng.vec3(0.5, 15.5));
            slivers.push([at(a), at(b), at(b + rng.vec3(-0.05, 0.05))]);
        }
        for tri in slivers {
            let set = voxelize(&[tri], &g);
            let voxels = occupied(&set, &g);
            // The sliver spans at least as many voxels as its longest axis crosses.
            let span = ((tri[1] - tri[0]) / g.voxel_size)
                .abs()
                .max_element()
                .floor() as usize;
            assert!(voxels.len() > span, "{tri:?}: {} voxels", voxels.len());
            for &v in &voxels {
                assert!(
                    voxels.iter().any(|&w| chebyshev(v, w) == 1),
                    "{tri:?}: {v} is isolated"
                );
            }
            assert!(connected(&set, &g), "{tri:?}");
        }
    }

    #[test]
    fn within_one_voxel_is_the_one_voxel_dilation_of_voxelize() {
        let g = Grid {
            origin: Vec3::new(-1.3, 0.2, 2.0),
            voxel_size: 0.37,
            resolution: 16,
        };
        let mut rng = Rng(42);
        let triangles = soup(&mut rng, &g, 60, 1.5);
        let exact = voxelize(&triangles, &g);
        let near = within_one_voxel(&triangles, &g);
        let occupied = occupied(&exact, &g);
        assert!(!occupied.is_empty());
        for c in coords(&g) {
            let index = g.index(c.x, c.y, c.z);
            assert!(!exact[index] || near[index], "{c} is occupied but not near");
            // The triangles lie inside the grid, so no triangle point is outside every voxel.
            let dilated = occupied.iter().any(|&o| chebyshev(c, o) <= 1);
            assert_eq!(near[index], dilated, "{c}");
        }
    }

    #[test]
    fn triangles_outside_the_grid_mark_nothing_but_may_be_near() {
        let g = GRID8;
        let below = g.origin.z - 0.5 * g.voxel_size;
        assert!(voxelize(&quad_at(&g, below), &g).iter().all(|&v| !v));
        assert_eq!(
            layers(&within_one_voxel(&quad_at(&g, below), &g), &g),
            [(0, true)]
        );
    }

    const RED: [f32; 4] = [1.0, 0.0, 0.0, 1.0];
    const GREEN: [f32; 4] = [0.0, 1.0, 0.0, 1.0];
    const EMPTY: [f32; 4] = [0.0; 4];

    fn assert_close(got: [f32; 4], want: [f32; 4], what: &str) {
        assert!(
            got.iter().zip(want).all(|(g, w)| (g - w).abs() <= 1e-6),
            "{what}: {got:?} != {want:?}"
        );
    }

    /// A base of resolution n whose voxel value depends on its coordinates.
    fn base_from(n: u32, value: impl Fn(UVec3) -> [f32; 4]) -> Vec<[f32; 4]> {
        let grid = Grid {
            origin: Vec3::ZERO,
            voxel_size: 1.0,
            resolution: n,
        };
        coords(&grid).map(value).collect()
    }

    #[test]
    fn opaque_constant_stays_constant_in_every_direction() {
        let colour = [0.2, 0.4, 0.6, 1.0];
        let base = vec![colour; 8usize.pow(3)];
        for (d, level) in filter_base(&base, 8).iter().enumerate() {
            assert_eq!(level.len(), 4usize.pow(3));
            let next = filter_directional(level, 4, d);
            let last = filter_directional(&next, 2, d);
            for v in level.iter().chain(&next).chain(&last) {
                assert_close(*v, colour, &format!("direction {d}"));
            }
        }
    }

    #[test]
    fn single_opaque_child_gives_a_quarter_in_every_direction() {
        let base = base_from(4, |c| if c == UVec3::ZERO { [1.0; 4] } else { EMPTY });
        for (d, level) in filter_base(&base, 4).iter().enumerate() {
            // One of the four pairs sees the opaque child, whether in front or behind.
            assert_close(level[0], [0.25; 4], &format!("direction {d}"));
            assert!(level[1..].iter().all(|&v| v == EMPTY), "direction {d}");
        }
    }

    #[test]
    fn front_child_hides_the_back_one() {
        for axis in 0..3 {
            let base = base_from(2, |c| if c[axis] == 0 { RED } else { GREEN });
            let levels = filter_base(&base, 2);
            assert_close(levels[2 * axis][0], RED, &format!("+ along axis {axis}"));
            assert_close(
                levels[2 * axis + 1][0],
                GREEN,
                &format!("- along axis {axis}"),
            );
            // Across the layers each pair is a single colour: half red, half green.
            for (d, level) in levels.iter().enumerate().filter(|(d, _)| d / 2 != axis) {
                assert_close(
                    level[0],
                    [0.5, 0.5, 0.0, 1.0],
                    &format!("direction {d}, layers along {axis}"),
                );
            }
        }
    }

    #[test]
    fn half_transparent_front_lets_half_of_the_back_through() {
        let base = base_from(2, |c| {
            if c.x == 0 {
                [0.5, 0.5, 0.5, 0.5]
            } else {
                [0.0, 0.0, 0.0, 1.0]
            }
        });
        let levels = filter_base(&base, 2);
        assert_close(levels[0][0], [0.5, 0.5, 0.5, 1.0], "+X");
        assert_close(levels[1][0], [0.0, 0.0, 0.0, 1.0], "-X");
        assert_close(
            over([0.5; 4], [0.0, 0.0, 0.0, 1.0]),
            [0.5, 0.5, 0.5, 1.0],
            "pair",
        );
    }
}
