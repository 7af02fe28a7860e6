//! A voxel grid remembering the nearest surface sample of each cell: the
//! nearest-sample search of the coarse stages in constant time.
//!
//! What: [`SampleGrid`] covers a box around the model with cubic cells; each
//! cell holds the index of the surface sample nearest to its centre.
//!
//! Why: the coarse stage fits dozens of start poses per segment, each a dozen
//! ICP iterations over a few hundred points, then scores each fit: a k-d tree
//! search per point was most of the detection time. Coarse fits tolerate a
//! pairing that is off by a fraction of a cell; the full ICP and the final
//! verification keep the exact search.
//!
//! How: built once per template: every sample is offered to its own cell,
//! then raster sweeps forward and backward (twice) offer each cell the samples
//! held by its already visited neighbours, keeping the one nearest to the
//! cell's centre (vector propagation, as in Danielsson's Euclidean distance
//! transform: linear in the number of cells; near ties can leave a cell a
//! sample slightly farther than the nearest, by a fraction of a cell at
//! worst). A point's cell is `floor((p − lo) / cell)`; outside the box there
//! is no answer (such points are farther from the surface than the margin the
//! box was built with). The sample found is farther from the point than its
//! nearest by at most the cell's diagonal (plus that fraction).
//!
//! ```
//! use nalgebra::Point3;
//! use tsukami_vision::lookup::SampleGrid;
//! let samples = [Point3::new(0.02, 0.05, 0.05), Point3::new(0.08, 0.05, 0.05)];
//! let grid = SampleGrid::build(Point3::origin(), Point3::new(0.1, 0.1, 0.1), 0.01, &samples);
//! assert_eq!(grid.get(&Point3::new(0.031, 0.05, 0.05)), Some(0));
//! assert_eq!(grid.get(&Point3::new(0.071, 0.0, 0.09)), Some(1));
//! assert_eq!(grid.get(&Point3::new(0.2, 0.0, 0.0)), None);
//! ```

use nalgebra::{Point3, Vector3};

/// An empty cell.
const EMPTY: u32 = u32::MAX;
/// Most cells a grid may hold (16 MiB of indices).
pub const MAX_CELLS: usize = 4 << 20;

/// Nearest-sample indices on a voxel grid.
pub struct SampleGrid {
    lo: Point3<f64>,
    cell: f64,
    dims: [usize; 3],
    cells: Vec<u32>,
}

impl std::fmt::Debug for SampleGrid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SampleGrid")
            .field("lo", &self.lo)
            .field("cell", &self.cell)
            .field("dims", &self.dims)
            .finish()
    }
}

impl SampleGrid {
    /// A grid over the box `[lo, hi]` with cells of edge `cell` (m), enlarged
    /// when needed so that it holds at most [`MAX_CELLS`] cells, storing for
    /// each cell the sample of `samples` nearest to its centre.
    pub fn build(lo: Point3<f64>, hi: Point3<f64>, cell: f64, samples: &[Point3<f64>]) -> Self {
        let size: Vector3<f64> = (hi - lo).map(|v| v.max(0.0));
        let mut cell = cell.max(1e-6);
        let count = |c: f64| size.map(|v| (v / c).ceil().max(1.0) as usize);
        while count(cell).iter().product::<usize>() > MAX_CELLS {
            cell *= 1.25;
        }
        let d = count(cell);
        let mut grid = SampleGrid {
            lo,
            cell,
            dims: [d.x, d.y, d.z],
            cells: vec![EMPTY; d.iter().product()],
        };
        let mut best = vec![f64::INFINITY; grid.cells.len()];
        for (j, p) in samples.iter().enumerate() {
            if let Some(i) = grid.index(p) {
                grid.offer(&mut best, i, j as u32, samples);
            }
        }
        for _ in 0..2 {
            grid.sweep(&mut best, samples, true);
            grid.sweep(&mut best, samples, false);
        }
        grid
    }

    /// The centre of cell `i`.
    fn centre(&self, i: usize) -> Point3<f64> {
        let [nx, ny, _] = self.dims;
        let (x, y, z) = (i % nx, i / nx % ny, i / nx / ny);
        self.lo + Vector3::new(x as f64 + 0.5, y as f64 + 0.5, z as f64 + 0.5) * self.cell
    }

    /// Stores sample `j` in cell `i` if it is nearer to its centre than the
    /// one there.
    fn offer(&mut self, best: &mut [f64], i: usize, j: u32, samples: &[Point3<f64>]) {
        let d2 = (samples[j as usize] - self.centre(i)).norm_squared();
        if d2 < best[i] {
            best[i] = d2;
            self.cells[i] = j;
        }
    }

