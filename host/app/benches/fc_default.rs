//! `tsukami fc` on 300 random problems of 3–5 contacts with the default methods
//! (ellipsoid and exact), timed end to end through the real binary — process
//! start, JSON in and out included — against the old default that also ran
//! Ferrari–Canny, on a few of the same problems (that one takes seconds each).
//!
//! `cargo bench -p tsukami --bench fc_default [-- PROBLEMS [FC_PROBLEMS]]`
//!
//! Prints figures; it asserts only that every problem was answered without an
//! error. Target (issue 8): the 300 problems in under 2 s.

use std::io::Write;
use std::process::{Command, Stdio};
use std::time::Instant;

use serde_json::{json, Value};

/// splitmix64: a seeded stream, so every run poses the same problems.
struct Stream(u64);

impl Stream {
    fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A contact on the side or a cap of a 350 ml can (Ø66 × 122 mm), normal inwards.
fn can_contact(s: &mut Stream) -> Value {
    let (r, h) = (0.033, 0.061);
    let a = s.next_f64() * std::f64::consts::TAU;
    if s.next_f64() < 0.8 {
        let z = (2.0 * s.next_f64() - 1.0) * h;
        json!({"position": [r * a.cos(), r * a.sin(), z], "normal": [-a.cos(), -a.sin(), 0.0]})
    } else {
        let rho = r * s.next_f64().sqrt();
        let top = if s.next_f64() < 0.5 { 1.0 } else { -1.0 };
        json!({"position": [rho * a.cos(), rho * a.sin(), top * h], "normal": [0.0, 0.0, -top]})
    }
}

fn problems(count: usize, seed: u64) -> Vec<Value> {
    let mut s = Stream(seed);
    (0..count)
        .map(|i| {
            let contacts: Vec<Value> = (0..3 + i % 3).map(|_| can_contact(&mut s)).collect();
            json!({"contacts": contacts, "mu": 0.2 + 0.8 * s.next_f64(), "f_max": 10.0,
                   "mass": 0.35, "center_of_mass": [0.0, 0.0, 0.0],
                   "characteristic_length": 0.033})
        })
        .collect()
}

/// Runs `tsukami fc` on `input`; the answers and the wall time (s).
fn run_fc(input: &Value) -> (Vec<Value>, f64) {
    let t0 = Instant::now();
    let mut child = Command::new(env!("CARGO_BIN_EXE_tsukami"))
        .arg("fc")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("start tsukami fc");
    let text = input.to_string();
    child
        .stdin
        .take()
        .expect("stdin")
        .write_all(text.as_bytes())
        .expect("write problems");
    let out = child.wait_with_output().expect("tsukami fc");
    let seconds = t0.elapsed().as_secs_f64();
    assert!(out.status.success(), "tsukami fc failed");
    let answers: Value = serde_json::from_slice(&out.stdout).expect("JSON answer");
    (answers.as_array().expect("an array").clone(), seconds)
}

fn sum_ms(answers: &[Value], method: &str) -> f64 {
    answers
        .iter()
        .filter_map(|a| a[method]["time_ns"].as_u64())
        .sum::<u64>() as f64
        / 1e6
}

fn main() {
    let mut args = std::env::args().skip(1).filter(|a| !a.starts_with('-'));
    let count: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(300);
    let fc_count: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(10);
    let set = problems(count, 0x0048_4643_2d66_6300);

    let (answers, total) = run_fc(&Value::Array(set.clone()));
    let errors = answers.iter().filter(|a| a.get("error").is_some()).count();
    assert_eq!(
        (answers.len(), errors),
        (count, 0),
        "every problem answered"
    );
    let closed = answers
        .iter()
        .filter(|a| a["exact"]["force_closure"] == true)
        .count();
    let holding = answers
        .iter()
        .filter(|a| a["exact"]["resists_weight"] == true)
        .count();
    println!("tsukami fc, default methods (ellipsoid + exact), {count} problems of 3-5 contacts on the can:");
    println!(
        "  total {:.3} s ({:.2} ms a problem; target < 2 s) — inside: ellipsoid {:.2} ms, exact {:.1} ms; {closed} closed, {holding} hold the weight",
        total,
        1e3 * total / count as f64,
        sum_ms(&answers, "ellipsoid"),
        sum_ms(&answers, "exact")
    );

    let with_fc: Vec<Value> = set
        .iter()
        .take(fc_count)
        .map(|p| {
            let mut p = p.clone();
            p["methods"] = json!(["ellipsoid", "exact", "ferrari_canny"]);
            p
        })
        .collect();
    let (fc_answers, fc_total) = run_fc(&Value::Array(with_fc));
    let (default_first, default_first_total) =
        run_fc(&Value::Array(set.iter().take(fc_count).cloned().collect()));
    assert_eq!(default_first.len(), fc_count);
    let per = |t: f64| 1e3 * t / fc_count as f64;
    println!(
        "old default (+ ferrari_canny: eps_L1 and eps_Linf), first {fc_count} problems: {:.2} s ({:.0} ms a problem; Ferrari-Canny {:.0} ms of it) vs default on the same {fc_count}: {:.3} s",
        fc_total,
        per(fc_total),
        sum_ms(&fc_answers, "ferrari_canny") / fc_count as f64,
        default_first_total
    );
    println!(
        "  ratio old / new, per problem: {:.0}x; the 300 with the old default would take about {:.0} s",
        per(fc_total) / (1e3 * total / count as f64),
        fc_total / fc_count as f64 * count as f64
    );
}
