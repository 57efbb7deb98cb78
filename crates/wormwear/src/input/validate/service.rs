//! The materials, the lubricant, the rating factors and the operating conditions (MODEL §6, §9,
//! §11 defaults).

use super::*;

/// The worm's material when the file gives none (MODEL §11).
pub(super) fn default_worm_material() -> Material {
    Material {
        name: "case-hardened steel (default)".into(),
        youngs_modulus: 203e9,
        poisson_ratio: 0.29,
        hardness: 7.0e9,
        wear_coefficient: 0.0,
        density: 7850.0,
        pitting_limit: f64::INFINITY,
    }
}

/// The wheel's material when the file gives none (MODEL §11).
pub(super) fn default_wheel_material() -> Material {
    Material {
        name: "chill-cast phosphor bronze CuSn12 (default)".into(),
        youngs_modulus: 110e9,
        poisson_ratio: 0.29,
        hardness: 1.0e9,
        wear_coefficient: 2.5e-8,
        density: 8800.0,
        pitting_limit: 425e6,
    }
}

/// The worm's and the wheel's materials, each its default where the file gives none.
pub(super) fn materials(
    ck: &mut Checker,
    m: &MaterialsSpec,
) -> (Option<Material>, Option<Material>) {
    let worm = material(
        ck,
        "materials.worm",
        m.worm.as_ref(),
        default_worm_material(),
    );
    let wheel = material(
        ck,
        "materials.wheel",
        m.wheel.as_ref(),
        default_wheel_material(),
    );
    (worm, wheel)
}

pub(super) fn material(
    ck: &mut Checker,
    name: &str,
    m: Option<&MaterialSpec>,
    default: Material,
) -> Option<Material> {
    let Some(m) = m else { return Some(default) };
    let field = |f: &str| format!("{name}.{f}");
    let e = ck.range(
        &field("youngs_modulus_gpa"),
        m.youngs_modulus_gpa,
        1.0,
        2000.0,
        "GPa",
    );
    let nu = ck.range(&field("poisson_ratio"), m.poisson_ratio, 0.0, 0.499, "");
    let h = match m.hardness_gpa {
        Some(v) => ck
            .range(&field("hardness_gpa"), v, 0.01, 100.0, "GPa")
            .map(|v| v * 1e9),
        None => Some(default.hardness),
    };
    let k = match m.wear_coefficient {
        Some(v) => ck.range(&field("wear_coefficient"), v, 0.0, 1e-2, ""),
        None => Some(default.wear_coefficient),
    };
    let rho = match m.density_kg_m3 {
        Some(v) => ck.range(&field("density_kg_m3"), v, 100.0, 30_000.0, "kg/m^3"),
        None => Some(default.density),
    };
    let lim = match m.pitting_limit_mpa {
        Some(v) => ck
            .range(&field("pitting_limit_mpa"), v, 10.0, 10_000.0, "MPa")
            .map(|v| v * 1e6),
        None => Some(default.pitting_limit),
    };
    Some(Material {
        name: m.name.clone().unwrap_or_else(|| name.to_string()),
        youngs_modulus: e? * 1e9,
        poisson_ratio: nu?,
        hardness: h?,
        wear_coefficient: k?,
        density: rho?,
        pitting_limit: lim?,
    })
}

