//! The receivers' transport coefficients α_ij (Sedláček 2019, 3.1.2.3 and 3.2.3.2): how
//! much of probe i's harmonic j reaches each receiver as irradiance,
//!
//! α_ij = ∫ K_ij(ω) cos θ dω,  K_ij(ω) = w_i V_i(ω) Y_j(Ψ_i(ω)) / Σ_k w_k V_k(ω),
//!
//! over the receiver's hemisphere: w_i the kernel of the receiver's distance to the probe,
//! V_i whether probe i sees the surface the receiver sees along ω, Ψ_i(ω) the direction
//! from the probe to that surface. The receiver's irradiance is then Σ_ij λ_ij α_ij with
//! λ_ij the probes' radiance coefficients.
//!
//! Estimated from cosine-distributed rays (each weighs π / N, the cosine cancelled by the
//! distribution). V_i is read from the probe's own map of hit distances (the depths of
//! its relight rays), not cast again. Rays that leave the scene see the sky, which is
//! constant: their share, the receiver's sky factor, multiplies the sky's radiance
//! exactly, where going through the probes' harmonics would blur it. Rays whose surface
//! no supporting probe sees add nothing (the thesis's choice, 5.1.3.1, against light
//! leaks); their share is reported. The thesis's distance weight of the hits
//! (5.1.3.2) is left out: with the rays distributed by solid angle and cosine, close
//! surfaces are sampled more densely exactly as much as they weigh.

use anyhow::Result;
use glam::Vec3;
use rayon::prelude::*;

use super::casting::{self, ProbeViews};
use super::placement::Probes;
use super::receivers::Receiver;
use super::sh::Basis;
use crate::gpu_layout::{RayHit, RayQuery, RAY_NONE};
use crate::progress::Progress;
use crate::ray::query::RayQueries;
use crate::ray::Triangles;

/// The transport of every receiver, sparse over the probes that support it.
#[derive(Clone, Debug)]
pub struct Transport {
    pub order: u32,
    /// Receiver r's entries are `offsets[r]..offsets[r + 1]` of `probes`, each with its
    /// (order + 1)² coefficients in `alpha`.
    pub offsets: Vec<u32>,
    pub probes: Vec<u32>,
    pub alpha: Vec<f32>,
    /// Per receiver, the cosine-weighted share of its hemisphere open to the sky (its
    /// irradiance from a sky of radiance S is sky · S; π for an open plane).
    pub sky: Vec<f32>,
    /// Receiver rays that hit a surface, those of them no supporting probe sees, and of
    /// those the ones whose surface no supporting probe even faces from the side the
    /// receiver sees it (the rest failed the depth test).
    pub hits: u64,
    pub unseen: u64,
    pub unseen_side: u64,
}

/// How the transport is estimated.
#[derive(Clone, Copy, Debug)]
pub struct TransportSettings {
    pub order: u32,
    pub rays: usize,
    pub overlaps: usize,
    /// Rays start this far along the receiver's normal (scene units).
    pub offset: f32,
}

/// Receivers per batch of rays (bounds the hits kept at once).
const BATCH: usize = 4096;

impl Transport {
    pub fn compute(
        queries: &mut RayQueries,
        triangles: &Triangles,
        receivers: &[Receiver],
        probes: &Probes,
        views: &ProbeViews,
        settings: &TransportSettings,
    ) -> Result<Self> {
        let basis = Basis::new(settings.order);
        let pattern = casting::cosine_directions(settings.rays);
        let coefficients = basis.count();
        let mut out = Transport {
            order: settings.order,
            offsets: vec![0],
            probes: Vec::new(),
            alpha: Vec::new(),
            sky: Vec::with_capacity(receivers.len()),
            hits: 0,
            unseen: 0,
            unseen_side: 0,
        };
        let progress = Progress::new("receiver transport", receivers.len() as u64);
        for (b, batch) in receivers.chunks(BATCH).enumerate() {
            let mut rays = Vec::with_capacity(batch.len() * settings.rays);
            for (i, r) in batch.iter().enumerate() {
                let origin = r.position + r.normal * settings.offset;
                let spin = spin_of(b * BATCH + i);
                rays.extend(
                    casting::oriented(&pattern, r.normal, spin)
                        .map(|d| casting::query(origin, d, 0.0)),
                );
            }
            let hits = queries.run(&rays)?;
            let results: Vec<Gathered> = batch
                .par_iter()
                .zip(rays.par_chunks(settings.rays))
                .zip(hits.par_chunks(settings.rays))
                .map(|((r, rays), hits)| {
                    let gather = Gather {
                        triangles,
                        probes,
                        views,
                        basis: &basis,
                        overlaps: settings.overlaps,
                    };
                    gather.receiver(r, rays, hits)
                })
                .collect();
            for g in results {
                for (p, a) in g.probes.iter().zip(g.alpha.chunks_exact(coefficients)) {
                    out.probes.push(*p);
                    out.alpha.extend_from_slice(a);
                }
                out.offsets.push(out.probes.len() as u32);
                out.sky.push(g.sky);
                out.hits += g.hits;
                out.unseen += g.unseen;
                out.unseen_side += g.unseen_side;
            }
            progress.set(((b + 1) * BATCH).min(receivers.len()) as u64);
        }
        progress.finish();
        Ok(out)
    }
}

