//! Recording an octree from voxel fragments: the build before the first frame, each
//! phase run again with grown pools when one overflows, and the insertion of the moving
//! meshes into the static part every frame (Dřínovský 2013, 5.2-5.4 and 5.7).

use std::time::Instant;

use anyhow::{ensure, Context as _, Result};
use ash::vk;
use gpu_allocator::MemoryLocation;

use super::super::voxel_list::reset_voxel_list;
use super::super::voxelize::{self, Meshes};
use super::nodes::Over;
use super::pools::{self, overflowed, Capacities, Fragments, Pools};
use super::{Octree, BRICK_USE, COUNTERS_BYTES, RADIANCE_USE};
use crate::gpu_layout::{self as layout, OctreeBounceDispatch, OctreeCounters, OctreeLevel};
use crate::progress::Progress;
use crate::scene_gpu::SceneDraw;
use crate::vk::{
    clear_to_zero, compute_to_compute, copies_to_host_barrier, image_barrier, stage_barrier,
    update_buffer, Buffer, GpuTimer, ImageUse, OneShot,
};

/// What a build made, measured: the counters, the level table and GPU time per pass.
#[derive(Clone, Debug)]
pub struct BuildReport {
    pub counters: OctreeCounters,
    /// Levels 0 (the root) to depth - 1 (the leaves).
    pub levels: Vec<OctreeLevel>,
    /// GPU milliseconds per pass of the last (successful) build.
    pub passes: Vec<(String, f64)>,
    /// One line per overflow that made the build run again.
    pub regrowths: Vec<String>,
    /// Host time of the whole build, rebuilds included.
    pub wall_ms: f64,
}

impl BuildReport {
    /// The `stats` of `bench`: fragments, nodes per level, bricks, pool use.
    pub fn stats(&self, capacities: &Capacities) -> Vec<(String, f64)> {
        let c = &self.counters;
        let mut stats = vec![
            ("fragments".to_string(), f64::from(c.fragment_count)),
            (
                "fragment_capacity".to_string(),
                f64::from(capacities.fragments),
            ),
            ("nodes_total".to_string(), f64::from(c.node_count)),
            ("node_capacity".to_string(), f64::from(capacities.nodes)),
            (
                "bricks".to_string(),
                f64::from(c.leaf_bricks + c.interior_bricks),
            ),
            ("leaf_bricks".to_string(), f64::from(c.leaf_bricks)),
            (
                "leaf_brick_capacity".to_string(),
                f64::from(capacities.leaf_bricks),
            ),
            ("interior_bricks".to_string(), f64::from(c.interior_bricks)),
            ("leaf_voxels".to_string(), f64::from(c.leaf_voxels)),
            (
                "leaf_voxel_capacity".to_string(),
                f64::from(capacities.leaf_voxels),
            ),
            (
                "interior_brick_capacity".to_string(),
                f64::from(capacities.interior_bricks),
            ),
            (
                "build_attempts".to_string(),
                self.regrowths.len() as f64 + 1.0,
            ),
            ("build_wall_ms".to_string(), self.wall_ms),
        ];
        for (i, level) in self.levels.iter().enumerate() {
            let nodes = level.count + level.appended_count;
            stats.push((format!("nodes_level_{i}"), f64::from(nodes)));
        }
        stats
    }
}

