//! Standard ratings beside the model (MODEL §9: ISO/TR 14521, DIN 3996, method C formulas):
//! efficiency with its four loss terms, mean Hertz stress sigma_Hm with p_m*, pitting lives
//! N_LI / N_LII / N_L(I+II) and Stahl's N_LI, wear limits. The formulas are written in the
//! standard's units (N/mm^2, mm, rpm, N m); the results are SI, units in the field names.

use crate::input::{GearSet, ProfileType, Torque};
use std::f64::consts::PI;

pub use crate::input::RatingFactors;

/// Ratings of one operating case (units in the names). A quantity whose formula is outside
/// its range is NaN (null in JSON) and `warnings` says why.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Rating {
    pub efficiency: f64,
    /// Mesh efficiency eta_z alone.
    pub mesh_efficiency: f64,
    pub worm_torque_nm: f64,
    pub wheel_torque_nm: f64,
    /// Sliding speed at the reference diameter, m/s.
    pub sliding_speed_m_s: f64,
    /// Mean mesh friction coefficient mu_zm.
    pub friction_coefficient: f64,
    /// Loss terms, W: mesh, churning (idle), bearings, seals.
    pub loss_mesh_w: f64,
    pub loss_churning_w: f64,
    pub loss_bearings_w: f64,
    pub loss_seals_w: f64,
    /// Output power, W.
    pub output_power_w: f64,
    /// Mean Hertz stress parameter p_m* and stress sigma_Hm.
    pub p_m_star: f64,
    pub sigma_hm_mpa: f64,
    /// The wheel material's pitting limit sigma_Hlim, N/mm^2.
    pub pitting_limit_mpa: f64,
    /// Pitting safety S_H = sigma_HG / sigma_Hm.
    pub pitting_safety: f64,
    /// Wheel cycles to first pitting (A_p10 = 2 %), to the end of the growth phase, and the
    /// check value N_L(I+II).
    pub n_li_cycles: f64,
    pub n_lii_cycles: f64,
    pub n_l_i_ii_cycles: f64,
    /// Stahl's N_LI (CuSn12Ni2, polyglycol), valid for sigma_Hm <= 500 N/mm^2 (NaN above).
    pub n_li_stahl_cycles: f64,
    /// Wear limits in the normal section, m: tip not pointed, and from the maximum backlash.
    pub wear_limit_pointed_tip_m: f64,
    pub wear_limit_backlash_m: f64,
    /// Profile shift coefficient x2 and the lead angle at the reference diameter used.
    pub profile_shift: f64,
    pub lead_angle_deg: f64,
    /// Why a quantity above is null (outside its formula's range), and a pitting safety
    /// below 1 (first).
    pub warnings: Vec<String>,
}

/// Pitting lives beyond this many wheel cycles are outside the data of the life formulas
/// (endurance tests end near 1e8): reported null with a warning instead of extrapolated.
pub const LIFE_LIMIT_CYCLES: f64 = 1e10;

/// Efficiencies below this are outside the loss method's range (the no-load losses then take
/// nearly all of the input power and the fixed point for the wheel torque collapses).
pub const EFFICIENCY_FLOOR: f64 = 0.05;

/// Mesh friction of bronze against steel with polyglycol, dip lubrication (MODEL §9):
/// mu_0T = 0.024 + 0.0032 / (v_g + 0.1)^1.71, capped at 0.094.
pub fn base_friction(sliding_speed: f64) -> f64 {
    (0.024 + 0.0032 / (sliding_speed + 0.1).powf(1.71)).min(0.094)
}

/// Rank's wheel cycles to first pitting (A_p10 = 2 %, MODEL §9):
/// N_LI = 1e6 (1 + 0.860 ln(3 v_gm / v_ref)) exp[28.078 - 4.666 ln(520 sigma_Hm / sigma_Hlim)],
/// v_gm the sliding speed at the reference diameter (m/s), v_ref = 3 m/s, stresses in MPa.
/// None outside the formula's range: a speed factor <= 0 (v_gm below 0.31 m/s, where it
/// would give a negative life), a stress that is not positive, or a life beyond
/// [`LIFE_LIMIT_CYCLES`] (outside the data).
pub fn rank_first_pitting_cycles(
    sliding_speed: f64,
    sigma_hm_mpa: f64,
    sigma_hlim_mpa: f64,
) -> Option<f64> {
    rank_formula(sliding_speed, sigma_hm_mpa, sigma_hlim_mpa).filter(|n| *n <= LIFE_LIMIT_CYCLES)
}

