//! A scene uploaded to the GPU: one position stream (shared by the shadow pass), one attribute
//! stream, one index buffer, textures with mipmaps, and a descriptor set per material.

use super::samplers::SamplerCache;
use crate::gpu::context::{Context, GpuError, VkCheck};
use crate::gpu::shaders::{allocate_sets, scene as sh, set_layout};
use crate::gpu::{Buffer, Image};
use crate::math::mips::mip_chain;
use crate::math::Aabb;
use crate::plan::settings::SceneOptions;
use crate::plan::uniforms::{MaterialUniform, SceneImmediates};
use crate::plan::Viewpoint;
use crate::scene::clusters::{self, Cluster};
use crate::scene::topology::{is_closed, plane_of};
use crate::scene::{AlphaMode, Material, Scene, TextureRef, BLEND_SHADOW_CUTOFF};
use ash::vk;
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3, Vec4};
use gpu_allocator::MemoryLocation;
use std::collections::HashMap;
use std::sync::Arc;

/// Non-position vertex attributes, interleaved (locations 1–3 of the camera pass).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct VertexAttributes {
    /// Object-space normal.
    pub normal: [f32; 3],
    /// TEXCOORD_0.
    pub uv: [f32; 2],
    /// Tangent with bitangent sign in w.
    pub tangent: [f32; 4],
    /// COLOR_0, linear RGBA as 16-bit unorm (white without one).
    pub color: [u16; 4],
    /// TEXCOORD_1 (TEXCOORD_0 without one).
    pub uv1: [f32; 2],
}

/// The texture-transform rows of a material's four slots (identity for an empty slot).
fn uv_rows(slots: [Option<crate::scene::TextureRef>; 4]) -> [Vec4; 8] {
    let mut rows = [Vec4::ZERO; 8];
    for (i, t) in slots.iter().enumerate() {
        let (r0, r1) = t.map(|t| t.transform).unwrap_or_default().rows();
        // w: the TEXCOORD set the slot reads.
        rows[2 * i] = r0.extend(t.map_or(0.0, |t| t.tex_coord as f32));
        rows[2 * i + 1] = r1.extend(0.0);
    }
    rows
}

/// The metallic-roughness slot of material `m` with its occlusion texture folded into the red
/// channel (glTF's ORM layout; the loader keeps an occlusion texture only where its sampler and
/// transform are the metallic-roughness texture's and its size too): the reference to sample, and
/// the (metallic-roughness, occlusion) image pair to merge when they are different images.
fn orm_slot(
    m: &crate::scene::Material,
    textures: usize,
) -> (
    Option<crate::scene::TextureRef>,
    Option<(Option<usize>, usize)>,
) {
    let mr = m
        .metallic_roughness_texture
        .filter(|t| t.texture < textures);
    match (mr, m.occlusion_texture.filter(|t| t.texture < textures)) {
        (mr, None) => (mr, None),
        (Some(mr), Some(o)) if mr.texture == o.texture => (Some(mr), None),
        (mr, Some(o)) => (
            Some(mr.unwrap_or(o)),
            Some((mr.map(|t| t.texture), o.texture)),
        ),
    }
}

/// An RGBA image with the red channel of `occlusion` and the green and blue channels of
/// `metallic_roughness` (white without one; the loader guarantees equal sizes).
fn packed_occlusion(
    occlusion: &crate::scene::Texture,
    metallic_roughness: Option<&crate::scene::Texture>,
) -> crate::scene::Texture {
    let mut rgba = match metallic_roughness {
        Some(t) if t.width == occlusion.width && t.height == occlusion.height => t.rgba.clone(),
        _ => vec![255; occlusion.rgba.len()],
    };
    for (d, s) in rgba.chunks_exact_mut(4).zip(occlusion.rgba.chunks_exact(4)) {
        d[0] = s[0];
    }
    crate::scene::Texture {
        name: format!("{} (occlusion packed)", occlusion.name),
        width: occlusion.width,
        height: occlusion.height,
        rgba,
    }
}

