//! Design studies: variants of a base gear file, each the base with some fields changed by
//! dotted name (`conditions.worm_torque_nm = 30`), run in parallel on the local cores
//! ([`run`]) or one at a time by another engine ([`run_variant`]: the Python package's Dask
//! tasks), one [`Row`] of key results each.
//!
//! A sweep file names the base gear file and the variants, as a grid (every combination of
//! the listed values, the first name varying slowest) or as a list of cases:
//!
//! ```toml
//! base = "gear-1x40-design.toml"      # relative to the sweep file
//! stages = ["ltca", "wear"]           # optional; default: those of `wormwear run`
//! cycles = 180000                     # optional life overrides, as the CLI's flags
//! [grid]
//! "conditions.worm_torque_nm" = [30.0, 60.0, 90.0]
//! "lubricant.composite_roughness_um" = [0.5, 1.0]
//! ```
//!
//! A variant that fails (an input out of range, a solver failure) gives a row with its error;
//! the others go on. Each finished variant leaves `variants/NAME/variant.json`, sealed with the
//! fingerprint of its inputs: a sweep run again into the same directory reuses the variants
//! whose inputs are unchanged (resume) and runs the others.

use crate::input::{self, GearSet, InputError};
use crate::runner::{error_chain, LifeOverrides, OverrideNames};
use crate::{Request, Results, RunError, Source, Stage};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

pub mod html;

/// Why a sweep could not start or finish (a failing variant is a row, not an error).
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    #[error("cannot read {path}: {message}")]
    Read { path: String, message: String },
    /// The sweep file is not valid (field, value, problem).
    #[error("{0}")]
    Invalid(String),
    /// The base gear file is not valid.
    #[error("base gear file {path}")]
    Base {
        path: String,
        #[source]
        source: InputError,
    },
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
}

/// The sweep file as written.
#[derive(Debug, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct SweepFile {
    base: String,
    #[serde(default)]
    stages: Option<Vec<String>>,
    #[serde(default)]
    cycles: Option<f64>,
    #[serde(default)]
    step_cycles: Option<f64>,
    #[serde(default)]
    step_wear_um: Option<f64>,
    #[serde(default)]
    no_pitting: bool,
    #[serde(default)]
    grid: Option<toml::Table>,
    #[serde(default)]
    cases: Option<Vec<toml::Table>>,
}

/// What every variant runs: the stages and the life overrides.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Settings {
    pub stages: BTreeSet<Stage>,
    #[serde(serialize_with = "overrides_json")]
    pub overrides: LifeOverrides,
}

fn overrides_json<S: serde::Serializer>(o: &LifeOverrides, s: S) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeStruct;
    let mut m = s.serialize_struct("LifeOverrides", 4)?;
    m.serialize_field("cycles", &o.cycles)?;
    m.serialize_field("step_cycles", &o.step_cycles)?;
    m.serialize_field("step_wear_um", &o.step_wear_um)?;
    m.serialize_field("no_pitting", &o.no_pitting)?;
    m.end()
}

impl Settings {
    /// The stages by name (None: those of `wormwear run`, the life when the base has a
    /// `[wear]` section or cycles are given) and the overrides.
    pub fn new(
        stages: Option<&[String]>,
        overrides: LifeOverrides,
        base_has_life: bool,
    ) -> Result<Self, SweepError> {
        let stages = match stages {
            Some(names) => names
                .iter()
                .map(|n| {
                    Stage::parse(n).ok_or_else(|| {
                        SweepError::Invalid(format!(
                            "stages = {n:?}: not a stage (geometry, tca, ltca, wear, report)"
                        ))
                    })
                })
                .collect::<Result<BTreeSet<_>, _>>()?,
            None => Stage::ALL
                .into_iter()
                .filter(|s| *s != Stage::Wear || base_has_life || overrides.asks_for_life())
                .collect(),
        };
        if stages.is_empty() {
            return Err(SweepError::Invalid(
                "stages = []: name at least one stage".into(),
            ));
        }
        if let (false, Some(name)) = (stages.contains(&Stage::Wear), overrides.given().first()) {
            let names: Vec<&str> = stages.iter().map(|s| s.name()).collect();
            return Err(SweepError::Invalid(format!(
                "{name} is a life override, but the stages ({}) have no life: add \"wear\" to \
                 the stages or remove {name}",
                names.join(", ")
            )));
        }
        Ok(Self { stages, overrides })
    }
}

/// One variant: its name (its folder) and the values it changes, by dotted name.
#[derive(Debug, Clone, PartialEq)]
pub struct Variant {
    pub name: String,
    pub values: Vec<(String, toml::Value)>,
}

