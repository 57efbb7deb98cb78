//! Input model: the TOML gear file ([`schema`]), its validation, and the checked gear set in SI
//! units that every pipeline stage consumes.
//!
//! Loading never panics: syntax errors come back as [`InputError::Syntax`] (with the TOML
//! parser's line and key), and every semantic problem as a [`FieldError`] naming the field, its
//! value and the allowed range. All problems found are reported together.

mod duty;
mod life_plan;
pub mod schema;
mod syntax;
pub mod template;
mod validate;

use std::f64::consts::PI;
use std::fmt;
use std::path::Path;

pub use duty::{cycle_shares, largest_load_bin, DutyBin};
pub use life_plan::*;
pub use schema::GearFile;
use syntax::{parse_gear_file, syntax_error};
pub use validate::Number;

/// Profile type of a worm or hob thread (ISO 10828 designations; MODEL §2.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum ProfileType {
    /// ZA: straight edge in the axial plane.
    A,
    /// ZN: straight edge in the plane normal to the reference helix.
    N,
    /// ZI: involute helicoid (straight generator tangent to the base cylinder).
    I,
    /// ZK: ground by a biconical wheel.
    K,
    /// ZC: ground by a wheel with a circular-arc profile.
    C,
}

impl ProfileType {
    /// Every thread profile, in the order A, N, I, K, C.
    pub const ALL: [ProfileType; 5] = [
        ProfileType::A,
        ProfileType::N,
        ProfileType::I,
        ProfileType::K,
        ProfileType::C,
    ];
}

/// Hand of the thread.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Hand {
    Right,
    Left,
}

impl Hand {
    /// +1 for a right-hand thread, -1 for a left-hand one (sign of the helix term in MODEL §2.1).
    pub fn sign(self) -> f64 {
        match self {
            Hand::Right => 1.0,
            Hand::Left => -1.0,
        }
    }
}

/// Grinding wheel of a K or C thread (SI: m, rad).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct GrindingWheel {
    /// Radius R_g at the point that grinds the reference cylinder, m.
    pub radius: f64,
    /// Distance between grinding-wheel axis and thread axis, m.
    pub axis_distance: f64,
    /// Profile angle alpha_0 of the wheel flank, rad.
    pub profile_angle: f64,
    /// Radius rho_0 of the circular-arc profile, m (C only).
    pub profile_radius: Option<f64>,
}

/// A checked worm or hob thread, SI units (m, rad).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ThreadDef {
    pub profile: ProfileType,
    pub starts: u32,
    pub hand: Hand,
    /// Axial pitch p_x, m.
    pub axial_pitch: f64,
    /// Reference radius r1, m.
    pub reference_radius: f64,
    /// Tip radius, m.
    pub tip_radius: f64,
    /// Root radius, m.
    pub root_radius: f64,
    /// Nominal axial pressure angle of the tool, rad.
    pub axial_pressure_angle: f64,
    /// Nominal normal pressure angle of the tool, rad (tan a_n = tan a_x cos gamma).
    pub normal_pressure_angle: f64,
    /// Axial thread thickness at the reference radius, m.
    pub axial_thickness: f64,
    /// Grinding wheel (K and C only).
    pub grinding_wheel: Option<GrindingWheel>,
    /// Tip relief: amount at the edge (m; 0 = sharp) and length from the tip (m).
    pub tip_relief: EdgeRelief,
    /// Radius of the broken tip edge in the axial section, m (0 = sharp; MODEL §2.3).
    pub tip_edge_radius: f64,
}

/// A parabolic edge relief C (s / L)^2 over the last L before an edge (m, m).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct EdgeRelief {
    /// Relief C at the edge, m (0 = sharp edge).
    pub amount: f64,
    /// Length L of the relief zone, m.
    pub length: f64,
}

impl EdgeRelief {
    /// Default: a sharp edge (the published model has no relief, MODEL §12 i); the zone
    /// length 1 mm applies when only an amount is given.
    pub const SHARP: EdgeRelief = EdgeRelief {
        amount: 0.0,
        length: 1e-3,
    };

