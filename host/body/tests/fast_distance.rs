//! The closed-form ball/capsule-vs-mesh path ([`DistanceMethod::Fast`])
//! against parry's general path ([`DistanceMethod::Parry`]) and against brute
//! force over every triangle, on random poses: separated, near contact,
//! penetrating and inside closed meshes, and on an open mesh.

mod common;

use nalgebra::{Isometry3, Point3, Unit, Vector3};
use parry3d_f64::query::PointQuery;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use tsukami_body::collision::{CollisionObject, DistanceMethod, Proximity, RobotCollision};
use tsukami_body::convert::{to_pose, to_vec, to_vector};
use tsukami_body::kinematics::FkState;
use tsukami_body::mesh::TriangleMesh;
use tsukami_body::RobotModel;

/// A one-link robot whose link carries `geometry`, with both narrow phases.
fn probe(geometry: &str) -> (RobotModel, RobotCollision, RobotCollision) {
    let xml = format!(
        r#"<robot name="probe"><link name="probe"><collision><origin xyz="0.001 -0.002 0.003" rpy="0.3 -0.2 0.1"/><geometry>{geometry}</geometry></collision></link></robot>"#
    );
    let m = RobotModel::from_urdf_str(&xml, std::path::Path::new("/tmp")).unwrap();
    let fast = RobotCollision::new(&m).unwrap();
    let mut parry = fast.clone();
    parry.set_distance_method(DistanceMethod::Parry);
    assert_eq!(fast.distance_method(), DistanceMethod::Fast);
    (m, fast, parry)
}

fn random_rotation(rng: &mut ChaCha8Rng) -> Vector3<f64> {
    let axis = Unit::new_normalize(Vector3::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    ));
    axis.into_inner() * rng.random_range(-3.1..3.1)
}

/// A link pose near the object's surface: a random point of a random
/// triangle, pushed along the triangle normal by `offset` (negative:
/// inwards), in the world.
fn pose_near(
    mesh: &TriangleMesh,
    object: &Isometry3<f64>,
    offset: f64,
    rng: &mut ChaCha8Rng,
) -> Isometry3<f64> {
    let k = rng.random_range(0..mesh.indices.len());
    let [a, b, c] = mesh.triangle(k);
    let (mut u, mut v) = (rng.random_range(0.0..1.0), rng.random_range(0.0..1.0));
    if u + v > 1.0 {
        (u, v) = (1.0 - u, 1.0 - v);
    }
    let on = a + (b - a) * u + (c - a) * v;
    let local = on + mesh.triangle_normal(k) * offset;
    Isometry3::new((object * local).coords, random_rotation(rng))
}

/// Exactness of the fast path: its distances against an independent brute
/// force, its witness points on the two surfaces.
const TOL: f64 = 1e-9;
/// Agreement of distances with parry's path. parry runs GJK on the capsule
/// as a curved support map and stops at a relative tolerance: its distances
/// are upper bounds that overshoot by up to ~2e-9 at a few centimetres on
/// the closed meshes here, and by up to ~8e-7 on the open tube's slender
/// triangles (the fast path matches the brute force there to 1e-9).
const PARRY_DISTANCE_TOL: f64 = 1e-6;
/// Agreement of witness points with parry's (same feature pair). Its
/// witnesses converge only to about the square root of its distance
/// tolerance (errors of 1e-6 occur), and near-parallel faces make them
/// ill-conditioned; the fast path's witnesses are checked exactly instead.
const PARRY_WITNESS_TOL: f64 = 1e-4;

