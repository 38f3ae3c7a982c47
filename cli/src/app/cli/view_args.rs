//! The view options every subcommand shares (`ViewArgs`) and the PCF kernel argument.

use crate::app::parse::{
    parse_ambient, parse_background, parse_budget, parse_exposure, parse_msaa, parse_on_off,
    parse_size, parse_time, parse_vec3,
};
use clap::{Args, ValueEnum};
use glam::Vec3;
use umbra::plan::{Background, Exposure, Pcf, ShadowSettings, Tonemap, ViewMode};

/// PCF kernels.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum PcfArg {
    /// Single nearest comparison.
    None,
    /// One bilinear 2×2 comparison.
    #[value(name = "2x2")]
    P2x2,
    /// 3×3 bilinear taps.
    #[value(name = "3x3")]
    P3x3,
    /// 5×5 bilinear taps.
    #[value(name = "5x5")]
    P5x5,
}

/// View options shared by the subcommands.
#[derive(Args, Debug, Clone)]
pub struct ViewArgs {
    /// Draw everything: no frustum culling, no back-face culling of closed double-sided meshes,
    /// no leaf cards cut to their alpha in the shadow pass (to measure what they save; the image
    /// is the same).
    #[arg(long)]
    pub no_culling: bool,
    /// A generated scene instead of SCENE: `double-sided` (52k triangles, 12 double-sided
    /// primitives), `close-up` (51k triangles of open, organic double-sided models filling a
    /// third of a close view), `foliage` and `foliage-masked` (six trees of textured leaf cards,
    /// blended or masked at 0.5, seen from a metre above the ground), `town` (2 km across,
    /// cameras at eye height and on a roof), `town-mover` (the town
    /// with a person-sized box walking across the street: animation \"move\"), `grazing` (a sun 6° above the
    /// horizon over posts, spheres and crates), `stability` (a thin wall, a box, spheres and a
    /// torus: the stability suite's scene), `room` (a point light in a furnished room),
    /// `sun-and-spot` and `two-suns` (a yard where two lights cast), `lux-yard` (the yard lit in
    /// lux and candela) or `spheres:N` (an N×N grid of 1,200-triangle spheres).
    #[arg(long)]
    pub synthetic: Option<String>,
    /// Image size WxH.
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Use the glTF camera with this index.
    #[arg(long)]
    pub camera: Option<usize>,
    /// Camera position X,Y,Z (with --target).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub eye: Option<Vec3>,
    /// Point looked at X,Y,Z (with --eye).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub target: Option<Vec3>,
    /// Direction the sun's light travels X,Y,Z (e.g. -1,-1,0).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub sun_dir: Option<Vec3>,
    /// Intensity of the sun (the first directional light, or the default sun).
    #[arg(long)]
    pub sun_intensity: Option<f32>,
    /// Size of every light, for soft shadows (PCSS; 0: hard): a directional light's angular
    /// diameter in degrees (the sun: 0.53), a point or spot light's radius in scene units.
    /// Default: each light's own (glTF `extras.light_size`; 0 for the default sun).
    #[arg(long)]
    pub light_size: Option<f32>,
    /// Output: the lit image or a debug view.
    #[arg(long = "view", value_enum, default_value = "lit")]
    pub mode: ViewMode,
    /// Exposure of the lit image: `auto` (metered from the scene's lights, so a scene authored
    /// in lux and candela needs no flag), an EV100 value (scale 1 / (1.2 · 2^EV100); e.g. 15 for
    /// a sunlit scene in lux), or `xS` for a linear scale S (`x1`: the shading's raw values).
    #[arg(long, default_value = "auto", value_parser = parse_exposure, allow_hyphen_values = true)]
    pub exposure: Exposure,
    /// A flat ambient intensity Ia (the formula's ka·Ia term, the same from every direction):
    /// one value for grey or R,G,B, in the units of the scene's lights. Default: a sky and
    /// ground hemisphere sized by the direct illuminance auto exposure meters (sky 20 %,
    /// ground 6 %; docs/accuracy.md), so it follows the lights' units.
    #[arg(long, value_parser = parse_ambient)]
    pub ambient: Option<Vec3>,
    /// What the lit image shows where nothing is drawn: `sky` (the ambient hemisphere seen
    /// along each pixel, exposed like the scene) or a display colour (#RRGGBB, or R,G,B within
    /// 0..1).
    #[arg(long, default_value = "sky", value_parser = parse_background)]
    pub background: Background,
    /// Tone-mapping curve of the lit image: Khronos PBR Neutral, ACES (Hill's fit), or none
    /// (exposed values clamped).
    #[arg(long, value_enum, default_value = "neutral")]
    pub tonemap: Tonemap,
    /// Shadow-map size in texels.
    #[arg(long, default_value_t = 2048)]
    pub shadow_map: u32,
    /// Shadow-map depth format.
    /// `auto` (the default) takes D16 where its depth step is under a quarter of the constant
    /// bias (a directional light's maps, most scenes), else D32.
    #[arg(long, value_parser = ["auto", "d32", "d16"], default_value = "auto")]
    pub shadow_format: String,
    /// How shadows are decided: `map` (shadow maps, the default), `exact` (each pixel's shadow
    /// ray tested against the caster triangles on the device: exact hard shadows, no bias; one
    /// shadowed light, else maps) or `hybrid` (the map's verdict where its texels prove it, shadow
    /// rays elsewhere).
    #[arg(long, value_parser = ["map", "exact", "hybrid"], default_value = "map")]
    pub shadow_method: String,
    /// Contact shadows over the maps: each pixel's shadow ray marched 8 texels towards the shown
    /// light through the depth the camera sees (contact detail finer than a texel; hard shadows
    /// only).
    #[arg(long)]
    pub contact_shadows: bool,
    /// PCF kernel (2x2 by default: on the demo, wider kernels cost more and measured no better
    /// against the ray-cast reference).
    #[arg(long, value_enum, default_value = "2x2")]
    pub pcf: PcfArg,
    /// Constant bias in shadow texels (receiver moved towards the light).
    #[arg(long, default_value_t = ShadowSettings::default().constant_bias, allow_hyphen_values = true)]
    pub bias_constant: f32,
    /// Slope-scaled depth bias.
    #[arg(long, default_value_t = ShadowSettings::default().slope_bias, allow_hyphen_values = true)]
    pub bias_slope: f32,
    /// Normal-offset bias in shadow texels.
    #[arg(long, default_value_t = ShadowSettings::default().normal_offset, allow_hyphen_values = true)]
    pub normal_offset: f32,
    /// Fit the light frustum to the receivers the camera sees (`camera`), to the bounding sphere
    /// of the camera's frustum within the scene (`sphere`: a size that does not follow the
    /// camera's moves, so less shimmer in motion, coarser texels), or to the whole scene.
    #[arg(long, value_parser = ["camera", "sphere", "scene"], default_value = "camera")]
    pub fit: String,
    /// Do not snap the light frustum to whole texels.
    #[arg(long)]
    pub no_snap: bool,
    /// Steps per doubling of the snapped light frustum's size: fewer steps, less shimmer in
    /// motion, coarser texels (1: powers of two).
    #[arg(long, default_value_t = ShadowSettings::default().extent_steps, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub extent_steps: u32,
    /// Cascades of the sun's shadow map (1–4; with `--fit camera`): each covers a slice of the
    /// view depth with its own map, so near shadows keep their detail in large scenes. 0 (the
    /// default) chooses 1, 2 or 4 per frame from how much coarser than a pixel one map's texels
    /// would be at the nearest surface in view.
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=4))]
    pub cascades: u32,
    /// Fit the sun's cascades to the depths the camera sees (sample-distribution shadow maps:
    /// a first pass measures them; needs --fit camera), not to the scene's boxes in view.
    #[arg(long)]
    pub depth_fit: bool,
    /// Side in texels of a point light's cube faces (0, the default: half of --shadow-map).
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=16384))]
    pub cube_face: u32,
    /// Choose the shadow settings for this scene and view: the cheapest configuration whose
    /// predicted misclassification is within this budget, e.g. `0.1%` or `0.001` (prints the
    /// choice and its prediction; overrides --shadow-map, --pcf, --cascades, --fit).
    #[arg(long, value_parser = parse_budget)]
    pub shadow_budget: Option<f64>,
    /// Which light's shadow visibility `--view shadow` (and `cascades`, `texel-density`) shows,
    /// by index in the scene's lights; default: the first light with shadow views.
    #[arg(long)]
    pub shadow_light: Option<usize>,
    /// Disable shadows.
    #[arg(long)]
    pub no_shadows: bool,
    /// Anisotropic filtering (1 = off); default 8 on GPUs, off on CPU devices (lavapipe).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16))]
    pub anisotropy: Option<u32>,
    /// Add a ground plane under the model (to see its shadow).
    #[arg(long)]
    pub ground: bool,
    /// Multisample anti-aliasing, samples per pixel (1 = off); default 4 on GPUs, 1 on CPU
    /// devices (lavapipe). A count the device lacks falls to the largest below it, with a
    /// warning.
    #[arg(long, value_parser = parse_msaa)]
    pub msaa: Option<u32>,
    /// Post-process anti-aliasing of the lit image: `none` (the default) or `fxaa` (one
    /// full-screen pass over the finished image, after any MSAA resolve: smooth edges for a
    /// fraction of MSAA's cost on CPU devices; docs/speed.md).
    #[arg(long, value_parser = ["none", "fxaa"], default_value = "none")]
    pub post_aa: String,
    /// Supersampling of offscreen frames: `2` draws at twice the width and height and gives
    /// each pixel the mean of its 2×2 samples in linear light (four samples a pixel, shading
    /// included: on CPU devices cheaper than `--msaa 4`; docs/speed.md); 1 (the default) is off.
    /// The viewer ignores it, with a warning.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=2), default_value = "1")]
    pub ssaa: u32,
    /// Shade draws of triangles smaller than a 4×4 pixel block deferred (a G-buffer, then each
    /// covered pixel shaded once: the same image, less work where llvmpipe would shade whole
    /// blocks per tiny triangle); default on for CPU devices at one sample per pixel, off on GPUs.
    #[arg(long, value_name = "on|off", value_parser = parse_on_off)]
    pub deferred: Option<bool>,
    /// Draw small receivers (a ground) without the shadow lookup beyond the casters' reach (the
    /// same image, scissored; llvmpipe pays a lookup even where a branch skips it); default on
    /// for CPU devices, off on GPUs.
    #[arg(long, value_name = "on|off", value_parser = parse_on_off)]
    pub receiver_split: Option<bool>,
    /// Keep KTX2 textures block-compressed on the device (the file's mips transcoded to BC7)
    /// where it samples BC7; default on for GPUs, off on CPU devices (RGBA8, the file's mips).
    #[arg(long, value_name = "on|off", value_parser = parse_on_off)]
    pub block_compressed: Option<bool>,
    /// Pose the scene at this time in seconds of `--animation` (each channel clamped to its
    /// keyframes, as glTF says). Without it (and without --animation) the scene is drawn at
    /// rest: the file's node transforms, skins and default morph weights applied.
    #[arg(long, value_parser = parse_time, allow_hyphen_values = true)]
    pub time: Option<f32>,
    /// Reuse shadow-map layers whose light view and static casters did not change since the
    /// last frame, drawing only moving casters over a cached copy (the same image). Default:
    /// on in the viewer and for image sequences (--frames), off for one frame and `bench`.
    #[arg(long, value_name = "on|off", value_parser = parse_on_off)]
    pub shadow_cache: Option<bool>,
    /// Which animation plays: its index, its name, or `all` (every animation at once, a later
    /// one winning where two animate the same property). Default with --time: the first (0).
    #[arg(long)]
    pub animation: Option<String>,
}

/// The `Pcf` of a PCF argument.
pub fn pcf_of(p: PcfArg) -> Pcf {
    match p {
        PcfArg::None => Pcf::None,
        PcfArg::P2x2 => Pcf::P2x2,
        PcfArg::P3x3 => Pcf::P3x3,
        PcfArg::P5x5 => Pcf::P5x5,
    }
}