/// A texture the materials use: an image in a colour space (sRGB: true), or an occlusion image
/// packed with a metallic-roughness one (`packed_occlusion`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum TextureJob {
    Image(usize, bool),
    Packed((Option<usize>, usize)),
}

/// The textures material `m` samples in its four slots (base colour and emissive in sRGB;
/// normal, metallic-roughness with occlusion packed in), None where a slot is empty (the shader
/// reads `DEFAULT_TEXTURES` there); `textures`: how many the scene has.
fn texture_jobs(m: &crate::scene::Material, textures: usize) -> [Option<TextureJob>; 4] {
    let (orm_ref, orm_merged) = orm_slot(m, textures);
    let image = |t: Option<crate::scene::TextureRef>, srgb| {
        t.filter(|t| t.texture < textures)
            .map(|t| TextureJob::Image(t.texture, srgb))
    };
    [
        image(m.base_color_texture, true),
        image(m.normal_texture, false),
        orm_merged
            .map(TextureJob::Packed)
            .or_else(|| image(orm_ref, false)),
        image(m.emissive_texture, true),
    ]
}

/// Per slot of `texture_jobs`, the default texture an empty slot reads (index into the defaults:
/// white sRGB, white linear, flat normal): white for colours and factors, a flat normal.
const DEFAULT_TEXTURES: [usize; 4] = [0, 2, 1, 0];

/// The vertex streams: positions (binding 0; the shadow pass reads only this one) and the
/// interleaved attributes (binding 1): locations 0 position, 1 normal, 2 uv, 3 tangent.
pub fn vertex_layout() -> (
    [vk::VertexInputBindingDescription; 2],
    [vk::VertexInputAttributeDescription; 6],
) {
    let f = |location, binding, format, offset| vk::VertexInputAttributeDescription {
        location,
        binding,
        format,
        offset,
    };
    (
        [
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
        ],
        [
            f(0, 0, vk::Format::R32G32B32_SFLOAT, 0),
            f(1, 1, vk::Format::R32G32B32_SFLOAT, 0),
            f(2, 1, vk::Format::R32G32_SFLOAT, 12),
            f(3, 1, vk::Format::R32G32B32A32_SFLOAT, 20),
            f(4, 1, vk::Format::R16G16B16A16_UNORM, 36),
            f(5, 1, vk::Format::R32G32_SFLOAT, 44),
        ],
    )
}

/// What the load-time analysis found about a primitive's shape.
struct PrimitiveShape {
    /// Total triangle area (model space).
    area: f32,
    closed: bool,
    plane: Option<Vec4>,
    clusters: Option<(Vec<u32>, Vec<Cluster>)>,
    /// Its lone cutout cards cut to their alpha for the shadow pass (`scene::trim`).
    trimmed: Option<crate::scene::Primitive>,
}

/// One uploaded primitive: its index range, material, model-space bounds and shape facts.
struct PrimitiveRange {
    first_index: u32,
    index_count: u32,
    vertex_offset: i32,
    material: usize,
    bounds: Aabb,
    /// See `Draw::closed`.
    closed: bool,
    /// Model-space plane of a flat primitive (`scene::topology::plane_of`).
    plane: Option<Vec4>,
    /// (first, count) in `GpuScene::clusters` (count 0: one draw).
    clusters: (u32, u32),
    /// No vertex colour other than white (see `Draw::deferrable`).
    white: bool,
    /// Total triangle area (model space).
    area: f32,
    /// See `Draw::shadow_range`.
    shadow_range: Option<IndexRange>,
}

/// An index range of the shared buffers: first index, index count, vertex offset.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IndexRange {
    /// First index in the index buffer.
    pub first_index: u32,
    /// Index count.
    pub index_count: u32,
    /// Added to each index.
    pub vertex_offset: i32,
}

/// How a draw's material treats alpha.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum AlphaDraw {
    /// Alpha ignored: the opaque pipeline (no discard), depth-only casters.
    Opaque,
    /// Discard below the cutoff (camera and shadow pass).
    Masked,
    /// Blended over what lies behind, after the others, back to front; casts where alpha ≥
    /// `BLEND_SHADOW_CUTOFF`.
    Blended,
}

