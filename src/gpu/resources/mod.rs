//! Buffers and images that free themselves on drop.

mod texture;

pub use texture::blit_linear;

use super::context::{Context, GpuError, VkCheck};
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

/// A named allocation from the context's allocator.
fn allocate(
    ctx: &Context,
    name: &str,
    requirements: vk::MemoryRequirements,
    location: MemoryLocation,
    linear: bool,
) -> Result<Allocation, GpuError> {
    ctx.allocator()
        .allocate(&AllocationCreateDesc {
            name,
            requirements,
            location,
            linear,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        })
        .map_err(|e| GpuError::Alloc {
            name: name.into(),
            message: e.to_string(),
        })
}

/// A buffer with its memory.
pub struct Buffer {
    ctx: Arc<Context>,
    /// The Vulkan handle.
    pub raw: vk::Buffer,
    /// Size in bytes.
    #[cfg_attr(not(feature = "viewer"), allow(dead_code))]
    pub size: u64,
    allocation: Option<Allocation>,
}

impl Buffer {
    /// Creates a named buffer in `location`.
    pub fn new(
        ctx: &Arc<Context>,
        name: &str,
        size: u64,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
    ) -> Result<Self, GpuError> {
        let size = size.max(4);
        let info = vk::BufferCreateInfo::default()
            .size(size)
            .usage(usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        let raw = unsafe { ctx.device.create_buffer(&info, None) }.vk("vkCreateBuffer")?;
        // Owned from here on: an error below drops `buffer`, which frees what exists.
        let mut buffer = Self {
            ctx: ctx.clone(),
            raw,
            size,
            allocation: None,
        };
        let requirements = unsafe { ctx.device.get_buffer_memory_requirements(raw) };
        let allocation =
            buffer
                .allocation
                .insert(allocate(ctx, name, requirements, location, true)?);
        unsafe {
            ctx.device
                .bind_buffer_memory(raw, allocation.memory(), allocation.offset())
        }
        .vk("vkBindBufferMemory")?;
        ctx.set_name(raw, name);
        Ok(buffer)
    }

    /// The mapped bytes of a host-visible buffer.
    pub fn mapped(&mut self) -> Option<&mut [u8]> {
        self.allocation.as_mut().and_then(|a| a.mapped_slice_mut())
    }

    /// Writes `data` at `offset` into a host-visible buffer.
    pub fn write(&mut self, offset: usize, data: &[u8]) -> Result<(), GpuError> {
        let m = self
            .mapped()
            .ok_or_else(|| GpuError::Unsupported("buffer is not host visible".into()))?;
        let end = offset + data.len();
        if end > m.len() {
            return Err(GpuError::Unsupported(format!(
                "write of {} bytes at {offset} past buffer end {}",
                data.len(),
                m.len()
            )));
        }
        m[offset..end].copy_from_slice(data);
        Ok(())
    }

    /// A device-local buffer filled with `data` through a staging buffer.
    pub fn device_local_with_data(
        ctx: &Arc<Context>,
        name: &str,
        usage: vk::BufferUsageFlags,
        data: &[u8],
    ) -> Result<Self, GpuError> {
        let mut staging = Buffer::new(
            ctx,
            &format!("{name} staging"),
            data.len() as u64,
            vk::BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::CpuToGpu,
        )?;
        staging.write(0, data)?;
        let buf = Buffer::new(
            ctx,
            name,
            data.len() as u64,
            usage | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuOnly,
        )?;
        ctx.immediate(|cmd| unsafe {
            let region = [vk::BufferCopy {
                src_offset: 0,
                dst_offset: 0,
                size: data.len().max(4) as u64,
            }];
            ctx.device
                .cmd_copy_buffer(cmd, staging.raw, buf.raw, &region);
        })?;
        Ok(buf)
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        if let Some(a) = self.allocation.take() {
            let _ = self.ctx.allocator().free(a);
        }
        self.ctx.clear_name(self.raw);
        unsafe { self.ctx.device.destroy_buffer(self.raw, None) };
    }
}

/// The aspects of an image of `format`: depth, depth and stencil, or colour.
pub fn aspect_of(format: vk::Format) -> vk::ImageAspectFlags {
    match format {
        vk::Format::D32_SFLOAT | vk::Format::D16_UNORM | vk::Format::X8_D24_UNORM_PACK32 => {
            vk::ImageAspectFlags::DEPTH
        }
        vk::Format::D32_SFLOAT_S8_UINT
        | vk::Format::D24_UNORM_S8_UINT
        | vk::Format::D16_UNORM_S8_UINT => {
            vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL
        }
        _ => vk::ImageAspectFlags::COLOR,
    }
}

/// Whether depth format `f` has a stencil aspect.
pub fn has_stencil(f: vk::Format) -> bool {
    aspect_of(f).contains(vk::ImageAspectFlags::STENCIL)
}

/// A 2-D image with one view over all its mip levels.
pub struct Image {
    ctx: Arc<Context>,
    /// The Vulkan handle.
    pub raw: vk::Image,
    /// View over all mips.
    pub view: vk::ImageView,
    /// Format.
    pub format: vk::Format,
    /// Size in pixels.
    pub extent: vk::Extent2D,
    /// Aspect (colour or depth).
    pub aspect: vk::ImageAspectFlags,
    /// One 2-D view per layer of an array image (`new_array`, to render into); empty otherwise.
    pub layer_views: Vec<vk::ImageView>,
    allocation: Option<Allocation>,
}

/// The size and layout of an image `Image::create` makes.
#[derive(Clone, Copy)]
struct Shape {
    extent: vk::Extent2D,
    mip_levels: u32,
    /// Layer count of an array image; `None`: a plain 2-D image.
    array: Option<u32>,
    samples: u32,
}

/// A 2D image's create info: `shape`, optimal tiling, exclusive, undefined at first.
fn image_info(
    format: vk::Format,
    shape: &Shape,
    usage: vk::ImageUsageFlags,
) -> vk::ImageCreateInfo<'static> {
    vk::ImageCreateInfo::default()
        .image_type(vk::ImageType::TYPE_2D)
        .format(format)
        .extent(vk::Extent3D {
            width: shape.extent.width.max(1),
            height: shape.extent.height.max(1),
            depth: 1,
        })
        .mip_levels(shape.mip_levels.max(1))
        .array_layers(shape.array.unwrap_or(1))
        .samples(vk::SampleCountFlags::from_raw(shape.samples.max(1)))
        .tiling(vk::ImageTiling::OPTIMAL)
        .usage(usage)
        .sharing_mode(vk::SharingMode::EXCLUSIVE)
        .initial_layout(vk::ImageLayout::UNDEFINED)
}

