//! Hybrid shadows' caster culling: before the casters are drawn into the grid, a compute pass
//! keeps, per caster draw, the triangles whose light-view box meets a tile of cells holding a
//! traced sample (`cs_cull` in `shaders/exact.wgsl`), and writes the draw's indirect arguments;
//! the caster pass then draws only those. On llvmpipe, which runs vertex work on one thread,
//! the triangles never pulled are the saving.

use super::{caster_column, record::bind, ExactImmediates};
use crate::gpu::context::{Context, GpuError, VkCheck};
use crate::gpu::resources::Buffer;
use crate::gpu::shaders::exact as sh;
use crate::gpu::{BufferAccess, Recorder, SharedBuffer, Uses};
use crate::plan::ExactPlan;
use crate::render::gpu_scene::GpuScene;
use crate::render::pipeline::create_compute_pipeline;
use ash::vk;
use glam::{Mat4, Vec4};
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

/// Invocations of a `cs_cull` workgroup.
const GROUP: u32 = 64;

/// The culling pipeline and its buffers (grown, never shrunk).
pub(super) struct Culling {
    ctx: Arc<Context>,
    /// Set 0 as the pass's, immediates visible to the compute stage.
    layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
    /// `cs_thin`: the thin-caster mask, before binning.
    thin_pipeline: vk::Pipeline,
    /// The thin-caster mask: a bit per map texel.
    pub thin: SharedBuffer,
    thin_capacity: u64,
    /// Kept triangle indices, a slot per caster triangle of the frame.
    pub kept: SharedBuffer,
    /// Indirect draw arguments, 16 bytes per caster draw.
    pub args: SharedBuffer,
    /// Per frame in flight, the arguments copied back to the host (the triangles kept:
    /// [`Culling::kept_triangles`]).
    readback: Vec<SharedBuffer>,
    kept_capacity: u64,
    args_capacity: u64,
}

impl Culling {
    /// The pipeline over `module` with the pass's set layout, and small buffers.
    pub fn new(
        ctx: &Arc<Context>,
        set_layout: vk::DescriptorSetLayout,
        module: vk::ShaderModule,
        slots: usize,
    ) -> Result<Self, GpuError> {
        let ranges = [vk::PushConstantRange {
            stage_flags: vk::ShaderStageFlags::COMPUTE,
            offset: 0,
            size: sh::IMMEDIATE_SIZE,
        }];
        let sets = [set_layout];
        let layout =
            crate::gpu::shaders::create_pipeline_layout(ctx, &sets, &ranges, "hybrid cull layout")?;
        let pipeline =
            create_compute_pipeline(ctx, layout, module, sh::ENTRY_CS_CULL, "hybrid cull")?;
        let thin_pipeline = create_compute_pipeline(
            ctx,
            layout,
            module,
            sh::ENTRY_CS_THIN,
            "hybrid thin casters",
        )?;
        let (kept, args) = buffers(ctx, 1024, 64)?;
        Ok(Self {
            ctx: ctx.clone(),
            layout,
            pipeline,
            thin_pipeline,
            thin: thin_buffer(ctx, 1)?,
            thin_capacity: 1,
            kept,
            args,
            readback: readback_buffers(ctx, 64, slots)?,
            kept_capacity: 1024,
            args_capacity: 64,
        })
    }

    /// Grows the buffers to hold `f`'s casters; true when they were made anew (every set's
    /// bindings must then be written again; the device was idled first).
    pub fn ensure(&mut self, scene: &GpuScene, f: &ExactPlan) -> Result<bool, GpuError> {
        let triangles: u64 = f
            .casters
            .iter()
            .map(|&i| u64::from(scene.draws[i].shadow_caster().index_count / 3))
            .sum();
        let draws = f.casters.len() as u64;
        let tiles = f
            .hybrid
            .map_or(1, |h| u64::from(h.map_size).pow(2).div_ceil(32));
        if triangles <= self.kept_capacity
            && draws <= self.args_capacity
            && tiles <= self.thin_capacity
        {
            return Ok(false);
        }
        unsafe { self.ctx.device.device_wait_idle() }.vk("vkDeviceWaitIdle")?;
        if tiles > self.thin_capacity {
            self.thin = thin_buffer(&self.ctx, tiles)?;
            self.thin_capacity = tiles;
        }
        let kept_capacity = triangles.next_power_of_two().max(self.kept_capacity);
        let args_capacity = draws.next_power_of_two().max(self.args_capacity);
        (self.kept, self.args) = buffers(&self.ctx, kept_capacity, args_capacity)?;
        if args_capacity > self.args_capacity {
            self.readback = readback_buffers(&self.ctx, args_capacity, self.readback.len())?;
        }
        self.kept_capacity = kept_capacity;
        self.args_capacity = args_capacity;
        Ok(true)
    }

