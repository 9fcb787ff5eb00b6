//! The path-traced reference, `--gi path` (`glsl/gi/path/trace.comp`): ground truth that
//! the tool renders itself, for any scene, view and component (`--max-depth 2`: direct
//! light only; 3: one bounce), in the conventions of the path-traced references.
//!
//! It casts its own camera rays through the scene ray caster ([`crate::ray`]): the frame
//! draws no shadow maps and no G-buffer for it. Each frame adds a bounded number of
//! samples per pixel to a running mean (no submission runs long enough for a GPU
//! watchdog) and shows it; the mean starts again whenever the camera, a light or a mesh
//! moves.

pub mod cli;

use std::sync::Arc;

use anyhow::{bail, Result};
use ash::vk;
use gpu_allocator::MemoryLocation;

use super::{
    DebugView, FrameInputs, GatherOptions, Gathered, Inputs, Preparation, Progress, Screen,
    ScreenRequest, Switch, Technique,
};
use crate::gpu_layout::{self as layout, PathPush, PathUniforms};
use crate::ray::{RayFeatures, SceneRays};
use crate::vk::{
    groups_2d, memory_barrier, to_compute_write, Binding, Buffer, Context, DescriptorSets, Image,
    ImageDesc, Pipeline, SetWriter,
};

/// Russian roulette starts at this path depth, as in the references' integrator.
pub const RR_DEPTH: u32 = 5;

/// Paths a frame traces at most, about: a frame traces as many samples per pixel as keep
/// it near this, at least one.
const PATHS_PER_FRAME: u32 = 1 << 18;

/// Most samples per pixel a frame traces.
const MAX_SAMPLES_PER_FRAME: u32 = 1024;

/// Most samples per pixel one dispatch traces on a CPU driver. Lavapipe ends every loop of
/// an invocation once they have run about 65,535 iterations together (the furnace lost
/// samples past a few hundred paths an invocation), so there each dispatch traces one
/// path per pixel, which fits many times over; a frame then records several.
const CPU_SAMPLES_PER_DISPATCH: u32 = 1;

/// One diffuse cone of the cone tracer's gather, for the path tracer to integrate
/// exactly (`--cone`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConeComponent {
    /// 0: the cone along the normal; 1..=`ring`: the ring's.
    pub index: u32,
    /// Cones in the gather's ring.
    pub ring: u32,
    /// Full aperture, degrees.
    pub aperture_deg: f32,
    /// The rays weighted by their cosine to the normal, as `--cosine-cones` weighs the
    /// gather's cones.
    pub cosine: bool,
}

/// The path tracer's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathSettings {
    /// Samples per pixel to converge to.
    pub spp: u32,
    /// Longest path, in vertices from the camera (2: direct light only); `None` for no
    /// limit (Russian roulette ends the paths).
    pub max_depth: Option<u32>,
    /// Seed of the random sequences: another seed, other noise.
    pub seed: u32,
    /// Cut-outs stop every shadow ray, whatever their coverage: the convention of the
    /// path-traced references, whose Mitsuba integrator ignores its masks in next-event
    /// estimation (camera and bounce rays pass cut-outs with the probability 1 -
    /// coverage either way).
    pub opaque_shadow_cut_outs: bool,
    /// Instead of the image, albedo times the mean radiance within this cone of the cone
    /// tracer's gather at each camera hit (cosine-weighted with `--cosine-cones`): the
    /// exact value of the one cone `--gi dense --cone` traces.
    pub cone: Option<ConeComponent>,
}

impl Default for PathSettings {
    fn default() -> Self {
        Self {
            spp: 256,
            max_depth: None,
            seed: 0,
            opaque_shadow_cut_outs: false,
            cone: None,
        }
    }
}

impl PathSettings {
    /// Checks every setting's range; errors name the command-line option.
    pub fn check(&self) -> Result<()> {
        if self.spp == 0 {
            bail!("--spp must be at least 1: a path-traced image needs a sample per pixel");
        }
        if self.max_depth == Some(0) {
            bail!(
                "--max-depth must be at least 1 (1: emitters seen directly; 2: direct light; \
                 3: one bounce), or left out for no limit"
            );
        }
        Ok(())
    }
}

