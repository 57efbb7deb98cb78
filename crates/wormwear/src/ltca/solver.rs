//! Solvers of the load-sharing problem (MODEL §5.2-5.4) in the form
//!
//! ```text
//! y_i = sum_j K_ij q_j + e_i - alpha >= 0,   q_i >= 0,   q_i y_i = 0,   sum_i q_i = W
//! ```
//!
//! K symmetric positive definite (block diagonal: one dense block per tooth, plus an optional
//! low-rank term F C F^T for bending), e_i the initial separations, alpha the rigid approach
//! (the multiplier of the load constraint). In the LTCA, q_i = l_i f_i is the moment of cell i's
//! force about the wheel axis (l_i the lever), K_ij = C_ij / (l_i l_j) and W the wheel torque,
//! so y, e and alpha are angles of the wheel — exactly MODEL §5.2 with R_i = 1/l_i.
//!
//! Two solvers: the Polonsky-Keer conjugate gradient with active set (fast, default) and the
//! published fixed point on the approach (reference).

/// y += sum_k a_k c_k for four columns (unused ones with a_k = 0).
#[inline(always)]
fn axpy4(y: &mut [f64], a: [f64; 4], c: [&[f64]; 4]) {
    let n = y.len();
    let (c0, c1, c2, c3) = (&c[0][..n], &c[1][..n], &c[2][..n], &c[3][..n]);
    for i in 0..n {
        y[i] += a[0] * c0[i] + a[1] * c1[i] + a[2] * c2[i] + a[3] * c3[i];
    }
}

/// [`axpy4`] compiled for AVX2 + FMA, chosen at run time.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn axpy4_avx2(y: &mut [f64], a: [f64; 4], c: [&[f64]; 4]) {
    axpy4(y, a, c)
}

/// Symmetric block on a contiguous range of unknowns.
#[derive(Debug, Clone)]
pub struct Block {
    pub start: usize,
    pub size: usize,
    pub matrix: BlockMatrix,
}

/// A block's entries: dense, or influence coefficients assembled as the solvers read them.
/// (Single precision was tried for speed: the rounding made a near-singular worn-flank block
/// indefinite and the CG failed late in case B.)
#[derive(Debug, Clone)]
pub enum BlockMatrix {
    /// Row-major size x size (shared with the lazy block it was cut from, if any).
    Dense(std::sync::Arc<Vec<f64>>),
    /// Rows and sub-blocks on demand, the same numbers as the dense block.
    Lazy(Box<crate::contact::InfluenceRows>),
}

impl Block {
    /// A dense block (row-major size x size).
    pub fn dense(start: usize, size: usize, matrix: Vec<f64>) -> Self {
        assert_eq!(matrix.len(), size * size);
        Self {
            start,
            size,
            matrix: BlockMatrix::Dense(std::sync::Arc::new(matrix)),
        }
    }

    /// Row j of the block (= column j: symmetric), local index.
    #[inline]
    pub fn row(&self, j: usize) -> &[f64] {
        match &self.matrix {
            BlockMatrix::Dense(m) => &m[j * self.size..(j + 1) * self.size],
            BlockMatrix::Lazy(rows) => rows.row(j),
        }
    }

    /// The block on the local unknowns `inside` (ascending), row-major.
    fn sub_block(&self, inside: &[usize]) -> std::sync::Arc<Vec<f64>> {
        match &self.matrix {
            BlockMatrix::Dense(_) => {
                let mut matrix = Vec::with_capacity(inside.len() * inside.len());
                for &r in inside {
                    let row = self.row(r);
                    matrix.extend(inside.iter().map(|&c| row[c]));
                }
                std::sync::Arc::new(matrix)
            }
            BlockMatrix::Lazy(rows) => rows.sub_block(inside),
        }
    }
}

/// Dot product with four independent partial sums (lets the compiler vectorise the
/// reduction; the summation order differs from a plain left-to-right sum by round-off).
#[inline(always)]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut acc = [0.0f64; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for l in 0..4 {
            acc[l] += x[l] * y[l];
        }
    }
    let tail: f64 = ra.iter().zip(rb).map(|(x, y)| x * y).sum();
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// [`dot`] with its four partial sums in one AVX register: the same operations in the same
/// order (a multiply, then an add per lane; no fused multiply-add), so the same result to the
/// last bit. (The compiler's own vectorisation of [`dot`] shuffled the lanes through 128-bit
/// registers: perf showed those shuffles as most of the bending product.)
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn dot_avx2(a: &[f64], b: &[f64]) -> f64 {
    use std::arch::x86_64::*;
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    // SAFETY: every chunk holds four f64 (unaligned loads).
    let acc = unsafe {
        let mut acc = _mm256_setzero_pd();
        for (x, y) in ca.zip(cb) {
            let p = _mm256_mul_pd(_mm256_loadu_pd(x.as_ptr()), _mm256_loadu_pd(y.as_ptr()));
            acc = _mm256_add_pd(acc, p);
        }
        let mut out = [0.0f64; 4];
        _mm256_storeu_pd(out.as_mut_ptr(), acc);
        out
    };
    let tail: f64 = ra.iter().zip(rb).map(|(x, y)| x * y).sum();
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// Low-rank symmetric term F C F^T (rows of F per unknown, C k x k). F is stored packed: each
/// row keeps only the values of its non-zero column ranges, one after the other (a row's
/// functions live on its own tooth and thread: ~1/3 of the columns), so the products stream
/// a third of the memory.
#[derive(Debug, Clone)]
pub struct LowRank {
    pub rank: usize,
    /// Packed rows: row i is `values[offsets[i]..offsets[i + 1]]`, the concatenation of its
    /// ranges' columns.
    values: Vec<f64>,
    offsets: Vec<usize>,
    /// Row-major rank x rank, symmetric.
    pub core: Vec<f64>,
    /// Column ranges [start, end) outside which row i of F is zero (up to three per row: a
    /// member's functions live on the row's tooth or thread only, plus the wheel shaft's rigid
    /// body terms); unused entries are (0, 0).
    pub ranges: Vec<[(usize, usize); 3]>,
    /// Per row of the core: its runs of non-zero columns [start, end) (the core is block
    /// sparse: tooth relations reach the neighbours only, the members do not couple).
    core_runs: Vec<Vec<(usize, usize)>>,
}

impl LowRank {
    /// The term F C F^T with F (n x rank, row-major, dense), C (rank x rank, row-major,
    /// symmetric) and the rows' non-zero column ranges (empty: rows are dense); F's entries
    /// outside a row's ranges are taken as zero.
    pub fn new(rank: usize, f: Vec<f64>, core: Vec<f64>, ranges: Vec<[(usize, usize); 3]>) -> Self {
        let n = f.len().checked_div(rank).unwrap_or(ranges.len());
        let ranges: Vec<[(usize, usize); 3]> = if ranges.is_empty() {
            vec![[(0, rank), (0, 0), (0, 0)]; n]
        } else {
            ranges
        };
        // A row's ranges must not overlap (the products would count those columns twice).
        debug_assert!(ranges.iter().all(|r| {
            (0..3).all(|a| {
                (a + 1..3).all(|b| {
                    r[a].0 >= r[a].1 || r[b].0 >= r[b].1 || r[a].1 <= r[b].0 || r[b].1 <= r[a].0
                })
            })
        }));
        let mut values = Vec::with_capacity(
            ranges
                .iter()
                .flatten()
                .map(|(a, b)| b.saturating_sub(*a))
                .sum(),
        );
        let mut offsets = Vec::with_capacity(n + 1);
        for (i, r) in ranges.iter().enumerate() {
            offsets.push(values.len());
            for &(a, b) in r {
                if a < b {
                    values.extend_from_slice(&f[i * rank + a..i * rank + b]);
                }
            }
        }
        offsets.push(values.len());
        let core_runs = core_runs(&core, rank);
        Self {
            rank,
            values,
            offsets,
            core,
            ranges,
            core_runs,
        }
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// Row i of F, dense (rank values; empty for a rank-0 term, whatever i).
    pub fn dense_row(&self, i: usize) -> Vec<f64> {
        let mut row = vec![0.0; self.rank];
        if self.rank == 0 {
            return row;
        }
        let mut at = self.offsets[i];
        for &(a, b) in &self.ranges[i] {
            if a < b {
                row[a..b].copy_from_slice(&self.values[at..at + b - a]);
                at += b - a;
            }
        }
        row
    }

    /// Divides row i of F by d.
    pub fn divide_row(&mut self, i: usize, d: f64) {
        for v in &mut self.values[self.offsets[i]..self.offsets[i + 1]] {
            *v /= d;
        }
    }

    /// Row i's packed values with its ranges.
    #[inline]
    fn packed_row(&self, i: usize) -> (&[f64], &[(usize, usize); 3]) {
        (
            &self.values[self.offsets[i]..self.offsets[i + 1]],
            &self.ranges[i],
        )
    }
}

/// Per row of a k x k row-major core: its runs of non-zero columns [start, end).
fn core_runs(core: &[f64], rank: usize) -> Vec<Vec<(usize, usize)>> {
    (0..rank)
        .map(|r| {
            let row = &core[r * rank..(r + 1) * rank];
            let mut runs = Vec::new();
            let mut c = 0;
            while c < rank {
                if row[c] == 0.0 {
                    c += 1;
                    continue;
                }
                let start = c;
                while c < rank && row[c] != 0.0 {
                    c += 1;
                }
                runs.push((start, c));
            }
            runs
        })
        .collect()
}

impl LowRank {
    /// The term on the rows `set` (sorted) only, with the columns no such row uses dropped
    /// (the teeth without a candidate cell): same values, a smaller core.
    pub fn restrict(&self, set: &[usize]) -> LowRank {
        let mut used = vec![false; self.rank];
        for &i in set {
            for &(a, b) in &self.ranges[i] {
                used[a..b.max(a)].iter_mut().for_each(|u| *u = true);
            }
        }
        let mut new_index = vec![usize::MAX; self.rank];
        let columns: Vec<usize> = (0..self.rank).filter(|&c| used[c]).collect();
        for (j, &c) in columns.iter().enumerate() {
            new_index[c] = j;
        }
        let rank = columns.len();
        let mut values = Vec::new();
        let mut offsets = Vec::with_capacity(set.len() + 1);
        let mut ranges = Vec::with_capacity(set.len());
        for &i in set {
            offsets.push(values.len());
            values.extend_from_slice(&self.values[self.offsets[i]..self.offsets[i + 1]]);
            // A range's columns are all used, so it stays contiguous in the new numbering.
            ranges.push(self.ranges[i].map(|(a, b)| {
                if a < b {
                    (new_index[a], new_index[a] + (b - a))
                } else {
                    (0, 0)
                }
            }));
        }
        offsets.push(values.len());
        let mut core = vec![0.0; rank * rank];
        for (r, &cr) in columns.iter().enumerate() {
            let row = &self.core[cr * self.rank..(cr + 1) * self.rank];
            for (c, &cc) in columns.iter().enumerate() {
                core[r * rank + c] = row[cc];
            }
        }
        let core_runs = core_runs(&core, rank);
        LowRank {
            rank,
            values,
            offsets,
            core,
            ranges,
            core_runs,
        }
    }
}

/// y += F C F^T x (the low-rank bending term) over the packed rows, skipping zero x. `dot`
/// is [`dot`] or its AVX2 form (the same numbers).
#[inline(always)]
fn low_rank_add(lr: &LowRank, x: &[f64], y: &mut [f64], dot: impl Fn(&[f64], &[f64]) -> f64) {
    let k = lr.rank;
    let mut ft = vec![0.0; k];
    for (i, &xi) in x.iter().enumerate() {
        if xi == 0.0 {
            continue;
        }
        let (row, ranges) = lr.packed_row(i);
        let mut at = 0;
        for &(a, b) in ranges {
            if a < b {
                for (v, f) in ft[a..b].iter_mut().zip(&row[at..at + b - a]) {
                    *v += f * xi;
                }
                at += b - a;
            }
        }
    }
    // (Plain loops, so that the dots are inlined into the AVX2 build of this function.)
    let mut cft = vec![0.0; k];
    for (r, out) in cft.iter_mut().enumerate() {
        let core = &lr.core[r * k..(r + 1) * k];
        let mut sum = 0.0;
        for &(a, b) in &lr.core_runs[r] {
            sum += dot(&core[a..b], &ft[a..b]);
        }
        *out = sum;
    }
    for (i, yi) in y.iter_mut().enumerate() {
        let (row, ranges) = lr.packed_row(i);
        let mut sum = 0.0;
        let mut at = 0;
        for &(a, b) in ranges {
            if a < b {
                sum += dot(&row[at..at + b - a], &cft[a..b]);
                at += b - a;
            }
        }
        *yi += sum;
    }
}

/// [`low_rank_add`] compiled for AVX2 + FMA; chosen at run time.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn low_rank_add_avx2(lr: &LowRank, x: &[f64], y: &mut [f64]) {
    low_rank_add(lr, x, y, |a, b| dot_avx2(a, b))
}

/// The complementarity problem.
#[derive(Debug, Clone)]
pub struct Problem {
    pub blocks: Vec<Block>,
    pub low_rank: Option<LowRank>,
    /// Initial separations e_i.
    pub separation: Vec<f64>,
    /// Total load W (sum of q).
    pub load: f64,
    /// Optional bounds q_i <= upper_i (the flow pressure times area and lever: elastic-
    /// perfectly plastic cells, MODEL §5.7); honoured by both solvers.
    pub upper: Option<Vec<f64>>,
}

/// Which solver: an input setting (`analysis.solver`), defined with the inputs so that the
/// input module does not depend on the solver's.
pub use crate::input::SolverKind;

/// Convergence settings.
#[derive(Debug, Clone, Copy)]
pub struct SolverSettings {
    pub kind: SolverKind,
    /// Relative tolerance on the gaps of loaded cells (|y_i| / alpha) and on the change of q.
    pub tolerance: f64,
    pub max_iterations: usize,
}

impl Default for SolverSettings {
    fn default() -> Self {
        Self {
            kind: SolverKind::ConjugateGradient,
            tolerance: 1e-10,
            max_iterations: 20_000,
        }
    }
}

/// Residuals of a solution.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Residuals {
    /// |sum q - W| / W.
    pub load: f64,
    /// max over loaded cells of |y_i| / alpha (complementarity: gap where loaded).
    pub complementarity: f64,
    /// min_i y_i / alpha (negative = penetration outside the loaded set).
    pub min_gap: f64,
    /// min_i q_i / max_i q_i (must be >= 0).
    pub min_load: f64,
    pub iterations: usize,
    /// Cells at their cap (plastic), excluded from the two gap residuals.
    pub capped: usize,
}

