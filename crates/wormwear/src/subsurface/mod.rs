//! Sub-surface stress below the wheel flank and the equivalent pressure of the fatigue
//! criterion (MODEL §8.1).
//!
//! **Field.** A uniform pressure on a rectangle of half sides (a, b) over the elastic half-space
//! has a closed-form stress field (Love 1929; K. L. Johnson, Contact Mechanics, 1985, §3.2 and
//! §3.3): with Love's potentials psi1 = integral of p ln(rho + z) and psi = d psi1/dz = integral
//! of p / rho over the loaded area (rho the distance from a surface point to the field point,
//! z the depth), the stresses are (tension positive)
//!
//!   sigma_x  = (1/2pi) [2 nu psi_z - z psi_xx - (1 - 2 nu) psi1_xx]
//!   sigma_y  = (1/2pi) [2 nu psi_z - z psi_yy - (1 - 2 nu) psi1_yy]
//!   sigma_z  = (1/2pi) [psi_z - z psi_zz]
//!   tau_xy   = -(1/2pi) [(1 - 2 nu) psi1_xy + z psi_xy]
//!   tau_xz   = -(1/2pi) z psi_xz,      tau_yz = -(1/2pi) z psi_yz
//!
//! and every derivative of psi and psi1 over a rectangle is a sum over its four corners of a
//! corner function of the offsets (X, Y) from the corner and the depth ([`corner`]; the second
//! derivatives psi1_yy and psi_yy follow from Laplace's equation). The field of the loaded
//! flank is the sum over its cells, each in its own tangent plane, rotated into the frame of
//! the cell below which the stress is read (x across the contact line, y along it, z into the
//! wheel). The tangential traction is zero: friction is not modelled yet (MODEL §13).
//!
//! **Criterion.** p_eq = max over depth of tau_1 / 0.300, tau_1 = (sigma_1 - sigma_3) / 2 the
//! principal shear stress: p0 below a Hertz line contact (tau_1 = 0.300 p0 at z = 0.786 a, any
//! nu), so the bronze's pressure–life curve applies unchanged; the depth of that maximum is the
//! pit depth. Option: the orthogonal shear |tau_xz| / 0.25 (0.25 p0 at z = 0.5 a, line contact).

mod lanes;
use lanes::Batch;
mod love;

pub use love::rectangle_stress;

use crate::contact::ContactCell;
use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;
use std::f64::consts::PI;
use std::ops::Range;

/// The largest principal shear stress below a Hertz line contact over its peak pressure, any
/// Poisson ratio (Johnson 1985, §4.2): tau_1 = 0.300 p0 at z = 0.786 a.
pub const LINE_CONTACT_PRINCIPAL_SHEAR: f64 = 0.300;
/// The largest orthogonal shear |tau_xz| below a Hertz line contact over p0 (0.25 p0 at
/// z = 0.5 a, x = +-0.87 a; Johnson 1985, §4.2).
pub const LINE_CONTACT_ORTHOGONAL_SHEAR: f64 = 0.25;

/// A symmetric stress tensor [xx, yy, zz, xy, xz, yz], Pa (tension positive).
pub type Stress = [f64; 6];

/// The stress the fatigue criterion reads (MODEL §8.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Criterion {
    /// Principal shear tau_1 = (sigma_1 - sigma_3) / 2, over 0.300.
    PrincipalShear,
    /// Orthogonal shear |tau_xz| (x across the contact line), over 0.25.
    OrthogonalShear,
}

impl Criterion {
    /// What the equivalent pressure is, in words (titles, summary).
    pub fn definition(self) -> &'static str {
        match self {
            Criterion::PrincipalShear => "max over depth of tau_1 / 0.300",
            Criterion::OrthogonalShear => "max over depth of |tau_xz| / 0.25",
        }
    }

    /// The criterion's stress of a tensor (Pa) and its value below a Hertz line contact per
    /// unit peak pressure.
    fn read(self, s: &Stress) -> f64 {
        match self {
            Criterion::PrincipalShear => principal_shear(s) / LINE_CONTACT_PRINCIPAL_SHEAR,
            Criterion::OrthogonalShear => s[4].abs() / LINE_CONTACT_ORTHOGONAL_SHEAR,
        }
    }
}

