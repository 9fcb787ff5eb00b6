//! `voxcone view`: a window with the live renderer.
//!
//! Controls: drag with the left mouse button to look around, W/A/S/D to move, Q/E to
//! go down/up, Shift to move faster; arrow keys move the first light in X/Z and
//! PageUp/PageDown in Y; Escape quits. With a GI technique: G turns the GI off and on;
//! 1 to 6 switch the terms (direct, indirect diffuse, indirect specular, transmission,
//! ambient occlusion, emission); V cycles the debug views and [ / ] pick the views' mip
//! level; the technique's own switches have their keys too (the cone tracer's C: shadow
//! maps or soft-shadow cones). F1 shows and hides the settings panel (`super::ui`),
//! which `--no-ui` starts hidden.

use std::collections::HashSet;
use std::ffi::CStr;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{anyhow, Context as _, Result};
use ash::vk;
use glam::{Quat, Vec3};
use raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Window, WindowId};

use super::ui::{Panel, PanelView, Request};
use super::{check_validation, create_context, load_scene};
use crate::cli::{CommonArgs, ViewArgs};
use crate::gi::vct::Quality;
use crate::renderer::{OutputTarget, Renderer};
use crate::vk::{copy_image_to_buffer, Acquired, Buffer, Context, ImageUse, Swapchain};

/// Everything that exists while the window is open.
struct Viewer {
    renderer: Renderer,
    swapchain: Swapchain,
    /// One per frame slot: signalled when the slot's swapchain image is acquired.
    acquired: Vec<vk::Semaphore>,
    window: Arc<Window>,
    ctx: Arc<Context>,
    needs_resize: bool,
    /// Scene extent used to scale camera and light speed.
    scene_size: f32,
    /// Swapchain recreations and frames skipped with nothing to present to (said at
    /// exit: the resize-storm test reads them).
    recreations: u64,
    hidden_frames: u64,
    panel: Panel,
    /// The command line as the panel edits it: a rebuild makes the renderer from it.
    args: CommonArgs,
    /// Camera speed multiplier (the panel's).
    speed: f32,
    /// Screenshots taken with the panel's button.
    screenshots: u32,
}

struct App {
    args: ViewArgs,
    viewer: Option<Viewer>,
    error: Option<anyhow::Error>,
    frames: u64,
    start: Instant,
    last_tick: Instant,
    last_title: Instant,
    keys: HashSet<KeyCode>,
    dragging: bool,
    cursor: Option<(f64, f64)>,
}

pub fn run(args: ViewArgs) -> Result<()> {
    let event_loop = EventLoop::new().map_err(|e| {
        anyhow!("cannot open a window ({e}); is a display available (DISPLAY/WAYLAND_DISPLAY)? `voxcone render` works without one")
    })?;
    event_loop.set_control_flow(ControlFlow::Poll);
    let mut app = App {
        args,
        viewer: None,
        error: None,
        frames: 0,
        start: Instant::now(),
        last_tick: Instant::now(),
        last_title: Instant::now(),
        keys: HashSet::new(),
        dragging: false,
        cursor: None,
    };
    event_loop.run_app(&mut app).context("window event loop")?;
    if let Some(error) = app.error.take() {
        return Err(error);
    }
    if let Some(viewer) = app.viewer.take() {
        log::info!(
            "viewer closed after {} frames ({:.1} ms per frame): {} swapchain recreations, {} \
             frames with nothing to present to",
            app.frames,
            app.start.elapsed().as_secs_f64() * 1e3 / app.frames.max(1) as f64,
            viewer.recreations,
            viewer.hidden_frames
        );
        let ctx = viewer.ctx.clone();
        drop(viewer);
        check_validation(&ctx)?;
    }
    Ok(())
}

