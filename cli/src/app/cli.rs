//! Argument parsing (clap) and turning arguments into a scene and a view.

use super::parse::{
    parse_ambient, parse_background, parse_budget, parse_exposure, parse_fps, parse_msaa,
    parse_on_off, parse_size, parse_time, parse_vec3,
};
use anyhow::{anyhow, bail};
use clap::{Args, Parser, Subcommand, ValueEnum};
use glam::Vec3;
use std::path::PathBuf;
use umbra::render::{
    Background, Exposure, Pcf, ShadowFit, ShadowFormat, ShadowSettings, Tonemap, View, ViewMode,
};
use umbra::scene::anim::Playing;
use umbra::scene::{demo::demo_scene, load_gltf, Camera, Scene};

/// umbra: real-time shadow-mapping renderer (Vulkan).
#[derive(Parser, Debug)]
#[command(name = "umbra", version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render a scene (the built-in demo without SCENE) to a PNG.
    Render(RenderArgs),
    /// Render on the GPU and by CPU ray casting, print shadow and image error as one JSON line,
    /// and write gpu.png, reference.png and diff.png (false shadow red, false light blue).
    #[cfg(feature = "reference")]
    Compare(CompareArgs),
    /// Open a window and render continuously (the demo scene without SCENE).
    #[cfg(feature = "viewer")]
    View(ViewArgsCmd),
    /// Time frames offscreen over shadow-map sizes and PCF kernels (medians of N frames) and
    /// print a Markdown table.
    Bench(BenchArgs),
    /// What is in a glTF file and how umbra sees and shadows it: asset, extensions, meshes,
    /// materials (as Blinn-Phong), textures, totals, scale, the default view's shadow plan and
    /// findings with codes and JSON pointers. Tables by default; --json (schema umbra-inspect/1)
    /// or --md.
    Inspect(InspectArgs),
    /// Speed against accuracy: render every shadow configuration of a grid on a few views of
    /// each scene, time it and score it against the ray-cast reference; write sweep.csv,
    /// sweep.json and the Pareto charts (pareto.svg/.png over all scenes, pareto-SCENE.svg/.png).
    /// Resumes from DIR/sweep.csv when interrupted.
    #[cfg(feature = "sweep")]
    Sweep(SweepArgs),
    /// Stability where shadow methods fail: sun elevation 0.5°–90° (acne, leaks, the bias
    /// trade-off), shimmer along a flythrough per shadow method, the scene far from the origin and
    /// scaled, degenerate views and input; each against the exact reference. Writes
    /// DIR/stability.json, charts (SVG + PNG) and DIR/stability.md with the thresholds judged.
    #[cfg(feature = "sweep")]
    Stability(StabilityArgs),
}

/// `umbra stability`.
#[cfg(feature = "sweep")]
#[derive(Args, Debug)]
pub struct StabilityArgs {
    /// A glTF file, `demo`, or a generated scene (`town`, `grazing`, `stability`, …); the demo
    /// when none.
    #[arg(conflicts_with = "builtin")]
    pub scene: Option<String>,
    /// The built-in stress scene (a thin wall for the contact gap, a box, spheres and a torus).
    #[arg(long)]
    pub builtin: bool,
    /// Output folder.
    #[arg(long, default_value = "stability")]
    pub out: PathBuf,
    /// Fewer angles, frames and cases (a first look; what the tests run).
    #[arg(long)]
    pub quick: bool,
    /// Image size WxH of every probe.
    #[arg(long, default_value = "640x360", value_parser = parse_size)]
    pub size: (u32, u32),
    /// The animation the motion probe's moving caster plays (index or name; default: the
    /// scene's first; a scene without animations gets a box that crosses it).
    #[arg(long)]
    pub animation: Option<String>,
    /// Add a ground plane under glTF models (as `render --ground`).
    #[arg(long)]
    pub ground: bool,
    /// Exit 1 when a threshold fails (the summary says which either way).
    #[arg(long)]
    pub strict: bool,
    /// Vulkan device to use (substring of its name); also UMBRA_DEVICE.
    #[arg(long)]
    pub device: Option<String>,
    /// Enable the Khronos validation layer: messages are counted per degenerate case, and the
    /// command exits 1 on any.
    #[arg(long)]
    pub validation: bool,
}

