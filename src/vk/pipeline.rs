//! Pipeline layouts, compute pipelines and dynamic-rendering graphics pipelines.

use std::sync::Arc;

use anyhow::{Context as _, Result};
use ash::vk;

use super::Context;

/// A pipeline with its layout; both destroyed when dropped.
pub struct Pipeline {
    pub raw: vk::Pipeline,
    pub layout: vk::PipelineLayout,
    pub bind_point: vk::PipelineBindPoint,
    ctx: Arc<Context>,
}

fn shader_module(ctx: &Context, spirv: &[u8], name: &str) -> Result<vk::ShaderModule> {
    let words = ash::util::read_spv(&mut std::io::Cursor::new(spirv))
        .with_context(|| format!("bad SPIR-V in {name}"))?;
    let info = vk::ShaderModuleCreateInfo::default().code(&words);
    let module = unsafe { ctx.device.create_shader_module(&info, None) }
        .with_context(|| format!("shader {name}"))?;
    ctx.set_name(module, name);
    Ok(module)
}

fn pipeline_layout(
    ctx: &Context,
    set_layouts: &[vk::DescriptorSetLayout],
    push_constant_bytes: u32,
    stages: vk::ShaderStageFlags,
) -> Result<vk::PipelineLayout> {
    let ranges = [vk::PushConstantRange {
        stage_flags: stages,
        offset: 0,
        size: push_constant_bytes,
    }];
    let mut info = vk::PipelineLayoutCreateInfo::default().set_layouts(set_layouts);
    if push_constant_bytes > 0 {
        info = info.push_constant_ranges(&ranges);
    }
    Ok(unsafe { ctx.device.create_pipeline_layout(&info, None) }?)
}

/// Map entries for specialization constants: value i is `constant_id = i`. A shader
/// without such an id ignores its entry (Vulkan spec, VkSpecializationMapEntry).
fn specialization_entries(constants: &[u32]) -> Vec<vk::SpecializationMapEntry> {
    (0..constants.len() as u32)
        .map(|id| vk::SpecializationMapEntry {
            constant_id: id,
            offset: id * 4,
            size: 4,
        })
        .collect()
}

impl Pipeline {
    pub fn compute(
        ctx: &Arc<Context>,
        name: &str,
        spirv: &[u8],
        set_layouts: &[vk::DescriptorSetLayout],
        push_constant_bytes: u32,
    ) -> Result<Self> {
        Self::compute_specialized(ctx, name, spirv, set_layouts, push_constant_bytes, &[])
    }

    /// A compute pipeline whose specialization constant i is `constants[i]`.
    pub fn compute_specialized(
        ctx: &Arc<Context>,
        name: &str,
        spirv: &[u8],
        set_layouts: &[vk::DescriptorSetLayout],
        push_constant_bytes: u32,
        constants: &[u32],
    ) -> Result<Self> {
        let entries = specialization_entries(constants);
        let specialization = vk::SpecializationInfo::default()
            .map_entries(&entries)
            .data(bytemuck::cast_slice(constants));
        let module = shader_module(ctx, spirv, name)?;
        let layout = pipeline_layout(
            ctx,
            set_layouts,
            push_constant_bytes,
            vk::ShaderStageFlags::COMPUTE,
        )?;
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module)
            .name(c"main")
            .specialization_info(&specialization);
        let info = [vk::ComputePipelineCreateInfo::default()
            .stage(stage)
            .layout(layout)];
        let result = unsafe {
            ctx.device
                .create_compute_pipelines(vk::PipelineCache::null(), &info, None)
        };
        unsafe { ctx.device.destroy_shader_module(module, None) };
        let raw = result
            .map_err(|(_, e)| e)
            .with_context(|| format!("creating compute pipeline {name}"))?[0];
        ctx.set_name(raw, name);
        Ok(Self {
            raw,
            layout,
            bind_point: vk::PipelineBindPoint::COMPUTE,
            ctx: ctx.clone(),
        })
    }

    pub fn bind(&self, cmd: vk::CommandBuffer, sets: &[(u32, vk::DescriptorSet)]) {
        unsafe {
            self.ctx
                .device
                .cmd_bind_pipeline(cmd, self.bind_point, self.raw);
            for (index, set) in sets {
                self.ctx.device.cmd_bind_descriptor_sets(
                    cmd,
                    self.bind_point,
                    self.layout,
                    *index,
                    &[*set],
                    &[],
                );
            }
        }
    }

    /// Dispatches `groups` workgroups of this compute pipeline, bound earlier with its sets.
    pub fn dispatch_bound(&self, cmd: vk::CommandBuffer, groups: [u32; 3]) {
        unsafe {
            self.ctx
                .device
                .cmd_dispatch(cmd, groups[0], groups[1], groups[2])
        };
    }

    /// Binds this compute pipeline and `sets`, then dispatches `groups` workgroups.
    pub fn dispatch(
        &self,
        cmd: vk::CommandBuffer,
        sets: &[(u32, vk::DescriptorSet)],
        groups: [u32; 3],
    ) {
        self.bind(cmd, sets);
        unsafe {
            self.ctx
                .device
                .cmd_dispatch(cmd, groups[0], groups[1], groups[2])
        };
    }

    /// Binds the pipeline and `sets`, then dispatches the workgroup counts stored at byte
    /// `offset` of `args`.
    pub fn dispatch_indirect(
        &self,
        cmd: vk::CommandBuffer,
        sets: &[(u32, vk::DescriptorSet)],
        args: vk::Buffer,
        offset: vk::DeviceSize,
    ) {
        self.bind(cmd, sets);
        unsafe { self.ctx.device.cmd_dispatch_indirect(cmd, args, offset) };
    }

    pub fn is_compute(&self) -> bool {
        self.bind_point == vk::PipelineBindPoint::COMPUTE
    }

    /// Binds one more descriptor set to the bound pipeline.
    pub fn bind_set(&self, cmd: vk::CommandBuffer, index: u32, set: vk::DescriptorSet) {
        unsafe {
            self.ctx.device.cmd_bind_descriptor_sets(
                cmd,
                self.bind_point,
                self.layout,
                index,
                &[set],
                &[],
            )
        };
    }

    pub fn push<T: bytemuck::Pod>(
        &self,
        cmd: vk::CommandBuffer,
        stages: vk::ShaderStageFlags,
        value: &T,
    ) {
        unsafe {
            self.ctx.device.cmd_push_constants(
                cmd,
                self.layout,
                stages,
                0,
                bytemuck::bytes_of(value),
            )
        };
    }
}