/// Solution of the problem.
#[derive(Debug, Clone)]
pub struct Solution {
    pub q: Vec<f64>,
    /// Rigid approach alpha (same units as e).
    pub approach: f64,
    /// Final gaps y_i.
    pub gap: Vec<f64>,
    pub residuals: Residuals,
}

/// Why a solve failed.
#[derive(Debug, Clone, thiserror::Error)]
pub enum SolverError {
    #[error("the {kind:?} solver did not converge in {iterations} iterations (residual {residual:e}, tolerance {tolerance:e})")]
    NotConverged {
        kind: SolverKind,
        iterations: usize,
        residual: f64,
        tolerance: f64,
    },
    #[error("empty contact problem (no cell can touch)")]
    Empty,
    #[error("invalid problem: {0}")]
    Invalid(String),
}

impl Problem {
    /// Number of unknowns.
    pub fn len(&self) -> usize {
        self.separation.len()
    }

    /// True when there are no unknowns.
    pub fn is_empty(&self) -> bool {
        self.separation.is_empty()
    }

    /// y = K x. The blocks are symmetric, so y is accumulated column by column over the
    /// non-zero entries of x only (contact loads are sparse: most band cells carry none);
    /// blocks in parallel.
    pub fn apply(&self, x: &[f64], y: &mut [f64]) {
        use rayon::prelude::*;
        // K 0 = 0 (PK's projection changes nothing on most iterations).
        if x.iter().all(|&v| v == 0.0) {
            y.iter_mut().for_each(|v| *v = 0.0);
            return;
        }
        let mut jobs: Vec<(&Block, &mut [f64])> = Vec::with_capacity(self.blocks.len());
        let mut rest: &mut [f64] = y;
        for b in &self.blocks {
            let (head, tail) = std::mem::take(&mut rest).split_at_mut(b.size);
            jobs.push((b, head));
            rest = tail;
        }
        #[cfg(target_arch = "x86_64")]
        let wide = is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma");
        let work = |(b, ys): (&Block, &mut [f64])| {
            ys.iter_mut().for_each(|v| *v = 0.0);
            let size = b.size;
            // Columns of the non-zero loads, four at a time (one pass over y per four),
            // gathered as they come (no allocation per product).
            let column = |j: usize| b.row(j);
            let flush = |ys: &mut [f64], coef: [f64; 4], cols: [&[f64]; 4]| {
                #[cfg(target_arch = "x86_64")]
                if wide {
                    // SAFETY: the CPU has AVX2 and FMA (checked above).
                    unsafe { axpy4_avx2(ys, coef, cols) };
                } else {
                    axpy4(ys, coef, cols);
                }
                #[cfg(not(target_arch = "x86_64"))]
                axpy4(ys, coef, cols);
            };
            // (Placeholders, never read: a flush has `filled` real columns and copies of the
            // first; a lazy block must not assemble a row for them.)
            let mut cols: [&[f64]; 4] = [&[]; 4];
            let mut coef = [0.0; 4];
            let mut filled = 0;
            for (j, &v) in x[b.start..b.start + size].iter().enumerate() {
                if v == 0.0 {
                    continue;
                }
                cols[filled] = column(j);
                coef[filled] = v;
                filled += 1;
                if filled == 4 {
                    flush(ys, coef, cols);
                    filled = 0;
                }
            }
            if filled > 0 {
                // Unused slots: zero coefficients on a valid column.
                for k in filled..4 {
                    coef[k] = 0.0;
                    cols[k] = cols[0];
                }
                flush(ys, coef, cols);
            }
        };
        // Threads only when the product is worth a fork-join (the projection's correction
        // products touch a handful of columns).
        let work_total: usize = self
            .blocks
            .iter()
            .map(|b| {
                b.size
                    * x[b.start..b.start + b.size]
                        .iter()
                        .filter(|v| **v != 0.0)
                        .count()
            })
            .sum();
        if work_total > 60_000 {
            jobs.into_par_iter().for_each(work);
        } else {
            jobs.into_iter().for_each(work);
        }
        if let Some(lr) = &self.low_rank {
            #[cfg(target_arch = "x86_64")]
            if wide {
                // SAFETY: the CPU has AVX2 and FMA (checked above).
                unsafe { low_rank_add_avx2(lr, x, y) };
            } else {
                low_rank_add(lr, x, y, dot);
            }
            #[cfg(not(target_arch = "x86_64"))]
            low_rank_add(lr, x, y, dot);
        }
    }

