//! Influence blocks of cells on a regular lattice, applied by FFT (MODEL §5.5).
//!
//! When every cell of a group has the same shape and orientation (normal, in-plane axes, half
//! sides) and the centres lie on a lattice c0 + i g1 + j g2 (i < nx, j < ny, the cells numbered
//! i + j nx), a coefficient depends on the index offset only: C(r, s) = T(i_r - i_s, j_r - j_s).
//! The block diag(1/lever) T diag(1/lever) is then a two-level Toeplitz matrix; its product
//! with a load vector is a discrete convolution, computed by FFT on a zero-padded grid of at
//! least (2 nx - 1) x (2 ny - 1) points (no wrap-around: the result is the non-periodic
//! half-space's, the same as the dense block's to round-off). Cost O(n log n) per product and
//! O(n) memory instead of O(n^2) for both. A product with few loaded cells is summed
//! directly from the kernel (cheaper than two transforms).
//!
//! The kernel T holds the numbers [`super::symmetric_block`] gives for such a group: the
//! coefficient with the lower-numbered cell as the receiver, divided by the source's area,
//! mirrored (T(-d) = T(d)), so the operator is symmetric as the solvers need. Flat contacts
//! (the Hertz checks) have such cells; a gear flank's cells never do (their normals turn).

use super::{coefficient, ContactCell, ElasticPair};
use realfft::num_complex::Complex;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use rustfft::Fft;
use std::sync::{Arc, OnceLock};

/// Relative tolerance of the lattice test: centres within this fraction of the lattice
/// spacing, unit vectors within it, half sides within it relatively. The coefficients then
/// differ from the pairwise ones by about this fraction, below the solvers' tolerance.
const LATTICE_TOLERANCE: f64 = 1e-10;

/// Work of a transform-based product relative to one multiply-add of a direct column sum,
/// per padded point and per factor of two in the padded size (measured on the Hertz grids,
/// BENCHMARKS.md session 27): a product sums columns directly while
/// loaded cells x cells < FFT_WORK x points x log2(points).
const FFT_WORK: f64 = 4.0;

/// The block of a lattice of identical cells (module doc): the kernel, the levers' scaling
/// and the kernel's spectrum on the padded grid, with the transform plans.
#[derive(Clone)]
pub struct GridInfluence {
    nx: usize,
    ny: usize,
    /// Padded grid, points along the lattice's first and second directions.
    px: usize,
    py: usize,
    /// T(dx, dy) at kernel[(dx + nx - 1) + (dy + ny - 1) (2 nx - 1)], m/Pa per m^2 of source
    /// (displacement per unit force).
    kernel: Vec<f64>,
    /// 1 / lever of each cell, 1/m.
    scale: Vec<f64>,
    /// Spectrum of the padded kernel divided by px py, column-major: (px / 2 + 1) columns of
    /// py values.
    spectrum: Vec<Complex<f64>>,
    forward_rows: Arc<dyn RealToComplex<f64>>,
    inverse_rows: Arc<dyn ComplexToReal<f64>>,
    forward_columns: Arc<dyn Fft<f64>>,
    inverse_columns: Arc<dyn Fft<f64>>,
    /// Rows handed out by [`GridInfluence::row`], built on first use.
    rows: Vec<OnceLock<Box<[f64]>>>,
}

impl std::fmt::Debug for GridInfluence {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GridInfluence")
            .field("nx", &self.nx)
            .field("ny", &self.ny)
            .field("px", &self.px)
            .field("py", &self.py)
            .finish_non_exhaustive()
    }
}

/// The lattice (nx, ny) of `cells` when they are identical in shape and orientation and
/// numbered i + j nx on centres c0 + i g1 + j g2 (g1, g2 not parallel; one line: ny = 1);
/// None otherwise.
pub fn lattice(cells: &[ContactCell]) -> Option<(usize, usize)> {
    let n = cells.len();
    if n < 2 || !cells.iter().all(|c| same_shape(c, &cells[0])) {
        return None;
    }
    let c0 = cells[0].centre;
    let step = cells[1].centre - c0;
    let tol = LATTICE_TOLERANCE * step.norm();
    if step.norm() == 0.0 {
        return None;
    }
    // The row length: the first place where the step from the previous centre changes.
    let nx = (2..n)
        .find(|&k| ((cells[k].centre - cells[k - 1].centre) - step).norm() > tol)
        .unwrap_or(n);
    if !n.is_multiple_of(nx) {
        return None;
    }
    let ny = n / nx;
    let g1 = (cells[nx - 1].centre - c0) / (nx - 1).max(1) as f64;
    let g2 = if ny > 1 {
        (cells[(ny - 1) * nx].centre - c0) / (ny - 1) as f64
    } else {
        g1.cross(&cells[0].normal)
    };
    if g1.cross(&g2).norm() <= 1e-6 * g1.norm() * g2.norm() {
        return None;
    }
    let on_lattice = cells.iter().enumerate().all(|(k, c)| {
        let expected = c0 + g1 * (k % nx) as f64 + g2 * (k / nx) as f64;
        (c.centre - expected).norm() <= tol
    });
    on_lattice.then_some((nx, ny))
}

