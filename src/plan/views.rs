//! The shadow views of a frame: cascades fitted to the camera (or one map), a spot light's
//! frustum, a point light's six cube faces, and their uniforms.

use super::camera::fitting_frustum;
use super::casters::CasterPlan;
use super::input::{PlanScene, PlanTarget};
use super::settings::{Pcf, ShadowFit, ShadowSettings, MAX_CASCADES};
use super::uniforms::{ShadowViewUniform, MAX_SHADOW_VIEWS};
use super::view::{HeldLight, View};
use crate::math::shadow_fit::{
    cascade_splits, fit_directional, fit_point_faces, fit_spot, frustum_box_intersection, widened,
    CameraFrustum, DirectionalFit, DirectionalFitInput,
};
use crate::math::Aabb;
use crate::scene::{Camera, Light, LightKind};
use crate::shader_consts::scene as sh;
use glam::{Mat4, Vec4};

/// Weight of logarithmic against uniform cascade splits (`cascade_splits`) under a perspective
/// camera (an orthographic one splits evenly).
pub const CASCADE_SPLIT_LAMBDA: f32 = 0.9;

/// The last fraction of each cascade (but the last) over which lookups move to the next one.
pub const CASCADE_BLEND: f32 = 0.1;

/// One shadow view (one layer of the shadow map): a cascade or the single map of a directional
/// light, a spot light's frustum, or one cube face of a point light, with the casters the shadow
/// pass draws into it.
#[derive(Clone, Debug)]
pub struct ShadowView {
    /// World → light clip.
    pub light_clip_from_world: Mat4,
    /// World size of a texel (directional) or per unit distance (spot, point face).
    pub texel_world: f32,
    /// View depth where this view stops being used (+inf for the last).
    pub far: f32,
    /// View depth where lookups start moving to the next view (= `far` for the last).
    pub blend: f32,
    /// The light (index into `FramePlan::lights`) it belongs to.
    pub light: usize,
    /// Side in texels of the square at its layer's origin it fills (the map size, or less for a
    /// point light's cube faces).
    pub res: u32,
    /// For cascades: the view depths (near, far) their light's cascades were split over.
    pub depth_range: Option<(f32, f32)>,
    /// The casters the shadow pass draws into this view and the texels they touch (none until
    /// `plan_frame` plans them with the views).
    pub casters: CasterPlan,
}

impl ShadowView {
    /// A view used at every depth (the single map, a spot light's, or the last cascade).
    pub fn whole(light_clip_from_world: Mat4, texel_world: f32) -> Self {
        Self {
            light_clip_from_world,
            texel_world,
            far: f32::INFINITY,
            blend: f32::INFINITY,
            light: 0,
            res: 0,
            depth_range: None,
            casters: CasterPlan::default(),
        }
    }
}

/// How many cascades the automatic setting (`ShadowSettings::cascades` = 0) uses when one map's
/// texel is `ratio` times the pixel footprint at the nearest receiver: 1 up to 4 (the single map
/// resolves near shadows to a few pixels), 2 up to 32, else 4. Measured (`umbra compare
/// --synthetic town`): from eye height the ratio is ~180 and 4 cascades take misclassification
/// from 1.10 % to 0.023 %; from the roof ~15 and 2 cascades take it from 0.104 % to 0.023 %; the
/// demo's ~0.6 keeps one map (4 cascades there: 0.042 → 0.041 % for 55 % more frame time).
pub fn auto_cascades(ratio: f32) -> usize {
    if ratio <= 4.0 {
        1
    } else if ratio <= 32.0 {
        2
    } else {
        MAX_CASCADES as usize
    }
}

/// The nearest receiver's texel-to-pixel ratio of one map up to which the automatic setting
/// (`ShadowSettings::cascades` = 0) draws one map of twice the side instead of two cascades:
/// there the doubled map's ratio (≤ 2.5) is close to what the nearer of two cascades reaches,
/// and it costs one view: one pass over the casters instead of two, and no per-pixel cascade
/// choice. Measured at 1280×720 (`umbra compare`, `umbra bench --repeat 9`, lavapipe): the
/// close-up stand-in (ratio 4.87) goes from two 2048² cascades (0.382 % misclassified, 40.65 dB)
/// to one 4096² map (0.397 %, 40.08 dB) and its frame from 87–102 to 70–76 ms; the grazing sun
/// (ratio 7.0) keeps its cascades, where one 4096² map would raise misclassification from
/// 1.49 % to 1.98 %.
pub const DOUBLED_MAP_RATIO: f32 = 5.0;

