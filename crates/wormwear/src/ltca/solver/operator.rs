//! The operator K of the load-sharing problem (MODEL §5.3, §5.5): dense symmetric contact blocks,
//! one per tooth, and the low-rank bending term F C F^T; their products, vectorised for AVX2 + FMA
//! when the processor has them (chosen at run time).

/// y += sum_k a_k c_k for four columns (unused ones with a_k = 0).
#[inline(always)]
pub(super) fn axpy4(y: &mut [f64], a: [f64; 4], c: [&[f64]; 4]) {
    let n = y.len();
    let (c0, c1, c2, c3) = (&c[0][..n], &c[1][..n], &c[2][..n], &c[3][..n]);
    for i in 0..n {
        y[i] += a[0] * c0[i] + a[1] * c1[i] + a[2] * c2[i] + a[3] * c3[i];
    }
}

/// [`axpy4`] compiled for AVX2 + FMA, chosen at run time.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
pub(super) unsafe fn axpy4_avx2(y: &mut [f64], a: [f64; 4], c: [&[f64]; 4]) {
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
    /// Cells on a regular lattice: products by FFT, entries from the kernel (the same
    /// numbers as the dense block to round-off).
    Grid(Box<crate::contact::GridInfluence>),
}

/// Cells from which a lattice's block is applied by FFT rather than assembled: below, the
/// assembled block is as fast (measured on the Hertz grids, BENCHMARKS.md session 27).
pub const GRID_CELLS: usize = 400;

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

    /// The influence block of a group of cells (one tooth contact) with their levers (m),
    /// entries those of [`crate::contact::symmetric_block`] (MODEL §5.5): applied by FFT when
    /// the cells form a lattice of at least [`GRID_CELLS`] (flat contacts; a gear flank's
    /// cells never do), else assembled as the solvers read it.
    pub fn influence(
        start: usize,
        pair: &crate::contact::ElasticPair,
        cells: &[crate::contact::ContactCell],
        levers: &[f64],
    ) -> Self {
        let size = cells.len();
        let grid = (size >= GRID_CELLS)
            .then(|| crate::contact::GridInfluence::new(pair, cells, levers))
            .flatten();
        let matrix = match grid {
            Some(grid) => BlockMatrix::Grid(Box::new(grid)),
            None => BlockMatrix::Lazy(Box::new(crate::contact::InfluenceRows::new(
                pair, cells, levers,
            ))),
        };
        Self {
            start,
            size,
            matrix,
        }
    }

    /// Row j of the block (= column j: symmetric), local index.
    #[inline]
    pub fn row(&self, j: usize) -> &[f64] {
        match &self.matrix {
            BlockMatrix::Dense(m) => &m[j * self.size..(j + 1) * self.size],
            BlockMatrix::Lazy(rows) => rows.row(j),
            BlockMatrix::Grid(grid) => grid.row(j),
        }
    }

    /// The block on the local unknowns `inside` (ascending), row-major.
    pub(super) fn sub_block(&self, inside: &[usize]) -> std::sync::Arc<Vec<f64>> {
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
            BlockMatrix::Grid(grid) => std::sync::Arc::new(grid.sub_block(inside)),
        }
    }
}

