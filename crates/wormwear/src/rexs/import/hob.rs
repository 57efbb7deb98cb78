//! The hob (`worm_wheel_hob_tool`) and the cutting settings it cuts the wheel with (MODEL §3): its
//! thread, radii and placement.

use super::*;

/// What the hob tool gives, each None where the file has no value.
pub(super) struct HobTool {
    pub(super) profile: Option<char>,
    pub(super) starts: Option<i64>,
    pub(super) lead: Option<f64>,
    pub(super) pressure_angle: Option<f64>,
    pub(super) reference_diameter: Option<f64>,
    pub(super) axial_thickness: Option<f64>,
}

pub(super) fn read_hob(reader: &Reader, hob: Option<&Component>) -> Result<HobTool, RexsError> {
    let Some(h) = hob else {
        return Ok(HobTool {
            profile: None,
            starts: None,
            lead: None,
            pressure_angle: None,
            reference_diameter: None,
            axial_thickness: None,
        });
    };
    let profile = match h.attribute("flank_form") {
        Some(_) => Some(profile_of(reader, h)?),
        None => None,
    };
    Ok(HobTool {
        profile,
        starts: reader.integer(h, "number_of_teeth")?.filter(|z| *z > 0),
        lead: reader.positive(h, "lead", Quantity::Length)?,
        pressure_angle: reader.positive(h, "pressure_angle_worm_gear", Quantity::Angle)?,
        reference_diameter: custom(reader, h, "reference_diameter", Quantity::Length)?,
        axial_thickness: custom(reader, h, "axial_thickness", Quantity::Length)?,
    })
}

/// The wheel's manufacturing settings: centre-distance and pressure-angle corrections.
pub(super) fn corrections(reader: &Reader, parts: &Parts) -> Result<(f64, f64), RexsError> {
    let Some(s) = parts.wheel_settings else {
        return Ok((0.0, 0.0));
    };
    let da = reader.number(s, "center_distance_correction", Quantity::Length)?;
    let dalpha = reader.number(s, "pressure_angle_correction", Quantity::Angle)?;
    Ok((da.unwrap_or(0.0), dalpha.unwrap_or(0.0)))
}

/// [hob]: the worm_wheel_hob_tool where the file has one, otherwise the worm with its tip
/// raised to cut the wheel's root; then [cutting].
pub(super) fn hob_thread(
    reader: &Reader,
    parts: &Parts,
    worm: &Worm,
    out: &mut GearText,
) -> Result<(), RexsError> {
    let what = "the centre distance a";
    let a = reader.required(parts.stage, "center_distance", Quantity::Length, what)?;
    let (correction, alpha_correction) = corrections(reader, parts)?;
    let wheel_root = reader.positive(parts.wheel, "root_diameter_worm_gear", Quantity::Length)?;
    let tool = read_hob(reader, parts.hob)?;
    let from = |given: bool, attr: &str| match given {
        true => format!("worm_wheel_hob_tool.{attr}"),
        false => "the worm's (REXS gives no hob value)".to_string(),
    };
    let profile = tool.profile.unwrap_or(worm.profile);
    if profile != worm.profile {
        out.warn(format!(
            "the hob's flank form Z{profile} differs from the worm's Z{}",
            worm.profile
        ));
    }
    out.section("hob");
    let profile_note = from(tool.profile.is_some(), "flank_form");
    out.field_text("profile", &profile.to_string(), Some(&profile_note));
    let starts = tool.starts.unwrap_or(worm.starts).to_string();
    out.line(
        "starts",
        starts,
        Some(&from(tool.starts.is_some(), "number_of_teeth")),
    );
    let hand = if worm.right_hand { "right" } else { "left" };
    out.field_text("hand", hand, Some("the worm's"));
    match tool.lead {
        Some(l) => out.field("lead_mm", l, "worm_wheel_hob_tool.lead"),
        None => out.field("axial_module_mm", worm.axial_module, "the worm's"),
    }
    match tool.reference_diameter {
        Some(d) => out.field(
            "reference_radius_mm",
            0.5 * d,
            "custom_wormwear_reference_diameter / 2",
        ),
        None => out.field(
            "reference_radius_mm",
            worm.reference_radius,
            "the worm's (a hob of the worm's size)",
        ),
    }
    let mut alpha_note = from(tool.pressure_angle.is_some(), "pressure_angle_worm_gear");
    if alpha_correction != 0.0 {
        alpha_note.push_str(" + worm_gear_manufacturing_settings.pressure_angle_correction");
    }
    let alpha = tool.pressure_angle.unwrap_or(worm.pressure_angle) + alpha_correction;
    out.field("pressure_angle_deg", alpha, &alpha_note);
    let plane = if worm.normal_plane { "normal" } else { "axial" };
    out.field_text("pressure_angle_plane", plane, Some("as the worm's"));
    let (tip, root) = hob_radii(reader, parts.hob, worm, a + correction, wheel_root)?;
    out.field("tip_radius_mm", tip.0, &tip.1);
    out.field("root_radius_mm", root.0, &root.1);
    match tool.axial_thickness {
        Some(t) => out.field("axial_thickness_mm", t, "custom_wormwear_axial_thickness"),
        None => out.field("axial_thickness_mm", worm.axial_thickness, "the worm's"),
    }
    if let Some(g) = worm.grinding {
        write_grinding(out, "hob", g);
    }
    cutting(reader, parts, a, correction, out)
}

