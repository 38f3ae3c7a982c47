//! What a window's frame records after the scene: the depth readback for a later frame's fit, the
//! screenshot copy and the overlay.

use super::{Capture, DepthRead, Overlay};
use crate::gpu::barrier::Access;
use crate::gpu::{Recorder, Uses};
use crate::render::renderer::copy_attachment_to_buffer;
use crate::render::targets::Attachment;
use ash::vk;

/// Records the copy of a frame's depth into its slot's readback buffer, and keeps the camera
/// projection and pixel count to read it with.
pub(super) fn record_depth_read(
    d: &ash::Device,
    cmd: vk::CommandBuffer,
    depth: &mut Attachment,
    read: &mut DepthRead,
    camera: &crate::scene::Camera,
    extent: vk::Extent2D,
) {
    let buffer = read.0.as_ref().expect("buffer").raw;
    copy_attachment_to_buffer(d, cmd, depth, vk::ImageAspectFlags::DEPTH, extent, buffer);
    let aspect = extent.width as f32 / extent.height.max(1) as f32;
    let pixels = extent.width as usize * extent.height as usize;
    read.1 = Some((crate::plan::camera_projection(camera, aspect), pixels));
}

/// Each shadow view's (light, resolution, texel size in world units).
pub(super) fn shadow_view_summary(plan: &crate::plan::FramePlan) -> Vec<(usize, u32, f32)> {
    plan.shadow_views
        .iter()
        .map(|v| (v.light, v.res, v.texel_world))
        .collect()
}

/// Records the overlay over `color`, and with a screenshot buffer (`shot`: what to capture, where)
/// the copy of `color` into it: before the overlay for `Capture::Scene` (or with no overlay),
/// after it for `Capture::Screen`.
pub(super) fn record_screenshot_and_overlay(
    d: &ash::Device,
    cmd: vk::CommandBuffer,
    color: &mut Attachment,
    extent: vk::Extent2D,
    overlay: Option<&mut dyn Overlay>,
    (capture, shot): (Capture, Option<vk::Buffer>),
) {
    let copy = |color: &mut Attachment, buffer| {
        copy_attachment_to_buffer(d, cmd, color, vk::ImageAspectFlags::COLOR, extent, buffer);
    };
    if let Some(b) = shot {
        if capture == Capture::Scene || overlay.is_none() {
            copy(color, b);
        }
    }
    if let Some(o) = overlay {
        record_overlay(d, cmd, color, extent, o);
        if let (Some(b), Capture::Screen) = (shot, capture) {
            copy(color, b);
        }
    }
}

/// Records `overlay` into a rendering of `color` (loaded and stored, after the scene's writes).
fn record_overlay(
    d: &ash::Device,
    cmd: vk::CommandBuffer,
    color: &mut Attachment,
    extent: vk::Extent2D,
    overlay: &mut dyn Overlay,
) {
    Uses::new()
        .writes(color, Access::ColorAttachment)
        .enter(d, cmd);
    let attachments = [vk::RenderingAttachmentInfo::default()
        .image_view(color.view)
        .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
        .load_op(vk::AttachmentLoadOp::LOAD)
        .store_op(vk::AttachmentStoreOp::STORE)];
    let rendering = vk::RenderingInfo::default()
        .render_area(vk::Rect2D {
            offset: vk::Offset2D::default(),
            extent,
        })
        .layer_count(1)
        .color_attachments(&attachments);
    Recorder::new(d, cmd).begin_rendering(&rendering);
    overlay.record(cmd, extent);
    Recorder::new(d, cmd).end_rendering();
}
