//! The bake's ray casting on the GPU (Sedláček 2019, 3.2.3), through the scene ray
//! caster's batched queries: each probe's rays through the texel centres of its
//! equal-area octahedral maps (one for the receivers' visibility match, coarser ones for
//! the relight), and each receiver's cosine-distributed hemisphere rays.

use glam::{Quat, Vec3};

use super::octahedral;
use crate::gpu_layout::{RayHit, RayQuery, RAY_CLOSEST, RAY_NONE};
use crate::ray::query::RayQueries;
use crate::ray::Triangles;
use anyhow::Result;

/// What the probes see: per probe, a `side` × `side` equal-area octahedral map of closest
/// hits.
pub struct ProbeViews {
    pub side: usize,
    /// Per probe and texel, the hit (`RAY_NONE`: the sky).
    pub hits: Vec<RayHit>,
}

impl ProbeViews {
    /// Casts every probe's rays.
    pub fn cast(queries: &mut RayQueries, probes: &[Vec3], side: usize) -> Result<Self> {
        let texels = side * side;
        let mut rays = Vec::with_capacity(probes.len() * texels);
        for p in probes {
            for i in 0..texels {
                rays.push(query(*p, octahedral::texel_direction(i, side), 0.0));
            }
        }
        Ok(Self {
            side,
            hits: queries.run(&rays)?,
        })
    }

    /// How far probe `probe` sees along its texel holding the unit direction `d`
    /// (infinite where it sees the sky).
    pub fn depth(&self, probe: usize, d: Vec3) -> f32 {
        let hit = &self.hits[probe * self.side * self.side + octahedral::texel_of(d, self.side)];
        if hit.triangle == RAY_NONE {
            f32::INFINITY
        } else {
            hit.t
        }
    }

    /// The angular radius of a texel's cone of equal solid angle, 4π / side² = π δ².
    pub fn texel_radius(&self) -> f32 {
        2.0 / self.side as f32
    }
}

/// The rays each probe's relight reads (3.2.3.1; fewer at the far levels of detail,
/// 4.2.2): through the texel centres of [`RelightRays::MAPS`] equal-area octahedral maps
/// of sides `side`, `side / 2`, ..., each probe's maps one after the other, probe after
/// probe. A coarser level reads a coarser map whole rather than every other texel of a
/// fine one: a texel's centre is close to its solid angle's centre, where the texel in the
/// corner of a 2 × 2 block is half a texel off its block's, an error of the first order
/// in the radiance's slope (`relight_maps_integrate_analytic_radiance`).
pub struct RelightRays {
    pub side: usize,
    /// Per probe and ray, the hit (`RAY_NONE`: the sky).
    pub hits: Vec<RayHit>,
}

impl RelightRays {
    /// The maps: the finest for level 0 of the level of detail, half and a quarter of its
    /// side for the coarser levels (`frame::LOD_RELIGHT_MAP`).
    pub const MAPS: usize = 3;

    /// Casts every probe's relight rays through maps beginning with side `side`.
    pub fn cast(queries: &mut RayQueries, probes: &[Vec3], side: usize) -> Result<Self> {
        let rays = Self::rays(side);
        let mut all = Vec::with_capacity(probes.len() * rays.len());
        for p in probes {
            all.extend(rays.iter().map(|&(d, _)| query(*p, d, 0.0)));
        }
        Ok(Self {
            side,
            hits: queries.run(&all)?,
        })
    }

    /// Each probe's rays, map after map: the direction and the solid angle it stands for.
    pub fn rays(side: usize) -> Vec<(Vec3, f64)> {
        (0..Self::MAPS)
            .flat_map(|m| {
                let s = side >> m;
                let solid_angle = 4.0 * std::f64::consts::PI / (s * s) as f64;
                (0..s * s).map(move |t| (octahedral::texel_direction(t, s), solid_angle))
            })
            .collect()
    }

    /// Where map `m` begins among a probe's rays, and its side.
    pub fn map(side: usize, m: usize) -> (usize, usize) {
        ((0..m).map(|k| (side >> k) * (side >> k)).sum(), side >> m)
    }

    /// Whether `side` is a side the relight's maps may start from: its quarter whole,
    /// and no 256² (which relights too dark, a cause not yet found: BENCHMARKS.md,
    /// session 52).
    pub fn allows(side: usize) -> bool {
        (16..=128).contains(&side) && side % 4 == 0
    }

    /// The rays of each probe.
    pub fn per_probe(side: usize) -> usize {
        Self::map(side, Self::MAPS).0
    }
}

pub fn query(origin: Vec3, dir: Vec3, t_min: f32) -> RayQuery {
    RayQuery {
        origin_tmin: origin.extend(t_min).to_array(),
        direction_tmax: dir.extend(f32::MAX).to_array(),
        kind: RAY_CLOSEST,
        ..Default::default()
    }
}

/// `count` directions about +Z distributed as cos θ / π: Vogel's spiral, even over the unit
/// disc, lifted onto the hemisphere (Malley's method).
pub fn cosine_directions(count: usize) -> Vec<Vec3> {
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    (0..count)
        .map(|i| {
            let r = ((i as f32 + 0.5) / count as f32).sqrt();
            let phi = golden * i as f32;
            Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - r * r).max(0.0).sqrt())
        })
        .collect()
}

/// The pattern `pattern` turned to the normal `n` and by `spin` radians about it (a
/// different spin per receiver keeps neighbours' errors apart).
pub fn oriented(pattern: &[Vec3], n: Vec3, spin: f32) -> impl Iterator<Item = Vec3> + '_ {
    let turn = Quat::from_rotation_arc(Vec3::Z, n) * Quat::from_rotation_z(spin);
    pattern.iter().map(move |d| (turn * *d).normalize())
}

/// The unit geometric normal of triangle `t` of `triangles` (their winding's).
pub fn triangle_normal(triangles: &Triangles, t: u32) -> Vec3 {
    let [a, b, c] = triangles.corners[t as usize];
    (b - a).cross(c - a).normalize_or_zero()
}
