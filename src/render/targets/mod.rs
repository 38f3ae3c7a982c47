//! The images a pass renders into: the multisampled targets of a camera pass and the window's
//! swapchain (an `Attachment`, the image and its last access, is `gpu::graph`'s).

#[cfg(feature = "viewer")]
pub(crate) mod swapchain;

use crate::gpu::context::{Context, GpuError};
pub(crate) use crate::gpu::Attachment;
use crate::gpu::Image;
use crate::render::passes::camera::DEPTH_FORMAT;
use ash::vk;
use std::sync::Arc;

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
