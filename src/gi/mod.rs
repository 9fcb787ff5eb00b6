//! Global illumination by voxel cone tracing (Crassin et al. 2011): on a dense voxel grid
//! held in 3D textures (`--gi dense`, as in Präntare 2016 and Villegas 2018), or on the
//! sparse voxel octree of `crate::svo` (`--gi svo`), which feeds the same passes.
//!
//! Per frame: voxelize (clear + rasterize into packed RGBA8 averages; the octree: built
//! once, or rebuilt around moving meshes) -> inject (voxel shading) -> filter
//! (anisotropic mips; the octree: its bricks bottom-up) -> bounces -> cone trace (after
//! the direct lighting).

mod compact;
pub(crate) use compact::reset_voxel_list;
mod cone_trace;
mod debug;
mod filter;
mod inject;
#[cfg(test)]
pub(crate) mod reference;
#[cfg(test)]
mod tests;
pub(crate) mod voxelize;

use std::sync::Arc;

use anyhow::{bail, Result};
use ash::vk;
use glam::Vec3;

use crate::gbuffer::GBuffer;
use crate::gpu_layout::{self as layout, GiUniforms, InjectPush};
use crate::renderer::GiSettings;
use crate::scene::{Aabb, Scene};
use crate::scene_gpu::{GpuScene, SceneDraw};
use crate::svo::{Capacities, SvoGi};
use crate::vk::{
    clear_to_zero, image_barrier, memory_barrier, read_back_image, sampler_info, Binding, Buffer,
    Context, DescriptorSets, GpuTimer, Image, ImageDesc, ImageUse, OneShot, Sampler, SetWriter,
};

/// The cube the voxels tile: voxel (i, j, k) covers origin + [i, i+1) x [j, j+1) x [k, k+1)
/// times `voxel_size`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    pub origin: Vec3,
    pub voxel_size: f32,
    pub resolution: u32,
}

impl Grid {
    /// Linear index of voxel (i, j, k): x fastest, then y, then z (the GPU's layout).
    pub fn index(&self, i: u32, j: u32, k: u32) -> usize {
        let n = self.resolution as usize;
        i as usize + n * (j as usize + n * k as usize)
    }

    /// A cube around the scene's bounds over all times (moving meshes never leave it),
    /// with a little room so that surfaces on the bounds are not cut by the grid's edge.
    pub fn around(scene: &Scene, resolution: u32) -> Self {
        let bounds = scene.swept_bounds();
        let size = (bounds.max - bounds.min).max_element().max(1e-3) * 1.04;
        Self {
            origin: bounds.center() - Vec3::splat(size * 0.5),
            voxel_size: size / resolution as f32,
            resolution,
        }
    }

    /// The voxels (first and last, each axis) that `bounds` touches, one more around
    /// (conservative voxelization dilates triangles by up to a voxel); `None` for empty
    /// bounds.
    pub fn voxels_of(&self, bounds: &Aabb) -> Option<[[i32; 3]; 2]> {
        if bounds.is_empty() {
            return None;
        }
        let voxel = |p: Vec3, extra: f32| {
            let v = ((p - self.origin) / self.voxel_size).floor() + Vec3::splat(extra);
            v.clamp(Vec3::splat(-2.0), Vec3::splat(self.resolution as f32 + 1.0))
                .as_ivec3()
                .to_array()
        };
        Some([voxel(bounds.min, -1.0), voxel(bounds.max, 1.0)])
    }
}

/// Moves new `images` into the layout compute passes write them in, and waits.
fn to_compute_write(ctx: &Arc<Context>, name: &str, images: &[&Image]) -> Result<()> {
    OneShot::new(ctx)?.run(name, |cmd| {
        for image in images {
            image_barrier(
                ctx,
                cmd,
                image.raw,
                image.full_range(),
                ImageUse::UNDEFINED,
                ImageUse::COMPUTE_WRITE,
            );
        }
        Ok(())
    })
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
/// soft shadows vary at the scale of the voxels, not of the pixels: at 512 rows LDR-FLIP
/// against the references is 0.0992 / 0.1414 / 0.0864 with 8 (Cornell / Sponza /
/// Sibenik) and 0.0990 / 0.1393 / 0.0848 with 4, and the speed case (`bench`, 720 rows,
/// nine cones) fits its budget.
pub fn auto_indirect_scale(height: u32) -> u32 {
    (height / 64).clamp(2, 8)
}

/// The scene's largest emitted radiance: voxels store emission divided by it, in RGBA8.
pub(crate) fn emission_range(scene: &Scene) -> f32 {
    scene
        .materials
        .iter()
        .map(|m| m.emission.max_element())
        .fold(0.0f32, f32::max)
        .max(1e-6)
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
            bounces: 8,
            indirect_scale: None,
            accumulate_bounces: true,
            shadow_aperture_deg: 4.0,
            ao_distance_voxels: 4.0,
        }
    }
}

