//! A worm stage of a REXS model as a gear file (`wormwear import`).
//!
//! The stage is found through its `stage` relation (roles gear_1 / gear_2: a `worm_gear` and a
//! `worm_wheel`); everything else is reached from it by relations: the shafts holding the gears
//! (`assembly`), their bearings (`side`), the loads on them (`assembly`), materials and
//! lubricant (`reference`), tools and manufacturing settings (`flank`, then
//! `manufacturing_step`). The gear file is written as commented TOML: each value says which
//! attribute it comes from, and where REXS has no value (or 0) the default used and its
//! source. Every attribute of these components that was not used is listed in a comment block
//! at the end, so that nothing is dropped silently. The mapping is tabulated in the README
//! ("REXS").
//!
//! Conventions adopted (REXS does not state them for worm stages):
//! - the hand is the sign of `lead_angle_worm_gear` (positive: right hand), as for the helix
//!   angle of cylindrical gears;
//! - our worm axis x1 is the worm shaft's u axis; y1 points from the worm axis to the wheel
//!   centre; z2 = x1 x y1. A positive worm speed (about u) of a right-hand worm moves the thread
//!   towards -x1: `worm_rotation = "positive"`.

use super::units::{convert, Quantity};
use super::{Component, Model, RexsError, Value};
use std::cell::RefCell;
use std::collections::BTreeSet;
use std::fmt::Write as _;

/// Prefix of the custom attributes wormwear writes for gear-file fields REXS has no attribute
/// for (REXS reserves ids starting with `custom_` for application data).
pub const CUSTOM_PREFIX: &str = "custom_wormwear_";

/// A worm stage of the model.
#[derive(Debug, Clone, PartialEq)]
pub struct StageInfo {
    /// Component id of the `worm_stage`.
    pub id: u64,
    pub name: String,
    pub worm: u64,
    pub wheel: u64,
}

/// The worm stages of a model, in file order.
pub fn worm_stages(model: &Model) -> Vec<StageInfo> {
    let mut stages = Vec::new();
    for c in model.components.iter().filter(|c| c.kind == "worm_stage") {
        let gears: Vec<&Component> = model
            .relations_with("stage", c.id, "stage")
            .flat_map(|r| r.refs.iter().filter(|x| x.role.starts_with("gear")))
            .filter_map(|x| model.component(x.id))
            .collect();
        let worm = gears.iter().find(|g| g.kind == "worm_gear");
        let wheel = gears.iter().find(|g| g.kind == "worm_wheel");
        if let (Some(worm), Some(wheel)) = (worm, wheel) {
            stages.push(StageInfo {
                id: c.id,
                name: c.name.clone(),
                worm: worm.id,
                wheel: wheel.id,
            });
        }
    }
    stages
}

/// A gear file made from a REXS stage.
#[derive(Debug, Clone)]
pub struct Imported {
    pub stage: StageInfo,
    /// The gear file (TOML with comments).
    pub text: String,
    /// What the user should look at: assumptions that change results, inconsistencies.
    pub warnings: Vec<String>,
}

/// A number in a comment or a warning: four decimals between 1e-4 and 1e7, scientific
/// notation outside (a mistyped 1e300 is not shown with 300 digits).
struct Shown(f64);

impl std::fmt::Display for Shown {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let a = self.0.abs();
        match a == 0.0 || !a.is_finite() || (1e-4..1e7).contains(&a) {
            true => write!(f, "{:.4}", self.0),
            false => write!(f, "{:e}", self.0),
        }
    }
}

impl Imported {
    /// Where the gear file's field `field` (dotted, e.g. `cutting.centre_distance_mm`) came
    /// from: the comment the import wrote beside it (the REXS attribute, or "default ...").
    pub fn source_of(&self, field: &str) -> Option<&str> {
        let field = field.split('[').next().unwrap_or(field); // an element: its list's source
        let mut table = String::new();
        for line in self.text.lines() {
            let line = line.trim();
            if let Some(name) = line.strip_prefix('[').and_then(|l| l.split(']').next()) {
                table = name.trim().to_string();
            } else if let Some((key, rest)) = line.split_once('=') {
                let dotted = match table.is_empty() {
                    true => key.trim().to_string(),
                    false => format!("{table}.{}", key.trim()),
                };
                if dotted == field {
                    return rest.split_once("    # ").map(|(_, comment)| comment.trim());
                }
            }
        }
        None
    }

    /// A validation error of the written gear file with each field's REXS source added to
    /// its problem, so that the message names the attribute to correct in the REXS file.
    pub fn with_sources(&self, error: crate::input::InputError) -> crate::input::InputError {
        match error {
            crate::input::InputError::Invalid(fields) => crate::input::InputError::Invalid(
                fields
                    .into_iter()
                    .map(|mut e| {
                        let mut sources = Vec::new();
                        if let Some(source) = self.source_of(&e.field) {
                            sources.push(format!("from REXS: {source}"));
                        }
                        // The other fields a relation names (`must be <= a.b - c.d`).
                        let words = e
                            .problem
                            .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '.'));
                        for word in words.filter(|w| w.contains('.') && *w != e.field) {
                            let word = word.trim_end_matches('.');
                            if let Some(source) = self.source_of(word) {
                                sources.push(format!("{word} from REXS: {source}"));
                            }
                        }
                        if !sources.is_empty() {
                            e.problem = format!("{} ({})", e.problem, sources.join("; "));
                        }
                        e
                    })
                    .collect(),
            ),
            other => other,
        }
    }
}

/// Makes the gear file of the worm stage `stage` (a component id; None: the model's only worm
/// stage). `source` names the REXS file in the header comment.
pub fn import(model: &Model, stage: Option<u64>, source: &str) -> Result<Imported, RexsError> {
    let stages = worm_stages(model);
    let info =
        match (stage, stages.len()) {
            (_, 0) => return Err(RexsError::Model(
                "the model has no worm stage: a worm_stage component with a `stage` relation to \
                 a worm_gear and a worm_wheel is needed"
                    .into(),
            )),
            (None, 1) => stages[0].clone(),
            (None, _) => {
                return Err(RexsError::Model(format!(
                    "the model has {} worm stages; choose one with --stage ID:\n{}",
                    stages.len(),
                    stage_list(&stages)
                )))
            }
            (Some(id), _) => stages.iter().find(|s| s.id == id).cloned().ok_or_else(|| {
                RexsError::Model(format!(
                    "--stage {id}: no worm stage with this component id; the model has:\n{}",
                    stage_list(&stages)
                ))
            })?,
        };
    let reader = Reader::new(model);
    let parts = Parts::locate(model, &info)?;
    let mut out = GearText::default();
    let _ = writeln!(
        out.text,
        "# Imported by wormwear from {source}: worm stage {} (REXS {}, written by {} {}).\n\
         # Each value names the REXS attribute it comes from; \"default\" marks a value REXS \
         does not give.\n# Check the defaults and warnings before trusting the results.",
        parts.stage.label(),
        model.version,
        model.application_id,
        model.application_version
    );
    out.field_text("title", &stage_title(&parts), None);
    let worm = worm_thread(&reader, &parts, &mut out)?;
    hob_thread(&reader, &parts, &worm, &mut out)?;
    let wheel = wheel_blank(&reader, &parts, &worm, &mut out)?;
    operating(&reader, &parts, &worm, &wheel, &mut out)?;
    materials(&reader, &parts, &mut out)?;
    lubricant(&reader, &parts, &mut out)?;
    conditions(&reader, &parts, &worm, &mut out)?;
    bending(&reader, &parts, &worm, &wheel, &mut out)?;
    unused_block(model, &reader, &parts, &mut out);
    Ok(Imported {
        stage: info,
        text: out.text,
        warnings: out.warnings,
    })
}

fn stage_list(stages: &[StageInfo]) -> String {
    stages
        .iter()
        .map(|s| {
            format!(
                "  --stage {}  {} (worm {}, wheel {})",
                s.id, s.name, s.worm, s.wheel
            )
        })
        .collect::<Vec<_>>()
        .join("\n")
}

fn stage_title(parts: &Parts) -> String {
    if parts.stage.name.is_empty() {
        format!("worm stage {}", parts.stage.id)
    } else {
        parts.stage.name.clone()
    }
}

/// The components of one stage.
struct Parts<'m> {
    stage: &'m Component,
    worm: &'m Component,
    wheel: &'m Component,
    worm_shaft: Option<&'m Component>,
    wheel_shaft: Option<&'m Component>,
    hob: Option<&'m Component>,
    disc: Option<&'m Component>,
    worm_settings: Option<&'m Component>,
    wheel_settings: Option<&'m Component>,
    lubricant: Option<&'m Component>,
    casing: Option<&'m Component>,
    unit: Option<&'m Component>,
    worm_material: Option<&'m Component>,
    wheel_material: Option<&'m Component>,
    worm_bearings: Vec<&'m Component>,
    wheel_bearings: Vec<&'m Component>,
    worm_loads: Vec<&'m Component>,
    wheel_loads: Vec<&'m Component>,
    worm_sections: Vec<&'m Component>,
    wheel_sections: Vec<&'m Component>,
    worm_gear_data: Option<&'m Component>,
    wheel_gear_data: Option<&'m Component>,
    flanks: Vec<&'m Component>,
}