impl Viewer {
    fn new(args: &ViewArgs, event_loop: &ActiveEventLoop) -> Result<Self> {
        let (width, height) = args.size;
        let attributes = Window::default_attributes()
            .with_title("voxcone")
            .with_inner_size(winit::dpi::PhysicalSize::new(width, height));
        let window = Arc::new(
            event_loop
                .create_window(attributes)
                .context("creating the window")?,
        );
        let display = window.display_handle().context("display handle")?.as_raw();
        let extensions = ash_window::enumerate_required_extensions(display)
            .context("this window system has no Vulkan surface support")?
            .iter()
            // SAFETY: ash-window returns pointers to static, NUL-terminated names.
            .map(|&name| unsafe { CStr::from_ptr(name) })
            .collect();
        let ctx = create_context(&args.common, extensions)?;
        let surface = unsafe {
            ash_window::create_surface(
                &ctx.entry,
                &ctx.instance,
                display,
                window.window_handle().context("window handle")?.as_raw(),
                None,
            )
        }
        .context("creating the window surface")?;
        let size = window.inner_size();
        let extent = vk::Extent2D {
            width: size.width.max(1),
            height: size.height.max(1),
        };
        let swapchain = Swapchain::new(&ctx, surface, extent)?;
        let scene = load_scene(&args.common)?;
        let settings = args.common.render_settings(&scene.gi, Quality::Fast)?;
        let bounds = scene.bounds(0.0);
        let diagonal = (bounds.max - bounds.min).length();
        // Camera speed follows the scene's units; a scene of one point moves by units.
        let scene_size = if diagonal > 0.0 { diagonal } else { 1.0 };
        let renderer = Renderer::new(&ctx, scene, settings, swapchain.extent, swapchain.format)?;
        let mut panel = Panel::new(&ctx, Some(&window), swapchain.format)?;
        panel.visible = !args.no_ui;
        let acquired = (0..2)
            .map(|_| unsafe {
                ctx.device
                    .create_semaphore(&vk::SemaphoreCreateInfo::default(), None)
            })
            .collect::<Result<_, _>>()?;
        Ok(Self {
            renderer,
            swapchain,
            acquired,
            window,
            ctx,
            needs_resize: false,
            scene_size,
            recreations: 0,
            hidden_frames: 0,
            panel,
            args: args.common.clone(),
            speed: 1.0,
            screenshots: 0,
        })
    }

    /// Builds the renderer again from the panel's edited command line, keeping the
    /// scene as it is now (lights moved or added), the camera and what the panel changes
    /// live (terms, exposure, tonemap, debug view and level where the new technique offers
    /// the view). A setting
    /// the command line would refuse is reported in the panel and changes nothing.
    fn rebuild(&mut self) -> Result<()> {
        let settings = match self
            .args
            .render_settings(&self.renderer.scene.gi, Quality::Fast)
        {
            Ok(settings) => settings,
            Err(e) => {
                self.panel.message = Some(format!("{e:#}"));
                return Ok(());
            }
        };
        log::info!("rebuilding the renderer for the panel's settings");
        self.renderer.finish()?;
        let camera = self.renderer.camera.clone();
        let live = &self.renderer.settings;
        let (terms, exposure_ev, tonemap) = (live.terms, live.exposure_ev, live.tonemap);
        let (debug_view, debug_level) = (live.debug_view, live.debug_level);
        match Renderer::new(
            &self.ctx,
            self.renderer.scene.clone(),
            settings,
            self.swapchain.extent,
            self.swapchain.format,
        ) {
            Ok(mut renderer) => {
                renderer.camera = camera;
                let offered = renderer.debug_views().contains(&debug_view);
                let settings = &mut renderer.settings;
                settings.terms = terms;
                settings.exposure_ev = exposure_ev;
                settings.tonemap = tonemap;
                if offered {
                    settings.debug_view = debug_view;
                    settings.debug_level = debug_level;
                }
                self.renderer = renderer;
                self.panel.message = None;
            }
            Err(e) => self.panel.message = Some(format!("{e:#}")),
        }
        Ok(())
    }

    fn resize(&mut self) -> Result<()> {
        let size = self.window.inner_size();
        self.renderer.finish()?;
        self.swapchain.recreate(vk::Extent2D {
            width: size.width.max(1),
            height: size.height.max(1),
        })?;
        self.renderer.resize(self.swapchain.extent)?;
        self.needs_resize = false;
        self.recreations += 1;
        Ok(())
    }

