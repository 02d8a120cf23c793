//! The results page: one self-contained `index.html` (styles, scripts, motion data and song
//! inside it; nothing fetched) that shows motions in 3-D with a shared timeline, the scene's
//! plots with a cursor on that timeline and the report's headline figures in words.
//!
//! The Rust side takes typed data ([`Page`]) and writes the page ([`page_html`],
//! [`write_page`]). Sizes are kept small: positions are quantised to whole millimetres (int16,
//! little-endian, base64), the song is resampled to [`SONG_RATE`] Hz mono 16-bit WAV. A page
//! whose motion data would pass [`MAX_PAGE_VALUES`] numbers is decimated in time (every k-th
//! frame of every motion) and says so on the page, so a page of a long capture still opens
//! without freezing a browser. The 3-D view's camera (orbit, zoom, floor grid) is the editor's
//! ([`ORBIT_JS`]).

use std::path::Path;

use glam::DVec3;
use serde_json::json;

use super::{Plot, RenderError, StickFigure};

/// The orbit camera shared by the results page and the editor: a canvas, drag to orbit, wheel
/// to zoom, a projection and a floor grid (a plain script defining `class OrbitView`).
pub const ORBIT_JS: &str = include_str!("orbit.js");
const PAGE_JS: &str = include_str!("page.js");
const PAGE_CSS: &str = include_str!("page.css");

/// Most numbers (coordinates) of motion data a page holds; above it frames are decimated.
/// At about 2.7 bytes a number in base64 int16 this keeps the motion data under 8 MB.
pub const MAX_PAGE_VALUES: usize = 3_000_000;
/// Sample rate of the song in a page (Hz, mono, 16-bit).
pub const SONG_RATE: u32 = 16_000;
/// Longest song a page holds (s); a longer one is left out and the page says so.
pub const MAX_SONG_S: f64 = 900.0;

/// A contact box of one link in one frame, in world coordinates (metres, Y up).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PageBox {
    /// Centre of the box.
    pub center: DVec3,
    /// The box's three half-edges as vectors (its axes times its half sizes).
    pub half_axes: [DVec3; 3],
}

/// Something that happens in a motion at a time, marked on the timeline and in the 3-D view.
#[derive(Clone, Debug, PartialEq)]
pub struct PageEvent {
    /// Time on the motion's own clock (s, frame 0 at 0).
    pub time_s: f64,
    /// What happens, in words (e.g. "head touches the floor at 5.1 m/s; its peak floor
    /// force 2859 N"), for the motion's list.
    pub label: String,
    /// A few words written beside the point in the 3-D view (e.g. "head 2859 N").
    pub tag: String,
    /// The point (index into the figure) it happens at, if any: marked with a ring.
    pub point: Option<usize>,
}

/// One motion: a figure, its global point positions per frame and what to draw with them.
#[derive(Clone, Debug, PartialEq)]
pub struct PageMotion {
    /// Name shown in the motion list.
    pub label: String,
    /// Point names and parents; bones are drawn as capsules when `boxes` is `None`.
    pub figure: StickFigure,
    /// Time between frames (s).
    pub frame_time: f64,
    /// Time on the shared timeline of frame 0 (s); the first frame is held before it.
    pub start_s: f64,
    /// `frames[k][i]`: global position of point `i` in frame `k` (metres, Y up, floor y = 0).
    pub frames: Vec<Vec<DVec3>>,
    /// Contact boxes per frame (`boxes[k][link]`), drawn instead of capsules when given.
    pub boxes: Option<Vec<Vec<PageBox>>>,
    /// Names of the links of `boxes`.
    pub box_names: Vec<String>,
    /// Events (impacts, peaks).
    pub events: Vec<PageEvent>,
}

impl PageMotion {
    /// A drawn track as a page motion: its bones become capsules; frame 0 at time 0, no events.
    pub fn from_track(track: &super::Track) -> PageMotion {
        PageMotion {
            label: track.label.clone(),
            figure: track.figure.clone(),
            frame_time: track.frame_time,
            start_s: 0.0,
            frames: track.frames.to_vec(),
            boxes: None,
            box_names: vec![],
            events: vec![],
        }
    }
}

