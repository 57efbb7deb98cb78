//! The validation study behind `VALIDATION.md` (MODEL §12 g-m): the analytic checks, the
//! studies the published work made on the reference gears, the sensitivity of the lives to the
//! inputs the published data do not give, and each refinement of ours against the default.
//!
//! A study is a list of jobs: loaded analyses of an unworn gear and lives. Each job's result is
//! written to `DIR/runs/<id>.json` with the full text of its inputs (gear, plan, code version);
//! a later run reuses a result only when that text is the same, so an interrupted study resumes
//! where it stopped and a changed input is always recomputed; the friction studies keep their
//! unworn analyses the same way in `DIR/friction-runs`. The report is then written from the
//! results ([`report`]).

pub mod analytic;
pub mod friction;
pub mod report;

use crate::geometry::Geometry;
use crate::input::{self, BendingKind, GearSet, Phase, StepControl, WearPlan};
use crate::wear::{StepRecord, WearState};
use std::path::{Path, PathBuf};

/// Version of the study's jobs: part of every job's key (a change of the code that changes
/// results bumps it, so old results are recomputed).
pub const STUDY_VERSION: &str = "validation-2";

/// Why the study stopped.
#[derive(Debug, thiserror::Error)]
pub enum ValidationError {
    #[error("example {path}: {source}")]
    Input {
        path: String,
        #[source]
        source: input::InputError,
    },
    #[error("job {id}: {message}")]
    Job { id: String, message: String },
    #[error("--jobs: no job {id} in the study (its jobs: {known})")]
    UnknownJob { id: String, known: String },
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
}

/// What the study runs.
#[derive(Debug, Clone)]
pub struct Settings {
    /// The directory of the reference cases (`examples/`).
    pub examples: PathBuf,
    /// Smoke run: lives cut to a hundredth, no bending, no million-cycle studies, one job per
    /// table (checks the machinery, not the model).
    pub quick: bool,
    /// Only these jobs (ids as in the report's "Run times"; empty: every job): the tables
    /// of the others are left out of the report.
    pub only: Vec<String>,
}

/// One job: a loaded analysis of the unworn gear (no plan) or a life.
#[derive(Debug, Clone)]
pub struct Job {
    pub id: String,
    pub gear: GearSet,
    pub plan: Option<WearPlan>,
}

/// What the study keeps of a job (units in the names).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct JobResult {
    pub id: String,
    /// The job's inputs as JSON text (gear, plan, study version): the result is reused only
    /// for the same text.
    pub key: String,
    pub seconds: f64,
    pub bending_model: String,
    /// Unworn loaded analysis.
    pub unworn: UnwornPattern,
    /// The life's records (without the per-position curves); empty for an unworn analysis.
    pub records: Vec<StepRecord>,
    /// The schedule, for the phase tables: (kind, start, end) in cycles.
    pub phases: Vec<(String, f64, f64)>,
    /// Why the job failed (then nothing else is filled in; not stored, tried again next run).
    #[serde(default)]
    pub error: Option<String>,
}

/// Loaded pattern of the unworn gear (MODEL §5.6) and where its maximum sits.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct UnwornPattern {
    pub max_pressure_pa: f64,
    pub pressure_patch_max_pa: f64,
    pub mean_pressure_pa: f64,
    pub s0: f64,
    pub s1: f64,
    pub s2: f64,
    /// Centre of the cell of the maximum, m; and its height above the worm-tip trace on its
    /// face column (how far from the worm's tip edge), m.
    pub max_r_m: f64,
    pub max_z_m: f64,
    pub max_above_tip_trace_m: f64,
    pub te_mean_rad: f64,
    pub te_p2p_rad: f64,
    pub stiffness_nm_per_rad: f64,
    /// p_eq,2%, the equivalent pressure below the flank exceeded on 2 % of the active flank
    /// (MODEL §8.1: what S_H reads), Pa.
    #[serde(default)]
    pub equivalent_pressure_first_pitting_pa: f64,
    /// The largest equivalent pressure (an edge's, MODEL §5.7), Pa.
    #[serde(default)]
    pub equivalent_pressure_max_pa: f64,
    /// The edges' share of the flank at or above p_eq,2% (the worm tip's trace, the face ends,
    /// the blank top; `ltca.first_pitting_places`).
    #[serde(default)]
    pub first_pitting_edge_share: f64,
}

