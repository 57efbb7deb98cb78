//! What a run owns in its output directory: the files the writers name (summary.json, the
//! stages' tables and drawings, the life's records, checkpoint and map states, the CAD and VTK
//! files, report.html). A new run clears them first, so that no file of an earlier run (a
//! longer life's map states, a stage not run this time) is read as this run's; other files
//! and folders are left alone.

use super::{io_err, OutputError};
use crate::Stage;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// The names the writers start their files with, and the endings they use.
const PREFIXES: &[&str] = &[
    "axial_profiles",
    "cad_faces",
    "duty_cycle",
    "friction_",
    "ltca_",
    "rating",
    "report",
    "section_z",
    "summary",
    "tca_",
    "wear_",
    "wheel",
    "worm",
];
const ENDINGS: &[&str] = &[
    ".csv", ".svg", ".json", ".jsonl", ".vtp", ".stl", ".step", ".html",
];

/// Whether a file name is one a run writes ([`PREFIXES`] and [`ENDINGS`]).
pub fn is_run_output(name: &str) -> bool {
    PREFIXES.iter().any(|p| name.starts_with(p)) && ENDINGS.iter().any(|e| name.ends_with(e))
}

/// The files of an earlier run in `dir` ([`is_run_output`], regular files and links only), in
/// name order; none when `dir` does not exist.
pub fn run_outputs(dir: &Path) -> Result<Vec<PathBuf>, OutputError> {
    let entries = match std::fs::read_dir(dir) {
        Ok(entries) => entries,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(io_err(dir)(e)),
    };
    let mut files = Vec::new();
    for entry in entries {
        let entry = entry.map_err(io_err(dir))?;
        let kind = entry.file_type().map_err(io_err(&entry.path()))?;
        let name = entry.file_name();
        let owned = name.to_str().is_some_and(is_run_output);
        if owned && (kind.is_file() || kind.is_symlink()) {
            files.push(entry.path());
        }
    }
    files.sort();
    Ok(files)
}

/// The stage whose writer writes the file `name` (None: summary.json, shared by all).
pub fn stage_of(name: &str) -> Option<Stage> {
    let starts = |prefixes: &[&str]| prefixes.iter().any(|p| name.starts_with(p));
    if name.starts_with("summary") {
        None
    } else if starts(&["wear_", "wheel_flank_wear", "wheel_worn"]) {
        Some(Stage::Wear)
    } else if starts(&["tca_", "wheel_flank_tca"]) {
        Some(Stage::Tca)
    } else if starts(&[
        "ltca_",
        "friction_",
        "duty_cycle",
        "rating",
        "wheel_flank_ltca",
    ]) {
        Some(Stage::Ltca)
    } else if starts(&["report"]) {
        Some(Stage::Report)
    } else {
        Some(Stage::Geometry)
    }
}

/// The stages whose files a run of `stages` replaces in its directory: those it runs, and for
/// the whole pipeline (the one that writes report.html over everything) all of them, with
/// summary.json (the second value).
pub fn replaced_by(stages: &BTreeSet<Stage>) -> (BTreeSet<Stage>, bool) {
    match stages.contains(&Stage::Report) {
        true => (Stage::ALL.into_iter().collect(), true),
        false => (stages.clone(), false),
    }
}

/// Removes what an earlier run left in `dir` that a run of `stages` replaces ([`replaced_by`]);
/// returns how many files.
pub fn clear_earlier(dir: &Path, stages: &BTreeSet<Stage>) -> Result<usize, OutputError> {
    let (replaced, whole) = replaced_by(stages);
    clear_stage_outputs(dir, &replaced, whole)
}

/// Removes the files an earlier run left in `dir` of the `stages` ([`run_outputs`],
/// [`stage_of`]), and summary.json too when `summary`; returns how many files.
pub fn clear_stage_outputs(
    dir: &Path,
    stages: &BTreeSet<Stage>,
    summary: bool,
) -> Result<usize, OutputError> {
    let mut removed = 0;
    for f in run_outputs(dir)? {
        let name = f.file_name().map(|n| n.to_string_lossy().into_owned());
        let stage = name.as_deref().and_then(stage_of);
        if stage.map_or(summary, |s| stages.contains(&s)) {
            std::fs::remove_file(&f).map_err(io_err(&f))?;
            removed += 1;
        }
    }
    Ok(removed)
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_writers_names_are_owned_and_others_are_not() {
        for name in [
            "summary.json",
            "report.html",
            "rating.csv",
            "wear_map_step16.svg",
            "wear_flank_step8.json",
            "wear_records.jsonl",
            "wheel_worn.step",
            "section_z+11.250mm.csv",
            "ltca_pressure_position0_tooth-1.svg",
        ] {
            assert!(super::is_run_output(name), "{name}");
        }
        for name in [
            "notes.txt",
            "gear.toml",
            "measured.csv",
            "wear_notes.txt",
            "sweep.csv",
        ] {
            assert!(!super::is_run_output(name), "{name}");
        }
    }

    #[test]
    fn each_file_belongs_to_the_stage_that_writes_it() {
        use crate::Stage;
        for (name, stage) in [
            ("wear_map_step16.svg", Some(Stage::Wear)),
            ("wheel_worn.step", Some(Stage::Wear)),
            ("wheel_flank_wear.vtp", Some(Stage::Wear)),
            ("tca_pattern.csv", Some(Stage::Tca)),
            ("ltca_pressure_position3_tooth1.svg", Some(Stage::Ltca)),
            ("friction_map.csv", Some(Stage::Ltca)),
            ("rating.csv", Some(Stage::Ltca)),
            ("report.html", Some(Stage::Report)),
            ("section_z+0.000mm.svg", Some(Stage::Geometry)),
            ("wheel.step", Some(Stage::Geometry)),
            ("summary.json", None),
        ] {
            assert_eq!(super::stage_of(name), stage, "{name}");
        }
    }
}
