//! The TOML gear file as written by the user (units in the field names: mm, deg, rpm, GPa...).
//!
//! These structs mirror the file one to one; `deny_unknown_fields` makes a misspelt key an
//! error. Nothing here is validated: [`super::validate`] turns a [`GearFile`] into a checked
//! [`super::GearSet`] in SI units.

use serde::{Deserialize, Serialize};

/// Whole input file.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct GearFile {
    /// Free text shown in reports.
    #[serde(default)]
    pub title: Option<String>,
    pub worm: ThreadSpec,
    pub hob: ThreadSpec,
    pub cutting: SettingSpec,
    pub wheel: WheelSpec,
    pub operating: OperatingSpec,
    #[serde(default)]
    pub materials: MaterialsSpec,
    #[serde(default)]
    pub lubricant: LubricantSpec,
    /// The housing's heat transfer (MODEL §13).
    #[serde(default)]
    pub housing: HousingSpec,
    /// The operating point; absent when `[[duty_cycle]]` gives a load spectrum instead.
    #[serde(default)]
    pub conditions: Option<ConditionsSpec>,
    /// Load spectrum (MODEL §14): bins of torque, worm speed and share of the running time;
    /// absent: the one operating point of `[conditions]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duty_cycle: Option<Vec<DutyBinSpec>>,
    #[serde(default)]
    pub analysis: AnalysisSpec,
    /// Life to simulate (wear stage); absent: no life run.
    #[serde(default)]
    pub wear: Option<WearSpec>,
    /// Factors of the standard ratings (ISO/TR 14521).
    #[serde(default)]
    pub rating: RatingSpec,
    /// Bending of the teeth and their environment (MODEL §5.5); absent: no bending.
    #[serde(default)]
    pub bending: BendingSpec,
}

/// Bending model of worm and wheel (MODEL §5.5).
#[derive(Debug, Clone, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BendingSpec {
    /// "none" (default) or "fe": finite-element models of both members, expanded on the
    /// function basis, cached on disk.
    #[serde(default)]
    pub model: Option<String>,
    /// Fit points along the tooth / thread height (default 5).
    #[serde(default)]
    pub height_points: Option<i64>,
    /// Fit points across the wheel's face width (default 7).
    #[serde(default)]
    pub width_points: Option<i64>,
    /// Fit points along the worm thread, across the zone the wheel reaches (default 13: the
    /// worm's influence is more peaked than the wheel's).
    #[serde(default)]
    pub worm_width_points: Option<i64>,
    /// Mesh refinement of both FE models, 1 (default) to 3.
    #[serde(default)]
    pub mesh_refinement: Option<i64>,
    /// Worm shaft radius beyond the threaded body, mm (default 0.75 x root radius).
    #[serde(default)]
    pub worm_shaft_radius_mm: Option<f64>,
    /// Length of the worm body at root radius, mm (default: the length the wheel blank can
    /// reach, 2 sqrt(r_e2^2 - (a - r_a1)^2)).
    #[serde(default)]
    pub worm_body_length_mm: Option<f64>,
    /// Worm bearing positions along the worm axis, mm; the first is on the drive side
    /// (default: +/- (body length / 2 + 2 x root radius)).
    #[serde(default)]
    pub worm_bearing_positions_mm: Option<Vec<f64>>,
}

