//! The voxel cone tracer's settings: the voxels, the store that holds them, the cones.

use anyhow::{bail, Result};

use super::octree::Capacities;
use super::voxelize::Voxelizer;
use super::Grid;
use crate::gi::bounces::MAX_BOUNCES;
use crate::gpu_layout as layout;
use crate::scene::Scene;
use crate::vk::Context;

/// Which structure holds the voxels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Store {
    /// A dense grid in 3D textures (`--gi dense`).
    Dense {
        /// How its directional levels are filtered.
        filter: DirectionalFilter,
        /// Whether the filter keeps each cell's surface plane, which the snapped cones
        /// count as the same rays from cell to cell (the default where the cones are
        /// snapped; `--no-plane-occlusion`).
        planes: bool,
    },
    /// A sparse voxel octree of the same effective resolution (`--gi octree`).
    Octree {
        /// Pool sizes to start from instead of the estimate from the scene.
        capacities: Option<Capacities>,
        /// Whether the interior bricks keep each cell's surface plane, as the dense grid's
        /// `planes`.
        planes: bool,
    },
}

impl Store {
    /// Whether the store keeps each cell's surface plane (the default where the cones are
    /// snapped; `--no-plane-occlusion`).
    pub fn planes(self) -> bool {
        match self {
            Self::Dense { planes, .. } | Self::Octree { planes, .. } => planes,
        }
    }

    /// The volumes of its directional levels, side by side along x
    /// (`layout::DIRECTIONAL_SLOTS`).
    pub fn directional_slots(self) -> u32 {
        layout::DIRECTIONAL_SLOTS
            + if self.planes() {
                layout::PLANE_SLOTS
            } else {
                0
            }
    }
}

/// How each directional level's cells are filtered from the voxels below them
/// (`--directional-filter`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum DirectionalFilter {
    /// From the level below, its 2x2x2 children composited in pairs along the axis and
    /// the pairs averaged (Crassin 2011): as if what lies behind were uncorrelated with
    /// what lies in front, so a surface seen edge-on comes out more opaque than its voxels
    #[default]
    Pairs,
    /// Every row of voxels along the axis composited whole, then the rows averaged: what
    /// rays along the axis see of the voxels. The dense grid only
    Rows,
}

/// Which defaults the cone tracer takes where neither the command line nor the scene file
/// gives a setting (`--quality`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Quality {
    /// For frames in real time (`view` and `bench`): the ring of `--diffuse-cones`, 64³
    /// on a CPU driver (`CPU_VOXELS`), whole sampled emitters
    Fast,
    /// For one image (`render`): the lattice of 72 cones (`LATTICE_CONES`), whose error
    /// falls as the voxels get finer, at the most voxels the device's memory holds (up to
    /// 256³, `MOST_VOXELS`), on a CPU driver too, the sampled emitters cut into 8 pieces
    /// (`EMITTER_PIECES`). The ring's options (`--diffuse-cones`,
    /// `--cosine-cones`, `--snapped-cones`, the steps' factors, `--cone`) keep the ring
    Accurate,
}

/// Voxels per axis (a power of two): of the dense grid, or effective of the octree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Resolution {
    /// As given: `--voxels`, `--octree-depth` or the scene file's `voxels`.
    Count(u32),
    /// From the device, the scene and the quality ([`auto_voxels`]); `size` is
    /// `--voxel-size` or the scene file's `voxel_size`, the largest voxel wanted, in scene
    /// units.
    Auto { size: Option<f32>, quality: Quality },
}

