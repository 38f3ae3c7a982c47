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

mod cull;
mod record;
mod targets;

use crate::gpu::context::{Context, GpuError};
use crate::gpu::resources::Buffer;
use crate::gpu::shaders::{
    allocate_sets, create_module, exact as sh, set_layout_for, write_buffers,
};
use crate::gpu::{Image, SharedBuffer};
use crate::plan::{ExactMode, ExactPlan};
use crate::render::gpu_scene::{vertex_layout, GpuScene};
use crate::render::pipeline::{
    create_compute_pipeline, create_layout, create_pipeline, ColorBlend, Depth, PipelineDesc,
    Stencil,
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

/// Words of the hybrid method's culling tiles: one per tile of 4² cells of a `GRID`² grid
/// (`TILE_CELLS` of `shaders/exact.wgsl`).
const TILE_WORDS: u64 = (GRID as u64 / 4).pow(2);

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
    hybrid: Vec4,
    rect: Vec4,
    world_from_map: Mat4,
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
    heads: SharedBuffer,
    next: SharedBuffer,
    samples: SharedBuffer,
    rays: SharedBuffer,
    /// Hybrid shadows: a bit per tile of cells holding a traced sample.
    tiles: SharedBuffer,
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
    /// The shadow map view each slot's set holds.
    bound_map: Vec<vk::ImageView>,
    /// Hybrid shadows' caster culling.
    culling: cull::Culling,
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
        let (receiver, caster) = graphics_pipelines(ctx, layout, module)?;
        let build =
            create_compute_pipeline(ctx, layout, module, sh::ENTRY_CS_BUILD, "exact build")?;
        let contact =
            create_compute_pipeline(ctx, layout, module, sh::ENTRY_CS_CONTACT, "contact shadows")?;
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
            bound_map: vec![vk::ImageView::null(); slots],
            culling: cull::Culling::new(ctx, set_layout, module, slots)?,
        })
    }

    /// The caster triangles slot `slot`'s frame (completed) drew into the grid, and the frame's
    /// caster triangles: all of them for exact shadows, those culling kept for hybrid ones; None
    /// for contact shadows, which draw none.
    pub fn grid_triangles(
        &mut self,
        slot: usize,
        scene: &GpuScene,
        f: &ExactPlan,
    ) -> Option<(u64, u64)> {
        if let ExactMode::Contact { .. } = f.mode {
            return None;
        }
        let all: u64 = f
            .casters
            .iter()
            .map(|&i| u64::from(scene.draws[i].shadow_caster().index_count / 3))
            .sum();
        if f.hybrid.is_none() {
            return Some((all, all));
        }
        Some((self.culling.kept_triangles(slot, f.casters.len())?, all))
    }

    /// The sample buffer the camera pass reads (the empty one before the first exact frame).
    pub fn samples(&self) -> vk::Buffer {
        self.targets
            .as_ref()
            .map_or(self.empty.raw, |t| t.samples.raw())
    }

    /// The samples as an input of the camera pass's fragments (`None` before the first exact
    /// frame).
    pub fn verdicts(&mut self) -> Option<&mut SharedBuffer> {
        self.targets.as_mut().map(|t| &mut t.samples)
    }

    /// Grows the hybrid method's culling buffers to `f`'s casters (rewriting every slot's
    /// bindings when they are made anew).
    pub fn ensure_culling(&mut self, scene: &GpuScene, f: &ExactPlan) -> Result<(), GpuError> {
        if self.culling.ensure(scene, f)? {
            for &set in &self.sets {
                write_buffers(&self.ctx.device, set, &self.culling.bindings());
            }
        }
        Ok(())
    }

    /// Points slot `slot`'s set at the shadow map `map` (a depth array view; its previous frame
    /// must have completed). Hybrid shadows read layer 0; the binding is written for every frame.
    pub fn bind_map(&mut self, slot: usize, map: vk::ImageView) {
        if self.bound_map[slot] == map || self.targets.is_none() {
            return;
        }
        let info = [vk::DescriptorImageInfo {
            sampler: vk::Sampler::null(),
            image_view: map,
            image_layout: vk::ImageLayout::DEPTH_READ_ONLY_OPTIMAL,
        }];
        let write = sh::SHADOW_MAP.write(self.sets[slot]).image_info(&info);
        unsafe { self.ctx.device.update_descriptor_sets(&[write], &[]) };
        self.bound_map[slot] = map;
    }

    /// Writes slot `slot`'s frame uniform (its previous frame must have completed).
    pub fn write_frame(&mut self, slot: usize, f: &ExactPlan) -> Result<(), GpuError> {
        let extent = self
            .targets
            .as_ref()
            .map_or(vk::Extent2D::default(), |t| t.extent);
        let (length, thickness, margin) = match f.mode {
            ExactMode::Exact => (0.0, 0.0, 0.0),
            ExactMode::Contact {
                length,
                thickness,
                margin,
            } => (length, thickness, margin),
        };
        let h = f.hybrid.as_ref();
        let u = ExactFrame {
            hybrid: h.map_or(Vec4::ZERO, |h| {
                Vec4::new(1.0, h.map_size as f32, h.texel_world, 0.0)
            }),
            rect: h.map_or(Vec4::ZERO, |h| Vec4::from_array(h.rect)),
            world_from_map: h.map_or(Mat4::IDENTITY, |h| h.world_from_clip),
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
                margin,
                grid_side(f.views.len()) as f32,
                extent.width as f32,
                extent.height as f32,
            ),
        };
        self.uniforms[slot].write(0, bytemuck::bytes_of(&u))
    }
}

/// The first column of a caster draw's `ExactImmediates::extra` (`shaders/exact.wgsl`): first
/// index, vertex offset (bit-cast), 1 when its alpha is tested, the view (cube face).
fn caster_column(dr: &crate::render::gpu_scene::Draw, view: usize) -> Vec4 {
    Vec4::new(
        f32::from_bits(dr.first_index),
        f32::from_bits(dr.vertex_offset as u32),
        if dr.alpha.tests_alpha_in_shadow() {
            1.0
        } else {
            0.0
        },
        view as f32,
    )
}

/// The receivers' pipeline (world positions and normals into two targets, depth-tested) and the
/// casters' (no attachments: their fragments test and mark the grid).
fn graphics_pipelines(
    ctx: &Context,
    layout: vk::PipelineLayout,
    module: vk::ShaderModule,
) -> Result<(vk::Pipeline, vk::Pipeline), GpuError> {
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
    Ok((receiver, caster))
}

impl Drop for ExactPass {
    fn drop(&mut self) {
        unsafe {
            let d = &self.ctx.device;
            let _ = d.device_wait_idle();
            self.targets = None;
            d.destroy_shader_module(self.module, None);
            d.destroy_pipeline_layout(self.layout, None);
            d.destroy_descriptor_pool(self.pool, None);
            d.destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}