impl AlphaDraw {
    /// Whether the shadow pass tests the draw's alpha (the masked depth pipeline).
    pub fn tests_alpha_in_shadow(self) -> bool {
        self != AlphaDraw::Opaque
    }
}

/// One indexed draw (a primitive of an instance).
#[derive(Clone, Copy, Debug)]
pub struct Draw {
    /// First index in the index buffer.
    pub first_index: u32,
    /// Index count.
    pub index_count: u32,
    /// Added to each index.
    pub vertex_offset: i32,
    /// Material index (= descriptor set index).
    pub material: usize,
    /// The scene instance and the primitive of its mesh this draws.
    pub source: (usize, usize),
    /// Model → world.
    pub world_from_model: Mat4,
    /// World → model (for cluster culling in model space).
    pub model_from_world: Mat4,
    /// (first, count) of the primitive's clusters in `GpuScene::clusters` (count 0: none).
    pub clusters: (u32, u32),
    /// Camera-pass immediates (transform and normal matrix), computed once at upload.
    pub immediates: SceneImmediates,
    /// World-space bounds (for culling).
    pub world_bounds: Aabb,
    /// World-space plane `(n, w)` of a flat primitive (`scene::topology::plane_of`), unit `n`.
    pub world_plane: Option<Vec4>,
    /// Draw both faces.
    pub double_sided: bool,
    /// The transform mirrors (negative determinant): its triangles wind clockwise on screen.
    pub mirrored: bool,
    /// How the material treats alpha (which camera pipeline draws it, and whether the shadow
    /// pass tests alpha).
    pub alpha: AlphaDraw,
    /// The material's shader variant bits (`material_variant_bits`).
    pub material_bits: usize,
    /// The primitive is closed and consistently wound (`scene::topology::is_closed`): seen from
    /// outside its bounds, culling back faces changes no pixel even if it is double-sided.
    pub closed: bool,
    /// The camera pass may shade it deferred (`CameraPass`): opaque, no vertex colour other than
    /// white, and every texture of its material reads TEXCOORD_0 (what the G-buffer holds).
    pub deferrable: bool,
    /// Mean triangle area in world units (model area scaled by the transform's area scale,
    /// |det|^⅔: exact for uniform scales).
    pub mean_area: f32,
    /// It can move between frames (`Scene::moving_instances`): animated, or skinned or morphed.
    /// The shadow cache draws such casters every frame.
    pub moving: bool,
    /// What the shadow pass draws instead for an alpha-tested caster whose lone cards were cut
    /// to where their alpha can pass (`scene::trim`; the same shadow map, fewer fragments).
    pub shadow_range: Option<IndexRange>,
}

/// A model-space plane `(n, w)` carried into world space by `m` (None for a singular `m`).
fn world_plane(plane: Vec4, m: &Mat4) -> Option<Vec4> {
    let n = plane.truncate();
    let point = m.transform_point3(n * -plane.w);
    let normal_matrix = glam::Mat3::from_mat4(*m).inverse().transpose();
    let wn = (normal_matrix * n).try_normalize()?;
    wn.is_finite().then(|| wn.extend(-wn.dot(point)))
}

impl Draw {
    /// The draw the shadow passes make of it: the range of its cards cut to their alpha
    /// (`shadow_range`) where it has one, drawn whole (no cluster skipping).
    pub fn shadow_caster(&self) -> Draw {
        match self.shadow_range {
            Some(r) if self.alpha.tests_alpha_in_shadow() => Draw {
                first_index: r.first_index,
                index_count: r.index_count,
                vertex_offset: r.vertex_offset,
                clusters: (0, 0),
                ..*self
            },
            _ => *self,
        }
    }

