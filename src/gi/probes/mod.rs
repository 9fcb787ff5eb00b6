//! Irradiance probes: precomputed local reconstruction from sparse radiance probes
//! (Silvennoinen & Lehtinen 2017, as Sedláček 2019 implements and extends it).
//!
//! The precomputation (`voxcone bake`) so far: the lightmap atlas ([`lightmap`]), its
//! receivers ([`receivers`]), the probes and their radius ([`placement`]), and the
//! spherical harmonics the probes will store their radiance in ([`sh`]).

pub mod cli;
pub mod lightmap;
pub mod placement;
pub mod receivers;
pub mod sh;
#[cfg(test)]
mod tests;

use std::time::Instant;

use anyhow::Result;
use serde::Serialize;

use self::lightmap::Lightmap;
use self::placement::Probes;
use self::receivers::Receivers;
use crate::scene::Scene;

/// The bake's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BakeSettings {
    /// The lightmap page's width and height in texels.
    pub lightmap_size: u32,
    /// The desired probe count.
    pub probes: u32,
    /// N_OVERLAPS: the most probes per receiver.
    pub overlaps: u32,
}

impl Default for BakeSettings {
    fn default() -> Self {
        Self {
            lightmap_size: 512,
            probes: 256,
            overlaps: 10,
        }
    }
}

/// What a bake made, with each phase's host time.
#[derive(Clone, Debug, Serialize)]
pub struct BakeReport {
    pub scene: String,
    pub lightmap: [u32; 2],
    pub texels_per_unit: f32,
    pub charts: u32,
    /// Share of the lightmap's texels that chart surface covers.
    pub utilization: f32,
    pub receivers: usize,
    /// Receivers whose texel's centre lies on the surface (the others border charts).
    pub receivers_inside: usize,
    /// Texels two charts claim (zero for a valid atlas).
    pub overlapping_texels: usize,
    pub probe_candidates: usize,
    pub probes: usize,
    pub probe_spacing: f32,
    pub probe_radius: f32,
    /// Mean probes supporting a receiver, and receivers none supports (they get no
    /// light: 3.2.3.2).
    pub mean_support: f64,
    pub unsupported_receivers: usize,
    /// Host milliseconds per phase, in order.
    pub phases_ms: Vec<(String, f64)>,
}

/// Runs the bake's phases on `scene`.
pub fn bake(scene: &Scene, settings: &BakeSettings) -> Result<BakeReport> {
    let mut phases = Vec::new();
    let mut clock = Instant::now();
    let mut lap = |name: &str| {
        phases.push((name.to_string(), clock.elapsed().as_secs_f64() * 1e3));
        clock = Instant::now();
    };
    let lightmap = Lightmap::generate(scene, settings.lightmap_size)?;
    lap("lightmap UVs");
    let receivers = Receivers::place(scene, &lightmap);
    lap("receivers");
    let probes = Probes::place(scene, &receivers.list, settings.probes, settings.overlaps)?;
    lap("probes");
    let overlaps = settings.overlaps as usize;
    let support: Vec<usize> = receivers
        .list
        .iter()
        .map(|r| probes.support(r.position, overlaps).len())
        .collect();
    lap("probe support");
    let supported = support.iter().filter(|&&n| n > 0).count();
    Ok(BakeReport {
        scene: scene.source.display().to_string(),
        lightmap: [lightmap.width, lightmap.height],
        texels_per_unit: lightmap.texels_per_unit,
        charts: lightmap.charts,
        utilization: lightmap.utilization,
        receivers: receivers.list.len(),
        receivers_inside: receivers.inside(),
        overlapping_texels: receivers.overlaps,
        probe_candidates: probes.candidates,
        probes: probes.positions.len(),
        probe_spacing: probes.spacing,
        probe_radius: probes.radius,
        mean_support: support.iter().sum::<usize>() as f64 / support.len().max(1) as f64,
        unsupported_receivers: support.len() - supported,
        phases_ms: phases,
    })
}
