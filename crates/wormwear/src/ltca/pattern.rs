//! What the positions give over the mesh cycle (MODEL §5.6, §5.7, §8.1): the swept contact
//! pattern, the mesh-converged patch pressure, the equivalent (sub-surface) pressures, the plastic
//! rows, and the warnings on deflection and the flow pressure.

use super::*;

/// The share of a wheel pitch beyond which the load's rotation of the wheel is implausible.
pub const DEFLECTION_PITCH_SHARE_WARNING: f64 = 0.1;

/// A warning when the load turns the wheel (the loaded transmission error less the unloaded
/// kinematic error: contact approach and bending) by more than
/// [`DEFLECTION_PITCH_SHARE_WARNING`] of its angular pitch at some position: deflections that
/// large are outside the small-deflection (linear) model, whatever the solver says. (A large
/// kinematic error, from a misalignment, is geometry and not warned here.)
pub(super) fn deflection_warning(
    positions: &[PositionResult],
    tca: &Tca,
    teeth: u32,
) -> Option<String> {
    let pitch = 2.0 * PI / teeth as f64;
    let largest = positions
        .iter()
        .map(|p| (tca.positions[p.position].kinematic_error - p.transmission_error).abs())
        .fold(0.0, f64::max);
    (largest > DEFLECTION_PITCH_SHARE_WARNING * pitch).then(|| {
        format!(
            "the load turns the wheel by {largest:.3e} rad (loaded less unloaded transmission \
             error), {:.0} % of a wheel pitch ({pitch:.4} rad): deflections this large are \
             outside the linear model (check the torque, the bending model's supports and the \
             materials)",
            100.0 * largest / pitch
        )
    })
}

/// A warning when some of the flank reaches the flow pressure (MODEL §5.7): what share, and
/// that its pressures are the plastic limit's.
pub(super) fn flow_pressure_warning(
    yielded_area_fraction: f64,
    flow_pressure: f64,
    place: &YieldedPlaces,
) -> Option<String> {
    (yielded_area_fraction > 0.0).then(|| {
        format!(
            "{:.2} % of the active flank reaches the flow pressure {:.0} MPa (MODEL §5.7), {}: \
             the pressures there are the bronze's plastic limit, not an elastic solution, and \
             the flank takes a plastic set",
            100.0 * yielded_area_fraction,
            flow_pressure * 1e-6,
            place.text()
        )
    })
}

/// A warning when local contact cells reach the flow pressure although no cell of the loaded
/// pattern does (`yielded_area_fraction` 0): a peak narrower than the global grid resolves (e.g.
/// at the wheel's sharp blank-top edge, or where an edge break meets the flank), which P_max
/// reports. Says how many cells at how many positions, their largest area at one position,
/// where they lie (the places of [`YieldedPlaces`], counted in cells) and their span.
pub(super) fn local_flow_pressure_warning(
    positions: &[PositionResult],
    (yielded_area_fraction, flow_pressure): (f64, f64),
    wf: &WheelFlank,
    (tip_trace, tip_edge_height): (&[(f64, f64)], f64),
) -> Option<String> {
    if yielded_area_fraction > 0.0 {
        return None;
    }
    let bound = flow_pressure * (1.0 - 1e-9);
    let (mut at_positions, mut widest) = (0, 0.0f64);
    let mut place = YieldedPlaces::empty();
    for p in positions {
        let at: Vec<usize> = (0..p.pressure.len())
            .filter(|&k| p.pressure[k] >= bound)
            .collect();
        if at.is_empty() {
            continue;
        }
        at_positions += 1;
        widest = widest.max(at.iter().map(|&k| p.cells[k].cell.area()).sum());
        for &k in &at {
            let c = &p.cells[k];
            let nj = wf.cells_face;
            let f = (c.z - wf.z[0]) / (wf.z[nj] - wf.z[0]) * nj as f64;
            let j = (f.max(0.0) as usize).min(nj - 1);
            let cell_height = wf.largest_row_of(j);
            let trace = tip_trace
                .get(j)
                .map_or(f64::NEG_INFINITY, |t| t.1 + tip_edge_height);
            let top = c.r > wf.r_high[j] - cell_height;
            place.add(
                YieldedPlaces::which(j, nj, (c.r, trace, cell_height), top),
                c,
                1.0,
            );
        }
    }
    let count: f64 = place.shares.iter().sum();
    (count > 0.0).then(|| {
        format!(
            "P_max is the flow pressure {:.0} MPa (MODEL §5.7) on {count} local contact cells at \
             {at_positions} of {} positions (at most {:.3} mm^2 at one position, {:.3} % of the \
             active flank), {}: a peak narrower than the flank grid, which the loaded pattern \
             (P_patch, p_eq,2%) does not resolve",
            flow_pressure * 1e-6,
            positions.len(),
            widest * 1e6,
            100.0 * widest / wf.active_area(),
            place.text_counted()
        )
    })
}