    /// Residuals of q with approach alpha (cells at their cap are in plastic flow: their
    /// negative gap is not a penetration and their gap need not close).
    fn residuals(&self, q: &[f64], gap: &[f64], approach: f64, iterations: usize) -> Residuals {
        residuals_at_load(
            self.load,
            q,
            gap,
            approach,
            iterations,
            self.upper.as_deref(),
        )
    }

    /// The problem on the unknowns `set` (sorted) only, the others held at zero load: the
    /// contact blocks' rows and columns of the set, the low-rank term's rows of the set.
    pub fn restrict(&self, set: &[usize]) -> Problem {
        let mut blocks = Vec::new();
        let mut at = 0;
        for b in &self.blocks {
            let inside: Vec<usize> = set
                .iter()
                .filter(|&&i| i >= b.start && i < b.start + b.size)
                .map(|&i| i - b.start)
                .collect();
            if inside.is_empty() {
                continue;
            }
            let m = inside.len();
            blocks.push(Block {
                start: at,
                size: m,
                matrix: BlockMatrix::Dense(b.sub_block(&inside)),
            });
            at += m;
        }
        debug_assert_eq!(at, set.len(), "every unknown lies in one contact block");
        Problem {
            blocks,
            low_rank: self.low_rank.as_ref().map(|lr| lr.restrict(set)),
            separation: set.iter().map(|&i| self.separation[i]).collect(),
            load: self.load,
            upper: self
                .upper
                .as_ref()
                .map(|u| set.iter().map(|&i| u[i]).collect()),
        }
    }

    /// The dense submatrix of K on the unknowns `set` (sorted): contact blocks plus the
    /// low-rank term.
    pub fn dense(&self, set: &[usize]) -> nalgebra::DMatrix<f64> {
        let m = set.len();
        let mut k = nalgebra::DMatrix::<f64>::zeros(m, m);
        for b in &self.blocks {
            let inside: Vec<(usize, usize)> = set
                .iter()
                .enumerate()
                .filter(|(_, &i)| i >= b.start && i < b.start + b.size)
                .map(|(a, &i)| (a, i - b.start))
                .collect();
            for &(c, ic) in &inside {
                let row = b.row(ic);
                for &(a, ia) in &inside {
                    k[(a, c)] = row[ia];
                }
            }
        }
        if let Some(lr) = &self.low_rank {
            let r = lr.rank;
            let rows: Vec<Vec<f64>> = set.iter().map(|&i| lr.dense_row(i)).collect();
            let f = nalgebra::DMatrix::from_fn(m, r, |a, c| rows[a][c]);
            let core = nalgebra::DMatrix::from_row_slice(r, r, &lr.core);
            k += &f * core * f.transpose();
        }
        k
    }

    fn validate(&self) -> Result<(), SolverError> {
        if self.is_empty() {
            return Err(SolverError::Empty);
        }
        if !(self.load > 0.0 && self.load.is_finite()) {
            return Err(SolverError::Invalid(format!(
                "load {} must be positive",
                self.load
            )));
        }
        if !self.separation.iter().any(|e| e.is_finite()) {
            return Err(SolverError::Empty);
        }
        Ok(())
    }
}

/// Solves the problem with the chosen solver; `warm` is an optional starting q.
pub fn solve(
    problem: &Problem,
    settings: &SolverSettings,
    warm: Option<&[f64]>,
) -> Result<Solution, SolverError> {
    problem.validate()?;
    match (settings.kind, warm) {
        (SolverKind::ConjugateGradient, Some(w)) => screened(problem, settings, w),
        (SolverKind::ConjugateGradient, _) => conjugate_gradient(problem, settings, warm),
        (SolverKind::FixedPoint, _) => fixed_point(problem, settings, warm),
    }
}

/// The screened solve's candidates: the cells the warm start loads and this many times as many
/// of the others, those with the smallest gaps under the warm start.
const SCREEN_EXTRA: usize = 1;

/// The warm-started solve on a screened set of cells: the loaded set moves little from one
/// wear state to the next (MODEL §7.5), so PK runs on the cells the warm start loads or nearly
/// closes (~1/3 of the band on case B), and the teeth without such a cell drop out of the
/// bending term. The others stay unloaded; one product with the whole K then checks their
/// gaps, and any that would penetrate joins the set (with the next closest) for another
/// solve. The
/// result is the solution of the whole problem (K positive definite: the solution is unique
/// and satisfies every complementarity condition checked here).
fn screened(
    problem: &Problem,
    settings: &SolverSettings,
    warm: &[f64],
) -> Result<Solution, SolverError> {
    screened_passes(problem, settings, warm, SCREEN_EXTRA).map(|(solution, _)| solution)
}

/// [`screened`] with `extra` times as many candidates as loaded cells besides those, and the
/// number of solves it made (restricted ones, and the last one may be of the whole problem
/// when the candidates grew past half the cells).
fn screened_passes(
    problem: &Problem,
    settings: &SolverSettings,
    warm: &[f64],
    extra: usize,
) -> Result<(Solution, usize), SolverError> {
    let n = problem.len();
    let e = &problem.separation;
    let q = initial(problem, Some(warm));
    let mut u = vec![0.0; n];
    problem.apply(&q, &mut u);
    let (sum, count) = (0..n)
        .filter(|&i| q[i] > 0.0)
        .fold((0.0, 0usize), |(s, c), i| (s + u[i] + e[i], c + 1));
    if count == 0 {
        return conjugate_gradient(problem, settings, Some(warm)).map(|s| (s, 0));
    }
    let gaps = |u: &[f64], approach: f64| -> Vec<f64> {
        (0..n)
            .map(|i| {
                if e[i].is_finite() {
                    u[i] + e[i] - approach
                } else {
                    f64::INFINITY
                }
            })
            .collect()
    };
    let mut inside: Vec<bool> = q.iter().map(|&v| v > 0.0).collect();
    add_closest(&mut inside, &gaps(&u, sum / count as f64), extra * count);
    screened_from(problem, settings, q, inside)
}

/// The restricted solves of [`screened`] from the loads q (any total) and the candidates
/// `inside`, until no cell outside penetrates.
fn screened_from(
    problem: &Problem,
    settings: &SolverSettings,
    mut q: Vec<f64>,
    mut inside: Vec<bool>,
) -> Result<(Solution, usize), SolverError> {
    let n = problem.len();
    let e = &problem.separation;
    let mut u = vec![0.0; n];
    let gaps = |u: &[f64], approach: f64| -> Vec<f64> {
        (0..n)
            .map(|i| {
                if e[i].is_finite() {
                    u[i] + e[i] - approach
                } else {
                    f64::INFINITY
                }
            })
            .collect()
    };
    let (mut iterations, mut passes) = (0, 0);
    loop {
        let set: Vec<usize> = (0..n).filter(|&i| inside[i]).collect();
        if 2 * set.len() > n {
            // Not worth a restriction.
            return conjugate_gradient(problem, settings, Some(&q)).map(|s| (s, passes + 1));
        }
        let sub = problem.restrict(&set);
        let start: Vec<f64> = set.iter().map(|&i| q[i]).collect();
        let part = match conjugate_gradient(&sub, settings, Some(&start)) {
            Ok(part) => part,
            // The restriction is only a speed-up: a failure on it is the whole problem's to
            // decide.
            Err(_) => {
                return conjugate_gradient(problem, settings, Some(&q)).map(|s| (s, passes + 1))
            }
        };
        iterations += part.residuals.iterations;
        passes += 1;
        q.iter_mut().for_each(|v| *v = 0.0);
        for (a, &i) in set.iter().enumerate() {
            q[i] = part.q[a];
        }
        problem.apply(&q, &mut u);
        let approach = part.approach;
        let gap = gaps(&u, approach);
        let limit = -settings.tolerance * approach.abs().max(f64::MIN_POSITIVE);
        if !(0..n).any(|i| !inside[i] && gap[i] < limit) {
            let residuals = problem.residuals(&q, &gap, approach, iterations);
            return Ok((
                Solution {
                    q,
                    approach,
                    gap,
                    residuals,
                },
                passes,
            ));
        }
        // The penetrating cells join, with as many of the closest others as are loaded.
        let loaded = part.q.iter().filter(|&&v| v > 0.0).count();
        add_closest(&mut inside, &gap, loaded);
    }
}

/// Marks as inside the `extra` cells outside with the smallest finite gaps, and every cell
/// outside with a negative gap.
fn add_closest(inside: &mut [bool], gap: &[f64], extra: usize) {
    let mut outside: Vec<(f64, usize)> = (0..gap.len())
        .filter(|&i| !inside[i] && gap[i].is_finite())
        .map(|i| (gap[i], i))
        .collect();
    outside.sort_by(|a, b| a.0.total_cmp(&b.0));
    for (k, &(g, i)) in outside.iter().enumerate() {
        if k >= extra && g >= 0.0 {
            break;
        }
        inside[i] = true;
    }
}

