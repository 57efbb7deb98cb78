//! Finite-element model of the worm built from the generated thread (MODEL §5.5): geometry
//! (volume), shaft bending against Timoshenko beam theory, the glued seam, interpolation of the
//! bending coefficients off the fit grid, reciprocity.

use crate::common::example;
use std::f64::consts::PI;
use wormwear::bending::fe::{element_volume, Elastic, Load};
use wormwear::bending::worm_mesh::{
    worm_mesh, worm_mesh_on, WormBody, WormLattice, WormMeshSettings,
};
use wormwear::bending::worm_model::{worm_bending_displacements, worm_displacements, WormBending};
use wormwear::geometry::{Flank, Geometry};
use wormwear::input::GearSet;

const STEEL: Elastic = Elastic {
    youngs_modulus: 203e9,
    poisson_ratio: 0.29,
};

fn settings(scale: usize) -> WormMeshSettings {
    WormMeshSettings {
        layers: 24 * scale,
        across: 2 * scale,
        height: 4 * scale,
        space: scale,
        core: scale,
        inner: 2 * scale,
    }
}

fn body(g: &GearSet) -> WormBody {
    WormBody {
        root_radius: g.worm.root_radius,
        tip_radius: g.worm.tip_radius,
        shaft_radius: 0.75 * g.worm.root_radius,
        body_half_length: 0.06,
        bearings: [-0.1, 0.1],
    }
}

#[test]
fn worm_mesh_volume_matches_the_thread_geometry() {
    let g = example("gear-1x40-design.toml");
    let geo = Geometry::build(&g).unwrap();
    let b = body(&g);
    let m = worm_mesh(&geo.worm, Flank::Left, &b, &settings(1));
    let ours: f64 = (0..m.mesh.elements.len())
        .map(|e| element_volume(&m.mesh, e))
        .sum();
    // Exact: core pitches (a helical shear keeps volumes), three threads of one pitch each:
    // per pitch, the thread's volume is the integral of 2 pi rho t(rho) over its height.
    let p = geo.worm.axial_pitch();
    let lead = geo.worm.lead();
    let (j_lo, j_hi) = (
        ((-0.1 - 2.0 * lead - p) / p).floor() as i64,
        ((0.1 + 2.0 * lead + p) / p).ceil() as i64,
    );
    let bore = 0.25 * b.shaft_radius;
    let body_pitches = (j_lo..j_hi)
        .filter(|&j| (j as f64 * p).abs() <= b.body_half_length)
        .count() as f64;
    let n = 2000;
    let dr = (b.tip_radius - b.root_radius) / n as f64;
    let thread: f64 = (0..n)
        .map(|i| {
            let rho = b.root_radius + (i as f64 + 0.5) * dr;
            2.0 * PI * rho * geo.worm.axial_thickness_at(rho) * dr
        })
        .sum();
    let exact = (j_hi - j_lo) as f64 * PI * (b.shaft_radius.powi(2) - bore * bore) * p
        + body_pitches * PI * (b.root_radius.powi(2) - b.shaft_radius.powi(2)) * p
        + 3.0 * thread;
    eprintln!(
        "worm mesh: {} elements, {} nodes, volume {ours:.6e} vs {exact:.6e} m^3",
        m.mesh.elements.len(),
        m.mesh.nodes.len()
    );
    assert!((ours / exact - 1.0).abs() < 2e-4, "{ours:e} vs {exact:e}");
    // The seam is glued: no two nodes coincide (an open seam would leave pairs).
    let mut keys: Vec<(i64, i64, i64)> = m
        .mesh
        .nodes
        .iter()
        .map(|x| {
            (
                (x[0] * 1e8).round() as i64,
                (x[1] * 1e8).round() as i64,
                (x[2] * 1e8).round() as i64,
            )
        })
        .collect();
    keys.sort_unstable();
    let before = keys.len();
    keys.dedup();
    assert_eq!(
        before,
        keys.len(),
        "coincident nodes: the seam is not glued"
    );
}

