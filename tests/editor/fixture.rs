//! Shared by the editor tests: a `Dance` scene on a database of generated dance clips and a
//! synthesized song, and a plain HTTP/1.1 client over `std::net`.

#![allow(dead_code)] // each test file uses some of these

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::Duration;
use std::time::Instant;

use marionette::choreo::Database;
use marionette::choreo::generated_database;

/// A fresh folder holding `dance.db.json` (generated clips: `clips` × `bars_per_clip` bars) and
/// `dance.ron` (a `Dance` scene: a 120 BPM synthesized song of `song_bars` bars, no pins);
/// returns the scene's path.
pub fn scene(name: &str, clips: usize, bars_per_clip: usize, song_bars: usize) -> PathBuf {
    scene_on(
        name,
        &generated_database(7, clips, bars_per_clip).unwrap(),
        song_bars,
    )
}

/// [`scene`] on the database `db`.
pub fn scene_on(name: &str, db: &Database, song_bars: usize) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("marionette-editor-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    db.save(&dir.join("dance.db.json")).unwrap();
    let text = format!(
        "// The editor tests' dance: generated clips, a synthesized song.\n\
         Dance(\n    format_version: 1,\n    name: \"editor-{name}\",\n    \
         song: Synth(bpm: 120.0, bars: {song_bars}),\n    \
         database: File(\"dance.db.json\"), // written by the test\n    \
         dance: (fps: 30.0, seam_frames: 5),\n    render: (gif: false),\n)\n"
    );
    let path = dir.join("dance.ron");
    std::fs::write(&path, text).unwrap();
    path
}

/// An answer: status and body.
#[derive(Debug)]
pub struct Answer {
    /// Status code (0 when the server closed without a status line).
    pub status: u16,
    /// Headers, lowercase names.
    pub headers: Vec<(String, String)>,
    /// Body bytes.
    pub body: Vec<u8>,
}

impl Answer {
    /// The body as JSON.
    pub fn json(&self) -> serde_json::Value {
        serde_json::from_slice(&self.body)
            .unwrap_or_else(|e| panic!("not JSON ({e}): {}", String::from_utf8_lossy(&self.body)))
    }

    /// The body as text.
    pub fn text(&self) -> String {
        String::from_utf8_lossy(&self.body).into_owned()
    }
}

/// Sends raw bytes and reads the answer until the server closes (send `Connection: close`).
pub fn raw(addr: SocketAddr, bytes: &[u8]) -> Answer {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    // The server may answer (413) and close before the whole body is sent.
    let _ = s.write_all(bytes);
    // Done sending: a request cut short ends here rather than waiting for more bytes.
    let _ = s.shutdown(std::net::Shutdown::Write);
    let mut out = vec![];
    let _ = s.read_to_end(&mut out);
    parse(&out)
}

fn parse(out: &[u8]) -> Answer {
    let split = out.windows(4).position(|w| w == b"\r\n\r\n");
    let Some(split) = split else {
        return Answer {
            status: 0,
            headers: vec![],
            body: out.to_vec(),
        };
    };
    let head = String::from_utf8_lossy(&out[..split]).into_owned();
    let mut lines = head.split("\r\n");
    let status = lines
        .next()
        .and_then(|l| l.split(' ').nth(1))
        .and_then(|c| c.parse().ok())
        .unwrap_or(0);
    let headers: Vec<(String, String)> = lines
        .filter_map(|l| l.split_once(':'))
        .map(|(k, v)| (k.trim().to_ascii_lowercase(), v.trim().to_string()))
        .collect();
    let mut body = out[split + 4..].to_vec();
    if headers
        .iter()
        .any(|(k, v)| k == "transfer-encoding" && v.contains("chunked"))
    {
        body = dechunk(&body);
    }
    Answer {
        status,
        headers,
        body,
    }
}

fn dechunk(mut b: &[u8]) -> Vec<u8> {
    let mut out = vec![];
    while let Some(eol) = b.windows(2).position(|w| w == b"\r\n") {
        let n = usize::from_str_radix(String::from_utf8_lossy(&b[..eol]).trim(), 16).unwrap_or(0);
        if n == 0 {
            break;
        }
        out.extend_from_slice(&b[eol + 2..eol + 2 + n]);
        b = &b[eol + 2 + n + 2..];
    }
    out
}

/// A request with a loopback Host header and `Connection: close`.
pub fn request(addr: SocketAddr, method: &str, path: &str, body: Option<&str>) -> Answer {
    let body = body.unwrap_or("");
    let len = if method == "POST" {
        format!(
            "Content-Length: {}\r\nContent-Type: application/json\r\n",
            body.len()
        )
    } else {
        String::new()
    };
    raw(
        addr,
        format!("{method} {path} HTTP/1.1\r\nHost: {addr}\r\n{len}Connection: close\r\n\r\n{body}")
            .as_bytes(),
    )
}

/// GET as JSON, expecting 200.
pub fn get(addr: SocketAddr, path: &str) -> serde_json::Value {
    let a = request(addr, "GET", path, None);
    assert_eq!(a.status, 200, "GET {path}: {}", a.text());
    a.json()
}

/// POST JSON, expecting 200.
pub fn post(addr: SocketAddr, path: &str, body: &str) -> serde_json::Value {
    let a = request(addr, "POST", path, Some(body));
    assert_eq!(a.status, 200, "POST {path} {body}: {}", a.text());
    a.json()
}

/// Checks that `bvh` is a BVH file from the song's t = 0 to the end of its last bar (from
/// `GET /api/bars`) at 30 fps, within a frame; returns its frame count.
pub fn assert_bvh_lasts_the_bars(addr: SocketAddr, bvh: &str) -> usize {
    assert!(
        bvh.starts_with("HIERARCHY"),
        "{}",
        &bvh[..40.min(bvh.len())]
    );
    let bars = get(addr, "/api/bars");
    let bars = bars["bars"].as_array().unwrap();
    let span = bars[bars.len() - 1]["end_s"].as_f64().unwrap();
    let frames: usize = bvh
        .lines()
        .find_map(|l| l.strip_prefix("Frames:"))
        .expect("a Frames: line")
        .trim()
        .parse()
        .unwrap();
    assert!(
        (frames as f64 - span * 30.0).abs() <= 1.0,
        "{frames} frames for {span} s at 30 fps"
    );
    frames
}

/// `marionette edit SCENE --port 0` started; its child process, URL, address and the seconds
/// until it printed the URL (loading the scene and building the transition table). Its stdout
/// and stderr are piped (the test reads stderr, if it wants to, once the child has ended).
pub fn start_editor(scene: &Path) -> (Child, String, SocketAddr, f64) {
    let t0 = Instant::now();
    let mut child = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["edit", scene.to_str().unwrap(), "--port", "0"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let startup_s = t0.elapsed().as_secs_f64();
    let url = line
        .trim()
        .strip_prefix("dance editor: ")
        .unwrap_or_else(|| panic!("no URL printed: {line:?}"))
        .to_string();
    let addr: SocketAddr = url
        .trim_start_matches("http://")
        .trim_end_matches('/')
        .parse()
        .unwrap();
    assert!(addr.ip().is_loopback());
    (child, url, addr, startup_s)
}
