//! Command-line interface.

use std::path::PathBuf;

use anyhow::{anyhow, bail, Result};
use clap::{Args, Parser, Subcommand, ValueEnum};

use crate::gi::path::cli::PathArgs;
use crate::gi::path::ConeComponent;
use crate::gi::probes::cli::ProbeArgs;
use crate::gi::vct::cli::VctArgs;
use crate::gi::vct::{ConeSettings, Quality};
use crate::gi::{DebugView, GiSettings};
use crate::passes::shadow::ShadowResolution;
use crate::scene::{GiOverrides, LoadOptions, Scene};
use crate::settings::{RenderSettings, Terms, Tonemap};

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
    /// Precompute the irradiance probes' data for a scene (lightmap atlas, receivers,
    /// probes) and report what it made.
    Bake(BakeArgs),
}

/// Which global-illumination technique runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum GiMode {
    /// Direct light only.
    Off,
    /// Voxel cone tracing on a dense voxel grid in 3D textures.
    #[default]
    Dense,
    /// Voxel cone tracing on a sparse voxel octree built on the GPU, with bricks in 3D
    /// textures (also accepted as `svo`).
    #[value(alias = "svo")]
    Octree,
    /// The path-traced reference: a path tracer with next-event estimation, in the
    /// references' conventions.
    Path,
    /// Irradiance probes: light transport precomputed by ray casting from sparse probes
    /// to lightmap receivers (Sedláček 2019), baked on first use.
    Probes,
}

#[derive(Args, Debug, Clone)]
pub struct CommonArgs {
    /// Scene: a .toml scene file, a reference .scene.json, or a bare .obj
    /// (default: the built-in Cornell box).
    pub scene: Option<PathBuf>,
    /// Global-illumination technique.
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
    /// Ignore MTL Ni: surfaces with d < 1 pass light straight through, as the
    /// path-traced references' masks do.
    #[arg(long)]
    pub no_refraction: bool,
    /// Exposure in stops before the tonemap (PNG and window only; EXR stays raw radiance).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = parse_finite)]
    pub exposure: f32,
    /// Tonemap for PNG and window output.
    #[arg(long, value_enum, default_value_t = Tonemap::Clamp)]
    pub tonemap: Tonemap,
    /// Shadow map resolution of each view of a point or spot light: a power of two,
    /// 16 to 8192 [default: 1024 for frames (view, bench), 4096 for one image (render,
    /// unless --quality fast)].
    #[arg(long, value_parser = parse_shadow_res)]
    pub shadow_res: Option<u32>,
    /// Shadow map resolution of a directional light, whose one view covers the whole
    /// scene: a power of two, 16 to 8192 [default: 4096 for frames (view, bench), 8192
    /// for one image (render, unless --quality fast)].
    #[arg(long, value_parser = parse_shadow_res)]
    pub sun_shadow_res: Option<u32>,
    /// The most memory the shadow maps may take, in MiB; with many lights the views'
    /// resolutions are halved until they fit.
    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub shadow_budget: u32,
    /// The cone tracer's options (--gi dense, --gi octree).
    #[command(flatten)]
    pub vct: VctArgs,
    /// The path tracer's options (--gi path).
    #[command(flatten)]
    pub path: PathArgs,
    /// The irradiance probes' options (--gi probes; their bake's settings).
    #[command(flatten)]
    pub probes: ProbeArgs,
    /// Leave out the direct light.
    #[arg(long)]
    pub no_direct: bool,
    /// Leave out emitted light.
    #[arg(long)]
    pub no_emission: bool,
    /// Leave out the indirect diffuse light.
    #[arg(long)]
    pub no_indirect: bool,
    /// Leave out the cone-traced specular reflections.
    #[arg(long)]
    pub no_indirect_specular: bool,
    /// Draw transmissive surfaces (d < 1) opaque, without the refraction cone.
    #[arg(long)]
    pub no_transmission: bool,
    /// Multiply the indirect light by ambient occlusion (contact shadows; the cone-traced
    /// light is already occluded, so this darkens twice and is off by default).
    #[arg(long)]
    pub ao: bool,
    /// Show a debug view instead of the image (needs --gi dense or --gi octree).
    #[arg(long, value_enum, default_value_t = DebugView::None)]
    pub debug_view: DebugView,
    /// Mip level of the voxel debug views (0: the voxels themselves).
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=10))]
    pub debug_level: u32,
    /// Scene time in seconds (animation).
    #[arg(long, default_value_t = 0.0, value_parser = parse_finite)]
    pub time: f32,
    /// One diffuse cone of the cone tracer's gather as a component reference: K = 0 the
    /// cone along the normal, 1 to --diffuse-cones - 1 the ring's. --gi dense and --gi
    /// octree trace that cone alone for the indirect light (albedo times its radiance);
    /// --gi path shows albedo times the exact mean radiance within it (one bounce with
    /// --max-depth 3), instead of the image, for the layout that --diffuse-cones,
    /// --diffuse-aperture and --cosine-cones give.
    #[arg(long)]
    pub cone: Option<u32>,
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    pub common: CommonArgs,
    /// Output image: .png (tonemapped sRGB) or .exr (linear radiance).
    #[arg(short, long, default_value = "voxcone.png")]
    pub output: PathBuf,
    /// Image size WIDTHxHEIGHT [default: a reference scene's resolution, else 1280x720].
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Anti-aliasing: render the frame N times wider and taller and make each pixel the
    /// mean of its NxN samples (a box filter over the pixel, as the path-traced
    /// references use), in linear light; 1 to 4, 1 for one sample per pixel. The indirect
    /// light's default trace scale follows the larger frame, so it is traced at the same
    /// resolution as without (an explicit --indirect-scale counts the larger frame's pixels).
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u32).range(1..=4))]
    pub supersample: u32,
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
    /// Save a PNG screenshot of the last frame here on exit (a `.png` path).
    #[arg(long, value_parser = parse_png_path)]
    pub screenshot: Option<PathBuf>,
    /// Ask the window system to resize the window to WIDTHxHEIGHT halfway through
    /// `--frames` (smoke tests of swapchain recreation).
    #[arg(long, value_parser = parse_size, requires = "frames")]
    pub resize_to: Option<(u32, u32)>,
    /// Start without the settings panel (F1 shows it).
    #[arg(long)]
    pub no_ui: bool,
}