/// Factors of the standard ratings; each defaults to 1 (A_p10,max to 8 %).
#[derive(Debug, Clone, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RatingSpec {
    /// Mesh friction: size factor Y_S (standard: (100 / a_mm)^0.5).
    pub friction_size_factor: Option<f64>,
    /// Mesh friction: geometry factor Y_G.
    pub friction_geometry_factor: Option<f64>,
    /// Mesh friction: material factor Y_W.
    pub friction_material_factor: Option<f64>,
    /// Mesh friction: roughness factor Y_R (standard: (Ra1_um / 0.5)^0.25).
    pub friction_roughness_factor: Option<f64>,
    /// Product of the pitting-limit life factors Z_h Z_v Z_s Z_u Z_oil.
    pub pitting_life_factor: Option<f64>,
    /// Allowable pitted flank share at the end of pitting growth A_p10,max, %.
    pub pitted_area_max_percent: Option<f64>,
    /// Safety table (MODEL §9.1): required life, hours (no default: S_H and S_W need it).
    pub required_life_h: Option<f64>,
    /// Application factor K_A on the torque of the strength checks (default 1).
    pub application_factor: Option<f64>,
    /// Starts per hour N_S (default 0): W_NS = 1 + 0.015 N_S on the flank loss (MODEL §9).
    pub starts_per_hour: Option<f64>,
    /// Allowable root stress of the wheel, MPa (no default: S_F needs it).
    pub root_stress_allowable_mpa: Option<f64>,
    /// Radius of the wheel's root fillet in the FE model of the root stress (the hob's tip
    /// edge radius), mm (no default: S_F needs it).
    pub root_fillet_radius_mm: Option<f64>,
    /// Worm deflection limit at the mesh point, um (no default: S_delta needs it).
    pub deflection_limit_um: Option<f64>,
    /// Allowable tooth thickness loss Delta_s_lim, mm (MODEL §9 (b); optional).
    pub thickness_loss_limit_mm: Option<f64>,
    /// Allowable wheel mass loss Delta_m_lim, g (MODEL §9 (c); optional).
    pub mass_loss_limit_g: Option<f64>,
    /// Allowed oil sump temperature, degC (no default: S_T needs it).
    pub oil_temperature_limit_c: Option<f64>,
    /// Minimum safeties (default 1 each: the computed value reaches the allowable).
    pub minimum_safety_root: Option<f64>,
    pub minimum_safety_deflection: Option<f64>,
    pub minimum_safety_pitting: Option<f64>,
    pub minimum_safety_wear: Option<f64>,
    pub minimum_safety_temperature: Option<f64>,
    /// The inputs of this table that are assumed, not known (names of `[rating]` keys given
    /// here; `wormwear init` lists those it writes): the safety rows that read them are marked
    /// "assumed" in the table, rating.csv and the report.
    pub assumed_inputs: Option<Vec<String>>,
}

/// Life simulation (MODEL §7.3, §8).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct WearSpec {
    /// Wheel cycles (revolutions) to simulate.
    pub life_cycles: f64,
    /// Adaptive steps: largest depth removed per step, um (default 4 when no step is given).
    #[serde(default)]
    pub step_wear_um: Option<f64>,
    /// Fixed steps of this many wheel cycles (instead of step_wear_um).
    #[serde(default)]
    pub step_cycles: Option<f64>,
    /// Stability guard: a step that would remove more than this somewhere is split into
    /// sub-steps, um (default 5; 0 disables).
    #[serde(default)]
    pub max_substep_wear_um: Option<f64>,
    /// How a step's removal follows from the wear per cycle: "explicit" (default, the
    /// published step) or "stabilised" (MODEL §7.3, `wear::stabilised`).
    #[serde(default)]
    pub step_scheme: Option<String>,
    /// Error control of adaptive steps: largest local error of a step as a share of the wear
    /// so far (default 0: off).
    #[serde(default)]
    pub step_tolerance: Option<f64>,
    /// Phase schedule (MODEL §8): wear and pitting phases, each until a number of cycles.
    #[serde(default)]
    pub phases: Vec<PhaseSpec>,
    /// How pitting enters the life (MODEL §8 beyond the schedule): "schedule" (default; the published
    /// coupling: pits cut above each pitting phase's limit), "off", "damage" (pits where a
    /// node's fatigue damage reaches 1; the schedule's pitting phases stop the wear) or
    /// "forecast" (pits from the damage, and the phases found from them).
    #[serde(default)]
    pub pitting: Option<String>,
    /// Forecast: share of the active flank whose damage must have reached 1 for a pitting
    /// phase to start, % (default 2; 0: the first node).
    #[serde(default)]
    pub pitting_onset_percent: Option<f64>,
    /// Bronze pressure-life curve p_lim(N) = p_ref (N / N_ref)^-exponent (default: MODEL §8).
    #[serde(default)]
    pub endurance: Option<EnduranceSpec>,
    /// Line load of the film formula: "loaded-analysis" (default, MODEL §6 / §12 h) or
    /// "hertz-peak-floor" (floored at the Hertz load of the band's peak pressure).
    #[serde(default)]
    pub film_load: Option<String>,
    /// Depth of the pits: "hertz" (default, 0.78 x the local Hertz half-width, MODEL §12 g)
    /// or "loaded-band" (0.78 x the loaded band's half-width).
    #[serde(default)]
    pub pit_depth: Option<String>,
    /// The stress of the fatigue damage of the "damage" and "forecast" pitting modes:
    /// "principal-shear" (default, MODEL §8.1), "orthogonal-shear" or "surface-pressure".
    #[serde(default)]
    pub pitting_stress: Option<String>,
    /// How a node of the damage reads the stress from the grid cells around it: "largest"
    /// (default, as the published pitting cut) or "interpolated" (the mean of its cells).
    #[serde(default)]
    pub damage_node_reading: Option<String>,
    /// Wheel cycles at which a state is computed and its maps written (increasing; default
    /// the states 0, 1, 2, 4, 8, ...).
    #[serde(default)]
    pub map_cycles: Option<Vec<f64>>,
    /// Which wear limit ends the life early: "pointed-tip" (default) or "backlash-limit"
    /// (MODEL §9 (a), (d)).
    #[serde(default)]
    pub stop_at: Option<String>,
    /// Backlash limit: increase of the tangential backlash at r2, um (default: the
    /// standard's limit (d), 0.3 m_x / cos(alpha_n)).
    #[serde(default)]
    pub backlash_limit_um: Option<f64>,
}

