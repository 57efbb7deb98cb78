//! Options shared by several commands: the life overrides and the CAD (STEP) output.

use crate::Failure;
use std::path::Path;

/// Overrides of the file's [wear] section.
#[derive(clap::Args, Debug, Clone, Default)]
pub(crate) struct LifeArgs {
    /// Wheel cycles to simulate (overrides wear.life_cycles).
    #[arg(long)]
    pub(crate) cycles: Option<f64>,
    /// Fixed steps of this many wheel cycles (overrides the file's step).
    #[arg(long, conflicts_with = "step_wear_um")]
    pub(crate) step_cycles: Option<f64>,
    /// Adaptive steps removing at most this depth, um (overrides the file's step).
    #[arg(long)]
    pub(crate) step_wear_um: Option<f64>,
    /// Ignore the pitting phases of the schedule (wear all along).
    #[arg(long)]
    pub(crate) no_pitting: bool,
    /// Continue from the checkpoint in the output directory.
    #[arg(long, conflicts_with = "force")]
    pub(crate) resume: bool,
    /// Replace the life the output directory holds (its checkpoint), which is refused
    /// without it: start again from the unworn flank.
    #[arg(long)]
    pub(crate) force: bool,
}

impl LifeArgs {
    /// The library's form of the overrides.
    pub(crate) fn overrides(&self) -> wormwear::runner::LifeOverrides {
        wormwear::runner::LifeOverrides {
            cycles: self.cycles,
            step_cycles: self.step_cycles,
            step_wear_um: self.step_wear_um,
            no_pitting: self.no_pitting,
        }
    }
}

/// The CAD output: STEP solids of the worm and the wheel (and the worn wheel after a life).
#[derive(clap::Args, Debug, Clone, Default)]
pub(crate) struct CadArgs {
    /// Also write worm.step and wheel.step (and wheel_worn.step after a life): B-spline solids
    /// for CAD, in mm, in the worm frame (they assemble at the centre distance).
    #[arg(long)]
    step: bool,
    /// Teeth of the wheel's STEP solid, 1 to the wheel's (default: all): a sector about the
    /// line of centres.
    #[arg(long, requires = "step", value_name = "N")]
    step_teeth: Option<usize>,
    /// The worn wheel as at the map state of this wear step (default: the last state).
    #[arg(long, requires = "step", value_name = "STEP")]
    step_state: Option<usize>,
}

impl CadArgs {
    /// The library's request, after checking that the STEP files can be written into `dir`
    /// (before a run, so that a long life is not lost at its end).
    pub(crate) fn request(&self, dir: &Path) -> Result<Option<wormwear::cad::CadRequest>, Failure> {
        if !self.step {
            return Ok(None);
        }
        wormwear::output::cad::check_targets(dir).map_err(|e| Failure::Input(e.into()))?;
        Ok(Some(wormwear::cad::CadRequest {
            teeth: self.step_teeth,
            state: self.step_state,
        }))
    }
}
