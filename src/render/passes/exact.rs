//! Exact hard shadows by an irregular z-buffer ([`crate::plan::ShadowMethod::Exact`]): the
//! shadowed light's visibility at each pixel's receiver, decided by intersecting its shadow ray
//! with the caster triangles themselves, on the device (`shaders/exact.wgsl`); and contact
//! shadows ([`crate::plan::ShadowSettings::contact`]), which share its first step.
//!
//! Three steps after the shadow pass: the camera's receivers (what casts and is judged: the
//! alpha cutoff of the shadow pass) are drawn into a position and a face-normal image; a compute
//! pass makes each covered pixel a sample and links it into the list of the light-view grid cell
//! its shadow ray starts in (a grid per cube face for a point light); every caster triangle is
//! drawn into that grid grown by half a cell (a sliver as its grown box), so that each cell it
//! touches runs a fragment, and each fragment tests the cell's samples against the exact
//! triangle (and its alpha texture), unless the triangle lies wholly farther from a directional
//! light than every sample of the cell. The camera pass then reads the verdict at its pixel where
//! its fragment is that receiver, and the shadow map elsewhere (blended layers over the receiver,
//! MSAA's edge samples). The grid only sorts the work: its size changes the cost, not the answer.
//! Contact shadows replace the last two steps by a march through the receiver image.
//!
//! The images and buffers are made on first use and remade when the image size changes; they are
//! shared by the frames in flight (each frame's barriers order it after the previous one's use).

use crate::gpu::barrier::{memory_barrier, Access};
use crate::gpu::context::{Context, GpuError, VkCheck};
use crate::gpu::resources::Buffer;
use crate::gpu::shaders::{allocate_sets, create_module, exact as sh, set_layout_for};
use crate::gpu::Image;
use crate::plan::Viewpoint;
use crate::plan::{ExactMode, ExactPlan};
use crate::render::gpu_scene::{vertex_layout, GpuScene};
use crate::render::pipeline::{
    create_layout, create_pipeline, depth_clear_attachment, set_viewport, ColorBlend, Depth,
    PipelineDesc, Stencil,
};
use crate::render::targets::Attachment;
use ash::vk;
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec4};
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

/// Cells per side of the light-view grid the samples are sorted into.
/// (At 1280×720 against 1024 cells: 0.76× the pass on the close-up stand-in, 0.69× on
/// FlightHelmet close by; 32 MiB of heads and depths, cleared every frame.)
pub const GRID: u32 = 2048;

/// Cells per side of each of a point light's six cube-face grids (six of 2048² would be 192 MiB).
pub const CUBE_GRID: u32 = 1024;

/// Cells of the largest grid set: one `GRID`² or six `CUBE_GRID`².
const MAX_CELLS: u64 = {
    let one = (GRID as u64) * (GRID as u64);
    let six = 6 * (CUBE_GRID as u64) * (CUBE_GRID as u64);
    if one > six {
        one
    } else {
        six
    }
};

/// Cells per side of the grids of a frame with `views` light views.
fn grid_side(views: usize) -> u32 {
    if views > 1 {
        CUBE_GRID
    } else {
        GRID
    }
}

const POSITION_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;
const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;

/// `ExactFrame` of `shaders/exact.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ExactFrame {
    views: [Mat4; 6],
    light: Vec4,
    params: Vec4,
    camera_clip: Mat4,
    eye: Vec4,
    contact: Vec4,
    counts: Vec4,
}

/// `ExactImmediates` of `shaders/exact.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ExactImmediates {
    world_from_model: Mat4,
    extra: Mat4,
}

/// The images and buffers of one image size.
struct Targets {
    extent: vk::Extent2D,
    _position: Image,
    _normal: Image,
    _depth: Image,
    position: Attachment,
    normal: Attachment,
    depth: Attachment,
    heads: Buffer,
    next: Buffer,
    samples: Buffer,
    rays: Buffer,
}

/// The exact shadow pass.
pub struct ExactPass {
    ctx: Arc<Context>,
    set_layout: vk::DescriptorSetLayout,
    layout: vk::PipelineLayout,
    module: vk::ShaderModule,
    receiver: vk::Pipeline,
    build: vk::Pipeline,
    contact: vk::Pipeline,
    caster: vk::Pipeline,
    pool: vk::DescriptorPool,
    sets: Vec<vk::DescriptorSet>,
    uniforms: Vec<Buffer>,
    targets: Option<Targets>,
    /// A buffer the camera pass binds when no frame has run the pass (its binding must be
    /// written); shaped like an empty sample list.
    empty: Buffer,
}