/// One phase of the schedule.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PhaseSpec {
    /// "wear" or "pitting".
    pub kind: String,
    /// The phase lasts until this many cycles.
    pub until_cycles: f64,
    /// Pitting: pressure limit, MPa (default: the endurance curve at the phase's duration,
    /// raised by the margin).
    #[serde(default)]
    pub pressure_limit_mpa: Option<f64>,
    /// Pitting: margin on the endurance pressure (default 0.1 = +10 %).
    #[serde(default)]
    pub margin: Option<f64>,
}

/// Power-law pressure-life curve; a field left out takes the MODEL §8 default (425 MPa at
/// 11e6 cycles, exponent 0.176).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct EnduranceSpec {
    #[serde(default = "default_reference_pressure_mpa")]
    pub reference_pressure_mpa: f64,
    #[serde(default = "default_reference_cycles")]
    pub reference_cycles: f64,
    #[serde(default = "default_exponent")]
    pub exponent: f64,
    /// The curve's position within its scatter band: a factor on the life axis (default 1;
    /// `wormwear calibrate --backlash` fits it with a forecast).
    #[serde(default)]
    pub life_factor: Option<f64>,
}

fn default_reference_pressure_mpa() -> f64 {
    crate::input::Endurance::DEFAULT.reference_pressure * 1e-6
}

fn default_reference_cycles() -> f64 {
    crate::input::Endurance::DEFAULT.reference_cycles
}

fn default_exponent() -> f64 {
    crate::input::Endurance::DEFAULT.exponent
}

/// Worm or hob thread (both are helicoids; MODEL §2, §3.1).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ThreadSpec {
    /// Profile type: "A", "N", "I", "K" or "C" (ISO 10828 ZA, ZN, ZI, ZK, ZC).
    pub profile: String,
    /// Number of starts z1.
    pub starts: i64,
    /// "right" or "left".
    pub hand: String,
    /// Axial module m_x, mm (give this or `lead_mm`).
    #[serde(default)]
    pub axial_module_mm: Option<f64>,
    /// Lead p_z = z1 pi m_x, mm (give this or `axial_module_mm`).
    #[serde(default)]
    pub lead_mm: Option<f64>,
    /// Reference radius r1, mm.
    pub reference_radius_mm: f64,
    /// Tip radius r_a, mm.
    pub tip_radius_mm: f64,
    /// Root radius r_f, mm.
    pub root_radius_mm: f64,
    /// Pressure angle of the tool, degrees, in the plane named by `pressure_angle_plane`.
    pub pressure_angle_deg: f64,
    /// "axial" or "normal" (normal to the reference helix).
    #[serde(default = "default_plane")]
    pub pressure_angle_plane: String,
    /// Axial thread thickness at the reference radius, mm.
    pub axial_thickness_mm: f64,
    /// Grinding wheel, profiles K and C only.
    #[serde(default)]
    pub grinding_wheel: Option<GrindingWheelSpec>,
    /// Tip relief at the tip edge, um: parabolic, C (s / L)^2 over the last L of the flank
    /// height (worm only; default 0: a sharp edge, the published model).
    #[serde(default)]
    pub tip_relief_um: Option<f64>,
    /// Length L of the tip relief, measured radially from the tip, mm (default 1 mm).
    #[serde(default)]
    pub tip_relief_length_mm: Option<f64>,
    /// Radius of the broken tip edge, mm: in the axial section the flank joins the tip
    /// cylinder through a circle of this radius tangent to both (MODEL §2.3; worm only; default
    /// 0: a sharp edge, the published gear).
    #[serde(default)]
    pub tip_edge_radius_mm: Option<f64>,
}

