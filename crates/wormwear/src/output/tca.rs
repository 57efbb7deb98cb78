//! Files of the unloaded analysis: `tca` section of summary.json, CSV tables (kinematic error,
//! flank contact map, no-load pattern, contact lines) and SVG plots (no-load pattern, kinematic
//! error, sliding speed) on the wheel flank in (z, r).

use super::{update_summary, Csv, OutputError};
use crate::geometry::{Geometry, WheelFlank};
use crate::input::GearSet;
use crate::kinematics::Tca;
use crate::plot::{flank_map, line_chart_spanned, IsoGrid, MapCell, Series};
use std::path::{Path, PathBuf};

const MM: f64 = 1e3;
const UM: f64 = 1e6;

/// Summary of the unloaded analysis (units in the names).
#[derive(Debug, Clone, serde::Serialize)]
pub struct TcaSummary {
    pub loaded_flank: String,
    pub positions: usize,
    pub teeth_studied: Vec<i32>,
    /// Phase of position 0 in tooth pitches (driven sense).
    pub position_phase_pitch: f64,
    pub kinematic_error_mean_rad: f64,
    pub kinematic_error_p2p_rad: f64,
    pub marking_thickness_um: f64,
    pub pattern_area_mm2: f64,
    pub active_flank_area_mm2: f64,
    /// Marked area / active flank area.
    pub pattern_area_fraction: f64,
    /// The no-load pattern's centre across the face (0 at the entry side, 1 at the exit side)
    /// and up the flank, and its extent along the face and up the flank (shares; MODEL §17).
    pub pattern_shape: Option<crate::kinematics::pattern_shape::PatternShape>,
    pub min_teeth_in_contact: usize,
    pub max_teeth_in_contact: usize,
    pub max_sliding_speed_m_s: f64,
    /// r1 omega1 / cos(gamma) from material velocities at the pitch point.
    pub sliding_speed_at_pitch_m_s: f64,
    pub warnings: Vec<String>,
}

impl TcaSummary {
    pub fn new(tca: &Tca) -> Self {
        let (mean, p2p) = tca.kinematic_error_stats();
        let counts = tca.positions.iter().map(|p| p.teeth_in_contact);
        Self {
            loaded_flank: tca.loaded_flank.name().to_string(),
            positions: tca.positions.len(),
            teeth_studied: tca.teeth.clone(),
            position_phase_pitch: tca.phase,
            kinematic_error_mean_rad: mean,
            kinematic_error_p2p_rad: p2p,
            marking_thickness_um: tca.marking_thickness * UM,
            pattern_area_mm2: tca.pattern_area * MM * MM,
            active_flank_area_mm2: tca.active_area * MM * MM,
            pattern_area_fraction: tca.pattern_area / tca.active_area,
            pattern_shape: tca.pattern_shape,
            min_teeth_in_contact: counts.clone().min().unwrap_or(0),
            max_teeth_in_contact: counts.max().unwrap_or(0),
            max_sliding_speed_m_s: tca.max_sliding_speed(),
            sliding_speed_at_pitch_m_s: tca.pitch_sliding_speed,
            warnings: tca.warnings.clone(),
        }
    }
}

/// The worm-tip trace as a chart series in (z, r) mm.
pub fn tip_trace_series(tca: &Tca) -> Series {
    Series {
        label: "worm tip trace".into(),
        points: tca
            .tip_trace
            .iter()
            .map(|&(z, r)| (z * MM, r * MM))
            .collect(),
        color: 1,
        bold: true,
    }
}

/// Outline of the active flank (flank/fillet boundary and blank top) in (z, r) mm.
pub fn flank_outline(wf: &WheelFlank, label: &str, color: usize) -> Series {
    let mut pts: Vec<(f64, f64)> =
        wf.z.iter()
            .zip(&wf.r_low)
            .map(|(z, r)| (z * MM, r * MM))
            .collect();
    pts.extend(
        wf.z.iter()
            .zip(&wf.r_high)
            .rev()
            .map(|(z, r)| (z * MM, r * MM)),
    );
    pts.push(pts[0]);
    Series {
        label: label.to_string(),
        points: pts,
        color,
        bold: false,
    }
}