/// The voxel volumes.
struct Volumes {
    albedo: Image,
    normal: Image,
    emission: Image,
    radiance: Image,
    /// Direct light only, the starting point of each bounce.
    direct: Image,
    /// The fragment sums the means in `albedo`, `normal` and `emission` are taken from
    /// (`BINDING_GI_SUMS`).
    sums: Image,
    /// The static meshes' fragment sums, kept to start each frame's voxelization of the
    /// moving meshes from (only when the scene has moving meshes and the static voxels
    /// are not re-voxelized every frame).
    static_sums: Option<Image>,
    /// +X -X +Y -Y +Z -Z side by side along x, each resolution / 2 down to 2 in its mip
    /// chain: one texture, so that a cone picks its volume by coordinate (descriptor
    /// arrays need constant indices on lavapipe, and branching over six textures costs
    /// twice as much). Each cube of edge w sits in a slot 2w wide, with w/2 texels on
    /// either side, so that one trilinear fetch blending two levels never reaches the
    /// next direction's cube ([`DIRECTIONAL_SLOT`]).
    directional: Image,
}

/// Width of a direction's slot in the directional texture, in cube edges: the cube in its
/// middle (`glsl/gi/sampling.glsl`, `glsl/gi/filter/filter.comp`).
const DIRECTIONAL_SLOT: u32 = 2;

/// Levels of the directional mip chain of an `n`³ grid: n/2 down to 2 (a single voxel
/// for the whole grid tells a cone nothing, and the octree has no such level either).
fn directional_levels(n: u32) -> u32 {
    n.trailing_zeros() - 1
}

const PACKED_FORMAT: vk::Format = vk::Format::R32_UINT;
/// The dense grid keeps the static meshes' fragment sums apart, and voxelizes only the
/// moving meshes every frame, when the scene has moving meshes and not every frame
/// re-voxelizes everything.
fn dense_keeps_static_sums(scene: &Scene, full_update: bool) -> bool {
    scene.has_moving_meshes() && !full_update
}
const RADIANCE_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;

impl Volumes {
    fn new(ctx: &Arc<Context>, n: u32, static_copies: bool) -> Result<Self> {
        // Every volume can be copied out, for the checks against the CPU twins.
        let packed_usage = vk::ImageUsageFlags::STORAGE
            | vk::ImageUsageFlags::TRANSFER_DST
            | vk::ImageUsageFlags::TRANSFER_SRC;
        let packed = |name| Image::new(ctx, name, ImageDesc::d3(PACKED_FORMAT, n, 1, packed_usage));
        let sums = |name| {
            let mut desc = ImageDesc::d3(PACKED_FORMAT, n, 1, packed_usage);
            // `sum_texel` in glsl/gi/sums.glsl.
            desc.extent.width = 2 * n;
            desc.extent.depth = layout::VOXEL_SUM_WORDS.div_ceil(2) * n;
            Image::new(ctx, name, desc)
        };
        // TRANSFER_DST: zeroed once, when created.
        let radiance_usage = vk::ImageUsageFlags::STORAGE
            | vk::ImageUsageFlags::SAMPLED
            | vk::ImageUsageFlags::TRANSFER_SRC
            | vk::ImageUsageFlags::TRANSFER_DST;
        let mut directional_desc = ImageDesc::d3(
            RADIANCE_FORMAT,
            n / 2,
            directional_levels(n),
            radiance_usage,
        );
        directional_desc.extent.width = 6 * DIRECTIONAL_SLOT * (n / 2);
        let directional = Image::new(ctx, "voxel radiance directional", directional_desc)?;
        let static_sums = static_copies
            .then(|| sums("static voxel sums"))
            .transpose()?;
        Ok(Self {
            static_sums,
            sums: sums("voxel sums")?,
            albedo: packed("voxel albedo")?,
            normal: packed("voxel normal")?,
            emission: packed("voxel emission")?,
            radiance: Image::new(
                ctx,
                "voxel radiance",
                ImageDesc::d3(RADIANCE_FORMAT, n, 1, radiance_usage),
            )?,
            direct: Image::new(
                ctx,
                "voxel direct",
                ImageDesc::d3(RADIANCE_FORMAT, n, 1, radiance_usage),
            )?,
            directional,
        })
    }

    fn bytes(&self) -> Vec<(&'static str, u64)> {
        vec![
            ("voxel_albedo", self.albedo.memory_bytes()),
            ("voxel_normal", self.normal.memory_bytes()),
            ("voxel_emission", self.emission.memory_bytes()),
            ("voxel_radiance", self.radiance.memory_bytes()),
            ("voxel_direct", self.direct.memory_bytes()),
            (
                "voxel_radiance_directional",
                self.directional.memory_bytes(),
            ),
            ("voxel_sums", self.sums.memory_bytes()),
            (
                "voxel_static_sums",
                self.static_sums.as_ref().map_or(0, Image::memory_bytes),
            ),
        ]
    }
}

/// What the cone tracer writes at reduced resolution and the upsample reads.
struct LowRes {
    /// Gathered indirect light (rgb) and ambient occlusion (a).
    indirect: Image,
    /// Soft-shadow cone visibility of every light (`BINDING_GI_SHADOW`).
    shadow: Image,
    /// Specular cone radiance (before Ks).
    specular: Image,
    /// Refraction cone radiance, and where it was traced.
    transmitted: Image,
}

