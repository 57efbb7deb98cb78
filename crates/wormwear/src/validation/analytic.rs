//! Section (a) of the validation: the model's components against analytic solutions and
//! invariants. Each check computes a figure with the library and its independent reference;
//! the tests named in [`Check::test`] assert the same computations against the same bounds,
//! so the table in VALIDATION.md is what the suite checks, with today's numbers.

use crate::contact::{ContactCell, ElasticPair};
use crate::ltca::solver::{solve, Block, Problem, SolverKind, SolverSettings};
use nalgebra::Vector3;
use std::f64::consts::PI;

/// One check: what, the computed figure and its reference (text with units), the relative
/// error, the bound the test accepts, and the test.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Check {
    pub what: String,
    pub computed: String,
    pub reference: String,
    pub error: f64,
    pub bound: f64,
    pub test: String,
}

/// Steel worm on bronze wheel (MODEL §11).
pub fn steel_on_bronze() -> ElasticPair {
    ElasticPair::new(203e9, 0.29, 110e9, 0.29)
}

/// Flat cells on a regular nx x ny grid of cell size (2 hx, 2 hy) centred at the origin.
pub fn flat_cells(nx: usize, ny: usize, hx: f64, hy: f64) -> Vec<ContactCell> {
    let mut cells = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let x = (i as f64 - (nx as f64 - 1.0) / 2.0) * 2.0 * hx;
            let y = (j as f64 - (ny as f64 - 1.0) / 2.0) * 2.0 * hy;
            cells.push(ContactCell {
                centre: Vector3::new(x, y, 0.0),
                normal: Vector3::z(),
                axis_nu: Vector3::x(),
                axis_zeta: Vector3::y(),
                half_nu: hx,
                half_zeta: hy,
            });
        }
    }
    cells
}

/// Contact problem in forces on flat cells: K_ij = C_ij / S_j (displacement per unit force;
/// [`Block::influence`]: by FFT on a lattice of many cells),
/// separations from `gap` at the cell centres, total load `load` (N).
pub fn flat_problem(
    cells: &[ContactCell],
    gap: impl Fn(&Vector3<f64>) -> f64,
    load: f64,
) -> Problem {
    let n = cells.len();
    let p = steel_on_bronze();
    Problem {
        blocks: vec![Block::influence(0, &p, cells, &vec![1.0; n])],
        low_rank: None,
        separation: cells.iter().map(|c| gap(&c.centre)).collect(),
        load,
        upper: None,
    }
}

/// Sphere (R 10 mm, 100 N) on a plane with the given solver: (peak pressure, contact radius
/// from the second moment of the load, approach) and Hertz's (p0, a, a^2 / R).
pub fn hertz_sphere(kind: SolverKind) -> ([f64; 3], [f64; 3]) {
    let (radius, load) = (10e-3, 100.0);
    let e_star = steel_on_bronze().effective_modulus;
    let a = (3.0 * load * radius / (4.0 * e_star)).cbrt();
    let p0 = 3.0 * load / (2.0 * PI * a * a);
    let n = 40;
    let h = 1.4 * a / n as f64;
    let cells = flat_cells(n, n, h, h);
    let pb = flat_problem(&cells, |c| (c.x * c.x + c.y * c.y) / (2.0 * radius), load);
    let settings = SolverSettings {
        kind,
        tolerance: 1e-9,
        max_iterations: 200_000,
    };
    let Ok(sol) = solve(&pb, &settings, None) else {
        return ([f64::NAN; 3], [p0, a, a * a / radius]);
    };
    let pmax = sol.q.iter().copied().fold(0.0, f64::max) / cells[0].area();
    let m2: f64 = sol
        .q
        .iter()
        .zip(&cells)
        .map(|(q, c)| q * (c.centre.x.powi(2) + c.centre.y.powi(2)))
        .sum();
    (
        [pmax, (2.5 * m2 / load).sqrt(), sol.approach],
        [p0, a, a * a / radius],
    )
}

