//! Stage 5a's local law — mixed-lubrication friction at one point of the contact (MODEL §13).
//!
//! The load at a loaded cell is shared between the asperities and the film (Greenwood & Tripp
//! 1970-71; Johnson, Greenwood & Poon 1972): with sigma the composite RMS roughness, h the
//! local central film thickness (the separation of the mean planes) and the summit statistics
//! eta_s beta sigma and sigma / beta,
//!
//! ```text
//! p_asp = min(p_Y, K_GT E* F_5/2(h / sigma)),
//! K_GT = (16 sqrt(2) pi / 15) (eta_s beta sigma)^2 sqrt(sigma / beta),
//! ```
//!
//! E* Hertz's contact modulus in Greenwood & Tripp's own convention (1 / E* = sum (1 - v^2) / E,
//! half MODEL §6's reduced modulus E'; the constant is that of summit pairs in Hertz contact,
//! re-derived by quadrature in the tests) and p_Y the wheel's flow pressure (plastic
//! asperities). The asperities take the share f_a = min(1, p_asp / p) at
//! boundary friction mu_b, the film the rest with Eyring's shear bounded by the limiting shear:
//! mu = f_a mu_b + (1 - f_a) tau_f / p. MODEL §10's asperity formula belongs to the protocol
//! that calibrates K from tests ([`crate::calibration`]), not here (MODEL §12 o).
//! SI units throughout (Pa, m, m/s).

use crate::input::{FrictionLaw, Lubricant};
use crate::lubrication::{self, LineContact};
use std::f64::consts::PI;
use std::sync::OnceLock;

/// The Gaussian summit-height integral of Greenwood & Williamson,
/// F_n(x) = (1 / sqrt(2 pi)) int_x^inf (s - x)^n exp(-s^2 / 2) ds, of order `order` >= 0 at
/// the dimensionless separation `x` (any sign), by Simpson's rule in u = sqrt(s - x) (smooth
/// for every order) over s - x in [0, max(0, -x) + 14]. F_0 = erfc(x / sqrt 2) / 2 and
/// F_n(0) = 2^((n-1)/2) Gamma((n+1)/2) / sqrt(2 pi) are its closed forms (the tests').
pub fn summit_integral(order: f64, x: f64) -> f64 {
    let top = ((-x).max(0.0) + 14.0).sqrt();
    let intervals = 4000;
    let du = top / intervals as f64;
    let integrand = |u: f64| {
        let t = u * u;
        let s = x + t;
        2.0 * u * t.powf(order) * (-0.5 * s * s).exp()
    };
    let mut sum = integrand(0.0) + integrand(top);
    for k in 1..intervals {
        let weight = if k % 2 == 1 { 4.0 } else { 2.0 };
        sum += weight * integrand(k as f64 * du);
    }
    sum * du / 3.0 / (2.0 * PI).sqrt()
}

/// Separations of the tabulated F_5/2: 0 to [`TABLE_END`] in steps of [`TABLE_STEP`].
const TABLE_STEP: f64 = 0.01;
const TABLE_END: f64 = 8.0;

/// F_5/2 and F_3/2 at the table's separations (F_5/2' = -(5/2) F_3/2).
fn summit_table() -> &'static (Vec<f64>, Vec<f64>) {
    static TABLE: OnceLock<(Vec<f64>, Vec<f64>)> = OnceLock::new();
    TABLE.get_or_init(|| {
        let n = (TABLE_END / TABLE_STEP).round() as usize + 1;
        let x = |k: usize| k as f64 * TABLE_STEP;
        let order =
            |order: f64| -> Vec<f64> { (0..n).map(|k| summit_integral(order, x(k))).collect() };
        // The two orders side by side (a one-off tenth of a second at a run's first friction,
        // while the other threads wait for it): a plain thread, not the pool's, since the pool's
        // threads may be the ones waiting here.
        std::thread::scope(|s| {
            let f_3_2 = s.spawn(|| order(1.5));
            let f_5_2 = order(2.5);
            (f_5_2, f_3_2.join().expect("the F_3/2 table's thread"))
        })
    })
}

