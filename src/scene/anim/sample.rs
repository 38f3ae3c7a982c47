//! Keyframe sampling: glTF's STEP, LINEAR (spherical for rotations, shortest arc) and
//! CUBICSPLINE (Hermite, tangents scaled by the keyframe interval) interpolation. Pure functions
//! over a sampler's times and flat output values, unit-tested against hand-computed values.

use glam::{Quat, Vec4};

/// How a sampler interpolates between keyframes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    /// The previous keyframe's value until the next keyframe.
    Step,
    /// Linear; rotations by spherical linear interpolation along the shorter arc.
    Linear,
    /// Cubic Hermite spline: each keyframe stores an in-tangent, a value and an out-tangent.
    CubicSpline,
}

impl Interpolation {
    /// The glTF name (`STEP`, `LINEAR`, `CUBICSPLINE`).
    pub fn name(self) -> &'static str {
        match self {
            Interpolation::Step => "STEP",
            Interpolation::Linear => "LINEAR",
            Interpolation::CubicSpline => "CUBICSPLINE",
        }
    }
}

/// Keyframes of one animated property.
#[derive(Clone, Debug, PartialEq)]
pub struct Keyframes {
    /// Interpolation mode.
    pub interpolation: Interpolation,
    /// Strictly increasing, finite keyframe times in seconds (at least one).
    pub times: Vec<f32>,
    /// Output values, `width` floats per element: one element per keyframe, or three
    /// (in-tangent, value, out-tangent) for CUBICSPLINE.
    pub values: Vec<f32>,
    /// Floats per element: 3 (translation, scale), 4 (rotation, x y z w) or the number of morph
    /// targets (weights).
    pub width: usize,
}

impl Keyframes {
    /// Checks the shape the sampling relies on; the message names what is wrong.
    pub fn validate(&self) -> Result<(), String> {
        if self.times.is_empty() {
            return Err("no keyframes".into());
        }
        if self.width == 0 {
            return Err("outputs have no components".into());
        }
        if let Some(t) = self.times.iter().find(|t| !t.is_finite()) {
            return Err(format!("keyframe time {t} is not finite"));
        }
        if let Some(k) = self.times.windows(2).position(|w| w[1] <= w[0]) {
            return Err(format!(
                "keyframe times are not strictly increasing (key {}: {} after {})",
                k + 1,
                self.times[k + 1],
                self.times[k]
            ));
        }
        let per_key = if self.interpolation == Interpolation::CubicSpline {
            3
        } else {
            1
        };
        let want = self.times.len() * per_key * self.width;
        if self.values.len() != want {
            return Err(format!(
                "{} output values for {} keyframes (expected {want})",
                self.values.len(),
                self.times.len()
            ));
        }
        if self.values.iter().any(|v| !v.is_finite()) {
            return Err("an output value is not finite".into());
        }
        Ok(())
    }

    /// First and last keyframe times.
    pub fn range(&self) -> (f32, f32) {
        (self.times[0], *self.times.last().unwrap_or(&self.times[0]))
    }

    /// Element `e` (0: in-tangent, 1: value, 2: out-tangent for CUBICSPLINE; 0 otherwise) of
    /// keyframe `k`.
    fn element(&self, k: usize, e: usize) -> &[f32] {
        let per_key = if self.interpolation == Interpolation::CubicSpline {
            3
        } else {
            1
        };
        let start = (k * per_key + e) * self.width;
        &self.values[start..start + self.width]
    }

    /// The keyframe value of key `k`.
    fn value(&self, k: usize) -> &[f32] {
        let e = usize::from(self.interpolation == Interpolation::CubicSpline);
        self.element(k, e)
    }

    /// The segment holding `t` (clamped to the keyframes' range): the key before it, and the
    /// fraction of the way to the next key; `None` for the fraction outside the range or with a
    /// single keyframe.
    fn segment(&self, t: f32) -> (usize, Option<f32>) {
        let n = self.times.len();
        if n == 1 || t.is_nan() || t <= self.times[0] {
            return (0, None);
        }
        if t >= self.times[n - 1] {
            return (n - 1, None);
        }
        // The last key with time <= t.
        let k = self.times.partition_point(|&x| x <= t) - 1;
        let s = (t - self.times[k]) / (self.times[k + 1] - self.times[k]);
        (k, Some(s))
    }

