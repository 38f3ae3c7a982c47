//! What a frame is asked to show: the `View` (camera, mode, shadow settings, exposure, tone curve,
//! background, ambient) and what it carries across frames (`ShadowHold`).

use super::batch::ShadowBatch;
use super::settings::{PostAa, ShadowSettings, Tonemap, ViewMode, CLEAR_COLOR};
use crate::scene::Camera;
use glam::Vec3;
use std::sync::Arc;

/// The default sky ambient as a fraction of the metered direct illuminance: what an up-facing
/// surface in shadow receives (0.34 under the demo's sun of 1.7). A clear sky gives a horizontal
/// surface 10–25 % of the sun's illuminance; a fifth keeps shadows readable without washing out
/// the key light.
pub const AUTO_SKY: f32 = 0.2;

/// The default ground (bounce) ambient as a fraction of the metered direct illuminance: what a
/// down-facing surface receives (a ground of albedo ~0.3 under the sky and sun).
pub const AUTO_GROUND: f32 = 0.06;

/// The default sky's colour, of luminance 1 (a pale blue).
pub const SKY_TINT: Vec3 = Vec3::new(0.89, 1.012, 1.2);

/// The default ground's colour, of luminance 1 (a warm grey).
pub const GROUND_TINT: Vec3 = Vec3::new(1.114, 0.985, 0.816);

/// The ambient umbra used before it followed the lights (`View::raw_output`), and where nothing
/// lights the scene.
pub const UNIT_AMBIENT: f32 = 0.12;

/// The ambient light Ia of Blinn-Phong's ka·Ia: a hemisphere, `sky` from above and `ground`
/// from below, blended by the normal's up (+Y) component, Ia(n) = mix(ground, sky, ½ + ½·n_y)
/// (three.js' hemisphere light); `sky` = `ground` is a flat ambient. The background of the lit
/// image is the same function of the view direction ([`Background::Sky`]).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Ambient {
    /// Ia of a surface facing straight up (rgb, in the lights' units).
    pub sky: Vec3,
    /// Ia of a surface facing straight down.
    pub ground: Vec3,
}

impl Ambient {
    /// The same Ia from every direction.
    pub fn flat(ia: Vec3) -> Self {
        Self {
            sky: ia,
            ground: ia,
        }
    }

    /// The default hemisphere for a metered direct illuminance `direct` ([`AUTO_SKY`],
    /// [`AUTO_GROUND`], tinted by [`SKY_TINT`] and [`GROUND_TINT`]).
    pub fn metered(direct: f32) -> Self {
        Self {
            sky: SKY_TINT * (AUTO_SKY * direct),
            ground: GROUND_TINT * (AUTO_GROUND * direct),
        }
    }

    /// Ia for a surface of unit normal `n` (or, for the background, seen along direction `n`).
    pub fn at(&self, n: Vec3) -> Vec3 {
        let up = (0.5 + 0.5 * n.y).clamp(0.0, 1.0);
        self.ground.lerp(self.sky, up)
    }

    /// Ia averaged over directions (what a vertical surface receives).
    pub fn mean(&self) -> Vec3 {
        0.5 * (self.sky + self.ground)
    }
}

/// What the lit image shows where no surface is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum Background {
    /// The ambient hemisphere seen along each pixel's view direction
    /// ([`Ambient::at`]), exposed and tone-mapped like the surfaces it lights: a sky gradient.
    #[default]
    Sky,
    /// A flat linear colour (written as it is: not exposed).
    Color(Vec3),
}

impl std::str::FromStr for Background {
    type Err = String;

    /// `sky`, or a display (sRGB) colour: `#RRGGBB`, or `R,G,B` / one grey value within 0..1
    /// (the command line's `--background`), kept as the linear colour cleared to.
    fn from_str(s: &str) -> Result<Self, String> {
        let t = s.trim();
        if t.eq_ignore_ascii_case("sky") {
            return Ok(Background::Sky);
        }
        let bad = || format!("background '{s}' must be sky, #RRGGBB or R,G,B within 0..1");
        let srgb: Vec<f32> = if let Some(hex) = t.strip_prefix('#') {
            if hex.len() != 6 {
                return Err(bad());
            }
            (0..3)
                .map(|k| {
                    hex.get(2 * k..2 * k + 2)
                        .and_then(|b| u8::from_str_radix(b, 16).ok())
                        .map(|b| b as f32 / 255.0)
                        .ok_or_else(bad)
                })
                .collect::<Result<_, _>>()?
        } else {
            t.split(',')
                .map(|v| v.trim().parse::<f32>().map_err(|_| bad()))
                .collect::<Result<_, _>>()?
        };
        let c = match srgb.as_slice() {
            [g] => Vec3::splat(*g),
            [r, g, b] => Vec3::new(*r, *g, *b),
            _ => return Err(bad()),
        };
        if !(c.is_finite() && c.min_element() >= 0.0 && c.max_element() <= 1.0) {
            return Err(bad());
        }
        Ok(Background::Color(
            c.map(crate::math::tonemap::srgb_to_linear),
        ))
    }
}

