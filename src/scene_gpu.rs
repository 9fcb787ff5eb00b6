//! The scene on the GPU: one vertex and index buffer, materials, textures with mips, and
//! the descriptor set (set 1) that shaders read them through.

use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use crate::gpu_layout::{self as layout, DrawPush, GpuMaterial};
use crate::scene::{Scene, TextureKind, Vertex};
use crate::vk::{
    image_barrier, sampler_info, upload_buffer, Binding, Buffer, Context, DescriptorSets, Image,
    ImageDesc, ImageUse, OneShot, Pipeline, Sampler, SetWriter,
};

/// What mesh draws need: the scene at a time and the descriptor sets to bind.
pub struct SceneDraw<'a> {
    pub scene: &'a crate::scene::Scene,
    pub gpu: &'a GpuScene,
    /// The frame's descriptor set (set 0).
    pub frame_set: vk::DescriptorSet,
    pub time_s: f32,
}

impl SceneDraw<'_> {
    /// Binds `pipeline` and the geometry, then draws every mesh that `keep` accepts with
    /// its model matrix and material in the push constants; `shadow_view` selects the
    /// shadow view. `gi_set` (a GI technique's own) is bound as set 3 when given.
    pub fn draw_meshes(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        pipeline: &Pipeline,
        shadow_view: u32,
        gi_set: Option<vk::DescriptorSet>,
        keep: impl Fn(&crate::scene::Mesh) -> bool,
    ) {
        self.for_each_mesh(ctx, cmd, pipeline, gi_set, keep, |draw, mut push| {
            push.shadow_view = shadow_view;
            pipeline.push(
                cmd,
                vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                &push,
            );
            unsafe {
                ctx.device.cmd_draw_indexed(
                    cmd,
                    draw.index_count,
                    1,
                    draw.first_index,
                    draw.vertex_offset,
                    0,
                )
            };
        });
    }

    /// Binds the compute `pipeline` and `gi_set` (set 3, which holds the geometry as
    /// storage buffers), then dispatches workgroups for every triangle of every mesh that
    /// `keep` accepts, with its model matrix, material, first index and vertex offset in
    /// the push constants: `slices(longest edge in world units)` workgroups per triangle
    /// along y, at most `max_groups` per dispatch along each axis.
    #[allow(clippy::too_many_arguments)]
    pub fn dispatch_triangles(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        pipeline: &Pipeline,
        gi_set: vk::DescriptorSet,
        max_groups: [u32; 2],
        slices: impl Fn(f32) -> u32,
        keep: impl Fn(&crate::scene::Mesh) -> bool,
    ) {
        let record = |draw: &Draw, mut push: DrawPush| {
            push.vertex_offset = draw.vertex_offset as u32;
            let model = glam::Mat4::from_cols_array_2d(&push.model);
            let scale = [model.x_axis, model.y_axis, model.z_axis]
                .map(|a| a.truncate().length())
                .into_iter()
                .fold(0.0, f32::max);
            let along_y = slices(draw.longest_edge * scale).clamp(1, max_groups[1]);
            let triangles = draw.index_count / 3;
            for start in (0..triangles).step_by(max_groups[0] as usize) {
                push.first_index = draw.first_index + 3 * start;
                pipeline.push(cmd, vk::ShaderStageFlags::COMPUTE, &push);
                let groups = (triangles - start).min(max_groups[0]);
                unsafe { ctx.device.cmd_dispatch(cmd, groups, along_y, 1) };
            }
        };
        self.for_each_mesh(ctx, cmd, pipeline, Some(gi_set), keep, record);
    }

    /// Binds `pipeline`, set 0, `gi_set` and (for draws) the geometry, then for every
    /// mesh that `keep` accepts binds its material's set and calls `record` with its
    /// draw and push constants (model matrix and material).
    fn for_each_mesh(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        pipeline: &Pipeline,
        gi_set: Option<vk::DescriptorSet>,
        keep: impl Fn(&crate::scene::Mesh) -> bool,
        mut record: impl FnMut(&Draw, DrawPush),
    ) {
        pipeline.bind(cmd, &[(layout::SET_FRAME, self.frame_set)]);
        if let Some(set) = gi_set {
            pipeline.bind_set(cmd, layout::SET_GI, set);
        }
        if !pipeline.is_compute() {
            self.gpu.bind_geometry(ctx, cmd);
        }
        for draw in self
            .gpu
            .draws
            .iter()
            .filter(|d| keep(&self.scene.meshes[d.mesh]))
        {
            pipeline.bind_set(
                cmd,
                layout::SET_SCENE,
                self.gpu.material_sets[draw.material as usize],
            );
            let push = DrawPush {
                model: self
                    .scene
                    .mesh_transform(draw.mesh, self.time_s)
                    .to_cols_array_2d(),
                material: draw.material,
                first_index: draw.first_index,
                ..Default::default()
            };
            record(draw, push);
        }
    }
}