/// The stress sigma_Hm, MPa, at which Rank's N_LI (MODEL §9) is `cycles`: the formula
/// inverted, sigma = sigma_Hlim / 520 exp[(28.078 - ln(N / (1e6 f_v))) / 4.666], f_v its speed
/// factor. None where the speed factor is not positive (v_gm below 0.31 m/s) or the cycles or
/// sigma_Hlim are not.
pub fn rank_stress_for_cycles(sliding_speed: f64, cycles: f64, sigma_hlim_mpa: f64) -> Option<f64> {
    let speed = 1.0 + 0.860 * (3.0 * sliding_speed / 3.0).ln();
    if !(speed > 0.0 && cycles > 0.0 && sigma_hlim_mpa > 0.0) {
        return None;
    }
    let log = (28.078 - (cycles / (1e6 * speed)).ln()) / 4.666;
    Some(sigma_hlim_mpa / 520.0 * log.exp()).filter(|s| s.is_finite())
}

/// Rank's N_LI formula itself, None only where its speed factor or stress is not positive.
fn rank_formula(sliding_speed: f64, sigma_hm_mpa: f64, sigma_hlim_mpa: f64) -> Option<f64> {
    let v_ref = 3.0;
    let speed = 1.0 + 0.860 * (3.0 * sliding_speed / v_ref).ln();
    if !(speed > 0.0 && sigma_hm_mpa > 0.0 && sigma_hlim_mpa > 0.0) {
        return None;
    }
    let n = 1e6 * speed * (28.078 - 4.666 * (520.0 * sigma_hm_mpa / sigma_hlim_mpa).ln()).exp();
    n.is_finite().then_some(n)
}

/// Parameter p_m* of the mean Hertz stress (method C). alpha in degrees.
#[allow(clippy::too_many_arguments)]
pub fn p_m_star(
    profile: ProfileType,
    a_mm: f64,
    d_m1_mm: f64,
    x2: f64,
    q1: f64,
    z1: f64,
    z2: f64,
    alpha_deg: f64,
) -> f64 {
    let shift = x2 * x2.abs().powf(3.18);
    let lead = (x2 + 0.005657) / z2 * (z1 / q1).powf(2.6872);
    match profile {
        ProfileType::C => {
            0.1401 + 0.1866 * a_mm / d_m1_mm + 0.0595 * shift + 0.0419 * q1
                - 0.00288 * z2
                - 0.0089 * alpha_deg
                + 35.1417 * lead
        }
        _ => {
            0.1794 + 0.2389 * a_mm / d_m1_mm + 0.0761 * shift + 0.0536 * q1
                - 0.00369 * z2
                - 0.01136 * alpha_deg
                + 44.9814 * lead
        }
    }
}

/// The nominal mean Hertz stress over the wheel's pitting limit above which a loaded analysis
/// warns that the load is beyond what the bronze carries (the wheel yields and runs in within
/// hours; the elastic bending and transmission error are outside the model's range).
pub const OVERLOAD_WARNING: f64 = 1.5;
/// The same ratio above which a loaded analysis is refused: the elastic model's deflections,
/// transmission error and lives are no longer the gear's (a 160-fold torque on the 1/40 gear
/// turned the wheel by 0.74 rad).
pub const OVERLOAD_REFUSAL: f64 = 5.0;

/// How the overload warning of [`Rating::warnings`] begins (the CLI shows it even when quiet).
pub const OVERLOAD_TAG: &str = "overload:";

/// The input field of the gear's torque.
pub(crate) fn torque_field(gear: &GearSet) -> (&'static str, f64) {
    match gear.conditions.torque {
        Torque::Worm(t) => ("conditions.worm_torque_nm", t),
        Torque::Wheel(t) => ("conditions.wheel_torque_nm", t),
    }
}

/// The smallest nominal mean Hertz stress a loaded analysis takes, N/mm^2: below it the
/// contact is narrower than the local mesh resolves and the solver's tolerances exceed the
/// load (a 1e-9 N m torque on the 1/40 gear ended in a non-converged solver).
pub const UNDERLOAD_REFUSAL_MPA: f64 = 1.0;

