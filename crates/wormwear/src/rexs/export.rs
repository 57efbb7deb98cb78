//! A worm stage and our results as a REXS model (`wormwear export-rexs`).
//!
//! The stage is written in the REXS 1.4 component and attribute ids (the mapping of
//! [`super::import`], read backwards), in a frame where the worm's centre is the origin, its
//! axis (shaft u) is global x and the wheel centre lies at (0, a, 0): our worm frame. Results go
//! to the standard's attribute ids where REXS has one (efficiency, sigma_Hm, coefficient of
//! friction, sliding velocity, pitting safety, LTCA pressures and contact ratio, backlash
//! increase); quantities REXS has no id for, and gear-file fields REXS cannot hold (thread
//! thickness, lubricant law, wear coefficient...), go to custom attributes named
//! `custom_wormwear_*` (REXS reserves the `custom_` prefix for application data). The importer
//! reads these custom attributes back, so import -> export -> import gives the same gear.

use super::import::CUSTOM_PREFIX;
use super::{Attribute, Component, LoadCase, Model, Ref, Relation, RexsError, Value};
use crate::input::{BendingKind, GearSet, Hand, ProfileType, Rotation, Torque};
use crate::Results;

/// Builds the model component by component.
struct Builder {
    model: Model,
    next_id: u64,
}

/// Attribute constructors (value and REXS unit). Numbers are written to 12 significant
/// digits: the conversions from SI leave round-off in the last bits (0.018 m x 2 x 1000 =
/// 36.00000000000001 mm) that the file should not carry.
fn float(id: &str, unit: &str, x: f64) -> Attribute {
    Attribute {
        id: id.into(),
        unit: unit.into(),
        value: Value::Float(significant(x, 12)),
    }
}

/// `x` rounded to `digits` significant digits (non-finite values unchanged).
fn significant(x: f64, digits: usize) -> f64 {
    if !x.is_finite() || x == 0.0 {
        return x;
    }
    format!("{:.*e}", digits - 1, x).parse().unwrap_or(x)
}
fn custom(name: &str, unit: &str, x: f64) -> Attribute {
    float(&format!("{CUSTOM_PREFIX}{name}"), unit, x)
}
fn integer(id: &str, x: i64) -> Attribute {
    Attribute {
        id: id.into(),
        unit: "none".into(),
        value: Value::Integer(x),
    }
}
fn enumeration(id: &str, s: &str) -> Attribute {
    Attribute {
        id: id.into(),
        unit: "none".into(),
        value: Value::Enum(s.into()),
    }
}
fn text(id: &str, s: &str) -> Attribute {
    Attribute {
        id: id.into(),
        unit: "none".into(),
        value: Value::Text(s.into()),
    }
}
fn boolean(id: &str, b: bool) -> Attribute {
    Attribute {
        id: id.into(),
        unit: "none".into(),
        value: Value::Boolean(b),
    }
}
fn vector(id: &str, v: [f64; 3]) -> Attribute {
    Attribute {
        id: id.into(),
        unit: "mm".into(),
        value: Value::FloatArray(v.to_vec()),
    }
}

/// Position attributes: origin (mm) and axes in the gear unit's frame (component 1).
fn placed(origin: [f64; 3], u: [f64; 3], w: [f64; 3]) -> Vec<Attribute> {
    vec![
        Attribute {
            id: "reference_component_for_position".into(),
            unit: "none".into(),
            value: Value::Reference(1),
        },
        vector("support_vector", origin),
        vector("u_axis_vector", u),
        vector("w_axis_vector", w),
    ]
}

impl Builder {
    fn component(&mut self, kind: &str, name: &str, attributes: Vec<Attribute>) -> u64 {
        let id = self.next_id;
        self.next_id += 1;
        self.model.components.push(Component {
            id,
            kind: kind.into(),
            name: name.into(),
            attributes,
        });
        id
    }

