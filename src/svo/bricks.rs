//! The bricks (`glsl/svo/bricks/`): leaf bricks filled from the voxel fragments
//! (`fill.comp`), the list of occupied leaf voxels that voxel shading runs over
//! (`compact.comp`), interior bricks filtered bottom-up (`filter.comp`) and every brick's
//! border copied from its neighbours (`apron.comp`).
//!
//! A brick holds its node's 2x2x2 voxels at voxel centres, exactly as the dense grid holds
//! them, so both paths read the same values and share their CPU references; the radiance
//! bricks add a border of one voxel (4x4x4 texels) so that hardware trilinear filtering
//! anywhere inside the node needs no other brick. Crassin's 3x3x3 bricks with values at
//! node corners use fewer texels, but their samples sit at other places than the dense
//! grid's, and the two paths could no longer be checked against each other voxel for
//! voxel.

use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use super::octree::{dispatch_for_level, Over};
use crate::gi::compute_to_compute;
use crate::gpu_layout::SvoPush;
use crate::vk::{Context, Pipeline};

pub struct BrickPasses {
    fill: Pipeline,
    list: Pipeline,
    filter: Pipeline,
    apron: Pipeline,
}

impl BrickPasses {
    /// `set_layouts` are those of sets 0, 1 and 2.
    pub fn new(ctx: &Arc<Context>, set_layouts: [vk::DescriptorSetLayout; 3]) -> Result<Self> {
        let push = std::mem::size_of::<SvoPush>() as u32;
        let pipeline = |name, spirv| Pipeline::compute(ctx, name, spirv, &set_layouts, push);
        use crate::vk::shaders as s;
        Ok(Self {
            fill: pipeline("svo fill", s::SVO_BRICKS_FILL_COMP)?,
            list: pipeline("svo voxel list", s::SVO_BRICKS_COMPACT_COMP)?,
            filter: pipeline("svo filter", s::SVO_BRICKS_FILTER_COMP)?,
            apron: pipeline("svo apron", s::SVO_BRICKS_APRON_COMP)?,
        })
    }

    /// One invocation per stored fragment; `counters` holds the dispatch at its start.
    pub fn record_fill(
        &self,
        cmd: vk::CommandBuffer,
        sets: &[(u32, vk::DescriptorSet)],
        counters: vk::Buffer,
    ) {
        self.fill.dispatch_indirect(cmd, sets, counters, 0);
    }

    /// Lists the occupied voxels of the leaves, at `leaf_level`.
    pub fn record_list(
        &self,
        cmd: vk::CommandBuffer,
        sets: &[(u32, vk::DescriptorSet)],
        counters: vk::Buffer,
        leaf_level: u32,
    ) {
        dispatch_for_level(&self.list, cmd, sets, leaf_level, counters, Over::Level);
    }

    /// Borders of the leaves, then each level above filtered from the one below and
    /// given its borders, up to the root.
    pub fn record_filter(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        sets: &[(u32, vk::DescriptorSet)],
        counters: vk::Buffer,
        depth: u32,
    ) {
        let leaves = depth - 1;
        dispatch_for_level(&self.apron, cmd, sets, leaves, counters, Over::Level);
        for level in (0..leaves).rev() {
            compute_to_compute(ctx, cmd);
            dispatch_for_level(&self.filter, cmd, sets, level, counters, Over::Level);
            compute_to_compute(ctx, cmd);
            dispatch_for_level(&self.apron, cmd, sets, level, counters, Over::Level);
        }
    }
}
