//! The affine torque step: the exact change of the solution with the load while the loaded set
//! stays the same (the complementarity problem is then linear), with its block-Jacobi
//! preconditioner.

use super::{residuals_at_load, Problem, Solution, SolverSettings};

/// Exact change of the solution with the load while the loaded set stays the same
/// (the complementarity problem is then linear): with K_AA v = 1 on the loaded set A,
/// q(W) = q0 + (W - W0) v / sum(v) and alpha(W) = alpha0 + (W - W0) / sum(v).
/// Finds the load at which sum(weights . q) = target and returns that solution and load, with
/// the response (reusable for other weights while its loaded set holds). Where the loaded set
/// would change (a load turning negative or a gap closing) it returns the loads the step
/// predicts with its loaded set taken as holding (near the balance when few cells change;
/// loads below zero among them), and None when CG fails or the weights do not move.
pub fn affine_step(
    problem: &Problem,
    solution: &Solution,
    weights: &[f64],
    target: f64,
    settings: &SolverSettings,
) -> Result<(Solution, f64, LoadResponse), Option<AffineLoads>> {
    let response = LoadResponse::of(problem, solution, settings).ok_or(None)?;
    let predicted = response
        .load_at_target(weights, target)
        .map(|load| response.loads_at(load));
    let Some(loads) = response.at_target(weights, target) else {
        return Err(predicted);
    };
    let load = loads.load;
    match response.solution(problem, loads, settings) {
        Some(s) => Ok((s, load, response)),
        None => Err(predicted),
    }
}

/// The solution's linear response to the load while its free loaded set holds (MODEL §5.4):
/// the base solution (q0 at the load W0, approach alpha0) and K_AA v = 1 on the free loaded
/// set A. One conjugate-gradient solve serves any number of targets (the friction's updates
/// of the torque weights, MODEL §5.2).
pub struct LoadResponse {
    active: Vec<bool>,
    v: Vec<f64>,
    sum_v: f64,
    q0: Vec<f64>,
    load0: f64,
    approach0: f64,
    iterations: usize,
}

/// Loads of a [`LoadResponse`] at one load: q (N m), the load W (N m) and the approach (rad).
#[derive(Debug, Clone)]
pub struct AffineLoads {
    pub q: Vec<f64>,
    pub load: f64,
    pub approach: f64,
}

impl LoadResponse {
    /// The response of `solution` of `problem` (at `problem.load`); None when the CG fails or
    /// the loaded set carries nothing.
    pub fn of(problem: &Problem, solution: &Solution, settings: &SolverSettings) -> Option<Self> {
        // The free cells (loaded, below their cap) move with the load; capped cells stay.
        let cap = |i: usize| problem.upper.as_ref().map_or(f64::INFINITY, |u| u[i]);
        let active: Vec<bool> = solution
            .q
            .iter()
            .enumerate()
            .map(|(i, &q)| q > 0.0 && q < cap(i))
            .collect();
        let v = unit_load_response(problem, &active, settings)?;
        let sum_v: f64 = v.iter().sum();
        if sum_v <= 0.0 {
            return None;
        }
        Some(Self {
            active,
            v,
            sum_v,
            q0: solution.q.clone(),
            load0: problem.load,
            approach0: solution.approach,
            iterations: solution.residuals.iterations,
        })
    }

    /// The loads at which sum(weights . q) = target, or None when a free cell would leave the
    /// loaded set (its load turning negative or reaching its cap) or the weights do not move.
    pub fn at_target(&self, weights: &[f64], target: f64) -> Option<AffineLoads> {
        let load = self.load_at_target(weights, target)?;
        Some(self.loads_at(load)).filter(|l| self.holds(&l.q, None))
    }

    /// The loads along the response at the load `load` (N m), its loaded set taken as holding
    /// (loads may turn negative).
    pub fn loads_at(&self, load: f64) -> AffineLoads {
        let dw = load - self.load0;
        let q: Vec<f64> = self
            .q0
            .iter()
            .zip(&self.v)
            .map(|(q, x)| q + dw * x / self.sum_v)
            .collect();
        AffineLoads {
            q,
            load,
            approach: self.approach0 + dw / self.sum_v,
        }
    }

    /// The load at which sum(weights . q) = target along the response (its loaded set taken
    /// as holding), or None when the weights do not move.
    pub fn load_at_target(&self, weights: &[f64], target: f64) -> Option<f64> {
        let t0: f64 = weights.iter().zip(&self.q0).map(|(w, q)| w * q).sum();
        let slope: f64 = weights.iter().zip(&self.v).map(|(w, x)| w * x).sum::<f64>() / self.sum_v;
        if slope == 0.0 || !slope.is_finite() {
            return None;
        }
        Some(self.load0 + (target - t0) / slope)
    }

