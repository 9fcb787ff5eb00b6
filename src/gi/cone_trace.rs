//! Cone tracing: indirect diffuse light gathered at reduced resolution, then upsampled
//! (depth- and normal-aware) and added to the direct light.

use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use crate::gpu_layout as layout;
use crate::vk::{groups_2d, Context, Pipeline};

pub struct ConeTracePass {
    /// Without and with ambient occlusion.
    trace: [Pipeline; 2],
    upsample: Pipeline,
}

impl ConeTracePass {
    /// `set_layouts` are those of sets 0, 1 and 2; `octree` picks the variants that
    /// sample the octree's bricks.
    pub fn new(
        ctx: &Arc<Context>,
        set_layouts: [vk::DescriptorSetLayout; 3],
        octree: bool,
    ) -> Result<Self> {
        use crate::vk::shaders as s;
        let (trace, trace_ao) = if octree {
            (
                s::GI_CONE_TRACE_CONE_TRACE_COMP_VOXELS_SVO,
                s::GI_CONE_TRACE_CONE_TRACE_COMP_VOXELS_SVO_AMBIENT_OCCLUSION,
            )
        } else {
            (
                s::GI_CONE_TRACE_CONE_TRACE_COMP,
                s::GI_CONE_TRACE_CONE_TRACE_COMP_AMBIENT_OCCLUSION,
            )
        };
        let trace = [
            Pipeline::compute(ctx, "cone_trace", trace, &set_layouts, 0)?,
            Pipeline::compute(ctx, "cone_trace with AO", trace_ao, &set_layouts, 0)?,
        ];
        let upsample = Pipeline::compute(
            ctx,
            "upsample",
            s::GI_CONE_TRACE_UPSAMPLE_COMP,
            &set_layouts,
            0,
        )?;
        Ok(Self { trace, upsample })
    }

    /// Gathers at the reduced resolution `low`, with `ambient_occlusion` (shown or
    /// applied) also the ambient occlusion.
    pub fn record(
        &self,
        cmd: vk::CommandBuffer,
        frame_set: vk::DescriptorSet,
        gi_set: vk::DescriptorSet,
        low: vk::Extent2D,
        ambient_occlusion: bool,
    ) {
        let sets = [(layout::SET_FRAME, frame_set), (layout::SET_PASS, gi_set)];
        self.trace[usize::from(ambient_occlusion)].dispatch(
            cmd,
            &sets,
            groups_2d(low, layout::SCREEN_GROUP_SIZE),
        );
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
