//! Viewer actions on the view settings, from keys (steps and cycles) and from the panel's
//! widgets (values set directly), as pure logic; each returns the line to print. A key and the
//! widget that sets the same value leave the same view, so they draw the same frame.

use glam::Vec3;
use umbra::plan::{Pcf, PostAa, ShadowMethod, Tonemap, View, ViewMode, MAX_CASCADES};
use umbra::scene::Light;

/// What a key or a panel widget does to the view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Action {
    /// Sun azimuth −5° (left arrow).
    SunLeft,
    /// Sun azimuth +5° (right arrow).
    SunRight,
    /// Sun elevation +5° (up arrow).
    SunUp,
    /// Sun elevation −5° (down arrow).
    SunDown,
    /// Halve the shadow map (`[`).
    MapSmaller,
    /// Double the shadow map (`]`).
    MapLarger,
    /// Next PCF kernel (`K`).
    CyclePcf,
    /// All biases ×1.25 (`=`/`+`).
    BiasUp,
    /// All biases ÷1.25 (`-`).
    BiasDown,
    /// Next debug view: lit, shadow, normals, shadow map, cascades (`V`).
    CycleView,
    /// Toggle shadows (`H`).
    ToggleShadows,
    /// Next cascade count: automatic, 1, 2, 3, 4 (`N`).
    CycleCascades,
    /// Next tone-mapping curve: PBR Neutral, ACES, none (`T`).
    CycleTonemap,
    /// FXAA on/off (`Y`; `View::post_aa`).
    ToggleFxaa,
    /// Shadow maps → exact → hybrid shadows (`M`; `ShadowSettings::method`).
    ToggleMethod,
    /// Contact shadows on/off (`B`; `ShadowSettings::contact`).
    ToggleContact,
    /// Exposure half a stop up (`.`).
    ExposureUp,
    /// Exposure half a stop down (`,`).
    ExposureDown,
    /// Cascades fitted to the depths seen on/off (`G`; `ShadowSettings::depth_fit`).
    ToggleDepthFit,
    /// Soft shadows (PCSS) for lights with a size on/off (`J`; `ShadowSettings::soft`).
    ToggleSoft,
    /// The sun at these angles (the panel's sliders).
    SetSun(SunAngles),
    /// Shadow map of this side (64…8192).
    SetMapSize(u32),
    /// This PCF kernel.
    SetPcf(Pcf),
    /// This shadow method.
    SetMethod(ShadowMethod),
    /// This cascade count (0: automatic).
    SetCascades(u32),
    /// This debug view.
    SetView(ViewMode),
    /// This tone curve.
    SetTonemap(Tonemap),
    /// Exposure compensation in stops.
    SetExposure(f32),
    /// Constant bias (texels), slope bias and normal offset (texels).
    SetBiases(f32, f32, f32),
}

/// The sun as elevation/azimuth in degrees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunAngles {
    /// Degrees above the horizon.
    pub elevation: f32,
    /// Degrees around +Y from +Z.
    pub azimuth: f32,
}

impl SunAngles {
    /// The angles of a light travelling along `direction`.
    pub fn from_direction(direction: Vec3) -> Self {
        let to_sun = -direction.normalize_or(Vec3::NEG_Y);
        Self {
            elevation: to_sun.y.clamp(-1.0, 1.0).asin().to_degrees(),
            azimuth: to_sun.x.atan2(to_sun.z).to_degrees(),
        }
    }

    /// The direction the light travels.
    pub fn direction(&self) -> Vec3 {
        Light::sun_direction(self.elevation.to_radians(), self.azimuth.to_radians())
    }
}

/// The views `V` cycles through, in order.
pub const VIEW_CYCLE: [ViewMode; 14] = [
    ViewMode::Lit,
    ViewMode::Shadow,
    ViewMode::Normals,
    ViewMode::ShadowMap,
    ViewMode::Cascades,
    ViewMode::TexelDensity,
    ViewMode::UvChecker,
    ViewMode::Tangents,
    ViewMode::Bitangents,
    ViewMode::BaseColor,
    ViewMode::Metallic,
    ViewMode::Roughness,
    ViewMode::Depth,
    ViewMode::Overdraw,
];