/// Whether two cells have the same normal, in-plane axes and half sides (to the lattice
/// tolerance).
fn same_shape(a: &ContactCell, b: &ContactCell) -> bool {
    let close = |u: &nalgebra::Vector3<f64>, v: &nalgebra::Vector3<f64>| {
        (u - v).amax() <= LATTICE_TOLERANCE
    };
    let near = |x: f64, y: f64| (x - y).abs() <= LATTICE_TOLERANCE * x.abs().max(y.abs());
    close(&a.normal, &b.normal)
        && close(&a.axis_nu, &b.axis_nu)
        && close(&a.axis_zeta, &b.axis_zeta)
        && near(a.half_nu, b.half_nu)
        && near(a.half_zeta, b.half_zeta)
}

/// The smallest n >= at least whose prime factors are 2, 3 and 5 (fast transform sizes);
/// even when `even`.
fn transform_size(at_least: usize, even: bool) -> usize {
    (at_least.max(1)..)
        .find(|&m| {
            let mut r = m;
            for p in [2, 3, 5] {
                while r % p == 0 {
                    r /= p;
                }
            }
            r == 1 && (!even || m % 2 == 0)
        })
        .expect("a 5-smooth number exists above any size")
}

impl GridInfluence {
    /// The block of `cells` with their levers (m) when they form a lattice ([`lattice`]);
    /// None otherwise. Entries in the units of [`super::symmetric_block`].
    pub fn new(pair: &ElasticPair, cells: &[ContactCell], levers: &[f64]) -> Option<Self> {
        assert_eq!(levers.len(), cells.len());
        let (nx, ny) = lattice(cells)?;
        let kernel = lattice_kernel(pair, cells, nx, ny);
        let (px, py) = (
            transform_size(2 * nx - 1, true),
            transform_size(2 * ny - 1, false),
        );
        let mut real_planner = RealFftPlanner::<f64>::new();
        let mut planner = rustfft::FftPlanner::<f64>::new();
        let mut grid = Self {
            nx,
            ny,
            px,
            py,
            kernel,
            scale: levers.iter().map(|l| 1.0 / l).collect(),
            spectrum: Vec::new(),
            forward_rows: real_planner.plan_fft_forward(px),
            inverse_rows: real_planner.plan_fft_inverse(px),
            forward_columns: planner.plan_fft_forward(py),
            inverse_columns: planner.plan_fft_inverse(py),
            rows: (0..cells.len()).map(|_| OnceLock::new()).collect(),
        };
        grid.spectrum = grid.kernel_spectrum();
        Some(grid)
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.nx * self.ny
    }

    /// True for a block without cells (never: a lattice has two cells at least).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The lattice's shape (nx, ny).
    pub fn shape(&self) -> (usize, usize) {
        (self.nx, self.ny)
    }

    /// T at the index offset of receiver r from source s.
    #[inline]
    fn kernel_at(&self, r: usize, s: usize) -> f64 {
        let (w, nx, ny) = (2 * self.nx - 1, self.nx, self.ny);
        let dx = (r % nx + nx - 1) - s % nx;
        let dy = (r / nx + ny - 1) - s / nx;
        self.kernel[dx + dy * w]
    }

    /// Entry (r, s) of the block.
    #[inline]
    pub fn entry(&self, r: usize, s: usize) -> f64 {
        (self.scale[r] * self.scale[s]) * self.kernel_at(r, s)
    }

    /// Row j (= column j), built on first use.
    pub fn row(&self, j: usize) -> &[f64] {
        self.rows[j].get_or_init(|| (0..self.len()).map(|k| self.entry(k, j)).collect())
    }

