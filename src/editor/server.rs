//! The editor's HTTP server: tiny_http on 127.0.0.1 only, one [`Session`] behind a `Mutex`
//! (one action at a time, so several tabs never interleave inside an action).
//!
//! Every request is answered on its own thread, at most [`MAX_IN_FLIGHT`] at once: a client
//! that sends part of a body and never closes (tiny_http 0.12 has no read timeout, and drains an
//! unread body when a request is dropped), or never reads a long answer, holds only its own
//! thread — as tiny_http already gives every connection's headers their own thread — never the
//! one that takes requests, so every other client is answered. Only when [`MAX_IN_FLIGHT`]
//! requests are all stuck does the next one wait for a thread.
//!
//! The listening socket has `TCP_NODELAY`, which the accepted connections inherit (Linux,
//! the BSDs): an answer's last partial segment goes out at once instead of waiting for the
//! client's delayed acknowledgement of the one before (Nagle's algorithm), a stall of about
//! 40 ms on a kept-alive connection. Every answer says in a `Server-Timing` header how long the
//! server took over it (`app;dur=` milliseconds, from the request's arrival at its thread to
//! the answer ready), so a client can tell the server's time from the rest.
//!
//! Every request is checked before it reaches the session: a `Host` that is not loopback
//! (`127.0.0.1`, `localhost`, `[::1]`, any port) gets 403 (a DNS-rebinding page cannot talk to
//! it), and so does an `Origin` other than the editor's own (another site's page cannot post to
//! it); a path that is not exactly one of the embedded files or an API route gets 404 (no path
//! from a request reaches the file system, so `..`, encoded slashes and absolute paths are
//! simply unknown); a body over [`MAX_BODY`] bytes gets 413. Nothing in the request path
//! unwraps request data; a poisoned lock (which only a bug could cause) is taken over rather
//! than spreading.

use std::io::Read;
use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

use super::EditorError;
use super::api::{Reply, handle};
use super::session::{Session, Song};

/// The default port of `marionette edit`.
pub const DEFAULT_PORT: u16 = 8765;

/// Largest request body accepted (bytes); the API's bodies are a few dozen bytes.
pub const MAX_BODY: usize = 16 * 1024;

/// Requests answered at once, each on its own thread; the next waits for one to finish.
pub const MAX_IN_FLIGHT: usize = 256;

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

/// How many requests are being answered, and a signal when one is done.
#[derive(Default)]
struct InFlight {
    count: Mutex<usize>,
    done: Condvar,
}

/// One request's place among the [`MAX_IN_FLIGHT`]; given back when dropped.
struct Slot(Arc<InFlight>);

