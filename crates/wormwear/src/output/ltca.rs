//! Files of the loaded analysis: `ltca` section of summary.json, CSV tables (per position,
//! loaded pattern, local pressures) and SVG plots (load sharing, transmission error, mesh
//! stiffness, pressure maps of the engaged teeth at a chosen position, loaded pattern).

use super::tca::{flank_outline, tip_trace_series};
use super::{update_summary, Csv, OutputError};
use crate::geometry::{Geometry, WheelFlank};
use crate::input::GearSet;
use crate::kinematics::Tca;
use crate::ltca::{Ltca, PositionResult};
use crate::plot::{flank_map, line_chart, line_chart_spanned, IsoGrid, MapCell, Series};
use std::path::{Path, PathBuf};

const MM: f64 = 1e3;
const UM: f64 = 1e6;
const MPA: f64 = 1e-6;

/// Summary of the loaded analysis (units in the names).
/// What a summary's `max_pressure_pa` means.
pub const MAX_PRESSURE_DEFINITION: &str = "largest pressure of the local contact cells over \
the positions (the published P_max; with the default plastic limit at most the flow pressure \
and mesh-converged; with contact = elastic it grows with mesh refinement at a sharp edge: see \
pressure_patch_max_pa, the largest mean pressure over a patch of stated size)";

#[derive(Debug, Clone, serde::Serialize)]
pub struct LtcaSummary {
    pub bending_model: String,
    pub solver: String,
    pub worm_torque_nm: f64,
    /// Mean over the positions: the torque the mesh transmits (MODEL §5.2).
    pub wheel_torque_nm: f64,
    /// Which torque the pressures carry: "transmitted" (with the contact's friction) or
    /// "frictionless" (the published reading, T2 = u T1).
    pub torque_balance: crate::input::TorqueBalance,
    /// The mesh efficiency the torques carry, eta_z = T2 / (u T1).
    pub mesh_efficiency: f64,
    /// Mean worm torque the friction consumes, P_Vz / omega1, N m.
    pub friction_torque_nm: f64,
    /// Largest pressure of the loaded pattern's cells (raw maximum, see
    /// `max_pressure_definition`) and where it sits on the flank (cell centre), mm.
    pub max_pressure_pa: f64,
    pub max_pressure_r_mm: f64,
    pub max_pressure_z_mm: f64,
    /// Largest mean pressure over the stated patch (`[analysis] pressure_patch_*`;
    /// mesh-converged at sharp edges).
    pub pressure_patch_max_pa: f64,
    pub pressure_patch_across_mm: f64,
    pub pressure_patch_along_mm: f64,
    pub max_pressure_definition: &'static str,
    /// Mean of the loaded pattern's non-zero cells (MODEL §5.6).
    pub mean_pressure_pa: f64,
    /// Largest equivalent pressure below the flank (MODEL §8.1: max over depth of tau_1 /
    /// 0.300, or the orthogonal shear's, `[wear] pitting_stress`) and its depth, over the
    /// pattern's cells; what the fatigue damage reads.
    pub equivalent_pressure_max_pa: f64,
    pub equivalent_pressure_depth_mm: f64,
    /// p_eq,2%: exceeded on 2 % of the active flank (MODEL §8.1), what S_H reads, Pa.
    pub equivalent_pressure_first_pitting_pa: f64,
    /// Where the cells at or above it lie: shares of the active flank at the worm tip's trace,
    /// the face ends, the blank top and elsewhere (MODEL §8.1).
    pub first_pitting_places: crate::ltca::FlankPlaces,
    pub equivalent_pressure_definition: &'static str,
    /// S0: contact area / active flank area.
    pub contact_area_fraction: f64,
    /// The loaded pattern's (cells with pressure) centre across the face (0 at the entry
    /// side, 1 at the exit side) and up the flank, and its extent (shares; MODEL §17).
    pub pattern_shape: Option<crate::kinematics::pattern_shape::PatternShape>,
    pub s1: f64,
    pub s2: f64,
    pub te_mean_rad: f64,
    pub te_p2p_rad: f64,
    /// Amplitudes of the mesh orders 1..k of the loaded TE and of the unloaded KE (MODEL §16),
    /// rad: `ltca_te_orders.csv`.
    pub te_orders: crate::ltca::TeOrders,
    pub mesh_stiffness_mean_nm_per_rad: f64,
    /// The wheel shaft's torsional compliance in the bending model (0: none), rad/(N m); its
    /// share of the TE is -c_t C2 at every position.
    pub wheel_shaft_torsion_rad_per_nm: f64,
    /// Mean mesh stiffness with the shaft's torsion taken out, N m/rad.
    pub mesh_stiffness_without_shaft_torsion_nm_per_rad: f64,
    pub mesh_stiffness_linear_mean_n_per_m: f64,
    pub max_teeth_in_contact: usize,
    /// Power balance: (mean wheel torque / u + friction torque) / worm torque - 1.
    pub power_balance: f64,
    /// What makes these results doubtful (also on stderr and in report.html).
    pub warnings: Vec<String>,
    /// Normal force per tooth (TCA tooth order) at each position, N.
    pub load_share: Vec<LoadShare>,
    pub solver_residuals: Vec<SolverResiduals>,
}