impl<'m> Parts<'m> {
    fn locate(model: &'m Model, info: &StageInfo) -> Result<Self, RexsError> {
        let get = |id: u64| {
            model
                .component(id)
                .ok_or_else(|| RexsError::Model(format!("component {id} is missing")))
        };
        let (stage, worm, wheel) = (get(info.id)?, get(info.worm)?, get(info.wheel)?);
        let l = Links(model);
        let (worm_shaft, wheel_shaft) = (l.shaft_of(worm), l.shaft_of(wheel));
        let (worm_flanks, wheel_flanks) = (l.flanks_of(worm), l.flanks_of(wheel));
        let casing = l.first("gear_casing");
        let lubricant = l
            .referenced(stage, "lubricant")
            .or_else(|| casing.and_then(|c| l.referenced(c, "lubricant")))
            .or_else(|| l.first("lubricant"));
        Ok(Parts {
            stage,
            worm,
            wheel,
            worm_shaft,
            wheel_shaft,
            hob: l.step(&wheel_flanks, "tool", "worm_wheel_hob_tool"),
            disc: l.step(&worm_flanks, "tool", "worm_grinding_disc_tool"),
            worm_settings: l.step(&worm_flanks, "manufacturing_settings", ""),
            wheel_settings: l.step(&wheel_flanks, "manufacturing_settings", ""),
            lubricant,
            casing,
            unit: l.first("gear_unit"),
            worm_material: l.referenced(worm, "material"),
            wheel_material: l.referenced(wheel, "material"),
            worm_bearings: l.bearings(worm_shaft),
            wheel_bearings: l.bearings(wheel_shaft),
            worm_loads: l.on_shaft(worm_shaft, "external_load"),
            wheel_loads: l.on_shaft(wheel_shaft, "external_load"),
            worm_sections: l.on_shaft(worm_shaft, "shaft_section"),
            wheel_sections: l.on_shaft(wheel_shaft, "shaft_section"),
            worm_gear_data: l.gear_data(worm),
            wheel_gear_data: l.gear_data(wheel),
            flanks: worm_flanks.into_iter().chain(wheel_flanks).collect(),
        })
    }

    /// Every component of the stage, for the list of unused attributes.
    fn all(&self) -> Vec<&'m Component> {
        let mut v = vec![self.stage, self.worm, self.wheel];
        let optional = [
            self.worm_shaft,
            self.wheel_shaft,
            self.hob,
            self.disc,
            self.worm_settings,
            self.wheel_settings,
            self.lubricant,
            self.casing,
            self.unit,
            self.worm_material,
            self.wheel_material,
            self.worm_gear_data,
            self.wheel_gear_data,
        ];
        v.extend(optional.into_iter().flatten());
        for list in [
            &self.worm_bearings,
            &self.wheel_bearings,
            &self.worm_loads,
            &self.wheel_loads,
            &self.worm_sections,
            &self.wheel_sections,
            &self.flanks,
        ] {
            v.extend(list.iter().copied());
        }
        let mut seen = BTreeSet::new();
        v.retain(|c| seen.insert(c.id));
        v
    }
}

/// The relations of the model that lead from a stage to its parts.
struct Links<'m>(&'m Model);

impl<'m> Links<'m> {
    /// The first component of a type.
    fn first(&self, kind: &str) -> Option<&'m Component> {
        self.0.components.iter().find(|c| c.kind == kind)
    }

    /// The shaft a gear is assembled on.
    fn shaft_of(&self, g: &Component) -> Option<&'m Component> {
        let owners = self.0.related("assembly", g.id, "part", "assembly");
        owners.into_iter().find(|c| c.kind == "shaft")
    }

    /// The parts of a type assembled on a shaft (loads, sections).
    fn on_shaft(&self, s: Option<&Component>, kind: &str) -> Vec<&'m Component> {
        let Some(s) = s else { return Vec::new() };
        let parts = self.0.related("assembly", s.id, "assembly", "part");
        parts.into_iter().filter(|c| c.kind == kind).collect()
    }

    /// The bearings a shaft sits in (`side` relations, the shaft as inner part).
    fn bearings(&self, s: Option<&Component>) -> Vec<&'m Component> {
        s.map(|s| self.0.related("side", s.id, "inner_part", "assembly"))
            .unwrap_or_default()
    }

    /// A gear's left and right flanks.
    fn flanks_of(&self, g: &Component) -> Vec<&'m Component> {
        let mut v = self.0.related("flank", g.id, "gear", "left");
        v.extend(self.0.related("flank", g.id, "gear", "right"));
        v
    }

    /// The component in `role` of the first manufacturing step of these flanks (of `kind`,
    /// or any when empty).
    fn step(&self, flanks: &[&Component], role: &str, kind: &str) -> Option<&'m Component> {
        flanks
            .iter()
            .flat_map(|f| {
                self.0
                    .related("manufacturing_step", f.id, "workpiece", role)
            })
            .find(|c| kind.is_empty() || c.kind == kind)
    }

    /// The component of a type a component references (material, lubricant).
    fn referenced(&self, c: &Component, kind: &str) -> Option<&'m Component> {
        let targets = self.0.related("reference", c.id, "origin", "referenced");
        targets.into_iter().find(|x| x.kind == kind)
    }

    /// A gear's stage gear data.
    fn gear_data(&self, g: &Component) -> Option<&'m Component> {
        let data = self
            .0
            .related("stage_gear_data", g.id, "gear", "stage_gear_data");
        data.into_iter().next()
    }
}

/// Typed, unit-converted access to attributes, remembering which were used.
struct Reader<'m> {
    model: &'m Model,
    used: RefCell<BTreeSet<(u64, String)>>,
}

impl<'m> Reader<'m> {
    fn new(model: &'m Model) -> Self {
        Self {
            model,
            used: RefCell::new(BTreeSet::new()),
        }
    }

    fn mark(&self, c: &Component, id: &str) {
        self.used.borrow_mut().insert((c.id, id.to_string()));
    }

    /// A number converted to `q`'s unit; None when absent.
    fn number(&self, c: &Component, id: &str, q: Quantity) -> Result<Option<f64>, RexsError> {
        let Some(a) = c.attribute(id) else {
            return Ok(None);
        };
        self.mark(c, id);
        let raw = match &a.value {
            Value::Float(x) => *x,
            Value::Integer(i) => *i as f64,
            Value::Text(s) if s.trim().is_empty() => return Ok(None),
            Value::Text(s) => s
                .trim()
                .parse::<f64>()
                .map_err(|_| RexsError::attribute(c, id, format!("\"{s}\" is not a number")))?,
            other => {
                return Err(RexsError::attribute(
                    c,
                    id,
                    format!("{other} is not a number"),
                ))
            }
        };
        if !raw.is_finite() {
            return Err(RexsError::attribute(c, id, format!("{raw} is not finite")));
        }
        convert(raw, &a.unit, q).map(Some).ok_or_else(|| {
            RexsError::attribute(
                c,
                id,
                format!(
                    "unknown unit \"{}\" for this quantity (accepted: {})",
                    a.unit,
                    q.accepted().join(", ")
                ),
            )
        })
    }

    /// A number that must be there and be > 0.
    fn required(&self, c: &Component, id: &str, q: Quantity, what: &str) -> Result<f64, RexsError> {
        match self.number(c, id, q)? {
            Some(v) if v > 0.0 => Ok(v),
            Some(v) => Err(RexsError::attribute(
                c,
                id,
                format!("{v} {}: {what} must be > 0", q.unit()),
            )),
            None => Err(RexsError::attribute(
                c,
                id,
                format!("missing: {what} is needed ({})", q.unit()),
            )),
        }
    }

    /// A number > 0, or None when absent or 0 (REXS writers put 0 for "not set").
    /// A quantity that must be positive: 0 reads as not given (exporters write 0 for an
    /// empty field); a negative or non-finite value is an error naming the attribute (it was
    /// read as not given, so a default or another attribute's message stood in for it).
    fn positive(&self, c: &Component, id: &str, q: Quantity) -> Result<Option<f64>, RexsError> {
        match self.number(c, id, q)? {
            Some(v) if v > 0.0 && v.is_finite() => Ok(Some(v)),
            Some(0.0) => Ok(None),
            Some(v) => Err(RexsError::attribute(
                c,
                id,
                format!(
                    "{}: must be a positive number (0 reads as not given)",
                    crate::input::Number(v)
                ),
            )),
            None => Ok(None),
        }
    }

    fn integer(&self, c: &Component, id: &str) -> Result<Option<i64>, RexsError> {
        match self.number(c, id, Quantity::Ratio)? {
            None => Ok(None),
            Some(v) if v.fract() == 0.0 => Ok(Some(v as i64)),
            Some(v) => Err(RexsError::attribute(
                c,
                id,
                format!("{v} is not an integer"),
            )),
        }
    }

    fn text(&self, c: &Component, id: &str) -> Option<String> {
        let a = c.attribute(id)?;
        self.mark(c, id);
        match &a.value {
            Value::Enum(s) | Value::Text(s) => Some(s.trim().to_string()),
            other => Some(other.to_string()),
        }
    }

    fn boolean(&self, c: &Component, id: &str) -> Option<bool> {
        match self.text(c, id)?.as_str() {
            "true" | "1" => Some(true),
            "false" | "0" => Some(false),
            _ => None,
        }
    }

    /// A 3-vector (positions in mm, directions unitless).
    fn vector(&self, c: &Component, id: &str) -> Result<Option<[f64; 3]>, RexsError> {
        let Some(a) = c.attribute(id) else {
            return Ok(None);
        };
        self.mark(c, id);
        let v = match &a.value {
            Value::FloatArray(v) if v.len() == 3 => [v[0], v[1], v[2]],
            other => {
                return Err(RexsError::attribute(
                    c,
                    id,
                    format!("{other}: three numbers expected"),
                ))
            }
        };
        let factor = convert(1.0, &a.unit, Quantity::Length).unwrap_or(1.0);
        Ok(Some(v.map(|x| x * factor)))
    }
}

/// The gear file being written, with its warnings.
#[derive(Default)]
struct GearText {
    text: String,
    warnings: Vec<String>,
}

impl GearText {
    fn section(&mut self, name: &str) {
        let _ = write!(self.text, "\n[{name}]\n");
    }

    fn line(&mut self, key: &str, value: String, comment: Option<&str>) {
        match comment {
            Some(c) => {
                let _ = writeln!(self.text, "{key} = {value}    # {c}");
            }
            None => {
                let _ = writeln!(self.text, "{key} = {value}");
            }
        }
    }

    fn field(&mut self, key: &str, value: f64, comment: &str) {
        self.line(key, float(value), Some(comment));
    }

