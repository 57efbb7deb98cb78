//! Duty cycles on the unworn gear (MODEL §14): each bin's unloaded and loaded analyses, friction
//! and wear of a cycle, and the spectrum's figures — the energy-weighted efficiency, the bins'
//! shares of the wear and of the pitting damage, Miner's sum of the damage over the bins and the
//! damage-equivalent pressure S_H reads, the hottest bin S_T reads.
//!
//! Pitting reads an area (MODEL §8.1 "Which p_eq decides"): at each cell of the flank grid
//! Miner's sum over the bins of the cell's equivalent pressures gives the constant pressure of
//! the same life, and S_H reads that map's p_eq,2%, exceeded on 2 % of the active flank (the
//! one operating point's figure for a spectrum of identical bins); its largest cell is shown
//! beside. The bins' damage shares are Miner's over their own p_eq,2%. The life resolves the
//! damage node by node ([`crate::wear::spectrum`]).
//!
//! The bins' shares of the wheel's cycles are their time shares times their worm speeds,
//! normalised ([`crate::input::cycle_shares`]). A life under the spectrum is
//! [`crate::wear::spectrum`]'s.

use crate::friction::{FrictionError, MeshContacts, Thermal};
use crate::geometry::Geometry;
use crate::input::{cycle_shares, largest_load_bin, Endurance, FilmLoad, GearSet};
use crate::kinematics::Tca;
use crate::ltca::{BendingModel, Ltca};
use crate::wear::CycleWear;

/// One bin analysed on the unworn gear: the gear at the bin, its analyses, friction (with its
/// heat balance's oil temperature when the gear has one) and wear of one wheel cycle.
#[derive(Debug, Clone)]
pub struct BinRun {
    pub gear: GearSet,
    pub tca: Tca,
    pub ltca: Ltca,
    pub thermal: Thermal,
    pub cycle: CycleWear,
}

/// Why a bin could not be analysed (bins counted from 1).
#[derive(Debug, thiserror::Error)]
pub enum SpectrumError {
    #[error("duty-cycle bin {bin}: unloaded meshing analysis")]
    Tca {
        bin: usize,
        #[source]
        source: crate::kinematics::KinematicsError,
    },
    #[error("duty-cycle bin {bin}: loaded tooth contact analysis")]
    Ltca {
        bin: usize,
        #[source]
        source: crate::ltca::LtcaError,
    },
    #[error("duty-cycle bin {bin}: heat balance")]
    Friction {
        bin: usize,
        #[source]
        source: FrictionError,
    },
}

impl SpectrumError {
    /// An input problem (a bin whose heat balance has no steady state), as the run's own
    /// stages count them.
    pub fn is_input(&self) -> bool {
        matches!(self, SpectrumError::Friction { .. })
    }
}

/// The bins of a spectrum analysed on the unworn gear (MODEL §14): the bin of the largest load
/// is `reference` (the gear's own conditions: its unloaded and loaded analyses and friction),
/// each other bin is analysed at its torque, speed and oil temperature with the bending model
/// `bending`; each bin's wear of a cycle reads the film load `film_load`.
pub fn run_bins(
    gear: &GearSet,
    geo: &Geometry,
    reference: (&Tca, &Ltca, &Thermal),
    bending: Option<&dyn BendingModel>,
    film_load: FilmLoad,
) -> Result<Vec<BinRun>, SpectrumError> {
    let bins = gear.duty_bins();
    let largest = largest_load_bin(&bins, gear.ratio());
    let mut runs = Vec::new();
    for (k, bin) in bins.iter().enumerate() {
        let at = gear.at_bin(bin);
        let (tca, ltca, thermal) = match k == largest {
            true => (
                reference.0.clone(),
                reference.1.clone(),
                reference.2.clone(),
            ),
            false => analyse_bin(&at, geo, bending, k + 1)?,
        };
        let cycle = cycle_wear(&at, geo, (&tca, &ltca, &thermal), film_load);
        runs.push(BinRun {
            gear: at,
            tca,
            ltca,
            thermal,
            cycle,
        });
    }
    Ok(runs)
}

/// The unloaded and loaded analyses and the friction of one bin's gear `at` (bin `bin`,
/// counted from 1).
fn analyse_bin(
    at: &GearSet,
    geo: &Geometry,
    bending: Option<&dyn BendingModel>,
    bin: usize,
) -> Result<(Tca, Ltca, Thermal), SpectrumError> {
    let tca =
        crate::kinematics::analyse(at, geo).map_err(|source| SpectrumError::Tca { bin, source })?;
    let ltca = crate::friction::unworn_analysis(at, geo, &tca, bending)
        .map_err(|source| SpectrumError::Ltca { bin, source })?;
    let rating = crate::rating::rate(at);
    let other = rating.loss_churning_w + rating.loss_bearings_w + rating.loss_seals_w;
    let contacts = MeshContacts::new(at, geo, &tca, &ltca);
    let thermal =
        crate::friction::heat_balance(&contacts, &at.lubricant, &at.friction, &at.housing, other)
            .map_err(|source| SpectrumError::Friction { bin, source })?;
    Ok((tca, ltca, thermal))
}

