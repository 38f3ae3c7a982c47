//! The offscreen renderer: the shared frame core into an image, read back to RGBA8.

use super::core::FrameCore;
use crate::gpu::barrier::Access;
use crate::gpu::context::{Context, GpuError, VkCheck};
use crate::gpu::{Buffer, Image};
use crate::gpu::{Recorder, Uses};
use crate::plan::settings::SceneOptions;
use crate::plan::view::{View, SUPERSAMPLE_FACTORS};
use crate::plan::FramePlan;
use crate::render::targets::{Attachment, MsaaTargets};
use crate::scene::Scene;
use ash::vk;
use glam::Mat4;
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

mod aov;
mod batch;
mod ring;
mod submit;
pub use aov::{AovSet, Aovs};
pub use batch::{BatchShadows, Sink, RING, SHARED_MAP_MAX};
use ring::ring_of;

/// Colour format of offscreen frames (sRGB-encoded on write).
pub const OFFSCREEN_FORMAT: vk::Format = vk::Format::R8G8B8A8_SRGB;
/// Largest offscreen side.
pub const MAX_SIDE: u32 = 16384;

/// Timings and counts of one frame.
#[derive(Clone, Debug, Default)]
pub struct FrameStats {
    /// GPU time of the shadow pass (ms), from timestamps.
    pub gpu_shadow_ms: Option<f64>,
    /// GPU time of the camera pass (ms).
    pub gpu_camera_ms: Option<f64>,
    /// Wall time of `render` (ms): recording, submission, wait and readback.
    pub wall_ms: f64,
    /// Casters drawn into the shadow map (after culling).
    pub casters_drawn: usize,
    /// Draws in the camera pass (after frustum culling).
    pub draws: usize,
    /// Of those, draws shaded deferred (through the G-buffer; `SceneOptions::deferred`).
    pub deferred_draws: usize,
    /// Of those, draws drawn, wholly or in part, without the shadow lookup where no caster can
    /// shadow them (`SceneOptions::receiver_split`).
    pub unshadowed_draws: usize,
    /// Of those, forward draws of large triangles that read the uniforms as flat inputs (CPU
    /// devices: `FLAT_FROM_PIXELS`).
    pub flat_draws: usize,
    /// Draws in the scene (instances × primitives), before culling.
    pub draws_total: usize,
    /// Triangles in the scene.
    pub triangles: usize,
    /// Whether comparisons were filtered in hardware.
    pub hardware_compare: bool,
    /// Whether the camera pass drew the instance ids and normals too
    /// (`Renderer::render_with_aovs` at one sample per pixel).
    pub aovs_in_camera_pass: bool,
    /// Exact and hybrid shadows: the caster triangles drawn into the grid, and the frame's
    /// caster triangles (equal for exact shadows; hybrid ones draw those culling kept).
    pub grid_triangles: Option<(u64, u64)>,
}

/// A rendered frame.
pub struct RenderedFrame {
    /// The pixels.
    pub image: image::RgbaImage,
    /// Timings and counts.
    pub stats: FrameStats,
    /// The CPU-side plan it was rendered with.
    pub plan: FramePlan,
    /// The camera depth buffer (reversed-z, 0 = nothing drawn), row-major, when requested with
    /// `Renderer::set_read_depth`; at the drawn size (`View::supersample` times the image's).
    pub depth: Option<Vec<f32>>,
}

struct Target {
    color: Image,
    /// Owns the image `depth_at` draws into.
    _depth: Image,
    color_at: Attachment,
    depth_at: Attachment,
    /// Per ring slot (`ring::RING`), the colour and depth readbacks.
    readback: [Buffer; ring::RING],
    depth_readback: [Buffer; ring::RING],
    /// The multisampled images drawn into (resolved into `color`, `depth`) with MSAA.
    msaa: Option<MsaaTargets>,
    /// With supersampling, the image at the asked size `color` is filtered into (read back
    /// instead of `color`).
    filtered: Option<(Image, Attachment)>,
}

