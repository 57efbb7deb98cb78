//! The requests the life commands (`wear`, `run`, `rating`) give the runner: the life plan
//! with the command line's overrides, the checked checkpoint with --resume, the CAD solids.

use crate::args::{CadArgs, LifeArgs};
use crate::Failure;
use std::path::Path;
use wormwear::input::GearSet;

/// The file's life plan with the command-line overrides applied.
pub(crate) fn life_plan(
    gear: &GearSet,
    args: &LifeArgs,
) -> Result<wormwear::input::WearPlan, Failure> {
    args.overrides()
        .plan(gear, wormwear::runner::OverrideNames::Cli)
        .map_err(|e| Failure::Input(e.into()))
}

/// The life request of `wear` and `run`: the plan, and the checked checkpoint with --resume.
pub(crate) fn life_request(
    dir: &Path,
    gear: &GearSet,
    args: &LifeArgs,
    stages: &[wormwear::Stage],
) -> Result<wormwear::Request, Failure> {
    let plan = life_plan(gear, args)?;
    let resume = match args.resume {
        true => Some(
            wormwear::output::wear::resume_state(dir, gear, &plan)
                .map_err(|e| Failure::Input(e.into()))?,
        ),
        false => None,
    };
    let mut request = wormwear::Request::new(stages.iter().copied()).with_life(plan);
    request.resume = resume;
    Ok(request)
}

/// `request` with the CAD solids the command line asks for; with --resume and a
/// `--step-state` before the checkpoint's state, that map state's worn flank read back (the
/// resumed life does not compute it again).
pub(crate) fn with_cad(
    mut request: wormwear::Request,
    cad: &CadArgs,
    dir: &Path,
    gear: &GearSet,
) -> Result<wormwear::Request, Failure> {
    request.cad = cad.request(dir)?;
    let asked = request.cad.as_ref().and_then(|c| c.state);
    let resumed_from = request.resume.as_ref().map(|s| s.step);
    if let (Some(step), Some(from), Some(plan)) = (asked, resumed_from, &request.life) {
        if step < from {
            request.resumed_map = wormwear::output::wear::resumed_map_state(dir, gear, plan, step)
                .map_err(|e| Failure::Input(e.into()))?;
        }
    }
    Ok(request)
}

/// The request of `run` and `rating`: the stages `with_life` and the life request when the
/// file has a `[wear]` section or the command line asks for a life, else `without`.
pub(crate) fn planned_request(
    dir: &Path,
    gear: &GearSet,
    args: &LifeArgs,
    (with_life, without): (&[wormwear::Stage], &[wormwear::Stage]),
) -> Result<wormwear::Request, Failure> {
    match gear.wear.is_some() || args.overrides().asks_for_life() {
        true => life_request(dir, gear, args, with_life),
        false => Ok(wormwear::Request::new(without.iter().copied())),
    }
}
