//! The contact-pattern assistant (MODEL §17): the inverse of the unloaded analysis. Given a
//! target shape of the no-load (or loaded) contact pattern — its centre across the face from
//! the entering to the leaving side, its centre up the flank, its extents along the face and up
//! the flank, any of them — it searches the wheel's cutting settings (by default the cutting
//! centre distance, the hob swivel and the hob oversize, each within bounds) for those that
//! bring the pattern's shape ([`PatternShape`]) closest to the target.
//!
//! The objective is the sum over the target's given components of (shape - target)^2, every
//! component a share of the face or of the flank height in [0, 1]; a setting whose wheel cannot
//! be generated, or that leaves no pattern, scores [`FAILED`] and is recorded with its reason.
//! The search is argmin's Nelder–Mead simplex on the settings scaled to [0, 1] between their
//! bounds (a point outside is scored at the nearest point inside plus a penalty growing with
//! the distance), started at the base gear's settings with a simplex a quarter of each range
//! wide and restarted from the best point with a simplex half as wide while a restart improves
//! it, within a budget of evaluations. The objective steps as cells enter or leave the pattern
//! (a cell is 1/cells_face of the face and 1/cells_height of the flank): what it can resolve is
//! the flank grid's cell.
//!
//! Rooms: `search` the simplex, `files` what a search writes (the best gear file with its
//! comments kept, the search's path, the patterns before and after).

pub mod files;
mod search;

pub use files::{best_gear_text, shape_text, target_text, write, BEST_GEAR_FILE};

use crate::geometry::Geometry;
use crate::input::{self, GearSet, InputError};
use crate::kinematics::pattern_shape::PatternShape;

/// The setting that grows the hob's reference, tip and root radii together, mm (the hob's
/// oversize over the base gear file's hob); every other setting is a numeric field of the gear
/// file by its dotted name.
pub const HOB_OVERSIZE: &str = "hob.oversize_mm";

/// The hob radii [`HOB_OVERSIZE`] moves.
const HOB_RADII: [&str; 3] = [
    "hob.reference_radius_mm",
    "hob.tip_radius_mm",
    "hob.root_radius_mm",
];

/// Evaluations a search may spend by default, and at most.
pub const DEFAULT_EVALUATIONS: usize = 60;
pub const MAX_EVALUATIONS: usize = 2000;

/// Decimals of its unit (mm, deg) each best setting is rounded to: 0.1 um, 0.0001 deg.
pub const ROUNDED_DECIMALS: i32 = 4;

/// Settings a search may vary at most.
pub const MAX_SETTINGS: usize = 8;

/// The objective of a setting that fails (its wheel not generated, no pattern): above any
/// pattern's, which is at most 4.
pub const FAILED: f64 = 10.0;

/// The objective as pattern.json states it.
pub const OBJECTIVE: &str = "sum over the target's given components of (shape - target)^2; \
    each component a share of the face or the flank height in [0, 1]";

/// Why a search cannot start or finish.
#[derive(Debug, thiserror::Error)]
pub enum PatternError {
    /// A target, a setting or a bound is not valid (field, value, problem).
    #[error("{0}")]
    Invalid(String),
    /// The base gear cannot be analysed.
    #[error("the base gear: {0}")]
    Base(String),
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
}

/// Which pattern the target is for (pattern.json writes [`Which::name`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Which {
    /// The no-load pattern of the unloaded analysis (MODEL §4.4): a marking test.
    NoLoad,
    /// The loaded pattern of the loaded analysis (MODEL §5), with the gear file's bending.
    Loaded,
}

impl Which {
    /// The name in pattern.json and the messages: "no-load" or "loaded".
    pub fn name(self) -> &'static str {
        match self {
            Which::NoLoad => "no-load",
            Which::Loaded => "loaded",
        }
    }
}

impl serde::Serialize for Which {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

/// A target pattern shape: the components to meet, each a share in [0, 1] (None: free).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Target {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub centre_across_face: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub centre_up_flank: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub extent_along_face: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub extent_up_flank: Option<f64>,
}

