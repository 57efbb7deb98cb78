//! Files of a life run, written after every completed state so an interruption loses nothing:
//! the records `wear_records.jsonl` (one JSON line per state, appended) and the checkpoint
//! `wear_checkpoint.json` (the worn flank and how many records belong to it: resume), both at
//! every state; `wear_steps.csv`, the `wear` section of summary.json and curves over cycles
//! (wear, backlash, TE, pressure) and `wear_positions.csv` (TE and load sharing per state and
//! position) when asked (the CLI: every two seconds); maps of the cumulative wear, of the wear
//! per cycle, of the film thickness and ratio, the loaded pattern and the node table at the map
//! states (`[wear] map_cycles`, default 0, 1, 2, 4, 8, ...: files `*_step{N}`) and, without
//! the suffix, the latest of them and the last; `wheel_flank_wear.vtp` with them; the worn
//! flank of each map state, sealed (`wear_flank_step{N}.json`: a resumed life's `--step-state`).
//!
//! Rooms: `resume` reading back and checking a checkpoint and its records, `tables` the CSV
//! tables and summary values, `maps` the map states' files; here the checkpoint and summary
//! shapes, and the writer that calls them after every state.

mod maps;
mod resume;
mod tables;

use maps::*;
pub use resume::*;
pub use tables::*;

use super::tca::{flank_outline, tip_trace_series, wheel_flank_map};
use super::{update_summary, write_atomic, Csv, OutputError};
use crate::geometry::{FlankField, Geometry};
use crate::input::{GearSet, WearPlan};
use crate::kinematics::Tca;
use crate::plot::{line_chart, Series};
use crate::wear::{StepView, WearState};
use std::path::{Path, PathBuf};

const UM: f64 = 1e6;
const MPA: f64 = 1e-6;

/// Name of the checkpoint file in the output directory.
pub const CHECKPOINT: &str = "wear_checkpoint.json";
/// Name of the records file (JSON lines) in the output directory.
pub const RECORDS: &str = "wear_records.jsonl";

/// One state's mesh orders of the TE (MODEL §16) in summary.json: its step, cycles and the
/// amplitudes, rad.
#[derive(Debug, Clone, serde::Serialize)]
pub struct StateTeOrders {
    pub step: usize,
    pub cycles: f64,
    #[serde(flatten)]
    pub orders: crate::ltca::TeOrders,
}

/// The `wear` section of summary.json.
#[derive(Debug, Clone, serde::Serialize)]
pub struct WearSummary<'a> {
    pub life_cycles: f64,
    pub step_control: &'a crate::input::StepControl,
    pub bending_model: &'a str,
    /// The model's choices and refinements in force (MODEL §12 g, h).
    pub film_load: crate::input::FilmLoad,
    pub pit_depth: crate::input::PitDepth,
    /// How the fatigue damage's nodes read their cells (MODEL §8.1; `max_damage` follows it).
    pub damage_node_reading: crate::input::NodeReading,
    /// States recorded (the start, one per step, one per pit cut) and loaded analyses run
    /// (a step split by the stability guard costs one per sub-step; MODEL §7.3 counts those).
    pub states: usize,
    pub loaded_analyses: usize,
    /// What `max_pressure_pa` is ([`MAX_PRESSURE_DEFINITION`]).
    pub max_pressure_definition: &'static str,
    /// The step fields that change by more than 5 % with the mesh ([`MESH_DEPENDENT`]): read
    /// them as indications; compare designs on the converged ones (backlash, mean wear,
    /// P_max, P_mean, S0).
    pub mesh_dependent: &'static [&'static str],
    /// The wear limits and where the life reached them.
    pub limits: LimitsSummary,
    /// How pitting entered the life (schedule, off, forecast with its margin).
    pub pitting: crate::input::Pitting,
    /// The phases of the life as they happened (consecutive states of one kind joined).
    pub phases: Vec<crate::wear::forecast::PhaseSpan>,
    /// The area reading of first pitting (MODEL §8.1): where the Miner sum of the states'
    /// p_eq,2% on the pressure–life curve (`area_damage` of the steps) reaches 1, cycles; null
    /// where it does not within the life. Beside the forecast's nodes (`phases`), whatever
    /// `pitting` is.
    pub area_first_pitting_cycles: Option<f64>,
    /// The schedule a forecast found (its phases with their pressure limits; run it as a
    /// `[wear] phases` schedule to repeat the life); empty without a forecast.
    pub found_phases: &'a [crate::wear::Phase],
    /// What an engineer must see about the life ([`crate::wear::WearState::warnings`]).
    pub warnings: Vec<String>,
    /// One record per state: the start and after each step (per-position curves in
    /// `wear_positions.csv`).
    pub steps: Vec<crate::wear::StepRecord>,
    /// Per state, the mesh orders of the loaded TE and of the unloaded KE (MODEL §16; also
    /// `wear_te_orders.csv`).
    pub te_orders: Vec<StateTeOrders>,
}

