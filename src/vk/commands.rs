//! Barriers (synchronization2) and one-off command submission for uploads and read-backs.

use std::sync::Arc;

use anyhow::{Context as _, Result};
use ash::vk;

use super::{Buffer, Context, Image};

/// The colour aspect of mip level 0, layer 0: a swapchain image or a 2D render target.
pub const COLOR_TARGET_RANGE: vk::ImageSubresourceRange = vk::ImageSubresourceRange {
    aspect_mask: vk::ImageAspectFlags::COLOR,
    base_mip_level: 0,
    level_count: 1,
    base_array_layer: 0,
    layer_count: 1,
};

/// One side of an image barrier: a layout with the stages and accesses that use it.
#[derive(Clone, Copy, Debug)]
pub struct ImageUse {
    pub layout: vk::ImageLayout,
    pub stage: vk::PipelineStageFlags2,
    pub access: vk::AccessFlags2,
}

impl ImageUse {
    /// Contents are not needed (first use in a frame).
    pub const UNDEFINED: Self = Self {
        layout: vk::ImageLayout::UNDEFINED,
        stage: vk::PipelineStageFlags2::TOP_OF_PIPE,
        access: vk::AccessFlags2::NONE,
    };
    pub const COLOR_ATTACHMENT: Self = Self {
        layout: vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
        stage: vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
        access: vk::AccessFlags2::from_raw(
            vk::AccessFlags2::COLOR_ATTACHMENT_WRITE.as_raw()
                | vk::AccessFlags2::COLOR_ATTACHMENT_READ.as_raw(),
        ),
    };
    pub const DEPTH_ATTACHMENT: Self = Self {
        layout: vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL,
        stage: vk::PipelineStageFlags2::from_raw(
            vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS.as_raw()
                | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS.as_raw(),
        ),
        access: vk::AccessFlags2::from_raw(
            vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE.as_raw()
                | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ.as_raw(),
        ),
    };
    pub const COMPUTE_READ: Self = Self {
        layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
        stage: vk::PipelineStageFlags2::COMPUTE_SHADER,
        access: vk::AccessFlags2::SHADER_READ,
    };
    pub const COMPUTE_STORAGE_READ: Self = Self {
        layout: vk::ImageLayout::GENERAL,
        stage: vk::PipelineStageFlags2::COMPUTE_SHADER,
        access: vk::AccessFlags2::SHADER_STORAGE_READ,
    };
    pub const COMPUTE_WRITE: Self = Self {
        layout: vk::ImageLayout::GENERAL,
        stage: vk::PipelineStageFlags2::COMPUTE_SHADER,
        access: vk::AccessFlags2::SHADER_STORAGE_WRITE,
    };
    pub const FRAGMENT_READ: Self = Self {
        layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
        stage: vk::PipelineStageFlags2::FRAGMENT_SHADER,
        access: vk::AccessFlags2::SHADER_SAMPLED_READ,
    };
    /// Sampled by any later shader (uploaded textures).
    pub const ANY_SHADER_READ: Self = Self {
        layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
        stage: vk::PipelineStageFlags2::ALL_COMMANDS,
        access: vk::AccessFlags2::SHADER_SAMPLED_READ,
    };
    pub const DEPTH_READ: Self = Self {
        layout: vk::ImageLayout::DEPTH_READ_ONLY_OPTIMAL,
        stage: vk::PipelineStageFlags2::from_raw(
            vk::PipelineStageFlags2::COMPUTE_SHADER.as_raw()
                | vk::PipelineStageFlags2::FRAGMENT_SHADER.as_raw(),
        ),
        access: vk::AccessFlags2::SHADER_SAMPLED_READ,
    };
    pub const TRANSFER_SRC: Self = Self {
        layout: vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
        stage: vk::PipelineStageFlags2::COPY,
        access: vk::AccessFlags2::TRANSFER_READ,
    };
    /// Copies, blits and clears.
    pub const TRANSFER_DST: Self = Self {
        layout: vk::ImageLayout::TRANSFER_DST_OPTIMAL,
        stage: vk::PipelineStageFlags2::ALL_TRANSFER,
        access: vk::AccessFlags2::TRANSFER_WRITE,
    };
    /// The layout transition must be in a stage the frame's semaphore signal (stage
    /// ALL_COMMANDS) waits for, or present reads before it (SYNC-HAZARD-PRESENT-AFTER-WRITE).
    pub const PRESENT: Self = Self {
        layout: vk::ImageLayout::PRESENT_SRC_KHR,
        stage: vk::PipelineStageFlags2::ALL_COMMANDS,
        access: vk::AccessFlags2::NONE,
    };
}

