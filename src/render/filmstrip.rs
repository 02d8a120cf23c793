//! A filmstrip: N instants of one or more motions in one PNG, one row per track, the time of
//! each column above it, like the sequence figures in the papers. The instants follow the
//! motion, not the clock: a jump gets columns, a body lying still does not.

use std::path::Path;

use ab_glyph::FontRef;
use tiny_skia::Pixmap;

use super::camera::{Camera, Eye, PanelLimits, View, scale_for};
use super::canvas::{
    INK, Style, WHITE, blit, draw_body, draw_key, encode_png, key_width, new_pixmap,
    panel_background, sheet_size,
};
use super::figure::{Side, Track, validate_tracks};
use super::text::{Align, Pen, ascent, draw_text, font};
use super::volume::Volumes;
use super::{RenderError, require_extension, write};
use crate::analysis::{ContactConfig, ground_contacts};
use glam::DVec3;

/// Height of each cell (pixels).
const CELL_HEIGHT: u32 = 220;
const MARGIN: u32 = 16;
/// Gap between cells of a row, and between rows (pixels).
const GAP: u32 = 6;
const ROW_GAP: u32 = 10;

/// [`filmstrip_view_png`] in the three-quarter view chosen from the motion
/// ([`super::camera::three_quarter`]: from in front and to the side, so that the travel crosses
/// the picture and the near and far limbs stand apart).
pub fn filmstrip_png(tracks: &[Track], n: usize, path: &Path) -> Result<(), RenderError> {
    filmstrip_view_png(tracks, n, View::ThreeQuarter, path)
}

/// Share of the column spacing given to elapsed time; the rest follows the motion.
const TIME_SHARE: f64 = 0.25;

/// The instants of a filmstrip of (at least) `n` columns, chosen by the motion of the first
/// track: a column at the apex of every flight it has ([`flight_apexes`]: both feet and the
/// body off the floor, the root highest), the others spread by distance travelled
/// ([`spread_times`], the first at t = 0 and the last at the end; each apex takes the place of
/// the spread column nearest to it). There are `n` columns, or more when the flights need them:
/// `flights + 2`, at most [`MAX_COLUMNS`] (then the flights with the highest apexes are kept). A figure without feet has no flights found: its inner
/// columns move to a root apex near them instead ([`snap_to_apexes`]).
pub(crate) fn column_times(tracks: &[Track], n: usize) -> Vec<f64> {
    if n == 1 {
        return spread_times(tracks, 1);
    }
    let Some(mut apexes) = flight_apexes(&tracks[0]) else {
        let mut times = spread_times(tracks, n);
        snap_to_apexes(&tracks[0], &mut times);
        return times;
    };
    if apexes.len() + 2 > MAX_COLUMNS {
        let y = |&(_, h): &(f64, f64)| h;
        apexes.sort_by(|a, b| y(b).total_cmp(&y(a)));
        apexes.truncate(MAX_COLUMNS - 2);
        apexes.sort_by(|a, b| a.0.total_cmp(&b.0));
    }
    // Each apex replaces the spread inner column nearest to it, so none lands beside another.
    let mut times = spread_times(tracks, n.max(apexes.len() + 2));
    let last = times.len() - 1;
    let mut free: Vec<usize> = (1..last).collect();
    for &(t, _) in &apexes {
        let Some(i) = (0..free.len()).min_by(|&a, &b| {
            (times[free[a]] - t)
                .abs()
                .total_cmp(&(times[free[b]] - t).abs())
        }) else {
            break;
        };
        times[free.swap_remove(i)] = t;
    }
    times.sort_by(f64::total_cmp);
    times
}

/// Most columns a filmstrip gets to show every flight.
pub(crate) const MAX_COLUMNS: usize = 64;

