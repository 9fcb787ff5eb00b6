//! The frame: one flat list of passes, in the order data flows through them.
//!
//! shadow maps -> G-buffer -> GI update -> deferred direct lighting -> GI gather ->
//! upsample -> composite (tonemap to output)
//!
//! The GI passes are a technique's ([`crate::gi::Technique`]); the lighting pass does not
//! run when the technique shades the direct light itself, and the upsample does not run
//! when its gather wrote the screen radiance (a debug view).

use std::sync::Arc;

use anyhow::{bail, Result};
use ash::vk;

use crate::frame_data::{self, FrameData};
use crate::gi::{self, DebugView, FrameInputs, GatherOptions, Gathered, Screen, Technique};
use crate::gpu_layout::{self as layout, FrameUniforms, ShadowView};
use crate::passes::composite::CompositePass;
use crate::passes::gbuffer::{GBuffer, GBufferPass};
use crate::passes::lighting::LightingPass;
use crate::passes::shadow::{self, ShadowPass};
use crate::scene::{Camera, Scene};
use crate::scene_gpu::{GpuScene, SceneDraw};
use crate::settings::{RenderSettings, Tonemap};
use crate::vk::{
    compute_to_compute, copy_image_to_buffer, image_barrier, sampler_info, Buffer, Context,
    DescriptorSets, Frame, FrameRing, Image, ImageUse, Sampler, COLOR_TARGET_RANGE,
};

/// Where a frame's composite goes.
#[derive(Clone, Copy, Debug)]
pub struct OutputTarget {
    pub image: vk::Image,
    pub view: vk::ImageView,
    pub extent: vk::Extent2D,
    /// Its state before the frame (layout UNDEFINED: contents are overwritten).
    pub before: ImageUse,
    /// The state to leave it in.
    pub after: ImageUse,
}

/// Screen-sized images, recreated on resize.
struct Targets {
    gbuffer: GBuffer,
    radiance: Image,
}

pub struct Renderer {
    pub scene: Scene,
    pub camera: Camera,
    pub settings: RenderSettings,
    /// GPU milliseconds per pass of the last completed frame.
    pub timings: Vec<(String, f64)>,
    targets: Targets,
    radiance_last_use: ImageUse,
    composite: CompositePass,
    lighting: LightingPass,
    gbuffer_pass: GBufferPass,
    shadow: ShadowPass,
    /// The technique and the screen contract it gathers into (none with `--gi off`).
    gi: Option<(Box<dyn Technique>, Screen)>,
    /// Whether the GI passes run (the viewer's toggle).
    indirect: bool,
    /// Light views and mesh transforms the shadow maps were last rendered with.
    shadow_inputs: Option<Vec<[[f32; 4]; 4]>>,
    frames: Vec<FrameData>,
    /// Owns the frame descriptor sets.
    _frame_sets: DescriptorSets,
    ring: FrameRing,
    gpu: GpuScene,
    nearest_sampler: Sampler,
    /// Referenced by the frame descriptor sets.
    _shadow_sampler: Sampler,
    ctx: Arc<Context>,
}

pub const FRAMES_IN_FLIGHT: usize = 2;

