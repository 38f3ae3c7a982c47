//! The camera's projection and the frustum shadows are fitted to.

use crate::math::projection::{perspective_infinite_reversed, perspective_reversed};
use crate::math::shadow_fit::CameraFrustum;
use crate::math::Aabb;
use crate::scene::Camera;
use glam::Mat4;

/// Camera projection (reversed-z; infinite when the camera has no far plane).
pub fn camera_projection(camera: &Camera, aspect: f32) -> Mat4 {
    match camera.far {
        Some(f) if f > camera.near => perspective_reversed(camera.fov_y, aspect, camera.near, f),
        _ => perspective_infinite_reversed(camera.fov_y, aspect, camera.near),
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
    CameraFrustum {
        view_from_world: camera.view_from_world(),
        fov_y: camera.fov_y,
        aspect,
        near: camera.near,
        far: far.max(camera.near * 1.01),
    }
}