/// Contact cells across the line that a contact must span to count as resolved (MODEL §5.1:
/// several cells across the Hertz width).
pub const RESOLVED_CELLS_ACROSS: f64 = 3.0;

/// The Hertz contact width (m) of the worm's broken tip edge on the wheel (MODEL §2.3): its
/// circle of radius `radius` (m) against the flank, nearly flat beside it, at the peak
/// pressure `pressure` (Pa), with the pair's Hertz modulus E* (Pa): 2 a = 4 R p0 / E*
/// (Johnson 1985, §4.2: a = 2 R p0 / E* for a cylinder on a plane).
pub fn tip_edge_contact_width(radius: f64, pressure: f64, effective_modulus: f64) -> f64 {
    4.0 * radius * pressure / effective_modulus
}

/// How the worm's broken tip edge (MODEL §2.3) meets the contact cells when its contact is
/// narrower than [`RESOLVED_CELLS_ACROSS`] cells across the line
/// ([`TipEdgeResolution::of`]): its strip's pressures, plastic set and equivalent pressures
/// then read the cells, not the round, and grow as the cells are refined (VALIDATION.md,
/// session 60).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TipEdgeResolution {
    /// The tip edge's radius `worm.tip_edge_radius`, m.
    pub radius_m: f64,
    /// The analysis' largest pressure, Pa (at most the flow pressure).
    pub max_pressure_pa: f64,
    /// The round's Hertz contact width at that pressure, 4 R P_max / E*, m
    /// ([`tip_edge_contact_width`]).
    pub contact_width_m: f64,
    /// The median width across the line of the loaded contact cells, m
    /// ([`loaded_cell_width`]).
    pub cell_width_m: f64,
}

impl TipEdgeResolution {
    /// The tip edge of radius `radius` (m; 0: sharp, None) against contact cells `cell_width`
    /// wide across the line (m), at the analysis' largest pressure `max_pressure` (Pa) with
    /// the Hertz modulus `effective_modulus` (Pa): Some where its Hertz width spans less than
    /// [`RESOLVED_CELLS_ACROSS`] cells. The Hertz width is the round's elastic contact at
    /// P_max; where the edge carries more than that contact can at the flow pressure, its
    /// contact spreads into a plastic plateau of width load / flow pressure, wider than the
    /// Hertz width (0.1-0.25 mm against 51 um for a 1 mm round on the design gear, VALIDATION.md
    /// session 63), so the cells this asks for are then finer than the plateau needs.
    pub fn of(
        radius: f64,
        max_pressure: f64,
        effective_modulus: f64,
        cell_width: f64,
    ) -> Option<Self> {
        if !(radius > 0.0 && max_pressure > 0.0 && cell_width > 0.0) {
            return None;
        }
        let width = tip_edge_contact_width(radius, max_pressure, effective_modulus);
        (width < RESOLVED_CELLS_ACROSS * cell_width).then_some(Self {
            radius_m: radius,
            max_pressure_pa: max_pressure,
            contact_width_m: width,
            cell_width_m: cell_width,
        })
    }

    /// The cell width across the line that would resolve the round's contact, m.
    pub fn resolving_cell_width(&self) -> f64 {
        self.contact_width_m / RESOLVED_CELLS_ACROSS
    }

    /// What this says, for the warnings: the round's width against the cells', and the cells
    /// that would resolve it.
    pub fn text(&self) -> String {
        format!(
            "the worm's broken tip edge (worm.tip_edge_radius_mm = {:.3}) touches the wheel over \
             a Hertz width of at most 4 R P_max / E* = {:.1} um (at P_max = {:.0} MPa), less \
             than {RESOLVED_CELLS_ACROSS:.0} contact cells across the line ({:.1} um each): \
             the pressures, the plastic set and the equivalent pressures on the strip it \
             sweeps read the cells, not the round, and grow as they are refined; resolving it \
             takes cells about {:.1} um wide there, {:.0} times finer (MODEL §2.3, §5.1)",
            self.radius_m * 1e3,
            self.contact_width_m * 1e6,
            self.max_pressure_pa * 1e-6,
            self.cell_width_m * 1e6,
            self.resolving_cell_width() * 1e6,
            (self.cell_width_m / self.resolving_cell_width()).ceil()
        )
    }
}

