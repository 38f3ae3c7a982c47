//! The speed/accuracy chart: every configuration as a point (x: GPU ms per frame, y:
//! misclassified fraction, both log scales), coloured by fitting method, shaped by filter, with
//! the Pareto front drawn and its points labelled. SVG and PNG (plotters; text in the PNG drawn
//! with the embedded DejaVu Sans, so no system font is needed).

use super::pareto::pareto_front;
use super::sweep::Row;

use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Misclassification drawn for configurations with none (log axes cannot show 0).
pub const ZERO_ERROR_FLOOR: f64 = 1e-6;

/// Chart size in pixels.
pub const SIZE: (u32, u32) = (1100, 720);

const METHODS: [(&str, RGBColor); 8] = [
    ("scene", RGBColor(150, 150, 150)),
    ("camera", RGBColor(31, 119, 180)),
    ("cascades2", RGBColor(44, 160, 44)),
    ("cascades4", RGBColor(214, 39, 40)),
    ("auto", RGBColor(148, 103, 189)),
    ("sdsm4", RGBColor(255, 127, 14)),
    ("exact", RGBColor(0, 0, 0)),
    ("hybrid", RGBColor(190, 30, 160)),
];

/// A chart that could not be drawn or written.
#[derive(Debug, thiserror::Error)]
#[error("chart {path}: {message}")]
pub struct ChartError {
    /// The file.
    pub path: String,
    /// What went wrong.
    pub message: String,
}

fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            dejavu::sans::regular(),
        );
    });
}

/// A configuration's short label: map size, filter, fitting, and format and bias when not the
/// defaults (`2048 pcf2x2 cascades4`, `4096 nearest scene d16 bias:low`); `exact` and `hybrid`
/// for exact and hybrid shadows (whose map only the pixels they do not trace read).
fn label(map: u32, filter: &str, method: &str, format: &str, bias: &str) -> String {
    if method == "exact" || method == "hybrid" {
        return method.into();
    }
    let mut s = format!("{map} {filter} {method}");
    if format != "d32" {
        s.push_str(&format!(" {format}"));
    }
    if bias != "default" {
        s.push_str(&format!(" bias:{bias}"));
    }
    s
}

/// The label of a sweep row's configuration (the chart's front points).
pub fn short_label(r: &Row) -> String {
    label(r.map_texels, &r.filter, &r.method, &r.format, &r.bias)
}

/// The same label for a configuration.
pub fn short_label_of(c: &super::grid::Config) -> String {
    label(
        c.shadow.map_size,
        c.filter(),
        &c.method(),
        super::grid::format_name(c.shadow.format),
        c.bias,
    )
}

/// Tick values 1, 2, 5 × 10ⁿ within [lo, hi]; a finer 1, 1.5, 2, 3, 4, 5, 7 sequence where that
/// gives fewer than four.
pub fn ticks_125(lo: f64, hi: f64) -> Vec<f64> {
    let coarse = ticks_with(lo, hi, &[1.0, 2.0, 5.0]);
    if coarse.len() >= 4 {
        coarse
    } else {
        ticks_with(lo, hi, &[1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 7.0])
    }
}

fn ticks_with(lo: f64, hi: f64, mantissas: &[f64]) -> Vec<f64> {
    let mut out = Vec::new();
    if !(lo > 0.0 && hi >= lo && hi.is_finite()) {
        return out;
    }
    let mut e = lo.log10().floor() as i32;
    while 10f64.powi(e) <= hi {
        for &m in mantissas {
            let v = m * 10f64.powi(e);
            if v >= lo && v <= hi {
                out.push(v);
            }
        }
        e += 1;
    }
    out
}

fn y_of(r: &Row) -> f64 {
    r.misclassified.max(ZERO_ERROR_FLOOR)
}

