//! Stage 4a — lubricant film at a contact line (MODEL §6): Moes–Venner minimum film thickness
//! of a line contact, Gupta's thermal reduction, film ratio, the local wear coefficient and the
//! asperity contact of the mixed regime (MODEL §10).
//! SI units throughout (m, Pa, m/s, N/m, K).

use crate::geometry::{FlankField, WheelFlank};
use crate::input::Lubricant;

/// Dimensionless Moes–Venner minimum film thickness H(M, L) of a line contact (MODEL §6):
/// a smooth blend of the rigid-isoviscous (2.45/M, Martin), elastic-isoviscous (2.05 M^-1/5)
/// and elastic-piezoviscous (0.99 M^-1/8 L^3/4) asymptotes. M > 0, L >= 0.
pub fn moes_venner(m: f64, l: f64) -> f64 {
    MoesVenner::at_l(l).at(m)
}

/// [`moes_venner`] at a fixed L (its powers of L computed once): H(M, L) for any M.
#[derive(Debug, Clone, Copy)]
struct MoesVenner {
    l: f64,
    /// L^-1/4, L^3/4 and the blend's exponent r = exp(1 - 3 / (L + 4)).
    l_quarter: f64,
    l_three_quarters: f64,
    r: f64,
}

impl MoesVenner {
    fn at_l(l: f64) -> Self {
        Self {
            l,
            l_quarter: l.powf(-0.25),
            l_three_quarters: l.powf(0.75),
            r: (1.0 - 3.0 / (l + 4.0)).exp(),
        }
    }

    fn at(&self, m: f64) -> f64 {
        // t -> 1 as L -> 0 (L^-1/4 -> infinity).
        let t = if self.l > 0.0 {
            1.0 - (-3.5 * m.powf(0.125) * self.l_quarter).exp()
        } else {
            1.0
        };
        let r = self.r;
        let s = 3.0 - (-1.0 / (2.0 * m)).exp();
        let ep = 0.99 * m.powf(-0.125) * self.l_three_quarters * t;
        let ei = 2.05 * m.powf(-0.2);
        let ri = 2.45 / m;
        ((ep.powf(r) + ei.powf(r)).powf(s / r) + ri.powf(s)).powf(1.0 / s)
    }
}

/// Conditions of a contact line at one point (MODEL §6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineContact {
    /// Relative radius of curvature across the line, m.
    pub radius: f64,
    /// Surface velocities normal to the line relative to the contact (worm, wheel), m/s.
    pub u1: f64,
    pub u2: f64,
    /// Load per unit length of line, N/m.
    pub line_load: f64,
    /// Hertz (maximum) pressure, Pa (thermal reduction).
    pub pressure: f64,
}

/// Film at a point of a contact line.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Film {
    /// Isothermal minimum film thickness, m.
    pub h_min: f64,
    /// Thermal reduction factor Phi_T (0..1].
    pub thermal_factor: f64,
    /// Film ratio lambda = h_min Phi_T / R_q.
    pub lambda: f64,
}

/// Reduced modulus E' of MODEL §6: 1/E' = (1/2) [(1 - v1^2)/E1 + (1 - v2^2)/E2], Pa.
pub fn reduced_modulus(e1: f64, v1: f64, e2: f64, v2: f64) -> f64 {
    2.0 / ((1.0 - v1 * v1) / e1 + (1.0 - v2 * v2) / e2)
}

/// Isothermal minimum film thickness (Moes–Venner), m: h_min = H R (2U)^1/2 with
/// U = eta0 (u1 + u2)/(2 E' R), W = w/(E' R), G = alpha E', M = W (2U)^-1/2, L = G (2U)^1/4.
/// The entrainment |u1 + u2| is used (the sense of rolling does not matter). Zero when there
/// is no entrainment or no load-free solution.
pub fn min_film_thickness(lub: &Lubricant, e_prime: f64, c: &LineContact) -> f64 {
    LineFilm::of(lub, e_prime, c).min_film_thickness(c.line_load)
}

/// Gupta's thermal reduction factor Phi_T (MODEL §6): inlet shear heating with the thermal
/// loading L_T = eta beta* (u1 + u2)^2 / (4 K_f T^2), slide-to-roll ratio
/// S = 2 |u1 - u2| / |u1 + u2|. Clamped to (0, 1].
pub fn thermal_factor(lub: &Lubricant, e_prime: f64, c: &LineContact) -> f64 {
    LineFilm::of(lub, e_prime, c).thermal_factor(c.pressure)
}

/// The film of a contact line (MODEL §6) with what its load does not change computed once:
/// the curvature, the rolling velocities and the lubricant set U, G, L and the thermal loading;
/// the line load and the peak pressure then give [`min_film_thickness`] and [`thermal_factor`]
/// (the same numbers: they are computed through it).
#[derive(Debug, Clone, Copy)]
pub struct LineFilm {
    /// None without entrainment or curvature (no film: h_min = 0).
    isothermal: Option<IsothermalFilm>,
    /// None without entrainment (Phi_T = 1).
    thermal: Option<ThermalLoading>,
}

