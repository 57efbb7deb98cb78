//! The contact kinematics of a flank node (MODEL §4.5, §4.6): the moment the worm flank meets it,
//! the sliding and rolling velocities across the contact line, and the relative curvature radius.

use super::*;
use crate::geometry::hobbing::PointKind;
use crate::geometry::placement::{from_wheel_body, wheel_point};
use crate::geometry::{Geometry, WheelFlank};
use nalgebra::Vector3;

/// Relative radius of curvature across the contact line on slice j at r: R = sin^2(beta) / g''
/// with g the normal gap along the slice (arc length s) and beta the angle between the slice
/// and the contact line (MODEL §4.6: gap ~ xi^2 / 2R across the line). m.
#[allow(clippy::too_many_arguments)]
pub(super) fn curvature_radius(
    ev: &GapEvaluator,
    wf: &WheelFlank,
    j: usize,
    r: f64,
    offset: f64,
    theta2: f64,
    theta1: f64,
    lever: f64,
    contacts: &[NodeContact],
) -> f64 {
    let z = wf.z[j];
    let h = 0.25 * wf.largest_row_of(j);
    let gap =
        |rr: f64| ev.angular(rr, wf.column_theta(j, rr).0 + offset, z, theta2, theta1) * lever;
    let (gm, g0, gp) = (gap(r - h), gap(r), gap(r + h));
    let pos = |rr: f64| wheel_point(rr, wf.column_theta(j, rr).0, z, 0.0);
    let ds = (pos(r + h) - pos(r - h)).norm() / 2.0;
    let g2 = (gp - 2.0 * g0 + gm) / (ds * ds);
    // Angle between the slice and the contact line (body frame), from the nearest node.
    let i = (wf.row_parameter(j, r).round().max(0.0) as usize).min(wf.cells_height);
    let c = &contacts[j * (wf.cells_height + 1) + i];
    let slice_dir = (pos(r + h) - pos(r - h)).normalize();
    let sin_b = slice_dir
        .cross(&Vector3::from(c.line_direction_body))
        .norm();
    if g2 > 0.0 {
        sin_b * sin_b / g2
    } else {
        f64::INFINITY
    }
}

/// Surface gradient of the contact moment theta2 at node (i, j) of the wheel flank (body
/// frame, 1/m), by differences on the node grid over the neighbours the worm flank reaches
/// (their contact moments are meaningful); tangential part only. None when a direction has no
/// reachable neighbour.
pub(super) fn contact_moment_gradient(
    wf: &WheelFlank,
    contact_theta2: &[f64],
    reachable_mask: &[bool],
    i: usize,
    j: usize,
) -> Option<Vector3<f64>> {
    let (ni, nj) = (wf.cells_height, wf.cells_face);
    let idx = |i: usize, j: usize| j * (ni + 1) + i;
    let ok = |i: usize, j: usize| reachable_mask[idx(i, j)];
    let pick = |lo: usize, mid: usize, hi: usize, f: &dyn Fn(usize) -> bool| -> (usize, usize) {
        match (f(lo), f(hi)) {
            (true, true) => (lo, hi),
            (true, false) => (lo, mid),
            (false, true) => (mid, hi),
            (false, false) => (mid, mid),
        }
    };
    let (i0, i1) = pick(i.saturating_sub(1), i, (i + 1).min(ni), &|ii| ok(ii, j));
    let (j0, j1) = pick(j.saturating_sub(1), j, (j + 1).min(nj), &|jj| ok(i, jj));
    if i0 == i1 || j0 == j1 {
        return None;
    }
    let pi = (wf.node(i1, j).position() - wf.node(i0, j).position()) / (i1 - i0) as f64;
    let pj = (wf.node(i, j1).position() - wf.node(i, j0).position()) / (j1 - j0) as f64;
    let fi = (contact_theta2[idx(i1, j)] - contact_theta2[idx(i0, j)]) / (i1 - i0) as f64;
    let fj = (contact_theta2[idx(i, j1)] - contact_theta2[idx(i, j0)]) / (j1 - j0) as f64;
    // grad = a pi + b pj with grad . pi = fi, grad . pj = fj.
    let (g11, g12, g22) = (pi.dot(&pi), pi.dot(&pj), pj.dot(&pj));
    let det = g11 * g22 - g12 * g12;
    let a = (fi * g22 - fj * g12) / det;
    let b = (fj * g11 - fi * g12) / det;
    // Keep the tangential part (the chords pi, pj are not exactly tangent).
    let nb = wf.node(i, j).normal_vec();
    let grad_body = pi * a + pj * b;
    Some(grad_body - nb * grad_body.dot(&nb))
}

