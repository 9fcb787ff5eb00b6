//! The sparse voxel octree store (`--gi octree`; Crassin et al. 2011), built on the GPU
//! level by level (Crassin & Green 2012) as in Dřínovský's thesis (2013, 5.2-5.4).
//!
//! Build (`build`): voxel-fragment list (the shared voxelization, appending records
//! through an atomic counter) -> octree, level by level (flag, alloc, init: `nodes`) ->
//! neighbour pointers -> leaf bricks filled from the fragments (`bricks`). Every pool's
//! capacity is checked on the GPU; a pool that overflows is reported, grown (`pools`),
//! and the build runs again.
//!
//! Frame: around moving meshes, the static part is restored and their nodes appended
//! after it (5.7); after voxel shading, only the nodes on the update lists are filtered
//! up the tree again (5.5).

mod bricks;
mod build;
mod nodes;
mod pools;
#[cfg(test)]
mod tests;

use std::sync::Arc;

use anyhow::{bail, Context as _, Result};
use ash::vk;
use gpu_allocator::MemoryLocation;

use super::voxelize::VoxelizePass;
use super::{
    Grid, PipelineBase, Preparation, Store, StoreShaders, VctSettings, VoxelStore, Voxels,
};
use crate::gi::DebugView;
use crate::gpu_layout::{self as layout, InjectPush, OctreeCounters, OctreeLevel};
use crate::scene::{Aabb, Scene};
use crate::scene_gpu::SceneDraw;
use crate::vk::shaders as s;
use crate::vk::{
    stage_barrier, update_buffer, Binding, Buffer, Context, GpuTimer, ImageUse, Pipeline, SetWriter,
};
pub use build::BuildReport;
use build::StaticPart;
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

/// The counters buffer: `OctreeCounters`, then the level table.
const COUNTERS_BYTES: usize = std::mem::size_of::<OctreeCounters>()
    + layout::OCTREE_MAX_LEVELS as usize * std::mem::size_of::<OctreeLevel>();

/// The radiance pools between passes: written as storage, sampled by cones.
const RADIANCE_USE: ImageUse = ImageUse {
    layout: vk::ImageLayout::GENERAL,
    stage: vk::PipelineStageFlags2::COMPUTE_SHADER,
    access: vk::AccessFlags2::from_raw(
        vk::AccessFlags2::SHADER_READ.as_raw() | vk::AccessFlags2::SHADER_WRITE.as_raw(),
    ),
};

/// How the leaf-brick attribute images are used between passes.
const BRICK_USE: ImageUse = ImageUse {
    layout: vk::ImageLayout::GENERAL,
    stage: vk::PipelineStageFlags2::COMPUTE_SHADER,
    access: vk::AccessFlags2::from_raw(
        vk::AccessFlags2::SHADER_STORAGE_READ.as_raw()
            | vk::AccessFlags2::SHADER_STORAGE_WRITE.as_raw(),
    ),
};

/// The sparse voxel octree of a scene.
pub struct Octree {
    /// The effective grid: 2^depth voxels per axis over the dense grid's cube.
    pub grid: Grid,
    pub depth: u32,
    /// `OctreeCounters`, then `OctreeLevel[OCTREE_MAX_LEVELS]`; also the indirect dispatches.
    counters: Buffer,
    /// Where cone samples start their descent (`BINDING_OCTREE_NODE_GRID`).
    node_grid: Buffer,
    fragments: Fragments,
    pools: Pools,
    voxelize: VoxelizePass,
    nodes: nodes::NodePasses,
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
    /// The counters ask for exact radiance stores (`OctreeCounters::exact_stores`, set by a
    /// build) until the end of the next frame's bounces.
    exact_stores: std::cell::Cell<bool>,
    /// `--full-update`: every mesh is voxelized again every frame too.
    full_update: bool,
    /// The carry table the current frame writes.
    carry_parity: u32,
    /// Per frame in flight: its counters, read when the slot comes round again.
    frame_counters: Vec<Buffer>,
    /// The radiance pools' sampler (the cone tracer's set refers to it).
    linear: vk::Sampler,
    /// Tests: shade every voxel every frame (what culling must match).
    #[cfg(test)]
    pub(crate) shade_every_voxel: bool,
    /// Tests: frames whose voxel shading culled.
    #[cfg(test)]
    pub(crate) culled_frames: u32,
    ctx: Arc<Context>,
}

