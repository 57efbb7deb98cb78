//! The friction tractions of the loaded contact and their moments (MODEL §5.2, §13).
//!
//! At each loaded cell the friction on the wheel is mu f along -v_g / |v_g| (v_g = V2 - V1, the
//! wheel's sliding on the worm): the worm drags the wheel. Its moments about the two axes come
//! from the power it carries: per unit normal force, the worm torque gains mu t.V1 / omega1 and
//! the wheel torque mu t.V2 / omega2 (t = -v_g / |v_g|), so that T1 omega1 = T2 omega2 + P_Vz
//! with P_Vz = sum mu f |v_g| wherever the normal forces do no work (the conjugate contact).
//! The local mu follows the pressures (the film's line load, the asperities' share,
//! [`crate::traction`]); the position's solve iterates pressures -> friction -> torques.
//! Also here, shared with the mesh loss of [`crate::friction`]: each slice's line contact for the
//! film, with the curvature rule at the band's end. SI units.

use super::*;
use crate::geometry::rows::nearest_node_on;
use crate::input::{FrictionLaw, Lubricant};
use crate::kinematics::material_velocities;
use crate::lubrication::{FlankRoughness, LineContact};
use crate::traction::{
    central_film_thickness, local_friction, CentralFilm, LocalFriction, PointContact,
};
use std::collections::HashMap;

/// The relative curvature radius across the contact line of every (position, tooth, slice)
/// of a TCA, with a defined value where the TCA has none (MODEL §13): slices at the band's end
/// (the contact line does not cross them) and slices whose gap has no curvature take the
/// radius of the nearest slice of the same contact line (position and tooth) that has one;
/// a contact line with none takes the median radius of the analysis.
#[derive(Debug, Clone)]
pub struct ContactLineRadii {
    /// Per (position, tooth): the (slice, radius) pairs with a finite positive radius.
    lines: HashMap<(usize, i32), Vec<(usize, f64)>>,
    median: f64,
}

impl ContactLineRadii {
    pub fn of(tca: &Tca) -> Self {
        let mut lines: HashMap<(usize, i32), Vec<(usize, f64)>> = HashMap::new();
        let mut all = Vec::new();
        for c in &tca.contact_lines {
            let r = c.curvature_radius;
            if r.is_finite() && r > 0.0 {
                lines
                    .entry((c.position, c.tooth))
                    .or_default()
                    .push((c.slice, r));
                all.push(r);
            }
        }
        all.sort_by(f64::total_cmp);
        let median = all.get(all.len() / 2).copied().unwrap_or(f64::NAN);
        Self { lines, median }
    }

    /// The radius at slice `slice` of tooth `tooth` at position `position`, m.
    pub fn at(&self, position: usize, tooth: i32, slice: usize) -> f64 {
        self.lines
            .get(&(position, tooth))
            .and_then(|line| {
                line.iter()
                    .min_by_key(|(s, _)| (*s as isize - slice as isize).unsigned_abs())
                    .map(|&(_, r)| r)
            })
            .unwrap_or(self.median)
    }
}

/// What the film of a loaded analysis needs that its pressures do not change: the curvature
/// radii and the rolling velocities of the loaded flank's nodes (MODEL §6).
#[derive(Debug, Clone)]
pub struct FilmGeometry {
    pub radii: ContactLineRadii,
    /// (u1, u2) of every node of the loaded flank, m/s ([`Tca::rolling_velocities`]).
    rolling: Vec<(f64, f64)>,
    /// Radii of the loaded flank's nodes, m (same order).
    node_radii: Vec<f64>,
    rows: usize,
}

impl FilmGeometry {
    pub fn new(tca: &Tca, wf: &WheelFlank) -> Self {
        Self {
            radii: ContactLineRadii::of(tca),
            rolling: tca.rolling_velocities(wf),
            node_radii: wf.nodes.iter().map(|n| n.r).collect(),
            rows: wf.cells_height,
        }
    }