pub(super) fn lubricant(ck: &mut Checker, l: &LubricantSpec) -> Option<Lubricant> {
    let mut get = |f: &str, v: Option<f64>, d: f64, lo: f64, hi: f64, unit: &str| match v {
        Some(v) => ck.range(&format!("lubricant.{f}"), v, lo, hi, unit),
        None => Some(d),
    };
    let eta = get(
        "viscosity_pa_s",
        l.viscosity_pa_s,
        0.227,
        1e-4,
        100.0,
        "Pa s",
    );
    let apv = get(
        "pressure_viscosity_per_gpa",
        l.pressure_viscosity_per_gpa,
        9.5,
        0.0,
        100.0,
        "1/GPa",
    );
    let beta = get(
        "thermo_viscosity_k",
        l.thermo_viscosity_k,
        3200.0,
        0.0,
        100_000.0,
        "K",
    );
    let kf = get(
        "thermal_conductivity_w_m_k",
        l.thermal_conductivity_w_m_k,
        0.148,
        0.01,
        10.0,
        "W/(m K)",
    );
    let t = get(
        "temperature_c",
        l.temperature_c,
        333.0 - 273.15,
        -50.0,
        250.0,
        "degC",
    );
    let rq = get(
        "composite_roughness_um",
        l.composite_roughness_um,
        1.0,
        0.001,
        100.0,
        "um",
    );
    let running_in = running_in(ck, l, rq);
    Some(Lubricant {
        name: l
            .name
            .clone()
            .unwrap_or_else(|| "polyglycol (default)".into()),
        viscosity: eta?,
        pressure_viscosity: apv? * 1e-9,
        thermo_viscosity: beta?,
        thermal_conductivity: kf?,
        temperature: t? + 273.15,
        composite_roughness: rq? * 1e-6,
        running_in: running_in?,
    })
}

/// The running-in of the roughness (MODEL §6.1) from `lubricant.run_in_roughness_um` and
/// `lubricant.running_in_depth_um` (both or neither; no default: no measurement of a worm
/// gear's running-in gives a citable pair), the run-in value at most the initial `rq` (um).
/// Some(None): no running-in; None: refused.
fn running_in(ck: &mut Checker, l: &LubricantSpec, rq: Option<f64>) -> Option<Option<RunningIn>> {
    let (roughness, depth) = match (l.run_in_roughness_um, l.running_in_depth_um) {
        (None, None) => return Some(None),
        (Some(r), None) => {
            let problem = "needs lubricant.running_in_depth_um (the worn depth over which the \
                           roughness runs in, um; MODEL §6.1)";
            ck.fail("lubricant.run_in_roughness_um", r, problem);
            return None;
        }
        (None, Some(h)) => {
            let problem = "needs lubricant.run_in_roughness_um (the run-in composite \
                           roughness, um; MODEL §6.1)";
            ck.fail("lubricant.running_in_depth_um", h, problem);
            return None;
        }
        (Some(r), Some(h)) => (r, h),
    };
    let depth = ck.positive("lubricant.running_in_depth_um", depth, 10_000.0, "um");
    let initial = rq?;
    let roughness = match ck.positive("lubricant.run_in_roughness_um", roughness, 100.0, "um")? {
        r if r > initial => {
            let problem = format!(
                "above the initial composite roughness (lubricant.composite_roughness_um = \
                 {initial} um): running-in only smooths a flank"
            );
            ck.fail("lubricant.run_in_roughness_um", r, problem);
            None
        }
        r => Some(r),
    };
    Some(Some(RunningIn {
        roughness: roughness? * 1e-6,
        depth: depth? * 1e-6,
    }))
}