/// The largest side the automatic setting doubles a map to.
pub const DOUBLED_MAP_MAX: u32 = 4096;

/// Whether the automatic setting draws one map of side `2 × size` for a single map of side
/// `size` whose texel is `ratio` pixels at the nearest receiver ([`DOUBLED_MAP_RATIO`]).
pub fn auto_doubles_map(ratio: f32, size: u32) -> bool {
    auto_cascades(ratio) == 2
        && ratio <= DOUBLED_MAP_RATIO
        && size.saturating_mul(2) <= DOUBLED_MAP_MAX
}

/// `n` cascades over the view depths `range` of `frustum`, each fitted by `fit(index, slice)` to
/// its slice (widened to cover the previous cascade's blend band), nearest first.
pub(super) fn cascade_views(
    frustum: &CameraFrustum,
    range: (f32, f32),
    n: usize,
    fit: impl Fn(usize, Option<CameraFrustum>) -> DirectionalFit,
) -> Vec<ShadowView> {
    // A parallel projection's pixels are the same size at every depth: even splits.
    let lambda = if frustum.tan_half > 0.0 {
        CASCADE_SPLIT_LAMBDA
    } else {
        0.0
    };
    let splits = cascade_splits(range.0, range.1, n, lambda);
    (0..n)
        .map(|c| {
            let near = match c {
                0 => splits[0],
                _ => splits[c] - CASCADE_BLEND * (splits[c] - splits[c - 1]),
            };
            let f = fit(
                c,
                Some(CameraFrustum {
                    near,
                    far: splits[c + 1],
                    ..*frustum
                }),
            );
            let mut v = ShadowView::whole(f.light_clip_from_world, f.texel_world);
            v.depth_range = Some(range);
            if c + 1 < n {
                v.far = splits[c + 1];
                v.blend = splits[c + 1] - CASCADE_BLEND * (splits[c + 1] - splits[c]);
            }
            v
        })
        .collect()
}

/// Steps per octave of the snapped receiver depth range.
const DEPTH_RANGE_STEPS_PER_OCTAVE: f32 = 4.0;

/// The receiver depth range widened to steps of 2^(1/4) (near rounded down, far up), within
/// `limits`: with snapping, the cascade splits (and so each cascade's extent) then change only
/// when the range crosses a step, not every frame the camera moves.
pub fn quantise_depth_range(near: f32, far: f32, limits: (f32, f32)) -> (f32, f32) {
    let q = |x: f32, up: bool| {
        if !(x.is_finite() && x > 0.0) {
            return x;
        }
        let k = x.log2() * DEPTH_RANGE_STEPS_PER_OCTAVE;
        let k = if up { k.ceil() } else { k.floor() };
        (k / DEPTH_RANGE_STEPS_PER_OCTAVE).exp2()
    };
    let n = q(near, false).max(limits.0);
    let f = q(far, true).min(limits.1).max(n);
    (n, f)
}

/// The view-depth range (near, far) where the camera frustum meets the receivers' boxes `parts`
/// (the scene `bounds` when there are none, or too many to clip each), within the frustum's own
/// range; the frustum's range when nothing is in view.
pub fn receiver_depths(frustum: &CameraFrustum, bounds: &Aabb, parts: &[Aabb]) -> (f32, f32) {
    let boxes = if parts.is_empty() || parts.len() > 1024 {
        std::slice::from_ref(bounds)
    } else {
        parts
    };
    let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
    for b in boxes {
        for p in frustum_box_intersection(frustum, b) {
            let d = -frustum.view_from_world.transform_point3(p).z;
            lo = lo.min(d);
            hi = hi.max(d);
        }
    }
    let lo = lo.max(frustum.near);
    let hi = hi.min(frustum.far);
    if lo.is_finite() && hi > lo {
        (lo, hi)
    } else {
        (frustum.near, frustum.far)
    }
}

