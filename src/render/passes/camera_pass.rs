//! The camera pass: Blinn-Phong, normal mapping, shadow-map reprojection (scene.wgsl), plus the
//! full-screen shadow-map debug view. One frame-uniform slot per frame in flight.

use crate::gpu::barrier::Access;
use crate::gpu::context::{Context, GpuError, VkCheck};
use crate::gpu::resources::has_stencil;
use crate::gpu::shaders::{
    allocate_sets, create_module, scene as sh, set_layout, ReflectedBinding,
};
use crate::gpu::Buffer;
use crate::plan::flat_hides_nothing;
use crate::plan::uniforms::FrameUniform;
use crate::render::gpu_scene::{vertex_layout, AlphaDraw, GpuScene};
use crate::render::passes::cull::{CameraCull, Entry};
use crate::render::passes::deferred::{self, DeferPlan, GBuffer, GBUFFER_FORMAT, GBUFFER_TARGETS};
use crate::render::passes::receivers::{self, Split};
use crate::render::passes::screen::pixels_per_triangle;
use crate::render::pipeline::{
    create_layout, create_pipeline, depth_clear_attachment, set_viewport, ColorBlend, Depth,
    PipelineDesc, Stencil,
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
    variant_modules: HashMap<usize, vk::ShaderModule>,
    /// Scene pipelines created so far, by (variant index, entry point).
    pipelines: HashMap<(usize, Entry), vk::Pipeline>,
    map_pipeline: vk::Pipeline,
    /// The background where nothing was drawn (`fs_sky`).
    sky_pipeline: vk::Pipeline,
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
        let desc = PipelineDesc {
            name: "shadow-map view pipeline",
            layout,
            vertex: (module, sh::ENTRY_VS_FULLSCREEN),
            fragment: Some((module, sh::ENTRY_FS_SHADOW_MAP)),
            bindings: &[],
            attributes: &[],
            color_formats: &[color_format],
            masked_targets: 0,
            depth_format,
            stencil: Stencil::Off,
            depth_clamp: false,
            depth_bias: false,
            depth: Depth::Off,
            blend: ColorBlend::Off,
            samples,
        };
        let map_pipeline = create_pipeline(ctx, &desc)?;
        // The sky: a full-screen triangle at depth 0 drawn where no surface was; on CPU devices
        // its uniforms as flat inputs (shaders/lib/uniforms.wgsl).
        let (sky_vs, sky_fs) = if flat_cpu {
            (sh::ENTRY_VS_SKY, sh::ENTRY_FS_SKY_FLAT)
        } else {
            (sh::ENTRY_VS_FULLSCREEN, sh::ENTRY_FS_SKY)
        };
        let sky_pipeline = create_pipeline(
            ctx,
            &PipelineDesc {
                name: "sky pipeline",
                vertex: (module, sky_vs),
                fragment: Some((module, sky_fs)),
                depth: Depth::Empty,
                ..desc
            },
        )?;
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
            pool,
            slots: slot_list,
            linear_sampler,
            nearest_sampler,
        })
    }

    /// Creates the scene pipelines this frame (`cull`, at `extent`) needs (once each): for every
    /// (material variant, alpha-masked) pair of the scene's draws, specialised by the frame's
    /// bits (`frame_bits`: one light, shadows), and when it shades draws deferred, the G-buffer
    /// pipeline, targets and its materials' resolve pipelines. Creation compiles the shader, so
    /// it happens here, not per draw.
    pub fn ensure_pipelines(
        &mut self,
        scene: &GpuScene,
        frame: &CameraFrame,
        extent: vk::Extent2D,
    ) -> Result<(), GpuError> {
        let cull = &frame.cull;
        let (frame_bits, debug_view) = (cull.frame_bits, cull.debug_view);
        let mut keys: Vec<(usize, Entry)> = scene
            .pipeline_keys
            .iter()
            .map(|&(bits, alpha)| (bits | frame_bits, Entry::of(alpha, debug_view)))
            .collect();
        let defer = &frame.defer;
        // The unshadowed variants of receivers drawn (partly) beyond the casters' reach, and the
        // flat-input pipelines of large-triangle draws.
        for ((&i, split), &flat) in defer.forward.iter().zip(&frame.splits).zip(&frame.flat) {
            let dr = &scene.draws[i];
            let entry = frame.entry(dr.alpha, flat);
            let bits = dr.material_bits | frame_bits;
            if flat {
                keys.push((bits, entry));
            }
            if *split != Split::Shadowed {
                keys.push((receivers::unshadowed(bits), entry));
            }
        }
        if !defer.deferred.is_empty() {
            // Per resolved material its resolve, and the G-buffer pipeline of its texture slots.
            keys.extend(defer.resolved.iter().flat_map(|r| {
                [
                    (r.material_bits | frame_bits, Entry::Resolve),
                    (deferred::gbuffer_variant(r.material_bits), Entry::GBuffer),
                ]
            }));
            self.ensure_gbuffer(extent)?;
        }
        self.build_pipelines(keys)
    }

    /// Creates the AOV pipelines (`fs_aov`) `frame`'s opaque and masked draws need: one per
    /// material variant (the frame's bits mean nothing to it).
    pub fn ensure_aov_pipelines(
        &mut self,
        scene: &GpuScene,
        frame: &CameraFrame,
    ) -> Result<(), GpuError> {
        let keys = aov_draws(scene, frame)
            .map(|i| (scene.draws[i].material_bits, Entry::Aov))
            .collect();
        self.build_pipelines(keys)
    }

    /// Creates the pipelines of `keys` (variant, entry) not made yet.
    fn build_pipelines(&mut self, keys: Vec<(usize, Entry)>) -> Result<(), GpuError> {
        // Modules first (cheap), then the missing pipelines compiled in parallel: on lavapipe
        // each is an LLVM compile of its shaders, the largest part of a cold first frame.
        let mut missing: Vec<(usize, Entry, vk::ShaderModule)> = Vec::new();
        for (variant, entry) in keys {
            if self.pipelines.contains_key(&(variant, entry))
                || missing.iter().any(|m| (m.0, m.1) == (variant, entry))
            {
                continue;
            }
            let module = match self.variant_modules.get(&variant) {
                Some(&m) => m,
                None => {
                    let m = create_module(
                        &self.ctx,
                        &sh::variant(variant)?,
                        &format!("scene.wgsl variant {variant}"),
                    )?;
                    self.variant_modules.insert(variant, m);
                    m
                }
            };
            missing.push((variant, entry, module));
        }
        let formats = Formats {
            color: self.color_format,
            depth: self.depth_format,
            samples: self.samples,
        };
        let (ctx, layout) = (&self.ctx, self.layout);
        let built: Vec<Result<vk::Pipeline, GpuError>> = std::thread::scope(|s| {
            let threads: Vec<_> = missing
                .iter()
                .map(|&(variant, entry, module)| {
                    s.spawn(move || scene_pipeline(ctx, layout, formats, variant, entry, module))
                })
                .collect();
            threads
                .into_iter()
                .map(|t| {
                    t.join().unwrap_or(Err(GpuError::Vk {
                        call: "vkCreateGraphicsPipelines (thread panicked)",
                        result: vk::Result::ERROR_UNKNOWN,
                    }))
                })
                .collect()
        });
        let mut first_error = None;
        for (&(variant, entry, _), result) in missing.iter().zip(built) {
            match result {
                Ok(p) => {
                    self.pipelines.insert((variant, entry), p);
                }
                Err(e) => first_error = first_error.or(Some(e)),
            }
        }
        first_error.map_or(Ok(()), Err)
    }

    /// The G-buffer targets at `extent` (re-made when the size changes).
    fn ensure_gbuffer(&mut self, extent: vk::Extent2D) -> Result<(), GpuError> {
        if self.gbuffer.as_ref().is_none_or(|g| g.extent != extent) {
            // The old targets (if any) are dropped first: a window's resize.
            self.gbuffer = None;
            self.gbuffer = Some(GBuffer::new(&self.ctx, extent, self.gbuffer_layout)?);
        }
        Ok(())
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
        let w = |b: &ReflectedBinding| {
            vk::WriteDescriptorSet::default()
                .dst_set(set)
                .dst_binding(b.binding)
                .descriptor_type(b.descriptor_type())
        };
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

    /// Records the pass into colour and depth attachments already in attachment layouts; with
    /// `shadow_map_view` it draws the shadow map full-screen instead of the scene. Draws that
    /// `deferred::plan` picks (their pipelines made by `ensure_pipelines`) go through the
    /// G-buffer first, and their materials are resolved before the forward draws. Returns the
    /// draws recorded, how many of them were deferred, and how many were drawn (in part) without
    /// the shadow lookup (`receivers::split`).
    pub fn record(
        &mut self,
        cmd: vk::CommandBuffer,
        slot: usize,
        scene: &GpuScene,
        targets: &CameraTargets,
        frame: &CameraFrame,
    ) -> CameraCounts {
        let (cull, shadow_map_view, plan) = (&frame.cull, frame.shadow_map_view, &frame.defer);
        let CameraTargets {
            color,
            depth,
            resolve,
            extent,
            clear,
        } = *targets;
        let ctx = self.ctx.clone();
        let d = &ctx.device;
        ctx.begin_label(cmd, "camera pass");
        let stencil = has_stencil(self.depth_format);
        let deferring = !plan.deferred.is_empty();
        let frame_set = self.slots[slot].set;
        let mut drawn = 0;
        let mut unshadowed = 0;
        let mut deferred_draws = 0;
        if deferring {
            deferred_draws = self.record_gbuffer(cmd, scene, targets, frame_set, plan, cull);
        }
        let mut color_att = vk::RenderingAttachmentInfo::default()
            .image_view(color)
            .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue {
                color: vk::ClearColorValue { float32: clear },
            });
        let mut depth_att = depth_clear_attachment(depth, stencil);
        if deferring {
            // The G-buffer pass's depth and stencil marks.
            depth_att = depth_att.load_op(vk::AttachmentLoadOp::LOAD);
        }
        if let Some(target) = resolve.color {
            // The samples are averaged into the target; they need not be kept.
            color_att = color_att
                .store_op(vk::AttachmentStoreOp::DONT_CARE)
                .resolve_mode(vk::ResolveModeFlags::AVERAGE)
                .resolve_image_view(target)
                .resolve_image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
        }
        if let Some(target) = resolve.depth {
            // Sample 0 (every device supports it): the depth of the pixel centre's nearest sample.
            depth_att = depth_att
                .resolve_mode(vk::ResolveModeFlags::SAMPLE_ZERO)
                .resolve_image_view(target)
                .resolve_image_layout(vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL);
        }
        let color_att = [color_att];
        let mut rendering = vk::RenderingInfo::default()
            .render_area(full_rect(extent))
            .layer_count(1)
            .color_attachments(&color_att)
            .depth_attachment(&depth_att);
        if stencil {
            rendering = rendering.stencil_attachment(&depth_att);
        }
        self.begin_rendering(cmd, &rendering, extent, frame_set);
        unsafe {
            if shadow_map_view {
                d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.map_pipeline);
                d.cmd_set_cull_mode(cmd, vk::CullModeFlags::NONE);
                d.cmd_set_front_face(cmd, vk::FrontFace::COUNTER_CLOCKWISE);
                d.cmd_draw(cmd, 3, 1, 0, 0);
            }
            if deferring {
                self.record_resolve(cmd, scene, plan, cull.frame_bits, extent);
            }
            if !plan.forward.is_empty() || frame.sky {
                let (n, u) = self.record_forward(cmd, scene, frame, extent);
                drawn += n;
                unshadowed += u;
            }
            d.cmd_end_rendering(cmd);
        }
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
        unsafe {
            bind_geometry(d, cmd, scene);
            let mut bound_material = usize::MAX;
            let mut bound_pipeline = vk::Pipeline::null();
            let mut sky = frame.sky;
            let forward = frame.defer.forward.iter().zip(&frame.splits);
            for ((&i, split), &flat) in forward.zip(&frame.flat) {
                let dr = &scene.draws[i];
                let entry = frame.entry(dr.alpha, flat);
                if sky && entry == Entry::Blended {
                    self.record_sky(cmd);
                    bound_pipeline = self.sky_pipeline;
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
                        d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, pipeline);
                        bound_pipeline = pipeline;
                    }
                    if let Some(s) = scissor {
                        d.cmd_set_scissor(cmd, 0, &[s]);
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
                    d.cmd_set_scissor(cmd, 0, &[full_rect(extent)]);
                }
            }
            if sky {
                self.record_sky(cmd);
            }
        }
        (drawn, unshadowed)
    }

    /// Records the sky: one full-screen triangle at depth 0, shaded only where no surface was
    /// drawn (inside a rendering whose set 0 is bound).
    fn record_sky(&self, cmd: vk::CommandBuffer) {
        let d = &self.ctx.device;
        unsafe {
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.sky_pipeline);
            d.cmd_set_cull_mode(cmd, vk::CullModeFlags::NONE);
            d.cmd_set_front_face(cmd, vk::FrontFace::COUNTER_CLOCKWISE);
            d.cmd_draw(cmd, 3, 1, 0, 0);
        }
    }

    /// Records the G-buffer pass of `plan`'s deferred draws (clearing depth and stencil, each
    /// draw marking its material), then makes the targets readable and the depth and stencil
    /// visible to the next rendering. Returns the number of draws.
    fn record_gbuffer(
        &mut self,
        cmd: vk::CommandBuffer,
        scene: &GpuScene,
        targets: &CameraTargets,
        frame_set: vk::DescriptorSet,
        plan: &DeferPlan,
        cull: &CameraCull,
    ) -> usize {
        let (depth, extent) = (targets.depth, targets.extent);
        let ctx = self.ctx.clone();
        let d = &ctx.device;
        let Some(gbuffer) = self.gbuffer.as_mut() else {
            return 0;
        };
        ctx.begin_label(cmd, "G-buffer");
        gbuffer.transition(cmd, Access::ColorAttachment);
        let views = gbuffer.views();
        let targets: Vec<vk::RenderingAttachmentInfo> = views
            .into_iter()
            .map(|v| {
                // Only marked pixels are read, and those are written: nothing to load.
                vk::RenderingAttachmentInfo::default()
                    .image_view(v)
                    .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                    .load_op(vk::AttachmentLoadOp::DONT_CARE)
                    .store_op(vk::AttachmentStoreOp::STORE)
            })
            .collect();
        let depth_att = depth_clear_attachment(depth, true);
        let rendering = vk::RenderingInfo::default()
            .render_area(full_rect(extent))
            .layer_count(1)
            .color_attachments(&targets)
            .depth_attachment(&depth_att)
            .stencil_attachment(&depth_att);
        self.begin_rendering(cmd, &rendering, extent, frame_set);
        bind_geometry(d, cmd, scene);
        let mut bound = None;
        for &(i, mark) in &plan.deferred {
            let dr = &scene.draws[i];
            let variant = deferred::gbuffer_variant(dr.material_bits);
            if bound != Some(variant) {
                // Made by `ensure_pipelines` for this frame.
                let pipeline = self.pipelines[&(variant, Entry::GBuffer)];
                unsafe { d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, pipeline) };
                bound = Some(variant);
            }
            unsafe { d.cmd_set_stencil_reference(cmd, vk::StencilFaceFlags::FRONT_AND_BACK, mark) };
            scene.record_draw(
                cmd,
                self.layout,
                dr,
                Some(cull.eye),
                cull.viewpoint,
                bytemuck::bytes_of(&dr.immediates),
            );
        }
        unsafe { d.cmd_end_rendering(cmd) };
        if let Some(g) = self.gbuffer.as_mut() {
            g.transition(cmd, Access::FragmentSampled);
        }
        // The resolve's stencil test and the forward draws' depth test read what this pass
        // wrote (same layout: a memory dependency only).
        let tests = vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS
            | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS;
        let mb = [vk::MemoryBarrier2::default()
            .src_stage_mask(tests)
            .src_access_mask(vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE)
            .dst_stage_mask(tests)
            .dst_access_mask(
                vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ
                    | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE,
            )];
        unsafe {
            d.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().memory_barriers(&mb))
        };
        ctx.end_label(cmd);
        plan.deferred.len()
    }

    /// Begins `rendering` with a full-extent viewport and the frame's set 0 bound (every camera
    /// pipeline shares the layout).
    fn begin_rendering(
        &self,
        cmd: vk::CommandBuffer,
        rendering: &vk::RenderingInfo,
        extent: vk::Extent2D,
        frame_set: vk::DescriptorSet,
    ) {
        let d = &self.ctx.device;
        unsafe {
            d.cmd_begin_rendering(cmd, rendering);
            set_viewport(&self.ctx, cmd, extent);
            d.cmd_bind_descriptor_sets(
                cmd,
                vk::PipelineBindPoint::GRAPHICS,
                self.layout,
                0,
                &[frame_set],
                &[],
            );
        }
    }

    /// Records one full-screen triangle per resolved material of `plan`, limited to its draws'
    /// screen rectangle and to the pixels its stencil mark holds (inside a rendering whose set 0
    /// is bound); restores the full scissor.
    fn record_resolve(
        &self,
        cmd: vk::CommandBuffer,
        scene: &GpuScene,
        plan: &DeferPlan,
        frame_bits: usize,
        extent: vk::Extent2D,
    ) {
        let Some(gbuffer) = self.gbuffer.as_ref() else {
            return;
        };
        let d = &self.ctx.device;
        unsafe {
            d.cmd_bind_descriptor_sets(
                cmd,
                vk::PipelineBindPoint::GRAPHICS,
                self.layout,
                2,
                &[gbuffer.set],
                &[],
            );
            d.cmd_set_cull_mode(cmd, vk::CullModeFlags::NONE);
            d.cmd_set_front_face(cmd, vk::FrontFace::COUNTER_CLOCKWISE);
            for r in &plan.resolved {
                let pipeline = self.pipelines[&(r.material_bits | frame_bits, Entry::Resolve)];
                d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, pipeline);
                scene.bind_material(d, cmd, self.layout, 1, r.material);
                d.cmd_set_stencil_reference(cmd, vk::StencilFaceFlags::FRONT_AND_BACK, r.mark);
                d.cmd_set_scissor(cmd, 0, &[r.rect.scissor()]);
                d.cmd_draw(cmd, 3, 1, 0, 0);
            }
            d.cmd_set_scissor(cmd, 0, &[full_rect(extent)]);
        }
    }
}

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