/// The median width across the contact line of the positions' loaded cells, m (0 when none
/// is loaded): the width [`TipEdgeResolution::of`] compares.
pub(super) fn loaded_cell_width(positions: &[PositionResult]) -> f64 {
    let mut widths: Vec<f64> = positions
        .iter()
        .flat_map(|p| {
            p.cells
                .iter()
                .zip(&p.pressure)
                .filter(|(_, &q)| q > 0.0)
                .map(|(c, _)| 2.0 * c.cell.half_nu)
        })
        .collect();
    if widths.is_empty() {
        return 0.0;
    }
    let middle = widths.len() / 2;
    *widths.select_nth_unstable_by(middle, f64::total_cmp).1
}

/// A point of the flank with its coordinates (r, z), m.
trait HasPlace {
    fn place(&self) -> (f64, f64);
}

impl HasPlace for crate::geometry::FlankPoint {
    fn place(&self) -> (f64, f64) {
        (self.r, self.z)
    }
}

impl HasPlace for LocalCell {
    fn place(&self) -> (f64, f64) {
        (self.r, self.z)
    }
}

/// Where the cells of a pattern at or above a level lie on the flank (MODEL §2.3, §8.1), as
/// shares of the active flank ([`YieldedPlaces`]'s places): the edges (the worm tip's trace,
/// the face ends, the blank top) and elsewhere.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FlankPlaces {
    pub tip_trace: f64,
    pub face_ends: f64,
    pub blank_top: f64,
    pub elsewhere: f64,
}

impl FlankPlaces {
    /// All of it, a share of the active flank.
    pub fn total(&self) -> f64 {
        self.tip_trace + self.face_ends + self.blank_top + self.elsewhere
    }

    /// The edges' part of the total (the worm tip's trace, the face ends, the blank top); 0
    /// for none.
    pub fn edge_share(&self) -> f64 {
        let total = self.total();
        if total > 0.0 {
            (total - self.elsewhere) / total
        } else {
            0.0
        }
    }
}

/// The edges' part of the area at or above p_eq,2% above which the loaded analysis warns that
/// p_eq,2% reads the edges ([`first_pitting_edge_warning`]).
pub const EDGE_READING_SHARE: f64 = 0.5;

/// A warning when p_eq,2% (`first_pitting`, Pa, > 0; MODEL §8.1), what S_H and the area
/// reading of first pitting read, lies mostly on the flank's edges: more than [`EDGE_READING_SHARE`] of
/// the cells at or above it (`places`) at the worm tip's trace, the face ends or the blank top.
/// Its value then follows the edges' shape and the contact cells more than the load
/// (VALIDATION.md, sessions 60-61).
pub(super) fn first_pitting_edge_warning(
    first_pitting: f64,
    places: &YieldedPlaces,
) -> Option<String> {
    let shares = places.places();
    (shares.edge_share() > EDGE_READING_SHARE).then(|| {
        format!(
            "p_eq,2% = {:.0} MPa, what S_H and the area reading of first pitting read (MODEL \
             §8.1), lies on the flank's edges: {:.0} % of the {:.2} % of the active flank at or \
             above it is at the worm tip's trace, the face ends or the blank top ({}); it \
             follows their shape (worm.tip_edge_radius_mm, wheel.face_edge_chamfer_mm, the \
             reliefs) and the contact cells across the line more than the flank's load \
             (VALIDATION.md, sessions 60-61)",
            first_pitting * 1e-6,
            100.0 * shares.edge_share(),
            100.0 * shares.total(),
            places.text()
        )
    })
}

/// Where the cells of a pattern at or above a level lie (MODEL §2.3, §5.7, §8.1): their shares
/// of the active flank at the worm tip's trace (the two rows of cells above the lowest radius
/// the worm's flank reaches in their column, above the rounded tip edge's strip where the worm
/// has one), at the face ends (the first and last columns), at the blank top (the top row) and
/// elsewhere, and the span of their radii and face positions, m.
pub(super) struct YieldedPlaces {
    shares: [f64; 4],
    r: (f64, f64),
    z: (f64, f64),
}