/// A plot on the page; when `time_axis`, its x is time on the shared timeline (s) and a cursor
/// follows the playhead.
#[derive(Clone, Debug)]
pub struct PagePlot {
    /// Title, axes, series, markers.
    pub plot: Plot,
    /// Whether x is time on the shared timeline (s).
    pub time_axis: bool,
}

/// A song played in sync with the timeline.
#[derive(Clone, Debug)]
pub struct PageSong {
    /// Mono samples, full scale ±1.
    pub samples: Vec<f32>,
    /// Their rate (Hz).
    pub sample_rate: u32,
    /// Time on the shared timeline of the song's first sample (s).
    pub start_s: f64,
}

/// Everything a results page shows.
#[derive(Clone, Debug, Default)]
pub struct Page {
    /// The page's title (the scene's name and kind).
    pub title: String,
    /// The report's headline figures, one sentence each.
    pub headline: Vec<String>,
    /// Every motion of the scene.
    pub motions: Vec<PageMotion>,
    /// The scene's plots.
    pub plots: Vec<PagePlot>,
    /// The song, if the scene has one.
    pub song: Option<PageSong>,
    /// Notes shown under the headline (what colours mean, what was left out).
    pub notes: Vec<String>,
}

/// Standard base64 with padding.
fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                s.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

/// Decodes [`base64`] (the inverse, for tests); `None` on a bad character.
#[cfg(test)]
fn unbase64(s: &str) -> Option<Vec<u8>> {
    let val = |c: u8| -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            _ => return None,
        } as u32)
    };
    let mut out = Vec::with_capacity(s.len() / 4 * 3);
    for c in s.as_bytes().chunks(4) {
        let pad = c.iter().filter(|&&b| b == b'=').count();
        let mut n = 0u32;
        for &b in c {
            n = n << 6 | if b == b'=' { 0 } else { val(b)? };
        }
        let bytes = [(n >> 16) as u8, (n >> 8) as u8, n as u8];
        out.extend_from_slice(&bytes[..3 - pad]);
    }
    Some(out)
}

/// Quantises `values` (metres) to whole multiples of `unit` metres as int16 little-endian,
/// base64. Errors, naming `what`, when a value does not fit 16 bits.
fn encode(values: impl Iterator<Item = f64>, unit: f64, what: &str) -> Result<String, RenderError> {
    let mut bytes = Vec::new();
    for v in values {
        let q = (v / unit).round();
        if q.abs() > i16::MAX as f64 {
            return Err(RenderError::InvalidArgument(format!(
                "{what}: {v:.1} m is beyond the ±{:.0} m a page stores (16 bits of {unit} m)",
                i16::MAX as f64 * unit
            )));
        }
        bytes.extend_from_slice(&(q as i16).to_le_bytes());
    }
    Ok(base64(&bytes))
}

/// Points as whole millimetres (int16, base64): each within 32 m of its frame's origin.
fn encode_points(points: &[DVec3], what: &str) -> Result<String, RenderError> {
    encode(points.iter().flat_map(|p| p.to_array()), 0.001, what)
}

/// Decodes [`encode`]: values in metres.
#[cfg(test)]
fn decode(s: &str, unit: f64) -> Option<Vec<f64>> {
    Some(
        unbase64(s)?
            .chunks_exact(2)
            .map(|c| i16::from_le_bytes([c[0], c[1]]) as f64 * unit)
            .collect(),
    )
}

/// Decodes [`encode_points`] as points (metres).
#[cfg(test)]
fn decode_points(s: &str) -> Option<Vec<DVec3>> {
    Some(
        decode(s, 0.001)?
            .chunks_exact(3)
            .map(|c| DVec3::new(c[0], c[1], c[2]))
            .collect(),
    )
}