/// The draws the AOV pass records for `frame`: its visible draws, blended ones left out.
fn aov_draws<'a>(scene: &'a GpuScene, frame: &'a CameraFrame) -> impl Iterator<Item = usize> + 'a {
    let d = &frame.defer;
    d.deferred
        .iter()
        .map(|&(i, _)| i)
        .chain(d.forward.iter().copied())
        .filter(|&i| scene.draws[i].alpha != AlphaDraw::Blended)
}

impl CameraPass {
    /// Records the AOV pass of `frame` (slot `slot`'s uniforms): every visible opaque and masked
    /// draw, depth-tested, writing its instance id + 1 and world normal (`fs_aov`). Returns the
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
        let color = |view, clear| {
            vk::RenderingAttachmentInfo::default()
                .image_view(view)
                .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                .load_op(vk::AttachmentLoadOp::CLEAR)
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(vk::ClearValue { color: clear })
        };
        let colors = [
            color(t.ids, vk::ClearColorValue { uint32: [0; 4] }),
            color(t.normals, vk::ClearColorValue { float32: [0.0; 4] }),
        ];
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
        bind_geometry(d, cmd, scene);
        let cull = &frame.cull;
        let (mut bound_material, mut drawn) = (usize::MAX, 0);
        for i in aov_draws(scene, frame) {
            let dr = &scene.draws[i];
            unsafe {
                if dr.material != bound_material {
                    scene.bind_material(d, cmd, self.layout, 1, dr.material);
                    bound_material = dr.material;
                }
                // Made by `ensure_aov_pipelines`.
                let pipeline = self.pipelines[&(dr.material_bits, Entry::Aov)];
                d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, pipeline);
            }
            let mut imm = dr.immediates;
            imm.normal_z.w = (dr.source.0 + 1) as f32;
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
        unsafe { d.cmd_end_rendering(cmd) };
        self.ctx.end_label(cmd);
        drawn
    }
}