    /// Relief and its derivative at distance `s` into the zone (s <= 0: outside the zone).
    #[inline]
    pub fn at(&self, s: f64) -> (f64, f64) {
        if self.amount <= 0.0 || s <= 0.0 {
            return (0.0, 0.0);
        }
        let k = self.amount / (self.length * self.length);
        (k * s * s, 2.0 * k * s)
    }
}

impl ThreadDef {
    /// Axial module m_x = p_x / pi, m.
    pub fn axial_module(&self) -> f64 {
        self.axial_pitch / PI
    }
    /// Lead p_z = z1 p_x, m.
    pub fn lead(&self) -> f64 {
        self.axial_pitch * self.starts as f64
    }
    /// Lead per radian h = p_z / (2 pi), m/rad.
    pub fn lead_per_rad(&self) -> f64 {
        self.lead() / (2.0 * PI)
    }
    /// Lead angle at the reference radius, tan(gamma) = p_z / (2 pi r1), rad.
    pub fn lead_angle(&self) -> f64 {
        (self.lead_per_rad() / self.reference_radius).atan()
    }
    /// Base radius of the involute helicoid (profile I; MODEL §2.2): r_b = r1 cos(alpha_t),
    /// tan(alpha_t) = tan(alpha_n) / sin(gamma). m.
    pub fn base_radius(&self) -> f64 {
        let alpha_t = (self.normal_pressure_angle.tan() / self.lead_angle().sin()).atan();
        self.reference_radius * alpha_t.cos()
    }
}

/// Relative placement of a worm (or the hob) with respect to the wheel (MODEL §1).
///
/// The worm axis passes through (0, -a, offset) of the wheel frame with direction
/// (cos i, 0, sin i): `offset` along z2, `inclination` i a rotation about the line of centres.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Placement {
    /// Centre distance a, m.
    pub centre_distance: f64,
    /// Offset of the worm axis along the wheel axis, m.
    pub offset: f64,
    /// Inclination of the worm axis out of the wheel median plane, rad.
    pub inclination: f64,
}

/// Wheel blank and body, SI.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct WheelBlank {
    pub teeth: u32,
    /// Face width b2, m.
    pub face_width: f64,
    /// Outer radius r_e2, m.
    pub outer_radius: f64,
    /// Throat (tip) radius r_a2 at the median plane, m.
    pub throat_radius: f64,
    /// Rim thickness under the root, m (None: twice the tooth height, fixed by the bending stage).
    pub rim_thickness: Option<f64>,
    pub web_thickness: Option<f64>,
    pub hub_radius: Option<f64>,
    pub shaft_radius: Option<f64>,
    /// Bearing positions along z2, m.
    pub bearing_positions: Option<Vec<f64>>,
    /// Edge relief of the teeth (blank top, face ends).
    pub edge_relief: EdgeRelief,
    /// Width along the wheel axis of the 45 deg chamfer at each face end, m (0 = sharp; MODEL
    /// §2.3).
    pub face_edge_chamfer: f64,
}

/// Elastic and wear properties of one member, SI.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Material {
    pub name: String,
    /// Young's modulus, Pa.
    pub youngs_modulus: f64,
    pub poisson_ratio: f64,
    /// Hardness, Pa.
    pub hardness: f64,
    /// Archard coefficient K (dimensionless).
    pub wear_coefficient: f64,
    /// Density, kg/m^3.
    pub density: f64,
    /// Pitting limit stress sigma_Hlim, Pa.
    pub pitting_limit: f64,
}

/// Lubricant, SI (MODEL §6).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Lubricant {
    pub name: String,
    /// eta0, Pa s.
    pub viscosity: f64,
    /// alpha_pv, 1/Pa.
    pub pressure_viscosity: f64,
    /// beta*, K.
    pub thermo_viscosity: f64,
    /// K_f, W/(m K).
    pub thermal_conductivity: f64,
    /// Oil temperature, K.
    pub temperature: f64,
    /// Composite RMS roughness, m: the flank's as cut (R_q,0 of MODEL §6.1).
    pub composite_roughness: f64,
    /// The running-in of the roughness with the wear (MODEL §6.1); None: the roughness stays
    /// `composite_roughness` (the published model).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub running_in: Option<RunningIn>,
}

