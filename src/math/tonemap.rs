//! Display transforms: exposure and tone-mapping curves from linear scene values to linear
//! display values in [0, 1] (the sRGB encoding follows in the attachment). The same formulas run
//! in `shaders/scene.wgsl` (`display`); the CPU reference uses these.

use glam::{Mat3, Vec3};

/// How exposed linear values become display values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Tonemap {
    /// Khronos PBR Neutral: identity (less a small black offset) up to 0.76, then a smooth
    /// compression of highlights towards white that keeps base colours' hues.
    #[default]
    Neutral,
    /// ACES filmic, Stephen Hill's fit of the RRT + ODT (sRGB primaries), with the Khronos
    /// Sample Viewer's 1/0.6 exposure bias.
    Aces,
    /// None: exposed values clamped to [0, 1] (for tests and tools that want raw values).
    None,
}

impl std::str::FromStr for Tonemap {
    type Err = String;

    /// `neutral`, `aces` or `none`.
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "neutral" => Ok(Tonemap::Neutral),
            "aces" => Ok(Tonemap::Aces),
            "none" => Ok(Tonemap::None),
            _ => Err(format!("tone curve '{s}' is not neutral, aces or none")),
        }
    }
}

impl Tonemap {
    /// The shader's operator number (`Frame.output.y`).
    pub fn shader_value(self) -> f32 {
        match self {
            Tonemap::None => 0.0,
            Tonemap::Neutral => 1.0,
            Tonemap::Aces => 2.0,
        }
    }

    /// Display value of the exposed linear colour `c` (each channel in [0, 1]).
    pub fn apply(self, c: Vec3) -> Vec3 {
        // Past this, f32 arithmetic in the curves loses the colour; every curve is at 1 there.
        let c = c.clamp(Vec3::ZERO, Vec3::splat(HDR_MAX));
        let out = match self {
            Tonemap::None => c,
            Tonemap::Neutral => pbr_neutral(c),
            Tonemap::Aces => aces_hill(c / 0.6),
        };
        out.clamp(Vec3::ZERO, Vec3::ONE)
    }
}

/// Largest exposed value the curves take (f16's largest finite value; brighter reads as this).
pub const HDR_MAX: f32 = 65504.0;

/// The sRGB transfer function's decoding: an encoded value in [0, 1] → linear light.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The sRGB transfer function's encoding: linear light in [0, 1] → an encoded value in [0, 1].
pub fn linear_to_srgb(l: f32) -> f32 {
    if l <= 0.003_130_8 {
        l * 12.92
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    }
}

/// Khronos PBR Neutral tone mapping (the Khronos 3D Commerce group's published formula).
pub fn pbr_neutral(c: Vec3) -> Vec3 {
    const START: f32 = 0.8 - 0.04;
    const DESATURATION: f32 = 0.15;
    let x = c.min_element();
    let offset = if x < 0.08 { x - 6.25 * x * x } else { 0.04 };
    let c = c - Vec3::splat(offset);
    let peak = c.max_element();
    if peak < START {
        return c;
    }
    let d = 1.0 - START;
    let new_peak = 1.0 - d * d / (peak + d - START);
    let c = c * (new_peak / peak);
    let g = 1.0 - 1.0 / (DESATURATION * (peak - new_peak) + 1.0);
    c.lerp(Vec3::splat(new_peak), g)
}

/// ACES filmic (Stephen Hill's fit): sRGB → ACES AP1-ish input matrix, the RRT + ODT rational
/// fit, and back.
pub fn aces_hill(c: Vec3) -> Vec3 {
    let input = Mat3::from_cols(
        Vec3::new(0.59719, 0.07600, 0.02840),
        Vec3::new(0.35458, 0.90834, 0.13383),
        Vec3::new(0.04823, 0.01566, 0.83777),
    );
    let output = Mat3::from_cols(
        Vec3::new(1.60475, -0.10208, -0.00327),
        Vec3::new(-0.53108, 1.10813, -0.07276),
        Vec3::new(-0.07367, -0.00605, 1.07602),
    );
    let v = input * c;
    let a = v * (v + Vec3::splat(0.0245786)) - Vec3::splat(0.000090537);
    let b = v * (v * 0.983729 + Vec3::splat(0.432_951)) + Vec3::splat(0.238081);
    output * (a / b)
}

