//! The offscreen renderer: shadow pass + camera pass into an image, read back to RGBA8.

use super::camera_pass::{CameraPass, DEPTH_FORMAT};
use super::frame::{plan_frame, FramePlan};
use super::gpu_scene::GpuScene;
use super::settings::{ShadowFormat, View, ViewMode};
use super::shadow_pass::ShadowPass;
use crate::gpu::barrier::{image_barrier, Access};
use crate::gpu::context::{Context, GpuError, VkCheck};
use crate::gpu::{Buffer, Image};
use crate::scene::Scene;
use ash::vk;
use gpu_allocator::MemoryLocation;
use std::sync::Arc;
use std::time::Instant;

/// Colour format of offscreen frames (sRGB-encoded on write).
pub const OFFSCREEN_FORMAT: vk::Format = vk::Format::R8G8B8A8_SRGB;
/// Linear colour where nothing is drawn (the reference uses it too).
pub const CLEAR_COLOR: [f32; 4] = [0.02, 0.02, 0.025, 1.0];
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
    /// Draws in the camera pass.
    pub draws: usize,
    /// Triangles in the scene.
    pub triangles: usize,
    /// Whether comparisons were filtered in hardware.
    pub hardware_compare: bool,
}

/// A rendered frame.
pub struct RenderedFrame {
    /// The pixels (the shadow map as grey for `ViewMode::ShadowMap`).
    pub image: image::RgbaImage,
    /// Timings and counts.
    pub stats: FrameStats,
    /// The CPU-side plan it was rendered with.
    pub plan: FramePlan,
    /// The camera depth buffer (reversed-z, 0 = nothing drawn), row-major, when requested with
    /// `Renderer::set_read_depth`.
    pub depth: Option<Vec<f32>>,
}

struct Target {
    color: Image,
    depth: Image,
    readback: Buffer,
    depth_readback: Buffer,
    color_state: Access,
    depth_state: Access,
}

/// Renders views of one scene offscreen.
pub struct Renderer {
    ctx: Arc<Context>,
    scene: Scene,
    gpu: GpuScene,
    shadow: ShadowPass,
    camera: CameraPass,
    target: Option<Target>,
    shadow_readback: Option<Buffer>,
    query_pool: vk::QueryPool,
    cmd: vk::CommandBuffer,
    read_depth: bool,
}

impl Renderer {
    /// Uploads `scene` and creates the passes.
    pub fn new(ctx: &Arc<Context>, scene: &Scene) -> Result<Self, GpuError> {
        let gpu = GpuScene::new(ctx, scene)?;
        let shadow = ShadowPass::new(ctx)?;
        let camera = CameraPass::new(ctx, &gpu, OFFSCREEN_FORMAT)?;
        let query_pool = unsafe {
            ctx.device.create_query_pool(
                &vk::QueryPoolCreateInfo::default()
                    .query_type(vk::QueryType::TIMESTAMP)
                    .query_count(3),
                None,
            )
        }
        .vk("vkCreateQueryPool")?;
        let cmd = ctx.allocate_command_buffer()?;
        Ok(Self {
            ctx: ctx.clone(),
            scene: scene.clone(),
            gpu,
            shadow,
            camera,
            target: None,
            shadow_readback: None,
            query_pool,
            cmd,
            read_depth: false,
        })
    }

    /// The context.
    pub fn context(&self) -> &Arc<Context> {
        &self.ctx
    }

    /// The scene (CPU copy).
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Also read back the camera depth buffer (into `RenderedFrame::depth`).
    pub fn set_read_depth(&mut self, on: bool) {
        self.read_depth = on;
    }

    /// Triangles per frame.
    pub fn triangles(&self) -> usize {
        self.gpu.triangles
    }

