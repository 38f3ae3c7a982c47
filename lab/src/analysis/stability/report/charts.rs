//! The suite's charts, by file stem.

use super::*;
use crate::analysis::lines::{LineChart, Series};
use crate::analysis::stability::light::AngleRow;
use crate::analysis::stability::precision::PrecisionRow;

/// A flip series' chart points: (frame, flipped fraction of that frame's points).
pub(super) fn per_frame(points: &[usize], flipped: &[usize]) -> Vec<(f64, f64)> {
    points
        .iter()
        .zip(flipped)
        .enumerate()
        .map(|(i, (&n, &f))| ((i + 1) as f64, crate::analysis::stability::fraction(f, n)))
        .collect()
}

/// The bias sweep's rows: sun directions with more than one bias factor.
pub(super) fn bias_rows(r: &StabilityReport) -> impl Iterator<Item = &AngleRow> {
    r.light_angle.iter().filter(|a| {
        r.light_angle
            .iter()
            .filter(|b| b.elevation_deg == a.elevation_deg && b.azimuth_deg == a.azimuth_deg)
            .count()
            > 1
    })
}

/// Per elevation at the defaults: the worst over azimuths of `f`.
pub(super) fn worst_by_elevation(
    r: &StabilityReport,
    f: impl Fn(&AngleRow) -> f64,
) -> Vec<(f64, f64)> {
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
pub(super) const FLOOR: f64 = 1e-6;

/// Errors against sun elevation.
pub(super) fn light_angle_chart(r: &StabilityReport, out: &mut Vec<(&'static str, LineChart)>) {
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
pub(super) fn bias_chart(r: &StabilityReport, out: &mut Vec<(&'static str, LineChart)>) {
    let (bias_elevations, _) = crate::analysis::stability::light::bias_sweep(r.quick);
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
            crate::analysis::stability::fraction(
                a.counts.acne_planar + a.counts.acne_curved,
                a.counts.judged,
            )
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
pub(super) fn shimmer_chart(r: &StabilityReport, out: &mut Vec<(&'static str, LineChart)>) {
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
pub(super) fn motion_chart(r: &StabilityReport, out: &mut Vec<(&'static str, LineChart)>) {
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
pub(super) fn precision_charts(r: &StabilityReport, out: &mut Vec<(&'static str, LineChart)>) {
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
