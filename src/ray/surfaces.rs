//! What a pass needs to shade a point of a triangle (`glsl/ray/surfaces.glsl`): the
//! scene's materials, its textures in one atlas, and the triangles' corners, normals and
//! uvs, in set 3's bindings `BINDING_RAY_TRIANGLES` to `BINDING_RAY_TEXTURES`. Ray casting
//! ([`super::SceneRays`]) keeps its triangles in the BVH's leaf order; a pass that looks
//! triangles up by their index in the scene (the probes' relight and gather) keeps them
//! in the scene's order ([`SceneTriangles`]).

use std::sync::Arc;

use anyhow::{bail, Result};
use ash::vk;

use super::bvh::Triangles;
use super::{atlas, STAGES, TEXEL_FORMAT};
use crate::gpu_layout::{self as layout, GpuMaterial, RayShading, RayTriangle};
use crate::scene::Scene;
use crate::scene_gpu::{gpu_materials, upload_texture};
use crate::vk::{
    sampler_info, upload_buffer, Binding, Context, Image, OneShot, Sampler, SetWriter, TexelBuffer,
};

/// Refuses a buffer of `size` bytes beyond `limit`, the most the device binds in one
/// texel buffer of `texel_bytes` texels, naming both.
pub(super) fn check_buffer_size(name: &str, size: u64, limit: u64, texel_bytes: u64) -> Result<()> {
    if size > limit {
        bail!(
            "the scene's {name} need {size} bytes ({:.1} MiB), more than the {limit} bytes \
             ({:.1} MiB) the device binds in one texel buffer (maxTexelBufferElements of \
             {texel_bytes} bytes)",
            size as f64 / 1048576.0,
            limit as f64 / 1048576.0
        );
    }
    Ok(())
}

/// `data` in a texel buffer of `format`, whose texels are `texel_bytes` long (at least one
/// texel, zero past the data's end), refused if the device cannot bind that much.
pub fn texel_buffer(
    ctx: &Arc<Context>,
    one_shot: &OneShot,
    name: &str,
    format: vk::Format,
    texel_bytes: u64,
    data: &[u8],
) -> Result<TexelBuffer> {
    let limit = texel_bytes * u64::from(ctx.properties.limits.max_texel_buffer_elements);
    let size = (data.len() as u64).div_ceil(texel_bytes).max(1) * texel_bytes;
    check_buffer_size(name, size, limit, texel_bytes)?;
    let mut bytes = data.to_vec();
    bytes.resize(size as usize, 0);
    let usage = vk::BufferUsageFlags::UNIFORM_TEXEL_BUFFER | vk::BufferUsageFlags::TRANSFER_DST;
    let buffer = upload_buffer(ctx, one_shot, name, &bytes, usage)?;
    TexelBuffer::new(name, buffer, format)
}

/// `count` structs of `element` bytes from `data` (zero past its end) in a texel buffer of
/// [`TEXEL_FORMAT`], as the rays read them.
pub(super) fn struct_texels(
    ctx: &Arc<Context>,
    one_shot: &OneShot,
    name: &str,
    element: usize,
    count: u32,
    data: &[u8],
) -> Result<TexelBuffer> {
    let mut bytes = data.to_vec();
    bytes.resize(element * count as usize, 0);
    texel_buffer(ctx, one_shot, name, TEXEL_FORMAT, 16, &bytes)
}

/// The scene's materials and textures as the shading of a hit reads them.
pub struct Materials {
    materials: TexelBuffer,
    textures: TexelBuffer,
    atlas: Image,
    /// Referenced by the sets the materials are written into.
    atlas_sampler: Sampler,
}

impl Materials {
    pub fn new(ctx: &Arc<Context>, one_shot: &OneShot, scene: &Scene) -> Result<Self> {
        let max_side = ctx.properties.limits.max_image_dimension2_d;
        let packed = atlas::pack(&scene.textures, max_side)?;
        let texels = atlas::texels(&scene.textures, &packed);
        let atlas = upload_texture(
            ctx,
            one_shot,
            "ray texture atlas",
            vk::Format::R8G8B8A8_UNORM,
            packed.width,
            packed.height,
            &[texels],
        )?;
        let textures = struct_texels(
            ctx,
            one_shot,
            "ray texture rects",
            std::mem::size_of::<[u32; 4]>(),
            packed.rects.len() as u32,
            bytemuck::cast_slice(&packed.rects),
        )?;
        let gpu_materials = gpu_materials(scene);
        let materials = struct_texels(
            ctx,
            one_shot,
            "ray materials",
            std::mem::size_of::<GpuMaterial>(),
            gpu_materials.len() as u32,
            bytemuck::cast_slice(&gpu_materials),
        )?;
        let atlas_sampler = Sampler::new(
            ctx,
            "ray texture atlas",
            &sampler_info(vk::Filter::NEAREST, vk::SamplerAddressMode::CLAMP_TO_EDGE),
        )?;
        Ok(Self {
            materials,
            textures,
            atlas,
            atlas_sampler,
        })
    }

