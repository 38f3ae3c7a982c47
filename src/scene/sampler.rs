//! glTF texture samplers: filters and wrap modes per axis, as a texture reference carries them.

/// A texel filter.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Filter {
    /// The nearest texel.
    Nearest,
    /// Bilinear between the four nearest texels.
    #[default]
    Linear,
}

/// What a texture coordinate outside [0, 1] reads.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Wrap {
    /// The image tiles.
    #[default]
    Repeat,
    /// The image tiles, every other tile mirrored.
    MirroredRepeat,
    /// The edge texels extend outwards.
    ClampToEdge,
}

impl Wrap {
    /// The texel index that integer texel coordinate `i` reads in an axis of `n` texels.
    pub fn texel(self, i: i64, n: i64) -> i64 {
        match self {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::MirroredRepeat => {
                let k = i.rem_euclid(2 * n);
                if k < n {
                    k
                } else {
                    2 * n - 1 - k
                }
            }
            Wrap::ClampToEdge => i.clamp(0, n - 1),
        }
    }

    /// From a glTF wrap constant (10497 REPEAT, 33648 MIRRORED_REPEAT, 33071 CLAMP_TO_EDGE).
    pub fn from_gltf(w: gltf::texture::WrappingMode) -> Self {
        use gltf::texture::WrappingMode as M;
        match w {
            M::Repeat => Wrap::Repeat,
            M::MirroredRepeat => Wrap::MirroredRepeat,
            M::ClampToEdge => Wrap::ClampToEdge,
        }
    }
}

/// How a texture is sampled (glTF `samplers`). The default, for textures without a sampler, is
/// what glTF leaves to the implementation: linear filtering with linear mipmaps, repeating.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Sampler {
    /// Magnification filter.
    pub mag: Filter,
    /// Minification filter within a mip level.
    pub min: Filter,
    /// Between mip levels: None samples the base level only (glTF's NEAREST and LINEAR min
    /// filters); else the filter across levels.
    pub mipmap: Option<Filter>,
    /// Along u.
    pub wrap_u: Wrap,
    /// Along v.
    pub wrap_v: Wrap,
}

impl Default for Sampler {
    fn default() -> Self {
        Self {
            mag: Filter::Linear,
            min: Filter::Linear,
            mipmap: Some(Filter::Linear),
            wrap_u: Wrap::Repeat,
            wrap_v: Wrap::Repeat,
        }
    }
}

impl Sampler {
    /// From a glTF sampler (absent filters take the implementation default).
    pub fn from_gltf(s: &gltf::texture::Sampler) -> Self {
        use gltf::texture::{MagFilter, MinFilter};
        let mag = match s.mag_filter() {
            Some(MagFilter::Nearest) => Filter::Nearest,
            _ => Filter::Linear,
        };
        let (min, mipmap) = match s.min_filter() {
            Some(MinFilter::Nearest) => (Filter::Nearest, None),
            Some(MinFilter::Linear) => (Filter::Linear, None),
            Some(MinFilter::NearestMipmapNearest) => (Filter::Nearest, Some(Filter::Nearest)),
            Some(MinFilter::LinearMipmapNearest) => (Filter::Linear, Some(Filter::Nearest)),
            Some(MinFilter::NearestMipmapLinear) => (Filter::Nearest, Some(Filter::Linear)),
            Some(MinFilter::LinearMipmapLinear) | None => (Filter::Linear, Some(Filter::Linear)),
        };
        Self {
            mag,
            min,
            mipmap,
            wrap_u: Wrap::from_gltf(s.wrap_s()),
            wrap_v: Wrap::from_gltf(s.wrap_t()),
        }
    }
}

/// A KHR_texture_transform: texture coordinates become offset + R(rotation) · (scale ⊙ uv), where
/// R turns u towards −v (u' = cos·u + sin·v, v' = −sin·u + cos·v): the Khronos glTF Sample
/// Viewer's and three.js's matrix.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvTransform {
    /// Added last.
    pub offset: glam::Vec2,
    /// Radians.
    pub rotation: f32,
    /// Applied first, per component.
    pub scale: glam::Vec2,
}

