//! The materials and the lubricant (`material`, `lubricant`): elastic constants, the wheel's
//! strength, the viscosity law and the pressure-viscosity coefficient.

use super::*;

/// [materials]: Young's modulus, Poisson's ratio, density, hardness; a warning when the wheel
/// is not a bronze.
pub(super) fn materials(
    reader: &Reader,
    parts: &Parts,
    out: &mut GearText,
) -> Result<(), RexsError> {
    for (member, material) in [
        ("worm", parts.worm_material),
        ("wheel", parts.wheel_material),
    ] {
        let Some(m) = material else {
            out.note(&format!(
                "[materials.{member}]: default (no material referenced by the {member})"
            ));
            continue;
        };
        let e = reader.required(m, "elastic_modulus", Quantity::Stress, "Young's modulus")?;
        let nu = reader
            .number(m, "poisson_ratio", Quantity::Ratio)?
            .ok_or_else(|| {
                RexsError::attribute(m, "poisson_ratio", "missing: Poisson's ratio is needed")
            })?;
        let (name, source) = match reader
            .text(m, "material_designation")
            .filter(|s| !s.is_empty())
        {
            Some(n) => (n, "material.material_designation"),
            None => (m.name.clone(), "the material component's name"),
        };
        out.section(&format!("materials.{member}"));
        out.field_text("name", &name, Some(source));
        out.field("youngs_modulus_gpa", e / 1000.0, "material.elastic_modulus");
        out.field("poisson_ratio", nu, "material.poisson_ratio");
        if let Some(rho) = reader.positive(m, "density", Quantity::Density)? {
            out.field("density_kg_m3", rho, "material.density");
        }
        if member == "wheel" {
            wheel_material(reader, m, &name, e, out)?;
        }
    }
    Ok(())
}

pub(super) fn wheel_material(
    reader: &Reader,
    m: &Component,
    name: &str,
    e_mpa: f64,
    out: &mut GearText,
) -> Result<(), RexsError> {
    let hv = reader.positive(m, "surface_hardness_vickers", Quantity::Hardness)?;
    let hb = reader.positive(m, "surface_hardness_brinell", Quantity::Hardness)?;
    let exact = custom(reader, m, "hardness", Quantity::Ratio)?;
    match (hv, hb) {
        _ if exact.is_some() => out.field(
            "hardness_gpa",
            exact.unwrap_or_default(),
            "custom_wormwear_hardness",
        ),
        (Some(h), _) => out.field(
            "hardness_gpa",
            h,
            "material.surface_hardness_vickers x 9.80665e-3",
        ),
        (None, Some(h)) => out.field(
            "hardness_gpa",
            h,
            "material.surface_hardness_brinell x 9.80665e-3",
        ),
        (None, None) => out.note("hardness_gpa: default (no hardness in the file)"),
    }
    let k = custom(reader, m, "wear_coefficient", Quantity::Ratio)?;
    let limit = custom(reader, m, "pitting_limit", Quantity::Stress)?;
    match k {
        Some(k) => out.field("wear_coefficient", k, "custom_wormwear_wear_coefficient"),
        None => out
            .note("wear_coefficient: wormwear's bronze default (REXS has no Archard coefficient)"),
    }
    match limit {
        Some(l) => out.field("pitting_limit_mpa", l, "custom_wormwear_pitting_limit"),
        None => out.note("pitting_limit_mpa: wormwear's bronze default"),
    }
    let lower = name.to_ascii_lowercase();
    let bronze_name = ["cu", "bz", "bronze", "brass"]
        .iter()
        .any(|k| lower.contains(k));
    if !bronze_name || e_mpa > 150_000.0 {
        out.warn(format!(
            "the wheel material \"{name}\" (E = {} GPa) is not a bronze: exports often carry a \
             placeholder here; the wear model and its defaults are for bronze wheels",
            crate::input::Number(e_mpa * 1e-3)
        ));
    }
    Ok(())
}

/// Kinematic viscosity at `t_c` from two points by Ubbelohde-Walther (ASTM D341):
/// log log (nu + 0.7) = A - B log T, nu in mm^2/s, T in K.
pub fn walther_viscosity(nu40: f64, nu100: f64, t_c: f64) -> f64 {
    let w = |nu: f64| (nu + 0.7).log10().log10();
    let (l40, l100) = ((40.0 + 273.15f64).log10(), (100.0 + 273.15f64).log10());
    let b = (w(nu40) - w(nu100)) / (l100 - l40);
    let a = w(nu40) + b * l40;
    10f64.powf(10f64.powf(a - b * (t_c + 273.15).log10())) - 0.7
}

/// Pressure-viscosity coefficient of AGMA 925-A03, alpha = k eta_M^s (alpha in mm^2/N, eta_M
/// the dynamic viscosity at the operating temperature in mPa s), for the base oils it
/// tabulates; 1/GPa. None for other lubricant types.
pub fn agma_pressure_viscosity(lubricant_type: &str, eta_mpa_s: f64) -> Option<f64> {
    let (k, s) = match lubricant_type {
        "mineral_oil" => (0.010471, 0.1348),
        "polyalfaolefin" => (0.010326, 0.0507),
        "non_water_soluble_polyglycol" | "water_soluble_polyglycol" => (0.0047, 0.1572),
        _ => return None,
    };
    Some(1e3 * k * eta_mpa_s.powf(s))
}

