//! The safety table from the model (MODEL §9.1, the standards' method A): pitting from the
//! equivalent pressure below the flank against the bronze's pressure–life curve, wear from the
//! simulated flank loss at the required life against the limits of MODEL §9 (a)-(d), the oil
//! temperature of the heat balance (MODEL §13), the worm's deflection and the wheel's root
//! stress. Each row: the computed value, its allowable, the safety, the minimum and a verdict;
//! an allowable without a citable default is an input, and without it the row says so.

use crate::bending::wheel_root::{RootStresses, ROOT_LEVEL};
use crate::friction::Thermal;
use crate::input::{Endurance, GearSet, SafetyInputs, Torque};
use crate::ltca::Ltca;
use crate::rating::Rating;
use crate::wear::StepRecord;
use std::f64::consts::PI;

/// What a safety row concludes.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// The safety reaches its minimum.
    Pass,
    /// The safety is below its minimum.
    Fail,
    /// An input the row needs is missing (named).
    NeedsInput(String),
    /// The model cannot give the value (why).
    NotComputed(String),
}

impl Verdict {
    /// The verdict as table text: "pass", "FAIL", "needs input: ...", "not computed: ...".
    pub fn text(&self) -> String {
        match self {
            Verdict::Pass => "pass".into(),
            Verdict::Fail => "FAIL".into(),
            Verdict::NeedsInput(what) => format!("needs input: {what}"),
            Verdict::NotComputed(why) => format!("not computed: {why}"),
        }
    }
}

/// One row of the safety table. Values and allowables in `unit`.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SafetyRow {
    pub quantity: String,
    pub symbol: String,
    pub unit: String,
    pub value: Option<f64>,
    pub allowable: Option<f64>,
    /// allowable / value (None where either is missing).
    pub safety: Option<f64>,
    pub minimum: f64,
    pub verdict: Verdict,
    /// How the value and the allowable were obtained, with the figures beside it.
    pub source: String,
    /// The inputs this row reads that the gear file marks as assumed
    /// (`rating.assumed_inputs`), as `rating.` field names; empty: none.
    #[serde(skip_serializing_if = "Vec::is_empty", default)]
    pub assumed: Vec<String>,
}

/// The safety table of one operating case (MODEL §9.1).
#[derive(Debug, Clone, serde::Serialize)]
pub struct SafetyTable {
    /// Application factor K_A on the torque of the strength rows.
    pub application_factor: f64,
    /// Required life in wheel cycles (revolutions), None without a required life.
    pub required_cycles: Option<f64>,
    pub rows: Vec<SafetyRow>,
}

impl SafetyTable {
    /// The rows whose safety is below its minimum.
    pub fn failed(&self) -> impl Iterator<Item = &SafetyRow> {
        self.rows.iter().filter(|r| r.verdict == Verdict::Fail)
    }
}

/// What the table reads from the other stages: the gear, the standard's ratings at K_A times
/// the torque (its torques, and the figures shown beside), the loaded analysis at K_A times
/// the torque, the
/// friction and oil temperature at the nominal torque, the life's records (nominal torque) and
/// the bronze's pressure–life curve.
pub struct SafetyInputsOf<'a> {
    pub gear: &'a GearSet,
    pub iso: &'a Rating,
    pub ltca: &'a Ltca,
    pub thermal: Option<&'a Thermal>,
    pub records: Option<&'a [StepRecord]>,
    pub endurance: Endurance,
    /// The worm FE model's largest deflection at the mesh point over the positions of the
    /// loaded analysis at K_A T, m (None without FE bending).
    pub worm_deflection: Option<f64>,
    /// The wheel's root stresses at K_A T (None: not asked for, i.e. no allowable or no fillet
    /// radius; an error: why they could not be computed).
    pub root_stress: Option<Result<RootStresses, String>>,
    /// The sump temperature's heat balance (None: no balance and no temperature limit; an
    /// error: why the balance has no solution).
    pub sump: Option<Result<Sump, SumpError>>,
    /// The duty cycle's figures (MODEL §14; None for one operating point): S_H then reads
    /// Miner's sum over its bins.
    pub spectrum: Option<&'a crate::spectrum::Spectrum>,
}