    /// Whether the free cells keep their state under `q` (given the caps of `problem`).
    fn holds(&self, q: &[f64], problem: Option<&Problem>) -> bool {
        let cap = |i: usize| {
            problem
                .and_then(|p| p.upper.as_ref())
                .map_or(f64::INFINITY, |u| u[i])
        };
        !q.iter()
            .zip(&self.active)
            .enumerate()
            .any(|(i, (&qi, &a))| a && (qi <= 0.0 || qi >= cap(i)))
    }

    /// The solution at `loads` of `problem`: its gaps and residuals, or None when a cell
    /// outside the free loaded set leaves its state (an unloaded one penetrates, a capped one
    /// opens) or a free one reaches its cap.
    pub fn solution(
        &self,
        problem: &Problem,
        loads: AffineLoads,
        settings: &SolverSettings,
    ) -> Option<Solution> {
        if !self.holds(&loads.q, Some(problem)) {
            return None;
        }
        let gap = gaps_if_the_set_holds(problem, &loads.q, loads.approach, &self.active, settings)?;
        let residuals = residuals_at_load(
            loads.load,
            &loads.q,
            &gap,
            loads.approach,
            self.iterations,
            problem.upper.as_deref(),
        );
        Some(Solution {
            q: loads.q,
            approach: loads.approach,
            gap,
            residuals,
        })
    }
}

/// Conjugate gradient on the loaded set `active` for K_AA v = 1 (v zero elsewhere), on the
/// problem restricted to that set (its products then cost the set's rows only, not the whole
/// band's: a third of the cells), preconditioned by the exact Cholesky factors of its contact
/// blocks (exact in one step without bending; the bending term is low rank, so few more steps
/// with it). None when K_AA is not positive on a direction.
fn unit_load_response(
    problem: &Problem,
    active: &[bool],
    settings: &SolverSettings,
) -> Option<Vec<f64>> {
    let set: Vec<usize> = (0..problem.len()).filter(|&i| active[i]).collect();
    let restricted = problem.restrict(&set);
    let m = set.len();
    let preconditioner = BlockPreconditioner::new(&restricted);
    let mut w = vec![0.0; m];
    let mut r = vec![1.0; m];
    let mut z = vec![0.0; m];
    preconditioner.apply(&r, &mut z);
    let mut p = z.clone();
    let mut kp = vec![0.0; m];
    let mut rz: f64 = r.iter().zip(&z).map(|(a, b)| a * b).sum();
    let rr0 = m as f64;
    for _ in 0..settings.max_iterations.min(10 * m) {
        restricted.apply(&p, &mut kp);
        let pkp: f64 = p.iter().zip(&kp).map(|(a, b)| a * b).sum();
        if pkp <= 0.0 {
            return None;
        }
        let a = rz / pkp;
        for i in 0..m {
            w[i] += a * p[i];
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
        for i in 0..m {
            p[i] = z[i] + beta * p[i];
        }
    }
    let mut v = vec![0.0; problem.len()];
    for (k, &i) in set.iter().enumerate() {
        v[i] = w[k];
    }
    Some(v)
}

/// The gaps of the loads `q` at `approach`, or None when a cell outside the free loaded set
/// `active` leaves its state: an unloaded cell penetrates, or a capped one opens.
fn gaps_if_the_set_holds(
    problem: &Problem,
    q: &[f64],
    approach: f64,
    active: &[bool],
    settings: &SolverSettings,
) -> Option<Vec<f64>> {
    let n = problem.len();
    let cap = |i: usize| problem.upper.as_ref().map_or(f64::INFINITY, |u| u[i]);
    let mut u = vec![0.0; n];
    problem.apply(q, &mut u);
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
    Some(gap)
}

/// Block-Jacobi preconditioner: Cholesky factors of each contact block (identity where a
/// factorisation fails).
pub(super) struct BlockPreconditioner {
    parts: Vec<(Vec<usize>, Option<faer::linalg::solvers::Llt<f64>>)>,
}

impl BlockPreconditioner {
    fn new(problem: &Problem) -> Self {
        use rayon::prelude::*;
        let parts = problem
            .blocks
            .par_iter()
            .map(|b| {
                let idx: Vec<usize> = (b.start..b.start + b.size).collect();
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

    /// z = M^-1 r.
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