/// Results of the study by job id.
pub type Results = std::collections::BTreeMap<String, JobResult>;

/// The reference case `name` of `examples/`, validated.
pub fn example(settings: &Settings, name: &str) -> Result<GearSet, ValidationError> {
    let path = settings.examples.join(name);
    let mut g = input::load(&path).map_err(|source| ValidationError::Input {
        path: path.display().to_string(),
        source,
    })?;
    if settings.quick {
        g.bending.kind = BendingKind::None;
    }
    // The validation reads no safety table: its jobs keep their keys whatever the examples'
    // safety inputs.
    g.rating.safety = input::SafetyInputs::default();
    Ok(g)
}

/// Runs every job not already in `dir/runs` (same key) and the friction studies over sliding
/// speeds ([`friction`]; each analysis not already in `dir/friction-runs`), and writes the
/// report and its figures (`dir/validation-figures`); returns the path of
/// `dir/VALIDATION.md`. `progress` receives a line per job.
pub fn run(
    settings: &Settings,
    dir: &Path,
    progress: &mut dyn FnMut(&str),
) -> Result<PathBuf, ValidationError> {
    let jobs = jobs(settings)?;
    let mut results = Results::new();
    for (k, job) in jobs.iter().enumerate() {
        let result = match cached(dir, job) {
            Some(r) => {
                progress(&format!(
                    "[{}/{}] {}: from {}",
                    k + 1,
                    jobs.len(),
                    job.id,
                    run_path(dir, &job.id).display()
                ));
                r
            }
            None => {
                progress(&format!("[{}/{}] {} ...", k + 1, jobs.len(), job.id));
                match run_job(job) {
                    Ok(r) => {
                        let text =
                            crate::integrity::seal(&r).map_err(|e| ValidationError::Job {
                                id: job.id.clone(),
                                message: e.to_string(),
                            })?;
                        crate::output::write_atomic(&run_path(dir, &job.id), text.as_bytes())?;
                        progress(&format!("    {} done in {:.1} s", job.id, r.seconds));
                        r
                    }
                    // A job that fails is reported as failed (and tried again next time), the
                    // study goes on.
                    Err(e) => {
                        progress(&format!("    {} FAILED: {e}", job.id));
                        JobResult {
                            id: job.id.clone(),
                            key: key(job),
                            seconds: 0.0,
                            bending_model: String::new(),
                            unworn: UnwornPattern::default(),
                            records: Vec::new(),
                            phases: Vec::new(),
                            error: Some(e.to_string()),
                        }
                    }
                }
            }
        };
        results.insert(job.id.clone(), result);
    }
    let analytic = analytic::checks(&example(settings, "gear-1x40-design.toml")?, settings.quick);
    let (speeds, window) = friction_studies(settings, dir, progress)?;
    let markdown = report::markdown(settings, &results, &analytic, (&speeds, &window));
    let path = dir.join("VALIDATION.md");
    crate::output::write_atomic(&path, markdown.as_bytes())?;
    let json = serde_json::json!({
        "analytic": analytic,
        "jobs": results,
        "friction_over_speeds": speeds,
        "limiting_shear_window": window,
    });
    crate::output::write_atomic(
        &dir.join("validation.json"),
        serde_json::to_string_pretty(&json)
            .unwrap_or_default()
            .as_bytes(),
    )?;
    Ok(path)
}

