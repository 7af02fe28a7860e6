//! Object meshes as they come: edge topology, consistent winding, and the
//! solid a planner may use for inside tests.
//!
//! What: [`prepare`] takes a cleaned mesh (vertices welded, zero-area
//! triangles dropped: `TriangleMesh::clean`) and
//! - counts its edges: boundary edges (one triangle: the mesh is open),
//!   non-manifold edges (more than two triangles, e.g. a mug whose handle
//!   touches the body along an edge) and edges whose two triangles are wound
//!   alike (inconsistent winding);
//! - winds every connected patch consistently (triangles flipped to agree
//!   with their neighbours across manifold edges) and outward (a patch whose
//!   signed volume is negative is turned inside out, only when the winding
//!   had to be repaired or the whole mesh is inside out);
//! - says whether the result is **closed** (every edge's two directions are
//!   used equally often: true for a closed non-manifold mug) and whether it
//!   can serve as a **solid** (it could be wound consistently), and lists
//!   what was done as warnings for the `set_object` reply.
//!
//! Why: scans and CAD exports are open, non-manifold or wound at random, and
//! a grasp planner must still plan on them. A closed mesh, manifold or not,
//! bounds a volume: its divergence-theorem volume and centroid are exact and
//! parry's oriented pseudo-normals answer inside tests. An open mesh gets the
//! documented fallback: the same pseudo-normal inside test, which is right
//! everywhere except for points whose nearest surface feature is a hole's rim
//! (there the hole behaves roughly as if capped by the rim's tangent plane),
//! and mass properties from the convex hull ([`hull_centroid`]). A mesh that
//! cannot be wound consistently (a Möbius-like scan) is used as a surface only,
//! and the reply says so. Nothing is refused for being untidy.
//!
//! How: the edges of all triangles are sorted once (bucketed by their smaller
//! vertex, then by the larger one: no hash map), a breadth-first walk over
//! manifold edges assigns flips, and one pass counts the edge kinds after the
//! flips.
//!
//! ```
//! use nalgebra::Vector3;
//! use tsukami_body::mesh::TriangleMesh;
//! use tsukami_planner_kit::mesh_topology::prepare;
//! let mut open = TriangleMesh::cuboid(Vector3::new(0.1, 0.1, 0.1));
//! open.indices.pop(); // a missing triangle: a hole with three rim edges
//! open.indices[0].swap(1, 2); // and one triangle wound the wrong way
//! let t = prepare(&mut open);
//! assert_eq!((t.boundary_edges, t.flipped, t.closed, t.solid), (3, 1, false, true));
//! assert!(t.warnings.iter().any(|w| w.contains("open mesh")));
//! ```

use nalgebra::{Point3, Vector3};
use tsukami_body::mesh::TriangleMesh;

/// What [`prepare`] found and did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Topology {
    /// Edges used by one triangle only (rims of holes).
    pub boundary_edges: usize,
    /// Edges used by more than two triangles.
    pub non_manifold_edges: usize,
    /// Triangles flipped to agree with their neighbours or to face outward.
    pub flipped: usize,
    /// Manifold edges whose triangles could not be made to agree (0 when the
    /// surface is orientable).
    pub conflicts: usize,
    /// Every edge is used equally often in both directions: the mesh bounds
    /// a volume (possibly a non-manifold one).
    pub closed: bool,
    /// The winding is consistent, so inside tests by oriented pseudo-normals
    /// work (exactly when closed; except near hole rims when open).
    pub solid: bool,
    /// What was done, one sentence each, for the `set_object` reply.
    pub warnings: Vec<String>,
}

/// One use of an edge by a triangle: the edge's sorted vertex pair packed in
/// a `u64`, the triangle, and whether the triangle runs it low → high.
#[derive(Clone, Copy)]
struct EdgeUse {
    key: u64,
    tri: u32,
    forward: bool,
}

