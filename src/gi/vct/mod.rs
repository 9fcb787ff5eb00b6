//! Global illumination by voxel cone tracing (Crassin et al. 2011): one technique with two
//! voxel stores behind [`VoxelStore`], a dense grid in 3D textures ([`dense`], `--gi
//! dense`; Präntare 2016, Villegas 2018) and a sparse voxel octree ([`octree`], `--gi
//! octree`; Dřínovský 2013), which feed the same passes.
//!
//! Per frame: voxelize (the store's) -> inject (voxel shading) -> filter (the store's) ->
//! bounces (inject's bounce, then the filter again) -> after the direct lighting, the
//! cone trace into the screen contract ([`crate::gi::screen`]).

pub mod cli;
mod cone_trace;
mod debug;
pub mod dense;
mod emitters;
mod grid;
mod inject;
pub mod octree;
#[cfg(test)]
pub(crate) mod reference;
mod settings;
mod voxel_list;
pub mod voxelize;

use std::sync::Arc;

use anyhow::{bail, Result};
use ash::vk;

pub use self::dense::Dense;
pub use self::grid::Grid;
pub use self::octree::Octree;
pub use self::settings::{
    auto_indirect_scale, auto_voxels, check_voxel_size, check_voxels, dense_bytes_per_voxel,
    dense_keeps_static_sums, ConeSettings, DirectionalFilter, Quality, Resolution, Store,
    VctSettings, CPU_VOXELS, DEFAULT_SAMPLED_EMITTERS, EMITTER_PIECES, LATTICE_CONES, MOST_VOXELS,
};
use super::{
    DebugView, FrameInputs, GatherOptions, Gathered, Inputs, Preparation, Screen, ScreenRequest,
    Switch, Technique,
};
use crate::gpu_layout::{self as layout, InjectPush, VctUniforms};
use crate::scene::Scene;
use crate::scene_gpu::SceneDraw;
use crate::vk::{
    compute_to_compute, memory_barrier, sampler_info, Binding, Buffer, Context, DescriptorSets,
    GpuTimer, Image, Pipeline, Sampler, SetWriter,
};

/// The shader stages that read the cone tracer's set: the voxelizers' and every compute
/// pass.
const STAGES: vk::ShaderStageFlags = vk::ShaderStageFlags::from_raw(
    vk::ShaderStageFlags::FRAGMENT.as_raw()
        | vk::ShaderStageFlags::COMPUTE.as_raw()
        | vk::ShaderStageFlags::GEOMETRY.as_raw(),
);

/// The SPIR-V of the passes every store shares, in the variant that reads the store's
/// voxels (`// variant: OCTREE` in the shaders).
pub struct StoreShaders {
    pub inject: &'static [u8],
    pub bounce: &'static [u8],
    pub cone_trace: &'static [u8],
    /// The cone trace that also gathers ambient occlusion.
    pub cone_trace_ao: &'static [u8],
    pub voxel_view: &'static [u8],
}

/// What a store's voxelization left for voxel shading.
pub struct Voxels {
    /// The occupied-voxel list (`glsl/gi/vct/voxel_list.glsl`), which holds the dispatch of
    /// the passes that run over it.
    pub list: vk::Buffer,
    /// The store was rebuilt this frame (the octree around moving meshes): its directional
    /// radiance is to be filtered again before the bounces gather from it.
    pub rebuilt: bool,
}

