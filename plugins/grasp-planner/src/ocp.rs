//! Object convex polygons (OCP, section 3.1): oriented boxes around the object.
//!
//! What: [`object_ocps`] turns a triangle surface (world-frame vertices and
//! triangles) into one [`Ocp`] per region, with the faces of each box marked
//! free or blocked (resting on the support below, or lying against another
//! region).
//!
//! Why: the paper selects grasp types by comparing the OCP edge lengths with the
//! hand's grasping rectangular convexes (eqs. (1)–(3)), and approaches the
//! object through one OCP face. A box per region lets a complex object (a
//! vase: foot, body, neck) be grasped on one part.
//!
//! How: the box axes are the eigenvectors of the area-weighted covariance of the
//! surface — the exact second moment of every triangle, so long thin triangles
//! of a coarse mesh weigh what their area says, not what their vertex count
//! says; the extents come from projecting the (clipped) vertices on the axes.
//! Axes whose eigenvalues coincide (the cross-section of a cylinder) are not
//! determined by the surface: [`OcpParams::preferred_axis`] picks them, so a
//! can's side faces look toward the robot. Regions: the radius profile of
//! cross-sections along the longest axis (of equally long ones, the first:
//! toward the robot) is cut where it jumps and where a region's radius range
//! grows too wide; similar neighbouring runs are merged back unless the merged
//! run would be that wide again (a vase's flared lip, its neck and its body
//! stay three regions). Where the axis leaves the material for a hole (the
//! parity of a ray in each cross-section) the cut is there instead: a ring
//! lying flat becomes its near arc, its middle with the hole and its far arc,
//! each arc holding the whole tube. Everything is pure over nalgebra values.
//!
//! ```
//! use nalgebra::Point3;
//! use tsukami_grasp_planner::ocp::{object_ocps, OcpParams};
//! // A unit cube resting on z = 0.
//! let v: Vec<Point3<f64>> = (0..8)
//!     .map(|i| Point3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
//!     .collect();
//! let t = [[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
//!          [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]];
//! let ocps = object_ocps(&v, &t, &OcpParams::default());
//! assert_eq!(ocps.len(), 1);
//! assert!((ocps[0].extents - nalgebra::Vector3::new(1.0, 1.0, 1.0)).norm() < 1e-9);
//! assert_eq!(ocps[0].free_faces().count(), 5); // the bottom rests on z = 0
//! ```

use nalgebra::{Matrix3, Point3, Rotation3, SymmetricEigen, UnitQuaternion, Vector3};
use tsukami_msgs::planner::{BoxFace, FaceBlock, OcpBox, Pose};

/// Box axes whose extents differ by less than this fraction of the longest
/// count as equally long when choosing the axis to split along.
const LONGEST_TIE: f64 = 0.02;

/// Spreads of two readings of a profile within this fraction of each other
/// are equal ([`segment_profile`]).
const SPREAD_TIE: f64 = 0.01;

/// A split axis whose vertical (or x) component is below this counts as
/// level for [`canonical_sign`] (sin 10°).
const LEVEL: f64 = 0.17;

/// Parameters of the OCP computation.
#[derive(Debug, Clone)]
pub struct OcpParams {
    /// World direction that in-plane axes of a symmetric cross-section should
    /// follow (default −x of the world: toward a robot standing at the origin
    /// facing +x, the face then looks at the robot).
    pub preferred_axis: Vector3<f64>,
    /// Relative eigenvalue difference under which two axes count as equal.
    pub symmetry_tolerance: f64,
    /// Number of cross-section samples along the splitting axis.
    pub slices: usize,
    /// Split where the radius changes between neighbouring slices by more than
    /// this fraction of the object's largest radius.
    pub jump_fraction: f64,
    /// Split where a region's radius range exceeds this fraction of its largest radius.
    pub range_fraction: f64,
    /// Merge neighbouring regions whose mean radii differ by less than this fraction.
    pub merge_fraction: f64,
    /// A region shorter than this fraction of the object's length is merged
    /// into its most similar neighbour.
    pub min_region_fraction: f64,
    /// A downward face within this height (m) of the object's lowest point rests on the support.
    pub support_tolerance: f64,
    /// Maximum number of regions.
    pub max_regions: usize,
    /// The object's box turns to the tightest box about a principal axis or
    /// the vertical ([`crate::tight_box`]) when that box's volume is below
    /// this fraction of the principal-axes box's (a mug's handle tilts the
    /// principal axes; a can's or a vase's are already tight).
    pub tight_box_ratio: f64,
}

impl Default for OcpParams {
    fn default() -> Self {
        Self {
            preferred_axis: -Vector3::x(),
            symmetry_tolerance: 0.03,
            slices: 32,
            jump_fraction: 0.12,
            range_fraction: 0.45,
            merge_fraction: 0.12,
            min_region_fraction: 0.08,
            support_tolerance: 0.01,
            max_regions: 4,
            tight_box_ratio: 0.9,
        }
    }
}

