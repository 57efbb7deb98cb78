//! The pieces of the pipeline runner ([`crate::run`], MODEL §0): what a run is asked for
//! ([`Request`], [`Stage`], [`LifeOverrides`]), what it reports while it goes ([`Event`]) and
//! what it returns ([`Results`]). The CLI, the Python package and sweeps call [`crate::run`];
//! [`crate::output::write_results`] turns its results into files.

use crate::bending::model::{BuiltBending, Origin};
use crate::bending::worm_model::FeBending;
use crate::geometry::Geometry;
use crate::input::{GearSet, Phase, StepControl, WearPlan};
use crate::kinematics::Tca;
use crate::ltca::{BendingModel, Ltca, LtcaSettings};
use crate::rating::Rating;
use crate::wear::{CycleWear, StepView, WearError, WearState};
use std::collections::BTreeSet;
use std::path::PathBuf;

mod safety;

/// A stage of the pipeline a request asks for. Each runs the stages it needs before it
/// (the loaded analysis needs the unloaded one); what is written follows what was asked
/// ([`crate::output::write_results`]).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Stage {
    /// Worm, hob and wheel flanks (MODEL §2-3): sections, profiles, STL.
    Geometry,
    /// Unloaded meshing analysis (MODEL §4).
    Tca,
    /// Loaded tooth contact analysis (MODEL §5), with the ratings (MODEL §9).
    Ltca,
    /// Wear over life (MODEL §7-8), with the ratings.
    Wear,
    /// report.html over what the other stages wrote.
    Report,
}

impl Stage {
    /// Every stage, in pipeline order.
    pub const ALL: [Stage; 5] = [
        Stage::Geometry,
        Stage::Tca,
        Stage::Ltca,
        Stage::Wear,
        Stage::Report,
    ];

    /// The stage's name in requests and messages ("geometry", "tca", "ltca", "wear", "report").
    pub fn name(self) -> &'static str {
        match self {
            Stage::Geometry => "geometry",
            Stage::Tca => "tca",
            Stage::Ltca => "ltca",
            Stage::Wear => "wear",
            Stage::Report => "report",
        }
    }

    /// The stage of a name (case-insensitive), None for an unknown one.
    pub fn parse(name: &str) -> Option<Stage> {
        Stage::ALL
            .into_iter()
            .find(|s| s.name().eq_ignore_ascii_case(name.trim()))
    }
}

/// The input a run came from: its file name (or a label such as `<dict>`) and its text, for
/// summary.json's `input` section and report.html.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Source {
    pub file: String,
    pub text: String,
}

impl Source {
    /// The title of the results: the gear's title, else the file name.
    pub fn title(&self, gear: &GearSet) -> String {
        if gear.title.is_empty() {
            self.file.clone()
        } else {
            gear.title.clone()
        }
    }
}

/// What a run is asked for.
#[derive(Debug, Clone)]
pub struct Request {
    /// The stages whose results are wanted.
    pub stages: BTreeSet<Stage>,
    /// The life plan, needed with [`Stage::Wear`] (see [`LifeOverrides::plan`]).
    pub life: Option<WearPlan>,
    /// The state to continue the life from (a checkpoint checked by the caller:
    /// [`crate::output::wear::resume_state`]); None: the unworn flank.
    pub resume: Option<WearState>,
    /// Position whose pressure maps are drawn, 0-based (below `analysis.positions`).
    pub map_position: usize,
    /// The CAD solids (STEP) to build, None: none.
    pub cad: Option<crate::cad::CadRequest>,
    /// The map state the CAD request asks for when a resumed life computed it before its
    /// checkpoint (its worn flank: [`crate::output::wear::resumed_map_state`]); None: none.
    pub resumed_map: Option<WearState>,
}

impl Request {
    /// The stages given, no life, no resume, maps at position 0.
    pub fn new(stages: impl IntoIterator<Item = Stage>) -> Self {
        Self {
            stages: stages.into_iter().collect(),
            life: None,
            resume: None,
            map_position: 0,
            cad: None,
            resumed_map: None,
        }
    }