/// Starting point: the given one if usable, else the load spread over the cells whose initial
/// separation is within a small band of the smallest.
fn initial(problem: &Problem, warm: Option<&[f64]>) -> Vec<f64> {
    let n = problem.len();
    if let Some(w) = warm {
        if w.len() == n && w.iter().any(|&v| v > 0.0) {
            let s: f64 = w.iter().sum();
            return w.iter().map(|&v| v.max(0.0) * problem.load / s).collect();
        }
    }
    let emin = problem
        .separation
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min);
    let finite: Vec<f64> = problem
        .separation
        .iter()
        .copied()
        .filter(|e| e.is_finite())
        .collect();
    let emax = finite.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let band = emin + 0.05 * (emax - emin).max(0.0);
    let chosen: Vec<bool> = problem
        .separation
        .iter()
        .map(|&e| e.is_finite() && e <= band)
        .collect();
    let count = chosen.iter().filter(|&&c| c).count().max(1);
    chosen
        .iter()
        .map(|&c| if c { problem.load / count as f64 } else { 0.0 })
        .collect()
}

/// Polonsky-Keer conjugate gradient, with optional caps q <= c (elastic-perfectly-plastic
/// cells: at the cap a cell carries it whatever its gap, which may then be negative — plastic
/// flow). Caps by an outer active set: cells above their cap are fixed at it and the PK solve
/// repeated for the others; fixed cells whose gap opens are freed.
fn conjugate_gradient(
    problem: &Problem,
    settings: &SolverSettings,
    warm: Option<&[f64]>,
) -> Result<Solution, SolverError> {
    let n = problem.len();
    let q0 = initial(problem, warm);
    let Some(cap) = problem.upper.as_ref() else {
        // PK can cycle between active sets on badly conditioned problems (worn, pitted flanks
        // with bending: a few cells of a ridge carrying the load, bending modes 40 times more
        // compliant than the contact); the primal active-set method then finishes the job. PK
        // gets a tenth of the iterations (it converges in ~100 when it does), the active set
        // the rest.
        let pk = SolverSettings {
            max_iterations: (settings.max_iterations / 10).max(1),
            ..*settings
        };
        return match pk_inner(problem, &pk, q0.clone(), &vec![false; n], true) {
            Err(e @ SolverError::NotConverged { .. }) => {
                active_set(problem, settings, &q0).map_err(|_| e)
            }
            other => other,
        };
    };
    check_capacity(problem, cap)?;
    let mut fixed = vec![false; n];
    let mut q = q0;
    let mut iterations = 0;
    for _ in 0..200 {
        // Loads for this pass: fixed cells at their caps, the others scaled to the rest.
        for i in 0..n {
            if fixed[i] {
                q[i] = cap[i];
            }
        }
        let rest = problem.load - (0..n).filter(|&i| fixed[i]).map(|i| cap[i]).sum::<f64>();
        let free: f64 = (0..n).filter(|&i| !fixed[i]).map(|i| q[i]).sum();
        if rest <= 0.0 {
            // Too many fixed: free the one with the largest gap... or all, and retry.
            fixed.iter_mut().for_each(|f| *f = false);
            continue;
        }
        if free > 0.0 {
            for i in 0..n {
                if !fixed[i] {
                    q[i] *= rest / free;
                }
            }
        } else {
            let open: Vec<usize> = (0..n)
                .filter(|&i| !fixed[i] && problem.separation[i].is_finite())
                .collect();
            for &i in &open {
                q[i] = rest / open.len() as f64;
            }
        }
        let pk_budget = (settings.max_iterations / 10).max(1);
        let mut sol = solve_with_fixed(problem, settings, q.clone(), &fixed, pk_budget)?;
        iterations += sol.residuals.iterations;
        let tol = settings.tolerance * sol.approach.abs();
        let mut changed = false;
        for i in 0..n {
            if !fixed[i] && sol.q[i] > cap[i] * (1.0 + 1e-12) {
                fixed[i] = true;
                changed = true;
            } else if fixed[i] && sol.gap[i] > tol {
                fixed[i] = false;
                changed = true;
            }
        }
        if !changed {
            sol.residuals.iterations = iterations;
            return Ok(sol);
        }
        q = sol.q;
    }
    Err(SolverError::Invalid(
        "the plastic (capped) set of the contact did not settle in 200 passes".into(),
    ))
}

/// The problem with the cells `fixed` held at their loads in `q0` (the capped cells of
/// [`conjugate_gradient`]): PK, and when it stalls the primal active-set method on the free
/// cells (the fixed cells' displacements added to the free cells' separations, their loads
/// taken off the total). PK gets `pk_iterations` at most. Gaps are returned for every cell,
/// fixed ones included.
fn solve_with_fixed(
    problem: &Problem,
    settings: &SolverSettings,
    q0: Vec<f64>,
    fixed: &[bool],
    pk_iterations: usize,
) -> Result<Solution, SolverError> {
    let pk = SolverSettings {
        max_iterations: pk_iterations,
        ..*settings
    };
    let error = match pk_inner(problem, &pk, q0.clone(), fixed, true) {
        Err(e @ SolverError::NotConverged { .. }) => e,
        other => return other,
    };
    let n = problem.len();
    let q_fixed: Vec<f64> = (0..n).map(|i| if fixed[i] { q0[i] } else { 0.0 }).collect();
    let mut u_fixed = vec![0.0; n];
    problem.apply(&q_fixed, &mut u_fixed);
    let fixed_load: f64 = q_fixed.iter().sum();
    let reduced = Problem {
        separation: (0..n)
            .map(|i| {
                if fixed[i] {
                    f64::INFINITY
                } else {
                    problem.separation[i] + u_fixed[i]
                }
            })
            .collect(),
        load: problem.load - fixed_load,
        upper: None,
        ..problem.clone()
    };
    let start: Vec<f64> = (0..n).map(|i| if fixed[i] { 0.0 } else { q0[i] }).collect();
    let free = active_set(&reduced, settings, &start).map_err(|_| error)?;
    let q: Vec<f64> = (0..n).map(|i| free.q[i] + q_fixed[i]).collect();
    let mut gap = vec![0.0; n];
    problem.apply(&q, &mut gap);
    for (g, e) in gap.iter_mut().zip(&problem.separation) {
        *g += e - free.approach;
    }
    let residuals = problem.residuals(&q, &gap, free.approach, free.residuals.iterations);
    Ok(Solution {
        q,
        approach: free.approach,
        gap,
        residuals,
    })
}

