//! `wormwear._native`: the Python package's native module over the wormwear library. It holds
//! gears and results as Rust values and hands out JSON text and plain number columns; the
//! Python layer (`wormwear/__init__.py`) turns them into dicts, DataFrames and arrays.
//!
//! Every computation runs with the GIL released; between the run's events (stages, wear
//! states, sweep variants) the interpreter's signals are checked, so Ctrl-C stops a run
//! (KeyboardInterrupt) at the next event.

use pyo3::exceptions::{PyKeyboardInterrupt, PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyList;
use std::path::Path;
use wormwear::input::{self, GearSet, InputError as GearInputError};
use wormwear::runner::{error_chain, LifeOverrides, OverrideNames};
use wormwear::sweep::{Row, Settings, Sweep, Variant};
use wormwear::{Request, Results, RunError, Source, Stage};

pyo3::create_exception!(
    _native,
    InputError,
    PyValueError,
    "An invalid gear input: every problem with its field, value and allowed range."
);
pyo3::create_exception!(
    _native,
    ComputationError,
    PyRuntimeError,
    "A computation that failed on a valid input (a solver or geometry failure)."
);

/// An input error as the Python exception: the message as the CLI prints it, and
/// `problems`, a list of (field, value, problem) tuples (empty for a syntax error).
fn input_error(py: Python<'_>, e: &GearInputError, context: &str) -> PyErr {
    let message = match context.is_empty() {
        true => e.to_string(),
        false => format!("{context}: {e}"),
    };
    let err = InputError::new_err(message);
    let problems: Vec<(String, String, String)> = e
        .field_errors()
        .iter()
        .map(|f| (f.field.clone(), f.value.clone(), f.problem.clone()))
        .collect();
    if let Ok(list) = PyList::new(py, problems) {
        let _ = err.value(py).setattr("problems", list);
    }
    err
}

/// A run error as the Python exception: input problems as InputError, an interrupt as
/// KeyboardInterrupt, the rest as ComputationError.
fn run_error(py: Python<'_>, e: &RunError) -> PyErr {
    match e {
        RunError::Stopped(m) if m == INTERRUPTED => PyKeyboardInterrupt::new_err("run interrupted"),
        e if e.is_input() => {
            let err = InputError::new_err(error_chain(e));
            let _ = err.value(py).setattr("problems", PyList::empty(py));
            err
        }
        e => ComputationError::new_err(error_chain(e)),
    }
}

const INTERRUPTED: &str = "interrupted (KeyboardInterrupt)";

/// Whether a signal handler raised (Ctrl-C): asked between events with the GIL taken back.
fn interrupted() -> bool {
    Python::attach(|py| py.check_signals().is_err())
}

/// A validated gear set with the document it came from.
#[pyclass(module = "wormwear._native", frozen)]
struct NativeGear {
    document: toml::Table,
    gear: GearSet,
    source: Source,
}

impl NativeGear {
    fn from_text(py: Python<'_>, text: &str, file: &str) -> PyResult<Self> {
        let gear = input::load_from_str(text).map_err(|e| input_error(py, &e, ""))?;
        let document = input::parse_document(text).map_err(|e| input_error(py, &e, ""))?;
        Ok(Self {
            document,
            gear,
            source: Source {
                file: file.to_string(),
                text: text.to_string(),
            },
        })
    }

    fn from_document(py: Python<'_>, document: toml::Table, file: String) -> PyResult<Self> {
        let text = input::document_text(&document).map_err(|e| input_error(py, &e, ""))?;
        let gear = input::load_document(&document).map_err(|e| input_error(py, &e, ""))?;
        Ok(Self {
            document,
            gear,
            source: Source { file, text },
        })
    }
}

/// A change whose name the gear file does not know: the TOML reader's error points at a line of
/// the document `with_` built, which the user never wrote; name the dotted field instead.
fn unknown_change(
    py: Python<'_>,
    e: PyErr,
    changes: &serde_json::Map<String, serde_json::Value>,
) -> PyErr {
    let text = e.value(py).to_string();
    let Some(problem) = text.lines().rev().find(|l| l.contains("unknown field")) else {
        return e;
    };
    let Some(name) = changes.keys().find(|name| {
        let last = name.rsplit('.').next().unwrap_or(name);
        problem.contains(&format!("`{last}`"))
    }) else {
        return e;
    };
    let err = InputError::new_err(format!("with_({name}): {}", problem.trim()));
    let value = changes.get(name).map_or(String::new(), |v| v.to_string());
    if let Ok(list) = PyList::new(py, [(name.clone(), value, problem.trim().to_string())]) {
        let _ = err.value(py).setattr("problems", list);
    }
    err
}

/// A JSON text as a TOML value (null: None).
fn toml_value(json: &serde_json::Value) -> Result<Option<toml::Value>, String> {
    match json {
        serde_json::Value::Null => Ok(None),
        v => serde_json::from_value::<toml::Value>(v.clone())
            .map(Some)
            .map_err(|e| format!("{v}: {e}")),
    }
}

#[pymethods]
impl NativeGear {
    /// Reads and validates a gear file (TOML).
    #[staticmethod]
    fn load(py: Python<'_>, path: &str) -> PyResult<Self> {
        let text =
            wormwear::files::read_text(std::path::Path::new(path), wormwear::files::INPUT_LIMIT)
                .map_err(|e| PyOSError::new_err(format!("cannot read {path}: {e}")))?;
        Self::from_text(py, &text, path)
    }

    /// Parses and validates a gear file's text; `file` names it in the results.
    #[staticmethod]
    fn from_text_(py: Python<'_>, text: &str, file: &str) -> PyResult<Self> {
        Self::from_text(py, text, file)
    }

    /// Validates a gear document given as JSON (the file's tables as objects).
    #[staticmethod]
    fn from_json(py: Python<'_>, json: &str, file: String) -> PyResult<Self> {
        let document: toml::Table = serde_json::from_str(json).map_err(|e| {
            InputError::new_err(format!("the gear document is not a table of values: {e}"))
        })?;
        Self::from_document(py, document, file)
    }

    /// The same gear with fields changed by dotted name (JSON object; null removes a field so
    /// it takes its default), validated.
    fn with_changes(&self, py: Python<'_>, changes_json: &str) -> PyResult<Self> {
        let changes: serde_json::Map<String, serde_json::Value> =
            serde_json::from_str(changes_json)
                .map_err(|e| InputError::new_err(format!("changes: {e}")))?;
        let mut document = self.document.clone();
        let mut described = Vec::new();
        for (name, value) in &changes {
            let value = toml_value(value)
                .map_err(|e| InputError::new_err(format!("{name} = {e}: not a gear file value")))?;
            input::set_dotted(&mut document, name, value.clone())
                .map_err(|e| input_error(py, &e, ""))?;
            described.push(format!(
                "{name} = {}",
                value.map_or("(default)".into(), |v| v.to_string())
            ));
        }
        let file = format!("{} with {}", self.source.file, described.join(", "));
        Self::from_document(py, document, file).map_err(|e| unknown_change(py, e, &changes))
    }

    /// The gear document as JSON (the file's tables as objects, the units of its names).
    fn document_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.document).map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// The validated gear set as JSON (SI units).
    fn validated_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.gear).map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// The file (or label) and text the gear came from.
    fn source(&self) -> (String, String) {
        (self.source.file.clone(), self.source.text.clone())
    }

    #[getter]
    fn title(&self) -> String {
        self.gear.title.clone()
    }
}