impl YieldedPlaces {
    /// The places of the cells of `pattern` at or above `level` (the flow pressure, p_eq,2%;
    /// Pa) on `wf`, with the worm tip's trace `tip_trace` (per node column: z, radius;
    /// `Tca::tip_trace`) and the height its rounded edge reaches above it (m;
    /// `LtcaSettings::tip_edge_height`).
    pub(super) fn of(
        wf: &WheelFlank,
        pattern: &[f64],
        level: f64,
        (tip_trace, tip_edge_height): (&[(f64, f64)], f64),
    ) -> Self {
        let (ni, nj) = (wf.cells_height, wf.cells_face);
        let bound = level * (1.0 - 1e-9);
        let active = wf.active_area();
        let mut place = Self::empty();
        for k in (0..pattern.len()).filter(|&k| pattern[k] >= bound) {
            let (j, i) = (k / ni, k % ni);
            let cell = &wf.cells[k];
            let trace = tip_trace
                .get(j)
                .map_or(f64::NEG_INFINITY, |t| t.1 + tip_edge_height);
            let cell_height = wf.largest_row_of(j);
            let which = Self::which(j, nj, (cell.r, trace, cell_height), i + 1 == ni);
            place.add(which, cell, wf.cell_area[k] / active);
        }
        place
    }

    /// The shares by place.
    pub(super) fn places(&self) -> FlankPlaces {
        let [tip_trace, face_ends, blank_top, elsewhere] = self.shares;
        FlankPlaces {
            tip_trace,
            face_ends,
            blank_top,
            elsewhere,
        }
    }

    fn empty() -> Self {
        Self {
            shares: [0.0; 4],
            r: (f64::INFINITY, f64::NEG_INFINITY),
            z: (f64::INFINITY, f64::NEG_INFINITY),
        }
    }

    /// The place of a point at radius r of column j (of nj; the worm tip's trace at `trace`,
    /// rows `cell_height` high, m), `top` in the grid's top row: 0 the worm tip's trace, 1 the
    /// face ends, 2 the blank top, 3 elsewhere.
    fn which(j: usize, nj: usize, (r, trace, cell_height): (f64, f64, f64), top: bool) -> usize {
        if j == 0 || j + 1 == nj {
            1
        } else if r <= trace + 2.0 * cell_height {
            0
        } else if top {
            2
        } else {
            3
        }
    }

    /// Adds `share` at place `which` for a point at (r, z) (m).
    fn add(&mut self, which: usize, at: &impl HasPlace, share: f64) {
        let (r, z) = at.place();
        self.shares[which] += share;
        self.r = (self.r.0.min(r), self.r.1.max(r));
        self.z = (self.z.0.min(z), self.z.1.max(z));
    }

    /// [`Self::text`] with the shares counted in cells: "at the blank top (160 cells), ...".
    fn text_counted(&self) -> String {
        self.clause(|s| format!("({s} cell{})", if s == 1.0 { "" } else { "s" }))
    }

    /// The places as a clause: "at the worm tip's trace 0.71 %, the face ends 0.17 %, ... (r
    /// 94.1-109.9 mm, z -22.1-22.1 mm)".
    fn text(&self) -> String {
        self.clause(|s| format!("{:.2} %", 100.0 * s))
    }

    /// The places with their shares as `share` writes them, and the span.
    fn clause(&self, share: impl Fn(f64) -> String) -> String {
        let names = [
            "the worm tip's trace",
            "the face ends",
            "the blank top",
            "elsewhere",
        ];
        let parts: Vec<String> = names
            .iter()
            .zip(self.shares)
            .filter(|(_, s)| *s > 0.0)
            .map(|(n, s)| format!("{n} {}", share(s)))
            .collect();
        format!(
            "at {} (cell centres at r {:.1}-{:.1} mm, z {:.1} to {:.1} mm)",
            parts.join(", "),
            self.r.0 * 1e3,
            self.r.1 * 1e3,
            self.z.0 * 1e3,
            self.z.1 * 1e3
        )
    }
}

/// The loaded pattern's statistics (MODEL §5.6, §5.7): the mean pressure of the loaded cells
/// weighted by their areas (Pa), the loaded share of the active flank S0, the share above the mean S1 (of the active
/// flank) and S2 (of the loaded area), and the share at the flow pressure `flow_pressure`.
pub(super) struct PatternStats {
    pub(super) mean_pressure: f64,
    pub(super) s0: f64,
    pub(super) s1: f64,
    pub(super) s2: f64,
    pub(super) yielded_area_fraction: f64,
}