/// The shadow views of every shadow-casting light, in light order, while the frame's views
/// last, and the lights left without (their views did not fit).
pub(super) fn shadow_views(
    lights: &[Light],
    scene: &PlanScene,
    view: &View,
    target: &PlanTarget,
) -> (Vec<ShadowView>, Vec<usize>) {
    let bounds = scene.bounds;
    let fit_camera = view.shadow_fit_camera.as_ref().unwrap_or(&view.camera);
    let size = view.shadow.map_size.max(1);
    let mut views: Vec<ShadowView> = Vec::new();
    let mut unshadowed = Vec::new();
    let any_soft = view.shadow.soft && lights.iter().any(|l| l.casts_shadows && soft_size(l) > 0.0);
    for (i, l) in lights.iter().enumerate() {
        if !(l.casts_shadows && l.intensity > 0.0) {
            continue;
        }
        let room = MAX_SHADOW_VIEWS - views.len();
        let mut own = match l.kind {
            // Fewer cascades where the views run short.
            LightKind::Directional if room > 0 => directional_views(
                l,
                scene,
                view,
                fit_camera,
                target,
                room,
                view.shadow_hold
                    .as_ref()
                    .and_then(|h| h.light(i, l.direction)),
            ),
            LightKind::Directional => Vec::new(),
            LightKind::Spot { outer, .. } => {
                let (m, tan_half) = fit_spot(l.position, l.direction, outer, bounds);
                vec![ShadowView::whole(m, 2.0 * tan_half / size as f32)]
            }
            LightKind::Point => {
                let res = cube_face_size(&view.shadow);
                let (faces, tan_half) =
                    fit_point_faces(l.position, bounds, res, point_face_margin(view, any_soft));
                let texel = 2.0 * tan_half / res as f32;
                faces
                    .iter()
                    .map(|&m| ShadowView {
                        res,
                        ..ShadowView::whole(m, texel)
                    })
                    .collect()
            }
        };
        // A light whose views do not fit casts no shadow.
        if own.is_empty() || own.len() > room {
            unshadowed.push(i);
            continue;
        }
        for v in &mut own {
            v.light = i;
            if v.res == 0 {
                v.res = size;
            }
        }
        views.extend(own);
    }
    (views, unshadowed)
}

/// Each shadow view's uniform: its matrix and cascade range; the rectangle with the casters is
/// set when the casters are planned (until then every lookup is lit). Slots past the views are
/// never read.
pub(super) fn view_uniforms(views: &[ShadowView]) -> [ShadowViewUniform; MAX_SHADOW_VIEWS] {
    let mut u = [ShadowViewUniform::default(); MAX_SHADOW_VIEWS];
    for (c, v) in views.iter().enumerate() {
        // f32::MAX rather than infinity: the shader compares and subtracts these.
        u[c].clip = v.light_clip_from_world;
        u[c].cascade = Vec4::new(
            v.far.min(f32::MAX),
            v.blend.min(f32::MAX),
            v.texel_world,
            v.res as f32,
        );
    }
    u
}

/// How much the depths seen are grown (near ÷, far ×) before the cascades are fitted to them.
pub const DEPTH_FIT_MARGIN: f32 = 1.01;

/// Widest penumbra, in shadow texels of radius, that a soft (PCSS) lookup filters: a larger
/// light or a finer map is softened this much and no more (the shader's `SOFT_MAX_TEXELS`).
pub const SOFT_MAX_TEXELS: f32 = sh::SOFT_MAX_TEXELS;

/// How many texels from its centre a shadow lookup reads: the PCF kernel's reach, or with soft
/// shadows the widest penumbra plus its bilinear taps (`SOFT_MAX_TEXELS` + 2).
pub fn lookup_reach(pcf: Pcf, soft: bool) -> u32 {
    if soft {
        pcf.lookup_reach().max(SOFT_MAX_TEXELS as u32 + 2)
    } else {
        pcf.lookup_reach()
    }
}

/// Side in texels of a point light's cube faces: `cube_face`, or half the map (0), within the map.
pub fn cube_face_size(s: &ShadowSettings) -> u32 {
    let size = s.map_size.max(1);
    match s.cube_face {
        0 => (size / 2).max(1),
        n => n.min(size),
    }
}