/// One indexed draw: a mesh of the scene.
#[derive(Clone, Copy, Debug)]
pub struct Draw {
    pub mesh: usize,
    pub first_index: u32,
    pub index_count: u32,
    pub vertex_offset: i32,
    pub material: u32,
    /// The longest edge of the mesh's triangles, in object space (the compute voxelizer
    /// sizes its dispatch by it).
    pub longest_edge: f32,
}

pub struct GpuScene {
    pub vertices: Buffer,
    pub indices: Buffer,
    pub materials: Buffer,
    pub draws: Vec<Draw>,
    /// Set 1 of each material: the material buffer and its textures.
    material_sets: Vec<vk::DescriptorSet>,
    /// The layout of set 1, and the pool the material sets come from.
    pub sets: DescriptorSets,
    textures: Vec<Image>,
    sampler: Sampler,
}

/// The `Vertex` attributes: (location, format, offset).
pub const VERTEX_ATTRIBUTES: [(u32, vk::Format, u32); 3] = [
    (0, vk::Format::R32G32B32_SFLOAT, 0),
    (1, vk::Format::R32G32B32_SFLOAT, 12),
    (2, vk::Format::R32G32_SFLOAT, 24),
];

fn texture_index(index: Option<u32>) -> u32 {
    index.unwrap_or(layout::NO_TEXTURE)
}

/// The scene's materials as the shaders read them, in the scene's order.
pub fn gpu_materials(scene: &Scene) -> Vec<GpuMaterial> {
    scene
        .materials
        .iter()
        .map(|m| GpuMaterial {
            albedo: m.albedo.extend(m.dissolve).to_array(),
            specular: m.specular.extend(m.roughness).to_array(),
            emission: m.emission.extend(m.ior).to_array(),
            albedo_texture: texture_index(m.albedo_texture),
            coverage_texture: texture_index(m.coverage_texture),
            normal_texture: texture_index(m.normal_texture),
            emission_texture: texture_index(m.emission_texture),
        })
        .collect()
}

impl GpuScene {
    pub fn bindings() -> [Binding; 5] {
        let stages = vk::ShaderStageFlags::ALL;
        let sampled = vk::DescriptorType::COMBINED_IMAGE_SAMPLER;
        [
            Binding::new(
                layout::BINDING_MATERIALS,
                vk::DescriptorType::STORAGE_BUFFER,
                stages,
            ),
            Binding::new(layout::BINDING_ALBEDO_TEXTURE, sampled, stages),
            Binding::new(layout::BINDING_COVERAGE_TEXTURE, sampled, stages),
            Binding::new(layout::BINDING_NORMAL_TEXTURE, sampled, stages),
            Binding::new(layout::BINDING_EMISSION_TEXTURE, sampled, stages),
        ]
    }