/// A sweep: the base gear document, the varied names and the variants.
#[derive(Debug, Clone)]
pub struct Sweep {
    /// The base gear file as given (for messages and summary.json).
    pub base_file: String,
    pub base: toml::Table,
    /// The varied dotted names, in the order of the file.
    pub parameters: Vec<String>,
    pub variants: Vec<Variant>,
    pub settings: Settings,
}

/// Where a sweep file's `base` may lie.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BaseAccess {
    /// In the sweep file's directory or below it (the default: a sweep file from elsewhere
    /// cannot read, nor echo in an error, a file outside its folder).
    Confined,
    /// Anywhere (the CLI's `--base-anywhere`).
    Anywhere,
}

impl Sweep {
    /// Reads a sweep file and its base gear file (which must be valid and, by default, lie in
    /// the sweep file's directory or below it).
    pub fn load(path: &Path) -> Result<Self, SweepError> {
        Self::load_with(path, BaseAccess::Confined)
    }

    /// [`Sweep::load`] with the base allowed where `access` says.
    pub fn load_with(path: &Path, access: BaseAccess) -> Result<Self, SweepError> {
        let read = |p: &Path| {
            crate::files::read_text(p, crate::files::INPUT_LIMIT).map_err(|e| SweepError::Read {
                path: p.display().to_string(),
                message: e.to_string(),
            })
        };
        let text = read(path)?;
        let file: SweepFile = toml::from_str(&text)
            .map_err(|e| SweepError::Invalid(format!("{}: {e}", path.display())))?;
        let (base_file, base) = base_document(folder_of(path), &file.base, access)?;
        let overrides = LifeOverrides {
            cycles: file.cycles,
            step_cycles: file.step_cycles,
            step_wear_um: file.step_wear_um,
            no_pitting: file.no_pitting,
        };
        let (parameters, variants) = match (file.grid, file.cases) {
            (Some(grid), None) => axes_variants(in_file_order(flat(&grid), &text))?,
            (None, Some(cases)) => case_variants(&cases)?,
            _ => {
                return Err(SweepError::Invalid(format!(
                    "{}: give the variants as [grid] (dotted name = list of values) or as \
                     [[cases]] (one table per variant), one of the two",
                    path.display()
                )))
            }
        };
        Self::new(
            base_file,
            base,
            parameters,
            variants,
            file.stages.as_deref(),
            overrides,
        )
    }

    /// A sweep from its parts: the base gear (checked valid), the varied names and variants,
    /// the stages by name and the life overrides.
    pub fn new(
        base_file: String,
        base: toml::Table,
        parameters: Vec<String>,
        variants: Vec<Variant>,
        stages: Option<&[String]>,
        overrides: LifeOverrides,
    ) -> Result<Self, SweepError> {
        let gear = input::load_document(&base).map_err(|source| SweepError::Base {
            path: base_file.clone(),
            source,
        })?;
        let settings = Settings::new(stages, overrides, gear.wear.is_some())?;
        // The life overrides checked on the base before any variant runs (a variant that
        // changes the plan is checked again when it runs).
        if settings.stages.contains(&Stage::Wear) {
            overrides
                .plan(&gear, OverrideNames::Python)
                .map_err(|e| SweepError::Invalid(format!("the sweep's life: {e}")))?;
        }
        if variants.is_empty() {
            return Err(SweepError::Invalid("the sweep has no variant".into()));
        }
        let mut names = BTreeSet::new();
        for v in &variants {
            if !names.insert(v.name.as_str()) {
                return Err(SweepError::Invalid(format!(
                    "two variants are named {:?}: names must differ (they name the folders)",
                    v.name
                )));
            }
        }
        Ok(Self {
            base_file,
            base,
            parameters,
            variants,
            settings,
        })
    }
}

/// The base gear file `written` (relative to `folder`) as (its path as given, its document):
/// readable, TOML, and with `access` confined, inside `folder` or below it.
pub(crate) fn base_document(
    folder: &Path,
    written: &str,
    access: BaseAccess,
) -> Result<(String, toml::Table), SweepError> {
    let base_path = folder.join(written);
    // A base that cannot be read is named as the file wrote it.
    let named = |e: SweepError| match e {
        SweepError::Read { path, message } => {
            SweepError::Invalid(format!("base = {written:?}: cannot read {path}: {message}"))
        }
        e => e,
    };
    if access == BaseAccess::Confined {
        confined(folder, &base_path, written).map_err(named)?;
    }
    let base_file = base_path.display().to_string();
    let text = crate::files::read_text(&base_path, crate::files::INPUT_LIMIT).map_err(|e| {
        named(SweepError::Read {
            path: base_file.clone(),
            message: e.to_string(),
        })
    })?;
    let base = input::parse_document(&text).map_err(|source| SweepError::Base {
        path: base_file.clone(),
        source,
    })?;
    Ok((base_file, base))
}

