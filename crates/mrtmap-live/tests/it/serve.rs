//! The live page's server facing a network: clients on 127.0.0.1 that send other methods, other
//! paths, huge or malformed requests, that stall, that stop reading, or that come too many; and a
//! deterministic fuzz of request heads. Each loop is bounded in count and time.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{Shutdown, TcpStream};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use mrtmap_live::{Limits, Server};
use mrtmap_pipeline::{LivePhase, LiveSink, LiveState};

fn state(n: usize) -> LiveState {
    LiveState {
        phase: LivePhase::Following,
        frames_received: n,
        verdict: "keep scanning".into(),
        ..LiveState::default()
    }
}

fn connect(server: &Server) -> TcpStream {
    let c = TcpStream::connect(server.addr()).unwrap();
    c.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    c.set_write_timeout(Some(Duration::from_secs(5))).unwrap();
    c
}

/// Everything the server sends until it closes (at most 8 MB, 5 s without a byte), and whether
/// the connection ended in an error (a reset) rather than a close.
fn read_all(c: &mut TcpStream) -> (Vec<u8>, bool) {
    let mut got = Vec::new();
    let mut chunk = [0u8; 16 * 1024];
    while got.len() < 8 << 20 {
        match c.read(&mut chunk) {
            Ok(0) => return (got, false),
            Ok(n) => got.extend_from_slice(&chunk[..n]),
            Err(_) => return (got, true),
        }
    }
    (got, false)
}

/// An answer: the status, the head's lines, the body.
struct Answer {
    status: u16,
    head: String,
    body: Vec<u8>,
}

impl Answer {
    fn header(&self, name: &str) -> Option<&str> {
        self.head.lines().skip(1).find_map(|l| {
            let (n, v) = l.split_once(':')?;
            n.eq_ignore_ascii_case(name).then(|| v.trim())
        })
    }
}

fn parse_answer(bytes: &[u8]) -> Option<Answer> {
    let end = bytes.windows(4).position(|w| w == b"\r\n\r\n")?;
    let head = String::from_utf8(bytes[..end].to_vec()).ok()?;
    let status = head.strip_prefix("HTTP/1.1 ")?.get(..3)?.parse().ok()?;
    Some(Answer {
        status,
        head,
        body: bytes[end + 4..].to_vec(),
    })
}

/// Sends `request` on a new connection and reads the answer until the server closes.
fn exchange(server: &Server, request: &[u8]) -> Answer {
    let mut c = connect(server);
    c.write_all(request).unwrap();
    let (bytes, _) = read_all(&mut c);
    parse_answer(&bytes)
        .unwrap_or_else(|| panic!("not an answer: {:?}", String::from_utf8_lossy(&bytes)))
}

fn get(server: &Server, path: &str) -> Answer {
    exchange(
        server,
        format!("GET {path} HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n").as_bytes(),
    )
}

/// The state's frames_received, as served.
fn served_frames(server: &Server) -> u64 {
    let a = get(server, "/state.json");
    assert_eq!(a.status, 200);
    let v: serde_json::Value = serde_json::from_slice(&a.body).unwrap();
    v["frames_received"].as_u64().unwrap()
}

