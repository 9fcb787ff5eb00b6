//! Global illumination on a sparse voxel octree (`--gi svo`; Crassin et al. 2011), built
//! on the GPU level by level (Crassin & Green 2012) as in Dřínovský's thesis (2013, 5.2-5.4).
//!
//! Build: voxel-fragment list (the dense path's voxelization, appending records through
//! an atomic counter) -> octree, level by level (flag, alloc, init) -> neighbour pointers
//! -> leaf bricks filled from the fragments. Every pool's capacity is checked on the
//! GPU; a pool that overflows is reported, grown (`pools`), and the build runs again.
//!
//! Frame: around moving meshes, the static part is restored and their nodes appended
//! after it (5.7); after voxel shading, only the nodes on the update lists are filtered
//! up the tree again (5.5).

mod bricks;
mod octree;
mod pools;
#[cfg(test)]
mod tests;

use std::sync::Arc;
use std::time::Instant;

use anyhow::{bail, ensure, Context as _, Result};
use ash::vk;
use gpu_allocator::MemoryLocation;

use crate::gi::voxelize::{Meshes, VoxelizePass, Voxelizer};
use crate::gi::{compute_to_compute, reset_voxel_list, Grid};
use crate::gpu_layout::{self as layout, SvoBounceDispatch, SvoCounters, SvoLevel};
use crate::scene::{Aabb, Scene};
use crate::scene_gpu::SceneDraw;
use crate::vk::{
    copies_to_host_barrier, image_barrier, stage_barrier, update_buffer, Binding, Buffer, Context,
    GpuTimer, ImageUse, OneShot, Pipeline, SetWriter,
};
use octree::Over;
pub use pools::Capacities;
use pools::{overflowed, Fragments, Pools};

/// Octree depths `--octree-depth` accepts: effective grids of 64³ to 1024³.
pub const DEPTHS: std::ops::RangeInclusive<u32> = 6..=10;

/// Checks an octree depth.
pub fn check_depth(depth: u32) -> Result<()> {
    if !DEPTHS.contains(&depth) {
        bail!(
            "--octree-depth must be between {} and {}, got {depth}",
            DEPTHS.start(),
            DEPTHS.end()
        );
    }
    Ok(())
}

/// The counters buffer: `SvoCounters`, then the level table.
const COUNTERS_BYTES: usize = std::mem::size_of::<SvoCounters>()
    + layout::SVO_MAX_LEVELS as usize * std::mem::size_of::<SvoLevel>();

/// The radiance pools between passes: written as storage, sampled by cones.
const RADIANCE_USE: ImageUse = ImageUse {
    layout: vk::ImageLayout::GENERAL,
    stage: vk::PipelineStageFlags2::COMPUTE_SHADER,
    access: vk::AccessFlags2::from_raw(
        vk::AccessFlags2::SHADER_READ.as_raw() | vk::AccessFlags2::SHADER_WRITE.as_raw(),
    ),
};

