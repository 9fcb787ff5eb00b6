//! Scene ray casting, for any pass that casts rays against the scene's triangles
//! (`glsl/ray/rays.glsl`): the closest hit (triangle, barycentrics, material, normal) and
//! any hit (visibility), through the first bindings of its set 3 (`BINDING_RAY_*`).
//!
//! Two compressed eight-wide BVHs (CWBVH): the static meshes', built once, and the moving
//! meshes', built again every frame at the frame's time (a rebuild over their triangles
//! alone: they are few; a refit would keep a tree built for other positions). The nodes
//! and triangles of both sit in the same buffers, the moving meshes' after the static
//! ones', rewritten in the frame's command buffer from a staging buffer per frame in
//! flight.

mod atlas;
mod bvh;
pub mod host;
pub mod query;
pub mod surfaces;
#[cfg(test)]
mod tests;

use std::sync::Arc;
use std::time::Instant;

use anyhow::{bail, Result};
use ash::vk;
use gpu_allocator::MemoryLocation;

use self::surfaces::{struct_texels, Materials};
use crate::gpu_layout::{
    self as layout, BvhNode, RayEmitter, RayShading, RayTriangle, RayUniforms, RAY_NONE,
};
use crate::scene::Scene;
use crate::vk::{memory_barrier, Binding, Buffer, Context, OneShot, SetWriter, TexelBuffer};
pub use bvh::{Bvh, Triangles};

/// What building the static BVH took and made, for `bench` and the logs.
#[derive(Clone, Debug)]
pub struct BuildStats {
    pub triangles: usize,
    pub nodes: usize,
    /// Host time of the static build, triangles gathered and flattened included.
    pub build_ms: f64,
    /// The longest path from the root to a leaf.
    pub depth: u32,
    /// The moving meshes' triangles, and the host time of their last rebuild (gathered,
    /// transformed, built and flattened; 0 without moving meshes).
    pub moving_triangles: usize,
    pub moving_build_ms: f64,
}

/// The scene's triangles on the GPU, ready to cast rays against.
/// What the scene asks of the passes that cast rays, each a specialization constant
/// (`SPEC_RAY_*`, and `SPEC_PATH_*` for the path tracer), so that the code of what the
/// scene lacks is not compiled in: a CPU driver runs every branch an invocation group
/// meets, taken or not.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayFeatures {
    /// Some triangle is cut out (`RAY_CUT_OUT`).
    pub cut_outs: bool,
    /// The scene has moving meshes.
    pub moving: bool,
    /// Some material has an albedo or emission texture.
    pub textures: bool,
    /// Some material has a normal map.
    pub normal_maps: bool,
    /// Some material has a specular lobe (Ks > 0).
    pub specular: bool,
    /// Some material refracts (d < 1, Ni > 1).
    pub transmission: bool,
    /// Next-event estimation has emissive triangles to sample.
    pub emitters: bool,
}

impl RayFeatures {
    /// The features of the materials the scene's meshes use (those of the GPU materials
    /// the shaders read, `gpu_materials`); `emitters` is left to the emitters' list.
    fn of(scene: &Scene) -> Self {
        let mut f = Self {
            moving: scene.has_moving_meshes(),
            ..Self::default()
        };
        for mesh in &scene.meshes {
            let m = &scene.materials[mesh.material as usize];
            f.cut_outs |= m.cut_out();
            f.textures |= m.albedo_texture.is_some() || m.emission_texture.is_some();
            f.normal_maps |= m.normal_texture.is_some();
            f.specular |= m.specular.max_element() > 0.0;
            f.transmission |= m.refracts();
        }
        f
    }

    /// The constants of the ray casting's include (`glsl/ray/rays.glsl`), ids
    /// `SPEC_RAY_CUT_OUTS` and `SPEC_RAY_MOVING`, which every pass that casts rays takes
    /// first.
    pub fn ray_constants(&self) -> [u32; 2] {
        let mut c = [0; 2];
        c[layout::SPEC_RAY_CUT_OUTS as usize] = u32::from(self.cut_outs);
        c[layout::SPEC_RAY_MOVING as usize] = u32::from(self.moving);
        c
    }
}

