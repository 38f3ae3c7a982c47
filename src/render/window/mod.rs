//! Rendering to a window: the shared frame core into swapchain images, two frames in flight
//! (per frame: command buffer, fence, acquire semaphore, uniform slot; per image: render-finished
//! semaphore).

mod record;

use super::core::{FrameCore, Targets};
use super::renderer::{rgba_from_readback, transfer_to_host_barrier, visible_depths};
use crate::gpu::barrier::{access_info, Access};
use crate::gpu::context::{Context, GpuError, VkCheck};
use crate::gpu::{Buffer, Image, Uses};
use crate::plan::settings::SceneOptions;
use crate::plan::view::{ShadowHold, View};
use crate::render::targets::swapchain::Swapchain;
use crate::render::targets::{Attachment, MsaaTargets};
use crate::scene::Scene;
use ash::vk;
use gpu_allocator::MemoryLocation;
use raw_window_handle::{RawDisplayHandle, RawWindowHandle};
use record::{record_depth_read, record_screenshot_and_overlay, shadow_view_summary};
use std::ffi::{CStr, CString};
use std::sync::Arc;

/// The instance extensions a Vulkan surface on `display` needs (for
/// [`ContextDesc::instance_extensions`](crate::gpu::ContextDesc::instance_extensions)).
pub fn surface_extensions(display: RawDisplayHandle) -> Result<Vec<CString>, GpuError> {
    let exts = ash_window::enumerate_required_extensions(display).map_err(|e| {
        GpuError::Unsupported(format!("no Vulkan surface support for this display: {e:?}"))
    })?;
    Ok(exts
        .iter()
        .map(|&p| unsafe { CStr::from_ptr(p) }.to_owned())
        .collect())
}

/// A frame begun by `WindowRenderer::begin_frame`: its slot, sync objects and command buffer,
/// the view it draws, whether it reads its depth back, and the acquired image.
struct Begun {
    f: usize,
    fence: vk::Fence,
    acquired: vk::Semaphore,
    cmd: vk::CommandBuffer,
    view: View,
    fit: bool,
    index: u32,
    extent: vk::Extent2D,
}

/// Frames recorded ahead of the GPU.
pub const FRAMES_IN_FLIGHT: usize = 2;

struct FrameSync {
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    acquired: vk::Semaphore,
}

/// Drawing recorded over a window's frame after the scene (an on-screen panel): called inside a
/// rendering of the swapchain image (its colour loaded and stored, no depth attachment, the
/// viewport and scissor left to the overlay), in the frame's command buffer. What it draws from
/// must stay alive until that frame completes (`WindowRenderer::draw_with` waits for a frame
/// slot's previous use before recording into it again).
pub trait Overlay {
    /// Records the overlay into `cmd` for an image of `extent`.
    fn record(&mut self, cmd: vk::CommandBuffer, extent: vk::Extent2D);
}

/// What a frame's screenshot holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Capture {
    /// No screenshot.
    None,
    /// The scene as rendered, without the overlay.
    Scene,
    /// What is on screen, the overlay included.
    Screen,
}

/// What one drawn frame did: its draws and shadow views, for a front end's statistics.
#[derive(Clone, Debug, Default)]
pub struct FrameSummary {
    /// Casters drawn into the shadow map.
    pub casters: usize,
    /// Draws in the camera pass (after culling).
    pub draws: usize,
    /// Of those, draws shaded deferred.
    pub deferred: usize,
    /// Per shadow view: its light, its side in texels and the world size of a texel
    /// (directional) or of a texel per unit distance (spot, point face).
    pub shadow_views: Vec<(usize, u32, f32)>,
}

/// What `draw` did.
pub enum DrawResult {
    /// Nothing drawn: the window is 0×0 or the swapchain was out of date (recreated).
    Skipped,
    /// A frame was submitted and presented.
    Drawn {
        /// What was drawn.
        summary: FrameSummary,
        /// The presented pixels, when a screenshot was asked for.
        screenshot: Option<image::RgbaImage>,
    },
}

/// A frame slot's depth readback buffer and, while a copy is in flight, the camera projection
/// and pixel count it holds.
pub(super) type DepthRead = (Option<Buffer>, Option<(glam::Mat4, usize)>);

