//! A state's record (MODEL §7.7, §12 j, §12 k): what the life loop writes down of each state
//! from its loaded analysis, friction and per-cycle wear.

use super::{LifeLoop, StateAnalysis};
use crate::friction::Thermal;
use crate::ltca::{stats, Ltca};
use crate::lubrication::FlankRoughness;
use crate::wear::forecast;
use crate::wear::spectrum::BinRecord;
use crate::wear::{pitted_fraction, CycleWear, Phase, PositionState, StepRecord, WearState};

impl LifeLoop<'_> {
    /// Adds state `state`'s record from its analysis `a` (in `phase`, after a step of
    /// (cycles, substeps) and `probes` analyses measuring the response), replacing the one a
    /// resumed run had written for it, and marks the state stopped where a wear limit is
    /// passed.
    pub(super) fn close_state(
        &self,
        state: &mut WearState,
        a: &StateAnalysis,
        phase: Option<(usize, Phase, f64)>,
        step: (f64, usize),
        probes: usize,
    ) {
        let mut record = self.record(state, (&a.ltca, &a.thermal), &a.cycle, phase, step);
        record.bins = self.bin_records(a);
        record.loaded_analyses += probes;
        record.area_damage = forecast::area_damage_after(
            state.records.iter().rev().find(|r| r.step < state.step),
            record.cycles,
            &self.life.endurance,
        );
        // A resumed run recomputes the state it stopped at: keep one record per step.
        state.records.retain(|r| r.step < state.step);
        state.stopped = self.limits.passed(&record);
        state.records.push(record);
    }

    /// What a record keeps of each bin of a spectrum (empty without one).
    fn bin_records(&self, a: &StateAnalysis) -> Vec<BinRecord> {
        a.bins
            .iter()
            .zip(&self.bins)
            .map(|(x, b)| BinRecord::of(b.cycle_share, &x.ltca, &x.cycle, self.wf, &x.thermal))
            .collect()
    }

    /// The rigid lag the flank change adds at each position (rad, MODEL §12 j), from the
    /// backlash per position on the changed flank, and each position's TE, TE relative to that
    /// lag, tooth loads and largest pressure.
    fn position_states(&self, l: &Ltca, per_position: &[f64]) -> (Vec<f64>, Vec<PositionState>) {
        let lag: Vec<f64> = per_position
            .iter()
            .zip(&self.initial_backlash)
            .map(|(b, b0)| b - b0)
            .collect();
        let positions: Vec<PositionState> = l
            .positions
            .iter()
            .map(|p| PositionState {
                te_rad: p.transmission_error,
                te_relative_rad: p.transmission_error + lag[p.position],
                // The worn flank's: the unworn KE (TE + approach) less the wear's rigid lag.
                kinematic_error_rad: Some(p.transmission_error + p.approach - lag[p.position]),
                tooth_load_n: p.tooth_load.clone(),
                max_pressure_pa: p.max_pressure,
            })
            .collect();
        (lag, positions)
    }

    /// The record of a state (MODEL §7.7, §12 j, §12 k) from its loaded analysis and friction.
    fn record(
        &self,
        state: &WearState,
        (l, thermal): (&Ltca, &Thermal),
        cw: &CycleWear,
        phase: Option<(usize, Phase, f64)>,
        (step_cycles, substeps): (f64, usize),
    ) -> StepRecord {
        let wf = self.wf;
        let change = state.flank_change();
        let per_position = self.backlash.per_position(&change);
        let (lag, positions) = self.position_states(l, &per_position);
        let b = self.backlash.stats_of(&per_position);
        let (te_mean, te_p2p) = l.te_stats();
        let (te_rel_mean, te_rel_p2p) = stats(positions.iter().map(|p| p.te_relative_rad));
        let lambdas = cw.lambda.values.iter().copied().filter(|v| v.is_finite());
        let volume = state.removal.integral(wf);
        let worst_node = argmax(&state.removal.values).map(|k| &wf.nodes[k]);
        let worst_cell = argmax(&l.pattern).map(|k| &wf.cells[k]);
        let patch = (self.settings.patch_across, self.settings.patch_along);
        let roughness = self.roughness_over_active(l);
        StepRecord {
            step: state.step,
            cycles: state.cycles,
            step_cycles,
            substeps,
            phase: phase_name(phase),
            pitted_area_fraction: pitted_fraction(wf, &state.pitted),
            max_wear_m: state.removal.max(),
            max_wear_r_m: worst_node.map_or(f64::NAN, |n| n.r),
            max_wear_z_m: worst_node.map_or(f64::NAN, |n| n.z),
            wear_patch_max_m: state.removal.patch_mean_max(wf, patch.0, patch.1),
            mean_wear_m: volume / self.active_area,
            worn_volume_m3: volume,
            backlash_m: b.linear_mean_m,
            backlash_increase_m: b.linear_mean_m - self.initial_backlash_linear(),
            backlash_min_rad: b.min_rad,
            backlash_max_rad: b.max_rad,
            max_pressure_pa: l.max_pressure,
            max_pressure_r_m: worst_cell.map_or(f64::NAN, |c| c.r),
            max_pressure_z_m: worst_cell.map_or(f64::NAN, |c| c.z),
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
            pressure_patch_max_pa: l.pressure_patch_max,
            rigid_lag_rad: lag.iter().sum::<f64>() / lag.len().max(1) as f64,
            te_mean_relative_rad: te_rel_mean,
            te_p2p_relative_rad: te_rel_p2p,
            n_li_model_cycles: self.model_first_pitting(l),
            loaded_analyses: state.loaded_analyses_before() + substeps.max(1) * self.bins.len(),
            thinnest_tooth_m: self.limits.thinnest(&state.removal).0,
            worn_through_loaded: self
                .limits
                .worn_through_loaded(&state.removal, &l.pattern, wf)
                .is_some(),
            power_balance: l.power_balance,
            max_damage: state.damage.iter().copied().fold(0.0, f64::max),
            max_plastic_set_m: state.plastic_set_after(l).max(),
            max_plastic_indentation_m: l.plastic_indentation.max(),
            yielded_area_fraction: l.yielded_area_fraction,
            band_edge_share: l.band_edge_share_warned(),
            tip_edge_resolution: l.tip_edge_resolution,
            equivalent_pressure_max_pa: l.equivalent_pattern.iter().copied().fold(0.0, f64::max),
            equivalent_pressure_first_pitting_pa: l.equivalent_pressure_first_pitting,
            first_pitting_edge_share: l.first_pitting_places.edge_share(),
            area_damage: 0.0,
            roughness_mean_m: roughness.0,
            roughness_min_m: roughness.1,
            friction: crate::wear::StateFriction::of(thermal),
            positions,
            bins: Vec::new(),
        }
    }

    /// Rank's cycles to first pitting with the loaded pattern's mean pressure (MODEL §12 k).
    fn model_first_pitting(&self, l: &Ltca) -> Option<f64> {
        crate::rating::rank_first_pitting_cycles(
            self.sliding_speed,
            l.mean_pressure * 1e-6,
            self.pitting_limit * 1e-6,
        )
    }

    /// The composite roughness over the active flank of analysis `l` (MODEL §6.1): mean and
    /// smallest, m.
    fn roughness_over_active(&self, l: &Ltca) -> (f64, f64) {
        let lubricant = &self.bins[0].gear.lubricant;
        FlankRoughness::of(lubricant, l.roughness.as_ref(), self.wf).over_active(self.wf)
    }

    /// The unworn backlash, mean over the positions, as a length at the reference radius, m.
    fn initial_backlash_linear(&self) -> f64 {
        self.initial_backlash.iter().sum::<f64>() / self.initial_backlash.len().max(1) as f64
            * self.backlash.reference_radius
    }
}

/// The name of a state's phase in its record: "pitting" or "wear".
fn phase_name(phase: Option<(usize, Phase, f64)>) -> String {
    match phase {
        Some((_, Phase::Pitting { .. }, _)) => "pitting".into(),
        _ => "wear".into(),
    }
}

/// Index of the largest value (None when empty or all NaN).
fn argmax(values: &[f64]) -> Option<usize> {
    values
        .iter()
        .enumerate()
        .filter(|(_, v)| v.is_finite())
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map(|(k, _)| k)
}
