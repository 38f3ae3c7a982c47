//! `stability.md`: the verdicts and each probe's table.

use super::*;
use crate::analysis::stability::EDGE_ON_DEGREES;
use crate::table::Table;
use std::fmt::Write as _;

/// The cells of a flip series: mean and worst flipped fraction, mean points per frame.
pub(super) fn flip_cells(mean: f64, max: f64, points: &[usize]) -> [String; 3] {
    let per_frame = points.iter().sum::<usize>() / points.len().max(1);
    [
        format!("{mean:.2e}"),
        format!("{max:.2e}"),
        per_frame.to_string(),
    ]
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
pub(super) fn summary_md(r: &StabilityReport) -> String {
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
pub(super) fn light_angle_md(r: &StabilityReport) -> String {
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
pub(super) fn bias_md(r: &StabilityReport) -> String {
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
pub(super) fn shimmer_md(r: &StabilityReport) -> String {
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
pub(super) fn motion_md(r: &StabilityReport) -> String {
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
        "mean flipped away from edges",
    ]);
    for s in &r.motion {
        let mut row = vec![s.probe.clone(), s.mover.clone(), s.method.clone()];
        row.extend(flip_cells(s.mean_fraction, s.max_fraction, &s.points));
        row.push(format!("{:.2e}", s.mean_interior_fraction));
        t.row(row);
    }
    m += &t.render(true);
    m
}

/// Precision far from the origin.
pub(super) fn precision_md(r: &StabilityReport) -> String {
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
pub(super) fn degenerate_md(r: &StabilityReport) -> String {
    let mut m = String::new();
    let _ = writeln!(m, "## Degenerate views and input\n");
    let _ = writeln!(
        m,
        "Interior misclassified: away from exact shadow edges, on receivers turned at least {EDGE_ON_DEGREES}° \
         towards the light (bound {:.1} %). Receivers closer to edge-on (walls under a sun overhead, \
         the ground under a sun on the horizon) are reported apart: a map texel spreads over more \
         than 11 texel lengths of them, so a texel or two decides their whole shadow, and they get \
         under 9 % of the light.\n",
        100.0 * crate::analysis::stability::degenerate::INTERIOR_BOUND
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
pub(super) fn runtime_md(r: &StabilityReport) -> String {
    let mut m = String::new();
    let _ = writeln!(m, "\n## Runtime\n");
    for (name, s) in &r.seconds {
        let _ = writeln!(m, "- {name}: {s:.1} s");
    }
    m
}