/// The names and values of a table, nested tables flattened to dotted names (`[grid]`
/// written with bare dotted keys nests them).
pub(crate) fn flatten(table: &toml::Table, prefix: &str, out: &mut Vec<(String, toml::Value)>) {
    for (key, value) in table {
        let name = match prefix.is_empty() {
            true => key.clone(),
            false => format!("{prefix}.{key}"),
        };
        match value {
            toml::Value::Table(t) => flatten(t, &name, out),
            v => out.push((name, v.clone())),
        }
    }
}

/// [`flatten`] from the top.
fn flat(table: &toml::Table) -> Vec<(String, toml::Value)> {
    let mut out = Vec::new();
    flatten(table, "", &mut out);
    out
}

/// The grid's names (`axes`) in the order the sweep file's `text` writes them under `[grid]`
/// (the TOML reader's tables sort their keys); a name not found keeps its place after them.
fn in_file_order(mut axes: Vec<(String, toml::Value)>, text: &str) -> Vec<(String, toml::Value)> {
    fn walk(table: &toml::de::DeTable, prefix: &str, out: &mut Vec<(usize, String)>) {
        for (key, value) in table {
            let name = match prefix.is_empty() {
                true => key.get_ref().to_string(),
                false => format!("{prefix}.{}", key.get_ref()),
            };
            match value.get_ref() {
                toml::de::DeValue::Table(t) => walk(t, &name, out),
                _ => out.push((key.span().start, name)),
            }
        }
    }
    let Ok(document) = toml::de::DeTable::parse(text) else {
        return axes;
    };
    let mut positions = Vec::new();
    let grid = document
        .get_ref()
        .iter()
        .find(|(k, _)| k.get_ref() == "grid");
    if let Some((_, value)) = grid {
        if let toml::de::DeValue::Table(t) = value.get_ref() {
            walk(t, "", &mut positions);
        }
    }
    let position = |name: &str| {
        let found = positions.iter().find(|(_, n)| n == name);
        found.map_or(usize::MAX, |(p, _)| *p)
    };
    axes.sort_by_key(|(name, _)| position(name));
    axes
}

/// Every combination of the grid's values, the first name varying slowest; variants named
/// v1, v2, ... (zero-padded). The table's names in its key order ([`axes_variants`] takes
/// them in a given order).
pub fn grid_variants(grid: &toml::Table) -> Result<(Vec<String>, Vec<Variant>), SweepError> {
    axes_variants(flat(grid))
}

/// Every combination of the values of `axes` (name, list of values), the first name varying
/// slowest; variants named v1, v2, ... (zero-padded).
pub fn axes_variants(
    axes: Vec<(String, toml::Value)>,
) -> Result<(Vec<String>, Vec<Variant>), SweepError> {
    let mut lists = Vec::new();
    for (name, value) in &axes {
        match value {
            toml::Value::Array(values) if !values.is_empty() => lists.push(values.clone()),
            other => {
                return Err(SweepError::Invalid(format!(
                    "grid.\"{name}\" = {other}: must be a list of at least one value"
                )))
            }
        }
    }
    if lists.is_empty() {
        return Err(SweepError::Invalid("[grid] names no parameter".into()));
    }
    let count: usize = lists.iter().map(Vec::len).product();
    if count > 100_000 {
        return Err(SweepError::Invalid(format!(
            "[grid] has {count} combinations: at most 100 000"
        )));
    }
    let width = count.to_string().len();
    let variants = (0..count)
        .map(|k| {
            let mut rest = k;
            let mut values = Vec::with_capacity(lists.len());
            for (axis, list) in axes.iter().zip(&lists).rev() {
                values.push((axis.0.clone(), list[rest % list.len()].clone()));
                rest /= list.len();
            }
            values.reverse();
            Variant {
                name: format!("v{:0width$}", k + 1),
                values,
            }
        })
        .collect();
    Ok((axes.into_iter().map(|a| a.0).collect(), variants))
}

