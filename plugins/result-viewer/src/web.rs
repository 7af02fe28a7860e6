//! The live web view: a small HTTP server on loopback for the page, its
//! scripts and the viewer's JSON, with server-sent events for live updates.
//!
//! What: [`WebServer::start`] binds the configured address (127.0.0.1 unless
//! configured otherwise; with `fallback`, a free port when that one is taken)
//! and serves `GET /` (the page), `/viewer.js`, `/three/*` (three.js, vendored
//! with its licence: the page works offline), `/scene.json`, `/state.json`,
//! `/trajectory.json` and `/events` (an event stream: the state JSON on every
//! change, at most [`MIN_EVENT_INTERVAL`] apart).
//!
//! Why: a person judges a grasp by looking at it, also on a headless robot PC
//! reached through an SSH tunnel; no GPU or display is needed on the server.
//!
//! How: `std::net` with a thread per connection, at most `max_clients` at
//! once (more get 503). The whole request head has a deadline (5 s from the
//! connection; then 408), each event must be written within 5 s, a page that
//! leaves more than its last event unread for 5 s is cut (its TCP window tells,
//! [`crate::unread`]), and an event stream's kernel send buffer is small, so a
//! slow, stalled or vanished browser ends only its own thread, soon; nothing here ever holds a lock the bus
//! followers or the plugin's calls wait on while writing. A request whose
//! `Host` is not a loopback name is refused when bound to loopback (DNS
//! rebinding).

use std::io::{self, Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crate::unread::{set_send_buffer, Unread};
use crate::viewer::Viewer;

/// Socket read and write timeout; also the whole request head's deadline and
/// the longest one event may take to write.
const IO_TIMEOUT: Duration = Duration::from_secs(5);
/// The kernel's send buffer of an event stream (it doubles it): a page that
/// stops reading fills it in a few events, and the next write then has
/// [`IO_TIMEOUT`] to finish (the default buffer grows to megabytes).
const EVENT_SNDBUF: usize = 16 * 1024;
/// Largest request head read.
const MAX_HEAD: usize = 8192;
/// Shortest time between two events to one page.
pub const MIN_EVENT_INTERVAL: Duration = Duration::from_millis(100);
/// A comment is sent on a quiet event stream this often (finds closed pages).
const KEEPALIVE: Duration = Duration::from_secs(10);
/// The keep-alive comment.
const KEEPALIVE_COMMENT: &[u8] = b": keep-alive\n\n";

const INDEX: &[u8] = include_bytes!("../assets/index.html");
const SCRIPT: &[u8] = include_bytes!("../assets/viewer.js");
const THREE_MODULE: &[u8] = include_bytes!("../assets/three/three.module.js");
const THREE_CORE: &[u8] = include_bytes!("../assets/three/three.core.js");
const ORBIT: &[u8] = include_bytes!("../assets/three/OrbitControls.js");
const THREE_LICENSE: &[u8] = include_bytes!("../assets/three/LICENSE");

/// The running server; dropping it stops accepting (open streams end at
/// their next write or when the viewer's board closes).
pub struct WebServer {
    addr: SocketAddr,
    stop: Arc<AtomicBool>,
    accept: Option<JoinHandle<()>>,
}

/// Binds `addr`, or with `fallback` a free port on the same address when
/// `addr`'s port is taken.
fn bind(addr: SocketAddr, fallback: bool) -> io::Result<TcpListener> {
    match TcpListener::bind(addr) {
        Err(e) if fallback && e.kind() == io::ErrorKind::AddrInUse => {
            TcpListener::bind(SocketAddr::new(addr.ip(), 0))
        }
        other => other,
    }
}

impl WebServer {
    /// Starts serving `viewer` on `addr` (see `bind` for `fallback`).
    pub fn start(
        addr: SocketAddr,
        fallback: bool,
        max_clients: usize,
        viewer: Arc<Viewer>,
    ) -> io::Result<WebServer> {
        let listener = bind(addr, fallback)?;
        let addr = listener.local_addr()?;
        let stop = Arc::new(AtomicBool::new(false));
        let flag = stop.clone();
        let active = Arc::new(AtomicUsize::new(0));
        let accept = std::thread::Builder::new()
            .name("viewer-web".into())
            .spawn(move || {
                for stream in listener.incoming() {
                    if flag.load(Ordering::Relaxed) {
                        break;
                    }
                    let Ok(stream) = stream else { continue };
                    connection(stream, &viewer, &active, max_clients, addr, &flag);
                }
            })?;
        Ok(WebServer {
            addr,
            stop,
            accept: Some(accept),
        })
    }

    /// Where it serves.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// The page's address.
    pub fn url(&self) -> String {
        format!("http://{}/", self.addr)
    }
}

impl Drop for WebServer {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        // Wake the accept loop.
        let _ = TcpStream::connect_timeout(&self.addr, Duration::from_secs(1));
        if let Some(t) = self.accept.take() {
            let _ = t.join();
        }
    }
}

