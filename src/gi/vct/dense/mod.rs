//! The dense voxel store (Präntare 2016; Villegas 2018): every voxel of the grid in 3D
//! textures. Per frame: voxelize (fragment sums) -> compact (means, the occupied-voxel
//! list) -> after voxel shading, the anisotropic filter (`filter`), six directional mip
//! chains side by side in one texture.

mod compact;
mod filter;
#[cfg(test)]
mod tests;

use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use super::voxelize::{self, Meshes, VoxelizePass};
use super::{
    bind_cone_samples, dense_keeps_static_sums, directional_levels, DirectionalFilter, Grid,
    PipelineBase, Preparation, Store, StoreShaders, VctSettings, VoxelStore, Voxels,
};
use crate::gi::DebugView;
use crate::gpu_layout::{self as layout, InjectPush};
use crate::scene::Scene;
use crate::scene_gpu::SceneDraw;
use crate::vk::shaders as s;
use crate::vk::{
    clear_to_zero, image_barrier, memory_barrier, read_back_image, to_compute_write, Binding,
    Context, GpuTimer, Image, ImageDesc, ImageUse, OneShot, SetWriter,
};

/// The voxel volumes.
struct Volumes {
    albedo: Image,
    normal: Image,
    emission: Image,
    radiance: Image,
    /// The share of each voxel's cross-section across x, y and z that its surfaces cover.
    coverage: Image,
    /// Direct light only, the starting point of each bounce.
    direct: Image,
    /// The fragment sums the means in `albedo`, `normal` and `emission` are taken from
    /// (`BINDING_DENSE_SUMS`).
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
/// middle (`glsl/gi/vct/sampling.glsl`, `glsl/gi/vct/dense/filter.comp`).
const DIRECTIONAL_SLOT: u32 = 2;

const PACKED_FORMAT: vk::Format = vk::Format::R32_UINT;
const RADIANCE_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;
/// The voxels' coverage (`BINDING_VCT_COVERAGE`), dense grid and octree alike.
pub(crate) const COVERAGE_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;

impl Volumes {
    /// `slots`: the directional texture's volumes (`Store::directional_slots`).
    fn new(ctx: &Arc<Context>, n: u32, static_copies: bool, slots: u32) -> Result<Self> {
        // Every volume can be copied out, for the checks against the CPU twins.
        let packed_usage = vk::ImageUsageFlags::STORAGE
            | vk::ImageUsageFlags::TRANSFER_DST
            | vk::ImageUsageFlags::TRANSFER_SRC;
        let packed = |name| Image::new(ctx, name, ImageDesc::d3(PACKED_FORMAT, n, 1, packed_usage));
        let sums = |name| {
            let mut desc = ImageDesc::d3(PACKED_FORMAT, n, 1, packed_usage);
            // `sum_texel` in glsl/gi/vct/sums.glsl.
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
        directional_desc.extent.width = slots * DIRECTIONAL_SLOT * (n / 2);
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
            coverage: Image::new(
                ctx,
                "voxel coverage",
                ImageDesc::d3(COVERAGE_FORMAT, n, 1, radiance_usage),
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
            ("voxel_coverage", self.coverage.memory_bytes()),
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

/// The dense grid's volumes and the passes that fill them.
pub struct Dense {
    grid: Grid,
    volumes: Volumes,
    voxelize: VoxelizePass,
    compact: compact::CompactPass,
    filter: filter::FilterPass,
    /// Re-voxelize everything every frame.
    full_update: bool,
    /// The static meshes are in the voxels (or in `Volumes::static_sums`).
    static_ready: bool,
    ctx: Arc<Context>,
}

impl VoxelStore for Dense {
    const SHADERS: StoreShaders = StoreShaders {
        inject: s::GI_VCT_INJECT_INJECT_COMP,
        bounce: s::GI_VCT_INJECT_BOUNCE_COMP,
        cone_trace: s::GI_VCT_CONE_TRACE_CONE_TRACE_COMP,
        cone_trace_ao: s::GI_VCT_CONE_TRACE_CONE_TRACE_COMP_AMBIENT_OCCLUSION,
        voxel_view: s::GI_VCT_DEBUG_VOXEL_VIEW_COMP,
    };

    const DEBUG_VIEWS: &'static [DebugView] = &[
        DebugView::None,
        DebugView::Indirect,
        DebugView::Ao,
        DebugView::VoxelAlbedo,
        DebugView::VoxelNormal,
        DebugView::VoxelRadiance,
        DebugView::EmitterLight,
    ];

    fn bindings() -> Vec<Binding> {
        let storage = vk::DescriptorType::STORAGE_IMAGE;
        vec![
            Binding::new(layout::BINDING_DENSE_SUMS, storage, super::STAGES),
            Binding::new(layout::BINDING_DENSE_STATIC_SUMS, storage, super::STAGES),
        ]
    }

    fn new(
        ctx: &Arc<Context>,
        scene: &Scene,
        settings: &VctSettings,
        grid: Grid,
        set: vk::DescriptorSet,
        base: PipelineBase,
        linear: vk::Sampler,
        _frames_in_flight: usize,
    ) -> Result<Self> {
        let (resolution, full_update) = (grid.resolution, settings.full_update);
        let voxelizer = settings.voxelizer;
        let (filter, planes) = match settings.store {
            Store::Dense { filter, planes } => (filter, planes),
            Store::Octree { .. } => (DirectionalFilter::Pairs, false),
        };
        let volumes = Volumes::new(
            ctx,
            resolution,
            dense_keeps_static_sums(scene, full_update),
            settings.store.directional_slots(),
        )?;
        let writer = SetWriter::new(ctx, set)
            .storage_image(layout::BINDING_VCT_ALBEDO, volumes.albedo.view)
            .storage_image(layout::BINDING_VCT_NORMAL, volumes.normal.view)
            .storage_image(layout::BINDING_VCT_EMISSION, volumes.emission.view)
            .storage_image(layout::BINDING_VCT_RADIANCE, volumes.radiance.view)
            .storage_image(layout::BINDING_VCT_DIRECT, volumes.direct.view)
            .storage_image(layout::BINDING_DENSE_SUMS, volumes.sums.view)
            // Not read without static sums (`VctUniforms.static_sums`), but bound.
            .storage_image(
                layout::BINDING_DENSE_STATIC_SUMS,
                volumes.static_sums.as_ref().unwrap_or(&volumes.sums).view,
            );
        bind_cone_samples(
            writer,
            &volumes.radiance,
            &volumes.coverage,
            &volumes.directional,
            linear,
        )
        .apply();
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
                &volumes.coverage,
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
        let compact = compact::CompactPass::new(ctx, base, resolution)?;
        SetWriter::new(ctx, set)
            .buffer(
                layout::BINDING_VCT_VOXEL_LIST,
                vk::DescriptorType::STORAGE_BUFFER,
                compact.list.raw,
            )
            .apply();
        Ok(Self {
            grid,
            voxelize: VoxelizePass::new(
                ctx,
                "voxelize",
                voxelizer,
                crate::vk::shaders::GI_VCT_VOXELIZE_VOXELIZE_FRAG,
                crate::vk::shaders::GI_VCT_VOXELIZE_VOXELIZE_COMP,
                base,
            )?,
            filter: filter::FilterPass::new(
                ctx,
                [base.sets[0], base.sets[1]],
                &volumes,
                filter,
                planes,
                resolution,
            )?,
            compact,
            volumes,
            full_update,
            static_ready: false,
            ctx: ctx.clone(),
        })
    }

    fn grid(&self) -> &Grid {
        &self.grid
    }

    fn static_sums(&self) -> bool {
        self.volumes.static_sums.is_some()
    }

    /// Voxelizes what this frame needs (the moving meshes, or everything the first time
    /// or with `full_update`) into `set`'s fragment sums, takes their means and lists the
    /// occupied voxels.
    fn record_voxels(
        &mut self,
        cmd: vk::CommandBuffer,
        timer: &mut GpuTimer,
        draw: &SceneDraw,
        set: vk::DescriptorSet,
        _slot: usize,
    ) -> Result<Voxels> {
        let ctx = self.ctx.clone();
        let ctx = &*ctx;
        let grid = self.grid;
        let grid = &grid;
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
                self.voxelize.record(ctx, cmd, draw, set, grid, Meshes::All);
            } else {
                self.voxelize
                    .record(ctx, cmd, draw, set, grid, Meshes::Static);
                if let Some(copy) = &self.volumes.static_sums {
                    keep_static_sums(ctx, cmd, &self.volumes.sums, copy);
                    self.voxelize
                        .record(ctx, cmd, draw, set, grid, Meshes::Moving);
                }
                self.static_ready = true;
            }
            timer.end(cmd);
        } else if self.volumes.static_sums.is_some() {
            // Only the moving meshes are drawn; the compact pass adds the static sums.
            timer.begin(cmd, "voxelize");
            self.voxelize
                .record(ctx, cmd, draw, set, grid, Meshes::Moving);
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
        Ok(Voxels {
            list: self.compact.list.raw,
            rebuilt: false,
        })
    }

    fn shading(&mut self, _lighting_changed: bool, _push: &mut InjectPush) -> bool {
        true
    }

    fn record_filter(
        &self,
        cmd: vk::CommandBuffer,
        timer: &mut GpuTimer,
        _frame_set: vk::DescriptorSet,
        _set: vk::DescriptorSet,
        name: &str,
    ) {
        timer.begin(cmd, name);
        self.filter.record(&self.ctx, cmd, self.grid.resolution);
        timer.end(cmd);
    }

    fn bounce_dispatch(
        &self,
        _cmd: vk::CommandBuffer,
        _frame_set: vk::DescriptorSet,
        _set: vk::DescriptorSet,
    ) -> (vk::Buffer, vk::DeviceSize) {
        (self.compact.list.raw, 0)
    }

    fn memory_bytes(&self) -> Vec<(&'static str, u64)> {
        let mut bytes = self.volumes.bytes();
        bytes.push(("voxel_list", self.compact.list.size));
        bytes.push(("voxel_filter_rows", self.filter.memory_bytes()));
        bytes
    }

    /// The occupied voxels, counted in the albedo volume (its alpha counts fragments).
    fn stats(&self) -> Result<Vec<(String, f64)>> {
        let albedo = self.download(Volume::Albedo, 0)?;
        let occupied = albedo.chunks_exact(4).filter(|t| t[3] > 0).count();
        Ok(vec![("occupied_voxels".to_string(), occupied as f64)])
    }

    fn preparation(&self) -> Option<Preparation> {
        None
    }
}

impl Dense {
    /// Downloads the occupied-voxel list (x, y, z of each entry, in list order) once the
    /// frames that build it are done.
    #[cfg(test)]
    pub fn download_voxel_list(&self) -> Result<Vec<[u32; 3]>> {
        let bytes = crate::vk::read_back_buffer(&self.ctx, &self.compact.list)?;
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
        let v = &self.volumes;
        let image = match volume {
            Volume::Albedo => &v.albedo,
            Volume::Normal => &v.normal,
            Volume::Emission => &v.emission,
            Volume::Radiance => &v.radiance,
            Volume::Coverage => &v.coverage,
            Volume::Directional(_) => &v.directional,
        };
        // Edge of the level; the directional texture is six slots of two such cubes wide.
        let n = (image.desc.extent.height >> level).max(1);
        let width = (image.desc.extent.width >> level).max(1);
        let texel = match image.desc.format {
            PACKED_FORMAT | COVERAGE_FORMAT => 4,
            _ => 8,
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

/// Moves the static meshes' fragment sums, just voxelized into `working`, to `copy`, once,
/// and zeroes `working` for the moving meshes. The copy then stays in GENERAL, read by
/// the compact pass every frame. (Copies and clears of these 3D images are slow on
/// a GPU, BENCHMARKS.md: the per-frame zeroing is done by the compact pass.)
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
    /// RGBA8 coverage across x, y and z; alpha 1 where occupied.
    Coverage,
    /// RGBA16F directional volume +X -X +Y -Y +Z -Z (0..6).
    Directional(usize),
}
