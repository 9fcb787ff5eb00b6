//! `voxcone bench`: renders frames headless and reports GPU time per pass.

use std::collections::BTreeMap;
use std::time::Instant;

use anyhow::{bail, Context as _, Result};
use ash::vk;
use serde::Serialize;

use super::{check_validation, create_context, load_scene, Offscreen};
use crate::cli::BenchArgs;
use crate::gi::vct::Quality;
use crate::renderer::{OutputTarget, Renderer};
use crate::vk::ImageUse;

#[derive(Serialize, Debug, Clone, Copy)]
pub struct PassStats {
    pub median_ms: f64,
    pub min_ms: f64,
    pub max_ms: f64,
}

#[derive(Serialize, Debug)]
pub struct BenchReport {
    pub device: String,
    pub driver: String,
    pub scene: String,
    pub size: [u32; 2],
    pub frames: u32,
    /// Passes in frame order (the JSON map is keyed by name).
    #[serde(skip)]
    pub order: Vec<String>,
    pub passes: BTreeMap<String, PassStats>,
    pub total_median_ms: f64,
    /// Median host time between frame starts, with the host waiting for each frame.
    pub wall_median_ms: f64,
    pub memory_mib: BTreeMap<String, f64>,
    pub stats: BTreeMap<String, f64>,
    /// GPU milliseconds per pass of the technique's preparation (the octree's build).
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub prepare_ms: BTreeMap<String, f64>,
    /// The process's resident memory (MiB) after measured frame 1 and every 100th, and
    /// after the last: a soak (`--frames 2000`) shows whether it stays flat. Empty where
    /// the system does not say (`/proc/self/status`, Linux).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub rss_mib: Vec<(u32, f64)>,
}

/// The resident set size in MiB, from `/proc/self/status` (`VmRSS: N kB`).
fn resident_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmRSS:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

pub fn median(values: &mut [f64]) -> f64 {
    values.sort_by(|a, b| a.total_cmp(b));
    let n = values.len();
    if n == 0 {
        0.0
    } else if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}

fn stats(values: &[f64]) -> PassStats {
    let mut sorted = values.to_vec();
    PassStats {
        median_ms: median(&mut sorted),
        min_ms: sorted.first().copied().unwrap_or(0.0),
        max_ms: sorted.last().copied().unwrap_or(0.0),
    }
}

