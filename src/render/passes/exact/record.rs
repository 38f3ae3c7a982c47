//! Recording the exact pass: the receivers' positions and normals, each pixel's ray binned into
//! the grid of light views, the casters drawn into the grid.

use super::*;
use crate::gpu::barrier::Access;
use crate::gpu::{BufferAccess, Recorder, Uses};
use crate::math::ray::RAY_OFFSET_RELATIVE;
use crate::plan::Viewpoint;
use crate::plan::{ExactMode, ExactPlan};
use crate::render::gpu_scene::GpuScene;
use crate::render::pipeline::{depth_clear_attachment, set_viewport};
use ash::vk;
use glam::{Mat4, Vec4};

impl ExactPass {
    /// Records the three steps for slot `slot` (after [`ExactPass::ensure`] and
    /// [`ExactPass::write_frame`]); binning reads the shadow map `map`. The camera
    /// pass's fragments then read the samples ([`ExactPass::verdicts`]).
    pub fn record(
        &mut self,
        cmd: vk::CommandBuffer,
        (slot, scene): (usize, &GpuScene),
        f: &ExactPlan,
        map: Option<&mut Attachment>,
    ) {
        let ctx = self.ctx.clone();
        let d = &ctx.device;
        let set = self.sets[slot];
        let mut t = self.targets.take().expect("exact targets made by ensure");
        let hybrid = f.hybrid.is_some();
        // The fills come after the previous frame's uses of the grid, the tiles, the arguments
        // and the mask. Binning reads the shadow map (the hybrid method's lit test; one binning
        // pipeline serves both methods, so its binding is in use either way).
        let fills = Uses::new()
            .writes_buffer(&mut t.heads, BufferAccess::TransferWrite)
            .reads_some(map, Access::DepthFragmentSampled);
        match hybrid {
            true => self
                .culling
                .fills(fills.writes_buffer(&mut t.tiles, BufferAccess::TransferWrite)),
            false => fills,
        }
        .enter(d, cmd);
        Recorder::new(d, cmd).fill_buffer(t.heads.raw(), 0, vk::WHOLE_SIZE, 0);
        if hybrid {
            Recorder::new(d, cmd).fill_buffer(t.tiles.raw(), 0, vk::WHOLE_SIZE, 0);
            self.culling.clear(cmd);
        }
        self.record_receivers(cmd, set, scene, f, &mut t);
        let groups = (t.extent.width.div_ceil(8), t.extent.height.div_ceil(8));
        if let ExactMode::Contact { .. } = f.mode {
            Uses::new()
                .writes_buffer(&mut t.samples, BufferAccess::ComputeWrite)
                .enter(d, cmd);
            bind(
                d,
                self.layout,
                cmd,
                (vk::PipelineBindPoint::COMPUTE, self.contact),
                set,
            );
            Recorder::new(d, cmd).dispatch(groups.0, groups.1, 1);
            self.targets = Some(t);
            return;
        }
        if hybrid {
            self.culling.record_thin(cmd, set, scene, f);
        }
        self.record_binning(cmd, set, groups, (&mut t, hybrid));
        let kept = hybrid.then(|| {
            self.culling
                .record(cmd, set, scene, (f, &mut t.tiles), slot)
        });
        self.record_casters(cmd, set, scene, f, (kept.as_deref(), &mut t));
        self.targets = Some(t);
    }

    /// Step 1: the receivers' world positions and normals, depth-tested, into `t`.
    fn record_receivers(
        &self,
        cmd: vk::CommandBuffer,
        set: vk::DescriptorSet,
        scene: &GpuScene,
        f: &ExactPlan,
        t: &mut Targets,
    ) {
        let ctx = &self.ctx;
        let d = &ctx.device;
        Uses::new()
            .writes(&mut t.position, Access::ColorAttachment)
            .writes(&mut t.normal, Access::ColorAttachment)
            .writes(&mut t.depth, Access::DepthAttachment)
            .enter(d, cmd);
        let clear = |view| {
            vk::RenderingAttachmentInfo::default()
                .image_view(view)
                .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                .load_op(vk::AttachmentLoadOp::CLEAR)
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(vk::ClearValue {
                    color: vk::ClearColorValue { float32: [0.0; 4] },
                })
        };
        let colors = [clear(t.position.view), clear(t.normal.view)];
        let depth = depth_clear_attachment(t.depth.view, false);
        let area = vk::Rect2D {
            offset: vk::Offset2D::default(),
            extent: t.extent,
        };
        let info = vk::RenderingInfo::default()
            .render_area(area)
            .layer_count(1)
            .color_attachments(&colors)
            .depth_attachment(&depth);
        Recorder::new(d, cmd).begin_rendering(&info);
        bind(
            d,
            self.layout,
            cmd,
            (vk::PipelineBindPoint::GRAPHICS, self.receiver),
            set,
        );
        set_viewport(ctx, cmd, t.extent);
        scene.bind_geometry(d, cmd);
        for &i in &f.receivers {
            let dr = &scene.draws[i];
            scene.bind_material(d, cmd, self.layout, 1, dr.material);
            // The ray offset's factors (`math::ray::ray_offset`), multiplied out.
            let mut extra = Mat4::ZERO;
            extra.x_axis = (dr.magnitudes * RAY_OFFSET_RELATIVE).extend(RAY_OFFSET_RELATIVE);
            let pc = ExactImmediates {
                world_from_model: dr.world_from_model,
                extra,
            };
            scene.record_draw(
                cmd,
                self.layout,
                dr,
                Some(f.eye),
                Viewpoint::Eye(f.eye.0),
                bytemuck::bytes_of(&pc),
            );
        }
        Recorder::new(d, cmd).end_rendering();
        // Inputs of the binning step.
        Uses::new()
            .reads(&mut t.position, Access::ComputeSampled)
            .reads(&mut t.normal, Access::ComputeSampled)
            .enter(d, cmd);
    }

