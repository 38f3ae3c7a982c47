//! What a frame is planned against (the scene's lights, bounds, draw boxes and planes) and for (the
//! image).

use crate::math::Aabb;
use crate::scene::Light;

/// What a frame is planned against: the scene's lights, its bounds, and each draw's world box
/// (may be empty), which bound the depths cascades are split over.
#[derive(Clone, Copy, Debug)]
pub struct PlanScene<'a> {
    /// The scene's lights (the default sun is added when there are none).
    pub lights: &'a [Light],
    /// The scene's bounds.
    pub bounds: &'a Aabb,
    /// The draws' world boxes.
    pub receivers: &'a [Aabb],
    /// The world plane `(n, w)` of each flat draw, index-aligned with `receivers` (empty or
    /// None where not known: such a draw is never skipped as a caster that hides nothing).
    pub planes: &'a [Option<glam::Vec4>],
    /// What the lights, bounds and boxes are relative to (world = given + origin); the plan's
    /// [`super::FramePlan::origin`].
    pub origin: glam::Vec3,
}

/// The image a frame is planned for.
#[derive(Clone, Copy, Debug)]
pub struct PlanTarget {
    /// Width over height.
    pub aspect: f32,
    /// The image height in pixels: the pixel footprint the automatic cascade count compares
    /// texels with.
    pub height_px: u32,
    /// The device filters depth comparisons in hardware (the shader variant's HW_COMPARE).
    pub hw_compare: bool,
    /// The device can run the exact pass (fragment-shader stores): exact and contact shadows.
    pub exact_capable: bool,
    /// Small receivers are drawn unshadowed beyond a single shadow view's reach
    /// (`SceneOptions::resolved_receiver_split`): the plan's sight carries the reach.
    pub receiver_split: bool,
}
