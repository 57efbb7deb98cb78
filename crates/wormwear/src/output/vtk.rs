//! VTK XML PolyData files (`.vtp`, read by ParaView and any VTK reader) of the flank surfaces
//! with their results as point and cell data, written with the `vtkio` crate.
//!
//! Coordinates are in mm in the worm frame at rotation 0 (x along the worm axis, the wheel
//! placed at the centre distance), the same placement as `worm.stl` / `wheel.stl`, so the files
//! overlay in one ParaView scene. Each array's unit is in its name (`_um`, `_mpa`, `_m_s`).

use super::{write_atomic, OutputError};
use crate::geometry::{Flank, FlankField, Geometry, WheelFlank};
use crate::input::GearSet;
use crate::kinematics::Tca;
use std::f64::consts::PI;
use std::path::Path;
use vtkio::model::{
    Attribute, Attributes, ByteOrder, DataArray, DataSet, ElementType, IOBuffer, PolyDataPiece,
    Version, VertexNumbers, Vtk,
};

const MM: f64 = 1e3;
const UM: f64 = 1e6;

/// Named scalar arrays (name, one value per point or per quad).
pub type NamedArrays = Vec<(String, Vec<f64>)>;

/// A structured quadrilateral surface: `rows` x `cols` points stored column by column (index
/// `col * rows + row`), quads between neighbouring rows and columns (index
/// `col * (rows - 1) + row`), with named scalar arrays on the points and on the quads.
#[derive(Debug, Clone, Default)]
pub struct QuadSurface {
    pub rows: usize,
    pub cols: usize,
    /// Point coordinates, mm.
    pub points: Vec<[f64; 3]>,
    /// Unit normals at the points (out of the material), written as the `normal` vectors.
    pub normals: Vec<[f64; 3]>,
    pub point_data: NamedArrays,
    pub cell_data: NamedArrays,
}

/// The points (x, y, z flattened) and the quads (connectivity and offsets, VTK XML) of the
/// surfaces, one patch after the other.
fn quads(surfaces: &[&QuadSurface]) -> (Vec<f64>, Vec<u64>, Vec<u64>) {
    let mut points = Vec::new();
    let mut connectivity = Vec::new();
    let mut offsets = Vec::new();
    let mut base = 0u64;
    for s in surfaces {
        for p in &s.points {
            points.extend_from_slice(p);
        }
        let rows = s.rows as u64;
        for col in 0..s.cols.saturating_sub(1) as u64 {
            for row in 0..s.rows.saturating_sub(1) as u64 {
                let at = |r: u64, c: u64| base + c * rows + r;
                connectivity.extend_from_slice(&[
                    at(row, col),
                    at(row + 1, col),
                    at(row + 1, col + 1),
                    at(row, col + 1),
                ]);
                offsets.push(connectivity.len() as u64);
            }
        }
        base += s.points.len() as u64;
    }
    (points, connectivity, offsets)
}

impl QuadSurface {
    /// Number of quads.
    pub fn cell_count(&self) -> usize {
        self.rows.saturating_sub(1) * self.cols.saturating_sub(1)
    }

    /// Adds a point array (one value per point; NaN: no value).
    pub fn add_point_data(&mut self, name: &str, values: Vec<f64>) {
        assert_eq!(values.len(), self.points.len());
        self.point_data.push((name.to_string(), values));
    }

    /// Adds a cell array (one value per quad) and the same field averaged to the points (mean
    /// of the finite values of the quads around each point), under the same name.
    pub fn add_cell_field(&mut self, name: &str, values: Vec<f64>) {
        assert_eq!(values.len(), self.cell_count());
        let nodal = cells_to_points(self.rows, self.cols, &values);
        self.point_data.push((name.to_string(), nodal));
        self.cell_data.push((name.to_string(), values));
    }

    /// Appends another surface's quads as a separate patch; both must carry the same arrays.
    fn vtk(&self, others: &[&QuadSurface], title: &str) -> Vtk {
        let surfaces: Vec<&QuadSurface> = std::iter::once(self)
            .chain(others.iter().copied())
            .collect();
        let (points, connectivity, offsets) = quads(&surfaces);
        let scalars = |name: &str, data: Vec<f64>| {
            Attribute::DataArray(DataArray {
                name: name.to_string(),
                elem: ElementType::Scalars {
                    num_comp: 1,
                    lookup_table: None,
                },
                data: IOBuffer::F64(data),
            })
        };
        let gather = |pick: &dyn Fn(&QuadSurface) -> &NamedArrays| {
            pick(self)
                .iter()
                .enumerate()
                .map(|(k, (name, _))| {
                    // Infinite values (e.g. gaps where the worm cannot reach) as NaN: "no value"
                    // to ParaView, and they keep the colour ranges finite.
                    let data: Vec<f64> = surfaces
                        .iter()
                        .flat_map(|s| pick(s)[k].1.iter())
                        .map(|&v| if v.is_finite() { v } else { f64::NAN })
                        .collect();
                    scalars(name, data)
                })
                .collect::<Vec<_>>()
        };
        let mut point = vec![Attribute::DataArray(DataArray {
            name: "normal".into(),
            elem: ElementType::Normals,
            data: IOBuffer::F64(
                surfaces
                    .iter()
                    .flat_map(|s| s.normals.iter().flatten().copied())
                    .collect(),
            ),
        })];
        point.extend(gather(&|s| &s.point_data));
        let cell = gather(&|s| &s.cell_data);
        Vtk {
            version: Version::Auto,
            title: title.to_string(),
            byte_order: ByteOrder::LittleEndian,
            file_path: None,
            data: DataSet::inline(PolyDataPiece {
                points: IOBuffer::F64(points),
                verts: None,
                lines: None,
                polys: Some(VertexNumbers::XML {
                    connectivity,
                    offsets,
                }),
                strips: None,
                data: Attributes { point, cell },
            }),
        }
    }

