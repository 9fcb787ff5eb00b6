//! The screen contract every technique gathers into (set 2, `glsl/gi/screen/`): the
//! G-buffer and the screen radiance, and the terms gathered at reduced resolution,
//! which the upsample (`glsl/gi/screen/upsample.comp`) spreads to every pixel, depth- and
//! normal-aware, and adds to the direct light.

use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use crate::gpu_layout::{self as layout, ScreenUniforms};
use crate::passes::gbuffer::GBuffer;
use crate::vk::{
    groups_2d, to_compute_write, Binding, Buffer, Context, DescriptorSets, Image, ImageDesc,
    Pipeline, SetWriter,
};

/// The format of the reduced-resolution terms.
const TERM_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;

/// How a technique wants the screen targets laid out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScreenRequest {
    /// The terms are gathered at one pixel of each `scale`² block.
    pub scale: u32,
    /// `ScreenUniforms.plane_tolerance`, in world units.
    pub plane_tolerance: f32,
}

/// The reduced-resolution terms (`BINDING_SCREEN_INDIRECT` and after).
struct Terms {
    indirect: Image,
    shadow: Image,
    specular: Image,
    transmitted: Image,
}

/// The screen contract's set, its targets and the upsample.
pub struct Screen {
    set: vk::DescriptorSet,
    sets: DescriptorSets,
    uniforms: Buffer,
    upsample: Pipeline,
    /// Created with the screen targets.
    terms: Option<Terms>,
    extent: vk::Extent2D,
    scale: u32,
    /// The scene's lights, each with a visibility channel in the shadow terms.
    light_count: u32,
    ctx: Arc<Context>,
}

