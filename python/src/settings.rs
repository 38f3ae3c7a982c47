//! `render`'s keyword settings, mirroring the command line's options: shadows (method, map size,
//! format, filter, cascades, depth fit, biases, budget, the light shown), image (exposure, tone curve,
//! ambient, background), the sun, and time.

use glam::Vec3;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use umbra::plan::{Background, Exposure, PostAa, ShadowFit, Tonemap, View, SUPERSAMPLE_FACTORS};

/// What a frame is rendered with besides the view: the error budget, the light whose visibility
/// `shadow` holds, and the scene's time.
#[derive(Clone, Debug, Default)]
pub struct Extras {
    /// Misclassified-pixel budget (a fraction) the shadow settings are chosen for.
    pub budget: Option<f64>,
    /// Seconds into `animation` to pose the scene at.
    pub time: Option<f32>,
    /// The animation: an index or a name (`all` for every one), the first when None.
    pub animation: Option<String>,
}

/// The names `render` takes, for the error a misspelt one gets.
pub const NAMES: &[&str] = &[
    "shadows",
    "shadow_map",
    "shadow_format",
    "shadow_method",
    "contact_shadows",
    "pcf",
    "cascades",
    "depth_fit",
    "fit",
    "bias_constant",
    "bias_slope",
    "normal_offset",
    "shadow_budget",
    "shadow_light",
    "light_size",
    "exposure",
    "tonemap",
    "post_aa",
    "supersample",
    "ambient",
    "background",
    "sun_direction",
    "sun_intensity",
    "time",
    "animation",
];

fn invalid(name: &str, e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(format!("{name}: {e}"))
}

/// Applies the keyword `settings` to `view`; returns what is not part of a view.
pub fn apply(view: &mut View, settings: Option<&Bound<'_, PyDict>>) -> PyResult<Extras> {
    let mut extras = Extras::default();
    let Some(settings) = settings else {
        return Ok(extras);
    };
    for (k, v) in settings.iter() {
        let name: String = k.extract()?;
        if !shadow_setting(&mut view.shadow, &name, &v)?
            && !view_setting(view, &mut extras, &name, &v)?
        {
            return Err(PyTypeError::new_err(format!(
                "unknown setting '{name}' (one of {})",
                NAMES.join(", ")
            )));
        }
    }
    Ok(extras)
}

/// Applies setting `name` = `v` when it is one of the shadow map's; false when it is not.
fn shadow_setting(
    s: &mut umbra::ShadowSettings,
    name: &str,
    v: &Bound<'_, PyAny>,
) -> PyResult<bool> {
    let text = || -> PyResult<String> { v.str().map(|s| s.to_string()) };
    match name {
        "shadows" => s.enabled = v.extract()?,
        "shadow_map" => {
            let n: u32 = v.extract()?;
            let range = umbra::ShadowSettings::MAP_SIZES;
            if !range.contains(&n) {
                return Err(invalid(name, format!("{n} outside {range:?}")));
            }
            s.map_size = n;
        }
        "shadow_format" => {
            s.format = text()?.parse().map_err(|e| invalid(name, e))?;
        }
        "shadow_method" => {
            s.method = text()?.parse().map_err(|e| invalid(name, e))?;
        }
        "contact_shadows" => s.contact = v.extract()?,
        "pcf" => s.pcf = text()?.parse().map_err(|e| invalid(name, e))?,
        "cascades" => {
            let n: u32 = v.extract()?;
            if n > umbra::plan::MAX_CASCADES {
                return Err(invalid(name, format!("{n} is above 4")));
            }
            s.cascades = n;
        }
        "depth_fit" => s.depth_fit = v.extract()?,
        "fit" => {
            s.fit = match text()?.as_str() {
                "camera" => ShadowFit::Camera,
                "sphere" => ShadowFit::Sphere,
                "scene" => ShadowFit::Scene,
                f => {
                    return Err(invalid(
                        name,
                        format!("'{f}' is not camera, sphere or scene"),
                    ))
                }
            }
        }
        "bias_constant" => s.constant_bias = finite(name, v.extract()?)?,
        "bias_slope" => s.slope_bias = finite(name, v.extract()?)?,
        "normal_offset" => s.normal_offset = finite(name, v.extract()?)?,
        _ => return Ok(false),
    }
    Ok(true)
}

/// Applies setting `name` = `v` when it is one of the view's or `extras`'; false when it is not.
fn view_setting(
    view: &mut View,
    extras: &mut Extras,
    name: &str,
    v: &Bound<'_, PyAny>,
) -> PyResult<bool> {
    let text = || -> PyResult<String> { v.str().map(|s| s.to_string()) };
    match name {
        "shadow_budget" => {
            // A percentage, as the command line takes `0.1%`.
            let p: f64 = v.extract()?;
            if !(0.0..100.0).contains(&p) {
                return Err(invalid(name, format!("{p} % must be within [0, 100)")));
            }
            extras.budget = Some(p / 100.0);
        }
        "shadow_light" => view.shown_light = v.extract()?,
        "light_size" => view.light_size = Some(finite(name, v.extract()?)?),
        "exposure" => {
            view.exposure = match v.extract::<f32>() {
                Ok(ev) => Exposure::Ev100(finite(name, ev)?),
                Err(_) => text()?.parse().map_err(|e| invalid(name, e))?,
            }
        }
        "tonemap" => view.tonemap = text()?.parse::<Tonemap>().map_err(|e| invalid(name, e))?,
        "post_aa" => view.post_aa = text()?.parse::<PostAa>().map_err(|e| invalid(name, e))?,
        "supersample" => {
            let f: u32 = v.extract()?;
            if !SUPERSAMPLE_FACTORS.contains(&f) {
                return Err(invalid(
                    name,
                    format!("{f} is not one of {SUPERSAMPLE_FACTORS:?}"),
                ));
            }
            view.supersample = f;
        }
        "ambient" => view.ambient = Some(rgb(name, v)?),
        "background" => {
            view.background = match v.extract::<[f32; 3]>() {
                Ok(c) => format!("{},{},{}", c[0], c[1], c[2]).parse(),
                Err(_) => text()?.parse::<Background>(),
            }
            .map_err(|e| invalid(name, e))?
        }
        "sun_direction" => {
            let d = Vec3::from(v.extract::<[f32; 3]>()?);
            if !(d.is_finite() && d.length_squared() > 0.0) {
                return Err(invalid(name, "must be finite and not zero"));
            }
            view.sun_direction = Some(d);
        }
        "sun_intensity" => view.sun_intensity = Some(finite(name, v.extract()?)?),
        "time" => extras.time = Some(finite(name, v.extract()?)?),
        "animation" => extras.animation = Some(text()?),
        _ => return Ok(false),
    }
    Ok(true)
}

fn finite(name: &str, x: f32) -> PyResult<f32> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(invalid(name, format!("{x} is not finite")))
    }
}

/// One value ≥ 0 (grey) or three.
fn rgb(name: &str, v: &Bound<'_, PyAny>) -> PyResult<Vec3> {
    let c = match v.extract::<f32>() {
        Ok(g) => Vec3::splat(g),
        Err(_) => Vec3::from(v.extract::<[f32; 3]>()?),
    };
    if !(c.is_finite() && c.min_element() >= 0.0) {
        return Err(invalid(name, "must be finite and >= 0"));
    }
    Ok(c)
}
