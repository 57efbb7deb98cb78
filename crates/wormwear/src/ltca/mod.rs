//! Stage 3 — loaded tooth contact analysis (MODEL §5, §12c, §12d).
//!
//! At each kinematic position of the TCA, around the contact line of every engaged tooth, a
//! local mesh of slices along the face width (node columns of the global flank grid, so the
//! flank is exact there) times columns across the line; cells know their centre, normal,
//! tangent axes, area and tooth. Contact coefficients (Boussinesq, [`crate::contact`]) couple
//! cells of the same tooth; bending (when a [`BendingModel`] is given) adds a low-rank term
//! F C F^T across teeth. Unknowns q_i = l_i f_i (cell force times lever about the wheel axis),
//! so the compatibility y_i = sum_j C_ij q_j / (S_j l_i l_j) + e_i - alpha >= 0 with
//! sum q_i = C2 is MODEL §5.2 with R_i = 1/l_i (exact ratio, §5.3); the worm-torque equilibrium
//! sum f_i (M_i x n_i)_x = C_m is closed by an outer update of the wheel torque C2.

pub(crate) mod passage;
pub mod solver;

use crate::contact::{hertz_half_width, ContactCell, ElasticPair, InfluenceRows};
use crate::geometry::placement::{from_wheel_body, wheel_point};
use crate::geometry::{FlankField, Geometry, WheelFlank};
use crate::input::{GearSet, Torque};
use crate::kinematics::{GapEvaluator, Tca};
use crate::subsurface::{Criterion, Equivalent, SubsurfaceSettings};
use nalgebra::Vector3;
use rayon::prelude::*;
use solver::{
    Block, BlockMatrix, LowRank, Problem, Residuals, SolverError, SolverKind, SolverSettings,
};
use std::f64::consts::PI;

/// Bending influence coefficients (worm and wheel), supplied by the bending stage.
pub trait BendingModel: Sync {
    /// "fe" for the finite-element model.
    fn name(&self) -> &'static str;
    /// Low-rank term (in force units: normal displacement at i per unit normal force at j,
    /// m/N) for the given cells (worm frame) and their teeth.
    fn coefficients(&self, cells: &[LocalCell]) -> LowRank;
    /// Part of [`BendingModel::coefficients`] that is a rigid rotation of the whole wheel
    /// about its axis (the torsion of its shaft), per unit wheel torque, rad/(N m): it adds
    /// -c_t C2 to the TE at every position and changes no pressure; reported separately.
    fn rigid_rotation_compliance(&self) -> f64 {
        0.0
    }
}

/// Settings of the local contact mesh and the solver.
#[derive(Debug, Clone, Copy)]
pub struct LtcaSettings {
    /// Use every `slice_step`-th node column of the global grid as a slice.
    pub slice_step: usize,
    /// Cells across the contact line on each slice.
    pub columns: usize,
    /// Half-width of the band across the line, in Hertz half-widths at the mean line load.
    pub band_factor: f64,
    /// Flow pressure p_Y of the wheel's surface: the largest contact pressure, cells at it
    /// are in plastic flow (MODEL §5.7), Pa; infinite: the purely elastic contact.
    pub flow_pressure: f64,
    /// Patch of the reported converged pressure: across the contact line and along the face
    /// width, m ([`max_patch_pressure`]).
    pub patch_across: f64,
    pub patch_along: f64,
    pub solver: SolverSettings,
    /// Direction of the pressure on a cell (MODEL §5.2's n_i).
    pub pressure_direction: crate::input::PressureDirection,
    /// The sub-surface stress criterion of the equivalent pressure (MODEL §8.1).
    pub subsurface: SubsurfaceSettings,
}

impl LtcaSettings {
    pub fn from_gear(gear: &GearSet) -> Self {
        let a = &gear.analysis;
        Self {
            slice_step: a.contact_slice_step,
            columns: a.contact_columns,
            band_factor: a.contact_band_factor,
            flow_pressure: a.contact.pressure_bound(),
            patch_across: a.pressure_patch_across,
            patch_along: a.pressure_patch_along,
            solver: SolverSettings {
                kind: a.solver,
                ..SolverSettings::default()
            },
            pressure_direction: a.pressure_direction,
            subsurface: SubsurfaceSettings {
                criterion: gear
                    .wear
                    .as_ref()
                    .map_or(Criterion::PrincipalShear, |w| w.pitting_stress.criterion()),
                ..SubsurfaceSettings::new(gear.wheel_material.poisson_ratio)
            },
        }
    }
}

/// One cell of a local contact mesh.
#[derive(Debug, Clone, Copy)]
pub struct LocalCell {
    pub cell: ContactCell,
    /// Tooth index k and its index in the TCA's tooth list.
    pub tooth: i32,
    pub tooth_index: usize,
    /// Slice (node column) and column across the line.
    pub slice: usize,
    pub column: usize,
    /// Flank coordinates (reference tooth), m.
    pub r: f64,
    pub z: f64,
    /// Half extent of the cell's slice along the face width, m.
    pub half_dz: f64,
    /// Lever of the normal about the wheel axis |(P x n)_z|, m.
    pub lever: f64,
    /// Cell centre and flank normal in the fixed wheel frame (origin at the wheel centre, z
    /// along the wheel axis; MODEL §1), m and unit.
    pub wheel_centre: Vector3<f64>,
    pub wheel_normal: Vector3<f64>,
    /// Moment of a unit normal force on the worm about its axis (M x n)_x, m.
    pub worm_lever: f64,
    /// Initial angular separation (after the kinematic error), rad.
    pub separation: f64,
    /// Edge relief (worm tip rounding, wheel edge rounding) included in it, as a normal
    /// distance, m.
    pub relief: f64,
}

/// Result at one position.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PositionResult {
    pub position: usize,
    /// Normal force carried by each studied tooth (TCA tooth order), N.
    pub tooth_load: Vec<f64>,
    /// Wheel torque carried, N m.
    pub wheel_torque: f64,
    /// Worm torque balanced, N m.
    pub worm_torque: f64,
    /// Rigid approach (wheel rotation against its driven sense), rad.
    pub approach: f64,
    /// Loaded transmission error = unloaded kinematic error - approach (driven sense,
    /// negative = lag), rad.
    pub transmission_error: f64,
    /// Angular mesh stiffness C2 / approach, N m/rad.
    pub stiffness_angular: f64,
    /// Linear mesh stiffness F / (approach x lever at the force barycentre), N/m.
    pub stiffness_linear: f64,
    pub max_pressure: f64,
    pub residuals: Residuals,
    /// Relative worm-torque balance error |sum f (M x n)_x - C_m| / C_m.
    pub torque_residual: f64,
    /// Pressures of the local cells, Pa (same order as `cells`).
    pub pressure: Vec<f64>,
    /// Plastic indentation of the local cells: the interference -y_i l_i of the cells at the
    /// flow pressure, normal to the flank, m (0 elsewhere; MODEL §5.7).
    pub plastic_depth: Vec<f64>,
    /// Equivalent pressure of the local cells and the depth of its maximum, from the stress
    /// below the wheel flank (MODEL §8.1; zero on unloaded cells).
    #[serde(skip)]
    pub equivalent: Vec<Equivalent>,
    #[serde(skip)]
    pub cells: Vec<LocalCell>,
    /// Band widenings needed (load at the band edge).
    pub band_widenings: usize,
}

