//! The exact method's choice, made with the rest of the plan: whether this frame judges the
//! shown light's visibility per pixel with shadow rays (exact shadows) or marches short rays
//! beside the maps (contact shadows), and what the exact pass needs to do it.

use super::view::View;
use glam::{Mat4, Vec3};

/// How far a contact shadow ray marches, in texels of the shown light's finest shadow view, and
/// how thick (a fraction of that) a surface of the depth image is taken to be. Chosen on
/// FlightHelmet + ground, the demo and the close-up at 640×360 from 4, 8 and 16 texels and
/// thicknesses of 0.25 and 1 (16 steps): 8 and 0.25 misclassified least on two of the three
/// (`docs/exact-shadows.md`). `shaders/exact.wgsl` marches them in 8 steps.
pub const CONTACT_TEXELS: f32 = 8.0;
/// See [`CONTACT_TEXELS`].
pub const CONTACT_THICKNESS: f32 = 0.25;

/// What the exact pass decides.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ExactMode {
    /// Exact shadows: every receiver's shadow ray against the caster triangles.
    Exact,
    /// Contact shadows: each ray marched `length` (world units; per unit of distance to a light
    /// with a position) through the receivers as a depth image, surfaces `thickness` thick.
    Contact {
        /// March length.
        length: f32,
        /// Thickness of what the depth image shows.
        thickness: f32,
        /// How far a ray starts off its surface, and how far behind a surface of the depth
        /// image a step must lie to count (world units): 2·10⁻⁵ of the scene's diagonal, what
        /// the depth image's planes are trusted to.
        margin: f32,
    },
}

/// What one frame's exact pass does.
#[derive(Clone, Debug)]
pub struct ExactPlan {
    /// Exact or contact shadows.
    pub mode: ExactMode,
    /// The light's view (clip from world) the grid covers, or a point light's six cube faces
    /// (a grid each).
    pub views: Vec<Mat4>,
    /// The direction a directional light's rays travel, or a spot or point light's position.
    pub light: Vec3,
    /// A light with a position (spot, or point for contact shadows), else directional.
    pub positional: bool,
    /// The camera's clip from world.
    pub clip_from_world: Mat4,
    /// The camera's position and near-plane reach (back-face culling, as the camera pass).
    pub eye: (Vec3, f32),
    /// Draws the receivers pass draws (the camera pass's visible draws).
    pub receivers: Vec<usize>,
    /// Draws that cast.
    pub casters: Vec<usize>,
    /// Hybrid shadows ([`crate::plan::ShadowMethod::Hybrid`]): the map's verdict kept where it is certain,
    /// only the other pixels traced (one light view: directional or spot).
    pub hybrid: Option<HybridPlan>,
}

/// What the hybrid method reads of the map behind it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HybridPlan {
    /// World from the map's clip space (the inverse of `ExactPlan::views[0]`).
    pub world_from_clip: Mat4,
    /// The map's side in texels.
    pub map_size: u32,
    /// The casters' rectangle in the map (texels: x0, y0, x1, y1): nothing outside it is shadowed.
    pub rect: [f32; 4],
    /// A texel's world size (at unit distance for a spot light).
    pub texel_world: f32,
}

/// Whether `view` asks for exact shadows and a device that can run the exact pass
/// (`capable`: fragment-shader stores) draws them.
pub(crate) fn exact_asked(view: &View, capable: bool) -> bool {
    view.shadow.enabled && view.shadow.method.traces() && capable
}
