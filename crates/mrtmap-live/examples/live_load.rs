//! The live page's server under load (`bench/run live-load`): the time from [`LiveSink::state`]
//! to a client holding the event, the time `state()` itself takes, and the process's resident
//! memory, first unloaded, then while another process runs 50 clients polling /state.json twice
//! a second (one kept-alive connection each), 10 clients reading /events, one that asks for
//! /events and never reads, and one that sends half a request and stalls (again after each
//! 408).
//!
//! `cargo run --release -p mrtmap-live --example live_load -- [SECONDS]` (20 per phase unless
//! given). The load runs in a child process (this program with `--load ADDR SECONDS`), so the
//! memory measured is the server's. States of about 11 kB (a 20 × 20 map's nodes) are pushed 10
//! times a second.
#![allow(clippy::unwrap_used, clippy::print_stdout, clippy::print_stderr)]

use std::collections::HashMap;
use std::io::{BufRead, BufReader, ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use mrtmap_live::Server;
use mrtmap_pipeline::{LivePhase, LiveSink, LiveState};

const POLLERS: usize = 50;
const STREAMS: usize = 10;
const PUSH_EVERY: Duration = Duration::from_millis(100);

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.get(1).map(String::as_str) == Some("--load") {
        let addr: SocketAddr = args[2].parse().unwrap();
        let secs: f64 = args[3].parse().unwrap();
        load(addr, Duration::from_secs_f64(secs));
        return;
    }
    let secs: f64 = args.get(1).map_or(20.0, |s| s.parse().unwrap());
    let phase = Duration::from_secs_f64(secs);
    let server = Server::start("127.0.0.1:0").unwrap();
    let probe = Probe::start(server.addr());
    let mut seq = 0;
    // A state before the phases, so that the probe's stream is open and has one.
    server.state(&state(seq));
    std::thread::sleep(Duration::from_millis(500));
    let size = serde_json::to_string(&state(0)).unwrap().len();
    println!(
        "live-load: a {:.0} kB state pushed every {} ms, {secs:.0} s unloaded then {secs:.0} s loaded ({POLLERS} clients polling /state.json twice a second, {STREAMS} reading /events, one stalled on /events, one stalled half-way through a request)",
        size as f64 / 1e3,
        PUSH_EVERY.as_millis()
    );
    let unloaded = run_phase(&server, &probe, &mut seq, phase);
    println!("  unloaded: {}", unloaded.line());

    let mut child = Command::new(std::env::current_exe().unwrap())
        .args([
            "--load",
            &server.addr().to_string(),
            &format!("{}", secs + 1.0),
        ])
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let want = 1 + POLLERS + STREAMS + 2;
    let t = Instant::now();
    while server.connections() < want && t.elapsed() < Duration::from_secs(10) {
        std::thread::sleep(Duration::from_millis(20));
    }
    let loaded = run_phase(&server, &probe, &mut seq, phase);
    println!("  loaded:   {}", loaded.line());
    let mut out = String::new();
    child
        .stdout
        .take()
        .unwrap()
        .read_to_string(&mut out)
        .unwrap();
    child.wait().unwrap();
    print!("{out}");
    println!(
        "  loaded / unloaded: latency median {:.2}x, p95 {:.2}x; state() median {:.2}x; RSS {:.2}x (max {:.2}x)",
        loaded.latency_ms(0.5) / unloaded.latency_ms(0.5),
        loaded.latency_ms(0.95) / unloaded.latency_ms(0.95),
        median(&loaded.calls_ms) / median(&unloaded.calls_ms),
        loaded.rss_end_mb / unloaded.rss_end_mb,
        loaded.rss_max_mb / unloaded.rss_max_mb,
    );
    drop(server);
}