/// The friction studies of the report's section (e) ([`friction`]): the speed study (its
/// charts written into `dir/validation-figures`) and the limiting shear's window, each unworn
/// analysis read from `dir/friction-runs` when stored there with the same inputs.
fn friction_studies(
    settings: &Settings,
    dir: &Path,
    progress: &mut dyn FnMut(&str),
) -> Result<(Vec<friction::SpeedPoint>, Vec<friction::LimitingShearRow>), ValidationError> {
    progress("friction over sliding speeds (MODEL §13, 14 unworn loaded analyses) ...");
    let store = friction::Store::new(Some(&dir.join(FRICTION_RUNS)));
    let speeds = friction::over_speeds(settings, &store)?;
    friction::charts(&speeds, &dir.join(FIGURES))?;
    progress(&format!(
        "the film's limiting shear over its window (MODEL §13: the speed study and case C at \
         {} values) ...",
        friction::LIMITING_SHEAR_STUDY.len()
    ));
    let window = friction::limiting_shear_window(settings, &store)?;
    let (read, computed) = store.counts();
    progress(&format!(
        "    friction studies: {computed} unworn analyses computed, {read} read from {}",
        dir.join(FRICTION_RUNS).display()
    ));
    Ok((speeds, window))
}

/// The folder beside `VALIDATION.md` that holds its figures (copied with it).
pub const FIGURES: &str = "validation-figures";

/// The folder beside `VALIDATION.md` that keeps the friction studies' unworn analyses between
/// calls ([`friction::Store`]).
pub const FRICTION_RUNS: &str = "friction-runs";

fn run_path(dir: &Path, id: &str) -> PathBuf {
    dir.join("runs").join(format!("{id}.json"))
}

/// The job's key: its inputs as JSON text, with the program that ran it ([`crate::PROGRAM`]:
/// a run kept by another build is run again).
fn key(job: &Job) -> String {
    serde_json::json!({
        "version": STUDY_VERSION,
        "program": crate::PROGRAM,
        "gear": job.gear,
        "plan": job.plan,
    })
    .to_string()
}

/// A stored result of the same job (same key), if any.
fn cached(dir: &Path, job: &Job) -> Option<JobResult> {
    let text =
        crate::files::read_text(&run_path(dir, &job.id), crate::files::OWN_FILE_LIMIT).ok()?;
    // (A run that fails its checksum is run again.)
    let r: JobResult = crate::integrity::open(&text).ok()?;
    (r.key == key(job)).then_some(r)
}

/// A gear's unworn analysis: its geometry, TCA, bending model (from the cache when built
/// before), loaded-analysis settings and loaded analysis.
pub(super) struct Unworn {
    pub geo: Geometry,
    pub tca: crate::kinematics::Tca,
    pub bending: Option<crate::bending::worm_model::FeBending>,
    pub settings: crate::ltca::LtcaSettings,
    pub ltca: crate::ltca::Ltca,
}

impl Unworn {
    /// Runs the stages up to the unworn loaded analysis of `g`; a failure is reported as the
    /// job `id`'s.
    pub fn analyse(g: &GearSet, id: &str) -> Result<Self, ValidationError> {
        let fail = |message: String| ValidationError::Job {
            id: id.to_string(),
            message,
        };
        let geo = Geometry::build(g).map_err(|e| fail(e.to_string()))?;
        let tca = crate::kinematics::analyse(g, &geo).map_err(|e| fail(e.to_string()))?;
        let (built, _) = crate::bending::model::build(g, &geo).map_err(|e| fail(e.to_string()))?;
        let bending = built.map(|b| b.model);
        let settings = crate::ltca::LtcaSettings::from_gear(g);
        let bending_ref = bending
            .as_ref()
            .map(|b| b as &dyn crate::ltca::BendingModel);
        let ltca = crate::ltca::analyse_with(g, &geo, &tca, &settings, bending_ref)
            .map_err(|e| fail(crate::runner::error_chain(&e)))?;
        Ok(Self {
            geo,
            tca,
            bending,
            settings,
            ltca,
        })
    }
}

