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
    /// The worn volume of one flank at the life's end, mm^3 (None: no life, or a table
    /// without it).
    pub worn_volume_mm3: Option<f64>,
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
    (
        "wear/loaded_analyses",
        "Loaded analyses of the life",
        "",
        1.0,
    ),
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
/// largest flank loss um), empty without a life, and the worn volume at its end (mm^3).
fn life_of(dir: &Path) -> (Vec<(f64, f64, f64)>, Option<f64>) {
    let Ok(text) = crate::files::read_text(&dir.join("wear_steps.csv"), crate::files::RESULT_LIMIT)
    else {
        return (Vec::new(), None);
    };
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let column = |name: &str| header.iter().position(|h| *h == name);
    let (Some(c), Some(b), Some(w)) = (
        column("cycles"),
        column("backlash_increase_m"),
        column("wear_patch_max_m"),
    ) else {
        return (Vec::new(), None);
    };
    let volume = column("worn_volume_m3");
    let mut end_volume = None;
    let life: Vec<(f64, f64, f64)> = lines
        .filter_map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            let get = |i: usize| {
                f.get(i)
                    .and_then(|s| s.parse::<f64>().ok())
                    .filter(|v| v.is_finite())
            };
            let point = (get(c)?, get(b)? * 1e6, get(w)? * 1e6);
            end_volume = volume.and_then(get).map(|v| v * 1e9);
            Some(point)
        })
        .collect();
    // A life's cycles never fall from state to state (a pitting phase's cut is a state at the
    // cycles of the one before); a table where they do is no life.
    if life.windows(2).any(|p| p[1].0 < p[0].0) {
        return (Vec::new(), None);
    }
    (life, end_volume)
}

/// The largest departure of each run's backlash increase from the first run's, % of the
/// first's (MODEL §7: the reference comparison of a step control against fine steps): at
/// [`DEPARTURE_POINTS`] cycles evenly over the lives' common span, each curve interpolated
/// linearly between its states, where the first run's increase is at least 1 % of its largest
/// there (a ratio of two near-zero increases says nothing). 0 for the first run; None for a
/// run without a life or without such a point.
fn backlash_departure(runs: &[ComparedRun]) -> Vec<Option<f64>> {
    let first = &runs[0].life;
    let interpolate = |life: &[(f64, f64, f64)], c: f64| -> Option<f64> {
        let k = life.partition_point(|p| p.0 < c);
        match (k.checked_sub(1).map(|i| life[i]), life.get(k)) {
            (_, Some(b)) if b.0 == c => Some(b.1),
            (Some(a), Some(b)) => Some(a.1 + (b.1 - a.1) * (c - a.0) / (b.0 - a.0)),
            _ => None,
        }
    };
    runs.iter()
        .enumerate()
        .map(|(k, run)| {
            let (start, end) = (first.first()?.0, first.last()?.0.min(run.life.last()?.0));
            let points: Vec<f64> = (1..=DEPARTURE_POINTS)
                .map(|i| start + (end - start) * i as f64 / DEPARTURE_POINTS as f64)
                .collect();
            let reference: Vec<Option<f64>> =
                points.iter().map(|&c| interpolate(first, c)).collect();
            let largest = reference
                .iter()
                .flatten()
                .fold(0.0_f64, |m, v| m.max(v.abs()));
            let departures: Vec<f64> = points
                .iter()
                .zip(&reference)
                .filter_map(|(&c, r)| {
                    let r = r.filter(|r| largest > 0.0 && r.abs() >= 0.01 * largest)?;
                    Some(100.0 * (interpolate(&run.life, c)? / r - 1.0))
                })
                .collect();
            if k == 0 {
                return (!departures.is_empty()).then_some(0.0);
            }
            departures
                .into_iter()
                .max_by(|a, b| a.abs().total_cmp(&b.abs()))
        })
        .collect()
}

/// Points of the lives' common span at which [`backlash_departure`] compares the backlash.
const DEPARTURE_POINTS: usize = 40;

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
        let (life, worn_volume_mm3) = life_of(dir);
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
            life,
            worn_volume_mm3,
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
    rows.extend(life_rows(&runs));
    rows.extend(safety_rows(&summaries));
    rows.retain(|r| r.values.iter().any(Option::is_some));
    Ok(Comparison { runs, rows })
}

