//! `voxcone bake`: the irradiance probes' precomputation, with its report.

use anyhow::{Context as _, Result};

use super::check_validation;
use crate::cli::{default_scene, validation_requested, BakeArgs};
use crate::gi::probes::file::default_path;
use crate::gi::probes::{load_or_bake, BakeReport, Origin};
use crate::scene::Scene;
use crate::vk::{Context, ContextOptions};

pub fn run(args: &BakeArgs) -> Result<BakeReport> {
    let frame_options = [
        (args.probes.probe_bounces.is_some(), "--probe-bounces"),
        (args.probes.probe_lod.is_some(), "--probe-lod"),
        (args.probes.lod_distances.is_some(), "--lod-distances"),
    ];
    if let Some((_, flag)) = frame_options.iter().find(|(given, _)| *given) {
        anyhow::bail!("{flag} sets the frame of --gi probes, not its bake");
    }
    let path = args.scene.clone().unwrap_or_else(default_scene);
    let scene = Scene::load(&path, &Default::default())
        .with_context(|| format!("loading scene {}", path.display()))?;
    let settings = args.probes.settings(&scene.gi)?;
    let ctx = Context::new(&ContextOptions {
        validation: validation_requested(args.validation),
        device: args.device.clone(),
        ..Default::default()
    })?;
    let path = match &args.probes.bake_file {
        Some(p) => p.clone(),
        None => default_path(&scene, &settings)?,
    };
    let bake = load_or_bake(
        &ctx,
        &scene,
        &settings,
        &path,
        args.force,
        args.preview.as_deref(),
    )?;
    check_validation(&ctx)?;
    if bake.origin == Origin::Cached && args.preview.is_some() {
        log::warn!("--preview: the bake was read from its file, not computed; give --force");
    }
    let report = bake.report;
    let text = serde_json::to_string_pretty(&report)?;
    println!("{text}");
    if let Some(path) = &args.json {
        std::fs::write(path, &text).with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(report)
}