/// Where the voxels are kept, and how they are filled and filtered. The shared passes
/// read and write them through the shared bindings of set 3 (`BINDING_VCT_*`), which each
/// store fills with its own resources, and through its variant of the sampling functions
/// (`glsl/gi/vct/sampling.glsl`).
pub trait VoxelStore: Sized + 'static {
    const SHADERS: StoreShaders;
    /// The debug views: the screen's ([`DebugView::SCREEN`]) and those of the store's
    /// voxels.
    const DEBUG_VIEWS: &'static [DebugView];

    /// The store's own set-3 bindings, after the shared ones.
    fn bindings() -> Vec<Binding>;

    /// Creates the store over `grid` and writes its resources into `set`. `base` makes
    /// its pipelines, `linear` the sampler of the radiance the cones sample;
    /// `frames_in_flight` frames may be recorded before the first is done.
    #[allow(clippy::too_many_arguments)]
    fn new(
        ctx: &Arc<Context>,
        scene: &Scene,
        settings: &VctSettings,
        grid: Grid,
        set: vk::DescriptorSet,
        base: PipelineBase,
        linear: vk::Sampler,
        frames_in_flight: usize,
    ) -> Result<Self>;

    fn grid(&self) -> &Grid;

    /// Whether the compact pass adds the static meshes' fragment sums
    /// (`VctUniforms.static_sums`).
    fn static_sums(&self) -> bool {
        false
    }

    /// Work before the first frame (the octree's build), waited for.
    fn prepare(&mut self, _draw: &SceneDraw, _set: vk::DescriptorSet) -> Result<()> {
        Ok(())
    }

    /// Records this frame's voxelization; `slot` is the frame's slot in flight.
    fn record_voxels(
        &mut self,
        cmd: vk::CommandBuffer,
        timer: &mut GpuTimer,
        draw: &SceneDraw,
        set: vk::DescriptorSet,
        slot: usize,
    ) -> Result<Voxels>;

    /// Fills the store's part of voxel shading's push constants; returns whether voxel
    /// shading runs. `lighting_changed`: the lights or their shadow views changed since
    /// voxel shading last ran.
    fn shading(&mut self, lighting_changed: bool, push: &mut InjectPush) -> bool;

    /// Records the filter of the radiance just written (after a barrier), timed as `name`
    /// or per level.
    fn record_filter(
        &self,
        cmd: vk::CommandBuffer,
        timer: &mut GpuTimer,
        frame_set: vk::DescriptorSet,
        set: vk::DescriptorSet,
        name: &str,
    );

    /// Records what a bounce dispatches, and returns where its dispatch is (buffer,
    /// offset).
    fn bounce_dispatch(
        &self,
        cmd: vk::CommandBuffer,
        frame_set: vk::DescriptorSet,
        set: vk::DescriptorSet,
    ) -> (vk::Buffer, vk::DeviceSize);

    /// After a frame's bounces.
    fn record_end_of_bounces(&self, _cmd: vk::CommandBuffer) {}

    fn memory_bytes(&self) -> Vec<(&'static str, u64)>;

    /// What `bench` reports of the store beyond the grid's size.
    fn stats(&self) -> Result<Vec<(String, f64)>>;

    /// The last preparation's summary and GPU time per pass.
    fn preparation(&self) -> Option<Preparation>;
}

/// The largest radiance the voxels' emission holds (the scene's, less the sampled
/// emitters'): voxels store emission divided by it, in RGBA8.
fn emission_range(scene: &Scene, sampled: &emitters::SampledEmitters) -> f32 {
    scene
        .materials
        .iter()
        .enumerate()
        .filter(|(i, _)| !sampled.samples_material(*i))
        .map(|(_, m)| m.emission.max_element())
        .fold(0.0f32, f32::max)
        .max(1e-6)
}

/// Levels of the directional mip chain of an `n`³ grid: n/2 down to 2 (a single voxel
/// for the whole grid tells a cone nothing, and the octree has no such level either).
pub(crate) fn directional_levels(n: u32) -> u32 {
    n.trailing_zeros() - 1
}