/// Every edge use, sorted by (edge, triangle): counted into buckets by the
/// edge's smaller vertex (in triangle order), then each bucket — the few
/// edges around one vertex — sorted stably by the larger vertex. Linear but
/// for the buckets' sorts, and no comparison of all 3n uses.
fn edge_uses(indices: &[[u32; 3]]) -> Vec<EdgeUse> {
    let edge = |t: &[u32; 3], e: usize| (t[e], t[(e + 1) % 3]);
    let n = indices
        .iter()
        .flatten()
        .max()
        .map_or(0, |&m| m as usize + 1);
    let mut start = vec![0u32; n + 1];
    for t in indices {
        for e in 0..3 {
            let (a, b) = edge(t, e);
            start[a.min(b) as usize + 1] += 1;
        }
    }
    for v in 0..n {
        start[v + 1] += start[v];
    }
    let mut fill = start.clone();
    let blank = EdgeUse {
        key: 0,
        tri: 0,
        forward: false,
    };
    let mut uses = vec![blank; indices.len() * 3];
    for (k, t) in indices.iter().enumerate() {
        for e in 0..3 {
            let (a, b) = edge(t, e);
            let slot = &mut fill[a.min(b) as usize];
            uses[*slot as usize] = EdgeUse {
                key: (u64::from(a.min(b)) << 32) | u64::from(a.max(b)),
                tri: k as u32,
                forward: a < b,
            };
            *slot += 1;
        }
    }
    for v in 0..n {
        uses[start[v] as usize..start[v + 1] as usize].sort_by_key(|u| u.key);
    }
    uses
}

/// Runs of equal keys in sorted uses.
fn groups(uses: &[EdgeUse]) -> impl Iterator<Item = &[EdgeUse]> {
    uses.chunk_by(|a, b| a.key == b.key)
}

/// Cleaned mesh in, consistently wound mesh out (in place), with its
/// topology (see the module documentation).
pub fn prepare(mesh: &mut TriangleMesh) -> Topology {
    let mut t = Topology::default();
    let uses = edge_uses(&mesh.indices);
    let (flips, conflicts, repaired) = winding_flips(mesh.indices.len(), &uses);
    t.conflicts = conflicts;
    t.solid = conflicts == 0;
    if t.solid {
        let mut flips = flips;
        orient_outward(mesh, &uses, &mut flips, repaired);
        for (tri, f) in mesh.indices.iter_mut().zip(&flips) {
            if *f {
                tri.swap(1, 2);
                t.flipped += 1;
            }
        }
    }
    // Count after the flips: a flip changes directions, not the grouping.
    let uses = if t.flipped > 0 {
        edge_uses(&mesh.indices)
    } else {
        uses
    };
    let mut balanced = true;
    for g in groups(&uses) {
        match g.len() {
            1 => t.boundary_edges += 1,
            2 => {}
            _ => t.non_manifold_edges += 1,
        }
        let forward = g.iter().filter(|u| u.forward).count();
        balanced &= 2 * forward == g.len();
    }
    t.closed = balanced;
    t.warnings = warnings(&t);
    t
}

/// Flips (per triangle) that make neighbours across manifold edges agree, the
/// number of edges that still disagree, and whether any flip was needed.
fn winding_flips(n: usize, uses: &[EdgeUse]) -> (Vec<bool>, usize, bool) {
    // Adjacency in compressed rows: (neighbour, must differ in flip).
    let mut degree = vec![0u32; n + 1];
    let pairs: Vec<(u32, u32, bool)> = groups(uses)
        .filter(|g| g.len() == 2)
        .map(|g| (g[0].tri, g[1].tri, g[0].forward == g[1].forward))
        .collect();
    for &(a, b, _) in &pairs {
        degree[a as usize + 1] += 1;
        degree[b as usize + 1] += 1;
    }
    for i in 0..n {
        degree[i + 1] += degree[i];
    }
    let mut fill = degree.clone();
    let mut adj = vec![(0u32, false); pairs.len() * 2];
    for &(a, b, differ) in &pairs {
        adj[fill[a as usize] as usize] = (b, differ);
        fill[a as usize] += 1;
        adj[fill[b as usize] as usize] = (a, differ);
        fill[b as usize] += 1;
    }
    let mut flip: Vec<Option<bool>> = vec![None; n];
    let (mut conflicts, mut any) = (0, false);
    let mut queue = Vec::new();
    for start in 0..n {
        if flip[start].is_some() {
            continue;
        }
        flip[start] = Some(false);
        queue.push(start as u32);
        while let Some(t) = queue.pop() {
            let ft = flip[t as usize].unwrap_or(false);
            for &(u, differ) in &adj[degree[t as usize] as usize..degree[t as usize + 1] as usize] {
                let want = ft ^ differ;
                match flip[u as usize] {
                    None => {
                        flip[u as usize] = Some(want);
                        any |= want;
                        queue.push(u);
                    }
                    Some(f) if f != want => conflicts += 1,
                    Some(_) => {}
                }
            }
        }
    }
    // Each conflicting edge is seen from both of its triangles.
    let flips = flip.into_iter().map(|f| f.unwrap_or(false)).collect();
    (flips, conflicts / 2, any)
}