    fn relation(&mut self, kind: &str, order: Option<i64>, refs: &[(u64, &str)]) {
        let hint = |id: u64| {
            self.model
                .component(id)
                .map_or(String::new(), |c| c.kind.clone())
        };
        let refs = refs
            .iter()
            .map(|(id, role)| Ref {
                id: *id,
                role: (*role).into(),
                hint: hint(*id),
            })
            .collect();
        let id = self.model.relations.len() as u64 + 1;
        self.model.relations.push(Relation {
            id,
            kind: kind.into(),
            order,
            refs,
        });
    }
}

const MM: f64 = 1e3;

fn flank_form(p: ProfileType) -> &'static str {
    match p {
        ProfileType::A => "za",
        ProfileType::N => "zn",
        ProfileType::I => "zi",
        ProfileType::K => "zk",
        ProfileType::C => "zc",
    }
}

/// The REXS model of a validated gear set, with its results when given. `date` is written
/// in the model header (ISO 8601).
pub fn stage_model(
    gear: &GearSet,
    results: Option<&Results>,
    date: &str,
) -> Result<Model, RexsError> {
    let mut b = Builder {
        model: Model {
            version: "1.4".into(),
            application_id: "wormwear".into(),
            application_version: env!("CARGO_PKG_VERSION").into(),
            date: date.into(),
            ..Model::default()
        },
        next_id: 1,
    };
    let unit_id = b.component(
        "gear_unit",
        &gear.title,
        placed([0.0; 3], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
    );
    let casing = b.component(
        "gear_casing",
        "casing",
        vec![float(
            "temperature_lubricant",
            "C",
            gear.lubricant.temperature - 273.15,
        )],
    );
    let stage = b.component("worm_stage", &gear.title, stage_attributes(gear));
    let (worm, wheel) = gears(&mut b, gear);
    b.relation("assembly", None, &[(unit_id, "assembly"), (casing, "part")]);
    b.relation("assembly", None, &[(unit_id, "assembly"), (stage, "part")]);
    b.relation(
        "stage",
        None,
        &[(stage, "stage"), (worm, "gear_1"), (wheel, "gear_2")],
    );
    let (worm_shaft, wheel_shaft) = shafts(&mut b, gear, unit_id, casing, worm, wheel);
    let _ = (worm_shaft, wheel_shaft);
    tools(&mut b, gear, worm, wheel);
    references(&mut b, gear, stage, casing, worm, wheel);
    load_spectrum(&mut b.model, gear);
    if let Some(r) = results {
        let sections = crate::output::summary_sections(r)
            .map_err(|e| RexsError::Model(format!("results: {e}")))?;
        let attributes = result_attributes(r, &sections);
        if let Some(c) = b.model.components.iter_mut().find(|c| c.id == stage) {
            c.attributes.extend(attributes);
        }
    }
    Ok(b.model)
}

fn stage_attributes(gear: &GearSet) -> Vec<Attribute> {
    let op = &gear.operating;
    let mut v = vec![
        float("center_distance", "mm", gear.nominal_centre_distance * MM),
        float(
            "center_distance_offset",
            "mm",
            (op.centre_distance - gear.nominal_centre_distance) * MM,
        ),
        float("width_offset", "mm", op.offset * MM),
        float(
            "intersection_angle_offset",
            "deg",
            op.inclination.to_degrees(),
        ),
        float("inclination_angle_offset", "deg", 0.0),
        float("gear_ratio", "none", gear.ratio()),
        float(
            "temperature_lubricant",
            "C",
            gear.lubricant.temperature - 273.15,
        ),
    ];
    let model = match gear.bending.kind {
        BendingKind::None => 0.0,
        BendingKind::Fe => 1.0,
    };
    v.push(custom("fe_bending", "none", model));
    v
}

/// worm_gear and worm_wheel components; returns their ids.
fn gears(b: &mut Builder, gear: &GearSet) -> (u64, u64) {
    let w = &gear.worm;
    let m_x = w.axial_module();
    let gamma = w.lead_angle().to_degrees() * w.hand.sign();
    let alpha = if w.profile == ProfileType::A {
        w.axial_pressure_angle
    } else {
        w.normal_pressure_angle
    };
    let mut worm_attrs = vec![
        enumeration("flank_form", flank_form(w.profile)),
        integer("number_of_teeth", w.starts as i64),
        float("axial_module", "mm", m_x * MM),
        float("lead", "mm", w.lead() * MM),
        float("lead_angle_worm_gear", "deg", gamma),
        float("normal_module", "mm", m_x * w.lead_angle().cos() * MM),
        float("pressure_angle_worm_gear", "deg", alpha.to_degrees()),
        float(
            "reference_diameter_worm_gear",
            "mm",
            2.0 * w.reference_radius * MM,
        ),
        float("tip_diameter_worm_gear", "mm", 2.0 * w.tip_radius * MM),
        float("root_diameter_worm_gear", "mm", 2.0 * w.root_radius * MM),
        float("length_worm_gear", "mm", gear.bending.worm_body_length * MM),
        float("u_coordinate_on_shaft", "mm", 0.0),
        custom("axial_thickness", "mm", w.axial_thickness * MM),
    ];
    // The broken tip edge (MODEL §2.3; REXS has no attribute for it), where given.
    if w.tip_edge_radius > 0.0 {
        worm_attrs.push(custom("tip_edge_radius", "mm", w.tip_edge_radius * MM));
    }
    worm_attrs.extend(placed([0.0; 3], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]));
    let worm = b.component("worm_gear", "worm", worm_attrs);
    let wh = &gear.wheel;
    let a = gear.nominal_centre_distance;
    let mut wheel_attrs = vec![
        enumeration("flank_form", flank_form(gear.hob.profile)),
        integer("number_of_teeth", wh.teeth as i64),
        float("axial_module", "mm", m_x * MM),
        float("face_width_worm_wheel", "mm", wh.face_width * MM),
        float("tip_diameter_worm_gear", "mm", 2.0 * wh.throat_radius * MM),
        float(
            "outer_diameter_worm_wheel",
            "mm",
            2.0 * wh.outer_radius * MM,
        ),
        float(
            "reference_diameter_worm_gear",
            "mm",
            wh.teeth as f64 * m_x * MM,
        ),
        float(
            "throat_radius_worm_wheel",
            "mm",
            (a - wh.throat_radius) * MM,
        ),
        float(
            "root_diameter_worm_gear",
            "mm",
            2.0 * (gear.cutting.centre_distance - gear.hob.tip_radius) * MM,
        ),
        float("u_coordinate_on_shaft", "mm", 0.0),
    ];
    wheel_attrs.extend(wheel_body_attributes(wh));
    wheel_attrs.extend(placed([0.0, a * MM, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]));
    let wheel = b.component("worm_wheel", "wheel", wheel_attrs);
    (worm, wheel)
}

