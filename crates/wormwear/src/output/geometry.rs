//! Files of the geometry stage: sections in rack planes (CSV + SVG), worm axial profiles, wheel
//! flank grids (CSV), flank outline (SVG), STL of worm and wheel, and the `geometry` section of
//! `summary.json`.

use super::{update_summary, write_atomic, Csv, OutputError};
use crate::geometry::sections::rack_plane_section;
use crate::geometry::stl::{wheel_mesh, worm_mesh};
use crate::geometry::{Flank, Geometry, GeometrySummary, WheelFlank};
use crate::input::GearSet;
use crate::plot::{line_chart, Series};
use std::path::{Path, PathBuf};

const MM: f64 = 1e3;

/// Writes every geometry output into `dir`; returns the files written.
pub fn write_geometry(
    gear: &GearSet,
    geo: &Geometry,
    input_file: &Path,
    dir: &Path,
) -> Result<Vec<PathBuf>, OutputError> {
    let mut files = Vec::new();
    for &offset in &gear.analysis.section_offsets {
        section_files(gear, geo, offset, dir, &mut files)?;
    }
    axial_profiles_csv(gear, geo, dir, &mut files)?;
    for wf in &geo.wheel_flanks {
        flank_grid_csv(wf, dir, &mut files)?;
    }
    flank_outline_svg(geo, dir, &mut files)?;
    meshes(gear, geo, dir, &mut files)?;
    write_geometry_summary(gear, geo, input_file, dir)?;
    files.push(dir.join("summary.json"));
    Ok(files)
}

/// The section in the rack plane at `offset` (m along the wheel axis): CSV and SVG.
fn section_files(
    gear: &GearSet,
    geo: &Geometry,
    offset: f64,
    dir: &Path,
    files: &mut Vec<PathBuf>,
) -> Result<(), OutputError> {
    let section = rack_plane_section(gear, geo, offset, 2).map_err(OutputError::Geometry)?;
    let stem = format!("section_z{:+.3}mm", offset * MM);
    let mut csv = Csv::new(&["member", "x_mm", "y_mm"]);
    for c in &section.curves {
        for &(x, y) in &c.points {
            csv.labelled_row(c.member, &[x * MM, y * MM]);
        }
    }
    let path = dir.join(format!("{stem}.csv"));
    csv.write(&path)?;
    files.push(path);
    let series: Vec<Series> = section
        .curves
        .iter()
        .map(|c| Series {
            label: if c.member == "worm" {
                "worm thread".into()
            } else {
                "wheel teeth".into()
            },
            points: c.points.iter().map(|&(x, y)| (x * MM, y * MM)).collect(),
            color: if c.member == "worm" { 0 } else { 1 },
            bold: false,
        })
        .collect();
    let path = dir.join(format!("{stem}.svg"));
    line_chart(
        &path,
        &format!(
            "Rack-plane section at z = {:+.2} mm (worm frame, rotation 0)",
            offset * MM
        ),
        "x1 along the worm axis (mm)",
        "y1 towards the wheel centre (mm)",
        &series,
        true,
    )?;
    files.push(path);
    Ok(())
}

/// The worm's and hob's axial profiles over the radius: CSV.
fn axial_profiles_csv(
    gear: &GearSet,
    geo: &Geometry,
    dir: &Path,
    files: &mut Vec<PathBuf>,
) -> Result<(), OutputError> {
    let mut csv = Csv::new(&[
        "rho_mm",
        "worm_left_x_mm",
        "worm_right_x_mm",
        "hob_left_x_mm",
        "hob_right_x_mm",
    ]);
    let (lo, hi) = (
        gear.worm.root_radius.min(gear.hob.root_radius),
        gear.worm.tip_radius.max(gear.hob.tip_radius),
    );
    for k in 0..=200 {
        let rho = lo + (hi - lo) * k as f64 / 200.0;
        csv.row(&[
            rho * MM,
            geo.worm.axial_profile(Flank::Left, rho).0 * MM,
            geo.worm.axial_profile(Flank::Right, rho).0 * MM,
            geo.hob.axial_profile(Flank::Left, rho).0 * MM,
            geo.hob.axial_profile(Flank::Right, rho).0 * MM,
        ]);
    }
    let path = dir.join("axial_profiles.csv");
    csv.write(&path)?;
    files.push(path);
    Ok(())
}