/// Binds the scene's vertex streams (positions, attributes) and index buffer.
fn bind_geometry(d: &ash::Device, cmd: vk::CommandBuffer, scene: &GpuScene) {
    unsafe {
        d.cmd_bind_vertex_buffers(
            cmd,
            0,
            &[scene.positions.raw, scene.attributes.raw],
            &[0, 0],
        );
        d.cmd_bind_index_buffer(cmd, scene.indices.raw, 0, vk::IndexType::UINT32);
    }
}

/// The draws the camera can see (unless culling is off), opaque ones first and front to back
/// (nearest bounds first, so llvmpipe's early depth test rejects more hidden fragments before
/// shading; flat draws that hide nothing from the eye, such as the ground, after the others),
/// then the alpha-masked ones, then the blended ones back to front (farthest bounds centre
/// first: each is blended over everything behind it).
fn draw_order(scene: &GpuScene, cull: &CameraCull) -> Vec<usize> {
    let mut v: Vec<((AlphaDraw, bool), f32, usize)> = scene
        .draws
        .iter()
        .enumerate()
        .filter(|(_, dr)| {
            !scene.frustum_culling || !dr.world_bounds.outside_clip_volume(&cull.clip_from_world)
        })
        .map(|(i, dr)| {
            let nearest = cull.eye.0.clamp(dr.world_bounds.min, dr.world_bounds.max);
            // A ground plane's nearest point is right under the eye, but it hides nothing: drawn
            // last, its fragments behind everything else fail the early depth test.
            let hides_nothing = dr
                .world_plane
                .is_some_and(|pl| flat_hides_nothing(pl, cull.viewpoint, &scene.bounds));
            let key = (dr.alpha, hides_nothing && dr.alpha != AlphaDraw::Blended);
            let distance = match dr.alpha {
                AlphaDraw::Blended => -dr.world_bounds.center().distance_squared(cull.eye.0),
                _ => nearest.distance_squared(cull.eye.0),
            };
            (key, distance, i)
        })
        .collect();
    v.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    v.into_iter().map(|(_, _, i)| i).collect()
}