    /// The same with a life plan.
    pub fn with_life(mut self, plan: WearPlan) -> Self {
        self.life = Some(plan);
        self
    }

    /// Whether the request asks for `stage`.
    pub fn has(&self, stage: Stage) -> bool {
        self.stages.contains(&stage)
    }

    /// Checks the request against the gear before any work: a life plan for the wear stage
    /// and one that can end (MODEL §9 (a)), a map position among the analysed ones.
    pub fn check(&self, gear: &GearSet) -> Result<(), RunError> {
        if self.stages.is_empty() {
            return Err(RunError::Request("no stage asked for".into()));
        }
        if self.needs_bending() {
            if let Some(problem) = crate::rating::implausible_load(gear) {
                return Err(RunError::Request(problem));
            }
        }
        if let Some(cad) = &self.cad {
            cad.check(gear.wheel.teeth).map_err(RunError::Cad)?;
            if cad.state.is_some() && self.life.is_none() {
                return Err(RunError::Request(
                    "a worn wheel's STEP file (its wear state) needs a life: give the cycles or \
                     a [wear] section"
                        .into(),
                ));
            }
        }
        let positions = gear.analysis.positions;
        if self.map_position >= positions {
            return Err(RunError::Request(format!(
                "map position = {}: the gear analyses {positions} positions, numbered 0 to {}",
                self.map_position,
                positions.saturating_sub(1)
            )));
        }
        match (&self.life, self.has(Stage::Wear)) {
            (None, true) => Err(RunError::Request(
                "the wear stage needs a life plan: the gear has no [wear] section; add one \
                 (life_cycles, step_wear_um or step_cycles) or give the cycles"
                    .into(),
            )),
            (Some(plan), true) => {
                crate::wear::check_plan_can_end(gear, plan).map_err(RunError::Wear)
            }
            _ => Ok(()),
        }
    }

    /// Checks the request against the gear's geometry, once built: for the loaded stages, a
    /// load the flanks can carry ([`crate::ltca::flank_capacity_problem`]).
    pub fn check_geometry(&self, gear: &GearSet, geo: &Geometry) -> Result<(), RunError> {
        match crate::ltca::flank_capacity_problem(gear, geo) {
            Some(problem) if self.needs_bending() => Err(RunError::Request(problem)),
            _ => Ok(()),
        }
    }

    /// Whether the unloaded analysis is needed.
    pub(crate) fn needs_tca(&self) -> bool {
        self.has(Stage::Tca) || self.needs_bending()
    }

    /// Whether the bending model and the ratings are needed (a loaded stage).
    pub(crate) fn needs_bending(&self) -> bool {
        self.has(Stage::Ltca) || self.has(Stage::Wear)
    }
}

/// Changes to the gear's `[wear]` plan (the CLI's `--cycles`, `--step-cycles`,
/// `--step-wear-um`, `--no-pitting`; the Python `run`'s keywords).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LifeOverrides {
    /// Wheel cycles to simulate.
    pub cycles: Option<f64>,
    /// Fixed steps of this many wheel cycles.
    pub step_cycles: Option<f64>,
    /// Adaptive steps removing at most this depth, um.
    pub step_wear_um: Option<f64>,
    /// Drop the pitting phases of the schedule (wear all along).
    pub no_pitting: bool,
}

/// How overrides are named in messages: the CLI's flags or the Python keywords.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OverrideNames {
    Cli,
    Python,
}

impl OverrideNames {
    fn of(self, field: &str) -> String {
        match self {
            OverrideNames::Cli => format!("--{}", field.replace('_', "-")),
            OverrideNames::Python => field.to_string(),
        }
    }
}

impl LifeOverrides {
    /// Whether any override asks for a life (cycles given).
    pub fn asks_for_life(&self) -> bool {
        self.cycles.is_some()
    }

