//! Spread and uncertainty (MODEL §17): inputs with ranges or distributions are sampled (a
//! seeded Latin hypercube), every sample runs the asked stages as a variant of the sweep
//! machinery ([`crate::sweep`]: the local cores, resumable), and each key result gets its
//! percentiles over the samples and its rank correlation with each input.
//!
//! A spread file names the base gear file like a sweep file, and a `[spread]` table:
//!
//! ```toml
//! base = "gear-1x40-design.toml"   # relative to the spread file
//! stages = ["ltca"]                # optional; "wear" with cycles for lives
//! [spread]
//! samples = 64                     # 2 to MAX_SAMPLES
//! seed = 1                         # default 1
//! sampler = "latin-hypercube"      # default; "sobol": Saltelli's design, samples (inputs + 2)
//!                                  # runs, and the first-order and total Sobol indices
//! [spread.inputs]
//! "operating.centre_distance_error_mm" = [-0.03, 0.03]                     # uniform
//! "lubricant.composite_roughness_um" = { mean = 1.0, sd = 0.2, min = 0.5 } # normal, truncated
//! ```
//!
//! Rooms: `sampling` the points and the distributions, `stats` the percentiles and rank
//! correlations; here the file, the run and the files it writes (`spread.csv`, `spread.json`).

mod html;
pub mod sampling;
pub mod stats;

use crate::runner::LifeOverrides;
use crate::sweep::{Row, Sweep, SweepError, Variant};
use sampling::Distribution;
use std::path::Path;

/// Most samples a spread may ask for (each is a run of its stages).
pub const MAX_SAMPLES: usize = 4096;

/// The spread file as written.
#[derive(Debug, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct SpreadFile {
    /// The base gear file (a spread file's; absent where the base is given, Python).
    #[serde(default)]
    base: Option<String>,
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
    spread: SpreadSpec,
}

/// The `[spread]` table.
#[derive(Debug, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct SpreadSpec {
    samples: i64,
    #[serde(default)]
    seed: Option<u64>,
    #[serde(default)]
    sampler: Option<String>,
    inputs: toml::Table,
    /// Fields every sample sets to the same value (e.g. `"bending.model" = "none"`).
    #[serde(default)]
    fixed: Option<toml::Table>,
}

/// One uncertain input: its dotted name in the gear file and its distribution.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Input {
    pub name: String,
    #[serde(flatten)]
    pub distribution: Distribution,
}

/// How a spread samples its inputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sampler {
    /// A seeded Latin hypercube of `samples` points (the default).
    LatinHypercube,
    /// Saltelli's design from a scrambled Sobol sequence: `samples` base points, `samples`
    /// (inputs + 2) runs, and each input's first-order and total Sobol indices.
    Sobol,
}

impl Sampler {
    /// The name in a spread file and in spread.json.
    pub fn name(self) -> &'static str {
        match self {
            Sampler::LatinHypercube => "latin-hypercube",
            Sampler::Sobol => "sobol",
        }
    }

    /// The runs of `samples` samples of `inputs` inputs.
    pub fn runs(self, samples: usize, inputs: usize) -> usize {
        match self {
            Sampler::LatinHypercube => samples,
            Sampler::Sobol => samples * (inputs + 2),
        }
    }
}

/// A spread: the sweep of its samples, its inputs and how they were sampled.
#[derive(Debug, Clone)]
pub struct Spread {
    pub sweep: Sweep,
    pub inputs: Vec<Input>,
    /// The samples asked for (with the Sobol sampler, the base points: the runs are
    /// [`Sampler::runs`]).
    pub samples: usize,
    pub seed: u64,
    pub sampler: Sampler,
}

