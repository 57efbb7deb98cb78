//! The state of a life after a completed step (MODEL §7.3): the flank's removal and plastic set,
//! the pits and the records of every state, what a checkpoint holds; the warnings an engineer must
//! see at its end; pits cut into the flank (MODEL §8).

use super::{cycles_label, forecast, CycleWear, Phase};
use crate::geometry::{FlankField, WheelFlank};
use crate::input::{Endurance, PitDepth};
use crate::ltca::Ltca;

/// State of a life run after a completed step: what a checkpoint holds.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WearState {
    /// Completed wear steps.
    pub step: usize,
    /// Wheel cycles run.
    pub cycles: f64,
    /// Depth worn off the loaded flank so far, normal to it, m.
    pub removal: FlankField,
    /// Plastic set of the loaded flank so far (running-in, MODEL §5.7): the permanent
    /// indentation where the contact reached the flow pressure, normal to the flank, m
    /// (empty: none yet).
    #[serde(default)]
    pub plastic_set: FlankField,
    /// Records of the states so far (the initial one and one per completed step).
    pub records: Vec<StepRecord>,
    /// Pitting phases (indices in the schedule) whose pits have been cut.
    #[serde(default)]
    pub pitted_phases: Vec<usize>,
    /// Pitted nodes of the loaded flank (empty: none).
    #[serde(default)]
    pub pitted: Vec<bool>,
    /// Band factor of the local contact meshes for this state's loaded analysis, reached by
    /// the widenings so far (None: the settings' own).
    #[serde(default)]
    pub band_factor: Option<f64>,
    /// Loads the solver of this state's loaded analysis starts from (the previous analysis';
    /// None: a cold start). Kept with the state so a resumed run repeats the analysis exactly.
    #[serde(default)]
    pub warm: Option<crate::ltca::WarmStart>,
    /// Why the life ended before its cycles: the wear limit passed
    /// ([`super::WearLimits::passed`]).
    #[serde(default)]
    pub stopped: Option<String>,
    /// Fatigue damage of every node of the loaded flank ([`forecast`]; empty: none yet).
    #[serde(default)]
    pub damage: Vec<f64>,
    /// The schedule a pitting forecast has found so far (empty without a forecast).
    #[serde(default)]
    pub found_phases: Vec<Phase>,
    /// Where each duty-cycle bin's loaded analysis starts (MODEL §14; empty without a
    /// spectrum, whose one analysis starts from `band_factor` and `warm`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub bin_starts: Vec<super::spectrum::BinStart>,
    /// The wear's measured response to a node-scale removal, on the life's first state (the
    /// stabilised step's, `super::stabilised`; None: not measured, the explicit step).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub node_response: Option<super::NodeResponse>,
    /// The wear per cycle's measures where the last wear step started (the error control's,
    /// `super::stabilised`; None: no wear step yet, or the last step a pitting phase's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rates_before: Option<super::RateMeasures>,
}

impl WearState {
    /// The last record before this state's step: the previous state's. (A resumed life
    /// recomputes the state its checkpoint holds, whose own record is then already there.)
    pub(crate) fn previous_record(&self) -> Option<&StepRecord> {
        self.records.iter().rev().find(|r| r.step < self.step)
    }

    /// The loaded analyses counted up to the last record before this state's step.
    pub(crate) fn loaded_analyses_before(&self) -> usize {
        self.previous_record().map_or(0, |r| r.loaded_analyses)
    }

    /// Unworn start.
    pub fn new(wf: &WheelFlank) -> Self {
        Self {
            damage: vec![0.0; wf.nodes.len()],
            ..Self::flank_at(0, 0.0, FlankField::zeros(wf), FlankField::zeros(wf))
        }
    }

    /// A state that holds only its worn flank (`removal` and `plastic_set`, m) after `step`
    /// steps and `cycles` wheel cycles: no records, pits, damage or warm start (what the worn
    /// wheel of a map state is built from).
    pub fn flank_at(
        step: usize,
        cycles: f64,
        removal: FlankField,
        plastic_set: FlankField,
    ) -> Self {
        Self {
            step,
            cycles,
            removal,
            plastic_set,
            records: Vec::new(),
            pitted_phases: Vec::new(),
            pitted: Vec::new(),
            band_factor: None,
            warm: None,
            stopped: None,
            damage: Vec::new(),
            found_phases: Vec::new(),
            bin_starts: Vec::new(),
            node_response: None,
            rates_before: None,
        }
    }

