//! Fitting the chooser's model: the coefficients of each filter from measured rows, the costs
//! relative to a base configuration, and the generated `model.rs` source.

use super::*;

/// Floor of the relative-error weights in the fit (misclassification this small counts as this).
pub const FIT_FLOOR: f64 = 1e-4;

/// Least squares of `m ≈ a·t + b·e + c` with a, b, c ≥ 0, each residual relative to
/// max(m, `FIT_FLOOR`): every subset of the three terms is solved and the best feasible kept,
/// then scaled so that half the rows are over and half under their prediction.
pub fn fit_coeffs(filter: &'static str, rows: &[&FeatureRow]) -> Coeffs {
    let cols = |r: &FeatureRow| [r.texel_term, r.edge_term, 1.0];
    let mut best = (f64::INFINITY, [0.0; 3]);
    for mask in 1u32..8 {
        let idx: Vec<usize> = (0..3).filter(|i| mask & (1 << i) != 0).collect();
        let n = idx.len();
        let mut ata = vec![vec![0.0f64; n]; n];
        let mut atb = vec![0.0f64; n];
        for r in rows {
            let w = 1.0 / r.misclassified.max(FIT_FLOOR);
            let x = cols(r);
            for (p, &i) in idx.iter().enumerate() {
                atb[p] += w * w * x[i] * r.misclassified;
                for (q, &j) in idx.iter().enumerate() {
                    ata[p][q] += w * w * x[i] * x[j];
                }
            }
        }
        let Some(sol) = solve(ata, atb) else { continue };
        if sol.iter().any(|v| *v < 0.0 || !v.is_finite()) {
            continue;
        }
        let mut k = [0.0; 3];
        for (p, &i) in idx.iter().enumerate() {
            k[i] = sol[p];
        }
        let loss: f64 = rows
            .iter()
            .map(|r| {
                let x = cols(r);
                let pred = k[0] * x[0] + k[1] * x[1] + k[2] * x[2];
                ((pred - r.misclassified) / r.misclassified.max(FIT_FLOOR)).powi(2)
            })
            .sum();
        if loss < best.0 {
            best = (loss, k);
        }
    }
    // Relative least squares is biased low (over-predictions cost more than under-predictions
    // can): rescale so the median of measured / predicted is 1.
    let k = best.1;
    let mut ratios: Vec<f64> = rows
        .iter()
        .map(|r| {
            let x = cols(r);
            r.misclassified / (k[0] * x[0] + k[1] * x[1] + k[2] * x[2])
        })
        .filter(|v| v.is_finite() && *v > 0.0)
        .collect();
    ratios.sort_by(f64::total_cmp);
    let s = ratios.get(ratios.len() / 2).copied().unwrap_or(1.0);
    Coeffs {
        filter,
        a: k[0] * s,
        b: k[1] * s,
        c: k[2] * s,
    }
}