/// A state of about 11 kB: a 20 × 20 map's nodes, the sequence number in frames_received.
fn state(seq: usize) -> LiveState {
    LiveState {
        phase: LivePhase::Following,
        frames_received: seq,
        frames_fused: seq,
        verdict: "keep scanning".into(),
        map_nodes: (0..400)
            .map(|i| {
                let (x, y) = ((i % 20) as f64 * 0.25, (i / 20) as f64 * 0.25);
                [x, y, 1.1, 21.0 + 0.013 * x - 0.021 * y]
            })
            .collect(),
        warnings: vec!["thermal.txt line 12: the file is not there after 2 s".into(); 5],
        ..LiveState::default()
    }
}

/// An event stream read in this process: the time each state arrived after it was pushed.
struct Probe {
    sent: Arc<Mutex<HashMap<usize, Instant>>>,
    latencies: Arc<Mutex<Vec<f64>>>,
}

impl Probe {
    fn start(addr: SocketAddr) -> Probe {
        let sent: Arc<Mutex<HashMap<usize, Instant>>> = Arc::new(Mutex::new(HashMap::new()));
        let latencies: Arc<Mutex<Vec<f64>>> = Arc::new(Mutex::new(Vec::new()));
        let (s, l) = (sent.clone(), latencies.clone());
        let mut c = TcpStream::connect(addr).unwrap();
        c.write_all(b"GET /events HTTP/1.1\r\nHost: x\r\n\r\n")
            .unwrap();
        std::thread::spawn(move || {
            let mut lines = BufReader::new(c);
            let mut line = String::new();
            while lines.read_line(&mut line).is_ok_and(|n| n > 0) {
                let now = Instant::now();
                if let Some(seq) = frames_received(&line)
                    && let Some(at) = s.lock().unwrap().remove(&seq)
                {
                    l.lock().unwrap().push((now - at).as_secs_f64() * 1e3);
                }
                line.clear();
            }
        });
        Probe { sent, latencies }
    }
}

fn frames_received(line: &str) -> Option<usize> {
    let rest = line.split("\"frames_received\":").nth(1)?;
    let end = rest.find(|c: char| !c.is_ascii_digit())?;
    rest[..end].parse().ok()
}

/// What a phase measured.
struct Phase {
    latencies_ms: Vec<f64>,
    pushed: usize,
    calls_ms: Vec<f64>,
    rss_end_mb: f64,
    rss_max_mb: f64,
    threads: usize,
    connections_max: usize,
}

fn median(v: &[f64]) -> f64 {
    quantile(v, 0.5)
}

fn quantile(v: &[f64], q: f64) -> f64 {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    v.get(((v.len() as f64 - 1.0) * q).round() as usize)
        .copied()
        .unwrap_or(f64::NAN)
}

impl Phase {
    fn latency_ms(&self, q: f64) -> f64 {
        quantile(&self.latencies_ms, q)
    }

    fn line(&self) -> String {
        format!(
            "state → event {:.3} ms median, {:.3} p95, {:.3} max ({} of {} states arrived); state() {:.3} ms median, {:.3} max; RSS {:.1} MB at the end, {:.1} max; {} threads, {} connections at most",
            self.latency_ms(0.5),
            self.latency_ms(0.95),
            self.latency_ms(1.0),
            self.latencies_ms.len(),
            self.pushed,
            median(&self.calls_ms),
            quantile(&self.calls_ms, 1.0),
            self.rss_end_mb,
            self.rss_max_mb,
            self.threads,
            self.connections_max,
        )
    }
}

/// A line of /proc/self/status as a number (kB for sizes).
fn status(key: &str) -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix(key))
                .and_then(|v| v.split_whitespace().next()?.parse().ok())
        })
        .unwrap_or(f64::NAN)
}

