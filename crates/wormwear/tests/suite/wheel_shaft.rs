//! The wheel shaft's compliance at the hub (bending/wheel_shaft.rs) against closed-form beam
//! results: torsion and thrust of the fixed-end segment, a Timoshenko cantilever with a rigid
//! hub arm, a propped cantilever (statically indeterminate) derived by compatibility.

use crate::common;
use std::f64::consts::PI;
use wormwear::bending::wheel_shaft::WheelShaft;

const E: f64 = 206e9;
const NU: f64 = 0.3;

fn shaft(radius: f64, hub_half_width: f64, bearings: [f64; 2]) -> WheelShaft {
    WheelShaft {
        radius,
        hub_half_width,
        bearings,
        youngs_modulus: E,
        poisson_ratio: NU,
    }
}

#[test]
fn torsion_and_thrust_are_taken_by_the_fixed_end() {
    // Bearing A holds the shaft laterally only: torque and thrust go to the fixed end B through
    // the segment from the hub face to B.
    let (r, h, zb) = (0.02, 0.015, 0.06);
    let s = shaft(r, h, [-0.05, zb]).compliance();
    let g = E / (2.0 * (1.0 + NU));
    let (area, polar) = (PI * r * r, 0.5 * PI * r.powi(4));
    let l = zb - h;
    let torsion = l / (g * polar);
    let thrust = l / (E * area);
    eprintln!(
        "torsion {:.6e} vs {torsion:.6e} rad/(N m); thrust {:.6e} vs {thrust:.6e} m/N",
        s[(5, 5)],
        s[(2, 2)]
    );
    assert!((s[(5, 5)] / torsion - 1.0).abs() < 1e-9);
    assert!((s[(2, 2)] / thrust - 1.0).abs() < 1e-9);
    // Symmetric, positive definite.
    assert!((s - s.transpose()).abs().max() < 1e-12 * s.abs().max());
    assert!(s.cholesky().is_some());
}

#[test]
fn lateral_compliance_is_a_timoshenko_cantilever_with_a_rigid_hub_arm() {
    // Bearing A very far away (L_A = 1e5 m) adds next to nothing (its segment's end
    // stiffness 3EI/L_A against EI/l: 3 l / L_A = 1.5e-6): the hub is a rigid arm of length h
    // on a cantilever of length l clamped at B. Load P at the hub centre: at the hub face the force P and the
    // moment P h; the centre moves by the face's deflection plus its slope times h.
    let (r, h, l) = (0.015, 0.02, 0.05);
    let s = shaft(r, h, [-1e5, h + l]).compliance();
    let g = E / (2.0 * (1.0 + NU));
    let area = PI * r * r;
    let inertia = 0.25 * PI * r.powi(4);
    let kappa = 6.0 * (1.0 + NU) / (7.0 + 6.0 * NU);
    let w_face =
        l.powi(3) / (3.0 * E * inertia) + l / (kappa * g * area) + h * l * l / (2.0 * E * inertia);
    let slope = l * l / (2.0 * E * inertia) + h * l / (E * inertia);
    let exact = w_face + slope * h;
    eprintln!(
        "lateral {:.6e} / {:.6e} vs {exact:.6e} m/N (shear part {:.1} %)",
        s[(0, 0)],
        s[(1, 1)],
        100.0 * l / (kappa * g * area) / exact
    );
    assert!((s[(0, 0)] / exact - 1.0).abs() < 1e-5);
    assert!((s[(1, 1)] / exact - 1.0).abs() < 1e-5);
    // Tilt under a moment at the hub: the face rotates by M l / EI (plus the arm's nothing).
    let tilt = l / (E * inertia);
    assert!((s[(3, 3)] / tilt - 1.0).abs() < 1e-5);
}

