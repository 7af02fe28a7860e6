//! One simulated trial, detected and explained: a debugging aid for the pipeline.
//!
//! `cargo run --release -p tsukami-vision --example trial -- TARGET [ASKED] [OCCLUDER|-] [SEED|FROM..TO] [--save] [--clusters [GAP]]`
//!
//! With a seed range `FROM..TO` it prints one line per seed (outcome, errors,
//! confidence, time, reason) and no debug logs. Otherwise it renders TARGET at
//! the random resting pose of SEED on the can_waist table (with OCCLUDER hiding
//! 30 % of it), asks for ASKED (default TARGET), and prints the outcome, the
//! error against the truth, the visible-surface objective of the truth and of
//! the detection and along the model's axes around it, and the stage timings
//! (debug logs on stderr; `REPEAT=n` detects n times, default 2). `--save`
//! writes `/tmp/vis_overlay.png`: the depth image with the true (green) and
//! detected (red) model surfaces drawn over it. `--clusters` writes
//! `/tmp/vis_clusters.png`, the clusters of the strided cloud (gap GAP m,
//! default 0.012), and prints their sizes. `CLUTTER=1` renders the
//! benchmark's noisy clutter (wall, floor, 1–3 distractors, σ 1–3 mm, dropout
//! 0.5–3 %) around the target; `OCCL=f` hides `f` of it instead of 30 %,
//! `MODES=i,j` keeps the target in those resting modes.

use std::path::PathBuf;
use std::time::Instant;
use tsukami_body::files::ModelRoots;
use tsukami_vision::detect::{DetectParams, Detector, Outcome};
use tsukami_vision::sim::testbed::{Clutter, Testbed, Trial};

