//! `wormwear calibrate`: the Archard coefficient K from wear tests or from a measured backlash
//! curve (MODEL §10), written to the `calibration` section of summary.json.
use anyhow::{anyhow, Context};
use std::path::Path;
use wormwear::calibration::{self, WearTest};
use wormwear::input::GearSet;

/// Numeric table of a CSV file with a header row: the named columns, in that order, per data
/// row. Errors name the file, the line and the column.
pub fn read_table(path: &Path, columns: &[&str]) -> anyhow::Result<Vec<Vec<f64>>> {
    let text = wormwear::files::read_text(path, wormwear::files::INPUT_LIMIT)
        .with_context(|| format!("cannot read {}", path.display()))?;
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

/// K by least squares on wear tests (`--tests`); returns the `calibration` section.
pub fn from_tests(
    gear: &GearSet,
    path: &Path,
    quiet: bool,
) -> Result<serde_json::Value, crate::Failure> {
    use crate::Failure;
    let data = tests_from_csv(gear, path).map_err(Failure::Input)?;
    let fit = calibration::fit_from_tests(&data, gear.wheel_material.hardness)
        .map_err(|e| Failure::Input(anyhow::Error::new(e).context(path.display().to_string())))?;
    if !quiet {
        println!(
            "K = {:.4e} from {} wear tests (relative rms residual {:.3})",
            fit.k, fit.points, fit.relative_rms
        );
    }
    Ok(serde_json::json!({
        "method": "wear tests",
        "data": path.display().to_string(),
        "k": fit.k,
        "relative_rms": fit.relative_rms,
        "points": fit.points,
    }))
}

/// K from a measured backlash curve (`--backlash`) through the life simulation: the curves
/// side by side in `dir`; returns the `calibration` section.
pub fn from_backlash(
    gear: &GearSet,
    file: &Path,
    dir: &Path,
    path: &Path,
    no_pitting: bool,
    quiet: bool,
    verbose: bool,
) -> Result<serde_json::Value, crate::Failure> {
    use crate::Failure;
    use calibration::CalibrationError;
    let measured = backlash_from_csv(path).map_err(Failure::Input)?;
    let last = measured.iter().map(|m| m.0).fold(0.0, f64::max);
    let args = crate::LifeArgs {
        cycles: Some(last.max(1.0)),
        no_pitting,
        ..Default::default()
    };
    let plan = crate::request::life_plan(gear, &args)?;
    let mut on_event = |event: wormwear::Event| -> Result<(), wormwear::RunError> {
        if let (wormwear::Event::Bending(info), false) = (event, quiet) {
            crate::print_bending(info);
        }
        Ok(())
    };
    let mut on_run = |run: usize, k: f64, records: &[wormwear::wear::StepRecord]| {
        if verbose {
            let b = records.last().map_or(0.0, |r| r.backlash_increase_m);
            eprintln!(
                "run {run}: K = {k:.5e}, backlash +{:.2} um at {} cycles",
                b * 1e6,
                wormwear::output::cycles_label(last)
            );
        }
    };
    let (fit, records, runs) =
        calibration::fit_life_to_backlash(gear, &plan, &measured, &mut on_event, &mut on_run)
            .map_err(|e| match e {
                CalibrationError::Setup(wormwear::RunError::Geometry(_)) => Failure::Input(
                    anyhow::Error::new(e).context(format!("geometry of {}", file.display())),
                ),
                CalibrationError::Simulation(_) | CalibrationError::Setup(_) => {
                    Failure::Run(anyhow::Error::new(e))
                }
                _ => Failure::Input(anyhow::Error::new(e).context(path.display().to_string())),
            })?;
    wormwear::output::write_calibration_curves(dir, &measured, &records, fit.k)
        .map_err(|e| Failure::Run(e.into()))?;
    let k_start = gear.wheel_material.wear_coefficient;
    if !quiet {
        println!(
            "K = {:.4e} from the backlash curve ({} points, {runs} life runs from K = {k_start:.3e}; relative rms residual {:.3})",
            fit.k, fit.points, fit.relative_rms
        );
        if let Some(f) = fit.life_factor {
            println!(
                "life factor of the pressure-life curve = {f:.4} (the forecast's first pitting \
                 where the measured backlash first stays flat); set [wear.endurance] life_factor"
            );
        }
    }
    Ok(serde_json::json!({
        "method": "backlash curve",
        "data": path.display().to_string(),
        "k": fit.k,
        "k_start": k_start,
        "relative_rms": fit.relative_rms,
        "points": fit.points,
        "life_runs": runs,
        "life_factor": fit.life_factor,
    }))
}