    /// The block on the cells `inside` (ascending), row-major.
    pub fn sub_block(&self, inside: &[usize]) -> Vec<f64> {
        let mut out = Vec::with_capacity(inside.len() * inside.len());
        for &r in inside {
            out.extend(inside.iter().map(|&s| self.entry(r, s)));
        }
        out
    }

    /// y = B x (x and y of the block's length): summed over the loaded cells' columns when
    /// they are few, else by FFT.
    pub fn product(&self, x: &[f64], y: &mut [f64]) {
        let n = self.len();
        let loaded = x.iter().filter(|v| **v != 0.0).count();
        let points = (self.px * self.py) as f64;
        if (loaded * n) as f64 <= FFT_WORK * points * points.log2() {
            self.column_product(x, y);
        } else {
            self.fft_product(x, y);
        }
    }

    /// y = B x summed over the non-zero entries of x, each a shifted copy of the kernel.
    pub fn column_product(&self, x: &[f64], y: &mut [f64]) {
        let (nx, ny, w) = (self.nx, self.ny, 2 * self.nx - 1);
        y.iter_mut().for_each(|v| *v = 0.0);
        for (s, &v) in x.iter().enumerate() {
            if v == 0.0 {
                continue;
            }
            let a = v * self.scale[s];
            let (is, js) = (s % nx, s / nx);
            for jr in 0..ny {
                let start = (nx - 1 - is) + (jr + ny - 1 - js) * w;
                let segment = &self.kernel[start..start + nx];
                for (yi, t) in y[jr * nx..(jr + 1) * nx].iter_mut().zip(segment) {
                    *yi += a * t;
                }
            }
        }
        for (yi, s) in y.iter_mut().zip(&self.scale) {
            *yi *= s;
        }
    }

    /// y = B x by FFT: the scaled loads' rows transformed (real to complex), then the
    /// columns, times the kernel's spectrum, and back.
    pub fn fft_product(&self, x: &[f64], y: &mut [f64]) {
        let mut columns = self.columns_of(x.iter().zip(&self.scale).map(|(v, s)| v * s));
        for (c, k) in columns.iter_mut().zip(&self.spectrum) {
            *c *= k;
        }
        self.transform_columns(&mut columns, false);
        self.rows_from_columns(&columns, y);
        for (yi, s) in y.iter_mut().zip(&self.scale) {
            *yi *= s;
        }
    }

    /// The 2-D spectrum of values given for the nx x ny lattice (zero on the rest of the
    /// padded grid), column-major.
    fn columns_of(&self, values: impl Iterator<Item = f64>) -> Vec<Complex<f64>> {
        let (nx, px, py) = (self.nx, self.px, self.py);
        let mut padded = vec![0.0; px * self.ny];
        for (k, v) in values.enumerate() {
            padded[(k / nx) * px + k % nx] = v;
        }
        self.columns_of_rows(&mut padded, self.ny, py)
    }

    /// Rows of px real values (`count` of them, the others zero) transformed along x, then
    /// gathered into `half` columns of py complex values and transformed along y.
    fn columns_of_rows(&self, padded: &mut [f64], count: usize, py: usize) -> Vec<Complex<f64>> {
        use rayon::prelude::*;
        let (px, half) = (self.px, self.px / 2 + 1);
        let mut spectra = vec![Complex::new(0.0, 0.0); half * count];
        let rows = padded.par_chunks_mut(px).zip(spectra.par_chunks_mut(half));
        rows.with_min_len(16).for_each_init(
            || self.forward_rows.make_scratch_vec(),
            |scratch, (row, spectrum)| {
                self.forward_rows
                    .process_with_scratch(row, spectrum, scratch)
                    .expect("buffer lengths from the plan");
            },
        );
        let mut columns = vec![Complex::new(0.0, 0.0); half * py];
        columns
            .par_chunks_mut(py)
            .enumerate()
            .with_min_len(16)
            .for_each(|(kx, column)| {
                for (j, c) in column[..count].iter_mut().enumerate() {
                    *c = spectra[j * half + kx];
                }
            });
        self.transform_columns(&mut columns, true);
        columns
    }

    /// Transforms every column (py values each) forward or backward.
    fn transform_columns(&self, columns: &mut [Complex<f64>], forward: bool) {
        use rayon::prelude::*;
        let plan = if forward {
            &self.forward_columns
        } else {
            &self.inverse_columns
        };
        let py = self.py;
        let per_task = py * 16;
        columns.par_chunks_mut(per_task).for_each_init(
            || vec![Complex::new(0.0, 0.0); plan.get_inplace_scratch_len()],
            |scratch, chunk| plan.process_with_scratch(chunk, scratch),
        );
    }

