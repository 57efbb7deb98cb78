//! The life loop (MODEL §7.1, §7.5): wear steps with the geometry updated, the step control, the
//! phases of the schedule, pitting between steps, the maps' states, and the check that a life
//! does not stall (that a plan can end: [`super::limits`]).

use super::spectrum::{spectrum_cycle_wear, spectrum_node_loads, BinStart};
use super::stabilised::{self, stabilised_removal, NodeResponse};
use super::{
    cut_pits, forecast, per_cycle, pit_depths, Backlash, CycleWear, Phase, Pitting, StepControl,
    StepScheme, WearError, WearLimits, WearPlan, WearState,
};
use crate::friction::{heat_balance_from, MeshContacts, Thermal};
use crate::geometry::{FlankField, Geometry, WheelFlank};
use crate::input::GearSet;
use crate::kinematics::Tca;
use crate::ltca::Ltca;
use std::borrow::Cow;

mod record;

/// What the life loop hands out after each completed state: the state (to checkpoint), the
/// loaded analysis, the per-cycle wear and the friction on that geometry.
pub struct StepView<'a> {
    pub state: &'a WearState,
    pub ltca: &'a Ltca,
    pub cycle: &'a CycleWear,
    /// The friction, efficiency and oil temperature of that loaded analysis (MODEL §13).
    pub thermal: &'a Thermal,
    /// The last state of the run (the life is reached).
    pub last: bool,
    /// A state whose maps are written (`map_cycles`, or 0, 1, 2, 4, ... by default).
    pub map: bool,
}

/// Runs the life (MODEL §7.3-7.7, §8) from `state` (unworn, or a checkpoint): at each state
/// the loaded analysis on the worn geometry, the wear of one cycle, a record; then, in a wear
/// phase, a step of C_k cycles (fixed, or removing at most the given depth; never across a
/// phase end or a map cycle) with the geometry frozen; at the start of a pitting phase the
/// pits are cut (every node whose loaded-pattern pressure exceeds the phase's limit loses
/// 0.78 a, a the local Hertz half-width there, MODEL §12 g), then the phase passes without
/// wear. Until the life is reached, or a wear limit is ([`WearLimits`]: the pointed tip, or the
/// backlash limit if the plan stops there; the state's `stopped` says which). `on_state` is
/// called on the calling thread after every record (checkpoint, files) while the pool steps
/// and analyses the next state; an error from it stops the run (after that analysis).
#[allow(clippy::too_many_arguments)]
pub fn simulate(
    gear: &GearSet,
    geo: &Geometry,
    tca: &Tca,
    settings: &crate::ltca::LtcaSettings,
    bending: Option<&dyn crate::ltca::BendingModel>,
    life: &WearPlan,
    mut state: WearState,
    on_state: &mut dyn FnMut(&StepView) -> Result<(), WearError>,
) -> Result<WearState, WearError> {
    fit_to_flank(&mut state, geo.wheel_flank(tca.loaded_flank))?;
    super::check_plan_can_end(gear, life)?;
    let life_loop = LifeLoop::new(gear, geo, tca, settings, bending, life)?;
    let mut step_cycles = state.records.last().map_or(0.0, |r| r.step_cycles);
    let mut substeps = state.records.last().map_or(0, |r| r.substeps);
    // A resumed run recomputes the state its checkpoint holds: its analysis must see the
    // records the uninterrupted run saw then (the heat balance starts from the last one), not
    // the state's own record, which it writes again.
    state.records.retain(|r| r.step < state.step);
    let mut stalled = 0;
    let mut analysis = life_loop.analyse_state(&state)?;
    let mut probes = life_loop.measure_response(&mut state, &analysis)?;
    // The analysis before the last: freed on this thread while the pool works (the loaded
    // analysis' many buffers take about as long to free as a record to draw up, issue 55).
    let mut retired: Option<StateAnalysis> = None;
    loop {
        let a = analysis;
        life_loop.start_forecast_phase(&mut state, &a.loads);
        let phase = life_loop.phase_at(&state, state.cycles);
        let probed = std::mem::take(&mut probes);
        life_loop.close_state(&mut state, &a, phase, (step_cycles, substeps), probed);
        let left = life.life_cycles - state.cycles;
        let last = left <= 1e-9 * life.life_cycles.max(1.0) || state.stopped.is_some();
        let map = life_loop.is_map_state(&state);
        if last {
            on_state(&StepView::of(&state, &a, last, map))?;
            break;
        }
        // The next state is stepped and analysed while this one is written (`on_state` on
        // this thread): the writing leaves the life's critical path (issue 55). The next
        // state's copy holds the last record only, all a step and an analysis read.
        let mut next = state_to_step(&mut state);
        let view = StepView::of(&state, &a, last, map);
        let mut stepped = None;
        // In place: the calling thread writes, the pool steps and analyses; a pool thread
        // (a sweep's variant) keeps stealing while it waits, so the pool cannot deadlock.
        let written = rayon::in_place_scope(|scope| {
            scope.spawn(|_| {
                stepped = Some((|| {
                    // What the next analysis starts from (after the checkpoint, which keeps
                    // what this state's analysis used).
                    carry_starts(&mut next, &a);
                    let before = next.cycles;
                    let steps = life_loop.step(&mut next, &a, phase, left)?;
                    next.step += 1;
                    let stalled = stalled_steps(stalled, before, &next)?;
                    let analysis = life_loop.analyse_state(&next)?;
                    let probes = life_loop.measure_response(&mut next, &analysis)?;
                    Ok::<_, WearError>((steps, stalled, analysis, probes))
                })());
            });
            let written = on_state(&view);
            drop(retired.take());
            written
        });
        written?;
        ((step_cycles, substeps), stalled, analysis, probes) =
            stepped.expect("the scope ran the step")?;
        next.records = std::mem::take(&mut state.records);
        state = next;
        retired = Some(a);
    }
    Ok(state)
}