/// Waits (at most `limit`) for the server to hold `n` connections.
fn wait_for_connections(server: &Server, n: usize, limit: Duration) -> bool {
    let start = Instant::now();
    while start.elapsed() < limit {
        if server.connections() == n {
            return true;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    false
}

#[test]
fn other_methods_are_refused_and_nothing_changes() {
    let server = Server::start("127.0.0.1:0").unwrap();
    server.state(&state(7));
    let before = get(&server, "/state.json").body;
    for method in ["POST", "PUT", "DELETE", "PATCH", "OPTIONS"] {
        for path in ["/state.json", "/", "/events", "/nope"] {
            let a = exchange(
                &server,
                format!(
                    "{method} {path} HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\nContent-Length: 17\r\n\r\n{{\"phase\":\"done\"}}"
                )
                .as_bytes(),
            );
            assert_eq!(a.status, 405, "{method} {path}: {}", a.head);
            assert_eq!(a.header("Allow"), Some("GET, HEAD"), "{}", a.head);
            assert_eq!(a.header("Connection"), Some("close"), "{}", a.head);
        }
    }
    assert_eq!(get(&server, "/state.json").body, before);
    assert_eq!(served_frames(&server), 7);
    assert!(wait_for_connections(&server, 0, Duration::from_secs(5)));
}

#[test]
fn other_paths_are_not_found() {
    let server = Server::start("127.0.0.1:0").unwrap();
    for path in [
        "/nope",
        "/state.json.bak",
        "/events/1",
        "/../../etc/passwd",
        "/%2e%2e/state.json",
        "/index.htm",
    ] {
        let a = get(&server, path);
        assert_eq!(a.status, 404, "{path}");
        assert!(!a.body.is_empty());
    }
    for path in ["/", "/index.html", "/state.json?x=1", "/view.html"] {
        assert_eq!(get(&server, path).status, 200, "{path}");
    }
    // The absolute form names the same paths.
    let a = exchange(
        &server,
        b"GET http://127.0.0.1/state.json HTTP/1.1\r\nConnection: close\r\n\r\n",
    );
    assert_eq!(a.status, 200);
}

#[test]
fn head_answers_the_head_alone() {
    let server = Server::start("127.0.0.1:0").unwrap();
    server.state(&state(3));
    server.view("<html>the view</html>".into());
    for path in ["/", "/state.json", "/view.html", "/nope"] {
        let full = get(&server, path);
        let head = exchange(
            &server,
            format!("HEAD {path} HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n").as_bytes(),
        );
        assert_eq!(head.status, full.status, "{path}");
        assert!(head.body.is_empty(), "{path}: {} bytes", head.body.len());
        assert_eq!(
            head.header("Content-Length"),
            Some(full.body.len().to_string().as_str()),
            "{path}"
        );
        assert_eq!(head.header("Content-Type"), full.header("Content-Type"));
    }
    let a = exchange(&server, b"HEAD /events HTTP/1.1\r\nHost: x\r\n\r\n");
    assert_eq!(a.status, 200);
    assert_eq!(a.header("Content-Type"), Some("text/event-stream"));
    assert!(a.body.is_empty());
}

#[test]
fn one_connection_answers_requests_in_turn_and_http_1_0_closes() {
    let server = Server::start("127.0.0.1:0").unwrap();
    server.state(&state(5));
    let mut c = connect(&server);
    // Two requests sent at once (pipelined), then a third after the answers.
    c.write_all(b"GET /state.json HTTP/1.1\r\nHost: x\r\n\r\nHEAD / HTTP/1.1\r\nHost: x\r\n\r\n")
        .unwrap();
    let mut r = BufReader::new(c.try_clone().unwrap());
    for expect_body in [true, false] {
        let mut line = String::new();
        r.read_line(&mut line).unwrap();
        assert!(line.starts_with("HTTP/1.1 200"), "{line}");
        let mut length = 0;
        loop {
            let mut h = String::new();
            r.read_line(&mut h).unwrap();
            if h == "\r\n" {
                break;
            }
            if let Some(v) = h.strip_prefix("Content-Length: ") {
                length = v.trim().parse().unwrap();
            }
            assert_ne!(h.trim(), "Connection: close");
        }
        if expect_body {
            let mut body = vec![0; length];
            r.read_exact(&mut body).unwrap();
            assert!(
                String::from_utf8(body)
                    .unwrap()
                    .contains("\"frames_received\":5")
            );
        }
    }
    c.write_all(b"GET /nope HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n")
        .unwrap();
    let mut rest = Vec::new();
    r.read_to_end(&mut rest).unwrap();
    assert!(rest.starts_with(b"HTTP/1.1 404"));
    // HTTP/1.0: the answer, then the connection closed.
    let mut c = connect(&server);
    c.write_all(b"GET /state.json HTTP/1.0\r\n\r\n").unwrap();
    let (bytes, reset) = read_all(&mut c);
    assert!(!reset && parse_answer(&bytes).unwrap().status == 200);
}

#[test]
fn a_request_sent_a_byte_at_a_time_is_answered() {
    let server = Server::start("127.0.0.1:0").unwrap();
    server.state(&state(9));
    for request in [
        &b"\r\nGET /state.json HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n"[..],
        b"GET /state.json HTTP/1.0\n\n",
    ] {
        let mut c = connect(&server);
        c.set_nodelay(true).unwrap();
        for b in request {
            c.write_all(&[*b]).unwrap();
            std::thread::sleep(Duration::from_millis(2));
        }
        let (bytes, _) = read_all(&mut c);
        let a = parse_answer(&bytes).unwrap();
        assert_eq!(a.status, 200);
        assert!(
            String::from_utf8(a.body)
                .unwrap()
                .contains("\"frames_received\":9")
        );
    }
}

#[test]
fn huge_and_garbage_requests_are_refused_and_the_server_goes_on() {
    let server = Server::start("127.0.0.1:0").unwrap();
    server.state(&state(11));
    let big = "a".repeat(100_000);
    let mut garbage = vec![0u8; 64 * 1024];
    let mut x = 0x9E37_79B9_7F4A_7C15u64;
    for b in &mut garbage {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        *b = (x >> 32) as u8;
    }
    for (what, request, status) in [
        (
            "a 100 kB header line",
            format!("GET / HTTP/1.1\r\nHost: x\r\nX-Big: {big}\r\n\r\n").into_bytes(),
            &[431][..],
        ),
        (
            "a 100 kB request line",
            format!("GET /{big} HTTP/1.1\r\nHost: x\r\n\r\n").into_bytes(),
            &[414],
        ),
        // 431 when no empty line comes within the head's limit.
        ("64 kB of binary garbage", garbage.clone(), &[400, 431]),
        (
            "binary garbage after a request line",
            [&b"GET / HTTP/1.1\r\n"[..], &garbage[..4000], b"\r\n\r\n"].concat(),
            &[400],
        ),
        (
            "a NUL in the path",
            b"GET /st\0te.json HTTP/1.1\r\n\r\n".to_vec(),
            &[400],
        ),
        ("HTTP/2", b"GET / HTTP/2.0\r\n\r\n".to_vec(), &[505]),
        (
            "a request line alone, then the end",
            b"GET / HTTP/1.1\r\nHost: x".to_vec(),
            &[400],
        ),
    ] {
        let mut c = connect(&server);
        // The server may stop reading (and close) before all of it is sent.
        let _ = c.write_all(&request);
        let _ = c.shutdown(Shutdown::Write);
        let (bytes, reset) = read_all(&mut c);
        match parse_answer(&bytes) {
            Some(a) => assert!(status.contains(&a.status), "{what}: {}", a.head),
            None => assert!(
                reset && bytes.is_empty(),
                "{what}: neither an answer nor a reset: {:?}",
                String::from_utf8_lossy(&bytes)
            ),
        }
        assert_eq!(served_frames(&server), 11, "after {what}");
    }
    assert!(wait_for_connections(&server, 0, Duration::from_secs(5)));
}

#[test]
fn a_half_request_or_silence_is_timed_out() {
    let limits = Limits {
        request_timeout: Duration::from_millis(500),
        ..Limits::default()
    };
    let server = Server::start_with("127.0.0.1:0", limits).unwrap();
    let started = Instant::now();
    let mut half = connect(&server);
    half.write_all(b"GET /state.json HTTP/1.1\r\nHost: x\r\n")
        .unwrap();
    let mut silent = connect(&server);
    let (bytes, _) = read_all(&mut half);
    let a = parse_answer(&bytes).unwrap();
    assert_eq!(a.status, 408);
    // Silence is closed without a word.
    let (bytes, _) = read_all(&mut silent);
    assert!(bytes.is_empty());
    assert!(
        started.elapsed() < Duration::from_secs(4),
        "{:?}",
        started.elapsed()
    );
    // A request dribbled a byte at a time does not extend the time limit.
    let mut slow = connect(&server);
    slow.set_read_timeout(Some(Duration::from_millis(20)))
        .unwrap();
    let started = Instant::now();
    let mut got = Vec::new();
    for b in b"GET /state.json HTTP/1.1\r\nHost: x\r\nX-Slow: "
        .iter()
        .cycle()
        .take(300)
    {
        if slow.write_all(&[*b]).is_err() {
            break;
        }
        let mut chunk = [0u8; 1024];
        match slow.read(&mut chunk) {
            Ok(0) => break,
            Ok(n) => {
                got.extend_from_slice(&chunk[..n]);
                break;
            }
            Err(_) => {}
        }
    }
    assert!(
        got.starts_with(b"HTTP/1.1 408"),
        "{:?}",
        String::from_utf8_lossy(&got)
    );
    assert!(
        started.elapsed() < Duration::from_secs(3),
        "{:?}",
        started.elapsed()
    );
    assert!(wait_for_connections(&server, 0, Duration::from_secs(3)));
}

/// Reads an event stream, keeping the newest state's frames_received and the count of states.
fn follow(mut c: TcpStream, newest: &AtomicUsize, count: &AtomicUsize, stop: &AtomicBool) {
    c.write_all(b"GET /events HTTP/1.1\r\nHost: x\r\n\r\n")
        .unwrap();
    let mut lines = BufReader::new(c);
    let mut line = String::new();
    let started = Instant::now();
    while !stop.load(Ordering::SeqCst) && started.elapsed() < Duration::from_secs(15) {
        line.clear();
        match lines.read_line(&mut line) {
            Ok(0) | Err(_) => return,
            Ok(_) => {}
        }
        if let Some(d) = line.strip_prefix("data: ") {
            let v: serde_json::Value = serde_json::from_str(d).unwrap();
            newest.store(
                v["frames_received"].as_u64().unwrap() as usize,
                Ordering::SeqCst,
            );
            count.fetch_add(1, Ordering::SeqCst);
        }
    }
}

#[test]
fn a_client_that_stops_reading_holds_no_one_up_and_is_dropped() {
    let limits = Limits {
        write_timeout: Duration::from_secs(1),
        ..Limits::default()
    };
    let server = Server::start_with("127.0.0.1:0", limits).unwrap();
    // About 100 kB a state: the stalled client's socket buffers fill within a second.
    let big = |n| LiveState {
        warnings: vec!["w".repeat(1000); 100],
        ..state(n)
    };
    server.state(&big(0));
    let mut stalled = connect(&server);
    stalled
        .write_all(b"GET /events HTTP/1.1\r\nHost: x\r\n\r\n")
        .unwrap();
    let (newest, count, stop) = (
        Arc::new(AtomicUsize::new(0)),
        Arc::new(AtomicUsize::new(0)),
        Arc::new(AtomicBool::new(false)),
    );
    let reader = {
        let (c, n, k, s) = (
            connect(&server),
            newest.clone(),
            count.clone(),
            stop.clone(),
        );
        std::thread::spawn(move || follow(c, &n, &k, &s))
    };
    assert!(wait_for_connections(&server, 2, Duration::from_secs(3)));
    let started = Instant::now();
    let (mut n, mut slowest, mut dropped_after) = (0, Duration::ZERO, None);
    while started.elapsed() < Duration::from_secs(6) {
        n += 1;
        let t = Instant::now();
        server.state(&big(n));
        slowest = slowest.max(t.elapsed());
        if n % 50 == 0 {
            // Polled meanwhile: the state now.
            assert_eq!(served_frames(&server), n as u64);
        }
        if server.connections() == 1 {
            dropped_after = Some(started.elapsed());
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    let dropped_after = dropped_after.unwrap_or_else(|| {
        panic!(
            "the stalled client was not dropped: {} connections after {n} states",
            server.connections()
        )
    });
    eprintln!(
        "stalled client dropped after {dropped_after:?} and {n} states; state() took {slowest:?} at most"
    );
    // The reader got states all along, and the newest.
    let waited = Instant::now();
    while newest.load(Ordering::SeqCst) != n && waited.elapsed() < Duration::from_secs(2) {
        std::thread::sleep(Duration::from_millis(10));
    }
    assert_eq!(newest.load(Ordering::SeqCst), n);
    assert!(
        count.load(Ordering::SeqCst) >= 10,
        "{}",
        count.load(Ordering::SeqCst)
    );
    // state() never waited for a client (it serializes 100 kB, in a debug build).
    assert!(
        slowest < Duration::from_millis(250),
        "state() took {slowest:?}"
    );
    assert!(dropped_after < Duration::from_secs(6));
    stop.store(true, Ordering::SeqCst);
    server.state(&big(n + 1));
    reader.join().unwrap();
    // The stalled client got states until its buffers filled, then the server closed it.
    let (b, reset) = read_all(&mut stalled);
    assert!(
        b.len() > 200_000 && !reset,
        "{} bytes, reset {reset}",
        b.len()
    );
}

#[test]
fn connections_beyond_the_limit_are_answered_503() {
    let server = Server::start("127.0.0.1:0").unwrap();
    server.state(&state(2));
    let cap = Limits::default().max_connections;
    let held: Vec<TcpStream> = (0..cap).map(|_| connect(&server)).collect();
    assert!(
        wait_for_connections(&server, cap, Duration::from_secs(5)),
        "{} of {cap}",
        server.connections()
    );
    let started = Instant::now();
    for _ in 0..3 {
        let a = get(&server, "/state.json");
        assert_eq!(a.status, 503, "{}", a.head);
        assert!(a.header("Retry-After").is_some());
    }
    assert!(started.elapsed() < Duration::from_secs(2));
    assert_eq!(server.connections(), cap);
    drop(held);
    assert!(wait_for_connections(&server, 0, Duration::from_secs(5)));
    assert_eq!(served_frames(&server), 2);
}

/// xorshift64: a deterministic stream of numbers.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }

    /// One of `from`: half the time one of its first `usual`.
    fn pick<'a>(&mut self, from: &[&'a str], usual: usize) -> &'a str {
        let n = if self.below(2) == 0 {
            usual
        } else {
            from.len()
        };
        from[self.below(n)]
    }

    fn bytes(&mut self, n: usize) -> Vec<u8> {
        (0..n).map(|_| self.next() as u8).collect()
    }
}

