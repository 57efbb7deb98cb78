//! Helpers shared by the integration tests.

use std::path::Path;
use wormwear::input::{self, GearSet};

/// A reference case from `examples/`, validated.
#[allow(dead_code)]
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

/// A test that cannot run without an optional independent reader: says so on stderr and, when
/// the runner asks for it (`WORMWEAR_SKIP_LOG`, set by `scripts/test-all`), appends a line to
/// that file so that the run's summary lists it.
#[allow(dead_code)]
pub fn skipped(test: &str, reason: &str) {
    eprintln!("SKIPPED: {reason}");
    if let Some(path) = std::env::var_os("WORMWEAR_SKIP_LOG").filter(|p| !p.is_empty()) {
        use std::io::Write;
        if let Ok(mut f) = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
        {
            let _ = writeln!(f, "{test}: {reason}");
        }
    }
}

/// A gear ready for life runs: geometry and unloaded analysis built once.
#[allow(dead_code)]
pub struct Bench {
    pub g: GearSet,
    pub geo: wormwear::geometry::Geometry,
    pub tca: wormwear::kinematics::Tca,
}

#[allow(dead_code)]
impl Bench {
    pub fn new(g: &GearSet) -> Self {
        let geo = wormwear::geometry::Geometry::build(g).unwrap();
        let tca = wormwear::kinematics::analyse(g, &geo).unwrap();
        Self {
            g: g.clone(),
            geo,
            tca,
        }
    }

    /// Runs `plan` without bending from `start` (None: unworn), calling `on_state` after
    /// every state.
    pub fn simulate(
        &self,
        plan: &wormwear::wear::WearPlan,
        start: Option<wormwear::wear::WearState>,
        on_state: &mut dyn FnMut(
            &wormwear::wear::StepView,
        ) -> Result<(), wormwear::wear::WearError>,
    ) -> Result<wormwear::wear::WearState, wormwear::wear::WearError> {
        let wf = self.geo.wheel_flank(self.tca.loaded_flank);
        wormwear::wear::simulate(
            &self.g,
            &self.geo,
            &self.tca,
            &wormwear::ltca::LtcaSettings::from_gear(&self.g),
            None,
            plan,
            start.unwrap_or_else(|| wormwear::wear::WearState::new(wf)),
            on_state,
        )
    }
}

/// The design example's text with `lines` added at the start of its `[section]`.
#[allow(dead_code)]
pub fn design_with(section: &str, lines: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/gear-1x40-design.toml");
    let text = std::fs::read_to_string(path).unwrap();
    text.replacen(
        &format!("[{section}]\n"),
        &format!("[{section}]\n{lines}\n"),
        1,
    )
}
