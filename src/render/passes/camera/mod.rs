//! The camera pass: Blinn-Phong, normal mapping, shadow-map reprojection (scene.wgsl), plus the
//! full-screen shadow-map debug view. One frame-uniform slot per frame in flight.
//!
//! `pipelines` creates the scene pipelines a frame needs, `frame` decides what a frame draws
//! (`CameraFrame`), `record` records it (forward draws, G-buffer and resolves, sky), `aov` the
//! instance-id and normal pass.

mod aov;
mod frame;
mod pipelines;
mod record;

use crate::shader_consts::VariantKey;
use aov::{aov_attachments, aov_draws};
use frame::flat_inputs_fit;
use pipelines::Formats;
use record::full_rect;

pub use aov::{AovTargets, AOV_FORMATS};
pub use frame::{CameraCounts, CameraFrame, CameraTargets, Redrawn, Resolve, FLAT_LOCATIONS};

use crate::gpu::context::{Context, GpuError, VkCheck};
use crate::gpu::shaders::{
    allocate_sets, create_module, scene as sh, set_layout, ReflectedBinding,
};
use crate::gpu::Buffer;
use crate::plan::uniforms::FrameUniform;
use crate::render::gpu_scene::GpuScene;
use crate::render::passes::cull::Entry;
use crate::render::passes::deferred::GBuffer;
use crate::render::pipeline::{
    create_layout, create_pipeline, ColorBlend, Depth, PipelineDesc, Stencil,
};
use ash::vk;
use gpu_allocator::MemoryLocation;
use std::collections::HashMap;
use std::sync::Arc;

/// Depth format of the camera pass.
pub const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;

/// Depth format of a camera pass that shades some draws deferred: the same depth, plus the
/// stencil that marks each deferred pixel's material.
pub const DEPTH_STENCIL_FORMAT: vk::Format = vk::Format::D32_SFLOAT_S8_UINT;

struct Slot {
    buffer: Buffer,
    set: vk::DescriptorSet,
    bound_map: vk::ImageView,
    /// The exact pass's sample buffer bound (`exact_samples`), or the pass's empty one.
    bound_exact: vk::Buffer,
    /// An empty sample list (no exact pass has run), so the binding is always written.
    no_exact: Buffer,
}

/// The camera pass for one colour format.
pub struct CameraPass {
    ctx: Arc<Context>,
    layout: vk::PipelineLayout,
    frame_layout: vk::DescriptorSetLayout,
    module: vk::ShaderModule,
    color_format: vk::Format,
    /// Depth (and stencil) format of the pass: `DEPTH_STENCIL_FORMAT` when it may defer.
    pub depth_format: vk::Format,
    /// Samples per pixel of the colour and depth attachments (MSAA; 1 = off).
    samples: u32,
    /// Whether micro-triangle draws are shaded deferred (`crate::render::passes::deferred`).
    deferred: bool,
    /// Whether opaque forward draws of large triangles read the uniforms as flat inputs (CPU
    /// devices: `FLAT_FROM_PIXELS`).
    flat_forward: bool,
    gbuffer_layout: vk::DescriptorSetLayout,
    /// The G-buffer targets, at the last deferring frame's size.
    gbuffer: Option<GBuffer>,
    /// Shader modules of the override variants created so far (by variant index).
    variant_modules: HashMap<VariantKey, vk::ShaderModule>,
    /// Scene pipelines created so far, by (variant index, entry point).
    pipelines: HashMap<(VariantKey, Entry), vk::Pipeline>,
    map_pipeline: vk::Pipeline,
    /// The background where nothing was drawn (`fs_sky`).
    sky_pipeline: vk::Pipeline,
    /// `sky_pipeline` in a pass that also draws the ids and normals (made by the first such
    /// frame; those targets left alone).
    sky_aovs: Option<vk::Pipeline>,
    pool: vk::DescriptorPool,
    slots: Vec<Slot>,
    linear_sampler: vk::Sampler,
    nearest_sampler: vk::Sampler,
}