impl Target {
    /// The components' names, as in `summary.json`'s `pattern_shape`.
    pub const NAMES: [&'static str; 4] = [
        "centre_across_face",
        "centre_up_flank",
        "extent_along_face",
        "extent_up_flank",
    ];

    /// A target from `name=value,name=value` (the CLI's `--target`), checked.
    pub fn parse(text: &str) -> Result<Self, PatternError> {
        let mut target = Target::default();
        for item in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let Some((name, value)) = item.split_once('=') else {
                return Err(invalid(format!(
                    "--target {item:?}: write name=value, e.g. centre_across_face=0.6"
                )));
            };
            let value: f64 = value.trim().parse().map_err(|_| {
                invalid(format!(
                    "--target {item:?}: {:?} is not a number",
                    value.trim()
                ))
            })?;
            let slot = target.slot(name.trim())?;
            if slot.replace(value).is_some() {
                return Err(invalid(format!("--target: {} given twice", name.trim())));
            }
        }
        target.check()?;
        Ok(target)
    }

    /// The component named `name` (an unknown name is refused with the names allowed).
    fn slot(&mut self, name: &str) -> Result<&mut Option<f64>, PatternError> {
        Ok(match name {
            "centre_across_face" => &mut self.centre_across_face,
            "centre_up_flank" => &mut self.centre_up_flank,
            "extent_along_face" => &mut self.extent_along_face,
            "extent_up_flank" => &mut self.extent_up_flank,
            _ => {
                return Err(invalid(format!(
                    "target: unknown component {name:?}: allowed {}",
                    Self::NAMES.join(", ")
                )))
            }
        })
    }

    /// At least one component; centres in [0, 1], extents in (0, 1].
    pub fn check(&self) -> Result<(), PatternError> {
        let given = self.given();
        if given.is_empty() {
            return Err(invalid(format!(
                "target: give at least one of {} (shares in [0, 1])",
                Self::NAMES.join(", ")
            )));
        }
        for (name, value) in given {
            let extent = name.starts_with("extent");
            let inside = match extent {
                true => value > 0.0 && value <= 1.0,
                false => (0.0..=1.0).contains(&value),
            };
            if !inside {
                let range = if extent { "(0, 1]" } else { "[0, 1]" };
                return Err(invalid(format!(
                    "target {name} = {value}: out of range: allowed {range} (a share of the \
                     face or of the flank height)"
                )));
            }
        }
        Ok(())
    }

    /// The given components, by name.
    pub fn given(&self) -> Vec<(&'static str, f64)> {
        let values = [
            self.centre_across_face,
            self.centre_up_flank,
            self.extent_along_face,
            self.extent_up_flank,
        ];
        Self::NAMES
            .into_iter()
            .zip(values)
            .filter_map(|(n, v)| v.map(|v| (n, v)))
            .collect()
    }

    /// The objective ([`OBJECTIVE`]) of a pattern's shape.
    pub fn distance(&self, shape: &PatternShape) -> f64 {
        self.given()
            .into_iter()
            .map(|(name, t)| (component(shape, name) - t).powi(2))
            .sum()
    }
}

/// A shape's component by its name in [`Target::NAMES`].
pub fn component(shape: &PatternShape, name: &str) -> f64 {
    match name {
        "centre_across_face" => shape.centre_across_face,
        "centre_up_flank" => shape.centre_up_flank,
        "extent_along_face" => shape.extent_along_face,
        "extent_up_flank" => shape.extent_up_flank,
        _ => f64::NAN,
    }
}

fn invalid(message: String) -> PatternError {
    PatternError::Invalid(message)
}

/// A setting the search varies: a gear-file field by dotted name (or [`HOB_OVERSIZE`]), its
/// bounds and the base gear's value it starts from, in the field's own units.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Setting {
    pub name: String,
    pub min: f64,
    pub max: f64,
    pub start: f64,
}

