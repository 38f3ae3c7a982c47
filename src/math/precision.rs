//! Depth precision over distance: the relative world-space gap Δd/d between a point at distance
//! d and the next distance whose stored depth differs, for reversed-z float (umbra's choice) and
//! for standard z in float or unorm formats. Computed in f64 from the closed-form depth.

/// How depth maps distance, and how it is stored.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DepthMapping {
    /// Reversed-z, infinite far plane: depth = n / d, stored as f32.
    ReversedInfiniteF32,
    /// Standard z in [0, 1] (near → 0, far → 1): depth = f (d − n) / (d (f − n)), stored as f32.
    StandardF32 {
        /// Far plane distance.
        far: f64,
    },
    /// Standard z stored as unsigned normalised integer of `bits` bits.
    StandardUnorm {
        /// Far plane distance.
        far: f64,
        /// 16 or 24.
        bits: u32,
    },
}

fn ulp_f32(x: f64) -> f64 {
    let f = x as f32;
    if f == 0.0 {
        return f32::from_bits(1) as f64;
    }
    let next = f32::from_bits(f.to_bits() + 1) as f64;
    next - f as f64
}

/// Δd / d at distance `d` for near plane `near` (d ≥ near).
pub fn relative_gap(mapping: DepthMapping, near: f64, d: f64) -> f64 {
    match mapping {
        DepthMapping::ReversedInfiniteF32 => {
            let z = near / d;
            let slope = near / (d * d); // |dz/dd|
            ulp_f32(z) / slope / d
        }
        DepthMapping::StandardF32 { far } => {
            let z = far * (d - near) / (d * (far - near));
            let slope = far * near / (d * d * (far - near));
            ulp_f32(z) / slope / d
        }
        DepthMapping::StandardUnorm { far, bits } => {
            let step = 1.0 / ((1u64 << bits) - 1) as f64;
            let slope = far * near / (d * d * (far - near));
            step / slope / d
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reversed_float_keeps_constant_relative_precision() {
        let near = 0.1;
        let mut d = near;
        while d < near * 1e6 {
            let r = relative_gap(DepthMapping::ReversedInfiniteF32, near, d);
            // One f32 ulp of relative precision (2^-23), independent of distance.
            assert!(r <= 1.2e-7 && r > 1e-8, "d {d}: {r}");
            d *= 1.7;
        }
    }

    #[test]
    fn standard_z_degrades_with_distance() {
        let (near, far) = (0.1, 1e4);
        let at = |m, d| relative_gap(m, near, d);
        let d = 1e3;
        let rev = at(DepthMapping::ReversedInfiniteF32, d);
        let std32 = at(DepthMapping::StandardF32 { far }, d);
        let un24 = at(DepthMapping::StandardUnorm { far, bits: 24 }, d);
        let un16 = at(DepthMapping::StandardUnorm { far, bits: 16 }, d);
        // At 10,000 near-plane distances, standard float is ~1000× coarser than reversed.
        assert!(std32 > 500.0 * rev, "{std32} vs {rev}");
        assert!(un24 > 500.0 * rev && un16 > un24 * 200.0);
        // Close to the near plane every mapping is fine.
        assert!(at(DepthMapping::StandardF32 { far }, 0.2) < 1e-6);
    }
}
