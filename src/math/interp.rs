//! Barycentric coordinates, perspective-correct interpolation and normal perturbation.

use glam::{Vec2, Vec3};

/// Barycentric coordinates (w0, w1, w2) of 2-D point `p` in triangle (a, b, c); `None` for a
/// zero-area triangle. Weights sum to 1; all ≥ 0 inside.
pub fn barycentric(p: Vec2, a: Vec2, b: Vec2, c: Vec2) -> Option<Vec3> {
    let area = (b - a).perp_dot(c - a);
    if area.abs() <= f32::EPSILON * (b - a).length() * (c - a).length() || area == 0.0 {
        return None;
    }
    let w1 = (p - a).perp_dot(c - a) / area;
    let w2 = (b - a).perp_dot(p - a) / area;
    Some(Vec3::new(1.0 - w1 - w2, w1, w2))
}

/// Perspective-correct interpolation of per-vertex values given screen-space barycentrics `bary`
/// and each vertex's clip-space w: interpolate value/w and 1/w linearly, then divide.
pub fn perspective_correct<T>(bary: Vec3, w: Vec3, values: [T; 3]) -> T
where
    T: Copy + std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>,
{
    let k = Vec3::new(bary.x / w.x, bary.y / w.y, bary.z / w.z);
    let sum = k.x + k.y + k.z;
    values[0] * (k.x / sum) + values[1] * (k.y / sum) + values[2] * (k.z / sum)
}

/// Tangent-space normal `tn` (already unpacked to [-1,1] and scaled) to world space, with the glTF
/// convention: bitangent = sign · (n × t). `t` need not be orthogonal to `n` (Gram–Schmidt here).
/// Returns `n` itself (normalised) when `t` is parallel to `n` or the result degenerates.
pub fn perturb_normal(n: Vec3, t: Vec3, sign: f32, tn: Vec3) -> Vec3 {
    let n = n.normalize_or_zero();
    let t = (t - n * n.dot(t)).normalize_or_zero();
    if t == Vec3::ZERO {
        return n;
    }
    let b = n.cross(t) * if sign < 0.0 { -1.0 } else { 1.0 };
    (t * tn.x + b * tn.y + n * tn.z).normalize_or(n)
}

/// Tangent-space normal of a height field from its slopes along the tangent-space x and y axes
/// and a strength: n ∝ (−∂h/∂x, −∂h/∂y, 1). (For glTF, y runs up the image, i.e. along −v.)
pub fn normal_from_height_slope(dh_du: f32, dh_dv: f32, strength: f32) -> Vec3 {
    Vec3::new(-dh_du * strength, -dh_dv * strength, 1.0).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn barycentric_vertices_centroid_and_degenerate() {
        let (a, b, c) = (Vec2::ZERO, Vec2::new(4.0, 0.0), Vec2::new(0.0, 2.0));
        assert!(barycentric(a, a, b, c).unwrap().abs_diff_eq(Vec3::X, 1e-6));
        assert!(barycentric(b, a, b, c).unwrap().abs_diff_eq(Vec3::Y, 1e-6));
        assert!(barycentric(c, a, b, c).unwrap().abs_diff_eq(Vec3::Z, 1e-6));
        let g = barycentric((a + b + c) / 3.0, a, b, c).unwrap();
        assert!(g.abs_diff_eq(Vec3::splat(1.0 / 3.0), 1e-6));
        let out = barycentric(Vec2::new(5.0, 5.0), a, b, c).unwrap();
        assert!(out.min_element() < 0.0);
        assert!(barycentric(a, a, b, b).is_none());
    }

    #[test]
    fn perspective_correct_recovers_view_space_attribute() {
        // A segment from z=-1 to z=-3 projected with w = -z: screen midpoint is not the 3-D midpoint.
        let (w0, w1) = (1.0f32, 3.0f32);
        // Screen-space x of points (x=-1, z=-1) and (x=1, z=-3): -1 and 1/3. Midpoint on screen: -1/3.
        // Solve in 3-D: the ray through screen x=-1/3 meets the segment at parameter s with
        // x/(-z) = -1/3 where x = -1+2s, z=-1-2s -> s = 1/4... check value interpolation.
        let bary = Vec3::new(0.5, 0.5, 0.0);
        let attr = perspective_correct(bary, Vec3::new(w0, w1, 1.0), [0.0f32, 1.0, 0.0]);
        assert!((attr - 0.25).abs() < 1e-6, "{attr}");
        // Equal w gives plain linear interpolation.
        let attr = perspective_correct(
            Vec3::new(0.2, 0.3, 0.5),
            Vec3::splat(2.0),
            [1.0f32, 2.0, 3.0],
        );
        assert!((attr - (0.2 + 0.6 + 1.5)).abs() < 1e-6);
    }

    #[test]
    fn normal_perturbation_follows_tangent_frame() {
        let n = Vec3::Z;
        let t = Vec3::X;
        assert!(perturb_normal(n, t, 1.0, Vec3::Z).abs_diff_eq(Vec3::Z, 1e-6));
        let tilted = Vec3::new(0.5, 0.0, 1.0).normalize();
        assert!(perturb_normal(n, t, 1.0, tilted).abs_diff_eq(tilted, 1e-6));
        // +y in tangent space is the bitangent n × t = +Y; a negative sign mirrors it.
        let ty = Vec3::new(0.0, 0.6, 0.8);
        assert!(perturb_normal(n, t, 1.0, ty).abs_diff_eq(Vec3::new(0.0, 0.6, 0.8), 1e-6));
        assert!(perturb_normal(n, t, -1.0, ty).abs_diff_eq(Vec3::new(0.0, -0.6, 0.8), 1e-6));
        // Height increasing along u tilts the normal towards -u.
        let hn = normal_from_height_slope(1.0, 0.0, 1.0);
        assert!(hn.x < 0.0 && hn.y == 0.0);
    }
}
