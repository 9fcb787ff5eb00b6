//! Irradiance probes: precomputed local reconstruction from sparse radiance probes
//! (Silvennoinen & Lehtinen 2017, as Sedláček 2019 implements and extends it).
//!
//! The precomputation (`voxcone bake`) so far: the lightmap atlas ([`lightmap`]), its
//! receivers ([`receivers`]), the probes and their radius ([`placement`]), the probes'
//! and the receivers' rays on the GPU ([`casting`]), the receivers' transport
//! coefficients ([`transport`]) in spherical harmonics ([`sh`]), their clustered PCA
//! ([`clusters`]), the grid of spatial receivers that shades moving meshes ([`grid`]),
//! and a host twin of the relight and the reconstruction ([`relight`]). The bake sees the
//! static meshes only: the transport assumes them (Sedláček 2019, 4.1), and moving meshes
//! neither occlude nor bounce light here.

pub mod casting;
pub mod cli;
pub mod clusters;
pub mod file;
pub mod frame;
pub mod grid;
pub mod levels;
pub mod lightmap;
pub mod octahedral;
pub mod placement;
pub mod receivers;
pub mod relight;
pub mod sh;
#[cfg(test)]
mod tests;
pub mod transport;

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use anyhow::Result;
use serde::{Deserialize, Serialize};

use self::casting::{ProbeViews, RelightRays};
use self::clusters::{ClusterSettings, Clusters};
use self::file::{BakeData, Unusable};
use self::lightmap::Lightmap;
use self::placement::Probes;
use self::receivers::Receivers;
use self::transport::{Transport, TransportSettings};
use crate::ray::query::RayQueries;
use crate::ray::{SceneRays, Triangles};
use crate::scene::Scene;
use crate::vk::Context;

/// The bake's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BakeSettings {
    /// The lightmap page's width and height in texels.
    pub lightmap_size: u32,
    /// The desired probe count.
    pub probes: u32,
    /// N_OVERLAPS: the most probes per receiver.
    pub overlaps: u32,
    /// Each probe's rays for the receivers' visibility match: through the texels of a
    /// `probe_side`² equal-area octahedral map.
    pub probe_side: u32,
    /// Each probe's relight rays: through the texels of a `relight_side`² map for level 0
    /// of the level of detail, of maps of half and a quarter of the side for the others.
    pub relight_side: u32,
    /// Each receiver's hemisphere rays.
    pub receiver_rays: u32,
    /// The highest band of the harmonics: (order + 1)² coefficients.
    pub sh_order: u32,
    /// The clustered PCA's bound on each cluster's projection error (the thesis's
    /// 1 − √(Σ_{i≤k} σ_i / Σ σ_i)) and its most basis vectors per cluster.
    pub pca_error: f32,
    pub max_basis: u32,
    /// The desired points of the grid of spatial receivers that shades moving meshes
    /// (Sedláček 2019, 4.1); 0: no grid.
    pub spatial_receivers: u32,
}

impl Default for BakeSettings {
    fn default() -> Self {
        Self {
            lightmap_size: 512,
            probes: 256,
            overlaps: 10,
            probe_side: 64,
            // The probes' maps' side: the relight's 64 coefficients from 4,096 rays (the
            // thesis: 512). 32² costs a quarter and projects a clamped cosine's and a
            // half-space step's irradiance nearly as well (0.1 % and 0.4 % off on average
            // against 64²'s 0.03 % and 0.2 %, `relight_maps_integrate_analytic_radiance`),
            // but not an emitter a probe sees under a few degrees: `cornell_area`'s
            // ceiling light, whose light all comes through the probes, LDR-FLIP 0.086 →
            // 0.106 (BENCHMARKS.md, session 52).
            relight_side: 64,
            receiver_rays: 64,
            // The thesis's bands 0 to 7. The probes' radiance has the lights' hot spots and
            // shadow edges in it: on the Cornell box the first bounce came out 7.5 %, 3.8 %
            // and 2.5 % below the path tracer's with bands to 3, 5 and 7.
            sh_order: 7,
            // Not the thesis's 0.005: with 64 rays per receiver the transport's Monte Carlo
            // noise spreads over every singular value, and 0.005 kept it (clusters of 30
            // receivers, a basis costlier than the raw transport). The truncation's error
            // is local and of zero mean: a furnace's worst receiver is 0.3, 0.8, 1.9 and
            // 2.2-5.6 % off with 0.005, 0.02, 0.05 and 0.1 (its mean 0.1 % throughout);
            // 0.05 is the loosest that keeps it within 2 %. There Sponza's LDR-FLIP is
            // 0.0924 (0.0929 with 0.005) and its basis pass costs half.
            pca_error: 0.05,
            max_basis: 32,
            // Between the thesis's 800 and 1440 ("sufficient for generally good results",
            // 5.2.1.2) and its densest; a point costs six receivers' transport in the bake
            // and nothing per frame unless a moving mesh is near it.
            spatial_receivers: 2048,
        }
    }
}

