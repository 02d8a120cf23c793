//! HTTP/1.1 connections (RFC 9112) for the editor: one thread per connection reads each request
//! — its head parsed by `httparse`, its body framed by `Content-Length` or chunked transfer
//! coding — hands it to the server's handler and writes the answer, as long as the client keeps
//! the connection alive.
//!
//! Every wait has a deadline, so a client that stalls holds only its own thread, and only for a
//! while: [`IDLE`] for the next request on a kept-alive connection, [`TRANSFER`] to send a
//! request's head or body once it has begun, or to take an answer. A connection still waiting
//! for its next request when the server stops is closed at once.
//!
//! Refusals close the connection: a head over [`MAX_HEAD`] bytes or [`MAX_HEADERS`] lines (431),
//! a body over the limit (413), a head not HTTP/1, or both `Content-Length` and
//! `Transfer-Encoding` (400, RFC 9112 §6.1), a version other than 1.0 or 1.1 — as HTTP/2's
//! preface (505), a coding other than chunked (501), an `Expect` other than `100-continue`
//! (417), a request too slow (408). The server then reads what still comes for a while before
//! closing, so that the client reads the refusal rather than a reset.

use std::io::{ErrorKind, Read, Write};
use std::net::{Shutdown, TcpStream};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Longest request head (request line and headers), bytes.
pub const MAX_HEAD: usize = 16 * 1024;

/// Most header lines in a request.
pub const MAX_HEADERS: usize = 64;

/// How long a kept-alive connection waits for its next request.
pub const IDLE: Duration = Duration::from_secs(30);

/// How long a request's head or body may take to arrive once begun, and an answer to be taken.
pub const TRANSFER: Duration = Duration::from_secs(20);

/// The longest single wait on the socket: how soon a waiting connection notices a stop.
const POLL: Duration = Duration::from_millis(200);

/// A request as the handler sees it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Request {
    /// The method, as sent (`GET`, `POST`, …).
    pub method: String,
    /// The request target (path and query), as sent.
    pub target: String,
    /// The header lines (name, value) in order, names as sent.
    pub headers: Vec<(String, String)>,
    /// The body, whole (empty when none was sent).
    pub body: Vec<u8>,
}

impl Request {
    /// The values of every header `name` (case-insensitive).
    pub fn header_values(&self, name: &str) -> Vec<&str> {
        values(&self.headers, name).collect()
    }
}

/// The values of every header `name` (case-insensitive) among `headers`.
fn values<'a>(headers: &'a [(String, String)], name: &str) -> impl Iterator<Item = &'a str> {
    headers
        .iter()
        .filter(move |(n, _)| n.eq_ignore_ascii_case(name))
        .map(|(_, v)| v.as_str())
}

/// An answer: status, header lines and body (`Content-Length` and `Connection` are added).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Response {
    /// The status code.
    pub status: u16,
    /// Header lines (name, value).
    pub headers: Vec<(String, String)>,
    /// The body (not sent in answer to `HEAD`, though its length is).
    pub body: Vec<u8>,
}

/// Serves the requests of one connection with `handle` until the client closes it, a refusal
/// closes it, a deadline passes or `stop` is set while it waits for a request. Bodies over
/// `max_body` bytes are refused (413). `started` is called when a request's head has arrived
/// and `finished` when its answer has been written or abandoned (the server counts the requests
/// in flight with them).
pub fn serve_connection(
    mut stream: TcpStream,
    max_body: usize,
    stop: &AtomicBool,
    handle: &dyn Fn(Request) -> Response,
    started: &dyn Fn(),
    finished: &dyn Fn(),
) {
    let _ = stream.set_write_timeout(Some(TRANSFER));
    let mut conn = Connection {
        stream: &mut stream,
        buf: Vec::new(),
        stop,
    };
    loop {
        let head = match conn.head() {
            Ok(Some(h)) => h,
            Ok(None) => return,
            Err(refusal) => return conn.refuse(refusal),
        };
        started();
        let served = conn.exchange(head, max_body, handle);
        finished();
        match served {
            Ok(true) => {}
            Ok(false) => {
                let _ = conn.stream.shutdown(Shutdown::Write);
                return;
            }
            Err(refusal) => return conn.refuse(refusal),
        }
    }
}

/// Why a request is refused: its status and a one-line reason.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Refusal(u16, String);