/// Renders views of one scene offscreen.
pub struct Renderer {
    core: FrameCore,
    target: Option<Target>,
    /// Per ring slot (`ring::RING`: frames in flight in a batch), a command buffer and its fence.
    cmds: [vk::CommandBuffer; ring::RING],
    fences: [vk::Fence; ring::RING],
    read_depth: bool,
    /// The depths the last measured camera saw (`ShadowSettings::depth_fit`).
    seen_depths: Option<SeenDepths>,
    /// The AOV pass's images (`render_aovs`), made at its first call.
    aov: Option<aov::AovTarget>,
}

/// A camera (view matrix, projection, drawn size) and the (nearest, farthest) view depth it saw
/// (None: nothing drawn).
type SeenDepths = (
    Mat4,
    crate::scene::Projection,
    (u32, u32),
    Option<(f32, f32)>,
);

/// [`copy_to_buffer`] of an attachment's image, moved to a transfer source first.
pub fn copy_attachment_to_buffer(
    d: &ash::Device,
    cmd: vk::CommandBuffer,
    at: &mut Attachment,
    aspect: vk::ImageAspectFlags,
    extent: vk::Extent2D,
    buffer: vk::Buffer,
) {
    Uses::new().reads(at, Access::TransferSrc).enter(d, cmd);
    copy_to_buffer(d, cmd, at.image, aspect, extent, buffer);
}

/// Copies a whole single-level image aspect into a tightly packed buffer.
pub fn copy_to_buffer(
    d: &ash::Device,
    cmd: vk::CommandBuffer,
    image: vk::Image,
    aspect: vk::ImageAspectFlags,
    extent: vk::Extent2D,
    buffer: vk::Buffer,
) {
    let region = [vk::BufferImageCopy::default()
        .buffer_row_length(0)
        .image_subresource(vk::ImageSubresourceLayers {
            aspect_mask: aspect,
            mip_level: 0,
            base_array_layer: 0,
            layer_count: 1,
        })
        .image_extent(vk::Extent3D {
            width: extent.width,
            height: extent.height,
            depth: 1,
        })];
    Recorder::new(d, cmd).copy_image_to_buffer(
        image,
        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
        buffer,
        &region,
    )
}

/// Makes transfer writes visible to the host.
pub fn transfer_to_host_barrier(d: &ash::Device, cmd: vk::CommandBuffer) {
    let mb = [vk::MemoryBarrier2::default()
        .src_stage_mask(vk::PipelineStageFlags2::ALL_TRANSFER)
        .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
        .dst_stage_mask(vk::PipelineStageFlags2::HOST)
        .dst_access_mask(vk::AccessFlags2::HOST_READ)];
    Recorder::new(d, cmd).pipeline_barrier2(&vk::DependencyInfo::default().memory_barriers(&mb));
}

/// Tightly packed RGBA8 rows (row pitch = width · 4) from a mapped readback; `bgra` swaps R and B.
pub fn rgba_from_readback(bytes: &[u8], width: u32, height: u32, bgra: bool) -> image::RgbaImage {
    let pitch = width as usize * 4;
    let mut rgba = bytes[..pitch * height as usize].to_vec();
    if bgra {
        for p in rgba.chunks_exact_mut(4) {
            p.swap(0, 2);
        }
    }
    image::RgbaImage::from_raw(width, height, rgba).expect("size matches")
}

impl Renderer {
    /// Uploads `scene` and creates the passes.
    pub fn new(ctx: &Arc<Context>, scene: &Scene) -> Result<Self, GpuError> {
        Self::with_options(ctx, scene, &SceneOptions::default())
    }

    /// Uploads `scene` with `options` and creates the passes.
    pub fn with_options(
        ctx: &Arc<Context>,
        scene: &Scene,
        options: &SceneOptions,
    ) -> Result<Self, GpuError> {
        let core = FrameCore::new(ctx, scene, options, OFFSCREEN_FORMAT, ring::RING)?;
        let mut cmds = [vk::CommandBuffer::null(); ring::RING];
        let mut fences = [vk::Fence::null(); ring::RING];
        for (cmd, fence) in cmds.iter_mut().zip(&mut fences) {
            *cmd = ctx.allocate_command_buffer()?;
            *fence = unsafe {
                ctx.device
                    .create_fence(&vk::FenceCreateInfo::default(), None)
            }
            .vk("vkCreateFence")?;
        }
        Ok(Self {
            core,
            target: None,
            cmds,
            fences,
            read_depth: false,
            seen_depths: None,
            aov: None,
        })
    }

