//! Light angle: acne and leaks from the sun at the horizon to overhead, the bias trade-off, and
//! the contact gap at a thin wall's base.

use super::{classify_view, finest_texel, shadow_frame, Counts};
use crate::reference::ReferenceScene;
use glam::{Mat4, Vec3, Vec4};
use serde::Serialize;
use umbra::gpu::GpuError;
use umbra::math::projection::pixel_to_ndc;
use umbra::math::ray::{ray_aabb, Ray};
use umbra::math::Aabb;
use umbra::plan::ScenePlanner;
use umbra::plan::View;
use umbra::render::Renderer;
use umbra::scene::{Camera, Light};

/// Sun elevations (degrees), log-spaced near the horizon.
pub fn elevations(quick: bool) -> Vec<f32> {
    if quick {
        vec![0.5, 1.0, 2.0, 5.0, 10.0, 30.0, 60.0, 90.0]
    } else {
        vec![
            0.5, 1.0, 1.5, 2.0, 3.0, 5.0, 7.5, 10.0, 15.0, 20.0, 30.0, 45.0, 60.0, 75.0, 90.0,
        ]
    }
}

/// Sun azimuths (degrees): the scene sun's own, then two more a third of a turn apart.
pub fn azimuths(first: f32, quick: bool) -> Vec<f32> {
    let n = if quick { 2 } else { 3 };
    (0..n).map(|k| first + 120.0 * k as f32).collect()
}

/// Elevations of the bias sweep and the factors applied to all three biases (constant, slope,
/// normal offset); 1 is the defaults.
pub fn bias_sweep(quick: bool) -> (Vec<f32>, Vec<f32>) {
    if quick {
        (vec![5.0, 30.0], vec![0.25, 0.5, 1.0, 2.0, 4.0])
    } else {
        (
            vec![2.0, 5.0, 15.0, 45.0],
            vec![0.0, 0.125, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0],
        )
    }
}

/// One sun direction and bias factor, classified.
#[derive(Clone, Debug, Serialize)]
pub struct AngleRow {
    /// Degrees above the horizon.
    pub elevation_deg: f32,
    /// Degrees around +Y from +Z.
    pub azimuth_deg: f32,
    /// Factor on the default constant, slope and normal-offset biases.
    pub bias_scale: f32,
    /// World size of a texel of the finest shadow view (m or scene units).
    pub texel_world: f64,
    /// The pixel counts.
    pub counts: Counts,
    /// Planar acne fraction of the planar judged pixels.
    pub acne_planar: f64,
    /// Curved acne fraction of the curved judged pixels.
    pub acne_curved: f64,
    /// False light fraction of all judged pixels.
    pub false_light: f64,
    /// Misclassified fraction of all judged pixels.
    pub misclassified: f64,
}

impl AngleRow {
    fn new(elevation: f32, azimuth: f32, scale: f32, texel: f64, c: Counts) -> Self {
        Self {
            elevation_deg: elevation,
            azimuth_deg: azimuth,
            bias_scale: scale,
            texel_world: texel,
            counts: c,
            acne_planar: super::fraction(c.acne_planar, c.planar),
            acne_curved: super::fraction(c.acne_curved, c.curved),
            false_light: c.false_light_fraction(),
            misclassified: c.misclassified_fraction(),
        }
    }
}

/// The view with the sun at `elevation`, `azimuth` (degrees) and every bias scaled by `scale`.
pub fn sun_view(view: &View, elevation: f32, azimuth: f32, scale: f32) -> View {
    let mut v = view.clone();
    v.sun_direction = Some(Light::sun_direction(
        elevation.to_radians(),
        azimuth.to_radians(),
    ));
    v.shadow.constant_bias *= scale;
    v.shadow.slope_bias *= scale;
    v.shadow.normal_offset *= scale;
    v
}