/// Long cylinder (R 10 mm, 2000 N over 20 mm) on a plane, central row: (peak pressure,
/// half-width from the second moment) and plane-strain Hertz for the row's own line load.
pub fn hertz_cylinder() -> ([f64; 2], [f64; 2]) {
    let (radius, load) = (10e-3, 2000.0);
    let e_star = steel_on_bronze().effective_modulus;
    let length = 20e-3;
    let b = (4.0 * load / length * radius / (PI * e_star)).sqrt();
    let (nx, ny) = (34, 21);
    let hx = 1.4 * b / nx as f64;
    let hy = length / (2.0 * ny as f64);
    let cells = flat_cells(nx, ny, hx, hy);
    let pb = flat_problem(&cells, |c| c.x * c.x / (2.0 * radius), load);
    let Ok(sol) = solve(&pb, &SolverSettings::default(), None) else {
        return ([f64::NAN; 2], [f64::NAN; 2]);
    };
    let row = ny / 2;
    let q_row: Vec<(f64, f64)> = (0..nx)
        .map(|i| (cells[row * nx + i].centre.x, sol.q[row * nx + i]))
        .collect();
    let wc: f64 = q_row.iter().map(|(_, q)| q).sum::<f64>() / (2.0 * hy);
    let bc = (4.0 * wc * radius / (PI * e_star)).sqrt();
    let p0c = 2.0 * wc / (PI * bc);
    let pmax = q_row.iter().map(|(_, q)| *q).fold(0.0, f64::max) / cells[0].area();
    let m2: f64 = q_row.iter().map(|(x, q)| q * x * x).sum::<f64>()
        / q_row.iter().map(|(_, q)| q).sum::<f64>();
    ([pmax, 2.0 * m2.sqrt()], [p0c, bc])
}

/// Martin's rigid-isoviscous film h = 4.9 eta0 u_m R / w against Moes-Venner at light load,
/// no pressure-viscosity, stiff bodies: (Moes-Venner, Martin), m.
pub fn martin_film() -> (f64, f64) {
    let lub = crate::input::Lubricant {
        name: String::new(),
        viscosity: 0.227,
        pressure_viscosity: 0.0,
        thermo_viscosity: 3200.0,
        thermal_conductivity: 0.148,
        temperature: 333.0,
        composite_roughness: 1e-6,
        running_in: None,
    };
    let c = crate::lubrication::LineContact {
        radius: 0.02,
        u1: 3.0,
        u2: 1.0,
        line_load: 50.0,
        pressure: 0.0,
    };
    let h = crate::lubrication::min_film_thickness(&lub, 1e15, &c);
    (h, 4.9 * lub.viscosity * 2.0 * 0.02 / 50.0)
}

/// Tip deflection of an FE cantilever against Timoshenko's beam (bending + shear), L/h = 10:
/// (FE, theory), m.
pub fn cantilever() -> (f64, f64) {
    use crate::bending::fe::{box_mesh, solve as fe_solve, Elastic, Load};
    let steel = Elastic {
        youngs_modulus: 210e9,
        poisson_ratio: 0.3,
    };
    let (l, h, b, p) = (0.1, 0.01, 0.01, 100.0);
    let n = (20, 4, 2);
    let (mesh, lattice) = box_mesh((l, h, b), n, |x| x);
    let (mx, my, mz) = (2 * n.0, 2 * n.1, 2 * n.2);
    let mut fixed = Vec::new();
    let mut loads: Vec<Load> = Vec::new();
    // Consistent nodal forces of a uniform traction on 8-node faces: corners -1/12, mid-sides
    // +1/3 of the face force, times the number of faces the node belongs to.
    let face_force = -p / (n.1 * n.2) as f64;
    let faces = |i: usize, count: usize| -> usize {
        if i % 2 == 1 {
            1
        } else {
            [i / 2, i / 2 + 1]
                .iter()
                .filter(|&&f| f >= 1 && f <= count)
                .count()
        }
    };
    let mut centre = None;
    for (k, ijk) in lattice.iter().enumerate() {
        if ijk[0] == 0 {
            for d in 0..3 {
                fixed.push((k, d, 0.0));
            }
        }
        if ijk[0] == mx {
            let corner = ijk[1] % 2 == 0 && ijk[2] % 2 == 0;
            let share = if corner { -1.0 / 12.0 } else { 1.0 / 3.0 };
            let count = (faces(ijk[1], n.1) * faces(ijk[2], n.2)) as f64;
            loads.push((k, 1, face_force * share * count));
            if ijk[1] == my / 2 && ijk[2] == mz / 2 {
                centre = Some(k);
            }
        }
    }
    let (e, v) = (steel.youngs_modulus, steel.poisson_ratio);
    let g = e / (2.0 * (1.0 + v));
    let kappa = 10.0 * (1.0 + v) / (12.0 + 11.0 * v);
    let i = b * h * h * h / 12.0;
    let theory = p * l * l * l / (3.0 * e * i) + p * l / (kappa * g * b * h);
    let fe = match (fe_solve(&mesh, &steel, &fixed, &[loads]), centre) {
        (Ok(u), Some(k)) => -u[0][k][1],
        _ => f64::NAN,
    };
    (fe, theory)
}

