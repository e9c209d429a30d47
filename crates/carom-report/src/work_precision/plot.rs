//! Work-precision diagrams: one log-log SVG per problem, error at the final time on x,
//! the fastest run's seconds on y, one line per method through its steps (a single point
//! for the event engine). Down and to the left is better.
//!
//! Errors at or below [`FLOOR`] (exact to rounding, or exactly 0) are drawn at the floor,
//! and the axis says so: a log axis has no 0.

use std::io;
use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::PROBLEMS;
use crate::model::WorkPrecisionRow;
use crate::plot::PALETTE;

/// Errors are drawn at this value or above.
const FLOOR: f64 = 1e-16;

/// The image format of a plot.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Scalable vector graphics (the report's plots).
    Svg,
    /// A bitmap, for viewers without SVG.
    Png,
}

/// Writes `work-precision-<problem>.svg` into `dir` for every problem that has rows,
/// returning the files written.
///
/// # Errors
/// Creating or writing a file in `dir`.
pub fn plot(rows: &[WorkPrecisionRow], dir: &Path) -> io::Result<Vec<PathBuf>> {
    plot_as(rows, dir, Format::Svg)
}

/// As [`plot`], in `format`.
///
/// # Errors
/// Creating or writing a file in `dir`.
pub fn plot_as(rows: &[WorkPrecisionRow], dir: &Path, format: Format) -> io::Result<Vec<PathBuf>> {
    crate::font::register();
    let mut written = Vec::new();
    for problem in PROBLEMS {
        let of: Vec<&WorkPrecisionRow> = rows.iter().filter(|r| r.problem == problem).collect();
        if of.is_empty() {
            continue;
        }
        let size = (960, 620);
        let (path, drawn) = match format {
            Format::Svg => {
                let path = dir.join(format!("work-precision-{problem}.svg"));
                let drawn = draw(
                    problem,
                    &of,
                    &SVGBackend::new(&path, size).into_drawing_area(),
                )
                .map_err(|e| e.to_string());
                (path, drawn)
            }
            Format::Png => {
                let path = dir.join(format!("work-precision-{problem}.png"));
                let mut rgb = vec![0_u8; size.0 as usize * size.1 as usize * 3];
                let drawn = draw(
                    problem,
                    &of,
                    &BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area(),
                )
                .map_err(|e| e.to_string());
                if drawn.is_ok() {
                    write_png(&path, size, &rgb)?;
                }
                (path, drawn)
            }
        };
        drawn.map_err(|e| io::Error::other(format!("{}: {e}", path.display())))?;
        written.push(path);
    }
    Ok(written)
}

/// Writes an RGB buffer as a PNG file.
fn write_png(path: &Path, (width, height): (u32, u32), rgb: &[u8]) -> io::Result<()> {
    let file = io::BufWriter::new(std::fs::File::create(path)?);
    let mut encoder = png::Encoder::new(file, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().map_err(io::Error::other)?;
    writer.write_image_data(rgb).map_err(io::Error::other)?;
    writer.finish().map_err(io::Error::other)
}

/// The methods of `rows`, in first-appearance order.
fn methods<'a>(rows: &[&'a WorkPrecisionRow]) -> Vec<&'a str> {
    let mut out: Vec<&str> = Vec::new();
    for r in rows {
        if !out.contains(&r.method.as_str()) {
            out.push(&r.method);
        }
    }
    out
}

/// The decade range `[10^floor(log lo), 10^ceil(log hi)]` around the values.
fn decades(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, 0.0_f64), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    (
        10f64.powf(lo.log10().floor()),
        10f64.powf(hi.log10().ceil()).max(lo * 10.0),
    )
}

/// The error measure of a problem, for the x axis.
fn error_label(problem: &str) -> &'static str {
    match problem {
        "elastic-gas" => "relative energy error at the final time",
        _ => "distance to the closed form at the final time (m)",
    }
}

/// Width of the legend panel right of the chart (pixels).
const LEGEND_WIDTH: u32 = 280;

/// What a reader needs to know about the methods a problem's plot does not show.
fn notes(problem: &str) -> &'static [&'static str] {
    match problem {
        "projectile-drag" => &["carom-event: not run, drag has", "no exact time of impact"],
        "stiff-spring" => &[
            "carom-integrate directly: the",
            "engines have no springs; exact:",
            "refused (no closed form);",
            "rapier2d: its spring joint",
        ],
        "two-ball" | "elastic-gas" => &[
            "no forces: every integrator",
            "flies the same straight lines",
        ],
        _ => &[],
    }
}

