//! The local contact mesh of a position (MODEL §5.1, §5.3): the band around each engaged tooth's
//! contact line, its slices (node columns of the global flank grid) and their cells across the
//! line, on the worn flank when a life gives one.

use super::*;

/// Half-width of the local meshes' band across the line before any widening (MODEL §5.1), m:
/// `band_factor` Hertz half-widths at the mean line load (the wheel torque `wheel_torque` N m
/// over the normal's lever and the mean line length of the TCA's positions) and the lines'
/// mean curvature radius.
pub(super) fn initial_band(
    gear: &GearSet,
    tca: &Tca,
    wf: &WheelFlank,
    settings: &LtcaSettings,
    pair: &ElasticPair,
    wheel_torque_guess: f64,
) -> f64 {
    // Line-load estimate for the band width: wheel torque / lever / line length.
    let step = settings.slice_step.max(1);
    let slice_dz = wf.z[1] - wf.z[0];
    let mut lengths = Vec::new();
    for n in 0..tca.positions.len() {
        let count = tca
            .contact_lines
            .iter()
            .filter(|c| c.position == n && !c.at_end && c.slice % step == 0)
            .count();
        lengths.push(count as f64 * slice_dz * step as f64);
    }
    let mean_length = lengths.iter().sum::<f64>() / lengths.len() as f64;
    let radii: Vec<f64> = tca
        .contact_lines
        .iter()
        .filter(|c| !c.at_end && c.curvature_radius.is_finite())
        .map(|c| c.curvature_radius)
        .collect();
    let radius = if radii.is_empty() {
        0.03
    } else {
        radii.iter().sum::<f64>() / radii.len() as f64
    };
    // Lever of the normal about the wheel axis, |(P x n)_z| ~ r2 cos(alpha_n).
    let lever_est = gear.wheel_reference_radius() * gear.worm.normal_pressure_angle.cos();
    let w_mean = wheel_torque_guess / lever_est / mean_length.max(1e-6);
    settings.band_factor * hertz_half_width(w_mean, radius, pair.effective_modulus)
}

/// The changed flank on the global grid's nodes (MODEL §7.5, §5.7): the depth worn off and
/// the whole change (wear and plastic set) normal to the flank, m.
pub(super) struct FlankShape {
    pub(super) removal: FlankField,
    pub(super) node_angle: Vec<f64>,
    pub(super) deepest: f64,
}

impl FlankShape {
    /// None for an unchanged flank.
    pub(super) fn new(wf: &WheelFlank, change: FlankChange) -> Option<Self> {
        if change.removal.is_none() && change.plastic_set.is_none() {
            return None;
        }
        let removal = change
            .removal
            .cloned()
            .unwrap_or_else(|| FlankField::zeros(wf));
        let mut whole = removal.clone();
        if let Some(set) = change.plastic_set {
            for (h, s) in whole
                .values
                .iter_mut()
                .zip(&set.with_rows(wf.cells_height).values)
            {
                *h += s;
            }
        }
        Some(Self {
            node_angle: Worn::node_angles(wf, &whole),
            deepest: whole.max(),
            removal,
        })
    }

    pub(super) fn worn<'a>(&'a self, plastic_set: Option<&'a FlankField>) -> Worn<'a> {
        Worn {
            depth: &self.removal,
            plastic_set,
            node_angle: &self.node_angle,
            deepest: self.deepest,
        }
    }
}

/// A changed flank as the local meshes read it (MODEL §7.5, §5.7): the depth worn off normal
/// to the flank (m, above the worm-tip trace), the plastic set on its finer rows (m), at each
/// node of the global grid the whole change as an angle over the node's lever |(P x n)_z|
/// (rad), and the largest change, computed once per analysis.
#[derive(Clone, Copy)]
pub(super) struct Worn<'a> {
    pub(super) depth: &'a FlankField,
    pub(super) plastic_set: Option<&'a FlankField>,
    pub(super) node_angle: &'a [f64],
    pub(super) deepest: f64,
}

