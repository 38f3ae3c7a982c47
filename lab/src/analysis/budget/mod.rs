//! Shadow settings chosen for an error budget.
//!
//! No sweep at render time. The chooser works in three cheap steps:
//!
//! 1. **Probe**: the exact visibility is ray-cast at every pixel (`PROBE_STRIDE`; 0.92 M rays at
//!    1280×720, a primary and a shadow ray each, a few hundred ms on two cores), which finds the
//!    view's shadow boundaries and how long they are on screen.
//! 2. **Predict**: misclassified pixels sit in a band along those boundaries whose width grows
//!    with the shadow texel's size in pixels there (ρ = texel world size / pixel footprint, at the
//!    cascade covering that depth). For each candidate configuration
//!    `e = a_f · Σ ℓ·ρ / N + b_f · Σ ℓ / N + c_f`, summed over boundary crossings between
//!    neighbouring probes (ℓ = π·s/4 pixels of boundary per crossing at spacing s, by
//!    Cauchy–Crofton), N the pixels that see a surface, (a_f, b_f, c_f) fitted per filter to
//!    sweeps of training scenes (`model::MODEL`, by `umbra sweep --fit-budget`). Each candidate's
//!    cost is its GPU time relative to the default configuration on those sweeps
//!    (`model::COSTS`).
//! 3. **Verify**: the cheapest candidate predicted within the budget is rendered once (shadow
//!    view and depth) and its misclassification measured at the probes (with a probe at every
//!    pixel this is exactly `reference::compare`'s measure). The measurements so far correct
//!    every prediction for this view (`Calibration`: a scale, then a line through them), and the
//!    search moves to a cheaper or a more accurate candidate accordingly; at most
//!    `MAX_VERIFIED` renders. The choice is the cheapest verified candidate measured within the
//!    budget, so the budget holds by measurement, not only by the model.

pub use super::coeffs::Coeffs;
mod choose;
mod fit;

pub use choose::*;
pub use fit::*;

use crate::reference::{Probe, ReferenceScene};
use glam::Vec3;
use umbra::plan::{FramePlan, ScenePlanner, ShadowSettings, View};
use umbra::scene::{LightKind, Scene};

/// Probes every this many pixels in x and y. 1: every pixel, so a verified candidate's
/// measurement is exactly what `reference::compare` measures. (Measured on the town from eye
/// height: every 2nd pixel, a quarter of the rays, put 512² with 4 cascades at 0.093 % where the
/// whole image has 0.114 %: thin error lines alias with a regular grid.)
pub const PROBE_STRIDE: u32 = 1;

/// The exact-visibility probe of one view.
#[derive(Clone, Debug)]
pub struct ViewProbe {
    /// Probes per row.
    pub cols: u32,
    /// Rows of probes.
    pub rows: u32,
    /// Spacing in pixels.
    pub stride: u32,
    /// Row-major probes (`None` where the ray hits nothing), at pixel centres
    /// (i·stride + stride/2, j·stride + stride/2).
    pub probes: Vec<Option<Probe>>,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

impl ViewProbe {
    /// The pixel of probe (i, j).
    pub fn pixel(&self, i: u32, j: u32) -> (u32, u32) {
        (
            (i * self.stride + self.stride / 2).min(self.width - 1),
            (j * self.stride + self.stride / 2).min(self.height - 1),
        )
    }
}

/// Boundary terms of one candidate's prediction (see the module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Features {
    /// Σ ℓ·ρ / N.
    pub texel_term: f64,
    /// Σ ℓ / N: boundary pixels per visible pixel.
    pub edge_term: f64,
}

/// The plan the renderer would make for `view` with `shadow` instead of its own settings.
fn plan_with(
    planner: &ScenePlanner,
    view: &View,
    shadow: ShadowSettings,
    w: u32,
    h: u32,
) -> FramePlan {
    let mut v = view.clone();
    v.shadow = shadow;
    planner.plan(&v, w, h)
}