/// What auto exposure maps the key illuminance E to before tone mapping: the value that puts an
/// 18 % grey card facing the key light at display middle grey (0.18 linear, sRGB 118) after PBR
/// Neutral, which subtracts 0.04 there: (0.18 + 0.04) / 0.18. A white surface facing the key
/// light shows at 0.90.
pub const KEY_VALUE: f32 = (0.18 + 0.04) / 0.18;

/// The EV100 umbra's auto exposure sets for key illuminance `lux`: the one whose scale
/// ([`exposure_from_ev100`]) is [`KEY_VALUE`] / E, i.e. log2(E / 1.467). That is 0.77 stops
/// above what an incident-light meter (ISO 2720, C = 250) reads, log2(E / 2.5): a physical
/// camera sees a Lambertian surface's radiance kd·E/π, where umbra's Blinn-Phong returns kd·E,
/// so a photographic exposure would be π times (1.65 stops) too bright here.
pub fn metered_ev100(lux: f32) -> f32 {
    (lux / (1.2 * KEY_VALUE)).log2()
}

/// The linear scale a camera set to `ev100` applies (saturation-based sensitivity, ISO 100:
/// 1 / (1.2 · 2^EV100), the convention of Lagarde and de Rousiers, "Moving Frostbite to PBR").
pub fn exposure_from_ev100(ev100: f32) -> f32 {
    1.0 / (1.2 * ev100.exp2())
}

/// Inverse of [`exposure_from_ev100`].
pub fn ev100_from_exposure(scale: f32) -> f32 {
    (1.0 / (1.2 * scale)).log2()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grey(t: Tonemap, x: f32) -> f32 {
        t.apply(Vec3::splat(x)).x
    }

    #[test]
    fn neutral_matches_the_formula_at_known_points() {
        // 0.18 is below the compression start: less the 0.04 offset.
        assert!((grey(Tonemap::Neutral, 0.18) - 0.14).abs() < 1e-6);
        // 1.0: 1 − 0.24² / (0.96 + 0.24 − 0.76) = 0.869091 (greys do not desaturate).
        assert!((grey(Tonemap::Neutral, 1.0) - 0.869_091).abs() < 1e-5);
        assert_eq!(grey(Tonemap::Neutral, 0.0), 0.0);
        // Hue kept below the compression start: a pure red stays pure red.
        let r = Tonemap::Neutral.apply(Vec3::new(0.5, 0.0, 0.0));
        assert_eq!(r, Vec3::new(0.5, 0.0, 0.0));
    }

    #[test]
    fn curves_are_monotonic_bounded_and_finite() {
        for t in [Tonemap::Neutral, Tonemap::Aces, Tonemap::None] {
            let mut last = -1.0;
            for i in 0..=4000 {
                let x = (i as f32 / 200.0 - 10.0).exp2(); // 2^-10 .. 2^10
                let y = grey(t, x);
                assert!(
                    y.is_finite() && (0.0..=1.0).contains(&y),
                    "{t:?}({x}) = {y}"
                );
                assert!(y >= last - 1e-6, "{t:?} falls at {x}: {last} -> {y}");
                last = y;
            }
            for x in [f32::INFINITY, f32::MAX, 1e30, HDR_MAX * 2.0] {
                let y = grey(t, x);
                assert!(
                    (y - 1.0).abs() < 1e-3 || t == Tonemap::Aces && y > 0.99,
                    "{t:?}({x}) = {y}"
                );
            }
            assert!(!t.apply(Vec3::splat(f32::NAN)).is_nan());
        }
        // ACES: mid grey 0.18 after the 1/0.6 bias lands near its published 0.22 (sRGB-linear).
        let y = grey(Tonemap::Aces, 0.18);
        assert!((0.2..0.26).contains(&y), "{y}");
    }

    #[test]
    fn exposure_conventions() {
        // 100,000 lux of sun meters EV100 log2(1e5 / 1.4667) = 16.06 (an incident meter: 15.29).
        assert!((metered_ev100(1e5) - 16.057).abs() < 1e-3);
        let s = exposure_from_ev100(15.0);
        assert!((ev100_from_exposure(s) - 15.0).abs() < 1e-4);
        // Metered exposure maps the key illuminance to KEY_VALUE whatever its size, and an 18 %
        // card there to middle grey after the curve.
        for lux in [0.5f32, 1.7, 1e4, 1e5] {
            let k = lux * exposure_from_ev100(metered_ev100(lux));
            assert!((k - KEY_VALUE).abs() < 1e-5, "{lux}: {k}");
        }
        assert!((grey(Tonemap::Neutral, 0.18 * KEY_VALUE) - 0.18).abs() < 1e-6);
    }
}
