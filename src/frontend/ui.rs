//! The viewer's panel (egui): the technique and its settings, the terms, debug views,
//! lights, camera, per-pass GPU times with a frame-time graph, memory and the
//! technique's stats, and a screenshot button. It is drawn over the composite as the
//! timed pass `ui` ([`Renderer::record_overlay`]); F1 shows and hides it, `--no-ui`
//! starts without it. `bench --ui` draws it over the offscreen image without a window,
//! to time it.
//!
//! Settings that change what the technique builds (the technique itself, cones, voxels,
//! bounces, lights added or removed) edit the viewer's copy of the command line, from
//! which the renderer is built again; the terms, debug views, light positions and
//! intensities and the camera change live.

use std::collections::VecDeque;
use std::sync::Arc;

use anyhow::{anyhow, Result};
use ash::vk;
use egui::{ClippedPrimitive, Color32, TextureId};
use egui_ash_renderer::allocator::DefaultAllocator;
use glam::Vec3;
use winit::window::Window;

use crate::cli::{CommonArgs, GiMode};
use crate::gi::bounces::MAX_BOUNCES;
use crate::gi::path::cli::PathArgs;
use crate::gi::probes::cli::{ProbeArgs, Switch};
use crate::gi::vct::cli::VctArgs;
use crate::gi::vct::voxelize::Voxelizer;
use crate::gi::vct::{DirectionalFilter, Store, CPU_VOXELS, LATTICE_CONES};
use crate::gi::{DebugView, GiSettings};
use crate::renderer::{Renderer, FRAMES_IN_FLIGHT};
use crate::scene::{Light, LightKind};
use crate::settings::Tonemap;
use crate::vk::Context;

/// Frames of the frame-time graph.
const GRAPH_FRAMES: usize = 300;

/// Frames between two readings of the technique's stats (they read GPU counters back).
const STATS_EVERY: u64 = 30;

/// What the panel asks the viewer to do after this frame's update.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Request {
    /// Build the renderer again from the edited command line.
    Rebuild,
    /// Save the next frame as a PNG.
    Screenshot,
}

/// What the panel shows and edits.
pub struct PanelView<'a> {
    pub renderer: &'a mut Renderer,
    /// The viewer's copy of the command line, which a rebuild uses.
    pub args: &'a mut CommonArgs,
    /// Camera speed multiplier.
    pub speed: &'a mut f32,
}

pub struct Panel {
    egui: egui::Context,
    /// The window's input (none in `bench`, which draws the panel without one).
    state: Option<egui_winit::State>,
    painter: egui_ash_renderer::Renderer<DefaultAllocator>,
    command_pool: vk::CommandPool,
    ctx: Arc<Context>,
    pub visible: bool,
    primitives: Vec<ClippedPrimitive>,
    pixels_per_point: f32,
    /// Textures egui freed, released once no frame in flight uses them.
    to_free: Vec<TextureId>,
    frame_ms: VecDeque<f32>,
    stats: Vec<(String, f64)>,
    frames: u64,
    /// The last rebuild's error, shown until the next rebuild.
    pub message: Option<String>,
    /// A rebuild is asked for: this frame says so, the next one does it.
    pub building: bool,
}