/// F_5/2(x) of Greenwood & Tripp at the separation ratio `x` = h / sigma: cubic Hermite
/// interpolation of [`summit_integral`] tabulated once (its derivative -(5/2) F_3/2 exact at
/// the nodes; interpolation error below 1e-9 of F_5/2(0)). Separations below 0 read F_5/2(0)
/// (a film is never negative); beyond 8 it is below 1e-17 and returns 0.
pub fn summit_integral_5_2(x: f64) -> f64 {
    if x.is_nan() {
        return f64::NAN;
    }
    if x >= TABLE_END {
        return 0.0;
    }
    let (f, g) = summit_table();
    let x = x.max(0.0);
    let k = ((x / TABLE_STEP) as usize).min(f.len() - 2);
    let t = x / TABLE_STEP - k as f64;
    let (d0, d1) = (-2.5 * g[k] * TABLE_STEP, -2.5 * g[k + 1] * TABLE_STEP);
    let (t2, t3) = (t * t, t * t * t);
    (2.0 * t3 - 3.0 * t2 + 1.0) * f[k]
        + (t3 - 2.0 * t2 + t) * d0
        + (-2.0 * t3 + 3.0 * t2) * f[k + 1]
        + (t3 - t2) * d1
}

/// Greenwood & Tripp's constant K_GT = (16 sqrt(2) pi / 15) (eta_s beta sigma)^2
/// sqrt(sigma / beta) of the summit statistics in `law` (dimensionless).
pub fn greenwood_tripp_constant(law: &FrictionLaw) -> f64 {
    let product = law.summit_density_radius_roughness;
    16.0 * 2f64.sqrt() * PI / 15.0 * product * product * law.summit_roughness_radius.sqrt()
}

/// Mean pressure carried by the asperities, Pa (MODEL §13): K_GT E* F_5/2(h / sigma) at the
/// mean-plane separation `separation` h (m) over the composite RMS roughness `roughness`
/// sigma (m), bounded by the flow pressure `flow_pressure` (Pa; plastic asperities). E* is
/// Hertz's contact modulus of Greenwood & Tripp's derivation (two summits of radius beta in
/// Hertz contact, 1 / E* = sum (1 - v^2) / E), i.e. half the reduced modulus `e_prime` of
/// MODEL §6 (Pa) that the film formulas use.
pub fn asperity_pressure(
    separation: f64,
    roughness: f64,
    e_prime: f64,
    law: &FrictionLaw,
    flow_pressure: f64,
) -> f64 {
    let x = if separation.is_finite() {
        separation / roughness
    } else {
        TABLE_END
    };
    let contact_modulus = 0.5 * e_prime;
    (greenwood_tripp_constant(law) * contact_modulus * summit_integral_5_2(x)).min(flow_pressure)
}

/// Central film thickness of a line contact, m (MODEL §13): the Moes–Venner minimum film of
/// MODEL §6 scaled by Pan & Hamrock's (1989) ratio of their central and minimum line-contact
/// fits, H_c / H_min = (2.922 / 1.714) W^-0.038 U^-0.002 G^-0.098 (W, U, G of MODEL §6, U with
/// the mean entrainment speed), times the thermal factor Phi_T. 0 without entrainment;
/// infinite without load.
pub fn central_film_thickness(lub: &Lubricant, e_prime: f64, line: &LineContact) -> f64 {
    // (No film or no load: the minimum film itself, before the powers of the formula.)
    lubrication::LineFilm::without_formula(line)
        .unwrap_or_else(|| CentralFilm::of(lub, e_prime, line).at(line.line_load, line.pressure))
}

/// [`central_film_thickness`] of one contact line with what its load does not change computed
/// once (the line's curvature and speeds, the lubricant): the thickness under any line load
/// and peak pressure (the same numbers: the function is computed through it).
#[derive(Debug, Clone, Copy)]
pub struct CentralFilm {
    film: lubrication::LineFilm,
    /// E' R, N/m.
    load_scale: f64,
    /// U^-0.002 and G^-0.098 of Pan & Hamrock's ratio.
    u_factor: f64,
    g_factor: f64,
}

