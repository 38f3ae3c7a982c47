//! The whole suite: run every probe, judge the results against the thresholds, and write
//! `stability.json`, the charts and `stability.md`.
//!
//! `verdicts` judges, `charts` draws and `markdown` writes the summary; this module runs the
//! probes and writes the files.

mod charts;
mod markdown;
mod verdicts;

pub use charts::charts;
pub use markdown::markdown;
pub use verdicts::verdicts;

use charts::{bias_rows, worst_by_elevation};
use verdicts::at_defaults;

use crate::analysis::chart::ChartError;
use crate::analysis::lines::write_lines;
use crate::analysis::stability::degenerate::{degenerate, DegenerateRow};
use crate::analysis::stability::light::{contact_gaps, light_angles, AngleRow, ContactRow};
use crate::analysis::stability::motion::{motion, MotionSeries};
use crate::analysis::stability::precision::{precision, PrecisionRow};
use crate::analysis::stability::shimmer::{camera_path, methods, shimmer, ShimmerSeries};
use crate::analysis::stability::{StabilityOptions, SCHEMA};
use crate::reference::ReferenceScene;
use glam::Vec3;
use serde::Serialize;
use std::path::Path;
use std::sync::Arc;
use umbra::gpu::{Context, GpuError};
use umbra::plan::ScenePlanner;
use umbra::plan::{SceneOptions, View};
use umbra::render::Renderer;
use umbra::scene::Scene;

/// Flipped points per frame allowed with snapping.
pub const SHIMMER_BOUND: f64 = 1e-4;

/// Still points flipped per frame allowed under a moving caster, cascades held (measured,
/// quick runs: demo 2.5·10⁻⁵, built-in scene 9.7·10⁻⁵, Fox walking 2.6·10⁻⁴, surveying 1.7·10⁻⁴).
pub const MOVING_CASTER_BOUND: f64 = 3e-4;

/// Still points flipped per frame allowed under a sun moving 0.5° a frame (measured, quick
/// runs: demo 8.0·10⁻⁴, Fox 1.0·10⁻³, built-in scene 1.2·10⁻³). A turning light turns the
/// map's texel grid, so every shadow edge is rasterised anew each frame: points within a texel
/// of an edge flip whatever the snapping; the bound is that edge band's share.
pub const SUN_ARC_BOUND: f64 = 2e-3;

/// Still points away from shadow edges flipped per frame allowed with exact shadows, on either
/// probe (measured, quick runs: built-in scene 0 under the moving box and 4.3·10⁻⁷ on the sun's
/// arc, 2 points of 4.7 million where the sun grazes the torus; Fox 0 and 0).
pub const EXACT_MOTION_BOUND: f64 = 1e-6;

/// Contact gap allowed at the thin wall's base (texels), for elevations ≥ 5°.
pub const CONTACT_BOUND_TEXELS: f64 = 2.0;

/// Misclassification at 10⁶ units from the origin, relative to the origin case.
pub const FAR_RATIO_BOUND: f64 = 2.0;

/// One threshold, judged.
#[derive(Clone, Debug, Serialize)]
pub struct Verdict {
    /// What is required.
    pub criterion: String,
    /// What was measured.
    pub measured: String,
    /// Met (None: not applicable to this scene).
    pub pass: Option<bool>,
}

/// Everything the suite measured (`stability.json`).
#[derive(Clone, Debug, Serialize)]
pub struct StabilityReport {
    /// [`SCHEMA`].
    pub schema: String,
    /// Scene name.
    pub scene: String,
    /// Frame size.
    pub size: (u32, u32),
    /// Device name.
    pub device: String,
    /// Quick mode.
    pub quick: bool,
    /// Default shadow settings used ("map 2048 d32 pcf2x2 bias 1/1.5/1.5 camera snap auto").
    pub defaults: String,
    /// Seconds per probe and in all.
    pub seconds: Vec<(String, f64)>,
    /// Light angle and bias rows.
    pub light_angle: Vec<AngleRow>,
    /// Contact gaps (built-in scene only).
    pub contact: Vec<ContactRow>,
    /// Frames along the path.
    pub path_frames: usize,
    /// Shimmer per method.
    pub shimmer: Vec<ShimmerSeries>,
    /// Frames of each motion probe.
    pub motion_frames: usize,
    /// Flicker in motion, per probe and method.
    pub motion: Vec<MotionSeries>,
    /// Precision cases.
    pub precision: Vec<PrecisionRow>,
    /// Degenerate cases.
    pub degenerate: Vec<DegenerateRow>,
    /// The thresholds, judged.
    pub verdicts: Vec<Verdict>,
}

