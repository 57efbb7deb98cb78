//! Stage 5a — friction, mesh power loss, efficiency and oil temperature (MODEL §13).
//!
//! Mixed lubrication at every loaded cell of every position of the loaded analysis
//! ([`crate::traction`]: Greenwood & Tripp's asperity share at the central film, Eyring's film
//! shear bounded by the limiting shear, boundary friction on the asperities). The mesh loss is
//! the cycle mean of sum mu p |v_g| S over the cells; with the no-load, bearing and seal losses
//! of MODEL §9 it gives the efficiency, and with the housing's heat transfer the steady oil
//! temperature: the fixed point temperature -> viscosity -> film -> friction -> loss
//! ([`heat_balance`]).
//!
//! The loaded analysis carries the friction's moments (MODEL §5.2: the transmitted torque,
//! [`crate::ltca`]); here the same local law is evaluated on its pressures at any oil
//! temperature. SI units throughout (Pa, m, m/s, W, K).

use crate::geometry::Geometry;
use crate::input::{FrictionLaw, GearSet, Housing, Lubricant};
use crate::kinematics::Tca;
use crate::ltca::{cell_sliding, FilmGeometry, FrictionInputs, Ltca};
use crate::lubrication::LineContact;
pub use crate::traction::LocalFriction;
use rayon::prelude::*;

mod backdriving;
mod flank;
pub use backdriving::{FrictionArms, SelfLocking};
use flank::FlankGrid;

/// Errors of the heat balance; each names the input that decides it.
#[derive(Debug, thiserror::Error)]
pub enum FrictionError {
    #[error(
        "housing.cooler_w = {cooler:.1} W removes more than the gear loses at the ambient \
         temperature ({loss:.1} W): the oil would be colder than the air around the housing (a \
         cooler held at a temperature is lubricant.temperature = \"fixed\"); give a cooler of \
         at most the loss, or none (0)"
    )]
    CoolerExceedsLoss { cooler: f64, loss: f64 },
    #[error(
        "no steady oil temperature below {limit_c:.0} C: at that temperature the gear still \
         loses {loss:.0} W and the housing (housing.area_m2 = {area:.3} m^2, \
         housing.heat_transfer_w_m2k = {coefficient:.1} W/(m^2 K)) with its cooler rejects \
         {rejected:.0} W; enlarge the area or the coefficient, or give a cooler \
         (housing.cooler_w)"
    )]
    NoEquilibrium {
        limit_c: f64,
        loss: f64,
        rejected: f64,
        area: f64,
        coefficient: f64,
    },
}

impl FrictionError {
    /// Every heat-balance failure is decided by the housing's inputs.
    pub fn is_input(&self) -> bool {
        true
    }
}

/// One loaded cell of one position with what its friction needs that the oil temperature does
/// not change.
#[derive(Debug, Clone, Copy)]
struct CellContact {
    /// Index of the position in the loaded analysis.
    position: usize,
    /// Index of the cell in its position's list.
    cell: usize,
    /// Pressure (Pa), sliding speed |v_g| (m/s) and area (m^2).
    pressure: f64,
    sliding_speed: f64,
    area: f64,
    /// Composite roughness R_q at the cell's centre after the running-in of the analysis'
    /// flank (MODEL §6.1, [`Ltca::roughness`]), m; None: the lubricant's.
    roughness: Option<f64>,
    /// Index of the cell's slice in [`MeshContacts::lines`].
    line: usize,
    /// The loaded flank's grid cells under the strip the local cell stands for over the
    /// cycle, with their shares of it: a range of [`MeshContacts::flank_shares`].
    flank_cells: (usize, usize),
}

/// One position's slices, loaded cells (indices local to the position) and flank shares.
type PositionContacts = (Vec<LineContact>, Vec<CellContact>, Vec<(usize, f64)>);