/// Result of the loaded analysis over the mesh cycle.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Ltca {
    pub bending_model: String,
    /// Torsional compliance of the wheel shaft included in the bending model, rad/(N m)
    /// (0: none; see [`BendingModel::rigid_rotation_compliance`]).
    pub shaft_torsion_compliance: f64,
    pub solver: SolverKind,
    pub positions: Vec<PositionResult>,
    /// Loaded contact pattern: max pressure over all positions and teeth per global cell of the
    /// loaded flank, Pa.
    pub pattern: Vec<f64>,
    pub max_pressure: f64,
    /// Mean of the non-zero pattern cells, Pa.
    pub mean_pressure: f64,
    /// Contact area / active flank area.
    pub s0: f64,
    /// Area with p > P_mean / active flank area.
    pub s1: f64,
    /// Area with p > P_mean / contact area.
    pub s2: f64,
    /// Largest mean pressure over a patch of the stated size (LtcaSettings::patch_across x
    /// patch_along; [`max_patch_pressure`]), Pa: mesh-converged where the maximum is an edge
    /// singularity.
    pub pressure_patch_max: f64,
    /// That patch: across the line and along the face width, m.
    pub pressure_patch_size: [f64; 2],
    /// Plastic indentation of the wheel flank over the cycle: at each node of the loaded
    /// flank's grid, the largest interference of the cells at the flow pressure over the
    /// positions and teeth, normal to the flank, m (zeros for the elastic contact; MODEL §5.7).
    pub plastic_indentation: FlankField,
    /// Share of the active flank area where some position reaches the flow pressure.
    pub yielded_area_fraction: f64,
    /// Equivalent pressure of the fatigue criterion over the cycle (MODEL §8.1): at each cell
    /// of the global grid, the largest over the band's passage, Pa.
    pub equivalent_pattern: Vec<f64>,
    /// Depth below the flank where that largest value is reached, per global cell, m.
    pub equivalent_depth: Vec<f64>,
    /// Largest equivalent pressure of any local cell, Pa.
    pub equivalent_pressure_max: f64,
    /// How the equivalent pressure was evaluated (its criterion, the wheel's Poisson ratio).
    pub subsurface: SubsurfaceSettings,
    pub worm_torque: f64,
    pub wheel_torque: f64,
    /// Frictionless power balance over the pitch: mean wheel torque over u x the mean worm
    /// torque, less 1 (0 for a model consistent with the kinematics; beyond
    /// [`POWER_BALANCE_LIMIT`] the contact is at non-conjugate points, see `warnings`).
    pub power_balance: f64,
    /// What makes these results doubtful, with the reason.
    pub warnings: Vec<String>,
}

/// Largest departure from the frictionless power balance of a trusted loaded analysis. The
/// aligned examples stay within 0.5 % (band cells off the contact line, the worm's tip edge).
pub const POWER_BALANCE_LIMIT: f64 = 0.02;

/// Warnings on a loaded analysis whose mean wheel torque departs from u x the worm torque
/// by more than [`POWER_BALANCE_LIMIT`]: the load sits at points where the pressure direction
/// is not the contact's (with `pressure_direction = "wheel-flank"`, the wheel's face edge
/// under a misalignment), which the small worm lever (|t| / |M| ~ tan of the lead angle) turns
/// into large torque errors.
fn power_balance_warnings(
    balance: f64,
    wheel: f64,
    ratio: f64,
    worm: f64,
    edge_z: f64,
) -> Vec<String> {
    if balance.abs() <= POWER_BALANCE_LIMIT {
        return Vec::new();
    }
    vec![format!(
        "the mean wheel torque over the pitch, {wheel:.1} N m, departs from u x the worm torque, \
         {:.1} N m, by {:+.1} % (frictionless power balance, limit {} %): the pressure \
         direction is not the contact's where the load sits (largest pressure at z = {:.2} mm; \
         with analysis.pressure_direction = \"wheel-flank\", the wheel's face edge under a \
         misalignment); torques, TE and stiffness are unreliable. The default \
         pressure_direction = \"worm-flank\" keeps the balance",
        ratio * worm,
        100.0 * balance,
        100.0 * POWER_BALANCE_LIMIT,
        edge_z * 1e3
    )]
}

impl Ltca {
    /// Mean and peak-to-peak of the loaded transmission error, rad.
    pub fn te_stats(&self) -> (f64, f64) {
        stats(self.positions.iter().map(|p| p.transmission_error))
    }
    /// Mean angular mesh stiffness, N m/rad.
    pub fn stiffness_mean(&self) -> f64 {
        stats(self.positions.iter().map(|p| p.stiffness_angular)).0
    }
    /// Mean angular mesh stiffness without the wheel shaft's torsion: C2 / (alpha - c_t C2),
    /// N m/rad (equal to [`Ltca::stiffness_mean`] when the model has no shaft torsion).
    pub fn stiffness_without_shaft_torsion_mean(&self) -> f64 {
        let c_t = self.shaft_torsion_compliance;
        stats(
            self.positions
                .iter()
                .map(|p| p.wheel_torque / (p.approach - c_t * p.wheel_torque)),
        )
        .0
    }
    /// Most teeth carrying load at one position.
    pub fn max_teeth_in_contact(&self) -> usize {
        self.positions
            .iter()
            .map(|p| {
                p.tooth_load
                    .iter()
                    .filter(|&&f| f > 1e-9 * p.tooth_load.iter().sum::<f64>())
                    .count()
            })
            .max()
            .unwrap_or(0)
    }
}

/// Mean and peak-to-peak (max - min) of a series.
pub(crate) fn stats(v: impl Iterator<Item = f64>) -> (f64, f64) {
    let v: Vec<f64> = v.collect();
    let mean = v.iter().sum::<f64>() / v.len().max(1) as f64;
    let (lo, hi) = v
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    (mean, hi - lo)
}

/// Why the loaded analysis failed.
#[derive(Debug, Clone, thiserror::Error)]
pub enum LtcaError {
    // The cause is the source (not repeated here: `{:#}` prints the chain once).
    #[error("position {position}")]
    Solver {
        position: usize,
        #[source]
        source: SolverError,
    },
    #[error("position {0}: no cell of any tooth can touch the worm")]
    NoContact(usize),
    #[error("position {0}: contact forces do not produce a worm torque in the driving sense")]
    TorqueSign(usize),
    /// The wheel shaft twists by more than a tooth pitch under the load (see
    /// [`shaft_torsion_problem`]).
    #[error("{0}")]
    ShaftTorsion(String),
    /// A position's contact problem above [`MAX_CONTACT_CELLS`], refused before its influence
    /// blocks are built.
    #[error(
        "position {position}: the contact problem has {cells} cells, more than the \
         {MAX_CONTACT_CELLS} the dense contact solver takes (its work grows about as the cube \
         of the cells: {MAX_CONTACT_CELLS} cells take about 9 s a position with FE bending on \
         2 cores); use fewer analysis.contact_columns (now {columns}, the cells across the \
         line), a larger analysis.contact_slice_step (now {slice_step}) or fewer \
         analysis.flank_cells_face (the slices along the line)"
    )]
    TooManyCells {
        position: usize,
        cells: usize,
        columns: usize,
        slice_step: usize,
    },
}

/// The most contact cells one position's problem may hold (MODEL §5.3): the influence blocks
/// are dense and the solver's iterations grow with the cells, so its work grows about as their
/// cube (the design case with FE bending, 2 cores: 2 700 cells 0.11 s a position, 5 400 cells
/// 1.2 s, 8 200 cells 8.6 s, 10 700 cells 11 s, 13 400 cells more than 30 s). 8 192 is half
/// again the finest mesh of the convergence studies (contact_columns = 41: about 5 100 cells
/// on the reference gears). The matrix-free operator of issue 36 is what would lift it.
pub const MAX_CONTACT_CELLS: usize = 8192;

/// A wheel shaft so compliant in torsion that the load alone turns the wheel by more than
/// one tooth pitch: a mesh whose teeth would pass one another under a static load is not a
/// gear the loaded analysis describes (and its solver, with the rigid rotation dwarfing the
/// contact compliances, can take hours). `compliance`: the shaft's torsion at the wheel,
/// rad per N m; `wheel_torque`, N m. The message names the inputs that set it.
pub fn shaft_torsion_problem(compliance: f64, wheel_torque: f64, teeth: u32) -> Option<String> {
    let pitch = 2.0 * std::f64::consts::PI / teeth as f64;
    let rotation = compliance * wheel_torque.abs();
    (rotation > pitch).then(|| {
        format!(
            "the wheel shaft twists by {} rad under the wheel torque {} N m, more than a tooth \
             pitch ({} rad): a thicker shaft (wheel.shaft_radius_mm), closer bearings \
             (wheel.bearing_positions_mm) or a lower torque (conditions) is needed",
            crate::input::Number(rotation),
            crate::input::Number(wheel_torque.abs()),
            crate::input::Number(pitch)
        )
    })
}

/// Runs the loaded analysis with the gear's settings, without bending.
pub fn analyse(gear: &GearSet, geo: &Geometry, tca: &Tca) -> Result<Ltca, LtcaError> {
    analyse_with(gear, geo, tca, &LtcaSettings::from_gear(gear), None)
}

/// Runs the loaded analysis at every TCA position (MODEL §5).
pub fn analyse_with(
    gear: &GearSet,
    geo: &Geometry,
    tca: &Tca,
    settings: &LtcaSettings,
    bending: Option<&dyn BendingModel>,
) -> Result<Ltca, LtcaError> {
    analyse_worn(gear, geo, tca, settings, bending, None, None)
}