/// The running-in of the composite roughness (MODEL §6.1, [`Lubricant::roughness_after`]):
/// R_q,r the run-in roughness (m, at most the initial), h_r the running-in depth (m).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct RunningIn {
    pub roughness: f64,
    pub depth: f64,
}

impl Lubricant {
    /// The lubricant at oil temperature `temperature` (K): eta0 from the thermo-viscosity law
    /// eta = eta_ref exp(beta* (1/T - 1/T_ref)) of MODEL §6 (`viscosity` holds at
    /// `self.temperature`).
    pub fn at_temperature(&self, temperature: f64) -> Self {
        let shift = self.thermo_viscosity * (1.0 / temperature - 1.0 / self.temperature);
        Self {
            viscosity: self.viscosity * shift.exp(),
            temperature,
            ..self.clone()
        }
    }

    /// The composite roughness R_q (m) of a flank point worn `worn_depth` deep (m, normal to
    /// the flank; MODEL §6.1): `composite_roughness` without running-in, else
    /// R_q,r + (R_q,0 - R_q,r) exp(-h / h_r) (exactly R_q,0 at h = 0 and where R_q,r = R_q,0).
    pub fn roughness_after(&self, worn_depth: f64) -> f64 {
        match self.running_in {
            Some(r) if worn_depth > 0.0 => {
                let decay = (-worn_depth / r.depth).exp();
                r.roughness + (self.composite_roughness - r.roughness) * decay
            }
            _ => self.composite_roughness,
        }
    }
}

/// The default limiting shear stress over pressure Lambda of the film (MODEL §13): within
/// the 0.009-0.027 a DGMK report measured for polyglycols, set on the level of ISO/TR 14521's
/// rig-fitted friction with the gears' factors Y (VALIDATION.md (e)).
pub const DEFAULT_LIMITING_SHEAR: f64 = 0.014;

/// Friction of the mixed lubrication (MODEL §13), SI.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct FrictionLaw {
    /// Boundary friction coefficient mu_b of the asperity contacts.
    pub boundary: f64,
    /// Greenwood & Tripp's summit product eta_s beta sigma (summit density x summit radius x
    /// composite RMS roughness), dimensionless.
    pub summit_density_radius_roughness: f64,
    /// Composite RMS roughness over the summit radius, sigma / beta, dimensionless.
    pub summit_roughness_radius: f64,
    /// Eyring stress tau_0, Pa.
    pub eyring_stress: f64,
    /// Limiting shear stress over pressure, Lambda.
    pub limiting_shear: f64,
}

/// The housing's heat balance (MODEL §13), SI.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Housing {
    /// The oil temperature from the heat balance (else the lubricant's, fixed).
    pub balance: bool,
    /// Heat-transferring area A_H, m^2.
    pub area: f64,
    /// Heat transfer coefficient alpha_L, W/(m^2 K).
    pub heat_transfer: f64,
    /// Ambient temperature theta_0, K.
    pub ambient: f64,
    /// Heat removed by a cooler, W.
    pub cooler: f64,
}

impl Housing {
    /// With a fixed oil temperature nothing reads the housing.
    pub fn is_unused(&self) -> bool {
        !self.balance
    }
}

/// Factors of the standard ratings (MODEL §9) the user may set.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RatingFactors {
    /// Product of the mesh-friction factors Y_S Y_G Y_W Y_R (size, geometry, material,
    /// roughness).
    pub friction_factor: f64,
    /// Product of the pitting-limit life factors Z_h Z_v Z_s Z_u Z_oil.
    pub pitting_life_factor: f64,
    /// Allowable pitted flank share at the end of the growth phase A_p10,max, %.
    pub pitted_area_max_percent: f64,
    /// The safety table's inputs (MODEL §9.1); left out of the gear's JSON when all default,
    /// so that gears without them keep their fingerprints.
    #[serde(skip_serializing_if = "SafetyInputs::is_default")]
    pub safety: SafetyInputs,
    /// The safety table's inputs the file marks as assumed (`rating.assumed_inputs`: their
    /// `[rating]` key names); left out of the gear's JSON when none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub assumed_inputs: Vec<String>,
}