    /// The loaded flank's change so far on the grid's nodes, normal to it, m: the wear and the
    /// plastic set (MODEL §7.5, §5.7), what the backlash sees.
    pub fn flank_change(&self) -> FlankField {
        let mut change = self.removal.clone();
        let set = self.plastic_set.with_rows(change.cells_height);
        for (h, s) in change.values.iter_mut().zip(&set.values) {
            *h += s;
        }
        change
    }

    /// The plastic set once the loaded analysis `l` of this state's flank has run in
    /// (MODEL §5.7): the set plus the analysis' plastic indentation, m, on the rows of the
    /// indentation (finer than the grid's, [`crate::ltca::Ltca::plastic_indentation`]).
    pub fn plastic_set_after(&self, l: &Ltca) -> FlankField {
        let add = &l.plastic_indentation;
        let mut set = self.plastic_set.with_rows(add.cells_height);
        if set.values.len() != add.values.len() {
            return add.clone();
        }
        for (s, d) in set.values.iter_mut().zip(&add.values) {
            *s += d;
        }
        set
    }

    /// [`Self::plastic_set_after`] on the grid's nodes, m.
    pub fn plastic_set_nodes_after(&self, l: &Ltca) -> FlankField {
        self.plastic_set_after(l)
            .with_rows(self.removal.cells_height)
    }

    /// Running-in (MODEL §5.7): the plastic indentation of a loaded analysis on this state's
    /// flank becomes part of its plastic set.
    pub fn run_in(&mut self, l: &Ltca) {
        self.plastic_set = self.plastic_set_after(l);
    }
}

