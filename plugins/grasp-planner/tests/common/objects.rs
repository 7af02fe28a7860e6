//! The object benchmark's objects and placements (issue #10), generated
//! procedurally so nothing large is committed: 55 everyday objects in 11 shape
//! families — cans, bottles, mugs whose handle touches the body along an edge
//! (closed but non-manifold), boxes, fruit, spray cans, vases, noisy open
//! "scans", cones (cups, a nearly pointed one), tori lying flat (rings,
//! doughnuts, rolls of tape), and low flat objects (a thin plate among them) —
//! each with a mass, and 5 placements on supports given as obstacles: a 0.78 m
//! table, a 1.00 m counter (rotated), a 0.45 m stool, lying on a 0.72 m table,
//! and an open shelf with a board above.
//!
//! Used by `examples/object_bench.rs` (every case, figures in
//! `docs/benchmarks.md`) and the workspace's `tests/tests/object_subset.rs` (a
//! fixed subset over the bus, checked in every test run). Included with `#[path]`; not every user calls every item.
#![allow(dead_code)]

use std::f64::consts::FRAC_PI_2;

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use serde_json::{json, Value};
use tsukami_body::mesh::TriangleMesh;

/// One benchmark object: its mesh in its own frame (standing on z = 0), mass
/// and family.
pub struct BenchObject {
    /// Unique name, `<family>_<k>`.
    pub name: String,
    /// Shape family.
    pub family: &'static str,
    /// Surface, object frame.
    pub mesh: TriangleMesh,
    /// Mass, kg.
    pub mass: f64,
    /// Low and flat: "lying" turns it about z instead of onto its side.
    pub flat: bool,
}