/// The set-2 bindings every GI pass shares.
fn gi_bindings() -> Vec<Binding> {
    let all = vk::ShaderStageFlags::FRAGMENT
        | vk::ShaderStageFlags::COMPUTE
        | vk::ShaderStageFlags::GEOMETRY;
    let storage = vk::DescriptorType::STORAGE_IMAGE;
    let sampled = vk::DescriptorType::COMBINED_IMAGE_SAMPLER;
    let mut bindings = vec![
        Binding::new(
            layout::BINDING_GI_UNIFORMS,
            vk::DescriptorType::UNIFORM_BUFFER,
            all,
        ),
        Binding::new(layout::BINDING_GI_ALBEDO, storage, all),
        Binding::new(layout::BINDING_GI_NORMAL, storage, all),
        Binding::new(layout::BINDING_GI_EMISSION, storage, all),
        Binding::new(layout::BINDING_GI_RADIANCE, storage, all),
        Binding::new(layout::BINDING_GI_RADIANCE_SAMPLED, sampled, all),
        Binding::new(layout::BINDING_GI_DIRECTIONAL, sampled, all),
        Binding::new(layout::BINDING_GI_SCREEN, storage, all),
        Binding::new(layout::BINDING_GI_GBUFFER_ALBEDO, storage, all),
        Binding::new(layout::BINDING_GI_GBUFFER_NORMAL, storage, all),
        Binding::new(layout::BINDING_GI_GBUFFER_DEPTH, sampled, all),
        Binding::new(layout::BINDING_GI_DIRECT, storage, all),
        Binding::new(layout::BINDING_GI_INDIRECT, storage, all),
        Binding::new(layout::BINDING_GI_GBUFFER_TRANSMISSION, storage, all),
        Binding::new(layout::BINDING_GI_SHADOW, storage, all),
        Binding::new(layout::BINDING_GI_SPECULAR, storage, all),
        Binding::new(layout::BINDING_GI_GBUFFER_EMISSION, storage, all),
        Binding::new(layout::BINDING_GI_TRANSMITTED, storage, all),
        Binding::new(
            layout::BINDING_GI_VOXEL_LIST,
            vk::DescriptorType::STORAGE_BUFFER,
            all,
        ),
        Binding::new(layout::BINDING_GI_SUMS, storage, all),
        Binding::new(layout::BINDING_GI_STATIC_SUMS, storage, all),
    ];
    bindings.extend(voxelize::geometry_bindings());
    bindings
}

/// Adds to `writer` what the cones sample, through the `linear` sampler: the base level
/// `radiance` and the `directional` radiance, both kept in GENERAL layout (written as
/// storage, sampled by the cones). The dense grid and the octree bind theirs alike.
pub(crate) fn bind_cone_samples<'a>(
    writer: SetWriter<'a>,
    radiance: &Image,
    directional: &Image,
    linear: vk::Sampler,
) -> SetWriter<'a> {
    writer
        .sampled_image(
            layout::BINDING_GI_RADIANCE_SAMPLED,
            radiance.view,
            linear,
            vk::ImageLayout::GENERAL,
        )
        .sampled_image(
            layout::BINDING_GI_DIRECTIONAL,
            directional.view,
            linear,
            vk::ImageLayout::GENERAL,
        )
}

/// A global barrier between two compute passes: writes before are visible to reads and
/// writes after.
pub(crate) fn compute_to_compute(ctx: &Context, cmd: vk::CommandBuffer) {
    let compute = vk::PipelineStageFlags2::COMPUTE_SHADER;
    memory_barrier(
        ctx,
        cmd,
        (compute, vk::AccessFlags2::SHADER_WRITE),
        (
            compute,
            vk::AccessFlags2::SHADER_READ | vk::AccessFlags2::SHADER_WRITE,
        ),
    );
}

/// Which structure holds the voxels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum VoxelStructure {
    /// A dense grid in 3D textures.
    Dense,
    /// A sparse voxel octree (`crate::svo`) of the same effective resolution.
    Octree {
        /// Pool sizes to start from instead of the estimate from the scene.
        capacities: Option<Capacities>,
    },
}

/// The dense grid's volumes and the passes that fill them.
struct Dense {
    volumes: Volumes,
    voxelize: voxelize::VoxelizePass,
    compact: compact::CompactPass,
    filter: filter::FilterPass,
    /// Re-voxelize everything every frame.
    full_update: bool,
    /// The static meshes are in the voxels (or in `Volumes::static_sums`).
    static_ready: bool,
}

enum Voxels {
    Dense(Box<Dense>),
    Octree(Box<SvoGi>),
}

/// Voxel cone tracing: the voxels (a dense grid or an octree), their shading and
/// filtering, and the cones gathered per pixel.
pub struct VoxelGi {
    pub grid: Grid,
    voxels: Voxels,
    inject: inject::InjectPass,
    bounces: u32,
    accumulate_bounces: bool,
    /// The directional volumes hold last frame's result (with its bounces).
    history: bool,
    /// What voxel shading last ran with (`record_update`'s `lighting`).
    lighting: Option<Vec<u8>>,
    /// Tests: shade every voxel every frame (what culling must match).
    #[cfg(test)]
    pub(crate) shade_every_voxel: bool,
    /// Tests: frames whose voxel shading culled.
    #[cfg(test)]
    pub(crate) culled_frames: u32,
    /// `ConeSettings::indirect_scale`.
    indirect_scale_setting: Option<u32>,
    /// The scale of the current screen targets.
    indirect_scale: u32,
    /// Created with the screen targets.
    low_res: Option<LowRes>,
    /// The scene's lights, each with a soft-shadow visibility channel at reduced resolution.
    light_count: u32,
    cone_trace: cone_trace::ConeTracePass,
    voxel_view: debug::VoxelViewPass,
    set: vk::DescriptorSet,
    _sets: DescriptorSets,
    uniforms: Buffer,
    /// Referenced by the GI descriptor set.
    _linear: Sampler,
    ctx: Arc<Context>,
}