/// What the isothermal minimum film of a line (Moes–Venner) keeps of its line contact.
#[derive(Debug, Clone, Copy)]
struct IsothermalFilm {
    radius: f64,
    /// E' R, N/m.
    load_scale: f64,
    /// (2U)^-1/2 and (2U)^1/2.
    two_u_inverse_root: f64,
    two_u_root: f64,
    moes_venner: MoesVenner,
}

/// What Gupta's thermal factor of a line keeps of its line contact.
#[derive(Debug, Clone, Copy)]
struct ThermalLoading {
    e_prime: f64,
    /// L_T^0.42 and the factor's denominator 1 + 0.213 (1 + 2.23 S^0.83) L_T^0.64.
    lt_042: f64,
    denominator: f64,
}

impl LineFilm {
    /// The film of the contact line `c` (its `line_load` and `pressure` not read) of the
    /// lubricant `lub` between surfaces of reduced modulus `e_prime` (Pa).
    pub fn of(lub: &Lubricant, e_prime: f64, c: &LineContact) -> Self {
        let entrainment = (c.u1 + c.u2).abs();
        // (Written as the early returns they replace: a NaN speed gives a NaN film, as before.)
        let no_entrainment = entrainment <= 0.0;
        let no_film = no_entrainment || c.radius <= 0.0 || !c.radius.is_finite();
        let isothermal = (!no_film).then(|| {
            let u = lub.viscosity * entrainment / (2.0 * e_prime * c.radius);
            let g = lub.pressure_viscosity * e_prime;
            let two_u = 2.0 * u;
            IsothermalFilm {
                radius: c.radius,
                load_scale: e_prime * c.radius,
                two_u_inverse_root: two_u.powf(-0.5),
                two_u_root: two_u.sqrt(),
                moes_venner: MoesVenner::at_l(g * two_u.powf(0.25)),
            }
        });
        let thermal = (!no_entrainment).then(|| {
            let t = lub.temperature;
            let lt = lub.viscosity * lub.thermo_viscosity * entrainment * entrainment
                / (4.0 * lub.thermal_conductivity * t * t);
            let s = 2.0 * (c.u1 - c.u2).abs() / entrainment;
            ThermalLoading {
                e_prime,
                lt_042: lt.powf(0.42),
                denominator: 1.0 + 0.213 * (1.0 + 2.23 * s.powf(0.83)) * lt.powf(0.64),
            }
        });
        Self {
            isothermal,
            thermal,
        }
    }

    /// The minimum film thickness of the contact line `c` (m) where its load leaves no
    /// formula to evaluate: 0 without entrainment or curvature, infinite without load (as
    /// [`min_film_thickness`] gives them); None where the film is the formula's.
    pub fn without_formula(c: &LineContact) -> Option<f64> {
        let entrainment = (c.u1 + c.u2).abs();
        if entrainment <= 0.0 || c.radius <= 0.0 || !c.radius.is_finite() {
            return Some(0.0);
        }
        (c.line_load.max(0.0) <= 0.0).then_some(f64::INFINITY)
    }

    /// Isothermal minimum film thickness (Moes–Venner) under the line load `line_load` (N/m),
    /// m; infinite without load.
    pub fn min_film_thickness(&self, line_load: f64) -> f64 {
        let Some(f) = &self.isothermal else {
            return 0.0;
        };
        let w = line_load.max(0.0) / f.load_scale;
        if w <= 0.0 {
            // No load: the film is not limited by the load (the formula's M -> 0 limit diverges).
            return f64::INFINITY;
        }
        let m = w * f.two_u_inverse_root;
        f.moes_venner.at(m) * f.radius * f.two_u_root
    }

    /// Gupta's thermal reduction factor at the peak pressure `pressure` (Pa), in (0, 1].
    pub fn thermal_factor(&self, pressure: f64) -> f64 {
        let Some(t) = &self.thermal else {
            return 1.0;
        };
        let phi = (1.0 - 13.2 * (pressure / t.e_prime) * t.lt_042) / t.denominator;
        phi.clamp(f64::MIN_POSITIVE, 1.0)
    }
}

/// Film thickness, thermal factor and film ratio at a point of a contact line, at the
/// lubricant's composite roughness.
pub fn film(lub: &Lubricant, e_prime: f64, c: &LineContact) -> Film {
    film_over(lub, e_prime, c, lub.composite_roughness)
}

