//! The picture of a song's analysis ([`crate::choreo::music`]): three panels over one time axis — the
//! waveform with the bars (numbered) and beats, the onset envelope the beats were placed on with
//! the beats, and each bar's intensity (RMS in dB) as a step over the bar.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::RenderError;
use crate::choreo::music::MusicAnalysis;

/// Size of the picture (pixels).
const SIZE: (u32, u32) = (1400, 960);

fn err<E: std::fmt::Display>(e: E) -> RenderError {
    RenderError::Encode(format!("music picture: {e}"))
}

/// Min and max of `samples` in each of `columns` equal spans.
fn envelope(samples: &[f32], columns: usize) -> Vec<(f64, f64)> {
    let n = samples.len();
    (0..columns)
        .map(|c| {
            let a = c * n / columns;
            let b = ((c + 1) * n / columns).max(a + 1).min(n);
            samples[a.min(n.saturating_sub(1))..b]
                .iter()
                .fold((0.0f64, 0.0f64), |(lo, hi), &s| {
                    (lo.min(s as f64), hi.max(s as f64))
                })
        })
        .collect()
}

/// Draws `analysis` of mono `samples` to the PNG `path`, titled `title` (e.g. the file name).
/// Errors: a path not ending in `.png`, no samples, encoding or writing.
pub fn music_png(
    analysis: &MusicAnalysis,
    samples: &[f32],
    title: &str,
    path: &Path,
) -> Result<(), RenderError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    if ext != "png" {
        return Err(RenderError::UnsupportedExtension {
            path: path.to_path_buf(),
            extension: ext,
            expected: ".png",
        });
    }
    if samples.is_empty() {
        return Err(RenderError::Empty("a song without samples".into()));
    }
    plotters::style::register_font(
        "sans-serif",
        plotters::style::FontStyle::Normal,
        super::FONT_TTF,
    )
    .map_err(|_| RenderError::Font("plotters rejected the bundled DejaVu Sans".into()))?;
    let (w, h) = SIZE;
    let mut rgb = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let root = root
            .titled(
                &format!(
                    "{title}: {:.2} BPM, {} beats, {}, {:.1} s",
                    analysis.tempo_bpm,
                    analysis.beats_s.len(),
                    analysis.bars_label(),
                    analysis.duration_s
                ),
                ("sans-serif", 24),
            )
            .map_err(err)?;
        let panels = root.split_evenly((3, 1));
        let t_end = analysis.duration_s.max(1e-3);
        waveform_panel(&panels[0], analysis, samples, t_end)?;
        onset_panel(&panels[1], analysis, t_end)?;
        intensity_panel(&panels[2], analysis, t_end)?;
        root.present().map_err(err)?;
    }
    let rgba: Vec<u8> = rgb
        .chunks_exact(3)
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect();
    let size = tiny_skia::IntSize::from_wh(w, h).ok_or_else(|| err("empty size"))?;
    let pixmap = tiny_skia::Pixmap::from_vec(rgba, size).ok_or_else(|| err("buffer size"))?;
    let png = pixmap.encode_png().map_err(err)?;
    crate::io::write_atomic(path, &png).map_err(|source| RenderError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// One of the picture's three panels.
type Panel<'a> = DrawingArea<BitMapBackend<'a>, Shift>;

/// Colour of the beats.
const BEAT: RGBColor = RGBColor(150, 150, 150);
/// Colour of the bars.
const BAR: RGBColor = RGBColor(213, 94, 0);
/// Colour of the waveform and the onset envelope.
const BLUE: RGBColor = RGBColor(0, 114, 178);

/// The top panel: the waveform (each column's min to max) with the bars' starts, numbered.
fn waveform_panel(
    panel: &Panel,
    analysis: &MusicAnalysis,
    samples: &[f32],
    t_end: f64,
) -> Result<(), RenderError> {
    let peak = samples.iter().fold(0f32, |m, s| m.max(s.abs())).max(1e-6) as f64;
    let mut c = ChartBuilder::on(panel)
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..t_end, -peak * 1.08..peak * 1.15)
        .map_err(err)?;
    c.configure_mesh()
        .disable_mesh()
        .y_desc("waveform")
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    let cols = 1300usize;
    let env = envelope(samples, cols);
    c.draw_series(env.iter().enumerate().map(|(i, &(lo, hi))| {
        let t = (i as f64 + 0.5) * t_end / cols as f64;
        PathElement::new(vec![(t, lo), (t, hi)], BLUE)
    }))
    .map_err(err)?;
    // Number the bars where a number fits after the previous one (about 7 px a digit on
    // the plot's ~1300 px): every bar while they fit, and no number over a short bar's.
    let s_per_px = t_end / cols as f64;
    let mut free_from = f64::NEG_INFINITY;
    for (k, b) in analysis.bars.iter().enumerate() {
        c.draw_series(std::iter::once(PathElement::new(
            vec![(b.start_s, -peak * 1.08), (b.start_s, peak * 1.15)],
            BAR.stroke_width(1),
        )))
        .map_err(err)?;
        let label = format!("{}", k + 1);
        if b.start_s >= free_from {
            free_from = b.start_s + (7.0 * label.len() as f64 + 4.0) * s_per_px;
            c.draw_series(std::iter::once(Text::new(
                label,
                (b.start_s, peak * 1.14),
                ("sans-serif", 12).into_font().color(&BAR),
            )))
            .map_err(err)?;
        }
    }
    Ok(())
}