impl Spread {
    /// Reads a spread file and its base gear file (in the spread file's folder or below it,
    /// as a sweep's), checks the inputs against the base and samples them.
    pub fn load(path: &Path) -> Result<Self, SweepError> {
        let text = crate::files::read_text(path, crate::files::INPUT_LIMIT).map_err(|e| {
            SweepError::Read {
                path: path.display().to_string(),
                message: e.to_string(),
            }
        })?;
        let file: SpreadFile = toml::from_str(&text)
            .map_err(|e| SweepError::Invalid(format!("{}: {e}", path.display())))?;
        let folder = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        let Some(base_name) = file.base.as_deref() else {
            return Err(SweepError::Invalid(format!(
                "{}: base: name the base gear file (base = \"gear.toml\", relative to the \
                 spread file)",
                path.display()
            )));
        };
        let access = crate::sweep::BaseAccess::Confined;
        let (base_file, base) = crate::sweep::base_document(folder, base_name, access)?;
        Self::build(base_file, base, file)
    }

    /// A spread of the gear document `base` (named `base_file`) from a spread file's tables
    /// as JSON, without `base` (the Python package's `wormwear.spread`): `stages`, `cycles`,
    /// ..., and `spread` with `samples`, `seed`, `sampler`, `inputs` and `fixed`.
    pub fn of_document(
        base_file: String,
        base: toml::Table,
        spec: serde_json::Value,
    ) -> Result<Self, SweepError> {
        let file: SpreadFile = serde_json::from_value(spec)
            .map_err(|e| SweepError::Invalid(format!("spread: {e}")))?;
        if file.base.is_some() {
            return Err(SweepError::Invalid(
                "spread: base: the base gear is given; leave base out".into(),
            ));
        }
        Self::build(base_file, base, file)
    }

    /// The spread of `file` on the base document: inputs checked and sampled.
    fn build(base_file: String, base: toml::Table, file: SpreadFile) -> Result<Self, SweepError> {
        let inputs = inputs(&file.spread.inputs, &base)?;
        let sampler = sampler(file.spread.sampler.as_deref())?;
        let samples = sample_count(file.spread.samples, sampler, inputs.len())?;
        let seed = file.spread.seed.unwrap_or(1);
        let overrides = LifeOverrides {
            cycles: file.cycles,
            step_cycles: file.step_cycles,
            step_wear_um: file.step_wear_um,
            no_pitting: file.no_pitting,
        };
        let mut variants = sample_variants(&inputs, samples, seed, sampler);
        let fixed = fixed_values(file.spread.fixed.as_ref(), &base, &inputs)?;
        for v in &mut variants {
            v.values.extend(fixed.iter().cloned());
        }
        let parameters = inputs.iter().map(|i| i.name.clone()).collect();
        let stages = file.stages.unwrap_or_else(|| vec!["ltca".into()]);
        let sweep = Sweep::new(
            base_file,
            base,
            parameters,
            variants,
            Some(&stages),
            overrides,
        )?;
        Ok(Self {
            sweep,
            inputs,
            samples,
            seed,
            sampler,
        })
    }
}

/// The sampler a spread file names (default: the Latin hypercube).
fn sampler(name: Option<&str>) -> Result<Sampler, SweepError> {
    match name {
        None => Ok(Sampler::LatinHypercube),
        Some(s) if s.eq_ignore_ascii_case("latin-hypercube") => Ok(Sampler::LatinHypercube),
        Some(s) if s.eq_ignore_ascii_case("sobol") => Ok(Sampler::Sobol),
        Some(s) => Err(SweepError::Invalid(format!(
            "spread.sampler = {s:?}: unknown sampler: allowed \"latin-hypercube\" (default) or \
             \"sobol\""
        ))),
    }
}

/// The fields `[spread.fixed]` sets in every sample, by dotted name: each a field of the base
/// document (an unknown name is refused with the nearest), none of them an input.
fn fixed_values(
    fixed: Option<&toml::Table>,
    base: &toml::Table,
    inputs: &[Input],
) -> Result<Vec<(String, toml::Value)>, SweepError> {
    let mut values = Vec::new();
    crate::sweep::flatten(fixed.unwrap_or(&toml::Table::new()), "", &mut values);
    for (name, _) in &values {
        let field = format!("spread.fixed.\"{name}\"");
        if inputs.iter().any(|i| &i.name == name) {
            return Err(SweepError::Invalid(format!(
                "{field}: also an input; a field is either sampled or fixed"
            )));
        }
    }
    // The base with the fixed values must be a valid gear (a misspelt name is refused there).
    let fixed_variant = Variant {
        name: "fixed".into(),
        values: values.clone(),
    };
    crate::sweep::variant_document(base, &fixed_variant)
        .and_then(|d| crate::input::load_document(&d))
        .map_err(|e| SweepError::Invalid(format!("spread.fixed: {e}")))?;
    Ok(values)
}

