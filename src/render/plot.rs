//! Line plots (joint angles, fitness per generation, head height over time …) with plotters:
//! title, axis labels, legend, and vertical event markers with labels; PNG or SVG by extension.

use std::path::Path;

use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::text::register_plot_font;
use super::{RenderError, extension, write};

/// One named curve: points (x, y) in the plot's units, drawn in order.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend entry.
    pub name: String,
    /// The points (x, y), joined by straight lines in the given order.
    pub points: Vec<(f64, f64)>,
}

/// A line plot: curves sharing axes, plus labelled vertical lines at chosen x (events such as
/// "push", "contact", "beat").
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Plot {
    /// Title above the plot.
    pub title: String,
    /// Label of the x axis, with units (e.g. "time (s)").
    pub x_label: String,
    /// Label of the y axis, with units (e.g. "left knee flexion (°)").
    pub y_label: String,
    /// The curves.
    pub series: Vec<Series>,
    /// Vertical dashed lines at x with a label each.
    pub markers: Vec<(f64, String)>,
}

/// Size of a plot (pixels; the SVG's nominal size).
const SIZE: (u32, u32) = (900, 540);

/// Supersampling factor of PNG plots (per axis).
const SUPERSAMPLE: u32 = 2;

/// Averages each k×k block of an RGB image of (w·k)×(h·k) pixels into one opaque RGBA pixel.
fn downsample(rgb: &[u8], w: usize, h: usize, k: usize) -> Vec<u8> {
    let mut out = Vec::with_capacity(w * h * 4);
    let row = w * k * 3;
    for y in 0..h {
        for x in 0..w {
            let mut acc = [0u32; 3];
            for dy in 0..k {
                let base = (y * k + dy) * row + x * k * 3;
                for dx in 0..k {
                    for c in 0..3 {
                        acc[c] += rgb[base + dx * 3 + c] as u32;
                    }
                }
            }
            let n = (k * k) as u32;
            out.extend(acc.map(|a| ((a + n / 2) / n) as u8));
            out.push(255);
        }
    }
    out
}

/// Okabe–Ito colours, distinguishable with colour-vision deficiencies, in order of use.
const COLOURS: [RGBColor; 8] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(86, 180, 233),
    RGBColor(230, 159, 0),
    RGBColor(0, 0, 0),
    RGBColor(240, 228, 66),
];

/// Draws `plot` to `path`: PNG for `.png`, SVG for `.svg`. The axes span the data (and the
/// markers) with a 5 % margin; series cycle through eight colour-blind-safe colours, with dots
/// at the points when a series has at most 40 of them; the legend goes to the corner with the
/// fewest data points; text uses the bundled DejaVu Sans.
pub fn plot(plot: &Plot, path: &Path) -> Result<(), RenderError> {
    let ext = extension(path);
    if ext != "png" && ext != "svg" {
        return Err(RenderError::UnsupportedExtension {
            path: path.to_path_buf(),
            extension: ext,
            expected: ".png or .svg",
        });
    }
    validate(plot)?;
    register_plot_font()?;
    let (w, h) = SIZE;
    let bytes = if ext == "svg" {
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
            draw(plot, &root, 1)?;
            root.present().map_err(plot_err)?;
        }
        svg.into_bytes()
    } else {
        // plotters' bitmap lines are not anti-aliased: draw at SUPERSAMPLE× the size and
        // average each SUPERSAMPLE² block of pixels.
        let k = SUPERSAMPLE;
        let mut rgb = vec![0u8; (w * h * 3 * k * k) as usize];
        {
            let root = BitMapBackend::with_buffer(&mut rgb, (w * k, h * k)).into_drawing_area();
            draw(plot, &root, k)?;
            root.present().map_err(plot_err)?;
        }
        let rgba = downsample(&rgb, w as usize, h as usize, k as usize);
        let size = tiny_skia::IntSize::from_wh(w, h)
            .ok_or_else(|| RenderError::Encode("empty plot size".into()))?;
        let pixmap = tiny_skia::Pixmap::from_vec(rgba, size)
            .ok_or_else(|| RenderError::Encode("plot buffer of the wrong size".into()))?;
        super::canvas::encode_png(&pixmap)?
    };
    write(path, &bytes)
}

/// The label of tick `v` on an axis of counts: the whole number it is (within rounding of the
/// tick arithmetic), nothing between two whole numbers.
fn whole_label(v: f64) -> String {
    let r = v.round();
    if (v - r).abs() <= 1e-9 * r.abs().max(1.0) {
        // `+ 0.0` turns a −0 into 0.
        format!("{}", r + 0.0)
    } else {
        String::new()
    }
}

