//! Validation of a parsed gear file and conversion to SI (MODEL §1-3, §11 defaults).
//!
//! Every check names the field, the value and the allowed range. Checks that depend on values
//! already found invalid are skipped, so one mistake gives one message.

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

pub(super) fn validate(f: &GearFile) -> Result<GearSet, InputError> {
    let mut ck = Checker::default();
    let mut warnings = Vec::new();
    // Each section in file order, so the errors come in the file's order.
    let worm = thread(&mut ck, "worm", &f.worm);
    let hob = thread(&mut ck, "hob", &f.hob);
    let cutting = cutting_placement(&mut ck, &f.cutting);
    let op = operating_parts(&mut ck, &f.operating);
    let wheel = wheel_parts(&mut ck, &f.wheel);
    let worm_material = material(
        &mut ck,
        "materials.worm",
        f.materials.worm.as_ref(),
        default_worm_material(),
    );
    let wheel_material = material(
        &mut ck,
        "materials.wheel",
        f.materials.wheel.as_ref(),
        default_wheel_material(),
    );
    let lubricant = lubricant(&mut ck, &f.lubricant);
    let conditions = conditions(&mut ck, &f.conditions);
    let wear = f.wear.as_ref().and_then(|w| wear_plan(&mut ck, w));
    let rating = rating_factors(&mut ck, &f.rating);
    let bending = bending_plan(&mut ck, &f.bending, &f.worm, &f.wheel, &f.operating);
    let analysis = analysis_settings(&mut ck, &f.analysis, wheel.teeth, wheel.face_width);
    // Cross-field checks, only when the fields involved are individually valid.
    if let (Some(wm), Some(hb)) = (&worm, &hob) {
        hob_matches_worm(&mut ck, wm, hb);
        if let Some(blank) = BlankRadii::of(&op, &wheel) {
            let mesh = Mesh {
                worm: wm,
                hob: hb,
                cutting: &cutting,
                blank,
                worm_offset: op.worm_offset,
                throat_radius_mm: f.wheel.throat_radius_mm,
            };
            mesh.check(&mut ck, &mut warnings);
        }
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
    let (Some(worm_material), Some(wheel_material), Some(lubricant), Some(conditions)) =
        (worm_material, wheel_material, lubricant, conditions)
    else {
        unreachable_input()?
    };
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
        conditions,
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

/// [cutting]: the hob's placement, SI; an invalid field is NaN (its error recorded).
fn cutting_placement(ck: &mut Checker, c: &SettingSpec) -> Placement {
    let a = ck.positive(
        "cutting.centre_distance_mm",
        c.centre_distance_mm,
        10_000.0,
        "mm",
    );
    let offset = ck.range("cutting.offset_mm", c.offset_mm, -1000.0, 1000.0, "mm");
    let tilt = ck.range(
        "cutting.inclination_deg",
        c.inclination_deg,
        -20.0,
        20.0,
        "deg",
    );
    Placement {
        centre_distance: a.unwrap_or(f64::NAN) * MM,
        offset: offset.unwrap_or(f64::NAN) * MM,
        inclination: tilt.unwrap_or(f64::NAN) * DEG,
    }
}

/// [operating], checked field by field (SI; None where the field is invalid).
struct OperatingParts {
    nominal_centre_distance: Option<f64>,
    centre_distance_error: Option<f64>,
    worm_offset: Option<f64>,
    inclination: Option<f64>,
    rotation: Option<Rotation>,
}

impl OperatingParts {
    /// The operating placement: nominal centre distance plus its error.
    fn placement(&self) -> Option<Placement> {
        Some(Placement {
            centre_distance: self.nominal_centre_distance? + self.centre_distance_error?,
            offset: self.worm_offset?,
            inclination: self.inclination?,
        })
    }
}

fn operating_parts(ck: &mut Checker, o: &OperatingSpec) -> OperatingParts {
    let a = ck.positive(
        "operating.centre_distance_mm",
        o.centre_distance_mm,
        10_000.0,
        "mm",
    );
    let da = ck.range(
        "operating.centre_distance_error_mm",
        o.centre_distance_error_mm,
        -1.0,
        1.0,
        "mm",
    );
    let offset = ck.range(
        "operating.worm_offset_mm",
        o.worm_offset_mm,
        -5.0,
        5.0,
        "mm",
    );
    let tilt = ck.range(
        "operating.inclination_deg",
        o.inclination_deg,
        -2.0,
        2.0,
        "deg",
    );
    let rotation = ck.choice(
        "operating.worm_rotation",
        &o.worm_rotation,
        &[
            ("positive", Rotation::Positive),
            ("negative", Rotation::Negative),
        ],
    );
    OperatingParts {
        nominal_centre_distance: a.map(|v| v * MM),
        centre_distance_error: da.map(|v| v * MM),
        worm_offset: offset.map(|v| v * MM),
        inclination: tilt.map(|v| v * DEG),
        rotation,
    }
}

/// [wheel], checked field by field (SI; None where the field is invalid).
struct WheelParts {
    teeth: Option<u32>,
    face_width: Option<f64>,
    outer_radius: Option<f64>,
    throat_radius: Option<f64>,
    rim_thickness: Option<f64>,
    web_thickness: Option<f64>,
    hub_radius: Option<f64>,
    shaft_radius: Option<f64>,
    bearing_positions: Option<Vec<f64>>,
    edge_relief: Option<EdgeRelief>,
}

impl WheelParts {
    /// The blank, when its required fields are valid.
    fn blank(self) -> Option<WheelBlank> {
        Some(WheelBlank {
            teeth: self.teeth?,
            face_width: self.face_width?,
            outer_radius: self.outer_radius?,
            throat_radius: self.throat_radius?,
            rim_thickness: self.rim_thickness,
            web_thickness: self.web_thickness,
            hub_radius: self.hub_radius,
            shaft_radius: self.shaft_radius,
            bearing_positions: self.bearing_positions,
            edge_relief: self.edge_relief.unwrap_or(EdgeRelief::SHARP),
        })
    }
}

fn wheel_parts(ck: &mut Checker, w: &WheelSpec) -> WheelParts {
    let teeth = ck
        .int_range("wheel.teeth", w.teeth, 10, 500)
        .map(|v| v as u32);
    let length =
        |ck: &mut Checker, name: &str, v: f64| ck.positive(name, v, 5000.0, "mm").map(|x| x * MM);
    let face_width = ck
        .positive("wheel.face_width_mm", w.face_width_mm, 2000.0, "mm")
        .map(|v| v * MM);
    let outer_radius = length(ck, "wheel.outer_radius_mm", w.outer_radius_mm);
    let throat_radius = length(ck, "wheel.throat_radius_mm", w.throat_radius_mm);
    let optional =
        |ck: &mut Checker, name: &str, v: Option<f64>| v.and_then(|x| length(ck, name, x));
    let rim_thickness = optional(ck, "wheel.rim_thickness_mm", w.rim_thickness_mm);
    let web_thickness = optional(ck, "wheel.web_thickness_mm", w.web_thickness_mm);
    let hub_radius = optional(ck, "wheel.hub_radius_mm", w.hub_radius_mm);
    let shaft_radius = optional(ck, "wheel.shaft_radius_mm", w.shaft_radius_mm);
    let bearing_positions = w.bearing_positions_mm.as_ref().map(|v| {
        v.iter()
            .enumerate()
            .map(|(i, &x)| {
                let name = format!("wheel.bearing_positions_mm[{i}]");
                ck.range(&name, x, -5000.0, 5000.0, "mm")
                    .unwrap_or(f64::NAN)
                    * MM
            })
            .collect::<Vec<_>>()
    });
    if let (Some(re), Some(ra)) = (outer_radius, throat_radius) {
        if re < ra {
            let problem = format!("must be >= wheel.throat_radius_mm = {}", w.throat_radius_mm);
            ck.fail("wheel.outer_radius_mm", w.outer_radius_mm, problem);
        }
    }
    let edge_relief = face_width.and_then(|b| {
        edge_relief(
            ck,
            "wheel.edge_relief_um",
            w.edge_relief_um,
            "wheel.edge_relief_length_mm",
            w.edge_relief_length_mm,
            (0.25 * b, "a quarter of wheel.face_width_mm"),
        )
    });
    if let (Some(hub), Some(sh)) = (hub_radius, shaft_radius) {
        if sh >= hub {
            let problem = format!(
                "must be < wheel.hub_radius_mm = {}",
                w.hub_radius_mm.unwrap_or_default()
            );
            ck.fail(
                "wheel.shaft_radius_mm",
                w.shaft_radius_mm.unwrap_or_default(),
                problem,
            );
        }
    }
    WheelParts {
        teeth,
        face_width,
        outer_radius,
        throat_radius,
        rim_thickness,
        web_thickness,
        hub_radius,
        shaft_radius,
        bearing_positions,
        edge_relief,
    }
}

/// The worm's material when the file gives none (MODEL §11).
fn default_worm_material() -> Material {
    Material {
        name: "case-hardened steel (default)".into(),
        youngs_modulus: 203e9,
        poisson_ratio: 0.29,
        hardness: 7.0e9,
        wear_coefficient: 0.0,
        density: 7850.0,
        pitting_limit: f64::INFINITY,
    }
}

/// The wheel's material when the file gives none (MODEL §11).
fn default_wheel_material() -> Material {
    Material {
        name: "chill-cast phosphor bronze CuSn12 (default)".into(),
        youngs_modulus: 110e9,
        poisson_ratio: 0.29,
        hardness: 1.0e9,
        wear_coefficient: 2.5e-8,
        density: 8800.0,
        pitting_limit: 425e6,
    }
}

/// [analysis] with its defaults; None when a field is invalid (its error recorded).
fn analysis_settings(
    ck: &mut Checker,
    a: &AnalysisSpec,
    teeth: Option<u32>,
    face_width: Option<f64>,
) -> Option<Analysis> {
    let height = ck.int_range("analysis.flank_cells_height", a.flank_cells_height, 4, 400);
    let face = ck.int_range("analysis.flank_cells_face", a.flank_cells_face, 4, 400);
    let positions = ck.int_range("analysis.positions", a.positions, 4, 720);
    let teeth_each_side = ck.int_range("analysis.teeth_each_side", a.teeth_each_side, 1, 10);
    let marking = ck
        .positive(
            "analysis.marking_thickness_um",
            a.marking_thickness_um,
            1000.0,
            "um",
        )
        .map(|v| v * 1e-6);
    let stl_threads = ck.int_range("analysis.stl_worm_threads", a.stl_worm_threads, 1, 50);
    let stl_teeth = ck.int_range("analysis.stl_wheel_teeth", a.stl_wheel_teeth, 0, 500);
    let contact = contact_settings(ck, a);
    if let (Some(n), Some(z2)) = (stl_teeth, teeth) {
        if n > z2 as i64 {
            let problem = format!("allowed [0, wheel.teeth = {z2}] (0 = all)");
            ck.fail("analysis.stl_wheel_teeth", n, problem);
        }
    }
    let section_offsets = section_offsets(ck, a, face_width);
    let mut analysis = contact?;
    analysis.flank_cells_height = height? as usize;
    analysis.flank_cells_face = face? as usize;
    analysis.positions = positions? as usize;
    analysis.teeth_each_side = teeth_each_side? as usize;
    analysis.marking_thickness = marking?;
    analysis.section_offsets = section_offsets;
    analysis.stl_worm_threads = stl_threads? as usize;
    analysis.stl_wheel_teeth = stl_teeth? as usize;
    Some(analysis)
}

/// The contact law of `[analysis]` (MODEL §5.7): `contact` plastic (default) or elastic,
/// `flow_pressure_mpa`; the former `contact_pressure_cap_mpa` is refused naming them. The flow
/// pressure's default, the wheel's hardness, is filled in by `validate` (NaN here).
fn contact_law(ck: &mut Checker, a: &AnalysisSpec) -> Option<ContactLaw> {
    if let Some(v) = a.contact_pressure_cap_mpa {
        ck.fail(
            "analysis.contact_pressure_cap_mpa",
            v,
            "is no longer read: the bronze's plastic limit is now the default (MODEL §5.7); \
             set analysis.flow_pressure_mpa (default: the wheel's hardness) for another bound, \
             or analysis.contact = \"elastic\" for none",
        );
    }
    let flow = a
        .flow_pressure_mpa
        .map(|v| ck.range("analysis.flow_pressure_mpa", v, 10.0, 100_000.0, "MPa"));
    let law = ck.choice(
        "analysis.contact",
        a.contact.as_deref().unwrap_or("plastic"),
        &[("plastic", true), ("elastic", false)],
    );
    match (law, flow) {
        (Some(true), None) => Some(ContactLaw::Plastic {
            flow_pressure: f64::NAN,
        }),
        (Some(true), Some(v)) => v.map(|v| ContactLaw::Plastic {
            flow_pressure: v * 1e6,
        }),
        (Some(false), _) => Some(ContactLaw::Elastic),
        (None, _) => None,
    }
}

/// The loaded analysis' settings of [analysis] (the grid and output fields left at zero for
/// [`analysis_settings`] to fill).
fn contact_settings(ck: &mut Checker, a: &AnalysisSpec) -> Option<Analysis> {
    let slice_step = ck.int_range("analysis.contact_slice_step", a.contact_slice_step, 1, 20);
    let columns = ck.int_range("analysis.contact_columns", a.contact_columns, 3, 200);
    let contact = contact_law(ck, a);
    let across = a.pressure_patch_across_mm;
    let across = ck.range(
        "analysis.pressure_patch_across_mm",
        across,
        0.01,
        100.0,
        "mm",
    );
    let along = a.pressure_patch_along_mm;
    let along = ck.range(
        "analysis.pressure_patch_along_mm",
        along,
        0.01,
        1000.0,
        "mm",
    );
    let unit = "Hertz half-widths";
    let band = ck.range(
        "analysis.contact_band_factor",
        a.contact_band_factor,
        1.0,
        50.0,
        unit,
    );
    let direction = ck.choice(
        "analysis.pressure_direction",
        a.pressure_direction.as_deref().unwrap_or("worm-flank"),
        &[
            ("worm-flank", PressureDirection::WormFlank),
            ("wheel-flank", PressureDirection::WheelFlank),
        ],
    );
    use super::SolverKind;
    let solver = ck.choice(
        "analysis.solver",
        &a.solver,
        &[
            ("conjugate-gradient", SolverKind::ConjugateGradient),
            ("fixed-point", SolverKind::FixedPoint),
        ],
    );
    Some(Analysis {
        flank_cells_height: 0,
        flank_cells_face: 0,
        positions: 0,
        teeth_each_side: 0,
        marking_thickness: 0.0,
        section_offsets: Vec::new(),
        stl_worm_threads: 0,
        stl_wheel_teeth: 0,
        contact_slice_step: slice_step? as usize,
        contact_columns: columns? as usize,
        contact_band_factor: band?,
        contact: contact?,
        pressure_patch_across: across? * 1e-3,
        pressure_patch_along: along? * 1e-3,
        solver: solver?,
        pressure_direction: direction?,
    })
}

/// The offsets of the drawn sections, m: the file's (inside the face width, at most 50),
/// else -b/4, 0, b/4.
fn section_offsets(ck: &mut Checker, a: &AnalysisSpec, face_width: Option<f64>) -> Vec<f64> {
    // Each section is a profile computation and a plot: a few dozen is plenty.
    const MAX_SECTIONS: usize = 50;
    if let Some(v) = a
        .section_offsets_mm
        .as_ref()
        .filter(|v| v.len() > MAX_SECTIONS)
    {
        ck.fail(
            "analysis.section_offsets_mm",
            format!("{} offsets", v.len()),
            format!("at most {MAX_SECTIONS} sections"),
        );
    }
    match (&a.section_offsets_mm, face_width) {
        (Some(v), Some(b)) if v.len() <= MAX_SECTIONS => v
            .iter()
            .enumerate()
            .filter_map(|(i, &z)| {
                ck.range(
                    &format!("analysis.section_offsets_mm[{i}]"),
                    z,
                    -0.5 * b / MM,
                    0.5 * b / MM,
                    "mm (inside wheel.face_width_mm)",
                )
                .map(|z| z * MM)
            })
            .collect(),
        (None, Some(b)) => vec![-0.25 * b, 0.0, 0.25 * b],
        _ => vec![],
    }
}

/// The hob must have the worm's axial pitch and hand.
fn hob_matches_worm(ck: &mut Checker, wm: &ThreadDef, hb: &ThreadDef) {
    if ((hb.axial_pitch - wm.axial_pitch) / wm.axial_pitch).abs() > 1e-6 {
        ck.fail(
            "hob.axial_module_mm",
            format!(
                "{:.6} (lead {:.6} mm)",
                hb.axial_module() / MM,
                hb.lead() / MM
            ),
            format!(
                "the hob must have the worm's axial pitch (worm.lead_mm / worm.starts, or worm.\
                 axial_module_mm): axial module {:.6} mm (relative difference allowed 1e-6)",
                wm.axial_module() / MM
            ),
        );
    }
    if hb.hand != wm.hand {
        ck.fail(
            "hob.hand",
            format!("{:?}", hb.hand),
            format!("must equal worm.hand ({:?})", wm.hand),
        );
    }
}

/// The blank's valid radii and the centre distance, SI.
struct BlankRadii {
    nominal_centre_distance: f64,
    teeth: u32,
    face_width: f64,
    outer_radius: f64,
    throat_radius: f64,
}

impl BlankRadii {
    fn of(op: &OperatingParts, w: &WheelParts) -> Option<Self> {
        Some(Self {
            nominal_centre_distance: op.nominal_centre_distance?,
            teeth: w.teeth?,
            face_width: w.face_width?,
            outer_radius: w.outer_radius?,
            throat_radius: w.throat_radius?,
        })
    }
}

/// Worm, hob and blank together: what must fit for the wheel to be cut and to mesh.
struct Mesh<'a> {
    worm: &'a ThreadDef,
    hob: &'a ThreadDef,
    cutting: &'a Placement,
    blank: BlankRadii,
    worm_offset: Option<f64>,
    throat_radius_mm: f64,
}

impl Mesh<'_> {
    fn check(&self, ck: &mut Checker, warnings: &mut Vec<String>) {
        self.radial_clearances(ck, warnings);
        self.profile_shift(ck, warnings);
        if self.throat_in_range(ck) {
            self.face_width(ck);
        }
        let lead_diff = self.hob.lead_angle() - self.worm.lead_angle();
        if (lead_diff - self.cutting.inclination).abs() > 1.0 * DEG {
            warnings.push(format!(
                "hob lead angle differs from the worm's by {:.3} deg and the hob inclination is \
                 {:.3} deg: the wheel will have a lead mismatch",
                lead_diff / DEG,
                self.cutting.inclination / DEG
            ));
        }
    }

    /// The worm root clears the wheel throat; the hob root does not cut the blank's throat;
    /// the hob tip cuts the wheel root deep enough for the worm tip.
    fn radial_clearances(&self, ck: &mut Checker, warnings: &mut Vec<String>) {
        let (wm, hb) = (self.worm, self.hob);
        let (an, ra) = (self.blank.nominal_centre_distance, self.blank.throat_radius);
        let a0 = self.cutting.centre_distance;
        if an - ra <= wm.root_radius {
            ck.fail(
                "wheel.throat_radius_mm",
                self.throat_radius_mm,
                format!(
                    "must be < operating.centre_distance_mm - worm.root_radius_mm = {:.6} mm \
                     (the wheel tip would hit the worm root)",
                    (an - wm.root_radius) / MM
                ),
            );
        }
        if !a0.is_finite() {
            return;
        }
        if a0 - ra < hb.root_radius {
            ck.fail(
                "hob.root_radius_mm",
                hb.root_radius / MM,
                format!(
                    "must be <= cutting.centre_distance_mm - wheel.throat_radius_mm = {:.6} mm \
                     (the hob root would cut the wheel tip)",
                    (a0 - ra) / MM
                ),
            );
        }
        let clearance = (an - wm.tip_radius) - (a0 - hb.tip_radius);
        if clearance < 0.0 {
            ck.fail(
                "hob.tip_radius_mm",
                hb.tip_radius / MM,
                format!(
                    "must be >= worm.tip_radius_mm + cutting.centre_distance_mm - \
                     operating.centre_distance_mm = {:.6} mm (the worm tip would hit the wheel \
                     root)",
                    (wm.tip_radius + a0 - an) / MM
                ),
            );
        }
        if hb.tip_radius < wm.tip_radius + a0 - an + 1e-9 && clearance >= 0.0 {
            warnings
                .push("no bottom clearance: the hob tip radius equals the worm tip radius".into());
        }
    }

    /// The centre distance must be consistent with the radii (implied wheel profile shift).
    fn profile_shift(&self, ck: &mut Checker, warnings: &mut Vec<String>) {
        let wm = self.worm;
        let (an, ra) = (self.blank.nominal_centre_distance, self.blank.throat_radius);
        let r2 = self.blank.teeth as f64 * wm.axial_pitch / (2.0 * PI);
        let x2 = (an - wm.reference_radius - r2) / wm.axial_module();
        if x2.abs() > 1.5 {
            ck.fail(
                "operating.centre_distance_mm",
                an / MM,
                format!(
                    "inconsistent with worm.reference_radius_mm + wheel reference radius \
                     (wheel.teeth x axial module / 2 = {:.4} mm): the implied profile shift x2 = \
                     {:.3} is outside [-1.5, 1.5]",
                    r2 / MM,
                    x2
                ),
            );
        } else if x2.abs() > 1.0 {
            warnings.push(format!("large wheel profile shift x2 = {x2:.3}"));
        }
        if ra < r2 && ra >= self.lowest_throat() {
            warnings.push(format!(
                "wheel throat radius {:.3} mm is below the reference radius {:.3} mm",
                ra / MM,
                r2 / MM
            ));
        }
    }

    /// The lowest throat radius a wheel blank may have: two axial modules below the wheel's
    /// reference radius z2 m_x / 2 (a wheel tip below that cuts away the teeth).
    fn lowest_throat(&self) -> f64 {
        let wm = self.worm;
        let r2 = self.blank.teeth as f64 * wm.axial_pitch / (2.0 * PI);
        r2 - 2.0 * wm.axial_module()
    }

    /// Whether the throat radius is at least [`Self::lowest_throat`]; else an error on it
    /// (and the face width, which the throat decides, is not checked).
    fn throat_in_range(&self, ck: &mut Checker) -> bool {
        let (ra, lowest) = (self.blank.throat_radius, self.lowest_throat());
        if ra >= lowest {
            return true;
        }
        ck.fail(
            "wheel.throat_radius_mm",
            ra / MM,
            format!(
                "must be >= {:.3} mm: the wheel's tip (throat) radius is more than two axial \
                 modules below its reference radius z2 m_x / 2 = {:.3} mm",
                lowest / MM,
                (lowest + 2.0 * self.worm.axial_module()) / MM
            ),
        );
        false
    }

    /// The face width the worm can reach (at |z| = b/2 the blank top must be inside the worm
    /// tip cylinder), and the offsets inside it.
    fn face_width(&self, ck: &mut Checker) {
        let bl = &self.blank;
        let b = bl.face_width;
        let gorge = bl.nominal_centre_distance - bl.throat_radius;
        let reach = reachable_half_width(
            bl.nominal_centre_distance,
            bl.outer_radius,
            gorge,
            self.worm.tip_radius,
        );
        if 0.5 * b >= reach {
            ck.fail(
                "wheel.face_width_mm",
                b / MM,
                format!(
                    "larger than the worm can reach: must be < {:.3} mm (twice the half-width \
                     at which the blank top, wheel.outer_radius_mm, leaves the worm tip \
                     cylinder, worm.tip_radius_mm)",
                    2.0 * reach / MM
                ),
            );
        }
        let inside = format!(
            "must be inside the face width: |offset| < {} mm",
            0.5 * b / MM
        );
        if let Some(off) = self.worm_offset.filter(|o| o.abs() >= 0.5 * b) {
            ck.fail("operating.worm_offset_mm", off / MM, inside.clone());
        }
        let off = self.cutting.offset;
        if off.is_finite() && off.abs() >= 0.5 * b {
            ck.fail("cutting.offset_mm", off / MM, inside);
        }
    }
}