/// The middle panel: the onset envelope and the beats tracked on it, with a legend.
fn onset_panel(panel: &Panel, analysis: &MusicAnalysis, t_end: f64) -> Result<(), RenderError> {
    let on = &analysis.onsets;
    let top = on.values.iter().fold(0.0f64, |m, &v| m.max(v)).max(1e-9);
    let mut c = ChartBuilder::on(panel)
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..t_end, 0.0..top * 1.05)
        .map_err(err)?;
    c.configure_mesh()
        .disable_mesh()
        .y_desc("onset strength")
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    for &b in &analysis.beats_s {
        c.draw_series(std::iter::once(PathElement::new(
            vec![(b, 0.0), (b, top * 1.05)],
            BEAT,
        )))
        .map_err(err)?;
    }
    c.draw_series(LineSeries::new(
        on.values
            .iter()
            .enumerate()
            .map(|(i, &v)| (on.time_of(i as f64), v)),
        BLUE,
    ))
    .map_err(err)?
    .label("onset envelope")
    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE));
    c.draw_series(std::iter::once(PathElement::new(
        vec![(0.0, 0.0), (0.0, 0.0)],
        BEAT,
    )))
    .map_err(err)?
    .label("beats (tracked)")
    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BEAT));
    c.configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    Ok(())
}

/// The bottom panel: each bar's intensity (RMS in dB) as a step over the bar.
fn intensity_panel(panel: &Panel, analysis: &MusicAnalysis, t_end: f64) -> Result<(), RenderError> {
    let (lo, hi) = analysis
        .bars
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), b| {
            (lo.min(b.rms_db), hi.max(b.rms_db))
        });
    let (lo, hi) = if lo.is_finite() {
        (lo - 3.0, hi + 3.0)
    } else {
        (-60.0, 0.0)
    };
    let mut c = ChartBuilder::on(panel)
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..t_end, lo..hi)
        .map_err(err)?;
    c.configure_mesh()
        .disable_mesh()
        .x_desc("time (s)")
        .y_desc("bar RMS (dB re 1)")
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    c.draw_series(analysis.bars.iter().map(|b| {
        PathElement::new(
            vec![(b.start_s, b.rms_db), (b.end_s, b.rms_db)],
            BAR.stroke_width(3),
        )
    }))
    .map_err(err)?;
    Ok(())
}
