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

/// Every reference case of `examples/`.
#[allow(dead_code)]
pub const EXAMPLES: [&str; 5] = [
    "gear-1x40-design.toml",
    "gear-1x40-case-a.toml",
    "gear-1x40-case-b.toml",
    "gear-1x40-case-c.toml",
    "gear-k-2x25.toml",
];
