//! The little HTTP/1.1 the live page needs, bounded: a request's head is read within a time limit
//! and a size limit, parsed without trusting a byte of it, and answered; nothing else is read.
//!
//! Only GET and HEAD are served. A request body is never read: a request that announces one is
//! answered (405 for the methods that carry one) and the connection is closed after the answer.

use std::io::{ErrorKind, Read, Write};
use std::net::{Shutdown, TcpStream};
use std::time::{Duration, Instant};

/// Most header lines in a request head.
const MAX_HEADERS: usize = 100;

/// A request's head, parsed.
#[derive(Debug, PartialEq, Eq)]
pub(crate) struct Request {
    /// HEAD: the answer's head only.
    pub head_only: bool,
    /// The path asked for, without its query.
    pub path: String,
    /// Whether the connection stays open for another request after the answer.
    pub keep_alive: bool,
}

/// An error answer: the status and one sentence saying why.
#[derive(Debug, PartialEq, Eq)]
pub(crate) struct Refused {
    pub status: u16,
    pub why: &'static str,
}

const fn refused(status: u16, why: &'static str) -> Refused {
    Refused { status, why }
}

/// What waiting for the next request's head gave.
#[derive(Debug)]
pub(crate) enum Next {
    /// A whole head (the request line and the header lines, without the empty line ending it).
    Head(Vec<u8>),
    /// The client closed the connection, or said nothing before the time limit: close quietly.
    Gone,
    /// Part of a head, then nothing until the time limit (408) or the end of the connection (400),
    /// or a head larger than the limit (414 or 431).
    Refused(Refused),
}

/// A connection's reading side: the bytes read and not yet used (the start of a pipelined
/// request, at most the head limit and one read more).
pub(crate) struct Reader {
    buf: Vec<u8>,
    /// How much of `buf` has been searched for the head's end (a request dribbled a byte at a
    /// time is not searched again from its start at each byte).
    searched: usize,
}

/// Where the first empty line ends in `buf` (a line ends with LF or CR LF), looking from `from`
/// on: (the head's length before it, the length with it).
fn head_end(buf: &[u8], from: usize) -> Option<(usize, usize)> {
    let mut i = from;
    while let Some(at) = buf.get(i..)?.iter().position(|&b| b == b'\n') {
        let nl = i + at;
        match buf.get(nl + 1..) {
            Some([b'\n', ..]) => return Some((nl, nl + 2)),
            Some([b'\r', b'\n', ..]) => return Some((nl, nl + 3)),
            _ => i = nl + 1,
        }
    }
    None
}

impl Reader {
    pub(crate) fn new() -> Self {
        Reader {
            buf: Vec::with_capacity(1024),
            searched: 0,
        }
    }

    /// Reads the next request's head, waiting at most `timeout` for it and keeping at most
    /// `max_bytes` of it.
    pub(crate) fn next(
        &mut self,
        stream: &mut TcpStream,
        timeout: Duration,
        max_bytes: usize,
    ) -> Next {
        let deadline = Instant::now() + timeout;
        let mut chunk = [0u8; 4096];
        loop {
            // Empty lines before a request line are ignored (RFC 9112, 2.2).
            let blank = self
                .buf
                .iter()
                .position(|&b| b != b'\r' && b != b'\n')
                .unwrap_or(self.buf.len());
            let blank = if blank == self.buf.len() && self.buf.last() == Some(&b'\r') {
                // A CR at the end may be the start of a CR LF still to come: it is kept.
                blank.saturating_sub(1)
            } else {
                blank
            };
            if blank > 0 {
                self.buf.drain(..blank);
                self.searched = 0;
            }
            // An end seen in part at the last search ("\n", "\n\r") is looked at again.
            let found = head_end(&self.buf, self.searched.saturating_sub(2));
            self.searched = self.buf.len();
            if let Some((head, with_end)) = found {
                if head > max_bytes {
                    return Next::Refused(too_large(&self.buf, max_bytes));
                }
                let rest = self.buf.split_off(with_end);
                let mut head_bytes = std::mem::replace(&mut self.buf, rest);
                head_bytes.truncate(head);
                self.searched = 0;
                return Next::Head(head_bytes);
            }
            if self.buf.len() > max_bytes {
                return Next::Refused(too_large(&self.buf, max_bytes));
            }
            let partial = !self.buf.iter().all(|&b| b == b'\r');
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() || stream.set_read_timeout(Some(left)).is_err() {
                return timed_out(partial);
            }
            match stream.read(&mut chunk) {
                Ok(0) if partial => {
                    return Next::Refused(refused(400, "the request ended before its head did"));
                }
                Ok(0) => return Next::Gone,
                Ok(n) => self
                    .buf
                    .extend_from_slice(chunk.get(..n).unwrap_or_default()),
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {
                    return timed_out(partial);
                }
                Err(_) => return Next::Gone,
            }
        }
    }
}