/// What a build made, measured: the counters, the level table and GPU time per pass.
#[derive(Clone, Debug)]
pub struct BuildReport {
    pub counters: SvoCounters,
    /// Levels 0 (the root) to depth - 1 (the leaves).
    pub levels: Vec<SvoLevel>,
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

/// The set-2 bindings of the octree's own buffers and images; the GI set holds them
/// beside the bindings of the dense grid (`gi::gi_bindings`), where the octree binds its
/// brick pools.
pub fn bindings() -> Vec<Binding> {
    let all = vk::ShaderStageFlags::FRAGMENT
        | vk::ShaderStageFlags::COMPUTE
        | vk::ShaderStageFlags::GEOMETRY;
    let storage = vk::DescriptorType::STORAGE_BUFFER;
    vec![
        Binding::new(layout::BINDING_SVO_COUNTERS, storage, all),
        Binding::new(layout::BINDING_SVO_FRAGMENTS, storage, all),
        Binding::new(layout::BINDING_SVO_FRAGMENT_SHADING, storage, all),
        Binding::new(layout::BINDING_SVO_NODES, storage, all),
        Binding::new(layout::BINDING_SVO_NODE_COORDS, storage, all),
        Binding::new(layout::BINDING_SVO_NODE_BRICKS, storage, all),
        Binding::new(layout::BINDING_SVO_NEIGHBOURS, storage, all),
        Binding::new(layout::BINDING_SVO_SUMS, storage, all),
        Binding::new(layout::BINDING_SVO_CARRY, storage, all),
        Binding::new(layout::BINDING_SVO_STATIC_NODES, storage, all),
        Binding::new(layout::BINDING_SVO_CHANGES, storage, all),
        Binding::new(layout::BINDING_SVO_UPDATES, storage, all),
        Binding::new(layout::BINDING_SVO_NODE_GRID, storage, all),
        Binding::new(
            layout::BINDING_SVO_DIRECTIONAL_STORAGE,
            vk::DescriptorType::STORAGE_IMAGE,
            all,
        ),
    ]
}

/// The sparse voxel octree of a scene.
pub struct SvoGi {
    /// The effective grid: 2^depth voxels per axis over the dense path's cube.
    pub grid: Grid,
    pub depth: u32,
    /// `SvoCounters`, then `SvoLevel[SVO_MAX_LEVELS]`; also the indirect dispatches.
    counters: Buffer,
    /// Where cone samples start their descent (`BINDING_SVO_NODE_GRID`).
    node_grid: Buffer,
    fragments: Fragments,
    pools: Pools,
    voxelize: VoxelizePass,
    octree: octree::OctreePasses,
    bricks: bricks::BrickPasses,
    /// `bounce_dispatch.comp`: whether a static octree's bounce runs.
    bounce_gate: Pipeline,
    report: Option<BuildReport>,
    /// The scene has moving meshes: every frame lists their fragments after the static
    /// ones and inserts them into the static part of the octree.
    moving: bool,
    /// What a frame starts from: the static part (the root alone with `--full-update`).
    statics: StaticPart,
    /// Where the moving meshes were in the last frame.
    moved: Aabb,
    /// Voxels (first, last) of the region where moving meshes were last frame or are
    /// now, whose nodes the filter takes as changed.
    region: Option<[[i32; 3]; 2]>,
    /// The next filter runs over every node (the first after a build).
    filter_all: std::cell::Cell<bool>,
    /// The counters ask for exact radiance stores (`SvoCounters::exact_stores`, set by a
    /// build) until the end of the next frame's bounces.
    exact_stores: std::cell::Cell<bool>,
    /// `--full-update`: every mesh is voxelized again every frame too.
    full_update: bool,
    /// The carry table the current frame writes.
    carry_parity: u32,
    /// Per frame in flight: its counters, read when the slot comes round again.
    frame_counters: Vec<Buffer>,
    /// The radiance pools' sampler (the GI set refers to it).
    linear: vk::Sampler,
    ctx: Arc<Context>,
}

impl SvoGi {
    /// `layouts` are those of sets 0, 1 and 2 (the GI set, into which the pools are
    /// written, with `linear` as the radiance pools' sampler). `capacities` overrides the
    /// first guess of the pool sizes (the overflow test starts from tiny pools).
    /// `frames_in_flight` frames may be recorded before the first is done. With
    /// `full_update` every frame voxelizes every mesh and rebuilds the octree. The
    /// fragments are listed by `voxelizer`.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        ctx: &Arc<Context>,
        scene: &Scene,
        depth: u32,
        capacities: Option<Capacities>,
        layouts: [vk::DescriptorSetLayout; 3],
        set: vk::DescriptorSet,
        linear: vk::Sampler,
        frames_in_flight: usize,
        full_update: bool,
        voxelizer: Voxelizer,
    ) -> Result<Self> {
        check_depth(depth)?;
        let grid = Grid::around(scene, 1 << depth);
        let capacities = capacities.unwrap_or_else(|| Capacities::estimate(scene, &grid));
        let counters = Buffer::new(
            ctx,
            "svo counters",
            COUNTERS_BYTES as u64,
            vk::BufferUsageFlags::STORAGE_BUFFER
                | vk::BufferUsageFlags::INDIRECT_BUFFER
                | vk::BufferUsageFlags::TRANSFER_SRC
                | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuOnly,
        )?;
        let node_grid = Buffer::new(
            ctx,
            "svo node grid",
            4 * u64::from(octree::node_grid_cells(depth)),
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::GpuOnly,
        )?;
        SetWriter::new(ctx, set)
            .buffer(
                layout::BINDING_SVO_COUNTERS,
                vk::DescriptorType::STORAGE_BUFFER,
                counters.raw,
            )
            .buffer(
                layout::BINDING_SVO_NODE_GRID,
                vk::DescriptorType::STORAGE_BUFFER,
                node_grid.raw,
            )
            .apply();
        let fragments = Fragments::new(ctx, capacities.fragments)?;
        fragments.write_set(ctx, set);
        let pools = Pools::new(ctx, capacities, scene.has_moving_meshes() || full_update)?;
        pools.write_set(ctx, set, linear);
        Ok(Self {
            grid,
            depth,
            counters,
            node_grid,
            fragments,
            pools,
            voxelize: VoxelizePass::new(
                ctx,
                "svo fragments",
                voxelizer,
                crate::vk::shaders::SVO_FRAGMENTS_FRAGMENTS_FRAG,
                crate::vk::shaders::GI_VOXELIZE_VOXELIZE_COMP_VOXELS_SVO,
                layouts,
            )?,
            octree: octree::OctreePasses::new(ctx, layouts)?,
            bricks: bricks::BrickPasses::new(ctx, layouts)?,
            bounce_gate: Pipeline::compute(
                ctx,
                "svo bounce dispatch",
                crate::vk::shaders::SVO_BRICKS_BOUNCE_DISPATCH_COMP,
                &layouts,
                0,
            )?,
            report: None,
            statics: StaticPart::root(),
            moved: Aabb::EMPTY,
            region: None,
            filter_all: std::cell::Cell::new(true),
            exact_stores: std::cell::Cell::new(true),
            moving: scene.has_moving_meshes(),
            full_update,
            carry_parity: 0,
            frame_counters: (0..frames_in_flight)
                .map(|i| {
                    let mut buffer = Buffer::new(
                        ctx,
                        &format!("svo frame counters {i}"),
                        COUNTERS_BYTES as u64,
                        vk::BufferUsageFlags::TRANSFER_DST,
                        MemoryLocation::GpuToCpu,
                    )?;
                    buffer.write(0, &[0; COUNTERS_BYTES]);
                    Ok(buffer)
                })
                .collect::<Result<_>>()?,
            linear,
            ctx: ctx.clone(),
        })
    }

