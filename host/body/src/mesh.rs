//! Triangle meshes: the [`TriangleMesh`] type, validation, watertightness,
//! volume and area, and generators for closed meshes of revolution and boxes.
//!
//! A [`TriangleMesh`] is plain data (vertices and index triples in the mesh's
//! own frame) that callers such as the grasp planner can read directly, e.g.
//! to fit the object's convex boxes (OCP). Files are read and written in
//! [`crate::mesh_io`] (STL, OBJ, PLY, Collada), and meshes as they come are
//! cleaned in [`crate::mesh_clean`]: duplicate vertices merged, zero-area,
//! non-finite and badly indexed triangles dropped and counted. Open and
//! non-manifold meshes load; whether a mesh is closed (every edge shared by
//! exactly two triangles, consistently oriented) is reported by
//! [`TriangleMesh::is_closed`], so callers can choose a fallback where a
//! solid is needed.
//!
//! ```
//! use tsukami_body::mesh::TriangleMesh;
//! let can = TriangleMesh::cylinder(0.033, 0.122, 32);
//! assert!(can.is_closed());
//! assert!((can.volume() - std::f64::consts::PI * 0.033f64.powi(2) * 0.122).abs() < 2e-5);
//! ```

use nalgebra::{Point3, Vector3};
use std::collections::HashMap;

/// A triangle mesh in its own frame: vertices and counter-clockwise
/// (outward-facing, seen from outside) index triples.
#[derive(Debug, Clone, PartialEq)]
pub struct TriangleMesh {
    /// Vertex positions (metres).
    pub vertices: Vec<Point3<f64>>,
    /// Triangles as indices into `vertices`.
    pub indices: Vec<[u32; 3]>,
}

impl TriangleMesh {
    /// Checks that the mesh has triangles, finite vertices, indices in range
    /// and no zero-area triangle. Returns a message describing the first
    /// problem found.
    pub fn validate(&self) -> std::result::Result<(), String> {
        if self.indices.is_empty() {
            return Err("the mesh has no triangles".into());
        }
        if let Some(i) = self
            .vertices
            .iter()
            .position(|v| !v.iter().all(|c| c.is_finite()))
        {
            return Err(format!("vertex {i} is not finite: {:?}", self.vertices[i]));
        }
        let n = self.vertices.len() as u32;
        let scale = self.bounding_diagonal().max(f64::MIN_POSITIVE);
        for (k, t) in self.indices.iter().enumerate() {
            if t.iter().any(|&i| i >= n) {
                return Err(format!(
                    "triangle {k} indexes vertex {t:?} but there are {n} vertices"
                ));
            }
            // Zero area, relative to the mesh size so millimetre and metre
            // meshes are judged alike.
            if self.triangle_area(k) <= 1e-14 * scale * scale {
                return Err(format!("triangle {k} {t:?} is degenerate (zero area)"));
            }
        }
        Ok(())
    }

    /// Area of triangle `k`.
    pub fn triangle_area(&self, k: usize) -> f64 {
        let [a, b, c] = self.triangle(k);
        (b - a).cross(&(c - a)).norm() * 0.5
    }

    /// The three corners of triangle `k`.
    pub fn triangle(&self, k: usize) -> [Point3<f64>; 3] {
        let t = self.indices[k];
        [
            self.vertices[t[0] as usize],
            self.vertices[t[1] as usize],
            self.vertices[t[2] as usize],
        ]
    }

    /// Length of the diagonal of the axis-aligned bounding box (0 if empty).
    pub fn bounding_diagonal(&self) -> f64 {
        let (lo, hi) = self.aabb();
        (hi - lo).norm()
    }

    /// Axis-aligned bounding box `(min, max)`.
    pub fn aabb(&self) -> (Point3<f64>, Point3<f64>) {
        let mut lo = Point3::from(Vector3::repeat(f64::INFINITY));
        let mut hi = Point3::from(Vector3::repeat(f64::NEG_INFINITY));
        for v in &self.vertices {
            lo = lo.inf(v);
            hi = hi.sup(v);
        }
        if self.vertices.is_empty() {
            (Point3::origin(), Point3::origin())
        } else {
            (lo, hi)
        }
    }

    /// True when the mesh is closed and consistently oriented: after merging
    /// vertices at identical positions, every directed edge appears exactly
    /// once and its reverse appears exactly once. Such a mesh bounds a solid.
    pub fn is_closed(&self) -> bool {
        let welded = self.welded_indices();
        let mut edges: HashMap<(u32, u32), u32> = HashMap::with_capacity(welded.len() * 3);
        for t in &welded {
            for e in 0..3 {
                *edges.entry((t[e], t[(e + 1) % 3])).or_insert(0) += 1;
            }
        }
        edges
            .iter()
            .all(|(&(a, b), &count)| count == 1 && edges.get(&(b, a)) == Some(&1))
    }