/// The heat balance behind S_T.
#[derive(Debug, Clone)]
pub struct Sump {
    pub thermal: Thermal,
    /// Whether it is the run's own (lubricant.temperature = "balance"), else solved for the
    /// table while the run held the lubricant's fixed temperature.
    pub own: bool,
}

/// Why the heat balance gave no sump temperature.
#[derive(Debug, Clone)]
pub struct SumpError {
    pub message: String,
    /// The temperature, degC, below which the oil has no steady state (the housing cannot
    /// reject the loss there): the oil is hotter than it; None for other failures.
    pub above_c: Option<f64>,
}

/// The gear with its torque times `factor` (the rating case of K_A).
pub fn scaled_torque(gear: &GearSet, factor: f64) -> GearSet {
    let mut g = gear.clone();
    g.conditions.torque = match g.conditions.torque {
        Torque::Worm(t) => Torque::Worm(t * factor),
        Torque::Wheel(t) => Torque::Wheel(t * factor),
    };
    g
}

/// The wheel cycles (revolutions) of `hours` at the gear's speed (with a duty cycle, its
/// time-weighted mean speed, MODEL §14).
pub fn cycles_of_hours(gear: &GearSet, hours: f64) -> f64 {
    let u = gear.wheel.teeth as f64 / gear.worm.starts as f64;
    hours * 3600.0 * gear.mean_worm_speed() / (2.0 * PI * u)
}

/// The safety table (MODEL §9.1) in the order root, deflection, pitting, wear, temperature.
pub fn safety_table(s: &SafetyInputsOf) -> SafetyTable {
    let inputs = &s.gear.rating.safety;
    let required_cycles = inputs
        .required_life_hours
        .map(|h| cycles_of_hours(s.gear, h));
    let mut rows = vec![root_row(inputs, s.root_stress.as_ref()), deflection_row(s)];
    rows.push(pitting_row(s, required_cycles));
    rows.push(published_pitting_row(s, required_cycles));
    rows.extend(wear_rows(s, required_cycles));
    rows.push(temperature_row(s));
    mark_assumed(&mut rows, &s.gear.rating.assumed_inputs);
    SafetyTable {
        application_factor: inputs.application_factor,
        required_cycles,
        rows,
    }
}

/// S_W's extrapolation beyond the simulated life that is warned: the required cycles more than
/// this many times the life's last state.
const EXTRAPOLATION_WARNING: f64 = 2.0;

/// The warnings of a safety table: a required life outside the pressure–life curve's data
/// (MODEL §8), S_W extrapolated far beyond the simulated life (`simulated`: its last state's
/// wheel cycles), rows not computed for their value, rows below their minimum.
pub fn warnings(table: &SafetyTable, endurance: Endurance, simulated: Option<f64>) -> Vec<String> {
    let mut warnings = Vec::new();
    if let Some(required) = table.required_cycles {
        let (low, high) = endurance.data_span();
        if required < low || required > high {
            warnings.push(format!(
                "safety: S_H reads the pressure–life curve at the required {required:.3e} wheel \
                 cycles (rating.required_life_h), outside the {low:.2e} to {high:.2e} cycles its \
                 data span (MODEL §8): its allowable there is an extrapolation"
            ));
        }
        if let Some(end) = simulated.filter(|&end| required > EXTRAPOLATION_WARNING * end) {
            warnings.push(format!(
                "safety: S_W extrapolates the life's last slope from {end:.3e} to the required \
                 {required:.3e} wheel cycles ({:.1} times the simulated life); run the life that \
                 far (--cycles {required:.0}) for a simulated figure",
                required / end
            ));
        }
    }
    warnings.extend(table.rows.iter().filter_map(|r| match &r.verdict {
        Verdict::NotComputed(why) if r.value.is_some() && r.allowable.is_some() => Some(format!(
            "safety: {} not computed: {why} ({})",
            r.symbol, r.quantity
        )),
        _ => None,
    }));
    warnings.extend(table.failed().map(|r| match r.safety {
        Some(s) => format!(
            "safety: {} = {s:.2} is below its minimum {} ({})",
            r.symbol, r.minimum, r.quantity
        ),
        None => format!("safety: {} fails ({}): {}", r.symbol, r.quantity, r.source),
    }));
    warnings
}