impl Refusal {
    fn new(status: u16, why: impl Into<String>) -> Refusal {
        Refusal(status, why.into())
    }
    fn too_large(max_body: usize) -> Refusal {
        Refusal::new(413, format!("request body over {max_body} bytes"))
    }
}

/// A parsed request head and how its body is framed.
struct Head {
    method: String,
    target: String,
    headers: Vec<(String, String)>,
    minor: u8,
}

impl Head {
    fn values(&self, name: &str) -> impl Iterator<Item = &str> {
        values(&self.headers, name)
    }

    /// Whether the connection stays open after this request (RFC 9112 §9.3).
    fn keep_alive(&self) -> bool {
        let has = |token: &str| {
            self.values("Connection")
                .flat_map(|v| v.split(','))
                .any(|t| t.trim().eq_ignore_ascii_case(token))
        };
        if self.minor == 0 {
            has("keep-alive")
        } else {
            !has("close")
        }
    }
}

/// How a request's body is framed.
enum Framing {
    Length(usize),
    Chunked,
}

struct Connection<'a> {
    stream: &'a mut TcpStream,
    /// Bytes read but not yet used (the start of the next request when pipelined).
    buf: Vec<u8>,
    stop: &'a AtomicBool,
}

/// What a wait for bytes gave.
enum Got {
    Bytes,
    Closed,
    Late,
}