    /// Whether every frame inserts meshes into the octree: the moving meshes into the
    /// static part, or with `--full-update` every mesh into the bare root.
    pub fn moving(&self) -> bool {
        self.moving || self.full_update
    }

    /// Whether the last build is not yet followed by a frame's bounces (voxel shading
    /// then shades every voxel: no brick holds light yet).
    pub fn just_built(&self) -> bool {
        self.exact_stores.get()
    }

    /// Voxels (first, last) of the region where moving meshes were last frame or are
    /// now.
    pub fn region(&self) -> Option<[[i32; 3]; 2]> {
        self.region
    }

    /// The occupied leaf voxels: the indirect dispatch of voxel shading and bounces.
    pub fn voxel_list(&self) -> vk::Buffer {
        self.pools.voxel_list.raw
    }

    /// Records what a bounce dispatches, and returns where (buffer, offset): the voxel
    /// list around moving meshes; in a static octree the list while anything changed
    /// since the last bounce and nothing once the bounces have converged (the same light
    /// would be stored again).
    pub fn record_bounce_dispatch(
        &self,
        cmd: vk::CommandBuffer,
        frame_set: vk::DescriptorSet,
        set: vk::DescriptorSet,
    ) -> (vk::Buffer, vk::DeviceSize) {
        if self.moving() {
            return (self.pools.voxel_list.raw, 0);
        }
        let sets = [(layout::SET_FRAME, frame_set), (layout::SET_PASS, set)];
        self.bounce_gate.dispatch(cmd, &sets, [1, 1, 1]);
        octree::compute_to_indirect(&self.ctx, cmd);
        (self.pools.updates.raw, pools::BOUNCE_DISPATCH_OFFSET)
    }