/// The most frames `bench` times or warms up with: together they count in a u32.
pub const MAX_BENCH_FRAMES: u32 = 1_000_000;

#[derive(Args, Debug)]
pub struct BenchArgs {
    #[command(flatten)]
    pub common: CommonArgs,
    /// Frames to time (after warm-up frames).
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u32).range(1..=MAX_BENCH_FRAMES as i64))]
    pub frames: u32,
    /// Frames rendered before timing (first-use shader compiles).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(0..=MAX_BENCH_FRAMES as i64))]
    pub warmup: u32,
    /// Image size WIDTHxHEIGHT [default: a reference scene's resolution, else 1280x720].
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Also write the results as JSON here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Move the first light every frame, as the viewer's arrow keys do: round a circle a
    /// tenth of the scene's size across, once every 60 frames.
    #[arg(long)]
    pub move_light: bool,
    /// Advance the scene's clock by 1/30 s every frame from `--time` (moving meshes and
    /// orbiting lights move as in the viewer) instead of rendering every frame at `--time`.
    #[arg(long)]
    pub animate: bool,
    /// Draw the viewer's settings panel over every frame, as the timed pass `ui`.
    #[arg(long)]
    pub ui: bool,
}

#[derive(Args, Debug)]
pub struct BakeArgs {
    /// Scene: a .toml scene file, a reference .scene.json, a bare .obj or a glTF scene
    /// (default: the built-in Cornell box).
    pub scene: Option<PathBuf>,
    #[command(flatten)]
    pub probes: ProbeArgs,
    /// Also write the report as JSON here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Bake again even where the file is up to date.
    #[arg(long)]
    pub force: bool,
    /// Write the lightmap's irradiance from the emitters and the sky here (.exr, or .png
    /// clamped and sRGB-encoded).
    #[arg(long)]
    pub preview: Option<PathBuf>,
    /// Enable the Vulkan validation layer; any message makes the command fail. Also on
    /// when VOXCONE_VALIDATION=1.
    #[arg(long)]
    pub validation: bool,
    /// Use the first Vulkan device whose name contains this text.
    #[arg(long)]
    pub device: Option<String>,
}

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// Reference image (.exr linear or .png sRGB).
    pub reference: PathBuf,
    /// Test image (.exr linear or .png sRGB).
    pub test: PathBuf,
    /// Exposure in stops applied to EXR inputs before the LDR metrics.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = parse_finite)]
    pub exposure: f32,
    /// Write the metrics as JSON here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write the FLIP error map as a PNG here.
    #[arg(long)]
    pub map: Option<PathBuf>,
    /// Also measure an NxN grid of blocks over the image: mean LDR-FLIP and, for EXR
    /// inputs, the test's mean brightness over the reference's, per block (a table on
    /// stderr, and `blocks` in the JSON).
    #[arg(long, value_name = "N")]
    pub blocks: Option<u32>,
}

/// The largest image side, in pixels, of any frame rendered.
pub const MAX_IMAGE_SIDE: u32 = 16384;

/// The size of an image of `scene`: `--size`, else what the scene file asks for, else
/// 1280x720.
pub fn image_size(option: Option<(u32, u32)>, scene: &Scene) -> (u32, u32) {
    option.or(scene.image_size).unwrap_or((1280, 720))
}

/// Parses `WIDTHxHEIGHT`.
/// A path the viewer writes a PNG to: its extension must say so (a `.jpg` would hold PNG
/// bytes).
pub fn parse_png_path(text: &str) -> Result<PathBuf> {
    let path = PathBuf::from(text);
    let png = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !png {
        bail!("screenshots are PNG: the path must end in .png, got {text:?}");
    }
    Ok(path)
}