/// Loads of a loaded analysis to start the next one's solver from (consecutive wear states
/// differ by micrometres, so their solutions are close): per position, the loaded cells as
/// (tooth, slice, column) and their unknown q = force x lever, N m. A start only: the result
/// is the converged solution whatever the start (to the solver's tolerance).
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WarmStart {
    pub positions: Vec<Vec<(i32, u32, u32, f64)>>,
}

impl WarmStart {
    /// The start for `cells` of position n: the load of the same (tooth, slice, column), 0 for
    /// a cell the previous analysis did not load; None when nothing matches.
    fn for_cells(&self, n: usize, cells: &[LocalCell]) -> Option<Vec<f64>> {
        let known = self.positions.get(n)?;
        let q: Vec<f64> = cells
            .iter()
            .map(|c| {
                let key = (c.tooth, c.slice as u32, c.column as u32);
                known
                    .binary_search_by(|e| (e.0, e.1, e.2).cmp(&key))
                    .map_or(0.0, |k| known[k].3)
            })
            .collect();
        q.iter().any(|&v| v > 0.0).then_some(q)
    }
}

impl Ltca {
    /// The loads of this analysis as a start for the next ([`WarmStart`]).
    pub fn warm_start(&self) -> WarmStart {
        WarmStart {
            positions: self
                .positions
                .iter()
                .map(|p| {
                    let mut loaded: Vec<(i32, u32, u32, f64)> = p
                        .cells
                        .iter()
                        .zip(&p.pressure)
                        .filter(|(_, &pr)| pr > 0.0)
                        .map(|(c, &pr)| {
                            (
                                c.tooth,
                                c.slice as u32,
                                c.column as u32,
                                pr * c.cell.area() * c.lever,
                            )
                        })
                        .collect();
                    loaded.sort_by_key(|e| (e.0, e.1, e.2));
                    loaded
                })
                .collect(),
        }
    }
}

/// [`analyse_with`] on a wheel whose loaded flank has lost `removal` (depth of material normal
/// to the flank on the flank's node grid, m; MODEL §7.5: it adds to the initial separations,
/// turned into an angle by each cell's lever), the solver started from `warm` when given.
pub fn analyse_worn(
    gear: &GearSet,
    geo: &Geometry,
    tca: &Tca,
    settings: &LtcaSettings,
    bending: Option<&dyn BendingModel>,
    removal: Option<&FlankField>,
    warm: Option<&WarmStart>,
) -> Result<Ltca, LtcaError> {
    let change = FlankChange {
        removal,
        plastic_set: None,
    };
    analyse_changed(gear, geo, tca, settings, bending, change, warm)
}

/// How the loaded wheel flank differs from the flank as cut, normal to it, m (MODEL §7.5,
/// §5.7): what a loaded analysis adds to the initial separations.
#[derive(Debug, Clone, Copy, Default)]
pub struct FlankChange<'a> {
    /// Depth worn off (wear and pits) on the flank's node grid; None: unworn.
    pub removal: Option<&'a FlankField>,
    /// Plastic set (running-in) on the flank's node columns, on rows a whole number of times
    /// finer than the grid's ([`Ltca::plastic_indentation`]); None: none.
    pub plastic_set: Option<&'a FlankField>,
}

/// [`analyse_worn`] on a flank changed by wear and by a plastic set ([`FlankChange`]).
pub fn analyse_changed(
    gear: &GearSet,
    geo: &Geometry,
    tca: &Tca,
    settings: &LtcaSettings,
    bending: Option<&dyn BendingModel>,
    change: FlankChange,
    warm: Option<&WarmStart>,
) -> Result<Ltca, LtcaError> {
    let pair = ElasticPair::new(
        gear.worm_material.youngs_modulus,
        gear.worm_material.poisson_ratio,
        gear.wheel_material.youngs_modulus,
        gear.wheel_material.poisson_ratio,
    );
    let ev = GapEvaluator::new(gear, geo);
    let wf = geo.wheel_flank(tca.loaded_flank);
    let (worm_torque, wheel_torque_guess) = match gear.conditions.torque {
        Torque::Worm(t) => (Some(t), t * gear.ratio()),
        Torque::Wheel(t) => (None, t),
    };
    if let Some(problem) = bending.and_then(|b| {
        shaft_torsion_problem(
            b.rigid_rotation_compliance(),
            wheel_torque_guess,
            gear.wheel.teeth,
        )
    }) {
        return Err(LtcaError::ShaftTorsion(problem));
    }
    let band0 = initial_band(gear, tca, wf, settings, &pair, wheel_torque_guess);
    let rows_per_row = change
        .plastic_set
        .filter(|s| s.fits(wf) && s.cells_height > wf.cells_height)
        .map_or_else(
            || plastic_rows_per_row(wf, settings, band0),
            |s| s.cells_height / wf.cells_height,
        );
    let changed = FlankShape::new(wf, change);
    let worn = changed.as_ref().map(|c| c.worn(change.plastic_set));

    let mut positions: Vec<PositionResult> = (0..tca.positions.len())
        .into_par_iter()
        .map(|n| {
            solve_position(
                geo,
                tca,
                &ev,
                wf,
                &pair,
                settings,
                bending,
                n,
                band0,
                worm_torque,
                wheel_torque_guess,
                worn,
                warm,
            )
        })
        .collect::<Result<_, _>>()?;
    positions
        .par_iter_mut()
        .for_each(|p| p.equivalent = position_equivalents(p, &settings.subsurface));
    let ratio = geo.teeth as f64 / gear.worm.starts as f64;
    Ok(over_the_cycle(
        positions,
        (wf, tca, geo.teeth, ratio),
        settings,
        bending,
        rows_per_row,
    ))
}

/// The loaded analysis over the mesh cycle from its positions (MODEL §5.6, §5.7, §8.1): the
/// swept patterns, their statistics, the torques and the warnings. `gear_set` holds the loaded
/// flank, the TCA, the wheel's teeth and the ratio u.
fn over_the_cycle(
    positions: Vec<PositionResult>,
    gear_set: (&WheelFlank, &Tca, u32, f64),
    settings: &LtcaSettings,
    bending: Option<&dyn BendingModel>,
    rows_per_row: usize,
) -> Ltca {
    let (wf, tca, teeth, ratio) = gear_set;

    // Loaded pattern on the global grid (MODEL §5.6), the yielded cells and the plastic
    // indentation (MODEL §5.7); the equivalent pressure's (MODEL §8.1).
    let Swept {
        pattern,
        plastic_indentation,
        equivalent_pattern,
        equivalent_depth,
    } = swept_pattern(wf, tca, &positions, teeth, rows_per_row);
    let equivalent_pressure_max = positions
        .iter()
        .flat_map(|p| p.equivalent.iter().map(|e| e.pressure))
        .fold(0.0, f64::max);
    let stats = PatternStats::of(wf, &pattern, settings.flow_pressure);
    // The largest local cell (the published P_max): the pattern's cell centres read the
    // profiles between cell centres, which can only be lower.
    let max_pressure = positions.iter().map(|p| p.max_pressure).fold(0.0, f64::max);
    let pressure_patch_max =
        max_patch_pressure(&positions, settings.patch_across, settings.patch_along);
    let (worm_torque, wheel_torque, power_balance, mut warnings) =
        torque_balance(&positions, ratio, wf, &pattern);
    warnings.extend(flow_pressure_warning(
        stats.yielded_area_fraction,
        settings.flow_pressure,
    ));
    warnings.extend(deflection_warning(&positions, tca, teeth));
    Ltca {
        bending_model: bending.map(|b| b.name()).unwrap_or("none").to_string(),
        shaft_torsion_compliance: bending.map_or(0.0, |b| b.rigid_rotation_compliance()),
        solver: settings.solver.kind,
        positions,
        pattern,
        max_pressure,
        mean_pressure: stats.mean_pressure,
        s0: stats.s0,
        s1: stats.s1,
        s2: stats.s2,
        pressure_patch_max,
        pressure_patch_size: [settings.patch_across, settings.patch_along],
        plastic_indentation,
        yielded_area_fraction: stats.yielded_area_fraction,
        equivalent_pattern,
        equivalent_depth,
        equivalent_pressure_max,
        subsurface: settings.subsurface,
        worm_torque,
        wheel_torque,
        power_balance,
        warnings,
    }
}

/// The share of a wheel pitch beyond which the load's rotation of the wheel is implausible.
pub const DEFLECTION_PITCH_SHARE_WARNING: f64 = 0.1;