pub fn run(args: &BenchArgs) -> Result<BenchReport> {
    let ctx = create_context(&args.common, Vec::new())?;
    let scene = load_scene(&args.common)?;
    if args.move_light && scene.lights.is_empty() {
        bail!("--move-light: the scene has no light to move");
    }
    let triangles = scene.triangle_count;
    let (width, height) = crate::cli::image_size(args.size, &scene);
    let extent = vk::Extent2D { width, height };
    let offscreen = Offscreen::new(&ctx, extent)?;
    let mut settings = args.common.render_settings(&scene.gi, Quality::Fast)?;
    // Every pass runs every frame, so that the table shows what each one costs.
    settings.cache_shadows = false;
    let mut renderer = Renderer::new(&ctx, scene, settings, extent, super::LDR_FORMAT)?;
    let target = OutputTarget {
        image: offscreen.image.raw,
        view: offscreen.image.view,
        extent,
        before: ImageUse::discard_after(ImageUse::COLOR_ATTACHMENT),
        after: ImageUse::COLOR_ATTACHMENT,
    };
    let mut panel = args
        .ui
        .then(|| super::ui::Panel::new(&ctx, None, super::LDR_FORMAT))
        .transpose()?;
    let (mut panel_args, mut speed, mut last_wall) = (args.common.clone(), 1.0, 0.0);
    let mut order: Vec<String> = Vec::new();
    let mut samples: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    let mut totals = Vec::new();
    let mut walls = Vec::new();
    let mut rss_mib = Vec::new();
    let total_frames = args.warmup + args.frames;
    let bounds = renderer.scene.bounds(args.common.time);
    let radius = 0.05 * (bounds.max - bounds.min).length();
    let light_start = renderer.scene.lights.first().map(|l| l.position);
    for index in 0..total_frames {
        if let (true, Some(centre)) = (args.move_light, light_start) {
            let angle = std::f32::consts::TAU * index as f32 / 60.0;
            renderer.scene.lights[0].position =
                centre + radius * glam::Vec3::new(angle.cos() - 1.0, 0.0, angle.sin());
        }
        let start = Instant::now();
        if let Some(panel) = &mut panel {
            let view = super::ui::PanelView {
                renderer: &mut renderer,
                args: &mut panel_args,
                speed: &mut speed,
            };
            // What it asks for (a rebuild, a screenshot) needs a click: there is none.
            panel.update(None, extent, view, last_wall)?;
        }
        let frame = renderer.begin_frame()?;
        let time = if args.animate {
            args.common.time + index as f32 / 30.0
        } else {
            args.common.time
        };
        renderer.record_frame(&frame, time, &target)?;
        if let Some(panel) = &mut panel {
            renderer.record_overlay(&frame, &target, "ui", ImageUse::COLOR_ATTACHMENT, |cmd| {
                panel.record(cmd, extent)
            })?;
        }
        renderer.submit(frame, None, None)?;
        // Waiting for each frame keeps frames from overlapping, so pass times are clean.
        renderer.finish()?;
        if index < args.warmup {
            continue;
        }
        let wall = start.elapsed().as_secs_f64() * 1e3;
        last_wall = wall as f32;
        walls.push(wall);
        let measured = index - args.warmup + 1;
        if measured == 1 || measured % 100 == 0 || measured == args.frames {
            rss_mib.extend(resident_mib().map(|m| (measured, m)));
        }
        // A pass that runs several times a frame (one per bounce) counts once, summed.
        let mut frame: BTreeMap<&str, f64> = BTreeMap::new();
        for (name, ms) in &renderer.timings {
            if !order.contains(name) {
                order.push(name.clone());
            }
            *frame.entry(name).or_default() += ms;
        }
        for (name, ms) in &frame {
            samples.entry(name.to_string()).or_default().push(*ms);
        }
        totals.push(frame.values().sum());
    }
    let passes: BTreeMap<String, PassStats> = samples
        .iter()
        .map(|(name, v)| (name.clone(), stats(v)))
        .collect();
    let mib = |bytes: u64| bytes as f64 / (1024.0 * 1024.0);
    let mut memory_mib = BTreeMap::new();
    memory_mib.insert("scene_textures".to_string(), mib(renderer.texture_bytes()));
    for (name, bytes) in renderer.gi_memory_bytes() {
        memory_mib.insert(name.to_string(), mib(bytes));
    }
    let mut stats_map = BTreeMap::new();
    let mut prepare_passes = Vec::new();
    stats_map.insert("triangles".to_string(), triangles as f64);
    if let Some(gi) = renderer.gi() {
        stats_map.extend(gi.stats()?);
        if let Some(preparation) = gi.preparation() {
            println!("{}, GPU ms per pass:", preparation.summary);
            for (name, ms) in &preparation.passes {
                println!("  {name:<14} {ms:9.2}");
            }
            prepare_passes = preparation.passes;
        }
    }
    // A technique that counts its rays (`--gi path`) gets its rate over its trace pass.
    if let (Some(rays), Some(pass)) = (stats_map.get("rays_per_frame"), passes.get("path_trace")) {
        let seconds: f64 = pass.median_ms / 1e3;
        if seconds > 0.0 {
            stats_map.insert("rays_per_second".to_string(), rays / seconds);
        }
    }
    let report = BenchReport {
        device: ctx.device_name(),
        driver: ctx.driver.clone(),
        scene: args.common.scene_path().display().to_string(),
        size: [extent.width, extent.height],
        frames: args.frames,
        order,
        passes,
        total_median_ms: median(&mut totals),
        wall_median_ms: median(&mut walls),
        memory_mib,
        stats: stats_map,
        prepare_ms: prepare_passes.into_iter().collect(),
        rss_mib,
    };
    print_table(&report);
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&report)?;
        std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))?;
        println!("wrote {}", path.display());
    }
    check_validation(&ctx)?;
    Ok(report)
}

fn print_table(report: &BenchReport) {
    println!(
        "{} ({}), {}x{}, {} frames",
        report.device, report.driver, report.size[0], report.size[1], report.frames
    );
    println!(
        "{:<24} {:>10} {:>10} {:>10}",
        "pass", "median ms", "min ms", "max ms"
    );
    for name in &report.order {
        let s = &report.passes[name];
        println!(
            "{:<24} {:>10.3} {:>10.3} {:>10.3}",
            name, s.median_ms, s.min_ms, s.max_ms
        );
    }
    println!("{:<24} {:>10.3}", "total (GPU)", report.total_median_ms);
    println!("{:<24} {:>10.3}", "wall per frame", report.wall_median_ms);
    if let (Some(first), Some(last)) = (report.rss_mib.first(), report.rss_mib.last()) {
        println!(
            "resident memory: {:.1} MiB after frame {}, {:.1} MiB after frame {}",
            first.1, first.0, last.1, last.0
        );
    }
}