impl PatternStats {
    pub(super) fn of(wf: &WheelFlank, pattern: &[f64], flow_pressure: f64) -> Self {
        let bound = flow_pressure * (1.0 - 1e-9);
        let active_area = wf.active_area();
        let yielded_area: f64 = (0..pattern.len())
            .filter(|&k| pattern[k] >= bound)
            .map(|k| wf.cell_area[k])
            .sum();
        let loaded: Vec<usize> = (0..pattern.len()).filter(|&k| pattern[k] > 0.0).collect();
        let contact_area: f64 = loaded.iter().map(|&k| wf.cell_area[k]).sum();
        // The mean over the loaded area (MODEL §5.6's mean of the non-zero cells, weighted by
        // their areas: the grid's rows are finer at the worm-tip trace, MODEL §3.3).
        let mean_pressure = if contact_area > 0.0 {
            loaded
                .iter()
                .map(|&k| pattern[k] * wf.cell_area[k])
                .sum::<f64>()
                / contact_area
        } else {
            0.0
        };
        let above: f64 = loaded
            .iter()
            .filter(|&&k| pattern[k] > mean_pressure)
            .map(|&k| wf.cell_area[k])
            .sum();
        Self {
            mean_pressure,
            s0: contact_area / active_area,
            s1: above / active_area,
            s2: if contact_area > 0.0 {
                above / contact_area
            } else {
                0.0
            },
            yielded_area_fraction: yielded_area / active_area,
        }
    }
}

/// What the band's passage leaves on the global grid ([`swept_pattern`]).
pub(super) struct Swept {
    /// Largest pressure at each cell centre, Pa (MODEL §5.6).
    pub(super) pattern: Vec<f64>,
    /// Largest plastic interference at each node of the plastic set's rows, m (MODEL §5.7).
    pub(super) plastic_indentation: FlankField,
    /// Largest equivalent pressure at each cell centre (Pa) and the depth where it is reached
    /// (m; MODEL §8.1).
    pub(super) equivalent_pattern: Vec<f64>,
    pub(super) equivalent_depth: Vec<f64>,
}

/// The loaded pattern (MODEL §5.6), the plastic indentation (MODEL §5.7) and the equivalent
/// pressure (MODEL §8.1) of the band's passage over the global grid: the largest pressure over
/// the whole mesh cycle at each cell centre (the positions' instants and the band's continuous
/// passage between them, [`passage`], so the pattern neither has holes between positions nor
/// moves with their number), the largest interference of the cells at the flow pressure at
/// each node, and the largest equivalent pressure at each cell centre with its depth; from the
/// band's instants on each node column `columns` ([`passage::band_samples`]).
pub(super) fn swept_pattern(
    wf: &WheelFlank,
    tca: &Tca,
    columns: &[Vec<passage::Sample>],
    teeth: u32,
    rows_per_row: usize,
) -> Swept {
    let (ni, nj) = (wf.cells_height, wf.cells_face);
    let tau = 2.0 * PI / teeth as f64;
    let dt = tau / tca.positions.len() as f64;
    let is_slice: Vec<bool> = columns.iter().map(|c| !c.is_empty()).collect();
    let node_r = |j: usize, i: usize| wf.nodes[j * (ni + 1) + i].r;
    type Column = (Vec<f64>, Vec<f64>, Vec<(f64, f64)>);
    let swept: Vec<Column> = columns
        .par_iter()
        .enumerate()
        .map(|(j, samples)| {
            let mid: Vec<f64> = (0..ni)
                .map(|i| 0.5 * (node_r(j, i) + node_r(j, i + 1)))
                .collect();
            // The plastic set's rows (MODEL §5.7): the grid's, rows_per_row times finer (at
            // the same height parameter, [`FlankField::with_rows`]).
            let rows = ni * rows_per_row;
            let fine: Vec<f64> = (0..=rows)
                .map(|i| wf.row_radius(j, i as f64 / rows_per_row as f64))
                .collect();
            (
                passage::swept_max(samples, &mid, dt, passage::Swept::Pressure),
                passage::swept_max(samples, &fine, dt, passage::Swept::Plastic),
                passage::swept_equivalent(samples, &mid, dt),
            )
        })
        .collect();
    // Cell-centre values on each node column (ni per column), then the cell between two.
    let between = |values: &mut Vec<f64>| {
        fill_between_slices(values, ni, &is_slice, wf);
        (0..nj)
            .flat_map(|j| (0..ni).map(move |i| (j, i)))
            .map(|(j, i)| 0.5 * (values[j * ni + i] + values[(j + 1) * ni + i]))
            .collect::<Vec<f64>>()
    };
    let mut mid: Vec<f64> = swept.iter().flat_map(|c| c.0.iter().copied()).collect();
    let pattern = between(&mut mid);
    let mut equivalent: Vec<f64> = swept.iter().flat_map(|c| c.2.iter().map(|e| e.0)).collect();
    // The depth as the equivalent pressure's moments (a cell between a loaded and an
    // unloaded column takes the loaded one's depth).
    let mut moment: Vec<f64> = swept
        .iter()
        .flat_map(|c| c.2.iter().map(|e| e.0 * e.1))
        .collect();
    let equivalent_pattern = between(&mut equivalent);
    let equivalent_depth = between(&mut moment)
        .iter()
        .zip(&equivalent_pattern)
        .map(|(m, p)| if *p > 0.0 { m / p } else { 0.0 })
        .collect();
    let mut plastic_indentation = FlankField::zeros_refined(wf, rows_per_row);
    plastic_indentation.values = swept.iter().flat_map(|c| c.1.iter().copied()).collect();
    fill_between_slices(
        &mut plastic_indentation.values,
        ni * rows_per_row + 1,
        &is_slice,
        wf,
    );
    Swept {
        pattern,
        plastic_indentation,
        equivalent_pattern,
        equivalent_depth,
    }
}

