//! PNG plots: scatter plots of point sets, log-scale heat maps of spectra,
//! and line plots (linear or log-log) with a legend and optional shaded
//! bands. Drawn with plotters into memory, then written atomically.

use std::path::Path;
use std::sync::Once;

use lumis_core::{Error, Result};
use plotters::coord::combinators::IntoLogRange;
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};

const FONT: &str = "sans-serif";

/// Registers the embedded font once: a fresh machine may have no system
/// fonts, and plotters' ab_glyph backend only knows registered ones.
fn ensure_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The embedded TTF is valid; a failure would only lose the text.
        let _ = register_font(FONT, FontStyle::Normal, epaint_default_fonts::HACK_REGULAR);
    });
}

/// Draws with `draw` on a `width x height` white canvas and writes the PNG.
fn render(
    path: &Path,
    (width, height): (u32, u32),
    draw: impl FnOnce(
        &DrawingArea<BitMapBackend, plotters::coord::Shift>,
    ) -> std::result::Result<(), String>,
) -> Result<()> {
    ensure_font();
    let mut buffer = vec![0u8; (width * height * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, (width, height)).into_drawing_area();
        root.fill(&WHITE)
            .map_err(|e| e.to_string())
            .and_then(|_| draw(&root))
            .and_then(|_| root.present().map_err(|e| e.to_string()))
            .map_err(|e| Error::msg(format!("{}: drawing the plot failed: {e}", path.display())))?;
    }
    lumis_image::write_rgb8_png(path, width as usize, height as usize, &buffer)
        .map_err(|e| Error::msg(e.to_string()))
}

fn text_error<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

/// A 2D point set in the unit square.
pub fn scatter(path: &Path, title: &str, points: &[[f64; 2]]) -> Result<()> {
    render(path, (640, 660), |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(title, (FONT, 18))
            .margin(12)
            .x_label_area_size(30)
            .y_label_area_size(40)
            .build_cartesian_2d(0f64..1f64, 0f64..1f64)
            .map_err(text_error)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .label_style((FONT, 12))
            .draw()
            .map_err(text_error)?;
        let radius = if points.len() > 4096 { 1 } else { 2 };
        chart
            .draw_series(
                points
                    .iter()
                    .map(|p| Circle::new((p[0], p[1]), radius, BLACK.filled())),
            )
            .map_err(text_error)?;
        Ok(())
    })
}

/// Viridis (van der Walt and Smith 2015), sampled at five stops.
fn viridis(t: f64) -> RGBColor {
    const STOPS: [(f64, f64, f64); 5] = [
        (68.0, 1.0, 84.0),
        (59.0, 82.0, 139.0),
        (33.0, 145.0, 140.0),
        (94.0, 201.0, 98.0),
        (253.0, 231.0, 37.0),
    ];
    let x = t.clamp(0.0, 1.0) * 4.0;
    let i = (x as usize).min(3);
    let f = x - i as f64;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    let lerp = |p: f64, q: f64| (p + (q - p) * f).round() as u8;
    RGBColor(lerp(a.0, b.0), lerp(a.1, b.1), lerp(a.2, b.2))
}

/// Where a heat map's cells sit: a `width x height` grid whose cell
/// `(0, 0)` (row 0 at the bottom) is at integer coordinate `origin`.
pub struct Grid<'a> {
    pub width: usize,
    pub height: usize,
    pub origin: (i64, i64),
    pub x_label: &'a str,
    pub y_label: &'a str,
    /// What the colour bar measures, e.g. "log10 P".
    pub value_label: &'a str,
}

/// A row-major array as a log10 heat map with a colour bar (viridis).
/// Values are clamped to `[min, max]` of the positive entries, or to
/// `range` when given.
/// The colour scale of [`heat_map`], as log10 of the values: `range`, or
/// the finite positive values' extent, at least a thousandth of a decade
/// wide. Values that are all zero or not finite (the error of an image
/// against itself) get the decade above 1e-12, so the scale and its ticks
/// stay finite.
fn log_range(values: &[f64], range: Option<(f64, f64)>) -> (f64, f64) {
    const FLOOR: f64 = 1e-12;
    let (lo, hi) = range.unwrap_or_else(|| {
        values
            .iter()
            .copied()
            .filter(|v| *v > 0.0 && v.is_finite())
            .fold((f64::INFINITY, 0.0f64), |(a, b), v| (a.min(v), b.max(v)))
    });
    if !(lo.is_finite() && hi.is_finite()) {
        return (FLOOR.log10(), FLOOR.log10() + 1.0);
    }
    let lo = lo.max(FLOOR).log10();
    (lo, hi.max(FLOOR).log10().max(lo + 1e-3))
}

