//! Collision and distance between robot links, objects and obstacles
//! (parry3d), with witness points and surface normals — what PQP gave the
//! paper's planner.
//!
//! * [`CollisionObject`]: a rigid set of shapes with a world pose — a grasped
//!   object, a table, a fridge. Meshes get parry's BVH, so a 100k-triangle
//!   object stays fast.
//! * [`RobotCollision`]: the collision shapes of every link of a
//!   [`RobotModel`] and the allowed (never checked) link pairs. Queries read
//!   link poses from an [`FkState`], so the caller runs forward kinematics
//!   once per configuration and then asks as many questions as it needs.
//!
//! # Meshes are surfaces
//! A parry `TriMesh` is a surface: a link entirely inside a mesh is at a
//! positive distance from it and does not intersect it. Meshes that are
//! closed ([`TriangleMesh::is_closed`]) are therefore built with parry's
//! oriented pseudo-normals and treated as solids: when a query finds a link
//! separated from such a mesh, it also tests whether the link lies inside it,
//! and reports a collision (a negative distance, see [`Proximity`]) if so.
//! Open meshes stay surfaces; callers that need solids should refuse them
//! ([`CollisionObject::is_solid`]). A part may instead carry the triangles
//! around each vertex ([`Part::around`]) and be built without parry's
//! pseudo-normals: its inside tests then compute the one pseudo-normal they
//! need ([`crate::mesh_inside`], the same answers), which spares building
//! all of them — the planner kit's objects do this.
//!
//! # Narrow phase
//! A link part that is a ball or a capsule (the finger phalanges) against an
//! object part that is a mesh is answered by the closed-form path of
//! [`crate::capsule_mesh`]; every other pair (boxes — palms, first
//! phalanges — included), and the penetration depth of overlapping pairs,
//! by parry's general queries. The
//! paths agree (the capsule path is exact where parry's GJK stops at its
//! tolerance, see `tests/fast_distance.rs`);
//! [`RobotCollision::set_distance_method`] selects parry's path for
//! everything (the reference, for tests and benchmarks).
//!
//! # Broad phase
//! Every pair test starts with the two parts' world AABBs (parry's own, so
//! as tight as parry makes them). A [`Placement`] holds them for one
//! configuration — each part's world pose and AABB, and each link's AABB
//! (the union of its parts') — so a caller that tests many pairs at one
//! configuration computes every AABB once, not once per pair, and skips a
//! link pair whose link AABBs are apart before looking at its parts
//! ([`RobotCollision::place`], [`RobotCollision::placed_self_collision`],
//! [`RobotCollision::placed_collision`]). A [`CollisionObject`] keeps its
//! parts' world AABBs from one `set_pose` to the next. The broad phase only
//! skips pairs that cannot collide: every answer is the narrow phase's.

use nalgebra::{Isometry3, Point3, Unit, UnitQuaternion, Vector3};
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::query::{self, ClosestPoints};
use parry3d_f64::shape::{SharedShape, TriMesh, TriMeshFlags};

use std::sync::Arc;

use crate::capsule_mesh::{self, MeshClosestPoints, SweptSphere};
use crate::convert::{from_pose, to_point, to_pose, to_vec, to_vector};
use crate::error::{BodyError, Result};
use crate::kinematics::FkState;
use crate::mesh::TriangleMesh;
use crate::mesh_inside::{self, VertexTriangles};
use crate::model::{Geometry, LinkId, RobotModel};

/// One shape of a link or object, placed in its owner's frame.
#[derive(Clone)]
pub struct Part {
    /// Pose of the shape in the owner's frame.
    pub origin: Pose,
    /// The parry shape.
    pub shape: SharedShape,
    /// True for a closed mesh treated as a solid (inside tests enabled).
    pub solid_mesh: bool,
    /// For a solid mesh built without parry's oriented pseudo-normals: the
    /// triangles around each vertex, from which its inside tests compute the
    /// one pseudo-normal they need ([`crate::mesh_inside`], the same answers).
    /// `None`: parry's own inside test.
    pub around: Option<Arc<VertexTriangles>>,
}

impl std::fmt::Debug for Part {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Part")
            .field("origin", &from_pose(&self.origin))
            .field("shape", &self.shape.shape_type())
            .field("solid_mesh", &self.solid_mesh)
            .field("around", &self.around.is_some())
            .finish()
    }
}