impl Octree {
    /// Builds the octree and waits for it: the voxel fragments of the static meshes
    /// (of every mesh in a static scene), then the octree and its bricks from them; with
    /// moving meshes or `--full-update`, one frame's insertion of the moving meshes at
    /// `draw.time_s` too, so that the pools have room for it. A pool that overflows is
    /// reported (in the log, and in the report), grown, and its phase runs again.
    pub fn build(&mut self, draw: &SceneDraw, set: vk::DescriptorSet) -> Result<&BuildReport> {
        let start = Instant::now();
        let mut regrowths = Vec::new();
        let mut passes = Vec::new();
        let mut fitted = false;
        let mut listed = 0;
        let mut built = None;
        let phases: &[Phase] = if self.moving() {
            &[Phase::Fragments, Phase::Octree, Phase::Frame]
        } else {
            &[Phase::Fragments, Phase::Octree]
        };
        let mut next = 0;
        // Phases done of those to run; a regrowth sets it back to the phase run again.
        let progress = Progress::new("building the octree", phases.len() as u64);
        while let Some(&phase) = phases.get(next) {
            progress.set(next as u64);
            let (counters, levels, timings) = self.run(phase, draw, set, listed)?;
            if counters.overflow == 0 {
                if phase == Phase::Octree {
                    let capacities = self.pools.capacities;
                    let fit = capacities.fitted(&counters);
                    if !fitted && fit != capacities {
                        // Growth overshoots: size the pools to what they hold (with the
                        // margin moving meshes need) and build the octree once more.
                        log::info!("octree pools fitted to what they hold: {fit:?}");
                        fitted = true;
                        self.pools = Pools::new(&self.ctx, fit, self.moving(), self.pools.slots)
                            .context("fitting the octree pools")?;
                        self.pools.write_set(&self.ctx, set, self.linear);
                        continue;
                    }
                    self.statics = if self.moving && !self.full_update {
                        StaticPart::built(&counters, &levels)
                    } else {
                        StaticPart::root()
                    };
                    built = Some((counters, levels));
                } else if phase == Phase::Fragments {
                    listed = counters.fragment_count;
                    passes.clear();
                }
                if phase != Phase::Frame {
                    passes.extend(timings);
                }
                next += 1;
                continue;
            }
            let capacities = self.pools.capacities;
            let grown = capacities.grown(&counters);
            let message = format!(
                "octree pools too small ({}); growing them and building again",
                overflowed(&counters, &capacities).join("; ")
            );
            // The first guess is small on purpose: growing is routine.
            log::info!("{message}");
            regrowths.push(message);
            ensure!(
                regrowths.len() < 8,
                "the octree build still overflows after {} regrowths",
                regrowths.len()
            );
            if counters.overflow & layout::OCTREE_OVERFLOW_FRAGMENTS != 0 {
                self.fragments = Fragments::new(&self.ctx, grown.fragments)
                    .context("growing the voxel-fragment list")?;
                self.fragments.write_set(&self.ctx, set);
                self.pools.capacities.fragments = grown.fragments;
                next = 0;
            } else {
                self.pools = Pools::new(&self.ctx, grown, self.moving(), self.pools.slots)
                    .context("growing the octree pools")?;
                self.pools.write_set(&self.ctx, set, self.linear);
                // The fragments' GPU times stay; the octree's are taken again.
                passes.retain(|(name, _)| name == "fragments");
                next = 1;
            }
        }
        progress.finish();
        let (counters, levels) = built.context("the octree phase did not run")?;
        // A frame's new bricks hold at most what the pools hold beyond the static part
        // (more overflows, and the pools grow).
        let fresh = self
            .moving()
            .then(|| self.pools.capacities.leaf_voxels - self.statics.leaf_voxels);
        self.pools.size_carry(&self.ctx, set, fresh)?;
        self.filter_all.set(true);
        self.exact_stores.set(true);
        self.moved = draw.scene.moving_bounds(draw.time_s);
        // Nothing carried yet.
        let carry = self.pools.carry.raw;
        OneShot::new(&self.ctx)?.run("clear octree carry", |cmd| {
            unsafe {
                self.ctx
                    .device
                    .cmd_fill_buffer(cmd, carry, 0, vk::WHOLE_SIZE, 0)
            };
            Ok(())
        })?;
        Ok(self.report.insert(BuildReport {
            counters,
            levels,
            passes,
            regrowths,
            wall_ms: start.elapsed().as_secs_f64() * 1e3,
        }))
    }

