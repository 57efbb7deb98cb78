//! `report.html`: one self-contained page (inline SVG, inline CSS, no network) gathering what a
//! run wrote into its output directory: the input file, the derived data of every stage from
//! summary.json, the figures of each stage in order, the ratings, the warnings and links to the
//! data files beside it (CSV tables, STL and VTK surfaces for viewing and ParaView, STEP solids
//! for CAD).

use super::text::{cycles_text, escape, human, number};
use super::{write_atomic, OutputError};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Sections of the report: title, summary.json section, figures in order: a file stem, or a
/// name prefix ending with `*` (all the files it starts, numbers in order).
const SECTIONS: [(&str, &str, &[&str]); 7] = [
    (
        "Geometry",
        "geometry",
        &["wheel_flank_outline", "section_*"],
    ),
    (
        "Unloaded meshing (TCA)",
        "tca",
        &[
            "tca_kinematic_error",
            "tca_pattern",
            "tca_sliding_speed",
            "tca_sliding_along",
            "tca_sliding_across",
        ],
    ),
    (
        "Loaded contact (LTCA)",
        "ltca",
        &[
            "ltca_load_sharing",
            "ltca_transmission_error",
            "ltca_te_orders",
            "ltca_mesh_stiffness",
            "ltca_pattern",
            "ltca_pressure_position*",
        ],
    ),
    ("Duty cycle (MODEL §14)", "duty_cycle", &["duty_cycle"]),
    (
        "Wear over life",
        "wear",
        &[
            "wear_backlash",
            "wear_depth",
            "wear_transmission_error",
            "wear_te_orders",
            "wear_pressure",
            "wear_efficiency",
            "wear_oil_temperature",
            "wear_map",
            "wear_per_cycle_map",
            "wear_film_ratio_map",
            "wear_film_thickness_map",
            "wear_damage_map",
            "wear_pattern",
            "wear_friction_coefficient_map",
            "wear_friction_power_map",
            "wear_map_step*",
            "wear_film_ratio_map_step*",
            "wear_pattern_step*",
            "wear_damage_map_step*",
        ],
    ),
    (
        "Friction, efficiency and oil temperature (MODEL §13)",
        "friction",
        &["friction_coefficient_map", "friction_power_map"],
    ),
    ("Ratings (ISO/TR 14521)", "rating", &[]),
];

/// A scalar of summary.json as table text (numbers to 6 significant digits).
fn scalar(v: &serde_json::Value) -> Option<String> {
    match v {
        serde_json::Value::Number(n) => Some(match n.as_f64() {
            Some(x) if n.is_f64() => format!("{x:.6e}")
                .parse::<f64>()
                .map(|y| format!("{y}"))
                .unwrap_or_default(),
            _ => n.to_string(),
        }),
        serde_json::Value::String(s) => Some(s.clone()),
        serde_json::Value::Bool(b) => Some(b.to_string()),
        serde_json::Value::Null => Some("-".into()),
        _ => None,
    }
}

/// The SVG files of `dir` named `pattern`.svg, or, for a pattern ending with `*`, whose names
/// start with it (sorted by name, numbers in order).
fn figures(dir: &Path, pattern: &str) -> Vec<PathBuf> {
    let (prefix, exact) = match pattern.strip_suffix('*') {
        Some(p) => (p, None),
        None => (pattern, Some(format!("{pattern}.svg"))),
    };
    let mut out: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|rd| {
            rd.filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| {
                    p.extension().is_some_and(|x| x == "svg")
                        && p.file_name().and_then(|n| n.to_str()).is_some_and(|n| {
                            exact.as_deref().map_or(n.starts_with(prefix), |e| n == e)
                        })
                })
                .collect()
        })
        .unwrap_or_default();
    // Natural order: digits compared as numbers (step2 before step16).
    let key = |p: &PathBuf| {
        let name = p
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or("")
            .to_string();
        let digits: String = name.chars().filter(|c| c.is_ascii_digit()).collect();
        let stem: String = name.chars().filter(|c| !c.is_ascii_digit()).collect();
        (stem, digits.parse::<u64>().unwrap_or(0))
    };
    out.sort_by_key(key);
    out
}