/// The wheel body the bending model builds (rim, web, hub, shaft and its bearings), checked
/// with its defaults filled in: each part must fit inside the one around it.
fn check_wheel_body(gear: &GearSet) -> Result<(), InputError> {
    let b = gear.wheel_body();
    let mut errors = Vec::new();
    let mut fail = |field: &str, value: f64, problem: String| {
        errors.push(FieldError {
            field: field.into(),
            value: format!("{:.4} mm", value / MM),
            problem,
        })
    };
    let r_in = b.rim_inner_radius();
    if r_in <= 0.0 {
        fail(
            "wheel.rim_thickness_mm",
            b.rim_thickness,
            format!("must be < the root radius {:.4} mm", b.root_radius / MM),
        );
    } else if b.hub_radius >= r_in {
        fail(
            "wheel.hub_radius_mm",
            b.hub_radius,
            format!(
                "must be < the rim's inner radius (root radius - rim thickness) = {:.4} mm",
                r_in / MM
            ),
        );
    }
    if b.shaft_radius >= b.hub_radius {
        fail(
            "wheel.shaft_radius_mm",
            b.shaft_radius,
            format!("must be < the hub radius {:.4} mm", b.hub_radius / MM),
        );
    }
    if b.web_thickness > gear.wheel.face_width {
        fail(
            "wheel.web_thickness_mm",
            b.web_thickness,
            format!(
                "must be <= the face width (wheel.face_width_mm) {} mm",
                Number(gear.wheel.face_width / MM)
            ),
        );
    }
    match gear.wheel.bearing_positions.as_deref() {
        Some(v) if v.len() != 2 => errors.push(FieldError {
            field: "wheel.bearing_positions_mm".into(),
            value: format!("{:?}", v.iter().map(|x| x / MM).collect::<Vec<_>>()),
            problem: "must hold two positions (the laterally holding bearing, then the fixed end)"
                .into(),
        }),
        _ => {
            let [a, c] = b.bearings;
            let h = b.hub_half_width;
            if !(a.min(c) < -h && a.max(c) > h) {
                errors.push(FieldError {
                    field: "wheel.bearing_positions_mm".into(),
                    value: format!("[{:.4}, {:.4}]", a / MM, c / MM),
                    problem: format!(
                        "need one bearing on each side of the hub, beyond +/- {:.4} mm (half the \
                         face width)",
                        h / MM
                    ),
                });
            }
        }
    }
    if errors.is_empty() {
        Ok(())
    } else {
        Err(InputError::Invalid(errors))
    }
}

