//! Comparison of finished runs (`wormwear compare`): their key results side by side with the
//! differences to the first, and the backlash and wear curves of their lives overlaid, read
//! from each run's summary.json and wear_steps.csv.

use super::plot::{line_chart, Series};
use super::text::{escape, number};
use super::{write_atomic, OutputError};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// One compared run.
#[derive(Debug, Clone)]
pub struct ComparedRun {
    /// Its label: the directory's name (with its position when two share a name).
    pub label: String,
    pub dir: PathBuf,
    pub title: String,
    /// Its inputs that differ from the first run's, one `path: first -> this` line each (SI,
    /// the validated gear's names); None for the first run, or where a summary.json does not
    /// hold the gear (written by an earlier version).
    pub differences: Option<Vec<String>>,
    /// The life's (cycles, backlash increase um, largest flank loss um), if it ran.
    pub life: Vec<(f64, f64, f64)>,
}

/// A key result of every run: label, unit and value per run (None where it is absent).
#[derive(Debug, Clone, PartialEq)]
pub struct KeyResult {
    pub quantity: String,
    pub unit: String,
    pub values: Vec<Option<f64>>,
}

/// Runs side by side.
#[derive(Debug, Clone)]
pub struct Comparison {
    pub runs: Vec<ComparedRun>,
    pub rows: Vec<KeyResult>,
}

/// Why runs could not be compared.
#[derive(Debug, thiserror::Error)]
pub enum CompareError {
    #[error("{dir}: not a wormwear output directory (no readable summary.json): {message}")]
    NotARun { dir: String, message: String },
    #[error("{dir}/summary.json: {message}")]
    Summary { dir: String, message: String },
    #[error("compare needs at least two run directories, got {0}")]
    TooFew(usize),
}

/// The key results: (summary.json path, quantity, unit, factor from the file's unit).
const KEYS: &[(&str, &str, &str, f64)] = &[
    ("ltca/worm_torque_nm", "Worm torque", "N m", 1.0),
    ("ltca/wheel_torque_nm", "Wheel torque", "N m", 1.0),
    (
        "ltca/max_pressure_pa",
        "Largest contact pressure",
        "MPa",
        1e-6,
    ),
    (
        "ltca/pressure_patch_max_pa",
        "Largest patch-mean contact pressure",
        "MPa",
        1e-6,
    ),
    (
        "ltca/mean_pressure_pa",
        "Mean contact pressure",
        "MPa",
        1e-6,
    ),
    (
        "ltca/equivalent_pressure_max_pa",
        "Equivalent pressure below the flank",
        "MPa",
        1e-6,
    ),
    (
        "ltca/contact_area_fraction",
        "Loaded share of the flank",
        "%",
        100.0,
    ),
    (
        "ltca/max_teeth_in_contact",
        "Teeth in contact (most)",
        "",
        1.0,
    ),
    (
        "ltca/te_p2p_rad",
        "Transmission error, peak to peak",
        "urad",
        1e6,
    ),
    (
        "ltca/mesh_stiffness_mean_nm_per_rad",
        "Mesh stiffness (mean)",
        "N m/rad",
        1.0,
    ),
    (
        "friction/efficiency/mesh_efficiency",
        "Mesh efficiency (contact)",
        "",
        1.0,
    ),
    (
        "friction/efficiency/total_efficiency",
        "Total efficiency (contact)",
        "",
        1.0,
    ),
    ("friction/oil_temperature_k", "Oil temperature", "C", 1.0),
    (
        "rating/mesh_efficiency",
        "Mesh efficiency (ISO/TR 14521)",
        "",
        1.0,
    ),
    ("rating/sigma_hm_mpa", "sigma_Hm (ISO/TR 14521)", "MPa", 1.0),
    ("rating/pitting_safety", "S_H (ISO/TR 14521)", "", 1.0),
    ("wear/life_cycles", "Simulated life", "wheel cycles", 1.0),
    ("wear/states", "Wear states", "", 1.0),
];

