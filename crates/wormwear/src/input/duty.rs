//! Duty cycles (load spectra, MODEL §14): the bins of torque, worm speed and time share a gear
//! runs, the share of the wheel's cycles each bin runs, and the gear at one bin.
//!
//! A gear without `[[duty_cycle]]` is the one bin of `[conditions]`; a file with one bin is
//! that operating point (the validated gear is the same value, so every result is the same
//! byte for byte). With several bins, [`GearSet::conditions`] holds the bin of the largest
//! wheel torque (the one the strength safeties are rated at, MODEL §14) and
//! [`GearSet::duty_cycle`] all of them.

use super::{Conditions, GearSet, Torque};

/// One bin of a duty cycle (MODEL §14), SI.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct DutyBin {
    /// The bin's torque and worm speed (rad/s).
    pub conditions: Conditions,
    /// Share of the running time, (0, 1]; the bins' shares sum to 1.
    pub time_share: f64,
    /// Oil temperature, K: the bin's own, else the lubricant's (with the heat balance, where
    /// the balance starts from).
    pub oil_temperature: f64,
    /// The housing's heat transfer coefficient at the bin's worm speed, W/(m^2 K): the given
    /// one, else the default at that speed (`input::validate`'s housing).
    pub heat_transfer: f64,
}

impl DutyBin {
    /// The wheel torque the bin's load stands for, N m: a wheel torque as given, a worm torque
    /// times the ratio `u` (the frictionless bound): what orders the bins by load.
    pub fn wheel_torque_bound(&self, u: f64) -> f64 {
        match self.conditions.torque {
            Torque::Wheel(t) => t,
            Torque::Worm(t) => u * t,
        }
    }
}

impl GearSet {
    /// Whether the gear runs a spectrum of several bins (`[[duty_cycle]]`, MODEL §14).
    pub fn has_spectrum(&self) -> bool {
        self.duty_cycle.len() > 1
    }

    /// The bins the gear runs: its spectrum, or the one bin of its conditions (time share 1).
    pub fn duty_bins(&self) -> Vec<DutyBin> {
        if self.has_spectrum() {
            return self.duty_cycle.clone();
        }
        vec![DutyBin {
            conditions: self.conditions.clone(),
            time_share: 1.0,
            oil_temperature: self.lubricant.temperature,
            heat_transfer: self.housing.heat_transfer,
        }]
    }

    /// The time-weighted mean worm speed of the gear's bins, rad/s (its speed for one bin):
    /// what the required hours count wheel cycles in.
    pub fn mean_worm_speed(&self) -> f64 {
        if !self.has_spectrum() {
            return self.conditions.worm_speed;
        }
        let bins = &self.duty_cycle;
        bins.iter()
            .map(|b| b.time_share * b.conditions.worm_speed)
            .sum()
    }

    /// The gear at one bin: its torque, worm speed, oil temperature (the viscosity follows the
    /// thermo-viscosity law, MODEL §6) and heat transfer, without a spectrum. The bin of a
    /// gear's own conditions gives the gear itself.
    pub fn at_bin(&self, bin: &DutyBin) -> GearSet {
        let mut gear = self.clone();
        gear.duty_cycle.clear();
        gear.conditions = bin.conditions.clone();
        if bin.oil_temperature != gear.lubricant.temperature {
            gear.lubricant = gear.lubricant.at_temperature(bin.oil_temperature);
        }
        gear.housing.heat_transfer = bin.heat_transfer;
        gear
    }
}

/// Share of the wheel's cycles each bin runs (MODEL §14): its time share times its worm speed,
/// over the sum; the shares of one bin, or of bins at one speed, are their time shares.
pub fn cycle_shares(bins: &[DutyBin]) -> Vec<f64> {
    let weights: Vec<f64> = bins
        .iter()
        .map(|b| b.time_share * b.conditions.worm_speed)
        .collect();
    let total: f64 = weights.iter().sum();
    if bins.len() == 1
        || bins
            .iter()
            .all(|b| b.conditions.worm_speed == bins[0].conditions.worm_speed)
    {
        return bins.iter().map(|b| b.time_share).collect();
    }
    weights.iter().map(|w| w / total).collect()
}

/// Index of the bin with the largest load ([`DutyBin::wheel_torque_bound`]; the first of
/// equals), for ratio `u`.
pub fn largest_load_bin(bins: &[DutyBin], u: f64) -> usize {
    let mut best = 0;
    for (k, b) in bins.iter().enumerate() {
        if b.wheel_torque_bound(u) > bins[best].wheel_torque_bound(u) {
            best = k;
        }
    }
    best
}
