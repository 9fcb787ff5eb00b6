//! The octree's pools: how large each is (a first guess from the scene, grown exactly
//! after an overflow, fitted once to what a build used) and the buffers and images that
//! hold them.

use std::sync::Arc;

use anyhow::{ensure, Result};
use ash::vk;
use gpu_allocator::MemoryLocation;

use super::super::dense::COVERAGE_FORMAT;
use super::super::{bind_cone_samples, Grid};
use crate::gpu_layout::{
    self as layout, OctreeBounceDispatch, OctreeCounters, OctreeUpdateList, VoxelListHeader,
};
use crate::scene::Scene;
use crate::vk::{Buffer, Context, Image, ImageDesc, ImageUse, SetWriter};

/// How many records each pool holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Capacities {
    pub fragments: u32,
    pub nodes: u32,
    pub leaf_bricks: u32,
    pub interior_bricks: u32,
    /// Occupied leaf voxels (their fragments' sums).
    pub leaf_voxels: u32,
}

impl Capacities {
    /// A first guess of the fragments from the scene's surface area (about three per
    /// voxel face of area: dilation, slopes, overlapping triangles), and of the octree's
    /// pools from that: small, since the octree's counters keep counting past a full pool,
    /// so one regrowth sizes a pool exactly. Wrong guesses cost a rebuild of the octree
    /// (not of the fragments), never a wrong image.
    pub fn estimate(scene: &Scene, grid: &Grid) -> Self {
        let area: f64 = (0..scene.meshes.len()).map(|m| scene.mesh_area(m)).sum();
        let triangles: u64 = scene
            .meshes
            .iter()
            .map(|m| m.indices.len() as u64 / 3)
            .sum();
        let face = f64::from(grid.voxel_size).powi(2);
        let fragments = (3.0 * area / face + 2.0 * triangles as f64).max(4096.0);
        Self::for_fragments(fragments.min(f64::from(u32::MAX / 2)) as u32)
    }

    /// The octree's pools for `fragments` fragments: a quarter of what a surface would
    /// need if every fragment were a voxel of its own.
    fn for_fragments(fragments: u32) -> Self {
        Self {
            fragments,
            nodes: fragments / 16 + 64,
            leaf_bricks: fragments / 64 + 16,
            interior_bricks: fragments / 256 + 16,
            leaf_voxels: fragments / 16 + 16,
        }
    }

    /// The octree's pools fitted to what a build without overflow used, with an eighth
    /// more (moving meshes change the counts from frame to frame); unchanged where the
    /// capacity is already within a quarter of that.
    pub(super) fn fitted(&self, counters: &OctreeCounters) -> Self {
        let fit = |capacity: u32, used: u32| {
            let want = used.saturating_add(used / 8).saturating_add(16);
            if capacity > want.saturating_add(want / 4) {
                want
            } else {
                capacity
            }
        };
        Self {
            fragments: self.fragments,
            nodes: fit(self.nodes, counters.node_count),
            leaf_bricks: fit(self.leaf_bricks, counters.leaf_bricks),
            interior_bricks: fit(self.interior_bricks, counters.interior_bricks),
            leaf_voxels: fit(self.leaf_voxels, counters.leaf_voxels),
        }
    }

    /// Capacities for another build after `counters` reported an overflow. The counters
    /// count past a full pool, so what a pool needed is exact when the pools it depends
    /// on did not overflow too (the fragments depend on nothing; the bricks on the node
    /// pool); it gets that with a margin. The node pool's count is exact only up to the
    /// level that ran out: it gets at least four times as much.
    pub(super) fn grown(&self, counters: &OctreeCounters) -> Self {
        let nodes_short = counters.overflow & layout::OCTREE_OVERFLOW_NODES != 0;
        let grow = |capacity: u32, used: u32, bit: u32, exact: bool| {
            if counters.overflow & bit == 0 {
                capacity
            } else if exact {
                used.saturating_add(used / 8).saturating_add(16)
            } else {
                capacity
                    .saturating_mul(4)
                    .max(used.saturating_add(used / 2))
            }
        };
        Self {
            fragments: grow(
                self.fragments,
                counters.fragment_count,
                layout::OCTREE_OVERFLOW_FRAGMENTS,
                true,
            ),
            nodes: grow(
                self.nodes,
                counters.node_count,
                layout::OCTREE_OVERFLOW_NODES,
                false,
            ),
            leaf_bricks: grow(
                self.leaf_bricks,
                counters.leaf_bricks,
                layout::OCTREE_OVERFLOW_LEAF_BRICKS,
                !nodes_short,
            ),
            interior_bricks: grow(
                self.interior_bricks,
                counters.interior_bricks,
                layout::OCTREE_OVERFLOW_INTERIOR_BRICKS,
                !nodes_short,
            ),
            leaf_voxels: grow(
                self.leaf_voxels,
                counters.leaf_voxels,
                layout::OCTREE_OVERFLOW_LEAF_VOXELS,
                !nodes_short,
            ),
        }
    }
}

