//! # mrtmap-live
//!
//! The page `mrtmap live` serves while a scan is recorded: offline (nothing from a CDN), pushed
//! to by Server-Sent Events. [`Server`] is a [`LiveSink`]: the pipeline's live run
//! ([`mrtmap_pipeline::Pipeline::live`]) sends it the state every second and a new 3D view after each
//! refresh, and it serves, to GET and HEAD:
//!
//! | path | what |
//! |---|---|
//! | `/`, `/index.html` | the page: the 3D view growing, the verdict, the map's largest ±, the advice, the warnings |
//! | `/state.json` | the state now ([`LiveState`]) |
//! | `/events` | Server-Sent Events: `state` (the state's JSON) at each change |
//! | `/view.html` | the 3D view of the last refresh (the report's viewer), shown by the page in a frame |
//!
//! It is read-only: no request changes anything. Another method is answered 405 (with
//! `Allow: GET, HEAD`), another path 404.
//!
//! ## Facing a network
//!
//! The server is a few hundred lines of its own on `std::net` rather than a general HTTP server,
//! so that every resource a client can make it spend is bounded ([`Limits`]):
//!
//! - connections: at most [`Limits::max_connections`] at once, each on a thread of its own; one
//!   more is answered 503 by the thread that accepts connections, at once, and closed;
//! - a request's head: read within [`Limits::request_timeout`] (408 after it; a connection kept
//!   open for another request is closed quietly after that time without one) and at most
//!   [`Limits::max_head_bytes`] long (414 or 431 beyond); a malformed one is answered 400 (505
//!   for another HTTP version) and the connection closed; a request body is never read;
//! - writing: an event must be taken whole within [`Limits::write_timeout`], an answer within it
//!   and a second more per 16 KiB, or the client is dropped (a deadline for the whole, not a
//!   timeout per write call, which a client taking a byte now and then would start again each
//!   time). An event stream whose client stopped reading fills the connection's buffers (the
//!   kernel's, not this process's), then its next event is not taken in time and it is dropped:
//!   nothing queues up for it here, as each event written is the newest state.
//!
//! [`LiveSink::state`] never waits for a client: it takes a lock that connections hold only to
//! copy a pointer to the newest state, and wakes the event streams.
//!
//! tiny_http, used before, could not be bounded from outside: it keeps reading a request line
//! or header line until its end, however long (memory without bound), reads with no time limit
//! and starts a thread for every connection before the application sees a request.

mod http;

use std::io::Read;
use std::net::{IpAddr, Ipv4Addr, Ipv6Addr, Shutdown, SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use mrtmap_pipeline::{LiveSink, LiveState};

use crate::http::{Answer, Next, Reader, Refused, Request};

/// The page (HTML, CSS and JavaScript in one file).
const PAGE: &str = include_str!("page.html");

/// What the 3D frame shows before the room has been put together.
const WAITING: &str = "<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\"><title>mrtmap live</title></head>\
<body style=\"font-family:system-ui,sans-serif;color:#555\"><p>The room is not put together yet: keep scanning the walls, the floor and the ceiling.</p></body></html>";

/// What another path is answered.
const NOT_FOUND: &str = "not served here: the page is at /, its state at /state.json";

/// A comment line sent when nothing changed for this long (s), so proxies keep the stream open.
const KEEP_ALIVE_S: u64 = 15;

/// After an answer that closes the connection, what the client still sends is read and thrown
/// away for at most this long and this much (see [`http::close_gently`]).
const LINGER: Duration = Duration::from_secs(2);
const LINGER_BYTES: usize = 256 * 1024;

/// Each connection's thread's stack (it holds two 4 KiB buffers and little else).
const STACK_BYTES: usize = 256 * 1024;

/// What the server lets a client make it spend.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Connections open at once (each has a thread); one more is answered 503 and closed.
    pub max_connections: usize,
    /// Time for a request's head to arrive, from the connection's start or the previous answer.
    pub request_timeout: Duration,
    /// Time for a client to take an event whole, or an answer (with a second more per 16 KiB of
    /// it), before it is dropped.
    pub write_timeout: Duration,
    /// Longest request head (request line and header lines), in bytes.
    pub max_head_bytes: usize,
}

impl Default for Limits {
    /// 64 connections, 10 s for a request's head, 10 s to take an event, 16 KiB of head.
    fn default() -> Self {
        Limits {
            max_connections: 64,
            request_timeout: Duration::from_secs(10),
            write_timeout: Duration::from_secs(10),
            max_head_bytes: 16 * 1024,
        }
    }
}

#[derive(Default)]
struct Latest {
    state: Arc<str>,
    state_version: u64,
    view: Option<Arc<str>>,
    closed: bool,
}

