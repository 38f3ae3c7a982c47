//! A scene uploaded to the GPU: one position stream (shared by the shadow pass), one attribute
//! stream, one index buffer, textures with mipmaps, and a descriptor set per material.
//!
//! `geometry` packs the vertex and index streams, `draws` makes the per-instance draws,
//! `textures` uploads the textures, `materials` writes each material's set.

mod draws;
mod geometry;
mod materials;
mod textures;

pub use draws::{AlphaDraw, Draw, IndexRange};
pub use geometry::{vertex_layout, VertexAttributes};
pub use materials::material_variant_bits;
pub use textures::TextureStats;

use crate::gpu::Recorder;
use crate::shader_consts::VariantKey;
use draws::build_draws;
use geometry::{pack_geometry, vertex_attributes, Geometry, PrimitiveRange};
use materials::{
    material_uniform, orm_slot, reads_texcoord0_only, write_material_set, TextureViews,
};
use textures::upload_textures;

use crate::gpu::context::{Context, GpuError, VkCheck};
use crate::gpu::shaders::{allocate_sets, scene as sh, set_layout};
use crate::gpu::{Buffer, Image};
use crate::math::Aabb;
use crate::plan::settings::SceneOptions;
use crate::plan::uniforms::MaterialUniform;
use crate::plan::Viewpoint;
use crate::render::samplers::SamplerCache;
use crate::scene::mesh::clusters::{self, Cluster};
use crate::scene::Scene;
use ash::vk;
use glam::Vec3;
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

/// The GPU copy of a scene.
pub struct GpuScene {
    ctx: Arc<Context>,
    /// Positions (vec3 f32), binding 0 of both passes.
    pub positions: Buffer,
    /// Attributes, binding 1 of the camera pass.
    pub attributes: Buffer,
    /// u32 indices.
    pub indices: Buffer,
    /// Draws.
    pub draws: Vec<Draw>,
    /// Descriptor set layout of group 1 (material).
    pub material_layout: vk::DescriptorSetLayout,
    /// One set per material.
    pub material_sets: Vec<vk::DescriptorSet>,
    /// World bounds.
    pub bounds: Aabb,
    /// Clusters of the large primitives (`scene::mesh::clusters`), indexed by `Draw::clusters`.
    pub clusters: Vec<Cluster>,
    /// Triangles drawn per frame.
    pub triangles: usize,
    /// Whether draws outside the camera's view are skipped (`SceneOptions::culling`).
    pub frustum_culling: bool,
    /// What the textures take on the device.
    pub texture_stats: TextureStats,
    /// The distinct (material variant bits, alpha treatment) pairs of the draws: the camera
    /// pipelines the scene needs per frame variant.
    pub pipeline_keys: Vec<(VariantKey, AlphaDraw)>,
    /// Per mesh, per primitive: where its vertices and indices are.
    ranges: Vec<Vec<PrimitiveRange>>,
    /// What the draws' world coordinates are relative to.
    origin: glam::Vec3,
    /// Per instance: whether it can move between poses (`Scene::moving_instances`, fixed by
    /// the rig).
    moving: Vec<bool>,
    pool: vk::DescriptorPool,
    /// Destroyed after the pool (fields drop after `Drop::drop`).
    _samplers: SamplerCache,
    _material_buffers: Vec<Buffer>,
    _textures: Vec<Image>,
}

impl GpuScene {
    /// What the plan reads of the draws (`plan::PlanScene`): each one's world box and, where it
    /// is flat, its world plane, index-aligned with `draws`.
    pub fn plan_inputs(&self) -> (Vec<crate::math::Aabb>, Vec<Option<glam::Vec4>>) {
        let bounds = self.draws.iter().map(|d| d.world_bounds).collect();
        let planes = self.draws.iter().map(|d| d.world_plane).collect();
        (bounds, planes)
    }

    /// Binds the scene's vertex streams (positions, attributes) and index buffer: what the camera,
    /// AOV and exact passes draw from.
    pub fn bind_geometry(&self, d: &ash::Device, cmd: vk::CommandBuffer) {
        Recorder::new(d, cmd).bind_vertex_buffers(
            0,
            &[self.positions.raw, self.attributes.raw],
            &[0, 0],
        );
        Recorder::new(d, cmd).bind_index_buffer(self.indices.raw, 0, vk::IndexType::UINT32);
    }

    /// Binds `material`'s descriptor set as set `set` of `layout`.
    pub fn bind_material(
        &self,
        d: &ash::Device,
        cmd: vk::CommandBuffer,
        layout: vk::PipelineLayout,
        set: u32,
        material: usize,
    ) {
        Recorder::new(d, cmd).bind_descriptor_sets(
            vk::PipelineBindPoint::GRAPHICS,
            layout,
            set,
            &[self.material_sets[material]],
            &[],
        )
    }