/// The decimals that tell apart the ticks of an axis spanning `span`: its labelled ticks are
/// at least a tenth of the span apart, at 1, 2 or 5 times a power of ten.
fn decimals_for(span: f64) -> usize {
    if !(span > 0.0 && span.is_finite()) {
        return 0;
    }
    (-(span / 10.0).log10().floor()).clamp(0.0, 9.0) as usize
}

/// Tick `v` with `decimals` decimals (no "−0").
fn fixed_label(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    if s.trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        s.trim_start_matches('-').to_string()
    } else {
        s
    }
}

fn plot_err<E: std::fmt::Display>(e: E) -> RenderError {
    RenderError::Encode(format!("plot: {e}"))
}

/// Requires some data and only finite numbers.
fn validate(plot: &Plot) -> Result<(), RenderError> {
    if plot.series.iter().all(|s| s.points.is_empty()) {
        return Err(RenderError::Empty(format!(
            "plot '{}' has no data points",
            plot.title
        )));
    }
    for s in &plot.series {
        if let Some(i) = s
            .points
            .iter()
            .position(|(x, y)| !(x.is_finite() && y.is_finite()))
        {
            return Err(RenderError::NonFinitePlot {
                plot: plot.title.clone(),
                series: s.name.clone(),
                index: i,
                x: s.points[i].0,
                y: s.points[i].1,
            });
        }
    }
    if let Some(i) = plot.markers.iter().position(|(x, _)| !x.is_finite()) {
        return Err(RenderError::NonFinitePlot {
            plot: plot.title.clone(),
            series: "markers".into(),
            index: i,
            x: plot.markers[i].0,
            y: 0.0,
        });
    }
    Ok(())
}

/// The range [lo, hi] widened by `margin` of its width on each side; a zero-width range becomes
/// lo ± max(0.5, 5 % of |lo|).
pub(crate) fn padded(lo: f64, hi: f64, margin: f64) -> (f64, f64) {
    if hi - lo <= f64::EPSILON * lo.abs().max(1.0) {
        let d = (lo.abs() * 0.05).max(0.5);
        return (lo - d, hi + d);
    }
    let d = (hi - lo) * margin;
    (lo - d, hi + d)
}

/// Share of series `a`'s points that series `b` (drawn later) covers: same x sample and y
/// within `tol`; 0 when their samples differ.
fn covered(a: &Series, b: &Series, tol: f64) -> f64 {
    if a.points.len() != b.points.len() || a.points.is_empty() {
        return 0.0;
    }
    let same = a
        .points
        .iter()
        .zip(&b.points)
        .filter(|(p, q)| p.0 == q.0 && (p.1 - q.1).abs() <= tol)
        .count();
    same as f64 / a.points.len() as f64
}

/// For each series, the later series drawn over it and the share of its points that one
/// hides (the most-covering later series, when it covers at least [`MOSTLY_HIDDEN`]): y within
/// 0.5 % of the y range `span` (e.g. left and right knee of a symmetric jump).
pub(crate) fn hidden_by(plot: &Plot, span: f64) -> Vec<Option<(usize, f64)>> {
    let tol = 0.005 * span.abs().max(1e-12);
    let n = plot.series.len();
    (0..n)
        .map(|i| {
            (i + 1..n)
                .map(|k| (k, covered(&plot.series[i], &plot.series[k], tol)))
                .filter(|&(_, c)| c >= MOSTLY_HIDDEN)
                .max_by(|a, b| a.1.total_cmp(&b.1))
        })
        .collect()
}

/// Share of a curve's points hidden under a later one from which its legend says so.
const MOSTLY_HIDDEN: f64 = 0.9;

/// The legend corner with the fewest data points in the 40 % × 35 % box next to it; only the
/// lower corners when the plot has event markers, whose labels run along the top.
fn legend_corner(plot: &Plot, x: (f64, f64), y: (f64, f64)) -> SeriesLabelPosition {
    let fx = |v: f64| (v - x.0) / (x.1 - x.0);
    let fy = |v: f64| (v - y.0) / (y.1 - y.0);
    let corners = [
        (SeriesLabelPosition::UpperRight, true, true),
        (SeriesLabelPosition::UpperLeft, false, true),
        (SeriesLabelPosition::LowerRight, true, false),
        (SeriesLabelPosition::LowerLeft, false, false),
    ];
    let count = |right: bool, upper: bool| {
        plot.series
            .iter()
            .flat_map(|s| &s.points)
            .filter(|&&(px, py)| {
                let (u, v) = (fx(px), fy(py));
                (if right { u > 0.6 } else { u < 0.4 }) && (if upper { v > 0.65 } else { v < 0.35 })
            })
            .count()
    };
    let mut best = (usize::MAX, SeriesLabelPosition::UpperRight);
    for (pos, right, upper) in corners {
        if upper && !plot.markers.is_empty() {
            continue;
        }
        let c = count(right, upper);
        if c < best.0 {
            best = (c, pos);
        }
    }
    best.1
}