/// Applies `a` to the view (and the sun angles); returns a one-line description of the change.
pub fn apply(a: Action, view: &mut View, sun: &mut SunAngles) -> String {
    if let Some(line) = apply_set(a, view, sun) {
        return line;
    }
    match step(a, view, sun) {
        Some(set) => apply(set, view, sun),
        None => toggle(a, view),
    }
}

/// The setting a stepping action (a key that moves a setting to its next value) sets, or None
/// for a toggle.
fn step(a: Action, view: &View, sun: &mut SunAngles) -> Option<Action> {
    let s = &view.shadow;
    Some(match a {
        Action::SunLeft | Action::SunRight | Action::SunUp | Action::SunDown => {
            match a {
                Action::SunLeft => sun.azimuth -= 5.0,
                Action::SunRight => sun.azimuth += 5.0,
                Action::SunUp => sun.elevation = (sun.elevation + 5.0).min(90.0),
                _ => sun.elevation = (sun.elevation - 5.0).max(-90.0),
            }
            Action::SetSun(*sun)
        }
        Action::MapSmaller => Action::SetMapSize((s.map_size / 2).max(64)),
        Action::MapLarger => Action::SetMapSize((s.map_size * 2).min(8192)),
        Action::CyclePcf => Action::SetPcf(match s.pcf {
            Pcf::None => Pcf::P2x2,
            Pcf::P2x2 => Pcf::P3x3,
            Pcf::P3x3 => Pcf::P5x5,
            Pcf::P5x5 => Pcf::None,
        }),
        Action::CycleView => {
            let i = VIEW_CYCLE.iter().position(|m| *m == view.mode).unwrap_or(0);
            Action::SetView(VIEW_CYCLE[(i + 1) % VIEW_CYCLE.len()])
        }
        Action::CycleCascades => Action::SetCascades((s.cascades + 1) % (MAX_CASCADES + 1)),
        Action::CycleTonemap => Action::SetTonemap(match view.tonemap {
            Tonemap::Neutral => Tonemap::Aces,
            Tonemap::Aces => Tonemap::None,
            Tonemap::None => Tonemap::Neutral,
        }),
        Action::ToggleMethod => Action::SetMethod(match view.shadow.method {
            ShadowMethod::Map => ShadowMethod::Exact,
            ShadowMethod::Exact => ShadowMethod::Hybrid,
            ShadowMethod::Hybrid => ShadowMethod::Map,
        }),
        Action::ExposureUp | Action::ExposureDown => {
            let step = if a == Action::ExposureUp { 0.5 } else { -0.5 };
            Action::SetExposure(view.exposure_compensation + step)
        }
        _ => return None,
    })
}

/// Applies a toggle (or the bias keys) and returns the line that reports it.
fn toggle(a: Action, view: &mut View) -> String {
    let on_off = |on: bool| if on { "on" } else { "off" };
    let s = &mut view.shadow;
    match a {
        Action::BiasUp | Action::BiasDown => {
            let k = if a == Action::BiasUp { 1.25 } else { 0.8 };
            s.constant_bias *= k;
            s.slope_bias *= k;
            s.normal_offset *= k;
            bias_line(s)
        }
        Action::ToggleShadows => {
            s.enabled = !s.enabled;
            format!("shadows: {}", on_off(s.enabled))
        }
        Action::ToggleDepthFit => {
            s.depth_fit = !s.depth_fit;
            format!(
                "cascades fitted to: {}",
                if s.depth_fit {
                    "the depths seen (last frame read back)"
                } else {
                    "the scene's boxes in view"
                }
            )
        }
        Action::ToggleSoft => {
            s.soft = !s.soft;
            format!(
                "soft shadows (PCSS) for lights with a size: {}",
                on_off(s.soft)
            )
        }
        Action::ToggleContact => {
            s.contact = !s.contact;
            format!(
                "contact shadows: {}",
                if s.contact {
                    "on (hard shadows; not with exact shadows)"
                } else {
                    "off"
                }
            )
        }
        Action::ToggleFxaa => {
            view.post_aa = match view.post_aa {
                PostAa::None => PostAa::Fxaa,
                PostAa::Fxaa => PostAa::None,
            };
            format!("FXAA: {}", on_off(view.post_aa == PostAa::Fxaa))
        }
        _ => unreachable!("set and stepping actions are applied by apply_set and step"),
    }
}

