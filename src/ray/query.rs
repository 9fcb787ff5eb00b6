//! Batched ray queries (`glsl/ray/query.comp`): rays from a storage buffer, their closest
//! or any hits into another, for passes and tools that cast many rays outside a frame.

use std::sync::Arc;

use anyhow::{ensure, Result};
use ash::vk;
use gpu_allocator::MemoryLocation;

use super::SceneRays;
use crate::gpu_layout::{self as layout, RayHit, RayQuery};
use crate::vk::{
    memory_barrier, Binding, Buffer, Context, DescriptorSets, OneShot, Pipeline, SetWriter,
};

/// The query pass with room for `capacity` rays a batch.
pub struct RayQueries {
    pipeline: Pipeline,
    set: vk::DescriptorSet,
    _sets: DescriptorSets,
    /// The layout of sets 0 to 2, which the pass does not read.
    _empty: DescriptorSets,
    queries: Buffer,
    hits: Buffer,
    capacity: usize,
    ctx: Arc<Context>,
}

impl RayQueries {
    /// Queries against `rays`.
    pub fn new(ctx: &Arc<Context>, rays: &SceneRays, capacity: usize) -> Result<Self> {
        ensure!(capacity > 0, "a ray query batch needs room for a ray");
        let storage = vk::DescriptorType::STORAGE_BUFFER;
        let compute = vk::ShaderStageFlags::COMPUTE;
        let mut bindings = SceneRays::bindings();
        bindings.push(Binding::new(layout::BINDING_QUERY_RAYS, storage, compute));
        bindings.push(Binding::new(layout::BINDING_QUERY_HITS, storage, compute));
        let sets = DescriptorSets::new(ctx, "ray queries", &bindings, 1)?;
        let set = sets.allocate("ray queries")?;
        let empty = DescriptorSets::new(ctx, "empty", &[], 1)?;
        let pipeline = Pipeline::compute_specialized(
            ctx,
            "ray_query",
            crate::vk::shaders::RAY_QUERY_COMP,
            &[empty.layout, empty.layout, empty.layout, sets.layout],
            4,
            &rays.features.ray_constants(),
        )?;
        let bytes = |element: usize| (element * capacity) as u64;
        let queries = Buffer::new(
            ctx,
            "ray queries",
            bytes(std::mem::size_of::<RayQuery>()),
            vk::BufferUsageFlags::STORAGE_BUFFER,
            MemoryLocation::CpuToGpu,
        )?;
        let hits = Buffer::new(
            ctx,
            "ray hits",
            bytes(std::mem::size_of::<RayHit>()),
            vk::BufferUsageFlags::STORAGE_BUFFER,
            MemoryLocation::GpuToCpu,
        )?;
        rays.write_set(set);
        SetWriter::new(ctx, set)
            .buffer(layout::BINDING_QUERY_RAYS, storage, queries.raw)
            .buffer(layout::BINDING_QUERY_HITS, storage, hits.raw)
            .apply();
        Ok(Self {
            pipeline,
            set,
            _sets: sets,
            _empty: empty,
            queries,
            hits,
            capacity,
            ctx: ctx.clone(),
        })
    }

    /// Casts `queries` (in batches of the capacity) and waits for their hits.
    pub fn run(&mut self, queries: &[RayQuery]) -> Result<Vec<RayHit>> {
        let mut hits = Vec::with_capacity(queries.len());
        for batch in queries.chunks(self.capacity) {
            self.queries.write(0, bytemuck::cast_slice(batch));
            let count = batch.len() as u32;
            OneShot::new(&self.ctx)?.run("ray queries", |cmd| {
                self.pipeline
                    .push(cmd, vk::ShaderStageFlags::COMPUTE, &count);
                self.pipeline.dispatch(
                    cmd,
                    &[(layout::SET_GI, self.set)],
                    [count.div_ceil(layout::RAY_GROUP_SIZE), 1, 1],
                );
                memory_barrier(
                    &self.ctx,
                    cmd,
                    (
                        vk::PipelineStageFlags2::COMPUTE_SHADER,
                        vk::AccessFlags2::SHADER_STORAGE_WRITE,
                    ),
                    (vk::PipelineStageFlags2::HOST, vk::AccessFlags2::HOST_READ),
                );
                Ok(())
            })?;
            let bytes = &self.hits.mapped()[..batch.len() * std::mem::size_of::<RayHit>()];
            hits.extend(
                bytes
                    .chunks_exact(std::mem::size_of::<RayHit>())
                    .map(bytemuck::pod_read_unaligned::<RayHit>),
            );
        }
        Ok(hits)
    }
}
