//! Global illumination: each technique behind one interface, [`Technique`].
//!
//! The frame ([`crate::renderer`]) runs a technique in two places. After the shadow maps
//! and the G-buffer, [`Technique::record_update`] brings the technique's own data up to
//! date (the cone tracer's voxels, their light and its bounces). After the direct
//! lighting, [`Technique::record_gather`] gathers the indirect light for the screen into
//! the screen contract ([`screen`]): reduced-resolution terms, which the frame's
//! upsample adds to the direct light, or the screen radiance itself (a debug view).
//!
//! A technique is a folder here with its shaders in the `glsl/gi/` folder of the same
//! name, an arm of [`GiSettings`] and of [`create`]; README.md, "Adding a technique",
//! lists what else it touches. Today: voxel cone tracing ([`vct`]), the path-traced
//! reference ([`path`]) and irradiance probes ([`probes`]).

pub mod bounces;
pub mod path;
pub mod probes;
pub mod screen;
pub mod vct;

use std::any::Any;
use std::sync::Arc;

use anyhow::Result;
use ash::vk;

pub use self::screen::{Screen, ScreenRequest};
use crate::gpu_layout::{self as layout, FrameUniforms, GpuLight, ShadowView};
use crate::scene::Scene;
use crate::scene_gpu::{GpuScene, SceneDraw};
use crate::vk::{Context, GpuTimer};

/// The global-illumination technique of a frame, with its settings: one arm per
/// technique.
#[derive(Clone, Debug)]
pub enum GiSettings {
    /// Direct light only.
    Off,
    /// Voxel cone tracing, on a dense grid or an octree ([`vct`]).
    ConeTracing(vct::VctSettings),
    /// The path-traced reference ([`path`]).
    Path(path::PathSettings),
    /// Irradiance probes ([`probes`]).
    Probes(probes::frame::ProbeSettings),
}

impl GiSettings {
    /// The settings with what the device and the scene decide filled in (the voxel
    /// grid's resolution), as the technique will run them.
    pub fn on(&self, ctx: &Context, scene: &Scene) -> Self {
        match self {
            GiSettings::ConeTracing(vct) => GiSettings::ConeTracing(vct::VctSettings {
                voxels: vct::Resolution::Count(vct.voxels.on(ctx, scene, vct)),
                cones: vct::ConeSettings {
                    bounces: if vct.converge_bounces {
                        bounces::bounces_for(scene)
                    } else {
                        vct.cones.bounces
                    },
                    ..vct.cones
                },
                converge_bounces: false,
                ..*vct
            }),
            GiSettings::Probes(probes) => GiSettings::Probes(probes::frame::ProbeSettings {
                bounces: if probes.converge_bounces {
                    bounces::bounces_for(scene)
                } else {
                    probes.bounces
                },
                converge_bounces: false,
                ..probes.clone()
            }),
            other => other.clone(),
        }
    }

    /// Whether the technique filters each pixel itself (a path tracer's jittered camera
    /// rays), so that rendering more samples per pixel adds nothing.
    pub fn filters_pixels(&self) -> bool {
        matches!(self, GiSettings::Path(_))
    }
}

/// What every technique is created from.
pub struct Inputs<'a> {
    pub ctx: &'a Arc<Context>,
    pub scene: &'a Scene,
    /// The scene's geometry and materials on the GPU.
    pub gpu: &'a GpuScene,
    /// Those of sets 0 to 2: the frame's, the scene's and the screen contract's.
    pub set_layouts: [vk::DescriptorSetLayout; 3],
    /// Frames that may be recorded before the first is done.
    pub frames_in_flight: usize,
}

/// Creates the technique `settings` asks for (none with [`GiSettings::Off`]).
pub fn create(inputs: &Inputs, settings: &GiSettings) -> Result<Option<Box<dyn Technique>>> {
    Ok(match settings {
        GiSettings::Off => None,
        GiSettings::ConeTracing(vct) => Some(vct::create(inputs, vct)?),
        GiSettings::Path(path) => Some(Box::new(path::PathTracer::new(inputs, path)?)),
        GiSettings::Probes(probes) => Some(Box::new(probes::frame::ProbeGi::new(inputs, probes)?)),
    })
}

/// What the image shows instead of the composited frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum DebugView {
    /// The composited frame.
    #[default]
    None,
    /// Indirect light only (diffuse, specular and transmitted).
    Indirect,
    /// Ambient occlusion only.
    Ao,
    /// Voxel albedo at mip `--debug-level`.
    VoxelAlbedo,
    /// Voxel normals (xyz * 0.5 + 0.5) at mip `--debug-level`.
    VoxelNormal,
    /// Voxel radiance at mip `--debug-level`, from the volume facing the camera ray.
    VoxelRadiance,
    /// The octree's occupied nodes `--debug-level` levels above the leaves, each in its
    /// own colour with its edges drawn (`--gi octree` only).
    OctreeNodes,
    /// The irradiance probes' lightmap (irradiance / π) at each pixel, at its nearest
    /// texel (`--gi probes` only).
    Lightmap,
    /// Each receiver's cluster in its own colour (`--gi probes` only).
    Clusters,
    /// The light of the emitters the cone tracer samples, alone: their shadowed
    /// irradiance times albedo / π (`--gi dense` and `--gi octree` only).
    EmitterLight,
    /// The probes as small spheres showing the mean radiance each sees, over the indirect
    /// light (`--gi probes` only).
    Probes,
}

impl DebugView {
    /// The views of the screen contract's terms, which every technique that gathers
    /// them has.
    pub const SCREEN: [DebugView; 3] = [DebugView::None, DebugView::Indirect, DebugView::Ao];

