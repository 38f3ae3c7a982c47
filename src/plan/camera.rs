//! The camera's projection and the frustum shadows are fitted to.

use crate::math::projection::{
    orthographic_reversed, perspective_infinite_reversed, perspective_reversed,
};
use crate::math::shadow_fit::CameraFrustum;
use crate::math::Aabb;
use crate::scene::{Camera, Projection};
use glam::Mat4;

/// Camera projection, reversed-z: a perspective (infinite when the camera has no far plane) or
/// an orthographic one (±ymag vertically, ±ymag·`aspect` horizontally, between its near plane and
/// [`Camera::far_plane`]).
pub fn camera_projection(camera: &Camera, aspect: f32) -> Mat4 {
    match camera.projection {
        Projection::Perspective { fov_y } => match camera.far {
            Some(f) if f > camera.near => perspective_reversed(fov_y, aspect, camera.near, f),
            _ => perspective_infinite_reversed(fov_y, aspect, camera.near),
        },
        Projection::Orthographic { ymag, .. } => {
            let (h, w) = (ymag.abs(), ymag.abs() * aspect);
            let far = camera.far_plane().unwrap_or(camera.near + 1.0);
            orthographic_reversed(-w, w, -h, h, camera.near, far)
        }
    }
}

/// The frustum used to fit shadows: far = the camera's far, or the farthest scene corner.
pub fn fitting_frustum(camera: &Camera, aspect: f32, bounds: &Aabb) -> CameraFrustum {
    let eye = camera.position();
    let far_scene = bounds
        .corners()
        .iter()
        .map(|c| c.distance(eye))
        .fold(0.0f32, f32::max);
    let far = camera
        .far
        .unwrap_or(far_scene)
        .min(far_scene.max(camera.near * 2.0));
    let (tan_half, half_height) = match camera.projection {
        Projection::Perspective { fov_y } => ((fov_y * 0.5).tan(), 0.0),
        Projection::Orthographic { ymag, .. } => (0.0, ymag.abs()),
    };
    CameraFrustum {
        view_from_world: camera.view_from_world(),
        tan_half,
        half_height,
        aspect,
        near: camera.near,
        far: far.max(camera.near * 1.01),
    }
}
