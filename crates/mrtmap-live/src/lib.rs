//! # mrtmap-live
//!
//! The page `mrtmap live` serves while a scan is recorded: offline (nothing from a CDN), pushed
//! to by Server-Sent Events. [`Server`] is a [`LiveSink`]: the pipeline's live run
//! ([`mrtmap_pipeline::Pipeline::live`]) sends it the state every second and a new 3D view after each
//! refresh, and it serves:
//!
//! | path | what |
//! |---|---|
//! | `/` | the page: the 3D view growing, the verdict, the map's largest ±, the advice, the warnings |
//! | `/state.json` | the state now ([`LiveState`]) |
//! | `/events` | Server-Sent Events: `state` (the state's JSON) at each change |
//! | `/view.html` | the 3D view of the last refresh (the report's viewer), shown by the page in a frame |

use std::io::Write;
use std::net::SocketAddr;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::Duration;

use mrtmap_pipeline::{LiveSink, LiveState};

/// The page (HTML, CSS and JavaScript in one file).
const PAGE: &str = include_str!("page.html");

/// What the 3D frame shows before the room has been put together.
const WAITING: &str = "<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\"><title>mrtmap live</title></head>\
<body style=\"font-family:system-ui,sans-serif;color:#555\"><p>The room is not put together yet: keep scanning the walls, the floor and the ceiling.</p></body></html>";

/// A comment line sent when nothing changed for this long (s), so proxies keep the stream open.
const KEEP_ALIVE_S: u64 = 15;

#[derive(Default)]
struct Latest {
    state: String,
    state_version: u64,
    view: Option<String>,
    closed: bool,
}

struct Shared {
    latest: Mutex<Latest>,
    changed: Condvar,
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, Latest> {
        self.latest
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }
}

/// The live page's server: serves until dropped.
pub struct Server {
    shared: Arc<Shared>,
    http: Arc<tiny_http::Server>,
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

impl Server {
    /// Listens on `addr` ("127.0.0.1:8080"; port 0 picks a free one) and serves in the
    /// background.
    pub fn start(addr: &str) -> Result<Self, ServeError> {
        let http = tiny_http::Server::http(addr).map_err(|e| {
            ServeError(format!(
                "cannot listen on {addr} ({e}): give --serve another address or port, such as 127.0.0.1:8081"
            ))
        })?;
        let bound = http
            .server_addr()
            .to_ip()
            .ok_or_else(|| ServeError(format!("{addr} is not an IP address and port")))?;
        let shared = Arc::new(Shared {
            latest: Mutex::new(Latest {
                state: "{}".into(),
                ..Latest::default()
            }),
            changed: Condvar::new(),
        });
        let http = Arc::new(http);
        let (h, s) = (Arc::clone(&http), Arc::clone(&shared));
        std::thread::spawn(move || {
            for request in h.incoming_requests() {
                let s = Arc::clone(&s);
                std::thread::spawn(move || answer(request, &s));
            }
        });
        Ok(Server {
            shared,
            http,
            addr: bound,
        })
    }

    /// The address served (with the port chosen when 0 was asked).
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        self.shared.lock().closed = true;
        self.shared.changed.notify_all();
        self.http.unblock();
    }
}

impl LiveSink for Server {
    fn state(&self, state: &LiveState) {
        let json = serde_json::to_string(state).unwrap_or_else(|_| "{}".into());
        let mut l = self.shared.lock();
        l.state = json;
        l.state_version += 1;
        drop(l);
        self.shared.changed.notify_all();
    }

    fn view(&self, html: String) {
        self.shared.lock().view = Some(html);
    }
}

/// `r` with a header added (the names and values here are all valid).
fn with_header<R: std::io::Read>(
    r: tiny_http::Response<R>,
    name: &str,
    value: &str,
) -> tiny_http::Response<R> {
    match tiny_http::Header::from_bytes(name.as_bytes(), value.as_bytes()) {
        Ok(h) => r.with_header(h),
        Err(()) => r,
    }
}

fn answer(request: tiny_http::Request, shared: &Shared) {
    let path = request.url().split('?').next().unwrap_or("/").to_string();
    let send = |body: String, kind: &str, request: tiny_http::Request| {
        let r = with_header(tiny_http::Response::from_string(body), "Content-Type", kind);
        let r = with_header(r, "Cache-Control", "no-store");
        let _ = request.respond(r);
    };
    match path.as_str() {
        "/" | "/index.html" => send(PAGE.to_string(), "text/html; charset=utf-8", request),
        "/state.json" => {
            let body = shared.lock().state.clone();
            send(body, "application/json", request);
        }
        "/view.html" => {
            let body = shared
                .lock()
                .view
                .clone()
                .unwrap_or_else(|| WAITING.to_string());
            send(body, "text/html; charset=utf-8", request);
        }
        "/events" => events(request, shared),
        _ => {
            let r = tiny_http::Response::from_string(format!(
                "{path} is not served here: the page is at /, its state at /state.json"
            ))
            .with_status_code(404);
            let _ = request.respond(r);
        }
    }
}

/// Server-Sent Events: the state at each change, until the client goes or the server closes.
fn events(request: tiny_http::Request, shared: &Shared) {
    let mut w = request.into_writer();
    let head = "HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nCache-Control: no-store\r\nConnection: keep-alive\r\n\r\n";
    if w.write_all(head.as_bytes())
        .and_then(|()| w.flush())
        .is_err()
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
        let msg = if l.state_version == seen {
            ": still here\n\n".to_string()
        } else {
            seen = l.state_version;
            format!("event: state\ndata: {}\n\n", l.state)
        };
        drop(l);
        if w.write_all(msg.as_bytes())
            .and_then(|()| w.flush())
            .is_err()
        {
            return;
        }
    }
}
