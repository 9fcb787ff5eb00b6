//! The grid of spatial receivers that shades moving meshes (Sedláček 2019, 4.1): a
//! regular grid over the static scene's box, each point a receiver in six directions
//! (±x, ±y, ±z) whose transport the bake computes like a lightmap texel's. A point's six
//! irradiances are those of surfaces facing each axis there; a moving mesh's fragment
//! reads them trilinearly at its position and weights them by its normal.
//!
//! Two choices differ from the thesis:
//! - The points sit at the cells' centres, not their corners: the corners of the box are
//!   on its walls (a room's), where half a receiver's hemisphere would leave through the
//!   wall. The lookup clamps to the outer points, which extends the border outwards as the
//!   thesis's texture border does.
//! - Each direction measures the irradiance of a plane facing it (the cosine lobe), and a
//!   normal n combines them as Σ_a n_a² E(sign(n_a) a) (the "ambient cube", McTaggart
//!   2004): exact for a uniform field and for the six axes, where the thesis's own lobe
//!   (π/2 − acos(max(d·l, 0))) / (π/2) measures something no surface receives.

use glam::{UVec3, Vec3};
use rayon::prelude::*;

use super::receivers::Receiver;
use crate::ray::host::HostRays;
use crate::scene::Aabb;

/// The six directions of every point, in the order of the grid's slabs.
pub const DIRECTIONS: [Vec3; 6] = [
    Vec3::X,
    Vec3::NEG_X,
    Vec3::Y,
    Vec3::NEG_Y,
    Vec3::Z,
    Vec3::NEG_Z,
];

/// A regular grid of points at the centres of its cells.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    pub size: UVec3,
    pub min: Vec3,
    pub max: Vec3,
}

impl Grid {
    /// About `count` points over `bounds`, spread by the thesis's equations (4.1.1, after
    /// Amanatides and Woo) so that the cells are as near cubes as the counts allow: z's
    /// count first, then y's from what is left, then x's, each rounded up. An axis the box
    /// is flat along (under a thousandth of its longest) gets one point.
    pub fn new(bounds: &Aabb, count: u32) -> Self {
        let extent = bounds.size().to_array().map(|e| f64::from(e.max(0.0)));
        let longest = extent.iter().copied().fold(0.0, f64::max);
        let mut size = [1u32; 3];
        let mut active: Vec<usize> = (0..3).filter(|&a| extent[a] > 1e-3 * longest).collect();
        let mut remaining = f64::from(count.max(1));
        while let Some(a) = active.pop() {
            let volume: f64 = active.iter().map(|&b| extent[b]).product::<f64>() * extent[a];
            let per_unit = (remaining / volume).powf(1.0 / (active.len() + 1) as f64);
            // Rounded up, less a hair: an exact count such as 10 for 1000 in a cube must
            // not become 11 by the root's rounding.
            let n = (extent[a] * per_unit - 1e-9).ceil().max(1.0);
            size[a] = n as u32;
            remaining /= n;
        }
        Self {
            size: UVec3::from_array(size),
            min: bounds.min,
            max: bounds.max,
        }
    }

    pub fn point_count(&self) -> usize {
        (self.size.x * self.size.y * self.size.z) as usize
    }

    pub fn cell(&self) -> Vec3 {
        (self.max - self.min) / self.size.as_vec3()
    }

    /// The point with index `i` (x fastest, then y, then z).
    pub fn point(&self, i: usize) -> Vec3 {
        let i = i as u32;
        let s = self.size;
        let at = UVec3::new(i % s.x, i / s.x % s.y, i / (s.x * s.y));
        self.min + (at.as_vec3() + 0.5) * self.cell()
    }

    /// The points a trilinear lookup anywhere in `bounds` reads: the index ranges per axis,
    /// inclusive (empty bounds: none).
    pub fn footprint(&self, bounds: &Aabb) -> Option<(UVec3, UVec3)> {
        if bounds.is_empty() {
            return None;
        }
        let last = (self.size - 1).as_vec3();
        let to_index = |p: Vec3| (p - self.min) / self.cell() - 0.5;
        let low = to_index(bounds.min).floor().clamp(Vec3::ZERO, last);
        let high = (to_index(bounds.max).floor() + 1.0).clamp(Vec3::ZERO, last);
        Some((low.as_uvec3(), high.as_uvec3()))
    }

    /// The points' indices in `footprint`, x fastest.
    pub fn points_in(&self, (low, high): (UVec3, UVec3)) -> impl Iterator<Item = usize> + '_ {
        let s = self.size;
        (low.z..=high.z).flat_map(move |z| {
            (low.y..=high.y).flat_map(move |y| {
                (low.x..=high.x).map(move |x| ((z * s.y + y) * s.x + x) as usize)
            })
        })
    }
}

/// `count` directions spread evenly over the sphere (a Fibonacci lattice).
fn sphere_directions(count: usize) -> Vec<Vec3> {
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    (0..count)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f32 + 0.5) / count as f32;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * i as f32;
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect()
}

