//! The octree build, level by level (Crassin & Green 2012; Dřínovský 2013, 5.2.3):
//! per level, flag the nodes the voxel fragments reach (`glsl/gi/vct/octree/nodes/flag.comp`),
//! allocate bricks and child tiles for the flagged ones (`alloc.comp`), enter the new
//! level into the level table (`level.comp`) and initialise its nodes (`init.comp`);
//! then link every node to its six neighbours (`neighbours.comp`). A frame with moving
//! meshes runs the same passes over their fragments only, on top of the static part
//! (Dřínovský 2013, 5.7): new nodes are appended to each level's static run.

use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use crate::gi::vct::PipelineBase;
use crate::gpu_layout::{self as layout, OctreeCounters, OctreeLevel, OctreePush};
use crate::vk::{compute_to_compute, memory_barrier, Context, GpuTimer, Pipeline};

/// Byte offset of level `level`'s entry (its indirect dispatch) in the counters buffer.
pub fn level_offset(level: u32) -> vk::DeviceSize {
    (std::mem::size_of::<OctreeCounters>() + level as usize * std::mem::size_of::<OctreeLevel>())
        as vk::DeviceSize
}

/// Cells of the node grid of an octree of `depth` levels (`BINDING_OCTREE_NODE_GRID`).
pub fn node_grid_cells(depth: u32) -> u32 {
    1 << (3 * (depth - 1 - layout::OCTREE_NODE_GRID_ABOVE_LEAVES))
}

/// What a pass over the octree runs over: one invocation per item.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Over {
    /// The voxel fragments the octree passes read (from `OctreeCounters::fragment_base`).
    Fragments,
    /// Every node of the level: its static run, then its appended one.
    Level,
    /// The level's appended nodes only (new this build or frame).
    Appended,
}

/// Pushes `level` to `pipeline`, binds it with `sets` and dispatches it indirectly over
/// `over`, whose workgroup counts `counters` holds.
pub fn dispatch_for_level(
    pipeline: &Pipeline,
    cmd: vk::CommandBuffer,
    sets: &[(u32, vk::DescriptorSet)],
    level: u32,
    counters: vk::Buffer,
    over: Over,
) {
    let push = OctreePush {
        level,
        over: if over == Over::Appended {
            layout::OCTREE_OVER_APPENDED
        } else {
            layout::OCTREE_OVER_LEVEL
        },
        ..Default::default()
    };
    let offset = match over {
        Over::Fragments => 0,
        Over::Level => level_offset(level),
        Over::Appended => {
            level_offset(level) + std::mem::offset_of!(OctreeLevel, appended_groups_x) as u64
        }
    };
    push_and_dispatch(pipeline, cmd, sets, &push, counters, offset);
}

/// Pushes `push` to `pipeline`, binds it with `sets` and dispatches it with the workgroup
/// counts at `offset` in `buffer`.
pub(super) fn push_and_dispatch(
    pipeline: &Pipeline,
    cmd: vk::CommandBuffer,
    sets: &[(u32, vk::DescriptorSet)],
    push: &OctreePush,
    buffer: vk::Buffer,
    offset: u64,
) {
    pipeline.push(cmd, vk::ShaderStageFlags::COMPUTE, push);
    pipeline.dispatch_indirect(cmd, sets, buffer, offset);
}

/// Records `pass` as GPU pass `name`: timed, and followed by a barrier to the next
/// compute pass.
pub fn timed_pass(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    timer: &mut GpuTimer,
    name: &str,
    pass: impl FnOnce(),
) {
    timer.begin(cmd, name);
    pass();
    compute_to_compute(ctx, cmd);
    timer.end(cmd);
}

pub struct NodePasses {
    flag: Pipeline,
    alloc: Pipeline,
    level: Pipeline,
    init: Pipeline,
    neighbours: Pipeline,
    grid: Pipeline,
}