/// `umbra sweep`.
#[cfg(feature = "sweep")]
#[derive(Args, Debug)]
pub struct SweepArgs {
    /// Scenes: glTF files, `demo`, or generated scenes (`town`, `grazing`, `double-sided`,
    /// `spheres:N`); the demo when none.
    pub scenes: Vec<String>,
    /// Output folder.
    #[arg(long, default_value = "sweep")]
    pub out: PathBuf,
    /// The coarse grid (48 configurations instead of 576).
    #[arg(long)]
    pub quick: bool,
    /// The map formats swept, comma-separated (`d16`, `d32`, `auto`); default: the grid's own
    /// (D16 and D32, or D32 alone with --quick).
    #[arg(long, value_delimiter = ',', value_parser = ["d16", "d32", "auto"])]
    pub formats: Vec<String>,
    /// Also 4 cascades fitted to the depths each view sees (method `sdsm4`).
    #[arg(long)]
    pub depth_fit: bool,
    /// Also exact shadows (`--shadow-method exact`: method and filter `exact`), one
    /// configuration.
    #[arg(long)]
    pub exact: bool,
    /// Also contact shadows over the default maps (`--contact-shadows`: filter `contact`), one
    /// configuration.
    #[arg(long)]
    pub contact: bool,
    /// Give every light this size (as for render: degrees of a directional light, radius of
    /// a point or spot light) and add PCSS (filter `pcss`); the reference is the area light,
    /// the other filters cast hard shadows from it.
    #[arg(long)]
    pub light_size: Option<f32>,
    /// Frames timed per configuration (after one warm-up frame).
    #[arg(long, default_value_t = 5)]
    pub repeat: usize,
    /// Image size WxH.
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Add a ground plane under glTF models (as `render --ground`).
    #[arg(long)]
    pub ground: bool,
    /// After sweeping, write budget-features.csv: each row with the error-budget model's
    /// prediction terms (training data for `analysis::budget`).
    #[arg(long)]
    pub features: bool,
    /// With --features: fit the error-budget model to the rows and write budget-model.rs (the
    /// source of `analysis::model`).
    #[arg(long, requires = "features")]
    pub fit_budget: bool,
    /// After sweeping, run the budget mode (`--shadow-budget`) on every swept view for each of
    /// these budgets (e.g. 0.1%,0.05%) and write budget-check.csv: the chosen configuration, its
    /// full-image misclassification, and its GPU time against the cheapest swept configuration
    /// within the budget.
    #[arg(long, value_delimiter = ',', value_parser = parse_budget)]
    pub check_budget: Vec<f64>,
    /// Views per scene (its cameras, else default, high and ground), at most this many.
    #[arg(long, default_value_t = 4)]
    pub views: usize,
    /// Vulkan device to use (substring of its name); also UMBRA_DEVICE.
    #[arg(long)]
    pub device: Option<String>,
    /// Enable the Khronos validation layer; exit 1 on any warning or error (also
    /// UMBRA_VALIDATION=1). Timings then include the layer's overhead.
    #[arg(long)]
    pub validation: bool,
}

#[cfg(feature = "sweep")]
/// Loads a scene named on the command line: an existing file, `demo`, or a generated scene's
/// name (`scene::synthetic::by_name`). Prints its warnings; adds a ground plane to files when
/// `ground`.
pub fn load_named(spec: &str, ground: bool) -> anyhow::Result<Scene> {
    let path = std::path::Path::new(spec);
    let mut s = if path.exists() {
        load_gltf(path)?
    } else if spec == "demo" {
        demo_scene()
    } else if let Some(s) = umbra::scene::synthetic::by_name(spec) {
        s
    } else {
        bail!("{spec}: no such file, and not demo, town, town-mover, grazing, stability, double-sided, room, sun-and-spot, two-suns, lux-yard or spheres:N");
    };
    for w in &s.warnings {
        print_warning(&s.name, w);
    }
    if ground && path.exists() {
        umbra::scene::shapes::add_ground(&mut s);
    }
    Ok(s)
}