pub fn heat_map(
    path: &Path,
    title: &str,
    values: &[f64],
    grid: &Grid,
    range: Option<(f64, f64)>,
) -> Result<()> {
    let (lo, hi) = log_range(values, range);
    let (w, h) = (grid.width, grid.height);
    let (x0, y0) = grid.origin;
    // Keep cells square: the plot area follows the grid's aspect ratio.
    let map_width = 650u32;
    let map_height = ((map_width - 60) as f64 * h as f64 / w as f64) as u32 + 80;
    render(path, (map_width + 110, map_height.max(200)), |root| {
        let (map_area, bar_area) = root.split_horizontally(map_width);
        let mut chart = ChartBuilder::on(&map_area)
            .caption(title, (FONT, 18))
            .margin(12)
            .x_label_area_size(30)
            .y_label_area_size(40)
            .build_cartesian_2d(x0..x0 + w as i64, y0..y0 + h as i64)
            .map_err(text_error)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .label_style((FONT, 12))
            .x_desc(grid.x_label)
            .y_desc(grid.y_label)
            .draw()
            .map_err(text_error)?;
        chart
            .draw_series((0..h).flat_map(|y| {
                (0..w).map(move |x| {
                    let v = values[y * w + x].max(1e-12).log10();
                    let (kx, ky) = (x as i64 + x0, y as i64 + y0);
                    Rectangle::new(
                        [(kx, ky), (kx + 1, ky + 1)],
                        viridis((v - lo) / (hi - lo)).filled(),
                    )
                })
            }))
            .map_err(text_error)?;
        let mut bar = ChartBuilder::on(&bar_area)
            .margin_top(42)
            .margin_bottom(42)
            .margin_right(8)
            .y_label_area_size(50)
            .build_cartesian_2d(0f64..1f64, lo..hi)
            .map_err(text_error)?;
        bar.configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .label_style((FONT, 11))
            .y_desc(grid.value_label)
            .draw()
            .map_err(text_error)?;
        let steps = 100;
        bar.draw_series((0..steps).map(|i| {
            let (a, b) = (i as f64 / steps as f64, (i + 1) as f64 / steps as f64);
            Rectangle::new(
                [(0.0, lo + a * (hi - lo)), (1.0, lo + b * (hi - lo))],
                viridis(a).filled(),
            )
        }))
        .map_err(text_error)?;
        Ok(())
    })
}

/// One line of a [`line_plot`], with an optional shaded band (low, high).
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    pub band: Option<Vec<(f64, f64, f64)>>,
}

pub struct Axes<'a> {
    pub title: &'a str,
    pub x_label: &'a str,
    pub y_label: &'a str,
    pub log_x: bool,
    pub log_y: bool,
}