/// Checks that a starting state (a checkpoint's) has the loaded flank's grid, and gives it
/// the fields it lacks (pits, damage and plastic set of earlier versions).
fn fit_to_flank(state: &mut WearState, wf: &WheelFlank) -> Result<(), WearError> {
    if state.removal.values.len() != wf.nodes.len() || state.removal.cells_height != wf.cells_height
    {
        return Err(WearError::Checkpoint(format!(
            "{} x {} cells, the gear has {} x {}",
            state.removal.cells_height, state.removal.cells_face, wf.cells_height, wf.cells_face
        )));
    }
    if state.pitted.len() != wf.nodes.len() {
        state.pitted = vec![false; wf.nodes.len()];
    }
    if state.damage.len() != wf.nodes.len() {
        state.damage = vec![0.0; wf.nodes.len()];
    }
    if !state.plastic_set.fits(wf) {
        state.plastic_set = FlankField::zeros(wf);
    }
    Ok(())
}

impl<'a> StepView<'a> {
    /// The view of `state` with its analysis `a`.
    fn of(state: &'a WearState, a: &'a StateAnalysis, last: bool, map: bool) -> Self {
        Self {
            state,
            ltca: &a.ltca,
            cycle: &a.cycle,
            thermal: &a.thermal,
            last,
            map,
        }
    }
}

/// A copy of `state` to step from, holding its last record only (a step and the analysis of
/// the state it reaches read no other: [`WearState::previous_record`]), and no warm starts
/// (the step's [`carry_starts`] sets them from the analysis: copying them would be waste).
fn state_to_step(state: &mut WearState) -> WearState {
    let records = std::mem::take(&mut state.records);
    let warm = state.warm.take();
    let bin_starts = std::mem::take(&mut state.bin_starts);
    let mut next = state.clone();
    next.records = records.last().cloned().into_iter().collect();
    state.records = records;
    state.warm = warm;
    state.bin_starts = bin_starts;
    next
}

/// Where the next loaded analyses start from after state analysis `a`: its band factors and
/// warm starts (each bin's with a spectrum), and the running-in of its plastic indentation
/// (the largest load's, MODEL §5.7, §14).
fn carry_starts(state: &mut WearState, a: &StateAnalysis) {
    state.band_factor = a.band;
    state.warm = Some(a.ltca.warm_start());
    if !a.bins.is_empty() {
        state.bin_starts = a
            .bins
            .iter()
            .map(|b| BinStart {
                band_factor: b.band,
                warm: Some(b.ltca.warm_start()),
            })
            .collect();
    }
    state.run_in(&a.ltca);
}