/// What a bake made, with each phase's host time.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BakeReport {
    pub scene: String,
    pub lightmap: [u32; 2],
    pub texels_per_unit: f32,
    pub charts: u32,
    /// The lightmap's UVs are the scene's second set (glTF's TEXCOORD_1).
    pub authored_uvs: bool,
    /// Share of the lightmap's texels that chart surface covers.
    pub utilization: f32,
    pub receivers: usize,
    /// Receivers whose texel's centre lies on the surface (the others border charts).
    pub receivers_inside: usize,
    /// Texels two charts claim (zero for a valid atlas).
    pub overlapping_texels: usize,
    /// Receivers moved out of geometry (5.1.4).
    pub receivers_shifted: usize,
    pub probe_candidates: usize,
    pub probes: usize,
    pub probe_spacing: f32,
    pub probe_radius: f32,
    /// Mean probes supporting a receiver, and receivers none supports (they get no
    /// light: 3.2.3.2).
    pub mean_support: f64,
    pub unsupported_receivers: usize,
    /// Rays cast: the probes' visibility maps, their relight maps, the receivers'.
    pub probe_rays: usize,
    pub relight_rays: usize,
    pub receiver_rays: usize,
    /// The share of the receivers' rays that hit a surface no supporting probe sees
    /// (their light is lost).
    pub unseen_hit_share: f64,
    /// Of those, the share whose surface no supporting probe faces from the receiver's
    /// side (the rest failed the depth test: occluded, or too far along the texel).
    pub unseen_from_the_side_share: f64,
    /// The receivers' transport: probe entries and their coefficients' memory.
    pub transport_entries: usize,
    pub transport_mib: f64,
    /// The clustered PCA: clusters, their mean basis count, the largest truncation
    /// error of a cluster and that of the whole transport (relative Frobenius norms),
    /// and the relative L1 error it makes in the receivers' irradiance from the emitters
    /// and the sky.
    pub clusters: usize,
    pub mean_basis: f64,
    pub largest_cluster_error: f64,
    pub transport_error: f64,
    pub irradiance_error: f64,
    pub cluster_matrices_mib: f64,
    pub receiver_coordinates_mib: f64,
    /// The grid of spatial receivers: points per axis, points moved out of geometry, its
    /// receivers (six per point) no probe supports, and its clusters (among `clusters`).
    pub grid: [u32; 3],
    pub grid_points_shifted: usize,
    pub unsupported_spatial_receivers: usize,
    pub spatial_clusters: usize,
    /// Host milliseconds per phase, in order.
    pub phases_ms: Vec<(String, f64)>,
}

/// The static meshes of `scene`, which the bake's transport assumes.
pub fn static_scene(scene: &Scene) -> Scene {
    let mut out = scene.clone();
    out.meshes.retain(|m| m.animation.is_none());
    out.triangle_count = out.meshes.iter().map(|m| m.indices.len() / 3).sum();
    out
}

