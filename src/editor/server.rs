//! The editor's HTTP server on 127.0.0.1 only: one [`Session`] behind a `Mutex` (one action at
//! a time, so several tabs never interleave inside an action).
//!
//! Every connection is served on its own thread, at most [`MAX_CONNECTIONS`] at once (the next
//! waits in the listening queue), by the editor's HTTP/1.1 layer (`editor::http`): a client that
//! sends part of a request and stalls, or never reads a long answer, holds only its own thread,
//! and only until its deadline (20 s to send a request or take an answer once begun, 30 s idle
//! between requests); every other client is answered meanwhile. An HTTP/2 client gets 505 at
//! once. (tiny_http 0.12, used before, had no read deadlines, and hung for ever on a request of
//! version 2.0: its 505 waited on the writer of the very request it refused.)
//!
//! Accepted connections get `TCP_NODELAY`: an answer's last partial segment goes out at once
//! instead of waiting for the client's delayed acknowledgement of the one before (Nagle's
//! algorithm), a stall of about 40 ms on a kept-alive connection. Every answer says in a
//! `Server-Timing` header how long the server took over it (`app;dur=` milliseconds, from the
//! request's arrival, body read, to the answer ready), so a client can tell the server's time
//! from the rest.
//!
//! Every request is checked before it reaches the session: a `Host` that is not loopback
//! (`127.0.0.1`, `localhost`, `[::1]`, any port) gets 403 (a DNS-rebinding page cannot talk to
//! it), and so does an `Origin` other than the editor's own (another site's page cannot post to
//! it); a path that is not exactly one of the embedded files or an API route gets 404 (no path
//! from a request reaches the file system, so `..`, encoded slashes and absolute paths are
//! simply unknown); a body over [`MAX_BODY`] bytes gets 413 before it is read. Nothing in the
//! request path unwraps request data; a poisoned lock (which only a bug could cause) is taken
//! over rather than spreading.

use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

use super::EditorError;
use super::api::{Reply, handle};
use super::http;
use super::session::{Session, Song};

/// The default port of `marionette edit`.
pub const DEFAULT_PORT: u16 = 8765;

/// Largest request body accepted (bytes); the API's bodies are a few dozen bytes.
pub const MAX_BODY: usize = 16 * 1024;

/// Connections served at once, each on its own thread; the next waits for one to close.
pub const MAX_CONNECTIONS: usize = 1024;

/// The page's files, embedded in the binary: (path, content type, bytes).
const ASSETS: [(&str, &str, &[u8]); 5] = [
    (
        "/",
        "text/html; charset=utf-8",
        include_bytes!("page/index.html"),
    ),
    (
        "/app.js",
        "text/javascript; charset=utf-8",
        include_bytes!("page/app.js"),
    ),
    (
        "/figure.js",
        "text/javascript; charset=utf-8",
        // The shared orbit camera first: the editor's stick figure extends it.
        concat!(
            include_str!("../render/page/orbit.js"),
            include_str!("page/figure.js")
        )
        .as_bytes(),
    ),
    (
        "/timeline.js",
        "text/javascript; charset=utf-8",
        include_bytes!("page/timeline.js"),
    ),
    (
        "/style.css",
        "text/css; charset=utf-8",
        include_bytes!("page/style.css"),
    ),
];

/// The song and its bars' spans (s), fixed for a session: `GET /api/audio.wav` is answered from
/// them without the session's lock, so the song never waits behind a Generate or a dance.
struct SongPieces {
    song: Arc<Song>,
    bars: Vec<(f64, f64)>,
}

/// A count of connections or of requests being answered, and a signal when one ends.
#[derive(Default)]
struct InFlight {
    count: Mutex<usize>,
    done: Condvar,
}

/// One connection's place among the [`MAX_CONNECTIONS`]; given back when dropped.
struct Slot(Arc<InFlight>);

impl InFlight {
    /// Waits for a place among `limit` (or for `stop`).
    fn acquire(self: &Arc<Self>, limit: usize, stop: &AtomicBool) -> Option<Slot> {
        let mut n = self.count.lock().unwrap_or_else(|e| e.into_inner());
        while *n >= limit {
            if stop.load(Ordering::Relaxed) {
                return None;
            }
            n = self
                .done
                .wait_timeout(n, Duration::from_millis(100))
                .unwrap_or_else(|e| e.into_inner())
                .0;
        }
        *n += 1;
        Some(Slot(self.clone()))
    }

    /// One more.
    fn begin(&self) {
        *self.count.lock().unwrap_or_else(|e| e.into_inner()) += 1;
    }

    /// One less, and a signal.
    fn end(&self) {
        let mut n = self.count.lock().unwrap_or_else(|e| e.into_inner());
        *n = n.saturating_sub(1);
        self.done.notify_all();
    }
}

