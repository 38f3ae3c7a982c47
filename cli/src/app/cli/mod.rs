//! Argument parsing (clap): the subcommands and their arguments here, the view options every
//! subcommand shares in `view_args`, turning arguments into a scene and a view in `setup`.

mod setup;
mod view_args;

pub use setup::*;
pub use view_args::*;

use super::parse::parse_fps;
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;

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
    /// One self-contained HTML page (no server, no network) of what lies under DIR: failed
    /// goldens (golden, actual and FLIP diff side by side, a slider, a blink, zoom, the figures),
    /// compare folders, sweep Pareto charts (each point's settings and images) and stability
    /// verdicts and charts. Writes DIR/report.html.
    Report(ReportArgs),
}

/// `umbra report`.
#[derive(Args, Debug)]
pub struct ReportArgs {
    /// The folder to report on (searched below; build trees and hidden folders skipped).
    pub dir: PathBuf,
    /// The page to write (default DIR/report.html).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
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
    #[arg(long, default_value = "640x360", value_parser = super::parse::parse_size)]
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
    /// Also write OUT/report.html (as `umbra report OUT`).
    #[arg(long)]
    pub report: bool,
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
    /// Also exact and hybrid shadows (`--shadow-method exact` and `hybrid`: method and filter
    /// `exact` and `hybrid`), a configuration each.
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
    #[arg(long, default_value = "1280x720", value_parser = super::parse::parse_size)]
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
    #[arg(long, value_delimiter = ',', value_parser = super::parse::parse_budget)]
    pub check_budget: Vec<f64>,
    /// Views per scene (its cameras, else default, high and ground), at most this many.
    #[arg(long, default_value_t = 4)]
    pub views: usize,
    /// Save each run's lit image as OUT/images/SCENE/VIEW/CONFIG.png (at most 320 pixels wide),
    /// which the report shows beside its point.
    #[arg(long)]
    pub images: bool,
    /// Also write OUT/report.html (as `umbra report OUT`); implies --images.
    #[arg(long)]
    pub report: bool,
    /// Vulkan device to use (substring of its name); also UMBRA_DEVICE.
    #[arg(long)]
    pub device: Option<String>,
    /// Enable the Khronos validation layer; exit 1 on any warning or error (also
    /// UMBRA_VALIDATION=1). Timings then include the layer's overhead.
    #[arg(long)]
    pub validation: bool,
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
    /// Folder for gpu.png, reference.png, diff.png, shadow.png (the GPU shadow view),
    /// coverage.png (the reference's visible fraction of the shown light) and compare.json (the
    /// line printed).
    #[arg(long, default_value = ".")]
    pub out: PathBuf,
    /// Also write OUT/report.html (as `umbra report OUT`).
    #[arg(long)]
    pub report: bool,
    /// View and shadow options (as for render).
    #[command(flatten)]
    pub view: ViewArgs,
    /// Vulkan device to use (substring of its name); also UMBRA_DEVICE.
    #[arg(long)]
    pub device: Option<String>,
    /// Enable the Khronos validation layer; exit 1 on any warning or error.
    #[arg(long)]
    pub validation: bool,
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
    /// A batch: one image per camera pose in this JSON file (a list of 4×4 world-from-camera
    /// matrices, row by row, or of {"eye": [x, y, z], "target": [x, y, z]}), each written to
    /// OUT with its index put in the `%04d`. Each directional light's map is fitted to all
    /// the views and drawn once (see --per-view-shadows).
    #[arg(long, conflicts_with_all = ["frames", "repeat"])]
    pub views: Option<PathBuf>,
    /// With --views: fit each view's shadow maps to it alone, as a single render does.
    #[arg(long, requires = "views")]
    pub per_view_shadows: bool,
    /// With --views: what to write per view, comma-separated: color (the PNG), depth,
    /// segmentation, normals (.npy beside it: OUT_0001.depth.npy, ...).
    #[arg(long, value_delimiter = ',', requires = "views", default_value = "color",
          value_parser = ["color", "depth", "segmentation", "normals"])]
    pub outputs: Vec<String>,
}