/// One object convex polygon: an oriented box in the world frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Ocp {
    /// Region index.
    pub region: usize,
    /// Box centre (world frame).
    pub center: Point3<f64>,
    /// Box axes as the columns of a rotation (world frame).
    pub rotation: Rotation3<f64>,
    /// Full edge lengths along the box axes.
    pub extents: Vector3<f64>,
    /// Per face (in [`BoxFace::ALL`] order): `None` if free, else why it is blocked.
    pub blocked: [Option<FaceBlock>; 6],
}

impl Ocp {
    /// Outward unit normal of `face` in the world frame.
    pub fn face_normal(&self, face: BoxFace) -> Vector3<f64> {
        self.rotation.matrix().column(face.axis()) * face.sign()
    }

    /// Centre of `face` in the world frame.
    pub fn face_center(&self, face: BoxFace) -> Point3<f64> {
        self.center + self.face_normal(face) * (0.5 * self.extents[face.axis()])
    }

    /// Faces not blocked.
    pub fn free_faces(&self) -> impl Iterator<Item = BoxFace> + '_ {
        BoxFace::ALL
            .into_iter()
            .zip(self.blocked.iter())
            .filter(|(_, b)| b.is_none())
            .map(|(f, _)| f)
    }

    /// Whether the world point `p` lies inside the box grown by `margin`.
    pub fn contains(&self, p: &Point3<f64>, margin: f64) -> bool {
        let local = self.rotation.inverse() * (p - self.center);
        (0..3).all(|k| local[k].abs() <= 0.5 * self.extents[k] + margin)
    }

    /// The message form.
    pub fn to_msg(&self) -> OcpBox {
        let q = UnitQuaternion::from_rotation_matrix(&self.rotation);
        let mut free = Vec::new();
        let mut blocked = Vec::new();
        for (face, b) in BoxFace::ALL.into_iter().zip(self.blocked.iter()) {
            match b {
                None => free.push(face),
                Some(b) => blocked.push((face, *b)),
            }
        }
        OcpBox {
            region: self.region,
            pose: Pose {
                position: [self.center.x, self.center.y, self.center.z],
                quaternion: [q.i, q.j, q.k, q.w],
            },
            extents: [self.extents.x, self.extents.y, self.extents.z],
            free_faces: free,
            blocked_faces: blocked,
        }
    }
}

/// Area-weighted surface moments: total area, first moment and second moment.
#[derive(Debug, Clone, Copy)]
struct Moments {
    area: f64,
    first: Vector3<f64>,
    second: Matrix3<f64>,
}

impl Moments {
    fn zero() -> Self {
        Self {
            area: 0.0,
            first: Vector3::zeros(),
            second: Matrix3::zeros(),
        }
    }

    /// Adds the exact moments of triangle `abc`: ∫x dA = A g and
    /// ∫x xᵀ dA = A/12 (9 g gᵀ + a aᵀ + b bᵀ + c cᵀ), g the centroid.
    fn add_triangle(&mut self, a: &Vector3<f64>, b: &Vector3<f64>, c: &Vector3<f64>) {
        let area = 0.5 * (b - a).cross(&(c - a)).norm();
        if area <= 0.0 || !area.is_finite() {
            return;
        }
        let g = (a + b + c) / 3.0;
        self.area += area;
        self.first += g * area;
        self.second +=
            (g * g.transpose() * 9.0 + a * a.transpose() + b * b.transpose() + c * c.transpose())
                * (area / 12.0);
    }

    fn mean(&self) -> Vector3<f64> {
        self.first / self.area
    }

    /// Covariance about the area centroid.
    fn covariance(&self) -> Matrix3<f64> {
        let m = self.mean();
        self.second / self.area - m * m.transpose()
    }
}

/// A surface patch: polygons (already clipped to a region), as vertex loops.
struct Patch {
    polygons: Vec<Vec<Vector3<f64>>>,
}

impl Patch {
    fn moments(&self) -> Moments {
        let mut m = Moments::zero();
        for poly in &self.polygons {
            for k in 1..poly.len().saturating_sub(1) {
                m.add_triangle(&poly[0], &poly[k], &poly[k + 1]);
            }
        }
        m
    }

    fn vertices(&self) -> impl Iterator<Item = &Vector3<f64>> {
        self.polygons.iter().flatten()
    }
}

/// Principal axes of a covariance, largest variance first, as a right-handed
/// rotation; symmetric (equal-eigenvalue) planes use `preferred`.
fn principal_axes(cov: &Matrix3<f64>, params: &OcpParams) -> Rotation3<f64> {
    let eig = SymmetricEigen::new(*cov);
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&i, &j| eig.eigenvalues[j].total_cmp(&eig.eigenvalues[i]));
    let vals = [
        eig.eigenvalues[idx[0]],
        eig.eigenvalues[idx[1]],
        eig.eigenvalues[idx[2]],
    ];
    let mut axes = [
        eig.eigenvectors.column(idx[0]).into_owned(),
        eig.eigenvectors.column(idx[1]).into_owned(),
        eig.eigenvectors.column(idx[2]).into_owned(),
    ];
    let scale = vals[0].abs().max(1e-300);
    let same = |a: f64, b: f64| (a - b).abs() <= params.symmetry_tolerance * scale;
    // A symmetric pair of axes: choose them from the preferred direction, keeping
    // the distinct axis.
    let pair = if same(vals[0], vals[1]) && !same(vals[1], vals[2]) {
        Some((0, 1, 2))
    } else if same(vals[1], vals[2]) && !same(vals[0], vals[1]) {
        Some((1, 2, 0))
    } else {
        None
    };
    if let Some((i, j, k)) = pair {
        if let Some((a, b)) = preferred_pair(&axes[k], params) {
            axes[i] = a;
            axes[j] = b;
        }
    } else if same(vals[0], vals[2]) {
        // Fully symmetric (a sphere, a cube): use the world axes.
        axes = [Vector3::x(), Vector3::y(), Vector3::z()];
    }
    for a in axes.iter_mut() {
        *a = a.normalize();
    }
    // Right-handed: the third axis follows from the first two.
    axes[2] = axes[0].cross(&axes[1]).normalize();
    Rotation3::from_matrix_unchecked(Matrix3::from_columns(&axes))
}