    /// Writes this surface (and `others`, same arrays) as one `.vtp` file, atomically.
    pub fn write_vtp(
        &self,
        path: &Path,
        others: &[&QuadSurface],
        title: &str,
    ) -> Result<(), OutputError> {
        let mut bytes = Vec::new();
        self.vtk(others, title)
            .write_xml(&mut bytes)
            .map_err(|e| OutputError::Encode {
                what: format!("VTK file {}", path.display()),
                message: e.to_string(),
            })?;
        write_atomic(path, &bytes)
    }
}

/// Point values from quad values on a `rows` x `cols` point grid: the mean of the finite values
/// of the (up to four) quads around each point; NaN where none is finite.
pub fn cells_to_points(rows: usize, cols: usize, cell_values: &[f64]) -> Vec<f64> {
    let (cr, cc) = (rows.saturating_sub(1), cols.saturating_sub(1));
    let mut out = Vec::with_capacity(rows * cols);
    for col in 0..cols {
        for row in 0..rows {
            let (mut sum, mut n) = (0.0, 0);
            for c in col.saturating_sub(1)..(col + 1).min(cc) {
                for r in row.saturating_sub(1)..(row + 1).min(cr) {
                    let v = cell_values[c * cr + r];
                    if v.is_finite() {
                        sum += v;
                        n += 1;
                    }
                }
            }
            out.push(if n > 0 { sum / n as f64 } else { f64::NAN });
        }
    }
    out
}

/// The wheel flank of the reference tooth space (MODEL §2 grid: rows along the height, columns
/// along the face width), placed in the worm frame at rotation 0, in mm, without data.
pub fn wheel_flank_surface(gear: &GearSet, wf: &WheelFlank) -> QuadSurface {
    let a = gear.operating;
    let (rows, cols) = (wf.cells_height + 1, wf.cells_face + 1);
    let mut s = QuadSurface {
        rows,
        cols,
        ..Default::default()
    };
    for j in 0..cols {
        for i in 0..rows {
            let n = wf.node(i, j);
            let p = a.wheel_to_worm(&n.position()) * MM;
            let v = a.vector_wheel_to_worm(&n.normal_vec());
            s.points.push([p.x, p.y, p.z]);
            s.normals.push([v.x, v.y, v.z]);
        }
    }
    s
}

/// The loaded wheel flank with the unloaded analysis's fields (MODEL §4): `no_load_gap_um`
/// (minimum normal separation over the cycle), `no_load_pattern` (1 where marked),
/// `sliding_speed_m_s`, `ease_off_um` (NaN where the worm flank does not reach).
pub fn wheel_flank_tca(gear: &GearSet, geo: &Geometry, tca: &Tca) -> QuadSurface {
    let wf = geo.wheel_flank(tca.loaded_flank);
    let mut s = wheel_flank_surface(gear, wf);
    s.add_cell_field(
        "no_load_gap_um",
        tca.min_separation.iter().map(|v| v * UM).collect(),
    );
    s.add_cell_field(
        "no_load_pattern",
        tca.marked.iter().map(|&m| m as u8 as f64).collect(),
    );
    let reach = |f: &dyn Fn(&crate::kinematics::NodeContact) -> f64| -> Vec<f64> {
        tca.node_contact
            .iter()
            .map(|c| if c.reachable { f(c) } else { f64::NAN })
            .collect()
    };
    s.add_point_data("sliding_speed_m_s", reach(&|c| c.sliding_speed));
    s.add_point_data("ease_off_um", reach(&|c| c.ease_off * UM));
    s
}

/// Adds the loaded contact pattern (largest pressure over the cycle per cell, MPa; 0 where no
/// contact) as `pressure_pattern_mpa`.
pub fn add_pressure_pattern(s: &mut QuadSurface, pattern_pa: &[f64]) {
    s.add_cell_field(
        "pressure_pattern_mpa",
        pattern_pa.iter().map(|p| p / 1e6).collect(),
    );
}

/// Adds a node field of the flank (e.g. wear depth) as point data, scaled by `scale`.
pub fn add_node_field(s: &mut QuadSurface, name: &str, field: &FlankField, scale: f64) {
    s.add_point_data(name, field.values.iter().map(|v| v * scale).collect());
}

