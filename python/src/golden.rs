//! `umbra._umbra.golden_check`: `umbra::golden::check_frame` for numpy frames, behind the pytest
//! plugin `umbra.testing`.

use crate::arrays::values;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use umbra::golden::{check_frame, Bless, Capture, Outcome, Tolerance};

pyo3::create_exception!(
    umbra,
    GoldenMismatch,
    crate::UmbraError,
    "A frame that does not match its golden image (the message is one line of figures)."
);

/// An (H, W, 3|4) uint8 colour array as an RGBA image.
fn color_image(obj: &Bound<'_, PyAny>) -> PyResult<image::RgbaImage> {
    let (w, h, rgba) = crate::arrays::rgba8(obj, "color")?;
    Ok(image::RgbaImage::from_raw(w, h, rgba).expect("sized by rgba8"))
}

/// An (H, W) float visibility array (the `shadow` output, 0–1) as the grey shadow view.
fn shadow_image(obj: &Bound<'_, PyAny>) -> PyResult<image::RgbaImage> {
    let (v, shape) = values::<f32>(obj, "float32", "shadow")?;
    let [h, w] = shape[..] else {
        return Err(PyValueError::new_err(format!(
            "shadow: shape {shape:?}, expected (H, W)"
        )));
    };
    let px = v
        .iter()
        .flat_map(|&s| {
            let b = (s.clamp(0.0, 1.0) * 255.0).round() as u8;
            [b, b, b, 255]
        })
        .collect();
    Ok(image::RgbaImage::from_raw(w as u32, h as u32, px).expect("sized above"))
}

/// Compares `color` (and `shadow`, the shadow visibility output) with the golden at `path`
/// (looked for first in the `device_class` folder beside it), under the tolerance given, blessing
/// when `bless`, refusing that under `ci`. Returns a dict (`outcome`: "matched" or "blessed",
/// `path`, and the figures); raises `GoldenMismatch` with one line.
#[pyfunction]
#[pyo3(signature = (color, path, shadow = None, device_class = "", pixel_flip = 0.0, pixels_over = 0, mean_flip = 0.0, shadow_changes = 0, bless = false, ci = false))]
#[allow(clippy::too_many_arguments)]
pub fn golden_check<'py>(
    py: Python<'py>,
    color: &Bound<'py, PyAny>,
    path: std::path::PathBuf,
    shadow: Option<&Bound<'py, PyAny>>,
    device_class: &str,
    pixel_flip: f32,
    pixels_over: usize,
    mean_flip: f32,
    shadow_changes: usize,
    bless: bool,
    ci: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let lit = color_image(color)?;
    let shadow = shadow.map(shadow_image).transpose()?;
    if shadow
        .as_ref()
        .is_some_and(|s| s.dimensions() != lit.dimensions())
    {
        return Err(PyValueError::new_err("shadow: not the colour image's size"));
    }
    let capture = Capture {
        lit,
        shadow,
        device_class: device_class.into(),
    };
    let tolerance = Tolerance {
        pixel_flip,
        pixels_over,
        mean_flip,
        shadow_changes,
    };
    let policy = Bless::from_values(bless.then_some("1"), ci.then_some("1"));
    let result = py.detach(|| check_frame(&capture, &path, tolerance, policy));
    let d = PyDict::new(py);
    match result {
        Ok(Outcome::Matched(f)) => {
            d.set_item("outcome", "matched")?;
            d.set_item("differing", f.differing)?;
            d.set_item("mean_flip", f.mean_flip)?;
            d.set_item("pixels_over", f.pixels_over)?;
            d.set_item("shadow_changes", f.shadow_changes.map(|c| c.0))?;
        }
        Ok(Outcome::Blessed { path, .. }) => {
            d.set_item("outcome", "blessed")?;
            d.set_item("path", path)?;
        }
        Err(m) => return Err(GoldenMismatch::new_err(m.reason)),
    }
    Ok(d)
}

/// Writes `umbra report`'s page for the folder `dir` (to `out`, else `dir/report.html`): failed
/// goldens side by side with a slider, a blink and zoom, and any `compare`, `sweep` and
/// `stability` outputs below it. Returns a dict (`path` and the counts found); raises `OSError`
/// with one line when the folder cannot be read or the page written.
#[pyfunction]
#[pyo3(signature = (dir, out = None))]
pub fn write_report<'py>(
    py: Python<'py>,
    dir: std::path::PathBuf,
    out: Option<std::path::PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    let s = py
        .detach(|| umbra_lab::report::write(&dir, out.as_deref()))
        .map_err(|e| pyo3::exceptions::PyOSError::new_err(e.to_string()))?;
    let d = PyDict::new(py);
    d.set_item("path", s.path)?;
    d.set_item("goldens", s.goldens)?;
    d.set_item("compares", s.compares)?;
    d.set_item("sweeps", s.sweeps)?;
    d.set_item("stabilities", s.stabilities)?;
    Ok(d)
}