/// Writes `dir/report.html` from the files in `dir` and the input text; returns its path.
/// The phases of a life (summary.json `wear.phases`) as a bar over the cycles (wear blue,
/// pitting orange) and a table: kind, start, end, pitted share at the end. `mode` is how
/// pitting entered the life (`wear.pitting`).
fn phase_timeline(phases: &[serde_json::Value], mode: Option<&serde_json::Value>) -> String {
    let span = |p: &serde_json::Value, k: &str| p[k].as_f64().unwrap_or(0.0);
    let total = phases.last().map_or(0.0, |p| span(p, "end_cycles"));
    if total <= 0.0 {
        return String::new();
    }
    let how = match mode.and_then(|m| m.as_str()) {
        Some("forecast") => {
            "found by the forecast from the fatigue damage (README: Pitting forecast)"
        }
        Some("damage") => "from the schedule, pits from the fatigue damage",
        Some("off") => "no pitting",
        _ => "from the schedule (published coupling)",
    };
    let mut h = format!(
        "<h3>Phases</h3><p>Wear and pitting phases, {how}. Pitting: no wear, the backlash \
         flat.</p><div style=\"display:flex;height:1.4em;border:1px solid #999;margin:.5em 0\">"
    );
    for p in phases {
        let pitting = p["kind"].as_str() == Some("pitting");
        let width = 100.0 * (span(p, "end_cycles") - span(p, "start_cycles")) / total;
        let _ = write!(
            h,
            "<div title=\"{} {:.4e}-{:.4e}\" style=\"width:{width:.3}%;background:{}\"></div>",
            if pitting { "pitting" } else { "wear" },
            span(p, "start_cycles"),
            span(p, "end_cycles"),
            if pitting { "#ff7f0e" } else { "#1f77b4" }
        );
    }
    h.push_str(
        "</div><table><tr><th>phase</th><th>from (cycles)</th><th>to (cycles)</th>\
         <th>pitted share at the end (%)</th></tr>",
    );
    for p in phases {
        let _ = write!(
            h,
            "<tr><td>{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td>\
             <td class=\"n\">{}</td></tr>",
            escape(p["kind"].as_str().unwrap_or("")),
            cycles_text(span(p, "start_cycles")),
            cycles_text(span(p, "end_cycles")),
            number(100.0 * span(p, "pitted_share_end"))
        );
    }
    h.push_str("</table>");
    h
}

pub fn write_report(dir: &Path, title: &str, input_text: &str) -> Result<PathBuf, OutputError> {
    let summary: serde_json::Value =
        crate::files::read_text(&dir.join("summary.json"), crate::files::OWN_FILE_LIMIT)
            .ok()
            .and_then(|t| serde_json::from_str(&t).ok())
            .unwrap_or(serde_json::Value::Null);
    let mut h = String::new();
    page_head(&mut h, title);
    contents(&mut h, &summary);
    let hours = hours_per_cycle(&summary, input_text);
    safety_section(&mut h, &summary, hours);
    warnings_section(&mut h, &summary);
    key_results(&mut h, &summary, hours);
    for (name, key, prefixes) in SECTIONS {
        if let Some(section) = summary.get(key) {
            stage_section(&mut h, dir, (name, key, prefixes), (section, hours));
        }
    }
    files_section(&mut h, dir);
    let _ = write!(
        h,
        "<section id=\"input\"><h2>Input</h2><pre>{}</pre></section>\n</body></html>\n",
        escape(input_text)
    );
    let path = dir.join("report.html");
    write_atomic(&path, h.as_bytes())?;
    Ok(path)
}