impl Renderer {
    pub fn new(
        ctx: &Arc<Context>,
        scene: Scene,
        settings: RenderSettings,
        extent: vk::Extent2D,
        output_format: vk::Format,
    ) -> Result<Self> {
        let settings = RenderSettings {
            gi: settings.gi.on(ctx, &scene),
            ..settings
        };
        let gpu = GpuScene::new(ctx, &scene, settings.anisotropy_on_cpu || !ctx.is_cpu())?;
        let frame_sets = DescriptorSets::new(
            ctx,
            "frame",
            &frame_data::bindings(),
            FRAMES_IN_FLIGHT as u32,
        )?;
        let set_layouts = [frame_sets.layout, gpu.sets.layout];
        let shadow = ShadowPass::new(
            ctx,
            &scene,
            settings.shadow_resolution,
            settings.opaque_shadow_cut_outs,
            &set_layouts,
        )?;
        let gbuffer_pass = GBufferPass::new(ctx, &set_layouts)?;
        let lighting = LightingPass::new(ctx, set_layouts)?;
        let composite = CompositePass::new(ctx, set_layouts, output_format)?;
        let gi = if matches!(settings.gi, gi::GiSettings::Off) {
            None
        } else {
            let screen = Screen::new(ctx, set_layouts, scene.lights.len() as u32)?;
            let inputs = gi::Inputs {
                ctx,
                scene: &scene,
                gpu: &gpu,
                set_layouts: [set_layouts[0], set_layouts[1], screen.layout()],
                frames_in_flight: FRAMES_IN_FLIGHT,
            };
            gi::create(&inputs, &settings.gi)?.map(|technique| (technique, screen))
        };
        let debug_views = gi.as_ref().map_or(&[][..], |(t, _)| t.debug_views());
        if settings.debug_view != DebugView::None && !debug_views.contains(&settings.debug_view) {
            bail!(
                "the debug view {:?} is not one of this technique's ({:?}): it needs \
                 --gi dense or --gi octree (octree-nodes: --gi octree)",
                settings.debug_view,
                debug_views
            );
        }
        let nearest_sampler = Sampler::new(
            ctx,
            "nearest",
            &sampler_info(vk::Filter::NEAREST, vk::SamplerAddressMode::CLAMP_TO_EDGE),
        )?;
        // Reverse Z (shadow::perspective): lit where the point is no farther from the light
        // than the map's depth; outside a map's coverage reads as lit (border depth 0).
        let shadow_sampler = Sampler::new(
            ctx,
            "shadow compare",
            &sampler_info(vk::Filter::LINEAR, vk::SamplerAddressMode::CLAMP_TO_BORDER)
                .border_color(vk::BorderColor::FLOAT_TRANSPARENT_BLACK)
                .compare_enable(true)
                .compare_op(vk::CompareOp::GREATER_OR_EQUAL),
        )?;
        let frames = (0..FRAMES_IN_FLIGHT)
            .map(|i| FrameData::new(ctx, i, &frame_sets, &scene, &shadow.map, &shadow_sampler))
            .collect::<Result<_>>()?;
        let targets = Self::create_targets(ctx, extent)?;
        let mut renderer = Self {
            camera: scene.camera.clone(),
            scene,
            settings,
            timings: Vec::new(),
            targets,
            radiance_last_use: ImageUse::FRAGMENT_READ,
            composite,
            lighting,
            gbuffer_pass,
            shadow,
            gi,
            indirect: true,
            shadow_inputs: None,
            frames,
            _frame_sets: frame_sets,
            ring: FrameRing::new(ctx, FRAMES_IN_FLIGHT)?,
            gpu,
            nearest_sampler,
            _shadow_sampler: shadow_sampler,
            ctx: ctx.clone(),
        };
        renderer.bind_targets()?;
        if let Some((technique, _)) = &mut renderer.gi {
            let draw = SceneDraw {
                scene: &renderer.scene,
                gpu: &renderer.gpu,
                frame_set: renderer.frames[0].set,
                time_s: 0.0,
            };
            technique.prepare(&draw)?;
        }
        Ok(renderer)
    }

    /// The first frame's descriptor set (set 0), for passes a test records itself.
    #[cfg(test)]
    pub fn first_frame_set(&self) -> vk::DescriptorSet {
        self.frames[0].set
    }

    fn create_targets(ctx: &Arc<Context>, extent: vk::Extent2D) -> Result<Targets> {
        Ok(Targets {
            gbuffer: GBuffer::new(ctx, extent)?,
            radiance: LightingPass::create_output(ctx, extent)?,
        })
    }

    fn bind_targets(&mut self) -> Result<()> {
        let t = &self.targets;
        self.lighting
            .bind_targets(&self.ctx, &t.gbuffer, &t.radiance, self.nearest_sampler.raw);
        self.composite
            .bind_input(&self.ctx, &t.radiance, self.nearest_sampler.raw);
        if let Some((technique, screen)) = &mut self.gi {
            let request = technique.bind_screen(t.gbuffer.extent())?;
            screen.bind(&t.gbuffer, &t.radiance, self.nearest_sampler.raw, request)?;
        }
        Ok(())
    }

    pub fn context(&self) -> &Arc<Context> {
        &self.ctx
    }

    pub fn extent(&self) -> vk::Extent2D {
        self.targets.gbuffer.extent()
    }

    /// The technique, while its passes run (the viewer can pause them).
    fn active_gi(&self) -> Option<&dyn Technique> {
        self.gi
            .as_ref()
            .filter(|_| self.indirect)
            .map(|(technique, _)| &**technique)
    }

    /// Whether this frame's technique shades the direct light itself (soft-shadow cones)
    /// instead of the lighting pass with shadow maps.
    fn gi_shades_direct(&self) -> bool {
        self.active_gi().is_some_and(|t| t.shades_direct())
    }