/// A wheel flank's grid: nodes and cells, CSV.
fn flank_grid_csv(
    wf: &WheelFlank,
    dir: &Path,
    files: &mut Vec<PathBuf>,
) -> Result<(), OutputError> {
    let name = wf.flank.name();
    let mut nodes = Csv::new(&[
        "i",
        "j",
        "r_mm",
        "z_mm",
        "theta_rad",
        "x2_mm",
        "y2_mm",
        "nx",
        "ny",
        "nz",
        "hob_radius_mm",
    ]);
    for j in 0..=wf.cells_face {
        for i in 0..=wf.cells_height {
            let n = wf.node(i, j);
            let p = n.position();
            nodes.row(&[
                i as f64,
                j as f64,
                n.r * MM,
                n.z * MM,
                n.theta,
                p.x * MM,
                p.y * MM,
                n.normal[0],
                n.normal[1],
                n.normal[2],
                n.hob_radius * MM,
            ]);
        }
    }
    let path = dir.join(format!("wheel_flank_{name}_nodes.csv"));
    nodes.write(&path)?;
    files.push(path);
    let cells = super::flank_cell_table(wf, &["theta_rad", "area_mm2", "active"], |k| {
        vec![
            wf.cells[k].theta,
            wf.cell_area[k] * MM * MM,
            if wf.active[k] { 1.0 } else { 0.0 },
        ]
    });
    let path = dir.join(format!("wheel_flank_{name}_cells.csv"));
    cells.write(&path)?;
    files.push(path);
    Ok(())
}

/// Outline of the active flank in (z, r): SVG.
fn flank_outline_svg(
    geo: &Geometry,
    dir: &Path,
    files: &mut Vec<PathBuf>,
) -> Result<(), OutputError> {
    let series: Vec<Series> = geo
        .wheel_flanks
        .iter()
        .enumerate()
        .map(|(k, wf)| {
            super::tca::flank_outline(wf, &format!("{}-mating flank", wf.flank.name()), k)
        })
        .collect();
    let path = dir.join("wheel_flank_outline.svg");
    line_chart(
        &path,
        "Active wheel flank (generated by the hob flank, inside the blank)",
        "z2 across the face width (mm)",
        "r wheel radius (mm)",
        &series,
        false,
    )?;
    files.push(path);
    Ok(())
}

/// STL of worm and wheel; VTK of both worm flanks and both wheel flanks of the reference
/// tooth space.
fn meshes(
    gear: &GearSet,
    geo: &Geometry,
    dir: &Path,
    files: &mut Vec<PathBuf>,
) -> Result<(), OutputError> {
    // STL.
    let path = dir.join("worm.stl");
    write_atomic(
        &path,
        &worm_mesh(gear, geo, gear.analysis.stl_worm_threads).to_binary_stl("worm", MM),
    )?;
    files.push(path);
    let path = dir.join("wheel.stl");
    write_atomic(
        &path,
        &wheel_mesh(gear, geo, gear.analysis.stl_wheel_teeth).to_binary_stl("wheel", MM),
    )?;
    files.push(path);
    // VTK: both worm flanks, both wheel flanks of the reference tooth space.
    let path = dir.join("worm_flanks.vtp");
    let [left, right] = super::vtk::worm_flank_surfaces(gear, geo);
    left.write_vtp(&path, &[&right], "worm flanks (mm)")?;
    files.push(path);
    let path = dir.join("wheel_flanks.vtp");
    let [left, right] = geo
        .wheel_flanks
        .each_ref()
        .map(|wf| super::vtk::wheel_flank_surface(gear, wf));
    left.write_vtp(
        &path,
        &[&right],
        "wheel flanks of the reference tooth space (mm)",
    )?;
    files.push(path);
    Ok(())
}

/// Writes the `input` and `geometry` sections of `dir/summary.json` (every command does).
pub fn write_geometry_summary(
    gear: &GearSet,
    geo: &Geometry,
    input_file: &Path,
    dir: &Path,
) -> Result<(), OutputError> {
    let (input, geometry) = summary_values(gear, geo, input_file)?;
    update_summary(dir, "input", input)?;
    update_summary(dir, "geometry", geometry)
}

/// The `input` and `geometry` sections of summary.json.
pub fn summary_values(
    gear: &GearSet,
    geo: &Geometry,
    input_file: &Path,
) -> Result<(serde_json::Value, serde_json::Value), OutputError> {
    // The validated gear (SI) without its title and warnings: what `compare` sets side by
    // side to name the inputs that differ between runs.
    let mut validated = serde_json::to_value(gear).map_err(|e| OutputError::Encode {
        what: "gear set".into(),
        message: e.to_string(),
    })?;
    if let Some(map) = validated.as_object_mut() {
        map.remove("title");
        map.remove("warnings");
    }
    let input = serde_json::json!({
        "file": input_file.display().to_string(),
        "title": gear.title,
        "program_version": env!("CARGO_PKG_VERSION"),
        "program": crate::PROGRAM,
        "gear": validated,
    });
    let geometry =
        serde_json::to_value(GeometrySummary::new(gear, geo)).map_err(|e| OutputError::Encode {
            what: "geometry summary".into(),
            message: e.to_string(),
        })?;
    Ok((input, geometry))
}
