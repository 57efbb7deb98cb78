//! The search of the contact-pattern assistant: argmin's Nelder–Mead simplex on the settings
//! scaled to [0, 1] between their bounds, restarted from the best point with a narrower simplex
//! while that improves it, within the evaluation budget (MODEL §17).

use super::{Assistant, Evaluation, Outcome};
use argmin::core::{CostFunction, Executor};
use argmin::solver::neldermead::NelderMead;
use std::collections::HashMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// The first simplex's edge, as a share of each setting's range.
const FIRST_SIMPLEX: f64 = 0.25;
/// Restarts after the first run at most (each with a simplex half as wide as the last).
const MOST_RESTARTS: usize = 4;
/// A run stops when the sample standard deviation of its vertices' objectives falls below
/// this (a cell along a 60-cell face moves an extent's objective by (1/60)^2 = 2.8e-4).
const SD_TOLERANCE: f64 = 1e-7;
/// Penalty per squared scaled distance outside the bounds (a point outside is scored at the
/// nearest point inside plus this).
const OUTSIDE_PENALTY: f64 = 10.0;
/// The objective at which the target counts as met: each given component within about 0.001
/// (a tenth of a 60-cell face's cell, below what the pattern resolves).
pub(super) const TARGET_MET: f64 = 1e-6;
/// Improvement a restart must bring to be followed by another.
const IMPROVEMENT: f64 = 1e-9;

/// The evaluations made so far, each point evaluated once.
struct Path {
    evaluations: Vec<Evaluation>,
    seen: HashMap<Vec<String>, usize>,
    best: usize,
}

/// The objective on the scaled settings, as argmin's cost function.
struct Scaled<'a> {
    assistant: &'a Assistant,
    path: &'a Mutex<Path>,
    on_evaluation: &'a (dyn Fn(usize, &Evaluation) + Sync),
    interrupt: &'a (dyn Fn() -> bool + Sync),
    /// Calls of this run of the simplex.
    calls: AtomicUsize,
}

/// Why a run of the simplex was cut short.
#[derive(Debug, thiserror::Error)]
enum Cut {
    #[error("the evaluation budget is spent")]
    Budget,
    #[error("interrupted")]
    Interrupted,
    #[error("the target is met")]
    Met,
}

impl CostFunction for Scaled<'_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, scaled: &Vec<f64>) -> Result<f64, argmin::core::Error> {
        let inside: Vec<f64> = scaled.iter().map(|u| u.clamp(0.0, 1.0)).collect();
        let outside: f64 = scaled
            .iter()
            .zip(&inside)
            .map(|(u, c)| (u - c).powi(2))
            .sum();
        let penalty = OUTSIDE_PENALTY * outside;
        let values = self.values(&inside);
        let key = key(&values);
        // argmin evaluates the first simplex's n + 1 vertices expecting no error.
        let in_first_simplex = self.calls.fetch_add(1, Ordering::SeqCst) <= values.len();
        let cut = {
            let path = self.lock();
            if let Some(&k) = path.seen.get(&key) {
                return Ok(path.evaluations[k].objective + penalty);
            }
            if path.evaluations[path.best].objective <= TARGET_MET {
                Some(Cut::Met)
            } else if path.evaluations.len() >= self.assistant.evaluations {
                Some(Cut::Budget)
            } else {
                (self.interrupt)().then_some(Cut::Interrupted)
            }
        };
        if let Some(cut) = cut {
            return match in_first_simplex {
                true => Ok(f64::INFINITY),
                false => Err(cut.into()),
            };
        }
        let evaluation = self.assistant.evaluate(&values);
        let objective = evaluation.objective;
        let mut path = self.lock();
        let k = path.evaluations.len();
        (self.on_evaluation)(k, &evaluation);
        if objective < path.evaluations[path.best].objective {
            path.best = k;
        }
        path.evaluations.push(evaluation);
        path.seen.insert(key, k);
        Ok(objective + penalty)
    }
}