/// The loaded cells of a loaded analysis with their sliding speeds and line contacts
/// (MODEL §13), ready to give the friction at any oil temperature.
#[derive(Debug, Clone)]
pub struct MeshContacts {
    cells: Vec<CellContact>,
    /// Areas of the loaded flank's grid cells, m^2.
    flank_areas: Vec<f64>,
    /// (grid cell, share) of every cell's strip, in the order of [`Self::cells`].
    flank_shares: Vec<(usize, f64)>,
    /// The line contact of each loaded slice: relative radius, rolling velocities, line load
    /// (the sum of p times the width across the line over the slice's cells), peak pressure.
    lines: Vec<LineContact>,
    positions: usize,
    e_prime: f64,
    /// Flow pressure bounding the asperities' pressure, Pa.
    flow_pressure: f64,
    /// Output power P2 = omega2 x mean transmitted wheel torque of the positions, W.
    pub output_power: f64,
}

/// Friction over the mesh cycle (MODEL §13).
#[derive(Debug, Clone, serde::Serialize)]
pub struct MeshFriction {
    /// Mesh power loss sum mu p |v_g| S at each position, W.
    pub position_loss_w: Vec<f64>,
    /// Cycle mean P_Vz, W.
    pub mesh_loss_w: f64,
    /// Load-weighted mean friction coefficient sum mu p S / sum p S.
    pub mean_coefficient: f64,
    /// Load-weighted mean share of the asperities.
    pub asperity_share: f64,
    /// Per loaded cell: (position, cell index, mu, friction power density mu p |v_g| in W/m^2).
    #[serde(skip)]
    pub cells: Vec<(usize, usize, f64, f64)>,
    /// On the loaded flank's grid cells: the load-weighted friction coefficient over the
    /// cycle (NaN where nothing loads the cell) and the friction power density, mean over the
    /// mesh cycle of every tooth's contact there, W/m^2 (its integral over the flank is the
    /// mesh loss).
    #[serde(skip)]
    pub flank_coefficient: Vec<f64>,
    #[serde(skip)]
    pub flank_power_density: Vec<f64>,
}

impl MeshContacts {
    /// The loaded cells of `ltca` (on the gear's operating placement and speed, MODEL §4.5):
    /// sliding speed at each cell centre, the film's line contact of each slice (its
    /// curvature from the TCA's contact line, the rolling velocities of the nearest flank node).
    pub fn new(gear: &GearSet, geo: &Geometry, tca: &Tca, ltca: &Ltca) -> Self {
        let wf = geo.wheel_flank(tca.loaded_flank);
        let film = FilmGeometry::new(tca, wf);
        let grid = FlankGrid::of(wf);
        let strips = flank::swept_strips(tca, ltca, 2.0 * std::f64::consts::PI / geo.teeth as f64);
        let roughness = ltca.roughness.as_ref();
        // Positions are independent: on the pool, then joined in their order (on many cores
        // this part would otherwise wait for one thread, issue 55).
        let per_position: Vec<PositionContacts> = ltca
            .positions
            .par_iter()
            .enumerate()
            .map(|(n, pr)| {
                let (lines, of_cell) = film.slice_lines(pr.position, &pr.cells, &pr.pressure);
                let sliding = cell_sliding(gear, geo, &pr.cells);
                let (mut cells, mut flank_shares) = (Vec::new(), Vec::new());
                for k in (0..pr.cells.len()).filter(|&k| pr.pressure[k] > 0.0) {
                    let c = &pr.cells[k];
                    let start = flank_shares.len();
                    grid.cells_under(strips[n][k], c.z, c.half_dz, &mut flank_shares);
                    cells.push(CellContact {
                        flank_cells: (start, flank_shares.len()),
                        position: n,
                        cell: k,
                        pressure: pr.pressure[k],
                        sliding_speed: sliding[k].speed,
                        area: c.cell.area(),
                        roughness: roughness.map(|f| f.at(wf, c.r, c.z)),
                        line: of_cell[k],
                    });
                }
                (lines, cells, flank_shares)
            })
            .collect();
        let (mut cells, mut lines, mut flank_shares) = (Vec::new(), Vec::new(), Vec::new());
        for (position_lines, position_cells, shares) in per_position {
            let (first_line, first_share) = (lines.len(), flank_shares.len());
            lines.extend(position_lines);
            flank_shares.extend(shares);
            cells.extend(position_cells.into_iter().map(|c| CellContact {
                line: first_line + c.line,
                flank_cells: (first_share + c.flank_cells.0, first_share + c.flank_cells.1),
                ..c
            }));
        }
        let mean = |f: &dyn Fn(&crate::ltca::PositionResult) -> f64| {
            ltca.positions.iter().map(f).sum::<f64>() / ltca.positions.len().max(1) as f64
        };
        let inputs = FrictionInputs::of(gear, &gear.lubricant);
        Self {
            cells,
            flank_areas: wf.cell_area.clone(),
            flank_shares,
            lines,
            positions: ltca.positions.len(),
            e_prime: inputs.e_prime,
            flow_pressure: inputs.flow_pressure,
            output_power: mean(&|p| p.wheel_torque.abs()) * gear.conditions.worm_speed
                / gear.ratio(),
        }
    }

