//! Files of a life run, written after every completed state so an interruption loses nothing:
//! the records `wear_records.jsonl` (one JSON line per state, appended) and the checkpoint
//! `wear_checkpoint.json` (the worn flank and how many records belong to it: resume), both at
//! every state; `wear_steps.csv`, the `wear` section of summary.json and curves over cycles
//! (wear, backlash, TE, pressure) and `wear_positions.csv` (TE and load sharing per state and
//! position) when asked (the CLI: every two seconds); maps of the cumulative wear, of the wear
//! per cycle, of the film thickness and ratio, the loaded pattern and the node table at the map
//! states (`[wear] map_cycles`, default 0, 1, 2, 4, 8, ...: files `*_step{N}`) and, without
//! the suffix, the latest of them and the last; `wheel_flank_wear.vtp` with them.

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

/// The checkpoint as written: the state without its records, and their number (the records
/// are the first `record_count` lines of [`RECORDS`]). O(1) in the number of states, so long
/// lives do not rewrite their whole history at every state.
#[derive(serde::Serialize)]
struct CheckpointOut<'a> {
    step: usize,
    cycles: f64,
    removal: &'a FlankField,
    plastic_set: &'a FlankField,
    pitted_phases: &'a [usize],
    pitted: &'a [bool],
    band_factor: Option<f64>,
    warm: Option<&'a crate::ltca::WarmStart>,
    damage: &'a [f64],
    found_phases: &'a [crate::wear::Phase],
    record_count: usize,
    /// SHA-256 of the first `record_count` lines of [`RECORDS`] as written (each with its
    /// newline): the records are sealed with the checkpoint.
    records_sha256: String,
    /// The inputs the states were computed with ([`life_inputs`]).
    inputs: Option<&'a serde_json::Value>,
}