/// The flights of `track` and the instant of each one's apex: `(t, root height)` at the frame
/// of the root's highest point within each flight found by [`ground_contacts`] (default
/// settings) on its points: the foot points are those named like a foot (`foot`, `toe`,
/// `ankle`, `heel`, see [`super::side_from_name`]) and every point below them, by side; every
/// other point but a ground-proxy root is the body. `None` when a side has no foot point.
pub(crate) fn flight_apexes(track: &Track) -> Option<Vec<(f64, f64)>> {
    let fig = track.figure;
    let sides = fig.sides();
    let n = fig.names.len();
    let named_foot = |i: usize| {
        let name = fig.names[i].to_lowercase();
        ["foot", "toe", "ankle", "heel"]
            .iter()
            .any(|w| name.contains(w))
    };
    // A point is on a foot when it or a point above it is named like one.
    let foot: Vec<bool> = (0..n)
        .map(|i| {
            let mut j = Some(i);
            // At most n steps up: a cyclic figure is rejected before this, but never loops here.
            for _ in 0..=n {
                match j {
                    Some(k) if named_foot(k) => return true,
                    Some(k) => j = fig.parents[k],
                    None => break,
                }
            }
            false
        })
        .collect();
    let proxy = track
        .frames
        .first()
        .and_then(|f| super::figure::ground_proxy(fig, f));
    let pick = |want: &dyn Fn(usize) -> bool| -> Vec<Vec<DVec3>> {
        let idx: Vec<usize> = (0..n).filter(|&i| want(i)).collect();
        track
            .frames
            .iter()
            .map(|f| idx.iter().map(|&i| f[i]).collect())
            .collect()
    };
    let left = pick(&|i| foot[i] && sides[i] == Side::Left);
    let right = pick(&|i| foot[i] && sides[i] == Side::Right);
    if left.first().is_none_or(Vec::is_empty) || right.first().is_none_or(Vec::is_empty) {
        return None;
    }
    let body = pick(&|i| !foot[i] && Some(i) != proxy);
    let contacts = ground_contacts(
        &left,
        &right,
        &body,
        track.frame_time,
        &ContactConfig::default(),
    );
    let root = fig.root();
    Some(
        contacts
            .flights
            .iter()
            .map(|fl| {
                let (a, b) = (track.frame_at(fl.start_s), track.frame_at(fl.end_s));
                let top = (a..=b.max(a))
                    .max_by(|&p, &q| track.frames[p][root].y.total_cmp(&track.frames[q][root].y))
                    .unwrap_or(a);
                (top as f64 * track.frame_time, track.frames[top][root].y)
            })
            .collect(),
    )
}

/// `n` instants spread evenly in a blend of elapsed time and distance travelled. With D(t) the distance all points of all tracks have travelled up to t
/// (summed over frames at the finest frame time) and T the longest duration, the progress
/// u(t) = s·t/T + (1 − s)·D(t)/D(T), s = [`TIME_SHARE`]; column j is at the first t with
/// u(t) ≥ j/(n − 1), so the first column is t = 0 and the last t = T. A motion that does not
/// move is spread evenly in time; just t = 0 when n = 1.
fn spread_times(tracks: &[Track], n: usize) -> Vec<f64> {
    let duration = tracks.iter().map(Track::duration).fold(0.0, f64::max);
    if n == 1 {
        return vec![0.0];
    }
    let dt = tracks
        .iter()
        .map(|t| t.frame_time)
        .fold(f64::INFINITY, f64::min);
    let steps = if duration > 0.0 && dt.is_finite() && dt > 0.0 {
        (duration / dt).round() as usize
    } else {
        0
    };
    // Cumulative distance at every step.
    let mut travelled = vec![0.0; steps + 1];
    for k in 1..=steps {
        let (t0, t1) = ((k - 1) as f64 * dt, k as f64 * dt);
        let d: f64 = tracks
            .iter()
            .map(|tr| {
                let (a, b) = (&tr.frames[tr.frame_at(t0)], &tr.frames[tr.frame_at(t1)]);
                a.iter()
                    .zip(b)
                    .map(|(p, q)| (*q - *p).length())
                    .sum::<f64>()
            })
            .sum();
        travelled[k] = travelled[k - 1] + d;
    }
    let total = travelled[steps];
    let share = if total > 0.0 { TIME_SHARE } else { 1.0 };
    let progress = |k: usize| {
        let time = if steps == 0 {
            1.0
        } else {
            k as f64 / steps as f64
        };
        let moved = if total > 0.0 {
            travelled[k] / total
        } else {
            0.0
        };
        share * time + (1.0 - share) * moved
    };
    let mut k = 0;
    (0..n)
        .map(|j| {
            let goal = j as f64 / (n - 1) as f64;
            while k < steps && progress(k) < goal - 1e-12 {
                k += 1;
            }
            if j == n - 1 {
                duration
            } else {
                (k as f64 * dt).min(duration)
            }
        })
        .collect()
}

