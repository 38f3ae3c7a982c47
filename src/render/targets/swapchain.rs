//! A swapchain on a surface: sRGB format, FIFO (vsync) or the fastest non-blocking present mode,
//! one render-finished semaphore per image. Out-of-date, suboptimal and 0×0 are normal paths.

use crate::gpu::context::{Context, GpuError, VkCheck};
use ash::vk;
use std::sync::Arc;

/// Swapchain and surface (the surface is destroyed with it, before the context).
pub struct Swapchain {
    ctx: Arc<Context>,
    surface_loader: ash::khr::surface::Instance,
    loader: ash::khr::swapchain::Device,
    surface: vk::SurfaceKHR,
    /// The swapchain (null while the window is 0×0).
    pub raw: vk::SwapchainKHR,
    /// Its images.
    pub images: Vec<vk::Image>,
    /// Views of the images.
    pub views: Vec<vk::ImageView>,
    /// Signalled when rendering to image i is done (waited on by present).
    pub render_finished: Vec<vk::Semaphore>,
    /// Colour format.
    pub format: vk::Format,
    /// Size in pixels (0×0 while minimised).
    pub extent: vk::Extent2D,
    /// Whether images can be copied out (screenshots).
    pub can_copy: bool,
    vsync: bool,
}

impl Swapchain {
    /// Takes ownership of `surface` and creates a swapchain of `width`×`height`.
    pub fn new(
        ctx: &Arc<Context>,
        surface: vk::SurfaceKHR,
        width: u32,
        height: u32,
        vsync: bool,
    ) -> Result<Self, GpuError> {
        let surface_loader = ash::khr::surface::Instance::new(&ctx.instance.entry, &ctx.instance);
        let supported = unsafe {
            surface_loader.get_physical_device_surface_support(
                ctx.physical,
                ctx.queue_family,
                surface,
            )
        }
        .unwrap_or(false);
        if !supported {
            unsafe { surface_loader.destroy_surface(surface, None) };
            return Err(GpuError::Unsupported(format!(
                "{} cannot present to this window",
                ctx.device_name
            )));
        }
        let formats =
            unsafe { surface_loader.get_physical_device_surface_formats(ctx.physical, surface) }
                .vk("vkGetPhysicalDeviceSurfaceFormatsKHR")?;
        let format = [vk::Format::B8G8R8A8_SRGB, vk::Format::R8G8B8A8_SRGB]
            .into_iter()
            .find(|f| {
                formats
                    .iter()
                    .any(|s| s.format == *f && s.color_space == vk::ColorSpaceKHR::SRGB_NONLINEAR)
            })
            .ok_or_else(|| {
                GpuError::Unsupported("the window offers no sRGB swapchain format".into())
            })?;
        let loader = ash::khr::swapchain::Device::new(&ctx.instance, &ctx.device);
        let mut s = Self {
            ctx: ctx.clone(),
            surface_loader,
            loader,
            surface,
            raw: vk::SwapchainKHR::null(),
            images: Vec::new(),
            views: Vec::new(),
            render_finished: Vec::new(),
            format,
            extent: vk::Extent2D::default(),
            can_copy: false,
            vsync,
        };
        s.recreate(width, height)?;
        Ok(s)
    }

    /// Recreates for a new window size (waits for the device to go idle). A 0×0 size leaves no
    /// swapchain until the next non-zero one.
    pub fn recreate(&mut self, width: u32, height: u32) -> Result<(), GpuError> {
        let ctx = self.ctx.clone();
        let d = &ctx.device;
        unsafe {
            let _ = d.device_wait_idle();
        }
        self.destroy_views();
        let caps = unsafe {
            self.surface_loader
                .get_physical_device_surface_capabilities(self.ctx.physical, self.surface)
        }
        .vk("vkGetPhysicalDeviceSurfaceCapabilitiesKHR")?;
        let extent = if caps.current_extent.width != u32::MAX {
            caps.current_extent
        } else {
            vk::Extent2D {
                width: width.clamp(caps.min_image_extent.width, caps.max_image_extent.width),
                height: height.clamp(caps.min_image_extent.height, caps.max_image_extent.height),
            }
        };
        if extent.width == 0 || extent.height == 0 || width == 0 || height == 0 {
            if self.raw != vk::SwapchainKHR::null() {
                unsafe { self.loader.destroy_swapchain(self.raw, None) };
                self.raw = vk::SwapchainKHR::null();
            }
            self.extent = vk::Extent2D::default();
            return Ok(());
        }
        let mode = self.present_mode();
        let mut count = caps.min_image_count + 1;
        if caps.max_image_count > 0 {
            count = count.min(caps.max_image_count);
        }
        self.can_copy = caps
            .supported_usage_flags
            .contains(vk::ImageUsageFlags::TRANSFER_SRC);
        let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT
            | if self.can_copy {
                vk::ImageUsageFlags::TRANSFER_SRC
            } else {
                vk::ImageUsageFlags::empty()
            };
        let old = self.raw;
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(self.surface)
            .min_image_count(count)
            .image_format(self.format)
            .image_color_space(vk::ColorSpaceKHR::SRGB_NONLINEAR)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(usage)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(vk::CompositeAlphaFlagsKHR::OPAQUE)
            .present_mode(mode)
            .clipped(true)
            .old_swapchain(old);
        self.raw =
            unsafe { self.loader.create_swapchain(&info, None) }.vk("vkCreateSwapchainKHR")?;
        if old != vk::SwapchainKHR::null() {
            unsafe { self.loader.destroy_swapchain(old, None) };
        }
        self.extent = extent;
        self.images =
            unsafe { self.loader.get_swapchain_images(self.raw) }.vk("vkGetSwapchainImagesKHR")?;
        self.create_views()?;
        log::info!(
            "swapchain {}x{} {:?} {:?}, {} images",
            extent.width,
            extent.height,
            self.format,
            mode,
            self.images.len()
        );
        Ok(())
    }