#[test]
fn lateral_compliance_of_a_propped_cantilever() {
    // Point hub: load P at distance b from the clamp B, prop at A, span L. Compatibility at A
    // with Timoshenko cantilever flexibilities (bending + shear): w_AA = L^3/3EI + L/kGA,
    // w_AC = b^2 (3L - b)/6EI + b/kGA (Maxwell: = w_CA), w_CC = b^3/3EI + b/kGA; the prop
    // force is P w_AC / w_AA and the deflection under the load w_CC - w_AC^2 / w_AA.
    let (r, a, b) = (0.01, 0.3, 0.2);
    let s = shaft(r, 0.0, [-a, b]).compliance();
    let g = E / (2.0 * (1.0 + NU));
    let area = PI * r * r;
    let inertia = 0.25 * PI * r.powi(4);
    let kga = 6.0 * (1.0 + NU) / (7.0 + 6.0 * NU) * g * area;
    let l = a + b;
    let w_aa = l.powi(3) / (3.0 * E * inertia) + l / kga;
    let w_ac = b * b * (3.0 * l - b) / (6.0 * E * inertia) + b / kga;
    let w_cc = b.powi(3) / (3.0 * E * inertia) + b / kga;
    let exact = w_cc - w_ac * w_ac / w_aa;
    eprintln!("propped cantilever {:.6e} vs {exact:.6e} m/N", s[(0, 0)]);
    assert!((s[(0, 0)] / exact - 1.0).abs() < 1e-9);
    // Without the prop (A far away) the shaft is softer.
    let free = shaft(r, 0.0, [-1e4, b]).compliance();
    assert!(free[(0, 0)] > s[(0, 0)]);
}

/// A bending model made of the shaft term alone (no teeth terms).
struct ShaftOnly(Vec<f64>);

impl wormwear::ltca::BendingModel for ShaftOnly {
    fn name(&self) -> &'static str {
        "shaft"
    }
    fn coefficients(&self, cells: &[wormwear::ltca::LocalCell]) -> wormwear::ltca::solver::LowRank {
        let empty = wormwear::ltca::solver::LowRank::new(0, Vec::new(), Vec::new(), Vec::new());
        wormwear::bending::wheel_model::with_rigid_body(empty, &self.0, cells)
    }
    fn rigid_rotation_compliance(&self) -> f64 {
        self.0[35]
    }
}

#[test]
fn shaft_torsion_shifts_the_te_and_leaves_the_load_sharing() {
    // A rigid rotation of the wheel is the LTCA's own unknown: a torsional compliance c_t of
    // the shaft adds c_t C2 to the transmission error at every position and changes no
    // pressure. A lateral compliance moves the wheel off the worm: the approach grows and the
    // pressures change.
    let g = common::example("gear-1x40-design.toml");
    let geo = wormwear::geometry::Geometry::build(&g).unwrap();
    let tca = wormwear::kinematics::analyse(&g, &geo).unwrap();
    let s = wormwear::ltca::LtcaSettings::from_gear(&g);
    let rigid = wormwear::ltca::analyse_with(&g, &geo, &tca, &s, None).unwrap();
    let c_t = 2e-6;
    let mut torsion = vec![0.0; 36];
    torsion[35] = c_t;
    let twisted =
        wormwear::ltca::analyse_with(&g, &geo, &tca, &s, Some(&ShaftOnly(torsion))).unwrap();
    let mut worst_te = 0.0f64;
    let mut worst_p = 0.0f64;
    for (a, b) in rigid.positions.iter().zip(&twisted.positions) {
        let shift = b.transmission_error - a.transmission_error;
        // TE is negative under load (the wheel lags): the shift is -c_t W, W the normal
        // pressures' wheel torque (the bending model carries no friction tractions).
        worst_te = worst_te.max((shift / (-c_t * a.normal_wheel_torque) - 1.0).abs());
        let pmax = a.pressure.iter().cloned().fold(0.0, f64::max);
        for (pa, pb) in a.pressure.iter().zip(&b.pressure) {
            worst_p = worst_p.max((pa - pb).abs() / pmax);
        }
    }
    eprintln!(
        "TE shift vs -c_t C2: worst {worst_te:.2e}; pressures: worst change {worst_p:.2e} of P_max"
    );
    assert!(worst_te < 1e-6 && worst_p < 1e-6);
    // The stiffness reported without the shaft's torsion is the one without the shaft.
    let k0 = rigid.stiffness_mean();
    let k1 = twisted.stiffness_without_shaft_torsion_mean();
    eprintln!(
        "mesh stiffness {k0:.6e}, with the torsion {:.6e}, taken out again {k1:.6e} N m/rad",
        twisted.stiffness_mean()
    );
    assert!((k1 / k0 - 1.0).abs() < 1e-6 && twisted.stiffness_mean() < 0.9 * k0);
    // Lateral compliance along the line of centres: more approach, different pressures.
    let mut lateral = vec![0.0; 36];
    lateral[0] = 1e-8;
    lateral[7] = 1e-8;
    let moved =
        wormwear::ltca::analyse_with(&g, &geo, &tca, &s, Some(&ShaftOnly(lateral))).unwrap();
    assert!(moved.te_stats().0 < rigid.te_stats().0);
}