/// Ray-casts the exact visibility at every `stride`-th pixel centre of `view`.
pub fn probe_view(
    reference: &ReferenceScene,
    planner: &ScenePlanner,
    view: &View,
    w: u32,
    h: u32,
    stride: u32,
) -> ViewProbe {
    let plan = planner.plan(view, w, h);
    let stride = stride.max(1);
    let mut probe = ViewProbe {
        cols: w.div_ceil(stride),
        rows: h.div_ceil(stride),
        stride,
        probes: Vec::new(),
        width: w,
        height: h,
    };
    let pixels: Vec<(f32, f32)> = (0..probe.rows)
        .flat_map(|j| (0..probe.cols).map(move |i| (i, j)))
        .map(|(i, j)| {
            let (x, y) = probe.pixel(i, j);
            (x as f32 + 0.5, y as f32 + 0.5)
        })
        .collect();
    probe.probes = reference.probe(&plan, &pixels, w, h);
    probe
}

/// Misclassified fraction of a GPU frame at the probes: its shadow view (`gpu_shadow`, lit at
/// ≥ 128) against the exact visibility, judged where the GPU depth (`depth`, of `plan`) and the
/// probe see the same surface (distances within 1 %, as `reference::compare`). Also returns the
/// probes judged.
pub fn misclassified_at_probes(
    probe: &ViewProbe,
    gpu_shadow: &image::RgbaImage,
    depth: &[f32],
    plan: &FramePlan,
) -> (f64, usize) {
    let inv = plan.clip_from_world.inverse();
    let (w, h) = (probe.width, probe.height);
    let (mut judged, mut wrong) = (0usize, 0usize);
    for j in 0..probe.rows {
        for i in 0..probe.cols {
            let Some(p) = probe.probes[(j * probe.cols + i) as usize].filter(|p| !p.coincident)
            else {
                continue;
            };
            let (x, y) = probe.pixel(i, j);
            let d = depth.get((y * w + x) as usize).copied().unwrap_or(0.0);
            if d <= 0.0 {
                continue;
            }
            let n = umbra::math::projection::pixel_to_ndc(x as f32 + 0.5, y as f32 + 0.5, w, h);
            let q = inv * glam::Vec4::new(n.x, n.y, d, 1.0);
            let dist = (q.truncate() / q.w).distance(plan.camera_position);
            if (dist - p.distance).abs() > 0.01 * p.distance + 1e-4 {
                continue;
            }
            judged += 1;
            let lit = gpu_shadow.get_pixel(x, y)[0] >= 128;
            wrong += (lit != p.visible) as usize;
        }
    }
    (
        if judged == 0 {
            0.0
        } else {
            wrong as f64 / judged as f64
        },
        judged,
    )
}

/// The boundary terms for a candidate's `plan` of the probed view.
pub fn features(probe: &ViewProbe, plan: &FramePlan, view: &View) -> Features {
    let Some(light) = plan.shadow_light.map(|i| plan.lights[i]) else {
        return Features::default();
    };
    let views = plan.primary_views();
    if views.is_empty() {
        return Features::default();
    }
    let eye = view.camera.position();
    let forward = -view
        .camera
        .world_from_view
        .z_axis
        .truncate()
        .normalize_or(Vec3::NEG_Z);
    // A pixel's footprint at distance d: d × its angle, or under an orthographic camera the same
    // at every distance.
    let rows = probe.height.max(1) as f32;
    let pixel_at = |d: f32| 2.0 * view.camera.half_extent_at(d, 1.0).y / rows;
    let rho = |p: &Probe| -> f64 {
        let depth = (p.position - eye).dot(forward);
        let k = views
            .iter()
            .position(|v| depth <= v.far)
            .unwrap_or(views.len() - 1);
        let tw = views[k].texel_world;
        let texel = match light.kind {
            LightKind::Directional => tw,
            _ => tw * (p.position - light.position).length(),
        };
        (texel / pixel_at(p.distance).max(f32::MIN_POSITIVE)) as f64
    };
    // A depth tie's verdict is either face's: no boundary runs through it.
    let at = |i: u32, j: u32| probe.probes[(j * probe.cols + i) as usize].filter(|p| !p.coincident);
    let ell = std::f64::consts::FRAC_PI_4 * probe.stride as f64;
    let (mut texel_sum, mut edge_sum, mut seen) = (0.0f64, 0.0f64, 0usize);
    for j in 0..probe.rows {
        for i in 0..probe.cols {
            let Some(a) = at(i, j) else { continue };
            seen += 1;
            for (ni, nj) in [(i + 1, j), (i, j + 1)] {
                if ni >= probe.cols || nj >= probe.rows {
                    continue;
                }
                if let Some(b) = at(ni, nj) {
                    if a.visible != b.visible {
                        texel_sum += ell * 0.5 * (rho(&a) + rho(&b));
                        edge_sum += ell;
                    }
                }
            }
        }
    }
    let n = seen as f64 * (probe.stride as f64).powi(2);
    if n == 0.0 {
        return Features::default();
    }
    Features {
        texel_term: texel_sum / n,
        edge_term: edge_sum / n,
    }
}