/// A row from its value and allowable: the safety allowable / value against `minimum`.
fn row(
    (quantity, symbol, unit): (&str, &str, &str),
    value: Option<f64>,
    allowable: Result<f64, Verdict>,
    minimum: f64,
    source: String,
) -> SafetyRow {
    let (allowable, verdict) = match (value, allowable) {
        (_, Err(v)) => (None, Some(v)),
        (None, Ok(a)) => (Some(a), None),
        (Some(_), Ok(a)) => (Some(a), None),
    };
    // The safety is the ratio allowable / value of two positive, finite figures; any other
    // ratio (a value of 0, below 0 as a temperature below 0 C, or infinite) is no safety.
    let ratio = match (value, allowable) {
        (Some(v), Some(a)) if v > 0.0 && v.is_finite() && a.is_finite() => Ok(a / v),
        (Some(v), Some(_)) => Err(Verdict::NotComputed(format!(
            "the value {v:.4} {unit} gives no ratio (it must be above 0 and finite)"
        ))),
        _ => Err(Verdict::NotComputed("no value".into())),
    };
    let safety = ratio.as_ref().ok().copied();
    let verdict = verdict.unwrap_or(match ratio {
        Ok(x) if x >= minimum => Verdict::Pass,
        Ok(_) => Verdict::Fail,
        Err(v) => v,
    });
    SafetyRow {
        quantity: quantity.into(),
        symbol: symbol.into(),
        unit: unit.into(),
        value,
        allowable,
        safety,
        minimum,
        verdict,
        source,
        assumed: Vec::new(),
    }
}

/// The `[rating]` inputs each row reads, by its symbol (MODEL §9.1; the wear rows S_W, S_W,a
/// ... alike), besides its minimum.
fn inputs_read(symbol: &str) -> &'static [&'static str] {
    let symbol = if symbol.starts_with("S_W") {
        "S_W"
    } else {
        symbol
    };
    match symbol {
        "S_F" => &[
            "root_stress_allowable_mpa",
            "root_fillet_radius_mm",
            "application_factor",
        ],
        "S_delta" => &["deflection_limit_um", "application_factor"],
        "S_H" | "S_H,pub" => &["required_life_h", "application_factor"],
        "S_W" => &[
            "required_life_h",
            "thickness_loss_limit_mm",
            "mass_loss_limit_g",
            "starts_per_hour",
        ],
        "S_T" => &["oil_temperature_limit_c"],
        _ => &[],
    }
}

/// Marks each row with the assumed inputs it reads (`assumed`: `[rating]` key names).
fn mark_assumed(rows: &mut [SafetyRow], assumed: &[String]) {
    for r in rows {
        r.assumed = inputs_read(&r.symbol)
            .iter()
            .filter(|name| assumed.iter().any(|a| a == *name))
            .map(|name| format!("rating.{name}"))
            .collect();
    }
}

