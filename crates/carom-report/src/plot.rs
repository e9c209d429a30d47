//! The report's plots: SVG line charts drawn with plotters, x on a log axis (ball count
//! or step), y on a log or linear axis.
//!
//! Text is laid out with the DejaVu Sans metrics embedded in this crate (plotters needs a
//! font to measure labels; the SVG names the family `sans-serif`, so viewers draw it with
//! their own). Series of the same engine or method share a colour; a dashed line marks
//! the second variant (2 threads, or the peer).

use std::ops::Range;
use std::path::Path;

use plotters::coord::ranged1d::{AsRangedCoord, Ranged, ValueFormatter};
use plotters::element::DashedPathElement;
use plotters::prelude::*;

use crate::error::ReportError;

/// One line of a chart.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// The legend's text.
    pub label: String,
    /// The points, in x order.
    pub points: Vec<(f64, f64)>,
    /// Which colour of the palette (series of one engine share it).
    pub colour: usize,
    /// Dashed instead of solid.
    pub dashed: bool,
}

/// A chart to draw.
#[derive(Clone, Debug, PartialEq)]
pub struct Chart {
    /// The title above the plot.
    pub title: String,
    /// The x axis' label (the axis is logarithmic).
    pub x_label: String,
    /// The y axis' label.
    pub y_label: String,
    /// A logarithmic y axis (linear otherwise).
    pub log_y: bool,
    /// Horizontal reference lines: value and legend text.
    pub references: Vec<(f64, String)>,
    /// The lines.
    pub series: Vec<Series>,
}

/// Distinct colours that read on white, for every plot of the report: the Okabe–Ito
/// palette (colour-blind safe) with black and grey (reference lines use black), then a
/// purple, and Okabe–Ito's yellow last (it is faint on white).
pub(crate) const PALETTE: [RGBColor; 10] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(86, 180, 233),
    RGBColor(230, 159, 0),
    RGBColor(0, 0, 0),
    RGBColor(150, 150, 150),
    RGBColor(150, 60, 200),
    RGBColor(240, 228, 66),
];

/// `[lo, hi]` of `values`, widened to a visible range: by a factor on a log axis (which
/// also needs positive values), by a margin on a linear one.
fn range(values: impl Iterator<Item = f64>, log: bool) -> Range<f64> {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && (!log || *v > 0.0))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        return if log { 0.1..10.0 } else { 0.0..1.0 };
    }
    if log {
        (lo / 1.6)..(hi * 1.6)
    } else {
        let pad = 0.08 * (hi - lo).max(0.1 * hi.abs()).max(1e-9);
        (lo - pad).min(0.0)..(hi + pad)
    }
}

/// A tick label: plain for ordinary magnitudes, `1e6` style for large and small ones.
fn tick(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".to_owned()
    } else if (1e-2..1e4).contains(&a) {
        let s = format!("{v:.2}");
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        format!("{v:.0e}")
    }
}

/// A label of a log axis: only at 1, 2 and 5 times a power of ten (plotters proposes
/// every integer multiple, which crowds the decade's end); counts below a million with
/// thousands separators.
fn log_tick(v: f64) -> String {
    let mantissa = v / 10f64.powf(v.log10().floor());
    if ![1.0, 2.0, 5.0].iter().any(|m| (mantissa - m).abs() < 1e-6) {
        return String::new();
    }
    if (1.0..1e6).contains(&v) && v.fract() == 0.0 {
        crate::targets::count(v as usize)
    } else {
        tick(v)
    }
}

/// Draws `chart` into the SVG file `path`.
///
/// # Errors
/// The file cannot be written or plotters fails.
pub fn draw(chart: &Chart, path: &Path) -> Result<(), ReportError> {
    crate::font::register();
    let fail = |e: &dyn std::fmt::Display| ReportError::Plot {
        path: path.to_owned(),
        message: e.to_string(),
    };
    let root = SVGBackend::new(path, (1180, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    let (plot_area, legend_area) = root.split_horizontally(860);
    let xs = range(
        chart
            .series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.0)),
        true,
    );
    let ys = chart
        .series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.1))
        .chain(chart.references.iter().map(|r| r.0));
    if chart.log_y {
        let ys = range(ys, true).log_scale();
        draw_on(&plot_area, chart, xs, ys).map_err(|e| fail(&e))?;
    } else {
        draw_on(&plot_area, chart, xs, range(ys, false)).map_err(|e| fail(&e))?;
    }
    draw_legend(&legend_area, chart).map_err(|e| fail(&e))?;
    root.present().map_err(|e| fail(&e))
}

/// The chart on `root`, y in `ys` (a log or linear range).
fn draw_on<DB: DrawingBackend, Y>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    chart: &Chart,
    xs: Range<f64>,
    ys: Y,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>>
