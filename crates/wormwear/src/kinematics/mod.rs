//! Stage 2 — unloaded meshing analysis, TCA (MODEL §4, §12a, §12b). Rooms: `gap` the gap
//! evaluator, `node` the contact kinematics of a flank node; here the study over the positions.
//!
//! For N_p positions over one wheel tooth pitch and teeth k = -K..K, the gaps between the
//! loaded wheel flank and the worm, through the operating placement (misalignments included):
//!
//! - linear gap e along the worm axis and the exact angular gap e_ang (the wheel rotation,
//!   against its driven sense, that closes e at the point; Newton on e), at every node and cell
//!   centre of every tooth at every position;
//! - on every face slice (node column) the contact point: the minimum of e_ang along r,
//!   refined on the column's Hermite interpolant of theta_w (exact to ~1e-11 m);
//! - the unloaded kinematic error Delta_theta2 = -min e_ang (lag, driven sense) and the initial
//!   separations e_ang - min e_ang >= 0 for the loaded problem (MODEL §4.3);
//! - the no-load pattern for a marking thickness j (MODEL §4.4);
//! - the contact map: for each flank node, the moment it meets the worm flank (from the worm's
//!   own envelope on the wheel, the machinery of hobbing with the worm as cutter), the worm
//!   radius there, the worm-tip trace, and the sliding velocities with material velocities
//!   (MODEL §4.5): magnitude, along/across the contact line, rolling velocities u1, u2 across the
//!   line, speed of the line over the wheel; and on the contact lines the relative curvature
//!   radius across the line (MODEL §4.6).
//!
//! Positions: theta2_n = sigma (phase + n / N_p) tau (tau = 2 pi / z2, sigma = +1 when the worm
//! turns in the positive sense; the phase centres the studied range on the contact zone of the
//! flank's central node); tooth k sits at body angle theta_w + sigma k tau, so tooth k at position
//! n is the reference tooth at extended position n + k N_p (MODEL §4.1).

use crate::geometry::hobbing::{Hobbing, PointKind};
use crate::geometry::placement::wheel_point;
use crate::geometry::roots::brent_max;
use crate::geometry::{Flank, Geometry, ThreadSurface, WheelFlank};
use crate::input::{GearSet, Placement, Rotation};
use nalgebra::Vector3;
use rayon::prelude::*;
use std::f64::consts::PI;

mod gap;
mod node;
pub mod pattern_shape;

pub use gap::*;
use node::*;

/// Why the TCA failed.
#[derive(Debug, Clone, thiserror::Error)]
pub enum KinematicsError {
    #[error("no contact: the worm flank never reaches the wheel flank at position {0}")]
    NoContact(usize),
}

/// The worm flank loaded by the operating rotation.
pub fn loaded_flank(gear: &GearSet) -> Flank {
    match gear.rotation {
        Rotation::Positive => Flank::Left,
        Rotation::Negative => Flank::Right,
    }
}

/// Material velocities at a point (MODEL §4.5), worm frame, m/s.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Velocities {
    /// Worm material velocity V1.
    pub worm: [f64; 3],
    /// Wheel material velocity V2.
    pub wheel: [f64; 3],
    /// Sliding velocity Vg = V2 - V1.
    pub sliding: [f64; 3],
}

/// Material velocities of worm and wheel at the point `q` (worm frame, m) for the worm turning
/// at theta1_dot (rad/s, the thread-advance angle of MODEL §2.1; physical spin = hand x
/// theta1_dot about +x1) and the wheel at theta2_dot = theta1_dot z1/z2.
pub fn material_velocities(
    q: &Vector3<f64>,
    worm: &ThreadSurface,
    placement: &Placement,
    theta1_dot: f64,
    ratio: f64,
) -> Velocities {
    let spin = worm.hand_sign() * theta1_dot;
    let v1 = Vector3::new(0.0, -q.z, q.y) * spin;
    let p = placement.worm_to_wheel(q);
    let theta2_dot = theta1_dot / ratio;
    let v2 = placement.vector_wheel_to_worm(&Vector3::new(p.y, -p.x, 0.0)) * theta2_dot;
    let vg = v2 - v1;
    Velocities {
        worm: v1.into(),
        wheel: v2.into(),
        sliding: vg.into(),
    }
}

