//! The images a pass renders into: an attachment that remembers its last access, the
//! multisampled targets of a camera pass, and the window's swapchain.

#[cfg(feature = "viewer")]
pub(crate) mod swapchain;

use crate::gpu::barrier::{image_barrier, Access};
use crate::gpu::context::{Context, GpuError};
use crate::gpu::Image;
use crate::render::passes::camera::DEPTH_FORMAT;
use ash::vk;
use std::sync::Arc;

/// An image rendered into, with the access it was last used with; `transition` records the
/// barrier to the next access and remembers it, so no caller tracks layouts by hand.
pub struct Attachment {
    /// Image.
    pub image: vk::Image,
    /// View.
    pub view: vk::ImageView,
    /// Colour or depth.
    pub aspect: vk::ImageAspectFlags,
    /// Last access.
    pub state: Access,
}

impl Attachment {
    /// An attachment for a not yet used `Image`.
    pub fn of(image: &Image) -> Self {
        Self {
            image: image.raw,
            view: image.view,
            aspect: image.aspect,
            state: Access::Undefined,
        }
    }

    /// Records a barrier from the last access to `to`, and remembers `to`.
    pub fn transition(&mut self, device: &ash::Device, cmd: vk::CommandBuffer, to: Access) {
        image_barrier(device, cmd, self.image, self.aspect, 0..1, self.state, to);
        self.state = to;
    }
}

/// The multisampled colour and depth images a camera pass renders into when MSAA is on; it
/// resolves them into the target's single-sample images.
pub struct MsaaTargets {
    _color: Image,
    _depth: Image,
    /// The multisampled colour attachment.
    pub color: Attachment,
    /// The multisampled depth attachment.
    pub depth: Attachment,
    /// Their size (the window compares it on resize).
    #[cfg_attr(not(feature = "viewer"), allow(dead_code))]
    pub extent: vk::Extent2D,
    /// The colour image's format.
    #[cfg_attr(not(feature = "viewer"), allow(dead_code))]
    pub color_format: vk::Format,
}

impl MsaaTargets {
    /// Colour (`format`) and depth images of `extent` at `samples` per pixel.
    pub fn new(
        ctx: &Arc<Context>,
        format: vk::Format,
        extent: vk::Extent2D,
        samples: u32,
    ) -> Result<Self, GpuError> {
        let color = Image::new_multisampled(
            ctx,
            "multisampled colour",
            format,
            extent,
            samples,
            vk::ImageUsageFlags::COLOR_ATTACHMENT,
        )?;
        let depth = Image::new_multisampled(
            ctx,
            "multisampled depth",
            DEPTH_FORMAT,
            extent,
            samples,
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
        )?;
        Ok(Self {
            color: Attachment::of(&color),
            depth: Attachment::of(&depth),
            _color: color,
            _depth: depth,
            extent,
            color_format: format,
        })
    }
}