impl Default for RatingFactors {
    /// All factors 1, A_p10,max 8 %.
    fn default() -> Self {
        Self {
            friction_factor: 1.0,
            pitting_life_factor: 1.0,
            pitted_area_max_percent: 8.0,
            safety: SafetyInputs::default(),
            assumed_inputs: Vec::new(),
        }
    }
}

/// The safety table's inputs (MODEL §9.1), SI. A limit left out (None) leaves its safety
/// "needs input": none of them has a citable default.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SafetyInputs {
    /// Required life, h.
    pub required_life_hours: Option<f64>,
    /// Application factor K_A on the torque of the strength checks (root, deflection,
    /// pitting).
    pub application_factor: f64,
    /// Starts per hour N_S (MODEL §9: W_NS = 1 + 0.015 N_S on the flank loss).
    pub starts_per_hour: f64,
    /// Allowable root stress of the wheel, Pa.
    pub root_stress_allowable: Option<f64>,
    /// Radius of the wheel's root fillet in the FE root-stress model (the hob's tip edge
    /// radius), m.
    pub root_fillet_radius: Option<f64>,
    /// Worm deflection limit at the mesh point, m.
    pub deflection_limit: Option<f64>,
    /// Allowable tooth thickness loss Delta_s_lim, m (MODEL §9 (b)).
    pub thickness_loss_limit: Option<f64>,
    /// Allowable wheel mass loss Delta_m_lim, kg (MODEL §9 (c)).
    pub mass_loss_limit: Option<f64>,
    /// Allowed oil sump temperature, K.
    pub oil_temperature_limit: Option<f64>,
    /// Minimum safeties, in the table's order: root S_F, deflection S_delta, pitting S_H,
    /// wear S_W, temperature S_T.
    pub minimum: [f64; 5],
}

impl Default for SafetyInputs {
    /// No required life and no limits, K_A 1, no starts, every minimum 1.
    fn default() -> Self {
        Self {
            required_life_hours: None,
            application_factor: 1.0,
            starts_per_hour: 0.0,
            root_stress_allowable: None,
            root_fillet_radius: None,
            deflection_limit: None,
            thickness_loss_limit: None,
            mass_loss_limit: None,
            oil_temperature_limit: None,
            minimum: [1.0; 5],
        }
    }
}

impl SafetyInputs {
    /// Whether every input is its default.
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }
}

/// Where the load is given.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub enum Torque {
    /// Driving torque on the worm, N m.
    Worm(f64),
    /// Output torque on the wheel, N m.
    Wheel(f64),
}

/// Operating conditions, SI.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Conditions {
    pub torque: Torque,
    /// Worm angular speed, rad/s.
    pub worm_speed: f64,
}

/// Worm rotation sense; selects the loaded flank pair.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Rotation {
    /// Thread advances towards -x1: the worm's left flank (facing -x1) drives.
    Positive,
    /// Thread advances towards +x1: the right flank drives.
    Negative,
}

/// Which contact solver the loaded analysis uses (`analysis.solver`, MODEL §5.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum SolverKind {
    /// Polonsky-Keer conjugate gradient with active set.
    ConjugateGradient,
    /// The published fixed point on the approach (MODEL §5.4).
    FixedPoint,
}

/// Analysis settings (grid sizes, positions...).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Analysis {
    /// Rows of the global flank grid's nominal height (the band at the worm-tip trace adds
    /// its finer rows, MODEL §3.3).
    pub flank_cells_height: usize,
    pub flank_cells_face: usize,
    /// How many times finer the rows are in the band at the worm-tip trace (1: a node row on
    /// the trace, no finer rows; 0: evenly spaced rows).
    pub tip_trace_refinement: usize,
    pub positions: usize,
    pub teeth_each_side: usize,
    /// Marking thickness j, m.
    pub marking_thickness: f64,
    /// Rack-plane offsets z1 for the sections, m.
    pub section_offsets: Vec<f64>,
    pub stl_worm_threads: usize,
    /// 0 = all teeth.
    pub stl_wheel_teeth: usize,
    /// LTCA local mesh: slice step (node columns), cells across the line, band factor.
    pub contact_slice_step: usize,
    pub contact_columns: usize,
    pub contact_band_factor: f64,
    /// Contact law of the loaded analysis (MODEL §5.7; default plastic at the wheel's
    /// hardness).
    pub contact: ContactLaw,
    /// Patch over which the converged pressure is reported (MODEL §12 i): across the contact
    /// line and along the face width, m.
    pub pressure_patch_across: f64,
    pub pressure_patch_along: f64,
    /// LTCA solver.
    pub solver: SolverKind,
    /// Direction of the pressure on a contact cell (MODEL §5.2's n_i).
    pub pressure_direction: PressureDirection,
    /// Which torque the pressures carry (MODEL §5.2, §12 n).
    pub torque_balance: TorqueBalance,
    /// How the local band grows where the contact reaches its edge (MODEL §5.1).
    pub contact_band_growth: BandGrowth,
}