/// The stages of a request by name (None: those of `wormwear run`).
fn stages(names: Option<Vec<String>>, has_life: bool) -> PyResult<Vec<Stage>> {
    match names {
        None => Ok(Stage::ALL
            .into_iter()
            .filter(|s| *s != Stage::Wear || has_life)
            .collect()),
        Some(names) => names
            .iter()
            .map(|n| {
                Stage::parse(n).ok_or_else(|| {
                    PyValueError::new_err(format!(
                        "stages: {n:?} is not a stage (geometry, tca, ltca, wear, report)"
                    ))
                })
            })
            .collect(),
    }
}

/// Runs the pipeline (see `wormwear.run`).
#[pyfunction]
#[pyo3(signature = (gear, stages=None, cycles=None, step_cycles=None, step_wear_um=None, no_pitting=false, map_position=0, progress=None, step=None))]
#[allow(clippy::too_many_arguments)]
fn run(
    py: Python<'_>,
    gear: &NativeGear,
    stages: Option<Vec<String>>,
    cycles: Option<f64>,
    step_cycles: Option<f64>,
    step_wear_um: Option<f64>,
    no_pitting: bool,
    map_position: usize,
    progress: Option<Py<PyAny>>,
    step: Option<(Option<usize>, Option<usize>)>,
) -> PyResult<NativeResults> {
    let overrides = LifeOverrides {
        cycles,
        step_cycles,
        step_wear_um,
        no_pitting,
    };
    let has_life = gear.gear.wear.is_some() || overrides.asks_for_life();
    let mut request = Request::new(self::stages(stages, has_life)?);
    request.map_position = map_position;
    request.cad = step.map(|(teeth, state)| wormwear::cad::CadRequest { teeth, state });
    if request.has(Stage::Wear) {
        let plan = overrides
            .plan(&gear.gear, OverrideNames::Python)
            .map_err(|e| run_error(py, &e))?;
        request = request.with_life(plan);
    }
    let source = gear.source.clone();
    let result = py.detach(|| {
        let mut on_event = |event: wormwear::Event| -> Result<(), RunError> {
            if interrupted() {
                return Err(RunError::Stopped(INTERRUPTED.into()));
            }
            report(progress.as_ref(), &event).map_err(RunError::Stopped)
        };
        wormwear::run(&gear.gear, source, request, &mut on_event)
    });
    match result {
        Ok(results) => Ok(NativeResults { results }),
        Err(RunError::Stopped(m)) if m != INTERRUPTED => Err(PyRuntimeError::new_err(format!(
            "the progress callback failed: {m}"
        ))),
        Err(e) => Err(run_error(py, &e)),
    }
}