impl Dense {
    /// `layouts` are those of sets 0, 1 and 2; writes the volumes into `set`.
    fn new(
        ctx: &Arc<Context>,
        scene: &Scene,
        settings: &GiSettings,
        set: vk::DescriptorSet,
        layouts: [vk::DescriptorSetLayout; 3],
        linear: vk::Sampler,
    ) -> Result<Self> {
        let (resolution, full_update) = (settings.voxels, settings.full_update);
        let voxelizer = settings.voxelizer;
        let volumes = Volumes::new(ctx, resolution, dense_keeps_static_sums(scene, full_update))?;
        let writer = SetWriter::new(ctx, set)
            .storage_image(layout::BINDING_GI_ALBEDO, volumes.albedo.view)
            .storage_image(layout::BINDING_GI_NORMAL, volumes.normal.view)
            .storage_image(layout::BINDING_GI_EMISSION, volumes.emission.view)
            .storage_image(layout::BINDING_GI_RADIANCE, volumes.radiance.view)
            .storage_image(layout::BINDING_GI_DIRECT, volumes.direct.view)
            .storage_image(layout::BINDING_GI_SUMS, volumes.sums.view)
            // Not read without static sums (`GiUniforms.static_sums`), but bound.
            .storage_image(
                layout::BINDING_GI_STATIC_SUMS,
                volumes.static_sums.as_ref().unwrap_or(&volumes.sums).view,
            );
        bind_cone_samples(writer, &volumes.radiance, &volumes.directional, linear).apply();
        // The volumes start at zero, once: the compact pass zeroes the sums after taking
        // their means, and a voxel's attributes and radiance when it empties. They stay in
        // GENERAL: written as storage, the radiance sampled by cones.
        OneShot::new(ctx)?.run("zero voxel volumes", |cmd| {
            let zeroed = [
                &volumes.sums,
                &volumes.albedo,
                &volumes.normal,
                &volumes.emission,
                &volumes.radiance,
                &volumes.direct,
            ];
            for image in zeroed {
                clear_to_zero(
                    ctx,
                    cmd,
                    image,
                    ImageUse::UNDEFINED,
                    ImageUse::COMPUTE_WRITE,
                );
            }
            Ok(())
        })?;
        to_compute_write(ctx, "gi volume layouts", &[&volumes.directional])?;
        let compact = compact::CompactPass::new(ctx, layouts, resolution)?;
        SetWriter::new(ctx, set)
            .buffer(
                layout::BINDING_GI_VOXEL_LIST,
                vk::DescriptorType::STORAGE_BUFFER,
                compact.list.raw,
            )
            .apply();
        Ok(Self {
            voxelize: voxelize::VoxelizePass::new(
                ctx,
                "voxelize",
                voxelizer,
                crate::vk::shaders::GI_VOXELIZE_VOXELIZE_FRAG,
                crate::vk::shaders::GI_VOXELIZE_VOXELIZE_COMP,
                layouts,
            )?,
            filter: filter::FilterPass::new(ctx, [layouts[0], layouts[1]], &volumes)?,
            compact,
            volumes,
            full_update,
            static_ready: false,
        })
    }

    /// Voxelizes what this frame needs (the moving meshes, or everything the first time
    /// or with `full_update`) into `set`'s fragment sums, takes their means and lists the
    /// occupied voxels.
    fn record_voxelize(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        timer: &mut GpuTimer,
        draw: &SceneDraw,
        set: vk::DescriptorSet,
        grid: &Grid,
    ) {
        let n = grid.resolution;
        let voxelized =
            self.full_update || !self.static_ready || self.volumes.static_sums.is_some();
        if voxelized {
            // Last frame's compact pass zeroed the sums.
            memory_barrier(
                ctx,
                cmd,
                (
                    vk::PipelineStageFlags2::COMPUTE_SHADER,
                    vk::AccessFlags2::SHADER_STORAGE_WRITE,
                ),
                (
                    voxelize::STAGES,
                    vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::SHADER_STORAGE_WRITE,
                ),
            );
        }
        if self.full_update || !self.static_ready {
            timer.begin(cmd, "voxelize");
            if self.full_update {
                self.voxelize
                    .record(ctx, cmd, draw, set, grid, voxelize::Meshes::All);
            } else {
                self.voxelize
                    .record(ctx, cmd, draw, set, grid, voxelize::Meshes::Static);
                if let Some(copy) = &self.volumes.static_sums {
                    keep_static_sums(ctx, cmd, &self.volumes.sums, copy);
                    self.voxelize
                        .record(ctx, cmd, draw, set, grid, voxelize::Meshes::Moving);
                }
                self.static_ready = true;
            }
            timer.end(cmd);
        } else if self.volumes.static_sums.is_some() {
            // Only the moving meshes are drawn; the compact pass adds the static sums.
            timer.begin(cmd, "voxelize");
            self.voxelize
                .record(ctx, cmd, draw, set, grid, voxelize::Meshes::Moving);
            timer.end(cmd);
        }
        if voxelized {
            timer.begin(cmd, "compact");
            // The sums are complete; last frame's passes are done with the means and the
            // radiance, which the compact pass rewrites.
            memory_barrier(
                ctx,
                cmd,
                (
                    vk::PipelineStageFlags2::FRAGMENT_SHADER
                        | vk::PipelineStageFlags2::COMPUTE_SHADER,
                    vk::AccessFlags2::SHADER_STORAGE_WRITE,
                ),
                (
                    vk::PipelineStageFlags2::COMPUTE_SHADER,
                    vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::SHADER_STORAGE_WRITE,
                ),
            );
            self.compact.record(ctx, cmd, draw.frame_set, set, n);
            timer.end(cmd);
        }
    }
}

