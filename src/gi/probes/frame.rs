//! `--gi probes`: the frame of the irradiance probes (Sedláček 2019, 3.3), from a bake
//! read or made when the technique starts ([`super::load_or_bake`]). Four compute passes,
//! each named as its shader in `glsl/gi/probes/`:
//! - `probe_relight`: the radiance every probe ray meets (the frame's direct light through
//!   its shadow maps, emission, the sky, last frame's lightmap for the bounces), projected
//!   onto the harmonics (λ);
//! - `probe_basis`: each cluster's basis vectors from its probes' λ;
//! - `probe_receivers`: each receiver's irradiance into the lightmap;
//! - `probe_levels`: the lightmap's coarser levels from the receivers that stand for their
//!   texels (4.2.3, [`super::levels`]); with the level of detail, the two passes compute
//!   only what the frame's lookups read;
//! - `probe_grid`: where moving meshes are, the irradiance of the grid's spatial receivers
//!   around them (4.1; the basis pass computes their clusters' vectors too);
//! - `probe_gather`: the lightmap at the uv of each pixel's triangle (the G-buffer numbers
//!   them), or for a moving mesh the grid at its position, as the screen contract's
//!   indirect term.
//!
//! Two lightmaps alternate: a frame writes one and its relight reads the other, last
//! frame's. Visibility is the bake's: moving meshes neither block nor bounce light here
//! (the shadow maps still see them, so they do cast direct shadows); they have no
//! lightmap and are shaded from the grid.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{bail, Result};
use ash::vk;
use gpu_allocator::MemoryLocation;

use super::casting::RelightRays;
use super::file::BakeData;
use super::grid::Grid;
use super::levels::{LightmapLevels, Work, LEVELS};
use super::sh::Basis;
use super::{BakeReport, BakeSettings, Origin};
use crate::gi::bounces::MAX_BOUNCES;
use crate::gi::{
    DebugView, FrameInputs, GatherOptions, Gathered, Inputs, Preparation, Screen, ScreenRequest,
    Switch, Technique,
};
use crate::gpu_layout::{
    self as layout, FrameUniforms, ProbeUniforms, ProbeView, RayHit, RAY_NONE,
};
use crate::ray::surfaces::{texel_buffer, SceneTriangles};
use crate::scene::Scene;
use crate::vk::{
    clear_to_zero, compute_to_compute, groups_2d, sampler_info, stage_barrier, update_buffer,
    Binding, Buffer, Context, DescriptorSets, Image, ImageDesc, ImageUse, OneShot, OwnedView,
    Pipeline, Sampler, SetWriter, TexelBuffer,
};

/// The technique's settings: the bake's, and where its file is.
#[derive(Clone, Debug, PartialEq)]
pub struct ProbeSettings {
    pub bake: BakeSettings,
    /// The bake's file; `None`: the user's cache folder ([`super::file::default_path`]).
    pub bake_file: Option<PathBuf>,
    /// Light bounces the first frame computes (1: the light that reaches a surface from
    /// the emitters, lights and sky by one bounce off the probes' surfaces). With more
    /// than one, every later frame adds one more on top of the last frame's lightmap, so
    /// the bounces converge as a geometric series.
    pub bounces: u32,
    /// One image without a given count: `bounces` becomes
    /// [`crate::gi::bounces::bounces_for`] the scene ([`crate::gi::GiSettings::on`]).
    pub converge_bounces: bool,
    /// The dynamic level of detail (4.2), and the camera distances where its levels 1 to 3
    /// begin (`None`: [`LOD_RADII`] probe radii).
    pub lod: bool,
    pub lod_distances: Option<[f32; 3]>,
}

impl Default for ProbeSettings {
    fn default() -> Self {
        Self {
            bake: BakeSettings::default(),
            bake_file: None,
            bounces: 8,
            converge_bounces: false,
            lod: true,
            lod_distances: None,
        }
    }
}

impl ProbeSettings {
    /// Checks the frame's settings (the bake's are checked as they are parsed); errors
    /// name the command-line option.
    pub fn check(&self) -> Result<()> {
        if !(1..=MAX_BOUNCES).contains(&self.bounces) {
            bail!(
                "--probe-bounces {}: give 1 to {MAX_BOUNCES} bounces",
                self.bounces
            );
        }
        if let Some(d) = self.lod_distances {
            let increasing = d[0] > 0.0 && d[0] < d[1] && d[1] < d[2] && d[2].is_finite();
            if !increasing {
                bail!(
                    "--lod-distances {},{},{}: give three finite distances, above zero and \
                     increasing",
                    d[0],
                    d[1],
                    d[2]
                );
            }
        }
        Ok(())
    }
}

/// The debug views the probes offer.
pub const DEBUG_VIEWS: [DebugView; 5] = [
    DebugView::None,
    DebugView::Indirect,
    DebugView::Lightmap,
    DebugView::Clusters,
    DebugView::Probes,
];

/// The format of the lightmaps: irradiance / π, HDR.
const LIGHTMAP_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;

/// How the lightmaps are used between frames: written as storage and sampled by compute
/// passes, in the general layout throughout.
pub(super) const LIGHTMAP_USE: ImageUse = ImageUse {
    layout: vk::ImageLayout::GENERAL,
    stage: vk::PipelineStageFlags2::COMPUTE_SHADER,
    access: vk::AccessFlags2::from_raw(
        vk::AccessFlags2::SHADER_STORAGE_WRITE.as_raw()
            | vk::AccessFlags2::SHADER_SAMPLED_READ.as_raw(),
    ),
};

/// The most workgroups of one dispatch along x that every device runs.
const MAX_GROUPS: u32 = 65535;

/// The level of detail's levels (Sedláček 2019, 4.2): per level, the highest harmonic
/// band the probes project onto (never above the bake's) and the relight map its probes
/// read ([`RelightRays`]). The thesis's example: 64, 25 and 16 coefficients, and rays
/// halved level by level (512, 256, 128, 64); here a level quarters the rays, until a
/// sixteenth of level 0's are left (4,096, 1,024, 256 and 256 at the default
/// `--relight-side`).
const LOD_BANDS: [u32; 4] = [7, 5, 3, 2];
const LOD_RELIGHT_MAP: [usize; 4] = [0, 1, 2, 2];

/// Where levels 1, 2 and 3 begin by default, in probe radii from the camera. Band 7
/// resolves about a seventh of a probe's sphere, detail a half radius across on its
/// receivers: 16 radii away that still spans 1.8° (12 pixels of a 256² view at 39°). With
/// levels from 8 radii, half the Cornell box's receivers drop to bands 0 to 5 and its
/// LDR-FLIP goes from 0.070 to 0.079; from 16 the box is all level 0.
pub const LOD_RADII: [f32; 3] = [16.0, 32.0, 64.0];

/// The camera as the level of detail sees it: where it is, where it looks, and the cosine
/// of the half-angle of the cone around its view direction that holds its frustum.
#[derive(Clone, Copy, Debug)]
pub(super) struct LodCamera {
    pub position: glam::Vec3,
    pub forward: glam::Vec3,
    pub cos_frustum: f32,
}

impl LodCamera {
    /// The camera of a frame's uniforms (a perspective projection).
    pub fn new(uniforms: &FrameUniforms) -> Self {
        Self::from_matrices(
            glam::Vec4::from(uniforms.camera_position).truncate(),
            glam::Mat4::from_cols_array_2d(&uniforms.view),
            glam::Mat4::from_cols_array_2d(&uniforms.proj),
        )
    }