    /// The friction of every loaded cell with `lubricant` (its viscosity and temperature as
    /// given; its composite roughness where the analysis' flank has not run in, MODEL §6.1)
    /// and `law`, and the mesh loss over the cycle (MODEL §13).
    pub fn friction(&self, lubricant: &Lubricant, law: &FrictionLaw) -> MeshFriction {
        let mut position_loss = vec![0.0; self.positions];
        let (mut weighted, mut share, mut load) = (0.0, 0.0, 0.0);
        let mut cells = Vec::with_capacity(self.cells.len());
        self.each_cell(lubricant, law, |c, f, density| {
            position_loss[c.position] += density * c.area;
            let force = c.pressure * c.area;
            weighted += f.coefficient * force;
            share += f.asperity_share * force;
            load += force;
            cells.push((c.position, c.cell, f.coefficient, density));
        });
        let mesh_loss_w = position_loss.iter().sum::<f64>() / self.positions.max(1) as f64;
        let (flank_coefficient, flank_power_density) = self.flank_fields(&cells);
        let mean = |x: f64| if load > 0.0 { x / load } else { 0.0 };
        MeshFriction {
            position_loss_w: position_loss,
            mesh_loss_w,
            mean_coefficient: mean(weighted),
            asperity_share: mean(share),
            cells,
            flank_coefficient,
            flank_power_density,
        }
    }

    /// The mesh loss P_Vz alone (W), as [`Self::friction`] sums it: what the heat balance's
    /// search evaluates, without the per-cell lists and flank fields.
    pub fn mesh_loss(&self, lubricant: &Lubricant, law: &FrictionLaw) -> f64 {
        let mut position_loss = vec![0.0; self.positions];
        self.each_cell(lubricant, law, |c, _, density| {
            position_loss[c.position] += density * c.area;
        });
        position_loss.iter().sum::<f64>() / self.positions.max(1) as f64
    }

    /// Calls `visit` with every loaded cell, its local friction and its friction power density
    /// mu p |v_g| (W/m^2), the film of each slice computed once (MODEL §6, §13).
    fn each_cell(
        &self,
        lubricant: &Lubricant,
        law: &FrictionLaw,
        mut visit: impl FnMut(&CellContact, LocalFriction, f64),
    ) {
        let inputs = FrictionInputs {
            lubricant,
            law,
            e_prime: self.e_prime,
            flow_pressure: self.flow_pressure,
        };
        let films = inputs.films(&self.lines);
        for c in &self.cells {
            let roughness = c.roughness.unwrap_or(lubricant.composite_roughness);
            let f = inputs.at(c.pressure, c.sliding_speed, films[c.line], roughness);
            let density = f.coefficient * c.pressure * c.sliding_speed;
            visit(c, f, density);
        }
    }

    /// The friction of the loaded cells `friction` ((position, cell, mu, density) in the
    /// order of [`Self::cells`]) gathered on the flank's grid cells under the strips they
    /// sweep over the cycle ([`flank::swept_strips`]): the load-weighted mu and the power
    /// density, sum of density x local area / (positions x grid cell area).
    fn flank_fields(&self, friction: &[(usize, usize, f64, f64)]) -> (Vec<f64>, Vec<f64>) {
        let n = self.flank_areas.len();
        let (mut mu_load, mut load, mut power) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        for (c, &(_, _, mu, density)) in self.cells.iter().zip(friction) {
            for &(g, share) in &self.flank_shares[c.flank_cells.0..c.flank_cells.1] {
                let force = c.pressure * c.area * share;
                mu_load[g] += mu * force;
                load[g] += force;
                power[g] += density * c.area * share;
            }
        }
        let positions = self.positions.max(1) as f64;
        let coefficient = (0..n)
            .map(|g| {
                if load[g] > 0.0 {
                    mu_load[g] / load[g]
                } else {
                    f64::NAN
                }
            })
            .collect();
        let density = (0..n)
            .map(|g| power[g] / (positions * self.flank_areas[g]))
            .collect();
        (coefficient, density)
    }
}