/// Contact kinematics of one flank node at the moment the worm flank meets it.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct NodeContact {
    /// The worm flank (not its tip edge) reaches the node.
    pub reachable: bool,
    /// Wheel rotation theta2 at the contact moment (reference tooth), rad.
    pub theta2: f64,
    /// Radius of the contact point on the worm, m.
    pub worm_radius: f64,
    /// Ease-off: theta_w of the actual wheel minus that of the wheel the worm itself would
    /// generate, times r (positive = material removed beyond conjugate), m.
    pub ease_off: f64,
    /// Sliding speed |Vg|, m/s.
    pub sliding_speed: f64,
    /// Sliding component along the contact line, m/s.
    pub sliding_along: f64,
    /// Sliding component across the contact line (in the tangent plane), m/s.
    pub sliding_across: f64,
    /// Rolling velocities across the line: of the contact relative to the worm (u1) and to the
    /// wheel (u2), m/s (u2 = speed of the contact line over the wheel flank).
    pub u1: f64,
    pub u2: f64,
    /// Sliding velocity vector and unit normal (worm frame) at the contact.
    pub sliding: [f64; 3],
    pub normal: [f64; 3],
    /// Unit direction of the contact line (worm frame, at the contact moment).
    pub line_direction: [f64; 3],
    /// Unit direction of the contact line on the wheel flank (wheel body frame).
    pub line_direction_body: [f64; 3],
}

/// Contact point of one face slice at one position and tooth.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SliceContact {
    pub position: usize,
    /// Tooth index k.
    pub tooth: i32,
    /// Node column j.
    pub slice: usize,
    /// Radius and face position of the point of minimum gap, m.
    pub r: f64,
    pub z: f64,
    /// theta_w there (body frame, reference tooth), rad.
    pub theta: f64,
    /// Angular gap before the kinematic-error shift, rad.
    pub angular_gap: f64,
    /// Normal separation after the kinematic-error shift, m.
    pub separation: f64,
    /// Radius from the worm axis, m.
    pub worm_radius: f64,
    /// Minimum on the slice's end (the contact line does not cross this slice).
    pub at_end: bool,
    /// Relative radius of curvature across the contact line from the gap curvature, m
    /// (NaN at slice ends).
    pub curvature_radius: f64,
}

/// One kinematic position.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Position {
    /// Nominal wheel rotation, rad.
    pub theta2: f64,
    /// Worm rotation (thread-advance angle), rad.
    pub theta1: f64,
    /// Unloaded kinematic error Delta_theta2 (driven sense; negative = lag), rad.
    pub kinematic_error: f64,
    /// Teeth within the marking thickness of contact.
    pub teeth_in_contact: usize,
}

/// Result of the unloaded analysis.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Tca {
    pub loaded_flank: Flank,
    /// +1 or -1 (driven sense of the wheel).
    pub sigma: f64,
    /// Phase of position 0, in tooth pitches (driven sense).
    pub phase: f64,
    pub teeth: Vec<i32>,
    pub positions: Vec<Position>,
    /// Angular gaps at the loaded flank's nodes before the kinematic-error shift, index
    /// `(n * teeth + t) * nodes + node`, rad (infinite where the worm cannot reach).
    pub node_gaps: Vec<f64>,
    /// Same at the cell centres, index `(n * teeth + t) * cells + cell`.
    pub cell_gaps: Vec<f64>,
    /// Contact points of every slice, tooth and position.
    pub contact_lines: Vec<SliceContact>,
    /// Per cell: minimum normal separation over all positions and teeth (mapped to the
    /// reference tooth), m.
    pub min_separation: Vec<f64>,
    /// Per cell: marked by the no-load pattern (min separation <= j).
    pub marked: Vec<bool>,
    pub marking_thickness: f64,
    pub pattern_area: f64,
    pub active_area: f64,
    /// Whether the worm's thread enters the mesh at the flank's low-z face end (the entering
    /// side, MODEL §17; [`pattern_shape::entry_at_low_z`]).
    pub entry_at_low_z: bool,
    /// The no-load pattern's centre and extent (None: no cell marked).
    pub pattern_shape: Option<pattern_shape::PatternShape>,
    /// Per node column: lowest radius the worm flank reaches (trace of the worm tip), m.
    pub tip_trace: Vec<(f64, f64)>,
    /// Per node of the loaded flank.
    pub node_contact: Vec<NodeContact>,
    /// Sliding speed at the pitch point, r1 omega1 / cos(gamma) by material velocities, m/s.
    pub pitch_sliding_speed: f64,
    pub warnings: Vec<String>,
}

