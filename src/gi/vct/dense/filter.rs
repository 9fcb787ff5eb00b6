//! Anisotropic filtering: the six directional mip chains of the voxel radiance (side by
//! side in one texture). By pairs (the default): one compute dispatch per level, each
//! level from the one below. By rows (`--directional-filter rows`): one dispatch per level
//! and direction, each level from the rows of voxels below it, kept composited along the
//! direction's axis in two images that the levels take turns writing.

use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use super::{Volumes, RADIANCE_FORMAT};
use crate::gi::vct::DirectionalFilter;
use crate::gpu_layout::{self as layout, FilterPush, FilterRowsPush};
use crate::vk::{
    compute_to_compute, groups_3d, to_compute_write, Binding, Context, DescriptorSets, Image,
    ImageDesc, OwnedView, Pipeline, SetWriter,
};

pub struct FilterPass {
    pipeline: Pipeline,
    /// One set per level: level 0 reads the base volume, level k the directional level
    /// k-1 (by pairs) or the rows of level k-1 (by rows).
    level_sets: Vec<vk::DescriptorSet>,
    by_rows: bool,
    /// By pairs: also the cells' surface planes (`Store::planes`).
    planes: bool,
    _sets: DescriptorSets,
    /// Per-level views of the directional texture, referenced by the sets.
    _views: Vec<OwnedView>,
    /// By rows: the rows of the levels written last and before, n/2 x n x n each
    /// (`glsl/gi/vct/dense/filter_rows.comp`).
    rows: Vec<Image>,
}

impl FilterPass {
    /// `set_layouts` are those of sets 0 and 1 (unused, but set 2 sits after them);
    /// `planes` whether the filter by pairs keeps the cells' planes; `n` the grid's
    /// resolution.
    pub(super) fn new(
        ctx: &Arc<Context>,
        set_layouts: [vk::DescriptorSetLayout; 2],
        volumes: &Volumes,
        filter: DirectionalFilter,
        planes: bool,
        n: u32,
    ) -> Result<Self> {
        let by_rows = filter == DirectionalFilter::Rows;
        let storage = vk::DescriptorType::STORAGE_IMAGE;
        let compute = vk::ShaderStageFlags::COMPUTE;
        let mut bindings = vec![
            Binding::new(layout::BINDING_FILTER_BASE, storage, compute),
            Binding::new(layout::BINDING_FILTER_DST, storage, compute),
            Binding::new(layout::BINDING_FILTER_NORMAL, storage, compute),
        ];
        let rows = if by_rows {
            bindings.push(Binding::new(
                layout::BINDING_FILTER_ROWS_SRC,
                storage,
                compute,
            ));
            bindings.push(Binding::new(
                layout::BINDING_FILTER_ROWS_DST,
                storage,
                compute,
            ));
            let mut desc = ImageDesc::d3(RADIANCE_FORMAT, n, 1, vk::ImageUsageFlags::STORAGE);
            desc.extent.width = n / 2;
            let rows = vec![
                Image::new(ctx, "voxel filter rows 0", desc)?,
                Image::new(ctx, "voxel filter rows 1", desc)?,
            ];
            to_compute_write(ctx, "voxel filter rows layouts", &[&rows[0], &rows[1]])?;
            rows
        } else {
            bindings.push(Binding::new(layout::BINDING_FILTER_SRC, storage, compute));
            Vec::new()
        };
        let levels = volumes.directional.desc.mip_levels;
        let sets = DescriptorSets::new(ctx, "filter", &bindings, levels)?;
        let (shader, push) = if by_rows {
            (
                crate::vk::shaders::GI_VCT_DENSE_FILTER_ROWS_COMP,
                std::mem::size_of::<FilterRowsPush>() as u32,
            )
        } else {
            (
                crate::vk::shaders::GI_VCT_DENSE_FILTER_COMP,
                std::mem::size_of::<FilterPush>() as u32,
            )
        };
        let pipeline = Pipeline::compute(
            ctx,
            "filter",
            shader,
            &[set_layouts[0], set_layouts[1], sets.layout],
            push,
        )?;
        let views = (0..levels)
            .map(|level| volumes.directional.layer_view(0, level))
            .collect::<Result<Vec<_>>>()?;
        let mut level_sets = Vec::new();
        for level in 0..levels as usize {
            let set = sets.allocate(&format!("filter level {level}"))?;
            let writer = SetWriter::new(ctx, set)
                .storage_image(layout::BINDING_FILTER_BASE, volumes.radiance.view)
                .storage_image(layout::BINDING_FILTER_DST, views[level].raw)
                .storage_image(layout::BINDING_FILTER_NORMAL, volumes.normal.view);
            // The first level reads the base; it still needs a source bound.
            let writer = if by_rows {
                writer
                    .storage_image(layout::BINDING_FILTER_ROWS_SRC, rows[(level + 1) % 2].view)
                    .storage_image(layout::BINDING_FILTER_ROWS_DST, rows[level % 2].view)
            } else {
                writer.storage_image(
                    layout::BINDING_FILTER_SRC,
                    views[level.saturating_sub(1)].raw,
                )
            };
            writer.apply();
            level_sets.push(set);
        }
        Ok(Self {
            pipeline,
            level_sets,
            by_rows,
            planes,
            _sets: sets,
            _views: views,
            rows,
        })
    }

    /// Builds every level from the base radiance (written before this, barrier included).
    pub fn record(&self, ctx: &Context, cmd: vk::CommandBuffer, n: u32) {
        let directions = if self.by_rows { 0..6 } else { 0..1 };
        for direction in directions {
            for (level, &set) in self.level_sets.iter().enumerate() {
                // Each dispatch reads what the one before wrote (by rows: the rows, which
                // the next direction's first level overwrites).
                if level > 0 || direction > 0 {
                    compute_to_compute(ctx, cmd);
                }
                let stages = vk::ShaderStageFlags::COMPUTE;
                if self.by_rows {
                    let push = FilterRowsPush {
                        level: level as u32,
                        direction,
                    };
                    self.pipeline.push(cmd, stages, &push);
                } else {
                    let push = FilterPush {
                        level: level as u32,
                        planes: u32::from(self.planes),
                    };
                    self.pipeline.push(cmd, stages, &push);
                }
                let size = (n >> (level + 1)).max(1);
                self.pipeline.dispatch(
                    cmd,
                    &[(layout::SET_PASS, set)],
                    groups_3d(size, layout::VOXEL_GROUP_SIZE),
                );
            }
        }
    }

    /// The rows' images' bytes (0 by pairs).
    pub fn memory_bytes(&self) -> u64 {
        self.rows.iter().map(Image::memory_bytes).sum()
    }
}
