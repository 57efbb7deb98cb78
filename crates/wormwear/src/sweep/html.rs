//! `sweep.html` of a design study ([`crate::sweep`]): the table of variants and, for every
//! numeric varied parameter, each key result against it (`plots/*.svg`), one curve per
//! combination of the other parameters' values.

use super::{Row, Sweep};
use crate::output::report::escape;
use crate::output::OutputError;
use crate::plot::{line_chart, Series};
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
        title: "Frictionless power balance",
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
                .map(|o| format!("{} = {}", short(o), value_text(row, o)))
                .collect();
            let label = label.join(", ");
            match groups.iter_mut().find(|g| g.0 == label) {
                Some(g) => g.1.push((x, y * q.scale)),
                None => groups.push((label, vec![(x, y * q.scale)])),
            }
        }
        if groups.is_empty() {
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
        line_chart(
            &dir.join(&file),
            &format!("{} against {}", q.title, short(name)),
            name,
            q.unit,
            &series,
            false,
        )?;
        charts.push((q.title.to_string(), file));
    }
    Ok(charts)
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

/// Writes `dir/sweep.html` and its charts in `dir/plots`; returns the page's path.
pub fn write_html(dir: &Path, sweep: &Sweep, rows: &[Row]) -> Result<PathBuf, OutputError> {
    let plots = dir.join("plots");
    std::fs::create_dir_all(&plots).map_err(|source| OutputError::Io {
        path: plots.clone(),
        source,
    })?;
    let mut h = String::new();
    let failed = rows.iter().filter(|r| !r.ok).count();
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <title>wormwear sweep — {base}</title><style>\
         body{{font-family:sans-serif;max-width:1150px;margin:2em auto;color:#222}}\
         table{{border-collapse:collapse;margin:.5em 0 1em;font-size:.9em}}\
         td,th{{border:1px solid #ccc;padding:.2em .5em}} td.n{{text-align:right;\
         font-variant-numeric:tabular-nums}} tr.fail td{{color:#a40}} img{{max-width:100%}}\
         h2{{border-bottom:2px solid #1f77b4}}</style></head><body>\n\
         <h1>Sweep of {base}</h1>\n<p>{n} variants ({failed} failed); stages: {stages}. \
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
        let _ = writeln!(h, "<h2>Against {}</h2>", escape(name));
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
    h.push_str("<table><tr><th>variant</th>");
    for p in &sweep.parameters {
        let _ = write!(h, "<th>{}</th>", escape(p));
    }
    for q in &QUANTITIES {
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
        for q in &QUANTITIES {
            let text = (q.value)(row).map_or(String::new(), |v| format!("{:.4}", v * q.scale));
            let _ = write!(h, "<td class=\"n\">{text}</td>");
        }
        let _ = writeln!(
            h,
            "<td>{}</td></tr>",
            escape(row.error.as_deref().unwrap_or(""))
        );
    }
    h.push_str("</table>\n");
}