/// Load sharing at one position.
#[derive(Debug, Clone, serde::Serialize)]
pub struct LoadShare {
    pub position: usize,
    pub teeth: Vec<i32>,
    pub tooth_load_n: Vec<f64>,
}

/// Residuals at one position.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SolverResiduals {
    pub position: usize,
    pub torque_balance: f64,
    pub complementarity: f64,
    pub min_gap: f64,
    pub min_pressure: f64,
    pub iterations: usize,
    pub cells: usize,
}

impl LtcaSummary {
    pub fn new(tca: &Tca, wf: &crate::geometry::WheelFlank, ltca: &Ltca) -> Self {
        let (te_mean, te_p2p) = ltca.te_stats();
        let at_max = ltca
            .pattern
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .map(|(k, _)| &wf.cells[k]);
        let n = ltca.positions.len().max(1) as f64;
        let mean =
            |f: &dyn Fn(&PositionResult) -> f64| ltca.positions.iter().map(f).sum::<f64>() / n;
        Self {
            bending_model: ltca.bending_model.clone(),
            solver: format!("{:?}", ltca.solver),
            worm_torque_nm: ltca.worm_torque,
            wheel_torque_nm: ltca.wheel_torque,
            torque_balance: ltca.torque_balance,
            mesh_efficiency: ltca.mesh_efficiency,
            friction_torque_nm: mean(&|p| p.friction_torque),
            max_pressure_pa: ltca.max_pressure,
            max_pressure_r_mm: at_max.map_or(f64::NAN, |c| c.r * MM),
            max_pressure_z_mm: at_max.map_or(f64::NAN, |c| c.z * MM),
            pressure_patch_max_pa: ltca.pressure_patch_max,
            pressure_patch_across_mm: ltca.pressure_patch_size[0] * MM,
            pressure_patch_along_mm: ltca.pressure_patch_size[1] * MM,
            max_pressure_definition: MAX_PRESSURE_DEFINITION,
            mean_pressure_pa: ltca.mean_pressure,
            equivalent_pressure_max_pa: ltca.equivalent_pattern.iter().copied().fold(0.0, f64::max),
            equivalent_pressure_depth_mm: ltca
                .equivalent_pattern
                .iter()
                .zip(&ltca.equivalent_depth)
                .max_by(|a, b| a.0.total_cmp(b.0))
                .map_or(f64::NAN, |(_, d)| d * MM),
            equivalent_pressure_first_pitting_pa: ltca.equivalent_pressure_first_pitting,
            first_pitting_places: ltca.first_pitting_places,
            equivalent_pressure_definition: ltca.subsurface.criterion.definition(),
            contact_area_fraction: ltca.s0,
            pattern_shape: crate::kinematics::pattern_shape::PatternShape::of(
                wf,
                &ltca.pattern.iter().map(|p| *p > 0.0).collect::<Vec<_>>(),
                tca.entry_at_low_z,
            ),
            s1: ltca.s1,
            s2: ltca.s2,
            te_mean_rad: te_mean,
            te_p2p_rad: te_p2p,
            te_orders: ltca.te_orders(),
            mesh_stiffness_mean_nm_per_rad: ltca.stiffness_mean(),
            wheel_shaft_torsion_rad_per_nm: ltca.shaft_torsion_compliance,
            mesh_stiffness_without_shaft_torsion_nm_per_rad: ltca
                .stiffness_without_shaft_torsion_mean(),
            mesh_stiffness_linear_mean_n_per_m: mean(&|p| p.stiffness_linear),
            max_teeth_in_contact: ltca.max_teeth_in_contact(),
            power_balance: ltca.power_balance,
            warnings: ltca.warnings.clone(),
            load_share: ltca
                .positions
                .iter()
                .map(|p| LoadShare {
                    position: p.position,
                    teeth: tca.teeth.clone(),
                    tooth_load_n: p.tooth_load.clone(),
                })
                .collect(),
            solver_residuals: ltca
                .positions
                .iter()
                .map(|p| SolverResiduals {
                    position: p.position,
                    torque_balance: p.torque_residual,
                    complementarity: p.residuals.complementarity,
                    min_gap: p.residuals.min_gap,
                    min_pressure: p.residuals.min_load,
                    iterations: p.residuals.iterations,
                    cells: p.cells.len(),
                })
                .collect(),
        }
    }
}