/// The count of consecutive steps that left the cycles where they were, with the one that
/// brought `state` from `before` cycles: a life that stops advancing would run for ever, a
/// defect reported as such after [`MAX_STALLED_STEPS`].
fn stalled_steps(stalled: usize, before: f64, state: &WearState) -> Result<usize, WearError> {
    let stalled = if state.cycles > before {
        0
    } else {
        stalled + 1
    };
    if stalled >= MAX_STALLED_STEPS {
        return Err(WearError::Plan(format!(
            "the life did not advance beyond {} cycles in {MAX_STALLED_STEPS} steps (step {}): \
             stopped rather than run for ever; please report it with the gear file",
            state.cycles, state.step
        )));
    }
    Ok(stalled)
}

/// The largest removal of an error-controlled life's first step, and of the first after a
/// pitting phase, where no estimate exists yet (the published adaptive step's, MODEL §7.3), m.
pub const FIRST_CONTROLLED_REMOVAL: f64 = 4e-6;

/// Consecutive steps that may leave the cycles where they were (a pitting phase's cut pits
/// take none) before a life is stopped as stalled.
const MAX_STALLED_STEPS: usize = 50;

/// What the life loop of [`simulate`] works with, and its named steps.
struct LifeLoop<'a> {
    geo: &'a Geometry,
    settings: &'a crate::ltca::LtcaSettings,
    bending: Option<&'a dyn crate::ltca::BendingModel>,
    life: &'a WearPlan,
    wf: &'a WheelFlank,
    backlash: Backlash,
    /// Backlash per position of the unworn flank, rad.
    initial_backlash: Vec<f64>,
    active_area: f64,
    /// Sliding speed at the reference diameter (the standard's v_gm) and sigma_Hlim, for
    /// Rank's N_LI from the model's mean pressure.
    sliding_speed: f64,
    pitting_limit: f64,
    limits: WearLimits,
    /// The bins the life runs (MODEL §14): the gear itself without a spectrum.
    bins: Vec<LifeBin<'a>>,
    /// The bin of the largest load (the gear's conditions), whose analysis the records show.
    reference: usize,
}

/// One bin of a life (MODEL §14): the gear at the bin, its unloaded analysis and loaded
/// analysis' settings, its share of the wheel's cycles, and MODEL §9's no-load, bearing and
/// seal losses beside the mesh's at its speed, W (MODEL §13).
struct LifeBin<'a> {
    gear: Cow<'a, GearSet>,
    tca: Cow<'a, Tca>,
    settings: crate::ltca::LtcaSettings,
    cycle_share: f64,
    other_losses: f64,
}

/// What a state's loaded analyses give (MODEL §7, §14): the analysis the record shows (the
/// bin of the largest load's) with its band factor and friction, the wear of one cycle and the
/// damage loads of the whole spectrum, and each bin's own (empty without a spectrum).
struct StateAnalysis {
    ltca: Ltca,
    band: Option<f64>,
    thermal: Thermal,
    cycle: CycleWear,
    loads: forecast::NodeLoads,
    bins: Vec<BinAnalysis>,
}

/// One bin's loaded analysis, band factor, wear of one cycle and friction in a state.
struct BinAnalysis {
    ltca: Ltca,
    band: Option<f64>,
    cycle: CycleWear,
    thermal: Thermal,
}

impl<'a> LifeLoop<'a> {
    fn new(
        gear: &'a GearSet,
        geo: &'a Geometry,
        tca: &'a Tca,
        settings: &'a crate::ltca::LtcaSettings,
        bending: Option<&'a dyn crate::ltca::BendingModel>,
        life: &'a WearPlan,
    ) -> Result<Self, WearError> {
        let wf = geo.wheel_flank(tca.loaded_flank);
        let backlash = Backlash::new(gear, geo, tca);
        let initial_backlash = backlash.per_position(&FlankField::zeros(wf));
        let rating = crate::rating::rate(gear);
        let (bins, reference) = life_bins(gear, geo, tca, settings)?;
        Ok(Self {
            geo,
            settings,
            bending,
            life,
            wf,
            backlash,
            initial_backlash,
            active_area: wf.active_area(),
            sliding_speed: rating.sliding_speed_m_s,
            pitting_limit: gear.wheel_material.pitting_limit,
            limits: WearLimits::new(gear, geo, tca, life),
            bins,
            reference,
        })
    }

