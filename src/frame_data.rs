//! Set 0: what the host writes for each frame in flight (the frame's uniforms, the
//! lights, the shadow views), beside the shadow maps (`glsl/common/frame.glsl`).

use std::sync::Arc;

use anyhow::Result;
use ash::vk;
use glam::Vec3;
use gpu_allocator::MemoryLocation;

use crate::gpu_layout::{self as layout, FrameUniforms, GpuLight, ShadowView};
use crate::passes::shadow;
use crate::scene::{LightKind, Scene};
use crate::vk::{Binding, Buffer, Context, DescriptorSets, GpuTimer, Image, Sampler, SetWriter};

/// The bindings of set 0.
pub fn bindings() -> [Binding; 4] {
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

/// One frame slot's host-written buffers, its set 0 and its GPU timer.
pub struct FrameData {
    pub uniforms: Buffer,
    pub lights: Buffer,
    pub shadow_views: Buffer,
    pub set: vk::DescriptorSet,
    pub timer: GpuTimer,
}

impl FrameData {
    /// Slot `i`'s data, its set allocated from `sets`, with room for `scene`'s lights and
    /// their shadow views; the set samples `shadow_map` through `shadow_sampler`.
    pub fn new(
        ctx: &Arc<Context>,
        i: usize,
        sets: &DescriptorSets,
        scene: &Scene,
        shadow_map: &Image,
        shadow_sampler: &Sampler,
    ) -> Result<Self> {
        let light_slots = scene.lights.len().max(1);
        let view_slots: u32 = scene
            .lights
            .iter()
            .map(shadow::view_count)
            .sum::<u32>()
            .max(1);
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
        let set = sets.allocate(&format!("frame {i}"))?;
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
                shadow_map.view,
                shadow_sampler.raw,
                vk::ImageLayout::DEPTH_READ_ONLY_OPTIMAL,
            )
            .apply();
        Ok(Self {
            uniforms,
            lights,
            shadow_views,
            set,
            timer: GpuTimer::new(ctx)?,
        })
    }
}

/// `scene`'s lights at time `time_s` as the GPU sees them, each pointing at its shadow
/// views (as many as `shadow::view_count`, one light's after another's).
pub fn gpu_lights(scene: &Scene, time_s: f32) -> Vec<GpuLight> {
    let mut first_view = 0;
    (0..scene.lights.len())
        .map(|i| {
            let light = scene.light_at(i, time_s);
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