    /// Takes a new pose of the scene it was made from (after [`Scene::pose_at`]): the next
    /// frame draws it, in every pass.
    pub fn set_pose(&mut self, scene: &Scene) -> Result<(), GpuError> {
        self.seen_depths = None;
        self.core.set_pose(scene)
    }

    /// The context.
    pub fn context(&self) -> &Arc<Context> {
        &self.core.ctx
    }

    /// Turns the shadow cache (`SceneOptions::shadow_cache`) on or off from the next frame.
    pub fn set_shadow_cache(&mut self, on: bool) {
        if self.core.shadow.caching() != on {
            self.core.shadow.set_caching(on);
        }
    }

    /// Whether the shadow cache is on.
    pub fn shadow_cache(&self) -> bool {
        self.core.shadow.caching()
    }

    /// Also read back the camera depth buffer (into `RenderedFrame::depth`).
    pub fn set_read_depth(&mut self, on: bool) {
        self.read_depth = on;
    }

    /// Samples per pixel of the camera pass (MSAA; 1 = off).
    pub fn samples(&self) -> u32 {
        self.core.samples
    }

    /// Triangles per frame.
    pub fn triangles(&self) -> usize {
        self.core.gpu.triangles
    }

    /// What the scene's textures take on the device: images, KTX2 images with the file's own
    /// levels, BC7 images, bytes.
    pub fn texture_stats(&self) -> crate::render::TextureStats {
        self.core.gpu.texture_stats
    }

    /// Draws whose shadow casters are their lone cutout cards cut to their alpha
    /// (`scene::mesh::trim`; only with `SceneOptions::culling`).
    pub fn cut_casters(&self) -> usize {
        self.core
            .gpu
            .draws
            .iter()
            .filter(|d| d.shadow_range.is_some())
            .count()
    }

    /// Targets of `w`×`h` drawn pixels, filtered to `out` (with supersampling).
    fn ensure_target(&mut self, w: u32, h: u32, out: Option<vk::Extent2D>) -> Result<(), GpuError> {
        if self.target.as_ref().is_some_and(|t| {
            t.color.extent.width == w
                && t.color.extent.height == h
                && t.filtered.as_ref().map(|f| f.0.extent) == out
        }) {
            return Ok(());
        }
        let ctx = &self.core.ctx;
        let extent = vk::Extent2D {
            width: w,
            height: h,
        };
        let usage = vk::ImageUsageFlags::TRANSFER_SRC;
        let color = Image::new(
            ctx,
            "offscreen colour",
            OFFSCREEN_FORMAT,
            extent,
            1,
            vk::ImageUsageFlags::COLOR_ATTACHMENT | usage,
        )?;
        let depth = Image::new(
            ctx,
            "offscreen depth",
            self.core.camera.depth_format,
            extent,
            1,
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | usage,
        )?;
        let bytes = w as u64 * h as u64 * 4;
        let readbacks = |name: &str| -> Result<[Buffer; ring::RING], GpuError> {
            let b = |i| {
                Buffer::new(
                    ctx,
                    &format!("{name} {i}"),
                    bytes,
                    vk::BufferUsageFlags::TRANSFER_DST,
                    MemoryLocation::GpuToCpu,
                )
            };
            ring_of(b)
        };
        let readback = readbacks("offscreen readback")?;
        let depth_readback = readbacks("depth readback")?;
        let samples = self.core.samples;
        let msaa = if samples > 1 {
            Some(MsaaTargets::new(ctx, OFFSCREEN_FORMAT, extent, samples)?)
        } else {
            None
        };
        let filtered = match out {
            Some(extent) => {
                let image = Image::new(
                    ctx,
                    "offscreen filtered colour",
                    OFFSCREEN_FORMAT,
                    extent,
                    1,
                    // SAMPLED: never sampled, but `Image` makes a view, which needs a view usage.
                    vk::ImageUsageFlags::TRANSFER_DST | vk::ImageUsageFlags::SAMPLED | usage,
                )?;
                let at = Attachment::of(&image);
                Some((image, at))
            }
            None => None,
        };
        self.target = Some(Target {
            msaa,
            filtered,
            color_at: Attachment::of(&color),
            depth_at: Attachment::of(&depth),
            color,
            _depth: depth,
            readback,
            depth_readback,
        });
        Ok(())
    }