/// Turns inside-out patches outward: every patch (connected across manifold
/// edges) when the winding was repaired, else the whole mesh if its volume
/// is negative. Volumes are taken about the mesh's box centre.
fn orient_outward(mesh: &TriangleMesh, uses: &[EdgeUse], flips: &mut [bool], repaired: bool) {
    let (lo, hi) = mesh.aabb();
    let c = nalgebra::center(&lo, &hi);
    let signed = |k: usize, flipped: bool| {
        let [a, b, d] = mesh.triangle(k);
        let v = (a - c).dot(&(b - c).cross(&(d - c)));
        if flipped {
            -v
        } else {
            v
        }
    };
    if !repaired {
        let volume: f64 = (0..flips.len()).map(|k| signed(k, flips[k])).sum();
        if volume < 0.0 {
            flips.iter_mut().for_each(|f| *f = !*f);
        }
        return;
    }
    let patch = patches(flips.len(), uses);
    let mut volume = vec![0.0; flips.len()];
    for k in 0..flips.len() {
        volume[patch[k] as usize] += signed(k, flips[k]);
    }
    for k in 0..flips.len() {
        if volume[patch[k] as usize] < 0.0 {
            flips[k] = !flips[k];
        }
    }
}

/// The patch (connected across manifold edges) of each triangle, as the
/// index of its smallest triangle (union–find).
fn patches(n: usize, uses: &[EdgeUse]) -> Vec<u32> {
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn root(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            parent[x as usize] = parent[parent[x as usize] as usize];
            x = parent[x as usize];
        }
        x
    }
    for g in groups(uses).filter(|g| g.len() == 2) {
        let (a, b) = (root(&mut parent, g[0].tri), root(&mut parent, g[1].tri));
        parent[a.max(b) as usize] = a.min(b);
    }
    (0..n as u32).map(|k| root(&mut parent, k)).collect()
}

fn warnings(t: &Topology) -> Vec<String> {
    let mut w = Vec::new();
    if t.non_manifold_edges > 0 && t.closed {
        w.push(format!(
            "non-manifold mesh: {} edges are shared by more than two triangles (e.g. a handle \
             touching the body); the mesh is closed and is used as a solid",
            t.non_manifold_edges
        ));
    } else if t.non_manifold_edges > 0 {
        w.push(format!(
            "non-manifold mesh: {} edges are shared by more than two triangles",
            t.non_manifold_edges
        ));
    }
    if t.flipped > 0 {
        w.push(format!(
            "{} triangles were wound against their neighbours or inward and were flipped",
            t.flipped
        ));
    }
    if !t.solid {
        w.push(format!(
            "the surface cannot be wound consistently ({} edges disagree): links are checked \
             against the surface only, not for lying wholly inside it",
            t.conflicts
        ));
    } else if !t.closed {
        w.push(format!(
            "open mesh: {} boundary edges (holes); inside tests use oriented pseudo-normals, \
             which treat points just behind a hole's rim as inside (as if capped); the default \
             centre of mass is the convex hull's centroid (give center_of_mass for a better one)",
            t.boundary_edges
        ));
    }
    w
}

/// Most points handed to the convex hull (see [`hull_centroid`]).
pub const HULL_POINTS: usize = 50_000;