/// Local cells of one tooth at one position as map quads in (z, r) mm.
fn local_cells(pr: &PositionResult, tooth: usize, wf: &WheelFlank) -> Vec<MapCell> {
    let dz = pr.cells.first().map(|c| c.cell.half_zeta).unwrap_or(0.0);
    pr.cells
        .iter()
        .zip(&pr.pressure)
        .filter(|(c, &p)| c.tooth_index == tooth && p > 0.0)
        .map(|(c, &p)| {
            // Half height of the cell in r: half_nu along the slice, mapped to r.
            let (_, slope) = wf.column_theta(c.slice, c.r);
            let dr = c.cell.half_nu / (1.0 + (c.r * slope).powi(2)).sqrt();
            let (z0, z1) = ((c.z - dz) * MM, (c.z + dz) * MM);
            let (r0, r1) = ((c.r - dr) * MM, (c.r + dr) * MM);
            MapCell {
                corners: [(z0, r0), (z1, r0), (z1, r1), (z0, r1)],
                value: p * MPA,
            }
        })
        .collect()
}

/// The pressure of one tooth's local cells (MPa) on the (column across the line, slice) grid
/// for iso-lines, at the cell centres in (z, r) mm; NaN where the local mesh has no cell.
fn local_iso_grid(pr: &PositionResult, tooth: usize) -> IsoGrid {
    let cells = || {
        pr.cells
            .iter()
            .zip(&pr.pressure)
            .filter(|(c, _)| c.tooth_index == tooth)
    };
    let (mut s0, mut s1, mut rows) = (usize::MAX, 0, 0);
    for (c, _) in cells() {
        s0 = s0.min(c.slice);
        s1 = s1.max(c.slice);
        rows = rows.max(c.column + 1);
    }
    if s0 > s1 {
        return IsoGrid {
            rows: 0,
            cols: 0,
            points: Vec::new(),
            values: Vec::new(),
        };
    }
    let cols = s1 - s0 + 1;
    let mut grid = IsoGrid {
        rows,
        cols,
        points: vec![(0.0, 0.0); rows * cols],
        values: vec![f64::NAN; rows * cols],
    };
    for (c, &p) in cells() {
        let k = (c.slice - s0) * rows + c.column;
        grid.points[k] = (c.z * MM, c.r * MM);
        grid.values[k] = p * MPA;
    }
    grid
}