impl CameraPass {
    /// Creates the pass for `color_format` at `samples` per pixel, with `slots` frame-uniform
    /// slots (frames in flight); `deferred`: shade micro-triangle draws deferred (single sample
    /// only).
    pub fn new(
        ctx: &Arc<Context>,
        scene: &GpuScene,
        color_format: vk::Format,
        samples: u32,
        slots: usize,
        deferred: bool,
    ) -> Result<Self, GpuError> {
        // The resolves read their uniforms as flat inputs (`FLAT_LOCATIONS`).
        let flat = flat_inputs_fit(ctx);
        if deferred && samples == 1 && !flat {
            log::warn!(
                "deferred shading off: the device takes {} fragment input components, the resolve {}",
                ctx.properties.limits.max_fragment_input_components,
                FLAT_LOCATIONS * 4
            );
        }
        let deferred = deferred && samples == 1 && flat;
        // Where flat inputs pay: llvmpipe's per-lane uniform loads (FLAT_FROM_PIXELS).
        let flat_cpu = flat && ctx.is_cpu();
        let depth_format = if deferred {
            DEPTH_STENCIL_FORMAT
        } else {
            DEPTH_FORMAT
        };
        let frame_layout = set_layout(ctx, sh::BINDINGS, 0, "frame set layout")?;
        let gbuffer_layout = set_layout(ctx, sh::BINDINGS, 2, "G-buffer set layout")?;
        let layout = create_layout(
            ctx,
            &[frame_layout, scene.material_layout, gbuffer_layout],
            sh::IMMEDIATE_SIZE,
            "camera pipeline layout",
        )?;
        let module = create_module(ctx, &sh::spirv()?, "scene.wgsl")?;
        let targets = Formats {
            color: color_format,
            depth: depth_format,
            samples,
        };
        let (map_pipeline, sky_pipeline) = fixed_pipelines(ctx, layout, module, targets, flat_cpu)?;
        let (pool, slot_list) = frame_slots(ctx, frame_layout, slots)?;
        let (linear_sampler, nearest_sampler) = compare_samplers(ctx)?;
        Ok(Self {
            ctx: ctx.clone(),
            layout,
            frame_layout,
            module,
            color_format,
            depth_format,
            samples,
            deferred,
            flat_forward: flat_cpu,
            gbuffer_layout,
            gbuffer: None,
            variant_modules: HashMap::new(),
            pipelines: HashMap::new(),
            map_pipeline,
            sky_pipeline,
            sky_aovs: None,
            pool,
            slots: slot_list,
            linear_sampler,
            nearest_sampler,
        })
    }