/// Counts a connection while it lives.
struct Slot(Arc<AtomicUsize>);

impl Drop for Slot {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::Relaxed);
    }
}

/// Hands `stream` to a thread of its own, or answers 503 when full.
fn connection(
    mut stream: TcpStream,
    viewer: &Arc<Viewer>,
    active: &Arc<AtomicUsize>,
    max_clients: usize,
    bound: SocketAddr,
    stop: &Arc<AtomicBool>,
) {
    let _ = stream.set_read_timeout(Some(IO_TIMEOUT));
    let _ = stream.set_write_timeout(Some(IO_TIMEOUT));
    if active.fetch_add(1, Ordering::Relaxed) >= max_clients {
        active.fetch_sub(1, Ordering::Relaxed);
        let _ = respond(
            &mut stream,
            "503 Service Unavailable",
            "text/plain",
            b"too many connections\n",
        );
        // Read what already came (never waiting: this is the accept thread), so
        // closing does not reset the connection under the answer.
        let _ = stream.shutdown(std::net::Shutdown::Write);
        if stream.set_nonblocking(true).is_ok() {
            let _ = io::copy(&mut (&stream).take(MAX_HEAD as u64), &mut io::sink());
        }
        return;
    }
    let slot = Slot(active.clone());
    let (viewer, stop) = (viewer.clone(), stop.clone());
    let spawned = std::thread::Builder::new()
        .name("viewer-web-conn".into())
        .spawn(move || {
            let _slot = slot;
            let _ = serve(stream, &viewer, bound, &stop);
        });
    drop(spawned);
}

/// Reads the request head (up to the blank line), all of it within
/// [`IO_TIMEOUT`] of the connection's start: a client trickling a byte at a time
/// cannot hold its slot longer (the socket timeout alone restarts with every
/// byte).
fn read_head(stream: &mut TcpStream) -> io::Result<String> {
    let deadline = Instant::now() + IO_TIMEOUT;
    let mut head = Vec::with_capacity(1024);
    let mut buf = [0u8; 1024];
    while !head.windows(4).any(|w| w == b"\r\n\r\n") {
        if head.len() > MAX_HEAD {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                "request head too large",
            ));
        }
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return Err(io::Error::new(
                io::ErrorKind::TimedOut,
                "request head not complete in time",
            ));
        }
        stream.set_read_timeout(Some(left))?;
        let n = stream.read(&mut buf)?;
        if n == 0 {
            return Err(io::ErrorKind::UnexpectedEof.into());
        }
        head.extend_from_slice(&buf[..n]);
    }
    Ok(String::from_utf8_lossy(&head).into_owned())
}

/// Writes a whole response and closes.
fn respond(stream: &mut TcpStream, status: &str, kind: &str, body: &[u8]) -> io::Result<()> {
    let head = format!(
        "HTTP/1.1 {status}\r\nContent-Type: {kind}\r\nContent-Length: {}\r\nCache-Control: no-cache\r\nX-Content-Type-Options: nosniff\r\nConnection: close\r\n\r\n",
        body.len()
    );
    stream.write_all(head.as_bytes())?;
    stream.write_all(body)?;
    stream.flush()
}

/// True when the request's `Host` names the loopback interface.
fn loopback_host(head: &str) -> bool {
    head.lines()
        .filter_map(|l| l.split_once(':'))
        .find(|(name, _)| name.trim().eq_ignore_ascii_case("host"))
        .is_some_and(|(_, value)| {
            let v = value.trim();
            let host = v.rsplit_once(':').map_or(v, |(h, _)| h);
            matches!(host, "127.0.0.1" | "localhost" | "[::1]")
        })
}