    /// The camera at `position` with the world-to-view `view` and the perspective `proj`.
    pub fn from_matrices(position: glam::Vec3, view: glam::Mat4, proj: glam::Mat4) -> Self {
        // The frustum's corner rays make the widest angle with the view direction.
        let corner = glam::Vec2::new(1.0 / proj.x_axis.x, 1.0 / proj.y_axis.y);
        Self {
            position,
            forward: view
                .inverse()
                .transform_vector3(glam::Vec3::NEG_Z)
                .normalize(),
            cos_frustum: 1.0 / (1.0 + corner.length_squared()).sqrt(),
        }
    }

    /// The level of the box `bounds` for levels beginning at `distances`: that of its
    /// nearest point, its distance scaled by the box's zone.
    pub fn box_level(&self, bounds: &crate::scene::Aabb, distances: &[f32; 3]) -> usize {
        let nearest = self.position.clamp(bounds.min, bounds.max);
        level_at(
            self.position.distance(nearest) * self.box_scale(bounds),
            distances,
        )
    }

    /// The whole level a lookup at `p` reads at least (the shaders' `lightmap_level` is
    /// this or up to one more where it blends towards the next).
    #[cfg(test)]
    pub fn point_level(&self, p: glam::Vec3, distances: &[f32; 3]) -> usize {
        let to = p - self.position;
        let d = to.length();
        let scale = if d > 0.0 {
            zone_scale(to.dot(self.forward) / d, self.cos_frustum)
        } else {
            1.0
        };
        level_at(d * scale, distances)
    }

    /// `ProbeView`'s `forward`.
    fn forward(&self) -> [f32; 4] {
        self.forward.extend(self.cos_frustum).to_array()
    }

    /// How much farther than it is the box `bounds` counts: the zone (`zone_scale`) of its
    /// bounding sphere's part nearest the view direction, so that no point of the box lies
    /// in a zone nearer than the box's.
    fn box_scale(&self, bounds: &crate::scene::Aabb) -> f32 {
        let centre = 0.5 * (bounds.min + bounds.max);
        let radius = 0.5 * bounds.min.distance(bounds.max);
        let to = centre - self.position;
        let d = to.length();
        if d <= radius {
            return 1.0;
        }
        let angle = (to.dot(self.forward) / d).clamp(-1.0, 1.0).acos();
        let nearest = (angle - (radius / d).asin()).max(0.0);
        zone_scale(nearest.cos(), self.cos_frustum)
    }
}

/// The level at distance `d` for levels beginning at `distances`.
pub(super) fn level_at(d: f32, distances: &[f32; 3]) -> usize {
    distances.iter().filter(|&&l| d >= l).count()
}

/// How much farther than it is a point counts for the level of detail, by the zone around
/// the camera it lies in (Sedláček 2019, 4.2.1, Figure 4.8): 1 inside the cone holding
/// the view frustum, 2 beside it in front of the camera, 4 behind. Surfaces out of view
/// reach the image only through the probes' bounces, so they take coarser levels sooner.
/// The shaders' `zone_scale` (`glsl/gi/probes/probes.glsl`) is the same.
fn zone_scale(cos_angle: f32, cos_frustum: f32) -> f32 {
    if cos_angle >= cos_frustum {
        1.0
    } else if cos_angle >= 0.0 {
        2.0
    } else {
        4.0
    }
}

/// The level of detail of each frame, from the camera.
struct LevelsOfDetail {
    /// Where levels 1 to 3 begin.
    distances: [f32; 3],
    order: u32,
    probes: usize,
    /// Per cluster, its receivers' box and its probes.
    bounds: Vec<crate::scene::Aabb>,
    cluster_probes: Vec<std::ops::Range<usize>>,
    probe_list: Vec<u32>,
}

impl LevelsOfDetail {
    /// A probe's entry and a cluster's in `BINDING_PROBE_LOD` at `level`.
    fn coefficients(&self, level: usize) -> u32 {
        (LOD_BANDS[level].min(self.order) + 1).pow(2)
    }

    /// This frame's `BINDING_PROBE_LOD` for `camera` (`on`: else everything at level 0),
    /// the probes at each level, and each cluster's level. A cluster's level is that of its
    /// receivers' box's nearest point (4.2.2), its distance scaled by the box's zone; a
    /// probe takes the finest level of the clusters it supports, so that every basis
    /// vector finds the coefficients it reads (the thesis shifts the probes' distance by
    /// their radius to the same end, 4.2.1).
    fn entries(&self, camera: &LodCamera, on: bool) -> (Vec<u32>, [u32; 4], Vec<u8>) {
        let mut probe_level = vec![LOD_BANDS.len() - 1; self.probes];
        let mut clusters = Vec::with_capacity(self.bounds.len());
        let mut cluster_levels = Vec::with_capacity(self.bounds.len());
        for (bounds, probes) in self.bounds.iter().zip(&self.cluster_probes) {
            let level = if on {
                camera.box_level(bounds, &self.distances)
            } else {
                0
            };
            for &p in &self.probe_list[probes.clone()] {
                let p = p as usize;
                probe_level[p] = probe_level[p].min(level);
            }
            clusters.push(self.coefficients(level));
            cluster_levels.push(level as u8);
        }
        if !on {
            probe_level.fill(0);
        }
        let mut per_level = [0u32; 4];
        let mut entries: Vec<u32> = probe_level
            .iter()
            .map(|&l| {
                per_level[l] += 1;
                self.coefficients(l) | (l as u32) << 16
            })
            .collect();
        entries.extend(clusters);
        (entries, per_level, cluster_levels)
    }
}

/// Whether the decoded surfaces of `rays` relight rays (two texels each) fit one texel
/// buffer of `texel_limit` elements, through which `probe_surfaces` writes them and the
/// relight reads them. (A storage buffer would bind far less: 128 MiB on lavapipe.)
pub(super) fn check_relight_rays(rays: u64, texel_limit: u64) -> Result<()> {
    if 2 * rays > texel_limit {
        bail!(
            "the bake's {rays} relight rays need {} texels, more than the {texel_limit} this \
             device binds in one texel buffer: bake fewer --probes or a smaller --relight-side",
            2 * rays
        );
    }
    Ok(())
}

/// The bake's tables as the passes read them, built on the host.
struct Tables {
    hits: Vec<[u32; 4]>,
    harmonics: Vec<f32>,
    positions: Vec<[f32; 4]>,
    vectors: Vec<[u32; 4]>,
    receivers: Vec<[u32; 4]>,
    /// The receivers' coordinates, then their sky factors.
    coordinates: Vec<f32>,
    corner_uvs: Vec<[f32; 2]>,
    /// Per lightmap texel, its receiver's cluster (`RAY_NONE`: none).
    texel_clusters: Vec<u32>,
    uniforms: ProbeUniforms,
    grid: Option<GridTables>,
}

/// What the host needs to list the grid's work of a frame.
struct GridTables {
    grid: Grid,
    /// Per spatial receiver (in the bake's order), its cluster.
    clusters: Vec<u32>,
    /// Per cluster, its first basis vector and their count.
    vectors: Vec<(u32, u32)>,
}