struct Shared {
    latest: Mutex<Latest>,
    changed: Condvar,
    /// Connections open (each on a thread of its own).
    open: AtomicUsize,
    limits: Limits,
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, Latest> {
        self.latest
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    fn closed(&self) -> bool {
        self.lock().closed
    }
}

/// One open connection, counted while it lives.
struct Counted(Arc<Shared>);

impl Drop for Counted {
    fn drop(&mut self) {
        self.0.open.fetch_sub(1, Ordering::SeqCst);
    }
}

/// The live page's server: serves until dropped.
pub struct Server {
    shared: Arc<Shared>,
    addr: SocketAddr,
}

/// Why the server could not start.
#[derive(Debug)]
pub struct ServeError(String);

impl std::fmt::Display for ServeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for ServeError {}

/// Whether only this machine can reach a server bound to `addr` (127.0.0.0/8, ::1, or ::1's
/// IPv4-mapped form): false for 0.0.0.0, :: and any other address, where anyone on the network
/// can read the page.
pub fn is_loopback(addr: SocketAddr) -> bool {
    addr.ip().to_canonical().is_loopback()
}

impl Server {
    /// Listens on `addr` ("127.0.0.1:8080"; port 0 picks a free one) and serves in the
    /// background, within the default [`Limits`].
    pub fn start(addr: &str) -> Result<Self, ServeError> {
        Self::start_with(addr, Limits::default())
    }

    /// [`Server::start`] within other limits.
    pub fn start_with(addr: &str, limits: Limits) -> Result<Self, ServeError> {
        let listener = TcpListener::bind(addr).map_err(|e| {
            ServeError(format!(
                "cannot listen on {addr} ({e}): give --serve another address or port, such as 127.0.0.1:8081"
            ))
        })?;
        let bound = listener
            .local_addr()
            .map_err(|e| ServeError(format!("cannot listen on {addr} ({e})")))?;
        let limits = Limits {
            max_connections: limits.max_connections.max(1),
            request_timeout: limits.request_timeout.max(Duration::from_millis(1)),
            write_timeout: limits.write_timeout.max(Duration::from_millis(1)),
            max_head_bytes: limits.max_head_bytes.max(64),
        };
        let shared = Arc::new(Shared {
            latest: Mutex::new(Latest {
                state: "{}".into(),
                ..Latest::default()
            }),
            changed: Condvar::new(),
            open: AtomicUsize::new(0),
            limits,
        });
        let s = Arc::clone(&shared);
        std::thread::Builder::new()
            .name("mrtmap-live accept".into())
            .spawn(move || accept(&listener, &s))
            .map_err(|e| ServeError(format!("cannot start serving on {addr} ({e})")))?;
        Ok(Server {
            shared,
            addr: bound,
        })
    }

    /// The address served (with the port chosen when 0 was asked).
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// Connections open now (each holds a thread): at most [`Limits::max_connections`].
    pub fn connections(&self) -> usize {
        self.shared.open.load(Ordering::SeqCst)
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        self.shared.lock().closed = true;
        self.shared.changed.notify_all();
        // The accepting thread waits in accept(): a connection wakes it, and it sees the close.
        let ip = match self.addr.ip() {
            IpAddr::V4(ip) if ip.is_unspecified() => IpAddr::V4(Ipv4Addr::LOCALHOST),
            IpAddr::V6(ip) if ip.is_unspecified() => IpAddr::V6(Ipv6Addr::LOCALHOST),
            ip => ip,
        };
        let _ = TcpStream::connect_timeout(
            &SocketAddr::new(ip, self.addr.port()),
            Duration::from_secs(1),
        );
    }
}

impl LiveSink for Server {
    fn state(&self, state: &LiveState) {
        let json: Arc<str> = serde_json::to_string(state)
            .unwrap_or_else(|_| "{}".into())
            .into();
        let mut l = self.shared.lock();
        l.state = json;
        l.state_version += 1;
        drop(l);
        self.shared.changed.notify_all();
    }

