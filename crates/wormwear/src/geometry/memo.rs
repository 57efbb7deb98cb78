//! The geometries of the last few builds, kept in memory by the inputs they were generated
//! from (MODEL §2-3 are deterministic: equal inputs give the same flanks, bit for bit).
//!
//! The hobbing simulation is a large part of a short run (about 0.2 s of the 1.6 s of the 1/40
//! design's `wormwear ltca` on two cores), and the geometry does not change with the
//! conditions, the materials, the lubricant or the analysis settings other than the grid: the
//! bins of a duty cycle, the jobs of the validation study, a Python session that runs a gear
//! again and the variants of a sweep over torques or oils (those started after the first
//! build has finished, or after the sweep's FE bending models were built) all need the same
//! one. The
//! key is the whole of [`GeometryInputs`] in its exact JSON text (every float to its last bit,
//! -0 apart from 0), and [`Geometry::generate`] reads nothing else, so a kept geometry is only
//! returned for the inputs it was generated from. The store is bounded, the least recently
//! used dropped first.

use super::{Geometry, GeometryInputs};
use std::collections::VecDeque;
use std::sync::Mutex;

/// How many geometries the process keeps (each holds its grids: well under a megabyte at the
/// reference gears' default grids).
const KEPT: usize = 8;

/// The process's kept geometries.
static RECENT: Mutex<Recent> = Mutex::new(Recent::new(KEPT));

/// Geometries with their inputs' exact JSON text, the most recently used last.
pub(super) struct Recent {
    entries: VecDeque<(String, Geometry)>,
    capacity: usize,
}

/// The exact text of `inputs`: serde_json writes every float so that it reads back to the
/// same bits (the crate's `float_roundtrip` feature).
fn key(inputs: &GeometryInputs) -> Option<String> {
    serde_json::to_string(inputs).ok()
}

impl Recent {
    const fn new(capacity: usize) -> Self {
        Self {
            entries: VecDeque::new(),
            capacity,
        }
    }

    /// A copy of the kept geometry generated from `inputs`, if any (now the most recent).
    fn recall(&mut self, inputs: &GeometryInputs) -> Option<Geometry> {
        let key = key(inputs)?;
        let at = self.entries.iter().position(|(k, _)| *k == key)?;
        let entry = self.entries.remove(at)?;
        let copy = entry.1.clone();
        self.entries.push_back(entry);
        Some(copy)
    }

    /// Keeps a copy of `geometry`, generated from `inputs`, dropping the least recently used
    /// one when full.
    fn keep(&mut self, inputs: &GeometryInputs, geometry: &Geometry) {
        let Some(key) = key(inputs) else { return };
        if self.entries.iter().any(|(k, _)| *k == key) || self.capacity == 0 {
            return;
        }
        if self.entries.len() == self.capacity {
            self.entries.pop_front();
        }
        self.entries.push_back((key, geometry.clone()));
    }
}

fn recent() -> std::sync::MutexGuard<'static, Recent> {
    // A panic elsewhere while the lock was held leaves whole entries only.
    RECENT
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// A copy of the process's kept geometry generated from `inputs`, if any.
pub(super) fn recall(inputs: &GeometryInputs) -> Option<Geometry> {
    recent().recall(inputs)
}

/// Keeps a copy of `geometry`, generated from `inputs`, in the process's store.
pub(super) fn keep(inputs: &GeometryInputs, geometry: &Geometry) {
    recent().keep(inputs, geometry);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::input::GearSet;

    fn example(name: &str) -> GearSet {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
        crate::input::load(&dir.join(name)).unwrap()
    }

    /// The geometry as text: Debug writes every float so that it reads back to the same bits.
    fn text(g: &Geometry) -> String {
        format!("{g:?}")
    }

    #[test]
    fn a_kept_geometry_is_returned_only_for_its_own_inputs_and_equals_a_new_one() {
        let gear = example("gear-k-2x25.toml");
        let inputs = GeometryInputs::of(&gear, 6, 8);
        let generated = Geometry::generate(&inputs).unwrap();
        // What the geometry does not read leaves its inputs equal.
        let mut loaded = gear.clone();
        loaded.conditions.torque = crate::input::Torque::Wheel(1234.0);
        loaded.analysis.positions += 1;
        loaded.lubricant.composite_roughness *= 2.0;
        assert_eq!(GeometryInputs::of(&loaded, 6, 8), inputs);
        let mut store = Recent::new(2);
        assert!(store.recall(&inputs).is_none());
        store.keep(&inputs, &generated);
        let recalled = store.recall(&GeometryInputs::of(&loaded, 6, 8)).unwrap();
        assert_eq!(text(&recalled), text(&generated));
        // A change in the last bit of one input, the grid, or the sign of a zero is another
        // key, and that geometry differs.
        let mut moved = gear.clone();
        moved.cutting.centre_distance = f64::from_bits(gear.cutting.centre_distance.to_bits() + 1);
        let mut signed = gear.clone();
        signed.operating.offset = -gear.operating.offset;
        assert_eq!(gear.operating.offset, 0.0);
        for other in [
            GeometryInputs::of(&moved, 6, 8),
            GeometryInputs::of(&signed, 6, 8),
            GeometryInputs::of(&gear, 6, 9),
        ] {
            assert!(store.recall(&other).is_none());
        }
        let other = GeometryInputs::of(&gear, 6, 9);
        let finer = Geometry::generate(&other).unwrap();
        assert_ne!(text(&finer), text(&generated));
        // Bounded, the least recently used dropped first.
        store.keep(&other, &finer);
        assert!(store.recall(&inputs).is_some());
        let third = GeometryInputs::of(&gear, 5, 8);
        store.keep(&third, &finer);
        assert!(store.recall(&other).is_none());
        assert!(store.recall(&inputs).is_some() && store.recall(&third).is_some());
    }

    #[test]
    fn a_build_gives_the_generated_geometry_whether_kept_or_not() {
        let gear = example("gear-1x40-design.toml");
        let inputs = GeometryInputs::of(&gear, 5, 7);
        let generated = text(&Geometry::generate(&inputs).unwrap());
        for _ in 0..2 {
            let built = Geometry::build_with_grid(&gear, 5, 7).unwrap();
            assert_eq!(text(&built), generated);
        }
    }
}