impl Panel {
    pub fn new(ctx: &Arc<Context>, window: Option<&Window>, format: vk::Format) -> Result<Self> {
        let egui = egui::Context::default();
        let max_side = ctx.properties.limits.max_image_dimension2_d as usize;
        let state = window.map(|window| {
            egui_winit::State::new(
                egui.clone(),
                egui::ViewportId::ROOT,
                window,
                Some(window.scale_factor() as f32),
                None,
                Some(max_side),
            )
        });
        let srgb = matches!(
            format,
            vk::Format::B8G8R8A8_SRGB | vk::Format::R8G8B8A8_SRGB
        );
        let painter = egui_ash_renderer::Renderer::with_default_allocator(
            &ctx.instance,
            ctx.physical_device,
            ctx.device.clone(),
            egui_ash_renderer::RenderMode::DynamicRendering(egui_ash_renderer::DynamicRendering {
                color_attachment_format: format,
                depth_attachment_format: None,
                stencil_attachment_format: None,
            }),
            egui_ash_renderer::Options {
                in_flight_frames: FRAMES_IN_FLIGHT,
                srgb_framebuffer: srgb,
                ..Default::default()
            },
        )
        .map_err(|e| anyhow!("creating the panel's renderer: {e}"))?;
        let command_pool = unsafe {
            ctx.device.create_command_pool(
                &vk::CommandPoolCreateInfo::default()
                    .queue_family_index(ctx.queue_family)
                    .flags(vk::CommandPoolCreateFlags::TRANSIENT),
                None,
            )
        }?;
        Ok(Self {
            egui,
            state,
            painter,
            command_pool,
            ctx: ctx.clone(),
            visible: true,
            primitives: Vec::new(),
            pixels_per_point: 1.0,
            to_free: Vec::new(),
            frame_ms: VecDeque::with_capacity(GRAPH_FRAMES),
            stats: Vec::new(),
            frames: 0,
            message: None,
            building: false,
        })
    }

    /// Passes a window event to the panel; true when the panel used it (a click on it,
    /// typing in it), so that the viewer's own controls leave it alone.
    pub fn on_event(&mut self, window: &Window, event: &winit::event::WindowEvent) -> bool {
        match &mut self.state {
            Some(state) if self.visible => state.on_window_event(window, event).consumed,
            _ => false,
        }
    }

    /// Whether the pointer is over the panel (drags there do not turn the camera).
    pub fn wants_pointer(&self) -> bool {
        self.visible && self.egui.egui_wants_pointer_input()
    }

    /// Lays the panel out for this frame (of `extent`, in `window` where there is one),
    /// applies its live edits and uploads its textures; returns what the viewer must do.
    pub fn update(
        &mut self,
        window: Option<&Window>,
        extent: vk::Extent2D,
        view: PanelView,
        frame_ms: f32,
    ) -> Result<Vec<Request>> {
        if self.frame_ms.len() == GRAPH_FRAMES {
            self.frame_ms.pop_front();
        }
        self.frame_ms.push_back(frame_ms);
        self.frames += 1;
        if !self.visible {
            self.primitives.clear();
            return Ok(Vec::new());
        }
        if self.frames % STATS_EVERY == 1 {
            if let Some(gi) = view.renderer.gi() {
                self.stats = gi.stats()?;
            }
        }
        let input = match (&mut self.state, window) {
            (Some(state), Some(window)) => state.take_egui_input(window),
            _ => egui::RawInput {
                screen_rect: Some(egui::Rect::from_min_size(
                    egui::Pos2::ZERO,
                    egui::vec2(extent.width as f32, extent.height as f32),
                )),
                ..Default::default()
            },
        };
        let mut requests = Vec::new();
        let shown = Shown {
            frame_ms: &self.frame_ms,
            stats: &self.stats,
            message: self.message.as_deref(),
            building: self.building,
        };
        let mut view = view;
        let output = self.egui.run_ui(input, |ui| {
            egui::Panel::left("voxcone settings")
                .resizable(false)
                .exact_size(300.0)
                .show(ui, |ui| {
                    egui::ScrollArea::vertical().show(ui, |ui| {
                        contents(ui, &mut view, &shown, &mut requests);
                    });
                });
        });
        if let (Some(state), Some(window)) = (&mut self.state, window) {
            state.handle_platform_output(window, output.platform_output);
        }
        self.pixels_per_point = output.pixels_per_point;
        self.primitives = self.egui.tessellate(output.shapes, output.pixels_per_point);
        let delta = output.textures_delta;
        if !delta.set.is_empty() || !self.to_free.is_empty() {
            // Uploads and frees wait for every frame in flight: a texture being drawn
            // is not overwritten (egui changes its font atlas only when new glyphs
            // appear).
            view.renderer.finish()?;
            // The upload's own barriers order nothing before it, so the wait must be one
            // the synchronization validation sees as well (it does not follow the host's
            // wait on the frames' timeline).
            unsafe { self.ctx.device.queue_wait_idle(self.ctx.queue) }?;
            for id in std::mem::take(&mut self.to_free) {
                self.painter
                    .free_texture(id)
                    .map_err(|e| anyhow!("freeing the panel's textures: {e}"))?;
            }
            for (id, images) in &delta.set {
                for image in images {
                    self.painter
                        .set_texture(self.ctx.queue, self.command_pool, *id, image)
                        .map_err(|e| anyhow!("uploading the panel's textures: {e}"))?;
                }
            }
        }
        self.to_free.extend(delta.free.iter().copied());
        Ok(requests)
    }

