//! The irradiance probes' command-line options.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;

use super::frame::ProbeSettings;
use super::BakeSettings;
use crate::scene::GiOverrides;

/// The most points of the grid of spatial receivers.
pub const MAX_SPATIAL_RECEIVERS: u32 = 262_144;

#[derive(Args, Debug, Clone, Default)]
pub struct ProbeArgs {
    /// Width and height of the lightmap page the receivers' atlas is fitted into, 16 to
    /// 16384 texels: one receiver per covered texel [default: 512].
    #[arg(long)]
    pub lightmap_size: Option<u32>,
    /// The desired number of probes: their spacing is that of this many cubes filling the
    /// static scene's bounding box (Sedláček's ρ_p); fewer where free space near surfaces
    /// is short, 1 to 65536 [default: 256].
    #[arg(long)]
    pub probes: Option<u32>,
    /// The most probes supporting each receiver, which also sets the probes' radius
    /// (Sedláček's N_OVERLAPS), 1 to 64 [default: 10].
    #[arg(long)]
    pub overlaps: Option<u32>,
    /// Each probe casts a ray through every texel of an N × N equal-area octahedral map
    /// for the receivers' visibility match, 8 to 256 [default: 64].
    #[arg(long)]
    pub probe_side: Option<u32>,
    /// Each probe's relight reads the rays through the texels of an N × N equal-area
    /// octahedral map at level 0 of the level of detail, of N/2 × N/2 and N/4 × N/4 ones
    /// at the others; N a multiple of 4, 16 to 128 [default: 64].
    #[arg(long)]
    pub relight_side: Option<u32>,
    /// Hemisphere rays per receiver for its transport coefficients, 1 to 4096
    /// [default: 64].
    #[arg(long)]
    pub receiver_rays: Option<u32>,
    /// The highest spherical-harmonic band the probes store, 0 to 7: (N + 1)²
    /// coefficients [default: 7].
    #[arg(long)]
    pub sh_order: Option<u32>,
    /// The clustered PCA's bound on each cluster's projection error, Sedláček's
    /// 1 − √(Σ_{i≤k} σ_i / Σ σ_i), above 0 and below 1 [default: 0.05; the thesis's
    /// 0.005 keeps the transport's sampling noise].
    #[arg(long)]
    pub pca_error: Option<f32>,
    /// The most basis vectors a cluster keeps, 1 to 256 [default: 32].
    #[arg(long)]
    pub max_basis: Option<u32>,
    /// The desired points of the grid of spatial receivers (six directions each) that
    /// shades moving meshes, 0 to 262144 (0: no grid; moving meshes get no indirect
    /// light) [default: 2048].
    #[arg(long)]
    pub spatial_receivers: Option<u32>,
    /// The bake's file [default: in the user's cache folder,
    /// $XDG_CACHE_HOME/voxcone/bakes or ~/.cache/voxcone/bakes, one per scene file and
    /// settings].
    #[arg(long)]
    pub bake_file: Option<PathBuf>,
    /// `--gi probes`: light bounces the first frame computes, 1 to 64 (1: no bounce
    /// between surfaces after the first; with more, every later frame adds one)
    /// [default: 8 for frames; for one image (`render`) as many as leave under 1 % of the
    /// light untraced, at the rate the camera's diffuse walks measure].
    #[arg(long)]
    pub probe_bounces: Option<u32>,
    /// `--gi probes`: the dynamic level of detail by camera distance (Sedláček 2019, 4.2):
    /// fewer harmonic bands and relight rays for far probes and clusters; `off` computes
    /// every probe and cluster in full, the reference [default: on].
    #[arg(long, value_enum)]
    pub probe_lod: Option<Switch>,
    /// `--gi probes`: the camera distances where levels 1, 2 and 3 of the level of detail
    /// begin, in scene units, increasing [default: 16, 32 and 64 probe radii].
    #[arg(long, value_delimiter = ',')]
    pub lod_distances: Option<Vec<f32>>,
}

/// On or off.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Switch {
    On,
    Off,
}

impl ProbeArgs {
    /// The frame's settings: the command line over the scene file's `[gi]` over the
    /// defaults (checked by [`ProbeSettings::check`]); `one_image`: a single render, which
    /// without a given count traces its bounces until they converge.
    pub fn frame_settings(&self, scene: &GiOverrides, one_image: bool) -> Result<ProbeSettings> {
        let bounces = self.probe_bounces.or(scene.probe_bounces);
        let d = ProbeSettings::default();
        let distances = match self.lod_distances.as_deref() {
            Some(v) => Some(<[f32; 3]>::try_from(v).map_err(|_| {
                anyhow::anyhow!(
                    "--lod-distances: give three distances, D1,D2,D3 (got {})",
                    v.len()
                )
            })?),
            None => scene.lod_distances,
        };
        let settings = ProbeSettings {
            bake: self.settings(scene)?,
            bake_file: self.bake_file.clone(),
            bounces: bounces.unwrap_or(d.bounces),
            converge_bounces: one_image && bounces.is_none(),
            lod: self
                .probe_lod
                .map(|s| s == Switch::On)
                .or(scene.probe_lod)
                .unwrap_or(d.lod),
            lod_distances: distances,
        };
        settings.check()?;
        Ok(settings)
    }