/// The grid's points, each moved out of geometry where it lies inside (4.1.1): of `rays`
/// rays over the sphere, where at least 80 % of those that meet a surface meet a back
/// face (rays that leave the scene do not count: a point outside the scene's shape is not
/// inside anything), the point moves along the shortest of them to `offset` beyond the
/// back face. Returns the points and how many moved.
pub fn place_points(grid: &Grid, host: &HostRays, rays: usize, offset: f32) -> (Vec<Vec3>, usize) {
    let pattern = sphere_directions(rays);
    let points: Vec<(Vec3, bool)> = (0..grid.point_count())
        .into_par_iter()
        .map(|i| {
            let p = grid.point(i);
            let (mut hits, mut back) = (0usize, 0usize);
            let mut shortest: Option<(f32, Vec3)> = None;
            for &d in &pattern {
                let Some(hit) = host.closest(p, d, 0.0) else {
                    continue;
                };
                hits += 1;
                if !hit.front {
                    back += 1;
                    if shortest.is_none_or(|(t, _)| hit.t < t) {
                        shortest = Some((hit.t, d));
                    }
                }
            }
            match shortest {
                Some((t, d)) if back * 10 >= hits * 8 => (p + d * (t + offset), true),
                _ => (p, false),
            }
        })
        .collect();
    let moved = points.iter().filter(|p| p.1).count();
    (points.into_iter().map(|p| p.0).collect(), moved)
}

/// The spatial receivers of `points` facing `direction` (their material and texel mean
/// nothing: the transport reads position and normal only).
pub fn receivers(points: &[Vec3], direction: Vec3) -> Vec<Receiver> {
    points
        .iter()
        .map(|&position| Receiver {
            position,
            normal: direction,
            material: 0,
            texel: [0, 0],
            inside: true,
        })
        .collect()
}

/// The irradiance at a surface of unit normal `n` from a point's six irradiances (in the
/// order of [`DIRECTIONS`]): the host twin of the gather's lookup.
pub fn irradiance(six: &[Vec3; 6], n: Vec3) -> Vec3 {
    let pick = |a: f32, plus: usize| six[if a >= 0.0 { plus } else { plus + 1 }] * (a * a);
    pick(n.x, 0) + pick(n.y, 2) + pick(n.z, 4)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn room() -> Aabb {
        Aabb {
            min: Vec3::new(-1.0, 0.0, -1.0),
            max: Vec3::new(1.0, 2.0, 1.0),
        }
    }

    /// The equations give about the count asked for, cells near cubes, one point along a
    /// flat axis.
    #[test]
    fn the_grid_spreads_its_points_as_cubes() {
        let cube = Grid::new(&room(), 1000);
        assert_eq!(cube.size, UVec3::splat(10));
        let slab = Aabb {
            min: Vec3::ZERO,
            max: Vec3::new(4.0, 1.0, 2.0),
        };
        let g = Grid::new(&slab, 2048);
        let count = g.point_count() as f32;
        assert!((2048.0..2048.0 * 1.3).contains(&count), "{:?}", g.size);
        let cell = g.cell();
        assert!(
            cell.max_element() / cell.min_element() < 1.5,
            "cells {cell} of {:?}",
            g.size
        );
        let flat = Aabb {
            min: Vec3::ZERO,
            max: Vec3::new(2.0, 0.0, 2.0),
        };
        let g = Grid::new(&flat, 100);
        assert_eq!(g.size.y, 1);
        assert!(g.point_count() >= 100, "{:?}", g.size);
        assert!(g.point(0).is_finite());
    }

    /// Points sit at the cells' centres; a box's footprint holds the eight points around
    /// each of its corners and is clamped to the grid.
    #[test]
    fn the_footprint_covers_every_lookup_in_the_box() {
        let g = Grid::new(&room(), 1000);
        assert!(g.point(0).abs_diff_eq(Vec3::new(-0.9, 0.1, -0.9), 1e-5));
        let last = g.point_count() - 1;
        assert!(g.point(last).abs_diff_eq(Vec3::new(0.9, 1.9, 0.9), 1e-5));
        let bounds = Aabb {
            min: Vec3::new(-0.25, 0.55, 0.0),
            max: Vec3::new(0.05, 0.65, 0.02),
        };
        let (low, high) = g.footprint(&bounds).unwrap();
        assert_eq!(low, UVec3::new(3, 2, 4));
        assert_eq!(high, UVec3::new(5, 3, 5));
        for i in g.points_in((low, high)) {
            let p = g.point(i);
            assert!(p.cmpge(bounds.min - g.cell()).all() && p.cmple(bounds.max + g.cell()).all());
        }
        assert_eq!(g.points_in((low, high)).count(), 3 * 2 * 2);
        let outside = Aabb {
            min: Vec3::splat(5.0),
            max: Vec3::splat(6.0),
        };
        assert_eq!(
            g.footprint(&outside),
            Some((UVec3::splat(9), UVec3::splat(9)))
        );
        assert_eq!(g.footprint(&Aabb::EMPTY), None);
    }

    /// The six directions give a uniform field exactly, and each axis its own irradiance.
    #[test]
    fn the_ambient_cube_is_exact_for_a_uniform_field_and_the_axes() {
        let uniform = [Vec3::splat(2.0); 6];
        for n in [
            Vec3::X,
            Vec3::new(1.0, 2.0, -3.0).normalize(),
            -Vec3::ONE.normalize(),
        ] {
            assert!(irradiance(&uniform, n).abs_diff_eq(Vec3::splat(2.0), 1e-5));
        }
        let six = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0].map(Vec3::splat);
        for (d, e) in DIRECTIONS.iter().zip(&six) {
            assert_eq!(irradiance(&six, *d), *e);
        }
    }
}