/// How the loaded analysis' local band grows where a position's contact reaches its edge
/// (MODEL §5.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum BandGrowth {
    /// Every slice's band widened by 1.6 with the same cells across the line (each cell 1.6
    /// times wider), up to four times; a life keeps the widest band of its states (the
    /// default until session 50: its worn contact is resolved ever more coarsely).
    Widen,
    /// Default: only the slices whose load reaches their band's first or last cell grow, on
    /// that side, by cells of the same width (the cells keep their size; at most three bands'
    /// worth of cells on each side); each analysis finds its own extent.
    #[default]
    Extend,
}

/// Which torque the loaded analysis' pressures carry (MODEL §5.2, §12 n).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum TorqueBalance {
    /// The torque the mesh transmits (default): equilibrium about both axes with the friction
    /// tractions of MODEL §13; a given worm torque T1 gives the wheel u eta_z T1.
    Transmitted,
    /// The published reading: frictionless pressures balance the given torque (a worm torque
    /// T1 puts u T1 on the wheel, over-loading the teeth by 1 / eta_z).
    Frictionless,
}

/// Contact law of the wheel's surface in the loaded analysis (MODEL §5.7, §12 i).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ContactLaw {
    /// Elastic–perfectly plastic: no pressure exceeds the flow pressure, Pa; the interference
    /// of the cells at it is plastic indentation, kept by a life run as running-in.
    Plastic { flow_pressure: f64 },
    /// Purely elastic (the published reading): no bound, singular at sharp edges.
    Elastic,
}

impl ContactLaw {
    /// The largest contact pressure, Pa (infinite for the elastic law).
    pub fn pressure_bound(&self) -> f64 {
        match *self {
            ContactLaw::Plastic { flow_pressure } => flow_pressure,
            ContactLaw::Elastic => f64::INFINITY,
        }
    }
}

/// Direction of the contact pressure on a cell of the loaded analysis: MODEL §5.2 writes n_i,
/// "the pressure direction", without saying whose normal. Both coincide on the conjugate
/// contact line; they differ where the wheel touches the worm with an edge (its face ends
/// under a misalignment) or off the line on a worn flank.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum PressureDirection {
    /// The worm flank's normal at the point the gap is measured to (default): the worm is the
    /// smooth, unworn body in every wheel-edge contact, and with it the loaded analysis keeps
    /// the frictionless power balance (mean wheel torque = u x worm torque) within 1 % up to
    /// the ends of the misalignment ranges.
    WormFlank,
    /// The wheel flank's normal of the unworn grid (the earlier reading): at a wheel edge it
    /// is not the contact's, and the worm's small lever turns that into torque errors of
    /// 13-180 % under misalignment.
    WheelFlank,
}

/// Which bending model the loaded analysis uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum BendingKind {
    /// Contact (Boussinesq) only.
    None,
    /// Finite-element models of worm and wheel (MODEL §5.5).
    Fe,
}

/// Validated bending settings, SI.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct BendingPlan {
    pub kind: BendingKind,
    pub height_points: usize,
    pub width_points: usize,
    pub worm_width_points: usize,
    pub mesh_refinement: usize,
    /// Worm shaft radius, body length and bearing positions (x1), m.
    pub worm_shaft_radius: f64,
    pub worm_body_length: f64,
    pub worm_bearings: [f64; 2],
}

