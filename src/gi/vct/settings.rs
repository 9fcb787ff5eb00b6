//! The voxel cone tracer's settings: the voxels, the store that holds them, the cones.

use anyhow::{bail, Result};

use super::octree::Capacities;
use super::voxelize::Voxelizer;

/// Which structure holds the voxels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Store {
    /// A dense grid in 3D textures (`--gi dense`).
    Dense,
    /// A sparse voxel octree of the same effective resolution (`--gi octree`).
    Octree {
        /// Pool sizes to start from instead of the estimate from the scene.
        capacities: Option<Capacities>,
    },
}

/// Voxel cone tracing.
#[derive(Clone, Copy, Debug)]
pub struct VctSettings {
    /// Voxels per axis (a power of two): of the dense grid, or effective of the octree.
    pub voxels: u32,
    pub store: Store,
    pub cones: ConeSettings,
    /// Direct light shadowed by soft-shadow cones through the voxels instead of by the
    /// shadow maps (which still light the voxels).
    pub shadow_cones: bool,
    /// Re-voxelize and re-shade the static geometry every frame too (benchmarks).
    pub full_update: bool,
    pub voxelizer: Voxelizer,
    /// The most emissive triangles whose light is sampled rather than gathered through the
    /// voxels (`emitters`); 0 gathers every emitter's.
    pub sampled_emitters: u32,
}

/// `VctSettings::sampled_emitters` unless the command line or the scene file says otherwise.
pub const DEFAULT_SAMPLED_EMITTERS: u32 = 64;

impl VctSettings {
    /// Default cones at `voxels` per axis in `store`.
    pub fn new(voxels: u32, store: Store) -> Self {
        Self {
            voxels,
            store,
            cones: ConeSettings::default(),
            shadow_cones: false,
            full_update: false,
            voxelizer: Voxelizer::default(),
            sampled_emitters: DEFAULT_SAMPLED_EMITTERS,
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
    /// Light bounces between voxels: 1 is direct light on the voxels only.
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
            (self.bounces, 1, 8, "--bounces / bounces"),
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

/// Voxels per axis unless the command line or the scene file says otherwise.
pub const DEFAULT_VOXELS: u32 = 64;

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
            bounces: 8,
            indirect_scale: None,
            accumulate_bounces: true,
            shadow_aperture_deg: 4.0,
            ao_distance_voxels: 4.0,
            only_cone: None,
        }
    }
}
