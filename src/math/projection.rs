//! Reversed-z projections (near → depth 1, far or infinity → depth 0), right-handed view space
//! looking down −Z, Y up in clip space. The Y flip to Vulkan's framebuffer happens in the shaders
//! (naga's `ADJUST_COORDINATE_SPACE`, see `build.rs`), so matrices here are the usual Y-up ones.
//!
//! The finite perspective is built the textbook way, as `ortho · persp_to_ortho`: the perspective
//! frustum is first squashed into a box by `persp_to_ortho` (A = n + f, B = −n·f, with n and f the
//! *signed* z of the planes), then mapped to clip space by an orthographic projection whose depth is
//! reversed.

use glam::{Mat4, Vec4};

/// The matrix that squashes the frustum between the planes z = `n` and z = `f` (signed view-space
/// z, both negative) into the box with the near plane's x/y extent: a point (x, y, z) goes to
/// (n x / z, n y / z, A − B / z) after the divide, with A = n + f and B = n f (so the matrix holds −B).
pub fn persp_to_ortho(n: f32, f: f32) -> Mat4 {
    let a = n + f;
    let b = -n * f;
    Mat4::from_cols(
        Vec4::new(n, 0.0, 0.0, 0.0),
        Vec4::new(0.0, n, 0.0, 0.0),
        Vec4::new(0.0, 0.0, a, 1.0),
        Vec4::new(0.0, 0.0, b, 0.0),
    )
}

/// Reversed-z orthographic projection of the view-space box [l,r]×[b,t] between distances
/// `near` and `far` in front of the eye (z = −near → depth 1, z = −far → depth 0).
pub fn orthographic_reversed(l: f32, r: f32, b: f32, t: f32, near: f32, far: f32) -> Mat4 {
    // depth = (z + far) / (far - near)  maps z=-far -> 0, z=-near -> 1.
    let d = far - near;
    Mat4::from_cols(
        Vec4::new(2.0 / (r - l), 0.0, 0.0, 0.0),
        Vec4::new(0.0, 2.0 / (t - b), 0.0, 0.0),
        Vec4::new(0.0, 0.0, 1.0 / d, 0.0),
        Vec4::new(-(r + l) / (r - l), -(t + b) / (t - b), far / d, 1.0),
    )
}

/// Reversed-z perspective with a finite far plane, built as `ortho · persp_to_ortho`.
/// `fov_y` in radians, `near` and `far` positive distances.
pub fn perspective_reversed(fov_y: f32, aspect: f32, near: f32, far: f32) -> Mat4 {
    let t = near * (fov_y * 0.5).tan();
    let r = t * aspect;
    // After persp_to_ortho, w = z (negative in front of the eye); the orthographic step therefore
    // works on the homogeneous point and the sign is fixed by negating the result, so that w = −z > 0.
    let ortho = orthographic_reversed(-r, r, -t, t, near, far);
    -(ortho * persp_to_ortho(-near, -far))
}

/// Reversed-z perspective with the far plane at infinity (depth → 0 as distance → ∞).
pub fn perspective_infinite_reversed(fov_y: f32, aspect: f32, near: f32) -> Mat4 {
    let f = 1.0 / (fov_y * 0.5).tan();
    Mat4::from_cols(
        Vec4::new(f / aspect, 0.0, 0.0, 0.0),
        Vec4::new(0.0, f, 0.0, 0.0),
        Vec4::new(0.0, 0.0, 0.0, -1.0),
        Vec4::new(0.0, 0.0, near, 0.0),
    )
}

/// NDC x/y of image position (`x`, `y`) in pixels (x right, y down; pixel centres at +0.5) in a
/// `w`×`h` image. NDC y points up: the Y flip of the framebuffer lives here and in
/// `ndc_to_pixel`, and in the shaders' naga `ADJUST_COORDINATE_SPACE`.
pub fn pixel_to_ndc(x: f32, y: f32, w: u32, h: u32) -> glam::Vec2 {
    glam::Vec2::new(x / w as f32 * 2.0 - 1.0, 1.0 - y / h as f32 * 2.0)
}

/// Image position in pixels of NDC x/y (the inverse of `pixel_to_ndc`).
pub fn ndc_to_pixel(ndc: glam::Vec2, w: u32, h: u32) -> (f32, f32) {
    (
        (ndc.x * 0.5 + 0.5) * w as f32,
        (0.5 - ndc.y * 0.5) * h as f32,
    )
}

/// Distance from which a camera with vertical field of view `fov_y` and `aspect` sees a sphere of
/// `radius` whole, with a 5 % margin (the narrower of the two fields of view decides).
pub fn framing_distance(radius: f32, fov_y: f32, aspect: f32) -> f32 {
    let fov_x = 2.0 * ((fov_y * 0.5).tan() * aspect).atan();
    radius / (fov_y.min(fov_x) * 0.5).sin() * 1.05
}