    /// The bindings of the materials, the atlas and the texture rectangles.
    pub fn bindings() -> [Binding; 3] {
        let texels = vk::DescriptorType::UNIFORM_TEXEL_BUFFER;
        [
            Binding::new(layout::BINDING_RAY_MATERIALS, texels, STAGES),
            Binding::new(
                layout::BINDING_RAY_ATLAS,
                vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
                STAGES,
            ),
            Binding::new(layout::BINDING_RAY_TEXTURES, texels, STAGES),
        ]
    }

    /// Adds the materials' bindings to `writer`.
    pub fn write<'a>(&self, writer: SetWriter<'a>) -> SetWriter<'a> {
        writer
            .sampled_image(
                layout::BINDING_RAY_ATLAS,
                self.atlas.view,
                self.atlas_sampler.raw,
                vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
            )
            .texel_buffer(layout::BINDING_RAY_MATERIALS, self.materials.view())
            .texel_buffer(layout::BINDING_RAY_TEXTURES, self.textures.view())
    }

    /// GPU memory, by name.
    pub fn memory_bytes(&self) -> Vec<(&'static str, u64)> {
        vec![
            ("ray_texture_atlas", self.atlas.memory_bytes()),
            (
                "ray_materials",
                self.materials.buffer.size + self.textures.buffer.size,
            ),
        ]
    }
}

/// Every triangle of the scene in the scene's order (meshes in order, triangles in index
/// order; the moving meshes' at time 0), with the materials: `ray_triangle(i)` in
/// `glsl/ray/surfaces.glsl` is the scene's triangle i.
pub struct SceneTriangles {
    triangles: TexelBuffer,
    shading: TexelBuffer,
    pub materials: Materials,
    pub count: u32,
}

impl SceneTriangles {
    pub fn new(ctx: &Arc<Context>, scene: &Scene) -> Result<Self> {
        let one_shot = OneShot::new(ctx)?;
        let all = Triangles::of(scene, 0.0, |_| true);
        let count = all.len() as u32;
        let triangles = struct_texels(
            ctx,
            &one_shot,
            "scene triangles",
            std::mem::size_of::<RayTriangle>(),
            count.max(1),
            bytemuck::cast_slice(&all.triangles),
        )?;
        let shading = struct_texels(
            ctx,
            &one_shot,
            "scene triangle shading",
            std::mem::size_of::<RayShading>(),
            count.max(1),
            bytemuck::cast_slice(&all.shading),
        )?;
        Ok(Self {
            triangles,
            shading,
            materials: Materials::new(ctx, &one_shot, scene)?,
            count,
        })
    }

    /// The bindings `glsl/ray/surfaces.glsl` declares.
    pub fn bindings() -> Vec<Binding> {
        let texels = vk::DescriptorType::UNIFORM_TEXEL_BUFFER;
        let mut bindings = vec![
            Binding::new(layout::BINDING_RAY_TRIANGLES, texels, STAGES),
            Binding::new(layout::BINDING_RAY_SHADING, texels, STAGES),
        ];
        bindings.extend(Materials::bindings());
        bindings
    }

    /// Writes the bindings into `set`.
    pub fn write_set(&self, ctx: &Context, set: vk::DescriptorSet) {
        let writer = SetWriter::new(ctx, set)
            .texel_buffer(layout::BINDING_RAY_TRIANGLES, self.triangles.view())
            .texel_buffer(layout::BINDING_RAY_SHADING, self.shading.view());
        self.materials.write(writer).apply();
    }

    /// GPU memory, by name.
    pub fn memory_bytes(&self) -> Vec<(&'static str, u64)> {
        let mut bytes = vec![(
            "scene_triangles",
            self.triangles.buffer.size + self.shading.buffer.size,
        )];
        bytes.extend(self.materials.memory_bytes());
        bytes
    }
}
