//! Per-frame planning on the CPU: which lights shade, the shadow views of each shadow-casting
//! light (cascades, a spot's frustum, a point light's six cube faces) as layers of one shadow
//! map, the camera projection, and the frame uniform block.

use super::casters::{CasterPlan, Viewpoint};
use super::settings::{
    Exposure, HeldLight, Pcf, ShadowFit, ShadowHold, ShadowSettings, Tonemap, View, AUTO_AMBIENT,
    MAX_CASCADES, UNIT_AMBIENT,
};
use super::uniforms::{
    FrameUniform, LightUniform, ShadowViewUniform, MAX_LIGHTS, MAX_SHADOW_VIEWS,
};
use crate::gpu::shaders::scene as sh;
use crate::math::projection::{perspective_infinite_reversed, perspective_reversed};
use crate::math::shadow_fit::{
    cascade_splits, fit_directional, fit_point_faces, fit_spot, frustum_box_intersection, widened,
    CameraFrustum, DirectionalFit, DirectionalFitInput,
};
use crate::math::Aabb;
use crate::scene::{Camera, Light, LightKind};
use glam::{Mat4, Vec3, Vec4};

/// Linear colour where nothing is drawn (the CPU reference uses it too).
pub const CLEAR_COLOR: [f32; 4] = [0.02, 0.02, 0.025, 1.0];

/// Elevation of the default sun used when a scene has no light (degrees).
pub const DEFAULT_SUN_ELEVATION_DEG: f32 = 50.0;
/// Azimuth of the default sun (degrees).
pub const DEFAULT_SUN_AZIMUTH_DEG: f32 = 35.0;
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

/// Camera projection (reversed-z; infinite when the camera has no far plane).
pub fn camera_projection(camera: &Camera, aspect: f32) -> Mat4 {
    match camera.far {
        Some(f) if f > camera.near => perspective_reversed(camera.fov_y, aspect, camera.near, f),
        _ => perspective_infinite_reversed(camera.fov_y, aspect, camera.near),
    }
}

/// The frustum used to fit shadows: far = the camera's far, or the farthest scene corner.
pub fn fitting_frustum(camera: &Camera, aspect: f32, bounds: &Aabb) -> CameraFrustum {
    let eye = camera.position();
    let far_scene = bounds
        .corners()
        .iter()
        .map(|c| c.distance(eye))
        .fold(0.0f32, f32::max);
    let far = camera
        .far
        .unwrap_or(far_scene)
        .min(far_scene.max(camera.near * 2.0));
    CameraFrustum {
        view_from_world: camera.view_from_world(),
        fov_y: camera.fov_y,
        aspect,
        near: camera.near,
        far: far.max(camera.near * 1.01),
    }
}

/// Weight of logarithmic against uniform cascade splits (`cascade_splits`).
pub const CASCADE_SPLIT_LAMBDA: f32 = 0.9;
/// The last fraction of each cascade (but the last) over which lookups move to the next one.
pub const CASCADE_BLEND: f32 = 0.1;

/// One shadow view (one layer of the shadow map): a cascade or the single map of a directional
/// light, a spot light's frustum, or one cube face of a point light.
#[derive(Clone, Copy, Debug)]
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