/// Calls the progress callback, if any, with (event, details dict as JSON text).
fn report(progress: Option<&Py<PyAny>>, event: &wormwear::Event) -> Result<(), String> {
    let Some(callback) = progress else {
        return Ok(());
    };
    let (kind, details) = match event {
        wormwear::Event::Stage(s) => ("stage", serde_json::json!({ "stage": s.name() })),
        wormwear::Event::Bending(b) => (
            "bending",
            serde_json::json!({ "origin": format!("{:?}", b.origin).to_lowercase(), "seconds": b.seconds }),
        ),
        wormwear::Event::WearState(l) => {
            let r = l.step.state.records.last();
            (
                "wear_state",
                serde_json::json!({
                    "step": l.step.state.step,
                    "cycles": l.step.state.cycles,
                    "life_cycles": l.plan.life_cycles,
                    "backlash_increase_m": r.map(|r| r.backlash_increase_m),
                    "max_wear_m": r.map(|r| r.max_wear_m),
                }),
            )
        }
    };
    Python::attach(|py| {
        callback
            .call1(py, (kind, details.to_string()))
            .map(|_| ())
            .map_err(|e| e.to_string())
    })
}

/// A table as (column names, columns of numbers).
type Columns = (Vec<String>, Vec<Vec<f64>>);

/// The results of a run.
#[pyclass(module = "wormwear._native", frozen)]
struct NativeResults {
    results: Results,
}