/// Runs one job: geometry, TCA, bending (from the cache when built before), the unworn loaded
/// analysis, and the life when there is a plan.
pub fn run_job(job: &Job) -> Result<JobResult, ValidationError> {
    let fail = |message: String| ValidationError::Job {
        id: job.id.clone(),
        message,
    };
    let start = std::time::Instant::now();
    let g = &job.gear;
    let Unworn {
        geo,
        tca,
        bending,
        settings,
        ltca: l,
    } = Unworn::analyse(g, &job.id)?;
    let bending_ref = bending
        .as_ref()
        .map(|b| b as &dyn crate::ltca::BendingModel);
    let unworn = unworn_pattern(&geo, &tca, &l);
    let mut records = Vec::new();
    if let Some(plan) = &job.plan {
        let wf = geo.wheel_flank(tca.loaded_flank);
        let end = crate::wear::simulate(
            g,
            &geo,
            &tca,
            &settings,
            bending_ref,
            plan,
            WearState::new(wf),
            &mut |_| Ok(()),
        )
        .map_err(|e| fail(crate::runner::error_chain(&e)))?;
        records = end
            .records
            .into_iter()
            .map(|r| StepRecord {
                positions: Vec::new(),
                ..r
            })
            .collect();
    }
    let phases = match &job.plan {
        Some(p) if p.pitting == crate::input::Pitting::Forecast => {
            crate::wear::forecast::phase_spans(&records)
                .into_iter()
                .map(|s| (s.kind, s.start_cycles, s.end_cycles))
                .collect()
        }
        Some(p) => schedule(p),
        None => Vec::new(),
    };
    Ok(JobResult {
        id: job.id.clone(),
        key: key(job),
        seconds: start.elapsed().as_secs_f64(),
        bending_model: l.bending_model.clone(),
        unworn,
        records,
        phases,
        error: None,
    })
}

/// The unworn pattern's figures (MODEL §5.6) and the place of its maximum.
fn unworn_pattern(
    geo: &Geometry,
    tca: &crate::kinematics::Tca,
    l: &crate::ltca::Ltca,
) -> UnwornPattern {
    let wf = geo.wheel_flank(tca.loaded_flank);
    let k = (0..l.pattern.len())
        .max_by(|&a, &b| l.pattern[a].total_cmp(&l.pattern[b]))
        .unwrap_or(0);
    let cell = &wf.cells[k];
    let j = k / wf.cells_height;
    let trace = 0.5 * (tca.tip_trace[j].1 + tca.tip_trace[j + 1].1);
    let (te_mean, te_p2p) = l.te_stats();
    UnwornPattern {
        max_pressure_pa: l.max_pressure,
        pressure_patch_max_pa: l.pressure_patch_max,
        mean_pressure_pa: l.mean_pressure,
        s0: l.s0,
        s1: l.s1,
        s2: l.s2,
        max_r_m: cell.r,
        max_z_m: cell.z,
        max_above_tip_trace_m: cell.r - trace,
        te_mean_rad: te_mean,
        te_p2p_rad: te_p2p,
        stiffness_nm_per_rad: l.stiffness_mean(),
        equivalent_pressure_first_pitting_pa: l.equivalent_pressure_first_pitting,
        equivalent_pressure_max_pa: l.equivalent_pressure_max,
        first_pitting_edge_share: l.first_pitting_places.edge_share(),
    }
}

/// The plan's phases as (kind, start, end); one wear phase for a plan without schedule.
fn schedule(plan: &WearPlan) -> Vec<(String, f64, f64)> {
    let mut out = Vec::new();
    let mut start = 0.0;
    for p in &plan.phases {
        let (kind, end) = match *p {
            Phase::Wear { until } => ("wear", until),
            Phase::Pitting { until, .. } => ("pitting", until),
        };
        let end = end.min(plan.life_cycles);
        if end > start {
            out.push((kind.to_string(), start, end));
        }
        start = end;
    }
    if start < plan.life_cycles {
        out.push(("wear".to_string(), start, plan.life_cycles));
    }
    out
}

/// A variant of a gear: `id` and a change.
fn variant(base: &GearSet, change: impl FnOnce(&mut GearSet)) -> GearSet {
    let mut g = base.clone();
    change(&mut g);
    g
}

