//! Hand-managed descriptor set layouts, pools and writes.

use std::sync::Arc;

use anyhow::Result;
use ash::vk;

use super::Context;

/// One binding of a set layout.
#[derive(Clone, Copy, Debug)]
pub struct Binding {
    pub binding: u32,
    pub kind: vk::DescriptorType,
    pub count: u32,
    pub stages: vk::ShaderStageFlags,
}

impl Binding {
    pub fn new(binding: u32, kind: vk::DescriptorType, stages: vk::ShaderStageFlags) -> Self {
        Self {
            binding,
            kind,
            count: 1,
            stages,
        }
    }

    pub fn array(mut self, count: u32) -> Self {
        self.count = count;
        self
    }
}

/// A set layout together with a pool sized for `capacity` sets of it.
pub struct DescriptorSets {
    pub layout: vk::DescriptorSetLayout,
    pool: vk::DescriptorPool,
    ctx: Arc<Context>,
}

impl DescriptorSets {
    pub fn new(
        ctx: &Arc<Context>,
        name: &str,
        bindings: &[Binding],
        capacity: u32,
    ) -> Result<Self> {
        let raw: Vec<_> = bindings
            .iter()
            .map(|b| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(b.binding)
                    .descriptor_type(b.kind)
                    .descriptor_count(b.count)
                    .stage_flags(b.stages)
            })
            .collect();
        let info = vk::DescriptorSetLayoutCreateInfo::default().bindings(&raw);
        let layout = unsafe { ctx.device.create_descriptor_set_layout(&info, None) }?;
        ctx.set_name(layout, name);
        let sizes: Vec<_> = bindings
            .iter()
            .map(|b| vk::DescriptorPoolSize {
                ty: b.kind,
                descriptor_count: b.count * capacity,
            })
            .collect();
        let pool_info = vk::DescriptorPoolCreateInfo::default()
            .max_sets(capacity)
            .pool_sizes(&sizes);
        let pool = unsafe { ctx.device.create_descriptor_pool(&pool_info, None) }?;
        ctx.set_name(pool, name);
        Ok(Self {
            layout,
            pool,
            ctx: ctx.clone(),
        })
    }

    pub fn allocate(&self, name: &str) -> Result<vk::DescriptorSet> {
        let layouts = [self.layout];
        let info = vk::DescriptorSetAllocateInfo::default()
            .descriptor_pool(self.pool)
            .set_layouts(&layouts);
        let set = unsafe { self.ctx.device.allocate_descriptor_sets(&info) }?[0];
        self.ctx.set_name(set, name);
        Ok(set)
    }
}

impl Drop for DescriptorSets {
    fn drop(&mut self) {
        unsafe {
            self.ctx.device.destroy_descriptor_pool(self.pool, None);
            self.ctx
                .device
                .destroy_descriptor_set_layout(self.layout, None);
        }
    }
}

/// Collects descriptor writes for one set and applies them together.
pub struct SetWriter<'a> {
    set: vk::DescriptorSet,
    buffers: Vec<(u32, vk::DescriptorType, vk::DescriptorBufferInfo)>,
    images: Vec<(u32, vk::DescriptorType, Vec<vk::DescriptorImageInfo>)>,
    texel_views: Vec<(u32, vk::DescriptorType, vk::BufferView)>,
    ctx: &'a Context,
}

impl<'a> SetWriter<'a> {
    pub fn new(ctx: &'a Context, set: vk::DescriptorSet) -> Self {
        Self {
            set,
            buffers: Vec::new(),
            images: Vec::new(),
            texel_views: Vec::new(),
            ctx,
        }
    }

    pub fn buffer(mut self, binding: u32, kind: vk::DescriptorType, buffer: vk::Buffer) -> Self {
        let info = vk::DescriptorBufferInfo {
            buffer,
            offset: 0,
            range: vk::WHOLE_SIZE,
        };
        self.buffers.push((binding, kind, info));
        self
    }

    /// A uniform texel buffer (`samplerBuffer`).
    pub fn texel_buffer(mut self, binding: u32, view: vk::BufferView) -> Self {
        let kind = vk::DescriptorType::UNIFORM_TEXEL_BUFFER;
        self.texel_views.push((binding, kind, view));
        self
    }

    pub fn storage_texel_buffer(mut self, binding: u32, view: vk::BufferView) -> Self {
        let kind = vk::DescriptorType::STORAGE_TEXEL_BUFFER;
        self.texel_views.push((binding, kind, view));
        self
    }

    pub fn storage_image(mut self, binding: u32, view: vk::ImageView) -> Self {
        let info = vk::DescriptorImageInfo {
            sampler: vk::Sampler::null(),
            image_view: view,
            image_layout: vk::ImageLayout::GENERAL,
        };
        self.images
            .push((binding, vk::DescriptorType::STORAGE_IMAGE, vec![info]));
        self
    }

    pub fn sampled_image(
        mut self,
        binding: u32,
        view: vk::ImageView,
        sampler: vk::Sampler,
        layout: vk::ImageLayout,
    ) -> Self {
        self.images.push((
            binding,
            vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
            vec![vk::DescriptorImageInfo {
                sampler,
                image_view: view,
                image_layout: layout,
            }],
        ));
        self
    }

    /// An array of image descriptors of type `kind`.
    pub fn images(
        mut self,
        binding: u32,
        kind: vk::DescriptorType,
        infos: Vec<vk::DescriptorImageInfo>,
    ) -> Self {
        self.images.push((binding, kind, infos));
        self
    }

    pub fn sampler(mut self, binding: u32, sampler: vk::Sampler) -> Self {
        let info = vk::DescriptorImageInfo {
            sampler,
            image_view: vk::ImageView::null(),
            image_layout: vk::ImageLayout::UNDEFINED,
        };
        self.images
            .push((binding, vk::DescriptorType::SAMPLER, vec![info]));
        self
    }

    pub fn apply(self) {
        let mut writes = Vec::new();
        for (binding, kind, info) in &self.buffers {
            writes.push(
                vk::WriteDescriptorSet::default()
                    .dst_set(self.set)
                    .dst_binding(*binding)
                    .descriptor_type(*kind)
                    .buffer_info(std::slice::from_ref(info)),
            );
        }
        for (binding, kind, infos) in &self.images {
            writes.push(
                vk::WriteDescriptorSet::default()
                    .dst_set(self.set)
                    .dst_binding(*binding)
                    .descriptor_type(*kind)
                    .image_info(infos),
            );
        }
        for (binding, kind, view) in &self.texel_views {
            writes.push(
                vk::WriteDescriptorSet::default()
                    .dst_set(self.set)
                    .dst_binding(*binding)
                    .descriptor_type(*kind)
                    .texel_buffer_view(std::slice::from_ref(view)),
            );
        }
        unsafe { self.ctx.device.update_descriptor_sets(&writes, &[]) };
    }
}