/// Moves each inner column to the apex of a jump near it: to the highest root of the first
/// track between the midpoints to its neighbours, when that is a peak inside the span (not at
/// its ends) rising more than [`APEX_RISE`] of the figure's height above the span's lowest root.
fn snap_to_apexes(track: &Track, times: &mut [f64]) {
    let root = track.figure.root();
    let y = |k: usize| track.frames[k][root].y;
    let height = track.frames.first().map_or(0.0, |f| {
        let hi = f.iter().map(|p| p.y).fold(f64::NEG_INFINITY, f64::max);
        let lo = f.iter().map(|p| p.y).fold(f64::INFINITY, f64::min);
        hi - lo
    });
    for j in 1..times.len().saturating_sub(1) {
        let a = track.frame_at(0.5 * (times[j - 1] + times[j]));
        let b = track.frame_at(0.5 * (times[j] + times[j + 1]));
        if b <= a + 2 {
            continue;
        }
        let top = (a..=b).max_by(|&p, &q| y(p).total_cmp(&y(q))).unwrap_or(a);
        let low = (a..=b).map(y).fold(f64::INFINITY, f64::min);
        if top > a && top < b && y(top) - low > APEX_RISE * height {
            times[j] = top as f64 * track.frame_time;
        }
    }
}

/// Least rise of the root above its lowest in a column's span, as a share of the figure's
/// height, for the column to move to that apex.
const APEX_RISE: f64 = 0.08;

/// Draws `n` instants of every track as a PNG at `path`, one row per track (its label above
/// it), in `view`, each frame's figure turned to face +Z by its own facing (see
/// [`super::facing`]) and drawn as volumes over its shadow ([`super::volume`]). Columns share one time t_j chosen by motion ([`column_times`]: a column at
/// every flight's apex of the first track, the rest spread by distance travelled; more than `n`
/// when the flights need them), written above each column; a shorter track holds its last frame. All cells
/// share one scale and one framing of the whole motion, so positions compare across the page;
/// a motion that travels further than a cell shows follows the root, with floor ticks every
/// 0.5 m. Footer: 1 m scale bar and left/right colour key.
pub fn filmstrip_view_png(
    tracks: &[Track],
    n: usize,
    view: View,
    path: &Path,
) -> Result<(), RenderError> {
    require_extension(path, "png")?;
    validate_tracks(tracks)?;
    if n == 0 {
        return Err(RenderError::InvalidArgument(
            "a filmstrip needs at least one column".into(),
        ));
    }
    draw_facing(tracks, view, path, |tracks| labelled_columns(tracks, n))
}

/// The columns of a filmstrip of `n`: [`column_times`], each moved onto the first track's frame
/// shown there (so the instant is one the track has), labelled with that frame's time,
/// "t = 1.23 s".
pub(crate) fn labelled_columns(tracks: &[Track], n: usize) -> (Vec<f64>, Vec<String>) {
    let first = &tracks[0];
    let times: Vec<f64> = column_times(tracks, n)
        .into_iter()
        .map(|t| first.frame_at(t) as f64 * first.frame_time)
        .collect();
    let labels = times.iter().map(|t| format!("t = {t:.2} s")).collect();
    (times, labels)
}

/// Draws `tracks` at the given instants (seconds), each column headed by its label, in `view`,
/// each frame turned to face +Z; otherwise as [`filmstrip_view_png`] (one scale and framing
/// for every cell, 1 m scale bar and colour key below). Used where the instants mean something
/// (a bar of a dance per column).
pub fn filmstrip_at_png(
    tracks: &[Track],
    times: &[f64],
    labels: &[String],
    view: View,
    path: &Path,
) -> Result<(), RenderError> {
    require_extension(path, "png")?;
    validate_tracks(tracks)?;
    if times.is_empty() || times.len() != labels.len() {
        return Err(RenderError::InvalidArgument(format!(
            "a filmstrip needs at least one column and a label per column ({} times, {} labels)",
            times.len(),
            labels.len()
        )));
    }
    draw_facing(tracks, view, path, |_| (times.to_vec(), labels.to_vec()))
}

/// Turns every figure to face +Z, frames them all at one scale in `view` and draws the columns
/// that `columns` chooses (instants in seconds and their labels) from the turned tracks.
fn draw_facing(
    tracks: &[Track],
    view: View,
    path: &Path,
    columns: impl FnOnce(&[Track]) -> (Vec<f64>, Vec<String>),
) -> Result<(), RenderError> {
    let turned = super::facing::turned_frames_each(tracks);
    let turned_tracks = super::facing::with_frames(tracks, &turned);
    let tracks = &turned_tracks[..];
    let eye = Eye::for_view(view, tracks);
    let (mpp, pad) = scale_for(tracks, &eye, CELL_HEIGHT);
    let limits = PanelLimits {
        height: CELL_HEIGHT,
        min_width: CELL_HEIGHT * 9 / 20,
        max_width: CELL_HEIGHT * 9 / 10,
    };
    let cam = Camera::fit(tracks, eye, mpp, pad, limits);
    let style = Style::for_height(CELL_HEIGHT.max(cam.height));
    let (times, labels) = columns(tracks);
    draw_columns(tracks, &times, &labels, &cam, style, mpp, path)
}

