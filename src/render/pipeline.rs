//! Graphics pipeline creation shared by the passes (dynamic rendering, no render pass objects).

use crate::gpu::context::{Context, GpuError};
use crate::gpu::pipeline_store::PipelineStore;
use crate::gpu::resources::has_stencil;
use crate::gpu::Recorder;
use ash::vk;
use std::ffi::CStr;
use std::hash::{Hash, Hasher};

/// What differs between the passes' pipelines.
#[derive(Clone, Copy)]
pub struct PipelineDesc<'a> {
    /// Debug name.
    pub name: &'a str,
    /// Pipeline layout.
    pub layout: vk::PipelineLayout,
    /// Vertex module and entry.
    pub vertex: (vk::ShaderModule, &'a CStr),
    /// Fragment module and entry, if any.
    pub fragment: Option<(vk::ShaderModule, &'a CStr)>,
    /// Vertex buffer bindings.
    pub bindings: &'a [vk::VertexInputBindingDescription],
    /// Vertex attributes.
    pub attributes: &'a [vk::VertexInputAttributeDescription],
    /// Colour attachment formats (none for depth-only passes).
    pub color_formats: &'a [vk::Format],
    /// How many of them, from the last, the fragment shader leaves alone: masked (their contents
    /// kept, and no bytes spent writing them) where the device has independent blend, written
    /// with whatever the shader leaves in them elsewhere.
    pub masked_targets: usize,
    /// Depth attachment format; a format with stencil is also the stencil attachment's.
    pub depth_format: vk::Format,
    /// Stencil test and write.
    pub stencil: Stencil,
    /// Clamp depth instead of clipping at near/far.
    pub depth_clamp: bool,
    /// Enable (dynamic) depth bias.
    pub depth_bias: bool,
    /// Depth test and write.
    pub depth: Depth,
    /// Colour blending.
    pub blend: ColorBlend,
    /// Samples per pixel of the attachments (1, or the MSAA count).
    pub samples: u32,
}

/// What a pipeline does with the stencil aspect (reference value: dynamic state).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Stencil {
    /// No stencil test or write.
    Off,
    /// Writes the reference wherever the depth test passes (the deferred draws' material mark).
    Mark,
    /// Passes only where the stored value equals the reference; writes nothing.
    Equal,
}

/// What a pipeline does with the depth aspect (reversed-z: larger is nearer, cleared to 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Depth {
    /// No test, no write (full-screen passes, the overdraw view).
    Off,
    /// GREATER, writing (no writes with [`ColorBlend::Over`]).
    Test,
    /// Passes only where the depth is still the clear value 0 (a full-screen triangle at depth
    /// 0 with GREATER_OR_EQUAL): the background where no surface was drawn; writes nothing.
    Empty,
}

/// How a pipeline's colour output combines with the attachment.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ColorBlend {
    /// Replace.
    Off,
    /// ONE + ONE (the overdraw view).
    Additive,
    /// Over: SRC_ALPHA, ONE_MINUS_SRC_ALPHA (blended materials); the pipeline tests depth but
    /// does not write it.
    Over,
}

/// The graphics pipeline of `d`: triangle lists, reversed-z depth test (GREATER, writes on),
/// counter-clockwise front faces, dynamic viewport, scissor and cull mode (and depth bias).
/// Made once per context and kept by it (`gpu::pipeline_store`): the caller never destroys it.
pub fn create_pipeline(ctx: &Context, d: &PipelineDesc) -> Result<vk::Pipeline, GpuError> {
    ctx.pipelines
        .get_or_create(definition(&ctx.pipelines, d), || make_pipeline(ctx, d))
}

/// The compute pipeline of `module`'s entry point `entry`, named `name`: made once per context and
/// kept by it (`gpu::pipeline_store`), known by its layout's and module's definitions and the
/// entry point, like [`create_pipeline`]'s. The caller never destroys it.
pub fn create_compute_pipeline(
    ctx: &Context,
    layout: vk::PipelineLayout,
    module: vk::ShaderModule,
    entry: &CStr,
    name: &str,
) -> Result<vk::Pipeline, GpuError> {
    let mut h = crate::gpu::pipeline_store::hasher();
    "compute".hash(&mut h);
    ctx.pipelines.hash_made_of(layout, &mut h);
    ctx.pipelines.hash_made_of(module, &mut h);
    entry.hash(&mut h);
    ctx.pipelines.get_or_create(h.finish(), || {
        make_compute(ctx, layout, (module, entry), name)
    })
}