#[pymethods]
impl NativeResults {
    /// The sections of summary.json as JSON.
    fn summary_json(&self) -> PyResult<String> {
        let sections = wormwear::output::summary_sections(&self.results)
            .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        Ok(serde_json::Value::Object(sections).to_string())
    }

    /// A table by name as (column names, columns of numbers): ltca_positions, ltca_pattern,
    /// ltca_pressures, friction_map, duty_cycle, wear_steps, wear_positions, wear_map; None when
    /// its stage did not run (duty_cycle: without a load spectrum).
    fn table(&self, name: &str) -> PyResult<Option<Columns>> {
        use wormwear::output::{ltca, wear};
        let r = &self.results;
        let tca = r.tca.as_ref();
        let wf = tca.map(|t| r.geometry.wheel_flank(t.loaded_flank));
        let life = r.life.as_ref();
        let table = match name {
            "ltca_positions" => tca
                .zip(r.ltca.as_ref())
                .map(|(t, l)| ltca::positions_table(t, l)),
            "ltca_pattern" => wf
                .zip(r.ltca.as_ref())
                .map(|(w, l)| ltca::pattern_table(w, l)),
            "ltca_pressures" => r.ltca.as_ref().map(ltca::pressures_table),
            "friction_map" => wf
                .zip(r.thermal.as_ref())
                .map(|(w, t)| wormwear::output::friction::friction_table(w, t)),
            "duty_cycle" => r
                .spectrum
                .as_ref()
                .map(wormwear::output::spectrum::spectrum_csv),
            "wear_steps" => life.map(|l| wear::steps_table(&l.end)),
            "wear_positions" => tca
                .zip(life)
                .map(|(t, l)| wear::position_table(t, &l.end.records)),
            "wear_map" => wf
                .zip(life.and_then(|l| l.maps.last().map(|m| (l, m))))
                .map(|(w, (_, m))| {
                    wear::node_table(
                        w,
                        &m.state,
                        &m.cycle,
                        &m.state.plastic_set_after(&m.ltca),
                        &m.ltca,
                    )
                }),
            _ => {
                return Err(PyValueError::new_err(format!(
                    "no table {name:?}: ltca_positions, ltca_pattern, ltca_pressures, \
                     friction_map, duty_cycle, wear_steps, wear_positions, wear_map"
                )))
            }
        };
        Ok(table.map(|t| (t.header().to_vec(), t.columns())))
    }

    /// The stages run.
    fn stages(&self) -> Vec<String> {
        self.results
            .stages
            .iter()
            .map(|s| s.name().to_string())
            .collect()
    }

    /// The warnings of the stages, of the life (its last state) and of the ratings.
    fn warnings(&self) -> Vec<String> {
        let r = &self.results;
        let mut w = r.warnings.clone();
        if let (Some(life), Some(tca)) = (&r.life, &r.tca) {
            let wf = r.geometry.wheel_flank(tca.loaded_flank);
            w.extend(life.warnings(wf));
        }
        if let Some(r) = &self.results.rating {
            w.extend(r.warnings.iter().map(|x| format!("rating: {x}")));
        }
        w
    }

    /// Writes the stage and these results as REXS to `path` (JSON when `json`, else XML),
    /// atomically; as `wormwear export-rexs` writes it.
    fn write_rexs(&self, path: &str, json: bool) -> PyResult<()> {
        let r = &self.results;
        let model = wormwear::rexs::export::stage_model(
            &r.gear,
            Some(r),
            &wormwear::rexs::export::utc_now(),
        )
        .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        let encoding = match json {
            true => wormwear::rexs::Encoding::Json,
            false => wormwear::rexs::Encoding::Xml,
        };
        let text = wormwear::rexs::to_string(&model, encoding);
        wormwear::output::write_atomic(Path::new(path), text.as_bytes())
            .map_err(|e| PyOSError::new_err(e.to_string()))
    }