/// Bored shaft without threads between its bearings, a lateral force at mid-span: axis
/// deflection vs Timoshenko (bending + shear) for a simply supported beam.
#[test]
fn worm_shaft_bends_as_a_timoshenko_beam() {
    let g = example("gear-1x40-design.toml");
    let geo = Geometry::build(&g).unwrap();
    // The worm's root radius (the section lattice follows its thread foot).
    let r = g.worm.root_radius;
    let span = 0.3;
    let b = WormBody {
        root_radius: r,
        tip_radius: g.worm.tip_radius,
        shaft_radius: r,
        body_half_length: -1.0,
        bearings: [-0.5 * span, 0.5 * span],
    };
    let deflection = |s: &WormMeshSettings| {
        let m = worm_mesh(&geo.worm, Flank::Left, &b, s);
        // Load: 1 kN along -y spread over the surface nodes nearest to the mid plane (one per
        // half-layer), measured on the bore nodes there.
        let plane = |radius: f64| -> Vec<usize> {
            let mut best: Vec<Option<(f64, usize)>> = vec![None; m.half_layers];
            for (i, x) in m.mesh.nodes.iter().enumerate() {
                let rho = (x[1] * x[1] + x[2] * x[2]).sqrt();
                if (rho - radius).abs() > 1e-9 {
                    continue;
                }
                let phi = x[2].atan2(x[1]);
                let li = (((phi + PI) / (2.0 * PI) * m.half_layers as f64).round() as usize)
                    % m.half_layers;
                if best[li].is_none_or(|(d, _)| x[0].abs() < d) {
                    best[li] = Some((x[0].abs(), i));
                }
            }
            best.into_iter().flatten().map(|(_, i)| i).collect()
        };
        let surface = plane(r);
        let bore = plane(0.25 * r);
        let f = 1000.0;
        let loads: Vec<Load> = surface
            .iter()
            .map(|&n| (n, 1, -f / surface.len() as f64))
            .collect();
        let u = &worm_displacements(&m, &b, &STEEL, &[loads]).unwrap()[0];
        -bore.iter().map(|&n| u[n][1]).sum::<f64>() / bore.len() as f64 / f
    };
    let ri = 0.25 * r;
    let i = PI / 4.0 * (r.powi(4) - ri.powi(4));
    let area = PI * (r * r - ri * ri);
    let nu = STEEL.poisson_ratio;
    let shear_modulus = STEEL.youngs_modulus / (2.0 * (1.0 + nu));
    // Shear coefficient of a thick-walled tube (Cowper): m = ri / r.
    let mm = ri / r;
    let mm2 = mm * mm;
    let kappa = 6.0 * (1.0 + nu) * (1.0 + mm2).powi(2)
        / ((7.0 + 6.0 * nu) * (1.0 + mm2).powi(2) + (20.0 + 12.0 * nu) * mm2);
    let beam = span.powi(3) / (48.0 * STEEL.youngs_modulus * i)
        + span / (4.0 * kappa * shear_modulus * area);
    let ours = deflection(&settings(1));
    eprintln!(
        "shaft mid-span compliance: FE {ours:.5e} m/N, Timoshenko {beam:.5e} m/N ({:+.2} %)",
        100.0 * (ours / beam - 1.0)
    );
    assert!((ours / beam - 1.0).abs() < 0.01, "{ours:e} vs {beam:e}");
}

#[test]
#[ignore = "heavy validation: scripts/validate-heavy runs it"]
fn worm_bending_coefficients_match_the_fe_off_the_fit_grid() {
    // MODEL §5.5 step 5 at the worm's 5 x 13 points (least-squares fit on the lattice's corner
    // nodes of the zone): FE vs fitted coefficients between points midway between fit points.
    let q2 = 13;
    let (geo, b, model, m) = design_worm_fit(5, q2);
    // Reciprocity (Maxwell-Betti): the same-thread core is symmetric up to round-off.
    let k = model.basis.len();
    let (mut asym, mut scale) = (0.0f64, 0.0f64);
    for i in 0..k {
        for j in 0..k {
            asym = asym.max((model.same[(i, j)] - model.same[(j, i)]).abs());
            scale = scale.max(model.same[(i, j)].abs());
        }
    }
    assert!(asym < 1e-8 * scale, "{asym:e} vs {scale:e}");
    // Off-grid points of the central thread's loaded flank (inside the fitted zone).
    let theta_m = model.theta_m;
    // Midway between fit points across the width, at the fit heights (corners of the lattice).
    let picks: Vec<usize> = [(0usize, 0usize), (1, 3), (2, 1), (3, 4), (4, 5)]
        .iter()
        .map(|&(a, c)| {
            (
                0.1 + 0.8 * a as f64 / 4.0,
                2.0 * (c.min(q2 - 2) as f64 + 0.5) / (q2 - 1) as f64 - 1.0,
            )
        })
        .collect::<Vec<_>>()
        .iter()
        .map(|&(rt, wt): &(f64, f64)| nearest_flank_node(&m, &b, (rt, wt * theta_m), true))
        .collect();
    let (normals, bend) = bending_at(&geo, &m, &b, &picks);
    let point = |n: usize| {
        let x = m.mesh.nodes[n];
        nalgebra::Vector3::new(x[0], x[1], x[2])
    };
    let mut worst = 0.0f64;
    let mut umax = 0.0f64;
    for (a, &na) in picks.iter().enumerate() {
        for (c, _) in picks.iter().enumerate() {
            let d = bend[c][a];
            let fe = -(d[0] * normals[a][0] + d[1] * normals[a][1] + d[2] * normals[a][2]);
            let fit = model.basis.coefficient(
                &model.same,
                model.coordinates(&point(na)),
                model.coordinates(&point(picks[c])),
            );
            umax = umax.max(fe.abs());
            worst = worst.max((fit - fe).abs());
        }
    }
    eprintln!(
        "worm bending off the fit grid (5 x {q2}): worst error {:.2} % of the largest ({umax:.3e} m/N)",
        100.0 * worst / umax
    );
    assert!(worst < 0.05 * umax);
}