impl Tables {
    /// The tables of `data`, baked from the static meshes of `scene`: its triangles are
    /// renumbered from the static scene's order to the whole scene's. `bounces`: the
    /// relight adds last frame's lightmap; `debug_radius`: the probes' spheres' radius.
    fn new(scene: &Scene, data: &BakeData, bounces: bool, debug_radius: f32) -> Result<Self> {
        let n = super::sh::coefficient_count(data.sh_order);
        // The whole scene's index of each static triangle, and the corners' lightmap uvs
        // of every triangle (moving meshes' negative: none).
        let mut whole_of_static = Vec::new();
        let mut corner_uvs = Vec::new();
        let mut first = 0u32;
        let mut static_mesh = 0usize;
        for mesh in &scene.meshes {
            let count = (mesh.indices.len() / 3) as u32;
            if mesh.animation.is_none() {
                let (start, end) = (
                    data.mesh_corners[static_mesh] as usize,
                    data.mesh_corners[static_mesh + 1] as usize,
                );
                if end - start != 3 * count as usize {
                    bail!("the bake's lightmap uvs do not match the scene's meshes");
                }
                corner_uvs.extend_from_slice(&data.corner_uvs[start..end]);
                whole_of_static.extend(first..first + count);
                static_mesh += 1;
            } else {
                corner_uvs.extend(std::iter::repeat_n([-1.0f32; 2], 3 * count as usize));
            }
            first += count;
        }
        let hits = data
            .relight_hits
            .iter()
            .map(|h: &RayHit| {
                let triangle = if h.triangle == RAY_NONE {
                    RAY_NONE
                } else {
                    whole_of_static[h.triangle as usize]
                };
                [triangle, h.t.to_bits(), h.u.to_bits(), h.v.to_bits()]
            })
            .collect();
        let side = data.relight_side as usize;
        let relight_rays = RelightRays::rays(side);
        let rays = relight_rays.len();
        let basis = Basis::new(data.sh_order);
        let mut y = vec![0.0f64; n];
        let mut harmonics = Vec::with_capacity(rays * n);
        for &(d, solid_angle) in &relight_rays {
            basis.eval_into(d, &mut y);
            harmonics.extend(y.iter().map(|y| (y * solid_angle) as f32));
        }
        let maps = LOD_RELIGHT_MAP.map(|m| RelightRays::map(side, m));
        let clusters = data.cluster_basis.len();
        let mut first_vector = Vec::with_capacity(clusters);
        let mut vectors = Vec::new();
        for c in 0..clusters {
            first_vector.push(vectors.len() as u32);
            let probes = data.cluster_probe_starts[c + 1] - data.cluster_probe_starts[c];
            let width = probes * n as u32;
            for i in 0..data.cluster_basis[c] {
                vectors.push([
                    data.cluster_probe_starts[c],
                    probes,
                    data.cluster_projection_starts[c] + i * width,
                    c as u32,
                ]);
            }
        }
        // The grid's receivers have no texel: `probe_grid` places them by their index.
        let receivers = (0..data.receiver_clusters.len())
            .map(|r| {
                let texel = data.receiver_texels.get(r).map_or(0, |&[x, y]| x | y << 16);
                let c = data.receiver_clusters[r] as usize;
                [
                    texel,
                    data.receiver_offsets[r],
                    first_vector[c],
                    data.cluster_basis[c],
                ]
            })
            .collect();
        let [width, height] = data.lightmap;
        let mut texel_clusters = vec![RAY_NONE; (width * height) as usize];
        for (&[x, y], &c) in data.receiver_texels.iter().zip(&data.receiver_clusters) {
            texel_clusters[(y * width + x) as usize] = c;
        }
        let mut coordinates = data.coordinates.clone();
        coordinates.extend_from_slice(&data.receiver_sky);
        // The grid's clusters follow the lightmap's (`super::compute`).
        let lightmap_receivers = data.receiver_texels.len();
        let lightmap_clusters = data.receiver_clusters[..lightmap_receivers]
            .iter()
            .map(|&c| c + 1)
            .max()
            .unwrap_or(0);
        let spatial = &data.receiver_clusters[lightmap_receivers..];
        if spatial.iter().any(|&c| c < lightmap_clusters) {
            bail!("the bake's grid shares clusters with its lightmap");
        }
        let lightmap_vectors = first_vector
            .get(lightmap_clusters as usize)
            .copied()
            .unwrap_or(vectors.len() as u32);
        let grid = (data.grid_points() > 0).then(|| {
            let [min, max] = data.grid_bounds.map(glam::Vec3::from);
            GridTables {
                grid: Grid {
                    size: glam::UVec3::from_array(data.grid_size),
                    min,
                    max,
                },
                clusters: spatial.to_vec(),
                vectors: (0..clusters)
                    .map(|c| (first_vector[c], data.cluster_basis[c]))
                    .collect(),
            }
        });
        let (grid_min, grid_inverse_extent) = match &grid {
            Some(g) => {
                let extent = g.grid.max - g.grid.min;
                let inverse = extent.map(|e| if e > 0.0 { 1.0 / e } else { 0.0 });
                (
                    g.grid.min.extend(0.0).to_array(),
                    inverse.extend(0.0).to_array(),
                )
            }
            None => ([0.0; 4], [0.0; 4]),
        };
        let [gx, gy, gz] = data.grid_size;
        let uniforms = ProbeUniforms {
            probe_count: data.probes.len() as u32,
            rays_per_probe: rays as u32,
            coefficients: n as u32,
            receiver_count: lightmap_receivers as u32,
            vector_count: lightmap_vectors,
            sky_offset: data.coordinates.len() as u32,
            bounces: u32::from(bounces),
            debug_radius,
            relight_first: maps.map(|(first, _)| first as u32),
            relight_side: maps.map(|(_, side)| side as u32),
            grid_size: [gx, gy, gz, data.grid_points() as u32],
            grid_min,
            grid_inverse_extent,
        };
        Ok(Self {
            hits,
            harmonics,
            positions: data
                .probes
                .iter()
                .map(|p| [p[0], p[1], p[2], 0.0])
                .collect(),
            vectors,
            receivers,
            coordinates,
            corner_uvs,
            texel_clusters,
            uniforms,
            grid,
        })
    }
}

impl GridTables {
    /// The grid's work at scene time `time_s`: the points a lookup on any moving mesh's
    /// box reads, their six receivers and their clusters' basis vectors, as the list of
    /// `BINDING_PROBE_GRID_ACTIVE` (`receivers` indexes the receivers' table, after the
    /// lightmap's `lightmap_receivers`).
    fn active(&self, scene: &Scene, time_s: f32, lightmap_receivers: u32) -> Vec<u32> {
        let points = self.grid.point_count();
        let mut point_on = vec![false; points];
        for m in (0..scene.meshes.len()).filter(|&m| scene.meshes[m].animation.is_some()) {
            let bounds = scene.meshes[m]
                .local_bounds
                .transformed(scene.mesh_transform(m, time_s));
            if let Some(footprint) = self.grid.footprint(&bounds) {
                for p in self.grid.points_in(footprint) {
                    point_on[p] = true;
                }
            }
        }
        let mut cluster_on = vec![false; self.vectors.len()];
        let mut receivers = Vec::new();
        for d in 0..super::grid::DIRECTIONS.len() {
            for p in (0..points).filter(|&p| point_on[p]) {
                let s = d * points + p;
                cluster_on[self.clusters[s] as usize] = true;
                receivers.push(lightmap_receivers + s as u32);
            }
        }
        let vectors: Vec<u32> = cluster_on
            .iter()
            .enumerate()
            .filter(|(_, &on)| on)
            .flat_map(|(c, _)| {
                let (first, count) = self.vectors[c];
                first..first + count
            })
            .collect();
        let mut list = vec![vectors.len() as u32, receivers.len() as u32];
        list.extend(vectors);
        list.extend(receivers);
        list
    }
}