impl Resolution {
    /// The count, the rule applied for the device, the scene and the `settings` (their
    /// cones, and whether the grid keeps the static sums) if it was not given.
    pub fn on(self, ctx: &Context, scene: &Scene, settings: &VctSettings) -> u32 {
        let cones = &settings.cones;
        match self {
            Self::Count(count) => count,
            Self::Auto { size, quality } => {
                // The frame rate bounds the voxels on a CPU driver in real time only.
                let memory = (!ctx.is_cpu() || quality == Quality::Accurate)
                    .then(|| ctx.device_local_bytes());
                let extent = Grid::extent_around(scene);
                let bytes =
                    dense_bytes_per_voxel(dense_keeps_static_sums(scene, settings.full_update));
                let count = auto_voxels(memory, bytes, extent, size, cones.snapped_cones);
                let device = match (ctx.is_cpu(), quality) {
                    (false, _) => "a GPU",
                    (true, Quality::Fast) => "a CPU driver in real time",
                    (true, Quality::Accurate) => "a CPU driver, for one image",
                };
                let voxel = extent / count as f32;
                let why = match size {
                    Some(size) => format!("voxels of at most {size} wanted, on {device}"),
                    None if cones.snapped_cones => format!("the most on {device}"),
                    None => "the ring of cones' resolution".to_owned(),
                };
                log::info!("voxels: {count}³ of {voxel} scene units ({why})");
                if let Some(size) = size.filter(|&size| voxel > size) {
                    log::warn!(
                        "voxels of at most {size} wanted, but {count}³ is the most the default \
                         gives on {device}: --voxels sets more"
                    );
                }
                count
            }
        }
    }

    /// The count, once given or resolved by [`Resolution::on`].
    pub fn count(self) -> Option<u32> {
        match self {
            Self::Count(count) => Some(count),
            Self::Auto { .. } => None,
        }
    }
}

/// The rule's resolution on a CPU driver: lavapipe's speed case takes 300 to 360 ms of its
/// 400 at 64³, and 2.6 times that at 128³ (BENCHMARKS.md, "The default resolution").
/// Also the rule's least: the cones' settings are tuned and tested at 64³.
pub const CPU_VOXELS: u32 = 64;

/// The lattice gather's cone count that the viewer's panel offers (`--lattice-cones`):
/// the fewest whose cones near the normal are no wider than 17 degrees, as the sub-cones
/// that keep a closed room closed (48 cones, 21 degrees, let a tenth of its light out;
/// BENCHMARKS.md, session 34).
pub const LATTICE_CONES: u32 = 72;
/// The rule's most where the frame rate does not bound it (a GPU, or one image): 256³ keeps
/// the dense grid's whole update, every frame, within 3 ms on an H100 (Sponza, 1.72 ms),
/// and renders a reference scene in 27 to 86 s on lavapipe with the lattice; 512³ has
/// eight times the voxels and 16 GiB of grid.
pub const MOST_VOXELS: u32 = 256;
/// The dense grid's bytes per voxel: volumes, their mips and the fragment sums (`bench`'s
/// `memory_mib`; 1376 MiB at 256³ before the voxels' coverage, session 47, which adds 4
/// bytes and 16 to the sums: 1696 MiB).
const BYTES_PER_VOXEL: u64 = 106;
/// The static meshes' copy of the fragment sums ([`dense_keeps_static_sums`]).
const STATIC_SUMS_BYTES_PER_VOXEL: u64 = 56;

/// The dense grid keeps the static meshes' fragment sums apart, and voxelizes only the
/// moving meshes every frame, when the scene has moving meshes and not every frame
/// re-voxelizes everything (`full_update`).
pub fn dense_keeps_static_sums(scene: &Scene, full_update: bool) -> bool {
    scene.has_moving_meshes() && !full_update
}

/// The dense grid's bytes per voxel, with or without the copy of the `static_sums`
/// ([`dense_keeps_static_sums`]).
pub fn dense_bytes_per_voxel(static_sums: bool) -> u64 {
    BYTES_PER_VOXEL + u64::from(static_sums) * STATIC_SUMS_BYTES_PER_VOXEL
}

/// Voxels per axis when none are given.
/// - The device sets the most: [`CPU_VOXELS`] on a CPU driver in real time (`memory` is
///   `None`); on a GPU, or for one image ([`Quality::Accurate`]), [`MOST_VOXELS`], halved
///   while the grid, of `bytes_per_voxel` ([`dense_bytes_per_voxel`]), would take more
///   than a quarter of the device-local `memory` (bytes).
/// - A wanted voxel `size` (in the units of the scene's `extent`) takes the least power of
///   two whose voxels are no larger, from [`CPU_VOXELS`] to that most.
/// - Without one, the most where finer voxels give a better image (`finer_helps`: the
///   snapped cones, whose error falls from 64³ to 256³ on four of the five references),
///   else [`CPU_VOXELS`]: the default cones are tuned there, and three of the five
///   references get worse at 256³ (BENCHMARKS.md, "The default resolution").
pub fn auto_voxels(
    memory: Option<u64>,
    bytes_per_voxel: u64,
    extent: f32,
    size: Option<f32>,
    finer_helps: bool,
) -> u32 {
    let most = match memory {
        None => CPU_VOXELS,
        Some(bytes) => {
            let mut most = MOST_VOXELS;
            while most > CPU_VOXELS && u64::from(most).pow(3) * bytes_per_voxel > bytes / 4 {
                most /= 2;
            }
            most
        }
    };
    match size {
        // The quotient is finite and positive (both are checked), so the cast saturates at
        // worst, and the clamp bounds it.
        Some(size) => ((extent / size).ceil() as u32)
            .checked_next_power_of_two()
            .unwrap_or(u32::MAX)
            .clamp(CPU_VOXELS, most),
        None if finer_helps => most,
        None => CPU_VOXELS,
    }
}

