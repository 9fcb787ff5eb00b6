//! The occupied-voxel list (`glsl/gi/vct/voxel_list.glsl`), filled by each store (the
//! dense grid's compact pass, the octree's brick list) and run over by voxel shading and
//! the bounces.

use ash::vk;

use crate::gpu_layout::VoxelListHeader;
use crate::vk::{update_buffer, Context};

/// Empties an occupied-voxel list (`glsl/gi/vct/voxel_list.glsl`) before the compute pass
/// that fills it: no entries, and an indirect dispatch of no workgroups.
pub fn reset_voxel_list(ctx: &Context, cmd: vk::CommandBuffer, list: vk::Buffer) {
    let empty = VoxelListHeader {
        groups_x: 0,
        groups_y: 1,
        groups_z: 1,
        count: 0,
    };
    update_buffer(
        ctx,
        cmd,
        list,
        0,
        bytemuck::bytes_of(&empty),
        vk::PipelineStageFlags2::COMPUTE_SHADER,
    );
}