/// A warning when the load turns the wheel (the loaded transmission error less the unloaded
/// kinematic error: contact approach and bending) by more than
/// [`DEFLECTION_PITCH_SHARE_WARNING`] of its angular pitch at some position: deflections that
/// large are outside the small-deflection (linear) model, whatever the solver says. (A large
/// kinematic error, from a misalignment, is geometry and not warned here.)
fn deflection_warning(positions: &[PositionResult], tca: &Tca, teeth: u32) -> Option<String> {
    let pitch = 2.0 * PI / teeth as f64;
    let largest = positions
        .iter()
        .map(|p| (tca.positions[p.position].kinematic_error - p.transmission_error).abs())
        .fold(0.0, f64::max);
    (largest > DEFLECTION_PITCH_SHARE_WARNING * pitch).then(|| {
        format!(
            "the load turns the wheel by {largest:.3e} rad (loaded less unloaded transmission \
             error), {:.0} % of a wheel pitch ({pitch:.4} rad): deflections this large are \
             outside the linear model (check the torque, the bending model's supports and the \
             materials)",
            100.0 * largest / pitch
        )
    })
}

/// A warning when some of the flank reaches the flow pressure (MODEL §5.7): what share, and
/// that its pressures are the plastic limit's.
fn flow_pressure_warning(yielded_area_fraction: f64, flow_pressure: f64) -> Option<String> {
    (yielded_area_fraction > 0.0).then(|| {
        format!(
            "{:.2} % of the active flank reaches the flow pressure {:.0} MPa (MODEL §5.7): the \
             pressures there are the bronze's plastic limit, not an elastic solution, and the \
             flank takes a plastic set",
            100.0 * yielded_area_fraction,
            flow_pressure * 1e-6
        )
    })
}

/// The positions' mean worm and wheel torques (N m), the frictionless power balance
/// wheel torque / (ratio x worm torque) - 1 and its warnings, which name the face position
/// (m) of the pattern's peak.
fn torque_balance(
    positions: &[PositionResult],
    ratio: f64,
    wf: &WheelFlank,
    pattern: &[f64],
) -> (f64, f64, f64, Vec<String>) {
    let ni = wf.cells_height;
    let wheel_torque =
        positions.iter().map(|p| p.wheel_torque).sum::<f64>() / positions.len() as f64;
    let worm_torque = positions.iter().map(|p| p.worm_torque).sum::<f64>() / positions.len() as f64;
    let power_balance = wheel_torque / (ratio * worm_torque) - 1.0;
    let peak = (0..pattern.len())
        .max_by(|&a, &b| pattern[a].total_cmp(&pattern[b]))
        .map_or(0.0, |k| 0.5 * (wf.z[k / ni] + wf.z[k / ni + 1]));
    let warnings = power_balance_warnings(power_balance, wheel_torque, ratio, worm_torque, peak);
    (worm_torque, wheel_torque, power_balance, warnings)
}

/// The loaded pattern's statistics (MODEL §5.6, §5.7): the mean pressure of the loaded cells
/// (Pa), the loaded share of the active flank S0, the share above the mean S1 (of the active
/// flank) and S2 (of the loaded area), and the share at the flow pressure `flow_pressure`.
struct PatternStats {
    mean_pressure: f64,
    s0: f64,
    s1: f64,
    s2: f64,
    yielded_area_fraction: f64,
}

impl PatternStats {
    fn of(wf: &WheelFlank, pattern: &[f64], flow_pressure: f64) -> Self {
        let bound = flow_pressure * (1.0 - 1e-9);
        let active_area = wf.active_area();
        let yielded_area: f64 = (0..pattern.len())
            .filter(|&k| pattern[k] >= bound)
            .map(|k| wf.cell_area[k])
            .sum();
        let loaded: Vec<usize> = (0..pattern.len()).filter(|&k| pattern[k] > 0.0).collect();
        let contact_area: f64 = loaded.iter().map(|&k| wf.cell_area[k]).sum();
        let mean_pressure = if loaded.is_empty() {
            0.0
        } else {
            loaded.iter().map(|&k| pattern[k]).sum::<f64>() / loaded.len() as f64
        };
        let above: f64 = loaded
            .iter()
            .filter(|&&k| pattern[k] > mean_pressure)
            .map(|&k| wf.cell_area[k])
            .sum();
        Self {
            mean_pressure,
            s0: contact_area / active_area,
            s1: above / active_area,
            s2: if contact_area > 0.0 {
                above / contact_area
            } else {
                0.0
            },
            yielded_area_fraction: yielded_area / active_area,
        }
    }
}

/// Half-width of the local meshes' band across the line before any widening (MODEL §5.1), m:
/// `band_factor` Hertz half-widths at the mean line load (the wheel torque `wheel_torque` N m
/// over the normal's lever and the mean line length of the TCA's positions) and the lines'
/// mean curvature radius.
fn initial_band(
    gear: &GearSet,
    tca: &Tca,
    wf: &WheelFlank,
    settings: &LtcaSettings,
    pair: &ElasticPair,
    wheel_torque_guess: f64,
) -> f64 {
    // Line-load estimate for the band width: wheel torque / lever / line length.
    let step = settings.slice_step.max(1);
    let slice_dz = wf.z[1] - wf.z[0];
    let mut lengths = Vec::new();
    for n in 0..tca.positions.len() {
        let count = tca
            .contact_lines
            .iter()
            .filter(|c| c.position == n && !c.at_end && c.slice % step == 0)
            .count();
        lengths.push(count as f64 * slice_dz * step as f64);
    }
    let mean_length = lengths.iter().sum::<f64>() / lengths.len() as f64;
    let radii: Vec<f64> = tca
        .contact_lines
        .iter()
        .filter(|c| !c.at_end && c.curvature_radius.is_finite())
        .map(|c| c.curvature_radius)
        .collect();
    let radius = if radii.is_empty() {
        0.03
    } else {
        radii.iter().sum::<f64>() / radii.len() as f64
    };
    // Lever of the normal about the wheel axis, |(P x n)_z| ~ r2 cos(alpha_n).
    let lever_est = gear.wheel_reference_radius() * gear.worm.normal_pressure_angle.cos();
    let w_mean = wheel_torque_guess / lever_est / mean_length.max(1e-6);
    settings.band_factor * hertz_half_width(w_mean, radius, pair.effective_modulus)
}

/// What the band's passage leaves on the global grid ([`swept_pattern`]).
struct Swept {
    /// Largest pressure at each cell centre, Pa (MODEL §5.6).
    pattern: Vec<f64>,
    /// Largest plastic interference at each node of the plastic set's rows, m (MODEL §5.7).
    plastic_indentation: FlankField,
    /// Largest equivalent pressure at each cell centre (Pa) and the depth where it is reached
    /// (m; MODEL §8.1).
    equivalent_pattern: Vec<f64>,
    equivalent_depth: Vec<f64>,
}

/// The loaded pattern (MODEL §5.6), the plastic indentation (MODEL §5.7) and the equivalent
/// pressure (MODEL §8.1) of the band's passage over the global grid: the largest pressure over
/// the whole mesh cycle at each cell centre (the positions' instants and the band's continuous
/// passage between them, [`passage`], so the pattern neither has holes between positions nor
/// moves with their number), the largest interference of the cells at the flow pressure at
/// each node, and the largest equivalent pressure at each cell centre with its depth.
fn swept_pattern(
    wf: &WheelFlank,
    tca: &Tca,
    positions: &[PositionResult],
    teeth: u32,
    rows_per_row: usize,
) -> Swept {
    let (ni, nj) = (wf.cells_height, wf.cells_face);
    let tau = 2.0 * PI / teeth as f64;
    let dt = tau / tca.positions.len() as f64;
    let columns = passage::band_samples(wf, tca, positions, tau);
    let is_slice: Vec<bool> = columns.iter().map(|c| !c.is_empty()).collect();
    let node_r = |j: usize, i: usize| wf.nodes[j * (ni + 1) + i].r;
    type Column = (Vec<f64>, Vec<f64>, Vec<(f64, f64)>);
    let swept: Vec<Column> = columns
        .par_iter()
        .enumerate()
        .map(|(j, samples)| {
            let mid: Vec<f64> = (0..ni)
                .map(|i| 0.5 * (node_r(j, i) + node_r(j, i + 1)))
                .collect();
            // The plastic set's rows (MODEL §5.7): the grid's, rows_per_row times finer.
            let rows = ni * rows_per_row;
            let (low, high) = (node_r(j, 0), node_r(j, ni));
            let fine: Vec<f64> = (0..=rows)
                .map(|i| low + (high - low) * i as f64 / rows as f64)
                .collect();
            (
                passage::swept_max(samples, &mid, dt, passage::Swept::Pressure),
                passage::swept_max(samples, &fine, dt, passage::Swept::Plastic),
                passage::swept_equivalent(samples, &mid, dt),
            )
        })
        .collect();
    // Cell-centre values on each node column (ni per column), then the cell between two.
    let between = |values: &mut Vec<f64>| {
        fill_between_slices(values, ni, &is_slice, wf);
        (0..nj)
            .flat_map(|j| (0..ni).map(move |i| (j, i)))
            .map(|(j, i)| 0.5 * (values[j * ni + i] + values[(j + 1) * ni + i]))
            .collect::<Vec<f64>>()
    };
    let mut mid: Vec<f64> = swept.iter().flat_map(|c| c.0.iter().copied()).collect();
    let pattern = between(&mut mid);
    let mut equivalent: Vec<f64> = swept.iter().flat_map(|c| c.2.iter().map(|e| e.0)).collect();
    // The depth as the equivalent pressure's moments (a cell between a loaded and an
    // unloaded column takes the loaded one's depth).
    let mut moment: Vec<f64> = swept
        .iter()
        .flat_map(|c| c.2.iter().map(|e| e.0 * e.1))
        .collect();
    let equivalent_pattern = between(&mut equivalent);
    let equivalent_depth = between(&mut moment)
        .iter()
        .zip(&equivalent_pattern)
        .map(|(m, p)| if *p > 0.0 { m / p } else { 0.0 })
        .collect();
    let mut plastic_indentation = FlankField::zeros_refined(wf, rows_per_row);
    plastic_indentation.values = swept.iter().flat_map(|c| c.1.iter().copied()).collect();
    fill_between_slices(
        &mut plastic_indentation.values,
        ni * rows_per_row + 1,
        &is_slice,
        wf,
    );
    Swept {
        pattern,
        plastic_indentation,
        equivalent_pattern,
        equivalent_depth,
    }
}