where
    Y: AsRangedCoord<Value = f64>,
    Y::CoordDescType: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let mut c = ChartBuilder::on(root)
        .caption(&chart.title, ("sans-serif", 22))
        .margin(14)
        .x_label_area_size(48)
        .y_label_area_size(72)
        .build_cartesian_2d(xs.clone().log_scale(), ys)?;
    c.configure_mesh()
        .x_desc(chart.x_label.as_str())
        .y_desc(chart.y_label.as_str())
        .x_label_formatter(&|x| log_tick(*x))
        .y_label_formatter(&|y| if chart.log_y { log_tick(*y) } else { tick(*y) })
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 15))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()?;
    for (k, (value, _)) in chart.references.iter().enumerate() {
        let style = reference_style(k);
        c.draw_series(DashedLineSeries::new(
            [(xs.start, *value), (xs.end, *value)],
            3,
            6,
            style,
        ))?;
    }
    for s in &chart.series {
        let (colour, style) = series_style(s);
        let points = s.points.iter().copied();
        if s.dashed {
            c.draw_series(DashedLineSeries::new(points, 8, 5, style))?;
        } else {
            c.draw_series(LineSeries::new(points, style))?;
        }
        c.draw_series(s.points.iter().map(|&p| Circle::new(p, 3, colour.filled())))?;
    }
    Ok(())
}

/// A series' colour and line style.
fn series_style(s: &Series) -> (RGBColor, ShapeStyle) {
    let colour = PALETTE[s.colour % PALETTE.len()];
    (colour, colour.stroke_width(2))
}

/// A reference line's style (the `k`-th).
fn reference_style(k: usize) -> ShapeStyle {
    PALETTE[6].mix(0.6 - 0.2 * k.min(1) as f64).stroke_width(1)
}

/// The legend in its own panel beside the plot, so it never hides a point.
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    chart: &Chart,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let font = ("sans-serif", 13).into_font().color(&BLACK);
    let entries = chart
        .series
        .iter()
        .map(|s| (s.label.as_str(), series_style(s).1, s.dashed))
        .chain(
            chart
                .references
                .iter()
                .enumerate()
                .map(|(k, (_, label))| (label.as_str(), reference_style(k), true)),
        );
    for (k, (label, style, dashed)) in entries.enumerate() {
        let y = 60 + 22 * k as i32;
        let line = [(6, y), (38, y)];
        if dashed {
            area.draw(&DashedPathElement::new(line, 6, 4, style))?;
        } else {
            area.draw(&PathElement::new(line, style))?;
        }
        area.draw(&Text::new(label, (46, y - 7), font.clone()))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_are_visible_and_log_ranges_positive() {
        let r = range([10.0, 1000.0].into_iter(), true);
        assert!(r.start > 0.0 && r.start < 10.0 && r.end > 1000.0);
        let r = range([5.0].into_iter(), true);
        assert!(r.start < 5.0 && r.end > 5.0);
        assert_eq!(range(std::iter::empty(), true), 0.1..10.0);
        let r = range([1.2, 1.9].into_iter(), false);
        assert!(r.start == 0.0 && r.end > 1.9);
        assert_eq!(tick(1e6), "1e6");
        assert_eq!(tick(0.25), "0.25");
        assert_eq!(tick(100.0), "100");
        assert_eq!(log_tick(20_000.0), "20,000");
        assert_eq!(log_tick(7000.0), "");
        assert_eq!(log_tick(1e6), "1e6");
    }

    #[test]
    fn a_chart_becomes_an_svg_with_its_labels() {
        let dir = tempfile::Builder::new()
            .prefix("carom-plot-")
            .tempdir()
            .unwrap();
        let path = dir.path().join("chart.svg");
        let chart = Chart {
            title: "ms per step".into(),
            x_label: "balls".into(),
            y_label: "ms".into(),
            log_y: true,
            references: vec![(2.0, "target".into())],
            series: vec![
                Series {
                    label: "carom".into(),
                    points: vec![(1e3, 0.5), (1e4, 5.0)],
                    colour: 0,
                    dashed: false,
                },
                Series {
                    label: "rapier2d".into(),
                    points: vec![(1e3, 0.7), (1e4, 12.0)],
                    colour: 1,
                    dashed: true,
                },
            ],
        };
        draw(&chart, &path).unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        assert!(svg.starts_with("<svg"));
        for text in ["ms per step", "carom", "rapier2d", "target", "balls"] {
            assert!(svg.contains(text), "{text}");
        }
        let linear = Chart {
            log_y: false,
            ..chart
        };
        draw(&linear, &path).unwrap();
    }
}
