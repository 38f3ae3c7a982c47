//! Cubic Bézier curves (camera paths).

use glam::Vec3;

/// A cubic Bézier curve with control points p0..p3.
#[derive(Clone, Copy, Debug)]
pub struct CubicBezier {
    /// Control points.
    pub p: [Vec3; 4],
}

impl CubicBezier {
    /// The point at parameter t ∈ [0, 1] (Bernstein form).
    pub fn eval(&self, t: f32) -> Vec3 {
        let u = 1.0 - t;
        let [p0, p1, p2, p3] = self.p;
        p0 * (u * u * u) + p1 * (3.0 * u * u * t) + p2 * (3.0 * u * t * t) + p3 * (t * t * t)
    }

    /// The tangent (first derivative) at t.
    pub fn derivative(&self, t: f32) -> Vec3 {
        let u = 1.0 - t;
        let [p0, p1, p2, p3] = self.p;
        (p1 - p0) * (3.0 * u * u) + (p2 - p1) * (6.0 * u * t) + (p3 - p2) * (3.0 * t * t)
    }

    /// The point at t by de Casteljau's construction (for checking `eval`).
    pub fn de_casteljau(&self, t: f32) -> Vec3 {
        let mut q = self.p;
        for k in (1..4).rev() {
            for i in 0..k {
                q[i] = q[i].lerp(q[i + 1], t);
            }
        }
        q[0]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn endpoints_tangents_and_de_casteljau() {
        let c = CubicBezier {
            p: [
                Vec3::ZERO,
                Vec3::new(1.0, 2.0, 0.0),
                Vec3::new(3.0, 2.0, 1.0),
                Vec3::new(4.0, 0.0, 0.0),
            ],
        };
        assert_eq!(c.eval(0.0), c.p[0]);
        assert!(c.eval(1.0).abs_diff_eq(c.p[3], 1e-6));
        assert!(c.derivative(0.0).abs_diff_eq((c.p[1] - c.p[0]) * 3.0, 1e-6));
        assert!(c.derivative(1.0).abs_diff_eq((c.p[3] - c.p[2]) * 3.0, 1e-6));
        for i in 0..=10 {
            let t = i as f32 / 10.0;
            assert!(c.eval(t).abs_diff_eq(c.de_casteljau(t), 1e-5));
            // Central difference agrees with the derivative.
            let h = 1e-3;
            if t > h && t < 1.0 - h {
                let fd = (c.eval(t + h) - c.eval(t - h)) / (2.0 * h);
                assert!(fd.abs_diff_eq(c.derivative(t), 2e-2), "{t}");
            }
        }
    }
}