/// The set-3 bindings every store fills.
fn shared_bindings() -> Vec<Binding> {
    let storage = vk::DescriptorType::STORAGE_IMAGE;
    let sampled = vk::DescriptorType::COMBINED_IMAGE_SAMPLER;
    let buffer = vk::DescriptorType::STORAGE_BUFFER;
    vec![
        Binding::new(
            layout::BINDING_VCT_UNIFORMS,
            vk::DescriptorType::UNIFORM_BUFFER,
            STAGES,
        ),
        Binding::new(layout::BINDING_VCT_ALBEDO, storage, STAGES),
        Binding::new(layout::BINDING_VCT_NORMAL, storage, STAGES),
        Binding::new(layout::BINDING_VCT_EMISSION, storage, STAGES),
        Binding::new(layout::BINDING_VCT_RADIANCE, storage, STAGES),
        Binding::new(layout::BINDING_VCT_RADIANCE_SAMPLED, sampled, STAGES),
        Binding::new(layout::BINDING_VCT_DIRECTIONAL, sampled, STAGES),
        Binding::new(layout::BINDING_VCT_DIRECT, storage, STAGES),
        Binding::new(layout::BINDING_VCT_COVERAGE, storage, STAGES),
        Binding::new(layout::BINDING_VCT_COVERAGE_SAMPLED, sampled, STAGES),
        Binding::new(layout::BINDING_VCT_VOXEL_LIST, buffer, STAGES),
        Binding::new(layout::BINDING_VCT_EMITTERS, buffer, STAGES),
        Binding::new(layout::BINDING_VCT_EMITTER_TRIANGLES, buffer, STAGES),
        Binding::new(layout::BINDING_VCT_SAMPLED_MATERIALS, buffer, STAGES),
        // The geometry the compute voxelizer reads.
        Binding::new(
            layout::BINDING_VCT_VERTICES,
            buffer,
            vk::ShaderStageFlags::COMPUTE,
        ),
        Binding::new(
            layout::BINDING_VCT_INDICES,
            buffer,
            vk::ShaderStageFlags::COMPUTE,
        ),
    ]
}

/// Whether any cone reads the base voxels' coverage (`sample_base_snapped`): only the
/// snapped cones do, and of them only those narrow enough to read the base level: a
/// sampled emitter's visibility (`has_emitters`), a glossy or transmissive material's
/// specular and refraction cones, and the soft-shadow cones (`shadow_cones`). Elsewhere
/// the voxelization skips the clipping that takes it (on lavapipe, Sponza's voxelization
/// at 128³ took 5.4 times as long with it).
fn reads_coverage(
    scene: &Scene,
    cones: &ConeSettings,
    has_emitters: bool,
    shadow_cones: bool,
) -> bool {
    let glossy = scene
        .materials
        .iter()
        .any(|m| m.specular.max_element() > 0.0 || m.dissolve < 1.0);
    cones.snapped_cones && (has_emitters || shadow_cones || glossy)
}

/// Adds to `writer` what the cones sample, through the `linear` sampler: the base level
/// `radiance` and `coverage` and the `directional` radiance, all kept in GENERAL layout
/// (written as storage, sampled by the cones). The dense grid and the octree bind theirs
/// alike.
pub(crate) fn bind_cone_samples<'a>(
    writer: SetWriter<'a>,
    radiance: &Image,
    coverage: &Image,
    directional: &Image,
    linear: vk::Sampler,
) -> SetWriter<'a> {
    writer
        .storage_image(layout::BINDING_VCT_COVERAGE, coverage.view)
        .sampled_image(
            layout::BINDING_VCT_COVERAGE_SAMPLED,
            coverage.view,
            linear,
            vk::ImageLayout::GENERAL,
        )
        .sampled_image(
            layout::BINDING_VCT_RADIANCE_SAMPLED,
            radiance.view,
            linear,
            vk::ImageLayout::GENERAL,
        )
        .sampled_image(
            layout::BINDING_VCT_DIRECTIONAL,
            directional.view,
            linear,
            vk::ImageLayout::GENERAL,
        )
}

/// What every pipeline of voxel cone tracing is made with: the layouts of sets 0 to 3,
/// and the specialization constants (`SPEC_OCTREE_DEPTH`, which the dense grid's shaders
/// do not declare and so ignore, `SPEC_SNAPPED_CONES`, `SPEC_LATTICE_CONES`,
/// `SPEC_PLANE_OCCLUSION` and `SPEC_VOXEL_COVERAGE`).
#[derive(Clone, Copy)]
pub struct PipelineBase {
    pub sets: [vk::DescriptorSetLayout; 4],
    constants: [u32; 5],
}

