//! One frame's submission and readback: recorded and submitted without waiting
//! (`Renderer::submit_frame`), then waited for and read back (`Renderer::finish_frame`), in a
//! ring slot of its own (`RING`: command buffer, fence, uniform slot, readbacks), so that
//! a batch keeps frames in flight.

use super::{
    aov, check_size, check_supersample, copy_attachment_to_buffer, copy_to_buffer,
    rgba_from_readback, transfer_to_host_barrier, AovSet, FrameStats, RenderedFrame, Renderer,
    Target,
};
use crate::gpu::barrier::Access;
use crate::gpu::context::{GpuError, VkCheck};
use crate::gpu::resources::blit_linear;
use crate::gpu::Uses;
use crate::plan::view::View;
use crate::plan::FramePlan;
use crate::render::core::Targets;
use ash::vk;
use std::time::Instant;

impl Renderer {
    /// One frame in ring slot 0, waited for: `submit_frame`, then `finish_frame`.
    pub(super) fn render_once(
        &mut self,
        view: &View,
        size: (u32, u32),
        aovs: Option<AovSet>,
    ) -> Result<(RenderedFrame, Option<aov::IdsNormals>), GpuError> {
        let p = self.submit_frame(0, view, size, aovs)?;
        self.finish_frame(p)
    }

    /// Prepares, records and submits `view` at `width`×`height` in ring slot `slot` (whose
    /// previous frame must have been finished), without waiting: `finish_frame` reads it back.
    /// With `aovs` the camera pass draws the instance ids and normals too where it can.
    pub(super) fn submit_frame(
        &mut self,
        slot: usize,
        view: &View,
        (width, height): (u32, u32),
        aovs: Option<AovSet>,
    ) -> Result<Pending, GpuError> {
        check_size(width, height)?;
        let s = view.supersample;
        check_supersample(&self.core.ctx, s)?;
        let extent = vk::Extent2D { width, height };
        let (dw, dh) = (width * s, height * s);
        check_size(dw, dh)?;
        let start = Instant::now();
        // The camera pass draws the AOVs asked for at one sample per pixel (`render_with_aovs`).
        let aovs = aovs.filter(|_| s == 1);
        let prepared = self
            .core
            .prepare_with(slot, view, (dw, dh), aovs.is_some())?;
        let aovs = aovs.filter(|_| prepared.draws_aovs());
        if aovs.is_some() {
            aov::AovTarget::ensure(self, extent)?;
        }
        self.ensure_target(dw, dh, (s > 1).then_some(extent))?;
        let ctx = self.core.ctx.clone();
        let d = &ctx.device;
        let cmd = self.cmds[slot];
        let drawn = vk::Extent2D {
            width: dw,
            height: dh,
        };
        let t = self.target.as_mut().expect("target");
        let mut aov_target = self.aov.as_mut().zip(aovs);
        ctx.begin_one_time(cmd)?;
        let counts = self.core.record(
            cmd,
            &prepared,
            Targets {
                color: &mut t.color_at,
                depth: &mut t.depth_at,
                msaa: t.msaa.as_mut(),
                resolve_depth: self.read_depth,
                aovs: aov_target.as_mut().map(|(a, set)| a.color_targets(*set)),
            },
        );
        if let Some((a, set)) = aov_target {
            // The depth is the frame's own (`read_depth`).
            a.record_copies(d, cmd, set, false, slot);
        }
        record_readback(d, cmd, t, (extent, drawn), self.read_depth, slot);
        unsafe { d.end_command_buffer(cmd).vk("vkEndCommandBuffer")? };
        ctx.submit_with(cmd, self.fences[slot])?;
        Ok(Pending {
            slot,
            start,
            plan: prepared.plan,
            counts,
            size: (width, height),
            drawn,
            read_depth: self.read_depth,
            aovs,
        })
    }