impl Connection<'_> {
    /// Reads more bytes into `buf` before `deadline`; when `idle`, gives up as soon as the server
    /// stops.
    fn fill(&mut self, deadline: Instant, idle: bool) -> Got {
        let mut chunk = [0u8; 8192];
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() || (idle && self.stop.load(Ordering::Relaxed)) {
                return Got::Late;
            }
            let _ = self.stream.set_read_timeout(Some(left.min(POLL)));
            match self.stream.read(&mut chunk) {
                Ok(0) => return Got::Closed,
                Ok(n) => {
                    self.buf.extend_from_slice(&chunk[..n]);
                    return Got::Bytes;
                }
                Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {}
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(_) => return Got::Closed,
            }
        }
    }

    /// The next request's head; `None` when the client closed or went quiet between requests.
    fn head(&mut self) -> Result<Option<Head>, Refusal> {
        let mut deadline = Instant::now() + IDLE;
        let mut begun = !self.buf.is_empty();
        if begun {
            deadline = Instant::now() + TRANSFER;
        }
        loop {
            if begun {
                let mut lines = [httparse::EMPTY_HEADER; MAX_HEADERS];
                let mut req = httparse::Request::new(&mut lines);
                match req.parse(&self.buf) {
                    Ok(httparse::Status::Complete(len)) => {
                        let head = own(&req)?;
                        self.buf.drain(..len);
                        return Ok(Some(head));
                    }
                    Ok(httparse::Status::Partial) => {}
                    Err(httparse::Error::Version) => {
                        return Err(Refusal::new(
                            505,
                            "the editor speaks HTTP/1.1 (and 1.0) only",
                        ));
                    }
                    Err(httparse::Error::TooManyHeaders) => {
                        return Err(Refusal::new(
                            431,
                            format!("more than {MAX_HEADERS} header lines"),
                        ));
                    }
                    Err(e) => return Err(Refusal::new(400, format!("not an HTTP request: {e}"))),
                }
                if self.buf.len() > MAX_HEAD {
                    return Err(Refusal::new(
                        431,
                        format!("request head over {MAX_HEAD} bytes"),
                    ));
                }
            }
            match self.fill(deadline, !begun) {
                Got::Bytes => {
                    if !begun {
                        begun = true;
                        deadline = Instant::now() + TRANSFER;
                    }
                }
                Got::Closed if begun => {
                    return Err(Refusal::new(400, "the request head was cut off"));
                }
                Got::Closed => return Ok(None),
                Got::Late if begun => {
                    return Err(Refusal::new(408, "the request head took too long"));
                }
                Got::Late => return Ok(None),
            }
        }
    }

    /// Reads `head`'s body, answers it and writes the answer; whether the connection stays open.
    fn exchange(
        &mut self,
        head: Head,
        max_body: usize,
        handle: &dyn Fn(Request) -> Response,
    ) -> Result<bool, Refusal> {
        let framing = framing(&head)?;
        if let Framing::Length(n) = framing
            && n > max_body
        {
            return Err(Refusal::too_large(max_body));
        }
        let expects: Vec<&str> = head.values("Expect").collect();
        if let Some(e) = expects
            .iter()
            .find(|e| !e.trim().eq_ignore_ascii_case("100-continue"))
        {
            return Err(Refusal::new(417, format!("cannot meet Expect: {e}")));
        }
        let body_coming = !matches!(framing, Framing::Length(0));
        if !expects.is_empty() && head.minor == 1 && body_coming && self.buf.is_empty() {
            self.write(b"HTTP/1.1 100 Continue\r\n\r\n")?;
        }
        let deadline = Instant::now() + TRANSFER;
        let body = match framing {
            Framing::Length(n) => self.exactly(n, deadline)?,
            Framing::Chunked => self.chunked(max_body, deadline)?,
        };
        let keep = head.keep_alive();
        let is_head = head.method == "HEAD";
        let answer = handle(Request {
            method: head.method,
            target: head.target,
            headers: head.headers,
            body,
        });
        self.answer(&answer, keep, is_head)?;
        Ok(keep)
    }

    /// The next `n` bytes of the body.
    fn exactly(&mut self, n: usize, deadline: Instant) -> Result<Vec<u8>, Refusal> {
        while self.buf.len() < n {
            self.more(deadline, "the request body")?;
        }
        Ok(self.buf.drain(..n).collect())
    }

    /// More bytes before `deadline`, or the refusal for `what` cut off or late.
    fn more(&mut self, deadline: Instant, what: &str) -> Result<(), Refusal> {
        match self.fill(deadline, false) {
            Got::Bytes => Ok(()),
            Got::Closed => Err(Refusal::new(400, format!("{what} was cut off"))),
            Got::Late => Err(Refusal::new(408, format!("{what} took too long"))),
        }
    }

    /// One line (without its CRLF) of a chunked body, at most `MAX_HEAD` bytes.
    fn line(&mut self, deadline: Instant) -> Result<String, Refusal> {
        loop {
            if let Some(i) = self.buf.windows(2).position(|w| w == b"\r\n") {
                let line: Vec<u8> = self.buf.drain(..i + 2).take(i).collect();
                return String::from_utf8(line)
                    .map_err(|_| Refusal::new(400, "a chunk line is not text"));
            }
            if self.buf.len() > MAX_HEAD {
                return Err(Refusal::new(400, "a chunk line is too long"));
            }
            self.more(deadline, "the chunked request body")?;
        }
    }

    /// A chunked body (RFC 9112 §7.1): chunks of a hexadecimal size, then trailer lines.
    fn chunked(&mut self, max_body: usize, deadline: Instant) -> Result<Vec<u8>, Refusal> {
        let mut body = Vec::new();
        loop {
            let line = self.line(deadline)?;
            let size = line.split(';').next().unwrap_or("").trim();
            let size = usize::from_str_radix(size, 16)
                .ok()
                .filter(|_| !size.is_empty() && size.bytes().all(|b| b.is_ascii_hexdigit()))
                .ok_or_else(|| Refusal::new(400, format!("bad chunk size {size:?}")))?;
            if size == 0 {
                while !self.line(deadline)?.is_empty() {}
                return Ok(body);
            }
            if body.len().saturating_add(size) > max_body {
                return Err(Refusal::too_large(max_body));
            }
            body.extend(self.exactly(size, deadline)?);
            if !self.line(deadline)?.is_empty() {
                return Err(Refusal::new(400, "a chunk is longer than its size"));
            }
        }
    }

    fn write(&mut self, bytes: &[u8]) -> Result<(), Refusal> {
        // A client that does not take its answer gets no further one.
        self.stream
            .write_all(bytes)
            .and_then(|_| self.stream.flush())
            .map_err(|_| Refusal::new(0, "the client did not take its answer"))
    }

    fn answer(&mut self, r: &Response, keep: bool, is_head: bool) -> Result<(), Refusal> {
        let mut out = format!("HTTP/1.1 {} {}\r\n", r.status, reason(r.status));
        for (name, value) in &r.headers {
            if [name, value].iter().any(|t| t.contains(['\r', '\n'])) {
                continue;
            }
            out.push_str(&format!("{name}: {value}\r\n"));
        }
        out.push_str(&format!("Content-Length: {}\r\n", r.body.len()));
        if !keep {
            out.push_str("Connection: close\r\n");
        }
        out.push_str("\r\n");
        let mut bytes = out.into_bytes();
        if !is_head {
            bytes.extend_from_slice(&r.body);
        }
        self.write(&bytes)
    }

    /// Answers a refusal (unless the client is gone), then closes gently (module docs).
    fn refuse(mut self, refusal: Refusal) {
        let Refusal(status, why) = refusal;
        if status != 0 {
            let r = Response {
                status,
                headers: vec![(
                    "Content-Type".into(),
                    "application/json; charset=utf-8".into(),
                )],
                body: serde_json::json!({ "error": why }).to_string().into_bytes(),
            };
            if self.answer(&r, false, false).is_err() {
                return;
            }
        }
        let _ = self.stream.shutdown(Shutdown::Write);
        // Read what is still coming (up to a second or 1 MiB), so that closing with unread
        // bytes does not reset the connection before the client has read the refusal.
        let until = Instant::now() + Duration::from_secs(1);
        let mut drained = 0usize;
        let mut chunk = [0u8; 8192];
        while drained < 1 << 20 {
            let left = until.saturating_duration_since(Instant::now());
            if left.is_zero() || self.stream.set_read_timeout(Some(left)).is_err() {
                break;
            }
            match self.stream.read(&mut chunk) {
                Ok(0) | Err(_) => break,
                Ok(n) => drained += n,
            }
        }
    }
}