/// A bin's wear of one wheel cycle (MODEL §7.2), its film at the heat balance's oil
/// temperature when the gear has one.
fn cycle_wear(
    at: &GearSet,
    geo: &Geometry,
    (tca, ltca, thermal): (&Tca, &Ltca, &Thermal),
    film_load: FilmLoad,
) -> CycleWear {
    if at.housing.balance {
        let mut hot = at.clone();
        hot.lubricant = at.lubricant.at_temperature(thermal.oil_temperature_k);
        return crate::wear::per_cycle(&hot, geo, tca, ltca, film_load);
    }
    crate::wear::per_cycle(at, geo, tca, ltca, film_load)
}

/// One bin's figures on the unworn gear (units in the names; bins counted from 1).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SpectrumBin {
    pub bin: usize,
    /// Mean torques of the bin's loaded analysis, N m.
    pub worm_torque_nm: f64,
    pub wheel_torque_nm: f64,
    pub worm_speed_rpm: f64,
    /// Share of the running time, and of the wheel's cycles.
    pub time_share: f64,
    pub cycle_share: f64,
    pub oil_temperature_c: f64,
    pub input_power_w: f64,
    pub output_power_w: f64,
    pub mesh_loss_w: f64,
    pub total_loss_w: f64,
    pub mesh_efficiency: f64,
    pub total_efficiency: f64,
    pub max_pressure_pa: f64,
    pub pressure_patch_max_pa: f64,
    pub equivalent_pressure_max_pa: f64,
    /// p_eq,2% of the bin's loaded analysis (MODEL §8.1), Pa: what its damage share reads.
    pub equivalent_pressure_first_pitting_pa: f64,
    pub max_wear_per_cycle_m: f64,
    pub worn_volume_per_cycle_m3: f64,
    /// The bin's share of the spectrum's worn volume per wheel cycle.
    pub wear_share: f64,
    /// The bin's share of the pitting damage of Miner's sum over the bins' p_eq,2%.
    pub damage_share: f64,
    /// Wheel cycles to first pitting at the bin's p_eq,2% alone (the pressure–life curve,
    /// MODEL §8; None: no pressure).
    pub pitting_life_cycles: Option<f64>,
}

/// The spectrum's figures on the unworn gear (MODEL §14).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Spectrum {
    pub bins: Vec<SpectrumBin>,
    /// The bin of the largest load (S_F and S_delta, and the analysis the other outputs show)
    /// and the hottest (S_T), counted from 1.
    pub largest_load_bin: usize,
    pub hottest_bin: usize,
    /// The time-weighted mean worm speed, rpm: what the required hours count wheel cycles in.
    pub mean_worm_speed_rpm: f64,
    /// Energy-weighted efficiencies: output energy over input energy over the running time.
    pub mesh_efficiency: f64,
    pub total_efficiency: f64,
    /// The damage-equivalent pressure exceeded on 2 % of the active flank (MODEL §8.1, §14):
    /// at each cell Miner's sum over the bins of its equivalent pressures gives the constant
    /// pressure of the same life on the curve; its p_eq,2%, Pa, and the wheel cycles to first
    /// pitting there (None: no damage). What S_H reads.
    pub equivalent_pressure_pa: f64,
    pub pitting_life_cycles: Option<f64>,
    /// The largest cell's damage-equivalent pressure (an edge's, where the flow pressure
    /// binds), Pa: shown beside.
    pub equivalent_pressure_max_pa: f64,
}