fn default_plane() -> String {
    "axial".to_string()
}

/// Grinding wheel of K (biconical) and C (circular-arc) worms (MODEL §2.2).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct GrindingWheelSpec {
    /// Radius R_g of the grinding wheel at the point that grinds the worm reference cylinder, mm.
    pub radius_mm: f64,
    /// Distance between grinding-wheel axis and worm axis, mm (default r1 + R_g).
    #[serde(default)]
    pub axis_distance_mm: Option<f64>,
    /// Profile angle alpha_0 of the wheel flank, degrees (default: the thread's normal
    /// pressure angle).
    #[serde(default)]
    pub profile_angle_deg: Option<f64>,
    /// Radius rho_0 of the circular-arc wheel profile, mm (profile C only).
    #[serde(default)]
    pub profile_radius_mm: Option<f64>,
}

/// Relative placement of worm (or hob) and wheel (MODEL §1).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SettingSpec {
    /// Centre distance, mm.
    pub centre_distance_mm: f64,
    /// Offset of the worm/hob axis along the wheel axis z2, mm.
    #[serde(default)]
    pub offset_mm: f64,
    /// Inclination of the worm/hob axis out of the wheel median plane (rotation about the
    /// line of centres), degrees.
    #[serde(default)]
    pub inclination_deg: f64,
}

/// Operating set-up: nominal centre distance plus misalignments.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct OperatingSpec {
    /// Nominal operating centre distance a, mm (the blank's throat torus is centred on it).
    pub centre_distance_mm: f64,
    /// Centre-distance error added to a in operation, mm.
    #[serde(default)]
    pub centre_distance_error_mm: f64,
    /// Worm offset along the wheel axis z2, mm.
    #[serde(default)]
    pub worm_offset_mm: f64,
    /// Inclination of the worm axis out of the wheel median plane (shaft-angle error), degrees.
    #[serde(default)]
    pub inclination_deg: f64,
    /// Worm rotation sense: "positive" (thread advances towards -x1, loads the left flank)
    /// or "negative" (loads the right flank).
    #[serde(default = "default_rotation")]
    pub worm_rotation: String,
}

fn default_rotation() -> String {
    "positive".to_string()
}

/// Wheel blank and body (MODEL §3.3; body dimensions are for the bending model).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct WheelSpec {
    /// Number of teeth z2.
    pub teeth: i64,
    /// Face width b2, mm.
    pub face_width_mm: f64,
    /// Outer (cylinder) radius r_e2, mm.
    pub outer_radius_mm: f64,
    /// Throat (tip) radius r_a2 at the median plane, mm.
    pub throat_radius_mm: f64,
    /// Rim thickness under the tooth root, mm (default: twice the tooth height).
    #[serde(default)]
    pub rim_thickness_mm: Option<f64>,
    /// Web thickness, mm (default: face width / 3).
    #[serde(default)]
    pub web_thickness_mm: Option<f64>,
    /// Hub outer radius, mm (default: 0.35 x reference radius).
    #[serde(default)]
    pub hub_radius_mm: Option<f64>,
    /// Shaft radius, mm (default: 0.2 x reference radius).
    #[serde(default)]
    pub shaft_radius_mm: Option<f64>,
    /// Bearing positions along the wheel shaft (z2), mm (default: +/- face width).
    #[serde(default)]
    pub bearing_positions_mm: Option<Vec<f64>>,
    /// Edge relief of the teeth at the blank top and the face ends, um: parabolic,
    /// C (s / L)^2 over the last L before the edge (default 0: sharp edges, the published
    /// model).
    #[serde(default)]
    pub edge_relief_um: Option<f64>,
    /// Length L of the edge relief, mm (default 1 mm).
    #[serde(default)]
    pub edge_relief_length_mm: Option<f64>,
    /// Width of a 45 deg chamfer at each face end of the teeth, mm, along the wheel axis (MODEL
    /// §2.3; default 0: sharp face ends, the published gear).
    #[serde(default)]
    pub face_edge_chamfer_mm: Option<f64>,
}