/// Tick labels: plain for moderate values, `1e-6` style for tiny or huge.
fn tick(v: &f64) -> String {
    let a = v.abs();
    if a != 0.0 && !(1e-2..1e5).contains(&a) {
        format!("{v:.0e}")
    } else {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

fn palette(i: usize) -> RGBColor {
    const COLORS: [RGBColor; 10] = [
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
    ];
    COLORS[i % COLORS.len()]
}

/// Lines with a legend, linear or logarithmic axes. Non-positive values are
/// left out of log axes.
pub fn line_plot(path: &Path, axes: &Axes, series: &[Series]) -> Result<()> {
    let usable = |(x, y): (f64, f64)| {
        x.is_finite() && y.is_finite() && (!axes.log_x || x > 0.0) && (!axes.log_y || y > 0.0)
    };
    let all: Vec<(f64, f64)> = series
        .iter()
        .flat_map(|s| {
            s.points.iter().copied().chain(
                s.band
                    .iter()
                    .flatten()
                    .flat_map(|&(x, lo, hi)| [(x, lo), (x, hi)]),
            )
        })
        .filter(|p| usable(*p))
        .collect();
    if all.is_empty() {
        return Err(Error::msg(format!("{}: nothing to plot", path.display())));
    }
    let bounds = |get: fn(&(f64, f64)) -> f64, log: bool| {
        let (mut lo, mut hi) = all
            .iter()
            .map(get)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            });
        if log {
            lo /= 1.5;
            hi *= 1.5;
        } else {
            let pad = ((hi - lo) * 0.05).max(1e-12);
            lo -= pad;
            hi += pad;
        }
        lo..hi
    };
    let (xr, yr) = (bounds(|p| p.0, axes.log_x), bounds(|p| p.1, axes.log_y));
    render(path, (820, 600), |root| {
        let mut builder = ChartBuilder::on(root);
        builder
            .caption(axes.title, (FONT, 18))
            .margin(14)
            .x_label_area_size(40)
            .y_label_area_size(70);
        // Four coordinate kinds; one generic body.
        macro_rules! draw {
            ($chart:expr) => {{
                let mut chart = $chart.map_err(text_error)?;
                chart
                    .configure_mesh()
                    .label_style((FONT, 12))
                    .x_label_formatter(&tick)
                    .y_label_formatter(&tick)
                    .x_desc(axes.x_label)
                    .y_desc(axes.y_label)
                    .draw()
                    .map_err(text_error)?;
                for (i, s) in series.iter().enumerate() {
                    let color = palette(i);
                    if let Some(band) = &s.band {
                        let mut outline: Vec<(f64, f64)> =
                            band.iter().map(|&(x, lo, _)| (x, lo)).collect();
                        outline.extend(band.iter().rev().map(|&(x, _, hi)| (x, hi)));
                        outline.retain(|p| usable(*p));
                        chart
                            .draw_series(std::iter::once(Polygon::new(outline, color.mix(0.18))))
                            .map_err(text_error)?;
                    }
                    let points: Vec<(f64, f64)> =
                        s.points.iter().copied().filter(|p| usable(*p)).collect();
                    chart
                        .draw_series(LineSeries::new(points.clone(), color.stroke_width(2)))
                        .map_err(text_error)?
                        .label(s.name.as_str())
                        .legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                        });
                    chart
                        .draw_series(points.iter().map(|&p| Circle::new(p, 3, color.filled())))
                        .map_err(text_error)?;
                }
                chart
                    .configure_series_labels()
                    .position(SeriesLabelPosition::UpperRight)
                    .label_font((FONT, 13))
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK)
                    .draw()
                    .map_err(text_error)?;
                Ok(())
            }};
        }
        match (axes.log_x, axes.log_y) {
            (true, true) => draw!(builder.build_cartesian_2d(xr.log_scale(), yr.log_scale())),
            (true, false) => draw!(builder.build_cartesian_2d(xr.log_scale(), yr)),
            (false, true) => draw!(builder.build_cartesian_2d(xr, yr.log_scale())),
            (false, false) => draw!(builder.build_cartesian_2d(xr, yr)),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plots_are_written_as_pngs() {
        let dir = std::env::temp_dir().join(format!("lumis-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        scatter(&dir.join("s.png"), "points", &[[0.1, 0.2], [0.7, 0.9]]).unwrap();
        let values: Vec<f64> = (0..64).map(|i| 1.0 + i as f64).collect();
        let grid = Grid {
            width: 8,
            height: 8,
            origin: (-4, -4),
            x_label: "k_x",
            y_label: "k_y",
            value_label: "log10 P",
        };
        heat_map(&dir.join("h.png"), "psd", &values, &grid, None).unwrap();
        let series = [Series {
            name: "a".into(),
            points: vec![(1.0, 1.0), (10.0, 0.1)],
            band: Some(vec![(1.0, 0.8, 1.2), (10.0, 0.08, 0.12)]),
        }];
        let axes = Axes {
            title: "t",
            x_label: "N",
            y_label: "RMSE",
            log_x: true,
            log_y: true,
        };
        line_plot(&dir.join("l.png"), &axes, &series).unwrap();
        for f in ["s.png", "h.png", "l.png"] {
            let bytes = std::fs::read(dir.join(f)).unwrap();
            assert_eq!(&bytes[1..4], b"PNG", "{f}");
        }
        let empty = Series {
            name: "e".into(),
            points: vec![(0.0, 0.0)],
            band: None,
        };
        assert!(line_plot(&dir.join("e.png"), &axes, &[empty]).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// All-zero and non-finite values (an image's error against itself, a
    /// NaN pixel) give a finite scale, so drawing it ends.
    #[test]
    fn degenerate_values_get_a_finite_scale() {
        for values in [
            vec![0.0; 4],
            vec![f64::INFINITY, 0.0],
            vec![f64::NAN, f64::NAN],
        ] {
            let (lo, hi) = log_range(&values, None);
            assert!(lo.is_finite() && hi.is_finite() && hi > lo, "{values:?}");
        }
        let (lo, hi) = log_range(&[1e-3, f64::INFINITY, 1e-1], None);
        assert_eq!((lo, hi), (-3.0, -1.0));
        let (lo, hi) = log_range(&[0.5, 0.5], None);
        assert!(hi - lo >= 1e-3 && lo == 0.5f64.log10());
        let dir = std::env::temp_dir().join(format!("lumis-plot-zero-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let grid = Grid {
            width: 2,
            height: 2,
            origin: (0, 0),
            x_label: "x",
            y_label: "y",
            value_label: "log10 error",
        };
        heat_map(&dir.join("z.png"), "zero", &[0.0; 4], &grid, None).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