    /// The bindings of the culling buffers, for a set write.
    pub fn bindings(&self) -> [(&'static crate::gpu::shaders::ReflectedBinding, vk::Buffer); 4] {
        [
            (&sh::THIN, self.thin.raw()),
            (&sh::KEPT, self.kept.raw()),
            (&sh::DRAW_ARGS, self.args.raw()),
            (&sh::KEPT_READ, self.kept.raw()),
        ]
    }

    /// The fills' uses: the indirect arguments and the thin-caster mask, zeroed by
    /// [`Culling::clear`] before the frame's first compute step.
    pub fn fills<'a>(&'a mut self, uses: Uses<'a>) -> Uses<'a> {
        uses.writes_buffer(&mut self.args, BufferAccess::TransferWrite)
            .writes_buffer(&mut self.thin, BufferAccess::TransferWrite)
    }

    /// Zeroes the indirect arguments and the thin-caster mask (after [`Culling::fills`]).
    pub fn clear(&self, cmd: vk::CommandBuffer) {
        let r = Recorder::new(&self.ctx.device, cmd);
        r.fill_buffer(self.args.raw(), 0, vk::WHOLE_SIZE, 0);
        r.fill_buffer(self.thin.raw(), 0, vk::WHOLE_SIZE, 0);
    }

    /// Marks the thin-caster mask under `f`'s thin and alpha-tested caster triangles (after the
    /// mask is cleared, before binning reads it).
    pub fn record_thin(
        &mut self,
        cmd: vk::CommandBuffer,
        set: vk::DescriptorSet,
        scene: &GpuScene,
        f: &ExactPlan,
    ) {
        Uses::new()
            .writes_buffer(&mut self.thin, BufferAccess::ComputeWrite)
            .enter(&self.ctx.device, cmd);
        self.dispatch_casters(cmd, set, scene, f, self.thin_pipeline);
    }

    /// Culls each caster draw of `f` against the `tiles` binning marked, then copies the
    /// arguments back for the host (slot `slot`: [`Culling::kept_triangles`]). Returns each
    /// draw's first kept slot, in `f.casters`' order.
    pub fn record(
        &mut self,
        cmd: vk::CommandBuffer,
        set: vk::DescriptorSet,
        scene: &GpuScene,
        (f, tiles): (&ExactPlan, &mut SharedBuffer),
        slot: usize,
    ) -> Vec<u32> {
        let d = &self.ctx.device;
        Uses::new()
            .reads_buffer(tiles, BufferAccess::ComputeRead)
            .writes_buffer(&mut self.args, BufferAccess::ComputeWrite)
            .writes_buffer(&mut self.kept, BufferAccess::ComputeWrite)
            .enter(d, cmd);
        let first = self.dispatch_casters(cmd, set, scene, f, self.pipeline);
        let back = &mut self.readback[slot];
        Uses::new()
            .reads_buffer(&mut self.args, BufferAccess::TransferRead)
            .writes_buffer(back, BufferAccess::TransferWrite)
            .enter(d, cmd);
        let region = vk::BufferCopy::default().size(16 * f.casters.len().max(1) as u64);
        Recorder::new(d, cmd).copy_buffer(self.args.raw(), back.raw(), &[region]);
        Uses::new()
            .reads_buffer(back, BufferAccess::HostRead)
            .enter(d, cmd);
        first
    }

    /// The caster pass's uses: the arguments of its indirect draws and the kept triangles its
    /// vertex shader reads.
    pub fn caster_inputs<'a>(&'a mut self, uses: Uses<'a>) -> Uses<'a> {
        uses.reads_buffer(&mut self.args, BufferAccess::Indirect)
            .reads_buffer(&mut self.kept, BufferAccess::VertexRead)
    }

    /// The caster triangles slot `slot`'s culling kept for `draws` caster draws (its frame
    /// completed): six vertices each in the indirect arguments.
    pub fn kept_triangles(&mut self, slot: usize, draws: usize) -> Option<u64> {
        let bytes = self.readback.get_mut(slot)?.buffer.mapped()?;
        let words: &[u32] = bytemuck::try_cast_slice(bytes.get(..16 * draws)?).ok()?;
        Some(words.chunks_exact(4).map(|a| u64::from(a[0] / 6)).sum())
    }

    /// Dispatches `pipeline` over each caster draw's triangles (a thread each), the draw's
    /// immediates as the caster pass's plus its slot; returns each draw's first kept slot.
    fn dispatch_casters(
        &self,
        cmd: vk::CommandBuffer,
        set: vk::DescriptorSet,
        scene: &GpuScene,
        f: &ExactPlan,
        pipeline: vk::Pipeline,
    ) -> Vec<u32> {
        let d = &self.ctx.device;
        bind(
            d,
            self.layout,
            cmd,
            (vk::PipelineBindPoint::COMPUTE, pipeline),
            set,
        );
        let mut first = Vec::with_capacity(f.casters.len());
        let mut at = 0u32;
        for (slot, &i) in f.casters.iter().enumerate() {
            let dr = &scene.draws[i].shadow_caster();
            let triangles = dr.index_count / 3;
            first.push(at);
            let mut extra = Mat4::ZERO;
            extra.x_axis = caster_column(dr, 0);
            extra.y_axis = Vec4::new(
                f32::from_bits(at),
                f32::from_bits(slot as u32),
                f32::from_bits(triangles),
                0.0,
            );
            let pc = ExactImmediates {
                world_from_model: dr.world_from_model,
                extra,
            };
            let r = Recorder::new(d, cmd);
            r.push_constants(
                self.layout,
                vk::ShaderStageFlags::COMPUTE,
                0,
                bytemuck::bytes_of(&pc),
            );
            // At least one group: its first invocation writes the instance count.
            r.dispatch(triangles.div_ceil(GROUP).max(1), 1, 1);
            at += triangles;
        }
        first
    }
}

/// Buffers for `triangles` kept slots and `draws` argument records.
fn buffers(
    ctx: &Arc<Context>,
    triangles: u64,
    draws: u64,
) -> Result<(SharedBuffer, SharedBuffer), GpuError> {
    let usage = vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST;
    let kept = Buffer::new(
        ctx,
        "hybrid kept triangles",
        triangles * 4,
        usage,
        MemoryLocation::GpuOnly,
    )?;
    let args = Buffer::new(
        ctx,
        "hybrid caster draws",
        draws * 16,
        usage | vk::BufferUsageFlags::INDIRECT_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC,
        MemoryLocation::GpuOnly,
    )?;
    Ok((SharedBuffer::new(kept), SharedBuffer::new(args)))
}

/// Host-readable copies of `draws` argument records, one per frame in flight.
fn readback_buffers(
    ctx: &Arc<Context>,
    draws: u64,
    slots: usize,
) -> Result<Vec<SharedBuffer>, GpuError> {
    (0..slots)
        .map(|i| {
            Buffer::new(
                ctx,
                &format!("hybrid caster draws, read back {i}"),
                draws * 16,
                vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuToCpu,
            )
            .map(SharedBuffer::new)
        })
        .collect()
}

/// The thin-caster mask of `tiles` words.
fn thin_buffer(ctx: &Arc<Context>, tiles: u64) -> Result<SharedBuffer, GpuError> {
    Buffer::new(
        ctx,
        "hybrid thin casters",
        tiles * 4,
        vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
        MemoryLocation::GpuOnly,
    )
    .map(SharedBuffer::new)
}

impl Drop for Culling {
    fn drop(&mut self) {
        unsafe {
            let d = &self.ctx.device;
            let _ = d.device_wait_idle();
            d.destroy_pipeline_layout(self.layout, None);
        }
    }
}