fn assert_same(fast: &Proximity, parry: &Proximity, what: &str) {
    assert!(
        (fast.distance - parry.distance).abs() < PARRY_DISTANCE_TOL,
        "{what}: distance {} vs {}",
        fast.distance,
        parry.distance
    );
    // Both are upper bounds of |distance|: ours is never the larger.
    assert!(
        fast.distance.abs() <= parry.distance.abs() + 1e-12 || parry.distance <= 0.0,
        "{what}: distance {} vs {}",
        fast.distance,
        parry.distance
    );
    assert!(
        (fast.point_on_link - parry.point_on_link).norm() < PARRY_WITNESS_TOL,
        "{what}: link witness {fast:?} vs {parry:?}"
    );
    assert!(
        (fast.point_on_object - parry.point_on_object).norm() < PARRY_WITNESS_TOL,
        "{what}: object witness {fast:?} vs {parry:?}"
    );
    assert!(
        fast.normal.dot(&parry.normal) > 0.99,
        "{what}: normal {fast:?} vs {parry:?}"
    );
    assert_eq!(
        (fast.link_part, fast.object_part),
        (parry.link_part, parry.object_part)
    );
}

/// Distance from segment `[p, q]` to a triangle: the distance from a point
/// of the segment to the triangle is convex along it, so a golden-section
/// search over the segment finds its minimum (to ~1e-15 m here).
fn segment_triangle_distance(p: Vector3<f64>, q: Vector3<f64>, t: &[Vector3<f64>; 3]) -> f64 {
    let f = |s: f64| {
        let x = p + (q - p) * s;
        (common::closest_on_triangle(x, t) - x).norm()
    };
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut lo, mut hi) = (0.0, 1.0);
    let (mut x1, mut x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut f1, mut f2) = (f(x1), f(x2));
    while hi - lo > 1e-13 {
        if f1 < f2 {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - g * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + g * (hi - lo);
            f2 = f(x2);
        }
    }
    f(0.0).min(f(1.0)).min(f1).min(f2)
}

/// The probe's core segment (world) and radius.
fn core_segment(c: &RobotCollision, fk: &FkState) -> (Vector3<f64>, Vector3<f64>, f64) {
    let part = &c.link_parts(0)[0];
    let w1 = to_pose(fk.pose(0)) * part.origin;
    let (a, b, r) = if let Some(cap) = part.shape.as_capsule() {
        (cap.segment.a, cap.segment.b, cap.radius)
    } else {
        let ball = part.shape.as_ball().unwrap();
        (
            parry3d_f64::math::Vector::ZERO,
            parry3d_f64::math::Vector::ZERO,
            ball.radius,
        )
    };
    (to_vector(w1 * a), to_vector(w1 * b), r)
}

/// Distance from the link's surface to the mesh surface (zero when they
/// cross), triangle by triangle, with no BVH and none of the fast path's
/// formulas.
fn brute_force(
    c: &RobotCollision,
    fk: &FkState,
    mesh: &TriangleMesh,
    pose: &Isometry3<f64>,
) -> f64 {
    let (p, q, r) = core_segment(c, fk);
    let (mid, half) = ((p + q) / 2.0, (q - p).norm() / 2.0);
    let mut best = f64::INFINITY;
    for k in 0..mesh.indices.len() {
        let t = mesh.triangle(k).map(|v| (pose * v).coords);
        // Skip triangles that cannot beat the best so far.
        if (common::closest_on_triangle(mid, &t) - mid).norm() - half >= best {
            continue;
        }
        best = best.min(segment_triangle_distance(p, q, &t));
    }
    (best - r).max(0.0)
}

/// A separated (or inside) answer is exact: its witnesses lie on the link's
/// surface and on the mesh, `brute` apart, and the normal joins them.
fn assert_exact(
    c: &RobotCollision,
    fk: &FkState,
    object: &CollisionObject,
    p: &Proximity,
    brute: f64,
    what: &str,
) {
    let (a, b, r) = core_segment(c, fk);
    let x = p.point_on_link.coords;
    let s = ((x - a).dot(&(b - a)) / (b - a).norm_squared().max(1e-300)).clamp(0.0, 1.0);
    let on_link = ((x - (a + (b - a) * s)).norm() - r).abs();
    let on_object = object.parts()[0].shape.distance_to_point(
        &to_pose(object.pose()),
        to_vec(&p.point_on_object),
        false,
    );
    assert!(
        on_link < TOL && on_object < TOL,
        "{what}: {on_link} {on_object} off the surfaces"
    );
    let gap = p.point_on_link - p.point_on_object;
    assert!(
        (gap.norm() - brute).abs() < TOL,
        "{what}: witnesses {} apart, not {brute}",
        gap.norm()
    );
    assert!(
        (p.distance.abs() - brute).abs() < TOL,
        "{what}: {p:?} vs {brute}"
    );
    let n = gap.normalize() * p.distance.signum();
    assert!(
        (p.normal.into_inner() - n).norm() < TOL,
        "{what}: normal {p:?}"
    );
}