    /// Renders `view` at `width`×`height` and reads the result back. With
    /// `ShadowSettings::depth_fit` and no `View::visible_depths`, a camera not seen before is
    /// first rendered once to measure the depths it sees (kept for the frames that follow).
    pub fn render(
        &mut self,
        view: &View,
        width: u32,
        height: u32,
    ) -> Result<RenderedFrame, GpuError> {
        self.render_drawing(view, (width, height), None)
            .map(|(f, _)| f)
    }

    /// `render`, its camera pass also drawing the ids and normals of `aovs` where it can
    /// (`render_with_aovs`): the frame, and what was drawn of them.
    fn render_drawing(
        &mut self,
        view: &View,
        (width, height): (u32, u32),
        aovs: Option<AovSet>,
    ) -> Result<(RenderedFrame, Option<aov::IdsNormals>), GpuError> {
        if !self.measures_depths(view) {
            return self.render_once(view, (width, height), aovs);
        }
        // The drawn size: a supersampled frame measures its own depths.
        let s = view.supersample;
        let key = (
            view.camera.view_from_world(),
            view.camera.projection,
            (width.saturating_mul(s), height.saturating_mul(s)),
        );
        let known = self
            .seen_depths
            .filter(|s| (s.0, s.1, s.2) == key)
            .map(|s| s.3);
        let seen = match known {
            Some(seen) => seen,
            None => {
                let was = self.read_depth;
                self.read_depth = true;
                // The depth buffer does not depend on shadows: measure without them.
                let mut probe = view.clone();
                probe.shadow.enabled = false;
                let f = self.render_once(&probe, (width, height), None);
                self.read_depth = was;
                let (f, _) = f?;
                let aspect = width as f32 / height.max(1) as f32;
                let seen = visible_depths(
                    f.depth.as_deref().unwrap_or(&[]),
                    &crate::plan::camera_projection(&view.camera, aspect),
                );
                self.seen_depths = Some((key.0, key.1, key.2, seen));
                seen
            }
        };
        let mut v = view.clone();
        v.visible_depths = seen;
        self.render_once(&v, (width, height), aovs)
    }

    /// Whether `render` of `view` fits its shadows to the depths the camera sees
    /// (`ShadowSettings::depth_fit`), measured by a frame of its own for a camera not seen before.
    fn measures_depths(&self, view: &View) -> bool {
        view.shadow.depth_fit
            && view.shadow.enabled
            && view.visible_depths.is_none()
            && view.shadow_fit_camera.is_none()
            && view.shadow_batch.is_none()
    }
}

/// An error for a supersampling factor outside [`SUPERSAMPLE_FACTORS`], or one the device
/// cannot filter down (a linear blit of the offscreen format).
fn check_supersample(ctx: &Context, s: u32) -> Result<(), GpuError> {
    if !SUPERSAMPLE_FACTORS.contains(&s) {
        return Err(GpuError::Unsupported(format!(
            "supersample {s} is not one of {SUPERSAMPLE_FACTORS:?}"
        )));
    }
    if s > 1 && !ctx.blits_linear(OFFSCREEN_FORMAT) {
        return Err(GpuError::Unsupported(format!(
            "supersample {s}: the device cannot filter {OFFSCREEN_FORMAT:?} in a blit"
        )));
    }
    Ok(())
}

/// An error for an image size outside 1×1..`MAX_SIDE`².
fn check_size(width: u32, height: u32) -> Result<(), GpuError> {
    if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
        return Err(GpuError::Unsupported(format!(
            "image size {width}x{height} is outside 1x1..{MAX_SIDE}x{MAX_SIDE}"
        )));
    }
    Ok(())
}

