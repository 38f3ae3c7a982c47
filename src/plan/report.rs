//! The shadow plan of a view as JSON, for `umbra inspect`: which light casts, the map size and
//! format, each shadow view (cascade) with the depth it covers and its texel's world size, how
//! many draws fall inside it, and the memory the maps take.

use crate::math::Aabb;
use crate::plan::settings::ShadowFormat;
use crate::plan::view::View;
use crate::scene::{LightKind, Scene};
use glam::Mat4;
use serde_json::{json, Value};

/// Whether `b` lies inside the x/y extent of `clip` (depth ignored: casters between the light and
/// the view's near plane still cast, the pass clamps their depth).
fn inside_xy(b: &Aabb, clip: &Mat4) -> bool {
    let r = clip.transpose();
    let planes = [
        r.w_axis + r.x_axis,
        r.w_axis - r.x_axis,
        r.w_axis + r.y_axis,
        r.w_axis - r.y_axis,
    ];
    !planes.iter().any(|p| {
        let n = p.truncate();
        let v = glam::Vec3::select(n.cmpge(glam::Vec3::ZERO), b.max, b.min);
        n.dot(v) + p.w < 0.0
    })
}

/// How `view` of `scene` is exposed: the exposure mode, what auto exposure metered (lux, as
/// luminance), the resolved EV100 and linear scale, the ambient and the tone curve.
pub fn exposure_report(scene: &Scene, view: &View, w: u32, h: u32) -> Value {
    let planner = crate::plan::ScenePlanner::new(scene);
    let plan = planner.plan(view, w, h);
    let mode = match view.exposure {
        crate::plan::view::Exposure::Auto => "auto".to_string(),
        crate::plan::view::Exposure::Ev100(ev) => format!("EV100 {ev}"),
        crate::plan::view::Exposure::Scale(k) => format!("scale {k}"),
    };
    json!({
        "mode": mode,
        "metered_lux": plan.metered_lux,
        "ev100": crate::math::tonemap::ev100_from_exposure(plan.exposure),
        "scale": plan.exposure,
        "compensation_ev": view.exposure_compensation,
        "ambient": plan.ambient.sky.to_array(),
        "ambient_ground": plan.ambient.ground.to_array(),
        "tonemap": format!("{:?}", view.tonemap),
    })
}

/// The shadow plan of `view` at `w`×`h` (the CPU side of a frame; no GPU needed).
pub fn plan_report(scene: &Scene, view: &View, w: u32, h: u32) -> Value {
    let planner = crate::plan::ScenePlanner::new(scene);
    let draws = planner.receivers();
    let plan = planner.plan(view, w, h);
    let Some(li) = plan.shadow_light.filter(|_| plan.shadows_on) else {
        return json!({"light": null, "reason": "no light casts a shadow (or shadows are off)"});
    };
    let l = &plan.lights[li];
    let kind = match l.kind {
        LightKind::Directional => "directional",
        LightKind::Spot { .. } => "spot",
        LightKind::Point => "point",
    };
    let bytes_per_texel = match plan.shadow_format {
        ShadowFormat::D16 => 2u64,
        _ => 4,
    };
    let size = plan.shadow_map_size() as u64;
    let mut near = view.camera.near;
    let views: Vec<Value> = plan
        .primary_views()
        .iter()
        .map(|v| {
            let casters = draws
                .iter()
                .filter(|b| inside_xy(b, &v.light_clip_from_world))
                .count();
            let out = json!({"from_depth": near, "to_depth": if v.far.is_finite() { json!(v.far) } else { json!(null) },
                             "texel_world": v.texel_world, "draws_inside": casters});
            near = v.far;
            out
        })
        .collect();
    json!({
        "light": li,
        "light_type": kind,
        "map_texels": size,
        "format": match plan.shadow_format { ShadowFormat::D16 => "D16", _ => "D32" },
        "cascades": plan.primary_views().len(),
        "views": views,
        "texel_world_nearest": plan.primary_views().first().map(|v| v.texel_world),
        "texel_world_farthest": plan.primary_views().last().map(|v| v.texel_world),
        "shadowed_lights": (0..plan.lights.len()).filter(|&i| plan.is_shadowed(i)).collect::<Vec<_>>(),
        "unshadowed_lights": plan.unshadowed,
        "layers": plan.shadow_views.len(),
        "gpu_bytes": size * size * bytes_per_texel * plan.shadow_views.len().max(1) as u64,
        "image": [w, h],
    })
}
