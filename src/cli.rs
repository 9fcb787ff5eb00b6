//! Command-line interface.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::{Args, Parser, Subcommand, ValueEnum};

use crate::gi::ConeSettings;
use crate::renderer::{GiSettings, RenderSettings, Tonemap};
use crate::scene::LoadOptions;

#[derive(Parser, Debug)]
#[command(
    name = "voxcone",
    version,
    about = "Real-time global illumination by voxel cone tracing on Vulkan"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render one frame headless (no window system needed) to a PNG or EXR.
    Render(RenderArgs),
    /// Open a window and render interactively.
    View(ViewArgs),
    /// Render frames headless and print GPU time per pass.
    Bench(BenchArgs),
    /// Compare a test image with a reference: LDR-FLIP and relative MSE.
    Compare(CompareArgs),
}

/// Which global-illumination method runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum GiMode {
    /// Direct light only.
    Off,
    /// Voxel cone tracing on a dense voxel grid in 3D textures.
    #[default]
    Dense,
}

#[derive(Args, Debug, Clone)]
pub struct CommonArgs {
    /// Scene: a .toml scene file, a reference .scene.json, or a bare .obj
    /// (default: the built-in Cornell box).
    pub scene: Option<PathBuf>,
    /// Global illumination method.
    #[arg(long, value_enum, default_value_t = GiMode::Dense)]
    pub gi: GiMode,
    /// Enable the Vulkan validation layer (with synchronization validation); any message
    /// makes the command fail. Also on when VOXCONE_VALIDATION=1.
    #[arg(long)]
    pub validation: bool,
    /// Use the first Vulkan device whose name contains this text.
    #[arg(long)]
    pub device: Option<String>,
    /// Ignore MTL Ks (Lambertian only), as the path-traced references do.
    #[arg(long)]
    pub diffuse_only: bool,
    /// Ignore normal and bump maps, as the path-traced references do.
    #[arg(long)]
    pub no_normal_maps: bool,
    /// Exposure in stops before the tonemap (PNG and window only; EXR stays raw radiance).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
    /// Tonemap for PNG and window output.
    #[arg(long, value_enum, default_value_t = Tonemap::Clamp)]
    pub tonemap: Tonemap,
    /// Shadow map resolution per light view.
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(16..=8192))]
    pub shadow_res: u32,
    /// Voxels per axis of the dense grid (a power of two).
    #[arg(long, default_value_t = 64)]
    pub voxels: u32,
    /// Full aperture of each diffuse cone, degrees (1 to 179).
    #[arg(long, default_value_t = ConeSettings::default().diffuse_aperture_deg, value_parser = parse_aperture)]
    pub diffuse_aperture: f32,
    /// Cone step as a fraction of the cone's diameter (beta, 0.05 to 2).
    #[arg(long, default_value_t = ConeSettings::default().step_factor, value_parser = parse_step_factor)]
    pub step_factor: f32,
    /// Diffuse cones per gather: one along the normal, the rest in a ring at 60 degrees.
    #[arg(long, default_value_t = ConeSettings::default().diffuse_cones, value_parser = clap::value_parser!(u32).range(1..=16))]
    pub diffuse_cones: u32,
    /// Trace indirect light on one pixel of each NxN block and upsample (1: every pixel).
    #[arg(long, default_value_t = ConeSettings::default().indirect_scale, value_parser = clap::value_parser!(u32).range(1..=8))]
    pub indirect_scale: u32,
    /// Recompute every bounce every frame, instead of adding one bounce per frame to the
    /// last frame's light (the first frame always computes them all).
    #[arg(long)]
    pub no_accumulate: bool,
    /// Light bounces between voxels (1: direct light on the voxels only).
    #[arg(long, default_value_t = ConeSettings::default().bounces, value_parser = clap::value_parser!(u32).range(1..=8))]
    pub bounces: u32,
    /// Scene time in seconds (animation).
    #[arg(long, default_value_t = 0.0)]
    pub time: f32,
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    pub common: CommonArgs,
    /// Output image: .png (tonemapped sRGB) or .exr (linear radiance).
    #[arg(short, long, default_value = "voxcone.png")]
    pub output: PathBuf,
    /// Image size WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    pub size: (u32, u32),
}

#[derive(Args, Debug)]
pub struct ViewArgs {
    #[command(flatten)]
    pub common: CommonArgs,
    /// Render this many frames, then exit (smoke tests, profiler captures).
    #[arg(long)]
    pub frames: Option<u64>,
    /// Initial window size WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Save a PNG screenshot of the last frame here on exit.
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// Ask the window system to resize the window to WIDTHxHEIGHT halfway through
    /// `--frames` (smoke tests of swapchain recreation).
    #[arg(long, value_parser = parse_size, requires = "frames")]
    pub resize_to: Option<(u32, u32)>,
}