    /// Renders and presents one frame; with `screenshot`, also saves it as a PNG.
    fn draw(&mut self, time_s: f32, screenshot: Option<&PathBuf>) -> Result<()> {
        let size = self.window.inner_size();
        if size.width == 0 || size.height == 0 {
            // Minimized: nothing to present to.
            self.hidden_frames += 1;
            return Ok(());
        }
        if self.needs_resize
            || size.width != self.swapchain.extent.width
            || size.height != self.swapchain.extent.height
        {
            self.resize()?;
        }
        let frame = self.renderer.begin_frame()?;
        let acquired = self.acquired[frame.slot];
        let index = match self.swapchain.acquire(acquired)? {
            Acquired::Image(index, suboptimal) => {
                self.needs_resize |= suboptimal;
                index
            }
            Acquired::OutOfDate => {
                // Nothing was acquired: submit the empty frame to keep the timeline going.
                self.needs_resize = true;
                return self.renderer.submit(frame, None, None);
            }
        };
        let readback = screenshot.filter(|_| self.swapchain.readable);
        let extent = self.swapchain.extent;
        let presented = if readback.is_some() {
            ImageUse::TRANSFER_SRC
        } else {
            ImageUse::PRESENT
        };
        let overlay = self.panel.drawn();
        let target = OutputTarget {
            image: self.swapchain.images[index as usize],
            view: self.swapchain.views[index as usize],
            extent,
            before: ImageUse {
                layout: vk::ImageLayout::UNDEFINED,
                stage: vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
                access: vk::AccessFlags2::NONE,
            },
            after: if overlay {
                ImageUse::COLOR_ATTACHMENT
            } else {
                presented
            },
        };
        self.renderer.record_frame(&frame, time_s, &target)?;
        if overlay {
            let panel = &mut self.panel;
            self.renderer
                .record_overlay(&frame, &target, "ui", presented, |cmd| {
                    panel.record(cmd, extent)
                })?;
        }
        let buffer = match readback {
            Some(_) => {
                let buffer = Buffer::new(
                    &self.ctx,
                    "screenshot",
                    u64::from(extent.width) * u64::from(extent.height) * 4,
                    vk::BufferUsageFlags::TRANSFER_DST,
                    gpu_allocator::MemoryLocation::GpuToCpu,
                )?;
                // A new buffer may reuse the memory of an earlier screenshot's, whose copy
                // the host read: order this copy after that one.
                crate::vk::stage_barrier(
                    &self.ctx,
                    frame.cmd,
                    vk::PipelineStageFlags2::COPY,
                    vk::PipelineStageFlags2::COPY,
                );
                copy_image_to_buffer(&self.ctx, frame.cmd, target.image, extent, buffer.raw);
                crate::vk::image_barrier(
                    &self.ctx,
                    frame.cmd,
                    target.image,
                    crate::vk::COLOR_TARGET_RANGE,
                    ImageUse::TRANSFER_SRC,
                    ImageUse::PRESENT,
                );
                Some(buffer)
            }
            None => None,
        };
        self.renderer.submit(
            frame,
            Some((acquired, vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT)),
            Some(self.swapchain.rendered[index as usize]),
        )?;
        if !self.swapchain.present(index)? {
            self.needs_resize = true;
        }
        if let (Some(path), Some(buffer)) = (readback, buffer) {
            self.renderer.finish()?;
            let mut pixels = buffer.mapped().to_vec();
            if self.swapchain.format == vk::Format::B8G8R8A8_SRGB {
                pixels.chunks_exact_mut(4).for_each(|p| p.swap(0, 2));
            }
            crate::imageio::write_png(path, extent.width, extent.height, &pixels)?;
            println!("screenshot: {}", path.display());
            if let Some(light) = self.renderer.scene.lights.first() {
                println!("first light at {}", light.position);
            }
        }
        Ok(())
    }

    fn update_controls(&mut self, keys: &HashSet<KeyCode>, dt: f32) {
        let camera = &mut self.renderer.camera;
        let forward = (camera.target - camera.position).normalize_or_zero();
        let right = forward.cross(camera.up).normalize_or_zero();
        let speed = self.scene_size
            * 0.25
            * self.speed
            * if keys.contains(&KeyCode::ShiftLeft) {
                4.0
            } else {
                1.0
            };
        let mut motion = Vec3::ZERO;
        for (key, direction) in [
            (KeyCode::KeyW, forward),
            (KeyCode::KeyS, -forward),
            (KeyCode::KeyD, right),
            (KeyCode::KeyA, -right),
            (KeyCode::KeyE, camera.up),
            (KeyCode::KeyQ, -camera.up),
        ] {
            if keys.contains(&key) {
                motion += direction;
            }
        }
        let step = motion * speed * dt;
        camera.position += step;
        camera.target += step;

        let mut light_motion = Vec3::ZERO;
        for (key, direction) in [
            (KeyCode::ArrowLeft, Vec3::NEG_X),
            (KeyCode::ArrowRight, Vec3::X),
            (KeyCode::ArrowUp, Vec3::NEG_Z),
            (KeyCode::ArrowDown, Vec3::Z),
            (KeyCode::PageUp, Vec3::Y),
            (KeyCode::PageDown, Vec3::NEG_Y),
        ] {
            if keys.contains(&key) {
                light_motion += direction;
            }
        }
        if let Some(light) = self.renderer.scene.lights.first_mut() {
            light.position += light_motion * self.scene_size * 0.15 * dt;
        }
    }

