//! The stabilised wear step and the error control of adaptive steps (MODEL §7.3; issue 55).
//!
//! The published step is explicit: a node removes the step's cycles times its wear per cycle on
//! the frozen geometry. A node worn deeper than its neighbours carries less pressure and wears
//! slower, so the flank's roughness at the grid's scale decays; an explicit step that removes
//! more than about twice the contact's local elastic approach overshoots it and roughens the
//! flank instead (MODEL §7.3: "steps removing about 10 um made the published computation
//! unstable"; BENCHMARKS.md session 37). The stabilised step takes that node-scale response at
//! the step's end: with w the wear per cycle and dC the step's cycles,
//!
//!   (M + theta dC L) dh = dC M w,
//!
//! M the nodes' areas (a quarter of each cell's at its corners: the worn volume is sum M dh,
//! `FlankField::integral`), theta per edge ([`theta`]), and L the graph Laplacian of the
//! flank's grid whose edge (k, l) along the height weighs min(beta_k w_k, beta_l w_l) (M_k + M_l) / 8, with
//! beta the rows' response (along the face, the columns'). beta is the wear's response to the
//! removal, measured at each node on the life's first state, and again after each pitting
//! phase's cut and every [`REMEASURE_WEAR`] of wear ([`NodeResponse`]): the change of
//! the wear per cycle under a removal alternating from row to row (column to column), per unit
//! removal and unit wear, 1/m. An alternating removal is then damped exactly as its measured response
//! says (L's eigenvalue for it is beta w), a uniform one not at all (L 1 = 0: a step wears the
//! same as the explicit one wherever the wear is even), and smooth variations over many nodes
//! little. L is symmetric with zero column sums, so the step removes the explicit step's worn
//! volume exactly; an edge to a node the contact never reaches weighs 0, so no
//! wear moves onto it; (M + theta dC L) is an M-matrix, so no node's removal is negative. As
//! dC -> 0 the step tends to the explicit one.
//!
//! theta weighs how much of the response is taken at the step's end. A node-scale roughness e
//! of response z = dC beta w evolves as e' = e (1 - (1 - theta) z) / (1 + theta z): the explicit
//! step (theta = 0) overshoots beyond z = 2 and grows; theta = 1 damps every z (e' -> 0) but
//! biases the worn pattern's real peaks low by about dC^2 J w / 2 per step, as the explicit step
//! biases them high (measured at tolerance 0.003: the design's and case B's one-node wear -1.7
//! and -6.7 %, case C's patch wear away from its pits -3.6 %); theta = 1/2 leaves the roughness
//! of z > 2 oscillating (e' -> -e as z grows; theta = 0.6 raised case B's worn volume by 2 %
//! over its life, BENCHMARKS.md session 42). [`theta`] is the least theta for which e' >= 0:
//! 0 up to z = 1, where the step is the published explicit one exactly, and 1 - 1/z beyond,
//! where the roughness the explicit step would flip is removed in one step (e' = 0). The
//! step departs from the explicit one only where that one would overshoot (BENCHMARKS.md
//! session 43: against the trapezoidal rule limited the same way, the same accuracy but on
//! case B's face-end peak, -2.3 against -5.2 %).
//!
//! The error control sets adaptive steps from the change of the wear per cycle over the last
//! step: the step's local error is about dC / 2 times the change of the rate (the explicit
//! step against the trapezoidal rule) on three converged measures, the worn volume, the
//! largest patch-mean wear and the backlash ([`RateMeasures`]; the backlash's rate over the last
//! step and the one before); the next step is the last one times
//! sqrt(tolerance / error), within half and twice it, and never beyond the adaptive step's
//! largest removal.

use crate::geometry::{FlankField, WheelFlank};