    fn field_text(&mut self, key: &str, value: &str, comment: Option<&str>) {
        self.line(
            key,
            toml::Value::String(value.to_string()).to_string(),
            comment,
        );
    }

    fn note(&mut self, text: &str) {
        for line in text.lines() {
            let _ = writeln!(self.text, "# {line}");
        }
    }

    fn warn(&mut self, text: String) {
        self.note(&format!("WARNING: {text}"));
        self.warnings.push(text);
    }
}

/// A TOML float: shortest round-trip form, always with a decimal point or exponent; a
/// non-finite value as TOML's `nan` / `inf`, which validation then refuses by field name.
fn float(x: f64) -> String {
    match x {
        x if x.is_nan() => "nan".into(),
        x if x.is_infinite() => if x > 0.0 { "inf" } else { "-inf" }.into(),
        x => format!("{x:?}"),
    }
}

/// The worm thread as imported (lengths in mm, angles in degrees).
struct Worm {
    profile: char,
    starts: i64,
    right_hand: bool,
    axial_module: f64,
    reference_radius: f64,
    tip_radius: f64,
    root_radius: f64,
    pressure_angle: f64,
    normal_plane: bool,
    axial_thickness: f64,
    lead_angle_deg: f64,
    grinding: Option<Grinding>,
}

/// Grinding disc of ZK/ZC worms, mm and degrees.
#[derive(Clone, Copy)]
struct Grinding {
    radius: f64,
    profile_angle: Option<f64>,
    profile_radius: Option<f64>,
}

fn profile_of(reader: &Reader, c: &Component) -> Result<char, RexsError> {
    let form = reader.text(c, "flank_form").ok_or_else(|| {
        RexsError::attribute(
            c,
            "flank_form",
            "missing: the flank form (za, zn, zi, zk, zc) is needed",
        )
    })?;
    match form.to_ascii_lowercase().as_str() {
        "za" => Ok('A'),
        "zn" => Ok('N'),
        "zi" => Ok('I'),
        "zk" => Ok('K'),
        "zc" => Ok('C'),
        other => Err(RexsError::attribute(
            c,
            "flank_form",
            format!("\"{other}\" is not a worm flank form (za, zn, zi, zk, zc)"),
        )),
    }
}

/// [worm]: form, starts, module, diameters, pressure angle and its plane, hand.
fn worm_thread(reader: &Reader, parts: &Parts, out: &mut GearText) -> Result<Worm, RexsError> {
    let (worm, sources) = read_worm(reader, parts)?;
    out.section("worm");
    let form = worm.profile.to_string();
    out.field_text("profile", &form, Some("worm_gear.flank_form"));
    out.line(
        "starts",
        worm.starts.to_string(),
        Some("worm_gear.number_of_teeth"),
    );
    let hand = if worm.right_hand { "right" } else { "left" };
    out.field_text("hand", hand, Some(&sources.hand));
    out.field("axial_module_mm", worm.axial_module, &sources.module);
    let diameter = |what: &str| format!("worm_gear.{what}_diameter_worm_gear / 2");
    out.field(
        "reference_radius_mm",
        worm.reference_radius,
        &diameter("reference"),
    );
    out.field("tip_radius_mm", worm.tip_radius, &diameter("tip"));
    out.field("root_radius_mm", worm.root_radius, &diameter("root"));
    let alpha_note = "worm_gear.pressure_angle_worm_gear (alpha_0)";
    out.field("pressure_angle_deg", worm.pressure_angle, alpha_note);
    let plane = if worm.normal_plane { "normal" } else { "axial" };
    let plane_note = "as the flank form implies (DIN 3975: ZA axial, ZN/ZI/ZK/ZC normal)";
    out.field_text("pressure_angle_plane", plane, Some(plane_note));
    out.field(
        "axial_thickness_mm",
        worm.axial_thickness,
        &sources.thickness,
    );
    out.note(&format!(
        "lead angle atan(z1 m_x / d_m1) = {} deg; tip relief: wormwear's default",
        Shown(worm.lead_angle_deg)
    ));
    if let Some(g) = sources.lead_angle {
        if (g.abs() - worm.lead_angle_deg).abs() > 0.01 {
            out.warn(format!(
                "worm_gear.lead_angle_worm_gear = {} deg does not match atan(z1 m_x / d_m1) = \
                 {} deg; the module and the diameter are used",
                Shown(g),
                Shown(worm.lead_angle_deg)
            ));
        }
    }
    if let Some(g) = worm.grinding {
        write_grinding(out, "worm", g);
    }
    Ok(worm)
}

/// Where the worm's values came from, for the comments.
struct WormSources {
    hand: String,
    module: String,
    thickness: String,
    /// The file's lead angle, degrees (signed).
    lead_angle: Option<f64>,
}

/// The worm's attributes, read and checked.
fn read_worm(reader: &Reader, parts: &Parts) -> Result<(Worm, WormSources), RexsError> {
    let c = parts.worm;
    let profile = profile_of(reader, c)?;
    let starts = reader.integer(c, "number_of_teeth")?.filter(|z| *z > 0);
    let starts = starts.ok_or_else(|| {
        RexsError::attribute(
            c,
            "number_of_teeth",
            "missing: the number of starts z1 is needed",
        )
    })?;
    let length = |id: &str, what: &str| reader.required(c, id, Quantity::Length, what);
    let d1 = length(
        "reference_diameter_worm_gear",
        "the reference diameter d_m1",
    )?;
    let da = length("tip_diameter_worm_gear", "the tip diameter d_a1")?;
    let df = length("root_diameter_worm_gear", "the root diameter d_f1")?;
    let alpha_what = "the pressure angle alpha_0";
    let alpha = reader.required(c, "pressure_angle_worm_gear", Quantity::Angle, alpha_what)?;
    let gamma_file = reader.number(c, "lead_angle_worm_gear", Quantity::Angle)?;
    let (m_x, module) = axial_module(reader, c, starts, gamma_file)?;
    let (thickness, thickness_source) =
        match custom(reader, c, "axial_thickness", Quantity::Length)? {
            Some(t) => (t, format!("{CUSTOM_PREFIX}axial_thickness")),
            None => (
                0.5 * std::f64::consts::PI * m_x,
                "default: half the axial pitch, p_x / 2 (DIN 3975; REXS has no thread thickness)"
                    .into(),
            ),
        };
    let grinding = match profile {
        'K' | 'C' => Some(grinding_disc(reader, parts, profile)?),
        _ => None,
    };
    let hand = match gamma_file {
        Some(g) => format!("sign of worm_gear.lead_angle_worm_gear = {g} deg (positive: right)"),
        None => "default: REXS gives no lead angle, so no hand".into(),
    };
    let worm = Worm {
        profile,
        starts,
        right_hand: gamma_file.is_none_or(|g| g >= 0.0),
        axial_module: m_x,
        reference_radius: 0.5 * d1,
        tip_radius: 0.5 * da,
        root_radius: 0.5 * df,
        pressure_angle: alpha,
        normal_plane: profile != 'A',
        axial_thickness: thickness,
        lead_angle_deg: (starts as f64 * m_x / d1).atan().to_degrees(),
        grinding,
    };
    let sources = WormSources {
        hand,
        module,
        thickness: thickness_source,
        lead_angle: gamma_file,
    };
    Ok((worm, sources))
}

/// The axial module and the attribute it came from.
fn axial_module(
    reader: &Reader,
    c: &Component,
    starts: i64,
    gamma: Option<f64>,
) -> Result<(f64, String), RexsError> {
    let z1 = starts as f64;
    if let Some(m) = reader.positive(c, "axial_module", Quantity::Length)? {
        return Ok((m, "worm_gear.axial_module".into()));
    }
    if let Some(p) = reader.positive(c, "lead", Quantity::Length)? {
        return Ok((
            p / (z1 * std::f64::consts::PI),
            "worm_gear.lead / (z1 pi)".into(),
        ));
    }
    if let Some(p) = reader.positive(c, "axial_pitch", Quantity::Length)? {
        return Ok((
            p / std::f64::consts::PI,
            "worm_gear.axial_pitch / pi".into(),
        ));
    }
    if let (Some(m_n), Some(g)) = (
        reader.positive(c, "normal_module", Quantity::Length)?,
        gamma,
    ) {
        return Ok((
            m_n / g.to_radians().cos(),
            "worm_gear.normal_module / cos(lead_angle_worm_gear)".into(),
        ));
    }
    Err(RexsError::attribute(
        c,
        "axial_module",
        "missing: the axial module is needed (or lead, axial_pitch, or normal_module with \
         lead_angle_worm_gear)",
    ))
}

/// The worm's grinding disc (ZK, ZC): radius from grinding_disk_diameter, profile angle and
/// (ZC) profile radius.
fn grinding_disc(reader: &Reader, parts: &Parts, profile: char) -> Result<Grinding, RexsError> {
    let Some(d) = parts.disc else {
        return Err(RexsError::attribute(
            parts.worm,
            "flank_form",
            format!(
                "profile Z{profile} needs its grinding disc: a worm_grinding_disc_tool \
                 (grinding_disk_diameter) linked to the worm's flanks by a manufacturing_step \
                 relation"
            ),
        ));
    };
    let diameter = reader.required(
        d,
        "grinding_disk_diameter",
        Quantity::Length,
        "the grinding disc diameter",
    )?;
    let profile_angle = reader.positive(d, "pressure_angle_worm_gear", Quantity::Angle)?;
    let profile_radius = reader.positive(d, "profile_radius_zc_disc", Quantity::Length)?;
    if profile == 'C' && profile_radius.is_none() {
        return Err(RexsError::attribute(
            d,
            "profile_radius_zc_disc",
            "missing: a ZC worm needs the disc's profile radius",
        ));
    }
    Ok(Grinding {
        radius: 0.5 * diameter,
        profile_angle,
        profile_radius: if profile == 'C' { profile_radius } else { None },
    })
}