/// The checkpoint as read; `records` inline is the earlier format (still read).
#[derive(serde::Deserialize)]
struct CheckpointIn {
    step: usize,
    cycles: f64,
    removal: FlankField,
    #[serde(default)]
    plastic_set: FlankField,
    #[serde(default)]
    pitted_phases: Vec<usize>,
    #[serde(default)]
    pitted: Vec<bool>,
    #[serde(default)]
    band_factor: Option<f64>,
    #[serde(default)]
    warm: Option<crate::ltca::WarmStart>,
    #[serde(default)]
    damage: Vec<f64>,
    #[serde(default)]
    found_phases: Vec<crate::wear::Phase>,
    #[serde(default)]
    record_count: Option<usize>,
    #[serde(default)]
    records_sha256: Option<String>,
    #[serde(default)]
    records: Option<Vec<crate::wear::StepRecord>>,
    #[serde(default)]
    inputs: Option<serde_json::Value>,
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
    /// The schedule a forecast found (its phases with their pressure limits; run it as a
    /// `[wear] phases` schedule to repeat the life); empty without a forecast.
    pub found_phases: &'a [crate::wear::Phase],
    /// What an engineer must see about the life ([`crate::wear::WearState::warnings`]).
    pub warnings: Vec<String>,
    /// One record per state: the start and after each step (per-position curves in
    /// `wear_positions.csv`).
    pub steps: Vec<crate::wear::StepRecord>,
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
/// `wear_patch_max_m`). Listed in the wear summary as `mesh_dependent`; no other stage reads
/// them (the pitting forecast reads the damage field's share at its onset, the step control
/// the largest per-cycle wear as a step size).
pub const MESH_DEPENDENT: &[&str] = &[
    "max_wear_m",
    "max_plastic_set_m",
    "max_plastic_indentation_m",
    "max_damage",
    "yielded_area_fraction",
    "pressure_patch_max_pa (worn states)",
];

/// Reads a checkpoint written by [`LifeWriter`] with its records (lines of [`RECORDS`] beyond
/// the checkpoint's count, e.g. from an interruption between the two writes, are ignored).
pub fn read_checkpoint(dir: &Path) -> Result<Option<WearState>, OutputError> {
    Ok(read_resume(dir)?.map(|(state, _)| state))
}

/// The inputs that shape a life's results: the gear set without its title, its remarks and
/// its life plan, and the plan without where the life ends (its length and the wear limit it
/// stops at: a resume may extend a life).
/// Stored in the checkpoint, compared on resume ([`input_changes`]).
pub fn life_inputs(gear: &GearSet, plan: &WearPlan) -> serde_json::Value {
    let mut g = serde_json::to_value(gear).unwrap_or(serde_json::Value::Null);
    if let Some(map) = g.as_object_mut() {
        for key in ["title", "warnings", "wear"] {
            map.remove(key);
        }
    }
    let mut p = serde_json::to_value(plan).unwrap_or(serde_json::Value::Null);
    if let Some(map) = p.as_object_mut() {
        for key in ["life_cycles", "stop_at", "backlash_limit"] {
            map.remove(key);
        }
    }
    serde_json::json!({ "gear": g, "plan": p })
}

/// Where two [`life_inputs`] differ: one line per differing leaf, `path: old -> new` (dotted
/// path; values cut to 60 characters), in document order.
pub fn input_changes(old: &serde_json::Value, new: &serde_json::Value) -> Vec<String> {
    fn cut(v: Option<&serde_json::Value>) -> String {
        let text = v.map_or("(absent)".to_string(), |v| v.to_string());
        if text.chars().count() > 60 {
            format!("{}...", text.chars().take(57).collect::<String>())
        } else {
            text
        }
    }
    fn walk(
        path: &str,
        a: Option<&serde_json::Value>,
        b: Option<&serde_json::Value>,
        out: &mut Vec<String>,
    ) {
        use serde_json::Value;
        match (a, b) {
            (Some(Value::Object(x)), Some(Value::Object(y))) => {
                let mut keys: Vec<&String> = x.keys().collect();
                keys.extend(y.keys().filter(|k| !x.contains_key(*k)));
                for k in keys {
                    let p = if path.is_empty() {
                        k.clone()
                    } else {
                        format!("{path}.{k}")
                    };
                    walk(&p, x.get(k), y.get(k), out);
                }
            }
            (Some(Value::Array(x)), Some(Value::Array(y))) if x.len() == y.len() => {
                for (i, (u, v)) in x.iter().zip(y).enumerate() {
                    walk(&format!("{path}[{i}]"), Some(u), Some(v), out);
                }
            }
            _ if a == b => {}
            _ => out.push(format!("{path}: {} -> {}", cut(a), cut(b))),
        }
    }
    let mut out = Vec::new();
    walk("", Some(old), Some(new), &mut out);
    out
}

/// [`read_checkpoint`], with the inputs the checkpoint was computed with (None: a checkpoint
/// of an earlier version, which did not store them).
pub fn read_resume(
    dir: &Path,
) -> Result<Option<(WearState, Option<serde_json::Value>)>, OutputError> {
    let path = dir.join(CHECKPOINT);
    let bad = |path: &Path, message: String| OutputError::Read {
        path: path.to_path_buf(),
        message,
    };
    let text = match crate::files::read_text(&path, crate::files::OWN_FILE_LIMIT) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(source) => {
            return Err(OutputError::Read {
                message: source.to_string(),
                path,
            })
        }
    };
    let c: CheckpointIn = crate::integrity::open(&text).map_err(|e| bad(&path, e.to_string()))?;
    let records = match (c.records, c.record_count) {
        (Some(records), _) => records,
        (None, Some(count)) => {
            let rpath = dir.join(RECORDS);
            let lines = crate::files::read_text(&rpath, crate::files::OWN_FILE_LIMIT)
                .map_err(|e| bad(&rpath, e.to_string()))?;
            let counted: Vec<&str> = lines.lines().take(count).collect();
            if counted.len() < count {
                return Err(bad(
                    &rpath,
                    format!("{} records, the checkpoint needs {count}", counted.len()),
                ));
            }
            check_records(&counted, c.records_sha256.as_deref()).map_err(|m| bad(&rpath, m))?;
            counted
                .iter()
                .map(|l| serde_json::from_str(l).map_err(|e| bad(&rpath, e.to_string())))
                .collect::<Result<_, _>>()?
        }
        (None, None) => return Err(bad(&path, "no records and no record count".into())),
    };
    Ok(Some((
        WearState {
            step: c.step,
            cycles: c.cycles,
            removal: c.removal,
            plastic_set: c.plastic_set,
            records,
            pitted_phases: c.pitted_phases,
            pitted: c.pitted,
            band_factor: c.band_factor,
            warm: c.warm,
            // Recomputed with the state's record on resume.
            stopped: None,
            damage: c.damage,
            found_phases: c.found_phases,
        },
        c.inputs,
    )))
}

