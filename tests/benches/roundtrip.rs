//! Round trip of an empty request from a client through the host into a plugin and
//! back, over zenoh on loopback, beside a bare zenoh get/reply measured in the same
//! run; and the latency of Stop interrupting a running call.
//!
//! Run: `cargo bench -p tsukami-e2e --bench roundtrip`. Prints p50 and p99 of each and
//! the ratio host / bare. Targets: p50 under 300 µs, within 1.5× of bare zenoh; stop
//! within 50 ms.

use std::time::{Duration, Instant};
use tsukami::bus::{free_loopback_port, BusConfig};
use tsukami::client::BusClient;
use tsukami_e2e::{plugin_entry, test_config, TestBus};
use zenoh::Wait;

const SAMPLES: usize = 2_000;
const WARM_UP: usize = 200;
const T: Duration = Duration::from_secs(10);

fn percentile(sorted: &[Duration], p: f64) -> Duration {
    let index = ((sorted.len() as f64 - 1.0) * p).round() as usize;
    sorted[index]
}

fn measure(mut once: impl FnMut()) -> (Duration, Duration) {
    for _ in 0..WARM_UP {
        once();
    }
    let mut times: Vec<Duration> = (0..SAMPLES)
        .map(|_| {
            let start = Instant::now();
            once();
            start.elapsed()
        })
        .collect();
    times.sort();
    (percentile(&times, 0.5), percentile(&times, 0.99))
}

fn us(d: Duration) -> f64 {
    d.as_secs_f64() * 1e6
}

fn main() {
    // Through the host into the `test-slow` fixture plugin's `echo` command.
    let bus = TestBus::start(test_config(vec![plugin_entry(
        "test-slow",
        "tsukami_test_slow",
    )]));
    let (host_p50, host_p99) = measure(|| {
        bus.client
            .command("test-slow", "echo", b"", T)
            .expect("echo reply");
    });

    // Bare zenoh: a queryable on its own peer session that replies with the query's
    // payload, queried by a second session — the same two-sessions-over-loopback path.
    let port = free_loopback_port().unwrap();
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let server = BusConfig::listening(&endpoint).open().unwrap();
    let _echo = server
        .declare_queryable("bare/echo")
        .callback(|query| {
            let payload = query
                .payload()
                .map(|p| p.to_bytes().into_owned())
                .unwrap_or_default();
            let _ = query.reply(query.key_expr().clone(), payload).wait();
        })
        .wait()
        .unwrap();
    let client = BusClient::connect(&BusConfig::connecting(&endpoint), "bare").unwrap();
    while client
        .request_key("bare/echo", b"", Duration::from_millis(200))
        .is_err()
    {}
    let (bare_p50, bare_p99) = measure(|| {
        client.request_key("bare/echo", b"", T).expect("bare reply");
    });

    // Stop latency: from sending Stop to the cancelled reply of a 10 s call.
    let mut stops: Vec<Duration> = (0..20)
        .map(|_| {
            std::thread::scope(|scope| {
                let running = scope.spawn(|| {
                    bus.client
                        .command("test-slow", "work", br#"{"ms": 10000}"#, T)
                });
                // Ask until the call is running (stop answers `stopped: false` before).
                loop {
                    let start = Instant::now();
                    let reply = bus.client.command("test-slow", "stop", b"", T).unwrap();
                    if serde_json::from_slice::<serde_json::Value>(&reply).unwrap()["stopped"]
                        == true
                    {
                        assert!(running.join().unwrap().is_err());
                        break start.elapsed();
                    }
                }
            })
        })
        .collect();
    stops.sort();

    println!(
        "round trip of an empty request, {SAMPLES} samples after {WARM_UP} warm-up, loopback TCP:"
    );
    println!(
        "  {:<34} p50 {:>8.1} µs   p99 {:>8.1} µs",
        "client -> host -> plugin -> client",
        us(host_p50),
        us(host_p99)
    );
    println!(
        "  {:<34} p50 {:>8.1} µs   p99 {:>8.1} µs",
        "bare zenoh get/reply",
        us(bare_p50),
        us(bare_p99)
    );
    println!(
        "  ratio host / bare: p50 {:.2}x   p99 {:.2}x",
        us(host_p50) / us(bare_p50),
        us(host_p99) / us(bare_p99)
    );
    println!(
        "stop -> cancelled reply of a running call (20 samples): p50 {:.2} ms   max {:.2} ms",
        stops[stops.len() / 2].as_secs_f64() * 1e3,
        stops[stops.len() - 1].as_secs_f64() * 1e3
    );
}