/// Stands a motion of unknown conventions up on the floor. Up is the mean direction, over
/// the motion, from the root to the trunk's branching point (the deepest point with three or
/// more children: the chest, where neck and arms meet); a figure without one takes the axis
/// along which its bones run most and the side of the root holding most of its points. The
/// motion is turned so that the axis of that direction (±X, ±Y or ±Z) becomes +Y, then moved
/// vertically so its lowest point over the whole motion is on the floor (y = 0). Returns what
/// was done, in words, or `None` when the motion already stood on its floor (within 1 cm).
pub fn stand_upright(m: &mut PageMotion) -> Option<String> {
    let n = m.frames.len();
    let parents = &m.figure.parents;
    if n == 0 || parents.is_empty() {
        return None;
    }
    let chest = trunk_branch(parents);
    let (axis, sign) = up_axis(&m.frames, parents, chest);
    let mut said = vec![];
    if axis != 1 || sign < 0.0 {
        // A proper rotation taking the found up direction to +Y.
        let from = DVec3::AXES[axis] * sign;
        let turn = glam::DQuat::from_rotation_arc(from, DVec3::Y);
        for f in &mut m.frames {
            for p in f.iter_mut() {
                *p = turn * *p;
            }
        }
        said.push(format!(
            "turned so that its up axis ({}{}) is up",
            if sign < 0.0 { "-" } else { "+" },
            ["X", "Y", "Z"][axis]
        ));
    }
    let lowest = m
        .frames
        .iter()
        .flat_map(|f| f.iter().map(|p| p.y))
        .fold(f64::INFINITY, f64::min);
    if lowest.abs() > 0.01 {
        for f in &mut m.frames {
            for p in f.iter_mut() {
                p.y -= lowest;
            }
        }
        said.push(format!(
            "moved {} {:.3} m so that its lowest point is on the floor",
            if lowest > 0.0 { "down" } else { "up" },
            lowest.abs()
        ));
    }
    (!said.is_empty()).then(|| format!("'{}' was {}.", m.label, said.join(" and ")))
}

/// The trunk's branching point: the deepest point with three or more children (the chest,
/// where neck and arms meet), if any.
fn trunk_branch(parents: &[Option<usize>]) -> Option<usize> {
    let depth = |mut i: usize| {
        let mut d = 0;
        while let Some(p) = parents[i] {
            i = p;
            d += 1;
            if d > parents.len() {
                break;
            }
        }
        d
    };
    (0..parents.len())
        .filter(|&i| parents[i].is_some() && parents.iter().filter(|p| **p == Some(i)).count() >= 3)
        .max_by_key(|&i| depth(i))
}

/// The figure's up axis (0, 1, 2 for X, Y, Z) and its sign over `frames` (about 200 of them):
/// from the root to `chest`, else the axis its bones run along most, towards the side of the
/// root holding most of its points.
fn up_axis(frames: &[Vec<DVec3>], parents: &[Option<usize>], chest: Option<usize>) -> (usize, f64) {
    let step = frames.len().div_ceil(200).max(1);
    let (mut up, mut along, mut side) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
    for f in frames.iter().step_by(step) {
        if let Some(c) = chest {
            up += f[c] - f[0];
        }
        for (i, p) in parents.iter().enumerate() {
            if let Some(p) = p {
                along += (f[i] - f[*p]).abs();
            }
            side += f[i] - f[0];
        }
    }
    if chest.is_some() && up.length() > 0.0 {
        let axis = largest_axis(up.abs());
        (axis, up[axis].signum())
    } else {
        let axis = largest_axis(along);
        (axis, if side[axis] < 0.0 { -1.0 } else { 1.0 })
    }
}

/// The axis (0, 1, 2) of the largest component of `a` (≥ 0), ties going to X, then to Y.
fn largest_axis(a: DVec3) -> usize {
    if a.x >= a.y && a.x >= a.z {
        0
    } else if a.z > a.y {
        2
    } else {
        1
    }
}

/// Numbers of motion data a motion takes per frame.
fn values_per_frame(m: &PageMotion) -> usize {
    3 * (m.figure.names.len()
        + 4 * m
            .boxes
            .as_ref()
            .map_or(0, |b| b.first().map_or(0, Vec::len)))
}

