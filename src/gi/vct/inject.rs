//! Light injection (deferred voxel shading): direct light into every occupied voxel.

use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use super::{PipelineBase, StoreShaders};
use crate::gpu_layout::{self as layout, InjectPush};
use crate::vk::{Context, Pipeline};

pub struct InjectPass {
    pipeline: Pipeline,
    bounce: Pipeline,
}

impl InjectPass {
    /// `base` makes the pipelines; `shaders` are the store's variants.
    pub fn new(ctx: &Arc<Context>, base: PipelineBase, shaders: &StoreShaders) -> Result<Self> {
        let push = std::mem::size_of::<InjectPush>() as u32;
        let pipeline = base.compute(ctx, "inject", shaders.inject, push)?;
        let bounce = base.compute(ctx, "bounce", shaders.bounce, 0)?;
        Ok(Self { pipeline, bounce })
    }

    /// Shades the voxels of the occupied-voxel list (`list`, which holds the dispatch)
    /// that `push` asks for: every one, or those whose light can have changed.
    pub fn record(
        &self,
        cmd: vk::CommandBuffer,
        frame_set: vk::DescriptorSet,
        set: vk::DescriptorSet,
        list: vk::Buffer,
        push: &InjectPush,
    ) {
        let sets = [(layout::SET_FRAME, frame_set), (layout::SET_GI, set)];
        self.pipeline.push(cmd, vk::ShaderStageFlags::COMPUTE, push);
        self.pipeline.dispatch_indirect(cmd, &sets, list, 0);
    }

    /// One more bounce: direct + albedo x gathered filtered radiance, into the radiance,
    /// for the voxels of the occupied-voxel list, dispatched from `(buffer, offset)`: the
    /// list's head, or a static octree's bounce dispatch (none once converged).
    pub fn record_bounce(
        &self,
        cmd: vk::CommandBuffer,
        frame_set: vk::DescriptorSet,
        set: vk::DescriptorSet,
        (buffer, offset): (vk::Buffer, vk::DeviceSize),
    ) {
        let sets = [(layout::SET_FRAME, frame_set), (layout::SET_GI, set)];
        self.bounce.dispatch_indirect(cmd, &sets, buffer, offset);
    }
}
