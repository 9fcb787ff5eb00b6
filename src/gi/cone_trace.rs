//! Cone tracing: indirect diffuse light gathered at reduced resolution, then upsampled
//! (depth- and normal-aware) and added to the direct light.

use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use crate::gpu_layout as layout;
use crate::vk::{groups_2d, Context, Pipeline};

pub struct ConeTracePass {
    pipeline: Pipeline,
    upsample: Pipeline,
}

impl ConeTracePass {
    /// `set_layouts` are those of sets 0, 1 and 2.
    pub fn new(ctx: &Arc<Context>, set_layouts: [vk::DescriptorSetLayout; 3]) -> Result<Self> {
        let pipeline = Pipeline::compute(
            ctx,
            "cone_trace",
            crate::vk::shaders::GI_CONE_TRACE_CONE_TRACE_COMP,
            &set_layouts,
            0,
        )?;
        let upsample = Pipeline::compute(
            ctx,
            "upsample",
            crate::vk::shaders::GI_CONE_TRACE_UPSAMPLE_COMP,
            &set_layouts,
            0,
        )?;
        Ok(Self { pipeline, upsample })
    }

    /// Gathers at the reduced resolution `low`.
    pub fn record(
        &self,
        cmd: vk::CommandBuffer,
        frame_set: vk::DescriptorSet,
        gi_set: vk::DescriptorSet,
        low: vk::Extent2D,
    ) {
        let sets = [(layout::SET_FRAME, frame_set), (layout::SET_PASS, gi_set)];
        self.pipeline
            .dispatch(cmd, &sets, groups_2d(low, layout::SCREEN_GROUP_SIZE));
    }

    /// Adds the upsampled indirect light to every pixel of `extent`.
    pub fn record_upsample(
        &self,
        cmd: vk::CommandBuffer,
        frame_set: vk::DescriptorSet,
        gi_set: vk::DescriptorSet,
        extent: vk::Extent2D,
    ) {
        let sets = [(layout::SET_FRAME, frame_set), (layout::SET_PASS, gi_set)];
        self.upsample
            .dispatch(cmd, &sets, groups_2d(extent, layout::SCREEN_GROUP_SIZE));
    }
}
