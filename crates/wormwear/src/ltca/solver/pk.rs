//! The Polonsky-Keer conjugate gradient with active set (MODEL §5.4; the default solver), with the
//! flow-pressure bounds of the plastic contact (MODEL §5.7).

use super::{
    active_set, at_cap, check_capacity, initial, Problem, Solution, SolverError, SolverKind,
    SolverSettings,
};

/// Polonsky-Keer conjugate gradient, with optional caps q <= c (elastic-perfectly-plastic
/// cells: at the cap a cell carries it whatever its gap, which may then be negative — plastic
/// flow). Caps by an outer active set: cells above their cap are fixed at it and the PK solve
/// repeated for the others; fixed cells whose gap opens are freed.
pub(super) fn conjugate_gradient(
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
    // A warm start's cells at their caps start fixed there (a warm start from a capped
    // solution otherwise first solved the elastic problem without them, 100-170 iterations,
    // and then the capped one); a fixed cell whose gap opens is freed as from any start.
    let mut fixed: Vec<bool> = match warm.filter(|w| w.len() == n) {
        Some(w) => (0..n).map(|i| at_cap(w[i], cap[i])).collect(),
        None => vec![false; n],
    };
    let mut q = q0;
    let mut iterations = 0;
    for _ in 0..200 {
        if !pass_loads(problem, cap, &fixed, &mut q) {
            // Too many fixed: free the one with the largest gap... or all, and retry.
            fixed.iter_mut().for_each(|f| *f = false);
            continue;
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

/// Loads for a pass of [`conjugate_gradient`]'s outer active set: the `fixed` cells at their
/// caps, the others scaled to the rest of the load (spread evenly over the reachable ones when
/// they carry none). False, with `q` unchanged, where the fixed cells' caps take the whole load.
fn pass_loads(problem: &Problem, cap: &[f64], fixed: &[bool], q: &mut [f64]) -> bool {
    let n = q.len();
    let rest = problem.load - (0..n).filter(|&i| fixed[i]).map(|i| cap[i]).sum::<f64>();
    if rest <= 0.0 {
        return false;
    }
    for i in (0..n).filter(|&i| fixed[i]) {
        q[i] = cap[i];
    }
    let free: f64 = (0..n).filter(|&i| !fixed[i]).map(|i| q[i]).sum();
    if free > 0.0 {
        for i in (0..n).filter(|&i| !fixed[i]) {
            q[i] *= rest / free;
        }
    } else {
        let open: Vec<usize> = (0..n)
            .filter(|&i| !fixed[i] && problem.separation[i].is_finite())
            .collect();
        for &i in &open {
            q[i] = rest / open.len() as f64;
        }
    }
    true
}

/// The problem with the cells `fixed` held at their loads in `q0` (the capped cells of
/// [`conjugate_gradient`]): PK, and when it stalls the primal active-set method on the free
/// cells (the fixed cells' displacements added to the free cells' separations, their loads
/// taken off the total). PK gets `pk_iterations` at most. Gaps are returned for every cell,
/// fixed ones included.
pub(super) fn solve_with_fixed(
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
pub(super) fn pk_inner(
    problem: &Problem,
    settings: &SolverSettings,
    q0: Vec<f64>,
    fixed: &[bool],
    give_up_on_stall: bool,
) -> Result<Solution, SolverError> {
    const STALL: usize = 400;
    let (mut best, mut best_at) = (f64::INFINITY, 0usize);
    let mut pk = PkState::new(problem, q0, fixed);
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
            problem.apply(&pk.q, &mut pk.u);
            exact = true;
        }
        let count = pk.gaps_about_mean()?;
        let measure = pk.measure();
        let scale = pk.approach.abs().max(f64::MIN_POSITIVE);
        if measure.worst / scale < 0.5 * best {
            (best, best_at) = (measure.worst / scale, it);
        } else if give_up_on_stall && it > best_at + STALL {
            break;
        }
        if measure.worst / scale < settings.tolerance && pk.last_change < settings.tolerance.sqrt()
        {
            if !exact {
                problem.apply(&pk.q, &mut pk.u);
                exact = true;
                it -= 1;
                continue;
            }
            return Ok(pk.solution(it));
        }
        pk.direction(measure.gsum);
        let (tau, tau_overlap) = pk.step_lengths(count, measure.gmax);
        pk.project(tau, tau_overlap).map_err(|()| {
            // A projected step that unloads every free cell: a PK breakdown (seen with most of
            // the load at the flow pressure), not a property of the problem; the callers'
            // fallback (the active-set method) takes it from the start.
            SolverError::NotConverged {
                kind: SolverKind::ConjugateGradient,
                iterations: it,
                residual: f64::INFINITY,
                tolerance: settings.tolerance,
            }
        })?;
        exact = false;
    }
    let res = pk.solution(it).residuals;
    Err(SolverError::NotConverged {
        kind: SolverKind::ConjugateGradient,
        iterations: it,
        residual: res.complementarity.max(-res.min_gap),
        tolerance: settings.tolerance,
    })
}

/// The convergence measures of one PK iteration, from the gaps about their mean on the loaded
/// set.
struct PkMeasure {
    /// Largest violation: |gap| of a loaded cell, or the penetration of an open one.
    worst: f64,
    /// Squared gradient (gaps) on the loaded set.
    gsum: f64,
    /// Largest |gap| of an open cell.
    gmax: f64,
}

/// The iterate of [`pk_inner`] and its work vectors (wheel angles and torques, as the
/// [`Problem`]). Loops are fused where they can be: every sum keeps its order over i, so the
/// results are those of separate passes, bit for bit.
struct PkState<'a> {
    problem: &'a Problem,
    /// Cells that may carry load: finite separation and not fixed.
    open: Vec<bool>,
    fixed: &'a [bool],
    /// The fixed cells' loads and their displacements K q_fixed (computed once).
    q_fixed: Vec<f64>,
    u_fixed: Vec<f64>,
    /// The load the free cells carry.
    load: f64,
    q: Vec<f64>,
    /// Gaps about their mean (the gradient).
    g: Vec<f64>,
    /// Conjugate direction, K t, and K q carried between iterations.
    t: Vec<f64>,
    r: Vec<f64>,
    u: Vec<f64>,
    /// The projection's changes and K times them.
    correction: Vec<f64>,
    kc: Vec<f64>,
    q_old: Vec<f64>,
    delta: f64,
    g_old: f64,
    approach: f64,
    /// Relative change of q in the last step.
    last_change: f64,
}

impl<'a> PkState<'a> {
    /// The start: the fixed cells' loads taken out of q0 (their displacements once), the free
    /// cells' loads as given.
    fn new(problem: &'a Problem, q0: Vec<f64>, fixed: &'a [bool]) -> Self {
        let n = problem.len();
        let open: Vec<bool> = problem
            .separation
            .iter()
            .zip(fixed)
            .map(|(v, f)| v.is_finite() && !f)
            .collect();
        let mut q = q0;
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
        Self {
            problem,
            open,
            fixed,
            q_fixed,
            u_fixed,
            load,
            q,
            g: vec![0.0; n],
            t: vec![0.0; n],
            r: vec![0.0; n],
            u: vec![0.0; n],
            correction: vec![0.0; n],
            kc: vec![0.0; n],
            q_old: vec![0.0; n],
            delta: 0.0,
            g_old: 1.0,
            approach: 0.0,
            last_change: f64::INFINITY,
        }
    }

    /// Gaps g = K q + e (fixed cells included: the outer loop frees them when one opens), less
    /// their mean on the loaded set, which is the approach. Returns the loaded cells' count.
    fn gaps_about_mean(&mut self) -> Result<usize, SolverError> {
        let (mut sum, mut count) = (0.0, 0usize);
        for (i, e) in self.problem.separation.iter().enumerate() {
            self.g[i] = if self.open[i] || self.fixed[i] {
                self.u[i] + self.u_fixed[i] + e
            } else {
                f64::INFINITY
            };
            if self.q[i] > 0.0 {
                sum += self.g[i];
                count += 1;
            }
        }
        if count == 0 {
            return Err(SolverError::Invalid("no loaded cell left".into()));
        }
        let gbar = sum / count as f64;
        self.approach = gbar;
        self.g.iter_mut().for_each(|g| *g -= gbar);
        Ok(count)
    }

    /// Convergence measure (loaded cells touch, others do not penetrate), the squared gradient
    /// on the loaded set and the largest open gap, in one pass.
    fn measure(&self) -> PkMeasure {
        let mut m = PkMeasure {
            worst: 0.0,
            gsum: 0.0,
            gmax: 0.0,
        };
        for (i, &gi) in self.g.iter().enumerate() {
            if self.q[i] > 0.0 {
                m.worst = m.worst.max(gi.abs());
                m.gsum += gi * gi;
            } else if self.open[i] && gi < 0.0 {
                m.worst = m.worst.max(-gi);
            }
            if self.open[i] && gi.is_finite() {
                m.gmax = m.gmax.max(gi.abs());
            }
        }
        m
    }

    /// The conjugate direction on the loaded set (restarted after an overlap step).
    fn direction(&mut self, gsum: f64) {
        for i in 0..self.q.len() {
            self.t[i] = if self.q[i] > 0.0 {
                self.g[i] + self.delta * (gsum / self.g_old) * self.t[i]
            } else {
                0.0
            };
        }
        self.g_old = gsum.max(f64::MIN_POSITIVE);
    }

    /// The step length along t (r = K t about its mean on the loaded set), and the overlap
    /// step's length for cells that would penetrate.
    fn step_lengths(&mut self, count: usize, gmax: f64) -> (f64, f64) {
        self.problem.apply(&self.t, &mut self.r);
        let loaded = |i: &usize| self.q[*i] > 0.0;
        let rbar = (0..self.q.len())
            .filter(loaded)
            .map(|i| self.r[i])
            .sum::<f64>()
            / count as f64;
        let (mut num, mut den) = (0.0, 0.0);
        for i in (0..self.q.len()).filter(loaded) {
            num += self.g[i] * self.t[i];
            den += (self.r[i] - rbar) * self.t[i];
        }
        let tau = if den > 0.0 { num / den } else { 0.0 };
        let tau_overlap = if tau > 0.0 {
            tau
        } else {
            self.load / (count as f64 * gmax.max(f64::MIN_POSITIVE))
        };
        (tau, tau_overlap)
    }

    /// Projected step on the loaded set; cells outside it that would penetrate join it (PK's
    /// overlap step); the loads scaled back to the total, and u = K q updated as
    /// u <- s (u - tau K t + K c), c the projection's changes. Err when the step unloads
    /// every free cell.
    fn project(&mut self, tau: f64, tau_overlap: f64) -> Result<(), ()> {
        let n = self.q.len();
        self.q_old.copy_from_slice(&self.q);
        let mut overlap = false;
        let mut total = 0.0;
        for i in 0..n {
            self.correction[i] = 0.0;
            if self.q[i] > 0.0 {
                let linear = self.q[i] - tau * self.t[i];
                self.q[i] = linear.max(0.0);
                self.correction[i] = self.q[i] - linear;
            } else if self.open[i] && self.g[i] < 0.0 {
                self.q[i] = -tau_overlap * self.g[i];
                self.correction[i] = self.q[i];
                overlap = true;
            }
            total += self.q[i];
        }
        self.delta = if overlap { 0.0 } else { 1.0 };
        if total <= 0.0 {
            return Err(());
        }
        let s = self.load / total;
        self.q.iter_mut().for_each(|v| *v *= s);
        self.problem.apply(&self.correction, &mut self.kc);
        let mut change = 0.0;
        for i in 0..n {
            self.u[i] = s * (self.u[i] - tau * self.r[i] + self.kc[i]);
            change += (self.q[i] - self.q_old[i]).abs();
        }
        self.last_change = change / self.problem.load;
        Ok(())
    }

    /// The solution at iteration `it`: every cell's load (fixed ones included), the gaps about
    /// the approach and the residuals.
    fn solution(mut self, it: usize) -> Solution {
        let gap = self.g.clone();
        for (q, f) in self.q.iter_mut().zip(&self.q_fixed) {
            *q += f;
        }
        let residuals = self.problem.residuals(&self.q, &gap, self.approach, it);
        Solution {
            q: self.q,
            approach: self.approach,
            gap,
            residuals,
        }
    }
}
