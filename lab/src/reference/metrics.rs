//! Accuracy of a GPU frame against the ray-cast reference: shadow misclassification (split into
//! false shadow and false light, at exact shadow edges and away from them) and image error (PSNR
//! and FLIP).

use super::raycast::ReferenceFrame;
use glam::Vec4;
use umbra::math::projection::pixel_to_ndc;
use umbra::plan::FramePlan;

/// Half-width, in pixels, of the band around exact shadow boundaries counted as "edge".
pub const EDGE_PIXELS: i32 = 2;

/// Comparison results. Fractions are of the judged pixels (visible surface where the GPU and
/// the reference see the same surface point).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Metrics {
    /// Fraction of judged pixels whose GPU visibility (at 0.5) differs from the exact one.
    pub misclassified: f64,
    /// Fraction wrongly in shadow (acne-like).
    pub false_shadow: f64,
    /// Fraction wrongly lit (leaks, peter-panning).
    pub false_light: f64,
    /// Misclassified fraction of judged pixels within `EDGE_PIXELS` of an exact shadow boundary.
    pub edge_misclassified: f64,
    /// Misclassified fraction of the other judged pixels.
    pub interior_misclassified: f64,
    /// PSNR (dB) of the GPU lit image against the reference image.
    pub psnr: f64,
    /// Mean FLIP error (0 = identical, 1 = maximal) of the GPU lit image against the reference.
    pub flip: f64,
    /// Mean FLIP error of the GPU shadow view (the shown light's visibility, grey) against the
    /// reference's fraction of that light's emitter visible: how close soft shadows come to
    /// the area light's (hard ones to the exact edge). None where no shadow view was compared.
    pub visibility_flip: Option<f64>,
    /// Pixels judged.
    pub judged_pixels: usize,
    /// Judged pixels in the edge band.
    pub edge_pixels: usize,
    /// Pixels left out because GPU and reference see different surfaces (silhouettes).
    pub coverage_mismatch: usize,
    /// Pixels left out because two faces lie where the surface seen lies and are judged
    /// differently: which one the GPU keeps is a depth tie ([`ReferenceFrame::coincident`]).
    pub coincident_surfaces: usize,
}

impl Metrics {
    /// The metrics as one JSON object.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "misclassified": self.misclassified,
            "false_shadow": self.false_shadow,
            "false_light": self.false_light,
            "edge_misclassified": self.edge_misclassified,
            "interior_misclassified": self.interior_misclassified,
            "psnr": self.psnr,
            "flip": self.flip,
            "visibility_flip": self.visibility_flip,
            "judged_pixels": self.judged_pixels,
            "edge_pixels": self.edge_pixels,
            "coverage_mismatch": self.coverage_mismatch,
            "coincident_surfaces": self.coincident_surfaces,
        })
    }
}

/// PSNR in dB of two same-size RGBA8 images over RGB (∞ when identical).
pub fn psnr(a: &image::RgbaImage, b: &image::RgbaImage) -> f64 {
    let mut se = 0.0f64;
    for (p, q) in a.pixels().zip(b.pixels()) {
        for c in 0..3 {
            let d = p[c] as f64 - q[c] as f64;
            se += d * d;
        }
    }
    let mse = se / (a.width() as f64 * a.height() as f64 * 3.0);
    if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (255.0f64 * 255.0 / mse).log10()
    }
}

/// Mean FLIP error of `test` against `reference` (NVIDIA's FLIP through the nv-flip crate).
pub fn flip(reference: &image::RgbaImage, test: &image::RgbaImage) -> f64 {
    let rgb = |img: &image::RgbaImage| {
        img.pixels()
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect::<Vec<u8>>()
    };
    let r =
        nv_flip::FlipImageRgb8::with_data(reference.width(), reference.height(), &rgb(reference));
    let t = nv_flip::FlipImageRgb8::with_data(test.width(), test.height(), &rgb(test));
    let err = nv_flip::flip(r, t, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    nv_flip::FlipPool::from_image(&err).mean() as f64
}

/// How one pixel's GPU shadow classification compares with the exact one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PixelClass {
    /// Not judged: GPU and reference see different surfaces (or nothing).
    Unjudged,
    /// GPU agrees with the exact visibility.
    Correct,
    /// GPU in shadow where the exact answer is lit (acne when away from edges).
    FalseShadow,
    /// GPU lit where the exact answer is in shadow (leaks, peter-panning).
    FalseLight,
}

/// Per-pixel comparison of a GPU shadow-visibility frame with the reference.
pub struct Classified {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The class of each pixel (row-major).
    pub class: Vec<PixelClass>,
    /// Within `EDGE_PIXELS` of an exact shadow boundary.
    pub edge: Vec<bool>,
    /// Pixels seen by exactly one of GPU and reference (left out).
    pub coverage_mismatch: usize,
    /// Pixels on coincident faces judged differently (left out: a depth tie).
    pub coincident: usize,
}

