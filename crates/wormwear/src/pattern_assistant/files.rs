//! What a pattern search writes (MODEL §17): the best gear file (the base gear file's text
//! with the settings changed, its comments kept), pattern.json (target, settings, start, best,
//! how the search ended), search.csv (every evaluation in order) and the analyses of the base
//! gear and of the best one in `before/` and `after/` (summary.json, the pattern's map and
//! table, as `wormwear tca` or `wormwear ltca` write them).

use super::{component, Assistant, Evaluation, Outcome, PatternError, Target, Which, HOB_OVERSIZE};
use crate::{Request, Source, Stage};
use std::path::{Path, PathBuf};

/// The best gear file's name in the output folder.
pub const BEST_GEAR_FILE: &str = "gear.toml";

/// Writes the search's files into `dir` (created if needed). Returns the files written.
pub fn write(
    assistant: &Assistant,
    outcome: &Outcome,
    dir: &Path,
) -> Result<Vec<PathBuf>, PatternError> {
    let io = |e: std::io::Error| crate::output::OutputError::Io {
        path: dir.to_path_buf(),
        source: e,
    };
    std::fs::create_dir_all(dir).map_err(io)?;
    let mut files = Vec::new();
    let text = best_gear_text(assistant, outcome)?;
    let path = dir.join(BEST_GEAR_FILE);
    crate::output::write_atomic(&path, text.as_bytes())?;
    files.push(path);
    let path = dir.join("search.csv");
    crate::output::write_atomic(&path, search_csv(assistant, outcome).as_bytes())?;
    files.push(path);
    let path = dir.join("pattern.json");
    let json = serde_json::to_string_pretty(&summary(assistant, outcome)).map_err(|e| {
        crate::output::OutputError::Encode {
            what: "pattern.json".into(),
            message: e.to_string(),
        }
    })?;
    crate::output::write_atomic(&path, json.as_bytes())?;
    files.push(path);
    let base_text = assistant.base_text.clone();
    for (folder, text, file) in [
        ("before", base_text, assistant.base_file.clone()),
        ("after", text, BEST_GEAR_FILE.to_string()),
    ] {
        files.extend(analysis_files(
            assistant.which,
            &text,
            file,
            &dir.join(folder),
        )?);
    }
    Ok(files)
}

/// The base gear file's text with the best settings (the hob oversize as the hob's three
/// radii), each value replaced in place (its comment kept), and a header naming the changes.
pub fn best_gear_text(assistant: &Assistant, outcome: &Outcome) -> Result<String, PatternError> {
    let mut document: toml_edit::DocumentMut = assistant
        .base_text
        .parse()
        .map_err(|e: toml_edit::TomlError| PatternError::Base(e.to_string()))?;
    let best = assistant
        .document(&outcome.best.values)
        .map_err(|e| PatternError::Base(crate::runner::error_chain(&e)))?;
    let mut header = format!(
        "# Cutting settings found by `wormwear pattern` (MODEL §17) from {}:\n# the {} \
         pattern's target {}, objective {:.3e} (start {:.3e}).\n",
        assistant.base_file,
        assistant.which.name(),
        target_text(&assistant.target),
        outcome.best.objective,
        outcome.start.objective
    );
    for (setting, value) in assistant.settings.iter().zip(&outcome.best.values) {
        header.push_str(&format!(
            "#   {}: {} -> {}\n",
            setting.name, setting.start, value
        ));
        let fields: Vec<&str> = match setting.name.as_str() {
            HOB_OVERSIZE => super::HOB_RADII.to_vec(),
            name => vec![name],
        };
        for field in fields {
            let value = crate::spread::lookup(&best, field)
                .and_then(crate::spread::number)
                .unwrap_or(f64::NAN);
            set_keeping_comment(&mut document, field, value);
        }
    }
    Ok(format!("{header}{document}"))
}

/// Sets the number at a dotted name of an editable document, keeping the value's comment and
/// spacing (creating the tables on the way where the field was absent).
fn set_keeping_comment(document: &mut toml_edit::DocumentMut, name: &str, value: f64) {
    let keys: Vec<&str> = name.split('.').collect();
    let mut item = document.as_item_mut();
    for key in &keys {
        item = &mut item[*key];
    }
    match item.as_value_mut() {
        Some(v) => {
            let decor = v.decor().clone();
            *v = toml_edit::Value::from(value);
            *v.decor_mut() = decor;
        }
        None => *item = toml_edit::value(value),
    }
}