/// A sweep row joined with its prediction terms (the budget model's training data).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct FeatureRow {
    /// Scene.
    pub scene: String,
    /// View.
    pub view: String,
    /// Configuration name.
    pub config: String,
    /// Filter name.
    pub filter: String,
    /// Fitting method.
    pub method: String,
    /// Map side.
    pub map_texels: u32,
    /// Σ ℓ·ρ / N.
    pub texel_term: f64,
    /// Σ ℓ / N.
    pub edge_term: f64,
    /// Measured misclassified fraction.
    pub misclassified: f64,
    /// Measured GPU ms.
    pub gpu_ms: f64,
}

/// The prediction terms of every row of `rows` that belongs to `scene` (views by name from
/// `views`, configurations by name from `configs`).
pub fn feature_rows(
    reference: &ReferenceScene,
    scene: &Scene,
    views: &[(String, umbra::scene::Camera)],
    configs: &[super::grid::Config],
    rows: &[super::sweep::Row],
) -> Vec<FeatureRow> {
    let planner = ScenePlanner::new(scene);
    let mut out = Vec::new();
    for (name, camera) in views {
        let of: Vec<&super::sweep::Row> = rows
            .iter()
            .filter(|r| r.scene == scene.name && &r.view == name)
            .collect();
        let Some(first) = of.first() else { continue };
        let (w, h) = (first.width_px, first.height_px);
        let view = View::new(*camera);
        let probe = probe_view(reference, &planner, &view, w, h, PROBE_STRIDE);
        for r in of {
            let Some(c) = configs.iter().find(|c| c.name() == r.config) else {
                continue;
            };
            let plan = plan_with(&planner, &view, c.shadow, w, h);
            let f = features(&probe, &plan, &view);
            out.push(FeatureRow {
                scene: r.scene.clone(),
                view: r.view.clone(),
                config: r.config.clone(),
                filter: r.filter.clone(),
                method: r.method.clone(),
                map_texels: r.map_texels,
                texel_term: f.texel_term,
                edge_term: f.edge_term,
                misclassified: r.misclassified,
                gpu_ms: r.gpu_ms,
            });
        }
    }
    out
}

/// A candidate's prediction for one view.
#[derive(Clone, Debug, PartialEq)]
pub struct Prediction {
    /// The configuration.
    pub config: super::grid::Config,
    /// Predicted misclassified fraction.
    pub predicted: f64,
    /// GPU time relative to the default configuration (`COSTS`).
    pub relative_cost: f64,
}

/// The prediction of `f` under `coeffs`.
pub fn predict(coeffs: &Coeffs, f: &Features) -> f64 {
    coeffs.a * f.texel_term + coeffs.b * f.edge_term + coeffs.c
}