/// Two axes across `normal` for a cross-section that does not choose its own
/// (a circle's): the first follows the preferred direction (or, when that is
/// along `normal`, the world's z, x or y).
fn preferred_pair(
    normal: &Vector3<f64>,
    params: &OcpParams,
) -> Option<(Vector3<f64>, Vector3<f64>)> {
    let candidates = [
        params.preferred_axis,
        Vector3::z(),
        Vector3::x(),
        Vector3::y(),
    ];
    candidates.into_iter().find_map(|c| {
        let p = c - normal * normal.dot(&c);
        (p.norm() > 0.3 * c.norm().max(1e-12)).then(|| {
            let a = p.normalize();
            (a, normal.cross(&a))
        })
    })
}

/// The box axes of a slab of the object cut across `axis`: `axis` itself and
/// the principal axes of the slab's surface across it, largest variance
/// first; a symmetric cross-section takes [`preferred_pair`]. Every region of
/// a split shares the split axis, so a region's box cannot tilt on its own
/// when its three variances come close (a squat neck), which would change its
/// sizes with the smallest move of the object.
fn slab_axes(cov: &Matrix3<f64>, axis: &Vector3<f64>, params: &OcpParams) -> Rotation3<f64> {
    let p = Matrix3::identity() - axis * axis.transpose();
    let across = SymmetricEigen::new(p * cov * p);
    // The eigenvector along `axis` has eigenvalue 0; the other two lie across it.
    let mut inplane: Vec<(f64, Vector3<f64>)> = (0..3)
        .map(|k| {
            (
                across.eigenvalues[k],
                across.eigenvectors.column(k).into_owned(),
            )
        })
        .collect();
    inplane.sort_by(|a, b| a.1.dot(axis).abs().total_cmp(&b.1.dot(axis).abs()));
    inplane.truncate(2);
    inplane.sort_by(|a, b| b.0.total_cmp(&a.0));
    let (big, small) = (inplane[0].0, inplane[1].0);
    let (u, v) = match preferred_pair(axis, params) {
        Some(pair) if big - small <= params.symmetry_tolerance * big.abs().max(1e-300) => pair,
        _ => {
            let u = (inplane[0].1 - axis * axis.dot(&inplane[0].1)).normalize();
            (u, axis.cross(&u))
        }
    };
    // Largest variance first, right-handed.
    let along = (axis.transpose() * cov * axis)[0];
    let mut cols = [(along, *axis), (big, u), (small, v)];
    cols.sort_by(|a, b| b.0.total_cmp(&a.0));
    let (a, b) = (cols[0].1, cols[1].1);
    Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[a, b, a.cross(&b)]))
}

/// Box around a patch: PCA axes, extents from vertex projections.
fn patch_box(patch: &Patch, params: &OcpParams, region: usize) -> Option<Ocp> {
    let m = patch.moments();
    if m.area <= 0.0 {
        return None;
    }
    let rotation = principal_axes(&m.covariance(), params);
    Some(box_from_axes(patch, rotation, region))
}

fn box_from_axes(patch: &Patch, rotation: Rotation3<f64>, region: usize) -> Ocp {
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    let rt = rotation.inverse();
    for v in patch.vertices() {
        let l = rt * v;
        lo = lo.inf(&l);
        hi = hi.sup(&l);
    }
    let mid = (lo + hi) * 0.5;
    Ocp {
        region,
        center: Point3::from(rotation * mid),
        rotation,
        extents: hi - lo,
        blocked: [None; 6],
    }
}

/// The tightest box about a principal axis or the vertical instead of `pca`
/// when it is much smaller (see [`OcpParams::tight_box_ratio`]).
fn tighten(pca: Ocp, whole: &Patch, vertices: &[Point3<f64>], params: &OcpParams) -> Ocp {
    let m = pca.rotation.matrix();
    let axes = [
        m.column(0).into_owned(),
        m.column(1).into_owned(),
        m.column(2).into_owned(),
        Vector3::z(),
    ];
    let pca_volume = pca.extents.product();
    match crate::tight_box::tightest_rotation(vertices, &axes) {
        Some((rotation, v)) if v < params.tight_box_ratio * pca_volume => {
            box_from_axes(whole, rotation, pca.region)
        }
        _ => pca,
    }
}