/// Draws views of a scene into a window's swapchain.
pub struct WindowRenderer {
    core: FrameCore,
    /// The swapchain.
    pub(crate) swapchain: Swapchain,
    frames: Vec<FrameSync>,
    depth: Option<(Image, Attachment)>,
    /// Multisampled colour and depth (resolved into the swapchain image) with MSAA.
    msaa: Option<MsaaTargets>,
    frame: usize,
    wanted: (u32, u32),
    screenshot: Option<Buffer>,
    last_gpu: Option<(f64, f64)>,
    /// Per frame slot: a depth readback buffer and, while a copy into it is in flight, the
    /// camera projection and pixel count it was drawn with (`ShadowSettings::depth_fit`).
    depth_reads: Vec<DepthRead>,
    /// The nearest and farthest view depth of the latest frame read back.
    seen_depths: Option<(f32, f32)>,
    /// The last frame's shadow extents, held by the next while the camera moves.
    held: Option<ShadowHold>,
    /// The last frame's camera and size (a change means the camera is moving).
    last_shot: Option<(crate::scene::Camera, u32, u32)>,
}

impl WindowRenderer {
    /// Creates a surface for the window, a swapchain of `width`×`height` on it and the passes
    /// for its format. `ctx` must have been created with [`surface_extensions`] of the display
    /// and `swapchain: true`; the window must outlive the renderer.
    pub fn new(
        ctx: &Arc<Context>,
        scene: &Scene,
        (display, window): (RawDisplayHandle, RawWindowHandle),
        (width, height): (u32, u32),
        vsync: bool,
        options: &SceneOptions,
    ) -> Result<Self, GpuError> {
        let surface = unsafe {
            ash_window::create_surface(&ctx.instance.entry, &ctx.instance, display, window, None)
        }
        .vk("vkCreateSurfaceKHR")?;
        let swapchain = Swapchain::new(ctx, surface, width, height, vsync)?;
        let core = FrameCore::new(ctx, scene, options, swapchain.format, FRAMES_IN_FLIGHT)?;
        let mut frames = Vec::new();
        for i in 0..FRAMES_IN_FLIGHT {
            let cmd = ctx.allocate_command_buffer()?;
            let fence = unsafe {
                ctx.device.create_fence(
                    &vk::FenceCreateInfo::default().flags(vk::FenceCreateFlags::SIGNALED),
                    None,
                )
            }
            .vk("vkCreateFence")?;
            let acquired = unsafe {
                ctx.device
                    .create_semaphore(&vk::SemaphoreCreateInfo::default(), None)
            }
            .vk("vkCreateSemaphore")?;
            ctx.set_name(acquired, &format!("image acquired {i}"));
            frames.push(FrameSync {
                cmd,
                fence,
                acquired,
            });
        }
        let mut r = Self {
            core,
            swapchain,
            frames,
            depth: None,
            msaa: None,
            frame: 0,
            wanted: (width, height),
            screenshot: None,
            last_gpu: None,
            depth_reads: (0..FRAMES_IN_FLIGHT).map(|_| (None, None)).collect(),
            seen_depths: None,
            held: None,
            last_shot: None,
        };
        r.ensure_depth()?;
        Ok(r)
    }

    /// Takes a new pose of the scene it was made from (`FrameCore::set_pose`); waits for the
    /// frames in flight first.
    pub fn set_pose(&mut self, scene: &Scene) -> Result<(), GpuError> {
        self.core.set_pose(scene)
    }

    /// Replaces the scene (a file opened or reloaded) keeping the window's swapchain: waits for
    /// the frames in flight, then uploads `scene` with `options` as [`Self::new`] does.
    pub fn set_scene(&mut self, scene: &Scene, options: &SceneOptions) -> Result<(), GpuError> {
        let ctx = self.core.ctx.clone();
        unsafe { ctx.device.device_wait_idle() }.vk("vkDeviceWaitIdle")?;
        self.core = FrameCore::new(
            &ctx,
            scene,
            options,
            self.swapchain.format,
            FRAMES_IN_FLIGHT,
        )?;
        // The depth format and sample count may differ; nothing read back belongs to it.
        self.depth = None;
        self.msaa = None;
        self.last_gpu = None;
        self.seen_depths = None;
        self.held = None;
        self.last_shot = None;
        for slot in &mut self.depth_reads {
            slot.1 = None;
        }
        self.ensure_depth()
    }

