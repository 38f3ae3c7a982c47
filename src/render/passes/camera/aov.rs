//! The AOV pass: each visible opaque or masked surface's instance id and world normal.

use super::*;
use crate::gpu::resources::has_stencil;
use crate::gpu::Recorder;
use crate::render::gpu_scene::{AlphaDraw, GpuScene};
use crate::render::passes::cull::Entry;
use crate::render::pipeline::depth_clear_attachment;
use ash::vk;

/// The AOV pass's colour targets: the instance id + 1 of each pixel's surface (0: none), and its
/// world normal.
pub const AOV_FORMATS: [vk::Format; 2] = [vk::Format::R32_UINT, vk::Format::R32G32B32A32_SFLOAT];

/// What the AOV pass draws into (already in attachment layouts): ids, normals, depth (the pass's
/// depth format, one sample).
#[derive(Clone, Copy, Debug)]
pub struct AovTargets {
    /// `AOV_FORMATS[0]`.
    pub ids: vk::ImageView,
    /// `AOV_FORMATS[1]`.
    pub normals: vk::ImageView,
    /// Depth.
    pub depth: vk::ImageView,
    /// The image size.
    pub extent: vk::Extent2D,
}

/// The attachments of the id and normal targets: cleared to 0 (no surface), or with `load` kept
/// from an earlier pass (the G-buffer pass drew the deferred draws' first).
pub(super) fn aov_attachments(
    ids: vk::ImageView,
    normals: vk::ImageView,
    load: bool,
) -> [vk::RenderingAttachmentInfo<'static>; 2] {
    [
        (ids, vk::ClearColorValue { uint32: [0; 4] }),
        (normals, vk::ClearColorValue { float32: [0.0; 4] }),
    ]
    .map(|(view, clear)| {
        vk::RenderingAttachmentInfo::default()
            .image_view(view)
            .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .load_op(if load {
                vk::AttachmentLoadOp::LOAD
            } else {
                vk::AttachmentLoadOp::CLEAR
            })
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue { color: clear })
    })
}

/// The draws the AOV pass records for `frame`: its visible draws, blended ones left out.
pub(super) fn aov_draws<'a>(
    scene: &'a GpuScene,
    frame: &'a CameraFrame,
) -> impl Iterator<Item = usize> + 'a {
    let d = &frame.defer;
    d.deferred
        .iter()
        .map(|&(i, _)| i)
        .chain(d.forward.iter().copied())
        .filter(|&i| scene.draws[i].alpha != AlphaDraw::Blended)
}

impl CameraPass {
    /// Records the AOV pass of `frame` (slot `slot`'s uniforms): every visible opaque and masked
    /// draw, depth-tested, writing its instance id + 1 and world normal (`fs_aov`,
    /// `fs_aov_masked`). Returns the
    /// draws recorded.
    pub fn record_aov(
        &self,
        cmd: vk::CommandBuffer,
        slot: usize,
        scene: &GpuScene,
        t: &AovTargets,
        frame: &CameraFrame,
    ) -> usize {
        let d = &self.ctx.device;
        let colors = aov_attachments(t.ids, t.normals, false);
        let stencil = has_stencil(self.depth_format);
        let depth = depth_clear_attachment(t.depth, stencil);
        let mut rendering = vk::RenderingInfo::default()
            .render_area(full_rect(t.extent))
            .layer_count(1)
            .color_attachments(&colors)
            .depth_attachment(&depth);
        if stencil {
            rendering = rendering.stencil_attachment(&depth);
        }
        self.ctx.begin_label(cmd, "AOV pass");
        self.begin_rendering(cmd, &rendering, t.extent, self.slots[slot].set);
        scene.bind_geometry(d, cmd);
        let cull = &frame.cull;
        let (mut bound_material, mut drawn) = (usize::MAX, 0);
        for i in aov_draws(scene, frame) {
            let dr = &scene.draws[i];
            if dr.material != bound_material {
                scene.bind_material(d, cmd, self.layout, 1, dr.material);
                bound_material = dr.material;
            }
            // Made by `ensure_aov_pipelines`.
            let pipeline = self.pipelines[&(dr.material_bits, Entry::aov(dr.alpha))];
            Recorder::new(d, cmd).bind_pipeline(vk::PipelineBindPoint::GRAPHICS, pipeline);
            // `normal_z.w` holds the instance id (`SceneImmediates::with_instance`).
            let imm = dr.immediates;
            scene.record_draw(
                cmd,
                self.layout,
                dr,
                Some(cull.eye),
                cull.viewpoint,
                bytemuck::bytes_of(&imm),
            );
            drawn += 1;
        }
        Recorder::new(d, cmd).end_rendering();
        self.ctx.end_label(cmd);
        drawn
    }
}
