//! A capture against a golden: FLIP over the lit image, shadow verdicts over the shadow view, and
//! the images a failure leaves.

use super::{beside, Capture, Tolerance};
use image::{RgbImage, RgbaImage};
use std::path::{Path, PathBuf};

/// What differs between a capture and its golden.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Figures {
    /// Pixels in the image.
    pub pixels: usize,
    /// Pixels whose colour bytes differ at all.
    pub differing: usize,
    /// Mean FLIP over the lit image.
    pub mean_flip: f32,
    /// Pixels over the tolerance's `pixel_flip` (`differing` where that is 0).
    pub pixels_over: usize,
    /// The threshold `pixels_over` counts against.
    pub pixel_flip: f32,
    /// Pixels whose shadow verdict changed (None: the golden or the capture has no shadow
    /// view), and of them, those now in shadow.
    pub shadow_changes: Option<(usize, usize)>,
}

impl Figures {
    /// Why they exceed `t`, in words and figures; None when within it.
    pub fn exceeds(&self, t: &Tolerance) -> Option<String> {
        let mut shading = Vec::new();
        if self.mean_flip > t.mean_flip {
            shading.push(format!(
                "mean FLIP {:.4} (allowed {})",
                self.mean_flip, t.mean_flip
            ));
        }
        if self.pixels_over > t.pixels_over {
            shading.push(format!(
                "{} pixels over FLIP {} (allowed {})",
                self.pixels_over, t.pixel_flip, t.pixels_over
            ));
        }
        let shadows = self
            .shadow_changes
            .filter(|&(n, _)| n > t.shadow_changes)
            .map(|(n, dark)| {
                format!(
                    "{n} pixels changed their shadow verdict ({dark} now in shadow, {} now lit; \
                     allowed {})",
                    n - dark,
                    t.shadow_changes
                )
            });
        if shading.is_empty() && shadows.is_none() {
            return None;
        }
        let shadows = shadows.unwrap_or_else(|| match self.shadow_changes {
            Some((n, _)) => format!("shadows within tolerance ({n} verdicts changed)"),
            None => "no shadow view to compare".into(),
        });
        let shading = if shading.is_empty() {
            format!("shading within tolerance (mean FLIP {:.4})", self.mean_flip)
        } else {
            format!("shading changed: {}", shading.join(", "))
        };
        Some(format!(
            "{shadows}; {shading} ({} of {} pixels differ)",
            self.differing, self.pixels
        ))
    }
}

fn load(path: &Path) -> Result<RgbaImage, String> {
    image::open(path)
        .map(|i| i.to_rgba8())
        .map_err(|e| format!("{}: {e}", path.display()))
}

fn rgb(img: &RgbaImage) -> Vec<u8> {
    img.pixels().flat_map(|p| [p[0], p[1], p[2]]).collect()
}

/// Per-pixel FLIP of `test` against `reference` (same size).
fn flip(reference: &RgbaImage, test: &RgbaImage) -> nv_flip::FlipImageFloat {
    let (w, h) = reference.dimensions();
    let r = nv_flip::FlipImageRgb8::with_data(w, h, &rgb(reference));
    let t = nv_flip::FlipImageRgb8::with_data(w, h, &rgb(test));
    nv_flip::flip(r, t, nv_flip::DEFAULT_PIXELS_PER_DEGREE)
}

/// Whether a shadow-view pixel is lit (the visibility term at least a half).
fn lit(p: &image::Rgba<u8>) -> bool {
    p[0] >= 128
}

/// What a comparison read and computed, kept for the failure's images: the golden and the FLIP
/// map (None where no colour differed).
pub(super) struct Compared {
    golden: RgbaImage,
    flip: Option<nv_flip::FlipImageFloat>,
}