/// Polonsky-Keer conjugate gradient with active set (Polonsky & Keer, Wear 1999), with the
/// load constraint sum q = W and the approach as its multiplier. Cells marked `fixed` keep
/// their load q0 (the caps of [`conjugate_gradient`]); the others carry the rest. With
/// `give_up_on_stall`, a residual that has not halved in STALL iterations ends the run as not
/// converged (PK cycling between active sets; the caller has a fallback).
fn pk_inner(
    problem: &Problem,
    settings: &SolverSettings,
    q0: Vec<f64>,
    fixed: &[bool],
    give_up_on_stall: bool,
) -> Result<Solution, SolverError> {
    const STALL: usize = 400;
    let (mut best, mut best_at) = (f64::INFINITY, 0usize);
    let n = problem.len();
    let e = &problem.separation;
    let open: Vec<bool> = e
        .iter()
        .zip(fixed)
        .map(|(v, f)| v.is_finite() && !f)
        .collect();
    let mut q = q0;
    // The fixed cells' displacements, once.
    let q_fixed: Vec<f64> = (0..n).map(|i| if fixed[i] { q[i] } else { 0.0 }).collect();
    let fixed_load: f64 = q_fixed.iter().sum();
    let load = problem.load - fixed_load;
    let mut u_fixed = vec![0.0; n];
    problem.apply(&q_fixed, &mut u_fixed);
    for i in 0..n {
        if fixed[i] {
            q[i] = 0.0;
        }
    }
    let mut g = vec![0.0; n];
    let mut t = vec![0.0; n];
    let mut r = vec![0.0; n];
    let mut u = vec![0.0; n];
    let mut delta = 0.0;
    let mut g_old = 1.0;
    let mut approach = 0.0;
    let mut last_change = f64::INFINITY;
    let mut correction = vec![0.0; n];
    let mut kc = vec![0.0; n];
    let mut q_old = vec![0.0; n];
    // u = K q is carried from one iteration to the next (one product K t per iteration, plus
    // a product with the few entries the projection changed) and recomputed exactly every
    // REFRESH iterations and before convergence is accepted (the drift between refreshes is
    // round-off, ~1e-16 per iteration: 64 instead of 16 changed case B results by 4e-13).
    const REFRESH: usize = 64;
    let mut exact = false;
    let mut it = 0;
    while it < settings.max_iterations {
        it += 1;
        if !exact && (it == 1 || it % REFRESH == 0) {
            problem.apply(&q, &mut u);
            exact = true;
        }
        // (Loops fused where they can be: every sum keeps its order over i, so the results
        // are those of the separate passes, bit for bit.)
        let (mut sum, mut count) = (0.0, 0usize);
        for i in 0..n {
            // Fixed (capped) cells keep a gap too: the outer loop frees them when it opens.
            g[i] = if open[i] || fixed[i] {
                u[i] + u_fixed[i] + e[i]
            } else {
                f64::INFINITY
            };
            if q[i] > 0.0 {
                sum += g[i];
                count += 1;
            }
        }
        if count == 0 {
            return Err(SolverError::Invalid("no loaded cell left".into()));
        }
        let gbar = sum / count as f64;
        approach = gbar;
        // Convergence measure (loaded cells touch, others do not penetrate), the squared
        // gradient on the loaded set and the largest open gap, in one pass.
        let mut worst: f64 = 0.0;
        let mut gsum = 0.0;
        let mut gmax = 0.0f64;
        for i in 0..n {
            g[i] -= gbar;
            let gi = g[i];
            if q[i] > 0.0 {
                worst = worst.max(gi.abs());
                gsum += gi * gi;
            } else if open[i] && gi < 0.0 {
                worst = worst.max(-gi);
            }
            if open[i] && gi.is_finite() {
                gmax = gmax.max(gi.abs());
            }
        }
        let scale = approach.abs().max(f64::MIN_POSITIVE);
        if worst / scale < 0.5 * best {
            (best, best_at) = (worst / scale, it);
        } else if give_up_on_stall && it > best_at + STALL {
            break;
        }
        if worst / scale < settings.tolerance && last_change < settings.tolerance.sqrt() {
            if !exact {
                problem.apply(&q, &mut u);
                exact = true;
                it -= 1;
                continue;
            }
            let gap: Vec<f64> = g.clone();
            for i in 0..n {
                q[i] += q_fixed[i];
            }
            let residuals = problem.residuals(&q, &gap, approach, it);
            return Ok(Solution {
                q,
                approach,
                gap,
                residuals,
            });
        }
        for i in 0..n {
            t[i] = if q[i] > 0.0 {
                g[i] + delta * (gsum / g_old) * t[i]
            } else {
                0.0
            };
        }
        g_old = gsum.max(f64::MIN_POSITIVE);
        problem.apply(&t, &mut r);
        let rbar = (0..n).filter(|&i| q[i] > 0.0).map(|i| r[i]).sum::<f64>() / count as f64;
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..n {
            if q[i] > 0.0 {
                num += g[i] * t[i];
                den += (r[i] - rbar) * t[i];
            }
        }
        let tau = if den > 0.0 { num / den } else { 0.0 };
        let tau_overlap = if tau > 0.0 {
            tau
        } else {
            load / (count as f64 * gmax.max(f64::MIN_POSITIVE))
        };
        // Projected step on the loaded set; cells outside it that would penetrate join it
        // (PK's overlap step); the new total load.
        q_old.copy_from_slice(&q);
        let mut overlap = false;
        let mut total = 0.0;
        for i in 0..n {
            correction[i] = 0.0;
            if q[i] > 0.0 {
                let linear = q[i] - tau * t[i];
                q[i] = linear.max(0.0);
                correction[i] = q[i] - linear;
            } else if open[i] && g[i] < 0.0 {
                q[i] = -tau_overlap * g[i];
                correction[i] = q[i];
                overlap = true;
            }
            total += q[i];
        }
        delta = if overlap { 0.0 } else { 1.0 };
        if total <= 0.0 {
            // A projected step that unloads every free cell: a PK breakdown (seen with most of
            // the load at the flow pressure), not a property of the problem; the callers'
            // fallback (the active-set method) takes it from the start.
            return Err(SolverError::NotConverged {
                kind: SolverKind::ConjugateGradient,
                iterations: it,
                residual: f64::INFINITY,
                tolerance: settings.tolerance,
            });
        }
        let s = load / total;
        q.iter_mut().for_each(|v| *v *= s);
        // u <- s (u - tau K t + K c), c the projection's changes.
        problem.apply(&correction, &mut kc);
        let mut change = 0.0;
        for i in 0..n {
            u[i] = s * (u[i] - tau * r[i] + kc[i]);
            change += (q[i] - q_old[i]).abs();
        }
        exact = false;
        last_change = change / problem.load;
    }
    let gap = g.clone();
    for i in 0..n {
        q[i] += q_fixed[i];
    }
    let res = problem.residuals(&q, &gap, approach, it);
    Err(SolverError::NotConverged {
        kind: SolverKind::ConjugateGradient,
        iterations: it,
        residual: res.complementarity.max(-res.min_gap),
        tolerance: settings.tolerance,
    })
}

/// Primal active-set method for the same problem (Lawson & Hanson's NNLS with the load
/// constraint): on the loaded set P the gaps are closed exactly, K_PP q_P - alpha = -e_P with
/// sum q_P = W (dense Cholesky of K_PP, which is small: the loaded cells); cells whose load
/// would turn negative leave P along the ratio test (q stays feasible), then the cells that
/// penetrate most join it. Finite for a positive definite K; each pass costs one dense
/// factorisation of the loaded set, so it is the fallback, not the default.
pub fn active_set(
    problem: &Problem,
    settings: &SolverSettings,
    start: &[f64],
) -> Result<Solution, SolverError> {
    active_set_within(problem, settings, start, ACTIVE_SET_WORK)
}

/// [`active_set`] with at most `budget` floating-point work in its factorisations (the sum of
/// m^3 / 3 over them); beyond, not converged.
fn active_set_within(
    problem: &Problem,
    settings: &SolverSettings,
    start: &[f64],
    budget: f64,
) -> Result<Solution, SolverError> {
    problem.validate()?;
    let n = problem.len();
    let e = &problem.separation;
    let load = problem.load;
    let mut q = feasible_start(problem, start)?;
    let mut set: Vec<usize> = (0..n).filter(|&i| q[i] > 0.0).collect();
    let mut y = vec![0.0; n];
    let mut approach = 0.0;
    let limit = settings.max_iterations.min(50 * n + 100);
    // Each factorisation costs m^3 / 3 for m loaded cells: a budget on their sum bounds the
    // method's time (~a minute) where it would otherwise take hours, on problems PK could not
    // solve either (a rigid rotation dwarfing the contact compliances).
    let mut work = 0.0;
    for pass in 1..=limit {
        // Inner loop: the equality problem on the set, stepping back while loads go negative.
        loop {
            work += (set.len() as f64).powi(3) / 3.0;
            if work > budget {
                let residuals = residuals_at_load(load, &q, &y, approach, pass, None);
                return Err(SolverError::NotConverged {
                    kind: SolverKind::ConjugateGradient,
                    iterations: pass,
                    residual: residuals.complementarity.max(-residuals.min_gap),
                    tolerance: settings.tolerance,
                });
            }
            let (z, alpha) = closed_gaps(problem, &set)?;
            if z.iter().all(|&v| v > 0.0) {
                for (&i, &v) in set.iter().zip(&z) {
                    q[i] = v;
                }
                approach = alpha;
                break;
            }
            step_back(&mut q, &mut set, &z)?;
        }
        // Gaps; the cells that penetrate most join the set.
        problem.apply(&q, &mut y);
        for i in 0..n {
            y[i] = if e[i].is_finite() {
                y[i] + e[i] - approach
            } else {
                f64::INFINITY
            };
        }
        let tol = settings.tolerance * approach.abs();
        let mut candidates: Vec<usize> = (0..n).filter(|&i| q[i] == 0.0 && y[i] < -tol).collect();
        if candidates.is_empty() {
            let residuals = residuals_at_load(load, &q, &y, approach, pass, None);
            return Ok(Solution {
                q,
                approach,
                gap: y,
                residuals,
            });
        }
        candidates.sort_by(|&a, &b| y[a].total_cmp(&y[b]));
        // Several at a time while far from the solution, one at a time near it (Lawson and
        // Hanson's rule, which guarantees the entering cell keeps a positive load).
        let take = if pass < 20 { 8 } else { 1 };
        set.extend(candidates.into_iter().take(take));
        set.sort_unstable();
    }
    let residuals = residuals_at_load(load, &q, &y, approach, limit, None);
    Err(SolverError::NotConverged {
        kind: SolverKind::ConjugateGradient,
        iterations: limit,
        residual: residuals.complementarity.max(-residuals.min_gap),
        tolerance: settings.tolerance,
    })
}

/// The active-set method's feasible start: the given loads on open cells scaled to the
/// load, else the whole load on the cell of smallest separation.
fn feasible_start(problem: &Problem, start: &[f64]) -> Result<Vec<f64>, SolverError> {
    let (n, e, load) = (problem.len(), &problem.separation, problem.load);
    let mut q: Vec<f64> = (0..n)
        .map(|i| {
            if e[i].is_finite() {
                start.get(i).copied().unwrap_or(0.0).max(0.0)
            } else {
                0.0
            }
        })
        .collect();
    let total: f64 = q.iter().sum();
    if total > 0.0 {
        q.iter_mut().for_each(|v| *v *= load / total);
    } else {
        let first = (0..n)
            .filter(|&i| e[i].is_finite())
            .min_by(|&a, &b| e[a].total_cmp(&e[b]))
            .ok_or(SolverError::Empty)?;
        q[first] = load;
    }
    Ok(q)
}

/// The ratio test of the active-set method: from loads `q` towards the set's equality
/// solution `z` as far as every load stays non-negative; the cells whose load reaches zero
/// leave the set (and their loads are zeroed).
fn step_back(q: &mut [f64], set: &mut Vec<usize>, z: &[f64]) -> Result<(), SolverError> {
    let mut t: f64 = 1.0;
    for (&i, &v) in set.iter().zip(z) {
        if v <= 0.0 {
            t = t.min(q[i] / (q[i] - v));
        }
    }
    for (&i, &v) in set.iter().zip(z) {
        q[i] += t * (v - q[i]);
    }
    let qmax = q.iter().copied().fold(0.0, f64::max);
    set.retain(|&i| q[i] > 1e-14 * qmax);
    let mut inside = vec![false; q.len()];
    set.iter().for_each(|&i| inside[i] = true);
    for (qi, keep) in q.iter_mut().zip(&inside) {
        if !keep {
            *qi = 0.0;
        }
    }
    if set.is_empty() {
        return Err(SolverError::Invalid("active set emptied".into()));
    }
    Ok(())
}

