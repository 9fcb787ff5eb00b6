//! Voxelization: each triangle is projected along its dominant axis onto a grid-sized
//! viewport and dilated for conservative coverage; every voxel a pixel of it covers
//! receives the triangle's attributes there (`glsl/gi/vct/voxelize/`). Two voxelizers do
//! the same: the hardware rasterizer (geometry shader and fragment shader), and a compute
//! shader that walks each triangle's pixels itself.

use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use super::{Grid, PipelineBase};
use crate::gpu_layout::{self as layout, DrawPush};
use crate::scene::Mesh;
use crate::scene_gpu::{SceneDraw, VERTEX_ATTRIBUTES};
use crate::vk::{set_viewport, Context, GraphicsDesc, ImageUse, Pipeline};

/// Which voxelizer runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Voxelizer {
    /// The compute voxelizer on a GPU, the rasterizer on a CPU driver such as lavapipe
    #[default]
    Auto,
    /// The hardware rasterizer, with a geometry shader (on lavapipe the much faster:
    /// Sponza at 64^3 in 1.0 s against about 110 s)
    Raster,
    /// A compute shader, one workgroup per triangle (on GPUs that draw with few units,
    /// such as an H100, the faster)
    Compute,
}

impl Voxelizer {
    /// `Auto` resolved for the device.
    pub fn on(self, ctx: &Context) -> Self {
        match self {
            Self::Auto if ctx.is_cpu() => Self::Raster,
            Self::Auto => Self::Compute,
            chosen => chosen,
        }
    }
}

/// The most pixels of a triangle that one lane of the compute voxelizer walks (more
/// pixels get more workgroups).
const PIXELS_PER_LANE: u32 = 64;

/// The shader stages that voxelize, with either voxelizer.
pub const STAGES: vk::PipelineStageFlags2 = vk::PipelineStageFlags2::from_raw(
    vk::PipelineStageFlags2::FRAGMENT_SHADER.as_raw()
        | vk::PipelineStageFlags2::COMPUTE_SHADER.as_raw(),
);

pub struct VoxelizePass {
    pipeline: Pipeline,
}

impl VoxelizePass {
    /// How the storage the voxelization writes is used while voxelizing.
    pub const IMAGE_USE: ImageUse = ImageUse {
        layout: vk::ImageLayout::GENERAL,
        stage: STAGES,
        access: vk::AccessFlags2::from_raw(
            vk::AccessFlags2::SHADER_STORAGE_READ.as_raw()
                | vk::AccessFlags2::SHADER_STORAGE_WRITE.as_raw(),
        ),
    };

    /// `fragment` and `compute` are the SPIR-V of the two voxelizers' shaders that store
    /// what each covered voxel receives (`glsl/gi/vct/voxelize/coverage.glsl`); `base` makes
    /// the pipeline.
    pub fn new(
        ctx: &Arc<Context>,
        name: &str,
        voxelizer: Voxelizer,
        fragment: &[u8],
        compute: &[u8],
        base: PipelineBase,
    ) -> Result<Self> {
        let push_bytes = std::mem::size_of::<DrawPush>() as u32;
        let pipeline = match voxelizer.on(ctx) {
            Voxelizer::Auto | Voxelizer::Raster => Pipeline::graphics(
                ctx,
                &GraphicsDesc {
                    name,
                    vertex: crate::vk::shaders::GI_VCT_VOXELIZE_VOXELIZE_VERT,
                    geometry: Some(crate::vk::shaders::GI_VCT_VOXELIZE_VOXELIZE_GEOM),
                    fragment: Some(fragment),
                    vertex_stride: std::mem::size_of::<crate::scene::Vertex>() as u32,
                    attributes: &VERTEX_ATTRIBUTES,
                    set_layouts: &base.sets,
                    push_constant_bytes: push_bytes,
                    color_formats: &[],
                    depth_format: None,
                    // Every triangle counts, whichever way it faces the projection.
                    cull: vk::CullModeFlags::NONE,
                    dynamic_depth_bias: false,
                    depth_clamp: false,
                    constants: base.constants(),
                },
            )?,
            Voxelizer::Compute => base.compute(ctx, name, compute, push_bytes)?,
        };
        Ok(Self { pipeline })
    }

    /// Voxelizes the meshes of `which` into `grid`.
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        draw: &SceneDraw,
        set: vk::DescriptorSet,
        grid: &Grid,
        which: Meshes,
    ) {
        let keep = |mesh: &Mesh| match which {
            Meshes::All => true,
            Meshes::Static => mesh.animation.is_none(),
            Meshes::Moving => mesh.animation.is_some(),
        };
        if self.pipeline.is_compute() {
            let limits = ctx.properties.limits.max_compute_work_group_count;
            // A triangle's projection spans at most about (edge / voxel + 2)^2 pixels,
            // shared among workgroups of at most PIXELS_PER_LANE per lane (one workgroup
            // walking a floor triangle of Sponza's at 1024^3 alone took 15 ms).
            let slices = |edge: f32| {
                let pixels = (edge / grid.voxel_size + 2.0).powi(2);
                let per_group = (layout::VOXELIZE_GROUP_SIZE * PIXELS_PER_LANE) as f32;
                (pixels / per_group).ceil() as u32
            };
            let max_groups = [limits[0], limits[1]];
            draw.dispatch_triangles(ctx, cmd, &self.pipeline, set, max_groups, slices, keep);
            return;
        }
        let extent = vk::Extent2D {
            width: grid.resolution,
            height: grid.resolution,
        };
        let rendering = vk::RenderingInfo::default()
            .render_area(vk::Rect2D {
                offset: vk::Offset2D::default(),
                extent,
            })
            .layer_count(1);
        unsafe { ctx.device.cmd_begin_rendering(cmd, &rendering) };
        set_viewport(ctx, cmd, extent);
        draw.draw_meshes(ctx, cmd, &self.pipeline, 0, Some(set), keep);
        unsafe { ctx.device.cmd_end_rendering(cmd) };
    }
}

/// Which meshes a voxelization draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Meshes {
    All,
    /// Those without animation.
    Static,
    /// Those with animation.
    Moving,
}