/// How the equivalent pressure is evaluated (MODEL §8.1).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SubsurfaceSettings {
    /// Poisson's ratio of the body below the surface (the wheel's bronze).
    pub poisson: f64,
    pub criterion: Criterion,
    /// Depths of the search: `depth_levels` (at least 3) from `depth_from` to `depth_to` times
    /// the loaded half-width a of the row. The layer above `depth_from` is left out: there a
    /// stress raiser narrower than a (an edge ridge, a one-cell spike) sets the stress, which is
    /// the plastic limit's and the wear's (MODEL §5.7, §7), not sub-surface fatigue's; the
    /// maxima of the Hertz line (0.786 a) and point (0.48 a) contacts lie inside.
    pub depth_levels: usize,
    pub depth_from: f64,
    pub depth_to: f64,
    /// Sources farther than this many loaded half-widths (in the surface) from the field point
    /// are left out of its sum.
    pub reach: f64,
}

impl SubsurfaceSettings {
    /// Principal shear, depths every 0.44 a from 0.25 a to 2 a (then refined), the loaded
    /// cells of the row and its neighbours exactly, the farther rows lumped.
    pub fn new(poisson: f64) -> Self {
        Self {
            poisson,
            criterion: Criterion::PrincipalShear,
            depth_levels: 5,
            depth_from: 0.25,
            depth_to: 2.0,
            reach: 0.5,
        }
    }
}

/// The mean stress, q = sqrt(J2 / 3) and cos(3 phi) = det(deviator) / (2 q^3) of a symmetric
/// tensor (Pa, Pa, -): the principal stresses are mean + 2 q cos(phi + 2 pi k / 3). None when
/// the deviator vanishes (to round-off).
fn deviator_invariants(s: &Stress) -> (f64, Option<(f64, f64)>) {
    let [xx, yy, zz, xy, xz, yz] = *s;
    let off = xy * xy + xz * xz + yz * yz;
    let mean = (xx + yy + zz) * (1.0 / 3.0);
    let (dx, dy, dz) = (xx - mean, yy - mean, zz - mean);
    let q2 = (dx * dx + dy * dy + dz * dz + 2.0 * off) * (1.0 / 6.0);
    if q2 <= 1e-30 * mean * mean || q2 == 0.0 {
        return (mean, None);
    }
    let q = q2.sqrt();
    let det = dx * (dy * dz - yz * yz) - xy * (xy * dz - yz * xz) + xz * (xy * yz - dy * xz);
    (mean, Some((q, (0.5 * det / (q2 * q)).clamp(-1.0, 1.0))))
}

/// Principal stresses of a symmetric tensor, descending (Pa): the closed-form roots of its
/// characteristic cubic (trigonometric form).
pub fn principal_stresses(s: &Stress) -> [f64; 3] {
    let (mean, invariants) = deviator_invariants(s);
    let Some((q, r)) = invariants else {
        return [mean; 3];
    };
    let phi = r.acos() / 3.0;
    let s1 = mean + 2.0 * q * phi.cos();
    let s3 = mean + 2.0 * q * (phi + 2.0 * PI / 3.0).cos();
    [s1, 3.0 * mean - s1 - s3, s3]
}

/// Principal shear stress tau_1 = (sigma_1 - sigma_3) / 2 of a tensor, Pa: from the
/// invariants of [`deviator_invariants`], sigma_1 - sigma_3 = 2 sqrt(3) q sin(phi + pi / 3)
/// = 2 sqrt(3) q cos(delta), delta = acos(cos 3 phi) / 3 - pi / 6 in [-pi/6, pi/6]; the
/// arccosine as the argument of (cos 3 phi, sin 3 phi), the cosine by its Taylor series to
/// delta^14 (the next term is below 2e-18).
pub fn principal_shear(s: &Stress) -> f64 {
    let (_, Some((q, r))) = deviator_invariants(s) else {
        return 0.0;
    };
    let three_phi = lanes::argument::<false>(r, ((1.0 - r) * (1.0 + r)).sqrt());
    let delta = three_phi * (1.0 / 3.0) - PI / 6.0;
    // (-1)^k / (2k)!, k = 0..7.
    const TAYLOR: [f64; 8] = [
        1.0,
        -0.5,
        1.0 / 24.0,
        -1.0 / 720.0,
        1.0 / 40_320.0,
        -1.0 / 3_628_800.0,
        1.0 / 479_001_600.0,
        -1.0 / 87_178_291_200.0,
    ];
    let d2 = delta * delta;
    let cosine = TAYLOR.iter().rev().fold(0.0, |sum, c| sum * d2 + c);
    3f64.sqrt() * q * cosine
}

