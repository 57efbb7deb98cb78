//! Stage 5 — wear of the bronze wheel over life (MODEL §7): Archard wear per mesh cycle on the
//! global flank grid, wear steps with the geometry updated, backlash.
//!
//! Per-cycle wear (MODEL §7.2). A wheel point M is swept once per wheel revolution by the
//! loaded band; the depth worn in that passage is (k/H) |vg| integral(p dt). On each node
//! column the loaded analysis gives, at every (position, tooth), the pressure profile across
//! the line; tooth k at wheel rotation theta2 is the reference tooth at theta2 + sigma k tau,
//! so these profiles are the history of the reference tooth over its whole engagement. Between
//! consecutive instants each instant's band moves continuously with its contact line (its
//! shape blended), and the time integral of the pressure at each node is taken by quadrature:
//! the passage is resolved whatever the number of positions (sampling p only at the positions
//! would alias, MODEL §7.2), and since the profiles come from the loaded analysis on the worn
//! flank, the band follows the wear. |vg| is the node's sliding speed at its contact moment
//! (TCA), the film and k(lambda) come from [`crate::lubrication`].
//!
//! Rooms: `cycle` the wear of one mesh cycle, `life` the life loop and its step control,
//! `state` a life's state, records and pits, `backlash` and `limits` what a state is checked
//! against, [`forecast`] the pitting forecast; here the error and the cycle labels.

mod backlash;
mod cycle;
pub mod forecast;
mod life;
mod limits;
pub mod spectrum;
mod stabilised;
mod state;

pub use backlash::*;
pub use cycle::*;
pub use life::*;
pub use limits::*;
pub use stabilised::{stabilised_removal, NodeResponse, RateMeasures};
pub use state::*;

pub use crate::input::{LifeStop, Phase, Pitting, StepControl, StepScheme, WearPlan};

/// A number of cycles for titles and messages: "180 000" below a million (thin groups of
/// three digits), "1.25 million" above.
pub fn cycles_label(cycles: f64) -> String {
    if !cycles.is_finite() {
        return format!("{cycles}");
    }
    if cycles.abs() >= 1e6 {
        let m = cycles / 1e6;
        let s = format!("{m:.3}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        return format!("{s} million");
    }
    grouped(cycles)
}

/// A finite number rounded to a whole one, in groups of three digits ("1 117 629").
pub fn grouped(value: f64) -> String {
    let digits = format!("{}", value.round().abs() as u64);
    let mut out = String::new();
    for (k, ch) in digits.chars().enumerate() {
        if k > 0 && (digits.len() - k) % 3 == 0 {
            out.push(' ');
        }
        out.push(ch);
    }
    if value < 0.0 {
        out.insert(0, '-');
    }
    out
}

/// Why a life run stopped.
#[derive(Debug, thiserror::Error)]
pub enum WearError {
    // The cause is the source (not repeated here: `{:#}` prints the chain once).
    #[error("at {cycles} cycles (step {step})")]
    Ltca {
        step: usize,
        cycles: f64,
        #[source]
        source: crate::ltca::LtcaError,
    },
    #[error("at {cycles} cycles (step {step}): heat balance")]
    Friction {
        step: usize,
        cycles: f64,
        #[source]
        source: crate::friction::FrictionError,
    },
    /// The unloaded analysis of a duty-cycle bin (counted from 1) failed.
    #[error("the unloaded analysis of duty-cycle bin {bin}")]
    Bin {
        bin: usize,
        #[source]
        source: crate::kinematics::KinematicsError,
    },
    #[error("the checkpoint does not match this gear's flank grid ({0})")]
    Checkpoint(String),
    /// A plan that could not end in a practical number of loaded analyses.
    #[error("{0}")]
    Plan(String),
    #[error("{0}")]
    Output(String),
}
