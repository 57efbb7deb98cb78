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
//!
//! Rooms: `mesh` the local contact mesh, `position` the solve at one position, `pattern` what
//! the positions give over the cycle, [`solver`] the complementarity solvers, `passage` the
//! band's passage over a node for the wear; here the settings, the results, the errors and the
//! analyses over the positions.

mod mesh;
mod orders;
pub(crate) mod passage;
mod pattern;
mod position;
pub mod solver;
mod traction;

use mesh::*;
pub use orders::{mesh_order_amplitudes, TeOrders};
pub use pattern::*;
pub use position::CellLoad;
use position::*;
use traction::torque_weights;
pub use traction::{
    cell_sliding, CellSliding, ContactLineRadii, FilmGeometry, FrictionInputs, PositionFriction,
};

use crate::contact::{hertz_half_width, ContactCell, ElasticPair};
use crate::geometry::placement::{from_wheel_body, wheel_point};
use crate::geometry::{FlankField, Geometry, WheelFlank};
use crate::input::{GearSet, Torque};
use crate::kinematics::{GapEvaluator, Tca};
use crate::subsurface::{Criterion, Equivalent, SubsurfaceSettings};
use nalgebra::Vector3;
use rayon::prelude::*;
use solver::{Block, LowRank, Problem, Residuals, SolverError, SolverKind, SolverSettings};
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
    /// How the band grows where the contact reaches its edge (MODEL §5.1).
    pub band_growth: crate::input::BandGrowth,
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
    /// Which torque the pressures carry (MODEL §5.2).
    pub torque_balance: crate::input::TorqueBalance,
    /// Oil temperature of the friction the transmitted torque carries, K (the lubricant's,
    /// or the heat balance's, MODEL §13).
    pub oil_temperature: f64,
    /// The sub-surface stress criterion of the equivalent pressure (MODEL §8.1).
    pub subsurface: SubsurfaceSettings,
    /// How far above the worm tip's trace its rounded tip edge reaches on the wheel flank,
    /// R (1 - sin alpha_x) with R `worm.tip_edge_radius` (MODEL §2.3), m; 0 for a sharp
    /// edge. The warnings count a flow pressure up to there as the worm tip's.
    pub tip_edge_height: f64,
}

impl LtcaSettings {
    /// Most cells a slice's band may grow by on each side when it extends, in bands' worth
    /// of cells (`columns` each): up to seven times the base band in all (MODEL §5.1).
    pub const EXTENSION_BANDS: usize = 3;

    /// The column index of a slice's first base cell: 0 when the band widens, room for the
    /// largest extension below it when it extends (so that a cell's column names the same
    /// place across the line whatever its slice's extension).
    pub fn column_offset(&self) -> usize {
        match self.band_growth {
            crate::input::BandGrowth::Widen => 0,
            crate::input::BandGrowth::Extend => Self::EXTENSION_BANDS * self.columns.max(1),
        }
    }

    /// The column that aligns the slices across the line where the band grows by extension
    /// ([`max_patch_pressure`]'s offset); None where it widens.
    pub fn aligned_columns(&self) -> Option<usize> {
        (self.band_growth == crate::input::BandGrowth::Extend).then(|| self.column_offset())
    }