/// A deterministic value in [-0.5, 0.5) from an index (for scan noise).
fn noise(i: usize, salt: u64) -> f64 {
    let mut x =
        (i as u64 ^ salt.wrapping_mul(0x9E37_79B9_7F4A_7C15)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x ^= x >> 31;
    x = x.wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^= x >> 29;
    (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5
}

fn lathe(profile: &[(f64, f64)]) -> TriangleMesh {
    TriangleMesh::lathe(profile, 32)
}

fn bottle(rb: f64, h: f64) -> TriangleMesh {
    let rn = 0.0135;
    lathe(&[
        (rb, 0.0),
        (rb, 0.6 * h),
        (0.85 * rb, 0.7 * h),
        (0.5 * rb, 0.78 * h),
        (rn, 0.84 * h),
        (rn, 0.9 * h),
        (rn + 0.002, 0.9 * h),
        (rn + 0.002, h),
    ])
}

fn spray(r: f64, h: f64) -> TriangleMesh {
    lathe(&[
        (r, 0.0),
        (r, 0.8 * h),
        (0.85 * r, 0.86 * h),
        (0.45 * r, 0.9 * h),
        (0.3 * r, 0.9 * h),
        (0.3 * r, 0.96 * h),
        (0.25 * r, h),
    ])
}

fn vase(rb: f64, rbody: f64, rneck: f64, rlip: f64, h: f64) -> TriangleMesh {
    lathe(&[
        (rb, 0.0),
        (rbody, 0.3 * h),
        (0.85 * rbody, 0.55 * h),
        (rneck, 0.8 * h),
        (rneck, 0.9 * h),
        (rlip, h),
    ])
}

/// A sphere (or a spheroid stretched `k` times along z) resting on z = 0.
fn fruit(r: f64, k: f64) -> TriangleMesh {
    let mut m = TriangleMesh::uv_sphere(r, 16, 32);
    for v in &mut m.vertices {
        v.z = (v.z + r) * k;
    }
    m
}

/// A box of `size` standing on z = 0.
fn cuboid(size: [f64; 3]) -> TriangleMesh {
    let mut m = TriangleMesh::cuboid(Vector3::from(size));
    for v in &mut m.vertices {
        v.z += size[2] / 2.0;
    }
    m
}

/// A mug: a cylinder body with a wedge-shaped handle that touches the body
/// only along one vertical edge, so that edge has four triangles (closed,
/// non-manifold; the mug had 48 such edges).
pub fn mug(r: f64, h: f64) -> TriangleMesh {
    let (z0, z1) = (0.25 * h, 0.8 * h);
    let mut m = lathe(&[(r, 0.0), (r, z0), (r, z1), (r, h)]);
    // Segment 0 of rings 1 and 2 lies at angle 0: (r, 0, z0) and (r, 0, z1).
    let seg = 32u32;
    let (p0, p1) = (seg, 2 * seg);
    let n = m.vertices.len() as u32;
    let (out, w) = (0.035, 0.008);
    for z in [z0, z1] {
        m.vertices.push(Point3::new(r + out, -w, z));
        m.vertices.push(Point3::new(r + out, w, z));
    }
    let (a0, b0, a1, b1) = (n, n + 1, n + 2, n + 3);
    // Wedge: bottom (p0, a0, b0), top (p1, b1, a1), three sides; outward.
    m.indices.extend([
        [p0, b0, a0],
        [p1, a1, b1],
        [a0, b0, b1],
        [a0, b1, a1],
        [p0, a0, a1],
        [p0, a1, p1],
        [b0, p0, p1],
        [b0, p1, b1],
    ]);
    m
}

/// A scan-like mesh: `base` with radial noise of ±`amp` m and its bottom cap
/// removed (open: scanners do not see the side an object stands on); with
/// `miswound`, every seventh triangle is wound the wrong way too.
pub fn scan(mut base: TriangleMesh, amp: f64, salt: u64, miswound: bool) -> TriangleMesh {
    let bottom = base.vertices.len() as u32 - 2; // lathe: bottom centre, top centre
    base.indices.retain(|t| !t.contains(&bottom));
    for (i, v) in base.vertices.iter_mut().enumerate() {
        let radial = Vector3::new(v.x, v.y, 0.0);
        if radial.norm() > 1e-9 {
            v.coords += radial.normalize() * amp * 2.0 * noise(i, salt);
        }
    }
    for (k, t) in base.indices.iter_mut().enumerate() {
        if miswound && k % 7 == 3 {
            t.swap(1, 2);
        }
    }
    base
}

/// The 55 objects.
pub fn objects() -> Vec<BenchObject> {
    let mut out = Vec::new();
    let mut add = |family: &'static str, mesh: TriangleMesh, mass: f64, flat: bool| {
        let k = out
            .iter()
            .filter(|o: &&BenchObject| o.family == family)
            .count();
        out.push(BenchObject {
            name: format!("{family}_{k}"),
            family,
            mesh,
            mass,
            flat,
        });
    };
    for (r, h, m) in [
        (0.026, 0.09, 0.2),
        (0.033, 0.122, 0.35),
        (0.0285, 0.135, 0.25),
        (0.038, 0.11, 0.3),
        (0.042, 0.07, 0.2),
    ] {
        add("can", TriangleMesh::cylinder(r, h, 32), m, false);
    }
    for (r, h, m) in [
        (0.028, 0.16, 0.3),
        (0.032, 0.2, 0.5),
        (0.035, 0.23, 0.55),
        (0.04, 0.25, 0.6),
        (0.03, 0.18, 0.35),
    ] {
        add("bottle", bottle(r, h), m, false);
    }
    for (r, h, m) in [
        (0.035, 0.09, 0.3),
        (0.04, 0.095, 0.35),
        (0.042, 0.1, 0.35),
        (0.038, 0.085, 0.3),
        (0.045, 0.11, 0.4),
    ] {
        add("mug", mug(r, h), m, false);
    }
    for (s, m) in [
        ([0.06, 0.04, 0.10], 0.2),
        ([0.05, 0.05, 0.05], 0.1),
        ([0.07, 0.045, 0.14], 0.25),
        ([0.055, 0.055, 0.19], 0.3),
        ([0.09, 0.06, 0.12], 0.2),
    ] {
        add("box", cuboid(s), m, false);
    }
    for (r, k, m) in [
        (0.03, 1.0, 0.1),
        (0.035, 1.0, 0.15),
        (0.04, 1.0, 0.2),
        (0.045, 0.9, 0.25),
        (0.028, 1.35, 0.12),
    ] {
        add("fruit", fruit(r, k), m, false);
    }
    for (r, h, m) in [
        (0.026, 0.15, 0.2),
        (0.029, 0.18, 0.25),
        (0.033, 0.2, 0.3),
        (0.03, 0.16, 0.25),
        (0.0325, 0.22, 0.35),
    ] {
        add("spray", spray(r, h), m, false);
    }
    for (rb, rbody, rneck, rlip, h, m) in [
        (0.03, 0.045, 0.02, 0.03, 0.18, 0.3),
        (0.035, 0.05, 0.022, 0.035, 0.2, 0.35),
        (0.025, 0.04, 0.018, 0.028, 0.16, 0.25),
        (0.04, 0.055, 0.025, 0.04, 0.22, 0.4),
        (0.03, 0.042, 0.03, 0.036, 0.15, 0.25),
    ] {
        add("vase", vase(rb, rbody, rneck, rlip, h), m, false);
    }
    let scans = [
        TriangleMesh::cylinder(0.033, 0.12, 48),
        bottle(0.032, 0.2),
        spray(0.03, 0.17),
        vase(0.03, 0.045, 0.02, 0.03, 0.18),
        TriangleMesh::cylinder(0.04, 0.1, 48),
    ];
    for (k, base) in scans.into_iter().enumerate() {
        add("scan", scan(base, 0.0008, k as u64, false), 0.3, false);
    }
    for (rb, rt, h, m) in [
        (0.035, 0.02, 0.12, 0.2),
        (0.03, 0.004, 0.1, 0.12),
        (0.025, 0.042, 0.11, 0.15),
        (0.045, 0.03, 0.09, 0.25),
        (0.02, 0.035, 0.15, 0.2),
    ] {
        add("cone", lathe(&[(rb, 0.0), (rt, h)]), m, false);
    }
    for (big, r, m) in [
        (0.035, 0.012, 0.1),
        (0.04, 0.015, 0.15),
        (0.03, 0.01, 0.08),
        (0.045, 0.02, 0.25),
        (0.05, 0.012, 0.12),
    ] {
        add("torus", TriangleMesh::torus(big, r, 48, 16), m, true);
    }
    add("low", cuboid([0.10, 0.07, 0.025]), 0.15, true);
    add("low", TriangleMesh::cylinder(0.042, 0.035, 32), 0.18, true);
    add("low", TriangleMesh::cylinder(0.05, 0.02, 32), 0.12, true);
    add("low", cuboid([0.09, 0.06, 0.03]), 0.12, true);
    add(
        "low",
        lathe(&[(0.045, 0.0), (0.03, 0.05), (0.012, 0.06)]),
        0.1,
        true,
    );
    out
}

/// Where an object is put: a support (and neighbours) as obstacles, a spot, and
/// how the object is turned.
pub struct Placement {
    /// Short name.
    pub name: &'static str,
    /// Height of the support's top face (m).
    pub top: f64,
    /// Object position (x, y) on it.
    pub xy: [f64; 2],
    /// Rotation about z after lying down (rad).
    pub yaw: f64,
    /// On its side (flat objects: turned 90° about z instead).
    pub lying: bool,
    /// The obstacles, as `set_env` JSON.
    pub obstacles: Value,
}

fn box_obstacle(name: &str, size: [f64; 3], at: [f64; 3]) -> Value {
    json!({"name": name, "shape": {"box": {"size": size}}, "pose": {"position": at}})
}

/// A table top of `w` × `d` at height `top` centred at (x, y), with 4 legs.
fn table(name: &str, top: f64, x: f64, y: f64, d: f64, w: f64) -> Vec<Value> {
    let mut v = vec![box_obstacle(name, [d, w, 0.03], [x, y, top - 0.015])];
    for (i, (sx, sy)) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)]
        .iter()
        .enumerate()
    {
        v.push(box_obstacle(
            &format!("{name}_leg{i}"),
            [0.04, 0.04, top - 0.03],
            [
                x + sx * (d / 2.0 - 0.03),
                y + sy * (w / 2.0 - 0.03),
                (top - 0.03) / 2.0,
            ],
        ));
    }
    v
}