    /// Turns the indirect light on or off (when the renderer has GI); returns whether it
    /// is on now.
    pub fn toggle_indirect(&mut self) -> bool {
        match &mut self.gi {
            Some((technique, _)) => {
                self.indirect = !self.indirect;
                // What was accumulated before the pause may no longer match the scene.
                technique.restart();
                self.indirect
            }
            None => false,
        }
    }

    /// The GI technique, when there is one.
    pub fn gi(&self) -> Option<&dyn Technique> {
        self.gi.as_ref().map(|(technique, _)| &**technique)
    }

    /// The GI technique, when there is one.
    pub fn gi_mut(&mut self) -> Option<&mut dyn Technique> {
        self.gi.as_mut().map(|(technique, _)| &mut **technique)
    }

    /// The GI technique as the type `T`, when it is one.
    pub fn gi_as<T: Technique>(&self) -> Option<&T> {
        let any: &dyn std::any::Any = self.gi()?;
        any.downcast_ref()
    }

    /// The GI technique as the type `T`, when it is one.
    pub fn gi_as_mut<T: Technique>(&mut self) -> Option<&mut T> {
        let any: &mut dyn std::any::Any = self.gi_mut()?;
        any.downcast_mut()
    }

    /// The debug views of this renderer's technique, in the viewer's cycling order (none
    /// without GI).
    pub fn debug_views(&self) -> &'static [DebugView] {
        self.gi().map_or(&[], |t| t.debug_views())
    }

    /// GPU memory of the technique's resources, by name (empty without GI).
    pub fn gi_memory_bytes(&self) -> Vec<(&'static str, u64)> {
        self.gi().map_or_else(Vec::new, |t| t.memory_bytes())
    }

    /// Bytes of GPU memory held by scene textures.
    pub fn texture_bytes(&self) -> u64 {
        self.gpu.texture_bytes()
    }

    /// Recreates the screen-sized images; waits for frames in flight first.
    pub fn resize(&mut self, extent: vk::Extent2D) -> Result<()> {
        // New images may take the memory of old ones; a device-wide wait orders every
        // earlier access before them (synchronization validation tracks this wait, not a
        // host wait on the timeline).
        self.ctx.wait_idle()?;
        self.targets = Self::create_targets(&self.ctx, extent)?;
        self.radiance_last_use = ImageUse::FRAGMENT_READ;
        self.bind_targets()
    }

    fn frame_uniforms(&self, time_s: f32) -> FrameUniforms {
        let extent = self.extent();
        let aspect = extent.width as f32 / extent.height as f32;
        let view = self.camera.view();
        let proj = self.camera.proj(aspect);
        let view_proj = proj * view;
        let s = &self.settings;
        let mut flags = 0;
        if s.specular {
            flags |= layout::FLAG_SPECULAR;
        }
        if s.tonemap == Tonemap::Aces {
            flags |= layout::FLAG_TONEMAP_ACES;
        }
        let t = &s.terms;
        for (on, flag) in [
            (t.direct, layout::FLAG_DIRECT),
            (t.emission, layout::FLAG_EMISSION),
        ] {
            if on {
                flags |= flag;
            }
        }
        let gi_on = self.active_gi().is_some();
        if gi_on {
            for (on, flag) in [
                (t.indirect_diffuse, layout::FLAG_INDIRECT_DIFFUSE),
                (t.indirect_specular, layout::FLAG_INDIRECT_SPECULAR),
                (
                    t.transmission && self.scene.materials.iter().any(|m| m.dissolve < 1.0),
                    layout::FLAG_TRANSMISSION,
                ),
                (t.ambient_occlusion, layout::FLAG_AO),
                (self.gi_shades_direct(), layout::FLAG_SHADOW_CONES),
            ] {
                if on {
                    flags |= flag;
                }
            }
        }
        let debug_view = if gi_on {
            s.debug_view.code()
        } else {
            layout::DEBUG_NONE
        };
        FrameUniforms {
            view: view.to_cols_array_2d(),
            proj: proj.to_cols_array_2d(),
            view_proj: view_proj.to_cols_array_2d(),
            inv_view_proj: view_proj.inverse().to_cols_array_2d(),
            camera_position: self.camera.position.extend(time_s).to_array(),
            sky_radiance: self.scene.sky.extend(2f32.powf(s.exposure_ev)).to_array(),
            width: extent.width,
            height: extent.height,
            light_count: self.scene.lights.len() as u32,
            flags,
            debug_view,
            debug_level: s.debug_level,
            ..Default::default()
        }
    }

    /// Waits until a frame slot is free and starts its command buffer.
    pub fn begin_frame(&mut self) -> Result<Frame> {
        let frame = self.ring.begin()?;
        // The slot's previous frame has completed (ring.begin waited for it).
        if frame.value > self.ring.frames_in_flight() as u64 {
            self.timings = self.frames[frame.slot].timer.results()?;
        }
        Ok(frame)
    }

    /// Records every pass of the frame at scene time `time_s`, ending in `output`. The
    /// command buffer stays open for the caller (read-backs); then call [`Self::submit`].
    pub fn record_frame(
        &mut self,
        frame: &Frame,
        time_s: f32,
        output: &OutputTarget,
    ) -> Result<()> {
        let ctx = self.ctx.clone();
        let cmd = frame.cmd;
        let uniforms = self.frame_uniforms(time_s);
        let lights = frame_data::gpu_lights(&self.scene, time_s);
        let views: Vec<ShadowView> = shadow::scene_views(&self.scene, time_s, &self.shadow.atlas);
        let shadow_cones = self.gi_shades_direct();
        // The shadow maps and the G-buffer: a technique that casts its own camera rays
        // needs neither.
        let raster = self.active_gi().is_none_or(|t| t.uses_raster_passes());
        let data = &mut self.frames[frame.slot];
        data.uniforms.write(0, bytemuck::bytes_of(&uniforms));
        data.lights.write(0, bytemuck::cast_slice(&lights));
        data.shadow_views.write(0, bytemuck::cast_slice(&views));
        let data = &mut self.frames[frame.slot];
        let draw = SceneDraw {
            scene: &self.scene,
            gpu: &self.gpu,
            frame_set: data.set,
            time_s,
        };
        let timer = &mut data.timer;
        timer.reset(cmd);

        if raster {
            let inputs: Vec<[[f32; 4]; 4]> = views
                .iter()
                .map(|v| v.view_proj)
                .chain(
                    (0..self.scene.meshes.len())
                        .map(|m| self.scene.mesh_transform(m, time_s).to_cols_array_2d()),
                )
                .collect();
            // Soft-shadow cones need no shadow maps (the voxels are lit by a voxel
            // ray-march then); they are rendered once all the same, so that they are valid
            // when the viewer switches back.
            let stale =
                !(self.settings.cache_shadows && self.shadow_inputs.as_ref() == Some(&inputs));
            if self.shadow_inputs.is_none() || (!shadow_cones && stale) {
                timer.begin(cmd, "shadow");
                self.shadow.record(&ctx, cmd, &draw, &views);
                timer.end(cmd);
                self.shadow_inputs = Some(inputs);
            }

            timer.begin(cmd, "gbuffer");
            let normal_maps = self.settings.normal_maps
                && self
                    .scene
                    .materials
                    .iter()
                    .any(|m| m.normal_texture.is_some());
            self.gbuffer_pass
                .record(&ctx, cmd, &self.targets.gbuffer, &draw, normal_maps);
            timer.end(cmd);
        }

        let indirect = self.indirect;
        let gi = self.gi.as_mut().filter(|_| indirect);
        if let Some((technique, _)) = gi {
            let inputs = FrameInputs {
                draw: &draw,
                uniforms: &uniforms,
                slot: frame.slot,
                lights: &lights,
                views: &views,
            };
            technique.record_update(cmd, timer, &inputs)?;
        }

        // When the technique shades the direct light, the upsample shades every pixel.
        if !shadow_cones {
            timer.begin(cmd, "lighting");
            self.lighting.record(
                &ctx,
                cmd,
                data.set,
                &self.targets.radiance,
                self.radiance_last_use,
            );
            timer.end(cmd);
        } else {
            let radiance = &self.targets.radiance;
            image_barrier(
                &ctx,
                cmd,
                radiance.raw,
                radiance.full_range(),
                ImageUse::discard_after(self.radiance_last_use),
                ImageUse::COMPUTE_WRITE,
            );
        }
        if let Some((technique, screen)) = self.gi.as_ref().filter(|_| indirect) {
            let options = GatherOptions {
                debug_view: self.settings.debug_view,
                ambient_occlusion: self.settings.terms.ambient_occlusion
                    || self.settings.debug_view == DebugView::Ao,
            };
            let gathered = technique.record_gather(cmd, timer, data.set, screen, &options);
            if gathered == Gathered::Terms {
                timer.begin(cmd, "upsample");
                compute_to_compute(&ctx, cmd);
                screen.record_upsample(cmd, data.set);
                timer.end(cmd);
            }
        }

        timer.begin(cmd, "composite");
        image_barrier(
            &ctx,
            cmd,
            self.targets.radiance.raw,
            self.targets.radiance.full_range(),
            ImageUse::COMPUTE_WRITE,
            ImageUse::FRAGMENT_READ,
        );
        self.radiance_last_use = ImageUse::FRAGMENT_READ;
        let range = COLOR_TARGET_RANGE;
        image_barrier(
            &ctx,
            cmd,
            output.image,
            range,
            output.before,
            ImageUse::COLOR_ATTACHMENT,
        );
        self.composite
            .record(&ctx, cmd, data.set, output.view, output.extent);
        image_barrier(
            &ctx,
            cmd,
            output.image,
            range,
            ImageUse::COLOR_ATTACHMENT,
            output.after,
        );
        timer.end(cmd);
        Ok(())
    }

    /// Draws an overlay (the viewer's panel) over the composite of [`Self::record_frame`],
    /// whose `output.after` must be [`ImageUse::COLOR_ATTACHMENT`], as the timed pass
    /// `name`, then leaves the image in `after`. `draw` records into a dynamic rendering
    /// that keeps the composite (load op LOAD).
    pub fn record_overlay(
        &mut self,
        frame: &Frame,
        output: &OutputTarget,
        name: &str,
        after: ImageUse,
        draw: impl FnOnce(vk::CommandBuffer) -> Result<()>,
    ) -> Result<()> {
        debug_assert_eq!(output.after.layout, ImageUse::COLOR_ATTACHMENT.layout);
        let (ctx, cmd) = (&self.ctx, frame.cmd);
        let timer = &mut self.frames[frame.slot].timer;
        timer.begin(cmd, name);
        let color = [vk::RenderingAttachmentInfo::default()
            .image_view(output.view)
            .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::LOAD)
            .store_op(vk::AttachmentStoreOp::STORE)];
        let rendering = vk::RenderingInfo::default()
            .render_area(vk::Rect2D {
                offset: vk::Offset2D::default(),
                extent: output.extent,
            })
            .layer_count(1)
            .color_attachments(&color);
        unsafe { ctx.device.cmd_begin_rendering(cmd, &rendering) };
        let drawn = draw(cmd);
        unsafe { ctx.device.cmd_end_rendering(cmd) };
        let range = COLOR_TARGET_RANGE;
        image_barrier(
            ctx,
            cmd,
            output.image,
            range,
            ImageUse::COLOR_ATTACHMENT,
            after,
        );
        timer.end(cmd);
        drawn
    }

    /// Copies the frame's HDR radiance (RGBA32F) into `buffer`, which must hold
    /// width x height x 16 bytes and be host visible.
    pub fn record_radiance_readback(&mut self, cmd: vk::CommandBuffer, buffer: &Buffer) {
        let radiance = &self.targets.radiance;
        image_barrier(
            &self.ctx,
            cmd,
            radiance.raw,
            radiance.full_range(),
            self.radiance_last_use,
            ImageUse::TRANSFER_SRC,
        );
        self.radiance_last_use = ImageUse::TRANSFER_SRC;
        copy_image_to_buffer(
            &self.ctx,
            cmd,
            radiance.raw,
            radiance.extent_2d(),
            buffer.raw,
        );
    }

    pub fn submit(
        &mut self,
        frame: Frame,
        wait: Option<(vk::Semaphore, vk::PipelineStageFlags2)>,
        signal: Option<vk::Semaphore>,
    ) -> Result<()> {
        self.ring.submit(frame, wait, signal)
    }

    /// Waits for every submitted frame and collects the last one's pass times.
    pub fn finish(&mut self) -> Result<()> {
        self.ring.wait_all()?;
        if let Some(slot) = self.ring.last_slot() {
            self.timings = self.frames[slot].timer.results()?;
        }
        Ok(())
    }
}

impl Drop for Renderer {
    /// The GPU may still be using every resource (an error can end a frame's wait
    /// early): nothing is destroyed before it is idle.
    fn drop(&mut self) {
        if let Err(e) = self.ctx.wait_idle() {
            log::error!("waiting for the GPU before freeing the renderer: {e:#}");
        }
    }
}