/// Centroid and volume of the convex hull of `points` (`None` when the hull
/// is flat or cannot be built): the mass properties of an open mesh.
///
/// Above [`HULL_POINTS`] points, every k-th point plus the extreme points
/// along the axes stand in for all (the hull of a scan is decided by few
/// points; this bounds the time on million-triangle meshes).
pub fn hull_centroid(points: &[Point3<f64>]) -> Option<(Point3<f64>, f64)> {
    use tsukami_body::convert::{to_point, to_vec};
    let step = points.len().div_ceil(HULL_POINTS).max(1);
    let mut pts: Vec<_> = points.iter().step_by(step).map(to_vec).collect();
    if step > 1 {
        for axis in 0..3 {
            let by = |a: &&Point3<f64>, b: &&Point3<f64>| a[axis].total_cmp(&b[axis]);
            pts.extend(points.iter().min_by(by).map(to_vec));
            pts.extend(points.iter().max_by(by).map(to_vec));
        }
    }
    let (v, idx) = parry3d_f64::transformation::try_convex_hull(&pts).ok()?;
    let v: Vec<Point3<f64>> = v.into_iter().map(to_point).collect();
    let c = v.iter().fold(Vector3::zeros(), |a, p| a + p.coords) / v.len().max(1) as f64;
    let (mut volume, mut moment) = (0.0f64, Vector3::zeros());
    for t in &idx {
        let [a, b, d] = t.map(|i| v[i as usize].coords - c);
        let s = a.dot(&b.cross(&d)) / 6.0;
        volume += s;
        moment += s * (a + b + d) / 4.0;
    }
    (volume.abs() > 1e-15).then(|| (Point3::from(c + moment / volume), volume.abs()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two closed boxes sharing one edge: that edge has four triangles.
    fn boxes_touching_on_an_edge() -> TriangleMesh {
        let mut a = TriangleMesh::cuboid(Vector3::new(0.5, 0.5, 0.5));
        let b = a.clone();
        let n = a.vertices.len() as u32;
        // Shift b by (0.5, 0.5, 0): its edge x = y = -0.25 lands on a's edge x = y = 0.25.
        a.vertices
            .extend(b.vertices.iter().map(|p| p + Vector3::new(0.5, 0.5, 0.0)));
        a.indices.extend(b.indices.iter().map(|t| t.map(|i| i + n)));
        a.clean();
        a
    }

    #[test]
    fn a_closed_non_manifold_mesh_is_closed_and_solid() {
        let mut m = boxes_touching_on_an_edge();
        let t = prepare(&mut m);
        assert!(t.non_manifold_edges >= 1, "{t:?}");
        assert!(t.closed && t.solid, "{t:?}");
        assert_eq!(t.flipped, 0);
        assert!((m.volume() - 0.25).abs() < 1e-12);
        assert!(t.warnings[0].contains("non-manifold"), "{:?}", t.warnings);
    }

    #[test]
    fn random_winding_is_repaired_and_faces_outward() {
        let mut m = TriangleMesh::cylinder(0.03, 0.1, 24);
        let volume = m.volume();
        for k in (0..m.indices.len()).step_by(3) {
            m.indices[k].swap(0, 1);
        }
        let t = prepare(&mut m);
        assert!(t.closed && t.solid && t.flipped > 0, "{t:?}");
        assert!((m.volume() - volume).abs() < 1e-12);
        // Inside out as a whole: flipped back.
        for tri in &mut m.indices {
            tri.swap(1, 2);
        }
        let t = prepare(&mut m);
        assert_eq!(t.flipped, m.indices.len());
        assert!((m.volume() - volume).abs() < 1e-12);
    }

    #[test]
    fn an_open_scan_is_open_solid_and_has_a_hull_centroid() {
        let mut m = TriangleMesh::cylinder(0.03, 0.1, 24);
        // Drop the top cap (triangles touching the top centre vertex).
        let top = m.vertices.len() as u32 - 1;
        m.indices.retain(|t| !t.contains(&top));
        m.clean();
        let t = prepare(&mut m);
        assert_eq!(t.boundary_edges, 24);
        assert!(!t.closed && t.solid, "{t:?}");
        let (c, v) = hull_centroid(&m.vertices).unwrap();
        assert!((c.z - 0.05).abs() < 1e-9 && c.x.abs() < 1e-9, "{c}");
        assert!(v > 2.5e-4 && v < 2.9e-4, "{v}");
    }

    #[test]
    fn a_moebius_strip_cannot_be_wound() {
        // Four quads around a loop with a half twist.
        let n = 8;
        let mut vertices = Vec::new();
        for k in 0..n {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            let (tw, r) = (a / 2.0, 0.1);
            let d = Vector3::new(a.cos() * tw.cos(), a.sin() * tw.cos(), tw.sin()) * 0.02;
            let c = Vector3::new(a.cos(), a.sin(), 0.0) * r;
            vertices.push(Point3::from(c + d));
            vertices.push(Point3::from(c - d));
        }
        let mut indices = Vec::new();
        for k in 0..n as u32 {
            let (a, b) = (2 * k, 2 * k + 1);
            let (c, d) = if k + 1 == n as u32 {
                (1, 0)
            } else {
                (2 * k + 2, 2 * k + 3)
            };
            indices.push([a, b, d]);
            indices.push([a, d, c]);
        }
        let mut m = TriangleMesh { vertices, indices };
        let t = prepare(&mut m);
        assert!(!t.solid && t.conflicts > 0, "{t:?}");
        assert!(t.warnings.iter().any(|w| w.contains("surface only")));
    }
}