fn timed_out(partial: bool) -> Next {
    if partial {
        Next::Refused(refused(408, "the request's head did not come in time"))
    } else {
        Next::Gone
    }
}

fn too_large(buf: &[u8], max_bytes: usize) -> Refused {
    let line = buf.iter().position(|&b| b == b'\n').unwrap_or(buf.len());
    if line > max_bytes {
        refused(414, "the request line is too long")
    } else {
        refused(431, "the request's header lines are too long")
    }
}

/// A token's characters (RFC 9110, 5.6.2): method and header names.
fn is_token(s: &[u8]) -> bool {
    !s.is_empty()
        && s.iter()
            .all(|&b| b.is_ascii_alphanumeric() || b"!#$%&'*+-.^_`|~".contains(&b))
}

/// Parses a request head (without its final empty line).
pub(crate) fn parse(head: &[u8]) -> Result<Request, Refused> {
    let mut lines = head
        .split(|&b| b == b'\n')
        .map(|l| l.strip_suffix(b"\r").unwrap_or(l));
    let line = lines.next().unwrap_or_default();
    let mut parts = line.split(|&b| b == b' ');
    let (Some(method), Some(target), Some(version), None) =
        (parts.next(), parts.next(), parts.next(), parts.next())
    else {
        return Err(refused(
            400,
            "the request line is not 'METHOD PATH HTTP/1.1'",
        ));
    };
    let http_1_0 = match version {
        b"HTTP/1.1" => false,
        b"HTTP/1.0" => true,
        [b'H', b'T', b'T', b'P', b'/', major, b'.', minor]
            if major.is_ascii_digit() && minor.is_ascii_digit() =>
        {
            return Err(refused(505, "only HTTP/1.0 and HTTP/1.1 are served"));
        }
        _ => {
            return Err(refused(
                400,
                "the request line is not 'METHOD PATH HTTP/1.1'",
            ));
        }
    };
    if !is_token(method) {
        return Err(refused(400, "the method is not a word"));
    }
    if target.is_empty() || !target.iter().all(|b| (0x21..0x7f).contains(b)) {
        return Err(refused(400, "the path holds a character a path cannot"));
    }
    let (mut close, mut keep_alive, mut body) = (false, false, false);
    let mut count = 0;
    for l in lines {
        count += 1;
        if count > MAX_HEADERS {
            return Err(refused(431, "the request has too many header lines"));
        }
        if matches!(l.first(), Some(b' ' | b'\t')) {
            return Err(refused(400, "a header line is folded"));
        }
        let Some(colon) = l.iter().position(|&b| b == b':') else {
            return Err(refused(400, "a header line has no ':'"));
        };
        let (name, value) = l.split_at(colon);
        let value = value.get(1..).unwrap_or_default();
        if !is_token(name) {
            return Err(refused(400, "a header's name is not a word"));
        }
        if value.iter().any(|&b| (b < 0x20 && b != b'\t') || b == 0x7f) {
            return Err(refused(400, "a header's value holds a control character"));
        }
        let value = value.trim_ascii();
        if name.eq_ignore_ascii_case(b"connection") {
            for option in value.split(|&b| b == b',') {
                let option = option.trim_ascii();
                close |= option.eq_ignore_ascii_case(b"close");
                keep_alive |= option.eq_ignore_ascii_case(b"keep-alive");
            }
        } else if name.eq_ignore_ascii_case(b"content-length") {
            if value.is_empty() || !value.iter().all(u8::is_ascii_digit) {
                return Err(refused(400, "Content-Length is not a number"));
            }
            body |= value.iter().any(|&b| b != b'0');
        } else if name.eq_ignore_ascii_case(b"transfer-encoding") {
            body = true;
        }
    }
    let head_only = match method {
        b"GET" => false,
        b"HEAD" => true,
        _ => {
            return Err(refused(
                405,
                "only GET and HEAD are answered here: the page is read-only",
            ));
        }
    };
    let path = if target.starts_with(b"/") {
        target
    } else if let Some(after) = target
        .strip_prefix(b"http://")
        .or_else(|| target.strip_prefix(b"https://"))
    {
        // The absolute form (RFC 9112, 3.2.2): the path after the authority.
        after
            .iter()
            .position(|&b| b == b'/')
            .and_then(|at| after.get(at..))
            .unwrap_or(b"/")
    } else {
        return Err(refused(400, "the path does not begin with '/'"));
    };
    let path = path
        .split(|&b| b == b'?' || b == b'#')
        .next()
        .unwrap_or_default();
    Ok(Request {
        head_only,
        // Printable ASCII only (checked above).
        path: String::from_utf8_lossy(path).into_owned(),
        keep_alive: !body && !close && (!http_1_0 || keep_alive),
    })
}