/// `n` cascades over the view depths `range` of `frustum`, each fitted by `fit(index, slice)` to
/// its slice (widened to cover the previous cascade's blend band), nearest first.
fn cascade_views(
    frustum: &CameraFrustum,
    range: (f32, f32),
    n: usize,
    fit: impl Fn(usize, Option<CameraFrustum>) -> DirectionalFit,
) -> Vec<ShadowView> {
    let splits = cascade_splits(range.0, range.1, n, CASCADE_SPLIT_LAMBDA);
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

/// The result of planning a frame.
#[derive(Clone, Debug)]
pub struct FramePlan {
    /// The uniform block for the camera pass (its packed fields have named copies below).
    pub(crate) uniform: FrameUniform,
    /// Whether this frame draws and samples a shadow map.
    pub shadows_on: bool,
    /// Whether a shadowed light has a size: its lookups are soft (PCSS), and every lookup may
    /// read up to [`lookup_reach`] texels from its centre.
    pub soft: bool,
    /// Side of the shadow map in texels.
    pub shadow_map_size: u32,
    /// The camera's world position.
    pub camera_position: Vec3,
    /// The scene shader's variant bits this frame sets (one light, shadows sampled, comparison
    /// path, PCF kernel); each draw adds its material's bits.
    pub(crate) shader_variant: usize,
    /// Lights shading this frame.
    pub lights: Vec<Light>,
    /// The shadowed light whose visibility `--view shadow` writes (and whose views the shadow
    /// reports describe): `View::shown_light` when that light has views, else the first light
    /// with views; None without one.
    pub shadow_light: Option<usize>,
    /// Every shadow view, grouped by light in light order (a light's views are consecutive:
    /// cascades near to far, one for a spot, six cube faces for a point light); view i is layer
    /// i of the shadow map. Empty without a shadowed light.
    pub shadow_views: Vec<ShadowView>,
    /// Shadow-casting lights left without views because the frame's views were used up
    /// (`MAX_SHADOW_VIEWS`); they light without shadows.
    pub unshadowed: Vec<usize>,
    /// The camera's world → clip.
    pub clip_from_world: Mat4,
    /// The shadow pass's casters and area per shadow view (set by `FrameCore::prepare`).
    pub casters: Vec<CasterPlan>,
    /// The linear scale applied to the lit image before tone mapping (`View::exposure`
    /// resolved: auto exposure metered from this frame's lights).
    pub exposure: f32,
    /// The tone-mapping curve of the lit image.
    pub tonemap: Tonemap,
    /// The ambient intensity Ia this frame is shaded with (`View::ambient` resolved).
    pub ambient: Vec3,
    /// What auto exposure metered for this frame ([`metered_illuminance`] with `ambient`), used
    /// or not.
    pub metered_lux: f32,
    /// What every position and matrix of this plan is relative to (world = plan + origin):
    /// [`crate::scene::Scene::render_origin`] when planned by the renderer, zero from
    /// [`plan_frame`].
    pub origin: Vec3,
}

impl FramePlan {
    /// The eye and the unit forward direction the cascades were split from (the fitting camera's,
    /// the view's unless shadows are fitted to another camera).
    pub fn split_eye_forward(&self) -> (Vec3, Vec3) {
        let u = &self.uniform;
        (u.shadow_light.truncate(), u.camera_forward.truncate())
    }

    /// True when every matrix the frame's uniform block carries (the camera's and each shadow
    /// view's clip-from-world) is finite.
    pub fn is_finite(&self) -> bool {
        let u = &self.uniform;
        std::iter::once(&u.clip_from_world)
            .chain(u.views.iter().map(|v| &v.clip))
            .flat_map(|m| m.to_cols_array())
            .all(f32::is_finite)
    }

    /// The camera's clip from *absolute* world coordinates (`clip_from_world` is relative to
    /// `origin`); for callers that work in the scene's own coordinates near the origin (f32
    /// precision is that of the absolute coordinates).
    pub fn clip_from_scene(&self) -> Mat4 {
        if self.origin == Vec3::ZERO {
            self.clip_from_world
        } else {
            self.clip_from_world * Mat4::from_translation(-self.origin)
        }
    }

    /// The views of light `i` (empty when it casts no shadow this frame).
    pub fn light_views(&self, i: usize) -> &[ShadowView] {
        let first = self.shadow_views.iter().position(|v| v.light == i);
        let Some(first) = first else {
            return &[];
        };
        let n = self.shadow_views[first..]
            .iter()
            .take_while(|v| v.light == i)
            .count();
        &self.shadow_views[first..first + n]
    }

    /// The shown light's views (`shadow_light`; empty without one).
    pub fn primary_views(&self) -> &[ShadowView] {
        self.shadow_light.map_or(&[][..], |i| self.light_views(i))
    }

    /// The display value of a lit colour: exposed, then tone-mapped (the camera pass's
    /// `display`; blended layers are composited after it, as on the GPU).
    pub fn display(&self, rgb: Vec3) -> Vec3 {
        self.tonemap.apply(rgb * self.exposure)
    }

    /// Whether light `i` is shadowed by the map this frame (shadows on and it has views).
    pub fn is_shadowed(&self, i: usize) -> bool {
        self.shadows_on && self.shadow_views.iter().any(|v| v.light == i)
    }

    /// World size of a texel of the shown light's first (nearest) view (directional), or per
    /// unit distance (spot, point); 0 without a shadow map.
    pub fn texel_world(&self) -> f32 {
        self.primary_views().first().map_or(0.0, |v| v.texel_world)
    }

    /// Where light `i` is seen from: a point or spot light's position, or the direction a
    /// directional light travels.
    pub fn light_source(&self, i: usize) -> Viewpoint {
        let l = &self.lights[i];
        match l.kind {
            LightKind::Directional => Viewpoint::Along(l.direction),
            _ => Viewpoint::Eye(l.position),
        }
    }

    /// The shown light's source (`light_source`); None without a shadowed light.
    pub fn shadow_source(&self) -> Option<Viewpoint> {
        Some(self.light_source(self.shadow_light?))
    }
}

impl ShadowHold {
    /// The extents `plan` used.
    pub fn from_plan(plan: &FramePlan) -> Self {
        let lights = plan
            .lights
            .iter()
            .enumerate()
            .map(|(i, l)| {
                (l.kind == LightKind::Directional && !plan.light_views(i).is_empty()).then(|| {
                    let views = plan.light_views(i);
                    HeldLight {
                        direction: l.direction,
                        extents: views.iter().map(|v| v.texel_world * v.res as f32).collect(),
                        depth_range: views[0].depth_range,
                    }
                })
            })
            .collect();
        Self { lights }
    }
}

/// What planning a frame of one scene needs, gathered once (CPU only: no GPU scene), for tools
/// that plan many views or settings (`umbra inspect`, the error budget). Like the renderer, it
/// works relative to the scene's [`crate::scene::Scene::render_origin`]: its plans (and the
/// draw boxes) are rebased, with `FramePlan::origin` saying by how much.
pub struct ScenePlanner {
    lights: Vec<Light>,
    bounds: Aabb,
    receivers: Vec<Aabb>,
    origin: Vec3,
}

impl ScenePlanner {
    /// Gathers `scene`'s lights, bounds and draw boxes.
    pub fn new(scene: &crate::scene::Scene) -> Self {
        let origin = scene.render_origin();
        let receivers = scene.draw_bounds_rebased(origin);
        let bounds = receivers.iter().fold(Aabb::EMPTY, |b, r| b.union(r)); // = scene.bounds()
        Self {
            lights: scene.lights.iter().map(|l| l.rebased(origin)).collect(),
            bounds,
            receivers,
            origin,
        }
    }

    /// The draw boxes (relative to the render origin).
    pub fn receivers(&self) -> &[Aabb] {
        &self.receivers
    }

    /// The plan the renderer makes for `view` at `w`×`h`.
    pub fn plan(&self, view: &View, w: u32, h: u32) -> FramePlan {
        let mut plan = plan_frame(
            &PlanScene {
                lights: &self.lights,
                bounds: &self.bounds,
                receivers: &self.receivers,
            },
            &view.rebased(self.origin),
            &PlanTarget {
                aspect: w as f32 / h.max(1) as f32,
                height_px: h,
                hw_compare: false,
            },
        );
        plan.origin = self.origin;
        plan
    }
}

/// What a frame is planned against: the scene's lights, its bounds, and each draw's world box
/// (may be empty), which bound the depths cascades are split over.
#[derive(Clone, Copy, Debug)]
pub struct PlanScene<'a> {
    /// The scene's lights (the default sun is added when there are none).
    pub lights: &'a [Light],
    /// The scene's bounds.
    pub bounds: &'a Aabb,
    /// The draws' world boxes.
    pub receivers: &'a [Aabb],
}