/// The bake's tables on the GPU.
struct Uploaded {
    harmonics: TexelBuffer,
    positions: TexelBuffer,
    vectors: TexelBuffer,
    cluster_probes: TexelBuffer,
    projections: TexelBuffer,
    receivers: TexelBuffer,
    coordinates: TexelBuffer,
    corner_uvs: TexelBuffer,
    texel_clusters: TexelBuffer,
}

impl Uploaded {
    fn new(ctx: &Arc<Context>, tables: &Tables, data: &BakeData) -> Result<Self> {
        use vk::Format as F;
        let one_shot = OneShot::new(ctx)?;
        let upload = |name: &str, format: F, texel: u64, bytes: &[u8]| {
            texel_buffer(ctx, &one_shot, name, format, texel, bytes)
        };
        Ok(Self {
            harmonics: upload(
                "probe ray harmonics",
                F::R32_SFLOAT,
                4,
                bytemuck::cast_slice(&tables.harmonics),
            )?,
            positions: upload(
                "probe positions",
                F::R32G32B32A32_SFLOAT,
                16,
                bytemuck::cast_slice(&tables.positions),
            )?,
            vectors: upload(
                "probe basis vectors",
                F::R32G32B32A32_UINT,
                16,
                bytemuck::cast_slice(&tables.vectors),
            )?,
            cluster_probes: upload(
                "probe clusters' probes",
                F::R32_UINT,
                4,
                bytemuck::cast_slice(&data.cluster_probes),
            )?,
            projections: upload(
                "probe cluster projections",
                F::R32_SFLOAT,
                4,
                bytemuck::cast_slice(&data.projections),
            )?,
            receivers: upload(
                "probe receivers",
                F::R32G32B32A32_UINT,
                16,
                bytemuck::cast_slice(&tables.receivers),
            )?,
            coordinates: upload(
                "probe receiver coordinates",
                F::R32_SFLOAT,
                4,
                bytemuck::cast_slice(&tables.coordinates),
            )?,
            corner_uvs: upload(
                "probe lightmap uvs",
                F::R32G32_SFLOAT,
                8,
                bytemuck::cast_slice(&tables.corner_uvs),
            )?,
            texel_clusters: upload(
                "probe texel clusters",
                F::R32_UINT,
                4,
                bytemuck::cast_slice(&tables.texel_clusters),
            )?,
        })
    }

    fn memory_bytes(&self) -> Vec<(&'static str, u64)> {
        vec![
            (
                "probe_rays",
                self.harmonics.buffer.size + self.positions.buffer.size,
            ),
            (
                "probe_clusters",
                self.vectors.buffer.size
                    + self.cluster_probes.buffer.size
                    + self.projections.buffer.size,
            ),
            (
                "probe_receivers",
                self.receivers.buffer.size + self.coordinates.buffer.size,
            ),
            ("probe_lightmap_uvs", self.corner_uvs.buffer.size),
            ("probe_texel_clusters", self.texel_clusters.buffer.size),
        ]
    }
}

/// The irradiance probes' frame.
pub struct ProbeGi {
    surfaces: SceneTriangles,
    tables: Uploaded,
    /// What each probe ray met: the bake's hits and their surfaces (`probe_surfaces`).
    hits: TexelBuffer,
    hit_surfaces: TexelBuffer,
    uniforms: Buffer,
    lambda: TexelBuffer,
    basis: Buffer,
    /// Per lightmap, a view of each of its levels (dropped before the lightmaps).
    _level_views: Vec<OwnedView>,
    /// Written by alternate frames, with their coarser levels.
    lightmaps: [Image; 2],
    /// Which texels of which levels stand for which receivers, and what the last recorded
    /// frame computed (its clusters' levels, its lists, and the buffer that holds them).
    levels: LightmapLevels,
    cluster_levels: Vec<u8>,
    work: Work,
    work_buffer: Buffer,
    /// `ProbeView` as the last frame had it.
    view_buffer: Buffer,
    view: ProbeView,
    /// The grid of spatial receivers' irradiance, and this frame's list of its work.
    grid: Image,
    grid_active: Buffer,
    grid_tables: Option<GridTables>,
    /// The spatial receivers the last recorded frame computed.
    active_spatial_receivers: u32,
    /// The level of detail (the viewer's switch), its buffer, and the probes at each
    /// level in the last frame.
    lod_on: bool,
    lod: LevelsOfDetail,
    lod_buffer: Buffer,
    /// What `lod_buffer` holds (uploaded again only when the levels change).
    lod_entries: Vec<u32>,
    probes_per_level: [u32; 4],
    /// Referenced by the sets.
    _sampler: Sampler,
    _sets: DescriptorSets,
    /// Set i writes lightmap i and reads the other as last frame's.
    sets: [vk::DescriptorSet; 2],
    relight: Pipeline,
    basis_pass: Pipeline,
    receivers: Pipeline,
    levels_pass: Pipeline,
    grid_pass: Pipeline,
    gather: Pipeline,
    counts: ProbeUniforms,
    /// The lightmap the next frame writes.
    next: usize,
    /// The lightmaps are cleared before the next frame (after a restart).
    clear: bool,
    /// Relight iterations the next frame runs: a bounce each (relight, basis and receivers,
    /// each reading the lightmap the last wrote), as the cone tracer's first frame
    /// computes its voxel bounces.
    iterations: u32,
    /// Those of a first frame.
    bounces: u32,
    report: BakeReport,
    origin: Origin,
    /// Reading or baking, and uploading, in milliseconds.
    prepare_ms: f64,
    lightmap_size: [u32; 2],
    extent: vk::Extent2D,
    ctx: Arc<Context>,
}