/// The sample count: 2 to [`MAX_SAMPLES`] runs (with the Sobol sampler, `n` (inputs + 2)
/// runs; at most 128 inputs).
fn sample_count(n: i64, sampler: Sampler, inputs: usize) -> Result<usize, SweepError> {
    let most = match sampler {
        Sampler::LatinHypercube => MAX_SAMPLES,
        Sampler::Sobol => MAX_SAMPLES / (inputs + 2),
    };
    if sampler == Sampler::Sobol && inputs > 128 {
        return Err(SweepError::Invalid(format!(
            "spread.inputs: {inputs} inputs: the Sobol sampler takes at most 128"
        )));
    }
    if !(2..=most as i64).contains(&n) {
        let why = match sampler {
            Sampler::LatinHypercube => String::new(),
            Sampler::Sobol => format!(
                " (the Sobol sampler runs samples x (inputs + 2) = samples x {}, at most \
                 {MAX_SAMPLES} runs)",
                inputs + 2
            ),
        };
        return Err(SweepError::Invalid(format!(
            "spread.samples = {n}: out of range: allowed integers [2, {most}]{why}"
        )));
    }
    Ok(n as usize)
}

/// The inputs of `[spread.inputs]`, each a numeric field of the base gear document `base`
/// (an unknown name is refused with the nearest names): `[min, max]` (uniform) or
/// `{ mean, sd, min, max }` (normal, truncated to the bounds given).
fn inputs(table: &toml::Table, base: &toml::Table) -> Result<Vec<Input>, SweepError> {
    let mut out = Vec::new();
    let mut names = Vec::new();
    input_names(table, "", &mut names);
    if names.is_empty() {
        return Err(SweepError::Invalid(
            "spread.inputs: name at least one input (a dotted name of the gear file = [min, \
             max] or { mean, sd })"
                .into(),
        ));
    }
    for (name, value) in names {
        let field = format!("spread.inputs.\"{name}\"");
        match lookup(base, &name) {
            Some(toml::Value::Float(_) | toml::Value::Integer(_)) => {}
            Some(other) => {
                return Err(SweepError::Invalid(format!(
                    "{field}: the gear file's {name} is {other}, not a number: only numeric \
                     fields can be sampled"
                )))
            }
            // A field the base leaves at its default is sampled if the gear file takes it.
            None => {
                if let Err(why) = accepts(base, &name, &value) {
                    let near = nearest_names(base, &name, 3);
                    return Err(SweepError::Invalid(format!(
                        "{field}: the base gear file has no field {name}, and the gear file \
                         does not take it at the input's centre ({why}); the base's nearest \
                         numeric fields: {}",
                        near.join(", ")
                    )));
                }
            }
        }
        out.push(Input {
            distribution: distribution(&field, &value)?,
            name,
        });
    }
    Ok(out)
}

/// Whether the gear file takes the field `name`, absent from `base`, at the middle of the
/// input's range or its mean (Err: the loader's or the distribution's message).
fn accepts(base: &toml::Table, name: &str, value: &toml::Value) -> Result<(), String> {
    let d = distribution(name, value).map_err(|e| e.to_string())?;
    let variant = Variant {
        name: "check".into(),
        values: vec![(name.to_string(), toml::Value::Float(d.centre()))],
    };
    crate::sweep::variant_document(base, &variant)
        .and_then(|doc| crate::input::load_document(&doc).map(|_| ()))
        .map_err(|e| e.to_string())
}