/// Bending settings with their defaults (see [`BendingSpec`]).
fn bending_plan(
    ck: &mut Checker,
    b: &BendingSpec,
    worm: &ThreadSpec,
    wheel: &WheelSpec,
    operating: &OperatingSpec,
) -> Option<BendingPlan> {
    let kind = ck.choice(
        "bending.model",
        b.model.as_deref().unwrap_or("none"),
        &[("none", BendingKind::None), ("fe", BendingKind::Fe)],
    );
    let height = ck.int_range("bending.height_points", b.height_points.unwrap_or(5), 2, 9);
    let width = ck.int_range("bending.width_points", b.width_points.unwrap_or(7), 2, 17);
    let worm_width = ck.int_range(
        "bending.worm_width_points",
        b.worm_width_points.unwrap_or(13),
        2,
        21,
    );
    let refinement = ck.int_range(
        "bending.mesh_refinement",
        b.mesh_refinement.unwrap_or(1),
        1,
        3,
    );
    let rf = worm.root_radius_mm;
    let shaft = match b.worm_shaft_radius_mm {
        Some(v) => ck.positive(
            "bending.worm_shaft_radius_mm",
            v,
            rf.max(1e-9),
            "mm (at most the worm root radius)",
        ),
        None => Some(0.75 * rf),
    };
    let reach = operating.centre_distance_mm - worm.tip_radius_mm;
    let default_body = 2.0
        * (wheel.outer_radius_mm.powi(2) - reach.powi(2))
            .max(0.0)
            .sqrt();
    let default_body = default_body.max(2.0 * wheel.face_width_mm);
    let body = match b.worm_body_length_mm {
        Some(v) => ck.positive("bending.worm_body_length_mm", v, 10_000.0, "mm"),
        None => Some(default_body),
    };
    let bearings = match (&b.worm_bearing_positions_mm, body) {
        (Some(v), _) if v.len() != 2 => {
            ck.fail(
                "bending.worm_bearing_positions_mm",
                format!("{v:?}"),
                "must hold two positions (drive side first)",
            );
            None
        }
        (Some(v), Some(body)) => {
            let (lo, hi) = (v[0].min(v[1]), v[0].max(v[1]));
            if !(lo.is_finite() && hi.is_finite()) || lo > -0.5 * body || hi < 0.5 * body {
                ck.fail(
                    "bending.worm_bearing_positions_mm",
                    format!("{v:?}"),
                    format!(
                        "the bearings must lie outside the worm body, beyond +/- {:.1} mm",
                        0.5 * body
                    ),
                );
                None
            } else {
                Some([v[0] * MM, v[1] * MM])
            }
        }
        (None, Some(body)) => {
            let x = 0.5 * body + 2.0 * rf;
            Some([-x * MM, x * MM])
        }
        _ => None,
    };
    Some(BendingPlan {
        kind: kind?,
        height_points: height? as usize,
        width_points: width? as usize,
        worm_width_points: worm_width? as usize,
        mesh_refinement: refinement? as usize,
        worm_shaft_radius: shaft? * MM,
        worm_body_length: body? * MM,
        worm_bearings: bearings?,
    })
}