/// The frame of a cell: columns across the line, along it, and into the body (-normal).
fn frame(c: &ContactCell) -> Matrix3<f64> {
    Matrix3::from_columns(&[c.axis_nu, c.axis_zeta, -c.normal])
}

/// The frame of a source rectangle, as [`frame`].
fn source_frame(s: &Source) -> Matrix3<f64> {
    Matrix3::from_columns(&[s.axis_nu, s.axis_zeta, -s.normal])
}

/// Stress at depth `depth` (m) below the centre of `at`, in its frame (x across the line, y
/// along it, z into the body), from the pressures (Pa) of the cells `sources` of `cells` (one
/// body's surface). Pa.
pub fn stress_below(
    cells: &[ContactCell],
    pressure: &[f64],
    sources: &[usize],
    at: &ContactCell,
    depth: f64,
    nu: f64,
) -> Stress {
    let to = frame(at).transpose();
    let mut batch = Batch::default();
    for &j in sources.iter().filter(|&&j| pressure[j] != 0.0) {
        batch.push(
            &Source::of(&cells[j], pressure[j]),
            &(to * frame(&cells[j])),
        );
    }
    field(at, &batch, depth, nu)
}

/// The equivalent pressure below one cell (MODEL §8.1): the criterion's largest value over
/// depth (Pa) and the depth of that maximum (m).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct Equivalent {
    pub pressure: f64,
    pub depth: f64,
}

/// One source rectangle seen from a row's field points: centre, frame, half sides, pressure.
#[derive(Debug, Clone)]
struct Source {
    centre: Vector3<f64>,
    axis_nu: Vector3<f64>,
    axis_zeta: Vector3<f64>,
    normal: Vector3<f64>,
    half_nu: f64,
    half_zeta: f64,
    pressure: f64,
}

impl Source {
    fn of(c: &ContactCell, pressure: f64) -> Self {
        Self {
            centre: c.centre,
            axis_nu: c.axis_nu,
            axis_zeta: c.axis_zeta,
            normal: c.normal,
            half_nu: c.half_nu,
            half_zeta: c.half_zeta,
            pressure,
        }
    }
}

/// A row's load as one rectangle, for field points far from it: its loaded width and length
/// at the mean pressure, centred on the force centroid, in the frame of its first loaded cell.
/// None for an unloaded row.
fn lumped_row(cells: &[ContactCell], pressure: &[f64], range: &Range<usize>) -> Option<Source> {
    let first = range.clone().find(|&k| pressure[k] > 0.0)?;
    let (mut force, mut area, mut moment) = (0.0, 0.0, Vector3::zeros());
    let mut half_zeta: f64 = 0.0;
    for k in range.clone().filter(|&k| pressure[k] > 0.0) {
        let f = pressure[k] * cells[k].area();
        force += f;
        area += cells[k].area();
        moment += cells[k].centre * f;
        half_zeta = half_zeta.max(cells[k].half_zeta);
    }
    let half_nu = 0.25 * area / half_zeta;
    Some(Source {
        centre: moment / force,
        half_nu,
        half_zeta,
        pressure: force / area,
        ..Source::of(&cells[first], 0.0)
    })
}