    /// FIFO with vsync; without, IMMEDIATE or MAILBOX where the surface offers one.
    fn present_mode(&self) -> vk::PresentModeKHR {
        let modes = unsafe {
            self.surface_loader
                .get_physical_device_surface_present_modes(self.ctx.physical, self.surface)
        }
        .unwrap_or_default();
        if self.vsync {
            vk::PresentModeKHR::FIFO
        } else {
            [vk::PresentModeKHR::IMMEDIATE, vk::PresentModeKHR::MAILBOX]
                .into_iter()
                .find(|m| modes.contains(m))
                .unwrap_or(vk::PresentModeKHR::FIFO)
        }
    }

    /// A view and a "render finished" semaphore for each of the swapchain's images.
    fn create_views(&mut self) -> Result<(), GpuError> {
        let ctx = self.ctx.clone();
        let d = &ctx.device;
        for (i, &img) in self.images.iter().enumerate() {
            let view_info = vk::ImageViewCreateInfo::default()
                .image(img)
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
                .push(unsafe { d.create_image_view(&view_info, None) }.vk("vkCreateImageView")?);
            let sem = unsafe { d.create_semaphore(&vk::SemaphoreCreateInfo::default(), None) }
                .vk("vkCreateSemaphore")?;
            self.ctx.set_name(sem, &format!("render finished {i}"));
            self.render_finished.push(sem);
        }
        Ok(())
    }

    fn destroy_views(&mut self) {
        let d = &self.ctx.device;
        unsafe {
            for v in self.views.drain(..) {
                d.destroy_image_view(v, None);
            }
            for s in self.render_finished.drain(..) {
                d.destroy_semaphore(s, None);
            }
        }
        self.images.clear();
    }

    /// Acquires the next image, signalling `semaphore`. `Ok(None)` means out of date: recreate.
    pub fn acquire(&self, semaphore: vk::Semaphore) -> Result<Option<(u32, bool)>, GpuError> {
        match unsafe {
            self.loader
                .acquire_next_image(self.raw, u64::MAX, semaphore, vk::Fence::null())
        } {
            Ok((i, suboptimal)) => Ok(Some((i, suboptimal))),
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => Ok(None),
            Err(e) => Err(GpuError::Vk {
                call: "vkAcquireNextImageKHR",
                result: e,
            }),
        }
    }

    /// Presents image `index` after its render-finished semaphore. Returns true when the
    /// swapchain should be recreated (out of date or suboptimal).
    pub fn present(&self, index: u32) -> Result<bool, GpuError> {
        let waits = [self.render_finished[index as usize]];
        let chains = [self.raw];
        let indices = [index];
        let info = vk::PresentInfoKHR::default()
            .wait_semaphores(&waits)
            .swapchains(&chains)
            .image_indices(&indices);
        match unsafe { self.loader.queue_present(self.ctx.queue, &info) } {
            Ok(suboptimal) => Ok(suboptimal),
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => Ok(true),
            Err(e) => Err(GpuError::Vk {
                call: "vkQueuePresentKHR",
                result: e,
            }),
        }
    }
}

impl Drop for Swapchain {
    fn drop(&mut self) {
        unsafe {
            let _ = self.ctx.device.device_wait_idle();
        }
        self.destroy_views();
        unsafe {
            if self.raw != vk::SwapchainKHR::null() {
                self.loader.destroy_swapchain(self.raw, None);
            }
            self.surface_loader.destroy_surface(self.surface, None);
        }
    }
}