/// The nearest and farthest view depth in a reversed-z depth buffer (0 = nothing drawn) under
/// the camera projection `proj`; None where nothing was drawn.
pub fn visible_depths(depth: &[f32], proj: &Mat4) -> Option<(f32, f32)> {
    let (mut lo, mut hi) = (f32::INFINITY, 0.0f32);
    for &z in depth {
        if z > 0.0 && z.is_finite() {
            lo = lo.min(z);
            hi = hi.max(z);
        }
    }
    if hi <= 0.0 {
        return None;
    }
    let inv = proj.inverse();
    let view_depth = |z: f32| {
        let p = inv * glam::Vec4::new(0.0, 0.0, z, 1.0);
        -p.z / p.w
    };
    // Reversed-z: the largest value is the nearest.
    Some((view_depth(hi), view_depth(lo)))
}

/// Each pixel's distance along the view axis (scene units) from a reversed-z depth buffer drawn
/// with the camera projection `proj`; 0 where nothing was drawn (a depth of 0).
pub fn view_axis_depths(depth: &[f32], proj: &Mat4) -> Vec<f32> {
    // The view-space point at (0, 0, z, 1) in clip space: only its z and w are needed, each
    // z·(third column) + fourth column, the same sums as the full product's (the x and y
    // columns add exact zeros), so the same bits.
    let inv = proj.inverse();
    let (c, d) = (inv.z_axis, inv.w_axis);
    depth
        .iter()
        .map(|&z| {
            if z > 0.0 {
                let (pz, pw) = (c.z * z + d.z, c.w * z + d.w);
                -pz / pw
            } else {
                0.0
            }
        })
        .collect()
}

impl Drop for Renderer {
    fn drop(&mut self) {
        unsafe {
            let _ = self.core.ctx.device.device_wait_idle();
        }
        for (&cmd, &fence) in self.cmds.iter().zip(&self.fences) {
            self.core.ctx.free_command_buffer(cmd);
            unsafe { self.core.ctx.device.destroy_fence(fence, None) };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::projection::perspective_infinite_reversed;

    #[test]
    fn visible_depths_reads_the_nearest_and_farthest_drawn_depth() {
        let near = 0.1;
        let proj = perspective_infinite_reversed(1.0, 1.5, near);
        // Reversed-z infinite: z = near / d; 0 is the cleared background.
        let depth = [0.0, near / 3.0, near / 12.5, 0.0, near / 7.0];
        let (lo, hi) = visible_depths(&depth, &proj).unwrap();
        assert!(
            (lo - 3.0).abs() < 1e-4 && (hi - 12.5).abs() < 1e-3,
            "{lo} {hi}"
        );
        assert_eq!(visible_depths(&[0.0; 4], &proj), None);
    }

    /// `view_axis_depths` is the full inverse product's `-z / w`, to the bit.
    #[test]
    fn view_axis_depths_equal_the_full_inverse_product() {
        let projections = [
            perspective_infinite_reversed(0.8, 1.5, 0.05),
            crate::math::projection::perspective_reversed(0.8, 1.5, 0.05, 100.0),
            crate::math::projection::orthographic_reversed(-2.0, 2.0, -1.5, 1.5, 0.1, 50.0),
        ];
        let depth: Vec<f32> = (0..4096).map(|i| i as f32 / 4095.0).collect();
        for proj in projections {
            let inv = proj.inverse();
            let full: Vec<u32> = depth
                .iter()
                .map(|&z| {
                    if z > 0.0 {
                        let p = inv * glam::Vec4::new(0.0, 0.0, z, 1.0);
                        (-p.z / p.w).to_bits()
                    } else {
                        0f32.to_bits()
                    }
                })
                .collect();
            let fast: Vec<u32> = view_axis_depths(&depth, &proj)
                .iter()
                .map(|d| d.to_bits())
                .collect();
            assert!(fast == full, "{proj:?}");
        }
    }
}
