//! A `sweep` folder in the report: per scene, GPU time against misclassified pixels (each
//! configuration averaged over the scene's views, log-log), its Pareto front drawn, and each
//! point's settings and images (what `sweep --images` saved) shown on a click.

use super::html::{esc, figure, table};
use super::scan::SweepRun;
use super::sections::{num, rel, value_text};
use super::ReportError;
use serde_json::Value;
use std::path::{Path, PathBuf};

/// Misclassified fractions below this are drawn at it (a log axis has no 0).
const Y_FLOOR: f64 = 1e-5;
/// Above this many points a chart embeds images for its Pareto front only.
const MAX_POINTS_WITH_IMAGES: usize = 200;
const PALETTE: [&str; 14] = [
    "#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b", "#e377c2",
    "#7f7f7f", "#bcbd22", "#000080", "#808000", "#00a080", "#a00060",
];
const W: f64 = 720.0;
const H: f64 = 420.0;
const M: (f64, f64, f64, f64) = (70.0, 40.0, 20.0, 50.0); // left, right, top, bottom

/// Where `sweep --images` keeps the lit image of one run: `DIR/images/SCENE/VIEW/CONFIG.png`,
/// each name reduced to letters, digits, `-`, `_` and `.`.
pub fn image_path(dir: &Path, scene: &str, view: &str, config: &str) -> PathBuf {
    let clean = |s: &str| -> String {
        let t: String = s
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || "-_.".contains(c) {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        t.trim_start_matches('.').to_string()
    };
    dir.join("images")
        .join(clean(scene))
        .join(clean(view))
        .join(format!("{}.png", clean(config)))
}

/// One configuration on one scene, averaged over its views.
struct Point<'a> {
    config: &'a str,
    first: &'a Value,
    views: Vec<&'a str>,
    gpu_ms: f64,
    misclassified: f64,
}

fn f(v: &Value, k: &str) -> f64 {
    v[k].as_f64().unwrap_or(f64::NAN)
}

/// The points of `scene`, in the order their configurations first appear.
fn points<'a>(rows: &'a [Value], scene: &str) -> Vec<Point<'a>> {
    let mut out: Vec<(Point<'a>, usize)> = Vec::new();
    for r in rows.iter().filter(|r| r["scene"] == scene) {
        let config = r["config"].as_str().unwrap_or("?");
        let view = r["view"].as_str().unwrap_or("?");
        match out.iter_mut().find(|(p, _)| p.config == config) {
            Some((p, n)) => {
                p.views.push(view);
                p.gpu_ms += f(r, "gpu_ms");
                p.misclassified += f(r, "misclassified");
                *n += 1;
            }
            None => out.push((
                Point {
                    config,
                    first: r,
                    views: vec![view],
                    gpu_ms: f(r, "gpu_ms"),
                    misclassified: f(r, "misclassified"),
                },
                1,
            )),
        }
    }
    out.into_iter()
        .map(|(mut p, n)| {
            p.gpu_ms /= n as f64;
            p.misclassified /= n as f64;
            p
        })
        .collect()
}