/// The records the checkpoint counts against its checksum of them: any change after they were
/// written (a digit, a line) is refused, as is a checkpoint that does not seal its records.
fn check_records(lines: &[&str], sealed: Option<&str>) -> Result<(), String> {
    let Some(sealed) = sealed else {
        return Err(format!(
            "the checkpoint ({CHECKPOINT}) holds no checksum of the records (written by an \
             earlier version?): run the life again without --resume"
        ));
    };
    let mut digest = crate::integrity::RunningDigest::default();
    for line in lines {
        digest.update(line);
        digest.update("\n");
    }
    if digest.hex() != sealed {
        return Err(format!(
            "the first {} records do not match the checksum in {CHECKPOINT}: the records were \
             changed after they were written; run the life again without --resume",
            lines.len()
        ));
    }
    Ok(())
}

/// Why a checkpoint cannot be resumed (all input problems: exit code 2 from the CLI).
#[derive(Debug, thiserror::Error)]
pub enum ResumeError {
    #[error("--resume: no {CHECKPOINT} in {0}")]
    Missing(String),
    #[error("--resume")]
    Unreadable(#[source] OutputError),
    #[error("{0}")]
    Refused(String),
}

/// The checkpoint in `dir` to continue a life from, checked: it must hold the inputs it was
/// computed with, they must equal this run's ([`life_inputs`]; every difference named), and
/// the life asked for must reach at least the checkpoint's cycles.
pub fn resume_state(dir: &Path, gear: &GearSet, plan: &WearPlan) -> Result<WearState, ResumeError> {
    let (state, stored) = read_resume(dir)
        .map_err(ResumeError::Unreadable)?
        .ok_or_else(|| ResumeError::Missing(dir.display().to_string()))?;
    let checkpoint = dir.join(CHECKPOINT);
    let Some(stored) = stored else {
        return Err(ResumeError::Refused(format!(
            "--resume: {} holds no record of the inputs it was computed with (written by an \
             earlier version): its states cannot be checked against this input file; run \
             without --resume into a new directory",
            checkpoint.display()
        )));
    };
    let changes = input_changes(&stored, &life_inputs(gear, plan));
    if !changes.is_empty() {
        let shown: Vec<&str> = changes.iter().take(12).map(String::as_str).collect();
        let more = changes.len().saturating_sub(shown.len());
        return Err(ResumeError::Refused(format!(
            "--resume: the inputs differ from those {} was computed with ({} difference{}, \
             checkpoint -> now):\n  {}{}\nresume with the original inputs, or run without \
             --resume into a new directory",
            checkpoint.display(),
            changes.len(),
            if changes.len() == 1 { "" } else { "s" },
            shown.join("\n  "),
            if more > 0 {
                format!("\n  ... and {more} more")
            } else {
                String::new()
            }
        )));
    }
    if plan.life_cycles < state.cycles {
        return Err(ResumeError::Refused(format!(
            "--resume: the life asked for ({:e} cycles) ends before the checkpoint's \
             state ({:e} cycles, step {}); ask for at least that many cycles",
            plan.life_cycles, state.cycles, state.step
        )));
    }
    Ok(state)
}

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
    for m in life.maps.iter().filter(|m| m.map && !m.last) {
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
    let mut writer = LifeWriter::new(dir).with_inputs(life_inputs(gear, &life.plan));
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
        let checkpoint = CheckpointOut {
            step: state.step,
            cycles: state.cycles,
            removal: &state.removal,
            plastic_set: &state.plastic_set,
            pitted_phases: &state.pitted_phases,
            pitted: &state.pitted,
            band_factor: state.band_factor,
            warm: state.warm.as_ref(),
            damage: &state.damage,
            found_phases: &state.found_phases,
            record_count: state.records.len(),
            records_sha256: self.records_digest.hex(),
            inputs: self.inputs.as_ref(),
        };
        let text = crate::integrity::seal(&checkpoint).map_err(|e| OutputError::Encode {
            what: CHECKPOINT.into(),
            message: e.to_string(),
        })?;
        write_atomic(&self.dir.join(CHECKPOINT), text.as_bytes())?;
        let mut files = vec![rpath, self.dir.join(CHECKPOINT)];
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

/// The tables and curves over the states so far: `wear_steps.csv`, `wear_positions.csv`, the
/// `wear` section of summary.json and the curves over cycles.
fn write_tables(
    gear: &GearSet,
    geo: &Geometry,
    tca: &Tca,
    plan: &WearPlan,
    view: &StepView,
    dir: &Path,
) -> Result<Vec<PathBuf>, OutputError> {
    let state = view.state;
    let mut files = Vec::new();
    // Steps table and summary.
    let csv = steps_table(state);
    let path = dir.join("wear_steps.csv");
    csv.write(&path)?;
    files.push(path);
    let path = dir.join("wear_positions.csv");
    position_table(tca, &state.records).write(&path)?;
    files.push(path);
    update_summary(dir, "wear", summary_value(gear, geo, tca, plan, view)?)?;
    // Curves over cycles.
    let curve = |f: &dyn Fn(&crate::wear::StepRecord) -> f64, label: &str, color: usize| Series {
        label: label.to_string(),
        points: state
            .records
            .iter()
            .map(|r| (r.cycles * 1e-6, f(r)))
            .collect(),
        color,
        bold: true,
    };
    let charts: [(&str, &str, &str, Vec<Series>); 4] = [
        (
            "wear_backlash.svg",
            "Backlash increase (tangential at r2, mean over positions)",
            "backlash increase (um)",
            backlash_series(&state.records),
        ),
        (
            "wear_depth.svg",
            "Wear depth",
            "depth (um)",
            vec![
                curve(&|r| r.max_wear_m * UM, "max (one node, mesh-dependent)", 1),
                curve(&|r| r.wear_patch_max_m * UM, "max over a patch", 2),
                curve(&|r| r.mean_wear_m * UM, "mean over the flank", 0),
            ],
        ),
        (
            "wear_transmission_error.svg",
            "Loaded transmission error over life",
            "TE (urad, wheel)",
            vec![
                curve(&|r| r.te_mean_rad * UM, "mean", 0),
                curve(&|r| r.te_p2p_rad * UM, "peak-to-peak", 2),
                curve(
                    &|r| r.te_mean_relative_rad * UM,
                    "mean relative to the wear's rigid lag",
                    3,
                ),
                curve(
                    &|r| r.te_p2p_relative_rad * UM,
                    "peak-to-peak relative to the lag",
                    4,
                ),
            ],
        ),
        (
            "wear_pressure.svg",
            "Contact pressure over life",
            "pressure (MPa)",
            vec![
                curve(&|r| r.max_pressure_pa * MPA, "P_max (raw)", 1),
                curve(
                    &|r| r.pressure_patch_max_pa * MPA,
                    "P_patch (largest mean over a patch)",
                    2,
                ),
                curve(&|r| r.mean_pressure_pa * MPA, "P_mean", 0),
            ],
        ),
    ];
    for (name, title, y, series) in charts {
        let path = dir.join(name);
        line_chart(&path, title, "wheel cycles (millions)", y, &series, false)?;
        files.push(path);
    }
    Ok(files)
}

/// Per state and position: TE, TE relative to the wear's rigid lag, largest pressure and the
/// normal force on each studied tooth (load sharing over life, MODEL §7.7).
pub fn position_table(tca: &Tca, records: &[crate::wear::StepRecord]) -> Csv {
    let tooth_columns: Vec<String> = tca
        .teeth
        .iter()
        .map(|k| format!("tooth{k}_load_n"))
        .collect();
    let mut header = vec![
        "step",
        "cycles",
        "position",
        "te_rad",
        "te_relative_rad",
        "max_pressure_pa",
    ];
    header.extend(tooth_columns.iter().map(String::as_str));
    let mut csv = Csv::new(&header);
    for r in records {
        for (n, p) in r.positions.iter().enumerate() {
            let mut row = vec![
                r.step as f64,
                r.cycles,
                n as f64,
                p.te_rad,
                p.te_relative_rad,
                p.max_pressure_pa,
            ];
            row.extend(
                (0..tooth_columns.len()).map(|t| p.tooth_load_n.get(t).copied().unwrap_or(0.0)),
            );
            csv.row(&row);
        }
    }
    csv
}

/// The table of states (`wear_steps.csv`): one row per record (units in the names).
pub fn steps_table(state: &WearState) -> Csv {
    let mut csv = Csv::new(&[
        "step",
        "cycles",
        "step_cycles",
        "max_wear_m",
        "wear_patch_max_m",
        "mean_wear_m",
        "worn_volume_m3",
        "backlash_m",
        "backlash_increase_m",
        "max_pressure_pa",
        "mean_pressure_pa",
        "contact_area_fraction",
        "s1",
        "s2",
        "te_mean_rad",
        "te_p2p_rad",
        "mesh_stiffness_mean_nm_per_rad",
        "max_wear_per_cycle_m",
        "lambda_min",
        "substeps",
        "loaded_analyses",
        "pressure_patch_max_pa",
        "rigid_lag_rad",
        "te_mean_relative_rad",
        "te_p2p_relative_rad",
        "n_li_model_cycles",
        "pitted_area_fraction",
        "thinnest_tooth_um",
        "worn_through_loaded",
        "power_balance",
        "max_damage",
        "max_plastic_set_m",
        "max_plastic_indentation_m",
        "yielded_area_fraction",
        "equivalent_pressure_max_pa",
    ]);
    for r in &state.records {
        csv.row(&[
            r.step as f64,
            r.cycles,
            r.step_cycles,
            r.max_wear_m,
            r.wear_patch_max_m,
            r.mean_wear_m,
            r.worn_volume_m3,
            r.backlash_m,
            r.backlash_increase_m,
            r.max_pressure_pa,
            r.mean_pressure_pa,
            r.contact_area_fraction,
            r.s1,
            r.s2,
            r.te_mean_rad,
            r.te_p2p_rad,
            r.mesh_stiffness_mean_nm_per_rad,
            r.max_wear_per_cycle_m,
            r.lambda_min,
            r.substeps as f64,
            r.loaded_analyses as f64,
            r.pressure_patch_max_pa,
            r.rigid_lag_rad,
            r.te_mean_relative_rad,
            r.te_p2p_relative_rad,
            r.n_li_model_cycles.unwrap_or(f64::NAN),
            r.pitted_area_fraction,
            r.thinnest_tooth_m * UM,
            f64::from(u8::from(r.worn_through_loaded)),
            r.power_balance,
            r.max_damage,
            r.max_plastic_set_m,
            r.max_plastic_indentation_m,
            r.yielded_area_fraction,
            r.equivalent_pressure_max_pa,
        ]);
    }
    csv
}

/// The `wear` section of summary.json after the state of `view`.
pub fn summary_value(
    gear: &GearSet,
    geo: &Geometry,
    tca: &Tca,
    plan: &WearPlan,
    view: &StepView,
) -> Result<serde_json::Value, OutputError> {
    let state = view.state;
    let summary = WearSummary {
        life_cycles: plan.life_cycles,
        step_control: &plan.step,
        bending_model: &view.ltca.bending_model,
        film_load: plan.film_load,
        pit_depth: plan.pit_depth,
        states: state.records.len(),
        loaded_analyses: state.records.last().map_or(0, |r| r.loaded_analyses),
        max_pressure_definition: MAX_PRESSURE_DEFINITION,
        mesh_dependent: MESH_DEPENDENT,
        limits: LimitsSummary::new(gear, geo, tca, plan, state),
        pitting: plan.pitting,
        phases: crate::wear::forecast::phase_spans(&state.records),
        found_phases: &state.found_phases,
        warnings: state.warnings(geo.wheel_flank(tca.loaded_flank)),
        steps: state
            .records
            .iter()
            .map(|r| crate::wear::StepRecord {
                positions: Vec::new(),
                ..r.clone()
            })
            .collect(),
    };
    serde_json::to_value(&summary).map_err(|e| OutputError::Encode {
        what: "wear summary".into(),
        message: e.to_string(),
    })
}

/// The backlash increase over cycles (1e6, um): the whole curve, and its pitting phases drawn
/// over it in orange (no wear: flat).
fn backlash_series(records: &[crate::wear::StepRecord]) -> Vec<Series> {
    let points = |rs: &[crate::wear::StepRecord]| -> Vec<(f64, f64)> {
        rs.iter()
            .map(|r| (r.cycles * 1e-6, r.backlash_increase_m * UM))
            .collect()
    };
    let spans = crate::wear::forecast::phase_spans(records);
    let pitting: Vec<_> = spans.iter().filter(|s| s.kind == "pitting").collect();
    let mut series = vec![Series {
        label: if pitting.is_empty() {
            String::new()
        } else {
            "wear".into()
        },
        points: points(records),
        color: 0,
        bold: true,
    }];
    for (k, s) in pitting.iter().enumerate() {
        let inside: Vec<_> = records
            .iter()
            .filter(|r| r.cycles >= s.start_cycles && r.cycles <= s.end_cycles)
            .cloned()
            .collect();
        series.push(Series {
            label: if k == 0 {
                "pitting phase".into()
            } else {
                String::new()
            },
            points: points(&inside),
            color: 4,
            bold: true,
        });
    }
    series
}

/// The node table of a state (`wear_map.csv`): per loaded-flank node (i up the height, j
/// across the face) its (r, z) mm, cumulative wear m, wear per cycle m, film ratio and film
/// thickness m, damage, and the plastic set m once the state has run in
/// ([`WearState::plastic_set_after`], read at the nodes).
pub fn node_table(
    wf: &crate::geometry::WheelFlank,
    state: &WearState,
    cycle: &crate::wear::CycleWear,
    plastic_set: &FlankField,
) -> Csv {
    let plastic_set = plastic_set.with_rows(wf.cells_height);
    let mut csv = Csv::new(&[
        "i",
        "j",
        "r_mm",
        "z_mm",
        "wear_m",
        "wear_per_cycle_m",
        "lambda",
        "film_m",
        "damage",
        "plastic_set_m",
    ]);
    for j in 0..=wf.cells_face {
        for i in 0..=wf.cells_height {
            let k = j * (wf.cells_height + 1) + i;
            let n = wf.node(i, j);
            csv.row(&[
                i as f64,
                j as f64,
                n.r * 1e3,
                n.z * 1e3,
                state.removal.values[k],
                cycle.depth.values[k],
                cycle.lambda.values[k],
                cycle.film.values[k],
                state.damage.get(k).copied().unwrap_or(0.0),
                plastic_set.values.get(k).copied().unwrap_or(0.0),
            ]);
        }
    }
    csv
}

/// The maps and node table of one state.
struct StateMaps<'a> {
    geo: &'a Geometry,
    tca: &'a Tca,
    view: &'a StepView<'a>,
    dir: &'a Path,
}

impl StateMaps<'_> {
    /// Map of a node field of the loaded flank (cell means, times `scale`), coloured over
    /// [0, top] or [0, its maximum], with the active flank and the worm tip's trace.
    fn node_map(
        &self,
        path: &Path,
        title: &str,
        field: &FlankField,
        scale: f64,
        bar: &str,
        top: Option<f64>,
    ) -> Result<(), OutputError> {
        let wf = self.geo.wheel_flank(self.tca.loaded_flank);
        let overlays = [
            flank_outline(wf, "active flank", 5),
            tip_trace_series(self.tca),
        ];
        let values: Vec<f64> = field.cell_means().iter().map(|v| v * scale).collect();
        let hi = top.unwrap_or_else(|| {
            values
                .iter()
                .copied()
                .filter(|v| v.is_finite())
                .fold(0.0, f64::max)
        });
        wheel_flank_map(
            path,
            title,
            wf,
            &values,
            (0.0, if hi > 0.0 { hi } else { 1.0 }),
            bar,
            &overlays,
            &[],
        )
    }

