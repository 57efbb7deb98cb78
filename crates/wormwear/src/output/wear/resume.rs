//! Resuming a life (`--resume`): the sealed checkpoint and records read back and checked against
//! the gear, the plan and their checksums before anything is trusted; what changed is named.

use super::*;

/// The checkpoint as written: the state without its records, and their number (the records
/// are the first `record_count` lines of [`RECORDS`]). O(1) in the number of states, so long
/// lives do not rewrite their whole history at every state.
#[derive(serde::Serialize)]
pub(super) struct CheckpointOut<'a> {
    pub(super) step: usize,
    pub(super) cycles: f64,
    pub(super) removal: &'a FlankField,
    pub(super) plastic_set: &'a FlankField,
    pub(super) pitted_phases: &'a [usize],
    pub(super) pitted: &'a [bool],
    pub(super) band_factor: Option<f64>,
    pub(super) warm: Option<&'a crate::ltca::WarmStart>,
    pub(super) damage: &'a [f64],
    pub(super) found_phases: &'a [crate::wear::Phase],
    #[serde(skip_serializing_if = "<[_]>::is_empty")]
    pub(super) bin_starts: &'a [crate::wear::spectrum::BinStart],
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) node_response: Option<&'a crate::wear::NodeResponse>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) rates_before: Option<&'a crate::wear::RateMeasures>,
    pub(super) record_count: usize,
    /// SHA-256 of the first `record_count` lines of [`RECORDS`] as written (each with its
    /// newline): the records are sealed with the checkpoint.
    pub(super) records_sha256: String,
    /// The inputs the states were computed with ([`life_inputs`]).
    pub(super) inputs: Option<&'a serde_json::Value>,
}

impl<'a> CheckpointOut<'a> {
    /// The checkpoint of `state`, whose records as written have the digest `records_sha256`,
    /// computed with `inputs`.
    pub(super) fn of(
        state: &'a crate::wear::WearState,
        records_sha256: String,
        inputs: Option<&'a serde_json::Value>,
    ) -> Self {
        Self {
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
            bin_starts: &state.bin_starts,
            node_response: state.node_response.as_ref(),
            rates_before: state.rates_before.as_ref(),
            record_count: state.records.len(),
            records_sha256,
            inputs,
        }
    }
}

/// The checkpoint as read; `records` inline is the earlier format (still read).
#[derive(serde::Deserialize)]
pub(super) struct CheckpointIn {
    pub(super) step: usize,
    pub(super) cycles: f64,
    pub(super) removal: FlankField,
    #[serde(default)]
    pub(super) plastic_set: FlankField,
    #[serde(default)]
    pub(super) pitted_phases: Vec<usize>,
    #[serde(default)]
    pub(super) pitted: Vec<bool>,
    #[serde(default)]
    pub(super) band_factor: Option<f64>,
    #[serde(default)]
    pub(super) warm: Option<crate::ltca::WarmStart>,
    #[serde(default)]
    pub(super) damage: Vec<f64>,
    #[serde(default)]
    pub(super) found_phases: Vec<crate::wear::Phase>,
    #[serde(default)]
    pub(super) bin_starts: Vec<crate::wear::spectrum::BinStart>,
    #[serde(default)]
    pub(super) node_response: Option<crate::wear::NodeResponse>,
    #[serde(default)]
    pub(super) rates_before: Option<crate::wear::RateMeasures>,
    #[serde(default)]
    pub(super) record_count: Option<usize>,
    #[serde(default)]
    pub(super) records_sha256: Option<String>,
    #[serde(default)]
    pub(super) records: Option<Vec<crate::wear::StepRecord>>,
    #[serde(default)]
    pub(super) inputs: Option<serde_json::Value>,
}

/// Reads a checkpoint written by [`LifeWriter`] with its records (lines of [`RECORDS`] beyond
/// the checkpoint's count, e.g. from an interruption between the two writes, are ignored).
pub fn read_checkpoint(dir: &Path) -> Result<Option<WearState>, OutputError> {
    Ok(read_resume(dir)?.map(|(state, _)| state))
}

