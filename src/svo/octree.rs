//! The octree build, level by level (Crassin & Green 2012; Dřínovský 2013, 5.2.3):
//! per level, flag the nodes the voxel fragments reach (`glsl/svo/octree/flag.comp`),
//! allocate bricks and child tiles for the flagged ones (`alloc.comp`), enter the new
//! level into the level table (`level.comp`) and initialise its nodes (`init.comp`);
//! then link every node to its six neighbours (`neighbours.comp`).

use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use crate::gi::compute_to_compute;
use crate::gpu_layout::{SvoCounters, SvoLevel, SvoPush};
use crate::vk::{memory_barrier, Context, GpuTimer, Pipeline};

/// Byte offset of level `level`'s entry (its indirect dispatch) in the counters buffer.
pub fn level_offset(level: u32) -> vk::DeviceSize {
    (std::mem::size_of::<SvoCounters>() + level as usize * std::mem::size_of::<SvoLevel>())
        as vk::DeviceSize
}

pub struct OctreePasses {
    flag: Pipeline,
    alloc: Pipeline,
    level: Pipeline,
    init: Pipeline,
    neighbours: Pipeline,
}

/// Makes the level table written by a compute pass readable as indirect dispatches and by
/// the next compute pass.
fn compute_to_indirect(ctx: &Context, cmd: vk::CommandBuffer) {
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

impl OctreePasses {
    /// `set_layouts` are those of sets 0, 1 and 2.
    pub fn new(ctx: &Arc<Context>, set_layouts: [vk::DescriptorSetLayout; 3]) -> Result<Self> {
        let push = std::mem::size_of::<SvoPush>() as u32;
        let pipeline = |name, spirv| Pipeline::compute(ctx, name, spirv, &set_layouts, push);
        use crate::vk::shaders as s;
        Ok(Self {
            flag: pipeline("svo flag", s::SVO_OCTREE_FLAG_COMP)?,
            alloc: pipeline("svo alloc", s::SVO_OCTREE_ALLOC_COMP)?,
            level: pipeline("svo level", s::SVO_OCTREE_LEVEL_COMP)?,
            init: pipeline("svo init", s::SVO_OCTREE_INIT_COMP)?,
            neighbours: pipeline("svo neighbours", s::SVO_OCTREE_NEIGHBOURS_COMP)?,
        })
    }

    /// Builds levels 1 to `depth - 1` under the root (whose entries and level-table row
    /// the caller wrote) from the voxel fragments, then the neighbour pointers. `counters`
    /// holds the indirect dispatches.
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        timer: &mut GpuTimer,
        sets: &[(u32, vk::DescriptorSet)],
        counters: vk::Buffer,
        depth: u32,
    ) {
        let compute = vk::ShaderStageFlags::COMPUTE;
        for level in 0..depth {
            let push = SvoPush {
                level,
                ..Default::default()
            };
            timer.begin(cmd, &format!("flag {level}"));
            self.flag.bind(cmd, sets);
            self.flag.push(cmd, compute, &push);
            unsafe { ctx.device.cmd_dispatch_indirect(cmd, counters, 0) };
            compute_to_compute(ctx, cmd);
            timer.end(cmd);

            timer.begin(cmd, &format!("alloc {level}"));
            self.alloc.bind(cmd, sets);
            self.alloc.push(cmd, compute, &push);
            unsafe {
                ctx.device
                    .cmd_dispatch_indirect(cmd, counters, level_offset(level))
            };
            compute_to_compute(ctx, cmd);
            timer.end(cmd);

            if level + 1 < depth {
                let child = SvoPush {
                    level: level + 1,
                    ..Default::default()
                };
                timer.begin(cmd, &format!("init {}", level + 1));
                self.level.bind(cmd, sets);
                self.level.push(cmd, compute, &child);
                unsafe { ctx.device.cmd_dispatch(cmd, 1, 1, 1) };
                compute_to_indirect(ctx, cmd);
                self.init.bind(cmd, sets);
                self.init.push(cmd, compute, &child);
                unsafe {
                    ctx.device
                        .cmd_dispatch_indirect(cmd, counters, level_offset(level + 1))
                };
                compute_to_compute(ctx, cmd);
                timer.end(cmd);
            }
        }
        timer.begin(cmd, "neighbours");
        self.neighbours.bind(cmd, sets);
        for level in 0..depth {
            let push = SvoPush {
                level,
                ..Default::default()
            };
            self.neighbours.push(cmd, compute, &push);
            unsafe {
                ctx.device
                    .cmd_dispatch_indirect(cmd, counters, level_offset(level))
            };
        }
        compute_to_compute(ctx, cmd);
        timer.end(cmd);
    }
}
