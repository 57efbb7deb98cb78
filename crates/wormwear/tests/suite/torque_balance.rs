//! Which torque the loaded analysis carries (MODEL §5.2, §12 n): the friction tractions'
//! moments in the equilibrium. Checked against independent truths: the frictionless limit
//! (T2 = u T1), the power balance T1 omega1 = T2 omega2 + P_Vz at every position, the closed-form
//! efficiency of a screw with uniform friction, T1 -> T2 -> T1, and the mesh loss under a finer
//! contact mesh.

use crate::common;

use wormwear::friction::MeshContacts;
use wormwear::input::{BendingKind, FrictionLaw, GearSet, Torque, TorqueBalance};
use wormwear::ltca::{self, Ltca, LtcaSettings};

/// The design gear without bending (the torque balance does not depend on it).
fn design() -> GearSet {
    let mut g = common::example("gear-1x40-design.toml");
    g.bending.kind = BendingKind::None;
    g
}

fn analyse(g: &GearSet, bench: &common::Bench) -> Ltca {
    ltca::analyse_with(g, &bench.geo, &bench.tca, &LtcaSettings::from_gear(g), None).unwrap()
}

/// The contact's mesh efficiency P2 / (P2 + P_Vz) of `l` from the friction stage (the same
/// local law evaluated on the final pressures).
fn mesh_efficiency(g: &GearSet, bench: &common::Bench, l: &Ltca) -> f64 {
    let contacts = MeshContacts::new(g, &bench.geo, &bench.tca, l);
    let loss = contacts.friction(&g.lubricant, &g.friction).mesh_loss_w;
    contacts.output_power / (contacts.output_power + loss)
}

#[test]
fn the_wheel_carries_u_eta_z_t1_and_the_frictionless_reading_u_t1() {
    let g = design();
    let bench = common::Bench::new(&g);
    let transmitted = analyse(&g, &bench);
    let eta = mesh_efficiency(&g, &bench, &transmitted);
    let u = g.ratio();
    eprintln!(
        "transmitted: T2 {:.1} N m, u eta_z T1 = {:.1} N m (eta_z {eta:.4})",
        transmitted.wheel_torque,
        u * eta * 60.0
    );
    assert!((transmitted.worm_torque / 60.0 - 1.0).abs() < 1e-9);
    assert!(
        (transmitted.wheel_torque / (u * eta * 60.0) - 1.0).abs() < 0.005,
        "{} vs {}",
        transmitted.wheel_torque,
        u * eta * 60.0
    );
    assert!(eta > 0.6 && eta < 0.95, "{eta}");
    // The published reading: frictionless pressures, T2 = u T1 (to the discretisation's
    // power balance), and every tooth loaded 1 / eta_z more.
    let mut f = g.clone();
    f.analysis.torque_balance = TorqueBalance::Frictionless;
    let frictionless = analyse(&f, &bench);
    assert!((frictionless.wheel_torque / 2400.0 - 1.0).abs() < 0.005);
    assert!(frictionless
        .positions
        .iter()
        .all(|p| p.friction_torque == 0.0));
    let load = |l: &Ltca| -> f64 { l.positions.iter().flat_map(|p| &p.tooth_load).sum() };
    let ratio = load(&frictionless) / load(&transmitted);
    assert!(
        (ratio * eta - 1.0).abs() < 0.01,
        "load ratio {ratio}, 1/eta {}",
        1.0 / eta
    );
}

#[test]
fn the_power_balance_holds_at_every_position() {
    // T1 omega1 = T2 omega2 + P_Vz + (the normal forces' power on the relative motion, which
    // the conjugate contact makes zero and the discretisation makes small): the friction's
    // power is the same sum mu f |v_g| whether read from its moments or from the cells.
    let g = design();
    let bench = common::Bench::new(&g);
    let l = analyse(&g, &bench);
    let mut f = g.clone();
    f.analysis.torque_balance = TorqueBalance::Frictionless;
    let frictionless = analyse(&f, &bench);
    let (omega1, u) = (g.conditions.worm_speed, g.ratio());
    for (p, q) in l.positions.iter().zip(&frictionless.positions) {
        let sliding = ltca::cell_sliding(&g, &bench.geo, &p.cells);
        let loss: f64 = p
            .cells
            .iter()
            .zip(&p.pressure)
            .zip(p.friction.iter().zip(&sliding))
            .map(|((c, pr), (mu, s))| mu * pr * c.cell.area() * s.speed)
            .sum();
        assert!(
            (p.friction_torque * omega1 / loss - 1.0).abs() < 1e-6,
            "position {}: {} W vs {loss} W",
            p.position,
            p.friction_torque * omega1
        );
        let balance = (p.wheel_torque * omega1 / u + loss) / (p.worm_torque * omega1) - 1.0;
        let normal = q.wheel_torque / (u * q.worm_torque) - 1.0;
        assert!(
            balance.abs() < 0.01 && (balance - normal).abs() < 0.003,
            "position {}: power balance {balance:e} (frictionless {normal:e})",
            p.position
        );
    }
    assert!(l.power_balance.abs() < 1e-3, "{}", l.power_balance);
    assert!(
        l.warnings
            .iter()
            .all(|w| w.contains("flow pressure") || w.contains("lies on the flank's edges")),
        "{:?}",
        l.warnings
    );
}