/// The equivalent pressure of the local cells of one position (MODEL §8.1): the rows across
/// the line are its slices, the surfaces its teeth.
pub fn position_equivalents(p: &PositionResult, settings: &SubsurfaceSettings) -> Vec<Equivalent> {
    let mut rows = Vec::new();
    let mut start = 0;
    for k in 1..=p.cells.len() {
        let (a, b) = (&p.cells[start], p.cells.get(k));
        if b.is_none_or(|b| b.tooth_index != a.tooth_index || b.slice != a.slice) {
            rows.push(start..k);
            start = k;
        }
    }
    // The rows of a tooth in their order along the line (node columns).
    rows.sort_by_key(|r| (p.cells[r.start].tooth_index, p.cells[r.start].slice));
    let surface: Vec<usize> = rows.iter().map(|r| p.cells[r.start].tooth_index).collect();
    let cells: Vec<ContactCell> = p.cells.iter().map(|c| c.cell).collect();
    crate::subsurface::equivalent_pressures(&cells, &p.pressure, &rows, &surface, settings)
}

/// Where the equivalent pressure peaks and the principal shear stress on the section below
/// it (MODEL §8.1): the position, the tooth, the face position z (m) and the section across
/// the line below that cell's row (60 x 40 points down to 2 loaded half-widths). `near`
/// (flank radius and face position of the reference tooth, m): the peak among the cells over
/// that point (within their half extents), over the whole flank when none is loaded there.
/// None when no cell is loaded.
pub fn equivalent_section(
    l: &Ltca,
    near: Option<(f64, f64)>,
) -> Option<(usize, i32, f64, crate::subsurface::Section)> {
    let over = |c: &LocalCell, (r, z): (f64, f64)| {
        (c.z - z).abs() <= c.half_dz && (c.r - r).abs() <= c.cell.half_nu.max(c.cell.half_zeta)
    };
    let loaded = |p: &&PositionResult, k: &usize| p.equivalent[*k].pressure > 0.0;
    let cells = || {
        l.positions
            .iter()
            .flat_map(|p| (0..p.equivalent.len()).map(move |k| (p, k)))
            .filter(|(p, k)| loaded(p, k))
    };
    let mut candidates: Vec<(&PositionResult, usize)> = near
        .map(|at| cells().filter(|(p, k)| over(&p.cells[*k], at)).collect())
        .unwrap_or_default();
    if candidates.is_empty() {
        candidates = cells().collect();
    }
    let (p, k) = candidates.into_iter().max_by(|a, b| {
        a.0.equivalent[a.1]
            .pressure
            .total_cmp(&b.0.equivalent[b.1].pressure)
    })?;
    let peak = &p.cells[k];
    let same_row = |c: &LocalCell| c.tooth_index == peak.tooth_index && c.slice == peak.slice;
    let start = (0..=k)
        .rev()
        .take_while(|&i| same_row(&p.cells[i]))
        .last()?;
    let end = (k..p.cells.len())
        .take_while(|&i| same_row(&p.cells[i]))
        .last()?
        + 1;
    let sources: Vec<usize> = (0..p.cells.len())
        .filter(|&i| p.cells[i].tooth_index == peak.tooth_index)
        .collect();
    let cells: Vec<ContactCell> = p.cells.iter().map(|c| c.cell).collect();
    let section = crate::subsurface::section(
        &cells,
        &p.pressure,
        start..end,
        &sources,
        (60, 40, 2.0),
        l.subsurface.poisson,
    );
    Some((p.position, peak.tooth, peak.z, section))
}