/// One variant per case (its `name`, else c1, c2, ...); the parameters are every name any
/// case sets.
pub fn case_variants(cases: &[toml::Table]) -> Result<(Vec<String>, Vec<Variant>), SweepError> {
    let width = cases.len().to_string().len();
    let mut parameters: Vec<String> = Vec::new();
    let mut variants = Vec::new();
    for (k, case) in cases.iter().enumerate() {
        let mut values = Vec::new();
        flatten(case, "", &mut values);
        let name = match values.iter().position(|(n, _)| n == "name") {
            Some(i) => match values.remove(i).1 {
                toml::Value::String(s) if valid_name(&s) => s,
                other => {
                    return Err(SweepError::Invalid(format!(
                        "cases[{k}].name = {other}: a folder name of letters, digits, '-', '_' \
                         and '.', 1 to 64 characters"
                    )))
                }
            },
            None => format!("c{:0width$}", k + 1),
        };
        for (n, _) in &values {
            if !parameters.contains(n) {
                parameters.push(n.clone());
            }
        }
        variants.push(Variant { name, values });
    }
    Ok((parameters, variants))
}

fn valid_name(s: &str) -> bool {
    (1..=64).contains(&s.len())
        && s != "."
        && s != ".."
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c))
}

/// The key results of one variant (units in the names; null where the stage did not run or
/// the quantity is undefined), or its error.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Row {
    pub variant: String,
    /// The values the variant changes, by dotted name, as JSON values.
    pub parameters: serde_json::Map<String, serde_json::Value>,
    pub ok: bool,
    pub error: Option<String>,
    /// Unworn loaded pattern: largest cell pressure, Pa; S0 contact-area share.
    pub max_pressure_pa: Option<f64>,
    pub contact_area_fraction: Option<f64>,
    /// Peak-to-peak transmission error of the unworn loaded analysis, rad.
    pub te_p2p_rad: Option<f64>,
    /// Power balance of the unworn loaded analysis (MODEL §5.2; 0 = exact).
    pub power_balance: Option<f64>,
    /// Mesh efficiency, worm driving (ISO/TR 14521, MODEL §9).
    pub efficiency: Option<f64>,
    /// Wheel cycles the life reached (its plan's, or where a wear limit stopped it).
    pub life_cycles: Option<f64>,
    /// Backlash increase (tangential at r2) and largest wear depth at the end of the life, m.
    pub backlash_increase_end_m: Option<f64>,
    pub max_wear_end_m: Option<f64>,
    /// The backlash limit (the plan's, else the standard's (d)), m, and the cycles at which
    /// the life reached it (null: not within the life).
    pub backlash_limit_m: Option<f64>,
    pub cycles_to_backlash_limit: Option<f64>,
    /// Wall time of the variant, s.
    pub seconds: f64,
}

/// The CSV columns of the results after the parameters.
const RESULT_COLUMNS: [&str; 12] = [
    "max_pressure_pa",
    "contact_area_fraction",
    "te_p2p_rad",
    "power_balance",
    "efficiency",
    "life_cycles",
    "backlash_increase_end_m",
    "max_wear_end_m",
    "backlash_limit_m",
    "cycles_to_backlash_limit",
    "seconds",
    "error",
];

impl Row {
    /// The row of a variant's results.
    pub fn of(variant: &Variant, results: &Results, seconds: f64) -> Self {
        let ltca = results.ltca.as_ref();
        let life = results.life.as_ref();
        let last = life.and_then(|l| l.end.records.last());
        let limit = match (life, results.tca.as_ref()) {
            (Some(l), Some(tca)) => Some(crate::wear::WearLimits::new(
                &results.gear,
                &results.geometry,
                tca,
                &l.plan,
            )),
            _ => None,
        };
        let first = life.and_then(|l| l.end.records.first());
        Self {
            max_pressure_pa: ltca
                .map(|l| l.max_pressure)
                .or(first.map(|r| r.max_pressure_pa)),
            contact_area_fraction: ltca
                .map(|l| l.s0)
                .or(first.map(|r| r.contact_area_fraction)),
            te_p2p_rad: ltca.map(|l| l.te_stats().1).or(first.map(|r| r.te_p2p_rad)),
            power_balance: ltca
                .map(|l| l.power_balance)
                .or(first.map(|r| r.power_balance)),
            efficiency: results.rating.as_ref().map(|r| r.efficiency),
            life_cycles: last.map(|r| r.cycles),
            backlash_increase_end_m: last.map(|r| r.backlash_increase_m),
            max_wear_end_m: last.map(|r| r.max_wear_m),
            backlash_limit_m: limit.as_ref().map(|l| l.backlash_increase_limit_m),
            cycles_to_backlash_limit: match (&limit, life) {
                (Some(l), Some(life)) => crate::wear::WearLimits::cycles_reached(
                    &life.end.records,
                    l.backlash_increase_limit_m,
                ),
                _ => None,
            },
            ..Self::failed(variant, None, seconds)
        }
        .finite()
    }

