//! wormwear — loaded tooth contact and wear of steel-worm / bronze-wheel worm gears.
//!
//! The pipeline runs one way through its stages, each a module whose result is a plain struct
//! the next one consumes (see `../shared/spec/MODEL.md` §0):
//!
//! 1. [`input`] — the validated gear file, SI units;
//! 2. [`geometry`] — worm and hob helicoids, wheel flanks by hobbing simulation (MODEL §2-3);
//! 3. [`kinematics`] — unloaded meshing analysis: gaps, kinematic error, no-load pattern,
//!    sliding velocities (MODEL §4);
//! 4. [`bending`] and [`contact`] — influence coefficients; [`ltca`] — loaded contact, load
//!    sharing, transmission error (MODEL §5);
//! 5. [`lubrication`] — film thickness and local wear coefficient (MODEL §6); [`wear`] — Archard
//!    wear over life, backlash, pitting phases (MODEL §7-8); [`traction`] — the local friction of
//!    the mixed lubrication, [`friction`] — mesh loss, efficiency and oil temperature (MODEL §13);
//! 6. [`rating`] — ISO/TR 14521 efficiency, sigma_Hm, pitting lives, wear limits (MODEL §9);
//!    [`safety`] — the safety table from the model's own results (MODEL §9.1);
//! 7. [`cad`] — worm and wheel (unworn or worn) as B-spline solids for STEP.
//!
//! [`run`] chains them for one [`Request`] and returns one [`Results`] value; [`output`]
//! writes results (summary.json, CSV, SVG, STL, report.html) atomically
//! ([`output::write_results`]); [`sweep`] runs variants of a gear in parallel;
//! [`validation`] runs the study behind VALIDATION.md.

pub mod bending;
pub mod cad;
pub mod calibration;
pub mod contact;
pub mod files;
pub mod friction;
pub mod geometry;
pub mod input;
pub mod integrity;
pub mod kinematics;
pub mod ltca;
pub mod lubrication;
pub mod output;
pub mod pattern_assistant;
pub mod pitting;
pub use output::plot;
pub mod rating;
pub mod rexs;
pub mod runner;
pub mod safety;
pub mod spectrum;
pub mod spread;
pub mod subsurface;
pub mod sweep;
pub mod traction;
pub mod validation;
pub mod wear;

pub use runner::{Event, Request, Results, RunError, Source, Stage};

/// The program that computes: the release version and a digest of the library's sources
/// (`build.rs`), e.g. "0.1.0+3f2a...". Results kept for reuse — a life's checkpoint
/// ([`output::wear::life_inputs`]), a sweep's finished variants, the validation study's runs —
/// are reused only by the same program: any change to the model's code may change them, and
/// the release version alone does not move with it.
pub const PROGRAM: &str = concat!(
    env!("CARGO_PKG_VERSION"),
    "+",
    env!("WORMWEAR_SOURCE_STAMP")
);

/// Runs the stages `request` asks for on a validated gear (MODEL §0), reporting progress to
/// `on_event` (an error from it stops the run); every stage runs the ones it needs first and
/// is skipped when nothing asked for needs it.
pub fn run(
    gear: &input::GearSet,
    source: Source,
    request: Request,
    on_event: &mut dyn FnMut(Event) -> Result<(), RunError>,
) -> Result<Results, RunError> {
    request.check(gear)?;
    let geometry = geometry::Geometry::build(gear).map_err(RunError::Geometry)?;
    request.check_geometry(gear, &geometry)?;
    let mut pipeline = runner::Pipeline::new(gear, source, request, on_event);
    let tca = pipeline.unloaded_analysis(&geometry)?;
    let bending = pipeline.bending_model(&geometry)?;
    let ltca = pipeline.loaded_analysis(&geometry, tca.as_ref(), &bending)?;
    let thermal = pipeline.friction(&geometry, tca.as_ref(), ltca.as_ref())?;
    let unworn = (tca.as_ref(), ltca.as_ref(), thermal.as_ref());
    let spectrum = pipeline.spectrum(&geometry, unworn, &bending)?;
    let life = pipeline.life(&geometry, tca.as_ref(), &bending)?;
    let analyses = (ltca.as_ref(), thermal.as_ref(), life.as_ref());
    let safety = pipeline.safety(
        &geometry,
        tca.as_ref(),
        &bending,
        analyses,
        spectrum.as_ref(),
    )?;
    let cad = pipeline.cad(&geometry, tca.as_ref(), life.as_ref())?;
    let analyses = (ltca, thermal, safety, spectrum.map(|s| s.1));
    Ok(pipeline.results(geometry, tca, bending, analyses, life, cad))
}