/// Cells of the flank grid as map quads in (z, r) mm with the given per-cell values.
pub fn flank_cells(wf: &WheelFlank, values: &[f64]) -> Vec<MapCell> {
    let mut cells = Vec::with_capacity(values.len());
    for j in 0..wf.cells_face {
        for i in 0..wf.cells_height {
            let c = |i: usize, j: usize| {
                let n = wf.node(i, j);
                (n.z * MM, n.r * MM)
            };
            cells.push(MapCell {
                corners: [c(i, j), c(i + 1, j), c(i + 1, j + 1), c(i, j + 1)],
                value: values[j * wf.cells_height + i],
            });
        }
    }
    cells
}

/// Colour map of per-cell values on the wheel flank in (z, r) mm (NaN: grey), values clipped
/// to `range`, with iso-lines through the cell centres.
#[allow(clippy::too_many_arguments)]
pub fn wheel_flank_map(
    path: &Path,
    title: &str,
    wf: &WheelFlank,
    cell_values: &[f64],
    range: (f64, f64),
    bar_label: &str,
    overlays: &[Series],
    segments: &[crate::plot::Segment],
) -> Result<(), OutputError> {
    let cells = flank_cells(wf, cell_values);
    let iso = IsoGrid {
        rows: wf.cells_height,
        cols: wf.cells_face,
        points: cells
            .iter()
            .map(|c| {
                let (x, y) = c
                    .corners
                    .iter()
                    .fold((0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1));
                (0.25 * x, 0.25 * y)
            })
            .collect(),
        values: cell_values.to_vec(),
    };
    flank_map(
        path,
        title,
        "z2 across the face width (mm)",
        "r wheel radius (mm)",
        &cells,
        range,
        bar_label,
        overlays,
        segments,
        Some(&iso),
    )
}

/// Cell edges separating marked from unmarked cells (the outline of a pattern), (z, r) mm.
pub fn pattern_outline(wf: &WheelFlank, marked: &[bool]) -> Vec<crate::plot::Segment> {
    let (ni, nj) = (wf.cells_height, wf.cells_face);
    let at = |i: usize, j: usize| marked[j * ni + i];
    let p = |i: usize, j: usize| {
        let n = wf.node(i, j);
        (n.z * MM, n.r * MM)
    };
    let mut segs = Vec::new();
    for j in 0..nj {
        for i in 0..ni {
            let m = at(i, j);
            // Edge along the height between columns j and j + 1, at face index j + 1.
            let right = if j + 1 < nj { at(i, j + 1) } else { false };
            if m != right && (m || right) {
                segs.push((p(i, j + 1), p(i + 1, j + 1)));
            }
            let up = if i + 1 < ni { at(i + 1, j) } else { false };
            if m != up && (m || up) {
                segs.push((p(i + 1, j), p(i + 1, j + 1)));
            }
            if j == 0 && m {
                segs.push((p(i, 0), p(i + 1, 0)));
            }
            if i == 0 && m {
                segs.push((p(0, j), p(0, j + 1)));
            }
        }
    }
    segs
}

/// Writes every TCA output into `dir`; returns the files written.
pub fn write_tca(
    gear: &GearSet,
    geo: &Geometry,
    tca: &Tca,
    dir: &Path,
) -> Result<Vec<PathBuf>, OutputError> {
    let wf = geo.wheel_flank(tca.loaded_flank);
    let mut files = Vec::new();
    kinematic_error_files(tca, dir, &mut files)?;
    let trace = tip_trace_series(tca);
    pattern_files(tca, wf, &trace, dir, &mut files)?;
    flank_map_csv(tca, wf, dir, &mut files)?;
    sliding_maps(tca, wf, &trace, dir, &mut files)?;
    contact_lines_csv(tca, dir, &mut files)?;
    update_summary(dir, "tca", summary_value(tca)?)?;
    files.push(dir.join("summary.json"));
    let path = dir.join("wheel_flank_tca.vtp");
    super::vtk::wheel_flank_tca(gear, geo, tca).write_vtp(
        &path,
        &[],
        "loaded wheel flank: unloaded analysis (mm)",
    )?;
    files.push(path);
    Ok(files)
}