/// Gaussian elimination with partial pivoting; None when singular.
fn solve(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Option<Vec<f64>> {
    let n = b.len();
    for col in 0..n {
        let piv = (col..n).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[piv][col].abs() < 1e-300 {
            return None;
        }
        a.swap(col, piv);
        b.swap(col, piv);
        let (top, rest) = a.split_at_mut(col + 1);
        let pivot_row = &top[col];
        for (k, row) in rest.iter_mut().enumerate() {
            let f = row[col] / pivot_row[col];
            for (x, p) in row[col..].iter_mut().zip(&pivot_row[col..]) {
                *x -= f * p;
            }
            b[col + 1 + k] -= f * b[col];
        }
    }
    let mut x = vec![0.0; n];
    for r in (0..n).rev() {
        let s: f64 = (r + 1..n).map(|c| a[r][c] * x[c]).sum();
        x[r] = (b[r] - s) / a[r][r];
    }
    Some(x)
}

/// The default configuration costs are relative to.
pub const COST_BASE: &str = "2048-d32-pcf2x2-camera-default";

/// Per-pass timings of one view's sweep with the noise of a shared machine averaged out: each
/// configuration's GPU time is estimated as the median camera-pass time of the configurations
/// sharing its filter and fitting method (the camera pass does not depend on the map size) plus
/// the median shadow-pass time of those sharing its map size and fitting method (the shadow pass
/// does not depend on the filter). Measured on lavapipe, single configurations' camera-pass
/// times scatter by 15–25 % between configurations that do the same camera work; these
/// estimates use 3–12 timings each.
pub fn denoised_ms(rows: &[&crate::analysis::sweep::Row]) -> Vec<(String, f64, f64)> {
    let med = crate::analysis::sweep::median;
    rows.iter()
        .map(|r| {
            let cam = med(rows
                .iter()
                .filter(|o| o.filter == r.filter && o.method == r.method)
                .map(|o| o.gpu_camera_ms)
                .collect());
            let sh = med(rows
                .iter()
                .filter(|o| {
                    o.map_texels == r.map_texels && o.method == r.method && o.format == r.format
                })
                .map(|o| o.gpu_shadow_ms)
                .collect());
            (r.config.clone(), cam, sh)
        })
        .collect()
}

/// Camera-pass and shadow-pass time of each configuration relative to `COST_BASE`'s, per
/// (scene, view) from `denoised_ms`, then the geometric mean over the views that have both.
pub fn relative_costs(rows: &[crate::analysis::sweep::Row]) -> Vec<(String, f64, f64)> {
    let mut views: Vec<(String, String)> = Vec::new();
    for r in rows {
        let k = (r.scene.clone(), r.view.clone());
        if !views.contains(&k) {
            views.push(k);
        }
    }
    type Logs = (String, Vec<f64>, Vec<f64>);
    let mut logs: Vec<Logs> = Vec::new();
    for (scene, view) in &views {
        let of: Vec<&crate::analysis::sweep::Row> = rows
            .iter()
            .filter(|r| &r.scene == scene && &r.view == view)
            .collect();
        let est = denoised_ms(&of);
        let Some(&(_, bc, bs)) = est.iter().find(|e| e.0 == COST_BASE) else {
            continue;
        };
        for (name, c, sh) in est {
            let (lc, ls) = ((c / bc).ln(), (sh / bs).ln());
            if !(lc.is_finite() && ls.is_finite()) {
                continue;
            }
            match logs.iter_mut().find(|e| e.0 == name) {
                Some(e) => {
                    e.1.push(lc);
                    e.2.push(ls);
                }
                None => logs.push((name, vec![lc], vec![ls])),
            }
        }
    }
    let gm = |l: &[f64]| (l.iter().sum::<f64>() / l.len() as f64).exp();
    logs.into_iter()
        .map(|(n, c, sh)| {
            let (c, sh) = (gm(&c), gm(&sh));
            (n, c, sh)
        })
        .collect()
}

/// Fits the model to a sweep: coefficients per filter from its rows' prediction terms `feats`
/// (`feature_rows`), costs from its `rows` (`relative_costs`); returns the Rust source of
/// `analysis::model` with `provenance` in its header.
pub fn fit_model(
    feats: &[FeatureRow],
    rows: &[crate::analysis::sweep::Row],
    provenance: &str,
) -> String {
    let model: Vec<Coeffs> = ["nearest", "pcf2x2", "pcf3x3", "pcf5x5"]
        .into_iter()
        .filter_map(|f| {
            let of: Vec<&FeatureRow> = feats.iter().filter(|r| r.filter == f).collect();
            (!of.is_empty()).then(|| fit_coeffs(f, &of))
        })
        .collect();
    model_source(&model, &relative_costs(rows), provenance)
}

/// Rust source of `analysis::model` for fitted coefficients and costs.
pub fn model_source(model: &[Coeffs], costs: &[(String, f64, f64)], provenance: &str) -> String {
    let mut s = String::new();
    s.push_str(
        "//! The error-budget model's fitted numbers, generated by `umbra sweep --fit-budget`.\n",
    );
    for line in provenance.lines() {
        s.push_str(&format!("//! {line}\n"));
    }
    s.push_str("\nuse super::coeffs::Coeffs;\n\n/// Coefficients per filter.\n");
    s.push_str(&format!("pub const MODEL: [Coeffs; {}] = [\n", model.len()));
    for k in model {
        s.push_str(&format!(
            "    Coeffs {{\n        filter: {:?},\n        a: {:e},\n        b: {:e},\n        c: {:e},\n    }},\n",
            k.filter, k.a, k.b, k.c
        ));
    }
    s.push_str(
        "];\n\n/// Candidates: (configuration, camera-pass time, shadow-pass time), each relative to the\n/// default configuration's (`budget::COST_BASE`).\n",
    );
    s.push_str(&format!(
        "pub const COSTS: [(&str, f64, f64); {}] = [\n",
        costs.len()
    ));
    for (n, c, sh) in costs {
        s.push_str(&format!("    ({n:?}, {c:.3}, {sh:.3}),\n"));
    }
    s.push_str("];\n");
    s
}