/// pattern.json: the target, the objective, the settings (bounds, start, best), the start's
/// and the best's shapes, how the search ended and what the flank grid resolves.
fn summary(assistant: &Assistant, outcome: &Outcome) -> serde_json::Value {
    let settings: Vec<serde_json::Value> = assistant
        .settings
        .iter()
        .zip(&outcome.best.values)
        .map(|(s, best)| {
            serde_json::json!({"name": s.name, "min": s.min, "max": s.max, "start": s.start, "best": best})
        })
        .collect();
    let grid = assistant
        .gear(&outcome.best.values)
        .map(|g| (g.analysis.flank_cells_face, g.analysis.flank_cells_height))
        .ok();
    serde_json::json!({
        "base": assistant.base_file,
        "pattern": assistant.which,
        "target": assistant.target,
        "objective": super::OBJECTIVE,
        "settings": settings,
        "start": outcome.start,
        "best": outcome.best,
        "evaluations": outcome.path.len(),
        "evaluation_budget": assistant.evaluations,
        "restarts": outcome.restarts,
        "stopped": outcome.stopped,
        "resolution": grid.map(|(face, height)| serde_json::json!({
            "along_face": 1.0 / face as f64,
            "up_flank": 1.0 / height as f64,
            "note": "a cell of the flank grid: the shape's components step by about this as cells enter or leave the pattern",
        })),
        "notes": assistant.notes,
        "best_gear_file": BEST_GEAR_FILE,
        "program_version": env!("CARGO_PKG_VERSION"),
    })
}

/// search.csv: one row per evaluation, in order: the settings, the shape, the objective and
/// the error of a failed one.
fn search_csv(assistant: &Assistant, outcome: &Outcome) -> String {
    let mut text = String::from("evaluation");
    for s in &assistant.settings {
        text.push(',');
        text.push_str(&crate::output::csv_text(&s.name));
    }
    for name in Target::NAMES {
        text.push(',');
        text.push_str(name);
    }
    text.push_str(",objective,error\n");
    for (k, e) in outcome.path.iter().enumerate() {
        text.push_str(&k.to_string());
        let shape = |name: &str| e.shape.map_or(f64::NAN, |s| component(&s, name));
        let numbers = e.values.iter().copied().chain(Target::NAMES.map(shape));
        for v in numbers.chain([e.objective]) {
            text.push_str(&format!(",{v}"));
        }
        text.push(',');
        text.push_str(&crate::output::csv_text(e.error.as_deref().unwrap_or("")));
        text.push('\n');
    }
    text
}

/// The analysis of a gear file's text into `dir`: the unloaded one (no-load pattern) or the
/// loaded one, as the CLI's `tca` or `ltca` writes it.
fn analysis_files(
    which: Which,
    text: &str,
    file: String,
    dir: &Path,
) -> Result<Vec<PathBuf>, PatternError> {
    let mut gear = crate::input::load_from_str(text)
        .map_err(|e| PatternError::Base(crate::runner::error_chain(&e)))?;
    // On the evenly spaced rows the search reads the pattern on (`Assistant::shape`).
    gear.analysis.tip_trace_refinement = 0;
    let stage = match which {
        Which::NoLoad => Stage::Tca,
        Which::Loaded => Stage::Ltca,
    };
    let source = Source {
        file,
        text: text.to_string(),
    };
    let results = crate::run(&gear, source, Request::new([stage]), &mut |_| Ok(()))
        .map_err(|e| PatternError::Base(crate::runner::error_chain(&e)))?;
    std::fs::create_dir_all(dir).map_err(|e| crate::output::OutputError::Io {
        path: dir.to_path_buf(),
        source: e,
    })?;
    Ok(crate::output::write_results(&results, dir, false)?)
}

/// A target as `name=value, ...`.
pub fn target_text(target: &Target) -> String {
    let given = target.given();
    let parts: Vec<String> = given.iter().map(|(n, v)| format!("{n}={v}")).collect();
    parts.join(", ")
}

/// An evaluation's shape as one line (for progress and the CLI's summary).
pub fn shape_text(e: &Evaluation) -> String {
    match e.shape {
        Some(s) => format!(
            "across {:.3}, up {:.3}, along {:.3}, height {:.3}",
            s.centre_across_face, s.centre_up_flank, s.extent_along_face, s.extent_up_flank
        ),
        None => e.error.clone().unwrap_or_default(),
    }
}