impl Tca {
    /// Rolling velocities of every node of the loaded flank (u1, u2; m/s); where the TCA has
    /// none (nodes at the border of the region the worm flank reaches, whose surface gradient is
    /// undefined), the nearest node of the same column that has them.
    pub fn rolling_velocities(&self, wf: &WheelFlank) -> Vec<(f64, f64)> {
        let (ni, nj) = (wf.cells_height, wf.cells_face);
        (0..=nj)
            .flat_map(|j| {
                let column: Vec<usize> = (0..=ni).map(|i| j * (ni + 1) + i).collect();
                let valid: Vec<usize> = column
                    .iter()
                    .copied()
                    .filter(|&k| self.node_contact[k].u2.is_finite())
                    .collect();
                column
                    .iter()
                    .map(|&k| {
                        let src = valid
                            .iter()
                            .copied()
                            .min_by_key(|&v| (v as isize - k as isize).unsigned_abs())
                            .unwrap_or(k);
                        let c = &self.node_contact[src];
                        (c.u1, c.u2)
                    })
                    .collect::<Vec<_>>()
            })
            .collect()
    }

    /// Number of teeth studied.
    pub fn tooth_count(&self) -> usize {
        self.teeth.len()
    }

    /// Initial angular separation (MODEL §4.3) of node `node` of tooth index `t` at position n:
    /// e_ang - min e_ang >= 0, rad (infinite where unreachable).
    pub fn initial_separation(&self, n: usize, t: usize, node: usize, nodes: usize) -> f64 {
        let g = self.node_gaps[(n * self.teeth.len() + t) * nodes + node];
        g + self.positions[n].kinematic_error
    }

    /// Mean and peak-to-peak of the unloaded kinematic error, rad.
    pub fn kinematic_error_stats(&self) -> (f64, f64) {
        let ke: Vec<f64> = self.positions.iter().map(|p| p.kinematic_error).collect();
        let mean = ke.iter().sum::<f64>() / ke.len() as f64;
        let (lo, hi) = ke
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        (mean, hi - lo)
    }

    /// Largest sliding speed over the reachable flank, m/s.
    pub fn max_sliding_speed(&self) -> f64 {
        self.node_contact
            .iter()
            .filter(|c| c.reachable)
            .map(|c| c.sliding_speed)
            .fold(0.0, f64::max)
    }
}

/// Settings of the analysis (from `[analysis]`).
#[derive(Debug, Clone, Copy)]
pub struct TcaSettings {
    pub positions: usize,
    pub teeth_each_side: usize,
    pub marking_thickness: f64,
}

impl TcaSettings {
    pub fn from_gear(gear: &GearSet) -> Self {
        Self {
            positions: gear.analysis.positions,
            teeth_each_side: gear.analysis.teeth_each_side,
            marking_thickness: gear.analysis.marking_thickness,
        }
    }
}

/// Runs the unloaded analysis with the gear's settings.
pub fn analyse(gear: &GearSet, geo: &Geometry) -> Result<Tca, KinematicsError> {
    analyse_with(gear, geo, TcaSettings::from_gear(gear))
}

