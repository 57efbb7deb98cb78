//! Stage 5 — wear of the bronze wheel over life (MODEL §7): Archard wear per mesh cycle on the
//! global flank grid, wear steps with the geometry updated, backlash.
//!
//! Per-cycle wear (MODEL §7.2, line-load form). A wheel point M is swept once per wheel
//! revolution by the contact band; the depth worn in that passage is
//! (k/H) |vg| integral(p dt) = (k/H) |vg| w / u2, with w the load per unit length of the
//! contact line when it crosses M and u2 the speed of the line over the wheel flank across
//! itself. On each node column the loaded analysis gives, at every (position, tooth), the line
//! crossing r and the line load w; tooth k at wheel rotation theta2 is the reference tooth at
//! theta2 + sigma k tau, so these samples are the history of the reference tooth over its whole
//! engagement. Between consecutive samples the crossing moves from r_a to r_b; the nodes in
//! between take w (and the Hertz pressure, the curvature) interpolated at their own crossing.
//! The map is therefore a smooth function sampled at nodes, converging as positions are added
//! (no aliasing from sampling pressures at discrete instants). |vg|, u1, u2 are the kinematics of
//! each node at its contact moment (TCA), the film and k(lambda) come from [`crate::lubrication`].

use crate::geometry::{FlankField, Geometry, WheelFlank};
use crate::input::GearSet;
use crate::kinematics::{GapEvaluator, Tca};
use crate::lubrication::{self, LineContact};
use crate::ltca::Ltca;
use std::collections::HashMap;
use std::f64::consts::PI;

/// Wear of one mesh cycle (one passage of the contact over every point of the reference
/// tooth) on the loaded wheel flank's nodes.
#[derive(Debug, Clone, serde::Serialize)]
pub struct CycleWear {
    /// Depth worn normal to the flank per cycle, m.
    pub depth: FlankField,
    /// Film ratio lambda at the passage (the smallest if swept more than once; NaN where the
    /// loaded line never passes).
    pub lambda: FlankField,
    /// Film thickness h_min Phi_T at the passage, m (NaN where not swept).
    pub film: FlankField,
    /// Line load at the passage, N/m (0 where not swept).
    pub line_load: FlankField,
}

/// One sample of the line's passage over a node column.
#[derive(Debug, Clone, Copy)]
struct Sample {
    /// Time of the reference tooth, as driven wheel rotation (sigma theta2_ref), rad.
    time: f64,
    r: f64,
    line_load: f64,
    pressure: f64,
    radius: f64,
}

/// Floor of the line's speed over the wheel, m/s: where the line runs almost along itself the
/// passage time 1/u2 diverges while the real contact time stays bounded by the engagement.
const MIN_LINE_SPEED: f64 = 1e-3;

