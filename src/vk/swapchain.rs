//! Window surface and swapchain.

use std::sync::Arc;

use anyhow::{bail, Context as _, Result};
use ash::vk;

use super::Context;

pub struct Swapchain {
    pub raw: vk::SwapchainKHR,
    pub format: vk::Format,
    pub extent: vk::Extent2D,
    pub images: Vec<vk::Image>,
    pub views: Vec<vk::ImageView>,
    /// One per image: signalled by the frame that renders into the image, waited by present.
    pub rendered: Vec<vk::Semaphore>,
    /// Images can be copied out (screenshots).
    pub readable: bool,
    pub loader: ash::khr::swapchain::Device,
    pub surface: vk::SurfaceKHR,
    pub surface_loader: ash::khr::surface::Instance,
    ctx: Arc<Context>,
}

/// The outcome of acquiring an image.
pub enum Acquired {
    /// The image index, and whether the swapchain should be recreated after this frame.
    Image(u32, bool),
    /// The swapchain no longer matches the window; recreate it.
    OutOfDate,
}

impl Swapchain {
    pub fn new(ctx: &Arc<Context>, surface: vk::SurfaceKHR, extent: vk::Extent2D) -> Result<Self> {
        let surface_loader = ash::khr::surface::Instance::new(&ctx.entry, &ctx.instance);
        let supported = unsafe {
            surface_loader.get_physical_device_surface_support(
                ctx.physical_device,
                ctx.queue_family,
                surface,
            )
        }?;
        if !supported {
            bail!(
                "the Vulkan device {} cannot present to this window",
                ctx.device_name()
            );
        }
        let formats = unsafe {
            surface_loader.get_physical_device_surface_formats(ctx.physical_device, surface)
        }?;
        let format = formats
            .iter()
            .find(|f| {
                matches!(
                    f.format,
                    vk::Format::B8G8R8A8_SRGB | vk::Format::R8G8B8A8_SRGB
                ) && f.color_space == vk::ColorSpaceKHR::SRGB_NONLINEAR
            })
            .copied()
            .context("the window surface offers no 8-bit sRGB format")?;
        let mut swapchain = Self {
            raw: vk::SwapchainKHR::null(),
            format: format.format,
            extent,
            images: Vec::new(),
            views: Vec::new(),
            rendered: Vec::new(),
            readable: false,
            loader: ash::khr::swapchain::Device::new(&ctx.instance, &ctx.device),
            surface,
            surface_loader,
            ctx: ctx.clone(),
        };
        swapchain.recreate(extent)?;
        Ok(swapchain)
    }

    /// Builds the swapchain for `extent` (clamped to what the surface allows); the caller
    /// has waited for frames that use the old one.
    pub fn recreate(&mut self, extent: vk::Extent2D) -> Result<()> {
        let ctx = self.ctx.clone();
        let caps = unsafe {
            self.surface_loader
                .get_physical_device_surface_capabilities(ctx.physical_device, self.surface)
        }?;
        let extent = if caps.current_extent.width != u32::MAX {
            caps.current_extent
        } else {
            vk::Extent2D {
                width: extent
                    .width
                    .clamp(caps.min_image_extent.width, caps.max_image_extent.width),
                height: extent
                    .height
                    .clamp(caps.min_image_extent.height, caps.max_image_extent.height),
            }
        };
        let mut image_count = caps.min_image_count + 1;
        if caps.max_image_count > 0 {
            image_count = image_count.min(caps.max_image_count);
        }
        let mut usage = vk::ImageUsageFlags::COLOR_ATTACHMENT;
        self.readable = caps
            .supported_usage_flags
            .contains(vk::ImageUsageFlags::TRANSFER_SRC);
        if self.readable {
            usage |= vk::ImageUsageFlags::TRANSFER_SRC;
        }
        let old = self.raw;
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(self.surface)
            .min_image_count(image_count)
            .image_format(self.format)
            .image_color_space(vk::ColorSpaceKHR::SRGB_NONLINEAR)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(usage)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(vk::CompositeAlphaFlagsKHR::OPAQUE)
            .present_mode(vk::PresentModeKHR::FIFO)
            .clipped(true)
            .old_swapchain(old);
        let raw = unsafe { self.loader.create_swapchain(&info, None) }
            .context("creating the swapchain")?;
        // The frames are done, but a present may still wait on an image's `rendered`
        // semaphore: no fence or timeline value covers a present's waits, only an idle
        // device does (without VK_EXT_swapchain_maintenance1's present fences).
        unsafe { ctx.device.device_wait_idle() }.context("waiting for the last present")?;
        self.destroy_images();
        if old != vk::SwapchainKHR::null() {
            unsafe { self.loader.destroy_swapchain(old, None) };
        }
        self.raw = raw;
        self.extent = extent;
        self.images = unsafe { self.loader.get_swapchain_images(raw) }?;
        for (i, &image) in self.images.iter().enumerate() {
            let view_info = vk::ImageViewCreateInfo::default()
                .image(image)
                .view_type(vk::ImageViewType::TYPE_2D)
                .format(self.format)
                .subresource_range(vk::ImageSubresourceRange {
                    aspect_mask: vk::ImageAspectFlags::COLOR,
                    base_mip_level: 0,
                    level_count: 1,
                    base_array_layer: 0,
                    layer_count: 1,
                });
            self.views
                .push(unsafe { ctx.device.create_image_view(&view_info, None) }?);
            let semaphore = unsafe {
                ctx.device
                    .create_semaphore(&vk::SemaphoreCreateInfo::default(), None)
            }?;
            ctx.set_name(semaphore, &format!("swapchain image {i} rendered"));
            self.rendered.push(semaphore);
        }
        Ok(())
    }

    pub fn acquire(&self, signal: vk::Semaphore) -> Result<Acquired> {
        match unsafe {
            self.loader
                .acquire_next_image(self.raw, u64::MAX, signal, vk::Fence::null())
        } {
            Ok((index, suboptimal)) => Ok(Acquired::Image(index, suboptimal)),
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => Ok(Acquired::OutOfDate),
            Err(e) => Err(e).context("acquiring a swapchain image"),
        }
    }

    /// Presents image `index` once its frame is rendered; false if the swapchain must be
    /// recreated.
    pub fn present(&self, index: u32) -> Result<bool> {
        let waits = [self.rendered[index as usize]];
        let swapchains = [self.raw];
        let indices = [index];
        let info = vk::PresentInfoKHR::default()
            .wait_semaphores(&waits)
            .swapchains(&swapchains)
            .image_indices(&indices);
        match unsafe { self.loader.queue_present(self.ctx.queue, &info) } {
            Ok(false) => Ok(true),
            Ok(true) | Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => Ok(false),
            Err(e) => Err(e).context("presenting"),
        }
    }

    fn destroy_images(&mut self) {
        unsafe {
            for view in self.views.drain(..) {
                self.ctx.device.destroy_image_view(view, None);
            }
            for semaphore in self.rendered.drain(..) {
                self.ctx.device.destroy_semaphore(semaphore, None);
            }
        }
    }
}

impl Drop for Swapchain {
    fn drop(&mut self) {
        unsafe {
            let _ = self.ctx.device.device_wait_idle();
        }
        self.destroy_images();
        unsafe {
            self.loader.destroy_swapchain(self.raw, None);
            self.surface_loader.destroy_surface(self.surface, None);
        }
    }
}
