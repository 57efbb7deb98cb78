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
//!
//! Rooms, by REXS component: `worm`, `hob`, `wheel`, `stage` (operating data and load),
//! `lubricant` (with the materials), `shafts` (frames, bearings, the bending section); here
//! finding the stage, the reader of attributes, the gear-file text and [`import`].

mod hob;
mod lubricant;
mod shafts;
mod stage;
mod wheel;
mod worm;

use hob::*;
use lubricant::*;
use shafts::*;
use stage::*;
use wheel::*;
use worm::*;

use super::units::{convert, Quantity};
use super::{Component, LoadCase, Model, RexsError, Value};
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
    // With a load spectrum the speed's sign (the rotation) is in its load cases: the first's.
    let first = model.load_cases.first().map(|c| model.with_load_case(c));
    let turning = first.as_ref().unwrap_or(model);
    let (turning_reader, turning_parts) = (Reader::new(turning), Parts::locate(turning, &info)?);
    let rotation = rotation(&turning_reader, &turning_parts, &worm)?;
    operating(&reader, &parts, (&worm, &wheel), rotation, &mut out)?;
    materials(&reader, &parts, &mut out)?;
    lubricant(&reader, &parts, &mut out)?;
    match model.load_cases.is_empty() {
        true => conditions(&reader, &parts, &worm, &mut out)?,
        false => duty_cycle(model, &info, &worm, &mut out)?,
    }
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

    /// A count the gear file needs (`what`, e.g. "the number of starts z1"): present and from 1
    /// to `max`, else an error naming the attribute, its value and the range.
    fn count(&self, c: &Component, id: &str, what: &str, max: i64) -> Result<i64, RexsError> {
        match self.integer(c, id)? {
            None => Err(RexsError::attribute(
                c,
                id,
                format!("missing: {what} is needed"),
            )),
            Some(z) if (1..=max).contains(&z) => Ok(z),
            Some(z) => Err(RexsError::attribute(
                c,
                id,
                format!("{z}: {what} must be from 1 to {max}"),
            )),
        }
    }

    fn integer(&self, c: &Component, id: &str) -> Result<Option<i64>, RexsError> {
        match self.number(c, id, Quantity::Ratio)? {
            None => Ok(None),
            // Exact as an integer up to 2^53 (beyond it, no count of teeth).
            Some(v) if v.fract() == 0.0 && v.abs() <= 9.007_199_254_740_992e15 => {
                Ok(Some(v as i64))
            }
            Some(v) if v.fract() == 0.0 => Err(RexsError::attribute(
                c,
                id,
                format!("{v:e} is too large for a count"),
            )),
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

/// A value wormwear wrote as a custom attribute (`custom_wormwear_<name>`), for the round trip.
fn custom(
    reader: &Reader,
    c: &Component,
    name: &str,
    q: Quantity,
) -> Result<Option<f64>, RexsError> {
    reader.number(c, &format!("{CUSTOM_PREFIX}{name}"), q)
}

/// A value (mm) with the attribute or rule it comes from.
type Sourced = (f64, String);

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