/// An opaque forward draw on a CPU device reads its uniforms as flat inputs (`fs_main_flat`)
/// when its triangles cover at least this many pixels on average (`pixels_per_triangle`): a
/// uniform read costs llvmpipe a bounds-checked load per lane for every 8 pixels
/// (shaders/lib/uniforms.wgsl), a flat input costs its triangle setup 31 vec4 inputs. At one
/// 4×4 block per triangle the setup's cost is a fraction of what it saves.
pub const FLAT_FROM_PIXELS: f32 = 16.0;

/// Locations of `FlatOut` (shaders/lib/uniforms.wgsl: the varyings and the uniforms' values).
pub const FLAT_LOCATIONS: u32 = 31;

/// Whether the device passes `FLAT_LOCATIONS` vec4 from vertex to fragment shader (lavapipe and
/// desktop GPUs take 32; Vulkan guarantees 16).
fn flat_inputs_fit(ctx: &Context) -> bool {
    let l = &ctx.properties.limits;
    FLAT_LOCATIONS * 4
        <= l.max_vertex_output_components
            .min(l.max_fragment_input_components)
}

/// What the camera pass records in one frame, decided before recording: its culling inputs, the
/// draws in order split between the G-buffer and the forward pass, and for each forward draw
/// whether it needs the shadow lookup everywhere, nowhere or in part (`receivers::split`) and
/// whether it reads its uniforms as flat inputs.
pub struct CameraFrame {
    /// The culling and variant inputs.
    pub cull: CameraCull,
    /// Draw the shadow map full-screen instead of the scene (the map debug view).
    pub shadow_map_view: bool,
    /// Draw the sky where no surface is (the lit image with `Background::Sky`).
    pub sky: bool,
    /// Deferred and forward draws.
    pub defer: DeferPlan,
    /// Per forward draw (`defer.forward`), its receiver split.
    pub splits: Vec<Split>,
    /// Per forward draw, whether it reads the uniforms as flat inputs (`FLAT_FROM_PIXELS`).
    pub flat: Vec<bool>,
}

