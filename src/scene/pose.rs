//! Camera poses handed in as 4×4 world-from-camera matrices (numpy poses, pose files): the
//! checks every front end makes on them, and their rigid part. One place, so that the command
//! line and the bindings refuse the same matrices with the same words.

use super::types::Camera;
use glam::{Mat3, Mat4, Vec3, Vec4};

impl Camera {
    /// The farthest from the origin a camera may stand, on any axis: the squared distances the
    /// planning and shading take stay finite in f32 (10³⁶ against a largest 3.4·10³⁸).
    pub const MAX_POSITION: f32 = 1.0e18;

    /// Whether `m` can place a camera (the camera looks down its −Z): finite, its last row
    /// 0 0 0 1, axes that span space (a singular upper 3×3 has no view direction), and a
    /// position within [`Camera::MAX_POSITION`]. The error says which, in words.
    pub fn check_pose(m: Mat4) -> Result<(), String> {
        if !m.is_finite() {
            return Err("holds a NaN or an infinity".into());
        }
        if m.row(3) != Vec4::W {
            let r = m.row(3);
            return Err(format!(
                "its last row is {} {} {} {}, expected 0 0 0 1",
                r.x, r.y, r.z, r.w
            ));
        }
        let axes = Mat3::from_mat4(m);
        let lengths = axes.x_axis.length() * axes.y_axis.length() * axes.z_axis.length();
        // Singular: a determinant that is zero beside the axes' own lengths (all zero included;
        // both are finite here).
        if axes.determinant().abs() <= 1e-6 * lengths {
            return Err("its axes are degenerate (the upper 3×3 is singular)".into());
        }
        Self::check_position(m.w_axis.truncate())
    }

    /// Whether a camera may stand at `eye`: within [`Camera::MAX_POSITION`] of the origin on
    /// every axis (finite included). The error says how far it is.
    pub fn check_position(eye: Vec3) -> Result<(), String> {
        if !eye.is_finite() {
            return Err(format!("its position {eye} is not finite"));
        }
        let far = eye.abs().max_element();
        if far > Self::MAX_POSITION {
            return Err(format!(
                "its position is {far:e} from the origin, beyond {:e}",
                Self::MAX_POSITION
            ));
        }
        Ok(())
    }

    /// The world-from-view transform of pose `m` ([`Camera::check_pose`]): its rotation and
    /// translation, its scale left out (scale in a pose would scale the view).
    pub fn rigid_pose(m: Mat4) -> Result<Mat4, String> {
        Self::check_pose(m)?;
        let (_, rotation, translation) = m.to_scale_rotation_translation();
        Ok(Mat4::from_rotation_translation(rotation, translation))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    fn rigid() -> Mat4 {
        Mat4::from_rotation_translation(Quat::from_rotation_y(0.7), Vec3::new(1.0, 2.0, 3.0))
    }

    #[test]
    fn a_rigid_pose_passes_and_scale_is_dropped() {
        let m = rigid();
        let got = Camera::rigid_pose(m).expect("a rigid pose");
        assert!(got.abs_diff_eq(m, 1e-6), "{got} vs {m}");
        let scaled = m * Mat4::from_scale(Vec3::splat(2.5));
        let got = Camera::rigid_pose(scaled).expect("a scaled pose");
        assert!(got.abs_diff_eq(m, 1e-5), "{got} vs {m}");
    }

    #[test]
    fn matrices_that_place_no_camera_are_refused_in_words() {
        let mut last_row = rigid();
        last_row.w_axis.w = 0.0;
        let mut flat = rigid();
        flat.y_axis = Vec4::ZERO;
        let mut nan = rigid();
        nan.x_axis.x = f32::NAN;
        let far = Mat4::from_translation(Vec3::new(0.0, 0.0, 2e18));
        for (m, words) in [
            (Mat4::ZERO, "last row"),
            (last_row, "last row is 0 0 0 0"),
            (flat, "degenerate"),
            (Mat4::from_scale(Vec3::new(1.0, 1.0, 0.0)), "degenerate"),
            (nan, "NaN"),
            (far, "beyond 1e18"),
        ] {
            let e = Camera::rigid_pose(m).expect_err("refused");
            assert!(e.contains(words), "{e:?} lacks {words:?}");
        }
        // Just within: 10¹⁸ on an axis.
        assert!(Camera::check_pose(Mat4::from_translation(Vec3::splat(1e18))).is_ok());
        let e = Camera::check_position(Vec3::new(0.0, f32::NAN, 0.0)).expect_err("NaN");
        assert!(e.contains("position [0, NaN, 0] is not finite"), "{e:?}");
    }
}