/// Tooth root (S_F): the linearised root stress of the FE wheel sector with filleted roots
/// under the loaded analysis at K_A T (MODEL §9.1, [`crate::bending::wheel_root`]) against
/// the allowable; computed when both the allowable and the fillet radius are given.
fn root_row(inputs: &SafetyInputs, root: Option<&Result<RootStresses, String>>) -> SafetyRow {
    let allowable = inputs
        .root_stress_allowable
        .map(|a| a * 1e-6)
        .ok_or_else(|| Verdict::NeedsInput("rating.root_stress_allowable_mpa".into()));
    let fillet = inputs.root_fillet_radius.unwrap_or(f64::NAN) * 1e3;
    let (value, source, failure) = match root {
        Some(Ok(r)) => (
            Some(r.interior.stress * 1e-6),
            format!(
                "FE wheel sector (three teeth on the rim, roots filleted with radius {fillet} mm, \
                 refinement {ROOT_LEVEL}) under the loaded analysis's pressures at K_A T at every \
                 position: the linearised normal stress (membrane + bending, ASME VIII-2 5-A) \
                 across the tooth's section between its fillets' mid points, largest over the \
                 positions and the sections from one module inside the face ends (position {}, \
                 z = {:.1} mm); within a module of the face ends {:.1} MPa (information: not \
                 converged under refinement)",
                r.interior.position,
                r.interior.z * 1e3,
                r.face_ends.stress * 1e-6
            ),
            None,
        ),
        Some(Err(e)) => (None, String::new(), Some(Verdict::NotComputed(e.clone()))),
        None => (
            None,
            "FE wheel sector with filleted roots (MODEL §9.1)".into(),
            inputs
                .root_fillet_radius
                .is_none()
                .then(|| Verdict::NeedsInput("rating.root_fillet_radius_mm".into())),
        ),
    };
    let mut r = row(
        ("Wheel tooth root stress", "S_F", "MPa"),
        value,
        allowable,
        inputs.minimum[0],
        source,
    );
    if let (Some(v), true) = (failure, r.allowable.is_some()) {
        r.verdict = v;
    }
    r
}

/// Worm deflection (S_delta) at the mesh point: the shaft as a simply supported beam of the
/// root diameter between the bearings under the resultant of the tangential and radial mesh
/// forces at K_A times the torque (Roark's Formulas for Stress and Strain, simply supported
/// beam under a concentrated load: y = F a^2 b^2 / (3 E I l)), m.
pub fn simple_beam_deflection(gear: &GearSet, worm_torque: f64, wheel_torque: f64) -> f64 {
    let w = &gear.worm;
    let d_m1 = 2.0 * w.reference_radius;
    let d_m2 = 2.0 * gear.wheel_reference_radius();
    let gamma = (w.lead() / (PI * d_m1)).atan();
    let tangential = 2.0 * worm_torque / d_m1;
    let axial = 2.0 * wheel_torque / d_m2;
    let radial = axial * w.normal_pressure_angle.tan() / gamma.cos();
    let force = tangential.hypot(radial);
    let [b1, b2] = gear.bending.worm_bearings;
    let (a, b) = ((0.0 - b1).abs(), (b2 - 0.0).abs());
    let l = a + b;
    let inertia = PI * (2.0 * w.root_radius).powi(4) / 64.0;
    force * a * a * b * b / (3.0 * gear.worm_material.youngs_modulus * inertia * l)
}

fn deflection_row(s: &SafetyInputsOf) -> SafetyRow {
    let inputs = &s.gear.rating.safety;
    let beam = simple_beam_deflection(s.gear, s.iso.worm_torque_nm, s.iso.wheel_torque_nm);
    let (value, source) = match s.worm_deflection {
        Some(fe) => (
            fe,
            format!(
                "the worm FE model with its shaft and bearings (MODEL §5.5) under the loaded \
                 analysis's mesh force at each position, the largest lateral displacement of the \
                 axis in the mesh plane; beside it the simple beam of the root diameter between \
                 the bearings (Roark): {:.2} um, FE / beam {:.3}",
                beam * 1e6,
                fe / beam
            ),
        ),
        None => (
            beam,
            "the simple beam of the root diameter between the bearings under the tangential and \
             radial mesh forces (Roark): [bending] model = \"none\" has no worm FE model"
                .to_string(),
        ),
    };
    row(
        ("Worm deflection at the mesh point", "S_delta", "um"),
        Some(value * 1e6),
        inputs
            .deflection_limit
            .map(|d| d * 1e6)
            .ok_or_else(|| Verdict::NeedsInput("rating.deflection_limit_um".into())),
        inputs.minimum[1],
        source,
    )
}