/// The wear's response to a node-scale removal, measured (module doc): at each node, the
/// per-cycle wear's decrease per unit removal, as a share of the wear per cycle, for a removal
/// alternating along the flank's height (`rows`) and along its face (`columns`), 1/m; with the
/// flank it was measured on (its largest removal, m, and its pitted nodes), which says when it
/// is measured again ([`NodeResponse::is_due`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct NodeResponse {
    pub rows_per_m: Vec<f64>,
    pub columns_per_m: Vec<f64>,
    /// The flank's largest removal when measured, m (checkpoints of session 42: 0).
    #[serde(default)]
    pub measured_at_removal_m: f64,
    /// The flank's pitted nodes when measured.
    #[serde(default)]
    pub measured_pitted_nodes: usize,
    /// The state (its step) it was measured on: a run resumed there counts the measurement's
    /// analyses in that state's record, as the uninterrupted run did.
    #[serde(default)]
    pub measured_at_step: usize,
}

/// Wear after which the node response is measured again, m: the response is the contact's at
/// the grid's scale, and it changes as the flank wears into a new shape (case B's life, 2.3 mm
/// of wear with its response measured on the unworn flank only: backlash 2.4 % above explicit
/// 1 um steps by its end; measured again every 200 um and after each pitting phase's cut:
/// 1.4 %, for 7 more loaded analyses; BENCHMARKS.md session 43).
pub const REMEASURE_WEAR: f64 = 200e-6;

impl NodeResponse {
    /// Whether the response no longer describes a flank whose largest removal is `removal`
    /// (m) with `pitted_nodes` pitted nodes: the flank has worn [`REMEASURE_WEAR`] since, or pits
    /// were cut (their edges respond as no worn flank does).
    pub fn is_due(&self, removal: f64, pitted_nodes: usize) -> bool {
        removal - self.measured_at_removal_m > REMEASURE_WEAR
            || pitted_nodes != self.measured_pitted_nodes
    }
}

/// The share theta of the node-scale response taken at the step's end, for a step whose
/// node-scale response is `z` = dC beta w (module doc): 0 (the explicit step) where the explicit
/// step does not flip that roughness (z <= 1), else 1 - 1/z, which removes it in one step
/// (amplification 0). Against explicit 1 um steps (BENCHMARKS.md session 43), 24 um steps with
/// the error control at 0.001: case B's final patch wear away from its pits -2.3 % (the
/// trapezoidal rule's 1/2 up to z = 2: -5.2 %; theta = 1 everywhere, session 42, biased the
/// design's one-node wear -1.7 % at 0.003).
pub fn theta(z: f64) -> f64 {
    if z > 1.0 {
        1.0 - 1.0 / z
    } else {
        0.0
    }
}

/// The amplitude of the probe's alternating removal, m: small against the contact's elastic
/// approach (~10 um), large against the solver's tolerance.
pub(crate) const PROBE_REMOVAL: f64 = 1e-6;

/// Nodes whose wear per cycle is at least this share of the largest take part in the
/// response's median (the loaded pattern, not its fringe).
const PROBE_SHARE: f64 = 0.2;

/// The probe's removal pattern on the grid of `field`: +-[`PROBE_REMOVAL`], alternating from row
/// to row (`along_height`) or from column to column, m.
pub(crate) fn probe_pattern(field: &FlankField, along_height: bool) -> Vec<f64> {
    let rows = field.cells_height + 1;
    (0..field.values.len())
        .map(|k| {
            let index = if along_height { k % rows } else { k / rows };
            if index % 2 == 0 {
                PROBE_REMOVAL
            } else {
                -PROBE_REMOVAL
            }
        })
        .collect()
}