/// How many texels a point light's cube face reaches past its 90° (so that the filter and the
/// normal offset of a lookup on one face stay inside that face's layer): PCF reach, normal
/// offset, constant bias, and two of slack.
pub(super) fn point_face_margin(view: &View, soft: bool) -> f32 {
    let s = &view.shadow;
    lookup_reach(s.pcf, soft) as f32
        + s.normal_offset.max(0.0).ceil()
        + s.constant_bias.max(0.0).ceil()
        + 2.0
}

/// The views of directional light `l`: one map, or cascades when fitted to the camera (count
/// from the settings, or automatic; at most `max`). `held`: what this light's views used the
/// frame before, for a camera in motion (`View::shadow_hold`).
pub(super) fn directional_views(
    l: &Light,
    scene: &PlanScene,
    view: &View,
    fit_cam: &Camera,
    target: &PlanTarget,
    max: usize,
    held: Option<&HeldLight>,
) -> Vec<ShadowView> {
    let bounds = scene.bounds;
    // Where a batch's cameras see the scene, which its shared map covers too (found once for
    // the batch).
    let also = view
        .shadow_batch
        .as_ref()
        .map(|b| b.receivers(scene.origin, l.direction, bounds, target.aspect));
    let fitter = Fitter {
        input: DirectionalFitInput {
            also,
            direction: l.direction,
            scene_bounds: *bounds,
            camera: None,
            map_size: view.shadow.map_size.max(1),
            snap: view.shadow.snap,
            sphere: view.shadow.fit == ShadowFit::Sphere,
            extent_steps: view.shadow.extent_steps,
            hold: None,
        },
        held: held.map(|h| h.extents.as_slice()),
    };
    match view.shadow.fit {
        ShadowFit::Camera | ShadowFit::Sphere => {
            let held_range = held.and_then(|h| h.depth_range);
            camera_fitted_views(&fitter, scene, view, fit_cam, target, max, held_range)
        }
        ShadowFit::Scene => {
            let f = fitter.fit(None, None);
            vec![ShadowView::whole(f.light_clip_from_world, f.texel_world)]
        }
    }
}

/// A directional light's fit for one frame: the settings, the batch's receivers and the extents
/// the light's views held the frame before.
struct Fitter<'a> {
    /// Everything but the camera, the hold and (for a doubled map) the size.
    input: DirectionalFitInput,
    held: Option<&'a [f32]>,
}

impl Fitter<'_> {
    /// Fits `camera` (or the scene) at the settings' map size, holding extent `hold`.
    fn fit(&self, camera: Option<CameraFrustum>, hold: Option<f32>) -> DirectionalFit {
        self.fit_sized(camera, hold, self.input.map_size)
    }

    /// [`Self::fit`] for a map of `map_size` texels.
    fn fit_sized(
        &self,
        camera: Option<CameraFrustum>,
        hold: Option<f32>,
        map_size: u32,
    ) -> DirectionalFit {
        fit_directional(&DirectionalFitInput {
            camera,
            hold,
            map_size,
            ..self.input
        })
    }

    /// The previous frame's extent of view `c` of `n`, when it had the same views.
    fn hold(&self, c: usize, n: usize) -> Option<f32> {
        self.held.filter(|h| h.len() == n).map(|h| h[c])
    }
}

/// A directional light's views fitted to the camera: one map (perhaps of twice the side) or
/// cascades, their count from the settings or automatic, at most `max`.
fn camera_fitted_views(
    fitter: &Fitter,
    scene: &PlanScene,
    view: &View,
    fit_cam: &Camera,
    target: &PlanTarget,
    max: usize,
    held_range: Option<(f32, f32)>,
) -> Vec<ShadowView> {
    let PlanScene {
        bounds, receivers, ..
    } = *scene;
    let size = fitter.input.map_size;
    let frustum = depth_fitted_frustum(view, fit_cam, target.aspect, bounds);
    let (near, far) = split_range(view, &frustum, (bounds, receivers), held_range);
    // The automatic count fits one map first; when it stays at one, that is the map.
    let mut single = None;
    let n = match view.shadow.cascades {
        0 => {
            let f = fitter.fit(Some(frustum), None);
            // A pixel's footprint at the nearest receiver (the same at every depth for an
            // orthographic camera).
            let pixel = 2.0 * fit_cam.half_extent_at(near, 1.0).y / target.height_px.max(1) as f32;
            let ratio = f.texel_world / pixel.max(f32::MIN_POSITIVE);
            single = Some(f);
            if auto_doubles_map(ratio, size) {
                // One map of twice the side instead of two cascades.
                let doubled = 2 * size;
                let f = fitter.fit_sized(Some(frustum), fitter.hold(0, 1), doubled);
                return vec![ShadowView {
                    res: doubled,
                    ..ShadowView::whole(f.light_clip_from_world, f.texel_world)
                }];
            }
            auto_cascades(ratio)
        }
        c => c.clamp(1, MAX_CASCADES) as usize,
    }
    .min(max);
    if n == 1 {
        let f = match fitter.hold(0, 1) {
            Some(h) => fitter.fit(Some(frustum), Some(h)),
            None => single.unwrap_or_else(|| fitter.fit(Some(frustum), None)),
        };
        vec![ShadowView::whole(f.light_clip_from_world, f.texel_world)]
    } else {
        cascade_views(&frustum, (near, far), n, |c, camera| {
            fitter.fit(camera, fitter.hold(c, n))
        })
    }
}