/// The trial of `seed`, in the benchmark's noisy clutter when `CLUTTER=1`.
fn draw(tb: &mut Testbed, target: &str, occ: Option<&str>, seed: u64) -> Trial {
    let clutter = if std::env::var("CLUTTER").is_ok_and(|v| v == "1") {
        let modes: Vec<usize> = std::env::var("MODES")
            .ok()
            .map(|m| m.split(',').filter_map(|i| i.parse().ok()).collect())
            .unwrap_or_default();
        Clutter::benchmark(true, &modes)
    } else {
        Clutter::default()
    };
    let occlusion = std::env::var("OCCL")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0.3);
    tb.trial_in(target, occ, occlusion, seed, &clutter).unwrap()
}
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let target = a.get(1).cloned().unwrap_or("can_350ml".into());
    let asked = a.get(2).cloned().unwrap_or(target.clone());
    let occ = a.get(3).filter(|s| *s != "-").cloned();
    if let Some((from, to)) = a.get(4).and_then(|s| s.split_once("..")) {
        let range = from.parse::<u64>().unwrap()..to.parse::<u64>().unwrap();
        return sweep(&target, &asked, occ.as_deref(), range);
    }
    tracing_subscriber::fmt()
        .with_max_level(tracing::Level::DEBUG)
        .with_writer(std::io::stderr)
        .init();
    let seed: u64 = a.get(4).and_then(|s| s.parse().ok()).unwrap_or(0);
    let (mut tb, mut det) = setup();
    let sym = det.template(&target).unwrap().symmetry.clone();
    println!(
        "symmetry of {target}: axis {:?} discrete {}",
        sym.axis,
        sym.discrete.len()
    );
    let t = draw(&mut tb, &target, occ.as_deref(), seed);
    println!(
        "truth {:?} occl {:.2} valid px {}",
        t.truth,
        t.occluded,
        t.image.valid_count()
    );
    if let Some(i) = a.iter().position(|x| x == "--clusters") {
        clusters_png(
            &t,
            a.get(i + 1).and_then(|g| g.parse().ok()).unwrap_or(0.012),
        );
    }
    let repeat = std::env::var("REPEAT")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(2);
    for _ in 0..repeat {
        let s = Instant::now();
        let out = det.detect(&asked, &t.image, &t.camera).unwrap();
        println!("{:.1} ms", s.elapsed().as_secs_f64() * 1e3);
        match out {
            Outcome::Found(d) => {
                if a.iter().any(|x| x == "--save") {
                    let tpl = det.template(&asked).unwrap();
                    overlay(&t, &tpl.points, &d.pose);
                }
                let tpl = det.template(&asked).unwrap();
                let sp = tsukami_vision::freespace::SettleParams::default();
                for (name, pose) in [("truth", t.truth), ("found", d.pose)] {
                    let v = tsukami_vision::verify::pixel_counts(
                        &tpl, &pose, &t.image, &t.camera, &sp.verify,
                    );
                    println!("{name}: {v:?}");
                }
                let (dp, da) = sym.pose_error(&d.pose, &t.truth);
                let c = tpl.moments.centroid;
                let dc = d.pose * c - t.truth * c;
                println!("centroid error {:?}", dc);
                for i in 0..3 {
                    let ax = d.pose.rotation * tpl.moments.axes.column(i).into_owned();
                    let line: Vec<String> = [-6.0, -4.0, -2.0, 0.0, 2.0, 4.0, 6.0]
                        .iter()
                        .map(|mm| {
                            let p = nalgebra::Translation3::from(ax * (mm * 1e-3)) * d.pose;
                            let v = tsukami_vision::verify::pixel_counts(
                                &tpl, &p, &t.image, &t.camera, &sp.verify,
                            );
                            format!(
                                "{mm}:{:.0}",
                                v.supported as f64
                                    - v.violations as f64
                                    - v.near_misses as f64
                                    - 0.5 * v.unmeasured as f64
                            )
                        })
                        .collect();
                    println!(
                        "axis {i} {:?} (err along {:.2} mm): {}",
                        ax,
                        dc.dot(&ax) * 1e3,
                        line.join(" ")
                    );
                }
                println!(
                    "FOUND pose {:?}\n err {:.2} mm {:.2} deg rms {:.4} conf {:.3} {:?}",
                    d.pose,
                    dp * 1e3,
                    da.to_degrees(),
                    d.rms,
                    d.confidence,
                    d.verdict
                );
            }
            Outcome::NotFound(n) => {
                if a.iter().any(|x| x == "--save") {
                    let tpl = det.template(&asked).unwrap();
                    overlay(
                        &t,
                        &tpl.points,
                        &n.best.as_ref().map_or(t.truth, |b| b.pose),
                    );
                }
                println!(
                    "NOT FOUND: {} best {:?}",
                    n.reason,
                    n.best.map(|b| (b.pose, b.verdict))
                )
            }
        }
    }
    if a.iter().any(|x| x == "--save") {
        t.image
            .save(std::path::Path::new("/tmp/vis_debug.png"))
            .unwrap();
    }
}

/// The can_waist testbed and a detector with the default settings.
fn setup() -> (Testbed, Detector) {
    let models = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../models");
    let tb = Testbed::new(
        &models.join("scenes/can_waist.toml"),
        "table",
        &models.join("objects"),
    )
    .unwrap();
    let det = Detector::new(ModelRoots::new([models]), DetectParams::default());
    (tb, det)
}

/// One line per seed of `range`.
fn sweep(target: &str, asked: &str, occ: Option<&str>, range: std::ops::Range<u64>) {
    let (mut tb, mut det) = setup();
    let sym = det.template(target).unwrap().symmetry.clone();
    let (mut within, mut n) = (0, 0);
    for seed in range {
        let t = draw(&mut tb, target, occ, seed);
        let s = Instant::now();
        let out = det.detect(asked, &t.image, &t.camera).unwrap();
        let ms = s.elapsed().as_secs_f64() * 1e3;
        let tilt = (t.truth.rotation * nalgebra::Vector3::z()).z;
        n += 1;
        match out {
            Outcome::Found(d) => {
                let (dp, da) = sym.pose_error(&d.pose, &t.truth);
                let ok = dp < 0.005 && da.to_degrees() < 3.0;
                within += usize::from(ok);
                println!(
                    "seed {seed:>5} {} err {:6.2} mm {:6.2}° conf {:.3} occl {:.2} up·z {tilt:+.2} {ms:6.1} ms seen-through {:.3}",
                    if ok { "ok  " } else { "BAD " },
                    dp * 1e3,
                    da.to_degrees(),
                    d.confidence,
                    t.occluded,
                    d.verdict.seen_through()
                );
            }
            Outcome::NotFound(nf) => {
                let err = nf.best.as_ref().map(|b| {
                    let (dp, da) = sym.pose_error(&b.pose, &t.truth);
                    format!("best err {:.1} mm {:.1}°", dp * 1e3, da.to_degrees())
                });
                println!(
                    "seed {seed:>5} MISS occl {:.2} up·z {tilt:+.2} {ms:6.1} ms {} | {}",
                    t.occluded,
                    err.unwrap_or_default(),
                    nf.reason
                );
            }
        }
    }
    println!("within 5 mm / 3°: {within}/{n}");
}

