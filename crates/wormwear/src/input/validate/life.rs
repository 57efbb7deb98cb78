//! The life plan (MODEL §7, §8): the wear steps and their control, the endurance law, the phases
//! of the schedule, the map states and the pitting mode.

use super::*;

pub(super) fn wear_plan(ck: &mut Checker, w: &WearSpec) -> Option<WearPlan> {
    let life = ck.range("wear.life_cycles", w.life_cycles, 1.0, 1e12, "cycles");
    let step = step_control(ck, w);
    let endurance = endurance(ck, w.endurance.as_ref());
    let mut phases = phases(ck, &w.phases)?;
    let pitting = pitting_mode(ck, w, &w.phases);
    let onset = pitting_onset(ck, w.pitting_onset_percent, pitting);
    if pitting == Some(Pitting::Off) {
        phases.retain(|p| matches!(p, Phase::Wear { .. }));
    }
    let (scheme, tolerance) = step_scheme(ck, w, step);
    let guard = substep_guard(ck, w.max_substep_wear_um, scheme);
    if let (Some(life), Some(StepControl::Cycles(c))) = (life, step) {
        if let Some(problem) = fixed_steps_problem(life, c) {
            ck.fail("wear.step_cycles", Number(c), problem);
        }
    }
    let (film_load, pit_depth, pitting_stress) = model_choices(ck, w);
    let damage_node_reading = node_reading(ck, w);
    let map_cycles = map_cycles(ck, w.map_cycles.as_ref());
    let (stop_at, backlash_limit) = life_stop(ck, w);
    Some(WearPlan {
        life_cycles: life?,
        step: step?,
        max_substep_removal: guard? * 1e-6,
        scheme: scheme?,
        step_tolerance: tolerance?,
        phases,
        pitting: pitting?,
        pitting_onset_share: onset? * 1e-2,
        endurance: endurance?,
        film_load: film_load?,
        pit_depth: pit_depth?,
        pitting_stress: pitting_stress?,
        damage_node_reading: damage_node_reading?,
        map_cycles: map_cycles?,
        stop_at: stop_at?,
        backlash_limit: backlash_limit?,
    })
}

/// The pitting onset share of a forecast (`wear.pitting_onset_percent`, %, default 2); refused
/// with any other pitting mode.
fn pitting_onset(ck: &mut Checker, given: Option<f64>, pitting: Option<Pitting>) -> Option<f64> {
    match given {
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
    }
}

/// The step scheme (`wear.step_scheme`, "explicit" by default or "stabilised") and the error
/// control of adaptive steps (`wear.step_tolerance`, a share, 0 to 0.5, default 0: off; refused
/// with fixed steps).
fn step_scheme(
    ck: &mut Checker,
    w: &WearSpec,
    step: Option<StepControl>,
) -> (Option<StepScheme>, Option<f64>) {
    let scheme = match w.step_scheme.as_deref() {
        None | Some("explicit") => Some(StepScheme::Explicit),
        Some("stabilised") => Some(StepScheme::Stabilised),
        Some(other) => {
            ck.fail(
                "wear.step_scheme",
                format!("\"{other}\""),
                "\"explicit\" (the published step) or \"stabilised\"",
            );
            None
        }
    };
    let tolerance = match (w.step_tolerance, step) {
        (Some(t), Some(StepControl::Cycles(_))) if t != 0.0 => {
            ck.fail(
                "wear.step_tolerance",
                t,
                "the error control sets adaptive steps: give wear.step_wear_um (its largest \
                 step), not wear.step_cycles",
            );
            None
        }
        (Some(t), _) if t != 0.0 => ck.range("wear.step_tolerance", t, 1e-4, 0.5, ""),
        _ => Some(0.0),
    };
    (scheme, tolerance)
}

/// The largest removal of a wear sub-step (`wear.max_substep_wear_um`, um; 0: off): by
/// default 5 um with the explicit step, whose stability it guards (MODEL §7.3), and off with
/// the stabilised one, which is stable without it (a guard would split its large steps into
/// sub-steps of the explicit step's size and undo what it saves).
fn substep_guard(ck: &mut Checker, given: Option<f64>, scheme: Option<StepScheme>) -> Option<f64> {
    let default = match scheme {
        Some(StepScheme::Stabilised) => 0.0,
        _ => 5.0,
    };
    match given.unwrap_or(default) {
        0.0 => Some(0.0),
        v => ck.range(
            "wear.max_substep_wear_um",
            v,
            MIN_STEP_WEAR_UM,
            1000.0,
            "um (or 0: off)",
        ),
    }
}

/// The model options of the life: the film's load, the pits' depth and the pitting stress.
fn model_choices(
    ck: &mut Checker,
    w: &WearSpec,
) -> (Option<FilmLoad>, Option<PitDepth>, Option<PittingStress>) {
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
    (film_load, pit_depth, pitting_stress)
}

/// How a node of the fatigue damage reads the stress of the cells around it.
fn node_reading(ck: &mut Checker, w: &WearSpec) -> Option<NodeReading> {
    ck.choice(
        "wear.damage_node_reading",
        w.damage_node_reading.as_deref().unwrap_or("largest"),
        &[
            ("largest", NodeReading::Largest),
            ("interpolated", NodeReading::Interpolated),
        ],
    )
}

/// Where the life stops: the criterion and the optional backlash limit (m).
fn life_stop(ck: &mut Checker, w: &WearSpec) -> (Option<LifeStop>, Option<Option<f64>>) {
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
    (stop_at, backlash_limit)
}

/// The step control: adaptive (largest removal, default 4 um) or fixed cycles.
pub(super) fn step_control(ck: &mut Checker, w: &WearSpec) -> Option<StepControl> {
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
pub(super) fn endurance(ck: &mut Checker, e: Option<&EnduranceSpec>) -> Option<Endurance> {
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
pub(super) fn phases(ck: &mut Checker, specs: &[PhaseSpec]) -> Option<Vec<Phase>> {
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
pub(super) fn map_cycles(ck: &mut Checker, list: Option<&Vec<f64>>) -> Option<Option<Vec<f64>>> {
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
pub(super) fn pitting_mode(
    ck: &mut Checker,
    w: &WearSpec,
    phases: &[PhaseSpec],
) -> Option<Pitting> {
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