    /// Samples a vector-valued property (translation, scale, weights) at time `t` into `out`
    /// (`width` floats).
    pub fn sample_into(&self, t: f32, out: &mut [f32]) {
        let (k, s) = self.segment(t);
        let Some(s) = s else {
            out.copy_from_slice(self.value(k));
            return;
        };
        match self.interpolation {
            Interpolation::Step => out.copy_from_slice(self.value(k)),
            Interpolation::Linear => {
                let (a, b) = (self.value(k), self.value(k + 1));
                for (o, (a, b)) in out.iter_mut().zip(a.iter().zip(b)) {
                    *o = a + (b - a) * s;
                }
            }
            Interpolation::CubicSpline => {
                let td = self.times[k + 1] - self.times[k];
                let [h00, h10, h01, h11] = hermite(s);
                let (v0, b0) = (self.element(k, 1), self.element(k, 2));
                let (a1, v1) = (self.element(k + 1, 0), self.element(k + 1, 1));
                for (i, o) in out.iter_mut().enumerate() {
                    *o = h00 * v0[i] + h10 * td * b0[i] + h01 * v1[i] + h11 * td * a1[i];
                }
            }
        }
    }

    /// Samples a rotation (x, y, z, w) at time `t`: LINEAR by slerp along the shorter arc,
    /// CUBICSPLINE componentwise then normalised (as the spec says).
    pub fn sample_rotation(&self, t: f32) -> Quat {
        let q = |v: &[f32]| Quat::from_vec4(Vec4::new(v[0], v[1], v[2], v[3]));
        let (k, s) = self.segment(t);
        let r = match (self.interpolation, s) {
            (_, None) | (Interpolation::Step, _) => q(self.value(k)),
            (Interpolation::Linear, Some(s)) => slerp(q(self.value(k)), q(self.value(k + 1)), s),
            (Interpolation::CubicSpline, Some(_)) => {
                let mut v = [0.0; 4];
                self.sample_into(t, &mut v);
                q(&v)
            }
        };
        unit_quat(r)
    }
}

/// `q` normalised; identity for a zero or non-finite quaternion.
pub fn unit_quat(q: Quat) -> Quat {
    let v = Vec4::from(q);
    match v.try_normalize() {
        Some(n) => Quat::from_vec4(n),
        None => Quat::IDENTITY,
    }
}

/// The cubic Hermite basis at `s` ∈ [0, 1]: weights of the first value, the first out-tangent,
/// the second value and the second in-tangent.
pub fn hermite(s: f32) -> [f32; 4] {
    let (s2, s3) = (s * s, s * s * s);
    [
        2.0 * s3 - 3.0 * s2 + 1.0,
        s3 - 2.0 * s2 + s,
        -2.0 * s3 + 3.0 * s2,
        s3 - s2,
    ]
}