/// `umbra inspect`.
#[derive(Args, Debug)]
pub struct InspectArgs {
    /// glTF 2.0 file (.gltf or .glb).
    pub scene: PathBuf,
    /// The report as JSON (schema `umbra-inspect/1`, docs/inspect-schema.json).
    #[arg(long, conflicts_with = "md")]
    pub json: bool,
    /// The report as Markdown tables.
    #[arg(long)]
    pub md: bool,
    /// The view the shadow plan is for (as for render).
    #[command(flatten)]
    pub view: ViewArgs,
}

/// `umbra bench`.
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// glTF 2.0 file; the built-in demo scene when omitted.
    pub scene: Option<PathBuf>,
    /// View and shadow options (as for render).
    #[command(flatten)]
    pub view: ViewArgs,
    /// Shadow-map sizes to sweep (0 = shadows off).
    #[arg(long, value_delimiter = ',', default_value = "0,1024,2048,4096")]
    pub maps: Vec<u32>,
    /// PCF kernels to sweep.
    #[arg(long, value_delimiter = ',', value_enum, default_value = "2x2")]
    pub kernels: Vec<PcfArg>,
    /// Frames timed per configuration (after one warm-up frame).
    #[arg(long, default_value_t = 9)]
    pub repeat: usize,
    /// Vulkan device to use (substring of its name); also UMBRA_DEVICE.
    #[arg(long)]
    pub device: Option<String>,
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

/// `umbra view`.
#[cfg(feature = "viewer")]
#[derive(Args, Debug)]
pub struct ViewArgsCmd {
    /// glTF 2.0 file; the built-in demo scene when omitted.
    pub scene: Option<PathBuf>,
    /// View and shadow options (as for render; --size is the window's inner size).
    #[command(flatten)]
    pub view: ViewArgs,
    /// Present without vsync (for measuring).
    #[arg(long)]
    pub no_vsync: bool,
    /// Render this many frames, then exit.
    #[arg(long)]
    pub frames: Option<u64>,
    /// With --frames: save the last frame here (the scene without the panel).
    #[arg(long, requires = "frames")]
    pub screenshot: Option<PathBuf>,
    /// Screenshots (`P`, --screenshot) hold the panel too.
    #[arg(long)]
    pub screenshot_ui: bool,
    /// Start with the panel hidden (F1 shows it).
    #[arg(long)]
    pub no_panel: bool,
    /// Vulkan device to use (substring of its name); also UMBRA_DEVICE.
    #[arg(long)]
    pub device: Option<String>,
    /// Enable the Khronos validation layer; exit 1 on any warning or error.
    #[arg(long)]
    pub validation: bool,
    /// Automation: inputs to play, one every two frames, comma-separated, each optionally
    /// repeated with `*N`: `WxH` resizes (0x0 minimises), `key:NAME` presses a key (up down left
    /// right [ ] k + - v h n g j l t comma period f tab c o p space u i z x r y m b f1), `wheel:N`
    /// scrolls N lines (positive zooms in), `click:X:Y` picks at window pixel (X, Y), `ui:NAME`
    /// clicks the panel's widget NAME, `drop:PATH` drops a file on the window,
    /// `copy:SRC>DST` copies a file (a model changed on disk) and `wait:reload` waits for the
    /// reload; e.g. `key:down*40,wheel:1*80,640x360,click:9:9,ui:pcf.3x3`. With --frames, the
    /// run ends after the last step.
    #[arg(long, alias = "resize-script", value_delimiter = ',', value_parser = super::script::parse_item)]
    pub script: Vec<(super::script::ScriptStep, u32)>,
}

/// `umbra compare`.
#[cfg(feature = "reference")]
#[derive(Args, Debug)]
pub struct CompareArgs {
    /// glTF 2.0 file; the built-in demo scene when omitted.
    pub scene: Option<PathBuf>,
    /// Folder for gpu.png, reference.png, diff.png, shadow.png (the GPU shadow view) and
    /// coverage.png (the reference's visible fraction of the shown light).
    #[arg(long, default_value = ".")]
    pub out: PathBuf,
    /// View and shadow options (as for render).
    #[command(flatten)]
    pub view: ViewArgs,
    /// Vulkan device to use (substring of its name); also UMBRA_DEVICE.
    #[arg(long)]
    pub device: Option<String>,
}

