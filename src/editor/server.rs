//! The editor's HTTP server: tiny_http on 127.0.0.1 only, a few worker threads over one
//! [`Session`] behind a `Mutex` (one action at a time, so several tabs never interleave inside
//! an action).
//!
//! Every request is checked before it reaches the session: a `Host` that is not loopback
//! (`127.0.0.1`, `localhost`, `[::1]`, any port) gets 403 (a DNS-rebinding page cannot talk to
//! it); a path that is not exactly one of the embedded files or an API route gets 404 (no path
//! from a request reaches the file system, so `..`, encoded slashes and absolute paths are
//! simply unknown); a body over [`MAX_BODY`] bytes gets 413. Nothing in the request path
//! unwraps request data; a poisoned lock (which only a bug could cause) is taken over rather
//! than spreading.

use std::io::Read;
use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

use super::EditorError;
use super::api::{Reply, handle};
use super::session::Session;

/// The default port of `marionette edit`.
pub const DEFAULT_PORT: u16 = 8765;

/// Largest request body accepted (bytes); the API's bodies are a few dozen bytes.
pub const MAX_BODY: usize = 16 * 1024;

/// Worker threads answering requests.
const WORKERS: usize = 4;

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
        include_bytes!("page/figure.js"),
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

/// A running editor server.
pub struct Editor {
    server: Arc<tiny_http::Server>,
    addr: SocketAddr,
    stop: Arc<AtomicBool>,
    workers: Vec<JoinHandle<()>>,
}

impl Editor {
    /// Starts serving `session` on 127.0.0.1:`port` (0: a free port).
    pub fn start(session: Session, port: u16) -> Result<Editor, EditorError> {
        let want = SocketAddr::from(([127, 0, 0, 1], port));
        let server = tiny_http::Server::http(want).map_err(|e| EditorError::Bind {
            addr: want.to_string(),
            message: e.to_string(),
        })?;
        let addr = server
            .server_addr()
            .to_ip()
            .ok_or_else(|| EditorError::Bind {
                addr: want.to_string(),
                message: "not an IP socket".into(),
            })?;
        let server = Arc::new(server);
        let session = Arc::new(Mutex::new(session));
        let stop = Arc::new(AtomicBool::new(false));
        let workers = (0..WORKERS)
            .map(|_| {
                let (server, session, stop) = (server.clone(), session.clone(), stop.clone());
                std::thread::spawn(move || {
                    while !stop.load(Ordering::Relaxed) {
                        if let Ok(Some(rq)) = server.recv_timeout(Duration::from_millis(100)) {
                            serve(rq, &session);
                        }
                    }
                })
            })
            .collect();
        Ok(Editor {
            server,
            addr,
            stop,
            workers,
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
        for w in self.workers {
            let _ = w.join();
        }
    }

    /// Stops serving and waits for the workers.
    pub fn stop(self) {
        self.stop.store(true, Ordering::Relaxed);
        for w in self.workers {
            let _ = w.join();
        }
        drop(self.server);
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

fn answer(rq: &mut tiny_http::Request, session: &Mutex<Session>) -> Reply {
    let hosts: Vec<&str> = rq
        .headers()
        .iter()
        .filter(|h| h.field.equiv("Host"))
        .map(|h| h.value.as_str())
        .collect();
    if hosts.len() != 1 || !loopback_host(hosts[0]) {
        return Reply::error(
            403,
            "the editor answers only requests to 127.0.0.1 or localhost",
        );
    }
    let method = rq.method().as_str().to_string();
    let url = rq.url().to_string();
    let (path, query) = url.split_once('?').unwrap_or((&url, ""));
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

fn header(name: &str, value: &str) -> Option<tiny_http::Header> {
    tiny_http::Header::from_bytes(name.as_bytes(), value.as_bytes()).ok()
}

fn serve(mut rq: tiny_http::Request, session: &Mutex<Session>) {
    let r = answer(&mut rq, session);
    let mut resp = tiny_http::Response::from_data(r.body).with_status_code(r.status);
    let headers = [
        header("Content-Type", r.content_type),
        header("Cache-Control", "no-store"),
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
}