/// The image a frame is planned for.
#[derive(Clone, Copy, Debug)]
pub struct PlanTarget {
    /// Width over height.
    pub aspect: f32,
    /// The image height in pixels: the pixel footprint the automatic cascade count compares
    /// texels with.
    pub height_px: u32,
    /// The device filters depth comparisons in hardware (the shader variant's HW_COMPARE).
    pub hw_compare: bool,
}

/// Plans a frame for `view` of `scene` rendered into `target`: pure, no GPU.
pub fn plan_frame(scene: &PlanScene, view: &View, target: &PlanTarget) -> FramePlan {
    let PlanTarget {
        aspect, hw_compare, ..
    } = *target;
    let bounds = scene.bounds;
    let lights = effective_lights(scene.lights, view);
    let fit_camera = view.shadow_fit_camera.as_ref().unwrap_or(&view.camera);
    let proj = camera_projection(&view.camera, aspect);
    let clip_from_world = proj * view.camera.view_from_world();
    let size = view.shadow.map_size.max(1);
    let (views, unshadowed) = shadow_views(&lights, scene, view, target);
    let has_views = |i: usize| views.iter().any(|v| v.light == i);
    let shadow_light = view
        .shown_light
        .filter(|&i| has_views(i))
        .or_else(|| views.first().map(|v| v.light));
    let shadows_on = view.shadow.enabled && shadow_light.is_some();
    let (ambient, metered_lux, exposure) = metering(&lights, scene, view);
    let u = FrameUniform {
        clip_from_world,
        world_from_clip: clip_from_world.as_dmat4().inverse().as_mat4(),
        camera_position: view.camera.position().extend(1.0),
        ambient: ambient.extend(0.0),
        shadow: Vec4::new(
            size as f32,
            view.shadow.normal_offset,
            far_view_depth(&view.camera, bounds),
            if shadows_on { 1.0 } else { 0.0 },
        ),
        // No shown light: an index the shader's light loop never reaches. xyz: the eye the
        // cascades were split from (the fitting camera, which is the view's unless a test or
        // the stability suite fits the shadows to another camera).
        shadow_light: fit_camera
            .position()
            .extend(shadow_light.map_or(MAX_LIGHTS as f32 + 1.0, |i| i as f32)),
        bias: Vec4::new(view.shadow.constant_bias, 0.0, 0.0, 0.0),
        camera_forward: (fit_camera
            .view_from_world()
            .inverse()
            .transform_vector3(Vec3::NEG_Z))
        .normalize_or(Vec3::NEG_Z)
        .extend(0.0),
        modes: [
            view.mode.shader_value(),
            view.shadow.pcf.taps(),
            hw_compare as u32,
            lights.len() as u32,
        ],
        output: Vec4::new(exposure, view.tonemap.shader_value(), 0.0, 0.0),
        lights: light_uniforms(&lights, &views, view),
        views: view_uniforms(&views),
    };
    // Soft where a shadowed light's uniform carries a size (set above).
    let soft = shadows_on && u.lights.iter().any(|l| l.direction.w > 0.0);
    FramePlan {
        uniform: u,
        shadows_on,
        soft,
        shadow_map_size: size,
        camera_position: view.camera.position(),
        shader_variant: frame_variant_bits(
            lights.len(),
            shadows_on,
            hw_compare,
            view.shadow.pcf,
            views.len(),
            soft,
        ),
        lights,
        shadow_light,
        shadow_views: views,
        unshadowed,
        clip_from_world,
        casters: Vec::new(),
        origin: Vec3::ZERO,
        exposure,
        tonemap: view.tonemap,
        ambient,
        metered_lux,
    }
}

