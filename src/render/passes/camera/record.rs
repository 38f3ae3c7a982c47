//! Recording a camera frame: the G-buffer pass, the resolves, the forward draws split by their
//! receivers, the sky.

use super::*;
use crate::gpu::barrier::Access;
use crate::gpu::resources::has_stencil;
use crate::gpu::{Recorder, Uses};
use crate::render::gpu_scene::GpuScene;
use crate::render::passes::cull::{CameraCull, Entry};
use crate::render::passes::deferred::{self, DeferPlan};
use crate::render::passes::receivers::{self, Split};
use crate::render::pipeline::{depth_clear_attachment, set_viewport};
use crate::shader_consts::VariantKey;
use ash::vk;

impl CameraPass {
    /// Records the pass into colour and depth attachments already in attachment layouts; with
    /// `shadow_map_view` it draws the shadow map full-screen instead of the scene. Draws that
    /// `deferred::plan` picks (their pipelines made by `ensure_pipelines`) go through the
    /// G-buffer first, and their materials are resolved before the forward draws. Returns the
    /// draws recorded, how many of them were deferred, and how many were drawn (in part) without
    /// the shadow lookup (`receivers::split`).
    pub fn record(
        &mut self,
        cmd: vk::CommandBuffer,
        (slot, scene): (usize, &GpuScene),
        (targets, redrawn): (&CameraTargets, Redrawn<'_>),
        frame: &CameraFrame,
    ) -> CameraCounts {
        let (cull, shadow_map_view, plan) = (&frame.cull, frame.shadow_map_view, &frame.defer);
        let extent = targets.extent;
        let ctx = self.ctx.clone();
        let d = &ctx.device;
        ctx.begin_label(cmd, "camera pass");
        let stencil = has_stencil(self.depth_format);
        let deferring = !plan.deferred.is_empty();
        // `ensure_pipelines` made the frame's pipelines for these targets.
        debug_assert_eq!(frame.aovs, targets.aovs.is_some());
        let frame_set = self.slots[slot].set;
        let mut drawn = 0;
        let mut unshadowed = 0;
        let mut deferred_draws = 0;
        if deferring {
            deferred_draws =
                self.record_gbuffer(cmd, scene, (targets, redrawn), frame_set, (plan, cull));
        }
        let (color_att, depth_att) = main_attachments(targets, stencil, deferring);
        let mut rendering = vk::RenderingInfo::default()
            .render_area(full_rect(extent))
            .layer_count(1)
            .color_attachments(&color_att)
            .depth_attachment(&depth_att);
        if stencil {
            rendering = rendering.stencil_attachment(&depth_att);
        }
        self.begin_rendering(cmd, &rendering, extent, frame_set);
        if shadow_map_view {
            Recorder::new(d, cmd).bind_pipeline(vk::PipelineBindPoint::GRAPHICS, self.map_pipeline);
            Recorder::new(d, cmd).set_cull_mode(vk::CullModeFlags::NONE);
            Recorder::new(d, cmd).set_front_face(vk::FrontFace::COUNTER_CLOCKWISE);
            Recorder::new(d, cmd).draw(3, 1, 0, 0);
        }
        if deferring {
            self.record_resolve(cmd, scene, frame, extent);
        }
        if !plan.forward.is_empty() || frame.sky {
            let (n, u) = self.record_forward(cmd, scene, frame, extent);
            drawn += n;
            unshadowed += u;
        }
        Recorder::new(d, cmd).end_rendering();
        ctx.end_label(cmd);
        CameraCounts {
            drawn: drawn + deferred_draws,
            deferred: deferred_draws,
            unshadowed,
            flat: frame.flat.iter().filter(|&&f| f).count(),
        }
    }

    /// Records the forward draws of the frame, splitting each into its shadowed and unshadowed
    /// pieces (`receivers::split`), and with `frame.sky` the sky after the opaque and masked draws
    /// and before the blended ones (which composite over it). Returns the draws recorded and how
    /// many of them were drawn (in part) without the shadow lookup.
    fn record_forward(
        &self,
        cmd: vk::CommandBuffer,
        scene: &GpuScene,
        frame: &CameraFrame,
        extent: vk::Extent2D,
    ) -> (usize, usize) {
        let cull = &frame.cull;
        let d = &self.ctx.device;
        let (mut drawn, mut unshadowed) = (0, 0);
        scene.bind_geometry(d, cmd);
        let mut bound_material = usize::MAX;
        let mut bound_pipeline = vk::Pipeline::null();
        let mut sky = frame.sky;
        let forward = frame.defer.forward.iter().zip(&frame.splits);
        for ((&i, split), &flat) in forward.zip(&frame.flat) {
            let dr = &scene.draws[i];
            let entry = frame.entry(dr.alpha, flat);
            if sky && matches!(entry, Entry::Blended | Entry::BlendedAov) {
                bound_pipeline = self.record_sky(cmd, frame.aovs);
                sky = false;
            }
            let bits = dr.material_bits | cull.frame_bits;
            unshadowed += usize::from(*split != Split::Shadowed);
            let pieces = pieces(bits, split.clone());
            drawn += 1;
            if dr.material != bound_material {
                scene.bind_material(d, cmd, self.layout, 1, dr.material);
                bound_material = dr.material;
            }
            let mut imm = dr.immediates;
            if cull.highlight == Some(dr.source) {
                imm.normal_y.w = 1.0;
            }
            for &(variant, scissor) in &pieces {
                // Created by `ensure_pipelines` for this frame's bits.
                let pipeline = self.pipelines[&(variant, entry)];
                if pipeline != bound_pipeline {
                    Recorder::new(d, cmd).bind_pipeline(vk::PipelineBindPoint::GRAPHICS, pipeline);
                    bound_pipeline = pipeline;
                }
                if let Some(s) = scissor {
                    Recorder::new(d, cmd).set_scissor(0, &[s]);
                }
                scene.record_draw(
                    cmd,
                    self.layout,
                    dr,
                    Some(cull.eye),
                    cull.viewpoint,
                    bytemuck::bytes_of(&imm),
                );
            }
            if pieces.iter().any(|p| p.1.is_some()) {
                Recorder::new(d, cmd).set_scissor(0, &[full_rect(extent)]);
            }
        }
        if sky {
            self.record_sky(cmd, frame.aovs);
        }
        (drawn, unshadowed)
    }

    /// Records the sky: one full-screen triangle at depth 0, shaded only where no surface was
    /// drawn (inside a rendering whose set 0 is bound); `aovs`: in a pass that also draws the ids
    /// and normals. Returns the pipeline bound.
    fn record_sky(&self, cmd: vk::CommandBuffer, aovs: bool) -> vk::Pipeline {
        let d = &self.ctx.device;
        // Made by `ensure_pipelines` for a frame with `aovs`.
        let pipeline = match self.sky_aovs {
            Some(p) if aovs => p,
            _ => self.sky_pipeline,
        };
        Recorder::new(d, cmd).bind_pipeline(vk::PipelineBindPoint::GRAPHICS, pipeline);
        Recorder::new(d, cmd).set_cull_mode(vk::CullModeFlags::NONE);
        Recorder::new(d, cmd).set_front_face(vk::FrontFace::COUNTER_CLOCKWISE);
        Recorder::new(d, cmd).draw(3, 1, 0, 0);
        pipeline
    }

    /// Records the G-buffer pass of `plan`'s deferred draws (clearing depth and stencil, each
    /// draw marking its material), then hands the targets on to the resolves and the depth,
    /// stencil, ids and normals (`redrawn`) on to the rendering that draws on over them.
    /// Returns the number of draws.
    fn record_gbuffer(
        &mut self,
        cmd: vk::CommandBuffer,
        scene: &GpuScene,
        (targets, redrawn): (&CameraTargets, Redrawn<'_>),
        frame_set: vk::DescriptorSet,
        (plan, cull): (&DeferPlan, &CameraCull),
    ) -> usize {
        let (depth, extent) = (targets.depth, targets.extent);
        let ctx = self.ctx.clone();
        let d = &ctx.device;
        let Some(gbuffer) = self.gbuffer.as_mut() else {
            return 0;
        };
        ctx.begin_label(cmd, "G-buffer");
        Uses::new()
            .writes_each(&mut gbuffer.targets, Access::ColorAttachment)
            .enter(d, cmd);
        let views = gbuffer.views();
        // With the ids and normals, those first (cleared; the forward pass keeps them).
        let aovs = targets.aovs;
        let entry = if aovs.is_some() {
            Entry::GBufferAov
        } else {
            Entry::GBuffer
        };
        let aov_targets = aovs
            .into_iter()
            .flat_map(|[ids, normals]| aov_attachments(ids, normals, false));
        let targets: Vec<vk::RenderingAttachmentInfo> = aov_targets
            .chain(views.into_iter().map(|v| {
                // Only marked pixels are read, and those are written: nothing to load.
                vk::RenderingAttachmentInfo::default()
                    .image_view(v)
                    .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                    .load_op(vk::AttachmentLoadOp::DONT_CARE)
                    .store_op(vk::AttachmentStoreOp::STORE)
            }))
            .collect();
        let depth_att = depth_clear_attachment(depth, true);
        let rendering = vk::RenderingInfo::default()
            .render_area(full_rect(extent))
            .layer_count(1)
            .color_attachments(&targets)
            .depth_attachment(&depth_att)
            .stencil_attachment(&depth_att);
        self.begin_rendering(cmd, &rendering, extent, frame_set);
        scene.bind_geometry(d, cmd);
        let mut bound = None;
        for &(i, mark) in &plan.deferred {
            let dr = &scene.draws[i];
            let variant = deferred::gbuffer_variant(dr.material_bits);
            if bound != Some(variant) {
                // Made by `ensure_pipelines` for this frame.
                let pipeline = self.pipelines[&(variant, entry)];
                Recorder::new(d, cmd).bind_pipeline(vk::PipelineBindPoint::GRAPHICS, pipeline);
                bound = Some(variant);
            }
            Recorder::new(d, cmd).set_stencil_reference(vk::StencilFaceFlags::FRONT_AND_BACK, mark);
            scene.record_draw(
                cmd,
                self.layout,
                dr,
                Some(cull.eye),
                cull.viewpoint,
                bytemuck::bytes_of(&dr.immediates),
            );
        }
        Recorder::new(d, cmd).end_rendering();
        // The targets handed on to the resolves (`textureLoad`); the depth and stencil (stencil
        // and depth tests), ids and normals (loaded, drawn over) written again after.
        let read = self.gbuffer.as_mut().map(|g| &mut g.targets);
        Uses::new()
            .reads_each(read.into_iter().flatten(), Access::FragmentSampled)
            .writes(redrawn.depth, Access::DepthAttachment)
            .writes_each(redrawn.aovs, Access::ColorAttachment)
            .enter(d, cmd);
        ctx.end_label(cmd);
        plan.deferred.len()
    }

    /// Begins `rendering` with a full-extent viewport and the frame's set 0 bound (every camera
    /// pipeline shares the layout).
    pub(super) fn begin_rendering(
        &self,
        cmd: vk::CommandBuffer,
        rendering: &vk::RenderingInfo,
        extent: vk::Extent2D,
        frame_set: vk::DescriptorSet,
    ) {
        let d = &self.ctx.device;
        Recorder::new(d, cmd).begin_rendering(rendering);
        set_viewport(&self.ctx, cmd, extent);
        Recorder::new(d, cmd).bind_descriptor_sets(
            vk::PipelineBindPoint::GRAPHICS,
            self.layout,
            0,
            &[frame_set],
            &[],
        );
    }

    /// Records one full-screen triangle per resolved material of `plan`, limited to its draws'
    /// screen rectangle and to the pixels its stencil mark holds (inside a rendering whose set 0
    /// is bound); restores the full scissor.
    fn record_resolve(
        &self,
        cmd: vk::CommandBuffer,
        scene: &GpuScene,
        frame: &CameraFrame,
        extent: vk::Extent2D,
    ) {
        let (plan, frame_bits) = (&frame.defer, frame.cull.frame_bits);
        let entry = frame.with_aovs(Entry::Resolve);
        let Some(gbuffer) = self.gbuffer.as_ref() else {
            return;
        };
        let d = &self.ctx.device;
        Recorder::new(d, cmd).bind_descriptor_sets(
            vk::PipelineBindPoint::GRAPHICS,
            self.layout,
            2,
            &[gbuffer.set],
            &[],
        );
        Recorder::new(d, cmd).set_cull_mode(vk::CullModeFlags::NONE);
        Recorder::new(d, cmd).set_front_face(vk::FrontFace::COUNTER_CLOCKWISE);
        for r in &plan.resolved {
            let pipeline = self.pipelines[&(r.material_bits | frame_bits, entry)];
            Recorder::new(d, cmd).bind_pipeline(vk::PipelineBindPoint::GRAPHICS, pipeline);
            scene.bind_material(d, cmd, self.layout, 1, r.material);
            Recorder::new(d, cmd)
                .set_stencil_reference(vk::StencilFaceFlags::FRONT_AND_BACK, r.mark);
            Recorder::new(d, cmd).set_scissor(0, &[r.rect.scissor()]);
            Recorder::new(d, cmd).draw(3, 1, 0, 0);
        }
        Recorder::new(d, cmd).set_scissor(0, &[full_rect(extent)]);
    }
}

/// The whole of an `extent` image, as a scissor.
pub(super) fn full_rect(extent: vk::Extent2D) -> vk::Rect2D {
    vk::Rect2D {
        offset: vk::Offset2D::default(),
        extent,
    }
}

/// The (variant, scissor) of each piece a draw of variant `bits` is drawn in (`None`: the whole
/// image): the unshadowed variant where `split` says the lookup cannot shadow anything.
fn pieces(bits: VariantKey, split: Split) -> Vec<(VariantKey, Option<vk::Rect2D>)> {
    match split {
        Split::Shadowed => vec![(bits, None)],
        Split::Unshadowed => vec![(receivers::unshadowed(bits), None)],
        Split::Both { inside, outside } => std::iter::once((bits, Some(inside)))
            .chain(
                outside
                    .into_iter()
                    .map(|r| (receivers::unshadowed(bits), Some(r))),
            )
            .collect(),
    }
}

/// The camera pass's attachments after the G-buffer pass (`deferring`: its depth, stencil marks,
/// ids and normals kept): the colour (resolved with MSAA) with the ids and normals when the
/// frame draws them, and the depth (and `stencil`; sample 0 resolved for depth readback).
fn main_attachments(
    targets: &CameraTargets,
    stencil: bool,
    deferring: bool,
) -> (
    Vec<vk::RenderingAttachmentInfo<'static>>,
    vk::RenderingAttachmentInfo<'static>,
) {
    let t = targets;
    let mut color_att = vk::RenderingAttachmentInfo::default()
        .image_view(t.color)
        .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
        .load_op(vk::AttachmentLoadOp::CLEAR)
        .store_op(vk::AttachmentStoreOp::STORE)
        .clear_value(vk::ClearValue {
            color: vk::ClearColorValue { float32: t.clear },
        });
    let mut depth_att = depth_clear_attachment(t.depth, stencil);
    if deferring {
        // The G-buffer pass's depth and stencil marks.
        depth_att = depth_att.load_op(vk::AttachmentLoadOp::LOAD);
    }
    if let Some(target) = t.resolve.color {
        // The samples are averaged into the target; they need not be kept.
        color_att = color_att
            .store_op(vk::AttachmentStoreOp::DONT_CARE)
            .resolve_mode(vk::ResolveModeFlags::AVERAGE)
            .resolve_image_view(target)
            .resolve_image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
    }
    if let Some(target) = t.resolve.depth {
        // Sample 0 (every device supports it): the depth of the pixel centre's nearest sample.
        depth_att = depth_att
            .resolve_mode(vk::ResolveModeFlags::SAMPLE_ZERO)
            .resolve_image_view(target)
            .resolve_image_layout(vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL);
    }
    // The ids and normals: cleared here, or kept from the G-buffer pass, which drew the deferred
    // draws' first.
    let mut colors = vec![color_att];
    if let Some([ids, normals]) = t.aovs {
        colors.extend(aov_attachments(ids, normals, deferring));
    }
    (colors, depth_att)
}
