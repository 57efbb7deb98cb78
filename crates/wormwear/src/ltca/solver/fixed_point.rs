//! The published fixed point on the approach (MODEL §5.4; the reference solver), with the
//! flow-pressure bounds (MODEL §5.7).

use super::{check_capacity, initial, Problem, Solution, SolverError, SolverKind, SolverSettings};

/// The published fixed point (MODEL §5.4): with y0 = K q + e,
/// alpha = W / sum(q_i / y0_i), q_i <- alpha q_i / y0_i. Cells start loaded where e is within
/// the band of the starting point and stay loaded until their share falls below 1e-14 W.
/// With bounds q_i <= c_i (MODEL §5.7) the update is q_i <- min(c_i, alpha q_i / y0_i) with
/// alpha the root of sum min(c_i, alpha q_i / y0_i) = W ([`bounded_approach`]): at its fixed
/// point the free cells have y0 = alpha (closed gaps) and a cell at its bound has
/// y0 <= alpha (interference), the bounded complementarity of MODEL §5.7.
pub(super) fn fixed_point(
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
    // The last pass's relative changes of the approach and of the loads (what `settled` reads).
    let mut residual = f64::INFINITY;
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
        residual =
            ((new_approach - approach).abs() / new_approach.abs()).max(change / problem.load);
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
        residual,
        tolerance: settings.tolerance,
    })
}

/// The approach alpha of the bounded fixed point: the root of
/// sum_i min(c_i, alpha r_i) = W (r_i = q_i / y0_i >= 0, c_i the bounds), a continuous,
/// non-decreasing, piecewise-linear function of alpha; found exactly by sorting the kinks
/// alpha_i = c_i / r_i. When the loaded cells cannot carry W at their bounds, the largest kink
/// (every loaded cell at its bound; the others load on the next pass through the scaling of
/// no cell, so the caller's capacity check must hold).
pub(super) fn bounded_approach(ratio: &[f64], cap: &[f64], load: f64) -> f64 {
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