/// The gear's state at some cycles: wear so far and the loaded analysis on that geometry
/// (units in the names; MODEL §7.7).
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StepRecord {
    /// Completed steps (0: the unworn gear).
    pub step: usize,
    pub cycles: f64,
    /// Cycles of the step that led here (0 for the start).
    pub step_cycles: f64,
    /// Sub-steps that step was split into by the stability guard (1: not split).
    pub substeps: usize,
    /// Phase of the schedule at these cycles: "wear" or "pitting".
    pub phase: String,
    /// Share of the active flank area pitted so far (pits cut at the starts of pitting
    /// phases).
    pub pitted_area_fraction: f64,
    /// Largest depth worn, m, and where on the flank (node radius and face position), m.
    pub max_wear_m: f64,
    #[serde(default)]
    pub max_wear_r_m: f64,
    #[serde(default)]
    pub max_wear_z_m: f64,
    /// Largest mean wear depth over a patch of the pressure patch's size (`[analysis]
    /// pressure_patch_*`, default 0.5 mm along the profile by 1 mm along the face), m: the
    /// peak wear that converges with the mesh (`max_wear_m`, one node, follows a band
    /// narrower than a grid row at the worm-tip trace; [`FlankField::patch_mean_max`]).
    #[serde(default)]
    pub wear_patch_max_m: f64,
    /// Worn volume / active flank area (mean depth over the flank), m.
    pub mean_wear_m: f64,
    /// Worn volume of one tooth flank, m^3.
    pub worn_volume_m3: f64,
    /// Tangential backlash at r2, mean over positions, m; and its increase since the start.
    pub backlash_m: f64,
    pub backlash_increase_m: f64,
    pub backlash_min_rad: f64,
    pub backlash_max_rad: f64,
    /// Largest pressure of the loaded pattern and the centre of its cell, m.
    pub max_pressure_pa: f64,
    #[serde(default)]
    pub max_pressure_r_m: f64,
    #[serde(default)]
    pub max_pressure_z_m: f64,
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
    /// Largest mean pressure over a patch of stated size (`[analysis] pressure_patch_*`,
    /// default 0.5 mm across the line by 1 mm along the face), Pa: unlike the maximum
    /// (`max_pressure_pa`, one cell, grows with refinement at a sharp edge) it converges with
    /// the mesh.
    #[serde(default)]
    pub pressure_patch_max_pa: f64,
    /// Rigid lag that the wear adds, mean over positions: the growth of the loaded flank's
    /// smallest angular gap (the worn flank's kinematic lag, part of the backlash), rad
    /// (MODEL §12 j).
    #[serde(default)]
    pub rigid_lag_rad: f64,
    /// Loaded TE relative to the rigid lag (TE + lag at each position): mean and
    /// peak-to-peak, rad.
    #[serde(default)]
    pub te_mean_relative_rad: f64,
    #[serde(default)]
    pub te_p2p_relative_rad: f64,
    /// Rank's cycles to first pitting N_LI with the model's mean pressure of the loaded
    /// pattern in place of sigma_Hm (MODEL §12 k); None where the formula is out of range.
    #[serde(default)]
    pub n_li_model_cycles: Option<f64>,
    /// Loaded analyses run so far (this state's included): a step split by the stability
    /// guard costs one per sub-step (MODEL §7.3: the geometry is frozen within one), one per
    /// bin of a duty cycle (MODEL §14).
    #[serde(default)]
    pub loaded_analyses: usize,
    /// Thinnest wheel tooth left anywhere on the flank (the normal wear depth that would go
    /// through it; negative: worn through), m ([`super::WearLimits::thinnest`]).
    #[serde(default)]
    pub thinnest_tooth_m: f64,
    /// Whether a node of this state's loaded pattern is worn through
    /// ([`super::WearLimits::worn_through_loaded`]).
    #[serde(default)]
    pub worn_through_loaded: bool,
    /// Power balance of this state's loaded analysis (`Ltca::power_balance`, MODEL §5.2).
    #[serde(default)]
    pub power_balance: f64,
    /// Largest fatigue damage of the loaded flank's nodes (1: a node's life on the
    /// pressure-life curve is spent; [`forecast`]).
    #[serde(default)]
    pub max_damage: f64,
    /// Largest plastic set of the flank once this state's analysis has run in (MODEL §5.7),
    /// m, and the largest indentation this state's analysis added, m.
    #[serde(default)]
    pub max_plastic_set_m: f64,
    #[serde(default)]
    pub max_plastic_indentation_m: f64,
    /// Share of the active flank area where this state's contact reached the flow pressure.
    #[serde(default)]
    pub yielded_area_fraction: f64,
    /// The largest share of a position's load on its local band's edge cells once the band
    /// stopped growing, where above [`crate::ltca::BAND_EDGE_WARNING`] (the contact cut by the
    /// local mesh, MODEL §5.1); None: every position's band held its contact.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub band_edge_share: Option<f64>,
    /// The worm's broken tip edge against the contact cells where this state's analysis does
    /// not resolve its contact (`Ltca::tip_edge_resolution`, MODEL §2.3, §5.1); None: a sharp
    /// tip, or a round the cells resolve.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tip_edge_resolution: Option<crate::ltca::TipEdgeResolution>,
    /// Largest equivalent pressure below the flank over the pattern (MODEL §8.1), Pa (0 in
    /// records of earlier versions).
    #[serde(default)]
    pub equivalent_pressure_max_pa: f64,
    /// The equivalent pressure exceeded on 2 % of the active flank, p_eq,2% (MODEL §8.1: the
    /// area of first pitting, A_p10, which S_H reads), Pa (0 in records of earlier versions).
    #[serde(default)]
    pub equivalent_pressure_first_pitting_pa: f64,
    /// The edges' part of the flank at or above that p_eq,2% (the worm tip's trace, the face
    /// ends, the blank top; `Ltca::first_pitting_places`), 0-1 (0 in records of earlier
    /// versions).
    #[serde(default)]
    pub first_pitting_edge_share: f64,
    /// The area reading of first pitting (MODEL §8.1): the Miner sum over the wear steps so far
    /// of each step's cycles over the life of p_eq,2% (of the state that starts it, each bin's
    /// at its cycle share with a duty cycle) on the pressure–life curve; 1 is first pitting on
    /// 2 % of the flank. Held over pitting phases, as the nodes' damage is (0 in records of
    /// earlier versions).
    #[serde(default)]
    pub area_damage: f64,
    /// Composite roughness R_q over the active flank once this state's wear has run it in
    /// (MODEL §6.1): area-weighted mean and smallest, m (the lubricant's without running-in;
    /// 0 in records of earlier versions).
    #[serde(default)]
    pub roughness_mean_m: f64,
    #[serde(default)]
    pub roughness_min_m: f64,
    /// Friction of this state's contact (MODEL §13; zeros in records of earlier versions).
    #[serde(flatten, default)]
    pub friction: StateFriction,
    /// Per position: TE, TE relative to the rigid lag, load per tooth (not in summary.json;
    /// `wear_positions.csv`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub positions: Vec<PositionState>,
    /// Each duty-cycle bin's figures in this state (MODEL §14; empty without a spectrum, whose
    /// record's figures are its one analysis'). With a spectrum the record's loaded-analysis
    /// figures are the bin of the largest load's, its wear and damage the spectrum's.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub bins: Vec<super::spectrum::BinRecord>,
}