    /// Records the panel into the current dynamic rendering of `extent`.
    pub fn record(&mut self, cmd: vk::CommandBuffer, extent: vk::Extent2D) -> Result<()> {
        self.painter
            .cmd_draw(cmd, extent, self.pixels_per_point, &self.primitives)
            .map_err(|e| anyhow!("drawing the panel: {e}"))
    }

    /// Whether this frame draws anything.
    pub fn drawn(&self) -> bool {
        self.visible && !self.primitives.is_empty()
    }
}

impl Drop for Panel {
    fn drop(&mut self) {
        unsafe {
            let _ = self.ctx.device.device_wait_idle();
            self.ctx
                .device
                .destroy_command_pool(self.command_pool, None);
        }
    }
}

/// What the panel shows beside the renderer's state.
struct Shown<'a> {
    frame_ms: &'a VecDeque<f32>,
    stats: &'a [(String, f64)],
    message: Option<&'a str>,
    building: bool,
}

const TECHNIQUES: [(GiMode, &str); 5] = [
    (GiMode::Off, "off"),
    (GiMode::Dense, "dense"),
    (GiMode::Octree, "octree"),
    (GiMode::Path, "path"),
    (GiMode::Probes, "probes"),
];

fn contents(ui: &mut egui::Ui, view: &mut PanelView, shown: &Shown, requests: &mut Vec<Request>) {
    ui.heading("voxcone");
    if let Some(message) = shown.message {
        ui.colored_label(Color32::LIGHT_RED, message);
    }
    if shown.building {
        ui.colored_label(
            Color32::YELLOW,
            "building the renderer… (the terminal shows its progress)",
        );
    }
    let mut rebuild = false;

    ui.label("Technique");
    let mut mode = view.args.gi;
    ui.horizontal(|ui| {
        for (m, label) in TECHNIQUES {
            ui.selectable_value(&mut mode, m, label);
        }
    });
    if mode != view.args.gi {
        switch_technique(view.args, mode);
        rebuild = true;
    }
    rebuild |= technique_settings(ui, view);

    egui::CollapsingHeader::new("Terms")
        .default_open(true)
        .show(ui, |ui| {
            let terms = &mut view.renderer.settings.terms;
            ui.checkbox(&mut terms.direct, "direct light");
            ui.checkbox(&mut terms.indirect_diffuse, "indirect diffuse");
            ui.checkbox(&mut terms.indirect_specular, "indirect specular");
            ui.checkbox(&mut terms.transmission, "transmission");
            ui.checkbox(&mut terms.ambient_occlusion, "ambient occlusion");
            ui.checkbox(&mut terms.emission, "emission");
        });

    let views = view.renderer.debug_views();
    if !views.is_empty() {
        egui::CollapsingHeader::new("Debug view").show(ui, |ui| {
            let settings = &mut view.renderer.settings;
            egui::ComboBox::from_id_salt("debug view")
                .selected_text(format!("{:?}", settings.debug_view))
                .show_ui(ui, |ui| {
                    ui.selectable_value(&mut settings.debug_view, DebugView::None, "None");
                    for &v in views {
                        ui.selectable_value(&mut settings.debug_view, v, format!("{v:?}"));
                    }
                });
            let levels = view.renderer.gi().map_or(0, |t| t.debug_levels());
            ui.add(
                egui::Slider::new(&mut view.renderer.settings.debug_level, 0..=levels)
                    .text("level"),
            );
        });
    }

    rebuild |= lights(ui, view);

    egui::CollapsingHeader::new("Camera and display").show(ui, |ui| {
        ui.add(
            egui::Slider::new(view.speed, 0.05..=10.0)
                .logarithmic(true)
                .text("speed"),
        );
        ui.add(
            egui::Slider::new(&mut view.renderer.camera.fov_y_deg, 10.0..=120.0)
                .text("field of view (deg)"),
        );
        let settings = &mut view.renderer.settings;
        ui.add(egui::Slider::new(&mut settings.exposure_ev, -8.0..=8.0).text("exposure (EV)"));
        ui.horizontal(|ui| {
            ui.label("tonemap");
            ui.selectable_value(&mut settings.tonemap, Tonemap::Clamp, "clamp");
            ui.selectable_value(&mut settings.tonemap, Tonemap::Aces, "ACES");
        });
    });

    egui::CollapsingHeader::new("GPU times")
        .default_open(true)
        .show(ui, |ui| {
            let timings = &view.renderer.timings;
            let total: f64 = timings.iter().map(|(_, ms)| ms).sum();
            let largest = timings.iter().map(|(_, ms)| *ms).fold(1e-6, f64::max);
            for (name, ms) in timings {
                ui.add(
                    egui::ProgressBar::new((ms / largest) as f32)
                        .text(format!("{name} {ms:.2} ms")),
                );
            }
            ui.label(format!("GPU total {total:.2} ms"));
            frame_graph(ui, shown.frame_ms);
        });

    egui::CollapsingHeader::new("Memory and stats").show(ui, |ui| {
        let mib = |b: u64| b as f64 / (1024.0 * 1024.0);
        ui.label(format!(
            "textures {:.1} MiB",
            mib(view.renderer.texture_bytes())
        ));
        for (name, bytes) in view.renderer.gi_memory_bytes() {
            ui.label(format!("{name} {:.1} MiB", mib(bytes)));
        }
        for (name, value) in shown.stats {
            ui.label(format!("{name} {value}"));
        }
    });

    if ui.button("Screenshot").clicked() {
        requests.push(Request::Screenshot);
    }
    if rebuild {
        requests.push(Request::Rebuild);
    }
}