impl CameraFrame {
    /// The entry point of a forward draw treating alpha as `alpha`, `flat`: reading the uniforms
    /// as flat inputs.
    fn entry(&self, alpha: AlphaDraw, flat: bool) -> Entry {
        if flat {
            Entry::OpaqueFlat
        } else {
            Entry::of(alpha, self.cull.debug_view)
        }
    }
}

impl CameraPass {
    /// Decides what the camera pass draws for `cull` at `extent`: the draw order, the deferred
    /// split (`deferred::plan`) and each forward draw's receiver split; `sky`: the background is
    /// the sky (not drawn with the shadow-map view).
    pub fn plan_frame(
        &self,
        scene: &GpuScene,
        cull: CameraCull,
        extent: vk::Extent2D,
        shadow_map_view: bool,
        sky: bool,
    ) -> CameraFrame {
        let order = if shadow_map_view {
            Vec::new()
        } else {
            draw_order(scene, &cull)
        };
        let defer = deferred::plan(order, &scene.draws, &cull, extent, self.deferred);
        let splits = defer
            .forward
            .iter()
            .map(|&i| {
                cull.shadow_reach.as_ref().map_or(Split::Shadowed, |r| {
                    receivers::split(r, &scene.draws[i], &cull.clip_from_world, extent)
                })
            })
            .collect();
        let flat = defer
            .forward
            .iter()
            .map(|&i| {
                let dr = &scene.draws[i];
                self.flat_forward
                    && Entry::of(dr.alpha, cull.debug_view) == Entry::Opaque
                    && pixels_per_triangle(dr, &cull.clip_from_world, extent) >= FLAT_FROM_PIXELS
            })
            .collect();
        CameraFrame {
            cull,
            shadow_map_view,
            sky: sky && !shadow_map_view,
            defer,
            splits,
            flat,
        }
    }
}