    /// The lattice's values (first nx x ny points) of the inverse row transforms of the
    /// columns' first ny rows, into `out` (row-major nx x ny).
    fn rows_from_columns(&self, columns: &[Complex<f64>], out: &mut [f64]) {
        use rayon::prelude::*;
        let (nx, px, py, half) = (self.nx, self.px, self.py, self.px / 2 + 1);
        out.par_chunks_mut(nx)
            .enumerate()
            .with_min_len(16)
            .for_each_init(
                || {
                    (
                        vec![Complex::new(0.0, 0.0); half],
                        vec![0.0; px],
                        self.inverse_rows.make_scratch_vec(),
                    )
                },
                |(spectrum, row, scratch), (j, target)| {
                    for (kx, s) in spectrum.iter_mut().enumerate() {
                        *s = columns[kx * py + j];
                    }
                    // A real signal's spectrum is real at 0 and px / 2: drop the round-off.
                    spectrum[0].im = 0.0;
                    spectrum[half - 1].im = 0.0;
                    self.inverse_rows
                        .process_with_scratch(spectrum, row, scratch)
                        .expect("real end values");
                    target.copy_from_slice(&row[..nx]);
                },
            );
    }

    /// The kernel wrapped onto the padded grid (offset d at d mod (px, py)), transformed and
    /// divided by px py (the inverse transforms are unnormalised).
    fn kernel_spectrum(&self) -> Vec<Complex<f64>> {
        let (nx, ny, px, py, w) = (self.nx, self.ny, self.px, self.py, 2 * self.nx - 1);
        let mut padded = vec![0.0; px * py];
        for dy in 0..2 * ny - 1 {
            let gy = (dy + py - (ny - 1)) % py;
            for dx in 0..w {
                let gx = (dx + px - (nx - 1)) % px;
                padded[gy * px + gx] = self.kernel[dx + dy * w];
            }
        }
        let mut spectrum = self.columns_of_rows(&mut padded, py, py);
        let norm = 1.0 / (px * py) as f64;
        spectrum.iter_mut().for_each(|c| *c *= norm);
        spectrum
    }
}

