//! The light-space depth pass: position-only stream, depth clamp on, reversed-z (clear 0, GREATER),
//! depth bias pushing casters away from the light (negative factors under reversed-z).

use super::core::Attachment;
use super::gpu_scene::GpuScene;
use super::pipeline::{
    create_layout, create_pipeline, depth_clear_attachment, set_viewport, PipelineDesc,
};
use super::settings::{ShadowFormat, ShadowSettings};
use super::uniforms::ShadowImmediates;
use crate::gpu::barrier::Access;
use crate::gpu::context::{Context, GpuError};
use crate::gpu::shaders::{create_module, shadow as sh};
use crate::gpu::Image;
use crate::math::Aabb;
use ash::vk;
use glam::{Mat4, Vec4};
use std::sync::Arc;

/// Vulkan format of a shadow format.
pub fn vk_format(f: ShadowFormat) -> vk::Format {
    match f {
        ShadowFormat::D32 => vk::Format::D32_SFLOAT,
        ShadowFormat::D16 => vk::Format::D16_UNORM,
    }
}

/// True when a caster with world bounds `b` may land inside the light's view (x, y in [−1, 1],
/// not entirely beyond the far plane). Near-plane overshoot is kept: depth clamp pancakes it.
pub fn caster_visible(light_clip_from_world: &Mat4, b: &Aabb) -> bool {
    let mut lo = glam::Vec3::splat(f32::INFINITY);
    let mut hi = glam::Vec3::splat(f32::NEG_INFINITY);
    for c in b.corners() {
        let p = *light_clip_from_world * Vec4::new(c.x, c.y, c.z, 1.0);
        if p.w <= 1e-12 {
            return true; // behind a perspective light's eye: be conservative.
        }
        let q = p.truncate() / p.w;
        lo = lo.min(q);
        hi = hi.max(q);
    }
    hi.x >= -1.0 && lo.x <= 1.0 && hi.y >= -1.0 && lo.y <= 1.0 && hi.z >= 0.0
}

/// The shadow depth pass and its map.
pub struct ShadowPass {
    ctx: Arc<Context>,
    layout: vk::PipelineLayout,
    module: vk::ShaderModule,
    pipeline: vk::Pipeline,
    pipeline_format: vk::Format,
    hardware_filtering: bool,
    /// The shadow map (None before the first `ensure_map`).
    pub map: Option<Image>,
    /// The map's attachment state (set with the map).
    map_at: Option<Attachment>,
}

impl ShadowPass {
    /// Creates the pass (the map is created by `ensure_map`).
    pub fn new(ctx: &Arc<Context>) -> Result<Self, GpuError> {
        let layout = create_layout(ctx, &[], sh::IMMEDIATE_SIZE, "shadow pipeline layout")?;
        let module = create_module(ctx, sh::SPIRV, "shadow.wgsl")?;
        Ok(Self {
            ctx: ctx.clone(),
            layout,
            module,
            pipeline: vk::Pipeline::null(),
            pipeline_format: vk::Format::UNDEFINED,
            hardware_filtering: false,
            map: None,
            map_at: None,
        })
    }

    /// Makes sure the map has this size and format; returns true if it was (re)created.
    pub fn ensure_map(&mut self, size: u32, format: ShadowFormat) -> Result<bool, GpuError> {
        let fmt = vk_format(format);
        if self.pipeline_format != fmt {
            unsafe { self.ctx.device.destroy_pipeline(self.pipeline, None) };
            self.pipeline = vk::Pipeline::null();
            let bindings = [vk::VertexInputBindingDescription {
                binding: 0,
                stride: 12,
                input_rate: vk::VertexInputRate::VERTEX,
            }];
            let attributes = [vk::VertexInputAttributeDescription {
                location: 0,
                binding: 0,
                format: vk::Format::R32G32B32_SFLOAT,
                offset: 0,
            }];
            self.pipeline = create_pipeline(
                &self.ctx,
                &PipelineDesc {
                    name: "shadow depth pipeline",
                    layout: self.layout,
                    vertex: (self.module, sh::ENTRY_VS_MAIN),
                    fragment: None,
                    bindings: &bindings,
                    attributes: &attributes,
                    color_format: None,
                    depth_format: fmt,
                    depth_clamp: true,
                    depth_bias: true,
                    depth_test: true,
                },
            )?;
            self.pipeline_format = fmt;
            self.hardware_filtering = self
                .ctx
                .format_features(fmt)
                .contains(vk::FormatFeatureFlags::SAMPLED_IMAGE_FILTER_LINEAR);
        }
        let size = size.clamp(1, 16384);
        if self
            .map
            .as_ref()
            .is_some_and(|m| m.extent.width == size && m.format == fmt)
        {
            return Ok(false);
        }
        if self.map.is_some() {
            unsafe {
                let _ = self.ctx.device.device_wait_idle();
            }
        }
        self.map = Some(Image::new(
            &self.ctx,
            "shadow map",
            fmt,
            vk::Extent2D {
                width: size,
                height: size,
            },
            1,
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
        )?);
        self.map_at = self.map.as_ref().map(Attachment::of);
        Ok(true)
    }

