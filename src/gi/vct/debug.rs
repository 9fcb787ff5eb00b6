//! Debug views of the voxels: albedo, normal or radiance at a chosen mip level, or the
//! octree's nodes at a chosen level, marched per pixel from the camera
//! (`glsl/gi/vct/debug/voxel_view.comp`).

use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use super::{PipelineBase, StoreShaders};
use crate::gpu_layout as layout;
use crate::vk::{groups_2d, Context, Pipeline};

pub struct VoxelViewPass {
    pipeline: Pipeline,
}

impl VoxelViewPass {
    /// `base` makes the pipelines; `shaders` are the store's variants (the
    /// octree's looks the voxels up in the octree, and draws its nodes).
    pub fn new(ctx: &Arc<Context>, base: PipelineBase, shaders: &StoreShaders) -> Result<Self> {
        let pipeline = base.compute(ctx, "voxel_view", shaders.voxel_view, 0)?;
        Ok(Self { pipeline })
    }

    /// Overwrites every pixel of `extent` in the screen radiance; `sets` are the frame's,
    /// the screen's and the cone tracer's.
    pub fn record(
        &self,
        cmd: vk::CommandBuffer,
        sets: &[(u32, vk::DescriptorSet)],
        extent: vk::Extent2D,
    ) {
        self.pipeline
            .dispatch(cmd, sets, groups_2d(extent, layout::SCREEN_GROUP_SIZE));
    }
}
