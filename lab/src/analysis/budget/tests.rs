use super::*;
use crate::analysis::grid::Grid;

fn feature_row(t: f64, e: f64, m: f64) -> FeatureRow {
    FeatureRow {
        scene: "s".into(),
        view: "v".into(),
        config: "c".into(),
        filter: "pcf2x2".into(),
        method: "camera".into(),
        map_texels: 2048,
        texel_term: t,
        edge_term: e,
        misclassified: m,
        gpu_ms: 10.0,
    }
}

#[test]
fn fit_recovers_known_coefficients_and_stays_non_negative() {
    let rows: Vec<FeatureRow> = (0..40)
        .map(|i| {
            let t = 1e-4 * (1.0 + i as f64);
            let e = 2e-3 * (1.0 + (i % 7) as f64);
            feature_row(t, e, 0.8 * t + 0.05 * e + 2e-5)
        })
        .collect();
    let refs: Vec<&FeatureRow> = rows.iter().collect();
    let k = fit_coeffs("pcf2x2", &refs);
    assert!(
        (k.a - 0.8).abs() < 1e-6 && (k.b - 0.05).abs() < 1e-6 && (k.c - 2e-5).abs() < 1e-9,
        "{k:?}"
    );
    // Data that would want a negative slope gets a non-negative fit.
    let neg: Vec<FeatureRow> = (0..10)
        .map(|i| feature_row(i as f64, 1.0, 1.0 - 0.05 * i as f64))
        .collect();
    let k = fit_coeffs("nearest", &neg.iter().collect::<Vec<_>>());
    assert!(k.a >= 0.0 && k.b >= 0.0 && k.c >= 0.0, "{k:?}");
}

#[test]
fn calibration_scales_then_fits_a_line() {
    let v = |i: usize, p: f64, m: f64| Verified {
        prediction: pred(i, p, 1.0),
        measured: m,
    };
    assert_eq!(Calibration::fit(&[]), Calibration::IDENTITY);
    let one = Calibration::fit(&[v(0, 2e-3, 1e-3)]);
    assert!((one.apply(4e-3) - 2e-3).abs() < 1e-12, "{one:?}");
    // Two points on m = 5e-4 + 0.25 p: the line through them.
    let two = Calibration::fit(&[v(0, 2e-3, 1e-3), v(1, 6e-3, 2e-3)]);
    assert!(
        (two.slope - 0.25).abs() < 1e-9 && (two.offset - 5e-4).abs() < 1e-12,
        "{two:?}"
    );
    // Ranked wrongly (higher prediction, lower measurement): flat at the worst measured.
    let flat = Calibration::fit(&[v(0, 2e-3, 3e-3), v(1, 6e-3, 1e-3)]);
    assert_eq!(flat.slope, 0.0);
    assert_eq!(flat.apply(1.0), 3e-3);
    // next_candidate: with everything calibrated under the budget, the cheapest.
    let p = vec![
        pred(0, 0.004, 0.8),
        pred(1, 0.0012, 1.0),
        pred(2, 0.0006, 1.3),
    ];
    let c = Calibration {
        offset: 0.0,
        slope: 0.1,
    };
    assert_eq!(next_candidate(&p, &[], &c, 0.001), Some(0));
    // Uncalibrated: only #2 is predicted within 80 % of the budget.
    assert_eq!(
        next_candidate(&p, &[], &Calibration::IDENTITY, 0.001),
        Some(2)
    );
    // Nothing predicted within: the most accurate.
    assert_eq!(
        next_candidate(&p, &[], &Calibration::IDENTITY, 1e-4),
        Some(2)
    );
}

fn pred(name_idx: usize, predicted: f64, cost: f64) -> Prediction {
    Prediction {
        config: Grid::quick().configs()[name_idx].clone(),
        predicted,
        relative_cost: cost,
    }
}

#[test]
fn chooser_takes_the_cheapest_within_budget_with_hysteresis() {
    let p = vec![
        pred(0, 0.004, 0.8),
        pred(1, 0.0012, 1.0),
        pred(2, 0.0006, 1.3),
        pred(3, 0.0002, 2.0),
    ];
    assert_eq!(cheapest_within(&p, 0.001).unwrap().relative_cost, 1.3);
    assert_eq!(cheapest_within(&p, 0.01).unwrap().relative_cost, 0.8);
    // Unreachable: the most accurate.
    assert_eq!(cheapest_within(&p, 1e-5).unwrap().relative_cost, 2.0);
    // Hysteresis (`keep_current`).
    let choice = |cost: f64| BudgetChoice {
        budget: 0.001,
        chosen: Prediction {
            relative_cost: cost,
            ..p[1].clone()
        },
        measured: Some(0.0005),
        met: true,
        verified: Vec::new(),
        current_measured: None,
        probes: 0,
        ms: 0.0,
    };
    assert!(
        keep_current(&choice(1.0), 1.2, 0.0008),
        "new one only 17 % cheaper: stay"
    );
    assert!(
        !keep_current(&choice(0.9), 1.2, 0.0008),
        "25 % cheaper: switch"
    );
    assert!(
        !keep_current(&choice(1.5), 1.2, 0.0012),
        "current over budget: switch"
    );
}