/// The equivalent pressure below every cell of one body's loaded surface (MODEL §8.1), from
/// the cells' pressures (Pa). `rows` are the ranges of cells that form rows across the contact
/// line (a slice of the local mesh) and `surface[r]` the surface (tooth) of row r: a cell's
/// field sums the loaded cells of the rows of its surface within `settings.reach` loaded
/// half-widths exactly, and the farther rows as rectangles ([`lumped_row`], merged in blocks
/// that grow with their distance; the in-plane stresses of a line load reach far), their field
/// read once per row and depth below the row's load centre. Depths: `depth_levels` from
/// `depth_from` to `depth_to` times the row's loaded half-width (half the width of its loaded
/// cells), the maximum refined by successive parabolas. Unloaded cells and rows get zero.
pub fn equivalent_pressures(
    cells: &[ContactCell],
    pressure: &[f64],
    rows: &[Range<usize>],
    surface: &[usize],
    settings: &SubsurfaceSettings,
) -> Vec<Equivalent> {
    let lumps: Vec<Option<Source>> = rows
        .iter()
        .map(|r| lumped_row(cells, pressure, r))
        .collect();
    // The rows of each surface in their order, and each row's place among them.
    let mut surfaces: Vec<Vec<usize>> = Vec::new();
    let mut place = vec![0; rows.len()];
    for (r, &s) in surface.iter().enumerate() {
        if surfaces.len() <= s {
            surfaces.resize(s + 1, Vec::new());
        }
        place[r] = surfaces[s].len();
        surfaces[s].push(r);
    }
    let radius: Vec<f64> = lumps
        .iter()
        .map(|l| l.as_ref().map_or(0.0, |l| l.half_nu.hypot(l.half_zeta)))
        .collect();
    let load = Load {
        cells,
        pressure,
        rows,
        surface,
        lumps: &lumps,
        surfaces: &surfaces,
        place: &place,
        radius: &radius,
    };
    let per_row: Vec<Vec<Equivalent>> = (0..rows.len())
        .into_par_iter()
        .map(|r| load.row_equivalents(r, settings))
        .collect();
    let mut out = vec![Equivalent::default(); cells.len()];
    for (range, values) in rows.iter().zip(per_row) {
        out[range.clone()].copy_from_slice(&values);
    }
    out
}

/// The loaded surface of [`equivalent_pressures`] with its rows' lumps: the rows of each
/// surface in order (`surfaces`), each row's place in its surface's list, and the radius of
/// each lump's circumscribed circle (m).
struct Load<'a> {
    cells: &'a [ContactCell],
    pressure: &'a [f64],
    rows: &'a [Range<usize>],
    surface: &'a [usize],
    lumps: &'a [Option<Source>],
    surfaces: &'a [Vec<usize>],
    place: &'a [usize],
    radius: &'a [f64],
}