/// Map of the loaded contact pattern (max pressure over the cycle per flank cell, MPa; grey
/// where no contact) with the given title and overlays.
pub fn pattern_map(
    path: &Path,
    wf: &WheelFlank,
    ltca: &Ltca,
    title: &str,
    overlays: &[Series],
) -> Result<(), OutputError> {
    pressure_map(path, wf, &ltca.pattern, ltca.max_pressure, title, overlays)
}

/// Map of a pressure per flank cell (Pa, drawn in MPa from 0 to `top`; grey where zero).
fn pressure_map(
    path: &Path,
    wf: &WheelFlank,
    pressure: &[f64],
    top: f64,
    title: &str,
    overlays: &[Series],
) -> Result<(), OutputError> {
    let values: Vec<f64> = pressure
        .iter()
        .map(|&p| if p > 0.0 { p * MPA } else { f64::NAN })
        .collect();
    super::tca::wheel_flank_map(
        path,
        title,
        wf,
        &values,
        (0.0, top * MPA),
        "pressure (MPa)",
        overlays,
        &[],
    )
}

/// Writes every LTCA output into `dir`; `map_position` selects the position of the pressure
/// maps. Returns the files written.
pub fn write_ltca(
    gear: &GearSet,
    geo: &Geometry,
    tca: &Tca,
    ltca: &Ltca,
    dir: &Path,
    map_position: usize,
) -> Result<Vec<PathBuf>, OutputError> {
    let wf = geo.wheel_flank(tca.loaded_flank);
    let mut files = Vec::new();
    let csv = positions_table(tca, ltca);
    let path = dir.join("ltca_positions.csv");
    csv.write(&path)?;
    files.push(path);
    position_charts(tca, ltca, dir, &mut files)?;
    let trace = tip_trace_series(tca);
    pattern_files(wf, ltca, &trace, dir, &mut files)?;
    pressure_maps(tca, ltca, wf, &trace, map_position, dir, &mut files)?;
    let path = dir.join("ltca_subsurface_section.svg");
    if subsurface_section(&path, ltca, None, "where the equivalent pressure peaks")? {
        files.push(path);
    }
    // Local pressures of every position.
    let csv = pressures_table(ltca);
    let path = dir.join("ltca_pressures.csv");
    csv.write(&path)?;
    files.push(path);
    update_summary(dir, "ltca", summary_value(tca, wf, ltca)?)?;
    files.push(dir.join("summary.json"));
    let path = dir.join("wheel_flank_ltca.vtp");
    let mut surface = super::vtk::wheel_flank_tca(gear, geo, tca);
    super::vtk::add_pressure_pattern(&mut surface, &ltca.pattern);
    surface.write_vtp(&path, &[], "loaded wheel flank: loaded analysis (mm)")?;
    files.push(path);
    Ok(files)
}

/// Load sharing, transmission error and mesh stiffness over the positions: SVG.
fn position_charts(
    tca: &Tca,
    ltca: &Ltca,
    dir: &Path,
    files: &mut Vec<PathBuf>,
) -> Result<(), OutputError> {
    files.push(load_sharing_chart(tca, ltca, dir)?);
    files.push(transmission_error_chart(tca, ltca, dir)?);
    files.extend(te_orders_files(&ltca.te_orders(), dir)?);
    files.push(stiffness_chart(ltca, dir)?);
    Ok(())
}