/// Which pools an overflow report names.
pub(super) fn overflowed(counters: &OctreeCounters, capacities: &Capacities) -> Vec<String> {
    let pools = [
        (
            layout::OCTREE_OVERFLOW_FRAGMENTS,
            "voxel-fragment list",
            counters.fragment_count,
            capacities.fragments,
        ),
        (
            layout::OCTREE_OVERFLOW_NODES,
            "node pool",
            counters.node_count,
            capacities.nodes,
        ),
        (
            layout::OCTREE_OVERFLOW_LEAF_BRICKS,
            "leaf brick pool",
            counters.leaf_bricks,
            capacities.leaf_bricks,
        ),
        (
            layout::OCTREE_OVERFLOW_INTERIOR_BRICKS,
            "interior brick pool",
            counters.interior_bricks,
            capacities.interior_bricks,
        ),
        (
            layout::OCTREE_OVERFLOW_LEAF_VOXELS,
            "leaf voxel sums",
            counters.leaf_voxels,
            capacities.leaf_voxels,
        ),
    ];
    pools
        .iter()
        .filter(|(bit, ..)| counters.overflow & bit != 0)
        .map(|(_, name, used, capacity)| {
            format!("{name}: {capacity} entries, at least {used} needed")
        })
        .collect()
}

/// The smallest cube of bricks holding `bricks`: bricks per edge of the pool image.
fn pool_side(bricks: u32) -> u32 {
    let mut side = (f64::from(bricks.max(1))).cbrt().ceil() as u32;
    while u64::from(side).pow(3) < u64::from(bricks) {
        side += 1;
    }
    side
}

/// The octree's pools on the GPU.
pub(super) struct Pools {
    pub(super) capacities: Capacities,
    pub(super) nodes: Buffer,
    pub(super) coords: Buffer,
    pub(super) bricks: Buffer,
    pub(super) neighbours: Buffer,
    pub(super) leaf_side: u32,
    pub(super) interior_side: u32,
    /// Leaf-brick attributes: albedo, normal, emission (`OCTREE_ATTRIBUTE_BRICK`³ each).
    pub(super) leaf_attributes: [Image; 3],
    /// Leaf voxels' direct light, the start of each bounce (`OCTREE_ATTRIBUTE_BRICK`³ each).
    pub(super) leaf_direct: Image,
    /// Leaf radiance (`OCTREE_RADIANCE_BRICK`³ each: the voxels and a border).
    pub(super) leaf_radiance: Image,
    /// Leaf voxels' coverage (`BINDING_VCT_COVERAGE`), laid out as `leaf_radiance`.
    pub(super) leaf_coverage: Image,
    /// Interior bricks' six directional radiances, and with the planes (`Store::planes`) their
    /// planes and coverage, side by side along x (`slots` of them).
    pub(super) directional: Image,
    pub(super) slots: u32,
    /// The occupied leaf voxels with their bricks (`VoxelListHeader`, then two words each).
    pub(super) voxel_list: Buffer,
    /// Per leaf voxel, its fragments' attribute sums and count (`VOXEL_SUM_WORDS` words).
    pub(super) sums: Buffer,
    /// Two tables of `carry_capacity` entries: the light each leaf voxel in a brick given
    /// out by a frame's insertion of meshes gathered, for the same voxel next frame (its
    /// brick is new again, or it is back in its static brick); sized by `size_carry`.
    pub(super) carry: Buffer,
    pub(super) carry_capacity: u32,
    /// The static part's child entries and bricks as its build left them (only with
    /// moving meshes): every frame restores them before it inserts the moving meshes.
    pub(super) static_children: Buffer,
    pub(super) static_bricks: Buffer,
    /// Per brick, its change bits while the filter's update lists are built.
    pub(super) changes: Buffer,
    /// The filter's update lists: their heads, then `capacities.nodes` nodes each.
    pub(super) updates: Buffer,
    /// The images have left their initial layout (they are in GENERAL since, read and
    /// written by any pass of earlier frames).
    pub(super) in_general: std::cell::Cell<bool>,
}