impl Part {
    /// Builds the parry shape of a geometry placed at `origin`.
    pub fn from_geometry(origin: &Isometry3<f64>, geometry: &Geometry) -> Result<Self> {
        let (shape, extra, solid_mesh) = match geometry {
            Geometry::Box { size } => (
                SharedShape::cuboid(size.x / 2.0, size.y / 2.0, size.z / 2.0),
                Isometry3::identity(),
                false,
            ),
            // parry's cylinder is along y, URDF's along z.
            Geometry::Cylinder { radius, length } => (
                SharedShape::cylinder(length / 2.0, *radius),
                Isometry3::from_parts(
                    nalgebra::Translation3::identity(),
                    UnitQuaternion::from_axis_angle(
                        &Vector3::x_axis(),
                        std::f64::consts::FRAC_PI_2,
                    ),
                ),
                false,
            ),
            Geometry::Capsule { radius, length } => (
                SharedShape::capsule_z(length / 2.0, *radius),
                Isometry3::identity(),
                false,
            ),
            Geometry::Sphere { radius } => {
                (SharedShape::ball(*radius), Isometry3::identity(), false)
            }
            Geometry::Mesh { path, mesh, .. } => {
                let (trimesh, solid) = build_trimesh(mesh).map_err(|message| BodyError::Mesh {
                    file: path.clone(),
                    message,
                })?;
                (SharedShape::new(trimesh), Isometry3::identity(), solid)
            }
        };
        Ok(Self {
            origin: to_pose(&(origin * extra)),
            shape,
            solid_mesh,
            around: None,
        })
    }

    /// Is the world point `p` inside this part placed at `pose` (its owner's
    /// pose times `origin`)? False for surfaces (`solid_mesh` unset on a mesh).
    fn contains(&self, pose: &Pose, p: Vector) -> bool {
        match (&self.around, self.shape.as_trimesh()) {
            (Some(around), Some(mesh)) => {
                let local = pose.inverse_transform_point(p);
                // Outside the mesh's box is outside the mesh: no search.
                mesh.local_aabb().contains_local_point(local)
                    && mesh_inside::contains_local_point(mesh, around, local)
            }
            _ => self.shape.contains_point(pose, p),
        }
    }

    /// [`Part::contains`] for a point whose nearest triangle of this mesh
    /// part is known (`nearest`, from a closest-point query).
    fn contains_near(&self, pose: &Pose, p: Vector, nearest: Option<u32>) -> bool {
        match (&self.around, self.shape.as_trimesh(), nearest) {
            (Some(around), Some(mesh), Some(t)) => mesh_inside::contains_local_point_near(
                mesh,
                around,
                pose.inverse_transform_point(p),
                t,
            ),
            _ => self.contains(pose, p),
        }
    }
}

/// Builds a parry mesh (with its BVH); closed meshes get oriented
/// pseudo-normals so inside tests work. Returns the mesh and whether it is a
/// solid.
pub fn build_trimesh(mesh: &TriangleMesh) -> std::result::Result<(TriMesh, bool), String> {
    mesh.validate()?;
    let closed = mesh.is_closed();
    let flags = if closed {
        TriMeshFlags::ORIENTED | TriMeshFlags::MERGE_DUPLICATE_VERTICES
    } else {
        TriMeshFlags::empty()
    };
    let vertices = mesh.vertices.iter().map(to_vec).collect();
    TriMesh::with_flags(vertices, mesh.indices.clone(), flags)
        .map(|m| (m, closed))
        .map_err(|e| format!("cannot build the collision mesh: {e}"))
}

/// A part at its world pose, with its world AABB.
#[derive(Debug, Clone, Copy)]
struct Placed {
    pose: Pose,
    aabb: Aabb,
}

impl Placed {
    /// `part` of an owner at `pose`.
    fn new(pose: &Pose, part: &Part) -> Self {
        let pose = *pose * part.origin;
        Placed {
            aabb: part.shape.compute_aabb(&pose),
            pose,
        }
    }
}

/// Do two AABBs come within `margin` of each other? (False when either is
/// empty or not finite.)
fn overlap(a: &Aabb, b: &Aabb, margin: f64) -> bool {
    a.mins.x <= b.maxs.x + margin
        && b.mins.x <= a.maxs.x + margin
        && a.mins.y <= b.maxs.y + margin
        && b.mins.y <= a.maxs.y + margin
        && a.mins.z <= b.maxs.z + margin
        && b.mins.z <= a.maxs.z + margin
}

/// The AABB of placed parts (empty — overlapping nothing — for none).
fn union(parts: &[Placed]) -> Aabb {
    parts.iter().fold(Aabb::new_invalid(), |acc, p| {
        Aabb::new(acc.mins.min(p.aabb.mins), acc.maxs.max(p.aabb.maxs))
    })
}

/// A rigid collision body with a world pose: an object or an obstacle.
#[derive(Debug, Clone)]
pub struct CollisionObject {
    /// Name (for messages and reports).
    pub name: String,
    pose: Isometry3<f64>,
    parry_pose: Pose,
    parts: Vec<Part>,
    /// The parts at `pose`, and their AABB.
    placed: Vec<Placed>,
    bounds: Aabb,
}

