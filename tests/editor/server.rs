//! The dance editor's server over real TCP: the API flow (search, like, search, set, generate,
//! undo/redo, save, export), and its defences — loopback only, Host check (DNS rebinding),
//! embedded files only, body limit, one-line 400s — and that it keeps answering correctly, with
//! the saved edit intact, after thousands of bad and concurrent requests.

use std::collections::BTreeSet;
use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::Duration;

use crate::fixture::{assert_bvh_lasts_the_bars, get, post, raw, request, scene, start_editor};
use marionette::editor::server::{Editor, MAX_BODY};
use marionette::editor::session::Session;

fn start(name: &str) -> (Editor, std::path::PathBuf) {
    let path = scene(name, 6, 10, 12);
    let editor = Editor::start(Session::open(&path).unwrap(), 0).unwrap();
    (editor, path)
}

/// The pins of the scene file at `path`, as a fresh editor session reads them.
fn pins_of(path: &std::path::Path) -> std::collections::BTreeMap<usize, usize> {
    Session::open(path).unwrap().edit().pins().clone()
}

fn segments(v: &serde_json::Value) -> Vec<u64> {
    v["candidates"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["segment"].as_u64().unwrap())
        .collect()
}

#[test]
fn the_api_flow_search_like_search_set_generate_save_export() {
    let (ed, path) = start("flow");
    let a = ed.addr();
    let state = get(a, "/api/state");
    assert_eq!(state["bars"], 12);
    let n_seg = state["segments"].as_u64().unwrap();
    assert!(n_seg >= 24, "{n_seg} segments");

    let first = post(a, "/api/search", r#"{"bar": 3}"#);
    let shown = segments(&first);
    assert_eq!(shown.len(), 6);
    // Each candidate carries its frames: bar_frames frames of every stick-figure point.
    let c0 = &first["candidates"][0];
    let frames = c0["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 32);
    assert_eq!(
        frames[0].as_array().unwrap().len(),
        state["parents"].as_array().unwrap().len()
    );
    assert_eq!(
        get(a, "/api/candidates?bar=3")["candidates"],
        first["candidates"]
    );

    post(
        a,
        "/api/like",
        &format!(r#"{{"bar": 3, "segment": {}}}"#, shown[0]),
    );
    post(
        a,
        "/api/like",
        &format!(r#"{{"bar": 3, "segment": {}}}"#, shown[1]),
    );
    let liked = post(
        a,
        "/api/unlike",
        &format!(r#"{{"bar": 3, "segment": {}}}"#, shown[1]),
    );
    assert_eq!(liked["liked"], serde_json::json!([shown[0]]));
    let second = segments(&post(a, "/api/search", r#"{"bar": 3}"#));
    assert_eq!(second.len(), 6);
    assert!(
        second.iter().all(|s| !shown.contains(s)),
        "{second:?} vs {shown:?}"
    );

    post(
        a,
        "/api/set",
        &format!(r#"{{"bar": 3, "segment": {}}}"#, second[2]),
    );
    post(a, "/api/set", r#"{"bar": 7, "segment": 0}"#);
    let s = post(a, "/api/unpin", r#"{"bar": 7}"#);
    assert_eq!(s["undo"], 3);
    let s = post(a, "/api/undo", "{}");
    assert_eq!(s["pins"]["7"], 0);
    let s = post(a, "/api/redo", "");
    assert!(s["pins"].get("7").is_none());

    let g = post(a, "/api/generate", "{}");
    let fill = g["fill"]["segments"].as_array().unwrap();
    assert_eq!(fill.len(), 12);
    assert_eq!(fill[3], second[2]);
    for w in fill.windows(2) {
        assert_ne!(w[0], w[1], "no adjacent repeat");
    }
    let bars = get(a, "/api/bars");
    assert_eq!(bars["bars"][3]["pin"], second[2]);
    assert!(
        bars["bars"]
            .as_array()
            .unwrap()
            .iter()
            .all(|b| !b["filled"].is_null())
    );

    let saved = post(a, "/api/save", "{}");
    assert_eq!(saved["saved"], path.display().to_string());
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.starts_with("// The editor tests' dance"),
        "comments kept: {text}"
    );
    assert!(text.contains("// written by the test"), "{text}");
    assert_eq!(
        pins_of(&path),
        std::collections::BTreeMap::from([(3, second[2] as usize)])
    );

    let bvh = request(a, "POST", "/api/export-bvh", Some("{}"));
    assert_eq!(bvh.status, 200);
    let text = bvh.text();
    let frames = assert_bvh_lasts_the_bars(a, &text);

    // `marionette run` of the saved scene dances what the editor showed: the same segments per
    // bar, and its motion.bvh is the editor's export byte for byte.
    let out = path.with_file_name("run");
    let report = marionette::scene::run(
        &marionette::scene::Scene::load(&path).unwrap(),
        path.parent().unwrap(),
        &out,
    )
    .unwrap();
    let ran: Vec<u64> = report["per_bar"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b["segment"].as_u64().unwrap())
        .collect();
    let shown: Vec<u64> = fill.iter().map(|s| s.as_u64().unwrap()).collect();
    assert_eq!(ran, shown);
    assert_eq!(
        std::fs::read_to_string(out.join("motion.bvh")).unwrap(),
        text
    );

    let dance = get(a, "/api/dance");
    let lead = (dance["start_s"].as_f64().unwrap() * 30.0).round() as usize;
    assert_eq!(dance["frames"].as_array().unwrap().len() + lead, frames);
    // The figures the page's status gives are the report's for the same dance.
    let (fig, m) = (&dance["figures"], &report["metrics"]);
    for (shown, reported) in [
        (
            &fig["metrics"]["beat_alignment_score"],
            &m["beat_alignment_score"],
        ),
        (&fig["metrics"]["foot_skating_m_s"], &m["foot_skating_m_s"]),
        (
            &fig["metrics"]["foot_penetration"]["deepest_m"],
            &m["foot_penetration"]["deepest_m"],
        ),
        (
            &fig["metrics"]["seam_jerk"]["mean_rad_s3"],
            &m["seam_jerk_mean_rad_s3"],
        ),
        (
            &fig["sources"]["foot_skating_m_s"],
            &m["sources"]["foot_skating_m_s"],
        ),
        (
            &fig["sources"]["beat_alignment_score"],
            &m["sources"]["beat_alignment_score"],
        ),
        (&fig["intensity_spearman"], &m["intensity_spearman"]),
    ] {
        assert_eq!(shown, reported);
    }

    let wav = request(a, "GET", "/api/audio.wav", None);
    assert_eq!(wav.status, 200);
    assert_eq!(&wav.body[..4], b"RIFF");
    let song_s = get(a, "/api/state")["song_s"].as_f64().unwrap();
    let samples = (wav.body.len() - 44) / 2;
    assert!((samples as f64 / 22_050.0 - song_s).abs() < 1e-3);
    ed.stop();
}

#[test]
fn liked_segments_stay_reachable_a_dry_bar_starts_over_and_tau0_is_set() {
    let (ed, _) = start("likes");
    let a = ed.addr();
    let n_seg = get(a, "/api/state")["segments"].as_u64().unwrap();
    assert_eq!(get(a, "/api/state")["search"]["tau0"], 1.0);

    // Like two of round 0; after Search they are gone from the candidates but in the liked
    // row, with their frames.
    let first = post(a, "/api/search", r#"{"bar": 5}"#);
    let shown = segments(&first);
    assert_eq!(first["left"], n_seg - 6);
    for s in [shown[1], shown[4]] {
        post(a, "/api/like", &format!(r#"{{"bar": 5, "segment": {s}}}"#));
    }
    let second = post(a, "/api/search", r#"{"bar": 5}"#);
    assert!(segments(&second).iter().all(|s| !shown.contains(s)));
    let liked: Vec<u64> = second["liked_segments"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["segment"].as_u64().unwrap())
        .collect();
    assert_eq!(liked, vec![shown[1], shown[4]]);
    let row = &second["liked_segments"][0];
    assert_eq!(row["liked"], true);
    assert_eq!(row["frames"].as_array().unwrap().len(), 32);
    // A liked card can be Set.
    let s = post(
        a,
        "/api/set",
        &format!(r#"{{"bar": 5, "segment": {}}}"#, liked[0]),
    );
    assert_eq!(s["pins"]["5"], liked[0]);

    // The slider: τ_0 for the next rounds (checked), τ = τ_0·0.95^k of the bar's round k.
    let p = post(a, "/api/search-params", r#"{"tau0": 0.3}"#);
    assert_eq!(
        (p["tau0"].as_f64(), p["tau_decay"].as_f64()),
        (Some(0.3), Some(0.95))
    );
    let c = get(a, "/api/candidates?bar=5");
    assert_eq!(c["round"], 2);
    assert!((c["tau"].as_f64().unwrap() - 0.3 * 0.95 * 0.95).abs() < 1e-12);
    let (status, reason) = refused(a, "POST", "/api/search-params", Some(r#"{"tau0": 1.5}"#));
    assert_eq!(status, 400);
    assert!(reason.contains("tau0 must lie in [0, 1]"), "{reason}");
    assert_eq!(get(a, "/api/state")["search"]["tau0"], 0.3);

    // Search until the bar runs dry: `left` says so before the refusal.
    let mut c = c;
    while c["left"] != 0 {
        c = post(a, "/api/search", r#"{"bar": 5}"#);
    }
    assert_eq!(c["shown"], n_seg);
    let (status, reason) = refused(a, "POST", "/api/search", Some(r#"{"bar": 5}"#));
    assert_eq!(status, 409);
    assert!(reason.contains("start the bar's search over"), "{reason}");
    // Start over: round 0, nothing shown but the likes, the likes and the pin kept; Search
    // shows six again, none of them liked.
    let c = post(a, "/api/start-over", r#"{"bar": 5}"#);
    assert_eq!(
        (c["round"].as_u64(), c["shown"].as_u64()),
        (Some(0), Some(2))
    );
    assert_eq!(c["left"], n_seg - 2);
    assert!(c["candidates"].as_array().unwrap().is_empty());
    assert_eq!(c["liked"], serde_json::json!([shown[1], shown[4]]));
    assert_eq!(c["liked_segments"].as_array().unwrap().len(), 2);
    assert_eq!(c["pin"], liked[0]);
    let again = segments(&post(a, "/api/search", r#"{"bar": 5}"#));
    assert_eq!(again.len(), 6);
    assert!(!again.contains(&shown[1]) && !again.contains(&shown[4]));
    // A liked card can be unliked from the Liked row.
    post(
        a,
        "/api/unlike",
        &format!(r#"{{"bar": 5, "segment": {}}}"#, shown[4]),
    );
    assert_eq!(
        get(a, "/api/candidates?bar=5")["liked"],
        serde_json::json!([shown[1]])
    );
    assert_eq!(
        refused(a, "POST", "/api/start-over", Some(r#"{"bar": 99}"#)).0,
        400
    );
    ed.stop();
}

/// The status and the one-line reason of a request.
fn refused(a: SocketAddr, method: &str, path: &str, body: Option<&str>) -> (u16, String) {
    let r = request(a, method, path, body);
    let text = r.text();
    assert!(!text.contains('\n'), "one line: {text}");
    (r.status, text)
}

#[test]
fn bad_requests_get_clear_refusals_and_the_server_keeps_serving() {
    let (ed, _) = start("refusals");
    let a = ed.addr();
    assert!(a.ip().is_loopback());

    // DNS rebinding: a page of evil.com resolving to 127.0.0.1 sends Host: evil.com.
    for host in [
        "evil.com",
        "127.0.0.1.evil.com",
        "localhost.evil.com:80",
        "10.0.0.1",
    ] {
        let r = raw(
            a,
            format!("GET /api/state HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n")
                .as_bytes(),
        );
        assert_eq!(r.status, 403, "{host}");
    }
    let no_host = raw(a, b"GET /api/state HTTP/1.0\r\n\r\n");
    assert_eq!(no_host.status, 403);
    let localhost = raw(
        a,
        format!(
            "GET / HTTP/1.1\r\nHost: localhost:{}\r\nConnection: close\r\n\r\n",
            a.port()
        )
        .as_bytes(),
    );
    assert_eq!(localhost.status, 200);
    assert!(localhost.text().contains("dance editor"));
    // Another site's page posting to the editor (its Origin is not the editor's own).
    for origin in [
        "http://evil.com".to_string(),
        "null".to_string(),
        format!("http://127.0.0.1:{}", a.port() ^ 1),
    ] {
        let r = raw(
            a,
            format!(
                "POST /api/set HTTP/1.1\r\nHost: {a}\r\nOrigin: {origin}\r\nContent-Length: 24\r\nConnection: close\r\n\r\n{{\"bar\": 0, \"segment\": 1}}"
            )
            .as_bytes(),
        );
        assert_eq!(r.status, 403, "{origin}");
    }
    let own = raw(
        a,
        format!(
            "GET /api/state HTTP/1.1\r\nHost: {a}\r\nOrigin: http://{a}\r\nConnection: close\r\n\r\n"
        )
        .as_bytes(),
    );
    assert_eq!(own.status, 200);
    assert!(own.json()["pins"].as_object().unwrap().is_empty());

    // Only the embedded files: every other path is 404, whatever it spells.
    for p in [
        "/../Cargo.toml",
        "/%2e%2e/Cargo.toml",
        "/app.js/../../Cargo.toml",
        "/..%2f..%2fCargo.toml",
        "/%2fetc%2fpasswd",
        "//etc/passwd",
        "/etc/passwd",
        "/src/editor/page/app.js",
        "/api/../Cargo.toml",
        "/api/%2e%2e/state",
        "/app.js%00",
        "/index.html",
    ] {
        assert_eq!(refused(a, "GET", p, None).0, 404, "{p}");
    }
    assert_eq!(request(a, "GET", "/app.js", None).status, 200);
    assert_eq!(request(a, "GET", "/figure.js", None).status, 200);

    // Bodies over the limit.
    let big = format!(r#"{{"bar": 1, "pad": "{}"}}"#, "x".repeat(MAX_BODY));
    assert_eq!(refused(a, "POST", "/api/search", Some(&big)).0, 413);
    let huge = "POST /api/search HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: 999999999\r\nConnection: close\r\n\r\n{}";
    assert_eq!(raw(a, huge.as_bytes()).status, 413);
    let mut chunked = b"POST /api/search HTTP/1.1\r\nHost: 127.0.0.1\r\nTransfer-Encoding: chunked\r\nConnection: close\r\n\r\n".to_vec();
    for _ in 0..40 {
        chunked.extend(format!("400\r\n{}\r\n", "y".repeat(1024)).as_bytes());
    }
    chunked.extend(b"0\r\n\r\n");
    assert_eq!(raw(a, &chunked).status, 413);

    // Malformed JSON, unknown fields, wrong types: 400 with serde's reason on one line.
    let cases = [
        ("/api/search", "{bar: 1", "key must be a string"),
        ("/api/search", r#"{"bar": 1, "x": 2}"#, "unknown field `x`"),
        ("/api/search", r#"{"bar": -1}"#, "invalid value"),
        ("/api/set", r#"{"bar": 1}"#, "missing field `segment`"),
        ("/api/undo", r#"{"please": true}"#, "unknown field `please`"),
        (
            "/api/search",
            r#"{"bar": 12}"#,
            "bar 12 is past the song's end",
        ),
        (
            "/api/set",
            r#"{"bar": 0, "segment": 100000}"#,
            "not in the database",
        ),
    ];
    for (p, body, why) in cases {
        let (status, text) = refused(a, "POST", p, Some(body));
        assert_eq!(status, 400, "{p} {body}: {text}");
        assert!(text.contains(why), "{p} {body}: {text}");
    }
    assert_eq!(refused(a, "GET", "/api/candidates?bar=x", None).0, 400);
    assert_eq!(refused(a, "GET", "/api/candidates", None).0, 400);
    assert_eq!(refused(a, "GET", "/api/search", None).0, 405);
    assert_eq!(refused(a, "POST", "/api/state", Some("{}")).0, 405);
    assert_eq!(refused(a, "DELETE", "/api/state", None).0, 405);
    assert_eq!(refused(a, "POST", "/api/nope", Some("{}")).0, 404);
    // Refused by the edit's state: 409.
    assert_eq!(refused(a, "POST", "/api/undo", Some("{}")).0, 409);
    assert_eq!(
        refused(a, "POST", "/api/unpin", Some(r#"{"bar": 2}"#)).0,
        409
    );
    assert_eq!(
        refused(a, "POST", "/api/like", Some(r#"{"bar": 2, "segment": 0}"#)).0,
        409
    );
    // HTTP/2, by its version or by its connection preface (as `curl --http2-prior-knowledge`
    // opens): refused at once with 505, never left hanging.
    for req in [
        &b"GET /api/state HTTP/2.0\r\nHost: 127.0.0.1\r\n\r\n"[..],
        b"PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n\x00\x00\x00\x04\x00\x00\x00\x00\x00",
    ] {
        let mut s = TcpStream::connect(a).unwrap();
        s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
        // The client does not close its side: the answer must come anyway.
        s.write_all(req).unwrap();
        let mut out = vec![];
        let _ = s.read_to_end(&mut out);
        let text = String::from_utf8_lossy(&out);
        assert!(text.starts_with("HTTP/1.1 505 "), "{text}");
    }
    // Garbage that is not HTTP at all, then a correct answer.
    let _ = raw(a, b"\x00\xff\xfe garbage\r\n\r\n");
    let _ = raw(a, b"GET");
    assert_eq!(get(a, "/api/state")["bars"], 12);
    ed.stop();
}

#[test]
fn thousands_of_bad_and_concurrent_requests_leave_the_edit_intact() {
    let (ed, path) = start("storm");
    let a = ed.addr();
    let bad: Vec<Vec<u8>> = vec![
        b"GET /../../etc/passwd HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n".to_vec(),
        b"GET /api/state HTTP/1.1\r\nHost: evil.com\r\nConnection: close\r\n\r\n".to_vec(),
        b"POST /api/set HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: 4\r\nConnection: close\r\n\r\n{\"ba".to_vec(),
        b"POST /api/set HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: 2\r\nConnection: close\r\n\r\n[]".to_vec(),
        b"POST /api/search HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: 99999999\r\nConnection: close\r\n\r\n".to_vec(),
        b"\x16\x03\x01\x02\x00\x01\x00\x01\xfc\x03\x03".to_vec(),
        b"GET /api/candidates?bar=99999999999999999999 HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n".to_vec(),
        b"POST /api/like HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: 30\r\nConnection: close\r\n\r\n{\"bar\":1e400,\"segment\":0}     ".to_vec(),
    ];
    // Four threads of bad requests; four "tabs", each pinning and unpinning its own bar.
    std::thread::scope(|sc| {
        for t in 0..4 {
            let bad = &bad;
            sc.spawn(move || {
                for k in 0..500 {
                    let r = raw(a, &bad[(k + t) % bad.len()]);
                    assert!(
                        r.status == 0 || (400..=413).contains(&r.status),
                        "{}: {}",
                        r.status,
                        r.text()
                    );
                }
            });
        }
        for tab in 0..4usize {
            sc.spawn(move || {
                for k in 0..25 {
                    post(
                        a,
                        "/api/set",
                        &format!(r#"{{"bar": {tab}, "segment": {}}}"#, k % 5),
                    );
                    if k % 2 == 1 {
                        post(a, "/api/unpin", &format!(r#"{{"bar": {tab}}}"#));
                    }
                }
            });
        }
    });
    // Each tab made 25 sets (k % 5 differs from the pin before, or there was none) and 12
    // unpins; its bar ends pinned to 24 % 5 = 4.
    let s = get(a, "/api/state");
    assert_eq!(s["undo"], 4 * (25 + 12));
    let pins: BTreeSet<(String, u64)> = s["pins"]
        .as_object()
        .unwrap()
        .iter()
        .map(|(k, v)| (k.clone(), v.as_u64().unwrap()))
        .collect();
    let want: BTreeSet<(String, u64)> = (0..4).map(|t| (t.to_string(), 4)).collect();
    assert_eq!(pins, want);
    post(a, "/api/save", "{}");
    let back = pins_of(&path);
    assert_eq!(back.len(), 4);
    assert!(back.values().all(|&s| s == 4));
    assert_eq!(segments(&post(a, "/api/search", r#"{"bar": 5}"#)).len(), 6);
    ed.stop();
}

#[test]
fn clients_that_stall_hold_no_one_else_up() {
    let (ed, _) = start("stalled");
    let a = ed.addr();
    // Clients that stop mid-request and never close: bodies shorter than their Content-Length
    // (over and under the 1,024 bytes a server may read ahead), a chunked body cut off, an
    // `Expect: 100-continue` never followed by its body, headers cut off.
    let cut: [&[u8]; 5] = [
        b"POST /api/set HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: 2000\r\n\r\n{\"bar\": 1,",
        b"POST /api/set HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: 500\r\n\r\n{\"bar\"",
        b"POST /api/search HTTP/1.1\r\nHost: 127.0.0.1\r\nTransfer-Encoding: chunked\r\n\r\n9\r\n{\"bar",
        b"POST /api/search HTTP/1.1\r\nHost: 127.0.0.1\r\nExpect: 100-continue\r\nContent-Length: 1500\r\n\r\n",
        b"GET /api/state HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: ",
    ];
    let mut stalled: Vec<TcpStream> = (0..20)
        .map(|k| {
            let mut s = TcpStream::connect(a).unwrap();
            s.write_all(cut[k % cut.len()]).unwrap();
            s
        })
        .collect();
    // Clients that ask for the song (the longest answer) again and again and never read.
    for _ in 0..4 {
        let mut s = TcpStream::connect(a).unwrap();
        for _ in 0..8 {
            s.write_all(b"GET /api/audio.wav HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
                .unwrap();
        }
        stalled.push(s);
    }
    std::thread::sleep(Duration::from_millis(300));
    // Everyone else is answered (each request gives up after 10 s), from four tabs at once.
    std::thread::scope(|sc| {
        for tab in 0..4usize {
            sc.spawn(move || {
                for k in 0..5 {
                    post(
                        a,
                        "/api/set",
                        &format!(r#"{{"bar": {tab}, "segment": {}}}"#, k + 1),
                    );
                    assert_eq!(
                        segments(&get(a, &format!("/api/candidates?bar={tab}"))).len(),
                        0
                    );
                }
            });
        }
    });
    let big = format!(
        r#"{{"bar": 6, "segment": 2, "pad": "{}"}}"#,
        " ".repeat(3000)
    );
    let r = request(a, "POST", "/api/set", Some(&big));
    assert_eq!(r.status, 400, "{}", r.text());
    assert!(r.text().contains("unknown field `pad`"), "{}", r.text());
    let s = get(a, "/api/state");
    assert_eq!(s["undo"], 20);
    assert_eq!(s["pins"]["3"], 5);
    // The stalled clients go away; their requests end and the server goes on.
    drop(stalled);
    std::thread::sleep(Duration::from_millis(200));
    assert_eq!(post(a, "/api/generate", "{}")["fill"]["segments"][3], 5);
    ed.stop();
}

/// Issue 36: the song is sent bar by bar (`?bar=K`) as mono 16-bit WAV at 22.05 kHz, the bars'
/// pieces tiling the whole song's samples; a bar out of range is a clear 400. After a Set (or
/// Undo) the unpinned bars' fills are marked stale until the next Generate.
#[test]
fn the_song_is_sent_by_bar_and_stale_fills_are_marked_until_generate() {
    let (ed, _) = start("by-bar");
    let a = ed.addr();
    let bars = get(a, "/api/bars");
    let list = bars["bars"].as_array().unwrap();
    let whole = request(a, "GET", "/api/audio.wav", None).body;
    let mut joined = vec![];
    for (k, bar) in list.iter().enumerate() {
        let w = request(a, "GET", &format!("/api/audio.wav?bar={k}"), None);
        assert_eq!(w.status, 200);
        assert_eq!(&w.body[..4], b"RIFF");
        assert_eq!(
            u32::from_le_bytes(w.body[24..28].try_into().unwrap()),
            22_050
        );
        assert_eq!(u16::from_le_bytes(w.body[22..24].try_into().unwrap()), 1);
        let span = bar["end_s"].as_f64().unwrap() - bar["start_s"].as_f64().unwrap();
        assert!(((w.body.len() - 44) as f64 / 2.0 / 22_050.0 - span).abs() < 1e-4);
        joined.extend_from_slice(&w.body[44..]);
    }
    let first = (list[0]["start_s"].as_f64().unwrap() * 22_050.0).round() as usize;
    assert_eq!(joined, whole[44 + 2 * first..44 + 2 * first + joined.len()]);
    for (q, says) in [
        (
            "bar=12",
            "bar 12 is out of range (the song has 12 bars, 0 to 11)",
        ),
        ("bar=x", "`bar=x` is not an index"),
        ("bars=1", "`bar` is missing"),
    ] {
        let r = request(a, "GET", &format!("/api/audio.wav?{q}"), None);
        assert_eq!(r.status, 400, "{q}");
        assert!(r.text().contains(says), "{q}: {}", r.text());
    }

    let stale = |a| {
        let b = get(a, "/api/bars");
        let per: Vec<bool> = b["bars"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x["stale"].as_bool().unwrap())
            .collect();
        (b["stale"].as_bool().unwrap(), per)
    };
    assert_eq!(stale(a), (false, vec![false; 12]));
    post(a, "/api/set", r#"{"bar": 3, "segment": 2}"#);
    let (any, per) = stale(a);
    assert!(any);
    assert!(!per[3], "a pinned bar is not stale");
    assert!(per.iter().enumerate().all(|(k, &s)| s == (k != 3)));
    post(a, "/api/generate", "{}");
    assert_eq!(stale(a), (false, vec![false; 12]));
    post(a, "/api/undo", "{}");
    assert!(stale(a).0, "Undo changes the pins: stale again");
    post(a, "/api/generate", "{}");
    assert!(!stale(a).0);
    ed.stop();
}

/// Issue 36: each candidate names its clip by file stem and bar, and says how it fits the bar:
/// the bar's loudness rank, the segment's intensity rank, rel = 1 − |difference|, W's unit.
#[test]
fn candidates_carry_the_clip_name_and_their_fit_to_the_bar() {
    let (ed, _) = start("fit");
    let a = ed.addr();
    let c = post(a, "/api/search", r#"{"bar": 4}"#);
    let loud = c["loudness_rank"].as_f64().unwrap();
    assert!((0.0..=1.0).contains(&loud));
    assert_eq!(c["intensity_unit"], "m/s");
    for m in c["candidates"].as_array().unwrap() {
        let source = m["source"].as_str().unwrap();
        let stem = std::path::Path::new(source).file_stem().unwrap();
        assert_eq!(m["name"].as_str().unwrap(), stem.to_str().unwrap());
        assert!(!m["name"].as_str().unwrap().contains('/'));
        let rank = m["intensity_rank"].as_f64().unwrap();
        assert!((0.0..=1.0).contains(&rank));
        let rel = m["relevance"].as_f64().unwrap();
        assert!((rel - (1.0 - (loud - rank).abs())).abs() < 1e-12);
    }
    ed.stop();
}

/// Issue 36: a candidate plays between its bar's current neighbours. The seams name the
/// neighbours the fill danced, and danced at the fill's own segments they cost, summed over
/// the song, the fill's total transition cost; the first and last bars have one seam each.
#[test]
fn a_candidate_plays_between_its_neighbours_with_both_seams_costed() {
    let (ed, _) = start("context");
    let a = ed.addr();
    post(a, "/api/generate", "{}");
    let state = get(a, "/api/state");
    let total = state["fill"]["total_cost"].as_f64().unwrap();
    let bars = get(a, "/api/bars")["bars"].as_array().unwrap().clone();
    let n = bars.len();
    let filled: Vec<u64> = bars.iter().map(|b| b["filled"].as_u64().unwrap()).collect();
    let mut sum = 0.0;
    for k in 0..n {
        let c = get(a, &format!("/api/in-context?bar={k}&segment={}", filled[k]));
        let (start, end, fps) = (
            c["start_s"].as_f64().unwrap(),
            c["end_s"].as_f64().unwrap(),
            c["fps"].as_f64().unwrap(),
        );
        let lo = k.saturating_sub(1);
        assert!((start - bars[lo]["start_s"].as_f64().unwrap()).abs() < 1e-9);
        let frames = c["frames"].as_array().unwrap().len() as f64;
        assert!(
            (frames - (end - start) * fps).abs() <= 2.0,
            "bar {k}: {frames} frames for {:.3} s at {fps} fps",
            end - start
        );
        if k == 0 {
            assert!(c["before"].is_null());
        } else {
            assert_eq!(c["before"]["from"].as_u64(), Some(filled[k - 1]));
            assert_eq!(c["before"]["to"].as_u64(), Some(filled[k]));
            sum += c["before"]["cost"].as_f64().unwrap();
        }
        if k + 1 == n {
            assert!(c["after"].is_null());
        } else {
            assert_eq!(c["after"]["from"].as_u64(), Some(filled[k]));
            assert_eq!(c["after"]["to"].as_u64(), Some(filled[k + 1]));
        }
    }
    assert!(
        (sum - total).abs() <= 1e-5 * total,
        "seams sum to {sum}, the fill costs {total}"
    );
    // Another segment: the seams join it to the same neighbours; a pin next door is used.
    let other = (filled[2] + 1) % state["segments"].as_u64().unwrap();
    post(
        a,
        "/api/set",
        &format!(r#"{{"bar": 1, "segment": {other}}}"#),
    );
    let c = get(a, &format!("/api/in-context?bar=2&segment={other}"));
    assert_eq!(c["before"]["from"].as_u64(), Some(other));
    assert_eq!(c["before"]["to"].as_u64(), Some(other));
    assert_eq!(c["after"]["to"].as_u64(), Some(filled[3]));
    let s = c["before"]["s"].as_f64().unwrap();
    let cost = c["before"]["cost"].as_f64().unwrap();
    assert!(
        cost > 0.0 && (s <= 0.0 || s * cost <= 1.0 + 1e-9),
        "S {s}, C {cost}"
    );
    assert_eq!(
        refused(a, "GET", "/api/in-context?bar=2&segment=99999", None).0,
        400
    );
    assert_eq!(refused(a, "GET", "/api/in-context?bar=2", None).0, 400);
    ed.stop();
}

/// Issue 36: `marionette edit` stops on SIGINT and on SIGTERM by itself and exits 0, the Save
/// sent 200 ms before the signal answered and its scene file whole, with the pin. (That the
/// server waits for an action still running at the signal is by construction,
/// `Editor::shutdown`; this test does not catch a Save mid-write.)
#[test]
fn sigint_and_sigterm_stop_the_server_after_its_saves() {
    use std::process::Command;
    for signal in ["INT", "TERM"] {
        let path = scene(&format!("signal-{signal}"), 6, 10, 12);
        let (mut child, _, addr, _) = start_editor(&path);
        post(addr, "/api/set", r#"{"bar": 4, "segment": 3}"#);
        let saver = std::thread::spawn(move || request(addr, "POST", "/api/save", Some("{}")));
        std::thread::sleep(Duration::from_millis(200));
        let kill = Command::new("kill")
            .args([format!("-{signal}"), child.id().to_string()])
            .status()
            .unwrap();
        assert!(kill.success());
        let t0 = std::time::Instant::now();
        let status = loop {
            if let Some(s) = child.try_wait().unwrap() {
                break s;
            }
            assert!(
                t0.elapsed() < Duration::from_secs(10),
                "SIG{signal}: still running"
            );
            std::thread::sleep(Duration::from_millis(20));
        };
        let mut stderr = String::new();
        std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut stderr).unwrap();
        assert_eq!(status.code(), Some(0), "SIG{signal}: {status:?}\n{stderr}");
        assert!(stderr.contains("dance editor: stopped"), "{stderr}");
        // The save was answered, and the file is the saved scene with its pin.
        let saved = saver.join().unwrap();
        assert_eq!(saved.status, 200, "SIG{signal}: {}", saved.text());
        assert_eq!(pins_of(&path).get(&4), Some(&3), "SIG{signal}");
    }
}