    /// Whether the map's format supports hardware linear filtering of comparisons.
    pub fn hardware_filtering(&self) -> bool {
        self.hardware_filtering
    }

    /// Records the pass; leaves the map ready for fragment-shader sampling. Returns casters drawn.
    pub fn record(
        &mut self,
        cmd: vk::CommandBuffer,
        scene: &GpuScene,
        light_clip_from_world: &Mat4,
        s: &ShadowSettings,
        draw: bool,
        eye: Option<(glam::Vec3, f32)>,
    ) -> usize {
        let (Some(map), Some(at)) = (&self.map, self.map_at.as_mut()) else {
            return 0;
        };
        let d = &self.ctx.device;
        self.ctx.begin_label(cmd, "shadow depth pass");
        at.transition(d, cmd, Access::DepthAttachment);
        let depth_attachment = depth_clear_attachment(map.view);
        let rendering = vk::RenderingInfo::default()
            .render_area(vk::Rect2D {
                offset: vk::Offset2D::default(),
                extent: map.extent,
            })
            .layer_count(1)
            .depth_attachment(&depth_attachment);
        let mut drawn = 0;
        unsafe {
            d.cmd_begin_rendering(cmd, &rendering);
            if draw && !scene.draws.is_empty() {
                d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline);
                set_viewport(&self.ctx, cmd, map.extent);
                // Reversed-z: "away from the light" is towards smaller depth, so the factor is negated.
                // The constant bias is applied on the receiver side, in texels (camera pass).
                d.cmd_set_depth_bias(cmd, 0.0, 0.0, -s.slope_bias);
                d.cmd_bind_vertex_buffers(cmd, 0, &[scene.positions.raw], &[0]);
                d.cmd_bind_index_buffer(cmd, scene.indices.raw, 0, vk::IndexType::UINT32);
                for dr in &scene.draws {
                    if !caster_visible(light_clip_from_world, &dr.world_bounds) {
                        continue;
                    }
                    let pc = ShadowImmediates {
                        light_clip_from_world: *light_clip_from_world,
                        world_from_model: dr.world_from_model,
                    };
                    d.cmd_set_cull_mode(cmd, dr.cull_mode(eye));
                    d.cmd_set_front_face(cmd, dr.front_face());
                    d.cmd_push_constants(
                        cmd,
                        self.layout,
                        vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                        0,
                        bytemuck::bytes_of(&pc),
                    );
                    d.cmd_draw_indexed(cmd, dr.index_count, 1, dr.first_index, dr.vertex_offset, 0);
                    drawn += 1;
                }
            }
            d.cmd_end_rendering(cmd);
        }
        at.transition(d, cmd, Access::DepthFragmentSampled);
        self.ctx.end_label(cmd);
        drawn
    }
}

impl Drop for ShadowPass {
    fn drop(&mut self) {
        unsafe {
            let d = &self.ctx.device;
            let _ = d.device_wait_idle();
            d.destroy_pipeline(self.pipeline, None);
            d.destroy_shader_module(self.module, None);
            d.destroy_pipeline_layout(self.layout, None);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn caster_culling() {
        let m = crate::math::projection::orthographic_reversed(-1.0, 1.0, -1.0, 1.0, 0.0, 10.0);
        assert!(caster_visible(
            &m,
            &Aabb::new(Vec3::new(-0.5, -0.5, -5.0), Vec3::new(0.5, 0.5, -4.0))
        ));
        // Outside in x.
        assert!(!caster_visible(
            &m,
            &Aabb::new(Vec3::new(2.0, -0.5, -5.0), Vec3::new(3.0, 0.5, -4.0))
        ));
        // Nearer than the near plane (depth > 1): kept, depth clamp flattens it.
        assert!(caster_visible(
            &m,
            &Aabb::new(Vec3::new(-0.5, -0.5, 1.0), Vec3::new(0.5, 0.5, 2.0))
        ));
        // Beyond the far plane: culled.
        assert!(!caster_visible(
            &m,
            &Aabb::new(Vec3::new(-0.5, -0.5, -20.0), Vec3::new(0.5, 0.5, -15.0))
        ));
    }
}