/// The page's head, style and title.
fn page_head(h: &mut String, title: &str) {
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <title>wormwear — {t}</title><style>\
         body{{font-family:sans-serif;max-width:1150px;margin:2em auto;color:#222}}\
         h1{{font-size:1.6em}} h2{{border-bottom:2px solid #1f77b4;padding-bottom:.2em;margin-top:2em}}\
         table{{border-collapse:collapse;margin:.5em 0 1em}} td,th{{border:1px solid #ccc;padding:.2em .6em;text-align:left}}\
         td.n{{text-align:right;font-variant-numeric:tabular-nums}} figure{{margin:1em 0}}\
         figcaption{{color:#555;font-size:.9em}} pre{{background:#f6f6f6;padding:1em;overflow-x:auto;font-size:.85em}}\
         .warn{{color:#a40}} .fail{{color:#b00}} tr.fail td{{background:#fdd}} nav a{{margin-right:1em}}</style></head><body>\n\
         <h1>wormwear — {t}</h1>\n",
        t = escape(title)
    );
}

/// The contents bar: the key results, the stages the summary holds, files and input.
fn contents(h: &mut String, summary: &serde_json::Value) {
    // Contents.
    h.push_str("<nav>");
    if summary["rating"]["safety"].is_object() {
        h.push_str("<a href=\"#safety\">Safety</a>");
    }
    h.push_str("<a href=\"#key\">Key results</a>");
    for (name, key, _) in SECTIONS {
        if summary.get(key).is_some() {
            let _ = write!(h, "<a href=\"#{key}\">{}</a>", escape(name));
        }
    }
    h.push_str("<a href=\"#files\">Files</a><a href=\"#input\">Input</a></nav>\n");
}

/// The verdict of a safety row of summary.json as text ("pass", "FAIL", "needs input: ...").
fn verdict_text(v: &serde_json::Value) -> String {
    match v {
        serde_json::Value::String(s) if s == "fail" => "FAIL".into(),
        serde_json::Value::String(s) => s.clone(),
        serde_json::Value::Object(m) => m
            .iter()
            .map(|(k, v)| format!("{}: {}", k.replace('_', " "), v.as_str().unwrap_or("")))
            .collect(),
        _ => String::new(),
    }
}

/// A row's verdict, with the assumed inputs it reads ("pass, on assumed rating.x").
fn assumed_verdict(row: &serde_json::Value) -> String {
    let verdict = verdict_text(&row["verdict"]);
    let assumed: Vec<&str> = row["assumed"]
        .as_array()
        .map(|a| a.iter().filter_map(|v| v.as_str()).collect())
        .unwrap_or_default();
    match assumed.is_empty() {
        true => verdict,
        false => format!("{verdict}, on assumed {}", assumed.join(", ")),
    }
}

/// The safety table (MODEL §9.1) at the top of the page, a row in red where its safety falls
/// below its minimum.
fn safety_section(h: &mut String, summary: &serde_json::Value, hours: Option<f64>) {
    let table = &summary["rating"]["safety"];
    let Some(rows) = table["rows"].as_array() else {
        return;
    };
    let value = |v: &serde_json::Value| v.as_f64().map_or("-".into(), number);
    let safety = |v: &serde_json::Value| v.as_f64().map_or("-".into(), |x| format!("{x:.2}"));
    let failed = rows.iter().filter(|r| r["verdict"] == "fail").count();
    let life = table["required_cycles"]
        .as_f64()
        .map_or("not given".into(), |n| {
            let h = hours.map_or(String::new(), |per| format!(" ({} h)", number(n * per)));
            format!("{} wheel cycles{h}", cycles_text(n))
        });
    let _ =
        writeln!(
        h,
        "<section id=\"safety\"><h2>Safety</h2><p>From the model (MODEL §9.1): K_A {}, required \
         life {life}. {}{}</p><table><tr><th>quantity</th><th>symbol</th><th>value</th>\
         <th>allowable</th><th>unit</th><th>safety</th><th>minimum</th><th>verdict</th>\
         <th>how</th></tr>",
        table["application_factor"],
        match failed {
            0 => String::new(),
            n => format!("<b class=\"fail\">{n} safety value(s) below the minimum.</b>"),
        },
        match rows.iter().any(|r| r["assumed"].as_array().is_some_and(|a| !a.is_empty())) {
            true => " A verdict \"on assumed\" reads inputs the gear file marks as assumed \
                     (rating.assumed_inputs): replace them with your requirement and your \
                     material's data, and take them off the list.",
            false => "",
        }
    );
    for r in rows {
        let class = if r["verdict"] == "fail" {
            " class=\"fail\""
        } else {
            ""
        };
        let _ = writeln!(
            h,
            "<tr{class}><td>{}</td><td>{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td>\
             <td>{}</td><td class=\"n\"><b>{}</b></td><td class=\"n\">{}</td><td>{}</td>\
             <td><details><summary>how</summary>{}</details></td></tr>",
            escape(r["quantity"].as_str().unwrap_or("")),
            escape(r["symbol"].as_str().unwrap_or("")),
            value(&r["value"]),
            value(&r["allowable"]),
            escape(r["unit"].as_str().unwrap_or("")),
            safety(&r["safety"]),
            value(&r["minimum"]),
            escape(&assumed_verdict(r)),
            escape(r["source"].as_str().unwrap_or(""))
        );
    }
    h.push_str("</table>");
    back_driving_rows(h, summary);
    h.push_str("</section>\n");
}

/// Beside the safety table: whether the wheel can drive the worm (MODEL §15), at rest and
/// running, each with its verdict and margin.
fn back_driving_rows(h: &mut String, summary: &serde_json::Value) {
    let lock = &summary["friction"]["self_locking"];
    let (Some(at_rest), Some(running)) = (
        lock["static_efficiency"].as_f64(),
        lock["dynamic_efficiency"].as_f64(),
    ) else {
        return;
    };
    let verdict = |locked: &serde_json::Value| match locked.as_bool() {
        Some(true) => "self-locking",
        _ => "back-drivable",
    };
    let margin = format!(
        "boundary friction {} against the {:.4} the gear locks from",
        number(lock["boundary_friction"].as_f64().unwrap_or(f64::NAN)),
        lock["locking_friction"].as_f64().unwrap_or(f64::NAN)
    );
    let _ = write!(
        h,
        "<table><tr><th>back-driving (MODEL §15)</th><th>efficiency eta'</th><th>verdict</th>\
         <th>how</th></tr><tr><td>static: the wheel driving from rest (boundary friction)</td>\
         <td class=\"n\">{at_rest:.3}</td><td>{}</td><td>{}</td></tr><tr><td>dynamic: the wheel \
         driving at the running speed (the contact's friction)</td><td class=\"n\">{running:.3}\
         </td><td>{}</td><td>eta' = (W - u M1) / (W - M2) from the loaded analysis' moments; \
         at or below 0 the gear self-locks</td></tr></table>",
        verdict(&lock["static_self_locking"]),
        escape(&margin),
        verdict(&lock["dynamic_self_locking"]),
    );
}

/// The warnings of every stage.
fn warnings_section(h: &mut String, summary: &serde_json::Value) {
    // Warnings of every stage.
    let mut warnings = Vec::new();
    if let serde_json::Value::Object(m) = &summary {
        for (stage, v) in m {
            if let Some(serde_json::Value::Array(ws)) = v.get("warnings") {
                for w in ws {
                    if let Some(w) = w.as_str() {
                        warnings.push(format!("{stage}: {w}"));
                    }
                }
            }
        }
    }
    h.push_str("<section id=\"warnings\"><h2>Warnings</h2>");
    if warnings.is_empty() {
        h.push_str("<p>None.</p>");
    } else {
        h.push_str("<ul>");
        for w in &warnings {
            let _ = write!(h, "<li class=\"warn\">{}</li>", escape(w));
        }
        h.push_str("</ul>");
    }
    h.push_str("</section>\n");
}

/// The key results: (label, where in summary.json — a stage's section, or `END` for the last
/// wear state — key (dotted: nested), scale to the unit, unit).
const KEY_RESULTS: [(&str, &str, &str, f64, &str); 24] = [
    ("Ratio", "geometry", "ratio", 1.0, ""),
    ("Lead angle", "geometry", "lead_angle_deg", 1.0, "deg"),
    (
        "Worm torque T1 (loaded analysis)",
        "ltca",
        "worm_torque_nm",
        1.0,
        "N m",
    ),
    (
        "Wheel torque T2 the pressures carry",
        "ltca",
        "wheel_torque_nm",
        1.0,
        "N m",
    ),
    (
        "Mesh efficiency of those torques, T2 / (u T1)",
        "ltca",
        "mesh_efficiency",
        1.0,
        "",
    ),
    (
        "Max contact pressure (unworn)",
        "ltca",
        "max_pressure_pa",
        1e-6,
        "MPa",
    ),
    (
        "Loaded pattern S0",
        "ltca",
        "contact_area_fraction",
        1.0,
        "",
    ),
    (
        "Transmission error, peak to peak",
        "ltca",
        "te_p2p_rad",
        1e6,
        "urad",
    ),
    (
        "Mesh stiffness (mean)",
        "ltca",
        "mesh_stiffness_mean_nm_per_rad",
        1.0,
        "N m/rad",
    ),
    ("Efficiency (ISO/TR 14521)", "rating", "efficiency", 1.0, ""),
    (
        "Efficiency from the contact's friction",
        "friction",
        "efficiency.total_efficiency",
        1.0,
        "",
    ),
    (
        "Back-driving efficiency at rest (<= 0: self-locking, MODEL §15)",
        "friction",
        "self_locking.static_efficiency",
        1.0,
        "",
    ),
    (
        "Back-driving efficiency running (<= 0: self-locking)",
        "friction",
        "self_locking.dynamic_efficiency",
        1.0,
        "",
    ),
    ("Oil temperature", "friction", "oil_temperature_k", 1.0, "C"),
    (
        "Output power (contact's friction)",
        "friction",
        "efficiency.output_power_w",
        1.0,
        "W",
    ),
    (
        "Worm torque (ISO/TR 14521)",
        "rating",
        "worm_torque_nm",
        1.0,
        "N m",
    ),
    (
        "Pitting life N_LI",
        "rating",
        "n_li_cycles",
        1.0,
        "wheel cycles",
    ),
    ("Life simulated", END, "cycles", 1.0, "wheel cycles"),
    (
        "Max wear at the end (patch mean)",
        END,
        "wear_patch_max_m",
        1e6,
        "um",
    ),
    (
        "Max wear at the end (one node)",
        END,
        "max_wear_m",
        1e6,
        "um",
    ),
    (
        "Backlash increase at the end",
        END,
        "backlash_increase_m",
        1e6,
        "um",
    ),
    (
        "Max contact pressure at the end",
        END,
        "max_pressure_pa",
        1e-6,
        "MPa",
    ),
    (
        "Duty cycle: efficiency over the energy (MODEL §14)",
        "duty_cycle",
        "total_efficiency",
        1.0,
        "",
    ),
    (
        "Duty cycle: first pit by Miner's sum over the bins (unworn)",
        "duty_cycle",
        "pitting_life_cycles",
        1.0,
        "wheel cycles",
    ),
];

/// The section name of [`KEY_RESULTS`] that stands for the last wear state.
const END: &str = "";

/// Key results first: what an engineer looks for before the details.
fn key_results(h: &mut String, summary: &serde_json::Value, hours: Option<f64>) {
    let last_step = summary["wear"]["steps"]
        .as_array()
        .and_then(|s| s.last())
        .cloned()
        .unwrap_or(serde_json::Value::Null);
    h.push_str("<section id=\"key\"><h2>Key results</h2><table>");
    for (label, section, key, scale, unit) in KEY_RESULTS {
        let value = if section == END {
            &last_step[key]
        } else {
            // A dotted key reads a nested value.
            key.split('.').fold(&summary[section], |v, part| &v[part])
        };
        if let Some(x) = value.as_f64() {
            let (text, unit) = match (unit, hours) {
                ("C", _) => (number(x - 273.15), unit.to_string()),
                ("wheel cycles", Some(per)) => (
                    cycles_text(x),
                    format!("wheel cycles ({} h at the running speed)", number(x * per)),
                ),
                ("wheel cycles", None) => (cycles_text(x), unit.to_string()),
                _ => (number(x * scale), unit.to_string()),
            };
            let _ = write!(
                h,
                "<tr><th>{}</th><td class=\"n\">{}</td><td>{}</td></tr>",
                escape(label),
                escape(&text),
                escape(&unit)
            );
        }
    }
    h.push_str("</table></section>\n");
}

/// One stage's section: its scalars, its phase timeline and wear-state table when it has
/// them, and its figures (inline SVG).
fn stage_section(
    h: &mut String,
    dir: &Path,
    (name, key, prefixes): (&str, &str, &[&str]),
    (section, hours): (&serde_json::Value, Option<f64>),
) {
    let _ = write!(h, "<section id=\"{key}\"><h2>{}</h2>", escape(name));
    // Scalars of the section as a table; the wear steps as their own table.
    if let serde_json::Value::Object(m) = section {
        h.push_str("<table><tr><th>quantity</th><th>value</th><th>unit</th></tr>");
        for (k, v) in m {
            let (label, value, unit) = match v.as_f64() {
                Some(x) => {
                    let (label, unit, x) = human(k, x);
                    (label, number(x), unit)
                }
                None => match scalar(v) {
                    Some(text) => (human(k, 0.0).0, text, String::new()),
                    None => continue,
                },
            };
            let _ = write!(
                h,
                "<tr><th>{}</th><td class=\"n\">{}</td><td>{}</td></tr>",
                escape(&label),
                escape(&value),
                escape(&unit)
            );
        }
        h.push_str("</table>");
    }
    if let Some(serde_json::Value::Array(phases)) = section.get("phases") {
        h.push_str(&phase_timeline(phases, section.get("pitting")));
    }
    if let Some(serde_json::Value::Array(steps)) = section.get("steps") {
        wear_states_table(h, steps, hours);
    }
    if let Some(serde_json::Value::Array(bins)) = section.get("bins") {
        duty_cycle_table(h, bins);
    }
    for prefix in prefixes {
        let paths = figures(dir, prefix);
        match prefix.strip_suffix('*') {
            Some(series) if !paths.is_empty() => state_figures(h, series, &paths),
            _ => paths.iter().for_each(|path| inline_figure(h, path)),
        }
    }
    h.push_str("</section>\n");
}

/// The file name of `path` as text.
fn file_name(path: &Path) -> String {
    path.file_name()
        .and_then(|n| n.to_str())
        .unwrap_or_default()
        .to_string()
}

/// A figure inline (its SVG in the page).
fn inline_figure(h: &mut String, path: &Path) {
    let Ok(svg) = crate::files::read_text(path, crate::files::OWN_FILE_LIMIT) else {
        return;
    };
    if let Some(k) = svg.find("<svg") {
        let _ = writeln!(
            h,
            "<figure>{}<figcaption>{}</figcaption></figure>",
            &svg[k..],
            escape(&file_name(path))
        );
    }
}

/// A map at every state, folded: the files beside the report, loaded when opened (the page
/// stays small; the last state's map is inline in its section).
fn state_figures(h: &mut String, series: &str, paths: &[PathBuf]) {
    let _ = write!(
        h,
        "<details><summary>{} at every map state ({} files, loaded when opened)</summary>",
        escape(series.trim_end_matches('_')),
        paths.len()
    );
    for path in paths {
        let name = escape(&file_name(path));
        let _ = write!(
            h,
            "<figure><img loading=\"lazy\" src=\"{name}\" alt=\"{name}\" \
             style=\"max-width:100%\"><figcaption>{name}</figcaption></figure>"
        );
    }
    h.push_str("</details>\n");
}

/// Hours per wheel cycle at the running speed: the ratio (summary's geometry) over the worm
/// speed (the input's `conditions.worm_speed_rpm`); None when either is missing.
fn hours_per_cycle(summary: &serde_json::Value, input_text: &str) -> Option<f64> {
    let ratio = summary["geometry"]["ratio"].as_f64()?;
    // Under a duty cycle, its time-weighted mean speed (MODEL §14).
    let mean = summary["duty_cycle"]["mean_worm_speed_rpm"].as_f64();
    let given = || -> Option<f64> {
        let input: toml::Table = input_text.parse().ok()?;
        let rpm = input.get("conditions")?.get("worm_speed_rpm")?;
        rpm.as_float()
            .or_else(|| rpm.as_integer().map(|i| i as f64))
    };
    let rpm = mean.or_else(given)?;
    (rpm > 0.0).then(|| ratio / (rpm * 60.0))
}

/// The duty cycle's bins (MODEL §14) as a table: load, speed, shares, oil temperature,
/// efficiency, pressures and each bin's share of the wear and of the pitting damage.
fn duty_cycle_table(h: &mut String, bins: &[serde_json::Value]) {
    const COLUMNS: [(&str, &str, f64, usize); 13] = [
        ("bin", "bin", 1.0, 0),
        ("worm torque (N m)", "worm_torque_nm", 1.0, 2),
        ("wheel torque (N m)", "wheel_torque_nm", 1.0, 1),
        ("worm speed (rpm)", "worm_speed_rpm", 1.0, 0),
        ("time share", "time_share", 1.0, 3),
        ("cycle share", "cycle_share", 1.0, 3),
        ("oil (C)", "oil_temperature_c", 1.0, 1),
        ("efficiency", "total_efficiency", 1.0, 4),
        ("P_patch (MPa)", "pressure_patch_max_pa", 1e-6, 0),
        (
            "p_eq,2% (MPa)",
            "equivalent_pressure_first_pitting_pa",
            1e-6,
            0,
        ),
        ("largest p_eq (MPa)", "equivalent_pressure_max_pa", 1e-6, 0),
        ("wear share (%)", "wear_share", 100.0, 1),
        ("damage share (%)", "damage_share", 100.0, 1),
    ];
    h.push_str("<table><tr>");
    for (label, ..) in COLUMNS {
        let _ = write!(h, "<th>{}</th>", escape(label));
    }
    h.push_str("</tr>");
    for b in bins {
        h.push_str("<tr>");
        for (_, key, scale, decimals) in COLUMNS {
            let text = b[key]
                .as_f64()
                .map_or("-".into(), |v| format!("{:.*}", decimals, v * scale));
            let _ = write!(h, "<td class=\"n\">{text}</td>");
        }
        h.push_str("</tr>");
    }
    h.push_str("</table>");
}

/// The wear states as a folded table.
fn wear_states_table(h: &mut String, steps: &[serde_json::Value], hours: Option<f64>) {
    let columns = [
        ("cycles", 1.0, "cycles"),
        ("phase", 1.0, "phase"),
        ("max_wear_m", 1e6, "max wear (um)"),
        ("mean_wear_m", 1e6, "mean wear (um)"),
        ("backlash_increase_m", 1e6, "backlash increase (um)"),
        ("max_pressure_pa", 1e-6, "P_max (MPa)"),
        ("mean_pressure_pa", 1e-6, "P_mean (MPa)"),
        ("contact_area_fraction", 1.0, "S0"),
        ("te_mean_rad", 1e6, "TE mean (urad)"),
    ];
    h.push_str("<details><summary>Wear states (table)</summary><table><tr>");
    for (_, _, label) in columns {
        let _ = write!(h, "<th>{label}</th>");
        if label == "cycles" && hours.is_some() {
            h.push_str("<th>hours</th>");
        }
    }
    h.push_str("</tr>");
    for s in steps {
        h.push_str("<tr>");
        for (k, scale, _) in columns {
            let cell = match &s[k] {
                serde_json::Value::Number(n) if k == "cycles" => {
                    cycles_text(n.as_f64().unwrap_or(f64::NAN))
                }
                serde_json::Value::Number(n) => number(n.as_f64().unwrap_or(f64::NAN) * scale),
                other => scalar(other).unwrap_or_default(),
            };
            let _ = write!(h, "<td class=\"n\">{}</td>", escape(&cell));
            if let (Some(per), "cycles") = (hours, k) {
                let hrs = s[k].as_f64().unwrap_or(f64::NAN) * per;
                let _ = write!(h, "<td class=\"n\">{}</td>", number(hrs));
            }
        }
        h.push_str("</tr>");
    }
    h.push_str("</table></details>");
}

/// The data files beside the report (relative links: they open from the same directory).
fn files_section(h: &mut String, dir: &Path) {
    // The data files beside the report (relative links: they open from the same directory).
    let mut files: Vec<String> = std::fs::read_dir(dir)
        .map(|rd| {
            rd.filter_map(|e| e.ok())
                .filter_map(|e| e.file_name().to_str().map(String::from))
                .filter(|n| {
                    [".vtp", ".stl", ".step", ".csv", ".json"]
                        .iter()
                        .any(|x| n.ends_with(x))
                })
                .collect()
        })
        .unwrap_or_default();
    files.sort();
    h.push_str(
        "<section id=\"files\"><h2>Files</h2><p>Beside this page: <code>.vtp</code> surfaces \
         with their results for ParaView (File > Open; colour by an array, e.g. \
         <code>wear_um</code>), STL for viewing, with <code>--step</code> the STEP solids for \
         CAD (mm, worm frame: worm and wheel assemble at the centre distance), CSV tables, \
         <code>summary.json</code>.</p><ul>",
    );
    for f in &files {
        let _ = write!(h, "<li><a href=\"{f}\">{f}</a></li>", f = escape(f));
    }
    h.push_str("</ul></section>\n");
}

#[cfg(test)]
mod human_tests {
    use super::*;

    #[test]
    fn keys_read_as_labels_with_units() {
        let (l, u, x) = human("max_pressure_pa", 1.862089e9);
        assert_eq!(
            (l.as_str(), u.as_str(), number(x).as_str()),
            ("Max pressure", "MPa", "1862")
        );
        let (l, u, x) = human("te_p2p_rad", 5.025e-5);
        assert_eq!((l.as_str(), u.as_str()), ("TE peak to peak", "urad"));
        assert!((x - 50.25).abs() < 1e-9);
        let (l, u, x) = human("oil_temperature_k", 333.0);
        assert_eq!(
            (l.as_str(), u.as_str(), number(x).as_str()),
            ("Oil temperature", "C", "59.85")
        );
        let (l, u, x) = human("contact_area_fraction", 0.936);
        assert_eq!(
            (l.as_str(), u.as_str(), number(x).as_str()),
            ("Contact area", "%", "93.60")
        );
        let (l, u, _) = human("mesh_stiffness_mean_nm_per_rad", 4.3e5);
        assert_eq!((l.as_str(), u.as_str()), ("Mesh stiffness mean", "N m/rad"));
        let (l, u, _) = human("states", 26.0);
        assert_eq!((l.as_str(), u.as_str()), ("States", ""));
        assert_eq!(cycles_text(180000.4), "180 000");
        assert_eq!(cycles_text(1234567.0), "1 234 567");
        assert_eq!(cycles_text(999.0), "999");
    }
}