/// Minimum of the angular gap along node column j, refined between the neighbours of the best
/// node on the column's Hermite interpolant. Returns (r, gap, at_end).
fn slice_minimum(
    ev: &GapEvaluator,
    wf: &WheelFlank,
    j: usize,
    gaps: &[f64],
    body_offset: f64,
    theta2: f64,
    theta1: f64,
) -> (f64, f64, bool) {
    let ni = wf.cells_height;
    let col = |i: usize| gaps[j * (ni + 1) + i];
    let (mut best, mut best_gap) = (0, f64::INFINITY);
    for i in 0..=ni {
        if col(i) < best_gap {
            best = i;
            best_gap = col(i);
        }
    }
    if !best_gap.is_finite() {
        return (wf.node(0, j).r, f64::INFINITY, true);
    }
    let z = wf.z[j];
    let f = |r: f64| {
        let (theta, _) = wf.column_theta(j, r);
        let g = ev.angular(r, theta + body_offset, z, theta2, theta1);
        if g.is_finite() {
            -g
        } else {
            -1.0
        }
    };
    let lo = wf.node(best.saturating_sub(1), j).r;
    let hi = wf.node((best + 1).min(ni), j).r;
    let (r, neg) = brent_max(f, lo, hi, 1e-12);
    let (r, gap) = if -neg <= best_gap {
        (r, -neg)
    } else {
        (wf.node(best, j).r, best_gap)
    };
    // A contact-line crossing is a proper interior minimum: finite, larger gaps on both sides.
    // (a minimum on the column's end node is its end, whatever the extension beyond it says)
    let h = 0.25 * wf.largest_row_of(j);
    let on_end = r <= wf.node(0, j).r || r >= wf.node(ni, j).r;
    let at_end =
        on_end || !(f(r - h) < -gap && f(r + h) < -gap) || -f(r - h) >= 1.0 || -f(r + h) >= 1.0;
    (r, gap, at_end)
}

/// Runs the unloaded analysis (MODEL §4): the contact map (the worm's own envelope on the wheel
/// flank), the gaps of every studied tooth at every position, the kinematic error, the no-load
/// pattern and the contact lines.
pub fn analyse_with(
    gear: &GearSet,
    geo: &Geometry,
    settings: TcaSettings,
) -> Result<Tca, KinematicsError> {
    let ev = GapEvaluator::new(gear, geo);
    let flank = ev.flank;
    let sigma = ev.sigma;
    let wf = geo.wheel_flank(flank);
    let kk = settings.teeth_each_side as i32;
    let worm_cut = Hobbing::new(&geo.worm, gear.operating, geo.teeth);
    let theta1_dot = sigma * gear.conditions.worm_speed;
    let map = ContactMap::new(&worm_cut, flank, wf);
    let (ni, nj) = (wf.cells_height, wf.cells_face);
    // Centre the studied extended positions [phase - K, phase + K + 1) (in pitches) on the
    // contact moment of the flank's central node.
    let centre = map.contact_theta2[(nj / 2) * (ni + 1) + ni / 2];
    let tau = 2.0 * PI / geo.teeth as f64;
    let phase = if centre.is_finite() {
        sigma * centre / tau - 0.5
    } else {
        0.0
    };
    let study = Study {
        ev: &ev,
        wf,
        sigma,
        tau,
        phase,
        positions: settings.positions,
        teeth: (-kk..=kk).collect(),
    };
    let node_contact = map.node_contacts(geo, &ev, wf, theta1_dot);
    let blocks = study.gap_blocks();
    let mut positions = study.kinematic_errors(&blocks)?;
    let j_mark = settings.marking_thickness;
    let (min_separation, warnings) = study.no_load_pattern(&blocks, &mut positions, j_mark);
    let marked: Vec<bool> = min_separation.iter().map(|&s| s <= j_mark).collect();
    let pattern_area: f64 = wf
        .cell_area
        .iter()
        .zip(&marked)
        .filter(|(_, &m)| m)
        .map(|(a, _)| a)
        .sum();
    let entry_at_low_z = pattern_shape::entry_at_low_z(
        &geo.worm,
        &gear.operating,
        gear.worm.reference_radius,
        theta1_dot,
    );
    let shape = pattern_shape::PatternShape::of(wf, &marked, entry_at_low_z);
    let contact_lines = study.contact_lines(&blocks, &positions, &node_contact);
    let (node_gaps, cell_gaps) = GapBlock::joined(&blocks);
    Ok(Tca {
        loaded_flank: flank,
        sigma,
        phase,
        teeth: study.teeth,
        positions,
        node_gaps,
        cell_gaps,
        contact_lines,
        min_separation,
        marked,
        marking_thickness: j_mark,
        pattern_area,
        active_area: wf.active_area(),
        entry_at_low_z,
        pattern_shape: shape,
        tip_trace: tip_trace(&worm_cut, flank, wf),
        node_contact,
        pitch_sliding_speed: pitch_sliding_speed(gear, geo, theta1_dot, ev.ratio),
        warnings,
    })
}