/// The equivalent pressure of the local cells of one position (MODEL §8.1): the rows across
/// the line are its slices, the surfaces its teeth.
pub fn position_equivalents(p: &PositionResult, settings: &SubsurfaceSettings) -> Vec<Equivalent> {
    let mut rows = Vec::new();
    let mut start = 0;
    for k in 1..=p.cells.len() {
        let (a, b) = (&p.cells[start], p.cells.get(k));
        if b.is_none_or(|b| b.tooth_index != a.tooth_index || b.slice != a.slice) {
            rows.push(start..k);
            start = k;
        }
    }
    // The rows of a tooth in their order along the line (node columns).
    rows.sort_by_key(|r| (p.cells[r.start].tooth_index, p.cells[r.start].slice));
    let surface: Vec<usize> = rows.iter().map(|r| p.cells[r.start].tooth_index).collect();
    let cells: Vec<ContactCell> = p.cells.iter().map(|c| c.cell).collect();
    crate::subsurface::equivalent_pressures(&cells, &p.pressure, &rows, &surface, settings)
}

/// Where the equivalent pressure peaks and the principal shear stress on the section below
/// it (MODEL §8.1): the position, the tooth, the face position z (m) and the section across
/// the line below that cell's row (60 x 40 points down to 2 loaded half-widths). `near`
/// (flank radius and face position of the reference tooth, m): the peak among the cells over
/// that point (within their half extents), over the whole flank when none is loaded there.
/// None when no cell is loaded.
pub fn equivalent_section(
    l: &Ltca,
    near: Option<(f64, f64)>,
) -> Option<(usize, i32, f64, crate::subsurface::Section)> {
    let over = |c: &LocalCell, (r, z): (f64, f64)| {
        (c.z - z).abs() <= c.half_dz && (c.r - r).abs() <= c.cell.half_nu.max(c.cell.half_zeta)
    };
    let loaded = |p: &&PositionResult, k: &usize| p.equivalent[*k].pressure > 0.0;
    let cells = || {
        l.positions
            .iter()
            .flat_map(|p| (0..p.equivalent.len()).map(move |k| (p, k)))
            .filter(|(p, k)| loaded(p, k))
    };
    let mut candidates: Vec<(&PositionResult, usize)> = near
        .map(|at| cells().filter(|(p, k)| over(&p.cells[*k], at)).collect())
        .unwrap_or_default();
    if candidates.is_empty() {
        candidates = cells().collect();
    }
    let (p, k) = candidates.into_iter().max_by(|a, b| {
        a.0.equivalent[a.1]
            .pressure
            .total_cmp(&b.0.equivalent[b.1].pressure)
    })?;
    let peak = &p.cells[k];
    let same_row = |c: &LocalCell| c.tooth_index == peak.tooth_index && c.slice == peak.slice;
    let start = (0..=k)
        .rev()
        .take_while(|&i| same_row(&p.cells[i]))
        .last()?;
    let end = (k..p.cells.len())
        .take_while(|&i| same_row(&p.cells[i]))
        .last()?
        + 1;
    let sources: Vec<usize> = (0..p.cells.len())
        .filter(|&i| p.cells[i].tooth_index == peak.tooth_index)
        .collect();
    let cells: Vec<ContactCell> = p.cells.iter().map(|c| c.cell).collect();
    let section = crate::subsurface::section(
        &cells,
        &p.pressure,
        start..end,
        &sources,
        (60, 40, 2.0),
        l.subsurface.poisson,
    );
    Some((p.position, peak.tooth, peak.z, section))
}

/// Node columns that are no slice take the linear interpolation along the face width of the
/// nearest slice columns on each side (the nearest one's values at the grid's ends); `values`
/// holds `rows` values per node column, column after column.
fn fill_between_slices(values: &mut [f64], rows: usize, is_slice: &[bool], wf: &WheelFlank) {
    let slices: Vec<usize> = (0..is_slice.len()).filter(|&j| is_slice[j]).collect();
    if slices.is_empty() || slices.len() == is_slice.len() {
        return;
    }
    for j in (0..is_slice.len()).filter(|&j| !is_slice[j]) {
        let after = slices.partition_point(|&s| s < j);
        let (a, b) = match (after.checked_sub(1).map(|x| slices[x]), slices.get(after)) {
            (Some(a), Some(&b)) => (a, b),
            (Some(a), None) => (a, a),
            (None, Some(&b)) => (b, b),
            (None, None) => continue,
        };
        let t = if a == b {
            0.0
        } else {
            (wf.z[j] - wf.z[a]) / (wf.z[b] - wf.z[a])
        };
        for i in 0..rows {
            let (va, vb) = (values[a * rows + i], values[b * rows + i]);
            values[j * rows + i] = va + (vb - va) * t;
        }
    }
}

/// Rows of the plastic set for each row of the flank's grid (MODEL §5.7): enough for four
/// rows across a local cell of the band `band` (m), so that the set a running-in leaves is
/// read back by the next state's cells as they left it (sampled on the grid's own rows, a
/// yielded band narrower than a row was missed and indented again at every state, and the set
/// grew with the cells across the line). 1 for the purely elastic contact.
fn plastic_rows_per_row(wf: &WheelFlank, settings: &LtcaSettings, band: f64) -> usize {
    if !settings.flow_pressure.is_finite() {
        return 1;
    }
    let row = (0..=wf.cells_face)
        .map(|j| (wf.r_high[j] - wf.r_low[j]) / wf.cells_height as f64)
        .fold(0.0, f64::max);
    let cell = 2.0 * band / settings.columns.max(1) as f64;
    (4.0 * row / cell).ceil().clamp(1.0, 64.0) as usize
}

/// The changed flank on the global grid's nodes (MODEL §7.5, §5.7): the depth worn off and
/// the whole change (wear and plastic set) normal to the flank, m.
struct FlankShape {
    removal: FlankField,
    node_angle: Vec<f64>,
    deepest: f64,
}

impl FlankShape {
    /// None for an unchanged flank.
    fn new(wf: &WheelFlank, change: FlankChange) -> Option<Self> {
        if change.removal.is_none() && change.plastic_set.is_none() {
            return None;
        }
        let removal = change
            .removal
            .cloned()
            .unwrap_or_else(|| FlankField::zeros(wf));
        let mut whole = removal.clone();
        if let Some(set) = change.plastic_set {
            for (h, s) in whole
                .values
                .iter_mut()
                .zip(&set.with_rows(wf.cells_height).values)
            {
                *h += s;
            }
        }
        Some(Self {
            node_angle: Worn::node_angles(wf, &whole),
            deepest: whole.max(),
            removal,
        })
    }

    fn worn<'a>(&'a self, plastic_set: Option<&'a FlankField>) -> Worn<'a> {
        Worn {
            depth: &self.removal,
            plastic_set,
            node_angle: &self.node_angle,
            deepest: self.deepest,
        }
    }
}