/// `umbra render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    /// glTF 2.0 file (.gltf or .glb); the built-in demo scene when omitted.
    pub scene: Option<PathBuf>,
    /// Output PNG.
    #[arg(short, long, default_value = "umbra.png")]
    pub output: PathBuf,
    /// View and shadow options.
    #[command(flatten)]
    pub view: ViewArgs,
    /// Vulkan device to use (substring of its name); also UMBRA_DEVICE.
    #[arg(long)]
    pub device: Option<String>,
    /// Enable the Khronos validation layer (also UMBRA_VALIDATION=1).
    #[arg(long)]
    pub validation: bool,
    /// Render this many frames and report median times (the image is the last frame).
    #[arg(long, default_value_t = 1)]
    pub repeat: usize,
    /// An image sequence: N frames of the animation from --time (default 0) at --fps, each
    /// written to OUT with its frame number put in the `%04d` (or `%d`) the name must hold.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub frames: Option<u32>,
    /// Frames per second of a sequence (--frames).
    #[arg(long, default_value_t = 30.0, value_parser = parse_fps)]
    pub fps: f32,
}

/// The file name of frame `i` of a sequence: `pattern` with its `%0Nd` or `%d` replaced by `i`
/// (zero-padded to N digits); an error names the pattern wanted when there is none.
pub fn frame_path(pattern: &std::path::Path, i: u32) -> anyhow::Result<PathBuf> {
    let text = pattern.to_string_lossy();
    let Some(start) = text.find('%') else {
        bail!("-o {text}: a sequence (--frames) needs a frame-number pattern such as out_%04d.png");
    };
    let rest = &text[start + 1..];
    let digits: String = rest.chars().take_while(|c| c.is_ascii_digit()).collect();
    if !rest[digits.len()..].starts_with('d') {
        bail!("-o {text}: expected %d or %0Nd (such as %04d) after '%'");
    }
    let width: usize = digits.parse().unwrap_or(0).min(12);
    let end = start + 1 + digits.len() + 1;
    Ok(PathBuf::from(format!(
        "{}{i:0width$}{}",
        &text[..start],
        &text[end..]
    )))
}

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
    /// How shadows are decided: `map` (shadow maps, the default) or `exact` (each pixel's shadow
    /// ray tested against the caster triangles on the device: exact hard shadows, no bias; one
    /// shadowed light, else maps).
    #[arg(long, value_parser = ["map", "exact"], default_value = "map")]
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

/// What `--animation` and `--time` ask of `scene`: the animations and the time, or None for the
/// rest pose. A scene without animations at `--time` gets a warning and its rest pose.
pub fn playing(scene: &Scene, a: &ViewArgs) -> anyhow::Result<Option<(Playing, f32)>> {
    if a.time.is_none() && a.animation.is_none() {
        return Ok(None);
    }
    let rig = scene.rig.as_deref();
    let Some(spec) = a.animation.as_deref() else {
        if rig.is_none_or(|r| r.animations.is_empty()) {
            return Ok(None);
        }
        return Ok(Some((Playing::One(0), a.time.unwrap_or(0.0))));
    };
    let p = Playing::parse(spec, rig).map_err(|e| anyhow!(e))?;
    Ok(Some((p, a.time.unwrap_or(0.0))))
}

/// With `--shadow-budget`: chooses this view's shadow settings (`analysis::budget::choose`), sets
/// them on `view`, and prints the choice on one line.
#[cfg(feature = "sweep")]
pub fn apply_budget(
    scene: &Scene,
    view: &mut View,
    a: &ViewArgs,
    renderer: &mut umbra::Renderer,
) -> anyhow::Result<()> {
    use umbra_lab::analysis::{budget, chart::short_label_of};
    let Some(b) = a.shadow_budget else {
        return Ok(());
    };
    let reference = umbra_lab::reference::ReferenceScene::new(scene);
    let Some(c) = budget::choose(renderer, &reference, scene, view, a.size, b, None)? else {
        eprintln!("warning: --shadow-budget: no light casts a shadow; settings unchanged");
        return Ok(());
    };
    view.shadow = c.chosen.config.shadow;
    println!("{}", budget_line(&c, &short_label_of(&c.chosen.config)));
    Ok(())
}