/// A validated gear set: everything the pipeline needs, SI units.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct GearSet {
    pub title: String,
    pub worm: ThreadDef,
    pub hob: ThreadDef,
    /// Hob placement during cutting.
    pub cutting: Placement,
    pub wheel: WheelBlank,
    /// Nominal operating centre distance (the blank's throat torus is centred on it), m.
    pub nominal_centre_distance: f64,
    /// Operating placement of the worm: nominal + misalignments.
    pub operating: Placement,
    pub rotation: Rotation,
    pub worm_material: Material,
    pub wheel_material: Material,
    pub lubricant: Lubricant,
    /// Friction of the mixed lubrication (MODEL §13).
    pub friction: FrictionLaw,
    /// The housing's heat balance (MODEL §13); left out of the serialised gear (fingerprints of
    /// checkpoints and caches) when the oil temperature is fixed, as nothing then reads it.
    #[serde(skip_serializing_if = "Housing::is_unused")]
    pub housing: Housing,
    /// The operating point: the one of `[conditions]`, or with a spectrum its bin of the
    /// largest load (MODEL §14).
    pub conditions: Conditions,
    /// The load spectrum's bins (MODEL §14); empty for one operating point (and left out of
    /// the serialised gear then, so its fingerprints are those of `[conditions]`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub duty_cycle: Vec<DutyBin>,
    pub analysis: Analysis,
    /// Life to simulate, when the file asks for one.
    pub wear: Option<WearPlan>,
    /// Factors of the standard ratings.
    pub rating: RatingFactors,
    /// Bending model (MODEL §5.5).
    pub bending: BendingPlan,
    /// Non-fatal remarks found during validation.
    pub warnings: Vec<String>,
}

/// The wheel's body under its teeth with the defaults filled in (MODEL §5.5, REFERENCE_GEARS:
/// "the wheel is bronze on a steel shaft, rim thickness twice the tooth height, wheel shaft
/// fixed at one end"), SI, m.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct WheelBody {
    /// Root radius at the median plane (cutting centre distance - hob tip radius).
    pub root_radius: f64,
    /// Rim thickness under the root (default: twice the tooth height).
    pub rim_thickness: f64,
    /// Web thickness along the axis (default: a third of the face width).
    pub web_thickness: f64,
    /// Hub outer radius (default: 0.35 r2).
    pub hub_radius: f64,
    /// Half the hub's width (the face width's half: the hub is as wide as the rim).
    pub hub_half_width: f64,
    /// Shaft radius (default: 0.2 r2).
    pub shaft_radius: f64,
    /// Bearing positions along z2 [laterally holding, fixed end] (default: -b2, +b2).
    pub bearings: [f64; 2],
}

impl WheelBody {
    /// Inner radius of the rim (where the web starts), m.
    pub fn rim_inner_radius(&self) -> f64 {
        self.root_radius - self.rim_thickness
    }
}

impl GearSet {
    /// The wheel's body with its defaults (see [`WheelBody`]).
    pub fn wheel_body(&self) -> WheelBody {
        let w = &self.wheel;
        let r2 = self.wheel_reference_radius();
        let root_radius = self.cutting.centre_distance - self.hob.tip_radius;
        let tooth_height = w.throat_radius - root_radius;
        let bearings = match w.bearing_positions.as_deref() {
            Some([a, b]) => [*a, *b],
            _ => [-w.face_width, w.face_width],
        };
        WheelBody {
            root_radius,
            rim_thickness: w.rim_thickness.unwrap_or(2.0 * tooth_height.max(1e-4)),
            web_thickness: w.web_thickness.unwrap_or(w.face_width / 3.0),
            hub_radius: w.hub_radius.unwrap_or(0.35 * r2),
            hub_half_width: 0.5 * w.face_width,
            shaft_radius: w.shaft_radius.unwrap_or(0.2 * r2),
            bearings,
        }
    }

    /// Wheel reference radius r2 = z2 p_x / (2 pi), m.
    pub fn wheel_reference_radius(&self) -> f64 {
        self.wheel.teeth as f64 * self.worm.axial_pitch / (2.0 * PI)
    }
    /// Gorge (throat form) radius r_g = a - r_a2, m.
    pub fn gorge_radius(&self) -> f64 {
        self.nominal_centre_distance - self.wheel.throat_radius
    }
    /// Transmission ratio u = z2 / z1.
    pub fn ratio(&self) -> f64 {
        self.wheel.teeth as f64 / self.worm.starts as f64
    }
}

