//! What a frame is rendered with: view, shadow and output settings.

pub use crate::math::tonemap::Tonemap;
use crate::scene::Camera;
use glam::Vec3;

/// Linear colour where nothing is drawn (the CPU reference uses it too).
pub const CLEAR_COLOR: [f32; 4] = [0.02, 0.02, 0.025, 1.0];

/// What the camera pass writes (the command line's `--view`; `clap::ValueEnum` with the `clap` feature).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum ViewMode {
    /// The shaded image.
    #[default]
    Lit,
    /// The shadowed light's visibility term alone (the factor the lit image multiplies by):
    /// 255 where lit, 0 where blocked or facing away, grey in filtered penumbrae.
    Shadow,
    /// World normals after normal mapping, encoded n·0.5+0.5.
    Normals,
    /// The shadow map itself (grey = depth, reversed-z: white is near the light).
    ShadowMap,
    /// Which shadow view (cascade) shades each pixel: red, green, blue, yellow for cascades 0–3,
    /// darkened where in shadow; grey where no map is read.
    Cascades,
    /// Texture coordinates 0 as a grey checker, 8 cells per unit (bytes 38 and 217).
    UvChecker,
    /// World tangents after orthogonalising against the normal, encoded t·0.5+0.5.
    Tangents,
    /// World bitangents (n × t · w), encoded b·0.5+0.5.
    Bitangents,
    /// Base colour (factor × texture), as stored: sRGB bytes, no lighting.
    BaseColor,
    /// Metallic (factor × texture blue) as grey bytes.
    Metallic,
    /// Roughness (factor × texture green) as grey bytes.
    Roughness,
    /// Linear view depth: white at the eye, black at the scene's far end (`1 − z / z_far`).
    Depth,
    /// Screen pixels per shadow-map texel as a heat map, log2 over 1/16…16: dark blue where
    /// texels are finer than pixels, teal-yellow near 1:1, white where a texel spans many pixels
    /// (blocky shadows). Grey without a shadow map.
    TexelDensity,
    /// Fragments rasterised per pixel (no depth test, additive): each adds 1/16 in linear light,
    /// so a pixel's byte decodes to n/16 (n up to 16).
    Overdraw,
}

impl ViewMode {
    /// Shader constant.
    pub fn shader_value(self) -> u32 {
        use crate::shader_consts::scene as sh;
        match self {
            ViewMode::Lit | ViewMode::ShadowMap => sh::VIEW_LIT,
            ViewMode::Shadow => sh::VIEW_SHADOW,
            ViewMode::Normals => sh::VIEW_NORMALS,
            ViewMode::Cascades => sh::VIEW_CASCADES,
            ViewMode::UvChecker => sh::VIEW_UV_CHECKER,
            ViewMode::Tangents => sh::VIEW_TANGENTS,
            ViewMode::Bitangents => sh::VIEW_BITANGENTS,
            ViewMode::BaseColor => sh::VIEW_BASE_COLOR,
            ViewMode::Metallic => sh::VIEW_METALLIC,
            ViewMode::Roughness => sh::VIEW_ROUGHNESS,
            ViewMode::Depth => sh::VIEW_DEPTH,
            ViewMode::TexelDensity => sh::VIEW_TEXEL_DENSITY,
            ViewMode::Overdraw => sh::VIEW_OVERDRAW,
        }
    }
}

/// Shadow-map filtering kernel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pcf {
    /// One nearest-texel comparison.
    None,
    /// One bilinear 2×2 comparison.
    P2x2,
    /// 3×3 bilinear taps at one-texel spacing (a 4×4-texel footprint).
    P3x3,
    /// 5×5 bilinear taps (a 6×6-texel footprint).
    P5x5,
}

impl Pcf {
    /// Bilinear taps per side (0 for nearest).
    pub fn taps(self) -> u32 {
        match self {
            Pcf::None => 0,
            Pcf::P2x2 => 1,
            Pcf::P3x3 => 3,
            Pcf::P5x5 => 5,
        }
    }

    /// How many texels from its centre a lookup reads: half the kernel's bilinear taps, plus the
    /// 2×2 texels of each tap (1 for the single nearest comparison).
    pub fn lookup_reach(self) -> u32 {
        self.taps().saturating_sub(1) / 2 + 1
    }
}