/// The chart a plot is drawn on: x and y in the plot's units.
type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Draws the plot on `root`, every length and font size multiplied by `k` (supersampling).
fn draw<DB: DrawingBackend>(
    plot: &Plot,
    root: &DrawingArea<DB, Shift>,
    k: u32,
) -> Result<(), RenderError> {
    let font = |size: u32| ("sans-serif", size * k);
    root.fill(&WHITE).map_err(plot_err)?;
    let (x, y) = axis_ranges(plot);
    let chart = ChartBuilder::on(root)
        .caption(&plot.title, font(26).into_font().color(&BLACK))
        .margin(18 * k)
        .x_label_area_size(56 * k)
        .y_label_area_size(84 * k)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)
        .map_err(plot_err)?;
    let mut drawing = Drawing { chart, plot, k };
    drawing.mesh(x, y)?;
    drawing.markers(y)?;
    drawing.curves(y)?;
    drawing
        .chart
        .configure_series_labels()
        .position(legend_corner(plot, x, y))
        .margin(12 * k)
        .legend_area_size(34 * k)
        .background_style(WHITE.mix(0.9))
        .border_style(RGBColor(160, 160, 160).stroke_width(k))
        .label_font(font(16))
        .draw()
        .map_err(plot_err)?;
    Ok(())
}

/// The x and y ranges of the plot: its points and markers with margins, and head-room along
/// the top for the marker labels.
fn axis_ranges(plot: &Plot) -> ((f64, f64), (f64, f64)) {
    let pts = || plot.series.iter().flat_map(|s| s.points.iter().copied());
    let xs = pts().map(|p| p.0).chain(plot.markers.iter().map(|m| m.0));
    let (x_lo, x_hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |a, v| {
        (a.0.min(v), a.1.max(v))
    });
    let (y_lo, y_hi) = pts().fold((f64::INFINITY, f64::NEG_INFINITY), |a, p| {
        (a.0.min(p.1), a.1.max(p.1))
    });
    let x = padded(x_lo, x_hi, 0.02);
    let mut y = padded(y_lo, y_hi, 0.06);
    if !plot.markers.is_empty() {
        // Head-room for the marker labels along the top.
        y.1 += (y.1 - y.0) * 0.08;
    }
    (x, y)
}

/// A plot being drawn on its chart, every length and font size multiplied by `k`.
struct Drawing<'a, 'p, DB: DrawingBackend> {
    chart: Chart<'a, DB>,
    plot: &'p Plot,
    k: u32,
}

impl<DB: DrawingBackend> Drawing<'_, '_, DB> {
    /// The axes, their labels and the grid, for the ranges `x` and `y`.
    fn mesh(&mut self, x: (f64, f64), y: (f64, f64)) -> Result<(), RenderError> {
        let (chart, plot, k) = (&mut self.chart, self.plot, self.k);
        let font = |size: u32| ("sans-serif", size * k);
        let pts = || plot.series.iter().flat_map(|s| s.points.iter().copied());
        // An axis of counts (generations, bars, frames: every x whole) is labelled with whole
        // numbers only; otherwise each axis with the decimals its tick spacing needs (no "5000.0").
        let counts =
            pts().all(|p| p.0.fract() == 0.0) && plot.markers.iter().all(|m| m.0.fract() == 0.0);
        let (dx, dy) = (decimals_for(x.1 - x.0), decimals_for(y.1 - y.0));
        let x_labels = |v: &f64| {
            if counts {
                whole_label(*v)
            } else {
                fixed_label(*v, dx)
            }
        };
        let y_labels = |v: &f64| fixed_label(*v, dy);
        let mut mesh = chart.configure_mesh();
        mesh.x_label_formatter(&x_labels)
            .y_label_formatter(&y_labels);
        mesh.x_desc(plot.x_label.as_str())
            .y_desc(plot.y_label.as_str())
            .axis_desc_style(font(19))
            .label_style(font(16))
            .bold_line_style(RGBColor(225, 225, 225).stroke_width(k))
            .light_line_style(RGBColor(245, 245, 245).stroke_width(k))
            .axis_style(RGBColor(90, 90, 90).stroke_width(k))
            .max_light_lines(3)
            .draw()
            .map_err(plot_err)
    }