    /// Cull mode for a pass seen from `eye` = (position, near-plane reach), None for a
    /// directional light (outside everything). Single-sided materials cull back faces;
    /// double-sided ones draw (and cast from) both faces, unless the primitive is closed and the
    /// eye, with its near plane, is outside its bounds: there back faces are hidden behind front
    /// faces anyway, and culling them saves half the rasterisation.
    pub fn cull_mode(&self, eye: Option<(Vec3, f32)>) -> vk::CullModeFlags {
        let outside = eye.is_none_or(|(e, reach)| !self.world_bounds.contains(e, reach));
        if !self.double_sided || (self.closed && outside) {
            vk::CullModeFlags::BACK
        } else {
            vk::CullModeFlags::NONE
        }
    }

    /// Front face for both passes: counter-clockwise, or clockwise under a mirroring transform
    /// (negative scale), so culling and the shader's `front_facing` keep their meaning.
    pub fn front_face(&self) -> vk::FrontFace {
        if self.mirrored {
            vk::FrontFace::CLOCKWISE
        } else {
            vk::FrontFace::COUNTER_CLOCKWISE
        }
    }
}

/// Whether every texture of `m` reads TEXCOORD_0.
fn reads_texcoord0_only(m: &crate::scene::Material) -> bool {
    [
        m.base_color_texture,
        m.normal_texture,
        m.metallic_roughness_texture,
        m.emissive_texture,
        m.occlusion_texture,
    ]
    .iter()
    .flatten()
    .all(|t| t.tex_coord == 0)
}

/// The scene shader's variant bits for a material: which texture slots it fills (the shader
/// leaves out the fetch of an empty slot, whose default texture is white, a factor of 1, so the
/// result is the same) and whether it is normal-mapped.
pub fn material_variant_bits(m: &crate::scene::Material) -> usize {
    use crate::gpu::shaders::scene as sh;
    let mut bits = 0;
    for (filled, bit) in [
        (m.base_color_texture.is_some(), sh::BIT_HAS_BASE_TEX),
        (m.normal_texture.is_some(), sh::BIT_HAS_NORMAL_MAP),
        (
            m.metallic_roughness_texture.is_some()
                || m.emissive_texture.is_some()
                || m.occlusion_texture.is_some(),
            sh::BIT_HAS_OTHER_TEX,
        ),
    ] {
        if filled {
            bits |= bit;
        }
    }
    bits
}

/// The camera pass's per-vertex attributes of `p` (defaults where it lacks one).
fn vertex_attributes(p: &crate::scene::Primitive) -> impl Iterator<Item = VertexAttributes> + '_ {
    (0..p.positions.len()).map(move |i| VertexAttributes {
        normal: p
            .normals
            .get(i)
            .copied()
            .unwrap_or(glam::Vec3::Y)
            .to_array(),
        uv: p.uvs.get(i).copied().unwrap_or_default().to_array(),
        tangent: p
            .tangents
            .get(i)
            .copied()
            .unwrap_or(Vec4::new(1.0, 0.0, 0.0, 1.0))
            .to_array(),
        color: p
            .color(i)
            .to_array()
            .map(|c| (c.clamp(0.0, 1.0) * 65535.0).round() as u16),
        uv1: p.uv1(i).to_array(),
    })
}