/// Answers one request.
fn serve(
    mut stream: TcpStream,
    viewer: &Viewer,
    bound: SocketAddr,
    stop: &AtomicBool,
) -> io::Result<()> {
    let head = match read_head(&mut stream) {
        Ok(head) => head,
        Err(e)
            if matches!(
                e.kind(),
                io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock
            ) =>
        {
            return respond(
                &mut stream,
                "408 Request Timeout",
                "text/plain",
                b"request head not complete within 5 s\n",
            );
        }
        Err(e) => return Err(e),
    };
    let _ = stream.set_read_timeout(Some(IO_TIMEOUT));
    let mut words = head.split_whitespace();
    let (method, target) = (words.next().unwrap_or(""), words.next().unwrap_or(""));
    if method != "GET" {
        return respond(
            &mut stream,
            "405 Method Not Allowed",
            "text/plain",
            b"GET only\n",
        );
    }
    if bound.ip().is_loopback() && !loopback_host(&head) {
        return respond(
            &mut stream,
            "403 Forbidden",
            "text/plain",
            b"Host must be a loopback name\n",
        );
    }
    const JS: &str = "text/javascript; charset=utf-8";
    const JSON: &str = "application/json";
    let path = target.split('?').next().unwrap_or("");
    match path {
        "/" | "/index.html" => respond(&mut stream, "200 OK", "text/html; charset=utf-8", INDEX),
        "/viewer.js" => respond(&mut stream, "200 OK", JS, SCRIPT),
        "/three/three.module.js" => respond(&mut stream, "200 OK", JS, THREE_MODULE),
        "/three/three.core.js" => respond(&mut stream, "200 OK", JS, THREE_CORE),
        "/three/OrbitControls.js" => respond(&mut stream, "200 OK", JS, ORBIT),
        "/three/LICENSE" => respond(
            &mut stream,
            "200 OK",
            "text/plain; charset=utf-8",
            THREE_LICENSE,
        ),
        "/scene.json" => respond(&mut stream, "200 OK", JSON, &viewer.scene_json()),
        "/state.json" => respond(&mut stream, "200 OK", JSON, &viewer.state_json()),
        "/trajectory.json" => respond(&mut stream, "200 OK", JSON, &viewer.trajectory_json()),
        "/events" => events(stream, viewer, stop),
        _ => respond(&mut stream, "404 Not Found", "text/plain", b"not found\n"),
    }
}

/// The event stream: the state now, then on every change (rate-limited) and
/// a keep-alive comment when quiet; ends on a failed write, on close, or when
/// the page has left more than its last event unread for [`IO_TIMEOUT`].
fn events(mut stream: TcpStream, viewer: &Viewer, stop: &AtomicBool) -> io::Result<()> {
    set_send_buffer(&stream, EVENT_SNDBUF);
    stream.write_all(
        b"HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nCache-Control: no-cache\r\nConnection: keep-alive\r\n\r\n",
    )?;
    viewer.event_clients.fetch_add(1, Ordering::Relaxed);
    let mut unread = Unread::default();
    let result = (|| loop {
        let seen = viewer.board.generation();
        let state = viewer.state_json();
        let mut event = Vec::with_capacity(state.len() + 24);
        event.extend_from_slice(b"event: state\ndata: ");
        event.extend_from_slice(&state);
        event.extend_from_slice(b"\n\n");
        write_by(&mut stream, &event, Instant::now() + IO_TIMEOUT)?;
        unread.wrote(event.len());
        viewer.sent();
        let sent_at = Instant::now();
        loop {
            if stop.load(Ordering::Relaxed) || viewer.board.is_closed() {
                return Ok(());
            }
            taken_in_time(&mut unread, &stream)?;
            // Watch a page that is behind closely; otherwise wait for a change.
            let wait = if unread.behind() {
                MIN_EVENT_INTERVAL
            } else {
                KEEPALIVE
            };
            if viewer.board.wait_past(seen, wait).is_some() {
                break;
            }
            if unread.quiet_for() >= KEEPALIVE {
                write_by(&mut stream, KEEPALIVE_COMMENT, Instant::now() + IO_TIMEOUT)?;
                unread.wrote(KEEPALIVE_COMMENT.len());
            }
        }
        std::thread::sleep(MIN_EVENT_INTERVAL.saturating_sub(sent_at.elapsed()));
    })();
    viewer.event_clients.fetch_sub(1, Ordering::Relaxed);
    result
}

/// Fails once the page has left more than its last write unread for
/// [`IO_TIMEOUT`] (see [`Unread`]).
fn taken_in_time(unread: &mut Unread, stream: &TcpStream) -> io::Result<()> {
    match unread.check(stream) {
        Some(stalled) if stalled >= IO_TIMEOUT => Err(io::Error::new(
            io::ErrorKind::TimedOut,
            "event stream not read for 5 s",
        )),
        _ => Ok(()),
    }
}

/// Writes all of `bytes` by `deadline` (the socket timeout alone restarts with
/// every partial write, so a page reading a byte at a time could stretch one
/// event without end).
fn write_by(stream: &mut TcpStream, mut bytes: &[u8], deadline: Instant) -> io::Result<()> {
    while !bytes.is_empty() {
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return Err(io::Error::new(
                io::ErrorKind::TimedOut,
                "event not taken in time",
            ));
        }
        stream.set_write_timeout(Some(left))?;
        match stream.write(bytes) {
            Ok(0) => return Err(io::ErrorKind::WriteZero.into()),
            Ok(n) => bytes = &bytes[n..],
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(())
}
