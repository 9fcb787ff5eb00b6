//! Cone tracing: indirect diffuse light, soft shadows, specular and refracted light
//! gathered at reduced resolution into the screen contract's terms
//! (`glsl/gi/vct/cone_trace/cone_trace.comp`), which the upsample adds to the direct light.

use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use super::{PipelineBase, StoreShaders};
use crate::gpu_layout as layout;
use crate::vk::{groups_2d, Context, Pipeline};

pub struct ConeTracePass {
    /// Without and with ambient occlusion.
    trace: [Pipeline; 2],
}

impl ConeTracePass {
    /// `base` makes the pipelines; `shaders` are the store's variants.
    pub fn new(ctx: &Arc<Context>, base: PipelineBase, shaders: &StoreShaders) -> Result<Self> {
        let trace = [
            base.compute(ctx, "cone_trace", shaders.cone_trace, 0)?,
            base.compute(ctx, "cone_trace with AO", shaders.cone_trace_ao, 0)?,
        ];
        Ok(Self { trace })
    }

    /// Gathers at the reduced resolution `low`, with `ambient_occlusion` (shown or
    /// applied) also the ambient occlusion; `sets` are the frame's, the screen's and the
    /// cone tracer's.
    pub fn record(
        &self,
        cmd: vk::CommandBuffer,
        sets: &[(u32, vk::DescriptorSet)],
        low: vk::Extent2D,
        ambient_occlusion: bool,
    ) {
        self.trace[usize::from(ambient_occlusion)].dispatch(
            cmd,
            sets,
            groups_2d(low, layout::SCREEN_GROUP_SIZE),
        );
    }
}