    /// The swapchain's colour format (what an [`Overlay`] draws into).
    pub fn format(&self) -> vk::Format {
        self.swapchain.format
    }

    /// The triangles drawn per frame.
    pub fn triangles(&self) -> usize {
        self.core.gpu.triangles
    }

    /// GPU milliseconds (shadow, camera) of the most recently completed frame.
    pub fn gpu_times(&self) -> Option<(f64, f64)> {
        self.last_gpu
    }

    fn ensure_depth(&mut self) -> Result<(), GpuError> {
        let e = self.swapchain.extent;
        if e.width == 0 || e.height == 0 {
            self.depth = None;
            self.msaa = None;
            return Ok(());
        }
        let samples = self.core.samples;
        let msaa_ok = samples == 1
            || self
                .msaa
                .as_ref()
                .is_some_and(|m| m.extent == e && m.color_format == self.swapchain.format);
        if self.depth.as_ref().is_some_and(|(d, _)| d.extent == e) && msaa_ok {
            return Ok(());
        }
        self.msaa = if samples > 1 {
            Some(MsaaTargets::new(
                &self.core.ctx,
                self.swapchain.format,
                e,
                samples,
            )?)
        } else {
            None
        };
        let image = Image::new(
            &self.core.ctx,
            "window depth",
            self.core.camera.depth_format,
            e,
            1,
            // Read back for depth fitting.
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
        )?;
        let at = Attachment::of(&image);
        self.depth = Some((image, at));
        Ok(())
    }

    /// The window's inner size changed (0×0 when minimised: drawing pauses).
    pub fn resize(&mut self, width: u32, height: u32) -> Result<(), GpuError> {
        self.wanted = (width, height);
        self.swapchain.recreate(width, height)?;
        self.ensure_depth()
    }

    /// Draws one frame of `view`; with `screenshot`, also returns the presented pixels. With
    /// `ShadowSettings::depth_fit` (and no `View::visible_depths`) each frame's depth is read
    /// back and fits the cascades of a later frame (the latest completed: one or two frames
    /// behind a moving camera).
    pub fn draw(&mut self, view: &View, screenshot: bool) -> Result<DrawResult, GpuError> {
        let capture = if screenshot {
            Capture::Scene
        } else {
            Capture::None
        };
        self.draw_with(view, capture, None)
    }

    /// [`Self::draw`] with an `overlay` recorded over the scene, and a screenshot (`capture`) of
    /// the scene alone or of the screen.
    pub fn draw_with(
        &mut self,
        view: &View,
        capture: Capture,
        overlay: Option<&mut dyn Overlay>,
    ) -> Result<DrawResult, GpuError> {
        let screenshot = capture != Capture::None;
        let ctx = self.core.ctx.clone();
        let d = &ctx.device;
        let Some(Begun {
            f,
            fence,
            acquired,
            cmd,
            view: v,
            fit,
            index,
            extent,
        }) = self.begin_frame(view)?
        else {
            return Ok(DrawResult::Skipped);
        };
        let view = &v;
        let prepared = self.core.prepare(f, view, extent.width, extent.height)?;
        self.held = Some(ShadowHold::from_plan(&prepared.plan));
        let want_copy = screenshot && self.swapchain.can_copy;
        self.ensure_readbacks(f, fit, want_copy)?;
        let (_, depth) = self.depth.as_mut().expect("depth exists with a swapchain");
        let mut color = Attachment {
            image: self.swapchain.images[index as usize],
            view: self.swapchain.views[index as usize],
            aspect: vk::ImageAspectFlags::COLOR,
            state: Access::Acquired,
        };
        ctx.begin_one_time(cmd)?;
        let counts = self.core.record(
            cmd,
            &prepared,
            Targets {
                color: &mut color,
                depth,
                msaa: self.msaa.as_mut(),
                resolve_depth: fit,
                aovs: None,
            },
        );
        let summary = FrameSummary {
            casters: counts.casters,
            draws: counts.camera_draws,
            deferred: counts.deferred_draws,
            shadow_views: shadow_view_summary(&prepared.plan),
        };
        if fit {
            record_depth_read(
                d,
                cmd,
                depth,
                &mut self.depth_reads[f],
                &view.camera,
                extent,
            );
        }
        let shot_buffer = want_copy
            .then(|| self.screenshot.as_ref().map(|b| b.raw))
            .flatten();
        record_screenshot_and_overlay(d, cmd, &mut color, extent, overlay, (capture, shot_buffer));
        if fit || want_copy {
            transfer_to_host_barrier(d, cmd);
        }
        Uses::new().reads(&mut color, Access::Present).enter(d, cmd);
        self.submit(cmd, acquired, fence, index)?;
        let shot = self.present(f, fence, index, extent, screenshot)?;
        Ok(DrawResult::Drawn {
            summary,
            screenshot: shot,
        })
    }

