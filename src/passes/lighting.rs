//! Deferred direct lighting (compute): G-buffer, lights and shadow maps to HDR radiance.

use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use super::gbuffer::GBuffer;
use crate::gpu_layout as layout;
use crate::vk::{
    groups_2d, image_barrier, Binding, Context, DescriptorSets, Image, ImageDesc, ImageUse,
    Pipeline, SetWriter,
};

/// Linear radiance; 32-bit floats so that an EXR written from it is exact.
pub const RADIANCE_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;

pub struct LightingPass {
    pipeline: Pipeline,
    /// Owns `set`; freed with the pass.
    _sets: DescriptorSets,
    set: vk::DescriptorSet,
}

impl LightingPass {
    fn bindings() -> [Binding; 5] {
        let compute = vk::ShaderStageFlags::COMPUTE;
        let storage = vk::DescriptorType::STORAGE_IMAGE;
        [
            Binding::new(layout::BINDING_LIGHTING_ALBEDO, storage, compute),
            Binding::new(layout::BINDING_LIGHTING_NORMAL, storage, compute),
            Binding::new(layout::BINDING_LIGHTING_EMISSION, storage, compute),
            Binding::new(
                layout::BINDING_LIGHTING_DEPTH,
                vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
                compute,
            ),
            Binding::new(layout::BINDING_LIGHTING_OUT, storage, compute),
        ]
    }

    /// `set_layouts` are those of sets 0 and 1.
    pub fn new(ctx: &Arc<Context>, set_layouts: [vk::DescriptorSetLayout; 2]) -> Result<Self> {
        let sets = DescriptorSets::new(ctx, "lighting", &Self::bindings(), 1)?;
        let set = sets.allocate("lighting")?;
        let pipeline = Pipeline::compute(
            ctx,
            "lighting",
            crate::vk::shaders::PASSES_LIGHTING_LIGHTING_COMP,
            &[set_layouts[0], set_layouts[1], sets.layout],
            0,
        )?;
        Ok(Self {
            pipeline,
            _sets: sets,
            set,
        })
    }

    pub fn create_output(ctx: &Arc<Context>, extent: vk::Extent2D) -> Result<Image> {
        Image::new(
            ctx,
            "radiance",
            ImageDesc::d2(
                RADIANCE_FORMAT,
                extent.width,
                extent.height,
                vk::ImageUsageFlags::STORAGE
                    | vk::ImageUsageFlags::SAMPLED
                    | vk::ImageUsageFlags::TRANSFER_SRC,
            ),
        )
    }

    /// Points the pass at new targets; no frame using the old ones may be in flight.
    pub fn bind_targets(
        &self,
        ctx: &Context,
        gbuffer: &GBuffer,
        output: &Image,
        depth_sampler: vk::Sampler,
    ) {
        SetWriter::new(ctx, self.set)
            .storage_image(layout::BINDING_LIGHTING_ALBEDO, gbuffer.albedo.view)
            .storage_image(layout::BINDING_LIGHTING_NORMAL, gbuffer.normal.view)
            .storage_image(layout::BINDING_LIGHTING_EMISSION, gbuffer.emission.view)
            .sampled_image(
                layout::BINDING_LIGHTING_DEPTH,
                gbuffer.depth.view,
                depth_sampler,
                vk::ImageLayout::DEPTH_READ_ONLY_OPTIMAL,
            )
            .storage_image(layout::BINDING_LIGHTING_OUT, output.view)
            .apply();
    }

    /// Writes `output` (left in `ImageUse::COMPUTE_WRITE`; `previous` is its last use).
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        frame_set: vk::DescriptorSet,
        output: &Image,
        previous: ImageUse,
    ) {
        image_barrier(
            ctx,
            cmd,
            output.raw,
            output.full_range(),
            ImageUse::discard_after(previous),
            ImageUse::COMPUTE_WRITE,
        );
        self.pipeline.dispatch(
            cmd,
            &[(layout::SET_FRAME, frame_set), (layout::SET_PASS, self.set)],
            groups_2d(output.extent_2d(), layout::SCREEN_GROUP_SIZE),
        );
    }
}
