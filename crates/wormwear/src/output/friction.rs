//! The friction's files (MODEL §13): maps of the local friction coefficient and of the
//! friction power density on the loaded wheel flank.

use super::tca::wheel_flank_map;
use super::OutputError;
use crate::friction::Thermal;
use crate::geometry::WheelFlank;
use std::path::{Path, PathBuf};

/// `friction_coefficient_map.svg` (load-weighted mu over the cycle) and
/// `friction_power_map.svg` (MW/m^2, mean over the mesh cycle) on the loaded flank `wf`.
pub fn write_friction(
    wf: &WheelFlank,
    thermal: &Thermal,
    dir: &Path,
) -> Result<Vec<PathBuf>, OutputError> {
    let f = &thermal.friction;
    let top = |v: &[f64]| {
        v.iter()
            .copied()
            .filter(|x| x.is_finite())
            .fold(0.0, f64::max)
    };
    let path = dir.join("friction_coefficient_map.svg");
    wheel_flank_map(
        &path,
        &format!(
            "Local friction coefficient over the cycle (load-weighted; mean {:.4}, oil {:.1} C); \
             grey: no contact",
            f.mean_coefficient,
            thermal.oil_temperature_k - 273.15
        ),
        wf,
        &f.flank_coefficient,
        (0.0, top(&f.flank_coefficient)),
        "friction coefficient",
        &[],
        &[],
    )?;
    let mut files = vec![path];
    let density: Vec<f64> = f
        .flank_power_density
        .iter()
        .map(|&d| if d > 0.0 { d * 1e-6 } else { f64::NAN })
        .collect();
    let path = dir.join("friction_power_map.svg");
    wheel_flank_map(
        &path,
        &format!(
            "Friction power density, mean over the mesh cycle (mesh loss {:.0} W); grey: none",
            f.mesh_loss_w
        ),
        wf,
        &density,
        (0.0, top(&density)),
        "friction power (MW/m^2)",
        &[],
        &[],
    )?;
    files.push(path);
    Ok(files)
}