/// A setting as asked for: `name=min:max` (the CLI's `--vary`).
pub fn parse_bounds(text: &str) -> Result<(String, f64, f64), PatternError> {
    let form = || {
        invalid(format!(
            "--vary {text:?}: write name=min:max, e.g. cutting.centre_distance_mm=124.5:125.5"
        ))
    };
    let (name, range) = text.split_once('=').ok_or_else(form)?;
    let (lo, hi) = range.split_once(':').ok_or_else(form)?;
    let number = |s: &str| s.trim().parse::<f64>().map_err(|_| form());
    Ok((name.trim().to_string(), number(lo)?, number(hi)?))
}

/// One evaluation of the search: the settings' values (in [`Assistant::settings`]' order), the
/// pattern's shape, the objective, and why it failed where it did.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Evaluation {
    pub values: Vec<f64>,
    pub shape: Option<PatternShape>,
    pub objective: f64,
    pub error: Option<String>,
}

/// What a search found.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Outcome {
    /// The base gear's settings.
    pub start: Evaluation,
    /// The best settings found (the start where nothing was better).
    pub best: Evaluation,
    /// Every evaluation in the order made (repeated points are not evaluated again).
    pub path: Vec<Evaluation>,
    /// Restarts of the simplex after the first run.
    pub restarts: usize,
    /// Why the search stopped: "converged" (a restart brought nothing), "target met" (the
    /// objective at most 1e-6), "budget", "interrupted" or "optimiser error".
    pub stopped: &'static str,
}

/// A search: the base gear file, the target, the settings and the budget, checked.
#[derive(Debug, Clone)]
pub struct Assistant {
    pub base_file: String,
    /// The base gear file's text (the best gear file is this text with the settings changed).
    pub base_text: String,
    base: toml::Table,
    pub target: Target,
    pub settings: Vec<Setting>,
    pub which: Which,
    pub evaluations: usize,
    /// What the assistant decided for the user: default settings and bounds narrowed.
    pub notes: Vec<String>,
}

impl Assistant {
    /// A search on the gear file `base_text` (named `base_file`): `bounds` the settings to vary
    /// with their bounds (None: the default settings, [`Assistant::default_bounds`]), checked
    /// against the base gear (each a numeric field of it or [`HOB_OVERSIZE`], the base's value
    /// inside its bounds, each bound a wheel the hob can generate).
    pub fn new(
        base_file: String,
        base_text: String,
        target: Target,
        bounds: Option<Vec<(String, f64, f64)>>,
        which: Which,
        evaluations: usize,
    ) -> Result<Self, PatternError> {
        target.check()?;
        if !(1..=MAX_EVALUATIONS).contains(&evaluations) {
            return Err(invalid(format!(
                "evaluations = {evaluations}: out of range: allowed [1, {MAX_EVALUATIONS}]"
            )));
        }
        let base = input::parse_document(&base_text).map_err(|e| base_error(&e))?;
        let gear = input::load_document(&base).map_err(|e| base_error(&e))?;
        let mut assistant = Self {
            base_file,
            base_text,
            base,
            target,
            settings: Vec::new(),
            which,
            evaluations,
            notes: Vec::new(),
        };
        let defaults = bounds.is_none();
        let bounds = bounds.unwrap_or_else(|| Self::default_bounds(&assistant.base, &gear));
        assistant.settings = assistant.checked_settings(bounds, defaults)?;
        Ok(assistant)
    }

    /// The default settings (MODEL §17): the cutting centre distance ± 0.2 m_x, the hob swivel
    /// (cutting inclination) ± 0.5 deg about the base's, and the hob oversize 0 to 0.2 m_x.
    pub fn default_bounds(base: &toml::Table, gear: &GearSet) -> Vec<(String, f64, f64)> {
        let m_mm = gear.worm.axial_module() * 1e3;
        let centre = number_at(base, "cutting.centre_distance_mm").unwrap_or(0.0);
        let swivel = number_at(base, "cutting.inclination_deg").unwrap_or(0.0);
        vec![
            (
                "cutting.centre_distance_mm".into(),
                centre - 0.2 * m_mm,
                centre + 0.2 * m_mm,
            ),
            ("cutting.inclination_deg".into(), swivel - 0.5, swivel + 0.5),
            (HOB_OVERSIZE.into(), 0.0, 0.2 * m_mm),
        ]
    }