impl CollisionObject {
    /// An object made of shapes placed in its frame, at `pose` in the world.
    pub fn new(name: impl Into<String>, pose: Isometry3<f64>, parts: Vec<Part>) -> Self {
        let mut me = Self {
            name: name.into(),
            parry_pose: to_pose(&pose),
            pose,
            parts,
            placed: Vec::new(),
            bounds: Aabb::new_invalid(),
        };
        me.place();
        me
    }

    fn place(&mut self) {
        self.placed.clear();
        let pose = self.parry_pose;
        self.placed
            .extend(self.parts.iter().map(|p| Placed::new(&pose, p)));
        self.bounds = union(&self.placed);
    }

    /// An object whose single shape is a triangle mesh (in the object frame).
    pub fn from_mesh(
        name: impl Into<String>,
        pose: Isometry3<f64>,
        mesh: &TriangleMesh,
    ) -> std::result::Result<Self, String> {
        let (trimesh, solid) = build_trimesh(mesh)?;
        Ok(Self::new(
            name,
            pose,
            vec![Part {
                origin: Pose::IDENTITY,
                shape: SharedShape::new(trimesh),
                solid_mesh: solid,
                around: None,
            }],
        ))
    }

    /// The world pose.
    pub fn pose(&self) -> &Isometry3<f64> {
        &self.pose
    }

    /// Moves the object.
    pub fn set_pose(&mut self, pose: Isometry3<f64>) {
        self.pose = pose;
        self.parry_pose = to_pose(&pose);
        self.place();
    }

    /// The world axis-aligned box holding every part, as (min, max) corners
    /// (min > max on some axis when the object has no part).
    pub fn bounds(&self) -> (Point3<f64>, Point3<f64>) {
        (to_point(self.bounds.mins), to_point(self.bounds.maxs))
    }

    /// The shapes.
    pub fn parts(&self) -> &[Part] {
        &self.parts
    }

    /// The nearest point of the object's mesh parts to the world point `p`
    /// (`None` when the object has no mesh part or `p` is not finite).
    pub fn surface_point(&self, p: &Point3<f64>) -> Option<SurfacePoint> {
        use parry3d_f64::query::PointQueryWithLocation;
        let mut best: Option<SurfacePoint> = None;
        for part in &self.parts {
            let Some(mesh) = part.shape.as_trimesh() else {
                continue;
            };
            let world = self.parry_pose * part.origin;
            let local = world.inverse_transform_point(to_vec(p));
            let (proj, (tri, _)) = mesh.project_local_point_and_get_location(local, false);
            let Some(n) = mesh.triangle(tri).normal() else {
                continue;
            };
            let point = to_point(world.transform_point(proj.point));
            let distance = (point - p).norm();
            if !distance.is_finite() || best.as_ref().is_some_and(|b| b.distance <= distance) {
                continue;
            }
            // The faces holding the point decide, not the location label: a
            // point on an edge (a capsule's closest point on a faceted
            // cylinder) is labelled inside one of its faces as often as not.
            let mut normals = incident_normals(mesh, proj.point);
            if normals.is_empty() {
                normals.push(n);
            }
            let on_face = normals.len() == 1;
            best = Some(SurfacePoint {
                point,
                distance,
                normal: to_vector(world.rotation * n).normalize(),
                on_face,
                normals: normals
                    .into_iter()
                    .map(|m| to_vector(world.rotation * m).normalize())
                    .collect(),
            });
        }
        best
    }

    /// Do the two objects come closer than `margin` (or overlap, or one lie
    /// inside the other's closed mesh)?
    pub fn intersects(&self, other: &CollisionObject, margin: f64) -> bool {
        if !overlap(&self.bounds, &other.bounds, margin) {
            return false;
        }
        self.parts.iter().zip(&self.placed).any(|(a, pa)| {
            other
                .parts
                .iter()
                .zip(&other.placed)
                .any(|(b, pb)| placed_collides(DistanceMethod::Parry, pa, a, pb, b, margin))
        })
    }

    /// True when every part is a solid (a primitive or a closed mesh).
    pub fn is_solid(&self) -> bool {
        self.parts
            .iter()
            .all(|p| p.solid_mesh || p.shape.as_trimesh().is_none())
    }
}

/// The nearest point of an object's mesh surface to a query point, found by
/// [`CollisionObject::surface_point`].
#[derive(Debug, Clone, PartialEq)]
pub struct SurfacePoint {
    /// The point on the surface (world frame).
    pub point: Point3<f64>,
    /// Its distance from the query point (m).
    pub distance: f64,
    /// The unit normal of the triangle it lies on (world frame), as the
    /// triangle is wound (outward for a closed, consistently wound mesh).
    pub normal: Vector3<f64>,
    /// True when the surface has one normal there: inside a face (or on the
    /// edge between coplanar triangles), not on an edge or vertex where
    /// faces meet at an angle (where the normal is a cone).
    pub on_face: bool,
    /// The unit normals (world frame, as wound) of every triangle holding the
    /// point: one inside a face, the faces meeting at an edge or a vertex
    /// otherwise. The surface's normal cone there is spanned by them.
    pub normals: Vec<Vector3<f64>>,
}