    /// Runs one phase of the build and waits for it; returns the counters, the level
    /// table's first `depth` rows and the phase's GPU time per pass. `listed`: the
    /// fragments the fragment phase listed.
    #[allow(clippy::type_complexity)]
    fn run(
        &self,
        phase: Phase,
        draw: &SceneDraw,
        set: vk::DescriptorSet,
        listed: u32,
    ) -> Result<(OctreeCounters, Vec<OctreeLevel>, Vec<(String, f64)>)> {
        let mut timer = GpuTimer::new(&self.ctx)?;
        let readback = Buffer::new(
            &self.ctx,
            "octree counters readback",
            COUNTERS_BYTES as u64,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        OneShot::new(&self.ctx)?.run("octree build", |cmd| {
            timer.reset(cmd);
            match phase {
                Phase::Fragments => self.record_fragments(cmd, &mut timer, draw, set),
                Phase::Octree => {
                    self.record_start(cmd, &StaticPart::root(), 0, listed);
                    self.record_levels(cmd, &mut timer, draw.frame_set, set, Over::Level);
                }
                Phase::Frame => self.record_frame(cmd, &mut timer, draw, set),
            }
            self.copy_counters(cmd, readback.raw);
            Ok(())
        })?;
        let bytes = readback.mapped();
        let head = std::mem::size_of::<OctreeCounters>();
        let counters = bytemuck::pod_read_unaligned(&bytes[..head]);
        let levels = bytes[head..COUNTERS_BYTES]
            .chunks_exact(std::mem::size_of::<OctreeLevel>())
            .take(self.depth as usize)
            .map(bytemuck::pod_read_unaligned)
            .collect();
        Ok((counters, levels, timer.results()?))
    }

    /// Records the first phase: the counters reset, then the voxel fragments of the
    /// static meshes (of every mesh in a static scene).
    fn record_fragments(
        &self,
        cmd: vk::CommandBuffer,
        timer: &mut GpuTimer,
        draw: &SceneDraw,
        set: vk::DescriptorSet,
    ) {
        let ctx = &self.ctx;
        let counters = OctreeCounters {
            fragment_groups_y: 1,
            fragment_groups_z: 1,
            fragment_capacity: self.fragments.capacity,
            ..Default::default()
        };
        update_buffer(
            ctx,
            cmd,
            self.counters.raw,
            0,
            bytemuck::bytes_of(&counters),
            voxelize::STAGES,
        );
        let meshes = if self.moving {
            Meshes::Static
        } else {
            Meshes::All
        };
        self.record_fragment_list(cmd, timer, draw, set, meshes);
    }

    /// Records the voxelization of `meshes` into the fragment list.
    fn record_fragment_list(
        &self,
        cmd: vk::CommandBuffer,
        timer: &mut GpuTimer,
        draw: &SceneDraw,
        set: vk::DescriptorSet,
        meshes: Meshes,
    ) {
        let ctx = &self.ctx;
        timer.begin(cmd, "fragments");
        self.voxelize
            .record(ctx, cmd, draw, set, &self.grid, meshes);
        stage_barrier(
            ctx,
            cmd,
            vk::PipelineStageFlags2::ALL_COMMANDS,
            vk::PipelineStageFlags2::ALL_COMMANDS,
        );
        timer.end(cmd);
    }

    /// Records one frame's insertion: the static part restored, the moving meshes' (with
    /// `--full-update`, every mesh's) fragments listed and inserted.
    pub(super) fn record_frame(
        &self,
        cmd: vk::CommandBuffer,
        timer: &mut GpuTimer,
        draw: &SceneDraw,
        set: vk::DescriptorSet,
    ) {
        let kept = self.statics.fragments;
        self.record_start(cmd, &self.statics, kept, kept);
        let meshes = if self.full_update {
            Meshes::All
        } else {
            Meshes::Moving
        };
        self.record_fragment_list(cmd, timer, draw, set, meshes);
        self.record_levels(cmd, timer, draw.frame_set, set, Over::Appended);
    }

    /// Records the start of an octree: the counters and level table of `part` (the root
    /// alone for a build), with the fragments from `base` read and `listed` so far; the
    /// part's nodes restored (the static part from its copy, or the bare root) and the
    /// sums after its own cleared.
    fn record_start(&self, cmd: vk::CommandBuffer, part: &StaticPart, base: u32, listed: u32) {
        let ctx = &self.ctx;
        let p = &self.pools;
        let c = &p.capacities;
        let counters = OctreeCounters {
            fragment_groups_x: (listed - base).div_ceil(layout::OCTREE_GROUP_SIZE),
            fragment_groups_y: 1,
            fragment_groups_z: 1,
            fragment_count: listed,
            fragment_capacity: self.fragments.capacity,
            node_count: part.nodes,
            node_capacity: c.nodes,
            leaf_bricks: part.leaf_bricks,
            leaf_brick_capacity: c.leaf_bricks,
            interior_bricks: part.interior_bricks,
            interior_brick_capacity: c.interior_bricks,
            leaf_pool_side: p.leaf_side,
            interior_pool_side: p.interior_side,
            leaf_voxels: part.leaf_voxels,
            leaf_voxel_capacity: c.leaf_voxels,
            carry_capacity: p.carry_capacity,
            carry_parity: self.carry_parity,
            fragment_base: base,
            static_node_count: part.nodes,
            static_leaf_bricks: part.leaf_bricks,
            exact_stores: u32::from(!part.saved),
            update_capacity: c.nodes,
            ..Default::default()
        };
        let mut head = bytemuck::bytes_of(&counters).to_vec();
        for level in part.level_table() {
            head.extend_from_slice(bytemuck::bytes_of(&level));
        }
        stage_barrier(
            ctx,
            cmd,
            vk::PipelineStageFlags2::ALL_COMMANDS,
            vk::PipelineStageFlags2::ALL_TRANSFER,
        );
        let sums_kept = 4 * u64::from(layout::VOXEL_SUM_WORDS) * u64::from(part.leaf_voxels);
        unsafe {
            let device = &ctx.device;
            device.cmd_update_buffer(cmd, self.counters.raw, 0, &head);
            if part.saved {
                let region = vk::BufferCopy::default().size(4 * u64::from(part.nodes));
                device.cmd_copy_buffer(cmd, p.static_children.raw, p.nodes.raw, &[region]);
                device.cmd_copy_buffer(cmd, p.static_bricks.raw, p.bricks.raw, &[region]);
            } else {
                // The root: no children yet, no brick, at (0, 0, 0).
                device.cmd_fill_buffer(cmd, p.nodes.raw, 0, 4, 0);
                device.cmd_fill_buffer(cmd, p.bricks.raw, 0, 4, layout::OCTREE_NO_BRICK);
                device.cmd_fill_buffer(cmd, p.coords.raw, 0, 4, 0);
            }
            if sums_kept < p.sums.size {
                device.cmd_fill_buffer(cmd, p.sums.raw, sums_kept, vk::WHOLE_SIZE, 0);
            }
            if !part.saved {
                // A build: no brick changed yet.
                device.cmd_fill_buffer(cmd, p.changes.raw, 0, vk::WHOLE_SIZE, 0);
            }
        }
        stage_barrier(
            ctx,
            cmd,
            vk::PipelineStageFlags2::ALL_TRANSFER,
            vk::PipelineStageFlags2::FRAGMENT_SHADER
                | vk::PipelineStageFlags2::COMPUTE_SHADER
                | vk::PipelineStageFlags2::DRAW_INDIRECT,
        );
        if !part.saved {
            let all: Vec<u32> = (0..layout::OCTREE_UPDATE_LISTS).collect();
            self.bricks
                .reset_update_lists(ctx, cmd, p.updates.raw, &all);
            // The first bounce after a build runs.
            let first = OctreeBounceDispatch {
                groups_y: 1,
                groups_z: 1,
                changed: 1,
                ..Default::default()
            };
            update_buffer(
                ctx,
                cmd,
                p.updates.raw,
                pools::BOUNCE_DISPATCH_OFFSET,
                bytemuck::bytes_of(&first),
                vk::PipelineStageFlags2::COMPUTE_SHADER,
            );
        }
    }

    /// Records the octree's levels from the fragments (`record_start` wrote where they
    /// start), the neighbour pointers of the nodes in `neighbours`, the new leaf bricks
    /// and the list of occupied leaf voxels. In a build (`Over::Level`) the brick pools
    /// go to their layouts first, and with moving meshes the static part is saved at the
    /// end.
    fn record_levels(
        &self,
        cmd: vk::CommandBuffer,
        timer: &mut GpuTimer,
        frame_set: vk::DescriptorSet,
        set: vk::DescriptorSet,
        neighbours: Over,
    ) {
        let ctx = &self.ctx;
        let p = &self.pools;
        let build = neighbours == Over::Level;
        let sets = [(layout::SET_FRAME, frame_set), (layout::SET_GI, set)];
        let counters = self.counters.raw;
        self.nodes
            .record(ctx, cmd, timer, &sets, counters, self.depth, neighbours);
        // The brick fill and every pass after it find nodes from the node grid.
        timer.begin(cmd, "node grid");
        self.nodes.record_grid(cmd, &sets, self.depth);
        compute_to_compute(ctx, cmd);
        timer.end(cmd);

        timer.begin(cmd, "brick fill");
        if build {
            // No clears of the pools at every build, only their layouts (clears cost
            // 65 ms of the depth-10 Sponza build on an H200): the list pass writes every
            // attribute texel of the bricks in use and zeroes the radiance bricks it gives
            // out, the direct light is read only at listed voxels, and the filter and the
            // borders write every texel of the interior bricks in use. But the sampler
            // fetches the texel beyond a brick's border too, weighted 0, where the
            // lookup lands on the border's centre, and 0 times a NaN left in new memory
            // (an earlier image's packed words) is a NaN: the sampled images are zeroed
            // once, when made.
            let attributes = p.leaf_attributes.iter().map(|image| (image, BRICK_USE));
            let radiance = [&p.leaf_direct]
                .into_iter()
                .map(|image| (image, RADIANCE_USE));
            for (image, to) in attributes.chain(radiance) {
                image_barrier(ctx, cmd, image.raw, image.full_range(), p.last_use(), to);
            }
            for image in [&p.leaf_radiance, &p.leaf_coverage, &p.directional] {
                if p.in_general.get() {
                    image_barrier(
                        ctx,
                        cmd,
                        image.raw,
                        image.full_range(),
                        p.last_use(),
                        RADIANCE_USE,
                    );
                } else {
                    clear_to_zero(ctx, cmd, image, ImageUse::UNDEFINED, RADIANCE_USE);
                }
            }
            p.in_general.set(true);
        }
        self.bricks.record_fill(cmd, &sets, counters);
        compute_to_compute(ctx, cmd);
        timer.end(cmd);

        timer.begin(cmd, "voxel list");
        reset_voxel_list(ctx, cmd, p.voxel_list.raw);
        self.bricks
            .record_list(cmd, &sets, counters, self.depth - 1);
        stage_barrier(
            ctx,
            cmd,
            vk::PipelineStageFlags2::COMPUTE_SHADER,
            vk::PipelineStageFlags2::COMPUTE_SHADER | vk::PipelineStageFlags2::DRAW_INDIRECT,
        );
        timer.end(cmd);
        if build && self.moving && !self.full_update {
            stage_barrier(
                ctx,
                cmd,
                vk::PipelineStageFlags2::COMPUTE_SHADER,
                vk::PipelineStageFlags2::COPY,
            );
            let region = vk::BufferCopy::default().size(p.nodes.size);
            unsafe {
                ctx.device
                    .cmd_copy_buffer(cmd, p.nodes.raw, p.static_children.raw, &[region]);
                ctx.device
                    .cmd_copy_buffer(cmd, p.bricks.raw, p.static_bricks.raw, &[region]);
            }
            stage_barrier(
                ctx,
                cmd,
                vk::PipelineStageFlags2::COPY,
                vk::PipelineStageFlags2::ALL_COMMANDS,
            );
        }
    }

    /// Copies the counters and the level table to `to` (host-visible) at the end of the
    /// command buffer.
    pub(super) fn copy_counters(&self, cmd: vk::CommandBuffer, to: vk::Buffer) {
        let ctx = &self.ctx;
        stage_barrier(
            ctx,
            cmd,
            vk::PipelineStageFlags2::COMPUTE_SHADER,
            vk::PipelineStageFlags2::COPY,
        );
        let region = vk::BufferCopy::default().size(COUNTERS_BYTES as u64);
        unsafe {
            ctx.device
                .cmd_copy_buffer(cmd, self.counters.raw, to, &[region])
        };
        copies_to_host_barrier(ctx, cmd);
    }
}

/// The static part of the octree (Dřínovský 2013, 5.7): built once; every frame with
/// moving meshes starts from it and appends their nodes after it.
#[derive(Clone, Debug)]
pub(super) struct StaticPart {
    /// Fragments of the static meshes, first in the list (a frame lists more after them).
    pub(super) fragments: u32,
    pub(super) nodes: u32,
    pub(super) leaf_bricks: u32,
    pub(super) interior_bricks: u32,
    pub(super) leaf_voxels: u32,
    /// Per level, its first node and node count.
    pub(super) levels: Vec<(u32, u32)>,
    /// Its nodes' child entries and bricks are saved in `Pools::static_children` and
    /// `static_bricks` (otherwise it is the bare root).
    pub(super) saved: bool,
}

impl StaticPart {
    /// Nothing static: the bare root, from which a build starts (and every frame, with
    /// `--full-update`).
    pub(super) fn root() -> Self {
        Self {
            fragments: 0,
            nodes: 1,
            leaf_bricks: 0,
            interior_bricks: 0,
            leaf_voxels: 0,
            levels: vec![(0, 1)],
            saved: false,
        }
    }