/// [`film`] over a flank point of composite roughness `roughness` (R_q, m; MODEL §6.1).
pub fn film_over(lub: &Lubricant, e_prime: f64, c: &LineContact, roughness: f64) -> Film {
    let h_min = min_film_thickness(lub, e_prime, c);
    let thermal_factor = thermal_factor(lub, e_prime, c);
    Film {
        h_min,
        thermal_factor,
        lambda: h_min * thermal_factor / roughness,
    }
}

/// The composite roughness R_q (m) of every node of a flank worn `removal` deep (m, normal to
/// the flank, on its node grid; MODEL §6.1: [`Lubricant::roughness_after`]). None where it is
/// the lubricant's `composite_roughness` everywhere: no running-in, running in to the initial
/// roughness, or an unworn flank.
pub fn running_in_roughness(lub: &Lubricant, removal: Option<&FlankField>) -> Option<FlankField> {
    lub.running_in
        .filter(|r| r.roughness != lub.composite_roughness)?;
    let removal = removal.filter(|f| f.values.iter().any(|&h| h > 0.0))?;
    Some(FlankField {
        values: removal
            .values
            .iter()
            .map(|&h| lub.roughness_after(h))
            .collect(),
        ..removal.clone()
    })
}

/// The composite roughness over a loaded flank (MODEL §6.1): the lubricant's, uniform, or a
/// field on the flank's nodes ([`running_in_roughness`]).
#[derive(Debug, Clone, Copy)]
pub struct FlankRoughness<'a> {
    /// R_q where there is no field, m.
    pub uniform: f64,
    /// R_q per node of the flank, m, and the flank.
    pub field: Option<(&'a FlankField, &'a WheelFlank)>,
}

impl<'a> FlankRoughness<'a> {
    /// The lubricant's uniform roughness, or `field` on the flank `wf` where given.
    pub fn of(lub: &Lubricant, field: Option<&'a FlankField>, wf: &'a WheelFlank) -> Self {
        Self {
            uniform: lub.composite_roughness,
            field: field.map(|f| (f, wf)),
        }
    }

    /// R_q at flank point (r, z) of the reference tooth (m), linear between nodes.
    pub fn at(&self, r: f64, z: f64) -> f64 {
        match self.field {
            Some((f, wf)) => f.at(wf, r, z),
            None => self.uniform,
        }
    }

    /// The area-weighted mean of R_q over the active flank and its smallest value there
    /// (cell means of the nodes' values), m.
    pub fn over_active(&self, wf: &WheelFlank) -> (f64, f64) {
        let Some((f, _)) = self.field else {
            return (self.uniform, self.uniform);
        };
        let (mut sum, mut area, mut least) = (0.0, 0.0, f64::INFINITY);
        let cells = f.cell_means();
        for ((v, a), _) in cells
            .iter()
            .zip(&wf.cell_area)
            .zip(&wf.active)
            .filter(|c| *c.1)
        {
            sum += v * a;
            area += a;
            least = least.min(*v);
        }
        if area > 0.0 {
            (sum / area, least)
        } else {
            (self.uniform, self.uniform)
        }
    }

    /// R_q at node k of the flank's grid, m.
    pub fn node(&self, k: usize) -> f64 {
        match self.field {
            Some((f, _)) => f.values[k],
            None => self.uniform,
        }
    }
}

/// Local wear coefficient k(lambda) (MODEL §6): K in boundary lubrication (lambda <= 0.5),
/// decreasing linearly (2/7) K (4 - lambda) through the mixed regime, 0 above lambda = 4.
pub fn wear_coefficient(k_dry: f64, lambda: f64) -> f64 {
    if lambda <= 0.5 {
        k_dry
    } else if lambda <= 4.0 {
        2.0 / 7.0 * k_dry * (4.0 - lambda)
    } else {
        0.0
    }
}

/// Fraction of the apparent contact area in asperity contact (MODEL §10):
/// A_c / A_0 = (1/2)(1/2)(1 - erf(h / (sqrt(2) sigma))), h the film thickness Phi_T h_min and
/// sigma the composite RMS roughness R_q (both m). 1/4 with no film, tends to 0 as h >> sigma.
pub fn asperity_area_fraction(film_thickness: f64, roughness_rq: f64) -> f64 {
    0.25 * (1.0 - libm::erf(film_thickness / (std::f64::consts::SQRT_2 * roughness_rq)))
}