    /// Presents image `index` and moves on from frame slot `f`: with `screenshot`, the copy read
    /// back (once `fence` signals) where the swapchain can be copied from; a stale swapchain
    /// recreated.
    fn present(
        &mut self,
        f: usize,
        fence: vk::Fence,
        index: u32,
        extent: vk::Extent2D,
        screenshot: bool,
    ) -> Result<Option<image::RgbaImage>, GpuError> {
        let stale = self.swapchain.present(index)?;
        self.frame = (f + 1) % FRAMES_IN_FLIGHT;
        let mut shot = None;
        if screenshot && self.swapchain.can_copy {
            shot = Some(self.read_screenshot(fence, extent)?);
        } else if screenshot {
            log::warn!(
                "this swapchain cannot be copied from (no TRANSFER_SRC usage); no screenshot"
            );
        }
        if stale {
            let (w, h) = self.wanted;
            self.resize(w, h)?;
        }
        Ok(shot)
    }

    /// The start of a frame: waits for its slot's fence, picks the view it draws
    /// ([`Self::frame_view`]) and acquires a swapchain image. `None`: nothing to draw into (a
    /// minimised window, or a swapchain out of date and recreated).
    fn begin_frame(&mut self, view: &View) -> Result<Option<Begun>, GpuError> {
        let d = &self.core.ctx.device;
        let f = self.frame;
        let (fence, acquired, cmd) = {
            let sync = &self.frames[f];
            (sync.fence, sync.acquired, sync.cmd)
        };
        unsafe { d.wait_for_fences(&[fence], true, u64::MAX) }.vk("vkWaitForFences")?;
        if let Some(t) = self.core.gpu_times(f) {
            self.last_gpu = Some(t);
        }
        let (view, fit) = self.frame_view(view, f);
        let extent = self.swapchain.extent;
        if extent.width == 0 || extent.height == 0 || self.swapchain.raw == vk::SwapchainKHR::null()
        {
            return Ok(None);
        }
        let Some((index, _suboptimal)) = self.swapchain.acquire(acquired)? else {
            let (w, h) = self.wanted;
            self.resize(w, h)?;
            return Ok(None);
        };
        let d = &self.core.ctx.device;
        unsafe { d.reset_fences(&[fence]) }.vk("vkResetFences")?;
        Ok(Some(Begun {
            f,
            fence,
            acquired,
            cmd,
            view,
            fit,
            index,
            extent,
        }))
    }

    /// The view this frame draws: with a depth fit, the depths the latest completed frame read
    /// back; for a camera in motion, the previous frame's shadow extents held. Also whether this
    /// frame reads its depth back (`ShadowSettings::depth_fit`).
    fn frame_view(&mut self, view: &View, f: usize) -> (View, bool) {
        let slot = &mut self.depth_reads[f];
        if let (Some(buf), Some((proj, n))) = (slot.0.as_mut(), slot.1.take()) {
            if let Some(bytes) = buf.mapped() {
                self.seen_depths =
                    visible_depths(bytemuck::cast_slice::<u8, f32>(&bytes[..n * 4]), &proj);
            }
        }
        let fit = view.shadow.depth_fit
            && view.shadow.enabled
            && view.visible_depths.is_none()
            && view.shadow_fit_camera.is_none();
        let extent = self.swapchain.extent;
        // A camera in motion holds the previous frame's shadow extents (less shimmer); one that
        // stands still for a frame is fitted afresh, as a still is.
        let shot = (view.camera, extent.width, extent.height);
        let moving = self.last_shot.is_some_and(|last| last != shot);
        self.last_shot = Some(shot);
        let mut v = view.clone();
        if fit {
            v.visible_depths = self.seen_depths;
        }
        if moving && v.shadow_hold.is_none() {
            v.shadow_hold = self.held.take();
        }
        (v, fit)
    }