fn run_phase(server: &Server, probe: &Probe, seq: &mut usize, length: Duration) -> Phase {
    probe.latencies.lock().unwrap().clear();
    let (mut calls_ms, mut rss_max_mb, mut connections_max, mut pushed) =
        (Vec::new(), 0.0f64, 0, 0);
    let start = Instant::now();
    let mut next = start;
    while start.elapsed() < length {
        *seq += 1;
        let s = state(*seq);
        let t = Instant::now();
        probe.sent.lock().unwrap().insert(*seq, t);
        server.state(&s);
        calls_ms.push(t.elapsed().as_secs_f64() * 1e3);
        pushed += 1;
        rss_max_mb = rss_max_mb.max(status("VmRSS:") / 1e3);
        connections_max = connections_max.max(server.connections());
        next += PUSH_EVERY;
        std::thread::sleep(next.saturating_duration_since(Instant::now()));
    }
    // The last states' events.
    std::thread::sleep(Duration::from_millis(300));
    probe.sent.lock().unwrap().clear();
    Phase {
        latencies_ms: probe.latencies.lock().unwrap().clone(),
        pushed,
        calls_ms,
        rss_end_mb: status("VmRSS:") / 1e3,
        rss_max_mb,
        threads: status("Threads:") as usize,
        connections_max,
    }
}