/// Volumetric thermal expansion of gear oils used to bring the density at 15 degC to the
/// operating temperature, 1/K (typical of mineral and synthetic gear oils; an importer
/// assumption, stated in the gear file).
pub const OIL_EXPANSION_PER_K: f64 = 7e-4;

/// [lubricant]: dynamic viscosity at the operating temperature from the 40/100 degC kinematic
/// viscosities, thermo-viscosity from the same curve, pressure-viscosity by lubricant type.
pub(super) fn lubricant(
    reader: &Reader,
    parts: &Parts,
    out: &mut GearText,
) -> Result<(), RexsError> {
    let temperature = oil_temperature(reader, parts)?;
    out.section("lubricant");
    let Some(l) = parts.lubricant else {
        out.note("no lubricant component: wormwear's default lubricant");
        if let Some((t, src)) = temperature {
            out.field("temperature_c", t, &src);
        }
        return Ok(());
    };
    let (name, source) = match reader.text(l, "name").filter(|s| !s.is_empty()) {
        Some(n) => (n, "lubricant.name"),
        None => (l.name.clone(), "the lubricant component's name"),
    };
    out.field_text("name", &name, Some(source));
    let (t, t_source) =
        temperature.unwrap_or((60.0, "default: REXS gives no lubricant temperature".into()));
    out.field("temperature_c", t, &t_source);
    if let Some(eta) = custom(reader, l, "viscosity", Quantity::Ratio)? {
        return lubricant_as_written(reader, l, eta, out);
    }
    let eta = viscosity(reader, parts, l, t, out)?;
    pressure_viscosity(reader, l, eta, out)?;
    match reader.positive(l, "thermal_conductivity", Quantity::Conductivity)? {
        Some(k) => out.field(
            "thermal_conductivity_w_m_k",
            k,
            "lubricant.thermal_conductivity",
        ),
        None => out.note("thermal_conductivity_w_m_k: wormwear's default (not in the file)"),
    }
    out.note("composite_roughness_um: wormwear's default (REXS has no flank roughness here)");
    Ok(())
}

/// The oil temperature, degC, and its source: the stage's, else the casing's.
pub(super) fn oil_temperature(
    reader: &Reader,
    parts: &Parts,
) -> Result<Option<Sourced>, RexsError> {
    for c in [Some(parts.stage), parts.casing].into_iter().flatten() {
        if let Some(t) = reader.number(c, "temperature_lubricant", Quantity::Temperature)? {
            return Ok(Some((t, format!("{}.temperature_lubricant", c.kind))));
        }
    }
    Ok(None)
}

/// Writes the dynamic viscosity at `t` degC and the thermo-viscosity coefficient; returns
/// the viscosity, Pa s. The stage's operating viscosity where the file gives it, else the
/// Ubbelohde-Walther line through the 40 and 100 degC viscosities; the density at 15 degC
/// brought to `t` with [`OIL_EXPANSION_PER_K`].
pub(super) fn viscosity(
    reader: &Reader,
    parts: &Parts,
    l: &Component,
    t: f64,
    out: &mut GearText,
) -> Result<f64, RexsError> {
    let q = Quantity::KinematicViscosity;
    let nu40 = reader.positive(l, "viscosity_at_40_degree_celsius", q)?;
    let nu100 = reader.positive(l, "viscosity_at_100_degree_celsius", q)?;
    let operating = reader.positive(parts.stage, "operating_viscosity", q)?;
    let (rho15, rho_note) =
        match reader.positive(l, "density_at_15_degree_celsius", Quantity::Density)? {
            Some(r) => (r, "lubricant.density_at_15_degree_celsius"),
            None => (900.0, "default 900 kg/m^3 (no density in the file)"),
        };
    let density = |tc: f64| rho15 * (1.0 - OIL_EXPANSION_PER_K * (tc - 15.0));
    let walther = nu40
        .zip(nu100)
        .map(|(a, b)| move |tc: f64| walther_viscosity(a, b, tc));
    let density_note = format!("x density ({rho_note}, expansion {OIL_EXPANSION_PER_K}/K)");
    let eta = match (operating, &walther) {
        (Some(nu), _) => {
            let note = format!("worm_stage.operating_viscosity = {nu} mm^2/s {density_note}");
            out.field("viscosity_pa_s", nu * 1e-6 * density(t), &note);
            nu * 1e-6 * density(t)
        }
        (None, Some(w)) => {
            let note = format!(
                "nu({t} degC) by Ubbelohde-Walther (ASTM D341) through lubricant.\
                 viscosity_at_40_degree_celsius and viscosity_at_100_degree_celsius {density_note}"
            );
            out.field("viscosity_pa_s", w(t) * 1e-6 * density(t), &note);
            w(t) * 1e-6 * density(t)
        }
        (None, None) => {
            let need = "missing: the lubricant's viscosities at 40 and 100 degC (or \
                        worm_stage.operating_viscosity) are needed";
            let missing = match nu40 {
                None => "viscosity_at_40_degree_celsius",
                Some(_) => "viscosity_at_100_degree_celsius",
            };
            return Err(RexsError::attribute(l, missing, need));
        }
    };
    match walther {
        Some(w) => {
            let eta_at = |tc: f64| w(tc) * 1e-6 * density(tc);
            let (t1, t2) = (t - 10.0 + 273.15, t + 10.0 + 273.15);
            let beta = (eta_at(t - 10.0) / eta_at(t + 10.0)).ln() / (1.0 / t1 - 1.0 / t2);
            let note = "d ln(eta) / d(1/T) of the Walther line over +/- 10 K";
            out.field("thermo_viscosity_k", beta, note);
        }
        None => out.note("thermo_viscosity_k: wormwear's default (no 40 / 100 degC viscosities)"),
    }
    Ok(eta)
}