/// A random request head: mostly near-valid, with one part broken at random.
fn random_request(r: &mut Rng) -> Vec<u8> {
    let methods = [
        "GET", "HEAD", "POST", "PUT", "DELETE", "get", "G ET", "", "GET\0", "\u{e9}",
    ];
    let paths = [
        "/",
        "/state.json",
        "/view.html",
        "/index.html",
        "/nope",
        "*",
        "",
        "/a b",
        "/%00",
        "http://x/state.json",
        "//",
        "/state.json?x=1#y",
    ];
    let versions = [
        "HTTP/1.1",
        "HTTP/1.0",
        "HTTP/2.0",
        "HTTP/1",
        "http/1.1",
        "",
        "HTTP/1.1 x",
    ];
    let headers = [
        "Host: x",
        "Connection: close",
        "Connection: keep-alive",
        "Content-Length: 0",
        "Content-Length: 5",
        "Content-Length: -3",
        "Transfer-Encoding: chunked",
        "X: \u{7f}",
        " folded",
        "no colon",
        ": empty name",
        "Expect: 100-continue",
    ];
    let mut out = Vec::new();
    match r.below(10) {
        // Garbage alone.
        0 => {
            let n = r.below(3000);
            out = r.bytes(n);
        }
        // A long line.
        1 => {
            out.extend_from_slice(b"GET /");
            out.extend(std::iter::repeat_n(b'a', r.below(40_000)));
            out.extend_from_slice(b" HTTP/1.1\r\n\r\n");
        }
        _ => {
            out.extend_from_slice(
                format!(
                    "{} {} {}\r\n",
                    r.pick(&methods, 2),
                    r.pick(&paths, 5),
                    r.pick(&versions, 2)
                )
                .as_bytes(),
            );
            for _ in 0..r.below(6) {
                out.extend_from_slice(r.pick(&headers, 5).as_bytes());
                out.extend_from_slice(if r.below(4) == 0 { b"\n" } else { b"\r\n" });
            }
            if r.below(5) == 0 {
                let at = r.below(out.len() + 1);
                let n = 1 + r.below(20);
                let junk = r.bytes(n);
                out.splice(at..at, junk);
            }
            if r.below(8) != 0 {
                out.extend_from_slice(b"\r\n");
            }
            if r.below(4) == 0 {
                // A body, or a second request.
                out.extend_from_slice(b"hello\r\nGET /state.json HTTP/1.1\r\n\r\n");
            }
        }
    }
    out
}