/// The friction law of the mixed lubrication (MODEL §13) from `[lubricant]`, with its
/// defaults: mu_b 0.094 (the low-speed cap of MODEL §9's mu_0T for a bronze wheel with
/// polyglycol, dip lubricated: the boundary regime); Greenwood & Tripp's summit statistics
/// eta_s beta sigma 0.05 and sigma / beta 0.01 (the upper ends of the ranges Greenwood & Tripp
/// 1970-71 give for engineering surfaces, 0.03-0.05 and 1e-4-1e-2: a hobbed bronze wheel is the
/// rough end; measure them); tau_0 5 MPa (Eyring stresses of a few MPa, Johnson & Tevaarwerk
/// 1977); Lambda 0.014 (the limiting shear stress over pressure of Bair & Winer 1979;
/// polyglycols shear low: a DGMK report, Doleschel et al., measured their EHL friction down to
/// 20 % of a mineral oil's 0.045, so 0.009-0.027; 0.014 within it is set on the level of
/// ISO/TR 14521's rig-fitted friction, one value for every gear and speed, VALIDATION.md (e)).
/// Greenwood & Tripp's asymptotics need sigma / beta
/// well below 1 (summits much wider than tall): at most 0.1.
pub(super) fn friction_law(ck: &mut Checker, l: &LubricantSpec) -> Option<FrictionLaw> {
    let mut get = |f: &str, v: Option<f64>, d: f64, lo: f64, hi: f64, unit: &str| match v {
        Some(v) => ck.range(&format!("lubricant.{f}"), v, lo, hi, unit),
        None => Some(d),
    };
    let boundary = get(
        "boundary_friction",
        l.boundary_friction,
        0.094,
        0.0,
        0.999,
        "",
    );
    let summits = get(
        "summit_density_radius_roughness",
        l.summit_density_radius_roughness,
        0.05,
        1e-6,
        1.0,
        "",
    );
    let ratio = get(
        "summit_roughness_radius",
        l.summit_roughness_radius,
        0.01,
        1e-8,
        0.1,
        "",
    );
    let eyring = get(
        "eyring_stress_mpa",
        l.eyring_stress_mpa,
        5.0,
        1e-3,
        1e3,
        "MPa",
    );
    let limiting = get(
        "limiting_shear_coefficient",
        l.limiting_shear_coefficient,
        crate::input::DEFAULT_LIMITING_SHEAR,
        0.0,
        1.0,
        "",
    );
    Some(FrictionLaw {
        boundary: boundary?,
        summit_density_radius_roughness: summits?,
        summit_roughness_radius: ratio?,
        eyring_stress: eyring? * 1e6,
        limiting_shear: limiting?,
    })
}

/// The housing's heat balance (MODEL §13) from `[housing]` and `lubricant.temperature`, with
/// its defaults: the area 43.2 a^1.7 in^2 (a the centre distance in inches) and, for a case
/// without fan, the coefficient n1/6494 + 0.13 ft lbf/(min in^2 F) (n1 the worm speed in rpm)
/// — AGMA's estimates as given in Shigley's Mechanical Engineering Design (worm gearing) —
/// 20 C ambient and no cooler.
pub(super) fn housing(
    ck: &mut Checker,
    h: &HousingSpec,
    l: &LubricantSpec,
    op: &OperatingSpec,
    worm_speed_rpm: f64,
) -> Option<Housing> {
    let balance = ck.choice(
        "lubricant.temperature",
        l.temperature.as_deref().unwrap_or("fixed"),
        &[("fixed", false), ("balance", true)],
    );
    const INCH: f64 = 0.0254;
    let a_inch = (op.centre_distance_mm * 1e-3 / INCH).max(0.0);
    let default_area = 43.2 * a_inch.powf(1.7) * INCH * INCH;
    let default_coefficient = default_heat_transfer(worm_speed_rpm);
    let mut get = |f: &str, v: Option<f64>, d: f64, lo: f64, hi: f64, unit: &str| match v {
        Some(v) => ck.range(&format!("housing.{f}"), v, lo, hi, unit),
        None => Some(d),
    };
    let area = get("area_m2", h.area_m2, default_area, 1e-4, 1e3, "m^2");
    let coefficient = get(
        "heat_transfer_w_m2k",
        h.heat_transfer_w_m2k,
        default_coefficient,
        0.1,
        1e4,
        "W/(m^2 K)",
    );
    let ambient = get("ambient_c", h.ambient_c, 20.0, -60.0, 80.0, "degC");
    let cooler = get("cooler_w", h.cooler_w, 0.0, 0.0, 1e7, "W");
    Some(Housing {
        balance: balance?,
        area: area?,
        heat_transfer: coefficient?,
        ambient: ambient? + 273.15,
        cooler: cooler?,
    })
}

/// The housing's default heat transfer coefficient at worm speed `worm_speed_rpm`, W/(m^2 K):
/// n1/6494 + 0.13 ft lbf/(min in^2 F) for a case without fan (AGMA's estimate as given in
/// Shigley's Mechanical Engineering Design, worm gearing).
pub(super) fn default_heat_transfer(worm_speed_rpm: f64) -> f64 {
    const INCH: f64 = 0.0254;
    // 1 ft lbf/(min in^2 F) in W/(m^2 K).
    let shigley_unit = 1.355_817_948 / 60.0 / (INCH * INCH) * 1.8;
    (worm_speed_rpm.max(0.0) / 6494.0 + 0.13) * shigley_unit
}