/// Depth format of the shadow map.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShadowFormat {
    /// 32-bit float.
    D32,
    /// 16-bit unorm.
    D16,
    /// Per frame (the default): D16 where its depth step is too small to matter (every view
    /// orthographic and its step at most a quarter of the constant bias, `plan::resolve_format`),
    /// else D32. Half the bytes a texel to write and read.
    Auto,
}

impl std::str::FromStr for ShadowFormat {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "d32" => Ok(Self::D32),
            "d16" => Ok(Self::D16),
            "auto" => Ok(Self::Auto),
            _ => Err(format!("shadow format '{s}' is not auto, d16 or d32")),
        }
    }
}

/// How the shadowed light's visibility is decided.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ShadowMethod {
    /// Shadow maps (the default): cascades, PCF or PCSS, bias.
    #[default]
    Map,
    /// Exact hard shadows by an irregular z-buffer (`crate::render::passes::exact`): each pixel's
    /// shadow ray tested against the caster triangles themselves, no bias, no texels. For one
    /// shadowed light: directional (the map's single cascade behind it), spot, or point (a grid
    /// per cube face); frames with several shadowed lights, and devices without fragment-shader
    /// stores, use maps. Hard: a light's size is ignored.
    Exact,
}

impl std::str::FromStr for ShadowMethod {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "map" => Ok(Self::Map),
            "exact" => Ok(Self::Exact),
            _ => Err(format!("shadow method '{s}' is not map or exact")),
        }
    }
}

/// Anti-aliasing applied to the finished lit image (after any MSAA resolve).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum PostAa {
    /// None (the default: pictures as drawn).
    #[default]
    None,
    /// FXAA (Lottes 2009, the published "quality" algorithm): each pixel whose 3×3 luma range
    /// marks an edge is resampled across the edge by its estimated coverage; flat pixels are
    /// copied unchanged. One full-screen pass: the smooth-edge option a CPU device can afford
    /// (docs/speed.md has its cost and edge error beside MSAA's).
    Fxaa,
}

impl std::str::FromStr for PostAa {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "none" | "off" => Ok(Self::None),
            "fxaa" => Ok(Self::Fxaa),
            _ => Err(format!("post anti-aliasing '{s}' is not none or fxaa")),
        }
    }
}

/// How the directional light's frustum is fitted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShadowFit {
    /// To the camera frustum ∩ scene bounds (receivers), extended to all casters.
    Camera,
    /// To the whole scene bounds.
    Scene,
    /// To the camera like `Camera`, but each map (or cascade) covers the bounding sphere of its
    /// slice of the camera frustum, within the scene's bounds: its size does not change as the
    /// camera moves or turns (only with the depth range, field of view and aspect), so snapped
    /// maps step, and shimmer, far less often, for coarser texels than `Camera` (1.2–2× on the
    /// built-in and sample scenes' first views).
    Sphere,
}

