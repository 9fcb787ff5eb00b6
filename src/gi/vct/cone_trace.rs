//! Cone tracing: indirect diffuse light, soft shadows, specular and refracted light
//! gathered at reduced resolution into the screen contract's terms
//! (`glsl/gi/vct/cone_trace/cone_trace.comp`), which the upsample adds to the direct light.

use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use super::{PipelineBase, StoreShaders};
use crate::gpu_layout::{self as layout, ConeTracePush};
use crate::vk::{compute_to_compute, groups_2d, Context, Pipeline};

/// The most lattice cones (`--lattice-cones`) one dispatch traces; more are shared out
/// over several, each adding to the gather the ones before left. Why: llvmpipe (lavapipe)
/// gives each invocation of a shader 65535 loop iterations, all its loops together,
/// counted once per iteration of its group of SIMD lanes (gallivm's
/// `LP_MAX_TGSI_LOOP_ITERATIONS`), then ends every loop silently. 72 cones through the
/// octree at depth 8, whose every lookup descends and may search the neighbouring nodes
/// in loops, crossed it and lost light in blocks of the image; shares of 24 lose none at
/// depth 8 (the dense grid's picture at 256³) nor at depth 9 (shares of 8's, but for
/// the partial sums' rounding in the half-float image, 0.2 % at most; BENCHMARKS.md,
/// session 36). A GPU has no such limit and pays only the few extra reads of the
/// G-buffer.
const LATTICE_CONES_PER_DISPATCH: u32 = 24;

pub struct ConeTracePass {
    ctx: Arc<Context>,
    /// Without and with ambient occlusion.
    trace: [Pipeline; 2],
    /// The dispatches' shares of the lattice (one, of no cones, without it).
    shares: Vec<ConeTracePush>,
}

impl ConeTracePass {
    /// `base` makes the pipelines; `shaders` are the store's variants.
    pub fn new(ctx: &Arc<Context>, base: PipelineBase, shaders: &StoreShaders) -> Result<Self> {
        let push = std::mem::size_of::<ConeTracePush>() as u32;
        let trace = [
            base.compute(ctx, "cone_trace", shaders.cone_trace, push)?,
            base.compute(ctx, "cone_trace with AO", shaders.cone_trace_ao, push)?,
        ];
        Ok(Self {
            ctx: ctx.clone(),
            trace,
            shares: shares(base.lattice_cones()),
        })
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
        let pipeline = &self.trace[usize::from(ambient_occlusion)];
        pipeline.bind(cmd, sets);
        for (i, share) in self.shares.iter().enumerate() {
            if i > 0 {
                // Each share adds to the indirect light the one before stored.
                compute_to_compute(&self.ctx, cmd);
            }
            pipeline.push(cmd, vk::ShaderStageFlags::COMPUTE, share);
            pipeline.dispatch_bound(cmd, groups_2d(low, layout::SCREEN_GROUP_SIZE));
        }
    }
}

/// `lattice` cones (0: none) shared out over dispatches of at most
/// LATTICE_CONES_PER_DISPATCH, as evenly as they go.
fn shares(lattice: u32) -> Vec<ConeTracePush> {
    let count = lattice.div_ceil(LATTICE_CONES_PER_DISPATCH).max(1);
    (0..count)
        .map(|i| ConeTracePush {
            first_cone: lattice * i / count,
            cone_count: lattice * (i + 1) / count - lattice * i / count,
            ..Default::default()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every lattice cone is traced once, no dispatch takes more than its share, and
    /// without the lattice there is one dispatch.
    #[test]
    fn the_lattice_is_shared_out_whole() {
        for lattice in [0, 32, 48, 72, 73, 96, 256] {
            let shares = shares(lattice);
            let mut next = 0;
            for share in &shares {
                assert_eq!(share.first_cone, next);
                assert!(share.cone_count <= LATTICE_CONES_PER_DISPATCH);
                next += share.cone_count;
            }
            assert_eq!(next, lattice);
            assert_eq!(
                shares.len(),
                lattice.div_ceil(LATTICE_CONES_PER_DISPATCH).max(1) as usize
            );
        }
    }
}