/// The receivers of `lightmap`; where the scene's own lightmap UVs put two places under
/// one texel (charts over each other would share receivers), an atlas of `size` made
/// instead, with a warning.
fn place_receivers(scene: &Scene, lightmap: &mut Lightmap, size: u32) -> Result<Receivers> {
    let receivers = Receivers::place(scene, lightmap);
    if !lightmap.authored || receivers.overlaps == 0 {
        return Ok(receivers);
    }
    log::warn!(
        "{}: the scene's lightmap UVs put {} texels under two places; unwrapping an atlas \
         instead",
        scene.source.display(),
        receivers.overlaps
    );
    *lightmap = Lightmap::unwrap(scene, &lightmap::static_meshes(scene)?, size)?;
    Ok(Receivers::place(scene, lightmap))
}

/// How a bake came about.
#[derive(Clone, Debug, PartialEq)]
pub enum Origin {
    /// Read from its file.
    Cached,
    /// Computed: there was no file, or (with the reason) it could not be used, or the
    /// caller asked for a fresh bake.
    Computed(Option<String>),
}

/// A bake, its report and where it came from.
pub struct Bake {
    pub data: BakeData,
    pub report: BakeReport,
    pub origin: Origin,
}

/// The bake of `scene` with `settings` from the file at `path` where it is whole and
/// made from the same static meshes and settings, else computed and written there
/// (also when `force`). `preview`: see [`compute`].
pub fn load_or_bake(
    ctx: &Arc<Context>,
    scene: &Scene,
    settings: &BakeSettings,
    path: &Path,
    force: bool,
    preview: Option<&Path>,
) -> Result<Bake> {
    let key = file::content_key(scene, settings);
    let reason = if force {
        None
    } else {
        match BakeData::read(path, key) {
            Ok(data) => {
                let report = serde_json::from_str(&data.report)
                    .map_err(|e| anyhow::anyhow!("the bake {}'s report: {e}", path.display()))?;
                log::info!("bake {} is up to date", path.display());
                return Ok(Bake {
                    data,
                    report,
                    origin: Origin::Cached,
                });
            }
            Err(Unusable::Missing) => None,
            Err(Unusable::Stale(why) | Unusable::Corrupt(why)) => {
                log::warn!("bake {}: {why}; baking again", path.display());
                Some(why)
            }
        }
    };
    let (data, report) = compute(ctx, scene, settings, preview)?;
    let start = Instant::now();
    data.write(path, key)?;
    log::info!(
        "wrote bake {} ({:.1} MiB, {:.2} s)",
        path.display(),
        std::fs::metadata(path).map(|m| m.len()).unwrap_or(0) as f64 / 1048576.0,
        start.elapsed().as_secs_f64()
    );
    Ok(Bake {
        data,
        report,
        origin: Origin::Computed(reason),
    })
}