/// A storage buffer of the pools (also copied and filled), within the device's limit.
fn storage_buffer(
    ctx: &Arc<Context>,
    name: &str,
    bytes: u64,
    extra: vk::BufferUsageFlags,
) -> Result<Buffer> {
    let device_limit = u64::from(ctx.properties.limits.max_storage_buffer_range);
    ensure!(
        bytes <= device_limit,
        "the octree {name} needs {bytes} bytes, more than the device's largest storage buffer \
         ({device_limit} bytes): use a smaller --octree-depth"
    );
    let storage = vk::BufferUsageFlags::STORAGE_BUFFER
        | vk::BufferUsageFlags::TRANSFER_SRC
        | vk::BufferUsageFlags::TRANSFER_DST;
    Buffer::new(ctx, name, bytes, storage | extra, MemoryLocation::GpuOnly)
}

/// The two carry tables of `capacity` entries (4 words each).
fn carry_tables(ctx: &Arc<Context>, capacity: u32) -> Result<Buffer> {
    storage_buffer(
        ctx,
        "octree carry",
        2 * 16 * u64::from(capacity.max(1)),
        vk::BufferUsageFlags::empty(),
    )
}

/// The update lists' heads, at the start of `Pools::updates`.
pub(super) const UPDATE_HEADS_BYTES: u64 =
    layout::OCTREE_UPDATE_LISTS as u64 * std::mem::size_of::<OctreeUpdateList>() as u64;

/// The bounce's dispatch, after the update lists' heads in `Pools::updates`.
pub(super) const BOUNCE_DISPATCH_OFFSET: u64 = UPDATE_HEADS_BYTES;