    /// The names (Python keywords) of the overrides that are given.
    pub fn given(&self) -> Vec<&'static str> {
        let given = [
            ("cycles", self.cycles.is_some()),
            ("step_cycles", self.step_cycles.is_some()),
            ("step_wear_um", self.step_wear_um.is_some()),
            ("no_pitting", self.no_pitting),
        ];
        given.into_iter().filter(|g| g.1).map(|g| g.0).collect()
    }

    /// The gear's life plan with these overrides; an error names the override and its range.
    pub fn plan(&self, gear: &GearSet, names: OverrideNames) -> Result<WearPlan, RunError> {
        let bad = |field: &str, value: f64, range: &str| {
            RunError::Request(format!(
                "{} = {}: must be {range}",
                names.of(field),
                crate::input::Number(value)
            ))
        };
        let mut plan = match (&gear.wear, self.cycles) {
            (Some(p), _) => p.clone(),
            (None, Some(_)) => WearPlan::with_life(0.0),
            (None, None) => {
                return Err(RunError::Request(format!(
                    "the file has no [wear] section: add one (life_cycles, step_wear_um or \
                     step_cycles) or give {}",
                    names.of("cycles")
                )))
            }
        };
        let cycles = |c: f64| c.is_finite() && (1.0..=1e12).contains(&c);
        if let Some(c) = self.cycles {
            if !cycles(c) {
                return Err(bad("cycles", c, "a number of cycles in [1, 1e12]"));
            }
            plan.life_cycles = c;
        }
        if let Some(c) = self.step_cycles {
            if !cycles(c) {
                return Err(bad("step_cycles", c, "a number of cycles in [1, 1e12]"));
            }
            plan.step = StepControl::Cycles(c);
        }
        if let Some(d) = self.step_wear_um {
            let min = crate::input::MIN_STEP_WEAR_UM;
            if !(d.is_finite() && (min..=1000.0).contains(&d)) {
                return Err(bad(
                    "step_wear_um",
                    d,
                    &format!("a depth in [{min}, 1000] um"),
                ));
            }
            plan.step = StepControl::MaxRemoval(d * 1e-6);
        }
        if let StepControl::Cycles(c) = plan.step {
            if let Some(problem) = crate::input::fixed_steps_problem(plan.life_cycles, c) {
                let field = if self.step_cycles.is_some() {
                    "step_cycles"
                } else {
                    "cycles"
                };
                return Err(RunError::Request(format!(
                    "{} = {c:e}: {problem}",
                    names.of(field)
                )));
            }
        }
        if self.no_pitting {
            plan.phases.retain(|p| matches!(p, Phase::Wear { .. }));
            plan.pitting = crate::input::Pitting::Off;
        }
        Ok(plan)
    }
}

/// Where the bending model came from and what it cost (MODEL §5.5).
#[derive(Debug, Clone, PartialEq)]
pub struct BendingInfo {
    pub origin: Origin,
    /// Cache file read or written, if any.
    pub cache_file: Option<PathBuf>,
    /// Wall time of the build or the read, s.
    pub seconds: f64,
}

/// What a run reports while it goes.
pub enum Event<'a> {
    /// A stage starts.
    Stage(Stage),
    /// The FE bending model is ready (built or read from the cache).
    Bending(&'a BendingInfo),
    /// A wear state is complete (its checkpoint and files may be written now).
    WearState(&'a LifeView<'a>),
}

/// One completed wear state with everything a writer needs.
pub struct LifeView<'a> {
    pub gear: &'a GearSet,
    pub source: &'a Source,
    pub geometry: &'a Geometry,
    pub tca: &'a Tca,
    pub plan: &'a WearPlan,
    pub step: &'a StepView<'a>,
}

/// A wear state kept for its maps: the state (with its last record only), the loaded
/// analysis, the wear of one cycle and the friction (MODEL §13) on its geometry.
#[derive(Debug, Clone)]
pub struct MapState {
    pub state: WearState,
    pub ltca: Ltca,
    pub cycle: CycleWear,
    pub thermal: crate::friction::Thermal,
    /// A map state of the plan (`map_cycles`).
    pub map: bool,
    /// The last state of the run.
    pub last: bool,
}