/// A number option: finite (NaN and infinities would pass every range check after it).
pub fn parse_finite(text: &str) -> Result<f32> {
    let value: f32 = text
        .trim()
        .parse()
        .map_err(|_| anyhow!("expected a number, got {text:?}"))?;
    if !value.is_finite() {
        bail!("expected a finite number, got {text:?}");
    }
    Ok(value)
}

/// A shadow view's side: a power of two (the atlas packs tiles by halving,
/// `ShadowAtlas`) from 16 to 8192.
fn parse_shadow_res(text: &str) -> Result<u32> {
    let value: u32 = text
        .trim()
        .parse()
        .map_err(|_| anyhow!("expected a whole number, got {text:?}"))?;
    let range = crate::passes::shadow::MIN_VIEW_RESOLUTION..=8192;
    if !value.is_power_of_two() || !range.contains(&value) {
        bail!("expected a power of two from 16 to 8192, got {value}");
    }
    Ok(value)
}

pub fn parse_size(text: &str) -> Result<(u32, u32)> {
    let Some((w, h)) = text.split_once(['x', 'X']) else {
        bail!("expected WIDTHxHEIGHT, e.g. 1280x720, got {text:?}");
    };
    let (w, h): (u32, u32) = match (w.trim().parse(), h.trim().parse()) {
        (Ok(w), Ok(h)) => (w, h),
        _ => bail!("expected WIDTHxHEIGHT with whole numbers, got {text:?}"),
    };
    if w == 0 || h == 0 || w > MAX_IMAGE_SIDE || h > MAX_IMAGE_SIDE {
        bail!("size {w}x{h} is out of range (1..={MAX_IMAGE_SIDE} per side)");
    }
    Ok((w, h))
}

impl CommonArgs {
    /// The scene path, or the built-in default scene.
    pub fn scene_path(&self) -> PathBuf {
        self.scene.clone().unwrap_or_else(default_scene)
    }

    /// Reference scenes (`*.scene.json`) declare two-sided Lambertian materials without
    /// normal maps, d as a straight-through mask, so loading one implies
    /// `--diffuse-only --no-normal-maps --no-refraction`.
    fn is_reference(&self) -> bool {
        self.scene_path().to_string_lossy().ends_with(".scene.json")
    }

    pub fn load_options(&self) -> LoadOptions {
        let reference = self.is_reference();
        LoadOptions {
            diffuse_only: self.diffuse_only || reference,
            no_normal_maps: self.no_normal_maps || reference,
            no_refraction: self.no_refraction || reference,
        }
    }

    /// `--cone`, checked against the gather's cones.
    fn cone_component(&self, cones: &ConeSettings) -> Result<Option<u32>> {
        match self.cone {
            Some(k) if cones.lattice_cones != 0 => {
                bail!("--cone {k} picks a cone of the ring: --lattice-cones has none")
            }
            Some(k) if k >= cones.diffuse_cones => bail!(
                "--cone {k}: the diffuse gather has cones 0 to {} (--diffuse-cones {})",
                cones.diffuse_cones - 1,
                cones.diffuse_cones
            ),
            cone => Ok(cone),
        }
    }