impl CentralFilm {
    /// The film of the contact line `line` (its `line_load` and `pressure` not read) of the
    /// lubricant `lub` between surfaces of reduced modulus `e_prime` (Pa).
    pub fn of(lub: &Lubricant, e_prime: f64, line: &LineContact) -> Self {
        let u = lub.viscosity * (line.u1 + line.u2).abs() / (2.0 * e_prime * line.radius);
        let g = lub.pressure_viscosity * e_prime;
        Self {
            film: lubrication::LineFilm::of(lub, e_prime, line),
            load_scale: e_prime * line.radius,
            u_factor: u.powf(-0.002),
            g_factor: g.max(1.0).powf(-0.098),
        }
    }

    /// The central film thickness (m) under the line load `line_load` (N/m) with the peak
    /// pressure `pressure` (Pa).
    pub fn at(&self, line_load: f64, pressure: f64) -> f64 {
        let h_min = self.film.min_film_thickness(line_load);
        if h_min <= 0.0 || !h_min.is_finite() {
            return h_min;
        }
        let w = line_load / self.load_scale;
        let ratio = 2.922 / 1.714 * w.powf(-0.038) * self.u_factor * self.g_factor;
        h_min * ratio * self.film.thermal_factor(pressure)
    }
}

/// Shear stress of the lubricant film, Pa, at pressure `pressure` (Pa), sliding speed
/// `sliding_speed` (m/s) and film thickness `film_thickness` (m): Eyring's law
/// tau = tau_0 asinh(eta(p) gamma / tau_0), gamma = v_s / h, with the Barus viscosity
/// eta(p) = eta_0 exp(alpha p) (`viscosity` eta_0 in Pa s, `pressure_viscosity` alpha in
/// 1/Pa), bounded by the limiting shear stress Lambda p (Bair & Winer). A film of no
/// thickness shears at the limit.
pub fn fluid_shear(
    pressure: f64,
    sliding_speed: f64,
    film_thickness: f64,
    viscosity: f64,
    pressure_viscosity: f64,
    law: &FrictionLaw,
) -> f64 {
    let p = pressure.max(0.0);
    let limit = law.limiting_shear * p;
    let speed = sliding_speed.abs();
    if speed == 0.0 {
        return 0.0;
    }
    if film_thickness.is_nan() || film_thickness <= 0.0 {
        return limit;
    }
    let eta = viscosity * (pressure_viscosity * p).exp();
    let rate = speed / film_thickness;
    let eyring = law.eyring_stress * (eta * rate / law.eyring_stress).asinh();
    eyring.min(limit)
}

/// The friction at one point of the contact (MODEL §13).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct LocalFriction {
    /// mu = f_a mu_b + (1 - f_a) tau_f / p.
    pub coefficient: f64,
    /// f_a, the asperities' share of the pressure.
    pub asperity_share: f64,
    /// tau_f, the film's shear stress, Pa.
    pub fluid_shear: f64,
}

/// The contact's conditions at one point for [`local_friction`], SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointContact {
    /// Contact pressure p, Pa.
    pub pressure: f64,
    /// Sliding speed |v_g|, m/s.
    pub sliding_speed: f64,
    /// Central film thickness h (the mean planes' separation), m.
    pub film_thickness: f64,
    /// Composite RMS roughness sigma there, m (MODEL §6.1: per node once the flank runs in).
    pub roughness: f64,
}

