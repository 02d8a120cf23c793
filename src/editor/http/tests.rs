//! Unit tests of the HTTP/1.1 layer over real sockets: one connection each.
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
    let a = exchange(b"GET /x HTTP/1.0\r\nConnection: keep-alive\r\n\r\nGET /y HTTP/1.0\r\n\r\n");
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