    /// Records draw `dr` of a pass seen from `eye` (`Draw::cull_mode`): its cull mode and front
    /// face, the pass's `immediates` (pushed to both stages of `layout`), and its triangles.
    pub fn record_draw(
        &self,
        cmd: vk::CommandBuffer,
        layout: vk::PipelineLayout,
        dr: &Draw,
        eye: Option<(Vec3, f32)>,
        from: Viewpoint,
        immediates: &[u8],
    ) {
        let cull = dr.cull_mode(eye);
        let device = &self.ctx.device;
        Recorder::new(device, cmd).set_cull_mode(cull);
        Recorder::new(device, cmd).set_front_face(dr.front_face());
        Recorder::new(device, cmd).push_constants(
            layout,
            vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
            0,
            immediates,
        );
        self.draw_indexed(device, cmd, dr, cull, from);
    }

    /// Records `dr` drawn with `cull`: with back faces culled, clusters whose faces all point away
    /// from `from` are left out (tested in model space, where a mirroring transform's flipped
    /// winding is undone by `Draw::front_face`), and runs of the rest are drawn.
    fn draw_indexed(
        &self,
        device: &ash::Device,
        cmd: vk::CommandBuffer,
        dr: &Draw,
        cull: vk::CullModeFlags,
        from: Viewpoint,
    ) {
        let (start, count) = dr.clusters;
        let draw = |first: u32, n: u32| {
            Recorder::new(device, cmd).draw_indexed(
                n,
                1,
                dr.first_index + first,
                dr.vertex_offset,
                0,
            )
        };
        if count == 0 || cull != vk::CullModeFlags::BACK {
            return draw(0, dr.index_count);
        }
        let cl = &self.clusters[start as usize..(start + count) as usize];
        let runs = match from {
            Viewpoint::Eye(e) => {
                let e = dr.model_from_world.transform_point3(e);
                clusters::visible_runs(cl, |c| c.back_facing_from(e))
            }
            Viewpoint::Along(d) => {
                let d = dr.model_from_world.transform_vector3(d);
                clusters::visible_runs(cl, |c| c.back_facing_along(d))
            }
        };
        for (first, n) in runs {
            draw(first, n);
        }
    }

    /// Takes a new pose of the scene it was made from (the same meshes, instances and
    /// materials; positions, normals, tangents and transforms changed by
    /// `Scene::apply_pose`): rewrites the deformed primitives' vertices and every draw's
    /// transform and bounds. Waits for the device first. Deformed primitives lose their cluster
    /// and flat-caster culling, which were computed for another shape; closed-mesh culling stays
    /// (a pose keeps the topology). Returns whether a draw that is not `moving` (one the shadow
    /// cache keeps) changed its transform.
    pub fn update_pose(&mut self, scene: &Scene) -> Result<bool, GpuError> {
        unsafe { self.ctx.device.device_wait_idle() }.vk("vkDeviceWaitIdle")?;
        let attr_size = std::mem::size_of::<VertexAttributes>();
        for (mesh, ranges) in scene.meshes.iter().zip(&mut self.ranges) {
            for (p, r) in mesh.primitives.iter().zip(ranges.iter_mut()) {
                if p.deform.is_none() {
                    continue;
                }
                let base = r.vertex_offset as usize;
                let pos: Vec<[f32; 3]> = p.positions.iter().map(|v| v.to_array()).collect();
                self.positions
                    .write(base * 12, bytemuck::cast_slice(&pos))?;
                let attrs: Vec<VertexAttributes> = vertex_attributes(p).collect();
                self.attributes
                    .write(base * attr_size, bytemuck::cast_slice(&attrs))?;
                // Cluster cones and a flat caster's plane belong to the shape they were
                // computed from; closedness is topology, which a pose does not change (culling
                // back faces of a closed mesh assumes it does not pass through itself, posed or
                // not).
                r.bounds = p.bounds();
                r.clusters.1 = 0;
                r.plane = None;
                r.shadow_range = None;
            }
        }
        let (draws, triangles, bounds) =
            build_draws(scene, &self.ranges, self.origin, &self.moving);
        let still_moved = draws.len() != self.draws.len()
            || draws.iter().zip(&self.draws).any(|(a, b)| {
                !a.moving && bytemuck::bytes_of(&a.immediates) != bytemuck::bytes_of(&b.immediates)
            });
        self.draws = draws;
        self.triangles = triangles;
        self.bounds = bounds;
        Ok(still_moved)
    }

