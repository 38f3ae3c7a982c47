//! Post-process anti-aliasing ([`crate::plan::PostAa`]): the camera pass draws (or resolves)
//! into a scratch image of the target's format, and two full-screen triangles run FXAA
//! (`shaders/post.wgsl`) from it into the target: one copies every pixel and marks edges in a
//! depth image, the other resamples the marked pixels only (llvmpipe's early depth test skips
//! the blocks without an edge: one pass that branched per pixel cost 47 ms a 1280×720 frame
//! there, as llvmpipe runs both sides of a branch). The scratch images are made on first use and
//! remade when the image size changes; they are shared by the frames in flight (each frame's
//! barriers order it after the previous frame's use).

use crate::gpu::barrier::Access;
use crate::gpu::context::{Context, GpuError, VkCheck};
use crate::gpu::shaders::{allocate_sets, create_module, post as sh, set_layout};
use crate::gpu::Image;
use crate::gpu::{Recorder, Uses};
use crate::render::pipeline::{
    create_layout, create_pipeline, depth_clear_attachment, set_viewport, ColorBlend, Depth,
    PipelineDesc, Stencil,
};
use crate::render::samplers;
use crate::render::targets::Attachment;
use crate::scene::{Filter, Sampler, Wrap};
use ash::vk;
use std::sync::Arc;

/// Format of the edge marks.
const MARK_FORMAT: vk::Format = vk::Format::D16_UNORM;

/// The scratch image, the edge marks and the scratch image's descriptor set.
struct Scratch {
    image: Image,
    attachment: Attachment,
    _marks: Image,
    marks: Attachment,
    pool: vk::DescriptorPool,
    set: vk::DescriptorSet,
}

/// The FXAA pass of one colour format.
pub struct PostAaPass {
    ctx: Arc<Context>,
    format: vk::Format,
    set_layout: vk::DescriptorSetLayout,
    layout: vk::PipelineLayout,
    module: vk::ShaderModule,
    sampler: vk::Sampler,
    /// The mark pass's and the edge pass's pipelines.
    pipelines: Option<[vk::Pipeline; 2]>,
    scratch: Option<Scratch>,
}

impl PostAaPass {
    /// The pass for targets of `format` (nothing is made until [`PostAaPass::ensure`]).
    pub fn new(ctx: &Arc<Context>, format: vk::Format) -> Result<Self, GpuError> {
        let set_layout = set_layout(ctx, sh::BINDINGS, 0, "post AA set layout")?;
        let layout = create_layout(ctx, &[set_layout], sh::IMMEDIATE_SIZE, "post AA layout")?;
        let module = create_module(ctx, &sh::spirv()?, "post.wgsl")?;
        // Bilinear, clamped to the edge, base level only: the glTF sampler of that meaning.
        let filter = Sampler {
            mag: Filter::Linear,
            min: Filter::Linear,
            mipmap: None,
            wrap_u: Wrap::ClampToEdge,
            wrap_v: Wrap::ClampToEdge,
        };
        let sampler = unsafe {
            ctx.device
                .create_sampler(&samplers::create_info(&filter, 1.0), None)
        }
        .vk("vkCreateSampler")?;
        Ok(Self {
            ctx: ctx.clone(),
            format,
            set_layout,
            layout,
            module,
            sampler,
            pipelines: None,
            scratch: None,
        })
    }

    /// Makes the pipeline and a scratch image of `extent` (every binding of its set written).
    pub fn ensure(&mut self, extent: vk::Extent2D) -> Result<(), GpuError> {
        if self.pipelines.is_none() {
            self.pipelines = Some(self.make_pipelines()?);
        }
        if self
            .scratch
            .as_ref()
            .is_some_and(|s| s.image.extent == extent)
        {
            return Ok(());
        }
        self.drop_scratch();
        let image = Image::new(
            &self.ctx,
            "post AA source",
            self.format,
            extent,
            1,
            vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
        )?;
        let marks = Image::new(
            &self.ctx,
            "FXAA edge marks",
            MARK_FORMAT,
            extent,
            1,
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
        )?;
        let (pool, sets) = allocate_sets(&self.ctx, sh::BINDINGS, 0, self.set_layout, 1)?;
        let set = sets[0];
        let image_info = [vk::DescriptorImageInfo {
            sampler: vk::Sampler::null(),
            image_view: image.view,
            image_layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
        }];
        let sampler_info = [vk::DescriptorImageInfo {
            sampler: self.sampler,
            image_view: vk::ImageView::null(),
            image_layout: vk::ImageLayout::UNDEFINED,
        }];
        let writes = [
            sh::SOURCE.write(set).image_info(&image_info),
            sh::SOURCE_SAMPLER.write(set).image_info(&sampler_info),
        ];
        unsafe { self.ctx.device.update_descriptor_sets(&writes, &[]) };
        self.scratch = Some(Scratch {
            attachment: Attachment::of(&image),
            image,
            marks: Attachment::of(&marks),
            _marks: marks,
            pool,
            set,
        });
        Ok(())
    }