/// Shadow settings. Biases are in the units named; the defaults were chosen by the acne and
/// peter-panning tests (`tests/gpu_shadows.rs`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowSettings {
    /// Shadows on or off.
    pub enabled: bool,
    /// Shadow maps or exact shadows.
    pub method: ShadowMethod,
    /// Contact shadows over the maps (`crate::render::passes::exact`): each pixel's shadow ray
    /// marched a few texels towards the shown light through the depth the camera sees, dark where
    /// it passes behind a surface. Restores contact detail finer than the map's texels; sees only
    /// what the camera sees. Hard shadows only (not with PCSS), devices with fragment-shader
    /// stores; ignored with exact shadows, which need none.
    pub contact: bool,
    /// Map size in texels (square), within [`ShadowSettings::MAP_SIZES`] (the renderer clamps
    /// other values into it).
    pub map_size: u32,
    /// Depth format.
    pub format: ShadowFormat,
    /// Filter.
    pub pcf: Pcf,
    /// Constant bias in shadow texels: the receiver's lookup point moves this many texel widths
    /// towards the light (so the bias follows the texel's world size).
    pub constant_bias: f32,
    /// Slope-scaled depth bias (hardware, multiplies the caster's depth slope), applied away from
    /// the light (negated internally for reversed-z).
    pub slope_bias: f32,
    /// Normal-offset bias in shadow texels (scaled by the texel's world size and sin θ).
    pub normal_offset: f32,
    /// Frustum fitting.
    pub fit: ShadowFit,
    /// Snap the fitted frustum to whole texels (stable under camera motion).
    pub snap: bool,
    /// With `snap`, steps per doubling of the fitted extent's ladder: the map changes size only
    /// when the extent crosses a step, and each change moves every shadow edge by up to a texel
    /// (shimmer). 8 (the default, 2^(1/8) apart) costs 4.5 % in texel size on average; 1 (powers
    /// of two) steps 7× less often on the stability suite's FlightHelmet flythrough (shimmer
    /// 3.1·10⁻⁴ → 8.7·10⁻⁵ per frame) for 44 % coarser texels on average (17 % along that path).
    pub extent_steps: u32,
    /// Cascades of a directional light's map fitted to the camera (1–4; `MAX_CASCADES`): each
    /// covers a slice of the view depth with its own `map_size`² layer. 1 is the single map; 0
    /// (the default) chooses per frame from how much coarser than a pixel one map's texels would
    /// be at the nearest receiver (`plan::views::auto_cascades`), drawing one map of twice the
    /// side instead of two cascades where that suffices (`plan::views::auto_doubles_map`).
    pub cascades: u32,
    /// Side in texels of each of a point light's six cube faces (each fills that square of its
    /// own layer); 0 (the default) is half of `map_size`, so a cube costs 1.5 maps of texels, not
    /// six.
    pub cube_face: u32,
    /// Sample-distribution fitting (SDSM, Lauritzen et al. 2010): a directional light's cascades
    /// are split over, and fitted to, the view depths the camera actually sees (the nearest and
    /// farthest depth in its depth buffer, grown by 1 %) instead of where its frustum meets the
    /// receivers' boxes, so a view that sees only near things spends every texel near. The
    /// offscreen renderer measures them with a first pass at each new camera (a frame at a new
    /// camera costs two); `View::visible_depths` can also be given.
    pub depth_fit: bool,
    /// Soft shadows (PCSS) for lights with a size (`crate::scene::Light::size`); false: hard
    /// PCF whatever their size (the sweep's hard configurations against an area light).
    pub soft: bool,
}

/// Most cascades a directional light can have.
pub const MAX_CASCADES: u32 = 4;

impl ShadowSettings {
    /// The shadow-map sizes the renderer accepts, in texels: the one range every front end
    /// checks against.
    pub const MAP_SIZES: std::ops::RangeInclusive<u32> = 16..=16384;

    /// `map_size` clamped into [`Self::MAP_SIZES`].
    pub fn clamped_map_size(&self) -> u32 {
        self.map_size
            .clamp(*Self::MAP_SIZES.start(), *Self::MAP_SIZES.end())
    }
}

impl Default for ShadowSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            method: ShadowMethod::Map,
            contact: false,
            map_size: 2048,
            format: ShadowFormat::Auto,
            pcf: Pcf::P2x2,
            constant_bias: 1.0,
            slope_bias: 1.5,
            normal_offset: 1.5,
            fit: ShadowFit::Camera,
            snap: true,
            extent_steps: 8,
            cascades: 0,
            cube_face: 0,
            depth_fit: false,
            soft: true,
        }
    }
}

/// Options fixed when a scene is uploaded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SceneOptions {
    /// Anisotropic texture filtering (1 = off). `None`: 8× on GPUs, off on CPU devices, where
    /// it more than doubles lavapipe's camera pass (demo, 1280×720: 80 → 37 ms without shadows).
    pub anisotropy: Option<u32>,
    /// Skip work that cannot change the image: draws outside the camera's view, back faces of
    /// closed double-sided meshes seen from outside, and the clear parts of lone cutout cards in
    /// the shadow passes (`crate::scene::mesh::trim`). On by default; off only to measure what it
    /// saves.
    pub culling: bool,
    /// Multisample anti-aliasing: samples per pixel of the camera pass (1, 2, 4 or 8). `None`:
    /// 4 on GPUs, 1 on CPU devices (lavapipe, where 4 samples cost
    /// `docs/speed.md`'s measured share of the frame). A count the device lacks falls to the
    /// largest it has below it (`resolved_samples`).
    pub msaa: Option<u32>,
    /// Where textures' mip chains are made: `Some(true)` on the CPU at upload
    /// (`crate::math::mips::mip_chain`, the same bytes on every device), `Some(false)` by linear
    /// blits on the device. `None`: the CPU on CPU devices (on lavapipe the blits run on the CPU
    /// too, after compiling blitter shaders that Mesa's shader cache does not keep: ~200 ms of
    /// every start), blits on GPUs.
    pub cpu_mips: Option<bool>,
    /// Shade draws of triangles smaller than llvmpipe's 4×4 shading block deferred
    /// (`crate::render::passes::deferred`: a G-buffer, then each covered pixel shaded once). `None`: on
    /// CPU devices at one sample per pixel, off on GPUs (which shade 2×2 quads in hardware).
    pub deferred: Option<bool>,
    /// Draw small receivers (a ground) without the shadow lookup where no caster can shadow them
    /// (`crate::render::passes::receivers`: the same image; llvmpipe runs the lookup even where a
    /// branch skips it). `None`: on for CPU devices, off on GPUs (whose branches skip it).
    pub receiver_split: Option<bool>,
    /// Reuse shadow-map layers across frames (`crate::render::passes::shadow_cache`): a layer whose
    /// light matrix, area and static casters are those of the last frame is not redrawn, and
    /// only moving casters (animated or deforming) are drawn over a cached copy of the static
    /// ones. The same image to the bit. Off by default (each `render` then measures the whole
    /// shadow pass); the viewer and image sequences turn it on.
    pub shadow_cache: bool,
}