#[test]
fn t1_to_t2_to_t1_closes() {
    // One position (the pitch's first), so that the wheel torque given back is that position's
    // own: over several positions, a mean T2 given to each would load each differently from
    // its forward T2, and the efficiency moves with the load (by 2.5 % of its relative change).
    let mut g = design();
    g.analysis.positions = 1;
    let bench = common::Bench::new(&g);
    let forward = analyse(&g, &bench);
    // The same contact mesh both ways: the band across the line is sized from the wheel
    // torque's estimate (u T1 eta_z of ISO/TR 14521 at its base friction when the worm torque
    // is given), so the backward band factor is scaled by the Hertz width's square root of the
    // load.
    let estimate = g.ratio() * 60.0 * wormwear::rating::base_mesh_efficiency(&g);
    let mut back = g.clone();
    back.conditions.torque = Torque::Wheel(forward.wheel_torque);
    back.analysis.contact_band_factor *= (estimate / forward.wheel_torque).sqrt();
    let backward = analyse(&back, &bench);
    eprintln!(
        "T1 60 -> T2 {:.4} -> T1 {:.7}",
        forward.wheel_torque, backward.worm_torque
    );
    assert!((backward.wheel_torque / forward.wheel_torque - 1.0).abs() < 1e-9);
    assert!((backward.worm_torque / 60.0 - 1.0).abs() < 1e-6);
}

/// Worm-driving efficiency of a screw with uniform friction mu at lead angle gamma and normal
/// pressure angle alpha_n: (cos a_n - mu tan g) / (cos a_n + mu cot g).
fn screw_efficiency(mu: f64, gamma: f64, alpha_n: f64) -> f64 {
    (alpha_n.cos() - mu * gamma.tan()) / (alpha_n.cos() + mu / gamma.tan())
}

/// Asperities that carry every pressure up to the flow pressure (summits dense and sharp, the
/// film too thin to part them) at boundary friction mu, and a film that would shear at the same
/// mu: mu uniform over the contact.
fn uniform_friction(mu: f64) -> FrictionLaw {
    FrictionLaw {
        boundary: mu,
        summit_density_radius_roughness: 1.0,
        summit_roughness_radius: 0.1,
        eyring_stress: 1e9,
        limiting_shear: mu,
    }
}

#[test]
fn a_uniform_friction_gives_the_screws_closed_form_efficiency() {
    // Asperities that carry every pressure up to the flow pressure (summits dense and sharp,
    // the film too thin to part them) at boundary friction mu, and a film that would shear at
    // the same mu: mu is uniform over the contact.
    let mut g = design();
    for mu in [0.02, 0.05, 0.1] {
        g.friction = uniform_friction(mu);
        let bench = common::Bench::new(&g);
        let l = analyse(&g, &bench);
        let eta = l.wheel_torque / (g.ratio() * l.worm_torque);
        // The screw at the load's mean worm radius: its lead angle there, and the normal
        // pressure angle of the ZA worm's straight axial profile (tan a_n = tan a_x cos g).
        let (mut mean_mu, mut radius, mut load) = (0.0, 0.0, 0.0);
        for p in &l.positions {
            for ((c, pr), f) in p.cells.iter().zip(&p.pressure).zip(&p.friction) {
                let force = pr * c.cell.area();
                mean_mu += f * force;
                radius += force * c.cell.centre.y.hypot(c.cell.centre.z);
                load += force;
            }
        }
        (mean_mu, radius) = (mean_mu / load, radius / load);
        let axial = (g.worm.normal_pressure_angle.tan() / g.worm.lead_angle().cos()).atan();
        let gamma = (g.worm.lead_per_rad() / radius).atan();
        let alpha_n = (axial.tan() * gamma.cos()).atan();
        let exact = screw_efficiency(mu, gamma, alpha_n);
        eprintln!(
            "mu {mu}: contact eta_z {eta:.4} (mean mu {mean_mu:.5}), screw at r {:.2} mm \
             {exact:.4}",
            radius * 1e3
        );
        assert!((mean_mu / mu - 1.0).abs() < 1e-3, "{mean_mu}");
        assert!((eta - exact).abs() < 0.001, "{eta} vs {exact}");
    }
}

