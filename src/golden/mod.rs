//! Golden images for frame-capture tests (feature `golden`, off by default).
//!
//! [`assert_frame`] compares a [`Capture`] (the lit image and, beside it, the shadow view) with
//! a stored PNG under a [`Tolerance`]: NVIDIA's FLIP per pixel (the `nv-flip` crate), a count of
//! pixels allowed over a per-pixel threshold, a mean, and a count of pixels allowed to change
//! their shadow verdict. On failure it writes `NAME.actual.png` and `NAME.diff.png` (the FLIP
//! heat map) beside the golden, with `NAME.actual.shadow.png` and `NAME.shadow-diff.png` when
//! the golden keeps a shadow view, and `NAME.failure.json` (the line and the figures, what
//! `umbra report` shows), and panics with one line of figures that says apart what changed in
//! the shadows and what changed in the shading. A later match or blessing removes them.
//!
//! **Where goldens live.** `assert_frame(&c, "tests/golden/demo.png", …)` reads
//! `tests/golden/<class>/demo.png`, `<class>` the device class ([`device_class`]: `lavapipe`,
//! `nvidia`, `amd`, `intel`, …), and falls back to `tests/golden/demo.png`, a golden shared by
//! every device. The shadow view sits beside each as `demo.shadow.png`.
//!
//! **Blessing.** With `UMBRA_BLESS=1`, a missing or failing golden is written (to the class
//! folder) and the check passes; a matching one is left alone. Without it a missing golden
//! fails, naming the path to bless. Under CI (`CI` set, not `0`/`false`) `UMBRA_BLESS` is
//! refused and fails the check: CI never blesses.

mod compare;

pub use compare::Figures;

use crate::plan::{View, ViewMode};
use crate::render::Renderer;
use crate::Context;
use image::RgbaImage;
use std::path::{Path, PathBuf};

/// How close counts as equal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    /// The FLIP value (0–1) over which a pixel counts as changed; 0: any byte that differs.
    pub pixel_flip: f32,
    /// Pixels allowed over `pixel_flip`.
    pub pixels_over: usize,
    /// The largest mean FLIP over the image.
    pub mean_flip: f32,
    /// Pixels allowed to change their shadow verdict (lit or in shadow in the shadow view).
    pub shadow_changes: usize,
}

impl Tolerance {
    /// The same bytes, lit image and shadow view: a frame on the device that wrote the golden.
    pub const EXACT: Tolerance = Tolerance {
        pixel_flip: 0.0,
        pixels_over: 0,
        mean_flip: 0.0,
        shadow_changes: 0,
    };
    /// What a driver or compiler update may move and a person does not see: no pixel over FLIP
    /// 0.1 beyond 0.1 % of the image (at least 4), mean FLIP 0.005, and shadow verdicts on at
    /// most 0.05 % of the pixels (at least 2; edges rounding the other way). Give the image's
    /// pixel count.
    pub fn close(pixels: usize) -> Tolerance {
        Tolerance {
            pixel_flip: 0.1,
            pixels_over: (pixels / 1000).max(4),
            mean_flip: 0.005,
            shadow_changes: (pixels / 2000).max(2),
        }
    }
}

/// A frame as a golden keeps it: the lit image, the shadow view beside it where there is one, and
/// the device class that drew them.
#[derive(Clone, Debug)]
pub struct Capture {
    /// The image.
    pub lit: RgbaImage,
    /// The shadowed light's visibility term (`ViewMode::Shadow`): 255 lit, 0 in shadow.
    pub shadow: Option<RgbaImage>,
    /// Where the golden is looked for first (`device_class`).
    pub device_class: String,
}

impl Capture {
    /// Renders `view` twice: as asked, and as the shadow view.
    pub fn render(
        r: &mut Renderer,
        view: &View,
        width: u32,
        height: u32,
    ) -> Result<Capture, crate::GpuError> {
        let lit = r.render(view, width, height)?.image;
        let shadow_view = View {
            mode: ViewMode::Shadow,
            ..view.clone()
        };
        let shadow = r.render(&shadow_view, width, height)?.image;
        Ok(Capture {
            lit,
            shadow: Some(shadow),
            device_class: device_class(r.context()),
        })
    }

    /// An image without a shadow view (compared by FLIP alone).
    pub fn image(lit: RgbaImage, device_class: &str) -> Capture {
        Capture {
            lit,
            shadow: None,
            device_class: device_class.into(),
        }
    }
}

/// The class of device whose goldens a frame is compared with: `lavapipe` (Mesa's CPU driver),
/// `cpu` (another CPU driver), or the GPU vendor (`nvidia`, `amd`, `intel`, `apple`, `arm`,
/// `qualcomm`, `vendor-XXXX`).
pub fn device_class(ctx: &Context) -> String {
    if ctx.is_cpu() {
        return if ctx.device_name.contains("llvmpipe") {
            "lavapipe".into()
        } else {
            "cpu".into()
        };
    }
    match ctx.properties.vendor_id {
        0x10DE => "nvidia".into(),
        0x1002 => "amd".into(),
        0x8086 => "intel".into(),
        0x106B => "apple".into(),
        0x13B5 => "arm".into(),
        0x5143 => "qualcomm".into(),
        v => format!("vendor-{v:04x}"),
    }
}

/// Whether goldens may be written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bless {
    /// Compare only.
    Off,
    /// Write missing and failing goldens.
    On,
    /// Asked for under CI: every check fails.
    RefusedUnderCi,
}