impl ProbeGi {
    pub fn new(inputs: &Inputs, settings: &ProbeSettings) -> Result<Self> {
        settings.check()?;
        let ctx = inputs.ctx;
        if !ctx.features.geometry_shader {
            bail!(
                "--gi probes needs the geometry-shader feature, which this device ({}) lacks: \
                 the G-buffer numbers its triangles with gl_PrimitiveID",
                ctx.device_name()
            );
        }
        let start = Instant::now();
        let scene = inputs.scene;
        let path = match &settings.bake_file {
            Some(p) => p.clone(),
            None => super::file::default_path(scene, &settings.bake)?,
        };
        let bake = super::load_or_bake(ctx, scene, &settings.bake, &path, false, None)?;
        let data = &bake.data;
        let [width, height] = data.lightmap;
        let limit = ctx.properties.limits.max_image_dimension2_d;
        if width > limit || height > limit {
            bail!(
                "the bake's lightmap is {width} × {height} texels, more than the {limit} this \
                 device ({}) allows: bake with a smaller --lightmap-size",
                ctx.device_name()
            );
        }
        // A tenth of the probes' spacing keeps their spheres apart on the screen.
        let tables = Tables::new(
            scene,
            data,
            settings.bounces > 1,
            0.1 * bake.report.probe_spacing,
        )?;
        let counts = tables.uniforms;
        if counts.probe_count > MAX_GROUPS {
            bail!(
                "the bake has {} probes: the relight runs a workgroup per probe, {MAX_GROUPS} at most",
                counts.probe_count
            );
        }
        let surfaces = SceneTriangles::new(ctx, scene)?;
        let uploaded = Uploaded::new(ctx, &tables, data)?;
        // Read once, by `probe_surfaces`; kept while the sets refer to it.
        let hits = texel_buffer(
            ctx,
            &OneShot::new(ctx)?,
            "probe hits",
            vk::Format::R32G32B32A32_UINT,
            16,
            bytemuck::cast_slice(&tables.hits),
        )?;
        let rays = u64::from(counts.probe_count) * u64::from(counts.rays_per_probe);
        let texel_limit = u64::from(ctx.properties.limits.max_texel_buffer_elements);
        check_relight_rays(rays, texel_limit)?;
        let hit_surfaces = TexelBuffer::new(
            "probe surfaces",
            Buffer::new(
                ctx,
                "probe surfaces",
                (32 * rays).max(32),
                vk::BufferUsageFlags::STORAGE_TEXEL_BUFFER
                    | vk::BufferUsageFlags::UNIFORM_TEXEL_BUFFER,
                MemoryLocation::GpuOnly,
            )?,
            vk::Format::R32G32B32A32_UINT,
        )?;
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let vec4 = 16u64;
        let lambdas = u64::from(counts.probe_count) * u64::from(counts.coefficients);
        if lambdas > texel_limit {
            bail!(
                "the probes' {lambdas} harmonic coefficients are more texels than the \
                 {texel_limit} this device binds in one texel buffer: bake fewer --probes or \
                 a lower --sh-order"
            );
        }
        // Written by the relight as storage, read by the basis pass as texels: a CPU
        // driver fetches texels for all SIMD lanes at once, where it loads a storage
        // buffer one lane and one word at a time (`surfaces.glsl`).
        let lambda = TexelBuffer::new(
            "probe lambda",
            Buffer::new(
                ctx,
                "probe lambda",
                (vec4 * lambdas).max(vec4),
                storage | vk::BufferUsageFlags::UNIFORM_TEXEL_BUFFER,
                MemoryLocation::GpuOnly,
            )?,
            vk::Format::R32G32B32A32_SFLOAT,
        )?;
        let basis = Buffer::new(
            ctx,
            "probe cluster basis",
            (vec4 * tables.vectors.len() as u64).max(vec4),
            storage,
            MemoryLocation::GpuOnly,
        )?;
        let uniforms = Buffer::with_data(
            ctx,
            "probe uniforms",
            bytemuck::bytes_of(&counts),
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?;
        if width.max(height) < 1 << (LEVELS - 1) {
            bail!(
                "the bake's lightmap is {width} × {height} texels: its {LEVELS} levels need \
                 {} texels along one side at least; bake with a larger --lightmap-size",
                1 << (LEVELS - 1)
            );
        }
        let lightmap = |i: usize| {
            Image::new(
                ctx,
                &format!("probe lightmap {i}"),
                ImageDesc {
                    mip_levels: LEVELS as u32,
                    ..ImageDesc::d2(
                        LIGHTMAP_FORMAT,
                        width,
                        height,
                        vk::ImageUsageFlags::STORAGE
                            | vk::ImageUsageFlags::SAMPLED
                            | vk::ImageUsageFlags::TRANSFER_DST
                            | vk::ImageUsageFlags::TRANSFER_SRC,
                    )
                },
            )
        };
        let lightmaps = [lightmap(0)?, lightmap(1)?];
        let mut level_views = Vec::with_capacity(2 * LEVELS);
        for image in &lightmaps {
            for level in 0..LEVELS as u32 {
                level_views.push(image.layer_view(0, level)?);
            }
        }
        let levels = LightmapLevels::new(
            data.lightmap,
            &data.receiver_texels,
            &data.receiver_clusters,
        );
        // The counts, then at most every receiver and every texel of the coarser levels.
        let work_buffer = Buffer::new(
            ctx,
            "probe work",
            4 * (2 + u64::from(counts.receiver_count) + 2 * levels.texel_count() as u64),
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuOnly,
        )?;
        let [gx, gy, gz, points] = counts.grid_size;
        let limit = ctx.properties.limits.max_image_dimension3_d;
        if gx.max(gy).max(6 * gz) > limit {
            bail!(
                "the bake's grid of spatial receivers is {gx} × {gy} × {gz} points, whose six \
                 slabs need an image {gx} × {gy} × {}, more than the {limit} this device ({}) \
                 allows: bake fewer --spatial-receivers",
                6 * gz,
                ctx.device_name()
            );
        }
        let grid = Image::new(
            ctx,
            "probe grid",
            ImageDesc {
                extent: vk::Extent3D {
                    width: gx.max(1),
                    height: gy.max(1),
                    depth: (6 * gz).max(1),
                },
                ..ImageDesc::d3(
                    LIGHTMAP_FORMAT,
                    1,
                    1,
                    vk::ImageUsageFlags::STORAGE
                        | vk::ImageUsageFlags::SAMPLED
                        | vk::ImageUsageFlags::TRANSFER_DST
                        | vk::ImageUsageFlags::TRANSFER_SRC,
                )
            },
        )?;
        // The counts, then at most every grid cluster's vectors and every spatial receiver.
        let spatial_vectors = tables.vectors.len() as u64 - u64::from(counts.vector_count);
        let grid_active = Buffer::new(
            ctx,
            "probe grid active",
            4 * (2 + spatial_vectors + 6 * u64::from(points)),
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuOnly,
        )?;
        let lod = LevelsOfDetail {
            distances: settings
                .lod_distances
                .unwrap_or(LOD_RADII.map(|r| r * bake.report.probe_radius)),
            order: data.sh_order,
            probes: data.probes.len(),
            bounds: data
                .cluster_bounds
                .iter()
                .map(|&[min, max]| crate::scene::Aabb {
                    min: glam::Vec3::from(min),
                    max: glam::Vec3::from(max),
                })
                .collect(),
            cluster_probes: data
                .cluster_probe_starts
                .windows(2)
                .map(|w| w[0] as usize..w[1] as usize)
                .collect(),
            probe_list: data.cluster_probes.clone(),
        };
        // Level 0 until a frame finds other levels for its camera.
        let off = LodCamera {
            position: glam::Vec3::ZERO,
            forward: glam::Vec3::NEG_Z,
            cos_frustum: 0.0,
        };
        let (entries, probes_per_level, _) = lod.entries(&off, false);
        let view = ProbeView {
            camera: [0.0; 4],
            previous_camera: [0.0; 4],
            forward: off.forward(),
            previous_forward: off.forward(),
            distances: [lod.distances[0], lod.distances[1], lod.distances[2], 0.0],
        };
        let view_buffer = Buffer::with_data(
            ctx,
            "probe view",
            bytemuck::bytes_of(&view),
            vk::BufferUsageFlags::UNIFORM_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
        )?;
        let lod_buffer = Buffer::with_data(
            ctx,
            "probe lod",
            bytemuck::cast_slice(&entries),
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
        )?;
        OneShot::new(ctx)?.run("clearing the probe lightmaps and grid", |cmd| {
            for image in lightmaps.iter().chain([&grid]) {
                clear_to_zero(ctx, cmd, image, ImageUse::UNDEFINED, LIGHTMAP_USE);
            }
            unsafe {
                ctx.device
                    .cmd_fill_buffer(cmd, grid_active.raw, 0, vk::WHOLE_SIZE, 0)
            };
            stage_barrier(
                ctx,
                cmd,
                vk::PipelineStageFlags2::ALL_TRANSFER,
                vk::PipelineStageFlags2::COMPUTE_SHADER,
            );
            Ok(())
        })?;
        let sampler = Sampler::new(
            ctx,
            "probe lightmap",
            &sampler_info(vk::Filter::LINEAR, vk::SamplerAddressMode::CLAMP_TO_EDGE),
        )?;
        let compute = vk::ShaderStageFlags::COMPUTE;
        let texels = vk::DescriptorType::UNIFORM_TEXEL_BUFFER;
        let sampled = vk::DescriptorType::COMBINED_IMAGE_SAMPLER;
        let mut bindings = SceneTriangles::bindings();
        bindings.extend([
            Binding::new(
                layout::BINDING_PROBE_UNIFORMS,
                vk::DescriptorType::UNIFORM_BUFFER,
                compute,
            ),
            Binding::new(layout::BINDING_PROBE_HITS, texels, compute),
            Binding::new(layout::BINDING_PROBE_SH, texels, compute),
            Binding::new(
                layout::BINDING_PROBE_LAMBDA,
                vk::DescriptorType::STORAGE_BUFFER,
                compute,
            ),
            Binding::new(layout::BINDING_PROBE_LAMBDA_TEXELS, texels, compute),
            Binding::new(layout::BINDING_PROBE_VECTORS, texels, compute),
            Binding::new(layout::BINDING_PROBE_CLUSTER_PROBES, texels, compute),
            Binding::new(layout::BINDING_PROBE_PROJECTIONS, texels, compute),
            Binding::new(
                layout::BINDING_PROBE_BASIS,
                vk::DescriptorType::STORAGE_BUFFER,
                compute,
            ),
            Binding::new(layout::BINDING_PROBE_RECEIVERS, texels, compute),
            Binding::new(layout::BINDING_PROBE_COORDINATES, texels, compute),
            Binding::new(
                layout::BINDING_PROBE_LIGHTMAP,
                vk::DescriptorType::STORAGE_IMAGE,
                compute,
            ),
            Binding::new(layout::BINDING_PROBE_LIGHTMAP_SAMPLED, sampled, compute),
            Binding::new(layout::BINDING_PROBE_LIGHTMAP_PREVIOUS, sampled, compute),
            Binding::new(layout::BINDING_PROBE_CORNER_UVS, texels, compute),
            Binding::new(layout::BINDING_PROBE_POSITIONS, texels, compute),
            Binding::new(
                layout::BINDING_PROBE_SURFACES,
                vk::DescriptorType::STORAGE_TEXEL_BUFFER,
                compute,
            ),
            Binding::new(layout::BINDING_PROBE_SURFACES_READ, texels, compute),
            Binding::new(layout::BINDING_PROBE_TEXEL_CLUSTERS, texels, compute),
            Binding::new(
                layout::BINDING_PROBE_GRID,
                vk::DescriptorType::STORAGE_IMAGE,
                compute,
            ),
            Binding::new(layout::BINDING_PROBE_GRID_SAMPLED, sampled, compute),
            Binding::new(
                layout::BINDING_PROBE_GRID_ACTIVE,
                vk::DescriptorType::STORAGE_BUFFER,
                compute,
            ),
            Binding::new(
                layout::BINDING_PROBE_LOD,
                vk::DescriptorType::STORAGE_BUFFER,
                compute,
            ),
            Binding::new(
                layout::BINDING_PROBE_LIGHTMAP_LEVELS,
                vk::DescriptorType::STORAGE_IMAGE,
                compute,
            )
            .array(LEVELS as u32 - 1),
            Binding::new(
                layout::BINDING_PROBE_WORK,
                vk::DescriptorType::STORAGE_BUFFER,
                compute,
            ),
            Binding::new(
                layout::BINDING_PROBE_VIEW,
                vk::DescriptorType::UNIFORM_BUFFER,
                compute,
            ),
        ]);
        let descriptor_sets = DescriptorSets::new(ctx, "probes", &bindings, 2)?;
        let sets = [
            descriptor_sets.allocate("probes 0")?,
            descriptor_sets.allocate("probes 1")?,
        ];
        for (i, &set) in sets.iter().enumerate() {
            surfaces.write_set(ctx, set);
            let storage_buffer = vk::DescriptorType::STORAGE_BUFFER;
            let t = &uploaded;
            SetWriter::new(ctx, set)
                .buffer(
                    layout::BINDING_PROBE_UNIFORMS,
                    vk::DescriptorType::UNIFORM_BUFFER,
                    uniforms.raw,
                )
                .buffer(
                    layout::BINDING_PROBE_LAMBDA,
                    storage_buffer,
                    lambda.buffer.raw,
                )
                .texel_buffer(layout::BINDING_PROBE_LAMBDA_TEXELS, lambda.view())
                .buffer(layout::BINDING_PROBE_BASIS, storage_buffer, basis.raw)
                .buffer(
                    layout::BINDING_PROBE_GRID_ACTIVE,
                    storage_buffer,
                    grid_active.raw,
                )
                .buffer(layout::BINDING_PROBE_LOD, storage_buffer, lod_buffer.raw)
                .buffer(layout::BINDING_PROBE_WORK, storage_buffer, work_buffer.raw)
                .buffer(
                    layout::BINDING_PROBE_VIEW,
                    vk::DescriptorType::UNIFORM_BUFFER,
                    view_buffer.raw,
                )
                .storage_image(layout::BINDING_PROBE_GRID, grid.view)
                .sampled_image(
                    layout::BINDING_PROBE_GRID_SAMPLED,
                    grid.view,
                    sampler.raw,
                    vk::ImageLayout::GENERAL,
                )
                .texel_buffer(layout::BINDING_PROBE_HITS, hits.view())
                .storage_texel_buffer(layout::BINDING_PROBE_SURFACES, hit_surfaces.view())
                .texel_buffer(layout::BINDING_PROBE_SURFACES_READ, hit_surfaces.view())
                .texel_buffer(layout::BINDING_PROBE_SH, t.harmonics.view())
                .texel_buffer(layout::BINDING_PROBE_VECTORS, t.vectors.view())
                .texel_buffer(
                    layout::BINDING_PROBE_CLUSTER_PROBES,
                    t.cluster_probes.view(),
                )
                .texel_buffer(layout::BINDING_PROBE_PROJECTIONS, t.projections.view())
                .texel_buffer(layout::BINDING_PROBE_RECEIVERS, t.receivers.view())
                .texel_buffer(layout::BINDING_PROBE_COORDINATES, t.coordinates.view())
                .texel_buffer(layout::BINDING_PROBE_CORNER_UVS, t.corner_uvs.view())
                .texel_buffer(layout::BINDING_PROBE_POSITIONS, t.positions.view())
                .texel_buffer(
                    layout::BINDING_PROBE_TEXEL_CLUSTERS,
                    t.texel_clusters.view(),
                )
                .storage_image(layout::BINDING_PROBE_LIGHTMAP, level_views[i * LEVELS].raw)
                .images(
                    layout::BINDING_PROBE_LIGHTMAP_LEVELS,
                    vk::DescriptorType::STORAGE_IMAGE,
                    level_views[i * LEVELS + 1..(i + 1) * LEVELS]
                        .iter()
                        .map(|v| vk::DescriptorImageInfo {
                            sampler: vk::Sampler::null(),
                            image_view: v.raw,
                            image_layout: vk::ImageLayout::GENERAL,
                        })
                        .collect(),
                )
                .sampled_image(
                    layout::BINDING_PROBE_LIGHTMAP_SAMPLED,
                    lightmaps[i].view,
                    sampler.raw,
                    vk::ImageLayout::GENERAL,
                )
                .sampled_image(
                    layout::BINDING_PROBE_LIGHTMAP_PREVIOUS,
                    lightmaps[1 - i].view,
                    sampler.raw,
                    vk::ImageLayout::GENERAL,
                )
                .apply();
        }
        let [frame, scene_layout, screen] = inputs.set_layouts;
        let set_layouts = [frame, scene_layout, screen, descriptor_sets.layout];
        use crate::vk::shaders as s;
        let coefficients = [counts.coefficients];
        let pipeline = |name: &str, spirv: &[u8], constants: &[u32]| {
            Pipeline::compute_specialized(ctx, name, spirv, &set_layouts, 0, constants)
        };
        let relight = pipeline("probe_relight", s::GI_PROBES_RELIGHT_COMP, &coefficients)?;
        let basis_pass = pipeline("probe_basis", s::GI_PROBES_BASIS_COMP, &coefficients)?;
        let receivers = pipeline("probe_receivers", s::GI_PROBES_RECEIVERS_COMP, &[])?;
        let levels_pass = pipeline("probe_levels", s::GI_PROBES_LEVELS_COMP, &[])?;
        let grid_pass = pipeline("probe_grid", s::GI_PROBES_GRID_COMP, &[])?;
        let gather = pipeline("probe_gather", s::GI_PROBES_GATHER_COMP, &[])?;
        let decode = pipeline("probe_surfaces", s::GI_PROBES_SURFACES_COMP, &[])?;
        OneShot::new(ctx)?.run("probe_surfaces", |cmd| {
            let groups = rays.div_ceil(u64::from(layout::PROBE_GROUP_SIZE));
            let x = groups.min(u64::from(MAX_GROUPS));
            decode.dispatch(
                cmd,
                &[(layout::SET_GI, sets[0])],
                [x as u32, groups.div_ceil(x) as u32, 1],
            );
            Ok(())
        })?;
        let prepare_ms = start.elapsed().as_secs_f64() * 1e3;
        log::info!(
            "irradiance probes: {} probes, {} receivers, {} clusters, {} basis vectors, \
             lightmap {width} × {height} ({:.0} ms to {} and upload)",
            counts.probe_count,
            counts.receiver_count,
            data.cluster_basis.len(),
            counts.vector_count,
            prepare_ms,
            if bake.origin == Origin::Cached {
                "read"
            } else {
                "bake"
            }
        );
        Ok(Self {
            surfaces,
            tables: uploaded,
            hits,
            hit_surfaces,
            uniforms,
            lambda,
            basis,
            _level_views: level_views,
            lightmaps,
            levels,
            // Differs from any frame's, so that the first frame lists its work.
            cluster_levels: Vec::new(),
            work: Work::default(),
            work_buffer,
            view_buffer,
            view,
            grid,
            grid_active,
            grid_tables: tables.grid,
            active_spatial_receivers: 0,
            lod_on: settings.lod,
            lod,
            lod_buffer,
            lod_entries: entries,
            probes_per_level,
            _sampler: sampler,
            _sets: descriptor_sets,
            sets,
            relight,
            basis_pass,
            receivers,
            levels_pass,
            grid_pass,
            gather,
            counts,
            next: 0,
            clear: false,
            iterations: settings.bounces,
            bounces: settings.bounces,
            report: bake.report,
            origin: bake.origin,
            prepare_ms,
            lightmap_size: data.lightmap,
            extent: vk::Extent2D::default(),
            ctx: ctx.clone(),
        })
    }

    /// The lightmap the last recorded frame wrote.
    pub fn lightmap(&self) -> &Image {
        &self.lightmaps[1 - self.next]
    }

    /// Its size in texels.
    pub fn lightmap_size(&self) -> [u32; 2] {
        self.lightmap_size
    }

    /// The grid of spatial receivers' irradiance / π (`BINDING_PROBE_GRID`).
    pub fn grid(&self) -> &Image {
        &self.grid
    }
}

impl Technique for ProbeGi {
    fn prepare(&mut self, _draw: &crate::scene_gpu::SceneDraw) -> Result<()> {
        Ok(())
    }