/// Creates [`create_compute_pipeline`]'s pipeline the first time.
fn make_compute(
    ctx: &Context,
    layout: vk::PipelineLayout,
    (module, entry): (vk::ShaderModule, &CStr),
    name: &str,
) -> Result<vk::Pipeline, GpuError> {
    let stage = vk::PipelineShaderStageCreateInfo::default()
        .stage(vk::ShaderStageFlags::COMPUTE)
        .module(module)
        .name(entry);
    let info = vk::ComputePipelineCreateInfo::default()
        .stage(stage)
        .layout(layout);
    let made = unsafe {
        ctx.device
            .create_compute_pipelines(ctx.pipeline_cache, &[info], None)
    };
    named_one(ctx, made, "vkCreateComputePipelines", name)
}

/// The one pipeline a `vkCreate*Pipelines` call `call` made, named `name`, or its error.
fn named_one(
    ctx: &Context,
    made: Result<Vec<vk::Pipeline>, (Vec<vk::Pipeline>, vk::Result)>,
    call: &'static str,
    name: &str,
) -> Result<vk::Pipeline, GpuError> {
    let p = made.map_err(|(_, result)| GpuError::Vk { call, result })?[0];
    ctx.set_name(p, name);
    Ok(p)
}

/// What `d` makes, hashed: everything but its name, its modules and layout by what they are
/// made of.
fn definition(store: &PipelineStore, d: &PipelineDesc) -> u64 {
    let mut h = crate::gpu::pipeline_store::hasher();
    "graphics".hash(&mut h);
    let counts = (d.bindings.len(), d.attributes.len(), d.color_formats.len());
    (counts, d.fragment.is_some()).hash(&mut h);
    store.hash_made_of(d.layout, &mut h);
    for (module, entry) in std::iter::once(d.vertex).chain(d.fragment) {
        store.hash_made_of(module, &mut h);
        entry.hash(&mut h);
    }
    for b in d.bindings {
        (b.binding, b.stride, b.input_rate.as_raw()).hash(&mut h);
    }
    for a in d.attributes {
        (a.location, a.binding, a.format.as_raw(), a.offset).hash(&mut h);
    }
    for f in d.color_formats {
        f.as_raw().hash(&mut h);
    }
    (
        d.masked_targets,
        d.depth_format.as_raw(),
        d.depth_clamp,
        d.depth_bias,
    )
        .hash(&mut h);
    (d.stencil, d.depth, d.blend, d.samples).hash(&mut h);
    h.finish()
}

/// Creates the pipeline of `d` ([`create_pipeline`]'s first time).
fn make_pipeline(ctx: &Context, d: &PipelineDesc) -> Result<vk::Pipeline, GpuError> {
    let mut stages = vec![vk::PipelineShaderStageCreateInfo::default()
        .stage(vk::ShaderStageFlags::VERTEX)
        .module(d.vertex.0)
        .name(d.vertex.1)];
    if let Some((m, e)) = d.fragment {
        stages.push(
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::FRAGMENT)
                .module(m)
                .name(e),
        );
    }
    let vertex_input = vk::PipelineVertexInputStateCreateInfo::default()
        .vertex_binding_descriptions(d.bindings)
        .vertex_attribute_descriptions(d.attributes);
    let input_assembly = vk::PipelineInputAssemblyStateCreateInfo::default()
        .topology(vk::PrimitiveTopology::TRIANGLE_LIST);
    let viewport = vk::PipelineViewportStateCreateInfo::default()
        .viewport_count(1)
        .scissor_count(1);
    let raster = vk::PipelineRasterizationStateCreateInfo::default()
        .depth_clamp_enable(d.depth_clamp)
        .polygon_mode(vk::PolygonMode::FILL)
        .cull_mode(vk::CullModeFlags::BACK)
        .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
        .depth_bias_enable(d.depth_bias)
        .line_width(1.0);
    let multisample = vk::PipelineMultisampleStateCreateInfo::default()
        .rasterization_samples(vk::SampleCountFlags::from_raw(d.samples.max(1)));
    let depth = depth_stencil_state(d);
    let blend_attachments = blend_attachments(ctx, d);
    let blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend_attachments);
    let dyn_states = dynamic_states(d);
    let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dyn_states);
    let mut rendering = vk::PipelineRenderingCreateInfo::default()
        .color_attachment_formats(d.color_formats)
        .depth_attachment_format(d.depth_format);
    if has_stencil(d.depth_format) {
        rendering = rendering.stencil_attachment_format(d.depth_format);
    }
    let info = vk::GraphicsPipelineCreateInfo::default()
        .stages(&stages)
        .vertex_input_state(&vertex_input)
        .input_assembly_state(&input_assembly)
        .viewport_state(&viewport)
        .rasterization_state(&raster)
        .multisample_state(&multisample)
        .depth_stencil_state(&depth)
        .color_blend_state(&blend)
        .dynamic_state(&dynamic)
        .layout(d.layout)
        .push_next(&mut rendering);
    let made = unsafe {
        ctx.device
            .create_graphics_pipelines(ctx.pipeline_cache, &[info], None)
    };
    named_one(ctx, made, "vkCreateGraphicsPipelines", d.name)
}

