//! G-buffer pass: rasterizes the scene into surface attributes and depth.

use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use crate::gpu_layout::DrawPush;
use crate::scene_gpu::{SceneDraw, VERTEX_ATTRIBUTES};
use crate::vk::{
    image_barrier, set_viewport, Context, GraphicsDesc, Image, ImageDesc, ImageUse, Pipeline,
};

pub const COLOR_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;
pub const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;
/// Reverse Z (`Camera::proj`): the depth at infinity, which the sky keeps (`is_sky` in
/// glsl/common/frame.glsl).
pub const DEPTH_CLEAR: f32 = 0.0;
pub const TRANSMISSION_FORMAT: vk::Format = vk::Format::R16G16_SFLOAT;
pub const TRIANGLE_FORMAT: vk::Format = vk::Format::R32_UINT;
const COLOR_FORMATS: [vk::Format; 5] = [
    COLOR_FORMAT,
    COLOR_FORMAT,
    COLOR_FORMAT,
    TRANSMISSION_FORMAT,
    TRIANGLE_FORMAT,
];

/// The G-buffer images of one resolution.
pub struct GBuffer {
    /// rgb albedo, a specular strength.
    pub albedo: Image,
    /// xyz world normal facing the camera, w roughness.
    pub normal: Image,
    /// rgb emitted radiance.
    pub emission: Image,
    /// r transmittance (1 - MTL d), g index of refraction (MTL Ni).
    pub transmission: Image,
    /// The triangle drawn, its index in the scene plus one (0 for none, and everywhere on a
    /// device without the geometry-shader feature, which `gl_PrimitiveID` needs).
    pub triangle: Image,
    pub depth: Image,
}

impl GBuffer {
    pub fn new(ctx: &Arc<Context>, extent: vk::Extent2D) -> Result<Self> {
        let color_usage = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::STORAGE;
        let color = |name, format| {
            Image::new(
                ctx,
                name,
                ImageDesc::d2(format, extent.width, extent.height, color_usage),
            )
        };
        Ok(Self {
            albedo: color("gbuffer albedo", COLOR_FORMAT)?,
            normal: color("gbuffer normal", COLOR_FORMAT)?,
            emission: color("gbuffer emission", COLOR_FORMAT)?,
            transmission: color("gbuffer transmission", TRANSMISSION_FORMAT)?,
            triangle: color("gbuffer triangle", TRIANGLE_FORMAT)?,
            depth: Image::new(
                ctx,
                "gbuffer depth",
                ImageDesc::d2(
                    DEPTH_FORMAT,
                    extent.width,
                    extent.height,
                    vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
                ),
            )?,
        })
    }

    pub fn extent(&self) -> vk::Extent2D {
        self.depth.extent_2d()
    }

    fn colors(&self) -> [&Image; 5] {
        [
            &self.albedo,
            &self.normal,
            &self.emission,
            &self.transmission,
            &self.triangle,
        ]
    }

    /// How later passes read the colour targets and the depth.
    pub const COLOR_FINAL_USE: ImageUse = ImageUse::COMPUTE_STORAGE_READ;
    pub const DEPTH_FINAL_USE: ImageUse = ImageUse::DEPTH_READ;
}

pub struct GBufferPass {
    /// Without and with normal mapping.
    pipelines: [Pipeline; 2],
}

impl GBufferPass {
    pub fn new(ctx: &Arc<Context>, set_layouts: &[vk::DescriptorSetLayout]) -> Result<Self> {
        use crate::vk::shaders as s;
        // Numbering the triangles needs gl_PrimitiveID, hence the geometry-shader feature.
        let [plain, mapped] = if ctx.features.geometry_shader {
            [
                s::PASSES_GBUFFER_GBUFFER_FRAG_TRIANGLE_IDS,
                s::PASSES_GBUFFER_GBUFFER_FRAG_NORMAL_MAPS_TRIANGLE_IDS,
            ]
        } else {
            [
                s::PASSES_GBUFFER_GBUFFER_FRAG,
                s::PASSES_GBUFFER_GBUFFER_FRAG_NORMAL_MAPS,
            ]
        };
        let pipeline = |name, fragment| {
            Pipeline::graphics(
                ctx,
                &GraphicsDesc {
                    name,
                    vertex: s::PASSES_GBUFFER_GBUFFER_VERT,
                    geometry: None,
                    fragment: Some(fragment),
                    vertex_stride: std::mem::size_of::<crate::scene::Vertex>() as u32,
                    attributes: &VERTEX_ATTRIBUTES,
                    set_layouts,
                    push_constant_bytes: std::mem::size_of::<DrawPush>() as u32,
                    color_formats: &COLOR_FORMATS,
                    depth_format: Some(DEPTH_FORMAT),
                    // Surfaces are two-sided (the references' convention).
                    cull: vk::CullModeFlags::NONE,
                    dynamic_depth_bias: false,
                    depth_clamp: false,
                    constants: &[],
                },
            )
        };
        Ok(Self {
            pipelines: [
                pipeline("gbuffer", plain)?,
                pipeline("gbuffer with normal maps", mapped)?,
            ],
        })
    }

    /// Draws the scene into `target`; `normal_maps`: with its normal maps applied.
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        target: &GBuffer,
        draw: &SceneDraw,
        normal_maps: bool,
    ) {
        for image in target.colors() {
            image_barrier(
                ctx,
                cmd,
                image.raw,
                image.full_range(),
                ImageUse::discard_after(GBuffer::COLOR_FINAL_USE),
                ImageUse::COLOR_ATTACHMENT,
            );
        }
        image_barrier(
            ctx,
            cmd,
            target.depth.raw,
            target.depth.full_range(),
            ImageUse::discard_after(GBuffer::DEPTH_FINAL_USE),
            ImageUse::DEPTH_ATTACHMENT,
        );
        let colors: Vec<_> = target
            .colors()
            .iter()
            .map(|image| {
                vk::RenderingAttachmentInfo::default()
                    .image_view(image.view)
                    .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                    .load_op(vk::AttachmentLoadOp::CLEAR)
                    .store_op(vk::AttachmentStoreOp::STORE)
                    .clear_value(vk::ClearValue {
                        color: vk::ClearColorValue { float32: [0.0; 4] },
                    })
            })
            .collect();
        let depth = vk::RenderingAttachmentInfo::default()
            .image_view(target.depth.view)
            .image_layout(vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue {
                depth_stencil: vk::ClearDepthStencilValue {
                    depth: DEPTH_CLEAR,
                    stencil: 0,
                },
            });
        let extent = target.extent();
        let rendering = vk::RenderingInfo::default()
            .render_area(vk::Rect2D {
                offset: vk::Offset2D::default(),
                extent,
            })
            .layer_count(1)
            .color_attachments(&colors)
            .depth_attachment(&depth);
        unsafe { ctx.device.cmd_begin_rendering(cmd, &rendering) };
        set_viewport(ctx, cmd, extent);
        let pipeline = &self.pipelines[usize::from(normal_maps)];
        draw.draw_meshes(ctx, cmd, pipeline, 0, None, |_| true);
        unsafe { ctx.device.cmd_end_rendering(cmd) };
        for image in target.colors() {
            image_barrier(
                ctx,
                cmd,
                image.raw,
                image.full_range(),
                ImageUse::COLOR_ATTACHMENT,
                GBuffer::COLOR_FINAL_USE,
            );
        }
        image_barrier(
            ctx,
            cmd,
            target.depth.raw,
            target.depth.full_range(),
            ImageUse::DEPTH_ATTACHMENT,
            GBuffer::DEPTH_FINAL_USE,
        );
    }
}