/// The study's jobs in order: (b) reference studies, (c) sensitivity, (d) options.
pub fn jobs(settings: &Settings) -> Result<Vec<Job>, ValidationError> {
    let scale = if settings.quick { 0.01 } else { 1.0 };
    let design = example(settings, "gear-1x40-design.toml")?;
    let (a, b, c) = (
        example(settings, "gear-1x40-case-a.toml")?,
        example(settings, "gear-1x40-case-b.toml")?,
        example(settings, "gear-1x40-case-c.toml")?,
    );
    let mut jobs = Vec::new();
    design_jobs(&mut jobs, &design, scale, settings.quick);
    endurance_jobs(&mut jobs, [&a, &b, &c], scale);
    thermal_jobs(&mut jobs, &c, scale);
    // (c) Sensitivity of case C's life to the unpublished inputs; (d) our options.
    for (id, g, plan) in variants(&c, scaled_life(&c, scale)) {
        push_job(&mut jobs, &id, g, Some(plan));
    }
    if settings.quick {
        jobs.retain(|j| QUICK_JOBS.contains(&j.id.as_str()));
    }
    if let Some(id) = settings
        .only
        .iter()
        .find(|id| !jobs.iter().any(|j| &j.id == *id))
    {
        return Err(ValidationError::UnknownJob {
            id: id.clone(),
            known: jobs
                .iter()
                .map(|j| j.id.as_str())
                .collect::<Vec<_>>()
                .join(", "),
        });
    }
    if !settings.only.is_empty() {
        jobs.retain(|j| settings.only.contains(&j.id));
    }
    Ok(jobs)
}

/// The smoke run's jobs: one per table of the document (its machinery, not its variants).
const QUICK_JOBS: [&str; 12] = [
    "unworn-design",
    "design-30000",
    "design-adaptive",
    "case-a",
    "case-b",
    "case-c",
    "case-b-wear-only",
    "case-c-forecast",
    "speed-600",
    "c-balance",
    "c-roughness-0.2",
    "c-elastic",
];

/// A gear's life plan (180 000 cycles when the file has none) with its life and phases
/// scaled by `scale` (the quick study's hundredth).
fn scaled_life(g: &GearSet, scale: f64) -> WearPlan {
    let mut p = g
        .wear
        .clone()
        .unwrap_or_else(|| WearPlan::with_life(180_000.0));
    p.life_cycles *= scale;
    for phase in &mut p.phases {
        match phase {
            Phase::Wear { until } | Phase::Pitting { until, .. } => *until *= scale,
        }
    }
    p
}

fn push_job(jobs: &mut Vec<Job>, id: &str, gear: GearSet, plan: Option<WearPlan>) {
    jobs.push(Job {
        id: id.to_string(),
        gear,
        plan,
    })
}

/// The worm torques of the load study besides the design example's 60 N m, N m.
pub const LOAD_STUDY_NM: [f64; 3] = [20.0, 30.0, 90.0];

/// (b) The design case: its unworn pattern, step controls over 180 000 cycles, and (not in
/// the quick study) a million cycles.
fn design_jobs(jobs: &mut Vec<Job>, design: &GearSet, scale: f64, quick: bool) {
    // (b) Unworn patterns (the lives below start with them too).
    push_job(jobs, "unworn-design", design.clone(), None);
    let design_life = scaled_life(design, scale);
    for (id, step) in [
        ("design-30000", StepControl::Cycles(30_000.0 * scale)),
        ("design-15000", StepControl::Cycles(15_000.0 * scale)),
        ("design-10000", StepControl::Cycles(10_000.0 * scale)),
        ("design-adaptive", StepControl::MaxRemoval(4e-6)),
    ] {
        let plan = WearPlan {
            step,
            ..design_life.clone()
        };
        push_job(jobs, id, design.clone(), Some(plan));
    }
    if !quick {
        // S_H against the load (MODEL §8.1, §9.1): the same life at other worm torques
        // (design-adaptive is the example's 60 N m).
        for torque in LOAD_STUDY_NM {
            let plan = WearPlan {
                step: StepControl::MaxRemoval(4e-6),
                ..design_life.clone()
            };
            let g = variant(design, |g| {
                g.conditions.torque = input::Torque::Worm(torque)
            });
            push_job(jobs, &format!("design-{torque:.0}nm"), g, Some(plan));
        }
        for (id, step) in [
            ("design-1e6-fixed", StepControl::Cycles(30_000.0)),
            ("design-1e6-adaptive", StepControl::MaxRemoval(4e-6)),
        ] {
            let plan = WearPlan {
                step,
                ..WearPlan::with_life(1e6)
            };
            push_job(jobs, id, design.clone(), Some(plan));
        }
    }
}