/// Every elevation × azimuth at the defaults, and the bias sweep at its elevations (first azimuth
/// only); one exact frame per sun direction. `progress` is called once per frame rendered.
pub fn light_angles(
    renderer: &mut Renderer,
    reference: &ReferenceScene,
    view: &View,
    size: (u32, u32),
    quick: bool,
    first_azimuth: f32,
    progress: &mut dyn FnMut(),
) -> Result<Vec<AngleRow>, GpuError> {
    let (bias_elevations, scales) = bias_sweep(quick);
    let mut suns: Vec<(f32, f32)> = Vec::new();
    for a in azimuths(first_azimuth, quick) {
        for e in elevations(quick) {
            suns.push((e, a));
        }
    }
    for &e in &bias_elevations {
        if !suns.contains(&(e, first_azimuth)) {
            suns.push((e, first_azimuth));
        }
    }
    let mut rows = Vec::new();
    for (e, a) in suns {
        let mut exact = None;
        let sweep = a == first_azimuth && bias_elevations.contains(&e);
        let factors: &[f32] = if sweep { &scales } else { &[1.0] };
        for &s in factors {
            let v = sun_view(view, e, a, s);
            let (c, f) = classify_view(renderer, reference, &v, size, &mut exact)?;
            rows.push(AngleRow::new(e, a, s, finest_texel(&f), c));
            progress();
        }
    }
    Ok(rows)
}

/// The contact gap at one elevation.
#[derive(Clone, Debug, Serialize)]
pub struct ContactRow {
    /// Degrees above the horizon (the sun faces the wall's +Z face).
    pub elevation_deg: f32,
    /// World size of a texel of the shadow view at the wall's base.
    pub texel_world: f64,
    /// Points checked (exactly in shadow, seen on the ground).
    pub points: usize,
    /// Largest distance behind the base, in texels, before which some point is lit while the
    /// wall shadows it exactly (0: the shadow touches the base).
    pub gap_texels_max: Option<f64>,
}

/// Distances behind the base probed, in texels.
const GAP_STEPS: usize = 40;
const GAP_STEP_TEXELS: f64 = 0.25;

/// The contact gap behind a thin wall of half extents `half` standing on y = 0 at the origin
/// (broad faces towards ±Z; `synthetic::stability_scene`), with the shadows fitted to `view`'s
/// camera as a user would see them. A second camera looks straight down at the ground behind the
/// base at a quarter texel per pixel and reads the shadow along lines across the wall: the gap is
/// the largest distance behind the base below which a point the wall shadows exactly is lit.
pub fn contact_gaps(
    renderer: &mut Renderer,
    planner: &ScenePlanner,
    view: &View,
    half: Vec3,
    elevations: &[f32],
    size: (u32, u32),
    progress: &mut dyn FnMut(),
) -> Result<Vec<ContactRow>, GpuError> {
    let wall = Aabb::new(
        Vec3::new(-half.x, 0.0, -half.z),
        Vec3::new(half.x, 2.0 * half.y, half.z),
    );
    let mut rows = Vec::new();
    for &e in elevations {
        let mut v = sun_view(view, e, 0.0, 1.0);
        v.shadow_fit_camera = Some(view.camera);
        let Some(texel) = base_texel(planner, &v, half, size) else {
            continue;
        };
        let light = -v.sun_direction.unwrap_or(Vec3::NEG_Y);
        // Observer: straight down over the band behind the base, a quarter texel per pixel.
        let fov = 40f32.to_radians();
        let height = (texel as f32 * 0.25 * size.1 as f32 / (2.0 * (fov * 0.5).tan())).max(1e-4);
        let span = GAP_STEPS as f32 * GAP_STEP_TEXELS as f32 * texel as f32;
        let centre = Vec3::new(0.0, 0.0, -half.z - 0.5 * span);
        v.camera = Camera::look_at(centre + Vec3::Y * height, centre, fov, height * 1e-3);
        let f = shadow_frame(renderer, &v, size)?;
        progress();
        let clip = f.plan.clip_from_scene();
        let inv = clip.inverse();
        let depth_buf = f.depth.as_deref().unwrap_or(&[]);
        let w = size.0;
        let mut points = 0;
        let mut gap: Option<f64> = None;
        // Lines across the wall, within the observer's view.
        let across = (w as f32 * 0.4 * texel as f32 * 0.25).min(0.9 * half.x);
        for line in 0..9 {
            let x = across * (line as f32 / 4.0 - 1.0);
            let mut first_lit_after: Option<usize> = None;
            for k in 0..GAP_STEPS {
                let d = (k as f64 + 0.5) * GAP_STEP_TEXELS * texel;
                let p = Vec3::new(x, 0.0, -half.z - d as f32);
                // Only points the wall shadows exactly.
                if ray_aabb(&Ray::new(p, light), &wall, 1e-6, f32::INFINITY).is_none() {
                    continue;
                }
                let Some((ix, iy)) = pixel_seeing(p, (clip, inv), depth_buf, size, 0.5 * texel)
                else {
                    continue;
                };
                points += 1;
                if f.image.get_pixel(ix, iy)[0] >= 128 {
                    first_lit_after = Some(k);
                }
            }
            if let Some(k) = first_lit_after {
                let g = (k + 1) as f64 * GAP_STEP_TEXELS;
                gap = Some(gap.map_or(g, |old: f64| old.max(g)));
            } else if points > 0 {
                gap.get_or_insert(0.0);
            }
        }
        rows.push(ContactRow {
            elevation_deg: e,
            texel_world: texel,
            points,
            gap_texels_max: if points > 0 { gap } else { None },
        });
    }
    Ok(rows)
}

