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
//!    wear over life, backlash, pitting phases (MODEL §7-8);
//! 6. [`rating`] — ISO/TR 14521 efficiency, sigma_Hm, pitting lives, wear limits (MODEL §9).
//!
//! [`output`] writes results (summary.json, CSV, SVG, STL) atomically; [`validation`] runs the
//! study behind VALIDATION.md.

pub mod bending;
pub mod calibration;
pub mod contact;
pub mod geometry;
pub mod input;
pub mod integrity;
pub mod kinematics;
pub mod ltca;
pub mod lubrication;
pub mod output;
pub mod plot;
pub mod rating;
pub mod validation;
pub mod wear;