/// The wheel's body dimensions the gear file gives (a default stays a default) and its
/// face-end chamfer where given (MODEL §2.3; REXS has no attribute for it), as custom
/// attributes in mm.
fn wheel_body_attributes(wh: &crate::input::WheelBlank) -> Vec<Attribute> {
    let chamfer = Some(wh.face_edge_chamfer).filter(|c| *c > 0.0);
    [
        ("rim_thickness", wh.rim_thickness),
        ("web_thickness", wh.web_thickness),
        ("hub_radius", wh.hub_radius),
        ("face_edge_chamfer", chamfer),
    ]
    .into_iter()
    .filter_map(|(name, value)| value.map(|v| custom(name, "mm", v * MM)))
    .collect()
}

/// Shafts with a section each, bearings (side relations to the casing), the loads and the
/// stage gear data.
fn shafts(
    b: &mut Builder,
    gear: &GearSet,
    unit_id: u64,
    casing: u64,
    worm: u64,
    wheel: u64,
) -> (u64, u64) {
    let a = gear.nominal_centre_distance * MM;
    let speed_rpm = gear.conditions.worm_speed * 60.0 / (2.0 * std::f64::consts::PI);
    let positive = gear.rotation == Rotation::Positive;
    let right = gear.worm.hand == Hand::Right;
    let signed_speed = if positive == right {
        speed_rpm
    } else {
        -speed_rpm
    };
    let mut worm_shaft_attrs = vec![
        float("rotational_speed", "1 / min", signed_speed),
        boolean("defines_speed", true),
    ];
    worm_shaft_attrs.extend(placed([0.0; 3], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]));
    let worm_shaft = b.component("shaft", "worm shaft", worm_shaft_attrs);
    let wheel_shaft = b.component(
        "shaft",
        "wheel shaft",
        placed([0.0, a, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),
    );
    for (shaft, gear_id) in [(worm_shaft, worm), (wheel_shaft, wheel)] {
        b.relation("assembly", None, &[(unit_id, "assembly"), (shaft, "part")]);
        b.relation("assembly", None, &[(shaft, "assembly"), (gear_id, "part")]);
    }
    let (worm_bearings, wheel_bearings) = supports(b, gear, casing, worm_shaft, wheel_shaft);
    loads(
        b,
        gear,
        worm_shaft,
        wheel_shaft,
        worm_bearings,
        wheel_bearings,
        worm,
        wheel,
    );
    (worm_shaft, wheel_shaft)
}

