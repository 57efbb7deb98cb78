//! Friction, mesh loss and efficiency from the loaded contact (MODEL §13) on the design gear:
//! the friction's power is the power of its moments about the two axes (energy), no friction
//! leaves no loss, and the contact's efficiency beside ISO/TR 14521's.

use crate::common;

use wormwear::friction::{heat_balance, MeshContacts};
use wormwear::geometry::{Geometry, WheelFlank};
use wormwear::input::{self, BendingKind, FrictionLaw, GearSet};
use wormwear::kinematics::{self, material_velocities};
use wormwear::ltca;

fn design() -> GearSet {
    let mut g = common::example("gear-1x40-design.toml");
    g.bending.kind = BendingKind::None;
    g
}

/// The friction power density gathered on the flank's grid, integrated over it, W.
fn on_flank(friction: &wormwear::friction::MeshFriction, wf: &WheelFlank) -> f64 {
    friction
        .flank_power_density
        .iter()
        .zip(&wf.cell_area)
        .map(|(d, a)| d * a)
        .sum()
}

#[test]
fn the_friction_loss_is_the_power_of_its_moments_about_the_worm_and_wheel_axes() {
    let g = design();
    let geo = Geometry::build(&g).unwrap();
    let tca = kinematics::analyse(&g, &geo).unwrap();
    let l = ltca::analyse(&g, &geo, &tca).unwrap();
    let contacts = MeshContacts::new(&g, &geo, &tca, &l);
    let friction = contacts.friction(&g.lubricant, &g.friction);
    // Friction on the wheel at a cell: -mu p S along the sliding velocity Vg = V2 - V1; on
    // the worm the opposite. The power it takes is minus the power of these forces on the
    // moving bodies, from their moments: spin (q x f_worm)_x about the worm axis (+x1 for
    // the worm's physical spin, MODEL §2.1) and -omega2 (p x f_wheel)_z about the wheel's
    // (the wheel turns about -z2 at theta1_dot z1 / z2, MODEL §4.5), p the point in the
    // wheel frame.
    let spin = geo.worm.hand_sign() * g.conditions.worm_speed;
    let omega2 = g.conditions.worm_speed / g.ratio();
    let mut moments = vec![0.0; l.positions.len()];
    for &(n, k, mu, _) in &friction.cells {
        let pr = &l.positions[n];
        let c = &pr.cells[k].cell;
        let v = material_velocities(
            &c.centre,
            &geo.worm,
            &g.operating,
            g.conditions.worm_speed,
            g.ratio(),
        );
        let vg = nalgebra::Vector3::from(v.sliding);
        let f_wheel = -vg.normalize() * (mu * pr.pressure[k] * c.area());
        let p = g.operating.worm_to_wheel(&c.centre);
        let f_wheel_frame = g.operating.vector_worm_to_wheel(&f_wheel);
        let worm_power = spin * c.centre.cross(&(-f_wheel)).x;
        let wheel_power = -omega2 * p.cross(&f_wheel_frame).z;
        moments[n] -= worm_power + wheel_power;
    }
    for (n, (by_moments, loss)) in moments.iter().zip(&friction.position_loss_w).enumerate() {
        assert!(
            (by_moments - loss).abs() <= 1e-9 * loss,
            "position {n}: {by_moments} W from the moments, {loss} W from mu p |vg| S"
        );
    }
    assert!(friction.mesh_loss_w > 0.0);
    // Gathered on the flank's grid, the power density integrates to the mesh loss.
    let wf = geo.wheel_flank(tca.loaded_flank);
    let on_flank = on_flank(&friction, wf);
    assert!(
        (on_flank / friction.mesh_loss_w - 1.0).abs() < 1e-12,
        "{on_flank} W on the flank"
    );
}

#[test]
fn without_friction_there_is_no_loss_and_the_mesh_efficiency_is_one() {
    // The frictionless limit of the transmitted torque (MODEL §5.2): with no friction the
    // pressures carry T2 = u T1 and nothing is lost.
    let mut g = design();
    let frictionless = FrictionLaw {
        boundary: 0.0,
        limiting_shear: 0.0,
        ..g.friction
    };
    g.friction = frictionless;
    let geo = Geometry::build(&g).unwrap();
    let tca = kinematics::analyse(&g, &geo).unwrap();
    let l = ltca::analyse(&g, &geo, &tca).unwrap();
    let contacts = MeshContacts::new(&g, &geo, &tca, &l);
    let t = heat_balance(&contacts, &g.lubricant, &frictionless, &g.housing, 0.0).unwrap();
    assert_eq!(t.friction.mesh_loss_w, 0.0);
    assert_eq!(t.efficiency.mesh_efficiency, 1.0);
    // The output power is the loaded analysis' wheel torque at the wheel speed, and the
    // frictionless analysis balances the worm's power with it (MODEL §5.2).
    let p1 = l.worm_torque * g.conditions.worm_speed;
    assert!(
        (t.efficiency.output_power_w / p1 - 1.0).abs() < 0.01,
        "{} W vs {p1} W",
        t.efficiency.output_power_w
    );
}