/// A changed flank as the local meshes read it (MODEL §7.5, §5.7): the depth worn off normal
/// to the flank (m, above the worm-tip trace), the plastic set on its finer rows (m), at each
/// node of the global grid the whole change as an angle over the node's lever |(P x n)_z|
/// (rad), and the largest change, computed once per analysis.
#[derive(Clone, Copy)]
struct Worn<'a> {
    depth: &'a FlankField,
    plastic_set: Option<&'a FlankField>,
    node_angle: &'a [f64],
    deepest: f64,
}

impl Worn<'_> {
    /// The depth at each node over the node's lever (the lever is rotation invariant about
    /// the wheel axis), rad.
    fn node_angles(wf: &WheelFlank, depth: &FlankField) -> Vec<f64> {
        wf.nodes
            .iter()
            .zip(&depth.values)
            .map(|(p, h)| h / GapEvaluator::lever(&p.position(), &p.normal_vec()))
            .collect()
    }
}

/// One slice of a local mesh: a strip across the contact line of one tooth at face position
/// z, with the line crossing r_line.
#[derive(Debug, Clone, Copy)]
struct Slice {
    tooth: i32,
    tooth_index: usize,
    /// Node column.
    base: usize,
    z: f64,
    /// Half extent along the face width, m.
    half_dz: f64,
    r_line: f64,
    /// The line's vector over the slice extent (worm frame), None at flank ends.
    line_step: Option<Vector3<f64>>,
}

/// Builds the local mesh of one position with band half-width `band` (m) (MODEL §5.1):
/// every `slice_step`-th node column crossed by a tooth's contact line is a slice.
#[allow(clippy::too_many_arguments)]
fn local_mesh(
    tca: &Tca,
    ev: &GapEvaluator,
    wf: &WheelFlank,
    settings: &LtcaSettings,
    teeth: u32,
    n: usize,
    band: f64,
    worn: Option<Worn>,
) -> Vec<LocalCell> {
    let pos = tca.positions[n];
    let tau = 2.0 * PI / teeth as f64;
    let step = settings.slice_step.max(1);
    let base_dz = (wf.z[1] - wf.z[0]) * step as f64;
    // Separation threshold for slices whose minimum is not a crossing (flank edges); on a worn
    // flank the edges left standing can be the first to touch: raised by the deepest wear.
    let edge_threshold = 50e-6 + worn.map_or(0.0, |w| w.deepest);
    // Line crossings of every node column at this position, to follow the line.
    let crossings: std::collections::HashMap<(i32, usize), &crate::kinematics::SliceContact> = tca
        .contact_lines
        .iter()
        .filter(|c| c.position == n && !c.at_end && c.separation.is_finite())
        .map(|c| ((c.tooth, c.slice), c))
        .collect();
    let offset_of = |tooth: i32| tca.sigma * tooth as f64 * tau;
    let line_point = |c: &crate::kinematics::SliceContact| {
        wheel_point(c.r, c.theta + offset_of(c.tooth), c.z, pos.theta2)
    };
    // Line direction at node column j of a tooth, scaled to a face-width advance of 1 m.
    let direction = |tooth: i32, j: usize| -> Option<Vector3<f64>> {
        let here = crossings.get(&(tooth, j))?;
        let before = j.checked_sub(1).and_then(|i| crossings.get(&(tooth, i)));
        let after = crossings.get(&(tooth, j + 1));
        let (a, b) = match (before, after) {
            (Some(a), Some(b)) => (line_point(a), line_point(b)),
            (Some(a), None) => (line_point(a), line_point(here)),
            (None, Some(b)) => (line_point(here), line_point(b)),
            (None, None) => return None,
        };
        let dz = b.z - a.z;
        (dz.abs() > 0.0).then(|| ev.placement.vector_wheel_to_worm(&((b - a) / dz)))
    };
    // Worn material exists only where the worm flank reaches (above the worm-tip trace).
    let tip_floor: Vec<f64> = if worn.is_some() {
        tca.tip_trace.iter().map(|t| t.1).collect()
    } else {
        Vec::new()
    };
    let mut base = Vec::new();
    for line in tca
        .contact_lines
        .iter()
        .filter(|c| c.position == n && c.slice % step == 0)
    {
        if !line.separation.is_finite() || (line.at_end && line.separation > edge_threshold) {
            continue;
        }
        let tooth_index = tca.teeth.iter().position(|&k| k == line.tooth).unwrap_or(0);
        // On a worn flank the band goes where the worn gap is smallest on the column (the TCA
        // node gaps plus the removal over each node's lever), which need not be the unworn line.
        let (r_line, at_end) = match worn {
            Some(w) => worn_minimum(tca, wf, w.node_angle, n, tooth_index, line),
            None => (line.r, line.at_end),
        };
        base.push(Slice {
            tooth: line.tooth,
            tooth_index,
            base: line.slice,
            z: wf.z[line.slice],
            half_dz: 0.5 * base_dz,
            r_line,
            line_step: if at_end {
                None
            } else {
                direction(line.tooth, line.slice).map(|d| d * base_dz)
            },
        });
    }
    base.iter()
        .flat_map(|s| {
            slice_cells(
                s,
                tca,
                ev,
                wf,
                settings,
                n,
                band,
                offset_of(s.tooth),
                worn,
                &tip_floor,
            )
        })
        .collect()
}

/// Radius of the smallest worn angular gap on the node column of `line` (tooth index t,
/// position n), and whether it is at a column end: the parabola through the best node and its
/// neighbours, less the same fit's bias on the unworn gaps (their minimum is the TCA's exact
/// line crossing), so that a flank worn by the same angle everywhere keeps the unworn line.
fn worn_minimum(
    tca: &Tca,
    wf: &WheelFlank,
    node_angle: &[f64],
    n: usize,
    t: usize,
    line: &crate::kinematics::SliceContact,
) -> (f64, bool) {
    let (ni, j) = (wf.cells_height, line.slice);
    let nodes = wf.nodes.len();
    let base = (n * tca.teeth.len() + t) * nodes;
    let gaps = |worn: bool| -> Vec<f64> {
        (0..=ni)
            .map(|i| {
                let k = j * (ni + 1) + i;
                tca.node_gaps[base + k] + if worn { node_angle[k] } else { 0.0 }
            })
            .collect()
    };
    let r = |i: usize| wf.node(i, j).r;
    // Parabola vertex through the smallest node and its neighbours (None at a column end).
    let vertex = |values: &[f64]| -> Option<(usize, Option<f64>)> {
        let (best, _) = values
            .iter()
            .enumerate()
            .filter(|(_, v)| v.is_finite())
            .min_by(|a, b| a.1.total_cmp(b.1))?;
        if best == 0 || best == ni || !values[best - 1].is_finite() || !values[best + 1].is_finite()
        {
            return Some((best, None));
        }
        let (a, b, c) = (values[best - 1], values[best], values[best + 1]);
        let den = a - 2.0 * b + c;
        let shift = if den > 0.0 { 0.5 * (a - c) / den } else { 0.0 };
        let h = r(best + 1) - r(best);
        Some((best, Some(r(best) + shift.clamp(-0.5, 0.5) * h)))
    };
    let Some((best, worn)) = vertex(&gaps(true)) else {
        return (line.r, line.at_end);
    };
    let unworn = vertex(&gaps(false));
    match (worn, unworn) {
        // Where the wear leaves the smallest node where it was, the nodes' fit is only a
        // correction to the TCA's exact line: its bias on the unworn gaps is taken off, and a
        // fit cut by the column's end (the worm-tip trace, the blank top) keeps the TCA line.
        (None, Some((b0, None))) if b0 == best => (line.r, line.at_end),
        (None, _) => (r(best), true),
        (Some(worn), Some((_, Some(unworn)))) if !line.at_end => {
            let h = r(best + 1) - r(best);
            (worn - (unworn - line.r).clamp(-h, h), false)
        }
        (Some(worn), _) => (worn, false),
    }
}

