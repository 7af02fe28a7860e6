//! Issue #24 item 5: the object's regions (its OCPs) do not jump when the
//! object moves a little. Every benchmark object and the shipped vase, bottle,
//! can and box, standing, lying and lying turned, are moved in small steps (0.1 µm, then 0.1 mm
//! steps up to 1 mm along each axis; tilts of 0.01° steps up to 0.1° about two
//! horizontal axes; small turns about the vertical) and their regions, taken
//! back to the object's frame, are compared with the unmoved ones and with the
//! step before: the same number of regions, each box's centre and sizes within
//! a tolerance far below one slice of the profile.

#[path = "common/objects.rs"]
mod objects;

use std::path::Path;

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use tsukami_body::mesh::TriangleMesh;
use tsukami_grasp_planner::ocp::{object_ocps, Ocp, OcpParams};

/// A region as seen from the object's frame: centre and sorted sizes.
#[derive(Debug, Clone)]
struct Region {
    centre: Vector3<f64>,
    sizes: [f64; 3],
}

fn regions(mesh: &TriangleMesh, pose: &Isometry3<f64>) -> Vec<Region> {
    let v: Vec<Point3<f64>> = mesh.vertices.iter().map(|p| pose * p).collect();
    let ocps: Vec<Ocp> = object_ocps(&v, &mesh.indices, &OcpParams::default());
    ocps.iter()
        .map(|o| {
            let mut sizes = [o.extents.x, o.extents.y, o.extents.z];
            sizes.sort_by(f64::total_cmp);
            Region {
                centre: (pose.inverse() * o.center).coords,
                sizes,
            }
        })
        .collect()
}

/// The largest difference between two region sets, or why they cannot be compared.
fn difference(a: &[Region], b: &[Region]) -> Result<f64, String> {
    if a.len() != b.len() {
        return Err(format!("{} regions became {}", a.len(), b.len()));
    }
    // Each region against the nearest one of the other set.
    let mut worst = 0.0f64;
    let mut left: Vec<&Region> = b.iter().collect();
    for x in a {
        let nearest = (0..left.len())
            .min_by(|&i, &j| {
                let d = |r: &Region| (r.centre - x.centre).norm();
                d(left[i]).total_cmp(&d(left[j]))
            })
            .expect("as many regions in both");
        let y = left.swap_remove(nearest);
        worst = worst.max((x.centre - y.centre).norm());
        for k in 0..3 {
            worst = worst.max((x.sizes[k] - y.sizes[k]).abs());
        }
    }
    Ok(worst)
}

/// How far a region may move per radian of tilt, in object sizes: a box that
/// stays about the vertical while the object under it turns is refitted to
/// the turned surface, and its sizes and centre follow at several times the
/// surface's own motion. A slice of the profile is 1/32 of the object, so a
/// region boundary jumping by one slice exceeds this at every step.
const TILT_SLOPE: f64 = 10.0;

/// What a turned object's box may change at once (m): the tightest box around
/// a polygonal outline lies along one of its edges, and moves to the next edge
/// when the outline turns, which changes its sizes by up to r·(1 − cos(π/n)):
/// 0.3 mm for a 32-sided mug of 62 mm radius.
const EDGE_TURN: f64 = 5e-4;

/// One small move, and how far it may move a region (m): against the unmoved
/// object, and against the step before.
type Move = (String, Isometry3<f64>, f64, f64);