/// The value at a slash-separated path of summary.json, times `factor` (an oil temperature
/// from K to C).
fn value_at(summary: &Value, path: &str, factor: f64) -> Option<f64> {
    let v = path
        .split('/')
        .try_fold(summary, |v, key| v.get(key))?
        .as_f64()
        .filter(|v| v.is_finite())?;
    Some(if path.ends_with("_k") {
        v - 273.15
    } else {
        v * factor
    })
}

/// The life of a run from its wear_steps.csv: (cycles, backlash increase um, patch-mean
/// largest flank loss um); empty without a life.
fn life_of(dir: &Path) -> Vec<(f64, f64, f64)> {
    let Ok(text) = crate::files::read_text(&dir.join("wear_steps.csv"), crate::files::RESULT_LIMIT)
    else {
        return Vec::new();
    };
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let column = |name: &str| header.iter().position(|h| *h == name);
    let (Some(c), Some(b), Some(w)) = (
        column("cycles"),
        column("backlash_increase_m"),
        column("wear_patch_max_m"),
    ) else {
        return Vec::new();
    };
    let life: Vec<(f64, f64, f64)> = lines
        .filter_map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            let get = |i: usize| {
                f.get(i)
                    .and_then(|s| s.parse::<f64>().ok())
                    .filter(|v| v.is_finite())
            };
            Some((get(c)?, get(b)? * 1e6, get(w)? * 1e6))
        })
        .collect();
    // A life's cycles rise from state to state; a table where they do not is no life.
    if life.windows(2).any(|p| p[1].0 <= p[0].0) {
        return Vec::new();
    }
    life
}

/// Reads the runs of `dirs` and gathers their key results: the table's rows, the life's end
/// (backlash increase, largest flank loss) and each safety of the safety table.
pub fn compare(dirs: &[PathBuf]) -> Result<Comparison, CompareError> {
    if dirs.len() < 2 {
        return Err(CompareError::TooFew(dirs.len()));
    }
    let mut summaries = Vec::new();
    let mut runs = Vec::new();
    for (k, dir) in dirs.iter().enumerate() {
        let shown = dir.display().to_string();
        let summary_path = dir.join("summary.json");
        let text =
            crate::files::read_text(&summary_path, crate::files::RESULT_LIMIT).map_err(|e| {
                CompareError::NotARun {
                    dir: shown.clone(),
                    message: e.to_string(),
                }
            })?;
        let summary: Value = serde_json::from_str(&text).map_err(|e| CompareError::Summary {
            dir: shown.clone(),
            message: e.to_string(),
        })?;
        if !summary["input"]["program_version"].is_string() {
            return Err(CompareError::Summary {
                dir: shown.clone(),
                message: "not a wormwear summary (it has no input.program_version)".into(),
            });
        }
        let name = dir
            .file_name()
            .map_or(shown.clone(), |n| n.to_string_lossy().into_owned());
        let clash = dirs
            .iter()
            .filter(|d| d.file_name() == dir.file_name())
            .count()
            > 1;
        runs.push(ComparedRun {
            label: if clash {
                format!("{name} ({})", k + 1)
            } else {
                name
            },
            dir: dir.clone(),
            title: summary["input"]["title"].as_str().unwrap_or("").to_string(),
            differences: summaries.first().and_then(|first: &Value| {
                let (a, b) = (first["input"].get("gear")?, summary["input"].get("gear")?);
                Some(super::wear::input_changes(a, b))
            }),
            life: life_of(dir),
        });
        summaries.push(summary);
    }
    let mut rows: Vec<KeyResult> = KEYS
        .iter()
        .map(|&(path, quantity, unit, factor)| KeyResult {
            quantity: quantity.into(),
            unit: unit.into(),
            values: summaries
                .iter()
                .map(|s| value_at(s, path, factor))
                .collect(),
        })
        .collect();
    rows.push(life_end_row(
        &runs,
        "Backlash increase at the life's end",
        |l| l.1,
    ));
    rows.push(life_end_row(
        &runs,
        "Largest flank loss at the life's end",
        |l| l.2,
    ));
    rows.extend(safety_rows(&summaries));
    rows.retain(|r| r.values.iter().any(Option::is_some));
    Ok(Comparison { runs, rows })
}