/// `ltca_te_orders.csv` (order; amplitudes of the loaded TE and of the unloaded KE at that
/// mesh order, rad) and its chart `ltca_te_orders.svg` (MODEL §16).
fn te_orders_files(
    orders: &crate::ltca::TeOrders,
    dir: &Path,
) -> Result<Vec<PathBuf>, OutputError> {
    let mut csv = Csv::new(&[
        "mesh_order",
        "loaded_te_amplitude_rad",
        "kinematic_error_amplitude_rad",
    ]);
    for (h, (te, ke)) in orders
        .loaded_rad
        .iter()
        .zip(&orders.unloaded_rad)
        .enumerate()
    {
        csv.row(&[(h + 1) as f64, *te, *ke]);
    }
    let table = dir.join("ltca_te_orders.csv");
    csv.write(&table)?;
    let series = |values: &[f64], label: &str, color: usize| Series {
        label: label.into(),
        points: values
            .iter()
            .enumerate()
            .map(|(h, a)| ((h + 1) as f64, a * UM))
            .collect(),
        color,
        bold: color == 0,
    };
    let chart = dir.join("ltca_te_orders.svg");
    crate::plot::line_chart_marked(
        &chart,
        (
            "Transmission error by mesh order (amplitude of each harmonic of the tooth-mesh \
             frequency)",
            "mesh order (1 = the tooth-mesh frequency)",
            "amplitude (urad, wheel)",
        ),
        &[
            series(&orders.loaded_rad, "loaded TE", 0),
            series(&orders.unloaded_rad, "unloaded KE", 5),
        ],
    )?;
    Ok(vec![table, chart])
}

/// The position n as a wheel rotation in tooth pitches from position 0.
fn pitches(n: usize, np: usize) -> f64 {
    n as f64 / np as f64
}

/// The normal force on each tooth that carries load over the positions (kN).
fn load_sharing_chart(tca: &Tca, ltca: &Ltca, dir: &Path) -> Result<PathBuf, OutputError> {
    let np = ltca.positions.len();
    let x = |n: usize| pitches(n, np);
    let series: Vec<Series> = tca
        .teeth
        .iter()
        .enumerate()
        .filter(|(t, _)| ltca.positions.iter().any(|p| p.tooth_load[*t] > 0.0))
        .map(|(t, &k)| Series {
            label: format!("tooth {k}"),
            points: ltca
                .positions
                .iter()
                .map(|p| (x(p.position), p.tooth_load[t] / 1e3))
                .collect(),
            color: t,
            bold: false,
        })
        .collect();
    let path = dir.join("ltca_load_sharing.svg");
    line_chart(
        &path,
        "Load sharing between the teeth",
        "wheel rotation (tooth pitches from position 0)",
        "normal force on the tooth (kN)",
        &series,
        false,
    )?;
    Ok(path)
}

/// The loaded transmission error and the unloaded kinematic error about their means (urad,
/// wheel): the loaded mean (mostly the wheel shaft's torsion) would flatten the ripple; it is
/// stated in the title.
fn transmission_error_chart(tca: &Tca, ltca: &Ltca, dir: &Path) -> Result<PathBuf, OutputError> {
    let np = ltca.positions.len();
    let x = |n: usize| pitches(n, np);
    let (m, p2p) = ltca.te_stats();
    let ke_mean = tca.positions.iter().map(|p| p.kinematic_error).sum::<f64>() / np as f64;
    let te = Series {
        label: "loaded TE - its mean".into(),
        points: (0..=np)
            .map(|n| (x(n), (ltca.positions[n % np].transmission_error - m) * UM))
            .collect(),
        color: 0,
        bold: true,
    };
    let ke = Series {
        label: "unloaded KE - its mean".into(),
        points: (0..=np)
            .map(|n| (x(n), (tca.positions[n % np].kinematic_error - ke_mean) * UM))
            .collect(),
        color: 5,
        bold: false,
    };
    let path = dir.join("ltca_transmission_error.svg");
    line_chart_spanned(
        &path,
        &format!(
            "Loaded TE about its mean (mean {:.0} urad, {:.0} of it the wheel shaft's torsion; \
             p2p {:.1} urad)",
            m * UM,
            -shaft_twist(ltca) * UM,
            p2p * UM
        ),
        "wheel rotation (tooth pitches from position 0)",
        "TE - mean (urad, wheel)",
        &[te, ke],
        false,
        0.02,
    )?;
    Ok(path)
}