fn write_grinding(out: &mut GearText, member: &str, g: Grinding) {
    out.section(&format!("{member}.grinding_wheel"));
    out.field(
        "radius_mm",
        g.radius,
        "worm_grinding_disc_tool.grinding_disk_diameter / 2",
    );
    match g.profile_angle {
        Some(a) => out.field(
            "profile_angle_deg",
            a,
            "worm_grinding_disc_tool.pressure_angle_worm_gear",
        ),
        None => out.note("profile_angle_deg: default, the thread's normal pressure angle"),
    }
    if let Some(r) = g.profile_radius {
        out.field(
            "profile_radius_mm",
            r,
            "worm_grinding_disc_tool.profile_radius_zc_disc",
        );
    }
}

/// A value wormwear wrote as a custom attribute (`custom_wormwear_<name>`), for the round trip.
fn custom(
    reader: &Reader,
    c: &Component,
    name: &str,
    q: Quantity,
) -> Result<Option<f64>, RexsError> {
    reader.number(c, &format!("{CUSTOM_PREFIX}{name}"), q)
}

/// What the hob tool gives, each None where the file has no value.
struct HobTool {
    profile: Option<char>,
    starts: Option<i64>,
    lead: Option<f64>,
    pressure_angle: Option<f64>,
    reference_diameter: Option<f64>,
    axial_thickness: Option<f64>,
}

fn read_hob(reader: &Reader, hob: Option<&Component>) -> Result<HobTool, RexsError> {
    let Some(h) = hob else {
        return Ok(HobTool {
            profile: None,
            starts: None,
            lead: None,
            pressure_angle: None,
            reference_diameter: None,
            axial_thickness: None,
        });
    };
    let profile = match h.attribute("flank_form") {
        Some(_) => Some(profile_of(reader, h)?),
        None => None,
    };
    Ok(HobTool {
        profile,
        starts: reader.integer(h, "number_of_teeth")?.filter(|z| *z > 0),
        lead: reader.positive(h, "lead", Quantity::Length)?,
        pressure_angle: reader.positive(h, "pressure_angle_worm_gear", Quantity::Angle)?,
        reference_diameter: custom(reader, h, "reference_diameter", Quantity::Length)?,
        axial_thickness: custom(reader, h, "axial_thickness", Quantity::Length)?,
    })
}

/// The wheel's manufacturing settings: centre-distance and pressure-angle corrections.
fn corrections(reader: &Reader, parts: &Parts) -> Result<(f64, f64), RexsError> {
    let Some(s) = parts.wheel_settings else {
        return Ok((0.0, 0.0));
    };
    let da = reader.number(s, "center_distance_correction", Quantity::Length)?;
    let dalpha = reader.number(s, "pressure_angle_correction", Quantity::Angle)?;
    Ok((da.unwrap_or(0.0), dalpha.unwrap_or(0.0)))
}

/// [hob]: the worm_wheel_hob_tool where the file has one, otherwise the worm with its tip
/// raised to cut the wheel's root; then [cutting].
fn hob_thread(
    reader: &Reader,
    parts: &Parts,
    worm: &Worm,
    out: &mut GearText,
) -> Result<(), RexsError> {
    let what = "the centre distance a";
    let a = reader.required(parts.stage, "center_distance", Quantity::Length, what)?;
    let (correction, alpha_correction) = corrections(reader, parts)?;
    let wheel_root = reader.positive(parts.wheel, "root_diameter_worm_gear", Quantity::Length)?;
    let tool = read_hob(reader, parts.hob)?;
    let from = |given: bool, attr: &str| match given {
        true => format!("worm_wheel_hob_tool.{attr}"),
        false => "the worm's (REXS gives no hob value)".to_string(),
    };
    let profile = tool.profile.unwrap_or(worm.profile);
    if profile != worm.profile {
        out.warn(format!(
            "the hob's flank form Z{profile} differs from the worm's Z{}",
            worm.profile
        ));
    }
    out.section("hob");
    let profile_note = from(tool.profile.is_some(), "flank_form");
    out.field_text("profile", &profile.to_string(), Some(&profile_note));
    let starts = tool.starts.unwrap_or(worm.starts).to_string();
    out.line(
        "starts",
        starts,
        Some(&from(tool.starts.is_some(), "number_of_teeth")),
    );
    let hand = if worm.right_hand { "right" } else { "left" };
    out.field_text("hand", hand, Some("the worm's"));
    match tool.lead {
        Some(l) => out.field("lead_mm", l, "worm_wheel_hob_tool.lead"),
        None => out.field("axial_module_mm", worm.axial_module, "the worm's"),
    }
    match tool.reference_diameter {
        Some(d) => out.field(
            "reference_radius_mm",
            0.5 * d,
            "custom_wormwear_reference_diameter / 2",
        ),
        None => out.field(
            "reference_radius_mm",
            worm.reference_radius,
            "the worm's (a hob of the worm's size)",
        ),
    }
    let mut alpha_note = from(tool.pressure_angle.is_some(), "pressure_angle_worm_gear");
    if alpha_correction != 0.0 {
        alpha_note.push_str(" + worm_gear_manufacturing_settings.pressure_angle_correction");
    }
    let alpha = tool.pressure_angle.unwrap_or(worm.pressure_angle) + alpha_correction;
    out.field("pressure_angle_deg", alpha, &alpha_note);
    let plane = if worm.normal_plane { "normal" } else { "axial" };
    out.field_text("pressure_angle_plane", plane, Some("as the worm's"));
    let (tip, root) = hob_radii(reader, parts.hob, worm, a + correction, wheel_root)?;
    out.field("tip_radius_mm", tip.0, &tip.1);
    out.field("root_radius_mm", root.0, &root.1);
    match tool.axial_thickness {
        Some(t) => out.field("axial_thickness_mm", t, "custom_wormwear_axial_thickness"),
        None => out.field("axial_thickness_mm", worm.axial_thickness, "the worm's"),
    }
    if let Some(g) = worm.grinding {
        write_grinding(out, "hob", g);
    }
    cutting(reader, parts, a, correction, out)
}

/// [cutting]: the hobbing centre distance; the settings wormwear does not model, warned.
fn cutting(
    reader: &Reader,
    parts: &Parts,
    a: f64,
    correction: f64,
    out: &mut GearText,
) -> Result<(), RexsError> {
    out.section("cutting");
    let note = if correction != 0.0 {
        "worm_stage.center_distance + worm_gear_manufacturing_settings.center_distance_correction"
    } else {
        "worm_stage.center_distance (no centre-distance correction in the file)"
    };
    out.field("centre_distance_mm", a + correction, note);
    out.field("offset_mm", 0.0, "default: hob centred on the wheel");
    out.field("inclination_deg", 0.0, "default");
    let Some(s) = parts.wheel_settings else {
        return Ok(());
    };
    if let Some(l) = reader.number(s, "lyra_angle", Quantity::Angle)? {
        if l != 0.0 {
            out.warn(format!(
                "lyra angle {l} deg of the wheel's hobbing is not modelled"
            ));
        }
    }
    if let Some(p) = reader.text(s, "hobbing_procedure") {
        out.note(&format!(
            "hobbing procedure {p}: the wheel is the hob's envelope either way"
        ));
    }
    Ok(())
}

/// A value (mm) with the attribute or rule it comes from.
type Sourced = (f64, String);

/// The hob's tip and root radii with their sources, mm.
fn hob_radii(
    reader: &Reader,
    hob: Option<&Component>,
    worm: &Worm,
    cutting_distance: f64,
    wheel_root: Option<f64>,
) -> Result<(Sourced, Sourced), RexsError> {
    let clearance = 0.2 * worm.axial_module;
    let tip_given = match hob {
        Some(h) => reader
            .positive(h, "tip_diameter_worm_gear", Quantity::Length)?
            .map(|d| 0.5 * d),
        None => None,
    };
    let tip = match (tip_given, wheel_root) {
        (Some(t), _) => (t, "worm_wheel_hob_tool.tip_diameter_worm_gear / 2".to_string()),
        (None, Some(d)) => (
            round_nm(cutting_distance - 0.5 * d),
            "cutting centre distance - worm_wheel.root_diameter_worm_gear / 2 (the hob tip cuts the wheel root)".to_string(),
        ),
        (None, None) => (
            worm.tip_radius + clearance,
            "worm_wheel_hob_tool.tip_diameter_worm_gear and worm_wheel.root_diameter_worm_gear \
             not given (absent or 0): default worm tip + bottom clearance 0.2 m_x (DIN 3975)"
                .to_string(),
        ),
    };
    let custom_root = match hob {
        Some(h) => custom(reader, h, "root_diameter", Quantity::Length)?.map(|d| 0.5 * d),
        None => None,
    };
    let depth = match hob {
        Some(h) => reader.positive(h, "tooth_depth_worm_wheel_hob", Quantity::Length)?,
        None => None,
    };
    let root = match (custom_root, depth) {
        (Some(r), _) => (r, "custom_wormwear_root_diameter / 2".to_string()),
        (None, Some(h)) => (
            round_nm(tip.0 - h),
            "tip radius - worm_wheel_hob_tool.tooth_depth_worm_wheel_hob".to_string(),
        ),
        (None, None) => (
            worm.root_radius,
            "the worm's (the hob root does not cut the wheel)".to_string(),
        ),
    };
    Ok((tip, root))
}