    /// Writes the files the CLI writes for the same stages into `directory` (created), under
    /// the same lock, first removing what an earlier run left there of these stages (all, for
    /// the whole pipeline); returns the paths written.
    fn write(&self, py: Python<'_>, directory: &str) -> PyResult<Vec<String>> {
        let dir = Path::new(directory);
        let files = py.detach(|| {
            let _lock = wormwear::output::lock_directory(dir).map_err(|e| e.to_string())?;
            // What an earlier run left there of these stages goes first, as the CLI does.
            wormwear::output::owned::clear_earlier(dir, &self.results.stages)
                .map_err(|e| error_chain(&e))?;
            wormwear::output::write_results(&self.results, dir, false).map_err(|e| error_chain(&e))
        });
        files
            .map(|f| f.iter().map(|p| p.display().to_string()).collect())
            .map_err(PyOSError::new_err)
    }
}

/// The sweep settings from JSON {stages, cycles, step_cycles, step_wear_um, no_pitting}.
fn sweep_settings(gear: &NativeGear, json: &str) -> PyResult<Settings> {
    #[derive(serde::Deserialize)]
    struct In {
        stages: Option<Vec<String>>,
        cycles: Option<f64>,
        step_cycles: Option<f64>,
        step_wear_um: Option<f64>,
        #[serde(default)]
        no_pitting: bool,
    }
    let s: In = serde_json::from_str(json).map_err(|e| PyValueError::new_err(e.to_string()))?;
    let overrides = LifeOverrides {
        cycles: s.cycles,
        step_cycles: s.step_cycles,
        step_wear_um: s.step_wear_um,
        no_pitting: s.no_pitting,
    };
    Settings::new(s.stages.as_deref(), overrides, gear.gear.wear.is_some())
        .map_err(|e| PyValueError::new_err(e.to_string()))
}

/// Variants from JSON [[name, {dotted: value}], ...].
fn variants(json: &str) -> PyResult<Vec<Variant>> {
    let list: Vec<(String, serde_json::Map<String, serde_json::Value>)> =
        serde_json::from_str(json).map_err(|e| PyValueError::new_err(e.to_string()))?;
    list.into_iter()
        .map(|(name, values)| {
            let values = values
                .into_iter()
                .map(|(n, v)| match toml_value(&v) {
                    Ok(Some(t)) => Ok((n, t)),
                    Ok(None) => Err(PyValueError::new_err(format!("{n} = null: give a value"))),
                    Err(e) => Err(PyValueError::new_err(format!("{n} = {e}"))),
                })
                .collect::<PyResult<Vec<_>>>()?;
            Ok(Variant { name, values })
        })
        .collect()
}

/// The variants of a grid (JSON [[dotted, [values]], ...] in the grid's order) as JSON
/// [[name, {dotted: value}]], and the parameter names.
#[pyfunction]
fn expand_grid(grid_json: &str) -> PyResult<(Vec<String>, String)> {
    // A list of (name, values) pairs: the grid's order, the first name varying slowest.
    let axes: Vec<(String, toml::Value)> =
        serde_json::from_str(grid_json).map_err(|e| PyValueError::new_err(e.to_string()))?;
    let (parameters, variants) =
        wormwear::sweep::axes_variants(axes).map_err(|e| PyValueError::new_err(e.to_string()))?;
    let list: Vec<(String, serde_json::Map<String, serde_json::Value>)> = variants
        .iter()
        .map(|v| {
            let values = v
                .values
                .iter()
                .map(|(n, x)| (n.clone(), wormwear::sweep::toml_to_json(x)))
                .collect();
            (v.name.clone(), values)
        })
        .collect();
    Ok((parameters, serde_json::to_string(&list).unwrap_or_default()))
}

