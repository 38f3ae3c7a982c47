//! The mapping from glTF metallic-roughness to Blinn-Phong, shared by the GPU shader
//! (`shaders/scene.wgsl` implements the same lines) and the CPU reference.
//!
//! kd = base · (1 − metallic); ks = mix(0.04, base, metallic); ka = base;
//! p = 2 / α² − 2 with α = roughness² (clamped to [1, 2048], roughness ≥ 0.03).
//! L = ka·Ia + Σ vis · (I / r²) · (kd · max(0, n·l) + ks · max(0, n·h)^p) + emissive.

use glam::Vec3;

/// Blinn-Phong constants for one surface point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlinnPhong {
    /// Ambient reflectance.
    pub ka: Vec3,
    /// Diffuse reflectance.
    pub kd: Vec3,
    /// Specular reflectance.
    pub ks: Vec3,
    /// Specular exponent.
    pub p: f32,
}

/// Maps base colour, metallic and roughness to Blinn-Phong constants.
pub fn blinn_phong_params(base: Vec3, metallic: f32, roughness: f32) -> BlinnPhong {
    let metallic = metallic.clamp(0.0, 1.0);
    let roughness = roughness.clamp(0.03, 1.0);
    let alpha = roughness * roughness;
    BlinnPhong {
        ka: base,
        kd: base * (1.0 - metallic),
        ks: Vec3::splat(0.04).lerp(base, metallic),
        p: (2.0 / (alpha * alpha) - 2.0).clamp(1.0, 2048.0),
    }
}

/// Diffuse + specular from one light: `radiance` is I (already divided by r² for local lights),
/// `vis` the shadow/facing term, n, l, v unit vectors.
pub fn shade_blinn_phong(
    m: &BlinnPhong,
    n: Vec3,
    l: Vec3,
    v: Vec3,
    radiance: Vec3,
    vis: f32,
) -> Vec3 {
    let h = (l + v).normalize_or_zero();
    let ndl = n.dot(l).max(0.0);
    let ndh = n.dot(h).max(0.0);
    vis * radiance * (m.kd * ndl + m.ks * ndh.powf(m.p))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dielectric_and_metal() {
        let d = blinn_phong_params(Vec3::new(0.5, 0.2, 0.1), 0.0, 1.0);
        assert_eq!(d.kd, Vec3::new(0.5, 0.2, 0.1));
        assert_eq!(d.ks, Vec3::splat(0.04));
        assert_eq!(d.p, 1.0);
        let m = blinn_phong_params(Vec3::new(0.9, 0.6, 0.2), 1.0, 0.5);
        assert_eq!(m.kd, Vec3::ZERO);
        assert_eq!(m.ks, Vec3::new(0.9, 0.6, 0.2));
        assert!((m.p - 30.0).abs() < 1e-3);
    }

    #[test]
    fn formula_terms() {
        let m = blinn_phong_params(Vec3::ONE, 0.0, 0.5);
        let n = Vec3::Y;
        let l = Vec3::new(0.0, 1.0, 1.0).normalize();
        let v = Vec3::new(0.0, 1.0, -1.0).normalize();
        let c = shade_blinn_phong(&m, n, l, v, Vec3::splat(2.0), 1.0);
        // h = +Y exactly, so the specular term is ks * 1.
        let expect = 2.0 * (l.y + 0.04);
        assert!((c.x - expect).abs() < 1e-5);
        assert_eq!(
            shade_blinn_phong(&m, n, l, v, Vec3::splat(2.0), 0.0),
            Vec3::ZERO
        );
    }
}