/// Pitting (S_H): p_eq,2%, the equivalent pressure below the flank exceeded on 2 % of the
/// active flank (MODEL §8.1, "Which p_eq decides"), of the loaded analysis at K_A times the
/// torque (or the duty cycle's damage-equivalent map's, MODEL §14) against the bronze's
/// pressure–life curve at the required cycles (MODEL §8); the largest (an edge's) and the
/// standard's sigma_Hm and S_H beside it.
fn pitting_row(s: &SafetyInputsOf, required_cycles: Option<f64>) -> SafetyRow {
    let inputs = &s.gear.rating.safety;
    let iso = format!(
        "; beside it ISO/TR 14521 (MODEL §9, at K_A T): sigma_Hm {:.0} MPa, S_H {:.2}, \
         N_LI {:.3e} cycles",
        s.iso.sigma_hm_mpa, s.iso.pitting_safety, s.iso.n_li_cycles
    );
    let (value, largest, what) = match s.spectrum {
        Some(spectrum) => (
            spectrum.equivalent_pressure_pa,
            spectrum.equivalent_pressure_max_pa,
            format!(
                "p_eq,2% of the duty cycle's {} bins at their own torques (MODEL §14: at each \
                 cell Miner's sum of each bin's share of the cycles over its life at the cell's \
                 p_eq = max over depth tau_1 / 0.300, unworn, as the constant pressure of the \
                 same life; the value exceeded on 2 % of the active flank)",
                spectrum.bins.len()
            ),
        ),
        None => (
            s.ltca.equivalent_pressure_first_pitting,
            s.ltca.equivalent_pressure_max,
            "p_eq,2%: the equivalent pressure (max over depth tau_1 / 0.300) of the unworn \
             loaded analysis exceeded on 2 % of the active flank, first pitting's area (MODEL \
             §8.1)"
                .to_string(),
        ),
    };
    row(
        ("Pitting: equivalent pressure below the flank", "S_H", "MPa"),
        Some(value * 1e-6),
        required_cycles
            .map(|n| s.endurance.pressure(n) * 1e-6)
            .ok_or_else(|| Verdict::NeedsInput("rating.required_life_h".into())),
        inputs.minimum[2],
        format!(
            "{what} against p_lim(N) = {:.0} MPa (N / {:.3e})^-{} at the required cycles; the \
             largest cell's {:.0} MPa beside it (edges, where the flow pressure binds, MODEL \
             §5.7){iso}",
            s.endurance.reference_pressure * 1e-6,
            s.endurance.life_factor * s.endurance.reference_cycles,
            s.endurance.exponent,
            largest * 1e-6
        ),
    )
}

/// Pitting in the published coupling (MODEL §12 k), beside S_H: the loaded pattern's mean
/// pressure P_mean at K_A times the torque against the stress at which Rank's N_LI (MODEL §9,
/// sigma_Hlim of the wheel's bronze, the sliding speed at the reference diameter) equals the
/// required cycles.
fn published_pitting_row(s: &SafetyInputsOf, required_cycles: Option<f64>) -> SafetyRow {
    let (speed, limit) = (s.iso.sliding_speed_m_s, s.iso.pitting_limit_mpa);
    let allowable = match required_cycles {
        None => Err(Verdict::NeedsInput("rating.required_life_h".into())),
        Some(n) => crate::rating::rank_stress_for_cycles(speed, n, limit).ok_or_else(|| {
            Verdict::NotComputed(format!(
                "Rank's N_LI has no stress for {n:.3e} cycles at a sliding speed of {speed:.2} \
                 m/s (its speed factor is not positive below 0.31 m/s)"
            ))
        }),
    };
    row(
        (
            "Pitting, published coupling: the pattern's mean pressure (Rank's N_LI)",
            "S_H,pub",
            "MPa",
        ),
        Some(s.ltca.mean_pressure * 1e-6),
        allowable,
        s.gear.rating.safety.minimum[2],
        format!(
            "P_mean of the unworn loaded pattern's non-zero cells in place of sigma_Hm in Rank's \
             N_LI (MODEL §9, §12 k: sigma_Hlim {limit:.0} MPa, v_gm {speed:.2} m/s) against the \
             stress at which N_LI is the required cycles"
        ),
    )
}

