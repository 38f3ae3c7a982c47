//! The lights a frame is shaded with, what auto exposure meters from them, and their uniforms.

use super::input::PlanScene;
use super::uniforms::{LightUniform, MAX_LIGHTS};
use super::view::{Ambient, Exposure, View, UNIT_AMBIENT};
use super::views::{soft_size, ShadowView};
use crate::math::Aabb;
use crate::scene::{Light, LightKind};
use crate::shader_consts::scene as sh;
use glam::{Vec3, Vec4};

/// Elevation of the default sun used when a scene has no light (degrees): a key light from the
/// viewer's upper left, in front of the model (the default view looks from +Z), so the model's
/// shadow falls behind it to the right, on the model and on a ground beside it.
pub const DEFAULT_SUN_ELEVATION_DEG: f32 = 35.0;

/// Azimuth of the default sun around +Y from +Z (degrees; negative towards −X, the default
/// view's left).
pub const DEFAULT_SUN_AZIMUTH_DEG: f32 = -60.0;

/// Intensity of the default sun.
pub const DEFAULT_SUN_INTENSITY: f32 = 1.7;

/// The lights a view is shaded with: the scene's `lights`, or the default sun when there are
/// none; `sun_direction` and `sun_intensity` override the first directional light's, and
/// `light_size` every light's size.
pub fn effective_lights(scene_lights: &[Light], view: &View) -> Vec<Light> {
    let mut lights = scene_lights.to_vec();
    if lights.is_empty() {
        lights.push(Light::sun(
            Light::sun_direction(
                DEFAULT_SUN_ELEVATION_DEG.to_radians(),
                DEFAULT_SUN_AZIMUTH_DEG.to_radians(),
            ),
            DEFAULT_SUN_INTENSITY,
        ));
    }
    if let Some(d) = view.sun_direction.and_then(|d| d.try_normalize()) {
        if let Some(l) = lights.iter_mut().find(|l| l.kind == LightKind::Directional) {
            l.direction = d;
        } else {
            lights.insert(0, Light::sun(d, DEFAULT_SUN_INTENSITY));
        }
    }
    if let Some(i) = view.sun_intensity.filter(|i| i.is_finite() && *i >= 0.0) {
        if let Some(l) = lights.iter_mut().find(|l| l.kind == LightKind::Directional) {
            l.intensity = i;
        }
    }
    if let Some(s) = view.light_size.filter(|s| s.is_finite() && *s >= 0.0) {
        for l in &mut lights {
            l.size = if l.kind == LightKind::Directional {
                s.to_radians()
            } else {
                s
            };
        }
    }
    lights.truncate(MAX_LIGHTS);
    lights
}

/// The ambient Ia (the view's flat one, else the sky and ground hemisphere sized by the metered
/// direct light), the metered illuminance, and the exposure scale. Metered once: the default
/// ambient follows the direct part, auto exposure the sum (the ambient's mean over directions).
pub(super) fn metering(lights: &[Light], scene: &PlanScene, view: &View) -> (Ambient, f32, f32) {
    let direct = metered_illuminance(lights, Vec3::ZERO, scene.receivers, scene.bounds);
    let ambient = match view.ambient {
        Some(a) => Ambient::flat(a),
        None if direct.is_finite() && direct > 0.0 => Ambient::metered(direct),
        None => Ambient::flat(Vec3::splat(UNIT_AMBIENT)),
    };
    let metered_lux = direct + luminance(ambient.mean().max(Vec3::ZERO));
    let exposure = exposure_scale(view.exposure, metered_lux)
        * view.exposure_compensation.clamp(-64.0, 64.0).exp2();
    (ambient, metered_lux, exposure)
}

