//! The scene's vertex and index streams: every primitive packed once, large ones split into
//! clusters, each analysed (closed? flat?) on all cores.

use super::*;
use crate::math::Aabb;
use crate::plan::settings::SceneOptions;
use crate::scene::mesh::clusters::{self, Cluster};
use crate::scene::mesh::topology::{is_closed, plane_of};
use crate::scene::Scene;
use ash::vk;
use bytemuck::{Pod, Zeroable};
use glam::Vec4;

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
pub(super) struct PrimitiveShape {
    /// Total triangle area (model space).
    pub(super) area: f32,
    pub(super) closed: bool,
    pub(super) plane: Option<Vec4>,
    pub(super) clusters: Option<(Vec<u32>, Vec<Cluster>)>,
    /// Its lone cutout cards cut to their alpha for the shadow pass (`scene::mesh::trim`).
    pub(super) trimmed: Option<crate::scene::Primitive>,
}

/// One uploaded primitive: its index range, material, model-space bounds and shape facts.
pub(super) struct PrimitiveRange {
    pub(super) first_index: u32,
    pub(super) index_count: u32,
    pub(super) vertex_offset: i32,
    pub(super) material: usize,
    pub(super) bounds: Aabb,
    /// See `Draw::closed`.
    pub(super) closed: bool,
    /// Model-space plane of a flat primitive (`scene::mesh::topology::plane_of`).
    pub(super) plane: Option<Vec4>,
    /// (first, count) in `GpuScene::clusters` (count 0: one draw).
    pub(super) clusters: (u32, u32),
    /// No vertex colour other than white (see `Draw::deferrable`).
    pub(super) white: bool,
    /// Total triangle area (model space).
    pub(super) area: f32,
    /// See `Draw::shadow_range`.
    pub(super) shadow_range: Option<IndexRange>,
}

/// The camera pass's per-vertex attributes of `p` (defaults where it lacks one).
pub(super) fn vertex_attributes(
    p: &crate::scene::Primitive,
) -> impl Iterator<Item = VertexAttributes> + '_ {
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

/// The scene's primitives packed into shared vertex and index arrays (large ones split into
/// clusters), with each primitive's range and shape.
pub(super) struct Geometry {
    pub(super) positions: Vec<[f32; 3]>,
    pub(super) attrs: Vec<VertexAttributes>,
    pub(super) indices: Vec<u32>,
    pub(super) ranges: Vec<Vec<PrimitiveRange>>,
    pub(super) clusters: Vec<Cluster>,
}

/// What the load-time analysis finds about primitive `p` of `scene`: its area, and with culling
/// on whether it is closed, its plane, its clusters and its cutout cards cut to their alpha.
fn analyse(scene: &Scene, options: &SceneOptions, p: &crate::scene::Primitive) -> PrimitiveShape {
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
                let cut = crate::scene::mesh::trim::AlphaCut::new(m, p, &scene.textures)?;
                crate::scene::mesh::trim::trim(p, &cut)
            })
            .flatten()
            .map(|t| t.primitive),
    }
}

/// Packs every mesh primitive once (instances share it), analysing each (closed? flat?
/// clusters) on all cores.
pub(super) fn pack_geometry(scene: &Scene, options: &SceneOptions) -> Geometry {
    let mut positions: Vec<[f32; 3]> = Vec::new();
    let mut attrs: Vec<VertexAttributes> = Vec::new();
    let mut indices: Vec<u32> = Vec::new();
    let mut ranges: Vec<Vec<PrimitiveRange>> = Vec::new();
    let mut all_clusters: Vec<Cluster> = Vec::new();
    // Shape analysis per primitive (closed? flat? clusters), on all cores.
    let prims: Vec<&crate::scene::Primitive> =
        scene.meshes.iter().flat_map(|m| &m.primitives).collect();
    let mut analyses = crate::parallel::map(&prims, |p| analyse(scene, options, p)).into_iter();
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