impl Scaled<'_> {
    fn lock(&self) -> std::sync::MutexGuard<'_, Path> {
        self.path.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// The settings' values at the scaled point (each in [0, 1]).
    fn values(&self, scaled: &[f64]) -> Vec<f64> {
        let settings = &self.assistant.settings;
        settings
            .iter()
            .zip(scaled)
            .map(|(s, u)| s.min + u * (s.max - s.min))
            .collect()
    }

    /// The best evaluation's objective and scaled point, and the evaluations made.
    fn best(&self) -> (f64, Vec<f64>, usize) {
        let path = self.lock();
        let best = &path.evaluations[path.best];
        (
            best.objective,
            self.scaled(&best.values),
            path.evaluations.len(),
        )
    }

    /// The scaled point of the settings' values.
    fn scaled(&self, values: &[f64]) -> Vec<f64> {
        let settings = &self.assistant.settings;
        settings
            .iter()
            .zip(values)
            .map(|(s, v)| (v - s.min) / (s.max - s.min))
            .collect()
    }
}

/// The simplex of n + 1 vertices around `centre` (scaled): the centre and a step of `edge`
/// along each setting (backwards where forwards leaves the bounds).
fn simplex(centre: &[f64], edge: f64) -> Vec<Vec<f64>> {
    let mut vertices = vec![centre.to_vec()];
    for i in 0..centre.len() {
        let mut v = centre.to_vec();
        v[i] += if centre[i] + edge <= 1.0 { edge } else { -edge };
        vertices.push(v);
    }
    vertices
}

/// The search from the base gear's evaluation `start` (its settings the search's start).
pub(super) fn nelder_mead(
    assistant: &Assistant,
    start: Evaluation,
    on_evaluation: &(dyn Fn(usize, &Evaluation) + Sync),
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Outcome {
    on_evaluation(0, &start);
    let path = Mutex::new(Path {
        evaluations: vec![start.clone()],
        seen: HashMap::from([(key(&start.values), 0)]),
        best: 0,
    });
    let problem = || Scaled {
        assistant,
        path: &path,
        on_evaluation,
        interrupt,
        calls: AtomicUsize::new(0),
    };
    let n = assistant.settings.len();
    let (mut edge, mut restarts, mut stopped) = (FIRST_SIMPLEX, 0, "converged");
    loop {
        let (best_before, centre, spent) = problem().best();
        if best_before <= TARGET_MET {
            stopped = "target met";
            break;
        }
        // The first simplex's n new vertices are evaluated without a budget check.
        if spent + n > assistant.evaluations {
            stopped = "budget";
            break;
        }
        if let Some(cut) = run_simplex(problem(), &centre, edge) {
            stopped = cut;
            break;
        }
        let (best_after, _, _) = problem().best();
        if restarts > 0 && best_before - best_after < IMPROVEMENT || restarts == MOST_RESTARTS {
            break;
        }
        restarts += 1;
        edge *= 0.5;
    }
    let path = path.into_inner().unwrap_or_else(|p| p.into_inner());
    Outcome {
        best: path.evaluations[path.best].clone(),
        start,
        path: path.evaluations,
        restarts,
        stopped,
    }
}

/// One run of the simplex from `centre` (scaled) with edges `edge`, to convergence or a cut:
/// why it was cut (None: converged).
fn run_simplex(problem: Scaled<'_>, centre: &[f64], edge: f64) -> Option<&'static str> {
    let interrupt = problem.interrupt;
    let budget = problem.assistant.evaluations as u64;
    let run = NelderMead::new(simplex(centre, edge))
        .with_sd_tolerance(SD_TOLERANCE)
        .and_then(|solver| {
            Executor::new(problem, solver)
                .configure(|state| state.max_iters(budget))
                .run()
        });
    match run {
        Err(e) => Some(match e.downcast_ref::<Cut>() {
            Some(Cut::Interrupted) => "interrupted",
            Some(Cut::Met) => "target met",
            Some(Cut::Budget) => "budget",
            None => "optimiser error",
        }),
        Ok(_) if interrupt() => Some("interrupted"),
        Ok(_) => None,
    }
}

/// The key of a point in the path: its values to 13 significant digits (a point scaled to
/// [0, 1] and back may differ from the one evaluated in its last bits).
fn key(values: &[f64]) -> Vec<String> {
    values.iter().map(|v| format!("{v:.12e}")).collect()
}
