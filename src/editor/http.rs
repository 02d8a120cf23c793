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
//! Refusals close the connection (what follows cannot be framed): a head over [`MAX_HEAD`]
//! bytes or [`MAX_HEADERS`] lines (431), a body over the server's limit (413), a head that is not
//! HTTP/1 (400), a version other than 1.0 or 1.1 — `GET / HTTP/2.0` or HTTP/2's connection
//! preface (505), a transfer coding other than chunked (501), both `Content-Length` and
//! `Transfer-Encoding` (400: RFC 9112 §6.1 asks a server to treat it as an error), an
//! `Expect` other than `100-continue` (417), a request that took too long (408). After a
//! refusal the server stops sending, reads what the client still sends for a short while and
//! then closes, so that the client reads the refusal rather than a reset.

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
        self.headers
            .iter()
            .filter(|(n, _)| n.eq_ignore_ascii_case(name))
            .map(|(_, v)| v.as_str())
            .collect()
    }
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
        self.headers
            .iter()
            .filter(move |(n, _)| n.eq_ignore_ascii_case(name))
            .map(|(_, v)| v.as_str())
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
            return Err(too_large(max_body));
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
                return Err(too_large(max_body));
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

fn too_large(max_body: usize) -> Refusal {
    Refusal::new(413, format!("request body over {max_body} bytes"))
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
        204 => "No Content",
        400 => "Bad Request",
        403 => "Forbidden",
        404 => "Not Found",
        405 => "Method Not Allowed",
        408 => "Request Timeout",
        409 => "Conflict",
        413 => "Content Too Large",
        417 => "Expectation Failed",
        422 => "Unprocessable Content",
        431 => "Request Header Fields Too Large",
        500 => "Internal Server Error",
        501 => "Not Implemented",
        503 => "Service Unavailable",
        505 => "HTTP Version Not Supported",
        _ => "",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::net::TcpListener;

    /// Serves one connection with an echoing handler; returns what a client sending `bytes`
    /// (then closing its side) reads back.
    fn exchange(bytes: &[u8]) -> String {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = listener.local_addr().unwrap();
        let server = std::thread::spawn(move || {
            let (s, _) = listener.accept().unwrap();
            let stop = AtomicBool::new(false);
            let echo = |r: Request| Response {
                status: 200,
                headers: vec![("X-Method".into(), r.method.clone())],
                body: [r.target.as_bytes(), b" ", &r.body].concat(),
            };
            serve_connection(s, 64, &stop, &echo, &|| {}, &|| {});
        });
        let mut c = TcpStream::connect(addr).unwrap();
        c.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
        let _ = c.write_all(bytes);
        let _ = c.shutdown(Shutdown::Write);
        let mut out = Vec::new();
        let _ = c.read_to_end(&mut out);
        server.join().unwrap();
        String::from_utf8_lossy(&out).into_owned()
    }

    fn statuses(answer: &str) -> Vec<u16> {
        answer
            .split("HTTP/1.1 ")
            .skip(1)
            .filter_map(|a| a.get(..3)?.parse().ok())
            .collect()
    }

    #[test]
    fn http2_and_unknown_versions_get_505_at_once() {
        for req in [
            &b"GET / HTTP/2.0\r\nHost: 127.0.0.1\r\n\r\n"[..],
            b"PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n",
            b"GET / HTTP/1.2\r\n\r\n",
        ] {
            let a = exchange(req);
            assert_eq!(statuses(&a), [505], "{a}");
            assert!(a.contains("HTTP/1.1 (and 1.0) only"), "{a}");
        }
    }

    #[test]
    fn pipelined_requests_are_answered_in_order_with_their_bodies() {
        let a = exchange(
            b"POST /a HTTP/1.1\r\nContent-Length: 3\r\n\r\nxyzGET /b?q=1 HTTP/1.1\r\n\r\n\
              POST /c HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\n2;x=y\r\nab\r\n1\r\nc\r\n0\r\nT: 1\r\n\r\n\
              HEAD /d HTTP/1.1\r\nConnection: close\r\n\r\nGET /never HTTP/1.1\r\n\r\n",
        );
        assert_eq!(statuses(&a), [200, 200, 200, 200], "{a}");
        assert!(a.contains("Content-Length: 6\r\n\r\n/a xyz"), "{a}");
        assert!(a.contains("\r\n\r\n/b?q=1 "), "{a}");
        assert!(a.contains("\r\n\r\n/c abc"), "{a}");
        // HEAD: the length of the body, no body, and the connection closes as asked.
        assert!(a.ends_with("X-Method: HEAD\r\nContent-Length: 3\r\nConnection: close\r\n\r\n"));
        assert!(!a.contains("/never"));
    }

    #[test]
    fn http10_closes_unless_kept_alive() {
        let a = exchange(b"GET /x HTTP/1.0\r\n\r\nGET /y HTTP/1.0\r\n\r\n");
        assert_eq!(statuses(&a), [200], "{a}");
        let a =
            exchange(b"GET /x HTTP/1.0\r\nConnection: keep-alive\r\n\r\nGET /y HTTP/1.0\r\n\r\n");
        assert_eq!(statuses(&a), [200, 200], "{a}");
    }

    #[test]
    fn refusals_name_their_reason_and_close() {
        let cases: [(&[u8], u16, &str); 10] = [
            (
                b"POST / HTTP/1.1\r\nContent-Length: 65\r\n\r\n",
                413,
                "over 64 bytes",
            ),
            (
                b"POST / HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\n41\r\n",
                413,
                "over 64",
            ),
            (
                b"POST / HTTP/1.1\r\nContent-Length: 5\r\n\r\nab",
                400,
                "cut off",
            ),
            (
                b"POST / HTTP/1.1\r\nContent-Length: -1\r\n\r\n",
                400,
                "Content-Length",
            ),
            (
                b"POST / HTTP/1.1\r\nContent-Length: 1\r\nContent-Length: 2\r\n\r\nab",
                400,
                "twice",
            ),
            (
                b"POST / HTTP/1.1\r\nTransfer-Encoding: gzip\r\n\r\n",
                501,
                "only chunked",
            ),
            (
                b"POST / HTTP/1.1\r\nTransfer-Encoding: chunked\r\nContent-Length: 2\r\n\r\n",
                400,
                "both",
            ),
            (b"GET / HTTP/1.1\r\nExpect: magic\r\n\r\n", 417, "magic"),
            (b"\x16\x03\x01\x02\x00\x01\x00", 400, "not an HTTP request"),
            (b"GET / HTTP/1.1\r\nX-Cut: ", 400, "cut off"),
        ];
        for (req, status, why) in cases {
            let a = exchange(req);
            assert_eq!(statuses(&a), [status], "{a}");
            assert!(a.contains(why), "{why}: {a}");
            assert!(a.contains("Connection: close"), "{a}");
        }
        let mut long = b"GET / HTTP/1.1\r\n".to_vec();
        for i in 0..MAX_HEADERS + 1 {
            long.extend(format!("X-{i}: 1\r\n").as_bytes());
        }
        assert_eq!(statuses(&exchange(&long)), [431]);
        let mut huge = b"GET / HTTP/1.1\r\nX: ".to_vec();
        huge.extend(vec![b'a'; MAX_HEAD + 1]);
        assert_eq!(statuses(&exchange(&huge)), [431]);
    }

    #[test]
    fn expect_100_continue_is_answered_before_the_body() {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = listener.local_addr().unwrap();
        let server = std::thread::spawn(move || {
            let (s, _) = listener.accept().unwrap();
            let stop = AtomicBool::new(false);
            let ok = |r: Request| Response {
                status: 200,
                headers: vec![],
                body: r.body,
            };
            serve_connection(s, 64, &stop, &ok, &|| {}, &|| {});
        });
        let mut c = TcpStream::connect(addr).unwrap();
        c.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
        c.write_all(b"POST / HTTP/1.1\r\nExpect: 100-continue\r\nContent-Length: 2\r\n\r\n")
            .unwrap();
        let mut first = [0u8; 25];
        c.read_exact(&mut first).unwrap();
        assert_eq!(&first, b"HTTP/1.1 100 Continue\r\n\r\n");
        c.write_all(b"hi").unwrap();
        c.shutdown(Shutdown::Write).unwrap();
        let mut rest = String::new();
        c.read_to_string(&mut rest).unwrap();
        assert!(rest.starts_with("HTTP/1.1 200 OK\r\n") && rest.ends_with("\r\n\r\nhi"));
        server.join().unwrap();
    }

    #[test]
    fn a_waiting_connection_closes_when_the_server_stops() {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = listener.local_addr().unwrap();
        let stop = std::sync::Arc::new(AtomicBool::new(false));
        let s2 = stop.clone();
        let server = std::thread::spawn(move || {
            let (s, _) = listener.accept().unwrap();
            let ok = |_: Request| Response {
                status: 200,
                headers: vec![],
                body: vec![],
            };
            let t = Instant::now();
            serve_connection(s, 64, &s2, &ok, &|| {}, &|| {});
            t.elapsed()
        });
        let mut c = TcpStream::connect(addr).unwrap();
        c.write_all(b"GET / HTTP/1.1\r\n\r\n").unwrap();
        std::thread::sleep(Duration::from_millis(300));
        stop.store(true, Ordering::Relaxed);
        // Kept alive and idle: it closes within a poll, not after `IDLE`.
        assert!(server.join().unwrap() < IDLE / 2);
        let mut out = String::new();
        c.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
        c.read_to_string(&mut out).unwrap();
        assert_eq!(statuses(&out), [200]);
    }
}
