//! Mesh cleaning: meshes as they come from CAD exports and scans.
//!
//! What: [`TriangleMesh::clean`] merges vertices at identical positions,
//! drops triangles that index a missing vertex, touch a non-finite vertex or
//! have zero area, removes vertices no triangle uses, and returns a
//! [`MeshCleanup`] with the counts and a first example of each problem.
//!
//! Why: real robot meshes have a stray zero-area triangle among thousands,
//! STL files repeat every vertex per triangle, and scans have NaNs. None of
//! that matters for collision or mass properties once removed, so the loader
//! cleans and reports instead of refusing. Open and non-manifold meshes are
//! kept as they are: whether a mesh is closed is a question for the caller
//! ([`TriangleMesh::is_closed`]).
//!
//! How: one pass keyed on the bit pattern of each position (with `-0.0`
//! folded into `0.0`; a fast keyed hash, see `WeldState`), then one pass over
//! the triangles; linear in the mesh size. "Zero area" is relative to the
//! mesh: area ≤ 1e-14 · diagonal², so millimetre and metre meshes are judged
//! alike.
//!
//! ```
//! use nalgebra::{Point3, Vector3};
//! use tsukami_body::mesh::TriangleMesh;
//! let mut m = TriangleMesh::cuboid(Vector3::new(1.0, 1.0, 1.0));
//! m.vertices.push(Point3::new(0.5, 0.5, 0.5)); // a duplicate of vertex 7
//! m.indices.push([0, 0, 1]); // zero area
//! let report = m.clean();
//! assert_eq!((report.merged_vertices, report.dropped_degenerate), (1, 1));
//! assert_eq!(m.indices.len(), 12);
//! assert!(m.is_closed());
//! ```

use std::collections::hash_map::RandomState;
use std::collections::HashMap;
use std::hash::{BuildHasher, Hasher};

use nalgebra::Point3;

use crate::mesh::TriangleMesh;

/// What [`TriangleMesh::clean`] changed. All zero for a tidy mesh.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct MeshCleanup {
    /// Triangles read from the file.
    pub triangles_in: usize,
    /// Triangles kept.
    pub triangles_out: usize,
    /// Vertices merged into another at the same position.
    pub merged_vertices: usize,
    /// Zero-area triangles dropped (including ones with a repeated corner).
    pub dropped_degenerate: usize,
    /// Triangles dropped because a corner is NaN or infinite.
    pub dropped_non_finite: usize,
    /// Triangles dropped because they index a vertex that does not exist.
    pub dropped_bad_index: usize,
    /// The first dropped triangle and why, e.g. `triangle 17 has zero area`.
    pub first_problem: Option<String>,
}

impl MeshCleanup {
    /// Total triangles dropped.
    pub fn dropped(&self) -> usize {
        self.dropped_degenerate + self.dropped_non_finite + self.dropped_bad_index
    }

    /// True when cleaning dropped a triangle (merging alone is routine: STL
    /// repeats vertices).
    pub fn dropped_any(&self) -> bool {
        self.dropped() > 0
    }

    /// One line for warnings: counts and the first example.
    pub fn summary(&self) -> String {
        let mut s = format!(
            "kept {} of {} triangles: dropped {} zero-area, {} non-finite, {} with a bad index; \
             merged {} duplicate vertices",
            self.triangles_out,
            self.triangles_in,
            self.dropped_degenerate,
            self.dropped_non_finite,
            self.dropped_bad_index,
            self.merged_vertices
        );
        if let Some(first) = &self.first_problem {
            s.push_str("; first: ");
            s.push_str(first);
        }
        s
    }
}

