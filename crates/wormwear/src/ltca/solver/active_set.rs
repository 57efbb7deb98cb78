//! The active-set method on the dense restricted problem: the exact fallback when the conjugate
//! gradient stalls, within a work budget.

use super::{residuals_at_load, Problem, Solution, SolverError, SolverKind, SolverSettings};

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
pub(super) fn active_set_within(
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
pub(super) fn feasible_start(problem: &Problem, start: &[f64]) -> Result<Vec<f64>, SolverError> {
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
pub(super) fn step_back(q: &mut [f64], set: &mut Vec<usize>, z: &[f64]) -> Result<(), SolverError> {
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
pub(super) const ACTIVE_SET_WORK: f64 = 2e11;

/// Loads z on `set` (sorted) that close every gap of the set, K_SS z - alpha = -e_S, with
/// sum z = W, and that alpha.
pub(super) fn closed_gaps(
    problem: &Problem,
    set: &[usize],
) -> Result<(Vec<f64>, f64), SolverError> {
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
