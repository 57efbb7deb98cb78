//! The loaded contact at one position (MODEL §5.2-5.4): the influence blocks and the bending
//! term, the solve, the band widened while the contact reaches its edge, and the outer update of
//! the wheel torque that closes the worm-torque equilibrium.

use super::*;
use crate::input::BandGrowth;
use crate::ltca::traction::SliceFilms;

/// The positions' mean worm and wheel torques (N m), the power balance
/// (wheel torque / ratio + friction's worm torque) / worm torque - 1 (0 where the normal
/// forces do no work) and its warnings, which name the face position
/// (m) of the pattern's peak.
pub(super) fn torque_balance(
    positions: &[PositionResult],
    ratio: f64,
    wf: &WheelFlank,
    pattern: &[f64],
) -> (f64, f64, f64, Vec<String>) {
    let ni = wf.cells_height;
    let wheel_torque =
        positions.iter().map(|p| p.wheel_torque).sum::<f64>() / positions.len() as f64;
    let worm_torque = positions.iter().map(|p| p.worm_torque).sum::<f64>() / positions.len() as f64;
    let friction_torque =
        positions.iter().map(|p| p.friction_torque).sum::<f64>() / positions.len() as f64;
    // T1 omega1 = T2 omega2 + P_Vz, P_Vz / omega1 the friction's share of the worm torque.
    let power_balance = if friction_torque == 0.0 {
        wheel_torque / (ratio * worm_torque) - 1.0
    } else {
        (wheel_torque / ratio + friction_torque) / worm_torque - 1.0
    };
    let peak = (0..pattern.len())
        .max_by(|&a, &b| pattern[a].total_cmp(&pattern[b]))
        .map_or(0.0, |k| 0.5 * (wf.z[k / ni] + wf.z[k / ni + 1]));
    let warnings = power_balance_warnings(power_balance, wheel_torque, ratio, worm_torque, peak);
    (worm_torque, wheel_torque, power_balance, warnings)
}

/// The loaded contact at position n (MODEL §5.2-5.4): the local mesh in a band around the
/// contact lines, the problem on it, the solve with the wheel torque updated until the worm
/// torque balances (with `friction`, the friction tractions' moments included: the
/// transmitted torque), and the band grown while load reaches its edge (widened up to four
/// times, or the slices reached extended, MODEL §5.1).
#[allow(clippy::too_many_arguments)]
pub(super) fn solve_position(
    geo: &Geometry,
    tca: &Tca,
    ev: &GapEvaluator,
    wf: &WheelFlank,
    pair: &ElasticPair,
    settings: &LtcaSettings,
    bending: Option<&dyn BendingModel>,
    n: usize,
    band0: f64,
    worm_torque: Option<f64>,
    wheel_torque_guess: f64,
    worn: Option<Worn>,
    seed: Option<&WarmStart>,
    friction: Option<&PositionFriction>,
) -> Result<PositionResult, LtcaError> {
    let mut band = band0;
    let mut widenings = 0;
    let mut extensions = seeded_extensions(seed, n, settings);
    // The last solve's loads, to start the next solve on an extended band from.
    let mut restart: Option<Vec<CellLoad>> = None;
    loop {
        let cells = local_mesh(tca, ev, wf, settings, geo.teeth, n, band, worn, &extensions);
        if cells.is_empty() {
            return Err(LtcaError::NoContact(n));
        }
        if cells.len() > MAX_CONTACT_CELLS {
            return Err(LtcaError::TooManyCells {
                position: n,
                cells: cells.len(),
                columns: settings.columns,
                slice_step: settings.slice_step,
            });
        }
        // The previous analysis' loads on the same cells (the first mesh only: a widened band
        // puts other points under the same indices); on an extended band, the last solve's
        // (an extension keeps every cell where it was).
        let warm: Option<Vec<f64>> = match &restart {
            Some(loads) => start_for(loads, &cells),
            None => seed
                .filter(|_| widenings == 0)
                .and_then(|s| s.for_cells(n, &cells)),
        };
        let targets = (worm_torque, wheel_torque_guess);
        let model = (pair, settings, bending, friction);
        let (balanced, load) = balance_on(&cells, model, targets, warm, n)?;
        let q = &balanced.solution.q;
        match settings.band_growth {
            BandGrowth::Widen if at_band_edge(&cells, q) && widenings < 4 => {
                band *= 1.6;
                widenings += 1;
                continue;
            }
            BandGrowth::Extend if extend_reached_slices(&cells, q, settings, &mut extensions) => {
                restart = Some(cell_loads_by_key(&cells, q));
                continue;
            }
            _ => {}
        }
        let edge_share = band_edge_share(&cells, q);
        let mut result = position_result(n, tca, ev, settings, cells, &balanced.solution, load);
        result.band_edge_share = edge_share;
        let worm = balanced.worm;
        result.worm_torque = worm;
        result.wheel_torque = balanced.wheel;
        result.friction = balanced.friction;
        result.friction_torque = balanced.friction_torque;
        let target = worm_torque.unwrap_or(worm);
        result.torque_residual = (worm - target).abs() / target;
        result.band_widenings = widenings;
        return Ok(result);
    }
}