/// A record quantity at `cycles` ([`along`] the records' (cycles, value) points).
fn at_cycles(records: &[StepRecord], cycles: f64, f: impl Fn(&StepRecord) -> f64) -> (f64, String) {
    let points: Vec<(f64, f64)> = records.iter().map(|r| (r.cycles, f(r))).collect();
    along(&points, cycles)
}

/// The value at `cycles` of the (cycles, value) points: interpolated between them, or
/// extrapolated along the slope of the last two beyond the last (the text says which).
fn along(points: &[(f64, f64)], cycles: f64) -> (f64, String) {
    let last = points[points.len() - 1];
    if let Some(k) = points.iter().position(|p| p.0 >= cycles) {
        if k == 0 {
            return (points[0].1, "simulated".into());
        }
        let (a, b) = (points[k - 1], points[k]);
        let t = (cycles - a.0) / (b.0 - a.0);
        return (a.1 + t * (b.1 - a.1), "simulated".into());
    }
    if points.len() < 2 {
        return (
            last.1,
            format!("held at its value at {:.3e} cycles", last.0),
        );
    }
    let before = points[points.len() - 2];
    let slope = (last.1 - before.1) / (last.0 - before.0);
    (
        last.1 + slope * (cycles - last.0),
        format!(
            "extrapolated from the life's last {:.3e} cycles along its last slope",
            last.0
        ),
    )
}

/// Wear (S_W): each limit of MODEL §9 (a)-(d) against its simulated counterpart at the
/// required cycles (times W_NS = 1 + 0.015 N_S), then the governing (smallest) one first.
fn wear_rows(s: &SafetyInputsOf, required_cycles: Option<f64>) -> Vec<SafetyRow> {
    let minimum = s.gear.rating.safety.minimum[3];
    let missing = |verdict: Verdict| {
        vec![row(
            ("Wear: flank loss at the required life", "S_W", "um"),
            None,
            Err(verdict),
            minimum,
            "MODEL §9.1".into(),
        )]
    };
    let Some(cycles) = required_cycles else {
        return missing(Verdict::NeedsInput("rating.required_life_h".into()));
    };
    let Some(records) = s.records.filter(|r| !r.is_empty()) else {
        return missing(Verdict::NotComputed(
            "needs a life: a [wear] section (`wormwear rating` and `run` simulate it)".into(),
        ));
    };
    let mut rows = wear_limit_rows(s, records, cycles);
    let governing = rows
        .iter()
        .filter(|r| r.safety.is_some())
        .min_by(|a, b| {
            a.safety
                .partial_cmp(&b.safety)
                .unwrap_or(std::cmp::Ordering::Equal)
        })
        .cloned();
    if let Some(mut g) = governing {
        g.source = format!("the smallest of (a)-(d): {}", g.symbol);
        g.quantity = "Wear: flank loss at the required life".into();
        g.symbol = "S_W".into();
        rows.insert(0, g);
    }
    rows
}