/// The parsed head as owned text (header values that are not UTF-8 are refused).
fn own(req: &httparse::Request) -> Result<Head, Refusal> {
    let (Some(method), Some(target), Some(minor)) = (req.method, req.path, req.version) else {
        return Err(Refusal::new(400, "incomplete request line"));
    };
    let mut headers = Vec::with_capacity(req.headers.len());
    for h in req.headers.iter() {
        let value = std::str::from_utf8(h.value)
            .map_err(|_| Refusal::new(400, format!("header {} is not UTF-8 text", h.name)))?;
        headers.push((h.name.to_string(), value.trim().to_string()));
    }
    Ok(Head {
        method: method.to_string(),
        target: target.to_string(),
        headers,
        minor,
    })
}

/// How the body of `head` is framed (RFC 9112 §6.3).
fn framing(head: &Head) -> Result<Framing, Refusal> {
    let codings: Vec<&str> = head.values("Transfer-Encoding").collect();
    let lengths: Vec<&str> = head.values("Content-Length").collect();
    if !codings.is_empty() {
        if !lengths.is_empty() {
            return Err(Refusal::new(
                400,
                "both Content-Length and Transfer-Encoding",
            ));
        }
        let all: Vec<String> = codings
            .iter()
            .flat_map(|v| v.split(','))
            .map(|t| t.trim().to_ascii_lowercase())
            .collect();
        return if all == ["chunked"] {
            Ok(Framing::Chunked)
        } else {
            Err(Refusal::new(
                501,
                format!("transfer coding {:?} (only chunked)", all.join(", ")),
            ))
        };
    }
    let mut length = None;
    for v in lengths.iter().flat_map(|v| v.split(',')) {
        let v = v.trim();
        let n = v
            .parse::<usize>()
            .ok()
            .filter(|_| v.bytes().all(|b| b.is_ascii_digit()))
            .ok_or_else(|| Refusal::new(400, format!("bad Content-Length {v:?}")))?;
        if length.is_some_and(|m| m != n) {
            return Err(Refusal::new(400, "Content-Length given twice, differently"));
        }
        length = Some(n);
    }
    Ok(Framing::Length(length.unwrap_or(0)))
}

/// The reason phrase of a status code.
fn reason(status: u16) -> &'static str {
    match status {
        200 => "OK",
        400 => "Bad Request",
        403 => "Forbidden",
        404 => "Not Found",
        405 => "Method Not Allowed",
        408 => "Request Timeout",
        409 => "Conflict",
        413 => "Content Too Large",
        417 => "Expectation Failed",
        431 => "Request Header Fields Too Large",
        500 => "Internal Server Error",
        501 => "Not Implemented",
        505 => "HTTP Version Not Supported",
        _ => "",
    }
}

#[cfg(test)]
mod tests;