/// Moves the static meshes' fragment sums, just voxelized into `working`, to `copy`, once,
/// and zeroes `working` for the moving meshes. The copy then stays in GENERAL, read by
/// the compact pass every frame. (Copies and clears of these 3D images ran at about
/// 50 GB/s on an H100: the per-frame zeroing is done by the compact pass.)
fn keep_static_sums(ctx: &Context, cmd: vk::CommandBuffer, working: &Image, copy: &Image) {
    let range = working.full_range();
    image_barrier(
        ctx,
        cmd,
        working.raw,
        range,
        voxelize::VoxelizePass::IMAGE_USE,
        ImageUse::TRANSFER_SRC,
    );
    image_barrier(
        ctx,
        cmd,
        copy.raw,
        range,
        ImageUse::UNDEFINED,
        ImageUse::TRANSFER_DST,
    );
    let layers = vk::ImageSubresourceLayers {
        aspect_mask: vk::ImageAspectFlags::COLOR,
        mip_level: 0,
        base_array_layer: 0,
        layer_count: 1,
    };
    let region = vk::ImageCopy {
        src_subresource: layers,
        src_offset: vk::Offset3D::default(),
        dst_subresource: layers,
        dst_offset: vk::Offset3D::default(),
        extent: working.desc.extent,
    };
    unsafe {
        ctx.device.cmd_copy_image(
            cmd,
            working.raw,
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
            copy.raw,
            vk::ImageLayout::TRANSFER_DST_OPTIMAL,
            &[region],
        )
    };
    clear_to_zero(
        ctx,
        cmd,
        working,
        ImageUse::TRANSFER_SRC,
        voxelize::VoxelizePass::IMAGE_USE,
    );
    image_barrier(
        ctx,
        cmd,
        copy.raw,
        range,
        ImageUse::TRANSFER_DST,
        ImageUse::COMPUTE_STORAGE_READ,
    );
}