/// The spectrum's figures from its bins' runs (`runs` in the gear's bin order) with the
/// pressure–life curve `curve` (MODEL §8, §14).
pub fn summarise(gear: &GearSet, geo: &Geometry, runs: &[BinRun], curve: &Endurance) -> Spectrum {
    let bins = gear.duty_bins();
    let shares = cycle_shares(&bins);
    let wf = geo.wheel_flank(runs[0].tca.loaded_flank);
    let volumes: Vec<f64> = runs.iter().map(|r| r.cycle.depth.integral(wf)).collect();
    let worn: f64 = shares.iter().zip(&volumes).map(|(c, v)| c * v).sum();
    let first_pitting: Vec<f64> = runs
        .iter()
        .map(|r| r.ltca.equivalent_pressure_first_pitting)
        .collect();
    let parts: Vec<(f64, f64)> = shares
        .iter()
        .copied()
        .zip(first_pitting.iter().copied())
        .collect();
    let rate = miner_rate(&parts, curve);
    let equivalent = damage_equivalent_map(wf, runs, &shares, curve);
    let hottest = (0..runs.len())
        .max_by(|&a, &b| {
            let t = |k: usize| runs[k].thermal.oil_temperature_k;
            t(a).total_cmp(&t(b)).then(b.cmp(&a))
        })
        .unwrap_or(0);
    let mut spectrum_bins = Vec::new();
    for (k, ((run, bin), share)) in runs.iter().zip(&bins).zip(&shares).enumerate() {
        let e = &run.thermal.efficiency;
        let p_eq = first_pitting[k];
        spectrum_bins.push(SpectrumBin {
            bin: k + 1,
            worm_torque_nm: run.ltca.worm_torque,
            wheel_torque_nm: run.ltca.wheel_torque,
            worm_speed_rpm: bin.conditions.worm_speed * 30.0 / std::f64::consts::PI,
            time_share: bin.time_share,
            cycle_share: *share,
            oil_temperature_c: run.thermal.oil_temperature_k - 273.15,
            input_power_w: e.output_power_w + e.total_loss_w(),
            output_power_w: e.output_power_w,
            mesh_loss_w: e.mesh_loss_w,
            total_loss_w: e.total_loss_w(),
            mesh_efficiency: e.mesh_efficiency,
            total_efficiency: e.total_efficiency,
            max_pressure_pa: run.ltca.max_pressure,
            pressure_patch_max_pa: run.ltca.pressure_patch_max,
            equivalent_pressure_max_pa: run.ltca.equivalent_pressure_max,
            equivalent_pressure_first_pitting_pa: p_eq,
            max_wear_per_cycle_m: run.cycle.depth.max(),
            worn_volume_per_cycle_m3: volumes[k],
            wear_share: if worn > 0.0 {
                share * volumes[k] / worn
            } else {
                0.0
            },
            damage_share: if rate > 0.0 {
                share / curve.life(p_eq) / rate
            } else {
                0.0
            },
            pitting_life_cycles: Some(curve.life(p_eq)).filter(|n| n.is_finite()),
        });
    }
    let energy = |f: &dyn Fn(&SpectrumBin) -> f64| -> f64 {
        spectrum_bins.iter().map(|b| b.time_share * f(b)).sum()
    };
    let output = energy(&|b| b.output_power_w);
    Spectrum {
        largest_load_bin: largest_load_bin(&bins, gear.ratio()) + 1,
        hottest_bin: hottest + 1,
        mean_worm_speed_rpm: gear.mean_worm_speed() * 30.0 / std::f64::consts::PI,
        mesh_efficiency: output / energy(&|b| b.output_power_w + b.mesh_loss_w),
        total_efficiency: output / energy(&|b| b.input_power_w),
        equivalent_pressure_pa: equivalent.first_pitting,
        pitting_life_cycles: Some(curve.life(equivalent.first_pitting)).filter(|n| n.is_finite()),
        equivalent_pressure_max_pa: equivalent.largest,
        bins: spectrum_bins,
    }
}

/// The duty cycle's damage-equivalent pressures over the flank (MODEL §8.1, §14): p_eq,2% and
/// the largest cell's, Pa.
struct DamageEquivalent {
    first_pitting: f64,
    largest: f64,
}

/// At each cell of the flank grid, Miner's sum over the bins (`shares` of the cycles) of the
/// cell's equivalent pressure in each bin's loaded analysis, as the constant pressure of the
/// same life on `curve`; its p_eq,2% and its largest.
fn damage_equivalent_map(
    wf: &crate::geometry::WheelFlank,
    runs: &[BinRun],
    shares: &[f64],
    curve: &Endurance,
) -> DamageEquivalent {
    let cells = wf.cell_area.len();
    let map: Vec<f64> = (0..cells)
        .map(|c| {
            let parts: Vec<(f64, f64)> = shares
                .iter()
                .zip(runs)
                .map(|(share, r)| {
                    (
                        *share,
                        r.ltca.equivalent_pattern.get(c).copied().unwrap_or(0.0),
                    )
                })
                .collect();
            let rate = miner_rate(&parts, curve);
            if rate > 0.0 {
                curve.pressure(1.0 / rate)
            } else {
                0.0
            }
        })
        .collect();
    DamageEquivalent {
        first_pitting: crate::pitting::exceeded_on_share(
            &map,
            &wf.cell_area,
            &wf.active,
            crate::pitting::FIRST_PITTING_SHARE,
        ),
        largest: map.iter().copied().fold(0.0, f64::max),
    }
}

/// Miner's damage per wheel cycle of `parts` (cycle share, pressure Pa) on `curve`: the sum
/// of c_b / N(p_b) (MODEL §8, §14).
pub fn miner_rate(parts: &[(f64, f64)], curve: &Endurance) -> f64 {
    parts.iter().map(|(c, p)| c / curve.life(*p)).sum()
}