/// One shaft section between the bearings of each shaft, and the bearings (side relations
/// to the casing); returns the bearing positions along each shaft, mm.
fn supports(
    b: &mut Builder,
    gear: &GearSet,
    casing: u64,
    worm_shaft: u64,
    wheel_shaft: u64,
) -> ([f64; 2], [f64; 2]) {
    let a = gear.nominal_centre_distance * MM;
    let body = gear.wheel_body();
    let worm_bearings = gear.bending.worm_bearings.map(|x| x * MM);
    let wheel_bearings = body.bearings.map(|x| x * MM);
    let sections = [
        (
            worm_shaft,
            gear.bending.worm_shaft_radius * MM,
            worm_bearings,
        ),
        (wheel_shaft, body.shaft_radius * MM, wheel_bearings),
    ];
    for (shaft, radius, [p, q]) in sections {
        let (lo, hi) = (p.min(q), p.max(q));
        let section = b.component(
            "shaft_section",
            "section",
            vec![
                float("u_coordinate_on_shaft", "mm", lo),
                float("length", "mm", hi - lo),
                float("outer_diameter_begin", "mm", 2.0 * radius),
                float("outer_diameter_end", "mm", 2.0 * radius),
                float("inner_diameter_begin", "mm", 0.0),
                float("inner_diameter_end", "mm", 0.0),
            ],
        );
        b.relation("assembly", None, &[(shaft, "assembly"), (section, "part")]);
    }
    for (k, x) in worm_bearings.iter().enumerate() {
        let name = format!("worm bearing {}", k + 1);
        bearing(b, casing, worm_shaft, &name, [*x, 0.0, 0.0], *x);
    }
    for (k, z) in wheel_bearings.iter().enumerate() {
        let name = format!("wheel bearing {}", k + 1);
        bearing(b, casing, wheel_shaft, &name, [0.0, a, *z], *z);
    }
    (worm_bearings, wheel_bearings)
}

fn bearing(b: &mut Builder, casing: u64, shaft: u64, name: &str, at: [f64; 3], u: f64) {
    let mut attrs = vec![
        boolean("radial_force_absorption", true),
        float("u_coordinate_on_shaft_inner_side", "mm", u),
        float("u_coordinate_on_shaft_outer_side", "mm", u),
    ];
    attrs.extend(placed(at, [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]));
    let id = b.component("concept_bearing", name, attrs);
    b.relation(
        "side",
        None,
        &[
            (casing, "outer_part"),
            (shaft, "inner_part"),
            (id, "assembly"),
        ],
    );
}