/// The solve on one local mesh (MODEL §5.2-5.4): the problem on `cells` under the elastic
/// pair, settings, bending and friction of `model`, balanced to the (worm torque, wheel torque
/// estimate) `targets` (N m) from `warm`; with the wheel torque it carries, N m.
#[allow(clippy::type_complexity)]
fn balance_on(
    cells: &[LocalCell],
    (pair, settings, bending, friction): (
        &ElasticPair,
        &LtcaSettings,
        Option<&dyn BendingModel>,
        Option<&PositionFriction>,
    ),
    (worm_torque, wheel_torque_guess): (Option<f64>, f64),
    warm: Option<Vec<f64>>,
    n: usize,
) -> Result<(Balanced, f64), LtcaError> {
    let (mut problem, weights, sign) =
        contact_problem(cells, pair, settings, bending, wheel_torque_guess)
            .ok_or(LtcaError::TorqueSign(n))?;
    let balanced = match friction {
        None => {
            let start = Start { warm, first: None };
            let (sol, worm, _) =
                balance_worm_torque(&mut problem, &weights, settings, worm_torque, start, n)?;
            let wheel = problem.load;
            Balanced::frictionless(sol, worm, wheel, cells.len())
        }
        Some(f) => {
            let target = (worm_torque, wheel_torque_guess);
            balance_with_friction(&mut problem, cells, sign, (settings, f), target, warm, n)?
        }
    };
    Ok((balanced, problem.load))
}

/// The ranges (start, size) of the teeth's cells (cells are grouped by tooth in mesh order).
fn tooth_ranges(cells: &[LocalCell]) -> Vec<(usize, usize)> {
    let mut ranges = Vec::new();
    let mut start = 0;
    while start < cells.len() {
        let t = cells[start].tooth_index;
        let mut end = start;
        while end < cells.len() && cells[end].tooth_index == t {
            end += 1;
        }
        ranges.push((start, end - start));
        start = end;
    }
    ranges
}

/// The complementarity problem on the cells (MODEL §5.2, §5.3): one contact block per tooth,
/// the bending term, the flow-pressure bounds, the separations and the wheel torque `load`;
/// with the weights that turn the unknowns into the worm torque and the driving sense of the
/// worm moments. None when the cells' worm moments cancel (no driving sense).
fn contact_problem(
    cells: &[LocalCell],
    pair: &ElasticPair,
    settings: &LtcaSettings,
    bending: Option<&dyn BendingModel>,
    load: f64,
) -> Option<(Problem, Vec<f64>, f64)> {
    use rayon::prelude::*;
    // The teeth's blocks and the bending term are independent: on the pool (on many cores
    // idle threads help the positions that take longest, issue 55).
    let contact_blocks = || -> Vec<Block> {
        tooth_ranges(cells)
            .into_par_iter()
            .map(|(start, size)| {
                // Upper triangle, mirrored: Love's term is symmetric for equal cells; the cells
                // of a tooth differ only slightly (line-aligned areas vary by the line's
                // obliquity), and the tangential term's small asymmetry on curved flanks is
                // dropped. Entries are assembled as the solver reads them: the rows of the
                // cells that carry load, and the screened solve's candidate block.
                let group = &cells[start..start + size];
                let contact: Vec<_> = group.iter().map(|c| c.cell).collect();
                let levers: Vec<f64> = group.iter().map(|c| c.lever).collect();
                Block::influence(start, pair, &contact, &levers)
            })
            .collect()
    };
    let bending_term = || {
        bending.map(|b| {
            let mut lr = b.coefficients(cells);
            for (i, c) in cells.iter().enumerate() {
                lr.divide_row(i, c.lever);
            }
            lr
        })
    };
    let (blocks, low_rank) = rayon::join(contact_blocks, bending_term);
    // Sign of the worm moments: all loaded cells push the worm the same way.
    let s: f64 = cells.iter().map(|c| c.worm_lever.signum()).sum();
    if s == 0.0 {
        return None;
    }
    let sign = s.signum();
    let upper = settings.flow_pressure.is_finite().then(|| {
        cells
            .iter()
            .map(|c| settings.flow_pressure * c.cell.area() * c.lever)
            .collect()
    });
    let problem = Problem {
        upper,
        blocks,
        low_rank,
        separation: cells.iter().map(|c| c.separation).collect(),
        load,
    };
    let weights = cells
        .iter()
        .map(|c| c.worm_lever * sign / c.lever)
        .collect();
    Some((problem, weights, sign))
}