/// Local friction at the point `at` over a film of `lubricant` (its viscosity at the oil
/// temperature), with the reduced modulus `e_prime` and the asperities' flow pressure
/// `flow_pressure` (Pa) (MODEL §13). The asperities carry everything where p <= p_asp.
pub fn local_friction(
    at: &PointContact,
    lubricant: &Lubricant,
    law: &FrictionLaw,
    (e_prime, flow_pressure): (f64, f64),
) -> LocalFriction {
    let p = at.pressure;
    if p.is_nan() || p <= 0.0 {
        // Nothing pressed: the asperities' share is whole and the film shears nothing
        // (fluid_shear is 0 at p = 0: its limit Lambda p is).
        return LocalFriction {
            coefficient: law.boundary,
            asperity_share: 1.0,
            fluid_shear: 0.0,
        };
    }
    let carried = asperity_pressure(at.film_thickness, at.roughness, e_prime, law, flow_pressure);
    let share = (carried / p).min(1.0);
    let tau = fluid_shear(
        p,
        at.sliding_speed,
        at.film_thickness,
        lubricant.viscosity,
        lubricant.pressure_viscosity,
        law,
    );
    let fluid = tau / p;
    LocalFriction {
        coefficient: share * law.boundary + (1.0 - share) * fluid,
        asperity_share: share,
        fluid_shear: tau,
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::lubrication::tests::oil;

    const E_PRIME: f64 = 1.557e11;

    /// The friction law of the tests: MODEL §13's cited defaults.
    pub(crate) fn law() -> FrictionLaw {
        FrictionLaw {
            boundary: 0.094,
            summit_density_radius_roughness: 0.05,
            summit_roughness_radius: 0.01,
            eyring_stress: 5e6,
            limiting_shear: 0.02,
        }
    }

    /// Gamma(x) for x in (0, 10] by Lanczos (g = 7, n = 9), to ~1e-15.
    fn gamma(x: f64) -> f64 {
        const C: [f64; 9] = [
            0.999_999_999_999_809_9,
            676.520_368_121_885_1,
            -1_259.139_216_722_402_8,
            771.323_428_777_653_1,
            -176.615_029_162_140_6,
            12.507_343_278_686_905,
            -0.138_571_095_265_720_12,
            9.984_369_578_019_572e-6,
            1.505_632_735_149_311_6e-7,
        ];
        let x = x - 1.0;
        let mut a = C[0];
        let t = x + 7.5;
        for (i, c) in C.iter().enumerate().skip(1) {
            a += c / (x + i as f64);
        }
        (2.0 * PI).sqrt() * t.powf(x + 0.5) * (-t).exp() * a
    }

    #[test]
    fn the_summit_integrals_have_their_closed_forms() {
        // F_0(x) = erfc(x / sqrt 2) / 2 and F_1(x) = phi(x) - x F_0(x), for any x.
        for x in [-2.0, -0.5, 0.0, 0.3, 1.0, 2.5, 4.0] {
            let f0 = 0.5 * libm::erfc(x / 2f64.sqrt());
            let f1 = (-0.5 * x * x).exp() / (2.0 * PI).sqrt() - x * f0;
            assert!(
                (summit_integral(0.0, x) / f0 - 1.0).abs() < 1e-9,
                "F_0({x})"
            );
            assert!(
                (summit_integral(1.0, x) / f1 - 1.0).abs() < 1e-9,
                "F_1({x})"
            );
        }
        // F_n(0) = 2^((n-1)/2) Gamma((n+1)/2) / sqrt(2 pi): F_3/2(0) = 0.4299, F_5/2(0) = 0.6167
        // (Greenwood & Tripp's tabulated 0.6168).
        for n in [0.5, 1.5, 2.5] {
            let exact = 2f64.powf((n - 1.0) / 2.0) * gamma((n + 1.0) / 2.0) / (2.0 * PI).sqrt();
            assert!(
                (summit_integral(n, 0.0) / exact - 1.0).abs() < 1e-9,
                "F_{n}(0)"
            );
        }
        assert!((summit_integral_5_2(0.0) - 0.6167).abs() < 1e-4);
    }

    #[test]
    fn the_tabulated_f52_matches_its_quadrature_and_the_published_fit() {
        // Between the table's nodes, against the direct quadrature.
        for x in [0.003, 0.4567, 1.2345, 2.999, 3.5001, 5.55] {
            let direct = summit_integral(2.5, x);
            assert!(
                (summit_integral_5_2(x) - direct).abs() < 1e-9 * 0.6167,
                "F_5/2({x}): {} vs {direct}",
                summit_integral_5_2(x)
            );
        }
        // The power fit used throughout the mixed-lubrication literature, 4.4086e-5 (4 - x)^6.804
        // (stated for x < 4), is within 11 % of the integral for 0.5 <= x <= 2 (the integral: 0.2404,
        // 0.08056, 0.02286, 0.005424 at x = 0.5, 1, 1.5, 2) and falls away beyond, where the
        // integral's Gaussian tail dominates: 1.5x low at 2.5, 4x at 3.
        for (x, integral) in [
            (0.5, 0.2404),
            (1.0, 0.08056),
            (1.5, 0.02286),
            (2.0, 0.005424),
        ] {
            let fit = 4.4086e-5 * (4.0f64 - x).powf(6.804);
            let ours = summit_integral_5_2(x);
            assert!(
                (ours / fit - 1.0).abs() < 0.11,
                "F_5/2({x}) = {ours} vs fit {fit}"
            );
            assert!((ours / integral - 1.0).abs() < 3e-4, "F_5/2({x}) = {ours}");
        }
        let tail = summit_integral_5_2(3.0) / (4.4086e-5 * 1f64.powf(6.804));
        assert!(tail > 3.0, "{tail}");
        // Decreasing, positive, 0 beyond the table.
        let mut last = f64::INFINITY;
        for k in 0..800 {
            let v = summit_integral_5_2(k as f64 * 0.01);
            assert!(v > 0.0 && v < last);
            last = v;
        }
        assert_eq!(summit_integral_5_2(9.0), 0.0);
        assert_eq!(summit_integral_5_2(-1.0), summit_integral_5_2(0.0));
    }

    #[test]
    fn the_asperity_pressure_is_greenwood_tripps_bounded_by_the_flow_pressure() {
        let l = law();
        let k = greenwood_tripp_constant(&l);
        let exact = 16.0 * 2f64.sqrt() * PI / 15.0 * 0.05 * 0.05 * 0.1;
        assert!((k / exact - 1.0).abs() < 1e-14);
        // At contact of the mean planes: K E* F_5/2(0), E* = E' / 2.
        let p0 = asperity_pressure(0.0, 1e-6, E_PRIME, &l, f64::INFINITY);
        let e_star = 0.5 * E_PRIME;
        assert!((p0 / (exact * e_star * summit_integral(2.5, 0.0)) - 1.0).abs() < 1e-9);
        // Bounded by the flow pressure; vanishing under a thick film.
        assert_eq!(asperity_pressure(0.0, 1e-6, E_PRIME, &l, 1e6), 1e6);
        assert!(asperity_pressure(5e-6, 1e-6, E_PRIME, &l, 1e9) < 1e-6 * p0);
        assert_eq!(
            asperity_pressure(f64::INFINITY, 1e-6, E_PRIME, &l, 1e9),
            0.0
        );
    }

    /// Simpson's rule of `f` over [a, b] in `n` (even) intervals.
    fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
        let h = (b - a) / n as f64;
        let inner: f64 = (1..n)
            .map(|k| f(a + k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 })
            .sum();
        (f(a) + f(b) + inner) * h / 3.0
    }

    #[test]
    fn the_asperity_pressure_is_the_sum_of_hertz_contacts_of_summit_pairs() {
        // Greenwood & Tripp's model from its premises, without F_5/2 or K_GT: both surfaces
        // carry eta summits per m^2 of radius beta, heights Gaussian with sd sigma / sqrt 2
        // each (composite sigma). Two summits of heights z1, z2 at lateral offset r, mean
        // planes h apart, overlap by w = z1 + z2 - h - r^2 / (4 beta) and press with Hertz's
        // P = (4/3) E* sqrt(beta / 2) w^(3/2), 1 / E* = sum (1 - v^2) / E = 2 / E'. The
        // nominal pressure is eta^2 times the sum over pairs, by quadrature in z1, z2 and r.
        let l = law();
        let sigma = 1e-6;
        let beta = sigma / l.summit_roughness_radius;
        let eta = l.summit_density_radius_roughness / (beta * sigma);
        let e_star = 0.5 * E_PRIME;
        let sd = sigma / 2f64.sqrt();
        let gauss = |z: f64| (-0.5 * (z / sd).powi(2)).exp() / (sd * (2.0 * PI).sqrt());
        let pair_load = |overlap: f64| {
            // Sum over r of the pairs' Hertz loads at a total overlap `overlap` (r = 0).
            if overlap <= 0.0 {
                return 0.0;
            }
            let r_max = (4.0 * beta * overlap).sqrt();
            let hertz = |r: f64| {
                let w = (overlap - r * r / (4.0 * beta)).max(0.0);
                2.0 * PI * r * 4.0 / 3.0 * e_star * (beta / 2.0).sqrt() * w.powf(1.5)
            };
            simpson(hertz, 0.0, r_max, 200)
        };
        for x in [0.0, 0.5, 1.0, 2.0] {
            let h = x * sigma;
            let span = 8.0 * sd;
            let nominal = eta
                * eta
                * simpson(
                    |z1| {
                        gauss(z1)
                            * simpson(|z2| gauss(z2) * pair_load(z1 + z2 - h), -span, span, 240)
                    },
                    -span,
                    span,
                    240,
                );
            let ours = asperity_pressure(h, sigma, E_PRIME, &l, f64::INFINITY);
            assert!(
                (ours / nominal - 1.0).abs() < 2e-3,
                "h / sigma = {x}: {ours} Pa vs the summit pairs' {nominal} Pa"
            );
        }
    }

    #[test]
    fn the_load_is_shared_between_asperities_and_film() {
        let l = law();
        let lub = oil();
        let at = |pressure: f64, film: f64| PointContact {
            pressure,
            sliding_speed: 3.0,
            film_thickness: film,
            roughness: 1e-6,
        };
        let carried = asperity_pressure(0.5e-6, 1e-6, E_PRIME, &l, 1e9);
        // Below what the asperities carry, they carry all at boundary friction.
        let f = local_friction(&at(0.5 * carried, 0.5e-6), &lub, &l, (E_PRIME, 1e9));
        assert_eq!((f.asperity_share, f.coefficient), (1.0, l.boundary));
        // Above it, their share is p_asp / p and the rest is the film's.
        let p = 4.0 * carried;
        let f = local_friction(&at(p, 0.5e-6), &lub, &l, (E_PRIME, 1e9));
        assert!((f.asperity_share - 0.25).abs() < 1e-12);
        let expected = 0.25 * l.boundary + 0.75 * f.fluid_shear / p;
        assert!((f.coefficient - expected).abs() < 1e-15);
        // Under a thick film the film's friction alone.
        let f = local_friction(&at(5e8, 10e-6), &lub, &l, (E_PRIME, 1e9));
        assert!(f.asperity_share < 1e-20);
        assert!((f.coefficient - f.fluid_shear / 5e8).abs() < 1e-15);
    }

    #[test]
    fn the_central_film_is_thicker_than_the_minimum_by_the_published_ratio() {
        // A gear-like line contact: the ratio H_c / H_min of Pan & Hamrock lies between 1 and
        // 1.5 in the elastic-piezoviscous regime, and the thermal factor applies to both.
        let lub = oil();
        let line = LineContact {
            radius: 0.01,
            u1: 2.0,
            u2: 1.0,
            line_load: 2e5,
            pressure: 5e8,
        };
        let film = lubrication::film(&lub, E_PRIME, &line);
        let central = central_film_thickness(&lub, E_PRIME, &line);
        let ratio = central / (film.h_min * film.thermal_factor);
        assert!(ratio > 1.0 && ratio < 1.5, "{ratio}");
        let still = LineContact {
            u1: 0.0,
            u2: 0.0,
            ..line
        };
        assert_eq!(central_film_thickness(&lub, E_PRIME, &still), 0.0);
    }

    #[test]
    fn a_line_s_central_film_is_the_same_number_from_its_load_independent_factors() {
        // One line's CentralFilm read at several loads gives the function's numbers to the bit
        // (the friction updates read it so); the early answers (no load, no entrainment, no
        // curvature) are the formula's limits: infinite, 0, 0.
        let lub = oil();
        let line = LineContact {
            radius: 0.012,
            u1: 3.0,
            u2: -0.5,
            line_load: 0.0,
            pressure: 0.0,
        };
        let film = CentralFilm::of(&lub, E_PRIME, &line);
        for (w, p) in [(1e3, 1e8), (2e5, 5e8), (3e6, 1.2e9)] {
            let loaded = LineContact {
                line_load: w,
                pressure: p,
                ..line
            };
            let direct = central_film_thickness(&lub, E_PRIME, &loaded);
            assert!(direct.is_finite() && direct > 0.0);
            assert_eq!(film.at(w, p).to_bits(), direct.to_bits(), "{w} {p}");
        }
        assert_eq!(central_film_thickness(&lub, E_PRIME, &line), f64::INFINITY);
        assert_eq!(film.at(0.0, 0.0), f64::INFINITY);
        for still in [
            LineContact { u1: 0.5, ..line },
            LineContact {
                radius: 0.0,
                line_load: 1e5,
                ..line
            },
        ] {
            assert_eq!(central_film_thickness(&lub, E_PRIME, &still), 0.0);
            assert_eq!(CentralFilm::of(&lub, E_PRIME, &still).at(1e5, 1e8), 0.0);
        }
    }

    /// The film's traction over a smooth Hertz line contact, p = p0 sqrt(1 - (x/a)^2), by the
    /// midpoint rule on `n` strips: F / w, the friction coefficient of the contact.
    fn hertz_traction(
        p0: f64,
        speed: f64,
        film: f64,
        viscosity: f64,
        alpha: f64,
        law: &FrictionLaw,
    ) -> f64 {
        let n = 200_000;
        let (mut force, mut load) = (0.0, 0.0);
        for k in 0..n {
            let x = -1.0 + (k as f64 + 0.5) * 2.0 / n as f64;
            let p = p0 * (1.0 - x * x).sqrt();
            force += fluid_shear(p, speed, film, viscosity, alpha, law);
            load += p;
        }
        force / load
    }

    #[test]
    fn a_newtonian_film_over_a_hertz_line_contact_has_its_closed_form_traction() {
        // tau_0 and Lambda out of reach, no pressure-viscosity: tau = eta v / h everywhere,
        // so F = eta v / h x 2a and w = pi a p0 / 2: mu = 4 eta v / (pi h p0).
        let newtonian = FrictionLaw {
            eyring_stress: 1e15,
            limiting_shear: 1.0,
            ..law()
        };
        let (p0, v, h, eta) = (5e8, 2.0, 1e-6, 0.227);
        let mu = hertz_traction(p0, v, h, eta, 0.0, &newtonian);
        let exact = 4.0 * eta * v / (PI * h * p0);
        assert!((mu / exact - 1.0).abs() < 1e-5, "{mu} vs {exact}");
    }

    #[test]
    fn a_saturated_eyring_film_over_a_hertz_line_contact_has_its_closed_form_traction() {
        // Where eta(p) gamma >> tau_0, tau = tau_0 ln(2 eta0 gamma / tau_0) + tau_0 alpha p:
        // mu = tau_0 alpha + (4 tau_0 / (pi p0)) ln(2 eta0 gamma / tau_0).
        let eyring = FrictionLaw {
            limiting_shear: 1.0,
            ..law()
        };
        let (p0, v, h, eta, alpha) = (5e8, 10.0, 1e-6, 10.0, 9.5e-9);
        let mu = hertz_traction(p0, v, h, eta, alpha, &eyring);
        let tau0 = eyring.eyring_stress;
        let exact = tau0 * alpha + 4.0 * tau0 / (PI * p0) * (2.0 * eta * v / h / tau0).ln();
        assert!((mu / exact - 1.0).abs() < 1e-3, "{mu} vs {exact}");
        // And the limiting shear bounds it: mu <= Lambda.
        let limited = hertz_traction(p0, v, h, eta, alpha, &law());
        assert!(
            limited <= law().limiting_shear + 1e-12 && limited < mu,
            "{limited}"
        );
    }
}