/// Powers and efficiencies of the gear, worm driving (MODEL §13, §9).
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Efficiency {
    /// P2, W.
    pub output_power_w: f64,
    /// P_Vz from the contact, W.
    pub mesh_loss_w: f64,
    /// P_V0 + P_VLP + P_VD of MODEL §9 (no-load, bearings, seals), W.
    pub other_losses_w: f64,
    /// eta_z = 1 - P_Vz / P1 = P2 / (P2 + P_Vz).
    pub mesh_efficiency: f64,
    /// eta = P2 / (P2 + P_V).
    pub total_efficiency: f64,
}

impl Efficiency {
    /// From the output power P2 (W), the mesh loss P_Vz and the other losses (W).
    pub fn new(output_power: f64, mesh_loss: f64, other_losses: f64) -> Self {
        Self {
            output_power_w: output_power,
            mesh_loss_w: mesh_loss,
            other_losses_w: other_losses,
            mesh_efficiency: output_power / (output_power + mesh_loss),
            total_efficiency: output_power / (output_power + mesh_loss + other_losses),
        }
    }

    /// The total loss P_V, W.
    pub fn total_loss_w(&self) -> f64 {
        self.mesh_loss_w + self.other_losses_w
    }
}

/// Friction, efficiency and the oil temperature of one loaded analysis (MODEL §13).
#[derive(Debug, Clone, serde::Serialize)]
pub struct Thermal {
    /// "fixed" (the lubricant's temperature) or "balance" (the housing's heat balance).
    pub mode: &'static str,
    /// Oil (sump) temperature, K.
    pub oil_temperature_k: f64,
    /// Viscosity eta0 at that temperature, Pa s.
    pub viscosity_pa_s: f64,
    /// Loss evaluations the balance took (1 with a fixed temperature).
    pub evaluations: usize,
    pub friction: MeshFriction,
    pub efficiency: Efficiency,
    /// Back-driving and self-locking at this friction (MODEL §15); None until the runner adds
    /// it ([`SelfLocking::new`]).
    pub self_locking: Option<SelfLocking>,
}

impl Thermal {
    /// With the back-driving and self-locking of its friction on the loaded analysis `ltca`
    /// (MODEL §15): the running friction of its cells, and the boundary friction at rest.
    pub fn with_self_locking(mut self, gear: &GearSet, geo: &Geometry, ltca: &Ltca) -> Self {
        let arms = FrictionArms::new(gear, geo, ltca);
        let locking = SelfLocking::new(&arms, &self.friction.cells, gear.friction.boundary);
        self.self_locking = Some(locking);
        self
    }
}

/// Highest oil temperature the heat balance looks for, K (200 C: beyond any lubricant's range).
pub const BALANCE_LIMIT_K: f64 = 473.15;

/// Step of the heat balance's scan up from the ambient temperature, K.
pub const BALANCE_SCAN_K: f64 = 5.0;

/// Tolerance of the heat balance's fixed point on the oil temperature, K.
pub const BALANCE_TOLERANCE_K: f64 = 0.01;

/// The friction and efficiency at the gear's oil temperature: the lubricant's, or with
/// `housing.balance` the steady temperature where the housing rejects the total loss,
/// P_V(theta) = alpha_L A_H (theta - theta_0) + Q_cooler: the first such temperature up from
/// the ambient one (what a cold start reaches), bracketed in steps of [`BALANCE_SCAN_K`] and
/// refined to [`BALANCE_TOLERANCE_K`] (MODEL §13). `other_losses` P_V0 + P_VLP + P_VD, W.
pub fn heat_balance(
    contacts: &MeshContacts,
    lubricant: &Lubricant,
    law: &FrictionLaw,
    housing: &Housing,
    other_losses: f64,
) -> Result<Thermal, FrictionError> {
    heat_balance_from(contacts, (lubricant, law, housing), other_losses, None)
}