/// At each node, -(w1 - w0) / (pattern w0): the per-cycle wear's response to the removal
/// `pattern` (m), as a share of the wear, 1/m; 0 where it is not positive (no damping rather
/// than a negative one: a node the removal unloads, or one at the flow pressure, whose load
/// does not follow its depth). A node the contact barely loads when measured (below
/// [`PROBE_SHARE`] of the largest wear) takes the median of the others.
pub(crate) fn response(w0: &FlankField, w1: &FlankField, pattern: &[f64]) -> Vec<f64> {
    let largest = w0.max();
    let measured: Vec<Option<f64>> = w0
        .values
        .iter()
        .zip(&w1.values)
        .zip(pattern)
        .map(|((w, w1), d)| {
            let share = -(w1 - w) / (d * w);
            (largest > 0.0 && *w >= PROBE_SHARE * largest && share.is_finite())
                .then(|| share.max(0.0))
        })
        .collect();
    let mut shares: Vec<f64> = measured.iter().flatten().copied().collect();
    shares.sort_by(f64::total_cmp);
    let median = shares.get(shares.len() / 2).copied().unwrap_or(0.0);
    measured.iter().map(|m| m.unwrap_or(median)).collect()
}

/// The stabilised step's removal (module doc) of `cycles` cycles at the wear per cycle `w`
/// (m per cycle on the nodes of the flank `wf`), m per node.
pub fn stabilised_removal(
    w: &FlankField,
    wf: &WheelFlank,
    cycles: f64,
    response: &NodeResponse,
) -> Vec<f64> {
    removal_on(w, &node_areas(wf), cycles, response)
}

/// [`stabilised_removal`] on nodes of the given areas (m^2).
fn removal_on(w: &FlankField, areas: &[f64], cycles: f64, response: &NodeResponse) -> Vec<f64> {
    let explicit: Vec<f64> = w.values.iter().map(|x| cycles * x).collect();
    let edges = edges(w, areas, cycles, response);
    if edges.is_empty() {
        return explicit;
    }
    let b: Vec<f64> = explicit.iter().zip(areas).map(|(x, m)| x * m).collect();
    conjugate_gradient(areas, &edges, &b)
}

/// The nodes' areas M (module doc): a quarter of each adjacent cell's, m^2.
fn node_areas(wf: &WheelFlank) -> Vec<f64> {
    let rows = wf.cells_height + 1;
    let mut areas = vec![0.0; wf.nodes.len()];
    for j in 0..wf.cells_face {
        for i in 0..wf.cells_height {
            let quarter = 0.25 * wf.cell_area[j * wf.cells_height + i];
            for k in [
                j * rows + i,
                j * rows + i + 1,
                (j + 1) * rows + i,
                (j + 1) * rows + i + 1,
            ] {
                areas[k] += quarter;
            }
        }
    }
    areas
}

/// The weighted edges (k, l, weight) of dC L (module doc), on the nodes' `areas`.
fn edges(
    w: &FlankField,
    areas: &[f64],
    cycles: f64,
    response: &NodeResponse,
) -> Vec<(usize, usize, f64)> {
    let rows = w.cells_height + 1;
    let columns = w.cells_face + 1;
    let v = &w.values;
    let mut edges = Vec::new();
    let mut add = |k: usize, l: usize, beta: &[f64]| {
        let damping = (beta[k] * v[k]).min(beta[l] * v[l]).max(0.0);
        let z = cycles * damping;
        let weight = theta(z) * z * (areas[k] + areas[l]) / 8.0;
        if weight > 0.0 {
            edges.push((k, l, weight));
        }
    };
    for j in 0..columns {
        for i in 0..rows {
            let k = j * rows + i;
            if i + 1 < rows {
                add(k, k + 1, &response.rows_per_m);
            }
            if j + 1 < columns {
                add(k, k + rows, &response.columns_per_m);
            }
        }
    }
    edges
}

/// y = (M + dC L) x for the nodes' areas and the edges of [`edges`].
fn apply(areas: &[f64], edges: &[(usize, usize, f64)], x: &[f64], y: &mut [f64]) {
    for ((y, x), m) in y.iter_mut().zip(x).zip(areas) {
        *y = m * x;
    }
    for &(k, l, weight) in edges {
        let d = weight * (x[k] - x[l]);
        y[k] += d;
        y[l] -= d;
    }
}