/// The wheel shaft's mean torsion under the normal pressures' wheel torque, rad (0 without
/// one in the bending model).
fn shaft_twist(ltca: &Ltca) -> f64 {
    let n = ltca.positions.len().max(1) as f64;
    ltca.shaft_torsion_compliance
        * ltca
            .positions
            .iter()
            .map(|p| p.normal_wheel_torque)
            .sum::<f64>()
        / n
}

/// The stiffness chart's title with its ripple, since the axis spans the ripple alone and
/// magnifies it (issue 59: a 1 % ripple filled the chart without a word).
fn stiffness_title(ltca: &Ltca) -> String {
    let k: Vec<f64> = ltca.positions.iter().map(|p| p.stiffness_angular).collect();
    let (lo, hi) = k
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let mean = k.iter().sum::<f64>() / k.len().max(1) as f64;
    match mean > 0.0 && hi.is_finite() && lo.is_finite() {
        true => format!(
            "Mesh stiffness C2 / approach (mean {:.4} MN m/rad, ripple +/-{:.2} %)",
            mean / 1e6,
            50.0 * (hi - lo) / mean
        ),
        false => "Mesh stiffness C2 / approach".to_string(),
    }
}

/// The angular mesh stiffness over the positions (MN m/rad).
fn stiffness_chart(ltca: &Ltca, dir: &Path) -> Result<PathBuf, OutputError> {
    let np = ltca.positions.len();
    let x = |n: usize| pitches(n, np);
    let k = Series {
        label: String::new(),
        points: (0..=np)
            .map(|n| (x(n), ltca.positions[n % np].stiffness_angular / 1e6))
            .collect(),
        color: 2,
        bold: true,
    };
    let path = dir.join("ltca_mesh_stiffness.svg");
    line_chart(
        &path,
        &stiffness_title(ltca),
        "wheel rotation (tooth pitches from position 0)",
        "angular stiffness (MN m/rad)",
        &[k],
        false,
    )?;
    Ok(path)
}

/// The loaded pattern: CSV and maps (pressure, equivalent pressure below the flank).
fn pattern_files(
    wf: &WheelFlank,
    ltca: &Ltca,
    trace: &Series,
    dir: &Path,
    files: &mut Vec<PathBuf>,
) -> Result<(), OutputError> {
    let csv = pattern_table(wf, ltca);
    let path = dir.join("ltca_pattern.csv");
    csv.write(&path)?;
    files.push(path);
    let path = dir.join("ltca_pattern.svg");
    pattern_map(
        &path,
        wf,
        ltca,
        &format!(
            "Loaded contact pattern: max pressure over the cycle (P_max {:.0} MPa, S0 {:.2}); grey: no contact",
            ltca.max_pressure * MPA,
            ltca.s0
        ),
        std::slice::from_ref(trace),
    )?;
    files.push(path);
    let path = dir.join("ltca_equivalent_pressure.svg");
    equivalent_map(&path, wf, ltca, std::slice::from_ref(trace))?;
    files.push(path);
    Ok(())
}

/// Map of the equivalent pressure below the flank over the cycle (MODEL §8.1), MPa.
fn equivalent_map(
    path: &Path,
    wf: &WheelFlank,
    ltca: &Ltca,
    overlays: &[Series],
) -> Result<(), OutputError> {
    let (k, top) = ltca
        .equivalent_pattern
        .iter()
        .copied()
        .enumerate()
        .fold((0, 0.0), |b, v| if v.1 > b.1 { v } else { b });
    let depth = ltca.equivalent_depth.get(k).copied().unwrap_or(0.0);
    let title = format!(
        "Equivalent pressure below the flank, {} (largest {:.0} MPa at {:.3} mm deep); grey: \
         no contact",
        ltca.subsurface.criterion.definition(),
        top * MPA,
        depth * MM
    );
    pressure_map(path, wf, &ltca.equivalent_pattern, top, &title, overlays)
}

