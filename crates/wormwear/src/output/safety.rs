//! The safety table's files (MODEL §9.1): `rating.csv` and the `safety` entry of summary.json's
//! `rating` section.

use super::{update_summary, write_atomic, OutputError};
use crate::safety::SafetyTable;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// A CSV field: quoted (inner quotes doubled) when it holds a comma, a quote or a newline.
fn field(text: &str) -> String {
    if text.contains([',', '"', '\n']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

/// A number of the table (empty: none; `inf` for an unbounded safety).
fn number(v: Option<f64>) -> String {
    match v {
        Some(x) if x.is_finite() => format!("{x:.6e}"),
        Some(x) if x > 0.0 => "inf".into(),
        _ => String::new(),
    }
}

/// `rating.csv`: quantity, symbol, unit, value, allowable, safety, minimum, verdict, source.
pub fn safety_csv(table: &SafetyTable) -> String {
    let mut text = String::from(
        "quantity,symbol,unit,value,allowable,safety,minimum,verdict,source,assumed_inputs\n",
    );
    for r in &table.rows {
        let _ = writeln!(
            text,
            "{},{},{},{},{},{},{},{},{},{}",
            field(&r.quantity),
            field(&r.symbol),
            field(&r.unit),
            number(r.value),
            number(r.allowable),
            number(r.safety),
            r.minimum,
            field(&r.verdict.text()),
            field(&r.source),
            field(&r.assumed.join(" "))
        );
    }
    text
}

/// The table as the JSON summary.json's `rating` section holds under `safety`.
pub fn safety_value(table: &SafetyTable) -> Result<serde_json::Value, OutputError> {
    serde_json::to_value(table).map_err(|e| OutputError::Encode {
        what: "safety table".into(),
        message: e.to_string(),
    })
}

/// Writes `rating.csv` and adds the table to the `rating` section of summary.json (written
/// before). Returns the file written.
pub fn write_safety(table: &SafetyTable, dir: &Path) -> Result<Vec<PathBuf>, OutputError> {
    let path = dir.join("rating.csv");
    write_atomic(&path, safety_csv(table).as_bytes())?;
    let summary = dir.join("summary.json");
    let mut rating = crate::files::read_text(&summary, crate::files::OWN_FILE_LIMIT)
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .and_then(|v| v.get("rating").cloned())
        .unwrap_or_else(|| serde_json::json!({}));
    if let Some(map) = rating.as_object_mut() {
        map.insert("safety".into(), safety_value(table)?);
    }
    update_summary(dir, "rating", rating)?;
    Ok(vec![path])
}