impl Pools {
    /// `moving`: moving meshes are inserted into the octree every frame; the static
    /// part is kept aside. `slots`: the interior bricks' volumes (`DIRECTIONAL_SLOTS`,
    /// and `PLANE_SLOTS` more with the planes: `Store::planes`).
    pub(super) fn new(
        ctx: &Arc<Context>,
        capacities: Capacities,
        moving: bool,
        slots: u32,
    ) -> Result<Self> {
        let max_3d = ctx.properties.limits.max_image_dimension3_d;
        let buffer = |name: &str, bytes: u64, extra| storage_buffer(ctx, name, bytes, extra);
        let nodes = u64::from(capacities.nodes);
        let leaf_side = pool_side(capacities.leaf_bricks);
        let interior_side = pool_side(capacities.interior_bricks);
        let radiance_edge = (slots * interior_side).max(leaf_side) * layout::OCTREE_RADIANCE_BRICK;
        ensure!(
            radiance_edge <= max_3d,
            "the octree brick pools ({} leaf, {} interior bricks) exceed the device's 3D image \
             size ({max_3d} texels, {radiance_edge} needed): use a smaller --octree-depth",
            capacities.leaf_bricks,
            capacities.interior_bricks
        );
        let usage = vk::ImageUsageFlags::STORAGE
            | vk::ImageUsageFlags::TRANSFER_DST
            | vk::ImageUsageFlags::TRANSFER_SRC;
        let image = |name, format, edge, sampled: bool| {
            let usage = if sampled {
                usage | vk::ImageUsageFlags::SAMPLED
            } else {
                usage
            };
            Image::new(ctx, name, ImageDesc::d3(format, edge, 1, usage))
        };
        let attribute_edge = leaf_side * layout::OCTREE_ATTRIBUTE_BRICK;
        let packed = |name| image(name, vk::Format::R32_UINT, attribute_edge, false);
        let rgba16 = vk::Format::R16G16B16A16_SFLOAT;
        let interior_edge = interior_side * layout::OCTREE_RADIANCE_BRICK;
        let mut directional_desc = ImageDesc::d3(
            rgba16,
            interior_edge,
            1,
            usage | vk::ImageUsageFlags::SAMPLED,
        );
        directional_desc.extent.width = slots * interior_edge;
        // A leaf's first sum sits in bits 8-31 of its child entry.
        ensure!(
            capacities.leaf_voxels <= 1 << 24,
            "the octree needs sums for {} leaf voxels, more than the 2^24 its nodes can point \
             to: use a smaller --octree-depth",
            capacities.leaf_voxels
        );
        let list_words = 2 * u64::from(capacities.leaf_voxels);
        Ok(Self {
            capacities,
            nodes: buffer("octree nodes", 4 * nodes, vk::BufferUsageFlags::empty())?,
            coords: buffer(
                "octree node coords",
                4 * nodes,
                vk::BufferUsageFlags::empty(),
            )?,
            bricks: buffer(
                "octree node bricks",
                4 * nodes,
                vk::BufferUsageFlags::empty(),
            )?,
            neighbours: buffer(
                "octree neighbours",
                24 * nodes,
                vk::BufferUsageFlags::empty(),
            )?,
            leaf_side,
            interior_side,
            leaf_attributes: [
                packed("octree leaf albedo")?,
                packed("octree leaf normal")?,
                packed("octree leaf emission")?,
            ],
            leaf_direct: image("octree leaf direct", rgba16, attribute_edge, false)?,
            leaf_radiance: image(
                "octree leaf radiance",
                rgba16,
                leaf_side * layout::OCTREE_RADIANCE_BRICK,
                true,
            )?,
            leaf_coverage: image(
                "octree leaf coverage",
                COVERAGE_FORMAT,
                leaf_side * layout::OCTREE_RADIANCE_BRICK,
                true,
            )?,
            directional: Image::new(ctx, "octree interior radiance", directional_desc)?,
            slots,
            voxel_list: buffer(
                "octree voxel list",
                std::mem::size_of::<VoxelListHeader>() as u64 + 4 * list_words,
                vk::BufferUsageFlags::INDIRECT_BUFFER,
            )?,
            sums: buffer(
                "octree fragment sums",
                4 * u64::from(layout::VOXEL_SUM_WORDS) * u64::from(capacities.leaf_voxels),
                vk::BufferUsageFlags::empty(),
            )?,
            in_general: std::cell::Cell::new(false),
            carry_capacity: 0,
            carry: carry_tables(ctx, 0)?,
            static_children: buffer(
                "octree static nodes",
                if moving { 4 * nodes } else { 4 },
                vk::BufferUsageFlags::empty(),
            )?,
            static_bricks: buffer(
                "octree static node bricks",
                if moving { 4 * nodes } else { 4 },
                vk::BufferUsageFlags::empty(),
            )?,
            changes: buffer(
                "octree brick changes",
                4 * (u64::from(capacities.leaf_bricks) + u64::from(capacities.interior_bricks)),
                vk::BufferUsageFlags::empty(),
            )?,
            updates: buffer(
                "octree update lists",
                UPDATE_HEADS_BYTES
                    + std::mem::size_of::<OctreeBounceDispatch>() as u64
                    + 4 * u64::from(layout::OCTREE_UPDATE_LISTS) * nodes,
                vk::BufferUsageFlags::INDIRECT_BUFFER,
            )?,
        })
    }

    /// Sizes the carry tables for `voxels` leaf voxels in new bricks per frame at most (none
    /// without moving meshes), half full at most for short probes, and writes them into
    /// the GI set.
    pub(super) fn size_carry(
        &mut self,
        ctx: &Arc<Context>,
        set: vk::DescriptorSet,
        voxels: Option<u32>,
    ) -> Result<()> {
        let capacity = voxels.map_or(0, |v| (2 * v.max(1)).next_power_of_two());
        if capacity != self.carry_capacity {
            self.carry = carry_tables(ctx, capacity)?;
            self.carry_capacity = capacity;
            SetWriter::new(ctx, set)
                .buffer(
                    layout::BINDING_OCTREE_CARRY,
                    vk::DescriptorType::STORAGE_BUFFER,
                    self.carry.raw,
                )
                .apply();
        }
        Ok(())
    }