/// Node columns that are no slice take the linear interpolation along the face width of the
/// nearest slice columns on each side (the nearest one's values at the grid's ends); `values`
/// holds `rows` values per node column, column after column.
pub(super) fn fill_between_slices(
    values: &mut [f64],
    rows: usize,
    is_slice: &[bool],
    wf: &WheelFlank,
) {
    let slices: Vec<usize> = (0..is_slice.len()).filter(|&j| is_slice[j]).collect();
    if slices.is_empty() || slices.len() == is_slice.len() {
        return;
    }
    for j in (0..is_slice.len()).filter(|&j| !is_slice[j]) {
        let after = slices.partition_point(|&s| s < j);
        let (a, b) = match (after.checked_sub(1).map(|x| slices[x]), slices.get(after)) {
            (Some(a), Some(&b)) => (a, b),
            (Some(a), None) => (a, a),
            (None, Some(&b)) => (b, b),
            (None, None) => continue,
        };
        let t = if a == b {
            0.0
        } else {
            (wf.z[j] - wf.z[a]) / (wf.z[b] - wf.z[a])
        };
        for i in 0..rows {
            let (va, vb) = (values[a * rows + i], values[b * rows + i]);
            values[j * rows + i] = va + (vb - va) * t;
        }
    }
}

/// Rows of the plastic set for each row of the flank's grid (MODEL §5.7): enough for four
/// rows across a local cell of the band `band` (m), so that the set a running-in leaves is
/// read back by the next state's cells as they left it (sampled on the grid's own rows, a
/// yielded band narrower than a row was missed and indented again at every state, and the set
/// grew with the cells across the line). 1 for the purely elastic contact.
pub(super) fn plastic_rows_per_row(wf: &WheelFlank, settings: &LtcaSettings, band: f64) -> usize {
    if !settings.flow_pressure.is_finite() {
        return 1;
    }
    let row = wf.largest_row();
    let cell = 2.0 * band / settings.columns.max(1) as f64;
    (4.0 * row / cell).ceil().clamp(1.0, 64.0) as usize
}

/// Largest mean pressure over a patch `across` wide across the contact line and `along` long
/// along the face width (m), over every tooth at every position, Pa: the pressure of a "cell
/// of stated size". At a sharp edge the local cells' own maximum grows as the mesh is refined
/// (an integrable singularity); this mean converges. Cells are placed in (distance across the
/// line from the band's first column, z) with their widths 2 half_nu and 2 half_dz; pressure is
/// zero outside the cells. The largest mean has a window end on a cell boundary in each
/// direction, which is where the candidates are taken.
///
/// `offset`: with the band grown by extension, the column of the slices' first base cell
/// ([`LtcaSettings::column_offset`]): a slice's cells then start across the line where that
/// column puts them, so that slices extended by different counts stay aligned (None: every
/// slice's first cell starts at 0).
pub fn max_patch_pressure(
    positions: &[PositionResult],
    across: f64,
    along: f64,
    offset: Option<usize>,
) -> f64 {
    positions
        .par_iter()
        .map(|p| {
            // (across lo, across hi, z lo, z hi, pressure) of the loaded cells, per tooth.
            let across_start = across_starts(&p.cells, offset);
            let mut teeth: std::collections::BTreeMap<usize, Vec<[f64; 5]>> = Default::default();
            for ((c, &pr), &x) in p.cells.iter().zip(&p.pressure).zip(&across_start) {
                if pr <= 0.0 {
                    continue;
                }
                teeth.entry(c.tooth_index).or_default().push([
                    x,
                    x + 2.0 * c.cell.half_nu,
                    c.z - c.half_dz,
                    c.z + c.half_dz,
                    pr,
                ]);
            }
            teeth
                .values()
                .map(|cells| patch_mean_max(cells, across, along))
                .fold(0.0, f64::max)
        })
        .reduce(|| 0.0, f64::max)
}