/// The torque as an external load beyond the worm's drive-side bearing (worm torque) or
/// beyond the wheel's fixed end (wheel torque), and the stage gear data.
#[allow(clippy::too_many_arguments)]
fn loads(
    b: &mut Builder,
    gear: &GearSet,
    worm_shaft: u64,
    wheel_shaft: u64,
    worm_bearings: [f64; 2],
    wheel_bearings: [f64; 2],
    worm: u64,
    wheel: u64,
) {
    let beyond = |near: f64, far: f64| near + 0.25 * (near - far);
    let (worm_t, wheel_t) = match gear.conditions.torque {
        Torque::Worm(t) => (Some(t), None),
        Torque::Wheel(t) => (None, Some(t)),
    };
    let worm_u = beyond(worm_bearings[0], worm_bearings[1]);
    let wheel_u = beyond(wheel_bearings[1], wheel_bearings[0]);
    for (shaft, u, torque, name) in [
        (worm_shaft, worm_u, worm_t, "worm load"),
        (wheel_shaft, wheel_u, wheel_t, "wheel load"),
    ] {
        let mut attrs = vec![
            float("u_coordinate_on_shaft", "mm", u),
            boolean("defines_torque", torque.is_some()),
            boolean("transmits_torque", true),
        ];
        if let Some(t) = torque {
            attrs.push(float("torque_around_u_axis", "N m", t));
        }
        let id = b.component("external_load", name, attrs);
        b.relation("assembly", None, &[(shaft, "assembly"), (id, "part")]);
    }
    for (gear_id, driving) in [(worm, true), (wheel, false)] {
        let data = b.component(
            "worm_stage_gear_data",
            "gear data",
            vec![boolean("is_driving_gear", driving)],
        );
        let stage = b
            .model
            .components
            .iter()
            .find(|c| c.kind == "worm_stage")
            .map_or(0, |c| c.id);
        b.relation(
            "stage_gear_data",
            None,
            &[
                (stage, "stage"),
                (gear_id, "gear"),
                (data, "stage_gear_data"),
            ],
        );
    }
}

/// The duty cycle as the model's load spectrum (MODEL §14; REXS: a master model and one
/// sub-model per load case holding only what varies): per bin, the gear unit's
/// `load_duration_fraction` (%), the worm shaft's signed `rotational_speed`, each external
/// load's `defines_torque` and `torque_around_u_axis` (0 on the one that does not define it:
/// every case has the same attributes) and, with a fixed oil temperature, the casing's
/// `temperature_lubricant`. Those attributes leave the master model. Nothing without a
/// spectrum.
fn load_spectrum(model: &mut Model, gear: &GearSet) {
    if !gear.has_spectrum() {
        return;
    }
    let find = |kind: &str, name: &str| {
        model
            .components
            .iter()
            .find(|c| c.kind == kind && (name.is_empty() || c.name == name))
            .map_or(0, |c| c.id)
    };
    let unit = find("gear_unit", "");
    let casing = find("gear_casing", "");
    let shaft = find("shaft", "worm shaft");
    let loads = [
        find("external_load", "worm load"),
        find("external_load", "wheel load"),
    ];
    let oil = !gear.housing.balance;
    for c in model.components.iter_mut() {
        let varied: &[&str] = match c.id {
            id if id == shaft => &["rotational_speed"],
            id if loads.contains(&id) => &["defines_torque", "torque_around_u_axis"],
            id if id == casing && oil => &["temperature_lubricant"],
            _ => &[],
        };
        c.attributes.retain(|a| !varied.contains(&a.id.as_str()));
    }
    let sign = match (gear.rotation == Rotation::Positive) == (gear.worm.hand == Hand::Right) {
        true => 1.0,
        false => -1.0,
    };
    let part = |id: u64, kind: &str, attributes: Vec<Attribute>| Component {
        id,
        kind: kind.into(),
        name: String::new(),
        attributes,
    };
    for (k, bin) in gear.duty_cycle.iter().enumerate() {
        let (worm_t, wheel_t) = match bin.conditions.torque {
            Torque::Worm(t) => (Some(t), None),
            Torque::Wheel(t) => (None, Some(t)),
        };
        let rpm = bin.conditions.worm_speed * 60.0 / (2.0 * std::f64::consts::PI);
        let mut components = vec![
            part(
                unit,
                "gear_unit",
                vec![float("load_duration_fraction", "%", 100.0 * bin.time_share)],
            ),
            part(
                shaft,
                "shaft",
                vec![float("rotational_speed", "1 / min", sign * rpm)],
            ),
        ];
        for (id, torque) in loads.into_iter().zip([worm_t, wheel_t]) {
            components.push(part(
                id,
                "external_load",
                vec![
                    boolean("defines_torque", torque.is_some()),
                    float("torque_around_u_axis", "N m", torque.unwrap_or(0.0)),
                ],
            ));
        }
        if oil {
            let t = float("temperature_lubricant", "C", bin.oil_temperature - 273.15);
            components.push(part(casing, "gear_casing", vec![t]));
        }
        model.load_cases.push(LoadCase {
            id: k as u64 + 1,
            components,
        });
    }
}

