//! Composite: HDR radiance to the display format (exposure, tonemap, sRGB).

use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use crate::gpu_layout as layout;
use crate::vk::{
    set_viewport, Binding, Context, DescriptorSets, GraphicsDesc, Image, Pipeline, SetWriter,
};

pub struct CompositePass {
    pipeline: Pipeline,
    /// Owns `set`; freed with the pass.
    _sets: DescriptorSets,
    set: vk::DescriptorSet,
    pub format: vk::Format,
}

impl CompositePass {
    /// `set_layouts` are those of sets 0 and 1; `format` is the target's, an sRGB format.
    pub fn new(
        ctx: &Arc<Context>,
        set_layouts: [vk::DescriptorSetLayout; 2],
        format: vk::Format,
    ) -> Result<Self> {
        let bindings = [Binding::new(
            layout::BINDING_COMPOSITE_HDR,
            vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
            vk::ShaderStageFlags::FRAGMENT,
        )];
        let sets = DescriptorSets::new(ctx, "composite", &bindings, 1)?;
        let set = sets.allocate("composite")?;
        let pipeline = Pipeline::graphics(
            ctx,
            &GraphicsDesc {
                name: "composite",
                vertex: crate::vk::shaders::PASSES_COMPOSITE_FULLSCREEN_VERT,
                geometry: None,
                fragment: Some(crate::vk::shaders::PASSES_COMPOSITE_COMPOSITE_FRAG),
                vertex_stride: 0,
                attributes: &[],
                set_layouts: &[set_layouts[0], set_layouts[1], sets.layout],
                push_constant_bytes: 0,
                color_formats: &[format],
                depth_format: None,
                cull: vk::CullModeFlags::NONE,
                dynamic_depth_bias: false,
                depth_clamp: false,
                constants: &[],
            },
        )?;
        Ok(Self {
            pipeline,
            _sets: sets,
            set,
            format,
        })
    }

    /// Points the pass at a new radiance image; no frame using the old one may be in flight.
    pub fn bind_input(&self, ctx: &Context, radiance: &Image, sampler: vk::Sampler) {
        SetWriter::new(ctx, self.set)
            .sampled_image(
                layout::BINDING_COMPOSITE_HDR,
                radiance.view,
                sampler,
                vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
            )
            .apply();
    }

    /// Draws into `target` (in COLOR_ATTACHMENT_OPTIMAL layout).
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        frame_set: vk::DescriptorSet,
        target: vk::ImageView,
        extent: vk::Extent2D,
    ) {
        let color = [vk::RenderingAttachmentInfo::default()
            .image_view(target)
            .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::DONT_CARE)
            .store_op(vk::AttachmentStoreOp::STORE)];
        let rendering = vk::RenderingInfo::default()
            .render_area(vk::Rect2D {
                offset: vk::Offset2D::default(),
                extent,
            })
            .layer_count(1)
            .color_attachments(&color);
        unsafe { ctx.device.cmd_begin_rendering(cmd, &rendering) };
        set_viewport(ctx, cmd, extent);
        self.pipeline.bind(
            cmd,
            &[(layout::SET_FRAME, frame_set), (layout::SET_PASS, self.set)],
        );
        unsafe {
            ctx.device.cmd_draw(cmd, 3, 1, 0, 0);
            ctx.device.cmd_end_rendering(cmd);
        }
    }
}
