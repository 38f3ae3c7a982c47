//! The suite's results judged against the thresholds, one verdict per threshold.

use super::*;
use crate::analysis::stability::light::{AngleRow, ContactRow};
use crate::analysis::stability::shimmer::ShimmerSeries;

/// The defaults' rows (bias factor 1).
pub(super) fn at_defaults(r: &StabilityReport) -> impl Iterator<Item = &AngleRow> {
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
pub(super) fn acne_verdicts(r: &StabilityReport, v: &mut Vec<Verdict>) {
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
pub(super) fn contact_verdicts(r: &StabilityReport, v: &mut Vec<Verdict>) {
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
pub(super) fn motion_verdicts(r: &StabilityReport, v: &mut Vec<Verdict>) {
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
    // Exact shadows have no texels to flicker: away from edges, their still points flip only
    // where the exact pass and the reference disagree in one frame and not the next (isolated
    // pixels where the light grazes a surface). Hybrid shadows keep the map's verdict only where
    // it is proven, so they are held to the same bound.
    for s in r
        .motion
        .iter()
        .filter(|s| s.method == "exact" || s.method == "hybrid")
    {
        v.push(Verdict {
            criterion: format!(
                "{} shadows: flicker in motion away from edges ≤ {EXACT_MOTION_BOUND:.0e} ({}: {})",
                s.method, s.probe, s.mover
            ),
            measured: format!(
                "mean {:.2e} away from edges, {:.2e} in all",
                s.mean_interior_fraction, s.mean_fraction
            ),
            pass: Some(s.mean_interior_fraction <= EXACT_MOTION_BOUND),
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
pub(super) fn precision_verdicts(r: &StabilityReport, v: &mut Vec<Verdict>) {
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
pub(super) fn degenerate_verdicts(r: &StabilityReport, v: &mut Vec<Verdict>) {
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