/// Flanks, the hob (wheel), the grinding disc (ZK/ZC worm) and their manufacturing settings.
fn tools(b: &mut Builder, gear: &GearSet, worm: u64, wheel: u64) {
    let h = &gear.hob;
    let hob_alpha = if h.profile == ProfileType::A {
        h.axial_pressure_angle
    } else {
        h.normal_pressure_angle
    };
    let hob = b.component(
        "worm_wheel_hob_tool",
        "hob",
        vec![
            enumeration("flank_form", flank_form(h.profile)),
            integer("number_of_teeth", h.starts as i64),
            float("lead", "mm", h.lead() * MM),
            float("pressure_angle_worm_gear", "deg", hob_alpha.to_degrees()),
            float("tip_diameter_worm_gear", "mm", 2.0 * h.tip_radius * MM),
            float(
                "tooth_depth_worm_wheel_hob",
                "mm",
                (h.tip_radius - h.root_radius) * MM,
            ),
            custom("root_diameter", "mm", 2.0 * h.root_radius * MM),
            custom("reference_diameter", "mm", 2.0 * h.reference_radius * MM),
            custom("axial_thickness", "mm", h.axial_thickness * MM),
        ],
    );
    let wheel_settings = b.component(
        "worm_gear_manufacturing_settings",
        "wheel hobbing",
        vec![
            float(
                "center_distance_correction",
                "mm",
                (gear.cutting.centre_distance - gear.nominal_centre_distance) * MM,
            ),
            float("pressure_angle_correction", "deg", 0.0),
            enumeration("hobbing_procedure", "radial"),
        ],
    );
    let disc = gear.worm.grinding_wheel.as_ref().map(|g| {
        let mut attrs = vec![
            enumeration("flank_form", flank_form(gear.worm.profile)),
            float("grinding_disk_diameter", "mm", 2.0 * g.radius * MM),
            float(
                "pressure_angle_worm_gear",
                "deg",
                g.profile_angle.to_degrees(),
            ),
        ];
        if let Some(r) = g.profile_radius {
            attrs.push(float("profile_radius_zc_disc", "mm", r * MM));
        }
        b.component("worm_grinding_disc_tool", "grinding disc", attrs)
    });
    for (gear_id, tool) in [(worm, disc), (wheel, Some(hob))] {
        let left = b.component("worm_gear_flank", "left flank", vec![]);
        let right = b.component("worm_gear_flank", "right flank", vec![]);
        b.relation(
            "flank",
            None,
            &[(gear_id, "gear"), (left, "left"), (right, "right")],
        );
        if let Some(tool) = tool {
            for flank in [left, right] {
                let mut refs = vec![(flank, "workpiece"), (tool, "tool")];
                if gear_id == wheel {
                    refs.push((wheel_settings, "manufacturing_settings"));
                }
                b.relation("manufacturing_step", Some(1), &refs);
            }
        }
    }
}