    /// `FrameUniforms.debug_view`.
    pub fn code(self) -> u32 {
        match self {
            DebugView::None => layout::DEBUG_NONE,
            DebugView::Indirect => layout::DEBUG_INDIRECT,
            DebugView::Ao => layout::DEBUG_AO,
            DebugView::VoxelAlbedo => layout::DEBUG_VOXEL_ALBEDO,
            DebugView::VoxelNormal => layout::DEBUG_VOXEL_NORMAL,
            DebugView::VoxelRadiance => layout::DEBUG_VOXEL_RADIANCE,
            DebugView::OctreeNodes => layout::DEBUG_OCTREE_NODES,
            DebugView::Lightmap => layout::DEBUG_LIGHTMAP,
            DebugView::Clusters => layout::DEBUG_CLUSTERS,
            DebugView::Probes => layout::DEBUG_PROBES,
            DebugView::EmitterLight => layout::DEBUG_EMITTER_LIGHT,
        }
    }

    /// Whether the view shows the voxels rather than the screen.
    pub fn shows_voxels(self) -> bool {
        matches!(
            self,
            DebugView::VoxelAlbedo
                | DebugView::VoxelNormal
                | DebugView::VoxelRadiance
                | DebugView::OctreeNodes
        )
    }
}

/// What a frame gives a technique's update.
pub struct FrameInputs<'a> {
    pub draw: &'a SceneDraw<'a>,
    /// The frame's uniforms (camera, image size, flags), as the GPU sees them.
    pub uniforms: &'a FrameUniforms,
    /// The frame's slot in flight (the frame recorded that many frames ago used it last).
    pub slot: usize,
    /// The lights as the GPU sees them this frame.
    pub lights: &'a [GpuLight],
    /// The shadow maps' views this frame.
    pub views: &'a [ShadowView],
}

/// How a technique's gather is to run.
#[derive(Clone, Copy, Debug)]
pub struct GatherOptions {
    pub debug_view: DebugView,
    /// The ambient occlusion is applied or shown.
    pub ambient_occlusion: bool,
}

/// What a technique's gather left for the frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Gathered {
    /// The terms in the screen contract's reduced-resolution targets: the upsample adds
    /// them to the screen radiance.
    Terms,
    /// The screen radiance itself, overwritten (a debug view of the technique's data).
    Screen,
}

/// A switch of a technique that the viewer offers on a key.
pub struct Switch<'a> {
    /// What it switches, for the log ("soft-shadow cones").
    pub name: &'static str,
    /// The viewer's key: a lower-case letter.
    pub key: char,
    pub on: &'a mut bool,
}

/// How far a technique that converges over frames has come (a path tracer's samples).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progress {
    /// Samples per pixel recorded so far.
    pub done: u32,
    /// Samples per pixel it converges to.
    pub total: u32,
    /// Frames still to record to get there, the next one included (1 for the last).
    pub frames_left: u32,
}

/// A technique's work before the first frame, as `bench` reports it.
pub struct Preparation {
    /// One line: what was prepared and how long it took.
    pub summary: String,
    /// GPU milliseconds per pass.
    pub passes: Vec<(String, f64)>,
}

/// A global-illumination technique, as the frame and the front ends see it.
pub trait Technique: Any {
    /// Work before the first frame, waited for (the octree's build).
    fn prepare(&mut self, draw: &SceneDraw) -> Result<()>;

    /// Makes the technique's screen-sized resources for frames of `extent` (no frame
    /// using the old ones is in flight) and says how the screen contract's terms are to be
    /// laid out.
    fn bind_screen(&mut self, extent: vk::Extent2D) -> Result<ScreenRequest>;

    /// Records the technique's update, after the shadow maps and the G-buffer and before
    /// the lighting pass.
    fn record_update(
        &mut self,
        cmd: vk::CommandBuffer,
        timer: &mut GpuTimer,
        frame: &FrameInputs,
    ) -> Result<()>;

    /// Records the gather into `screen`, after the lighting pass (or instead of it, when
    /// [`Self::shades_direct`]).
    fn record_gather(
        &self,
        cmd: vk::CommandBuffer,
        timer: &mut GpuTimer,
        frame_set: vk::DescriptorSet,
        screen: &Screen,
        options: &GatherOptions,
    ) -> Gathered;

    /// Forgets what earlier frames accumulated (after a pause, say).
    fn restart(&mut self);

    /// Whether the technique shades the direct light itself, with its own visibility in
    /// the screen contract's shadow terms: the lighting pass does not run, and the
    /// upsample shades every pixel.
    fn shades_direct(&self) -> bool;

    /// GPU memory of the technique's resources, by name.
    fn memory_bytes(&self) -> Vec<(&'static str, u64)>;

    /// Counts `bench` reports (voxels, nodes, bricks...), by name; read once the frames
    /// are done.
    fn stats(&self) -> Result<Vec<(String, f64)>>;

    /// The last preparation, if the technique prepares anything.
    fn preparation(&self) -> Option<Preparation>;

    /// The debug views the technique offers, [`DebugView::None`] first.
    fn debug_views(&self) -> &'static [DebugView];

    /// The highest `--debug-level` its views have.
    fn debug_levels(&self) -> u32;

    /// The switches the viewer offers.
    fn switches(&mut self) -> Vec<Switch<'_>>;

    /// Whether the frame's shadow maps and G-buffer feed the technique (a path tracer
    /// casts its own camera rays: without them, neither is drawn).
    fn uses_raster_passes(&self) -> bool {
        true
    }

    /// How far a technique that converges over frames has come; `None` for one whose
    /// every frame is complete.
    fn progress(&self) -> Option<Progress> {
        None
    }
}
