//! Voxelization: the hardware rasterizer projects each triangle along its dominant axis
//! onto a grid-sized viewport; fragments average their attributes into the voxels.

use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use crate::gpu_layout::DrawPush;
use crate::scene::Mesh;
use crate::scene_gpu::{SceneDraw, VERTEX_ATTRIBUTES};
use crate::vk::{set_viewport, Context, GraphicsDesc, ImageUse, Pipeline};

pub struct VoxelizePass {
    pipeline: Pipeline,
}

impl VoxelizePass {
    /// How the packed attribute volumes are used while voxelizing.
    pub const IMAGE_USE: ImageUse = ImageUse {
        layout: vk::ImageLayout::GENERAL,
        stage: vk::PipelineStageFlags2::FRAGMENT_SHADER,
        access: vk::AccessFlags2::from_raw(
            vk::AccessFlags2::SHADER_STORAGE_READ.as_raw()
                | vk::AccessFlags2::SHADER_STORAGE_WRITE.as_raw(),
        ),
    };

    /// `fragment` is the SPIR-V of the fragment shader that stores what each covered
    /// voxel receives (`glsl/gi/voxelize/coverage.glsl`); `set_layouts` are those of sets
    /// 0, 1 and 2.
    pub fn new(
        ctx: &Arc<Context>,
        name: &str,
        fragment: &[u8],
        set_layouts: [vk::DescriptorSetLayout; 3],
    ) -> Result<Self> {
        let pipeline = Pipeline::graphics(
            ctx,
            &GraphicsDesc {
                name,
                vertex: crate::vk::shaders::GI_VOXELIZE_VOXELIZE_VERT,
                geometry: Some(crate::vk::shaders::GI_VOXELIZE_VOXELIZE_GEOM),
                fragment: Some(fragment),
                vertex_stride: std::mem::size_of::<crate::scene::Vertex>() as u32,
                attributes: &VERTEX_ATTRIBUTES,
                set_layouts: &set_layouts,
                push_constant_bytes: std::mem::size_of::<DrawPush>() as u32,
                color_formats: &[],
                depth_format: None,
                // Every triangle counts, whichever way it faces the projection.
                cull: vk::CullModeFlags::NONE,
                dynamic_depth_bias: false,
                depth_clamp: false,
            },
        )?;
        Ok(Self { pipeline })
    }

    /// Voxelizes the meshes of `which` into an `n`³ grid.
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        draw: &SceneDraw,
        gi_set: vk::DescriptorSet,
        n: u32,
        which: Meshes,
    ) {
        let extent = vk::Extent2D {
            width: n,
            height: n,
        };
        let rendering = vk::RenderingInfo::default()
            .render_area(vk::Rect2D {
                offset: vk::Offset2D::default(),
                extent,
            })
            .layer_count(1);
        unsafe { ctx.device.cmd_begin_rendering(cmd, &rendering) };
        set_viewport(ctx, cmd, extent);
        let keep = |mesh: &Mesh| match which {
            Meshes::All => true,
            Meshes::Static => mesh.animation.is_none(),
            Meshes::Moving => mesh.animation.is_some(),
        };
        draw.draw_meshes(ctx, cmd, &self.pipeline, 0, Some(gi_set), keep);
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