/// A status's reason phrase.
pub(crate) fn reason(status: u16) -> &'static str {
    match status {
        200 => "OK",
        400 => "Bad Request",
        404 => "Not Found",
        405 => "Method Not Allowed",
        408 => "Request Timeout",
        414 => "URI Too Long",
        431 => "Request Header Fields Too Large",
        503 => "Service Unavailable",
        505 => "HTTP Version Not Supported",
        _ => "",
    }
}

/// An answer: the status, its headers beyond the length and the connection's, and the body.
pub(crate) struct Answer<'a> {
    pub status: u16,
    pub content_type: &'a str,
    pub extra: &'a [(&'a str, &'a str)],
    pub body: &'a [u8],
}

impl Answer<'_> {
    /// Writes the answer (its head only when `head_only`) within `within` and a second more per
    /// [`MIN_RATE`] bytes; `keep_alive` says whether the connection stays open after it.
    pub(crate) fn write(
        &self,
        w: &mut TcpStream,
        head_only: bool,
        keep_alive: bool,
        within: Duration,
    ) -> std::io::Result<()> {
        let size = if head_only { 0 } else { self.body.len() };
        let rate = u64::try_from(size).unwrap_or(u64::MAX).saturating_mul(1000) / MIN_RATE;
        let deadline = Instant::now() + within.saturating_add(Duration::from_millis(rate));
        let mut head = format!(
            "HTTP/1.1 {} {}\r\nContent-Type: {}\r\nContent-Length: {}\r\nCache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\nConnection: {}\r\n",
            self.status,
            reason(self.status),
            self.content_type,
            self.body.len(),
            if keep_alive { "keep-alive" } else { "close" }
        );
        for (name, value) in self.extra {
            head.push_str(name);
            head.push_str(": ");
            head.push_str(value);
            head.push_str("\r\n");
        }
        head.push_str("\r\n");
        if head_only || self.body.is_empty() {
            write_by(w, head.as_bytes(), deadline)
        } else if self.body.len() <= 16 * 1024 {
            // One write: the head and a small body leave in one packet.
            let mut all = head.into_bytes();
            all.extend_from_slice(self.body);
            write_by(w, &all, deadline)
        } else {
            write_by(w, head.as_bytes(), deadline)?;
            write_by(w, self.body, deadline)
        }
    }
}

/// The slowest a client may take an answer, once the write timeout's grace is spent (bytes a
/// second): a 5 MB view may take 10 s + 5 min.
const MIN_RATE: u64 = 16 * 1024;

