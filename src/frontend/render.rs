//! `voxcone render`: one frame, headless, to PNG or EXR.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context as _, Result};
use ash::vk;

use super::{check_validation, create_context, load_scene, Offscreen};
use crate::cli::{RenderArgs, MAX_IMAGE_SIDE};
use crate::imageio::{box_downsample, box_downsample_srgb8};
use crate::renderer::{OutputTarget, Renderer};
use crate::vk::{copy_image_to_buffer, Buffer, ImageUse};

enum Format {
    Png,
    Exr,
}

fn output_format(path: &Path) -> Result<Format> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("png") => Ok(Format::Png),
        Some("exr") => Ok(Format::Exr),
        _ => bail!(
            "output {} must end in .png (tonemapped sRGB) or .exr (linear radiance)",
            path.display()
        ),
    }
}

/// Renders one frame and writes it; returns the path written.
pub fn run(args: &RenderArgs) -> Result<PathBuf> {
    let format = output_format(&args.output)?;
    let samples = args.supersample;
    let (width, height) = (args.size.0 * samples, args.size.1 * samples);
    if width.max(height) > MAX_IMAGE_SIDE {
        bail!(
            "--size {}x{} with --supersample {samples} renders {width}x{height}, over {MAX_IMAGE_SIDE} \
             pixels per side: lower one of them",
            args.size.0,
            args.size.1
        );
    }
    let ctx = create_context(&args.common, Vec::new())?;
    let scene = load_scene(&args.common)?;
    let settings = args.common.render_settings(&scene.gi)?;
    let extent = vk::Extent2D { width, height };
    let offscreen = Offscreen::new(&ctx, extent)?;
    let mut renderer = Renderer::new(&ctx, scene, settings, extent, super::LDR_FORMAT)?;
    let radiance = Buffer::new(
        &ctx,
        "radiance readback",
        u64::from(extent.width) * u64::from(extent.height) * 16,
        vk::BufferUsageFlags::TRANSFER_DST,
        gpu_allocator::MemoryLocation::GpuToCpu,
    )?;
    let start = Instant::now();
    let target = OutputTarget {
        image: offscreen.image.raw,
        view: offscreen.image.view,
        extent,
        before: ImageUse::UNDEFINED,
        after: ImageUse::TRANSFER_SRC,
    };
    let frame = renderer.begin_frame()?;
    renderer.record_frame(&frame, args.common.time, &target)?;
    match format {
        Format::Exr => renderer.record_radiance_readback(frame.cmd, &radiance),
        Format::Png => copy_image_to_buffer(
            &ctx,
            frame.cmd,
            offscreen.image.raw,
            extent,
            offscreen.readback.raw,
        ),
    }
    renderer.submit(frame, None, None)?;
    renderer.finish()?;
    log::info!(
        "rendered {}x{} ({samples}x{samples} samples per pixel) in {:.1} ms (GPU: {})",
        args.size.0,
        args.size.1,
        start.elapsed().as_secs_f64() * 1e3,
        renderer
            .timings
            .iter()
            .map(|(name, ms)| format!("{name} {ms:.2} ms"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let (out_width, out_height) = args.size;
    match format {
        Format::Exr => {
            let data: &[f32] = bytemuck::cast_slice(radiance.mapped());
            let data = box_downsample(data, width, height, samples);
            crate::imageio::write_exr(&args.output, out_width, out_height, &data)
        }
        Format::Png => {
            let data = box_downsample_srgb8(offscreen.readback.mapped(), width, height, samples);
            crate::imageio::write_png(&args.output, out_width, out_height, &data)
        }
    }
    .with_context(|| format!("writing {}", args.output.display()))?;
    check_validation(&ctx)?;
    Ok(args.output.clone())
}