impl PipelineBase {
    /// For the cone tracer over `grid` with `cones` in `store`, whose set 3 has the layout
    /// `store_set`, taking the voxels' `coverage` where some cone reads it
    /// ([`reads_coverage`]).
    fn new(
        set_layouts: &[vk::DescriptorSetLayout; 3],
        store_set: vk::DescriptorSetLayout,
        grid: &Grid,
        cones: &ConeSettings,
        store: Store,
        coverage: bool,
    ) -> Self {
        let mut constants = [0; 5];
        constants[layout::SPEC_OCTREE_DEPTH as usize] = grid.resolution.ilog2();
        constants[layout::SPEC_SNAPPED_CONES as usize] = u32::from(cones.snapped_cones);
        constants[layout::SPEC_LATTICE_CONES as usize] = cones.lattice_cones;
        constants[layout::SPEC_PLANE_OCCLUSION as usize] = u32::from(store.planes());
        constants[layout::SPEC_VOXEL_COVERAGE as usize] = u32::from(coverage);
        Self {
            sets: [set_layouts[0], set_layouts[1], set_layouts[2], store_set],
            constants,
        }
    }

    pub fn compute(
        &self,
        ctx: &Arc<Context>,
        name: &str,
        spirv: &[u8],
        push_constant_bytes: u32,
    ) -> Result<Pipeline> {
        Pipeline::compute_specialized(
            ctx,
            name,
            spirv,
            &self.sets,
            push_constant_bytes,
            &self.constants,
        )
    }

    /// The lattice's cones (`SPEC_LATTICE_CONES`; 0: the ring instead).
    pub fn lattice_cones(&self) -> u32 {
        self.constants[layout::SPEC_LATTICE_CONES as usize]
    }

    /// For a graphics pipeline's `GraphicsDesc::constants`.
    pub fn constants(&self) -> &[u32] {
        &self.constants
    }
}

/// Creates the cone tracer with the store `settings` asks for.
pub fn create(inputs: &Inputs, settings: &VctSettings) -> Result<Box<dyn Technique>> {
    Ok(match settings.store {
        Store::Dense { .. } => Box::new(ConeTracing::<Dense>::new(inputs, settings)?),
        Store::Octree { .. } => Box::new(ConeTracing::<Octree>::new(inputs, settings)?),
    })
}

/// Voxel cone tracing over the voxel store `S`: its voxels' shading and bounces, and the
/// cones gathered per pixel.
pub struct ConeTracing<S: VoxelStore> {
    store: S,
    inject: inject::InjectPass,
    bounces: u32,
    accumulate_bounces: bool,
    /// The directional volumes hold last frame's result (with its bounces).
    history: bool,
    /// What voxel shading last ran with ([`Self::lighting_key`]).
    lighting: Option<Vec<u8>>,
    /// Direct light shadowed by soft-shadow cones instead of shadow maps (the viewer
    /// switches it).
    shadow_cones: bool,
    /// `ConeSettings::indirect_scale`.
    indirect_scale: Option<u32>,
    cone_trace: cone_trace::ConeTracePass,
    voxel_view: debug::VoxelViewPass,
    set: vk::DescriptorSet,
    _sets: DescriptorSets,
    /// Referenced by the set.
    _uniforms: Buffer,
    /// Referenced by the set: the sampled emitters, their triangles and materials.
    _emitters: [Buffer; 3],
    /// Referenced by the set.
    _linear: Sampler,
    ctx: Arc<Context>,
}