/// Friction of a state's contact (MODEL §13): load-weighted mean coefficient, mesh loss P_Vz
/// (W), mesh and total efficiency, oil temperature (K) and its viscosity (Pa s) — the
/// lubricant's with a fixed temperature, the heat balance's otherwise.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StateFriction {
    #[serde(default)]
    pub friction_coefficient_mean: f64,
    #[serde(default)]
    pub mesh_loss_w: f64,
    #[serde(default)]
    pub mesh_efficiency: f64,
    #[serde(default)]
    pub total_efficiency: f64,
    #[serde(default)]
    pub oil_temperature_k: f64,
    #[serde(default)]
    pub viscosity_pa_s: f64,
}

impl StateFriction {
    /// The figures of a heat balance's result.
    pub fn of(thermal: &crate::friction::Thermal) -> Self {
        Self {
            friction_coefficient_mean: thermal.friction.mean_coefficient,
            mesh_loss_w: thermal.friction.mesh_loss_w,
            mesh_efficiency: thermal.efficiency.mesh_efficiency,
            total_efficiency: thermal.efficiency.total_efficiency,
            oil_temperature_k: thermal.oil_temperature_k,
            viscosity_pa_s: thermal.viscosity_pa_s,
        }
    }
}

impl StepRecord {
    /// The mesh orders of this state's loaded TE and unloaded kinematic error (MODEL §16), from
    /// its positions; the unloaded ones empty where a checkpoint written before they were
    /// recorded left them out.
    pub fn te_orders(&self) -> crate::ltca::TeOrders {
        let loaded: Vec<f64> = self.positions.iter().map(|p| p.te_rad).collect();
        let unloaded: Option<Vec<f64>> = self
            .positions
            .iter()
            .map(|p| p.kinematic_error_rad)
            .collect();
        match unloaded {
            Some(unloaded) => crate::ltca::TeOrders::of(&loaded, &unloaded),
            None => crate::ltca::TeOrders {
                loaded_rad: crate::ltca::mesh_order_amplitudes(&loaded),
                unloaded_rad: Vec::new(),
            },
        }
    }
}

/// One position of a state's loaded analysis (MODEL §7.7: load sharing and TE over life).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PositionState {
    /// Loaded transmission error, rad (negative = lag).
    pub te_rad: f64,
    /// TE + the rigid lag of the wear at this position, rad.
    pub te_relative_rad: f64,
    /// Unloaded kinematic error of the state's worn flank (the unworn one's, TE plus the rigid
    /// approach, less the wear's rigid lag), rad; None in a checkpoint written before it was
    /// recorded.
    #[serde(default)]
    pub kinematic_error_rad: Option<f64>,
    /// Normal force per studied tooth (TCA tooth order), N.
    pub tooth_load_n: Vec<f64>,
    pub max_pressure_pa: f64,
}

/// The share of the area reading's Miner sum from beyond the pressure–life curve's data above
/// which a life warns ([`WearState::warnings`]).
pub const EXTRAPOLATED_SHARE: f64 = 0.01;