/// The row of column labels along the top of the sheet, each centred over its column.
fn draw_column_labels(
    sheet: &mut Pixmap,
    font: &FontRef,
    labels: &[String],
    cam: &Camera,
    style: Style,
) {
    let time_base = MARGIN as f32 + ascent(font, style.small);
    for (j, s) in labels.iter().enumerate() {
        let cx = (MARGIN + j as u32 * (cam.width + GAP)) as f32 + cam.width as f32 * 0.5;
        draw_text(
            sheet,
            font,
            s,
            (cx, time_base),
            Pen {
                size: style.small,
                rgb: INK,
                align: Align::Centre,
            },
        );
    }
}

/// The sheet of a filmstrip: a column per instant with its label above, a row per track.
fn draw_columns(
    tracks: &[Track],
    times: &[f64],
    labels: &[String],
    cam: &Camera,
    style: Style,
    mpp: f64,
    path: &Path,
) -> Result<(), RenderError> {
    let font = font()?;
    let n = times.len();

    let time_row = (style.small * 1.8) as u32;
    let label_row = (style.text * 1.7) as u32;
    let footer = (style.small * 2.6) as u32;
    let row = n as u64 * cam.width as u64 + (n as u64 - 1) * GAP as u64;
    let rows = tracks.len() as u64 * (label_row + cam.height + ROW_GAP) as u64;
    sheet_size(
        row + 2 * MARGIN as u64,
        rows + (MARGIN + time_row + footer) as u64,
    )?;
    let row_w = row as u32;
    let caption = cam.eye.caption();
    let key_w = key_width(font, mpp, row_w as f64 * 0.6, style, Some(&caption)) as u32;
    let width = 2 * MARGIN + row_w.max(key_w);
    let height = MARGIN + time_row + rows as u32 + footer;
    let mut sheet = new_pixmap(width, height, WHITE)?;

    let x0 = MARGIN;
    let mut y = MARGIN;
    draw_column_labels(&mut sheet, font, labels, cam, style);
    y += time_row;
    // The view's name is in the key, where no figure can cover it.
    let background = panel_background(cam, font, style, false)?;
    for track in tracks {
        let base = y as f32 + ascent(font, style.text);
        draw_text(
            &mut sheet,
            font,
            &track.label,
            (x0 as f32, base),
            Pen {
                size: style.text,
                rgb: INK,
                align: Align::Left,
            },
        );
        y += label_row;
        let body = Volumes::of(track);
        for (j, &t) in times.iter().enumerate() {
            let mut cell = background.clone();
            draw_body(&mut cell, cam, track, &body, track.frame_at(t), style);
            blit(&mut sheet, &cell, x0 + j as u32 * (cam.width + GAP), y);
        }
        y += cam.height + ROW_GAP;
    }
    let key_base = y as f32 + style.small * 1.2;
    draw_key(
        &mut sheet,
        font,
        x0 as f32,
        key_base,
        mpp,
        row_w as f64 * 0.6,
        style,
        Some(&caption),
    );
    write(path, &encode_png(&sheet)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::render::StickFigure;
    use crate::render::facing::tests::track;
    use glam::DVec3;

    #[test]
    fn every_flight_gets_a_column_at_its_apex() {
        // A figure standing on two feet (ankles 0.08 m up, toes on the floor) that jumps 0.5 m
        // forward three times, ballistic flights 1.0–1.4 s, 2.2–2.5 s and 3.3–3.8 s.
        let fig = StickFigure {
            names: [
                "pelvis",
                "left_ankle",
                "left_toe",
                "right_ankle",
                "right_toe",
                "head",
            ]
            .map(String::from)
            .to_vec(),
            parents: vec![None, Some(0), Some(1), Some(0), Some(3), Some(0)],
        };
        let flights = [(1.0, 1.4), (2.2, 2.5), (3.3, 3.8)];
        let dt = 0.01;
        let frames: Vec<Vec<DVec3>> = (0..=450)
            .map(|k| {
                let t = k as f64 * dt;
                let lift: f64 = flights
                    .iter()
                    .map(|&(a, b)| {
                        if t > a && t < b {
                            4.9 * (t - a) * (b - t)
                        } else {
                            0.0
                        }
                    })
                    .sum();
                let x: f64 = flights
                    .iter()
                    .map(|&(a, b)| 0.5 * ((t - a) / (b - a)).clamp(0.0, 1.0))
                    .sum();
                vec![
                    DVec3::new(x, 0.95 + lift, 0.0),
                    DVec3::new(x + 0.1, 0.08 + lift, 0.0),
                    DVec3::new(x + 0.1, lift, 0.15),
                    DVec3::new(x - 0.1, 0.08 + lift, 0.0),
                    DVec3::new(x - 0.1, lift, 0.15),
                    DVec3::new(x, 1.6 + lift, 0.0),
                ]
            })
            .collect();
        let tr = Track {
            figure: &fig,
            frames: &frames,
            label: "t".into(),
            frame_time: dt,
        };
        let apexes = flight_apexes(&tr).unwrap();
        assert_eq!(apexes.len(), 3, "{apexes:?}");
        // Fewer columns asked than flights: every apex still gets one, with the clip's ends.
        for n in [2, 4, 8] {
            let times = column_times(std::slice::from_ref(&tr), n);
            for &(a, b) in &flights {
                let apex = 0.5 * (a + b);
                assert!(
                    times.iter().any(|t| (t - apex).abs() < dt + 1e-9),
                    "n = {n}: no column at the apex {apex} s: {times:?}"
                );
            }
            assert_eq!(times.len(), n.max(5), "{times:?}");
            assert_eq!((times[0], *times.last().unwrap()), (0.0, 4.5));
            assert!(times.windows(2).all(|w| w[0] < w[1]), "{times:?}");
        }
        // Standing still is not a flight.
        let still = vec![frames[0].clone(); 200];
        let tr = Track {
            frames: &still,
            ..tr
        };
        assert_eq!(flight_apexes(&tr).unwrap(), vec![]);
    }

    #[test]
    fn each_column_is_labelled_with_the_time_of_the_frame_it_shows() {
        let fig = StickFigure {
            names: vec!["a".into()],
            parents: vec![None],
        };
        // A coarse first track (10 frames/s) beside a fine one (1/30 s): the columns are
        // spread on the fine clock but show the coarse track's frames.
        let fall: Vec<Vec<DVec3>> = (0..21)
            .map(|k| vec![DVec3::new(0.0, (1.0 - k as f64 * 0.07).max(0.0), 0.0)])
            .collect();
        let fine: Vec<Vec<DVec3>> = (0..61).map(|k| vec![DVec3::X * k as f64 * 0.01]).collect();
        let coarse = track(&fig, &fall);
        let other = Track {
            frames: &fine,
            frame_time: 1.0 / 30.0,
            ..coarse.clone()
        };
        let tracks = [coarse, other];
        let (times, labels) = labelled_columns(&tracks, 7);
        assert_eq!(times.len(), 7);
        for (t, label) in times.iter().zip(&labels) {
            let shown = tracks[0].frame_at(*t) as f64 * tracks[0].frame_time;
            let written: f64 = label
                .trim_start_matches("t = ")
                .trim_end_matches(" s")
                .parse()
                .unwrap();
            assert!(
                (written - shown).abs() < 0.005 + 1e-12,
                "{label} shows {shown} s"
            );
        }
    }

    #[test]
    fn columns_follow_the_motion_and_span_the_whole_duration() {
        let fig = StickFigure {
            names: vec!["a".into()],
            parents: vec![None],
        };
        // Still: evenly in time.
        let still = vec![vec![DVec3::ZERO]; 21];
        assert_eq!(
            column_times(&[track(&fig, &still)], 5),
            vec![0.0, 0.5, 1.0, 1.5, 2.0]
        );
        assert_eq!(column_times(&[track(&fig, &still)], 1), vec![0.0]);
        // Moving during the first 0.5 s of 2 s, then lying still: most columns in the motion.
        let fall: Vec<Vec<DVec3>> = (0..21)
            .map(|k| vec![DVec3::new(0.0, (1.0 - k as f64 * 0.2).max(0.0), 0.0)])
            .collect();
        let times = column_times(&[track(&fig, &fall)], 8);
        assert_eq!((times[0], times[7]), (0.0, 2.0));
        let moving = times.iter().filter(|&&t| t <= 0.5).count();
        assert!(moving >= 5, "{times:?}");
        assert!(times.windows(2).all(|w| w[0] <= w[1]), "{times:?}");
    }
}