/// The pixels within [`EDGE_PIXELS`] of an exact shadow boundary (two neighbouring pixels whose
/// exact visibility differs) of a `w`×`h` visibility image.
pub fn edge_band(visibility: &[Option<bool>], w: u32, h: u32) -> Vec<bool> {
    let idx = |x: i32, y: i32| (y as u32 * w + x as u32) as usize;
    // Exact boundary pixels, then the band within EDGE_PIXELS of them.
    let mut boundary = vec![false; (w * h) as usize];
    for y in 0..h as i32 {
        for x in 0..w as i32 {
            let Some(v) = visibility[idx(x, y)] else {
                continue;
            };
            for (dx, dy) in [(1, 0), (0, 1)] {
                let (nx, ny) = (x + dx, y + dy);
                if nx < w as i32 && ny < h as i32 {
                    if let Some(u) = visibility[idx(nx, ny)] {
                        if u != v {
                            boundary[idx(x, y)] = true;
                            boundary[idx(nx, ny)] = true;
                        }
                    }
                }
            }
        }
    }
    let mut edge = vec![false; (w * h) as usize];
    for y in 0..h as i32 {
        for x in 0..w as i32 {
            if !boundary[idx(x, y)] {
                continue;
            }
            for dy in -EDGE_PIXELS..=EDGE_PIXELS {
                for dx in -EDGE_PIXELS..=EDGE_PIXELS {
                    let (nx, ny) = (x + dx, y + dy);
                    if nx >= 0 && ny >= 0 && nx < w as i32 && ny < h as i32 {
                        edge[idx(nx, ny)] = true;
                    }
                }
            }
        }
    }
    edge
}

/// Classifies every pixel of a GPU shadow-visibility frame (`gpu_shadow`, thresholded at 0.5, and
/// its depth buffer) against the reference for the same plan.
pub fn classify(
    gpu_shadow: &image::RgbaImage,
    gpu_depth: &[f32],
    plan: &FramePlan,
    reference: &ReferenceFrame,
) -> Classified {
    let (w, h) = (reference.width, reference.height);
    let inv = plan.clip_from_world.inverse();
    let eye = plan.camera_position;
    // Same surface point: both see something, at distances within 1% (+ a small absolute term).
    let same = |x: u32, y: u32| -> Option<bool> {
        let i = (y * w + x) as usize;
        let vis = reference.visibility[i]?;
        let d = gpu_depth[i];
        if d <= 0.0 {
            return None;
        }
        let n = pixel_to_ndc(x as f32 + 0.5, y as f32 + 0.5, w, h);
        let p = inv * Vec4::new(n.x, n.y, d, 1.0);
        let dist = (p.truncate() / p.w).distance(eye);
        let r = reference.distance[i];
        ((dist - r).abs() <= 0.01 * r + 1e-4).then_some(vis)
    };
    let edge = edge_band(&reference.visibility, w, h);
    let mut class = vec![PixelClass::Unjudged; (w * h) as usize];
    let mut coverage_mismatch = 0;
    let mut coincident = 0;
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let Some(exact) = same(x, y) else {
                if reference.visibility[i].is_some() || gpu_depth[i] > 0.0 {
                    coverage_mismatch += 1;
                }
                continue;
            };
            if reference.coincident[i] {
                coincident += 1;
                continue;
            }
            let gpu_lit = gpu_shadow.get_pixel(x, y)[0] >= 128;
            class[i] = match (exact, gpu_lit) {
                (true, false) => PixelClass::FalseShadow,
                (false, true) => PixelClass::FalseLight,
                _ => PixelClass::Correct,
            };
        }
    }
    Classified {
        width: w,
        height: h,
        class,
        edge,
        coverage_mismatch,
        coincident,
    }
}

/// Judged and misclassified pixels within one range of view depth (`misclassified_by_depth`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthBin {
    /// Nearest view depth of the bin.
    pub near: f32,
    /// Farthest view depth of the bin.
    pub far: f32,
    /// Pixels judged.
    pub judged: usize,
    /// Of which misclassified.
    pub wrong: usize,
}

impl DepthBin {
    /// Misclassified fraction (0 when nothing was judged).
    pub fn fraction(&self) -> f64 {
        if self.judged == 0 {
            0.0
        } else {
            self.wrong as f64 / self.judged as f64
        }
    }
}