/// [`heat_balance`], its bracket searched from `start` (K, e.g. the previous wear state's
/// temperature: a few evaluations where the loss changed little) when given and above the
/// ambient temperature: the crossing next to it, which is the first one up from the ambient
/// temperature unless the loss has changed enough between the two calls to open another.
pub fn heat_balance_from(
    contacts: &MeshContacts,
    (lubricant, law, housing): (&Lubricant, &FrictionLaw, &Housing),
    other_losses: f64,
    start: Option<f64>,
) -> Result<Thermal, FrictionError> {
    let at = |t: f64| {
        let lub = lubricant.at_temperature(t);
        let friction = contacts.friction(&lub, law);
        let efficiency = Efficiency::new(contacts.output_power, friction.mesh_loss_w, other_losses);
        (lub.viscosity, friction, efficiency)
    };
    let thermal = |mode, t: f64, evaluations| {
        let (viscosity, friction, efficiency) = at(t);
        Thermal {
            mode,
            oil_temperature_k: t,
            viscosity_pa_s: viscosity,
            evaluations,
            friction,
            efficiency,
            self_locking: None,
        }
    };
    if !housing.balance {
        return Ok(thermal("fixed", lubricant.temperature, 1));
    }
    let conductance = housing.heat_transfer * housing.area;
    let evaluations = std::cell::Cell::new(0usize);
    // Excess of the loss over what the housing rejects at t, W (decreasing through the root).
    let excess = |t: f64| {
        evaluations.set(evaluations.get() + 1);
        let mesh = contacts.mesh_loss(&lubricant.at_temperature(t), law);
        mesh + other_losses - housing.cooler - conductance * (t - housing.ambient)
    };
    let cold = excess(housing.ambient);
    if cold < 0.0 {
        return Err(FrictionError::CoolerExceedsLoss {
            cooler: housing.cooler,
            loss: cold + housing.cooler,
        });
    }
    let start = start
        .filter(|t| *t > housing.ambient && *t < BALANCE_LIMIT_K)
        .unwrap_or(housing.ambient);
    let Some(((lo, f_lo), (hi, f_hi))) = bracket(&excess, (housing.ambient, cold), start) else {
        let rejected = conductance * (BALANCE_LIMIT_K - housing.ambient) + housing.cooler;
        let loss = excess(BALANCE_LIMIT_K) + rejected;
        return Err(FrictionError::NoEquilibrium {
            limit_c: BALANCE_LIMIT_K - 273.15,
            loss,
            rejected,
            area: housing.area,
            coefficient: housing.heat_transfer,
        });
    };
    let t = illinois(&excess, (lo, f_lo), (hi, f_hi), BALANCE_TOLERANCE_K);
    Ok(thermal("balance", t, evaluations.get() + 1))
}

/// Largest number of loaded analyses of the oil temperature's fixed point (MODEL §13).
const OIL_ITERATIONS: usize = 6;

/// The oil temperature's fixed point between the loaded analysis' friction and the heat
/// balance has converged when two passes differ by less than this, K.
pub const OIL_TOLERANCE_K: f64 = 0.05;

/// The unworn loaded analysis of `gear` (MODEL §5) with its bending model; with the heat
/// balance and the transmitted torque, the friction the pressures carry is at the balance's oil
/// temperature ([`oil_fixed_point`]).
pub fn unworn_analysis(
    gear: &GearSet,
    geo: &Geometry,
    tca: &Tca,
    bending: Option<&dyn crate::ltca::BendingModel>,
) -> Result<Ltca, crate::ltca::LtcaError> {
    let analyse = |settings: &crate::ltca::LtcaSettings, warm: Option<&crate::ltca::WarmStart>| {
        crate::ltca::analyse_worn(gear, geo, tca, settings, bending, None, warm)
    };
    let rating = crate::rating::rate(gear);
    let other = rating.loss_churning_w + rating.loss_bearings_w + rating.loss_seals_w;
    let settings = crate::ltca::LtcaSettings::from_gear(gear);
    let first = analyse(&settings, None)?;
    oil_fixed_point((gear, geo, tca), other, (settings, first), analyse)
}