impl TriangleMesh {
    /// Cleans the mesh in place (see the module documentation) and says what
    /// changed. The result may have no triangles; callers decide whether
    /// that is an error.
    pub fn clean(&mut self) -> MeshCleanup {
        let mut report = MeshCleanup {
            triangles_in: self.indices.len(),
            ..MeshCleanup::default()
        };
        let n = self.vertices.len();
        let finite: Vec<bool> = self
            .vertices
            .iter()
            .map(|v| v.iter().all(|c| c.is_finite()))
            .collect();
        let (remap, merged) = weld(&self.vertices, &finite);
        report.merged_vertices = merged;
        let diag = finite_diagonal(&self.vertices, &finite);
        let min_area2 = (1e-14 * diag * diag).powi(2) * 4.0;
        let mut kept = Vec::with_capacity(self.indices.len());
        for (k, t) in self.indices.iter().enumerate() {
            let why = if t.iter().any(|&i| i as usize >= n) {
                report.dropped_bad_index += 1;
                format!("triangle {k} indexes vertex {t:?} but there are {n} vertices")
            } else if t.iter().any(|&i| !finite[i as usize]) {
                report.dropped_non_finite += 1;
                format!("triangle {k} has a non-finite corner")
            } else {
                let w = t.map(|i| remap[i as usize]);
                let [a, b, c] = w.map(|i| self.vertices[i as usize]);
                if w[0] != w[1]
                    && w[1] != w[2]
                    && w[0] != w[2]
                    && (b - a).cross(&(c - a)).norm_squared() > min_area2
                {
                    kept.push(w);
                    continue;
                }
                report.dropped_degenerate += 1;
                format!("triangle {k} {t:?} has zero area")
            };
            if report.first_problem.is_none() {
                report.first_problem = Some(why);
            }
        }
        self.indices = kept;
        self.compact();
        report.triangles_out = self.indices.len();
        report
    }

    /// Removes vertices no triangle uses and renumbers the rest in order.
    fn compact(&mut self) {
        let mut new_index = vec![u32::MAX; self.vertices.len()];
        let mut vertices = Vec::with_capacity(self.vertices.len());
        for t in &mut self.indices {
            for i in t.iter_mut() {
                let slot = &mut new_index[*i as usize];
                if *slot == u32::MAX {
                    *slot = vertices.len() as u32;
                    vertices.push(self.vertices[*i as usize]);
                }
                *i = *slot;
            }
        }
        self.vertices = vertices;
    }
}

/// For every vertex, the first vertex at the same position; and how many
/// finite vertices were merged into an earlier one.
fn weld(vertices: &[Point3<f64>], finite: &[bool]) -> (Vec<u32>, usize) {
    let mut first: HashMap<(u64, u64, u64), u32, WeldState> =
        HashMap::with_capacity_and_hasher(vertices.len() / 4, WeldState::new());
    let mut merged = 0;
    let remap = vertices
        .iter()
        .enumerate()
        .map(|(i, v)| {
            if !finite[i] {
                return i as u32;
            }
            // +0.0 folds -0.0 into 0.0.
            let key = (
                (v.x + 0.0).to_bits(),
                (v.y + 0.0).to_bits(),
                (v.z + 0.0).to_bits(),
            );
            let j = *first.entry(key).or_insert(i as u32);
            merged += usize::from(j != i as u32);
            j
        })
        .collect();
    (remap, merged)
}

/// The hash of [`weld`]'s map: a folded 64 × 64-bit multiply per coordinate
/// (a few nanoseconds, where the standard SipHash made welding a scan's
/// 300k corners take 10 ms), keyed per map by the standard library's random
/// state so a crafted file cannot make positions collide on purpose. The key
/// changes which bucket a position lands in, never which vertex it is merged
/// with: the result is the same on every run.
#[derive(Clone, Copy)]
struct WeldState(u64);

impl WeldState {
    fn new() -> Self {
        Self(RandomState::new().hash_one(0x7473_756b_616d_6921_u64) | 1)
    }
}

impl BuildHasher for WeldState {
    type Hasher = WeldHasher;
    fn build_hasher(&self) -> WeldHasher {
        WeldHasher(self.0)
    }
}

