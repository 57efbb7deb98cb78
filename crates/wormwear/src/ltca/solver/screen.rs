//! The screened solve: the problem restricted to the cells near the contact first, widened until
//! no cell outside it would close (same solution as the whole problem, to the tolerance).

use super::{conjugate_gradient, initial, Problem, Solution, SolverError, SolverSettings};

/// The screened solve's candidates: the cells the warm start loads and this many times as many
/// of the others, those with the smallest gaps under the warm start. Half as many: on the
/// design life a second pass (a cell outside penetrating) came in 1 of 727 solves, and the
/// candidates stayed below half the band in nearly all (with as many, a third of the solves
/// fell back to the whole band; BENCHMARKS.md session 40).
pub(super) const SCREEN_EXTRA: f64 = 0.5;

/// The warm-started solve on a screened set of cells: the loaded set moves little from one
/// wear state to the next (MODEL §7.5), so PK runs on the cells the warm start loads or nearly
/// closes (~1/3 of the band on case B), and the teeth without such a cell drop out of the
/// bending term. The others stay unloaded; one product with the whole K then checks their
/// gaps, and any that would penetrate joins the set (with the next closest) for another
/// solve. The
/// result is the solution of the whole problem (K positive definite: the solution is unique
/// and satisfies every complementarity condition checked here).
pub(super) fn screened(
    problem: &Problem,
    settings: &SolverSettings,
    warm: &[f64],
) -> Result<Solution, SolverError> {
    screened_passes(problem, settings, warm, SCREEN_EXTRA).map(|(solution, _)| solution)
}

/// [`screened`] with `extra` times as many candidates as loaded cells besides those, and the
/// number of solves it made (restricted ones, and the last one may be of the whole problem
/// when the candidates grew past half the cells).
pub(super) fn screened_passes(
    problem: &Problem,
    settings: &SolverSettings,
    warm: &[f64],
    extra: f64,
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
    add_closest(
        &mut inside,
        &gaps(&u, sum / count as f64),
        (extra * count as f64).ceil() as usize,
    );
    screened_from(problem, settings, q, inside)
}

/// The restricted solves of [`screened`] from the loads q (any total) and the candidates
/// `inside`, until no cell outside penetrates.
pub(super) fn screened_from(
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
pub(super) fn add_closest(inside: &mut [bool], gap: &[f64], extra: usize) {
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