    /// Uploads `scene`.
    pub fn new(
        ctx: &Arc<Context>,
        scene: &Scene,
        options: &SceneOptions,
        origin: glam::Vec3,
    ) -> Result<Self, GpuError> {
        let anisotropy = options.resolved_anisotropy(&crate::render::device_facts(ctx));
        let Geometry {
            positions,
            attrs,
            indices,
            ranges,
            clusters: all_clusters,
        } = pack_geometry(scene, options);
        let moving = scene.moving_instances();
        let (draws, triangles, bounds) = build_draws(scene, &ranges, origin, &moving);
        let mut pipeline_keys: Vec<(VariantKey, AlphaDraw)> =
            draws.iter().map(|d| (d.material_bits, d.alpha)).collect();
        pipeline_keys.sort_unstable();
        pipeline_keys.dedup();
        // Storage too: the exact shadow pass pulls caster triangles from them.
        let vb = vk::BufferUsageFlags::VERTEX_BUFFER | vk::BufferUsageFlags::STORAGE_BUFFER;
        // A scene that deforms rewrites its vertices each pose (`update_pose`): host-visible.
        let vertex_buffer = |name: &str, data: &[u8]| {
            if scene.deforms() {
                let mut b =
                    Buffer::new(ctx, name, data.len() as u64, vb, MemoryLocation::CpuToGpu)?;
                b.write(0, data)?;
                Ok(b)
            } else {
                Buffer::device_local_with_data(ctx, name, vb, data)
            }
        };
        let pos_buf = vertex_buffer("positions", bytemuck::cast_slice(&positions))?;
        let attr_buf = vertex_buffer("attributes", bytemuck::cast_slice(&attrs))?;
        let idx_buf = Buffer::device_local_with_data(
            ctx,
            "indices",
            vk::BufferUsageFlags::INDEX_BUFFER | vk::BufferUsageFlags::STORAGE_BUFFER,
            bytemuck::cast_slice(&indices),
        )?;

        let (textures, tex_index, defaults, texture_stats) = upload_textures(ctx, scene, options)?;

        let material_layout = set_layout(ctx, sh::BINDINGS, 1, "material set layout")?;
        let (pool, sets) =
            allocate_sets(ctx, sh::BINDINGS, 1, material_layout, scene.materials.len())?;
        let mut samplers = SamplerCache::new(ctx, anisotropy);

        let views = TextureViews {
            scene_textures: scene.textures.len(),
            textures: &textures,
            index: &tex_index,
            defaults,
        };
        let material_buffers = write_materials(ctx, scene, &sets, &views, &mut samplers)?;
        Ok(Self {
            ctx: ctx.clone(),
            positions: pos_buf,
            attributes: attr_buf,
            indices: idx_buf,
            draws,
            material_layout,
            material_sets: sets,
            bounds,
            clusters: all_clusters,
            triangles,
            frustum_culling: options.culling,
            texture_stats,
            pipeline_keys,
            ranges,
            origin,
            moving,
            pool,
            _samplers: samplers,
            _material_buffers: material_buffers,
            _textures: textures,
        })
    }
}

/// Each material's uniform buffer, written with its descriptor set (`sets[i]` for material i).
fn write_materials(
    ctx: &Arc<Context>,
    scene: &Scene,
    sets: &[vk::DescriptorSet],
    views: &TextureViews,
    samplers: &mut SamplerCache,
) -> Result<Vec<Buffer>, GpuError> {
    let mut material_buffers = Vec::new();
    for (i, m) in scene.materials.iter().enumerate() {
        let (orm_ref, _) = orm_slot(m, scene.textures.len());
        let u = material_uniform(m, orm_ref);
        let mut buf = Buffer::new(
            ctx,
            &format!("material {i} '{}'", m.name),
            std::mem::size_of::<MaterialUniform>() as u64,
            vk::BufferUsageFlags::UNIFORM_BUFFER,
            MemoryLocation::CpuToGpu,
        )?;
        buf.write(0, bytemuck::bytes_of(&u))?;
        write_material_set(ctx, sets[i], &buf, m, views, samplers)?;
        material_buffers.push(buf);
    }
    Ok(material_buffers)
}

impl Drop for GpuScene {
    fn drop(&mut self) {
        unsafe {
            let d = &self.ctx.device;
            let _ = d.device_wait_idle();
            d.destroy_descriptor_pool(self.pool, None);
            d.destroy_descriptor_set_layout(self.material_layout, None);
        }
    }
}