/// One draw per non-empty primitive of every instance, placed relative to `origin`; the
/// triangles drawn and the world bounds.
fn build_draws(
    scene: &Scene,
    ranges: &[Vec<PrimitiveRange>],
    origin: glam::Vec3,
    moving: &[bool],
) -> (Vec<Draw>, usize, Aabb) {
    let mut draws = Vec::new();
    let mut triangles = 0;
    let mut bounds = Aabb::EMPTY;
    for (ii, inst) in scene.instances.iter().enumerate() {
        let world_from_model = crate::scene::rebased(inst.world_from_model, origin);
        for (pi, r) in ranges[inst.mesh].iter().enumerate() {
            let (index_count, material) = (r.index_count, r.material);
            let world_bounds = r.bounds.transformed(&world_from_model);
            bounds = bounds.union(&world_bounds);
            if index_count == 0 {
                continue;
            }
            let mat = scene.materials.get(material);
            triangles += index_count as usize / 3;
            draws.push(Draw {
                first_index: r.first_index,
                index_count,
                vertex_offset: r.vertex_offset,
                material,
                source: (ii, pi),
                world_from_model,
                model_from_world: world_from_model.inverse(),
                clusters: r.clusters,
                immediates: SceneImmediates::new(world_from_model),
                world_bounds,
                world_plane: r.plane.and_then(|pl| world_plane(pl, &world_from_model)),
                double_sided: mat.is_some_and(|m| m.double_sided),
                mirrored: glam::Mat3::from_mat4(world_from_model).determinant() < 0.0,
                closed: r.closed,
                alpha: match mat.map(|m| m.alpha_mode) {
                    Some(AlphaMode::Mask(_)) => AlphaDraw::Masked,
                    Some(AlphaMode::Blend) => AlphaDraw::Blended,
                    _ => AlphaDraw::Opaque,
                },
                material_bits: mat.map_or(0, material_variant_bits),
                mean_area: r.area
                    * glam::Mat3::from_mat4(world_from_model)
                        .determinant()
                        .abs()
                        .powf(2.0 / 3.0)
                    / (index_count / 3).max(1) as f32,
                deferrable: r.white
                    && mat.is_none_or(|m| {
                        m.alpha_mode == AlphaMode::Opaque && reads_texcoord0_only(m)
                    }),
                moving: moving.get(ii).copied().unwrap_or(false),
                shadow_range: r.shadow_range,
            });
        }
    }
    (draws, triangles, bounds)
}

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
    /// Clusters of the large primitives (`scene::clusters`), indexed by `Draw::clusters`.
    pub clusters: Vec<Cluster>,
    /// Triangles drawn per frame.
    pub triangles: usize,
    /// Whether draws outside the camera's view are skipped (`SceneOptions::culling`).
    pub frustum_culling: bool,
    /// The distinct (material variant bits, alpha treatment) pairs of the draws: the camera
    /// pipelines the scene needs per frame variant.
    pub pipeline_keys: Vec<(usize, AlphaDraw)>,
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
    /// Binds `material`'s descriptor set as set `set` of `layout`.
    pub fn bind_material(
        &self,
        d: &ash::Device,
        cmd: vk::CommandBuffer,
        layout: vk::PipelineLayout,
        set: u32,
        material: usize,
    ) {
        unsafe {
            d.cmd_bind_descriptor_sets(
                cmd,
                vk::PipelineBindPoint::GRAPHICS,
                layout,
                set,
                &[self.material_sets[material]],
                &[],
            )
        };
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
        unsafe {
            device.cmd_set_cull_mode(cmd, cull);
            device.cmd_set_front_face(cmd, dr.front_face());
            device.cmd_push_constants(
                cmd,
                layout,
                vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                0,
                immediates,
            );
        }
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
        let draw = |first: u32, n: u32| unsafe {
            device.cmd_draw_indexed(cmd, n, 1, dr.first_index + first, dr.vertex_offset, 0)
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
    /// (a pose keeps the topology).
    pub fn update_pose(&mut self, scene: &Scene) -> Result<(), GpuError> {
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
        self.draws = draws;
        self.triangles = triangles;
        self.bounds = bounds;
        Ok(())
    }

    /// Uploads `scene`.
    pub fn new(
        ctx: &Arc<Context>,
        scene: &Scene,
        options: &SceneOptions,
        origin: glam::Vec3,
    ) -> Result<Self, GpuError> {
        let anisotropy = options.resolved_anisotropy(ctx);
        let Geometry {
            positions,
            attrs,
            indices,
            ranges,
            clusters: all_clusters,
        } = pack_geometry(scene, options);
        let moving = scene.moving_instances();
        let (draws, triangles, bounds) = build_draws(scene, &ranges, origin, &moving);
        let mut pipeline_keys: Vec<(usize, AlphaDraw)> =
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

        let (textures, tex_index, defaults) = upload_textures(ctx, scene, options)?;

        let material_layout = set_layout(ctx, sh::BINDINGS, 1, "material set layout")?;
        let (pool, sets) =
            allocate_sets(ctx, sh::BINDINGS, 1, material_layout, scene.materials.len())?;
        let mut samplers = SamplerCache::new(ctx, anisotropy);

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
            let views = TextureViews {
                scene_textures: scene.textures.len(),
                textures: &textures,
                index: &tex_index,
                defaults,
            };
            write_material_set(ctx, sets[i], &buf, m, &views, &mut samplers)?;
            material_buffers.push(buf);
        }
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

/// The scene's primitives packed into shared vertex and index arrays (large ones split into
/// clusters), with each primitive's range and shape.
struct Geometry {
    positions: Vec<[f32; 3]>,
    attrs: Vec<VertexAttributes>,
    indices: Vec<u32>,
    ranges: Vec<Vec<PrimitiveRange>>,
    clusters: Vec<Cluster>,
}

/// Packs every mesh primitive once (instances share it), analysing each (closed? flat?
/// clusters) on all cores.
fn pack_geometry(scene: &Scene, options: &SceneOptions) -> Geometry {
    let mut positions: Vec<[f32; 3]> = Vec::new();
    let mut attrs: Vec<VertexAttributes> = Vec::new();
    let mut indices: Vec<u32> = Vec::new();
    let mut ranges: Vec<Vec<PrimitiveRange>> = Vec::new();
    let mut all_clusters: Vec<Cluster> = Vec::new();
    // Shape analysis per primitive (closed? flat? clusters), on all cores.
    let prims: Vec<&crate::scene::Primitive> =
        scene.meshes.iter().flat_map(|m| &m.primitives).collect();
    let mut analyses = crate::parallel::map(&prims, |p| {
        let double_sided = scene
            .materials
            .get(p.material)
            .is_some_and(|m| m.double_sided);
        PrimitiveShape {
            area: p
                .indices
                .chunks_exact(3)
                .map(|t| {
                    let v = |k: usize| p.positions.get(t[k] as usize).copied().unwrap_or_default();
                    0.5 * (v(1) - v(0)).cross(v(2) - v(0)).length()
                })
                .sum(),
            // Only double-sided materials can use it; skip the check for the others.
            closed: options.culling && double_sided && is_closed(&p.positions, &p.indices),
            plane: options
                .culling
                .then(|| plane_of(&p.positions, &p.indices))
                .flatten(),
            clusters: options
                .culling
                .then(|| clusters::build(&p.positions, &p.indices))
                .flatten(),
            // Work that cannot change the image, as culling is.
            trimmed: options
                .culling
                .then(|| {
                    let m = scene.materials.get(p.material)?;
                    let cut = crate::scene::trim::AlphaCut::new(m, p, &scene.textures)?;
                    crate::scene::trim::trim(p, &cut)
                })
                .flatten()
                .map(|t| t.primitive),
        }
    })
    .into_iter();
    for mesh in &scene.meshes {
        let mut r = Vec::new();
        for p in &mesh.primitives {
            let shape = analyses.next().expect("one analysis per primitive");
            let first = indices.len() as u32;
            let base = positions.len() as i32;
            positions.extend(p.positions.iter().map(|v| v.to_array()));
            attrs.extend(vertex_attributes(p));
            // Large primitives are split into clusters (their indices reordered cluster by
            // cluster) so that clusters facing away can be skipped.
            let cluster_start = all_clusters.len() as u32;
            match shape.clusters {
                Some((reordered, cl)) => {
                    indices.extend_from_slice(&reordered);
                    all_clusters.extend(cl);
                }
                None => indices.extend_from_slice(&p.indices),
            }
            let cluster_range = (cluster_start, all_clusters.len() as u32 - cluster_start);
            let index_count = indices.len() as u32 - first;
            // The cut cards share the primitive's vertices: only the new ones (numbered from
            // its vertex count on) are uploaded, right after it, so its indices hold as they are.
            let shadow_range = shape.trimmed.map(|t| {
                let n = p.positions.len();
                debug_assert_eq!(positions.len(), base as usize + n);
                let range = IndexRange {
                    first_index: indices.len() as u32,
                    index_count: t.indices.len() as u32,
                    vertex_offset: base,
                };
                positions.extend(t.positions[n..].iter().map(|v| v.to_array()));
                attrs.extend(vertex_attributes(&t).skip(n));
                indices.extend_from_slice(&t.indices);
                range
            });
            r.push(PrimitiveRange {
                clusters: cluster_range,
                first_index: first,
                index_count,
                vertex_offset: base,
                material: p.material.min(scene.materials.len().saturating_sub(1)),
                bounds: p.bounds(),
                closed: shape.closed,
                plane: shape.plane,
                white: p
                    .colors
                    .iter()
                    .all(|c| c.clamp(Vec4::ZERO, Vec4::ONE) == Vec4::ONE),
                area: shape.area,
                shadow_range,
            });
        }
        ranges.push(r);
    }
    Geometry {
        positions,
        attrs,
        indices,
        ranges,
        clusters: all_clusters,
    }
}

/// Uploads the textures the materials use: one per (image, colour space), one per packed
/// (metallic-roughness, occlusion) pair, then the three defaults (white sRGB, white linear, flat
/// normal) from the returned index on.
fn upload_textures(
    ctx: &Arc<Context>,
    scene: &Scene,
    options: &SceneOptions,
) -> Result<Uploaded, GpuError> {
    // Textures, created per (image, colour space) actually used, and per packed
    // (metallic-roughness, occlusion) pair; their mip chains computed on all cores first.
    let mut jobs: Vec<TextureJob> = scene
        .materials
        .iter()
        .flat_map(|m| texture_jobs(m, scene.textures.len()))
        .flatten()
        .collect();
    let mut seen = std::collections::HashSet::new();
    jobs.retain(|j| seen.insert(*j));
    // Mip chains computed here (`SceneOptions::cpu_mips`: by default on CPU devices), a few
    // textures at a time on all cores (a 2048² chain is 21 MiB, dropped once uploaded), or
    // blitted on the device.
    let cpu_mips = options.resolved_cpu_mips(ctx);
    let batch = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut textures: Vec<Image> = Vec::new();
    let mut tex_index: HashMap<TextureJob, usize> = HashMap::new();
    for part in jobs.chunks(batch.max(1)) {
        let done = crate::parallel::map(part, |j| {
            let t = match *j {
                TextureJob::Image(i, _) => std::borrow::Cow::Borrowed(&scene.textures[i]),
                TextureJob::Packed((mr, o)) => std::borrow::Cow::Owned(packed_occlusion(
                    &scene.textures[o],
                    mr.map(|i| &scene.textures[i]),
                )),
            };
            let srgb = matches!(j, TextureJob::Image(_, true));
            let chain = cpu_mips.then(|| mip_chain(t.width, t.height, &t.rgba, srgb));
            (t, chain, srgb)
        });
        for (j, (t, chain, srgb)) in part.iter().zip(done) {
            textures.push(match chain {
                Some(c) => Image::texture_mips(ctx, &t.name, &c, srgb)?,
                None => Image::texture_rgba8(ctx, &t.name, t.width, t.height, &t.rgba, srgb)?,
            });
            tex_index.insert(*j, textures.len() - 1);
        }
    }
    let white_srgb = Image::texture_rgba8(ctx, "default white sRGB", 1, 1, &[255; 4], true)?;
    let white_linear = Image::texture_rgba8(ctx, "default white", 1, 1, &[255; 4], false)?;
    let flat_normal = Image::texture_rgba8(
        ctx,
        "default flat normal",
        1,
        1,
        &[128, 128, 255, 255],
        false,
    )?;
    let defaults = textures.len();
    textures.extend([white_srgb, white_linear, flat_normal]);
    Ok((textures, tex_index, defaults))
}

/// What `upload_textures` made: the images, the image of each texture job, and the index of the
/// first default texture.
type Uploaded = (Vec<Image>, HashMap<TextureJob, usize>, usize);

/// Material `m`'s uniform block; `orm_ref` is the texture its metallic-roughness slot reads.
fn material_uniform(m: &Material, orm_ref: Option<TextureRef>) -> MaterialUniform {
    MaterialUniform {
        base_color: m.base_color,
        emissive: m.emissive.extend(m.normal_scale),
        params: Vec4::new(
            m.metallic,
            m.roughness,
            if m.occlusion_texture.is_some() {
                m.occlusion_strength
            } else {
                0.0
            },
            m.unlit as u32 as f32,
        ),
        extra: match m.alpha_mode {
            AlphaMode::Mask(c) => Vec4::new(c.max(1e-6), c.max(1e-6), 0.0, 0.0),
            AlphaMode::Blend => Vec4::new(0.0, BLEND_SHADOW_CUTOFF, 0.0, 0.0),
            AlphaMode::Opaque => Vec4::ZERO,
        },
        uv: uv_rows([
            m.base_color_texture,
            m.normal_texture,
            orm_ref,
            m.emissive_texture,
        ]),
    }
}

/// The uploaded textures, where each texture job landed, where the defaults start, and the
/// scene's texture count (which texture references are valid).
struct TextureViews<'a> {
    scene_textures: usize,
    textures: &'a [Image],
    index: &'a HashMap<TextureJob, usize>,
    defaults: usize,
}

/// Writes material `m`'s descriptor set: its uniform buffer `buf`, its four textures (a default
/// where a slot is empty) and their samplers.
fn write_material_set(
    ctx: &Arc<Context>,
    set: vk::DescriptorSet,
    buf: &Buffer,
    m: &Material,
    views: &TextureViews,
    samplers: &mut SamplerCache,
) -> Result<(), GpuError> {
    let (orm_ref, _) = orm_slot(m, views.scene_textures);
    let jobs = texture_jobs(m, views.scene_textures);
    let [base, normal, mr, emissive]: [vk::ImageView; 4] = std::array::from_fn(|k| {
        views.textures[jobs[k].map_or(views.defaults + DEFAULT_TEXTURES[k], |j| views.index[&j])]
            .view
    });
    let buf_info = [vk::DescriptorBufferInfo {
        buffer: buf.raw,
        offset: 0,
        range: vk::WHOLE_SIZE,
    }];
    let img = |v| {
        [vk::DescriptorImageInfo {
            sampler: vk::Sampler::null(),
            image_view: v,
            image_layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
        }]
    };
    let (i_base, i_normal, i_mr, i_em) = (img(base), img(normal), img(mr), img(emissive));
    let mut samp = |t: Option<TextureRef>| -> Result<_, GpuError> {
        Ok([vk::DescriptorImageInfo {
            sampler: samplers.get(t.map(|t| t.sampler).unwrap_or_default())?,
            image_view: vk::ImageView::null(),
            image_layout: vk::ImageLayout::UNDEFINED,
        }])
    };
    let s_base = samp(m.base_color_texture)?;
    let s_normal = samp(m.normal_texture)?;
    let s_mr = samp(orm_ref)?;
    let s_em = samp(m.emissive_texture)?;
    let w = |b: &crate::gpu::shaders::ReflectedBinding| {
        vk::WriteDescriptorSet::default()
            .dst_set(set)
            .dst_binding(b.binding)
            .descriptor_type(b.descriptor_type())
    };
    let writes = [
        w(&sh::MATERIAL_BLOCK).buffer_info(&buf_info),
        w(&sh::BASE_COLOR_TEX).image_info(&i_base),
        w(&sh::NORMAL_TEX).image_info(&i_normal),
        w(&sh::METAL_ROUGH_TEX).image_info(&i_mr),
        w(&sh::EMISSIVE_TEX).image_info(&i_em),
        w(&sh::BASE_COLOR_SAMPLER).image_info(&s_base),
        w(&sh::NORMAL_SAMPLER).image_info(&s_normal),
        w(&sh::METAL_ROUGH_SAMPLER).image_info(&s_mr),
        w(&sh::EMISSIVE_SAMPLER).image_info(&s_em),
    ];
    unsafe { ctx.device.update_descriptor_sets(&writes, &[]) };
    Ok(())
}