/// Applies the panel's set actions (None for the keys' steps and cycles).
fn apply_set(a: Action, view: &mut View, sun: &mut SunAngles) -> Option<String> {
    let s = &mut view.shadow;
    Some(match a {
        Action::SetSun(angles) => {
            *sun = SunAngles {
                elevation: angles.elevation.clamp(-90.0, 90.0),
                azimuth: (angles.azimuth + 540.0).rem_euclid(360.0) - 180.0,
            };
            view.sun_direction = Some(sun.direction());
            format!(
                "sun: elevation {:.0}°, azimuth {:.0}°{}",
                sun.elevation,
                sun.azimuth,
                horizon_note(sun.elevation)
            )
        }
        Action::SetMapSize(n) => {
            s.map_size = n.clamp(64, 8192);
            format!("shadow map: {0}x{0}", s.map_size)
        }
        Action::SetPcf(k) => {
            s.pcf = k;
            format!("PCF: {:?}", s.pcf)
        }
        Action::SetMethod(m) => {
            s.method = m;
            match m {
                ShadowMethod::Map => "shadows: maps".to_string(),
                ShadowMethod::Exact => {
                    "shadows: exact (one shadowed light; maps otherwise)".to_string()
                }
                ShadowMethod::Hybrid => {
                    "shadows: hybrid (the map where it is certain, traced elsewhere)".to_string()
                }
            }
        }
        Action::SetCascades(n) => {
            s.cascades = n.min(MAX_CASCADES);
            match s.cascades {
                0 => "cascades: automatic (1, 2 or 4 by texel size; one map of twice the side in place of 2 where that suffices)".into(),
                n => format!("cascades: {n}"),
            }
        }
        Action::SetView(m) => {
            view.mode = m;
            format!("view: {:?}", view.mode)
        }
        Action::SetTonemap(t) => {
            view.tonemap = t;
            format!("tone mapping: {:?}", view.tonemap)
        }
        Action::SetExposure(ev) => {
            view.exposure_compensation = ev.clamp(-16.0, 16.0);
            format!(
                "exposure compensation: {:+.1} EV",
                view.exposure_compensation
            )
        }
        Action::SetBiases(c, sl, n) => {
            (s.constant_bias, s.slope_bias, s.normal_offset) = (c, sl, n);
            bias_line(s)
        }
        _ => return None,
    })
}

/// What the sun's elevation means for what it lights.
fn horizon_note(elevation: f32) -> &'static str {
    if elevation < 0.0 {
        " (below the horizon: upward faces unlit, the shadow map fitted from below)"
    } else if elevation < 1.0 {
        " (on the horizon: upward faces unlit)"
    } else {
        ""
    }
}

/// The biases, as printed.
fn bias_line(s: &umbra::plan::ShadowSettings) -> String {
    format!(
        "bias: constant {:.2} texels, slope {:.2}, normal offset {:.2} texels",
        s.constant_bias, s.slope_bias, s.normal_offset
    )
}