/// The normals of the triangles of `mesh` whose closest point to `q` (a point
/// on the mesh, mesh frame) is `q` itself, within 0.1 µm: the one face holding
/// it, or those meeting at an edge or vertex (coplanar ones once).
fn incident_normals(mesh: &TriMesh, q: Vector) -> Vec<Vector> {
    use parry3d_f64::query::PointQuery;
    const SAME: f64 = 1e-7;
    let around = Aabb::new(q - Vector::splat(SAME), q + Vector::splat(SAME));
    let mut normals: Vec<Vector> = Vec::new();
    for t in mesh.bvh().intersect_aabb(&around) {
        let tri = mesh.triangle(t);
        let d = (tri.project_local_point(q, false).point - q).length();
        // Coplanar triangles (a quad's two halves) give one direction.
        match tri.normal() {
            Some(n) if d <= SAME && !normals.iter().any(|m| m.dot(n) > 1.0 - 1e-12) => {
                normals.push(n)
            }
            _ => {}
        }
    }
    normals
}

/// Closest points between a link and an object.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Proximity {
    /// Distance (m); negative when they overlap (the penetration depth), or
    /// when the link lies inside a closed mesh (then minus the distance from
    /// the link to the mesh surface, a lower bound of the depth).
    pub distance: f64,
    /// Witness point on the link's surface (world frame).
    pub point_on_link: Point3<f64>,
    /// Witness point on the object's surface (world frame).
    pub point_on_object: Point3<f64>,
    /// Unit outward normal of the object's surface at `point_on_object`
    /// (world frame): the direction in which the link must move to
    /// separate. When separated it points from the object toward the link.
    pub normal: Unit<Vector3<f64>>,
    /// Which part of the link (index into its collision elements).
    pub link_part: usize,
    /// Which part of the object.
    pub object_part: usize,
}

/// Signed distance, witness points (link, object) and object normal.
type PairProximity = (f64, Point3<f64>, Point3<f64>, Unit<Vector3<f64>>);

/// Which narrow phase answers the queries of a [`RobotCollision`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DistanceMethod {
    /// The closed-form ball/capsule-vs-mesh path where it applies
    /// ([`crate::capsule_mesh`]), parry's general queries elsewhere.
    #[default]
    Fast,
    /// parry's general queries for every pair: the reference.
    Parry,
}

/// Closest points of two placed shapes (world poses `w1`, `w2`) by the fast
/// paths, in parry's conventions (world frame), with the index of the mesh
/// triangle holding the witness point on the mesh when separated; `None`
/// when no fast path applies to the pair: `p2` is not a mesh, `p1` neither a
/// ball nor a capsule, or `method` is parry's.
fn fast_closest_triangle(
    method: DistanceMethod,
    w1: &Pose,
    p1: &Part,
    w2: &Pose,
    p2: &Part,
    max_distance: f64,
) -> Option<(ClosestPoints, Option<u32>)> {
    if method != DistanceMethod::Fast {
        return None;
    }
    let mesh = p2.shape.as_trimesh()?;
    // The link part in the mesh's frame.
    let pose = w2.inv_mul(w1);
    let sphere = SweptSphere::from_shape(&*p1.shape)?.transformed(&pose);
    Some(
        match capsule_mesh::closest_points_to_trimesh(mesh, &sphere, max_distance) {
            MeshClosestPoints::Separated {
                on_sphere,
                on_mesh,
                triangle,
                ..
            } => (
                ClosestPoints::WithinMargin(*w2 * on_sphere, *w2 * on_mesh),
                Some(triangle),
            ),
            MeshClosestPoints::Intersecting => (ClosestPoints::Intersecting, None),
            MeshClosestPoints::Disjoint => (ClosestPoints::Disjoint, None),
        },
    )
}

/// Closest points of two placed shapes (world poses `w1`, `w2`), with
/// parry's conventions.
fn closest_points(
    method: DistanceMethod,
    w1: &Pose,
    p1: &Part,
    w2: &Pose,
    p2: &Part,
    max_distance: f64,
) -> Option<ClosestPoints> {
    fast_closest_triangle(method, w1, p1, w2, p2, max_distance)
        .map(|(cp, _)| cp)
        .or_else(|| query::closest_points(w1, &*p1.shape, w2, &*p2.shape, max_distance).ok())
}