/// Internal consistency guard: a missing value without a recorded error is a bug, reported as
/// an error rather than a panic.
fn unreachable_input<T>() -> Result<T, InputError> {
    Err(InputError::Invalid(vec![FieldError {
        field: "(internal)".into(),
        value: "-".into(),
        problem: "validation lost a value without reporting why; please report this file".into(),
    }]))
}

/// Largest |z| at which the wheel blank top (outer cylinder clipped by the throat torus) is
/// still inside the worm tip cylinder of radius `tip` (worm axis at distance `a`). m.
fn reachable_half_width(a: f64, outer: f64, gorge: f64, tip: f64) -> f64 {
    let top_distance = |z: f64| {
        let r_top = if z.abs() < gorge {
            outer.min(a - (gorge * gorge - z * z).sqrt())
        } else {
            outer
        };
        ((a - r_top).powi(2) + z * z).sqrt()
    };
    if top_distance(0.0) >= tip {
        return 0.0;
    }
    let (mut lo, mut hi) = (0.0, tip);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if top_distance(mid) < tip {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

fn thread(ck: &mut Checker, name: &str, t: &ThreadSpec) -> Option<ThreadDef> {
    let field = |f: &str| format!("{name}.{f}");
    let n_errors = ck.errors.len();
    let profile = profile_choice(ck, &field("profile"), &t.profile);
    let starts = ck.int_range(&field("starts"), t.starts, 1, 10);
    let hand = ck.choice(
        &field("hand"),
        &t.hand,
        &[("right", Hand::Right), ("left", Hand::Left)],
    );
    let axial_pitch = axial_pitch(ck, name, t, starts);
    let (r1, ra, rf) = thread_radii(ck, name, t);
    let (alpha, plane, thickness) = flank_inputs(ck, name, t);
    grinding_wheel_presence(
        ck,
        &field("grinding_wheel"),
        profile,
        t.grinding_wheel.is_some(),
    );
    if ck.errors.len() > n_errors {
        return None;
    }
    let (profile, starts, hand, p_x, r1, ra, rf, alpha, axial_plane, s) = (
        profile?,
        starts?,
        hand?,
        axial_pitch?,
        r1? * MM,
        ra? * MM,
        rf? * MM,
        alpha? * DEG,
        plane?,
        thickness? * MM,
    );
    let lead_angle = lead_angle(ck, name, starts, p_x, r1)?;
    let (alpha_x, alpha_n) = if axial_plane {
        (alpha, (alpha.tan() * lead_angle.cos()).atan())
    } else {
        ((alpha.tan() / lead_angle.cos()).atan(), alpha)
    };
    let fits = thread_space(ck, name, p_x, s, (r1, ra, rf), alpha_x)?;
    let mut def = ThreadDef {
        profile,
        starts: starts as u32,
        hand,
        axial_pitch: p_x,
        reference_radius: r1,
        tip_radius: ra,
        root_radius: rf,
        axial_pressure_angle: alpha_x,
        normal_pressure_angle: alpha_n,
        axial_thickness: s,
        grinding_wheel: None,
        tip_relief: EdgeRelief::SHARP,
    };
    let relief = edge_relief(
        ck,
        &field("tip_relief_um"),
        t.tip_relief_um,
        &field("tip_relief_length_mm"),
        t.tip_relief_length_mm,
        (
            0.5 * (ra - rf),
            &format!("half the thread depth, {name}.tip_radius_mm - {name}.root_radius_mm"),
        ),
    );
    match relief {
        Some(r) => def.tip_relief = r,
        None => return None,
    }
    if profile == ProfileType::I {
        base_cylinder_below_root(ck, name, &def);
    }
    if let (Some(gw), ProfileType::K | ProfileType::C) = (&t.grinding_wheel, profile) {
        let radii = (r1, ra, rf);
        def.grinding_wheel = Some(grinding_wheel(ck, name, gw, profile, radii, alpha_n)?);
    }
    fits.then_some(def)
}

/// The pressure angle (deg), whether it is given in the axial plane, and the axial
/// thickness (mm) of a thread, each checked.
fn flank_inputs(
    ck: &mut Checker,
    name: &str,
    t: &ThreadSpec,
) -> (Option<f64>, Option<bool>, Option<f64>) {
    let field = |f: &str| format!("{name}.{f}");
    let alpha = ck.range(
        &field("pressure_angle_deg"),
        t.pressure_angle_deg,
        5.0,
        40.0,
        "deg",
    );
    let plane = ck.choice(
        &field("pressure_angle_plane"),
        &t.pressure_angle_plane,
        &[("axial", true), ("normal", false)],
    );
    let s = t.axial_thickness_mm;
    let thickness = ck.positive(&field("axial_thickness_mm"), s, 1000.0, "mm");
    (alpha, plane, thickness)
}

/// A thread profile by name: A, N, I, K, C or ZA, ZN, ZI, ZK, ZC.
fn profile_choice(ck: &mut Checker, field: &str, value: &str) -> Option<ProfileType> {
    ck.choice(
        field,
        value,
        &[
            ("A", ProfileType::A),
            ("N", ProfileType::N),
            ("I", ProfileType::I),
            ("K", ProfileType::K),
            ("C", ProfileType::C),
            ("ZA", ProfileType::A),
            ("ZN", ProfileType::N),
            ("ZI", ProfileType::I),
            ("ZK", ProfileType::K),
            ("ZC", ProfileType::C),
        ],
    )
}

/// Profiles K and C need a grinding wheel; the others must not have one.
fn grinding_wheel_presence(ck: &mut Checker, field: &str, p: Option<ProfileType>, given: bool) {
    match (p, given) {
        (Some(ProfileType::K | ProfileType::C), false) => ck.fail(
            field,
            "(missing)",
            "profiles K and C need a [grinding_wheel] table (radius_mm, ...)",
        ),
        (Some(ProfileType::A | ProfileType::N | ProfileType::I), true) => ck.fail(
            field,
            "(given)",
            "a grinding wheel is only used by profiles K and C",
        ),
        _ => {}
    }
}

/// Whether the thread has material at its tip and space at its root (straight-line
/// estimates from the axial thickness `s` and pressure angle `alpha_x` at r1; SI), each
/// failure recorded; None when the thickness is not even below the pitch.
fn thread_space(
    ck: &mut Checker,
    name: &str,
    p_x: f64,
    s: f64,
    (r1, ra, rf): (f64, f64, f64),
    alpha_x: f64,
) -> Option<bool> {
    let field = |f: &str| format!("{name}.{f}");
    if s >= p_x {
        ck.fail(
            &field("axial_thickness_mm"),
            s / MM,
            format!(
                "must be less than the axial pitch {:.4} mm ({name}.lead_mm / {name}.starts, or \
                 pi {name}.axial_module_mm)",
                p_x / MM
            ),
        );
        return None;
    }
    // Straight-line estimate of the thread thickness at the tip and of the space at the root.
    let tip_thickness = s - 2.0 * (ra - r1) * alpha_x.tan();
    if tip_thickness <= 0.0 {
        ck.fail(
            &field("tip_radius_mm"),
            ra / MM,
            format!(
                "the thread is pointed below its tip: with this thickness and pressure angle \
                 ({name}.axial_thickness_mm, {name}.pressure_angle_deg) the tip radius must be < \
                 {:.4} mm",
                (r1 + 0.5 * s / alpha_x.tan()) / MM
            ),
        );
    }
    let root_space = p_x - s - 2.0 * (r1 - rf) * alpha_x.tan();
    if root_space <= 0.0 {
        ck.fail(
            &field("root_radius_mm"),
            rf / MM,
            format!(
                "the thread space closes above the root: with this pitch, thickness and \
                 pressure angle ({name}.lead_mm / {name}.starts, {name}.axial_thickness_mm, \
                 {name}.pressure_angle_deg) the root radius must be > {:.4} mm",
                (r1 - 0.5 * (p_x - s) / alpha_x.tan()) / MM
            ),
        );
    }
    Some(tip_thickness > 0.0 && root_space > 0.0)
}

/// The lead angle at the reference radius, rad; None (recorded) above 45 degrees.
fn lead_angle(ck: &mut Checker, name: &str, starts: i64, p_x: f64, r1: f64) -> Option<f64> {
    let lead_angle = (starts as f64 * p_x / (2.0 * PI * r1)).atan();
    if lead_angle > 45.0 * DEG {
        ck.fail(
            &format!("{name}.reference_radius_mm"),
            r1 / MM,
            format!(
                "lead angle {:.2} deg exceeds 45 deg: with this lead ({name}.starts and \
                 {name}.axial_module_mm or {name}.lead_mm) the reference radius must be >= \
                 {:.4} mm",
                lead_angle / DEG,
                starts as f64 * p_x / (2.0 * PI) / MM
            ),
        );
        return None;
    }
    Some(lead_angle)
}

/// Profile I is an involute helicoid: its root must lie above the base cylinder.
fn base_cylinder_below_root(ck: &mut Checker, name: &str, def: &ThreadDef) {
    let (rb, rf) = (def.base_radius(), def.root_radius);
    if rb >= rf {
        ck.fail(
            &format!("{name}.root_radius_mm"),
            rf / MM,
            format!(
                "profile I needs the root above the base cylinder: must be > base radius {:.4} mm",
                rb / MM
            ),
        );
    }
}

/// The axial pitch p_x of a thread, m, from its axial module or its lead (one of the two).
fn axial_pitch(ck: &mut Checker, name: &str, t: &ThreadSpec, starts: Option<i64>) -> Option<f64> {
    let field = |f: &str| format!("{name}.{f}");
    match (t.axial_module_mm, t.lead_mm, starts) {
        (Some(_), Some(_), _) => {
            ck.fail(
                &field("lead_mm"),
                t.lead_mm.unwrap_or_default(),
                format!(
                    "give either {} or {}, not both",
                    field("axial_module_mm"),
                    field("lead_mm")
                ),
            );
            None
        }
        (None, None, _) => {
            ck.fail(
                &field("axial_module_mm"),
                "(missing)",
                format!("give {} or {}", field("axial_module_mm"), field("lead_mm")),
            );
            None
        }
        (Some(m), None, _) => ck
            .range(&field("axial_module_mm"), m, 0.1, 100.0, "mm")
            .map(|m| m * PI * MM),
        (None, Some(l), Some(z)) => ck
            .range(&field("lead_mm"), l, 0.1, 5000.0, "mm")
            .map(|l| l * MM / z as f64),
        (None, Some(_), None) => None,
    }
}

/// The reference, tip and root radii of a thread, mm, each checked and in order.
fn thread_radii(
    ck: &mut Checker,
    name: &str,
    t: &ThreadSpec,
) -> (Option<f64>, Option<f64>, Option<f64>) {
    let field = |f: &str| format!("{name}.{f}");
    let r1 = ck.positive(
        &field("reference_radius_mm"),
        t.reference_radius_mm,
        2000.0,
        "mm",
    );
    let ra = ck.positive(&field("tip_radius_mm"), t.tip_radius_mm, 2000.0, "mm");
    let rf = ck.positive(&field("root_radius_mm"), t.root_radius_mm, 2000.0, "mm");
    if let (Some(r1), Some(ra), Some(rf)) = (r1, ra, rf) {
        if ra <= rf {
            ck.fail(
                &field("tip_radius_mm"),
                ra,
                format!(
                    "must be greater than {} = {rf} mm (tip below root)",
                    field("root_radius_mm")
                ),
            );
        } else if r1 <= rf || r1 >= ra {
            ck.fail(
                &field("reference_radius_mm"),
                r1,
                format!("must lie strictly between the root ({rf} mm) and tip ({ra} mm) radii"),
            );
        }
    }
    (r1, ra, rf)
}

/// The grinding wheel of a K or C thread (MODEL §2.2), checked against the thread's radii
/// (`radii` = reference, tip, root, m) and with its defaults (profile angle: the thread's
/// normal pressure angle `alpha_n`, rad; axis distance r1 + R_g).
fn grinding_wheel(
    ck: &mut Checker,
    name: &str,
    gw: &GrindingWheelSpec,
    profile: ProfileType,
    radii: (f64, f64, f64),
    alpha_n: f64,
) -> Option<GrindingWheel> {
    let (r1, ra, rf) = radii;
    let gfield = |f: &str| format!("{name}.grinding_wheel.{f}");
    let rg = ck.range(
        &gfield("radius_mm"),
        gw.radius_mm,
        (ra - rf) / MM * 1.5,
        2000.0,
        "mm",
    );
    let angle = match gw.profile_angle_deg {
        Some(v) => ck
            .range(&gfield("profile_angle_deg"), v, 5.0, 40.0, "deg")
            .map(|v| v * DEG),
        None => Some(alpha_n),
    };
    let dist = match (gw.axis_distance_mm, rg) {
        (Some(d), Some(rg)) => ck
            .range(
                &gfield("axis_distance_mm"),
                d,
                (r1 / MM + rg) - 0.5 * (ra - rf) / MM,
                (r1 / MM + rg) + 0.5 * (ra - rf) / MM,
                "mm (reference radius + grinding-wheel radius +/- half the thread height)",
            )
            .map(|d| d * MM),
        (None, Some(rg)) => Some(r1 + rg * MM),
        _ => None,
    };
    let rho0 = match (profile, gw.profile_radius_mm) {
        (ProfileType::C, Some(v)) => ck
            .range(
                &gfield("profile_radius_mm"),
                v,
                2.0 * (ra - rf) / MM,
                10_000.0,
                "mm",
            )
            .map(|v| Some(v * MM)),
        (ProfileType::C, None) => {
            ck.fail(
                &gfield("profile_radius_mm"),
                "(missing)",
                "profile C needs the arc radius rho_0",
            );
            None
        }
        (_, Some(v)) => {
            ck.fail(
                &gfield("profile_radius_mm"),
                v,
                "only profile C has a circular-arc wheel",
            );
            None
        }
        (_, None) => Some(None),
    };
    Some(GrindingWheel {
        radius: rg? * MM,
        axis_distance: dist?,
        profile_angle: angle?,
        profile_radius: rho0?,
    })
}

fn material(
    ck: &mut Checker,
    name: &str,
    m: Option<&MaterialSpec>,
    default: Material,
) -> Option<Material> {
    let Some(m) = m else { return Some(default) };
    let field = |f: &str| format!("{name}.{f}");
    let e = ck.range(
        &field("youngs_modulus_gpa"),
        m.youngs_modulus_gpa,
        1.0,
        2000.0,
        "GPa",
    );
    let nu = ck.range(&field("poisson_ratio"), m.poisson_ratio, 0.0, 0.499, "");
    let h = match m.hardness_gpa {
        Some(v) => ck
            .range(&field("hardness_gpa"), v, 0.01, 100.0, "GPa")
            .map(|v| v * 1e9),
        None => Some(default.hardness),
    };
    let k = match m.wear_coefficient {
        Some(v) => ck.range(&field("wear_coefficient"), v, 0.0, 1e-2, ""),
        None => Some(default.wear_coefficient),
    };
    let rho = match m.density_kg_m3 {
        Some(v) => ck.range(&field("density_kg_m3"), v, 100.0, 30_000.0, "kg/m^3"),
        None => Some(default.density),
    };
    let lim = match m.pitting_limit_mpa {
        Some(v) => ck
            .range(&field("pitting_limit_mpa"), v, 10.0, 10_000.0, "MPa")
            .map(|v| v * 1e6),
        None => Some(default.pitting_limit),
    };
    Some(Material {
        name: m.name.clone().unwrap_or_else(|| name.to_string()),
        youngs_modulus: e? * 1e9,
        poisson_ratio: nu?,
        hardness: h?,
        wear_coefficient: k?,
        density: rho?,
        pitting_limit: lim?,
    })
}

fn lubricant(ck: &mut Checker, l: &LubricantSpec) -> Option<Lubricant> {
    let mut get = |f: &str, v: Option<f64>, d: f64, lo: f64, hi: f64, unit: &str| match v {
        Some(v) => ck.range(&format!("lubricant.{f}"), v, lo, hi, unit),
        None => Some(d),
    };
    let eta = get(
        "viscosity_pa_s",
        l.viscosity_pa_s,
        0.227,
        1e-4,
        100.0,
        "Pa s",
    );
    let apv = get(
        "pressure_viscosity_per_gpa",
        l.pressure_viscosity_per_gpa,
        9.5,
        0.0,
        100.0,
        "1/GPa",
    );
    let beta = get(
        "thermo_viscosity_k",
        l.thermo_viscosity_k,
        3200.0,
        0.0,
        100_000.0,
        "K",
    );
    let kf = get(
        "thermal_conductivity_w_m_k",
        l.thermal_conductivity_w_m_k,
        0.148,
        0.01,
        10.0,
        "W/(m K)",
    );
    let t = get(
        "temperature_c",
        l.temperature_c,
        333.0 - 273.15,
        -50.0,
        250.0,
        "degC",
    );
    let rq = get(
        "composite_roughness_um",
        l.composite_roughness_um,
        1.0,
        0.001,
        100.0,
        "um",
    );
    Some(Lubricant {
        name: l
            .name
            .clone()
            .unwrap_or_else(|| "polyglycol (default)".into()),
        viscosity: eta?,
        pressure_viscosity: apv? * 1e-9,
        thermo_viscosity: beta?,
        thermal_conductivity: kf?,
        temperature: t? + 273.15,
        composite_roughness: rq? * 1e-6,
    })
}

fn rating_factors(ck: &mut Checker, r: &RatingSpec) -> Option<RatingFactors> {
    let mut factor = |name: &str, v: Option<f64>, d: f64, lo: f64, hi: f64| match v {
        Some(v) => ck.range(&format!("rating.{name}"), v, lo, hi, ""),
        None => Some(d),
    };
    let ys = factor(
        "friction_size_factor",
        r.friction_size_factor,
        1.0,
        0.1,
        10.0,
    );
    let yg = factor(
        "friction_geometry_factor",
        r.friction_geometry_factor,
        1.0,
        0.1,
        10.0,
    );
    let yw = factor(
        "friction_material_factor",
        r.friction_material_factor,
        1.0,
        0.1,
        10.0,
    );
    let yr = factor(
        "friction_roughness_factor",
        r.friction_roughness_factor,
        1.0,
        0.1,
        10.0,
    );
    let z = factor(
        "pitting_life_factor",
        r.pitting_life_factor,
        1.0,
        0.01,
        100.0,
    );
    let ap = factor(
        "pitted_area_max_percent",
        r.pitted_area_max_percent,
        8.0,
        2.0 + 1e-9,
        100.0,
    );
    Some(RatingFactors {
        friction_factor: ys? * yg? * yw? * yr?,
        pitting_life_factor: z?,
        pitted_area_max_percent: ap?,
    })
}

fn wear_plan(ck: &mut Checker, w: &WearSpec) -> Option<WearPlan> {
    let life = ck.range("wear.life_cycles", w.life_cycles, 1.0, 1e12, "cycles");
    let step = step_control(ck, w);
    let endurance = endurance(ck, w.endurance.as_ref());
    let mut phases = phases(ck, &w.phases)?;
    let pitting = pitting_mode(ck, w, &w.phases);
    let onset = match w.pitting_onset_percent {
        Some(v) if pitting.is_some() && pitting != Some(Pitting::Forecast) => {
            ck.fail(
                "wear.pitting_onset_percent",
                v,
                "only a forecast (wear.pitting = \"forecast\") takes a pitting onset share",
            );
            None
        }
        v => ck.range(
            "wear.pitting_onset_percent",
            v.unwrap_or(2.0),
            0.0,
            100.0,
            "%",
        ),
    };
    if pitting == Some(Pitting::Off) {
        phases.retain(|p| matches!(p, Phase::Wear { .. }));
    }
    let guard = match w.max_substep_wear_um.unwrap_or(5.0) {
        0.0 => Some(0.0),
        v => ck.range(
            "wear.max_substep_wear_um",
            v,
            MIN_STEP_WEAR_UM,
            1000.0,
            "um (or 0: off)",
        ),
    };
    if let (Some(life), Some(StepControl::Cycles(c))) = (life, step) {
        if let Some(problem) = fixed_steps_problem(life, c) {
            ck.fail("wear.step_cycles", Number(c), problem);
        }
    }
    let film_load = ck.choice(
        "wear.film_load",
        w.film_load.as_deref().unwrap_or("loaded-analysis"),
        &[
            ("loaded-analysis", FilmLoad::LoadedAnalysis),
            ("hertz-peak-floor", FilmLoad::HertzPeakFloor),
        ],
    );
    let pit_depth = ck.choice(
        "wear.pit_depth",
        w.pit_depth.as_deref().unwrap_or("hertz"),
        &[
            ("hertz", PitDepth::Hertz),
            ("loaded-band", PitDepth::LoadedBand),
        ],
    );
    let pitting_stress = ck.choice(
        "wear.pitting_stress",
        w.pitting_stress.as_deref().unwrap_or("principal-shear"),
        &[
            ("principal-shear", PittingStress::PrincipalShear),
            ("orthogonal-shear", PittingStress::OrthogonalShear),
            ("surface-pressure", PittingStress::SurfacePressure),
        ],
    );
    let map_cycles = map_cycles(ck, w.map_cycles.as_ref());
    let stop_at = ck.choice(
        "wear.stop_at",
        w.stop_at.as_deref().unwrap_or("pointed-tip"),
        &[
            ("pointed-tip", LifeStop::PointedTip),
            ("backlash-limit", LifeStop::BacklashLimit),
        ],
    );
    let backlash_limit = match w.backlash_limit_um {
        None => Some(None),
        Some(v) => ck
            .positive("wear.backlash_limit_um", v, 1e5, "um")
            .map(|v| Some(v * 1e-6)),
    };
    Some(WearPlan {
        life_cycles: life?,
        step: step?,
        max_substep_removal: guard? * 1e-6,
        phases,
        pitting: pitting?,
        pitting_onset_share: onset? * 1e-2,
        endurance: endurance?,
        film_load: film_load?,
        pit_depth: pit_depth?,
        pitting_stress: pitting_stress?,
        map_cycles: map_cycles?,
        stop_at: stop_at?,
        backlash_limit: backlash_limit?,
    })
}

/// The step control: adaptive (largest removal, default 4 um) or fixed cycles.
fn step_control(ck: &mut Checker, w: &WearSpec) -> Option<StepControl> {
    match (w.step_wear_um, w.step_cycles) {
        (Some(_), Some(c)) => {
            ck.fail(
                "wear.step_cycles",
                c,
                "give either wear.step_wear_um (adaptive) or wear.step_cycles (fixed), not both",
            );
            None
        }
        (None, Some(c)) => ck
            .range("wear.step_cycles", c, 1.0, 1e12, "cycles")
            .map(StepControl::Cycles),
        (Some(d), None) => ck
            .range("wear.step_wear_um", d, MIN_STEP_WEAR_UM, 1000.0, "um")
            .map(|d| StepControl::MaxRemoval(d * 1e-6)),
        (None, None) => Some(StepControl::MaxRemoval(4e-6)),
    }
}

/// The bronze pressure-life curve (MODEL §8; default when the section is absent).
fn endurance(ck: &mut Checker, e: Option<&EnduranceSpec>) -> Option<Endurance> {
    match e {
        None => Some(Endurance::DEFAULT),
        Some(e) => {
            // Bounded so that every life on the curve, N = f N_ref (p / p_ref)^(-1/b) for
            // pressures up to 10 GPa, is a finite positive number: b >= 0.02 keeps the power at
            // most 50, and p_ref, N_ref and f keep the factors away from 0 and infinity.
            let p = ck.range(
                "wear.endurance.reference_pressure_mpa",
                e.reference_pressure_mpa,
                1.0,
                1e5,
                "MPa",
            );
            let n = ck.range(
                "wear.endurance.reference_cycles",
                e.reference_cycles,
                1.0,
                1e15,
                "cycles",
            );
            let x = ck.range("wear.endurance.exponent", e.exponent, 0.02, 5.0, "");
            let f = ck.range(
                "wear.endurance.life_factor",
                e.life_factor.unwrap_or(1.0),
                0.01,
                100.0,
                "",
            );
            match (p, n, x, f) {
                (Some(p), Some(n), Some(x), Some(f)) => Some(Endurance {
                    reference_pressure: p * 1e6,
                    reference_cycles: n,
                    exponent: x,
                    life_factor: f,
                }),
                _ => None,
            }
        }
    }
}

/// The phase schedule, each phase checked; None when one is invalid (recorded).
fn phases(ck: &mut Checker, specs: &[PhaseSpec]) -> Option<Vec<Phase>> {
    if specs.len() > MAX_PHASES {
        ck.fail(
            "wear.phases",
            format!("{} phases", specs.len()),
            format!("a schedule may list at most {MAX_PHASES} phases"),
        );
        return None;
    }
    let mut phases = Vec::new();
    let mut previous = 0.0;
    let mut ok = true;
    for (k, p) in specs.iter().enumerate() {
        let field = |f: &str| format!("wear.phases[{k}].{f}");
        let until = ck.positive(&field("until_cycles"), p.until_cycles, 1e12, "cycles");
        let Some(until) = until else {
            ok = false;
            continue;
        };
        if until <= previous {
            ck.fail(
                &field("until_cycles"),
                until,
                format!("phases must end in increasing order (previous phase ends at {previous})"),
            );
            ok = false;
        }
        previous = until;
        let kind = ck.choice(
            &field("kind"),
            &p.kind,
            &[("wear", false), ("pitting", true)],
        );
        match kind {
            Some(false) => {
                if p.pressure_limit_mpa.is_some() || p.margin.is_some() {
                    ck.fail(
                        &field("pressure_limit_mpa"),
                        p.pressure_limit_mpa.or(p.margin).unwrap_or_default(),
                        "only pitting phases take a pressure limit or margin",
                    );
                    ok = false;
                }
                phases.push(Phase::Wear { until });
            }
            Some(true) => {
                let limit = match p.pressure_limit_mpa {
                    Some(v) => ck
                        .positive(&field("pressure_limit_mpa"), v, 1e5, "MPa")
                        .map(|v| Some(v * 1e6)),
                    None => Some(None),
                };
                let margin = ck.range(&field("margin"), p.margin.unwrap_or(0.1), 0.0, 10.0, "");
                match (limit, margin) {
                    (Some(pressure_limit), Some(margin)) => phases.push(Phase::Pitting {
                        until,
                        pressure_limit,
                        margin,
                    }),
                    _ => ok = false,
                }
            }
            None => ok = false,
        }
    }
    ok.then_some(phases)
}

/// The cycles of the map states, increasing (None: the default 0, 1, 2, 4, ...).
fn map_cycles(ck: &mut Checker, list: Option<&Vec<f64>>) -> Option<Option<Vec<f64>>> {
    match list {
        None => Some(None),
        Some(list) if list.len() > MAX_MAP_STATES => {
            ck.fail(
                "wear.map_cycles",
                format!("{} entries", list.len()),
                format!(
                    "at most {MAX_MAP_STATES} map states (each writes about 6 files: {} would \
                     write about {})",
                    list.len(),
                    6 * list.len()
                ),
            );
            None
        }
        Some(list) => {
            let mut ok = true;
            let mut previous = 0.0;
            for (k, &c) in list.iter().enumerate() {
                let field = format!("wear.map_cycles[{k}]");
                if ck.range(&field, c, 0.0, 1e12, "cycles").is_none() {
                    ok = false;
                } else if k > 0 && c <= previous {
                    ck.fail(
                        &field,
                        c,
                        format!("must be larger than the one before ({previous}): give the cycles in increasing order"),
                    );
                    ok = false;
                }
                previous = c;
            }
            ok.then(|| Some(list.clone()))
        }
    }
}

/// `wear.pitting` (MODEL §8 beyond the schedule): a forecast finds its own pitting phases, so it takes
/// none from the schedule; pits from the damage take no pressure limit.
fn pitting_mode(ck: &mut Checker, w: &WearSpec, phases: &[PhaseSpec]) -> Option<Pitting> {
    let mode = ck.choice(
        "wear.pitting",
        w.pitting.as_deref().unwrap_or("schedule"),
        &[
            ("schedule", Pitting::Schedule),
            ("off", Pitting::Off),
            ("damage", Pitting::Damage),
            ("forecast", Pitting::Forecast),
        ],
    )?;
    for (k, p) in phases.iter().enumerate() {
        let field = |f: &str| format!("wear.phases[{k}].{f}");
        if mode == Pitting::Forecast && p.kind == "pitting" {
            ck.fail(
                &field("kind"),
                "pitting",
                "a forecast (wear.pitting = \"forecast\") finds its own pitting phases: remove \
                 them from the schedule or use wear.pitting = \"schedule\" or \"damage\"",
            );
            return None;
        }
        if mode == Pitting::Damage && (p.pressure_limit_mpa.is_some() || p.margin.is_some()) {
            ck.fail(
                &field("pressure_limit_mpa"),
                p.pressure_limit_mpa.or(p.margin).unwrap_or_default(),
                "pits from the damage (wear.pitting = \"damage\") take no pressure limit or \
                 margin: they form where a node's damage reaches 1",
            );
            return None;
        }
    }
    Some(mode)
}

fn conditions(ck: &mut Checker, c: &ConditionsSpec) -> Option<Conditions> {
    let torque = match (c.worm_torque_nm, c.wheel_torque_nm) {
        (Some(t), None) => ck
            .positive("conditions.worm_torque_nm", t, 1e6, "N m")
            .map(Torque::Worm),
        (None, Some(t)) => ck
            .positive("conditions.wheel_torque_nm", t, 1e8, "N m")
            .map(Torque::Wheel),
        (Some(_), Some(_)) => {
            ck.fail(
                "conditions.wheel_torque_nm",
                c.wheel_torque_nm.unwrap_or_default(),
                "give either conditions.worm_torque_nm or conditions.wheel_torque_nm, not both",
            );
            None
        }
        (None, None) => {
            ck.fail(
                "conditions.worm_torque_nm",
                "(missing)",
                "give conditions.worm_torque_nm or conditions.wheel_torque_nm",
            );
            None
        }
    };
    // Below 1e-3 rpm the film and sliding-speed formulas underflow (1e-300 rpm ended a life
    // in "the reachable cells carry only ... of the load").
    let speed = ck.range(
        "conditions.worm_speed_rpm",
        c.worm_speed_rpm,
        1e-3,
        20_000.0,
        "rpm",
    );
    Some(Conditions {
        torque: torque?,
        worm_speed: speed? * 2.0 * PI / 60.0,
    })
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