impl<S: VoxelStore> ConeTracing<S> {
    /// The compute voxelizer reads the inputs' geometry.
    pub fn new(inputs: &Inputs, settings: &VctSettings) -> Result<Self> {
        let Inputs {
            ctx,
            scene,
            gpu,
            set_layouts,
            frames_in_flight,
        } = *inputs;
        let resolution = settings.voxels.on(ctx, scene, settings);
        let cones = settings.cones;
        check_voxels(resolution)?;
        let rasterized = settings.voxelizer.on(ctx) == voxelize::Voxelizer::Raster;
        if rasterized && !(ctx.features.geometry_shader && ctx.features.fragment_stores_and_atomics)
        {
            bail!(
                "the rasterizing voxelizer needs geometry shaders and fragment stores/atomics, \
                 which {} lacks: try --voxelizer compute",
                ctx.device_name()
            );
        }
        let grid = Grid::around(scene, resolution);
        let mut bindings = shared_bindings();
        bindings.extend(S::bindings());
        let sets = DescriptorSets::new(ctx, "vct", &bindings, 1)?;
        let set = sets.allocate("vct")?;
        let linear = Sampler::new(
            ctx,
            "voxel linear",
            // Not a transparent border: at coarse levels the grid is a few texels across,
            // and filtering towards a border would thin every wall there.
            &sampler_info(vk::Filter::LINEAR, vk::SamplerAddressMode::CLAMP_TO_EDGE),
        )?;
        let sampled = emitters::sampled_emitters(
            scene,
            settings.sampled_emitters,
            settings.emitter_pieces as usize,
            grid.voxel_size,
        );
        let coverage = reads_coverage(
            scene,
            &cones,
            !sampled.emitters.is_empty(),
            settings.shadow_cones,
        );
        let base = PipelineBase::new(
            &set_layouts,
            sets.layout,
            &grid,
            &cones,
            settings.store,
            coverage,
        );
        let store = S::new(
            ctx,
            scene,
            settings,
            grid,
            set,
            base,
            linear.raw,
            frames_in_flight,
        )?;
        let uniforms = VctUniforms {
            origin: grid.origin.extend(grid.voxel_size).to_array(),
            resolution,
            directional_levels: directional_levels(resolution),
            emission_range: emission_range(scene, &sampled),
            step_factor: cones.step_factor,
            bounce_step_factor: cones.bounce_step_factor,
            shadow_step_factor: cones.shadow_step_factor,
            diffuse_tan_half: (cones.diffuse_aperture_deg.to_radians() * 0.5).tan(),
            max_distance: grid.voxel_size * resolution as f32 * 1.8,
            diffuse_cones: cones.diffuse_cones.clamp(1, 16),
            shadow_tan_half: (cones.shadow_aperture_deg.to_radians() * 0.5).tan(),
            ao_distance: cones.ao_distance_voxels.max(1e-3) * grid.voxel_size,
            wide_steps_by_level: u32::from(cones.wide_steps_by_level),
            static_sums: u32::from(store.static_sums()),
            only_cone: cones.only_cone.unwrap_or(u32::MAX),
            cosine_cones: u32::from(cones.cosine_cones),
            emitter_count: sampled.emitters.len() as u32,
        };
        let uniforms = Buffer::with_data(
            ctx,
            "vct uniforms",
            bytemuck::bytes_of(&uniforms),
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?;
        let emitter_buffers = sampled.upload(ctx)?;
        let storage = vk::DescriptorType::STORAGE_BUFFER;
        SetWriter::new(ctx, set)
            .buffer(
                layout::BINDING_VCT_UNIFORMS,
                vk::DescriptorType::UNIFORM_BUFFER,
                uniforms.raw,
            )
            .buffer(layout::BINDING_VCT_VERTICES, storage, gpu.vertices.raw)
            .buffer(layout::BINDING_VCT_INDICES, storage, gpu.indices.raw)
            .buffer(
                layout::BINDING_VCT_EMITTERS,
                storage,
                emitter_buffers[0].raw,
            )
            .buffer(
                layout::BINDING_VCT_EMITTER_TRIANGLES,
                storage,
                emitter_buffers[1].raw,
            )
            .buffer(
                layout::BINDING_VCT_SAMPLED_MATERIALS,
                storage,
                emitter_buffers[2].raw,
            )
            .apply();
        Ok(Self {
            store,
            inject: inject::InjectPass::new(ctx, base, &S::SHADERS)?,
            bounces: cones.bounces.max(1),
            accumulate_bounces: cones.accumulate_bounces && cones.bounces > 1,
            history: false,
            lighting: None,
            shadow_cones: settings.shadow_cones,
            indirect_scale: cones.indirect_scale,
            cone_trace: cone_trace::ConeTracePass::new(
                ctx,
                base,
                &S::SHADERS,
                sampled.emitters.len() as u32,
            )?,
            voxel_view: debug::VoxelViewPass::new(ctx, base, &S::SHADERS)?,
            set,
            _sets: sets,
            _uniforms: uniforms,
            _emitters: emitter_buffers,
            _linear: linear,
            ctx: ctx.clone(),
        })
    }

    /// The grid the voxels tile.
    pub fn grid(&self) -> &Grid {
        self.store.grid()
    }

    /// The voxel store.
    pub fn store(&self) -> &S {
        &self.store
    }

    #[cfg(test)]
    pub fn store_mut(&mut self) -> &mut S {
        &mut self.store
    }

    /// The cone tracer's descriptor set (set 3), for passes a test records itself.
    #[cfg(test)]
    pub fn set(&self) -> vk::DescriptorSet {
        self.set
    }

    /// Everything voxel shading reads besides the voxels: the lights, their shadow views
    /// and the shadow mode. While it stays the same, the octree shades again only the
    /// voxels whose light moving meshes can have changed.
    fn lighting_key(&self, frame: &FrameInputs) -> Vec<u8> {
        let mut key: Vec<u8> = bytemuck::cast_slice(frame.lights).to_vec();
        key.extend_from_slice(bytemuck::cast_slice(frame.views));
        key.push(u8::from(self.shadow_cones));
        key
    }
}

impl<S: VoxelStore> Technique for ConeTracing<S> {
    fn prepare(&mut self, draw: &SceneDraw) -> Result<()> {
        self.store.prepare(draw, self.set)
    }