impl Default for UvTransform {
    fn default() -> Self {
        Self {
            offset: glam::Vec2::ZERO,
            rotation: 0.0,
            scale: glam::Vec2::ONE,
        }
    }
}

impl UvTransform {
    /// The two rows of the affine map: u' = rows.0 · (u, v, 1), v' = rows.1 · (u, v, 1).
    pub fn rows(&self) -> (glam::Vec3, glam::Vec3) {
        let (s, c) = self.rotation.sin_cos();
        (
            glam::Vec3::new(c * self.scale.x, s * self.scale.y, self.offset.x),
            glam::Vec3::new(-s * self.scale.x, c * self.scale.y, self.offset.y),
        )
    }

    /// The transformed coordinates of `uv`.
    pub fn apply(&self, uv: glam::Vec2) -> glam::Vec2 {
        let (r0, r1) = self.rows();
        let p = uv.extend(1.0);
        glam::Vec2::new(r0.dot(p), r1.dot(p))
    }

    /// From a KHR_texture_transform JSON object (absent or malformed fields keep their defaults;
    /// non-finite values are ignored).
    pub fn from_json(v: &serde_json::Value) -> Self {
        let pair = |k: &str, d: glam::Vec2| {
            v.get(k)
                .and_then(|a| a.as_array())
                .filter(|a| a.len() == 2)
                .and_then(|a| {
                    Some(glam::Vec2::new(
                        a[0].as_f64()? as f32,
                        a[1].as_f64()? as f32,
                    ))
                })
                .filter(|p| p.is_finite())
                .unwrap_or(d)
        };
        let mut t = Self::default();
        t.offset = pair("offset", t.offset);
        t.scale = pair("scale", t.scale);
        if let Some(r) = v.get("rotation").and_then(|r| r.as_f64()) {
            if r.is_finite() {
                t.rotation = r as f32;
            }
        }
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uv_transform_follows_the_extension() {
        use glam::Vec2;
        // The extension's example: the lower-left quadrant, rotated 90°.
        let t = UvTransform::from_json(&serde_json::json!({
            "offset": [0, 1], "rotation": std::f64::consts::FRAC_PI_2, "scale": [0.5, 0.5]}));
        // u' = 0 + (0.5·v), v' = 1 − 0.5·u.
        for (uv, want) in [
            (Vec2::new(0.0, 0.0), Vec2::new(0.0, 1.0)),
            (Vec2::new(1.0, 0.0), Vec2::new(0.0, 0.5)),
            (Vec2::new(0.0, 1.0), Vec2::new(0.5, 1.0)),
        ] {
            assert!(
                (t.apply(uv) - want).length() < 1e-6,
                "{uv} → {}",
                t.apply(uv)
            );
        }
        assert_eq!(
            UvTransform::default().apply(Vec2::new(0.3, 0.7)),
            Vec2::new(0.3, 0.7)
        );
        let bad = UvTransform::from_json(&serde_json::json!({"scale": [1], "rotation": "x"}));
        assert_eq!(bad, UvTransform::default());
    }

    #[test]
    fn wrap_modes_map_texels() {
        let n = 4;
        let row = |w: Wrap| (-5..9).map(|i| w.texel(i, n)).collect::<Vec<_>>();
        assert_eq!(
            row(Wrap::Repeat),
            [3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0]
        );
        assert_eq!(
            row(Wrap::MirroredRepeat),
            [3, 3, 2, 1, 0, 0, 1, 2, 3, 3, 2, 1, 0, 0]
        );
        assert_eq!(
            row(Wrap::ClampToEdge),
            [0, 0, 0, 0, 0, 0, 1, 2, 3, 3, 3, 3, 3, 3]
        );
    }
}