/// Records one image layout transition with its dependency.
pub fn image_barrier(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    image: vk::Image,
    range: vk::ImageSubresourceRange,
    from: ImageUse,
    to: ImageUse,
) {
    let barrier = vk::ImageMemoryBarrier2::default()
        .image(image)
        .subresource_range(range)
        .old_layout(from.layout)
        .new_layout(to.layout)
        .src_stage_mask(from.stage)
        .src_access_mask(from.access)
        .dst_stage_mask(to.stage)
        .dst_access_mask(to.access);
    let barriers = [barrier];
    let dependency = vk::DependencyInfo::default().image_memory_barriers(&barriers);
    unsafe { ctx.device.cmd_pipeline_barrier2(cmd, &dependency) };
}

/// Records a global memory dependency (buffers, or images whose layout stays).
pub fn memory_barrier(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    src: (vk::PipelineStageFlags2, vk::AccessFlags2),
    dst: (vk::PipelineStageFlags2, vk::AccessFlags2),
) {
    let barrier = [vk::MemoryBarrier2::default()
        .src_stage_mask(src.0)
        .src_access_mask(src.1)
        .dst_stage_mask(dst.0)
        .dst_access_mask(dst.1)];
    let dependency = vk::DependencyInfo::default().memory_barriers(&barrier);
    unsafe { ctx.device.cmd_pipeline_barrier2(cmd, &dependency) };
}

/// Every memory write by the stages `from` before it is visible to every read and write by
/// the stages `to` after it.
pub fn stage_barrier(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    from: vk::PipelineStageFlags2,
    to: vk::PipelineStageFlags2,
) {
    memory_barrier(
        ctx,
        cmd,
        (from, vk::AccessFlags2::MEMORY_WRITE),
        (
            to,
            vk::AccessFlags2::MEMORY_READ | vk::AccessFlags2::MEMORY_WRITE,
        ),
    );
}

/// A global barrier between two compute passes: writes before are visible to reads and
/// writes after.
pub fn compute_to_compute(ctx: &Context, cmd: vk::CommandBuffer) {
    let compute = vk::PipelineStageFlags2::COMPUTE_SHADER;
    memory_barrier(
        ctx,
        cmd,
        (compute, vk::AccessFlags2::SHADER_WRITE),
        (
            compute,
            vk::AccessFlags2::SHADER_READ | vk::AccessFlags2::SHADER_WRITE,
        ),
    );
}

/// Moves new `images` into the layout compute passes write them in, and waits.
pub fn to_compute_write(ctx: &Arc<Context>, name: &str, images: &[&Image]) -> Result<()> {
    OneShot::new(ctx)?.run(name, |cmd| {
        for image in images {
            image_barrier(
                ctx,
                cmd,
                image.raw,
                image.full_range(),
                ImageUse::UNDEFINED,
                ImageUse::COMPUTE_WRITE,
            );
        }
        Ok(())
    })
}

/// Clears every level and layer of a colour image to zero (all bits: any format), which
/// was in state `before` and is left in state `after`; its contents are discarded.
pub fn clear_to_zero(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    image: &Image,
    before: ImageUse,
    after: ImageUse,
) {
    let range = image.full_range();
    image_barrier(
        ctx,
        cmd,
        image.raw,
        range,
        ImageUse::discard_after(before),
        ImageUse::TRANSFER_DST,
    );
    let zero = vk::ClearColorValue { uint32: [0; 4] };
    unsafe {
        ctx.device.cmd_clear_color_image(
            cmd,
            image.raw,
            vk::ImageLayout::TRANSFER_DST_OPTIMAL,
            &zero,
            &[range],
        )
    };
    image_barrier(ctx, cmd, image.raw, range, ImageUse::TRANSFER_DST, after);
}

