//! Choosing: candidates verified by rendering them at the probes, the choice kept or changed.

use super::*;
use crate::reference::ReferenceScene;
use umbra::plan::{ScenePlanner, View};
use umbra::scene::Scene;

/// Most candidates rendered to verify a choice.
pub const MAX_VERIFIED: usize = 5;
/// How far over the budget a cheaper candidate's rescaled prediction may be and still be tried.
pub const EXPLORE_FACTOR: f64 = 2.0;
/// The search aims a candidate's rescaled prediction at this fraction of the budget.
pub const SEARCH_MARGIN: f64 = 0.8;

/// A candidate rendered and measured at the probes.
#[derive(Clone, Debug, PartialEq)]
pub struct Verified {
    /// The candidate and its (unscaled) prediction.
    pub prediction: Prediction,
    /// Misclassified fraction measured at the probes.
    pub measured: f64,
}

/// What `choose` decided.
#[derive(Clone, Debug)]
pub struct BudgetChoice {
    /// The budget (fraction).
    pub budget: f64,
    /// The chosen candidate.
    pub chosen: Prediction,
    /// Its misclassification measured at the probes, when it was rendered.
    pub measured: Option<f64>,
    /// Whether the chosen candidate's measurement (or, unverified, its prediction) is within
    /// the budget.
    pub met: bool,
    /// Every candidate rendered, in order.
    pub verified: Vec<Verified>,
    /// The misclassification of the running configuration passed to `choose`, if any.
    pub current_measured: Option<f64>,
    /// Probe rays cast.
    pub probes: usize,
    /// Time the choice took (ms), probe and renders included.
    pub ms: f64,
}

/// Measures `c`'s misclassification at the probes with one render (shadow view and depth).
pub fn measure(
    renderer: &mut umbra::render::Renderer,
    probe: &ViewProbe,
    view: &View,
    c: &crate::analysis::grid::Config,
) -> Result<f64, umbra::gpu::GpuError> {
    let mut v = view.clone();
    v.shadow = c.shadow;
    v.mode = umbra::plan::ViewMode::Shadow;
    renderer.set_read_depth(true);
    let f = renderer.render(&v, probe.width, probe.height);
    renderer.set_read_depth(false);
    let f = f?;
    let depth = f.depth.as_deref().unwrap_or(&[]);
    Ok(misclassified_at_probes(probe, &f.image, depth, &f.plan).0)
}

/// This view's correction of the model, from the candidates measured so far: measured ≈
/// `offset + slope · predicted`. One measurement: a pure scale. Two or more with predictions
/// apart: least squares; a negative slope (the model ranks them wrongly here) becomes a flat
/// line at the largest measurement.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Calibration {
    /// Added.
    pub offset: f64,
    /// Multiplies the prediction.
    pub slope: f64,
}

impl Calibration {
    /// No correction.
    pub const IDENTITY: Calibration = Calibration {
        offset: 0.0,
        slope: 1.0,
    };

    /// Fitted to `verified`.
    pub fn fit(verified: &[Verified]) -> Self {
        let pts: Vec<(f64, f64)> = verified
            .iter()
            .map(|v| (v.prediction.predicted, v.measured))
            .collect();
        let Some(&(p0, m0)) = pts.last() else {
            return Self::IDENTITY;
        };
        let n = pts.len() as f64;
        let (mp, mm) = (
            pts.iter().map(|p| p.0).sum::<f64>() / n,
            pts.iter().map(|p| p.1).sum::<f64>() / n,
        );
        let var = pts.iter().map(|p| (p.0 - mp).powi(2)).sum::<f64>();
        if pts.len() < 2 || var <= (0.05 * mp).powi(2) {
            return Self {
                offset: 0.0,
                slope: if p0 > 0.0 {
                    (m0 / p0).clamp(0.02, 50.0)
                } else {
                    1.0
                },
            };
        }
        let slope = pts.iter().map(|p| (p.0 - mp) * (p.1 - mm)).sum::<f64>() / var;
        if slope <= 0.0 {
            let top = pts.iter().map(|p| p.1).fold(0.0, f64::max);
            return Self {
                offset: top,
                slope: 0.0,
            };
        }
        Self {
            offset: mm - slope * mp,
            slope,
        }
    }

    /// The corrected prediction.
    pub fn apply(&self, predicted: f64) -> f64 {
        (self.offset + self.slope * predicted).max(0.0)
    }
}