    /// Makes frame slot `f`'s depth readback (with `fit`) and the screenshot buffer (with
    /// `want_copy`) large enough for the swapchain.
    fn ensure_readbacks(&mut self, f: usize, fit: bool, want_copy: bool) -> Result<(), GpuError> {
        let ctx = self.core.ctx.clone();
        let extent = self.swapchain.extent;
        let pixels = extent.width as usize * extent.height as usize;
        if fit
            && self.depth_reads[f]
                .0
                .as_ref()
                .is_none_or(|b| b.size < pixels as u64 * 4)
        {
            self.depth_reads[f].0 = Some(Buffer::new(
                &ctx,
                "depth readback",
                pixels as u64 * 4,
                vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuToCpu,
            )?);
        }
        if want_copy {
            let need = extent.width as u64 * extent.height as u64 * 4;
            if self.screenshot.as_ref().is_none_or(|b| b.size < need) {
                self.screenshot = Some(Buffer::new(
                    &ctx,
                    "screenshot readback",
                    need,
                    vk::BufferUsageFlags::TRANSFER_DST,
                    MemoryLocation::GpuToCpu,
                )?);
            }
        }
        Ok(())
    }

    /// Submits `cmd`, waiting for `acquired` and signalling the image's render-finished
    /// semaphore and `fence`.
    fn submit(
        &self,
        cmd: vk::CommandBuffer,
        acquired: vk::Semaphore,
        fence: vk::Fence,
        index: u32,
    ) -> Result<(), GpuError> {
        let ctx = &self.core.ctx;
        let d = &ctx.device;
        unsafe {
            d.end_command_buffer(cmd).vk("vkEndCommandBuffer")?;
            let waits = [vk::SemaphoreSubmitInfo::default()
                .semaphore(acquired)
                // The same stage the acquired image's first barrier waits at (barrier table).
                .stage_mask(access_info(Access::Acquired).0)];
            let signals = [vk::SemaphoreSubmitInfo::default()
                .semaphore(self.swapchain.render_finished[index as usize])
                .stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)];
            let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
            let submit = [vk::SubmitInfo2::default()
                .wait_semaphore_infos(&waits)
                .command_buffer_infos(&cmds)
                .signal_semaphore_infos(&signals)];
            d.queue_submit2(ctx.queue, &submit, fence)
                .vk("vkQueueSubmit2")?;
        }
        Ok(())
    }

    /// The screenshot the frame guarded by `fence` copied, as RGBA.
    fn read_screenshot(
        &mut self,
        fence: vk::Fence,
        extent: vk::Extent2D,
    ) -> Result<image::RgbaImage, GpuError> {
        let d = &self.core.ctx.device;
        unsafe { d.wait_for_fences(&[fence], true, u64::MAX) }.vk("vkWaitForFences")?;
        let bgra = self.swapchain.format == vk::Format::B8G8R8A8_SRGB;
        let buf = self.screenshot.as_mut().expect("buffer");
        let bytes = buf
            .mapped()
            .ok_or_else(|| GpuError::Unsupported("readback not mapped".into()))?;
        Ok(rgba_from_readback(bytes, extent.width, extent.height, bgra))
    }
}

impl Drop for WindowRenderer {
    fn drop(&mut self) {
        let ctx = self.core.ctx.clone();
        unsafe {
            let _ = ctx.device.device_wait_idle();
            for f in self.frames.drain(..) {
                ctx.device.destroy_fence(f.fence, None);
                ctx.device.destroy_semaphore(f.acquired, None);
                ctx.free_command_buffer(f.cmd);
            }
        }
    }
}