/// Solves (M + dC L) x = b (symmetric positive definite) by conjugate gradients from
/// x = M^-1 b, to 1e-13 of b.
fn conjugate_gradient(areas: &[f64], edges: &[(usize, usize, f64)], b: &[f64]) -> Vec<f64> {
    let n = b.len();
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(a, b)| a * b).sum::<f64>();
    let mut x: Vec<f64> = b
        .iter()
        .zip(areas)
        .map(|(b, m)| if *m > 0.0 { b / m } else { 0.0 })
        .collect();
    let mut ax = vec![0.0; n];
    apply(areas, edges, &x, &mut ax);
    let mut r: Vec<f64> = b.iter().zip(&ax).map(|(b, a)| b - a).collect();
    let mut p = r.clone();
    let mut rr = dot(&r, &r);
    let target = 1e-26 * dot(b, b);
    let mut ap = vec![0.0; n];
    for _ in 0..10 * n {
        if rr <= target {
            break;
        }
        apply(areas, edges, &p, &mut ap);
        let alpha = rr / dot(&p, &ap);
        for k in 0..n {
            x[k] += alpha * p[k];
            r[k] -= alpha * ap[k];
        }
        let next = dot(&r, &r);
        let beta = next / rr;
        rr = next;
        for k in 0..n {
            p[k] = r[k] + beta * p[k];
        }
    }
    x
}

/// The converged measures whose change over a step the error control reads: the worn volume
/// of one flank (m^3), the largest patch-mean wear (m) and the backlash increase (m), or their
/// rates per cycle.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RateMeasures {
    pub volume: f64,
    pub patch: f64,
    /// The backlash increase's rate over the step that led to this state (m per cycle; None:
    /// no step yet), or, for the wear so far, the backlash increase (m). The backlash is the
    /// least worn contact's at each position, not a sum over the flank: in the running-in it
    /// rises twice as fast at its end as at its start while the worn volume's rate holds.
    #[serde(default)]
    pub backlash: Option<f64>,
    /// The backlash increase at this state, m (the next step's rate starts from it).
    #[serde(default)]
    pub backlash_increase: f64,
}

impl RateMeasures {
    /// The measures of a field on the flank `wf` (a removal, m, or a wear per cycle), with
    /// the pressure patch's size across and along (m).
    pub(crate) fn of(field: &FlankField, wf: &WheelFlank, patch: (f64, f64)) -> Self {
        Self {
            volume: field.integral(wf),
            patch: field.patch_mean_max(wf, patch.0, patch.1),
            backlash: None,
            backlash_increase: 0.0,
        }
    }
}