    /// The cones are traced on one pixel of each block (the settings' scale, or one
    /// chosen from the image height), and the upsample keeps samples within two voxels of
    /// a pixel's plane.
    fn bind_screen(&mut self, extent: vk::Extent2D) -> Result<ScreenRequest> {
        Ok(ScreenRequest {
            scale: self
                .indirect_scale
                .unwrap_or_else(|| auto_indirect_scale(extent.height))
                .max(1),
            plane_tolerance: 2.0 * self.grid().voxel_size,
        })
    }

    /// Voxelizes the scene and lights and filters the voxels (after the shadow maps).
    ///
    /// The first frame computes all bounces. Later frames compute one, gathering from the
    /// previous frame's filtered radiance, so bounces accumulate over frames at the cost
    /// of one (moving light takes a few frames to settle in the indirect light).
    ///
    /// With moving meshes every frame inserts them into the octree's static part, and
    /// their bricks are assigned anew; the light the voxels of new bricks gathered is
    /// carried over by voxel ([`octree`]), the others keep theirs, so bounces still
    /// accumulate one per frame.
    fn record_update(
        &mut self,
        cmd: vk::CommandBuffer,
        timer: &mut GpuTimer,
        frame: &FrameInputs,
    ) -> Result<()> {
        let ctx = self.ctx.clone();
        let ctx = &*ctx;
        let set = self.set;
        let draw = frame.draw;
        let Voxels { list, rebuilt } = self
            .store
            .record_voxels(cmd, timer, draw, set, frame.slot)?;

        timer.begin(cmd, "inject");
        memory_barrier(
            ctx,
            cmd,
            (
                voxelize::STAGES,
                vk::AccessFlags2::SHADER_STORAGE_WRITE | vk::AccessFlags2::SHADER_STORAGE_READ,
            ),
            (
                vk::PipelineStageFlags2::COMPUTE_SHADER,
                vk::AccessFlags2::SHADER_STORAGE_READ,
            ),
        );
        // Last frame's cone tracing sampled the radiance volumes that are rewritten now.
        compute_to_compute(ctx, cmd);
        // Unless a bounce rewrites the radiance before the filter reads it.
        let filter_now = !self.history || rebuilt;
        let lighting = self.lighting_key(frame);
        let lighting_changed = self.lighting.as_ref() != Some(&lighting);
        if lighting_changed {
            self.lighting = Some(lighting);
        }
        let mut push = InjectPush {
            store_radiance: u32::from(filter_now),
            ..Default::default()
        };
        if self.store.shading(lighting_changed, &mut push) {
            self.inject.record(cmd, draw.frame_set, set, list, &push);
        }
        timer.end(cmd);

        let bounces = if self.history { 1 } else { self.bounces - 1 };
        // A rebuilt octree's bricks are new: its voxel shading started from the light
        // carried by voxel, which is filtered before the bounce.
        if filter_now {
            compute_to_compute(ctx, cmd);
            self.store
                .record_filter(cmd, timer, draw.frame_set, set, "filter");
        }
        self.history = self.accumulate_bounces;
        for _ in 0..bounces {
            timer.begin(cmd, "bounce");
            compute_to_compute(ctx, cmd);
            let dispatch = self.store.bounce_dispatch(cmd, draw.frame_set, set);
            self.inject
                .record_bounce(cmd, draw.frame_set, set, dispatch);
            timer.end(cmd);
            compute_to_compute(ctx, cmd);
            self.store
                .record_filter(cmd, timer, draw.frame_set, set, "bounce filter");
        }
        self.store.record_end_of_bounces(cmd);
        Ok(())
    }

