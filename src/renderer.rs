//! The frame: the passes in the order data flows through them.
//!
//! shadow maps -> G-buffer -> deferred direct lighting -> composite (tonemap to output)

use std::sync::Arc;

use anyhow::{bail, Result};
use ash::vk;
use glam::Vec3;
use gpu_allocator::MemoryLocation;

use crate::composite::CompositePass;
use crate::gbuffer::{GBuffer, GBufferPass};
use crate::gi::{ConeSettings, VoxelGi, VoxelStructure};
use crate::gpu_layout::{self as layout, FrameUniforms, GpuLight, ShadowView};
use crate::lighting::LightingPass;
use crate::scene::{Camera, LightKind, Scene};
use crate::scene_gpu::{GpuScene, SceneDraw};
use crate::shadow::{self, ShadowPass, ShadowResolution};
use crate::vk::{
    copies_to_host_barrier, image_barrier, sampler_info, Binding, Buffer, Context, DescriptorSets,
    Frame, FrameRing, GpuTimer, Image, ImageUse, Sampler, SetWriter,
};

/// How the final image is mapped to the display.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Tonemap {
    /// clamp(x), then sRGB: the convention of the reference PNGs.
    #[default]
    Clamp,
    /// Filmic curve (Narkowicz's ACES fit), then sRGB.
    Aces,
}

/// Global illumination by voxel cone tracing.
#[derive(Clone, Copy, Debug)]
pub struct GiSettings {
    /// Voxels per axis (a power of two): of the dense grid, or effective of the octree.
    pub voxels: u32,
    pub structure: VoxelStructure,
    pub cones: ConeSettings,
    /// Direct light shadowed by soft-shadow cones through the voxels instead of by the
    /// shadow maps (which still light the voxels).
    pub shadow_cones: bool,
    /// Re-voxelize and re-shade the static geometry every frame too (benchmarks).
    pub full_update: bool,
    pub voxelizer: crate::gi::voxelize::Voxelizer,
}

/// The terms of the final image; each can be switched.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Terms {
    pub direct: bool,
    pub emission: bool,
    pub indirect_diffuse: bool,
    pub indirect_specular: bool,
    pub transmission: bool,
    /// Multiply the indirect light by ambient occlusion. Off by default: the cones that
    /// gather the indirect light are already occluded by the same voxels, so this darkens
    /// twice (Cornell box LDR-FLIP 0.226 with it against 0.171 without); it is the classic
    /// contact-shadow look, not the physically based image.
    pub ambient_occlusion: bool,
}

impl Default for Terms {
    fn default() -> Self {
        Self {
            direct: true,
            emission: true,
            indirect_diffuse: true,
            indirect_specular: true,
            transmission: true,
            ambient_occlusion: false,
        }
    }
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
    /// own colour with its edges drawn (`--gi svo` only).
    OctreeNodes,
}

impl DebugView {
    /// Every view, in the viewer's cycling order.
    pub const ALL: [DebugView; 7] = [
        DebugView::None,
        DebugView::Indirect,
        DebugView::Ao,
        DebugView::VoxelAlbedo,
        DebugView::VoxelNormal,
        DebugView::VoxelRadiance,
        DebugView::OctreeNodes,
    ];