/// Steps `run` reports through `progress` (for a progress bar).
pub fn planned_steps(quick: bool, contact: bool) -> u64 {
    let (be, bs) = super::light::bias_sweep(quick);
    let el = super::light::elevations(quick);
    let az = super::light::azimuths(0.0, quick).len();
    let extra: usize = be
        .iter()
        .map(|e| {
            if el.contains(e) {
                bs.len() - 1
            } else {
                bs.len()
            }
        })
        .sum();
    let light = el.len() * az + extra;
    let contact = if contact {
        contact_elevations(quick).len()
    } else {
        0
    };
    let shimmer = methods(&Default::default()).len() * (path_frames(quick) - 1) * 2;
    let precision = super::precision::offsets(quick).len() + super::precision::scales(quick).len();
    let degenerate = if quick { 9 } else { 10 };
    let moving = 2 * super::motion::METHODS.len() * super::motion::frames(quick);
    (light + contact + shimmer + moving + precision + degenerate) as u64
}

/// Frames of the flythrough: 4 s at 60 frames per second, so the motion per frame is what a
/// viewer shows (`quick`: its first second).
pub fn path_frames(quick: bool) -> usize {
    if quick {
        60
    } else {
        240
    }
}

/// Elevations of the contact-gap probe.
pub fn contact_elevations(quick: bool) -> Vec<f32> {
    if quick {
        vec![5.0, 15.0, 45.0, 80.0]
    } else {
        vec![1.0, 2.0, 5.0, 10.0, 20.0, 45.0, 80.0]
    }
}

fn describe(s: &umbra::plan::ShadowSettings) -> String {
    format!(
        "map {} {:?} {:?}, bias constant {} slope {} normal {}, fit {:?}, snap {}, cascades {}",
        s.map_size,
        s.format,
        s.pcf,
        s.constant_bias,
        s.slope_bias,
        s.normal_offset,
        s.fit,
        s.snap,
        if s.cascades == 0 {
            "auto".to_string()
        } else {
            s.cascades.to_string()
        }
    )
    .to_lowercase()
}

/// Runs every probe on `scene` seen through `view` (whose shadow settings are the defaults under
/// test). `wall`: the half extents of a thin wall standing at the origin (the built-in scene),
/// for the contact gap. `progress(phase)` is called once per step of [`planned_steps`].
pub fn run(
    ctx: &Arc<Context>,
    scene: &Scene,
    view: &View,
    scene_options: &SceneOptions,
    opts: &StabilityOptions,
    wall: Option<Vec3>,
    progress: &mut dyn FnMut(&str),
) -> Result<StabilityReport, GpuError> {
    let size = opts.size;
    let quick = opts.quick;
    let t_all = std::time::Instant::now();
    let mut seconds = Vec::new();
    let probes = Probes {
        ctx,
        scene,
        view,
        scene_options,
        opts,
        wall,
    };
    let (light_angle, contact, frames, shimmer) = renderer_probes(&probes, &mut seconds, progress)?;
    let mut timed = |name: &str, t: std::time::Instant| {
        seconds.push((name.to_string(), t.elapsed().as_secs_f64()))
    };

    let t = std::time::Instant::now();
    let motion = motion(ctx, scene, view, scene_options, opts, &mut || {
        progress("motion")
    })?;
    timed("motion", t);

    let t = std::time::Instant::now();
    let precision = precision(ctx, scene, view, scene_options, size, quick, &mut || {
        progress("precision")
    })?;
    timed("precision", t);

    let t = std::time::Instant::now();
    let degenerate = degenerate(ctx, scene, view, scene_options, size, quick, &mut || {
        progress("degenerate")
    })?;
    timed("degenerate", t);
    seconds.push(("total".into(), t_all.elapsed().as_secs_f64()));

    let mut r = StabilityReport {
        schema: SCHEMA.into(),
        scene: scene.name.clone(),
        size,
        device: ctx.device_name.clone(),
        quick,
        defaults: describe(&view.shadow),
        seconds,
        light_angle,
        contact,
        path_frames: frames,
        shimmer,
        motion_frames: super::motion::frames(quick),
        motion,
        precision,
        degenerate,
        verdicts: Vec::new(),
    };
    r.verdicts = verdicts(&r);
    Ok(r)
}