/// The principal shear stress below the flank where the equivalent pressure peaks, over the
/// flank point `near` (r, z, m) when given (MODEL §8.1; [`crate::ltca::equivalent_section`]):
/// across the line x depth, MPa; `place` says where in the title. Returns whether it was drawn
/// (nothing loaded: not).
pub(crate) fn subsurface_section(
    path: &Path,
    ltca: &Ltca,
    near: Option<(f64, f64)>,
    place: &str,
) -> Result<bool, OutputError> {
    let Some((position, tooth, z, section)) = crate::ltca::equivalent_section(ltca, near) else {
        return Ok(false);
    };
    let (nx, nz) = (section.x.len(), section.z.len());
    let edges = |v: &[f64], k: usize| {
        let h = if v.len() > 1 { v[1] - v[0] } else { v[0] };
        (v[k] - 0.5 * h, v[k] + 0.5 * h)
    };
    let cells: Vec<MapCell> = (0..nz)
        .flat_map(|d| (0..nx).map(move |i| (d, i)))
        .map(|(d, i)| {
            let ((x0, x1), (z0, z1)) = (edges(&section.x, i), edges(&section.z, d));
            let (x0, x1, y0, y1) = (x0 * MM, x1 * MM, -z0 * MM, -z1 * MM);
            MapCell {
                corners: [(x0, y0), (x1, y0), (x1, y1), (x0, y1)],
                value: section.tau1[d * nx + i] * MPA,
            }
        })
        .collect();
    let top = section.tau1.iter().copied().fold(0.0, f64::max) * MPA;
    flank_map(
        path,
        &format!(
            "Principal shear stress tau_1 below the flank {place} (position {position}, tooth \
             {tooth}, z = {:.2} mm; largest {top:.0} MPa)",
            z * MM
        ),
        "across the contact line (mm)",
        "depth (mm, below the flank)",
        &cells,
        (0.0, top),
        "tau_1 (MPa)",
        &[],
        &[],
        None,
    )?;
    Ok(true)
}

/// Pressure maps of the engaged teeth at `map_position` (clamped to the last position).
fn pressure_maps(
    tca: &Tca,
    ltca: &Ltca,
    wf: &WheelFlank,
    trace: &Series,
    map_position: usize,
    dir: &Path,
    files: &mut Vec<PathBuf>,
) -> Result<(), OutputError> {
    let np = ltca.positions.len();
    let n = map_position.min(np - 1);
    let pr = &ltca.positions[n];
    for (t, &k) in tca.teeth.iter().enumerate() {
        if pr.tooth_load[t] <= 0.0 {
            continue;
        }
        let cells = local_cells(pr, t, wf);
        let path = dir.join(format!("ltca_pressure_position{n}_tooth{k}.svg"));
        flank_map(
            &path,
            &format!(
                "Pressure on tooth {k} at position {n}: {:.1} kN, max {:.0} MPa",
                pr.tooth_load[t] / 1e3,
                pr.cells
                    .iter()
                    .zip(&pr.pressure)
                    .filter(|(c, _)| c.tooth_index == t)
                    .map(|(_, p)| *p)
                    .fold(0.0, f64::max)
                    * MPA
            ),
            "z2 across the face width (mm)",
            "r wheel radius (mm)",
            &cells,
            (0.0, ltca.max_pressure * MPA),
            "pressure (MPa)",
            &[flank_outline(wf, "active flank", 5), trace.clone()],
            &[],
            Some(&local_iso_grid(pr, t)),
        )?;
        files.push(path);
    }
    Ok(())
}