/// Load carried by the asperities, N (MODEL §10): W_asp = (W_sec / A_c)(A_c / A_0) A_0 with
/// W_sec / A_c = 0.2 E' sqrt(m2 / pi), m2 = Rdq^2 the mean square profile slope. `e_prime` the
/// reduced modulus E' (Pa, MODEL §6), `apparent_area` A_0 (m^2).
pub fn asperity_load(
    e_prime: f64,
    slope_rdq: f64,
    film_thickness: f64,
    roughness_rq: f64,
    apparent_area: f64,
) -> f64 {
    0.2 * e_prime
        * (slope_rdq * slope_rdq / std::f64::consts::PI).sqrt()
        * asperity_area_fraction(film_thickness, roughness_rq)
        * apparent_area
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// MODEL §11's polyglycol at 333 K, composite roughness 1 um (also the friction tests').
    pub(crate) fn oil() -> Lubricant {
        // MODEL §11 polyglycol at 333 K, composite roughness 1 um.
        Lubricant {
            name: "polyglycol".into(),
            viscosity: 0.227,
            pressure_viscosity: 9.5e-9,
            thermo_viscosity: 3200.0,
            thermal_conductivity: 0.148,
            temperature: 333.0,
            composite_roughness: 1e-6,
            running_in: None,
        }
    }

    #[test]
    fn rigid_isoviscous_limit_is_martins_solution() {
        // Martin (1916): h_min = 4.9 eta0 u_m R / w for a rigid cylinder on a plane with an
        // isoviscous oil, u_m = (u1 + u2)/2. Light load, no pressure-viscosity, stiff bodies
        // (validation::analytic::martin_film, the figure of VALIDATION.md).
        let (h, martin) = crate::validation::analytic::martin_film();
        assert!((h / martin - 1.0).abs() < 1e-3, "{h} vs Martin {martin}");
    }

    #[test]
    fn elastic_piezoviscous_regime_agrees_with_dowson_higginson() {
        // Dowson & Higginson's minimum film thickness of a line contact (an independent fit of
        // numerical EHL solutions): h_min/R = 2.65 U^0.70 G^0.54 W^-0.13, with U = eta0 u_m/(E'R),
        // W = w/(E'R), G = alpha E'. The two regressions agree within a few per cent over the
        // usual steel/bronze gear range (4-7 % at these points).
        let lub = oil();
        let e_prime = reduced_modulus(203e9, 0.29, 110e9, 0.29);
        for &(um, w, radius) in &[
            (0.5, 2e5, 0.02),
            (2.0, 2e5, 0.02),
            (1.0, 5e5, 0.01),
            (5.0, 1e6, 0.03),
            (0.2, 1e5, 0.05),
        ] {
            let c = LineContact {
                radius,
                u1: um,
                u2: um,
                line_load: w,
                pressure: 0.0,
            };
            let h = min_film_thickness(&lub, e_prime, &c);
            let u = lub.viscosity * um / (e_prime * radius);
            let wd = w / (e_prime * radius);
            let g = lub.pressure_viscosity * e_prime;
            let dh = 2.65 * u.powf(0.7) * g.powf(0.54) * wd.powf(-0.13) * radius;
            eprintln!(
                "u_m {um} w {w} R {radius}: Moes-Venner {h:.3e} m, Dowson-Higginson {dh:.3e} m"
            );
            assert!((h / dh - 1.0).abs() < 0.08, "{h} vs {dh}");
        }
    }

    #[test]
    fn moes_venner_has_its_asymptotes() {
        // Elastic-isoviscous (L = 0, large M): 2.05 M^-1/5; elastic-piezoviscous (large M and
        // L): 0.99 M^-1/8 L^3/4.
        let m: f64 = 1e4;
        assert!((moes_venner(m, 0.0) / (2.05 * m.powf(-0.2)) - 1.0).abs() < 0.02);
        let (m, l): (f64, f64) = (1e5, 30.0);
        let ep = 0.99 * m.powf(-0.125) * l.powf(0.75);
        assert!((moes_venner(m, l) / ep - 1.0).abs() < 0.05);
    }

    #[test]
    fn thermal_factor_tends_to_one_without_heating() {
        let lub = oil();
        let e_prime = reduced_modulus(203e9, 0.29, 110e9, 0.29);
        let mut last = 0.0;
        for &u in &[1.0, 0.1, 0.01, 0.001, 1e-5] {
            let c = LineContact {
                radius: 0.02,
                u1: u,
                u2: 0.5 * u,
                line_load: 2e5,
                pressure: 5e8,
            };
            let phi = thermal_factor(&lub, e_prime, &c);
            assert!(
                phi > last && phi <= 1.0,
                "Phi_T must rise towards 1 as L_T -> 0"
            );
            last = phi;
        }
        assert!(1.0 - last < 1e-3, "Phi_T at L_T -> 0: {last}");
    }

    #[test]
    fn wear_coefficient_is_continuous() {
        let k = 2.5e-8;
        for &x in &[0.5, 4.0] {
            let (a, b) = (
                wear_coefficient(k, x - 1e-12),
                wear_coefficient(k, x + 1e-12),
            );
            assert!((a - b).abs() < 1e-18, "jump at lambda = {x}");
        }
        assert_eq!(wear_coefficient(k, 0.1), k);
        assert_eq!(wear_coefficient(k, 5.0), 0.0);
    }
}
