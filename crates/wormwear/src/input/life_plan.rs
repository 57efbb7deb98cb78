//! The life plan of the `[wear]` section, checked (MODEL §7, §8): the step control and scheme,
//! the phases of the schedule, the pressure-life curve, the pitting mode and the wear limits.

/// How the cycles of a wear step are chosen (MODEL §7.3).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum StepControl {
    /// Fixed number of wheel cycles per step.
    Cycles(f64),
    /// Adaptive: each step removes at most this depth, m.
    MaxRemoval(f64),
}

/// How a wear step's removal follows from the wear per cycle (MODEL §7.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum StepScheme {
    /// The published step: each node removes the step's cycles times its own wear per cycle,
    /// the geometry frozen (explicit Euler); stable for steps removing up to ~10 um.
    Explicit,
    /// The explicit step with the flank's node-scale response to the removal taken at the
    /// step's end (linearly implicit; `wear::stabilised`): the same worn volume, redistributed
    /// where the step would roughen the flank at the grid's scale; stable for larger steps.
    Stabilised,
}

/// A phase of the life schedule (MODEL §8).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Phase {
    /// Wear until the given cycles.
    Wear { until: f64 },
    /// Pitting until the given cycles: cells above the pressure limit (Pa; None: from the
    /// endurance curve at the phase's duration times 1 + margin) are pitted, no wear.
    Pitting {
        until: f64,
        pressure_limit: Option<f64>,
        margin: f64,
    },
}

/// Power-law pressure-life curve p_lim(N) = p_ref (N / (f N_ref))^-exponent (Pa, cycles),
/// with f the curve's position within its scatter band as a factor on the life axis.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Endurance {
    pub reference_pressure: f64,
    pub reference_cycles: f64,
    pub exponent: f64,
    /// Factor on the life axis (1: the fitted curve; < 1 towards the band's lower edge).
    #[serde(default = "one")]
    pub life_factor: f64,
}

fn one() -> f64 {
    1.0
}

impl Endurance {
    /// CuSn12 disc-roller fit of MODEL §8: 425 MPa at 11e6 cycles, exponent 0.176.
    pub const DEFAULT: Endurance = Endurance {
        reference_pressure: 425e6,
        reference_cycles: 11e6,
        exponent: 0.176,
        life_factor: 1.0,
    };

    /// The lives the curve rests on, cycles: the CuSn12 fit's points span 0.6e6 to 11e6 cycles
    /// (MODEL §8), the same span relative to the reference for a curve given as an input, on
    /// the life axis moved by the life factor. Outside it p_lim is an extrapolation.
    pub fn data_span(&self) -> (f64, f64) {
        let reference = self.life_factor * self.reference_cycles;
        (reference * 0.6e6 / 11e6, reference)
    }

    /// Endurance pressure for a life of n cycles, Pa.
    pub fn pressure(&self, n: f64) -> f64 {
        self.reference_pressure
            * (n / (self.life_factor * self.reference_cycles)).powf(-self.exponent)
    }
}

/// Line load w of the film-thickness formula at a passage (MODEL §6, §12 h).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FilmLoad {
    /// The load per unit length of contact line from the loaded analysis (published model).
    LoadedAnalysis,
    /// Refinement: w floored at the Hertz load of the band's peak pressure, 2 pi R p0^2 / E'
    /// (a band cut short by an edge carries little load per length but is no thicker a film
    /// for that); thins the film where the band is cut.
    HertzPeakFloor,
}

/// Depth of the pits cut at the start of a pitting phase (MODEL §8, §12 g).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PitDepth {
    /// 0.78 a with a the local Hertz half-width of the line contact (local line load and
    /// relative radius; published model).
    Hertz,
    /// Refinement: 0.78 times the half-width of the loaded band of the loaded analysis (on a
    /// worn, conforming flank much wider than Hertz's).
    LoadedBand,
}

/// The stress the fatigue damage of the `damage` and `forecast` pitting modes reads
/// (MODEL §8.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PittingStress {
    /// The equivalent pressure max tau_1 / 0.300 below the flank, pits as deep as its
    /// maximum (default).
    PrincipalShear,
    /// The orthogonal shear max |tau_xz| / 0.25 below the flank, pits as deep as its maximum.
    OrthogonalShear,
    /// The surface pressure of the loaded pattern, pits `pit_depth` deep (the criterion before
    /// MODEL §8.1).
    SurfacePressure,
}

/// How a flank node reads the stress of the fatigue damage from the grid cells around it
/// (MODEL §8.1; `damage` and `forecast` pitting).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum NodeReading {
    /// The largest of its (up to four) cells, as the published pitting cut reads the pattern
    /// (default): a peak one cell row wide reaches two rows of nodes at full height.
    Largest,
    /// The mean of its cells: the cell-centred field interpolated to the node, the stress at
    /// the node's own place (the pit depth still the largest cell's).
    Interpolated,
}

impl PittingStress {
    /// The sub-surface criterion of the loaded analysis (principal shear for the surface
    /// pressure, whose equivalent pressure is then only reported).
    pub fn criterion(self) -> crate::subsurface::Criterion {
        match self {
            PittingStress::OrthogonalShear => crate::subsurface::Criterion::OrthogonalShear,
            _ => crate::subsurface::Criterion::PrincipalShear,
        }
    }
}