/// The axes' ranges for `pts` on log scales: GPU time widened by 15 % each way, the error
/// halved and doubled (at most 1); defaults where no value is finite and positive.
fn log_ranges(pts: &[(f64, f64)]) -> ((f64, f64), (f64, f64)) {
    let finite = |v: f64| v.is_finite() && v > 0.0;
    let xs: Vec<f64> = pts.iter().map(|p| p.0).filter(|v| finite(*v)).collect();
    let ys: Vec<f64> = pts.iter().map(|p| p.1).filter(|v| finite(*v)).collect();
    let (x0, x1) = (
        xs.iter().copied().fold(f64::INFINITY, f64::min),
        xs.iter().copied().fold(0.0, f64::max),
    );
    let (y0, y1) = (
        ys.iter().copied().fold(f64::INFINITY, f64::min),
        ys.iter().copied().fold(0.0, f64::max),
    );
    let (x0, x1) = if x0.is_finite() {
        (x0 / 1.15, x1 * 1.15)
    } else {
        (1.0, 10.0)
    };
    let (y0, y1) = if y0.is_finite() {
        (y0 / 2.0, (y1 * 2.0).min(1.0))
    } else {
        (1e-6, 1.0)
    };
    ((x0, x1), (y0, y1))
}

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    rows: &[Row],
    title: &str,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    root.fill(&WHITE).map_err(e)?;
    let pts: Vec<(f64, f64)> = rows.iter().map(|r| (r.gpu_ms, y_of(r))).collect();
    let ((x0, x1), (y0, y1)) = log_ranges(&pts);
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 22))
        .margin(14)
        .x_label_area_size(48)
        .y_label_area_size(80)
        .build_cartesian_2d(
            (x0..x1).log_scale().with_key_points(ticks_125(x0, x1)),
            (y0..y1.max(y0 * 10.0))
                .log_scale()
                .with_key_points(ticks_125(y0, y1.max(y0 * 10.0))),
        )
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc("GPU time per frame (ms, median)")
        .y_desc("misclassified fraction of pixels (0 drawn at 1e-6)")
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .x_label_formatter(&|v| {
            if *v >= 10.0 {
                format!("{v:.0}")
            } else {
                format!("{v:.1}")
            }
        })
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 16))
        .draw()
        .map_err(e)?;
    draw_points(&mut chart, rows)?;
    let at: Vec<(i32, i32)> = pts.iter().map(|p| chart.backend_coord(p)).collect();
    draw_front(&mut chart, rows, &pts, &at)?;
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()
        .map_err(e)?;
    root.present().map_err(e)?;
    Ok(())
}

/// The Pareto front: a staircase through its points, each ringed, and labelled where the label
/// does not overlap the previous one (`at`: each point's position on the drawing).
fn draw_front<'a, DB, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
    rows: &[Row],
    pts: &[(f64, f64)],
    at: &[(i32, i32)],
) -> Result<(), String>
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
    CT: CoordTranslate<From = (f64, f64)>,
{
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    let front = pareto_front(pts);
    let mut stair = Vec::new();
    for (k, &i) in front.iter().enumerate() {
        if k > 0 {
            stair.push((pts[i].0, pts[front[k - 1]].1));
        }
        stair.push(pts[i]);
    }
    chart
        .draw_series(LineSeries::new(stair, BLACK.stroke_width(1)))
        .map_err(e)?
        .label("Pareto front")
        .legend(|(x, y)| PathElement::new(vec![(x - 8, y), (x + 8, y)], BLACK));
    // Every front point ringed; labels to the right, only where they do not overlap the previous
    // label.
    let mut labelled: Vec<(usize, (i32, i32))> = Vec::new();
    for &i in &front {
        let at = at[i];
        if labelled
            .last()
            .is_none_or(|(_, p)| (p.1 - at.1).abs() >= 16 || (p.0 - at.0).abs() >= 260)
        {
            labelled.push((i, at));
        }
    }
    chart
        .draw_series(
            front
                .iter()
                .map(|&i| Circle::new(pts[i], 7, BLACK.stroke_width(1))),
        )
        .map_err(e)?;
    chart
        .draw_series(labelled.iter().map(|&(i, _)| {
            EmptyElement::at(pts[i])
                + Text::new(short_label(&rows[i]), (10, -7), ("sans-serif", 13))
        }))
        .map_err(e)?;
    Ok(())
}

