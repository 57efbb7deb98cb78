//! The friction's files (MODEL §13): maps of the local friction coefficient and of the
//! friction power density on the loaded wheel flank, and their table `friction_map.csv`.

use super::tca::wheel_flank_map;
use super::{Csv, OutputError};
use crate::friction::Thermal;
use crate::geometry::WheelFlank;
use crate::plot::Series;
use std::path::{Path, PathBuf};

/// `friction_map.csv`, `friction_coefficient_map.svg` (load-weighted mu over the cycle) and
/// `friction_power_map.svg` (MW/m^2, mean over the mesh cycle) of the run's loaded analysis on
/// the loaded flank `wf`.
pub fn write_friction(
    wf: &WheelFlank,
    thermal: &Thermal,
    dir: &Path,
) -> Result<Vec<PathBuf>, OutputError> {
    let path = dir.join("friction_map.csv");
    friction_table(wf, thermal).write(&path)?;
    let mut files = vec![path];
    files.extend(friction_maps(wf, thermal, dir, ("friction", ""), "", &[])?);
    Ok(files)
}

/// The friction on the loaded flank's grid cells (`friction_map.csv`): i (height), j (face),
/// r_mm, z_mm, the load-weighted friction coefficient over the cycle (NaN: no contact) and
/// the friction power density, mean over the mesh cycle, W/m^2 (MODEL §13).
pub fn friction_table(wf: &WheelFlank, thermal: &Thermal) -> Csv {
    let f = &thermal.friction;
    super::flank_cell_table(
        wf,
        &["friction_coefficient", "friction_power_density_w_m2"],
        |k| {
            vec![
                f.flank_coefficient.get(k).copied().unwrap_or(f64::NAN),
                f.flank_power_density.get(k).copied().unwrap_or(0.0),
            ]
        },
    )
}

/// The two friction maps of one loaded analysis: `{prefix}_coefficient_map{suffix}.svg` and
/// `{prefix}_power_map{suffix}.svg`; `when` is added to the titles (e.g. "after 1e6 cycles"),
/// `overlays` drawn over the maps.
pub fn friction_maps(
    wf: &WheelFlank,
    thermal: &Thermal,
    dir: &Path,
    (prefix, suffix): (&str, &str),
    when: &str,
    overlays: &[Series],
) -> Result<Vec<PathBuf>, OutputError> {
    let f = &thermal.friction;
    let top = |v: &[f64]| {
        v.iter()
            .copied()
            .filter(|x| x.is_finite())
            .fold(0.0, f64::max)
    };
    let path = dir.join(format!("{prefix}_coefficient_map{suffix}.svg"));
    wheel_flank_map(
        &path,
        &format!(
            "Local friction coefficient over the cycle{when} (load-weighted; mean {:.4}, oil {:.1} C); \
             grey: no contact",
            f.mean_coefficient,
            thermal.oil_temperature_k - 273.15
        ),
        wf,
        &f.flank_coefficient,
        (0.0, top(&f.flank_coefficient)),
        "friction coefficient",
        overlays,
        &[],
    )?;
    let mut files = vec![path];
    let density: Vec<f64> = f
        .flank_power_density
        .iter()
        .map(|&d| if d > 0.0 { d * 1e-6 } else { f64::NAN })
        .collect();
    let path = dir.join(format!("{prefix}_power_map{suffix}.svg"));
    wheel_flank_map(
        &path,
        &format!(
            "Friction power density, mean over the mesh cycle{when} (mesh loss {:.0} W); grey: none",
            f.mesh_loss_w
        ),
        wf,
        &density,
        (0.0, top(&density)),
        "friction power (MW/m^2)",
        overlays,
        &[],
    )?;
    files.push(path);
    Ok(files)
}