/// Clips a convex polygon to the half-space `axis·x ≥ t` (`keep_above`) or `≤ t`.
fn clip(poly: &[Vector3<f64>], axis: &Vector3<f64>, t: f64, keep_above: bool) -> Vec<Vector3<f64>> {
    let side = |p: &Vector3<f64>| {
        let d = axis.dot(p) - t;
        if keep_above {
            d
        } else {
            -d
        }
    };
    let mut out = Vec::with_capacity(poly.len() + 2);
    for i in 0..poly.len() {
        let a = poly[i];
        let b = poly[(i + 1) % poly.len()];
        let (da, db) = (side(&a), side(&b));
        if da >= 0.0 {
            out.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            let s = da / (da - db);
            out.push(a + (b - a) * s);
        }
    }
    out
}

/// One cross-section of the surface by the plane `axis·x = t`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Section {
    /// The largest distance of a section point from the line through the
    /// box centre along `axis`.
    radius: f64,
    /// Whether that line passes through material here (an odd number of the
    /// section's segments cross a ray from it in the plane), not through a
    /// hole: false in the middle of a ring lying flat.
    pierced: bool,
}

/// The cross-section at `t`; `ray` is a unit direction across `axis` (the
/// parity ray, chosen off the box's axes).
fn section(
    tris: &[[Vector3<f64>; 3]],
    axis: &Vector3<f64>,
    center: &Vector3<f64>,
    t: f64,
    ray: &Vector3<f64>,
) -> Section {
    let on_line = center + axis * (t - axis.dot(center));
    let across = axis.cross(ray);
    let (mut r, mut crossings): (f64, u32) = (0.0, 0);
    for tri in tris {
        let d = [
            axis.dot(&tri[0]) - t,
            axis.dot(&tri[1]) - t,
            axis.dot(&tri[2]) - t,
        ];
        let mut ends = [Vector3::zeros(); 2];
        let mut n = 0;
        for e in 0..3 {
            let (i, j) = (e, (e + 1) % 3);
            if (d[i] >= 0.0) != (d[j] >= 0.0) {
                let s = d[i] / (d[i] - d[j]);
                let q = tri[i] + (tri[j] - tri[i]) * s;
                let from_centre = q - center;
                r = r.max((from_centre - axis * axis.dot(&from_centre)).norm());
                if n < 2 {
                    ends[n] = q - on_line;
                }
                n += 1;
            }
        }
        if n == 2 {
            // Does the segment cross the ray `on_line + s·ray`, s > 0?
            let (a, b) = (across.dot(&ends[0]), across.dot(&ends[1]));
            if (a >= 0.0) != (b >= 0.0) {
                let (sa, sb) = (ray.dot(&ends[0]), ray.dot(&ends[1]));
                if sa + (sb - sa) * a / (a - b) > 0.0 {
                    crossings += 1;
                }
            }
        }
    }
    Section {
        radius: r,
        pierced: crossings % 2 == 1,
    }
}

/// Splits the slices `0..flags.len()` where the split axis goes from
/// material into a hole or back (a ring lying flat: its near arc, the middle
/// with the hole, its far arc), ignoring runs shorter than `min_len` slices
/// (merged into the run before, or after for the first), so a stray parity
/// flip of an untidy mesh cuts nothing.
fn hole_runs(flags: &[bool], min_len: usize) -> Vec<std::ops::Range<usize>> {
    let mut runs: Vec<(std::ops::Range<usize>, bool)> = Vec::new();
    for (k, &f) in flags.iter().enumerate() {
        match runs.last_mut() {
            Some((r, g)) if *g == f => r.end = k + 1,
            _ => runs.push((k..k + 1, f)),
        }
    }
    // Short runs join a neighbour; neighbours with the same flag then join.
    let mut out: Vec<(std::ops::Range<usize>, bool)> = Vec::new();
    for (r, f) in runs {
        match out.last_mut() {
            Some((prev, _)) if r.len() < min_len => prev.end = r.end,
            Some((prev, g)) if *g == f => prev.end = r.end,
            Some((prev, _)) if prev.len() < min_len => {
                prev.end = r.end;
                out.last_mut().expect("just matched").1 = f;
            }
            _ => out.push((r, f)),
        }
    }
    out.into_iter().map(|(r, _)| r).collect()
}