/// The wear limits of the life (MODEL §9 (a), (d)) and where it reached them.
#[derive(Debug, Clone, serde::Serialize)]
pub struct LimitsSummary {
    /// The limits, as flank loss and as tangential backlash increase.
    #[serde(flatten)]
    pub limits: crate::wear::WearLimits,
    /// Flank loss in the normal section at the last state (from the backlash increase), m.
    pub flank_loss_m: f64,
    /// Thinnest wheel tooth left at the last state (the normal wear depth that would go
    /// through it), m, and where (node radius and face position, m).
    pub thinnest_tooth_m: f64,
    pub thinnest_tooth_r_m: f64,
    pub thinnest_tooth_z_m: f64,
    /// Share of the loaded flank's nodes whose tooth is worn through at the last state, and
    /// the first cycles at which a worn-through node was in the loaded pattern (contact on
    /// material that is gone; null: never).
    pub worn_through_share: f64,
    pub worn_through_loaded_cycles: Option<f64>,
    /// Cycles at which each limit was reached (linear between states); null: not reached.
    pub pointed_tip_cycles: Option<f64>,
    pub backlash_limit_cycles: Option<f64>,
    /// Why the life ended before its cycles (null: it did not).
    pub stopped: Option<String>,
}

impl LimitsSummary {
    /// The limits of this plan over the records of `state`.
    pub fn new(
        gear: &GearSet,
        geo: &Geometry,
        tca: &Tca,
        plan: &WearPlan,
        state: &WearState,
    ) -> Self {
        let limits = crate::wear::WearLimits::new(gear, geo, tca, plan);
        let (thinnest, k) = limits.thinnest(&state.removal);
        let node = &geo.wheel_flank(tca.loaded_flank).nodes[k];
        let reached = |limit| crate::wear::WearLimits::cycles_reached(&state.records, limit);
        Self {
            flank_loss_m: state.records.last().map_or(0.0, |r| {
                r.backlash_increase_m * limits.flank_loss_per_backlash
            }),
            thinnest_tooth_m: thinnest,
            thinnest_tooth_r_m: node.r,
            thinnest_tooth_z_m: node.z,
            worn_through_share: limits.worn_through_share(&state.removal),
            worn_through_loaded_cycles: state
                .records
                .iter()
                .find(|r| r.worn_through_loaded)
                .map(|r| r.cycles),
            pointed_tip_cycles: reached(limits.pointed_tip_backlash_increase_m),
            backlash_limit_cycles: reached(limits.backlash_increase_limit_m),
            stopped: state.stopped.clone(),
            limits,
        }
    }
}

pub use super::ltca::MAX_PRESSURE_DEFINITION;

/// The per-state results that still change by more than 5 % with the mesh (issue 39's
/// convergence study, VALIDATION.md "Mesh convergence"): largest values at one node of the
/// worn worm-tip trace or the wheel's tip edge (the peak wear's converged counterpart is
/// `wear_patch_max_m`), the worn flank's largest equivalent pressure below it (MODEL §8.1: it
/// reads that node's pressures; the unworn one is converged), and the worn pattern's mean
/// pressure P_mean with Rank's N_LI from it (case C: 5 % between 40 and 80 positions, and the
/// default level 31 % below the finer ones once the band has widened), and the worn flank's
/// p_eq,2% with the area reading's sum from it (case C: 530-560 MPa over 0.06-0.33e6 cycles
/// at 11 cells across the line, 650-740 MPa at 21, likely the edges' running-in, which does
/// not converge with the cells; VALIDATION.md, session 59), and the edges' part of the flank at
/// or above it (the design gear unworn: 0.92-0.99 at 31 cells where 11 give 0.99-1.00; session
/// 61). Listed in the wear
/// summary as `mesh_dependent`; no other stage reads them (the pitting forecast reads the
/// damage field's share at its onset, the step control the largest per-cycle wear as a step
/// size, the safety table the unworn analysis).
pub const MESH_DEPENDENT: &[&str] = &[
    "max_wear_m",
    "max_plastic_set_m",
    "max_plastic_indentation_m",
    "max_damage",
    "yielded_area_fraction",
    "pressure_patch_max_pa (worn states)",
    "equivalent_pressure_max_pa (worn states)",
    "equivalent_pressure_first_pitting_pa (worn states)",
    "first_pitting_edge_share",
    "area_damage",
    "mean_pressure_pa (worn states)",
    "n_li_model_cycles (worn states)",
];