impl Load<'_> {
    /// [`equivalent_pressures`] of row r.
    fn row_equivalents(&self, r: usize, settings: &SubsurfaceSettings) -> Vec<Equivalent> {
        let range = &self.rows[r];
        let mut out = vec![Equivalent::default(); range.len()];
        let Some(lump) = &self.lumps[r] else {
            return out;
        };
        let a = lump.half_nu;
        let sources = self.sources_of(r, settings.reach * a);
        let levels = settings.depth_levels.max(3);
        let (from, to) = (settings.depth_from * a, settings.depth_to * a);
        let depths: Vec<f64> = (0..levels)
            .map(|k| (from + (to - from) * k as f64 / (levels - 1) as f64).max(1e-3 * a))
            .collect();
        // The far rows' field varies over distances of their distance: read once per depth
        // below the row's load centre.
        let below = ContactCell {
            centre: lump.centre,
            normal: lump.normal,
            axis_nu: lump.axis_nu,
            axis_zeta: lump.axis_zeta,
            half_nu: lump.half_nu,
            half_zeta: lump.half_zeta,
        };
        let far_field: Vec<Stress> = depths
            .iter()
            .map(|&z| field(&below, &sources.far, z, settings.poisson))
            .collect();
        let loaded: Vec<usize> = range.clone().filter(|&k| self.pressure[k] > 0.0).collect();
        let cells: Vec<&ContactCell> = loaded.iter().map(|&k| &self.cells[k]).collect();
        let found = row_search(&cells, &sources.near, &far_field, &depths, settings);
        for (k, e) in loaded.into_iter().zip(found) {
            out[k - range.start] = e;
        }
        out
    }

    /// The sources of row r's field, rotated into its frame, near and far: the loaded cells of
    /// the rows of its surface whose lump lies within `reach` (m, in the surface) of its own;
    /// beyond, the rows' lumps, merged in blocks of consecutive rows up to half as long as their
    /// distance from r in rows ([`Block`]; the rows of a surface are given in their order along
    /// the line).
    fn sources_of(&self, r: usize, reach: f64) -> Sources {
        let Some(own) = &self.lumps[r] else {
            return Sources::default();
        };
        let to = source_frame(own).transpose();
        let same = &self.surfaces[self.surface[r]];
        let at = self.place[r];
        // The row's lump and whether it lies beyond the reach (its gap to r's lump, the
        // distance less both circumscribed radii, above `reach`), None for an unloaded row.
        let lump_of = |o: usize| {
            let lump = self.lumps[o].as_ref()?;
            let limit = reach + self.radius[o] + self.radius[r];
            let far = limit < 0.0 || (lump.centre - own.centre).norm_squared() > limit * limit;
            Some((lump, far))
        };
        let far_lump = |o: usize| lump_of(o).and_then(|(lump, far)| far.then_some(lump));
        let mut sources = Sources::default();
        for &o in same
            .iter()
            .filter(|&&o| lump_of(o).is_some_and(|(_, far)| !far))
        {
            for k in self.rows[o].clone().filter(|&k| self.pressure[k] > 0.0) {
                let cell = &self.cells[k];
                sources
                    .near
                    .push(&Source::of(cell, self.pressure[k]), &(to * frame(cell)));
            }
        }
        // The far rows on each side, outward from r.
        let sides: [&mut dyn Iterator<Item = (usize, usize)>; 2] = [
            &mut (0..at).rev().map(|index| (at - index, same[index])),
            &mut (at + 1..same.len()).map(|index| (index - at, same[index])),
        ];
        for side in sides {
            let mut block: Option<Block> = None;
            for (distance, o) in side {
                let Some(lump) = far_lump(o) else {
                    continue;
                };
                let b = block.get_or_insert_with(|| Block::new(lump, distance));
                b.add(lump);
                if b.count >= (b.first / 2).max(1) {
                    b.push_to(&mut sources.far, &to);
                    block = None;
                }
            }
            if let Some(b) = block {
                b.push_to(&mut sources.far, &to);
            }
        }
        sources
    }
}

/// Lumps of consecutive rows as one rectangle: their force at its centroid over their area,
/// as long as the rows together, in the frame of the first; `first` is the first row's
/// distance from the field's row, in rows.
struct Block<'a> {
    lump: &'a Source,
    first: usize,
    count: usize,
    force: f64,
    area: f64,
    moment: Vector3<f64>,
    half_zeta: f64,
}

impl<'a> Block<'a> {
    fn new(lump: &'a Source, first: usize) -> Self {
        Self {
            lump,
            first,
            count: 0,
            force: 0.0,
            area: 0.0,
            moment: Vector3::zeros(),
            half_zeta: 0.0,
        }
    }

    fn add(&mut self, s: &Source) {
        let (a, f) = (
            4.0 * s.half_nu * s.half_zeta,
            s.pressure * 4.0 * s.half_nu * s.half_zeta,
        );
        self.force += f;
        self.area += a;
        self.moment += s.centre * f;
        self.half_zeta += s.half_zeta;
        self.count += 1;
    }

    /// The block's rectangle (the lump itself for one row) into `batch`, rotated by `to`
    /// (the field frame's transpose).
    fn push_to(&self, batch: &mut Batch, to: &Matrix3<f64>) {
        let rotation = to * source_frame(self.lump);
        if self.count == 1 {
            batch.push(self.lump, &rotation);
            return;
        }
        let merged = Source {
            centre: self.moment / self.force,
            half_nu: 0.25 * self.area / self.half_zeta,
            half_zeta: self.half_zeta,
            pressure: self.force / self.area,
            ..self.lump.clone()
        };
        batch.push(&merged, &rotation);
    }
}

/// The sources of one row's field ([`Load::sources_of`]), rotated into its frame: the
/// loaded cells of the row and of the rows near it, and the farther rows' merged lumps.
#[derive(Default)]
struct Sources {
    near: Batch,
    far: Batch,
}

/// Parabolic refinements of the depth search.
const REFINEMENTS: usize = 3;