impl ExactPass {
    /// The pass for `scene` (its material set layout at set 1) with `slots` frames in flight.
    pub fn new(ctx: &Arc<Context>, scene: &GpuScene, slots: usize) -> Result<Self, GpuError> {
        let stages = vk::ShaderStageFlags::VERTEX
            | vk::ShaderStageFlags::FRAGMENT
            | vk::ShaderStageFlags::COMPUTE;
        let set_layout = set_layout_for(ctx, sh::BINDINGS, 0, stages, "exact set layout")?;
        let layout = create_layout(
            ctx,
            &[set_layout, scene.material_layout],
            sh::IMMEDIATE_SIZE,
            "exact layout",
        )?;
        let module = create_module(ctx, &sh::spirv()?, "exact.wgsl")?;
        let (bindings, all) = vertex_layout();
        let attributes = [all[0], all[2], all[4], all[5]];
        let receiver = create_pipeline(
            ctx,
            &PipelineDesc {
                name: "exact receivers",
                layout,
                vertex: (module, sh::ENTRY_VS_RECEIVER),
                fragment: Some((module, sh::ENTRY_FS_RECEIVER)),
                bindings: &bindings,
                attributes: &attributes,
                color_formats: &[POSITION_FORMAT, POSITION_FORMAT],
                masked_targets: 0,
                depth_format: DEPTH_FORMAT,
                stencil: Stencil::Off,
                depth_clamp: false,
                depth_bias: false,
                depth: Depth::Test,
                blend: ColorBlend::Off,
                samples: 1,
            },
        )?;
        let caster = create_pipeline(
            ctx,
            &PipelineDesc {
                name: "exact casters",
                layout,
                vertex: (module, sh::ENTRY_VS_CASTER),
                fragment: Some((module, sh::ENTRY_FS_CASTER)),
                bindings: &[],
                attributes: &[],
                color_formats: &[],
                masked_targets: 0,
                depth_format: vk::Format::UNDEFINED,
                stencil: Stencil::Off,
                depth_clamp: false,
                depth_bias: false,
                depth: Depth::Off,
                blend: ColorBlend::Off,
                samples: 1,
            },
        )?;
        let compute = |entry, name: &str| -> Result<vk::Pipeline, GpuError> {
            let stage = vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::COMPUTE)
                .module(module)
                .name(entry);
            let info = vk::ComputePipelineCreateInfo::default()
                .stage(stage)
                .layout(layout);
            let p = unsafe {
                ctx.device
                    .create_compute_pipelines(ctx.pipeline_cache, &[info], None)
            }
            .map_err(|(_, e)| GpuError::Vk {
                call: "vkCreateComputePipelines",
                result: e,
            })?[0];
            ctx.set_name(p, name);
            Ok(p)
        };
        let build = compute(sh::ENTRY_CS_BUILD, "exact build")?;
        let contact = compute(sh::ENTRY_CS_CONTACT, "contact shadows")?;
        let (pool, sets) = allocate_sets(ctx, sh::BINDINGS, 0, set_layout, slots)?;
        let uniforms = (0..slots)
            .map(|i| {
                Buffer::new(
                    ctx,
                    &format!("exact frame {i}"),
                    std::mem::size_of::<ExactFrame>() as u64,
                    vk::BufferUsageFlags::UNIFORM_BUFFER,
                    MemoryLocation::CpuToGpu,
                )
            })
            .collect::<Result<Vec<_>, _>>()?;
        let mut empty = Buffer::new(
            ctx,
            "exact samples (none)",
            16,
            vk::BufferUsageFlags::STORAGE_BUFFER,
            MemoryLocation::CpuToGpu,
        )?;
        empty.write(0, bytemuck::cast_slice(&[0f32; 4]))?;
        Ok(Self {
            ctx: ctx.clone(),
            set_layout,
            layout,
            module,
            receiver,
            build,
            contact,
            caster,
            pool,
            sets,
            uniforms,
            targets: None,
            empty,
        })
    }

    /// The sample buffer the camera pass reads (the empty one before the first exact frame).
    pub fn samples(&self) -> vk::Buffer {
        self.targets
            .as_ref()
            .map_or(self.empty.raw, |t| t.samples.raw)
    }

    /// Makes the images and buffers for `extent` (and writes every slot's set), if not made yet.
    pub fn ensure(&mut self, scene: &GpuScene, extent: vk::Extent2D) -> Result<(), GpuError> {
        if self.targets.as_ref().is_some_and(|t| t.extent == extent) {
            return Ok(());
        }
        if let Some(old) = self.targets.take() {
            // A new image size: the frames in flight may still read the old targets and sets.
            unsafe { self.ctx.device.device_wait_idle() }.vk("vkDeviceWaitIdle")?;
            drop(old);
        }
        let ctx = &self.ctx;
        let image = |name: &str, format, usage| Image::new(ctx, name, format, extent, 1, usage);
        let color = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED;
        let position = image("exact receiver positions", POSITION_FORMAT, color)?;
        let normal = image("exact receiver normals", POSITION_FORMAT, color)?;
        let depth = image(
            "exact receiver depth",
            DEPTH_FORMAT,
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
        )?;
        let pixels = (extent.width * extent.height) as u64;
        let storage = |name: &str, size: u64| {
            Buffer::new(
                ctx,
                name,
                size,
                vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuOnly,
            )
        };
        let t = Targets {
            extent,
            position: Attachment::of(&position),
            normal: Attachment::of(&normal),
            depth: Attachment::of(&depth),
            _position: position,
            _normal: normal,
            _depth: depth,
            heads: storage("exact grid heads", 2 * MAX_CELLS * 4)?,
            next: storage("exact sample links", pixels * 4)?,
            samples: storage("exact samples", (pixels + 1) * 16)?,
            rays: storage("exact shadow rays", pixels * 16)?,
        };
        for (slot, &set) in self.sets.iter().enumerate() {
            let buffer = |b: &Buffer| {
                [vk::DescriptorBufferInfo {
                    buffer: b.raw,
                    offset: 0,
                    range: vk::WHOLE_SIZE,
                }]
            };
            let image = |view| {
                [vk::DescriptorImageInfo {
                    sampler: vk::Sampler::null(),
                    image_view: view,
                    image_layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                }]
            };
            let buffers = [
                (sh::XF, buffer(&self.uniforms[slot])),
                (sh::HEADS, buffer(&t.heads)),
                (sh::NEXT, buffer(&t.next)),
                (sh::SAMPLES, buffer(&t.samples)),
                (sh::RAYS, buffer(&t.rays)),
                (sh::POSITIONS, buffer(&scene.positions)),
                (sh::INDICES, buffer(&scene.indices)),
                (sh::ATTRIBUTES, buffer(&scene.attributes)),
            ];
            let images = [
                (sh::RECEIVER_POSITION, image(t.position.view)),
                (sh::RECEIVER_NORMAL, image(t.normal.view)),
            ];
            let mut writes: Vec<vk::WriteDescriptorSet> = buffers
                .iter()
                .map(|(b, info)| {
                    vk::WriteDescriptorSet::default()
                        .dst_set(set)
                        .dst_binding(b.binding)
                        .descriptor_type(b.descriptor_type())
                        .buffer_info(info)
                })
                .collect();
            writes.extend(images.iter().map(|(b, info)| {
                vk::WriteDescriptorSet::default()
                    .dst_set(set)
                    .dst_binding(b.binding)
                    .descriptor_type(b.descriptor_type())
                    .image_info(info)
            }));
            unsafe { ctx.device.update_descriptor_sets(&writes, &[]) };
        }
        self.targets = Some(t);
        Ok(())
    }

    /// Writes slot `slot`'s frame uniform (its previous frame must have completed).
    pub fn write_frame(&mut self, slot: usize, f: &ExactPlan) -> Result<(), GpuError> {
        let extent = self
            .targets
            .as_ref()
            .map_or(vk::Extent2D::default(), |t| t.extent);
        let (length, thickness) = match f.mode {
            ExactMode::Exact => (0.0, 0.0),
            ExactMode::Contact { length, thickness } => (length, thickness),
        };
        let u = ExactFrame {
            camera_clip: f.clip_from_world,
            eye: f.eye.0.extend(1.0),
            contact: Vec4::new(length, 0.0, thickness, 0.0),
            views: std::array::from_fn(|i| f.views.get(i).copied().unwrap_or(Mat4::ZERO)),
            counts: Vec4::new(f.views.len() as f32, 0.0, 0.0, 0.0),
            light: f.light.extend(if f.positional {
                crate::gpu::shaders::scene::LIGHT_SPOT
            } else {
                crate::gpu::shaders::scene::LIGHT_DIRECTIONAL
            }),
            params: Vec4::new(
                f.eps,
                grid_side(f.views.len()) as f32,
                extent.width as f32,
                extent.height as f32,
            ),
        };
        self.uniforms[slot].write(0, bytemuck::bytes_of(&u))
    }

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
                S::FRAGMENT_SHADER | S::COMPUTE_SHADER,
                A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE,
            ),
            (
                S::ALL_TRANSFER | S::COMPUTE_SHADER,
                A::TRANSFER_WRITE | A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE,
            ),
        );
        unsafe { d.cmd_fill_buffer(cmd, t.heads.raw, 0, vk::WHOLE_SIZE, 0) };
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
            unsafe { d.cmd_dispatch(cmd, groups.0, groups.1, 1) };
            memory_barrier(
                d,
                cmd,
                (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE),
                (S::FRAGMENT_SHADER, A::SHADER_STORAGE_READ),
            );
            self.targets = Some(t);
            return;
        }
        self.record_binning(cmd, set, groups);
        self.record_casters(cmd, set, scene, f);
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
        unsafe { d.cmd_begin_rendering(cmd, &info) };
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
            let pc = ExactImmediates {
                world_from_model: dr.world_from_model,
                extra: f.clip_from_world,
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
        unsafe { d.cmd_end_rendering(cmd) };
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
        unsafe { d.cmd_dispatch(cmd, groups.0, groups.1, 1) };
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
    /// the rays they hit), then made visible to the camera pass's fragments.
    fn record_casters(
        &self,
        cmd: vk::CommandBuffer,
        set: vk::DescriptorSet,
        scene: &GpuScene,
        f: &ExactPlan,
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
        unsafe { d.cmd_begin_rendering(cmd, &info) };
        bind(
            d,
            self.layout,
            cmd,
            (vk::PipelineBindPoint::GRAPHICS, self.caster),
            set,
        );
        set_viewport(ctx, cmd, grid);
        unsafe {
            d.cmd_set_cull_mode(cmd, vk::CullModeFlags::NONE);
            d.cmd_set_front_face(cmd, vk::FrontFace::COUNTER_CLOCKWISE);
        }
        for &i in &f.casters {
            let dr = &scene.draws[i].shadow_caster();
            scene.bind_material(d, cmd, self.layout, 1, dr.material);
            for view in 0..f.views.len() {
                let mut extra = Mat4::ZERO;
                extra.x_axis = Vec4::new(
                    f32::from_bits(dr.first_index),
                    f32::from_bits(dr.vertex_offset as u32),
                    if dr.alpha.tests_alpha_in_shadow() {
                        1.0
                    } else {
                        0.0
                    },
                    view as f32,
                );
                let pc = ExactImmediates {
                    world_from_model: dr.world_from_model,
                    extra,
                };
                unsafe {
                    d.cmd_push_constants(
                        cmd,
                        self.layout,
                        vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                        0,
                        bytemuck::bytes_of(&pc),
                    );
                    // Six vertices a triangle: the triangle grown (or its box's two halves).
                    d.cmd_draw(cmd, 2 * dr.index_count, 1, 0, 0);
                }
            }
        }
        unsafe { d.cmd_end_rendering(cmd) };
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
fn bind(
    d: &ash::Device,
    layout: vk::PipelineLayout,
    cmd: vk::CommandBuffer,
    (point, pipeline): (vk::PipelineBindPoint, vk::Pipeline),
    set: vk::DescriptorSet,
) {
    unsafe {
        d.cmd_bind_pipeline(cmd, point, pipeline);
        d.cmd_bind_descriptor_sets(cmd, point, layout, 0, &[set], &[]);
    }
}

impl Drop for ExactPass {
    fn drop(&mut self) {
        unsafe {
            let d = &self.ctx.device;
            let _ = d.device_wait_idle();
            self.targets = None;
            d.destroy_pipeline(self.receiver, None);
            d.destroy_pipeline(self.build, None);
            d.destroy_pipeline(self.contact, None);
            d.destroy_pipeline(self.caster, None);
            d.destroy_shader_module(self.module, None);
            d.destroy_pipeline_layout(self.layout, None);
            d.destroy_descriptor_pool(self.pool, None);
            d.destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}