/// Writes every file of a finished life ([`crate::runner::Life`]) at once, as [`LifeWriter`]
/// leaves them when it writes the life state by state: the maps of each map state, then the
/// records, checkpoint, tables and maps of the last. Returns the files written.
pub fn write_life(
    gear: &GearSet,
    geo: &Geometry,
    tca: &Tca,
    life: &crate::runner::Life,
    dir: &Path,
) -> Result<Vec<PathBuf>, OutputError> {
    let mut files = Vec::new();
    let inputs = life_inputs(gear, &life.plan);
    for m in life.maps.iter().filter(|m| m.map && !m.last) {
        files.push(write_map_flank(dir, &m.state, &inputs)?);
        let view = m.view();
        let maps = StateMaps {
            geo,
            tca,
            view: &view,
            dir,
        };
        files.extend(maps.write(&format!("_step{}", m.state.step))?);
    }
    let Some(last) = life.maps.last().filter(|m| m.last) else {
        return Ok(files);
    };
    let view = StepView {
        state: &life.end,
        ..last.view()
    };
    let mut writer = LifeWriter::new(dir).with_inputs(inputs);
    files.extend(writer.write_state(gear, geo, tca, &life.plan, &view, true)?);
    Ok(files)
}

/// Writes the files of a life run state by state (see the module doc), appending to the
/// records file: one writer per run (a new one after a resume rewrites the records file from
/// the state's records first).
#[derive(Debug)]
pub struct LifeWriter {
    dir: PathBuf,
    /// Records known to be on disk (None: none yet from this writer).
    records_written: Option<usize>,
    /// SHA-256 of the records on disk, as written by this writer.
    records_digest: crate::integrity::RunningDigest,
    /// The run's [`life_inputs`], stored in every checkpoint.
    inputs: Option<serde_json::Value>,
    /// When the tables were last written ([`LifeWriter::write_view`]), None: not yet.
    tables_written: Option<std::time::Instant>,
}

impl LifeWriter {
    /// A writer into `dir`.
    pub fn new(dir: &Path) -> Self {
        Self {
            dir: dir.to_path_buf(),
            records_written: None,
            records_digest: Default::default(),
            inputs: None,
            tables_written: None,
        }
    }

    /// Writes one state of a running life ([`crate::Event::WearState`]): before the first,
    /// the `input`, `geometry` and `rating` sections of summary.json (an interrupted life
    /// keeps them); the tables, which grow with the number of states, at most every two
    /// seconds (and at the map states and the last). Stores the life's inputs in the
    /// checkpoints. Returns the files written.
    pub fn write_view(
        &mut self,
        life: &crate::runner::LifeView,
    ) -> Result<Vec<PathBuf>, OutputError> {
        let mut files = Vec::new();
        if self.tables_written.is_none() {
            super::geometry::write_geometry_summary(
                life.gear,
                life.geometry,
                Path::new(&life.source.file),
                &self.dir,
            )?;
            super::write_rating(life.gear, &self.dir)?;
            files.push(self.dir.join("summary.json"));
            self.inputs = Some(life_inputs(life.gear, life.plan));
        }
        let tables = self
            .tables_written
            .is_none_or(|t| t.elapsed().as_secs_f64() >= 2.0);
        files.extend(self.write_state(
            life.gear,
            life.geometry,
            life.tca,
            life.plan,
            life.step,
            tables,
        )?);
        if tables || self.tables_written.is_none() {
            self.tables_written = Some(std::time::Instant::now());
        }
        Ok(files)
    }

    /// The same, storing the run's inputs ([`life_inputs`]) in every checkpoint so that a
    /// resume can check them.
    pub fn with_inputs(mut self, inputs: serde_json::Value) -> Self {
        self.inputs = Some(inputs);
        self
    }

