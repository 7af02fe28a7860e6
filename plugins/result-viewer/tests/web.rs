//! The viewer's web server on a real loopback socket: the page and its
//! scripts, the JSON, the event stream following the board, refusals
//! (method, foreign `Host`, too many connections), slow clients (a request head
//! trickled a byte at a time, an event stream never read) cut at their
//! deadlines, and shutdown.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::{Duration, Instant};

use tsukami_planner_kit::Session;
use tsukami_result_viewer::latest::{Board, Outcome};
use tsukami_result_viewer::viewer::Viewer;
use tsukami_result_viewer::web::WebServer;
use tsukami_result_viewer::world::ViewerWorld;

fn start(max_clients: usize) -> (WebServer, Arc<Viewer>) {
    let models = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models");
    let session = Session::<ViewerWorld>::new(models);
    let viewer = Arc::new(Viewer::new(session, Arc::new(Board::default())));
    let addr: SocketAddr = "127.0.0.1:0".parse().unwrap();
    let server = WebServer::start(addr, false, max_clients, viewer.clone()).unwrap();
    (server, viewer)
}

fn connect(addr: SocketAddr) -> TcpStream {
    let s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
    s
}

/// Sends a request, returns the status line and the body.
fn request(addr: SocketAddr, head: &str) -> (String, Vec<u8>) {
    let mut s = connect(addr);
    s.write_all(head.as_bytes()).unwrap();
    let mut all = Vec::new();
    s.read_to_end(&mut all).unwrap();
    let split = all.windows(4).position(|w| w == b"\r\n\r\n").unwrap();
    let status = String::from_utf8_lossy(&all[..split])
        .lines()
        .next()
        .unwrap()
        .to_owned();
    (status, all[split + 4..].to_vec())
}

fn get(addr: SocketAddr, path: &str) -> (String, Vec<u8>) {
    request(
        addr,
        &format!("GET {path} HTTP/1.1\r\nHost: {addr}\r\n\r\n"),
    )
}

#[test]
fn serves_the_page_its_scripts_and_json_and_refuses_the_rest() {
    let (server, _viewer) = start(8);
    let addr = server.addr();
    assert!(server.url().starts_with("http://127.0.0.1:"));
    let (status, page) = get(addr, "/");
    assert_eq!(status, "HTTP/1.1 200 OK");
    let page = String::from_utf8(page).unwrap();
    assert!(page.contains("importmap") && page.contains("/viewer.js"));
    for path in [
        "/viewer.js",
        "/three/three.module.js",
        "/three/three.core.js",
        "/three/OrbitControls.js",
    ] {
        assert_eq!(get(addr, path).0, "HTTP/1.1 200 OK", "{path}");
    }
    assert!(String::from_utf8(get(addr, "/three/LICENSE").1)
        .unwrap()
        .contains("MIT License"));
    let (_, state) = get(addr, "/state.json");
    let state: serde_json::Value = serde_json::from_slice(&state).unwrap();
    assert_eq!(state["world_version"], 0);
    assert!(state["posture"].is_null() && state["plan"].is_null());
    let (_, scene) = get(addr, "/scene.json");
    let scene: serde_json::Value = serde_json::from_slice(&scene).unwrap();
    assert_eq!(scene["links"].as_array().unwrap().len(), 0);

    assert!(get(addr, "/../../etc/passwd").0.contains("404"));
    let post = format!("POST / HTTP/1.1\r\nHost: {addr}\r\nContent-Length: 0\r\n\r\n");
    assert!(request(addr, &post).0.contains("405"));
    let rebinding = "GET /state.json HTTP/1.1\r\nHost: attacker.example:80\r\n\r\n";
    assert!(request(addr, rebinding).0.contains("403"));
}

/// The next event's data line on an open stream.
fn next_event(reader: &mut BufReader<TcpStream>) -> serde_json::Value {
    let mut line = String::new();
    loop {
        line.clear();
        assert!(reader.read_line(&mut line).unwrap() > 0, "the stream ended");
        if let Some(data) = line.strip_prefix("data: ") {
            return serde_json::from_str(data).unwrap();
        }
    }
}

#[test]
fn the_event_stream_sends_the_state_then_every_change() {
    let (server, viewer) = start(8);
    let addr = server.addr();
    let mut s = connect(addr);
    write!(s, "GET /events HTTP/1.1\r\nHost: {addr}\r\n\r\n").unwrap();
    let mut reader = BufReader::new(s);
    let first = next_event(&mut reader);
    assert!(first["plan"].is_null());
    viewer
        .board
        .update(|l| l.plan = Some(Arc::new(Outcome::Failed("infeasible: no grasp".into()))));
    let second = next_event(&mut reader);
    assert_eq!(second["plan"]["error"], "infeasible: no grasp");
    assert!(second["generation"].as_u64() > first["generation"].as_u64());
    // Closing the board (the plugin going away) ends the stream.
    viewer.board.close();
    let mut rest = String::new();
    assert!(reader.read_to_string(&mut rest).is_ok());
}