/// Writes the pressure-viscosity coefficient: the file's AGMA 925-A03 value, else k eta^s with
/// the file's k and s, else with AGMA 925-A03's k and s for the lubricant type, else the
/// default (warned). `eta` in Pa s.
pub(super) fn pressure_viscosity(
    reader: &Reader,
    l: &Component,
    eta: f64,
    out: &mut GearText,
) -> Result<(), RexsError> {
    let key = "pressure_viscosity_per_gpa";
    let given = "pressure_viscosity_coefficient_agma_925_a03";
    if let Some(a) = reader.positive(l, given, Quantity::PressureViscosity)? {
        out.field(key, a, &format!("lubricant.{given}"));
        return Ok(());
    }
    let k_id = "parameter_k_for_calculation_of_pressure_viscosity_coefficient_agma_925_a03";
    let s_id = "parameter_s_for_calculation_of_pressure_viscosity_coefficient_agma_925_a03";
    let k = reader.positive(l, k_id, Quantity::Ratio)?;
    let s = reader.number(l, s_id, Quantity::Ratio)?;
    if let (Some(k), Some(s)) = (k, s) {
        let note = "AGMA 925-A03: k eta^s with the file's k and s (eta in mPa s, alpha in mm^2/N)";
        out.field(key, 1e3 * k * (eta * 1e3).powf(s), note);
        return Ok(());
    }
    let kind = reader
        .text(l, "lubricant_type_iso_6336_2006")
        .unwrap_or_default();
    match agma_pressure_viscosity(&kind, eta * 1e3) {
        Some(a) => out.field(key, a, &format!(
            "AGMA 925-A03: k eta^s for {kind} at the operating viscosity"
        )),
        None => out.warn(format!(
            "lubricant type \"{kind}\" has no pressure-viscosity rule (AGMA 925-A03 tabulates mineral oil, PAO and PAG): wormwear's default is used"
        )),
    }
    Ok(())
}

/// The lubricant law of a file wormwear wrote (custom attributes), taken as it is.
pub(super) fn lubricant_as_written(
    reader: &Reader,
    l: &Component,
    eta: f64,
    out: &mut GearText,
) -> Result<(), RexsError> {
    out.field("viscosity_pa_s", eta, "custom_wormwear_viscosity");
    for (name, key, q) in [
        (
            "pressure_viscosity_per_gpa",
            "pressure_viscosity_per_gpa",
            Quantity::Ratio,
        ),
        ("thermo_viscosity", "thermo_viscosity_k", Quantity::Ratio),
        (
            "thermal_conductivity",
            "thermal_conductivity_w_m_k",
            Quantity::Ratio,
        ),
        (
            "composite_roughness",
            "composite_roughness_um",
            Quantity::Ratio,
        ),
        ("run_in_roughness", "run_in_roughness_um", Quantity::Ratio),
        ("running_in_depth", "running_in_depth_um", Quantity::Ratio),
    ] {
        if let Some(v) = custom_any_unit(reader, l, name, q)? {
            out.field(key, v, &format!("{CUSTOM_PREFIX}{name}"));
        }
    }
    Ok(())
}

/// A custom attribute's number as written, whatever its unit (wormwear writes each in the
/// unit of the gear-file field it stands for).
pub(super) fn custom_any_unit(
    reader: &Reader,
    c: &Component,
    name: &str,
    _q: Quantity,
) -> Result<Option<f64>, RexsError> {
    let id = format!("{CUSTOM_PREFIX}{name}");
    let Some(a) = c.attribute(&id) else {
        return Ok(None);
    };
    reader.mark(c, &id);
    match &a.value {
        Value::Float(x) => Ok(Some(*x)),
        Value::Integer(i) => Ok(Some(*i as f64)),
        Value::Text(s) => s
            .trim()
            .parse()
            .map(Some)
            .map_err(|_| RexsError::attribute(c, &id, format!("\"{s}\" is not a number"))),
        other => Err(RexsError::attribute(
            c,
            &id,
            format!("{other} is not a number"),
        )),
    }
}