/// Predicts every candidate (`COSTS`, whose filters have `MODEL` coefficients) for the probed
/// view. `base_ms` = (camera pass, shadow pass) of `COST_BASE` measured in this view weighs the
/// stored per-pass cost ratios into one relative cost (a scene heavy in casters pays more for
/// larger maps); without it the passes weigh 4:1.
pub fn predict_all(
    probe: &ViewProbe,
    planner: &ScenePlanner,
    view: &View,
    base_ms: Option<(f64, f64)>,
) -> Vec<Prediction> {
    let (w, h) = (probe.width, probe.height);
    let configs: std::collections::HashMap<String, super::grid::Config> = super::grid::Grid::full()
        .configs()
        .into_iter()
        .map(|c| (c.name(), c))
        .collect();
    let (bc, bs) = base_ms.unwrap_or((4.0, 1.0));
    let mut out = Vec::new();
    for (name, cam, shadow) in super::model::COSTS {
        let cost = (bc * cam + bs * shadow) / (bc + bs);
        let Some(c) = configs.get(name) else {
            continue;
        };
        let Some(k) = super::model::MODEL
            .iter()
            .find(|k| k.filter == super::grid::filter_name(c.shadow.pcf))
        else {
            continue;
        };
        let plan = plan_with(planner, view, c.shadow, w, h);
        let f = features(probe, &plan, view);
        out.push(Prediction {
            config: c.clone(),
            predicted: predict(k, &f),
            relative_cost: cost,
        });
    }
    // Exact and hybrid shadows: nothing to predict but the residue on exact shadow edges, at
    // their cost (the chooser takes the cheaper).
    if !out.is_empty() {
        for (config, (cam, shadow)) in [
            (super::grid::Config::exact(EXACT_MAP), EXACT_COST),
            (super::grid::Config::hybrid(EXACT_MAP), HYBRID_COST),
        ] {
            out.push(Prediction {
                config,
                predicted: 0.0,
                relative_cost: (bc * cam + bs * shadow) / (bc + bs),
            });
        }
    }
    out
}

/// The map size of the exact candidate (read only where the exact pass does not judge).
pub const EXACT_MAP: u32 = 2048;

/// The exact candidate's camera-pass and shadow-pass time (exact pass included) relative to
/// `COST_BASE`'s: geometric means over the demo, foliage, close-up and FlightHelmet + ground
/// sweeps' first views (`umbra sweep demo foliage close-up FlightHelmet.gltf --ground --quick
/// --exact --views 1`, lavapipe, 1280×720; camera 1.04, 1.14, 1.81, 1.40; shadow 69, 30, 41, 66).
pub const EXACT_COST: (f64, f64) = (1.32, 48.6);

/// The hybrid candidate's, measured as `EXACT_COST` (with `--exact`, which sweeps both, at a
/// 4096² map): camera 1.17, 1.16, 1.17, 1.00; shadow 83.3, 52.1, 32.3, 64.9 (exact in the same
/// run: 1.18 and 43.5 as geometric means). Dearer than exact at this map size: its thin-caster
/// pass marks every texel a leaf card covers.
pub const HYBRID_COST: (f64, f64) = (1.12, 54.9);

/// The cheapest prediction within `budget` (a fraction), else the most accurate one.
pub fn cheapest_within(predictions: &[Prediction], budget: f64) -> Option<&Prediction> {
    predictions
        .iter()
        .filter(|p| p.predicted <= budget)
        .min_by(|a, b| a.relative_cost.total_cmp(&b.relative_cost))
        .or_else(|| {
            predictions
                .iter()
                .min_by(|a, b| a.predicted.total_cmp(&b.predicted))
        })
}

/// A running choice (the viewer's) moves only to a candidate at most this fraction of its cost;
/// otherwise it stays while it measures within the budget (no flicker between two candidates
/// near the budget).
pub const SWITCH_COST_RATIO: f64 = 0.8;

/// Whether a running choice should stay after `new` was chosen for the current view: when the
/// running one measures within the budget here and `new` is not clearly cheaper.
pub fn keep_current(new: &BudgetChoice, current_cost: f64, current_measured: f64) -> bool {
    current_measured <= new.budget && new.chosen.relative_cost > SWITCH_COST_RATIO * current_cost
}

#[cfg(test)]
mod tests;