/// The capture against the golden at `path` (and its shadow view beside it, if both have one).
pub(super) fn against(
    c: &Capture,
    path: &Path,
    t: &Tolerance,
) -> Result<(Figures, Compared), String> {
    let golden = load(path)?;
    if golden.dimensions() != c.lit.dimensions() {
        let (gw, gh) = golden.dimensions();
        let (w, h) = c.lit.dimensions();
        return Err(format!(
            "{}: the frame is {w}x{h}, the golden {gw}x{gh}",
            path.display()
        ));
    }
    let differs = |a: &image::Rgba<u8>, b: &image::Rgba<u8>| a.0[..3] != b.0[..3];
    let differing = golden
        .pixels()
        .zip(c.lit.pixels())
        .filter(|(a, b)| differs(a, b))
        .count();
    let map = (differing > 0).then(|| flip(&golden, &c.lit));
    let (mean_flip, over) = match &map {
        None => (0.0, 0),
        Some(m) => {
            let err = m.to_vec();
            let mean = err.iter().map(|&e| e as f64).sum::<f64>() / err.len() as f64;
            let over = err.iter().filter(|&&e| e > t.pixel_flip).count();
            (mean as f32, over)
        }
    };
    let shadow_path = beside(path, "shadow.png");
    let shadow_changes = match (&c.shadow, shadow_path.exists()) {
        (Some(s), true) => {
            let g = load(&shadow_path)?;
            if g.dimensions() != s.dimensions() {
                return Err(format!("{}: another size", shadow_path.display()));
            }
            let (mut n, mut dark) = (0, 0);
            for (a, b) in g.pixels().zip(s.pixels()) {
                if lit(a) != lit(b) {
                    n += 1;
                    dark += usize::from(lit(a));
                }
            }
            Some((n, dark))
        }
        _ => None,
    };
    let figures = Figures {
        pixels: golden.len() / 4,
        differing,
        mean_flip,
        pixels_over: if t.pixel_flip == 0.0 { differing } else { over },
        pixel_flip: t.pixel_flip,
        shadow_changes,
    };
    Ok((figures, Compared { golden, flip: map }))
}

/// Writes `NAME.actual.png`, `NAME.diff.png` (FLIP heat map, magma) and, with shadow views,
/// `NAME.actual.shadow.png` and `NAME.shadow-diff.png` (red: now in shadow, blue: now lit, the
/// golden's verdicts dimmed elsewhere) beside the golden at `path`, from what `against` read.
pub(super) fn write_failure(
    c: &Capture,
    path: &Path,
    compared: Compared,
) -> Result<Vec<PathBuf>, String> {
    let save = |img: &dyn Fn(&Path) -> image::ImageResult<()>, p: PathBuf| {
        img(&p).map_err(|e| format!("{}: {e}", p.display()))?;
        Ok::<PathBuf, String>(p)
    };
    let Compared { golden, flip: map } = compared;
    let (w, h) = golden.dimensions();
    let mut written = vec![save(&|p| c.lit.save(p), beside(path, "actual.png"))?];
    let map = map.unwrap_or_else(|| flip(&golden, &c.lit));
    let heat = map.apply_color_lut(&nv_flip::magma_lut());
    let heat = RgbImage::from_raw(w, h, heat.to_vec()).ok_or("FLIP heat map size")?;
    written.push(save(&|p| heat.save(p), beside(path, "diff.png"))?);
    let shadow_path = beside(path, "shadow.png");
    if let (Some(s), true) = (&c.shadow, shadow_path.exists()) {
        let g = load(&shadow_path)?;
        written.push(save(&|p| s.save(p), beside(path, "actual.shadow.png"))?);
        let diff = RgbImage::from_fn(w, h, |x, y| {
            let (a, b) = (g.get_pixel(x, y), s.get_pixel(x, y));
            match (lit(a), lit(b)) {
                (true, false) => image::Rgb([230, 40, 40]),
                (false, true) => image::Rgb([40, 80, 230]),
                _ => image::Rgb([a[0] / 3; 3]),
            }
        });
        written.push(save(&|p| diff.save(p), beside(path, "shadow-diff.png"))?);
    }
    Ok(written)
}

/// The suffixes of the files a failure leaves beside its golden.
const FAILURE_FILES: [&str; 5] = [
    "actual.png",
    "diff.png",
    "actual.shadow.png",
    "shadow-diff.png",
    "failure.json",
];

/// Removes what an earlier failure left beside the golden at `path` (a stale `NAME.actual.png`
/// would show as a failure in `umbra report`). Files that are not there are no error.
pub(super) fn remove_failure(path: &Path) {
    for suffix in FAILURE_FILES {
        let _ = std::fs::remove_file(beside(path, suffix));
    }
}

/// `NAME.failure.json`: the one-line reason, the figures and the tolerance (schema
/// `umbra-golden-failure/1`).
pub(super) fn failure_json(
    reason: &str,
    f: &Figures,
    t: &Tolerance,
    device_class: &str,
) -> serde_json::Value {
    serde_json::json!({
        "schema": "umbra-golden-failure/1",
        "reason": reason,
        "device_class": device_class,
        "figures": {
            "pixels": f.pixels,
            "differing": f.differing,
            "mean_flip": f.mean_flip,
            "pixels_over": f.pixels_over,
            "pixel_flip": f.pixel_flip,
            "shadow_changes": f.shadow_changes.map(|(n, _)| n),
            "now_in_shadow": f.shadow_changes.map(|(_, d)| d),
        },
        "tolerance": {
            "pixel_flip": t.pixel_flip,
            "pixels_over": t.pixels_over,
            "mean_flip": t.mean_flip,
            "shadow_changes": t.shadow_changes,
        },
    })
}
