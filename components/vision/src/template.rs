//! Object templates: what the detector knows about a model — surface samples
//! with normals in a k-d tree, principal axes, size and symmetry.
//!
//! What: [`ObjectTemplate::from_model`] turns a [`tsukami_body`] object (its
//! triangles in the object frame) into a template; [`ObjectTemplate::load`]
//! finds `objects/<name>/object.toml` inside the model roots.
//!
//! Why: ICP needs the nearest model point and its normal for every measured
//! point, many thousands of times per detection; hypotheses need the model's
//! principal axes; verification needs the surface seen from the camera.
//!
//! How: the surface is sampled area-uniformly (deterministic ChaCha stream)
//! at a given spacing, each sample carrying its triangle's outward normal;
//! samples go into a `kiddo` k-d tree, and a voxel grid
//! ([`crate::lookup`]) remembers the nearest sample per cell for the coarse
//! stages. Principal axes come from the samples
//! ([`crate::cloud::Moments`]), symmetry from [`crate::symmetry`] with
//! parry's exact point-to-mesh distance.

use std::path::Path;

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use nalgebra::{Isometry3, Point3, Vector3};
use parry3d_f64::math::Vector as PVec;
use parry3d_f64::query::PointQuery;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tsukami_body::collision::build_trimesh;
use tsukami_body::files::ModelRoots;
use tsukami_body::object::ObjectModel;

use crate::cloud::Moments;
use crate::error::{Result, VisionError};
use crate::lookup::SampleGrid;
use crate::symmetry::Symmetry;

/// Default distance between surface samples (m).
pub const SAMPLE_SPACING: f64 = 0.002;
/// Most samples a template keeps.
const MAX_SAMPLES: usize = 60_000;
/// Edge of a cell of the nearest-sample grid (m).
pub const LOOKUP_CELL: f64 = 0.003;
/// The nearest-sample grid reaches this far beyond the model's box (m).
pub const LOOKUP_MARGIN: f64 = 0.04;

/// A detector's model of one object.
pub struct ObjectTemplate {
    /// Object name.
    pub name: String,
    /// The object as loaded (mass, friction, mesh).
    pub model: ObjectModel,
    /// Surface samples in the object frame.
    pub points: Vec<Point3<f64>>,
    /// Outward unit normal of each sample.
    pub normals: Vec<Vector3<f64>>,
    tree: ImmutableKdTree<f64, 3>,
    lookup: SampleGrid,
    /// Principal axes of the surface.
    pub moments: Moments,
    /// Largest distance of a sample from the centroid (m).
    pub radius: f64,
    /// The model's self-motions.
    pub symmetry: Symmetry,
}

impl std::fmt::Debug for ObjectTemplate {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ObjectTemplate")
            .field("name", &self.name)
            .field("samples", &self.points.len())
            .field("radius", &self.radius)
            .field("symmetry", &self.symmetry)
            .finish()
    }
}

/// True for names that can only mean a folder directly under `objects/`.
pub fn is_plain_name(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= 64
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}

impl ObjectTemplate {
    /// Loads `objects/<name>/object.toml` from inside `roots` (the name must be
    /// a plain folder name; nothing outside the roots is opened).
    pub fn load(roots: &ModelRoots, name: &str) -> Result<Self> {
        let model_err = |message: String| VisionError::Model {
            object: name.chars().take(64).collect(),
            message,
        };
        if !is_plain_name(name) {
            return Err(model_err(
                "an object name is a folder name under objects/ (letters, digits, '_', '-')".into(),
            ));
        }
        let file = roots
            .resolve(&format!("objects/{name}/object.toml"))
            .map_err(|e| model_err(e.to_string()))?;
        let model = ObjectModel::load(file.path()).map_err(|e| model_err(e.to_string()))?;
        Self::from_model(name, model, SAMPLE_SPACING)
    }

    /// Loads an object TOML file given by path (command-line use).
    pub fn load_file(path: &Path) -> Result<Self> {
        let model = ObjectModel::load(path)?;
        let name = model.name.clone();
        Self::from_model(&name, model, SAMPLE_SPACING)
    }