#[derive(Args, Debug)]
pub struct BenchArgs {
    #[command(flatten)]
    pub common: CommonArgs,
    /// Frames to time (after warm-up frames).
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u32).range(1..))]
    pub frames: u32,
    /// Frames rendered before timing (first-use shader compiles).
    #[arg(long, default_value_t = 3)]
    pub warmup: u32,
    /// Image size WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Also write the results as JSON here.
    #[arg(long)]
    pub json: Option<PathBuf>,
}

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// Reference image (.exr linear or .png sRGB).
    pub reference: PathBuf,
    /// Test image (.exr linear or .png sRGB).
    pub test: PathBuf,
    /// Exposure in stops applied to EXR inputs before the LDR metrics.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
    /// Write the metrics as JSON here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write the FLIP error map as a PNG here.
    #[arg(long)]
    pub map: Option<PathBuf>,
}

fn parse_float_in(text: &str, min: f32, max: f32) -> Result<f32> {
    match text.trim().parse::<f32>() {
        Ok(v) if (min..=max).contains(&v) => Ok(v),
        Ok(v) => bail!("{v} is out of range ({min} to {max})"),
        Err(_) => bail!("expected a number, got {text:?}"),
    }
}

fn parse_aperture(text: &str) -> Result<f32> {
    parse_float_in(text, 1.0, 179.0)
}

fn parse_step_factor(text: &str) -> Result<f32> {
    parse_float_in(text, 0.05, 2.0)
}

/// Parses `WIDTHxHEIGHT`.
pub fn parse_size(text: &str) -> Result<(u32, u32)> {
    let Some((w, h)) = text.split_once(['x', 'X']) else {
        bail!("expected WIDTHxHEIGHT, e.g. 1280x720, got {text:?}");
    };
    let (w, h): (u32, u32) = match (w.trim().parse(), h.trim().parse()) {
        (Ok(w), Ok(h)) => (w, h),
        _ => bail!("expected WIDTHxHEIGHT with whole numbers, got {text:?}"),
    };
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        bail!("size {w}x{h} is out of range (1..=16384 per side)");
    }
    Ok((w, h))
}

impl CommonArgs {
    /// The scene path, or the built-in default scene.
    pub fn scene_path(&self) -> PathBuf {
        self.scene.clone().unwrap_or_else(default_scene)
    }

    /// Reference scenes (`*.scene.json`) declare two-sided Lambertian materials without
    /// normal maps, so loading one implies `--diffuse-only --no-normal-maps`.
    fn is_reference(&self) -> bool {
        self.scene_path().to_string_lossy().ends_with(".scene.json")
    }

    pub fn load_options(&self) -> LoadOptions {
        let reference = self.is_reference();
        LoadOptions {
            diffuse_only: self.diffuse_only || reference,
            no_normal_maps: self.no_normal_maps || reference,
        }
    }

    pub fn render_settings(&self) -> RenderSettings {
        let options = self.load_options();
        RenderSettings {
            specular: !options.diffuse_only,
            normal_maps: !options.no_normal_maps,
            exposure_ev: self.exposure,
            tonemap: self.tonemap,
            shadow_resolution: self.shadow_res,
            cache_shadows: true,
            gi: (self.gi == GiMode::Dense).then_some(GiSettings {
                voxels: self.voxels,
                cones: ConeSettings {
                    bounces: self.bounces,
                    indirect_scale: self.indirect_scale,
                    diffuse_cones: self.diffuse_cones,
                    diffuse_aperture_deg: self.diffuse_aperture,
                    step_factor: self.step_factor,
                    accumulate_bounces: !self.no_accumulate,
                },
            }),
        }
    }

    pub fn validation(&self) -> bool {
        self.validation || std::env::var("VOXCONE_VALIDATION").is_ok_and(|v| v == "1")
    }
}

/// The built-in Cornell box in `assets/`.
pub fn default_scene() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/cornell.toml")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_and_bad_sizes_are_explained() {
        assert_eq!(parse_size("256x128").unwrap(), (256, 128));
        assert!(format!("{:#}", parse_size("256").unwrap_err()).contains("WIDTHxHEIGHT"));
        assert!(format!("{:#}", parse_size("0x5").unwrap_err()).contains("out of range"));
        assert!(format!("{:#}", parse_size("axb").unwrap_err()).contains("whole numbers"));
    }

    #[test]
    fn unknown_gi_mode_is_rejected() {
        let err = Cli::try_parse_from(["voxcone", "render", "--gi", "magic"]).unwrap_err();
        let text = err.to_string();
        assert!(text.contains("magic") && text.contains("off"), "{text}");
    }
}