/// Materials of worm and wheel (MODEL §11 defaults).
#[derive(Debug, Clone, Deserialize, Serialize, Default)]
#[serde(deny_unknown_fields)]
pub struct MaterialsSpec {
    #[serde(default)]
    pub worm: Option<MaterialSpec>,
    #[serde(default)]
    pub wheel: Option<MaterialSpec>,
}

/// One material.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    #[serde(default)]
    pub name: Option<String>,
    /// Young's modulus, GPa.
    pub youngs_modulus_gpa: f64,
    /// Poisson's ratio.
    pub poisson_ratio: f64,
    /// Hardness H used by Archard's law, GPa (wheel only; optional for the worm).
    #[serde(default)]
    pub hardness_gpa: Option<f64>,
    /// Dry/boundary Archard wear coefficient K (wheel only).
    #[serde(default)]
    pub wear_coefficient: Option<f64>,
    /// Density, kg/m^3.
    #[serde(default)]
    pub density_kg_m3: Option<f64>,
    /// Pitting limit stress sigma_Hlim, MPa (wheel only, ratings).
    #[serde(default)]
    pub pitting_limit_mpa: Option<f64>,
}

/// Lubricant (MODEL §6, §11 defaults).
#[derive(Debug, Clone, Deserialize, Serialize, Default)]
#[serde(deny_unknown_fields)]
pub struct LubricantSpec {
    #[serde(default)]
    pub name: Option<String>,
    /// Dynamic viscosity eta0 at ambient pressure and oil temperature, Pa s.
    #[serde(default)]
    pub viscosity_pa_s: Option<f64>,
    /// Pressure-viscosity coefficient alpha_pv, 1/GPa.
    #[serde(default)]
    pub pressure_viscosity_per_gpa: Option<f64>,
    /// Thermo-viscosity coefficient beta*, K.
    #[serde(default)]
    pub thermo_viscosity_k: Option<f64>,
    /// Thermal conductivity K_f, W/(m K).
    #[serde(default)]
    pub thermal_conductivity_w_m_k: Option<f64>,
    /// Oil temperature, degrees Celsius.
    #[serde(default)]
    pub temperature_c: Option<f64>,
    /// Composite RMS roughness R_q of worm and wheel, um.
    #[serde(default)]
    pub composite_roughness_um: Option<f64>,
    /// Run-in composite roughness R_q,r, um (MODEL §6.1; at most `composite_roughness_um`):
    /// with `running_in_depth_um`, the roughness falls toward it as the flank wears. None: no
    /// running-in (the published model).
    #[serde(default)]
    pub run_in_roughness_um: Option<f64>,
    /// Running-in depth h_r, um (MODEL §6.1): the worn depth over which the roughness runs in.
    #[serde(default)]
    pub running_in_depth_um: Option<f64>,
    /// "fixed" (default: the oil at `temperature_c`) or "balance": the steady sump temperature
    /// of the housing's heat balance (MODEL §13, `[housing]`); `viscosity_pa_s` then holds at
    /// `temperature_c` and follows the thermo-viscosity law.
    #[serde(default)]
    pub temperature: Option<String>,
    /// Boundary friction coefficient mu_b of the asperity contacts (MODEL §13).
    #[serde(default)]
    pub boundary_friction: Option<f64>,
    /// Greenwood & Tripp's summit product eta_s beta sigma, dimensionless (MODEL §13).
    #[serde(default)]
    pub summit_density_radius_roughness: Option<f64>,
    /// Composite RMS roughness over the summit radius, sigma / beta (MODEL §13).
    #[serde(default)]
    pub summit_roughness_radius: Option<f64>,
    /// Eyring stress tau_0 of the film's shear, MPa (MODEL §13).
    #[serde(default)]
    pub eyring_stress_mpa: Option<f64>,
    /// Limiting shear stress over pressure, Lambda (MODEL §13).
    #[serde(default)]
    pub limiting_shear_coefficient: Option<f64>,
}

