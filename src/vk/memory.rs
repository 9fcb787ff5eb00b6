//! Buffers and images with their memory, freed when dropped.

use std::sync::Arc;

use anyhow::{Context as _, Result};
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;

use super::Context;

/// A buffer and its memory.
pub struct Buffer {
    pub raw: vk::Buffer,
    pub size: vk::DeviceSize,
    allocation: Option<Allocation>,
    ctx: Arc<Context>,
}

impl Buffer {
    pub fn new(
        ctx: &Arc<Context>,
        name: &str,
        size: vk::DeviceSize,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
    ) -> Result<Self> {
        let info = vk::BufferCreateInfo::default()
            .size(size.max(4))
            .usage(usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        let raw = unsafe { ctx.device.create_buffer(&info, None) }
            .with_context(|| format!("creating buffer {name}"))?;
        let requirements = unsafe { ctx.device.get_buffer_memory_requirements(raw) };
        let allocation = ctx
            .allocator
            .lock()
            .unwrap()
            .allocate(&AllocationCreateDesc {
                name,
                requirements,
                location,
                linear: true,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .with_context(|| format!("allocating {} bytes for buffer {name}", size))?;
        unsafe {
            ctx.device
                .bind_buffer_memory(raw, allocation.memory(), allocation.offset())
        }?;
        ctx.set_name(raw, name);
        Ok(Self {
            raw,
            size,
            allocation: Some(allocation),
            ctx: ctx.clone(),
        })
    }

    /// A host-visible buffer filled with `data`.
    pub fn with_data(
        ctx: &Arc<Context>,
        name: &str,
        data: &[u8],
        usage: vk::BufferUsageFlags,
    ) -> Result<Self> {
        let mut buffer = Self::new(
            ctx,
            name,
            data.len() as u64,
            usage,
            MemoryLocation::CpuToGpu,
        )?;
        buffer.write(0, data);
        Ok(buffer)
    }

    /// The mapped bytes of a host-visible buffer.
    pub fn mapped(&self) -> &[u8] {
        let allocation = self.allocation.as_ref().unwrap();
        &allocation
            .mapped_slice()
            .expect("buffer is not host visible")[..self.size as usize]
    }

    pub fn write(&mut self, offset: usize, data: &[u8]) {
        let allocation = self.allocation.as_mut().unwrap();
        let mapped = allocation
            .mapped_slice_mut()
            .expect("buffer is not host visible");
        mapped[offset..offset + data.len()].copy_from_slice(data);
    }
}

/// A buffer read as a `samplerBuffer` (a uniform texel buffer): the buffer and its typed
/// view, the view destroyed first.
pub struct TexelBuffer {
    view: vk::BufferView,
    pub buffer: Buffer,
}

impl TexelBuffer {
    /// The whole of `buffer` as texels of `format`; the buffer needs the
    /// `UNIFORM_TEXEL_BUFFER` usage.
    pub fn new(name: &str, buffer: Buffer, format: vk::Format) -> Result<Self> {
        let info = vk::BufferViewCreateInfo::default()
            .buffer(buffer.raw)
            .format(format)
            .offset(0)
            .range(vk::WHOLE_SIZE);
        let ctx = &buffer.ctx;
        let view = unsafe { ctx.device.create_buffer_view(&info, None) }
            .with_context(|| format!("creating the texel view of buffer {name}"))?;
        ctx.set_name(view, name);
        Ok(Self { view, buffer })
    }

    pub fn view(&self) -> vk::BufferView {
        self.view
    }
}

impl Drop for TexelBuffer {
    fn drop(&mut self) {
        unsafe { self.buffer.ctx.device.destroy_buffer_view(self.view, None) };
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        unsafe { self.ctx.device.destroy_buffer(self.raw, None) };
        if let Some(allocation) = self.allocation.take() {
            let _ = self.ctx.allocator.lock().unwrap().free(allocation);
        }
    }
}

/// What to create an [`Image`] with.
#[derive(Clone, Copy, Debug)]
pub struct ImageDesc {
    pub format: vk::Format,
    pub extent: vk::Extent3D,
    pub image_type: vk::ImageType,
    pub mip_levels: u32,
    pub layers: u32,
    pub usage: vk::ImageUsageFlags,
}

impl ImageDesc {
    /// A cubic 3D image of edge `n` with `mip_levels` levels.
    pub fn d3(format: vk::Format, n: u32, mip_levels: u32, usage: vk::ImageUsageFlags) -> Self {
        Self {
            format,
            extent: vk::Extent3D {
                width: n,
                height: n,
                depth: n,
            },
            image_type: vk::ImageType::TYPE_3D,
            mip_levels,
            layers: 1,
            usage,
        }
    }

    pub fn d2(format: vk::Format, width: u32, height: u32, usage: vk::ImageUsageFlags) -> Self {
        Self {
            format,
            extent: vk::Extent3D {
                width,
                height,
                depth: 1,
            },
            image_type: vk::ImageType::TYPE_2D,
            mip_levels: 1,
            layers: 1,
            usage,
        }
    }
}

/// An image, its memory and one view of all its levels and layers.
pub struct Image {
    pub raw: vk::Image,
    pub view: vk::ImageView,
    pub desc: ImageDesc,
    pub aspect: vk::ImageAspectFlags,
    allocation: Option<Allocation>,
    ctx: Arc<Context>,
}

pub fn is_depth_format(format: vk::Format) -> bool {
    matches!(
        format,
        vk::Format::D32_SFLOAT
            | vk::Format::D16_UNORM
            | vk::Format::D24_UNORM_S8_UINT
            | vk::Format::D32_SFLOAT_S8_UINT
    )
}

impl Image {
    pub fn new(ctx: &Arc<Context>, name: &str, desc: ImageDesc) -> Result<Self> {
        let info = vk::ImageCreateInfo::default()
            .image_type(desc.image_type)
            .format(desc.format)
            .extent(desc.extent)
            .mip_levels(desc.mip_levels)
            .array_layers(desc.layers)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(desc.usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        let raw = unsafe { ctx.device.create_image(&info, None) }.with_context(|| {
            format!(
                "creating image {name} ({:?} {:?})",
                desc.format, desc.extent
            )
        })?;
        let requirements = unsafe { ctx.device.get_image_memory_requirements(raw) };
        let allocation = ctx
            .allocator
            .lock()
            .unwrap()
            .allocate(&AllocationCreateDesc {
                name,
                requirements,
                location: MemoryLocation::GpuOnly,
                linear: false,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .with_context(|| format!("allocating {} bytes for image {name}", requirements.size))?;
        unsafe {
            ctx.device
                .bind_image_memory(raw, allocation.memory(), allocation.offset())
        }?;
        let aspect = if is_depth_format(desc.format) {
            vk::ImageAspectFlags::DEPTH
        } else {
            vk::ImageAspectFlags::COLOR
        };
        let view_type = match (desc.image_type, desc.layers) {
            (vk::ImageType::TYPE_3D, _) => vk::ImageViewType::TYPE_3D,
            (_, 1) => vk::ImageViewType::TYPE_2D,
            _ => vk::ImageViewType::TYPE_2D_ARRAY,
        };
        let view_info = vk::ImageViewCreateInfo::default()
            .image(raw)
            .view_type(view_type)
            .format(desc.format)
            .subresource_range(vk::ImageSubresourceRange {
                aspect_mask: aspect,
                base_mip_level: 0,
                level_count: desc.mip_levels,
                base_array_layer: 0,
                layer_count: desc.layers,
            });
        let view = unsafe { ctx.device.create_image_view(&view_info, None) }?;
        ctx.set_name(raw, name);
        ctx.set_name(view, name);
        Ok(Self {
            raw,
            view,
            desc,
            aspect,
            allocation: Some(allocation),
            ctx: ctx.clone(),
        })
    }

    /// A view of one layer and one mip level (a render target of a layered image, or one
    /// level of a 3D image).
    pub fn layer_view(&self, layer: u32, level: u32) -> Result<OwnedView> {
        let view_type = if self.desc.image_type == vk::ImageType::TYPE_3D {
            vk::ImageViewType::TYPE_3D
        } else {
            vk::ImageViewType::TYPE_2D
        };
        let info = vk::ImageViewCreateInfo::default()
            .image(self.raw)
            .view_type(view_type)
            .format(self.desc.format)
            .subresource_range(vk::ImageSubresourceRange {
                aspect_mask: self.aspect,
                base_mip_level: level,
                level_count: 1,
                base_array_layer: layer,
                layer_count: 1,
            });
        let raw = unsafe { self.ctx.device.create_image_view(&info, None) }?;
        Ok(OwnedView {
            raw,
            ctx: self.ctx.clone(),
        })
    }

    pub fn full_range(&self) -> vk::ImageSubresourceRange {
        vk::ImageSubresourceRange {
            aspect_mask: self.aspect,
            base_mip_level: 0,
            level_count: self.desc.mip_levels,
            base_array_layer: 0,
            layer_count: self.desc.layers,
        }
    }

    pub fn extent_2d(&self) -> vk::Extent2D {
        vk::Extent2D {
            width: self.desc.extent.width,
            height: self.desc.extent.height,
        }
    }

    /// Bytes of GPU memory this image holds.
    pub fn memory_bytes(&self) -> u64 {
        self.allocation.as_ref().map_or(0, |a| a.size())
    }
}

impl Drop for Image {
    fn drop(&mut self) {
        unsafe {
            self.ctx.device.destroy_image_view(self.view, None);
            self.ctx.device.destroy_image(self.raw, None);
        }
        if let Some(allocation) = self.allocation.take() {
            let _ = self.ctx.allocator.lock().unwrap().free(allocation);
        }
    }
}

/// An extra image view, destroyed when dropped (drop it before its image).
pub struct OwnedView {
    pub raw: vk::ImageView,
    ctx: Arc<Context>,
}

impl Drop for OwnedView {
    fn drop(&mut self) {
        unsafe { self.ctx.device.destroy_image_view(self.raw, None) };
    }
}

/// Sampler settings with one filter for magnification, minification and mips, and one
/// address mode on every axis; callers add what else they need.
pub fn sampler_info(
    filter: vk::Filter,
    address: vk::SamplerAddressMode,
) -> vk::SamplerCreateInfo<'static> {
    let mipmap = if filter == vk::Filter::LINEAR {
        vk::SamplerMipmapMode::LINEAR
    } else {
        vk::SamplerMipmapMode::NEAREST
    };
    vk::SamplerCreateInfo::default()
        .mag_filter(filter)
        .min_filter(filter)
        .mipmap_mode(mipmap)
        .address_mode_u(address)
        .address_mode_v(address)
        .address_mode_w(address)
        .max_lod(vk::LOD_CLAMP_NONE)
}

/// A sampler, destroyed when dropped.
pub struct Sampler {
    pub raw: vk::Sampler,
    ctx: Arc<Context>,
}

impl Sampler {
    pub fn new(ctx: &Arc<Context>, name: &str, info: &vk::SamplerCreateInfo) -> Result<Self> {
        let raw = unsafe { ctx.device.create_sampler(info, None) }?;
        ctx.set_name(raw, name);
        Ok(Self {
            raw,
            ctx: ctx.clone(),
        })
    }
}

impl Drop for Sampler {
    fn drop(&mut self) {
        unsafe { self.ctx.device.destroy_sampler(self.raw, None) };
    }
}

/// Uploads `data` into a new device-local buffer through a staging buffer.
pub fn upload_buffer(
    ctx: &Arc<Context>,
    one_shot: &super::OneShot,
    name: &str,
    data: &[u8],
    usage: vk::BufferUsageFlags,
) -> Result<Buffer> {
    let staging = Buffer::with_data(
        ctx,
        &format!("{name} staging"),
        data,
        vk::BufferUsageFlags::TRANSFER_SRC,
    )?;
    let buffer = Buffer::new(
        ctx,
        name,
        data.len() as u64,
        usage | vk::BufferUsageFlags::TRANSFER_DST,
        MemoryLocation::GpuOnly,
    )?;
    one_shot.run(&format!("upload {name}"), |cmd| {
        let region = vk::BufferCopy {
            src_offset: 0,
            dst_offset: 0,
            size: data.len().max(4) as u64,
        };
        unsafe {
            ctx.device
                .cmd_copy_buffer(cmd, staging.raw, buffer.raw, &[region])
        };
        Ok(())
    })?;
    Ok(buffer)
}