/// Cuts the radius profile into runs of similar radius; returns slice index
/// ranges.
///
/// The profile is read from each end ([`greedy_runs`]): cut where neighbouring
/// slices jump by more than [`OcpParams::jump_fraction`] of the largest radius
/// or a run's radius range grows beyond [`OcpParams::range_fraction`] of its
/// largest; then short runs and similar neighbours merge. The two readings can
/// differ (from its foot a vase's neck and lip read as one uneven run, from
/// its lip as two even ones): the one with fewer uneven runs is taken, then
/// the one with fewer runs, then the one whose radii spread least about their
/// runs' means. The result does not depend on which way the axis points.
fn segment_profile(radii: &[f64], params: &OcpParams) -> Vec<std::ops::Range<usize>> {
    let n = radii.len();
    let forward = greedy_runs(radii, params);
    let reversed: Vec<f64> = radii.iter().rev().copied().collect();
    let mut backward: Vec<std::ops::Range<usize>> = greedy_runs(&reversed, params)
        .into_iter()
        .map(|r| (n - r.end)..(n - r.start))
        .collect();
    backward.reverse();
    if forward == backward {
        return forward;
    }
    let score = |runs: &[std::ops::Range<usize>]| {
        let (mut uneven, mut spread) = (0usize, 0.0);
        for r in runs {
            let v = &radii[r.clone()];
            let (lo, hi) = v
                .iter()
                .fold((f64::INFINITY, 0.0f64), |(l, h), &x| (l.min(x), h.max(x)));
            uneven += usize::from(hi - lo > params.range_fraction * hi);
            let mean = v.iter().sum::<f64>() / v.len().max(1) as f64;
            spread += v.iter().map(|x| (x - mean).powi(2)).sum::<f64>();
        }
        (uneven, runs.len(), spread)
    };
    // Of equal readings (a sphere's, mirror images) the one from the
    // first slice: the axis's sign is fixed ([`canonical_sign`]).
    let (f, b) = (score(&forward), score(&backward));
    let less_spread = b.2 < (1.0 - SPREAD_TIE) * f.2;
    if (b.0, b.1) < (f.0, f.1) || ((b.0, b.1) == (f.0, f.1) && less_spread) {
        backward
    } else {
        forward
    }
}

/// Cuts the radius profile into runs of similar radius, read from its first
/// slice on: cut at jumps and where a run grows uneven, then short runs and
/// similar neighbours merged (see [`segment_profile`]).
fn greedy_runs(radii: &[f64], params: &OcpParams) -> Vec<std::ops::Range<usize>> {
    let n = radii.len();
    let rmax = radii.iter().cloned().fold(0.0, f64::max);
    if n == 0 || rmax <= 0.0 {
        return std::iter::once(0..n).collect();
    }
    // 1. Cut at jumps and where a run's radius range grows too wide.
    let mut runs: Vec<std::ops::Range<usize>> = Vec::new();
    let mut start = 0;
    let (mut lo, mut hi) = (radii[0], radii[0]);
    for k in 1..n {
        let r = radii[k];
        let jump = (r - radii[k - 1]).abs() > params.jump_fraction * rmax;
        let (nlo, nhi) = (lo.min(r), hi.max(r));
        let wide = nhi - nlo > params.range_fraction * nhi;
        if jump || wide {
            runs.push(start..k);
            start = k;
            lo = r;
            hi = r;
        } else {
            lo = nlo;
            hi = nhi;
        }
    }
    runs.push(start..n);
    let mean = |r: &std::ops::Range<usize>| radii[r.clone()].iter().sum::<f64>() / r.len() as f64;
    // 2. Merge short runs into the neighbour with the closer mean radius, and
    //    neighbours of similar mean radius.
    let min_len = ((params.min_region_fraction * n as f64).ceil() as usize).max(1);
    loop {
        let mut changed = false;
        if runs.len() > 1 {
            // Shortest run below the minimum length first.
            if let Some((i, _)) = runs
                .iter()
                .enumerate()
                .filter(|(_, r)| r.len() < min_len)
                .min_by_key(|(_, r)| r.len())
            {
                let mi = mean(&runs[i]);
                let left = (i > 0).then(|| (mean(&runs[i - 1]) - mi).abs());
                let right = (i + 1 < runs.len()).then(|| (mean(&runs[i + 1]) - mi).abs());
                let into_left = match (left, right) {
                    (Some(l), Some(r)) => l <= r,
                    (Some(_), None) => true,
                    _ => false,
                };
                let (a, b) = if into_left { (i - 1, i) } else { (i, i + 1) };
                runs[a] = runs[a].start..runs[b].end;
                runs.remove(b);
                changed = true;
            }
        }
        if !changed {
            // Similar neighbours merge unless the merged run would be as
            // uneven as step 1 cuts (a vase's flared lip and its neck).
            let even = |a: usize, b: usize| {
                let r = &radii[a..b];
                let (lo, hi) = r
                    .iter()
                    .fold((f64::INFINITY, 0.0f64), |(l, h), &x| (l.min(x), h.max(x)));
                hi - lo <= params.range_fraction * hi
            };
            for i in 0..runs.len().saturating_sub(1) {
                if (mean(&runs[i]) - mean(&runs[i + 1])).abs() < params.merge_fraction * rmax
                    && even(runs[i].start, runs[i + 1].end)
                {
                    runs[i] = runs[i].start..runs[i + 1].end;
                    runs.remove(i + 1);
                    changed = true;
                    break;
                }
            }
        }
        if !changed && runs.len() > params.max_regions.max(1) {
            // Too many: merge the most similar neighbours.
            let i = (0..runs.len() - 1)
                .min_by(|&a, &b| {
                    let da = (mean(&runs[a]) - mean(&runs[a + 1])).abs();
                    let db = (mean(&runs[b]) - mean(&runs[b + 1])).abs();
                    da.total_cmp(&db)
                })
                .unwrap_or(0);
            runs[i] = runs[i].start..runs[i + 1].end;
            runs.remove(i + 1);
            changed = true;
        }
        if !changed {
            break;
        }
    }
    runs
}