    /// The row of a variant that failed (`error` None: a row to fill).
    fn failed(variant: &Variant, error: Option<String>, seconds: f64) -> Self {
        Self {
            variant: variant.name.clone(),
            parameters: variant
                .values
                .iter()
                .map(|(n, v)| (n.clone(), toml_to_json(v)))
                .collect(),
            ok: error.is_none(),
            error,
            max_pressure_pa: None,
            contact_area_fraction: None,
            te_p2p_rad: None,
            power_balance: None,
            efficiency: None,
            life_cycles: None,
            backlash_increase_end_m: None,
            max_wear_end_m: None,
            backlash_limit_m: None,
            cycles_to_backlash_limit: None,
            seconds,
        }
    }

    /// Non-finite numbers (a rating outside its formula's range) as null.
    fn finite(mut self) -> Self {
        for x in [
            &mut self.max_pressure_pa,
            &mut self.contact_area_fraction,
            &mut self.te_p2p_rad,
            &mut self.power_balance,
            &mut self.efficiency,
            &mut self.life_cycles,
            &mut self.backlash_increase_end_m,
            &mut self.max_wear_end_m,
            &mut self.backlash_limit_m,
            &mut self.cycles_to_backlash_limit,
        ] {
            *x = x.filter(|v| v.is_finite());
        }
        self
    }

    /// The result columns' values as CSV fields ([`RESULT_COLUMNS`]).
    fn result_fields(&self) -> Vec<String> {
        let number =
            |x: Option<f64>| x.map_or(crate::output::NO_VALUE.to_string(), |v| format!("{v:e}"));
        let mut fields: Vec<String> = [
            self.max_pressure_pa,
            self.contact_area_fraction,
            self.te_p2p_rad,
            self.power_balance,
            self.efficiency,
            self.life_cycles,
            self.backlash_increase_end_m,
            self.max_wear_end_m,
            self.backlash_limit_m,
            self.cycles_to_backlash_limit,
        ]
        .into_iter()
        .map(number)
        .collect();
        fields.push(format!("{:.3}", self.seconds));
        // One line per row: the problems of an input error joined.
        let error = self.error.as_deref().unwrap_or("");
        fields.push(csv_field(
            &error.replace("\n  - ", " - ").replace('\n', " "),
        ));
        fields
    }
}

/// That the base (`base_path`, written `written` in the sweep file) lies in `folder` or below
/// it, symbolic links resolved; else an error that reads nothing of it.
/// The folder of a file the sweep's relative paths start from: its parent, or the current
/// directory for a bare file name (whose parent is the empty path).
fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

fn confined(folder: &Path, base_path: &Path, written: &str) -> Result<(), SweepError> {
    let resolve = |p: &Path| {
        std::fs::canonicalize(p).map_err(|e| SweepError::Read {
            path: p.display().to_string(),
            message: e.to_string(),
        })
    };
    let (folder, base) = (resolve(folder)?, resolve(base_path)?);
    if base.starts_with(&folder) {
        return Ok(());
    }
    Err(SweepError::Invalid(format!(
        "base = {written:?}: outside the sweep file's directory {}; copy the gear file next to \
         the sweep file, or allow a base elsewhere (wormwear sweep --base-anywhere)",
        folder.display()
    )))
}

/// A TOML value as JSON (dates as their text).
pub fn toml_to_json(value: &toml::Value) -> serde_json::Value {
    serde_json::to_value(value).unwrap_or_else(|_| serde_json::Value::String(value.to_string()))
}

/// A CSV field of a text or a number ([`crate::output::csv_cell`]).
fn csv_field(text: &str) -> String {
    crate::output::csv_cell(text, text.parse::<f64>().is_ok())
}

/// A CSV field of a text value (a TOML string: "+1" is a name, not a number).
fn csv_text(text: &str) -> String {
    crate::output::csv_text(text)
}

/// The gear document of a variant: the base with the variant's values.
pub fn variant_document(base: &toml::Table, variant: &Variant) -> Result<toml::Table, InputError> {
    let mut document = base.clone();
    for (name, value) in &variant.values {
        input::set_dotted(&mut document, name, Some(value.clone()))?;
    }
    Ok(document)
}