impl std::str::FromStr for Exposure {
    type Err = String;

    /// `auto`, an EV100 within −64..64, or `x` and a linear scale above 0 (the command line's
    /// `--exposure`).
    fn from_str(s: &str) -> Result<Self, String> {
        let t = s.trim();
        if t.eq_ignore_ascii_case("auto") {
            return Ok(Exposure::Auto);
        }
        if let Some(k) = t.strip_prefix(['x', 'X']) {
            return match k.trim().parse::<f32>() {
                Ok(v) if v.is_finite() && v > 0.0 => Ok(Exposure::Scale(v)),
                _ => Err(format!("exposure scale '{k}' must be a number above 0")),
            };
        }
        match t.parse::<f32>() {
            Ok(v) if v.is_finite() && v.abs() <= 64.0 => Ok(Exposure::Ev100(v)),
            _ => Err(format!(
                "'{s}' is not `auto`, an EV100 within -64..64, or `x` and a scale (e.g. x1)"
            )),
        }
    }
}

/// How bright the scene is drawn: the linear scale applied before tone mapping.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum Exposure {
    /// Metered from the scene's lights (the default): scale `math::tonemap::KEY_VALUE` / E (an
    /// 18 % grey card facing the key light lands at middle grey), E the illuminance the lights
    /// and the ambient term deliver at the centre of the scene's bounds
    /// (`frame::metered_illuminance`; EV100 `math::tonemap::metered_ev100`), so a scene
    /// authored in lux and candela and the same scene in unit intensities look alike.
    #[default]
    Auto,
    /// A camera's exposure value at ISO 100: scale 1 / (1.2 · 2^EV100).
    Ev100(f32),
    /// A linear scale (1 = the shading's values as they are; tests that want raw values).
    Scale(f32),
}

/// Everything that decides one frame's pixels besides the scene.
#[derive(Clone, Debug)]
pub struct View {
    /// The camera.
    pub camera: Camera,
    /// Override for the direction of the scene's first directional light (or the default sun).
    pub sun_direction: Option<Vec3>,
    /// Override for that light's intensity.
    pub sun_intensity: Option<f32>,
    /// Override for every light's emitter size (soft shadows by PCSS where it is above 0): a
    /// directional light's angular diameter in degrees (the sun: 0.53), a point or spot light's
    /// radius in scene units. `None`: each light's own ([`crate::scene::Light::size`]).
    pub light_size: Option<f32>,
    /// Output.
    pub mode: ViewMode,
    /// Shadow settings.
    pub shadow: ShadowSettings,
    /// A flat ambient Ia (the same from every direction), in the lights' units. `None` (the
    /// default): the sky and ground hemisphere [`Ambient::metered`] from the direct illuminance
    /// auto exposure meters (`frame::metered_illuminance`), so the fill follows the lights
    /// whatever their units (sky 0.34, ground 0.10 under the demo's sun of 1.7).
    pub ambient: Option<Vec3>,
    /// What the lit image shows where nothing is drawn (debug views always clear to
    /// [`crate::plan::CLEAR_COLOR`]).
    pub background: Background,
    /// Exposure before tone mapping (the lit image; debug views are not exposed).
    pub exposure: Exposure,
    /// Exposure compensation in stops on top of `exposure` (+1 doubles the scale; the viewer's
    /// `,` and `.` keys).
    pub exposure_compensation: f32,
    /// Tone-mapping curve from exposed values to the display (the lit image only).
    pub tonemap: Tonemap,
    /// Post-process anti-aliasing of the lit image ([`PostAa`]; debug views are not filtered).
    pub post_aa: PostAa,
    /// Supersampling of offscreen frames ([`SUPERSAMPLE_FACTORS`]): 1 (off) or 2, drawn at
    /// twice the width and height and filtered down to the asked size, each pixel the mean of
    /// its 2×2 samples in linear light: four samples a pixel, shading included, for less than
    /// 4× MSAA costs on lavapipe (docs/speed.md). The shadow maps are planned for the asked
    /// size's pixels (as with MSAA, a pixel's samples share its texels). The viewer draws at
    /// its window's size and ignores it.
    pub supersample: u32,
    /// Fit the light frustum to this camera instead of `camera` (for stability tests).
    pub shadow_fit_camera: Option<Camera>,
    /// Tint this (instance, primitive) orange in the lit image (the viewer's picked primitive).
    pub highlight: Option<(usize, usize)>,
    /// The light whose shadow visibility the shadow view shows (index into the frame's lights);
    /// None or a light without shadow views: the first shadowed light.
    pub shown_light: Option<usize>,
    /// The nearest and farthest view depth the camera sees (from its depth buffer), which
    /// `ShadowSettings::depth_fit` fits cascades to; the offscreen renderer measures it when
    /// None.
    pub visible_depths: Option<(f32, f32)>,
    /// The previous frame's snapped shadow extents, for a camera in motion (the viewer sets it
    /// each frame; see [`ShadowHold`]). None: every frame fitted afresh, as a still is.
    pub shadow_hold: Option<ShadowHold>,
    /// The cameras of a batch whose views share their shadow maps (`Renderer::render_batch`
    /// sets it; in world coordinates, also when the view is rebased): each directional light
    /// gets one map fitted to all of their frusta with the scene (no cascades, no hold, no depth
    /// fit), the same in every view of the batch, so the shadow cache draws it once for the
    /// whole batch. Spot and point lights' views never depend on the camera. None: fitted to
    /// this view alone.
    pub shadow_batch: Option<Arc<ShadowBatch>>,
}