#[test]
fn the_contacts_efficiency_of_the_reference_gears_beside_iso_tr_14521() {
    // Not a bound: the model's figure and the standard's side by side (VALIDATION.md). Both
    // must be efficiencies, and the contact's loss must grow with the roughness.
    for name in ["gear-1x40-design.toml", "gear-k-2x25.toml"] {
        let mut g = common::example(name);
        g.bending.kind = BendingKind::None;
        let geo = Geometry::build(&g).unwrap();
        let tca = kinematics::analyse(&g, &geo).unwrap();
        let l = ltca::analyse(&g, &geo, &tca).unwrap();
        let contacts = MeshContacts::new(&g, &geo, &tca, &l);
        let iso = wormwear::rating::rate(&g);
        let ours = contacts.friction(&g.lubricant, &g.friction);
        let smooth = input::Lubricant {
            composite_roughness: 0.2e-6,
            running_in: None,
            ..g.lubricant.clone()
        };
        let smoother = contacts.friction(&smooth, &g.friction);
        let eta = |loss: f64| contacts.output_power / (contacts.output_power + loss);
        eprintln!(
            "{name}: mesh efficiency ISO/TR 14521 {:.4} (mu {:.4}); contact {:.4} (mu {:.4}, \
             asperity share {:.2}); with R_q 0.2 um {:.4} (mu {:.4})",
            iso.mesh_efficiency,
            iso.friction_coefficient,
            eta(ours.mesh_loss_w),
            ours.mean_coefficient,
            ours.asperity_share,
            eta(smoother.mesh_loss_w),
            smoother.mean_coefficient
        );
        assert!(eta(ours.mesh_loss_w) > 0.0 && eta(ours.mesh_loss_w) < 1.0);
        assert!(smoother.mesh_loss_w < ours.mesh_loss_w);
        assert!(smoother.asperity_share < ours.asperity_share);
    }
}

#[test]
fn a_life_with_the_heat_balance_holds_it_at_every_state_and_the_film_follows_the_oil() {
    // The design gear in a forced-air housing (so that a steady temperature exists), four
    // fixed steps: at every state the total loss is what the housing rejects at the oil
    // temperature recorded, and that temperature's viscosity is the one the film used; the
    // fixed-temperature life beside it records the lubricant's.
    let mut g = design();
    g.housing = wormwear::validation::study_housing();
    let plan = wormwear::wear::WearPlan {
        step: wormwear::wear::StepControl::Cycles(45_000.0),
        ..wormwear::wear::WearPlan::with_life(180_000.0)
    };
    let bench = common::Bench::new(&g);
    let wf = bench.geo.wheel_flank(bench.tca.loaded_flank);
    // Each state hands its friction to the writers (the maps of the worn flank): the one its
    // record states, whose flank map integrates to its mesh loss.
    let mut views = 0;
    let end = bench
        .simulate(&plan, None, &mut |view| {
            let f = &view.thermal.friction;
            let r = view.state.records.last().unwrap();
            assert_eq!(f.mesh_loss_w, r.friction.mesh_loss_w);
            assert_eq!(view.thermal.oil_temperature_k, r.friction.oil_temperature_k);
            let on_flank = on_flank(f, wf);
            assert!((on_flank / f.mesh_loss_w - 1.0).abs() < 1e-12);
            views += 1;
            Ok(())
        })
        .unwrap();
    assert_eq!(views, end.records.len());
    let conductance = g.housing.heat_transfer * g.housing.area;
    for r in &end.records {
        // P2 from the mesh efficiency and loss, then P_V from the total efficiency.
        let p2 = r.friction.mesh_loss_w * r.friction.mesh_efficiency
            / (1.0 - r.friction.mesh_efficiency);
        let total_loss = p2 * (1.0 / r.friction.total_efficiency - 1.0);
        let rejected = conductance * (r.friction.oil_temperature_k - g.housing.ambient);
        assert!(
            (total_loss - rejected).abs() <= conductance * 0.011,
            "state {}: loss {total_loss} W, rejected {rejected} W at {} K",
            r.step,
            r.friction.oil_temperature_k
        );
        let viscosity = g
            .lubricant
            .at_temperature(r.friction.oil_temperature_k)
            .viscosity;
        assert!((r.friction.viscosity_pa_s / viscosity - 1.0).abs() < 1e-12);
        assert!(r.friction.oil_temperature_k > g.housing.ambient + 1.0);
    }
    let mut fixed = g.clone();
    fixed.housing.balance = false;
    let fixed_end = common::Bench::new(&fixed)
        .simulate(&plan, None, &mut |_| Ok(()))
        .unwrap();
    assert!(fixed_end
        .records
        .iter()
        .all(|r| r.friction.oil_temperature_k == g.lubricant.temperature));
    // A different oil temperature is a different film, hence a different wear.
    let (a, b) = (
        end.records.last().unwrap(),
        fixed_end.records.last().unwrap(),
    );
    assert_ne!(a.backlash_increase_m, b.backlash_increase_m);
}