/// Misclassification along the view depth of the shadow-fitting camera (the plan's cascade
/// axis): the judged pixels in `bins` log-spaced ranges between the nearest and farthest judged
/// depth, each with its count of misclassified pixels, so a spike at a cascade split shows.
pub fn misclassified_by_depth(
    c: &Classified,
    reference: &ReferenceFrame,
    plan: &FramePlan,
    bins: usize,
) -> Vec<DepthBin> {
    let (w, h) = (c.width, c.height);
    let inv = plan.clip_from_world.inverse();
    let eye = plan.camera_position;
    let (from, forward) = plan.split_eye_forward();
    let mut depths = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            if c.class[i] == PixelClass::Unjudged {
                continue;
            }
            let n = pixel_to_ndc(x as f32 + 0.5, y as f32 + 0.5, w, h);
            let q = inv * Vec4::new(n.x, n.y, 0.5, 1.0);
            let dir = ((q.truncate() / q.w) - eye).normalize_or_zero();
            let p = eye + dir * reference.distance[i];
            let d = (p - from).dot(forward);
            if d.is_finite() && d > 0.0 {
                depths.push((d, c.class[i] != PixelClass::Correct));
            }
        }
    }
    let (lo, hi) = depths
        .iter()
        .fold((f32::INFINITY, 0.0f32), |(a, b), &(d, _)| {
            (a.min(d), b.max(d))
        });
    let bins = bins.max(1);
    if depths.is_empty() {
        return Vec::new();
    }
    let hi = hi.max(lo * 1.0001);
    let edge = |k: usize| lo * (hi / lo).powf(k as f32 / bins as f32);
    let mut out: Vec<DepthBin> = (0..bins)
        .map(|k| DepthBin {
            near: edge(k),
            far: edge(k + 1),
            judged: 0,
            wrong: 0,
        })
        .collect();
    for (d, wrong) in depths {
        let k = (((d / lo).ln() / (hi / lo).ln()) * bins as f32).floor() as usize;
        let b = &mut out[k.min(bins - 1)];
        b.judged += 1;
        b.wrong += wrong as usize;
    }
    out
}

/// Compares a GPU frame (lit image, shadow view, depth buffer) with the reference for the same
/// plan. Returns the metrics and a difference image: the reference in grey, false shadow red,
/// false light blue.
pub fn compare(
    gpu_lit: &image::RgbaImage,
    gpu_shadow: &image::RgbaImage,
    gpu_depth: &[f32],
    plan: &FramePlan,
    reference: &ReferenceFrame,
) -> (Metrics, image::RgbaImage) {
    let c = classify(gpu_shadow, gpu_depth, plan, reference);
    let (mut m, diff) = summarise(&c, gpu_lit, reference);
    m.visibility_flip = Some(flip(&reference.coverage_image(), gpu_shadow));
    (m, diff)
}

/// The metrics and the difference image of classified pixels (see [`compare`]).
pub fn summarise(
    c: &Classified,
    gpu_lit: &image::RgbaImage,
    reference: &ReferenceFrame,
) -> (Metrics, image::RgbaImage) {
    let (w, h) = (c.width, c.height);
    let mut diff = image::RgbaImage::new(w, h);
    let (mut n, mut fs, mut fl, mut ne, mut me, mut mi) =
        (0usize, 0usize, 0usize, 0usize, 0usize, 0usize);
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let g = reference.image.get_pixel(x, y);
            let grey = ((g[0] as u32 + g[1] as u32 + g[2] as u32) / 6) as u8;
            diff.put_pixel(x, y, image::Rgba([grey, grey, grey, 255]));
            let k = c.class[i];
            if k == PixelClass::Unjudged {
                continue;
            }
            n += 1;
            let wrong = k != PixelClass::Correct;
            if c.edge[i] {
                ne += 1;
                me += wrong as usize;
            } else {
                mi += wrong as usize;
            }
            if k == PixelClass::FalseShadow {
                fs += 1;
                diff.put_pixel(x, y, image::Rgba([255, 0, 0, 255]));
            } else if k == PixelClass::FalseLight {
                fl += 1;
                diff.put_pixel(x, y, image::Rgba([0, 80, 255, 255]));
            }
        }
    }
    let frac = |a: usize, b: usize| if b == 0 { 0.0 } else { a as f64 / b as f64 };
    let m = Metrics {
        misclassified: frac(fs + fl, n),
        false_shadow: frac(fs, n),
        false_light: frac(fl, n),
        edge_misclassified: frac(me, ne),
        interior_misclassified: frac(mi, n - ne),
        psnr: psnr(gpu_lit, &reference.image),
        flip: flip(&reference.image, gpu_lit),
        visibility_flip: None,
        judged_pixels: n,
        edge_pixels: ne,
        coverage_mismatch: c.coverage_mismatch,
        coincident_surfaces: c.coincident,
    };
    (m, diff)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn psnr_and_flip_basics() {
        let a = image::RgbaImage::from_pixel(16, 16, image::Rgba([100, 150, 200, 255]));
        let mut b = a.clone();
        assert_eq!(psnr(&a, &b), f64::INFINITY);
        assert!(flip(&a, &b) < 1e-6);
        b.put_pixel(3, 3, image::Rgba([0, 0, 0, 255]));
        let p = psnr(&a, &b);
        assert!(p > 20.0 && p < 60.0, "{p}");
        assert!(flip(&a, &b) > 1e-4);
    }
}