/// Proximity between two placed shapes, or `None` if farther than
/// `max_distance`.
fn pair_proximity(
    method: DistanceMethod,
    pose1: &Pose,
    p1: &Part,
    pose2: &Pose,
    p2: &Part,
    max_distance: f64,
) -> Option<PairProximity> {
    let w1 = *pose1 * p1.origin;
    let w2 = *pose2 * p2.origin;
    // The fast path knows the mesh triangle nearest the link: the inside
    // test then needs no search of its own (the link's witness point has
    // the mesh's witness point as its nearest surface point).
    let (cp, nearest) = match fast_closest_triangle(method, &w1, p1, &w2, p2, max_distance) {
        Some(found) => found,
        None => (
            closest_points(method, &w1, p1, &w2, p2, max_distance)?,
            None,
        ),
    };
    match cp {
        ClosestPoints::WithinMargin(a, b) => {
            let d = (a - b).length();
            if d > 1e-12 {
                let n = Unit::new_normalize(to_vector(a - b));
                if p2.solid_mesh && p2.contains_near(&w2, a, nearest) {
                    // The link is inside the closed mesh.
                    return Some((-d, to_point(a), to_point(b), -n));
                }
                return Some((d, to_point(a), to_point(b), n));
            }
            penetration(method, &w1, p1, &w2, p2)
        }
        ClosestPoints::Intersecting => penetration(method, &w1, p1, &w2, p2),
        ClosestPoints::Disjoint => None,
    }
}

/// A ball or capsule sunk into a mesh surface, in closed form: when its core
/// segment stays outside the surface at distance `d > 0`, the penetration is
/// `radius − d` along the core's closest-point direction — what parry's
/// contact query gives as the deepest of its per-triangle contacts, since a
/// swept sphere's penetration into a convex triangle is its radius less the
/// core's distance (without running EPA on every overlapping triangle).
/// `None` when the fast path does not apply or the core itself touches or
/// crosses the surface (parry then answers).
fn fast_penetration(
    method: DistanceMethod,
    w1: &Pose,
    p1: &Part,
    w2: &Pose,
    p2: &Part,
) -> Option<PairProximity> {
    if method != DistanceMethod::Fast {
        return None;
    }
    let mesh = p2.shape.as_trimesh()?;
    let sphere = SweptSphere::from_shape(&*p1.shape)?.transformed(&w2.inv_mul(w1));
    let core = SweptSphere {
        radius: 0.0,
        ..sphere
    };
    match capsule_mesh::closest_points_to_trimesh(mesh, &core, sphere.radius) {
        MeshClosestPoints::Separated {
            distance,
            on_sphere,
            on_mesh,
            ..
        } if distance > 1e-9 && distance <= sphere.radius => {
            let dir = (on_sphere - on_mesh) / distance;
            let deepest = on_sphere - dir * sphere.radius;
            let n = Unit::new_normalize(to_vector(w2.rotation * dir));
            Some((
                distance - sphere.radius,
                to_point(*w2 * deepest),
                to_point(*w2 * on_mesh),
                n,
            ))
        }
        _ => None,
    }
}

fn penetration(
    method: DistanceMethod,
    w1: &Pose,
    p1: &Part,
    w2: &Pose,
    p2: &Part,
) -> Option<PairProximity> {
    if let Some(p) = fast_penetration(method, w1, p1, w2, p2) {
        return Some(p);
    }
    match query::contact(w1, &*p1.shape, w2, &*p2.shape, 0.0) {
        Ok(Some(c)) => {
            let n = Unit::try_new(to_vector(c.normal2), 1e-12).unwrap_or(Vector3::z_axis());
            Some((c.dist.min(0.0), to_point(c.point1), to_point(c.point2), n))
        }
        // Touching within round-off but no contact manifold: report contact
        // at distance zero along the world z axis.
        _ => {
            let a = to_point(w1.translation);
            Some((0.0, a, a, Vector3::z_axis()))
        }
    }
}

/// Broad phase: do the world AABBs of two placed parts overlap (with a margin)?
fn aabbs_overlap(pose1: &Pose, p1: &Part, pose2: &Pose, p2: &Part, margin: f64) -> bool {
    let a = p1.shape.compute_aabb(&(*pose1 * p1.origin));
    let b = p2.shape.compute_aabb(&(*pose2 * p2.origin));
    overlap(&a, &b, margin)
}