impl Screen {
    /// `set_layouts` are those of sets 0 and 1.
    pub fn new(
        ctx: &Arc<Context>,
        set_layouts: [vk::DescriptorSetLayout; 2],
        light_count: u32,
    ) -> Result<Self> {
        let compute = vk::ShaderStageFlags::COMPUTE;
        let storage = vk::DescriptorType::STORAGE_IMAGE;
        let bindings = [
            Binding::new(
                layout::BINDING_SCREEN_UNIFORMS,
                vk::DescriptorType::UNIFORM_BUFFER,
                compute,
            ),
            Binding::new(layout::BINDING_SCREEN_RADIANCE, storage, compute),
            Binding::new(layout::BINDING_SCREEN_ALBEDO, storage, compute),
            Binding::new(layout::BINDING_SCREEN_NORMAL, storage, compute),
            Binding::new(
                layout::BINDING_SCREEN_DEPTH,
                vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
                compute,
            ),
            Binding::new(layout::BINDING_SCREEN_TRANSMISSION, storage, compute),
            Binding::new(layout::BINDING_SCREEN_EMISSION, storage, compute),
            Binding::new(layout::BINDING_SCREEN_INDIRECT, storage, compute),
            Binding::new(layout::BINDING_SCREEN_SHADOW, storage, compute),
            Binding::new(layout::BINDING_SCREEN_SPECULAR, storage, compute),
            Binding::new(layout::BINDING_SCREEN_TRANSMITTED, storage, compute),
            Binding::new(layout::BINDING_SCREEN_TRIANGLE, storage, compute),
        ];
        let sets = DescriptorSets::new(ctx, "screen", &bindings, 1)?;
        let set = sets.allocate("screen")?;
        let uniforms = Buffer::with_data(
            ctx,
            "screen uniforms",
            bytemuck::bytes_of(&ScreenUniforms::default()),
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?;
        SetWriter::new(ctx, set)
            .buffer(
                layout::BINDING_SCREEN_UNIFORMS,
                vk::DescriptorType::UNIFORM_BUFFER,
                uniforms.raw,
            )
            .apply();
        let upsample = Pipeline::compute(
            ctx,
            "upsample",
            crate::vk::shaders::GI_SCREEN_UPSAMPLE_COMP,
            &[set_layouts[0], set_layouts[1], sets.layout],
            0,
        )?;
        Ok(Self {
            set,
            sets,
            uniforms,
            upsample,
            terms: None,
            extent: vk::Extent2D::default(),
            scale: 1,
            light_count,
            ctx: ctx.clone(),
        })
    }

    /// The set's layout, set 2 of the technique's screen passes.
    pub fn layout(&self) -> vk::DescriptorSetLayout {
        self.sets.layout
    }

    /// The set (set 2).
    pub fn set(&self) -> vk::DescriptorSet {
        self.set
    }

    /// The full-resolution extent.
    pub fn extent(&self) -> vk::Extent2D {
        self.extent
    }

    /// The extent of the reduced-resolution terms.
    pub fn reduced_extent(&self) -> vk::Extent2D {
        vk::Extent2D {
            width: self.extent.width.div_ceil(self.scale),
            height: self.extent.height.div_ceil(self.scale),
        }
    }

    /// Points the set at new screen targets, with terms laid out as `request` asks; no
    /// frame using the old ones may be in flight.
    pub fn bind(
        &mut self,
        gbuffer: &GBuffer,
        radiance: &Image,
        depth_sampler: vk::Sampler,
        request: ScreenRequest,
    ) -> Result<()> {
        self.extent = gbuffer.extent();
        self.scale = request.scale;
        let uniforms = ScreenUniforms {
            indirect_scale: request.scale,
            plane_tolerance: request.plane_tolerance,
            ..Default::default()
        };
        self.uniforms.write(0, bytemuck::bytes_of(&uniforms));
        let low = self.reduced_extent();
        let term = |name, bands: u32| {
            Image::new(
                &self.ctx,
                name,
                ImageDesc::d2(
                    TERM_FORMAT,
                    low.width,
                    low.height * bands,
                    vk::ImageUsageFlags::STORAGE,
                ),
            )
        };
        let terms = Terms {
            indirect: term("indirect", 1)?,
            // One band of rows per four lights.
            shadow: term("cone shadow", self.light_count.div_ceil(4).max(1))?,
            specular: term("cone specular", 1)?,
            transmitted: term("cone transmitted", 1)?,
        };
        to_compute_write(
            &self.ctx,
            "reduced-resolution layouts",
            &[
                &terms.indirect,
                &terms.shadow,
                &terms.specular,
                &terms.transmitted,
            ],
        )?;
        SetWriter::new(&self.ctx, self.set)
            .storage_image(layout::BINDING_SCREEN_INDIRECT, terms.indirect.view)
            .storage_image(layout::BINDING_SCREEN_SHADOW, terms.shadow.view)
            .storage_image(layout::BINDING_SCREEN_SPECULAR, terms.specular.view)
            .storage_image(layout::BINDING_SCREEN_TRANSMITTED, terms.transmitted.view)
            .storage_image(layout::BINDING_SCREEN_RADIANCE, radiance.view)
            .storage_image(layout::BINDING_SCREEN_ALBEDO, gbuffer.albedo.view)
            .storage_image(layout::BINDING_SCREEN_NORMAL, gbuffer.normal.view)
            .storage_image(
                layout::BINDING_SCREEN_TRANSMISSION,
                gbuffer.transmission.view,
            )
            .storage_image(layout::BINDING_SCREEN_EMISSION, gbuffer.emission.view)
            .storage_image(layout::BINDING_SCREEN_TRIANGLE, gbuffer.triangle.view)
            .sampled_image(
                layout::BINDING_SCREEN_DEPTH,
                gbuffer.depth.view,
                depth_sampler,
                vk::ImageLayout::DEPTH_READ_ONLY_OPTIMAL,
            )
            .apply();
        self.terms = Some(terms);
        Ok(())
    }

    /// Adds the upsampled terms to every pixel of the screen radiance (or, when the
    /// technique shades the direct light, shades every pixel).
    pub fn record_upsample(&self, cmd: vk::CommandBuffer, frame_set: vk::DescriptorSet) {
        let sets = [
            (layout::SET_FRAME, frame_set),
            (layout::SET_SCREEN, self.set),
        ];
        self.upsample.dispatch(
            cmd,
            &sets,
            groups_2d(self.extent, layout::SCREEN_GROUP_SIZE),
        );
    }
}