    /// The lightmap is smooth: its gather runs at every pixel, which costs a texel fetch.
    fn bind_screen(&mut self, extent: vk::Extent2D) -> Result<ScreenRequest> {
        self.extent = extent;
        Ok(ScreenRequest {
            scale: 1,
            plane_tolerance: 1.0 / self.report.texels_per_unit.max(f32::MIN_POSITIVE),
        })
    }

    fn record_update(
        &mut self,
        cmd: vk::CommandBuffer,
        timer: &mut crate::vk::GpuTimer,
        frame: &FrameInputs,
    ) -> Result<()> {
        let ctx = &self.ctx;
        // Last frame's passes read and wrote what this one rewrites.
        compute_to_compute(ctx, cmd);
        if self.clear {
            for image in self.lightmaps.iter().chain([&self.grid]) {
                clear_to_zero(ctx, cmd, image, LIGHTMAP_USE, LIGHTMAP_USE);
            }
            self.clear = false;
        }
        let c = &self.counts;
        // Earlier frames' passes read the lists this rewrites.
        stage_barrier(
            ctx,
            cmd,
            vk::PipelineStageFlags2::COMPUTE_SHADER,
            vk::PipelineStageFlags2::ALL_TRANSFER,
        );
        let upload = |buffer: vk::Buffer, list: &[u32]| {
            let readers = vk::PipelineStageFlags2::COMPUTE_SHADER;
            update_buffer(ctx, cmd, buffer, 0, bytemuck::cast_slice(list), readers);
        };
        let camera = LodCamera::new(frame.uniforms);
        let (entries, per_level, cluster_levels) = self.lod.entries(&camera, self.lod_on);
        if entries != self.lod_entries {
            upload(self.lod_buffer.raw, &entries);
            self.lod_entries = entries;
        }
        self.probes_per_level = per_level;
        if cluster_levels != self.cluster_levels {
            self.work = self.levels.work(&cluster_levels);
            self.cluster_levels = cluster_levels;
            let mut list = vec![
                self.work.receivers.len() as u32,
                self.work.texels.len() as u32,
            ];
            list.extend(&self.work.receivers);
            list.extend(self.work.texels.iter().flatten());
            upload(self.work_buffer.raw, &list);
        }
        // The first frame after a restart has no earlier lightmap but its own iterations'.
        let now = camera
            .position
            .extend(f32::from(u8::from(self.lod_on)))
            .to_array();
        let restart = self.iterations > 1;
        let view = ProbeView {
            previous_camera: if restart { now } else { self.view.camera },
            previous_forward: if restart {
                camera.forward()
            } else {
                self.view.forward
            },
            camera: now,
            forward: camera.forward(),
            ..self.view
        };
        if view != self.view {
            let bytes = bytemuck::bytes_of(&view);
            let readers = vk::PipelineStageFlags2::COMPUTE_SHADER;
            update_buffer(ctx, cmd, self.view_buffer.raw, 0, bytes, readers);
            self.view = view;
        }
        // The grid's work where moving meshes are this frame; none without them.
        let (mut listed_vectors, mut listed_receivers) = (0, 0);
        let scene = frame.draw.scene;
        if let Some(grid) = self
            .grid_tables
            .as_ref()
            .filter(|_| scene.has_moving_meshes())
        {
            let list = grid.active(scene, frame.draw.time_s, c.receiver_count);
            (listed_vectors, listed_receivers) = (list[0], list[1]);
            upload(self.grid_active.raw, &list);
        }
        self.active_spatial_receivers = listed_receivers;
        for _ in 0..self.iterations {
            let sets = [
                (layout::SET_FRAME, frame.draw.frame_set),
                (layout::SET_GI, self.sets[self.next]),
            ];
            timer.begin(cmd, "probe_relight");
            self.relight.dispatch(cmd, &sets, [c.probe_count, 1, 1]);
            timer.end(cmd);
            compute_to_compute(ctx, cmd);
            timer.begin(cmd, "probe_basis");
            let groups = (c.vector_count + listed_vectors).div_ceil(layout::PROBE_GROUP_SIZE);
            self.basis_pass.dispatch(cmd, &sets, [groups, 1, 1]);
            timer.end(cmd);
            compute_to_compute(ctx, cmd);
            timer.begin(cmd, "probe_receivers");
            let groups = (self.work.receivers.len() as u32).div_ceil(layout::PROBE_GROUP_SIZE);
            if groups > 0 {
                self.receivers.dispatch(cmd, &sets, [groups, 1, 1]);
            }
            timer.end(cmd);
            compute_to_compute(ctx, cmd);
            timer.begin(cmd, "probe_levels");
            let groups = (self.work.texels.len() as u32).div_ceil(layout::PROBE_GROUP_SIZE);
            if groups > 0 {
                self.levels_pass.dispatch(cmd, &sets, [groups, 1, 1]);
            }
            timer.end(cmd);
            compute_to_compute(ctx, cmd);
            self.next = 1 - self.next;
        }
        self.iterations = 1;
        if listed_receivers > 0 {
            // After the last bounce's basis vectors; nothing in the transport reads the
            // grid (moving meshes do not bounce light here).
            timer.begin(cmd, "probe_grid");
            let sets = [
                (layout::SET_FRAME, frame.draw.frame_set),
                (layout::SET_GI, self.sets[self.next]),
            ];
            let groups = listed_receivers.div_ceil(layout::PROBE_GROUP_SIZE);
            self.grid_pass.dispatch(cmd, &sets, [groups, 1, 1]);
            timer.end(cmd);
            compute_to_compute(ctx, cmd);
        }
        Ok(())
    }