/// `axis` or its opposite, whichever points up (or, for an axis within
/// [`LEVEL`] of horizontal, along +x, then +y). An eigenvector's sign is
/// arbitrary and flips with the smallest change of the surface; the profile
/// along it is read from one end.
fn canonical_sign(axis: Vector3<f64>) -> Vector3<f64> {
    let key = if axis.z.abs() > LEVEL {
        axis.z
    } else if axis.x.abs() > LEVEL {
        axis.x
    } else {
        axis.y
    };
    if key < 0.0 {
        -axis
    } else {
        axis
    }
}

/// Where the object's box is cut into regions: along `axis`, between
/// `t0` and `t1`, into runs of `n` slices.
struct Split {
    axis: Vector3<f64>,
    t0: f64,
    t1: f64,
    n: usize,
    runs: Vec<std::ops::Range<usize>>,
}

impl Split {
    /// The cuts of the box `global` around the triangles `tris`.
    fn of(tris: &[[Vector3<f64>; 3]], global: &Ocp, params: &OcpParams) -> Split {
        // Split along the longest box axis; of axes equally long (within
        // `LONGEST_TIE`), the first: the preferred one of a symmetric pair (a
        // ring lying flat splits into its near arc, middle and far arc).
        let longest = global.extents.max();
        let long = (0..3)
            .find(|&k| global.extents[k] >= (1.0 - LONGEST_TIE) * longest)
            .unwrap_or(0);
        let m = global.rotation.matrix();
        let axis = canonical_sign(m.column(long).into_owned());
        let center = global.center.coords;
        let c = axis.dot(&center);
        let (t0, t1) = (
            c - 0.5 * global.extents[long],
            c + 0.5 * global.extents[long],
        );
        let n = params.slices.max(1);
        let (u, v) = (m.column((long + 1) % 3), m.column((long + 2) % 3));
        // The parity ray, off the box's axes and diagonals.
        let ray = (u * 0.37f64.cos() + v * 0.37f64.sin()).normalize();
        let sections: Vec<Section> = (0..n)
            .map(|k| {
                let t = t0 + (k as f64 + 0.5) / n as f64 * (t1 - t0);
                section(tris, &axis, &center, t, &ray)
            })
            .collect();
        let radii: Vec<f64> = sections.iter().map(|s| s.radius).collect();
        let flags: Vec<bool> = sections.iter().map(|s| s.pierced).collect();
        let min_len = ((params.min_region_fraction * n as f64).ceil() as usize).max(1);
        // Where the axis enters or leaves a hole is the cut (a ring lying
        // flat: near arc, middle, far arc; the radius profile means nothing
        // across a hole); without a hole, the paper's radius profile cuts.
        let runs = match hole_runs(&flags, min_len) {
            parts if parts.len() > 1 => parts,
            _ => segment_profile(&radii, params),
        };
        Split {
            axis,
            t0,
            t1,
            n,
            runs,
        }
    }

    /// The run's bounds along the axis.
    fn bounds(&self, run: &std::ops::Range<usize>) -> (f64, f64) {
        let at = |k: usize| self.t0 + k as f64 / self.n as f64 * (self.t1 - self.t0);
        (at(run.start), at(run.end))
    }
}

/// The OCPs of an object surface given in the world frame, with free faces.
///
/// `vertices` and `triangles` must describe a valid surface (see
/// [`crate::object::check_mesh`]; open meshes are fine); degenerate triangles are ignored. Regions are split
/// along the box's longest axis; the support is the horizontal plane under the
/// object's lowest point.
pub fn object_ocps(
    vertices: &[Point3<f64>],
    triangles: &[[u32; 3]],
    params: &OcpParams,
) -> Vec<Ocp> {
    let tris: Vec<[Vector3<f64>; 3]> = triangles
        .iter()
        .filter_map(|t| {
            let get = |i: u32| vertices.get(i as usize).map(|p| p.coords);
            Some([get(t[0])?, get(t[1])?, get(t[2])?])
        })
        .collect();
    let whole = Patch {
        polygons: tris.iter().map(|t| t.to_vec()).collect(),
    };
    let Some(global) = patch_box(&whole, params, 0) else {
        return Vec::new();
    };
    let global = tighten(global, &whole, vertices, params);
    let split = Split::of(&tris, &global, params);
    let mut ocps = if split.runs.len() <= 1 {
        vec![global]
    } else {
        let mut out = Vec::new();
        for run in &split.runs {
            let (a, b) = split.bounds(run);
            let polygons: Vec<Vec<Vector3<f64>>> = tris
                .iter()
                .filter_map(|t| {
                    let p = clip(t, &split.axis, a, true);
                    let p = clip(&p, &split.axis, b, false);
                    (p.len() >= 3).then_some(p)
                })
                .collect();
            let patch = Patch { polygons };
            let m = patch.moments();
            if m.area > 0.0 {
                let rotation = slab_axes(&m.covariance(), &split.axis, params);
                out.push(box_from_axes(&patch, rotation, out.len()));
            }
        }
        out
    };
    mark_blocked_faces(&mut ocps, vertices, params);
    ocps
}

