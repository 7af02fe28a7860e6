//! A wrong or absent object is reported as not found, never as a confident pose.

use std::path::PathBuf;

use nalgebra::Point3;
use tsukami_body::files::ModelRoots;
use tsukami_vision::detect::{DetectParams, Detector, Outcome};
use tsukami_vision::sim::testbed::{Clutter, Testbed};

fn setup() -> (Testbed, Detector) {
    let m = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../models");
    let tb = Testbed::new(
        &m.join("scenes/can_waist.toml"),
        "table",
        &m.join("objects"),
    )
    .unwrap();
    (
        tb,
        Detector::new(ModelRoots::new([m]), DetectParams::default()),
    )
}

#[test]
fn empty_table() {
    let (mut tb, mut det) = setup();
    let centre = Point3::new(0.5 * (tb.table.x.0 + tb.table.x.1), -0.2, tb.table.z);
    let q = tb.look_at(&centre);
    let (image, camera) = tb.render(&[], &q, 3).unwrap();
    for object in ["can_350ml", "pet_500ml", "box"] {
        match det.detect(object, &image, &camera).unwrap() {
            Outcome::NotFound(n) => assert!(!n.reason.is_empty()),
            Outcome::Found(d) => panic!("{object} found on an empty table: {d:?}"),
        }
    }
}

#[test]
fn wrong_object() {
    let (mut tb, mut det) = setup();
    for (shown, asked, seed) in [
        ("can_350ml", "pet_500ml", 0),
        // A lying can: the bottle fits its cylinder and sticks out over the
        // table (0.80, just under the threshold, before verification refused
        // models seen through on more than 6 % of their pixels).
        ("can_350ml", "pet_500ml", 108),
        ("can_350ml", "box", 1),
        ("pet_500ml", "box", 1000),
        ("box", "can_350ml", 2000),
        ("box", "pet_500ml", 2001),
    ] {
        let trial = tb.trial(shown, None, 0.0, seed).unwrap();
        match det.detect(asked, &trial.image, &trial.camera).unwrap() {
            Outcome::NotFound(n) => {
                // Well below the 0.8 threshold, not just under it.
                if let Some(best) = n.best {
                    assert!(best.confidence < 0.5, "{asked} in {shown} {seed}: {best:?}");
                }
            }
            Outcome::Found(d) => panic!("{asked} reported in an image of {shown}: {d:?}"),
        }
    }
}

/// A wall behind the table and the floor, nothing on the table: not found,
/// and the message says how wide what it saw is against the object — the
/// nearest-sized cluster when nothing is object-sized, else the cluster the
/// best candidate was fitted to (here a piece of the wall or the floor).
#[test]
fn only_a_wall_says_how_wide_what_it_saw_is() {
    let (mut tb, mut det) = setup();
    let scene = Clutter {
        wall: true,
        floor: true,
        hide_target: true,
        ..Clutter::default()
    };
    let trial = tb.trial_in("can_350ml", None, 0.0, 5, &scene).unwrap();
    match det
        .detect("can_350ml", &trial.image, &trial.camera)
        .unwrap()
    {
        Outcome::NotFound(n) => {
            let r = &n.reason;
            let nothing =
                r.contains("no object-sized cluster") && r.contains("the nearest in size is");
            let piece = r.contains("fitted to a piece of a cluster");
            assert!(nothing || piece, "{r}");
            assert!(r.contains("m wide") && r.contains("0.134 m across"), "{r}");
        }
        Outcome::Found(d) => panic!("a can found on an empty table before a wall: {d:?}"),
    }
}

/// Absent objects asked for among a wall, the legs and distractors.
#[test]
fn absent_objects_among_distractors() {
    let (mut tb, mut det) = setup();
    let scene = Clutter {
        wall: true,
        floor: true,
        distractors: (2, 3),
        pool: ["can_200ml", "vase", "pet_500ml"]
            .map(String::from)
            .to_vec(),
        hide_target: true,
        ..Clutter::default()
    };
    for seed in [20_000, 20_001] {
        let trial = tb.trial_in("can_200ml", None, 0.0, seed, &scene).unwrap();
        for object in ["can_350ml", "box"] {
            match det.detect(object, &trial.image, &trial.camera).unwrap() {
                Outcome::NotFound(n) => assert!(!n.reason.is_empty()),
                Outcome::Found(d) => panic!("{object} reported among distractors ({seed}): {d:?}"),
            }
        }
    }
}
