//! What the camera culls with, planned with the frame (`frame::finish` makes it): its eye and near-plane reach (back-face
//! culling), what its faces are seen from (clusters and flat draws), and where the frame's single
//! shadow view can shadow anything (small receivers are drawn unshadowed beyond it).

use super::casters::Viewpoint;
use super::reach::ShadowReach;
use glam::Vec3;

/// The camera's culling inputs for one frame.
#[derive(Clone, Debug)]
pub struct Sight {
    /// Eye position and the distance from it to the near plane's farthest corner.
    pub eye: (Vec3, f32),
    /// What faces are seen from: the eye (perspective) or the viewing direction (orthographic),
    /// for skipping clusters that face away and flat draws that hide nothing.
    pub viewpoint: Viewpoint,
    /// Where the frame's single shadow view can shadow anything, when small receivers are
    /// drawn unshadowed beyond it (`render::passes::receivers`).
    pub shadow_reach: Option<ShadowReach>,
}