    /// The event markers: a dashed vertical line each, its label along the top (staggered over
    /// three rows).
    fn markers(&mut self, y: (f64, f64)) -> Result<(), RenderError> {
        let (chart, plot, k) = (&mut self.chart, self.plot, self.k);
        let ki = k as i32;
        let grey = RGBColor(110, 110, 110);
        for (i, (mx, label)) in plot.markers.iter().enumerate() {
            chart
                .draw_series(DashedLineSeries::new(
                    [(*mx, y.0), (*mx, y.1)],
                    6 * k,
                    4 * k,
                    grey.stroke_width(k),
                ))
                .map_err(plot_err)?;
            // Stagger labels over three rows so that close events stay readable.
            let row = (i % 3) as i32;
            let text = EmptyElement::at((*mx, y.1))
                + Text::new(
                    label.clone(),
                    (4 * ki, (4 + 18 * row) * ki),
                    ("sans-serif", 15 * k).into_font().color(&grey),
                );
            chart.draw_series(std::iter::once(text)).map_err(plot_err)?;
        }
        Ok(())
    }

    /// The curves with their legend entries (dots on curves of 40 points or fewer); a curve wholly
    /// hidden under a later one gets no entry, the one on top names both; one mostly hidden says
    /// under which.
    fn curves(&mut self, y: (f64, f64)) -> Result<(), RenderError> {
        let (chart, plot, k) = (&mut self.chart, self.plot, self.k);
        let ki = k as i32;
        let hidden = hidden_by(plot, y.1 - y.0);
        let whole = |j: usize| hidden[j].is_some_and(|(_, c)| c >= 1.0);
        for (i, s) in plot.series.iter().enumerate() {
            let c = COLOURS[i % COLOURS.len()];
            let style = c.stroke_width(2 * k);
            let drawn = chart
                .draw_series(LineSeries::new(s.points.iter().copied(), style))
                .map_err(plot_err)?;
            if !whole(i) {
                let under: Vec<&str> = (0..i)
                    .filter(|&j| whole(j) && hidden[j].is_some_and(|(t, _)| t == i))
                    .map(|j| plot.series[j].name.as_str())
                    .collect();
                let mut label = if under.is_empty() {
                    s.name.clone()
                } else {
                    format!("{} = {} (overlap)", s.name, under.join(" = "))
                };
                if let Some((top, _)) = hidden[i] {
                    label.push_str(&format!(" (mostly under {})", plot.series[top].name));
                }
                drawn.label(label).legend(move |(lx, ly)| {
                    PathElement::new(vec![(lx, ly), (lx + 24 * ki, ly)], c.stroke_width(3 * k))
                });
            }
            if s.points.len() <= 40 {
                chart
                    .draw_series(s.points.iter().map(|&p| Circle::new(p, 3 * ki, c.filled())))
                    .map_err(plot_err)?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_get_margins_and_flat_ranges_get_width() {
        assert_eq!(padded(0.0, 10.0, 0.1), (-1.0, 11.0));
        let (lo, hi) = padded(3.0, 3.0, 0.1);
        assert!(lo < 3.0 && hi > 3.0);
        let (lo, hi) = padded(100.0, 100.0, 0.1);
        assert_eq!((lo, hi), (95.0, 105.0));
    }

    #[test]
    fn a_curve_hidden_under_another_is_named_with_it() {
        let line = |name: &str, dy: f64| Series {
            name: name.into(),
            points: (0..10).map(|i| (i as f64, i as f64 + dy)).collect(),
        };
        let p = Plot {
            title: "t".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            series: vec![line("left", 0.0), line("right", 0.001), line("other", 3.0)],
            markers: vec![],
        };
        assert_eq!(hidden_by(&p, 12.0), [Some((1, 1.0)), None, None]);
        // Apart in 1 point of 10: mostly hidden.
        let mut p = p;
        p.series[1].points[3].1 += 5.0;
        assert_eq!(hidden_by(&p, 12.0), [Some((1, 0.9)), None, None]);
    }

    #[test]
    fn legend_avoids_the_data() {
        // A rising line fills the lower-left and upper-right corners.
        let p = Plot {
            series: vec![Series {
                name: "up".into(),
                points: (0..=100).map(|i| (i as f64, i as f64)).collect(),
            }],
            ..Plot::default()
        };
        let pos = legend_corner(&p, (0.0, 100.0), (0.0, 100.0));
        assert!(matches!(
            pos,
            SeriesLabelPosition::UpperLeft | SeriesLabelPosition::LowerRight
        ));
    }

    /// The tick labels of an SVG plot (the text of its `<text>` elements that parse as numbers).
    fn numeric_labels(plot_: &Plot, name: &str) -> Vec<String> {
        let path =
            std::env::temp_dir().join(format!("marionette-{}-{name}.svg", std::process::id()));
        plot(plot_, &path).unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        let _ = std::fs::remove_file(&path);
        svg.split("<text")
            .skip(1)
            .filter_map(|t| {
                let s = t.split_once('>')?.1.split_once('<')?.0.trim();
                s.parse::<f64>().is_ok().then(|| s.to_string())
            })
            .collect()
    }

    #[test]
    fn an_axis_of_counts_is_labelled_with_whole_numbers() {
        assert_eq!(whole_label(4.000_000_000_000_001), "4");
        assert_eq!(whole_label(-0.0), "0");
        assert_eq!(whole_label(2.5), "");
        assert_eq!(
            (
                decimals_for(20_000.0),
                decimals_for(3.0),
                decimals_for(0.02)
            ),
            (0, 1, 3)
        );
        assert_eq!(fixed_label(-0.0001, 2), "0.00");
        assert_eq!(fixed_label(0.25, 1), "0.2");
        // Fitness over 20 generations: whole generations on the x axis.
        let gens = Plot {
            series: vec![Series {
                name: "best".into(),
                points: (0..=20)
                    .map(|g| (g as f64, 1000.0 - 3.0 * g as f64))
                    .collect(),
            }],
            ..Plot::default()
        };
        let labels = numeric_labels(&gens, "counts");
        // The damages are near 1000: every label from 0 to 20 is a generation's.
        let x: Vec<&String> = labels
            .iter()
            .filter(|l| (0.0..=20.0).contains(&l.parse::<f64>().unwrap()))
            .collect();
        assert!(x.iter().any(|l| *l == "10"), "{labels:?}");
        assert!(x.iter().all(|l| !l.contains('.')), "{labels:?}");
        // Over 2 generations the ticks between whole ones are left blank.
        let short = Plot {
            series: vec![Series {
                name: "best".into(),
                points: vec![(0.0, 5.0), (1.0, 4.0), (2.0, 3.5)],
            }],
            ..Plot::default()
        };
        let labels = numeric_labels(&short, "short");
        for g in ["0", "1", "2"] {
            assert!(labels.iter().any(|l| l == g), "{g} in {labels:?}");
        }
        let x = labels
            .iter()
            .filter(|l| (0.0..=2.0).contains(&l.parse::<f64>().unwrap()));
        assert!(x.clone().all(|l| !l.contains('.')), "{labels:?}");
        // Time in seconds keeps its fractions.
        let time = Plot {
            series: vec![Series {
                name: "height".into(),
                points: (0..=30).map(|k| (k as f64 * 0.1, 100.0)).collect(),
            }],
            ..Plot::default()
        };
        // The heights are near 100: every label below 3 is a time's.
        let labels = numeric_labels(&time, "time");
        let fractions = labels.iter().filter(|l| {
            let v = l.parse::<f64>().unwrap();
            v > 0.0 && v < 3.0 && v.fract() != 0.0
        });
        assert!(fractions.count() >= 2, "{labels:?}");
    }

    #[test]
    fn bad_plots_are_errors() {
        let dir = std::env::temp_dir();
        let empty = Plot::default();
        assert!(matches!(
            plot(&empty, &dir.join("marionette-empty.png")),
            Err(RenderError::Empty(_))
        ));
        let nan = Plot {
            series: vec![Series {
                name: "s".into(),
                points: vec![(0.0, 1.0), (1.0, f64::NAN)],
            }],
            ..Plot::default()
        };
        assert!(matches!(
            plot(&nan, &dir.join("marionette-nan.png")),
            Err(RenderError::NonFinitePlot { index: 1, .. })
        ));
        assert!(matches!(
            plot(&nan, &dir.join("marionette.jpg")),
            Err(RenderError::UnsupportedExtension { .. })
        ));
    }
}