    /// The loaded analyses of a state (MODEL §7, §14): the gear's, or each bin's with the
    /// spectrum's wear of a cycle and damage loads summed over them.
    fn analyse_state(&self, state: &WearState) -> Result<StateAnalysis, WearError> {
        if self.bins.len() == 1 {
            let (ltca, band) = self.analyse(state, 0)?;
            let (cycle, thermal) = self.cycle_wear(state, 0, &ltca)?;
            let loads = self.node_loads(&ltca, &cycle);
            return Ok(StateAnalysis {
                ltca,
                band,
                thermal,
                cycle,
                loads,
                bins: Vec::new(),
            });
        }
        let mut bins = Vec::new();
        for b in 0..self.bins.len() {
            let (ltca, band) = self.analyse(state, b)?;
            let (cycle, thermal) = self.cycle_wear(state, b, &ltca)?;
            bins.push(BinAnalysis {
                ltca,
                band,
                cycle,
                thermal,
            });
        }
        let shares = self.bins.iter().map(|b| b.cycle_share);
        let wear: Vec<(f64, &CycleWear)> =
            shares.clone().zip(bins.iter().map(|a| &a.cycle)).collect();
        let cycle = spectrum_cycle_wear(&wear, self.reference);
        let each: Vec<forecast::NodeLoads> = bins
            .iter()
            .map(|a| self.node_loads(&a.ltca, &a.cycle))
            .collect();
        let parts: Vec<(f64, &forecast::NodeLoads)> = shares.zip(&each).collect();
        let loads = spectrum_node_loads(&parts, &self.life.endurance);
        let r = &bins[self.reference];
        Ok(StateAnalysis {
            ltca: r.ltca.clone(),
            band: r.band,
            thermal: r.thermal.clone(),
            cycle,
            loads,
            bins,
        })
    }

    /// The damage loads of the flank's nodes under one loaded analysis and its wear of a cycle.
    fn node_loads(&self, l: &Ltca, cw: &CycleWear) -> forecast::NodeLoads {
        let life = self.life;
        forecast::NodeLoads::new(
            self.wf,
            l,
            cw,
            &life.endurance,
            (
                life.pit_depth,
                life.pitting_stress,
                life.damage_node_reading,
            ),
        )
    }