    /// The settings of `bounds`, checked; with `defaults`, a bound the hob cannot generate is
    /// moved halfway to the start until it can (up to 8 times, noted), else refused.
    fn checked_settings(
        &mut self,
        bounds: Vec<(String, f64, f64)>,
        defaults: bool,
    ) -> Result<Vec<Setting>, PatternError> {
        if bounds.is_empty() || bounds.len() > MAX_SETTINGS {
            return Err(invalid(format!(
                "vary: {} settings: allowed 1 to {MAX_SETTINGS}",
                bounds.len()
            )));
        }
        let mut settings = Vec::new();
        for (name, min, max) in bounds {
            let start = self.start_value(&name, &settings)?;
            let field = format!("vary {name}");
            if !(min.is_finite() && max.is_finite() && min < max) {
                return Err(invalid(format!(
                    "{field} = {min}:{max}: give finite bounds with min < max (to keep a field \
                     fixed, leave it out)"
                )));
            }
            if !(min..=max).contains(&start) {
                return Err(invalid(format!(
                    "{field} = {min}:{max}: the base gear's value {start} lies outside; the \
                     search starts from the base gear: widen the bounds or change the base"
                )));
            }
            settings.push(Setting {
                name,
                min,
                max,
                start,
            });
        }
        self.settings = settings;
        for k in 0..self.settings.len() {
            self.check_bound(k, false, defaults)?;
            self.check_bound(k, true, defaults)?;
        }
        Ok(std::mem::take(&mut self.settings))
    }

    /// The base gear's value of the setting `name` (0 for the hob oversize; a field the base
    /// leaves out starts at 0 where the gear file takes 0 for it, its default), checked: a
    /// numeric field of the gear file, not twice, not a hob radius beside the oversize.
    fn start_value(&self, name: &str, earlier: &[Setting]) -> Result<f64, PatternError> {
        let field = format!("vary {name}");
        if earlier.iter().any(|s| s.name == name) {
            return Err(invalid(format!("{field}: given twice")));
        }
        let radii = |s: &str| HOB_RADII.contains(&s);
        let clash = earlier.iter().any(|s| {
            (s.name == HOB_OVERSIZE && radii(name)) || (name == HOB_OVERSIZE && radii(&s.name))
        });
        if clash {
            return Err(invalid(format!(
                "{field}: {HOB_OVERSIZE} moves the hob's radii; vary either it or a radius"
            )));
        }
        if name == HOB_OVERSIZE {
            return Ok(0.0);
        }
        match crate::spread::lookup(&self.base, name) {
            Some(v) => crate::spread::number(v).ok_or_else(|| {
                invalid(format!(
                    "{field}: the gear file's {name} is {v}, not a number: only numeric fields \
                     can be searched"
                ))
            }),
            None => self.absent_start(name, &field),
        }
    }

    /// The start of a field the base leaves out: 0, where the gear file takes it and the gear
    /// with 0 is the base gear (0 is its default).
    fn absent_start(&self, name: &str, field: &str) -> Result<f64, PatternError> {
        let mut with_zero = self.base.clone();
        let zero = input::set_dotted(&mut with_zero, name, Some(toml::Value::Float(0.0)))
            .and_then(|_| input::load_document(&with_zero));
        let base = input::load_document(&self.base).map_err(|e| base_error(&e))?;
        let same = |g: &GearSet| serde_json::to_string(g).ok() == serde_json::to_string(&base).ok();
        match zero {
            Ok(g) if same(&g) => Ok(0.0),
            Ok(_) => Err(invalid(format!(
                "{field}: the base gear file does not set {name}: write its value there (the \
                 search starts from the base gear)"
            ))),
            Err(_) => {
                let near = crate::spread::nearest_names(&self.base, name, 3);
                Err(invalid(format!(
                    "{field}: the gear file has no numeric field {name} (nor is it \
                     {HOB_OVERSIZE}); the base's nearest numeric fields: {}",
                    near.join(", ")
                )))
            }
        }
    }