    /// Rolling velocities of the node of column `j` nearest radius `r` (m).
    fn rolling_at(&self, j: usize, r: f64) -> (f64, f64) {
        let n = self.rows + 1;
        let column = &self.node_radii[j * n..(j + 1) * n];
        self.rolling[j * n + nearest_node_on(column, |&x| x, r)]
    }

    /// The line contact of each slice of a position's cells (a slice's cells are consecutive:
    /// same tooth, same node column) under the pressures `pressure` (Pa): its curvature radius,
    /// rolling velocities, line load sum p x (width across the line) (N/m) and peak pressure;
    /// with each cell's slice index.
    pub fn slice_lines(
        &self,
        position: usize,
        cells: &[LocalCell],
        pressure: &[f64],
    ) -> (Vec<LineContact>, Vec<usize>) {
        let (ranges, of_cell) = slice_ranges(cells);
        let lines = ranges
            .iter()
            .map(|&(start, end)| {
                let unloaded = self.unloaded_line(position, &cells[start]);
                loaded_line(&unloaded, start..end, cells, pressure)
            })
            .collect();
        (lines, of_cell)
    }

    /// The slices of a position's cells with their films up to the load, for
    /// [`PositionFriction::coefficients`].
    pub fn slice_films(&self, position: usize, cells: &[LocalCell]) -> SliceFilms {
        let (ranges, of_cell) = slice_ranges(cells);
        let slices = ranges
            .into_iter()
            .map(|(start, end)| {
                let line = self.unloaded_line(position, &cells[start]);
                (start, end, line, std::cell::OnceCell::new())
            })
            .collect();
        SliceFilms { slices, of_cell }
    }

    /// The contact line, unloaded, of the slice whose first cell is `first`: its curvature
    /// radius and the rolling velocities where the line crosses the slice (not at its first
    /// cell, which moves with the band's extent).
    fn unloaded_line(&self, position: usize, first: &LocalCell) -> LineContact {
        let (u1, u2) = self.rolling_at(first.slice, first.line_r);
        LineContact {
            radius: self.radii.at(position, first.tooth, first.slice),
            u1,
            u2,
            line_load: 0.0,
            pressure: 0.0,
        }
    }
}

/// The contact line `unloaded` of the slice of cells `range` under their pressures `pressure`
/// (Pa): its line load sum p x (width across the line) (N/m) and its peak pressure.
fn loaded_line(
    unloaded: &LineContact,
    range: std::ops::Range<usize>,
    cells: &[LocalCell],
    pressure: &[f64],
) -> LineContact {
    LineContact {
        line_load: range
            .clone()
            .map(|k| pressure[k] * 2.0 * cells[k].cell.half_nu)
            .sum(),
        pressure: range.map(|k| pressure[k]).fold(0.0, f64::max),
        ..*unloaded
    }
}

/// The slices of a position's cells (a slice's cells are consecutive: same tooth, same node
/// column): each one's (first cell, end), and each cell's slice index.
fn slice_ranges(cells: &[LocalCell]) -> (Vec<(usize, usize)>, Vec<usize>) {
    let mut ranges = Vec::new();
    let mut of_cell = Vec::with_capacity(cells.len());
    let mut start = 0;
    while start < cells.len() {
        let first = &cells[start];
        let end = (start..cells.len())
            .find(|&k| cells[k].tooth_index != first.tooth_index || cells[k].slice != first.slice)
            .unwrap_or(cells.len());
        ranges.push((start, end));
        of_cell.extend(std::iter::repeat_n(ranges.len() - 1, end - start));
        start = end;
    }
    (ranges, of_cell)
}