    /// Where bin `b`'s loaded analysis starts in a state: its band factor, the solver's warm
    /// start and the oil temperature of the last record (K; None at the first state).
    fn start_of<'s>(
        &self,
        state: &'s WearState,
        b: usize,
    ) -> (Option<f64>, Option<&'s crate::ltca::WarmStart>, Option<f64>) {
        let last = state.records.last();
        if self.bins.len() == 1 {
            let oil = last.map(|r| r.friction.oil_temperature_k);
            return (state.band_factor, state.warm.as_ref(), oil);
        }
        let start = state.bin_starts.get(b);
        let oil = last
            .and_then(|r| r.bins.get(b))
            .map(|x| x.friction.oil_temperature_k);
        (
            start.and_then(|s| s.band_factor),
            start.and_then(|s| s.warm.as_ref()),
            oil,
        )
    }

    /// The schedule of this life: the plan's, or the one its forecast has found so far.
    fn schedule<'s>(&'s self, state: &'s WearState) -> &'s [Phase] {
        match self.life.pitting {
            Pitting::Forecast => &state.found_phases,
            _ => &self.life.phases,
        }
    }

    /// Whether the pits come from the damage (`wear::forecast`).
    fn pits_from_damage(&self) -> bool {
        matches!(self.life.pitting, Pitting::Damage | Pitting::Forecast)
    }

    /// A forecast starts a pitting phase at a state of a wear phase (after its first state)
    /// where loaded nodes whose damage has reached 1 make up the onset share of the flank
    /// (default 2 %; 0: the first such node; `wear::forecast`). The phase lasts the life on
    /// the pressure–life curve of its least loaded pit.
    fn start_forecast_phase(&self, state: &mut WearState, loads: &forecast::NodeLoads) {
        if self.life.pitting != Pitting::Forecast {
            return;
        }
        let cycles = state.cycles;
        if let Some((_, Phase::Pitting { .. }, _)) = self.phase_at(state, cycles) {
            return;
        }
        let wear_start = state.found_phases.last().map_or(0.0, phase_end);
        let Some(pressure) = loads.median_due_pressure(&state.damage) else {
            return;
        };
        let onset = self.life.pitting_onset_share;
        if cycles > wear_start && loads.due_share(&state.damage) >= onset {
            state.found_phases.push(Phase::Wear { until: cycles });
            state.found_phases.push(Phase::Pitting {
                until: cycles + self.life.endurance.life(pressure),
                pressure_limit: None,
                margin: 0.0,
            });
        }
    }

    /// The step from a state (`left`: cycles to the life's end): in a pitting phase, its pits
    /// or its passing without wear ([`Self::pitting_step`]); in a wear phase, a wear step,
    /// which with pits from the damage ends where the nodes due make up the onset share. The damage advances
    /// over a wear step and holds in a pitting phase (`wear::forecast`). Returns the step's cycles
    /// and sub-steps.
    fn step(
        &self,
        state: &mut WearState,
        a: &StateAnalysis,
        phase: Option<(usize, Phase, f64)>,
        left: f64,
    ) -> Result<(f64, usize), WearError> {
        let (l, cw, loads) = (&a.ltca, &a.cycle, &a.loads);
        let end = match phase {
            Some((k, Phase::Pitting { .. }, end)) => {
                state.rates_before = None;
                let advanced = self.pitting_step(state, l, cw, loads, k, end);
                return Ok((advanced, 1));
            }
            Some((_, Phase::Wear { .. }, end)) => end,
            None => self.life.life_cycles,
        };
        let mut left = left
            .min(end - state.cycles)
            .min(self.next_map_cycles(state.cycles) - state.cycles);
        if self.pits_from_damage() {
            // Steps end where the nodes due to pit make up the onset share: a forecast starts
            // its phases there, and a schedule with pits from the damage resolves the same
            // states (the phases a forecast found repeat it).
            let onset = self.life.pitting_onset_share;
            if let Some(n) = loads.cycles_to_onset(&state.damage, onset) {
                left = left.min(n);
            }
        }
        let step_cycles = self.step_cycles(state, cw).min(left);
        let target = state.cycles + step_cycles;
        let substeps = self.wear_step(state, cw.clone(), step_cycles)?;
        // The sub-steps' sum lands on the step's end, and a step to a phase's end on that
        // end, exactly: a schedule's phases then start at the cycles they were found at.
        state.cycles = if (end - target).abs() <= 1e-9 * end {
            end
        } else {
            target
        };
        loads.advance(&mut state.damage, step_cycles, true);
        Ok((step_cycles, substeps))
    }

    /// The cycles of a wear step from `state` at the wear per cycle `cw` (MODEL §7.3): fixed,
    /// or removing at most the adaptive step's depth at the fastest node, and with the error
    /// control (`wear::stabilised`) the last step's cycles grown or cut by its error estimate
    /// (a first step, or the first after a pitting phase, removes at most
    /// [`FIRST_CONTROLLED_REMOVAL`]); with it, sets the rates the next step's estimate starts
    /// from (without it the state holds none).
    fn step_cycles(&self, state: &mut WearState, cw: &CycleWear) -> f64 {
        let rate = cw.depth.max();
        let cap = match self.life.step {
            StepControl::Cycles(c) => return c,
            StepControl::MaxRemoval(d) if rate > 0.0 => d / rate,
            StepControl::MaxRemoval(_) => return f64::INFINITY,
        };
        let tolerance = self.life.step_tolerance;
        if tolerance <= 0.0 {
            return cap;
        }
        let patch = (self.settings.patch_across, self.settings.patch_along);
        // This state's record (the step that led here): a step's copy holds it last.
        let record = state.records.last().filter(|r| r.step == state.step);
        let last = record.map_or(0.0, |r| r.step_cycles);
        let mut now = stabilised::RateMeasures::of(&cw.depth, self.wf, patch);
        now.backlash_increase = record.map_or(0.0, |r| r.backlash_increase_m);
        let before = state.rates_before.take();
        now.backlash = before
            .filter(|_| last > 0.0)
            .map(|b| (now.backlash_increase - b.backlash_increase) / last);
        state.rates_before = Some(now);
        let mut worn = stabilised::RateMeasures::of(&state.removal, self.wf, patch);
        worn.backlash = Some(now.backlash_increase);
        before
            .and_then(|b| stabilised::controlled_cycles(last, (&b, &now), &worn, tolerance))
            .unwrap_or(FIRST_CONTROLLED_REMOVAL / rate)
            .min(cap)
    }

    /// The stabilised step's measured response of the wear to a node-scale removal
    /// (`wear::stabilised`), on the state `a` of `state`: on the life's first state, and again
    /// where the flank has changed since ([`NodeResponse::is_due`]); none with the explicit step.
    /// Returns the loaded analyses it took (a run resumed at the state it was measured on counts
    /// them again, so that the state's record is the uninterrupted run's).
    fn measure_response(
        &self,
        state: &mut WearState,
        a: &StateAnalysis,
    ) -> Result<usize, WearError> {
        if self.life.scheme != StepScheme::Stabilised {
            return Ok(0);
        }
        let (removal, pitted) = (
            state.removal.max(),
            state.pitted.iter().filter(|p| **p).count(),
        );
        let probes = 2 * self.bins.len();
        if let Some(r) = &state.node_response {
            if !r.is_due(removal, pitted) {
                return Ok(if r.measured_at_step == state.step {
                    probes
                } else {
                    0
                });
            }
        }
        let along = |height: bool| -> Result<Vec<f64>, WearError> {
            let pattern = stabilised::probe_pattern(&state.removal, height);
            let mut probe = state.clone();
            for (h, d) in probe.removal.values.iter_mut().zip(&pattern) {
                *h += d;
            }
            let b = self.analyse_state(&probe)?;
            Ok(stabilised::response(
                &a.cycle.depth,
                &b.cycle.depth,
                &pattern,
            ))
        };
        let response = NodeResponse {
            rows_per_m: along(true)?,
            columns_per_m: along(false)?,
            measured_at_removal_m: removal,
            measured_pitted_nodes: pitted,
            measured_at_step: state.step,
        };
        state.node_response = Some(response);
        Ok(probes)
    }

    /// Phase at some cycles: (index, phase, end); None after the schedule (wear).
    fn phase_at(&self, state: &WearState, cycles: f64) -> Option<(usize, Phase, f64)> {
        let mut start = 0.0;
        for (k, p) in self.schedule(state).iter().enumerate() {
            let end = phase_end(p);
            if cycles < end * (1.0 - 1e-12) && cycles >= start * (1.0 - 1e-12) {
                return Some((k, *p, end));
            }
            start = end;
        }
        None
    }

    /// The first map cycle beyond `cycles` (infinite: none).
    fn next_map_cycles(&self, cycles: f64) -> f64 {
        self.life
            .map_cycles
            .iter()
            .flatten()
            .copied()
            .find(|&c| c > cycles * (1.0 + 1e-12) + 1e-9)
            .unwrap_or(f64::INFINITY)
    }

    /// Whether the maps of this state are written: at the map cycles, or by default at the
    /// states 0, 1, 2, 4, 8, ...
    fn is_map_state(&self, state: &WearState) -> bool {
        match &self.life.map_cycles {
            None => state.step == 0 || state.step.is_power_of_two(),
            Some(list) => list
                .iter()
                .any(|&c| (c - state.cycles).abs() <= 1e-9 * c.max(1.0)),
        }
    }

    /// Loaded analysis on the worn geometry. The worn contact widens: the band of the local
    /// meshes starts as wide as the last analysis needed (no repeated widenings), carried in
    /// the state for an exact resume. An unworn flank is analysed as the LTCA stage does.
    fn analyse(&self, state: &WearState, b: usize) -> Result<(Ltca, Option<f64>), WearError> {
        let bin = &self.bins[b];
        let (band_factor, warm_start, last) = self.start_of(state, b);
        let mut local = bin.settings;
        local.band_factor = band_factor.unwrap_or(bin.settings.band_factor);
        // The friction the pressures carry at the last state's oil temperature (MODEL §13:
        // the heat balance's lags one state); the first state's from the fixed point.
        let gear: &GearSet = &bin.gear;
        if let Some(t) = last.filter(|t| *t > 0.0 && gear.housing.balance) {
            local.oil_temperature = t;
        }
        let changed = |f: &FlankField| f.values.iter().any(|&h| h != 0.0);
        let change = crate::ltca::FlankChange {
            removal: Some(&state.removal).filter(|f| changed(f)),
            plastic_set: Some(&state.plastic_set).filter(|f| changed(f)),
        };
        let analyse = |settings: &crate::ltca::LtcaSettings,
                       warm: Option<&crate::ltca::WarmStart>| {
            crate::ltca::analyse_changed(
                gear,
                self.geo,
                &bin.tca,
                settings,
                self.bending,
                change,
                warm.or(warm_start),
            )
            .map_err(|source| WearError::Ltca {
                step: state.step,
                cycles: state.cycles,
                source,
            })
        };
        let first = analyse(&local, None)?;
        let l = match last {
            Some(_) => first,
            None => {
                let inputs = (gear, self.geo, &*bin.tca);
                let other = bin.other_losses;
                crate::friction::oil_fixed_point(inputs, other, (local, first), analyse)?
            }
        };
        let widenings = l
            .positions
            .iter()
            .map(|p| p.band_widenings)
            .max()
            .unwrap_or(0);
        let band = (widenings > 0)
            .then(|| (local.band_factor * 1.6f64.powi(widenings as i32)).min(50.0))
            .or(band_factor);
        Ok((l, band))
    }

    /// The wear of one cycle of a state's loaded analysis `l` (MODEL §7.2) and its friction
    /// (MODEL §13): with the heat balance, the film of the wear at the balance's oil
    /// temperature (from the last record's, the temperature it starts from).
    fn cycle_wear(
        &self,
        state: &WearState,
        b: usize,
        l: &Ltca,
    ) -> Result<(CycleWear, Thermal), WearError> {
        let bin = &self.bins[b];
        let (gear, tca) = (&*bin.gear, &*bin.tca);
        let contacts = MeshContacts::new(gear, self.geo, tca, l);
        let start = self.start_of(state, b).2;
        let thermal = heat_balance_from(
            &contacts,
            (&gear.lubricant, &gear.friction, &gear.housing),
            bin.other_losses,
            start.filter(|t| *t > 0.0),
        )
        .map_err(|source| WearError::Friction {
            step: state.step,
            cycles: state.cycles,
            source,
        })?;
        let cw = if gear.housing.balance {
            let mut at = gear.clone();
            at.lubricant = gear.lubricant.at_temperature(thermal.oil_temperature_k);
            per_cycle(&at, self.geo, tca, l, self.life.film_load)
        } else {
            per_cycle(gear, self.geo, tca, l, self.life.film_load)
        };
        Ok((cw, thermal))
    }

    /// A state in pitting phase k (ending at `end`): at its start the pits are cut (same
    /// cycles; the next record shows the new pressures): above the phase's limit (published
    /// coupling) or where the damage has reached 1 ([`forecast`]; the cut nodes start
    /// again undamaged). Then the phase passes without wear up to its end (or the life's, if
    /// first). Returns the cycles advanced.
    fn pitting_step(
        &self,
        state: &mut WearState,
        l: &Ltca,
        cw: &CycleWear,
        loads: &forecast::NodeLoads,
        k: usize,
        end: f64,
    ) -> f64 {
        let Phase::Pitting {
            pressure_limit,
            margin,
            ..
        } = self.schedule(state)[k]
        else {
            return 0.0;
        };
        if !state.pitted_phases.contains(&k) && self.pits_from_damage() {
            loads.cut_due(&mut state.damage, &mut state.removal, &mut state.pitted);
            state.pitted_phases.push(k);
            return 0.0;
        }
        if !state.pitted_phases.contains(&k) {
            let duration = end - state.cycles;
            let limit = pressure_limit
                .unwrap_or_else(|| self.life.endurance.pressure(duration) * (1.0 + margin));
            let depth = pit_depths(cw, self.life.pit_depth);
            for k in cut_pits(
                self.wf,
                &l.pattern,
                limit,
                &depth,
                &mut state.removal,
                &mut state.pitted,
            ) {
                state.damage[k] = 0.0;
            }
            state.pitted_phases.push(k);
            return 0.0;
        }
        let end = end.min(self.life.life_cycles);
        let advanced = end - state.cycles;
        state.cycles = end;
        advanced
    }

    /// Advances the state by `step_cycles` of wear at the rates of `rate_map`, in equal
    /// sub-steps with the pressures recomputed when the stability guard asks for them
    /// (MODEL §7.3). Returns the number of sub-steps.
    fn wear_step(
        &self,
        state: &mut WearState,
        mut rate_map: CycleWear,
        step_cycles: f64,
    ) -> Result<usize, WearError> {
        let mut remaining = step_cycles;
        let mut substeps = 0;
        loop {
            let rate = rate_map.depth.max();
            let cap = self.life.max_substep_removal;
            let dc = if cap > 0.0 && rate * remaining > cap * (1.0 + 1e-9) {
                // Equal sub-steps over what is left of the step.
                let n = (rate * remaining / cap).ceil();
                remaining / n
            } else {
                remaining
            };
            let removal = match (self.life.scheme, &state.node_response) {
                (StepScheme::Stabilised, Some(r)) => {
                    stabilised_removal(&rate_map.depth, self.wf, dc, r)
                }
                _ => rate_map.depth.values.iter().map(|dh| dc * dh).collect(),
            };
            for (h, dh) in state.removal.values.iter_mut().zip(&removal) {
                *h += dh;
            }
            state.cycles += dc;
            remaining -= dc;
            substeps += 1;
            if remaining <= 1e-9 * step_cycles {
                return Ok(substeps);
            }
            let a = self.analyse_state(state)?;
            carry_starts(state, &a);
            rate_map = a.cycle;
        }
    }
}