fn life_end_row(
    runs: &[ComparedRun],
    quantity: &str,
    pick: impl Fn(&(f64, f64, f64)) -> f64,
) -> KeyResult {
    KeyResult {
        quantity: quantity.into(),
        unit: "um".into(),
        values: runs.iter().map(|r| r.life.last().map(&pick)).collect(),
    }
}

/// One row per safety of the runs' safety tables (in the first table's order).
fn safety_rows(summaries: &[Value]) -> Vec<KeyResult> {
    let rows = |s: &Value| {
        s["rating"]["safety"]["rows"]
            .as_array()
            .cloned()
            .unwrap_or_default()
    };
    let mut symbols: Vec<String> = Vec::new();
    for s in summaries {
        for r in rows(s) {
            if let Some(sym) = r["symbol"]
                .as_str()
                .filter(|x| !symbols.iter().any(|y| y == x))
            {
                symbols.push(sym.to_string());
            }
        }
    }
    symbols
        .into_iter()
        .map(|sym| KeyResult {
            quantity: format!("Safety {sym}"),
            unit: String::new(),
            values: summaries
                .iter()
                .map(|s| {
                    rows(s)
                        .iter()
                        .find(|r| r["symbol"].as_str() == Some(sym.as_str()))
                        .and_then(|r| r["safety"].as_f64())
                })
                .collect(),
        })
        .collect()
}

/// The difference of `v` to the first run's `first`: absolute and in % of it.
fn difference(first: Option<f64>, v: Option<f64>) -> String {
    match (first, v) {
        (Some(a), Some(b)) if !(b - a).is_finite() => "-".into(),
        (Some(a), Some(b)) if a != 0.0 => {
            format!("{} ({:+.1} %)", number(b - a), 100.0 * (b - a) / a.abs())
        }
        (Some(a), Some(b)) => number(b - a),
        _ => "-".into(),
    }
}

/// Writes compare.csv, the overlaid curves (compare_backlash.svg, compare_wear.svg, when a
/// run has a life) and compare.html into `out`; returns the page's path.
pub fn write_comparison(c: &Comparison, out: &Path) -> Result<PathBuf, OutputError> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| OutputError::Io { path, source }
    };
    std::fs::create_dir_all(out).map_err(io(out))?;
    let mut csv = String::from("quantity,unit");
    for r in &c.runs {
        csv.push(',');
        csv.push_str(&super::csv_text(&r.label));
    }
    csv.push('\n');
    for row in &c.rows {
        let (quantity, unit) = (super::csv_text(&row.quantity), super::csv_text(&row.unit));
        csv.push_str(&format!("{quantity},{unit}"));
        for v in &row.values {
            csv.push(',');
            if let Some(v) = v {
                csv.push_str(&format!("{v:.10e}"));
            }
        }
        csv.push('\n');
    }
    write_atomic(&out.join("compare.csv"), csv.as_bytes())?;
    let mut charts = Vec::new();
    if c.runs.iter().any(|r| !r.life.is_empty()) {
        for (file, title, y, pick) in [
            (
                "compare_backlash.svg",
                "Backlash increase over the life",
                "backlash increase (um)",
                1usize,
            ),
            (
                "compare_wear.svg",
                "Largest flank loss (patch mean) over the life",
                "flank loss (um)",
                2,
            ),
        ] {
            let series: Vec<Series> = c
                .runs
                .iter()
                .enumerate()
                .filter(|(_, r)| !r.life.is_empty())
                .map(|(k, r)| Series {
                    label: r.label.clone(),
                    points: r
                        .life
                        .iter()
                        .map(|l| (l.0, if pick == 1 { l.1 } else { l.2 }))
                        .collect(),
                    color: k,
                    bold: false,
                })
                .collect();
            let path = out.join(file);
            line_chart(&path, title, "wheel cycles", y, &series, false)?;
            charts.push(path);
        }
    }
    let page = out.join("compare.html");
    write_atomic(&page, html(c, &charts).as_bytes())?;
    Ok(page)
}