/// One blend state per colour target; with independent blending, the last `d.masked_targets`
/// written to by nothing.
fn blend_attachments(
    ctx: &Context,
    d: &PipelineDesc,
) -> Vec<vk::PipelineColorBlendAttachmentState> {
    let blend_attachment = blend_attachment_state(d);
    let mut blend_attachments = vec![blend_attachment; d.color_formats.len()];
    if ctx.independent_blend {
        for masked in blend_attachments.iter_mut().rev().take(d.masked_targets) {
            masked.color_write_mask = vk::ColorComponentFlags::empty();
            // Nothing to blend (and integer targets cannot blend).
            masked.blend_enable = vk::FALSE;
        }
    }
    blend_attachments
}

/// The dynamic states: viewport, scissor, cull mode and front face; depth bias and stencil
/// reference where `d` uses them.
fn dynamic_states(d: &PipelineDesc) -> Vec<vk::DynamicState> {
    let mut dyn_states = vec![
        vk::DynamicState::VIEWPORT,
        vk::DynamicState::SCISSOR,
        vk::DynamicState::CULL_MODE,
        vk::DynamicState::FRONT_FACE,
    ];
    if d.depth_bias {
        dyn_states.push(vk::DynamicState::DEPTH_BIAS);
    }
    if d.stencil != Stencil::Off {
        dyn_states.push(vk::DynamicState::STENCIL_REFERENCE);
    }
    dyn_states
}

/// Reversed-z depth (`d.depth`; no writes from blended draws) and the stencil test of
/// `d.stencil`.
fn depth_stencil_state(d: &PipelineDesc) -> vk::PipelineDepthStencilStateCreateInfo<'static> {
    let (test, write, op) = match d.depth {
        Depth::Off => (false, false, vk::CompareOp::ALWAYS),
        Depth::Test => (true, d.blend != ColorBlend::Over, vk::CompareOp::GREATER),
        Depth::Empty => (true, false, vk::CompareOp::GREATER_OR_EQUAL),
    };
    let mut depth = vk::PipelineDepthStencilStateCreateInfo::default()
        .depth_test_enable(test)
        .depth_write_enable(write)
        .depth_compare_op(op);
    let stencil_op = |compare, pass, write_mask| vk::StencilOpState {
        fail_op: vk::StencilOp::KEEP,
        pass_op: pass,
        depth_fail_op: vk::StencilOp::KEEP,
        compare_op: compare,
        compare_mask: 0xff,
        write_mask,
        reference: 0,
    };
    let stencil = match d.stencil {
        Stencil::Off => None,
        Stencil::Mark => Some(stencil_op(
            vk::CompareOp::ALWAYS,
            vk::StencilOp::REPLACE,
            0xff,
        )),
        Stencil::Equal => Some(stencil_op(vk::CompareOp::EQUAL, vk::StencilOp::KEEP, 0)),
    };
    if let Some(op) = stencil {
        depth = depth.stencil_test_enable(true).front(op).back(op);
    }
    depth
}