/// Outer update of the normal wheel torque (`problem.load`) until the torque `weights . q`
/// (the worm torque, or with friction the transmitted wheel torque) balances `target`
/// (MODEL §5.2; None: the load is given): with the fast solver, an exact affine step on the
/// loaded set after each of the first [`AFFINE_STEPS`] solves, and where that step would change
/// the loaded set, the next solve at the load it predicts; the fixed-point solver (and later
/// solves) iterates by secants on the (wheel torque, worm torque) pairs: with
/// cells at the flow pressure (MODEL §5.7) the worm torque is not proportional to the wheel
/// torque and a plain rescaling can cycle. Returns the last solution and its worm torque,
/// with the linear response the affine step moved along (when it did: reusable for other
/// weights while its loaded set holds).
fn balance_worm_torque(
    problem: &mut Problem,
    weights: &[f64],
    settings: &LtcaSettings,
    target: Option<f64>,
    start: Start,
    n: usize,
) -> Result<(solver::Solution, f64, Option<solver::LoadResponse>), LtcaError> {
    let Start {
        mut warm,
        mut first,
    } = start;
    let mut response = None;
    let worm_of = |q: &[f64]| -> f64 { weights.iter().zip(q).map(|(w, q)| w * q).sum() };
    let mut solution = None;
    let mut previous = None;
    for it in 0..20 {
        let sol = match first.take() {
            Some(sol) => sol,
            None => {
                solver::solve(problem, &settings.solver, warm.as_deref()).map_err(|source| {
                    LtcaError::Solver {
                        position: n,
                        source,
                    }
                })?
            }
        };
        let worm = worm_of(&sol.q);
        let target = match target {
            Some(t) => t,
            None => {
                solution = Some((sol, worm));
                break;
            }
        };
        let ratio = target / worm;
        if (ratio - 1.0).abs() < 1e-9 {
            solution = Some((sol, worm));
            break;
        }
        let mut predicted = None;
        if settings.solver.kind == SolverKind::ConjugateGradient && it < AFFINE_STEPS {
            match solver::affine_step(problem, &sol, weights, target, &settings.solver) {
                Ok((updated, load, at)) => {
                    response = Some(at);
                    problem.load = load;
                    let worm = worm_of(&updated.q);
                    let close = ((worm - target) / target).abs() < 1e-9;
                    warm = Some(updated.q.clone());
                    solution = Some((updated, worm));
                    if close {
                        break;
                    }
                    continue;
                }
                Err(loads) => {
                    predicted = loads.filter(|l| l.load.is_finite() && l.load > 0.0);
                }
            }
        }
        // Where the loaded set changes, the next solve is at the load the affine step predicts
        // (few cells change near the balance), from its loads (those leaving the set cut at
        // zero and at their caps), else at the secant's from this solution.
        let (next, start) = match predicted {
            Some(loads) => (loads.load, within_bounds(loads.q, problem)),
            None => (
                next_wheel_torque(previous, (problem.load, worm), target),
                sol.q.clone(),
            ),
        };
        previous = Some((problem.load, worm));
        (problem.load, warm) = (next, Some(start));
        solution = Some((sol, worm));
    }
    let (sol, worm) = solution.expect("at least one solve");
    Ok((sol, worm, response))
}