/// The step k (every k-th frame kept) that brings `motions` under [`MAX_PAGE_VALUES`].
pub fn decimation(motions: &[PageMotion]) -> usize {
    let total: usize = motions
        .iter()
        .map(|m| values_per_frame(m) * m.frames.len())
        .sum();
    total.div_ceil(MAX_PAGE_VALUES).max(1)
}

/// Checks a motion before it is encoded.
fn check(m: &PageMotion) -> Result<(), RenderError> {
    m.figure.validate()?;
    if m.frames.is_empty() {
        return Err(RenderError::Empty(format!(
            "motion '{}' has no frames",
            m.label
        )));
    }
    if !(m.frame_time.is_finite() && m.frame_time > 0.0) {
        return Err(RenderError::InvalidArgument(format!(
            "motion '{}': frame time {} s, expected a positive number",
            m.label, m.frame_time
        )));
    }
    let n = m.figure.names.len();
    for (k, f) in m.frames.iter().enumerate() {
        if f.len() != n {
            return Err(RenderError::PointCount {
                track: m.label.clone(),
                frame: k,
                got: f.len(),
                expected: n,
            });
        }
        if let Some((i, p)) = f.iter().enumerate().find(|(_, p)| !p.is_finite()) {
            return Err(RenderError::NonFinite {
                track: m.label.clone(),
                frame: k,
                point: i,
                name: m.figure.names[i].clone(),
                value: p.to_array(),
            });
        }
    }
    if let Some(b) = &m.boxes
        && (b.len() != m.frames.len() || b.iter().any(|f| f.len() != m.box_names.len()))
    {
        return Err(RenderError::InvalidArgument(format!(
            "motion '{}': boxes for {} frames of {} links expected",
            m.label,
            m.frames.len(),
            m.box_names.len()
        )));
    }
    Ok(())
}

/// The JSON of one motion, every `step`-th frame.
fn motion_json(m: &PageMotion, step: usize) -> Result<serde_json::Value, RenderError> {
    let frames: Vec<&Vec<DVec3>> = m.frames.iter().step_by(step).collect();
    // Each frame's points from its origin, the root rounded to whole metres (stored in
    // metres), so a capture that walks far keeps millimetres.
    let origins: Vec<DVec3> = frames.iter().map(|f| f[0].round()).collect();
    let what = format!("motion '{}'", m.label);
    let rel: Vec<DVec3> = frames
        .iter()
        .zip(&origins)
        .flat_map(|(f, o)| f.iter().map(move |p| *p - *o))
        .collect();
    let boxes = match &m.boxes {
        Some(b) => {
            let rel: Vec<DVec3> = b
                .iter()
                .step_by(step)
                .zip(&origins)
                .flat_map(|(f, o)| {
                    f.iter().flat_map(move |x| {
                        [
                            x.center - *o,
                            x.half_axes[0],
                            x.half_axes[1],
                            x.half_axes[2],
                        ]
                    })
                })
                .collect();
            json!(encode_points(&rel, &format!("{what}, a box"))?)
        }
        None => serde_json::Value::Null,
    };
    let sides: Vec<&str> = m
        .figure
        .sides()
        .iter()
        .map(|s| match s {
            super::Side::Left => "l",
            super::Side::Right => "r",
            super::Side::Centre => "c",
        })
        .collect();
    Ok(json!({
        "label": m.label,
        "names": m.figure.names,
        "parents": m.figure.parents,
        "sides": sides,
        "frame_time": m.frame_time * step as f64,
        "start_s": m.start_s,
        "frames": frames.len(),
        "origins": encode(origins.iter().flat_map(|o| o.to_array()), 1.0, &format!("{what}, the root"))?,
        "points": encode_points(&rel, &format!("{what}, a point from its root"))?,
        "boxes": boxes,
        "box_names": m.box_names,
        "events": m.events.iter().map(|e| json!({"t": e.time_s, "label": e.label, "tag": e.tag, "point": e.point})).collect::<Vec<_>>(),
    }))
}

