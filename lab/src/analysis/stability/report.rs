//! The whole suite: run every probe, judge the results against the thresholds, and write
//! `stability.json`, the charts and `stability.md`.

use super::degenerate::{degenerate, DegenerateRow};
use super::light::{contact_gaps, light_angles, AngleRow, ContactRow};
use super::motion::{motion, MotionSeries};
use super::precision::{precision, PrecisionRow};
use super::shimmer::{camera_path, methods, shimmer, ShimmerSeries};
use super::{StabilityOptions, EDGE_ON_DEGREES, SCHEMA};
use crate::analysis::chart::ChartError;
use crate::analysis::lines::{write_lines, LineChart, Series};
use crate::reference::ReferenceScene;
use glam::Vec3;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;
use std::sync::Arc;
use umbra::gpu::{Context, GpuError};
use umbra::plan::ScenePlanner;
use umbra::render::{Renderer, SceneOptions, View};
use umbra::scene::Scene;
use umbra::table::Table;

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
    let moving = 4 * super::motion::frames(quick);
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

fn describe(s: &umbra::render::ShadowSettings) -> String {
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
    let mut timed = |name: &str, t: std::time::Instant| {
        seconds.push((name.to_string(), t.elapsed().as_secs_f64()))
    };
    let lights = umbra::plan::effective_lights(&scene.lights, view);
    let first_azimuth = lights
        .iter()
        .find(|l| l.kind == umbra::scene::LightKind::Directional)
        .map_or(0.0, |l| {
            let to_sun = -l.direction.normalize_or(Vec3::NEG_Y);
            to_sun.x.atan2(to_sun.z).to_degrees()
        });
    let first_azimuth = if wall.is_some() { 0.0 } else { first_azimuth };

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

/// A flip series' chart points: (frame, flipped fraction of that frame's points).
fn per_frame(points: &[usize], flipped: &[usize]) -> Vec<(f64, f64)> {
    points
        .iter()
        .zip(flipped)
        .enumerate()
        .map(|(i, (&n, &f))| ((i + 1) as f64, super::fraction(f, n)))
        .collect()
}

/// The cells of a flip series: mean and worst flipped fraction, mean points per frame.
fn flip_cells(mean: f64, max: f64, points: &[usize]) -> [String; 3] {
    let per_frame = points.iter().sum::<usize>() / points.len().max(1);
    [
        format!("{mean:.2e}"),
        format!("{max:.2e}"),
        per_frame.to_string(),
    ]
}

fn pct(x: f64) -> String {
    format!("{:.4} %", 100.0 * x)
}

/// The defaults' rows (bias factor 1).
fn at_defaults(r: &StabilityReport) -> impl Iterator<Item = &AngleRow> {
    r.light_angle.iter().filter(|a| a.bias_scale == 1.0)
}

/// Judges the report against the thresholds.
pub fn verdicts(r: &StabilityReport) -> Vec<Verdict> {
    let mut v = Vec::new();
    acne_verdicts(r, &mut v);
    contact_verdicts(r, &mut v);
    motion_verdicts(r, &mut v);
    precision_verdicts(r, &mut v);
    degenerate_verdicts(r, &mut v);
    v
}

/// No acne on planar and curved receivers at the defaults.
fn acne_verdicts(r: &StabilityReport, v: &mut Vec<Verdict>) {
    let worst = |from: f32, curved: bool| {
        at_defaults(r)
            .filter(|a| a.elevation_deg >= from)
            .map(|a| {
                let (n, of) = if curved {
                    (a.counts.acne_curved, a.counts.curved)
                } else {
                    (a.counts.acne_planar, a.counts.planar)
                };
                (n, of, a.elevation_deg, a.azimuth_deg)
            })
            .max_by_key(|x| x.0)
    };
    for (from, curved, what) in [(1.0, false, "planar"), (5.0, true, "curved")] {
        let judged: usize = at_defaults(r)
            .filter(|a| a.elevation_deg >= from)
            .map(|a| {
                if curved {
                    a.counts.curved
                } else {
                    a.counts.planar
                }
            })
            .sum();
        let w = worst(from, curved);
        v.push(Verdict {
            criterion: format!("no acne on {what} receivers from {from}° to 90° at the defaults"),
            measured: match w {
                Some((0, _, _, _)) if judged > 0 => {
                    format!("0 acne pixels at every elevation; {judged} {what} pixels judged")
                }
                Some((n, of, e, az)) if judged > 0 => format!(
                    "worst {n} acne pixels of {of} {what} judged (sun {e}°, azimuth {az:.0}°); {judged} {what} pixels judged in all"
                ),
                _ => format!("no {what} receivers judged"),
            },
            pass: (judged > 0).then(|| w.is_none_or(|x| x.0 == 0)),
        });
    }
}

/// The contact gap at the thin wall's base.
fn contact_verdicts(r: &StabilityReport, v: &mut Vec<Verdict>) {
    let gaps: Vec<&ContactRow> = r
        .contact
        .iter()
        .filter(|c| c.elevation_deg >= 5.0)
        .collect();
    if !gaps.is_empty() {
        let worst = gaps
            .iter()
            .filter_map(|c| c.gap_texels_max.map(|g| (g, c.elevation_deg)))
            .fold(None::<(f64, f32)>, |a, b| match a {
                Some(x) if x.0 >= b.0 => Some(x),
                _ => Some(b),
            });
        v.push(Verdict {
            criterion: format!(
                "contact shadow within {CONTACT_BOUND_TEXELS} texels of the thin wall's base at every elevation ≥ 5°"
            ),
            measured: match worst {
                Some((g, e)) => format!("largest gap {g:.2} texels (sun {e}°)"),
                None => "no base points seen".into(),
            },
            pass: Some(worst.is_some_and(|(g, _)| g <= CONTACT_BOUND_TEXELS)),
        });
    }
}

/// Shimmer and flicker for a camera and casters in motion.
fn motion_verdicts(r: &StabilityReport, v: &mut Vec<Verdict>) {
    // Judged: what a camera in motion gets (held across frames, as the viewer renders); the
    // fits made afresh every frame are reported beside them.
    let judged: Vec<&ShimmerSeries> = r.shimmer.iter().filter(|s| s.snapped && s.held).collect();
    for s in &judged {
        v.push(Verdict {
            criterion: format!(
                "shimmer ≤ {SHIMMER_BOUND:e} flipped points per frame ({})",
                s.method
            ),
            measured: format!(
                "mean {:.2e}, worst frame {:.2e}",
                s.mean_fraction, s.max_fraction
            ),
            pass: Some(s.mean_fraction <= SHIMMER_BOUND),
        });
    }
    for s in r.motion.iter().filter(|s| s.method.ends_with("held")) {
        let bound = if s.probe == "sun arc" {
            SUN_ARC_BOUND
        } else {
            MOVING_CASTER_BOUND
        };
        v.push(Verdict {
            criterion: format!(
                "flicker in motion ≤ {bound:e} still points per frame ({}: {}, {})",
                s.probe, s.mover, s.method
            ),
            measured: format!(
                "mean {:.2e}, worst frame {:.2e}",
                s.mean_fraction, s.max_fraction
            ),
            pass: Some(s.mean_fraction <= bound),
        });
    }
    for s in r.shimmer.iter().filter(|s| !s.snapped) {
        let twin = r
            .shimmer
            .iter()
            .find(|t| t.snapped && !t.held && t.cascades == s.cascades && t.fit == s.fit);
        if let Some(t) = twin {
            v.push(Verdict {
                criterion: format!(
                    "unsnapped control measurably worse ({} ≥ 2× {})",
                    s.method, t.method
                ),
                measured: format!("mean {:.2e} vs {:.2e}", s.mean_fraction, t.mean_fraction),
                pass: Some(s.mean_fraction >= 2.0 * t.mean_fraction && s.mean_fraction > 0.0),
            });
        }
    }
}

/// Far from the origin as near it.
fn precision_verdicts(r: &StabilityReport, v: &mut Vec<Verdict>) {
    if let (Some(o), Some(far)) = (
        r.precision.first(),
        r.precision
            .iter()
            .filter(|p| p.scale == 1.0)
            .max_by(|a, b| a.offset.total_cmp(&b.offset)),
    ) {
        let begins = r
            .precision
            .iter()
            .filter(|p| p.scale == 1.0 && p.ratio_to_origin > FAR_RATIO_BOUND)
            .map(|p| p.offset)
            .fold(None, |a: Option<f64>, o| Some(a.map_or(o, |a| a.min(o))));
        v.push(Verdict {
            criterion: format!(
                "misclassification at {:.0e} units from the origin within {FAR_RATIO_BOUND}× the origin case",
                far.offset
            ),
            measured: format!(
                "{} vs {} ({:.2}×){}; f32 step of the scene's own coordinates there {:.3e}, of the GPU's (relative to the render origin) {:.3e}, finest texel {:.3e}",
                pct(far.misclassified),
                pct(o.misclassified),
                far.ratio_to_origin,
                begins.map_or(String::new(), |o| format!(
                    "; the limit shows from {o:.0e} units"
                )),
                far.position_step,
                far.gpu_position_step,
                far.texel_world
            ),
            pass: Some(far.ratio_to_origin <= FAR_RATIO_BOUND),
        });
    }
}

/// Degenerate views and input.
fn degenerate_verdicts(r: &StabilityReport, v: &mut Vec<Verdict>) {
    let failed: Vec<&str> = r
        .degenerate
        .iter()
        .filter(|d| !d.ok)
        .map(|d| d.case.as_str())
        .collect();
    v.push(Verdict {
        criterion:
            "degenerate views and input: no validation message, finite depth, the documented result"
                .into(),
        measured: if failed.is_empty() {
            format!(
                "{} of {} cases pass",
                r.degenerate.len(),
                r.degenerate.len()
            )
        } else {
            format!("failed: {}", failed.join(", "))
        },
        pass: Some(failed.is_empty()),
    });
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

/// The bias sweep's rows: sun directions with more than one bias factor.
fn bias_rows(r: &StabilityReport) -> impl Iterator<Item = &AngleRow> {
    r.light_angle.iter().filter(|a| {
        r.light_angle
            .iter()
            .filter(|b| b.elevation_deg == a.elevation_deg && b.azimuth_deg == a.azimuth_deg)
            .count()
            > 1
    })
}

/// Per elevation at the defaults: the worst over azimuths of `f`.
fn worst_by_elevation(r: &StabilityReport, f: impl Fn(&AngleRow) -> f64) -> Vec<(f64, f64)> {
    let mut out: Vec<(f64, f64)> = Vec::new();
    for a in at_defaults(r) {
        let (e, y) = (a.elevation_deg as f64, f(a));
        match out.iter_mut().find(|p| p.0 == e) {
            Some(p) => p.1 = p.1.max(y),
            None => out.push((e, y)),
        }
    }
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out
}

/// The charts, by file stem.
pub fn charts(r: &StabilityReport) -> Vec<(&'static str, LineChart)> {
    let mut out = Vec::new();
    light_angle_chart(r, &mut out);
    bias_chart(r, &mut out);
    shimmer_chart(r, &mut out);
    motion_chart(r, &mut out);
    precision_charts(r, &mut out);
    out
}

/// Where log charts draw 0.
const FLOOR: f64 = 1e-6;

/// Errors against sun elevation.
fn light_angle_chart(r: &StabilityReport, out: &mut Vec<(&'static str, LineChart)>) {
    let series = |label: &str, f: &dyn Fn(&AngleRow) -> f64| Series {
        label: label.into(),
        points: worst_by_elevation(r, f),
    };
    out.push((
        "light-angle",
        LineChart {
            title: format!(
                "{}: errors against sun elevation (defaults, worst azimuth)",
                r.scene
            ),
            x_desc: "sun elevation (degrees)".into(),
            y_desc: "fraction of judged pixels (0 drawn at 1e-6)".into(),
            x_log: true,
            y_floor: FLOOR,
            series: vec![
                series("acne, planar receivers", &|a| a.acne_planar),
                series("acne, curved receivers", &|a| a.acne_curved),
                series("false light (leaks, peter-panning)", &|a| a.false_light),
                series("misclassified", &|a| a.misclassified),
            ],
            thresholds: Vec::new(),
            marks: Vec::new(),
        },
    ));
}

/// Acne against peter-panning across the bias.
fn bias_chart(r: &StabilityReport, out: &mut Vec<(&'static str, LineChart)>) {
    let (bias_elevations, _) = super::light::bias_sweep(r.quick);
    let mut bias = Vec::new();
    let mut marks = Vec::new();
    for e in bias_elevations {
        let rows: Vec<&AngleRow> = bias_rows(r)
            .filter(|a| a.elevation_deg == e && a.bias_scale > 0.0)
            .collect();
        if rows.is_empty() {
            continue;
        }
        let acne = |a: &&AngleRow| {
            super::fraction(a.counts.acne_planar + a.counts.acne_curved, a.counts.judged)
        };
        bias.push(Series {
            label: format!("acne, sun {e}°"),
            points: rows
                .iter()
                .map(|a| (a.bias_scale as f64, acne(a)))
                .collect(),
        });
        bias.push(Series {
            label: format!("false light, sun {e}°"),
            points: rows
                .iter()
                .map(|a| (a.bias_scale as f64, a.false_light))
                .collect(),
        });
        if let Some(d) = rows.iter().find(|a| a.bias_scale == 1.0) {
            marks.push((format!("defaults, {e}°"), (1.0, d.false_light)));
        }
    }
    out.push((
        "bias",
        LineChart {
            title: format!("{}: acne against peter-panning across the bias", r.scene),
            x_desc: "factor on the default constant, slope and normal-offset biases".into(),
            y_desc: "fraction of judged pixels (0 drawn at 1e-6)".into(),
            x_log: true,
            y_floor: FLOOR,
            series: bias,
            thresholds: Vec::new(),
            marks,
        },
    ));
}

/// Shimmer along the flythrough.
fn shimmer_chart(r: &StabilityReport, out: &mut Vec<(&'static str, LineChart)>) {
    out.push((
        "shimmer",
        LineChart {
            title: format!(
                "{}: shimmer along a {}-frame flythrough",
                r.scene, r.path_frames
            ),
            x_desc: "frame".into(),
            y_desc: "flipped fraction of fixed world points (0 drawn at 1e-6)".into(),
            x_log: false,
            y_floor: FLOOR,
            series: r
                .shimmer
                .iter()
                .map(|s| Series {
                    label: s.method.clone(),
                    points: per_frame(&s.points, &s.flipped),
                })
                .collect(),
            thresholds: vec![("bound with snapping".into(), SHIMMER_BOUND)],
            marks: Vec::new(),
        },
    ));
}

/// Flicker in motion, per probe.
fn motion_chart(r: &StabilityReport, out: &mut Vec<(&'static str, LineChart)>) {
    out.push((
        "motion",
        LineChart {
            title: format!(
                "{}: flicker in motion, a still camera ({} frames)",
                r.scene, r.motion_frames
            ),
            x_desc: "frame".into(),
            y_desc: "flipped fraction of still points (0 drawn at 1e-6)".into(),
            x_log: false,
            y_floor: FLOOR,
            series: r
                .motion
                .iter()
                .map(|s| Series {
                    label: format!("{} ({}), {}", s.probe, s.mover, s.method),
                    points: per_frame(&s.points, &s.flipped),
                })
                .collect(),
            thresholds: vec![
                ("moving caster bound".into(), MOVING_CASTER_BOUND),
                ("sun arc bound".into(), SUN_ARC_BOUND),
            ],
            marks: Vec::new(),
        },
    ));
}

/// Errors far from the origin and across scales.
fn precision_charts(r: &StabilityReport, out: &mut Vec<(&'static str, LineChart)>) {
    let offset_x = |p: &PrecisionRow| p.offset.max(1.0);
    let moved: Vec<&PrecisionRow> = r.precision.iter().filter(|p| p.scale == 1.0).collect();
    let scaled: Vec<&PrecisionRow> = r.precision.iter().filter(|p| p.offset == 0.0).collect();
    let mut sorted = scaled.clone();
    sorted.sort_by(|a, b| a.scale.total_cmp(&b.scale));
    let origin = r.precision.first().map_or(0.0, |p| p.misclassified);
    out.push((
        "precision",
        LineChart {
            title: format!("{}: far from the origin (the origin drawn at 1)", r.scene),
            x_desc: "distance from the origin (scene units)".into(),
            y_desc: "fraction (0 drawn at 1e-6) / ratio".into(),
            x_log: true,
            y_floor: FLOOR,
            series: vec![
                Series {
                    label: "misclassified".into(),
                    points: moved
                        .iter()
                        .map(|p| (offset_x(p), p.misclassified))
                        .collect(),
                },
                Series {
                    label: "acne".into(),
                    points: moved.iter().map(|p| (offset_x(p), p.acne)).collect(),
                },
                Series {
                    label: "f32 step of world positions / finest texel".into(),
                    points: moved
                        .iter()
                        .map(|p| (offset_x(p), p.position_step / p.texel_world.max(1e-30)))
                        .collect(),
                },
                Series {
                    label: "f32 step on the GPU (rebased) / finest texel".into(),
                    points: moved
                        .iter()
                        .map(|p| (offset_x(p), p.gpu_position_step / p.texel_world.max(1e-30)))
                        .collect(),
                },
            ],
            thresholds: vec![(
                format!("{FAR_RATIO_BOUND}× the origin's misclassification"),
                FAR_RATIO_BOUND * origin,
            )],
            marks: Vec::new(),
        },
    ));
    out.push((
        "scale",
        LineChart {
            title: format!("{}: scaled from 1e-3 to 1e4", r.scene),
            x_desc: "uniform scale".into(),
            y_desc: "fraction of judged pixels (0 drawn at 1e-6)".into(),
            x_log: true,
            y_floor: FLOOR,
            series: vec![
                Series {
                    label: "misclassified".into(),
                    points: sorted.iter().map(|p| (p.scale, p.misclassified)).collect(),
                },
                Series {
                    label: "acne".into(),
                    points: sorted.iter().map(|p| (p.scale, p.acne)).collect(),
                },
            ],
            thresholds: Vec::new(),
            marks: Vec::new(),
        },
    ));
}

/// The Markdown summary.
pub fn markdown(r: &StabilityReport) -> String {
    [
        summary_md(r),
        light_angle_md(r),
        bias_md(r),
        shimmer_md(r),
        motion_md(r),
        precision_md(r),
        degenerate_md(r),
        runtime_md(r),
    ]
    .concat()
}

/// The title, the run, the verdicts and what the terms mean.
fn summary_md(r: &StabilityReport) -> String {
    let mut m = String::new();
    let total = r
        .seconds
        .iter()
        .find(|s| s.0 == "total")
        .map_or(0.0, |s| s.1);
    let _ = writeln!(m, "# umbra stability: {}\n", r.scene);
    let _ = writeln!(
        m,
        "{}×{} on {}; shadow defaults: {}. {} s in all{}.\n",
        r.size.0,
        r.size.1,
        r.device,
        r.defaults,
        total.round(),
        if r.quick { " (quick)" } else { "" }
    );
    let mut t = Table::new(&["criterion", "measured", "result"]);
    for v in &r.verdicts {
        let res = match v.pass {
            Some(true) => "pass",
            Some(false) => "**FAIL**",
            None => "n/a",
        };
        t.row(vec![v.criterion.clone(), v.measured.clone(), res.into()]);
    }
    m += &t.render(true);
    let _ = writeln!(
        m,
        "\nAcne: false shadow that touches no exactly shadowed pixel, no 2-pixel band around an \
         exact shadow edge and no silhouette (a shadow drawn too wide is edge error, not acne). \
         False light: lit where the exact answer is shadow (leaks, peter-panning). Fractions are \
         of the pixels where the GPU and the ray-cast reference see the same surface.\n"
    );
    m
}

/// Acne, false light and misclassification by sun elevation.
fn light_angle_md(r: &StabilityReport) -> String {
    let mut m = String::new();
    let _ = writeln!(
        m,
        "## Light angle (defaults, worst azimuth)\n\n![light angle](light-angle.png)\n"
    );
    let ap = worst_by_elevation(r, |a| a.counts.acne_planar as f64);
    let ac = worst_by_elevation(r, |a| a.counts.acne_curved as f64);
    let fl = worst_by_elevation(r, |a| a.false_light);
    let mc = worst_by_elevation(r, |a| a.misclassified);
    let mut t = Table::new(&[
        "sun",
        "acne planar (px)",
        "acne curved (px)",
        "false light",
        "misclassified",
    ]);
    for i in 0..ap.len() {
        t.row(vec![
            format!("{}°", ap[i].0),
            ap[i].1.to_string(),
            ac[i].1.to_string(),
            pct(fl[i].1),
            pct(mc[i].1),
        ]);
    }
    m += &t.render(true);
    let low: Vec<String> = ap
        .iter()
        .zip(&fl)
        .filter(|(a, _)| a.0 < 5.0)
        .map(|(a, f)| format!("{}°: {} acne px, {} false light", a.0, a.1, pct(f.1)))
        .collect();
    if !low.is_empty() {
        let _ = writeln!(
            m,
            "\nBelow 5° (receivers at grazing incidence, shadows 11× longer than their casters and \
             more): {}. Curved receivers are judged from 5°: below it the band between a \
             tessellated surface's interpolated terminator and its facets' own shadow is wider \
             than the normal offset.\n",
            low.join("; ")
        );
    }
    m
}

/// The bias trade-off and the contact gap at the thin wall's base.
fn bias_md(r: &StabilityReport) -> String {
    let mut m = String::new();
    let _ = writeln!(m, "\n## Bias trade-off\n\n![bias](bias.png)\n");
    let mut t = Table::new(&[
        "sun",
        "bias factor",
        "acne (px)",
        "false light",
        "misclassified",
    ]);
    for a in bias_rows(r) {
        t.row(vec![
            format!("{}°", a.elevation_deg),
            a.bias_scale.to_string(),
            (a.counts.acne_planar + a.counts.acne_curved).to_string(),
            pct(a.false_light),
            pct(a.misclassified),
        ]);
    }
    m += &t.render(true);
    if !r.contact.is_empty() {
        let _ = writeln!(m, "\n## Contact gap at the thin wall's base\n");
        let mut t = Table::new(&["sun", "texel", "points", "gap (texels)"]);
        for c in &r.contact {
            t.row(vec![
                format!("{}°", c.elevation_deg),
                format!("{:.2e}", c.texel_world),
                c.points.to_string(),
                c.gap_texels_max.map_or("n/a".into(), |g| format!("{g:.2}")),
            ]);
        }
        m += &t.render(true);
    }
    m
}

/// Shimmer along the flythrough, per method.
fn shimmer_md(r: &StabilityReport) -> String {
    let mut m = String::new();
    let _ = writeln!(
        m,
        "\n## Shimmer along the flythrough ({} frames)\n\n![shimmer](shimmer.png)\n",
        r.path_frames
    );
    let mut t = Table::new(&[
        "method",
        "mean flipped",
        "worst frame",
        "points per frame",
        "mean finest texel",
    ]);
    for s in &r.shimmer {
        let mut row = vec![s.method.clone()];
        row.extend(flip_cells(s.mean_fraction, s.max_fraction, &s.points));
        row.push(format!("{:.3e}", s.mean_texel));
        t.row(row);
    }
    m += &t.render(true);
    m
}

/// Flicker in motion, per probe.
fn motion_md(r: &StabilityReport) -> String {
    let mut m = String::new();
    let _ = writeln!(
        m,
        "\n## Flicker in motion ({} frames, a still camera)\n\n![motion](motion.png)\n",
        r.motion_frames
    );
    let mut t = Table::new(&[
        "probe",
        "mover",
        "method",
        "mean flipped",
        "worst frame",
        "points per frame",
    ]);
    for s in &r.motion {
        let mut row = vec![s.probe.clone(), s.mover.clone(), s.method.clone()];
        row.extend(flip_cells(s.mean_fraction, s.max_fraction, &s.points));
        t.row(row);
    }
    m += &t.render(true);
    m
}

/// Precision far from the origin.
fn precision_md(r: &StabilityReport) -> String {
    let mut m = String::new();
    let _ = writeln!(
        m,
        "\n## Precision\n\n![precision](precision.png) ![scale](scale.png)\n"
    );
    let mut t = Table::new(&[
        "offset",
        "scale",
        "misclassified",
        "acne",
        "× origin",
        "f32 step, world",
        "f32 step, GPU",
        "finest texel",
        "depth step reversed-z",
        "depth step standard-z (analytic)",
    ]);
    for p in &r.precision {
        t.row(vec![
            format!("{:.0e}", p.offset),
            format!("{:.0e}", p.scale),
            pct(p.misclassified),
            pct(p.acne),
            format!("{:.2}", p.ratio_to_origin),
            format!("{:.2e}", p.position_step),
            format!("{:.2e}", p.gpu_position_step),
            format!("{:.2e}", p.texel_world),
            format!("{:.2e}", p.depth_step_reversed),
            format!("{:.2e}", p.depth_step_standard),
        ]);
    }
    m += &t.render(true);
    let _ = writeln!(
        m,
        "\nA renderer that sent world-space f32 positions to the GPU would lose its shadows where \
         the world step passes the shadow texel (10⁵ units for a centimetre texel). umbra \
         rebases every transform, light and camera on the CPU, in f64, to the scene's render \
         origin (the centre of its bounds when that lies more than 4 radii out), so the GPU works \
         with the small relative step; the stored f32 coordinates still round the input itself \
         (each object placed to within the world step). The camera-depth columns compare umbra's reversed-z float buffer with a standard-z float \
         buffer at the same view distance (analytic: umbra has no standard-z path).\n"
    );
    m
}

/// The degenerate views and inputs.
fn degenerate_md(r: &StabilityReport) -> String {
    let mut m = String::new();
    let _ = writeln!(m, "## Degenerate views and input\n");
    let _ = writeln!(
        m,
        "Interior misclassified: away from exact shadow edges, on receivers turned at least {EDGE_ON_DEGREES}° \
         towards the light (bound {:.1} %). Receivers closer to edge-on (walls under a sun overhead, \
         the ground under a sun on the horizon) are reported apart: a map texel spreads over more \
         than 11 texel lengths of them, so a texel or two decides their whole shadow, and they get \
         under 9 % of the light.\n",
        100.0 * super::degenerate::INTERIOR_BOUND
    );
    let mut t = Table::new(&[
        "case",
        "documented result",
        "triangles",
        "validation",
        "finite",
        "interior misclassified",
        "edge-on receivers (pixels): misclassified",
        "GPU ms",
        "result",
    ]);
    for d in &r.degenerate {
        t.row(vec![
            d.case.clone(),
            d.expected.clone(),
            d.triangles.to_string(),
            d.validation_messages
                .map_or("off".into(), |n| format!("{n} messages")),
            d.finite.to_string(),
            pct(d.interior_misclassified),
            format!("{} ({})", pct(d.edge_on_misclassified), d.counts.edge_on),
            d.gpu_ms.map_or("n/a".into(), |g| format!("{g:.1}")),
            if d.ok { "pass" } else { "**FAIL**" }.into(),
        ]);
    }
    m += &t.render(true);
    m
}

/// Where the time went.
fn runtime_md(r: &StabilityReport) -> String {
    let mut m = String::new();
    let _ = writeln!(m, "\n## Runtime\n");
    for (name, s) in &r.seconds {
        let _ = writeln!(m, "- {name}: {s:.1} s");
    }
    m
}