/// Do two parts (`p1` placed as `a`, `p2` as `b`) collide, i.e. come closer
/// than `margin` (or overlap, or one lies inside the other's closed mesh)?
fn placed_collides(
    method: DistanceMethod,
    a: &Placed,
    p1: &Part,
    b: &Placed,
    p2: &Part,
    margin: f64,
) -> bool {
    if !overlap(&a.aabb, &b.aabb, margin) {
        return false;
    }
    let (w1, w2) = (a.pose, b.pose);
    let fast = fast_closest_triangle(method, &w1, p1, &w2, p2, margin.max(0.0));
    let hit = if let Some((cp, _)) = fast {
        // Margin 0 accepts only overlaps, like parry's intersection test.
        !matches!(cp, ClosestPoints::Disjoint)
    } else if margin > 0.0 {
        !matches!(
            query::closest_points(&w1, &*p1.shape, &w2, &*p2.shape, margin),
            Ok(ClosestPoints::Disjoint)
        )
    } else {
        query::intersection_test(&w1, &*p1.shape, &w2, &*p2.shape)
            .map(|r| r.intersecting)
            .unwrap_or(false)
    };
    if hit {
        return true;
    }
    // A shape wholly inside a closed mesh does not touch its surface.
    let inside =
        |a: &Placed, b: &Placed, pb: &Part| pb.solid_mesh && pb.contains(&b.pose, a.aabb.center());
    inside(a, b, p2) || inside(b, a, p1)
}

/// How deep one placed part sinks into another: 0 when they are apart or
/// only touch; the overlap depth when they overlap; when `p1` lies inside
/// the closed mesh `p2`, its distance to that surface plus its own size
/// along the way out (a lower bound of the depth, never below the overlap).
fn pair_depth(method: DistanceMethod, pose1: &Pose, p1: &Part, pose2: &Pose, p2: &Part) -> f64 {
    if !aabbs_overlap(pose1, p1, pose2, p2, 0.0) {
        return 0.0;
    }
    let w1 = *pose1 * p1.origin;
    let w2 = *pose2 * p2.origin;
    let inside = p2.solid_mesh && p2.contains(&w2, p1.shape.compute_aabb(&w1).center());
    // Inside a closed mesh the surface may be far: look that far.
    let reach = if inside {
        let a = p2.shape.compute_aabb(&w2);
        (a.maxs - a.mins).length()
    } else {
        0.0
    };
    match pair_proximity(method, pose1, p1, pose2, p2, reach) {
        Some((d, ..)) if d < 0.0 => -d,
        Some((d, ..)) if inside => d.max(0.0) + 1e-9,
        _ => 0.0,
    }
}

/// A link sunk into an object, found by [`RobotCollision::link_penetration`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Penetration {
    /// The link.
    pub link: LinkId,
    /// Index of the object in the slice given to the query (0 for a single object).
    pub object: usize,
    /// Depth (m): how far the link is in, a lower bound when it lies wholly
    /// inside a closed mesh.
    pub depth: f64,
}

/// A colliding pair found by [`RobotCollision::first_collision`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Hit {
    /// The link.
    pub link: LinkId,
    /// Index of the object in the slice given to the query.
    pub object: usize,
}

/// The collision shapes of a robot's links and the link pairs never checked
/// for self-collision.
#[derive(Debug, Clone)]
pub struct RobotCollision {
    parts: Vec<Vec<Part>>,
    /// Row-major `n × n` table of allowed pairs.
    allowed: Vec<bool>,
    n: usize,
    /// Links with geometry, for self-collision loops.
    with_geometry: Vec<LinkId>,
    method: DistanceMethod,
}

impl RobotCollision {
    /// Builds the link shapes from the model's `<collision>` elements. By
    /// default a link may touch its nearest ancestor that has geometry (its
    /// "adjacent" link) and any link rigidly attached to it (only fixed joints
    /// between them).
    pub fn new(model: &RobotModel) -> Result<Self> {
        let n = model.links.len();
        let mut parts = Vec::with_capacity(n);
        for link in &model.links {
            let p = link
                .collisions
                .iter()
                .map(|e| Part::from_geometry(&e.origin, &e.geometry))
                .collect::<Result<Vec<_>>>()?;
            parts.push(p);
        }
        let with_geometry: Vec<LinkId> = (0..n).filter(|&l| !parts[l].is_empty()).collect();
        let mut me = Self {
            parts,
            allowed: vec![false; n * n],
            n,
            with_geometry,
            method: DistanceMethod::Fast,
        };
        for l in 0..n {
            me.allow(l, l);
            if me.parts[l].is_empty() {
                continue;
            }
            // Nearest ancestor with geometry, and rigidly attached ones.
            let mut rigid = true;
            let mut found = false;
            let mut a = l;
            while let Some(j) = model.links[a].parent_joint {
                rigid &= !model.joints[j].is_movable();
                a = model.joints[j].parent;
                let has = !me.parts[a].is_empty();
                if rigid || (has && !found) {
                    me.allow(l, a);
                }
                found |= has;
                if found && !rigid {
                    break;
                }
            }
        }
        Ok(me)
    }

    /// Selects the narrow phase of every query (default
    /// [`DistanceMethod::Fast`]; [`DistanceMethod::Parry`] is the reference).
    pub fn set_distance_method(&mut self, method: DistanceMethod) {
        self.method = method;
    }

    /// The narrow phase in use.
    pub fn distance_method(&self) -> DistanceMethod {
        self.method
    }

