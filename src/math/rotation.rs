//! Rotations about the principal axes and about an arbitrary axis (Rodrigues' formula).

use glam::{Mat3, Vec3};

/// Rotation by `angle` radians about +X (right-handed: Y turns towards Z).
pub fn rotation_x(angle: f32) -> Mat3 {
    let (s, c) = angle.sin_cos();
    Mat3::from_cols(Vec3::X, Vec3::new(0.0, c, s), Vec3::new(0.0, -s, c))
}

/// Rotation by `angle` radians about +Y (Z turns towards X).
pub fn rotation_y(angle: f32) -> Mat3 {
    let (s, c) = angle.sin_cos();
    Mat3::from_cols(Vec3::new(c, 0.0, -s), Vec3::Y, Vec3::new(s, 0.0, c))
}

/// Rotation by `angle` radians about +Z (X turns towards Y).
pub fn rotation_z(angle: f32) -> Mat3 {
    let (s, c) = angle.sin_cos();
    Mat3::from_cols(Vec3::new(c, s, 0.0), Vec3::new(-s, c, 0.0), Vec3::Z)
}

/// Rotation by `angle` radians about the unit vector `axis`, by Rodrigues' formula
/// R = cos θ I + (1 − cos θ) k kᵀ + sin θ [k]×. A zero axis gives the identity.
pub fn rodrigues(axis: Vec3, angle: f32) -> Mat3 {
    let len = axis.length();
    if len.is_nan() || len <= 0.0 || !len.is_finite() {
        return Mat3::IDENTITY;
    }
    let k = axis / len;
    let (s, c) = angle.sin_cos();
    let outer = Mat3::from_cols(k * k.x, k * k.y, k * k.z);
    let cross = Mat3::from_cols(
        Vec3::new(0.0, k.z, -k.y),
        Vec3::new(-k.z, 0.0, k.x),
        Vec3::new(k.y, -k.x, 0.0),
    );
    Mat3::IDENTITY * c + outer * (1.0 - c) + cross * s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Mat3, b: Mat3) -> bool {
        a.abs_diff_eq(b, 1e-6)
    }

    #[test]
    fn principal_axes_match_rodrigues() {
        for i in -12..=12 {
            let a = i as f32 * 0.37;
            assert!(close(rotation_x(a), rodrigues(Vec3::X, a)), "x {a}");
            assert!(close(rotation_y(a), rodrigues(Vec3::Y, a)), "y {a}");
            assert!(close(rotation_z(a), rodrigues(Vec3::Z, a)), "z {a}");
        }
    }

    #[test]
    fn right_handed_quarter_turns() {
        let q = std::f32::consts::FRAC_PI_2;
        assert!((rotation_x(q) * Vec3::Y).abs_diff_eq(Vec3::Z, 1e-6));
        assert!((rotation_y(q) * Vec3::Z).abs_diff_eq(Vec3::X, 1e-6));
        assert!((rotation_z(q) * Vec3::X).abs_diff_eq(Vec3::Y, 1e-6));
    }

    #[test]
    fn matches_glam_axis_angle_and_is_orthonormal() {
        let axis = Vec3::new(1.0, -2.0, 0.5).normalize();
        for i in 0..20 {
            let a = i as f32 * 0.3 - 3.0;
            let r = rodrigues(axis, a);
            assert!(close(r, Mat3::from_axis_angle(axis, a)));
            assert!(close(r * r.transpose(), Mat3::IDENTITY));
            assert!((r.determinant() - 1.0).abs() < 1e-5);
            // The axis is fixed.
            assert!((r * axis).abs_diff_eq(axis, 1e-6));
        }
    }

    #[test]
    fn unnormalised_and_degenerate_axes() {
        assert!(close(rodrigues(Vec3::X * 5.0, 0.4), rotation_x(0.4)));
        assert_eq!(rodrigues(Vec3::ZERO, 1.0), Mat3::IDENTITY);
        assert_eq!(rodrigues(Vec3::NAN, 1.0), Mat3::IDENTITY);
    }
}