/// The 5 placements.
pub fn placements() -> Vec<Placement> {
    vec![
        Placement {
            name: "table_0.78",
            top: 0.78,
            xy: [0.42, -0.25],
            yaw: 0.0,
            lying: false,
            obstacles: json!(table("table", 0.78, 0.61, -0.20, 0.5, 1.0)),
        },
        Placement {
            name: "counter_1.00_rotated",
            top: 1.00,
            xy: [0.50, -0.25],
            yaw: 0.7,
            lying: false,
            obstacles: json!([box_obstacle(
                "counter",
                [0.45, 1.0, 1.0],
                [0.68, -0.20, 0.5]
            )]),
        },
        Placement {
            name: "stool_0.45",
            top: 0.45,
            xy: [0.45, -0.25],
            yaw: 0.0,
            lying: false,
            obstacles: json!(table("stool", 0.45, 0.55, -0.25, 0.35, 0.35)),
        },
        Placement {
            name: "table_0.72_lying",
            top: 0.72,
            xy: [0.42, -0.22],
            yaw: 0.3,
            lying: true,
            obstacles: json!(table("table", 0.72, 0.64, -0.20, 0.6, 1.0)),
        },
        Placement {
            name: "shelf_0.60",
            top: 0.60,
            xy: [0.50, -0.25],
            yaw: 0.0,
            lying: false,
            obstacles: json!([
                box_obstacle("shelf", [0.36, 0.8, 0.02], [0.62, -0.25, 0.59]),
                box_obstacle("shelf_above", [0.36, 0.8, 0.02], [0.62, -0.25, 0.97]),
                box_obstacle("shelf_back", [0.02, 0.8, 0.6], [0.81, -0.25, 0.75]),
                box_obstacle("shelf_side", [0.36, 0.02, 0.4], [0.62, 0.16, 0.78]),
            ]),
        },
    ]
}

