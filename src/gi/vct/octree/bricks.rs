//! The bricks (`glsl/gi/vct/octree/bricks/`): leaf bricks filled from the voxel fragments
//! (`fill.comp`), the list of occupied leaf voxels that voxel shading runs over
//! (`compact.comp`), interior bricks filtered bottom-up (`filter.comp`) and every brick's
//! border copied from its neighbours (`apron.comp`); after voxel shading, either all of
//! them or only the nodes on the update lists (`spread.comp` builds them level by level
//! from the leaves whose radiance changed).
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

use super::nodes::{compute_to_indirect, dispatch_for_level, push_and_dispatch, timed_pass, Over};
use crate::gi::vct::PipelineBase;
use crate::gpu_layout::{self as layout, OctreePush, OctreeUpdateList};
use crate::vk::{stage_barrier, Context, GpuTimer, Pipeline};

/// Byte offset of update list `list`'s head (its indirect dispatch) in the update buffer.
fn list_offset(list: u32) -> vk::DeviceSize {
    u64::from(list) * std::mem::size_of::<OctreeUpdateList>() as u64
}

/// Pushes `level` to `pipeline` and dispatches it over update list `list` of `updates`.
fn dispatch_for_list(
    pipeline: &Pipeline,
    cmd: vk::CommandBuffer,
    sets: &[(u32, vk::DescriptorSet)],
    level: u32,
    updates: vk::Buffer,
    list: u32,
) {
    let push = OctreePush {
        level,
        over: layout::OCTREE_OVER_LIST,
        list,
        ..Default::default()
    };
    push_and_dispatch(pipeline, cmd, sets, &push, updates, list_offset(list));
}

pub struct BrickPasses {
    fill: Pipeline,
    list: Pipeline,
    filter: Pipeline,
    apron: Pipeline,
    spread: Pipeline,
    mark: Pipeline,
    /// Workgroups that share each node of an update list (`OCTREE_LIST_SLICES`; 1 on a CPU
    /// driver, where each workgroup costs more than the work it would share).
    pub(super) list_slices: u32,
}

impl BrickPasses {
    pub fn new(ctx: &Arc<Context>, base: PipelineBase) -> Result<Self> {
        let push = std::mem::size_of::<OctreePush>() as u32;
        let pipeline = |name, spirv| base.compute(ctx, name, spirv, push);
        use crate::vk::shaders as s;
        Ok(Self {
            fill: pipeline("octree fill", s::GI_VCT_OCTREE_BRICKS_FILL_COMP)?,
            list: pipeline("octree voxel list", s::GI_VCT_OCTREE_BRICKS_COMPACT_COMP)?,
            filter: pipeline("octree filter", s::GI_VCT_OCTREE_BRICKS_FILTER_COMP)?,
            apron: pipeline("octree apron", s::GI_VCT_OCTREE_BRICKS_APRON_COMP)?,
            spread: pipeline("octree spread", s::GI_VCT_OCTREE_BRICKS_SPREAD_COMP)?,
            mark: pipeline("octree mark", s::GI_VCT_OCTREE_BRICKS_MARK_COMP)?,
            list_slices: if ctx.is_cpu() {
                1
            } else {
                layout::OCTREE_LIST_SLICES
            },
        })
    }

    /// Records emptying update lists `lists` of `updates` (a transfer, between compute
    /// passes).
    pub fn reset_update_lists(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        updates: vk::Buffer,
        lists: &[u32],
    ) {
        let empty = OctreeUpdateList {
            groups_y: self.list_slices,
            groups_z: 1,
            ..Default::default()
        };
        stage_barrier(
            ctx,
            cmd,
            vk::PipelineStageFlags2::ALL_COMMANDS,
            vk::PipelineStageFlags2::ALL_TRANSFER,
        );
        for &list in lists {
            unsafe {
                ctx.device.cmd_update_buffer(
                    cmd,
                    updates,
                    list_offset(list),
                    bytemuck::bytes_of(&empty),
                )
            };
        }
        stage_barrier(
            ctx,
            cmd,
            vk::PipelineStageFlags2::ALL_TRANSFER,
            vk::PipelineStageFlags2::COMPUTE_SHADER | vk::PipelineStageFlags2::DRAW_INDIRECT,
        );
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
        timer: &mut GpuTimer,
        sets: &[(u32, vk::DescriptorSet)],
        counters: vk::Buffer,
        depth: u32,
    ) {
        for level in (0..depth).rev() {
            if level + 1 < depth {
                timed_pass(ctx, cmd, timer, &format!("filter {level}"), || {
                    dispatch_for_level(&self.filter, cmd, sets, level, counters, Over::Level)
                });
            }
            timed_pass(ctx, cmd, timer, &format!("border {level}"), || {
                dispatch_for_level(&self.apron, cmd, sets, level, counters, Over::Level)
            });
        }
    }

    /// Filters only what changed, bottom-up from the leaves that voxel shading put on
    /// the changed list of their level: per level, the changed nodes put themselves and
    /// their 26 neighbours on the level's border list and their parents on the changed
    /// list above, which the nodes near `region` (voxels of the effective grid, first and
    /// last, where moving meshes were or are) join; the border list gets its borders, the
    /// changed parents are filtered.
    #[allow(clippy::too_many_arguments)]
    pub fn record_update(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        timer: &mut GpuTimer,
        sets: &[(u32, vk::DescriptorSet)],
        (counters, updates): (vk::Buffer, vk::Buffer),
        depth: u32,
        region: Option<[[i32; 3]; 2]>,
    ) {
        let mark = |level: u32| {
            let Some([first, last]) = region else {
                return;
            };
            let push = OctreePush {
                level,
                over: layout::OCTREE_OVER_LEVEL,
                region_min: [first[0], first[1], first[2], 0],
                region_max: [last[0], last[1], last[2], 0],
                ..Default::default()
            };
            self.mark.push(cmd, vk::ShaderStageFlags::COMPUTE, &push);
            let offset = super::nodes::level_offset(level);
            self.mark.dispatch_indirect(cmd, sets, counters, offset);
            compute_to_indirect(ctx, cmd);
        };
        for level in (0..depth).rev() {
            let changed = level & 1;
            let border = 2 + changed;
            let filled: &[u32] = if level > 0 {
                &[border, changed ^ 1]
            } else {
                &[border]
            };
            timer.begin(cmd, &format!("spread {level}"));
            self.reset_update_lists(ctx, cmd, updates, filled);
            if level + 1 == depth {
                mark(level);
            }
            dispatch_for_list(&self.spread, cmd, sets, level, updates, changed);
            compute_to_indirect(ctx, cmd);
            if level > 0 {
                mark(level - 1);
            }
            timer.end(cmd);
            timed_pass(ctx, cmd, timer, &format!("border {level}"), || {
                dispatch_for_list(&self.apron, cmd, sets, level, updates, border)
            });
            if level > 0 {
                timed_pass(ctx, cmd, timer, &format!("filter {}", level - 1), || {
                    dispatch_for_list(&self.filter, cmd, sets, level - 1, updates, changed ^ 1)
                });
            }
        }
    }
}