/// The inputs that shape a life's results: the gear set without its title, its remarks and
/// its life plan, and the plan without where the life ends (its length and the wear limit it
/// stops at: a resume may extend a life).
/// With them the program that computes them ([`crate::PROGRAM`]): a checkpoint of another
/// build may hold states of another model. Stored in the checkpoint, compared on resume
/// ([`input_changes`]).
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
    serde_json::json!({ "gear": g, "plan": p, "program": crate::PROGRAM })
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
            bin_starts: c.bin_starts,
            node_response: c.node_response,
            rates_before: c.rates_before,
        },
        c.inputs,
    )))
}

/// The records the checkpoint counts against its checksum of them: any change after they were
/// written (a digit, a line) is refused, as is a checkpoint that does not seal its records.
pub(super) fn check_records(lines: &[&str], sealed: Option<&str>) -> Result<(), String> {
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
    let now = life_inputs(gear, plan);
    if stored.get("program") != now.get("program") {
        let shown = |v: Option<&serde_json::Value>| {
            v.and_then(|v| v.as_str())
                .unwrap_or("an earlier version")
                .to_string()
        };
        return Err(ResumeError::Refused(format!(
            "--resume: {} was computed by another build of wormwear ({}; this one is {}): its \
             states may come from another model; finish the life with that build, or run \
             without --resume into a new directory",
            checkpoint.display(),
            shown(stored.get("program")),
            shown(now.get("program"))
        )));
    }
    let changes = input_changes(&stored, &now);
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

/// The file holding the worn flank of the map state of wear step `step`.
pub fn map_flank_file(step: usize) -> String {
    format!("wear_flank_step{step}.json")
}

/// A map state's worn flank as written: what the worn wheel of that state is built from.
#[derive(serde::Serialize)]
struct MapFlankOut<'a> {
    step: usize,
    cycles: f64,
    removal: &'a FlankField,
    plastic_set: &'a FlankField,
    /// The inputs the state was computed with ([`life_inputs`]).
    inputs: &'a serde_json::Value,
}

/// A map state's worn flank as read.
#[derive(serde::Deserialize)]
struct MapFlankIn {
    step: usize,
    cycles: f64,
    removal: FlankField,
    plastic_set: FlankField,
    inputs: serde_json::Value,
}

/// Writes the worn flank of a map state ([`map_flank_file`], sealed with its checksum and the
/// life's inputs) so that a resumed life can still build the worn wheel of a state computed
/// before its resume (`--step-state`). Returns the file written.
pub(super) fn write_map_flank(
    dir: &Path,
    state: &WearState,
    inputs: &serde_json::Value,
) -> Result<PathBuf, OutputError> {
    let path = dir.join(map_flank_file(state.step));
    let flank = MapFlankOut {
        step: state.step,
        cycles: state.cycles,
        removal: &state.removal,
        plastic_set: &state.plastic_set,
        inputs,
    };
    let text = crate::integrity::seal(&flank).map_err(|e| OutputError::Encode {
        what: path.display().to_string(),
        message: e.to_string(),
    })?;
    write_atomic(&path, text.as_bytes())?;
    Ok(path)
}

/// The map state of wear step `step` that a resumed life computed before its checkpoint, read
/// back from its [`map_flank_file`] and checked: its checksum, its step and the inputs it was
/// computed with (they must equal this run's). The state carries the worn flank, the step
/// and the cycles only (no records). None: no such file.
pub fn resumed_map_state(
    dir: &Path,
    gear: &GearSet,
    plan: &WearPlan,
    step: usize,
) -> Result<Option<WearState>, ResumeError> {
    let path = dir.join(map_flank_file(step));
    let refused = |why: String| {
        ResumeError::Refused(format!(
            "--step-state {step}: {} {why}; run the life again without --resume to rebuild it",
            path.display()
        ))
    };
    let text = match crate::files::read_text(&path, crate::files::OWN_FILE_LIMIT) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(refused(format!("cannot be read: {e}"))),
    };
    let flank: MapFlankIn = crate::integrity::open(&text).map_err(|e| {
        refused(format!(
            "is not the sealed worn flank it was written as: {e}"
        ))
    })?;
    if flank.step != step {
        return Err(refused(format!("holds step {}", flank.step)));
    }
    let changes = input_changes(&flank.inputs, &life_inputs(gear, plan));
    if !changes.is_empty() {
        return Err(refused(format!(
            "was computed with other inputs ({}, ...)",
            changes[0]
        )));
    }
    Ok(Some(WearState::flank_at(
        flank.step,
        flank.cycles,
        flank.removal,
        flank.plastic_set,
    )))
}