    /// The principal shear stress below the most damaged node (MODEL §8.1), from this state's
    /// loaded analysis: `wear_subsurface_section.svg` (None: no node is damaged or loaded).
    fn damage_section(&self) -> Result<Option<PathBuf>, OutputError> {
        let (state, wf) = (self.view.state, self.geo.wheel_flank(self.tca.loaded_flank));
        let Some((k, _)) = state
            .damage
            .iter()
            .enumerate()
            .filter(|(_, &d)| d > 0.0)
            .max_by(|a, b| a.1.total_cmp(b.1))
        else {
            return Ok(None);
        };
        let node = wf.nodes[k];
        let path = self.dir.join("wear_subsurface_section.svg");
        let place = format!("at the most damaged node (r = {:.2} mm)", node.r * 1e3);
        let drawn =
            super::ltca::subsurface_section(&path, self.view.ltca, Some((node.r, node.z)), &place)?;
        Ok(drawn.then_some(path))
    }

    /// Writes the maps (cumulative wear, wear per cycle, film ratio and thickness, fatigue
    /// damage, loaded pattern) and the node table, their names ending with `suffix` before
    /// the extension.
    fn write(&self, suffix: &str) -> Result<Vec<PathBuf>, OutputError> {
        let (tca, view, dir) = (self.tca, self.view, self.dir);
        let state = view.state;
        let wf = self.geo.wheel_flank(tca.loaded_flank);
        let mut files = Vec::new();
        let overlays = [flank_outline(wf, "active flank", 5), tip_trace_series(tca)];
        let map = |path: &Path, title: &str, field: &FlankField, scale, bar: &str, top| {
            self.node_map(path, title, field, scale, bar, top)
        };
        let r = state.records.last().expect("a state has a record");
        let path = dir.join(format!("wear_map{suffix}.svg"));
        map(
            &path,
            &format!(
                "Cumulative wear after {} cycles (max {:.2} um, mesh-dependent; map: cell means)",
                super::cycles_label(r.cycles),
                r.max_wear_m * UM
            ),
            &state.removal,
            UM,
            "wear depth (um)",
            None,
        )?;
        files.push(path);
        let path = dir.join(format!("wear_per_cycle_map{suffix}.svg"));
        map(
            &path,
            &format!(
                "Wear per cycle at {} cycles (max {:.3} nm; map: cell means)",
                super::cycles_label(r.cycles),
                r.max_wear_per_cycle_m * 1e9
            ),
            &view.cycle.depth,
            1e9,
            "wear per cycle (nm)",
            None,
        )?;
        files.push(path);
        let lambda = FlankField {
            values: view
                .cycle
                .lambda
                .values
                .iter()
                .map(|v| v.min(4.0))
                .collect(),
            ..view.cycle.lambda.clone()
        };
        let path = dir.join(format!("wear_film_ratio_map{suffix}.svg"));
        map(
            &path,
            &format!(
                "Film ratio lambda at {} cycles (clipped at 4: no wear above)",
                super::cycles_label(r.cycles)
            ),
            &lambda,
            1.0,
            "lambda",
            Some(4.0),
        )?;
        files.push(path);
        let path = dir.join(format!("wear_film_thickness_map{suffix}.svg"));
        map(
            &path,
            &format!(
                "Minimum film thickness h_min at {} cycles (Moes-Venner, thermal factor)",
                super::cycles_label(r.cycles)
            ),
            &view.cycle.film,
            UM,
            "h_min (um)",
            None,
        )?;
        files.push(path);
        let path = dir.join(format!("wear_damage_map{suffix}.svg"));
        map(
            &path,
            &format!(
                "Fatigue damage at {} cycles (max {:.3}, mesh-dependent; 1: pits; map: cell means)",
                super::cycles_label(r.cycles),
                r.max_damage
            ),
            &FlankField {
                values: state.damage.clone(),
                ..state.removal.clone()
            },
            1.0,
            "damage (Miner, wear-relieved)",
            Some(1.0),
        )?;
        files.push(path);
        if suffix.is_empty() {
            files.extend(self.damage_section()?);
        }
        let plastic = view.state.plastic_set_nodes_after(view.ltca);
        let path = dir.join(format!("wear_plastic_set_map{suffix}.svg"));
        map(
            &path,
            &format!(
                "Plastic set (running-in) at {} cycles (max {:.2} um, mesh-dependent; yielded {:.1} % of the \
                 flank; map: cell means)",
                super::cycles_label(r.cycles),
                r.max_plastic_set_m * UM,
                100.0 * r.yielded_area_fraction
            ),
            &plastic,
            UM,
            "plastic set (um)",
            None,
        )?;
        files.push(path);
        let csv = node_table(wf, state, view.cycle, &plastic);
        let path = dir.join(format!("wear_map{suffix}.csv"));
        csv.write(&path)?;
        files.push(path);
        // Loaded pattern (the maximum pressure over the cycle per flank cell).
        {
            let path = dir.join(format!("wear_pattern{suffix}.svg"));
            super::ltca::pattern_map(
                &path,
                wf,
                view.ltca,
                &format!(
                    "Loaded pattern at {} cycles (P_max {:.0} MPa, S0 {:.2})",
                    super::cycles_label(r.cycles),
                    r.max_pressure_pa * MPA,
                    r.contact_area_fraction
                ),
                &overlays,
            )?;
            files.push(path);
        }
        Ok(files)
    }
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