/// The colour blend of `d.blend`: off, additive, or over (source alpha), the target's alpha kept.
fn blend_attachment_state(d: &PipelineDesc) -> vk::PipelineColorBlendAttachmentState {
    let mut blend_attachment = vk::PipelineColorBlendAttachmentState::default()
        .color_write_mask(vk::ColorComponentFlags::RGBA);
    let factors = match d.blend {
        ColorBlend::Off => None,
        ColorBlend::Additive => Some((vk::BlendFactor::ONE, vk::BlendFactor::ONE)),
        ColorBlend::Over => Some((
            vk::BlendFactor::SRC_ALPHA,
            vk::BlendFactor::ONE_MINUS_SRC_ALPHA,
        )),
    };
    if let Some((src, dst)) = factors {
        // The target's alpha stays opaque (1 from the clear; ONE, ONE_MINUS_SRC_ALPHA keeps it).
        blend_attachment = blend_attachment
            .blend_enable(true)
            .src_color_blend_factor(src)
            .dst_color_blend_factor(dst)
            .color_blend_op(vk::BlendOp::ADD)
            .src_alpha_blend_factor(vk::BlendFactor::ONE)
            .dst_alpha_blend_factor(if d.blend == ColorBlend::Over {
                vk::BlendFactor::ONE_MINUS_SRC_ALPHA
            } else {
                vk::BlendFactor::ZERO
            })
            .alpha_blend_op(vk::BlendOp::ADD);
    }
    blend_attachment
}

/// Creates a pipeline layout with set layouts and one immediate (push-constant) range.
pub fn create_layout(
    ctx: &Context,
    sets: &[vk::DescriptorSetLayout],
    immediate_size: u32,
    name: &str,
) -> Result<vk::PipelineLayout, GpuError> {
    let ranges = [vk::PushConstantRange {
        stage_flags: vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
        offset: 0,
        size: immediate_size,
    }];
    let ranges = if immediate_size > 0 { &ranges[..] } else { &[] };
    crate::gpu::shaders::create_pipeline_layout(ctx, sets, ranges, name)
}

/// Full-extent viewport and scissor.
pub fn set_viewport(ctx: &Context, cmd: vk::CommandBuffer, extent: vk::Extent2D) {
    let vp = [vk::Viewport {
        x: 0.0,
        y: 0.0,
        width: extent.width as f32,
        height: extent.height as f32,
        min_depth: 0.0,
        max_depth: 1.0,
    }];
    let sc = [vk::Rect2D {
        offset: vk::Offset2D::default(),
        extent,
    }];
    Recorder::new(&ctx.device, cmd).set_viewport(0, &vp);
    Recorder::new(&ctx.device, cmd).set_scissor(0, &sc);
}

/// A depth attachment cleared to 0 (reversed-z: 0 is the far plane) and stored (with a stencil
/// aspect, `stencil` true: both aspects, cleared to 0, in the combined layout).
pub fn depth_clear_attachment(
    view: vk::ImageView,
    stencil: bool,
) -> vk::RenderingAttachmentInfo<'static> {
    vk::RenderingAttachmentInfo::default()
        .image_view(view)
        .image_layout(if stencil {
            vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL
        } else {
            vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL
        })
        .load_op(vk::AttachmentLoadOp::CLEAR)
        .store_op(vk::AttachmentStoreOp::STORE)
        .clear_value(vk::ClearValue {
            depth_stencil: vk::ClearDepthStencilValue {
                depth: 0.0,
                stencil: 0,
            },
        })
}

/// `r` as Vulkan's rectangle.
pub(crate) fn texel_rect(r: crate::plan::TexelRect) -> vk::Rect2D {
    vk::Rect2D {
        offset: vk::Offset2D {
            x: r.x as i32,
            y: r.y as i32,
        },
        extent: vk::Extent2D {
            width: r.width,
            height: r.height,
        },
    }
}