    /// The two FXAA pipelines: the edge marks, then the filter on the marked pixels.
    fn make_pipelines(&self) -> Result<[vk::Pipeline; 2], GpuError> {
        let pipeline = |name, vertex, fragment| {
            create_pipeline(
                &self.ctx,
                &PipelineDesc {
                    name,
                    layout: self.layout,
                    vertex: (self.module, vertex),
                    fragment: Some((self.module, fragment)),
                    bindings: &[],
                    attributes: &[],
                    color_formats: &[self.format],
                    masked_targets: 0,
                    depth_format: MARK_FORMAT,
                    stencil: Stencil::Off,
                    depth_clamp: false,
                    depth_bias: false,
                    depth: Depth::Test,
                    blend: ColorBlend::Off,
                    samples: 1,
                },
            )
        };
        let mark = pipeline("FXAA marks", sh::ENTRY_VS_MARK, sh::ENTRY_FS_MARK)?;
        let edges = pipeline("FXAA edges", sh::ENTRY_VS_EDGES, sh::ENTRY_FS_FXAA)?;
        Ok([mark, edges])
    }

    /// The scratch image the camera pass draws into ([`PostAaPass::ensure`] first).
    pub fn source(&mut self) -> Option<&mut Attachment> {
        self.scratch.as_mut().map(|s| &mut s.attachment)
    }

    /// Records FXAA from the scratch image into `target` (a colour attachment of the pass's
    /// format and the scratch image's size), which it overwrites whole.
    pub fn record(&mut self, cmd: vk::CommandBuffer, target: &mut Attachment) {
        let (Some([mark, edges]), Some(scratch)) = (self.pipelines, self.scratch.as_mut()) else {
            return;
        };
        let ctx = self.ctx.clone();
        let d = &ctx.device;
        let extent = scratch.image.extent;
        ctx.begin_label(cmd, "FXAA");
        let rcp = [1.0 / extent.width as f32, 1.0 / extent.height as f32];
        let bytes: &[u8] = bytemuck::cast_slice(&rcp);
        // Pass 1 copies and marks (marks cleared to 0, so every pixel passes); pass 2 loads both.
        for (pipeline, first) in [(mark, true), (edges, false)] {
            // The scene's colour is the input; the target and the marks the outputs.
            Uses::new()
                .reads(&mut scratch.attachment, Access::FragmentSampled)
                .writes(target, Access::ColorAttachment)
                .writes(&mut scratch.marks, Access::DepthAttachment)
                .enter(d, cmd);
            let color = [vk::RenderingAttachmentInfo::default()
                .image_view(target.view)
                .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                .load_op(if first {
                    vk::AttachmentLoadOp::DONT_CARE
                } else {
                    vk::AttachmentLoadOp::LOAD
                })
                .store_op(vk::AttachmentStoreOp::STORE)];
            let mut depth = depth_clear_attachment(scratch.marks.view, false);
            if !first {
                depth = depth
                    .load_op(vk::AttachmentLoadOp::LOAD)
                    .store_op(vk::AttachmentStoreOp::DONT_CARE);
            }
            let rendering = vk::RenderingInfo::default()
                .render_area(vk::Rect2D {
                    offset: vk::Offset2D::default(),
                    extent,
                })
                .layer_count(1)
                .color_attachments(&color)
                .depth_attachment(&depth);
            Recorder::new(d, cmd).begin_rendering(&rendering);
            set_viewport(&ctx, cmd, extent);
            Recorder::new(d, cmd).set_cull_mode(vk::CullModeFlags::NONE);
            Recorder::new(d, cmd).set_front_face(vk::FrontFace::COUNTER_CLOCKWISE);
            Recorder::new(d, cmd).bind_pipeline(vk::PipelineBindPoint::GRAPHICS, pipeline);
            Recorder::new(d, cmd).bind_descriptor_sets(
                vk::PipelineBindPoint::GRAPHICS,
                self.layout,
                0,
                &[scratch.set],
                &[],
            );
            Recorder::new(d, cmd).push_constants(
                self.layout,
                vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                0,
                bytes,
            );
            Recorder::new(d, cmd).draw(3, 1, 0, 0);
            Recorder::new(d, cmd).end_rendering();
        }
        ctx.end_label(cmd);
    }

    fn drop_scratch(&mut self) {
        if let Some(s) = self.scratch.take() {
            unsafe {
                let _ = self.ctx.device.device_wait_idle();
                self.ctx.device.destroy_descriptor_pool(s.pool, None);
            }
        }
    }
}

impl Drop for PostAaPass {
    fn drop(&mut self) {
        self.drop_scratch();
        unsafe {
            let d = &self.ctx.device;
            let _ = d.device_wait_idle();
            d.destroy_sampler(self.sampler, None);
            d.destroy_shader_module(self.module, None);
            d.destroy_pipeline_layout(self.layout, None);
            d.destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}
