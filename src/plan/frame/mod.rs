//! Per-frame planning on the CPU: the camera projection, the frame plan made from the lights
//! (`super::lights`) and shadow views (`super::views`), and the frame uniform block.

use super::camera::camera_projection;
use super::casters::{plan_casters, Viewpoint};
use super::exact::{exact_asked, ExactMode, ExactPlan};
use super::input::{PlanScene, PlanTarget};
use super::lights::{effective_lights, light_uniforms, metering};
use super::settings::{Pcf, ShadowFit, ShadowFormat, ShadowMethod, ShadowSettings, Tonemap};
use super::sight::Sight;
use super::uniforms::{FrameUniform, MAX_LIGHTS};
use super::view::{Ambient, Background, Exposure, HeldLight, ShadowHold, View};
use super::views::lookup_reach;
use super::views::{far_view_depth, shadow_views, view_uniforms, ShadowView};
use crate::math::Aabb;
use crate::scene::{Light, LightKind};
use crate::shader_consts::VariantKey;
use finish::finish;
use glam::{Mat4, Vec3, Vec4};

pub use super::settings::CLEAR_COLOR;

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
    /// The shadow map's depth format (`ShadowFormat::Auto` resolved: never `Auto`).
    pub shadow_format: ShadowFormat,
    /// The slope-scaled depth bias the shadow pass draws with (`ShadowSettings::slope_bias`; 0
    /// for hybrid shadows, whose map must hold the casters' own depths).
    pub slope_bias: f32,
    /// The camera's world position.
    pub camera_position: Vec3,
    /// Whether the camera projects in parallel (every pixel seen along its forward direction).
    pub orthographic: bool,
    /// The scene shader's variant bits this frame sets (one light, shadows sampled, comparison
    /// path, PCF kernel); each draw adds its material's bits.
    pub(crate) shader_variant: VariantKey,
    /// What decided the shown light's visibility per pixel beside the maps, when anything did
    /// (set when the frame is prepared on the device).
    pub(crate) exact: Option<ExactPlan>,
    /// What the camera culls with (eye, viewpoint, the shadow view's reach).
    pub sight: Sight,
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
    /// The linear scale applied to the lit image before tone mapping (`View::exposure`
    /// resolved: auto exposure metered from this frame's lights).
    pub exposure: f32,
    /// The tone-mapping curve of the lit image.
    pub tonemap: Tonemap,
    /// The ambient Ia this frame is shaded with (`View::ambient` resolved: the sky and ground
    /// hemisphere, or a flat one).
    pub ambient: Ambient,
    /// What the lit image shows where nothing is drawn.
    pub background: Background,
    /// How unlit (KHR_materials_unlit) colours are shown: `Some(k)`, as authored × k, clamped,
    /// with no tone curve (the automatic exposure: k = 2^compensation, so an authored texel is
    /// the displayed one whatever lights the scene); `None`, exposed and tone-mapped like lit
    /// colours (an exposure was given).
    pub unlit_scale: Option<f32>,
    /// What auto exposure metered for this frame ([`metered_illuminance`] with `ambient`), used
    /// or not.
    pub metered_lux: f32,
    /// What every position and matrix of this plan is relative to (world = plan + origin):
    /// [`crate::scene::Scene::render_origin`] when planned by the renderer, zero from
    /// [`plan_frame`].
    pub origin: Vec3,
}

impl FramePlan {
    /// Side of the shadow map's layers in texels: the map size, or more where the automatic
    /// setting doubled a view (held once, in the uniform block the shader reads).
    pub fn shadow_map_size(&self) -> u32 {
        self.uniform.shadow.x as u32
    }

    /// Plans each shadow view's casters among `scene`'s draws and packs their lookup rectangles
    /// into the uniform block (`full`: every view's whole square is drawn, the map debug view).
    fn plan_casters(&mut self, scene: &PlanScene, pcf: Pcf, full: bool) {
        if !self.shadows_on {
            return;
        }
        let reach = lookup_reach(pcf, self.soft);
        for c in 0..self.shadow_views.len() {
            let v = &self.shadow_views[c];
            let light = self.light_source(v.light);
            let cp = plan_casters(scene, &v.light_clip_from_world, light, v.res, reach, full);
            self.uniform.views[c].rect = cp.lookup;
            self.shadow_views[c].casters = cp;
        }
    }

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

