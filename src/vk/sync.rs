//! The frame loop's pacing: frames in flight, each waited for through one timeline semaphore.

use std::sync::Arc;

use anyhow::{bail, Context as _, Result};
use ash::vk;

use super::Context;

/// How long the host waits for a frame before calling the GPU stuck. Lavapipe renders a
/// large scene in seconds, but the first frame of a 512³ octree of Sponza, with all its
/// voxel bounces, takes minutes there.
const FRAME_TIMEOUT_NS: u64 = 300_000_000_000;

struct Slot {
    pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    /// Timeline value that the slot's last submit signals.
    value: u64,
}

/// `N` frames in flight. Frame `k` signals timeline value `k + 1`; a slot is reused only
/// once the value its previous frame signals is reached.
pub struct FrameRing {
    pub timeline: vk::Semaphore,
    last_signalled: u64,
    slots: Vec<Slot>,
    current: usize,
    ctx: Arc<Context>,
}

/// The frame being recorded.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    pub slot: usize,
    pub cmd: vk::CommandBuffer,
    /// Timeline value this frame's submit will signal.
    pub value: u64,
}

impl FrameRing {
    pub fn new(ctx: &Arc<Context>, frames_in_flight: usize) -> Result<Self> {
        let mut type_info = vk::SemaphoreTypeCreateInfo::default()
            .semaphore_type(vk::SemaphoreType::TIMELINE)
            .initial_value(0);
        let info = vk::SemaphoreCreateInfo::default().push_next(&mut type_info);
        let timeline = unsafe { ctx.device.create_semaphore(&info, None) }?;
        ctx.set_name(timeline, "frame timeline");
        let mut slots = Vec::new();
        for i in 0..frames_in_flight {
            let pool_info = vk::CommandPoolCreateInfo::default()
                .queue_family_index(ctx.queue_family)
                .flags(vk::CommandPoolCreateFlags::TRANSIENT);
            let pool = unsafe { ctx.device.create_command_pool(&pool_info, None) }?;
            let alloc = vk::CommandBufferAllocateInfo::default()
                .command_pool(pool)
                .level(vk::CommandBufferLevel::PRIMARY)
                .command_buffer_count(1);
            let cmd = unsafe { ctx.device.allocate_command_buffers(&alloc) }?[0];
            ctx.set_name(cmd, &format!("frame slot {i}"));
            slots.push(Slot {
                pool,
                cmd,
                value: 0,
            });
        }
        Ok(Self {
            timeline,
            last_signalled: 0,
            slots,
            current: 0,
            ctx: ctx.clone(),
        })
    }

    /// The slot of the last submitted frame, if any.
    pub fn last_slot(&self) -> Option<usize> {
        (self.last_signalled > 0).then(|| (self.current + self.slots.len() - 1) % self.slots.len())
    }

    pub fn frames_in_flight(&self) -> usize {
        self.slots.len()
    }

    /// Waits until the next slot is free, then starts recording its command buffer.
    pub fn begin(&mut self) -> Result<Frame> {
        let slot = &self.slots[self.current];
        self.wait_for(slot.value)?;
        unsafe {
            self.ctx
                .device
                .reset_command_pool(slot.pool, vk::CommandPoolResetFlags::empty())?;
            let begin = vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            self.ctx.device.begin_command_buffer(slot.cmd, &begin)?;
        }
        Ok(Frame {
            slot: self.current,
            cmd: slot.cmd,
            value: self.last_signalled + 1,
        })
    }

    /// Ends and submits the frame; it signals the timeline (and `signal`, for present).
    pub fn submit(
        &mut self,
        frame: Frame,
        wait: Option<(vk::Semaphore, vk::PipelineStageFlags2)>,
        signal: Option<vk::Semaphore>,
    ) -> Result<()> {
        let ctx = &self.ctx;
        unsafe { ctx.device.end_command_buffer(frame.cmd) }?;
        let waits: Vec<_> = wait
            .iter()
            .map(|&(semaphore, stage)| {
                vk::SemaphoreSubmitInfo::default()
                    .semaphore(semaphore)
                    .stage_mask(stage)
            })
            .collect();
        let mut signals = vec![vk::SemaphoreSubmitInfo::default()
            .semaphore(self.timeline)
            .value(frame.value)
            .stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)];
        if let Some(semaphore) = signal {
            signals.push(
                vk::SemaphoreSubmitInfo::default()
                    .semaphore(semaphore)
                    .stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS),
            );
        }
        let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(frame.cmd)];
        let submit = [vk::SubmitInfo2::default()
            .wait_semaphore_infos(&waits)
            .command_buffer_infos(&cmds)
            .signal_semaphore_infos(&signals)];
        unsafe {
            ctx.device
                .queue_submit2(ctx.queue, &submit, vk::Fence::null())
        }
        .context("vkQueueSubmit2 failed (device lost?)")?;
        self.last_signalled = frame.value;
        self.slots[frame.slot].value = frame.value;
        self.current = (self.current + 1) % self.slots.len();
        Ok(())
    }

    /// Blocks until the timeline reaches `value`.
    pub fn wait_for(&self, value: u64) -> Result<()> {
        if value == 0 {
            return Ok(());
        }
        let semaphores = [self.timeline];
        let values = [value];
        let info = vk::SemaphoreWaitInfo::default()
            .semaphores(&semaphores)
            .values(&values);
        match unsafe { self.ctx.device.wait_semaphores(&info, FRAME_TIMEOUT_NS) } {
            Ok(()) => Ok(()),
            Err(vk::Result::TIMEOUT) => bail!(
                "the GPU did not finish frame {value} within {} s",
                FRAME_TIMEOUT_NS / 1_000_000_000
            ),
            Err(e) => Err(e).context("waiting for a frame (device lost?)"),
        }
    }

    /// Blocks until every submitted frame is done.
    pub fn wait_all(&self) -> Result<()> {
        self.wait_for(self.last_signalled)
    }
}

impl Drop for FrameRing {
    fn drop(&mut self) {
        unsafe {
            let _ = self.ctx.device.device_wait_idle();
            for slot in &self.slots {
                self.ctx.device.destroy_command_pool(slot.pool, None);
            }
            self.ctx.device.destroy_semaphore(self.timeline, None);
        }
    }
}