    fn code(self) -> u32 {
        match self {
            DebugView::None => layout::DEBUG_NONE,
            DebugView::Indirect => layout::DEBUG_INDIRECT,
            DebugView::Ao => layout::DEBUG_AO,
            DebugView::VoxelAlbedo => layout::DEBUG_VOXEL_ALBEDO,
            DebugView::VoxelNormal => layout::DEBUG_VOXEL_NORMAL,
            DebugView::VoxelRadiance => layout::DEBUG_VOXEL_RADIANCE,
            DebugView::OctreeNodes => layout::DEBUG_OCTREE_NODES,
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

/// Settings that change what a frame computes.
#[derive(Clone, Debug)]
pub struct RenderSettings {
    /// Add the specular lobe of MTL Ks.
    pub specular: bool,
    /// Use tangent-space normal maps.
    pub normal_maps: bool,
    /// Exposure in stops applied before the tonemap (not to EXR output).
    pub exposure_ev: f32,
    pub tonemap: Tonemap,
    /// Texels per side of each light view's shadow map.
    pub shadow_resolution: ShadowResolution,
    /// Keep the shadow maps while no light and no mesh moves.
    pub cache_shadows: bool,
    /// Indirect light; `None` for direct light only.
    pub gi: Option<GiSettings>,
    pub terms: Terms,
    /// Needs `gi`.
    pub debug_view: DebugView,
    /// Mip level of the voxel debug views.
    pub debug_level: u32,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            specular: true,
            normal_maps: true,
            exposure_ev: 0.0,
            tonemap: Tonemap::Clamp,
            shadow_resolution: ShadowResolution::default(),
            cache_shadows: true,
            gi: None,
            terms: Terms::default(),
            debug_view: DebugView::None,
            debug_level: 0,
        }
    }
}

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

/// Per-frame-in-flight data written by the host.
struct FrameData {
    uniforms: Buffer,
    lights: Buffer,
    shadow_views: Buffer,
    set: vk::DescriptorSet,
    timer: GpuTimer,
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
    gi: Option<VoxelGi>,
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

const FRAMES_IN_FLIGHT: usize = 2;

fn frame_bindings() -> [Binding; 4] {
    let all = vk::ShaderStageFlags::ALL;
    [
        Binding::new(
            layout::BINDING_FRAME_UNIFORMS,
            vk::DescriptorType::UNIFORM_BUFFER,
            all,
        ),
        Binding::new(
            layout::BINDING_LIGHTS,
            vk::DescriptorType::STORAGE_BUFFER,
            all,
        ),
        Binding::new(
            layout::BINDING_SHADOW_VIEWS,
            vk::DescriptorType::STORAGE_BUFFER,
            all,
        ),
        Binding::new(
            layout::BINDING_SHADOW_MAP,
            vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
            all,
        ),
    ]
}

impl Renderer {
    pub fn new(
        ctx: &Arc<Context>,
        scene: Scene,
        settings: RenderSettings,
        extent: vk::Extent2D,
        output_format: vk::Format,
    ) -> Result<Self> {
        if settings.gi.is_none() && settings.debug_view != DebugView::None {
            bail!(
                "the debug view {:?} shows the voxel GI: it needs --gi dense",
                settings.debug_view
            );
        }
        let gpu = GpuScene::new(ctx, &scene)?;
        let frame_sets =
            DescriptorSets::new(ctx, "frame", &frame_bindings(), FRAMES_IN_FLIGHT as u32)?;
        let set_layouts = [frame_sets.layout, gpu.sets.layout];
        let shadow = ShadowPass::new(ctx, &scene, settings.shadow_resolution, &set_layouts)?;
        let gbuffer_pass = GBufferPass::new(ctx, &set_layouts)?;
        let lighting = LightingPass::new(ctx, set_layouts)?;
        let composite = CompositePass::new(ctx, set_layouts, output_format)?;
        let gi = settings
            .gi
            .map(|g| VoxelGi::new(ctx, &scene, &gpu, &g, set_layouts, FRAMES_IN_FLIGHT))
            .transpose()?;
        let nearest_sampler = Sampler::new(
            ctx,
            "nearest",
            &sampler_info(vk::Filter::NEAREST, vk::SamplerAddressMode::CLAMP_TO_EDGE),
        )?;
        // Outside a shadow map's coverage reads as lit (border depth 1).
        let shadow_sampler = Sampler::new(
            ctx,
            "shadow compare",
            &sampler_info(vk::Filter::LINEAR, vk::SamplerAddressMode::CLAMP_TO_BORDER)
                .border_color(vk::BorderColor::FLOAT_OPAQUE_WHITE)
                .compare_enable(true)
                .compare_op(vk::CompareOp::LESS_OR_EQUAL),
        )?;
        let light_slots = scene.lights.len().max(1);
        let view_slots: u32 = scene
            .lights
            .iter()
            .map(shadow::view_count)
            .sum::<u32>()
            .max(1);
        let mut frames = Vec::new();
        for i in 0..FRAMES_IN_FLIGHT {
            let uniforms = Buffer::new(
                ctx,
                &format!("frame uniforms {i}"),
                std::mem::size_of::<FrameUniforms>() as u64,
                vk::BufferUsageFlags::UNIFORM_BUFFER,
                MemoryLocation::CpuToGpu,
            )?;
            let lights = Buffer::new(
                ctx,
                &format!("lights {i}"),
                (std::mem::size_of::<GpuLight>() * light_slots) as u64,
                vk::BufferUsageFlags::STORAGE_BUFFER,
                MemoryLocation::CpuToGpu,
            )?;
            let shadow_views = Buffer::new(
                ctx,
                &format!("shadow views {i}"),
                (std::mem::size_of::<ShadowView>() * view_slots as usize) as u64,
                vk::BufferUsageFlags::STORAGE_BUFFER,
                MemoryLocation::CpuToGpu,
            )?;
            let set = frame_sets.allocate(&format!("frame {i}"))?;
            SetWriter::new(ctx, set)
                .buffer(
                    layout::BINDING_FRAME_UNIFORMS,
                    vk::DescriptorType::UNIFORM_BUFFER,
                    uniforms.raw,
                )
                .buffer(
                    layout::BINDING_LIGHTS,
                    vk::DescriptorType::STORAGE_BUFFER,
                    lights.raw,
                )
                .buffer(
                    layout::BINDING_SHADOW_VIEWS,
                    vk::DescriptorType::STORAGE_BUFFER,
                    shadow_views.raw,
                )
                .sampled_image(
                    layout::BINDING_SHADOW_MAP,
                    shadow.map.view,
                    shadow_sampler.raw,
                    vk::ImageLayout::DEPTH_READ_ONLY_OPTIMAL,
                )
                .apply();
            frames.push(FrameData {
                uniforms,
                lights,
                shadow_views,
                set,
                timer: GpuTimer::new(ctx)?,
            });
        }
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
        if let Some(gi) = &mut renderer.gi {
            let draw = SceneDraw {
                scene: &renderer.scene,
                gpu: &renderer.gpu,
                frame_set: renderer.frames[0].set,
                time_s: 0.0,
            };
            gi.prepare(&draw)?;
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
        if let Some(gi) = &mut self.gi {
            gi.bind_screen(&t.gbuffer, &t.radiance, self.nearest_sampler.raw)?;
        }
        Ok(())
    }

    pub fn context(&self) -> &Arc<Context> {
        &self.ctx
    }

    pub fn extent(&self) -> vk::Extent2D {
        self.targets.gbuffer.extent()
    }

    /// Whether this frame shadows the direct light with soft-shadow cones (GI on, and
    /// asked for) instead of shadow maps.
    fn shadow_cones_active(&self) -> bool {
        self.indirect && self.gi.is_some() && self.settings.gi.is_some_and(|g| g.shadow_cones)
    }

    /// Turns the indirect light on or off (when the renderer has GI); returns whether it
    /// is on now.
    pub fn toggle_indirect(&mut self) -> bool {
        match &mut self.gi {
            Some(gi) => {
                self.indirect = !self.indirect;
                // Bounces accumulated before the pause may no longer match the scene.
                gi.restart();
                self.indirect
            }
            None => false,
        }
    }

    /// The voxel GI, when enabled.
    pub fn gi(&self) -> Option<&VoxelGi> {
        self.gi.as_ref()
    }

    #[cfg(test)]
    pub fn gi_mut(&mut self) -> Option<&mut VoxelGi> {
        self.gi.as_mut()
    }

    /// GPU memory of the voxel volumes or of the octree, by name (empty without GI).
    pub fn gi_memory_bytes(&self) -> Vec<(&'static str, u64)> {
        self.gi
            .as_ref()
            .map_or_else(Vec::new, VoxelGi::memory_bytes)
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
        let gi_on = self.indirect && s.gi.is_some();
        if gi_on {
            for (on, flag) in [
                (t.indirect_diffuse, layout::FLAG_INDIRECT_DIFFUSE),
                (t.indirect_specular, layout::FLAG_INDIRECT_SPECULAR),
                (
                    t.transmission && self.scene.materials.iter().any(|m| m.dissolve < 1.0),
                    layout::FLAG_TRANSMISSION,
                ),
                (t.ambient_occlusion, layout::FLAG_AO),
                (self.shadow_cones_active(), layout::FLAG_SHADOW_CONES),
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

    fn gpu_lights(&self, time_s: f32) -> Vec<GpuLight> {
        let mut first_view = 0;
        (0..self.scene.lights.len())
            .map(|i| {
                let light = self.scene.light_at(i, time_s);
                let views = shadow::view_count(&light);
                let (kind, direction, cos_outer, cos_inner) = match light.kind {
                    LightKind::Point => (layout::LIGHT_POINT, Vec3::ZERO, -1.0, -1.0),
                    LightKind::Spot {
                        direction,
                        inner_deg,
                        outer_deg,
                    } => (
                        layout::LIGHT_SPOT,
                        direction.normalize(),
                        outer_deg.to_radians().cos(),
                        inner_deg.to_radians().cos(),
                    ),
                    LightKind::Directional { direction } => {
                        (layout::LIGHT_DIRECTIONAL, direction.normalize(), -1.0, -1.0)
                    }
                };
                let gpu = GpuLight {
                    position: light.position.extend(1.0).to_array(),
                    intensity: light.intensity.extend(0.0).to_array(),
                    direction: direction.extend(cos_outer).to_array(),
                    kind,
                    first_shadow_view: first_view,
                    shadow_view_count: views,
                    cos_inner,
                };
                first_view += views;
                gpu
            })
            .collect()
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
        let lights = self.gpu_lights(time_s);
        let views: Vec<ShadowView> =
            shadow::scene_views(&self.scene, time_s, self.settings.shadow_resolution);
        let extent = self.extent();
        let shadow_cones = self.shadow_cones_active();
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

        let inputs: Vec<[[f32; 4]; 4]> = views
            .iter()
            .map(|v| v.view_proj)
            .chain(
                (0..self.scene.meshes.len())
                    .map(|m| self.scene.mesh_transform(m, time_s).to_cols_array_2d()),
            )
            .collect();
        // Soft-shadow cones need no shadow maps (the voxels are lit by a voxel ray-march
        // then); they are rendered once all the same, so that they are valid when the
        // viewer switches back.
        let stale = !(self.settings.cache_shadows && self.shadow_inputs.as_ref() == Some(&inputs));
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

        let gi = self.gi.as_mut().filter(|_| self.indirect);
        if let Some(gi) = gi {
            let mut lighting: Vec<u8> = bytemuck::cast_slice(&lights).to_vec();
            lighting.extend_from_slice(bytemuck::cast_slice(&views));
            lighting.push(u8::from(shadow_cones));
            gi.record_update(cmd, timer, &draw, frame.slot, &lighting)?;
        }

        // With soft-shadow cones the GI's upsample pass shades every pixel.
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
        if let Some(gi) = self.gi.as_ref().filter(|_| self.indirect) {
            let voxel_view = self.settings.debug_view.shows_voxels();
            let ambient_occlusion =
                self.settings.terms.ambient_occlusion || self.settings.debug_view == DebugView::Ao;
            gi.record_gather(cmd, timer, data.set, extent, voxel_view, ambient_occlusion);
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
        let range = vk::ImageSubresourceRange {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            base_mip_level: 0,
            level_count: 1,
            base_array_layer: 0,
            layer_count: 1,
        };
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

/// Records a copy of mip 0, layer 0 of a colour image in TRANSFER_SRC layout to `buffer`.
pub fn copy_image_to_buffer(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    image: vk::Image,
    extent: vk::Extent2D,
    buffer: vk::Buffer,
) {
    let region = vk::BufferImageCopy {
        buffer_offset: 0,
        buffer_row_length: 0,
        buffer_image_height: 0,
        image_subresource: vk::ImageSubresourceLayers {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            mip_level: 0,
            base_array_layer: 0,
            layer_count: 1,
        },
        image_offset: vk::Offset3D::default(),
        image_extent: vk::Extent3D {
            width: extent.width,
            height: extent.height,
            depth: 1,
        },
    };
    unsafe {
        ctx.device.cmd_copy_image_to_buffer(
            cmd,
            image,
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
            buffer,
            &[region],
        )
    };
    copies_to_host_barrier(ctx, cmd);
}