/// The gear case's heat transfer (MODEL §13), used when `lubricant.temperature = "balance"`.
#[derive(Debug, Clone, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct HousingSpec {
    /// Heat-transferring area of the housing A_H, m^2.
    #[serde(default)]
    pub area_m2: Option<f64>,
    /// Heat transfer coefficient alpha_L of the housing to the air, W/(m^2 K).
    #[serde(default)]
    pub heat_transfer_w_m2k: Option<f64>,
    /// Ambient temperature, degrees Celsius.
    #[serde(default)]
    pub ambient_c: Option<f64>,
    /// Heat removed by a cooler, W.
    #[serde(default)]
    pub cooler_w: Option<f64>,
}

/// Operating conditions.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ConditionsSpec {
    /// Driving torque on the worm, N m (give this or `wheel_torque_nm`).
    #[serde(default)]
    pub worm_torque_nm: Option<f64>,
    /// Output torque on the wheel, N m (worm torque then follows from the efficiency).
    #[serde(default)]
    pub wheel_torque_nm: Option<f64>,
    /// Worm speed, rpm.
    pub worm_speed_rpm: f64,
}

/// One bin of a load spectrum (`[[duty_cycle]]`, MODEL §14).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct DutyBinSpec {
    /// Driving torque on the worm, N m (give this or `wheel_torque_nm`).
    #[serde(default)]
    pub worm_torque_nm: Option<f64>,
    /// Output torque on the wheel, N m.
    #[serde(default)]
    pub wheel_torque_nm: Option<f64>,
    /// Worm speed, rpm.
    pub worm_speed_rpm: f64,
    /// Share of the running time, (0, 1]; the bins' shares sum to 1 (give this or `hours`).
    #[serde(default)]
    pub time_share: Option<f64>,
    /// Running hours of the bin (the shares are the hours over their sum), h.
    #[serde(default)]
    pub hours: Option<f64>,
    /// Oil temperature of the bin, degrees Celsius (default: `lubricant.temperature_c`; not
    /// with `lubricant.temperature = "balance"`, which finds each bin's own).
    #[serde(default)]
    pub oil_temperature_c: Option<f64>,
}