pub(super) fn rating_factors(ck: &mut Checker, r: &RatingSpec) -> Option<RatingFactors> {
    let mut factor = |name: &str, v: Option<f64>, d: f64, lo: f64, hi: f64| match v {
        Some(v) => ck.range(&format!("rating.{name}"), v, lo, hi, ""),
        None => Some(d),
    };
    let ys = factor(
        "friction_size_factor",
        r.friction_size_factor,
        1.0,
        0.1,
        10.0,
    );
    let yg = factor(
        "friction_geometry_factor",
        r.friction_geometry_factor,
        1.0,
        0.1,
        10.0,
    );
    let yw = factor(
        "friction_material_factor",
        r.friction_material_factor,
        1.0,
        0.1,
        10.0,
    );
    let yr = factor(
        "friction_roughness_factor",
        r.friction_roughness_factor,
        1.0,
        0.1,
        10.0,
    );
    let z = factor(
        "pitting_life_factor",
        r.pitting_life_factor,
        1.0,
        0.01,
        100.0,
    );
    let ap = factor(
        "pitted_area_max_percent",
        r.pitted_area_max_percent,
        8.0,
        2.0 + 1e-9,
        100.0,
    );
    let safety = safety_inputs(ck, r);
    let assumed = assumed_inputs(ck, r);
    Some(RatingFactors {
        friction_factor: ys? * yg? * yw? * yr?,
        pitting_life_factor: z?,
        pitted_area_max_percent: ap?,
        safety: safety?,
        assumed_inputs: assumed?,
    })
}

/// `rating.assumed_inputs`: each a key of the safety table's inputs given in this `[rating]`.
fn assumed_inputs(ck: &mut Checker, r: &RatingSpec) -> Option<Vec<String>> {
    let given = |name: &str| match name {
        "required_life_h" => r.required_life_h.is_some(),
        "application_factor" => r.application_factor.is_some(),
        "starts_per_hour" => r.starts_per_hour.is_some(),
        "root_stress_allowable_mpa" => r.root_stress_allowable_mpa.is_some(),
        "root_fillet_radius_mm" => r.root_fillet_radius_mm.is_some(),
        "deflection_limit_um" => r.deflection_limit_um.is_some(),
        "thickness_loss_limit_mm" => r.thickness_loss_limit_mm.is_some(),
        "mass_loss_limit_g" => r.mass_loss_limit_g.is_some(),
        "oil_temperature_limit_c" => r.oil_temperature_limit_c.is_some(),
        _ => false,
    };
    let names = r.assumed_inputs.clone().unwrap_or_default();
    let mut ok = true;
    for name in &names {
        if !given(name) {
            ok = false;
            ck.fail(
                "rating.assumed_inputs",
                name,
                "must name a safety-table input given in [rating] (required_life_h, \
                 application_factor, starts_per_hour, root_stress_allowable_mpa, \
                 root_fillet_radius_mm, deflection_limit_um, thickness_loss_limit_mm, \
                 mass_loss_limit_g, oil_temperature_limit_c)",
            );
        }
    }
    ok.then_some(names)
}