/// The world size of a texel at the wall's base (`half`: the wall's half extents), from the
/// plan of `v` (the user's camera, the sun set): the shadow view whose range holds the base's
/// view depth.
fn base_texel(planner: &ScenePlanner, v: &View, half: Vec3, size: (u32, u32)) -> Option<f64> {
    let plan = planner.plan(v, size.0, size.1);
    let base = Vec3::new(0.0, 0.0, -half.z);
    let eye = v.camera.position();
    let fwd = v
        .camera
        .world_from_view
        .transform_vector3(Vec3::NEG_Z)
        .normalize();
    let depth = (base - eye).dot(fwd);
    let views = plan.primary_views();
    let sv = views.iter().find(|s| depth <= s.far).or(views.last())?;
    Some(sv.texel_world as f64)
}

/// The pixel of a `w`×`h` frame (`clip`, its inverse, its reversed-z depths) whose centre sees
/// the ground within `tolerance` of `p`, if one does.
fn pixel_seeing(
    p: Vec3,
    (clip, inv): (Mat4, Mat4),
    depth: &[f32],
    (w, h): (u32, u32),
    tolerance: f64,
) -> Option<(u32, u32)> {
    let c = clip * p.extend(1.0);
    if c.w <= 0.0 {
        return None;
    }
    let (px, py) = (
        ((c.x / c.w) * 0.5 + 0.5) * w as f32,
        (0.5 - (c.y / c.w) * 0.5) * h as f32,
    );
    if px < 0.0 || py < 0.0 || px >= w as f32 || py >= h as f32 {
        return None;
    }
    let (ix, iy) = (px as u32, py as u32);
    let dz = depth.get((iy * w + ix) as usize).copied().unwrap_or(0.0);
    let n = pixel_to_ndc(ix as f32 + 0.5, iy as f32 + 0.5, w, h);
    let q = inv * Vec4::new(n.x, n.y, dz, 1.0);
    let far = dz <= 0.0 || (q.truncate() / q.w).distance(p) as f64 > tolerance;
    (!far).then_some((ix, iy))
}

/// One sun direction (degrees) and bias factor classified (for tests and single checks).
pub fn classify_view_at(
    renderer: &mut Renderer,
    reference: &ReferenceScene,
    view: &View,
    elevation: f32,
    azimuth: f32,
    bias_scale: f32,
    size: (u32, u32),
) -> Result<(Counts, umbra::render::RenderedFrame), GpuError> {
    classify_view(
        renderer,
        reference,
        &sun_view(view, elevation, azimuth, bias_scale),
        size,
        &mut None,
    )
}