/// Checks a wanted voxel size.
pub fn check_voxel_size(size: f32) -> Result<()> {
    if !(size.is_finite() && size > 0.0) {
        bail!("--voxel-size / voxel_size must be a positive length in scene units, got {size}");
    }
    Ok(())
}

/// Voxel cone tracing.
#[derive(Clone, Copy, Debug)]
pub struct VctSettings {
    pub voxels: Resolution,
    pub store: Store,
    pub cones: ConeSettings,
    /// One image without a given count: `cones.bounces` becomes
    /// [`crate::gi::bounces::bounces_for`] the scene ([`crate::gi::GiSettings::on`]).
    pub converge_bounces: bool,
    /// Direct light shadowed by soft-shadow cones through the voxels instead of by the
    /// shadow maps (which still light the voxels).
    pub shadow_cones: bool,
    /// Re-voxelize and re-shade the static geometry every frame too (benchmarks).
    pub full_update: bool,
    pub voxelizer: Voxelizer,
    /// The most emissive triangles whose light is sampled rather than gathered through the
    /// voxels (`emitters`); 0 gathers every emitter's.
    pub sampled_emitters: u32,
    /// The pieces the sampled emitters are cut into, each with its own visibility cone
    /// (`emitters::sampled_emitters`).
    pub emitter_pieces: u32,
}

/// `VctSettings::emitter_pieces` for one image ([`Quality::Accurate`]) unless the command
/// line or the scene file says otherwise. On a floor under a block lit by a square
/// emitter, at 128³, the light in view is 0.24 of the path tracer's with one piece and
/// 0.79 with four to 256 (the rest is the block's voxels, whose shadow was 1.4 voxels too
/// wide; 0.44 and 0.90 with one and eight pieces since the narrow cones read the voxels'
/// coverage, session 47); more pieces spread it better over the penumbra (32x32 blocks
/// off by 0.38, 0.33 and 0.29 on average with 4, 8 and 16). Eight: sixteen spread it a
/// little better for twice the cones, and `cornell_area`'s emitter light per block barely
/// moves (off by 0.087 with one piece, 0.072 with eight, 0.070 with sixteen; BENCHMARKS.md,
/// session 46). Frames keep one: each piece costs every traced point a cone.
pub const EMITTER_PIECES: u32 = 8;

/// `VctSettings::sampled_emitters` unless the command line or the scene file says otherwise.
pub const DEFAULT_SAMPLED_EMITTERS: u32 = 64;

impl VctSettings {
    /// Default cones at `voxels` per axis in `store`.
    pub fn new(voxels: u32, store: Store) -> Self {
        Self {
            voxels: Resolution::Count(voxels),
            store,
            cones: ConeSettings::default(),
            converge_bounces: false,
            shadow_cones: false,
            full_update: false,
            voxelizer: Voxelizer::default(),
            sampled_emitters: DEFAULT_SAMPLED_EMITTERS,
            emitter_pieces: 1,
        }
    }
}

