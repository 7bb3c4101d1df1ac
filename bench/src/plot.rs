//! PNG plots with `plotters` (bitmap backend). Text goes through `ab_glyph` with an embedded
//! font (Hack Regular, from `epaint_default_fonts`), so no system font or fontconfig is needed.

use crate::stats::loglog_fit;
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

const FONT: &str = "sans-serif";
const SIZE: (u32, u32) = (1100, 650);

/// One named series of points.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend name.
    pub name: String,
    /// `(x, y)` points.
    pub points: Vec<(f64, f64)>,
}

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The embedded font is a valid TTF; if registration failed anyway, text would be
        // missing from the plots, not the data.
        let _ = plotters::style::register_font(
            FONT,
            FontStyle::Normal,
            epaint_default_fonts::HACK_REGULAR,
        );
    });
}

fn color(i: usize) -> RGBColor {
    const PALETTE: [RGBColor; 12] = [
        RGBColor(31, 119, 180),
        RGBColor(255, 127, 14),
        RGBColor(44, 160, 44),
        RGBColor(214, 39, 40),
        RGBColor(148, 103, 189),
        RGBColor(140, 86, 75),
        RGBColor(227, 119, 194),
        RGBColor(127, 127, 127),
        RGBColor(188, 189, 34),
        RGBColor(23, 190, 207),
        RGBColor(0, 0, 0),
        RGBColor(255, 215, 0),
    ];
    PALETTE[i % PALETTE.len()]
}

fn plot_error<E: std::fmt::Debug>(path: &Path, e: E) -> String {
    format!("cannot draw {}: {e:?}", path.display())
}

/// Range of positive values, padded by a factor for a log axis.
fn log_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for v in values.filter(|v| *v > 0.0 && v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return (0.1, 10.0);
    }
    if lo == hi {
        return (lo / 2.0, hi * 2.0);
    }
    (lo / 1.5, hi * 1.5)
}

/// Log-log scatter with one least-squares line per series (slope in the legend). Returns the
/// slope of each series (`None` where it cannot be fitted).
///
/// # Errors
/// A message if the PNG cannot be drawn or written.
pub fn loglog(
    path: &Path,
    title: &str,
    x_desc: &str,
    y_desc: &str,
    series: &[Series],
) -> Result<Vec<Option<f64>>, String> {
    register_font();
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(|e| plot_error(path, e))?;
    let (x0, x1) = log_range(series.iter().flat_map(|s| s.points.iter().map(|p| p.0)));
    let (y0, y1) = log_range(series.iter().flat_map(|s| s.points.iter().map(|p| p.1)));
    let mut chart = ChartBuilder::on(&root)
        .caption(title, (FONT, 22))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(80)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
        .map_err(|e| plot_error(path, e))?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .label_style((FONT, 14))
        .y_label_formatter(&|v| format!("{v:.1e}"))
        .draw()
        .map_err(|e| plot_error(path, e))?;
    let mut slopes = Vec::new();
    for (i, s) in series.iter().enumerate() {
        let c = color(i);
        let pts: Vec<(f64, f64)> = s
            .points
            .iter()
            .copied()
            .filter(|(x, y)| *x > 0.0 && *y > 0.0)
            .collect();
        let fit = loglog_fit(&pts);
        slopes.push(fit.map(|f| f.0));
        let label = match fit {
            Some((slope, _)) => format!("{} (slope {slope:.2})", s.name),
            None => s.name.clone(),
        };
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 5, c.filled())))
            .map_err(|e| plot_error(path, e))?
            .label(label)
            .legend(move |(x, y)| Circle::new((x + 8, y), 5, c.filled()));
        if let Some((slope, icpt)) = fit {
            let (lo, hi) = pts.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| {
                (a.min(p.0), b.max(p.0))
            });
            let line = [lo, hi].map(|x| (x, (icpt + slope * x.ln()).exp()));
            chart
                .draw_series(LineSeries::new(line, c.stroke_width(2)))
                .map_err(|e| plot_error(path, e))?;
        }
    }
    chart
        .configure_series_labels()
        .label_font((FONT, 13))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(|e| plot_error(path, e))?;
    root.present().map_err(|e| plot_error(path, e))?;
    Ok(slopes)
}

/// Grouped bars: one group per entry of `groups`, one bar per series (`values[g]` of each
/// series; 0 draws nothing).
///
/// # Errors
/// A message if the PNG cannot be drawn or written.
pub fn grouped_bars(
    path: &Path,
    title: &str,
    y_desc: &str,
    groups: &[String],
    series: &[(String, Vec<f64>)],
) -> Result<(), String> {
    register_font();
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(|e| plot_error(path, e))?;
    let y_max = series
        .iter()
        .flat_map(|s| s.1.iter().copied())
        .fold(0.0f64, f64::max)
        .max(1e-9)
        * 1.3;
    let n = groups.len().max(1);
    let mut chart = ChartBuilder::on(&root)
        .caption(title, (FONT, 22))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(-0.5f64..(n as f64 - 0.5), 0f64..y_max)
        .map_err(|e| plot_error(path, e))?;
    let names = groups.to_vec();
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(n + 1)
        .x_label_formatter(&|x: &f64| {
            let i = x.round();
            if (x - i).abs() < 1e-6 && i >= 0.0 {
                names.get(i as usize).cloned().unwrap_or_default()
            } else {
                String::new()
            }
        })
        .y_desc(y_desc)
        .label_style((FONT, 14))
        .draw()
        .map_err(|e| plot_error(path, e))?;
    let k = series.len().max(1) as f64;
    let width = 0.8 / k;
    for (i, (name, values)) in series.iter().enumerate() {
        let c = color(i);
        let bars = values
            .iter()
            .enumerate()
            .filter(|(_, v)| **v > 0.0)
            .map(|(g, &v)| {
                let x = g as f64 - 0.4 + width * i as f64;
                Rectangle::new([(x, 0.0), (x + width * 0.9, v)], c.filled())
            });
        chart
            .draw_series(bars)
            .map_err(|e| plot_error(path, e))?
            .label(name.clone())
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 12, y + 5)], c.filled()));
    }
    chart
        .configure_series_labels()
        .label_font((FONT, 13))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(|e| plot_error(path, e))?;
    root.present().map_err(|e| plot_error(path, e))?;
    Ok(())
}
