//! The cone tracer's command-line options, flattened into every command's.

use anyhow::{bail, Result};
use clap::Args;

use super::octree::check_depth;
use super::voxelize::Voxelizer;
use super::{
    check_voxel_size, check_voxels, ConeSettings, DirectionalFilter, Quality, Resolution, Store,
    VctSettings, DEFAULT_SAMPLED_EMITTERS, EMITTER_PIECES, LATTICE_CONES,
};
use crate::scene::GiOverrides;

#[derive(Args, Debug, Clone, Default)]
pub struct VctArgs {
    /// The defaults of the settings not given: fast, for frames in real time (the ring of
    /// --diffuse-cones; 64 voxels per axis on a CPU driver), or accurate, for one image
    /// (the lattice of 72 cones, whose error falls as the voxels get finer, at the most
    /// voxels the device's memory holds, up to 256 per axis; the ring where an option of
    /// the ring is given: --diffuse-cones, --cosine-cones, --snapped-cones, the steps'
    /// factors, --cone); also the shadow maps' texels (--shadow-res, --sun-shadow-res),
    /// and on a CPU driver whether textures are filtered anisotropically (accurate) or
    /// trilinearly (fast: about half of a textured scene's frame there)
    /// [default: accurate for render, fast for view and bench].
    #[arg(long, value_enum)]
    pub quality: Option<Quality>,
    /// Voxels per axis of the dense grid, a power of two from 4 to 1024 [default: the scene
    /// file's [gi] voxels, else by the device: 64 on a CPU driver, 256 on a GPU (fewer
    /// where its memory is short, or where --voxel-size asks for larger voxels)].
    #[arg(long, conflicts_with = "voxel_size")]
    pub voxels: Option<u32>,
    /// The largest voxel wanted, in scene units: the grid takes the least power of two
    /// voxels per axis whose voxels are no larger, from 64 to the device's default
    /// (--voxels).
    #[arg(long, value_parser = crate::cli::parse_finite)]
    pub voxel_size: Option<f32>,
    /// Levels of the sparse voxel octree (--gi octree), 6 to 10: an effective grid of
    /// 2^depth voxels per axis [default: log2 of --voxels, or of the device's default
    /// resolution].
    #[arg(long)]
    pub octree_depth: Option<u32>,
    /// Full aperture of each diffuse cone, degrees, 1 to 179 [default: 60].
    #[arg(long, value_parser = crate::cli::parse_finite)]
    pub diffuse_aperture: Option<f32>,
    /// Step of the cones gathering light for the pixels (diffuse, specular, refraction)
    /// as a fraction of the cone's diameter (beta), 0.05 to 2; not with --snapped-cones,
    /// whose cones march from cell to cell [default: 0.25].
    #[arg(long, value_parser = crate::cli::parse_finite)]
    pub step_factor: Option<f32>,
    /// Step of the voxel bounce's diffuse cones as a fraction of the cone's diameter,
    /// 0.05 to 2; not with --snapped-cones [default: 0.5].
    #[arg(long, value_parser = crate::cli::parse_finite)]
    pub bounce_step_factor: Option<f32>,
    /// Step of the soft-shadow cones as a fraction of the cone's diameter, 0.05 to 2
    /// [default: 0.5].
    #[arg(long, value_parser = crate::cli::parse_finite)]
    pub shadow_step_factor: Option<f32>,
    /// Step the diffuse cones level by level, each sample twice as far and wide as the
    /// last (Dřínovský's sampling of wide cones), instead of by the step factor; not
    /// with --snapped-cones.
    #[arg(long)]
    pub wide_steps_by_level: bool,
    /// Weight the diffuse gather's cones by the cosine: each ring cone's sub-cones by the
    /// cosine of their axis to the normal, each cone by its region's share of the
    /// cosine-weighted hemisphere (the cone along the normal its cap's, sin² of the half
    /// aperture; the ring the rest), and the path tracer's cone component (--cone) by the
    /// cosine too. Off: each cone's plain mean, weighted 1 along the normal and 1/2 in the
    /// ring.
    #[arg(long)]
    pub cosine_cones: bool,
    /// Read each directional volume snapped to its cell along the volume's axis (the cell
    /// whole along the way the cone crosses it, trilinear across it), in cells half the
    /// cone's diameter; keep the ring cones' lookups clear of their own surface (cells at
    /// most a third of the height above it, samples at least 1.5 coarser cells above
    /// it); trace the cone along the normal as four sub-cones. Off: the trilinear lookups
    /// in cells as wide as the cone, tuned at 64³.
    #[arg(long)]
    pub snapped_cones: bool,
    /// Diffuse cones per gather, 1 to 16: one along the normal, the rest in a ring at 57.5
    /// degrees, each traced on screen as narrower sub-cones [default: 6].
    #[arg(long)]
    pub diffuse_cones: Option<u32>,
    /// Gather the pixels' diffuse light with N narrow cones spread evenly over the
    /// cosine-weighted hemisphere (a Fibonacci lattice), 32 to 256 (0: off), each counting 1/N,
    /// instead of the ring of --diffuse-cones (the voxel bounce keeps the ring); implies
    /// --snapped-cones, and 72 keeps a closed room closed. The image converges as the
    /// voxels get finer, at about 4.5 times the default cone_trace on lavapipe [default: off].
    #[arg(long)]
    pub lattice_cones: Option<u32>,
    /// Trace the cones (indirect light, soft shadows, specular, refraction) on one pixel of
    /// each NxN block and upsample, 1 to 8
    /// [default: height / 64, 2 to 8: 4 at 256 rows, 8 at 512 and above].
    #[arg(long)]
    pub indirect_scale: Option<u32>,
    /// Recompute every bounce every frame, instead of adding one bounce per frame to the
    /// last frame's light (the first frame always computes them all).
    #[arg(long)]
    pub no_accumulate: bool,
    /// Light bounces between voxels, 1 to 64 (1: direct light on the voxels only)
    /// [default: 8 for frames; for one image (`render`) as many as leave under 1 % of the
    /// light untraced, at the rate the camera's diffuse walks measure].
    #[arg(long)]
    pub bounces: Option<u32>,
    /// Shadow the direct light with soft-shadow cones through the voxels instead of with
    /// shadow maps (needs --gi dense or --gi octree).
    #[arg(long)]
    pub shadow_cones: bool,
    /// Full aperture of the soft-shadow cones, degrees, 0.1 to 90: the apparent size of
    /// the lights [default: 4].
    #[arg(long, value_parser = crate::cli::parse_finite)]
    pub shadow_aperture: Option<f32>,
    /// Ambient occlusion: occluders this many voxels away occlude half as much, 0.1 to
    /// 1024 [default: 4].
    #[arg(long, value_parser = crate::cli::parse_finite)]
    pub ao_distance: Option<f32>,
    /// Re-voxelize and re-shade the static geometry every frame too (for benchmarks);
    /// by default static geometry is voxelized once and only moving meshes every frame.
    #[arg(long)]
    pub full_update: bool,
    /// The most emissive triangles whose light is sampled, 0 to 1024: each shaded point adds
    /// their exact irradiance times a soft-shadow cone's visibility, and their emission is
    /// left out of the voxels. Only static, untextured, opaque emitters, and only where the
    /// scene has at most this many triangles of them; the others' light, and every
    /// emitter's with 0, is gathered through the voxels [default: 64].
    #[arg(long)]
    pub sampled_emitters: Option<u32>,
    /// The pieces the sampled emitters are cut into, 1 to 256, each with its own
    /// soft-shadow cone, so that an emitter's shadows have penumbrae: the longest piece is
    /// halved until there are this many or none is longer than a voxel [default: 8 where
    /// --quality is accurate, else 1]
    #[arg(long)]
    pub emitter_pieces: Option<u32>,
    /// How the scene is voxelized (both cover the same voxels)
    #[arg(long, value_enum, default_value_t)]
    pub voxelizer: Voxelizer,
    /// How the dense grid's directional levels are filtered from the voxels
    #[arg(long, value_enum, default_value_t)]
    pub directional_filter: DirectionalFilter,
    /// Composite every cell's opacity as uncorrelated with the cells before it. By default,
    /// where the cones are snapped (the lattice, --snapped-cones) and the directional
    /// levels filtered by pairs, each cell keeps its surface plane and a cone counts a
    /// plane it runs beside as the same rays from cell to cell (correlated occlusion)
    #[arg(long)]
    pub no_plane_occlusion: bool,
}