/// The loaded analysis `first` (run by `analyse` with `settings` and a warm start), and with
/// the heat balance
/// and the transmitted torque, again at the balance's oil temperature until two temperatures
/// differ by less than [`OIL_TOLERANCE_K`] (MODEL §13: the friction the pressures carry
/// follows the oil; at most [`OIL_ITERATIONS`] analyses; a balance that fails ends the passes,
/// and the friction stage reports it). `other_losses` P_V0 + P_VLP + P_VD, W.
pub fn oil_fixed_point<E>(
    (gear, geo, tca): (&GearSet, &Geometry, &Tca),
    other_losses: f64,
    (mut settings, first): (crate::ltca::LtcaSettings, Ltca),
    analyse: impl Fn(&crate::ltca::LtcaSettings, Option<&crate::ltca::WarmStart>) -> Result<Ltca, E>,
) -> Result<Ltca, E> {
    let mut result = first;
    let coupled = settings.torque_balance == crate::input::TorqueBalance::Transmitted;
    if !(gear.housing.balance && coupled) {
        return Ok(result);
    }
    for _ in 1..OIL_ITERATIONS {
        let contacts = MeshContacts::new(gear, geo, tca, &result);
        let law = (&gear.lubricant, &gear.friction, &gear.housing);
        let start = Some(settings.oil_temperature);
        let Ok(t) = heat_balance_from(&contacts, law, other_losses, start) else {
            break;
        };
        if (t.oil_temperature_k - settings.oil_temperature).abs() < OIL_TOLERANCE_K {
            break;
        }
        settings.oil_temperature = t.oil_temperature_k;
        result = analyse(&settings, Some(&result.warm_start()))?;
    }
    Ok(result)
}

/// The first downward crossing of `excess` above the ambient temperature `(ambient, f)`
/// (f > 0 there), as a bracket (lo, f(lo) > 0), (hi, f(hi) <= 0): searched from `start` down
/// while the excess there is not positive (the first crossing is below it), then up, in steps
/// of [`BALANCE_SCAN_K`]. None below [`BALANCE_LIMIT_K`].
fn bracket(
    excess: &dyn Fn(f64) -> f64,
    ambient: (f64, f64),
    start: f64,
) -> Option<((f64, f64), (f64, f64))> {
    let mut lo = if start > ambient.0 {
        (start, excess(start))
    } else {
        ambient
    };
    while lo.1 <= 0.0 {
        let down = (lo.0 - BALANCE_SCAN_K).max(ambient.0);
        let below = if down <= ambient.0 {
            ambient
        } else {
            (down, excess(down))
        };
        if below.1 > 0.0 {
            return Some((below, lo));
        }
        lo = below;
    }
    loop {
        let t = (lo.0 + BALANCE_SCAN_K).min(BALANCE_LIMIT_K);
        let hi = (t, excess(t));
        if hi.1 <= 0.0 {
            return Some((lo, hi));
        }
        if t >= BALANCE_LIMIT_K {
            return None;
        }
        lo = hi;
    }
}