/// (b) The endurance cases A, B, C with their schedules, case B wear only, each case's pitting
/// forecast, and the speed study on case C.
fn endurance_jobs(jobs: &mut Vec<Job>, [a, b, c]: [&GearSet; 3], scale: f64) {
    let life = |g: &GearSet| scaled_life(g, scale);
    push_job(jobs, "case-a", a.clone(), Some(life(a)));
    push_job(jobs, "case-b", b.clone(), Some(life(b)));
    push_job(jobs, "case-c", c.clone(), Some(life(c)));
    let mut wear_only = life(b);
    wear_only.phases.clear();
    push_job(jobs, "case-b-wear-only", b.clone(), Some(wear_only));
    // (b) The pitting forecast of each endurance case: its schedule's phases dropped, found
    // from the damage (the forecast law of `wear::forecast`; the example's curve, life factor
    // 1, no fit per case).
    for (id, g) in [("a", a), ("b", b), ("c", c)] {
        let mut plan = life(g);
        plan.phases.clear();
        plan.pitting = crate::input::Pitting::Forecast;
        push_job(jobs, &format!("case-{id}-forecast"), g.clone(), Some(plan));
    }
    // (b) Speed study: case C's torque at 100 / 600 / 1200 rpm (900 rpm is case C).
    for rpm in [100.0, 600.0, 1200.0] {
        let g = variant(c, |g| {
            g.conditions.worm_speed = rpm * 2.0 * std::f64::consts::PI / 60.0
        });
        push_job(jobs, &format!("speed-{rpm:.0}"), g, Some(life(c)));
    }
}

/// A strongly cooled housing for the tests' heat balances (MODEL §13): forced air,
/// 200 W/(m^2 K) over 1 m^2, 20 C, no cooler (a steady oil temperature for any of the
/// examples' losses; the validation's thermal jobs use the examples' own fan-cooled housing,
/// 40 W/(m^2 K), which puts the design case's oil at 90 C; natural convection over the default
/// area rejects none of these losses below 200 C).
pub fn study_housing() -> input::Housing {
    input::Housing {
        balance: true,
        area: 1.0,
        heat_transfer: 200.0,
        ambient: 293.15,
        cooler: 0.0,
    }
}

/// (e) Case C's life and the speed study with the oil temperature from the heat balance of
/// the example's own housing (its fan-cooled case, assumed, sized on the contact's loss)
/// instead of the fixed 60 C.
fn thermal_jobs(jobs: &mut Vec<Job>, c: &GearSet, scale: f64) {
    for rpm in [100.0, 600.0, 900.0, 1200.0] {
        let g = variant(c, |g| {
            g.conditions.worm_speed = rpm * 2.0 * std::f64::consts::PI / 60.0;
            g.housing.balance = true;
        });
        let id = if rpm == 900.0 {
            "c-balance".to_string()
        } else {
            format!("speed-{rpm:.0}-balance")
        };
        push_job(jobs, &id, g, Some(scaled_life(c, scale)));
    }
}

/// A change of a gear (a variant's).
type GearChange = fn(&mut GearSet);

/// Case C's edge variants: 20 um reliefs over 1 mm on the worm's tip and the wheel's edges,
/// and broken edges (MODEL §2.3: no citable default, so the default is sharp; 0.5 mm, the
/// middle of the 0.2-1 mm issue 54 names, on the worm's tip and the wheel's face ends).
fn edge_variants(c: &GearSet, plan: &WearPlan) -> [(String, GearSet, WearPlan); 2] {
    let relief = input::EdgeRelief {
        amount: 20e-6,
        length: 1e-3,
    };
    [
        (
            "c-reliefs".to_string(),
            variant(c, |g| {
                g.worm.tip_relief = relief;
                g.wheel.edge_relief = relief;
            }),
            plan.clone(),
        ),
        (
            "c-edge-breaks".to_string(),
            variant(c, |g| {
                g.worm.tip_edge_radius = 0.5e-3;
                g.wheel.face_edge_chamfer = 0.5e-3;
            }),
            plan.clone(),
        ),
    ]
}

