//! Thin front ends over the renderer: headless render, window viewer, benchmark.

pub mod bake;
pub mod bench;
pub mod render;
mod ui;
pub mod view;

use std::ffi::CStr;
use std::sync::Arc;

use anyhow::{bail, Context as _, Result};
use ash::vk;

use crate::cli::CommonArgs;
use crate::scene::Scene;
use crate::vk::{Buffer, Context, ContextOptions, Image, ImageDesc};

/// Format of LDR output images (the composite writes sRGB-encoded values).
pub const LDR_FORMAT: vk::Format = vk::Format::R8G8B8A8_SRGB;

pub fn create_context(
    common: &CommonArgs,
    surface_extensions: Vec<&'static CStr>,
) -> Result<Arc<Context>> {
    Context::new(&ContextOptions {
        validation: common.validation(),
        device: common.device.clone(),
        surface_extensions,
    })
}

pub fn load_scene(common: &CommonArgs) -> Result<Scene> {
    let path = common.scene_path();
    Scene::load(&path, &common.load_options())
        .with_context(|| format!("loading scene {}", path.display()))
}

/// Fails if the validation layer reported anything.
pub fn check_validation(ctx: &Context) -> Result<()> {
    let count = ctx.validation_messages();
    if count > 0 {
        bail!("the Vulkan validation layer reported {count} message(s) (see the log above)");
    }
    if ctx.validation_enabled() {
        log::info!("validation: no messages");
    }
    Ok(())
}

/// An offscreen LDR target with a host-visible buffer to read it back.
pub struct Offscreen {
    pub image: Image,
    pub readback: Buffer,
}

impl Offscreen {
    pub fn new(ctx: &Arc<Context>, extent: vk::Extent2D) -> Result<Self> {
        let image = Image::new(
            ctx,
            "ldr output",
            ImageDesc::d2(
                LDR_FORMAT,
                extent.width,
                extent.height,
                vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
            ),
        )?;
        let readback = Buffer::new(
            ctx,
            "ldr readback",
            u64::from(extent.width) * u64::from(extent.height) * 4,
            vk::BufferUsageFlags::TRANSFER_DST,
            gpu_allocator::MemoryLocation::GpuToCpu,
        )?;
        Ok(Self { image, readback })
    }
}
