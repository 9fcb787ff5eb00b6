//! `voxcone render`: one frame, headless, to PNG or EXR.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Result};
use ash::vk;

use super::{check_validation, create_context, load_scene, Offscreen};
use crate::cli::{RenderArgs, MAX_IMAGE_SIDE};
use crate::gi::vct::Quality;
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

/// Renders the frame and writes it; returns the path written. A technique that converges
/// over frames (`--gi path`) renders frames until it has its samples, with a progress bar.
pub fn run(args: &RenderArgs) -> Result<PathBuf> {
    let format = output_format(&args.output)?;
    let scene = load_scene(&args.common)?;
    let settings = args.common.render_settings(&scene.gi, Quality::Accurate)?;
    let samples = if settings.gi.filters_pixels() {
        if args.supersample != 1 {
            log::info!("the technique filters each pixel itself: one sample per pixel to render");
        }
        1
    } else {
        args.supersample
    };
    let size = crate::cli::image_size(args.size, &scene);
    let (width, height) = (size.0 * samples, size.1 * samples);
    if width.max(height) > MAX_IMAGE_SIDE {
        bail!(
            "size {}x{} with --supersample {samples} renders {width}x{height}, over {MAX_IMAGE_SIDE} \
             pixels per side: lower one of them",
            size.0,
            size.1
        );
    }
    let ctx = create_context(&args.common, Vec::new())?;
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
    // The progress of a render that converges over frames.
    let bar = renderer
        .gi()
        .and_then(|t| t.progress())
        .filter(|p| p.frames_left > 1)
        .map(|p| {
            crate::progress::Progress::with_unit(
                "path tracing",
                "samples per pixel",
                u64::from(p.total),
            )
        });
    for index in 0.. {
        let progress = renderer.gi().and_then(|t| t.progress());
        let last = progress.is_none_or(|p| p.frames_left <= 1);
        let target = OutputTarget {
            image: offscreen.image.raw,
            view: offscreen.image.view,
            extent,
            before: if index == 0 {
                ImageUse::UNDEFINED
            } else {
                ImageUse::discard_after(ImageUse::TRANSFER_SRC)
            },
            after: ImageUse::TRANSFER_SRC,
        };
        let frame = renderer.begin_frame()?;
        renderer.record_frame(&frame, args.common.time, &target)?;
        if last {
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
        }
        renderer.submit(frame, None, None)?;
        if last {
            break;
        }
        if index == 0 {
            // The first frame, waited for, gives the estimate of the whole render.
            renderer.finish()?;
            let frames = progress.map_or(1, |p| p.frames_left);
            let estimate = start.elapsed().as_secs_f64() * f64::from(frames);
            log::info!(
                "{frames} frames to render, about {} in all",
                duration_text(estimate)
            );
        }
        if let (Some(bar), Some(p)) = (&bar, renderer.gi().and_then(|t| t.progress())) {
            bar.set(u64::from(p.done));
        }
    }
    renderer.finish()?;
    if let Some(bar) = &bar {
        bar.finish();
    }
    log::info!(
        "rendered {}x{} ({}) in {:.1} ms (last frame's GPU: {})",
        size.0,
        size.1,
        match renderer.gi().and_then(|t| t.progress()) {
            Some(p) => format!("{} samples per pixel", p.done),
            None => format!("{samples}x{samples} samples per pixel"),
        },
        start.elapsed().as_secs_f64() * 1e3,
        renderer
            .timings
            .iter()
            .map(|(name, ms)| format!("{name} {ms:.2} ms"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let (out_width, out_height) = size;
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
    }?;
    check_validation(&ctx)?;
    Ok(args.output.clone())
}

/// `seconds` as "1 h 5 min", "3 min 20 s" or "12.3 s".
fn duration_text(seconds: f64) -> String {
    let whole = seconds.round() as u64;
    if whole >= 3600 {
        format!("{} h {} min", whole / 3600, whole % 3600 / 60)
    } else if whole >= 60 {
        format!("{} min {} s", whole / 60, whole % 60)
    } else {
        format!("{seconds:.1} s")
    }
}