    /// The indirect term; or, in a debug view of the probes' own, the screen radiance.
    fn record_gather(
        &self,
        cmd: vk::CommandBuffer,
        timer: &mut crate::vk::GpuTimer,
        frame_set: vk::DescriptorSet,
        screen: &Screen,
        options: &GatherOptions,
    ) -> Gathered {
        timer.begin(cmd, "probe_gather");
        let sets = [
            (layout::SET_FRAME, frame_set),
            (layout::SET_SCREEN, screen.set()),
            (layout::SET_GI, self.sets[1 - self.next]),
        ];
        self.gather.dispatch(
            cmd,
            &sets,
            groups_2d(screen.reduced_extent(), layout::SCREEN_GROUP_SIZE),
        );
        timer.end(cmd);
        match options.debug_view {
            DebugView::Lightmap | DebugView::Clusters | DebugView::Probes => Gathered::Screen,
            _ => Gathered::Terms,
        }
    }

    fn restart(&mut self) {
        self.clear = true;
        self.iterations = self.bounces;
    }

    fn shades_direct(&self) -> bool {
        false
    }

    fn memory_bytes(&self) -> Vec<(&'static str, u64)> {
        let mut bytes = self.surfaces.memory_bytes();
        bytes.extend(self.tables.memory_bytes());
        bytes.push((
            "probe_ray_hits",
            self.hits.buffer.size + self.hit_surfaces.buffer.size,
        ));
        bytes.push((
            "probe_lambda_and_basis",
            self.lambda.buffer.size + self.basis.size + self.uniforms.size,
        ));
        bytes.push((
            "probe_lightmaps",
            self.lightmaps.iter().map(Image::memory_bytes).sum(),
        ));
        bytes.push((
            "probe_grid",
            self.grid.memory_bytes() + self.grid_active.size,
        ));
        bytes.push((
            "probe_lod",
            self.lod_buffer.size + self.work_buffer.size + self.view_buffer.size,
        ));
        bytes
    }

