//! Shimmer along a camera path: how many fixed world points change shadow classification between
//! consecutive frames while nothing but the camera moves.
//!
//! A world point's classification in frame i is what frame i's shadow maps (fitted to camera i)
//! say about it. To read both frames' answers at exactly the same points, pair (i, i+1) renders
//! camera i's pixels twice: with the shadows fitted to camera i (frame i as the user sees it) and
//! fitted to camera i+1 (frame i+1's maps, cascades chosen by camera i+1's depths). The light and
//! the points are fixed, so their exact visibility is the same in both; every flip is shimmer.
//! Points count when camera i+1's frustum contains them too.

use super::{finest_texel, fraction, shadow_frame};
use glam::{Mat4, Vec3, Vec4};
use serde::Serialize;
use umbra::gpu::GpuError;
use umbra::math::bezier::CubicBezier;
use umbra::math::projection::pixel_to_ndc;
use umbra::math::Aabb;
use umbra::plan::camera_projection;
use umbra::plan::{ShadowFit, ShadowHold, ShadowMethod, ShadowSettings, View};
use umbra::render::Renderer;
use umbra::scene::Camera;

/// A shadow method the path is flown with.
#[derive(Clone, Debug)]
pub struct Method {
    /// Its name in the results.
    pub name: String,
    /// Its settings.
    pub shadow: ShadowSettings,
    /// Flown as the viewer flies: each frame holds the previous frame's extents
    /// (`View::shadow_hold`); else every frame is fitted afresh, as a still is.
    pub held: bool,
}

/// The methods compared. Fitted afresh every frame (as stills are): a single map fitted to the
/// camera, snapped and unsnapped; four cascades, snapped and unsnapped; a single map fitted to
/// the frustum's bounding sphere; a single map whose extent steps by powers of 2
/// (`ShadowSettings::extent_steps` = 1). Held across frames (as the viewer renders,
/// `View::shadow_hold`): the snapped single map, the snapped cascades, and the defaults
/// (automatic cascade count). And exact shadows (`ShadowMethod::Exact`), whose verdict at a
/// point does not depend on any fit. (Cascades fitted to spheres are left out: their splits follow the
/// receivers' depth range, which steps as the camera moves, and each step changes every cascade:
/// 1.38·10⁻⁴ against 0.99·10⁻⁴ fitted to the receivers on the built-in scene.)
pub fn methods(defaults: &ShadowSettings) -> Vec<Method> {
    let s = |cascades: u32, snap: bool, fit: ShadowFit, extent_steps: u32| ShadowSettings {
        cascades,
        snap,
        fit,
        extent_steps,
        ..*defaults
    };
    let steps = defaults.extent_steps;
    [
        (
            "single map, snapped",
            s(1, true, ShadowFit::Camera, steps),
            false,
        ),
        (
            "single map, unsnapped",
            s(1, false, ShadowFit::Camera, steps),
            false,
        ),
        (
            "4 cascades, snapped",
            s(4, true, ShadowFit::Camera, steps),
            false,
        ),
        (
            "4 cascades, unsnapped",
            s(4, false, ShadowFit::Camera, steps),
            false,
        ),
        (
            "single map, sphere fit",
            s(1, true, ShadowFit::Sphere, steps),
            false,
        ),
        (
            "single map, snapped to powers of 2",
            s(1, true, ShadowFit::Camera, 1),
            false,
        ),
        (
            "single map, snapped, held",
            s(1, true, ShadowFit::Camera, steps),
            true,
        ),
        (
            "4 cascades, snapped, held",
            s(4, true, ShadowFit::Camera, steps),
            true,
        ),
        ("defaults, held (the viewer)", *defaults, true),
        (
            "exact",
            ShadowSettings {
                method: ShadowMethod::Exact,
                ..*defaults
            },
            false,
        ),
    ]
    .into_iter()
    .map(|(name, shadow, held)| Method {
        name: name.into(),
        shadow,
        held,
    })
    .collect()
}

/// The flythrough (over `frames` frames; the suite takes 4 s at 60 fps): a cubic Bézier from the view's eye, dipping low past the scene's centre (close
/// to its casters), to the far side a quarter turn around; the camera looks at a target that
/// drifts across the scene and its field of view narrows to 60 % and back.
pub fn camera_path(start: &Camera, bounds: &Aabb, frames: usize) -> Vec<Camera> {
    let c = bounds.center();
    let radius = (bounds.diagonal() * 0.5).max(1e-6);
    let eye0 = start.position();
    let rel = eye0 - c;
    let turned = Mat4::from_rotation_y(std::f32::consts::FRAC_PI_2).transform_vector3(rel);
    let low = bounds.min.y + 0.15 * (bounds.max.y - bounds.min.y) + 0.05 * radius;
    let mut p1 = c + rel * 0.45;
    p1.y = low.max(c.y - 0.3 * radius);
    let mut p2 = c + turned * 0.5;
    p2.y = low + 0.1 * radius;
    let path = CubicBezier {
        p: [eye0, p1, p2, c + turned],
    };
    let target = CubicBezier {
        p: [
            c,
            c + Vec3::new(0.2, -0.1, 0.0) * radius,
            c + Vec3::new(-0.2, -0.1, 0.2) * radius,
            c,
        ],
    };
    (0..frames)
        .map(|i| {
            let t = i as f32 / (frames.max(2) - 1) as f32;
            let fov = start
                .fov_y()
                .unwrap_or(umbra::scene::mesh::framing::FOV_Y_DEG.to_radians())
                * (1.0 - 0.4 * (std::f32::consts::PI * t).sin());
            let mut cam = Camera::look_at(path.eval(t), target.eval(t), fov, start.near);
            cam.far = start.far;
            cam
        })
        .collect()
}