/// Runs every variant on the local cores (into `directory` as `wormwear sweep` does, when
/// given); returns the rows as JSON in variant order.
#[pyfunction]
#[pyo3(signature = (base, parameters, variants_json, settings_json, directory=None))]
fn sweep(
    py: Python<'_>,
    base: &NativeGear,
    parameters: Vec<String>,
    variants_json: &str,
    settings_json: &str,
    directory: Option<String>,
) -> PyResult<String> {
    let settings = sweep_settings(base, settings_json)?;
    let study = Sweep {
        base_file: base.source.file.clone(),
        base: base.document.clone(),
        parameters,
        variants: variants(variants_json)?,
        settings,
    };
    let rows: Result<Vec<Row>, String> = py.detach(|| {
        let interrupt = || interrupted();
        match &directory {
            Some(d) => {
                let dir = Path::new(d);
                let _lock = wormwear::output::lock_directory(dir).map_err(|e| e.to_string())?;
                wormwear::sweep::run(&study, dir, &|_| {}, &interrupt).map_err(|e| error_chain(&e))
            }
            None => Ok(wormwear::sweep::run_in_memory(&study, &|_| {}, &interrupt)),
        }
    });
    let rows = rows.map_err(PyOSError::new_err)?;
    if rows
        .iter()
        .any(|r| r.error.as_deref() == Some("interrupted"))
        && interrupted()
    {
        return Err(PyKeyboardInterrupt::new_err("sweep interrupted"));
    }
    serde_json::to_string(&rows).map_err(|e| PyRuntimeError::new_err(e.to_string()))
}

/// Runs one variant (a Dask task): its row as JSON; its files into `directory` when given.
#[pyfunction]
#[pyo3(signature = (base, variant_json, settings_json, directory=None))]
fn run_variant(
    py: Python<'_>,
    base: &NativeGear,
    variant_json: &str,
    settings_json: &str,
    directory: Option<String>,
) -> PyResult<String> {
    let settings = sweep_settings(base, settings_json)?;
    let variant = variants(&format!("[{variant_json}]"))?
        .pop()
        .ok_or_else(|| PyValueError::new_err("no variant"))?;
    let row = py.detach(|| {
        let dir = directory
            .as_ref()
            .map(|d| wormwear::sweep::variant_dir(Path::new(d), &variant));
        if let Some(d) = &dir {
            std::fs::create_dir_all(d).map_err(|e| format!("{}: {e}", d.display()))?;
        }
        Ok::<Row, String>(wormwear::sweep::run_variant(
            &base.source.file,
            &base.document,
            &variant,
            &settings,
            dir.as_deref(),
            &|| false,
        ))
    });
    let row = row.map_err(PyOSError::new_err)?;
    serde_json::to_string(&row).map_err(|e| PyRuntimeError::new_err(e.to_string()))
}

/// The spread of `base` from a spread file's tables as JSON, without `base`.
fn spread_of(base: &NativeGear, spec_json: &str) -> PyResult<wormwear::spread::Spread> {
    let spec: serde_json::Value =
        serde_json::from_str(spec_json).map_err(|e| PyValueError::new_err(e.to_string()))?;
    let study = wormwear::spread::Spread::of_document(
        base.source.file.clone(),
        base.document.clone(),
        spec,
    )
    .map_err(|e| InputError::new_err(error_chain(&e)))?;
    Ok(study)
}

/// Runs a spread of `base` (MODEL §17) on the local cores into `directory` as `wormwear spread`
/// does: `spec_json` is a spread file's tables as JSON without `base` (`stages`, `cycles`, ...,
/// `spread`). Returns spread.json's text and the count of samples reused from `directory`
/// (finished there with the same inputs: by an earlier run, or by Dask tasks).
#[pyfunction]
fn spread(
    py: Python<'_>,
    base: &NativeGear,
    spec_json: &str,
    directory: String,
) -> PyResult<(String, usize)> {
    let study = spread_of(base, spec_json)?;
    let reused = std::sync::atomic::AtomicUsize::new(0);
    let done: Result<(), String> = py.detach(|| {
        let dir = Path::new(&directory);
        std::fs::create_dir_all(dir).map_err(|e| format!("{directory}: {e}"))?;
        let _lock = wormwear::output::lock_directory(dir).map_err(|e| e.to_string())?;
        let interrupt = || interrupted();
        let progress = |p: wormwear::sweep::Progress| {
            if p.reused {
                reused.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
            }
        };
        wormwear::spread::run(&study, dir, &progress, &interrupt)
            .map(|_| ())
            .map_err(|e| error_chain(&e))
    });
    done.map_err(PyOSError::new_err)?;
    if interrupted() {
        return Err(PyKeyboardInterrupt::new_err("spread interrupted"));
    }
    let summary = std::fs::read_to_string(Path::new(&directory).join("spread.json"))
        .map_err(|e| PyOSError::new_err(e.to_string()))?;
    Ok((summary, reused.into_inner()))
}