impl WearState {
    /// What an engineer must see about this life at its last state (summary.json, stderr, the
    /// top of report.html): why it stopped early, loaded analyses off the power balance,
    /// contact on worn-through teeth, flank nodes whose fatigue damage has reached 1 (read as
    /// first pitting where they make up the `onset` share of the active flank, the plan's
    /// `pitting_onset_share`; MODEL §8.1), the area reading's Miner sum where it rests on the
    /// pressure–life curve `curve` beyond its data (MODEL §8), and pressures at the flow
    /// pressure (MODEL §5.7).
    pub fn warnings(&self, wf: &WheelFlank, onset: f64, curve: &Endurance) -> Vec<String> {
        let mut w = Vec::new();
        if let Some(why) = &self.stopped {
            w.push(format!("wear limit: {why}"));
        }
        let balance = self
            .records
            .iter()
            .find(|r| r.power_balance.abs() > crate::ltca::POWER_BALANCE_LIMIT);
        if let Some(r) = balance {
            w.push(format!(
                "wear: from {} cycles the loaded analyses depart from the power \
                 balance by {:+.1} % (more than {} %): the load sits at non-conjugate points (the \
                 wheel's face edge under a misalignment) and the model's torques, TE and wear \
                 there are unreliable (power_balance in wear_steps.csv)",
                cycles_label(r.cycles),
                100.0 * r.power_balance,
                100.0 * crate::ltca::POWER_BALANCE_LIMIT
            ));
        }
        if let Some(r) = self.records.iter().find(|r| r.worn_through_loaded) {
            w.push(format!(
                "wear: from {} cycles the loaded pattern reaches flank nodes whose tooth is worn \
                 through (contact computed on material that is gone; see wear.limits)",
                cycles_label(r.cycles)
            ));
        }
        if let Some(r) = self.records.iter().find(|r| r.band_edge_share.is_some()) {
            let worst = self
                .records
                .iter()
                .filter_map(|r| r.band_edge_share)
                .fold(0.0, f64::max);
            w.push(format!(
                "contact: from {} cycles some position's contact still reaches the local band's \
                 edge after the band grew as far as it may (MODEL §5.1; at most {:.1} % of a \
                 position's load on the edge cells): the contact there is cut by the local mesh; \
                 a wider analysis.contact_band_factor holds it",
                cycles_label(r.cycles),
                100.0 * worst
            ));
        }
        w.extend(self.tip_edge_warning());
        w.extend(self.damage_warning(wf, onset, curve));
        w.extend(self.area_extrapolation_warning(curve));
        w.extend(self.edge_reading_warning());
        if let Some(r) = self
            .records
            .last()
            .filter(|r| r.yielded_area_fraction > 0.0)
        {
            w.push(format!(
                "contact: at {} cycles {:.2} % of the active flank reaches the flow pressure (MODEL \
                 §5.7): \
                 the pressures there are the bronze's plastic limit, and the flank takes a \
                 plastic set",
                cycles_label(r.cycles),
                100.0 * r.yielded_area_fraction
            ));
        }
        w
    }

    /// The warning on the worm's broken tip edge where the life's analyses did not resolve its
    /// contact (MODEL §2.3, §5.1; [`crate::ltca::TipEdgeResolution`]): from which cycles, in
    /// how many states, and the state where the cells were widest against the round's width.
    fn tip_edge_warning(&self) -> Option<String> {
        let unresolved: Vec<(f64, crate::ltca::TipEdgeResolution)> = self
            .records
            .iter()
            .filter_map(|r| r.tip_edge_resolution.map(|t| (r.cycles, t)))
            .collect();
        let first = unresolved.first()?.0;
        let ratio = |t: &crate::ltca::TipEdgeResolution| t.cell_width_m / t.contact_width_m;
        let (worst_cycles, worst) = unresolved
            .iter()
            .max_by(|a, b| ratio(&a.1).total_cmp(&ratio(&b.1)))?;
        Some(format!(
            "contact: from {} cycles, in {} of the life's {} states, {} (the worst state, at {} \
             cycles)",
            cycles_label(first),
            unresolved.len(),
            self.records.len(),
            worst.text(),
            cycles_label(*worst_cycles)
        ))
    }