/// Makes the level table written by a compute pass readable as indirect dispatches and by
/// the next compute pass.
pub(super) fn compute_to_indirect(ctx: &Context, cmd: vk::CommandBuffer) {
    memory_barrier(
        ctx,
        cmd,
        (
            vk::PipelineStageFlags2::COMPUTE_SHADER,
            vk::AccessFlags2::SHADER_WRITE,
        ),
        (
            vk::PipelineStageFlags2::COMPUTE_SHADER | vk::PipelineStageFlags2::DRAW_INDIRECT,
            vk::AccessFlags2::SHADER_READ
                | vk::AccessFlags2::SHADER_WRITE
                | vk::AccessFlags2::INDIRECT_COMMAND_READ,
        ),
    );
}

impl NodePasses {
    pub fn new(ctx: &Arc<Context>, base: PipelineBase) -> Result<Self> {
        let push = std::mem::size_of::<OctreePush>() as u32;
        let pipeline = |name, spirv| base.compute(ctx, name, spirv, push);
        use crate::vk::shaders as s;
        Ok(Self {
            flag: pipeline("octree flag", s::GI_VCT_OCTREE_NODES_FLAG_COMP)?,
            alloc: pipeline("octree alloc", s::GI_VCT_OCTREE_NODES_ALLOC_COMP)?,
            level: pipeline("octree level", s::GI_VCT_OCTREE_NODES_LEVEL_COMP)?,
            init: pipeline("octree init", s::GI_VCT_OCTREE_NODES_INIT_COMP)?,
            neighbours: pipeline("octree neighbours", s::GI_VCT_OCTREE_NODES_NEIGHBOURS_COMP)?,
            grid: pipeline("octree node grid", s::GI_VCT_OCTREE_NODES_GRID_COMP)?,
        })
    }

    /// Enters the nodes (or gaps) of level `node_grid_level(depth)` into the node grid,
    /// once the octree's levels are built.
    pub fn record_grid(
        &self,
        cmd: vk::CommandBuffer,
        sets: &[(u32, vk::DescriptorSet)],
        depth: u32,
    ) {
        let cells = node_grid_cells(depth);
        self.grid
            .dispatch(cmd, sets, [cells.div_ceil(layout::OCTREE_GROUP_SIZE), 1, 1]);
    }

    /// Builds levels 1 to `depth - 1` under the root (whose entries and level-table rows
    /// the caller wrote: the root alone for a build, the static part for a frame) from
    /// the voxel fragments, then the neighbour pointers of the nodes in `neighbours`
    /// (every node in a build; the appended ones in a frame, as the static nodes' links
    /// to each other hold, and a missing link is searched from the root). `counters`
    /// holds the indirect dispatches.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        timer: &mut GpuTimer,
        sets: &[(u32, vk::DescriptorSet)],
        counters: vk::Buffer,
        depth: u32,
        neighbours: Over,
    ) {
        for level in 0..depth {
            timed_pass(ctx, cmd, timer, &format!("flag {level}"), || {
                dispatch_for_level(&self.flag, cmd, sets, level, counters, Over::Fragments)
            });
            timed_pass(ctx, cmd, timer, &format!("alloc {level}"), || {
                dispatch_for_level(&self.alloc, cmd, sets, level, counters, Over::Level)
            });

            if level + 1 < depth {
                let child = level + 1;
                timer.begin(cmd, &format!("init {child}"));
                let push = OctreePush {
                    level: child,
                    ..Default::default()
                };
                self.level.push(cmd, vk::ShaderStageFlags::COMPUTE, &push);
                self.level.dispatch(cmd, sets, [1, 1, 1]);
                compute_to_indirect(ctx, cmd);
                dispatch_for_level(&self.init, cmd, sets, child, counters, Over::Appended);
                compute_to_compute(ctx, cmd);
                timer.end(cmd);
            }
        }
        timer.begin(cmd, "neighbours");
        for level in 0..depth {
            dispatch_for_level(&self.neighbours, cmd, sets, level, counters, neighbours);
        }
        compute_to_compute(ctx, cmd);
        timer.end(cmd);
    }
}
