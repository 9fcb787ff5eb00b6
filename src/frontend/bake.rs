//! `voxcone bake`: the irradiance probes' precomputation, with its report.

use anyhow::{Context as _, Result};

use super::check_validation;
use crate::cli::{default_scene, BakeArgs};
use crate::gi::probes::{bake, BakeReport};
use crate::scene::Scene;
use crate::vk::{Context, ContextOptions};

pub fn run(args: &BakeArgs) -> Result<BakeReport> {
    let settings = args.probes.settings()?;
    let path = args.scene.clone().unwrap_or_else(default_scene);
    let scene = Scene::load(&path, &Default::default())
        .with_context(|| format!("loading scene {}", path.display()))?;
    let ctx = Context::new(&ContextOptions {
        validation: args.validation || std::env::var("VOXCONE_VALIDATION").is_ok_and(|v| v == "1"),
        device: args.device.clone(),
        ..Default::default()
    })?;
    let report = bake(&ctx, &scene, &settings, args.preview.as_deref())?;
    check_validation(&ctx)?;
    let text = serde_json::to_string_pretty(&report)?;
    println!("{text}");
    if let Some(path) = &args.json {
        std::fs::write(path, &text).with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(report)
}