/// Every row as a point (colour = fitting method, shape = filter), with the legend's entries
/// (empty series carry them).
fn draw_points<'a, DB, CT>(chart: &mut ChartContext<'a, DB, CT>, rows: &[Row]) -> Result<(), String>
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
    CT: CoordTranslate<From = (f64, f64)>,
{
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    for (method, color) in METHODS {
        let of = |f: &str| -> Vec<(f64, f64)> {
            rows.iter()
                .filter(|r| r.method == method && r.filter == f)
                .map(|r| (r.gpu_ms, y_of(r)))
                .collect()
        };
        if !rows.iter().any(|r| r.method == method) {
            continue;
        }
        let fill = ShapeStyle::from(&color).filled();
        let line = color.stroke_width(2);
        chart
            .draw_series(of("nearest").into_iter().map(|p| Cross::new(p, 4, line)))
            .map_err(e)?;
        chart
            .draw_series(of("pcf2x2").into_iter().map(|p| Circle::new(p, 3, fill)))
            .map_err(e)?;
        chart
            .draw_series(
                of("pcf3x3")
                    .into_iter()
                    .map(|p| TriangleMarker::new(p, 5, fill)),
            )
            .map_err(e)?;
        chart
            .draw_series(of("pcf5x5").into_iter().map(|p| Circle::new(p, 6, line)))
            .map_err(e)?;
        chart
            .draw_series(
                of("pcss")
                    .into_iter()
                    .map(|p| TriangleMarker::new(p, 8, line)),
            )
            .map_err(e)?;
        chart
            .draw_series(
                of("contact")
                    .into_iter()
                    .map(|p| EmptyElement::at(p) + Rectangle::new([(-6, -6), (6, 6)], line)),
            )
            .map_err(e)?;
        chart
            .draw_series(
                of("exact")
                    .into_iter()
                    .chain(of("hybrid"))
                    .map(|p| EmptyElement::at(p) + Rectangle::new([(-6, -6), (6, 6)], fill)),
            )
            .map_err(e)?;
        chart
            .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
            .map_err(e)?
            .label(method)
            .legend(move |(x, y)| Rectangle::new([(x - 6, y - 5), (x + 6, y + 5)], fill));
    }
    draw_shape_legend(chart)
}

/// The legend's shape entries (grey, one per filter), carried by empty series.
fn draw_shape_legend<'a, DB, CT>(chart: &mut ChartContext<'a, DB, CT>) -> Result<(), String>
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
    CT: CoordTranslate<From = (f64, f64)>,
{
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    let grey = RGBColor(60, 60, 60);
    for (label, shape) in [
        ("nearest", 0),
        ("PCF 2x2", 1),
        ("PCF 3x3", 2),
        ("PCF 5x5", 3),
        ("PCSS", 4),
        ("exact, hybrid", 5),
        ("PCF 2x2 + contact", 6),
    ] {
        chart
            .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
            .map_err(e)?
            .label(label)
            .legend(move |(x, y)| -> DynElement<'static, DB, (i32, i32)> {
                match shape {
                    0 => Cross::new((x, y), 4, grey.stroke_width(2)).into_dyn(),
                    1 => Circle::new((x, y), 3, grey.filled()).into_dyn(),
                    2 => TriangleMarker::new((x, y), 5, grey.filled()).into_dyn(),
                    3 => Circle::new((x, y), 6, grey.stroke_width(2)).into_dyn(),
                    4 => TriangleMarker::new((x, y), 8, grey.stroke_width(2)).into_dyn(),
                    5 => Rectangle::new([(x - 6, y - 6), (x + 6, y + 6)], grey.filled()).into_dyn(),
                    _ => Rectangle::new([(x - 6, y - 6), (x + 6, y + 6)], grey.stroke_width(2))
                        .into_dyn(),
                }
            });
    }
    Ok(())
}