/// Leaves the options of other techniques out of `args`, which would be refused with
/// `mode` (as on the command line), and selects `mode`.
fn switch_technique(args: &mut CommonArgs, mode: GiMode) {
    args.gi = mode;
    match mode {
        GiMode::Dense => args.vct.octree_depth = None,
        GiMode::Octree => args.vct.directional_filter = DirectionalFilter::Pairs,
        GiMode::Off | GiMode::Path | GiMode::Probes => args.vct = VctArgs::default(),
    }
    if mode != GiMode::Path {
        args.path = PathArgs::default();
    }
    if mode != GiMode::Probes {
        args.probes = ProbeArgs::default();
    }
    args.debug_view = DebugView::None;
}

/// The technique's own settings; true when one changed that needs a rebuild. A slider
/// asks for it when it is let go, not at every step of a drag.
fn technique_settings(ui: &mut egui::Ui, view: &mut PanelView) -> bool {
    let mut rebuild = false;
    let mut settle = |response: egui::Response| {
        rebuild |= response.drag_stopped() || (response.changed() && !response.dragged());
    };
    match &view.renderer.settings.gi {
        GiSettings::ConeTracing(vct) => {
            let args = &mut view.args.vct;
            let mut cones = vct.cones.diffuse_cones;
            let mut aperture = vct.cones.diffuse_aperture_deg;
            let mut bounces = vct.cones.bounces;
            let mut step = vct.cones.step_factor;
            let mut bounce_step = vct.cones.bounce_step_factor;
            let mut shadow_step = vct.cones.shadow_step_factor;
            let mut shadow_aperture = vct.cones.shadow_aperture_deg;
            let mut ao_distance = vct.cones.ao_distance_voxels;
            let mut scale = vct.cones.indirect_scale.unwrap_or(0);
            let mut shadow_cones = vct.shadow_cones;
            let octree = view.args.gi == GiMode::Octree;
            // What the cone layout in use ignores is shown, not offered (cli.rs refuses it).
            let (snapped_now, lattice_now) =
                (vct.cones.snapped_cones, vct.cones.lattice_cones != 0);
            settle(ui.add_enabled(
                !lattice_now,
                egui::Slider::new(&mut cones, 1..=16).text("diffuse cones"),
            ));
            settle(ui.add(egui::Slider::new(&mut aperture, 10.0..=120.0).text("aperture (deg)")));
            settle(ui.add_enabled(
                !snapped_now,
                egui::Slider::new(&mut step, 0.1..=1.0).text("step factor"),
            ));
            settle(ui.add_enabled(
                !snapped_now,
                egui::Slider::new(&mut bounce_step, 0.1..=1.0).text("bounce step factor"),
            ));
            settle(ui.add(egui::Slider::new(&mut bounces, 1..=MAX_BOUNCES).text("bounces")));
            settle(
                ui.add(egui::Slider::new(&mut scale, 0..=8).text("indirect scale"))
                    .on_hover_text("trace one pixel of each N×N block; 0: by the image height"),
            );
            settle(
                ui.add(
                    egui::Slider::new(&mut ao_distance, 0.5..=16.0).text("AO distance (voxels)"),
                ),
            );
            // The renderer's settings hold the resolution the device and the scene gave.
            let resolution = vct.voxels.count().unwrap_or(CPU_VOXELS);
            if octree {
                let mut depth = resolution.trailing_zeros();
                settle(ui.add(egui::Slider::new(&mut depth, 6..=10).text("octree depth")));
                override_if(&mut args.octree_depth, depth, resolution.trailing_zeros());
            } else {
                let mut voxels = resolution;
                egui::ComboBox::from_label("voxels")
                    .selected_text(format!("{voxels}³"))
                    .show_ui(ui, |ui| {
                        for v in [32, 64, 128, 256] {
                            settle(ui.selectable_value(&mut voxels, v, format!("{v}³")));
                        }
                    });
                override_if(&mut args.voxels, voxels, resolution);
            }
            let mut wide = vct.cones.wide_steps_by_level;
            let mut cosine = vct.cones.cosine_cones;
            let mut snapped = vct.cones.snapped_cones;
            let lattice_was = vct.cones.lattice_cones != 0;
            let mut lattice = lattice_was;
            let mut accumulate = vct.cones.accumulate_bounces;
            let mut full_update = vct.full_update;
            let mut voxelizer = vct.voxelizer;
            let mut rows = matches!(
                vct.store,
                Store::Dense {
                    filter: DirectionalFilter::Rows,
                    ..
                }
            );
            let mut planes = !args.no_plane_occlusion;
            settle(ui.add_enabled(
                !snapped_now,
                egui::Checkbox::new(&mut wide, "wide steps by level"),
            ));
            settle(ui.add_enabled(
                !lattice_now,
                egui::Checkbox::new(&mut cosine, "cosine-weighted cones"),
            ));
            settle(ui.checkbox(&mut snapped, "snapped cones"));
            settle(ui.checkbox(&mut lattice, format!("lattice of {LATTICE_CONES} cones")));
            settle(ui.checkbox(&mut accumulate, "accumulate bounces over frames"));
            settle(ui.checkbox(&mut full_update, "voxelize everything every frame"));
            settle(
                ui.add_enabled(
                    !octree,
                    egui::Checkbox::new(&mut rows, "directional levels by rows"),
                )
                .on_hover_text(
                    "each row of voxels composited whole along the axis, then the rows \
                     averaged (the dense grid only); off: children in pairs",
                ),
            );
            // The planes apply only with the filter by pairs and snapped cones: elsewhere
            // the box is greyed out and keeps its choice for when they apply again.
            let planes_possible = !rows && (snapped || lattice);
            settle(
                ui.add_enabled(
                    planes_possible,
                    egui::Checkbox::new(&mut planes, "plane occlusion"),
                )
                .on_hover_text(
                    "each cell keeps its surface plane, and a plane the cones run beside \
                     counts as the same rays from cell to cell (filtered by pairs, snapped \
                     cones)",
                ),
            );
            egui::ComboBox::from_label("voxelizer")
                .selected_text(format!("{voxelizer:?}"))
                .show_ui(ui, |ui| {
                    for v in [Voxelizer::Auto, Voxelizer::Raster, Voxelizer::Compute] {
                        settle(ui.selectable_value(&mut voxelizer, v, format!("{v:?}")));
                    }
                });
            args.wide_steps_by_level = wide;
            args.cosine_cones = cosine;
            args.snapped_cones = snapped;
            if lattice != lattice_was {
                args.lattice_cones = Some(if lattice { LATTICE_CONES } else { 0 });
            }
            args.no_accumulate = !accumulate;
            args.full_update = full_update;
            args.directional_filter = if rows {
                DirectionalFilter::Rows
            } else {
                DirectionalFilter::Pairs
            };
            if planes_possible {
                args.no_plane_occlusion = !planes;
            }
            if voxelizer != vct.voxelizer {
                args.voxelizer = voxelizer;
            }
            settle(ui.checkbox(&mut shadow_cones, "soft-shadow cones"));
            if shadow_cones {
                settle(
                    ui.add(
                        egui::Slider::new(&mut shadow_aperture, 0.5..=30.0)
                            .text("shadow aperture (deg)"),
                    ),
                );
                settle(ui.add(
                    egui::Slider::new(&mut shadow_step, 0.1..=1.0).text("shadow step factor"),
                ));
            }
            let c = &vct.cones;
            override_if(&mut args.diffuse_cones, cones, c.diffuse_cones);
            override_if(&mut args.diffuse_aperture, aperture, c.diffuse_aperture_deg);
            override_if(&mut args.step_factor, step, c.step_factor);
            override_if(&mut args.bounces, bounces, c.bounces);
            override_if(
                &mut args.bounce_step_factor,
                bounce_step,
                c.bounce_step_factor,
            );
            override_if(
                &mut args.shadow_step_factor,
                shadow_step,
                c.shadow_step_factor,
            );
            override_if(
                &mut args.shadow_aperture,
                shadow_aperture,
                c.shadow_aperture_deg,
            );
            override_if(&mut args.ao_distance, ao_distance, c.ao_distance_voxels);
            if scale != vct.cones.indirect_scale.unwrap_or(0) {
                args.indirect_scale = (scale > 0).then_some(scale);
            }
            args.shadow_cones = shadow_cones;
            args.drop_ignored_by(snapped, lattice);
        }
        GiSettings::Path(path) => {
            let mut spp = path.spp;
            settle(
                ui.add(
                    egui::Slider::new(&mut spp, 1..=4096)
                        .logarithmic(true)
                        .text("samples per pixel"),
                ),
            );
            override_if(&mut view.args.path.spp, spp, path.spp);
            let mut depth = path.max_depth.unwrap_or(0);
            settle(
                ui.add(egui::Slider::new(&mut depth, 0..=32).text("longest path"))
                    .on_hover_text("vertices of the longest path; 0: no limit"),
            );
            if depth != path.max_depth.unwrap_or(0) {
                view.args.path.max_depth = (depth > 0).then_some(depth);
            }
            if let Some(p) = view.renderer.gi().and_then(|t| t.progress()) {
                ui.add(
                    egui::ProgressBar::new(p.done as f32 / p.total.max(1) as f32)
                        .text(format!("{} / {} samples per pixel", p.done, p.total)),
                );
            }
        }
        GiSettings::Probes(probes) => {
            // The frame's settings: a rebuild reads the same bake from its file. The
            // bake's own are the command line's (a change would bake again, minutes).
            let args = &mut view.args.probes;
            let mut bounces = probes.bounces;
            settle(ui.add(egui::Slider::new(&mut bounces, 1..=64).text("first frame's bounces")));
            override_if(&mut args.probe_bounces, bounces, probes.bounces);
            let mut lod = probes.lod;
            settle(ui.checkbox(&mut lod, "level of detail"));
            if lod != probes.lod {
                args.probe_lod = Some(if lod { Switch::On } else { Switch::Off });
            }
            if let Some(distances) = probes.lod_distances {
                let mut d = distances;
                ui.horizontal(|ui| {
                    for (i, v) in d.iter_mut().enumerate() {
                        settle(
                            ui.add(egui::DragValue::new(v).speed(0.1).range(0.01..=1e6))
                                .on_hover_text(format!("where level {} begins", i + 1)),
                        );
                    }
                    ui.label("level distances");
                });
                if d != distances {
                    args.lod_distances = Some(d.to_vec());
                }
            } else {
                ui.label("levels from 16, 32 and 64 probe radii (--lod-distances)");
            }
        }
        GiSettings::Off => {}
    }
    rebuild
}