    /// The states whose p_eq,2% lay mostly on the flank's edges (more than
    /// [`crate::ltca::EDGE_READING_SHARE`] of the flank at or above it at the worm tip's trace,
    /// the face ends or the blank top; MODEL §8.1): how many, from which cycles, and the
    /// largest share.
    fn edge_reading_warning(&self) -> Option<String> {
        let on_edges: Vec<&StepRecord> = self
            .records
            .iter()
            .filter(|r| r.first_pitting_edge_share > crate::ltca::EDGE_READING_SHARE)
            .collect();
        let first = on_edges.first()?;
        let most = on_edges.iter().max_by(|a, b| {
            a.first_pitting_edge_share
                .total_cmp(&b.first_pitting_edge_share)
        })?;
        Some(format!(
            "pitting: in {} of the life's {} states, from {} cycles, p_eq,2% lay on the flank's \
             edges: more than half of the flank at or above it at the worm tip's trace, the face \
             ends or the blank top (up to {:.0} %, at {} cycles; first_pitting_edge_share); the \
             area reading (area_damage, area_first_pitting_cycles) then reads the edges, which \
             follow their shape and the contact cells across the line more than the flank's \
             load (VALIDATION.md, sessions 60-61)",
            on_edges.len(),
            self.records.len(),
            cycles_label(first.cycles),
            100.0 * most.first_pitting_edge_share,
            cycles_label(most.cycles)
        ))
    }

    /// The area reading's Miner sum (MODEL §8.1) where more than [`EXTRAPOLATED_SHARE`] of it,
    /// at first pitting or at the last state, comes from states whose p_eq,2% lies above the
    /// pressure–life curve's data ([`forecast::area_damage_beyond_data`]): that part of
    /// `area_damage` and of `area_first_pitting_cycles` extrapolates the curve (MODEL §8).
    fn area_extrapolation_warning(&self, curve: &Endurance) -> Option<String> {
        let last = self.records.last()?;
        let first_pitting = forecast::area_first_pitting_cycles(&self.records, curve);
        let until = first_pitting.unwrap_or(last.cycles);
        let e = forecast::area_damage_beyond_data(&self.records, curve, until);
        if e.share() <= EXTRAPOLATED_SHARE {
            return None;
        }
        let at = match first_pitting {
            Some(c) => format!("at first pitting, {} cycles", cycles_label(c)),
            None => format!("at {} cycles", cycles_label(until)),
        };
        let shortest = curve.data_span().0;
        Some(format!(
            "pitting: {:.0} % of the area reading's Miner sum ({:.3} {at}) comes from states \
             whose p_eq,2% lies above the pressure–life curve's data (from {} cycles, up to {:.0} \
             MPa, against {:.0} MPa at its shortest tested life, {} cycles; MODEL §8): that part \
             of area_damage and area_first_pitting_cycles extrapolates the curve",
            100.0 * e.share(),
            e.damage,
            cycles_label(e.first_cycles.unwrap_or(0.0)),
            e.highest_pa * 1e-6,
            curve.pressure(shortest) * 1e-6,
            cycles_label(shortest)
        ))
    }

    /// Flank nodes whose fatigue damage has reached 1 at the last state (MODEL §8.1): how
    /// many, their share of the active flank, the largest damage, read as first pitting only
    /// where they make up the `onset` share of the flank (2 %, A_p10, "Which p_eq decides";
    /// a forecast's `pitting_onset_percent`); fewer are local damage (an edge's), said as
    /// such. The share is the nodes' own areas ([`forecast::node_shares`]), as a forecast's
    /// onset counts them: the cells touching a damaged node would count a strip of nodes
    /// about twice.
    fn damage_warning(&self, wf: &WheelFlank, onset: f64, curve: &Endurance) -> Option<String> {
        let due: Vec<usize> = (0..self.damage.len())
            .filter(|&k| self.damage[k] >= forecast::REACHED)
            .collect();
        if due.is_empty() || self.damage.len() != wf.nodes.len() {
            return None;
        }
        let largest = due.iter().map(|&k| self.damage[k]).fold(0.0, f64::max);
        let shares = forecast::node_shares(wf);
        let share: f64 = due.iter().map(|&k| shares[k]).sum();
        let first = match (onset - crate::pitting::FIRST_PITTING_SHARE).abs() < 1e-12 {
            true => "2 % of the flank, A_p10".to_string(),
            false => format!(
                "{:.2} % of the flank, wear.pitting_onset_percent",
                100.0 * onset
            ),
        };
        let reading = match share >= onset {
            true => format!("first pitting ({first}, or more): the model expects pits there"),
            false => format!(
                "less than first pitting ({first}): local damage, such as at an edge, not yet \
                 first pitting"
            ),
        };
        Some(format!(
            "pitting: {} flank nodes (about {:.2} % of the active flank) have reached a fatigue \
             damage of 1 at {} cycles (largest {:.3}): {reading} (damage map; MODEL §8.1){}",
            due.len(),
            100.0 * share,
            cycles_label(self.cycles),
            largest,
            self.beyond_data_note(curve)
        ))
    }