impl Drop for Pipeline {
    fn drop(&mut self) {
        unsafe {
            self.ctx.device.destroy_pipeline(self.raw, None);
            self.ctx.device.destroy_pipeline_layout(self.layout, None);
        }
    }
}

/// What a graphics pipeline draws into and how.
pub struct GraphicsDesc<'a> {
    pub name: &'a str,
    pub vertex: &'a [u8],
    pub geometry: Option<&'a [u8]>,
    pub fragment: Option<&'a [u8]>,
    /// Vertex stride and (location, format, offset) attributes; empty for a full-screen triangle.
    pub vertex_stride: u32,
    pub attributes: &'a [(u32, vk::Format, u32)],
    pub set_layouts: &'a [vk::DescriptorSetLayout],
    pub push_constant_bytes: u32,
    pub color_formats: &'a [vk::Format],
    pub depth_format: Option<vk::Format>,
    pub cull: vk::CullModeFlags,
    /// Depth bias set per draw with `vkCmdSetDepthBias` (shadow maps).
    pub dynamic_depth_bias: bool,
    pub depth_clamp: bool,
    /// Specialization constant i of every stage is `constants[i]`.
    pub constants: &'a [u32],
}

impl Pipeline {
    pub fn graphics(ctx: &Arc<Context>, desc: &GraphicsDesc) -> Result<Self> {
        let push_stages = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
        let layout = pipeline_layout(ctx, desc.set_layouts, desc.push_constant_bytes, push_stages)?;
        let vertex = shader_module(ctx, desc.vertex, desc.name)?;
        let geometry = desc
            .geometry
            .map(|g| shader_module(ctx, g, desc.name))
            .transpose()?;
        let fragment = desc
            .fragment
            .map(|f| shader_module(ctx, f, desc.name))
            .transpose()?;
        let entries = specialization_entries(desc.constants);
        let specialization = vk::SpecializationInfo::default()
            .map_entries(&entries)
            .data(bytemuck::cast_slice(desc.constants));
        let mut stages = vec![vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::VERTEX)
            .module(vertex)
            .name(c"main")
            .specialization_info(&specialization)];
        if let Some(geometry) = geometry {
            stages.push(
                vk::PipelineShaderStageCreateInfo::default()
                    .stage(vk::ShaderStageFlags::GEOMETRY)
                    .module(geometry)
                    .name(c"main")
                    .specialization_info(&specialization),
            );
        }
        if let Some(fragment) = fragment {
            stages.push(
                vk::PipelineShaderStageCreateInfo::default()
                    .stage(vk::ShaderStageFlags::FRAGMENT)
                    .module(fragment)
                    .name(c"main")
                    .specialization_info(&specialization),
            );
        }
        let bindings = [vk::VertexInputBindingDescription {
            binding: 0,
            stride: desc.vertex_stride,
            input_rate: vk::VertexInputRate::VERTEX,
        }];
        let attributes: Vec<_> = desc
            .attributes
            .iter()
            .map(
                |&(location, format, offset)| vk::VertexInputAttributeDescription {
                    location,
                    binding: 0,
                    format,
                    offset,
                },
            )
            .collect();
        let mut vertex_input = vk::PipelineVertexInputStateCreateInfo::default();
        if !attributes.is_empty() {
            vertex_input = vertex_input
                .vertex_binding_descriptions(&bindings)
                .vertex_attribute_descriptions(&attributes);
        }
        let assembly = vk::PipelineInputAssemblyStateCreateInfo::default()
            .topology(vk::PrimitiveTopology::TRIANGLE_LIST);
        let viewport = vk::PipelineViewportStateCreateInfo::default()
            .viewport_count(1)
            .scissor_count(1);
        let raster = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(desc.cull)
            .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
            .depth_bias_enable(desc.dynamic_depth_bias)
            .depth_clamp_enable(desc.depth_clamp)
            .line_width(1.0);
        let multisample = vk::PipelineMultisampleStateCreateInfo::default()
            .rasterization_samples(vk::SampleCountFlags::TYPE_1);
        let depth = vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(desc.depth_format.is_some())
            .depth_write_enable(desc.depth_format.is_some())
            // Reverse Z everywhere (the camera's and the lights' projections): nearer is
            // larger.
            .depth_compare_op(vk::CompareOp::GREATER);
        let blend_attachments: Vec<_> = desc
            .color_formats
            .iter()
            .map(|_| {
                vk::PipelineColorBlendAttachmentState::default()
                    .color_write_mask(vk::ColorComponentFlags::RGBA)
            })
            .collect();
        let blend =
            vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend_attachments);
        let mut dynamic_states = vec![vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
        if desc.dynamic_depth_bias {
            dynamic_states.push(vk::DynamicState::DEPTH_BIAS);
        }
        let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
        let mut rendering = vk::PipelineRenderingCreateInfo::default()
            .color_attachment_formats(desc.color_formats)
            .depth_attachment_format(desc.depth_format.unwrap_or(vk::Format::UNDEFINED));
        let info = [vk::GraphicsPipelineCreateInfo::default()
            .stages(&stages)
            .vertex_input_state(&vertex_input)
            .input_assembly_state(&assembly)
            .viewport_state(&viewport)
            .rasterization_state(&raster)
            .multisample_state(&multisample)
            .depth_stencil_state(&depth)
            .color_blend_state(&blend)
            .dynamic_state(&dynamic)
            .layout(layout)
            .push_next(&mut rendering)];
        let result = unsafe {
            ctx.device
                .create_graphics_pipelines(vk::PipelineCache::null(), &info, None)
        };
        unsafe {
            ctx.device.destroy_shader_module(vertex, None);
            if let Some(geometry) = geometry {
                ctx.device.destroy_shader_module(geometry, None);
            }
            if let Some(fragment) = fragment {
                ctx.device.destroy_shader_module(fragment, None);
            }
        }
        let raw = result
            .map_err(|(_, e)| e)
            .with_context(|| format!("creating graphics pipeline {}", desc.name))?[0];
        ctx.set_name(raw, desc.name);
        Ok(Self {
            raw,
            layout,
            bind_point: vk::PipelineBindPoint::GRAPHICS,
            ctx: ctx.clone(),
        })
    }
}

