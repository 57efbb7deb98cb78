//! Worm helicoids against their defining geometry (MODEL §2): straight axial section (A),
//! involute transverse sections and base-tangent generators (I), straight normal section (N),
//! screw invariance, near-coincidence of the profiles of a small single-start worm.

use nalgebra::Vector3;
use std::f64::consts::PI;
use wormwear::geometry::{Flank, ThreadSurface};
use wormwear::input::{GrindingWheel, Hand, ProfileType, ThreadDef};

const MM: f64 = 1e-3;
const DEG: f64 = PI / 180.0;

/// A thread with axial module `m` (m), `starts`, reference radius r1, axial pressure angle.
fn thread(
    profile: ProfileType,
    m: f64,
    starts: u32,
    r1: f64,
    alpha_x_deg: f64,
    hand: Hand,
) -> ThreadDef {
    let p_x = PI * m;
    let gamma = (starts as f64 * p_x / (2.0 * PI * r1)).atan();
    let alpha_x = alpha_x_deg * DEG;
    let alpha_n = (alpha_x.tan() * gamma.cos()).atan();
    ThreadDef {
        profile,
        starts,
        hand,
        axial_pitch: p_x,
        reference_radius: r1,
        tip_radius: r1 + m,
        root_radius: r1 - 1.2 * m,
        axial_pressure_angle: alpha_x,
        normal_pressure_angle: alpha_n,
        axial_thickness: 0.5 * p_x,
        grinding_wheel: matches!(profile, ProfileType::K | ProfileType::C).then(|| GrindingWheel {
            radius: 60.0 * MM,
            axis_distance: r1 + 60.0 * MM,
            profile_angle: alpha_n,
            profile_radius: (profile == ProfileType::C).then_some(100.0 * MM),
        }),
        tip_edge_radius: 0.0,
        tip_relief: wormwear::input::EdgeRelief {
            amount: 0.0,
            length: 1e-3,
        },
    }
}

fn radii(def: &ThreadDef, n: usize) -> impl Iterator<Item = f64> + '_ {
    (0..=n).map(move |k| def.root_radius + (def.tip_radius - def.root_radius) * k as f64 / n as f64)
}

#[test]
fn profile_a_axial_section_is_straight() {
    let def = thread(ProfileType::A, 4.95 * MM, 1, 26.0 * MM, 21.81, Hand::Right);
    let w = ThreadSurface::new(&def).unwrap();
    let r1 = def.reference_radius;
    for flank in Flank::BOTH {
        let x_ref = w.flank_x(flank, r1, 0.0).0;
        let slope = -flank.sign() * def.axial_pressure_angle.tan();
        let worst = radii(&def, 200)
            .map(|y| (w.flank_x(flank, y, 0.0).0 - (x_ref + (y - r1) * slope)).abs())
            .fold(0.0, f64::max);
        assert!(
            worst < 1e-9,
            "{flank:?}: deviation from straight line {worst:e} m"
        );
    }
    // Axial thickness at r1 is exact.
    assert!((w.axial_thickness_at(r1) - def.axial_thickness).abs() < 1e-12);
}

#[test]
fn profile_i_is_an_involute_helicoid() {
    let def = thread(ProfileType::I, 6.0 * MM, 2, 30.0 * MM, 22.0, Hand::Right);
    let w = ThreadSurface::new(&def).unwrap();
    let h = def.lead_per_rad();
    let rb = def.base_radius();
    // Base lead angle relation of helical involutes: cos(gamma_b) = cos(gamma) cos(alpha_n).
    let gamma_b = (h / rb).atan();
    assert!(
        (gamma_b.cos() - def.lead_angle().cos() * def.normal_pressure_angle.cos()).abs() < 1e-12
    );
    let inv = |rho: f64| {
        let a = (rb / rho).acos();
        a.tan() - a
    };
    // Transverse section x = x0: the polar angle phi(rho) of the left flank plus the involute
    // function is constant (involute of the base circle).
    for x0 in [-3.0 * MM, 0.0, 2.5 * MM] {
        let phi = |rho: f64| (x0 - w.axial_profile(Flank::Left, rho).0) / h;
        let c0 = phi(def.reference_radius) + inv(def.reference_radius);
        let worst = radii(&def, 100)
            .map(|rho| rho * (phi(rho) + inv(rho) - c0).abs())
            .fold(0.0, f64::max);
        assert!(
            worst < 1e-9,
            "transverse section at x0 = {x0}: off the involute by {worst:e} m"
        );
    }
    // Generators: straight lines tangent to the base helix lie on the flank.
    let x_b = w.axial_profile(Flank::Left, def.reference_radius).0 - h * inv(def.reference_radius);
    let mut worst: f64 = 0.0;
    for tau in [-0.6, -0.1, 0.0, 0.4, 1.0] {
        let (s, c) = f64::sin_cos(tau);
        let p0 = Vector3::new(x_b + h * tau, rb * c, rb * s);
        let d = Vector3::new(gamma_b.sin(), -gamma_b.cos() * s, gamma_b.cos() * c);
        for rho in radii(&def, 20) {
            let u = (rho * rho - rb * rb).sqrt() / gamma_b.cos();
            let p = p0 + d * u;
            let (gap, _) = w.axial_gap(Flank::Left, &p, 0.0);
            worst = worst.max(gap.abs());
        }
    }
    assert!(
        worst < 1e-9,
        "base-tangent generators leave the flank by {worst:e} m"
    );
}

