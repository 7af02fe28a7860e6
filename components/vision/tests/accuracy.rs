//! Detection accuracy on a few simulated head-camera frames (the full set of
//! 20 poses per object is the `vision` bench): position error < 5 mm and
//! symmetry-aware orientation error < 3° with 1 mm depth noise.

use std::path::PathBuf;

use tsukami_body::files::ModelRoots;
use tsukami_vision::detect::{DetectParams, Detection, Detector, Outcome};
use tsukami_vision::sim::testbed::{Clutter, Testbed, Trial};

fn models() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../models")
}

fn setup() -> (Testbed, Detector) {
    let m = models();
    let tb = Testbed::new(
        &m.join("scenes/can_waist.toml"),
        "table",
        &m.join("objects"),
    )
    .unwrap();
    let det = Detector::new(ModelRoots::new([m]), DetectParams::default());
    (tb, det)
}

fn check(tb: &mut Testbed, det: &mut Detector, object: &str, occluder: Option<&str>, seed: u64) {
    let trial = tb.trial(object, occluder, 0.3, seed).unwrap();
    if occluder.is_some() {
        assert!(
            (trial.occluded - 0.3).abs() < 0.05,
            "occluded {}",
            trial.occluded
        );
    }
    let d = found_within(det, object, seed, &trial);
    assert!(d.confidence >= 0.8 && d.rms < 0.002, "{d:?}");
}

/// The detection of `object` in `trial`, asserted found within 5 mm / 3°.
fn found_within(det: &mut Detector, object: &str, seed: u64, trial: &Trial) -> Detection {
    let sym = det.template(object).unwrap().symmetry.clone();
    match det.detect(object, &trial.image, &trial.camera).unwrap() {
        Outcome::Found(d) => {
            let (dp, da) = sym.pose_error(&d.pose, &trial.truth);
            assert!(
                dp < 0.005 && da.to_degrees() < 3.0,
                "{object} seed {seed}: error {:.2} mm {:.2}°",
                dp * 1e3,
                da.to_degrees()
            );
            d
        }
        Outcome::NotFound(n) => panic!("{object} seed {seed} not found: {}", n.reason),
    }
}

#[test]
fn can_bottle_and_box_alone() {
    let (mut tb, mut det) = setup();
    check(&mut tb, &mut det, "can_350ml", None, 0);
    check(&mut tb, &mut det, "pet_500ml", None, 1000);
    check(&mut tb, &mut det, "box", None, 2000);
}

#[test]
fn occluded_by_a_second_object() {
    let (mut tb, mut det) = setup();
    check(&mut tb, &mut det, "can_350ml", Some("box"), 500);
    check(&mut tb, &mut det, "pet_500ml", Some("box"), 1500);
    check(&mut tb, &mut det, "box", Some("pet_500ml"), 2501);
}

/// Poses the pipeline of 2026-12-01 03:26 missed: a can behind a box whose
/// visible part was judged too large by its distance from the centroid
/// (502), a box whose coarse fits ranked below pieces of the robot's arm
/// (2005), and a box that ICP slid 7 mm along its faces behind a bottle
/// (2500: the visible-surface refinement brings it back).
#[test]
fn poses_missed_before() {
    let (mut tb, mut det) = setup();
    check(&mut tb, &mut det, "can_350ml", Some("box"), 502);
    check(&mut tb, &mut det, "box", None, 2005);
    check(&mut tb, &mut det, "box", Some("pet_500ml"), 2500);
}

/// Before issue 26 a wall behind the table, the legs and the distractors
/// filled the six clusters examined and pushed the target out.
#[test]
fn found_before_a_wall_among_distractors() {
    let (mut tb, mut det) = setup();
    for (object, modes, occluder, seed) in [
        ("can_350ml", &[][..], None, 10_100),
        ("pet_500ml", &[1][..], None, 11_200),
        ("box", &[1][..], None, 12_300),
        ("box", &[2, 3][..], None, 12_201),
        // A bottle fitted to a 2 cm scrap at the image's edge, 0.5 m off, was
        // "confirmed" at 0.98 by the 41 pixels of it inside the image.
        ("pet_500ml", &[][..], Some("box"), 11_316),
    ] {
        let trial = tb
            .trial_in(
                object,
                occluder,
                0.32,
                seed,
                &Clutter::benchmark(true, modes),
            )
            .unwrap();
        assert!(!trial.others.is_empty(), "{object} {seed}: no distractor");
        found_within(&mut det, object, seed, &trial);
    }
}

#[test]
fn symmetric_objects_say_so() {
    let (_, mut det) = setup();
    let can = det.template("can_350ml").unwrap();
    assert!(
        can.symmetry.axis.is_some(),
        "a can is symmetric about its axis"
    );
    let bottle = det.template("pet_500ml").unwrap();
    assert!(bottle.symmetry.axis.is_some());
    assert_eq!(
        bottle.symmetry.discrete.len(),
        1,
        "a bottle has no flip symmetry"
    );
    let boxed = det.template("box").unwrap();
    assert!(boxed.symmetry.axis.is_none());
    assert_eq!(
        boxed.symmetry.discrete.len(),
        4,
        "a box has the 180° turns about its three axes"
    );
}