/// The snapped extents a frame's directional lights used (per light: its direction, the side of
/// each of its views, nearest first, and the depth range its cascades were split over), carried
/// to the next frame. A light with the same direction and the same number of views keeps each
/// extent while it still covers what the new frame needs at most one doubling too coarse, and
/// otherwise steps from it by whole doublings; the cascades' depth range is kept while it covers
/// the receivers and otherwise only widens, by doublings (so their splits hold still): in motion a map changes size once per doubling of what the camera needs
/// instead of once per 2^(1/8), and each change moves every shadow edge (shimmer). A still (no
/// hold) keeps the fine ladder of `ShadowSettings::extent_steps`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ShadowHold {
    /// Per light of the frame's light list (by index): what a directional one used.
    pub lights: Vec<Option<HeldLight>>,
}

/// What one directional light's views used in a frame (see [`ShadowHold`]).
#[derive(Clone, Debug, PartialEq)]
pub struct HeldLight {
    /// The direction the light travelled.
    pub direction: Vec3,
    /// The side of each of its views, nearest first.
    pub extents: Vec<f32>,
    /// The view-depth range its cascades were split over (None for one map).
    pub depth_range: Option<(f32, f32)>,
}

impl ShadowHold {
    /// What light `i` used, if it travelled along `direction` then too.
    pub fn light(&self, i: usize, direction: Vec3) -> Option<&HeldLight> {
        self.lights
            .get(i)
            .and_then(Option::as_ref)
            .filter(|h| h.direction == direction)
    }
}

/// The values `View::supersample` takes.
pub const SUPERSAMPLE_FACTORS: [u32; 2] = [1, 2];

impl View {
    /// The same view in coordinates relative to `origin` (cameras moved; directions unchanged).
    pub fn rebased(&self, origin: Vec3) -> Self {
        let mut v = self.clone();
        v.camera = v.camera.rebased(origin);
        v.shadow_fit_camera = v.shadow_fit_camera.map(|c| c.rebased(origin));
        v
    }

    /// The same view with its lit image's raw values: exposure 1, no tone curve (values
    /// clamped to [0, 1]), unless set a flat ambient of [`UNIT_AMBIENT`], and the clear colour
    /// behind, as umbra drew before exposure and the sky existed; for tests that check levels.
    pub fn raw_output(mut self) -> Self {
        self.exposure = Exposure::Scale(1.0);
        self.exposure_compensation = 0.0;
        self.ambient = self.ambient.or(Some(Vec3::splat(UNIT_AMBIENT)));
        self.tonemap = Tonemap::None;
        let c = CLEAR_COLOR;
        self.background = Background::Color(Vec3::new(c[0], c[1], c[2]));
        self
    }

    /// A view through `camera` with default settings.
    pub fn new(camera: Camera) -> Self {
        Self {
            camera,
            sun_direction: None,
            sun_intensity: None,
            light_size: None,
            mode: ViewMode::Lit,
            shadow: ShadowSettings::default(),
            ambient: None,
            background: Background::Sky,
            exposure: Exposure::Auto,
            exposure_compensation: 0.0,
            tonemap: Tonemap::Neutral,
            post_aa: PostAa::None,
            supersample: 1,
            shadow_fit_camera: None,
            highlight: None,
            shown_light: None,
            visible_depths: None,
            shadow_hold: None,
            shadow_batch: None,
        }
    }
}