/// The kinematic error per position: CSV and chart.
fn kinematic_error_files(
    tca: &Tca,
    dir: &Path,
    files: &mut Vec<PathBuf>,
) -> Result<(), OutputError> {
    let mut csv = Csv::new(&[
        "position",
        "theta1_rad",
        "theta2_rad",
        "kinematic_error_rad",
        "teeth_in_contact",
    ]);
    for (n, p) in tca.positions.iter().enumerate() {
        csv.row(&[
            n as f64,
            p.theta1,
            p.theta2,
            p.kinematic_error,
            p.teeth_in_contact as f64,
        ]);
    }
    let path = dir.join("tca_kinematic_error.csv");
    csv.write(&path)?;
    files.push(path);
    let np = tca.positions.len();
    let ke: Vec<(f64, f64)> = (0..=np)
        .map(|n| {
            (
                n as f64 / np as f64,
                tca.positions[n % np].kinematic_error * UM,
            )
        })
        .collect();
    let path = dir.join("tca_kinematic_error.svg");
    let (mean, p2p) = tca.kinematic_error_stats();
    line_chart_spanned(
        &path,
        &format!(
            "Unloaded kinematic error (mean {:.4} urad, p2p {:.4} urad; negative: wheel lags)",
            mean * UM,
            p2p * UM
        ),
        "wheel rotation (tooth pitches from position 0)",
        "kinematic error (urad, wheel)",
        &[Series {
            label: String::new(),
            points: ke,
            color: 0,
            bold: true,
        }],
        false,
        0.02,
    )?;
    files.push(path);
    Ok(())
}

/// The no-load contact pattern: CSV per cell and the flank map with the worm-tip trace.
fn pattern_files(
    tca: &Tca,
    wf: &WheelFlank,
    trace: &Series,
    dir: &Path,
    files: &mut Vec<PathBuf>,
) -> Result<(), OutputError> {
    let csv = super::flank_cell_table(wf, &["min_separation_um", "marked"], |k| {
        vec![tca.min_separation[k] * UM, tca.marked[k] as u8 as f64]
    });
    let path = dir.join("tca_pattern.csv");
    csv.write(&path)?;
    files.push(path);
    let j_um = tca.marking_thickness * UM;
    let sep_um: Vec<f64> = tca.min_separation.iter().map(|s| s * UM).collect();
    let path = dir.join("tca_pattern.svg");
    wheel_flank_map(
        &path,
        &format!(
            "No-load contact pattern, marking {j_um:.0} um: {:.1} % of the active flank ({} flank)",
            100.0 * tca.pattern_area / tca.active_area,
            tca.loaded_flank.name()
        ),
        wf,
        &sep_um,
        (0.0, 3.0 * j_um),
        "separation (um)",
        std::slice::from_ref(trace),
        &pattern_outline(wf, &tca.marked),
    )?;
    files.push(path);
    Ok(())
}

/// The contact map per node (reach, contact angle, ease-off, sliding): CSV.
fn flank_map_csv(
    tca: &Tca,
    wf: &WheelFlank,
    dir: &Path,
    files: &mut Vec<PathBuf>,
) -> Result<(), OutputError> {
    let mut csv = Csv::new(&[
        "i",
        "j",
        "r_mm",
        "z_mm",
        "reachable",
        "contact_theta2_rad",
        "worm_radius_mm",
        "ease_off_um",
        "sliding_speed_m_s",
        "sliding_along_m_s",
        "sliding_across_m_s",
        "u1_m_s",
        "u2_m_s",
    ]);
    for j in 0..=wf.cells_face {
        for i in 0..=wf.cells_height {
            let k = j * (wf.cells_height + 1) + i;
            let (n, c) = (wf.node(i, j), &tca.node_contact[k]);
            csv.row(&[
                i as f64,
                j as f64,
                n.r * MM,
                n.z * MM,
                c.reachable as u8 as f64,
                c.theta2,
                c.worm_radius * MM,
                c.ease_off * UM,
                c.sliding_speed,
                c.sliding_along,
                c.sliding_across,
                c.u1,
                c.u2,
            ]);
        }
    }
    let path = dir.join("tca_flank_map.csv");
    csv.write(&path)?;
    files.push(path);
    Ok(())
}