/// The object's pose for a placement: turned, then moved so that its lowest
/// point rests on the support and its box centre is over the spot.
pub fn object_pose(o: &BenchObject, p: &Placement) -> Isometry3<f64> {
    let turn = match (p.lying, o.flat) {
        (false, _) => UnitQuaternion::identity(),
        (true, false) => UnitQuaternion::from_axis_angle(&Vector3::x_axis(), FRAC_PI_2),
        (true, true) => UnitQuaternion::from_axis_angle(&Vector3::z_axis(), FRAC_PI_2),
    };
    let rot = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), p.yaw) * turn;
    let (mut lo, mut hi) = (
        Vector3::repeat(f64::INFINITY),
        Vector3::repeat(f64::NEG_INFINITY),
    );
    for v in &o.mesh.vertices {
        let w = rot * v.coords;
        lo = lo.inf(&w);
        hi = hi.sup(&w);
    }
    let centre = (lo + hi) / 2.0;
    let t = Vector3::new(p.xy[0] - centre.x, p.xy[1] - centre.y, p.top - lo.z + 1e-4);
    Isometry3::from_parts(Translation3::from(t), rot)
}

/// The `set_object` request of `o` at `p`, the mesh being at `path`. Closed
/// meshes take the default centre of mass (the enclosed volume's centroid,
/// which the checker computes the same way); open scans state theirs (the box
/// centre), so planner and checker agree on it.
pub fn set_object(o: &BenchObject, p: &Placement, path: &str) -> Value {
    let pose = object_pose(o, p);
    let q = pose.rotation.coords;
    let mut req = json!({
        "name": o.name,
        "shape": {"mesh": {"path": path}},
        "mass": o.mass,
        "pose": {"position": pose.translation.vector.as_slice(), "quaternion": [q.x, q.y, q.z, q.w]},
    });
    if o.family == "scan" {
        let (lo, hi) = o.mesh.aabb();
        let c = nalgebra::center(&lo, &hi);
        req["center_of_mass"] = json!([c.x, c.y, c.z]);
    }
    req
}

/// The requests of one benchmark case: object `object` (by name) at placement
/// `placement` (by name), its mesh written as `<object>.stl` under `dir`; the
/// `set_object` and `set_env` requests. Panics on an unknown name (tests only).
pub fn case_requests(object: &str, placement: &str, dir: &std::path::Path) -> (Value, Value) {
    let o = objects().into_iter().find(|o| o.name == object).unwrap();
    let p = placements()
        .into_iter()
        .find(|p| p.name == placement)
        .unwrap();
    let path = dir.join(format!("{object}.stl"));
    o.mesh.write_stl(&path).unwrap();
    (set_object(&o, &p, &path.display().to_string()), set_env(&p))
}

/// The `set_env` request of a placement.
pub fn set_env(p: &Placement) -> Value {
    json!({"obstacles": p.obstacles, "replace": true})
}

/// A 350 ml can (r = 33 mm, h = 122 mm) of about `triangles` triangles: rings
/// every few millimetres like a scan's (for the size figures).
pub fn can_with(triangles: usize) -> TriangleMesh {
    let segments = ((triangles as f64).sqrt() * 1.0).round().max(8.0) as usize;
    let bands = (triangles / (2 * segments)).saturating_sub(1).max(1);
    let profile: Vec<(f64, f64)> = (0..=bands)
        .map(|k| (0.033, 0.122 * k as f64 / bands as f64))
        .collect();
    TriangleMesh::lathe(&profile, segments)
}

/// A sphere of about `triangles` triangles (for the size figures).
pub fn sphere_with(triangles: usize, r: f64) -> TriangleMesh {
    let rings = ((triangles as f64 / 4.0).sqrt().floor() + 1.0).max(3.0) as usize;
    let mut m = TriangleMesh::uv_sphere(r, rings, 2 * rings);
    for v in &mut m.vertices {
        v.z += r;
    }
    m
}