    /// One raster pass (forward or backward) offering each cell the samples
    /// of its 13 neighbours already visited in that order (vector
    /// propagation, as in Danielsson's distance transform).
    fn sweep(&mut self, best: &mut [f64], samples: &[Point3<f64>], forward: bool) {
        let [nx, ny, nz] = self.dims;
        let sign: i64 = if forward { 1 } else { -1 };
        let mut offsets = Vec::with_capacity(13);
        for dz in -1i64..=0 {
            for dy in -1i64..=1 {
                for dx in -1i64..=1 {
                    if dz < 0 || dy < 0 || (dy == 0 && dx < 0) {
                        offsets.push((sign * dx, sign * dy, sign * dz));
                    }
                }
            }
        }
        let order = |n: usize, k: usize| if forward { k } else { n - 1 - k };
        for kz in 0..nz {
            let z = order(nz, kz);
            for ky in 0..ny {
                let y = order(ny, ky);
                for kx in 0..nx {
                    let x = order(nx, kx);
                    let i = (z * ny + y) * nx + x;
                    let centre = self.lo
                        + Vector3::new(x as f64 + 0.5, y as f64 + 0.5, z as f64 + 0.5) * self.cell;
                    for &(dx, dy, dz) in &offsets {
                        let (a, b, c) = (x as i64 + dx, y as i64 + dy, z as i64 + dz);
                        if a < 0
                            || b < 0
                            || c < 0
                            || a >= nx as i64
                            || b >= ny as i64
                            || c >= nz as i64
                        {
                            continue;
                        }
                        let j = self.cells[(c as usize * ny + b as usize) * nx + a as usize];
                        if j == EMPTY || j == self.cells[i] {
                            continue;
                        }
                        let d2 = (samples[j as usize] - centre).norm_squared();
                        if d2 < best[i] {
                            best[i] = d2;
                            self.cells[i] = j;
                        }
                    }
                }
            }
        }
    }

    /// The index of the cell holding `p`, if inside.
    #[inline]
    fn index(&self, p: &Point3<f64>) -> Option<usize> {
        let r = (p - self.lo) / self.cell;
        let mut idx = [0usize; 3];
        for k in 0..3 {
            // Also false for NaN.
            if !(r[k] >= 0.0 && r[k] < self.dims[k] as f64) {
                return None;
            }
            idx[k] = r[k] as usize;
        }
        Some((idx[2] * self.dims[1] + idx[1]) * self.dims[0] + idx[0])
    }

    /// Edge of a cell (m).
    pub fn cell(&self) -> f64 {
        self.cell
    }

    /// The sample stored for the cell holding `p`; `None` outside the grid
    /// (or for a grid built without samples).
    #[inline]
    pub fn get(&self, p: &Point3<f64>) -> Option<u32> {
        self.index(p).map(|i| self.cells[i]).filter(|&j| j != EMPTY)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn pairs_within_a_cell_diagonal_of_the_nearest() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        // Samples on a sphere of radius 3 cm.
        let samples: Vec<Point3<f64>> = (0..2000)
            .map(|_| {
                let v = Vector3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                );
                Point3::from(v.normalize() * 0.03)
            })
            .collect();
        let (lo, hi) = (
            Point3::new(-0.05, -0.05, -0.05),
            Point3::new(0.05, 0.05, 0.05),
        );
        let grid = SampleGrid::build(lo, hi, 0.004, &samples);
        let diagonal = grid.cell() * 3f64.sqrt();
        let (mut worst, mut close): (f64, usize) = (0.0, 0);
        for _ in 0..2000 {
            let p = Point3::new(
                rng.random_range(-0.05..0.05),
                rng.random_range(-0.05..0.05),
                rng.random_range(-0.05..0.05),
            );
            let j = grid.get(&p).expect("inside") as usize;
            let nearest = samples
                .iter()
                .map(|s| (s - p).norm())
                .fold(f64::INFINITY, f64::min);
            assert!((samples[j] - p).norm() <= nearest + diagonal + 1e-12);
            // The stored sample is the nearest to the cell's centre, or one
            // hardly farther (vector propagation keeps a near tie).
            let r = (p - lo) / grid.cell();
            let c = lo + r.map(|v| v.floor() + 0.5) * grid.cell();
            let best = samples
                .iter()
                .map(|s| (s - c).norm())
                .fold(f64::INFINITY, f64::min);
            let excess = (samples[j] - c).norm() - best;
            worst = worst.max(excess);
            close += usize::from(excess < 1e-4);
        }
        assert!(
            worst < 0.5 * grid.cell(),
            "{worst} m farther than the nearest"
        );
        // Inside a sphere of samples most cells have many near-equidistant ones.
        assert!(
            close >= 1300,
            "{close} of 2000 within 0.1 mm of the nearest"
        );
        assert_eq!(grid.get(&Point3::new(0.06, 0.0, 0.0)), None);
        assert_eq!(grid.get(&Point3::new(f64::NAN, 0.0, 0.0)), None);
    }
}