/// The most floating-point work the active-set fallback may spend on one problem (the sum of
/// its factorisations' m^3 / 3): about a minute on one core.
const ACTIVE_SET_WORK: f64 = 2e11;

/// Loads z on `set` (sorted) that close every gap of the set, K_SS z - alpha = -e_S, with
/// sum z = W, and that alpha.
fn closed_gaps(problem: &Problem, set: &[usize]) -> Result<(Vec<f64>, f64), SolverError> {
    let m = set.len();
    let k = problem.dense(set);
    let chol = nalgebra::Cholesky::new(k).ok_or_else(|| {
        SolverError::Invalid(
            "the influence matrix of the loaded set is not positive definite".into(),
        )
    })?;
    let rhs = nalgebra::DVector::from_iterator(m, set.iter().map(|&i| -problem.separation[i]));
    let a = chol.solve(&rhs);
    let b = chol.solve(&nalgebra::DVector::from_element(m, 1.0));
    let alpha = (problem.load - a.sum()) / b.sum();
    Ok(((a + b * alpha).iter().copied().collect(), alpha))
}

/// The published fixed point (MODEL §5.4): with y0 = K q + e,
/// alpha = W / sum(q_i / y0_i), q_i <- alpha q_i / y0_i. Cells start loaded where e is within
/// the band of the starting point and stay loaded until their share falls below 1e-14 W.
/// With bounds q_i <= c_i (MODEL §5.7) the update is q_i <- min(c_i, alpha q_i / y0_i) with
/// alpha the root of sum min(c_i, alpha q_i / y0_i) = W ([`bounded_approach`]): at its fixed
/// point the free cells have y0 = alpha (closed gaps) and a cell at its bound has
/// y0 <= alpha (interference), the bounded complementarity of MODEL §5.7.
fn fixed_point(
    problem: &Problem,
    settings: &SolverSettings,
    warm: Option<&[f64]>,
) -> Result<Solution, SolverError> {
    let n = problem.len();
    let e = &problem.separation;
    let mut q: Vec<f64> = match warm {
        Some(_) => initial(problem, warm),
        None => {
            // All reachable cells start loaded (the scheme cannot load a cell it starts at 0).
            let count = e.iter().filter(|v| v.is_finite()).count().max(1);
            e.iter()
                .map(|v| {
                    if v.is_finite() {
                        problem.load / count as f64
                    } else {
                        0.0
                    }
                })
                .collect()
        }
    };
    if let Some(cap) = &problem.upper {
        check_capacity(problem, cap)?;
        q.iter_mut().zip(cap).for_each(|(v, c)| *v = v.min(*c));
    }
    let mut y0 = vec![0.0; n];
    let mut ratio = vec![0.0; n];
    let mut approach = 0.0;
    for it in 1..=settings.max_iterations {
        problem.apply(&q, &mut y0);
        for i in 0..n {
            y0[i] += e[i];
            ratio[i] = if q[i] > 0.0 { q[i] / y0[i] } else { 0.0 };
        }
        let new_approach = match &problem.upper {
            None => problem.load / ratio.iter().sum::<f64>(),
            Some(cap) => bounded_approach(&ratio, cap, problem.load),
        };
        let cap = |i: usize| problem.upper.as_ref().map_or(f64::INFINITY, |u| u[i]);
        let mut change = 0.0;
        for i in 0..n {
            if q[i] > 0.0 {
                let v = (new_approach * ratio[i]).min(cap(i));
                let v = if v < 1e-14 * problem.load { 0.0 } else { v };
                change += (v - q[i]).abs();
                q[i] = v;
            }
        }
        if problem.upper.is_none() {
            let total: f64 = q.iter().sum();
            let s = problem.load / total;
            q.iter_mut().for_each(|v| *v *= s);
        }
        let settled = (new_approach - approach).abs() <= settings.tolerance * new_approach.abs()
            && change / problem.load < settings.tolerance;
        approach = new_approach;
        if settled {
            let gap: Vec<f64> = (0..n).map(|i| y0[i] - approach).collect();
            let residuals = problem.residuals(&q, &gap, approach, it);
            return Ok(Solution {
                q,
                approach,
                gap,
                residuals,
            });
        }
    }
    Err(SolverError::NotConverged {
        kind: SolverKind::FixedPoint,
        iterations: settings.max_iterations,
        residual: f64::NAN,
        tolerance: settings.tolerance,
    })
}

/// The approach alpha of the bounded fixed point: the root of
/// sum_i min(c_i, alpha r_i) = W (r_i = q_i / y0_i >= 0, c_i the bounds), a continuous,
/// non-decreasing, piecewise-linear function of alpha; found exactly by sorting the kinks
/// alpha_i = c_i / r_i. When the loaded cells cannot carry W at their bounds, the largest kink
/// (every loaded cell at its bound; the others load on the next pass through the scaling of
/// no cell, so the caller's capacity check must hold).
fn bounded_approach(ratio: &[f64], cap: &[f64], load: f64) -> f64 {
    let mut kinks: Vec<(f64, usize)> = (0..ratio.len())
        .filter(|&i| ratio[i] > 0.0)
        .map(|i| (cap[i] / ratio[i], i))
        .collect();
    kinks.sort_by(|a, b| a.0.total_cmp(&b.0));
    // Below kink k: the cells of kinks before k are at their bounds, the others linear.
    let mut at_bound = 0.0;
    let mut slope: f64 = kinks.iter().map(|&(_, i)| ratio[i]).sum();
    for &(kink, i) in &kinks {
        if at_bound + slope * kink >= load {
            return (load - at_bound) / slope;
        }
        at_bound += cap[i];
        slope -= ratio[i];
    }
    kinks.last().map_or(f64::INFINITY, |k| k.0)
}

/// Refuses bounds that let the reachable cells carry no more than the load.
fn check_capacity(problem: &Problem, cap: &[f64]) -> Result<(), SolverError> {
    let capacity: f64 = cap
        .iter()
        .zip(&problem.separation)
        .filter(|(_, e)| e.is_finite())
        .map(|(c, _)| c)
        .sum();
    if capacity <= problem.load {
        return Err(SolverError::Invalid(format!(
            "the flow pressure lets the reachable cells carry only {capacity:e} of the load {:e}: \
             raise the flow pressure (analysis.flow_pressure_mpa, by default the wheel's \
             materials.wheel.hardness_gpa) or lower the torque (conditions)",
            problem.load
        )));
    }
    Ok(())
}

/// Exact change of the solution with the load while the loaded set stays the same
/// (the complementarity problem is then linear): with K_AA v = 1 on the loaded set A,
/// q(W) = q0 + (W - W0) v / sum(v) and alpha(W) = alpha0 + (W - W0) / sum(v).
/// Finds the load at which sum(weights . q) = target and returns that solution, or None when
/// the loaded set would change (a load turning negative or a gap closing), or CG fails.
pub fn affine_load_update(
    problem: &Problem,
    solution: &Solution,
    weights: &[f64],
    target: f64,
    settings: &SolverSettings,
) -> Option<(Solution, f64)> {
    let n = problem.len();
    // The free cells (loaded, below their cap) move with the load; capped cells stay.
    let cap = |i: usize| problem.upper.as_ref().map_or(f64::INFINITY, |u| u[i]);
    let active: Vec<bool> = solution
        .q
        .iter()
        .enumerate()
        .map(|(i, &q)| q > 0.0 && q < cap(i))
        .collect();
    // Conjugate gradient on the loaded set for K_AA v = 1, preconditioned by the exact
    // Cholesky factors of the contact blocks restricted to the loaded set (exact in one step
    // without bending; the bending term is low rank, so few more steps with it).
    let preconditioner = BlockPreconditioner::new(problem, &active);
    let mut v = vec![0.0; n];
    let mut r: Vec<f64> = active.iter().map(|&a| if a { 1.0 } else { 0.0 }).collect();
    let mut z = vec![0.0; n];
    preconditioner.apply(&r, &mut z);
    let mut p = z.clone();
    let mut kp = vec![0.0; n];
    let mut rz: f64 = r.iter().zip(&z).map(|(a, b)| a * b).sum();
    let rr0: f64 = r.iter().map(|x| x * x).sum();
    for _ in 0..settings.max_iterations.min(10 * n) {
        problem.apply(&p, &mut kp);
        for i in 0..n {
            if !active[i] {
                kp[i] = 0.0;
            }
        }
        let pkp: f64 = p.iter().zip(&kp).map(|(a, b)| a * b).sum();
        if pkp <= 0.0 {
            return None;
        }
        let a = rz / pkp;
        for i in 0..n {
            v[i] += a * p[i];
            r[i] -= a * kp[i];
        }
        let rr: f64 = r.iter().map(|x| x * x).sum();
        if rr <= 1e-24 * rr0 {
            break;
        }
        preconditioner.apply(&r, &mut z);
        let rz_new: f64 = r.iter().zip(&z).map(|(a, b)| a * b).sum();
        let beta = rz_new / rz;
        rz = rz_new;
        for i in 0..n {
            p[i] = z[i] + beta * p[i];
        }
    }
    let sum_v: f64 = v.iter().sum();
    if sum_v <= 0.0 {
        return None;
    }
    let t0: f64 = weights.iter().zip(&solution.q).map(|(w, q)| w * q).sum();
    let slope: f64 = weights.iter().zip(&v).map(|(w, x)| w * x).sum::<f64>() / sum_v;
    if slope == 0.0 || !slope.is_finite() {
        return None;
    }
    let load = problem.load + (target - t0) / slope;
    let dw = load - problem.load;
    let q: Vec<f64> = solution
        .q
        .iter()
        .zip(&v)
        .map(|(q, x)| q + dw * x / sum_v)
        .collect();
    if q.iter()
        .zip(&active)
        .enumerate()
        .any(|(i, (&qi, &a))| a && (qi <= 0.0 || qi >= cap(i)))
    {
        return None;
    }
    let approach = solution.approach + dw / sum_v;
    let mut u = vec![0.0; n];
    problem.apply(&q, &mut u);
    let gap: Vec<f64> = (0..n)
        .map(|i| u[i] + problem.separation[i] - approach)
        .collect();
    let tol = settings.tolerance * approach.abs();
    if (0..n).any(|i| {
        !active[i]
            && problem.separation[i].is_finite()
            && if q[i] >= cap(i) {
                gap[i] > tol
            } else {
                gap[i] < -tol
            }
    }) {
        return None;
    }
    let residuals = residuals_at_load(
        load,
        &q,
        &gap,
        approach,
        solution.residuals.iterations,
        problem.upper.as_deref(),
    );
    Some((
        Solution {
            q,
            approach,
            gap,
            residuals,
        },
        load,
    ))
}