    /// The display value of a surface's colour (`display_surface`): an unlit material's as
    /// authored at the automatic exposure ([`FramePlan::unlit_scale`]), else [`Self::display`].
    pub fn display_surface(&self, rgb: Vec3, unlit: bool) -> Vec3 {
        match self.unlit_scale {
            Some(k) if unlit => (rgb * k).clamp(Vec3::ZERO, Vec3::ONE),
            _ => self.display(rgb),
        }
    }

    /// The unit direction the camera looks along at image position (`x`, `y`) (pixel units,
    /// centres at +0.5) of a `w`×`h` image: from the near plane's point there to the point at
    /// half the depth range, as the sky pass computes it (from the eye through the pixel for a
    /// perspective camera; the camera's forward for an orthographic one).
    pub fn view_direction(&self, x: f32, y: f32, w: u32, h: u32) -> Vec3 {
        let ndc = crate::math::projection::pixel_to_ndc(x, y, w, h);
        let inv = self.uniform.world_from_clip;
        let at = |depth: f32| {
            let p = inv * Vec4::new(ndc.x, ndc.y, depth, 1.0);
            p.truncate() / p.w
        };
        (at(0.5) - at(1.0)).normalize_or(Vec3::NEG_Z)
    }

    /// The lit image's background alone at `w`×`h` (what a frame with nothing drawn shows):
    /// [`Self::background_along`] each pixel's [`Self::view_direction`], sRGB-encoded.
    pub fn background_image(&self, w: u32, h: u32) -> image::RgbaImage {
        let byte = |c: f32| {
            (crate::math::tonemap::linear_to_srgb(c.clamp(0.0, 1.0)) * 255.0).round() as u8
        };
        image::RgbaImage::from_fn(w, h, |x, y| {
            let c =
                self.background_along(self.view_direction(x as f32 + 0.5, y as f32 + 0.5, w, h));
            image::Rgba([byte(c.x), byte(c.y), byte(c.z), 255])
        })
    }

    /// The lit image's background seen along unit direction `dir` (the sky pass's `fs_sky`):
    /// the ambient hemisphere exposed and tone-mapped, or the flat colour.
    pub fn background_along(&self, dir: Vec3) -> Vec3 {
        match self.background {
            Background::Sky => self.display(self.ambient.at(dir)),
            Background::Color(c) => c,
        }
    }

    /// Whether the frame's shadowed light is judged by the exact pass
    /// ([`crate::plan::ShadowMethod::Exact`]) rather than its map.
    pub fn exact_shadows(&self) -> bool {
        matches!(&self.exact, Some(e) if e.mode == ExactMode::Exact)
    }

    /// Whether this frame's exact shadows are hybrid: the map's verdict kept where it is
    /// certain ([`crate::plan::ShadowMethod::Hybrid`]).
    pub fn hybrid_shadows(&self) -> bool {
        matches!(&self.exact, Some(e) if e.hybrid.is_some())
    }

    /// Whether contact shadows darkened the shown light's creases this frame
    /// ([`crate::plan::ShadowSettings::contact`]).
    pub fn contact_shadows(&self) -> bool {
        matches!(&self.exact, Some(e) if matches!(e.mode, ExactMode::Contact { .. }))
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
        plan_frame(
            &PlanScene {
                lights: &self.lights,
                bounds: &self.bounds,
                receivers: &self.receivers,
                planes: &[],
                origin: self.origin,
            },
            &view.rebased(self.origin),
            &PlanTarget {
                aspect: w as f32 / h.max(1) as f32,
                height_px: h,
                hw_compare: false,
                exact_capable: true,
                receiver_split: false,
            },
        )
    }
}