/// Linear resampling of `samples` from `from` Hz to `to` Hz.
fn resample(samples: &[f32], from: u32, to: u32) -> Vec<f32> {
    if from == to || samples.is_empty() {
        return samples.to_vec();
    }
    let n = (samples.len() as f64 * to as f64 / from as f64).floor() as usize;
    let ratio = from as f64 / to as f64;
    // Averaging over the source samples a target sample spans, as a simple low-pass.
    (0..n)
        .map(|k| {
            let a = (k as f64 * ratio) as usize;
            let b = (((k + 1) as f64 * ratio) as usize).clamp(a + 1, samples.len());
            samples[a..b].iter().sum::<f32>() / (b - a) as f32
        })
        .collect()
}

/// The page's data (everything the script reads) as JSON.
fn page_json(page: &Page) -> Result<serde_json::Value, RenderError> {
    if page.motions.is_empty() {
        return Err(RenderError::Empty(format!(
            "page '{}': no motion",
            page.title
        )));
    }
    for m in &page.motions {
        check(m)?;
    }
    let step = decimation(&page.motions);
    let mut notes = page.notes.clone();
    if step > 1 {
        let frames: usize = page.motions.iter().map(|m| m.frames.len()).sum();
        notes.push(format!(
            "Shortened to fit the page: one frame in {step} of the {frames} is shown (a page holds \
             at most {MAX_PAGE_VALUES} coordinates); the files beside it have every frame."
        ));
    }
    let song = match &page.song {
        Some(s) if s.samples.len() as f64 / s.sample_rate.max(1) as f64 > MAX_SONG_S => {
            notes.push(format!(
                "The song ({:.0} s) is longer than a page holds ({MAX_SONG_S:.0} s): it is left out.",
                s.samples.len() as f64 / s.sample_rate as f64
            ));
            serde_json::Value::Null
        }
        Some(s) => {
            let wav = crate::choreo::music::wav::wav_bytes(
                &resample(&s.samples, s.sample_rate, SONG_RATE),
                1,
                SONG_RATE,
            )
            .ok_or_else(|| RenderError::Encode("the song does not fit a WAV file".into()))?;
            json!({"wav": base64(&wav), "start_s": s.start_s})
        }
        None => serde_json::Value::Null,
    };
    let plots: Vec<serde_json::Value> = page
        .plots
        .iter()
        .map(|p| {
            json!({
                "title": p.plot.title,
                "x_label": p.plot.x_label,
                "y_label": p.plot.y_label,
                "time_axis": p.time_axis,
                "series": p.plot.series.iter().map(|s| json!({
                    "name": s.name,
                    "points": s.points.iter().filter(|(x, y)| x.is_finite() && y.is_finite()).map(|(x, y)| [x, y]).collect::<Vec<_>>(),
                })).collect::<Vec<_>>(),
                "markers": p.plot.markers.iter().map(|(x, l)| json!([x, l])).collect::<Vec<_>>(),
            })
        })
        .collect();
    Ok(json!({
        "title": page.title,
        "headline": page.headline,
        "notes": notes,
        "decimation": step,
        "motions": page.motions.iter().map(|m| motion_json(m, step)).collect::<Result<Vec<_>, _>>()?,
        "plots": plots,
        "song": song,
    }))
}

/// Escapes text for HTML.
fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The page as one HTML document.
pub fn page_html(page: &Page) -> Result<String, RenderError> {
    // `</` inside a script would end it: JSON allows `<\/` for `</`.
    let data = page_json(page)?.to_string().replace("</", "<\\/");
    Ok(format!(
        "<!doctype html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>{title}</title>\n<link rel=\"icon\" href=\"data:,\">\n<style>\n{PAGE_CSS}</style>\n\
         </head>\n<body>\n<script type=\"application/json\" id=\"page-data\">{data}</script>\n\
         <script>\n{ORBIT_JS}\n{PAGE_JS}</script>\n</body>\n</html>\n",
        title = escape(&page.title),
    ))
}