/// The sliding speed at the worm's reference radius on the line of centres, m/s.
fn pitch_sliding_speed(gear: &GearSet, geo: &Geometry, theta1_dot: f64, ratio: f64) -> f64 {
    let r1 = gear.worm.reference_radius;
    let pitch = material_velocities(
        &Vector3::new(0.0, r1, 0.0),
        &geo.worm,
        &Placement::aligned(gear.nominal_centre_distance),
        theta1_dot,
        ratio,
    );
    Vector3::from(pitch.sliding).norm()
}

/// The contact map: the worm's own envelope on the wheel flank (MODEL §4.5), per node: the
/// envelope point, the wheel angle of its contact moment, and whether the worm's flank (not
/// its tip or an edge) reaches it.
struct ContactMap {
    envelopes: Vec<crate::geometry::EnvelopePoint>,
    contact_theta2: Vec<f64>,
    reachable_mask: Vec<bool>,
}

impl ContactMap {
    /// The contact of every flank node (MODEL §4.5-4.6), node-major as the flank.
    fn node_contacts(
        &self,
        geo: &Geometry,
        ev: &GapEvaluator,
        wf: &WheelFlank,
        theta1_dot: f64,
    ) -> Vec<NodeContact> {
        let ni = wf.cells_height;
        (0..wf.nodes.len())
            .map(|k| {
                let (i, j) = (k % (ni + 1), k / (ni + 1));
                node_contact(
                    geo,
                    ev,
                    wf,
                    &self.envelopes[k],
                    &self.contact_theta2,
                    &self.reachable_mask,
                    i,
                    j,
                    theta1_dot,
                )
            })
            .collect()
    }

    fn new(worm_cut: &Hobbing, flank: Flank, wf: &WheelFlank) -> Self {
        let envelopes: Vec<_> = wf
            .nodes
            .par_iter()
            .map(|p| worm_cut.envelope(flank, p.r, p.z))
            .collect();
        let contact_theta2: Vec<f64> = envelopes
            .iter()
            .zip(&wf.nodes)
            .map(|(e, p)| e.psi - p.theta)
            .collect();
        let reachable_mask: Vec<bool> = envelopes
            .iter()
            .map(|e| e.kind == PointKind::Flank)
            .collect();
        Self {
            envelopes,
            contact_theta2,
            reachable_mask,
        }
    }
}

/// The studied positions and teeth of an unloaded analysis, and what its steps share.
struct Study<'a> {
    ev: &'a GapEvaluator<'a>,
    wf: &'a WheelFlank,
    /// +1 or -1: the wheel's sense of rotation.
    sigma: f64,
    /// Angular pitch of the wheel, rad.
    tau: f64,
    /// Phase of the first position, in pitches.
    phase: f64,
    positions: usize,
    /// Tooth indices studied, -K..=K.
    teeth: Vec<i32>,
}

/// Gaps of one studied tooth at one position: at the nodes and cells (angular, rad) and each
/// slice's minimum (r, gap, at the end of the flank).
struct GapBlock {
    node_gaps: Vec<f64>,
    cell_gaps: Vec<f64>,
    slices: Vec<(f64, f64, bool)>,
}