/// The table of positions (`ltca_positions.csv`): torques (the transmitted wheel torque, the
/// worm's, the normal pressures' wheel torque and the friction's worm torque, MODEL §5.2), the
/// mesh efficiency T2 / (u T1), approach, TE, KE, stiffness, maximum pressure and the normal
/// force on each tooth (units in the names).
pub fn positions_table(tca: &Tca, ltca: &Ltca) -> Csv {
    let mut header: Vec<String> = [
        "position",
        "wheel_torque_nm",
        "worm_torque_nm",
        "normal_wheel_torque_nm",
        "friction_torque_nm",
        "mesh_efficiency",
        "approach_rad",
        "transmission_error_rad",
        "kinematic_error_rad",
        "stiffness_nm_per_rad",
        "stiffness_n_per_m",
        "max_pressure_pa",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    header.extend(tca.teeth.iter().map(|k| format!("tooth_{k}_load_n")));
    let mut csv = Csv::new(&header.iter().map(|s| s.as_str()).collect::<Vec<_>>());
    for p in &ltca.positions {
        let mut row = vec![
            p.position as f64,
            p.wheel_torque,
            p.worm_torque,
            p.normal_wheel_torque,
            p.friction_torque,
            p.wheel_torque / (ltca.ratio * p.worm_torque),
            p.approach,
            p.transmission_error,
            tca.positions[p.position].kinematic_error,
            p.stiffness_angular,
            p.stiffness_linear,
            p.max_pressure,
        ];
        row.extend(&p.tooth_load);
        csv.row(&row);
    }
    csv
}

/// The loaded pattern per flank cell (`ltca_pattern.csv`): the largest pressure over the
/// cycle, Pa, at the cell's (r, z), mm.
pub fn pattern_table(wf: &WheelFlank, ltca: &Ltca) -> Csv {
    super::flank_cell_table(
        wf,
        &[
            "max_pressure_pa",
            "equivalent_pressure_pa",
            "equivalent_depth_mm",
        ],
        |k| {
            vec![
                ltca.pattern[k],
                ltca.equivalent_pattern.get(k).copied().unwrap_or(0.0),
                ltca.equivalent_depth.get(k).copied().unwrap_or(0.0) * MM,
            ]
        },
    )
}

/// The local pressures of every position (`ltca_pressures.csv`): per contact cell its tooth,
/// slice, column, (r, z) mm, pressure Pa, initial separation rad, relief um, and the
/// equivalent pressure below it (Pa) with its depth (mm; MODEL §8.1).
pub fn pressures_table(ltca: &Ltca) -> Csv {
    let mut csv = Csv::new(&[
        "position",
        "tooth",
        "slice",
        "column",
        "r_mm",
        "z_mm",
        "pressure_pa",
        "separation_rad",
        "relief_um",
        "equivalent_pressure_pa",
        "equivalent_depth_mm",
    ]);
    for p in &ltca.positions {
        for (k, (c, pr)) in p.cells.iter().zip(&p.pressure).enumerate() {
            let e = p.equivalent.get(k).copied().unwrap_or_default();
            csv.row(&[
                p.position as f64,
                c.tooth as f64,
                c.slice as f64,
                c.column as f64,
                c.r * MM,
                c.z * MM,
                *pr,
                c.separation,
                c.relief * UM,
                e.pressure,
                e.depth * MM,
            ]);
        }
    }
    csv
}

/// The `ltca` section of summary.json.
pub fn summary_value(
    tca: &Tca,
    wf: &WheelFlank,
    ltca: &Ltca,
) -> Result<serde_json::Value, OutputError> {
    serde_json::to_value(LtcaSummary::new(tca, wf, ltca)).map_err(|e| OutputError::Encode {
        what: "ltca summary".into(),
        message: e.to_string(),
    })
}