/// The cells of one slice: `columns` cells of width 2 band / columns along the flank's
/// radial direction, centred on the line crossing.
#[allow(clippy::too_many_arguments)]
fn slice_cells(
    slice: &Slice,
    tca: &Tca,
    ev: &GapEvaluator,
    wf: &WheelFlank,
    settings: &LtcaSettings,
    n: usize,
    band: f64,
    offset: f64,
    worn: Option<Worn>,
    tip_floor: &[f64],
) -> Vec<LocalCell> {
    let pos = tca.positions[n];
    let nc = settings.columns.max(1);
    let ds = 2.0 * band / nc as f64;
    let z = slice.z;
    let (lo, hi) = wf.radial_range_at(z);
    let (_, slope) = wf.theta_at(slice.r_line, z);
    let drds = 1.0 / (1.0 + (slice.r_line * slope).powi(2)).sqrt();
    let mut cells = Vec::with_capacity(nc);
    for k in 0..nc {
        let s = (k as f64 - 0.5 * (nc as f64 - 1.0)) * ds;
        let r = slice.r_line + s * drds;
        if r < lo || r > hi {
            continue;
        }
        let (theta, slope) = wf.theta_at(r, z);
        let (e, worm_gradient) =
            ev.angular_with_gradient(r, theta + offset, z, pos.theta2, pos.theta1);
        if !e.is_finite() {
            continue;
        }
        let nb = wf.normal_at(r, z);
        let stat = wheel_point(r, theta + offset, z, pos.theta2);
        let mut n_stat = from_wheel_body(&nb, offset + pos.theta2);
        let centre = ev.placement.wheel_to_worm(&stat);
        let relief = ev
            .relief(r, z, (centre.y * centre.y + centre.z * centre.z).sqrt())
            .0;
        let mut normal = ev.placement.vector_wheel_to_worm(&n_stat);
        // A depth worn off the wheel flank is normal to it: its angle is over the wheel's lever.
        let wheel_lever = GapEvaluator::lever(&stat, &n_stat);
        if settings.pressure_direction == crate::input::PressureDirection::WormFlank {
            (normal, n_stat) = worm_flank_direction(ev, worm_gradient, &normal);
        }
        let lever = GapEvaluator::lever(&stat, &n_stat);
        let dpdr = ev.placement.vector_wheel_to_worm(&from_wheel_body(
            &radial_tangent(r, theta + offset, slope),
            pos.theta2,
        ));
        let (axis_nu, axis_zeta, half_nu, half_zeta) = cell_axes(slice, &normal, &dpdr, ds);
        cells.push(LocalCell {
            cell: ContactCell {
                centre,
                normal,
                axis_nu,
                axis_zeta,
                half_nu,
                half_zeta,
            },
            tooth: slice.tooth,
            tooth_index: slice.tooth_index,
            slice: slice.base,
            column: k,
            r,
            z,
            half_dz: slice.half_dz,
            lever,
            wheel_centre: stat,
            wheel_normal: n_stat,
            worm_lever: centre.cross(&normal).x,
            separation: e
                + pos.kinematic_error
                + worn.map_or(0.0, |w| {
                    // The plastic set also below the worm-tip trace: the tip's edge indents
                    // the cells it crosses.
                    let set = w.plastic_set.map_or(0.0, |s| s.at(wf, r, z));
                    (w.depth.at_above(wf, r, z, Some(tip_floor)) + set) / wheel_lever
                }),
            relief,
        });
    }
    cells
}

/// d P / d r of the wheel flank point at radius r and body angle theta with d theta / d r =
/// `slope` (body frame, m/m).
fn radial_tangent(r: f64, theta: f64, slope: f64) -> Vector3<f64> {
    let (st, ct) = theta.sin_cos();
    Vector3::new(ct - r * st * slope, -st - r * ct * slope, 0.0)
}

/// In-plane axes (across, along the contact line) and half sides (m) of a local cell with unit
/// normal `normal` and the flank's radial tangent `dpdr` (worm frame), `ds` wide across: the
/// parallelogram of sides `ds` along the radial direction and the line's step along the line,
/// taken as the rectangle of the same area aligned with the line (exact tiling of a band of
/// straight lines); at a flank end (no line step) the radial rectangle of the slice.
fn cell_axes(
    slice: &Slice,
    normal: &Vector3<f64>,
    dpdr: &Vector3<f64>,
    ds: f64,
) -> (Vector3<f64>, Vector3<f64>, f64, f64) {
    let radial = (dpdr - normal * dpdr.dot(normal)).normalize();
    match slice.line_step {
        Some(a) => {
            let a = a - normal * a.dot(normal);
            let along = a.norm();
            let zeta = a / along;
            (
                zeta.cross(normal),
                zeta,
                0.5 * ds * radial.cross(&zeta).norm(),
                0.5 * along,
            )
        }
        None => (radial, normal.cross(&radial), 0.5 * ds, slice.half_dz),
    }
}

/// The pressure direction along the worm flank's normal where the gap of a wheel point is
/// measured to (see `PressureDirection`), from the worm flank's axial-gap gradient there
/// ([`GapEvaluator::angular_with_gradient`]): worm-frame and stationary wheel-frame components,
/// oriented like the wheel normal `wheel_normal` (worm frame).
fn worm_flank_direction(
    ev: &GapEvaluator,
    gradient: [f64; 2],
    wheel_normal: &Vector3<f64>,
) -> (Vector3<f64>, Vector3<f64>) {
    let n = GapEvaluator::worm_normal_from(gradient, wheel_normal);
    (n, ev.placement.vector_worm_to_wheel(&n))
}

#[allow(clippy::too_many_arguments)]
fn solve_position(
    geo: &Geometry,
    tca: &Tca,
    ev: &GapEvaluator,
    wf: &WheelFlank,
    pair: &ElasticPair,
    settings: &LtcaSettings,
    bending: Option<&dyn BendingModel>,
    n: usize,
    band0: f64,
    worm_torque: Option<f64>,
    wheel_torque_guess: f64,
    worn: Option<Worn>,
    seed: Option<&WarmStart>,
) -> Result<PositionResult, LtcaError> {
    let mut band = band0;
    let mut widenings = 0;
    loop {
        let cells = local_mesh(tca, ev, wf, settings, geo.teeth, n, band, worn);
        if cells.is_empty() {
            return Err(LtcaError::NoContact(n));
        }
        if cells.len() > MAX_CONTACT_CELLS {
            return Err(LtcaError::TooManyCells {
                position: n,
                cells: cells.len(),
                columns: settings.columns,
                slice_step: settings.slice_step,
            });
        }
        // The previous analysis' loads on the same cells (the first mesh only: a widened band
        // puts other points under the same indices).
        let mut warm: Option<Vec<f64>> = seed
            .filter(|_| widenings == 0)
            .and_then(|s| s.for_cells(n, &cells));
        // Blocks per tooth (cells are grouped by tooth in mesh order), assembled in parallel.
        let mut ranges = Vec::new();
        let mut start = 0;
        while start < cells.len() {
            let t = cells[start].tooth_index;
            let mut end = start;
            while end < cells.len() && cells[end].tooth_index == t {
                end += 1;
            }
            ranges.push((start, end - start));
            start = end;
        }
        let blocks: Vec<Block> = ranges
            .into_iter()
            .map(|(start, size)| {
                // Upper triangle, mirrored: Love's term is symmetric for equal cells; the cells
                // of a tooth differ only slightly (line-aligned areas vary by the line's
                // obliquity), and the tangential term's small asymmetry on curved flanks is
                // dropped. Entries are assembled as the solver reads them: the rows of the
                // cells that carry load, and the screened solve's candidate block.
                let group = &cells[start..start + size];
                let contact: Vec<_> = group.iter().map(|c| c.cell).collect();
                let levers: Vec<f64> = group.iter().map(|c| c.lever).collect();
                Block {
                    start,
                    size,
                    matrix: BlockMatrix::Lazy(Box::new(InfluenceRows::new(
                        pair, &contact, &levers,
                    ))),
                }
            })
            .collect();
        let low_rank = bending.map(|b| {
            let mut lr = b.coefficients(&cells);
            for (i, c) in cells.iter().enumerate() {
                lr.divide_row(i, c.lever);
            }
            lr
        });
        // Sign of the worm moments: all loaded cells push the worm the same way.
        let sign = {
            let s: f64 = cells.iter().map(|c| c.worm_lever.signum()).sum();
            if s == 0.0 {
                return Err(LtcaError::TorqueSign(n));
            }
            s.signum()
        };
        let upper = settings.flow_pressure.is_finite().then(|| {
            cells
                .iter()
                .map(|c| settings.flow_pressure * c.cell.area() * c.lever)
                .collect()
        });
        let mut problem = Problem {
            upper,
            blocks,
            low_rank,
            separation: cells.iter().map(|c| c.separation).collect(),
            load: wheel_torque_guess,
        };
        let mut solution = None;
        let weights: Vec<f64> = cells
            .iter()
            .map(|c| c.worm_lever * sign / c.lever)
            .collect();
        let worm_of = |q: &[f64]| -> f64 { weights.iter().zip(q).map(|(w, q)| w * q).sum() };
        // Outer update of the wheel torque until the worm torque balances (MODEL §5.2): with
        // the fast solver, one exact affine step on the loaded set after the first solve; the
        // fixed-point solver (and any change of the loaded set) iterates, by secants on the
        // (wheel torque, worm torque) pairs: with cells at the flow pressure (MODEL §5.7) the
        // worm torque is not proportional to the wheel torque and a plain rescaling can cycle.
        let mut previous = None;
        for it in 0..20 {
            let sol =
                solver::solve(&problem, &settings.solver, warm.as_deref()).map_err(|source| {
                    LtcaError::Solver {
                        position: n,
                        source,
                    }
                })?;
            let worm = worm_of(&sol.q);
            let target = match worm_torque {
                Some(t) => t,
                None => {
                    solution = Some((sol, worm));
                    break;
                }
            };
            let ratio = target / worm;
            if (ratio - 1.0).abs() < 1e-9 {
                solution = Some((sol, worm));
                break;
            }
            if it == 0 && settings.solver.kind == SolverKind::ConjugateGradient {
                if let Some((updated, load)) =
                    solver::affine_load_update(&problem, &sol, &weights, target, &settings.solver)
                {
                    problem.load = load;
                    let worm = worm_of(&updated.q);
                    let close = ((worm - target) / target).abs() < 1e-9;
                    warm = Some(updated.q.clone());
                    solution = Some((updated, worm));
                    if close {
                        break;
                    }
                    continue;
                }
            }
            let next = next_wheel_torque(previous, (problem.load, worm), target);
            previous = Some((problem.load, worm));
            problem.load = next;
            warm = Some(sol.q.clone());
            solution = Some((sol, worm));
        }
        let (sol, worm) = solution.expect("at least one solve");
        // Load at the band edge: widen and redo.
        let nc = settings.columns;
        let qmax = sol.q.iter().copied().fold(0.0, f64::max);
        let at_edge = cells
            .iter()
            .zip(&sol.q)
            .any(|(c, &q)| q > 1e-6 * qmax && (c.column == 0 || c.column == nc - 1));
        if at_edge && widenings < 4 {
            band *= 1.6;
            widenings += 1;
            continue;
        }
        let (forces, pressure, plastic_depth) =
            cell_loads(&cells, &sol.q, &sol.gap, settings.flow_pressure);
        let mut tooth_load = vec![0.0; tca.teeth.len()];
        for (c, f) in cells.iter().zip(&forces) {
            tooth_load[c.tooth_index] += f;
        }
        let total_force: f64 = forces.iter().sum();
        let lever_b = barycentre_lever(&ev.placement, &cells, &forces, total_force);
        let approach = sol.approach;
        let target = worm_torque.unwrap_or(worm);
        return Ok(PositionResult {
            position: n,
            tooth_load,
            wheel_torque: problem.load,
            worm_torque: worm,
            approach,
            transmission_error: tca.positions[n].kinematic_error - approach,
            stiffness_angular: problem.load / approach,
            stiffness_linear: total_force / (approach * lever_b),
            max_pressure: pressure.iter().copied().fold(0.0, f64::max),
            residuals: sol.residuals,
            torque_residual: (worm - target).abs() / target,
            pressure,
            plastic_depth,
            equivalent: Vec::new(),
            cells,
            band_widenings: widenings,
        });
    }
}