    /// Checks that setting `k` at its upper (`upper`) or lower bound, the others at their
    /// starts, is a gear whose wheel the hob generates; with `narrow`, moves a failing bound
    /// toward the start, to the last point that does (bisection, 10 halvings; noted), else
    /// refuses it with the reason.
    fn check_bound(&mut self, k: usize, upper: bool, narrow: bool) -> Result<(), PatternError> {
        let s = self.settings[k].clone();
        let bound = if upper { s.max } else { s.min };
        let Err(why) = self.generates(k, bound) else {
            return Ok(());
        };
        if !narrow {
            let side = if upper { "max" } else { "min" };
            return Err(invalid(format!(
                "vary {} = {}:{}: at its {side} {bound} (the other settings at the base gear's) \
                 the wheel cannot be generated: {why}",
                s.name, s.min, s.max
            )));
        }
        let (mut good, mut bad) = (s.start, bound);
        for _ in 0..10 {
            let middle = 0.5 * (good + bad);
            match self.generates(k, middle) {
                Ok(()) => good = middle,
                Err(_) => bad = middle,
            }
        }
        if good == if upper { s.min } else { s.max } {
            return Err(invalid(format!(
                "vary {}: the hob generates the wheel only at the base gear's value {}: no \
                 default range to search; name the settings to vary (--vary)",
                s.name, s.start
            )));
        }
        self.notes.push(format!(
            "{}: the default {} {bound:.4} narrowed to {good:.4}, where the hob still generates \
             the wheel ({why})",
            s.name,
            if upper { "max" } else { "min" }
        ));
        let setting = &mut self.settings[k];
        match upper {
            true => setting.max = good,
            false => setting.min = good,
        }
        Ok(())
    }

    /// Whether the gear with setting `k` at `value` and the others at their starts is valid
    /// and its wheel generated (Err: why not).
    fn generates(&self, k: usize, value: f64) -> Result<(), String> {
        let mut values: Vec<f64> = self.settings.iter().map(|s| s.start).collect();
        values[k] = value;
        let gear = self.gear(&values)?;
        Geometry::build(&gear)
            .map(|_| ())
            .map_err(|e| e.to_string())
    }

    /// The base gear document with the settings at `values` (the hob oversize added to the
    /// base's hob radii).
    pub fn document(&self, values: &[f64]) -> Result<toml::Table, InputError> {
        let mut document = self.base.clone();
        for (setting, &v) in self.settings.iter().zip(values) {
            let changes: Vec<(&str, f64)> = match setting.name.as_str() {
                HOB_OVERSIZE => HOB_RADII
                    .iter()
                    .map(|r| {
                        let base = number_at(&self.base, r).unwrap_or(f64::NAN);
                        (*r, base + v)
                    })
                    .collect(),
                name => vec![(name, v)],
            };
            for (name, value) in changes {
                input::set_dotted(&mut document, name, Some(toml::Value::Float(value)))?;
            }
        }
        Ok(document)
    }

    /// The validated gear at `values` (the loader's message where it is not valid).
    pub fn gear(&self, values: &[f64]) -> Result<GearSet, String> {
        self.document(values)
            .and_then(|d| input::load_document(&d))
            .map_err(|e| crate::runner::error_chain(&e))
    }

    /// The pattern's shape at `values` and its objective (or why it failed).
    pub fn evaluate(&self, values: &[f64]) -> Evaluation {
        let shape = self.gear(values).and_then(|g| self.shape(&g));
        let (shape, objective, error) = match shape {
            Ok(Some(s)) => (Some(s), self.target.distance(&s), None),
            Ok(None) => (None, FAILED, Some("no contact pattern".to_string())),
            Err(e) => (None, FAILED, Some(e)),
        };
        Evaluation {
            values: values.to_vec(),
            shape,
            objective,
            error,
        }
    }

