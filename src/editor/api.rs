//! The editor's JSON API: one route per action, a pure function from (method, path, query,
//! body) to a [`Reply`] over the [`Session`], so it is tested without a network.
//!
//! | route | body / query | answer |
//! |---|---|---|
//! | `GET /api/state` | | pins, undo/redo depth, last fill, tempo, song length, figure links |
//! | `GET /api/bars` | | every bar (span, dB, normalised intensity, pin, filled segment, whether that fill is stale), beats |
//! | `GET /api/candidates` | `?bar=K` | bar K's round, τ, segments left, its six candidates' frames and its liked segments' frames |
//! | `GET /api/in-context` | `?bar=K&segment=S` | S danced in bar K between K's current neighbours (their pins, else their fill) as the dance would be: frames from bar K − 1 to K + 1, and both seams' S and C ([`Session::in_context`]) |
//! | `GET /api/dance` | | the whole dance of the current pins at the scene's fps (generates first), and its figures |
//! | `GET /api/audio.wav` | `?bar=K` (optional) | bar K's span of the song (without `bar`, the whole song) as mono 16-bit WAV at most 22.05 kHz ([`crate::editor::session::Song::span`]) |
//! | `POST /api/search` | `{"bar": K}` | the next relevance-feedback round; as `candidates` |
//! | `POST /api/start-over` | `{"bar": K}` | bar K's search back to round 0, nothing shown but the likes (kept); as `candidates` |
//! | `POST /api/search-params` | `{"tau0": x, "tau_decay": y}` (either) | τ_0 and decay for every bar's next rounds; the search parameters |
//! | `POST /api/like` | `{"bar": K, "segment": S}` | S into bar K's liked set L_l |
//! | `POST /api/unlike` | `{"bar": K, "segment": S}` | S out of L_l |
//! | `POST /api/set` | `{"bar": K, "segment": S}` | pins S to bar K |
//! | `POST /api/unpin` | `{"bar": K}` | removes bar K's pin |
//! | `POST /api/undo`, `POST /api/redo` | `{}` | the pin change undone/redone |
//! | `POST /api/generate` | `{}` | every unpinned bar filled: segments and total cost |
//! | `POST /api/save` | `{}` | the scene written back with its pins (atomically) |
//! | `POST /api/export-bvh` | `{}` | the dance as BVH, `marionette run`'s motion.bvh (a download) |
//!
//! Errors are `{"error": "one line"}`: 400 for a malformed request (bad JSON, unknown field,
//! index out of range), 404 for an unknown route, 405 for a wrong method, 409 for an action the
//! edit's state refuses (nothing to undo, not shown, no candidate left), 500 for a failure to
//! write the scene. A parameter out of range (τ_0 outside [0, 1]) is a 400. τ_0 set through
//! the API is the session's: Save writes the pins, not the search parameters.

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use serde_json::{Value, json};

use super::EditorError;
use super::session::{Frames, Session, Song};
use crate::choreo::edit::EditError;

/// An HTTP answer.
#[derive(Debug, Clone, PartialEq)]
pub struct Reply {
    /// Status code.
    pub status: u16,
    /// Content type.
    pub content_type: &'static str,
    /// Body.
    pub body: Vec<u8>,
    /// A file name for a download (`Content-Disposition: attachment`).
    pub download: Option<&'static str>,
}

impl Reply {
    /// A JSON answer, serialised straight from `v` (no intermediate [`Value`] tree).
    pub fn json<T: Serialize + ?Sized>(status: u16, v: &T) -> Reply {
        match serde_json::to_vec(v) {
            Ok(body) => Reply {
                status,
                content_type: "application/json",
                body,
                download: None,
            },
            Err(e) => Reply::error(
                500,
                &format!("the answer could not be written as JSON: {e}"),
            ),
        }
    }