/// The loads `q` (N m) cut at zero and at `problem`'s caps.
fn within_bounds(mut q: Vec<f64>, problem: &Problem) -> Vec<f64> {
    for (i, v) in q.iter_mut().enumerate() {
        let cap = problem.upper.as_ref().map_or(f64::INFINITY, |u| u[i]);
        *v = v.clamp(0.0, cap);
    }
    q
}

/// Where a torque balance starts: the warm start's loads for its first solve, or that solve's
/// solution itself (at the problem's current load).
struct Start {
    warm: Option<Vec<f64>>,
    first: Option<solver::Solution>,
}

/// Solves of a torque balance after which it takes an affine step on the loaded set (MODEL
/// §5.2); later ones go by secants.
const AFFINE_STEPS: usize = 3;

/// Largest number of friction updates of a position's torque balance (MODEL §5.2).
const FRICTION_ITERATIONS: usize = 12;

/// Relative change of the torque the balance does not set between two friction updates at
/// which the torque balance with friction has converged.
const FRICTION_TOLERANCE: f64 = 1e-7;

/// A position's solution with its torques (N m) and the friction it carries.
struct Balanced {
    solution: solver::Solution,
    /// Worm torque T1 and transmitted wheel torque T2, N m.
    worm: f64,
    wheel: f64,
    /// mu of each cell (zeros without friction).
    friction: Vec<f64>,
    /// The worm torque the friction consumes, sum mu f |v_g| / omega1, N m.
    friction_torque: f64,
}

impl Balanced {
    /// The balance's solution `sol` with its friction `mu` on the cells' `sliding`: torques
    /// under the (worm, wheel) torque weights and the friction's worm torque at the worm speed
    /// `omega1` (rad/s).
    fn with_friction(
        cells: &[LocalCell],
        sol: solver::Solution,
        (mu, sliding): (Vec<f64>, &[CellSliding]),
        (worm_weights, wheel_weights): (&Vec<f64>, &Vec<f64>),
        omega1: f64,
    ) -> Self {
        Self {
            worm: torque_of(worm_weights, &sol.q),
            wheel: torque_of(wheel_weights, &sol.q),
            friction_torque: friction_worm_torque(cells, &sol.q, (&mu, sliding), omega1),
            solution: sol,
            friction: mu,
        }
    }

    fn frictionless(solution: solver::Solution, worm: f64, wheel: f64, cells: usize) -> Self {
        Self {
            solution,
            worm,
            wheel,
            friction: vec![0.0; cells],
            friction_torque: 0.0,
        }
    }
}