impl Worn<'_> {
    /// The depth at each node over the node's lever (the lever is rotation invariant about
    /// the wheel axis), rad.
    pub(super) fn node_angles(wf: &WheelFlank, depth: &FlankField) -> Vec<f64> {
        wf.nodes
            .iter()
            .zip(&depth.values)
            .map(|(p, h)| h / GapEvaluator::lever(&p.position(), &p.normal_vec()))
            .collect()
    }
}

/// One slice of a local mesh: a strip across the contact line of one tooth at face position
/// z, with the line crossing r_line.
#[derive(Debug, Clone, Copy)]
pub(super) struct Slice {
    pub(super) tooth: i32,
    pub(super) tooth_index: usize,
    /// Node column.
    pub(super) base: usize,
    pub(super) z: f64,
    /// Half extent along the face width, m.
    pub(super) half_dz: f64,
    pub(super) r_line: f64,
    /// The line's vector over the slice extent (worm frame), None at flank ends.
    pub(super) line_step: Option<Vector3<f64>>,
    /// Cells added below and above the base band (band growth by extension, MODEL §5.1).
    pub(super) extension: (usize, usize),
}

impl Slice {
    /// The first and last column of the slice's band: the base band's `columns` from
    /// [`LtcaSettings::column_offset`], and its extension's below and above.
    fn columns(&self, settings: &LtcaSettings) -> (usize, usize) {
        let (below, above) = self.extension;
        let offset = settings.column_offset();
        (offset - below, offset + settings.columns.max(1) - 1 + above)
    }

    /// Where a column's cell centre lies across the line from the line crossing, in cell
    /// widths (the base band's cells centred on the crossing).
    fn across(column: usize, settings: &LtcaSettings) -> f64 {
        let nc = settings.columns.max(1) as f64;
        column as f64 - settings.column_offset() as f64 - 0.5 * (nc - 1.0)
    }
}

/// The contact lines of one position (MODEL §5.1), to follow a tooth's line from one node
/// column to the next.
struct PositionLines<'a> {
    /// Line crossings of every node column, by (tooth, column).
    crossings: std::collections::HashMap<(i32, usize), &'a crate::kinematics::SliceContact>,
    ev: &'a GapEvaluator<'a>,
    /// Wheel angle of the position, rad.
    theta2: f64,
    /// The wheel's sense of rotation (+1 or -1, as the TCA's) and the angular pitch 2 pi / z2,
    /// rad: tooth k sits at sigma k tau.
    sigma: f64,
    tau: f64,
}

impl<'a> PositionLines<'a> {
    fn new(tca: &'a Tca, ev: &'a GapEvaluator<'a>, n: usize, tau: f64) -> Self {
        let crossings = tca
            .contact_lines
            .iter()
            .filter(|c| c.position == n && !c.at_end && c.separation.is_finite())
            .map(|c| ((c.tooth, c.slice), c))
            .collect();
        Self {
            crossings,
            ev,
            theta2: tca.positions[n].theta2,
            sigma: tca.sigma,
            tau,
        }
    }

    /// The angular offset of a tooth, rad.
    fn offset_of(&self, tooth: i32) -> f64 {
        self.sigma * tooth as f64 * self.tau
    }

    fn line_point(&self, c: &crate::kinematics::SliceContact) -> Vector3<f64> {
        wheel_point(c.r, c.theta + self.offset_of(c.tooth), c.z, self.theta2)
    }

    /// Line direction at node column j of a tooth, scaled to a face-width advance of 1 m
    /// (worm frame); None where the column has no crossing or no neighbour has one.
    fn direction(&self, tooth: i32, j: usize) -> Option<Vector3<f64>> {
        let here = self.crossings.get(&(tooth, j))?;
        let before = j
            .checked_sub(1)
            .and_then(|i| self.crossings.get(&(tooth, i)));
        let after = self.crossings.get(&(tooth, j + 1));
        let (a, b) = match (before, after) {
            (Some(a), Some(b)) => (self.line_point(a), self.line_point(b)),
            (Some(a), None) => (self.line_point(a), self.line_point(here)),
            (None, Some(b)) => (self.line_point(here), self.line_point(b)),
            (None, None) => return None,
        };
        let dz = b.z - a.z;
        (dz.abs() > 0.0).then(|| self.ev.placement.vector_wheel_to_worm(&((b - a) / dz)))
    }
}

