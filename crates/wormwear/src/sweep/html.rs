//! `sweep.html` of a design study ([`crate::sweep`]): the table of variants and, for every
//! numeric varied parameter, each key result against it (`plots/*.svg`), one curve per
//! combination of the other parameters' values.

use super::{Row, Sweep};
use crate::output::text::{escape, human, number};
use crate::output::OutputError;
use crate::plot::{line_chart_marked, Series};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// A key result: title, unit label, scale from SI and its value in a row.
struct Quantity {
    title: &'static str,
    unit: &'static str,
    scale: f64,
    value: fn(&Row) -> Option<f64>,
    file: &'static str,
}

const QUANTITIES: [Quantity; 8] = [
    Quantity {
        title: "Maximum pressure of the unworn pattern",
        unit: "P_max (MPa)",
        scale: 1e-6,
        value: |r| r.max_pressure_pa,
        file: "max_pressure",
    },
    Quantity {
        title: "Contact area share S0",
        unit: "S0",
        scale: 1.0,
        value: |r| r.contact_area_fraction,
        file: "s0",
    },
    Quantity {
        title: "Transmission error, peak to peak",
        unit: "TE p2p (urad)",
        scale: 1e6,
        value: |r| r.te_p2p_rad,
        file: "te_p2p",
    },
    Quantity {
        title: "Efficiency (ISO/TR 14521)",
        unit: "efficiency",
        scale: 1.0,
        value: |r| r.efficiency,
        file: "efficiency",
    },
    Quantity {
        title: "Power balance",
        unit: "power balance (%)",
        scale: 100.0,
        value: |r| r.power_balance,
        file: "power_balance",
    },
    Quantity {
        title: "Backlash increase at the end of life",
        unit: "backlash increase (um)",
        scale: 1e6,
        value: |r| r.backlash_increase_end_m,
        file: "backlash_end",
    },
    Quantity {
        title: "Largest wear depth at the end of life",
        unit: "max wear (um)",
        scale: 1e6,
        value: |r| r.max_wear_end_m,
        file: "max_wear_end",
    },
    Quantity {
        title: "Life to the backlash limit",
        unit: "life to backlash limit (million cycles)",
        scale: 1e-6,
        value: |r| r.cycles_to_backlash_limit,
        file: "life_to_backlash_limit",
    },
];

/// A parameter's value in a row as text.
fn value_text(row: &Row, name: &str) -> String {
    match row.parameters.get(name) {
        Some(serde_json::Value::String(s)) => s.clone(),
        Some(v) => v.to_string(),
        None => "(base)".into(),
    }
}

/// The charts of one numeric parameter: each quantity some row has, one series per
/// combination of the other parameters. Returns (quantity title, file) pairs.
fn parameter_charts(
    dir: &Path,
    sweep: &Sweep,
    rows: &[Row],
    index: usize,
) -> Result<Vec<(String, PathBuf)>, OutputError> {
    let name = &sweep.parameters[index];
    let others: Vec<&String> = sweep.parameters.iter().filter(|p| *p != name).collect();
    let mut charts = Vec::new();
    for q in &QUANTITIES {
        let mut groups: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
        for row in rows.iter().filter(|r| r.ok) {
            let (Some(x), Some(y)) = (
                row.parameters.get(name).and_then(|v| v.as_f64()),
                (q.value)(row),
            ) else {
                continue;
            };
            let label: Vec<String> = others
                .iter()
                .map(|o| {
                    let (label, unit, _) = human(short(o), 0.0);
                    format!("{label} = {} {unit}", value_text(row, o))
                        .trim_end()
                        .to_string()
                })
                .collect();
            let label = label.join(", ");
            match groups.iter_mut().find(|g| g.0 == label) {
                Some(g) => g.1.push((x, y * q.scale)),
                None => groups.push((label, vec![(x, y * q.scale)])),
            }
        }
        // Nothing to see where the result does not change along this parameter.
        let flat = groups.iter().all(|(_, points)| {
            points
                .iter()
                .all(|p| (p.1 - points[0].1).abs() <= 1e-9 * points[0].1.abs().max(1e-300))
        });
        if groups.is_empty() || !varies(rows, q) || flat {
            continue;
        }
        let series: Vec<Series> = groups
            .into_iter()
            .enumerate()
            .map(|(k, (label, mut points))| {
                points.sort_by(|a, b| a.0.total_cmp(&b.0));
                Series {
                    label,
                    points,
                    color: k,
                    bold: false,
                }
            })
            .collect();
        let file = PathBuf::from("plots").join(format!("{}_vs_{}.svg", q.file, slug(name)));
        let axis = axis_title(name);
        line_chart_marked(
            &dir.join(&file),
            (&format!("{} against {}", q.title, axis), &axis, q.unit),
            &series,
        )?;
        charts.push((q.title.to_string(), file));
    }
    Ok(charts)
}

/// A parameter's axis title: its last part in words with its unit, from the unit in its name
/// ("conditions.worm_torque_nm" -> "Worm torque (N m)"); the values stay in the file's units.
fn axis_title(name: &str) -> String {
    let (label, unit, _) = human(short(name), 0.0);
    if unit.is_empty() {
        label
    } else {
        format!("{label} ({unit})")
    }
}