#[test]
#[ignore = "heavy validation: scripts/validate-heavy runs it"]
fn the_mesh_loss_converges_as_the_local_contact_mesh_is_refined() {
    // 11, 22 and 41 cells across the contact line: the loss (a sum of mu p |v_g| S, whose
    // pressures converge as patch means, VALIDATION.md "Mesh convergence") moves by 1.1 % and
    // then by 0.4 % on this gear; the bound is 2 % between the two finer meshes.
    let loss = |columns: usize| {
        let mut g = design();
        g.analysis.contact_columns = columns;
        let geo = Geometry::build(&g).unwrap();
        let tca = kinematics::analyse(&g, &geo).unwrap();
        let l = ltca::analyse(&g, &geo, &tca).unwrap();
        MeshContacts::new(&g, &geo, &tca, &l).mesh_loss(&g.lubricant, &g.friction)
    };
    let (coarse, fine, finest) = (loss(11), loss(22), loss(41));
    eprintln!("mesh loss: 11 columns {coarse:.1} W, 22 {fine:.1} W, 41 {finest:.1} W");
    assert!((finest / fine - 1.0).abs() < 0.02, "{fine} W -> {finest} W");
}

/// The validation study's settings over the repository's examples (the whole study).
fn study_settings() -> wormwear::validation::Settings {
    wormwear::validation::Settings {
        examples: std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples"),
        quick: false,
        only: Vec::new(),
    }
}

/// The contact's mean friction and mesh efficiency beside ISO/TR 14521's rig-fitted mu_0T
/// (MODEL §9, §13 validation (1)) on the 1/40 and the K 2/25 gears, worm speeds giving sliding
/// speeds from 0.3 to 8 m/s, one set of inputs (the examples' cited defaults; the standard's
/// factors Y at 1: mu_0T itself). Prints the table of VALIDATION.md (e); asserts the physics
/// that does not depend on the constants: the friction falls with the sliding speed as
/// ISO's does (the film grows), the asperities' share falls with it, and the torques carry
/// the contact's own efficiency. Run: cargo test --release -p wormwear --test suite friction:: -- --ignored
#[test]
#[ignore = "heavy validation: scripts/validate-heavy runs it"]
fn the_contacts_friction_over_sliding_speeds_beside_iso_tr_14521() {
    use wormwear::validation::{self, friction};
    let settings = study_settings();
    let points = friction::over_speeds(&settings, &friction::Store::new(None)).unwrap();
    print!("{}", friction::table(&points));
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(validation::FIGURES);
    friction::charts(&points, &dir).unwrap();
    println!("charts in {}", dir.display());
    for gear in points.chunks(friction::SPEED_STUDY[0].1.len()) {
        for pair in gear.windows(2) {
            // The friction and the asperities' share fall with the sliding speed.
            assert!(pair[1].friction < pair[0].friction, "{pair:?}");
            assert!(pair[1].asperity_share < pair[0].asperity_share, "{pair:?}");
        }
        // The rating's efficiency with the gear's factors Y is the closed form at mu_0T times
        // their product (two computations of ISO's efficiency, the rating's and the study's).
        let file = format!("{}.toml", gear[0].gear);
        let g = validation::example(&settings, &file).unwrap();
        let gamma = g.worm.lead_angle();
        for p in gear {
            let mu = p.iso_friction * g.rating.friction_factor;
            let closed = gamma.tan() / (gamma + mu.atan()).tan();
            assert!(
                (p.iso_efficiency_with_factors - closed).abs() < 1e-9,
                "{p:?}"
            );
        }
        for p in gear {
            // The torques the loaded analysis carries are the contact's own efficiency.
            assert!(
                (p.torque_efficiency / p.mesh_efficiency - 1.0).abs() < 0.005,
                "{p:?}"
            );
        }
    }
}