// The uniform blocks and immediates the plan writes are the size the shaders read.
const _: () = assert!(
    std::mem::size_of::<crate::plan::uniforms::FrameUniform>()
        == crate::gpu::shaders::scene::FRAME_BLOCK.size as usize
);
const _: () = assert!(
    std::mem::size_of::<crate::plan::uniforms::MaterialUniform>()
        == crate::gpu::shaders::scene::MATERIAL_BLOCK.size as usize
);
const _: () = assert!(
    std::mem::size_of::<crate::plan::uniforms::SceneImmediates>()
        == crate::gpu::shaders::scene::IMMEDIATE_SIZE as usize
);
const _: () = assert!(
    std::mem::size_of::<crate::plan::uniforms::ShadowImmediates>()
        == crate::gpu::shaders::shadow::IMMEDIATE_SIZE as usize
);

#[cfg(test)]
mod tests {
    use super::*;
    use ash::vk::Handle;

    const MOVED: [vk::VertexInputAttributeDescription; 1] = [vk::VertexInputAttributeDescription {
        location: 0,
        binding: 0,
        format: vk::Format::UNDEFINED,
        offset: 12,
    }];
    const TWO: [vk::Format; 2] = [vk::Format::R8G8B8A8_SRGB, vk::Format::R32_UINT];

    /// Every field but the name changes what a pipeline is known by; modules and layouts count
    /// by what they are made of.
    #[test]
    fn a_pipeline_is_known_by_all_it_is_made_of() {
        let store = PipelineStore::default();
        let module = |raw, made_of| {
            let m = vk::ShaderModule::from_raw(raw);
            store.note(m, made_of);
            m
        };
        let (vs, fs, fs_twin, other) = (module(1, 10), module(2, 20), module(3, 20), module(4, 30));
        let layout = vk::PipelineLayout::from_raw(5);
        store.note(layout, 50);
        let layout_twin = vk::PipelineLayout::from_raw(6);
        store.note(layout_twin, 50);
        let other_layout = vk::PipelineLayout::from_raw(7);
        store.note(other_layout, 70);
        let binding = [vk::VertexInputBindingDescription::default().stride(32)];
        let attributes = [vk::VertexInputAttributeDescription::default()];
        let colour = [vk::Format::R8G8B8A8_SRGB];
        let base = PipelineDesc {
            name: "a",
            layout,
            vertex: (vs, c"vs_main"),
            fragment: Some((fs, c"fs_main")),
            bindings: &binding,
            attributes: &attributes,
            color_formats: &colour,
            masked_targets: 0,
            depth_format: vk::Format::D32_SFLOAT,
            stencil: Stencil::Off,
            depth_clamp: false,
            depth_bias: false,
            depth: Depth::Test,
            blend: ColorBlend::Off,
            samples: 1,
        };
        let key = |change: &dyn Fn(&mut PipelineDesc)| {
            let mut d = base;
            change(&mut d);
            definition(&store, &d)
        };
        let same: [&dyn Fn(&mut PipelineDesc); 3] = [
            &|d| d.name = "b",
            &|d| d.fragment = Some((fs_twin, c"fs_main")),
            &|d| d.layout = layout_twin,
        ];
        for change in same {
            assert_eq!(key(change), key(&|_| ()));
        }
        let differ: [&dyn Fn(&mut PipelineDesc); 18] = [
            &|d| d.layout = other_layout,
            &|d| d.vertex = (other, c"vs_main"),
            &|d| d.vertex = (vs, c"vs_flat"),
            &|d| d.fragment = Some((other, c"fs_main")),
            &|d| d.fragment = Some((fs, c"fs_flat")),
            &|d| d.fragment = None,
            &|d| d.bindings = &[],
            &|d| d.attributes = &MOVED,
            &|d| d.color_formats = &TWO,
            &|d| d.color_formats = &[],
            &|d| d.masked_targets = 1,
            &|d| d.depth_format = vk::Format::D32_SFLOAT_S8_UINT,
            &|d| d.stencil = Stencil::Mark,
            &|d| d.depth_clamp = true,
            &|d| d.depth_bias = true,
            &|d| d.depth = Depth::Off,
            &|d| d.blend = ColorBlend::Over,
            &|d| d.samples = 4,
        ];
        let mut keys: Vec<u64> = differ.iter().map(|&change| key(change)).collect();
        keys.push(key(&|_| ()));
        let n = keys.len();
        keys.sort_unstable();
        keys.dedup();
        assert_eq!(keys.len(), n, "two different pipelines share a key");
    }
}