/// Each light's uniform: kind, position, direction with its soft-shadow size, colour, cone and
/// range, and its shadow views.
pub(super) fn light_uniforms(
    lights: &[Light],
    views: &[ShadowView],
    view: &View,
) -> [LightUniform; MAX_LIGHTS] {
    let mut u = [LightUniform::default(); MAX_LIGHTS];
    for (i, l) in lights.iter().enumerate() {
        let (kind, cone) = match l.kind {
            LightKind::Directional => (sh::LIGHT_DIRECTIONAL, Vec4::ZERO),
            LightKind::Point => (sh::LIGHT_POINT, Vec4::ZERO),
            LightKind::Spot { inner, outer } => (
                sh::LIGHT_SPOT,
                Vec4::new(inner.cos(), outer.cos(), 0.0, 0.0),
            ),
        };
        // z: the range (0 = none).
        let cone = Vec4::new(cone.x, cone.y, l.range.unwrap_or(0.0), 0.0);
        let first = views.iter().position(|v| v.light == i);
        // w: the soft-shadow size (0: hard), as the penumbra formula takes it.
        let soft = if first.is_some() && view.shadow.soft {
            soft_size(l)
        } else {
            0.0
        };
        let count = views.iter().filter(|v| v.light == i).count();
        u[i] = LightUniform {
            position: l.position.extend(kind),
            direction: l.direction.normalize_or(Vec3::NEG_Y).extend(soft),
            color: (l.color * l.intensity).extend(0.0),
            cone,
            shadow: Vec4::new(first.map_or(-1.0, |f| f as f32), count as f32, 0.0, 0.0),
        };
    }
    u
}

/// The illuminance (lux, as luminance) that auto exposure meters: the median, over the
/// `receivers` (each draw's world box; the centre of `bounds` when there are none), of what the
/// lights deliver at the box's centre to a surface facing each (a directional light its
/// intensity; a point or spot light I / d², range-windowed, the spot's cone ignored, d at least
/// the box's half-diagonal, so a lamp inside a room is metered on the room's walls), plus the
/// ambient term. The median keeps one receiver next to a lamp from darkening the whole frame.
pub fn metered_illuminance(
    lights: &[Light],
    ambient: Vec3,
    receivers: &[Aabb],
    bounds: &Aabb,
) -> f32 {
    let at = |centre: Vec3, radius: f32| -> f32 {
        let min_d2 = (radius * radius).max(1e-12);
        lights
            .iter()
            .map(|l| {
                let i = luminance(l.color) * l.intensity.max(0.0);
                match l.kind {
                    LightKind::Directional => i,
                    _ => {
                        let d2 = l.position.distance_squared(centre).max(min_d2);
                        let window = l.range.map_or(1.0, |r| {
                            let q = d2 / (r * r).max(1e-30);
                            (1.0 - q * q).clamp(0.0, 1.0)
                        });
                        i * window / d2
                    }
                }
            })
            .sum()
    };
    let mut values: Vec<f32> = receivers
        .iter()
        .filter(|b| !b.is_empty())
        .map(|b| at(b.center(), 0.5 * b.diagonal()))
        .filter(|e| e.is_finite())
        .collect();
    if values.is_empty() {
        let (c, r) = if bounds.is_empty() {
            (Vec3::ZERO, 0.0)
        } else {
            (bounds.center(), 0.5 * bounds.diagonal())
        };
        values.push(at(c, r));
    }
    values.sort_by(f32::total_cmp);
    let n = values.len();
    let median = if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    };
    median + luminance(ambient.max(Vec3::ZERO))
}

/// Rec. 709 luminance of a linear colour.
pub(super) fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// The linear scale `exposure` sets for a scene whose auto exposure metered `metered_lux`
/// ([`metered_illuminance`]; scale 1 where nothing lights the scene).
pub fn exposure_scale(exposure: Exposure, metered_lux: f32) -> f32 {
    use crate::math::tonemap::{exposure_from_ev100, metered_ev100};
    let s = match exposure {
        Exposure::Auto => {
            if metered_lux.is_finite() && metered_lux > 0.0 {
                exposure_from_ev100(metered_ev100(metered_lux))
            } else {
                1.0
            }
        }
        Exposure::Ev100(ev) => exposure_from_ev100(ev),
        Exposure::Scale(s) => s,
    };
    if s.is_finite() && s > 0.0 {
        s
    } else {
        1.0
    }
}