/// Records a copy of mip 0, layer 0 of a colour image in TRANSFER_SRC layout to `buffer`,
/// made visible to the host.
pub fn copy_image_to_buffer(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    image: vk::Image,
    extent: vk::Extent2D,
    buffer: vk::Buffer,
) {
    let region = vk::BufferImageCopy {
        buffer_offset: 0,
        buffer_row_length: 0,
        buffer_image_height: 0,
        image_subresource: vk::ImageSubresourceLayers {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            mip_level: 0,
            base_array_layer: 0,
            layer_count: 1,
        },
        image_offset: vk::Offset3D::default(),
        image_extent: vk::Extent3D {
            width: extent.width,
            height: extent.height,
            depth: 1,
        },
    };
    unsafe {
        ctx.device.cmd_copy_image_to_buffer(
            cmd,
            image,
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
            buffer,
            &[region],
        )
    };
    copies_to_host_barrier(ctx, cmd);
}

/// Makes the copies recorded before it visible to host reads of their buffers (after the
/// submit is waited for).
pub fn copies_to_host_barrier(ctx: &Context, cmd: vk::CommandBuffer) {
    memory_barrier(
        ctx,
        cmd,
        (
            vk::PipelineStageFlags2::COPY,
            vk::AccessFlags2::TRANSFER_WRITE,
        ),
        (vk::PipelineStageFlags2::HOST, vk::AccessFlags2::HOST_READ),
    );
}

/// A command pool for work submitted once and waited for (uploads, read-backs).
pub struct OneShot {
    pool: vk::CommandPool,
    ctx: Arc<Context>,
}

impl OneShot {
    pub fn new(ctx: &Arc<Context>) -> Result<Self> {
        let info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(ctx.queue_family)
            .flags(vk::CommandPoolCreateFlags::TRANSIENT);
        let pool = unsafe { ctx.device.create_command_pool(&info, None) }?;
        Ok(Self {
            pool,
            ctx: ctx.clone(),
        })
    }

