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
//!
//! Rooms: `operator` the blocks and the low-rank term, `pk` the conjugate gradient, `screen`
//! the screened solve around it, `active_set` its exact fallback, `fixed_point` the published
//! solver, `torque` the affine torque step; here the problem, its settings, residuals and
//! errors, and the entry point [`solve`].

mod active_set;
mod fixed_point;
mod operator;
mod pk;
mod screen;
mod torque;

pub use active_set::*;
use fixed_point::*;
pub use operator::*;
use pk::*;
use screen::*;
pub use torque::*;

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

impl SolverSettings {
    /// The defaults for solver `kind`: the published fixed point (MODEL §5.4) converges
    /// linearly, so it gets [`FIXED_POINT_ITERATIONS`] passes (on the design example without
    /// bending one position stood at a relative change of 1.9e-10 after the 20 000 the
    /// conjugate gradient's budget allows, against the tolerance 1e-10).
    pub fn for_kind(kind: SolverKind) -> Self {
        let max_iterations = match kind {
            SolverKind::FixedPoint => FIXED_POINT_ITERATIONS,
            SolverKind::ConjugateGradient => Self::default().max_iterations,
        };
        Self {
            kind,
            max_iterations,
            ..Self::default()
        }
    }
}

/// Passes the published fixed point may take on one solve ([`SolverSettings::for_kind`]).
pub const FIXED_POINT_ITERATIONS: usize = 400_000;

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
        let wide = wide_kernels();
        let work = |(b, ys): (&Block, &mut [f64])| block_product(b, x, ys, wide);
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
                // SAFETY: the CPU has AVX2 and FMA (checked by wide_kernels).
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
        assert_eq!(at, set.len(), "every unknown lies in one contact block");
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

/// Starting point: the given one if usable (scaled to the problem's load; cells at their caps
/// kept there and the others scaled to the rest, where they leave a rest), else the load
/// spread over the cells whose initial separation is within a small band of the smallest.
fn initial(problem: &Problem, warm: Option<&[f64]>) -> Vec<f64> {
    let n = problem.len();
    if let Some(w) = warm {
        if w.len() == n && w.iter().any(|&v| v > 0.0) {
            if let Some(start) = problem
                .upper
                .as_ref()
                .and_then(|cap| capped_start(w, cap, problem.load))
            {
                return start;
            }
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

/// The warm start `w` at the load `load` with its cells at their caps `cap` kept there and the
/// others scaled to the rest; None where no cell is capped or the capped ones carry the load.
fn capped_start(w: &[f64], cap: &[f64], load: f64) -> Option<Vec<f64>> {
    let held = |i: usize| at_cap(w[i], cap[i]);
    let capped: f64 = (0..w.len()).filter(|&i| held(i)).map(|i| cap[i]).sum();
    let free: f64 = (0..w.len())
        .filter(|&i| !held(i))
        .map(|i| w[i].max(0.0))
        .sum();
    if capped == 0.0 || free <= 0.0 || capped >= load {
        return None;
    }
    let scale = (load - capped) / free;
    Some(
        (0..w.len())
            .map(|i| {
                if held(i) {
                    cap[i]
                } else {
                    w[i].max(0.0) * scale
                }
            })
            .collect(),
    )
}

/// Whether a cell's load `q` sits at its cap `cap` (to round-off), N m.
fn at_cap(q: f64, cap: f64) -> bool {
    q > 0.0 && q >= cap * (1.0 - 1e-12)
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
            "the flow pressure lets the reachable cells carry only {:.1} N m of the wheel torque \
             {:.1} N m (the flow pressure x area x lever of every cell that can touch): raise the \
             flow pressure (analysis.flow_pressure_mpa, by default the wheel's \
             materials.wheel.hardness_gpa) or lower the torque (conditions)",
            capacity, problem.load
        )));
    }
    Ok(())
}

/// Whether the AVX2 + FMA kernels can run on this CPU.
fn wide_kernels() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// ys = B x_B for one symmetric block B (its rows of x): accumulated column by column over the
/// non-zero entries of x only, four columns at a time (one pass over ys per four), gathered as
/// they come (no allocation per product); `wide`: the AVX2 kernel.
fn block_product(b: &Block, x: &[f64], ys: &mut [f64], wide: bool) {
    if let BlockMatrix::Grid(grid) = &b.matrix {
        grid.product(&x[b.start..b.start + b.size], ys);
        return;
    }
    ys.iter_mut().for_each(|v| *v = 0.0);
    let column = |j: usize| b.row(j);
    let flush = |ys: &mut [f64], coef: [f64; 4], cols: [&[f64]; 4]| {
        #[cfg(target_arch = "x86_64")]
        if wide {
            // SAFETY: the CPU has AVX2 and FMA (checked by wide_kernels).
            unsafe { axpy4_avx2(ys, coef, cols) };
        } else {
            axpy4(ys, coef, cols);
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = wide;
            axpy4(ys, coef, cols);
        }
    };
    // (Placeholders, never read: a flush has `filled` real columns and copies of the first; a
    // lazy block must not assemble a row for them.)
    let mut cols: [&[f64]; 4] = [&[]; 4];
    let mut coef = [0.0; 4];
    let mut filled = 0;
    for (j, &v) in x[b.start..b.start + b.size].iter().enumerate() {
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
            // A set that keeps every column shares the whole term's core instead of a copy.
            let (whole, part) = (
                pb.low_rank.as_ref().unwrap(),
                sub.low_rank.as_ref().unwrap(),
            );
            assert_eq!(std::sync::Arc::ptr_eq(&whole.core, &part.core), rank == 4);
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
    fn a_low_rank_term_built_packed_is_the_one_built_from_its_dense_rows() {
        // Rows on one of three "teeth" (3 columns each) plus a shared block (2 columns), as
        // the FE bending builds them: packed straight, or dense (zeros outside the ranges,
        // where the dense F holds garbage that must not count) and packed by `new`.
        let (n, k, width) = (23, 11, 5);
        let value = |a: usize, b: usize| ((a * 5 + b * 11) % 13) as f64 / 13.0 - 0.3;
        let ranges: Vec<[(usize, usize); 3]> = (0..n)
            .map(|i| [(3 * (i % 3), 3 * (i % 3) + 3), (9, 11), (0, 0)])
            .collect();
        let mut dense = vec![f64::NAN; n * k];
        let mut packed = Vec::new();
        for (i, r) in ranges.iter().enumerate() {
            for &(a, b) in r {
                for c in a..b {
                    dense[i * k + c] = value(i, c);
                    packed.push(value(i, c));
                }
            }
        }
        let core: Vec<f64> = (0..k * k)
            .map(|x| {
                value(x / k, x % k) + value(x % k, x / k) + if x % (k + 1) == 0 { 4.0 } else { 0.0 }
            })
            .collect();
        let from_dense = LowRank::new(k, dense, core.clone(), ranges.clone());
        let built_packed = LowRank::packed(k, packed, width, core, ranges);
        let x: Vec<f64> = (0..n).map(|i| value(i, 2)).collect();
        let (mut a, mut b) = (vec![0.25; n], vec![0.25; n]);
        low_rank_add(&from_dense, &x, &mut a, dot);
        low_rank_add(&built_packed, &x, &mut b, dot);
        assert_eq!(a, b);
        assert!(a.iter().all(|v| v.is_finite()));
        for i in 0..n {
            assert_eq!(from_dense.dense_row(i), built_packed.dense_row(i));
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