/// A position's slices on one local mesh (MODEL §6, §13): each slice's cells (consecutive),
/// its contact line unloaded, and its central film up to the load ([`CentralFilm`], found the
/// first time the slice carries load), built once per mesh and read at every update of the
/// friction (the numbers of [`FilmGeometry::slice_lines`] and [`FrictionInputs::films`]).
#[derive(Debug, Clone)]
pub struct SliceFilms {
    /// Each slice's cells (start, end), its line and its film.
    slices: Vec<(usize, usize, LineContact, std::cell::OnceCell<CentralFilm>)>,
    /// Each cell's slice.
    of_cell: Vec<usize>,
}

impl SliceFilms {
    /// The central film thickness (m) of each slice under its cells' pressures `pressure` (Pa):
    /// its line load sum p x (width across the line) and peak pressure.
    fn films(&self, cells: &[LocalCell], pressure: &[f64], inputs: &FrictionInputs) -> Vec<f64> {
        self.slices
            .iter()
            .map(|(start, end, unloaded, film)| {
                let line = loaded_line(unloaded, *start..*end, cells, pressure);
                crate::lubrication::LineFilm::without_formula(&line).unwrap_or_else(|| {
                    film.get_or_init(|| CentralFilm::of(inputs.lubricant, inputs.e_prime, &line))
                        .at(line.line_load, line.pressure)
                })
            })
            .collect()
    }
}

/// The sliding of one cell at the operating speed and the moments of a unit friction force
/// on the wheel along t = -v_g / |v_g| (MODEL §5.2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellSliding {
    /// |v_g|, m/s.
    pub speed: f64,
    /// t.V1 / omega1: the worm torque per newton of friction, m.
    pub worm_arm: f64,
    /// t.V2 / omega2: the wheel torque per newton of friction, m.
    pub wheel_arm: f64,
}

/// The sliding of the cells `cells` (worm frame) of `gear` at its worm speed (MODEL §4.5).
pub fn cell_sliding(gear: &GearSet, geo: &Geometry, cells: &[LocalCell]) -> Vec<CellSliding> {
    let omega1 = gear.conditions.worm_speed;
    let omega2 = omega1 / gear.ratio();
    cells
        .iter()
        .map(|c| {
            let v = material_velocities(
                &c.cell.centre,
                &geo.worm,
                &gear.operating,
                omega1,
                gear.ratio(),
            );
            let vg = Vector3::from(v.sliding);
            let speed = vg.norm();
            if speed == 0.0 {
                return CellSliding {
                    speed,
                    worm_arm: 0.0,
                    wheel_arm: 0.0,
                };
            }
            let t = -vg / speed;
            CellSliding {
                speed,
                worm_arm: t.dot(&Vector3::from(v.worm)) / omega1,
                wheel_arm: t.dot(&Vector3::from(v.wheel)) / omega2,
            }
        })
        .collect()
}

/// The lubricant, friction law and moduli of the local friction (MODEL §13).
#[derive(Debug, Clone, Copy)]
pub struct FrictionInputs<'a> {
    /// The lubricant at the oil temperature.
    pub lubricant: &'a Lubricant,
    pub law: &'a FrictionLaw,
    /// Reduced modulus E' of MODEL §6, Pa.
    pub e_prime: f64,
    /// Flow pressure bounding the asperities' pressure (the wheel's hardness), Pa.
    pub flow_pressure: f64,
}

impl<'a> FrictionInputs<'a> {
    /// The friction inputs of `gear` with `lubricant` (the gear's at some oil temperature).
    pub fn of(gear: &'a GearSet, lubricant: &'a Lubricant) -> Self {
        Self {
            lubricant,
            law: &gear.friction,
            e_prime: crate::lubrication::reduced_modulus(
                gear.worm_material.youngs_modulus,
                gear.worm_material.poisson_ratio,
                gear.wheel_material.youngs_modulus,
                gear.wheel_material.poisson_ratio,
            ),
            flow_pressure: gear.wheel_material.hardness,
        }
    }