/// Sets the command-line option `slot` to `new` where it differs from the value in use,
/// `old`; an option left unset keeps following the scene file and the defaults.
fn override_if<T: PartialEq>(slot: &mut Option<T>, new: T, old: T) {
    if new != old {
        *slot = Some(new);
    }
}

/// The lights, edited live; adding or removing one asks for a rebuild (the shadow atlas
/// is laid out for the scene's lights).
fn lights(ui: &mut egui::Ui, view: &mut PanelView) -> bool {
    let mut rebuild = false;
    let bounds = view.renderer.scene.bounds(0.0);
    let size = bounds.diagonal().max(1e-6);
    egui::CollapsingHeader::new("Lights").show(ui, |ui| {
        let lights = &mut view.renderer.scene.lights;
        let mut remove = None;
        for (i, light) in lights.iter_mut().enumerate() {
            ui.push_id(i, |ui| {
                ui.horizontal(|ui| {
                    ui.label(format!("{i}:"));
                    let before = kind_name(&light.kind);
                    let mut kind = before;
                    egui::ComboBox::from_id_salt("kind")
                        .selected_text(kind)
                        .show_ui(ui, |ui| {
                            for k in ["point", "spot", "directional"] {
                                ui.selectable_value(&mut kind, k, k);
                            }
                        });
                    if kind != before {
                        light.kind = kind_named(kind, light.kind);
                        rebuild = true;
                    }
                    if ui.small_button("remove").clicked() {
                        remove = Some(i);
                    }
                });
                if !matches!(light.kind, LightKind::Directional { .. }) {
                    ui.horizontal(|ui| {
                        for c in 0..3 {
                            ui.add(
                                egui::DragValue::new(&mut light.position[c]).speed(size * 0.005),
                            );
                        }
                    });
                }
                direction_and_cone(ui, &mut light.kind);
                colour_and_intensity(ui, light);
            });
        }
        if let Some(i) = remove {
            lights.remove(i);
            rebuild = true;
        }
        if ui.button("add point light").clicked() {
            lights.push(Light {
                kind: LightKind::Point,
                position: bounds.center(),
                intensity: Vec3::splat(0.1 * size * size),
                orbit: None,
            });
            rebuild = true;
        }
    });
    rebuild
}