/// The lives' rows: the backlash increase, largest flank loss and worn volume at their ends,
/// and each backlash's departure from the first run's.
fn life_rows(runs: &[ComparedRun]) -> Vec<KeyResult> {
    vec![
        life_end_row(runs, "Backlash increase at the life's end", |l| l.1),
        life_end_row(runs, "Largest flank loss at the life's end", |l| l.2),
        KeyResult {
            quantity: "Worn volume of a flank at the life's end".into(),
            unit: "mm^3".into(),
            values: runs.iter().map(|r| r.worn_volume_mm3).collect(),
        },
        KeyResult {
            quantity: "Backlash departure from the first run".into(),
            unit: "%".into(),
            values: backlash_departure(runs),
        },
    ]
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

    fn run_with(life: Vec<(f64, f64, f64)>) -> ComparedRun {
        ComparedRun {
            label: String::new(),
            dir: PathBuf::new(),
            title: String::new(),
            differences: None,
            life,
            worn_volume_mm3: None,
        }
    }

    #[test]
    fn the_backlash_departure_is_the_largest_relative_difference_over_the_common_life() {
        // The first run's backlash rises linearly to 100 um at 1e6 cycles in 11 states; the
        // second follows it 2 % higher in 3 states (exact between them: both are linear) and
        // ends at 0.8e6; the third is 5 % lower up to 0.5e6 and 1 % lower after, with a state
        // at 0.5e6; the fourth has no life. Points where the first's increase is below 1 %
        // of its largest are left out (the second's 0-cycle state is 1 um, not 0: 2 % higher
        // there would read +inf).
        let first: Vec<(f64, f64, f64)> = (0..=10)
            .map(|i| (i as f64 * 1e5, i as f64 * 10.0, 0.0))
            .collect();
        let second = vec![(0.0, 0.0, 0.0), (0.4e6, 40.8, 0.0), (0.8e6, 81.6, 0.0)];
        let third = vec![
            (0.0, 0.0, 0.0),
            (0.5e6, 47.5, 0.0),
            (0.5e6 + 1.0, 49.50099, 0.0),
            (1e6, 99.0, 0.0),
        ];
        let runs = [first, second, third, Vec::new()].map(run_with);
        let d = backlash_departure(&runs);
        assert_eq!(d[0], Some(0.0));
        assert!((d[1].unwrap() - 2.0).abs() < 1e-9, "{d:?}");
        assert!((d[2].unwrap() + 5.0).abs() < 1e-9, "{d:?}");
        assert_eq!(d[3], None);
        // The same run against itself departs by nothing.
        let same = [runs[1].clone(), runs[1].clone()];
        assert_eq!(backlash_departure(&same), vec![Some(0.0), Some(0.0)]);
    }

    #[test]
    fn a_life_with_a_pitting_cut_is_a_life_and_one_whose_cycles_fall_is_not() {
        // A pitting phase's cut is a state at the cycles of the state before it: the table
        // must still read as a life (before, the lives with pitting phases lost their rows
        // and curves in the comparison).
        let dir = tempfile::tempdir().unwrap();
        let table = |rows: &[(f64, f64)]| {
            let mut t =
                "step,cycles,wear_patch_max_m,worn_volume_m3,backlash_increase_m\n".to_string();
            for (k, (c, b)) in rows.iter().enumerate() {
                t.push_str(&format!("{k},{c},{},{},{b}\n", 2.0 * b, 1e-9 * c));
            }
            std::fs::write(dir.path().join("wear_steps.csv"), t).unwrap();
        };
        table(&[(0.0, 0.0), (1e5, 1e-6), (1e5, 1e-6), (2e5, 3e-6)]);
        let (life, volume) = life_of(dir.path());
        assert_eq!(life.len(), 4);
        assert_eq!(life[3], (2e5, 3.0, 6.0));
        assert_eq!(volume, Some(2e5 * 1e-9 * 1e9));
        table(&[(0.0, 0.0), (1e5, 1e-6), (0.5e5, 1e-6)]);
        assert_eq!(life_of(dir.path()), (Vec::new(), None));
    }

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