/// Per local cell: the normal force (N), the pressure (Pa) and the plastic depth (m: the
/// interference of a cell at the flow pressure, MODEL §5.7) from the solver's loads q (N m)
/// and gaps (rad).
fn cell_loads(
    cells: &[LocalCell],
    q: &[f64],
    gap: &[f64],
    flow_pressure: f64,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let forces: Vec<f64> = cells.iter().zip(q).map(|(c, q)| q / c.lever).collect();
    let pressure: Vec<f64> = cells
        .iter()
        .zip(&forces)
        // (The bound holds on q = p S lever; the division's round-off stays below it.)
        .map(|(c, f)| (f / c.cell.area()).min(flow_pressure))
        .collect();
    let plastic_depth: Vec<f64> = cells
        .iter()
        .zip(&pressure)
        .zip(gap)
        .map(|((c, &p), &y)| {
            let at_bound = p >= flow_pressure * (1.0 - 1e-12);
            if at_bound && y < 0.0 {
                -y * c.lever
            } else {
                0.0
            }
        })
        .collect();
    (forces, pressure, plastic_depth)
}

/// Lever |(B x n)_z| (m) of the force barycentre B with the force-weighted mean normal n
/// (MODEL §5.6), for the linear mesh stiffness.
fn barycentre_lever(
    placement: &crate::input::Placement,
    cells: &[LocalCell],
    forces: &[f64],
    total_force: f64,
) -> f64 {
    let mut b = Vector3::zeros();
    let mut nsum = Vector3::zeros();
    for (c, f) in cells.iter().zip(forces) {
        b += c.cell.centre * *f;
        nsum += c.cell.normal * *f;
    }
    let b_wheel = placement.worm_to_wheel(&(b / total_force));
    let n_wheel = placement.vector_worm_to_wheel(&nsum.normalize());
    GapEvaluator::lever(&b_wheel, &n_wheel)
}

/// The next wheel torque (N m) of the torque balance (MODEL §5.2) from the last two
/// (wheel torque, worm torque) pairs: the secant through them where it rises (the worm torque
/// grows with the wheel torque), else the rescaling by target / worm of the last one.
fn next_wheel_torque(previous: Option<(f64, f64)>, last: (f64, f64), target: f64) -> f64 {
    let (load, worm) = last;
    let rescaled = load * target / worm;
    let Some((load0, worm0)) = previous else {
        return rescaled;
    };
    let slope = (worm - worm0) / (load - load0);
    let secant = load + (target - worm) / slope;
    if slope.is_finite() && slope > 0.0 && secant > 0.0 {
        secant
    } else {
        rescaled
    }
}

/// Largest mean pressure over a patch `across` wide across the contact line and `along` long
/// along the face width (m), over every tooth at every position, Pa: the pressure of a "cell
/// of stated size". At a sharp edge the local cells' own maximum grows as the mesh is refined
/// (an integrable singularity); this mean converges. Cells are placed in (distance across the
/// line from the band's first column, z) with their widths 2 half_nu and 2 half_dz; pressure is
/// zero outside the cells. The largest mean has a window end on a cell boundary in each
/// direction, which is where the candidates are taken.
pub fn max_patch_pressure(positions: &[PositionResult], across: f64, along: f64) -> f64 {
    positions
        .par_iter()
        .map(|p| {
            // (across lo, across hi, z lo, z hi, pressure) of the loaded cells, per tooth.
            let mut teeth: std::collections::BTreeMap<usize, Vec<[f64; 5]>> = Default::default();
            for (c, &pr) in p.cells.iter().zip(&p.pressure) {
                if pr <= 0.0 {
                    continue;
                }
                let w = 2.0 * c.cell.half_nu;
                teeth.entry(c.tooth_index).or_default().push([
                    c.column as f64 * w,
                    (c.column + 1) as f64 * w,
                    c.z - c.half_dz,
                    c.z + c.half_dz,
                    pr,
                ]);
            }
            teeth
                .values()
                .map(|cells| patch_mean_max(cells, across, along))
                .fold(0.0, f64::max)
        })
        .reduce(|| 0.0, f64::max)
}

/// [`max_patch_pressure`] over one tooth's loaded cells.
fn patch_mean_max(cells: &[[f64; 5]], across: f64, along: f64) -> f64 {
    // Cells sorted by their z extent's start: a window's cells are found by bisection.
    let mut cells = cells.to_vec();
    cells.sort_by(|a, b| a[2].total_cmp(&b[2]));
    let longest = cells.iter().map(|c| c[3] - c[2]).fold(0.0, f64::max);
    let mut best: f64 = 0.0;
    for c in &cells {
        for x0 in [c[0], c[1] - across] {
            for z0 in [c[2], c[3] - along] {
                let (x1, z1) = (x0 + across, z0 + along);
                let first = cells.partition_point(|d| d[2] < z0 - longest);
                let force: f64 = cells[first..]
                    .iter()
                    .take_while(|d| d[2] < z1)
                    .map(|d| {
                        let ox = (d[1].min(x1) - d[0].max(x0)).max(0.0);
                        let oz = (d[3].min(z1) - d[2].max(z0)).max(0.0);
                        d[4] * ox * oz
                    })
                    .sum();
                best = best.max(force / (across * along));
            }
        }
    }
    best
}
