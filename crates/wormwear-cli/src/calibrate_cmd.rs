//! `wormwear calibrate`: the Archard coefficient K from wear tests or from a measured backlash
//! curve (MODEL §10), written to the `calibration` section of summary.json.
use anyhow::{anyhow, Context};
use std::path::Path;
use wormwear::calibration::{self, WearTest};
use wormwear::input::GearSet;

/// Numeric table of a CSV file with a header row: the named columns, in that order, per data
/// row. Errors name the file, the line and the column.
pub fn read_table(path: &Path, columns: &[&str]) -> anyhow::Result<Vec<Vec<f64>>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let (_, header) = lines
        .next()
        .ok_or_else(|| anyhow!("{}: empty file (expected a header row)", path.display()))?;
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let index: Vec<usize> = columns
        .iter()
        .map(|c| {
            names.iter().position(|n| n == c).ok_or_else(|| {
                anyhow!(
                    "{}: no column '{c}' in the header (expected: {})",
                    path.display(),
                    columns.join(", ")
                )
            })
        })
        .collect::<anyhow::Result<_>>()?;
    let mut rows = Vec::new();
    for (line, l) in lines {
        let fields: Vec<&str> = l.split(',').map(str::trim).collect();
        let row = index
            .iter()
            .zip(columns)
            .map(|(&k, c)| {
                let f = fields.get(k).copied().unwrap_or("");
                f.parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| {
                        anyhow!(
                            "{}:{}: column '{c}' = '{f}' is not a finite number",
                            path.display(),
                            line + 1
                        )
                    })
            })
            .collect::<anyhow::Result<Vec<f64>>>()?;
        rows.push(row);
    }
    if rows.is_empty() {
        return Err(anyhow!("{}: no data rows", path.display()));
    }
    Ok(rows)
}

/// Wear tests from CSV (columns `worn_volume_mm3, sliding_length_m, apparent_area_mm2,
/// film_thickness_um, roughness_rq_um, slope_rdq`), with W_asp from the gear file's materials.
pub fn tests_from_csv(gear: &GearSet, path: &Path) -> anyhow::Result<Vec<WearTest>> {
    let rows = read_table(
        path,
        &[
            "worn_volume_mm3",
            "sliding_length_m",
            "apparent_area_mm2",
            "film_thickness_um",
            "roughness_rq_um",
            "slope_rdq",
        ],
    )?;
    let (w1, w2) = (&gear.worm_material, &gear.wheel_material);
    let e_prime = wormwear::lubrication::reduced_modulus(
        w1.youngs_modulus,
        w1.poisson_ratio,
        w2.youngs_modulus,
        w2.poisson_ratio,
    );
    rows.iter()
        .enumerate()
        .map(|(k, r)| {
            if r[4] <= 0.0 {
                return Err(anyhow!(
                    "{}: data row {}: roughness_rq_um = {} (must be > 0)",
                    path.display(),
                    k + 1,
                    r[4]
                ));
            }
            Ok(WearTest {
                worn_volume: r[0] * 1e-9,
                sliding_length: r[1],
                asperity_load: calibration::asperity_load(
                    e_prime,
                    r[5],
                    r[3] * 1e-6,
                    r[4] * 1e-6,
                    r[2] * 1e-6,
                ),
            })
        })
        .collect()
}

/// Measured backlash increase from CSV (columns `cycles, backlash_increase_um`): (cycles, m).
pub fn backlash_from_csv(path: &Path) -> anyhow::Result<Vec<(f64, f64)>> {
    let rows = read_table(path, &["cycles", "backlash_increase_um"])?;
    Ok(rows.iter().map(|r| (r[0], r[1] * 1e-6)).collect())
}
