//! Precision: the same scene, camera and light translated far from the origin and scaled from
//! millimetres to tens of kilometres, each classified against the exact reference.
//!
//! Next to each measured case: the f32 spacing of world positions at that distance from the
//! origin (the precision of the input, and what would limit a renderer that sent world-space
//! positions to the GPU), the spacing of the positions the GPU does see (relative to
//! `Scene::render_origin`, rebased in f64 on the CPU), and
//! the camera-depth step at the view distance for umbra's reversed-z float buffer and for a
//! standard-z float buffer (an analytic control from `math::precision`: umbra has no standard-z
//! render path).

use super::{classify_scene, finest_texel, Counts};
use glam::{Mat4, Vec3};
use serde::Serialize;
use std::sync::Arc;
use umbra::gpu::{Context, GpuError};
use umbra::math::precision::{relative_gap, DepthMapping};
use umbra::plan::{SceneOptions, View};
use umbra::scene::{LightKind, Scene};

/// Distances from the origin (scene units) of the translated cases; 0 is the reference case.
pub fn offsets(quick: bool) -> Vec<f64> {
    if quick {
        vec![0.0, 1e2, 1e4, 1e6]
    } else {
        vec![0.0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6]
    }
}

/// Uniform scales of the scaled cases.
pub fn scales(quick: bool) -> Vec<f64> {
    if quick {
        vec![1e-3, 1e4]
    } else {
        vec![1e-3, 1e-2, 1e-1, 1e1, 1e2, 1e3, 1e4]
    }
}

/// One placement of the scene.
#[derive(Clone, Debug, Serialize)]
pub struct PrecisionRow {
    /// Distance of the scene from the origin (scene units, before scaling).
    pub offset: f64,
    /// Uniform scale.
    pub scale: f64,
    /// The pixel counts.
    pub counts: Counts,
    /// Misclassified fraction of judged pixels.
    pub misclassified: f64,
    /// Acne (planar + curved) fraction of judged pixels.
    pub acne: f64,
    /// False light fraction of judged pixels.
    pub false_light: f64,
    /// Misclassified fraction relative to the untransformed case.
    pub ratio_to_origin: f64,
    /// Finest shadow texel (world units).
    pub texel_world: f64,
    /// f32 spacing of world positions at the scene's farthest point from the origin.
    pub position_step: f64,
    /// f32 spacing of the positions the GPU computes (relative to the render origin) at the
    /// scene's farthest point from that origin.
    pub gpu_position_step: f64,
    /// Camera-depth step at the view distance, reversed-z f32 (umbra).
    pub depth_step_reversed: f64,
    /// Camera-depth step at the view distance, standard z f32 with the far plane at twice the
    /// view distance (analytic control).
    pub depth_step_standard: f64,
}

fn f32_step(x: f64) -> f64 {
    let f = (x.abs() as f32).max(f32::MIN_POSITIVE);
    (f32::from_bits(f.to_bits() + 1) - f) as f64
}

/// `scene` and `view` placed by `m` (uniform scale `s`, then a translation): instances, lights
/// (point and spot intensities × s² so the image is unchanged), cameras and framing.
pub fn place(scene: &Scene, view: &View, m: Mat4, s: f32) -> (Scene, View) {
    let mut out = scene.clone();
    for inst in &mut out.instances {
        inst.world_from_model = m * inst.world_from_model;
    }
    for l in &mut out.lights {
        l.position = m.transform_point3(l.position);
        if l.kind != LightKind::Directional {
            l.intensity *= s * s;
        }
    }
    let place_camera = |c: &mut umbra::scene::Camera| {
        let eye = m.transform_point3(c.position());
        let rot = c.world_from_view;
        c.world_from_view = Mat4::from_cols(rot.x_axis, rot.y_axis, rot.z_axis, eye.extend(1.0));
        c.near *= s;
        c.far = c.far.map(|f| f * s);
    };
    out.cameras.iter_mut().for_each(place_camera);
    out.framing = out.framing.map(|b| b.transformed(&m));
    let mut v = view.clone();
    place_camera(&mut v.camera);
    if let Some(c) = v.shadow_fit_camera.as_mut() {
        place_camera(c);
    }
    (out, v)
}

/// Every offset and scale; a renderer and a reference per case. `progress` once per case.
pub fn precision(
    ctx: &Arc<Context>,
    scene: &Scene,
    view: &View,
    options: &SceneOptions,
    size: (u32, u32),
    quick: bool,
    progress: &mut dyn FnMut(),
) -> Result<Vec<PrecisionRow>, GpuError> {
    let mut cases: Vec<(f64, f64)> = offsets(quick).into_iter().map(|o| (o, 1.0)).collect();
    cases.extend(scales(quick).into_iter().map(|s| (0.0, s)));
    let radius = (scene.bounds().diagonal() * 0.5) as f64;
    let centre = scene.bounds().center();
    let mut rows: Vec<PrecisionRow> = Vec::new();
    for (offset, scale) in cases {
        let dir = Vec3::new(1.0, 0.0, 1.0).normalize();
        let m = Mat4::from_translation(dir * offset as f32)
            * Mat4::from_scale(Vec3::splat(scale as f32));
        let (placed, v) = place(scene, view, m, scale as f32);
        let (c, f, _) = classify_scene(ctx, &placed, options, &v, size)?;
        progress();
        let far_point = (offset + (centre.length() as f64 + radius) * scale).abs();
        let dist = (view.camera.position() - centre).length() as f64 * scale;
        let near = (view.camera.near as f64 * scale).max(1e-12);
        let dist = dist.max(near);
        let rel = placed.render_origin();
        let pb = placed.bounds();
        let gpu_far = (pb.min - rel).abs().max((pb.max - rel).abs()).length() as f64;
        let misclassified = c.misclassified_fraction();
        let origin = rows
            .first()
            .map_or(misclassified, |r: &PrecisionRow| r.misclassified);
        rows.push(PrecisionRow {
            offset,
            scale,
            counts: c,
            misclassified,
            acne: c.acne_fraction(),
            false_light: c.false_light_fraction(),
            ratio_to_origin: if origin > 0.0 {
                misclassified / origin
            } else if misclassified > 0.0 {
                f64::INFINITY
            } else {
                1.0
            },
            texel_world: finest_texel(&f),
            position_step: f32_step(far_point),
            gpu_position_step: f32_step(gpu_far),
            depth_step_reversed: relative_gap(DepthMapping::ReversedInfiniteF32, near, dist) * dist,
            depth_step_standard: relative_gap(
                DepthMapping::StandardF32 { far: 2.0 * dist },
                near,
                dist,
            ) * dist,
        });
    }
    Ok(rows)
}