    /// The settings of a frame: the command line over the scene file's `[gi]` over the
    /// defaults, the cone tracer's and the shadow maps' those of `quality` unless
    /// `--quality` or the scene file says otherwise (`render` asks for
    /// [`Quality::Accurate`], `view` and `bench` for [`Quality::Fast`]).
    pub fn render_settings(&self, scene: &GiOverrides, quality: Quality) -> Result<RenderSettings> {
        let quality = self.vct.quality.or(scene.quality).unwrap_or(quality);
        let shadows = match quality {
            Quality::Fast => ShadowResolution::FRAMES,
            Quality::Accurate => ShadowResolution::ONE_IMAGE,
        };
        let options = self.load_options();
        if self.vct.octree_depth.is_some() && self.gi != GiMode::Octree {
            bail!("--octree-depth sets the sparse voxel octree: it needs --gi octree");
        }
        if self.gi != GiMode::Path {
            if let Some(option) = self.path.given().first() {
                bail!("{option} sets the path tracer: it needs --gi path");
            }
        }
        if self.gi != GiMode::Probes {
            if let Some(option) = self.probes.given().first() {
                bail!("{option} sets the irradiance probes: it needs --gi probes");
            }
        }
        if self.cone.is_some() && matches!(self.gi, GiMode::Off | GiMode::Probes) {
            bail!("--cone is a cone of the cone tracer's gather: it needs --gi dense, --gi octree or --gi path");
        }
        if !matches!(self.gi, GiMode::Dense | GiMode::Octree) {
            // The path tracer's cone component takes the gather's layout, so that the
            // exact cones of any layout can be rendered.
            let layout = ["--diffuse-cones", "--diffuse-aperture", "--cosine-cones"];
            let path_cone = self.gi == GiMode::Path && self.cone.is_some();
            if let Some(option) = self
                .vct
                .given()
                .into_iter()
                .find(|o| !(path_cone && layout.contains(o)))
            {
                bail!("{option} works on the voxels: it needs --gi dense or --gi octree");
            }
        }
        let gi = match self.gi {
            GiMode::Dense | GiMode::Octree => {
                let octree = self.gi == GiMode::Octree;
                if !octree && self.debug_view == DebugView::OctreeNodes {
                    bail!("--debug-view octree-nodes shows the octree: it needs --gi octree");
                }
                let mut settings =
                    self.vct
                        .settings(octree, scene, quality, self.cone.is_some())?;
                settings.cones.only_cone = self.cone_component(&settings.cones)?;
                GiSettings::ConeTracing(settings)
            }
            GiMode::Path => {
                let mut settings = self.path.settings(scene, self.is_reference());
                settings.check()?;
                if self.cone.is_some() {
                    // The gather's layout as the cone tracer's settings give it (the
                    // scene file's [gi] over the defaults).
                    let cones = self.vct.settings(false, scene, quality, true)?.cones;
                    settings.cone = self.cone_component(&cones)?.map(|index| ConeComponent {
                        index,
                        ring: cones.diffuse_cones - 1,
                        aperture_deg: cones.diffuse_aperture_deg,
                        cosine: cones.cosine_cones,
                    });
                }
                GiSettings::Path(settings)
            }
            GiMode::Probes => {
                if !crate::gi::probes::frame::DEBUG_VIEWS.contains(&self.debug_view) {
                    let name = self
                        .debug_view
                        .to_possible_value()
                        .map(|v| v.get_name().to_owned());
                    bail!(
                        "--debug-view {}: --gi probes offers none, indirect, lightmap, clusters \
                         and probes",
                        name.unwrap_or_default()
                    );
                }
                GiSettings::Probes(
                    self.probes
                        .frame_settings(scene, quality == Quality::Accurate)?,
                )
            }
            GiMode::Off => {
                if self.debug_view != DebugView::None {
                    bail!("--debug-view works on the voxels: it needs --gi dense or --gi octree");
                }
                GiSettings::Off
            }
        };
        Ok(RenderSettings {
            specular: !options.diffuse_only,
            normal_maps: !options.no_normal_maps,
            exposure_ev: self.exposure,
            tonemap: self.tonemap,
            shadow_resolution: ShadowResolution {
                local: self.shadow_res.unwrap_or(shadows.local),
                directional: self.sun_shadow_res.unwrap_or(shadows.directional),
                budget_mib: self.shadow_budget,
            },
            cache_shadows: true,
            anisotropy_on_cpu: quality == Quality::Accurate,
            opaque_shadow_cut_outs: self.is_reference(),
            terms: Terms {
                direct: !self.no_direct,
                emission: !self.no_emission,
                indirect_diffuse: !self.no_indirect,
                indirect_specular: !self.no_indirect_specular,
                transmission: !self.no_transmission,
                ambient_occlusion: self.ao,
            },
            debug_view: self.debug_view,
            debug_level: self.debug_level,
            gi,
        })
    }

    pub fn validation(&self) -> bool {
        validation_requested(self.validation)
    }
}

/// Whether validation is on: by the `--validation` flag, or VOXCONE_VALIDATION=1.
pub fn validation_requested(flag: bool) -> bool {
    flag || std::env::var("VOXCONE_VALIDATION").is_ok_and(|v| v == "1")
}

/// The built-in Cornell box in `assets/`: of the checkout `cargo run` runs from, else of
/// the one the binary was built in (a build shared between checkouts may be either's),
/// else, for a binary copied or installed elsewhere, the copy of it that the binary
/// carries, written to `$XDG_CACHE_HOME/voxcone/builtin` (or `~/.cache/...`, or the
/// temporary directory). Where that cannot be written either, the checkout's path: the
/// loader's error names it.
pub fn default_scene() -> PathBuf {
    let in_checkout = std::env::var_os("CARGO_MANIFEST_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")))
        .join("assets/cornell.toml");
    if in_checkout.exists() {
        return in_checkout;
    }
    let cache = std::env::var_os("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
        .unwrap_or_else(std::env::temp_dir);
    write_builtin_scene(&cache.join("voxcone/builtin")).unwrap_or(in_checkout)
}

/// The built-in scene's files, as the binary carries them.
const BUILTIN_SCENE: [(&str, &str); 3] = [
    ("cornell.toml", include_str!("../assets/cornell.toml")),
    ("cornell.obj", include_str!("../assets/cornell.obj")),
    ("cornell.mtl", include_str!("../assets/cornell.mtl")),
];