fn draw<DB: DrawingBackend>(
    problem: &str,
    rows: &[&WorkPrecisionRow],
    area: &DrawingArea<DB, plotters::coord::Shift>,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    area.fill(&WHITE)?;
    let (width, _) = area.dim_in_pixel();
    let (plot_area, legend_area) = area.split_horizontally(width.saturating_sub(LEGEND_WIDTH));
    let x = |r: &WorkPrecisionRow| r.error.max(FLOOR);
    let (x_lo, x_hi) = decades(rows.iter().map(|r| x(r)));
    let (y_lo, y_hi) = decades(rows.iter().map(|r| r.seconds));
    // A decade of room left of the floor, so points drawn there are not on the axis.
    let x_lo = x_lo / 10.0;
    let mut chart = ChartBuilder::on(&plot_area)
        .caption(
            format!("{problem}: error against run time"),
            (crate::font::FAMILY, 20),
        )
        .margin(12)
        .x_label_area_size(48)
        .y_label_area_size(80)
        .build_cartesian_2d((x_lo..x_hi).log_scale(), (y_lo..y_hi).log_scale())?;
    chart
        .configure_mesh()
        .x_desc(format!(
            "{} (≤ {FLOOR:.0e} drawn at {FLOOR:.0e})",
            error_label(problem)
        ))
        .y_desc("seconds (fastest of several runs)")
        .x_label_formatter(&|v| format!("{v:.0e}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()?;
    let methods = methods(rows);
    let font = (crate::font::FAMILY, 14).into_font();
    legend_area.draw(&Text::new(
        "log-log; down and left is better",
        (8, 40),
        font.clone(),
    ))?;
    legend_area.draw(&Text::new(
        "rings: coinciding methods",
        (8, 58),
        font.clone(),
    ))?;
    for (k, method) in methods.iter().enumerate() {
        let colour = PALETTE[k % PALETTE.len()];
        let mut of: Vec<&&WorkPrecisionRow> = rows.iter().filter(|r| r.method == *method).collect();
        // Along the steps, coarse to fine: the line follows the method's refinement.
        of.sort_by(|a, b| b.dt.unwrap_or(0.0).total_cmp(&a.dt.unwrap_or(0.0)));
        let points: Vec<(f64, f64)> = of.iter().map(|r| (x(r), r.seconds)).collect();
        chart.draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))?;
        // Rings shrinking with the method's index: methods whose points coincide stay
        // visible as concentric rings.
        let radius = 3 + (3 * (methods.len() - 1 - k) as i32) / 2;
        chart.draw_series(
            points
                .iter()
                .map(|&p| Circle::new(p, radius, colour.stroke_width(2))),
        )?;
        let y = 90 + 24 * k as i32;
        legend_area.draw(&PathElement::new(
            vec![(8, y), (34, y)],
            colour.stroke_width(3),
        ))?;
        legend_area.draw(&Circle::new((21, y), radius, colour.stroke_width(2)))?;
        legend_area.draw(&Text::new(*method, (42, y - 7), font.clone()))?;
    }
    let below = 90 + 24 * methods.len() as i32 + 10;
    for (k, line) in notes(problem).iter().enumerate() {
        legend_area.draw(&Text::new(*line, (8, below + 18 * k as i32), font.clone()))?;
    }
    area.present()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decades_enclose_the_values() {
        assert_eq!(decades([3e-5, 2e-2].into_iter()), (1e-5, 1e-1));
        // A single value still spans a decade.
        let (lo, hi) = decades([1e-3].into_iter());
        assert!(lo <= 1e-3 && hi >= 1e-2);
    }

    #[test]
    fn plots_are_written_per_problem() {
        let rows: Vec<WorkPrecisionRow> = [(1e-3, 1e-4), (1e-5, 4e-4), (0.0, 1e-3)]
            .iter()
            .map(|&(error, seconds)| WorkPrecisionRow {
                problem: "two-ball".to_owned(),
                method: "carom-stepped/rk4".to_owned(),
                dt: Some(0.01),
                error,
                seconds,
            })
            .collect();
        let dir = tempfile::Builder::new()
            .prefix("carom-wp-")
            .tempdir()
            .unwrap();
        let files = plot(&rows, dir.path()).unwrap();
        assert_eq!(files.len(), 1);
        let svg = std::fs::read_to_string(&files[0]).unwrap();
        assert!(svg.contains("<svg") && svg.contains("carom-stepped/rk4"));
    }
}