/// Draws one camera pass recorded.
#[derive(Clone, Copy, Debug)]
pub struct CameraCounts {
    /// Draws recorded (deferred ones included).
    pub drawn: usize,
    /// Of those, draws shaded deferred.
    pub deferred: usize,
    /// Of those, draws drawn wholly or in part without the shadow lookup.
    pub unshadowed: usize,
    /// Of those, forward draws reading the uniforms as flat inputs (`FLAT_FROM_PIXELS`).
    pub flat: usize,
}

/// The whole of an `extent` image, as a scissor.
fn full_rect(extent: vk::Extent2D) -> vk::Rect2D {
    vk::Rect2D {
        offset: vk::Offset2D::default(),
        extent,
    }
}

/// The attachments a camera pass draws into (already in attachment layouts), where it resolves
/// to, its size and its clear colour.
#[derive(Clone, Copy, Debug)]
pub struct CameraTargets {
    /// The colour attachment (multisampled with MSAA).
    pub color: vk::ImageView,
    /// The depth attachment (multisampled with MSAA).
    pub depth: vk::ImageView,
    /// The single-sample images MSAA resolves into.
    pub resolve: Resolve,
    /// The image size.
    pub extent: vk::Extent2D,
    /// The linear clear colour.
    pub clear: [f32; 4],
}