/// How pitting enters a life (MODEL §8 beyond the schedule).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Pitting {
    /// The published coupling: at the start of each pitting phase of the schedule the pits
    /// are cut where the loaded pattern exceeds the phase's limit; no wear in the phase.
    Schedule,
    /// No pitting: the schedule's pitting phases are dropped.
    Off,
    /// Pits from the fatigue damage of every flank node ([`crate::pitting`]): a node pits
    /// when its damage reaches 1, in any phase; the schedule's pitting phases only stop the
    /// wear. With the phases a forecast found it repeats the forecast.
    Damage,
    /// Pits from the damage as with `Damage`, and the phases found from them: a pit forming
    /// in a wear phase starts a pitting phase (no wear), which ends when its pits re-enter
    /// contact.
    Forecast,
}

/// Which wear limit ends a life before its cycles (MODEL §9 (a), (d)); the pointed tip ends
/// it in any case (no tooth is left to wear past it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LifeStop {
    /// The wheel tooth's tip is pointed: flank loss delta_Wn = m_x cos(gamma) (pi/2 -
    /// 2 tan(alpha_0)) (default).
    PointedTip,
    /// The backlash limit: the plan's `backlash_limit` (default: the standard's limit (d),
    /// flank loss 0.3 m_x cos(gamma)).
    BacklashLimit,
}

/// The most states a life with fixed steps may take (life cycles over step cycles): a plan
/// beyond it would run for days; adaptive steps are bounded by [`MIN_STEP_WEAR_UM`].
pub const MAX_LIFE_STATES: f64 = 1e5;
/// The smallest adaptive step and sub-step removal, um (a life of a millimetre of wear in
/// steps this small is 20 000 states).
pub const MIN_STEP_WEAR_UM: f64 = 0.05;
/// The most phases a schedule may list.
pub const MAX_PHASES: usize = 100;
/// The most map states a life may ask for (each writes about six files: maps and tables).
pub const MAX_MAP_STATES: usize = 200;

/// Why a fixed-step life is too long to run (None: it is not): the message after the value.
pub fn fixed_steps_problem(life_cycles: f64, step_cycles: f64) -> Option<String> {
    let states = life_cycles / step_cycles;
    (states > MAX_LIFE_STATES).then(|| {
        format!(
            "a life of {life_cycles:e} cycles in steps of {step_cycles:e} is {states:.3e} states, \
             more than the {MAX_LIFE_STATES:e} a run may take: give at least {:e} cycles per \
             step, or adaptive steps (step_wear_um)",
            life_cycles / MAX_LIFE_STATES
        )
    })
}

/// Life simulation plan.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct WearPlan {
    /// Wheel cycles to simulate.
    pub life_cycles: f64,
    pub step: StepControl,
    /// Stability guard: largest removal of one sub-step, m (0: no guard).
    pub max_substep_removal: f64,
    /// How a step's removal follows from the wear per cycle.
    pub scheme: StepScheme,
    /// Error control of adaptive steps: the largest local error of a step, as a share of the
    /// worn volume, the largest patch-mean wear and the backlash so far (0: off;
    /// `wear::stabilised`).
    pub step_tolerance: f64,
    /// Phase schedule (empty: wear all along).
    pub phases: Vec<Phase>,
    /// Schedule, off, damage, or forecast.
    pub pitting: Pitting,
    /// Forecast: share of the active flank whose damage must have reached 1 for a pitting
    /// phase to start (default 0.02; 0: the first node).
    pub pitting_onset_share: f64,
    pub endurance: Endurance,
    /// Line load of the film formula.
    pub film_load: FilmLoad,
    /// Depth of the pits of a pitting phase.
    pub pit_depth: PitDepth,
    /// The stress of the fatigue damage (`damage`, `forecast`).
    pub pitting_stress: PittingStress,
    /// How a node reads that stress from its cells (`damage`, `forecast`).
    pub damage_node_reading: NodeReading,
    /// Cycles at which the life stops for a state whose maps are written (steps are cut
    /// there); None: the states 0, 1, 2, 4, 8, ...
    pub map_cycles: Option<Vec<f64>>,
    /// Which wear limit ends the life early.
    pub stop_at: LifeStop,
    /// Backlash limit: increase of the tangential backlash at r2, m (None: the standard's
    /// limit (d)).
    pub backlash_limit: Option<f64>,
}

impl WearPlan {
    /// A plan of `life_cycles` with the defaults of a `[wear]` section that gives nothing
    /// else: adaptive 4 um steps, 5 um guard, no schedule, the published model's choices.
    pub fn with_life(life_cycles: f64) -> Self {
        Self {
            life_cycles,
            step: StepControl::MaxRemoval(4e-6),
            max_substep_removal: 5e-6,
            scheme: StepScheme::Explicit,
            step_tolerance: 0.0,
            phases: Vec::new(),
            pitting: Pitting::Schedule,
            pitting_onset_share: 0.02,
            endurance: Endurance::DEFAULT,
            film_load: FilmLoad::LoadedAnalysis,
            pit_depth: PitDepth::Hertz,
            pitting_stress: PittingStress::PrincipalShear,
            damage_node_reading: NodeReading::Largest,
            map_cycles: None,
            stop_at: LifeStop::PointedTip,
            backlash_limit: None,
        }
    }
}