impl NodeContact {
    /// A node the worm flank does not reach (or whose contact moment has no gradient): its
    /// moment, worm radius `rho` (m), sliding velocity `vg` and normal `n` (worm frame), the
    /// rest NaN.
    fn unreachable(theta2: f64, rho: f64, vg: Vector3<f64>, n: Vector3<f64>) -> Self {
        NodeContact {
            reachable: false,
            theta2,
            worm_radius: rho,
            ease_off: f64::NAN,
            sliding_speed: vg.norm(),
            sliding_along: f64::NAN,
            sliding_across: f64::NAN,
            u1: f64::NAN,
            u2: f64::NAN,
            sliding: vg.into(),
            normal: n.into(),
            line_direction: [f64::NAN; 3],
            line_direction_body: [f64::NAN; 3],
        }
    }
}

/// Contact kinematics of node (i, j) from the worm's envelope at that node.
#[allow(clippy::too_many_arguments)]
pub(super) fn node_contact(
    geo: &Geometry,
    ev: &GapEvaluator,
    wf: &WheelFlank,
    env: &crate::geometry::EnvelopePoint,
    contact_theta2: &[f64],
    reachable_mask: &[bool],
    i: usize,
    j: usize,
    theta1_dot: f64,
) -> NodeContact {
    let ni = wf.cells_height;
    let node = wf.node(i, j);
    let reachable = env.kind == PointKind::Flank;
    let theta2 = contact_theta2[j * (ni + 1) + i];
    let p = wheel_point(node.r, node.theta, node.z, theta2);
    let q = ev.placement.wheel_to_worm(&p);
    let rho = (q.y * q.y + q.z * q.z).sqrt();
    let v = material_velocities(&q, &geo.worm, &ev.placement, theta1_dot, ev.ratio);
    let vg = Vector3::from(v.sliding);
    // Normal: the wheel node's normal (body) turned to the contact moment, in the worm frame,
    // oriented like the worm's outward normal (out of the worm, into the wheel).
    let n = -ev
        .placement
        .vector_wheel_to_worm(&from_wheel_body(&node.normal_vec(), theta2));
    let gradient = contact_moment_gradient(wf, contact_theta2, reachable_mask, i, j);
    let Some(grad_body) = gradient.filter(|_| reachable) else {
        return NodeContact::unreachable(theta2, rho, vg, n);
    };
    let grad = ev
        .placement
        .vector_wheel_to_worm(&from_wheel_body(&grad_body, theta2));
    let theta2_dot = theta1_dot / ev.ratio;
    let g2 = grad.norm_squared();
    let (line, across, w2, line_body) = if g2 > 0.0 && g2.is_finite() {
        let nu = grad / g2.sqrt();
        let t = n.cross(&nu).normalize();
        let t_body = node.normal_vec().cross(&grad_body).normalize();
        (t, nu, grad * (theta2_dot / g2), t_body)
    } else {
        (
            Vector3::zeros(),
            Vector3::zeros(),
            Vector3::zeros(),
            Vector3::zeros(),
        )
    };
    let u2 = w2.dot(&across);
    let u1 = (vg + w2).dot(&across);
    let ease_off = if reachable {
        node.r * (node.theta - env.theta) * -ev.flank.sign()
    } else {
        f64::NAN
    };
    NodeContact {
        reachable,
        theta2,
        worm_radius: rho,
        ease_off,
        sliding_speed: vg.norm(),
        sliding_along: vg.dot(&line),
        sliding_across: vg.dot(&across),
        u1,
        u2,
        sliding: vg.into(),
        normal: n.into(),
        line_direction: line.into(),
        line_direction_body: line_body.into(),
    }
}