/// Where each cell starts across the contact line, m: the widths 2 half_nu of the cells before
/// it in its slice (same tooth and slice, lower columns), so that the cells of a slice tile the
/// band without overlap even where their widths differ from column to column; a slice's first
/// cell at 0, or with `offset` at its column's distance from that base column.
fn across_starts(cells: &[LocalCell], offset: Option<usize>) -> Vec<f64> {
    let mut order: Vec<usize> = (0..cells.len()).collect();
    order.sort_by_key(|&k| (cells[k].tooth_index, cells[k].slice, cells[k].column));
    let mut start = vec![0.0; cells.len()];
    let mut x = 0.0;
    for (n, &k) in order.iter().enumerate() {
        let same_slice = n > 0 && {
            let previous = &cells[order[n - 1]];
            (previous.tooth_index, previous.slice) == (cells[k].tooth_index, cells[k].slice)
        };
        x = if same_slice {
            x + 2.0 * cells[order[n - 1]].cell.half_nu
        } else {
            offset.map_or(0.0, |o| {
                (cells[k].column as f64 - o as f64) * 2.0 * cells[k].cell.half_nu
            })
        };
        start[k] = x;
    }
    start
}

/// [`max_patch_pressure`] over one tooth's loaded cells.
pub(super) fn patch_mean_max(cells: &[[f64; 5]], across: f64, along: f64) -> f64 {
    // Cells sorted by their z extent's start: a window's cells are found by bisection.
    let mut cells = cells.to_vec();
    cells.sort_by(|a, b| a[2].total_cmp(&b[2]));
    let longest = cells.iter().map(|c| c[3] - c[2]).fold(0.0, f64::max);
    let mut best: f64 = 0.0;
    for c in &cells {
        for x0 in [c[0], c[1] - across] {
            for z0 in [c[2], c[3] - along] {
                let (x1, z1) = (x0 + across, z0 + along);
                let first = cells.partition_point(|d| d[2] < z0 - longest);
                let force: f64 = cells[first..]
                    .iter()
                    .take_while(|d| d[2] < z1)
                    .map(|d| {
                        let ox = (d[1].min(x1) - d[0].max(x0)).max(0.0);
                        let oz = (d[3].min(z1) - d[2].max(z0)).max(0.0);
                        d[4] * ox * oz
                    })
                    .sum();
                best = best.max(force / (across * along));
            }
        }
    }
    // A mean is never above the largest value it averages (the cells tile the band without
    // overlap: this only removes the sum's rounding).
    best.min(cells.iter().map(|c| c[4]).fold(0.0, f64::max))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_edges_share_is_their_part_of_the_placed_area() {
        let places = FlankPlaces {
            tip_trace: 0.012,
            face_ends: 0.003,
            blank_top: 0.001,
            elsewhere: 0.004,
        };
        assert!((places.total() - 0.02).abs() < 1e-15);
        assert!((places.edge_share() - 0.8).abs() < 1e-12);
        assert_eq!(FlankPlaces::default().edge_share(), 0.0);
    }

    #[test]
    fn the_tip_edge_s_contact_width_is_hertz_s_for_a_cylinder_on_a_plane() {
        // Hertz (contact.rs): a = sqrt(4 w R / (pi E*)), p0 = 2 w / (pi a).
        let (radius, modulus) = (0.5e-3, 77.9e9);
        for line_load in [1e4, 1e5, 4e5] {
            let a = crate::contact::hertz_half_width(line_load, radius, modulus);
            let p0 = 2.0 * line_load / (PI * a);
            let width = tip_edge_contact_width(radius, p0, modulus);
            assert!(
                (width - 2.0 * a).abs() < 1e-12 * a,
                "{width} against {}",
                2.0 * a
            );
        }
    }

    #[test]
    fn a_round_narrower_than_three_cells_is_warned_and_a_sharp_edge_is_not() {
        let (radius, p, modulus) = (0.5e-3, 1e9, 77.9e9);
        // 2 a = 4 R p / E* = 25.7 um.
        let width = tip_edge_contact_width(radius, p, modulus);
        let warned =
            |cells: f64| TipEdgeResolution::of(radius, p, modulus, cells).map(|t| t.text());
        let text = warned(180e-6).expect("a 25.7 um contact in 180 um cells");
        assert!(text.contains("worm.tip_edge_radius_mm = 0.500"), "{text}");
        assert!(text.contains("25.7 um"), "{text}");
        assert!(text.contains("8.6 um wide"), "{text}");
        assert!(text.contains("22 times finer"), "{text}");
        assert!(warned(width / 3.0 * 1.01).is_some());
        assert!(warned(width / 3.0 * 0.99).is_none());
        assert!(TipEdgeResolution::of(0.0, p, modulus, 180e-6).is_none());
    }
}