/// The rows of the wear limits (a)-(d) of MODEL §9 at `cycles` of the life's `records`.
fn wear_limit_rows(s: &SafetyInputsOf, records: &[StepRecord], cycles: f64) -> Vec<SafetyRow> {
    let inputs = &s.gear.rating.safety;
    let minimum = inputs.minimum[3];
    let starts = 1.0 + 0.015 * inputs.starts_per_hour;
    let w = &s.gear.worm;
    let gamma = (w.lead() / (2.0 * PI * w.reference_radius)).atan();
    let (peak, how) = at_cycles(records, cycles, |r| r.wear_patch_max_m);
    let (backlash, _) = at_cycles(records, cycles, |r| r.backlash_increase_m);
    let (volume, _) = at_cycles(records, cycles, |r| r.worn_volume_m3);
    let equivalent = backlash * w.normal_pressure_angle.cos() * gamma.cos();
    let mass = volume * s.gear.wheel.teeth as f64 * s.gear.wheel_material.density;
    let note = format!(
        "at {cycles:.3e} wheel cycles, {how}; times W_NS = {starts:.3} (MODEL §9, {} starts/h)",
        inputs.starts_per_hour
    );
    let um = |m: f64| m * 1e6;
    let needs = |field: &str| Verdict::NeedsInput(format!("rating.{field}"));
    vec![
        row(
            ("Wear (a): pointed tooth tip", "S_W,a", "um"),
            Some(um(starts * peak)),
            Ok(um(s.iso.wear_limit_pointed_tip_m)),
            minimum,
            format!("largest flank loss (patch mean) against m_x cos(gamma) (pi/2 - 2 tan(alpha_0)), MODEL §9 (a); {note}"),
        ),
        row(
            ("Wear (b): tooth thickness loss", "S_W,b", "um"),
            Some(um(starts * peak)),
            inputs
                .thickness_loss_limit
                .map(|d| um(d * gamma.cos()))
                .ok_or_else(|| needs("thickness_loss_limit_mm")),
            minimum,
            format!("largest flank loss (patch mean) against Delta_s_lim cos(gamma), MODEL §9 (b); {note}"),
        ),
        row(
            ("Wear (c): wheel mass loss", "S_W,c", "g"),
            Some(starts * mass * 1e3),
            inputs
                .mass_loss_limit
                .map(|m| m * 1e3)
                .ok_or_else(|| needs("mass_loss_limit_g")),
            minimum,
            format!("worn volume of a flank x z2 x the bronze's density against Delta_m_lim, MODEL §9 (c); {note}"),
        ),
        row(
            ("Wear (d): backlash", "S_W,d", "um"),
            Some(um(starts * equivalent)),
            Ok(um(s.iso.wear_limit_backlash_m)),
            minimum,
            format!("the simulated backlash increase as a normal flank loss (x cos(alpha_n) cos(gamma)) against 0.3 m_x cos(gamma), MODEL §9 (d); {note}"),
        ),
    ]
}