/// The fingerprint of a variant's inputs: its gear document, the settings and the program
/// ([`crate::PROGRAM`]: a variant finished by another build is run again) (SHA-256, hex).
fn fingerprint(document_text: &str, settings: &Settings) -> String {
    let settings = serde_json::to_string(settings).unwrap_or_default();
    crate::integrity::digest_text(&format!("{}\n{settings}\n{document_text}", crate::PROGRAM))
}

/// A finished variant as stored in its folder (sealed).
#[derive(serde::Serialize, serde::Deserialize)]
struct Finished {
    fingerprint: String,
    row: Row,
}

/// The file a finished variant leaves in its folder.
pub const VARIANT_FILE: &str = "variant.json";

/// Runs one variant of `base` (its file name for messages) and returns its row; into `dir`,
/// when given, its full output, its gear file `gear.toml` and [`VARIANT_FILE`] last. Any
/// failure is the row's error. `interrupt` is asked at every event; true stops the variant
/// (its row says so).
pub fn run_variant(
    base_file: &str,
    base: &toml::Table,
    variant: &Variant,
    settings: &Settings,
    dir: Option<&Path>,
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Row {
    let start = std::time::Instant::now();
    let failed = |e: String| Row::failed(variant, Some(e), start.elapsed().as_secs_f64());
    let prepared = variant_document(base, variant)
        .and_then(|d| Ok((input::document_text(&d)?, input::load_document(&d)?)));
    let (text, gear) = match prepared {
        Ok(p) => p,
        Err(e) => return failed(format!("{base_file} with the variant's values: {e}")),
    };
    let row = match run_gear(&gear, &text, settings, dir, interrupt) {
        Ok(results) => Row::of(variant, &results, start.elapsed().as_secs_f64()),
        Err(e) => failed(e),
    };
    if let Some(dir) = dir {
        let finished = Finished {
            fingerprint: fingerprint(&text, settings),
            row: row.clone(),
        };
        let stored = crate::integrity::seal(&finished)
            .map_err(|e| e.to_string())
            .and_then(|t| {
                crate::output::write_atomic(&dir.join(VARIANT_FILE), t.as_bytes())
                    .map_err(|e| e.to_string())
            });
        if let Err(e) = stored {
            return failed(format!("cannot record the variant: {e}"));
        }
    }
    row
}

/// The pipeline on one variant's gear, its files into `dir` when given.
fn run_gear(
    gear: &GearSet,
    text: &str,
    settings: &Settings,
    dir: Option<&Path>,
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Result<Results, String> {
    let mut request = Request::new(settings.stages.iter().copied());
    if settings.stages.contains(&Stage::Wear) {
        request.life = Some(
            settings
                .overrides
                .plan(gear, OverrideNames::Python)
                .map_err(|e| e.to_string())?,
        );
    }
    let file = match dir {
        Some(d) => {
            let path = d.join("gear.toml");
            crate::output::write_atomic(&path, text.as_bytes()).map_err(|e| e.to_string())?;
            path.display().to_string()
        }
        None => "gear.toml".to_string(),
    };
    let source = Source {
        file,
        text: text.to_string(),
    };
    let mut on_event = |_: crate::Event| match interrupt() {
        true => Err(RunError::Stopped("interrupted".into())),
        false => Ok(()),
    };
    let results = crate::run(gear, source, request, &mut on_event).map_err(|e| error_chain(&e))?;
    if let Some(d) = dir {
        crate::output::write_results(&results, d, false).map_err(|e| error_chain(&e))?;
    }
    Ok(results)
}

/// The row a finished variant left in `dir`, if its inputs are those of this run and its
/// file is intact (a failed variant is run again).
fn finished_row(
    dir: &Path,
    base: &toml::Table,
    variant: &Variant,
    settings: &Settings,
) -> Option<Row> {
    let text =
        crate::files::read_text(&dir.join(VARIANT_FILE), crate::files::OWN_FILE_LIMIT).ok()?;
    let finished: Finished = crate::integrity::open(&text).ok()?;
    let document = variant_document(base, variant).ok()?;
    let expected = fingerprint(&input::document_text(&document).ok()?, settings);
    (finished.fingerprint == expected && finished.row.ok).then_some(finished.row)
}

/// One gear per distinct FE bending model the variants need (by cache key, in variant
/// order): the variants whose loaded stages use `[bending] model = "fe"`. Variants that do
/// not load are left to report their own errors.
pub fn distinct_bending_models(sweep: &Sweep, wanted: &dyn Fn(&Variant) -> bool) -> Vec<GearSet> {
    let loaded = sweep.settings.stages.contains(&Stage::Ltca)
        || sweep.settings.stages.contains(&Stage::Wear);
    let mut keys = BTreeSet::new();
    let mut gears = Vec::new();
    for variant in sweep.variants.iter().filter(|v| loaded && wanted(v)) {
        let Ok(gear) =
            variant_document(&sweep.base, variant).and_then(|d| input::load_document(&d))
        else {
            continue;
        };
        if gear.bending.kind == crate::input::BendingKind::Fe
            && keys.insert(crate::bending::model::cache_key(&gear))
        {
            gears.push(gear);
        }
    }
    gears
}

/// Builds (or reads) the FE bending models of the variants into the cache, one after the
/// other, before the variants run side by side: variants that share a model would otherwise
/// each build it on a cold cache (a waste of the build time and twice the memory). Failures
/// are left for the variants to report.
fn warm_bending_cache(
    sweep: &Sweep,
    wanted: &dyn Fn(&Variant) -> bool,
    interrupt: &(dyn Fn() -> bool + Sync),
) {
    for gear in distinct_bending_models(sweep, wanted) {
        if interrupt() {
            return;
        }
        if let Ok(geo) = crate::geometry::Geometry::build(&gear) {
            let _ = crate::bending::model::build(&gear, &geo);
        }
    }
}

/// What [`run`] reports as variants finish: the row, whether it was reused from an earlier
/// run, and how many of how many are done.
pub struct Progress<'a> {
    pub row: &'a Row,
    pub reused: bool,
    pub done: usize,
    pub total: usize,
}

/// Runs every variant of `sweep` in parallel on the local cores into `dir`: each variant's
/// output in `dir/variants/NAME`, `sweep.csv` (one row per variant, rewritten as variants
/// finish), the `sweep` section of summary.json and `sweep.html` at the end. Variants
/// finished by an earlier run with the same inputs are reused. Returns the rows in variant
/// order.
pub fn run(
    sweep: &Sweep,
    dir: &Path,
    on_progress: &(dyn Fn(Progress) + Sync),
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Result<Vec<Row>, SweepError> {
    use rayon::prelude::*;
    let unfinished =
        |v: &Variant| finished_row(&variant_dir(dir, v), &sweep.base, v, &sweep.settings).is_none();
    warm_bending_cache(sweep, &unfinished, interrupt);
    let total = sweep.variants.len();
    let rows: std::sync::Mutex<Vec<Option<Row>>> = std::sync::Mutex::new(vec![None; total]);
    sweep.variants.par_iter().enumerate().try_for_each(
        |(k, variant)| -> Result<(), SweepError> {
            let out = variant_dir(dir, variant);
            let reused = finished_row(&out, &sweep.base, variant, &sweep.settings);
            let row = match &reused {
                Some(row) => row.clone(),
                None => {
                    std::fs::create_dir_all(&out).map_err(|e| SweepError::Read {
                        path: out.display().to_string(),
                        message: e.to_string(),
                    })?;
                    let base_file = &sweep.base_file;
                    let (base, settings) = (&sweep.base, &sweep.settings);
                    run_variant(base_file, base, variant, settings, Some(&out), interrupt)
                }
            };
            let mut all = rows.lock().unwrap_or_else(|p| p.into_inner());
            all[k] = Some(row.clone());
            let done: Vec<&Row> = all.iter().flatten().collect();
            write_csv(&dir.join("sweep.csv"), &sweep.parameters, &done)?;
            on_progress(Progress {
                row: &row,
                reused: reused.is_some(),
                done: done.len(),
                total,
            });
            Ok(())
        },
    )?;
    let rows: Vec<Row> = rows
        .into_inner()
        .unwrap_or_else(|p| p.into_inner())
        .into_iter()
        .flatten()
        .collect();
    write_summary(sweep, &rows, dir)?;
    html::write_html(dir, sweep, &rows)?;
    Ok(rows)
}

/// Runs every variant of `sweep` in parallel on the local cores without writing any file;
/// returns the rows in variant order.
pub fn run_in_memory(
    sweep: &Sweep,
    on_progress: &(dyn Fn(Progress) + Sync),
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Vec<Row> {
    use rayon::prelude::*;
    warm_bending_cache(sweep, &|_| true, interrupt);
    let total = sweep.variants.len();
    let done = std::sync::atomic::AtomicUsize::new(0);
    sweep
        .variants
        .par_iter()
        .map(|variant| {
            let (base, settings) = (&sweep.base, &sweep.settings);
            let row = run_variant(&sweep.base_file, base, variant, settings, None, interrupt);
            on_progress(Progress {
                row: &row,
                reused: false,
                done: done.fetch_add(1, std::sync::atomic::Ordering::SeqCst) + 1,
                total,
            });
            row
        })
        .collect()
}

/// Writes `sweep.csv`: the variant, the varied values, `ok`, then [`RESULT_COLUMNS`].
pub fn write_csv(path: &Path, parameters: &[String], rows: &[&Row]) -> Result<(), SweepError> {
    let mut text = String::from("variant");
    for p in parameters {
        text.push(',');
        text.push_str(&csv_field(p));
    }
    text.push_str(",ok,");
    text.push_str(&RESULT_COLUMNS.join(","));
    text.push('\n');
    for row in rows {
        text.push_str(&csv_field(&row.variant));
        for p in parameters {
            text.push(',');
            let value = row.parameters.get(p).map_or(String::new(), |v| match v {
                serde_json::Value::String(s) => csv_text(s),
                other => csv_field(&other.to_string()),
            });
            text.push_str(&value);
        }
        text.push_str(if row.ok { ",1" } else { ",0" });
        for field in row.result_fields() {
            text.push(',');
            text.push_str(&field);
        }
        text.push('\n');
    }
    crate::output::write_atomic(path, text.as_bytes())?;
    Ok(())
}

/// The `sweep` section of summary.json: the base, the settings, the parameters and the rows.
fn write_summary(sweep: &Sweep, rows: &[Row], dir: &Path) -> Result<(), SweepError> {
    let value = serde_json::json!({
        "base": sweep.base_file,
        "stages": sweep.settings.stages,
        "overrides": serde_json::to_value(&sweep.settings).ok().and_then(|s| s.get("overrides").cloned()),
        "parameters": sweep.parameters,
        "variants": rows.len(),
        "failed": rows.iter().filter(|r| !r.ok).count(),
        "rows": rows,
        "program_version": env!("CARGO_PKG_VERSION"),
    });
    crate::output::update_summary(dir, "sweep", value)?;
    Ok(())
}

/// The path of a variant's folder in a sweep's output directory.
pub fn variant_dir(dir: &Path, variant: &Variant) -> PathBuf {
    dir.join("variants").join(&variant.name)
}

#[cfg(test)]
mod tests {
    use super::{axes_variants, csv_field, csv_text, flat, folder_of, in_file_order};
    use std::path::Path;

    #[test]
    fn a_bare_sweep_file_name_is_in_the_current_directory() {
        // Issue 59: `wormwear sweep sweep-k.toml` read its base from "" ("cannot read :").
        assert_eq!(folder_of(Path::new("sweep-k.toml")), Path::new("."));
        assert_eq!(folder_of(Path::new("a/sweep.toml")), Path::new("a"));
        assert_eq!(folder_of(Path::new("/sweep.toml")), Path::new("/"));
    }

    #[test]
    fn the_grid_varies_its_first_name_slowest_in_the_files_order() {
        // Issue 59: names were sorted alphabetically, not in the order the file gives them.
        let text = "[grid]\n\"z.torque\" = [1.0, 2.0]\nm.x = [0.0]\na.speed = [3.0, 4.0, 5.0]\n";
        let file: toml::Table = toml::from_str(text).unwrap();
        let grid = file["grid"].as_table().unwrap();
        let axes = in_file_order(flat(grid), text);
        let (names, variants) = axes_variants(axes).unwrap();
        assert_eq!(names, ["z.torque", "m.x", "a.speed"]);
        let firsts: Vec<String> = variants.iter().map(|v| v.values[0].1.to_string()).collect();
        assert_eq!(firsts, ["1.0", "1.0", "1.0", "2.0", "2.0", "2.0"]);
    }

    #[test]
    fn a_cell_that_reads_as_a_formula_is_shown_as_text() {
        assert_eq!(csv_field("=1+1"), "'=1+1");
        assert_eq!(csv_field("@SUM(A1)"), "'@SUM(A1)");
        assert_eq!(csv_field("+cmd|' /C calc'!A0"), "'+cmd|' /C calc'!A0");
        assert_eq!(csv_field("-2+3,x"), "\"'-2+3,x\"");
        // Numbers stay numbers.
        assert_eq!(csv_field("-5"), "-5");
        assert_eq!(csv_field("+1.5e-3"), "+1.5e-3");
        assert_eq!(csv_field("a,b"), "\"a,b\"");
        // A text value is text even when it reads as a number (a material named "+1").
        assert_eq!(csv_text("+1"), "'+1");
        assert_eq!(csv_text("-5"), "'-5");
        assert_eq!(csv_text("bronze"), "bronze");
    }
}