/// T(dx, dy) for every offset of an nx x ny lattice, (2 nx - 1) x (2 ny - 1) values: the
/// coefficient with the lower-numbered cell as the receiver over the source's area
/// ([`super::symmetric_block`]'s entries), mirrored to the opposite offset.
fn lattice_kernel(pair: &ElasticPair, cells: &[ContactCell], nx: usize, ny: usize) -> Vec<f64> {
    let w = 2 * nx - 1;
    let mut kernel = vec![0.0; w * (2 * ny - 1)];
    let inv_area = 1.0 / cells[0].area();
    for dy in -(ny as isize - 1)..=(ny as isize - 1) {
        for dx in -(nx as isize - 1)..=(nx as isize - 1) {
            // The receiver numbered lower than the source: offset dx + dy nx <= 0.
            if dx + dy * nx as isize > 0 {
                continue;
            }
            let at = |i: isize, j: isize| i.max(0) as usize + j.max(0) as usize * nx;
            let (receiver, source) = (at(dx, dy), at(-dx, -dy));
            let value = coefficient(pair, &cells[receiver], &cells[source]) * inv_area;
            let index = |i: isize, j: isize| {
                (i + nx as isize - 1) as usize + (j + ny as isize - 1) as usize * w
            };
            kernel[index(dx, dy)] = value;
            kernel[index(-dx, -dy)] = value;
        }
    }
    kernel
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    fn pair() -> ElasticPair {
        ElasticPair::new(203e9, 0.29, 110e9, 0.29)
    }

    /// nx x ny identical cells on a skewed lattice out of their tangent plane (so the
    /// tangential Boussinesq term is not zero), numbered i + j nx, levers varying.
    fn skewed_lattice(nx: usize, ny: usize) -> (Vec<ContactCell>, Vec<f64>) {
        let normal = Vector3::new(0.1, 0.2, 1.0).normalize();
        let axis_nu = Vector3::x().cross(&normal).normalize();
        let axis_zeta = normal.cross(&axis_nu);
        let (h_nu, h_zeta) = (0.1e-3, 0.07e-3);
        let g1 = axis_zeta * 2.0 * h_zeta + normal * 0.01e-3;
        let g2 = axis_nu * 2.0 * h_nu + axis_zeta * 0.03e-3;
        let mut cells = Vec::new();
        let mut levers = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                cells.push(ContactCell {
                    centre: Vector3::new(0.03, -0.01, 0.002) + g1 * i as f64 + g2 * j as f64,
                    normal,
                    axis_nu,
                    axis_zeta,
                    half_nu: h_nu,
                    half_zeta: h_zeta,
                });
                levers.push(0.08 + 0.001 * ((i * 7 + j * 3) % 11) as f64);
            }
        }
        (cells, levers)
    }

    /// Dense product with the pairwise block of `symmetric_block`.
    fn dense_product(matrix: &[f64], x: &[f64]) -> Vec<f64> {
        let n = x.len();
        (0..n)
            .map(|r| (0..n).map(|s| matrix[r * n + s] * x[s]).sum())
            .collect()
    }

    #[test]
    fn a_lattice_block_equals_the_pairwise_block() {
        // Skewed lattices (2-D, one line, one column of a 2-D shape), entries, rows,
        // sub-blocks and both products against symmetric_block, with loads on a few cells
        // and on every cell.
        for (nx, ny) in [(13, 9), (17, 1), (8, 12)] {
            let (cells, levers) = skewed_lattice(nx, ny);
            let n = cells.len();
            let dense = super::super::symmetric_block(&pair(), &cells, &levers);
            let grid = GridInfluence::new(&pair(), &cells, &levers).expect("a lattice");
            assert_eq!(grid.shape(), (nx, ny));
            let scale = dense.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let mut worst = 0.0f64;
            for r in 0..n {
                for s in 0..n {
                    let (g, d) = (grid.entry(r, s), dense[r * n + s]);
                    worst = worst.max((g - d).abs() / scale);
                }
            }
            // Round-off of the centres' differences (the lattice tolerance allows 1e-10).
            assert!(worst <= 1e-12, "{nx} x {ny}: entries differ by {worst:e}");
            assert_eq!(
                grid.row(5),
                &(0..n).map(|k| grid.entry(k, 5)).collect::<Vec<_>>()[..]
            );
            let inside = [1, 4, 5, n - 1];
            let sub = grid.sub_block(&inside);
            assert_eq!(sub[4 + 2], grid.entry(4, 5));
            let every: Vec<f64> = (0..n).map(|k| 1.0 + ((k * 5) % 7) as f64).collect();
            let few: Vec<f64> = (0..n).map(|k| if k % 9 == 2 { 2.0 } else { 0.0 }).collect();
            for x in [every, few] {
                let expected = dense_product(&dense, &x);
                let big = expected.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                let (mut by_fft, mut by_columns) = (vec![0.0; n], vec![0.0; n]);
                grid.fft_product(&x, &mut by_fft);
                grid.column_product(&x, &mut by_columns);
                let differ = |y: &[f64]| {
                    y.iter()
                        .zip(&expected)
                        .map(|(a, b)| (a - b).abs() / big)
                        .fold(0.0, f64::max)
                };
                let (fft, sum) = (differ(&by_fft), differ(&by_columns));
                eprintln!("{nx} x {ny}: entries {worst:.1e}, FFT {fft:.1e}, sums {sum:.1e}");
                assert!(fft <= 1e-12 && sum <= 1e-12, "FFT {fft:e}, sums {sum:e}");
            }
        }
    }

    #[test]
    fn cells_off_a_lattice_are_refused() {
        // One cell moved by a hundredth of a spacing, one turned, one larger, a numbering
        // whose rows have different lengths: no lattice.
        let (cells, _) = skewed_lattice(6, 5);
        assert_eq!(lattice(&cells), Some((6, 5)));
        let mut moved = cells.clone();
        moved[14].centre.x += 2e-6;
        let mut turned = cells.clone();
        turned[3].normal = (turned[3].normal + Vector3::new(0.0, 1e-3, 0.0)).normalize();
        let mut larger = cells.clone();
        larger[7].half_nu *= 1.001;
        for bad in [
            moved,
            turned,
            larger,
            cells[..29].to_vec(),
            cells[..1].to_vec(),
        ] {
            assert_eq!(lattice(&bad), None);
        }
    }

    #[test]
    fn transform_sizes_are_five_smooth() {
        assert_eq!(transform_size(255, true), 256);
        assert_eq!(transform_size(193, true), 200);
        assert_eq!(transform_size(7, false), 8);
        assert_eq!(transform_size(1, false), 1);
        assert_eq!(transform_size(1, true), 2);
    }
}