impl VoxelGi {
    /// `set_layouts` are those of sets 0 and 1; `frames_in_flight` frames may be recorded
    /// before the first is done. The compute voxelizer reads `gpu`'s geometry.
    pub fn new(
        ctx: &Arc<Context>,
        scene: &Scene,
        gpu: &GpuScene,
        settings: &GiSettings,
        set_layouts: [vk::DescriptorSetLayout; 2],
        frames_in_flight: usize,
    ) -> Result<Self> {
        let resolution = settings.voxels;
        let cones = settings.cones;
        check_voxels(resolution)?;
        let rasterized = settings.voxelizer.on(ctx) == voxelize::Voxelizer::Raster;
        if rasterized && !(ctx.features.geometry_shader && ctx.features.fragment_stores_and_atomics)
        {
            bail!(
                "the rasterizing voxelizer needs geometry shaders and fragment stores/atomics, \
                 which {} lacks: try --voxelizer compute",
                ctx.device_name()
            );
        }
        let grid = Grid::around(scene, resolution);
        let uniforms = GiUniforms {
            origin: grid.origin.extend(grid.voxel_size).to_array(),
            resolution,
            directional_levels: directional_levels(resolution),
            emission_range: emission_range(scene),
            step_factor: cones.step_factor,
            bounce_step_factor: cones.bounce_step_factor,
            shadow_step_factor: cones.shadow_step_factor,
            diffuse_tan_half: (cones.diffuse_aperture_deg.to_radians() * 0.5).tan(),
            max_distance: grid.voxel_size * resolution as f32 * 1.8,
            indirect_scale: 0,
            diffuse_cones: cones.diffuse_cones.clamp(1, 16),
            shadow_tan_half: (cones.shadow_aperture_deg.to_radians() * 0.5).tan(),
            ao_distance: cones.ao_distance_voxels.max(1e-3) * grid.voxel_size,
            wide_steps_by_level: u32::from(cones.wide_steps_by_level),
            static_sums: u32::from(
                settings.structure == VoxelStructure::Dense
                    && dense_keeps_static_sums(scene, settings.full_update),
            ),
            pad0: 0,
            pad1: 0,
        };
        let uniforms = Buffer::with_data(
            ctx,
            "gi uniforms",
            bytemuck::bytes_of(&uniforms),
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?;
        let mut bindings = gi_bindings();
        bindings.extend(crate::svo::bindings());
        let sets = DescriptorSets::new(ctx, "gi", &bindings, 1)?;
        let set = sets.allocate("gi")?;
        let storage = vk::DescriptorType::STORAGE_BUFFER;
        SetWriter::new(ctx, set)
            .buffer(
                layout::BINDING_GI_UNIFORMS,
                vk::DescriptorType::UNIFORM_BUFFER,
                uniforms.raw,
            )
            .buffer(layout::BINDING_GI_VERTICES, storage, gpu.vertices.raw)
            .buffer(layout::BINDING_GI_INDICES, storage, gpu.indices.raw)
            .apply();
        let linear = Sampler::new(
            ctx,
            "voxel linear",
            // Not a transparent border: at coarse levels the grid is a few texels across,
            // and filtering towards a border would thin every wall there.
            &sampler_info(vk::Filter::LINEAR, vk::SamplerAddressMode::CLAMP_TO_EDGE),
        )?;
        let layouts = [set_layouts[0], set_layouts[1], sets.layout];
        let octree = !matches!(settings.structure, VoxelStructure::Dense);
        let voxels = match settings.structure {
            VoxelStructure::Dense => Voxels::Dense(Box::new(Dense::new(
                ctx, scene, settings, set, layouts, linear.raw,
            )?)),
            VoxelStructure::Octree { capacities } => Voxels::Octree(Box::new(SvoGi::new(
                ctx,
                scene,
                resolution.trailing_zeros(),
                capacities,
                layouts,
                set,
                linear.raw,
                frames_in_flight,
                settings.full_update,
                settings.voxelizer,
            )?)),
        };
        Ok(Self {
            grid,
            voxels,
            inject: inject::InjectPass::new(ctx, layouts, octree)?,
            bounces: cones.bounces.max(1),
            accumulate_bounces: cones.accumulate_bounces && cones.bounces > 1,
            history: false,
            lighting: None,
            #[cfg(test)]
            shade_every_voxel: false,
            #[cfg(test)]
            culled_frames: 0,
            indirect_scale_setting: cones.indirect_scale,
            indirect_scale: 1,
            low_res: None,
            light_count: scene.lights.len() as u32,
            cone_trace: cone_trace::ConeTracePass::new(ctx, layouts, octree)?,
            voxel_view: debug::VoxelViewPass::new(ctx, layouts, octree)?,
            set,
            _sets: sets,
            uniforms,
            _linear: linear,
            ctx: ctx.clone(),
        })
    }

    /// Work before the first frame: the octree's build (waited for; its pools grow and it
    /// runs again if they overflow).
    pub fn prepare(&mut self, draw: &SceneDraw) -> Result<()> {
        if let Voxels::Octree(svo) = &mut self.voxels {
            svo.build(draw, self.set)?;
        }
        Ok(())
    }

    /// The GI descriptor set (set 2), for passes a test records itself.
    #[cfg(test)]
    pub fn set(&self) -> vk::DescriptorSet {
        self.set
    }

    #[cfg(test)]
    pub fn octree_mut(&mut self) -> Option<&mut SvoGi> {
        match &mut self.voxels {
            Voxels::Octree(svo) => Some(svo),
            Voxels::Dense(_) => None,
        }
    }

    /// The octree, with `--gi svo`.
    pub fn octree(&self) -> Option<&SvoGi> {
        match &self.voxels {
            Voxels::Octree(svo) => Some(svo),
            Voxels::Dense(_) => None,
        }
    }

    fn dense(&self) -> Result<&Dense> {
        match &self.voxels {
            Voxels::Dense(dense) => Ok(dense),
            Voxels::Octree(_) => bail!("the voxels are in an octree, not in dense volumes"),
        }
    }

    /// Points the cone tracer at new screen targets; no frame using the old ones may be
    /// in flight.
    pub fn bind_screen(
        &mut self,
        gbuffer: &GBuffer,
        radiance: &Image,
        depth_sampler: vk::Sampler,
    ) -> Result<()> {
        let extent = gbuffer.extent();
        self.indirect_scale = self
            .indirect_scale_setting
            .unwrap_or_else(|| auto_indirect_scale(extent.height))
            .max(1);
        self.uniforms.write(
            std::mem::offset_of!(GiUniforms, indirect_scale),
            bytemuck::bytes_of(&self.indirect_scale),
        );
        let (width, height) = (
            extent.width.div_ceil(self.indirect_scale),
            extent.height.div_ceil(self.indirect_scale),
        );
        let low = |name, bands: u32| {
            Image::new(
                &self.ctx,
                name,
                ImageDesc::d2(
                    RADIANCE_FORMAT,
                    width,
                    height * bands,
                    vk::ImageUsageFlags::STORAGE,
                ),
            )
        };
        let low_res = LowRes {
            indirect: low("indirect", 1)?,
            // One band of rows per four lights.
            shadow: low("cone shadow", self.light_count.div_ceil(4).max(1))?,
            specular: low("cone specular", 1)?,
            transmitted: low("cone transmitted", 1)?,
        };
        to_compute_write(
            &self.ctx,
            "reduced-resolution layouts",
            &[
                &low_res.indirect,
                &low_res.shadow,
                &low_res.specular,
                &low_res.transmitted,
            ],
        )?;
        SetWriter::new(&self.ctx, self.set)
            .storage_image(layout::BINDING_GI_INDIRECT, low_res.indirect.view)
            .storage_image(layout::BINDING_GI_SHADOW, low_res.shadow.view)
            .storage_image(layout::BINDING_GI_SPECULAR, low_res.specular.view)
            .storage_image(layout::BINDING_GI_TRANSMITTED, low_res.transmitted.view)
            .storage_image(layout::BINDING_GI_SCREEN, radiance.view)
            .storage_image(layout::BINDING_GI_GBUFFER_ALBEDO, gbuffer.albedo.view)
            .storage_image(layout::BINDING_GI_GBUFFER_NORMAL, gbuffer.normal.view)
            .storage_image(
                layout::BINDING_GI_GBUFFER_TRANSMISSION,
                gbuffer.transmission.view,
            )
            .storage_image(layout::BINDING_GI_GBUFFER_EMISSION, gbuffer.emission.view)
            .sampled_image(
                layout::BINDING_GI_GBUFFER_DEPTH,
                gbuffer.depth.view,
                depth_sampler,
                vk::ImageLayout::DEPTH_READ_ONLY_OPTIMAL,
            )
            .apply();
        self.low_res = Some(low_res);
        Ok(())
    }

    /// Forgets the accumulated bounces: the next frame computes them all again.
    pub fn restart(&mut self) {
        self.history = false;
    }

    /// GPU memory of every voxel volume (or octree pool) and the voxel list, by name.
    pub fn memory_bytes(&self) -> Vec<(&'static str, u64)> {
        match &self.voxels {
            Voxels::Dense(dense) => {
                let mut bytes = dense.volumes.bytes();
                bytes.push(("voxel_list", dense.compact.list.size));
                bytes
            }
            Voxels::Octree(svo) => svo.memory_bytes(),
        }
    }

    /// Voxelizes the scene and lights and filters the voxels (after the shadow maps).
    ///
    /// The first frame computes all bounces. Later frames compute one, gathering from the
    /// previous frame's filtered radiance, so bounces accumulate over frames at the cost
    /// of one (moving light takes a few frames to settle in the indirect light).
    ///
    /// With moving meshes every frame inserts them into the octree's static part, and
    /// their bricks are assigned anew; the light the voxels of new bricks gathered is
    /// carried over by voxel (`crate::svo`), the others keep theirs, so bounces still
    /// accumulate one per frame. `slot` is the frame's slot in flight.
    ///
    /// `lighting` holds everything voxel shading reads besides the voxels (the lights,
    /// their shadow views, the shadow mode): while it stays the same, the octree shades
    /// again only the voxels whose light moving meshes can have changed.
    pub fn record_update(
        &mut self,
        cmd: vk::CommandBuffer,
        timer: &mut GpuTimer,
        draw: &SceneDraw,
        slot: usize,
        lighting: &[u8],
    ) -> Result<()> {
        let ctx = &self.ctx;
        let n = self.grid.resolution;
        let set = self.set;
        let mut rebuilt = false;
        let list = match &mut self.voxels {
            Voxels::Dense(dense) => {
                dense.record_voxelize(ctx, cmd, timer, draw, set, &self.grid);
                dense.compact.list.raw
            }
            // Built before the first frame; moving meshes inserted every frame.
            Voxels::Octree(svo) => {
                if svo.moving() {
                    svo.record_moving(cmd, timer, draw, set, slot)?;
                    rebuilt = true;
                }
                svo.voxel_list()
            }
        };

        timer.begin(cmd, "inject");
        memory_barrier(
            ctx,
            cmd,
            (
                voxelize::STAGES,
                vk::AccessFlags2::SHADER_STORAGE_WRITE | vk::AccessFlags2::SHADER_STORAGE_READ,
            ),
            (
                vk::PipelineStageFlags2::COMPUTE_SHADER,
                vk::AccessFlags2::SHADER_STORAGE_READ,
            ),
        );
        // Last frame's cone tracing sampled the radiance volumes that are rewritten now.
        compute_to_compute(ctx, cmd);
        // Unless a bounce rewrites the radiance before the filter reads it.
        let filter_now = !self.history || rebuilt;
        let lighting_changed = self.lighting.as_deref() != Some(lighting);
        if lighting_changed {
            self.lighting = Some(lighting.to_vec());
        }
        let mut push = InjectPush {
            store_radiance: u32::from(filter_now),
            ..Default::default()
        };
        let mut shade = true;
        if let Voxels::Octree(svo) = &self.voxels {
            // The frame after a build shades every voxel (the bricks hold no light yet).
            let built = svo.just_built();
            let cull = !built && !lighting_changed;
            #[cfg(test)]
            let cull = cull && !self.shade_every_voxel;
            #[cfg(test)]
            {
                self.culled_frames += u32::from(cull);
            }
            push.cull = u32::from(cull);
            push.keep_indirect = u32::from(svo.moving() && !built);
            let [first, last] = svo.region().unwrap_or([[0; 3], [-1; 3]]);
            push.region_min = [first[0], first[1], first[2], 0];
            push.region_max = [last[0], last[1], last[2], 0];
            // A still octree under the same light: no voxel's light changed.
            shade = !cull || svo.moving();
        }
        if shade {
            self.inject.record(cmd, draw.frame_set, set, list, &push);
        }
        timer.end(cmd);

        // The dense filter is one pass; the octree's are timed per level.
        let filter = |voxels: &Voxels, timer: &mut GpuTimer, name: &str| {
            compute_to_compute(ctx, cmd);
            match voxels {
                Voxels::Dense(dense) => {
                    timer.begin(cmd, name);
                    dense.filter.record(ctx, cmd, n);
                    timer.end(cmd);
                }
                Voxels::Octree(svo) => svo.record_filter(cmd, timer, draw.frame_set, set),
            }
        };
        let bounces = if self.history { 1 } else { self.bounces - 1 };
        // A rebuilt octree's bricks are new: its voxel shading started from the light
        // carried by voxel, which is filtered before the bounce.
        if filter_now {
            filter(&self.voxels, timer, "filter");
        }
        self.history = self.accumulate_bounces;
        for _ in 0..bounces {
            timer.begin(cmd, "bounce");
            compute_to_compute(ctx, cmd);
            let dispatch = match &self.voxels {
                Voxels::Dense(_) => (list, 0),
                Voxels::Octree(svo) => svo.record_bounce_dispatch(cmd, draw.frame_set, set),
            };
            self.inject
                .record_bounce(cmd, draw.frame_set, set, dispatch);
            timer.end(cmd);
            filter(&self.voxels, timer, "bounce filter");
        }
        if let Voxels::Octree(svo) = &self.voxels {
            svo.record_end_of_bounces(cmd);
        }
        Ok(())
    }

    /// Adds the cone-traced light to `radiance` (written by the lighting pass), or with
    /// `voxel_view` overwrites it with a debug view of the voxels; `ambient_occlusion`:
    /// the ambient occlusion is applied or shown.
    pub fn record_gather(
        &self,
        cmd: vk::CommandBuffer,
        timer: &mut GpuTimer,
        frame_set: vk::DescriptorSet,
        extent: vk::Extent2D,
        voxel_view: bool,
        ambient_occlusion: bool,
    ) {
        if voxel_view {
            timer.begin(cmd, "voxel_view");
            compute_to_compute(&self.ctx, cmd);
            self.voxel_view.record(cmd, frame_set, self.set, extent);
            timer.end(cmd);
            return;
        }
        timer.begin(cmd, "cone_trace");
        compute_to_compute(&self.ctx, cmd);
        let scale = self.indirect_scale;
        let low = vk::Extent2D {
            width: extent.width.div_ceil(scale),
            height: extent.height.div_ceil(scale),
        };
        self.cone_trace
            .record(cmd, frame_set, self.set, low, ambient_occlusion);
        timer.end(cmd);

        timer.begin(cmd, "upsample");
        compute_to_compute(&self.ctx, cmd);
        self.cone_trace
            .record_upsample(cmd, frame_set, self.set, extent);
        timer.end(cmd);
    }

    /// Downloads the occupied-voxel list (x, y, z of each entry, in list order) once the
    /// frames that build it are done.
    #[cfg(test)]
    pub fn download_voxel_list(&self) -> Result<Vec<[u32; 3]>> {
        let bytes = crate::vk::read_back_buffer(&self.ctx, &self.dense()?.compact.list)?;
        let words: &[u32] = bytemuck::cast_slice(&bytes);
        let header: layout::VoxelListHeader =
            bytemuck::pod_read_unaligned(bytemuck::cast_slice(&words[..4]));
        let expected_groups = header.count.div_ceil(layout::VOXEL_LIST_GROUP_SIZE);
        anyhow::ensure!(
            (header.groups_x, header.groups_y, header.groups_z) == (expected_groups, 1, 1),
            "dispatch {:?} for {} voxels",
            (header.groups_x, header.groups_y, header.groups_z),
            header.count
        );
        Ok(words[4..4 + header.count as usize]
            .iter()
            .map(|v| [v & 0x3ff, (v >> 10) & 0x3ff, v >> 20])
            .collect())
    }

    /// Downloads one level of a volume, texel after texel (x fastest), once the frames
    /// that write it are done: the check of each stage against its CPU twin reads it.
    pub fn download(&self, volume: Volume, level: u32) -> Result<Vec<u8>> {
        let v = &self.dense()?.volumes;
        let image = match volume {
            Volume::Albedo => &v.albedo,
            Volume::Normal => &v.normal,
            Volume::Emission => &v.emission,
            Volume::Radiance => &v.radiance,
            Volume::Directional(_) => &v.directional,
        };
        // Edge of the level; the directional texture is six slots of two such cubes wide.
        let n = (image.desc.extent.height >> level).max(1);
        let width = (image.desc.extent.width >> level).max(1);
        let texel = if image.desc.format == PACKED_FORMAT {
            4
        } else {
            8
        };
        let any_shader = ImageUse {
            layout: vk::ImageLayout::GENERAL,
            stage: vk::PipelineStageFlags2::ALL_COMMANDS,
            access: vk::AccessFlags2::SHADER_READ | vk::AccessFlags2::SHADER_WRITE,
        };
        let extent = vk::Extent3D {
            width,
            height: n,
            depth: n,
        };
        let bytes = read_back_image(&self.ctx, image, level, extent, texel, any_shader)?;
        Ok(match volume {
            // Direction d's cube: in every row, n texels from the middle of slot d.
            Volume::Directional(d) => {
                let row = n as usize * texel as usize;
                let start = (DIRECTIONAL_SLOT as usize * d) * row + row / 2;
                bytes
                    .chunks_exact(width as usize * texel as usize)
                    .flat_map(|r| &r[start..start + row])
                    .copied()
                    .collect()
            }
            _ => bytes.to_vec(),
        })
    }
}

/// A voxel volume, for [`VoxelGi::download`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Volume {
    /// Packed RGBA8 albedo; alpha counts the fragments (0 = empty voxel).
    Albedo,
    /// Packed RGBA8 normal (xyz * 0.5 + 0.5), turned to the lit side by injection.
    Normal,
    /// Packed RGBA8 emission / emission range.
    Emission,
    /// RGBA16F radiance, premultiplied by opacity.
    Radiance,
    /// RGBA16F directional volume +X -X +Y -Y +Z -Z (0..6).
    Directional(usize),
}
