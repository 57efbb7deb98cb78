//! The wheel (`worm_wheel`): its blank, face width and radii, and the checks of its attributes
//! against the worm's.

use super::*;

/// The wheel as imported, mm.
pub(super) struct Wheel {
    pub(super) teeth: i64,
    pub(super) reference_radius: f64,
    pub(super) face_width: f64,
}

/// [wheel]: teeth, face width, outer and throat radii; consistency with the worm.
pub(super) fn wheel_blank(
    reader: &Reader,
    parts: &Parts,
    worm: &Worm,
    out: &mut GearText,
) -> Result<Wheel, RexsError> {
    let c = parts.wheel;
    let z2 = reader.count(c, "number_of_teeth", "the number of wheel teeth z2", 500)?;
    let a = reader.required(
        parts.stage,
        "center_distance",
        Quantity::Length,
        "the centre distance a",
    )?;
    let m = worm.axial_module;
    let d2 = z2 as f64 * m;
    let x2 = (a - worm.reference_radius - 0.5 * d2) / m;
    let (b2, width_source) = face_width(reader, c)?;
    let (tip, outer) = wheel_radii(reader, c, d2, x2, m)?;
    out.section("wheel");
    out.line("teeth", z2.to_string(), Some("worm_wheel.number_of_teeth"));
    out.field("face_width_mm", b2, &width_source);
    out.field("outer_radius_mm", outer.0, &outer.1);
    out.field(
        "throat_radius_mm",
        tip.0,
        &format!("wheel tip radius r_a2 at the median plane: {}", tip.1),
    );
    for (field, name) in [
        ("rim_thickness", "rim_thickness_mm"),
        ("web_thickness", "web_thickness_mm"),
        ("hub_radius", "hub_radius_mm"),
        ("face_edge_chamfer", "face_edge_chamfer_mm"),
    ] {
        if let Some(v) = custom(reader, c, field, Quantity::Length)? {
            out.field(name, v, &format!("{CUSTOM_PREFIX}{field}"));
        }
    }
    out.note(&format!(
        "d_2 = z2 m_x = {} mm; profile shift x2 = (a - d_m1/2 - d_2/2) / m_x = {}",
        Shown(d2),
        Shown(x2)
    ));
    wheel_checks(reader, parts, worm, a, d2, tip.0, out)?;
    Ok(Wheel {
        teeth: z2,
        reference_radius: 0.5 * d2,
        face_width: b2,
    })
}

/// The wheel's face width: the face width, else the effective face width, else the rim width.
pub(super) fn face_width(reader: &Reader, c: &Component) -> Result<Sourced, RexsError> {
    let ids = [
        "face_width_worm_wheel",
        "effective_face_width_worm_wheel",
        "rim_width_worm_wheel",
    ];
    for id in ids {
        if let Some(b) = reader.positive(c, id, Quantity::Length)? {
            return Ok((b, format!("worm_wheel.{id}")));
        }
    }
    let need = "missing: the wheel face width is needed (or effective_face_width_worm_wheel, \
                rim_width_worm_wheel)";
    Err(RexsError::attribute(c, "face_width_worm_wheel", need))
}

/// The wheel's tip (throat) and outer radii, mm: the file's, else DIN 3975's rules.
pub(super) fn wheel_radii(
    reader: &Reader,
    c: &Component,
    d2: f64,
    x2: f64,
    m: f64,
) -> Result<(Sourced, Sourced), RexsError> {
    let tip = match reader.positive(c, "tip_diameter_worm_gear", Quantity::Length)? {
        Some(d) => (0.5 * d, "worm_wheel.tip_diameter_worm_gear / 2".to_string()),
        None => (
            0.5 * d2 + (1.0 + x2) * m,
            "worm_wheel.tip_diameter_worm_gear not given (absent or 0): default d_a2 = d_2 + \
             2 (1 + x2) m_x (DIN 3975, h_a* = 1)"
                .to_string(),
        ),
    };
    let outer = match reader.positive(c, "outer_diameter_worm_wheel", Quantity::Length)? {
        Some(d) => (
            0.5 * d,
            "worm_wheel.outer_diameter_worm_wheel / 2".to_string(),
        ),
        None => (
            tip.0 + 0.5 * m,
            "worm_wheel.outer_diameter_worm_wheel not given (absent or 0): default d_e2 = \
             d_a2 + m_x (DIN 3975 guidance)"
                .to_string(),
        ),
    };
    Ok((tip, outer))
}

/// Warnings where the wheel's attributes disagree with the worm's data.
pub(super) fn wheel_checks(
    reader: &Reader,
    parts: &Parts,
    worm: &Worm,
    a: f64,
    d2: f64,
    tip: f64,
    out: &mut GearText,
) -> Result<(), RexsError> {
    let c = parts.wheel;
    if let Some(m) = reader.positive(c, "axial_module", Quantity::Length)? {
        if (m - worm.axial_module).abs() > 1e-6 * worm.axial_module.max(1.0) {
            out.warn(format!(
                "worm_wheel.axial_module = {m} mm differs from the worm's {} mm; the worm's is used",
                worm.axial_module
            ));
        }
    }
    if let Some(d) = reader.positive(c, "reference_diameter_worm_gear", Quantity::Length)? {
        if (d - d2).abs() > 1e-3 {
            out.warn(format!(
                "worm_wheel.reference_diameter_worm_gear = {} mm differs from z2 m_x = {} mm",
                Shown(d),
                Shown(d2)
            ));
        }
    }
    if let Some(rk) = reader.positive(c, "throat_radius_worm_wheel", Quantity::Length)? {
        if (rk - (a - tip)).abs() > 0.01 {
            out.warn(format!(
                "worm_wheel.throat_radius_worm_wheel = {} mm: wormwear's blank has the gorge radius a - r_a2 = {} mm",
                Shown(rk),
                Shown(a - tip)
            ));
        }
    } else {
        out.note(&format!(
            "gorge radius of the blank: a - r_a2 = {} mm (REXS throat radius absent or 0)",
            Shown(a - tip)
        ));
    }
    let wheel_form = c
        .attribute("flank_form")
        .map(|_| profile_of(reader, c))
        .transpose()?;
    if let Some(p) = wheel_form {
        if p != worm.profile {
            out.warn(format!(
                "the wheel's flank form Z{p} differs from the worm's Z{}",
                worm.profile
            ));
        }
    }
    Ok(())
}
