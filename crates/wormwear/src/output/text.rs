//! Text of the written reports: HTML escapes, engineering numbers, summary.json's keys as
//! labels with units, cycles in groups of three digits.

/// `s` as HTML text (also inside attribute values).
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A number for the table: four significant digits, integers as integers.
pub fn number(v: f64) -> String {
    // Whole numbers plainly up to a million (180000 cycles), beyond it as the others: a
    // stiffness of 50693969 N/m reads 5.069e7.
    if (v - v.round()).abs() <= 1e-9 * v.abs().max(1.0) && v.abs() < 1e6 {
        format!("{v:.0}")
    } else if v.abs() >= 1e5 || v.abs() < 1e-3 {
        format!("{v:.3e}")
    } else {
        let digits = (3 - v.abs().log10().floor() as i32).max(0) as usize;
        format!("{v:.digits$}")
    }
}

/// Units of summary.json's keys by their suffix: (suffix, unit shown, factor). The longest
/// suffix that matches wins; SI values become the units an engineer reads (MPa, um, urad).
const UNITS: &[(&str, &str, f64)] = &[
    ("_nm_per_rad", "N m/rad", 1.0),
    ("_rad_per_nm", "urad/(N m)", 1e6),
    ("_n_per_m", "N/m", 1.0),
    ("_w_m2", "W/m^2", 1.0),
    ("_pa_s", "Pa s", 1.0),
    ("_m_s", "m/s", 1.0),
    ("_mm2", "mm^2", 1.0),
    ("_m3", "mm^3", 1e9),
    ("_mpa", "MPa", 1.0),
    ("_gpa", "GPa", 1.0),
    ("_deg", "deg", 1.0),
    ("_rpm", "rpm", 1.0),
    ("_mm", "mm", 1.0),
    ("_um", "um", 1.0),
    ("_pa", "MPa", 1e-6),
    ("_rad", "urad", 1e6),
    ("_nm", "N m", 1.0),
    ("_m", "um", 1e6),
    ("_w", "W", 1.0),
    ("_k", "C", 1.0),
    ("_c", "C", 1.0),
    ("_n", "N", 1.0),
    ("_cycles", "wheel cycles", 1.0),
    ("_percent", "%", 1.0),
    ("_fraction", "%", 100.0),
    ("_share", "%", 100.0),
];

/// A summary.json key and value as a label, a unit and the value in that unit: the key's unit
/// suffix read ([`UNITS`]), the rest in words ("max_pressure_pa", 1.86e9 -> "Max pressure",
/// "MPa", 1860); kelvin to Celsius.
pub fn human(key: &str, value: f64) -> (String, String, f64) {
    let (stem, unit, x) = match UNITS.iter().find(|(suffix, ..)| key.ends_with(suffix)) {
        Some((suffix, unit, factor)) => {
            let stem = &key[..key.len() - suffix.len()];
            let x = if *suffix == "_k" {
                value - 273.15
            } else {
                value * factor
            };
            (stem.to_string(), unit.to_string(), x)
        }
        None => (key.to_string(), String::new(), value),
    };
    let words: Vec<String> = stem
        .split('_')
        .filter(|w| !w.is_empty())
        .map(|w| match w {
            "te" => "TE".to_string(),
            "p2p" => "peak to peak".to_string(),
            "ke" => "KE".to_string(),
            "iso" => "ISO".to_string(),
            "ltca" => "LTCA".to_string(),
            "tca" => "TCA".to_string(),
            _ => w.to_string(),
        })
        .collect();
    let mut label = words.join(" ");
    if let Some(first) = label.get(..1) {
        label = first.to_uppercase() + &label[1..];
    }
    (label, unit, x)
}

/// Wheel cycles as a whole number with thin groups of three digits ("180 000"; "-" when not
/// finite).
pub fn cycles_text(cycles: f64) -> String {
    if cycles.is_finite() {
        crate::wear::grouped(cycles)
    } else {
        "-".into()
    }
}