/// The next candidate to render, or None to stop. With `q` the calibrated prediction and only
/// candidates cheaper than the best one measured within budget: the cheapest with `q` within
/// `SEARCH_MARGIN` of the budget; else the cheapest with `q` within the budget; else, once one
/// is within budget, the most accurate with `q` within `EXPLORE_FACTOR` × the budget (the model
/// ranks configurations of one view imperfectly); before any is within budget and none is
/// predicted to be, the most accurate unverified candidate.
pub fn next_candidate(
    predictions: &[Prediction],
    verified: &[Verified],
    cal: &Calibration,
    budget: f64,
) -> Option<usize> {
    let is_verified = |p: &Prediction| verified.iter().any(|v| v.prediction.config == p.config);
    let best_ok = verified
        .iter()
        .filter(|v| v.measured <= budget)
        .map(|v| v.prediction.relative_cost)
        .fold(f64::INFINITY, f64::min);
    let open = || {
        predictions
            .iter()
            .enumerate()
            .filter(|(_, p)| !is_verified(p) && p.relative_cost < best_ok)
    };
    let cheapest_under = |limit: f64| {
        open()
            .filter(|(_, p)| cal.apply(p.predicted) <= limit)
            .min_by(|a, b| a.1.relative_cost.total_cmp(&b.1.relative_cost))
            .map(|(i, _)| i)
    };
    let most_accurate = |limit: f64| {
        open()
            .filter(|(_, p)| cal.apply(p.predicted) <= limit)
            .min_by(|a, b| {
                a.1.predicted
                    .total_cmp(&b.1.predicted)
                    .then(a.1.relative_cost.total_cmp(&b.1.relative_cost))
            })
            .map(|(i, _)| i)
    };
    cheapest_under(budget * SEARCH_MARGIN)
        .or_else(|| cheapest_under(budget))
        .or_else(|| {
            if best_ok.is_finite() {
                most_accurate(budget * EXPLORE_FACTOR)
            } else {
                most_accurate(f64::INFINITY)
            }
        })
}

/// This view's GPU (camera, shadow) milliseconds under the default configuration (the second
/// of two frames: the first may compile pipelines or allocate the map).
fn base_split(
    renderer: &mut umbra::render::Renderer,
    view: &View,
    (w, h): (u32, u32),
) -> Result<Option<(f64, f64)>, umbra::gpu::GpuError> {
    let base = crate::analysis::grid::Grid::full()
        .configs()
        .into_iter()
        .find(|c| c.name() == COST_BASE);
    let mut base_ms = None;
    if let Some(b) = base {
        let mut v = view.clone();
        v.shadow = b.shadow;
        renderer.render(&v, w, h)?;
        let st = renderer.render(&v, w, h)?.stats;
        base_ms = st.gpu_camera_ms.zip(st.gpu_shadow_ms);
    }
    Ok(base_ms)
}

/// The choice among the verified candidates: the cheapest within `budget` (`ok`); failing that,
/// the most accurate measured, or without measurements the cheapest predicted within it. With
/// the measured error, if any, and whether the budget is met.
fn pick(
    ok: Option<&Verified>,
    verified: &[Verified],
    preds: &[Prediction],
    budget: f64,
) -> (Prediction, Option<f64>, bool) {
    match ok {
        Some(v) => (v.prediction.clone(), Some(v.measured), true),
        None => {
            // Not reachable within the renders: the most accurate measured (or predicted).
            match verified
                .iter()
                .min_by(|a, b| a.measured.total_cmp(&b.measured))
            {
                Some(v) => (v.prediction.clone(), Some(v.measured), false),
                None => {
                    let p = cheapest_within(preds, budget)
                        .cloned()
                        .unwrap_or_else(|| preds[0].clone());
                    let met = p.predicted <= budget;
                    (p, None, met)
                }
            }
        }
    }
}

/// Chooses the cheapest configuration for `view` whose misclassification is within `budget`
/// (module documentation: probe, predict, verify); with `current`, the running configuration is
/// measured too (`BudgetChoice::current_measured`, for `keep_current`). `None` when no candidate
/// applies (no light casts a shadow).
pub fn choose(
    renderer: &mut umbra::render::Renderer,
    reference: &ReferenceScene,
    scene: &Scene,
    view: &View,
    (w, h): (u32, u32),
    budget: f64,
    current: Option<&crate::analysis::grid::Config>,
) -> Result<Option<BudgetChoice>, umbra::gpu::GpuError> {
    let t0 = std::time::Instant::now();
    let planner = ScenePlanner::new(scene);
    let probe = probe_view(reference, &planner, view, w, h, PROBE_STRIDE);
    let base_ms = base_split(renderer, view, (w, h))?;
    let preds = predict_all(&probe, &planner, view, base_ms);
    if preds.is_empty() {
        return Ok(None);
    }
    let mut verified: Vec<Verified> = Vec::new();
    let mut cal = Calibration::IDENTITY;
    while verified.len() < MAX_VERIFIED {
        let Some(i) = next_candidate(&preds, &verified, &cal, budget) else {
            break;
        };
        let m = measure(renderer, &probe, view, &preds[i].config)?;
        log::debug!(
            "budget {budget:e}: tried {} (cost {:.2}, predicted {:.2e}, calibrated {:.2e}) measured {m:.2e}",
            preds[i].config.name(),
            preds[i].relative_cost,
            preds[i].predicted,
            cal.apply(preds[i].predicted)
        );
        verified.push(Verified {
            prediction: preds[i].clone(),
            measured: m,
        });
        cal = Calibration::fit(&verified);
    }
    let ok = verified
        .iter()
        .filter(|v| v.measured <= budget)
        .min_by(|a, b| {
            a.prediction
                .relative_cost
                .total_cmp(&b.prediction.relative_cost)
        });
    let (chosen, measured, met) = pick(ok, &verified, &preds, budget);
    // The running configuration (the viewer's), measured with the same probe.
    let current_measured = match current {
        None => None,
        Some(c) => match verified.iter().find(|v| &v.prediction.config == c) {
            Some(v) => Some(v.measured),
            None => Some(measure(renderer, &probe, view, c)?),
        },
    };
    Ok(Some(BudgetChoice {
        budget,
        chosen,
        measured,
        met,
        verified,
        current_measured,
        probes: probe.probes.len(),
        ms: t0.elapsed().as_secs_f64() * 1e3,
    }))
}