/// Draws the chart of `rows` to `svg` and `png`. Shapes: cross = nearest, small dot = PCF 2×2,
/// triangle = PCF 3×3, ring = PCF 5×5.
pub fn write_pareto(rows: &[Row], title: &str, svg: &Path, png: &Path) -> Result<(), ChartError> {
    write_svg_png(
        svg,
        png,
        |root| draw(root, rows, title),
        |root| draw(root, rows, title),
    )
}

/// Writes one chart of [`SIZE`] twice: `draw_svg` onto an SVG file, `draw_png` onto a bitmap
/// saved as PNG (text drawn with the embedded font).
pub(crate) fn write_svg_png(
    svg: &Path,
    png: &Path,
    draw_svg: impl FnOnce(DrawingArea<SVGBackend, Shift>) -> Result<(), String>,
    draw_png: impl FnOnce(DrawingArea<BitMapBackend, Shift>) -> Result<(), String>,
) -> Result<(), ChartError> {
    register_font();
    let err = |p: &Path, m: String| ChartError {
        path: p.display().to_string(),
        message: m,
    };
    draw_svg(SVGBackend::new(svg, SIZE).into_drawing_area()).map_err(|m| err(svg, m))?;
    let mut buf = vec![255u8; (SIZE.0 * SIZE.1 * 3) as usize];
    draw_png(BitMapBackend::with_buffer(&mut buf, SIZE).into_drawing_area())
        .map_err(|m| err(png, m))?;
    let img = image::RgbImage::from_raw(SIZE.0, SIZE.1, buf)
        .ok_or_else(|| err(png, "buffer size".into()))?;
    img.save(png).map_err(|x| err(png, x.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_1_2_5_within_the_range() {
        assert_eq!(ticks_125(15.0, 220.0), vec![20.0, 50.0, 100.0, 200.0]);
        assert_eq!(ticks_125(15.0, 60.0), vec![15.0, 20.0, 30.0, 40.0, 50.0]);
        let t = ticks_125(3e-5, 2e-3);
        assert_eq!(t.len(), 6, "{t:?}");
        assert!(
            (t[0] - 5e-5).abs() < 1e-12 && (t[5] - 2e-3).abs() < 1e-12,
            "{t:?}"
        );
        assert!(ticks_125(0.0, 1.0).is_empty());
    }

    #[test]
    fn chart_files_are_written_with_points_front_and_labels() {
        let mk = |config: &str, method: &str, filter: &str, ms: f64, m: f64| {
            let mut r = crate::analysis::sweep::tests::row("demo", config, ms, m);
            r.method = method.into();
            r.filter = filter.into();
            r
        };
        let rows = vec![
            mk("a", "camera", "pcf2x2", 20.0, 2e-3),
            mk("b", "cascades4", "nearest", 30.0, 5e-4),
            mk("c", "scene", "pcf5x5", 40.0, 1e-3),
            mk("d", "cascades2", "pcf3x3", 50.0, 0.0),
        ];
        let dir = std::env::temp_dir().join(format!("umbra-chart-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (svg, png) = (dir.join("p.svg"), dir.join("p.png"));
        write_pareto(&rows, "test chart", &svg, &png).unwrap();
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(text.contains("test chart") && text.contains("Pareto front"));
        // The front (a, b, d) is labelled; c is dominated by b.
        assert!(text.contains("2048 pcf2x2 camera") && text.contains("2048 pcf3x3 cascades2"));
        let img = image::open(&png).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), SIZE);
        let coloured = img
            .pixels()
            .filter(|p| p[0] != p[1] || p[1] != p[2])
            .count();
        assert!(
            coloured > 100,
            "{coloured} coloured pixels: the points are drawn"
        );
        let dark = img
            .pixels()
            .filter(|p| p[0] < 60 && p[1] < 60 && p[2] < 60)
            .count();
        assert!(
            dark > 2000,
            "{dark} dark pixels: axes, text and the front are drawn"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
