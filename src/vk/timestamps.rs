//! GPU time per named pass, from timestamp queries, with a debug label of the same name.

use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use super::Context;

/// Passes one frame may time.
const MAX_PASSES: u32 = 512;
/// Each pass writes a begin and an end timestamp, each followed by a throw-away one.
const QUERIES_PER_PASS: u32 = 4;

/// A timestamp query pool for one frame slot.
pub struct GpuTimer {
    pool: vk::QueryPool,
    names: Vec<String>,
    open: Vec<usize>,
    period_ns: f64,
    ctx: Arc<Context>,
}

impl GpuTimer {
    pub fn new(ctx: &Arc<Context>) -> Result<Self> {
        let info = vk::QueryPoolCreateInfo::default()
            .query_type(vk::QueryType::TIMESTAMP)
            .query_count(MAX_PASSES * QUERIES_PER_PASS);
        let pool = unsafe { ctx.device.create_query_pool(&info, None) }?;
        Ok(Self {
            pool,
            names: Vec::new(),
            open: Vec::new(),
            period_ns: f64::from(ctx.properties.limits.timestamp_period),
            ctx: ctx.clone(),
        })
    }

    /// Starts a frame: forgets the last frame's passes and resets the queries.
    pub fn reset(&mut self, cmd: vk::CommandBuffer) {
        self.names.clear();
        self.open.clear();
        unsafe {
            self.ctx
                .device
                .cmd_reset_query_pool(cmd, self.pool, 0, MAX_PASSES * QUERIES_PER_PASS)
        };
    }

    fn stamp(&self, cmd: vk::CommandBuffer, query: u32) {
        unsafe {
            self.ctx.device.cmd_write_timestamp2(
                cmd,
                vk::PipelineStageFlags2::ALL_COMMANDS,
                self.pool,
                query,
            );
            // Lavapipe records a timestamp after rendering only at the next flush; a second
            // one right behind it forces that (shared/notes/lavapipe.md, pitfall 1).
            self.ctx.device.cmd_write_timestamp2(
                cmd,
                vk::PipelineStageFlags2::ALL_COMMANDS,
                self.pool,
                query + 1,
            );
        }
    }

    /// Opens pass `name`: a debug label and a begin timestamp.
    pub fn begin(&mut self, cmd: vk::CommandBuffer, name: &str) {
        self.ctx.begin_label(cmd, name);
        let index = self.names.len();
        if (index as u32) < MAX_PASSES {
            self.stamp(cmd, index as u32 * QUERIES_PER_PASS);
        }
        self.names.push(name.to_string());
        self.open.push(index);
    }

    /// Closes the innermost open pass.
    pub fn end(&mut self, cmd: vk::CommandBuffer) {
        let index = self.open.pop().expect("GpuTimer::end without begin");
        if (index as u32) < MAX_PASSES {
            self.stamp(cmd, index as u32 * QUERIES_PER_PASS + 2);
        }
        self.ctx.end_label(cmd);
    }

    /// Milliseconds per pass of the frame last recorded with this timer; call only once
    /// that frame has completed.
    pub fn results(&self) -> Result<Vec<(String, f64)>> {
        let count = self.names.len().min(MAX_PASSES as usize);
        if count == 0 {
            return Ok(Vec::new());
        }
        let mut data = vec![0u64; count * QUERIES_PER_PASS as usize];
        unsafe {
            self.ctx.device.get_query_pool_results(
                self.pool,
                0,
                &mut data,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
        }?;
        Ok(self.names[..count]
            .iter()
            .enumerate()
            .map(|(i, name)| {
                let base = i * QUERIES_PER_PASS as usize;
                let ticks = data[base + 2].saturating_sub(data[base]);
                (name.clone(), ticks as f64 * self.period_ns / 1e6)
            })
            .collect())
    }
}

impl Drop for GpuTimer {
    fn drop(&mut self) {
        unsafe { self.ctx.device.destroy_query_pool(self.pool, None) };
    }
}