/// Why the gear's load is outside what a loaded analysis can take (None: it is not): the
/// nominal mean Hertz stress sigma_Hm (MODEL §9) above [`OVERLOAD_REFUSAL`] times the wheel's
/// pitting limit, or an [`underload`] (below [`UNDERLOAD_REFUSAL_MPA`], or a worm torque whose
/// power the no-load and seal losses take whole). The message names the torque field, its
/// value and the torque the bound allows (sigma_Hm grows with the square root of the torque).
pub fn implausible_load(gear: &GearSet) -> Option<String> {
    let r = rate(gear);
    let limit = gear.wheel_material.pitting_limit * 1e-6;
    let ratio = r.sigma_hm_mpa / limit;
    let (field, torque) = torque_field(gear);
    if let Some(why) = underload(gear, &r) {
        let needed = match smallest_torque(gear) {
            Some(t) => format!("give at least about {t:.3e} N m"),
            None => "give a larger torque".into(),
        };
        return Some(format!("{field} = {torque:e}: {why}: {needed}"));
    }
    // (A NaN ratio, from a p_m* outside its formula, is no refusal.)
    if ratio.is_nan() || ratio <= OVERLOAD_REFUSAL {
        return None;
    }
    // sigma_Hm grows with the square root of the wheel torque.
    let allowed = torque * (OVERLOAD_REFUSAL / ratio).powi(2);
    Some(format!(
        "{field} = {torque}: the nominal mean Hertz stress (ISO/TR 14521 sigma_Hm, MODEL §9) \
         would be {:.0} N/mm^2, {ratio:.1} times the wheel's pitting limit \
         (materials.wheel.pitting_limit_mpa = {limit:.0} N/mm^2); a loaded analysis holds to \
         {OVERLOAD_REFUSAL} times (the elastic contact, bending and transmission error are not \
         the gear's beyond): give at most about {allowed:.3e} N m, or check the pitting limit",
        r.sigma_hm_mpa
    ))
}

/// Why the load is below what a loaded analysis takes (None: it is not): a worm torque whose
/// power the no-load and seal losses (MODEL §9, independent of the load) take whole, so that
/// the wheel carries no torque; or the nominal mean Hertz stress sigma_Hm below
/// [`UNDERLOAD_REFUSAL_MPA`].
fn underload(gear: &GearSet, r: &Rating) -> Option<String> {
    if let Torque::Worm(t) = gear.conditions.torque {
        let (losses, input) = (
            r.loss_churning_w + r.loss_seals_w,
            t * gear.conditions.worm_speed,
        );
        if losses >= input {
            return Some(format!(
                "the no-load and seal losses ({losses:.3e} W at {:.0} rpm, MODEL §9) take the \
                 whole input of {input:.3e} W, so the wheel would carry no torque",
                gear.conditions.worm_speed * 60.0 / (2.0 * PI)
            ));
        }
    }
    (r.sigma_hm_mpa.is_nan() || r.sigma_hm_mpa < UNDERLOAD_REFUSAL_MPA).then(|| {
        format!(
            "the nominal mean Hertz stress (ISO/TR 14521 sigma_Hm, MODEL §9) would be {:.3e} \
             N/mm^2, below the {UNDERLOAD_REFUSAL_MPA} N/mm^2 a loaded analysis resolves (at \
             small torques the no-load, bearing and seal losses take most of the input)",
            r.sigma_hm_mpa.max(0.0)
        )
    })
}

