//! Recording the exact pass: the receivers' positions and normals, each pixel's ray binned into
//! the grid of light views, the casters drawn into the grid.

use super::*;
use crate::gpu::barrier::{memory_barrier, Access};
use crate::gpu::Recorder;
use crate::math::ray::RAY_OFFSET_RELATIVE;
use crate::plan::Viewpoint;
use crate::plan::{ExactMode, ExactPlan};
use crate::render::gpu_scene::GpuScene;
use crate::render::pipeline::{depth_clear_attachment, set_viewport};
use ash::vk;
use glam::{Mat4, Vec4};

impl ExactPass {
    /// Records the three steps for slot `slot` (after [`ExactPass::ensure`] and
    /// [`ExactPass::write_frame`]); the samples are then ready for the camera pass's fragment
    /// shaders.
    pub fn record(&mut self, cmd: vk::CommandBuffer, slot: usize, scene: &GpuScene, f: &ExactPlan) {
        let ctx = self.ctx.clone();
        let d = &ctx.device;
        let set = self.sets[slot];
        let mut t = self.targets.take().expect("exact targets made by ensure");
        use vk::AccessFlags2 as A;
        use vk::PipelineStageFlags2 as S;
        // The previous frame's reads and writes of the lists and samples come first.
        memory_barrier(
            d,
            cmd,
            (
                S::DRAW_INDIRECT | S::VERTEX_SHADER | S::FRAGMENT_SHADER | S::COMPUTE_SHADER,
                A::INDIRECT_COMMAND_READ | A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE,
            ),
            (
                S::ALL_TRANSFER | S::COMPUTE_SHADER,
                A::TRANSFER_WRITE | A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE,
            ),
        );
        Recorder::new(d, cmd).fill_buffer(t.heads.raw, 0, vk::WHOLE_SIZE, 0);
        if f.hybrid.is_some() {
            Recorder::new(d, cmd).fill_buffer(t.tiles.raw, 0, vk::WHOLE_SIZE, 0);
            self.culling.clear(cmd);
        }
        self.record_receivers(cmd, set, scene, f, &mut t);
        let groups = (t.extent.width.div_ceil(8), t.extent.height.div_ceil(8));
        if let ExactMode::Contact { .. } = f.mode {
            bind(
                d,
                self.layout,
                cmd,
                (vk::PipelineBindPoint::COMPUTE, self.contact),
                set,
            );
            Recorder::new(d, cmd).dispatch(groups.0, groups.1, 1);
            memory_barrier(
                d,
                cmd,
                (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE),
                (S::FRAGMENT_SHADER, A::SHADER_STORAGE_READ),
            );
            self.targets = Some(t);
            return;
        }
        if f.hybrid.is_some() {
            // After the fills (the binning barrier's first half orders them first).
            memory_barrier(
                d,
                cmd,
                (S::ALL_TRANSFER, A::TRANSFER_WRITE),
                (
                    S::COMPUTE_SHADER,
                    A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE,
                ),
            );
            self.culling.record_thin(cmd, set, scene, f);
        }
        self.record_binning(cmd, set, groups);
        let kept = f
            .hybrid
            .is_some()
            .then(|| self.culling.record(cmd, set, scene, f, slot));
        self.record_casters(cmd, set, scene, f, kept.as_deref());
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
        t.position.transition(d, cmd, Access::ColorAttachment);
        t.normal.transition(d, cmd, Access::ColorAttachment);
        t.depth.transition(d, cmd, Access::DepthAttachment);
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
        t.position.transition(d, cmd, Access::ComputeSampled);
        t.normal.transition(d, cmd, Access::ComputeSampled);
    }

    /// Step 2: each pixel's shadow ray binned into the grid of light views (`groups` of 8×8).
    fn record_binning(&self, cmd: vk::CommandBuffer, set: vk::DescriptorSet, groups: (u32, u32)) {
        let d = &self.ctx.device;
        use vk::AccessFlags2 as A;
        use vk::PipelineStageFlags2 as S;
        memory_barrier(
            d,
            cmd,
            (S::ALL_TRANSFER, A::TRANSFER_WRITE),
            (
                S::COMPUTE_SHADER,
                A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE,
            ),
        );
        bind(
            d,
            self.layout,
            cmd,
            (vk::PipelineBindPoint::COMPUTE, self.build),
            set,
        );
        Recorder::new(d, cmd).dispatch(groups.0, groups.1, 1);
        memory_barrier(
            d,
            cmd,
            (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE),
            (
                S::VERTEX_SHADER | S::FRAGMENT_SHADER,
                A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE,
            ),
        );
    }

    /// Step 3: the casters drawn into the grid (no attachments: the fragments only test and mark
    /// the rays they hit), then made visible to the camera pass's fragments. With `kept` (hybrid
    /// shadows: each draw's first kept triangle), only the triangles culling kept, indirectly.
    fn record_casters(
        &self,
        cmd: vk::CommandBuffer,
        set: vk::DescriptorSet,
        scene: &GpuScene,
        f: &ExactPlan,
        kept: Option<&[u32]>,
    ) {
        let ctx = &self.ctx;
        let d = &ctx.device;
        use vk::AccessFlags2 as A;
        use vk::PipelineStageFlags2 as S;
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
        set_viewport(ctx, cmd, grid);
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
                        self.culling.args.raw,
                        16 * slot as u64,
                        1,
                        16,
                    ),
                    None => Recorder::new(d, cmd).draw(2 * dr.index_count, 1, 0, 0),
                }
            }
        }
        Recorder::new(d, cmd).end_rendering();
        // The verdicts, for the camera pass's fragments.
        memory_barrier(
            d,
            cmd,
            (S::FRAGMENT_SHADER, A::SHADER_STORAGE_WRITE),
            (S::FRAGMENT_SHADER, A::SHADER_STORAGE_READ),
        );
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