impl GapBlock {
    /// The node and cell gaps of all blocks, in block order (position-major).
    fn joined(blocks: &[GapBlock]) -> (Vec<f64>, Vec<f64>) {
        let n_nodes = blocks.first().map_or(0, |b| b.node_gaps.len());
        let n_cells = blocks.first().map_or(0, |b| b.cell_gaps.len());
        let mut node_gaps = Vec::with_capacity(blocks.len() * n_nodes);
        let mut cell_gaps = Vec::with_capacity(blocks.len() * n_cells);
        for b in blocks {
            node_gaps.extend_from_slice(&b.node_gaps);
            cell_gaps.extend_from_slice(&b.cell_gaps);
        }
        (node_gaps, cell_gaps)
    }
}

impl Study<'_> {
    /// Wheel angle of position n, rad.
    fn theta2(&self, n: usize) -> f64 {
        self.sigma * (self.phase + n as f64 / self.positions as f64) * self.tau
    }

    /// Gaps at nodes and cells, slice minima: one task per (position, tooth), position-major.
    fn gap_blocks(&self) -> Vec<GapBlock> {
        let (ev, wf) = (self.ev, self.wf);
        let nt = self.teeth.len();
        let nj = wf.cells_face;
        (0..self.positions * nt)
            .into_par_iter()
            .map(|b| {
                let (n, t) = (b / nt, b % nt);
                let theta2 = self.theta2(n);
                let theta1 = theta2 * ev.ratio;
                let offset = self.sigma * self.teeth[t] as f64 * self.tau;
                let node_gaps: Vec<f64> = wf
                    .nodes
                    .iter()
                    .map(|p| ev.angular(p.r, p.theta + offset, p.z, theta2, theta1))
                    .collect();
                let cell_gaps: Vec<f64> = wf
                    .cells
                    .iter()
                    .map(|p| ev.angular(p.r, p.theta + offset, p.z, theta2, theta1))
                    .collect();
                let slices = (0..=nj)
                    .map(|j| slice_minimum(ev, wf, j, &node_gaps, offset, theta2, theta1))
                    .collect();
                GapBlock {
                    node_gaps,
                    cell_gaps,
                    slices,
                }
            })
            .collect()
    }

    /// Kinematic error per position: minus the smallest gap over the studied teeth (MODEL §4.3).
    fn kinematic_errors(&self, blocks: &[GapBlock]) -> Result<Vec<Position>, KinematicsError> {
        let nt = self.teeth.len();
        let mut positions = Vec::with_capacity(self.positions);
        for n in 0..self.positions {
            let theta2 = self.theta2(n);
            let min = (0..nt)
                .flat_map(|t| blocks[n * nt + t].slices.iter().map(|s| s.1))
                .chain((0..nt).flat_map(|t| blocks[n * nt + t].cell_gaps.iter().copied()))
                .fold(f64::INFINITY, f64::min);
            if !min.is_finite() {
                return Err(KinematicsError::NoContact(n));
            }
            positions.push(Position {
                theta2,
                theta1: theta2 * self.ev.ratio,
                kinematic_error: -min,
                teeth_in_contact: 0,
            });
        }
        Ok(positions)
    }

    /// The no-load pattern (MODEL §4.4): the smallest normal separation of every cell over the
    /// cycle, m, and the teeth within the marking thickness `j_mark` at each position (set on
    /// `positions`); a warning when the outermost studied tooth is near contact.
    fn no_load_pattern(
        &self,
        blocks: &[GapBlock],
        positions: &mut [Position],
        j_mark: f64,
    ) -> (Vec<f64>, Vec<String>) {
        let wf = self.wf;
        let (np, nt) = (self.positions, self.teeth.len());
        let n_cells = wf.cells.len();
        // Levers (angular -> normal distance) per cell.
        let cell_lever: Vec<f64> = wf
            .cells
            .iter()
            .map(|c| GapEvaluator::lever(&c.position(), &c.normal_vec()))
            .collect();
        let mut min_separation = vec![f64::INFINITY; n_cells];
        let mut warnings = Vec::new();
        // Extended positions n + k N_p cover [-K N_p, (K + 1) N_p); if the tooth at either end
        // of that range is near contact, teeth beyond the studied ones may touch too.
        let mut end_touch = f64::INFINITY;
        for n in 0..np {
            let ke = positions[n].kinematic_error;
            let mut in_contact = 0;
            for t in 0..nt {
                let block = &blocks[n * nt + t];
                let mut tooth_min = f64::INFINITY;
                for c in 0..n_cells {
                    let sep = (block.cell_gaps[c] + ke) * cell_lever[c];
                    tooth_min = tooth_min.min(sep);
                    if sep < min_separation[c] {
                        min_separation[c] = sep;
                    }
                }
                if tooth_min <= j_mark {
                    in_contact += 1;
                }
                if (t == 0 && n == 0) || (t == nt - 1 && n == np - 1) {
                    end_touch = end_touch.min(tooth_min);
                }
            }
            positions[n].teeth_in_contact = in_contact;
        }
        if end_touch <= j_mark {
            let kk = self.teeth.last().copied().unwrap_or(0);
            warnings.push(format!(
                "the outermost studied tooth (k = +-{kk}) is within {:.2} um of contact at the end \
                 of the studied range: teeth beyond it may touch; increase analysis.teeth_each_side",
                end_touch * 1e6
            ));
        }
        (min_separation, warnings)
    }

    /// The contact line of every studied tooth at every position: each slice's minimum gap with
    /// its point, separation, worm radius, lever and relative curvature radius (MODEL §4.6).
    fn contact_lines(
        &self,
        blocks: &[GapBlock],
        positions: &[Position],
        node_contact: &[NodeContact],
    ) -> Vec<SliceContact> {
        let (ev, wf) = (self.ev, self.wf);
        let nt = self.teeth.len();
        let mut contact_lines = Vec::with_capacity(self.positions * nt * (wf.cells_face + 1));
        for (n, position) in positions.iter().enumerate() {
            let ke = position.kinematic_error;
            let (theta2, theta1) = (position.theta2, position.theta1);
            for t in 0..nt {
                let offset = self.sigma * self.teeth[t] as f64 * self.tau;
                for (j, &(r, gap, at_end)) in blocks[n * nt + t].slices.iter().enumerate() {
                    if !gap.is_finite() {
                        continue;
                    }
                    let z = wf.z[j];
                    let (theta, _) = wf.column_theta(j, r);
                    let p = wheel_point(r, theta + offset, z, theta2);
                    let q = ev.placement.wheel_to_worm(&p);
                    let rho = (q.y * q.y + q.z * q.z).sqrt();
                    let normal = ev.worm.outward_normal(ev.flank, q.y, q.z);
                    let n_wheel = ev.placement.vector_worm_to_wheel(&normal);
                    let lever = GapEvaluator::lever(&p, &n_wheel);
                    let curvature_radius = if at_end {
                        f64::NAN
                    } else {
                        curvature_radius(ev, wf, j, r, offset, theta2, theta1, lever, node_contact)
                    };
                    contact_lines.push(SliceContact {
                        position: n,
                        tooth: self.teeth[t],
                        slice: j,
                        r,
                        z,
                        theta,
                        angular_gap: gap,
                        separation: (gap + ke) * lever,
                        worm_radius: rho,
                        at_end,
                        curvature_radius,
                    });
                }
            }
        }
        contact_lines
    }
}

/// The lowest radius the worm's tip reaches on each node column of the wheel flank, (z, r), m
/// (the flank's root where the worm does not reach below it).
fn tip_trace(worm_cut: &Hobbing, flank: Flank, wf: &WheelFlank) -> Vec<(f64, f64)> {
    let ni = wf.cells_height;
    wf.z.par_iter()
        .enumerate()
        .map(|(j, &z)| {
            let top = wf.node(ni, j).r;
            match worm_cut.radial_limits(flank, z, top) {
                Ok((lo, _)) => (z, lo.max(wf.node(0, j).r)),
                Err(_) => (z, top),
            }
        })
        .collect()
}
