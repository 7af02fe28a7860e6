//! Convex hulls of 6-D wrench sets, for [`crate::ferrari_canny`].
//!
//! **What.** [`hull`] returns every facet of the hull of a point set as a unit
//! outward normal and an offset (`normal · x + offset ≤ 0` inside) and, when
//! asked, the indices of the points that are hull vertices.
//!
//! **Why.** Ferrari–Canny ε is the distance from the origin to the nearest
//! facet, and the L∞ Minkowski sum is pruned to hull vertices. No maintained
//! pure-Rust crate builds hulls in six dimensions (the ones on crates.io stop
//! at 3-D or 4-D), while Qhull handles the degenerate, coplanar wrench sets
//! grasps produce.
//!
//! **How.** Qhull 2020.2 (`libqhull_r`) is vendored in `host/grasp/vendor/qhull` and
//! compiled by `build.rs` with the `cc` crate — a C compiler is all the build
//! needs (no bindgen, no libclang). `csrc/hull.c` is the one C function this
//! module declares by hand; Qhull's errors unwind inside C (its own `setjmp`)
//! and come back as an exit code. Qhull runs with its default options, the
//! same as the `qhull` crate used before; `tests/hull_reference.rs` checks ε
//! against values recorded with that crate.
//!
//! ```
//! use nalgebra::Vector6;
//! use tsukami_grasp::hull::hull;
//!
//! // The cross-polytope ±e_k: 64 facets, each at distance 1/√6 from the origin.
//! let points: Vec<Vector6<f64>> = (0..12)
//!     .map(|i| {
//!         let mut p = Vector6::zeros();
//!         p[i / 2] = if i % 2 == 0 { 1.0 } else { -1.0 };
//!         p
//!     })
//!     .collect();
//! let h = hull(&points, true).unwrap();
//! assert_eq!(h.facets.len(), 64);
//! assert!(h.facets.iter().all(|f| (-f.offset - 1.0 / 6f64.sqrt()).abs() < 1e-12));
//! assert_eq!(h.vertices.len(), 12);
//! ```

use std::ffi::{c_int, c_void};

use nalgebra::Vector6;

/// Dimension of the wrench space.
const DIM: usize = 6;

/// A hull facet: `normal · x + offset ≤ 0` inside, `normal` of unit length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Facet {
    /// Unit outward normal.
    pub normal: Vector6<f64>,
    /// Offset; `-offset` is the facet's signed distance from the origin
    /// (positive when the origin is inside).
    pub offset: f64,
}

/// The hull of a point set.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Hull {
    /// Every facet (Qhull's default output: merged facets where points are coplanar).
    pub facets: Vec<Facet>,
    /// Indices into the input of the hull's vertices (empty unless asked for).
    pub vertices: Vec<usize>,
}

/// Why no hull was built.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum HullError {
    /// A 6-D hull needs at least seven points.
    #[error("a 6-D hull needs at least 7 points, got {0}")]
    TooFewPoints(usize),
    /// A coordinate is NaN or infinite.
    #[error("point {0} has a non-finite coordinate")]
    NotFinite(usize),
    /// More points than the C interface can index.
    #[error("{0} points are more than the hull can take")]
    TooManyPoints(usize),
    /// Qhull stopped, e.g. because the points span fewer than six dimensions.
    #[error("Qhull failed with exit code {0} (flat or degenerate point set)")]
    Qhull(i32),
}

type FacetFn = unsafe extern "C" fn(ctx: *mut c_void, normal: *const f64, offset: f64);
type VertexFn = unsafe extern "C" fn(ctx: *mut c_void, point_index: c_int);

extern "C" {
    /// `csrc/hull.c`: Qhull on `num_points` points of `dim` coordinates.
    fn tsukami_qhull_hull(
        dim: c_int,
        num_points: c_int,
        points: *mut f64,
        ctx: *mut c_void,
        on_facet: FacetFn,
        on_vertex: Option<VertexFn>,
    ) -> c_int;
}

/// Receives one facet from C.
///
/// # Safety
/// `ctx` is the `&mut Hull` passed to `tsukami_qhull_hull`; `normal` points to
/// `DIM` doubles.
unsafe extern "C" fn push_facet(ctx: *mut c_void, normal: *const f64, offset: f64) {
    // SAFETY: guaranteed by the caller contract above (hull() below).
    let (out, normal) = unsafe {
        (
            &mut *ctx.cast::<Hull>(),
            std::slice::from_raw_parts(normal, DIM),
        )
    };
    out.facets.push(Facet {
        normal: Vector6::from_column_slice(normal),
        offset,
    });
}

/// Receives one vertex index from C.
///
/// # Safety
/// `ctx` is the `&mut Hull` passed to `tsukami_qhull_hull`.
unsafe extern "C" fn push_vertex(ctx: *mut c_void, point_index: c_int) {
    // SAFETY: guaranteed by the caller contract above (hull() below).
    let out = unsafe { &mut *ctx.cast::<Hull>() };
    if let Ok(i) = usize::try_from(point_index) {
        out.vertices.push(i);
    }
}

/// The convex hull of `points`, with the vertex indices when `with_vertices`.
pub fn hull(points: &[Vector6<f64>], with_vertices: bool) -> Result<Hull, HullError> {
    if points.len() <= DIM {
        return Err(HullError::TooFewPoints(points.len()));
    }
    if let Some(i) = points.iter().position(|p| !p.iter().all(|x| x.is_finite())) {
        return Err(HullError::NotFinite(i));
    }
    let count = c_int::try_from(points.len())
        .ok()
        .filter(|&n| (n as usize).checked_mul(DIM).is_some())
        .ok_or(HullError::TooManyPoints(points.len()))?;
    let mut coords: Vec<f64> = points.iter().flat_map(|p| p.iter().copied()).collect();
    let mut out = Hull::default();
    // SAFETY: `coords` holds `count * DIM` doubles and outlives the call (Qhull
    // keeps pointers into it only until it returns, after freeing its state);
    // `ctx` is `&mut out`, which the callbacks alone use, during the call only.
    let code = unsafe {
        tsukami_qhull_hull(
            DIM as c_int,
            count,
            coords.as_mut_ptr(),
            (&mut out as *mut Hull).cast::<c_void>(),
            push_facet,
            with_vertices.then_some(push_vertex as VertexFn),
        )
    };
    if code != 0 {
        return Err(HullError::Qhull(code));
    }
    Ok(out)
}