/// The smallest torque of the gear's kind (worm or wheel, N m) that is not an [`underload`],
/// to 1 %: doubled from the given torque until it is not, then bisected (the no-load losses
/// make T2 no power of T1). None beyond 1e9 N m.
fn smallest_torque(gear: &GearSet) -> Option<f64> {
    let at = |t: f64| {
        let mut g = gear.clone();
        g.conditions.torque = match gear.conditions.torque {
            Torque::Worm(_) => Torque::Worm(t),
            Torque::Wheel(_) => Torque::Wheel(t),
        };
        underload(&g, &rate(&g)).is_none()
    };
    let (_, given) = torque_field(gear);
    let mut hi = given.abs().max(1e-9);
    while !at(hi) {
        hi *= 2.0;
        if hi > 1e9 {
            return None;
        }
    }
    let mut lo = hi / 2.0;
    while hi - lo > 0.01 * hi {
        let mid = 0.5 * (lo + hi);
        if at(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}

/// The worm and wheel torques (N m) of the operating case: the given one, and the other
/// through the ratio `u` and the total efficiency at the wheel torque (`efficiency_at`; the
/// losses depend on the output, so a fixed point when the worm torque is given).
fn operating_torques(
    torque: &Torque,
    u: f64,
    eta_z: f64,
    efficiency_at: impl Fn(f64) -> f64,
) -> (f64, f64) {
    match *torque {
        Torque::Wheel(t2) => (t2 / (u * efficiency_at(t2)), t2),
        Torque::Worm(t1) => {
            // T2 = T1 u eta(T2): fixed point (the losses are nearly linear in T2).
            let mut t2 = t1 * u * eta_z;
            for _ in 0..100 {
                let next = t1 * u * efficiency_at(t2);
                if (next - t2).abs() <= 1e-12 * t2 {
                    t2 = next;
                    break;
                }
                t2 = next;
            }
            (t1, t2)
        }
    }
}

/// The reduced modulus 2 / ((1 - v1^2)/E1 + (1 - v2^2)/E2) of the worm and wheel materials,
/// N/mm^2 (MODEL §9).
fn reduced_modulus_mpa(gear: &GearSet) -> f64 {
    let e1 = gear.worm_material.youngs_modulus * 1e-6;
    let e2 = gear.wheel_material.youngs_modulus * 1e-6;
    let (v1, v2) = (
        gear.worm_material.poisson_ratio,
        gear.wheel_material.poisson_ratio,
    );
    2.0 / ((1.0 - v1 * v1) / e1 + (1.0 - v2 * v2) / e2)
}

/// The pitting lives of MODEL §9 (cycles): N_LII to the largest pitted area
/// `pitted_area_max_percent`, N_LI-II, and N_LI for steel wheels (NaN above 500 N/mm^2), from
/// the mean Hertz stress and the pitting limit (N/mm^2) and the sliding speed (m/s).
fn pitting_life_cycles(
    sigma_hm: f64,
    sigma_lim: f64,
    v_g: f64,
    pitted_area_max_percent: f64,
) -> (f64, f64, f64) {
    let v_ref = 3.0;
    let n_lii = (pitted_area_max_percent - 2.0) * 1e6
        / (16.212 * (sigma_hm - 180.0) / sigma_lim
            * (1.541 * sigma_hm / sigma_lim - 0.581 * v_g / v_ref).exp());
    let n_l_i_ii =
        3e6 * (v_g / v_ref) * (24.924 - 4.047 * (520.0 * sigma_hm / sigma_lim).ln()).exp();
    let n_li_stahl = if sigma_hm <= 500.0 {
        (2650.0 / sigma_hm).powf(7.8)
    } else {
        f64::NAN
    };
    (n_lii, n_l_i_ii, n_li_stahl)
}

/// The worm's lead angle gamma_m at its reference diameter (rad) and the sliding speed there,
/// v_gm = pi d_m1 n1 / cos(gamma_m) (m/s; MODEL §9).
fn lead_and_sliding_speed(gear: &GearSet) -> (f64, f64) {
    let gamma = gear.worm.lead_angle();
    let rim_speed = gear.worm.reference_radius * gear.conditions.worm_speed;
    (gamma, rim_speed / gamma.cos())
}

/// Mesh efficiency of a screw of lead angle `gamma` (rad) with the friction `mu` (worm
/// driving, MODEL §9): eta_z = tan(gamma) / tan(gamma + atan(mu)).
fn screw_efficiency(gamma: f64, mu: f64) -> f64 {
    gamma.tan() / (gamma + mu.atan()).tan()
}

/// ISO/TR 14521's mesh efficiency with the base friction mu_0T alone, none of the rating's
/// factors Y (MODEL §9): the loaded analysis' first estimate of the wheel torque (MODEL §5.2),
/// which the rating's inputs must not move.
pub fn base_mesh_efficiency(gear: &GearSet) -> f64 {
    let (gamma, v_g) = lead_and_sliding_speed(gear);
    screw_efficiency(gamma, base_friction(v_g))
}

/// Ratings for the gear's operating case with the file's factors. The wheel torque follows
/// from the worm torque by the efficiency (fixed point: the losses depend on the output) or is
/// given.
pub fn rate(gear: &GearSet) -> Rating {
    let factors = &gear.rating;
    let w = &gear.worm;
    let z1 = w.starts as f64;
    let z2 = gear.wheel.teeth as f64;
    let u = z2 / z1;
    let m_x = w.axial_pitch / PI * 1e3; // mm
    let d_m1 = 2.0 * w.reference_radius * 1e3; // mm
    let d_m2 = 2.0 * gear.wheel_reference_radius() * 1e3; // mm
    let a = gear.operating.centre_distance * 1e3; // mm
    let x2 = (a - 0.5 * (d_m1 + d_m2)) / m_x;
    let q1 = d_m1 / m_x;
    let (gamma, v_g) = lead_and_sliding_speed(gear);
    let n1 = gear.conditions.worm_speed * 60.0 / (2.0 * PI); // rpm
    let mu = base_friction(v_g) * factors.friction_factor;
    let eta_z = screw_efficiency(gamma, mu);
    let losses = |t2: f64| {
        let p2 = t2 * (n1 / u) * 2.0 * PI / 60.0;
        let mesh = 0.1 * t2 * n1 / u * (1.0 / eta_z - 1.0);
        let churning = 0.89e-4 * a * n1.powf(4.0 / 3.0);
        let bearings = 0.03 * p2 * a.powf(0.44) * u / d_m2;
        let seals = 11.78e-6 * d_m1 * d_m1 * n1;
        (p2, mesh, churning, bearings, seals)
    };
    let efficiency_at = |t2: f64| {
        let (p2, mesh, churning, bearings, seals) = losses(t2);
        p2 / (p2 + mesh + churning + bearings + seals)
    };
    let (t1, t2) = operating_torques(&gear.conditions.torque, u, eta_z, efficiency_at);
    let (p2, mesh, churning, bearings, seals) = losses(t2);
    let efficiency = p2 / (p2 + mesh + churning + bearings + seals);
    let alpha_deg = match w.profile {
        ProfileType::C => w.axial_pressure_angle.to_degrees(),
        _ => w.normal_pressure_angle.to_degrees(),
    };
    let pm = p_m_star(w.profile, a, d_m1, x2, q1, z1, z2, alpha_deg);
    let sigma_hm = 4.0 / PI * (pm * t2 * 1e3 * reduced_modulus_mpa(gear) / a.powi(3)).sqrt();
    let sigma_lim = gear.wheel_material.pitting_limit * 1e-6;
    let sigma_hg = sigma_lim * factors.pitting_life_factor;
    let (n_lii, n_l_i_ii, n_li_stahl) =
        pitting_life_cycles(sigma_hm, sigma_lim, v_g, factors.pitted_area_max_percent);
    let alpha_0 = w.normal_pressure_angle;
    let n_li = rank_formula(v_g, sigma_hm, sigma_lim).unwrap_or(f64::NAN);
    Rating {
        efficiency,
        mesh_efficiency: eta_z,
        worm_torque_nm: t1,
        wheel_torque_nm: t2,
        sliding_speed_m_s: v_g,
        friction_coefficient: mu,
        loss_mesh_w: mesh,
        loss_churning_w: churning,
        loss_bearings_w: bearings,
        loss_seals_w: seals,
        output_power_w: p2,
        p_m_star: pm,
        sigma_hm_mpa: sigma_hm,
        pitting_limit_mpa: sigma_lim,
        pitting_safety: sigma_hg / sigma_hm,
        n_li_cycles: n_li,
        n_lii_cycles: n_lii,
        n_l_i_ii_cycles: n_l_i_ii,
        n_li_stahl_cycles: n_li_stahl,
        wear_limit_pointed_tip_m: m_x * 1e-3 * gamma.cos() * (PI / 2.0 - 2.0 * alpha_0.tan()),
        wear_limit_backlash_m: 0.3 * m_x * 1e-3 * gamma.cos(),
        profile_shift: x2,
        lead_angle_deg: gamma.to_degrees(),
        warnings: Vec::new(),
    }
    .within_ranges()
}

impl Rating {
    /// The same ratings with every quantity outside its formula's range set to NaN and a
    /// warning saying why (MODEL §9's formulas hold for test-rig conditions only).
    fn within_ranges(mut self) -> Self {
        let w = &mut self.warnings;
        let sigma_hm = self.sigma_hm_mpa;
        let ratio = sigma_hm / self.pitting_limit_mpa;
        if ratio > OVERLOAD_WARNING {
            w.push(format!(
                "{OVERLOAD_TAG} the nominal mean Hertz stress sigma_Hm {sigma_hm:.0} N/mm^2 is \
                 {ratio:.1} times the wheel's pitting limit ({:.0} N/mm^2): beyond \
                 {OVERLOAD_WARNING} times the bronze yields and runs in within hours, and the \
                 elastic bending and transmission error are outside the model's range (refused \
                 above {OVERLOAD_REFUSAL} times)",
                self.pitting_limit_mpa
            ));
        }
        if self.pitting_safety < 1.0 {
            w.push(format!(
                "pitting safety S_H = {:.2} below 1 (ISO/TR 14521 sigma_Hm {sigma_hm:.0} N/mm^2)",
                self.pitting_safety
            ));
        }
        if self.efficiency.is_nan() || self.efficiency < EFFICIENCY_FLOOR {
            w.push(format!(
                "efficiency {:.3e} below {EFFICIENCY_FLOOR}: the no-load losses (churning {:.0} W, \
                 seals {:.0} W) take nearly all of the input power at {:.3} N m, outside the \
                 loss method's range (reported null; the wheel torque and the stresses below \
                 assume it)",
                self.efficiency, self.loss_churning_w, self.loss_seals_w, self.worm_torque_nm
            ));
            self.efficiency = f64::NAN;
        }
        self.n_li_cycles = if self.n_li_cycles.is_nan() {
            w.push(format!(
                "N_LI: Rank's formula needs a sliding speed above 0.31 m/s (here {:.3} m/s) and \
                 a positive stress (reported null)",
                self.sliding_speed_m_s
            ));
            f64::NAN
        } else {
            within_life_data("N_LI", self.n_li_cycles, sigma_hm, w)
        };
        self.n_lii_cycles = if sigma_hm > 180.0 {
            within_life_data("N_LII", self.n_lii_cycles, sigma_hm, w)
        } else {
            w.push(format!(
                "N_LII: Rank's growth formula needs sigma_Hm above 180 N/mm^2 (here \
                 {sigma_hm:.0}; reported null)"
            ));
            f64::NAN
        };
        self.n_l_i_ii_cycles = within_life_data("N_L(I+II)", self.n_l_i_ii_cycles, sigma_hm, w);
        self.n_li_stahl_cycles = if self.n_li_stahl_cycles.is_nan() {
            w.push(format!(
                "Stahl's N_LI holds for sigma_Hm up to 500 N/mm^2 (here {sigma_hm:.0}; reported \
                 null)"
            ));
            f64::NAN
        } else {
            within_life_data("Stahl's N_LI", self.n_li_stahl_cycles, sigma_hm, w)
        };
        self
    }
}

/// A pitting life if it is a positive number of cycles within [`LIFE_LIMIT_CYCLES`]; else NaN
/// and a warning naming the life and the stress.
fn within_life_data(name: &str, cycles: f64, sigma_hm: f64, warnings: &mut Vec<String>) -> f64 {
    if cycles > 0.0 && cycles <= LIFE_LIMIT_CYCLES {
        return cycles;
    }
    warnings.push(
        if cycles > LIFE_LIMIT_CYCLES && cycles.is_finite() || cycles == f64::INFINITY {
            format!(
                "{name} = {cycles:.3e} cycles at sigma_Hm {sigma_hm:.0} N/mm^2 lies beyond \
             {LIFE_LIMIT_CYCLES:e} cycles, outside the formula's data (no pitting expected; \
             reported null)"
            )
        } else {
            format!(
                "{name}: the formula gives {cycles:.3e} cycles at sigma_Hm {sigma_hm:.0} N/mm^2, \
             not a life (reported null)"
            )
        },
    );
    f64::NAN
}