/// The inputs of `[spread.inputs]` by dotted name: bare dotted keys nest tables, which are
/// followed; a table with `mean` or `sd` is a distribution, not a level of names.
fn input_names(table: &toml::Table, prefix: &str, out: &mut Vec<(String, toml::Value)>) {
    for (key, value) in table {
        let name = match prefix.is_empty() {
            true => key.clone(),
            false => format!("{prefix}.{key}"),
        };
        match value {
            toml::Value::Table(t) if !t.contains_key("mean") && !t.contains_key("sd") => {
                input_names(t, &name, out)
            }
            v => out.push((name, v.clone())),
        }
    }
}

/// The `count` dotted names of the numeric fields of `doc` nearest to `name` (edit distance;
/// what an unknown name most likely meant).
pub(crate) fn nearest_names(doc: &toml::Table, name: &str, count: usize) -> Vec<String> {
    let mut leaves = Vec::new();
    crate::sweep::flatten(doc, "", &mut leaves);
    let mut scored: Vec<(usize, String)> = leaves
        .into_iter()
        .filter(|(_, v)| number(v).is_some())
        .map(|(n, _)| (edit_distance(&n, name), n))
        .collect();
    scored.sort();
    scored.into_iter().take(count).map(|(_, n)| n).collect()
}

/// Levenshtein's edit distance between two names (characters).
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let next = (diagonal + usize::from(ca != *cb))
                .min(row[j] + 1)
                .min(row[j + 1] + 1);
            diagonal = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}

/// The value at a dotted name of a gear document.
pub(crate) fn lookup<'a>(doc: &'a toml::Table, name: &str) -> Option<&'a toml::Value> {
    let mut parts = name.split('.');
    let mut value = doc.get(parts.next()?)?;
    for p in parts {
        value = value.as_table()?.get(p)?;
    }
    Some(value)
}

/// A number of a spread file (integers read as floats).
pub(crate) fn number(v: &toml::Value) -> Option<f64> {
    v.as_float().or_else(|| v.as_integer().map(|i| i as f64))
}

/// An input's distribution from `[min, max]` or `{ mean, sd, min?, max? }`.
fn distribution(field: &str, value: &toml::Value) -> Result<Distribution, SweepError> {
    let bad = |problem: String| SweepError::Invalid(format!("{field} = {value}: {problem}"));
    let finite = |x: Option<f64>, what: &str| match x {
        Some(v) if v.is_finite() => Ok(v),
        _ => Err(bad(format!("{what} must be a finite number"))),
    };
    let d = match value {
        toml::Value::Array(a) if a.len() == 2 => {
            let min = finite(number(&a[0]), "the range's first value")?;
            let max = finite(number(&a[1]), "the range's second value")?;
            Distribution::Uniform { min, max }
        }
        toml::Value::Table(t) => {
            if let Some(k) = t
                .keys()
                .find(|k| !["mean", "sd", "min", "max"].contains(&k.as_str()))
            {
                return Err(bad(format!(
                    "unknown key {k:?}: a normal input takes mean, sd, min, max"
                )));
            }
            let get = |k: &str| t.get(k).and_then(number);
            let bound = |k: &str, default: f64| match t.get(k) {
                None => Ok(default),
                Some(v) => finite(number(v), k),
            };
            Distribution::Normal {
                mean: finite(get("mean"), "mean")?,
                sd: finite(get("sd"), "sd")?,
                min: bound("min", f64::NEG_INFINITY)?,
                max: bound("max", f64::INFINITY)?,
            }
        }
        _ => {
            return Err(bad(
                "give a range [min, max] (uniform) or { mean, sd, min, max } (normal)".into(),
            ))
        }
    };
    match d {
        Distribution::Uniform { min, max } if min > max => {
            Err(bad(format!("an inverted range: {min} > {max}")))
        }
        Distribution::Normal { sd, .. } if sd < 0.0 => Err(bad("sd must be >= 0".into())),
        Distribution::Normal { mean, min, max, .. } if !(min <= mean && mean <= max) => Err(bad(
            format!("the mean {mean} must lie within [min, max] = [{min}, {max}]"),
        )),
        d => Ok(d),
    }
}