/// Depth (after the divide) that a projection gives a view-space point at distance `d` on the axis.
pub fn depth_at(proj: &Mat4, d: f32) -> f32 {
    let c = *proj * Vec4::new(0.0, 0.0, -d, 1.0);
    c.z / c.w
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn persp_to_ortho_squashes_frustum_to_box() {
        let (n, f) = (-1.0f32, -10.0f32);
        let m = persp_to_ortho(n, f);
        // Near-plane points are unchanged.
        for p in [Vec3::new(0.3, -0.2, n), Vec3::new(-0.5, 0.5, n)] {
            let q = m * p.extend(1.0);
            assert!((q.truncate() / q.w).abs_diff_eq(p, 1e-5), "{q:?}");
        }
        // Far-plane corners (x, y scaled by f/n) land on the box's far face, x/y back to near size.
        let p = Vec3::new(0.5 * f / n, -0.25 * f / n, f);
        let q = m * p.extend(1.0);
        assert!((q.truncate() / q.w).abs_diff_eq(Vec3::new(0.5, -0.25, f), 1e-4));
        // A point half-way in z stays between the planes (squashed, not on them).
        let q = m * Vec3::new(0.0, 0.0, 0.5 * (n + f)).extend(1.0);
        let z = q.z / q.w;
        assert!(z < n && z > f);
    }

    #[test]
    fn reversed_finite_maps_near_to_one_far_to_zero_monotonic() {
        let p = perspective_reversed(1.0, 1.5, 0.1, 100.0);
        assert!((depth_at(&p, 0.1) - 1.0).abs() < 1e-5);
        assert!(depth_at(&p, 100.0).abs() < 1e-5);
        let mut last = f32::INFINITY;
        for i in 0..2000 {
            let d = 0.1 + i as f32 * 0.05;
            let z = depth_at(&p, d);
            assert!(z < last, "not strictly decreasing at {d}");
            last = z;
        }
    }

    #[test]
    fn reversed_finite_matches_glam() {
        let p = perspective_reversed(0.8, 16.0 / 9.0, 0.5, 50.0);
        let g = Mat4::perspective_rh(0.8, 16.0 / 9.0, 50.0, 0.5);
        assert!(p.abs_diff_eq(g, 1e-5), "{p:?}\n{g:?}");
    }

    #[test]
    fn reversed_infinite_goes_to_zero() {
        let p = perspective_infinite_reversed(1.0, 1.0, 0.1);
        assert!((depth_at(&p, 0.1) - 1.0).abs() < 1e-6);
        assert!(depth_at(&p, 1e6) > 0.0 && depth_at(&p, 1e6) < 1e-6);
        let mut last = f32::INFINITY;
        for i in 0..1000 {
            let z = depth_at(&p, 0.1 * 1.01f32.powi(i));
            assert!(z < last && z > 0.0);
            last = z;
        }
        assert!(p.abs_diff_eq(Mat4::perspective_infinite_reverse_rh(1.0, 1.0, 0.1), 1e-6));
    }

    #[test]
    fn y_up_and_x_right_in_clip_space() {
        let p = perspective_reversed(1.0, 1.0, 0.1, 10.0);
        let up = p * Vec4::new(0.0, 1.0, -5.0, 1.0);
        let right = p * Vec4::new(1.0, 0.0, -5.0, 1.0);
        assert!(up.y / up.w > 0.0 && up.w > 0.0);
        assert!(right.x / right.w > 0.0);
    }

    #[test]
    fn pixel_ndc_round_trip_and_y_down_images() {
        let n = pixel_to_ndc(0.5, 0.5, 4, 2);
        assert!(
            n.x < 0.0 && n.y > 0.0,
            "the top-left pixel is left and up in NDC: {n}"
        );
        assert_eq!(pixel_to_ndc(2.0, 1.0, 4, 2), glam::Vec2::ZERO);
        for (x, y) in [(0.5, 0.5), (3.5, 1.5), (1.25, 0.75)] {
            let (px, py) = ndc_to_pixel(pixel_to_ndc(x, y, 4, 2), 4, 2);
            assert!((px - x).abs() < 1e-6 && (py - y).abs() < 1e-6);
        }
    }

    #[test]
    fn framing_distance_fits_the_sphere_in_both_directions() {
        for aspect in [0.5f32, 1.0, 16.0 / 9.0] {
            let fov_y = 0.8f32;
            let d = framing_distance(2.0, fov_y, aspect);
            let fov_x = 2.0 * ((fov_y * 0.5).tan() * aspect).atan();
            // The sphere's angular radius is inside both half-angles, with the 5 % margin.
            let angular = (2.0 / d).asin();
            assert!(
                angular <= fov_y * 0.5 + 1e-6 && angular <= fov_x * 0.5 + 1e-6,
                "{aspect}"
            );
            assert!(
                (angular - fov_y.min(fov_x) * 0.5).abs() < 0.05,
                "{aspect}: not wasteful"
            );
        }
    }

    #[test]
    fn orthographic_reversed_box() {
        let o = orthographic_reversed(-2.0, 4.0, -1.0, 3.0, 1.0, 11.0);
        let a = o * Vec4::new(-2.0, -1.0, -1.0, 1.0);
        let b = o * Vec4::new(4.0, 3.0, -11.0, 1.0);
        assert!(a.truncate().abs_diff_eq(Vec3::new(-1.0, -1.0, 1.0), 1e-6));
        assert!(b.truncate().abs_diff_eq(Vec3::new(1.0, 1.0, 0.0), 1e-6));
    }
}
