//! Per-pixel outputs besides the image (AOVs), for image tests and datasets: each pixel's surface
//! (instance), world normal and distance along the view axis. With the image at one sample per
//! pixel they are targets of the camera pass itself (`Renderer::render_with_aovs`); otherwise,
//! and alone, they come from one extra depth-tested pass (`CameraPass::record_aov`) at one
//! sample per pixel.

use super::{copy_attachment_to_buffer, transfer_to_host_barrier, RenderedFrame, Renderer};
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

/// Instance ids, normals and reversed-z depths as read back (`AovTarget::read`).
type ReadAovs = (Vec<u32>, Vec<[f32; 3]>, Vec<f32>);

/// Instance ids and normals drawn by a camera pass, as read back.
pub(super) type IdsNormals = (Vec<u32>, Vec<[f32; 3]>);

/// An AOV target's image, its attachment state and a readback per ring slot.
type Output = (Image, Attachment, [Buffer; super::ring::RING]);

/// The AOV pass's images and readbacks, kept between frames of one size.
pub(super) struct AovTarget {
    ids: Output,
    normals: Output,
    depth: Output,
}

impl AovTarget {
    /// The images and readbacks of `r` at `extent` (made again when the size changed).
    pub(super) fn ensure(r: &mut Renderer, extent: vk::Extent2D) -> Result<(), GpuError> {
        if r.aov.as_ref().is_none_or(|t| t.ids.0.extent != extent) {
            r.aov = None;
            r.aov = Some(AovTarget::new(r, extent)?);
        }
        Ok(())
    }

    /// The id and normal targets of the outputs in `set`, for a camera pass that draws them
    /// (`None`: not asked for, so not drawn).
    pub(super) fn color_targets(
        &mut self,
        set: AovSet,
    ) -> (Option<&mut Attachment>, Option<&mut Attachment>) {
        (
            Some(&mut self.ids.1).filter(|_| set.instance),
            Some(&mut self.normals.1).filter(|_| set.normal),
        )
    }

    /// Records the copies of the outputs in `set` into ring slot `slot`'s readbacks (`depth`:
    /// of this target's depth image, drawn by the AOV pass); the caller makes them visible to
    /// the host.
    pub(super) fn record_copies(
        &mut self,
        d: &ash::Device,
        cmd: vk::CommandBuffer,
        set: AovSet,
        depth: bool,
        slot: usize,
    ) {
        let extent = self.ids.0.extent;
        let color = vk::ImageAspectFlags::COLOR;
        for (wanted, (_, at, buffers), aspect) in [
            (set.instance, &mut self.ids, color),
            (set.normal, &mut self.normals, color),
            (
                set.depth && depth,
                &mut self.depth,
                vk::ImageAspectFlags::DEPTH,
            ),
        ] {
            if wanted {
                copy_attachment_to_buffer(d, cmd, at, aspect, extent, buffers[slot].raw);
            }
        }
    }

    /// The (ids, normals, depth) in ring slot `slot`'s readbacks, each empty where `set` (or
    /// `depth`) left it out.
    pub(super) fn read(
        &mut self,
        set: AovSet,
        depth: bool,
        slot: usize,
    ) -> Result<ReadAovs, GpuError> {
        fn read<T: bytemuck::Pod>(b: &mut Buffer, n: usize) -> Result<Vec<T>, GpuError> {
            if n == 0 {
                return Ok(Vec::new());
            }
            let m = b
                .mapped()
                .ok_or_else(|| GpuError::Unsupported("readback not mapped".into()))?;
            Ok(bytemuck::pod_collect_to_vec(&m[..n * size_of::<T>()]))
        }
        let e = self.ids.0.extent;
        let n = |wanted: bool| {
            if wanted {
                (e.width * e.height) as usize
            } else {
                0
            }
        };
        let ids = read(&mut self.ids.2[slot], n(set.instance))?;
        let normals: Vec<[f32; 4]> = read(&mut self.normals.2[slot], n(set.normal))?;
        let depth = read(&mut self.depth.2[slot], n(set.depth && depth))?;
        let normals = normals.iter().map(|n| [n[0], n[1], n[2]]).collect();
        Ok((ids, normals, depth))
    }

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
            let buffer = |i| {
                Buffer::new(
                    ctx,
                    &format!("{name} readback {i}"),
                    pixels * texel,
                    vk::BufferUsageFlags::TRANSFER_DST,
                    MemoryLocation::GpuToCpu,
                )
            };
            Ok((image, at, super::ring::ring_of(buffer)?))
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
        AovTarget::ensure(self, extent)?;
        let ctx = self.core.ctx.clone();
        let d = &ctx.device;
        let cmd = self.cmds[0];
        ctx.begin_one_time(cmd)?;
        let t = self.aov.as_mut().expect("made above");
        self.core.record_aov(
            cmd,
            &prepared,
            (&mut t.ids.1, &mut t.normals.1, &mut t.depth.1),
        )?;
        t.record_copies(d, cmd, set, true, 0);
        transfer_to_host_barrier(d, cmd);
        unsafe { d.end_command_buffer(cmd).vk("vkEndCommandBuffer")? };
        ctx.submit_and_wait_with(cmd, self.fences[0])?;
        let (instance, normal, depth) = t.read(set, true, 0)?;
        Ok(aovs_of(
            view,
            (width, height),
            (instance, normal, &depth),
            prepared.plan,
        ))
    }

    /// Renders `view` as [`Renderer::render`] does, with its AOVs (those in `set`): at one
    /// sample per pixel the camera pass draws the ids and normals as two more targets and the
    /// depth is its own depth buffer (one pass over the scene; the image is the same to the
    /// byte, and the AOVs are those of `render_aovs_of`, as tests check); otherwise (MSAA,
    /// supersampling, a debug view) the AOV pass draws them after the image. Depth alone adds
    /// no target at one sample per pixel: it is the frame's depth buffer.
    pub fn render_with_aovs(
        &mut self,
        view: &View,
        width: u32,
        height: u32,
        set: AovSet,
    ) -> Result<(RenderedFrame, Aovs), GpuError> {
        let one_sample = self.core.samples == 1 && view.supersample <= 1;
        let targets = set.instance || set.normal;
        let was = self.read_depth;
        self.read_depth = was || (set.depth && one_sample);
        let frame = self.render_drawing(view, (width, height), targets.then_some(set));
        self.read_depth = was;
        let (mut frame, drawn) = frame?;
        // Depth alone at one sample is the frame's: nothing more to draw.
        let drawn = drawn.or_else(|| (!targets && one_sample).then(Default::default));
        let aovs = match drawn {
            Some((instance, normal)) => {
                let depth = frame.depth.as_deref().filter(|_| set.depth).unwrap_or(&[]);
                let plan = frame.plan.clone();
                aovs_of(view, (width, height), (instance, normal, depth), plan)
            }
            None => self.render_aovs_of(view, width, height, set)?,
        };
        if !was {
            frame.depth = None;
        }
        Ok((frame, aovs))
    }
}

/// The AOVs of `view` at `width`×`height` from what was read back (`depth`: the reversed-z
/// depth buffer, made view-axis distances).
pub(super) fn aovs_of(
    view: &View,
    (width, height): (u32, u32),
    (instance, normal, depth): (Vec<u32>, Vec<[f32; 3]>, &[f32]),
    plan: FramePlan,
) -> Aovs {
    let aspect = width as f32 / height.max(1) as f32;
    let proj = crate::plan::camera_projection(&view.camera, aspect);
    Aovs {
        width,
        height,
        depth: super::view_axis_depths(depth, &proj),
        instance,
        normal,
        plan,
    }
}
