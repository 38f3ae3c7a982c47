//! Per-pixel outputs besides the image (AOVs), for image tests and datasets: each pixel's surface
//! (instance), world normal and distance along the view axis, from one extra depth-tested pass
//! (`CameraPass::record_aov`) at one sample per pixel.

use super::{copy_to_buffer, transfer_to_host_barrier, Renderer};
use crate::gpu::barrier::Access;
use crate::gpu::context::{GpuError, VkCheck};
use crate::gpu::{Buffer, Image};
use crate::plan::settings::ViewMode;
use crate::plan::view::View;
use crate::plan::FramePlan;
use crate::render::passes::camera::AOV_FORMATS;
use crate::render::targets::Attachment;
use ash::vk;
use gpu_allocator::MemoryLocation;

/// Which AOVs a call reads back (the pass draws all three; only these are copied and read).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AovSet {
    /// `Aovs::instance`.
    pub instance: bool,
    /// `Aovs::normal`.
    pub normal: bool,
    /// `Aovs::depth`.
    pub depth: bool,
}

impl AovSet {
    /// All three.
    pub const ALL: AovSet = AovSet {
        instance: true,
        normal: true,
        depth: true,
    };
}

/// A frame's AOVs, row-major, `width`×`height`; an output not asked for (`AovSet`) is empty.
pub struct Aovs {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Distance from the camera along its view axis, in scene units (the view-space depth, not
    /// the distance to the eye); 0 where no surface is drawn.
    pub depth: Vec<f32>,
    /// The scene instance (`Scene::instances`) drawn at each pixel, plus 1; 0 where none. Exact:
    /// the nearest opaque or alpha-masked surface at the pixel centre (blended surfaces do not
    /// count, as they write no depth).
    pub instance: Vec<u32>,
    /// The interpolated world normal of that surface, facing the camera (zero where none).
    pub normal: Vec<[f32; 3]>,
    /// The plan the frame was drawn with.
    pub plan: FramePlan,
}

/// The AOV pass's images and readbacks, kept between frames of one size.
pub(super) struct AovTarget {
    ids: (Image, Attachment, Buffer),
    normals: (Image, Attachment, Buffer),
    depth: (Image, Attachment, Buffer),
}

impl AovTarget {
    fn new(r: &Renderer, extent: vk::Extent2D) -> Result<Self, GpuError> {
        let ctx = &r.core.ctx;
        let pixels = extent.width as u64 * extent.height as u64;
        let make = |name: &str, format, usage, texel: u64| -> Result<_, GpuError> {
            let image = Image::new(
                ctx,
                name,
                format,
                extent,
                1,
                usage | vk::ImageUsageFlags::TRANSFER_SRC,
            )?;
            let at = Attachment::of(&image);
            let buffer = Buffer::new(
                ctx,
                &format!("{name} readback"),
                pixels * texel,
                vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuToCpu,
            )?;
            Ok((image, at, buffer))
        };
        let color = vk::ImageUsageFlags::COLOR_ATTACHMENT;
        Ok(Self {
            ids: make("AOV instance ids", AOV_FORMATS[0], color, 4)?,
            normals: make("AOV normals", AOV_FORMATS[1], color, 16)?,
            depth: make(
                "AOV depth",
                r.core.camera.depth_format,
                vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
                4,
            )?,
        })
    }
}

impl Renderer {
    /// Renders `view`'s AOVs at `width`×`height` (the camera and culling of `render`, no shadows,
    /// no shading): see [`Aovs`].
    pub fn render_aovs(&mut self, view: &View, width: u32, height: u32) -> Result<Aovs, GpuError> {
        self.render_aovs_of(view, width, height, AovSet::ALL)
    }

    /// `render_aovs`, reading back only the outputs in `set` (the others are left empty).
    pub fn render_aovs_of(
        &mut self,
        view: &View,
        width: u32,
        height: u32,
        set: AovSet,
    ) -> Result<Aovs, GpuError> {
        super::check_size(width, height)?;
        let mut v = view.clone();
        v.mode = ViewMode::Lit;
        v.shadow.enabled = false;
        v.highlight = None;
        let prepared = self.core.prepare(0, &v, width, height)?;
        let extent = vk::Extent2D { width, height };
        if self.aov.as_ref().is_none_or(|t| t.ids.0.extent != extent) {
            self.aov = None;
            self.aov = Some(AovTarget::new(self, extent)?);
        }
        let ctx = self.core.ctx.clone();
        let d = &ctx.device;
        let cmd = self.cmd;
        ctx.begin_one_time(cmd)?;
        let t = self.aov.as_mut().expect("made above");
        self.core.record_aov(
            cmd,
            &prepared,
            (&mut t.ids.1, &mut t.normals.1, &mut t.depth.1),
        )?;
        for (wanted, image, at, buffer, aspect) in [
            (
                set.instance,
                &t.ids.0,
                &mut t.ids.1,
                &t.ids.2,
                vk::ImageAspectFlags::COLOR,
            ),
            (
                set.normal,
                &t.normals.0,
                &mut t.normals.1,
                &t.normals.2,
                vk::ImageAspectFlags::COLOR,
            ),
            (
                set.depth,
                &t.depth.0,
                &mut t.depth.1,
                &t.depth.2,
                vk::ImageAspectFlags::DEPTH,
            ),
        ] {
            if !wanted {
                continue;
            }
            at.transition(d, cmd, Access::TransferSrc);
            copy_to_buffer(d, cmd, image.raw, aspect, extent, buffer.raw);
        }
        transfer_to_host_barrier(d, cmd);
        unsafe { d.end_command_buffer(cmd).vk("vkEndCommandBuffer")? };
        ctx.submit_and_wait_with(cmd, self.fence)?;
        fn read<T: bytemuck::Pod>(b: &mut Buffer, n: usize) -> Result<Vec<T>, GpuError> {
            if n == 0 {
                return Ok(Vec::new());
            }
            let m = b
                .mapped()
                .ok_or_else(|| GpuError::Unsupported("readback not mapped".into()))?;
            Ok(bytemuck::pod_collect_to_vec(&m[..n * size_of::<T>()]))
        }
        let n = |wanted: bool| if wanted { (width * height) as usize } else { 0 };
        let ids: Vec<u32> = read(&mut t.ids.2, n(set.instance))?;
        let normals: Vec<[f32; 4]> = read(&mut t.normals.2, n(set.normal))?;
        let depth: Vec<f32> = read(&mut t.depth.2, n(set.depth))?;
        let plan = prepared.plan;
        let aspect = width as f32 / height.max(1) as f32;
        let proj = crate::plan::camera_projection(&view.camera, aspect);
        Ok(Aovs {
            width,
            height,
            depth: super::view_axis_depths(&depth, &proj),
            instance: ids,
            normal: normals.iter().map(|n| [n[0], n[1], n[2]]).collect(),
            plan,
        })
    }
}