/// The torque balance with the friction tractions' moments (MODEL §5.2): with the friction
/// coefficients of the last pressures frozen, the normal load is set so that the worm torque
/// (worm torque given) or the transmitted wheel torque (else) meets its target; the friction is
/// then updated from the new pressures, until the torque the balance does not set (the wheel's
/// when the worm torque is given, else the worm's) changes by less than [`FRICTION_TOLERANCE`].
/// The first balance starts from the friction of the warm start's loads, else a uniform
/// estimate ([`starting_friction`]); the updates move along that solution's exact linear
/// response to the load ([`solver::LoadResponse`]: one CG for them all) while its loaded set
/// holds, and solve again where it does not; converged loads whose gaps leave the set are
/// solved there and the friction updated again, so that the torques returned are those of the
/// friction returned. `target`: the worm torque when given, and the wheel torque (used when the
/// worm torque is not given), N m.
fn balance_with_friction(
    problem: &mut Problem,
    cells: &[LocalCell],
    sign: f64,
    (settings, friction): (&LtcaSettings, &PositionFriction),
    (worm_torque, wheel_torque): (Option<f64>, f64),
    warm: Option<Vec<f64>>,
    n: usize,
) -> Result<Balanced, LtcaError> {
    let sliding = cell_sliding(friction.gear, friction.geo, cells);
    let slices = friction.slice_films(n, cells);
    let target = worm_torque.unwrap_or(wheel_torque);
    let pick = |(worm, wheel): (Vec<f64>, Vec<f64>)| match worm_torque {
        Some(_) => (worm.clone(), worm, wheel),
        None => (wheel.clone(), worm, wheel),
    };
    let mesh = (cells, &sliding[..], &slices);
    let (mut mu, first) = starting_friction(problem, mesh, (settings, friction), &warm, n)?;
    let (weights, _, _) = pick(torque_weights(cells, &sliding, &mu, sign));
    let (mut sol, mut response) = rebalance(problem, &weights, settings, (target, warm), first, n)?;
    // The current loads: the solution's, or those of its response at a later target (gaps
    // and residuals computed once, at the end).
    let mut moved: Option<solver::AffineLoads> = None;
    let mut last_free = f64::NAN;
    for it in 0..FRICTION_ITERATIONS {
        let previous = moved.as_ref().map_or(&sol.q, |m| &m.q).clone();
        let pressure = cell_pressures(cells, &previous, settings.flow_pressure);
        mu = friction.coefficients(&slices, cells, &sliding, &pressure);
        let (weights, worm_weights, wheel_weights) =
            pick(torque_weights(cells, &sliding, &mu, sign));
        let free_weights = if worm_torque.is_some() {
            &wheel_weights
        } else {
            &worm_weights
        };
        moved = response
            .as_ref()
            .and_then(|r| r.at_target(&weights, target));
        if moved.is_none() {
            // The loaded set changes: solve again, and respond from there.
            let warm = Some(previous);
            (sol, response) = rebalance(problem, &weights, settings, (target, warm), None, n)?;
        }
        let free = torque_of(free_weights, moved.as_ref().map_or(&sol.q, |m| &m.q));
        let converged = (free - last_free).abs() <= FRICTION_TOLERANCE * free.abs();
        let last = it + 1 == FRICTION_ITERATIONS;
        if !(converged || last) {
            last_free = free;
            continue;
        }
        if let Some(loads) = moved.take() {
            problem.load = loads.load;
            let exact = response
                .as_ref()
                .and_then(|r| r.solution(problem, loads.clone(), &settings.solver));
            match exact {
                Some(s) => sol = s,
                None => {
                    // The final loads leave the set: solve there, and go on updating the
                    // friction from that solution (its torques must be its friction's).
                    let warm = Some(loads.q);
                    (sol, response) =
                        rebalance(problem, &weights, settings, (target, warm), None, n)?;
                    if !last {
                        last_free = torque_of(free_weights, &sol.q);
                        continue;
                    }
                }
            }
        }
        let (omega1, torques) = (
            friction.gear.conditions.worm_speed,
            (&worm_weights, &wheel_weights),
        );
        let with = (mu, &sliding[..]);
        return Ok(Balanced::with_friction(cells, sol, with, torques, omega1));
    }
    unreachable!("the last friction update returns")
}

/// The torque sum weights . q of the loads `q` (N m) under torque weights `weights`.
fn torque_of(weights: &[f64], q: &[f64]) -> f64 {
    weights.iter().zip(q).map(|(w, q)| w * q).sum()
}

/// A balance of `weights . q` on `target` warm-started from the loads `warm` (sets
/// `problem.load`), or starting from `first`, the solution at the current load, with its linear
/// response to the load.
fn rebalance(
    problem: &mut Problem,
    weights: &[f64],
    settings: &LtcaSettings,
    (target, warm): (f64, Option<Vec<f64>>),
    first: Option<solver::Solution>,
    n: usize,
) -> Result<(solver::Solution, Option<solver::LoadResponse>), LtcaError> {
    let start = Start { warm, first };
    let (sol, _, response) =
        balance_worm_torque(problem, weights, settings, Some(target), start, n)?;
    let response = response.or_else(|| solver::LoadResponse::of(problem, &sol, &settings.solver));
    Ok((sol, response))
}

/// The worm torque the friction consumes, sum mu f |v_g| / omega1 (N m), with the cells'
/// loads `q` = f l (N m), coefficients `mu`, sliding and the worm speed `omega1` (rad/s).
fn friction_worm_torque(
    cells: &[LocalCell],
    q: &[f64],
    (mu, sliding): (&[f64], &[CellSliding]),
    omega1: f64,
) -> f64 {
    cells
        .iter()
        .zip(q)
        .zip(mu.iter().zip(sliding))
        .map(|((c, q), (m, s))| m * q / c.lever * s.speed)
        .sum::<f64>()
        / omega1
}