/// The path tracer.
pub struct PathTracer {
    settings: PathSettings,
    rays: SceneRays,
    pipeline: Pipeline,
    set: vk::DescriptorSet,
    _sets: DescriptorSets,
    _uniforms: Buffer,
    /// The running mean of the samples and their count per pixel (screen-sized).
    mean: Option<Image>,
    /// Rays cast by the last frame that traced samples (host-visible).
    rays_cast: Buffer,
    /// Samples per pixel recorded into the mean so far.
    samples: u32,
    /// Samples a frame adds.
    per_frame: u32,
    /// This frame's dispatches: their shares of the samples.
    dispatches: Vec<PathPush>,
    /// Samples one dispatch traces at most.
    per_dispatch: u32,
    /// What the mean was taken with (camera, lights, moving meshes), to start it again when
    /// that changes.
    view: Option<Vec<u8>>,
    extent: vk::Extent2D,
    ctx: Arc<Context>,
}

impl PathTracer {
    pub fn new(inputs: &Inputs, settings: &PathSettings) -> Result<Self> {
        settings.check()?;
        let ctx = inputs.ctx;
        let rays = SceneRays::new(ctx, inputs.scene, inputs.frames_in_flight)?;
        let compute = vk::ShaderStageFlags::COMPUTE;
        let mut bindings = SceneRays::bindings();
        bindings.extend([
            Binding::new(
                layout::BINDING_PATH_UNIFORMS,
                vk::DescriptorType::UNIFORM_BUFFER,
                compute,
            ),
            Binding::new(
                layout::BINDING_PATH_MEAN,
                vk::DescriptorType::STORAGE_IMAGE,
                compute,
            ),
            Binding::new(
                layout::BINDING_PATH_RAYS,
                vk::DescriptorType::STORAGE_BUFFER,
                compute,
            ),
        ]);
        let sets = DescriptorSets::new(ctx, "path", &bindings, 1)?;
        let set = sets.allocate("path")?;
        let [frame, scene, screen] = inputs.set_layouts;
        log::info!(
            "path tracer compiled for the scene's features: {:?}",
            rays.features
        );
        let pipeline = Pipeline::compute_specialized(
            ctx,
            "path_trace",
            crate::vk::shaders::GI_PATH_TRACE_COMP,
            &[frame, scene, screen, sets.layout],
            std::mem::size_of::<PathPush>() as u32,
            &Self::constants(&rays.features, settings),
        )?;
        let uniforms = PathUniforms {
            max_depth: settings.max_depth.unwrap_or(0),
            rr_depth: RR_DEPTH,
            seed: settings.seed,
            opaque_shadow_cut_outs: u32::from(settings.opaque_shadow_cut_outs),
            cone: settings.cone.map_or(u32::MAX, |c| c.index),
            ring: settings.cone.map_or(0, |c| c.ring),
            cone_cos_half: settings
                .cone
                .map_or(1.0, |c| (c.aperture_deg.to_radians() * 0.5).cos()),
            cone_cosine: settings.cone.map_or(0, |c| u32::from(c.cosine)),
        };
        let uniforms = Buffer::with_data(
            ctx,
            "path uniforms",
            bytemuck::bytes_of(&uniforms),
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?;
        let mut rays_cast = Buffer::new(
            ctx,
            "path rays cast",
            4,
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        rays_cast.write(0, &[0; 4]);
        rays.write_set(set);
        SetWriter::new(ctx, set)
            .buffer(
                layout::BINDING_PATH_UNIFORMS,
                vk::DescriptorType::UNIFORM_BUFFER,
                uniforms.raw,
            )
            .buffer(
                layout::BINDING_PATH_RAYS,
                vk::DescriptorType::STORAGE_BUFFER,
                rays_cast.raw,
            )
            .apply();
        Ok(Self {
            settings: *settings,
            rays,
            pipeline,
            set,
            _sets: sets,
            _uniforms: uniforms,
            mean: None,
            rays_cast,
            samples: 0,
            per_frame: 1,
            dispatches: Vec::new(),
            per_dispatch: if ctx.is_cpu() {
                CPU_SAMPLES_PER_DISPATCH
            } else {
                MAX_SAMPLES_PER_FRAME
            },
            view: None,
            extent: vk::Extent2D::default(),
            ctx: ctx.clone(),
        })
    }

    /// The pipeline's specialization constants: the ray casting's, then the scene's
    /// materials' features and the cone component (`SPEC_PATH_*`).
    fn constants(f: &RayFeatures, settings: &PathSettings) -> [u32; 8] {
        let mut c = [0; 8];
        c[..2].copy_from_slice(&f.ray_constants());
        c[layout::SPEC_PATH_TEXTURES as usize] = u32::from(f.textures);
        c[layout::SPEC_PATH_NORMAL_MAPS as usize] = u32::from(f.normal_maps);
        c[layout::SPEC_PATH_SPECULAR as usize] = u32::from(f.specular);
        c[layout::SPEC_PATH_TRANSMISSION as usize] = u32::from(f.transmission);
        c[layout::SPEC_PATH_EMITTERS as usize] = u32::from(f.emitters);
        c[layout::SPEC_PATH_CONE as usize] = u32::from(settings.cone.is_some());
        c
    }

    /// What the image depends on besides the scene's static meshes: the camera and image
    /// (not the clock), the lights and the moving meshes' transforms.
    fn view_key(frame: &FrameInputs) -> Vec<u8> {
        let u = frame.uniforms;
        let mut key: Vec<u8> = bytemuck::bytes_of(&u.inv_view_proj).to_vec();
        key.extend_from_slice(bytemuck::cast_slice(&u.camera_position[..3]));
        key.extend_from_slice(bytemuck::cast_slice(&u.sky_radiance[..3]));
        key.extend_from_slice(bytemuck::cast_slice(frame.lights));
        let scene = frame.draw.scene;
        for (m, mesh) in scene.meshes.iter().enumerate() {
            if mesh.animation.is_some() {
                let transform = scene.mesh_transform(m, frame.draw.time_s);
                key.extend_from_slice(bytemuck::bytes_of(&transform.to_cols_array()));
            }
        }
        key
    }

    /// Rays the last frame that traced samples cast.
    fn rays_cast(&self) -> u32 {
        bytemuck::pod_read_unaligned(&self.rays_cast.mapped()[..4])
    }
}

impl Technique for PathTracer {
    fn prepare(&mut self, _draw: &crate::scene_gpu::SceneDraw) -> Result<()> {
        Ok(())
    }

    /// A new mean at the new size; the terms of the screen contract are unused.
    fn bind_screen(&mut self, extent: vk::Extent2D) -> Result<ScreenRequest> {
        let mean = Image::new(
            &self.ctx,
            "path mean",
            ImageDesc::d2(
                vk::Format::R32G32B32A32_SFLOAT,
                extent.width,
                extent.height,
                vk::ImageUsageFlags::STORAGE,
            ),
        )?;
        to_compute_write(&self.ctx, "path mean layout", &[&mean])?;
        SetWriter::new(&self.ctx, self.set)
            .storage_image(layout::BINDING_PATH_MEAN, mean.view)
            .apply();
        self.mean = Some(mean);
        self.extent = extent;
        self.samples = 0;
        let pixels = (extent.width * extent.height).max(1);
        let most = if self.ctx.is_cpu() {
            MAX_SAMPLES_PER_FRAME.min(256)
        } else {
            MAX_SAMPLES_PER_FRAME
        };
        self.per_frame = (PATHS_PER_FRAME / pixels).clamp(1, most);
        Ok(ScreenRequest {
            scale: 1,
            plane_tolerance: 1.0,
        })
    }

    /// Takes this frame's share of the samples, the mean started again if the view
    /// changed; rebuilds the moving meshes' BVH.
    fn record_update(
        &mut self,
        cmd: vk::CommandBuffer,
        _timer: &mut crate::vk::GpuTimer,
        frame: &FrameInputs,
    ) -> Result<()> {
        let key = Self::view_key(frame);
        if self.view.as_ref() != Some(&key) {
            self.view = Some(key);
            self.samples = 0;
        }
        let now = self
            .per_frame
            .min(self.settings.spp.saturating_sub(self.samples));
        self.dispatches.clear();
        let mut done = 0;
        while done < now || self.dispatches.is_empty() {
            let share = (now - done).min(self.per_dispatch);
            self.dispatches.push(PathPush {
                samples_done: self.samples + done,
                samples_now: share,
                ..Default::default()
            });
            done += share;
        }
        self.samples += now;
        if now > 0 {
            // Counted afresh (a frame that traces nothing keeps the last count).
            let ctx = &self.ctx;
            crate::vk::stage_barrier(
                ctx,
                cmd,
                vk::PipelineStageFlags2::COMPUTE_SHADER,
                vk::PipelineStageFlags2::ALL_TRANSFER,
            );
            unsafe {
                ctx.device
                    .cmd_fill_buffer(cmd, self.rays_cast.raw, 0, vk::WHOLE_SIZE, 0)
            };
            crate::vk::stage_barrier(
                ctx,
                cmd,
                vk::PipelineStageFlags2::ALL_TRANSFER,
                vk::PipelineStageFlags2::COMPUTE_SHADER,
            );
        }
        let draw = frame.draw;
        self.rays
            .record_moving(cmd, draw.scene, draw.time_s, frame.slot)
    }

    /// Adds this frame's samples to the mean and writes it to the screen radiance.
    fn record_gather(
        &self,
        cmd: vk::CommandBuffer,
        timer: &mut crate::vk::GpuTimer,
        frame_set: vk::DescriptorSet,
        screen: &Screen,
        _options: &GatherOptions,
    ) -> Gathered {
        timer.begin(cmd, "path_trace");
        let sets = [
            (layout::SET_FRAME, frame_set),
            (layout::SET_SCREEN, screen.set()),
            (layout::SET_GI, self.set),
        ];
        // Bound once for all the frame's dispatches: lavapipe (Mesa 22.3) took about 15 ms
        // and 2.5 MB per dispatch that bound the sets again, the memory never returned
        // (the glossy furnace's 16,384 samples on four pixels ran out of 24 GiB).
        self.pipeline.bind(cmd, &sets);
        for push in &self.dispatches {
            // The last dispatch (or frame) wrote the means this one adds to.
            memory_barrier(
                &self.ctx,
                cmd,
                (
                    vk::PipelineStageFlags2::COMPUTE_SHADER,
                    vk::AccessFlags2::SHADER_STORAGE_WRITE,
                ),
                (
                    vk::PipelineStageFlags2::COMPUTE_SHADER,
                    vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::SHADER_STORAGE_WRITE,
                ),
            );
            self.pipeline.push(cmd, vk::ShaderStageFlags::COMPUTE, push);
            self.pipeline
                .dispatch_bound(cmd, groups_2d(self.extent, layout::SCREEN_GROUP_SIZE));
        }
        // The ray count, read by the host once the frame is done.
        memory_barrier(
            &self.ctx,
            cmd,
            (
                vk::PipelineStageFlags2::COMPUTE_SHADER,
                vk::AccessFlags2::SHADER_STORAGE_WRITE,
            ),
            (vk::PipelineStageFlags2::HOST, vk::AccessFlags2::HOST_READ),
        );
        timer.end(cmd);
        Gathered::Screen
    }

    fn restart(&mut self) {
        self.samples = 0;
    }

    /// It shades every pixel itself.
    fn shades_direct(&self) -> bool {
        true
    }

    fn memory_bytes(&self) -> Vec<(&'static str, u64)> {
        let mut bytes = self.rays.memory_bytes();
        bytes.push((
            "path_mean",
            self.mean.as_ref().map_or(0, Image::memory_bytes),
        ));
        bytes
    }

    /// The samples per pixel so far, and the rays the last frame that traced cast
    /// (`bench` divides them by the `path_trace` pass's time).
    fn stats(&self) -> Result<Vec<(String, f64)>> {
        let s = &self.rays.stats;
        Ok(vec![
            ("samples_per_pixel".into(), f64::from(self.samples)),
            ("samples_per_frame".into(), f64::from(self.per_frame)),
            ("rays_per_frame".into(), f64::from(self.rays_cast())),
            ("bvh_triangles".into(), s.triangles as f64),
            ("bvh_nodes".into(), s.nodes as f64),
            ("bvh_depth".into(), f64::from(s.depth)),
            ("bvh_build_ms".into(), s.build_ms),
            ("moving_bvh_triangles".into(), s.moving_triangles as f64),
            ("moving_bvh_build_ms".into(), s.moving_build_ms),
        ])
    }

    fn preparation(&self) -> Option<Preparation> {
        None
    }

    fn debug_views(&self) -> &'static [DebugView] {
        &[DebugView::None]
    }

    fn debug_levels(&self) -> u32 {
        0
    }

    fn switches(&mut self) -> Vec<Switch<'_>> {
        Vec::new()
    }

    fn uses_raster_passes(&self) -> bool {
        false
    }

    fn progress(&self) -> Option<Progress> {
        let left = self.settings.spp.saturating_sub(self.samples);
        Some(Progress {
            done: self.samples,
            total: self.settings.spp,
            frames_left: left.div_ceil(self.per_frame).max(1),
        })
    }
}