/// Runs of small moves, each run in growing steps from the unmoved object.
/// A region may move by the move itself plus, for a tilt, as much again for a
/// box refitted to the turned surface.
fn moves(centre: Vector3<f64>, size: f64) -> Vec<Vec<Move>> {
    let mut out = Vec::new();
    for (name, dir) in [
        ("x", Vector3::x()),
        ("y", Vector3::y()),
        ("z", Vector3::z()),
    ] {
        let mut run: Vec<Move> = vec![(
            format!("{name} +0.1 µm"),
            Translation3::from(dir * 1e-7).into(),
            1e-4,
            1e-4,
        )];
        for k in 1..=10 {
            let d = 1e-4 * k as f64;
            run.push((
                format!("{name} +{:.1} mm", d * 1e3),
                Translation3::from(dir * d).into(),
                1e-4,
                1e-4,
            ));
        }
        out.push(run);
    }
    let about = |axis: Vector3<f64>, deg: f64| -> Isometry3<f64> {
        let r = UnitQuaternion::from_scaled_axis(axis * deg.to_radians());
        // About the object's centre.
        Translation3::from(centre) * r * Translation3::from(-centre)
    };
    for (name, axis) in [
        ("x", Vector3::x()),
        ("y", Vector3::y()),
        ("z", Vector3::z()),
    ] {
        let run = (1..=10)
            .map(|k| {
                let deg = 0.01 * k as f64;
                let tol = EDGE_TURN + TILT_SLOPE * size * deg.to_radians();
                let step = EDGE_TURN + TILT_SLOPE * size * 0.01f64.to_radians();
                (
                    format!("turn about {name} {deg:.2}°"),
                    about(axis, deg),
                    tol,
                    step,
                )
            })
            .collect();
        out.push(run);
    }
    out
}

/// Checks one object in one pose; returns the failures.
fn check(name: &str, mesh: &TriangleMesh, base: Isometry3<f64>) -> Vec<String> {
    let (mut lo, mut hi) = (
        Vector3::repeat(f64::INFINITY),
        Vector3::repeat(f64::NEG_INFINITY),
    );
    for p in &mesh.vertices {
        let w = (base * p).coords;
        lo = lo.inf(&w);
        hi = hi.sup(&w);
    }
    let (centre, size) = ((lo + hi) / 2.0, (hi - lo).max());
    let reference = regions(mesh, &base);
    let mut failures = Vec::new();
    for run in moves(centre, size) {
        let mut previous = reference.clone();
        for (what, m, tol, step) in run {
            let now = regions(mesh, &(m * base));
            let against = [
                ("the unmoved object", &reference, tol),
                ("the step before", &previous, step),
            ];
            for (whom, was, allowed) in against {
                match difference(was, &now) {
                    Ok(d) if d <= allowed => {}
                    Ok(d) => failures.push(format!(
                        "{name}: {what} moved a region by {:.2} mm against {whom} (allowed {:.2} mm)",
                        d * 1e3,
                        allowed * 1e3
                    )),
                    Err(e) => failures.push(format!("{name}: {what}: {e} against {whom}")),
                }
            }
            previous = now;
        }
    }
    failures
}

#[test]
fn regions_move_continuously_with_the_object() {
    let mut cases: Vec<(String, TriangleMesh)> = objects::objects()
        .into_iter()
        .map(|o| (o.name, o.mesh))
        .collect();
    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/objects");
    for name in ["vase", "pet_500ml", "can_350ml", "box"] {
        let o = tsukami_body::object::ObjectModel::load(&models.join(name).join("object.toml"))
            .expect("the shipped object loads");
        cases.push((format!("model {name}"), o.mesh));
    }
    let standing = Isometry3::translation(0.55, -0.1, 0.78);
    let on_side = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2);
    let lying = standing * on_side;
    let turned = standing * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.52) * on_side;
    let mut failures = Vec::new();
    let mut checked = 0;
    for (name, mesh) in &cases {
        let poses = [
            ("standing", standing),
            ("lying", lying),
            ("lying turned 30°", turned),
        ];
        for (pose_name, pose) in poses {
            failures.extend(check(&format!("{name} {pose_name}"), mesh, pose));
            checked += 1;
        }
    }
    assert!(checked >= 170, "{checked} cases");
    assert!(
        failures.is_empty(),
        "{} of the moves changed the regions:\n{}",
        failures.len(),
        failures.join("\n")
    );
}