impl MapState {
    fn of(view: &StepView) -> Self {
        let mut state = WearState {
            records: Vec::new(),
            warm: None,
            ..view.state.clone()
        };
        state.records.extend(view.state.records.last().cloned());
        Self {
            state,
            ltca: view.ltca.clone(),
            cycle: view.cycle.clone(),
            thermal: view.thermal.clone(),
            map: view.map,
            last: view.last,
        }
    }

    /// The view a writer draws this state's maps from.
    pub fn view(&self) -> StepView<'_> {
        StepView {
            state: &self.state,
            ltca: &self.ltca,
            cycle: &self.cycle,
            thermal: &self.thermal,
            last: self.last,
            map: self.map,
        }
    }
}

/// The life of a run: its plan, the final state (every record) and the states whose maps
/// are drawn (the plan's map states and the last).
#[derive(Debug, Clone)]
pub struct Life {
    pub plan: WearPlan,
    pub end: WearState,
    pub maps: Vec<MapState>,
}

impl Life {
    /// The life's warnings at its last state on the loaded flank `wf`, read with its plan's
    /// onset share and pressure–life curve ([`WearState::warnings`]).
    pub fn warnings(&self, wf: &crate::geometry::WheelFlank) -> Vec<String> {
        let plan = &self.plan;
        self.end
            .warnings(wf, plan.pitting_onset_share, &plan.endurance)
    }
}

/// Everything a run computed.
#[derive(Debug, Clone)]
pub struct Results {
    pub gear: GearSet,
    pub source: Source,
    /// The stages asked for.
    pub stages: BTreeSet<Stage>,
    pub map_position: usize,
    pub geometry: Geometry,
    pub tca: Option<Tca>,
    pub bending: Option<BendingInfo>,
    pub ltca: Option<Ltca>,
    pub life: Option<Life>,
    /// The standard's ratings (MODEL §9), with the loaded stages.
    pub rating: Option<Rating>,
    /// Friction, efficiency and oil temperature from the loaded analysis (MODEL §13).
    pub thermal: Option<crate::friction::Thermal>,
    /// The safety table from the model (MODEL §9.1), with a loaded analysis.
    pub safety: Option<crate::safety::SafetyTable>,
    /// The duty cycle's bins on the unworn gear (MODEL §14), with a spectrum.
    pub spectrum: Option<crate::spectrum::Spectrum>,
    /// The CAD solids, when asked for.
    pub cad: Option<crate::cad::CadSolids>,
    /// Warnings of the stages, each with its stage's prefix where the CLI prints one.
    pub warnings: Vec<String>,
}

