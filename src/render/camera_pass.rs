//! The camera pass: Blinn-Phong, normal mapping, shadow-map reprojection (scene.wgsl).

use super::gpu_scene::{GpuScene, VertexAttributes};
use super::pipeline::{create_layout, create_pipeline, set_viewport, PipelineDesc};
use super::uniforms::{FrameUniform, SceneImmediates};
use crate::gpu::context::{Context, GpuError, VkCheck};
use crate::gpu::shaders::{create_module, scene as sh, set_layout, ReflectedBinding};
use crate::gpu::Buffer;
use ash::vk;
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

/// Depth format of the camera pass.
pub const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;

/// The camera pass for one colour format.
pub struct CameraPass {
    ctx: Arc<Context>,
    layout: vk::PipelineLayout,
    frame_layout: vk::DescriptorSetLayout,
    module: vk::ShaderModule,
    pipeline: vk::Pipeline,
    pool: vk::DescriptorPool,
    frame_set: vk::DescriptorSet,
    frame_buffer: Buffer,
    linear_sampler: vk::Sampler,
    nearest_sampler: vk::Sampler,
    bound_map: vk::ImageView,
}

impl CameraPass {
    /// Creates the pass for `color_format` with the scene's material set layout.
    pub fn new(
        ctx: &Arc<Context>,
        scene: &GpuScene,
        color_format: vk::Format,
    ) -> Result<Self, GpuError> {
        let frame_layout = set_layout(ctx, sh::BINDINGS, 0, "frame set layout")?;
        let layout = create_layout(
            ctx,
            &[frame_layout, scene.material_layout],
            sh::IMMEDIATE_SIZE,
            "camera pipeline layout",
        )?;
        let module = create_module(ctx, sh::SPIRV, "scene.wgsl")?;
        let bindings = [
            vk::VertexInputBindingDescription {
                binding: 0,
                stride: 12,
                input_rate: vk::VertexInputRate::VERTEX,
            },
            vk::VertexInputBindingDescription {
                binding: 1,
                stride: std::mem::size_of::<VertexAttributes>() as u32,
                input_rate: vk::VertexInputRate::VERTEX,
            },
        ];
        let attributes = [
            vk::VertexInputAttributeDescription {
                location: 0,
                binding: 0,
                format: vk::Format::R32G32B32_SFLOAT,
                offset: 0,
            },
            vk::VertexInputAttributeDescription {
                location: 1,
                binding: 1,
                format: vk::Format::R32G32B32_SFLOAT,
                offset: 0,
            },
            vk::VertexInputAttributeDescription {
                location: 2,
                binding: 1,
                format: vk::Format::R32G32_SFLOAT,
                offset: 12,
            },
            vk::VertexInputAttributeDescription {
                location: 3,
                binding: 1,
                format: vk::Format::R32G32B32A32_SFLOAT,
                offset: 20,
            },
        ];
        let pipeline = create_pipeline(
            ctx,
            &PipelineDesc {
                name: "camera pipeline",
                layout,
                vertex: (module, sh::ENTRY_VS_MAIN),
                fragment: Some((module, sh::ENTRY_FS_MAIN)),
                bindings: &bindings,
                attributes: &attributes,
                color_format: Some(color_format),
                depth_format: DEPTH_FORMAT,
                depth_clamp: false,
                depth_bias: false,
            },
        )?;
        let sizes = [
            vk::DescriptorPoolSize {
                ty: vk::DescriptorType::UNIFORM_BUFFER,
                descriptor_count: 1,
            },
            vk::DescriptorPoolSize {
                ty: vk::DescriptorType::SAMPLED_IMAGE,
                descriptor_count: 1,
            },
            vk::DescriptorPoolSize {
                ty: vk::DescriptorType::SAMPLER,
                descriptor_count: 1,
            },
        ];
        let pool = unsafe {
            ctx.device.create_descriptor_pool(
                &vk::DescriptorPoolCreateInfo::default()
                    .max_sets(1)
                    .pool_sizes(&sizes),
                None,
            )
        }
        .vk("vkCreateDescriptorPool")?;
        let layouts = [frame_layout];
        let frame_set = unsafe {
            ctx.device.allocate_descriptor_sets(
                &vk::DescriptorSetAllocateInfo::default()
                    .descriptor_pool(pool)
                    .set_layouts(&layouts),
            )
        }
        .vk("vkAllocateDescriptorSets")?[0];
        let frame_buffer = Buffer::new(
            ctx,
            "frame uniforms",
            std::mem::size_of::<FrameUniform>() as u64,
            vk::BufferUsageFlags::UNIFORM_BUFFER,
            MemoryLocation::CpuToGpu,
        )?;
        // Comparison samplers: reversed-z, so "lit" is reference >= stored.
        let mk = |filter| {
            let info = vk::SamplerCreateInfo::default()
                .mag_filter(filter)
                .min_filter(filter)
                .mipmap_mode(vk::SamplerMipmapMode::NEAREST)
                .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                .compare_enable(true)
                .compare_op(vk::CompareOp::GREATER_OR_EQUAL)
                .max_lod(0.0);
            unsafe { ctx.device.create_sampler(&info, None) }.vk("vkCreateSampler")
        };
        let linear_sampler = mk(vk::Filter::LINEAR)?;
        let nearest_sampler = mk(vk::Filter::NEAREST)?;
        ctx.set_name(linear_sampler, "shadow compare sampler (linear)");
        ctx.set_name(nearest_sampler, "shadow compare sampler (nearest)");
        Ok(Self {
            ctx: ctx.clone(),
            layout,
            frame_layout,
            module,
            pipeline,
            pool,
            frame_set,
            frame_buffer,
            linear_sampler,
            nearest_sampler,
            bound_map: vk::ImageView::null(),
        })
    }