#[derive(Default, Debug)]
struct Seen {
    separated: usize,
    near: usize,
    penetrating: usize,
    inside: usize,
}

/// Random poses of the probe around `mesh` placed at `object_pose`.
fn compare(geometry: &str, mesh: &TriangleMesh, seed: u64, poses: usize) -> Seen {
    let (m, fast, parry) = probe(geometry);
    let object_pose = Isometry3::new(Vector3::new(0.3, -0.1, 0.7), Vector3::new(0.4, 0.2, -0.9));
    let object = CollisionObject::from_mesh("o", object_pose, mesh).unwrap();
    let mut fk = FkState::new(&m);
    let mut rng = common::rng(seed);
    let mut seen = Seen::default();
    let (_, _, radius) = core_segment(&fast, &fk);
    for i in 0..poses {
        // Far, near contact (within 3 mm), penetrating, inside.
        let offset = match i % 4 {
            0 => rng.random_range(-0.05..0.08),
            1 => radius + rng.random_range(0.0..0.003),
            2 => rng.random_range(-radius..radius),
            _ => rng.random_range(-0.03..-0.01) - radius,
        };
        fk.base = pose_near(mesh, &object_pose, offset, &mut rng);
        m.forward_kinematics(&[], &mut fk);
        let what = format!("{geometry} pose {i} offset {offset}");
        // Exact against brute force first, then against parry's path.
        let p = fast.link_object_proximity(&fk, 0, &object, 1.0).unwrap();
        let brute = brute_force(&fast, &fk, mesh, &object_pose);
        if brute > 0.0 {
            // Separated from the surface: outside, or inside a closed mesh.
            assert_exact(&fast, &fk, &object, &p, brute, &what);
            if p.distance < 0.0 {
                seen.inside += 1;
            } else if p.distance < 0.004 {
                seen.near += 1;
            } else {
                seen.separated += 1;
            }
        } else {
            assert!(p.distance <= 0.0, "{what}: {p:?}");
            seen.penetrating += 1;
        }
        for max_distance in [1.0, 0.004] {
            let a = fast.link_object_proximity(&fk, 0, &object, max_distance);
            let b = parry.link_object_proximity(&fk, 0, &object, max_distance);
            match (a, b) {
                (Some(a), Some(b)) => assert_same(&a, &b, &what),
                (None, None) => assert!(max_distance < 1.0, "{what}: nothing found"),
                _ => panic!("{what} max {max_distance}: {a:?} vs {b:?}"),
            }
        }
        for margin in [0.0, 0.003] {
            assert_eq!(
                fast.first_collision(&fk, &[0], &[&object], margin),
                parry.first_collision(&fk, &[0], &[&object], margin),
                "{what} margin {margin}"
            );
        }
    }
    seen
}

fn can() -> TriangleMesh {
    TriangleMesh::load(
        &common::models_dir().join("objects/can_350ml/can_350ml.stl"),
        Vector3::repeat(1.0),
    )
    .unwrap()
}

const FINGERTIP: &str = r#"<capsule radius="0.0085" length="0.009"/>"#;
const LONG_CAPSULE: &str = r#"<capsule radius="0.004" length="0.07"/>"#;
const BALL: &str = r#"<sphere radius="0.01"/>"#;