    /// Index triples where vertices at bit-identical positions share one index
    /// (STL files repeat each vertex per triangle).
    fn welded_indices(&self) -> Vec<[u32; 3]> {
        let mut first: HashMap<[u64; 3], u32> = HashMap::with_capacity(self.vertices.len());
        let remap: Vec<u32> = self
            .vertices
            .iter()
            .enumerate()
            .map(|(i, v)| {
                let key = [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
                *first.entry(key).or_insert(i as u32)
            })
            .collect();
        self.indices
            .iter()
            .map(|t| {
                [
                    remap[t[0] as usize],
                    remap[t[1] as usize],
                    remap[t[2] as usize],
                ]
            })
            .collect()
    }

    /// Signed volume (divergence theorem); positive for a closed mesh with
    /// outward normals.
    pub fn volume(&self) -> f64 {
        (0..self.indices.len())
            .map(|k| {
                let [a, b, c] = self.triangle(k);
                a.coords.dot(&b.coords.cross(&c.coords)) / 6.0
            })
            .sum()
    }

    /// Total surface area.
    pub fn area(&self) -> f64 {
        (0..self.indices.len()).map(|k| self.triangle_area(k)).sum()
    }

    /// Outward unit normal of triangle `k` (from the winding).
    pub fn triangle_normal(&self, k: usize) -> Vector3<f64> {
        let [a, b, c] = self.triangle(k);
        (b - a).cross(&(c - a)).normalize()
    }

    /// A closed solid of revolution about the z axis. `profile` lists
    /// `(radius, z)` pairs from bottom to top, every radius > 0; the bottom
    /// and top are closed with flat caps. `segments` is the number of
    /// divisions around the axis (at least 3).
    pub fn lathe(profile: &[(f64, f64)], segments: usize) -> Self {
        let segments = segments.max(3);
        let rings = profile.len();
        let mut vertices = Vec::with_capacity(rings * segments + 2);
        for &(r, z) in profile {
            for s in 0..segments {
                let a = std::f64::consts::TAU * s as f64 / segments as f64;
                vertices.push(Point3::new(r * a.cos(), r * a.sin(), z));
            }
        }
        let bottom = vertices.len() as u32;
        vertices.push(Point3::new(0.0, 0.0, profile[0].1));
        let top = vertices.len() as u32;
        vertices.push(Point3::new(0.0, 0.0, profile[rings - 1].1));
        let idx = |ring: usize, s: usize| (ring * segments + s % segments) as u32;
        let mut indices = Vec::with_capacity(2 * segments * rings);
        for ring in 0..rings - 1 {
            for s in 0..segments {
                let (a, b) = (idx(ring, s), idx(ring, s + 1));
                let (c, d) = (idx(ring + 1, s), idx(ring + 1, s + 1));
                // Counter-clockwise seen from outside.
                indices.push([a, b, d]);
                indices.push([a, d, c]);
            }
        }
        for s in 0..segments {
            indices.push([bottom, idx(0, s + 1), idx(0, s)]);
            indices.push([top, idx(rings - 1, s), idx(rings - 1, s + 1)]);
        }
        Self { vertices, indices }
    }

    /// A closed cylinder of `radius` and `height`, its base on z = 0.
    pub fn cylinder(radius: f64, height: f64, segments: usize) -> Self {
        Self::lathe(&[(radius, 0.0), (radius, height)], segments)
    }

    /// A closed box with edge lengths `size`, centred on the origin.
    pub fn cuboid(size: Vector3<f64>) -> Self {
        let h = size * 0.5;
        let vertices = (0..8)
            .map(|i| {
                Point3::new(
                    if i & 1 == 0 { -h.x } else { h.x },
                    if i & 2 == 0 { -h.y } else { h.y },
                    if i & 4 == 0 { -h.z } else { h.z },
                )
            })
            .collect();
        let indices = vec![
            [0, 2, 3],
            [0, 3, 1], // -z
            [4, 5, 7],
            [4, 7, 6], // +z
            [0, 1, 5],
            [0, 5, 4], // -y
            [2, 6, 7],
            [2, 7, 3], // +y
            [0, 4, 6],
            [0, 6, 2], // -x
            [1, 3, 7],
            [1, 7, 5], // +x
        ];
        Self { vertices, indices }
    }

    /// A closed UV sphere of `radius` centred on the origin, with `rings`
    /// latitude bands and `segments` longitudes (about `2·rings·segments`
    /// triangles). Used to build large test meshes.
    pub fn uv_sphere(radius: f64, rings: usize, segments: usize) -> Self {
        let rings = rings.max(2);
        let profile: Vec<(f64, f64)> = (1..rings)
            .map(|i| {
                let t = std::f64::consts::PI * i as f64 / rings as f64;
                (radius * t.sin(), -radius * t.cos())
            })
            .collect();
        let mut m = Self::lathe(&profile, segments);
        // Replace the flat caps' centres by the poles.
        let n = m.vertices.len();
        m.vertices[n - 2] = Point3::new(0.0, 0.0, -radius);
        m.vertices[n - 1] = Point3::new(0.0, 0.0, radius);
        m
    }

    /// A closed torus lying on `z = 0` about the z axis: a tube of radius
    /// `tube` swept along a circle of radius `ring` (`ring > tube`), with
    /// `around` divisions along the ring and `across` around the tube.
    pub fn torus(ring: f64, tube: f64, around: u32, across: u32) -> Self {
        let (around, across) = (around.max(3), across.max(3));
        let mut vertices = Vec::with_capacity((around * across) as usize);
        for i in 0..around {
            let a = std::f64::consts::TAU * i as f64 / around as f64;
            for j in 0..across {
                let b = std::f64::consts::TAU * j as f64 / across as f64;
                let rho = ring + tube * b.cos();
                vertices.push(Point3::new(
                    rho * a.cos(),
                    rho * a.sin(),
                    tube * (1.0 + b.sin()),
                ));
            }
        }
        let at = |i: u32, j: u32| (i % around) * across + j % across;
        let mut indices = Vec::with_capacity((2 * around * across) as usize);
        for i in 0..around {
            for j in 0..across {
                let (p, q, u, v) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                indices.extend([[p, q, u], [p, u, v]]);
            }
        }
        Self { vertices, indices }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generated_meshes_are_closed_and_outward() {
        let c = TriangleMesh::cylinder(0.033, 0.122, 24);
        assert!(c.validate().is_ok());
        assert!(c.is_closed());
        assert!(c.volume() > 0.0);
        let b = TriangleMesh::cuboid(Vector3::new(0.1, 0.2, 0.3));
        assert!(b.is_closed());
        assert!((b.volume() - 0.006).abs() < 1e-12);
        let s = TriangleMesh::uv_sphere(0.1, 16, 32);
        assert!(s.is_closed());
        let exact = 4.0 / 3.0 * std::f64::consts::PI * 1e-3;
        assert!((s.volume() - exact).abs() / exact < 0.03);
        let t = TriangleMesh::torus(0.04, 0.015, 48, 16);
        assert!(t.validate().is_ok());
        assert!(t.is_closed());
        // 2π² R r², and it rests on z = 0.
        let exact = 2.0 * std::f64::consts::PI.powi(2) * 0.04 * 0.015f64.powi(2);
        assert!((t.volume() - exact).abs() / exact < 0.03, "{}", t.volume());
        let lowest = t.vertices.iter().map(|v| v.z).fold(f64::INFINITY, f64::min);
        assert!(lowest.abs() < 1e-12);
    }

    #[test]
    fn open_and_flipped_meshes_are_not_closed() {
        let mut b = TriangleMesh::cuboid(Vector3::new(1.0, 1.0, 1.0));
        b.indices.pop();
        assert!(!b.is_closed());
        let mut f = TriangleMesh::cuboid(Vector3::new(1.0, 1.0, 1.0));
        f.indices[0].swap(1, 2);
        assert!(!f.is_closed());
    }

    #[test]
    fn validation_rejects_bad_meshes() {
        let empty = TriangleMesh {
            vertices: vec![Point3::origin()],
            indices: vec![],
        };
        assert!(empty.validate().unwrap_err().contains("no triangles"));
        let mut nan = TriangleMesh::cuboid(Vector3::new(1.0, 1.0, 1.0));
        nan.vertices[3].y = f64::NAN;
        assert!(nan.validate().unwrap_err().contains("vertex 3"));
        let mut degenerate = TriangleMesh::cuboid(Vector3::new(1.0, 1.0, 1.0));
        degenerate.indices[5] = [0, 0, 1];
        assert!(degenerate.validate().unwrap_err().contains("triangle 5"));
        let mut range = TriangleMesh::cuboid(Vector3::new(1.0, 1.0, 1.0));
        range.indices[2] = [0, 1, 99];
        assert!(range.validate().unwrap_err().contains("triangle 2"));
    }
}