/// The one-line report of a budget choice.
#[cfg(feature = "sweep")]
pub fn budget_line(c: &umbra_lab::analysis::budget::BudgetChoice, label: &str) -> String {
    let measured = c
        .measured
        .map(|m| format!(", measured {:.4} % at {} probes", m * 100.0, c.probes))
        .unwrap_or_default();
    let met = if c.met {
        ""
    } else {
        " — budget not reachable: the most accurate candidate tried"
    };
    format!(
        "shadow budget {:.3} %: {label} (predicted {:.4} %{measured}; {:.2}x the default's GPU time; {} render(s), {:.0} ms){met}",
        c.budget * 100.0,
        c.chosen.predicted * 100.0,
        c.chosen.relative_cost,
        c.verified.len(),
        c.ms
    )
}

#[cfg(not(feature = "sweep"))]
pub fn apply_budget(
    _: &Scene,
    _: &mut View,
    a: &ViewArgs,
    _: &mut umbra::Renderer,
) -> anyhow::Result<()> {
    if a.shadow_budget.is_some() {
        bail!("--shadow-budget needs umbra built with the `sweep` feature");
    }
    Ok(())
}

/// Prints one loader warning as `warning: NAME: MESSAGE [CODE POINTER]`: the finding code and
/// JSON pointer that `umbra inspect` reports for it.
pub fn print_warning(scene: &str, w: &umbra::scene::Warning) {
    let at = if w.pointer.is_empty() {
        String::new()
    } else {
        format!(" {}", w.pointer)
    };
    eprintln!("warning: {scene}: {} [{}{at}]", w.message, w.code);
}

/// Warns when `view` asked for exact shadows and the frame planned as `plan` could not have
/// them (it has several shadowed lights, or the device no fragment-shader stores).
pub fn warn_exact(view: &View, plan: &umbra::FramePlan) {
    if view.shadow.method == umbra::ShadowMethod::Exact && plan.shadows_on && !plan.exact_shadows()
    {
        eprintln!(
            "warning: --shadow-method exact: {} shadow view(s) (exact shadows need one shadowed \
             light, and a device with fragment-shader stores); shadow maps used",
            plan.shadow_views.len()
        );
    }
}

/// Loads SCENE or builds the demo, prints its warnings (`warning: NAME: …` on stderr, one per
/// line), and adds a ground plane when asked.
pub fn load_scene(path: Option<&PathBuf>, a: &ViewArgs) -> anyhow::Result<Scene> {
    let mut s = match (path, a.synthetic.as_deref()) {
        (Some(_), Some(_)) => bail!("give either SCENE or --synthetic, not both"),
        (Some(p), None) => load_gltf(p)?,
        (None, None) => demo_scene(),
        (None, Some(name)) => umbra::scene::synthetic::by_name(name).ok_or_else(|| {
            anyhow!(
                "--synthetic {name}: expected {} or spheres:N with N in 1..=256",
                umbra::scene::synthetic::NAMES.join(", ")
            )
        })?,
    };
    let ground = a.ground;
    for w in &s.warnings {
        print_warning(&s.name, w);
    }
    match playing(&s, a)? {
        Some((p, t)) => s.pose_at(&p, t),
        None if a.time.is_some() => {
            eprintln!(
                "warning: {}: --time: the scene has no animations; drawn at rest",
                s.name
            );
        }
        None => {}
    }
    if ground {
        umbra::scene::shapes::add_ground(&mut s);
    }
    Ok(s)
}

/// Upload options from arguments.
pub fn scene_options(a: &ViewArgs) -> umbra::render::SceneOptions {
    umbra::render::SceneOptions {
        anisotropy: a.anisotropy,
        culling: !a.no_culling,
        msaa: a.msaa,
        cpu_mips: None,
        deferred: a.deferred,
        receiver_split: a.receiver_split,
        shadow_cache: a.shadow_cache.unwrap_or(false),
    }
}