    /// Where some state's largest equivalent pressure lies above the pressure–life curve's
    /// data (MODEL §8), the damage warning's note that the damage there extrapolates it: the
    /// life's largest p_eq and its cycles against the highest tested pressure; empty where
    /// every state stays within the data.
    fn beyond_data_note(&self, curve: &Endurance) -> String {
        let tested = curve.pressure(curve.data_span().0);
        let worst = self.records.iter().max_by(|a, b| {
            a.equivalent_pressure_max_pa
                .total_cmp(&b.equivalent_pressure_max_pa)
        });
        match worst.filter(|r| r.equivalent_pressure_max_pa > tested) {
            Some(r) => format!(
                "; the damage of nodes loaded above {:.0} MPa, the curve's highest tested \
                 pressure, extrapolates it (the life's largest p_eq {:.0} MPa, at {} cycles)",
                tested * 1e-6,
                r.equivalent_pressure_max_pa * 1e-6,
                cycles_label(r.cycles)
            ),
            None => String::new(),
        }
    }
}

/// Depth of the pits at every node (MODEL §8, §12 g): 0.78 a, a the local Hertz half-width
/// (published) or the loaded band's half-width (refinement), m.
pub fn pit_depths(cw: &CycleWear, rule: PitDepth) -> FlankField {
    let half_width = match rule {
        PitDepth::Hertz => &cw.hertz_half_width,
        PitDepth::LoadedBand => &cw.half_width,
    };
    FlankField {
        values: half_width.values.iter().map(|a| 0.78 * a).collect(),
        ..half_width.clone()
    }
}

/// Share of the active flank the pitted nodes stand for: each node a quarter of each grid cell
/// around it, the area the forecast's onset counts ([`forecast::node_shares`]; MODEL §8.1).
pub(super) fn pitted_fraction(wf: &WheelFlank, pitted: &[bool]) -> f64 {
    forecast::node_shares(wf)
        .iter()
        .zip(pitted)
        .filter(|(_, &p)| p)
        .map(|(share, _)| share)
        .sum()
}

/// Cuts the pits of a pitting phase (MODEL §8): every node whose loaded-pattern pressure (the
/// largest of its cells) exceeds `limit` (Pa) and that the contact passes (depth > 0) loses
/// `depth` more (m; [`pit_depths`]: 0.78 a, the depth of the largest shear stress under a
/// line contact). Returns the nodes cut.
pub fn cut_pits(
    wf: &WheelFlank,
    pattern: &[f64],
    limit: f64,
    depth: &FlankField,
    removal: &mut FlankField,
    pitted: &mut [bool],
) -> Vec<usize> {
    let mut cut = Vec::new();
    for (k, pit) in pitted.iter_mut().enumerate() {
        if node_pattern_pressure(wf, pattern, k) > limit && depth.values[k] > 0.0 {
            removal.values[k] += depth.values[k];
            *pit = true;
            cut.push(k);
        }
    }
    cut
}

/// The (up to four) cells of the flank grid around node k, as indices of a cell pattern.
pub(super) fn node_cells(wf: &WheelFlank, k: usize) -> impl Iterator<Item = usize> {
    let (ni, nj) = (wf.cells_height, wf.cells_face);
    let (i, j) = (k % (ni + 1), k / (ni + 1));
    [
        (i, j),
        (i.wrapping_sub(1), j),
        (i, j.wrapping_sub(1)),
        (i.wrapping_sub(1), j.wrapping_sub(1)),
    ]
    .into_iter()
    .filter(move |&(ci, cj)| ci < ni && cj < nj)
    .map(move |(ci, cj)| cj * ni + ci)
}

/// Loaded-pattern pressure at node k of the flank grid: the largest of the (up to four)
/// cells around it, Pa.
pub(super) fn node_pattern_pressure(wf: &WheelFlank, pattern: &[f64], k: usize) -> f64 {
    node_cells(wf, k).map(|c| pattern[c]).fold(0.0, f64::max)
}
