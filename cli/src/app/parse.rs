//! Parsers of the command line's values (sizes, times, vectors, on/off, …): each returns a one-line
//! message for clap on bad input.

use glam::Vec3;
use umbra::plan::{Background, Exposure};

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

/// `--background`: `Background`'s own parser.
pub(crate) fn parse_background(s: &str) -> Result<Background, String> {
    s.parse()
}

/// `--exposure`: `Exposure`'s own parser.
pub(crate) fn parse_exposure(s: &str) -> Result<Exposure, String> {
    s.parse()
}

pub(crate) fn parse_budget(s: &str) -> Result<f64, String> {
    let t = s.trim();
    let v = match t.strip_suffix('%') {
        Some(p) => p.trim().parse::<f64>().map(|v| v / 100.0),
        None => t.parse::<f64>(),
    }
    .map_err(|_| format!("'{s}' is not a fraction or a percentage"))?;
    if !(v.is_finite() && (0.0..1.0).contains(&v)) {
        return Err(format!("budget {s} must be at least 0 and below 100%"));
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