    /// Builds a template from a loaded object, sampling its surface every
    /// `spacing` metres on average.
    pub fn from_model(name: &str, model: ObjectModel, spacing: f64) -> Result<Self> {
        let model_err = |message: String| VisionError::Model {
            object: name.to_owned(),
            message,
        };
        let mesh = &model.mesh;
        let (trimesh, _closed) = build_trimesh(mesh).map_err(model_err)?;
        let areas: Vec<f64> = (0..mesh.indices.len())
            .map(|k| mesh.triangle_area(k))
            .collect();
        let total: f64 = areas.iter().sum();
        if !(total.is_finite() && total > 0.0) {
            return Err(model_err("the surface has no area".into()));
        }
        let n = ((total / (spacing * spacing)) as usize).clamp(500, MAX_SAMPLES);
        let mut cumulative = Vec::with_capacity(areas.len());
        let mut acc = 0.0;
        for a in &areas {
            acc += a;
            cumulative.push(acc);
        }
        let mut rng = ChaCha8Rng::seed_from_u64(0x7375_6b61_6d69);
        let (mut points, mut normals) = (Vec::with_capacity(n), Vec::with_capacity(n));
        for _ in 0..n {
            let x = rng.random::<f64>() * total;
            let k = cumulative.partition_point(|c| *c < x).min(areas.len() - 1);
            let [a, b, c] = mesh.triangle(k);
            let (r1, r2): (f64, f64) = (rng.random(), rng.random());
            let s = r1.sqrt();
            let p = a.coords * (1.0 - s) + b.coords * (s * (1.0 - r2)) + c.coords * (s * r2);
            points.push(Point3::from(p));
            normals.push(mesh.triangle_normal(k));
        }
        let moments = Moments::of_surface((0..mesh.indices.len()).map(|k| mesh.triangle(k)))
            .ok_or_else(|| model_err("degenerate surface".into()))?;
        let radius = points
            .iter()
            .map(|p| (p - moments.centroid).norm())
            .fold(0.0, f64::max);
        let sym_points: Vec<Point3<f64>> =
            points.iter().step_by((n / 600).max(1)).copied().collect();
        let tol = (0.004 * radius).max(0.0006);
        let on_surface = |g: &Isometry3<f64>| {
            let mut sum2 = 0.0;
            for p in &sym_points {
                let q = g * p;
                let proj = trimesh.project_local_point(PVec::new(q.x, q.y, q.z), false);
                let d = ((proj.point.x - q.x).powi(2)
                    + (proj.point.y - q.y).powi(2)
                    + (proj.point.z - q.z).powi(2))
                .sqrt();
                if d > 4.0 * tol {
                    return false;
                }
                sum2 += d * d;
            }
            (sum2 / sym_points.len() as f64).sqrt() < tol
        };
        let symmetry = Symmetry::detect(&moments.centroid, &moments.axes, on_surface);
        let entries: Vec<[f64; 3]> = points.iter().map(|p| [p.x, p.y, p.z]).collect();
        let tree = ImmutableKdTree::new_from_slice(&entries)
            .map_err(|e| model_err(format!("cannot build the k-d tree: {e:?}")))?;
        let (lo, hi) = model.mesh.aabb();
        let m = nalgebra::Vector3::repeat(LOOKUP_MARGIN);
        let lookup = SampleGrid::build(lo - m, hi + m, LOOKUP_CELL, &points);
        Ok(ObjectTemplate {
            name: name.to_owned(),
            model,
            points,
            normals,
            tree,
            lookup,
            moments,
            radius,
            symmetry,
        })
    }

    /// The nearest surface sample to an object-frame point: its index and the
    /// squared distance.
    #[inline]
    pub fn nearest(&self, p: &Point3<f64>) -> (usize, f64) {
        let r = self
            .tree
            .query(&[p.x, p.y, p.z])
            .nearest_one::<SquaredEuclidean<f64>>()
            .execute();
        (r.item as usize, r.distance)
    }

    /// The surface sample the lookup grid pairs with an object-frame point
    /// (the nearest to its cell's centre) and its squared distance from the
    /// point; the distance is infinite for a point outside the grid, which
    /// is farther than [`LOOKUP_MARGIN`] from the surface.
    #[inline]
    pub fn nearest_fast(&self, p: &Point3<f64>) -> (usize, f64) {
        match self.lookup.get(p) {
            Some(j) => {
                let j = j as usize;
                (j, (self.points[j] - p).norm_squared())
            }
            None => (0, f64::INFINITY),
        }
    }

    /// The nearest sample, exactly or by the lookup grid.
    #[inline]
    pub fn pair(&self, p: &Point3<f64>, fast: bool) -> (usize, f64) {
        if fast {
            self.nearest_fast(p)
        } else {
            self.nearest(p)
        }
    }

    /// The lowest point of the model under `rotation` (for resting poses):
    /// `min over vertices of (R v).z`.
    pub fn lowest_z(&self, rotation: &nalgebra::UnitQuaternion<f64>) -> f64 {
        self.model
            .mesh
            .vertices
            .iter()
            .map(|v| (rotation * v).z)
            .fold(f64::INFINITY, f64::min)
    }
}
