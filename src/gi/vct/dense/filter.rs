//! Anisotropic filtering: the six directional mip chains of the voxel radiance (side by
//! side in one texture), one compute dispatch per level.

use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use super::Volumes;
use crate::gpu_layout as layout;
use crate::vk::{
    compute_to_compute, groups_3d, Binding, Context, DescriptorSets, OwnedView, Pipeline, SetWriter,
};

pub struct FilterPass {
    pipeline: Pipeline,
    /// One set per level: level 0 reads the base volume, level k the directional level k-1.
    level_sets: Vec<vk::DescriptorSet>,
    _sets: DescriptorSets,
    /// Per-level views of the directional texture, referenced by the sets.
    _views: Vec<OwnedView>,
}

impl FilterPass {
    /// `set_layouts` are those of sets 0 and 1 (unused, but set 2 sits after them).
    pub(super) fn new(
        ctx: &Arc<Context>,
        set_layouts: [vk::DescriptorSetLayout; 2],
        volumes: &Volumes,
    ) -> Result<Self> {
        let storage = vk::DescriptorType::STORAGE_IMAGE;
        let compute = vk::ShaderStageFlags::COMPUTE;
        let bindings = [
            Binding::new(layout::BINDING_FILTER_BASE, storage, compute),
            Binding::new(layout::BINDING_FILTER_SRC, storage, compute),
            Binding::new(layout::BINDING_FILTER_DST, storage, compute),
            Binding::new(layout::BINDING_FILTER_NORMAL, storage, compute),
        ];
        let levels = volumes.directional.desc.mip_levels;
        let sets = DescriptorSets::new(ctx, "filter", &bindings, levels)?;
        let pipeline = Pipeline::compute(
            ctx,
            "filter",
            crate::vk::shaders::GI_VCT_DENSE_FILTER_COMP,
            &[set_layouts[0], set_layouts[1], sets.layout],
            4,
        )?;
        let views = (0..levels)
            .map(|level| volumes.directional.layer_view(0, level))
            .collect::<Result<Vec<_>>>()?;
        let mut level_sets = Vec::new();
        for level in 0..levels as usize {
            let set = sets.allocate(&format!("filter level {level}"))?;
            // The first level reads the base; it still needs some level bound as source.
            let src = &views[level.saturating_sub(1)];
            SetWriter::new(ctx, set)
                .storage_image(layout::BINDING_FILTER_BASE, volumes.radiance.view)
                .storage_image(layout::BINDING_FILTER_SRC, src.raw)
                .storage_image(layout::BINDING_FILTER_DST, views[level].raw)
                .storage_image(layout::BINDING_FILTER_NORMAL, volumes.normal.view)
                .apply();
            level_sets.push(set);
        }
        Ok(Self {
            pipeline,
            level_sets,
            _sets: sets,
            _views: views,
        })
    }

    /// Builds every level from the base radiance (written before this, barrier included).
    pub fn record(&self, ctx: &Context, cmd: vk::CommandBuffer, n: u32) {
        for (level, &set) in self.level_sets.iter().enumerate() {
            if level > 0 {
                compute_to_compute(ctx, cmd);
            }
            self.pipeline
                .push(cmd, vk::ShaderStageFlags::COMPUTE, &(level as u32));
            let size = (n >> (level + 1)).max(1);
            self.pipeline.dispatch(
                cmd,
                &[(layout::SET_PASS, set)],
                groups_3d(size, layout::VOXEL_GROUP_SIZE),
            );
        }
    }
}