/// Dot product with four independent partial sums (lets the compiler vectorise the
/// reduction; the summation order differs from a plain left-to-right sum by round-off).
#[inline(always)]
pub(super) fn dot(a: &[f64], b: &[f64]) -> f64 {
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
pub(super) fn dot_avx2(a: &[f64], b: &[f64]) -> f64 {
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
    /// Row-major rank x rank, symmetric (shared by the restrictions that keep every column).
    pub core: std::sync::Arc<Vec<f64>>,
    /// Column ranges [start, end) outside which row i of F is zero (up to three per row: a
    /// member's functions live on the row's tooth or thread only, plus the wheel shaft's rigid
    /// body terms); unused entries are (0, 0).
    pub ranges: Vec<[(usize, usize); 3]>,
    /// Per row of the core: its runs of non-zero columns [start, end) (the core is block
    /// sparse: tooth relations reach the neighbours only, the members do not couple).
    core_runs: std::sync::Arc<Vec<Vec<(usize, usize)>>>,
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
        assert!(ranges.iter().all(|r| {
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
        Self::of_packed_rows(rank, values, offsets, core, ranges)
    }

    /// The term F C F^T from F already packed (`values`: row i's values of its non-empty
    /// ranges, one after the other, at `values[i * width..(i + 1) * width]`; every row's
    /// ranges cover `width` columns), C (rank x rank, row-major, symmetric) and the rows'
    /// ranges: the numbers of [`LowRank::new`] without a dense F to fill and copy.
    pub fn packed(
        rank: usize,
        values: Vec<f64>,
        width: usize,
        core: Vec<f64>,
        ranges: Vec<[(usize, usize); 3]>,
    ) -> Self {
        assert_eq!(
            values.len(),
            ranges.len() * width,
            "packed rows of {width} values"
        );
        assert!(ranges
            .iter()
            .all(|r| { r.iter().map(|(a, b)| b.saturating_sub(*a)).sum::<usize>() == width }));
        let offsets = (0..=ranges.len()).map(|i| i * width).collect();
        Self::of_packed_rows(rank, values, offsets, core, ranges)
    }

    /// The term of packed rows (row i `values[offsets[i]..offsets[i + 1]]`), its core and the
    /// rows' ranges, with the core's runs found.
    fn of_packed_rows(
        rank: usize,
        values: Vec<f64>,
        offsets: Vec<usize>,
        core: Vec<f64>,
        ranges: Vec<[(usize, usize); 3]>,
    ) -> Self {
        let core_runs = std::sync::Arc::new(core_runs(&core, rank));
        Self {
            rank,
            values,
            offsets,
            core: std::sync::Arc::new(core),
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
pub(super) fn core_runs(core: &[f64], rank: usize) -> Vec<Vec<(usize, usize)>> {
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
        let row_length = |i: usize| self.offsets[i + 1] - self.offsets[i];
        let mut values = Vec::with_capacity(set.iter().map(|&i| row_length(i)).sum());
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
        if rank == self.rank {
            // Every column stays: the same core and runs (copied and scanned again, they were
            // about 40 % of the restrictions' time on the design life, BENCHMARKS.md session 64).
            return LowRank {
                rank,
                values,
                offsets,
                core: self.core.clone(),
                ranges,
                core_runs: self.core_runs.clone(),
            };
        }
        let mut core = vec![0.0; rank * rank];
        for (r, &cr) in columns.iter().enumerate() {
            let row = &self.core[cr * self.rank..(cr + 1) * self.rank];
            for (c, &cc) in columns.iter().enumerate() {
                core[r * rank + c] = row[cc];
            }
        }
        LowRank::of_packed_rows(rank, values, offsets, core, ranges)
    }
}

/// y += F C F^T x (the low-rank bending term) over the packed rows, skipping zero x. `dot`
/// is [`dot`] or its AVX2 form (the same numbers).
#[inline(always)]
pub(super) fn low_rank_add(
    lr: &LowRank,
    x: &[f64],
    y: &mut [f64],
    dot: impl Fn(&[f64], &[f64]) -> f64 + Sync,
) {
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
    // Rows are independent (each its own dot): in chunks on the pool when the product is
    // big enough to pay for it, the same sums either way. On many cores this is what lets
    // idle threads help a position that takes longer than the others (issue 55).
    let row_product = |first: usize, ys: &mut [f64]| {
        for (i, yi) in (first..).zip(ys.iter_mut()) {
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
    };
    if lr.values.len() >= PARALLEL_ROW_ENTRIES {
        use rayon::prelude::*;
        y.par_chunks_mut(ROW_CHUNK)
            .enumerate()
            .for_each(|(c, ys)| row_product(c * ROW_CHUNK, ys));
    } else {
        row_product(0, y);
    }
}

/// The low-rank term's stored entries from which its rows' product runs on the pool.
const PARALLEL_ROW_ENTRIES: usize = 65_536;
/// Rows per task of the low-rank term's row product.
const ROW_CHUNK: usize = 256;

/// [`low_rank_add`] compiled for AVX2 + FMA; chosen at run time.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
pub(super) unsafe fn low_rank_add_avx2(lr: &LowRank, x: &[f64], y: &mut [f64]) {
    low_rank_add(lr, x, y, |a, b| dot_avx2(a, b))
}
