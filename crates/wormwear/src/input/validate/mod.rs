//! Validation of a parsed gear file and conversion to SI (MODEL §1-3, §11 defaults).
//!
//! Every check names the field, the value and the allowed range. Checks that depend on values
//! already found invalid are skipped, so one mistake gives one message.
//!
//! Rooms, by section of the gear file: `worm` the thread and its tools, `mesh` the wheel, its
//! cutting and the operating mesh, `analysis` the analysis and bending settings, `service` the
//! materials, lubricant, rating factors and conditions, `life` the life plan; here the checker
//! and [`validate`], which calls them in order.

mod analysis;
mod duty;
mod life;
mod mesh;
mod service;
mod worm;

use analysis::*;
use duty::*;
use life::*;
use mesh::*;
use service::*;
use worm::*;

use super::schema::*;
use super::*;

const MM: f64 = 1e-3;
const DEG: f64 = PI / 180.0;

/// Collects field errors.
#[derive(Default)]
struct Checker {
    errors: Vec<FieldError>,
}

/// A number as a message shows it: plainly between 1e-4 and 1e7, in scientific notation
/// outside (1e-300 is not 300 digits).
pub struct Number(pub f64);

impl fmt::Display for Number {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let a = self.0.abs();
        if a == 0.0 || !a.is_finite() || (1e-4..1e7).contains(&a) {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

impl Checker {
    /// Records a problem; a value that reads as a long number is shown as [`Number`] shows it.
    fn fail(&mut self, field: &str, value: impl fmt::Display, problem: impl Into<String>) {
        let mut value = value.to_string();
        if value.len() > 24 {
            if let Ok(v) = value.parse::<f64>() {
                value = Number(v).to_string();
            }
        }
        self.errors.push(FieldError {
            field: field.to_string(),
            value,
            problem: problem.into(),
        });
    }

    /// Finite and inside [lo, hi] (inclusive). Returns the value when valid.
    fn range(&mut self, field: &str, v: f64, lo: f64, hi: f64, unit: &str) -> Option<f64> {
        let (lo_, hi_) = (Number(lo), Number(hi));
        if !v.is_finite() {
            self.fail(
                field,
                v,
                format!("must be a finite number in [{lo_}, {hi_}] {unit}"),
            );
            None
        } else if v < lo || v > hi {
            self.fail(
                field,
                v,
                format!("out of range: allowed [{lo_}, {hi_}] {unit}"),
            );
            None
        } else {
            Some(v)
        }
    }

    /// Finite and strictly positive, at most `hi`.
    fn positive(&mut self, field: &str, v: f64, hi: f64, unit: &str) -> Option<f64> {
        if !v.is_finite() || v <= 0.0 || v > hi {
            self.fail(
                field,
                v,
                format!("must be a finite number > 0 and <= {} {unit}", Number(hi)),
            );
            None
        } else {
            Some(v)
        }
    }

    fn int_range(&mut self, field: &str, v: i64, lo: i64, hi: i64) -> Option<i64> {
        if v < lo || v > hi {
            self.fail(
                field,
                v,
                format!("out of range: allowed integers [{lo}, {hi}]"),
            );
            None
        } else {
            Some(v)
        }
    }

    fn choice<T: Copy>(&mut self, field: &str, v: &str, options: &[(&str, T)]) -> Option<T> {
        let found = options
            .iter()
            .find(|(name, _)| name.eq_ignore_ascii_case(v.trim()));
        match found {
            Some((_, t)) => Some(*t),
            None => {
                let names: Vec<&str> = options.iter().map(|(n, _)| *n).collect();
                self.fail(
                    field,
                    format!("\"{v}\""),
                    format!("must be one of {}", names.join(", ")),
                );
                None
            }
        }
    }
}

/// Cross-field checks of the worm, the hob and the mesh, run only when the fields involved
/// are individually valid.
fn mesh_checks(
    ck: &mut Checker,
    warnings: &mut Vec<String>,
    worm: &ThreadDef,
    hob: &ThreadDef,
    (cutting, op, wheel): (&Placement, &OperatingParts, &WheelParts),
    throat_radius_mm: f64,
) {
    hob_matches_worm(ck, worm, hob);
    if let Some(blank) = BlankRadii::of(op, wheel) {
        let mesh = Mesh {
            worm,
            hob,
            cutting,
            blank,
            worm_offset: op.worm_offset,
            throat_radius_mm,
        };
        mesh.check(ck, warnings);
    }
}

/// The lubricant, its friction law and the housing's heat balance (MODEL §6, §13); each is
/// checked, so their errors all come.
/// `worm_speed_rpm` is the speed the housing's default heat transfer is taken at.
fn oil_parts(
    ck: &mut Checker,
    f: &GearFile,
    worm_speed_rpm: f64,
) -> Option<(Lubricant, FrictionLaw, Housing)> {
    let lubricant = lubricant(ck, &f.lubricant);
    let friction = friction_law(ck, &f.lubricant);
    let housing = housing(ck, &f.housing, &f.lubricant, &f.operating, worm_speed_rpm);
    Some((lubricant?, friction?, housing?))
}

/// The oil's parts ([`oil_parts`]) and the operating point or spectrum ([`operation`]); the
/// lubricant at the oil temperature of the spectrum's bin of the largest load when it has its
/// own.
fn oil_and_operation(
    ck: &mut Checker,
    f: &GearFile,
) -> (Option<(Lubricant, FrictionLaw, Housing)>, Option<Operation>) {
    let ratio = (f.worm.starts > 0 && f.wheel.teeth > 0)
        .then(|| f.wheel.teeth as f64 / f.worm.starts as f64);
    let mut oil = oil_parts(ck, f, reference_speed_rpm(f, ratio));
    let (lube, housing) = (oil.as_ref().map(|o| &o.0), oil.as_ref().map(|o| &o.2));
    let operation = operation(ck, f, lube, housing, ratio);
    if let (Some(o), Some(t)) = (&mut oil, operation.as_ref().and_then(|o| o.oil_temperature)) {
        if t != o.0.temperature {
            o.0 = o.0.at_temperature(t);
        }
    }
    (oil, operation)
}

/// Oil temperatures, degC, over which a lubricant's viscosity–temperature law is read within
/// its data (MODEL §6: viscosity grades measured at 40 and 100 C, a margin either side).
const OIL_DATA_C: (f64, f64) = (0.0, 150.0);

/// The warning for an oil temperature outside [`OIL_DATA_C`].
fn oil_temperature_warning(lubricant: &Lubricant) -> Option<String> {
    let oil_c = lubricant.temperature - 273.15;
    (!(OIL_DATA_C.0..=OIL_DATA_C.1).contains(&oil_c)).then(|| {
        format!(
            "lubricant.temperature_c = {oil_c} degC lies outside {} to {} degC, where an oil's \
             viscosity law rests on its data (grades are measured at 40 and 100 C): the \
             viscosity, film and friction there are extrapolations",
            OIL_DATA_C.0, OIL_DATA_C.1
        )
    })
}

pub(super) fn validate(f: &GearFile) -> Result<GearSet, InputError> {
    let mut ck = Checker::default();
    let mut warnings = Vec::new();
    // Each section in file order, so the errors come in the file's order.
    let worm = thread(&mut ck, "worm", &f.worm);
    let hob = thread(&mut ck, "hob", &f.hob);
    let cutting = cutting_placement(&mut ck, &f.cutting);
    let op = operating_parts(&mut ck, &f.operating);
    let wheel = wheel_parts(&mut ck, &f.wheel);
    let (worm_material, wheel_material) = materials(&mut ck, &f.materials);
    let (oil, operation) = oil_and_operation(&mut ck, f);
    let wear = f.wear.as_ref().and_then(|w| wear_plan(&mut ck, w));
    let rating = rating_factors(&mut ck, &f.rating);
    let bending = bending_plan(&mut ck, &f.bending, &f.worm, &f.wheel, &f.operating);
    let analysis = analysis_settings(&mut ck, &f.analysis, wheel.teeth, wheel.face_width);
    if let (Some(wm), Some(hb)) = (&worm, &hob) {
        let (parts, throat) = ((&cutting, &op, &wheel), f.wheel.throat_radius_mm);
        mesh_checks(&mut ck, &mut warnings, wm, hb, parts, throat);
    }
    if !ck.errors.is_empty() {
        return Err(InputError::Invalid(ck.errors));
    }
    // All Options are Some here: every None above came with an error.
    let (Some(worm), Some(hob), Some(operating), Some(rotation), Some(nominal_a)) = (
        worm,
        hob,
        op.placement(),
        op.rotation,
        op.nominal_centre_distance,
    ) else {
        unreachable_input()?
    };
    let (Some(worm_material), Some(wheel_material), Some(oil), Some(operation)) =
        (worm_material, wheel_material, oil, operation)
    else {
        unreachable_input()?
    };
    let (lubricant, friction, housing) = oil;
    warnings.extend(oil_temperature_warning(&lubricant));
    let (Some(wheel), Some(mut analysis), Some(bending)) = (wheel.blank(), analysis, bending)
    else {
        unreachable_input()?
    };
    if let ContactLaw::Plastic { flow_pressure } = &mut analysis.contact {
        if flow_pressure.is_nan() {
            *flow_pressure = wheel_material.hardness;
        }
    }
    let gear = GearSet {
        title: f.title.clone().unwrap_or_default(),
        worm,
        hob,
        cutting,
        wheel,
        nominal_centre_distance: nominal_a,
        operating,
        rotation,
        worm_material,
        wheel_material,
        lubricant,
        friction,
        housing,
        conditions: operation.conditions,
        duty_cycle: operation.bins,
        analysis,
        wear,
        rating: rating.unwrap_or_default(),
        bending,
        warnings,
    };
    if gear.bending.kind == BendingKind::Fe {
        check_wheel_body(&gear)?;
    }
    Ok(gear)
}

/// Edge relief from (amount um, length mm), defaults 0 (sharp: MODEL §12 i) over 1 mm; the length is at most
/// `max_length` (m).
fn edge_relief(
    ck: &mut Checker,
    amount_field: &str,
    amount: Option<f64>,
    length_field: &str,
    length: Option<f64>,
    (max_length, max_is): (f64, &str),
) -> Option<EdgeRelief> {
    let a = match amount {
        Some(v) => ck.range(amount_field, v, 0.0, 500.0, "um")? * 1e-6,
        None => EdgeRelief::SHARP.amount,
    };
    let l = match length {
        Some(v) => {
            let unit = format!("mm (the longest: {max_is})");
            ck.range(length_field, v, 0.01, max_length / MM, &unit)? * MM
        }
        None => EdgeRelief::SHARP.length.min(max_length),
    };
    Some(EdgeRelief {
        amount: a,
        length: l,
    })
}