#[test]
fn capsules_and_balls_against_the_can_match_parry_and_brute_force() {
    let can = can();
    assert!(can.is_closed());
    for (k, shape) in [FINGERTIP, LONG_CAPSULE, BALL].into_iter().enumerate() {
        let seen = compare(shape, &can, 10 + k as u64, 160);
        assert!(
            seen.separated > 10 && seen.near > 5 && seen.penetrating > 10 && seen.inside > 2,
            "{shape}: {seen:?}"
        );
    }
}

#[test]
fn capsules_against_a_fine_sphere_match_parry_and_brute_force() {
    let sphere = TriangleMesh::uv_sphere(0.1, 24, 24);
    for (k, shape) in [FINGERTIP, LONG_CAPSULE].into_iter().enumerate() {
        let seen = compare(shape, &sphere, 20 + k as u64, 120);
        assert!(
            seen.separated > 5 && seen.near > 5 && seen.penetrating > 5 && seen.inside > 5,
            "{shape}: {seen:?}"
        );
    }
}

#[test]
fn open_meshes_stay_surfaces_on_the_fast_path() {
    let mut tube = can();
    // Drop the triangles facing up or down (the can's ends): an open tube.
    let keep: Vec<_> = (0..tube.indices.len())
        .filter(|&k| tube.triangle_normal(k).z.abs() < 0.5)
        .map(|k| tube.indices[k])
        .collect();
    tube.indices = keep;
    assert!(!tube.is_closed());
    let seen = compare(FINGERTIP, &tube, 30, 120);
    assert_eq!(seen.inside, 0, "{seen:?}");
    assert!(seen.separated > 5 && seen.penetrating > 5, "{seen:?}");
}

#[test]
fn the_fingertip_beside_the_can_is_answered_exactly() {
    // The benchmark's situation: the humanoid's fingertip 2 cm from the can.
    let m = common::humanoid();
    let fast = RobotCollision::new(&m).unwrap();
    let mut parry = fast.clone();
    parry.set_distance_method(DistanceMethod::Parry);
    let mut fk = FkState::new(&m);
    let mut rng = common::rng(40);
    let can = can();
    let tip = m.link_id("r_index_l4").unwrap();
    for _ in 0..40 {
        let q = common::random_q(&m, &mut rng);
        m.forward_kinematics(&q, &mut fk);
        let t = fk.pose(tip).translation.vector;
        let jitter = Vector3::new(
            rng.random_range(-0.03..0.03),
            rng.random_range(-0.03..0.03),
            rng.random_range(-0.08..0.0),
        );
        let pose = Isometry3::translation(t.x + jitter.x, t.y + jitter.y, t.z + jitter.z);
        let object = CollisionObject::from_mesh("can", pose, &can).unwrap();
        let a = fast.link_object_proximity(&fk, tip, &object, 1.0).unwrap();
        let b = parry.link_object_proximity(&fk, tip, &object, 1.0).unwrap();
        assert_same(&a, &b, &format!("q {q:?}"));
        // The witness on the object lies on the can's surface.
        let local = pose.inverse() * a.point_on_object;
        let mesh = object.parts()[0].shape.as_trimesh().unwrap();
        let d = mesh
            .triangles()
            .map(|t| t.distance_to_local_point(to_vec(&Point3::from(local.coords)), false))
            .fold(f64::INFINITY, f64::min);
        assert!(d < TOL, "{d}");
    }
}