    /// Never check the pair `(a, b)` for self-collision.
    pub fn allow(&mut self, a: LinkId, b: LinkId) {
        self.allowed[a * self.n + b] = true;
        self.allowed[b * self.n + a] = true;
    }

    /// Check the pair `(a, b)` again.
    pub fn disallow(&mut self, a: LinkId, b: LinkId) {
        self.allowed[a * self.n + b] = false;
        self.allowed[b * self.n + a] = false;
    }

    /// Is the pair allowed to touch?
    pub fn is_allowed(&self, a: LinkId, b: LinkId) -> bool {
        self.allowed[a * self.n + b]
    }

    /// The collision shapes of a link.
    pub fn link_parts(&self, link: LinkId) -> &[Part] {
        &self.parts[link]
    }

    /// Distance, witness points and normal between `link` and `object` for
    /// the configuration in `fk`; `None` when the link has no geometry or
    /// they are farther apart than `max_distance`. With several shapes on
    /// either side, the closest pair wins.
    pub fn link_object_proximity(
        &self,
        fk: &FkState,
        link: LinkId,
        object: &CollisionObject,
        max_distance: f64,
    ) -> Option<Proximity> {
        let link_pose = to_pose(fk.pose(link));
        let mut best: Option<Proximity> = None;
        for (i, lp) in self.parts[link].iter().enumerate() {
            for (k, op) in object.parts.iter().enumerate() {
                let limit = best.map_or(max_distance, |b| b.distance.min(max_distance));
                if let Some((d, a, b, n)) = pair_proximity(
                    self.method,
                    &link_pose,
                    lp,
                    &object.parry_pose,
                    op,
                    limit.max(0.0),
                ) {
                    if best.is_none_or(|bb| d < bb.distance) {
                        best = Some(Proximity {
                            distance: d,
                            point_on_link: a,
                            point_on_object: b,
                            normal: n,
                            link_part: i,
                            object_part: k,
                        });
                    }
                }
            }
        }
        best
    }

    /// The first of `links` that comes closer than `margin` to (or overlaps,
    /// or lies inside) one of `objects`; `None` when all are clear.
    pub fn first_collision(
        &self,
        fk: &FkState,
        links: &[LinkId],
        objects: &[&CollisionObject],
        margin: f64,
    ) -> Option<Hit> {
        let mut placed = Vec::new();
        links.iter().find_map(|&link| {
            let pose = to_pose(fk.pose(link));
            placed.clear();
            placed.extend(self.parts[link].iter().map(|p| Placed::new(&pose, p)));
            self.link_hit(link, &placed, &union(&placed), objects, margin)
        })
    }

    /// How deep `link` sinks into `object` (0 when apart or only touching):
    /// the deepest of its parts against the object's parts. Touching is
    /// allowed; callers compare the depth with their tolerance.
    pub fn link_penetration(&self, fk: &FkState, link: LinkId, object: &CollisionObject) -> f64 {
        let link_pose = to_pose(fk.pose(link));
        let mut depth: f64 = 0.0;
        for lp in &self.parts[link] {
            for op in &object.parts {
                depth = depth.max(pair_depth(
                    self.method,
                    &link_pose,
                    lp,
                    &object.parry_pose,
                    op,
                ));
            }
        }
        depth
    }

    /// The first of `links` that sinks deeper than `tolerance` into one of
    /// `objects` (touching and shallower overlaps pass); `None` when none does.
    pub fn first_penetration(
        &self,
        fk: &FkState,
        links: &[LinkId],
        objects: &[&CollisionObject],
        tolerance: f64,
    ) -> Option<Penetration> {
        for &link in links {
            for (o, object) in objects.iter().enumerate() {
                let depth = self.link_penetration(fk, link, object);
                if depth > tolerance {
                    return Some(Penetration {
                        link,
                        object: o,
                        depth,
                    });
                }
            }
        }
        None
    }

    /// The first pair of links, not allowed to touch, that come closer than
    /// `margin`; `None` when the robot is free of self-collision.
    pub fn first_self_collision(&self, fk: &FkState, margin: f64) -> Option<(LinkId, LinkId)> {
        self.self_collision_pairs(fk, margin, true)
            .into_iter()
            .next()
    }

    /// Every pair of links, not allowed to touch, that come closer than
    /// `margin`.
    pub fn self_collisions(&self, fk: &FkState, margin: f64) -> Vec<(LinkId, LinkId)> {
        self.self_collision_pairs(fk, margin, false)
    }

    fn self_collision_pairs(
        &self,
        fk: &FkState,
        margin: f64,
        first: bool,
    ) -> Vec<(LinkId, LinkId)> {
        let mut placement = Placement::default();
        self.place(fk, &self.with_geometry, &mut placement);
        let mut out = Vec::new();
        for (a, b) in self.self_pairs() {
            if self.placed_pair_collides(&placement, a, b, margin) {
                out.push((a, b));
                if first {
                    break;
                }
            }
        }
        out
    }

