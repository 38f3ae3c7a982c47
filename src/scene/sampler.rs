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

#[cfg(test)]
mod tests {
    use super::*;

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