/// Boxes stay on parry's path under either method: identical answers, and
/// the least cost of parry's triangle–box function over every triangle.
fn compare_box(size: &str, mesh: &TriangleMesh, seed: u64, poses: usize) -> Seen {
    let (m, fast, parry) = probe(&format!(r#"<box size="{size}"/>"#));
    let object_pose = Isometry3::new(Vector3::new(-0.2, 0.4, 0.1), Vector3::new(-0.3, 0.5, 0.2));
    let object = CollisionObject::from_mesh("o", object_pose, mesh).unwrap();
    let trimesh = object.parts()[0].shape.as_trimesh().unwrap();
    let part = &fast.link_parts(0)[0];
    let cuboid = part.shape.as_cuboid().unwrap();
    let reach = cuboid.half_extents.length();
    let mut fk = FkState::new(&m);
    let mut rng = common::rng(seed);
    let mut seen = Seen::default();
    for i in 0..poses {
        let offset = match i % 4 {
            0 => rng.random_range(-0.05..0.08),
            1 => reach + rng.random_range(0.0..0.003),
            2 => rng.random_range(-reach..reach),
            _ => rng.random_range(-0.03..-0.01) - reach,
        };
        fk.base = pose_near(mesh, &object_pose, offset, &mut rng);
        m.forward_kinematics(&[], &mut fk);
        let what = format!("box {size} pose {i} offset {offset}");
        for max_distance in [1.0, 0.004] {
            let a = fast.link_object_proximity(&fk, 0, &object, max_distance);
            let b = parry.link_object_proximity(&fk, 0, &object, max_distance);
            match (a, b) {
                (Some(a), Some(b)) => {
                    assert!((a.distance - b.distance).abs() < TOL, "{what}: {a:?} {b:?}");
                    assert!((a.point_on_link - b.point_on_link).norm() < TOL, "{what}");
                    assert!(
                        (a.point_on_object - b.point_on_object).norm() < TOL,
                        "{what}"
                    );
                    assert!((a.normal.into_inner() - b.normal.into_inner()).norm() < TOL);
                }
                (None, None) => assert!(max_distance < 1.0, "{what}: nothing found"),
                _ => panic!("{what} max {max_distance}: {a:?} vs {b:?}"),
            }
        }
        // Brute force: the least cost over every triangle.
        let w1 = to_pose(fk.pose(0)) * part.origin;
        let w2 = to_pose(object.pose());
        let pose = w2.inv_mul(&w1);
        let brute = trimesh
            .triangles()
            .map(|t| {
                use parry3d_f64::query::{details::closest_points_triangle_cuboid, ClosestPoints};
                match closest_points_triangle_cuboid(&pose, &t, cuboid, 1.0) {
                    ClosestPoints::WithinMargin(a, b) => (a - pose * b).length(),
                    ClosestPoints::Intersecting => 0.0,
                    ClosestPoints::Disjoint => f64::INFINITY,
                }
            })
            .fold(f64::INFINITY, f64::min);
        let p = fast.link_object_proximity(&fk, 0, &object, 1.0).unwrap();
        if brute > 0.0 {
            assert!(
                (p.distance.abs() - brute).abs() < TOL,
                "{what}: {p:?} vs {brute}"
            );
            if p.distance < 0.0 {
                seen.inside += 1;
            } else if p.distance < 0.004 {
                seen.near += 1;
            } else {
                seen.separated += 1;
            }
        } else {
            assert!(p.distance <= 0.0, "{what}: {p:?}");
            seen.penetrating += 1;
        }
        for margin in [0.0, 0.003] {
            assert_eq!(
                fast.first_collision(&fk, &[0], &[&object], margin),
                parry.first_collision(&fk, &[0], &[&object], margin),
                "{what} margin {margin}"
            );
        }
    }
    seen
}

#[test]
fn boxes_against_meshes_match_brute_force_under_both_methods() {
    let can = can();
    // The palm and a first phalanx of the humanoid.
    for (k, size) in ["0.1 0.09 0.03", "0.012 0.018 0.018"]
        .into_iter()
        .enumerate()
    {
        let seen = compare_box(size, &can, 50 + k as u64, 120);
        assert!(
            seen.separated > 5 && seen.near > 2 && seen.penetrating > 5,
            "{size}: {seen:?}"
        );
        let sphere = TriangleMesh::uv_sphere(0.1, 24, 24);
        let seen = compare_box(size, &sphere, 60 + k as u64, 80);
        assert!(
            seen.separated > 5 && seen.penetrating > 5,
            "{size}: {seen:?}"
        );
    }
}