/// The cells each slice's band has grown by below and above its base band, by (tooth, node
/// column) (band growth by extension, MODEL §5.1; empty: none).
pub(super) type Extensions = std::collections::HashMap<(i32, usize), (usize, usize)>;

/// Builds the local mesh of one position with band half-width `band` (m) (MODEL §5.1):
/// every `slice_step`-th node column crossed by a tooth's contact line is a slice, grown by
/// `extensions`.
#[allow(clippy::too_many_arguments)]
pub(super) fn local_mesh(
    tca: &Tca,
    ev: &GapEvaluator,
    wf: &WheelFlank,
    settings: &LtcaSettings,
    teeth: u32,
    n: usize,
    band: f64,
    worn: Option<Worn>,
    extensions: &Extensions,
) -> Vec<LocalCell> {
    let tau = 2.0 * PI / teeth as f64;
    let step = settings.slice_step.max(1);
    let base_dz = (wf.z[1] - wf.z[0]) * step as f64;
    // Separation threshold for slices whose minimum is not a crossing (flank edges); on a worn
    // flank the edges left standing can be the first to touch: raised by the deepest wear.
    let edge_threshold = 50e-6 + worn.map_or(0.0, |w| w.deepest);
    let lines = PositionLines::new(tca, ev, n, tau);
    // Worn material exists only where the worm flank reaches (above the worm-tip trace).
    let tip_floor: Vec<f64> = if worn.is_some() {
        tca.tip_trace.iter().map(|t| t.1).collect()
    } else {
        Vec::new()
    };
    let mut base = Vec::new();
    for line in tca
        .contact_lines
        .iter()
        .filter(|c| c.position == n && c.slice % step == 0)
    {
        if !line.separation.is_finite() || (line.at_end && line.separation > edge_threshold) {
            continue;
        }
        let tooth_index = tca.teeth.iter().position(|&k| k == line.tooth).unwrap_or(0);
        // On a worn flank the band goes where the worn gap is smallest on the column (the TCA
        // node gaps plus the removal over each node's lever), which need not be the unworn line.
        let (r_line, at_end) = match worn {
            Some(w) => worn_minimum(tca, wf, w.node_angle, n, tooth_index, line),
            None => (line.r, line.at_end),
        };
        base.push(Slice {
            tooth: line.tooth,
            tooth_index,
            base: line.slice,
            z: wf.z[line.slice],
            half_dz: 0.5 * base_dz,
            r_line,
            line_step: if at_end {
                None
            } else {
                lines.direction(line.tooth, line.slice).map(|d| d * base_dz)
            },
            extension: extensions
                .get(&(line.tooth, line.slice))
                .copied()
                .unwrap_or((0, 0)),
        });
    }
    // Slices in parallel, in their order (on many cores idle threads help the positions
    // that take longest, issue 55).
    use rayon::prelude::*;
    base.par_iter()
        .flat_map_iter(|s| {
            slice_cells(
                s,
                tca,
                ev,
                wf,
                settings,
                n,
                band,
                lines.offset_of(s.tooth),
                worn,
                &tip_floor,
            )
        })
        .collect()
}