impl Drop for Slot {
    fn drop(&mut self) {
        self.0.end();
    }
}

/// A running editor server.
pub struct Editor {
    addr: SocketAddr,
    stop: Arc<AtomicBool>,
    acceptor: JoinHandle<()>,
    session: Arc<Mutex<Session>>,
    in_flight: Arc<InFlight>,
}

impl Editor {
    /// Starts serving `session` on 127.0.0.1:`port` (0: a free port).
    pub fn start(session: Session, port: u16) -> Result<Editor, EditorError> {
        let want = SocketAddr::from(([127, 0, 0, 1], port));
        let bind_err = |message: String| EditorError::Bind {
            addr: want.to_string(),
            message,
        };
        let listener = std::net::TcpListener::bind(want).map_err(|e| bind_err(e.to_string()))?;
        let addr = listener.local_addr().map_err(|e| bind_err(e.to_string()))?;
        let song = Arc::new(SongPieces {
            song: session.shared_song(),
            bars: session
                .edit()
                .bars()
                .iter()
                .map(|b| (b.start_s, b.end_s))
                .collect(),
        });
        let session = Arc::new(Mutex::new(session));
        let stop = Arc::new(AtomicBool::new(false));
        let in_flight = Arc::new(InFlight::default());
        let connections = Arc::new(InFlight::default());
        let acceptor = {
            let (stop, session, in_flight) = (stop.clone(), session.clone(), in_flight.clone());
            std::thread::spawn(move || {
                for stream in listener.incoming() {
                    if stop.load(Ordering::Relaxed) {
                        break;
                    }
                    let Ok(stream) = stream else {
                        // Out of descriptors, say: wait for connections to close rather than
                        // spin on the queued ones.
                        std::thread::sleep(Duration::from_millis(50));
                        continue;
                    };
                    // Answers go out whole at once (module docs).
                    let _ = stream.set_nodelay(true);
                    let Some(slot) = connections.acquire(MAX_CONNECTIONS, &stop) else {
                        break;
                    };
                    let (session, song, stop, in_flight) = (
                        session.clone(),
                        song.clone(),
                        stop.clone(),
                        in_flight.clone(),
                    );
                    // Should the system refuse a thread, the connection is closed unanswered.
                    let _ = std::thread::Builder::new()
                        .name("editor-connection".into())
                        .spawn(move || {
                            let _slot = slot;
                            let handle =
                                |rq: http::Request| serve(&rq, &session, &song, addr.port());
                            http::serve_connection(
                                stream,
                                MAX_BODY,
                                &stop,
                                &handle,
                                &|| in_flight.begin(),
                                &|| in_flight.end(),
                            );
                        });
                }
            })
        };
        Ok(Editor {
            addr,
            stop,
            acceptor,
            session,
            in_flight,
        })
    }

    /// The address served.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// The page's URL.
    pub fn url(&self) -> String {
        format!("http://{}/", self.addr)
    }

    /// Serves until the process ends.
    pub fn wait(self) {
        let _ = self.acceptor.join();
    }

    /// Stops taking connections and requests; kept-alive connections close, and requests being
    /// answered finish on their own threads.
    pub fn stop(self) {
        self.stop_accepting();
        let _ = self.acceptor.join();
    }

    fn stop_accepting(&self) {
        self.stop.store(true, Ordering::Relaxed);
        // The acceptor waits in `accept`: one more connection wakes it to see the flag.
        let _ = std::net::TcpStream::connect(self.addr);
    }

    /// Stops taking requests and waits for those being answered: up to `grace` for every one
    /// to end (a client stalled mid-body may take until its deadline, [`http::TRANSFER`]), then
    /// for the session, so that an action holding it — a Save writing the scene — is finished
    /// before this returns. Returns how many requests were still waiting for their clients.
    pub fn shutdown(self, grace: Duration) -> usize {
        self.stop_accepting();
        let _ = self.acceptor.join();
        let until = std::time::Instant::now() + grace;
        let mut n = self
            .in_flight
            .count
            .lock()
            .unwrap_or_else(|e| e.into_inner());
        while *n > 0 {
            let left = until.saturating_duration_since(std::time::Instant::now());
            if left.is_zero() {
                break;
            }
            n = self
                .in_flight
                .done
                .wait_timeout(n, left)
                .unwrap_or_else(|e| e.into_inner())
                .0;
        }
        let stuck = *n;
        drop(n);
        drop(self.session.lock().unwrap_or_else(|e| e.into_inner()));
        stuck
    }
}