    /// Records with `record`, submits, and waits until the GPU is done.
    pub fn run(
        &self,
        name: &str,
        record: impl FnOnce(vk::CommandBuffer) -> Result<()>,
    ) -> Result<()> {
        let ctx = &self.ctx;
        let info = vk::CommandBufferAllocateInfo::default()
            .command_pool(self.pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        let cmd = unsafe { ctx.device.allocate_command_buffers(&info) }?[0];
        let result = (|| {
            let begin = vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            unsafe { ctx.device.begin_command_buffer(cmd, &begin) }?;
            ctx.begin_label(cmd, name);
            record(cmd)?;
            ctx.end_label(cmd);
            unsafe { ctx.device.end_command_buffer(cmd) }?;
            let fence = unsafe {
                ctx.device
                    .create_fence(&vk::FenceCreateInfo::default(), None)
            }?;
            let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
            let submit = [vk::SubmitInfo2::default().command_buffer_infos(&cmds)];
            let waited = unsafe {
                ctx.device
                    .queue_submit2(ctx.queue, &submit, fence)
                    .and_then(|_| ctx.device.wait_for_fences(&[fence], true, u64::MAX))
            };
            unsafe { ctx.device.destroy_fence(fence, None) };
            waited.with_context(|| format!("GPU work '{name}' failed"))
        })();
        unsafe { ctx.device.free_command_buffers(self.pool, &[cmd]) };
        result
    }
}

impl Drop for OneShot {
    fn drop(&mut self) {
        unsafe { self.ctx.device.destroy_command_pool(self.pool, None) };
    }
}

/// Writes `data` into `buffer` at byte `offset` from the command buffer, visible to
/// shader reads and writes (and indirect dispatches) in `readers` after it.
pub fn update_buffer(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    buffer: vk::Buffer,
    offset: u64,
    data: &[u8],
    readers: vk::PipelineStageFlags2,
) {
    // vkCmdUpdateBuffer takes 64 KiB at most.
    const CHUNK: usize = 65536;
    for (i, chunk) in data.chunks(CHUNK).enumerate() {
        unsafe {
            ctx.device
                .cmd_update_buffer(cmd, buffer, offset + (i * CHUNK) as u64, chunk)
        };
    }
    let mut access = vk::AccessFlags2::SHADER_READ | vk::AccessFlags2::SHADER_WRITE;
    if readers.contains(vk::PipelineStageFlags2::DRAW_INDIRECT) {
        access |= vk::AccessFlags2::INDIRECT_COMMAND_READ;
    }
    memory_barrier(
        ctx,
        cmd,
        (
            vk::PipelineStageFlags2::ALL_TRANSFER,
            vk::AccessFlags2::TRANSFER_WRITE,
        ),
        (readers, access),
    );
}

/// Copies `buffer` (written by any earlier shader) to the host and returns its bytes,
/// once the GPU is done with it.
pub fn read_back_buffer(ctx: &Arc<Context>, buffer: &Buffer) -> Result<Vec<u8>> {
    let readback = Buffer::new(
        ctx,
        "readback",
        buffer.size,
        vk::BufferUsageFlags::TRANSFER_DST,
        gpu_allocator::MemoryLocation::GpuToCpu,
    )?;
    OneShot::new(ctx)?.run("read back buffer", |cmd| {
        memory_barrier(
            ctx,
            cmd,
            (
                vk::PipelineStageFlags2::ALL_COMMANDS,
                vk::AccessFlags2::SHADER_STORAGE_WRITE,
            ),
            (
                vk::PipelineStageFlags2::COPY,
                vk::AccessFlags2::TRANSFER_READ,
            ),
        );
        let region = vk::BufferCopy::default().size(buffer.size);
        unsafe {
            ctx.device
                .cmd_copy_buffer(cmd, buffer.raw, readback.raw, &[region])
        };
        copies_to_host_barrier(ctx, cmd);
        Ok(())
    })?;
    Ok(readback.mapped().to_vec())
}

/// Copies mip `level` of `image` (its first `extent`, texels x fastest) to the host and
/// returns its bytes, once the GPU is done with it; the image is in state `around` before
/// and after.
pub fn read_back_image(
    ctx: &Arc<Context>,
    image: &Image,
    level: u32,
    extent: vk::Extent3D,
    texel_bytes: u64,
    around: ImageUse,
) -> Result<Vec<u8>> {
    let bytes =
        texel_bytes * u64::from(extent.width) * u64::from(extent.height) * u64::from(extent.depth);
    let readback = Buffer::new(
        ctx,
        "image readback",
        bytes,
        vk::BufferUsageFlags::TRANSFER_DST,
        gpu_allocator::MemoryLocation::GpuToCpu,
    )?;
    let range = vk::ImageSubresourceRange {
        aspect_mask: vk::ImageAspectFlags::COLOR,
        base_mip_level: level,
        level_count: 1,
        base_array_layer: 0,
        layer_count: 1,
    };
    OneShot::new(ctx)?.run("read back image", |cmd| {
        image_barrier(ctx, cmd, image.raw, range, around, ImageUse::TRANSFER_SRC);
        let region = vk::BufferImageCopy {
            image_subresource: vk::ImageSubresourceLayers {
                aspect_mask: vk::ImageAspectFlags::COLOR,
                mip_level: level,
                base_array_layer: 0,
                layer_count: 1,
            },
            image_extent: extent,
            ..Default::default()
        };
        unsafe {
            ctx.device.cmd_copy_image_to_buffer(
                cmd,
                image.raw,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                readback.raw,
                &[region],
            )
        };
        image_barrier(ctx, cmd, image.raw, range, ImageUse::TRANSFER_SRC, around);
        copies_to_host_barrier(ctx, cmd);
        Ok(())
    })?;
    Ok(readback.mapped().to_vec())
}

impl ImageUse {
    /// Contents not needed, after a use in `stage` (the previous frame's last use) that the
    /// layout transition must wait for.
    pub fn discard_after(previous: ImageUse) -> Self {
        Self {
            layout: vk::ImageLayout::UNDEFINED,
            stage: previous.stage,
            access: vk::AccessFlags2::NONE,
        }
    }
}
