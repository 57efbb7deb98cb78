//! A life under a load spectrum (MODEL §14): the bins a life analyses at every state, the wear
//! of one wheel cycle of the spectrum (each bin's wear of a cycle times its share of the
//! cycles), the damage loads by Miner's sum over the bins, and what a record keeps of a bin.
//!
//! Readings we adopt where MODEL §14 is silent (stated in the README and the closing note of
//! issue 56): a bin's share of the wheel's cycles is its time share times its worm speed,
//! normalised ([`crate::input::cycle_shares`]); the record's loaded-analysis figures (pressures,
//! TE, stiffness, pattern, friction) are those of the bin of the largest load, each bin's own
//! in [`BinRecord`]; the running-in plastic set and the published pits (cut above a pressure
//! limit) read that bin's analysis, the largest load being the one that indents and pits; a
//! node's damage layer is the damage-weighted mean of the bins' layers.

use super::forecast::NodeLoads;
use super::{CycleWear, StateFriction};
use crate::input::Endurance;
use crate::ltca::Ltca;
use crate::pitting::CellLoad;

/// Where a bin's loaded analysis starts at the next state: its band factor and the solver's
/// warm start (the bin of the largest load keeps the state's own fields).
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BinStart {
    #[serde(default)]
    pub band_factor: Option<f64>,
    #[serde(default)]
    pub warm: Option<crate::ltca::WarmStart>,
}

/// What a life's record keeps of one bin of its spectrum (units in the names).
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BinRecord {
    /// Share of the wheel's cycles the bin runs.
    pub cycle_share: f64,
    /// Mean worm and wheel torques of the bin's loaded analysis, N m.
    pub worm_torque_nm: f64,
    pub wheel_torque_nm: f64,
    pub max_pressure_pa: f64,
    pub pressure_patch_max_pa: f64,
    pub equivalent_pressure_max_pa: f64,
    /// p_eq,2% of the bin's analysis (MODEL §8.1), Pa (0 in records of earlier versions).
    #[serde(default)]
    pub equivalent_pressure_first_pitting_pa: f64,
    /// Largest depth the bin wears per wheel cycle, m.
    pub max_wear_per_cycle_m: f64,
    /// Volume the bin wears per wheel cycle, m^3.
    pub worn_volume_per_cycle_m3: f64,
    pub friction: StateFriction,
}

impl BinRecord {
    /// The record of a bin running `cycle_share` of the cycles, from its loaded analysis, wear
    /// of one cycle (on flank `wf`) and friction.
    pub fn of(
        cycle_share: f64,
        l: &Ltca,
        cw: &CycleWear,
        wf: &crate::geometry::WheelFlank,
        thermal: &crate::friction::Thermal,
    ) -> Self {
        Self {
            cycle_share,
            worm_torque_nm: l.worm_torque,
            wheel_torque_nm: l.wheel_torque,
            max_pressure_pa: l.max_pressure,
            pressure_patch_max_pa: l.pressure_patch_max,
            equivalent_pressure_max_pa: l.equivalent_pattern.iter().copied().fold(0.0, f64::max),
            equivalent_pressure_first_pitting_pa: l.equivalent_pressure_first_pitting,
            max_wear_per_cycle_m: cw.depth.max(),
            worn_volume_per_cycle_m3: cw.depth.integral(wf),
            friction: StateFriction::of(thermal),
        }
    }
}

/// The wear of one wheel cycle of the spectrum: the depth is the sum over the bins of their
/// cycle shares times their depths (MODEL §14); the film, loads and widths of the passage are
/// those of bin `reference` (the largest load's). `parts`: (cycle share, the bin's wear).
pub fn spectrum_cycle_wear(parts: &[(f64, &CycleWear)], reference: usize) -> CycleWear {
    let mut out = parts[reference].1.clone();
    for v in out.depth.values.iter_mut() {
        *v = 0.0;
    }
    for (share, cw) in parts {
        for (d, v) in out.depth.values.iter_mut().zip(&cw.depth.values) {
            *d += share * v;
        }
    }
    out
}

/// The damage loads of the spectrum (Miner's sum, MODEL §14): at every node the damage per
/// wheel cycle is the sum of the bins' shares times their 1 / N(p), the wear per cycle the
/// spectrum's, the damaged layer the damage-weighted mean of the bins'; the node's pressure is
/// the damage-equivalent constant one, p with 1 / N(p) the summed rate, on `curve`.
/// `parts`: (cycle share, the bin's loads).
pub fn spectrum_node_loads(parts: &[(f64, &NodeLoads)], curve: &Endurance) -> NodeLoads {
    let nodes = parts[0].1.pressure.len();
    let mut pressure = vec![0.0; nodes];
    let mut cells = vec![None; nodes];
    for k in 0..nodes {
        let (mut rate, mut wear, mut layer) = (0.0, 0.0, 0.0);
        for (share, loads) in parts {
            if let Some(c) = loads.cells[k] {
                rate += share * c.damage_rate;
                wear += share * c.wear_rate;
                layer += share * c.damage_rate * c.layer;
            }
        }
        if rate > 0.0 {
            pressure[k] = curve.pressure(1.0 / rate);
            cells[k] = Some(CellLoad {
                damage_rate: rate,
                wear_rate: wear,
                layer: layer / rate,
            });
        } else {
            pressure[k] = parts.iter().map(|p| p.1.pressure[k]).fold(0.0, f64::max);
        }
    }
    NodeLoads {
        pressure,
        cells,
        share: parts[0].1.share.clone(),
    }
}