/// Root of `f` in the bracket (a, f(a) > 0), (b, f(b) <= 0) by the Illinois variant of
/// regula falsi, to `tol` in x.
fn illinois(
    f: &dyn Fn(f64) -> f64,
    (mut a, mut fa): (f64, f64),
    (mut b, mut fb): (f64, f64),
    tol: f64,
) -> f64 {
    let mut side = 0i8;
    for _ in 0..100 {
        if (b - a).abs() <= tol {
            break;
        }
        let c = if fa != fb {
            (a * fb - b * fa) / (fb - fa)
        } else {
            0.5 * (a + b)
        };
        let fc = f(c);
        if fc > 0.0 {
            (a, fa) = (c, fc);
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        } else {
            (b, fb) = (c, fc);
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        }
        if fc.abs() <= f64::EPSILON * fa.abs().max(fb.abs()) {
            return c;
        }
    }
    0.5 * (a + b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lubrication::tests::oil;

    const E_PRIME: f64 = 1.557e11;

    fn law() -> FrictionLaw {
        crate::traction::tests::law()
    }

    #[test]
    fn the_viscosity_follows_the_thermo_viscosity_law_both_ways() {
        let lub = oil();
        let hot = lub.at_temperature(353.0);
        let expected = 0.227 * (3200.0f64 * (1.0 / 353.0 - 1.0 / 333.0)).exp();
        assert!((hot.viscosity / expected - 1.0).abs() < 1e-14);
        let back = hot.at_temperature(333.0);
        assert!((back.viscosity / lub.viscosity - 1.0).abs() < 1e-14);
    }

    /// One loaded cell: 500 MPa over 1 mm^2 sliding at 4 m/s, on a line contact of 20 mm
    /// radius, 2 m/s of entrainment and 200 N/mm.
    fn one_cell(output_power: f64) -> MeshContacts {
        MeshContacts {
            cells: vec![CellContact {
                position: 0,
                cell: 0,
                pressure: 5e8,
                sliding_speed: 4.0,
                area: 1e-6,
                roughness: None,
                line: 0,
                flank_cells: (0, 1),
            }],
            flank_areas: vec![1e-6],
            flank_shares: vec![(0, 1.0)],
            lines: vec![LineContact {
                radius: 0.02,
                u1: 2.0,
                u2: 2.0,
                line_load: 2e5,
                pressure: 5e8,
            }],
            positions: 1,
            e_prime: E_PRIME,
            flow_pressure: f64::INFINITY,
            output_power,
        }
    }

    fn housing() -> Housing {
        Housing {
            balance: true,
            area: 0.3,
            heat_transfer: 17.0,
            ambient: 293.15,
            cooler: 50.0,
        }
    }

    #[test]
    fn a_temperature_independent_loss_balances_at_the_hand_solution() {
        // Boundary friction on every asperity (summits so dense and sharp that the asperities
        // carry all at this contact's film, lambda about 1), no film shear: P_Vz = mu_b p |v_g| S whatever the temperature, so
        // theta = theta_0 + (P_Vz + P_other - Q) / (alpha A).
        let boundary = FrictionLaw {
            summit_density_radius_roughness: 1.0,
            summit_roughness_radius: 0.1,
            limiting_shear: 0.0,
            ..law()
        };
        let contacts = one_cell(10_000.0);
        let h = housing();
        let t = heat_balance(&contacts, &oil(), &boundary, &h, 300.0).unwrap();
        let loss = 0.094 * 5e8 * 4.0 * 1e-6;
        let hand = h.ambient + (loss + 300.0 - h.cooler) / (h.heat_transfer * h.area);
        assert!((t.friction.mesh_loss_w - loss).abs() < 1e-9);
        assert!(
            (t.oil_temperature_k - hand).abs() <= BALANCE_TOLERANCE_K,
            "{} vs {hand}",
            t.oil_temperature_k
        );
        assert!((t.efficiency.mesh_efficiency - 10_000.0 / (10_000.0 + loss)).abs() < 1e-15);
    }

    #[test]
    fn the_balance_holds_at_its_temperature_and_refuses_what_has_no_equilibrium() {
        let contacts = one_cell(10_000.0);
        let h = housing();
        let t = heat_balance(&contacts, &oil(), &law(), &h, 300.0).unwrap();
        // The loss at the returned temperature is what the housing rejects there.
        let rejected = h.heat_transfer * h.area * (t.oil_temperature_k - h.ambient) + h.cooler;
        let slope = h.heat_transfer * h.area * BALANCE_TOLERANCE_K;
        assert!(
            (t.efficiency.total_loss_w() - rejected).abs() <= slope,
            "{t:?}"
        );
        // A cooler larger than the loss, and a housing too small for it, are named.
        let big_cooler = Housing { cooler: 1e6, ..h };
        let e = heat_balance(&contacts, &oil(), &law(), &big_cooler, 300.0).unwrap_err();
        assert!(e.to_string().contains("housing.cooler_w"), "{e}");
        let tiny = Housing {
            area: 1e-4,
            cooler: 0.0,
            ..h
        };
        let e = heat_balance(&contacts, &oil(), &law(), &tiny, 3000.0).unwrap_err();
        assert!(e.to_string().contains("housing.area_m2"), "{e}");
        // With a fixed temperature the lubricant's is used as given.
        let fixed = heat_balance(
            &contacts,
            &oil(),
            &law(),
            &Housing {
                balance: false,
                ..h
            },
            300.0,
        )
        .unwrap();
        assert_eq!((fixed.oil_temperature_k, fixed.mode), (333.0, "fixed"));
    }
}