/// The largest view depth of `bounds` seen from `camera` (the depth view's black end); at least
/// the near plane.
pub(super) fn far_view_depth(camera: &Camera, bounds: &Aabb) -> f32 {
    if bounds.is_empty() {
        return camera.near * 2.0;
    }
    let m = camera.view_from_world();
    let far = bounds
        .corners()
        .iter()
        .map(|c| -m.transform_point3(*c).z)
        .fold(0.0f32, f32::max);
    far.max(camera.near * 2.0)
}

/// A shadowed light's soft-shadow size as the shader's penumbra formula takes it: tan of half
/// the angular diameter for a directional light, the radius for a point or spot light; 0 for a
/// punctual light (hard shadows) or a size that is not a finite number above 0.
pub fn soft_size(l: &Light) -> f32 {
    let s = if l.size.is_finite() {
        l.size.max(0.0)
    } else {
        0.0
    };
    match l.kind {
        LightKind::Directional => (0.5 * s.min(3.0)).tan(),
        _ => s,
    }
}

/// The fitting camera's frustum clipped to the scene, and with sample-distribution fitting
/// (`depth_fit`) ended where the depths the view saw end.
fn depth_fitted_frustum(
    view: &View,
    fit_cam: &Camera,
    aspect: f32,
    bounds: &Aabb,
) -> CameraFrustum {
    let mut frustum = fitting_frustum(fit_cam, aspect, bounds);
    // Sample-distribution fitting: the frustum ends where the depths seen end.
    if let Some((lo, hi)) = view
        .visible_depths
        .filter(|_| view.shadow.depth_fit && view.shadow_fit_camera.is_none())
        .filter(|(lo, hi)| lo.is_finite() && hi.is_finite() && *hi >= *lo && *lo > 0.0)
    {
        let near = (lo / DEPTH_FIT_MARGIN).max(frustum.near);
        let far = (hi * DEPTH_FIT_MARGIN).min(frustum.far);
        if far > near {
            (frustum.near, frustum.far) = (near, far);
        }
    }
    frustum
}

/// The view depths the cascades split: where the view meets the scene's receivers (held still
/// in motion while they stay inside `held_range`, quantised otherwise), or the whole frustum for
/// one map.
fn split_range(
    view: &View,
    frustum: &CameraFrustum,
    (bounds, receivers): (&Aabb, &[Aabb]),
    held_range: Option<(f32, f32)>,
) -> (f32, f32) {
    // Split the depths where the view meets the scene, not the whole frustum: a camera
    // high above a compact scene sees nothing near. (Per frame, so only when the count
    // is not fixed at one map.)
    match view.shadow.cascades {
        1 => (frustum.near, frustum.far),
        _ if view.shadow.snap => {
            let (n, f) = receiver_depths(frustum, bounds, receivers);
            match held_range {
                // In motion the range, and so the splits, hold still until the
                // receivers leave it, then widen by doublings; they narrow again when
                // the camera stops (a step changes every cascade at once).
                Some((hn, hf)) => {
                    let near = (1.0 / widened(1.0 / hn, 1.0 / n)).max(frustum.near);
                    (near, widened(hf, f).max(near))
                }
                None => quantise_depth_range(n, f, (frustum.near, frustum.far)),
            }
        }
        _ => receiver_depths(frustum, bounds, receivers),
    }
}