pub struct SceneRays {
    uniforms: Buffer,
    nodes: TexelBuffer,
    triangles: TexelBuffer,
    shading: TexelBuffer,
    emitters: TexelBuffer,
    materials: Materials,
    /// Nodes and triangles of the static part (the moving meshes' follow).
    static_nodes: u32,
    static_triangles: u32,
    /// The moving meshes' triangles (0 without moving meshes).
    moving_triangles: u32,
    /// Per frame in flight: the moving meshes' nodes, triangles, shading and uniforms to
    /// copy in.
    staging: Vec<Buffer>,
    pub stats: BuildStats,
    pub features: RayFeatures,
    ctx: Arc<Context>,
}

/// The stages that cast rays.
pub(crate) const STAGES: vk::ShaderStageFlags = vk::ShaderStageFlags::COMPUTE;

/// The most triangles the BVHs hold: a triangle's shading is texel 4i of its buffer, an
/// `int` in GLSL.
const MAX_TRIANGLES: usize = 1 << 29;

/// Refuses a BVH deeper than the traversal stack holds (it pushes a group of children per
/// level at most).
fn check_depth(depth: u32, what: &str) -> Result<()> {
    if depth >= layout::RAY_STACK_SIZE {
        bail!(
            "the {what} BVH is {depth} levels deep, more than the {} its traversal stack holds",
            layout::RAY_STACK_SIZE
        );
    }
    Ok(())
}

/// The texel format of every buffer rays read: an integer format, whose fetches return
/// every bit as stored (the indices kept in float lanes are denormals, which a float
/// format's fetch may flush).
pub(crate) const TEXEL_FORMAT: vk::Format = vk::Format::R32G32B32A32_UINT;

impl SceneRays {
    /// The set-3 bindings every ray-casting pass starts with.
    pub fn bindings() -> Vec<Binding> {
        let texels = vk::DescriptorType::UNIFORM_TEXEL_BUFFER;
        vec![
            Binding::new(
                layout::BINDING_RAY_UNIFORMS,
                vk::DescriptorType::UNIFORM_BUFFER,
                STAGES,
            ),
            Binding::new(layout::BINDING_RAY_NODES, texels, STAGES),
            Binding::new(layout::BINDING_RAY_TRIANGLES, texels, STAGES),
            Binding::new(layout::BINDING_RAY_SHADING, texels, STAGES),
            Binding::new(layout::BINDING_RAY_EMITTERS, texels, STAGES),
        ]
        .into_iter()
        .chain(Materials::bindings())
        .collect()
    }