    /// Points the frame set at the shadow map (call when the map is recreated). Every binding is
    /// written (lavapipe crashes on unwritten descriptors, used or not).
    pub fn bind_shadow_map(&mut self, view: vk::ImageView, hardware_filtering: bool) {
        if view == self.bound_map {
            return;
        }
        unsafe {
            let _ = self.ctx.device.device_wait_idle();
        }
        let buf = [vk::DescriptorBufferInfo {
            buffer: self.frame_buffer.raw,
            offset: 0,
            range: vk::WHOLE_SIZE,
        }];
        let img = [vk::DescriptorImageInfo {
            sampler: vk::Sampler::null(),
            image_view: view,
            image_layout: vk::ImageLayout::DEPTH_READ_ONLY_OPTIMAL,
        }];
        let sampler = if hardware_filtering {
            self.linear_sampler
        } else {
            self.nearest_sampler
        };
        let samp = [vk::DescriptorImageInfo {
            sampler,
            image_view: vk::ImageView::null(),
            image_layout: vk::ImageLayout::UNDEFINED,
        }];
        let set = self.frame_set;
        let w = |b: &ReflectedBinding| {
            vk::WriteDescriptorSet::default()
                .dst_set(set)
                .dst_binding(b.binding)
                .descriptor_type(b.descriptor_type())
        };
        let writes = [
            w(&sh::FRAME).buffer_info(&buf),
            w(&sh::SHADOW_MAP).image_info(&img),
            w(&sh::SHADOW_SAMPLER).image_info(&samp),
        ];
        unsafe { self.ctx.device.update_descriptor_sets(&writes, &[]) };
        self.bound_map = view;
    }

    /// Writes the frame uniforms (the previous frame using them must have completed).
    pub fn write_frame(&mut self, u: &FrameUniform) -> Result<(), GpuError> {
        self.frame_buffer.write(0, bytemuck::bytes_of(u))
    }

    /// Records the pass into colour and depth attachments already in attachment layouts.
    pub fn record(
        &self,
        cmd: vk::CommandBuffer,
        scene: &GpuScene,
        color: vk::ImageView,
        depth: vk::ImageView,
        extent: vk::Extent2D,
        clear: [f32; 4],
    ) {
        let d = &self.ctx.device;
        self.ctx.begin_label(cmd, "camera pass");
        let color_att = [vk::RenderingAttachmentInfo::default()
            .image_view(color)
            .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue {
                color: vk::ClearColorValue { float32: clear },
            })];
        let depth_att = vk::RenderingAttachmentInfo::default()
            .image_view(depth)
            .image_layout(vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue {
                depth_stencil: vk::ClearDepthStencilValue {
                    depth: 0.0,
                    stencil: 0,
                },
            });
        let rendering = vk::RenderingInfo::default()
            .render_area(vk::Rect2D {
                offset: vk::Offset2D::default(),
                extent,
            })
            .layer_count(1)
            .color_attachments(&color_att)
            .depth_attachment(&depth_att);
        unsafe {
            d.cmd_begin_rendering(cmd, &rendering);
            if !scene.draws.is_empty() {
                d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline);
                set_viewport(&self.ctx, cmd, extent);
                d.cmd_bind_vertex_buffers(
                    cmd,
                    0,
                    &[scene.positions.raw, scene.attributes.raw],
                    &[0, 0],
                );
                d.cmd_bind_index_buffer(cmd, scene.indices.raw, 0, vk::IndexType::UINT32);
                d.cmd_bind_descriptor_sets(
                    cmd,
                    vk::PipelineBindPoint::GRAPHICS,
                    self.layout,
                    0,
                    &[self.frame_set],
                    &[],
                );
                let mut bound_material = usize::MAX;
                for dr in &scene.draws {
                    if dr.material != bound_material {
                        d.cmd_bind_descriptor_sets(
                            cmd,
                            vk::PipelineBindPoint::GRAPHICS,
                            self.layout,
                            1,
                            &[scene.material_sets[dr.material]],
                            &[],
                        );
                        bound_material = dr.material;
                    }
                    d.cmd_set_cull_mode(
                        cmd,
                        if dr.double_sided {
                            vk::CullModeFlags::NONE
                        } else {
                            vk::CullModeFlags::BACK
                        },
                    );
                    let pc = SceneImmediates::new(dr.world_from_model);
                    d.cmd_push_constants(
                        cmd,
                        self.layout,
                        vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                        0,
                        bytemuck::bytes_of(&pc),
                    );
                    d.cmd_draw_indexed(cmd, dr.index_count, 1, dr.first_index, dr.vertex_offset, 0);
                }
            }
            d.cmd_end_rendering(cmd);
        }
        self.ctx.end_label(cmd);
    }
}

impl Drop for CameraPass {
    fn drop(&mut self) {
        unsafe {
            let d = &self.ctx.device;
            let _ = d.device_wait_idle();
            d.destroy_pipeline(self.pipeline, None);
            d.destroy_shader_module(self.module, None);
            d.destroy_pipeline_layout(self.layout, None);
            d.destroy_descriptor_pool(self.pool, None);
            d.destroy_descriptor_set_layout(self.frame_layout, None);
            d.destroy_sampler(self.linear_sampler, None);
            d.destroy_sampler(self.nearest_sampler, None);
        }
    }
}