    /// Writes one completed state: records and checkpoint always, the rest as
    /// [`write_state`] says. Returns the files written.
    #[allow(clippy::too_many_arguments)]
    pub fn write_state(
        &mut self,
        gear: &GearSet,
        geo: &Geometry,
        tca: &Tca,
        plan: &WearPlan,
        view: &StepView,
        tables: bool,
    ) -> Result<Vec<PathBuf>, OutputError> {
        let state = view.state;
        let encode = |what: &str, e: serde_json::Error| OutputError::Encode {
            what: what.into(),
            message: e.to_string(),
        };
        let line = |r: &crate::wear::StepRecord| -> Result<String, OutputError> {
            let mut l = serde_json::to_string(r).map_err(|e| encode(RECORDS, e))?;
            l.push('\n');
            Ok(l)
        };
        // Records first, then the checkpoint that counts them.
        let rpath = self.dir.join(RECORDS);
        match self.records_written {
            Some(n) if n <= state.records.len() => {
                use std::io::Write as _;
                let mut text = String::new();
                for r in &state.records[n..] {
                    text.push_str(&line(r)?);
                }
                let io = |source| OutputError::Io {
                    path: rpath.clone(),
                    source,
                };
                let mut f = std::fs::OpenOptions::new()
                    .append(true)
                    .open(&rpath)
                    .map_err(io)?;
                f.write_all(text.as_bytes()).map_err(io)?;
                f.sync_data().map_err(io)?;
                self.records_digest.update(&text);
            }
            _ => {
                let mut text = String::new();
                for r in &state.records {
                    text.push_str(&line(r)?);
                }
                write_atomic(&rpath, text.as_bytes())?;
                self.records_digest = Default::default();
                self.records_digest.update(&text);
            }
        }
        self.records_written = Some(state.records.len());
        let checkpoint = CheckpointOut::of(state, self.records_digest.hex(), self.inputs.as_ref());
        let text = crate::integrity::seal(&checkpoint).map_err(|e| OutputError::Encode {
            what: CHECKPOINT.into(),
            message: e.to_string(),
        })?;
        write_atomic(&self.dir.join(CHECKPOINT), text.as_bytes())?;
        let mut files = vec![rpath, self.dir.join(CHECKPOINT)];
        if let (true, Some(inputs)) = (view.map, &self.inputs) {
            files.push(write_map_flank(&self.dir, state, inputs)?);
        }
        files.extend(write_state(gear, geo, tca, plan, view, &self.dir, tables)?);
        Ok(files)
    }
}

/// Writes the result files of one completed state except the records and the checkpoint
/// ([`LifeWriter`] writes those first). Returns the files written.
///
/// With `tables` false, the steps table, summary and curves (which grow with the number of
/// states) are left for a later state; they are always written at state 0, at log-spaced
/// states and at the last one.
fn write_state(
    gear: &GearSet,
    geo: &Geometry,
    tca: &Tca,
    plan: &WearPlan,
    view: &StepView,
    dir: &Path,
    tables: bool,
) -> Result<Vec<PathBuf>, OutputError> {
    let state = view.state;
    let mut files = Vec::new();
    if !(tables || view.map || view.last) {
        return Ok(files);
    }
    files.extend(write_tables(gear, geo, tca, plan, view, dir)?);
    // Maps and the node table: at the map states and the last (drawing every state would
    // cost more than the state itself on long lives).
    if !(view.map || view.last) {
        return Ok(files);
    }
    let r = state.records.last().expect("a state has a record");
    let maps = StateMaps {
        geo,
        tca,
        view,
        dir,
    };
    if view.map {
        files.extend(maps.write(&format!("_step{}", state.step))?);
    }
    files.extend(maps.write("")?);
    let path = dir.join("wheel_flank_wear.vtp");
    let mut surface = super::vtk::wheel_flank_tca(gear, geo, tca);
    super::vtk::add_pressure_pattern(&mut surface, &view.ltca.pattern);
    super::vtk::add_node_field(&mut surface, "wear_um", &state.removal, UM);
    super::vtk::add_node_field(
        &mut surface,
        "plastic_set_um",
        &view.state.plastic_set_nodes_after(view.ltca),
        UM,
    );
    super::vtk::add_node_field(&mut surface, "wear_per_cycle_um", &view.cycle.depth, UM);
    super::vtk::add_node_field(&mut surface, "film_thickness_um", &view.cycle.film, UM);
    super::vtk::add_node_field(&mut surface, "film_ratio", &view.cycle.lambda, 1.0);
    surface.write_vtp(
        &path,
        &[],
        &format!(
            "loaded wheel flank after {} cycles (mm)",
            super::cycles_label(r.cycles)
        ),
    )?;
    files.push(path);
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn input_changes_name_every_differing_leaf_and_nothing_else() {
        let old = serde_json::json!({
            "gear": {"conditions": {"torque": {"Worm": 60.0}, "worm_speed": 157.0},
                     "grid": [40, 60], "name": "x"},
            "plan": {"step": {"Cycles": 10000.0}}
        });
        assert!(input_changes(&old, &old).is_empty());
        let new = serde_json::json!({
            "gear": {"conditions": {"torque": {"Wheel": 1250.0}, "worm_speed": 15.7},
                     "grid": [30, 60], "extra": true, "name": "x"},
            "plan": {"step": {"Cycles": 10000.0}}
        });
        let changes = input_changes(&old, &new);
        assert_eq!(
            changes,
            vec![
                "gear.conditions.torque.Worm: 60.0 -> (absent)",
                "gear.conditions.torque.Wheel: (absent) -> 1250.0",
                "gear.conditions.worm_speed: 157.0 -> 15.7",
                "gear.grid[0]: 40 -> 30",
                "gear.extra: (absent) -> true",
            ]
        );
        // Long values are cut.
        let long = serde_json::json!({"a": "y".repeat(200)});
        let line = &input_changes(&serde_json::json!({"a": 1}), &long)[0];
        assert!(line.len() < 80 && line.ends_with("..."));
    }
}