/// Materials and lubricant, referenced from the gears and the stage.
fn references(b: &mut Builder, gear: &GearSet, stage: u64, casing: u64, worm: u64, wheel: u64) {
    for (gear_id, m, is_wheel) in [
        (worm, &gear.worm_material, false),
        (wheel, &gear.wheel_material, true),
    ] {
        let mut attrs = vec![
            text("material_designation", &m.name),
            float("elastic_modulus", "N / mm^2", m.youngs_modulus * 1e-6),
            float("poisson_ratio", "none", m.poisson_ratio),
            float("density", "kg / dm^3", m.density * 1e-3),
        ];
        if is_wheel {
            attrs.extend([
                float(
                    "surface_hardness_vickers",
                    "HV",
                    m.hardness * 1e-9 / 9.80665e-3,
                ),
                custom("hardness", "none", m.hardness * 1e-9),
                custom("wear_coefficient", "none", m.wear_coefficient),
                custom("pitting_limit", "N / mm^2", m.pitting_limit * 1e-6),
            ]);
        }
        let id = b.component("material", &m.name, attrs);
        b.relation(
            "reference",
            None,
            &[(gear_id, "origin"), (id, "referenced")],
        );
    }
    let l = &gear.lubricant;
    let mut attributes = vec![
        text("name", &l.name),
        custom("viscosity", "none", l.viscosity),
        custom(
            "pressure_viscosity_per_gpa",
            "none",
            l.pressure_viscosity * 1e9,
        ),
        custom("thermo_viscosity", "K", l.thermo_viscosity),
        custom("thermal_conductivity", "W / (m K)", l.thermal_conductivity),
        custom("composite_roughness", "mum", l.composite_roughness * 1e6),
    ];
    // The running-in of the roughness (MODEL §6.1), where the gear has one.
    if let Some(r) = l.running_in {
        attributes.push(custom("run_in_roughness", "mum", r.roughness * 1e6));
        attributes.push(custom("running_in_depth", "mum", r.depth * 1e6));
    }
    let lub = b.component("lubricant", &l.name, attributes);
    for origin in [stage, casing] {
        b.relation(
            "reference",
            None,
            &[(origin, "origin"), (lub, "referenced")],
        );
    }
}

/// The standard's rating (MODEL §9) under the DIN 3996 ids; the two wear limits, the total
/// efficiency and the pitting life as custom attributes.
fn rating_attributes(r: &crate::rating::Rating) -> Vec<Attribute> {
    let din = |name: &str| format!("{name}_din_3996_2019");
    vec![
        float(
            &din("gear_efficiency_in_reducer"),
            "none",
            r.mesh_efficiency,
        ),
        float(&din("mean_hertzian_stress"), "N / mm^2", r.sigma_hm_mpa),
        float(&din("parameter_mean_hertzian_stress"), "none", r.p_m_star),
        float(
            &din("mean_tooth_coefficient_of_friction"),
            "none",
            r.friction_coefficient,
        ),
        float(
            &din("sliding_velocity_at_reference_diameter"),
            "m / s",
            r.sliding_speed_m_s,
        ),
        float(&din("meshing_power_loss"), "W", r.loss_mesh_w),
        float(&din("safety_factor_pitting"), "none", r.pitting_safety),
        float(
            &din("limiting_value_flank_loss"),
            "mm",
            r.wear_limit_pointed_tip_m.min(r.wear_limit_backlash_m) * MM,
        ),
        custom("total_efficiency", "none", r.efficiency),
        custom(
            "wear_limit_pointed_tip",
            "mm",
            r.wear_limit_pointed_tip_m * MM,
        ),
        custom("wear_limit_backlash", "mm", r.wear_limit_backlash_m * MM),
        custom("pitting_life_cycles", "none", r.n_l_i_ii_cycles),
    ]
}