/// Wear of one mesh cycle from the loaded analysis (MODEL §7.1-7.2), on the loaded flank.
pub fn per_cycle(gear: &GearSet, geo: &Geometry, tca: &Tca, ltca: &Ltca) -> CycleWear {
    let wf = geo.wheel_flank(tca.loaded_flank);
    let (ni, nj) = (wf.cells_height, wf.cells_face);
    let tau = 2.0 * PI / geo.teeth as f64;
    let np = tca.positions.len();
    let dt = tau / np as f64;
    // Line load and Hertz pressure per (position, tooth, slice) from the local cells.
    let mut loads: HashMap<(usize, i32, usize), (f64, f64)> = HashMap::new();
    for pr in &ltca.positions {
        for (c, &p) in pr.cells.iter().zip(&pr.pressure) {
            let e = loads.entry((pr.position, c.tooth, c.slice)).or_insert((0.0, 0.0));
            e.0 += p * 2.0 * c.cell.half_nu;
            e.1 = e.1.max(p);
        }
    }
    // Samples per node column, in time order.
    let mut columns: Vec<Vec<Sample>> = vec![Vec::new(); nj + 1];
    for line in &tca.contact_lines {
        let theta2 = tca.positions[line.position].theta2 + tca.sigma * line.tooth as f64 * tau;
        let (w, p) = loads
            .get(&(line.position, line.tooth, line.slice))
            .copied()
            .unwrap_or((0.0, 0.0));
        columns[line.slice].push(Sample {
            time: tca.sigma * theta2,
            r: line.r,
            line_load: w,
            pressure: p,
            radius: line.curvature_radius,
        });
    }
    let e_prime = lubrication::reduced_modulus(
        gear.worm_material.youngs_modulus,
        gear.worm_material.poisson_ratio,
        gear.wheel_material.youngs_modulus,
        gear.wheel_material.poisson_ratio,
    );
    let k_dry = gear.wheel_material.wear_coefficient;
    let hardness = gear.wheel_material.hardness;
    let mut depth = FlankField::zeros(wf);
    let mut lambda = FlankField::zeros(wf);
    let mut film = FlankField::zeros(wf);
    let mut line_load = FlankField::zeros(wf);
    lambda.values.fill(f64::NAN);
    film.values.fill(f64::NAN);
    for (j, samples) in columns.iter_mut().enumerate() {
        samples.sort_by(|a, b| a.time.total_cmp(&b.time));
        for pair in samples.windows(2) {
            let (a, b) = (pair[0], pair[1]);
            // Consecutive instants of the same engagement only.
            if b.time - a.time > 1.5 * dt || a.r == b.r {
                continue;
            }
            if a.line_load <= 0.0 && b.line_load <= 0.0 {
                continue;
            }
            let (lo, hi) = (a.r.min(b.r), a.r.max(b.r));
            for i in 0..=ni {
                let k = j * (ni + 1) + i;
                let node = &wf.nodes[k];
                if node.r < lo || node.r >= hi {
                    continue;
                }
                let nc = &tca.node_contact[k];
                if !nc.reachable || !nc.u2.is_finite() {
                    continue;
                }
                let f = (node.r - a.r) / (b.r - a.r);
                let lerp = |x: f64, y: f64| {
                    if !x.is_finite() {
                        y
                    } else if !y.is_finite() {
                        x
                    } else {
                        x + f * (y - x)
                    }
                };
                let w = lerp(a.line_load, b.line_load).max(0.0);
                if w <= 0.0 {
                    continue;
                }
                let contact = LineContact {
                    radius: lerp(a.radius, b.radius),
                    u1: nc.u1,
                    u2: nc.u2,
                    line_load: w,
                    pressure: lerp(a.pressure, b.pressure),
                };
                let fl = lubrication::film(&gear.lubricant, e_prime, &contact);
                let kw = lubrication::wear_coefficient(k_dry, fl.lambda);
                depth.values[k] +=
                    kw / hardness * nc.sliding_speed * w / nc.u2.abs().max(MIN_LINE_SPEED);
                if !(lambda.values[k] <= fl.lambda) {
                    lambda.values[k] = fl.lambda;
                    film.values[k] = fl.h_min * fl.thermal_factor;
                }
                line_load.values[k] = line_load.values[k].max(w);
            }
        }
    }
    CycleWear {
        depth,
        lambda,
        film,
        line_load,
    }
}

/// Lever |(P x n)_z| of node k of a flank (rotation invariant about the wheel axis), m.
fn node_lever(wf: &WheelFlank, k: usize) -> f64 {
    let n = &wf.nodes[k];
    GapEvaluator::lever(&n.position(), &n.normal_vec())
}

/// Backlash with the worm blocked (MODEL §7.6): at each position the wheel turns both ways
/// until a flank of any studied tooth touches the worm; the loaded flank's gaps grow with the
/// material worn off it.
#[derive(Debug, Clone)]
pub struct Backlash {
    /// Smallest angular gap of the unloaded opposite flank per position, rad.
    opposite: Vec<f64>,
    /// Loaded flank: angular gaps per (position, tooth, node) (TCA), rad.
    loaded: Vec<f64>,
    levers: Vec<f64>,
    teeth: usize,
    nodes: usize,
    /// Wheel reference radius r2 for the linear (tangential) value, m.
    pub reference_radius: f64,
}

/// Backlash over the positions.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct BacklashStats {
    /// Angular backlash, rad: mean, min, max over positions.
    pub mean_rad: f64,
    pub min_rad: f64,
    pub max_rad: f64,
    /// Linear (tangential at r2) mean backlash, m.
    pub linear_mean_m: f64,
}