/// Where a multisampled camera pass resolves to (both None without MSAA).
#[derive(Clone, Copy, Debug, Default)]
pub struct Resolve {
    /// The single-sample colour image the samples are averaged into.
    pub color: Option<vk::ImageView>,
    /// The single-sample depth image sample 0 is copied into (for depth readback).
    pub depth: Option<vk::ImageView>,
}

/// The attachment formats and sample count every camera pipeline is made for.
#[derive(Clone, Copy)]
struct Formats {
    color: vk::Format,
    depth: vk::Format,
    samples: u32,
}

/// Creates the scene pipeline of shader `variant` (in `module`) with fragment entry `entry`.
fn scene_pipeline(
    ctx: &Context,
    layout: vk::PipelineLayout,
    formats: Formats,
    variant: usize,
    entry: Entry,
    module: vk::ShaderModule,
) -> Result<vk::Pipeline, GpuError> {
    let (bindings, attributes) = vertex_layout();
    let name = format!("camera pipeline variant {variant} {entry:?}");
    let resolve = entry == Entry::Resolve;
    let gbuffer = entry == Entry::GBuffer;
    let aov = entry == Entry::Aov;
    create_pipeline(
        ctx,
        &PipelineDesc {
            name: &name,
            layout,
            vertex: match entry {
                Entry::Resolve => (module, sh::ENTRY_VS_FULLSCREEN_FLAT),
                Entry::OpaqueFlat => (module, sh::ENTRY_VS_MAIN_FLAT),
                _ => (module, sh::ENTRY_VS_MAIN),
            },
            fragment: Some((
                module,
                match entry {
                    Entry::Opaque => sh::ENTRY_FS_MAIN,
                    Entry::OpaqueFlat => sh::ENTRY_FS_MAIN_FLAT,
                    Entry::Masked => sh::ENTRY_FS_MASKED,
                    Entry::Blended => sh::ENTRY_FS_BLEND,
                    Entry::Debug | Entry::Overdraw => sh::ENTRY_FS_DEBUG,
                    Entry::Resolve => sh::ENTRY_FS_RESOLVE,
                    Entry::GBuffer => sh::ENTRY_FS_GBUFFER,
                    Entry::Aov => sh::ENTRY_FS_AOV,
                },
            )),
            bindings: if resolve { &[] } else { &bindings },
            attributes: if resolve { &[] } else { &attributes },
            color_formats: if gbuffer {
                &[GBUFFER_FORMAT; GBUFFER_TARGETS]
            } else if aov {
                &AOV_FORMATS
            } else {
                std::slice::from_ref(&formats.color)
            },
            masked_targets: if gbuffer {
                deferred::gbuffer_targets_masked(variant)
            } else {
                0
            },
            depth_format: formats.depth,
            stencil: match entry {
                Entry::Resolve => Stencil::Equal,
                Entry::GBuffer => Stencil::Mark,
                _ => Stencil::Off,
            },
            depth_clamp: false,
            depth_bias: false,
            depth: if entry == Entry::Overdraw || resolve {
                Depth::Off
            } else {
                Depth::Test
            },
            blend: match entry {
                Entry::Overdraw => ColorBlend::Additive,
                Entry::Blended => ColorBlend::Over,
                _ => ColorBlend::Off,
            },
            // The AOV pass draws one sample per pixel whatever the camera pass's MSAA.
            samples: if aov { 1 } else { formats.samples },
        },
    )
}