fn kind_name(kind: &LightKind) -> &'static str {
    match kind {
        LightKind::Point => "point",
        LightKind::Spot { .. } => "spot",
        LightKind::Directional { .. } => "directional",
    }
}

/// The light kind `name`, keeping the direction of `old` where it has one (a new one
/// points down); a new spot's cone is 20 to 30 degrees.
fn kind_named(name: &str, old: LightKind) -> LightKind {
    let direction = match old {
        LightKind::Spot { direction, .. } | LightKind::Directional { direction } => direction,
        LightKind::Point => Vec3::NEG_Y,
    };
    match name {
        "spot" => LightKind::Spot {
            direction,
            inner_deg: 20.0,
            outer_deg: 30.0,
        },
        "directional" => LightKind::Directional { direction },
        _ => LightKind::Point,
    }
}

/// A spot's or sun's direction (kept unit length) and a spot's cone, edited live.
fn direction_and_cone(ui: &mut egui::Ui, kind: &mut LightKind) {
    let (direction, cone) = match kind {
        LightKind::Point => return,
        LightKind::Spot {
            direction,
            inner_deg,
            outer_deg,
        } => (direction, Some((inner_deg, outer_deg))),
        LightKind::Directional { direction } => (direction, None),
    };
    let mut d = *direction;
    ui.horizontal(|ui| {
        ui.label("direction");
        for c in 0..3 {
            ui.add(
                egui::DragValue::new(&mut d[c])
                    .speed(0.01)
                    .range(-1.0..=1.0),
            );
        }
    });
    if d.length_squared() > 1e-6 {
        *direction = d.normalize();
    }
    if let Some((inner, outer)) = cone {
        ui.add(egui::Slider::new(outer, 1.0..=89.0).text("outer (deg)"));
        let top = *outer;
        ui.add(egui::Slider::new(inner, 0.0..=top).text("inner (deg)"));
    }
}