/// The azimuth in degrees of the scene's first directional light (0 without one, or with the
/// built-in wall, whose probes are laid out from 0).
fn first_azimuth(scene: &Scene, view: &View, wall: Option<Vec3>) -> f32 {
    let lights = umbra::plan::effective_lights(&scene.lights, view);
    let first_azimuth = lights
        .iter()
        .find(|l| l.kind == umbra::scene::LightKind::Directional)
        .map_or(0.0, |l| {
            let to_sun = -l.direction.normalize_or(Vec3::NEG_Y);
            to_sun.x.atan2(to_sun.z).to_degrees()
        });
    if wall.is_some() {
        0.0
    } else {
        first_azimuth
    }
}

/// What every probe of [`run`] is given.
struct Probes<'a> {
    ctx: &'a Arc<Context>,
    scene: &'a Scene,
    view: &'a View,
    scene_options: &'a SceneOptions,
    opts: &'a StabilityOptions,
    wall: Option<Vec3>,
}

/// The light angle, contact and shimmer probes' results, and the camera path's frame count.
type RendererProbes = (Vec<AngleRow>, Vec<ContactRow>, usize, Vec<ShimmerSeries>);

/// The probes that share one renderer: light angle, contact gaps and shimmer along the camera
/// path (with the path's frame count), each one's seconds pushed to `seconds`.
fn renderer_probes(
    p: &Probes,
    seconds: &mut Vec<(String, f64)>,
    progress: &mut dyn FnMut(&str),
) -> Result<RendererProbes, GpuError> {
    let (ctx, scene, view, scene_options, opts, wall) =
        (p.ctx, p.scene, p.view, p.scene_options, p.opts, p.wall);
    let (size, quick) = (opts.size, opts.quick);
    let mut timed = |name: &str, t: std::time::Instant| {
        seconds.push((name.to_string(), t.elapsed().as_secs_f64()))
    };
    let first_azimuth = first_azimuth(scene, view, wall);
    let t = std::time::Instant::now();
    let mut renderer = Renderer::with_options(ctx, scene, scene_options)?;
    let reference = ReferenceScene::new(scene);
    let light_angle = light_angles(
        &mut renderer,
        &reference,
        view,
        size,
        quick,
        first_azimuth,
        &mut || progress("light angle"),
    )?;
    timed("light angle", t);

    let t = std::time::Instant::now();
    let contact = match wall {
        Some(half) => contact_gaps(
            &mut renderer,
            &ScenePlanner::new(scene),
            view,
            half,
            &contact_elevations(quick),
            size,
            &mut || progress("contact"),
        )?,
        None => Vec::new(),
    };
    timed("contact", t);

    let t = std::time::Instant::now();
    let frames = path_frames(quick);
    // Quick mode flies the first quarter of the same path, at the same speed.
    let mut path = camera_path(&view.camera, &scene.bounds(), path_frames(false));
    path.truncate(frames);
    let shimmer = shimmer(
        &mut renderer,
        view,
        &path,
        &methods(&view.shadow),
        size,
        &mut || progress("shimmer"),
    )?;
    timed("shimmer", t);
    drop(renderer);
    drop(reference);

    Ok((light_angle, contact, frames, shimmer))
}

fn pct(x: f64) -> String {
    format!("{:.4} %", 100.0 * x)
}

/// Writes `stability.json`, the charts (`light-angle`, `bias`, `shimmer`, `motion`, `precision`, as SVG and
/// PNG) and `stability.md` into `dir`.
pub fn write(r: &StabilityReport, dir: &Path) -> Result<(), WriteError> {
    std::fs::create_dir_all(dir).map_err(|e| WriteError::io(dir, e))?;
    let json = serde_json::to_string_pretty(r).map_err(|e| WriteError::Json(e.to_string()))?;
    let p = dir.join("stability.json");
    std::fs::write(&p, json).map_err(|e| WriteError::io(&p, e))?;
    for (name, chart) in charts(r) {
        write_lines(
            &chart,
            &dir.join(format!("{name}.svg")),
            &dir.join(format!("{name}.png")),
        )?;
    }
    let p = dir.join("stability.md");
    std::fs::write(&p, markdown(r)).map_err(|e| WriteError::io(&p, e))?;
    Ok(())
}

/// A report that could not be written.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    /// A file.
    #[error("{0}")]
    Io(String),
    /// The JSON.
    #[error("stability.json: {0}")]
    Json(String),
    /// A chart.
    #[error(transparent)]
    Chart(#[from] ChartError),
}

impl WriteError {
    fn io(p: &Path, e: std::io::Error) -> Self {
        WriteError::Io(format!("{}: {e}", p.display()))
    }
}