/// Runs the bake's phases on the static meshes of `scene`; with `preview`, writes there
/// the lightmap's irradiance from the emitters and the sky (an EXR of radiance, or a PNG
/// of it clamped and sRGB-encoded).
pub fn compute(
    ctx: &Arc<Context>,
    scene: &Scene,
    settings: &BakeSettings,
    preview: Option<&Path>,
) -> Result<(BakeData, BakeReport)> {
    let scene = &static_scene(scene);
    let mut phases = Vec::new();
    let mut clock = Instant::now();
    let mut lap = |name: &str| {
        phases.push((name.to_string(), clock.elapsed().as_secs_f64() * 1e3));
        clock = Instant::now();
    };
    let mut lightmap = Lightmap::generate(scene, settings.lightmap_size)?;
    lap("lightmap UVs");
    let mut receivers = place_receivers(scene, &mut lightmap, settings.lightmap_size)?;
    let offset = 1e-4 * placement::static_bounds(scene).diagonal();
    let host = crate::ray::host::HostRays::of_static(scene);
    let shifted = receivers.shift_out_of_geometry(&host, 32, offset);
    lap("receivers");
    let probes = Probes::place(
        scene,
        &host,
        &receivers.list,
        settings.probes,
        settings.overlaps,
    )?;
    lap("probes");
    let rays = SceneRays::new(ctx, scene, 1)?;
    let mut queries = RayQueries::new(ctx, &rays, 1 << 18)?;
    let triangles = Triangles::of(scene, 0.0, |_| true);
    lap("scene rays");
    let views = ProbeViews::cast(
        &mut queries,
        &probes.positions,
        settings.probe_side as usize,
    )?;
    let relight_rays = RelightRays::cast(
        &mut queries,
        &probes.positions,
        settings.relight_side as usize,
    )?;
    lap("probe rays");
    let transport_settings = TransportSettings {
        order: settings.sh_order,
        rays: settings.receiver_rays as usize,
        overlaps: settings.overlaps as usize,
        offset,
    };
    let cluster_settings = ClusterSettings {
        max_error: f64::from(settings.pca_error),
        max_basis: settings.max_basis as usize,
        ..ClusterSettings::default()
    };
    let transport = Transport::compute(
        &mut queries,
        &triangles,
        &receivers.list,
        &probes,
        &views,
        &transport_settings,
    )?;
    lap("receiver transport");
    let clusters = Clusters::build(&receivers.list, &transport, &cluster_settings);
    lap("clusters");
    // The compression's error where it matters, in the receivers' irradiance from the
    // emitters and the sky: through the clusters against the full transport.
    let basis = sh::Basis::new(settings.sh_order);
    let lambda = relight::emitted_lambda(
        scene,
        &triangles,
        &relight_rays,
        probes.positions.len(),
        &basis,
    );
    let (mut difference, mut total) = (0.0f64, 0.0f64);
    let mut compressed = Vec::with_capacity(receivers.list.len());
    for i in 0..receivers.list.len() {
        let full = relight::irradiance(&transport, &lambda, scene.sky, i);
        let e = clusters.irradiance(&transport, &lambda, scene.sky, i);
        difference += (e - full).abs().element_sum() as f64;
        total += full.abs().element_sum() as f64;
        compressed.push(e);
    }
    lap("compression check");
    // The grid (4.1): each direction's receivers clustered on their own, as the thesis
    // does (one direction's transport varies smoothly from point to point; the six of a
    // point differ by whole hemispheres).
    let lightmap_clusters = clusters.list.len();
    let mut clusters = clusters;
    let mut spatial_sky = Vec::new();
    let mut unsupported_spatial = 0;
    let (grid, grid_shifted) = if settings.spatial_receivers > 0 {
        let grid = grid::Grid::new(&placement::static_bounds(scene), settings.spatial_receivers);
        let (points, shifted) = grid::place_points(&grid, &host, 32, offset);
        for d in grid::DIRECTIONS {
            let list = grid::receivers(&points, d);
            let t = Transport::compute(
                &mut queries,
                &triangles,
                &list,
                &probes,
                &views,
                &transport_settings,
            )?;
            unsupported_spatial += t.offsets.windows(2).filter(|w| w[0] == w[1]).count();
            clusters.append(Clusters::build(&list, &t, &cluster_settings));
            spatial_sky.extend(t.sky);
        }
        (Some(grid), shifted)
    } else {
        (None, 0)
    };
    lap("spatial receivers");
    if let Some(path) = preview {
        let mut rgba = vec![0.0f32; (lightmap.width * lightmap.height * 4) as usize];
        for (r, e) in receivers.list.iter().zip(&compressed) {
            let texel = (r.texel[1] * lightmap.width + r.texel[0]) as usize;
            rgba[texel * 4..texel * 4 + 4].copy_from_slice(&e.extend(1.0).to_array());
        }
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("png"))
        {
            let srgb: Vec<u8> = rgba
                .iter()
                .map(|&x| crate::imageio::srgb8_encode(x))
                .collect();
            crate::imageio::write_png(path, lightmap.width, lightmap.height, &srgb)?;
        } else {
            crate::imageio::write_exr(path, lightmap.width, lightmap.height, &rgba)?;
        }
        lap("preview");
    }
    // Each receiver's transport entries are its supporting probes.
    let support: Vec<usize> = transport
        .offsets
        .windows(2)
        .map(|w| (w[1] - w[0]) as usize)
        .collect();
    let supported = support.iter().filter(|&&n| n > 0).count();
    let report = BakeReport {
        scene: scene.source.display().to_string(),
        lightmap: [lightmap.width, lightmap.height],
        texels_per_unit: lightmap.texels_per_unit,
        charts: lightmap.charts,
        authored_uvs: lightmap.authored,
        utilization: lightmap.utilization,
        receivers: receivers.list.len(),
        receivers_inside: receivers.inside(),
        overlapping_texels: receivers.overlaps,
        receivers_shifted: shifted,
        probe_candidates: probes.candidates,
        probes: probes.positions.len(),
        probe_spacing: probes.spacing,
        probe_radius: probes.radius,
        mean_support: support.iter().sum::<usize>() as f64 / support.len().max(1) as f64,
        unsupported_receivers: support.len() - supported,
        probe_rays: views.hits.len(),
        relight_rays: relight_rays.hits.len(),
        receiver_rays: receivers.list.len() * settings.receiver_rays as usize,
        unseen_hit_share: transport.unseen as f64 / transport.hits.max(1) as f64,
        unseen_from_the_side_share: transport.unseen_side as f64 / transport.unseen.max(1) as f64,
        transport_entries: transport.probes.len(),
        transport_mib: (transport.alpha.len() * 4 + transport.probes.len() * 4) as f64 / 1048576.0,
        clusters: clusters.list.len(),
        mean_basis: clusters.list.iter().map(|c| c.basis).sum::<usize>() as f64
            / clusters.list.len().max(1) as f64,
        largest_cluster_error: clusters.list.iter().map(|c| c.error).fold(0.0, f64::max),
        transport_error: (clusters.residual / clusters.energy.max(f64::MIN_POSITIVE)).sqrt(),
        irradiance_error: difference / total.max(f64::MIN_POSITIVE),
        cluster_matrices_mib: clusters.bytes().0 as f64 / 1048576.0,
        receiver_coordinates_mib: clusters.bytes().1 as f64 / 1048576.0,
        grid: grid.map_or([0; 3], |g| g.size.to_array()),
        grid_points_shifted: grid_shifted,
        unsupported_spatial_receivers: unsupported_spatial,
        spatial_clusters: clusters.list.len() - lightmap_clusters,
        phases_ms: phases,
    };
    let mut mesh_corners = vec![0u32];
    for c in &lightmap.corners {
        mesh_corners.push(mesh_corners.last().copied().unwrap_or(0) + c.len() as u32);
    }
    let mut cluster_probe_starts = vec![0u32];
    let mut cluster_projection_starts = vec![0u32];
    for c in &clusters.list {
        cluster_probe_starts
            .push(cluster_probe_starts.last().copied().unwrap_or(0) + c.probes.len() as u32);
        cluster_projection_starts.push(
            cluster_projection_starts.last().copied().unwrap_or(0) + c.projection.len() as u32,
        );
    }
    let data = BakeData {
        lightmap: [lightmap.width, lightmap.height],
        sh_order: settings.sh_order,
        mesh_corners,
        corner_uvs: lightmap.corners.concat(),
        receiver_texels: receivers.list.iter().map(|r| r.texel).collect(),
        receiver_clusters: clusters.cluster_of.clone(),
        receiver_offsets: clusters.offsets.clone(),
        receiver_sky: [transport.sky.as_slice(), &spatial_sky].concat(),
        coordinates: clusters.coordinates.clone(),
        grid_size: grid.map_or([0; 3], |g| g.size.to_array()),
        grid_bounds: grid.map_or([[0.0; 3]; 2], |g| [g.min.to_array(), g.max.to_array()]),
        probes: probes.positions.iter().map(|p| p.to_array()).collect(),
        relight_side: settings.relight_side,
        relight_hits: relight_rays.hits,
        cluster_probe_starts,
        cluster_probes: clusters
            .list
            .iter()
            .flat_map(|c| c.probes.iter().copied())
            .collect(),
        cluster_basis: clusters.list.iter().map(|c| c.basis as u32).collect(),
        cluster_projection_starts,
        projections: clusters
            .list
            .iter()
            .flat_map(|c| c.projection.iter().copied())
            .collect(),
        cluster_bounds: clusters
            .list
            .iter()
            .map(|c| [c.bounds.min.to_array(), c.bounds.max.to_array()])
            .collect(),
        report: serde_json::to_string(&report)?,
    };
    Ok((data, report))
}