    /// What a build of the static meshes made (every level but the root appended).
    fn built(counters: &OctreeCounters, levels: &[OctreeLevel]) -> Self {
        let mut runs = vec![(0, 1)];
        runs.extend(
            levels
                .iter()
                .skip(1)
                .map(|l| (l.appended_first, l.appended_count)),
        );
        Self {
            fragments: counters.fragment_count,
            nodes: counters.node_count,
            leaf_bricks: counters.leaf_bricks,
            interior_bricks: counters.interior_bricks,
            leaf_voxels: counters.leaf_voxels,
            levels: runs,
            saved: true,
        }
    }

    /// The level table a build or frame starts from: each level's static run, nothing
    /// appended yet (the root's appended run starts after the static nodes).
    fn level_table(&self) -> Vec<OctreeLevel> {
        (0..layout::OCTREE_MAX_LEVELS as usize)
            .map(|l| {
                let (first, count) = self.levels.get(l).copied().unwrap_or((0, 0));
                OctreeLevel {
                    groups_x: count.div_ceil(layout::OCTREE_GROUP_SIZE),
                    groups_y: 1,
                    groups_z: 1,
                    first,
                    count,
                    appended_first: if l == 0 { self.nodes } else { 0 },
                    appended_groups_y: 1,
                    appended_groups_z: 1,
                    ..Default::default()
                }
            })
            .collect()
    }
}

/// The phases of a build, each run again alone when its pools overflow (from the
/// fragments when the fragment list overflowed, from the octree otherwise).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Phase {
    /// The voxel-fragment list.
    Fragments,
    /// The octree, its bricks and the occupied-voxel list, from the fragments.
    Octree,
    /// One frame's insertion of the moving meshes, to size the pools for it.
    Frame,
}
