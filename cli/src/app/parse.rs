//! Parsers of the command line's values (sizes, times, vectors, on/off, …): each returns a one-line
//! message for clap on bad input.

use glam::Vec3;
use umbra::render::{Background, Exposure};

/// A frame rate within 0.001..=10000.
pub(crate) fn parse_fps(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(f) if (0.001..=10_000.0).contains(&f) => Ok(f),
        _ => Err(format!("'{s}' is not a frame rate within 0.001..10000")),
    }
}

/// A finite time in seconds.
pub(crate) fn parse_time(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(t) if t.is_finite() => Ok(t),
        _ => Err(format!("'{s}' is not a finite number of seconds")),
    }
}

/// `on` or `off`.
pub(crate) fn parse_on_off(s: &str) -> Result<bool, String> {
    match s {
        "on" => Ok(true),
        "off" => Ok(false),
        _ => Err(format!("expected on or off, got '{s}'")),
    }
}

/// `WxH`, each side 1..=`MAX_SIDE`.
pub(crate) fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("'{s}' is not WxH"))?;
    let w: u32 = w
        .trim()
        .parse()
        .map_err(|_| format!("bad width in '{s}'"))?;
    let h: u32 = h
        .trim()
        .parse()
        .map_err(|_| format!("bad height in '{s}'"))?;
    if w == 0 || h == 0 {
        return Err(format!("size {w}x{h} must be at least 1x1"));
    }
    if w > umbra::render::MAX_SIDE || h > umbra::render::MAX_SIDE {
        return Err(format!(
            "size {w}x{h} exceeds {0}x{0}",
            umbra::render::MAX_SIDE
        ));
    }
    Ok((w, h))
}

/// 1, 2, 4 or 8.
pub(crate) fn parse_msaa(s: &str) -> Result<u32, String> {
    match s.trim().parse::<u32>() {
        Ok(n @ (1 | 2 | 4 | 8)) => Ok(n),
        _ => Err(format!("'{s}' is not 1, 2, 4 or 8 samples")),
    }
}

/// One finite value ≥ 0 (grey) or R,G,B.
pub(crate) fn parse_ambient(s: &str) -> Result<Vec3, String> {
    let v = match s.trim().parse::<f32>() {
        Ok(g) => Vec3::splat(g),
        Err(_) => parse_vec3(s)?,
    };
    if !(v.is_finite() && v.min_element() >= 0.0) {
        return Err(format!("ambient '{s}' must be finite and >= 0"));
    }
    Ok(v)
}

/// `sky`, or a display (sRGB) colour: `#RRGGBB`, or `R,G,B` / one grey value within 0..1,
/// returned as the linear colour the background is cleared to.
pub(crate) fn parse_background(s: &str) -> Result<Background, String> {
    let t = s.trim();
    if t.eq_ignore_ascii_case("sky") {
        return Ok(Background::Sky);
    }
    let srgb = if let Some(hex) = t.strip_prefix('#') {
        let byte = |i: usize| {
            hex.get(i..i + 2)
                .and_then(|b| u8::from_str_radix(b, 16).ok())
                .map(|b| b as f32 / 255.0)
        };
        match (hex.len(), byte(0), byte(2), byte(4)) {
            (6, Some(r), Some(g), Some(b)) => Vec3::new(r, g, b),
            _ => return Err(format!("background '{s}' is not #RRGGBB")),
        }
    } else {
        match t.parse::<f32>() {
            Ok(g) => Vec3::splat(g),
            Err(_) => parse_vec3(t)?,
        }
    };
    if !(srgb.is_finite() && srgb.min_element() >= 0.0 && srgb.max_element() <= 1.0) {
        return Err(format!(
            "background '{s}' must be sky, #RRGGBB or R,G,B within 0..1"
        ));
    }
    Ok(Background::Color(
        srgb.map(umbra::math::tonemap::srgb_to_linear),
    ))
}

/// `auto`, an EV100 number, or `x` and a linear scale.
pub(crate) fn parse_exposure(s: &str) -> Result<Exposure, String> {
    let t = s.trim();
    if t.eq_ignore_ascii_case("auto") {
        return Ok(Exposure::Auto);
    }
    if let Some(k) = t.strip_prefix(['x', 'X']) {
        return match k.trim().parse::<f32>() {
            Ok(v) if v.is_finite() && v > 0.0 => Ok(Exposure::Scale(v)),
            _ => Err(format!("exposure scale '{k}' must be a number above 0")),
        };
    }
    match t.parse::<f32>() {
        Ok(v) if v.is_finite() && v.abs() <= 64.0 => Ok(Exposure::Ev100(v)),
        _ => Err(format!(
            "'{s}' is not `auto`, an EV100 within -64..64, or `x` and a scale (e.g. x1)"
        )),
    }
}

pub(crate) fn parse_budget(s: &str) -> Result<f64, String> {
    let t = s.trim();
    let v = match t.strip_suffix('%') {
        Some(p) => p.trim().parse::<f64>().map(|v| v / 100.0),
        None => t.parse::<f64>(),
    }
    .map_err(|_| format!("'{s}' is not a fraction or a percentage"))?;
    if !(v.is_finite() && v > 0.0 && v < 1.0) {
        return Err(format!("budget {s} must be above 0 and below 100%"));
    }
    Ok(v)
}

pub(crate) fn parse_vec3(s: &str) -> Result<Vec3, String> {
    let parts: Vec<&str> = s.split(',').collect();
    if parts.len() != 3 {
        return Err(format!("'{s}' is not X,Y,Z"));
    }
    let mut v = [0.0f32; 3];
    for (i, p) in parts.iter().enumerate() {
        v[i] = p
            .trim()
            .parse()
            .map_err(|_| format!("'{p}' is not a number"))?;
        if !v[i].is_finite() {
            return Err(format!("'{p}' is not finite"));
        }
    }
    Ok(Vec3::from_array(v))
}
