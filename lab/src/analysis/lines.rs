//! Line charts (the stability suite's): series of (x, y) points on a log y axis (zeros drawn at a
//! stated floor) and a log or linear x axis, with threshold lines and labelled marks. SVG and PNG
//! through [`super::chart`]'s writer.

use super::chart::{ticks_125, write_svg_png, ChartError};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Colours of successive series (matplotlib's tab10).
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// One line.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// Points in x order.
    pub points: Vec<(f64, f64)>,
}

/// A chart of lines.
#[derive(Clone, Debug)]
pub struct LineChart {
    /// Caption.
    pub title: String,
    /// X axis description.
    pub x_desc: String,
    /// Y axis description.
    pub y_desc: String,
    /// Log x axis (else linear).
    pub x_log: bool,
    /// Values below this (zeros) are drawn at it; the y axis is logarithmic.
    pub y_floor: f64,
    /// The lines.
    pub series: Vec<Series>,
    /// Horizontal dashed lines (label, y): thresholds.
    pub thresholds: Vec<(String, f64)>,
    /// Ringed, labelled points (label, (x, y)).
    pub marks: Vec<(String, (f64, f64))>,
}

fn range(vals: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let (lo, hi) = vals
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    lo.is_finite().then_some((lo, hi))
}

macro_rules! draw_body {
    ($chart:ident, $c:ident, $root:ident, $e:ident, $fmt_x:ident) => {{
        $chart
            .configure_mesh()
            .x_desc(&$c.x_desc)
            .y_desc(&$c.y_desc)
            .x_label_formatter(&$fmt_x)
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .label_style(("sans-serif", 15))
            .axis_desc_style(("sans-serif", 16))
            .draw()
            .map_err($e)?;
        for (k, s) in $c.series.iter().enumerate() {
            let color = PALETTE[k % PALETTE.len()];
            let pts: Vec<(f64, f64)> = s
                .points
                .iter()
                .map(|&(x, y)| (x, y.max($c.y_floor)))
                .collect();
            $chart
                .draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))
                .map_err($e)?
                .label(s.label.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x - 10, y), (x + 10, y)], color.stroke_width(2))
                });
            $chart
                .draw_series(pts.into_iter().map(|p| Circle::new(p, 3, color.filled())))
                .map_err($e)?;
        }
        for (label, y) in &$c.thresholds {
            let (x0, x1) = ($chart.x_range().start, $chart.x_range().end);
            let y = y.max($c.y_floor);
            $chart
                .draw_series(DashedLineSeries::new(
                    vec![(x0, y), (x1, y)],
                    8,
                    5,
                    BLACK.stroke_width(1),
                ))
                .map_err($e)?;
            $chart
                .draw_series(std::iter::once(
                    EmptyElement::at((x0, y))
                        + Text::new(label.clone(), (6, -16), ("sans-serif", 13)),
                ))
                .map_err($e)?;
        }
        for (label, (x, y)) in &$c.marks {
            let p = (*x, y.max($c.y_floor));
            $chart
                .draw_series(std::iter::once(
                    EmptyElement::at(p)
                        + Circle::new((0, 0), 8, BLACK.stroke_width(2))
                        + Text::new(label.clone(), (10, -14), ("sans-serif", 13)),
                ))
                .map_err($e)?;
        }
        $chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .draw()
            .map_err($e)?;
        $root.present().map_err($e)?;
    }};
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, c: &LineChart) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    root.fill(&WHITE).map_err(e)?;
    let all = || c.series.iter().flat_map(|s| s.points.iter());
    let (x0, x1) =
        range(all().map(|p| p.0).filter(|x| !c.x_log || *x > 0.0)).unwrap_or((1.0, 10.0));
    let ys = all()
        .map(|p| p.1.max(c.y_floor))
        .chain(c.thresholds.iter().map(|t| t.1.max(c.y_floor)));
    let (y0, y1) = range(ys).unwrap_or((c.y_floor, 1.0));
    let (y0, y1) = (y0.min(c.y_floor) / 1.5, (y1 * 3.0).max(y0 * 10.0));
    let y_axis = (y0..y1).log_scale().with_key_points(ticks_125(y0, y1));
    let mut builder = ChartBuilder::on(&root);
    builder
        .caption(&c.title, ("sans-serif", 22))
        .margin(14)
        .x_label_area_size(48)
        .y_label_area_size(80);
    let fmt_x = |v: &f64| {
        if v.abs() >= 10.0 || *v == 0.0 {
            format!("{v:.0}")
        } else if v.abs() >= 1.0 {
            format!("{v:.1}")
        } else {
            format!("{v:.0e}")
        }
    };
    if c.x_log {
        let (x0, x1) = (x0 / 1.2, x1 * 1.2);
        let mut chart = builder
            .build_cartesian_2d(
                (x0..x1).log_scale().with_key_points(ticks_125(x0, x1)),
                y_axis,
            )
            .map_err(e)?;
        draw_body!(chart, c, root, e, fmt_x);
    } else {
        let pad = ((x1 - x0) * 0.03).max(1e-9);
        let mut chart = builder
            .build_cartesian_2d((x0 - pad)..(x1 + pad), y_axis)
            .map_err(e)?;
        draw_body!(chart, c, root, e, fmt_x);
    }
    Ok(())
}

/// Draws `chart` to `svg` and `png`.
pub fn write_lines(chart: &LineChart, svg: &Path, png: &Path) -> Result<(), ChartError> {
    write_svg_png(svg, png, |r| draw(r, chart), |r| draw(r, chart))
}