/// Radius of the smallest worn angular gap on the node column of `line` (tooth index t,
/// position n), and whether it is at a column end: the parabola through the best node and its
/// neighbours, less the same fit's bias on the unworn gaps (their minimum is the TCA's exact
/// line crossing), so that a flank worn by the same angle everywhere keeps the unworn line.
pub(super) fn worn_minimum(
    tca: &Tca,
    wf: &WheelFlank,
    node_angle: &[f64],
    n: usize,
    t: usize,
    line: &crate::kinematics::SliceContact,
) -> (f64, bool) {
    let (ni, j) = (wf.cells_height, line.slice);
    let nodes = wf.nodes.len();
    let base = (n * tca.teeth.len() + t) * nodes;
    let gaps = |worn: bool| -> Vec<f64> {
        (0..=ni)
            .map(|i| {
                let k = j * (ni + 1) + i;
                tca.node_gaps[base + k] + if worn { node_angle[k] } else { 0.0 }
            })
            .collect()
    };
    let r = |i: usize| wf.node(i, j).r;
    // Parabola vertex through the smallest node and its neighbours (None at a column end).
    let vertex = |values: &[f64]| -> Option<(usize, Option<f64>)> {
        let (best, _) = values
            .iter()
            .enumerate()
            .filter(|(_, v)| v.is_finite())
            .min_by(|a, b| a.1.total_cmp(b.1))?;
        if best == 0 || best == ni || !values[best - 1].is_finite() || !values[best + 1].is_finite()
        {
            return Some((best, None));
        }
        let (a, b, c) = (values[best - 1], values[best], values[best + 1]);
        let den = a - 2.0 * b + c;
        let shift = if den > 0.0 { 0.5 * (a - c) / den } else { 0.0 };
        let h = r(best + 1) - r(best);
        Some((best, Some(r(best) + shift.clamp(-0.5, 0.5) * h)))
    };
    let Some((best, worn)) = vertex(&gaps(true)) else {
        return (line.r, line.at_end);
    };
    let unworn = vertex(&gaps(false));
    match (worn, unworn) {
        // Where the wear leaves the smallest node where it was, the nodes' fit is only a
        // correction to the TCA's exact line: its bias on the unworn gaps is taken off, and a
        // fit cut by the column's end (the worm-tip trace, the blank top) keeps the TCA line.
        (None, Some((b0, None))) if b0 == best => (line.r, line.at_end),
        (None, _) => (r(best), true),
        (Some(worn), Some((_, Some(unworn)))) if !line.at_end => {
            let h = r(best + 1) - r(best);
            (worn - (unworn - line.r).clamp(-h, h), false)
        }
        (Some(worn), _) => (worn, false),
    }
}

/// The cells of one slice: `columns` cells of width 2 band / columns along the flank's
/// radial direction, centred on the line crossing, and the slice's extension's cells of the
/// same width beyond them.
#[allow(clippy::too_many_arguments)]
pub(super) fn slice_cells(
    slice: &Slice,
    tca: &Tca,
    ev: &GapEvaluator,
    wf: &WheelFlank,
    settings: &LtcaSettings,
    n: usize,
    band: f64,
    offset: f64,
    worn: Option<Worn>,
    tip_floor: &[f64],
) -> Vec<LocalCell> {
    let (pos, z) = (tca.positions[n], slice.z);
    let ds = 2.0 * band / settings.columns.max(1) as f64;
    let (lo, hi) = wf.radial_range_at(z);
    let (_, slope) = wf.theta_at(slice.r_line, z);
    let drds = 1.0 / (1.0 + (slice.r_line * slope).powi(2)).sqrt();
    let (first, last) = slice.columns(settings);
    let mut cells = Vec::with_capacity(last + 1 - first);
    for column in first..=last {
        let r = slice.r_line + Slice::across(column, settings) * ds * drds;
        if r < lo || r > hi {
            continue;
        }
        let (theta, slope) = wf.theta_at(r, z);
        let (e, worm_gradient) =
            ev.angular_with_gradient(r, theta + offset, z, pos.theta2, pos.theta1);
        if !e.is_finite() {
            continue;
        }
        let nb = wf.normal_at(r, z);
        let stat = wheel_point(r, theta + offset, z, pos.theta2);
        let mut n_stat = from_wheel_body(&nb, offset + pos.theta2);
        let centre = ev.placement.wheel_to_worm(&stat);
        let relief = ev
            .relief(r, z, (centre.y * centre.y + centre.z * centre.z).sqrt())
            .0;
        let mut normal = ev.placement.vector_wheel_to_worm(&n_stat);
        // A depth worn off the wheel flank is normal to it: its angle is over the wheel's lever.
        let wheel_lever = GapEvaluator::lever(&stat, &n_stat);
        if settings.pressure_direction == crate::input::PressureDirection::WormFlank {
            (normal, n_stat) = worm_flank_direction(ev, worm_gradient, &normal);
        }
        let lever = GapEvaluator::lever(&stat, &n_stat);
        let dpdr = ev.placement.vector_wheel_to_worm(&from_wheel_body(
            &radial_tangent(r, theta + offset, slope),
            pos.theta2,
        ));
        let (axis_nu, axis_zeta, half_nu, half_zeta) = cell_axes(slice, &normal, &dpdr, ds);
        cells.push(LocalCell {
            cell: ContactCell {
                centre,
                normal,
                axis_nu,
                axis_zeta,
                half_nu,
                half_zeta,
            },
            tooth: slice.tooth,
            tooth_index: slice.tooth_index,
            slice: slice.base,
            column,
            band_first: first,
            band_last: last,
            r,
            z,
            line_r: slice.r_line,
            half_dz: slice.half_dz,
            lever,
            wheel_centre: stat,
            wheel_normal: n_stat,
            worm_lever: centre.cross(&normal).x,
            separation: e
                + pos.kinematic_error
                + worn_separation(worn, wf, (r, z), tip_floor, wheel_lever),
            relief,
        });
    }
    cells
}