/// Why a run failed. [`RunError::is_input`] tells an input problem (exit code 2) from a
/// computation one.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The request does not fit the gear (a life without plan, a map position out of range,
    /// an override out of range).
    #[error("{0}")]
    Request(String),
    #[error("geometry")]
    Geometry(#[source] crate::geometry::GeometryError),
    #[error("unloaded meshing analysis")]
    Tca(#[source] crate::kinematics::KinematicsError),
    #[error("bending influence coefficients")]
    Bending(#[source] crate::bending::model::BendingError),
    #[error("loaded tooth contact analysis")]
    Ltca(#[source] crate::ltca::LtcaError),
    #[error("heat balance")]
    Friction(#[source] crate::friction::FrictionError),
    #[error("duty cycle")]
    Spectrum(#[source] crate::spectrum::SpectrumError),
    #[error("{}", wear_context(.0))]
    Wear(#[source] WearError),
    #[error("CAD solids")]
    Cad(#[source] crate::cad::CadError),
    /// The caller's event handler stopped the run (an interrupt, a file that cannot be
    /// written).
    #[error("{0}")]
    Stopped(String),
}

fn wear_context(e: &WearError) -> &'static str {
    match e {
        WearError::Checkpoint(_) => "resume",
        WearError::Plan(_) => "life plan",
        _ => "wear simulation",
    }
}

impl RunError {
    /// An input problem (the gear, the request, a checkpoint of another gear), not a failure
    /// of the computation.
    pub fn is_input(&self) -> bool {
        matches!(
            self,
            RunError::Request(_)
                | RunError::Cad(crate::cad::CadError::Request(_))
                | RunError::Geometry(_)
                | RunError::Friction(_)
                | RunError::Bending(crate::bending::model::BendingError::TooLarge { .. })
                | RunError::Ltca(crate::ltca::LtcaError::TooManyCells { .. })
                | RunError::Wear(WearError::Ltca {
                    source: crate::ltca::LtcaError::TooManyCells { .. },
                    ..
                })
                | RunError::Wear(
                    WearError::Checkpoint(_) | WearError::Plan(_) | WearError::Friction { .. }
                )
        ) || matches!(self, RunError::Spectrum(e) if e.is_input())
    }
}

/// A run in progress ([`crate::run`]): the gear, the request, the event handler and the
/// warnings so far; each step runs its stage when the request needs it.
pub(crate) struct Pipeline<'a> {
    gear: &'a GearSet,
    source: Source,
    request: Request,
    on_event: &'a mut dyn FnMut(Event) -> Result<(), RunError>,
    warnings: Vec<String>,
}

/// The bending model of a run (None without bending or without a loaded stage).
pub(crate) struct Bending {
    model: Option<FeBending>,
    info: Option<BendingInfo>,
}

impl<'a> Pipeline<'a> {
    pub(crate) fn new(
        gear: &'a GearSet,
        source: Source,
        request: Request,
        on_event: &'a mut dyn FnMut(Event) -> Result<(), RunError>,
    ) -> Self {
        Self {
            gear,
            source,
            request,
            on_event,
            // The input's own warnings (values outside a law's data) come first.
            warnings: gear
                .warnings
                .iter()
                .map(|w| format!("input: {w}"))
                .collect(),
        }
    }

    /// The unloaded meshing analysis (MODEL §4), when a stage needs it.
    pub(crate) fn unloaded_analysis(&mut self, geo: &Geometry) -> Result<Option<Tca>, RunError> {
        if !self.request.needs_tca() {
            return Ok(None);
        }
        let tca = crate::kinematics::analyse(self.gear, geo).map_err(RunError::Tca)?;
        self.warnings.extend(tca.warnings.iter().cloned());
        Ok(Some(tca))
    }

    /// The bending model (MODEL §5.5), when a loaded stage needs it.
    pub(crate) fn bending_model(&mut self, geo: &Geometry) -> Result<Bending, RunError> {
        let (model, info) = match self.request.needs_bending() {
            true => bending_model(self.gear, geo, &mut self.warnings, self.on_event)?,
            false => (None, None),
        };
        Ok(Bending { model, info })
    }

    /// The unworn loaded analysis (MODEL §5), when asked for.
    pub(crate) fn loaded_analysis(
        &mut self,
        geo: &Geometry,
        tca: Option<&Tca>,
        bending: &Bending,
    ) -> Result<Option<Ltca>, RunError> {
        let Some(tca) = tca.filter(|_| self.request.has(Stage::Ltca)) else {
            return Ok(None);
        };
        (self.on_event)(Event::Stage(Stage::Ltca))?;
        let model = bending.model.as_ref();
        loaded_analysis(self.gear, geo, tca, model, &mut self.warnings).map(Some)
    }

    /// The life (MODEL §7-8), when asked for.
    pub(crate) fn life(
        &mut self,
        geo: &Geometry,
        tca: Option<&Tca>,
        bending: &Bending,
    ) -> Result<Option<Life>, RunError> {
        let (Some(tca), Some(plan), true) = (
            tca,
            self.request.life.as_ref(),
            self.request.has(Stage::Wear),
        ) else {
            return Ok(None);
        };
        (self.on_event)(Event::Stage(Stage::Wear))?;
        let (gear, source, resume) = (self.gear, &self.source, self.request.resume.clone());
        let model = bending.model.as_ref();
        life(gear, source, geo, tca, model, plan, resume, self.on_event).map(Some)
    }

    /// Friction, efficiency and oil temperature of the loaded analysis (MODEL §13).
    pub(crate) fn friction(
        &mut self,
        geo: &Geometry,
        tca: Option<&Tca>,
        ltca: Option<&Ltca>,
    ) -> Result<Option<crate::friction::Thermal>, RunError> {
        let (Some(tca), Some(ltca)) = (tca, ltca) else {
            return Ok(None);
        };
        let gear = self.gear;
        let rating = crate::rating::rate(gear);
        let other = rating.loss_churning_w + rating.loss_bearings_w + rating.loss_seals_w;
        let contacts = crate::friction::MeshContacts::new(gear, geo, tca, ltca);
        crate::friction::heat_balance(
            &contacts,
            &gear.lubricant,
            &gear.friction,
            &gear.housing,
            other,
        )
        .map(|t| Some(t.with_self_locking(gear, geo, ltca)))
        .map_err(RunError::Friction)
    }

    /// The results of the run, with the ratings (MODEL §9) beside a loaded stage.
    pub(crate) fn results(
        self,
        geometry: Geometry,
        tca: Option<Tca>,
        bending: Bending,
        (ltca, thermal, safety, spectrum): (
            Option<Ltca>,
            Option<crate::friction::Thermal>,
            Option<crate::safety::SafetyTable>,
            Option<crate::spectrum::Spectrum>,
        ),
        life: Option<Life>,
        cad: Option<crate::cad::CadSolids>,
    ) -> Results {
        Results {
            thermal,
            safety,
            spectrum,
            rating: self
                .request
                .needs_bending()
                .then(|| crate::rating::rate(self.gear)),
            gear: self.gear.clone(),
            source: self.source,
            stages: self.request.stages,
            map_position: self.request.map_position,
            geometry,
            tca,
            bending: bending.info,
            ltca,
            life,
            cad,
            warnings: self.warnings,
        }
    }

    /// The CAD solids the request asks for (issue 37): worm and wheel, and after a life the
    /// wheel worn as at the asked map state (its wear step) or the last state.
    pub(crate) fn cad(
        &mut self,
        geo: &Geometry,
        tca: Option<&Tca>,
        life: Option<&Life>,
    ) -> Result<Option<crate::cad::CadSolids>, RunError> {
        let Some(request) = self.request.cad else {
            return Ok(None);
        };
        let resumed = self.request.resumed_map.take();
        let state = match (life, tca) {
            (Some(life), Some(tca)) => {
                let s = self.worn_state(life, resumed.as_ref(), request.state);
                Some((s, tca.loaded_flank))
            }
            _ => None,
        };
        let change = state.map(|(s, flank)| (s, flank, s.flank_change()));
        let worn = change.as_ref().map(|(s, flank, change)| {
            let from = crate::cad::WornFrom {
                step: s.step,
                cycles: s.cycles,
            };
            (from, *flank, change)
        });
        crate::cad::solids(self.gear, geo, request, worn)
            .map(Some)
            .map_err(RunError::Cad)
    }

    /// The life's state whose worn wheel is written: the map state of wear step `asked` (this
    /// run's, or the one a resumed life computed before its checkpoint, `resumed`), or the
    /// last (with a warning when no map state has that step).
    fn worn_state<'l>(
        &mut self,
        life: &'l Life,
        resumed: Option<&'l WearState>,
        asked: Option<usize>,
    ) -> &'l WearState {
        let last = life.maps.last().map_or(&life.end, |m| &m.state);
        let Some(step) = asked else { return last };
        let mut states = life.maps.iter().map(|m| &m.state).chain(resumed);
        match states.find(|s| s.step == step) {
            Some(s) => s,
            None => {
                let kept: Vec<String> =
                    life.maps.iter().map(|m| m.state.step.to_string()).collect();
                self.warnings.push(format!(
                    "cad: no map state at wear step {step} (the life kept steps {}); the worn \
                     wheel is the last state's, step {}",
                    kept.join(", "),
                    last.step
                ));
                last
            }
        }
    }
}

/// The bending model the gear asks for (`[bending] model`), from the cache or the FE build;
/// reported as an event, its cache warnings added to `warnings`.
pub(crate) fn bending_model(
    gear: &GearSet,
    geo: &Geometry,
    warnings: &mut Vec<String>,
    on_event: &mut dyn FnMut(Event) -> Result<(), RunError>,
) -> Result<(Option<FeBending>, Option<BendingInfo>), RunError> {
    let (built, cache_warnings) =
        crate::bending::model::build(gear, geo).map_err(RunError::Bending)?;
    warnings.extend(cache_warnings);
    let Some(BuiltBending {
        model,
        origin,
        cache_file,
        seconds,
    }) = built
    else {
        return Ok((None, None));
    };
    let info = BendingInfo {
        origin,
        cache_file,
        seconds,
    };
    on_event(Event::Bending(&info))?;
    Ok((Some(model), Some(info)))
}

/// The unworn loaded analysis (MODEL §5); its warnings added to `warnings`. With the heat
/// balance and the transmitted torque, the friction the pressures carry is at the balance's
/// oil temperature ([`crate::friction::oil_fixed_point`]).
pub(crate) fn loaded_analysis(
    gear: &GearSet,
    geo: &Geometry,
    tca: &Tca,
    bending: Option<&FeBending>,
    warnings: &mut Vec<String>,
) -> Result<Ltca, RunError> {
    let model = bending.map(|b| b as &dyn BendingModel);
    let result = crate::friction::unworn_analysis(gear, geo, tca, model).map_err(RunError::Ltca)?;
    let said = result.warnings.iter();
    warnings.extend(said.map(|w| format!("loaded analysis: {w}")));
    Ok(result)
}

/// The life (MODEL §7-8) from the unworn flank or the request's resumed state: every
/// completed state goes to `on_event`; the plan's map states and the last are kept.
#[allow(clippy::too_many_arguments)]
pub(crate) fn life(
    gear: &GearSet,
    source: &Source,
    geo: &Geometry,
    tca: &Tca,
    bending: Option<&FeBending>,
    plan: &WearPlan,
    resume: Option<WearState>,
    on_event: &mut dyn FnMut(Event) -> Result<(), RunError>,
) -> Result<Life, RunError> {
    let start = resume.unwrap_or_else(|| WearState::new(geo.wheel_flank(tca.loaded_flank)));
    let mut maps = Vec::new();
    let mut stopped: Option<RunError> = None;
    let mut on_state = |view: &StepView| -> Result<(), WearError> {
        if view.map || view.last {
            maps.push(MapState::of(view));
        }
        let life_view = LifeView {
            gear,
            source,
            geometry: geo,
            tca,
            plan,
            step: view,
        };
        on_event(Event::WearState(&life_view)).map_err(|e| {
            let message = format!("{e:#}");
            stopped = Some(e);
            WearError::Output(message)
        })
    };
    let end = crate::wear::simulate(
        gear,
        geo,
        tca,
        &LtcaSettings::from_gear(gear),
        bending.map(|b| b as &dyn BendingModel),
        plan,
        start,
        &mut on_state,
    );
    match (end, stopped) {
        (Ok(end), _) => Ok(Life {
            plan: plan.clone(),
            end,
            maps,
        }),
        (Err(_), Some(stop)) => Err(stop),
        (Err(e), None) => Err(RunError::Wear(e)),
    }
}

/// An error and its sources on one line, `error: source: source...`, each said once.
pub fn error_chain(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        // A source its error already quotes is said once.
        let said = s.to_string();
        if !text.ends_with(&said) {
            text.push_str(": ");
            text.push_str(&said);
        }
        source = s.source();
    }
    text
}