/// The indices of the points on the Pareto front (no other point is both faster and more
/// accurate), fastest first.
fn front(points: &[Point]) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..points.len())
        .filter(|&i| points[i].gpu_ms.is_finite() && points[i].misclassified.is_finite())
        .collect();
    idx.sort_by(|&a, &b| {
        (points[a].gpu_ms, points[a].misclassified)
            .partial_cmp(&(points[b].gpu_ms, points[b].misclassified))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    let mut best = f64::INFINITY;
    idx.into_iter()
        .filter(|&i| {
            let keep = points[i].misclassified < best;
            best = best.min(points[i].misclassified);
            keep
        })
        .collect()
}

/// A log axis over `lo..hi` mapped to `a..b` (pixels).
struct Axis {
    lo: f64,
    hi: f64,
    a: f64,
    b: f64,
}

impl Axis {
    fn new(values: impl Iterator<Item = f64>, floor: f64, a: f64, b: f64) -> Axis {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in values.filter(|v| v.is_finite()) {
            lo = lo.min(v.max(floor));
            hi = hi.max(v.max(floor));
        }
        if !lo.is_finite() {
            (lo, hi) = (floor.max(1e-3), 1.0);
        }
        let (lo, hi) = (
            lo.log10().floor(),
            hi.log10().ceil().max(lo.log10().floor() + 1.0),
        );
        Axis { lo, hi, a, b }
    }
    fn at(&self, v: f64, floor: f64) -> f64 {
        let t = (v.max(floor).log10() - self.lo) / (self.hi - self.lo);
        self.a + t * (self.b - self.a)
    }
    fn decades(&self) -> impl Iterator<Item = f64> {
        (self.lo as i32..=self.hi as i32).map(|e| 10f64.powi(e))
    }
}

/// The chart of one scene's points, each circle naming its details box.
fn chart(points: &[Point], on_front: &[usize], id: &str) -> String {
    let x = Axis::new(points.iter().map(|p| p.gpu_ms), 1e-3, M.0, W - M.1);
    let y = Axis::new(
        points.iter().map(|p| p.misclassified),
        Y_FLOOR,
        H - M.3,
        M.2,
    );
    let mut s = format!(
        "<svg class=\"pareto\" data-details=\"{id}-details\" width=\"{W}\" height=\"{H}\" \
         viewBox=\"0 0 {W} {H}\" xmlns=\"http://www.w3.org/2000/svg\" font-size=\"11\">"
    );
    for d in x.decades() {
        let px = x.at(d, 1e-3);
        s += &format!(
            "<line x1=\"{px:.1}\" y1=\"{}\" x2=\"{px:.1}\" y2=\"{}\" stroke=\"#ddd\"/>\
             <text x=\"{px:.1}\" y=\"{}\" text-anchor=\"middle\">{} ms</text>",
            M.2,
            H - M.3,
            H - M.3 + 15.0,
            decade(d)
        );
    }
    for d in y.decades() {
        let py = y.at(d, Y_FLOOR);
        s += &format!(
            "<line x1=\"{}\" y1=\"{py:.1}\" x2=\"{}\" y2=\"{py:.1}\" stroke=\"#ddd\"/>\
             <text x=\"{}\" y=\"{:.1}\" text-anchor=\"end\">{}</text>",
            M.0,
            W - M.1,
            M.0 - 4.0,
            py + 4.0,
            decade(d)
        );
    }
    s += &format!(
        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">GPU time per frame (shadow + camera pass)\
         </text><text transform=\"translate(14 {}) rotate(-90)\" text-anchor=\"middle\">\
         misclassified fraction (0 drawn at {Y_FLOOR:e})</text>",
        (M.0 + W - M.1) / 2.0,
        H - 8.0,
        (M.2 + H - M.3) / 2.0
    );
    let line: Vec<String> = on_front
        .iter()
        .map(|&i| {
            let p = &points[i];
            format!(
                "{:.1},{:.1}",
                x.at(p.gpu_ms, 1e-3),
                y.at(p.misclassified, Y_FLOOR)
            )
        })
        .collect();
    s += &format!(
        "<polyline points=\"{}\" fill=\"none\" stroke=\"#333\" stroke-dasharray=\"4 3\"/>",
        line.join(" ")
    );
    let methods = method_order(points);
    for (k, p) in points.iter().enumerate() {
        if !(p.gpu_ms.is_finite() && p.misclassified.is_finite()) {
            continue;
        }
        let m = methods.iter().position(|m| *m == method(p)).unwrap_or(0);
        s += &format!(
            "<circle data-point=\"{id}-p{k}\" cx=\"{:.1}\" cy=\"{:.1}\" r=\"5\" fill=\"{}\" \
             fill-opacity=\"0.8\"><title>{}: {} ms, {}</title></circle>",
            x.at(p.gpu_ms, 1e-3),
            y.at(p.misclassified, Y_FLOOR),
            PALETTE[m % PALETTE.len()],
            esc(p.config),
            num(p.gpu_ms),
            num(p.misclassified)
        );
    }
    s + "</svg>"
}

/// A power of ten as a tick label: `0.01`, `1`, `100`, `1e-5`.
fn decade(d: f64) -> String {
    let e = d.log10().round() as i32;
    if (-3..=4).contains(&e) {
        num(d)
    } else {
        format!("1e{e}")
    }
}

fn method(p: &Point) -> String {
    format!(
        "{} / {}",
        value_text(&p.first["method"]),
        value_text(&p.first["filter"])
    )
}

fn method_order(points: &[Point]) -> Vec<String> {
    let mut v: Vec<String> = Vec::new();
    for p in points {
        let m = method(p);
        if !v.contains(&m) {
            v.push(m);
        }
    }
    v
}

/// The settings and figures of one point, and its images where saved.
fn details(dir: &Path, scene: &str, p: &Point, images: bool) -> Result<String, ReportError> {
    let keys = [
        "method",
        "filter",
        "format",
        "bias",
        "map_texels",
        "shadow_views",
        "shadow_memory_mib",
    ];
    let mut rows: Vec<(String, String)> = vec![("configuration".into(), esc(p.config))];
    rows.extend(
        keys.iter()
            .map(|k| (k.to_string(), esc(&value_text(&p.first[*k])))),
    );
    rows.push((
        format!("GPU ms (mean of {} views)", p.views.len()),
        num(p.gpu_ms),
    ));
    rows.push(("misclassified (mean)".into(), num(p.misclassified)));
    rows.push(("device".into(), esc(&value_text(&p.first["device"]))));
    let mut s = table(&rows);
    let mut imgs = String::new();
    if images {
        for v in &p.views {
            let path = image_path(dir, scene, v, p.config);
            if path.is_file() {
                imgs += &figure(&path, v, "x")?;
            }
        }
    }
    s += &if imgs.is_empty() {
        "<p class=\"note\">no images (run the sweep with --images or --report)</p>".to_string()
    } else {
        format!("<div class=\"imgs\">{imgs}</div>")
    };
    Ok(s)
}

/// One sweep folder: a chart and details per scene.
pub(crate) fn sweep(root: &Path, n: usize, run: &SweepRun) -> Result<String, ReportError> {
    let mut scenes: Vec<&str> = Vec::new();
    for r in &run.rows {
        let s = r["scene"].as_str().unwrap_or("?");
        if !scenes.contains(&s) {
            scenes.push(s);
        }
    }
    let mut s = format!(
        "<article class=\"sweep\"><h3>{}: {} runs, {} scene(s)</h3>\
         <p class=\"note\">Click a point for its settings and images. Dashed: the Pareto front \
         (no configuration both faster and more accurate).</p>",
        esc(&rel(root, &run.dir)),
        run.rows.len(),
        scenes.len()
    );
    for (k, scene) in scenes.iter().enumerate() {
        let pts = points(&run.rows, scene);
        let on_front = front(&pts);
        let id = format!("sweep{n}-{k}");
        let methods = method_order(&pts);
        s += &format!("<h4>{}: {} configurations</h4>", esc(scene), pts.len());
        s += "<p class=\"legend\">";
        for (i, m) in methods.iter().enumerate() {
            s += &format!(
                "<span style=\"color:{}\">● {}</span>",
                PALETTE[i % PALETTE.len()],
                esc(m)
            );
        }
        s += "</p>";
        s += &chart(&pts, &on_front, &id);
        s += &format!("<div id=\"{id}-details\">");
        let all_images = pts.len() <= MAX_POINTS_WITH_IMAGES;
        for (i, p) in pts.iter().enumerate() {
            let images = all_images || on_front.contains(&i);
            s += &format!(
                "<div class=\"point\" id=\"{id}-p{i}\" hidden>{}</div>",
                details(&run.dir, scene, p, images)?
            );
        }
        s += "</div>";
    }
    Ok(s + "</article>")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(config: &str, view: &str, gpu: f64, mis: f64) -> Value {
        serde_json::json!({"scene": "s", "view": view, "config": config, "gpu_ms": gpu,
            "misclassified": mis, "method": "m", "filter": "f"})
    }

    #[test]
    fn points_average_over_views_and_the_front_keeps_the_undominated() {
        let rows = vec![
            row("a", "v1", 1.0, 0.10),
            row("a", "v2", 3.0, 0.30), // a: 2 ms, 0.2
            row("b", "v1", 4.0, 0.01), // b: 4 ms, 0.01
            row("c", "v1", 5.0, 0.05), // c: dominated by b
            row("d", "v1", 1.0, 0.50), // d: fastest
        ];
        let p = points(&rows, "s");
        assert_eq!(p.len(), 4);
        assert_eq!((p[0].gpu_ms, p[0].misclassified), (2.0, 0.2));
        assert_eq!(p[0].views, ["v1", "v2"]);
        let names: Vec<&str> = front(&p).iter().map(|&i| p[i].config).collect();
        assert_eq!(names, ["d", "a", "b"]);
    }

    #[test]
    fn image_paths_stay_inside_the_folder() {
        let p = image_path(Path::new("out"), "../up", "v/1", "pcf 3x3");
        assert_eq!(p, Path::new("out/images/_up/v_1/pcf_3x3.png"));
    }
}