/// The friction the first balance starts from, close to the final one so that the friction's
/// updates keep its loaded set: under the warm start's loads `warm` (the previous wear
/// state's; their sum then starts the solve as `problem.load`, not the estimate from the
/// torque given); else under the loads of a first solve at the load's estimate, returned
/// with that solution for the balance to start from. (A uniform estimate, ISO's mu_0T, moved
/// the balanced load by about 8 % at its first update and unloaded edge cells: a solve more.)
fn starting_friction(
    problem: &mut Problem,
    (cells, sliding, slices): (&[LocalCell], &[CellSliding], &SliceFilms),
    (settings, friction): (&LtcaSettings, &PositionFriction),
    warm: &Option<Vec<f64>>,
    n: usize,
) -> Result<(Vec<f64>, Option<solver::Solution>), LtcaError> {
    let (loads, first) = match warm {
        Some(q) if q.iter().any(|&q| q > 0.0) => {
            problem.load = q.iter().sum();
            (q.clone(), None)
        }
        _ => {
            let sol = solver::solve(problem, &settings.solver, None).map_err(|source| {
                LtcaError::Solver {
                    position: n,
                    source,
                }
            })?;
            (sol.q.clone(), Some(sol))
        }
    };
    let pressure = cell_pressures(cells, &loads, settings.flow_pressure);
    Ok((
        friction.coefficients(slices, cells, sliding, &pressure),
        first,
    ))
}

/// The pressure of each cell (Pa) under the loads `q` (N m), bounded by the flow pressure.
fn cell_pressures(cells: &[LocalCell], q: &[f64], flow_pressure: f64) -> Vec<f64> {
    cells
        .iter()
        .zip(q)
        .map(|(c, q)| (q / c.lever / c.cell.area()).min(flow_pressure))
        .collect()
}

/// Whether a cell at its slice band's first or last column carries load (above 1e-6 of the
/// largest cell's).
fn at_edge(c: &LocalCell, q: f64, qmax: f64) -> bool {
    q > 1e-6 * qmax && (c.column == c.band_first || c.column == c.band_last)
}

/// A warning when some position's contact still reaches its band's edge once the band stopped
/// growing, with more than [`BAND_EDGE_WARNING`] of its load there: how many positions, the
/// largest share and where.
pub(super) fn band_edge_warning(positions: &[PositionResult]) -> Option<String> {
    let cut: Vec<&PositionResult> = positions
        .iter()
        .filter(|p| p.band_edge_share > BAND_EDGE_WARNING)
        .collect();
    let worst = cut
        .iter()
        .max_by(|a, b| a.band_edge_share.total_cmp(&b.band_edge_share))?;
    Some(format!(
        "contact: at {} of {} positions the contact still reaches the local band's edge after \
         the band grew as far as it may (MODEL §5.1; at most {:.1} % of a position's load on the \
         edge cells, position {}): the contact there is cut by the local mesh; a wider \
         analysis.contact_band_factor holds it",
        cut.len(),
        positions.len(),
        100.0 * worst.band_edge_share,
        worst.position
    ))
}

/// Share of the loads `q` on cells at their slice band's first or last column (above 1e-6 of
/// the largest cell's): 0 unless the band stopped growing with its contact still reaching its
/// edge (four widenings, the extension's limit, or the dense solver's cells).
fn band_edge_share(cells: &[LocalCell], q: &[f64]) -> f64 {
    let qmax = q.iter().copied().fold(0.0, f64::max);
    let total: f64 = q.iter().sum();
    let edge: f64 = cells
        .iter()
        .zip(q)
        .filter(|(c, &q)| at_edge(c, q, qmax))
        .map(|(_, &q)| q)
        .sum();
    if total > 0.0 {
        edge / total
    } else {
        0.0
    }
}

/// Whether load reaches the first or last cell across the line of any slice.
fn at_band_edge(cells: &[LocalCell], q: &[f64]) -> bool {
    let qmax = q.iter().copied().fold(0.0, f64::max);
    cells.iter().zip(q).any(|(c, &q)| at_edge(c, q, qmax))
}