/// The speed study over the film's limiting shear Lambda (MODEL §13; VALIDATION.md (e)):
/// prints the window table; asserts what Lambda must do whatever the reference: on every gear
/// at every speed (and case C) the friction rises and the efficiency falls with Lambda, and at
/// the highest speed, where the film shears at its limit on nearly all the loaded flank, the
/// mean friction moves by the film's share of the load times the change of Lambda. Run:
/// cargo test --release -p wormwear --test suite friction:: -- --ignored
#[test]
#[ignore = "heavy validation: scripts/validate-heavy runs it"]
fn the_film_limiting_shear_sets_the_friction_at_speed() {
    use wormwear::validation::friction;
    let rows =
        friction::limiting_shear_window(&study_settings(), &friction::Store::new(None)).unwrap();
    print!("{}", friction::limiting_shear_table(&rows));
    for pair in rows.windows(2) {
        let (low, high) = (&pair[0], &pair[1]);
        assert!(high.limiting_shear > low.limiting_shear);
        assert!(high.case_c_efficiency < low.case_c_efficiency, "{pair:?}");
        for (a, b) in low.points.iter().zip(&high.points) {
            assert!(
                b.friction > a.friction && b.mesh_efficiency < a.mesh_efficiency,
                "{a:?} -> {b:?}"
            );
        }
    }
    let (first, last) = (&rows[0], &rows[rows.len() - 1]);
    let step = last.limiting_shear - first.limiting_shear;
    let per_gear = friction::SPEED_STUDY[0].1.len();
    for (a, b) in first
        .points
        .iter()
        .zip(&last.points)
        .skip(per_gear - 1)
        .step_by(per_gear)
    {
        let film = 1.0 - 0.5 * (a.asperity_share + b.asperity_share);
        let ratio = (b.friction - a.friction) / (film * step);
        eprintln!(
            "{} at {} rpm: friction change / film share x Lambda change {ratio:.3}",
            a.gear, a.worm_speed_rpm
        );
        assert!((ratio - 1.0).abs() < 0.05, "{a:?} -> {b:?}");
    }
}

/// NaN cells of a flank field inside its finite extent on each face column (k = j ni + i).
fn interior_holes(field: &[f64], ni: usize) -> usize {
    field
        .chunks(ni)
        .map(|column| {
            let loaded: Vec<usize> = (0..ni).filter(|&i| column[i].is_finite()).collect();
            match (loaded.first(), loaded.last()) {
                (Some(&a), Some(&b)) => (a..=b).filter(|&i| !column[i].is_finite()).count(),
                _ => 0,
            }
        })
        .sum()
}

#[test]
fn the_friction_maps_have_no_holes_between_positions_and_follow_the_passage() {
    // The friction maps gather the positions' loaded cells on the flank's grid. At their
    // centres alone, a grid finer than the band's travel between positions showed rows of
    // "no contact" inside the loaded flank (the worn design gear at 180 000 cycles, issue 59;
    // here the unworn one on a fine grid). Each cell now stands for the strip the band
    // sweeps to the instants before and after it (MODEL §5.6's passage): no holes, the map
    // still integrates to the mesh loss, and it hardly moves when the positions double.
    let mut results = Vec::new();
    for (height, face, positions) in [(80, 120, 20), (80, 120, 40)] {
        let mut g = design();
        g.analysis.flank_cells_height = height;
        g.analysis.flank_cells_face = face;
        g.analysis.positions = positions;
        let geo = Geometry::build(&g).unwrap();
        let tca = kinematics::analyse(&g, &geo).unwrap();
        let l = ltca::analyse(&g, &geo, &tca).unwrap();
        let friction = MeshContacts::new(&g, &geo, &tca, &l).friction(&g.lubricant, &g.friction);
        let wf = geo.wheel_flank(tca.loaded_flank);
        let holes = interior_holes(&friction.flank_coefficient, wf.cells_height);
        let on_flank = on_flank(&friction, wf);
        eprintln!(
            "{height} x {face} cells, {positions} positions: {holes} holes, mesh loss {:.1} W",
            friction.mesh_loss_w
        );
        assert_eq!(holes, 0);
        assert!((on_flank / friction.mesh_loss_w - 1.0).abs() < 1e-12);
        results.push((friction.flank_power_density, friction.mesh_loss_w));
    }
    // The power density's change from 20 to 40 positions, as a share of the map (L1).
    let (a, b) = (&results[0], &results[1]);
    let change: f64 =
        a.0.iter()
            .zip(&b.0)
            .map(|(x, y)| (x - y).abs())
            .sum::<f64>()
            / a.0.iter().map(|x| x.abs()).sum::<f64>();
    eprintln!(
        "power density map: {:.1} % L1 change from 20 to 40 positions",
        100.0 * change
    );
    assert!(change < 0.1, "{change}");
}