/// The samples as sweep variants `s001`, `s002`, ... (zero-padded): the Latin hypercube points
/// of `seed`, or Saltelli's design's rows ([`sampling::saltelli`], in its order), mapped
/// through each input's distribution.
pub fn sample_variants(
    inputs: &[Input],
    samples: usize,
    seed: u64,
    sampler: Sampler,
) -> Vec<Variant> {
    let points = match sampler {
        Sampler::LatinHypercube => sampling::latin_hypercube(samples, inputs.len(), seed),
        Sampler::Sobol => sampling::saltelli(samples, inputs.len(), seed),
    };
    let width = points.len().to_string().len();
    points
        .iter()
        .enumerate()
        .map(|(k, point)| Variant {
            name: format!("s{:0width$}", k + 1),
            values: inputs
                .iter()
                .zip(point)
                .map(|(i, &u)| (i.name.clone(), toml::Value::Float(i.distribution.value(u))))
                .collect(),
        })
        .collect()
}

/// The key results a spread reports, by name, and where each is in a variant's summary.json
/// (a dotted path; `wear.end.` the life's last record, `wear.first_pitting` the cycles of the
/// life's first record with pits, `safety.` the safety table's row).
pub const RESULTS: [(&str, &str); 23] = [
    ("max_pressure_pa", "ltca.max_pressure_pa"),
    ("pressure_patch_max_pa", "ltca.pressure_patch_max_pa"),
    (
        "equivalent_pressure_max_pa",
        "ltca.equivalent_pressure_max_pa",
    ),
    (
        "equivalent_pressure_first_pitting_pa",
        "ltca.equivalent_pressure_first_pitting_pa",
    ),
    ("contact_area_fraction", "ltca.contact_area_fraction"),
    (
        "pattern_centre_across_face",
        "ltca.pattern_shape.centre_across_face",
    ),
    (
        "pattern_centre_up_flank",
        "ltca.pattern_shape.centre_up_flank",
    ),
    (
        "pattern_extent_along_face",
        "ltca.pattern_shape.extent_along_face",
    ),
    (
        "pattern_extent_up_flank",
        "ltca.pattern_shape.extent_up_flank",
    ),
    (
        "no_load_pattern_centre_across_face",
        "tca.pattern_shape.centre_across_face",
    ),
    (
        "no_load_pattern_extent_along_face",
        "tca.pattern_shape.extent_along_face",
    ),
    (
        "no_load_pattern_extent_up_flank",
        "tca.pattern_shape.extent_up_flank",
    ),
    ("te_p2p_rad", "ltca.te_p2p_rad"),
    (
        "mesh_stiffness_mean_nm_per_rad",
        "ltca.mesh_stiffness_mean_nm_per_rad",
    ),
    ("mesh_efficiency", "friction.efficiency.mesh_efficiency"),
    ("total_efficiency", "friction.efficiency.total_efficiency"),
    ("backlash_increase_end_m", "wear.end.backlash_increase_m"),
    ("wear_patch_max_end_m", "wear.end.wear_patch_max_m"),
    ("first_pitting_cycles", "wear.first_pitting"),
    ("safety_root", "safety.S_F"),
    ("safety_deflection", "safety.S_delta"),
    ("safety_pitting", "safety.S_H"),
    ("safety_wear", "safety.S_W"),
];

/// A key result of a variant's summary.json at `path` ([`RESULTS`]); None where absent.
fn result_at(summary: &serde_json::Value, path: &str) -> Option<f64> {
    if let Some(symbol) = path.strip_prefix("safety.") {
        let rows = summary["rating"]["safety"]["rows"].as_array()?;
        let row = rows.iter().find(|r| r["symbol"] == symbol)?;
        return row["safety"].as_f64();
    }
    if path == "wear.first_pitting" {
        // The first state with pits on the flank (NaN for a life without: none within it).
        let steps = summary["wear"]["steps"].as_array()?;
        let pitted = steps
            .iter()
            .find(|s| s["pitted_area_fraction"].as_f64().is_some_and(|f| f > 0.0))?;
        return pitted["cycles"].as_f64();
    }
    if let Some(key) = path.strip_prefix("wear.end.") {
        return summary["wear"]["steps"].as_array()?.last()?[key].as_f64();
    }
    path.split('.').fold(summary, |v, k| &v[k]).as_f64()
}