/// Whether a `Host` header value names the loopback host (any port).
pub fn loopback_host(host: &str) -> bool {
    let host = host.trim();
    let name = if let Some(rest) = host.strip_prefix('[') {
        match rest.split_once(']') {
            Some((h, port)) if port.is_empty() || port.strip_prefix(':').is_some_and(port_ok) => {
                return h == "::1";
            }
            _ => return false,
        }
    } else {
        match host.rsplit_once(':') {
            Some((h, port)) if port_ok(port) => h,
            Some(_) => return false,
            None => host,
        }
    };
    name == "127.0.0.1" || name.eq_ignore_ascii_case("localhost")
}

fn port_ok(p: &str) -> bool {
    p.parse::<u16>().is_ok()
}

/// Whether an `Origin` header value is the editor's own page: `http://` a loopback host and
/// `port` (80 when the origin names none).
pub fn own_origin(origin: &str, port: u16) -> bool {
    let Some(host) = origin.trim().strip_prefix("http://") else {
        return false;
    };
    let given = match host.rsplit_once(':') {
        Some((h, p)) if !h.is_empty() && !p.contains(']') => p.parse::<u16>().ok(),
        _ => Some(80),
    };
    loopback_host(host) && given == Some(port)
}

fn answer(rq: &http::Request, session: &Mutex<Session>, song: &SongPieces, port: u16) -> Reply {
    let hosts = rq.header_values("Host");
    if hosts.len() != 1 || !loopback_host(hosts[0]) {
        return Reply::error(
            403,
            "the editor answers only requests to 127.0.0.1 or localhost",
        );
    }
    if rq
        .header_values("Origin")
        .iter()
        .any(|o| !own_origin(o, port))
    {
        return Reply::error(403, "the editor answers only its own page (Origin)");
    }
    let method = rq.method.as_str();
    let (path, query) = rq.target.split_once('?').unwrap_or((&rq.target, ""));
    if path == "/api/audio.wav" && method == "GET" && rq.body.is_empty() {
        return match super::api::audio(&song.song, &song.bars, query) {
            Ok(r) | Err(r) => r,
        };
    }
    if path.starts_with("/api/") {
        let mut s = session.lock().unwrap_or_else(|e| e.into_inner());
        return handle(&mut s, method, path, query, &rq.body);
    }
    match ASSETS.iter().find(|a| a.0 == path) {
        Some(&(_, content_type, bytes)) if method == "GET" || method == "HEAD" => Reply {
            status: 200,
            content_type,
            body: bytes.to_vec(),
            download: None,
        },
        Some(_) => Reply::error(405, &format!("{path} takes GET")),
        None => Reply::error(404, &format!("no file {path}")),
    }
}

/// The answer to `rq`, with the headers every answer carries.
fn serve(
    rq: &http::Request,
    session: &Mutex<Session>,
    song: &SongPieces,
    port: u16,
) -> http::Response {
    let t0 = std::time::Instant::now();
    let r = answer(rq, session, song, port);
    let server_ms = t0.elapsed().as_secs_f64() * 1e3;
    let mut headers: Vec<(String, String)> = [
        ("Content-Type", r.content_type.to_string()),
        ("Cache-Control", "no-store".into()),
        ("Server-Timing", format!("app;dur={server_ms:.2}")),
        ("X-Content-Type-Options", "nosniff".into()),
        (
            "Content-Security-Policy",
            "default-src 'self'; media-src 'self' blob:; img-src 'self' data: blob:".into(),
        ),
    ]
    .into_iter()
    .map(|(n, v)| (n.to_string(), v))
    .collect();
    if let Some(f) = r.download {
        headers.push((
            "Content-Disposition".into(),
            format!("attachment; filename=\"{f}\""),
        ));
    }
    http::Response {
        status: r.status,
        headers,
        body: r.body,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn loopback_hosts() {
        for h in [
            "127.0.0.1",
            "127.0.0.1:8765",
            "localhost:1",
            "LOCALHOST",
            "[::1]:80",
            "[::1]",
        ] {
            assert!(loopback_host(h), "{h}");
        }
        for h in [
            "evil.com",
            "127.0.0.1.evil.com",
            "localhost.evil.com:80",
            "127.0.0.1:notaport",
            "[::2]:80",
            "",
            "127.0.0.2",
            "localhost:99999",
        ] {
            assert!(!loopback_host(h), "{h}");
        }
    }

    #[test]
    fn own_origins() {
        for o in [
            "http://127.0.0.1:8765",
            "http://localhost:8765",
            "http://[::1]:8765",
        ] {
            assert!(own_origin(o, 8765), "{o}");
        }
        assert!(own_origin("http://localhost", 80));
        for o in [
            "http://127.0.0.1:8766",
            "http://evil.com:8765",
            "https://127.0.0.1:8765",
            "null",
            "http://127.0.0.1.evil.com:8765",
            "http://[::1]",
            "",
        ] {
            assert!(!own_origin(o, 8765), "{o}");
        }
    }
}