    /// Points slot `slot`'s set at the shadow map. Every binding is written (lavapipe crashes on
    /// unwritten descriptors, used or not). The slot's previous frame must have completed.
    pub fn bind_shadow_map(
        &mut self,
        slot: usize,
        view: vk::ImageView,
        hardware_filtering: bool,
        exact: Option<vk::Buffer>,
    ) {
        let s = &mut self.slots[slot];
        let exact = exact.unwrap_or(s.no_exact.raw);
        if view == s.bound_map && exact == s.bound_exact {
            return;
        }
        let samples = [vk::DescriptorBufferInfo {
            buffer: exact,
            offset: 0,
            range: vk::WHOLE_SIZE,
        }];
        let buf = [vk::DescriptorBufferInfo {
            buffer: s.buffer.raw,
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
        let set = s.set;
        let w = |b: &ReflectedBinding| b.write(set);
        let writes = [
            w(&sh::FRAME_BLOCK).buffer_info(&buf),
            w(&sh::SHADOW_MAP).image_info(&img),
            w(&sh::SHADOW_SAMPLER).image_info(&samp),
            w(&sh::EXACT_SAMPLES).buffer_info(&samples),
        ];
        unsafe { self.ctx.device.update_descriptor_sets(&writes, &[]) };
        s.bound_map = view;
        s.bound_exact = exact;
    }

    /// Writes slot `slot`'s frame uniforms (its previous frame must have completed).
    pub fn write_frame(&mut self, slot: usize, u: &FrameUniform) -> Result<(), GpuError> {
        self.slots[slot].buffer.write(0, bytemuck::bytes_of(u))
    }
}

/// The pipelines every camera pass has: the shadow-map view and the sky (a full-screen triangle
/// at depth 0 drawn where no surface was; with `flat_cpu` its uniforms as flat inputs,
/// shaders/lib/uniforms.wgsl).
fn fixed_pipelines(
    ctx: &Context,
    layout: vk::PipelineLayout,
    module: vk::ShaderModule,
    formats: Formats,
    flat_cpu: bool,
) -> Result<(vk::Pipeline, vk::Pipeline), GpuError> {
    let desc = PipelineDesc {
        name: "shadow-map view pipeline",
        layout,
        vertex: (module, sh::ENTRY_VS_FULLSCREEN),
        fragment: Some((module, sh::ENTRY_FS_SHADOW_MAP)),
        bindings: &[],
        attributes: &[],
        color_formats: &[formats.color],
        masked_targets: 0,
        depth_format: formats.depth,
        stencil: Stencil::Off,
        depth_clamp: false,
        depth_bias: false,
        depth: Depth::Off,
        blend: ColorBlend::Off,
        samples: formats.samples,
    };
    let map_pipeline = create_pipeline(ctx, &desc)?;
    let sky_pipeline = sky_pipeline(
        ctx,
        layout,
        module,
        &[formats.color],
        (formats.depth, formats.samples),
        flat_cpu,
    )?;
    Ok((map_pipeline, sky_pipeline))
}

/// The sky's pipeline for a pass of `color_formats` (the first the image; any others left
/// alone) and `depth` (format, samples): one full-screen triangle at depth 0, shaded where no
/// surface was; with `flat_cpu` its uniforms as flat inputs.
pub(super) fn sky_pipeline(
    ctx: &Context,
    layout: vk::PipelineLayout,
    module: vk::ShaderModule,
    color_formats: &[vk::Format],
    (depth_format, samples): (vk::Format, u32),
    flat_cpu: bool,
) -> Result<vk::Pipeline, GpuError> {
    let (sky_vs, sky_fs) = if flat_cpu {
        (sh::ENTRY_VS_SKY, sh::ENTRY_FS_SKY_FLAT)
    } else {
        (sh::ENTRY_VS_FULLSCREEN, sh::ENTRY_FS_SKY)
    };
    create_pipeline(
        ctx,
        &PipelineDesc {
            name: "sky pipeline",
            layout,
            vertex: (module, sky_vs),
            fragment: Some((module, sky_fs)),
            bindings: &[],
            attributes: &[],
            color_formats,
            masked_targets: color_formats.len() - 1,
            depth_format,
            stencil: Stencil::Off,
            depth_clamp: false,
            depth_bias: false,
            depth: Depth::Empty,
            blend: ColorBlend::Off,
            samples,
        },
    )
}

/// `slots` frame-uniform slots: each a uniform buffer, its set and an empty exact-sample list.
fn frame_slots(
    ctx: &Arc<Context>,
    frame_layout: vk::DescriptorSetLayout,
    slots: usize,
) -> Result<(vk::DescriptorPool, Vec<Slot>), GpuError> {
    let (pool, sets) = allocate_sets(ctx, sh::BINDINGS, 0, frame_layout, slots)?;
    let mut slot_list = Vec::new();
    for (i, set) in sets.into_iter().enumerate() {
        let buffer = Buffer::new(
            ctx,
            &format!("frame uniforms {i}"),
            std::mem::size_of::<FrameUniform>() as u64,
            vk::BufferUsageFlags::UNIFORM_BUFFER,
            MemoryLocation::CpuToGpu,
        )?;
        let mut no_exact = Buffer::new(
            ctx,
            &format!("exact samples (none) {i}"),
            16,
            vk::BufferUsageFlags::STORAGE_BUFFER,
            MemoryLocation::CpuToGpu,
        )?;
        no_exact.write(0, bytemuck::cast_slice(&[0f32; 4]))?;
        slot_list.push(Slot {
            buffer,
            set,
            bound_map: vk::ImageView::null(),
            bound_exact: vk::Buffer::null(),
            no_exact,
        });
    }
    Ok((pool, slot_list))
}

/// The shadow map's comparison samplers, linear and nearest.
fn compare_samplers(ctx: &Context) -> Result<(vk::Sampler, vk::Sampler), GpuError> {
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
    Ok((linear_sampler, nearest_sampler))
}

impl Drop for CameraPass {
    fn drop(&mut self) {
        unsafe {
            let d = &self.ctx.device;
            let _ = d.device_wait_idle();
            for (_, m) in self.variant_modules.drain() {
                d.destroy_shader_module(m, None);
            }
            self.gbuffer = None;
            d.destroy_descriptor_set_layout(self.gbuffer_layout, None);
            d.destroy_shader_module(self.module, None);
            d.destroy_pipeline_layout(self.layout, None);
            d.destroy_descriptor_pool(self.pool, None);
            d.destroy_descriptor_set_layout(self.frame_layout, None);
            d.destroy_sampler(self.linear_sampler, None);
            d.destroy_sampler(self.nearest_sampler, None);
        }
    }
}