    /// Handles a key that switches something; returns what it did.
    fn switch(&mut self, code: KeyCode) -> Option<String> {
        let renderer = &mut self.renderer;
        if code == KeyCode::KeyG {
            if renderer.gi().is_none() {
                return Some(
                    "no indirect light: start with --gi dense or --gi octree to have it".into(),
                );
            }
            let on = renderer.toggle_indirect();
            return Some(format!("indirect light {}", if on { "on" } else { "off" }));
        }
        let views = renderer.debug_views();
        let levels = renderer.gi()?.debug_levels();
        let settings = &mut renderer.settings;
        let terms = &mut settings.terms;
        let (name, on) = match code {
            KeyCode::Digit1 => ("direct light", &mut terms.direct),
            KeyCode::Digit2 => ("indirect diffuse light", &mut terms.indirect_diffuse),
            KeyCode::Digit3 => ("indirect specular light", &mut terms.indirect_specular),
            KeyCode::Digit4 => ("transmission", &mut terms.transmission),
            KeyCode::Digit5 => ("ambient occlusion", &mut terms.ambient_occlusion),
            KeyCode::Digit6 => ("emission", &mut terms.emission),
            KeyCode::KeyV => {
                let next = views
                    .iter()
                    .position(|v| *v == settings.debug_view)
                    .map_or(0, |i| (i + 1) % views.len());
                settings.debug_view = views[next];
                return Some(format!("debug view: {:?}", settings.debug_view));
            }
            KeyCode::BracketLeft | KeyCode::BracketRight => {
                let level = &mut settings.debug_level;
                *level = if code == KeyCode::BracketLeft {
                    level.saturating_sub(1)
                } else {
                    (*level + 1).min(levels)
                };
                return Some(format!("voxel view mip level {level}"));
            }
            _ => {
                let key = letter(code)?;
                let mut switches = renderer.gi_mut()?.switches();
                let switch = switches.iter_mut().find(|s| s.key == key)?;
                *switch.on = !*switch.on;
                return Some(format!(
                    "{} {}",
                    switch.name,
                    if *switch.on { "on" } else { "off" }
                ));
            }
        };
        *on = !*on;
        Some(format!("{name} {}", if *on { "on" } else { "off" }))
    }

    fn look(&mut self, dx: f32, dy: f32) {
        let camera = &mut self.renderer.camera;
        let forward = camera.target - camera.position;
        let distance = forward.length().max(1e-4);
        let right = forward.cross(camera.up).normalize_or_zero();
        let yaw = Quat::from_axis_angle(camera.up.normalize_or_zero(), -dx * 0.004);
        let pitch = Quat::from_axis_angle(right, -dy * 0.004);
        let turned = (yaw * pitch * forward).normalize_or_zero();
        // Stop short of looking straight up or down, where `right` degenerates.
        if turned.dot(camera.up.normalize_or_zero()).abs() < 0.98 {
            camera.target = camera.position + turned * distance;
        }
    }
}

impl Drop for Viewer {
    fn drop(&mut self) {
        let _ = self.renderer.finish();
        for &semaphore in &self.acquired {
            unsafe { self.ctx.device.destroy_semaphore(semaphore, None) };
        }
    }
}

impl App {
    fn fail(&mut self, event_loop: &ActiveEventLoop, error: anyhow::Error) {
        self.error = Some(error);
        event_loop.exit();
    }