/// Writes the built-in scene's files into `dir` (unless they are there already) and
/// returns the path of its scene file.
fn write_builtin_scene(dir: &std::path::Path) -> std::io::Result<PathBuf> {
    std::fs::create_dir_all(dir)?;
    for (name, text) in BUILTIN_SCENE {
        let path = dir.join(name);
        if std::fs::read_to_string(&path).ok().as_deref() != Some(text) {
            std::fs::write(&path, text)?;
        }
    }
    Ok(dir.join(BUILTIN_SCENE[0].0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gi::vct::{
        ConeSettings, DirectionalFilter, Resolution, Store, VctSettings, LATTICE_CONES,
    };

    fn cone_tracing(settings: RenderSettings) -> VctSettings {
        match settings.gi {
            GiSettings::ConeTracing(vct) => vct,
            _ => panic!("no cone tracing"),
        }
    }

    /// NaN and infinities are refused by every number option (they pass range checks).
    #[test]
    fn number_options_must_be_finite() {
        assert_eq!(parse_finite(" -2.5").unwrap(), -2.5);
        for text in ["nan", "NaN", "inf", "-inf", "infinity", "1e39"] {
            let error = parse_finite(text).unwrap_err().to_string();
            assert!(error.contains("finite") && error.contains(text), "{error}");
        }
        assert!(parse_finite("two")
            .unwrap_err()
            .to_string()
            .contains("a number"));
    }

    #[test]
    fn screenshots_are_png_paths() {
        assert!(parse_png_path("shot.PNG").is_ok());
        for text in ["shot.jpg", "shot", "shot.exr"] {
            let error = parse_png_path(text).unwrap_err().to_string();
            assert!(error.contains(".png") && error.contains(text), "{error}");
        }
    }

    #[test]
    fn bench_frame_counts_are_bounded() {
        for option in ["--warmup", "--frames"] {
            let err = Cli::try_parse_from(["voxcone", "bench", option, "4294967295"]).unwrap_err();
            assert!(err.to_string().contains("1000000"), "{err}");
        }
    }

    /// A binary away from its checkout loads the copy of the built-in scene it carries.
    #[test]
    fn builtin_scene_loads_from_the_copy_the_binary_carries() {
        let dir = std::env::temp_dir().join(format!("voxcone-builtin-{}", std::process::id()));
        let path = write_builtin_scene(&dir).unwrap();
        let copy = crate::scene::Scene::load(&path, &Default::default()).unwrap();
        let original = crate::scene::Scene::load(&default_scene(), &Default::default()).unwrap();
        assert_eq!(copy.meshes.len(), original.meshes.len());
        assert!(!copy.meshes.is_empty());
        // Written again over an older copy.
        std::fs::write(dir.join("cornell.obj"), "# stale").unwrap();
        write_builtin_scene(&dir).unwrap();
        assert_eq!(
            std::fs::read_to_string(dir.join("cornell.obj")).unwrap(),
            BUILTIN_SCENE[1].1
        );
        std::fs::remove_dir_all(&dir).ok();
    }

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

    /// The settings the command line `args` (`render`, `view` or `bench`) makes with the
    /// scene file's `[gi]` table `scene`: one image accurate, frames fast.
    fn settings_of(args: &[&str], scene: &GiOverrides) -> Result<RenderSettings> {
        match Cli::try_parse_from(args).unwrap().command {
            Some(Command::Render(r)) => r.common.render_settings(scene, Quality::Accurate),
            Some(Command::View(v)) => v.common.render_settings(scene, Quality::Fast),
            Some(Command::Bench(b)) => b.common.render_settings(scene, Quality::Fast),
            _ => unreachable!(),
        }
    }

    #[test]
    fn command_line_wins_over_the_scene_file_over_the_defaults() {
        let scene = GiOverrides {
            voxels: Some(32),
            diffuse_cones: Some(9),
            shadow_cones: Some(true),
            ..Default::default()
        };
        let parse = |args: &[&str]| settings_of(args, &scene).unwrap();
        let gi = cone_tracing(parse(&["voxcone", "render"]));
        assert_eq!(
            (gi.voxels, gi.cones.diffuse_cones),
            (Resolution::Count(32), 9)
        );
        assert!(gi.shadow_cones);
        assert_eq!(gi.cones.step_factor, ConeSettings::default().step_factor);
        let gi = cone_tracing(parse(&[
            "voxcone",
            "render",
            "--voxels",
            "16",
            "--diffuse-cones",
            "4",
        ]));
        assert_eq!(
            (gi.voxels, gi.cones.diffuse_cones),
            (Resolution::Count(16), 4)
        );
    }

    /// A count wins over a size from the same place, the command line over the scene
    /// file; without either the device decides (`Resolution::Auto`).
    #[test]
    fn voxels_come_from_a_count_a_size_or_the_device() {
        let parse = |scene: GiOverrides, args: &[&str]| settings_of(args, &scene).map(cone_tracing);
        let none = GiOverrides::default();
        let sized = GiOverrides {
            voxel_size: Some(0.5),
            ..Default::default()
        };
        let auto = |size| Resolution::Auto {
            size,
            quality: Quality::Accurate,
        };
        let voxels = |scene, args: &[&str]| parse(scene, args).unwrap().voxels;
        assert_eq!(voxels(none, &["voxcone", "render"]), auto(None));
        assert_eq!(voxels(sized, &["voxcone", "render"]), auto(Some(0.5)));
        let args = ["voxcone", "render", "--voxels", "128"];
        assert_eq!(voxels(sized, &args), Resolution::Count(128));
        let args = ["voxcone", "render", "--voxel-size", "2"];
        let counted = GiOverrides {
            voxels: Some(32),
            ..Default::default()
        };
        assert_eq!(voxels(counted, &args), auto(Some(2.0)));
        let args = ["voxcone", "render", "--gi", "octree", "--octree-depth", "7"];
        assert_eq!(voxels(sized, &args), Resolution::Count(128));
        // The octree takes a given count's depth, checked at once.
        let args = ["voxcone", "render", "--gi", "octree", "--voxels", "32"];
        let err = parse(none, &args).unwrap_err();
        assert!(format!("{err:#}").contains("--octree-depth"), "{err:#}");
        let both = GiOverrides {
            voxels: Some(32),
            voxel_size: Some(0.5),
            ..Default::default()
        };
        let err = parse(both, &["voxcone", "render"]).unwrap_err();
        assert!(
            format!("{err:#}").contains("both voxels and voxel_size"),
            "{err:#}"
        );
        let args = ["voxcone", "render", "--voxel-size", "0"];
        let err = parse(none, &args).unwrap_err();
        assert!(format!("{err:#}").contains("positive length"), "{err:#}");
        let args = ["voxcone", "render", "--voxels", "64", "--voxel-size", "1"];
        assert!(Cli::try_parse_from(args).is_err());
    }

    /// The path tracer's cone component takes the gather's layout from the command line;
    /// without `--cone` the layout's options are still the voxels' alone.
    #[test]
    fn path_cone_takes_the_gathers_layout() {
        let parse = |args: &[&str]| settings_of(args, &GiOverrides::default());
        let settings = parse(&[
            "voxcone",
            "render",
            "--gi",
            "path",
            "--cone",
            "7",
            "--diffuse-cones",
            "9",
            "--diffuse-aperture",
            "40",
        ])
        .unwrap();
        let cone = match settings.gi {
            GiSettings::Path(path) => path.cone.unwrap(),
            _ => panic!("no path tracer"),
        };
        assert_eq!((cone.index, cone.ring, cone.aperture_deg), (7, 8, 40.0));
        let err =
            parse(&["voxcone", "render", "--gi", "path", "--diffuse-cones", "9"]).unwrap_err();
        assert!(
            err.to_string()
                .contains("--diffuse-cones works on the voxels"),
            "{err}"
        );
        let err = parse(&[
            "voxcone", "render", "--gi", "path", "--cone", "1", "--voxels", "32",
        ])
        .unwrap_err();
        assert!(
            err.to_string().contains("--voxels works on the voxels"),
            "{err}"
        );
    }

    /// `--lattice-cones` implies the snapped lookups and replaces the ring, whose options
    /// and components it refuses; snapped cones refuse the steps' options.
    #[test]
    fn lattice_replaces_the_ring() {
        let parse = |args: &[&str]| settings_of(args, &GiOverrides::default());
        let gi = cone_tracing(parse(&["voxcone", "render", "--lattice-cones", "72"]).unwrap());
        assert_eq!(gi.cones.lattice_cones, 72);
        assert!(gi.cones.snapped_cones);
        for (args, message) in [
            (&["--lattice-cones", "16"][..], "between 32 and 256, got 16"),
            (
                &["--lattice-cones", "72", "--cone", "1"],
                "--lattice-cones has none",
            ),
            (
                &["--lattice-cones", "72", "--diffuse-cones", "9"],
                "--diffuse-cones / diffuse_cones sets the ring",
            ),
            (
                &["--lattice-cones", "72", "--cosine-cones"],
                "--cosine-cones / cosine_cones sets the ring",
            ),
            (
                &["--lattice-cones", "72", "--step-factor", "0.3"],
                "--step-factor / step_factor sets the steps of the trilinear cones",
            ),
            (
                &["--snapped-cones", "--wide-steps-by-level"],
                "snapped cones (--snapped-cones, --lattice-cones) march from cell to cell",
            ),
        ] {
            let err = parse(&[&["voxcone", "render"][..], args].concat()).unwrap_err();
            assert!(format!("{err:#}").contains(message), "{err:#}");
        }
    }

    /// Switching to the lattice (or to snapped cones) from the settings panel, with the
    /// ring's and the steps' options set before, drops them rather than being refused.
    #[test]
    fn switching_the_layout_drops_what_it_ignores() {
        let mut args = match Cli::try_parse_from([
            "voxcone",
            "render",
            "--diffuse-cones",
            "9",
            "--cosine-cones",
            "--step-factor",
            "0.3",
            "--bounce-step-factor",
            "0.4",
            "--wide-steps-by-level",
        ])
        .unwrap()
        .command
        {
            Some(Command::Render(r)) => r.common,
            _ => unreachable!(),
        };
        args.vct.lattice_cones = Some(72);
        assert!(args
            .render_settings(&GiOverrides::default(), Quality::Accurate)
            .is_err());
        args.vct.drop_ignored_by(true, true);
        let gi = cone_tracing(
            args.render_settings(&GiOverrides::default(), Quality::Accurate)
                .unwrap(),
        );
        assert_eq!(gi.cones.lattice_cones, 72);
        args.vct.lattice_cones = Some(0);
        args.vct.snapped_cones = true;
        args.vct.diffuse_cones = Some(9);
        args.vct.step_factor = Some(0.3);
        assert!(args
            .render_settings(&GiOverrides::default(), Quality::Accurate)
            .is_err());
        args.vct.drop_ignored_by(true, false);
        let gi = cone_tracing(
            args.render_settings(&GiOverrides::default(), Quality::Accurate)
                .unwrap(),
        );
        assert_eq!(gi.cones.diffuse_cones, 9);
        assert!(gi.cones.snapped_cones);
    }

    /// Textures are filtered anisotropically on a CPU driver for one image, not for frames
    /// (`--quality` chooses, as for the cones), whatever the technique.
    #[test]
    fn a_cpu_driver_filters_anisotropically_for_one_image_only() {
        let anisotropy = |args: &[&str]| {
            settings_of(args, &GiOverrides::default())
                .unwrap()
                .anisotropy_on_cpu
        };
        assert!(anisotropy(&["voxcone", "render"]));
        assert!(anisotropy(&["voxcone", "render", "--gi", "off"]));
        assert!(!anisotropy(&["voxcone", "render", "--quality", "fast"]));
        assert!(!anisotropy(&["voxcone", "view", "--gi", "probes"]));
        assert!(!anisotropy(&["voxcone", "bench"]));
        assert!(anisotropy(&["voxcone", "bench", "--quality", "accurate"]));
    }

    /// `render` takes the accurate defaults (the lattice, the voxels by memory), `view`
    /// and `bench` the fast ones (the ring); `--quality` and the scene file's `quality`
    /// choose, and the ring's options keep the ring.
    #[test]
    fn one_image_is_accurate_frames_are_fast() {
        let settings = |args: &[&str], scene: &GiOverrides| {
            let gi = cone_tracing(settings_of(args, scene).unwrap());
            let Resolution::Auto { quality, .. } = gi.voxels else {
                panic!("a given resolution");
            };
            (gi.cones.lattice_cones, quality)
        };
        let none = GiOverrides::default();
        let accurate = (LATTICE_CONES, Quality::Accurate);
        assert_eq!(settings(&["voxcone", "render"], &none), accurate);
        assert_eq!(settings(&["voxcone", "view"], &none), (0, Quality::Fast));
        assert_eq!(settings(&["voxcone", "bench"], &none), (0, Quality::Fast));
        let fast = ["voxcone", "render", "--quality", "fast"];
        assert_eq!(settings(&fast, &none), (0, Quality::Fast));
        let scene = GiOverrides {
            quality: Some(Quality::Accurate),
            ..Default::default()
        };
        assert_eq!(settings(&["voxcone", "view"], &scene), accurate);
        assert_eq!(
            settings(&["voxcone", "view", "--quality", "fast"], &scene),
            (0, Quality::Fast)
        );
        for ring in [
            &["--diffuse-cones", "9"][..],
            &["--cosine-cones"],
            &["--snapped-cones"],
            &["--step-factor", "0.3"],
        ] {
            let args = [&["voxcone", "render"][..], ring].concat();
            assert_eq!(settings(&args, &none), (0, Quality::Accurate), "{ring:?}");
        }
        let cone = ["voxcone", "render", "--cone", "1"];
        assert_eq!(settings(&cone, &none), (0, Quality::Accurate));
        let octree = ["voxcone", "render", "--gi", "octree"];
        assert_eq!(settings(&octree, &none), accurate);
        let error = settings_of(
            &["voxcone", "render", "--gi", "off", "--quality", "fast"],
            &none,
        )
        .unwrap_err();
        assert!(
            error.to_string().contains("--quality works on the voxels"),
            "{error}"
        );
    }

    /// `render` (`--quality accurate`) traces as many bounces as converge unless a count is
    /// given, on the command line or in the scene file; frames keep theirs.
    #[test]
    fn one_image_converges_its_bounces() {
        let converge = |args: &[&str], scene: &GiOverrides| {
            cone_tracing(settings_of(args, scene).unwrap()).converge_bounces
        };
        let none = GiOverrides::default();
        assert!(converge(&["voxcone", "render"], &none));
        assert!(converge(&["voxcone", "render", "--gi", "octree"], &none));
        assert!(!converge(&["voxcone", "render", "--bounces", "8"], &none));
        let given = GiOverrides {
            bounces: Some(3),
            ..Default::default()
        };
        assert!(!converge(&["voxcone", "render"], &given));
        assert!(!converge(
            &["voxcone", "render", "--quality", "fast"],
            &none
        ));
        assert!(!converge(&["voxcone", "view"], &none));
    }

    /// So do the irradiance probes' (`--probe-bounces`).
    #[test]
    fn one_image_converges_the_probes_bounces() {
        let converge = |args: &[&str], scene: &GiOverrides| {
            let args = [args, &["--gi", "probes"][..]].concat();
            match settings_of(&args, scene).unwrap().gi {
                GiSettings::Probes(probes) => probes.converge_bounces,
                _ => panic!("no probes"),
            }
        };
        let none = GiOverrides::default();
        assert!(converge(&["voxcone", "render"], &none));
        assert!(!converge(
            &["voxcone", "render", "--probe-bounces", "8"],
            &none
        ));
        let given = GiOverrides {
            probe_bounces: Some(3),
            ..Default::default()
        };
        assert!(!converge(&["voxcone", "render"], &given));
        assert!(!converge(&["voxcone", "view"], &none));
        assert!(!converge(&["voxcone", "bench"], &none));
    }

    /// `render` draws its shadow maps finer than the frames do, `--quality fast` as the
    /// frames, and the flags win over both.
    #[test]
    fn one_image_takes_finer_shadow_maps() {
        let shadows = |args: &[&str]| {
            let cli = Cli::try_parse_from(args).unwrap();
            let settings = match cli.command {
                Some(Command::Render(r)) => r
                    .common
                    .render_settings(&GiOverrides::default(), Quality::Accurate),
                Some(Command::View(v)) => v
                    .common
                    .render_settings(&GiOverrides::default(), Quality::Fast),
                _ => unreachable!(),
            };
            let r = settings.unwrap().shadow_resolution;
            (r.local, r.directional)
        };
        assert_eq!(shadows(&["voxcone", "render"]), (4096, 8192));
        assert_eq!(shadows(&["voxcone", "render", "--gi", "off"]), (4096, 8192));
        assert_eq!(shadows(&["voxcone", "view"]), (1024, 4096));
        assert_eq!(
            shadows(&["voxcone", "render", "--quality", "fast"]),
            (1024, 4096)
        );
        let given = [
            "voxcone",
            "render",
            "--shadow-res",
            "512",
            "--sun-shadow-res",
            "2048",
        ];
        assert_eq!(shadows(&given), (512, 2048));
        let given = ["voxcone", "view", "--shadow-res", "2048"];
        assert_eq!(shadows(&given), (2048, 4096));
    }

    #[test]
    fn rows_filter_the_dense_grid_only() {
        let parse = |args: &[&str]| settings_of(args, &GiOverrides::default());
        let gi =
            cone_tracing(parse(&["voxcone", "render", "--directional-filter", "rows"]).unwrap());
        assert_eq!(
            gi.store,
            Store::Dense {
                filter: DirectionalFilter::Rows,
                planes: false,
            }
        );
        let octree = [
            "voxcone",
            "render",
            "--gi",
            "octree",
            "--directional-filter",
            "rows",
        ];
        let error = parse(&octree).unwrap_err().to_string();
        assert!(error.contains("needs --gi dense"), "{error}");
    }

    #[test]
    fn planes_wherever_pairs_and_snapped_cones_meet() {
        let planes = |args: &[&str]| {
            let args = [&["voxcone", "render"][..], args].concat();
            cone_tracing(settings_of(&args, &GiOverrides::default()).unwrap())
                .store
                .planes()
        };
        assert!(planes(&[]));
        assert!(planes(&["--gi", "octree"]));
        assert!(planes(&["--quality", "fast", "--snapped-cones"]));
        assert!(!planes(&["--no-plane-occlusion"]));
        assert!(!planes(&["--gi", "octree", "--no-plane-occlusion"]));
        assert!(!planes(&["--directional-filter", "rows"]));
        assert!(!planes(&["--quality", "fast"]));
    }

    #[test]
    fn each_kind_of_cone_takes_its_own_step() {
        let scene = GiOverrides {
            bounce_step_factor: Some(0.4),
            ..Default::default()
        };
        let parse = |args: &[&str]| settings_of(args, &scene);
        let gi =
            cone_tracing(parse(&["voxcone", "render", "--shadow-step-factor", "0.3"]).unwrap());
        let d = ConeSettings::default();
        assert_eq!(
            (
                gi.cones.step_factor,
                gi.cones.bounce_step_factor,
                gi.cones.shadow_step_factor
            ),
            (d.step_factor, 0.4, 0.3)
        );
        let err = parse(&["voxcone", "render", "--bounce-step-factor", "3"]).unwrap_err();
        assert!(
            format!("{err:#}").contains("--bounce-step-factor"),
            "{err:#}"
        );
    }
}