/// Sets a viewport and scissor covering `extent`.
pub fn set_viewport(ctx: &Context, cmd: vk::CommandBuffer, extent: vk::Extent2D) {
    set_viewport_rect(
        ctx,
        cmd,
        vk::Rect2D {
            offset: vk::Offset2D::default(),
            extent,
        },
    );
}

/// Viewport and scissor both `rect` (a tile of an atlas).
pub fn set_viewport_rect(ctx: &Context, cmd: vk::CommandBuffer, rect: vk::Rect2D) {
    let viewport = vk::Viewport {
        x: rect.offset.x as f32,
        y: rect.offset.y as f32,
        width: rect.extent.width as f32,
        height: rect.extent.height as f32,
        min_depth: 0.0,
        max_depth: 1.0,
    };
    let scissor = rect;
    unsafe {
        ctx.device.cmd_set_viewport(cmd, 0, &[viewport]);
        ctx.device.cmd_set_scissor(cmd, 0, &[scissor]);
    }
}

/// Workgroup count covering `size` items with groups of `group`.
pub fn groups(size: u32, group: u32) -> u32 {
    size.div_ceil(group).max(1)
}

/// Workgroups covering an image of `extent` with square groups of edge `group`.
pub fn groups_2d(extent: vk::Extent2D, group: u32) -> [u32; 3] {
    [groups(extent.width, group), groups(extent.height, group), 1]
}

/// Workgroups covering an `n`³ volume with cubic groups of edge `group`.
pub fn groups_3d(n: u32, group: u32) -> [u32; 3] {
    let g = groups(n, group);
    [g, g, g]
}
