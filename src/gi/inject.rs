//! Light injection (deferred voxel shading): direct light into every occupied voxel.

use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use crate::gpu_layout as layout;
use crate::vk::{groups, Context, Pipeline};

pub struct InjectPass {
    pipeline: Pipeline,
    bounce: Pipeline,
}

impl InjectPass {
    /// `set_layouts` are those of sets 0, 1 and 2.
    pub fn new(ctx: &Arc<Context>, set_layouts: [vk::DescriptorSetLayout; 3]) -> Result<Self> {
        let pipeline = Pipeline::compute(
            ctx,
            "inject",
            crate::vk::shaders::GI_INJECT_INJECT_COMP,
            &set_layouts,
            0,
        )?;
        let bounce = Pipeline::compute(
            ctx,
            "bounce",
            crate::vk::shaders::GI_INJECT_BOUNCE_COMP,
            &set_layouts,
            0,
        )?;
        Ok(Self { pipeline, bounce })
    }

    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        frame_set: vk::DescriptorSet,
        gi_set: vk::DescriptorSet,
        n: u32,
    ) {
        dispatch_voxels(ctx, cmd, &self.pipeline, frame_set, gi_set, n);
    }

    /// One more bounce: direct + albedo x gathered filtered radiance, into the radiance.
    pub fn record_bounce(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        frame_set: vk::DescriptorSet,
        gi_set: vk::DescriptorSet,
        n: u32,
    ) {
        dispatch_voxels(ctx, cmd, &self.bounce, frame_set, gi_set, n);
    }
}

fn dispatch_voxels(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    pipeline: &Pipeline,
    frame_set: vk::DescriptorSet,
    gi_set: vk::DescriptorSet,
    n: u32,
) {
    pipeline.bind(
        cmd,
        &[(layout::SET_FRAME, frame_set), (layout::SET_PASS, gi_set)],
    );
    let g = groups(n, layout::VOXEL_GROUP_SIZE);
    unsafe { ctx.device.cmd_dispatch(cmd, g, g, g) };
}