impl VoxelStore for Octree {
    const SHADERS: StoreShaders = StoreShaders {
        inject: s::GI_VCT_INJECT_INJECT_COMP_OCTREE,
        bounce: s::GI_VCT_INJECT_BOUNCE_COMP_OCTREE,
        cone_trace: s::GI_VCT_CONE_TRACE_CONE_TRACE_COMP_OCTREE,
        cone_trace_ao: s::GI_VCT_CONE_TRACE_CONE_TRACE_COMP_OCTREE_AMBIENT_OCCLUSION,
        voxel_view: s::GI_VCT_DEBUG_VOXEL_VIEW_COMP_OCTREE,
    };

    const DEBUG_VIEWS: &'static [DebugView] = &[
        DebugView::None,
        DebugView::Indirect,
        DebugView::Ao,
        DebugView::VoxelAlbedo,
        DebugView::VoxelNormal,
        DebugView::VoxelRadiance,
        DebugView::EmitterLight,
        DebugView::OctreeNodes,
    ];

    /// The octree's own buffers and images; it binds its brick pools in the shared
    /// bindings, where the dense grid binds its volumes.
    fn bindings() -> Vec<Binding> {
        let all = super::STAGES;
        let storage = vk::DescriptorType::STORAGE_BUFFER;
        vec![
            Binding::new(layout::BINDING_OCTREE_COUNTERS, storage, all),
            Binding::new(layout::BINDING_OCTREE_FRAGMENTS, storage, all),
            Binding::new(layout::BINDING_OCTREE_FRAGMENT_SHADING, storage, all),
            Binding::new(layout::BINDING_OCTREE_NODES, storage, all),
            Binding::new(layout::BINDING_OCTREE_NODE_COORDS, storage, all),
            Binding::new(layout::BINDING_OCTREE_NODE_BRICKS, storage, all),
            Binding::new(layout::BINDING_OCTREE_NEIGHBOURS, storage, all),
            Binding::new(layout::BINDING_OCTREE_SUMS, storage, all),
            Binding::new(layout::BINDING_OCTREE_CARRY, storage, all),
            Binding::new(layout::BINDING_OCTREE_STATIC_NODES, storage, all),
            Binding::new(layout::BINDING_OCTREE_CHANGES, storage, all),
            Binding::new(layout::BINDING_OCTREE_UPDATES, storage, all),
            Binding::new(layout::BINDING_OCTREE_NODE_GRID, storage, all),
            Binding::new(
                layout::BINDING_OCTREE_DIRECTIONAL_STORAGE,
                vk::DescriptorType::STORAGE_IMAGE,
                all,
            ),
        ]
    }

    /// Writes the pools into `set`, with `linear` as the radiance pools' sampler. The
    /// store's `capacities` override the first guess of the pool sizes (the overflow test
    /// starts from tiny pools). With `full_update` every frame voxelizes every mesh and
    /// rebuilds the octree. The fragments are listed by the settings' voxelizer.
    fn new(
        ctx: &Arc<Context>,
        scene: &Scene,
        settings: &VctSettings,
        grid: Grid,
        set: vk::DescriptorSet,
        base: PipelineBase,
        linear: vk::Sampler,
        frames_in_flight: usize,
    ) -> Result<Self> {
        let depth = grid.resolution.trailing_zeros();
        check_depth(depth)?;
        let capacities = match settings.store {
            Store::Octree { capacities, .. } => capacities,
            Store::Dense { .. } => None,
        };
        let full_update = settings.full_update;
        let voxelizer = settings.voxelizer;
        let capacities = capacities.unwrap_or_else(|| Capacities::estimate(scene, &grid));
        let counters = Buffer::new(
            ctx,
            "octree counters",
            COUNTERS_BYTES as u64,
            vk::BufferUsageFlags::STORAGE_BUFFER
                | vk::BufferUsageFlags::INDIRECT_BUFFER
                | vk::BufferUsageFlags::TRANSFER_SRC
                | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuOnly,
        )?;
        let node_grid = Buffer::new(
            ctx,
            "octree node grid",
            4 * u64::from(nodes::node_grid_cells(depth)),
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::GpuOnly,
        )?;
        SetWriter::new(ctx, set)
            .buffer(
                layout::BINDING_OCTREE_COUNTERS,
                vk::DescriptorType::STORAGE_BUFFER,
                counters.raw,
            )
            .buffer(
                layout::BINDING_OCTREE_NODE_GRID,
                vk::DescriptorType::STORAGE_BUFFER,
                node_grid.raw,
            )
            .apply();
        let fragments = Fragments::new(ctx, capacities.fragments)?;
        fragments.write_set(ctx, set);
        let pools = Pools::new(
            ctx,
            capacities,
            scene.has_moving_meshes() || full_update,
            settings.store.directional_slots(),
        )?;
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
                "octree fragments",
                voxelizer,
                crate::vk::shaders::GI_VCT_OCTREE_FRAGMENTS_FRAGMENTS_FRAG,
                crate::vk::shaders::GI_VCT_VOXELIZE_VOXELIZE_COMP_OCTREE,
                base,
            )?,
            nodes: nodes::NodePasses::new(ctx, base)?,
            bricks: bricks::BrickPasses::new(ctx, base)?,
            bounce_gate: base.compute(
                ctx,
                "octree bounce dispatch",
                crate::vk::shaders::GI_VCT_OCTREE_BRICKS_BOUNCE_DISPATCH_COMP,
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
                        &format!("octree frame counters {i}"),
                        COUNTERS_BYTES as u64,
                        vk::BufferUsageFlags::TRANSFER_DST,
                        MemoryLocation::GpuToCpu,
                    )?;
                    buffer.write(0, &[0; COUNTERS_BYTES]);
                    Ok(buffer)
                })
                .collect::<Result<_>>()?,
            linear,
            #[cfg(test)]
            shade_every_voxel: false,
            #[cfg(test)]
            culled_frames: 0,
            ctx: ctx.clone(),
        })
    }

    fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The octree's build (waited for; its pools grow and it runs again if they
    /// overflow).
    fn prepare(&mut self, draw: &SceneDraw, set: vk::DescriptorSet) -> Result<()> {
        self.build(draw, set).map(|_| ())
    }

    /// Built before the first frame; with moving meshes, they are inserted every frame.
    fn record_voxels(
        &mut self,
        cmd: vk::CommandBuffer,
        timer: &mut GpuTimer,
        draw: &SceneDraw,
        set: vk::DescriptorSet,
        slot: usize,
    ) -> Result<Voxels> {
        let rebuilt = self.moving();
        if rebuilt {
            self.record_moving(cmd, timer, draw, set, slot)?;
        }
        Ok(Voxels {
            list: self.pools.voxel_list.raw,
            rebuilt,
        })
    }

    /// Culls: shades again only the voxels whose light can have changed, unless a build
    /// just happened (the bricks hold no light yet) or the lighting changed.
    fn shading(&mut self, lighting_changed: bool, push: &mut InjectPush) -> bool {
        let built = self.just_built();
        let cull = !built && !lighting_changed;
        #[cfg(test)]
        let cull = cull && !self.shade_every_voxel;
        #[cfg(test)]
        {
            self.culled_frames += u32::from(cull);
        }
        push.cull = u32::from(cull);
        push.keep_indirect = u32::from(self.moving() && !built);
        let [first, last] = self.region.unwrap_or([[0; 3], [-1; 3]]);
        push.region_min = [first[0], first[1], first[2], 0];
        push.region_max = [last[0], last[1], last[2], 0];
        // A still octree under the same light: no voxel's light changed.
        !cull || self.moving()
    }

    /// Filters the leaf radiance up the tree, bottom-up, with the bricks' borders copied
    /// from their neighbours at every level (after voxel shading or a bounce): only the
    /// nodes on the update lists (Dřínovský 2013, 5.5), which start from the leaves whose
    /// radiance voxel shading changed and, around moving meshes, the nodes near where
    /// they were or are; every node after a build and with `--full-update`.
    /// Each level's passes are timed apart: `spread L`, `border L` and `filter L`.
    fn record_filter(
        &self,
        cmd: vk::CommandBuffer,
        timer: &mut GpuTimer,
        frame_set: vk::DescriptorSet,
        set: vk::DescriptorSet,
        _name: &str,
    ) {
        let sets = [(layout::SET_FRAME, frame_set), (layout::SET_GI, set)];
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
        let all: Vec<u32> = (0..layout::OCTREE_UPDATE_LISTS).collect();
        self.bricks
            .reset_update_lists(ctx, cmd, self.pools.updates.raw, &all);
    }

    /// Records what a bounce dispatches, and returns where (buffer, offset): the voxel
    /// list around moving meshes; in a static octree the list while anything changed
    /// since the last bounce and nothing once the bounces have converged (the same light
    /// would be stored again).
    fn bounce_dispatch(
        &self,
        cmd: vk::CommandBuffer,
        frame_set: vk::DescriptorSet,
        set: vk::DescriptorSet,
    ) -> (vk::Buffer, vk::DeviceSize) {
        if self.moving() {
            return (self.pools.voxel_list.raw, 0);
        }
        let sets = [(layout::SET_FRAME, frame_set), (layout::SET_GI, set)];
        self.bounce_gate.dispatch(cmd, &sets, [1, 1, 1]);
        nodes::compute_to_indirect(&self.ctx, cmd);
        (self.pools.updates.raw, pools::BOUNCE_DISPATCH_OFFSET)
    }

    /// After a frame's bounces: the frames after the one that follows a build store only
    /// changes beyond the tolerance, so that converged bounces stop.
    fn record_end_of_bounces(&self, cmd: vk::CommandBuffer) {
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
                std::mem::offset_of!(OctreeCounters, exact_stores) as u64,
                bytemuck::bytes_of(&0u32),
                vk::PipelineStageFlags2::COMPUTE_SHADER,
            );
        }
    }

    /// GPU memory of every octree resource, by name.
    fn memory_bytes(&self) -> Vec<(&'static str, u64)> {
        let mut bytes = vec![
            (
                "octree_fragments",
                self.fragments.voxels.size + self.fragments.shading.size,
            ),
            ("octree_counters", self.counters.size),
            ("octree_node_grid", self.node_grid.size),
        ];
        bytes.extend(self.pools.bytes());
        bytes
    }

    fn stats(&self) -> Result<Vec<(String, f64)>> {
        let build = self.report().context("the octree was not built")?;
        let mut stats = vec![("octree_depth".to_string(), f64::from(self.depth))];
        stats.extend(build.stats(&self.capacities()));
        Ok(stats)
    }

    fn preparation(&self) -> Option<Preparation> {
        self.report.as_ref().map(|build| Preparation {
            summary: format!(
                "octree build ({}^3 effective, {} attempt(s), {:.1} ms wall)",
                self.grid.resolution,
                build.regrowths.len() + 1,
                build.wall_ms
            ),
            passes: build.passes.clone(),
        })
    }
}

impl Octree {
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

    /// The last build's report.
    pub fn report(&self) -> Option<&BuildReport> {
        self.report.as_ref()
    }

    pub fn capacities(&self) -> Capacities {
        self.pools.capacities
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
        let seen: OctreeCounters = bytemuck::pod_read_unaligned(
            &self.frame_counters[slot].mapped()[..std::mem::size_of::<OctreeCounters>()],
        );
        if seen.overflow != 0 {
            log::warn!(
                "octree pools overflowed while meshes moved ({}); rebuilding",
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
}

#[cfg(test)]
impl Octree {
    /// Filters every node, whatever the update lists hold, and waits.
    fn full_filter(&self, frame_set: vk::DescriptorSet, set: vk::DescriptorSet) -> Result<()> {
        let sets = [(layout::SET_FRAME, frame_set), (layout::SET_GI, set)];
        // Outlives the command buffer, which writes its queries.
        let mut timer = GpuTimer::new(&self.ctx)?;
        crate::vk::OneShot::new(&self.ctx)?.run("full octree filter", |cmd| {
            crate::vk::compute_to_compute(&self.ctx, cmd);
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
