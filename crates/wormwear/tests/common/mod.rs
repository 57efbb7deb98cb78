//! Helpers shared by the integration tests.

use std::path::Path;
use wormwear::input::{self, GearSet};

/// A reference case from `examples/`, validated.
pub fn example(name: &str) -> GearSet {
    input::load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../examples")
            .join(name),
    )
    .unwrap()
}