/// One semantic problem of the input.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field} = {value}: {problem}")]
pub struct FieldError {
    /// Dotted path of the field, e.g. `worm.tip_radius_mm`.
    pub field: String,
    /// The value as written (with units where useful).
    pub value: String,
    /// What is wrong and the allowed range.
    pub problem: String,
}

/// Why a gear file could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum InputError {
    #[error("cannot read {path}: {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
    #[error("{0}")]
    Syntax(String),
    #[error("{}", FieldErrors(.0))]
    Invalid(Vec<FieldError>),
}

struct FieldErrors<'a>(&'a [FieldError]);

impl fmt::Display for FieldErrors<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} problem(s) in the gear file:", self.0.len())?;
        for e in self.0 {
            write!(f, "\n  - {e}")?;
        }
        Ok(())
    }
}

impl InputError {
    /// The field errors, if this is a validation failure.
    pub fn field_errors(&self) -> &[FieldError] {
        match self {
            InputError::Invalid(v) => v,
            _ => &[],
        }
    }
}

/// Parses and validates a gear file given as TOML text.
pub fn load_from_str(text: &str) -> Result<GearSet, InputError> {
    let file = parse_gear_file(text)?;
    validate::validate(&file)
}

/// A gear file's document: the TOML table as written, before validation (what variants
/// change by dotted name, [`set_dotted`]). Syntax errors as [`load_from_str`]'s.
pub fn parse_document(text: &str) -> Result<toml::Table, InputError> {
    toml::from_str::<toml::Table>(text).map_err(|e| syntax_error(&e, text))
}

/// Validates a gear document ([`parse_document`], or one built from another format) as the
/// gear file it writes out to, so its errors are those of the same file.
pub fn load_document(document: &toml::Table) -> Result<GearSet, InputError> {
    load_from_str(&document_text(document)?)
}

/// A gear document as TOML text (comments are not kept).
pub fn document_text(document: &toml::Table) -> Result<String, InputError> {
    toml::to_string(document)
        .map_err(|e| InputError::Syntax(format!("cannot write the gear document: {e}")))
}

/// Sets the value at a dotted name of a gear document (`conditions.worm_torque_nm`,
/// `materials.wheel.wear_coefficient`), creating the tables on the way; `None` removes the key
/// (the field takes its default). The value is checked when the document is loaded
/// ([`load_document`]): an unknown name is an unknown field there.
pub fn set_dotted(
    document: &mut toml::Table,
    name: &str,
    value: Option<toml::Value>,
) -> Result<(), InputError> {
    let bad = |problem: &str| {
        InputError::Invalid(vec![FieldError {
            field: name.to_string(),
            value: value.as_ref().map_or("(removed)".into(), |v| v.to_string()),
            problem: problem.to_string(),
        }])
    };
    let keys: Vec<&str> = name.split('.').map(str::trim).collect();
    if keys.iter().any(|k| k.is_empty()) {
        return Err(bad(
            "a dotted name of the gear file, such as conditions.worm_torque_nm",
        ));
    }
    let (leaf, tables) = keys.split_last().expect("split gives one key at least");
    let mut table = document;
    for (depth, key) in tables.iter().enumerate() {
        let entry = table
            .entry(key.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        table = match entry {
            toml::Value::Table(t) => t,
            _ => {
                return Err(bad(&format!(
                    "{} is a value, not a table: it has no field {}",
                    keys[..=depth].join("."),
                    keys[depth + 1]
                )))
            }
        };
    }
    match value {
        Some(v) => {
            table.insert(leaf.to_string(), v);
        }
        None => {
            table.remove(*leaf);
        }
    }
    Ok(())
}

/// Reads, parses and validates a gear file.
pub fn load(path: &Path) -> Result<GearSet, InputError> {
    let text = crate::files::read_text(path, crate::files::INPUT_LIMIT).map_err(|source| {
        InputError::Io {
            path: path.display().to_string(),
            source,
        }
    })?;
    load_from_str(&text)
}