/// Sliding speed maps: magnitude, and its components along and across the contact line
/// (MODEL §4.5; the across component drives the film's entrainment, the along one does not).
fn sliding_maps(
    tca: &Tca,
    wf: &WheelFlank,
    trace: &Series,
    dir: &Path,
    files: &mut Vec<PathBuf>,
) -> Result<(), OutputError> {
    type Component = fn(&crate::kinematics::NodeContact) -> f64;
    let maps: [(&str, String, &str, Component); 3] = [
        (
            "tca_sliding_speed.svg",
            format!(
                "Sliding speed at contact (max {:.2} m/s, pitch point {:.2} m/s); grey: not reached by the worm flank",
                tca.max_sliding_speed(),
                tca.pitch_sliding_speed
            ),
            "|Vg| (m/s)",
            |c| c.sliding_speed,
        ),
        (
            "tca_sliding_along.svg",
            "Sliding speed along the contact line (signed, along the line's direction)".into(),
            "Vg along (m/s)",
            |c| c.sliding_along,
        ),
        (
            "tca_sliding_across.svg",
            "Sliding speed across the contact line (signed, in the tangent plane)".into(),
            "Vg across (m/s)",
            |c| c.sliding_across,
        ),
    ];
    for (name, title, bar, component) in maps {
        let values = reachable_cell_means(tca, wf, component);
        let (lo, hi) = values
            .iter()
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        let path = dir.join(name);
        wheel_flank_map(
            &path,
            &title,
            wf,
            &values,
            (lo, hi),
            bar,
            std::slice::from_ref(trace),
            &[],
        )?;
        files.push(path);
    }
    Ok(())
}

/// The contact lines of every position and tooth: CSV.
fn contact_lines_csv(tca: &Tca, dir: &Path, files: &mut Vec<PathBuf>) -> Result<(), OutputError> {
    let mut csv = Csv::new(&[
        "position",
        "tooth",
        "slice",
        "r_mm",
        "z_mm",
        "separation_um",
        "worm_radius_mm",
        "at_end",
        "curvature_radius_mm",
    ]);
    for c in &tca.contact_lines {
        csv.row(&[
            c.position as f64,
            c.tooth as f64,
            c.slice as f64,
            c.r * MM,
            c.z * MM,
            c.separation * UM,
            c.worm_radius * MM,
            c.at_end as u8 as f64,
            c.curvature_radius * MM,
        ]);
    }
    let path = dir.join("tca_contact_lines.csv");
    csv.write(&path)?;
    files.push(path);
    Ok(())
}

/// Per flank cell, the mean of `value` over its corner nodes that the worm flank reaches (NaN
/// with fewer than two).
fn reachable_cell_means(
    tca: &Tca,
    wf: &crate::geometry::WheelFlank,
    value: fn(&crate::kinematics::NodeContact) -> f64,
) -> Vec<f64> {
    let node_value = |i: usize, j: usize| {
        let c = &tca.node_contact[j * (wf.cells_height + 1) + i];
        if c.reachable {
            value(c)
        } else {
            f64::NAN
        }
    };
    let mut out = Vec::with_capacity(wf.cells.len());
    for j in 0..wf.cells_face {
        for i in 0..wf.cells_height {
            let ok: Vec<f64> = [
                node_value(i, j),
                node_value(i + 1, j),
                node_value(i, j + 1),
                node_value(i + 1, j + 1),
            ]
            .into_iter()
            .filter(|x| x.is_finite())
            .collect();
            out.push(if ok.len() >= 2 {
                ok.iter().sum::<f64>() / ok.len() as f64
            } else {
                f64::NAN
            });
        }
    }
    out
}

/// The `tca` section of summary.json.
pub fn summary_value(tca: &Tca) -> Result<serde_json::Value, OutputError> {
    serde_json::to_value(TcaSummary::new(tca)).map_err(|e| OutputError::Encode {
        what: "tca summary".into(),
        message: e.to_string(),
    })
}