/// The depths evaluated below one cell, ascending, with the criterion's value at each.
#[derive(Clone, Copy)]
struct DepthSearch {
    points: [(f64, f64); MAX_DEPTHS],
    count: usize,
    done: bool,
}

impl DepthSearch {
    /// The next depth to evaluate: the vertex of the parabola through the best depth so far and
    /// its nearest evaluated neighbours (successive parabolic interpolation); None when the
    /// best is at an end of the grid or the vertex falls on a depth already evaluated (no
    /// threshold on the step: a discrete choice would turn round-off in the pressures into a
    /// different depth).
    fn next_depth(&self) -> Option<f64> {
        let evaluated = &self.points[..self.count];
        let best = (0..self.count)
            .max_by(|&a, &b| evaluated[a].1.total_cmp(&evaluated[b].1))
            .unwrap_or(0);
        if best == 0 || best + 1 == self.count {
            return None;
        }
        let ((z0, l), (z1, c), (z2, r)) =
            (evaluated[best - 1], evaluated[best], evaluated[best + 1]);
        let (d0, d2) = (z1 - z0, z1 - z2);
        let num = d0 * d0 * (c - r) - d2 * d2 * (c - l);
        let den = d0 * (c - r) - d2 * (c - l);
        if den == 0.0 {
            return None;
        }
        let z = (z1 - 0.5 * num / den).clamp(z0, z2);
        (!evaluated.iter().any(|p| p.0 == z)).then_some(z)
    }

    /// Adds the value at depth z in its place.
    fn insert(&mut self, z: f64, value: f64) {
        let at = self.points[..self.count].partition_point(|p| p.0 < z);
        self.points.copy_within(at..self.count, at + 1);
        self.points[at] = (z, value);
        self.count += 1;
    }

    /// The largest value and its depth.
    fn best(&self) -> Equivalent {
        let (depth, pressure) = self.points[..self.count]
            .iter()
            .copied()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or_default();
        Equivalent { pressure, depth }
    }
}

/// The equivalent pressure below each of a row's loaded `cells`: the criterion on the depth
/// grid of the stress of the `near` sources plus the far rows' field `far` (at `depths`), its
/// maximum refined [`REFINEMENTS`] times ([`DepthSearch::next_depth`]), the near sources'
/// field exact at each new depth, the far one interpolated ([`cubic_at`]). The cells advance
/// together, so each evaluation round is one call for all of them (the sources' last, partly
/// loaded pass shared by their points).
fn row_search(
    cells: &[&ContactCell],
    near: &Batch,
    far: &[Stress],
    depths: &[f64],
    settings: &SubsurfaceSettings,
) -> Vec<Equivalent> {
    let read = |near: &Stress, far: &Stress| settings.criterion.read(&add(*near, far));
    let grid = depths.len().min(MAX_DEPTHS - REFINEMENTS);
    let below = |cell: &ContactCell, z: f64| cell.centre - cell.normal * z;
    let points: Vec<Vector3<f64>> = cells
        .iter()
        .flat_map(|c| depths[..grid].iter().map(move |&z| below(c, z)))
        .collect();
    let near_grid = near.stress_at_points(&points, settings.poisson);
    let mut searches: Vec<DepthSearch> = near_grid
        .chunks(grid.max(1))
        .map(|stresses| {
            let mut s = DepthSearch {
                points: [(0.0, 0.0); MAX_DEPTHS],
                count: grid,
                done: false,
            };
            for (p, ((&z, f), n)) in s
                .points
                .iter_mut()
                .zip(depths.iter().zip(far).zip(stresses))
            {
                *p = (z, read(n, f));
            }
            s
        })
        .collect();
    for _ in 0..REFINEMENTS {
        let mut next = Vec::new();
        for (k, s) in searches.iter_mut().enumerate().filter(|(_, s)| !s.done) {
            match s.next_depth() {
                Some(z) => next.push((k, z)),
                None => s.done = true,
            }
        }
        if next.is_empty() {
            break;
        }
        let points: Vec<Vector3<f64>> = next.iter().map(|&(k, z)| below(cells[k], z)).collect();
        let stresses = near.stress_at_points(&points, settings.poisson);
        for (&(k, z), n) in next.iter().zip(&stresses) {
            searches[k].insert(z, read(n, &cubic_at(depths, far, z)));
        }
    }
    searches.iter().map(DepthSearch::best).collect()
}