#[test]
fn profile_n_normal_section_is_straight() {
    let def = thread(ProfileType::N, 8.0 * MM, 3, 35.0 * MM, 20.0, Hand::Right);
    let w = ThreadSurface::new(&def).unwrap();
    let gamma = def.lead_angle();
    // Plane normal to the reference helix through the thread middle (0, r1, 0): points
    // (s cos g, y, -s sin g). Find the left flank in it for several y.
    let on_flank = |s: f64, y: f64| {
        let (x, z) = (s * gamma.cos(), -s * gamma.sin());
        w.flank_x(Flank::Left, y, z).0 - x
    };
    let pts: Vec<(f64, f64)> = radii(&def, 40)
        .map(|y| {
            let (mut lo, mut hi) = (-def.axial_pitch, 0.0);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if on_flank(lo, y) * on_flank(mid, y) <= 0.0 {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            (0.5 * (lo + hi), y)
        })
        .collect();
    let (a, b) = (pts[0], pts[pts.len() - 1]);
    let len = ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt();
    let worst = pts
        .iter()
        .map(|p| ((b.0 - a.0) * (p.1 - a.1) - (b.1 - a.1) * (p.0 - a.0)).abs() / len)
        .fold(0.0, f64::max);
    assert!(
        worst < 1e-9,
        "normal section deviates from a straight line by {worst:e} m"
    );
    // The blade angle in that plane is the normal pressure angle.
    let angle = ((b.0 - a.0) / (b.1 - a.1)).atan();
    assert!((angle - def.normal_pressure_angle).abs() < 1e-9);
}

#[test]
fn flanks_are_invariant_under_the_screw_motion() {
    for hand in [Hand::Right, Hand::Left] {
        for profile in ProfileType::ALL {
            let def = thread(profile, 5.0 * MM, 3, 28.0 * MM, 20.0, hand);
            let w = ThreadSurface::new(&def).unwrap();
            let h = def.lead_per_rad();
            let s = hand.sign();
            for flank in Flank::BOTH {
                for (rho, phi) in [(26.0, 0.1), (30.0, 3.0), (24.0, -3.1), (31.5, 1.7)] {
                    let p = w.flank_point(flank, rho * MM, phi, 0);
                    // Screw motion: rotate by tau about x, advance s h tau; also step whole pitches
                    // (every start is the same flank) and cross the atan2 branch cut.
                    for tau in [0.0, 0.3, -2.0, 3.5, 7.0] {
                        for k in [-2.0, 0.0, 1.0] {
                            let (st, ct) = f64::sin_cos(tau);
                            let q = Vector3::new(
                                p.x + s * h * tau + k * def.axial_pitch,
                                p.y * ct - p.z * st,
                                p.y * st + p.z * ct,
                            );
                            let (gap, _) = w.axial_gap(flank, &q, 0.0);
                            assert!(
                                gap.abs() < 1e-12,
                                "{profile:?} {hand:?} {flank:?}: gap {gap:e} after screw motion {tau}"
                            );
                            // Turning the worm by theta1 advances the flank by -h theta1.
                            let theta1 = 0.37;
                            let moved = Vector3::new(q.x - h * theta1, q.y, q.z);
                            assert!(w.axial_gap(flank, &moved, theta1).0.abs() < 1e-12);
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn table_matches_exact_profile() {
    for profile in [
        ProfileType::A,
        ProfileType::N,
        ProfileType::I,
        ProfileType::K,
        ProfileType::C,
    ] {
        let def = thread(profile, 4.0 * MM, 2, 22.0 * MM, 20.0, Hand::Right);
        let w = ThreadSurface::new(&def).unwrap();
        for rho in radii(&def, 333) {
            let (x, s) = w.axial_profile(Flank::Left, rho);
            let (xe, se) = w.axial_profile_exact(Flank::Left, rho).unwrap();
            assert!(
                (x - xe).abs() < 1e-12,
                "{profile:?}: table error {:e} m",
                (x - xe).abs()
            );
            assert!(
                (s - se).abs() < 1e-8,
                "{profile:?}: slope error {:e}",
                (s - se).abs()
            );
        }
    }
}

#[test]
fn small_single_start_worm_profiles_nearly_coincide() {
    // Module 1 mm, single start, q = 20: A, I, N, K with the same axial pressure angle and
    // thickness at r1 differ by less than 1 um over the flank (MODEL §2.2).
    let m = 1.0 * MM;
    let r1 = 10.0 * MM;
    let def_a = thread(ProfileType::A, m, 1, r1, 20.0, Hand::Right);
    let a = ThreadSurface::new(&def_a).unwrap();
    for profile in [ProfileType::I, ProfileType::N, ProfileType::K] {
        let def = thread(profile, m, 1, r1, 20.0, Hand::Right);
        let other = ThreadSurface::new(&def).unwrap();
        let worst = radii(&def, 100)
            .map(|rho| {
                (a.axial_profile(Flank::Left, rho).0 - other.axial_profile(Flank::Left, rho).0)
                    .abs()
            })
            .fold(0.0, f64::max);
        assert!(worst < 1e-6, "A vs {profile:?}: {worst:e} m");
        // Not identical: the profiles are genuinely different surfaces.
        assert!(worst > 1e-10, "A vs {profile:?} identical ({worst:e} m)?");
        if profile == ProfileType::I {
            // The ZI axial profile is X(rho) = X(r1) + h [inv(rho) - inv(r1)] (inv the involute
            // function of the base circle) while ZA is straight: their difference is known in
            // closed form at every radius.
            let rb = def.base_radius();
            let h = def.lead_per_rad();
            let inv = |rho: f64| {
                let t = (rb / rho).acos();
                t.tan() - t
            };
            for rho in radii(&def, 50) {
                let expected =
                    h * (inv(rho) - inv(r1)) - (rho - r1) * def.axial_pressure_angle.tan();
                let got =
                    other.axial_profile(Flank::Left, rho).0 - a.axial_profile(Flank::Left, rho).0;
                assert!(
                    (got - expected).abs() < 1e-10,
                    "A-I at {rho}: {got:e} vs {expected:e}"
                );
            }
        }
    }
}

#[test]
fn k_and_c_flanks_are_envelopes_of_the_grinding_wheel() {
    // Points of the grinding wheel surface never enter the thread (the flank is an envelope),
    // and the wheel touches the flank along its contact curve.
    for profile in [ProfileType::K, ProfileType::C] {
        let def = thread(profile, 8.0 * MM, 2, 32.0 * MM, 20.0, Hand::Right);
        let w = ThreadSurface::new(&def).unwrap();
        let gw = def.grinding_wheel.clone().unwrap();
        let gamma = def.lead_angle();
        let axis = Vector3::new(gamma.cos(), 0.0, -gamma.sin());
        let u1 = Vector3::new(0.0, -1.0, 0.0);
        let u2 = axis.cross(&u1);
        // The wheel as the generator places it, moved by the thickness shift.
        let centre = Vector3::new(w.generator_shift(), gw.axis_distance, 0.0);
        let (sa, ca) = gw.profile_angle.sin_cos();
        // Wheel section: straight (K) or circular arc of radius rho_0 (C), as (a, R).
        let section = |t: f64| match gw.profile_radius {
            None => (-t * sa, gw.radius + t * ca),
            Some(r0) => {
                let b = gw.profile_angle + t / r0;
                (-r0 * ca + r0 * b.cos(), gw.radius - r0 * sa + r0 * b.sin())
            }
        };
        let mut min_gap = f64::INFINITY;
        let mut touching = 0;
        for kt in -40..=40 {
            let (a, big_r) = section(kt as f64 * 0.15 * MM);
            for kp in -150..=150 {
                let psi = kp as f64 * 0.002;
                let er = u1 * psi.cos() + u2 * psi.sin();
                let p = centre + axis * a + er * big_r;
                let rho = (p.y * p.y + p.z * p.z).sqrt();
                if rho < def.root_radius || rho > def.tip_radius || p.x > 0.0 {
                    continue;
                }
                // The wheel lies in the space left of the left flank: x_flank - x >= 0.
                let gap = w.flank_x(Flank::Left, p.y, p.z).0 - p.x;
                min_gap = min_gap.min(gap);
                if gap.abs() < 2e-7 {
                    touching += 1;
                }
            }
        }
        assert!(
            min_gap > -1e-9,
            "{profile:?}: grinding wheel cuts the flank by {:e} m",
            -min_gap
        );
        assert!(
            touching > 20,
            "{profile:?}: wheel does not touch the flank ({touching} points)"
        );
    }
}
