//! One simulated trial, detected and explained: a debugging aid for the pipeline.
//!
//! `cargo run --release -p tsukami-vision --example trial -- TARGET [ASKED] [OCCLUDER|-] [SEED] [--save]`
//!
//! Renders TARGET at the random resting pose of SEED on the can_waist table (with
//! OCCLUDER hiding 30 % of it), asks for ASKED (default TARGET), prints the outcome,
//! the error against the truth and the stage timings (`RUST_LOG`-style debug logs on
//! stderr). `--save` writes `/tmp/vis_overlay.png`: the depth image with the true
//! (green) and detected (red) model surfaces drawn over it.

use std::path::PathBuf;
use std::time::Instant;
use tsukami_body::files::ModelRoots;
use tsukami_vision::detect::{DetectParams, Detector, Outcome};
use tsukami_vision::sim::testbed::Testbed;
fn main() {
    tracing_subscriber::fmt()
        .with_max_level(tracing::Level::DEBUG)
        .with_writer(std::io::stderr)
        .init();
    let a: Vec<String> = std::env::args().collect();
    let target = a.get(1).cloned().unwrap_or("can_350ml".into());
    let asked = a.get(2).cloned().unwrap_or(target.clone());
    let occ = a.get(3).filter(|s| *s != "-").cloned();
    let seed: u64 = a.get(4).and_then(|s| s.parse().ok()).unwrap_or(0);
    let models = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../models");
    let mut tb = Testbed::new(
        &models.join("scenes/can_waist.toml"),
        "table",
        &models.join("objects"),
    )
    .unwrap();
    let mut det = Detector::new(ModelRoots::new([models.clone()]), DetectParams::default());
    let sym = det.template(&target).unwrap().symmetry.clone();
    println!(
        "symmetry of {target}: axis {:?} discrete {}",
        sym.axis,
        sym.discrete.len()
    );
    let t = tb.trial(&target, occ.as_deref(), 0.3, seed).unwrap();
    println!(
        "truth {:?} occl {:.2} valid px {}",
        t.truth,
        t.occluded,
        t.image.valid_count()
    );
    for _ in 0..2 {
        let s = Instant::now();
        let out = det.detect(&asked, &t.image, &t.camera).unwrap();
        println!("{:.1} ms", s.elapsed().as_secs_f64() * 1e3);
        match out {
            Outcome::Found(d) => {
                if a.iter().any(|x| x == "--save") {
                    let tpl = det.template(&asked).unwrap();
                    overlay(&t, &tpl.points, &d.pose);
                }
                let (dp, da) = sym.pose_error(&d.pose, &t.truth);
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
                if let (Some(b), true) = (&n.best, a.iter().any(|x| x == "--save")) {
                    let tpl = det.template(&asked).unwrap();
                    overlay(&t, &tpl.points, &b.pose);
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

fn overlay(
    t: &tsukami_vision::sim::testbed::Trial,
    pts: &[nalgebra::Point3<f64>],
    pose: &nalgebra::Isometry3<f64>,
) {
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