/// One method's flips along the path.
#[derive(Clone, Debug, Serialize)]
pub struct ShimmerSeries {
    /// The method.
    pub method: String,
    /// Cascades (0 = automatic).
    pub cascades: u32,
    /// Origin snapped to whole texels, extent quantised.
    pub snapped: bool,
    /// Each frame held the previous frame's extents (as the viewer renders).
    pub held: bool,
    /// Fitted to the receivers the camera sees (`camera`) or to its frustum's bounding sphere
    /// (`sphere`).
    pub fit: String,
    /// Per consecutive pair (i, i+1): points compared.
    pub points: Vec<usize>,
    /// Per pair: points whose classification flipped.
    pub flipped: Vec<usize>,
    /// Mean over pairs of the flipped fraction.
    pub mean_fraction: f64,
    /// Mean over the frames of the finest shadow texel's world size (what the method pays in
    /// resolution).
    pub mean_texel: f64,
    /// Largest flipped fraction of one pair.
    pub max_fraction: f64,
}

/// Flies `path` with every method; `progress` is called once per frame rendered.
pub fn shimmer(
    renderer: &mut Renderer,
    view: &View,
    path: &[Camera],
    methods: &[Method],
    size: (u32, u32),
    progress: &mut dyn FnMut(),
) -> Result<Vec<ShimmerSeries>, GpuError> {
    let (w, h) = size;
    let aspect = w as f32 / h.max(1) as f32;
    let mut out = Vec::new();
    for m in methods {
        let (mut points, mut flipped, mut texels) = (Vec::new(), Vec::new(), 0.0);
        // Held: frame i holds frame i-1's extents, and frame i+1 (fitted to camera i+1,
        // rendered at camera i's pixels) holds frame i's.
        let mut hold = None;
        for pair in path.windows(2) {
            let mut v = view.clone();
            v.shadow = m.shadow;
            v.camera = pair[0];
            v.shadow_fit_camera = None;
            v.shadow_hold = hold.clone();
            let a = shadow_frame(renderer, &v, size)?;
            if m.held {
                hold = Some(ShadowHold::from_plan(&a.plan));
                v.shadow_hold = hold.clone();
            }
            v.shadow_fit_camera = Some(pair[1]);
            let b = shadow_frame(renderer, &v, size)?;
            texels += finest_texel(&a);
            progress();
            progress();
            let inv = a.plan.clip_from_world.inverse();
            // In the plan's coordinates (relative to the render origin).
            let cam_b = pair[1].rebased(a.plan.origin);
            let next = camera_projection(&cam_b, aspect) * cam_b.view_from_world();
            let depth = a.depth.as_deref().unwrap_or(&[]);
            let (mut n, mut f) = (0usize, 0usize);
            for y in 0..h {
                for x in 0..w {
                    let i = (y * w + x) as usize;
                    let d = depth.get(i).copied().unwrap_or(0.0);
                    if d <= 0.0 {
                        continue;
                    }
                    let nd = pixel_to_ndc(x as f32 + 0.5, y as f32 + 0.5, w, h);
                    let p = inv * Vec4::new(nd.x, nd.y, d, 1.0);
                    let q = next * (p.truncate() / p.w).extend(1.0);
                    if q.w <= 0.0 || q.x.abs() > q.w || q.y.abs() > q.w {
                        continue;
                    }
                    n += 1;
                    let lit_a = a.image.get_pixel(x, y)[0] >= 128;
                    let lit_b = b.image.get_pixel(x, y)[0] >= 128;
                    f += (lit_a != lit_b) as usize;
                }
            }
            points.push(n);
            flipped.push(f);
        }
        let fr: Vec<f64> = points
            .iter()
            .zip(&flipped)
            .map(|(&n, &f)| fraction(f, n))
            .collect();
        out.push(ShimmerSeries {
            method: m.name.clone(),
            cascades: m.shadow.cascades,
            snapped: m.shadow.snap,
            held: m.held,
            fit: format!("{:?}", m.shadow.fit).to_lowercase(),
            mean_fraction: fr.iter().sum::<f64>() / fr.len().max(1) as f64,
            mean_texel: texels / fr.len().max(1) as f64,
            max_fraction: fr.iter().copied().fold(0.0, f64::max),
            points,
            flipped,
        });
    }
    Ok(out)
}
