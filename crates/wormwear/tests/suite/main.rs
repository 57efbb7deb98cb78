//! The library's integration tests, one module per subject, built as one test binary: each
//! integration test file was its own binary linking the whole library (about 3 s of the 2-core
//! box's build apiece, 33 of them), and each ran only after the one before had finished its
//! slowest test. Run one subject with `cargo test -p wormwear --test suite plastic::`, its
//! ignored validations with `... --test suite plastic:: -- --ignored`. The heavy validations
//! (`#[ignore = "heavy validation: ..."]`: refinement and tolerance studies, long lives) are
//! left out of the test command to keep it within CI's 15 minutes; `scripts/validate-heavy`
//! runs them all with the release profile.

mod common;

mod basis;
mod bending_model;
mod cad;
mod duty_cycle;
mod edges;
mod fe;
mod fidelity;
mod friction;
mod hertz;
mod input_fuzz;
mod input_validation;
mod ltca;
mod pattern_assistant;
mod pitting_forecast;
mod plastic;
mod rating;
mod rexs;
mod root_stress;
mod running_in;
mod safety;
mod spread;
mod subsurface;
mod sweep;
mod tca;
mod torque_balance;
mod wear;
mod wheel_fe;
mod wheel_generation;
mod wheel_shaft;
mod workspace;
mod worm_fe;
mod worm_profiles;