struct WeldHasher(u64);

impl Hasher for WeldHasher {
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut word = [0u8; 8];
            word[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(word));
        }
    }

    fn write_u64(&mut self, x: u64) {
        let p =
            u128::from(self.0 ^ x) * u128::from(0x9E37_79B9_7F4A_7C15u64 ^ self.0.rotate_left(29));
        self.0 = (p as u64) ^ ((p >> 64) as u64);
    }

    fn finish(&self) -> u64 {
        self.0
    }
}

fn finite_diagonal(vertices: &[Point3<f64>], finite: &[bool]) -> f64 {
    let mut lo = Point3::from([f64::INFINITY; 3]);
    let mut hi = Point3::from([f64::NEG_INFINITY; 3]);
    for (v, _) in vertices.iter().zip(finite).filter(|(_, &f)| f) {
        lo = lo.inf(v);
        hi = hi.sup(v);
    }
    if lo.x.is_finite() {
        (hi - lo).norm()
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    /// An STL-style soup: every triangle has its own three vertices.
    fn soup(m: &TriangleMesh) -> TriangleMesh {
        let vertices = (0..m.indices.len()).flat_map(|k| m.triangle(k)).collect();
        let indices = (0..m.indices.len() as u32)
            .map(|k| [3 * k, 3 * k + 1, 3 * k + 2])
            .collect();
        TriangleMesh { vertices, indices }
    }

    #[test]
    fn a_soup_welds_back_into_a_closed_mesh() {
        let cyl = TriangleMesh::cylinder(0.03, 0.1, 16);
        let mut s = soup(&cyl);
        let r = s.clean();
        assert_eq!(r.dropped(), 0);
        assert_eq!(s.vertices.len(), cyl.vertices.len());
        assert_eq!(
            r.merged_vertices,
            3 * cyl.indices.len() - cyl.vertices.len()
        );
        assert!(s.is_closed());
        assert!((s.volume() - cyl.volume()).abs() < 1e-15);
    }

    #[test]
    fn bad_triangles_are_dropped_and_counted() {
        let mut m = TriangleMesh::cuboid(Vector3::new(1.0, 1.0, 1.0));
        m.vertices.push(Point3::new(f64::NAN, 0.0, 0.0));
        m.vertices.push(Point3::new(0.5, 0.5, 0.5)); // same place as vertex 7
        m.indices.push([0, 1, 8]); // non-finite
        m.indices.push([0, 1, 77]); // bad index
        m.indices.insert(0, [7, 9, 3]); // zero area after welding
        m.indices.push([0, 1, 1]); // repeated corner
        let r = m.clean();
        assert_eq!(
            (
                r.dropped_non_finite,
                r.dropped_bad_index,
                r.dropped_degenerate
            ),
            (1, 1, 2)
        );
        assert_eq!((r.triangles_in, r.triangles_out), (16, 12));
        assert_eq!(
            r.first_problem.as_deref(),
            Some("triangle 0 [7, 9, 3] has zero area")
        );
        assert!(r
            .summary()
            .contains("dropped 2 zero-area, 1 non-finite, 1 with a bad index"));
        assert_eq!(m.vertices.len(), 8);
        assert!(m.is_closed());
        assert!(m.validate().is_ok());
    }

    #[test]
    fn slivers_of_real_size_are_kept_and_open_meshes_stay_open() {
        // A thin but real triangle (1 µm tall on a 1 m mesh) is not zero area.
        let mut m = TriangleMesh {
            vertices: vec![
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(1.0, 0.0, 0.0),
                Point3::new(0.5, 1e-6, 0.0),
                Point3::new(0.0, 1.0, 0.0),
            ],
            indices: vec![[0, 1, 2], [0, 2, 3]],
        };
        let r = m.clean();
        assert_eq!(r.dropped(), 0);
        assert_eq!(m.indices.len(), 2);
        assert!(!m.is_closed());
    }
}