    /// After a frame's bounces: the frames after the one that follows a build store only
    /// changes beyond the tolerance, so that converged bounces stop.
    pub fn record_end_of_bounces(&self, cmd: vk::CommandBuffer) {
        if self.exact_stores.replace(false) {
            // The bounces and the filter read the counters until now.
            stage_barrier(
                &self.ctx,
                cmd,
                vk::PipelineStageFlags2::COMPUTE_SHADER,
                vk::PipelineStageFlags2::ALL_TRANSFER,
            );
            update_buffer(
                &self.ctx,
                cmd,
                self.counters.raw,
                std::mem::offset_of!(SvoCounters, exact_stores) as u64,
                bytemuck::bytes_of(&0u32),
                vk::PipelineStageFlags2::COMPUTE_SHADER,
            );
        }
    }

    /// Filters the leaf radiance up the tree, bottom-up, with the bricks' borders copied
    /// from their neighbours at every level (after voxel shading or a bounce): only the
    /// nodes on the update lists (Dřínovský 2013, 5.5), which start from the leaves whose
    /// radiance voxel shading changed and, around moving meshes, the nodes near where
    /// they were or are; every node after a build and with `--full-update`.
    /// Each level's passes are timed apart: `spread L`, `border L` and `filter L`.
    pub fn record_filter(
        &self,
        cmd: vk::CommandBuffer,
        timer: &mut GpuTimer,
        frame_set: vk::DescriptorSet,
        set: vk::DescriptorSet,
    ) {
        let sets = [(layout::SET_FRAME, frame_set), (layout::SET_PASS, set)];
        let ctx = &self.ctx;
        let counters = self.counters.raw;
        let all = self.full_update || self.filter_all.replace(false);
        if all {
            self.bricks
                .record_filter(ctx, cmd, timer, &sets, counters, self.depth);
        } else {
            let buffers = (counters, self.pools.updates.raw);
            self.bricks
                .record_update(ctx, cmd, timer, &sets, buffers, self.depth, self.region);
        }
        // Empty lists for the next voxel shading (after a full filter, also the change
        // bits voxel shading gave).
        if all {
            stage_barrier(
                ctx,
                cmd,
                vk::PipelineStageFlags2::COMPUTE_SHADER,
                vk::PipelineStageFlags2::ALL_TRANSFER,
            );
            let changes = self.pools.changes.raw;
            unsafe {
                ctx.device
                    .cmd_fill_buffer(cmd, changes, 0, vk::WHOLE_SIZE, 0)
            };
        }
        let all: Vec<u32> = (0..layout::SVO_UPDATE_LISTS).collect();
        self.bricks
            .reset_update_lists(ctx, cmd, self.pools.updates.raw, &all);
    }

    /// The last build's report.
    pub fn report(&self) -> Option<&BuildReport> {
        self.report.as_ref()
    }

    pub fn capacities(&self) -> Capacities {
        self.pools.capacities
    }