    /// Builds the static meshes' BVH, uploads it, the texture atlas and the emitters, and
    /// makes room for the moving meshes' (at time 0 until the first frame's update).
    /// `frames_in_flight` frames may be recorded before the first is done.
    pub fn new(ctx: &Arc<Context>, scene: &Scene, frames_in_flight: usize) -> Result<Self> {
        let start = Instant::now();
        let triangle_count: usize = scene.meshes.iter().map(|m| m.indices.len() / 3).sum();
        if triangle_count >= MAX_TRIANGLES {
            bail!(
                "the scene has {triangle_count} triangles: ray casting holds fewer than {MAX_TRIANGLES}"
            );
        }
        let statics = Triangles::of(scene, 0.0, |m| m.animation.is_none());
        let built = Bvh::build(&statics, 0, 0, false);
        let depth = built.depth;
        check_depth(depth, "static meshes'")?;
        let stats = BuildStats {
            triangles: statics.len(),
            nodes: built.nodes.len(),
            build_ms: start.elapsed().as_secs_f64() * 1e3,
            depth,
            moving_triangles: 0,
            moving_build_ms: 0.0,
        };
        log::info!(
            "ray casting: BVH of {} static triangles, {} nodes, {depth} levels, built in {:.0} ms",
            stats.triangles,
            stats.nodes,
            stats.build_ms
        );
        let moving = Triangles::of(scene, 0.0, |m| m.animation.is_some());
        let static_nodes = built.nodes.len() as u32;
        let static_triangles = built.triangles.len() as u32;
        let moving_triangles = moving.len() as u32;
        // Every inner node has two children or more, and every leaf a triangle or more: a
        // BVH of n triangles has fewer than n nodes (but one, for one triangle).
        let node_capacity = static_nodes + moving_triangles + 1;
        let triangle_capacity = (static_triangles + moving_triangles).max(1);
        let one_shot = OneShot::new(ctx)?;
        let sized = |name: &str, element: usize, count: u32, data: &[u8]| {
            struct_texels(ctx, &one_shot, name, element, count, data)
        };
        let nodes = sized(
            "ray BVH nodes",
            std::mem::size_of::<BvhNode>(),
            node_capacity,
            bytemuck::cast_slice(&built.nodes),
        )?;
        let triangles = sized(
            "ray triangles",
            std::mem::size_of::<RayTriangle>(),
            triangle_capacity,
            bytemuck::cast_slice(&built.triangles),
        )?;
        let shading = sized(
            "ray triangle shading",
            std::mem::size_of::<RayShading>(),
            triangle_capacity,
            bytemuck::cast_slice(&built.shading),
        )?;
        let (emitters, emitter_power) = emitters(scene, &built);
        let emitter_count = emitters.len() as u32;
        let emitters = sized(
            "ray emitters",
            std::mem::size_of::<RayEmitter>(),
            emitter_count.max(1),
            bytemuck::cast_slice(&emitters),
        )?;
        let materials = Materials::new(ctx, &one_shot, scene)?;
        let bounds = scene.swept_bounds();
        let uniforms = RayUniforms {
            static_root: built.root(0),
            moving_root: RAY_NONE,
            emitter_count,
            emitter_power,
            // Large enough to clear the float error of positions across the scene, small
            // enough to miss no contact: 1e-5 of its size.
            epsilon: 1e-5 * (bounds.max - bounds.min).length().max(1e-6),
            ..Default::default()
        };
        let uniforms = Buffer::with_data(
            ctx,
            "ray uniforms",
            bytemuck::bytes_of(&uniforms),
            vk::BufferUsageFlags::UNIFORM_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
        )?;
        let staging_bytes = Self::moving_bytes(moving_triangles) as u64;
        let staging = (0..frames_in_flight)
            .map(|i| {
                Buffer::new(
                    ctx,
                    &format!("ray moving meshes {i}"),
                    staging_bytes.max(16),
                    vk::BufferUsageFlags::TRANSFER_SRC,
                    MemoryLocation::CpuToGpu,
                )
            })
            .collect::<Result<_>>()?;
        Ok(Self {
            uniforms,
            nodes,
            triangles,
            shading,
            materials,
            emitters,
            static_nodes,
            static_triangles,
            moving_triangles,
            staging,
            stats,
            features: RayFeatures {
                emitters: emitter_count > 0,
                ..RayFeatures::of(scene)
            },
            ctx: ctx.clone(),
        })
    }

    /// Bytes the moving meshes' part takes in a staging buffer: nodes, triangles, shading.
    fn moving_bytes(moving_triangles: u32) -> usize {
        let n = moving_triangles as usize;
        (n + 1) * std::mem::size_of::<BvhNode>()
            + n * (std::mem::size_of::<RayTriangle>() + std::mem::size_of::<RayShading>())
    }

    /// Writes the ray-casting bindings into `set`.
    pub fn write_set(&self, set: vk::DescriptorSet) {
        let writer = SetWriter::new(&self.ctx, set)
            .buffer(
                layout::BINDING_RAY_UNIFORMS,
                vk::DescriptorType::UNIFORM_BUFFER,
                self.uniforms.raw,
            )
            .texel_buffer(layout::BINDING_RAY_NODES, self.nodes.view())
            .texel_buffer(layout::BINDING_RAY_TRIANGLES, self.triangles.view())
            .texel_buffer(layout::BINDING_RAY_SHADING, self.shading.view())
            .texel_buffer(layout::BINDING_RAY_EMITTERS, self.emitters.view());
        self.materials.write(writer).apply();
    }

    /// Whether the scene has moving meshes, whose BVH [`Self::record_moving`] rebuilds.
    pub fn has_moving_meshes(&self) -> bool {
        self.moving_triangles > 0
    }