    fn view(&self, html: String) {
        let html: Arc<str> = html.into();
        self.shared.lock().view = Some(html);
    }
}

/// Accepts connections until the server closes: each on a thread of its own while there are
/// fewer than the limit, else answered 503 here.
fn accept(listener: &TcpListener, shared: &Arc<Shared>) {
    loop {
        let accepted = listener.accept();
        if shared.closed() {
            return;
        }
        let stream = match accepted {
            Ok((stream, _)) => stream,
            Err(_) => {
                // Out of file descriptors, or a connection reset before it was accepted: the
                // next accept may do; without the pause an error that stays would spin.
                std::thread::sleep(Duration::from_millis(50));
                continue;
            }
        };
        if shared.open.load(Ordering::SeqCst) >= shared.limits.max_connections {
            busy(stream);
            continue;
        }
        shared.open.fetch_add(1, Ordering::SeqCst);
        let counted = Counted(Arc::clone(shared));
        // When no thread can be started, the closure is dropped: the connection is closed and
        // uncounted.
        let _ = std::thread::Builder::new()
            .name("mrtmap-live connection".into())
            .stack_size(STACK_BYTES)
            .spawn(move || {
                connection(stream, &counted.0);
                drop(counted);
            });
    }
}

/// 503 at once, on the accepting thread, to a connection beyond the limit.
fn busy(mut stream: TcpStream) {
    // What already came is read (without waiting), so that closing does not reset the connection
    // before the client reads the answer.
    if stream.set_nonblocking(true).is_ok() {
        let mut chunk = [0u8; 4096];
        let _ = stream.read(&mut chunk);
    }
    let _ = stream.set_nonblocking(false);
    let busy = Refused {
        status: 503,
        why: "too many connections to the live page: try again in a few seconds",
    };
    let _ = http::refusal(&busy).write(&mut stream, false, false, Duration::from_millis(100));
    let _ = stream.shutdown(Shutdown::Write);
}

/// Answers a connection's requests until it closes, times out or asks for the event stream.
fn connection(mut stream: TcpStream, shared: &Shared) {
    let limits = shared.limits;
    let _ = stream.set_nodelay(true);
    if stream
        .set_write_timeout(Some(limits.write_timeout))
        .is_err()
    {
        return;
    }
    let mut reader = Reader::new();
    loop {
        let head = match reader.next(&mut stream, limits.request_timeout, limits.max_head_bytes) {
            Next::Gone => return,
            Next::Refused(r) => return refuse(stream, &r, limits.write_timeout),
            Next::Head(head) => head,
        };
        if shared.closed() {
            return;
        }
        let request = match http::parse(&head) {
            Ok(r) => r,
            Err(r) => return refuse(stream, &r, limits.write_timeout),
        };
        match answer(&mut stream, &request, shared) {
            Ok(Then::Next) => {}
            Ok(Then::Close) => return http::close_gently(stream, LINGER, LINGER_BYTES),
            Ok(Then::Drop) | Err(_) => return,
        }
    }
}

/// An error answer, then the connection closed.
fn refuse(mut stream: TcpStream, r: &Refused, write_timeout: Duration) {
    if http::refusal(r)
        .write(&mut stream, false, false, write_timeout)
        .is_ok()
    {
        http::close_gently(stream, LINGER, LINGER_BYTES);
    }
}

/// What follows an answer.
enum Then {
    /// The next request on the same connection.
    Next,
    /// Closing, gently (the client may still be sending).
    Close,
    /// Closing at once (an event stream ended: the client went or stopped reading).
    Drop,
}

/// Answers one request.
fn answer(stream: &mut TcpStream, r: &Request, shared: &Shared) -> std::io::Result<Then> {
    let html = "text/html; charset=utf-8";
    let held: Arc<str>;
    let (status, content_type, body) = match r.path.as_str() {
        "/" | "/index.html" => (200, html, PAGE),
        "/state.json" => {
            held = Arc::clone(&shared.lock().state);
            (200, "application/json", &*held)
        }
        "/view.html" => match shared.lock().view.clone() {
            Some(view) => {
                held = view;
                (200, html, &*held)
            }
            None => (200, html, WAITING),
        },
        "/events" => {
            events(stream, r.head_only, shared);
            return Ok(Then::Drop);
        }
        _ => (404, "text/plain; charset=utf-8", NOT_FOUND),
    };
    Answer {
        status,
        content_type,
        extra: &[],
        body: body.as_bytes(),
    }
    .write(
        stream,
        r.head_only,
        r.keep_alive,
        shared.limits.write_timeout,
    )?;
    Ok(if r.keep_alive {
        Then::Next
    } else {
        Then::Close
    })
}

/// Server-Sent Events: the state at each change, until the client goes, stops reading (an event
/// not taken whole within the write timeout) or the server closes.
fn events(stream: &mut TcpStream, head_only: bool, shared: &Shared) {
    let head = "HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nCache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\nConnection: close\r\n\r\n";
    if http::write_by(
        stream,
        head.as_bytes(),
        Instant::now() + shared.limits.write_timeout,
    )
    .is_err()
        || head_only
    {
        return;
    }
    let mut seen = 0;
    loop {
        let mut l = shared.lock();
        while l.state_version == seen && !l.closed {
            let (g, timeout) = shared
                .changed
                .wait_timeout(l, Duration::from_secs(KEEP_ALIVE_S))
                .unwrap_or_else(std::sync::PoisonError::into_inner);
            l = g;
            if timeout.timed_out() {
                break;
            }
        }
        if l.closed {
            return;
        }
        let (state, version) = (Arc::clone(&l.state), l.state_version);
        drop(l);
        let msg = if version == seen {
            ": still here\n\n".to_string()
        } else {
            seen = version;
            format!("event: state\ndata: {state}\n\n")
        };
        if http::write_by(
            stream,
            msg.as_bytes(),
            Instant::now() + shared.limits.write_timeout,
        )
        .is_err()
        {
            return;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn loopback_addresses_are_told_from_the_network() {
        for local in [
            "127.0.0.1:8080",
            "127.1.2.3:0",
            "[::1]:8080",
            "[::ffff:127.0.0.1]:80",
        ] {
            assert!(is_loopback(local.parse().unwrap()), "{local}");
        }
        for open in [
            "0.0.0.0:8080",
            "[::]:8080",
            "192.168.1.20:8080",
            "10.0.0.1:80",
            "[fe80::1]:80",
            "[::ffff:192.168.1.2]:80",
        ] {
            assert!(!is_loopback(open.parse().unwrap()), "{open}");
        }
    }
}