/// The next light whose visibility the shadow view shows (`L`), of a frame with `lights` lights
/// (the plan falls back to the first shadowed light where that light has no views).
pub fn next_shadow_light(view: &mut View, lights: usize) -> String {
    let next = view.shown_light.map_or(0, |i| i + 1);
    view.shown_light = (next < lights).then_some(next);
    match view.shown_light {
        Some(i) => format!("shadow view: light {i} (the first shadowed light if it casts none)"),
        None => "shadow view: the first shadowed light".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use umbra::scene::Camera;

    fn view() -> View {
        View::new(Camera::look_at(
            Vec3::new(0.0, 1.0, 5.0),
            Vec3::ZERO,
            0.8,
            0.1,
        ))
    }

    #[test]
    fn sun_keys_rotate_and_clamp() {
        let mut v = view();
        let mut sun = SunAngles {
            elevation: 30.0,
            azimuth: 0.0,
        };
        let msg = apply(Action::SunUp, &mut v, &mut sun);
        assert_eq!(sun.elevation, 35.0);
        assert!(msg.contains("elevation 35"));
        let d = v.sun_direction.unwrap();
        assert!((SunAngles::from_direction(d).elevation - 35.0).abs() < 1e-3);
        for _ in 0..7 {
            apply(Action::SunDown, &mut v, &mut sun);
        }
        let msg = apply(Action::SunDown, &mut v, &mut sun);
        assert_eq!(sun.elevation, -5.0);
        assert!(msg.contains("below the horizon"), "{msg}");
        for _ in 0..40 {
            apply(Action::SunDown, &mut v, &mut sun);
        }
        assert_eq!(sun.elevation, -90.0, "clamped straight up");
        for _ in 0..72 {
            apply(Action::SunRight, &mut v, &mut sun);
        }
        assert!(sun.azimuth.abs() < 1e-3, "full turn: {}", sun.azimuth);
    }

    #[test]
    fn map_size_pcf_bias_and_view_cycle() {
        let mut v = view();
        let mut sun = SunAngles {
            elevation: 30.0,
            azimuth: 0.0,
        };
        apply(Action::MapLarger, &mut v, &mut sun);
        assert_eq!(v.shadow.map_size, 4096);
        for _ in 0..10 {
            apply(Action::MapSmaller, &mut v, &mut sun);
        }
        assert_eq!(v.shadow.map_size, 64);
        let pcf = v.shadow.pcf;
        for _ in 0..4 {
            apply(Action::CyclePcf, &mut v, &mut sun);
        }
        assert_eq!(v.shadow.pcf, pcf, "four kernels cycle");
        let b = v.shadow.normal_offset;
        apply(Action::BiasUp, &mut v, &mut sun);
        assert!((v.shadow.normal_offset - b * 1.25).abs() < 1e-6);
        let mut seen = vec![v.mode];
        for _ in 0..VIEW_CYCLE.len() {
            apply(Action::CycleView, &mut v, &mut sun);
            seen.push(v.mode);
        }
        assert_eq!(&seen[..5], &VIEW_CYCLE[..5]);
        assert_eq!(seen[14], ViewMode::Lit, "the cycle closes");
        let mut distinct = seen[..14].to_vec();
        distinct.dedup();
        assert_eq!(distinct.len(), 14, "every view once");
        assert!(apply(Action::ToggleShadows, &mut v, &mut sun).contains("off"));
        // N: automatic, 1, 2, 3, 4, automatic.
        let counts: Vec<u32> = (0..5)
            .map(|_| {
                apply(Action::CycleCascades, &mut v, &mut sun);
                v.shadow.cascades
            })
            .collect();
        assert_eq!(counts, [1, 2, 3, 4, 0]);
        let fit = v.shadow.depth_fit;
        apply(Action::ToggleDepthFit, &mut v, &mut sun);
        assert_eq!(v.shadow.depth_fit, !fit);
        let soft = v.shadow.soft;
        apply(Action::ToggleSoft, &mut v, &mut sun);
        assert_eq!(v.shadow.soft, !soft);
        let curves: Vec<Tonemap> = (0..3)
            .map(|_| {
                apply(Action::CycleTonemap, &mut v, &mut sun);
                v.tonemap
            })
            .collect();
        assert_eq!(curves, [Tonemap::Aces, Tonemap::None, Tonemap::Neutral]);
        assert!(apply(Action::ToggleFxaa, &mut v, &mut sun).contains("on"));
        assert_eq!(v.post_aa, PostAa::Fxaa);
        apply(Action::ToggleFxaa, &mut v, &mut sun);
        assert_eq!(v.post_aa, PostAa::None);
        assert!(apply(Action::ToggleContact, &mut v, &mut sun).contains("on"));
        assert!(v.shadow.contact);
        apply(Action::ToggleContact, &mut v, &mut sun);
        assert!(!v.shadow.contact);
        assert!(apply(Action::ToggleMethod, &mut v, &mut sun).contains("exact"));
        assert_eq!(v.shadow.method, ShadowMethod::Exact);
        assert!(apply(Action::ToggleMethod, &mut v, &mut sun).contains("hybrid"));
        assert_eq!(v.shadow.method, ShadowMethod::Hybrid);
        apply(Action::ToggleMethod, &mut v, &mut sun);
        assert_eq!(v.shadow.method, ShadowMethod::Map);
        apply(Action::ExposureUp, &mut v, &mut sun);
        apply(Action::ExposureUp, &mut v, &mut sun);
        apply(Action::ExposureDown, &mut v, &mut sun);
        assert_eq!(v.exposure_compensation, 0.5);
        // L: lights 0, 1, then back to the default.
        let shown: Vec<Option<usize>> = (0..3)
            .map(|_| {
                next_shadow_light(&mut v, 2);
                v.shown_light
            })
            .collect();
        assert_eq!(shown, [Some(0), Some(1), None]);
    }
}