    fn stats(&self) -> Result<Vec<(String, f64)>> {
        let r = &self.report;
        Ok(vec![
            ("probes".into(), r.probes as f64),
            ("receivers".into(), r.receivers as f64),
            ("clusters".into(), r.clusters as f64),
            ("basis_vectors".into(), f64::from(self.counts.vector_count)),
            ("probe_rays".into(), r.probe_rays as f64),
            ("relight_rays".into(), r.relight_rays as f64),
            (
                "sh_coefficients".into(),
                f64::from(self.counts.coefficients),
            ),
            (
                "lightmap_texels".into(),
                f64::from(r.lightmap[0] * r.lightmap[1]),
            ),
            ("unseen_hit_share".into(), r.unseen_hit_share),
            (
                "spatial_receivers".into(),
                6.0 * f64::from(self.counts.grid_size[3]),
            ),
            (
                "active_spatial_receivers".into(),
                f64::from(self.active_spatial_receivers),
            ),
            ("lod_probes_0".into(), f64::from(self.probes_per_level[0])),
            ("lod_probes_1".into(), f64::from(self.probes_per_level[1])),
            ("lod_probes_2".into(), f64::from(self.probes_per_level[2])),
            ("lod_probes_3".into(), f64::from(self.probes_per_level[3])),
            ("lod_receivers".into(), self.work.receivers.len() as f64),
            ("lod_level_texels".into(), self.work.texels.len() as f64),
        ])
    }

    fn preparation(&self) -> Option<Preparation> {
        let how = match &self.origin {
            Origin::Cached => "read the bake".to_string(),
            Origin::Computed(None) => "baked".to_string(),
            Origin::Computed(Some(why)) => format!("baked again ({why})"),
        };
        Some(Preparation {
            summary: format!(
                "irradiance probes: {how}, {} probes, {} receivers, {} clusters, in {:.0} ms",
                self.report.probes, self.report.receivers, self.report.clusters, self.prepare_ms
            ),
            passes: Vec::new(),
        })
    }

    fn debug_views(&self) -> &'static [DebugView] {
        &DEBUG_VIEWS
    }

    fn debug_levels(&self) -> u32 {
        0
    }

    fn switches(&mut self) -> Vec<Switch<'_>> {
        vec![Switch {
            name: "level of detail",
            key: 'l',
            on: &mut self.lod_on,
        }]
    }
}