/// Residuals of q with approach alpha under total load `load`.
fn residuals_at_load(
    load: f64,
    q: &[f64],
    gap: &[f64],
    approach: f64,
    iterations: usize,
    upper: Option<&[f64]>,
) -> Residuals {
    let scale = approach.abs().max(f64::MIN_POSITIVE);
    let qmax = q.iter().copied().fold(0.0, f64::max).max(f64::MIN_POSITIVE);
    let mut comp: f64 = 0.0;
    let mut min_gap = f64::INFINITY;
    let mut capped = 0;
    for (i, (qi, yi)) in q.iter().zip(gap).enumerate() {
        if upper.is_some_and(|u| *qi >= u[i]) {
            capped += 1;
            continue;
        }
        if *qi > 0.0 {
            comp = comp.max(yi.abs() * (qi / qmax).min(1.0));
        }
        if yi.is_finite() {
            min_gap = min_gap.min(*yi);
        }
    }
    Residuals {
        load: (q.iter().sum::<f64>() - load).abs() / load,
        complementarity: comp / scale,
        min_gap: min_gap / scale,
        min_load: q.iter().copied().fold(f64::INFINITY, f64::min) / qmax,
        iterations,
        capped,
    }
}

/// Block-Jacobi preconditioner: Cholesky factors of each contact block restricted to a set of
/// unknowns (identity where a factorisation fails).
struct BlockPreconditioner {
    parts: Vec<(Vec<usize>, Option<faer::linalg::solvers::Llt<f64>>)>,
}

impl BlockPreconditioner {
    fn new(problem: &Problem, set: &[bool]) -> Self {
        use rayon::prelude::*;
        let parts = problem
            .blocks
            .par_iter()
            .map(|b| {
                let idx: Vec<usize> = (b.start..b.start + b.size).filter(|&i| set[i]).collect();
                let rows: Vec<&[f64]> = idx.iter().map(|&i| b.row(i - b.start)).collect();
                let m = faer::Mat::from_fn(idx.len(), idx.len(), |r, c| rows[r][idx[c] - b.start]);
                let llt = (!idx.is_empty())
                    .then(|| m.llt(faer::Side::Lower).ok())
                    .flatten();
                (idx, llt)
            })
            .collect();
        Self { parts }
    }