/// The most depths a search evaluates (grid and refinements).
const MAX_DEPTHS: usize = 32;

/// The sum of two tensors.
fn add(mut a: Stress, b: &Stress) -> Stress {
    for (x, y) in a.iter_mut().zip(b) {
        *x += y;
    }
    a
}

/// The tensor at depth z from its values at `depths` (ascending, evenly spaced, at least 3):
/// the cubic through the four depths around z (the parabola through three when there are
/// three), componentwise, its Lagrange weights in t = (z - first depth) / spacing.
fn cubic_at(depths: &[f64], values: &[Stress], z: f64) -> Stress {
    let n = depths.len();
    let k = depths.partition_point(|&d| d <= z).clamp(1, n - 1);
    let spacing = (depths[n - 1] - depths[0]) / (n - 1) as f64;
    let (first, weights) = if n >= 4 {
        let first = (k - 1).saturating_sub(1).min(n - 4);
        let t = (z - depths[first]) / spacing;
        let (a, b, c, d) = (t, t - 1.0, t - 2.0, t - 3.0);
        (
            first,
            [
                -b * c * d / 6.0,
                a * c * d / 2.0,
                -a * b * d / 2.0,
                a * b * c / 6.0,
            ],
        )
    } else {
        let t = (z - depths[0]) / spacing;
        let (a, b, c) = (t, t - 1.0, t - 2.0);
        (0, [b * c / 2.0, -a * c, a * b / 2.0, 0.0])
    };
    let mut out = [0.0; 6];
    for (w, v) in weights.iter().zip(&values[first..]) {
        for (o, x) in out.iter_mut().zip(v) {
            *o += w * x;
        }
    }
    out
}

/// Stress at depth z below the centre of `at` from `sources`, in the row's frame. Pa.
fn field(at: &ContactCell, sources: &Batch, z: f64, nu: f64) -> Stress {
    sources.stress_at(&(at.centre - at.normal * z), nu)
}

/// The principal shear stress tau_1 on a section below one row of cells (MODEL §8.1): across
/// the line over the row's extent and down to `depth_to` times its loaded half-width, on
/// `across` x `depths` points (Pa; `tau1[d * across + i]` at `x[i]`, `z[d]`, m, x from the row's
/// first cell's outer edge along its axis across the line).
#[derive(Debug, Clone, serde::Serialize)]
pub struct Section {
    pub x: Vec<f64>,
    pub z: Vec<f64>,
    pub tau1: Vec<f64>,
}

/// [`Section`] below `row` (cells of `cells`, consecutive, in order across the line) from
/// the pressures of the cells `sources` (Pa) of one body's surface, Poisson's ratio `nu`.
pub fn section(
    cells: &[ContactCell],
    pressure: &[f64],
    row: Range<usize>,
    sources: &[usize],
    (across, depths, depth_to): (usize, usize, f64),
    nu: f64,
) -> Section {
    let first = cells[row.start];
    let last = cells[row.end - 1];
    let width = (last.centre - first.centre).dot(&first.axis_nu) + first.half_nu + last.half_nu;
    let a = row
        .clone()
        .filter(|&k| pressure[k] > 0.0)
        .map(|k| cells[k].half_nu)
        .sum::<f64>()
        .max(first.half_nu);
    let x: Vec<f64> = (0..across)
        .map(|i| (i as f64 + 0.5) / across as f64 * width)
        .collect();
    let z: Vec<f64> = (0..depths)
        .map(|d| (d as f64 + 0.5) / depths as f64 * depth_to * a)
        .collect();
    let origin = first.centre - first.axis_nu * first.half_nu;
    let tau1 = z
        .iter()
        .flat_map(|&depth| x.iter().map(move |&xi| (depth, xi)))
        .map(|(depth, xi)| {
            let at = ContactCell {
                centre: origin + first.axis_nu * xi,
                ..first
            };
            principal_shear(&stress_below(cells, pressure, sources, &at, depth, nu))
        })
        .collect();
    Section { x, z, tau1 }
}