fn overlay(t: &Trial, pts: &[nalgebra::Point3<f64>], pose: &nalgebra::Isometry3<f64>) {
    let (w, h) = (t.image.width(), t.image.height());
    let mut rgb = vec![0u8; (w * h * 3) as usize];
    for (i, d) in t.image.data().iter().enumerate() {
        let g = if *d > 0.0 {
            (255.0 * (1.0 - ((*d - 0.5) / 1.5).clamp(0.0, 1.0))) as u8
        } else {
            0
        };
        rgb[i * 3] = g;
        rgb[i * 3 + 1] = g;
        rgb[i * 3 + 2] = g;
    }
    for (pose, c) in [(t.truth, 1usize), (*pose, 0usize)] {
        for p in pts.iter().step_by(3) {
            if let Some((u, v)) = t.camera.pixel_of(&(pose * p)) {
                rgb[((v * w + u) * 3) as usize + c] = 255;
            }
        }
    }
    let f = std::fs::File::create("/tmp/vis_overlay.png").unwrap();
    let mut e = png::Encoder::new(f, w, h);
    e.set_color(png::ColorType::Rgb);
    e.set_depth(png::BitDepth::Eight);
    e.write_header().unwrap().write_image_data(&rgb).unwrap();
}

/// Writes `/tmp/vis_clusters.png`: the off-plane clusters of the strided cloud, one colour each.
pub fn clusters_png(t: &Trial, gap: f64) {
    use tsukami_vision::cloud::PointCloud;
    let p = DetectParams::default();
    let cloud = PointCloud::from_depth(&t.image, &t.camera, p.stride);
    let planes = tsukami_vision::plane::find_planes(&cloud.points, &p.plane);
    let w = t.image.width();
    let s = p.stride;
    let gw = w.div_ceil(s) as usize;
    let gh = t.image.height().div_ceil(s) as usize;
    let mut grid = vec![None; gw * gh];
    let mut inpl = vec![false; cloud.len()];
    for pl in &planes {
        for &i in &pl.inliers {
            inpl[i] = true;
        }
    }
    for (i, (pt, px)) in cloud.points.iter().zip(&cloud.pixels).enumerate() {
        if !inpl[i] {
            grid[(px / w / s) as usize * gw + (px % w / s) as usize] = Some(*pt);
        }
    }
    let cl = tsukami_vision::cluster::clusters(&grid, gw, gap, 25);
    let mut rgb = vec![40u8; gw * gh * 3];
    let colours = [
        [255, 0, 0],
        [0, 255, 0],
        [0, 0, 255],
        [255, 255, 0],
        [255, 0, 255],
        [0, 255, 255],
    ];
    for (k, c) in cl.iter().enumerate() {
        for &i in c {
            rgb[i * 3..i * 3 + 3].copy_from_slice(&colours[k % 6]);
        }
        let pts: Vec<_> = c.iter().filter_map(|&i| grid[i]).collect();
        let m = tsukami_vision::cloud::Moments::of(&pts).unwrap();
        let ext = pts
            .iter()
            .map(|q| (q - m.centroid).norm())
            .fold(0.0, f64::max);
        println!(
            "cluster {k}: {} points, extent {:.3} m, centroid {:?}",
            c.len(),
            ext,
            m.centroid
        );
    }
    let f = std::fs::File::create("/tmp/vis_clusters.png").unwrap();
    let mut e = png::Encoder::new(f, gw as u32, gh as u32);
    e.set_color(png::ColorType::Rgb);
    e.set_depth(png::BitDepth::Eight);
    e.write_header().unwrap().write_image_data(&rgb).unwrap();
}