/// Upload options for runs of many frames (the viewer, image sequences): the shadow cache on
/// unless `--shadow-cache off`.
pub fn animated_scene_options(a: &ViewArgs) -> umbra::render::SceneOptions {
    umbra::render::SceneOptions {
        shadow_cache: a.shadow_cache.unwrap_or(true),
        ..scene_options(a)
    }
}

/// The documented fallback of `--msaa N` on a device without N samples: a warning line naming
/// the count used.
pub fn warn_msaa(a: &ViewArgs, samples: u32) {
    if let Some(n) = a.msaa.filter(|&n| n != samples) {
        eprintln!("warning: --msaa {n}: the device has no {n}-sample attachments; using {samples}");
    }
}

/// Builds the view from arguments.
pub fn make_view(scene: &Scene, a: &ViewArgs) -> anyhow::Result<View> {
    let aspect = a.size.0 as f32 / a.size.1 as f32;
    let camera: Camera = match (a.eye, a.target, a.camera) {
        (Some(eye), Some(target), _) => {
            if (target - eye).length_squared() == 0.0 {
                bail!("--eye and --target must differ");
            }
            let b = scene.bounds();
            let near = if b.is_empty() {
                0.01
            } else {
                (b.diagonal() * 1e-4).max(1e-4)
            };
            Camera::look_at(eye, target, 45f32.to_radians(), near)
        }
        (Some(_), None, _) | (None, Some(_), _) => bail!("--eye and --target go together"),
        (None, None, Some(i)) => *scene.cameras.get(i).ok_or_else(|| {
            anyhow!(
                "--camera {i}: the scene has {} camera(s)",
                scene.cameras.len()
            )
        })?,
        (None, None, None) => scene
            .cameras
            .first()
            .copied()
            .unwrap_or_else(|| scene.default_camera(aspect)),
    };
    let mut v = View::new(camera);
    v.sun_direction = match a.sun_dir {
        Some(d) if d.length_squared() == 0.0 => bail!("--sun-dir must not be zero"),
        d => d,
    };
    v.sun_intensity = match a.sun_intensity {
        Some(i) if !(i.is_finite() && i >= 0.0) => {
            bail!("--sun-intensity must be a finite number >= 0")
        }
        i => i,
    };
    v.light_size = match a.light_size {
        Some(x) if !(x.is_finite() && (0.0..=1e6).contains(&x)) => {
            bail!("--light-size must be a number within 0..1e6")
        }
        x => x,
    };
    v.mode = a.mode;
    v.exposure = a.exposure;
    v.ambient = a.ambient;
    v.background = a.background;
    v.tonemap = a.tonemap;
    v.post_aa = a.post_aa.parse().unwrap_or_default();
    v.supersample = a.ssaa;
    if let Some(i) = a.shadow_light {
        let n = umbra::render::effective_lights(&scene.lights, &v).len();
        if i >= n {
            bail!("--shadow-light {i}: the scene has {n} light(s) (0..{n})");
        }
    }
    v.shown_light = a.shadow_light;
    let sizes = ShadowSettings::MAP_SIZES;
    if !sizes.contains(&a.shadow_map) {
        bail!(
            "--shadow-map {} must be within {}..{}",
            a.shadow_map,
            sizes.start(),
            sizes.end()
        );
    }
    v.shadow = ShadowSettings {
        enabled: !a.no_shadows,
        method: a.shadow_method.parse().unwrap_or_default(),
        contact: a.contact_shadows,
        map_size: a.shadow_map,
        format: a.shadow_format.parse().unwrap_or(ShadowFormat::Auto),
        pcf: pcf_of(a.pcf),
        constant_bias: a.bias_constant,
        slope_bias: a.bias_slope,
        normal_offset: a.normal_offset,
        fit: match a.fit.as_str() {
            "scene" => ShadowFit::Scene,
            "sphere" => ShadowFit::Sphere,
            _ => ShadowFit::Camera,
        },
        snap: !a.no_snap,
        extent_steps: a.extent_steps,
        cascades: a.cascades,
        cube_face: a.cube_face,
        depth_fit: a.depth_fit,
        soft: true,
    };
    Ok(v)
}