    /// Step 2: each pixel's shadow ray binned into the grid of light views (`groups` of 8×8);
    /// with hybrid shadows, the tiles holding a traced sample marked, after the thin-caster mask.
    fn record_binning(
        &mut self,
        cmd: vk::CommandBuffer,
        set: vk::DescriptorSet,
        groups: (u32, u32),
        (t, hybrid): (&mut Targets, bool),
    ) {
        let d = &self.ctx.device;
        let uses = Uses::new()
            .writes_buffer(&mut t.heads, BufferAccess::ComputeWrite)
            .writes_buffer(&mut t.next, BufferAccess::ComputeWrite)
            .writes_buffer(&mut t.samples, BufferAccess::ComputeWrite)
            .writes_buffer(&mut t.rays, BufferAccess::ComputeWrite);
        match hybrid {
            true => uses
                .writes_buffer(&mut t.tiles, BufferAccess::ComputeWrite)
                .reads_buffer(&mut self.culling.thin, BufferAccess::ComputeRead),
            false => uses,
        }
        .enter(d, cmd);
        bind(
            d,
            self.layout,
            cmd,
            (vk::PipelineBindPoint::COMPUTE, self.build),
            set,
        );
        Recorder::new(d, cmd).dispatch(groups.0, groups.1, 1);
    }

    /// Step 3: the casters drawn into the grid (no attachments: the fragments only test and mark
    /// the rays they hit), then made visible to the camera pass's fragments. With `kept` (hybrid
    /// shadows: each draw's first kept triangle), only the triangles culling kept, indirectly.
    fn record_casters(
        &mut self,
        cmd: vk::CommandBuffer,
        set: vk::DescriptorSet,
        scene: &GpuScene,
        f: &ExactPlan,
        (kept, t): (Option<&[u32]>, &mut Targets),
    ) {
        let ctx = self.ctx.clone();
        let d = &ctx.device;
        let uses = Uses::new()
            .reads_buffer(&mut t.heads, BufferAccess::FragmentRead)
            .reads_buffer(&mut t.next, BufferAccess::FragmentRead)
            .reads_buffer(&mut t.rays, BufferAccess::FragmentRead)
            .writes_buffer(&mut t.samples, BufferAccess::FragmentWrite);
        match kept {
            Some(_) => self.culling.caster_inputs(uses),
            None => uses,
        }
        .enter(d, cmd);
        let side = grid_side(f.views.len());
        let grid = vk::Extent2D {
            width: side,
            height: side,
        };
        let info = vk::RenderingInfo::default()
            .render_area(vk::Rect2D {
                offset: vk::Offset2D::default(),
                extent: grid,
            })
            .layer_count(1);
        Recorder::new(d, cmd).begin_rendering(&info);
        bind(
            d,
            self.layout,
            cmd,
            (vk::PipelineBindPoint::GRAPHICS, self.caster),
            set,
        );
        set_viewport(&ctx, cmd, grid);
        Recorder::new(d, cmd).set_cull_mode(vk::CullModeFlags::NONE);
        Recorder::new(d, cmd).set_front_face(vk::FrontFace::COUNTER_CLOCKWISE);
        for (slot, &i) in f.casters.iter().enumerate() {
            let dr = &scene.draws[i].shadow_caster();
            scene.bind_material(d, cmd, self.layout, 1, dr.material);
            for view in 0..f.views.len() {
                let mut extra = Mat4::ZERO;
                extra.x_axis = caster_column(dr, view);
                if let Some(kept) = kept {
                    extra.y_axis = Vec4::new(f32::from_bits(kept[slot]), 0.0, 0.0, 0.0);
                }
                let pc = ExactImmediates {
                    world_from_model: dr.world_from_model,
                    extra,
                };
                Recorder::new(d, cmd).push_constants(
                    self.layout,
                    vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                    0,
                    bytemuck::bytes_of(&pc),
                );
                // Six vertices a triangle: the triangle grown (or its box's two halves).
                match kept {
                    Some(_) => Recorder::new(d, cmd).draw_indirect(
                        self.culling.args.raw(),
                        16 * slot as u64,
                        1,
                        16,
                    ),
                    None => Recorder::new(d, cmd).draw(2 * dr.index_count, 1, 0, 0),
                }
            }
        }
        Recorder::new(d, cmd).end_rendering();
    }
}

/// Binds `pipeline` at `point` with the frame's set `set` (set 0 of `layout`).
pub(super) fn bind(
    d: &ash::Device,
    layout: vk::PipelineLayout,
    cmd: vk::CommandBuffer,
    (point, pipeline): (vk::PipelineBindPoint, vk::Pipeline),
    set: vk::DescriptorSet,
) {
    Recorder::new(d, cmd).bind_pipeline(point, pipeline);
    Recorder::new(d, cmd).bind_descriptor_sets(point, layout, 0, &[set], &[]);
}