    /// Traces the cones into the screen's reduced-resolution terms, or with a voxel debug
    /// view overwrites the screen radiance with a view of the voxels.
    fn record_gather(
        &self,
        cmd: vk::CommandBuffer,
        timer: &mut GpuTimer,
        frame_set: vk::DescriptorSet,
        screen: &Screen,
        options: &GatherOptions,
    ) -> Gathered {
        let sets = [
            (layout::SET_FRAME, frame_set),
            (layout::SET_SCREEN, screen.set()),
            (layout::SET_GI, self.set),
        ];
        if options.debug_view.shows_voxels() {
            timer.begin(cmd, "voxel_view");
            compute_to_compute(&self.ctx, cmd);
            self.voxel_view.record(cmd, &sets, screen.extent());
            timer.end(cmd);
            return Gathered::Screen;
        }
        timer.begin(cmd, "cone_trace");
        compute_to_compute(&self.ctx, cmd);
        self.cone_trace.record(
            cmd,
            &sets,
            screen.reduced_extent(),
            options.ambient_occlusion,
        );
        timer.end(cmd);
        Gathered::Terms
    }

    /// Forgets the accumulated bounces: the next frame computes them all again.
    fn restart(&mut self) {
        self.history = false;
    }

    fn shades_direct(&self) -> bool {
        self.shadow_cones
    }

    fn memory_bytes(&self) -> Vec<(&'static str, u64)> {
        self.store.memory_bytes()
    }

    fn stats(&self) -> Result<Vec<(String, f64)>> {
        let mut stats = vec![("voxels".to_string(), f64::from(self.grid().resolution))];
        stats.extend(self.store.stats()?);
        Ok(stats)
    }

    fn preparation(&self) -> Option<Preparation> {
        self.store.preparation()
    }

    fn debug_views(&self) -> &'static [DebugView] {
        S::DEBUG_VIEWS
    }

    /// Down to the grid's single voxel.
    fn debug_levels(&self) -> u32 {
        self.grid().resolution.trailing_zeros()
    }

    fn switches(&mut self) -> Vec<Switch<'_>> {
        vec![Switch {
            name: "soft-shadow cones",
            key: 'c',
            on: &mut self.shadow_cones,
        }]
    }
}