impl Image {
    /// Creates a named device-local 2-D image and its view.
    pub fn new(
        ctx: &Arc<Context>,
        name: &str,
        format: vk::Format,
        extent: vk::Extent2D,
        mip_levels: u32,
        usage: vk::ImageUsageFlags,
    ) -> Result<Self, GpuError> {
        Self::create(
            ctx,
            name,
            format,
            Shape {
                extent,
                mip_levels,
                array: None,
                samples: 1,
            },
            usage,
        )
    }

    /// Creates a named device-local multisampled 2-D image of `samples` samples per pixel (one
    /// mip level; a render target to resolve from).
    pub fn new_multisampled(
        ctx: &Arc<Context>,
        name: &str,
        format: vk::Format,
        extent: vk::Extent2D,
        samples: u32,
        usage: vk::ImageUsageFlags,
    ) -> Result<Self, GpuError> {
        Self::create(
            ctx,
            name,
            format,
            Shape {
                extent,
                mip_levels: 1,
                array: None,
                samples,
            },
            usage,
        )
    }

    /// Creates a named device-local 2-D array image of `layers` layers (at least 1), one mip
    /// level: `view` is a 2-D array view of every layer, `layer_views` a 2-D view per layer.
    pub fn new_array(
        ctx: &Arc<Context>,
        name: &str,
        format: vk::Format,
        extent: vk::Extent2D,
        layers: u32,
        usage: vk::ImageUsageFlags,
    ) -> Result<Self, GpuError> {
        Self::create(
            ctx,
            name,
            format,
            Shape {
                extent,
                mip_levels: 1,
                array: Some(layers.max(1)),
                samples: 1,
            },
            usage,
        )
    }

    /// `new` (`array` None) or `new_array` (`array` = its layer count), `samples` per pixel.
    fn create(
        ctx: &Arc<Context>,
        name: &str,
        format: vk::Format,
        shape: Shape,
        usage: vk::ImageUsageFlags,
    ) -> Result<Self, GpuError> {
        let Shape {
            extent,
            mip_levels,
            array,
            ..
        } = shape;
        let layers = array.unwrap_or(1);
        let info = image_info(format, &shape, usage);
        let raw = unsafe { ctx.device.create_image(&info, None) }.vk("vkCreateImage")?;
        let aspect = aspect_of(format);
        // Owned from here on: an error below drops `image`, which frees what exists.
        let mut image = Self {
            ctx: ctx.clone(),
            raw,
            view: vk::ImageView::null(),
            format,
            extent,
            aspect,
            layer_views: Vec::new(),
            allocation: None,
        };
        let requirements = unsafe { ctx.device.get_image_memory_requirements(raw) };
        let allocation = image.allocation.insert(allocate(
            ctx,
            name,
            requirements,
            MemoryLocation::GpuOnly,
            false,
        )?);
        unsafe {
            ctx.device
                .bind_image_memory(raw, allocation.memory(), allocation.offset())
        }
        .vk("vkBindImageMemory")?;
        let view_of = |view_type, base_array_layer, layer_count| {
            let view_info = vk::ImageViewCreateInfo::default()
                .image(raw)
                .view_type(view_type)
                .format(format)
                .subresource_range(vk::ImageSubresourceRange {
                    aspect_mask: aspect,
                    base_mip_level: 0,
                    level_count: mip_levels.max(1),
                    base_array_layer,
                    layer_count,
                });
            unsafe { ctx.device.create_image_view(&view_info, None) }.vk("vkCreateImageView")
        };
        if array.is_none() {
            image.view = view_of(vk::ImageViewType::TYPE_2D, 0, 1)?;
        } else {
            image.view = view_of(vk::ImageViewType::TYPE_2D_ARRAY, 0, layers)?;
            for layer in 0..layers {
                let v = view_of(vk::ImageViewType::TYPE_2D, layer, 1)?;
                image.layer_views.push(v);
                ctx.set_name(v, &format!("{name} layer {layer}"));
            }
        }
        ctx.set_name(raw, name);
        ctx.set_name(image.view, name);
        Ok(image)
    }
}

impl Drop for Image {
    fn drop(&mut self) {
        for v in self.layer_views.drain(..) {
            self.ctx.clear_name(v);
            unsafe { self.ctx.device.destroy_image_view(v, None) };
        }
        if self.view != vk::ImageView::null() {
            self.ctx.clear_name(self.view);
            unsafe { self.ctx.device.destroy_image_view(self.view, None) };
        }
        self.ctx.clear_name(self.raw);
        if let Some(a) = self.allocation.take() {
            let _ = self.ctx.allocator().free(a);
        }
        unsafe { self.ctx.device.destroy_image(self.raw, None) };
    }
}