/// Writes all of `bytes` by `deadline`, or fails. A socket's write timeout alone bounds each
/// write call: a client that takes a few bytes now and then (a byte every 9 s against a 10 s
/// timeout) would start it again each time and hold its thread for ever.
pub(crate) fn write_by(
    stream: &mut TcpStream,
    bytes: &[u8],
    deadline: Instant,
) -> std::io::Result<()> {
    let mut left = bytes;
    while !left.is_empty() {
        let time = deadline.saturating_duration_since(Instant::now());
        if time.is_zero() {
            return Err(ErrorKind::TimedOut.into());
        }
        stream.set_write_timeout(Some(time))?;
        match stream.write(left) {
            Ok(0) => return Err(ErrorKind::WriteZero.into()),
            Ok(n) => left = left.get(n..).unwrap_or_default(),
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(())
}

/// An error answer, closing the connection after it.
pub(crate) fn refusal(r: &Refused) -> Answer<'_> {
    Answer {
        status: r.status,
        content_type: "text/plain; charset=utf-8",
        extra: match r.status {
            405 => &[("Allow", "GET, HEAD")],
            503 => &[("Retry-After", "5")],
            _ => &[],
        },
        body: r.why.as_bytes(),
    }
}

/// Closes a connection after an answer while the client may still be sending: the writing side
/// first, then what the client sends is read and thrown away, for at most `wait` and `max_bytes`,
/// so that closing with unread bytes (which resets the connection) does not wipe out the answer
/// before the client reads it.
pub(crate) fn close_gently(mut stream: TcpStream, wait: Duration, max_bytes: usize) {
    let _ = stream.shutdown(Shutdown::Write);
    let deadline = Instant::now() + wait;
    let mut chunk = [0u8; 4096];
    let mut read = 0;
    while read < max_bytes {
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() || stream.set_read_timeout(Some(left)).is_err() {
            return;
        }
        match stream.read(&mut chunk) {
            Ok(0) => return,
            Ok(n) => read += n,
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(_) => return,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ok(head: &str) -> Request {
        parse(head.as_bytes()).unwrap()
    }

    fn status(head: &[u8]) -> u16 {
        parse(head).unwrap_err().status
    }

    #[test]
    fn requests_are_parsed() {
        assert_eq!(
            ok("GET /state.json?x=1 HTTP/1.1\r\nHost: a"),
            Request {
                head_only: false,
                path: "/state.json".into(),
                keep_alive: true
            }
        );
        let r = ok("HEAD / HTTP/1.0");
        assert!(r.head_only && !r.keep_alive && r.path == "/");
        assert!(ok("GET / HTTP/1.0\nConnection: Keep-Alive").keep_alive);
        assert!(!ok("GET / HTTP/1.1\r\nConnection: foo, close").keep_alive);
        assert!(!ok("GET / HTTP/1.1\r\nContent-Length: 12").keep_alive);
        assert!(ok("GET / HTTP/1.1\r\nContent-Length: 0").keep_alive);
        assert_eq!(
            ok("GET http://example.com:80/events HTTP/1.1").path,
            "/events"
        );
        assert_eq!(ok("GET http://example.com HTTP/1.1").path, "/");
    }

    #[test]
    fn bad_requests_are_refused_with_their_status() {
        for m in [
            "POST", "PUT", "DELETE", "PATCH", "OPTIONS", "get", "CONNECT",
        ] {
            assert_eq!(status(format!("{m} / HTTP/1.1").as_bytes()), 405, "{m}");
        }
        assert_eq!(status(b"GET / HTTP/2.0"), 505);
        for bad in [
            &b"GET /"[..],
            b"GET  / HTTP/1.1",
            b"GET / HTTP/1.1 x",
            b"G(T / HTTP/1.1",
            b"GET /\xff HTTP/1.1",
            b"GET x HTTP/1.1",
            b"GET / HTTP/1.1\r\nno colon",
            b"GET / HTTP/1.1\r\n folded: x",
            b"GET / HTTP/1.1\r\nbad name: x",
            b"GET / HTTP/1.1\r\nx: a\x00b",
            b"GET / HTTP/1.1\r\nContent-Length: -1",
            b"",
            b"\xff\xfe\x00\x01",
        ] {
            assert_eq!(status(bad), 400, "{}", String::from_utf8_lossy(bad));
        }
        let many = format!("GET / HTTP/1.1{}", "\r\nx: y".repeat(MAX_HEADERS + 1));
        assert_eq!(status(many.as_bytes()), 431);
    }

    #[test]
    fn the_head_ends_at_the_first_empty_line() {
        assert_eq!(head_end(b"GET / HTTP/1.1\r\n\r\nnext", 0), Some((15, 18)));
        assert_eq!(head_end(b"GET / HTTP/1.1\n\nnext", 0), Some((14, 16)));
        assert_eq!(head_end(b"GET / HTTP/1.1\r\nHost: a\r\n", 0), None);
        assert_eq!(head_end(b"\r\n", 0), None);
        // From where the last search left off, less two bytes.
        assert_eq!(head_end(b"GET / HTTP/1.1\r\n\r\n", 14), Some((15, 18)));
        assert_eq!(head_end(b"GET / HTTP/1.1\r\n\r\n", 16), None);
        assert_eq!(head_end(b"GET / HTTP/1.1\r\n\r\n", 99), None);
    }
}