    fn ensure_target(&mut self, w: u32, h: u32) -> Result<(), GpuError> {
        if self
            .target
            .as_ref()
            .is_some_and(|t| t.color.extent.width == w && t.color.extent.height == h)
        {
            return Ok(());
        }
        let extent = vk::Extent2D {
            width: w,
            height: h,
        };
        let color = Image::new(
            &self.ctx,
            "offscreen colour",
            OFFSCREEN_FORMAT,
            extent,
            1,
            vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
        )?;
        let depth = Image::new(
            &self.ctx,
            "offscreen depth",
            DEPTH_FORMAT,
            extent,
            1,
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
        )?;
        let readback = Buffer::new(
            &self.ctx,
            "offscreen readback",
            w as u64 * h as u64 * 4,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        let depth_readback = Buffer::new(
            &self.ctx,
            "depth readback",
            w as u64 * h as u64 * 4,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        self.target = Some(Target {
            color,
            depth,
            readback,
            depth_readback,
            color_state: Access::Undefined,
            depth_state: Access::Undefined,
        });
        Ok(())
    }

    /// Renders `view` at `width`×`height` and reads the result back.
    pub fn render(
        &mut self,
        view: &View,
        width: u32,
        height: u32,
    ) -> Result<RenderedFrame, GpuError> {
        if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
            return Err(GpuError::Unsupported(format!(
                "image size {width}x{height} is outside 1x1..{MAX_SIDE}x{MAX_SIDE}"
            )));
        }
        let start = Instant::now();
        let map_size = if view.shadow.enabled {
            view.shadow.map_size.clamp(16, 16384)
        } else {
            1
        };
        if self.shadow.ensure_map(map_size, view.shadow.format)? {
            let hw = self.shadow.hardware_filtering();
            self.camera.bind_shadow_map(
                self.shadow.map.as_ref().map(|m| m.view).unwrap_or_default(),
                hw,
            );
        }
        let hw = self.shadow.hardware_filtering();
        self.ensure_target(width, height)?;
        let mut v = view.clone();
        v.shadow.map_size = map_size;
        let plan = plan_frame(
            &self.scene,
            &self.gpu.bounds,
            &v,
            width as f32 / height as f32,
            hw,
        );
        self.camera.write_frame(&plan.uniform)?;

        let ctx = self.ctx.clone();
        let d = &ctx.device;
        let cmd = self.cmd;
        let timestamps = ctx.timestamp_valid_bits > 0;
        let want_map = view.mode == ViewMode::ShadowMap;
        if want_map {
            let bytes_per = if view.shadow.format == ShadowFormat::D16 {
                2
            } else {
                4
            };
            let need = map_size as u64 * map_size as u64 * bytes_per;
            if self.shadow_readback.as_ref().is_none_or(|b| b.size < need) {
                self.shadow_readback = Some(Buffer::new(
                    &ctx,
                    "shadow map readback",
                    need,
                    vk::BufferUsageFlags::TRANSFER_DST,
                    MemoryLocation::GpuToCpu,
                )?);
            }
        }
        let casters;
        unsafe {
            d.reset_command_buffer(cmd, vk::CommandBufferResetFlags::empty())
                .vk("vkResetCommandBuffer")?;
            d.begin_command_buffer(
                cmd,
                &vk::CommandBufferBeginInfo::default()
                    .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
            )
            .vk("vkBeginCommandBuffer")?;
            if timestamps {
                d.cmd_reset_query_pool(cmd, self.query_pool, 0, 3);
                d.cmd_write_timestamp2(
                    cmd,
                    vk::PipelineStageFlags2::TOP_OF_PIPE,
                    self.query_pool,
                    0,
                );
            }
            let shadows_on = plan.uniform.shadow.w > 0.5;
            casters = self.shadow.record(
                cmd,
                &self.gpu,
                &plan.light_clip_from_world,
                &view.shadow,
                shadows_on,
            );
            if timestamps {
                d.cmd_write_timestamp2(
                    cmd,
                    vk::PipelineStageFlags2::ALL_COMMANDS,
                    self.query_pool,
                    1,
                );
            }
            let t = self.target.as_mut().expect("target");
            image_barrier(
                d,
                cmd,
                t.color.raw,
                vk::ImageAspectFlags::COLOR,
                0..1,
                t.color_state,
                Access::ColorAttachment,
            );
            image_barrier(
                d,
                cmd,
                t.depth.raw,
                vk::ImageAspectFlags::DEPTH,
                0..1,
                t.depth_state,
                Access::DepthAttachment,
            );
            self.camera.record(
                cmd,
                &self.gpu,
                t.color.view,
                t.depth.view,
                t.color.extent,
                CLEAR_COLOR,
            );
            if timestamps {
                d.cmd_write_timestamp2(
                    cmd,
                    vk::PipelineStageFlags2::ALL_COMMANDS,
                    self.query_pool,
                    2,
                );
            }
            image_barrier(
                d,
                cmd,
                t.color.raw,
                vk::ImageAspectFlags::COLOR,
                0..1,
                Access::ColorAttachment,
                Access::TransferSrc,
            );
            t.color_state = Access::TransferSrc;
            t.depth_state = Access::DepthAttachment;
            let region = [vk::BufferImageCopy::default()
                .buffer_row_length(0)
                .image_subresource(vk::ImageSubresourceLayers {
                    aspect_mask: vk::ImageAspectFlags::COLOR,
                    mip_level: 0,
                    base_array_layer: 0,
                    layer_count: 1,
                })
                .image_extent(vk::Extent3D {
                    width,
                    height,
                    depth: 1,
                })];
            d.cmd_copy_image_to_buffer(
                cmd,
                t.color.raw,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                t.readback.raw,
                &region,
            );
            if self.read_depth {
                image_barrier(
                    d,
                    cmd,
                    t.depth.raw,
                    vk::ImageAspectFlags::DEPTH,
                    0..1,
                    Access::DepthAttachment,
                    Access::TransferSrc,
                );
                t.depth_state = Access::TransferSrc;
                let region = [vk::BufferImageCopy::default()
                    .image_subresource(vk::ImageSubresourceLayers {
                        aspect_mask: vk::ImageAspectFlags::DEPTH,
                        mip_level: 0,
                        base_array_layer: 0,
                        layer_count: 1,
                    })
                    .image_extent(vk::Extent3D {
                        width,
                        height,
                        depth: 1,
                    })];
                d.cmd_copy_image_to_buffer(
                    cmd,
                    t.depth.raw,
                    vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    t.depth_readback.raw,
                    &region,
                );
            }
            if want_map {
                let map = self.shadow.map.as_ref().expect("map");
                image_barrier(
                    d,
                    cmd,
                    map.raw,
                    vk::ImageAspectFlags::DEPTH,
                    0..1,
                    Access::DepthFragmentSampled,
                    Access::TransferSrc,
                );
                let region = [vk::BufferImageCopy::default()
                    .image_subresource(vk::ImageSubresourceLayers {
                        aspect_mask: vk::ImageAspectFlags::DEPTH,
                        mip_level: 0,
                        base_array_layer: 0,
                        layer_count: 1,
                    })
                    .image_extent(vk::Extent3D {
                        width: map_size,
                        height: map_size,
                        depth: 1,
                    })];
                d.cmd_copy_image_to_buffer(
                    cmd,
                    map.raw,
                    vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    self.shadow_readback.as_ref().expect("buffer").raw,
                    &region,
                );
                self.shadow.set_state(Access::TransferSrc);
            }
            // Make the copies visible to the host.
            let mb = [vk::MemoryBarrier2::default()
                .src_stage_mask(vk::PipelineStageFlags2::ALL_TRANSFER)
                .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
                .dst_stage_mask(vk::PipelineStageFlags2::HOST)
                .dst_access_mask(vk::AccessFlags2::HOST_READ)];
            d.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().memory_barriers(&mb));
            d.end_command_buffer(cmd).vk("vkEndCommandBuffer")?;
        }
        ctx.submit_and_wait(cmd)?;
        let mut stats = FrameStats {
            casters_drawn: casters,
            draws: self.gpu.draws.len(),
            triangles: self.gpu.triangles,
            hardware_compare: hw,
            ..Default::default()
        };
        if timestamps {
            let mut q = [0u64; 3];
            unsafe {
                d.get_query_pool_results(
                    self.query_pool,
                    0,
                    &mut q,
                    vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
                )
            }
            .vk("vkGetQueryPoolResults")?;
            let period = ctx.properties.limits.timestamp_period as f64 * 1e-6;
            stats.gpu_shadow_ms = Some(q[1].wrapping_sub(q[0]) as f64 * period);
            stats.gpu_camera_ms = Some(q[2].wrapping_sub(q[1]) as f64 * period);
        }
        let image = if want_map {
            let buf = self.shadow_readback.as_mut().expect("buffer");
            let bytes = buf
                .mapped()
                .ok_or_else(|| GpuError::Unsupported("readback not mapped".into()))?;
            let n = (map_size * map_size) as usize;
            let grey: Vec<u8> = if view.shadow.format == ShadowFormat::D16 {
                bytemuck::cast_slice::<u8, u16>(&bytes[..n * 2])
                    .iter()
                    .map(|&v| (v >> 8) as u8)
                    .collect()
            } else {
                bytemuck::cast_slice::<u8, f32>(&bytes[..n * 4])
                    .iter()
                    .map(|&v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
                    .collect()
            };
            let rgba: Vec<u8> = grey.iter().flat_map(|&g| [g, g, g, 255]).collect();
            image::RgbaImage::from_raw(map_size, map_size, rgba).expect("size")
        } else {
            let t = self.target.as_mut().expect("target");
            let bytes = t
                .readback
                .mapped()
                .ok_or_else(|| GpuError::Unsupported("readback not mapped".into()))?;
            // Tightly packed rows (bufferRowLength 0): row pitch = width * 4.
            let pitch = width as usize * 4;
            let mut rgba = Vec::with_capacity(pitch * height as usize);
            for row in 0..height as usize {
                rgba.extend_from_slice(&bytes[row * pitch..row * pitch + pitch]);
            }
            image::RgbaImage::from_raw(width, height, rgba).expect("size")
        };
        let depth = if self.read_depth {
            let t = self.target.as_mut().expect("target");
            let bytes = t
                .depth_readback
                .mapped()
                .ok_or_else(|| GpuError::Unsupported("readback not mapped".into()))?;
            Some(bytemuck::cast_slice::<u8, f32>(&bytes[..(width * height * 4) as usize]).to_vec())
        } else {
            None
        };
        stats.wall_ms = start.elapsed().as_secs_f64() * 1e3;
        Ok(RenderedFrame {
            image,
            stats,
            plan,
            depth,
        })
    }
}

impl Drop for Renderer {
    fn drop(&mut self) {
        unsafe {
            let _ = self.ctx.device.device_wait_idle();
            self.ctx.device.destroy_query_pool(self.query_pool, None);
        }
        self.ctx.free_command_buffer(self.cmd);
    }
}