/// Cone settings.
#[derive(Clone, Copy, Debug)]
pub struct ConeSettings {
    /// Full aperture of the diffuse cones, degrees.
    pub diffuse_aperture_deg: f32,
    /// Number of diffuse cones: one along the normal, the rest in a ring at 57.5 degrees.
    pub diffuse_cones: u32,
    /// Step length of the cones gathering light for the pixels (diffuse, specular,
    /// refraction) as a fraction of the cone diameter (beta).
    pub step_factor: f32,
    /// Step length of the voxel bounce's diffuse cones, as a fraction of the cone
    /// diameter.
    pub bounce_step_factor: f32,
    /// Step length of the soft-shadow cones, as a fraction of the cone diameter.
    pub shadow_step_factor: f32,
    /// The diffuse cones step level by level (each sample twice as far, so twice as wide)
    /// instead of by `step_factor` (or, in the voxel bounce, `bounce_step_factor`) of
    /// their diameter.
    pub wide_steps_by_level: bool,
    /// The diffuse gather weighs its cones by the cosine (`--cosine-cones`): the ring
    /// cones' sub-cones by their axes' cosine to the normal, each cone by its region's
    /// share of the cosine-weighted hemisphere. Off by default: the plain quadrature's
    /// errors still balance the tracer's (BENCHMARKS.md, session 28).
    pub cosine_cones: bool,
    /// The cones read the directional volumes snapped along each volume's axis
    /// (`--snapped-cones`): whole cells along the axis, trilinear across it, cells half the
    /// cone's diameter, the ring cones kept clear of their own surface and the cone along
    /// the normal traced as four sub-cones. Off by default: better on large rooms and as
    /// the voxels get finer, worse on the Cornell box at 64³ (BENCHMARKS.md, session 30).
    pub snapped_cones: bool,
    /// Cones of the lattice gather (`--lattice-cones`), 0 for the ring of `diffuse_cones`:
    /// this many narrow cones spread evenly over the cosine-weighted hemisphere, each
    /// counting alike, in the screen's gather (the voxel bounce keeps the ring). It reads
    /// the voxels as `snapped_cones` does (which it implies).
    pub lattice_cones: u32,
    /// Light bounces between voxels: 1 is direct light on the voxels only; for one image
    /// without a given count as many as converge
    /// ([`crate::gi::bounces::converged_bounces`]).
    pub bounces: u32,
    /// Indirect light is traced on one pixel of each `indirect_scale`² block and
    /// upsampled; `None` picks it from the image height ([`auto_indirect_scale`]).
    pub indirect_scale: Option<u32>,
    /// After the first frame, add one bounce per frame on top of the last frame's.
    pub accumulate_bounces: bool,
    /// Full aperture of the soft-shadow cones, degrees: the angular size of the lights.
    pub shadow_aperture_deg: f32,
    /// Ambient occlusion halves for occluders this many voxels away.
    pub ao_distance_voxels: f32,
    /// The one diffuse cone the screen's gather traces, its radiance alone (0 along the
    /// normal, 1.. the ring's): a component to compare with the path tracer's exact
    /// integral over the same cone (`--cone`).
    pub only_cone: Option<u32>,
}

impl ConeSettings {
    /// Checks every setting's range; errors name the command-line option and the scene
    /// file key.
    pub fn check(&self) -> Result<()> {
        let floats = [
            (
                self.diffuse_aperture_deg,
                1.0,
                179.0,
                "--diffuse-aperture / diffuse_aperture_deg",
            ),
            (self.step_factor, 0.05, 2.0, "--step-factor / step_factor"),
            (
                self.bounce_step_factor,
                0.05,
                2.0,
                "--bounce-step-factor / bounce_step_factor",
            ),
            (
                self.shadow_step_factor,
                0.05,
                2.0,
                "--shadow-step-factor / shadow_step_factor",
            ),
            (
                self.shadow_aperture_deg,
                0.1,
                90.0,
                "--shadow-aperture / shadow_aperture_deg",
            ),
            (
                self.ao_distance_voxels,
                0.1,
                1024.0,
                "--ao-distance / ao_distance_voxels",
            ),
        ];
        for (value, min, max, name) in floats {
            if !(min..=max).contains(&value) {
                bail!("{name} must be between {min} and {max}, got {value}");
            }
        }
        let counts = [
            (self.diffuse_cones, 1, 16, "--diffuse-cones / diffuse_cones"),
            (self.bounces, 1, MAX_BOUNCES, "--bounces / bounces"),
            (
                self.indirect_scale.unwrap_or(1),
                1,
                8,
                "--indirect-scale / indirect_scale",
            ),
        ];
        for (value, min, max, name) in counts {
            if !(min..=max).contains(&value) {
                bail!("{name} must be between {min} and {max}, got {value}");
            }
        }
        if self.lattice_cones != 0 && !(32..=256).contains(&self.lattice_cones) {
            bail!(
                "--lattice-cones / lattice_cones must be between 32 and 256, got {}",
                self.lattice_cones
            );
        }
        Ok(())
    }
}