    /// The scene's buffers, textures and material sets; the materials' sampler filters
    /// anisotropically (8×) where `anisotropy` and the device offers it
    /// (`RenderSettings::anisotropy_on_cpu`).
    pub fn new(ctx: &Arc<Context>, scene: &Scene, anisotropy: bool) -> Result<Self> {
        let one_shot = OneShot::new(ctx)?;
        let mut vertices: Vec<Vertex> = Vec::new();
        let mut indices: Vec<u32> = Vec::new();
        let mut draws = Vec::new();
        for (mesh_index, mesh) in scene.meshes.iter().enumerate() {
            draws.push(Draw {
                mesh: mesh_index,
                first_index: indices.len() as u32,
                index_count: mesh.indices.len() as u32,
                vertex_offset: vertices.len() as i32,
                material: mesh.material,
                longest_edge: longest_edge(mesh),
            });
            vertices.extend_from_slice(&mesh.vertices);
            indices.extend_from_slice(&mesh.indices);
        }
        let vertex_usage =
            vk::BufferUsageFlags::VERTEX_BUFFER | vk::BufferUsageFlags::STORAGE_BUFFER;
        let index_usage = vk::BufferUsageFlags::INDEX_BUFFER | vk::BufferUsageFlags::STORAGE_BUFFER;
        let vertices = upload_buffer(
            ctx,
            &one_shot,
            "scene vertices",
            bytemuck::cast_slice(&vertices),
            vertex_usage,
        )?;
        let indices = upload_buffer(
            ctx,
            &one_shot,
            "scene indices",
            bytemuck::cast_slice(&indices),
            index_usage,
        )?;
        let gpu_materials = gpu_materials(scene);
        let materials = upload_buffer(
            ctx,
            &one_shot,
            "scene materials",
            bytemuck::cast_slice(&gpu_materials),
            vk::BufferUsageFlags::STORAGE_BUFFER,
        )?;

        let mut textures = Vec::new();
        for texture in &scene.textures {
            let format = match texture.kind {
                TextureKind::Albedo => vk::Format::R8G8B8A8_SRGB,
                TextureKind::Coverage | TextureKind::Normal => vk::Format::R8G8B8A8_UNORM,
            };
            let name = texture
                .path
                .file_name()
                .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
            textures.push(upload_texture(
                ctx,
                &one_shot,
                &name,
                format,
                texture.width,
                texture.height,
                &texture.mips,
            )?);
        }
        // Unused slots of the texture array must still hold a valid descriptor.
        let white = upload_texture(
            ctx,
            &one_shot,
            "white",
            vk::Format::R8G8B8A8_UNORM,
            1,
            1,
            &[vec![255; 4]],
        )?;

        let max_anisotropy = ctx.properties.limits.max_sampler_anisotropy.min(8.0);
        let sampler = Sampler::new(
            ctx,
            "material sampler",
            &sampler_info(vk::Filter::LINEAR, vk::SamplerAddressMode::REPEAT)
                .anisotropy_enable(anisotropy && ctx.features.sampler_anisotropy)
                .max_anisotropy(max_anisotropy),
        )?;
        let sets = DescriptorSets::new(
            ctx,
            "materials",
            &Self::bindings(),
            scene.materials.len().max(1) as u32,
        )?;
        let texture_view =
            |index: Option<u32>| index.map_or(white.view, |i| textures[i as usize].view);
        let material_sets = scene
            .materials
            .iter()
            .map(|m| {
                let set = sets.allocate(&format!("material {}", m.name))?;
                let layout_ro = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
                SetWriter::new(ctx, set)
                    .buffer(
                        layout::BINDING_MATERIALS,
                        vk::DescriptorType::STORAGE_BUFFER,
                        materials.raw,
                    )
                    .sampled_image(
                        layout::BINDING_ALBEDO_TEXTURE,
                        texture_view(m.albedo_texture),
                        sampler.raw,
                        layout_ro,
                    )
                    .sampled_image(
                        layout::BINDING_COVERAGE_TEXTURE,
                        texture_view(m.coverage_texture),
                        sampler.raw,
                        layout_ro,
                    )
                    .sampled_image(
                        layout::BINDING_NORMAL_TEXTURE,
                        texture_view(m.normal_texture),
                        sampler.raw,
                        layout_ro,
                    )
                    .sampled_image(
                        layout::BINDING_EMISSION_TEXTURE,
                        texture_view(m.emission_texture),
                        sampler.raw,
                        layout_ro,
                    )
                    .apply();
                Ok(set)
            })
            .collect::<Result<Vec<_>>>()?;
        textures.push(white);
        Ok(Self {
            vertices,
            indices,
            materials,
            draws,
            material_sets,
            sets,
            textures,
            sampler,
        })
    }

