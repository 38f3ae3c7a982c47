//! What the shadow pass draws for one view: its casters, the texels they touch, and the
//! viewpoint their faces are tested against.

use crate::math::Aabb;
use glam::{Vec3, Vec4};

/// What a draw's faces are tested against when clusters are skipped.
#[derive(Clone, Copy, Debug)]
pub enum Viewpoint {
    /// A perspective eye (camera, spot light) at this world position.
    Eye(Vec3),
    /// An orthographic view (directional light) looking along this world direction.
    Along(Vec3),
}

/// True when a flat primitive on `plane` (`(n, w)`, unit `n`) hides nothing from `from`: the
/// viewpoint and the whole scene (bounds `scene`) lie on one closed side of the plane, and a
/// segment from a point to the viewpoint never leaves that side (a half-space is convex), so it
/// never meets the primitive except at its own end. Seen from a light, such a caster shadows
/// nothing (the shadow pass skips a ground plane with nothing under it, the largest caster of most
/// scenes); seen from the camera, it occludes nothing (the camera pass draws it after the rest, so
/// the early depth test rejects its hidden fragments). Scene parts within 1e-5 of the scene's
/// diagonal behind the plane still count as in front (a model resting on the ground), a choice
/// that can only matter for geometry sunk that little and seen from beneath the plane.
pub fn flat_hides_nothing(plane: Vec4, from: Viewpoint, scene: &Aabb) -> bool {
    let n = plane.truncate();
    let light_side = match from {
        Viewpoint::Along(d) => -n.dot(d.normalize_or_zero()),
        Viewpoint::Eye(p) => n.dot(p) + plane.w,
    };
    // Edge-on to the light, or the light on the plane: keep it (cheap, and no sign to trust).
    if light_side.abs() <= 1e-6 || !light_side.is_finite() {
        return false;
    }
    let s = light_side.signum();
    let tolerance = 1e-5 * scene.diagonal();
    scene
        .corners()
        .iter()
        .all(|c| s * (n.dot(*c) + plane.w) >= -tolerance)
}

/// A rectangle of a shadow-map layer, in texels: its corner and size.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TexelRect {
    /// First column.
    pub x: u32,
    /// First row.
    pub y: u32,
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
}

/// The casters one frame draws into the shadow map, and the texels they can touch.
#[derive(Clone, Debug)]
pub struct CasterPlan {
    /// Indices into `GpuScene::draws`.
    pub draws: Vec<usize>,
    /// The texels the pass clears and draws (the casters' rectangle grown by twice the lookup
    /// reach, so every texel a lookup inside `lookup` reads is written this frame).
    pub area: TexelRect,
    /// Texel rectangle `(x0, y0, x1, y1)` outside which a lookup's footprint meets no caster
    /// texel (the casters' rectangle grown by the reach): such lookups are lit without a read.
    pub lookup: Vec4,
    /// The view's light (clusters facing away from it are not drawn).
    pub light: Viewpoint,
    /// Side in texels of the view's square (at its layer's origin).
    pub size: u32,
}

impl Default for CasterPlan {
    /// No casters: one texel cleared, every lookup lit.
    fn default() -> Self {
        Self {
            draws: Vec::new(),
            area: TexelRect {
                x: 0,
                y: 0,
                width: 1,
                height: 1,
            },
            lookup: Vec4::new(1.0, 1.0, -1.0, -1.0),
            light: Viewpoint::Along(Vec3::NEG_Y),
            size: 1,
        }
    }
}