/// A length in mm rounded to the nanometre: differences of file values carry round-off
/// (100 - 77.2 = 22.799999999999997) that would only clutter the gear file.
fn round_nm(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

/// The wheel as imported, mm.
struct Wheel {
    teeth: i64,
    reference_radius: f64,
    face_width: f64,
}

/// [wheel]: teeth, face width, outer and throat radii; consistency with the worm.
fn wheel_blank(
    reader: &Reader,
    parts: &Parts,
    worm: &Worm,
    out: &mut GearText,
) -> Result<Wheel, RexsError> {
    let c = parts.wheel;
    let z2 = reader
        .integer(c, "number_of_teeth")?
        .filter(|z| *z > 0)
        .ok_or_else(|| {
            RexsError::attribute(
                c,
                "number_of_teeth",
                "missing: the number of wheel teeth z2 is needed",
            )
        })?;
    let a = reader.required(
        parts.stage,
        "center_distance",
        Quantity::Length,
        "the centre distance a",
    )?;
    let m = worm.axial_module;
    let d2 = z2 as f64 * m;
    let x2 = (a - worm.reference_radius - 0.5 * d2) / m;
    let (b2, width_source) = face_width(reader, c)?;
    let (tip, outer) = wheel_radii(reader, c, d2, x2, m)?;
    out.section("wheel");
    out.line("teeth", z2.to_string(), Some("worm_wheel.number_of_teeth"));
    out.field("face_width_mm", b2, &width_source);
    out.field("outer_radius_mm", outer.0, &outer.1);
    out.field(
        "throat_radius_mm",
        tip.0,
        &format!("wheel tip radius r_a2 at the median plane: {}", tip.1),
    );
    for (field, name) in [
        ("rim_thickness", "rim_thickness_mm"),
        ("web_thickness", "web_thickness_mm"),
        ("hub_radius", "hub_radius_mm"),
    ] {
        if let Some(v) = custom(reader, c, field, Quantity::Length)? {
            out.field(name, v, &format!("{CUSTOM_PREFIX}{field}"));
        }
    }
    out.note(&format!(
        "d_2 = z2 m_x = {} mm; profile shift x2 = (a - d_m1/2 - d_2/2) / m_x = {}",
        Shown(d2),
        Shown(x2)
    ));
    wheel_checks(reader, parts, worm, a, d2, tip.0, out)?;
    Ok(Wheel {
        teeth: z2,
        reference_radius: 0.5 * d2,
        face_width: b2,
    })
}

/// The wheel's face width: the face width, else the effective face width, else the rim width.
fn face_width(reader: &Reader, c: &Component) -> Result<Sourced, RexsError> {
    let ids = [
        "face_width_worm_wheel",
        "effective_face_width_worm_wheel",
        "rim_width_worm_wheel",
    ];
    for id in ids {
        if let Some(b) = reader.positive(c, id, Quantity::Length)? {
            return Ok((b, format!("worm_wheel.{id}")));
        }
    }
    let need = "missing: the wheel face width is needed (or effective_face_width_worm_wheel, \
                rim_width_worm_wheel)";
    Err(RexsError::attribute(c, "face_width_worm_wheel", need))
}

/// The wheel's tip (throat) and outer radii, mm: the file's, else DIN 3975's rules.
fn wheel_radii(
    reader: &Reader,
    c: &Component,
    d2: f64,
    x2: f64,
    m: f64,
) -> Result<(Sourced, Sourced), RexsError> {
    let tip = match reader.positive(c, "tip_diameter_worm_gear", Quantity::Length)? {
        Some(d) => (0.5 * d, "worm_wheel.tip_diameter_worm_gear / 2".to_string()),
        None => (
            0.5 * d2 + (1.0 + x2) * m,
            "worm_wheel.tip_diameter_worm_gear not given (absent or 0): default d_a2 = d_2 + \
             2 (1 + x2) m_x (DIN 3975, h_a* = 1)"
                .to_string(),
        ),
    };
    let outer = match reader.positive(c, "outer_diameter_worm_wheel", Quantity::Length)? {
        Some(d) => (
            0.5 * d,
            "worm_wheel.outer_diameter_worm_wheel / 2".to_string(),
        ),
        None => (
            tip.0 + 0.5 * m,
            "worm_wheel.outer_diameter_worm_wheel not given (absent or 0): default d_e2 = \
             d_a2 + m_x (DIN 3975 guidance)"
                .to_string(),
        ),
    };
    Ok((tip, outer))
}

/// Warnings where the wheel's attributes disagree with the worm's data.
fn wheel_checks(
    reader: &Reader,
    parts: &Parts,
    worm: &Worm,
    a: f64,
    d2: f64,
    tip: f64,
    out: &mut GearText,
) -> Result<(), RexsError> {
    let c = parts.wheel;
    if let Some(m) = reader.positive(c, "axial_module", Quantity::Length)? {
        if (m - worm.axial_module).abs() > 1e-6 * worm.axial_module.max(1.0) {
            out.warn(format!(
                "worm_wheel.axial_module = {m} mm differs from the worm's {} mm; the worm's is used",
                worm.axial_module
            ));
        }
    }
    if let Some(d) = reader.positive(c, "reference_diameter_worm_gear", Quantity::Length)? {
        if (d - d2).abs() > 1e-3 {
            out.warn(format!(
                "worm_wheel.reference_diameter_worm_gear = {} mm differs from z2 m_x = {} mm",
                Shown(d),
                Shown(d2)
            ));
        }
    }
    if let Some(rk) = reader.positive(c, "throat_radius_worm_wheel", Quantity::Length)? {
        if (rk - (a - tip)).abs() > 0.01 {
            out.warn(format!(
                "worm_wheel.throat_radius_worm_wheel = {} mm: wormwear's blank has the gorge radius a - r_a2 = {} mm",
                Shown(rk),
                Shown(a - tip)
            ));
        }
    } else {
        out.note(&format!(
            "gorge radius of the blank: a - r_a2 = {} mm (REXS throat radius absent or 0)",
            Shown(a - tip)
        ));
    }
    let wheel_form = c
        .attribute("flank_form")
        .map(|_| profile_of(reader, c))
        .transpose()?;
    if let Some(p) = wheel_form {
        if p != worm.profile {
            out.warn(format!(
                "the wheel's flank form Z{p} differs from the worm's Z{}",
                worm.profile
            ));
        }
    }
    Ok(())
}

/// [operating]: centre distance and its deviations.
fn operating(
    reader: &Reader,
    parts: &Parts,
    worm: &Worm,
    wheel: &Wheel,
    out: &mut GearText,
) -> Result<(), RexsError> {
    let s = parts.stage;
    let a = reader.required(
        s,
        "center_distance",
        Quantity::Length,
        "the centre distance a",
    )?;
    let da = reader
        .number(s, "center_distance_offset", Quantity::Length)?
        .unwrap_or(0.0);
    let width = reader
        .number(s, "width_offset", Quantity::Length)?
        .unwrap_or(0.0);
    let shaft_angle = reader
        .number(s, "intersection_angle_offset", Quantity::Angle)?
        .unwrap_or(0.0);
    let tilt = reader
        .number(s, "inclination_angle_offset", Quantity::Angle)?
        .unwrap_or(0.0);
    out.section("operating");
    out.field("centre_distance_mm", a, "worm_stage.center_distance");
    out.field(
        "centre_distance_error_mm",
        da,
        "worm_stage.center_distance_offset",
    );
    out.field(
        "worm_offset_mm",
        width,
        "worm_stage.width_offset (along the wheel axis)",
    );
    out.field(
        "inclination_deg",
        shaft_angle,
        "worm_stage.intersection_angle_offset (shaft-angle error)",
    );
    if tilt != 0.0 {
        out.warn(format!("worm_stage.inclination_angle_offset = {tilt} deg is not modelled (only the shaft-angle error is)"));
    }
    let rotation = rotation(reader, parts, worm)?;
    out.field_text("worm_rotation", rotation.0, Some(&rotation.1));
    let ratio = wheel.teeth as f64 / worm.starts as f64;
    out.note(&format!(
        "ratio z2/z1 = {}; lead angle {} deg; wheel reference radius {} mm; face width {} mm",
        Shown(ratio),
        Shown(worm.lead_angle_deg),
        Shown(wheel.reference_radius),
        Shown(wheel.face_width)
    ));
    Ok(())
}

/// The worm speed with its sign (about the worm shaft's u axis), rpm, and its source.
fn worm_speed(reader: &Reader, parts: &Parts) -> Result<Option<(f64, String)>, RexsError> {
    for (c, label) in [(parts.worm_shaft, "shaft"), (Some(parts.worm), "worm_gear")] {
        if let Some(c) = c {
            if let Some(n) = reader.number(c, "rotational_speed", Quantity::Speed)? {
                if n != 0.0 {
                    return Ok(Some((n, format!("{label} [{}].rotational_speed", c.id))));
                }
            }
        }
    }
    Ok(None)
}

/// worm_rotation from the signs of the speed and the hand; default positive.
fn rotation(
    reader: &Reader,
    parts: &Parts,
    worm: &Worm,
) -> Result<(&'static str, String), RexsError> {
    Ok(match worm_speed(reader, parts)? {
        Some((n, source)) => {
            let positive = (n > 0.0) == worm.right_hand;
            (
                if positive { "positive" } else { "negative" },
                format!("from the sign of {source} = {n} rpm about the worm axis and the hand"),
            )
        }
        None => (
            "positive",
            "default: the worm speed's sign is not given".to_string(),
        ),
    })
}

/// [conditions]: worm speed and the torque that defines the load.
fn conditions(
    reader: &Reader,
    parts: &Parts,
    worm: &Worm,
    out: &mut GearText,
) -> Result<(), RexsError> {
    let z2 = reader.integer(parts.wheel, "number_of_teeth")?.unwrap_or(1) as f64;
    let ratio = z2 / worm.starts as f64;
    let speed = match worm_speed(reader, parts)? {
        Some((n, source)) => (n.abs(), source),
        None => {
            let wheel_speed = [parts.wheel_shaft, Some(parts.wheel)]
                .into_iter()
                .flatten()
                .map(|c| reader.number(c, "rotational_speed", Quantity::Speed))
                .collect::<Result<Vec<_>, _>>()?
                .into_iter()
                .flatten()
                .find(|n| *n != 0.0);
            match wheel_speed {
                Some(n) => (
                    n.abs() * ratio,
                    "wheel shaft rotational_speed x z2/z1".to_string(),
                ),
                None => {
                    return Err(RexsError::attribute(
                        parts.worm_shaft.unwrap_or(parts.worm),
                        "rotational_speed",
                        "missing: a rotational speed of the worm (or wheel) shaft is needed",
                    ))
                }
            }
        }
    };
    let (member, torque, source) = torque(reader, parts)?;
    out.section("conditions");
    out.field(&format!("{member}_torque_nm"), torque, &source);
    out.field("worm_speed_rpm", speed.0, &speed.1);
    if let Some(g) = parts.wheel_gear_data {
        if reader.boolean(g, "is_driving_gear") == Some(true) {
            out.warn(
                "the file has the wheel driving; wormwear analyses the worm driving the wheel"
                    .into(),
            );
        }
    }
    if let Some(g) = parts.worm_gear_data {
        let _ = reader.boolean(g, "is_driving_gear");
    }
    Ok(())
}

/// The defining torque: "worm" or "wheel", |T| in N m, and its source.
fn torque(reader: &Reader, parts: &Parts) -> Result<(&'static str, f64, String), RexsError> {
    for (member, loads) in [("worm", &parts.worm_loads), ("wheel", &parts.wheel_loads)] {
        for l in loads.iter() {
            let defines = reader.boolean(l, "defines_torque").unwrap_or(false);
            if let Some(t) = reader.number(l, "torque_around_u_axis", Quantity::Torque)? {
                if defines && t != 0.0 {
                    return Ok((
                        member,
                        t.abs(),
                        format!(
                            "external_load [{}].torque_around_u_axis (defines_torque)",
                            l.id
                        ),
                    ));
                }
            }
        }
    }
    for (member, data) in [
        ("wheel", parts.wheel_gear_data),
        ("worm", parts.worm_gear_data),
    ] {
        if let Some(g) = data {
            if let Some(t) = reader.number(g, "torque", Quantity::Torque)? {
                if t != 0.0 {
                    return Ok((
                        member,
                        t.abs(),
                        format!("worm_stage_gear_data [{}].torque", g.id),
                    ));
                }
            }
        }
    }
    Err(RexsError::attribute(
        parts.stage,
        "torque",
        "missing: the load is needed: an external_load with defines_torque and \
         torque_around_u_axis on the worm or wheel shaft, or worm_stage_gear_data.torque",
    ))
}

/// [materials]: Young's modulus, Poisson's ratio, density, hardness; a warning when the wheel
/// is not a bronze.
fn materials(reader: &Reader, parts: &Parts, out: &mut GearText) -> Result<(), RexsError> {
    for (member, material) in [
        ("worm", parts.worm_material),
        ("wheel", parts.wheel_material),
    ] {
        let Some(m) = material else {
            out.note(&format!(
                "[materials.{member}]: default (no material referenced by the {member})"
            ));
            continue;
        };
        let e = reader.required(m, "elastic_modulus", Quantity::Stress, "Young's modulus")?;
        let nu = reader
            .number(m, "poisson_ratio", Quantity::Ratio)?
            .ok_or_else(|| {
                RexsError::attribute(m, "poisson_ratio", "missing: Poisson's ratio is needed")
            })?;
        let (name, source) = match reader
            .text(m, "material_designation")
            .filter(|s| !s.is_empty())
        {
            Some(n) => (n, "material.material_designation"),
            None => (m.name.clone(), "the material component's name"),
        };
        out.section(&format!("materials.{member}"));
        out.field_text("name", &name, Some(source));
        out.field("youngs_modulus_gpa", e / 1000.0, "material.elastic_modulus");
        out.field("poisson_ratio", nu, "material.poisson_ratio");
        if let Some(rho) = reader.positive(m, "density", Quantity::Density)? {
            out.field("density_kg_m3", rho, "material.density");
        }
        if member == "wheel" {
            wheel_material(reader, m, &name, e, out)?;
        }
    }
    Ok(())
}

fn wheel_material(
    reader: &Reader,
    m: &Component,
    name: &str,
    e_mpa: f64,
    out: &mut GearText,
) -> Result<(), RexsError> {
    let hv = reader.positive(m, "surface_hardness_vickers", Quantity::Hardness)?;
    let hb = reader.positive(m, "surface_hardness_brinell", Quantity::Hardness)?;
    let exact = custom(reader, m, "hardness", Quantity::Ratio)?;
    match (hv, hb) {
        _ if exact.is_some() => out.field(
            "hardness_gpa",
            exact.unwrap_or_default(),
            "custom_wormwear_hardness",
        ),
        (Some(h), _) => out.field(
            "hardness_gpa",
            h,
            "material.surface_hardness_vickers x 9.80665e-3",
        ),
        (None, Some(h)) => out.field(
            "hardness_gpa",
            h,
            "material.surface_hardness_brinell x 9.80665e-3",
        ),
        (None, None) => out.note("hardness_gpa: default (no hardness in the file)"),
    }
    let k = custom(reader, m, "wear_coefficient", Quantity::Ratio)?;
    let limit = custom(reader, m, "pitting_limit", Quantity::Stress)?;
    match k {
        Some(k) => out.field("wear_coefficient", k, "custom_wormwear_wear_coefficient"),
        None => out
            .note("wear_coefficient: wormwear's bronze default (REXS has no Archard coefficient)"),
    }
    match limit {
        Some(l) => out.field("pitting_limit_mpa", l, "custom_wormwear_pitting_limit"),
        None => out.note("pitting_limit_mpa: wormwear's bronze default"),
    }
    let lower = name.to_ascii_lowercase();
    let bronze_name = ["cu", "bz", "bronze", "brass"]
        .iter()
        .any(|k| lower.contains(k));
    if !bronze_name || e_mpa > 150_000.0 {
        out.warn(format!(
            "the wheel material \"{name}\" (E = {} GPa) is not a bronze: exports often carry a \
             placeholder here; the wear model and its defaults are for bronze wheels",
            crate::input::Number(e_mpa * 1e-3)
        ));
    }
    Ok(())
}

/// Kinematic viscosity at `t_c` from two points by Ubbelohde-Walther (ASTM D341):
/// log log (nu + 0.7) = A - B log T, nu in mm^2/s, T in K.
pub fn walther_viscosity(nu40: f64, nu100: f64, t_c: f64) -> f64 {
    let w = |nu: f64| (nu + 0.7).log10().log10();
    let (l40, l100) = ((40.0 + 273.15f64).log10(), (100.0 + 273.15f64).log10());
    let b = (w(nu40) - w(nu100)) / (l100 - l40);
    let a = w(nu40) + b * l40;
    10f64.powf(10f64.powf(a - b * (t_c + 273.15).log10())) - 0.7
}

/// Pressure-viscosity coefficient of AGMA 925-A03, alpha = k eta_M^s (alpha in mm^2/N, eta_M
/// the dynamic viscosity at the operating temperature in mPa s), for the base oils it
/// tabulates; 1/GPa. None for other lubricant types.
pub fn agma_pressure_viscosity(lubricant_type: &str, eta_mpa_s: f64) -> Option<f64> {
    let (k, s) = match lubricant_type {
        "mineral_oil" => (0.010471, 0.1348),
        "polyalfaolefin" => (0.010326, 0.0507),
        "non_water_soluble_polyglycol" | "water_soluble_polyglycol" => (0.0047, 0.1572),
        _ => return None,
    };
    Some(1e3 * k * eta_mpa_s.powf(s))
}

/// Volumetric thermal expansion of gear oils used to bring the density at 15 degC to the
/// operating temperature, 1/K (typical of mineral and synthetic gear oils; an importer
/// assumption, stated in the gear file).
pub const OIL_EXPANSION_PER_K: f64 = 7e-4;

/// [lubricant]: dynamic viscosity at the operating temperature from the 40/100 degC kinematic
/// viscosities, thermo-viscosity from the same curve, pressure-viscosity by lubricant type.
fn lubricant(reader: &Reader, parts: &Parts, out: &mut GearText) -> Result<(), RexsError> {
    let temperature = oil_temperature(reader, parts)?;
    out.section("lubricant");
    let Some(l) = parts.lubricant else {
        out.note("no lubricant component: wormwear's default lubricant");
        if let Some((t, src)) = temperature {
            out.field("temperature_c", t, &src);
        }
        return Ok(());
    };
    let (name, source) = match reader.text(l, "name").filter(|s| !s.is_empty()) {
        Some(n) => (n, "lubricant.name"),
        None => (l.name.clone(), "the lubricant component's name"),
    };
    out.field_text("name", &name, Some(source));
    let (t, t_source) =
        temperature.unwrap_or((60.0, "default: REXS gives no lubricant temperature".into()));
    out.field("temperature_c", t, &t_source);
    if let Some(eta) = custom(reader, l, "viscosity", Quantity::Ratio)? {
        return lubricant_as_written(reader, l, eta, out);
    }
    let eta = viscosity(reader, parts, l, t, out)?;
    pressure_viscosity(reader, l, eta, out)?;
    match reader.positive(l, "thermal_conductivity", Quantity::Conductivity)? {
        Some(k) => out.field(
            "thermal_conductivity_w_m_k",
            k,
            "lubricant.thermal_conductivity",
        ),
        None => out.note("thermal_conductivity_w_m_k: wormwear's default (not in the file)"),
    }
    out.note("composite_roughness_um: wormwear's default (REXS has no flank roughness here)");
    Ok(())
}

/// The oil temperature, degC, and its source: the stage's, else the casing's.
fn oil_temperature(reader: &Reader, parts: &Parts) -> Result<Option<Sourced>, RexsError> {
    for c in [Some(parts.stage), parts.casing].into_iter().flatten() {
        if let Some(t) = reader.number(c, "temperature_lubricant", Quantity::Temperature)? {
            return Ok(Some((t, format!("{}.temperature_lubricant", c.kind))));
        }
    }
    Ok(None)
}

/// Writes the dynamic viscosity at `t` degC and the thermo-viscosity coefficient; returns
/// the viscosity, Pa s. The stage's operating viscosity where the file gives it, else the
/// Ubbelohde-Walther line through the 40 and 100 degC viscosities; the density at 15 degC
/// brought to `t` with [`OIL_EXPANSION_PER_K`].
fn viscosity(
    reader: &Reader,
    parts: &Parts,
    l: &Component,
    t: f64,
    out: &mut GearText,
) -> Result<f64, RexsError> {
    let q = Quantity::KinematicViscosity;
    let nu40 = reader.positive(l, "viscosity_at_40_degree_celsius", q)?;
    let nu100 = reader.positive(l, "viscosity_at_100_degree_celsius", q)?;
    let operating = reader.positive(parts.stage, "operating_viscosity", q)?;
    let (rho15, rho_note) =
        match reader.positive(l, "density_at_15_degree_celsius", Quantity::Density)? {
            Some(r) => (r, "lubricant.density_at_15_degree_celsius"),
            None => (900.0, "default 900 kg/m^3 (no density in the file)"),
        };
    let density = |tc: f64| rho15 * (1.0 - OIL_EXPANSION_PER_K * (tc - 15.0));
    let walther = nu40
        .zip(nu100)
        .map(|(a, b)| move |tc: f64| walther_viscosity(a, b, tc));
    let density_note = format!("x density ({rho_note}, expansion {OIL_EXPANSION_PER_K}/K)");
    let eta = match (operating, &walther) {
        (Some(nu), _) => {
            let note = format!("worm_stage.operating_viscosity = {nu} mm^2/s {density_note}");
            out.field("viscosity_pa_s", nu * 1e-6 * density(t), &note);
            nu * 1e-6 * density(t)
        }
        (None, Some(w)) => {
            let note = format!(
                "nu({t} degC) by Ubbelohde-Walther (ASTM D341) through lubricant.\
                 viscosity_at_40_degree_celsius and viscosity_at_100_degree_celsius {density_note}"
            );
            out.field("viscosity_pa_s", w(t) * 1e-6 * density(t), &note);
            w(t) * 1e-6 * density(t)
        }
        (None, None) => {
            let need = "missing: the lubricant's viscosities at 40 and 100 degC (or \
                        worm_stage.operating_viscosity) are needed";
            let missing = match nu40 {
                None => "viscosity_at_40_degree_celsius",
                Some(_) => "viscosity_at_100_degree_celsius",
            };
            return Err(RexsError::attribute(l, missing, need));
        }
    };
    match walther {
        Some(w) => {
            let eta_at = |tc: f64| w(tc) * 1e-6 * density(tc);
            let (t1, t2) = (t - 10.0 + 273.15, t + 10.0 + 273.15);
            let beta = (eta_at(t - 10.0) / eta_at(t + 10.0)).ln() / (1.0 / t1 - 1.0 / t2);
            let note = "d ln(eta) / d(1/T) of the Walther line over +/- 10 K";
            out.field("thermo_viscosity_k", beta, note);
        }
        None => out.note("thermo_viscosity_k: wormwear's default (no 40 / 100 degC viscosities)"),
    }
    Ok(eta)
}

/// Writes the pressure-viscosity coefficient: the file's AGMA 925-A03 value, else k eta^s with
/// the file's k and s, else with AGMA 925-A03's k and s for the lubricant type, else the
/// default (warned). `eta` in Pa s.
fn pressure_viscosity(
    reader: &Reader,
    l: &Component,
    eta: f64,
    out: &mut GearText,
) -> Result<(), RexsError> {
    let key = "pressure_viscosity_per_gpa";
    let given = "pressure_viscosity_coefficient_agma_925_a03";
    if let Some(a) = reader.positive(l, given, Quantity::PressureViscosity)? {
        out.field(key, a, &format!("lubricant.{given}"));
        return Ok(());
    }
    let k_id = "parameter_k_for_calculation_of_pressure_viscosity_coefficient_agma_925_a03";
    let s_id = "parameter_s_for_calculation_of_pressure_viscosity_coefficient_agma_925_a03";
    let k = reader.positive(l, k_id, Quantity::Ratio)?;
    let s = reader.number(l, s_id, Quantity::Ratio)?;
    if let (Some(k), Some(s)) = (k, s) {
        let note = "AGMA 925-A03: k eta^s with the file's k and s (eta in mPa s, alpha in mm^2/N)";
        out.field(key, 1e3 * k * (eta * 1e3).powf(s), note);
        return Ok(());
    }
    let kind = reader
        .text(l, "lubricant_type_iso_6336_2006")
        .unwrap_or_default();
    match agma_pressure_viscosity(&kind, eta * 1e3) {
        Some(a) => out.field(key, a, &format!(
            "AGMA 925-A03: k eta^s for {kind} at the operating viscosity"
        )),
        None => out.warn(format!(
            "lubricant type \"{kind}\" has no pressure-viscosity rule (AGMA 925-A03 tabulates mineral oil, PAO and PAG): wormwear's default is used"
        )),
    }
    Ok(())
}

/// The lubricant law of a file wormwear wrote (custom attributes), taken as it is.
fn lubricant_as_written(
    reader: &Reader,
    l: &Component,
    eta: f64,
    out: &mut GearText,
) -> Result<(), RexsError> {
    out.field("viscosity_pa_s", eta, "custom_wormwear_viscosity");
    for (name, key, q) in [
        (
            "pressure_viscosity_per_gpa",
            "pressure_viscosity_per_gpa",
            Quantity::Ratio,
        ),
        ("thermo_viscosity", "thermo_viscosity_k", Quantity::Ratio),
        (
            "thermal_conductivity",
            "thermal_conductivity_w_m_k",
            Quantity::Ratio,
        ),
        (
            "composite_roughness",
            "composite_roughness_um",
            Quantity::Ratio,
        ),
    ] {
        if let Some(v) = custom_any_unit(reader, l, name, q)? {
            out.field(key, v, &format!("{CUSTOM_PREFIX}{name}"));
        }
    }
    Ok(())
}

/// A custom attribute's number as written, whatever its unit (wormwear writes each in the
/// unit of the gear-file field it stands for).
fn custom_any_unit(
    reader: &Reader,
    c: &Component,
    name: &str,
    _q: Quantity,
) -> Result<Option<f64>, RexsError> {
    let id = format!("{CUSTOM_PREFIX}{name}");
    let Some(a) = c.attribute(&id) else {
        return Ok(None);
    };
    reader.mark(c, &id);
    match &a.value {
        Value::Float(x) => Ok(Some(*x)),
        Value::Integer(i) => Ok(Some(*i as f64)),
        Value::Text(s) => s
            .trim()
            .parse()
            .map(Some)
            .map_err(|_| RexsError::attribute(c, &id, format!("\"{s}\" is not a number"))),
        other => Err(RexsError::attribute(
            c,
            &id,
            format!("{other} is not a number"),
        )),
    }
}

/// A frame: origin (mm) and unit axes u, v, w, in the gear unit's coordinates.
#[derive(Clone, Copy)]
struct Frame {
    origin: [f64; 3],
    axes: [[f64; 3]; 3],
}

impl Frame {
    const GLOBAL: Frame = Frame {
        origin: [0.0; 3],
        axes: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    };

    fn point(&self, p: [f64; 3]) -> [f64; 3] {
        let mut q = self.origin;
        for (i, axis) in self.axes.iter().enumerate() {
            for k in 0..3 {
                q[k] += p[i] * axis[k];
            }
        }
        q
    }

    fn direction(&self, d: [f64; 3]) -> [f64; 3] {
        let o = Frame {
            origin: [0.0; 3],
            ..*self
        };
        o.point(d)
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn unit(a: [f64; 3]) -> Option<[f64; 3]> {
    let n = dot(a, a).sqrt();
    (n > 1e-12).then(|| a.map(|x| x / n))
}

/// The frame a component's position attributes are given in: that of its
/// `reference_component_for_position` (resolved through the chain), else the global one.
fn reference_frame(reader: &Reader, c: &Component, depth: usize) -> Result<Frame, RexsError> {
    let Some(r) = c.attribute("reference_component_for_position") else {
        return Ok(Frame::GLOBAL);
    };
    reader.mark(c, "reference_component_for_position");
    let id = match &r.value {
        Value::Reference(id) => Some(*id),
        Value::Integer(i) => u64::try_from(*i).ok(),
        Value::Text(s) => s.trim().parse().ok(),
        _ => None,
    };
    match id.and_then(|id| reader.model.component(id)) {
        Some(rc) if rc.id != c.id && depth < 8 => own_frame(reader, rc, depth + 1),
        _ => Ok(Frame::GLOBAL),
    }
}

/// A component's own frame (support vector and axes) in global coordinates.
fn own_frame(reader: &Reader, c: &Component, depth: usize) -> Result<Frame, RexsError> {
    let parent = reference_frame(reader, c, depth)?;
    let origin = reader.vector(c, "support_vector")?.unwrap_or([0.0; 3]);
    let u = reader
        .vector(c, "u_axis_vector")?
        .and_then(unit)
        .unwrap_or([1.0, 0.0, 0.0]);
    let w0 = reader
        .vector(c, "w_axis_vector")?
        .and_then(unit)
        .unwrap_or([0.0, 0.0, 1.0]);
    let v = unit(cross(w0, u)).unwrap_or([0.0, 1.0, 0.0]);
    let w = cross(u, v);
    Ok(Frame {
        origin: parent.point(origin),
        axes: [
            parent.direction(u),
            parent.direction(v),
            parent.direction(w),
        ],
    })
}

/// Where the stage's axes are: worm centre and axis, wheel centre and axis (global, mm).
struct Axes {
    worm_centre: [f64; 3],
    x1: [f64; 3],
    wheel_centre: [f64; 3],
    z2: [f64; 3],
}

fn stage_axes(reader: &Reader, parts: &Parts) -> Result<Option<Axes>, RexsError> {
    let has_position = |c: &Component| c.attribute("support_vector").is_some();
    if !has_position(parts.worm) || !has_position(parts.wheel) {
        return Ok(None);
    }
    let worm = own_frame(reader, parts.worm, 0)?;
    let wheel = own_frame(reader, parts.wheel, 0)?;
    let x1 = match parts.worm_shaft {
        Some(s) => own_frame(reader, s, 0)?.axes[0],
        None => worm.axes[0],
    };
    let line = sub(wheel.origin, worm.origin);
    let Some(y1) = unit(sub(line, x1.map(|x| x * dot(line, x1)))) else {
        return Ok(None);
    };
    Ok(Some(Axes {
        worm_centre: worm.origin,
        x1,
        wheel_centre: wheel.origin,
        z2: cross(x1, y1),
    }))
}

/// A bearing's centre (global, mm): its support vector, else its u coordinate on the shaft.
fn bearing_point(
    reader: &Reader,
    b: &Component,
    shaft: Option<&Component>,
) -> Result<Option<[f64; 3]>, RexsError> {
    if b.attribute("support_vector").is_some() {
        let frame = reference_frame(reader, b, 0)?;
        return Ok(reader.vector(b, "support_vector")?.map(|p| frame.point(p)));
    }
    let u = match reader.number(b, "u_coordinate_on_shaft_inner_side", Quantity::Length)? {
        Some(u) => Some(u),
        None => reader.number(b, "u_coordinate_on_shaft", Quantity::Length)?,
    };
    match (u, shaft) {
        (Some(u), Some(s)) => Ok(Some(own_frame(reader, s, 0)?.point([u, 0.0, 0.0]))),
        _ => Ok(None),
    }
}

/// The load point of a shaft (the torque's external_load), global mm.
fn load_point(
    reader: &Reader,
    loads: &[&Component],
    shaft: Option<&Component>,
) -> Result<Option<[f64; 3]>, RexsError> {
    let Some(s) = shaft else { return Ok(None) };
    for l in loads {
        if l.attribute("torque_around_u_axis").is_some() || l.attribute("defines_torque").is_some()
        {
            if let Some(u) = reader.number(l, "u_coordinate_on_shaft", Quantity::Length)? {
                return Ok(Some(own_frame(reader, s, 0)?.point([u, 0.0, 0.0])));
            }
        }
    }
    Ok(None)
}

/// [bending]: FE bending with the worm's body length, shaft radius and bearing positions;
/// then the wheel's shaft radius and bearings ([`wheel_support`]).
fn bending(
    reader: &Reader,
    parts: &Parts,
    worm: &Worm,
    wheel: &Wheel,
    out: &mut GearText,
) -> Result<(), RexsError> {
    out.section("bending");
    match custom(reader, parts.stage, "fe_bending", Quantity::Ratio)? {
        Some(0.0) => out.field_text("model", "none", Some("custom_wormwear_fe_bending = 0")),
        _ => out.field_text(
            "model",
            "fe",
            Some("worm and wheel bending with their shafts and bearings"),
        ),
    }
    if let Some(l) = reader.positive(parts.worm, "length_worm_gear", Quantity::Length)? {
        out.field("worm_body_length_mm", l, "worm_gear.length_worm_gear");
    }
    let sections: Vec<f64> = parts
        .worm_sections
        .iter()
        .map(|s| {
            Ok([
                reader.positive(s, "outer_diameter_begin", Quantity::Length)?,
                reader.positive(s, "outer_diameter_end", Quantity::Length)?,
            ])
        })
        .collect::<Result<Vec<_>, RexsError>>()?
        .into_iter()
        .flatten()
        .flatten()
        .collect();
    if let Some(d) = sections.iter().copied().reduce(f64::min) {
        let r = 0.5 * d;
        if r < worm.root_radius {
            out.field(
                "worm_shaft_radius_mm",
                r,
                "smallest shaft_section outer diameter / 2 of the worm shaft",
            );
        } else {
            out.field("worm_shaft_radius_mm", worm.root_radius, &format!("the worm root radius: the file's shaft sections (smallest {d} mm) are not thinner than the threaded body"));
        }
    }
    let axes = stage_axes(reader, parts)?;
    match &axes {
        Some(ax) => {
            let points = bearing_positions(
                reader,
                &parts.worm_bearings,
                parts.worm_shaft,
                ax.worm_centre,
                ax.x1,
            )?;
            let load = load_point(reader, &parts.worm_loads, parts.worm_shaft)?
                .map(|p| dot(sub(p, ax.worm_centre), ax.x1));
            write_bearings(out, "worm_bearing_positions_mm", points, load, true, "along the worm axis from the worm centre; drive side (nearest the worm's load) first");
        }
        None => out.note(
            "worm_bearing_positions_mm: default (the file gives no positions of worm and wheel)",
        ),
    }
    wheel_support(reader, parts, wheel, axes.as_ref(), out)
}

fn bearing_positions(
    reader: &Reader,
    bearings: &[&Component],
    shaft: Option<&Component>,
    centre: [f64; 3],
    axis: [f64; 3],
) -> Result<Vec<f64>, RexsError> {
    let mut v = Vec::new();
    for b in bearings {
        if let Some(p) = bearing_point(reader, b, shaft)? {
            v.push(dot(sub(p, centre), axis));
        }
    }
    Ok(v)
}

/// Writes two bearing positions ordered by the load: the one nearest the load first
/// (`near_first`) or last.
fn write_bearings(
    out: &mut GearText,
    key: &str,
    mut points: Vec<f64>,
    load: Option<f64>,
    near_first: bool,
    what: &str,
) {
    if points.is_empty() {
        out.note(&format!(
            "{key}: default (no bearings on this shaft in the file)"
        ));
        return;
    }
    if points.len() != 2 {
        out.warn(format!("{key}: the file has {} bearings on this shaft, wormwear's model takes two: default positions used", points.len()));
        return;
    }
    points.sort_by(f64::total_cmp);
    if let Some(l) = load {
        let near_lower = (points[0] - l).abs() <= (points[1] - l).abs();
        if near_lower != near_first {
            points.swap(0, 1);
        }
    }
    out.line(
        key,
        format!("[{}, {}]", float(points[0]), float(points[1])),
        Some(&format!("concept bearings' support_vector, {what}")),
    );
}

/// The wheel's shaft radius and bearing positions, inserted into the [wheel] table written
/// earlier (a table's keys must follow its header).
fn wheel_support(
    reader: &Reader,
    parts: &Parts,
    wheel: &Wheel,
    axes: Option<&Axes>,
    out: &mut GearText,
) -> Result<(), RexsError> {
    let mut lines = GearText::default();
    if let Some(ax) = axes {
        let points = bearing_positions(
            reader,
            &parts.wheel_bearings,
            parts.wheel_shaft,
            ax.wheel_centre,
            ax.z2,
        )?;
        let load = load_point(reader, &parts.wheel_loads, parts.wheel_shaft)?
            .map(|p| dot(sub(p, ax.wheel_centre), ax.z2));
        write_bearings(&mut lines, "bearing_positions_mm", points, load, false, "along the wheel axis z2 from the wheel centre; the fixed end (nearest the wheel's load) last");
    }
    if let (Some(s), Some(_)) = (parts.wheel_shaft, axes) {
        let u_wheel = reader.number(parts.wheel, "u_coordinate_on_shaft", Quantity::Length)?;
        let mut radius = None;
        for sec in &parts.wheel_sections {
            let u0 = reader.number(sec, "u_coordinate_on_shaft", Quantity::Length)?;
            let len = reader.positive(sec, "length", Quantity::Length)?;
            let d = reader.positive(sec, "outer_diameter_begin", Quantity::Length)?;
            if let (Some(u), Some(u0), Some(len), Some(d)) = (u_wheel, u0, len, d) {
                if u >= u0 && u <= u0 + len {
                    radius = Some(0.5 * d);
                }
            }
        }
        let hub_default = custom(reader, parts.wheel, "hub_radius", Quantity::Length)?
            .unwrap_or(0.35 * wheel.reference_radius);
        match radius {
            Some(r) if r < hub_default => lines.field("shaft_radius_mm", r, &format!("shaft_section of shaft [{}] under the wheel: outer diameter / 2", s.id)),
            Some(r) => lines.warn(format!("the wheel shaft radius {r} mm is not below the default hub radius {hub_default:.3} mm: the default shaft radius is used")),
            None => {}
        }
    }
    out.warnings.append(&mut lines.warnings);
    insert_into_table(&mut out.text, "wheel", &lines.text);
    Ok(())
}

/// Inserts lines at the end of table `[name]` of a TOML text.
fn insert_into_table(text: &mut String, name: &str, lines: &str) {
    if lines.is_empty() {
        return;
    }
    let header = format!("\n[{name}]\n");
    let Some(start) = text.find(&header) else {
        return;
    };
    let after = start + header.len();
    let end = text[after..].find("\n[").map_or(text.len(), |i| after + i);
    text.insert_str(end, lines);
}

/// The comment block listing every attribute of the stage's components that the import did
/// not use, and the count of components outside the stage.
fn unused_block(model: &Model, reader: &Reader, parts: &Parts, out: &mut GearText) {
    let used = reader.used.borrow();
    let all = parts.all();
    let _ = write!(
        out.text,
        "\n# ---- REXS attributes not used by this import ----\n"
    );
    let mut count = 0;
    for c in &all {
        for a in &c.attributes {
            if !used.contains(&(c.id, a.id.clone())) {
                count += 1;
                let _ = writeln!(
                    out.text,
                    "# {}: {} = {} [{}]",
                    c.label(),
                    a.id,
                    a.value,
                    a.unit
                );
            }
        }
    }
    if count == 0 {
        out.text.push_str("# (none)\n");
    }
    let ids: BTreeSet<u64> = all.iter().map(|c| c.id).collect();
    let others = model
        .components
        .iter()
        .filter(|c| !ids.contains(&c.id))
        .count();
    if others > 0 {
        let _ = writeln!(out.text, "# {others} other component(s) of the model are not part of this stage and were not read.");
    }
}