fn relative(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

/// Every check of section (a); the gear checks on `design` (the 1/40 design case).
pub fn checks(design: &crate::input::GearSet, quick: bool) -> Vec<Check> {
    let mut out = Vec::new();
    for kind in [SolverKind::ConjugateGradient, SolverKind::FixedPoint] {
        let (got, hertz) = hertz_sphere(kind);
        let name = match kind {
            SolverKind::ConjugateGradient => "conjugate gradient",
            SolverKind::FixedPoint => "fixed point",
        };
        out.push(Check {
            what: format!("Sphere on a plane, peak pressure ({name} solver)"),
            computed: format!("{:.1} MPa", got[0] * 1e-6),
            reference: format!("Hertz {:.1} MPa", hertz[0] * 1e-6),
            error: relative(got[0], hertz[0]),
            bound: 0.02,
            test: "hertz::sphere_on_a_plane_matches_hertz".into(),
        });
        out.push(Check {
            what: format!("Sphere on a plane, contact radius ({name})"),
            computed: format!("{:.4} mm", got[1] * 1e3),
            reference: format!("Hertz {:.4} mm", hertz[1] * 1e3),
            error: relative(got[1], hertz[1]),
            bound: 0.02,
            test: "hertz::sphere_on_a_plane_matches_hertz".into(),
        });
    }
    let (got, hertz) = hertz_cylinder();
    out.push(Check {
        what: "Long cylinder on a plane, peak pressure".into(),
        computed: format!("{:.1} MPa", got[0] * 1e-6),
        reference: format!("Hertz (line contact) {:.1} MPa", hertz[0] * 1e-6),
        error: relative(got[0], hertz[0]),
        bound: 0.02,
        test: "hertz::long_cylinder_on_a_plane_matches_line_contact_hertz".into(),
    });
    out.push(Check {
        what: "Long cylinder on a plane, half-width".into(),
        computed: format!("{:.4} mm", got[1] * 1e3),
        reference: format!("Hertz {:.4} mm", hertz[1] * 1e3),
        error: relative(got[1], hertz[1]),
        bound: 0.02,
        test: "hertz::long_cylinder_on_a_plane_matches_line_contact_hertz".into(),
    });
    let (h, martin) = martin_film();
    out.push(Check {
        what: "Film thickness, rigid-isoviscous limit (Moes-Venner)".into(),
        computed: format!("{:.4} um", h * 1e6),
        reference: format!("Martin {:.4} um", martin * 1e6),
        error: relative(h, martin),
        bound: 1e-3,
        test: "lubrication::tests::rigid_isoviscous_limit_is_martins_solution".into(),
    });
    let (fe, beam) = cantilever();
    out.push(Check {
        what: "FE cantilever (20-node hexahedra), tip deflection, L/h = 10".into(),
        computed: format!("{:.5e} m", fe),
        reference: format!("Timoshenko {:.5e} m", beam),
        error: relative(fe, beam),
        bound: 0.01,
        test: "fe::cantilever_matches_timoshenko_beam_theory".into(),
    });
    out.extend(gear_checks(design, quick));
    out
}

/// Mesh convergence of the pressures at the worm's sharp tip edge (no bending), as the tests
/// named in the rows check it: bounded by the flow pressure (the default, MODEL §5.7), P_max
/// and P_patch from 21 to 41 cells across the line (`plastic.rs`); purely elastic with
/// frictionless pressures (the contact alone), the patch mean from 11 to 41 cells and the raw
/// maximum, which grows (`fidelity.rs`).
fn peak_convergence(
    g: &crate::input::GearSet,
    geo: &crate::geometry::Geometry,
    tca: &crate::kinematics::Tca,
    settings: &crate::ltca::LtcaSettings,
) -> Vec<Check> {
    let mut out = Vec::new();
    let at = |columns: usize, elastic: bool| {
        let mut s = *settings;
        s.columns = columns;
        if elastic {
            s.flow_pressure = f64::INFINITY;
            s.torque_balance = crate::input::TorqueBalance::Frictionless;
        }
        crate::ltca::analyse_with(g, geo, tca, &s, None)
    };
    if let (Ok(mid), Ok(fine)) = (at(21, false), at(41, false)) {
        let test = "plastic::the_plastic_limit_makes_the_peaks_mesh_converged";
        out.push(refinement_check(
            "P_max with the plastic limit (default), 21 -> 41 cells across the line",
            (mid.max_pressure, fine.max_pressure),
            0.05,
            test,
        ));
        out.push(refinement_check(
            "P_patch (0.5 x 1 mm mean) with the plastic limit, 21 -> 41 cells across the line",
            (mid.pressure_patch_max, fine.pressure_patch_max),
            0.05,
            test,
        ));
    }
    if let (Ok(c), Ok(f)) = (at(11, true), at(41, true)) {
        let test = "fidelity::the_patch_pressure_converges_where_the_maximum_does_not";
        out.push(refinement_check(
            "P_patch with the elastic law, frictionless, 11 -> 41 cells across the line",
            (c.pressure_patch_max, f.pressure_patch_max),
            0.03,
            test,
        ));
        out.push(refinement_check(
            "raw P_max with the elastic law, frictionless, 11 -> 41 cells across the line (edge singularity: grows)",
            (c.max_pressure, f.max_pressure),
            f64::NAN,
            test,
        ));
    }
    out
}

/// A pressure of the 1/40 gear (no bending) under refinement, coarse -> fine (Pa), against
/// convergence (ratio 1) with `bound` (NaN: none, it is not expected to converge) and the test
/// that checks it.
fn refinement_check(what: &str, (coarse, fine): (f64, f64), bound: f64, test: &str) -> Check {
    Check {
        what: format!("1/40 (no bending), {what}"),
        computed: format!("{:.0} -> {:.0} MPa", coarse * 1e-6, fine * 1e-6),
        reference: "converged: ratio 1".into(),
        error: relative(fine, coarse),
        bound,
        test: test.into(),
    }
}

/// Checks on the 1/40 gear (design case without bending: these are the contact model's
/// properties): conjugacy, the uniform angular
/// recession (rigid lag), the backlash law of a uniform removal, the mesh-converged pressure.
fn gear_checks(design: &crate::input::GearSet, quick: bool) -> Vec<Check> {
    let mut out = Vec::new();
    let mut g = design.clone();
    g.bending.kind = crate::input::BendingKind::None;
    out.extend(conjugate_pair_check(&g));
    let Ok(geo) = crate::geometry::Geometry::build(&g) else {
        return out;
    };
    let Ok(tca) = crate::kinematics::analyse(&g, &geo) else {
        return out;
    };
    out.push(uniform_removal_check(&g, &geo, &tca));
    out.extend(recession_checks(&g, &geo, &tca, quick));
    out
}

/// Conjugate pair: the worm as its own hob leaves no kinematic error.
fn conjugate_pair_check(g: &crate::input::GearSet) -> Option<Check> {
    let mut conj = g.clone();
    conj.hob = conj.worm.clone();
    let geo = crate::geometry::Geometry::build(&conj).ok()?;
    let tca = crate::kinematics::analyse(&conj, &geo).ok()?;
    let (_, p2p) = tca.kinematic_error_stats();
    Some(Check {
        what: "1/40 conjugate pair (hob = worm): unloaded kinematic error, peak-to-peak".into(),
        computed: format!("{p2p:.2e} rad"),
        reference: "0 (bound: 1e-7 rad)".into(),
        error: p2p,
        bound: 1e-7,
        test: "tca::conjugate_pair_has_no_kinematic_error_and_full_contact_lines".into(),
    })
}

/// Uniform normal removal d: the tangential backlash at r2 opens by d / (cos an cos gamma).
fn uniform_removal_check(
    g: &crate::input::GearSet,
    geo: &crate::geometry::Geometry,
    tca: &crate::kinematics::Tca,
) -> Check {
    let wf = geo.wheel_flank(tca.loaded_flank);
    let backlash = crate::wear::Backlash::new(g, geo, tca);
    let zero = crate::geometry::FlankField::zeros(wf);
    let mut uniform = zero.clone();
    let d = 10e-6;
    uniform.values.fill(d);
    let got = backlash.stats(&uniform).linear_mean_m - backlash.stats(&zero).linear_mean_m;
    let gamma = g.worm.lead_angle();
    let alpha_n = (g.worm.axial_pressure_angle.tan() * gamma.cos()).atan();
    let expected = d / (alpha_n.cos() * gamma.cos());
    Check {
        what: "1/40, backlash of a uniform 10 um removal (tangential at r2)".into(),
        computed: format!("{:.4} um", got * 1e6),
        reference: format!("d / (cos an cos gamma) = {:.4} um", expected * 1e6),
        error: relative(got, expected),
        bound: 0.02,
        test: "wear::uniform_removal_raises_the_tangential_backlash_by_the_normal_depth_over_cos_an_cos_gamma".into(),
    }
}

/// Uniform angular recession delta: pure rigid lag (TE relative to it = unworn TE); then the
/// peak convergence and the pits' depth on the unworn loaded analysis.
fn recession_checks(
    g: &crate::input::GearSet,
    geo: &crate::geometry::Geometry,
    tca: &crate::kinematics::Tca,
    quick: bool,
) -> Vec<Check> {
    let mut out = Vec::new();
    let wf = geo.wheel_flank(tca.loaded_flank);
    let zero = crate::geometry::FlankField::zeros(wf);
    let settings = crate::ltca::LtcaSettings::from_gear(g);
    let delta = 2e-5;
    let mut recession = zero.clone();
    for (k, n) in wf.nodes.iter().enumerate() {
        recession.values[k] =
            delta * crate::kinematics::GapEvaluator::lever(&n.position(), &n.normal_vec());
    }
    let analyses = (
        crate::ltca::analyse_with(g, geo, tca, &settings, None),
        crate::ltca::analyse_worn(g, geo, tca, &settings, None, Some(&recession), None),
    );
    if let (Ok(unworn), Ok(worn)) = analyses {
        let (te0, _) = unworn.te_stats();
        let (te1, _) = worn.te_stats();
        out.push(Check {
            what: "1/40 (no bending), flank worn by a uniform angle delta = 20 urad: TE shift"
                .into(),
            computed: format!("{:.6} urad", (te0 - te1) * 1e6),
            reference: "delta = 20 urad (rigid lag)".into(),
            error: relative(te0 - te1, delta),
            bound: 1e-4,
            test: "fidelity::a_uniform_angular_recession_is_all_rigid_lag".into(),
        });
        // The refinement rows repeat their named tests' analyses at 41 cells across the line;
        // the quick smoke run leaves them to those tests.
        if !quick {
            out.extend(peak_convergence(g, geo, tca, &settings));
        }
        out.push(pit_depth_check(g, geo, tca, &unworn));
    }
    out
}

/// Hertz half-width against the loaded band's on the unworn flank (the pits' depth).
fn pit_depth_check(
    g: &crate::input::GearSet,
    geo: &crate::geometry::Geometry,
    tca: &crate::kinematics::Tca,
    unworn: &crate::ltca::Ltca,
) -> Check {
    let wf = geo.wheel_flank(tca.loaded_flank);
    let cw = crate::wear::per_cycle(g, geo, tca, unworn, crate::input::FilmLoad::LoadedAnalysis);
    let e_star = steel_on_bronze().effective_modulus;
    let mut worst: f64 = 0.0;
    for k in 0..wf.nodes.len() {
        let (w, r) = (cw.line_load.values[k], cw.contact_radius.values[k]);
        if w > 0.0 && r > 0.0 {
            let a = (4.0 * w * r / (PI * e_star)).sqrt();
            worst = worst.max(relative(cw.hertz_half_width.values[k], a));
        }
    }
    Check {
        what: "1/40 (no bending), pit depth: Hertz half-width a = sqrt(4 w R / (pi E*)) at every swept node"
            .into(),
        computed: format!("largest {:.1} um", cw.hertz_half_width.max() * 1e6),
        reference: "the formula with the node's line load and radius".into(),
        error: worst,
        bound: 1e-9,
        test: "fidelity::pits_are_cut_0_78_hertz_half_widths_deep".into(),
    }
}