#[test]
fn connections_beyond_the_limit_get_503_and_a_dropped_server_stops_listening() {
    let (server, _viewer) = start(2);
    let addr = server.addr();
    // Two connections that never send a request hold both places.
    let held = [connect(addr), connect(addr)];
    // The third is answered at once, before it says anything.
    let mut third = connect(addr);
    let mut answer = String::new();
    third.read_to_string(&mut answer).unwrap();
    assert!(answer.starts_with("HTTP/1.1 503"), "{answer}");
    drop(held);
    drop(server);
    assert!(
        TcpStream::connect(addr).is_err(),
        "nothing listens after the drop"
    );
}

/// 16 clients trickle a request head a byte a second — each byte well within the
/// 5 s socket timeout — and so hold all 16 places; each is cut when the head's
/// 5 s deadline passes, and a normal client is then served the page.
#[test]
fn clients_trickling_a_request_head_are_cut_at_its_deadline() {
    const SLOW: usize = 16;
    let (server, _viewer) = start(SLOW);
    let addr = server.addr();
    let started = Instant::now();
    let slow: Vec<_> = (0..SLOW)
        .map(|_| {
            let reader = connect(addr);
            let mut writer = reader.try_clone().unwrap();
            let trickle = std::thread::spawn(move || {
                for b in b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: 1".iter() {
                    if writer.write_all(&[*b]).is_err() {
                        return;
                    }
                    std::thread::sleep(Duration::from_secs(1));
                }
            });
            (reader, trickle)
        })
        .collect();
    // Every place is held: a normal client is refused for now.
    let (status, _) = get(addr, "/");
    assert!(status.starts_with("HTTP/1.1 503"), "{status}");
    let mut cut = vec![];
    for (mut reader, trickle) in slow {
        let mut answer = Vec::new();
        match reader.read_to_end(&mut answer) {
            Ok(_) => assert!(
                answer.is_empty() || answer.starts_with(b"HTTP/1.1 408"),
                "{}",
                String::from_utf8_lossy(&answer)
            ),
            Err(e) => assert_eq!(e.kind(), std::io::ErrorKind::ConnectionReset, "{e}"),
        }
        cut.push(started.elapsed().as_secs_f64());
        trickle.join().unwrap();
    }
    let last = cut.iter().cloned().fold(0.0, f64::max);
    eprintln!("slow clients cut after {:.2}–{last:.2} s", cut[0]);
    assert!(last < 8.0, "the last slow client was cut after {last:.2} s");
    let (status, page) = get(addr, "/");
    assert_eq!(status, "HTTP/1.1 200 OK");
    assert!(!page.is_empty());
}

/// Polls `GET /state.json` until it is served (its place is free), changing
/// the state in 2 KB events ten times a second meanwhile; how long it took.
fn served_after(addr: SocketAddr, viewer: &Viewer, started: Instant, limit: f64) -> f64 {
    let mut k = 0u64;
    loop {
        let elapsed = started.elapsed().as_secs_f64();
        assert!(elapsed < limit, "no place free after {elapsed:.1} s");
        k += 1;
        let why = format!("infeasible: change {k} {}", "x".repeat(2000));
        viewer
            .board
            .update(|l| l.plan = Some(Arc::new(Outcome::Failed(why))));
        if get(addr, "/state.json").0 == "HTTP/1.1 200 OK" {
            return started.elapsed().as_secs_f64();
        }
        // Pacing the changes, not waiting for the result: the loop polls.
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// Waits (polling, with a deadline) until `n` event streams are open.
fn await_streams(viewer: &Viewer, n: u64) {
    let started = Instant::now();
    while viewer.event_clients.load(Ordering::Relaxed) != n {
        assert!(started.elapsed().as_secs() < 10, "{n} streams never open");
        std::thread::yield_now();
    }
}

/// An event stream whose page never reads loses its place once more than its
/// last event has sat unread for 5 s: with the places full, another client is
/// served again soon after (measured from the stream's start, while the state
/// changes ten times a second in 2 KB events). A page reading all along keeps
/// its stream.
#[test]
fn an_event_stream_never_read_loses_its_place_within_its_deadline() {
    let (server, viewer) = start(2);
    let addr = server.addr();
    let mut reading = connect(addr);
    write!(reading, "GET /events HTTP/1.1\r\nHost: {addr}\r\n\r\n").unwrap();
    await_streams(&viewer, 1);
    let reader = std::thread::spawn(move || {
        let (mut reader, mut events) = (BufReader::new(reading), 0u64);
        let mut line = String::new();
        while reader.read_line(&mut line).is_ok_and(|n| n > 0) {
            events += u64::from(line.starts_with("data: "));
            line.clear();
        }
        events
    });
    let mut stalled = connect(addr);
    write!(stalled, "GET /events HTTP/1.1\r\nHost: {addr}\r\n\r\n").unwrap();
    let started = Instant::now();
    await_streams(&viewer, 2);
    assert_eq!(
        get(addr, "/state.json").0,
        "HTTP/1.1 503 Service Unavailable"
    );
    let freed = served_after(addr, &viewer, started, 30.0);
    eprintln!("an unread event stream lost its place after {freed:.2} s");
    // 5 s from the first event not taken, plus one 100 ms check and a poll.
    assert!(freed < 5.6, "the unread stream held its place {freed:.2} s");
    assert_eq!(
        viewer.event_clients.load(Ordering::Relaxed),
        1,
        "the reader was cut"
    );
    viewer.board.close();
    let events = reader.join().unwrap();
    assert!(events > 20, "the reading page got {events} events");
    drop(stalled);
}