    /// Rebuilds the moving meshes' BVH at scene time `time_s` and records its copy into
    /// the buffers, for the ray casts recorded after it in `cmd`; `slot` is the frame's
    /// slot in flight (its staging buffer is free again).
    pub fn record_moving(
        &mut self,
        cmd: vk::CommandBuffer,
        scene: &Scene,
        time_s: f32,
        slot: usize,
    ) -> Result<()> {
        if !self.has_moving_meshes() {
            return Ok(());
        }
        let start = Instant::now();
        let moving = Triangles::of(scene, time_s, |m| m.animation.is_some());
        let built = Bvh::build(&moving, self.static_nodes, self.static_triangles, true);
        check_depth(built.depth, "moving meshes'")?;
        self.stats.moving_triangles = moving.len();
        self.stats.moving_build_ms = start.elapsed().as_secs_f64() * 1e3;
        let parts: [&[u8]; 3] = [
            bytemuck::cast_slice(&built.nodes),
            bytemuck::cast_slice(&built.triangles),
            bytemuck::cast_slice(&built.shading),
        ];
        let targets = [
            (
                &self.nodes.buffer,
                self.static_nodes as usize * std::mem::size_of::<BvhNode>(),
            ),
            (
                &self.triangles.buffer,
                self.static_triangles as usize * std::mem::size_of::<RayTriangle>(),
            ),
            (
                &self.shading.buffer,
                self.static_triangles as usize * std::mem::size_of::<RayShading>(),
            ),
        ];
        let staging = &mut self.staging[slot];
        let mut offset = 0;
        let mut regions = Vec::new();
        for (part, (target, at)) in parts.iter().zip(targets) {
            staging.write(offset, part);
            regions.push((target.raw, offset, at, part.len()));
            offset += part.len();
        }
        let ctx = &self.ctx;
        // Last frame's ray casts read the part rewritten now.
        memory_barrier(
            ctx,
            cmd,
            (
                vk::PipelineStageFlags2::COMPUTE_SHADER,
                vk::AccessFlags2::SHADER_SAMPLED_READ,
            ),
            (
                vk::PipelineStageFlags2::ALL_TRANSFER,
                vk::AccessFlags2::TRANSFER_WRITE,
            ),
        );
        for (target, from, to, size) in regions {
            let region = vk::BufferCopy::default()
                .src_offset(from as u64)
                .dst_offset(to as u64)
                .size(size as u64);
            unsafe {
                ctx.device
                    .cmd_copy_buffer(cmd, staging.raw, target, &[region])
            };
        }
        let root = built.root(self.static_nodes);
        unsafe {
            ctx.device.cmd_update_buffer(
                cmd,
                self.uniforms.raw,
                std::mem::offset_of!(RayUniforms, moving_root) as u64,
                bytemuck::bytes_of(&root),
            )
        };
        memory_barrier(
            ctx,
            cmd,
            (
                vk::PipelineStageFlags2::ALL_TRANSFER,
                vk::AccessFlags2::TRANSFER_WRITE,
            ),
            (
                vk::PipelineStageFlags2::COMPUTE_SHADER,
                vk::AccessFlags2::SHADER_SAMPLED_READ | vk::AccessFlags2::UNIFORM_READ,
            ),
        );
        Ok(())
    }

    /// GPU memory of the ray-casting resources, by name.
    pub fn memory_bytes(&self) -> Vec<(&'static str, u64)> {
        let mut bytes = vec![
            ("ray_bvh_nodes", self.nodes.buffer.size),
            (
                "ray_triangles",
                self.triangles.buffer.size + self.shading.buffer.size,
            ),
            ("ray_emitters", self.emitters.buffer.size),
        ];
        bytes.extend(self.materials.memory_bytes());
        bytes
    }
}

/// The emissive triangles of `bvh` (by their index in it), with their cumulative
/// distribution by power (area x largest emitted radiance of the material's factor, which an
/// emission texture scales by at most one), and the total power.
fn emitters(scene: &Scene, bvh: &Bvh) -> (Vec<RayEmitter>, f32) {
    let mut list = Vec::new();
    let mut total = 0.0f64;
    for (i, tri) in bvh.triangles.iter().enumerate() {
        let material = &scene.materials[tri.v0[3].to_bits() as usize];
        let radiance = material.emission.max_element();
        if radiance <= 0.0 {
            continue;
        }
        let e1 = glam::Vec3::from_slice(&tri.e1[..3]);
        let e2 = glam::Vec3::from_slice(&tri.e2[..3]);
        let area = 0.5 * e1.cross(e2).length();
        if area <= 0.0 {
            continue;
        }
        total += f64::from(area * radiance);
        list.push((i as u32, total));
    }
    let emitters = list
        .iter()
        .map(|&(triangle, cdf)| RayEmitter {
            triangle,
            cdf: (cdf / total) as f32,
            ..Default::default()
        })
        .collect();
    (emitters, total as f32)
}
