//! Debug views of the voxels: albedo, normal or radiance at a chosen mip level, or the
//! octree's nodes at a chosen level, marched per pixel from the camera
//! (`glsl/gi/debug/voxel_view.comp`).

use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use crate::gpu_layout as layout;
use crate::vk::{groups_2d, Context, Pipeline};

pub struct VoxelViewPass {
    pipeline: Pipeline,
}

impl VoxelViewPass {
    /// `set_layouts` are those of sets 0, 1 and 2; `octree` picks the variant that looks
    /// the voxels up in the octree (and draws its nodes).
    pub fn new(
        ctx: &Arc<Context>,
        set_layouts: [vk::DescriptorSetLayout; 3],
        octree: bool,
    ) -> Result<Self> {
        let spirv = if octree {
            crate::vk::shaders::GI_DEBUG_VOXEL_VIEW_COMP_VOXELS_SVO
        } else {
            crate::vk::shaders::GI_DEBUG_VOXEL_VIEW_COMP
        };
        let pipeline = Pipeline::compute(ctx, "voxel_view", spirv, &set_layouts, 0)?;
        Ok(Self { pipeline })
    }

    /// Overwrites every pixel of `extent` in the screen radiance.
    pub fn record(
        &self,
        cmd: vk::CommandBuffer,
        frame_set: vk::DescriptorSet,
        gi_set: vk::DescriptorSet,
        extent: vk::Extent2D,
    ) {
        let sets = [(layout::SET_FRAME, frame_set), (layout::SET_PASS, gi_set)];
        self.pipeline
            .dispatch(cmd, &sets, groups_2d(extent, layout::SCREEN_GROUP_SIZE));
    }
}