/// Spherical linear interpolation from `a` to `b` along the shorter arc (`b` negated when the
/// two lie in opposite hemispheres); linear and normalised when they are almost equal.
pub fn slerp(a: Quat, b: Quat, s: f32) -> Quat {
    let a = a.normalize();
    let mut b = b.normalize();
    let mut d = a.dot(b);
    if d < 0.0 {
        b = -b;
        d = -d;
    }
    if d > 0.9995 {
        return Quat::from_vec4(Vec4::from(a).lerp(Vec4::from(b), s)).normalize();
    }
    let theta = d.clamp(-1.0, 1.0).acos();
    let sin = theta.sin();
    let wa = ((1.0 - s) * theta).sin() / sin;
    let wb = (s * theta).sin() / sin;
    Quat::from_vec4(Vec4::from(a) * wa + Vec4::from(b) * wb)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn keys(
        interpolation: Interpolation,
        times: &[f32],
        values: &[f32],
        width: usize,
    ) -> Keyframes {
        let k = Keyframes {
            interpolation,
            times: times.to_vec(),
            values: values.to_vec(),
            width,
        };
        k.validate().unwrap();
        k
    }

    fn sample(k: &Keyframes, t: f32) -> Vec<f32> {
        let mut v = vec![0.0; k.width];
        k.sample_into(t, &mut v);
        v
    }

    #[test]
    fn step_holds_the_previous_key() {
        let k = keys(Interpolation::Step, &[0.0, 1.0, 2.0], &[1.0, 5.0, 9.0], 1);
        assert_eq!(sample(&k, 0.0), [1.0]);
        assert_eq!(sample(&k, 0.999), [1.0]);
        assert_eq!(sample(&k, 1.0), [5.0]);
        assert_eq!(sample(&k, 1.5), [5.0]);
        assert_eq!(sample(&k, 7.0), [9.0]);
    }

    #[test]
    fn linear_interpolates_and_clamps_to_the_range() {
        let k = keys(
            Interpolation::Linear,
            &[1.0, 3.0],
            &[0.0, 10.0, -2.0, 4.0, 20.0, 2.0],
            3,
        );
        assert_eq!(sample(&k, 2.0), [2.0, 15.0, 0.0]);
        assert_eq!(sample(&k, 1.5), [1.0, 12.5, -1.0]);
        // Before the first key and after the last: clamped.
        assert_eq!(sample(&k, -5.0), [0.0, 10.0, -2.0]);
        assert_eq!(sample(&k, 9.0), [4.0, 20.0, 2.0]);
        assert_eq!(sample(&k, f32::NAN), [0.0, 10.0, -2.0]);
    }

    #[test]
    fn cubic_spline_follows_the_hermite_formula_with_scaled_tangents() {
        // One scalar, keys at t = 0 and t = 2: v0 = 1, out-tangent b0 = 3; v1 = 4, in-tangent
        // a1 = -1. At t = 0.5: s = 0.25, td = 2.
        // h00 = 2/64 - 3/16 + 1 = 0.84375, h10 = 1/64 - 2/16 + 1/4 = 0.140625,
        // h01 = -2/64 + 3/16 = 0.15625, h11 = 1/64 - 1/16 = -0.046875.
        // p = 0.84375·1 + 0.140625·2·3 + 0.15625·4 + (-0.046875)·2·(-1) = 2.40625.
        let k = keys(
            Interpolation::CubicSpline,
            &[0.0, 2.0],
            &[9.0, 1.0, 3.0, -1.0, 4.0, 9.0],
            1,
        );
        assert!((sample(&k, 0.5)[0] - 2.40625).abs() < 1e-6);
        // At the keys the spline passes through the values; tangents outside are ignored.
        assert_eq!(sample(&k, 0.0), [1.0]);
        assert_eq!(sample(&k, 2.0), [4.0]);
        assert_eq!(sample(&k, 3.0), [4.0]);
    }

    #[test]
    fn linear_rotation_takes_the_shorter_arc() {
        // 0° to 270° about Y stored as q(270°) = -q(-90°): the shorter arc goes through -45°.
        let turn = |b: Quat| {
            let values: Vec<f32> = Quat::IDENTITY
                .to_array()
                .into_iter()
                .chain(b.to_array())
                .collect();
            keys(Interpolation::Linear, &[0.0, 1.0], &values, 4)
        };
        let k = turn(Quat::from_rotation_y(270f32.to_radians()));
        let mid = k.sample_rotation(0.5);
        let want = Quat::from_rotation_y((-45f32).to_radians());
        assert!(mid.dot(want).abs() > 1.0 - 1e-6, "{mid:?} vs {want:?}");
        // A quarter of the way along 0° → 90°: 22.5°, not a normalised lerp.
        let q = turn(Quat::from_rotation_x(90f32.to_radians())).sample_rotation(0.25);
        let (axis, angle) = q.to_axis_angle();
        assert!((angle - 22.5f32.to_radians()).abs() < 1e-5, "{angle}");
        assert!(axis.abs_diff_eq(glam::Vec3::X, 1e-5));
    }

    #[test]
    fn malformed_keyframes_are_refused() {
        let bad = |times: &[f32], values: &[f32], interpolation| {
            Keyframes {
                interpolation,
                times: times.to_vec(),
                values: values.to_vec(),
                width: 1,
            }
            .validate()
            .unwrap_err()
        };
        assert!(bad(&[0.0, 0.0], &[1.0, 2.0], Interpolation::Linear).contains("increasing"));
        assert!(bad(&[1.0, 0.5], &[1.0, 2.0], Interpolation::Linear).contains("increasing"));
        assert!(bad(&[0.0, f32::NAN], &[1.0, 2.0], Interpolation::Linear).contains("finite"));
        assert!(bad(&[0.0, 1.0], &[1.0], Interpolation::Linear).contains("expected 2"));
        assert!(bad(&[0.0, 1.0], &[1.0, 2.0], Interpolation::CubicSpline).contains("expected 6"));
        assert!(bad(&[0.0], &[f32::INFINITY], Interpolation::Step).contains("not finite"));
        assert!(bad(&[], &[], Interpolation::Step).contains("no keyframes"));
    }
}