    /// Bytes of GPU memory held by textures.
    pub fn texture_bytes(&self) -> u64 {
        self.textures.iter().map(Image::memory_bytes).sum()
    }

    /// Binds the vertex and index buffers for mesh draws.
    pub fn bind_geometry(&self, ctx: &Context, cmd: vk::CommandBuffer) {
        unsafe {
            ctx.device
                .cmd_bind_vertex_buffers(cmd, 0, &[self.vertices.raw], &[0]);
            ctx.device
                .cmd_bind_index_buffer(cmd, self.indices.raw, 0, vk::IndexType::UINT32);
        }
    }

    pub fn sampler(&self) -> vk::Sampler {
        self.sampler.raw
    }
}

/// The longest edge of `mesh`'s triangles, in object space.
fn longest_edge(mesh: &crate::scene::Mesh) -> f32 {
    let position = |i: u32| glam::Vec3::from(mesh.vertices[i as usize].position);
    mesh.indices
        .chunks_exact(3)
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .map(|(a, b)| position(a).distance(position(b)))
        .fold(0.0, f32::max)
}

pub(crate) fn upload_texture(
    ctx: &Arc<Context>,
    one_shot: &OneShot,
    name: &str,
    format: vk::Format,
    width: u32,
    height: u32,
    mips: &[Vec<u8>],
) -> Result<Image> {
    // A texture beyond the device's largest image starts at its first mip level that
    // fits (each level halves, down to 1x1, so one always does).
    let max = ctx.properties.limits.max_image_dimension2_d;
    let skip = (0..mips.len())
        .find(|&l| (width >> l).max(1) <= max && (height >> l).max(1) <= max)
        .unwrap_or(mips.len() - 1);
    if skip > 0 {
        log::warn!(
            "texture {name} is {width}x{height}, beyond the device's {max} texels: using its \
             mip level {skip} ({}x{})",
            (width >> skip).max(1),
            (height >> skip).max(1)
        );
    }
    let (width, height, mips) = (
        (width >> skip).max(1),
        (height >> skip).max(1),
        &mips[skip..],
    );
    let mut desc = ImageDesc::d2(
        format,
        width,
        height,
        vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST,
    );
    desc.mip_levels = mips.len() as u32;
    let image = Image::new(ctx, name, desc)?;
    let bytes: Vec<u8> = mips.concat();
    let staging = Buffer::with_data(
        ctx,
        &format!("{name} staging"),
        &bytes,
        vk::BufferUsageFlags::TRANSFER_SRC,
    )?;
    let mut regions = Vec::new();
    let mut offset = 0u64;
    for (level, mip) in mips.iter().enumerate() {
        regions.push(vk::BufferImageCopy {
            buffer_offset: offset,
            buffer_row_length: 0,
            buffer_image_height: 0,
            image_subresource: vk::ImageSubresourceLayers {
                aspect_mask: vk::ImageAspectFlags::COLOR,
                mip_level: level as u32,
                base_array_layer: 0,
                layer_count: 1,
            },
            image_offset: vk::Offset3D::default(),
            image_extent: vk::Extent3D {
                width: (width >> level).max(1),
                height: (height >> level).max(1),
                depth: 1,
            },
        });
        offset += mip.len() as u64;
    }
    one_shot.run(&format!("upload {name}"), |cmd| {
        image_barrier(
            ctx,
            cmd,
            image.raw,
            image.full_range(),
            ImageUse::UNDEFINED,
            ImageUse::TRANSFER_DST,
        );
        unsafe {
            ctx.device.cmd_copy_buffer_to_image(
                cmd,
                staging.raw,
                image.raw,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &regions,
            )
        };
        image_barrier(
            ctx,
            cmd,
            image.raw,
            image.full_range(),
            ImageUse::TRANSFER_DST,
            ImageUse::ANY_SHADER_READ,
        );
        Ok(())
    })?;
    Ok(image)
}