/// Marks faces resting on the support below the object and faces against another region.
fn mark_blocked_faces(ocps: &mut [Ocp], vertices: &[Point3<f64>], params: &OcpParams) {
    let zmin = vertices.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
    let boxes = ocps.to_vec();
    for (i, ocp) in ocps.iter_mut().enumerate() {
        for (k, face) in BoxFace::ALL.into_iter().enumerate() {
            let n = ocp.face_normal(face);
            let c = ocp.face_center(face);
            if n.z < -0.9 && c.z - zmin < params.support_tolerance {
                ocp.blocked[k] = Some(FaceBlock::Support);
                continue;
            }
            let probe = c + n * 0.005;
            if boxes
                .iter()
                .enumerate()
                .any(|(j, b)| j != i && b.contains(&probe, 0.002))
            {
                ocp.blocked[k] = Some(FaceBlock::Region);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed surface of revolution about z with the radius profile `(z, r)`.
    pub(crate) fn lathe(
        profile: &[(f64, f64)],
        segments: usize,
    ) -> (Vec<Point3<f64>>, Vec<[u32; 3]>) {
        let mut v = Vec::new();
        let mut t = Vec::new();
        for &(z, r) in profile {
            for s in 0..segments {
                let a = s as f64 / segments as f64 * std::f64::consts::TAU;
                v.push(Point3::new(r * a.cos(), r * a.sin(), z));
            }
        }
        let ring = |i: usize, s: usize| (i * segments + s % segments) as u32;
        for i in 0..profile.len() - 1 {
            for s in 0..segments {
                t.push([ring(i, s), ring(i, s + 1), ring(i + 1, s + 1)]);
                t.push([ring(i, s), ring(i + 1, s + 1), ring(i + 1, s)]);
            }
        }
        let bottom = v.len() as u32;
        v.push(Point3::new(0.0, 0.0, profile[0].0));
        let top = v.len() as u32;
        v.push(Point3::new(0.0, 0.0, profile[profile.len() - 1].0));
        let last = profile.len() - 1;
        for s in 0..segments {
            t.push([bottom, ring(0, s + 1), ring(0, s)]);
            t.push([top, ring(last, s), ring(last, s + 1)]);
        }
        (v, t)
    }

    #[test]
    fn triangle_second_moment_is_exact() {
        // Compare with a fine Monte-Carlo-free quadrature: subdivide the triangle.
        let a = Vector3::new(0.0, 0.0, 0.0);
        let b = Vector3::new(2.0, 0.0, 0.5);
        let c = Vector3::new(0.3, 1.5, -0.2);
        let mut exact = Moments::zero();
        exact.add_triangle(&a, &b, &c);
        let mut approx = Moments::zero();
        let n = 40;
        let p = |i: usize, j: usize| {
            a + (b - a) * (i as f64 / n as f64) + (c - a) * (j as f64 / n as f64)
        };
        for i in 0..n {
            for j in 0..n - i {
                approx.add_triangle_centroid(&p(i, j), &p(i + 1, j), &p(i, j + 1));
                if i + j + 1 < n {
                    approx.add_triangle_centroid(&p(i + 1, j), &p(i + 1, j + 1), &p(i, j + 1));
                }
            }
        }
        assert!((exact.area - approx.area).abs() < 1e-9);
        assert!((exact.second - approx.second).norm() < 1e-3 * exact.second.norm());
    }

    impl Moments {
        fn add_triangle_centroid(&mut self, a: &Vector3<f64>, b: &Vector3<f64>, c: &Vector3<f64>) {
            let area = 0.5 * (b - a).cross(&(c - a)).norm();
            let g = (a + b + c) / 3.0;
            self.area += area;
            self.first += g * area;
            self.second += g * g.transpose() * area;
        }
    }

    #[test]
    fn can_is_one_box_with_side_facing_robot() {
        // 350 ml can: r 33 mm, h 122 mm, standing on z = 1.0.
        let (mut v, t) = lathe(&[(0.0, 0.033), (0.122, 0.033)], 24);
        for p in &mut v {
            p.x += 0.5;
            p.z += 1.0;
        }
        let ocps = object_ocps(&v, &t, &OcpParams::default());
        assert_eq!(ocps.len(), 1);
        let o = &ocps[0];
        assert!((o.extents[0] - 0.122).abs() < 1e-9, "{:?}", o.extents);
        assert!((o.extents[1] - 0.066).abs() < 2e-3);
        assert!((o.center - Point3::new(0.5, 0.0, 1.061)).norm() < 1e-6);
        // One side face looks straight at the robot (−x world).
        assert!(o
            .free_faces()
            .any(|f| o.face_normal(f).dot(&-Vector3::x()) > 0.999));
        // The bottom rests on the table; the top is free.
        let bottom = BoxFace::ALL
            .into_iter()
            .find(|&f| o.face_normal(f).z < -0.99)
            .unwrap();
        assert_eq!(
            o.blocked[BoxFace::ALL.iter().position(|&f| f == bottom).unwrap()],
            Some(FaceBlock::Support)
        );
        assert_eq!(o.free_faces().count(), 5);
    }

    #[test]
    fn a_ring_lying_flat_splits_at_its_hole_into_near_arc_middle_and_far_arc() {
        // A roll of tape: ring 40 mm, tube 15 mm, lying on a table at 0.75 m.
        let mesh = tsukami_body::mesh::TriangleMesh::torus(0.04, 0.015, 48, 16);
        let v: Vec<Point3<f64>> = mesh
            .vertices
            .iter()
            .map(|p| p + Vector3::new(0.5, -0.2, 0.75))
            .collect();
        let mut ocps = object_ocps(&v, &mesh.indices, &OcpParams::default());
        assert_eq!(ocps.len(), 3, "{ocps:?}");
        ocps.sort_by(|a, b| a.center.x.total_cmp(&b.center.x));
        // Split toward the robot (world x): the arcs hold the whole tube,
        // 30 mm from its outer to its inner side; the middle spans the hole.
        let along_x = |o: &Ocp| {
            let m = o.rotation.matrix();
            (0..3).map(|k| m[(0, k)].abs() * o.extents[k]).sum::<f64>()
        };
        let (near, middle, far) = (&ocps[0], &ocps[1], &ocps[2]);
        for arc in [near, far] {
            assert!((along_x(arc) - 0.03).abs() < 2e-3, "{arc:?}");
        }
        assert!((along_x(middle) - 0.05).abs() < 2e-3, "{middle:?}");
        // The near arc can be taken from the top and from the robot's side.
        for n in [Vector3::z(), -Vector3::x()] {
            assert!(near
                .free_faces()
                .any(|f| near.face_normal(f).dot(&n) > 0.99));
        }
    }

    #[test]
    fn short_parity_flips_cut_nothing() {
        let (t, f) = (true, false);
        // Material, hole, material: three parts.
        let flags = [t, t, t, t, f, f, f, f, f, t, t, t, t];
        assert_eq!(hole_runs(&flags, 3), vec![0..4, 4..9, 9..13]);
        // A one-slice flip (an untidy mesh) joins its neighbours.
        let flags = [t, t, t, t, f, t, t, t, t, t];
        assert_eq!(hole_runs(&flags, 3), vec![0..10]);
        // A short run at the start joins the next.
        let flags = [f, t, t, t, t, t];
        assert_eq!(hole_runs(&flags, 3), vec![0..6]);
    }

    #[test]
    fn vase_splits_into_regions_with_blocked_joints() {
        let profile = [
            (0.0, 0.04),
            (0.03, 0.06),
            (0.09, 0.075),
            (0.15, 0.06),
            (0.18, 0.03),
            (0.19, 0.022),
            (0.26, 0.022),
            (0.27, 0.035),
            (0.28, 0.035),
        ];
        let (v, t) = lathe(&profile, 32);
        let ocps = object_ocps(&v, &t, &OcpParams::default());
        assert!(ocps.len() >= 2, "{} regions", ocps.len());
        // Every region boundary blocks the two faces that meet there.
        let region_blocks: usize = ocps
            .iter()
            .map(|o| {
                o.blocked
                    .iter()
                    .filter(|b| **b == Some(FaceBlock::Region))
                    .count()
            })
            .sum();
        assert!(region_blocks >= 2 * (ocps.len() - 1));
        // The neck is much thinner than the body.
        let widths: Vec<f64> = ocps.iter().map(|o| o.extents.min()).collect();
        let (lo, hi) = widths
            .iter()
            .fold((f64::MAX, 0.0f64), |(a, b), &w| (a.min(w), b.max(w)));
        assert!(hi > 1.5 * lo, "{widths:?}");
    }

    #[test]
    fn lying_box_gets_its_own_axes() {
        // A 0.2 × 0.1 × 0.05 box rotated 30° about z.
        let rot = Rotation3::from_axis_angle(&Vector3::z_axis(), std::f64::consts::FRAC_PI_6);
        let half = Vector3::new(0.1, 0.05, 0.025);
        let v: Vec<Point3<f64>> = (0..8)
            .map(|i| {
                let s = Vector3::new(
                    if i & 1 == 1 { 1.0 } else { -1.0 },
                    if i & 2 == 2 { 1.0 } else { -1.0 },
                    if i & 4 == 4 { 1.0 } else { -1.0 },
                );
                Point3::from(rot * half.component_mul(&s))
            })
            .collect();
        let t = [
            [0, 2, 1],
            [1, 2, 3],
            [4, 5, 6],
            [5, 7, 6],
            [0, 1, 4],
            [1, 5, 4],
            [2, 6, 3],
            [3, 6, 7],
            [0, 4, 2],
            [2, 4, 6],
            [1, 3, 5],
            [3, 7, 5],
        ];
        let ocps = object_ocps(&v, &t, &OcpParams::default());
        assert_eq!(ocps.len(), 1);
        let e = ocps[0].extents;
        assert!((e - Vector3::new(0.2, 0.1, 0.05)).norm() < 1e-9, "{e:?}");
        let x = ocps[0].rotation.matrix().column(0).into_owned();
        assert!(x.dot(&(rot * Vector3::x())).abs() > 0.9999);
    }
}
