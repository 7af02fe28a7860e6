//! A drawing: named groups of world-frame triangles, one flat colour each.
//!
//! What: [`Drawing`] and its [`Group`]s, with the shapes a grasp picture
//! needs: a placed collision part (box, sphere, capsule, cylinder, mesh), a
//! triangle mesh, a ball-shaped marker and a cone.
//!
//! Why: the renderer and the glTF writer share one tessellation, so the
//! picture and the `.glb` show the same scene.
//!
//! How: parry's `to_trimesh` tessellates the primitive shapes; vertices are
//! moved into the world frame at once, so a group is just positions and
//! triangles.
//!
//! ```
//! use nalgebra::{Point3, Vector3};
//! use tsukami_render::drawing::{Drawing, Rgba};
//! let mut d = Drawing::default();
//! d.cone("cone", Rgba::CONE, &Point3::origin(), &Vector3::z(), 0.3, 0.02);
//! let (lo, hi) = d.bounds().unwrap();
//! assert!((hi.z - 0.02).abs() < 1e-12 && lo.z.abs() < 1e-12);
//! ```

use nalgebra::{Isometry3, Point3, Rotation3, Vector3};
use tsukami_body::collision::Part;
use tsukami_body::convert::{from_pose, to_point};
use tsukami_body::mesh::TriangleMesh;

/// Segments around a round shape.
const ROUND_SUBDIVISIONS: u32 = 24;

/// A colour: linear red, green, blue and opacity in `[0, 1]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rgba(pub [f32; 4]);

impl Rgba {
    /// The robot's body and arm.
    pub const ROBOT: Rgba = Rgba([0.62, 0.64, 0.70, 1.0]);
    /// The hand (palm and fingers).
    pub const HAND: Rgba = Rgba([0.95, 0.55, 0.12, 1.0]);
    /// The object to grasp.
    pub const OBJECT: Rgba = Rgba([0.12, 0.42, 0.95, 1.0]);
    /// Tables, shelves and other obstacles: see-through, so a fridge's walls
    /// do not hide the grasp inside.
    pub const OBSTACLE: Rgba = Rgba([0.55, 0.42, 0.28, 0.4]);
    /// Contact markers.
    pub const CONTACT: Rgba = Rgba([0.95, 0.08, 0.08, 1.0]);
    /// Friction cones (translucent).
    pub const CONE: Rgba = Rgba([0.15, 0.85, 0.30, 0.45]);

    /// True when the colour is see-through.
    pub fn is_translucent(&self) -> bool {
        self.0[3] < 1.0
    }
}

/// One named, single-coloured set of triangles in the world frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Group {
    /// What it shows (`link r_palm`, `object can`, `contact 2`, …).
    pub name: String,
    /// Its colour.
    pub color: Rgba,
    /// Vertex positions (m, world frame).
    pub positions: Vec<Point3<f64>>,
    /// Triangles as indices into `positions`, counter-clockwise seen from
    /// outside.
    pub triangles: Vec<[u32; 3]>,
    /// An annotation the picture shows in front of everything else (contact
    /// markers sit half inside the object, under a fingertip).
    pub on_top: bool,
}

/// Everything to draw.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Drawing {
    /// The groups, in drawing order.
    pub groups: Vec<Group>,
}

impl Drawing {
    /// Adds a group; empty ones are dropped.
    pub fn push(
        &mut self,
        name: &str,
        color: Rgba,
        positions: Vec<Point3<f64>>,
        triangles: Vec<[u32; 3]>,
    ) {
        if !triangles.is_empty() {
            self.groups.push(Group {
                name: name.to_owned(),
                color,
                positions,
                triangles,
                on_top: false,
            });
        }
    }

    /// Adds a collision part of a link or obstacle whose frame is at `pose`.
    /// Returns false for a shape kind this viewer does not tessellate.
    pub fn part(&mut self, name: &str, color: Rgba, pose: &Isometry3<f64>, part: &Part) -> bool {
        let shape = &part.shape;
        let (vertices, triangles) = if let Some(c) = shape.as_cuboid() {
            c.to_trimesh()
        } else if let Some(b) = shape.as_ball() {
            b.to_trimesh(ROUND_SUBDIVISIONS, ROUND_SUBDIVISIONS / 2)
        } else if let Some(c) = shape.as_capsule() {
            c.to_trimesh(ROUND_SUBDIVISIONS, ROUND_SUBDIVISIONS / 4)
        } else if let Some(c) = shape.as_cylinder() {
            c.to_trimesh(ROUND_SUBDIVISIONS)
        } else if let Some(m) = shape.as_trimesh() {
            (m.vertices().to_vec(), m.indices().to_vec())
        } else {
            return false;
        };
        let at = pose * from_pose(&part.origin);
        let positions = vertices.into_iter().map(|v| at * to_point(v)).collect();
        self.push(name, color, positions, triangles);
        true
    }

    /// Adds a triangle mesh placed at `pose`.
    pub fn mesh(&mut self, name: &str, color: Rgba, pose: &Isometry3<f64>, mesh: &TriangleMesh) {
        let positions = mesh.vertices.iter().map(|v| pose * v).collect();
        self.push(name, color, positions, mesh.indices.clone());
    }

    /// Adds a ball of `radius` at `center`, drawn on top (see [`Group::on_top`]).
    pub fn marker(&mut self, name: &str, color: Rgba, center: &Point3<f64>, radius: f64) {
        let (vertices, triangles) = parry3d_f64::shape::Ball::new(radius)
            .to_trimesh(ROUND_SUBDIVISIONS / 2, ROUND_SUBDIVISIONS / 4);
        let positions = vertices
            .into_iter()
            .map(|v| center + to_point(v).coords)
            .collect();
        self.push(name, color, positions, triangles);
        if let Some(g) = self.groups.last_mut() {
            g.on_top = true;
        }
    }

    /// Adds a cone with its apex at `apex`, opening along `axis` with
    /// `half_angle` (rad) and `height` (m), closed by its base disc.
    pub fn cone(
        &mut self,
        name: &str,
        color: Rgba,
        apex: &Point3<f64>,
        axis: &Vector3<f64>,
        half_angle: f64,
        height: f64,
    ) {
        let n = ROUND_SUBDIVISIONS;
        let radius = height * half_angle.tan();
        let turn = Rotation3::rotation_between(&Vector3::z(), axis).unwrap_or_else(|| {
            Rotation3::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
        });
        let mut positions = vec![*apex, apex + turn * Vector3::new(0.0, 0.0, height)];
        for k in 0..n {
            let a = std::f64::consts::TAU * f64::from(k) / f64::from(n);
            positions.push(apex + turn * Vector3::new(radius * a.cos(), radius * a.sin(), height));
        }
        let rim = |k: u32| 2 + k % n;
        let triangles = (0..n)
            .flat_map(|k| [[0, rim(k + 1), rim(k)], [1, rim(k), rim(k + 1)]])
            .collect();
        self.push(name, color, positions, triangles);
    }

    /// The axis-aligned box around every vertex, or `None` when empty.
    pub fn bounds(&self) -> Option<(Point3<f64>, Point3<f64>)> {
        let mut points = self.groups.iter().flat_map(|g| g.positions.iter());
        let first = *points.next()?;
        Some(points.fold((first, first), |(lo, hi), p| (lo.inf(p), hi.sup(p))))
    }

    /// Triangles in all groups.
    pub fn triangle_count(&self) -> usize {
        self.groups.iter().map(|g| g.triangles.len()).sum()
    }
}