/// Writes the page to `path` (atomically).
pub fn write_page(page: &Page, path: &Path) -> Result<(), RenderError> {
    super::write(path, page_html(page)?.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A figure standing 1.7 m tall: hips, spine, chest (neck, both hands), head, both feet.
    fn walker(frames: usize) -> PageMotion {
        let figure = StickFigure {
            names: [
                "Hips",
                "Chest",
                "Head",
                "LeftHand",
                "RightHand",
                "LeftFoot",
                "RightFoot",
            ]
            .map(String::from)
            .to_vec(),
            parents: vec![None, Some(0), Some(1), Some(1), Some(1), Some(0), Some(0)],
        };
        PageMotion {
            label: "walker".into(),
            figure,
            frame_time: 1.0 / 120.0,
            start_s: 0.0,
            frames: (0..frames)
                .map(|k| {
                    let x = k as f64 * 0.001;
                    [
                        (0.0, 0.9, 0.0),
                        (0.0, 1.35, 0.0),
                        (0.0, 1.7, 0.0),
                        (0.3, 0.85, 0.0),
                        (-0.3, 0.85, 0.0),
                        (0.1, 0.0, 0.05),
                        (-0.1, 0.0, 0.05),
                    ]
                    .map(|(a, b, c)| DVec3::new(x + a, b, c))
                    .to_vec()
                })
                .collect(),
            boxes: None,
            box_names: vec![],
            events: vec![],
        }
    }

    #[test]
    fn base64_and_points_round_trip() {
        for n in 0..7 {
            let b: Vec<u8> = (0..n).map(|k| (k * 37 + 5) as u8).collect();
            assert_eq!(unbase64(&base64(&b)).unwrap(), b, "{n} bytes");
        }
        assert_eq!(base64(b"Man"), "TWFu");
        assert_eq!(base64(b"Ma"), "TWE=");
        let pts = vec![
            DVec3::new(1.2344, -0.0004, 31.9),
            DVec3::new(-31.5, 0.0, 0.0006),
        ];
        let back = decode_points(&encode_points(&pts, "t").unwrap()).unwrap();
        for (a, b) in pts.iter().zip(&back) {
            assert!((*a - *b).abs().max_element() <= 0.0005 + 1e-12, "{a} {b}");
        }
        // Out of the 16-bit millimetre range: refused with what it was named.
        let far = [DVec3::new(40.0, 0.0, 0.0)];
        let e = encode_points(&far, "motion 'x'").unwrap_err().to_string();
        assert!(e.contains("motion 'x'") && e.contains("±33 m"), "{e}");
    }

    #[test]
    fn the_page_holds_the_motion_as_given() {
        let m = walker(50);
        let page = Page {
            title: "t".into(),
            motions: vec![m.clone()],
            ..Page::default()
        };
        let v = page_json(&page).unwrap();
        let j = &v["motions"][0];
        let origins = decode(j["origins"].as_str().unwrap(), 1.0).unwrap();
        let n = m.figure.names.len();
        let back: Vec<DVec3> = decode_points(j["points"].as_str().unwrap())
            .unwrap()
            .iter()
            .enumerate()
            .map(|(i, p)| *p + DVec3::from_slice(&origins[3 * (i / n)..]))
            .collect();
        let flat: Vec<DVec3> = m.frames.concat();
        assert_eq!(back.len(), flat.len());
        assert!(
            back.iter()
                .zip(&flat)
                .all(|(a, b)| (*a - *b).abs().max_element() <= 0.0005 + 1e-12)
        );
        assert_eq!(v["decimation"], 1);
        // A script-ending tag in a label cannot end the data script.
        let mut evil = page.clone();
        evil.motions[0].label = "</script><b>".into();
        let html = page_html(&evil).unwrap();
        assert_eq!(
            html.matches("</script>").count(),
            2,
            "only the page's own two scripts"
        );
    }

    #[test]
    fn a_two_hour_capture_is_decimated_and_says_so() {
        // 2 h at 120 Hz of a 7-point figure, two of them: 864 000 frames × 21 numbers × 2.
        let m = walker(864_000);
        let per_frame = 3 * m.figure.names.len();
        let page = Page {
            title: "long".into(),
            motions: vec![m.clone(), m],
            ..Page::default()
        };
        let step = decimation(&page.motions);
        assert_eq!(step, (2 * 864_000 * per_frame).div_ceil(MAX_PAGE_VALUES));
        assert!(step > 1);
        let v = page_json(&page).unwrap();
        assert_eq!(v["decimation"], step);
        let kept = v["motions"][0]["frames"].as_u64().unwrap() as usize;
        assert_eq!(kept, 864_000usize.div_ceil(step));
        assert!(2 * kept * per_frame <= MAX_PAGE_VALUES);
        let note = v["notes"]
            .as_array()
            .unwrap()
            .last()
            .unwrap()
            .as_str()
            .unwrap();
        assert!(note.contains(&format!("one frame in {step}")), "{note}");
        // The last kept frame, 864 m from the start, still to the millimetre.
        let j = &v["motions"][0];
        let origins = decode(j["origins"].as_str().unwrap(), 1.0).unwrap();
        let pts = decode_points(j["points"].as_str().unwrap()).unwrap();
        let (k, n) = (kept - 1, 7);
        let got = pts[k * n + 2] + DVec3::from_slice(&origins[3 * k..]);
        let want = page.motions[0].frames[k * step][2];
        assert!(
            (got - want).abs().max_element() <= 0.0005 + 1e-9,
            "{got} {want}"
        );
        // The decimated motion keeps its duration.
        let ft = v["motions"][0]["frame_time"].as_f64().unwrap();
        assert!((ft - step as f64 / 120.0).abs() < 1e-12);
        let html = page_html(&page).unwrap();
        assert!(html.len() < 10_000_000, "{} bytes", html.len());
        // Below the limit nothing is decimated.
        assert_eq!(decimation(&[walker(1000)]), 1);
    }

    #[test]
    fn bad_motions_are_refused_with_their_name() {
        let mut m = walker(3);
        m.frames[1][2] = DVec3::new(f64::NAN, 0.0, 0.0); // Head
        let page = Page {
            title: "t".into(),
            motions: vec![m],
            ..Page::default()
        };
        let e = page_html(&page).unwrap_err().to_string();
        assert!(e.contains("walker") && e.contains("Head"), "{e}");
        let empty = Page::default();
        assert!(
            page_html(&empty)
                .unwrap_err()
                .to_string()
                .contains("no motion")
        );
    }

    #[test]
    fn the_song_is_resampled_to_the_page_rate() {
        let s: Vec<f32> = (0..44_100).map(|k| (k as f32 * 0.01).sin()).collect();
        let r = resample(&s, 44_100, SONG_RATE);
        assert_eq!(r.len(), SONG_RATE as usize);
        assert!((r[8_000] - s[22_050]).abs() < 0.05);
    }

    #[test]
    fn a_z_up_figure_below_its_floor_is_stood_up_on_it() {
        let mut m = walker(10);
        let upright = m.frames.clone();
        // The same figure with Z up, 0.3 m below the floor.
        for f in &mut m.frames {
            for p in f.iter_mut() {
                *p = DVec3::new(p.x, -p.z, p.y - 0.3);
            }
        }
        let said = stand_upright(&mut m).unwrap();
        assert!(said.contains("+Z") && said.contains("up 0.300 m"), "{said}");
        for (a, b) in m.frames.iter().flatten().zip(upright.iter().flatten()) {
            assert!((a.y - b.y).abs() < 1e-9, "{a} {b}");
        }
        // Upright on its floor already: nothing to do.
        assert_eq!(stand_upright(&mut m), None);
        // Upside down (−Y up).
        for f in &mut m.frames {
            for p in f.iter_mut() {
                p.y = -p.y;
            }
        }
        let said = stand_upright(&mut m).unwrap();
        assert!(said.contains("-Y"), "{said}");
        let head = m.frames[0][2].y - m.frames[0][0].y;
        assert!(head > 0.7, "the head is above the hips: {head}");
    }
}