/// The shadow views of every shadow-casting light, in light order, while the frame's views
/// last, and the lights left without (their views did not fit).
fn shadow_views(
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

/// The ambient Ia (the view's, else a share of the metered direct light), the metered
/// illuminance, and the exposure scale. Metered once: the default ambient follows the direct
/// part, auto exposure the sum.
fn metering(lights: &[Light], scene: &PlanScene, view: &View) -> (Vec3, f32, f32) {
    let direct = metered_illuminance(lights, Vec3::ZERO, scene.receivers, scene.bounds);
    let ambient = view.ambient.unwrap_or_else(|| {
        Vec3::splat(if direct.is_finite() && direct > 0.0 {
            AUTO_AMBIENT * direct
        } else {
            UNIT_AMBIENT
        })
    });
    let metered_lux = direct + luminance(ambient.max(Vec3::ZERO));
    let exposure = exposure_scale(view.exposure, metered_lux)
        * view.exposure_compensation.clamp(-64.0, 64.0).exp2();
    (ambient, metered_lux, exposure)
}

/// Each shadow view's uniform: its matrix and cascade range; the rectangle with the casters is
/// set when the casters are planned (until then every lookup is lit). Slots past the views are
/// never read.
fn view_uniforms(views: &[ShadowView]) -> [ShadowViewUniform; MAX_SHADOW_VIEWS] {
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

/// Each light's uniform: kind, position, direction with its soft-shadow size, colour, cone and
/// range, and its shadow views.
fn light_uniforms(
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
fn luminance(c: Vec3) -> f32 {
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

/// How much the depths seen are grown (near ÷, far ×) before the cascades are fitted to them.
pub const DEPTH_FIT_MARGIN: f32 = 1.01;

/// Widest penumbra, in shadow texels of radius, that a soft (PCSS) lookup filters: a larger
/// light or a finer map is softened this much and no more (the shader's `SOFT_MAX_TEXELS`).
pub const SOFT_MAX_TEXELS: f32 = sh::SOFT_MAX_TEXELS;

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
fn point_face_margin(view: &View, soft: bool) -> f32 {
    let s = &view.shadow;
    lookup_reach(s.pcf, soft) as f32
        + s.normal_offset.max(0.0).ceil()
        + s.constant_bias.max(0.0).ceil()
        + 2.0
}

/// The views of directional light `l`: one map, or cascades when fitted to the camera (count
/// from the settings, or automatic; at most `max`). `held`: what this light's views used the
/// frame before, for a camera in motion (`View::shadow_hold`).
fn directional_views(
    l: &Light,
    scene: &PlanScene,
    view: &View,
    fit_cam: &Camera,
    target: &PlanTarget,
    max: usize,
    held: Option<&HeldLight>,
) -> Vec<ShadowView> {
    let PlanScene {
        bounds, receivers, ..
    } = *scene;
    let PlanTarget {
        aspect, height_px, ..
    } = *target;
    let held_range = held.and_then(|h| h.depth_range);
    let held = held.map(|h| h.extents.as_slice());
    let size = view.shadow.map_size.max(1);
    // The previous frame's extent of view `c` of `n`, when it had the same views.
    let hold = |c: usize, n: usize| held.filter(|h| h.len() == n).map(|h| h[c]);
    let fit_held = |camera, hold: Option<f32>| {
        fit_directional(&DirectionalFitInput {
            direction: l.direction,
            scene_bounds: *bounds,
            camera,
            map_size: size,
            snap: view.shadow.snap,
            sphere: view.shadow.fit == ShadowFit::Sphere,
            extent_steps: view.shadow.extent_steps,
            hold,
        })
    };
    let fit = |camera| fit_held(camera, None);
    match view.shadow.fit {
        ShadowFit::Camera | ShadowFit::Sphere => {
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
            // Split the depths where the view meets the scene, not the whole frustum: a camera
            // high above a compact scene sees nothing near. (Per frame, so only when the count
            // is not fixed at one map.)
            let (near, far) = match view.shadow.cascades {
                1 => (frustum.near, frustum.far),
                _ if view.shadow.snap => {
                    let (n, f) = receiver_depths(&frustum, bounds, receivers);
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
                _ => receiver_depths(&frustum, bounds, receivers),
            };
            // The automatic count fits one map first; when it stays at one, that is the map.
            let mut single = None;
            let n = match view.shadow.cascades {
                0 => {
                    let f = fit(Some(frustum));
                    let pixel = 2.0 * near * (fit_cam.fov_y * 0.5).tan() / height_px.max(1) as f32;
                    single = Some(f);
                    auto_cascades(f.texel_world / pixel.max(f32::MIN_POSITIVE))
                }
                c => c.clamp(1, MAX_CASCADES) as usize,
            }
            .min(max);
            if n == 1 {
                let f = match hold(0, 1) {
                    Some(h) => fit_held(Some(frustum), Some(h)),
                    None => single.unwrap_or_else(|| fit(Some(frustum))),
                };
                vec![ShadowView::whole(f.light_clip_from_world, f.texel_world)]
            } else {
                cascade_views(&frustum, (near, far), n, |c, camera| {
                    fit_held(camera, hold(c, n))
                })
            }
        }
        ShadowFit::Scene => {
            let f = fit(None);
            vec![ShadowView::whole(f.light_clip_from_world, f.texel_world)]
        }
    }
}

/// The largest view depth of `bounds` seen from `camera` (the depth view's black end); at least
/// the near plane.
fn far_view_depth(camera: &Camera, bounds: &Aabb) -> f32 {
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

/// The scene shader's frame variant bits: one light (a constant loop), shadows sampled, hardware
/// comparison, and the PCF kernel (constant loops instead of per-frame uniforms).
fn frame_variant_bits(
    lights: usize,
    shadows_on: bool,
    hw_compare: bool,
    pcf: Pcf,
    views: usize,
    soft: bool,
) -> usize {
    use crate::gpu::shaders::scene as sh;
    let mut bits = 0;
    if lights == 1 {
        bits |= sh::BIT_SINGLE_LIGHT;
    }
    // The filter, comparison path and cascades mean nothing without a map (one shader for all).
    if !shadows_on {
        return bits;
    }
    bits |= sh::BIT_SHADOWS
        | match pcf {
            Pcf::None => 0,
            Pcf::P2x2 => sh::BIT_PCF_BIT0,
            Pcf::P3x3 => sh::BIT_PCF_BIT1,
            Pcf::P5x5 => sh::BIT_PCF_BIT0 | sh::BIT_PCF_BIT1,
        };
    for (on, bit) in [
        (hw_compare, sh::BIT_HW_COMPARE),
        (views > 1, sh::BIT_MANY_VIEWS),
        (soft, sh::BIT_SOFT),
    ] {
        if on {
            bits |= bit;
        }
    }
    bits
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metering_takes_the_median_receiver_and_walls_for_an_inside_lamp() {
        let lamp = Light {
            kind: LightKind::Point,
            position: Vec3::ZERO,
            direction: Vec3::NEG_Y,
            color: Vec3::ONE,
            intensity: 100.0,
            casts_shadows: false,
            range: None,
            size: 0.0,
        };
        let room = Aabb::new(Vec3::splat(-5.0), Vec3::splat(5.0));
        // A lamp inside a room is metered at the room's half-diagonal: 100 / 75.
        let e = metered_illuminance(&[lamp], Vec3::ZERO, &[room], &room);
        assert!((e - 100.0 / 75.0).abs() < 1e-5, "{e}");
        // Three small boxes 1, 2 and 10 m away: the median is the one 2 m away (100 / 4).
        let boxes: Vec<Aabb> = [1.0f32, 2.0, 10.0]
            .iter()
            .map(|&d| Aabb::new(Vec3::new(d, -0.01, -0.01), Vec3::new(d, 0.01, 0.01)))
            .collect();
        let e = metered_illuminance(&[lamp], Vec3::splat(0.5), &boxes, &room);
        assert!((e - (25.0 + 0.5)).abs() < 1e-3, "{e}");
        // A sun meters its intensity wherever the receivers are; the default ambient is 7 % of it.
        let sun = Light::sun(Vec3::NEG_Y, 3.0);
        let v = View::new(crate::scene::Camera::look_at(
            Vec3::new(0.0, 2.0, 8.0),
            Vec3::ZERO,
            0.8,
            0.1,
        ));
        let p = plan_frame(
            &PlanScene {
                lights: &[sun],
                bounds: &room,
                receivers: &boxes,
            },
            &v,
            &PlanTarget {
                aspect: 1.5,
                height_px: 100,
                hw_compare: false,
            },
        );
        assert!((p.ambient - Vec3::splat(AUTO_AMBIENT * 3.0)).length() < 1e-5);
        let k = crate::math::tonemap::KEY_VALUE;
        assert!((p.exposure - k / (3.0 * (1.0 + AUTO_AMBIENT))).abs() < 1e-5);
    }
    use crate::scene::demo::demo_scene;

    #[test]
    fn default_sun_and_override() {
        let mut s = demo_scene();
        s.lights.clear();
        let mut v = View::new(s.default_camera(1.5));
        let p = plan_frame(
            &PlanScene {
                lights: &s.lights,
                bounds: &s.bounds(),
                receivers: &[],
            },
            &v,
            &PlanTarget {
                aspect: 1.5,
                height_px: 720,
                hw_compare: false,
            },
        );
        // The compact demo keeps one map by default (automatic cascade count).
        assert_eq!(p.shadow_views.len(), 1);
        assert_eq!(p.lights.len(), 1);
        assert_eq!(p.shadow_light, Some(0));
        assert!(p.texel_world() > 0.0);
        v.sun_direction = Some(Vec3::new(0.0, -1.0, 0.0));
        let p = plan_frame(
            &PlanScene {
                lights: &s.lights,
                bounds: &s.bounds(),
                receivers: &[],
            },
            &v,
            &PlanTarget {
                aspect: 1.5,
                height_px: 720,
                hw_compare: false,
            },
        );
        assert_eq!(p.lights[0].direction, Vec3::NEG_Y);
        assert_eq!(p.uniform.modes[3], 1);
        // One light, shadows on, PCF 2×2 by hand (hw_compare false).
        use crate::gpu::shaders::scene as sh;
        let want = sh::BIT_SINGLE_LIGHT | sh::BIT_SHADOWS | sh::BIT_PCF_BIT0;
        assert_eq!(p.shader_variant, want);
        // Cascades: four views, nearest first, each ending where the next blends in.
        v.shadow.cascades = 4;
        let p = plan_frame(
            &PlanScene {
                lights: &s.lights,
                bounds: &s.bounds(),
                receivers: &[],
            },
            &v,
            &PlanTarget {
                aspect: 1.5,
                height_px: 720,
                hw_compare: false,
            },
        );
        assert_eq!(p.shader_variant, want | sh::BIT_MANY_VIEWS);
        assert_eq!(p.shadow_views.len(), 4);
        for w in p.shadow_views.windows(2) {
            assert!(w[0].blend < w[0].far && w[0].far < w[1].far, "{w:?}");
            assert!(w[0].texel_world > 0.0 && w[1].texel_world > 0.0, "{w:?}");
        }
        assert!(p.shadow_views[3].far.is_infinite());
        // Without shadows the filter, comparison and cascade bits mean nothing: one shader.
        v.shadow.enabled = false;
        let p = plan_frame(
            &PlanScene {
                lights: &s.lights,
                bounds: &s.bounds(),
                receivers: &[],
            },
            &v,
            &PlanTarget {
                aspect: 1.5,
                height_px: 720,
                hw_compare: false,
            },
        );
        assert_eq!(p.shader_variant, sh::BIT_SINGLE_LIGHT);
    }
    #[test]
    fn held_cascades_keep_their_splits_until_the_receivers_leave_them() {
        let s = demo_scene();
        let sun = [Light::sun(Vec3::new(0.3, -1.0, 0.2), 1.0)];
        let cam = s.default_camera(1.5);
        let (c, eye) = (s.bounds().center(), cam.position());
        let at = |k: f32| Camera::look_at(c + (eye - c) * k, c, cam.fov_y, cam.near);
        let mut v = View::new(cam);
        v.shadow.cascades = 4;
        let plan = |v: &View| {
            plan_frame(
                &PlanScene {
                    lights: &sun,
                    bounds: &s.bounds(),
                    receivers: &[],
                },
                v,
                &PlanTarget {
                    aspect: 1.5,
                    height_px: 720,
                    hw_compare: false,
                },
            )
        };
        let range = |p: &FramePlan| p.primary_views()[0].depth_range.unwrap();
        let splits = |p: &FramePlan| p.primary_views().iter().map(|v| v.far).collect::<Vec<_>>();
        let first = plan(&v);
        let r0 = range(&first);
        // Closer in, fitted afresh, the range narrows: its far end comes more than a doubling
        // nearer (measured 63.4 -> 30.8).
        v.camera = at(0.3);
        let fresh = range(&plan(&v));
        assert!(fresh.1 < 0.5 * r0.1, "{fresh:?} vs {r0:?}");
        // Held, its far end stays where it was (its near end follows the receivers closer, by
        // doublings, down to the fitting frustum's near plane: measured 26.9 -> 15.0).
        v.shadow_hold = Some(crate::plan::ShadowHold::from_plan(&first));
        let held = range(&plan(&v));
        assert_eq!(held.1, r0.1, "{held:?} vs {r0:?}");
        assert!(held.0 <= fresh.0 && held.0 < r0.0, "{held:?} vs {fresh:?}");
        // A camera that has not moved keeps the very same splits.
        v.camera = cam;
        assert_eq!(splits(&plan(&v)), splits(&first));
        // Drawn back until the receivers pass its far end, it widens by a whole doubling.
        v.camera = at(2.0);
        let need = range(&{
            let mut u = v.clone();
            u.shadow_hold = None;
            plan(&u)
        });
        let wide = range(&plan(&v));
        assert!(need.1 > r0.1, "{need:?} vs {r0:?}");
        assert_eq!(
            wide.1,
            r0.1 * (need.1 / r0.1).log2().ceil().exp2(),
            "{need:?}"
        );
    }

    #[test]
    fn every_casting_light_gets_views_while_they_last() {
        let s = demo_scene();
        let point = |x: f32| Light {
            kind: LightKind::Point,
            position: Vec3::new(x, 3.0, 0.0),
            direction: Vec3::NEG_Y,
            color: Vec3::ONE,
            intensity: 5.0,
            casts_shadows: true,
            range: None,
            size: 0.0,
        };
        let spot = Light {
            kind: LightKind::Spot {
                inner: 0.3,
                outer: 0.5,
            },
            ..point(1.0)
        };
        let mut dark = point(0.0);
        dark.casts_shadows = false;
        let sun = Light::sun(Vec3::new(0.3, -1.0, 0.2), 1.0);
        let lights = vec![sun, point(-2.0), dark, spot, point(2.0), point(4.0)];
        let mut v = View::new(s.default_camera(1.5));
        v.shadow.cascades = 4;
        let p = plan_frame(
            &PlanScene {
                lights: &lights,
                bounds: &s.bounds(),
                receivers: &[],
            },
            &v,
            &PlanTarget {
                aspect: 1.5,
                height_px: 720,
                hw_compare: false,
            },
        );
        // Sun 4 cascades, point 6 faces, spot 1: 11 of 16; the next two point lights need 6
        // each, more than the 5 left, and the light that casts none gets none.
        let per_light: Vec<usize> = (0..lights.len()).map(|i| p.light_views(i).len()).collect();
        assert_eq!(per_light, [4, 6, 0, 1, 0, 0]);
        assert_eq!(p.unshadowed, [4, 5]);
        assert_eq!(p.shadow_views.len(), 11);
        assert!(p.is_shadowed(3) && !p.is_shadowed(2) && !p.is_shadowed(4));
        // Layer order: grouped by light; the uniform says where each light's views start.
        let firsts: Vec<f32> = p.uniform.lights[..6].iter().map(|l| l.shadow.x).collect();
        assert_eq!(firsts, [0.0, 4.0, -1.0, 10.0, -1.0, -1.0]);
        assert_eq!(
            p.shader_variant & crate::gpu::shaders::scene::BIT_MANY_VIEWS,
            crate::gpu::shaders::scene::BIT_MANY_VIEWS
        );
        // The shown light: the first shadowed one, or the one asked for if it has views.
        assert_eq!(p.shadow_light, Some(0));
        v.shown_light = Some(3);
        let p = plan_frame(
            &PlanScene {
                lights: &lights,
                bounds: &s.bounds(),
                receivers: &[],
            },
            &v,
            &PlanTarget {
                aspect: 1.5,
                height_px: 720,
                hw_compare: false,
            },
        );
        assert_eq!(
            (
                p.shadow_light,
                p.uniform.lights[3].shadow.x,
                p.uniform.lights[3].shadow.y
            ),
            (Some(3), 10.0, 1.0)
        );
        v.shown_light = Some(4);
        let p = plan_frame(
            &PlanScene {
                lights: &lights,
                bounds: &s.bounds(),
                receivers: &[],
            },
            &v,
            &PlanTarget {
                aspect: 1.5,
                height_px: 720,
                hw_compare: false,
            },
        );
        assert_eq!(p.shadow_light, Some(0));
        // A point light's faces look along ±x, ±y, ±z: each face's centre direction lands in the
        // middle of its own layer.
        let faces = p.light_views(1);
        let at = lights[1].position;
        for (k, d) in [
            Vec3::X,
            Vec3::NEG_X,
            Vec3::Y,
            Vec3::NEG_Y,
            Vec3::Z,
            Vec3::NEG_Z,
        ]
        .iter()
        .enumerate()
        {
            let c = faces[k].light_clip_from_world * (at + *d).extend(1.0);
            let ndc = c.truncate() / c.w;
            assert!(
                ndc.x.abs() < 1e-4 && ndc.y.abs() < 1e-4 && c.w > 0.0,
                "face {k}: {ndc}"
            );
        }
    }
}