/// The samples of a spread of `base` (`spec_json` as [`spread`]'s) as sweep variants, JSON
/// [[name, {dotted: value}], ...]: what a Dask client runs one task each.
#[pyfunction]
fn spread_variants(base: &NativeGear, spec_json: &str) -> PyResult<String> {
    let study = spread_of(base, spec_json)?;
    let list: Vec<(String, serde_json::Map<String, serde_json::Value>)> = study
        .sweep
        .variants
        .iter()
        .map(|v| {
            let values = v
                .values
                .iter()
                .map(|(n, t)| (n.clone(), serde_json::to_value(t).unwrap_or_default()))
                .collect();
            (v.name.clone(), values)
        })
        .collect();
    serde_json::to_string(&list).map_err(|e| PyRuntimeError::new_err(e.to_string()))
}

/// The contact-pattern assistant (MODEL §17) on `base` as `wormwear pattern` does: `target_json`
/// the target's components ({"centre_across_face": 0.6, ...}), `bounds_json` [[name, min, max],
/// ...] or null (the default settings), the loaded pattern when `loaded`, at most `evaluations`
/// analyses; its files into `directory`. Returns pattern.json's text. Bad input raises
/// InputError naming it; an interrupt (Ctrl-C) stops the search at the next evaluation and
/// raises KeyboardInterrupt.
#[pyfunction]
fn pattern(
    py: Python<'_>,
    base: &NativeGear,
    target_json: &str,
    bounds_json: &str,
    loaded: bool,
    evaluations: usize,
    directory: String,
) -> PyResult<String> {
    use wormwear::pattern_assistant::{Assistant, Target, Which};
    let target: Target = serde_json::from_str(target_json)
        .map_err(|e| InputError::new_err(format!("target: {e}")))?;
    let bounds: Option<Vec<(String, f64, f64)>> = serde_json::from_str(bounds_json)
        .map_err(|e| InputError::new_err(format!("vary: {e} (a map of name to (min, max))")))?;
    let which = if loaded { Which::Loaded } else { Which::NoLoad };
    let (file, text) = (base.source.file.clone(), base.source.text.clone());
    let study = Assistant::new(file, text, target, bounds, which, evaluations)
        .map_err(|e| InputError::new_err(error_chain(&e)))?;
    let done: Result<(), String> = py.detach(|| {
        let dir = Path::new(&directory);
        std::fs::create_dir_all(dir).map_err(|e| format!("{directory}: {e}"))?;
        let _lock = wormwear::output::lock_directory(dir).map_err(|e| e.to_string())?;
        let outcome = study
            .run(&|_, _| {}, &|| interrupted())
            .map_err(|e| error_chain(&e))?;
        wormwear::pattern_assistant::write(&study, &outcome, dir)
            .map(|_| ())
            .map_err(|e| error_chain(&e))
    });
    done.map_err(PyOSError::new_err)?;
    if interrupted() {
        return Err(PyKeyboardInterrupt::new_err("pattern search interrupted"));
    }
    std::fs::read_to_string(Path::new(&directory).join("pattern.json"))
        .map_err(|e| PyOSError::new_err(e.to_string()))
}