impl Backlash {
    /// Gaps of both flanks over the TCA's positions and teeth.
    pub fn new(gear: &GearSet, geo: &Geometry, tca: &Tca) -> Self {
        use rayon::prelude::*;
        let other = match tca.loaded_flank {
            crate::geometry::Flank::Left => crate::geometry::Flank::Right,
            crate::geometry::Flank::Right => crate::geometry::Flank::Left,
        };
        let ev = GapEvaluator::for_flank(gear, geo, other);
        let wf = geo.wheel_flank(other);
        let tau = 2.0 * PI / geo.teeth as f64;
        let opposite: Vec<f64> = tca
            .positions
            .par_iter()
            .map(|pos| {
                let mut best = f64::INFINITY;
                for &k in &tca.teeth {
                    let offset = tca.sigma * k as f64 * tau;
                    for p in &wf.nodes {
                        best = best.min(ev.angular(p.r, p.theta + offset, p.z, pos.theta2, pos.theta1));
                    }
                }
                best
            })
            .collect();
        let lwf = geo.wheel_flank(tca.loaded_flank);
        Self {
            opposite,
            loaded: tca.node_gaps.clone(),
            levers: (0..lwf.nodes.len()).map(|k| node_lever(lwf, k)).collect(),
            teeth: tca.teeth.len(),
            nodes: lwf.nodes.len(),
            reference_radius: gear.wheel_reference_radius(),
        }
    }

    /// Backlash per position with `removal` (m, normal) worn off the loaded flank, rad.
    pub fn per_position(&self, removal: &FlankField) -> Vec<f64> {
        self.opposite
            .iter()
            .enumerate()
            .map(|(n, opp)| {
                let mut best = f64::INFINITY;
                for t in 0..self.teeth {
                    let base = (n * self.teeth + t) * self.nodes;
                    for k in 0..self.nodes {
                        let g = self.loaded[base + k] + removal.values[k] / self.levers[k];
                        best = best.min(g);
                    }
                }
                best + opp
            })
            .collect()
    }

    /// Mean, min, max over positions and the linear mean at r2.
    pub fn stats(&self, removal: &FlankField) -> BacklashStats {
        let v = self.per_position(removal);
        let mean = v.iter().sum::<f64>() / v.len().max(1) as f64;
        BacklashStats {
            mean_rad: mean,
            min_rad: v.iter().copied().fold(f64::INFINITY, f64::min),
            max_rad: v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            linear_mean_m: mean * self.reference_radius,
        }
    }
}

/// How the cycles of a wear step are chosen (MODEL §7.3).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum StepControl {
    /// Fixed number of wheel cycles per step.
    Cycles(f64),
    /// Adaptive: each step removes at most this depth, m.
    MaxRemoval(f64),
}

/// Life to simulate.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LifeSettings {
    /// Total wheel cycles (revolutions).
    pub cycles: f64,
    pub step: StepControl,
}

/// State of a life run after a completed step: what a checkpoint holds.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WearState {
    /// Completed wear steps.
    pub step: usize,
    /// Wheel cycles run.
    pub cycles: f64,
    /// Depth worn off the loaded flank so far, normal to it, m.
    pub removal: FlankField,
    /// Records of the states so far (the initial one and one per completed step).
    pub records: Vec<StepRecord>,
}

impl WearState {
    /// Unworn start.
    pub fn new(wf: &WheelFlank) -> Self {
        Self {
            step: 0,
            cycles: 0.0,
            removal: FlankField::zeros(wf),
            records: Vec::new(),
        }
    }
}

/// The gear's state at some cycles: wear so far and the loaded analysis on that geometry
/// (units in the names; MODEL §7.7).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StepRecord {
    /// Completed steps (0: the unworn gear).
    pub step: usize,
    pub cycles: f64,
    /// Cycles of the step that led here (0 for the start).
    pub step_cycles: f64,
    /// Largest depth worn, m.
    pub max_wear_m: f64,
    /// Worn volume / active flank area (mean depth over the flank), m.
    pub mean_wear_m: f64,
    /// Worn volume of one tooth flank, m^3.
    pub worn_volume_m3: f64,
    /// Tangential backlash at r2, mean over positions, m; and its increase since the start.
    pub backlash_m: f64,
    pub backlash_increase_m: f64,
    pub backlash_min_rad: f64,
    pub backlash_max_rad: f64,
    pub max_pressure_pa: f64,
    pub mean_pressure_pa: f64,
    pub contact_area_fraction: f64,
    pub s1: f64,
    pub s2: f64,
    pub te_mean_rad: f64,
    pub te_p2p_rad: f64,
    pub mesh_stiffness_mean_nm_per_rad: f64,
    /// Wear per cycle on this geometry (the rate of the next step), largest, m.
    pub max_wear_per_cycle_m: f64,
    /// Film ratio range over the swept nodes.
    pub lambda_min: f64,
    pub lambda_max: f64,
}