impl Drop for CameraPass {
    fn drop(&mut self) {
        unsafe {
            let d = &self.ctx.device;
            let _ = d.device_wait_idle();
            for (_, p) in self.pipelines.drain() {
                d.destroy_pipeline(p, None);
            }
            for (_, m) in self.variant_modules.drain() {
                d.destroy_shader_module(m, None);
            }
            d.destroy_pipeline(self.map_pipeline, None);
            d.destroy_pipeline(self.sky_pipeline, None);
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

/// The (variant, scissor) of each piece a draw of variant `bits` is drawn in (`None`: the whole
/// image): the unshadowed variant where `split` says the lookup cannot shadow anything.
fn pieces(bits: usize, split: Split) -> Vec<(usize, Option<vk::Rect2D>)> {
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

#[cfg(test)]
mod tests {
    /// `FLAT_LOCATIONS` counts `FlatOut` (checked against the device's limits).
    #[test]
    fn flat_locations_match_the_shader() {
        let source = include_str!("../../../shaders/lib/uniforms.wgsl");
        let start = source
            .find("struct FlatOut {")
            .expect("FlatOut in uniforms.wgsl");
        let end = start + source[start..].find('}').expect("its end");
        let locations = source[start..end].matches("@location(").count();
        assert_eq!(locations as u32, super::FLAT_LOCATIONS);
    }
}