/// The load: runs for `length`, then prints what the clients saw. One function on purpose: it
/// starts every kind of client, waits, and sums up what each saw, and a bench harness read top to
/// bottom is easier to check against the list of clients than one split into pieces.
fn load(addr: SocketAddr, length: Duration) {
    let stop = Arc::new(AtomicBool::new(false));
    let (polls, poll_errors, busy, events) = (
        Arc::new(AtomicUsize::new(0)),
        Arc::new(AtomicUsize::new(0)),
        Arc::new(AtomicUsize::new(0)),
        Arc::new(AtomicUsize::new(0)),
    );
    let poll_ms = Arc::new(Mutex::new(Vec::new()));
    let mut threads = Vec::new();
    // The stalled clients first: the event stream never read, the half request.
    let mut stalled = TcpStream::connect(addr).unwrap();
    stalled
        .write_all(b"GET /events HTTP/1.1\r\nHost: x\r\n\r\n")
        .unwrap();
    let timeouts = Arc::new(AtomicUsize::new(0));
    {
        let (stop, timeouts) = (stop.clone(), timeouts.clone());
        threads.push(std::thread::spawn(move || {
            while !stop.load(Ordering::SeqCst) {
                let Ok(mut c) = TcpStream::connect(addr) else {
                    std::thread::sleep(Duration::from_millis(100));
                    continue;
                };
                let _ = c.write_all(b"GET /state.json HTTP/1.1\r\nHost: x\r\n");
                let _ = c.set_read_timeout(Some(Duration::from_millis(200)));
                let mut got = Vec::new();
                let mut chunk = [0u8; 1024];
                while !stop.load(Ordering::SeqCst) {
                    match c.read(&mut chunk) {
                        Ok(0) => break,
                        Ok(n) => got.extend_from_slice(&chunk[..n]),
                        Err(e)
                            if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {}
                        Err(_) => break,
                    }
                }
                if got.starts_with(b"HTTP/1.1 408") {
                    timeouts.fetch_add(1, Ordering::SeqCst);
                }
            }
        }));
    }
    for _ in 0..STREAMS {
        let (stop, events) = (stop.clone(), events.clone());
        threads.push(std::thread::spawn(move || {
            let mut c = TcpStream::connect(addr).unwrap();
            c.set_read_timeout(Some(Duration::from_millis(500)))
                .unwrap();
            c.write_all(b"GET /events HTTP/1.1\r\nHost: x\r\n\r\n")
                .unwrap();
            let mut lines = BufReader::new(c);
            let mut line = String::new();
            while !stop.load(Ordering::SeqCst) {
                match lines.read_line(&mut line) {
                    Ok(0) => break,
                    Ok(_) => {
                        if line.starts_with("data: ") {
                            events.fetch_add(1, Ordering::SeqCst);
                        }
                        line.clear();
                    }
                    // A timeout keeps what was read of the line.
                    Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {}
                    Err(_) => break,
                }
            }
        }));
    }
    for i in 0..POLLERS {
        let (stop, polls, poll_errors, busy, poll_ms) = (
            stop.clone(),
            polls.clone(),
            poll_errors.clone(),
            busy.clone(),
            poll_ms.clone(),
        );
        threads.push(std::thread::spawn(move || {
            // Spread over the half second.
            std::thread::sleep(Duration::from_millis(10 * i as u64));
            let mut conn: Option<BufReader<TcpStream>> = None;
            let mut next = Instant::now();
            while !stop.load(Ordering::SeqCst) {
                let t = Instant::now();
                match poll(&mut conn, addr) {
                    Ok(200) => {
                        polls.fetch_add(1, Ordering::SeqCst);
                        poll_ms
                            .lock()
                            .unwrap()
                            .push(t.elapsed().as_secs_f64() * 1e3);
                    }
                    Ok(503) => {
                        busy.fetch_add(1, Ordering::SeqCst);
                        conn = None;
                    }
                    _ => {
                        poll_errors.fetch_add(1, Ordering::SeqCst);
                        conn = None;
                    }
                }
                next += Duration::from_millis(500);
                std::thread::sleep(next.saturating_duration_since(Instant::now()));
            }
        }));
    }
    std::thread::sleep(length);
    stop.store(true, Ordering::SeqCst);
    for t in threads {
        let _ = t.join();
    }
    // Whether the server closed the stalled stream: what it holds, then the end or nothing more.
    stalled
        .set_read_timeout(Some(Duration::from_millis(500)))
        .unwrap();
    let (mut waiting, mut closed) = (0usize, false);
    let mut chunk = [0u8; 64 * 1024];
    loop {
        match stalled.read(&mut chunk) {
            Ok(0) => {
                closed = true;
                break;
            }
            Ok(n) => waiting += n,
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => break,
            Err(_) => {
                closed = true;
                break;
            }
        }
    }
    let ms = poll_ms.lock().unwrap().clone();
    println!(
        "  the load: {} polls of /state.json answered ({:.3} ms median, {:.3} p95, {:.3} max), {} failed, {} answered 503; {} events read by the {STREAMS} streams; the stalled stream {} ({:.1} MB had reached it); the half request answered 408 {} times",
        polls.load(Ordering::SeqCst),
        median(&ms),
        quantile(&ms, 0.95),
        quantile(&ms, 1.0),
        poll_errors.load(Ordering::SeqCst),
        busy.load(Ordering::SeqCst),
        events.load(Ordering::SeqCst),
        if closed {
            "was closed by the server"
        } else {
            "was still open: the socket's buffers still took every state (it is dropped once an event waits 10 s for room)"
        },
        waiting as f64 / 1e6,
        timeouts.load(Ordering::SeqCst),
    );
}

/// GET /state.json on a kept-alive connection (opened when there is none): the status.
fn poll(conn: &mut Option<BufReader<TcpStream>>, addr: SocketAddr) -> std::io::Result<u16> {
    if conn.is_none() {
        let c = TcpStream::connect(addr)?;
        c.set_read_timeout(Some(Duration::from_secs(5)))?;
        *conn = Some(BufReader::new(c));
    }
    let Some(r) = conn.as_mut() else {
        return Err(ErrorKind::NotConnected.into());
    };
    r.get_mut()
        .write_all(b"GET /state.json HTTP/1.1\r\nHost: x\r\n\r\n")?;
    let mut line = String::new();
    r.read_line(&mut line)?;
    let status = line
        .split(' ')
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    let mut length = 0;
    loop {
        line.clear();
        if r.read_line(&mut line)? == 0 {
            return Err(ErrorKind::UnexpectedEof.into());
        }
        if line == "\r\n" {
            break;
        }
        if let Some(v) = line.strip_prefix("Content-Length: ") {
            length = v.trim().parse().unwrap_or(0);
        }
    }
    let mut body = vec![0; length];
    r.read_exact(&mut body)?;
    Ok(status)
}