    /// The options given, as their flags.
    pub fn given(&self) -> Vec<&'static str> {
        [
            (self.lightmap_size.is_some(), "--lightmap-size"),
            (self.probes.is_some(), "--probes"),
            (self.overlaps.is_some(), "--overlaps"),
            (self.probe_side.is_some(), "--probe-side"),
            (self.relight_side.is_some(), "--relight-side"),
            (self.receiver_rays.is_some(), "--receiver-rays"),
            (self.sh_order.is_some(), "--sh-order"),
            (self.pca_error.is_some(), "--pca-error"),
            (self.max_basis.is_some(), "--max-basis"),
            (self.spatial_receivers.is_some(), "--spatial-receivers"),
            (self.bake_file.is_some(), "--bake-file"),
            (self.probe_bounces.is_some(), "--probe-bounces"),
            (self.probe_lod.is_some(), "--probe-lod"),
            (self.lod_distances.is_some(), "--lod-distances"),
        ]
        .into_iter()
        .filter_map(|(set, flag)| set.then_some(flag))
        .collect()
    }

    /// The bake's settings: the command line over the scene file's `[gi]` over the
    /// defaults.
    pub fn settings(&self, scene: &GiOverrides) -> Result<BakeSettings> {
        let d = BakeSettings::default();
        let settings = BakeSettings {
            lightmap_size: self
                .lightmap_size
                .or(scene.lightmap_size)
                .unwrap_or(d.lightmap_size),
            probes: self.probes.or(scene.probes).unwrap_or(d.probes),
            overlaps: self.overlaps.or(scene.overlaps).unwrap_or(d.overlaps),
            probe_side: self.probe_side.or(scene.probe_side).unwrap_or(d.probe_side),
            relight_side: self
                .relight_side
                .or(scene.relight_side)
                .unwrap_or(d.relight_side),
            receiver_rays: self
                .receiver_rays
                .or(scene.receiver_rays)
                .unwrap_or(d.receiver_rays),
            sh_order: self.sh_order.or(scene.sh_order).unwrap_or(d.sh_order),
            pca_error: self.pca_error.or(scene.pca_error).unwrap_or(d.pca_error),
            max_basis: self.max_basis.or(scene.max_basis).unwrap_or(d.max_basis),
            spatial_receivers: self
                .spatial_receivers
                .or(scene.spatial_receivers)
                .unwrap_or(d.spatial_receivers),
        };
        if settings.spatial_receivers > MAX_SPATIAL_RECEIVERS {
            bail!(
                "--spatial-receivers {}: the grid holds 0 to {MAX_SPATIAL_RECEIVERS} points",
                settings.spatial_receivers
            );
        }
        if !(settings.pca_error > 0.0 && settings.pca_error < 1.0) {
            bail!(
                "--pca-error {}: the clusters' projection error bound lies above 0 and below 1",
                settings.pca_error
            );
        }
        if !(1..=256).contains(&settings.max_basis) {
            bail!(
                "--max-basis {}: a cluster keeps 1 to 256 basis vectors",
                settings.max_basis
            );
        }
        if !(16..=16384).contains(&settings.lightmap_size) {
            bail!(
                "--lightmap-size {}: the lightmap must be 16 to 16384 texels wide",
                settings.lightmap_size
            );
        }
        if !(1..=65536).contains(&settings.probes) {
            bail!("--probes {}: give 1 to 65536 probes", settings.probes);
        }
        if !(1..=64).contains(&settings.overlaps) {
            bail!(
                "--overlaps {}: each receiver takes 1 to 64 probes",
                settings.overlaps
            );
        }
        if !(8..=256).contains(&settings.probe_side) {
            bail!(
                "--probe-side {}: each probe's map is 8 to 256 texels wide",
                settings.probe_side
            );
        }
        if !super::casting::RelightRays::allows(settings.relight_side as usize) {
            bail!(
                "--relight-side {}: each probe's relight map is 16 to 128 texels wide, a multiple of 4",
                settings.relight_side
            );
        }
        if !(1..=4096).contains(&settings.receiver_rays) {
            bail!(
                "--receiver-rays {}: give 1 to 4096 rays per receiver",
                settings.receiver_rays
            );
        }
        if settings.sh_order > super::sh::MAX_ORDER {
            bail!(
                "--sh-order {}: the probes store bands 0 to {} at most",
                settings.sh_order,
                super::sh::MAX_ORDER
            );
        }
        Ok(settings)
    }
}