/// The depth format `settings.format` asks for, `Auto` resolved for the shadow `views`: D16
/// where every view is orthographic (a directional light's, whose depth is linear) and one D16
/// step across its depth range is at most a quarter of the constant bias (which moves each lookup
/// `constant_bias` texel widths towards the light), so rounding a stored depth can never undo
/// more than a quarter of the bias; D32 otherwise (spot and point lights' perspective depth,
/// depth ranges far deeper than a texel is wide, no constant bias).
pub fn resolve_format(settings: &ShadowSettings, views: &[ShadowView]) -> ShadowFormat {
    if settings.format != ShadowFormat::Auto {
        return settings.format;
    }
    let fits = |v: &ShadowView| {
        let m = v.light_clip_from_world;
        let orthographic = m.row(3) == Vec4::W;
        // Clip z is linear in world position: its gradient's length is 1 / the depth range.
        let range = 1.0 / m.row(2).truncate().length();
        orthographic
            && range.is_finite()
            && range / 65535.0 <= 0.25 * settings.constant_bias * v.texel_world
    };
    if !views.is_empty() && views.iter().all(fits) {
        ShadowFormat::D16
    } else {
        ShadowFormat::D32
    }
}

/// Plans a frame for `view` of `scene` rendered into `target`: pure, no GPU.
pub fn plan_frame(scene: &PlanScene, view: &View, target: &PlanTarget) -> FramePlan {
    let view = &settled(view, target);
    let (aspect, hw_compare) = (target.aspect, target.hw_compare);
    let bounds = scene.bounds;
    let lights = effective_lights(scene.lights, view);
    let proj = camera_projection(&view.camera, aspect);
    let clip_from_world = proj * view.camera.view_from_world();
    let (views, unshadowed) = shadow_views(&lights, scene, view, target);
    // The layers' side: the map size, or more where the automatic setting doubled a view.
    let size = views
        .iter()
        .map(|v| v.res)
        .fold(view.shadow.map_size.max(1), u32::max);
    let has_views = |i: usize| views.iter().any(|v| v.light == i);
    let shadow_light = view
        .shown_light
        .filter(|&i| has_views(i))
        .or_else(|| views.first().map(|v| v.light));
    let shadows_on = view.shadow.enabled && shadow_light.is_some();
    let (ambient, metered_lux, exposure) = metering(&lights, scene, view);
    let unlit_scale = (view.exposure == Exposure::Auto)
        .then(|| view.exposure_compensation.clamp(-64.0, 64.0).exp2());
    let u = frame_uniform(
        view,
        &UniformInputs {
            clip_from_world,
            map_size: size,
            far: far_view_depth(&view.camera, bounds),
            shadows_on,
            shadow_light,
            hw_compare,
            lights: &lights,
            views: &views,
            ambient,
            exposure,
            unlit_scale,
        },
    );
    // Soft where a shadowed light's uniform carries a size (set above).
    let soft = shadows_on && u.lights.iter().any(|l| l.direction.w > 0.0);
    let shadow_format = resolve_format(&view.shadow, &views);
    let mut plan = FramePlan {
        uniform: u,
        shadows_on,
        soft,
        shadow_format,
        slope_bias: view.shadow.slope_bias,
        camera_position: view.camera.position(),
        orthographic: view.camera.is_orthographic(),
        exact: None,
        sight: Sight {
            eye: (Vec3::ZERO, 0.0),
            viewpoint: Viewpoint::Along(Vec3::NEG_Z),
            shadow_reach: None,
        },
        shader_variant: frame_variant_bits(
            lights.len() == 1 && lights[0].kind == LightKind::Directional,
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
        origin: scene.origin,
        exposure,
        tonemap: view.tonemap,
        ambient,
        background: view.background,
        unlit_scale,
        metered_lux,
    };
    finish(&mut plan, scene, view, target);
    plan
}

/// `view` as the plan reads it: the map size settled (the one place: clamped into
/// `ShadowSettings::MAP_SIZES`, 1 without shadows; the layers' side,
/// `FramePlan::shadow_map_size`, follows from it), and with exact shadows on a device that
/// draws them one view (the map's single cascade, for the pixels they do not judge), hard; for
/// hybrid shadows, whose certainty test reads the casters' own depths from the map, that map in
/// D32 without slope bias.
fn settled(view: &View, target: &PlanTarget) -> View {
    let mut v = view.clone();
    v.shadow.map_size = if view.shadow.enabled {
        view.shadow.clamped_map_size()
    } else {
        1
    };
    if view.shadow_batch.is_some() {
        // One map per directional light, the same in every view of the batch.
        v.shadow.cascades = 1;
        v.shadow.depth_fit = false;
        v.shadow_hold = None;
        if v.shadow.fit == ShadowFit::Sphere {
            v.shadow.fit = ShadowFit::Camera;
        }
    }
    if exact_asked(view, target.exact_capable) {
        v.shadow.cascades = 1;
        v.shadow.soft = false;
        if view.shadow.method == ShadowMethod::Hybrid {
            v.shadow.slope_bias = 0.0;
            v.shadow.format = ShadowFormat::D32;
        }
    }
    v
}

/// What the frame's uniform block is made from, beside the view.
struct UniformInputs<'a> {
    clip_from_world: Mat4,
    map_size: u32,
    /// The farthest view depth of the scene.
    far: f32,
    shadows_on: bool,
    shadow_light: Option<usize>,
    hw_compare: bool,
    lights: &'a [Light],
    views: &'a [ShadowView],
    ambient: Ambient,
    exposure: f32,
    unlit_scale: Option<f32>,
}

