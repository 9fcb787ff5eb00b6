//! The dense grid's compact pass (`glsl/gi/vct/dense/compact.comp`): the voxels' means from
//! their fragment sums, and the occupied-voxel list that voxel shading and the bounces run
//! over, one invocation per occupied voxel, dispatched indirectly from its head.

use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use crate::gi::vct::voxel_list::reset_voxel_list;
use crate::gi::vct::PipelineBase;
use crate::gpu_layout::{self as layout, VoxelListHeader};
use crate::vk::{groups_3d, memory_barrier, Buffer, Context, Pipeline};

pub struct CompactPass {
    pipeline: Pipeline,
    /// `VoxelListHeader` then one `u32` per voxel of the grid (all may be occupied).
    pub list: Buffer,
}

impl CompactPass {
    /// `base` makes the pipeline; `n` is the grid resolution.
    pub fn new(ctx: &Arc<Context>, base: PipelineBase, n: u32) -> Result<Self> {
        let pipeline = base.compute(
            ctx,
            "compact",
            crate::vk::shaders::GI_VCT_DENSE_COMPACT_COMP,
            0,
        )?;
        let header = std::mem::size_of::<VoxelListHeader>() as u64;
        let list = Buffer::new(
            ctx,
            "voxel list",
            header + 4 * u64::from(n).pow(3),
            // TRANSFER_SRC: the check against the occupancy downloads it.
            vk::BufferUsageFlags::STORAGE_BUFFER
                | vk::BufferUsageFlags::INDIRECT_BUFFER
                | vk::BufferUsageFlags::TRANSFER_DST
                | vk::BufferUsageFlags::TRANSFER_SRC,
            gpu_allocator::MemoryLocation::GpuOnly,
        )?;
        Ok(Self { pipeline, list })
    }

    /// Takes the means of the fragment sums and rebuilds the list (after voxelization).
    /// Waits for last frame's bounces, which read the list.
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        frame_set: vk::DescriptorSet,
        set: vk::DescriptorSet,
        n: u32,
    ) {
        let readers =
            vk::PipelineStageFlags2::COMPUTE_SHADER | vk::PipelineStageFlags2::DRAW_INDIRECT;
        memory_barrier(
            ctx,
            cmd,
            (
                readers,
                vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::INDIRECT_COMMAND_READ,
            ),
            (
                vk::PipelineStageFlags2::ALL_TRANSFER,
                vk::AccessFlags2::TRANSFER_WRITE,
            ),
        );
        reset_voxel_list(ctx, cmd, self.list.raw);
        let sets = [(layout::SET_FRAME, frame_set), (layout::SET_GI, set)];
        self.pipeline
            .dispatch(cmd, &sets, groups_3d(n, layout::VOXEL_GROUP_SIZE));
        // The list, the means and the zeroed radiance, read (the radiance also sampled)
        // and written by the passes after.
        memory_barrier(
            ctx,
            cmd,
            (
                vk::PipelineStageFlags2::COMPUTE_SHADER,
                vk::AccessFlags2::SHADER_STORAGE_WRITE,
            ),
            (
                readers,
                vk::AccessFlags2::SHADER_READ
                    | vk::AccessFlags2::SHADER_WRITE
                    | vk::AccessFlags2::INDIRECT_COMMAND_READ,
            ),
        );
    }
}