/// Why a life run stopped.
#[derive(Debug, thiserror::Error)]
pub enum WearError {
    #[error("at {cycles} cycles (step {step}): {source}")]
    Ltca {
        step: usize,
        cycles: f64,
        #[source]
        source: crate::ltca::LtcaError,
    },
    #[error("the checkpoint does not match this gear's flank grid ({0})")]
    Checkpoint(String),
    #[error("{0}")]
    Output(String),
}

/// What the life loop hands out after each completed state: the state (to checkpoint), the
/// loaded analysis and the per-cycle wear on that geometry.
pub struct StepView<'a> {
    pub state: &'a WearState,
    pub ltca: &'a Ltca,
    pub cycle: &'a CycleWear,
}

/// Runs the life (MODEL §7.3-7.7) from `state` (unworn, or a checkpoint): at each state the
/// loaded analysis on the worn geometry, the wear of one cycle, a record; then a step of
/// C_k cycles (fixed, or removing at most the given depth) with the geometry frozen; until
/// the life is reached. `on_state` is called after every record (checkpoint, files); an error
/// from it stops the run.
#[allow(clippy::too_many_arguments)]
pub fn simulate(
    gear: &GearSet,
    geo: &Geometry,
    tca: &Tca,
    settings: &crate::ltca::LtcaSettings,
    bending: Option<&dyn crate::ltca::BendingModel>,
    life: &LifeSettings,
    mut state: WearState,
    on_state: &mut dyn FnMut(&StepView) -> Result<(), WearError>,
) -> Result<WearState, WearError> {
    let wf = geo.wheel_flank(tca.loaded_flank);
    if state.removal.values.len() != wf.nodes.len()
        || state.removal.cells_height != wf.cells_height
    {
        return Err(WearError::Checkpoint(format!(
            "{} x {} cells, the gear has {} x {}",
            state.removal.cells_height,
            state.removal.cells_face,
            wf.cells_height,
            wf.cells_face
        )));
    }
    let backlash = Backlash::new(gear, geo, tca);
    let initial = backlash.stats(&FlankField::zeros(wf)).linear_mean_m;
    let area = wf.active_area();
    let mut step_cycles = state.records.last().map_or(0.0, |r| r.step_cycles);
    loop {
        let l = crate::ltca::analyse_worn(gear, geo, tca, settings, bending, Some(&state.removal))
            .map_err(|source| WearError::Ltca {
                step: state.step,
                cycles: state.cycles,
                source,
            })?;
        let cw = per_cycle(gear, geo, tca, &l);
        let b = backlash.stats(&state.removal);
        let (te_mean, te_p2p) = l.te_stats();
        let lambdas = cw.lambda.values.iter().copied().filter(|v| v.is_finite());
        let volume = state.removal.integral(wf);
        let record = StepRecord {
            step: state.step,
            cycles: state.cycles,
            step_cycles,
            max_wear_m: state.removal.max(),
            mean_wear_m: volume / area,
            worn_volume_m3: volume,
            backlash_m: b.linear_mean_m,
            backlash_increase_m: b.linear_mean_m - initial,
            backlash_min_rad: b.min_rad,
            backlash_max_rad: b.max_rad,
            max_pressure_pa: l.max_pressure,
            mean_pressure_pa: l.mean_pressure,
            contact_area_fraction: l.s0,
            s1: l.s1,
            s2: l.s2,
            te_mean_rad: te_mean,
            te_p2p_rad: te_p2p,
            mesh_stiffness_mean_nm_per_rad: l.stiffness_mean(),
            max_wear_per_cycle_m: cw.depth.max(),
            lambda_min: lambdas.clone().fold(f64::INFINITY, f64::min),
            lambda_max: lambdas.fold(0.0, f64::max),
        };
        // A resumed run recomputes the state it stopped at: keep one record per step.
        state.records.retain(|r| r.step < state.step);
        state.records.push(record);
        on_state(&StepView {
            state: &state,
            ltca: &l,
            cycle: &cw,
        })?;
        let left = life.cycles - state.cycles;
        if left <= 1e-9 * life.cycles.max(1.0) {
            break;
        }
        let rate = cw.depth.max();
        step_cycles = match life.step {
            StepControl::Cycles(c) => c.min(left),
            StepControl::MaxRemoval(d) if rate > 0.0 => (d / rate).min(left),
            StepControl::MaxRemoval(_) => left,
        };
        for (h, dh) in state.removal.values.iter_mut().zip(&cw.depth.values) {
            *h += step_cycles * dh;
        }
        state.cycles += step_cycles;
        state.step += 1;
    }
    Ok(state)
}