/// What a spread gives: each sample's inputs and key results ([`RESULTS`]; NaN where a
/// sample failed or the stage did not run), and with lives each sample's backlash increase
/// over the cycles (wheel cycles, m; empty without a life), in sample order.
#[derive(Debug, Clone, PartialEq)]
pub struct SpreadResults {
    pub rows: Vec<Row>,
    pub inputs: Vec<Vec<f64>>,
    pub results: Vec<Vec<f64>>,
    pub curves: Vec<Vec<(f64, f64)>>,
}

/// A life's backlash increase over its states from its summary.json (cycles, m).
fn backlash_curve(summary: &serde_json::Value) -> Vec<(f64, f64)> {
    summary["wear"]["steps"]
        .as_array()
        .map(|steps| {
            steps
                .iter()
                .filter_map(|s| Some((s["cycles"].as_f64()?, s["backlash_increase_m"].as_f64()?)))
                .collect()
        })
        .unwrap_or_default()
}

/// Runs the samples of `spread` as a sweep into `dir` (local cores; finished samples of an
/// earlier run with the same inputs are reused) and writes `spread.csv`, `spread.json` and
/// `spread.html` (with its charts in `plots/`).
pub fn run(
    spread: &Spread,
    dir: &Path,
    on_progress: &(dyn Fn(crate::sweep::Progress) + Sync),
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Result<SpreadResults, SweepError> {
    let rows = crate::sweep::run(&spread.sweep, dir, on_progress, interrupt)?;
    let mut inputs = Vec::new();
    let mut results = Vec::new();
    let mut curves = Vec::new();
    for (row, variant) in rows.iter().zip(&spread.sweep.variants) {
        inputs.push(
            variant
                .values
                .iter()
                .filter_map(|(_, v)| number(v))
                .collect(),
        );
        let path = crate::sweep::variant_dir(dir, variant).join("summary.json");
        let summary: serde_json::Value =
            crate::files::read_text(&path, crate::files::OWN_FILE_LIMIT)
                .ok()
                .and_then(|t| serde_json::from_str(&t).ok())
                .filter(|_| row.ok)
                .unwrap_or(serde_json::Value::Null);
        results.push(
            RESULTS
                .iter()
                .map(|(_, p)| result_at(&summary, p).unwrap_or(f64::NAN))
                .collect(),
        );
        curves.push(backlash_curve(&summary));
    }
    let out = SpreadResults {
        rows,
        inputs,
        results,
        curves,
    };
    write_csv(spread, &out, &dir.join("spread.csv"))?;
    let json = serde_json::to_string_pretty(&summary(spread, &out)).unwrap_or_default() + "\n";
    crate::output::write_atomic(&dir.join("spread.json"), json.as_bytes())?;
    html::write_html(dir, spread, &out)?;
    Ok(out)
}

/// `spread.csv`: the sample, its inputs, `ok`, its key results (NaN: none).
fn write_csv(spread: &Spread, out: &SpreadResults, path: &Path) -> Result<(), SweepError> {
    let mut header = vec!["sample".to_string()];
    header.extend(spread.inputs.iter().map(|i| i.name.clone()));
    header.push("ok".into());
    header.extend(RESULTS.iter().map(|(n, _)| n.to_string()));
    let mut text = header.join(",") + "\n";
    for ((row, inputs), results) in out.rows.iter().zip(&out.inputs).zip(&out.results) {
        let mut cells = vec![row.variant.clone()];
        cells.extend(inputs.iter().map(|v| format!("{v:e}")));
        cells.push(if row.ok { "1".into() } else { "0".into() });
        cells.extend(results.iter().map(|v| format!("{v:e}")));
        text.push_str(&(cells.join(",") + "\n"));
    }
    crate::output::write_atomic(path, text.as_bytes())?;
    Ok(())
}

/// `spread.json`: the base, the sampling, the inputs, each key result's min / P10 / P50 /
/// P90 / max / mean over the samples that have it, and each result's rank correlation
/// (Spearman) with each input; with the Sobol sampler these over the design's A and B rows
/// (independent points; the A_B rows mix them), and each result's first-order and total Sobol
/// index per input. No time or machine, so that one seed gives the same bytes.
pub fn summary(spread: &Spread, out: &SpreadResults) -> serde_json::Value {
    let independent = match spread.sampler {
        Sampler::LatinHypercube => out.results.len(),
        Sampler::Sobol => (2 * spread.samples).min(out.results.len()),
    };
    let column = |table: &[Vec<f64>], k: usize, rows: usize| -> Vec<f64> {
        table.iter().take(rows).map(|r| r[k]).collect()
    };
    let mut results = serde_json::Map::new();
    let mut sensitivity = serde_json::Map::new();
    let mut sobol = serde_json::Map::new();
    for (k, (name, _)) in RESULTS.iter().enumerate() {
        let values = column(&out.results, k, independent);
        let finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
        if finite.is_empty() {
            continue;
        }
        let q = |p: f64| stats::percentile(&finite, p);
        results.insert(
            name.to_string(),
            serde_json::json!({
                "count": finite.len(),
                "min": q(0.0), "p10": q(0.1), "p50": q(0.5), "p90": q(0.9), "max": q(1.0),
                "mean": finite.iter().sum::<f64>() / finite.len() as f64,
            }),
        );
        let mut by_input = serde_json::Map::new();
        for (i, input) in spread.inputs.iter().enumerate() {
            let rho = stats::spearman(&column(&out.inputs, i, independent), &values);
            by_input.insert(input.name.clone(), serde_json::json!(rho));
        }
        sensitivity.insert(name.to_string(), serde_json::Value::Object(by_input));
        if spread.sampler == Sampler::Sobol {
            let all = column(&out.results, k, out.results.len());
            let indices = stats::sobol_indices(&all, spread.samples, spread.inputs.len());
            let by_input: serde_json::Map<String, serde_json::Value> = spread
                .inputs
                .iter()
                .zip(indices)
                .map(|(input, index)| (input.name.clone(), serde_json::json!(index)))
                .collect();
            sobol.insert(name.to_string(), serde_json::Value::Object(by_input));
        }
    }
    let mut json = serde_json::json!({
        "base": spread.sweep.base_file,
        "stages": spread.sweep.settings.stages,
        "sampler": spread.sampler.name(),
        "samples": spread.samples,
        "runs": out.rows.len(),
        "seed": spread.seed,
        "failed": out.rows.iter().filter(|r| !r.ok).count(),
        "inputs": spread.inputs,
        "results": results,
        "rank_correlation": sensitivity,
        "program_version": env!("CARGO_PKG_VERSION"),
    });
    if spread.sampler == Sampler::Sobol {
        json["sobol_indices"] = serde_json::Value::Object(sobol);
    }
    json
}

#[cfg(test)]
mod tests {
    /// A key result read off a summary: the life's first state with pits (none: absent), the
    /// last record's value, a safety row's.
    #[test]
    fn key_results_are_read_where_the_summary_has_them() {
        let steps = |shares: &[f64]| {
            let s: Vec<serde_json::Value> = shares
                .iter()
                .enumerate()
                .map(|(k, f)| {
                    serde_json::json!({"cycles": 1e5 * k as f64, "pitted_area_fraction": f,
                        "backlash_increase_m": 1e-6 * k as f64})
                })
                .collect();
            serde_json::json!({"wear": {"steps": s}, "rating": {"safety": {"rows": [
                {"symbol": "S_H", "safety": 0.7}, {"symbol": "S_H,pub", "safety": 1.3}]}}})
        };
        let pitted = steps(&[0.0, 0.0, 0.004, 0.03]);
        assert_eq!(super::result_at(&pitted, "wear.first_pitting"), Some(2e5));
        assert_eq!(
            super::result_at(&steps(&[0.0, 0.0]), "wear.first_pitting"),
            None
        );
        let end = super::result_at(&pitted, "wear.end.backlash_increase_m");
        assert_eq!(end, Some(3e-6));
        assert_eq!(super::result_at(&pitted, "safety.S_H"), Some(0.7));
    }
}