impl InFlight {
    /// Waits for a free place (or for `stop`).
    fn acquire(self: &Arc<Self>, stop: &AtomicBool) -> Option<Slot> {
        let mut n = self.count.lock().unwrap_or_else(|e| e.into_inner());
        while *n >= MAX_IN_FLIGHT {
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
}

impl Drop for Slot {
    fn drop(&mut self) {
        let mut n = self.0.count.lock().unwrap_or_else(|e| e.into_inner());
        *n -= 1;
        self.0.done.notify_one();
    }
}

/// A running editor server.
pub struct Editor {
    server: Arc<tiny_http::Server>,
    addr: SocketAddr,
    stop: Arc<AtomicBool>,
    dispatcher: JoinHandle<()>,
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
        let listener = listen(want).map_err(|e| bind_err(e.to_string()))?;
        let server = tiny_http::Server::from_listener(listener, None)
            .map_err(|e| bind_err(e.to_string()))?;
        let addr = server
            .server_addr()
            .to_ip()
            .ok_or_else(|| EditorError::Bind {
                addr: want.to_string(),
                message: "not an IP socket".into(),
            })?;
        let server = Arc::new(server);
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
        let dispatcher = {
            let (server, stop, session, in_flight) = (
                server.clone(),
                stop.clone(),
                session.clone(),
                in_flight.clone(),
            );
            std::thread::spawn(move || {
                while !stop.load(Ordering::Relaxed) {
                    let Ok(Some(rq)) = server.recv_timeout(Duration::from_millis(100)) else {
                        continue;
                    };
                    let Some(slot) = in_flight.acquire(&stop) else {
                        break;
                    };
                    let (session, song) = (session.clone(), song.clone());
                    // Should the system refuse a thread, the request is dropped (tiny_http
                    // answers 500).
                    let _ = std::thread::Builder::new()
                        .name("editor-request".into())
                        .spawn(move || {
                            let _slot = slot;
                            serve(rq, &session, &song, addr.port());
                        });
                }
            })
        };
        Ok(Editor {
            server,
            addr,
            stop,
            dispatcher,
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
        let _ = self.dispatcher.join();
    }

    /// Stops taking requests (those being answered finish on their own threads).
    pub fn stop(self) {
        self.stop.store(true, Ordering::Relaxed);
        let _ = self.dispatcher.join();
        drop(self.server);
    }

    /// Stops taking requests and waits for those being answered: up to `grace` for every one
    /// to end (a client stalled mid-body may never end), then for the session, so that an
    /// action holding it — a Save writing the scene — is finished before this returns. Returns
    /// how many requests were still waiting for their clients.
    pub fn shutdown(self, grace: Duration) -> usize {
        self.stop.store(true, Ordering::Relaxed);
        let _ = self.dispatcher.join();
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
        drop(self.server);
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

/// The values of every header `name` of `rq`.
fn header_values<'a>(rq: &'a tiny_http::Request, name: &'static str) -> Vec<&'a str> {
    rq.headers()
        .iter()
        .filter(|h| h.field.equiv(name))
        .map(|h| h.value.as_str())
        .collect()
}

fn answer(
    rq: &mut tiny_http::Request,
    session: &Mutex<Session>,
    song: &SongPieces,
    port: u16,
) -> Reply {
    let hosts = header_values(rq, "Host");
    if hosts.len() != 1 || !loopback_host(hosts[0]) {
        return Reply::error(
            403,
            "the editor answers only requests to 127.0.0.1 or localhost",
        );
    }
    if header_values(rq, "Origin")
        .iter()
        .any(|o| !own_origin(o, port))
    {
        return Reply::error(403, "the editor answers only its own page (Origin)");
    }
    let method = rq.method().as_str().to_string();
    let url = rq.url().to_string();
    let (path, query) = url.split_once('?').unwrap_or((&url, ""));
    if path == "/api/audio.wav"
        && method == "GET"
        && rq.body_length().unwrap_or(0) == 0
        && header_values(rq, "Transfer-Encoding").is_empty()
    {
        return match super::api::audio(&song.song, &song.bars, query) {
            Ok(r) | Err(r) => r,
        };
    }
    if path.starts_with("/api/") {
        if rq.body_length().is_some_and(|n| n > MAX_BODY) {
            return Reply::error(413, &format!("request body over {MAX_BODY} bytes"));
        }
        let mut body = Vec::new();
        if rq
            .as_reader()
            .take(MAX_BODY as u64 + 1)
            .read_to_end(&mut body)
            .is_err()
        {
            return Reply::error(400, "request body: could not be read");
        }
        if body.len() > MAX_BODY {
            return Reply::error(413, &format!("request body over {MAX_BODY} bytes"));
        }
        let mut s = session.lock().unwrap_or_else(|e| e.into_inner());
        return handle(&mut s, &method, path, query, &body);
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

/// A listening socket on `addr` with `TCP_NODELAY`, which its connections inherit (module
/// docs).
fn listen(addr: SocketAddr) -> std::io::Result<std::net::TcpListener> {
    let listener = std::net::TcpListener::bind(addr)?;
    socket2::SockRef::from(&listener).set_tcp_nodelay(true)?;
    Ok(listener)
}

fn header(name: &str, value: &str) -> Option<tiny_http::Header> {
    tiny_http::Header::from_bytes(name.as_bytes(), value.as_bytes()).ok()
}

fn serve(mut rq: tiny_http::Request, session: &Mutex<Session>, song: &SongPieces, port: u16) {
    let t0 = std::time::Instant::now();
    let r = answer(&mut rq, session, song, port);
    let server_ms = t0.elapsed().as_secs_f64() * 1e3;
    let mut resp = tiny_http::Response::from_data(r.body).with_status_code(r.status);
    let headers = [
        header("Content-Type", r.content_type),
        header("Cache-Control", "no-store"),
        header("Server-Timing", &format!("app;dur={server_ms:.2}")),
        header("X-Content-Type-Options", "nosniff"),
        header(
            "Content-Security-Policy",
            "default-src 'self'; media-src 'self' blob:; img-src 'self' data: blob:",
        ),
        r.download.and_then(|f| {
            header(
                "Content-Disposition",
                &format!("attachment; filename=\"{f}\""),
            )
        }),
    ];
    for h in headers.into_iter().flatten() {
        resp.add_header(h);
    }
    // A client that went away is not the server's failure.
    let _ = rq.respond(resp);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An answer's last partial segment must not wait for the client's delayed ACK (about
    /// 40 ms per kept-alive request): the connections the server accepts have `TCP_NODELAY`.
    #[test]
    fn accepted_connections_do_not_wait_for_acks() {
        let listener = listen(SocketAddr::from(([127, 0, 0, 1], 0))).unwrap();
        let _client = std::net::TcpStream::connect(listener.local_addr().unwrap()).unwrap();
        let (accepted, _) = listener.accept().unwrap();
        assert!(accepted.nodelay().unwrap());
    }

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