/// The design case's worm: its geometry, body, bending model at q1 x q2 fit points, and the FE
/// mesh of the thread lattice that model was fitted on (MODEL §5.5).
fn design_worm_fit(
    q1: usize,
    q2: usize,
) -> (
    Geometry,
    WormBody,
    WormBending,
    wormwear::bending::worm_mesh::WormMesh,
) {
    let g = example("gear-1x40-design.toml");
    let geo = Geometry::build(&g).unwrap();
    let (b, s) = (body(&g), settings(1));
    let model = WormBending::build(&g, &geo, &b, &s, q1, q2).unwrap();
    let lattice = WormLattice::aligned(&s, model.theta_m, q1, q2);
    let m = worm_mesh_on(&geo.worm, Flank::Left, &b, &s, &lattice);
    (geo, b, model, m)
}

/// The central thread's loaded-flank node nearest the point at height share rt of the thread
/// (0 root, 1 tip) and polar angle phi (rad); `corners`: the lattice's corner nodes only.
fn nearest_flank_node(
    m: &wormwear::bending::worm_mesh::WormMesh,
    b: &WormBody,
    (rt, phi): (f64, f64),
    corners: bool,
) -> usize {
    let rho = b.root_radius + (b.tip_radius - b.root_radius) * rt;
    m.loaded[1]
        .iter()
        .filter(|f| !corners || (f.0 % 2 == 0 && f.1 % 2 == 0))
        .map(|&(_, _, n)| {
            let x = m.mesh.nodes[n];
            let rn = (x[1] * x[1] + x[2] * x[2]).sqrt();
            let d = (rn - rho).powi(2) + (rho * (x[2].atan2(x[1]) - phi)).powi(2);
            (d, n)
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .unwrap()
        .1
}

/// The outward normals at `picks` (loaded-flank nodes) and the FE bending displacements of
/// every pick under a unit normal load at each (MODEL §5.5 step 2), m/N.
fn bending_at(
    geo: &Geometry,
    m: &wormwear::bending::worm_mesh::WormMesh,
    b: &WormBody,
    picks: &[usize],
) -> (Vec<nalgebra::Vector3<f64>>, Vec<Vec<[f64; 3]>>) {
    let normals: Vec<nalgebra::Vector3<f64>> = picks
        .iter()
        .map(|&n| {
            let x = m.mesh.nodes[n];
            geo.worm.outward_normal(Flank::Left, x[1], x[2])
        })
        .collect();
    let loads: Vec<_> = picks.iter().copied().zip(normals.iter().copied()).collect();
    let bend = worm_bending_displacements(m, b, &STEEL, &loads, picks).unwrap();
    (normals, bend)
}

#[test]
#[ignore = "heavy validation: scripts/validate-heavy runs it"]
fn worm_bending_holds_at_the_thread_root_and_tip_beyond_the_fit_zone() {
    // MODEL §5.5 fits the worm between r_f1 + 0.1 H and r_a1 - 0.1 H, but the wheel's contact
    // reaches the worm's tip (its edge carries the flow pressure), where the LTCA extrapolates
    // the height monomials. At the default 5 points the fitted self-compliance at the root and
    // tip rows (mid-zone) stays within 10 % of the FE; with more points the extrapolation
    // grows (session 67: +28 % at the tip with 7, +152 % with 9, which is what moved TE
    // peak-to-peak by +8.5 % and +36 %), so 7 and 9 are printed, not checked.
    for q1 in [5usize, 7, 9] {
        let (geo, b, model, m) = design_worm_fit(q1, 13);
        let picks = [0.0, 1.0].map(|rt| nearest_flank_node(&m, &b, (rt, 0.0), false));
        let (normals, bend) = bending_at(&geo, &m, &b, &picks);
        let errors: Vec<f64> = (0..2)
            .map(|a| {
                let d = bend[a][a];
                let fe = -(d[0] * normals[a][0] + d[1] * normals[a][1] + d[2] * normals[a][2]);
                let x = m.mesh.nodes[picks[a]];
                let c = model.coordinates(&nalgebra::Vector3::new(x[0], x[1], x[2]));
                model.basis.coefficient(&model.same, c, c) / fe - 1.0
            })
            .collect();
        eprintln!(
            "worm {q1} x 13 height points: fitted self-compliance against the FE at the root row \
             {:+.1} %, at the tip row {:+.1} %",
            100.0 * errors[0],
            100.0 * errors[1]
        );
        if q1 == 5 {
            assert!(errors.iter().all(|e| e.abs() < 0.1), "{errors:?}");
        }
        // The model's own check of the same rows, from the fit's factorisation (the warning's
        // numbers), agrees with this separate solve.
        for (own, here) in model.edge_fit_errors.iter().zip(&errors) {
            assert!((own - here).abs() < 1e-6, "{own} vs {here}");
        }
    }
}

#[test]
fn the_mesh_point_compliance_lies_between_the_threaded_bodys_root_and_tip_shafts() {
    // The worm of the design case under a lateral force on its loaded flank at the mesh point
    // (MODEL §9.1), the axis read in the mesh plane, against the unit-load integral of a
    // stepped Timoshenko shaft between the bearings: the shaft section beyond the threaded
    // body, and over the body a solid section of the root radius (the threads left out: an
    // upper bound of the compliance) or of the tip radius (the threads as solid: a lower
    // bound); all with the model's bore (a quarter of the shaft radius) and the thick tube's
    // shear coefficient (Cowper).
    let g = example("gear-1x40-design.toml");
    let geo = Geometry::build(&g).unwrap();
    let (c, _) = wormwear::bending::worm_deflection::compliance_in(&g, &geo, None).unwrap();
    let root = stepped_shaft_compliance(&g, g.worm.root_radius);
    let tip = stepped_shaft_compliance(&g, g.worm.tip_radius);
    for (axis, name) in [(1, "radial (y)"), (2, "tangential (z)")] {
        let fe = c.columns[axis][axis];
        eprintln!(
            "{name}: FE {fe:.5e} m/N; stepped shafts: root body {root:.5e} ({:+.2} %), tip body {tip:.5e} m/N",
            100.0 * (fe / root - 1.0)
        );
        assert!(
            tip < fe && fe < root,
            "{name}: {fe:e} outside [{tip:e}, {root:e}]"
        );
    }
    // A lateral force displaces the axis laterally: the axial response is small beside it.
    assert!(c.columns[1][0].abs() < 0.01 * c.columns[1][1]);
}

/// Lateral compliance at x1 = 0 of the worm's shaft between its bearings (unit-load integral
/// of the bending moment and shear force, Timoshenko): radius `body` over the threaded body,
/// the shaft radius beyond, both bored to a quarter of the shaft radius, m/N.
fn stepped_shaft_compliance(g: &GearSet, body: f64) -> f64 {
    let e = g.worm_material.youngs_modulus;
    let nu = g.worm_material.poisson_ratio;
    let shear_modulus = e / (2.0 * (1.0 + nu));
    let [b1, b2] = g.bending.worm_bearings;
    let half_body = 0.5 * g.bending.worm_body_length;
    let shaft = g.bending.worm_shaft_radius.min(g.worm.root_radius);
    let bore = 0.25 * shaft;
    let section = |x: f64| {
        let r = if x.abs() <= half_body { body } else { shaft };
        let m2 = (bore / r).powi(2);
        let kappa = 6.0 * (1.0 + nu) * (1.0 + m2).powi(2)
            / ((7.0 + 6.0 * nu) * (1.0 + m2).powi(2) + (20.0 + 12.0 * nu) * m2);
        (
            PI / 4.0 * (r.powi(4) - bore.powi(4)),
            kappa * PI * (r * r - bore * bore),
        )
    };
    let (a, l) = (-b1, b2 - b1);
    let n = 100_000;
    let dx = l / n as f64;
    (0..n)
        .map(|k| {
            let x = b1 + (k as f64 + 0.5) * dx;
            // Unit load at x = 0: bending moment and shear force.
            let (m, v) = if x <= 0.0 {
                ((l - a) / l * (x - b1), (l - a) / l)
            } else {
                (a / l * (b2 - x), a / l)
            };
            let (i, shear_area) = section(x);
            (m * m / (e * i) + v * v / (shear_modulus * shear_area)) * dx
        })
        .sum()
}