#[test]
fn the_mesh_loss_converges_under_the_contact_mesh() {
    let g = design();
    let bench = common::Bench::new(&g);
    let coarse = LtcaSettings::from_gear(&g);
    let fine = LtcaSettings {
        columns: coarse.columns * 2,
        ..coarse
    };
    let run = |s: &LtcaSettings| {
        let l = ltca::analyse_with(&g, &bench.geo, &bench.tca, s, None).unwrap();
        let contacts = MeshContacts::new(&g, &bench.geo, &bench.tca, &l);
        (
            l.wheel_torque,
            contacts.friction(&g.lubricant, &g.friction).mesh_loss_w,
        )
    };
    let (t_coarse, loss_coarse) = run(&coarse);
    let (t_fine, loss_fine) = run(&fine);
    eprintln!(
        "columns {} -> {}: T2 {t_coarse:.2} -> {t_fine:.2} N m, P_Vz {loss_coarse:.1} -> \
         {loss_fine:.1} W",
        coarse.columns, fine.columns
    );
    assert!((t_fine / t_coarse - 1.0).abs() < 0.005);
    assert!((loss_fine / loss_coarse - 1.0).abs() < 0.02);
}

#[test]
fn back_driving_gives_the_screws_closed_form_and_one_without_friction() {
    // MODEL §15: the wheel driving the worm is the same contact with the sliding reversed.
    // With a uniform mu the moments of the driving analysis give, for the power flow
    // reversed, the screw's back-driving efficiency tan(gamma - rho') / tan(gamma) =
    // (cos a_n - mu cot g) / (cos a_n + mu tan g) at the load's mean worm radius; their driving
    // efficiency is the loaded analysis' own T2 / (u T1); without friction both are 1; and the
    // gear self-locks past the friction where eta' = 0, tan(gamma) cos(a_n) on the screw.
    let mut g = design();
    let mu = 0.05;
    g.friction = uniform_friction(mu);
    let bench = common::Bench::new(&g);
    let l = analyse(&g, &bench);
    let arms = wormwear::friction::FrictionArms::new(&g, &bench.geo, &l);
    let (driving, back) = arms.efficiencies(&|_, _| mu);
    let own = l.wheel_torque / (g.ratio() * l.worm_torque);
    assert!((driving - own).abs() < 1e-3, "{driving} vs {own}");
    let (mut radius, mut load) = (0.0, 0.0);
    for p in &l.positions {
        for (c, pr) in p.cells.iter().zip(&p.pressure) {
            let force = pr * c.cell.area();
            radius += force * c.cell.centre.y.hypot(c.cell.centre.z);
            load += force;
        }
    }
    radius /= load;
    let axial = (g.worm.normal_pressure_angle.tan() / g.worm.lead_angle().cos()).atan();
    let gamma = (g.worm.lead_per_rad() / radius).atan();
    let alpha_n = (axial.tan() * gamma.cos()).atan();
    let screw = (alpha_n.cos() - mu / gamma.tan()) / (alpha_n.cos() + mu * gamma.tan());
    let locking = gamma.tan() * alpha_n.cos();
    eprintln!(
        "mu {mu}: driving {driving:.4} (analysis {own:.4}); back-driving {back:.4}, screw \
         {screw:.4}; self-locking from mu {:.4}, screw {locking:.4}",
        arms.locking_friction()
    );
    assert!((back - screw).abs() < 0.003, "{back} vs {screw}");
    assert!((arms.locking_friction() / locking - 1.0).abs() < 0.02);
    assert_eq!(arms.efficiencies(&|_, _| 0.0), (1.0, 1.0));
    // Past the locking friction eta' is negative: the verdict.
    let locked = wormwear::friction::SelfLocking::new(&arms, &[], 1.5 * locking);
    assert!(locked.static_self_locking && locked.static_efficiency < 0.0);
    assert!(!locked.dynamic_self_locking && locked.dynamic_efficiency == 1.0);
}