/// The default reduction of the indirect light's resolution for an image `height` pixels
/// high: height / 64 (2 to 8), so that it is traced on 64 to 127 rows up to 511 rows and
/// at an eighth above (2 at 128 rows; 4 at 256; 8 at 512, where `render`'s 2x2 samples
/// measure the quality against the references, and at 720). Indirect diffuse light and
/// soft shadows vary at the scale of the voxels, not of the pixels: 8 and 4 score within
/// 0.002 of each other against the references at 512 rows (BENCHMARKS.md), and 8 keeps
/// the speed case within its budget.
pub fn auto_indirect_scale(height: u32) -> u32 {
    (height / 64).clamp(2, 8)
}

/// Checks a grid resolution.
pub fn check_voxels(resolution: u32) -> Result<()> {
    if !resolution.is_power_of_two() || !(4..=1024).contains(&resolution) {
        bail!("--voxels / voxels must be a power of two between 4 and 1024, got {resolution}");
    }
    Ok(())
}

impl Default for ConeSettings {
    fn default() -> Self {
        Self {
            diffuse_aperture_deg: 60.0,
            diffuse_cones: 6,
            step_factor: 0.25,
            bounce_step_factor: 0.5,
            shadow_step_factor: 0.5,
            wide_steps_by_level: false,
            cosine_cones: false,
            snapped_cones: false,
            lattice_cones: 0,
            bounces: 8,
            indirect_scale: None,
            accumulate_bounces: true,
            shadow_aperture_deg: 4.0,
            ao_distance_voxels: 4.0,
            only_cone: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GIB: u64 = 1 << 30;

    /// The rule: the device's most, fewer for a short memory or a large wanted voxel,
    /// never under the CPU's; 64³ for the default cones unless a size is wanted.
    #[test]
    fn default_resolution_follows_the_device_and_the_scene() {
        let (moving, still) = (dense_bytes_per_voxel(true), dense_bytes_per_voxel(false));
        // A CPU driver in real time: 64³ whatever the wanted size.
        assert_eq!(auto_voxels(None, moving, 10.0, None, true), CPU_VOXELS);
        assert_eq!(
            auto_voxels(None, moving, 10.0, Some(0.001), true),
            CPU_VOXELS
        );
        // A GPU, or one image, with 80 GiB: 256³ (2.5 GiB of grid with moving meshes); with
        // 4 GiB, a quarter is 1 GiB: 128³; with 8 GiB, 256³ without moving meshes (1.7 GiB)
        // and 128³ with them (2.5 GiB).
        assert_eq!(
            auto_voxels(Some(80 * GIB), moving, 10.0, None, true),
            MOST_VOXELS
        );
        assert_eq!(auto_voxels(Some(4 * GIB), moving, 10.0, None, true), 128);
        assert_eq!(auto_voxels(Some(8 * GIB), still, 10.0, None, true), 256);
        assert_eq!(auto_voxels(Some(8 * GIB), moving, 10.0, None, true), 128);
        assert_eq!(
            auto_voxels(Some(GIB / 4), moving, 10.0, None, true),
            CPU_VOXELS
        );
        // Without a wanted size the default cones keep 64³ on every device.
        assert_eq!(
            auto_voxels(Some(80 * GIB), moving, 10.0, None, false),
            CPU_VOXELS
        );
        // A wanted size: the least power of two whose voxels are no larger.
        assert_eq!(
            auto_voxels(Some(80 * GIB), moving, 10.0, Some(0.1), false),
            128
        );
        assert_eq!(
            auto_voxels(Some(80 * GIB), moving, 12.8, Some(0.1), false),
            128
        );
        assert_eq!(
            auto_voxels(Some(80 * GIB), moving, 12.81, Some(0.1), false),
            256
        );
        assert_eq!(
            auto_voxels(Some(80 * GIB), moving, 10.0, Some(5.0), false),
            CPU_VOXELS
        );
        assert_eq!(
            auto_voxels(Some(80 * GIB), moving, 1e30, Some(1e-30), false),
            MOST_VOXELS
        );
    }
}