/// The frame's uniform block.
fn frame_uniform(view: &View, f: &UniformInputs) -> FrameUniform {
    let fit_camera = view.shadow_fit_camera.as_ref().unwrap_or(&view.camera);
    FrameUniform {
        clip_from_world: f.clip_from_world,
        world_from_clip: f.clip_from_world.as_dmat4().inverse().as_mat4(),
        camera_position: view.camera.position().extend(1.0),
        ambient_sky: f.ambient.sky.extend(0.0),
        ambient_ground: f.ambient.ground.extend(0.0),
        shadow: Vec4::new(
            f.map_size as f32,
            view.shadow.normal_offset,
            f.far,
            if f.shadows_on { 1.0 } else { 0.0 },
        ),
        // No shown light: an index the shader's light loop never reaches. xyz: the eye the
        // cascades were split from (the fitting camera, which is the view's unless a test or
        // the stability suite fits the shadows to another camera).
        shadow_light: fit_camera
            .position()
            .extend(f.shadow_light.map_or(MAX_LIGHTS as f32 + 1.0, |i| i as f32)),
        bias: Vec4::new(view.shadow.constant_bias, 0.0, 0.0, 0.0),
        camera_forward: (fit_camera
            .view_from_world()
            .inverse()
            .transform_vector3(Vec3::NEG_Z))
        .normalize_or(Vec3::NEG_Z)
        .extend(0.0),
        eye_forward: view
            .camera
            .forward()
            .extend(if view.camera.is_orthographic() {
                1.0
            } else {
                0.0
            }),
        modes: [
            view.mode.shader_value(),
            view.shadow.pcf.taps(),
            f.hw_compare as u32,
            f.lights.len() as u32,
        ],
        output: Vec4::new(
            f.exposure,
            view.tonemap.shader_value(),
            f.unlit_scale.unwrap_or(1.0),
            if f.unlit_scale.is_some() { 1.0 } else { 0.0 },
        ),
        lights: light_uniforms(f.lights, f.views, view),
        views: view_uniforms(f.views),
    }
}

/// The scene shader's frame variant bits: one directional light and nothing else (a constant
/// loop without the point and spot code, which llvmpipe would run masked for every pixel),
/// shadows sampled, hardware comparison, and the PCF kernel (constant loops instead of
/// per-frame uniforms).
fn frame_variant_bits(
    one_sun: bool,
    shadows_on: bool,
    hw_compare: bool,
    pcf: Pcf,
    views: usize,
    soft: bool,
) -> VariantKey {
    let mut bits = VariantKey::empty();
    if one_sun {
        bits |= VariantKey::ONE_SUN;
    }
    // The filter, comparison path and cascades mean nothing without a map (one shader for all).
    if !shadows_on {
        return bits;
    }
    bits |= VariantKey::SHADOWS
        | match pcf {
            Pcf::None => VariantKey::empty(),
            Pcf::P2x2 => VariantKey::PCF_BIT0,
            Pcf::P3x3 => VariantKey::PCF_BIT1,
            Pcf::P5x5 => VariantKey::PCF_BIT0 | VariantKey::PCF_BIT1,
        };
    for (on, bit) in [
        (hw_compare, VariantKey::HW_COMPARE),
        (views > 1, VariantKey::MANY_VIEWS),
        (soft, VariantKey::SOFT),
    ] {
        if on {
            bits |= bit;
        }
    }
    bits
}

mod finish;

#[cfg(test)]
mod tests;
