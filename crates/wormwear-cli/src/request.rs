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

/// Refuses, before any work, a `request` that would replace the life its directory holds
/// (its checkpoint) unless it continues it (--resume) or `force` says to replace it.
pub(crate) fn check_held_life(
    dir: &Path,
    request: &wormwear::Request,
    force: bool,
) -> Result<(), Failure> {
    let checkpoint = dir.join(wormwear::output::wear::CHECKPOINT);
    let replaced = wormwear::output::owned::replaced_by(&request.stages).0;
    let replaces_life = replaced.contains(&wormwear::Stage::Wear);
    if request.resume.is_some() || force || !replaces_life || !checkpoint.exists() {
        return Ok(());
    }
    let held = match wormwear::output::wear::read_checkpoint(dir) {
        Ok(Some(s)) => format!("a life (step {}, {:.0} cycles)", s.step, s.cycles),
        _ => format!("a life's checkpoint ({})", checkpoint.display()),
    };
    Err(Failure::Input(anyhow::anyhow!(
        "{} holds {held}: continue it with --resume (the same file and options), or replace \
         it with --force",
        dir.display()
    )))
}

/// The files an earlier run left in a directory that a request's run replaces
/// ([`wormwear::output::owned::replaced_by`]): removed once, when the run writes its first
/// file, so that none is read as this run's and a refused or failed run leaves them as they
/// were. Kept with --resume, which continues them.
pub(crate) struct EarlierOutputs {
    dir: std::path::PathBuf,
    stages: std::collections::BTreeSet<wormwear::Stage>,
    cleared: std::cell::Cell<bool>,
}

impl EarlierOutputs {
    pub(crate) fn of(dir: &Path, request: &wormwear::Request) -> Self {
        Self {
            dir: dir.to_path_buf(),
            stages: request.stages.clone(),
            cleared: std::cell::Cell::new(request.resume.is_some()),
        }
    }

    /// Removes them, the first time only.
    pub(crate) fn clear(&self) -> Result<(), wormwear::output::OutputError> {
        if self.cleared.replace(true) {
            return Ok(());
        }
        wormwear::output::owned::clear_earlier(&self.dir, &self.stages).map(|_| ())
    }
}