impl Bless {
    /// From `UMBRA_BLESS` and `CI` (see the module's documentation).
    pub fn from_env() -> Bless {
        let var = |k| std::env::var(k).ok();
        Bless::from_values(var("UMBRA_BLESS").as_deref(), var("CI").as_deref())
    }

    /// From the values of `UMBRA_BLESS` and `CI` (None: unset).
    pub fn from_values(bless: Option<&str>, ci: Option<&str>) -> Bless {
        let on = |v: Option<&str>| v.is_some_and(|v| !matches!(v, "" | "0" | "false"));
        match (on(bless), on(ci)) {
            (false, _) => Bless::Off,
            (true, false) => Bless::On,
            (true, true) => Bless::RefusedUnderCi,
        }
    }
}

/// What a check ended in.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// Within the tolerance (the figures against the golden).
    Matched(Figures),
    /// Written: missing, or failing while blessing (the figures it failed with).
    Blessed {
        /// The golden written.
        path: PathBuf,
        /// The figures against the golden it replaced, if there was one.
        replaced: Option<Figures>,
    },
}

/// A failed check: one line to print, the figures and the files written.
#[derive(Clone, Debug, PartialEq)]
pub struct Mismatch {
    /// One line: the golden, what changed, by how much, against what was allowed.
    pub reason: String,
    /// The figures (None where there was nothing to compare).
    pub figures: Option<Figures>,
    /// The actual and diff images written beside the golden.
    pub written: Vec<PathBuf>,
}

/// `assert_frame` without the panic, the blessing policy given.
pub fn check_frame(
    capture: &Capture,
    golden: impl AsRef<Path>,
    tolerance: Tolerance,
    bless: Bless,
) -> Result<Outcome, Mismatch> {
    let shared = golden.as_ref();
    let classed = class_path(shared, &capture.device_class);
    let fail = |reason: String| Mismatch {
        reason,
        figures: None,
        written: Vec::new(),
    };
    if bless == Bless::RefusedUnderCi {
        return Err(fail(format!(
            "{}: UMBRA_BLESS is refused under CI (CI is set): goldens are blessed on a \
             developer's machine and committed",
            shared.display()
        )));
    }
    let found = [classed.as_path(), shared]
        .into_iter()
        .find(|p| p.exists())
        .map(Path::to_path_buf);
    let Some(path) = found else {
        if bless == Bless::On {
            write_golden(capture, &classed).map_err(fail)?;
            return Ok(Outcome::Blessed {
                path: classed,
                replaced: None,
            });
        }
        return Err(fail(format!(
            "no golden at {} or {}; run with UMBRA_BLESS=1 to write {}",
            classed.display(),
            shared.display(),
            classed.display()
        )));
    };
    let (figures, compared) = compare::against(capture, &path, &tolerance).map_err(fail)?;
    let Some(why) = figures.exceeds(&tolerance) else {
        compare::remove_failure(&path);
        return Ok(Outcome::Matched(figures));
    };
    if bless == Bless::On {
        compare::remove_failure(&path);
        write_golden(capture, &classed).map_err(fail)?;
        return Ok(Outcome::Blessed {
            path: classed,
            replaced: Some(figures),
        });
    }
    let mut written = compare::write_failure(capture, &path, compared).map_err(fail)?;
    written.push(beside(&path, "failure.json"));
    let names: Vec<String> = written
        .iter()
        .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .collect();
    let reason = format!("{}: {why}; wrote {}", path.display(), names.join(", "));
    let json = compare::failure_json(&reason, &figures, &tolerance, &capture.device_class);
    let json_path = beside(&path, "failure.json");
    std::fs::write(&json_path, format!("{json:#}\n"))
        .map_err(|e| fail(format!("{}: {e}", json_path.display())))?;
    Err(Mismatch {
        reason,
        figures: Some(figures),
        written,
    })
}

/// Compares `capture` with the golden at `golden` (its device class's first, then the shared
/// one) under `tolerance`, blessing as `UMBRA_BLESS` and `CI` say; panics with one line on a
/// mismatch. Returns what happened.
pub fn assert_frame(capture: &Capture, golden: impl AsRef<Path>, tolerance: Tolerance) -> Outcome {
    match check_frame(capture, golden, tolerance, Bless::from_env()) {
        Ok(o) => o,
        Err(m) => panic!("{}", m.reason),
    }
}

/// `dir/<class>/name.png` for `dir/name.png`.
fn class_path(shared: &Path, class: &str) -> PathBuf {
    let dir = shared.parent().unwrap_or(Path::new(""));
    dir.join(class).join(shared.file_name().unwrap_or_default())
}

/// `stem.suffix` beside `path` (`a/b.png`, `shadow.png` → `a/b.shadow.png`).
fn beside(path: &Path, suffix: &str) -> PathBuf {
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    path.with_file_name(format!("{stem}.{suffix}"))
}

/// Writes the capture as the golden at `path` (and its shadow view beside it).
fn write_golden(capture: &Capture, path: &Path) -> Result<(), String> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    let save = |img: &RgbaImage, p: &Path| img.save(p).map_err(|e| format!("{}: {e}", p.display()));
    save(&capture.lit, path)?;
    if let Some(s) = &capture.shadow {
        save(s, &beside(path, "shadow.png"))?;
    }
    Ok(())
}