    /// GPU memory of every octree resource, by name.
    pub fn memory_bytes(&self) -> Vec<(&'static str, u64)> {
        let mut bytes = vec![
            (
                "svo_fragments",
                self.fragments.voxels.size + self.fragments.shading.size,
            ),
            ("svo_counters", self.counters.size),
            ("svo_node_grid", self.node_grid.size),
        ];
        bytes.extend(self.pools.bytes());
        bytes
    }

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
        while let Some(&phase) = phases.get(next) {
            let (counters, levels, timings) = self.run(phase, draw, set, listed)?;
            if counters.overflow == 0 {
                if phase == Phase::Octree {
                    let capacities = self.pools.capacities;
                    let fit = capacities.fitted(&counters);
                    if !fitted && fit != capacities {
                        // Growth overshoots: size the pools to what they hold (with the
                        // margin moving meshes need) and build the octree once more.
                        log::info!("SVO pools fitted to what they hold: {fit:?}");
                        fitted = true;
                        self.pools = Pools::new(&self.ctx, fit, self.moving())
                            .context("fitting the SVO pools")?;
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
                "SVO pools too small ({}); growing them and building again",
                overflowed(&counters, &capacities).join("; ")
            );
            // The first guess is small on purpose: growing is routine.
            log::info!("{message}");
            regrowths.push(message);
            ensure!(
                regrowths.len() < 8,
                "the SVO build still overflows after {} regrowths",
                regrowths.len()
            );
            if counters.overflow & layout::SVO_OVERFLOW_FRAGMENTS != 0 {
                self.fragments = Fragments::new(&self.ctx, grown.fragments)
                    .context("growing the voxel-fragment list")?;
                self.fragments.write_set(&self.ctx, set);
                self.pools.capacities.fragments = grown.fragments;
                next = 0;
            } else {
                self.pools =
                    Pools::new(&self.ctx, grown, self.moving()).context("growing the SVO pools")?;
                self.pools.write_set(&self.ctx, set, self.linear);
                // The fragments' GPU times stay; the octree's are taken again.
                passes.retain(|(name, _)| name == "fragments");
                next = 1;
            }
        }
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
        OneShot::new(&self.ctx)?.run("clear svo carry", |cmd| {
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
    ) -> Result<(SvoCounters, Vec<SvoLevel>, Vec<(String, f64)>)> {
        let mut timer = GpuTimer::new(&self.ctx)?;
        let readback = Buffer::new(
            &self.ctx,
            "svo counters readback",
            COUNTERS_BYTES as u64,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        OneShot::new(&self.ctx)?.run("svo build", |cmd| {
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
        let head = std::mem::size_of::<SvoCounters>();
        let counters = bytemuck::pod_read_unaligned(&bytes[..head]);
        let levels = bytes[head..COUNTERS_BYTES]
            .chunks_exact(std::mem::size_of::<SvoLevel>())
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
        let counters = SvoCounters {
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
            crate::gi::voxelize::STAGES,
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

    /// With moving meshes or `--full-update`, every frame: the static part restored, the
    /// moving meshes' fragments listed after the static ones (kept from the build), and
    /// inserted into the octree (Dřínovský 2013, 5.7). A pool that overflowed in an
    /// earlier frame (its counters are read back when its slot comes round) is grown
    /// first, with the GPU idle, by a full build.
    pub fn record_moving(
        &mut self,
        cmd: vk::CommandBuffer,
        timer: &mut GpuTimer,
        draw: &SceneDraw,
        set: vk::DescriptorSet,
        slot: usize,
    ) -> Result<()> {
        let seen: SvoCounters = bytemuck::pod_read_unaligned(
            &self.frame_counters[slot].mapped()[..std::mem::size_of::<SvoCounters>()],
        );
        if seen.overflow != 0 {
            log::warn!(
                "SVO pools overflowed while meshes moved ({}); rebuilding",
                overflowed(&seen, &self.pools.capacities).join("; ")
            );
            self.ctx.wait_idle()?;
            self.frame_counters[slot].write(0, &[0; COUNTERS_BYTES]);
            self.build(draw, set)?;
        }
        self.carry_parity ^= 1;
        let now = draw.scene.moving_bounds(draw.time_s);
        self.region = self.grid.voxels_of(&now.union(&self.moved));
        self.moved = now;
        let ctx = &self.ctx;
        // The carry table this frame writes; the other holds what last frame gathered.
        let half = 16 * u64::from(self.pools.carry_capacity);
        stage_barrier(
            ctx,
            cmd,
            vk::PipelineStageFlags2::ALL_COMMANDS,
            vk::PipelineStageFlags2::ALL_TRANSFER,
        );
        unsafe {
            ctx.device.cmd_fill_buffer(
                cmd,
                self.pools.carry.raw,
                u64::from(self.carry_parity) * half,
                half,
                0,
            )
        };
        self.record_frame(cmd, timer, draw, set);
        self.copy_counters(cmd, self.frame_counters[slot].raw);
        Ok(())
    }

    /// Records one frame's insertion: the static part restored, the moving meshes' (with
    /// `--full-update`, every mesh's) fragments listed and inserted.
    fn record_frame(
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
        let counters = SvoCounters {
            fragment_groups_x: (listed - base).div_ceil(layout::SVO_GROUP_SIZE),
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
                device.cmd_fill_buffer(cmd, p.bricks.raw, 0, 4, layout::SVO_NO_BRICK);
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
            let all: Vec<u32> = (0..layout::SVO_UPDATE_LISTS).collect();
            self.bricks
                .reset_update_lists(ctx, cmd, p.updates.raw, &all);
            // The first bounce after a build runs.
            let first = SvoBounceDispatch {
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
        let sets = [(layout::SET_FRAME, frame_set), (layout::SET_PASS, set)];
        let counters = self.counters.raw;
        self.octree
            .record(ctx, cmd, timer, &sets, counters, self.depth, neighbours);
        // The brick fill and every pass after it find nodes from the node grid.
        timer.begin(cmd, "node grid");
        self.octree.record_grid(cmd, &sets, self.depth);
        compute_to_compute(ctx, cmd);
        timer.end(cmd);

        timer.begin(cmd, "brick fill");
        if build {
            // No clears of the pools, only their layouts (clears cost 65 ms of the
            // depth-10 Sponza build on an H200): the list pass writes every attribute
            // texel of the bricks in use and zeroes the radiance bricks it gives out, the
            // direct light is read only at listed voxels, and the filter and the borders
            // write every texel of the interior bricks in use.
            let attributes = p.leaf_attributes.iter().map(|image| (image, BRICK_USE));
            let radiance = [&p.leaf_radiance, &p.leaf_direct, &p.directional]
                .into_iter()
                .map(|image| (image, RADIANCE_USE));
            for (image, to) in attributes.chain(radiance) {
                image_barrier(ctx, cmd, image.raw, image.full_range(), p.last_use(), to);
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
    fn copy_counters(&self, cmd: vk::CommandBuffer, to: vk::Buffer) {
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
struct StaticPart {
    /// Fragments of the static meshes, first in the list (a frame lists more after them).
    fragments: u32,
    nodes: u32,
    leaf_bricks: u32,
    interior_bricks: u32,
    leaf_voxels: u32,
    /// Per level, its first node and node count.
    levels: Vec<(u32, u32)>,
    /// Its nodes' child entries and bricks are saved in `Pools::static_children` and
    /// `static_bricks` (otherwise it is the bare root).
    saved: bool,
}

impl StaticPart {
    /// Nothing static: the bare root, from which a build starts (and every frame, with
    /// `--full-update`).
    fn root() -> Self {
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
    fn built(counters: &SvoCounters, levels: &[SvoLevel]) -> Self {
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
    fn level_table(&self) -> Vec<SvoLevel> {
        (0..layout::SVO_MAX_LEVELS as usize)
            .map(|l| {
                let (first, count) = self.levels.get(l).copied().unwrap_or((0, 0));
                SvoLevel {
                    groups_x: count.div_ceil(layout::SVO_GROUP_SIZE),
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

/// How the leaf-brick attribute images are used between passes.
const BRICK_USE: ImageUse = ImageUse {
    layout: vk::ImageLayout::GENERAL,
    stage: vk::PipelineStageFlags2::COMPUTE_SHADER,
    access: vk::AccessFlags2::from_raw(
        vk::AccessFlags2::SHADER_STORAGE_READ.as_raw()
            | vk::AccessFlags2::SHADER_STORAGE_WRITE.as_raw(),
    ),
};

#[cfg(test)]
impl SvoGi {
    /// Filters every node, whatever the update lists hold, and waits.
    fn full_filter(&self, frame_set: vk::DescriptorSet, set: vk::DescriptorSet) -> Result<()> {
        let sets = [(layout::SET_FRAME, frame_set), (layout::SET_PASS, set)];
        // Outlives the command buffer, which writes its queries.
        let mut timer = GpuTimer::new(&self.ctx)?;
        OneShot::new(&self.ctx)?.run("full svo filter", |cmd| {
            compute_to_compute(&self.ctx, cmd);
            timer.reset(cmd);
            self.bricks.record_filter(
                &self.ctx,
                cmd,
                &mut timer,
                &sets,
                self.counters.raw,
                self.depth,
            );
            Ok(())
        })
    }

    /// Downloads a pool buffer as `u32` words.
    fn download_words(&self, buffer: &Buffer) -> Result<Vec<u32>> {
        let bytes = crate::vk::read_back_buffer(&self.ctx, buffer)?;
        Ok(bytemuck::cast_slice(&bytes).to_vec())
    }

    /// Downloads a leaf-brick attribute image (0 albedo, 1 normal, 2 emission), texel
    /// after texel (x fastest).
    fn download_leaf_attribute(&self, which: usize) -> Result<Vec<u32>> {
        let image = &self.pools.leaf_attributes[which];
        let bytes =
            crate::vk::read_back_image(&self.ctx, image, 0, image.desc.extent, 4, BRICK_USE)?;
        Ok(bytemuck::cast_slice(&bytes).to_vec())
    }
}