/// The angle (rad) a worn flank adds to a cell's separation at (r, z) (m): the wear depth
/// above the worm-tip trace `tip_floor` plus the plastic set (also below the trace: the tip's
/// edge indents the cells it crosses), over the wheel's lever (m); 0 on the unworn flank.
fn worn_separation(
    worn: Option<Worn>,
    wf: &WheelFlank,
    (r, z): (f64, f64),
    tip_floor: &[f64],
    wheel_lever: f64,
) -> f64 {
    worn.map_or(0.0, |w| {
        let set = w.plastic_set.map_or(0.0, |s| s.at(wf, r, z));
        (w.depth.at_above(wf, r, z, Some(tip_floor)) + set) / wheel_lever
    })
}

/// d P / d r of the wheel flank point at radius r and body angle theta with d theta / d r =
/// `slope` (body frame, m/m).
pub(super) fn radial_tangent(r: f64, theta: f64, slope: f64) -> Vector3<f64> {
    let (st, ct) = theta.sin_cos();
    Vector3::new(ct - r * st * slope, -st - r * ct * slope, 0.0)
}

/// In-plane axes (across, along the contact line) and half sides (m) of a local cell with unit
/// normal `normal` and the flank's radial tangent `dpdr` (worm frame), `ds` wide across: the
/// parallelogram of sides `ds` along the radial direction and the line's step along the line,
/// taken as the rectangle of the same area aligned with the line (exact tiling of a band of
/// straight lines); at a flank end (no line step) the radial rectangle of the slice.
pub(super) fn cell_axes(
    slice: &Slice,
    normal: &Vector3<f64>,
    dpdr: &Vector3<f64>,
    ds: f64,
) -> (Vector3<f64>, Vector3<f64>, f64, f64) {
    let radial = (dpdr - normal * dpdr.dot(normal)).normalize();
    match slice.line_step {
        Some(a) => {
            let a = a - normal * a.dot(normal);
            let along = a.norm();
            let zeta = a / along;
            (
                zeta.cross(normal),
                zeta,
                0.5 * ds * radial.cross(&zeta).norm(),
                0.5 * along,
            )
        }
        None => (radial, normal.cross(&radial), 0.5 * ds, slice.half_dz),
    }
}

/// The pressure direction along the worm flank's normal where the gap of a wheel point is
/// measured to (see `PressureDirection`), from the worm flank's axial-gap gradient there
/// ([`GapEvaluator::angular_with_gradient`]): worm-frame and stationary wheel-frame components,
/// oriented like the wheel normal `wheel_normal` (worm frame).
pub(super) fn worm_flank_direction(
    ev: &GapEvaluator,
    gradient: [f64; 2],
    wheel_normal: &Vector3<f64>,
) -> (Vector3<f64>, Vector3<f64>) {
    let n = GapEvaluator::worm_normal_from(gradient, wheel_normal);
    (n, ev.placement.vector_worm_to_wheel(&n))
}