/// Whether a quantity takes more than one value over the finished variants (a result that
/// does not change is neither charted nor tabled).
fn varies(rows: &[Row], q: &Quantity) -> bool {
    let mut values = rows.iter().filter(|r| r.ok).filter_map(|r| (q.value)(r));
    match values.next() {
        Some(first) => values.any(|v| (v - first).abs() > 1e-9 * first.abs().max(1e-300)),
        None => false,
    }
}

/// The last part of a dotted name.
fn short(name: &str) -> &str {
    name.rsplit('.').next().unwrap_or(name)
}

/// A dotted name as a file name part.
fn slug(name: &str) -> String {
    name.chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect()
}

/// The opening of a study's page (sweep.html, spread.html) up to its body, with `title`.
pub(crate) fn page_head(title: &str) -> String {
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <title>{}</title><style>\
         body{{font-family:sans-serif;max-width:1150px;margin:2em auto;color:#222}}\
         table{{border-collapse:collapse;margin:.5em 0 1em;font-size:.9em}}\
         td,th{{border:1px solid #ccc;padding:.2em .5em}} td.n{{text-align:right;\
         font-variant-numeric:tabular-nums}} tr.fail td{{color:#a40}} img{{max-width:100%}}\
         h2{{border-bottom:2px solid #1f77b4}}</style></head><body>\n",
        escape(title)
    )
}

/// Writes `dir/sweep.html` and its charts in `dir/plots`; returns the page's path.
pub fn write_html(dir: &Path, sweep: &Sweep, rows: &[Row]) -> Result<PathBuf, OutputError> {
    let plots = dir.join("plots");
    std::fs::create_dir_all(&plots).map_err(|source| OutputError::Io {
        path: plots.clone(),
        source,
    })?;
    let mut h = String::new();
    let failed = rows.iter().filter(|r| !r.ok).count();
    h.push_str(&page_head(&format!("wormwear sweep — {}", sweep.base_file)));
    let _ = write!(
        h,
        "<h1>Sweep of {base}</h1>\n<p>{n} variants ({failed} failed); stages: {stages}. \
         Every variant's full output is in <code>variants/NAME/</code>; the numbers are in \
         <a href=\"sweep.csv\">sweep.csv</a>.</p>\n",
        base = escape(&sweep.base_file),
        n = rows.len(),
        stages = sweep
            .settings
            .stages
            .iter()
            .map(|s| s.name())
            .collect::<Vec<_>>()
            .join(", ")
    );
    write_table(&mut h, sweep, rows);
    for (index, name) in sweep.parameters.iter().enumerate() {
        let charts = parameter_charts(dir, sweep, rows, index)?;
        if charts.is_empty() {
            continue;
        }
        let _ = writeln!(
            h,
            "<h2>Against {} <small>({})</small></h2>",
            escape(&axis_title(name)),
            escape(name)
        );
        for (title, file) in charts {
            let _ = writeln!(
                h,
                "<figure><img src=\"{}\" alt=\"{}\"></figure>",
                escape(&file.display().to_string()),
                escape(&title)
            );
        }
    }
    h.push_str("</body></html>\n");
    let path = dir.join("sweep.html");
    crate::output::write_atomic(&path, h.as_bytes())?;
    Ok(path)
}

/// The table of variants: name (a link to its report when there is one), parameters, key
/// results, error.
fn write_table(h: &mut String, sweep: &Sweep, rows: &[Row]) {
    let shown: Vec<&Quantity> = QUANTITIES.iter().filter(|q| varies(rows, q)).collect();
    h.push_str("<div style=\"overflow-x:auto\"><table><tr><th>variant</th>");
    for p in &sweep.parameters {
        let _ = write!(
            h,
            "<th title=\"{}\">{}</th>",
            escape(p),
            escape(&axis_title(p))
        );
    }
    for q in &shown {
        let _ = write!(h, "<th>{}</th>", escape(q.unit));
    }
    h.push_str("<th>error</th></tr>\n");
    let reports = sweep.settings.stages.contains(&crate::Stage::Report);
    for row in rows {
        let v = escape(&row.variant);
        let name = match reports && row.ok {
            true => format!("<a href=\"variants/{v}/report.html\">{v}</a>"),
            false => v,
        };
        let _ = write!(
            h,
            "<tr{}><td>{name}</td>",
            if row.ok { "" } else { " class=\"fail\"" },
        );
        for p in &sweep.parameters {
            let _ = write!(h, "<td class=\"n\">{}</td>", escape(&value_text(row, p)));
        }
        for q in &shown {
            let text = (q.value)(row).map_or(String::new(), |v| number(v * q.scale));
            let _ = write!(h, "<td class=\"n\">{text}</td>");
        }
        let _ = writeln!(
            h,
            "<td>{}</td></tr>",
            escape(row.error.as_deref().unwrap_or(""))
        );
    }
    h.push_str("</table></div>\n");
    let constant: Vec<&str> = QUANTITIES
        .iter()
        .filter(|q| !varies(rows, q))
        .map(|q| q.title)
        .collect();
    if !constant.is_empty() {
        let _ = writeln!(
            h,
            "<p>The same in every variant (or not computed), so neither tabled nor charted: {} \
             (their values are in sweep.csv).</p>",
            escape(&constant.join("; "))
        );
    }
}