impl VctArgs {
    /// The options given that only the cone tracer reads, as their flags.
    pub fn given(&self) -> Vec<&'static str> {
        [
            (self.quality.is_some(), "--quality"),
            (self.shadow_cones, "--shadow-cones"),
            (self.full_update, "--full-update"),
            (self.voxels.is_some(), "--voxels"),
            (self.voxel_size.is_some(), "--voxel-size"),
            (self.octree_depth.is_some(), "--octree-depth"),
            (self.diffuse_aperture.is_some(), "--diffuse-aperture"),
            (self.step_factor.is_some(), "--step-factor"),
            (self.bounce_step_factor.is_some(), "--bounce-step-factor"),
            (self.shadow_step_factor.is_some(), "--shadow-step-factor"),
            (self.wide_steps_by_level, "--wide-steps-by-level"),
            (self.cosine_cones, "--cosine-cones"),
            (self.snapped_cones, "--snapped-cones"),
            (self.diffuse_cones.is_some(), "--diffuse-cones"),
            (self.lattice_cones.is_some(), "--lattice-cones"),
            (self.indirect_scale.is_some(), "--indirect-scale"),
            (self.no_accumulate, "--no-accumulate"),
            (self.bounces.is_some(), "--bounces"),
            (self.shadow_aperture.is_some(), "--shadow-aperture"),
            (self.ao_distance.is_some(), "--ao-distance"),
            (self.voxelizer != Voxelizer::Auto, "--voxelizer"),
            (
                self.directional_filter != DirectionalFilter::Pairs,
                "--directional-filter",
            ),
            (self.sampled_emitters.is_some(), "--sampled-emitters"),
            (self.emitter_pieces.is_some(), "--emitter-pieces"),
            (self.no_plane_occlusion, "--no-plane-occlusion"),
        ]
        .into_iter()
        .filter_map(|(set, flag)| set.then_some(flag))
        .collect()
    }

    /// The cone tracer's settings in `store` (`octree`: the octree, else the dense grid):
    /// the command line over the scene file's `[gi]` over the defaults.
    /// Drops the options that snapped cones (`snapped`) and the lattice (`lattice`) would
    /// ignore and so refuse (`settings`): the settings panel switching the layout, which
    /// must not be left with a refusal its sliders cannot undo.
    pub fn drop_ignored_by(&mut self, snapped: bool, lattice: bool) {
        if snapped || lattice {
            self.step_factor = None;
            self.bounce_step_factor = None;
            self.wide_steps_by_level = false;
        }
        if lattice {
            self.diffuse_cones = None;
            self.cosine_cones = false;
        }
    }

    /// `quality` gives the defaults; `ring` says an option outside these (`--cone`) picks
    /// a cone of the ring.
    pub fn settings(
        &self,
        octree: bool,
        scene: &GiOverrides,
        quality: Quality,
        ring: bool,
    ) -> Result<VctSettings> {
        let d = ConeSettings::default();
        // The ring's layout and the trilinear cones' steps, each option given or not.
        let layout = [
            (
                self.diffuse_cones.or(scene.diffuse_cones).is_some(),
                "--diffuse-cones / diffuse_cones",
            ),
            (
                self.cosine_cones || scene.cosine_cones == Some(true),
                "--cosine-cones / cosine_cones",
            ),
        ];
        let steps = [
            (
                self.step_factor.or(scene.step_factor).is_some(),
                "--step-factor / step_factor",
            ),
            (
                self.bounce_step_factor
                    .or(scene.bounce_step_factor)
                    .is_some(),
                "--bounce-step-factor / bounce_step_factor",
            ),
            (
                self.wide_steps_by_level || scene.wide_steps_by_level == Some(true),
                "--wide-steps-by-level / wide_steps_by_level",
            ),
        ];
        let snapped_given = self.snapped_cones || scene.snapped_cones == Some(true);
        // The ring's own options keep the ring where the quality's default is the lattice:
        // they say which ring is wanted.
        let ring = ring || snapped_given || layout.iter().chain(&steps).any(|(set, _)| *set);
        let lattice_cones = self
            .lattice_cones
            .or(scene.lattice_cones)
            .unwrap_or(match quality {
                Quality::Accurate if !ring => LATTICE_CONES,
                _ => d.lattice_cones,
            });
        // The lattice replaces the ring: its layout's options would be ignored.
        if let Some((_, option)) = layout.iter().find(|(set, _)| lattice_cones != 0 && *set) {
            bail!("{option} sets the ring of cones: --lattice-cones / lattice_cones replaces it");
        }
        let snapped_cones = self.snapped_cones
            || scene.snapped_cones.unwrap_or(d.snapped_cones)
            || lattice_cones > 0;
        // Snapped cones march from cell to cell (cones.glsl, march_cells): the steps'
        // options would be ignored.
        if let Some((_, option)) = steps.iter().find(|(set, _)| snapped_cones && *set) {
            bail!(
                "{option} sets the steps of the trilinear cones: snapped cones (--snapped-cones, \
                 --lattice-cones) march from cell to cell"
            );
        }
        let cones = ConeSettings {
            bounces: self.bounces.or(scene.bounces).unwrap_or(d.bounces),
            indirect_scale: self.indirect_scale.or(scene.indirect_scale),
            diffuse_cones: self
                .diffuse_cones
                .or(scene.diffuse_cones)
                .unwrap_or(d.diffuse_cones),
            diffuse_aperture_deg: self
                .diffuse_aperture
                .or(scene.diffuse_aperture_deg)
                .unwrap_or(d.diffuse_aperture_deg),
            step_factor: self
                .step_factor
                .or(scene.step_factor)
                .unwrap_or(d.step_factor),
            bounce_step_factor: self
                .bounce_step_factor
                .or(scene.bounce_step_factor)
                .unwrap_or(d.bounce_step_factor),
            shadow_step_factor: self
                .shadow_step_factor
                .or(scene.shadow_step_factor)
                .unwrap_or(d.shadow_step_factor),
            wide_steps_by_level: self.wide_steps_by_level
                || scene.wide_steps_by_level.unwrap_or(d.wide_steps_by_level),
            cosine_cones: self.cosine_cones || scene.cosine_cones.unwrap_or(d.cosine_cones),
            snapped_cones,
            lattice_cones,
            accumulate_bounces: !self.no_accumulate,
            shadow_aperture_deg: self
                .shadow_aperture
                .or(scene.shadow_aperture_deg)
                .unwrap_or(d.shadow_aperture_deg),
            ao_distance_voxels: self
                .ao_distance
                .or(scene.ao_distance_voxels)
                .unwrap_or(d.ao_distance_voxels),
            only_cone: None,
        };
        cones.check()?;
        if scene.voxels.is_some() && scene.voxel_size.is_some() {
            bail!("the scene file's [gi] gives both voxels and voxel_size: keep one");
        }
        // The command line over the scene file, a count or a size alike.
        let voxels = match (self.voxels, self.voxel_size) {
            (Some(count), _) => Resolution::Count(count),
            (None, Some(size)) => Resolution::Auto {
                size: Some(size),
                quality,
            },
            (None, None) => match scene.voxels {
                Some(count) => Resolution::Count(count),
                None => Resolution::Auto {
                    size: scene.voxel_size,
                    quality,
                },
            },
        };
        if let Resolution::Auto {
            size: Some(size), ..
        } = voxels
        {
            check_voxel_size(size)?;
        }
        let filter = self.directional_filter;
        // The planes are filtered by pairs, and only the snapped cones' march reads them
        // (cones.glsl, plane_increment).
        let planes =
            !self.no_plane_occlusion && filter == DirectionalFilter::Pairs && cones.snapped_cones;
        let store = match (octree, filter) {
            (true, DirectionalFilter::Pairs) => Store::Octree {
                capacities: None,
                planes,
            },
            // The octree's bricks are filtered from their children's bricks, which keep no
            // rows (BENCHMARKS.md, session 37).
            (true, DirectionalFilter::Rows) => {
                bail!(
                    "--directional-filter rows needs --gi dense: the octree filters by pairs only"
                )
            }
            (false, filter) => Store::Dense { filter, planes },
        };
        let voxels = match (octree, self.octree_depth, voxels) {
            (true, Some(depth), _) => {
                check_depth(depth)?;
                Resolution::Count(1 << depth)
            }
            (true, None, Resolution::Count(count)) => {
                check_depth(count.trailing_zeros())?;
                Resolution::Count(count)
            }
            (_, _, voxels) => voxels,
        };
        if let Resolution::Count(count) = voxels {
            check_voxels(count)?;
        }
        let sampled_emitters = self
            .sampled_emitters
            .or(scene.sampled_emitters)
            .unwrap_or(DEFAULT_SAMPLED_EMITTERS);
        if sampled_emitters > 1024 {
            bail!("--sampled-emitters / sampled_emitters must be at most 1024, got {sampled_emitters}");
        }
        let emitter_pieces =
            self.emitter_pieces
                .or(scene.emitter_pieces)
                .unwrap_or(match quality {
                    Quality::Accurate => EMITTER_PIECES,
                    Quality::Fast => 1,
                });
        if !(1..=256).contains(&emitter_pieces) {
            bail!(
                "--emitter-pieces / emitter_pieces must be between 1 and 256, got {emitter_pieces}"
            );
        }
        Ok(VctSettings {
            voxels,
            store,
            cones,
            converge_bounces: quality == Quality::Accurate
                && self.bounces.or(scene.bounces).is_none(),
            shadow_cones: self.shadow_cones || scene.shadow_cones.unwrap_or(false),
            full_update: self.full_update,
            voxelizer: self.voxelizer,
            sampled_emitters,
            emitter_pieces,
        })
    }
}
