//! Mip chains of RGBA8 images, computed on the CPU: each level a 2×2 box filter of the one
//! above (the last row or column repeated where a side is odd), in linear light for sRGB images
//! (alpha is always linear). On lavapipe this replaces a chain of linear blits, whose blitter
//! shaders llvmpipe compiles afresh in every process (its shader cache does not keep them).

use super::tonemap::{linear_to_srgb, srgb_to_linear};
use std::sync::OnceLock;

/// A full mip chain: level 0 first, each level's RGBA8 texels row by row, levels back to back.
#[derive(Clone, Debug, PartialEq)]
pub struct MipChain {
    /// (width, height, byte offset in `bytes`) of each level.
    pub levels: Vec<(u32, u32, usize)>,
    /// All levels' texels.
    pub bytes: Vec<u8>,
}

/// sRGB-encoded 8-bit value → linear light in 16-bit fixed point (0..=65535).
fn decode_table() -> &'static [u16; 256] {
    static T: OnceLock<[u16; 256]> = OnceLock::new();
    T.get_or_init(|| {
        let mut t = [0u16; 256];
        for (i, v) in t.iter_mut().enumerate() {
            *v = (srgb_to_linear(i as f32 / 255.0) * 65535.0).round() as u16;
        }
        t
    })
}

/// Linear light in 16-bit fixed point → the nearest sRGB-encoded 8-bit value.
fn encode_table() -> &'static [u8] {
    static T: OnceLock<Vec<u8>> = OnceLock::new();
    T.get_or_init(|| {
        (0..=65535u32)
            .map(|l| (linear_to_srgb(l as f32 / 65535.0) * 255.0).round() as u8)
            .collect()
    })
}

/// The full chain of a `width`×`height` RGBA8 image (`rgba` row by row; short data reads as
/// zeros), down to 1×1. `srgb`: colour channels averaged in linear light.
pub fn mip_chain(width: u32, height: u32, rgba: &[u8], srgb: bool) -> MipChain {
    let (w0, h0) = (width.max(1), height.max(1));
    let n = super::mip_levels(w0, h0);
    let mut levels = Vec::with_capacity(n as usize);
    let mut total = 0usize;
    let (mut w, mut h) = (w0, h0);
    for _ in 0..n {
        levels.push((w, h, total));
        total += w as usize * h as usize * 4;
        (w, h) = ((w / 2).max(1), (h / 2).max(1));
    }
    let mut bytes = vec![0u8; total];
    let base = w0 as usize * h0 as usize * 4;
    let m = base.min(rgba.len());
    bytes[..m].copy_from_slice(&rgba[..m]);
    // Each level is filtered from the one above it, kept in 16-bit linear light (level 1 read
    // straight from the 8-bit base, so no 16-bit copy of the largest level is made).
    let dec = decode_table();
    let enc = encode_table();
    let mut cur: Vec<u16> = Vec::new();
    for k in 1..levels.len() {
        let (pw, ph, _) = levels[k - 1];
        let (lw, lh, off) = levels[k];
        let next = if k == 1 {
            let base = &bytes[..base];
            downsample(
                |i| {
                    let v = base[i];
                    if srgb && i % 4 != 3 {
                        dec[v as usize] as u32
                    } else {
                        v as u32 * 257
                    }
                },
                (pw, ph),
                (lw, lh),
            )
        } else {
            downsample(|i| cur[i] as u32, (pw, ph), (lw, lh))
        };
        for (i, v) in next.iter().enumerate() {
            bytes[off + i] = if srgb && i % 4 != 3 {
                enc[*v as usize]
            } else {
                ((*v as u32 + 128) / 257) as u8
            };
        }
        cur = next;
    }
    MipChain { levels, bytes }
}

/// One level of `to` texels, each the rounded mean of the 2×2 block of the `from`-sized level
/// above it (`src(i)`: channel value i of that level, row by row, 16-bit linear; the last row or
/// column repeated where a side is odd).
fn downsample(src: impl Fn(usize) -> u32, from: (u32, u32), to: (u32, u32)) -> Vec<u16> {
    let (pw, ph) = (from.0 as usize, from.1 as usize);
    let (lw, lh) = (to.0 as usize, to.1 as usize);
    let mut next = vec![0u16; lw * lh * 4];
    for y in 0..lh {
        let (r0, r1) = ((2 * y).min(ph - 1) * pw, (2 * y + 1).min(ph - 1) * pw);
        for x in 0..lw {
            let (c0, c1) = ((2 * x).min(pw - 1), (2 * x + 1).min(pw - 1));
            for ch in 0..4 {
                let s = src((r0 + c0) * 4 + ch)
                    + src((r0 + c1) * 4 + ch)
                    + src((r1 + c0) * 4 + ch)
                    + src((r1 + c1) * 4 + ch);
                next[(y * lw + x) * 4 + ch] = ((s + 2) / 4) as u16;
            }
        }
    }
    next
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_halve_down_to_one_texel() {
        let c = mip_chain(5, 2, &[0; 40], false);
        let sizes: Vec<_> = c.levels.iter().map(|l| (l.0, l.1)).collect();
        assert_eq!(sizes, [(5, 2), (2, 1), (1, 1)]);
        assert_eq!(c.bytes.len(), (10 + 2 + 1) * 4);
        assert_eq!(c.levels[2].2, 12 * 4);
    }

    #[test]
    fn linear_levels_are_box_averages() {
        // 2×2: a black, a white and two grey texels (alpha 0, 255, 100, 100).
        let px = [
            0, 0, 0, 0, 255, 255, 255, 255, 100, 100, 100, 100, 101, 101, 101, 100,
        ];
        let c = mip_chain(2, 2, &px, false);
        let top = &c.bytes[c.levels[1].2..];
        // (0 + 255 + 100 + 101) / 4 = 114; alpha (0 + 255 + 100 + 100) / 4 = 113.75.
        assert_eq!(top, [114, 114, 114, 114]);
    }

    #[test]
    fn srgb_levels_average_in_linear_light() {
        // Black and white stripes average to linear 0.5: sRGB 188, not 128.
        let mut px = Vec::new();
        for _ in 0..2 {
            px.extend_from_slice(&[0, 0, 0, 255, 255, 255, 255, 255]);
        }
        let c = mip_chain(2, 2, &px, true);
        assert_eq!(&c.bytes[c.levels[1].2..], [188, 188, 188, 255]);
        let l = mip_chain(2, 2, &px, false);
        assert_eq!(&l.bytes[l.levels[1].2..], [128, 128, 128, 255]);
    }

    #[test]
    fn a_flat_image_stays_flat_at_every_level() {
        for srgb in [false, true] {
            let px: Vec<u8> = [37u8, 128, 201, 77].repeat(7 * 3);
            let c = mip_chain(7, 3, &px, srgb);
            assert!(
                c.bytes.chunks_exact(4).all(|p| p == [37, 128, 201, 77]),
                "srgb {srgb}"
            );
        }
    }

    #[test]
    fn tables_round_trip_every_srgb_value() {
        let (d, e) = (decode_table(), encode_table());
        for v in 0..=255usize {
            assert_eq!(e[d[v] as usize] as usize, v);
        }
    }
}