/// Temperature (S_T): the sump temperature of the heat balance (MODEL §13, nominal torque)
/// against the allowed oil temperature, both in degC.
fn temperature_row(s: &SafetyInputsOf) -> SafetyRow {
    let inputs = &s.gear.rating.safety;
    let limit = inputs
        .oil_temperature_limit
        .map(|t| t - 273.15)
        .ok_or_else(|| Verdict::NeedsInput("rating.oil_temperature_limit_c".into()));
    let (value, source, failure) = match &s.sump {
        Some(Ok(sump)) => (
            Some(
                s.records
                    .filter(|_| sump.own)
                    .into_iter()
                    .flatten()
                    .map(|r| r.friction.oil_temperature_k)
                    .fold(sump.thermal.oil_temperature_k, f64::max)
                    - 273.15,
            ),
            if sump.own {
                "steady sump temperature of the run's heat balance at the nominal torque, the \
                 highest over the life when it ran (MODEL §13), ratio in degC"
                    .to_string()
            } else {
                format!(
                    "steady sump temperature of the housing's heat balance at the nominal torque \
                     (MODEL §13; [housing] or its defaults), solved for this table: the run \
                     itself holds the lubricant's fixed {:.1} C; ratio in degC",
                    s.gear.lubricant.temperature - 273.15
                )
            },
            None,
        ),
        // No steady state below a temperature above the limit: the oil passes the limit,
        // whatever temperature it reaches (a verdict without a value).
        Some(Err(SumpError {
            message,
            above_c: Some(above),
        })) if limit.as_ref().is_ok_and(|l| l < above) => (
            None,
            format!("the heat balance: {message}"),
            Some(Verdict::Fail),
        ),
        Some(Err(e)) => (
            None,
            String::new(),
            Some(Verdict::NotComputed(e.message.clone())),
        ),
        None => (None, "housing heat balance (MODEL §13)".into(), None),
    };
    let mut r = row(
        ("Oil sump temperature", "S_T", "degC"),
        value,
        limit,
        inputs.minimum[4],
        source,
    );
    if let (Some(v), true) = (failure, r.allowable.is_some()) {
        r.verdict = v;
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_simple_beam_matches_the_unit_load_integral_of_the_bending_moment() {
        // An independent route to the deflection under the load: y = integral of M m / (E I)
        // over the span (unit-load method), by the midpoint rule.
        let gear = crate::input::load(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../examples/gear-1x40-design.toml"),
        )
        .unwrap();
        for bearings in [[-0.1, 0.1], [-0.06, 0.14]] {
            let mut g = gear.clone();
            g.bending.worm_bearings = bearings;
            let (t1, t2) = (60.0, 1500.0);
            let y = simple_beam_deflection(&g, t1, t2);
            let w = &g.worm;
            let d_m1 = 2.0 * w.reference_radius;
            let gamma = (w.lead() / (PI * d_m1)).atan();
            let axial = 2.0 * t2 / (2.0 * g.wheel_reference_radius());
            let f = (2.0 * t1 / d_m1).hypot(axial * w.normal_pressure_angle.tan() / gamma.cos());
            let (a, l) = (-bearings[0], bearings[1] - bearings[0]);
            let moment = |x: f64, load: f64| {
                // Simply supported, load at x = a from the first bearing.
                let left = load * (l - a) / l;
                if x <= a {
                    left * x
                } else {
                    left * x - load * (x - a)
                }
            };
            let ei = g.worm_material.youngs_modulus * PI * (2.0 * w.root_radius).powi(4) / 64.0;
            let n = 200_000;
            let dx = l / n as f64;
            let integral: f64 = (0..n)
                .map(|k| {
                    let x = (k as f64 + 0.5) * dx;
                    moment(x, f) * moment(x, 1.0) * dx / ei
                })
                .sum();
            assert!(
                (y / integral - 1.0).abs() < 1e-8,
                "{y} m against {integral} m"
            );
        }
    }

    #[test]
    fn the_wear_at_the_required_life_is_interpolated_or_extrapolated_along_the_last_slope() {
        let points = [(0.0, 0.0), (10.0, 2.0), (20.0, 3.0)];
        let (v, how) = along(&points, 15.0);
        assert!((v - 2.5).abs() < 1e-15 && how == "simulated");
        let (v, how) = along(&points, 40.0);
        assert!(
            (v - 5.0).abs() < 1e-15 && how.starts_with("extrapolated"),
            "{v} {how}"
        );
    }

    #[test]
    fn a_row_passes_at_its_minimum_and_fails_below() {
        let r = |value: f64| row(("q", "S", "u"), Some(value), Ok(2.0), 1.25, String::new());
        assert_eq!(r(1.6).verdict, Verdict::Pass);
        assert_eq!(r(1.6).safety, Some(1.25));
        assert_eq!(r(1.7).verdict, Verdict::Fail);
        let missing = row(
            ("q", "S", "u"),
            Some(1.0),
            Err(Verdict::NeedsInput("x".into())),
            1.0,
            String::new(),
        );
        assert_eq!(
            (missing.safety, missing.verdict),
            (None, Verdict::NeedsInput("x".into()))
        );
        // A value of 0, below 0 (an oil temperature below 0 C in degC) or infinite gives no
        // ratio: not computed, never an infinite or negative safety that passes.
        for value in [0.0, -32.09, f64::INFINITY, f64::NAN] {
            let r = r(value);
            assert_eq!(r.safety, None, "{value}");
            assert!(
                matches!(&r.verdict, Verdict::NotComputed(why) if why.contains("no ratio")),
                "{value}: {:?}",
                r.verdict
            );
        }
    }
}