/// [cutting]: the hobbing centre distance; the settings wormwear does not model, warned.
pub(super) fn cutting(
    reader: &Reader,
    parts: &Parts,
    a: f64,
    correction: f64,
    out: &mut GearText,
) -> Result<(), RexsError> {
    out.section("cutting");
    let note = if correction != 0.0 {
        "worm_stage.center_distance + worm_gear_manufacturing_settings.center_distance_correction"
    } else {
        "worm_stage.center_distance (no centre-distance correction in the file)"
    };
    out.field("centre_distance_mm", a + correction, note);
    out.field("offset_mm", 0.0, "default: hob centred on the wheel");
    out.field("inclination_deg", 0.0, "default");
    let Some(s) = parts.wheel_settings else {
        return Ok(());
    };
    if let Some(l) = reader.number(s, "lyra_angle", Quantity::Angle)? {
        if l != 0.0 {
            out.warn(format!(
                "lyra angle {l} deg of the wheel's hobbing is not modelled"
            ));
        }
    }
    if let Some(p) = reader.text(s, "hobbing_procedure") {
        out.note(&format!(
            "hobbing procedure {p}: the wheel is the hob's envelope either way"
        ));
    }
    Ok(())
}

/// The hob's tip and root radii with their sources, mm.
pub(super) fn hob_radii(
    reader: &Reader,
    hob: Option<&Component>,
    worm: &Worm,
    cutting_distance: f64,
    wheel_root: Option<f64>,
) -> Result<(Sourced, Sourced), RexsError> {
    let clearance = 0.2 * worm.axial_module;
    let tip_given = match hob {
        Some(h) => reader
            .positive(h, "tip_diameter_worm_gear", Quantity::Length)?
            .map(|d| 0.5 * d),
        None => None,
    };
    let tip = match (tip_given, wheel_root) {
        (Some(t), _) => (t, "worm_wheel_hob_tool.tip_diameter_worm_gear / 2".to_string()),
        (None, Some(d)) => (
            round_nm(cutting_distance - 0.5 * d),
            "cutting centre distance - worm_wheel.root_diameter_worm_gear / 2 (the hob tip cuts the wheel root)".to_string(),
        ),
        (None, None) => (
            worm.tip_radius + clearance,
            "worm_wheel_hob_tool.tip_diameter_worm_gear and worm_wheel.root_diameter_worm_gear \
             not given (absent or 0): default worm tip + bottom clearance 0.2 m_x (DIN 3975)"
                .to_string(),
        ),
    };
    let custom_root = match hob {
        Some(h) => custom(reader, h, "root_diameter", Quantity::Length)?.map(|d| 0.5 * d),
        None => None,
    };
    let depth = match hob {
        Some(h) => reader.positive(h, "tooth_depth_worm_wheel_hob", Quantity::Length)?,
        None => None,
    };
    let root = match (custom_root, depth) {
        (Some(r), _) => (r, "custom_wormwear_root_diameter / 2".to_string()),
        (None, Some(h)) => (
            round_nm(tip.0 - h),
            "tip radius - worm_wheel_hob_tool.tooth_depth_worm_wheel_hob".to_string(),
        ),
        (None, None) => (
            worm.root_radius,
            "the worm's (the hob root does not cut the wheel)".to_string(),
        ),
    };
    Ok((tip, root))
}

/// A length in mm rounded to the nanometre: differences of file values carry round-off
/// (100 - 77.2 = 22.799999999999997) that would only clutter the gear file.
pub(super) fn round_nm(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}