/// A different turn of the ray pattern for each receiver: the golden ratio's multiples
/// modulo one full turn spread evenly.
fn spin_of(receiver: usize) -> f32 {
    const GOLDEN: f64 = 0.618_033_988_749_894_8;
    ((receiver as f64 * GOLDEN).fract() * std::f64::consts::TAU) as f32
}

/// One receiver's coefficients.
struct Gathered {
    probes: Vec<u32>,
    alpha: Vec<f32>,
    sky: f32,
    hits: u64,
    unseen: u64,
    unseen_side: u64,
}

/// What a receiver's gather reads.
struct Gather<'a> {
    triangles: &'a Triangles,
    probes: &'a Probes,
    views: &'a ProbeViews,
    basis: &'a Basis,
    overlaps: usize,
}

impl Gather<'_> {
    fn receiver(&self, r: &Receiver, rays: &[RayQuery], hits: &[RayHit]) -> Gathered {
        let support = self.probes.support(r.position, self.overlaps);
        let n = self.basis.count();
        let mut alpha = vec![0.0f64; support.len() * n];
        let mut y = vec![0.0f64; n];
        let mut seen = Vec::with_capacity(support.len());
        let weight = std::f64::consts::PI / rays.len() as f64;
        let (mut sky, mut count, mut unseen, mut unseen_side) = (0.0f64, 0u64, 0u64, 0u64);
        for (ray, hit) in rays.iter().zip(hits) {
            if hit.triangle == RAY_NONE {
                sky += weight;
                continue;
            }
            count += 1;
            let origin = Vec3::from_slice(&ray.origin_tmin[..3]);
            let dir = Vec3::from_slice(&ray.direction_tmax[..3]);
            let point = origin + dir * hit.t;
            let normal = casting::triangle_normal(self.triangles, hit.triangle);
            seen.clear();
            let mut total = 0.0f64;
            let mut facing = false;
            for (k, &(probe, w)) in support.iter().enumerate() {
                let offset = point - self.probes.positions[probe as usize];
                let distance = offset.length();
                if distance <= 0.0 {
                    continue;
                }
                let towards = offset / distance;
                // The same surface is the same side of it, too: a receiver behind a
                // one-sided emitter would otherwise take the light the probes in front
                // of it see.
                let same_side = (normal.dot(towards) < 0.0) == (normal.dot(dir) < 0.0);
                facing |= same_side;
                if same_side && self.sees(probe as usize, towards, distance, normal) {
                    seen.push((k, towards, w as f64));
                    total += w as f64;
                }
            }
            if total <= 0.0 {
                unseen += 1;
                unseen_side += u64::from(!facing);
                continue;
            }
            for &(k, towards, w) in &seen {
                self.basis.eval_into(towards, &mut y);
                let scale = weight * w / total;
                for (a, y) in alpha[k * n..(k + 1) * n].iter_mut().zip(&y) {
                    *a += scale * y;
                }
            }
        }
        Gathered {
            probes: support.iter().map(|s| s.0).collect(),
            alpha: alpha.iter().map(|&a| a as f32).collect(),
            sky: sky as f32,
            hits: count,
            unseen,
            unseen_side,
        }
    }

    /// Whether probe `probe` sees the surface point `distance` along the unit `towards`
    /// from it, on a surface of geometric normal `normal`. Its texel's ray passed through
    /// the texel's centre, up to δ (the texel's angular radius) away: on the same plane,
    /// met at θ from its normal, that ray's depth differs by up to distance · δ · tan θ,
    /// which the test allows (tan θ capped at 8, about 83°), with a thousandth of the
    /// distance for the hits' own rounding.
    fn sees(&self, probe: usize, towards: Vec3, distance: f32, normal: Vec3) -> bool {
        let depth = self.views.depth(probe, towards);
        let cos = normal.dot(towards).abs().max(1e-3);
        let tan = ((1.0 - cos * cos).sqrt() / cos).min(8.0);
        distance <= depth + distance * (self.views.texel_radius() * tan + 1e-3)
    }
}