    pub fn from_gear(gear: &GearSet) -> Self {
        let a = &gear.analysis;
        Self {
            slice_step: a.contact_slice_step,
            columns: a.contact_columns,
            band_factor: a.contact_band_factor,
            band_growth: a.contact_band_growth,
            flow_pressure: a.contact.pressure_bound(),
            patch_across: a.pressure_patch_across,
            patch_along: a.pressure_patch_along,
            solver: SolverSettings::for_kind(a.solver),
            pressure_direction: a.pressure_direction,
            torque_balance: a.torque_balance,
            oil_temperature: gear.lubricant.temperature,
            subsurface: SubsurfaceSettings {
                criterion: gear
                    .wear
                    .as_ref()
                    .map_or(Criterion::PrincipalShear, |w| w.pitting_stress.criterion()),
                ..SubsurfaceSettings::new(gear.wheel_material.poisson_ratio)
            },
            tip_edge_height: gear.worm.tip_edge_radius
                * (1.0 - gear.worm.axial_pressure_angle.sin()),
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
    /// Slice (node column) and column across the line (ascending radii; with the band grown
    /// by extension, the first base column is [`LtcaSettings::column_offset`]).
    pub slice: usize,
    pub column: usize,
    /// The first and last column of the cell's slice band (cells outside the flank are not
    /// made: a band cut by the flank has no cell at its end column).
    pub band_first: usize,
    pub band_last: usize,
    /// Flank coordinates (reference tooth), m.
    pub r: f64,
    pub z: f64,
    /// Radius where the slice's contact line crosses it (the base band's centre; on a worn
    /// flank the worn gap's minimum), m: where the slice's film is entrained (MODEL §6, §13),
    /// whatever the band's extent.
    pub line_r: f64,
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
    /// Wheel torque transmitted T2 (the moments of the pressures and, with friction, of the
    /// friction tractions about the wheel axis), N m.
    pub wheel_torque: f64,
    /// Worm torque balanced T1, N m.
    pub worm_torque: f64,
    /// Moment of the normal pressures alone about the wheel axis W = sum f l, N m: the load of
    /// the contact's compliance (approach, stiffness W / approach, the shaft's torsion); T2
    /// without the friction tractions' moments.
    pub normal_wheel_torque: f64,
    /// Rigid approach (wheel rotation against its driven sense), rad.
    pub approach: f64,
    /// Loaded transmission error = unloaded kinematic error - approach (driven sense,
    /// negative = lag), rad.
    pub transmission_error: f64,
    /// Angular mesh stiffness W / approach (W the normal pressures' wheel torque), N m/rad.
    pub stiffness_angular: f64,
    /// Linear mesh stiffness F / (approach x lever at the force barycentre), N/m.
    pub stiffness_linear: f64,
    pub max_pressure: f64,
    pub residuals: Residuals,
    /// Relative worm-torque balance error |sum f (M x n)_x - C_m| / C_m.
    pub torque_residual: f64,
    /// Friction coefficient of the local cells (same order as `cells`; zeros without friction,
    /// MODEL §5.2, §13).
    #[serde(skip)]
    pub friction: Vec<f64>,
    /// The worm torque the friction consumes, P_Vz / omega1 = sum mu f |v_g| / omega1, N m.
    pub friction_torque: f64,
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
    /// Share of the position's load on its bands' edge cells once the band stopped growing
    /// (0: the contact within its band; see [`Ltca::band_edge_share`]).
    #[serde(skip)]
    pub band_edge_share: f64,
}

/// Share of a position's load on its band's edge cells above which the contact is reported as
/// cut by the local mesh ([`Ltca::band_edge_share`]).
pub const BAND_EDGE_WARNING: f64 = 0.01;

impl PositionResult {
    /// The mesh force on the worm at this position: the sum over the loaded cells of pressure
    /// x area along the cell's normal (worm frame, N; its sign is the normal's convention).
    pub fn worm_force(&self) -> nalgebra::Vector3<f64> {
        self.cells
            .iter()
            .zip(&self.pressure)
            .map(|(c, &p)| c.cell.normal * (p * c.cell.area()))
            .sum()
    }
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
    /// Mean of the non-zero pattern cells weighted by their areas, Pa.
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
    /// Largest equivalent pressure of any local cell, Pa (at a sharp edge: the flow
    /// pressure's plateau, MODEL §5.7).
    pub equivalent_pressure_max: f64,
    /// p_eq,2%: the equivalent pressure exceeded on 2 % of the active flank (MODEL §8.1,
    /// "Which p_eq decides"; [`crate::pitting::exceeded_on_share`] of `equivalent_pattern`), Pa:
    /// what the pitting safety reads.
    pub equivalent_pressure_first_pitting: f64,
    /// Where the cells at or above p_eq,2% lie (MODEL §8.1; shares of the active flank at the
    /// worm tip's trace, the face ends, the blank top and elsewhere; zeros for no load).
    pub first_pitting_places: FlankPlaces,
    /// How the equivalent pressure was evaluated (its criterion, the wheel's Poisson ratio).
    pub subsurface: SubsurfaceSettings,
    /// Mean worm torque T1 and transmitted wheel torque T2 over the positions, N m.
    pub worm_torque: f64,
    pub wheel_torque: f64,
    /// Ratio u = z2 / z1.
    pub ratio: f64,
    /// Which torque the pressures carry (MODEL §5.2).
    pub torque_balance: crate::input::TorqueBalance,
    /// The mesh efficiency the torques carry, eta_z = T2 / (u T1) (1 for frictionless
    /// pressures, to the power balance).
    pub mesh_efficiency: f64,
    /// Power balance over the pitch: (mean T2 / u + the friction's worm torque P_Vz /
    /// omega1) / mean T1, less 1 (0 for a model consistent with the kinematics; beyond
    /// [`POWER_BALANCE_LIMIT`] the contact is at non-conjugate points, see `warnings`).
    pub power_balance: f64,
    /// The worm's broken tip edge against the contact cells where its contact spans less
    /// than [`RESOLVED_CELLS_ACROSS`] of them (MODEL §2.3, §5.1); None: a sharp tip, or a
    /// round the cells resolve.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tip_edge_resolution: Option<TipEdgeResolution>,
    /// What makes these results doubtful, with the reason.
    pub warnings: Vec<String>,
    /// The composite roughness R_q on the loaded flank's nodes after its running-in
    /// (MODEL §6.1), m; None: the lubricant's `composite_roughness` everywhere.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub roughness: Option<FlankField>,
    /// The band's instants on each node column of the loaded flank, sorted by time (MODEL
    /// §5.6, §7.2, [`passage::band_samples`]): the loaded pattern's passages and the cycle's
    /// wear's.
    #[serde(skip)]
    pub(crate) passage_samples: std::sync::Arc<Vec<Vec<passage::Sample>>>,
}

/// Largest departure from the power balance (T2 omega2 + P_Vz = T1 omega1, MODEL §5.2) of a
/// trusted loaded analysis. The
/// aligned examples stay within 0.5 % (band cells off the contact line, the worm's tip edge).
pub const POWER_BALANCE_LIMIT: f64 = 0.02;

/// Warnings on a loaded analysis whose power balance departs by more than
/// [`POWER_BALANCE_LIMIT`]: the load sits at points where the pressure direction
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
        "the power balance over the pitch, T2 omega2 + P_Vz = T1 omega1 (mean wheel torque \
         {wheel:.1} N m, u x the worm torque {:.1} N m), departs by {:+.1} % (limit {} %): the \
         pressure \
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
    /// Mean angular mesh stiffness without the wheel shaft's torsion: W / (alpha - c_t W) with
    /// W the normal pressures' wheel torque, N m/rad (equal to [`Ltca::stiffness_mean`] when the model has no shaft torsion).
    pub fn stiffness_without_shaft_torsion_mean(&self) -> f64 {
        let c_t = self.shaft_torsion_compliance;
        stats(self.positions.iter().map(|p| {
            let w = p.normal_wheel_torque;
            w / (p.approach - c_t * w)
        }))
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

/// A load no flank of the gear can carry (None: it can; MODEL §5.7): each studied tooth's
/// active flank carries at most the flow pressure over its area, while the wheel torque T2
/// needs a normal load of at least T2 / r_a on the flanks (no contact force has a longer lever
/// about the wheel axis than the blank's outer radius r_a). A face width typed in metres (0.045
/// for 45 mm) fails it; the solver refused such a gear only at its first position, in terms of
/// its cells. None for the purely elastic contact (no flow pressure).
pub fn flank_capacity_problem(gear: &GearSet, geo: &Geometry) -> Option<String> {
    use crate::geometry::Flank;
    use crate::input::Number;
    let settings = LtcaSettings::from_gear(gear);
    if !settings.flow_pressure.is_finite() {
        return None;
    }
    let (_, wheel_torque) = torque_targets(gear, &settings);
    let needed = wheel_torque.abs() / gear.wheel.outer_radius;
    let teeth = 2 * gear.analysis.teeth_each_side + 1;
    let area = [Flank::Left, Flank::Right]
        .map(|f| geo.wheel_flank(f).active_area())
        .into_iter()
        .fold(0.0, f64::max);
    let capacity = settings.flow_pressure * area * teeth as f64;
    let (field, torque) = crate::rating::torque_field(gear);
    (needed > capacity).then(|| {
        format!(
            "{field} = {}: the wheel torque (about {:.0} N m) needs a normal load of at least \
             {:.0} N on the wheel's flanks (T2 over the blank's outer radius, \
             wheel.outer_radius_mm = {}), more than the {teeth} teeth the analysis studies can \
             carry at the flow pressure ({} MPa) on their active flanks of {:.4} mm^2 each \
             ({:.0} N in all): the flank is far too small for the load; check wheel.face_width_mm = {} \
             (millimetres) and the blank's radii, or lower the torque, or raise the flow \
             pressure (analysis.flow_pressure_mpa, by default materials.wheel.hardness_gpa)",
            Number(torque),
            wheel_torque.abs(),
            needed,
            Number(gear.wheel.outer_radius * 1e3),
            Number(settings.flow_pressure * 1e-6),
            area * 1e6,
            capacity,
            Number(gear.wheel.face_width * 1e3),
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
/// is the converged solution whatever the start (to the solver's tolerance); where the band
/// grows by extension it also gives each slice's extent to start from (its loaded cells and
/// one more each side: the same loaded cells, so the same contact, with fewer solves).
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WarmStart {
    pub positions: Vec<Vec<CellLoad>>,
}

impl WarmStart {
    /// The start for `cells` of position n: the load of the same (tooth, slice, column), 0 for
    /// a cell the previous analysis did not load; None when nothing matches.
    fn for_cells(&self, n: usize, cells: &[LocalCell]) -> Option<Vec<f64>> {
        position::start_for(self.positions.get(n)?, cells)
    }
}

impl Ltca {
    /// The largest share of a position's load on its band's edge cells once the band stopped
    /// growing (MODEL §5.1): 0 when every position's band holds its contact; above
    /// [`BAND_EDGE_WARNING`] the contact is cut by the local mesh, and the analysis warns.
    pub fn band_edge_share(&self) -> f64 {
        self.positions
            .iter()
            .map(|p| p.band_edge_share)
            .fold(0.0, f64::max)
    }

    /// [`Self::band_edge_share`] where above [`BAND_EDGE_WARNING`] (the contact cut by the
    /// local mesh), None where not.
    pub fn band_edge_share_warned(&self) -> Option<f64> {
        Some(self.band_edge_share()).filter(|&s| s > BAND_EDGE_WARNING)
    }

    /// The loads of this analysis as a start for the next ([`WarmStart`]).
    pub fn warm_start(&self) -> WarmStart {
        let loads = |p: &PositionResult| -> Vec<f64> {
            let cells = p.cells.iter().zip(&p.pressure);
            cells.map(|(c, pr)| pr * c.cell.area() * c.lever).collect()
        };
        WarmStart {
            positions: self
                .positions
                .iter()
                .map(|p| cell_loads_by_key(&p.cells, &loads(p)))
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
    let (worm_torque, wheel_torque_guess) = torque_targets(gear, settings);
    check_shaft_torsion(bending, wheel_torque_guess, gear.wheel.teeth)?;
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
    let oil = gear.lubricant.at_temperature(settings.oil_temperature);
    let roughness = crate::lubrication::running_in_roughness(&gear.lubricant, change.removal);
    let friction = position_friction((gear, geo, tca), settings, &oil, roughness.as_ref());

    let positions: Vec<PositionResult> = (0..tca.positions.len())
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
                friction.as_ref(),
            )
            .map(|mut p| {
                // In the position's own task: no second wait for the slowest (issue 55).
                p.equivalent = position_equivalents(&p, &settings.subsurface);
                p
            })
        })
        .collect::<Result<_, _>>()?;
    let ratio = geo.teeth as f64 / gear.worm.starts as f64;
    let mut ltca = Ltca {
        roughness,
        ..over_the_cycle(
            positions,
            (wf, tca, geo.teeth, ratio),
            settings,
            bending,
            rows_per_row,
        )
    };
    ltca.tip_edge_resolution = tip_edge_resolution(gear.worm.tip_edge_radius, &ltca, &pair);
    ltca.warnings
        .extend(ltca.tip_edge_resolution.map(|t| t.text()));
    Ok(ltca)
}

/// The worm's broken tip edge of radius `radius` (m; 0: sharp, None without gathering the
/// cells) against the loaded cells of `ltca` ([`TipEdgeResolution::of`], MODEL §2.3, §5.1).
fn tip_edge_resolution(radius: f64, ltca: &Ltca, pair: &ElasticPair) -> Option<TipEdgeResolution> {
    (radius > 0.0)
        .then(|| {
            TipEdgeResolution::of(
                radius,
                ltca.max_pressure,
                pair.effective_modulus,
                loaded_cell_width(&ltca.positions),
            )
        })
        .flatten()
}

/// Refuses a bending model whose shaft torsion alone would turn the wheel by more than a pitch
/// under the wheel torque `wheel_torque` (N m) on `teeth` teeth ([`shaft_torsion_problem`]).
fn check_shaft_torsion(
    bending: Option<&dyn BendingModel>,
    wheel_torque: f64,
    teeth: u32,
) -> Result<(), LtcaError> {
    let compliance = bending.map_or(0.0, |b| b.rigid_rotation_compliance());
    match bending.and(shaft_torsion_problem(compliance, wheel_torque, teeth)) {
        Some(problem) => Err(LtcaError::ShaftTorsion(problem)),
        None => Ok(()),
    }
}

/// The worm torque to balance (None: the wheel torque is given) and the wheel torque's
/// estimate that sizes the band and starts the solve, N m: the given wheel torque, or u T1,
/// times ISO/TR 14521's mesh efficiency at its base friction mu_0T (none of the rating's
/// factors Y, which must not move the contact) when the pressures carry the transmitted torque
/// (MODEL §5.2).
fn torque_targets(gear: &GearSet, settings: &LtcaSettings) -> (Option<f64>, f64) {
    let transmitted = settings.torque_balance == crate::input::TorqueBalance::Transmitted;
    match gear.conditions.torque {
        Torque::Worm(t) if transmitted => (
            Some(t),
            t * gear.ratio() * crate::rating::base_mesh_efficiency(gear),
        ),
        Torque::Worm(t) => (Some(t), t * gear.ratio()),
        Torque::Wheel(t) => (None, t),
    }
}

/// What the positions' friction needs (MODEL §5.2, §13) when the pressures carry the
/// transmitted torque; None for the frictionless reading. `oil`: the lubricant at the
/// analysis' oil temperature; `roughness`: the run-in roughness on the loaded flank's nodes
/// (MODEL §6.1; None: the lubricant's).
fn position_friction<'a>(
    (gear, geo, tca): (&'a GearSet, &'a Geometry, &Tca),
    settings: &LtcaSettings,
    oil: &'a crate::input::Lubricant,
    roughness: Option<&'a FlankField>,
) -> Option<PositionFriction<'a>> {
    let transmitted = settings.torque_balance == crate::input::TorqueBalance::Transmitted;
    let wf = geo.wheel_flank(tca.loaded_flank);
    transmitted.then(|| PositionFriction {
        gear,
        geo,
        film: FilmGeometry::new(tca, wf),
        inputs: FrictionInputs::of(gear, oil),
        roughness: crate::lubrication::FlankRoughness::of(oil, roughness, wf),
        estimate: crate::rating::base_friction(tca.pitch_sliding_speed),
    })
}

/// The warnings on a cycle's loaded pattern `pattern` (Pa per cell, its yielded share of the
/// flank `yielded_area_fraction`) and its positions: the flow pressure reached (MODEL §5.7;
/// the flow pressure and the tip edge's height from `settings`), the deflections, the band's
/// edge.
fn pattern_warnings(
    positions: &[PositionResult],
    (wf, tca, teeth): (&WheelFlank, &Tca, u32),
    (pattern, yielded_area_fraction): (&[f64], f64),
    settings: &LtcaSettings,
) -> Vec<String> {
    let flow_pressure = settings.flow_pressure;
    let trace = (tca.tip_trace.as_slice(), settings.tip_edge_height);
    let places = pattern::YieldedPlaces::of(wf, pattern, flow_pressure, trace);
    let mut warnings: Vec<String> =
        flow_pressure_warning(yielded_area_fraction, flow_pressure, &places)
            .into_iter()
            .collect();
    warnings.extend(pattern::local_flow_pressure_warning(
        positions,
        (yielded_area_fraction, flow_pressure),
        wf,
        trace,
    ));
    warnings.extend(deflection_warning(positions, tca, teeth));
    warnings.extend(band_edge_warning(positions));
    warnings
}

/// p_eq,2% of the equivalent pattern `equivalent` (Pa per global cell; MODEL §8.1: the level
/// exceeded on 2 % of the active flank, Pa) and where the cells at or above it lie (None
/// without load), with the worm tip's trace and the tip edge's height of `settings`.
fn first_pitting_level(
    wf: &WheelFlank,
    tca: &Tca,
    settings: &LtcaSettings,
    equivalent: &[f64],
) -> (f64, Option<pattern::YieldedPlaces>) {
    let level = crate::pitting::exceeded_on_share(
        equivalent,
        &wf.cell_area,
        &wf.active,
        crate::pitting::FIRST_PITTING_SHARE,
    );
    let trace = (tca.tip_trace.as_slice(), settings.tip_edge_height);
    let places = (level > 0.0).then(|| pattern::YieldedPlaces::of(wf, equivalent, level, trace));
    (level, places)
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
    // indentation (MODEL §5.7); the equivalent pressure's (MODEL §8.1). The band's instants
    // are kept for the cycle's wear (MODEL §7.2), which reads the same passages.
    let tau = 2.0 * std::f64::consts::PI / teeth as f64;
    let passage_samples = passage::band_samples(wf, tca, &positions, tau, settings.slice_step);
    let Swept {
        pattern,
        plastic_indentation,
        equivalent_pattern,
        equivalent_depth,
    } = swept_pattern(wf, tca, &passage_samples, teeth, rows_per_row);
    let equivalent_pressure_max = positions
        .iter()
        .flat_map(|p| p.equivalent.iter().map(|e| e.pressure))
        .fold(0.0, f64::max);
    let (equivalent_pressure_first_pitting, first_pitting_places) =
        first_pitting_level(wf, tca, settings, &equivalent_pattern);
    let stats = PatternStats::of(wf, &pattern, settings.flow_pressure);
    // The largest local cell (the published P_max): the pattern's cell centres read the
    // profiles between cell centres, which can only be lower.
    let max_pressure = positions.iter().map(|p| p.max_pressure).fold(0.0, f64::max);
    let (across, along) = (settings.patch_across, settings.patch_along);
    let pressure_patch_max =
        max_patch_pressure(&positions, across, along, settings.aligned_columns());
    let (worm_torque, wheel_torque, power_balance, mut warnings) =
        torque_balance(&positions, ratio, wf, &pattern);
    warnings.extend(pattern_warnings(
        &positions,
        (wf, tca, teeth),
        (&pattern, stats.yielded_area_fraction),
        settings,
    ));
    warnings.extend(first_pitting_places.as_ref().and_then(|places| {
        pattern::first_pitting_edge_warning(equivalent_pressure_first_pitting, places)
    }));
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
        equivalent_pressure_first_pitting,
        first_pitting_places: first_pitting_places
            .map_or_else(FlankPlaces::default, |p| p.places()),
        subsurface: settings.subsurface,
        worm_torque,
        wheel_torque,
        ratio,
        torque_balance: settings.torque_balance,
        mesh_efficiency: wheel_torque / (ratio * worm_torque),
        power_balance,
        tip_edge_resolution: None,
        warnings,
        roughness: None,
        passage_samples: std::sync::Arc::new(passage_samples),
    }
}
