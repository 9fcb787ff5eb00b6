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
/// The most sampled emitters whose light one dispatch adds: each emitter's visibility
/// cone marches through the voxels as a lattice cone does, and sixteen of them beside the
/// lattice's first share ran past llvmpipe's loop budget in the octree at depth 7
/// (`cornell_area` cut into sixteen pieces: LDR-FLIP 0.112 against the dense grid's
/// 0.059; BENCHMARKS.md, session 46). The lattice's shares are full, so its emitters get
/// dispatches of their own. The ring's one dispatch takes them all, as before: frames
/// keep one piece an emitter, and later dispatches cost the ring's cone_trace up to 12 %
/// (a dispatch of their own, or the branch for them in its shader).
const EMITTERS_PER_DISPATCH: u32 = 8;

pub struct ConeTracePass {
    ctx: Arc<Context>,
    /// Without and with ambient occlusion.
    trace: [Pipeline; 2],
    /// The dispatches' shares of the lattice (one, of no cones, without it), then of the
    /// sampled emitters.
    shares: Vec<ConeTracePush>,
}

impl ConeTracePass {
    /// `base` makes the pipelines; `shaders` are the store's variants; `emitters` is the
    /// count of sampled emitters.
    pub fn new(
        ctx: &Arc<Context>,
        base: PipelineBase,
        shaders: &StoreShaders,
        emitters: u32,
    ) -> Result<Self> {
        let push = std::mem::size_of::<ConeTracePush>() as u32;
        let trace = [
            base.compute(ctx, "cone_trace", shaders.cone_trace, push)?,
            base.compute(ctx, "cone_trace with AO", shaders.cone_trace_ao, push)?,
        ];
        Ok(Self {
            ctx: ctx.clone(),
            trace,
            shares: shares(base.lattice_cones(), emitters),
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
/// LATTICE_CONES_PER_DISPATCH, as evenly as they go, and `emitters` over dispatches of at
/// most EMITTERS_PER_DISPATCH after them; without the lattice, one dispatch for the ring
/// and every emitter. Only the first dispatch has first cone and first emitter 0.
fn shares(lattice: u32, emitters: u32) -> Vec<ConeTracePush> {
    if lattice == 0 {
        return vec![ConeTracePush {
            emitter_count: emitters,
            ..Default::default()
        }];
    }
    let cones = lattice.div_ceil(LATTICE_CONES_PER_DISPATCH);
    let lights = emitters.div_ceil(EMITTERS_PER_DISPATCH);
    let mut shares: Vec<ConeTracePush> = (0..cones)
        .map(|i| ConeTracePush {
            first_cone: lattice * i / cones,
            cone_count: lattice * (i + 1) / cones - lattice * i / cones,
            ..Default::default()
        })
        .collect();
    for i in 0..lights {
        let (first_emitter, emitter_count) = (
            emitters * i / lights,
            emitters * (i + 1) / lights - emitters * i / lights,
        );
        shares.push(ConeTracePush {
            first_cone: lattice,
            first_emitter,
            emitter_count,
            ..Default::default()
        });
    }
    shares
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every lattice cone and every emitter is traced once, no dispatch takes more than
    /// its share or both kinds, only the first starts afresh (first cone and first
    /// emitter 0), and without the lattice one dispatch takes every emitter.
    #[test]
    fn the_lattice_and_the_emitters_are_shared_out_whole() {
        for lattice in [0, 32, 48, 72, 73, 96, 256] {
            for emitters in [0, 1, 8, 9, 64] {
                let shares = shares(lattice, emitters);
                let (mut cone, mut emitter) = (0, 0);
                for (i, share) in shares.iter().enumerate() {
                    assert_eq!(share.first_cone, cone.min(lattice));
                    assert_eq!(share.first_emitter, emitter);
                    assert!(share.cone_count <= LATTICE_CONES_PER_DISPATCH);
                    assert!(lattice == 0 || share.emitter_count <= EMITTERS_PER_DISPATCH);
                    assert!(share.cone_count == 0 || share.emitter_count == 0);
                    let fresh = share.first_cone == 0 && share.first_emitter == 0;
                    assert_eq!(fresh, i == 0);
                    cone += share.cone_count;
                    emitter += share.emitter_count;
                }
                assert_eq!((cone, emitter), (lattice, emitters));
                let later = if lattice == 0 {
                    0
                } else {
                    emitters.div_ceil(EMITTERS_PER_DISPATCH)
                };
                assert_eq!(
                    shares.len() as u32,
                    lattice.div_ceil(LATTICE_CONES_PER_DISPATCH).max(1) + later
                );
            }
        }
    }
}
