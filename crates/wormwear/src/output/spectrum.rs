//! The duty cycle's files (MODEL §14): `duty_cycle.csv` (one row per bin), `duty_cycle.svg`
//! (each bin's share of the running time, the cycles, the wear and the pitting damage, as bars)
//! and summary.json's `duty_cycle` section.

use super::{to_json, update_summary, write_atomic, Csv, OutputError};
use crate::spectrum::Spectrum;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The columns of `duty_cycle.csv`, SI units in their names.
const COLUMNS: &[&str] = &[
    "bin",
    "worm_torque_nm",
    "wheel_torque_nm",
    "worm_speed_rpm",
    "time_share",
    "cycle_share",
    "oil_temperature_c",
    "input_power_w",
    "output_power_w",
    "mesh_loss_w",
    "total_loss_w",
    "mesh_efficiency",
    "total_efficiency",
    "max_pressure_pa",
    "pressure_patch_max_pa",
    "equivalent_pressure_max_pa",
    "equivalent_pressure_first_pitting_pa",
    "max_wear_per_cycle_m",
    "worn_volume_per_cycle_m3",
    "wear_share",
    "damage_share",
    "pitting_life_cycles",
];

/// `duty_cycle.csv`: one row per bin ([`COLUMNS`]; a pitting life without pressure is NaN).
pub fn spectrum_csv(spectrum: &Spectrum) -> Csv {
    let mut csv = Csv::new(COLUMNS);
    for b in &spectrum.bins {
        csv.row(&[
            b.bin as f64,
            b.worm_torque_nm,
            b.wheel_torque_nm,
            b.worm_speed_rpm,
            b.time_share,
            b.cycle_share,
            b.oil_temperature_c,
            b.input_power_w,
            b.output_power_w,
            b.mesh_loss_w,
            b.total_loss_w,
            b.mesh_efficiency,
            b.total_efficiency,
            b.max_pressure_pa,
            b.pressure_patch_max_pa,
            b.equivalent_pressure_max_pa,
            b.equivalent_pressure_first_pitting_pa,
            b.max_wear_per_cycle_m,
            b.worn_volume_per_cycle_m3,
            b.wear_share,
            b.damage_share,
            b.pitting_life_cycles.unwrap_or(f64::NAN),
        ]);
    }
    csv
}

/// Writes `duty_cycle.csv`, `duty_cycle.svg` and summary.json's `duty_cycle` section. Returns
/// the files written.
pub fn write_spectrum(spectrum: &Spectrum, dir: &Path) -> Result<Vec<PathBuf>, OutputError> {
    update_summary(dir, "duty_cycle", to_json("duty_cycle", spectrum)?)?;
    let csv = dir.join("duty_cycle.csv");
    spectrum_csv(spectrum).write(&csv)?;
    let svg = dir.join("duty_cycle.svg");
    write_atomic(&svg, shares_chart(spectrum).as_bytes())?;
    Ok(vec![csv, svg])
}

/// The bars of one bin: (label, share, colour) for the time, the cycles, the wear and the
/// damage.
const BARS: [(&str, usize); 4] = [
    ("running time", 5),
    ("wheel cycles", 0),
    ("wear (worn volume per cycle)", 4),
    ("pitting damage (Miner's sum)", 1),
];

/// The bar chart of each bin's shares (SVG text, 1000 x 560 px): one group of [`BARS`] per bin,
/// labelled with the bin's torques and speed, the shares in per cent.
pub fn shares_chart(spectrum: &Spectrum) -> String {
    let (width, height) = (1000.0, 560.0);
    let (left, right, top, bottom) = (80.0, 20.0, 90.0, 80.0);
    let plot_w = width - left - right;
    let plot_h = height - top - bottom;
    let n = spectrum.bins.len().max(1) as f64;
    let group = plot_w / n;
    let bar = 0.8 * group / BARS.len() as f64;
    let y = |share: f64| top + plot_h * (1.0 - share.clamp(0.0, 1.0));
    let mut svg = String::new();
    let _ = write!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" viewBox="0 0 {width} {height}" font-family="sans-serif">
<rect width="100%" height="100%" fill="white"/>
<text x="{}" y="30" font-size="20" text-anchor="middle">Duty cycle: each bin's share of the time, the cycles, the wear and the pitting damage (unworn)</text>
"#,
        width / 2.0
    );
    for k in 0..=4 {
        let share = k as f64 * 0.25;
        let _ = writeln!(
            svg,
            r##"<line x1="{left}" x2="{}" y1="{y:.1}" y2="{y:.1}" stroke="#ebebeb"/><text x="{}" y="{:.1}" font-size="15" text-anchor="end">{}</text>"##,
            width - right,
            left - 8.0,
            y(share) + 5.0,
            k * 25,
            y = y(share)
        );
    }
    let _ = writeln!(
        svg,
        r#"<text x="22" y="{:.1}" font-size="17" text-anchor="middle" transform="rotate(-90 22 {:.1})">share (%)</text>"#,
        top + plot_h / 2.0,
        top + plot_h / 2.0
    );
    for (k, b) in spectrum.bins.iter().enumerate() {
        let x0 = left + group * k as f64 + 0.1 * group;
        let values = [b.time_share, b.cycle_share, b.wear_share, b.damage_share];
        for (m, ((_, color), v)) in BARS.iter().zip(values).enumerate() {
            let c = crate::plot::COLORS[*color];
            let _ = writeln!(
                svg,
                r#"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="rgb({},{},{})"><title>{:.1} %</title></rect>"#,
                x0 + bar * m as f64,
                y(v),
                bar * 0.9,
                (y(0.0) - y(v)).max(0.0),
                c.0,
                c.1,
                c.2,
                100.0 * v
            );
        }
        let _ = writeln!(
            svg,
            r#"<text x="{:.1}" y="{:.1}" font-size="15" text-anchor="middle">bin {}: {:.0} N m on the worm, {:.0} rpm</text>"#,
            left + group * (k as f64 + 0.5),
            top + plot_h + 24.0,
            b.bin,
            b.worm_torque_nm,
            b.worm_speed_rpm
        );
    }
    let _ = writeln!(
        svg,
        r#"<line x1="{left}" x2="{}" y1="{:.1}" y2="{:.1}" stroke="black"/>"#,
        width - right,
        y(0.0),
        y(0.0)
    );
    legend(&mut svg, left);
    svg.push_str("</svg>\n");
    svg
}

/// The legend of [`shares_chart`]: a swatch and a label per bar, in a row from `left`.
fn legend(svg: &mut String, left: f64) {
    let mut x = left;
    for (label, color) in BARS {
        let c = crate::plot::COLORS[color];
        let _ = writeln!(
            svg,
            r#"<rect x="{x:.1}" y="52" width="14" height="14" fill="rgb({},{},{})"/><text x="{:.1}" y="64" font-size="14">{label}</text>"#,
            c.0,
            c.1,
            c.2,
            x + 20.0
        );
        // About 7.5 px a character at 14 px.
        x += 20.0 + 7.5 * label.len() as f64 + 24.0;
    }
}