/// The variants of case C for (c) and (d): id, gear, plan.
fn variants(c: &GearSet, plan: WearPlan) -> Vec<(String, GearSet, WearPlan)> {
    let mut out = Vec::new();
    for rq in [0.2, 0.5] {
        out.push((
            format!("c-roughness-{rq}"),
            variant(c, |g| g.lubricant.composite_roughness = rq * 1e-6),
            plan.clone(),
        ));
    }
    // Running-in of the roughness (MODEL §6.1) as examples/gear-1x40-running-in.toml has it.
    out.push((
        "c-running-in".to_string(),
        variant(c, |g| {
            g.lubricant.running_in = Some(input::RunningIn {
                roughness: 0.5 * g.lubricant.composite_roughness,
                depth: 2.0 * g.lubricant.composite_roughness,
            })
        }),
        plan.clone(),
    ));
    for (id, factor) in [("c-k-half", 0.5), ("c-k-double", 2.0)] {
        out.push((
            id.to_string(),
            variant(c, |g| g.wheel_material.wear_coefficient *= factor),
            plan.clone(),
        ));
    }
    if c.bending.kind == BendingKind::Fe {
        out.push((
            "c-no-bending".to_string(),
            variant(c, |g| g.bending.kind = BendingKind::None),
            plan.clone(),
        ));
    }
    out.extend(edge_variants(c, &plan));
    // Our options of the loaded analysis, one at a time.
    let analysis_options: [(&str, GearChange); 3] = [
        ("c-elastic", |g| {
            g.analysis.contact = input::ContactLaw::Elastic
        }),
        ("c-band-widen", |g| {
            g.analysis.contact_band_growth = input::BandGrowth::Widen
        }),
        ("c-wheel-flank-pressure", |g| {
            g.analysis.pressure_direction = input::PressureDirection::WheelFlank
        }),
    ];
    for (id, change) in analysis_options {
        out.push((id.to_string(), variant(c, change), plan.clone()));
    }
    out.push((
        "c-band-pits".to_string(),
        c.clone(),
        WearPlan {
            pit_depth: input::PitDepth::LoadedBand,
            ..plan.clone()
        },
    ));
    out.push((
        "c-film-floor".to_string(),
        c.clone(),
        WearPlan {
            film_load: input::FilmLoad::HertzPeakFloor,
            ..plan
        },
    ));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_quick_job_is_a_job_of_the_study() {
        // A renamed job would silently leave its table out of the smoke run.
        let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
        let settings = |quick| Settings {
            examples: examples.clone(),
            quick,
            only: Vec::new(),
        };
        let ids = |quick| -> Vec<String> {
            jobs(&settings(quick))
                .unwrap()
                .into_iter()
                .map(|j| j.id)
                .collect()
        };
        let (full, quick) = (ids(false), ids(true));
        assert_eq!(quick.len(), QUICK_JOBS.len(), "{quick:?}");
        assert!(quick.iter().all(|id| full.contains(id)));
    }

    #[test]
    fn a_subset_of_jobs_runs_just_those_and_an_unknown_id_is_named() {
        let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
        let settings = |only: &[&str]| Settings {
            examples: examples.clone(),
            quick: false,
            only: only.iter().map(|s| s.to_string()).collect(),
        };
        let all: Vec<String> = jobs(&settings(&[]))
            .unwrap()
            .into_iter()
            .map(|j| j.id)
            .collect();
        assert!(all.len() > 30, "{all:?}");
        let some: Vec<String> = jobs(&settings(&["case-c", "c-edge-breaks", "design-90nm"]))
            .unwrap()
            .into_iter()
            .map(|j| j.id)
            .collect();
        // In the study's order, not the list's.
        assert_eq!(some, ["design-90nm", "case-c", "c-edge-breaks"]);
        let message = jobs(&settings(&["case-c", "case-d"]))
            .unwrap_err()
            .to_string();
        assert!(
            message.contains("--jobs") && message.contains("case-d") && message.contains("case-a"),
            "{message}"
        );
    }
}