    /// The local friction at pressure `pressure` (Pa), sliding speed `sliding_speed` (m/s)
    /// over a central film `film` (m), where the composite roughness is `roughness` (R_q, m;
    /// MODEL §6.1).
    pub fn at(
        &self,
        pressure: f64,
        sliding_speed: f64,
        film: f64,
        roughness: f64,
    ) -> LocalFriction {
        let at = PointContact {
            pressure,
            sliding_speed,
            film_thickness: film,
            roughness,
        };
        let moduli = (self.e_prime, self.flow_pressure);
        local_friction(&at, self.lubricant, self.law, moduli)
    }

    /// The local friction of every cell `cells` with pressure `pressure` (Pa), sliding
    /// `sliding`, the film of its slice `films[of_cell[k]]` (central thickness, m) and the
    /// roughness `roughness` at its centre.
    pub fn cells(
        &self,
        (cells, pressure, sliding): (&[LocalCell], &[f64], &[CellSliding]),
        (films, of_cell): (&[f64], &[usize]),
        roughness: &FlankRoughness,
    ) -> Vec<LocalFriction> {
        cells
            .iter()
            .zip(pressure)
            .zip(sliding)
            .zip(of_cell)
            .map(|(((c, &p), s), &line)| self.at(p, s.speed, films[line], roughness.at(c.r, c.z)))
            .collect()
    }

    /// The central film thickness of each line contact `lines`, m.
    pub fn films(&self, lines: &[LineContact]) -> Vec<f64> {
        lines
            .iter()
            .map(|l| central_film_thickness(self.lubricant, self.e_prime, l))
            .collect()
    }
}

/// The friction of a loaded analysis' positions: what it needs of the gear and its TCA.
pub struct PositionFriction<'a> {
    pub gear: &'a GearSet,
    pub geo: &'a Geometry,
    pub film: FilmGeometry,
    pub inputs: FrictionInputs<'a>,
    /// The composite roughness over the loaded flank (MODEL §6.1).
    pub roughness: FlankRoughness<'a>,
    /// A uniform friction coefficient to start the torque balance from (ISO/TR 14521's mu_0T
    /// at the pitch point's sliding speed): only the start, not the result.
    pub estimate: f64,
}

impl PositionFriction<'_> {
    /// The slices of position `position`'s cells `cells` with their films up to the load,
    /// for [`Self::coefficients`] (once per local mesh).
    pub fn slice_films(&self, position: usize, cells: &[LocalCell]) -> SliceFilms {
        self.film.slice_films(position, cells)
    }

    /// mu of each cell `cells` (their slices `slices`) under the pressures `pressure` (Pa).
    pub fn coefficients(
        &self,
        slices: &SliceFilms,
        cells: &[LocalCell],
        sliding: &[CellSliding],
        pressure: &[f64],
    ) -> Vec<f64> {
        let films = slices.films(cells, pressure, &self.inputs);
        self.inputs
            .cells(
                (cells, pressure, sliding),
                (&films, &slices.of_cell),
                &self.roughness,
            )
            .iter()
            .map(|f| f.coefficient)
            .collect()
    }
}

/// Per unknown q_i = l_i f_i (MODEL §5.2): the worm torque and the wheel torque it carries
/// with the friction coefficients `mu` — (worm_lever_i sign + mu_i worm_arm_i) / l_i and
/// 1 + mu_i wheel_arm_i / l_i — `sign` the driving sense of the worm moments.
pub(super) fn torque_weights(
    cells: &[LocalCell],
    sliding: &[CellSliding],
    mu: &[f64],
    sign: f64,
) -> (Vec<f64>, Vec<f64>) {
    cells
        .iter()
        .zip(sliding)
        .zip(mu)
        .map(|((c, s), &m)| {
            (
                (c.worm_lever * sign + m * s.worm_arm) / c.lever,
                1.0 + m * s.wheel_arm / c.lever,
            )
        })
        .unzip()
}
