//! The Polonsky-Keer conjugate gradient with active set (MODEL §5.4; the default solver), with the
//! flow-pressure bounds of the plastic contact (MODEL §5.7).

use super::{
    active_set, check_capacity, initial, Problem, Solution, SolverError, SolverKind, SolverSettings,
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