    /// z = M^-1 r on the set (r outside the set is ignored, z there is 0).
    fn apply(&self, r: &[f64], z: &mut [f64]) {
        use faer::linalg::solvers::Solve;
        z.iter_mut().for_each(|v| *v = 0.0);
        for (idx, llt) in &self.parts {
            match llt {
                Some(llt) => {
                    let mut rhs = faer::Mat::from_fn(idx.len(), 1, |k, _| r[idx[k]]);
                    llt.solve_in_place(&mut rhs);
                    for (k, &i) in idx.iter().enumerate() {
                        z[i] = rhs[(k, 0)];
                    }
                }
                None => {
                    for &i in idx {
                        z[i] = r[i];
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Hertz data of the test sphere: contact radius a (m), peak pressure p0 (Pa), load (N).
    struct Sphere {
        a: f64,
        p0: f64,
        load: f64,
    }

    /// A 10 mm sphere on a plane under 100 N (the Hertz check of VALIDATION.md), in forces, on
    /// n x n cells spanning +-`span` Hertz radii.
    fn sphere_on_a_plane(
        n: usize,
        span: f64,
    ) -> (Vec<crate::contact::ContactCell>, Problem, Sphere) {
        use crate::validation::analytic::{flat_cells, flat_problem, steel_on_bronze};
        let (radius, load) = (10e-3, 100.0);
        let e_star = steel_on_bronze().effective_modulus;
        let a = (3.0 * load * radius / (4.0 * e_star)).cbrt();
        let p0 = 3.0 * load / (2.0 * std::f64::consts::PI * a * a);
        let h = span * a / n as f64;
        let cells = flat_cells(n, n, h, h);
        let pb = flat_problem(&cells, |c| (c.x * c.x + c.y * c.y) / (2.0 * radius), load);
        (cells, pb, Sphere { a, p0, load })
    }

    /// A rank-2 term 50 times more compliant than a cell's own contact coefficient, along a
    /// uniform and a tilting mode (a "bending" of the whole plane).
    fn compliant_rank_two(cells: &[crate::contact::ContactCell], pb: &Problem, a: f64) -> LowRank {
        let rows: Vec<f64> = cells.iter().flat_map(|c| [1.0, c.centre.x / a]).collect();
        let scale = 50.0 * pb.blocks[0].row(0)[0];
        LowRank::new(2, rows, vec![scale, 0.0, 0.0, 0.3 * scale], Vec::new())
    }

    #[test]
    fn the_active_set_method_solves_hertz_and_agrees_with_pk() {
        // Sphere on a plane (the Hertz check of VALIDATION.md) plus a low-rank term (a
        // compliant "bending" mode): the primal active-set fallback gives the KKT point PK
        // gives (the problem is positive definite: one solution), and without the low-rank
        // term Hertz's peak pressure.
        let (cells, mut pb, Sphere { a, p0, load }) = sphere_on_a_plane(24, 1.4);
        let settings = SolverSettings {
            tolerance: 1e-10,
            ..SolverSettings::default()
        };
        let start = vec![0.0; pb.len()];
        let exact = active_set(&pb, &settings, &start).unwrap();
        let pmax = exact.q.iter().copied().fold(0.0, f64::max) / cells[0].area();
        assert!((pmax / p0 - 1.0).abs() < 0.03, "{pmax:e} vs {p0:e}");
        // Add a rank-2 term much more compliant than the contact along two smooth modes.
        pb.low_rank = Some(compliant_rank_two(&cells, &pb, a));
        // PK alone, without the fallback (the compliant modes slow it: ~470 iterations).
        let q0 = initial(&pb, None);
        let by_pk = pk_inner(&pb, &settings, q0, &vec![false; pb.len()], false).unwrap();
        let by_active_set = active_set(&pb, &settings, &start).unwrap();
        let worst = by_pk
            .q
            .iter()
            .zip(&by_active_set.q)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "active set: {} passes, PK {} iterations; largest load difference {worst:e} N",
            by_active_set.residuals.iterations, by_pk.residuals.iterations
        );
        assert!(worst < 1e-6 * load);
        assert!((by_pk.approach / by_active_set.approach - 1.0).abs() < 1e-8);
        assert!(by_active_set.residuals.complementarity < 1e-9);
        assert!(by_active_set.residuals.min_gap > -1e-9);
        assert!(by_active_set.residuals.load < 1e-12);
        // Its work is bounded: a budget below what these passes need ends it, not converged.
        let n = by_active_set.q.iter().filter(|&&v| v > 0.0).count() as f64;
        match active_set_within(&pb, &settings, &start, n.powi(3) / 3.0) {
            Err(SolverError::NotConverged { .. }) => {}
            other => panic!("not bounded: {:?}", other.map(|s| s.residuals.iterations)),
        }
    }

    #[test]
    fn a_capped_problem_is_finished_by_the_active_set_when_pk_cannot() {
        // The sphere with the compliant rank-2 term and a pressure cap at 0.8 p0: an
        // elastic-perfectly-plastic solution (no cell above its cap, capped cells in plastic
        // flow with a closed or negative gap, the others complementary) carrying the load.
        let (cells, mut pb, Sphere { a, p0, load }) = sphere_on_a_plane(24, 1.4);
        pb.low_rank = Some(compliant_rank_two(&cells, &pb, a));
        let area = cells[0].area();
        let cap = 0.8 * p0 * area;
        pb.upper = Some(vec![cap; cells.len()]);
        let settings = SolverSettings {
            tolerance: 1e-10,
            ..SolverSettings::default()
        };
        let sol = solve(&pb, &settings, None).unwrap();
        let total: f64 = sol.q.iter().sum();
        assert!((total / load - 1.0).abs() < 1e-12);
        let capped = sol.q.iter().filter(|&&q| q >= cap).count();
        assert!(capped > 0 && sol.residuals.capped == capped);
        for (q, y) in sol.q.iter().zip(&sol.gap) {
            assert!(*q <= cap * (1.0 + 1e-12));
            if *q >= cap {
                assert!(
                    *y <= 1e-8 * sol.approach,
                    "capped cell with an open gap {y:e}"
                );
            }
        }
        assert!(sol.residuals.complementarity < 1e-8, "{:?}", sol.residuals);
        assert!(sol.residuals.min_gap > -1e-8, "{:?}", sol.residuals);
        // A bound under which the cells cannot carry the load: refused, naming the inputs
        // that set it (issue 38's probe: a 0.1 GPa hardness named none).
        let mut weak = pb.clone();
        weak.upper = Some(vec![0.5 * load / cells.len() as f64; cells.len()]);
        let e = solve(&weak, &settings, None).unwrap_err().to_string();
        assert!(
            e.contains("analysis.flow_pressure_mpa") && e.contains("materials.wheel.hardness_gpa"),
            "{e}"
        );
        // The fallback itself: the capped cells held, PK given one iteration (it cannot
        // finish), the active set on the free cells gives the same loads.
        let fixed: Vec<bool> = sol.q.iter().map(|&q| q >= cap).collect();
        // Free cells start with the rest of the load spread over those inside the contact.
        let inside: Vec<bool> = cells
            .iter()
            .zip(&fixed)
            .map(|(c, f)| !f && c.centre.x.hypot(c.centre.y) < a)
            .collect();
        let rest = load - cap * fixed.iter().filter(|&&f| f).count() as f64;
        let share = rest / inside.iter().filter(|&&i| i).count() as f64;
        let q0: Vec<f64> = (0..pb.len())
            .map(|i| {
                if fixed[i] {
                    cap
                } else if inside[i] {
                    share
                } else {
                    0.0
                }
            })
            .collect();
        let again = solve_with_fixed(&pb, &settings, q0, &fixed, 1).unwrap();
        let worst = sol
            .q
            .iter()
            .zip(&again.q)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-6 * load, "{worst:e}");
        assert!((again.approach / sol.approach - 1.0).abs() < 1e-8);
    }

    /// A sphere on a plane in forces (the Hertz check) on a grid of +-4 Hertz radii, with
    /// a compliant rank-4 term whose rows live on the cell's half of the plane (two "teeth":
    /// columns 0-1 for x < 0, 2-3 for x >= 0), coupled through the core.
    fn sphere_with_two_halves(n: usize) -> (Vec<crate::contact::ContactCell>, Problem, f64) {
        let (cells, mut pb, Sphere { load, .. }) = sphere_on_a_plane(n, 4.0);
        let h = cells[0].half_nu;
        let k = 4;
        let mut rows = vec![0.0; cells.len() * k];
        let mut ranges = Vec::new();
        for (i, c) in cells.iter().enumerate() {
            let at = if c.centre.x < 0.0 { 0 } else { 2 };
            rows[i * k + at] = 1.0;
            rows[i * k + at + 1] = c.centre.y / (n as f64 * h);
            ranges.push([(at, at + 2), (0, 0), (0, 0)]);
        }
        let s = 50.0 * pb.blocks[0].row(0)[0];
        #[rustfmt::skip]
        let core = vec![
            s, 0.0, 0.4 * s, 0.0,
            0.0, 0.3 * s, 0.0, 0.1 * s,
            0.4 * s, 0.0, s, 0.0,
            0.0, 0.1 * s, 0.0, 0.3 * s,
        ];
        pb.low_rank = Some(LowRank::new(k, rows, core, ranges));
        (cells, pb, load)
    }

    #[test]
    fn a_restricted_problem_holds_the_entries_of_its_set() {
        // K restricted to a set (here: cells of one half only, so two columns of the bending
        // term drop out, and a set across both halves) against the dense submatrix of K.
        let (cells, pb, _) = sphere_with_two_halves(8);
        let left: Vec<usize> = (0..cells.len())
            .filter(|&i| cells[i].centre.x < 0.0)
            .collect();
        let across: Vec<usize> = (0..cells.len()).filter(|i| i % 5 == 1).collect();
        for (set, rank) in [(left, 2), (across, 4)] {
            let sub = pb.restrict(&set);
            assert_eq!(sub.low_rank.as_ref().unwrap().rank, rank);
            let all: Vec<usize> = (0..set.len()).collect();
            let (a, b) = (sub.dense(&all), pb.dense(&set));
            let scale = b.amax();
            assert!((a - &b).amax() <= 1e-14 * scale);
            let e: Vec<f64> = set.iter().map(|&i| pb.separation[i]).collect();
            assert_eq!(sub.separation, e);
            // Products agree too (the packed rows were carried over in order).
            let x: Vec<f64> = (0..set.len()).map(|i| (i % 3) as f64).collect();
            let mut y = vec![0.0; set.len()];
            sub.apply(&x, &mut y);
            let expected = &b * nalgebra::DVector::from_vec(x);
            for (u, v) in y.iter().zip(expected.iter()) {
                assert!((u - v).abs() <= 1e-12 * expected.amax());
            }
        }
    }

    #[test]
    fn the_screened_solve_is_the_solve_of_the_whole_problem() {
        // Warm started from the converged loads (one restricted pass, nothing to add) and from
        // the loads of one half of the contact (the screen misses cells that then penetrate:
        // they join and the restricted solve is repeated): both give PK's solution of the whole
        // problem, and every complementarity condition holds on the whole problem.
        let (cells, pb, load) = sphere_with_two_halves(40);
        let settings = SolverSettings::default();
        let q0 = initial(&pb, None);
        let whole = pk_inner(&pb, &settings, q0, &vec![false; pb.len()], false).unwrap();
        // Half the contact (x < 0) loaded, and only its cells as candidates.
        let left: Vec<f64> = cells
            .iter()
            .zip(&whole.q)
            .map(|(c, q)| if c.centre.x < 0.0 { *q } else { 0.0 })
            .collect();
        let left_inside: Vec<bool> = left.iter().map(|&q| q > 0.0).collect();
        let runs = [
            screened_passes(&pb, &settings, &whole.q, SCREEN_EXTRA).unwrap(),
            screened_from(&pb, &settings, left, left_inside).unwrap(),
        ];
        for ((sol, passes), (at_least, at_most)) in runs.into_iter().zip([(1, 1), (2, 99)]) {
            assert!((at_least..=at_most).contains(&passes), "{passes} solves");
            let worst = sol
                .q
                .iter()
                .zip(&whole.q)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max);
            eprintln!("screened: {passes} passes, largest load difference {worst:e} N");
            assert!(worst < 1e-7 * load, "{worst:e}");
            assert!((sol.approach / whole.approach - 1.0).abs() < 1e-9);
            // The gaps reported are those of the whole problem.
            let mut u = vec![0.0; pb.len()];
            pb.apply(&sol.q, &mut u);
            for ((ui, e), reported) in u.iter().zip(&pb.separation).zip(&sol.gap) {
                let g = ui + e - sol.approach;
                assert!((g - reported).abs() <= 1e-12 * sol.approach.abs());
            }
            assert!(sol.residuals.complementarity < 1e-9, "{:?}", sol.residuals);
            assert!(sol.residuals.min_gap > -1e-9, "{:?}", sol.residuals);
            assert!(sol.residuals.load < 1e-12);
        }
    }

    #[test]
    fn the_wide_low_rank_product_equals_the_portable_one() {
        // The AVX2 build of F C F^T x (chosen at run time) against the portable build and a
        // plain triple loop: same numbers to round-off, with row ranges, a block-sparse core
        // and zero loads.
        let (n, k) = (37, 11);
        let value = |a: usize, b: usize| ((a * 7 + b * 13) % 17) as f64 / 17.0 - 0.4;
        let f: Vec<f64> = (0..n * k).map(|i| value(i / k, i % k)).collect();
        let mut core = vec![0.0; k * k];
        for a in 0..k {
            for b in 0..k {
                if a.abs_diff(b) <= 3 {
                    core[a * k + b] = value(a, b) + value(b, a) + if a == b { 3.0 } else { 0.0 };
                }
            }
        }
        let ranges: Vec<[(usize, usize); 3]> =
            (0..n).map(|i| [(0, 3 + i % 4), (7, k), (0, 0)]).collect();
        let lr = LowRank::new(k, f.clone(), core.clone(), ranges.clone());
        let x: Vec<f64> = (0..n)
            .map(|i| if i % 3 == 0 { 0.0 } else { value(i, 1) })
            .collect();
        let inside = |i: usize, c: usize| ranges[i].iter().any(|&(a, b)| c >= a && c < b);
        let fz = |i: usize, c: usize| if inside(i, c) { f[i * k + c] } else { 0.0 };
        // (Ranges do not overlap, as the bending models build them.)
        let direct: Vec<f64> = (0..n)
            .map(|i| {
                let mut v = 0.5;
                for a in 0..k {
                    for b in 0..k {
                        v += (0..n)
                            .map(|j| fz(i, a) * core[a * k + b] * fz(j, b) * x[j])
                            .sum::<f64>();
                    }
                }
                v
            })
            .collect();
        let scale = direct.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let mut portable = vec![0.5; n];
        low_rank_add(&lr, &x, &mut portable, dot);
        for (p, d) in portable.iter().zip(&direct) {
            assert!((p - d).abs() < 1e-13 * scale, "{p} vs {d}");
        }
        #[cfg(target_arch = "x86_64")]
        if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") {
            let mut wide = vec![0.5; n];
            // SAFETY: the CPU has AVX2 and FMA (checked above).
            unsafe { low_rank_add_avx2(&lr, &x, &mut wide) };
            // The same operations in the same order: the same numbers to the last bit.
            assert_eq!(wide, portable);
        }
    }
}