/// The bins of a life (MODEL §14) and the index of the largest load's: the gear itself without
/// a spectrum; with one, each bin's gear, its own unloaded analysis (the sliding speeds follow
/// the worm speed; the largest load's is `tca`, the gear's conditions) and settings.
fn life_bins<'a>(
    gear: &'a GearSet,
    geo: &Geometry,
    tca: &'a Tca,
    settings: &crate::ltca::LtcaSettings,
) -> Result<(Vec<LifeBin<'a>>, usize), WearError> {
    let other_losses = |g: &GearSet| {
        let rating = crate::rating::rate(g);
        rating.loss_churning_w + rating.loss_bearings_w + rating.loss_seals_w
    };
    if !gear.has_spectrum() {
        let bin = LifeBin {
            gear: Cow::Borrowed(gear),
            tca: Cow::Borrowed(tca),
            settings: *settings,
            cycle_share: 1.0,
            other_losses: other_losses(gear),
        };
        return Ok((vec![bin], 0));
    }
    let duty = gear.duty_bins();
    let shares = crate::input::cycle_shares(&duty);
    let reference = crate::input::largest_load_bin(&duty, gear.ratio());
    let mut bins = Vec::new();
    for (b, (bin, share)) in duty.iter().zip(shares).enumerate() {
        let at = gear.at_bin(bin);
        let tca = match b == reference {
            true => Cow::Borrowed(tca),
            false => Cow::Owned(
                crate::kinematics::analyse(&at, geo)
                    .map_err(|source| WearError::Bin { bin: b + 1, source })?,
            ),
        };
        bins.push(LifeBin {
            settings: crate::ltca::LtcaSettings::from_gear(&at),
            other_losses: other_losses(&at),
            gear: Cow::Owned(at),
            tca,
            cycle_share: share,
        });
    }
    Ok((bins, reference))
}

/// The cycles a phase lasts until.
fn phase_end(p: &Phase) -> f64 {
    match *p {
        Phase::Wear { until } | Phase::Pitting { until, .. } => until,
    }
}