impl Default for SceneOptions {
    fn default() -> Self {
        Self {
            anisotropy: None,
            culling: true,
            msaa: None,
            cpu_mips: None,
            deferred: None,
            receiver_split: None,
            shadow_cache: false,
        }
    }
}

/// What the plan needs to know of a device, as plain values (`render::device_facts` reads them
/// from a Vulkan context): the plan never sees the device itself.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeviceFacts {
    /// A CPU device (lavapipe): the defaults that pay there differ.
    pub cpu: bool,
    /// Sample counts (bit n set: 2ⁿ samples) that colour and depth attachments both support.
    pub sample_counts: u32,
    /// Whether the deferred path's formats work: D32_SFLOAT_S8_UINT as a depth-stencil
    /// attachment, R32G32B32A32_SFLOAT as a colour attachment and sampled image.
    pub deferred_formats: bool,
    /// The largest sampler anisotropy, None when the feature is off.
    pub max_anisotropy: Option<f32>,
}

impl SceneOptions {
    /// The MSAA sample count to use on the device: `msaa` (or the device class's default)
    /// rounded down to a count its colour and depth attachments both support.
    pub fn resolved_samples(&self, device: &DeviceFacts) -> u32 {
        let wanted = self
            .msaa
            .unwrap_or(if device.cpu { 1 } else { 4 })
            .clamp(1, 64);
        // The largest power of two not above `wanted`, then down to what the device has.
        let mut n = 1u32 << wanted.ilog2();
        while n > 1 && device.sample_counts & n == 0 {
            n /= 2;
        }
        n.max(1)
    }

    /// Whether mip chains are made on the CPU on the device (`cpu_mips`, or its default).
    pub fn resolved_cpu_mips(&self, device: &DeviceFacts) -> bool {
        self.cpu_mips.unwrap_or(device.cpu)
    }

    /// Whether micro-triangle draws may be shaded deferred on the device (`deferred`, or its
    /// default; the camera pass also needs one sample per pixel).
    pub fn resolved_deferred(&self, device: &DeviceFacts) -> bool {
        self.deferred.unwrap_or(device.cpu) && device.deferred_formats
    }

    /// Whether small receivers are drawn unshadowed beyond the casters' reach on the device
    /// (`receiver_split`, or its default).
    pub fn resolved_receiver_split(&self, device: &DeviceFacts) -> bool {
        self.receiver_split.unwrap_or(device.cpu)
    }

    /// The anisotropy to use on the device (1.0 = off), clamped to what it supports.
    pub fn resolved_anisotropy(&self, device: &DeviceFacts) -> f32 {
        let Some(max) = device.max_anisotropy else {
            return 1.0;
        };
        let wanted = self
            .anisotropy
            .unwrap_or(if device.cpu { 1 } else { 8 })
            .max(1) as f32;
        wanted.min(max.max(1.0))
    }
}

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

impl std::str::FromStr for Pcf {
    type Err = String;

    /// `none`, `2x2`, `3x3` or `5x5`.
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "none" => Ok(Pcf::None),
            "2x2" => Ok(Pcf::P2x2),
            "3x3" => Ok(Pcf::P3x3),
            "5x5" => Ok(Pcf::P5x5),
            _ => Err(format!("filter '{s}' is not none, 2x2, 3x3 or 5x5")),
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
        }
    }
}