/// The budget mode checked on one view against its sweep.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct CheckRow {
    /// Scene.
    pub scene: String,
    /// View.
    pub view: String,
    /// Budget (fraction).
    pub budget: f64,
    /// Chosen configuration.
    pub chosen: String,
    /// Its prediction before verification.
    pub predicted: f64,
    /// Misclassification of the chosen configuration by `reference::compare` (full image).
    pub measured: f64,
    /// Whether `measured` ≤ `budget`.
    pub within_budget: bool,
    /// The chosen configuration's GPU ms in the sweep.
    pub chosen_sweep_gpu_ms: f64,
    /// The cheapest configuration of the sweep that meets the budget ("" if none).
    pub cheapest: String,
    /// Its GPU ms in the sweep.
    pub cheapest_gpu_ms: f64,
    /// chosen / cheapest GPU time (sweep figures).
    pub time_ratio: f64,
    /// The same with both times from `denoised_ms` (and the cheapest within budget by those).
    pub denoised_time_ratio: f64,
    /// Renders the choice took.
    pub renders: usize,
    /// Time the choice took (ms).
    pub choose_ms: f64,
}

/// Runs the budget mode on `camera`'s view (named `view_name`) at `w`×`h` and checks it against
/// that view's sweep rows: the chosen configuration's full-image misclassification
/// (`reference::compare`) and its GPU time against the cheapest swept configuration within the
/// budget.
pub fn check_view(
    renderer: &mut umbra::render::Renderer,
    reference: &ReferenceScene,
    scene: &Scene,
    (view_name, camera): (&str, umbra::scene::Camera),
    (w, h): (u32, u32),
    budget: f64,
    rows: &[crate::analysis::sweep::Row],
) -> Result<Option<CheckRow>, umbra::gpu::GpuError> {
    let view = View::new(camera);
    let Some(c) = choose(renderer, reference, scene, &view, (w, h), budget, None)? else {
        return Ok(None);
    };
    let mut v = view.clone();
    v.shadow = c.chosen.config.shadow;
    let m = crate::score::score(renderer, reference, &v, (w, h), &mut None)?.metrics;
    let of: Vec<&crate::analysis::sweep::Row> = rows
        .iter()
        .filter(|r| r.scene == scene.name && r.view == view_name)
        .collect();
    let name = c.chosen.config.name();
    let chosen_ms = of
        .iter()
        .find(|r| r.config == name)
        .map_or(f64::NAN, |r| r.gpu_ms);
    let cheapest = of
        .iter()
        .filter(|r| r.misclassified <= budget)
        .min_by(|a, b| a.gpu_ms.total_cmp(&b.gpu_ms));
    Ok(Some(CheckRow {
        scene: scene.name.clone(),
        view: view_name.into(),
        budget,
        chosen: name.clone(),
        predicted: c.chosen.predicted,
        measured: m.misclassified,
        within_budget: m.misclassified <= budget,
        chosen_sweep_gpu_ms: chosen_ms,
        cheapest: cheapest.map(|r| r.config.clone()).unwrap_or_default(),
        cheapest_gpu_ms: cheapest.map_or(f64::NAN, |r| r.gpu_ms),
        time_ratio: cheapest.map_or(f64::NAN, |r| chosen_ms / r.gpu_ms),
        denoised_time_ratio: {
            let est = denoised_ms(&of);
            let ms = |n: &str| {
                est.iter()
                    .find(|e| e.0 == n)
                    .map_or(f64::NAN, |e| e.1 + e.2)
            };
            let best = of
                .iter()
                .filter(|r| r.misclassified <= budget)
                .map(|r| ms(&r.config))
                .fold(f64::INFINITY, f64::min);
            ms(&name) / best
        },
        renders: c.verified.len(),
        choose_ms: c.ms,
    }))
}