/// Lets go of the root stress's kept FE sector (the last wheel's, kept for the next run of
/// the same wheel; up to a few hundred MB).
#[pyfunction]
fn forget_kept_sector() {
    wormwear::bending::wheel_root::forget_kept_sector();
}

/// The CSV of rows (JSON) as `wormwear sweep` writes it.
#[pyfunction]
fn write_sweep_csv(path: &str, parameters: Vec<String>, rows_json: &str) -> PyResult<()> {
    let rows: Vec<Row> =
        serde_json::from_str(rows_json).map_err(|e| PyValueError::new_err(e.to_string()))?;
    let refs: Vec<&Row> = rows.iter().collect();
    wormwear::sweep::write_csv(Path::new(path), &parameters, &refs)
        .map_err(|e| PyOSError::new_err(e.to_string()))
}

/// The worm stages of a REXS file as (id, name, worm id, wheel id).
#[pyfunction]
fn rexs_stages(path: &str) -> PyResult<Vec<(u64, String, u64, u64)>> {
    let model =
        wormwear::rexs::read(Path::new(path)).map_err(|e| InputError::new_err(e.to_string()))?;
    Ok(wormwear::rexs::import::worm_stages(&model)
        .into_iter()
        .map(|s| (s.id, s.name, s.worm, s.wheel))
        .collect())
}

/// A REXS file's worm stage as a gear file: (TOML text, warnings), as `wormwear import`
/// writes it. REXS problems raise InputError.
#[pyfunction]
#[pyo3(signature = (path, stage=None))]
fn import_rexs(path: &str, stage: Option<u64>) -> PyResult<(String, Vec<String>)> {
    let model =
        wormwear::rexs::read(Path::new(path)).map_err(|e| InputError::new_err(e.to_string()))?;
    let imported = wormwear::rexs::import::import(&model, stage, path)
        .map_err(|e| InputError::new_err(format!("in {path}: {e}")))?;
    Ok((imported.text, imported.warnings))
}

/// Compares finished runs (`wormwear compare`): writes compare.html, compare.csv and the
/// overlaid curves into `output`; returns the page's path, the runs' labels and the key results
/// as (quantity, unit, value per run).
#[pyfunction]
#[allow(clippy::type_complexity)]
fn compare(
    dirs: Vec<String>,
    output: &str,
) -> PyResult<(String, Vec<String>, Vec<(String, String, Vec<Option<f64>>)>)> {
    let dirs: Vec<std::path::PathBuf> = dirs.into_iter().map(Into::into).collect();
    let comparison = wormwear::output::compare::compare(&dirs)
        .map_err(|e| InputError::new_err(e.to_string()))?;
    let page = wormwear::output::compare::write_comparison(&comparison, Path::new(output))
        .map_err(|e| PyOSError::new_err(e.to_string()))?;
    Ok((
        page.display().to_string(),
        comparison.runs.iter().map(|r| r.label.clone()).collect(),
        comparison
            .rows
            .into_iter()
            .map(|r| (r.quantity, r.unit, r.values))
            .collect(),
    ))
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("InputError", m.py().get_type::<InputError>())?;
    m.add("ComputationError", m.py().get_type::<ComputationError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<NativeGear>()?;
    m.add_class::<NativeResults>()?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(expand_grid, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(spread, m)?)?;
    m.add_function(wrap_pyfunction!(spread_variants, m)?)?;
    m.add_function(wrap_pyfunction!(forget_kept_sector, m)?)?;
    m.add_function(wrap_pyfunction!(pattern, m)?)?;
    m.add_function(wrap_pyfunction!(run_variant, m)?)?;
    m.add_function(wrap_pyfunction!(write_sweep_csv, m)?)?;
    m.add_function(wrap_pyfunction!(rexs_stages, m)?)?;
    m.add_function(wrap_pyfunction!(import_rexs, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    Ok(())
}