/// Our results as worm_stage attributes: the standard's ids where REXS has one, custom ones
/// otherwise.
fn result_attributes(
    results: &Results,
    sections: &serde_json::Map<String, serde_json::Value>,
) -> Vec<Attribute> {
    let get = |section: &str, key: &str| {
        sections
            .get(section)
            .and_then(|s| s.get(key))
            .and_then(serde_json::Value::as_f64)
    };
    let mut v = results
        .rating
        .as_ref()
        .map(rating_attributes)
        .unwrap_or_default();
    if let Some(p) = get("ltca", "mean_pressure_pa") {
        v.push(float(
            "mean_hertzian_stress_ltca_worm_stage",
            "N / mm^2",
            p * 1e-6,
        ));
    }
    if let Some(p) = get("ltca", "max_pressure_pa") {
        v.push(float(
            "maximum_hertzian_stress_ltca_worm_stage",
            "N / mm^2",
            p * 1e-6,
        ));
    }
    if let Some(s) = get("ltca", "contact_area_fraction") {
        v.push(float("contact_ratio_ltca_worm_stage", "%", 100.0 * s));
    }
    if let Some(t) = get("ltca", "te_p2p_rad") {
        v.push(custom("transmission_error_peak_to_peak", "rad", t));
    }
    if let Some(k) = get("ltca", "mesh_stiffness_mean_nm_per_rad") {
        v.push(custom("mesh_stiffness_n_m_per_rad", "none", k));
    }
    if let Some(t) = results.thermal.as_ref() {
        // The contact's friction (MODEL §13): REXS's efficiency ids are the standard's
        // method, so ours are custom.
        v.extend([
            custom(
                "mesh_efficiency_contact",
                "none",
                t.efficiency.mesh_efficiency,
            ),
            custom(
                "total_efficiency_contact",
                "none",
                t.efficiency.total_efficiency,
            ),
            custom("meshing_power_loss_contact", "W", t.friction.mesh_loss_w),
            custom(
                "mean_coefficient_of_friction_contact",
                "none",
                t.friction.mean_coefficient,
            ),
            custom("oil_temperature", "C", t.oil_temperature_k - 273.15),
        ]);
    }
    if let Some(last) = results.life.as_ref().and_then(|l| l.end.records.last()) {
        v.extend([
            float(
                "axial_backlash_increase",
                "mm",
                last.backlash_increase_m * MM,
            ),
            custom("life_cycles", "none", last.cycles),
            custom("max_wear_depth", "mum", last.max_wear_m * 1e6),
            custom("worn_volume", "mm^3", last.worn_volume_m3 * 1e9),
        ]);
    }
    if let Some(table) = results.safety.as_ref() {
        v.extend(safety_attributes(table));
    }
    v
}

/// The safety table from the model (MODEL §9.1) as custom attributes: REXS's safety ids are
/// the standard's method, ours is its method A. Only the safeties with a value, and the worm's
/// deflection at the mesh point.
fn safety_attributes(table: &crate::safety::SafetyTable) -> Vec<Attribute> {
    let mut v = Vec::new();
    for (symbol, name) in [
        ("S_F", "root"),
        ("S_delta", "deflection"),
        ("S_H", "pitting"),
        ("S_W", "wear"),
        ("S_T", "temperature"),
    ] {
        let Some(row) = table.rows.iter().find(|r| r.symbol == symbol) else {
            continue;
        };
        if let Some(x) = row.safety.filter(|x| x.is_finite()) {
            v.push(custom(&format!("safety_{name}_model"), "none", x));
        }
        if let (Some(d), "S_delta") = (row.value, symbol) {
            v.push(custom("worm_deflection_mesh_point", "mum", d));
        }
    }
    v
}

/// The current UTC time as ISO 8601 (`2026-11-24T06:30:00Z`), for the model header.
pub fn utc_now() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs()) as i64;
    let (days, rem) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    // Civil date from days since 1970-01-01 (H. Hinnant's algorithm).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}