/// The page: the runs, the key results with differences to the first, the curves inline.
fn html(c: &Comparison, charts: &[PathBuf]) -> String {
    let mut h = String::from(
        "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>wormwear compare</title>\
         <style>body{font-family:sans-serif;max-width:1200px;margin:auto;padding:1em}\
         .scroll{overflow-x:auto}table{border-collapse:collapse}\
         td,th{border:1px solid #ccc;padding:3px 8px;text-align:right}\
         td:first-child,th:first-child{text-align:left}svg{max-width:100%;height:auto}\
         </style></head><body><h1>Comparison of runs</h1><ol>",
    );
    for r in &c.runs {
        let differs = match r.differences.as_ref().map(Vec::is_empty) {
            None => String::new(),
            Some(true) => format!("<br>inputs: as {}", escape(&c.runs[0].label)),
            Some(false) => format!(
                "<br>inputs that differ from {} (SI): {}",
                escape(&c.runs[0].label),
                r.differences
                    .iter()
                    .flatten()
                    .map(|d| format!("<code>{}</code>", escape(d)))
                    .collect::<Vec<_>>()
                    .join("; ")
            ),
        };
        h.push_str(&format!(
            "<li><b>{}</b>: {} <small>({})</small>{differs}</li>",
            escape(&r.label),
            escape(&r.title),
            escape(&r.dir.display().to_string())
        ));
    }
    h.push_str(
        "</ol><h2>Key results</h2><div class=\"scroll\"><table><tr><th>quantity</th><th>unit</th>",
    );
    for (k, r) in c.runs.iter().enumerate() {
        h.push_str(&format!("<th>{}</th>", escape(&r.label)));
        if k > 0 {
            h.push_str(&format!(
                "<th>difference to {}</th>",
                escape(&c.runs[0].label)
            ));
        }
    }
    h.push_str("</tr>");
    for row in &c.rows {
        h.push_str(&format!(
            "<tr><td>{}</td><td>{}</td>",
            escape(&row.quantity),
            escape(&row.unit)
        ));
        for (k, v) in row.values.iter().enumerate() {
            h.push_str(&format!("<td>{}</td>", v.map_or("-".into(), number)));
            if k > 0 {
                h.push_str(&format!("<td>{}</td>", difference(row.values[0], *v)));
            }
        }
        h.push_str("</tr>");
    }
    h.push_str("</table></div>");
    if !charts.is_empty() {
        h.push_str("<h2>Life</h2>");
    }
    for chart in charts {
        if let Ok(svg) = std::fs::read_to_string(chart) {
            h.push_str(&svg[svg.find("<svg").unwrap_or(0)..]);
        }
    }
    h.push_str("</body></html>\n");
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_read_as_an_engineer_writes_them() {
        assert_eq!(number(60.0), "60");
        assert_eq!(number(59.99999999998869), "60");
        assert_eq!(number(1126.2994), "1126");
        assert_eq!(number(0.57211), "0.5721");
        assert_eq!(number(41.63), "41.63");
        assert_eq!(number(2.5e-8), "2.500e-8");
        // Issue 59: a stiffness read "50693969 N/m"; whole numbers up to a million stay plain.
        assert_eq!(number(50_693_969.0), "5.069e7");
        assert_eq!(number(180_000.0), "180000");
        assert_eq!(difference(Some(50.0), Some(60.0)), "10 (+20.0 %)");
        assert_eq!(difference(None, Some(60.0)), "-");
    }
}