/// Both flanks of the worm thread (`gear.analysis.stl_worm_threads` axial pitches of thread
/// sweep, root to tip), in mm, worm frame at rotation 0, with `radius_mm` and `flank` (0 left,
/// 1 right) as point data. Returns one surface per flank.
pub fn worm_flank_surfaces(gear: &GearSet, geo: &Geometry) -> [QuadSurface; 2] {
    let worm = &geo.worm;
    let (rf, ra) = (gear.worm.root_radius, gear.worm.tip_radius);
    let threads = gear.analysis.stl_worm_threads.max(1);
    // Polar sweep covering `threads` axial pitches of one thread's helicoid.
    let lead = worm.lead_per_rad() * 2.0 * PI;
    let span = 2.0 * PI * threads as f64 * worm.axial_pitch() / lead;
    let (rows, cols) = (13, (48.0 * span / (2.0 * PI)).ceil().max(8.0) as usize + 1);
    [Flank::Left, Flank::Right].map(|flank| {
        let mut s = QuadSurface {
            rows,
            cols,
            ..Default::default()
        };
        let mut radius = Vec::new();
        for c in 0..cols {
            let phi = -0.5 * span + span * c as f64 / (cols - 1) as f64;
            for r in 0..rows {
                let rho = rf + (ra - rf) * r as f64 / (rows - 1) as f64;
                let p = worm.flank_point(flank, rho, phi, 0);
                let n = worm.outward_normal(flank, p.y, p.z);
                s.points.push([p.x * MM, p.y * MM, p.z * MM]);
                s.normals.push([n.x, n.y, n.z]);
                radius.push(rho * MM);
            }
        }
        s.add_point_data("radius_mm", radius);
        let side = match flank {
            Flank::Left => 0.0,
            Flank::Right => 1.0,
        };
        s.add_point_data("flank", vec![side; rows * cols]);
        s
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_surface_reads_back_through_a_vtk_parser() {
        // Two patches (3 x 2 and 2 x 2 points) with one point and one cell array.
        let patch = |rows: usize, cols: usize, dx: f64| {
            let mut s = QuadSurface {
                rows,
                cols,
                ..Default::default()
            };
            for c in 0..cols {
                for r in 0..rows {
                    s.points.push([dx + c as f64, r as f64, 0.5]);
                    s.normals.push([0.0, 0.0, 1.0]);
                }
            }
            let n = s.points.len();
            s.add_point_data("height", (0..n).map(|k| k as f64 * 0.25).collect());
            s.add_cell_field("gap_um", vec![f64::INFINITY; s.cell_count()]);
            s
        };
        let (a, b) = (patch(3, 2, 0.0), patch(2, 2, 10.0));
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.vtp");
        a.write_vtp(&path, &[&b], "test").unwrap();
        let vtk = Vtk::import(&path).unwrap();
        let DataSet::PolyData { pieces, .. } = vtk.data else {
            panic!("not PolyData")
        };
        let piece = pieces[0].load_piece_data(None).unwrap();
        assert_eq!(piece.num_points(), 10);
        let Some(VertexNumbers::XML {
            connectivity,
            offsets,
        }) = piece.polys
        else {
            panic!("no polygons")
        };
        // 2 + 1 quads; the second patch's indices are offset by the first's 6 points.
        assert_eq!(offsets, vec![4, 8, 12]);
        assert_eq!(&connectivity[..4], &[0, 1, 4, 3]);
        assert_eq!(&connectivity[8..], &[6, 7, 9, 8]);
        let points: Vec<f64> = piece.points.cast_into().unwrap();
        assert_eq!(&points[3 * 6..3 * 7], &[10.0, 0.0, 0.5]);
        let array = |attrs: &[Attribute], name: &str| -> Vec<f64> {
            attrs
                .iter()
                .find_map(|a| match a {
                    Attribute::DataArray(d) if d.name == name => d.data.clone().cast_into(),
                    _ => None,
                })
                .unwrap_or_else(|| panic!("no array {name}"))
        };
        let height = array(&piece.data.point, "height");
        assert_eq!(height.len(), 10);
        assert_eq!(height[5], 1.25);
        assert_eq!(height[9], 0.75);
        let gap = array(&piece.data.cell, "gap_um");
        assert_eq!(gap.len(), 3);
        assert!(
            gap.iter().all(|v| v.is_nan()),
            "infinite values are written as NaN"
        );
        assert_eq!(array(&piece.data.point, "normal").len(), 30);
    }

    #[test]
    fn cell_values_average_to_points() {
        // 3 x 3 points, 2 x 2 quads with values 1, 2, 3, NaN (column by column).
        let p = cells_to_points(3, 3, &[1.0, 2.0, 3.0, f64::NAN]);
        assert_eq!(p[0], 1.0);
        assert_eq!(p[4], 2.0); // centre: mean of 1, 2, 3
        assert!(p[8].is_nan()); // corner touching only the NaN quad
        assert_eq!(p[2], 2.0);
        assert_eq!(p[7], 3.0);
    }
}