#[test]
fn two_thousand_random_requests_leave_the_server_answering() {
    let server = Server::start("127.0.0.1:0").unwrap();
    server.state(&state(42));
    let mut r = Rng(0x2545_F491_4F6C_DD1D);
    let started = Instant::now();
    let (mut answered, mut sent) = (0, 0);
    let mut statuses = std::collections::BTreeMap::new();
    for i in 0..2000 {
        if started.elapsed() > Duration::from_secs(8) {
            break;
        }
        let request = random_request(&mut r);
        let mut c = connect(&server);
        let _ = c.write_all(&request);
        let _ = c.shutdown(Shutdown::Write);
        let (bytes, reset) = read_all(&mut c);
        sent += 1;
        if bytes.is_empty() {
            // Closed without a word: only for nothing but empty lines, or a reset while a long
            // line was still being sent.
            assert!(
                reset || request.iter().all(|b| *b == b'\r' || *b == b'\n'),
                "request {i} went unanswered: {:?}",
                String::from_utf8_lossy(&request)
            );
            continue;
        }
        let a = parse_answer(&bytes).unwrap_or_else(|| {
            panic!(
                "request {i}: not an answer: {:?}",
                String::from_utf8_lossy(&bytes[..bytes.len().min(200)])
            )
        });
        assert!(
            [200, 400, 404, 405, 408, 414, 431, 505].contains(&a.status),
            "request {i}: {}",
            a.head
        );
        *statuses.entry(a.status).or_insert(0) += 1;
        answered += 1;
    }
    eprintln!(
        "{answered} of {sent} random requests answered in {:?}: {statuses:?}",
        started.elapsed()
    );
    // Every kind of answer came up.
    for status in [200, 400, 404, 405, 414, 505] {
        assert!(statuses.contains_key(&status), "no {status}: {statuses:?}");
    }
    assert!(sent >= 500, "only {sent} requests in 8 s");
    assert!(answered * 10 >= sent * 9, "{answered} of {sent} answered");
    assert_eq!(served_frames(&server), 42);
    assert!(wait_for_connections(&server, 0, Duration::from_secs(5)));
}