    /// An error answer: `{"error": reason}` with the reason on one line.
    pub fn error(status: u16, reason: &str) -> Reply {
        let line: String = reason.split_whitespace().collect::<Vec<_>>().join(" ");
        Reply::json(status, &json!({ "error": line }))
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BarBody {
    bar: usize,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BarSegmentBody {
    bar: usize,
    segment: usize,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Empty {}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TauBody {
    tau0: Option<f64>,
    tau_decay: Option<f64>,
}

/// Parses a JSON body into `T` or answers 400 with serde's one-line reason.
fn body<T: DeserializeOwned>(b: &[u8]) -> Result<T, Reply> {
    let b = if b.iter().all(u8::is_ascii_whitespace) {
        b"{}".as_slice()
    } else {
        b
    };
    serde_json::from_slice(b).map_err(|e| Reply::error(400, &format!("request body: {e}")))
}

/// The status of an editor error.
fn status_of(e: &EditorError) -> u16 {
    match e {
        EditorError::Edit(
            EditError::NoSuchBar { .. } | EditError::NoSuchSegment { .. } | EditError::Search(_),
        ) => 400,
        EditorError::Edit(_) | EditorError::Fill(_) | EditorError::Dance(_) => 409,
        _ => 500,
    }
}

fn fail(e: EditorError) -> Reply {
    Reply::error(status_of(&e), &e.to_string())
}

/// The value of `key` in a query string as an index, or a 400.
fn query_index(query: &str, key: &str) -> Result<usize, Reply> {
    let v = query
        .split('&')
        .find_map(|kv| kv.strip_prefix(key)?.strip_prefix('='))
        .ok_or_else(|| Reply::error(400, &format!("query: `{key}` is missing")))?;
    v.parse()
        .map_err(|_| Reply::error(400, &format!("query: `{key}={v}` is not an index")))
}

/// Answers one API request (`path` starts with `/api/`, `query` without its `?`).
pub fn handle(s: &mut Session, method: &str, path: &str, query: &str, b: &[u8]) -> Reply {
    match route(s, method, path, query, b) {
        Ok(r) | Err(r) => r,
    }
}

const GETS: [&str; 6] = [
    "/api/state",
    "/api/in-context",
    "/api/bars",
    "/api/candidates",
    "/api/dance",
    "/api/audio.wav",
];
const POSTS: [&str; 12] = [
    "/api/search",
    "/api/start-over",
    "/api/search-params",
    "/api/like",
    "/api/unlike",
    "/api/set",
    "/api/unpin",
    "/api/undo",
    "/api/redo",
    "/api/generate",
    "/api/save",
    "/api/export-bvh",
];

fn route(s: &mut Session, method: &str, path: &str, query: &str, b: &[u8]) -> Result<Reply, Reply> {
    let get = GETS.contains(&path);
    let post = POSTS.contains(&path);
    if !get && !post {
        return Err(Reply::error(404, &format!("no route {path}")));
    }
    let expected = if get { "GET" } else { "POST" };
    if method != expected {
        return Err(Reply::error(
            405,
            &format!("{path} takes {expected}, not {method}"),
        ));
    }
    if get && !b.is_empty() {
        return Err(Reply::error(400, &format!("GET {path} takes no body")));
    }
    if get {
        get_route(s, path, query)
    } else {
        post_route(s, path, b)
    }
}

/// A 200 answer of `v` as JSON.
fn ok(v: Value) -> Result<Reply, Reply> {
    Ok(Reply::json(200, &v))
}

/// The answer to `GET path` (one of [`GETS`]) with the query `query`.
fn get_route(s: &mut Session, path: &str, query: &str) -> Result<Reply, Reply> {
    match path {
        "/api/state" => ok(state(s)),
        "/api/bars" => ok(bars(s)),
        "/api/candidates" => {
            let bar = query_index(query, "bar")?;
            candidates(s, bar)
        }
        "/api/in-context" => {
            let bar = query_index(query, "bar")?;
            let segment = query_index(query, "segment")?;
            ok(json!(s.in_context(bar, segment).map_err(fail)?))
        }
        "/api/dance" => {
            let (frames, start_s, figures) = s.dance_with_figures().map_err(fail)?;
            Ok(Reply::json(
                200,
                &DanceAnswer {
                    fps: s.fps(),
                    start_s,
                    frames: &frames,
                    figures,
                },
            ))
        }
        "/api/audio.wav" => {
            let spans: Vec<(f64, f64)> = s
                .edit()
                .bars()
                .iter()
                .map(|b| (b.start_s, b.end_s))
                .collect();
            audio(s.song(), &spans, query)
        }
        _ => Err(Reply::error(404, &format!("no route {path}"))),
    }
}

/// The answer to `POST path` (one of [`POSTS`]) with the body `b`.
fn post_route(s: &mut Session, path: &str, b: &[u8]) -> Result<Reply, Reply> {
    match path {
        "/api/search" => {
            let BarBody { bar } = body(b)?;
            s.edit_mut().search(bar).map_err(|e| fail(e.into()))?;
            candidates(s, bar)
        }
        "/api/start-over" => {
            let BarBody { bar } = body(b)?;
            s.edit_mut().start_over(bar).map_err(|e| fail(e.into()))?;
            candidates(s, bar)
        }
        "/api/search-params" => search_params(s, b),
        "/api/like" | "/api/unlike" => like(s, path == "/api/like", b),
        "/api/set" => {
            let BarSegmentBody { bar, segment } = body(b)?;
            s.edit_mut().set(bar, segment).map_err(|e| fail(e.into()))?;
            ok(state(s))
        }
        "/api/unpin" => {
            let BarBody { bar } = body(b)?;
            s.edit_mut().unpin(bar).map_err(|e| fail(e.into()))?;
            ok(state(s))
        }
        "/api/undo" | "/api/redo" => undo_redo(s, path == "/api/undo", b),
        "/api/generate" => {
            let Empty {} = body(b)?;
            s.generate().map_err(fail)?;
            ok(state(s))
        }
        "/api/save" => {
            let Empty {} = body(b)?;
            let p = s.save().map_err(fail)?;
            ok(json!({ "saved": p.display().to_string() }))
        }
        "/api/export-bvh" => {
            let Empty {} = body(b)?;
            let bvh = s.export_bvh().map_err(fail)?;
            Ok(Reply {
                status: 200,
                content_type: "text/plain; charset=utf-8",
                body: bvh.into_bytes(),
                download: Some("dance.bvh"),
            })
        }
        _ => Err(Reply::error(404, &format!("no route {path}"))),
    }
}

/// `POST /api/search-params`: the search's τ₀ and τ decay, each kept when not given; answers
/// the parameters now.
fn search_params(s: &mut Session, b: &[u8]) -> Result<Reply, Reply> {
    let TauBody { tau0, tau_decay } = body(b)?;
    let mut p = s.edit().search_params().clone();
    p.tau0 = tau0.unwrap_or(p.tau0);
    p.tau_decay = tau_decay.unwrap_or(p.tau_decay);
    s.edit_mut()
        .set_search_params(p)
        .map_err(|e| fail(e.into()))?;
    ok(json!(s.edit().search_params()))
}

/// `POST /api/like` (`liked`) or `/api/unlike`: a bar's candidate segment liked or not;
/// answers the bar's liked segments.
fn like(s: &mut Session, liked: bool, b: &[u8]) -> Result<Reply, Reply> {
    let BarSegmentBody { bar, segment } = body(b)?;
    s.edit_mut()
        .like(bar, segment, liked)
        .map_err(|e| fail(e.into()))?;
    let liked = &s.edit().bar_search(bar).map_err(|e| fail(e.into()))?.liked;
    ok(json!({ "bar": bar, "liked": liked }))
}

/// `POST /api/undo` (`undo`) or `/api/redo`: answers the state with the change undone or
/// redone.
fn undo_redo(s: &mut Session, undo: bool, b: &[u8]) -> Result<Reply, Reply> {
    let Empty {} = body(b)?;
    let c = if undo {
        s.edit_mut().undo()
    } else {
        s.edit_mut().redo()
    }
    .map_err(|e| fail(e.into()))?;
    let mut v = state(s);
    v["change"] = json!(c);
    ok(v)
}

/// `GET /api/audio.wav` over `song` and its bars' spans `bars` (s), `query` without its `?`:
/// bar K's piece of the song (`bar=K`) or, with no query, the whole song, as mono 16-bit WAV at
/// most 22.05 kHz ([`Song::span`]). It needs no session: the server answers it without the
/// session's lock, so the song never waits behind a Generate.
pub fn audio(song: &Song, bars: &[(f64, f64)], query: &str) -> Result<Reply, Reply> {
    let (from_s, to_s) = if query.is_empty() {
        (0.0, f64::INFINITY)
    } else {
        let bar = query_index(query, "bar")?;
        *bars.get(bar).ok_or_else(|| {
            Reply::error(
                400,
                &format!(
                    "query: bar {bar} is out of range (the song has {} bars, 0 to {})",
                    bars.len(),
                    bars.len().saturating_sub(1)
                ),
            )
        })?
    };
    let (samples, rate) = song.span(from_s, to_s);
    let wav = crate::choreo::music::wav::wav_bytes(&samples, 1, rate)
        .ok_or_else(|| Reply::error(500, "the song does not fit a WAV file"))?;
    Ok(Reply {
        status: 200,
        content_type: "audio/wav",
        body: wav,
        download: None,
    })
}

fn state(s: &Session) -> Value {
    let e = s.edit();
    let st = e.state();
    let pins: serde_json::Map<String, Value> = st
        .pins
        .iter()
        .map(|(b, g)| (b.to_string(), json!(g)))
        .collect();
    let bars = e.bars();
    json!({
        "bars": bars.len(),
        "segments": e.database().segments.len(),
        "pins": pins,
        "undo": st.undo.len(),
        "redo": st.redo.len(),
        "fill": s.fill().map(|f| json!({ "segments": f.segments, "total_cost": f.total_cost })),
        "search": e.search_params(),
        "tempo_bpm": s.song().tempo_bpm,
        "song_s": s.song().samples.len() as f64 / s.song().sample_rate as f64,
        "parents": s.point_parents(),
        "sides": s.point_sides().iter().map(|c| c.to_string()).collect::<Vec<_>>(),
        "head": s.head_points(),
        "scene": s.scene_path().display().to_string(),
    })
}

fn bars(s: &Session) -> Value {
    let e = s.edit();
    let fill = s.fill().map(|f| &f.segments);
    let stale = s.fill_is_stale();
    let list: Vec<Value> = e
        .bars()
        .iter()
        .enumerate()
        .map(|(k, b)| {
            json!({
                "start_s": b.start_s,
                "end_s": b.end_s,
                "rms_db": if b.rms_db.is_finite() { json!(b.rms_db) } else { Value::Null },
                "intensity": e.music_intensity()[k],
                "pin": e.pins().get(&k),
                "filled": fill.and_then(|f| f.get(k)),
                "stale": stale && !e.pins().contains_key(&k),
                "round": e.state().searches[k].round,
            })
        })
        .collect();
    json!({ "bars": list, "beats_s": s.song().beats_s, "stale": stale })
}

/// `GET /api/dance`.
#[derive(Serialize)]
struct DanceAnswer<'a> {
    fps: f64,
    start_s: f64,
    frames: &'a Frames,
    figures: crate::experiments::dance::DanceFigures,
}

/// One candidate (or liked segment) of `GET /api/candidates` and `POST /api/search`.
#[derive(Serialize)]
struct Candidate<'a> {
    segment: usize,
    liked: bool,
    intensity: f64,
    source: Option<&'a str>,
    /// The source clip's file stem ("acrnn_salsa_01" for ".../acrnn_salsa_01.bvh").
    name: Option<&'a str>,
    source_bar: usize,
    /// The segment's W as a percentile rank among the database's segments, in [0, 1].
    intensity_rank: f64,
    /// rel(q, m) = 1 − |bar's loudness rank − segment's intensity rank| (eq. 1).
    relevance: f64,
    frames: Frames,
}

/// `GET /api/candidates` and `POST /api/search`.
#[derive(Serialize)]
struct Candidates<'a> {
    bar: usize,
    start_s: f64,
    end_s: f64,
    /// The bar's loudness (RMS dB) as a percentile rank among the song's bars, in [0, 1].
    loudness_rank: f64,
    /// The unit of W: m/s when every weight α_i is 1.
    intensity_unit: &'static str,
    /// Rounds run (the k of the next round).
    round: usize,
    /// τ of the next round, τ_0·decay^k.
    tau: f64,
    tau0: f64,
    tau_decay: f64,
    /// Segments shown for the bar since its search (re)started.
    shown: usize,
    /// Segments never shown yet: 0 when the bar has run dry (then only a start over helps).
    left: usize,
    liked: &'a [usize],
    pin: Option<&'a usize>,
    candidates: Vec<Candidate<'a>>,
    /// The liked segments, in the order liked, with their frames (reachable after any round).
    liked_segments: Vec<Candidate<'a>>,
}

fn candidates(s: &Session, bar: usize) -> Result<Reply, Reply> {
    let e = s.edit();
    let search = e.bar_search(bar).map_err(|e| fail(e.into()))?;
    let b = e.bars()[bar];
    let db = e.database();
    let loudness = e.music_intensity()[bar];
    let card = |seg: usize| -> Result<Candidate, Reply> {
        let m = &db.segments[seg];
        let source = db.sources.get(m.clip).map(|c| c.file.as_str());
        let rank = s.motion_intensity()[seg];
        Ok(Candidate {
            segment: seg,
            liked: search.liked.contains(&seg),
            intensity: m.intensity,
            source,
            name: source.and_then(|f| std::path::Path::new(f).file_stem()?.to_str()),
            source_bar: m.bar,
            intensity_rank: rank,
            relevance: crate::choreo::relevance::rel(loudness, rank),
            frames: s.segment_frames(seg).map_err(fail)?,
        })
    };
    let p = e.search_params();
    Ok(Reply::json(
        200,
        &Candidates {
            bar,
            start_s: b.start_s,
            end_s: b.end_s,
            loudness_rank: loudness,
            intensity_unit: if db.params.alpha.iter().all(|&a| a == 1.0) {
                "m/s"
            } else {
                "α-weighted m/s"
            },
            round: search.round,
            tau: p.tau(search.round),
            tau0: p.tau0,
            tau_decay: p.tau_decay,
            shown: search.shown.len(),
            left: db.segments.len().saturating_sub(search.shown.len()),
            liked: &search.liked,
            pin: e.pins().get(&bar),
            candidates: search
                .current
                .iter()
                .map(|&m| card(m))
                .collect::<Result<_, _>>()?,
            liked_segments: search
                .liked
                .iter()
                .map(|&m| card(m))
                .collect::<Result<_, _>>()?,
        },
    ))
}