/// The safety table's inputs of `[rating]` (MODEL §9.1), in SI.
fn safety_inputs(ck: &mut Checker, r: &RatingSpec) -> Option<SafetyInputs> {
    let mut limit = |name: &str, v: Option<f64>, hi: f64, unit: &str, scale: f64| match v {
        Some(v) => ck
            .positive(&format!("rating.{name}"), v, hi, unit)
            .map(|v| Some(v * scale)),
        None => Some(None),
    };
    let hours = limit("required_life_h", r.required_life_h, 1e7, "h", 1.0);
    let root = limit(
        "root_stress_allowable_mpa",
        r.root_stress_allowable_mpa,
        1e4,
        "MPa",
        1e6,
    );
    let fillet = limit(
        "root_fillet_radius_mm",
        r.root_fillet_radius_mm,
        20.0,
        "mm",
        1e-3,
    );
    let deflection = limit(
        "deflection_limit_um",
        r.deflection_limit_um,
        1e5,
        "um",
        1e-6,
    );
    let thickness = limit(
        "thickness_loss_limit_mm",
        r.thickness_loss_limit_mm,
        100.0,
        "mm",
        1e-3,
    );
    let mass = limit("mass_loss_limit_g", r.mass_loss_limit_g, 1e6, "g", 1e-3);
    let temperature = match r.oil_temperature_limit_c {
        Some(t) => ck
            .range("rating.oil_temperature_limit_c", t, 0.0, 200.0, "degC")
            .map(|t| Some(t + 273.15)),
        None => Some(None),
    };
    let mut factor = |name: &str, v: Option<f64>, d: f64, lo: f64, hi: f64| match v {
        Some(v) => ck.range(&format!("rating.{name}"), v, lo, hi, ""),
        None => Some(d),
    };
    let ka = factor("application_factor", r.application_factor, 1.0, 1.0, 10.0);
    let starts = factor("starts_per_hour", r.starts_per_hour, 0.0, 0.0, 3600.0);
    let minimum = [
        ("minimum_safety_root", r.minimum_safety_root),
        ("minimum_safety_deflection", r.minimum_safety_deflection),
        ("minimum_safety_pitting", r.minimum_safety_pitting),
        ("minimum_safety_wear", r.minimum_safety_wear),
        ("minimum_safety_temperature", r.minimum_safety_temperature),
    ]
    .map(|(name, v)| factor(name, v, 1.0, 0.1, 10.0));
    Some(SafetyInputs {
        required_life_hours: hours?,
        application_factor: ka?,
        starts_per_hour: starts?,
        root_stress_allowable: root?,
        root_fillet_radius: fillet?,
        deflection_limit: deflection?,
        thickness_loss_limit: thickness?,
        mass_loss_limit: mass?,
        oil_temperature_limit: temperature?,
        minimum: [
            minimum[0]?,
            minimum[1]?,
            minimum[2]?,
            minimum[3]?,
            minimum[4]?,
        ],
    })
}

/// The torque and worm speed of `[conditions]` or of a duty-cycle bin (`section`: the name its
/// fields are reported under).
pub(super) fn conditions(
    ck: &mut Checker,
    section: &str,
    c: &ConditionsSpec,
) -> Option<Conditions> {
    let field = |name: &str| format!("{section}.{name}");
    let torque = match (c.worm_torque_nm, c.wheel_torque_nm) {
        (Some(t), None) => ck
            .positive(&field("worm_torque_nm"), t, 1e6, "N m")
            .map(Torque::Worm),
        (None, Some(t)) => ck
            .positive(&field("wheel_torque_nm"), t, 1e8, "N m")
            .map(Torque::Wheel),
        (Some(_), Some(_)) => {
            ck.fail(
                &field("wheel_torque_nm"),
                c.wheel_torque_nm.unwrap_or_default(),
                format!(
                    "give either {} or {}, not both",
                    field("worm_torque_nm"),
                    field("wheel_torque_nm")
                ),
            );
            None
        }
        (None, None) => {
            ck.fail(
                &field("worm_torque_nm"),
                "(missing)",
                format!(
                    "give {} or {}",
                    field("worm_torque_nm"),
                    field("wheel_torque_nm")
                ),
            );
            None
        }
    };
    // Below 1e-3 rpm the film and sliding-speed formulas underflow (1e-300 rpm ended a life
    // in "the reachable cells carry only ... of the load").
    let speed = ck.range(
        &field("worm_speed_rpm"),
        c.worm_speed_rpm,
        1e-3,
        20_000.0,
        "rpm",
    );
    Some(Conditions {
        torque: torque?,
        worm_speed: speed? * 2.0 * PI / 60.0,
    })
}