    /// Every pair of links with geometry not allowed to touch, each once as
    /// `(a, b)` with `a < b`, in the order the self-collision queries test them.
    pub fn self_pairs(&self) -> Vec<(LinkId, LinkId)> {
        let g = &self.with_geometry;
        g.iter()
            .enumerate()
            .flat_map(|(i, &a)| g[i + 1..].iter().map(move |&b| (a, b)))
            .filter(|&(a, b)| !self.is_allowed(a, b))
            .collect()
    }

    /// Places the parts of `links` for the configuration in `fk` (world poses
    /// and AABBs) into `placement`; other links keep what it held.
    pub fn place(&self, fk: &FkState, links: &[LinkId], placement: &mut Placement) {
        placement.parts.resize_with(self.n, Vec::new);
        placement.bounds.resize(self.n, Aabb::new_invalid());
        for &link in links {
            let pose = to_pose(fk.pose(link));
            let placed = &mut placement.parts[link];
            placed.clear();
            placed.extend(self.parts[link].iter().map(|p| Placed::new(&pose, p)));
            placement.bounds[link] = union(placed);
        }
    }

    /// Do the placed links `a` and `b` come closer than `margin` (whether
    /// the pair is allowed is the caller's business)?
    fn placed_pair_collides(
        &self,
        placement: &Placement,
        a: LinkId,
        b: LinkId,
        margin: f64,
    ) -> bool {
        let (Some((pa, ba)), Some((pb, bb))) = (placement.link(a), placement.link(b)) else {
            return false; // not placed
        };
        if !overlap(ba, bb, margin) {
            return false;
        }
        let (xs, ys) = (self.link_parts(a), self.link_parts(b));
        xs.iter().zip(pa).any(|(x, xa)| {
            ys.iter()
                .zip(pb)
                .any(|(y, yb)| placed_collides(self.method, xa, x, yb, y, margin))
        })
    }

    /// [`Self::first_self_collision`] over the placed links: the first of
    /// `pairs` (e.g. a subset of [`Self::self_pairs`]) whose links come
    /// closer than `margin`. Links never placed collide with nothing.
    pub fn placed_self_collision(
        &self,
        placement: &Placement,
        pairs: &[(LinkId, LinkId)],
        margin: f64,
    ) -> Option<(LinkId, LinkId)> {
        pairs
            .iter()
            .copied()
            .find(|&(a, b)| self.placed_pair_collides(placement, a, b, margin))
    }

    /// [`Self::first_collision`] over the placed links: the first of `links`
    /// that comes closer than `margin` to one of `objects` (links never placed
    /// collide with nothing).
    pub fn placed_collision(
        &self,
        placement: &Placement,
        links: &[LinkId],
        objects: &[&CollisionObject],
        margin: f64,
    ) -> Option<Hit> {
        links.iter().find_map(|&link| {
            let (placed, bounds) = placement.link(link)?;
            self.link_hit(link, placed, bounds, objects, margin)
        })
    }

    /// The first of `objects` that `link`, its parts placed as `placed` within
    /// `bounds`, comes closer than `margin` to.
    fn link_hit(
        &self,
        link: LinkId,
        placed: &[Placed],
        bounds: &Aabb,
        objects: &[&CollisionObject],
        margin: f64,
    ) -> Option<Hit> {
        let o = objects.iter().position(|object| {
            overlap(bounds, &object.bounds, margin)
                && self.link_parts(link).iter().zip(placed).any(|(lp, la)| {
                    object
                        .parts
                        .iter()
                        .zip(&object.placed)
                        .any(|(op, oa)| placed_collides(self.method, la, lp, oa, op, margin))
                })
        })?;
        Some(Hit { link, object: o })
    }
}

/// The collision parts of a robot's links placed for one configuration
/// ([`RobotCollision::place`]): each part's world pose and AABB and each
/// link's AABB, computed once and shared by every pair test at that
/// configuration.
#[derive(Debug, Clone, Default)]
pub struct Placement {
    parts: Vec<Vec<Placed>>,
    bounds: Vec<Aabb>,
}

impl Placement {
    /// A placed link's parts and box.
    fn link(&self, link: LinkId) -> Option<(&[Placed], &Aabb)> {
        Some((self.parts.get(link)?, self.bounds.get(link)?))
    }

    /// The world axis-aligned box of a placed link's parts, as (min, max)
    /// corners (min > max when the link has no part or was never placed).
    pub fn link_bounds(&self, link: LinkId) -> (Point3<f64>, Point3<f64>) {
        let b = self
            .bounds
            .get(link)
            .copied()
            .unwrap_or_else(Aabb::new_invalid);
        (to_point(b.mins), to_point(b.maxs))
    }
}
