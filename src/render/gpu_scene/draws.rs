//! The draws of a scene: one per primitive of every instance, with its world bounds, plane,
//! alpha treatment and shadow-pass range.

use super::*;
use crate::math::ray::coordinate_magnitudes;
use crate::math::Aabb;
use crate::plan::uniforms::SceneImmediates;
use crate::scene::{AlphaMode, Scene};
use crate::shader_consts::VariantKey;
use ash::vk;
use glam::{Mat4, Vec3, Vec4};

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
    /// Its coordinates' size per axis (`math::ray::coordinate_magnitudes`): how far its
    /// surfaces' shadow rays start off them (`math::ray::ray_offset`).
    pub magnitudes: Vec3,
    /// World-space plane `(n, w)` of a flat primitive (`scene::mesh::topology::plane_of`), unit `n`.
    pub world_plane: Option<Vec4>,
    /// Draw both faces.
    pub double_sided: bool,
    /// The transform mirrors (negative determinant): its triangles wind clockwise on screen.
    pub mirrored: bool,
    /// How the material treats alpha (which camera pipeline draws it, and whether the shadow
    /// pass tests alpha).
    pub alpha: AlphaDraw,
    /// The material's shader variant bits (`material_variant_bits`).
    pub material_bits: VariantKey,
    /// The primitive is closed and consistently wound (`scene::mesh::topology::is_closed`): seen from
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
    /// to where their alpha can pass (`scene::mesh::trim`; the same shadow map, fewer fragments).
    pub shadow_range: Option<IndexRange>,
}

/// A model-space plane `(n, w)` carried into world space by `m` (None for a singular `m`).
pub(super) fn world_plane(plane: Vec4, m: &Mat4) -> Option<Vec4> {
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

/// One draw per non-empty primitive of every instance, placed relative to `origin`; the
/// triangles drawn and the world bounds.
pub(super) fn build_draws(
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
                immediates: SceneImmediates::new(world_from_model).with_instance(ii),
                magnitudes: coordinate_magnitudes(&world_bounds, &world_from_model),
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
                material_bits: mat.map_or(VariantKey::empty(), material_variant_bits),
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