/// Band growth by extension (MODEL §5.1): every slice whose load reaches its band's first or
/// last cell gets half a band's worth of cells (of the same width) more on that side, up to
/// [`LtcaSettings::EXTENSION_BANDS`] bands' worth and as long as the mesh stays within
/// [`MAX_CONTACT_CELLS`]; whether any slice grew.
fn extend_reached_slices(
    cells: &[LocalCell],
    q: &[f64],
    settings: &LtcaSettings,
    extensions: &mut Extensions,
) -> bool {
    let columns = settings.columns.max(1);
    let (step, limit) = (columns.div_ceil(2), LtcaSettings::EXTENSION_BANDS * columns);
    let qmax = q.iter().copied().fold(0.0, f64::max);
    let mut grown = extensions.clone();
    let mut grew = 0;
    for (c, &load) in cells.iter().zip(q) {
        if !at_edge(c, load, qmax) {
            continue;
        }
        let e = grown.entry((c.tooth, c.slice)).or_default();
        let side = if c.column == c.band_first {
            &mut e.0
        } else {
            &mut e.1
        };
        // Once per slice and side in a pass (the edge cell is the slice's one cell there).
        let before = if c.column == c.band_first {
            settings.column_offset() - c.band_first
        } else {
            c.band_last + 1 - settings.column_offset() - columns
        };
        if *side == before && before < limit {
            *side = (before + step).min(limit);
            grew += step;
        }
    }
    // Not past the dense solver's cells: the contact stays cut, and the position says so
    // (its band-edge share).
    if grew == 0 || cells.len() + grew > MAX_CONTACT_CELLS {
        return false;
    }
    *extensions = grown;
    true
}

/// With the band grown by extension, the extensions that hold the previous analysis' loaded
/// cells of position n (from `seed`) and one cell more on each side: consecutive wear states
/// differ by micrometres, so a worn contact's extent is known before it is solved again
/// (empty without a seed, or where the band widens).
fn seeded_extensions(seed: Option<&WarmStart>, n: usize, settings: &LtcaSettings) -> Extensions {
    let mut extensions = Extensions::new();
    let Some(loads) = seed.and_then(|s| s.positions.get(n)) else {
        return extensions;
    };
    if settings.band_growth != BandGrowth::Extend {
        return extensions;
    }
    let (offset, columns) = (settings.column_offset(), settings.columns.max(1));
    let limit = LtcaSettings::EXTENSION_BANDS * columns;
    for &(tooth, slice, column, _) in loads {
        let column = column as usize;
        let below = (offset + 1).saturating_sub(column).min(limit);
        let above = (column + 2).saturating_sub(offset + columns).min(limit);
        let e = extensions.entry((tooth, slice as usize)).or_default();
        *e = (e.0.max(below), e.1.max(above));
    }
    extensions
}

/// One loaded cell of a solve: (tooth, slice, column) and its load q = force x lever (N m);
/// a solve's are kept sorted by key, a start for the same cells.
pub type CellLoad = (i32, u32, u32, f64);

/// The loaded cells of `cells` under `q` as [`CellLoad`]s, sorted by key.
pub(super) fn cell_loads_by_key(cells: &[LocalCell], q: &[f64]) -> Vec<CellLoad> {
    let mut loads: Vec<CellLoad> = cells
        .iter()
        .zip(q)
        .filter(|(_, &q)| q > 0.0)
        .map(|(c, &q)| (c.tooth, c.slice as u32, c.column as u32, q))
        .collect();
    loads.sort_by_key(|e| (e.0, e.1, e.2));
    loads
}

/// The start for `cells` from sorted `known` loads: the load of the same (tooth, slice,
/// column), 0 for a cell without one; None when nothing matches.
pub(super) fn start_for(known: &[CellLoad], cells: &[LocalCell]) -> Option<Vec<f64>> {
    let q: Vec<f64> = cells
        .iter()
        .map(|c| {
            let key = (c.tooth, c.slice as u32, c.column as u32);
            known
                .binary_search_by(|e| (e.0, e.1, e.2).cmp(&key))
                .map_or(0.0, |k| known[k].3)
        })
        .collect();
    q.iter().any(|&v| v > 0.0).then_some(q)
}

