//! Backlash with the worm blocked (MODEL §7.6): the angular gaps of both flanks over the
//! positions, and the loaded flank's growing with the material worn off it.

use super::{node_lever, StepRecord};
use crate::geometry::{FlankField, Geometry};
use crate::input::GearSet;
use crate::kinematics::{GapEvaluator, Tca};
use rayon::prelude::*;
use std::f64::consts::PI;

/// Backlash with the worm blocked (MODEL §7.6): at each position the wheel turns both ways
/// until a flank of any studied tooth touches the worm; the loaded flank's gaps grow with the
/// material worn off it.
#[derive(Debug, Clone)]
pub struct Backlash {
    /// Smallest angular gap of the unloaded opposite flank per position, rad.
    opposite: Vec<f64>,
    /// Loaded flank: angular gaps per (position, tooth, node) (TCA), rad.
    loaded: Vec<f64>,
    levers: Vec<f64>,
    teeth: usize,
    nodes: usize,
    /// Wheel reference radius r2 for the linear (tangential) value, m.
    pub reference_radius: f64,
}

/// Backlash over the positions.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct BacklashStats {
    /// Angular backlash, rad: mean, min, max over positions.
    pub mean_rad: f64,
    pub min_rad: f64,
    pub max_rad: f64,
    /// Linear (tangential at r2) mean backlash, m.
    pub linear_mean_m: f64,
}

impl Backlash {
    /// Gaps of both flanks over the TCA's positions and teeth.
    pub fn new(gear: &GearSet, geo: &Geometry, tca: &Tca) -> Self {
        let other = match tca.loaded_flank {
            crate::geometry::Flank::Left => crate::geometry::Flank::Right,
            crate::geometry::Flank::Right => crate::geometry::Flank::Left,
        };
        let ev = GapEvaluator::for_flank(gear, geo, other);
        let wf = geo.wheel_flank(other);
        let tau = 2.0 * PI / geo.teeth as f64;
        let opposite: Vec<f64> = tca
            .positions
            .par_iter()
            .map(|pos| {
                let mut best = f64::INFINITY;
                for &k in &tca.teeth {
                    let offset = tca.sigma * k as f64 * tau;
                    for p in &wf.nodes {
                        best = best.min(ev.angular(
                            p.r,
                            p.theta + offset,
                            p.z,
                            pos.theta2,
                            pos.theta1,
                        ));
                    }
                }
                best
            })
            .collect();
        let lwf = geo.wheel_flank(tca.loaded_flank);
        Self {
            opposite,
            loaded: tca.node_gaps.clone(),
            levers: (0..lwf.nodes.len()).map(|k| node_lever(lwf, k)).collect(),
            teeth: tca.teeth.len(),
            nodes: lwf.nodes.len(),
            reference_radius: gear.wheel_reference_radius(),
        }
    }

    /// Backlash per position with `removal` (m, normal) worn off the loaded flank, rad.
    pub fn per_position(&self, removal: &FlankField) -> Vec<f64> {
        // The removal's angle at each node, the same for every position and tooth.
        let angle: Vec<f64> = (0..self.nodes)
            .map(|k| removal.values[k] / self.levers[k])
            .collect();
        self.opposite
            .par_iter()
            .enumerate()
            .map(|(n, opp)| {
                let mut best = f64::INFINITY;
                for t in 0..self.teeth {
                    let base = (n * self.teeth + t) * self.nodes;
                    let loaded = &self.loaded[base..base + self.nodes];
                    for (g, a) in loaded.iter().zip(&angle) {
                        best = best.min(g + a);
                    }
                }
                best + opp
            })
            .collect()
    }

    /// Mean, min, max over positions and the linear mean at r2.
    pub fn stats(&self, removal: &FlankField) -> BacklashStats {
        self.stats_of(&self.per_position(removal))
    }

    /// [`Self::stats`] of the backlash per position `v` ([`Self::per_position`]), rad.
    pub fn stats_of(&self, v: &[f64]) -> BacklashStats {
        let mean = v.iter().sum::<f64>() / v.len().max(1) as f64;
        BacklashStats {
            mean_rad: mean,
            min_rad: v.iter().copied().fold(f64::INFINITY, f64::min),
            max_rad: v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            linear_mean_m: mean * self.reference_radius,
        }
    }
}

/// Backlash increase of the records at `cycles`, linear between records (m); None beyond them.
pub fn backlash_at(records: &[StepRecord], cycles: f64) -> Option<f64> {
    let k = records.iter().position(|r| r.cycles >= cycles)?;
    if k == 0 {
        return Some(records[0].backlash_increase_m);
    }
    let (a, b) = (&records[k - 1], &records[k]);
    let t = if b.cycles > a.cycles {
        (cycles - a.cycles) / (b.cycles - a.cycles)
    } else {
        1.0
    };
    Some(a.backlash_increase_m + t * (b.backlash_increase_m - a.backlash_increase_m))
}