    /// Writes the pools into the GI set: the octree's own bindings, and the bindings where
    /// the dense grid has its volumes.
    pub(super) fn write_set(&self, ctx: &Context, set: vk::DescriptorSet, linear: vk::Sampler) {
        let storage = vk::DescriptorType::STORAGE_BUFFER;
        let [albedo, normal, emission] = &self.leaf_attributes;
        let writer = SetWriter::new(ctx, set)
            .buffer(layout::BINDING_OCTREE_NODES, storage, self.nodes.raw)
            .buffer(layout::BINDING_OCTREE_NODE_COORDS, storage, self.coords.raw)
            .buffer(layout::BINDING_OCTREE_NODE_BRICKS, storage, self.bricks.raw)
            .buffer(
                layout::BINDING_OCTREE_NEIGHBOURS,
                storage,
                self.neighbours.raw,
            )
            .buffer(layout::BINDING_VCT_VOXEL_LIST, storage, self.voxel_list.raw)
            .buffer(layout::BINDING_OCTREE_SUMS, storage, self.sums.raw)
            .buffer(layout::BINDING_OCTREE_CARRY, storage, self.carry.raw)
            .buffer(
                layout::BINDING_OCTREE_STATIC_NODES,
                storage,
                self.static_children.raw,
            )
            .buffer(layout::BINDING_OCTREE_CHANGES, storage, self.changes.raw)
            .buffer(layout::BINDING_OCTREE_UPDATES, storage, self.updates.raw)
            .storage_image(layout::BINDING_VCT_ALBEDO, albedo.view)
            .storage_image(layout::BINDING_VCT_NORMAL, normal.view)
            .storage_image(layout::BINDING_VCT_EMISSION, emission.view)
            .storage_image(layout::BINDING_VCT_DIRECT, self.leaf_direct.view)
            .storage_image(layout::BINDING_VCT_RADIANCE, self.leaf_radiance.view)
            .storage_image(
                layout::BINDING_OCTREE_DIRECTIONAL_STORAGE,
                self.directional.view,
            );
        bind_cone_samples(
            writer,
            &self.leaf_radiance,
            &self.leaf_coverage,
            &self.directional,
            linear,
        )
        .apply();
    }

    /// The state of the images before a build: new (the first time), or whatever any
    /// shader of an earlier frame did with them.
    pub(super) fn last_use(&self) -> ImageUse {
        if self.in_general.get() {
            ImageUse {
                layout: vk::ImageLayout::GENERAL,
                stage: vk::PipelineStageFlags2::ALL_COMMANDS,
                access: vk::AccessFlags2::SHADER_READ | vk::AccessFlags2::SHADER_WRITE,
            }
        } else {
            ImageUse::UNDEFINED
        }
    }

    pub(super) fn bytes(&self) -> Vec<(&'static str, u64)> {
        let bricks: u64 = self
            .leaf_attributes
            .iter()
            .chain([
                &self.leaf_direct,
                &self.leaf_radiance,
                &self.leaf_coverage,
                &self.directional,
            ])
            .map(Image::memory_bytes)
            .sum();
        vec![
            (
                "octree_node_pool",
                self.nodes.size + self.coords.size + self.bricks.size + self.neighbours.size,
            ),
            ("octree_brick_pool", bricks),
            ("octree_voxel_list", self.voxel_list.size),
            ("octree_fragment_sums", self.sums.size),
            ("octree_carry", self.carry.size),
            (
                "octree_static_nodes",
                self.static_children.size + self.static_bricks.size,
            ),
            ("octree_update_lists", self.changes.size + self.updates.size),
        ]
    }
}

/// The voxel-fragment list, in two halves of 8 bytes per fragment: the voxels then the
/// albedos (`voxels`), the normals and emissions (`shading`).
pub(super) struct Fragments {
    pub(super) capacity: u32,
    pub(super) voxels: Buffer,
    pub(super) shading: Buffer,
}

impl Fragments {
    pub(super) fn new(ctx: &Arc<Context>, capacity: u32) -> Result<Self> {
        let bytes = 8 * u64::from(capacity);
        let limit = u64::from(ctx.properties.limits.max_storage_buffer_range);
        ensure!(
            bytes <= limit,
            "the octree's voxel-fragment list needs 2 x {bytes} bytes for {capacity} fragments, \
             more than the device's largest storage buffer ({limit} bytes): use a smaller \
             --octree-depth"
        );
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC;
        let buffer = |name| Buffer::new(ctx, name, bytes, usage, MemoryLocation::GpuOnly);
        Ok(Self {
            capacity,
            voxels: buffer("octree fragment voxels")?,
            shading: buffer("octree fragment shading")?,
        })
    }

    pub(super) fn write_set(&self, ctx: &Context, set: vk::DescriptorSet) {
        let storage = vk::DescriptorType::STORAGE_BUFFER;
        SetWriter::new(ctx, set)
            .buffer(layout::BINDING_OCTREE_FRAGMENTS, storage, self.voxels.raw)
            .buffer(
                layout::BINDING_OCTREE_FRAGMENT_SHADING,
                storage,
                self.shading.raw,
            )
            .apply();
    }
}