/// A light's colour (its intensity over the largest channel) and that largest channel.
fn colour_and_intensity(ui: &mut egui::Ui, light: &mut Light) {
    let strength = light.intensity.max_element();
    let mut colour = if strength > 0.0 {
        (light.intensity / strength).to_array()
    } else {
        [1.0; 3]
    };
    let mut value = strength;
    ui.horizontal(|ui| {
        ui.color_edit_button_rgb(&mut colour);
        ui.add(
            egui::DragValue::new(&mut value)
                .speed(strength.max(1e-3) * 0.01)
                .range(0.0..=f32::MAX),
        );
        ui.label(if matches!(light.kind, LightKind::Directional { .. }) {
            "W/m²"
        } else {
            "W/sr"
        });
    });
    light.intensity = Vec3::from(colour) * value;
}

/// The last frames' times as a line, with the largest as its scale.
fn frame_graph(ui: &mut egui::Ui, frame_ms: &VecDeque<f32>) {
    let largest = frame_ms.iter().copied().fold(1e-3, f32::max);
    ui.label(format!(
        "frame time, last {} frames (top {largest:.1} ms)",
        frame_ms.len()
    ));
    let (response, painter) =
        ui.allocate_painter(egui::vec2(ui.available_width(), 60.0), egui::Sense::hover());
    let rect = response.rect;
    painter.rect_filled(rect, 2.0, Color32::from_gray(30));
    let points: Vec<egui::Pos2> = frame_ms
        .iter()
        .enumerate()
        .map(|(i, &ms)| {
            egui::pos2(
                rect.left() + rect.width() * i as f32 / (GRAPH_FRAMES - 1) as f32,
                rect.bottom() - rect.height() * ms / largest,
            )
        })
        .collect();
    painter.add(egui::Shape::line(
        points,
        egui::Stroke::new(1.0, Color32::LIGHT_GREEN),
    ));
}
