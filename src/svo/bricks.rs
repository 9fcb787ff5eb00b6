//! Leaf bricks from the voxel fragments (`glsl/svo/bricks/fill.comp`): each fragment adds
//! its attributes to its voxel in its leaf's brick, as RGBA8 moving averages.

use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use crate::vk::{Context, Pipeline};

/// Leaf bricks hold the leaf's 2x2x2 voxels of the effective grid, with voxel values at
/// voxel centres exactly as the dense grid holds them, so that the two paths sample the
/// same values.
pub const LEAF_BRICK_EDGE: u32 = 2;

pub struct FillPass {
    pipeline: Pipeline,
}

impl FillPass {
    /// `set_layouts` are those of sets 0, 1 and 2.
    pub fn new(ctx: &Arc<Context>, set_layouts: [vk::DescriptorSetLayout; 3]) -> Result<Self> {
        Ok(Self {
            pipeline: Pipeline::compute(
                ctx,
                "svo fill",
                crate::vk::shaders::SVO_BRICKS_FILL_COMP,
                &set_layouts,
                0,
            )?,
        })
    }

    /// One invocation per stored fragment; `counters` holds the dispatch at its start.
    pub fn record(
        &self,
        cmd: vk::CommandBuffer,
        sets: &[(u32, vk::DescriptorSet)],
        counters: vk::Buffer,
    ) {
        self.pipeline.dispatch_indirect(cmd, sets, counters, 0);
    }
}