/// Analysis settings. Every field has a default.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct AnalysisSpec {
    /// Cells of the global wheel-flank grid along the profile height.
    #[serde(default = "default_grid_height")]
    pub flank_cells_height: i64,
    /// Cells of the global wheel-flank grid along the face width.
    #[serde(default = "default_grid_face")]
    pub flank_cells_face: i64,
    /// How many times finer the grid's rows are in the band at the worm-tip trace (MODEL §3.3):
    /// 1 puts a node row on the trace with rows of the grid's height, 0 spaces the rows evenly
    /// from the flank's foot to its top (before session 58).
    #[serde(default = "default_tip_trace_refinement")]
    pub tip_trace_refinement: i64,
    /// Kinematic positions per wheel tooth pitch (MODEL §4.1).
    #[serde(default = "default_positions")]
    pub positions: i64,
    /// Teeth studied on each side of the reference tooth (2 gives k = -2..2).
    #[serde(default = "default_teeth_each_side")]
    pub teeth_each_side: i64,
    /// Marking-film thickness j of the no-load pattern, um (MODEL §4.4).
    #[serde(default = "default_marking")]
    pub marking_thickness_um: f64,
    /// Offsets z1 of the rack planes in which sections are drawn, mm.
    #[serde(default)]
    pub section_offsets_mm: Option<Vec<f64>>,
    /// Threads of the worm written to the STL file.
    #[serde(default = "default_stl_threads")]
    pub stl_worm_threads: i64,
    /// Teeth of the wheel written to the STL file (0 = all).
    #[serde(default = "default_stl_teeth")]
    pub stl_wheel_teeth: i64,
    /// LTCA: use every n-th node column of the flank grid as a slice of the local contact mesh.
    #[serde(default = "default_slice_step")]
    pub contact_slice_step: i64,
    /// LTCA: cells across the contact line on each slice.
    #[serde(default = "default_contact_columns")]
    pub contact_columns: i64,
    /// LTCA: half-width of the local mesh across the line, in Hertz half-widths at the mean
    /// line load (widened automatically when the load reaches the band edge).
    #[serde(default = "default_band_factor")]
    pub contact_band_factor: f64,
    /// LTCA: how the band grows where the contact reaches its edge: "extend" (default: the
    /// slices reached get more cells of the same width on that side; MODEL §5.1) or "widen"
    /// (every slice's cells widened together, the default until session 50).
    #[serde(default)]
    pub contact_band_growth: Option<String>,
    /// LTCA: contact law, "plastic" (default: pressures bounded by the wheel's flow pressure,
    /// the interference there kept as running-in, MODEL §5.7) or "elastic" (no bound, the
    /// published reading, MODEL §12 i).
    #[serde(default)]
    pub contact: Option<String>,
    /// LTCA: flow pressure p_Y of the wheel's surface, MPa (default: the wheel's hardness).
    #[serde(default)]
    pub flow_pressure_mpa: Option<f64>,
    /// Replaced by `contact` and `flow_pressure_mpa`; read only to refuse it with a message
    /// naming them.
    #[serde(default)]
    pub contact_pressure_cap_mpa: Option<f64>,
    /// Patch of the reported mesh-converged pressure: mean pressure over a patch this wide
    /// across the contact line, mm (default 0.5) ...
    #[serde(default = "default_patch_across")]
    pub pressure_patch_across_mm: f64,
    /// ... and this long along the face width, mm (default 1).
    #[serde(default = "default_patch_along")]
    pub pressure_patch_along_mm: f64,
    /// Direction of the contact pressure: "worm-flank" (default: the worm flank's normal) or
    /// "wheel-flank" (MODEL §5.2's n_i; see PressureDirection).
    #[serde(default)]
    pub pressure_direction: Option<String>,
    /// Which torque the pressures carry: "transmitted" (default: equilibrium with the contact's
    /// friction, MODEL §5.2) or "frictionless" (the published reading: frictionless pressures
    /// balance the given torque).
    #[serde(default)]
    pub torque_balance: Option<String>,
    /// LTCA solver: "conjugate-gradient" (default) or "fixed-point" (the published scheme).
    #[serde(default = "default_solver")]
    pub solver: String,
}

fn default_slice_step() -> i64 {
    1
}
fn default_contact_columns() -> i64 {
    11
}
fn default_band_factor() -> f64 {
    3.0
}
fn default_patch_across() -> f64 {
    0.5
}
fn default_patch_along() -> f64 {
    1.0
}
fn default_solver() -> String {
    "conjugate-gradient".to_string()
}

fn default_grid_height() -> i64 {
    40
}
fn default_grid_face() -> i64 {
    60
}
fn default_tip_trace_refinement() -> i64 {
    4
}
fn default_positions() -> i64 {
    20
}
fn default_teeth_each_side() -> i64 {
    2
}
fn default_marking() -> f64 {
    10.0
}
fn default_stl_threads() -> i64 {
    3
}
fn default_stl_teeth() -> i64 {
    5
}

impl Default for AnalysisSpec {
    fn default() -> Self {
        Self {
            flank_cells_height: default_grid_height(),
            flank_cells_face: default_grid_face(),
            tip_trace_refinement: default_tip_trace_refinement(),
            positions: default_positions(),
            teeth_each_side: default_teeth_each_side(),
            marking_thickness_um: default_marking(),
            section_offsets_mm: None,
            stl_worm_threads: default_stl_threads(),
            stl_wheel_teeth: default_stl_teeth(),
            contact_slice_step: default_slice_step(),
            contact_columns: default_contact_columns(),
            contact_band_factor: default_band_factor(),
            contact_band_growth: None,
            contact: None,
            flow_pressure_mpa: None,
            contact_pressure_cap_mpa: None,
            pressure_patch_across_mm: default_patch_across(),
            pressure_patch_along_mm: default_patch_along(),
            solver: default_solver(),
            pressure_direction: None,
            torque_balance: None,
        }
    }
}