    /// The shape of the asked pattern of `gear`: the unloaded analysis, and the loaded one
    /// with the gear file's bending for [`Which::Loaded`].
    ///
    /// The grid's rows are evenly spaced here: the band at the worm-tip trace (MODEL §3.3)
    /// changes its row counts in steps as the settings move the trace, which would make the
    /// objective jump where the search needs it continuous.
    fn shape(&self, gear: &GearSet) -> Result<Option<PatternShape>, String> {
        let chain = |e: &dyn std::error::Error| crate::runner::error_chain(e);
        let mut even = gear.clone();
        even.analysis.tip_trace_refinement = 0;
        let gear = &even;
        let geo = Geometry::build(gear).map_err(|e| chain(&e))?;
        let tca = crate::kinematics::analyse(gear, &geo).map_err(|e| chain(&e))?;
        if self.which == Which::NoLoad {
            return Ok(tca.pattern_shape);
        }
        let mut warnings = Vec::new();
        let (bending, _) = crate::runner::bending_model(gear, &geo, &mut warnings, &mut |_| Ok(()))
            .map_err(|e| chain(&e))?;
        let ltca =
            crate::runner::loaded_analysis(gear, &geo, &tca, bending.as_ref(), &mut warnings)
                .map_err(|e| chain(&e))?;
        let wf = geo.wheel_flank(tca.loaded_flank);
        Ok(crate::output::ltca::LtcaSummary::new(&tca, wf, &ltca).pattern_shape)
    }

    /// Runs the search from the base gear's settings: `on_evaluation` hears each new
    /// evaluation (its index from 0); `interrupt` stops it at the next evaluation.
    pub fn run(
        &self,
        on_evaluation: &(dyn Fn(usize, &Evaluation) + Sync),
        interrupt: &(dyn Fn() -> bool + Sync),
    ) -> Result<Outcome, PatternError> {
        let starts: Vec<f64> = self.settings.iter().map(|s| s.start).collect();
        let start = self.evaluate(&starts);
        if let Some(e) = &start.error {
            return Err(PatternError::Base(e.clone()));
        }
        let mut outcome = search::nelder_mead(self, start, on_evaluation, interrupt);
        self.round_best(&mut outcome, on_evaluation);
        Ok(outcome)
    }

    /// The best settings rounded to [`ROUNDED_DECIMALS`] decimals of their units (what a
    /// workshop sets, and what the best gear file writes), evaluated and kept as the best
    /// where the pattern is as good (within [`search::TARGET_MET`]); added to the path.
    fn round_best(
        &self,
        outcome: &mut Outcome,
        on_evaluation: &(dyn Fn(usize, &Evaluation) + Sync),
    ) {
        let scale = 10f64.powi(ROUNDED_DECIMALS);
        let rounded: Vec<f64> = outcome
            .best
            .values
            .iter()
            .map(|v| (v * scale).round() / scale)
            .collect();
        let inside = self
            .settings
            .iter()
            .zip(&rounded)
            .all(|(s, v)| (s.min..=s.max).contains(v));
        if rounded == outcome.best.values || !inside {
            return;
        }
        let evaluation = self.evaluate(&rounded);
        on_evaluation(outcome.path.len(), &evaluation);
        outcome.path.push(evaluation.clone());
        if evaluation.objective <= outcome.best.objective + search::TARGET_MET {
            outcome.best = evaluation;
        }
    }
}

/// The number at a dotted name of a gear document.
fn number_at(doc: &toml::Table, name: &str) -> Option<f64> {
    crate::spread::lookup(doc, name).and_then(crate::spread::number)
}

fn base_error(e: &InputError) -> PatternError {
    PatternError::Base(crate::runner::error_chain(e))
}