/// The position's result from the solution at wheel torque `wheel_torque` (N m): forces,
/// pressures and plastic depths per cell, the load per tooth, TE and stiffness; the worm
/// torque, its residual and the band widenings are the caller's.
fn position_result(
    n: usize,
    tca: &Tca,
    ev: &GapEvaluator,
    settings: &LtcaSettings,
    cells: Vec<LocalCell>,
    sol: &solver::Solution,
    wheel_torque: f64,
) -> PositionResult {
    let (forces, pressure, plastic_depth) =
        cell_loads(&cells, &sol.q, &sol.gap, settings.flow_pressure);
    let mut tooth_load = vec![0.0; tca.teeth.len()];
    for (c, f) in cells.iter().zip(&forces) {
        tooth_load[c.tooth_index] += f;
    }
    let total_force: f64 = forces.iter().sum();
    let lever_b = barycentre_lever(&ev.placement, &cells, &forces, total_force);
    let approach = sol.approach;
    PositionResult {
        position: n,
        tooth_load,
        wheel_torque,
        worm_torque: f64::NAN,
        normal_wheel_torque: wheel_torque,
        approach,
        transmission_error: tca.positions[n].kinematic_error - approach,
        stiffness_angular: wheel_torque / approach,
        stiffness_linear: total_force / (approach * lever_b),
        max_pressure: pressure.iter().copied().fold(0.0, f64::max),
        residuals: sol.residuals,
        torque_residual: f64::NAN,
        friction: Vec::new(),
        friction_torque: 0.0,
        pressure,
        plastic_depth,
        equivalent: Vec::new(),
        cells,
        band_widenings: 0,
        band_edge_share: 0.0,
    }
}

/// Per local cell: the normal force (N), the pressure (Pa) and the plastic depth (m: the
/// interference of a cell at the flow pressure, MODEL §5.7) from the solver's loads q (N m)
/// and gaps (rad).
pub(super) fn cell_loads(
    cells: &[LocalCell],
    q: &[f64],
    gap: &[f64],
    flow_pressure: f64,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let forces: Vec<f64> = cells.iter().zip(q).map(|(c, q)| q / c.lever).collect();
    let pressure: Vec<f64> = cells
        .iter()
        .zip(&forces)
        // (The bound holds on q = p S lever; the division's round-off stays below it.)
        .map(|(c, f)| (f / c.cell.area()).min(flow_pressure))
        .collect();
    let plastic_depth: Vec<f64> = cells
        .iter()
        .zip(&pressure)
        .zip(gap)
        .map(|((c, &p), &y)| {
            let at_bound = p >= flow_pressure * (1.0 - 1e-12);
            if at_bound && y < 0.0 {
                -y * c.lever
            } else {
                0.0
            }
        })
        .collect();
    (forces, pressure, plastic_depth)
}

/// Lever |(B x n)_z| (m) of the force barycentre B with the force-weighted mean normal n
/// (MODEL §5.6), for the linear mesh stiffness.
pub(super) fn barycentre_lever(
    placement: &crate::input::Placement,
    cells: &[LocalCell],
    forces: &[f64],
    total_force: f64,
) -> f64 {
    let mut b = Vector3::zeros();
    let mut nsum = Vector3::zeros();
    for (c, f) in cells.iter().zip(forces) {
        b += c.cell.centre * *f;
        nsum += c.cell.normal * *f;
    }
    let b_wheel = placement.worm_to_wheel(&(b / total_force));
    let n_wheel = placement.vector_worm_to_wheel(&nsum.normalize());
    GapEvaluator::lever(&b_wheel, &n_wheel)
}

/// The next wheel torque (N m) of the torque balance (MODEL §5.2) from the last two
/// (wheel torque, worm torque) pairs: the secant through them where it rises (the worm torque
/// grows with the wheel torque), else the rescaling by target / worm of the last one.
pub(super) fn next_wheel_torque(
    previous: Option<(f64, f64)>,
    last: (f64, f64),
    target: f64,
) -> f64 {
    let (load, worm) = last;
    let rescaled = load * target / worm;
    let Some((load0, worm0)) = previous else {
        return rescaled;
    };
    let slope = (worm - worm0) / (load - load0);
    let secant = load + (target - worm) / slope;
    if slope.is_finite() && slope > 0.0 && secant > 0.0 {
        secant
    } else {
        rescaled
    }
}