/// The next adaptive step's cycles under the error control (module doc): `last` the last
/// step's cycles, `before` and `now` the rates at its start and end, `worn` the measures of the
/// wear so far; None without an estimate (no wear yet).
pub(crate) fn controlled_cycles(
    last: f64,
    (before, now): (&RateMeasures, &RateMeasures),
    worn: &RateMeasures,
    tolerance: f64,
) -> Option<f64> {
    let share = |rate_before: f64, rate_now: f64, worn: f64| {
        (worn > 0.0).then(|| 0.5 * last * (rate_now - rate_before).abs() / worn)
    };
    let backlash = match (before.backlash, now.backlash, worn.backlash) {
        (Some(b), Some(n), Some(w)) => share(b, n, w).unwrap_or(0.0),
        _ => 0.0,
    };
    let error = share(before.volume, now.volume, worn.volume)?
        .max(share(before.patch, now.patch, worn.patch).unwrap_or(0.0))
        .max(backlash);
    let factor = if error > 0.0 {
        (tolerance / error).sqrt().clamp(0.5, 2.0)
    } else {
        2.0
    };
    (last > 0.0).then_some(last * factor)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A field on a grid of `height` x `face` cells from its values by node (i, j).
    fn field(height: usize, face: usize, value: impl Fn(usize, usize) -> f64) -> FlankField {
        let rows = height + 1;
        FlankField {
            cells_height: height,
            cells_face: face,
            values: (0..rows * (face + 1))
                .map(|k| value(k % rows, k / rows))
                .collect(),
        }
    }

    /// Node areas varying smoothly over the grid (m^2).
    fn areas(w: &FlankField) -> Vec<f64> {
        (0..w.values.len())
            .map(|k| 1e-7 * (1.0 + 0.3 * (k as f64 * 0.37).sin()))
            .collect()
    }

    /// A response of 2e5 / m along the height and 4e5 / m along the face at every node.
    fn even_response(w: &FlankField) -> NodeResponse {
        NodeResponse {
            rows_per_m: vec![2e5; w.values.len()],
            columns_per_m: vec![4e5; w.values.len()],
            measured_at_removal_m: 0.0,
            measured_pitted_nodes: 0,
            measured_at_step: 0,
        }
    }

    /// A worn patch with node-scale roughness, zero outside rows 3..=12 and columns 2..=20
    /// (m per cycle).
    fn rough_patch() -> FlankField {
        field(16, 24, |i, j| {
            if (3..=12).contains(&i) && (2..=20).contains(&j) {
                1e-9 * (1.0 + 0.5 * ((i * 7 + j * 3) % 5) as f64 / 4.0)
            } else {
                0.0
            }
        })
    }

    #[test]
    fn an_even_wear_is_stepped_as_the_explicit_step_does() {
        let w = field(10, 12, |_, _| 3e-10);
        let removal = removal_on(&w, &areas(&w), 8e4, &even_response(&w));
        for x in removal {
            assert!((x - 8e4 * 3e-10).abs() <= 1e-12 * 8e4 * 3e-10, "{x:e}");
        }
    }

    #[test]
    fn the_step_removes_the_explicit_worn_volume_and_nothing_where_no_contact_passes() {
        let w = rough_patch();
        let m = areas(&w);
        let cycles = 3e4;
        let removal = removal_on(&w, &m, cycles, &even_response(&w));
        let volume: f64 = removal.iter().zip(&m).map(|(x, m)| x * m).sum();
        let explicit: f64 = w.values.iter().zip(&m).map(|(x, m)| cycles * x * m).sum();
        assert!(
            (volume - explicit).abs() <= 1e-11 * explicit,
            "{volume:e} {explicit:e}"
        );
        for (x, w) in removal.iter().zip(&w.values) {
            assert!(*x >= 0.0);
            if *w == 0.0 {
                assert_eq!(*x, 0.0);
            }
        }
        // It smooths: the largest removal falls, the smallest in the patch rises.
        let inside = |v: &[f64]| -> (f64, f64) {
            let ws = w
                .values
                .iter()
                .zip(v)
                .filter(|(w, _)| **w > 0.0)
                .map(|(_, x)| *x);
            ws.clone()
                .fold((f64::INFINITY, 0.0), |(lo, hi), x| (lo.min(x), hi.max(x)))
        };
        let explicit_removal: Vec<f64> = w.values.iter().map(|x| cycles * x).collect();
        let (lo, hi) = inside(&removal);
        let (lo0, hi0) = inside(&explicit_removal);
        assert!(
            hi < hi0 && lo > lo0,
            "{lo:e} {hi:e} against {lo0:e} {hi0:e}"
        );
    }

    #[test]
    fn two_nodes_part_as_the_analytic_damping_says() {
        // Two nodes of equal area m, one edge of weight a = theta(z) z m / 4, z = dC beta min(w):
        // (m + a) x1 - a x2 = m dC w1 and its mirror, so x1 - x2 = dC (w1 - w2) / (1 + 2 a / m),
        // and x1 + x2 = dC (w1 + w2).
        let w = field(1, 0, |i, _| if i == 0 { 4e-10 } else { 3e-10 });
        let m = vec![2e-7, 2e-7];
        // z = 0.6 (theta 0: the explicit step) and 3 (theta 2/3).
        for cycles in [1e4, 5e4] {
            let x = removal_on(&w, &m, cycles, &even_response(&w));
            let z = cycles * 2e5 * 3e-10;
            let a_over_m = theta(z) * z / 4.0;
            let expected = cycles * 1e-10 / (1.0 + 2.0 * a_over_m);
            assert!(((x[0] - x[1]) - expected).abs() <= 1e-12 * expected);
            assert!(((x[0] + x[1]) - cycles * 7e-10).abs() <= 1e-12 * cycles * 7e-10);
        }
    }

    #[test]
    fn node_scale_roughness_decays_without_changing_sign_and_vanishes_beyond_z_1() {
        // A flank rough from row to row by e, whose wear responds to it (w = wbar (1 -+ beta e)),
        // no response along the face: each column a chain whose middle rows see the infinite
        // chain's node-scale mode. After a step e' = e (1 - (1 - theta) z) / (1 + theta z):
        // the explicit step's 1 - z up to z = 1, 0 beyond.
        let (wbar, beta, e) = (1e-9, 2e5, 1e-12);
        let sign = |i: usize| if i.is_multiple_of(2) { 1.0 } else { -1.0 };
        let w = field(60, 2, |i, _| wbar * (1.0 - beta * e * sign(i)));
        let m = vec![1e-7; w.values.len()];
        let response = NodeResponse {
            rows_per_m: vec![beta; w.values.len()],
            columns_per_m: vec![0.0; w.values.len()],
            measured_at_removal_m: 0.0,
            measured_pitted_nodes: 0,
            measured_at_step: 0,
        };
        for z in [0.2, 0.9, 1.0, 1.5, 3.0, 10.0] {
            let cycles = z / (beta * wbar);
            let x = removal_on(&w, &m, cycles, &response);
            let middle = 30;
            let rough = 0.5 * (x[middle] - x[middle + 1]) * sign(middle);
            let after = e + rough;
            let zmin = z * (1.0 - beta * e);
            let t = theta(zmin);
            let expected = e * (1.0 - (1.0 - t) * z) / (1.0 + t * zmin);
            assert!(
                after >= -1e-6 * e,
                "z {z}: e' {after:e} flips the roughness"
            );
            assert!(
                (after - expected).abs() <= 1e-6 * e,
                "z {z}: e' {after:e}, expected {expected:e}"
            );
            if z > 1.0 {
                assert!(after.abs() <= 1e-6 * e, "z {z}: e' {after:e}");
            } else {
                assert!((after - e * (1.0 - z)).abs() <= 1e-6 * e, "z {z}");
            }
        }
    }

    #[test]
    fn the_response_is_measured_again_after_its_wear_or_new_pits() {
        let response = NodeResponse {
            measured_at_removal_m: 150e-6,
            measured_pitted_nodes: 12,
            measured_at_step: 7,
            ..even_response(&rough_patch())
        };
        assert!(!response.is_due(150e-6, 12));
        assert!(!response.is_due(150e-6 + 0.99 * REMEASURE_WEAR, 12));
        assert!(response.is_due(150e-6 + 1.01 * REMEASURE_WEAR, 12));
        assert!(response.is_due(150e-6, 13));
    }

    #[test]
    fn the_step_is_the_explicit_one_where_that_one_does_not_overshoot() {
        // The rough patch's largest z = dC beta w is 4e5 x 1.5e-9 x dC (its fastest node along
        // the face): at dC = 1000, z = 0.6 everywhere, the explicit step exactly; at 4000 and
        // 8000 (z up to 2.4 and 4.8) it departs, more for the longer step.
        let w = rough_patch();
        let m = areas(&w);
        let gap = |cycles: f64| {
            let x = removal_on(&w, &m, cycles, &even_response(&w));
            x.iter()
                .zip(&w.values)
                .map(|(x, w)| (x - cycles * w).abs())
                .fold(0.0, f64::max)
                / (cycles * w.max())
        };
        assert_eq!(gap(1000.0), 0.0);
        let (shorter, longer) = (gap(4000.0), gap(8000.0));
        assert!(shorter > 0.0 && longer > shorter, "{shorter:e} {longer:e}");
    }

    #[test]
    fn the_measured_response_is_the_wear_change_per_unit_removal_and_wear() {
        let w0 = rough_patch();
        let pattern = probe_pattern(&w0, true);
        let beta = 3e5;
        let mut w1 = w0.clone();
        for (w, d) in w1.values.iter_mut().zip(&pattern) {
            *w *= 1.0 - beta * d;
        }
        // Every loaded node's own response; the unloaded ones take the loaded ones' median.
        for (r, w) in response(&w0, &w1, &pattern).iter().zip(&w0.values) {
            assert!((r - beta).abs() <= 1e-6 * beta, "{r:e} at w {w:e}");
        }
        // Alternating from row to row along the height.
        assert_eq!(pattern[0], -pattern[1]);
        assert_eq!(pattern[0], pattern[17]);
        // A node whose wear does not fall where it is worn deeper (at the flow pressure) gets
        // no damping, not a negative one; nor do nodes with no response.
        let loaded = w0.values.iter().position(|w| *w > 0.0).unwrap();
        let mut capped = w1.clone();
        capped.values[loaded] = w0.values[loaded] * (1.0 + beta * pattern[loaded]);
        let r = response(&w0, &capped, &pattern);
        assert_eq!(r[loaded], 0.0);
        assert!((r[loaded + 1] - beta).abs() <= 1e-6 * beta);
        assert!(response(&w0, &w0, &pattern).iter().all(|r| *r == 0.0));
    }

    #[test]
    fn the_error_control_grows_steady_steps_and_cuts_changing_ones() {
        let worn = RateMeasures {
            volume: 1e-9,
            patch: 1e-5,
            backlash: Some(1e-5),
            backlash_increase: 1e-5,
        };
        let rate = RateMeasures {
            volume: 1e-14,
            patch: 1e-10,
            backlash: Some(1e-10),
            backlash_increase: 1e-5,
        };
        let steady = controlled_cycles(1e4, (&rate, &rate), &worn, 0.01);
        assert_eq!(steady, Some(2e4));
        // A volume rate that changed by 4e-15 over 1e4 cycles: error 1e4 / 2 * 4e-15 / 1e-9 =
        // 0.02, twice the tolerance: the step shrinks by sqrt(0.5).
        let faster = RateMeasures {
            volume: 1.4e-14,
            ..rate
        };
        let cut = controlled_cycles(1e4, (&rate, &faster), &worn, 0.01).unwrap();
        assert!((cut - 1e4 * 0.5f64.sqrt()).abs() < 1e-6, "{cut}");
        // Within half and twice the last step.
        let tiny = controlled_cycles(1e4, (&rate, &faster), &worn, 1e-6).unwrap();
        assert_eq!(tiny, 5e3);
        // The patch's change counts too (4e-11 of 1e-5 over 1e4 cycles: the same 0.02).
        let patch = RateMeasures {
            patch: 1.4e-10,
            ..rate
        };
        let by_patch = controlled_cycles(1e4, (&rate, &patch), &worn, 0.01).unwrap();
        assert!((by_patch - 1e4 * 0.5f64.sqrt()).abs() < 1e-6, "{by_patch}");
        // The backlash's change counts too; without a rate over the last step, not at all.
        let backlash = RateMeasures {
            backlash: Some(1.4e-10),
            ..rate
        };
        let by_backlash = controlled_cycles(1e4, (&rate, &backlash), &worn, 0.01).unwrap();
        assert!(
            (by_backlash - 1e4 * 0.5f64.sqrt()).abs() < 1e-6,
            "{by_backlash}"
        );
        let unknown = RateMeasures {
            backlash: None,
            ..rate
        };
        assert_eq!(
            controlled_cycles(1e4, (&unknown, &backlash), &worn, 0.01),
            Some(2e4)
        );
        let unworn = RateMeasures {
            volume: 0.0,
            patch: 0.0,
            backlash: Some(0.0),
            backlash_increase: 0.0,
        };
        assert_eq!(
            controlled_cycles(1e4, (&rate, &faster), &unworn, 0.01),
            None
        );
        assert_eq!(controlled_cycles(0.0, (&rate, &rate), &worn, 0.01), None);
    }
}