    /// Waits for a frame `submit_frame` submitted and reads it back, with the instance ids and
    /// normals its camera pass drew (those asked for; None when it drew none).
    pub(super) fn finish_frame(
        &mut self,
        p: Pending,
    ) -> Result<(RenderedFrame, Option<aov::IdsNormals>), GpuError> {
        self.core.ctx.wait_and_reset(self.fences[p.slot])?;
        let times = self.core.gpu_times(p.slot);
        let (plan, counts) = (p.plan, p.counts);
        let mut stats = FrameStats {
            gpu_shadow_ms: times.map(|t| t.0),
            gpu_camera_ms: times.map(|t| t.1),
            wall_ms: 0.0,
            casters_drawn: counts.casters,
            draws: counts.camera_draws,
            deferred_draws: counts.deferred_draws,
            unshadowed_draws: counts.unshadowed_draws,
            flat_draws: counts.flat_draws,
            draws_total: self.core.gpu.draws.len(),
            triangles: self.core.gpu.triangles,
            hardware_compare: self.core.shadow.hardware_filtering(plan.shadow_format),
            aovs_in_camera_pass: p.aovs.is_some(),
            grid_triangles: self.core.grid_triangles(p.slot, &plan),
        };
        let t = self.target.as_mut().expect("target");
        let (image, depth) = read_back(t, p.size, p.drawn, p.read_depth, p.slot)?;
        let drawn = match (self.aov.as_mut(), p.aovs) {
            (Some(a), Some(set)) => {
                let (ids, normals, _) = a.read(set, false, p.slot)?;
                Some((ids, normals))
            }
            _ => None,
        };
        stats.wall_ms = p.start.elapsed().as_secs_f64() * 1e3;
        let frame = RenderedFrame {
            image,
            stats,
            plan,
            depth,
        };
        Ok((frame, drawn))
    }
}

/// A frame submitted by `Renderer::submit_frame`, not yet read back.
pub(super) struct Pending {
    slot: usize,
    start: Instant,
    plan: FramePlan,
    counts: crate::render::core::PassCounts,
    /// The image size.
    size: (u32, u32),
    /// The drawn size (supersampled).
    drawn: vk::Extent2D,
    read_depth: bool,
    /// The AOVs its camera pass draws.
    aovs: Option<AovSet>,
}

/// Records the copies a frame is read back from: the colour (through the 2:1 filter when
/// supersampled) at `extent`, and with `read_depth` the depth at the `drawn` size, then makes
/// them visible to the host.
fn record_readback(
    d: &ash::Device,
    cmd: vk::CommandBuffer,
    t: &mut Target,
    (extent, drawn): (vk::Extent2D, vk::Extent2D),
    read_depth: bool,
    slot: usize,
) {
    let (dw, dh, width, height) = (drawn.width, drawn.height, extent.width, extent.height);
    // The colour is copied from, whether into the filtered image or straight to the buffer.
    let colour = Uses::new().reads(&mut t.color_at, Access::TransferSrc);
    let shown = match t.filtered.as_mut() {
        Some((image, at)) => {
            colour.writes(at, Access::TransferDst).enter(d, cmd);
            // 2:1: each pixel the mean of its 2×2 samples, in linear light.
            let (dw, dh, w, h) = (dw as i32, dh as i32, width as i32, height as i32);
            blit_linear(d, cmd, (t.color.raw, 0, dw, dh), (image.raw, 0, w, h));
            Uses::new().reads(at, Access::TransferSrc).enter(d, cmd);
            image.raw
        }
        None => {
            colour.enter(d, cmd);
            t.color.raw
        }
    };
    copy_to_buffer(
        d,
        cmd,
        shown,
        vk::ImageAspectFlags::COLOR,
        extent,
        t.readback[slot].raw,
    );
    if read_depth {
        let (depth, buffer) = (vk::ImageAspectFlags::DEPTH, t.depth_readback[slot].raw);
        copy_attachment_to_buffer(d, cmd, &mut t.depth_at, depth, drawn, buffer);
    }
    transfer_to_host_barrier(d, cmd);
}

/// The image (`width`×`height`) and, with `read_depth`, the depth (`drawn` size) a frame's
/// readback buffers hold.
fn read_back(
    t: &mut Target,
    (width, height): (u32, u32),
    drawn: vk::Extent2D,
    read_depth: bool,
    slot: usize,
) -> Result<(image::RgbaImage, Option<Vec<f32>>), GpuError> {
    let (dw, dh) = (drawn.width, drawn.height);
    let bytes = t.readback[slot]
        .mapped()
        .ok_or_else(|| GpuError::Unsupported("readback not mapped".into()))?;
    let image = rgba_from_readback(bytes, width, height, false);
    let depth = if read_depth {
        let bytes = t.depth_readback[slot]
            .mapped()
            .ok_or_else(|| GpuError::Unsupported("readback not mapped".into()))?;
        Some(bytemuck::pod_collect_to_vec(
            &bytes[..(dw * dh * 4) as usize],
        ))
    } else {
        None
    };
    Ok((image, depth))
}