    fn redraw(&mut self, event_loop: &ActiveEventLoop) {
        let Some(viewer) = self.viewer.as_mut() else {
            return;
        };
        let now = Instant::now();
        let frame_ms = (now - self.last_tick).as_secs_f32() * 1e3;
        let dt = (frame_ms * 1e-3).min(0.25);
        self.last_tick = now;
        viewer.update_controls(&self.keys, dt);
        if viewer.panel.building {
            // The last frame said the rebuild was coming; it blocks until done.
            viewer.panel.building = false;
            if let Err(e) = viewer.rebuild() {
                return self.fail(event_loop, e);
            }
        }
        let view = PanelView {
            renderer: &mut viewer.renderer,
            args: &mut viewer.args,
            speed: &mut viewer.speed,
        };
        let extent = viewer.swapchain.extent;
        let requests = match viewer
            .panel
            .update(Some(&viewer.window), extent, view, frame_ms)
        {
            Ok(requests) => requests,
            Err(e) => return self.fail(event_loop, e),
        };
        if requests.contains(&Request::Rebuild) {
            viewer.panel.building = true;
        }
        let last = self.args.frames.is_some_and(|n| self.frames + 1 >= n);
        let button = requests.contains(&Request::Screenshot).then(|| {
            viewer.screenshots += 1;
            PathBuf::from(format!("voxcone-screenshot-{}.png", viewer.screenshots))
        });
        let screenshot = if last {
            self.args.screenshot.clone()
        } else {
            button
        };
        let time_s = (now - self.start).as_secs_f32() + self.args.common.time;
        if let Err(e) = viewer.draw(time_s, screenshot.as_ref()) {
            self.fail(event_loop, e);
            return;
        }
        self.frames += 1;
        if let (Some((w, h)), Some(n)) = (self.args.resize_to, self.args.frames) {
            if self.frames == n / 2 {
                log::info!("resizing the window to {w}x{h}");
                // The new size arrives as a Resized event, or is applied at once.
                let _ = viewer
                    .window
                    .request_inner_size(winit::dpi::PhysicalSize::new(w, h));
            }
        }
        if now.duration_since(self.last_title).as_secs_f32() > 0.5 {
            self.last_title = now;
            let passes: Vec<String> = viewer
                .renderer
                .timings
                .iter()
                .map(|(name, ms)| format!("{name} {ms:.1}"))
                .collect();
            let samples = viewer
                .renderer
                .gi()
                .and_then(|t| t.progress())
                .map_or_else(String::new, |p| {
                    format!(", {}/{} samples per pixel", p.done, p.total)
                });
            viewer.window.set_title(&format!(
                "voxcone, {:.1} ms/frame dt{samples}, GPU ms: {}",
                dt * 1e3,
                passes.join(" ")
            ));
        }
        if last {
            if let Some(p) = viewer.renderer.gi().and_then(|t| t.progress()) {
                log::info!(
                    "the last frame showed {} of {} samples per pixel",
                    p.done,
                    p.total
                );
            }
            event_loop.exit();
        }
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.viewer.is_none() {
            match Viewer::new(&self.args, event_loop) {
                Ok(viewer) => {
                    self.start = Instant::now();
                    self.last_tick = self.start;
                    self.viewer = Some(viewer);
                }
                Err(e) => self.fail(event_loop, e),
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        // The panel sees every event first; what it uses (a click on it, typing in it)
        // does not reach the viewer's controls.
        let used = self
            .viewer
            .as_mut()
            .is_some_and(|v| v.panel.on_event(&v.window, &event));
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(_) => {
                if let Some(viewer) = self.viewer.as_mut() {
                    viewer.needs_resize = true;
                }
            }
            WindowEvent::KeyboardInput { event, .. } => {
                if let PhysicalKey::Code(code) = event.physical_key {
                    match event.state {
                        ElementState::Pressed if used && code != KeyCode::Escape => {}
                        ElementState::Pressed => {
                            if code == KeyCode::Escape {
                                event_loop.exit();
                            } else if code == KeyCode::F1 && !event.repeat {
                                if let Some(viewer) = self.viewer.as_mut() {
                                    viewer.panel.visible = !viewer.panel.visible;
                                }
                            } else if !event.repeat {
                                if let Some(message) =
                                    self.viewer.as_mut().and_then(|v| v.switch(code))
                                {
                                    log::info!("{message}");
                                }
                            }
                            self.keys.insert(code);
                        }
                        ElementState::Released => {
                            self.keys.remove(&code);
                        }
                    }
                }
            }
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => {
                let over_panel = self
                    .viewer
                    .as_ref()
                    .is_some_and(|v| v.panel.wants_pointer());
                self.dragging = state == ElementState::Pressed && !over_panel && !used;
            }
            WindowEvent::CursorMoved { position, .. } => {
                if let (Some((x, y)), true, Some(viewer)) =
                    (self.cursor, self.dragging, self.viewer.as_mut())
                {
                    viewer.look((position.x - x) as f32, (position.y - y) as f32);
                }
                self.cursor = Some((position.x, position.y));
            }
            WindowEvent::RedrawRequested => self.redraw(event_loop),
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(viewer) = &self.viewer {
            viewer.window.request_redraw();
        }
    }
}

/// The lower-case letter of a letter key (winit names them `KeyA` to `KeyZ`).
fn letter(code: KeyCode) -> Option<char> {
    let name = format!("{code:?}");
    let mut chars = name.strip_prefix("Key")?.chars();
    match (chars.next(), chars.next()) {
        (Some(c), None) => Some(c.to_ascii_lowercase()),
        _ => None,
    }
}
