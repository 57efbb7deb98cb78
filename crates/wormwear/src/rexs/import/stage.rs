//! The stage's operating data (`worm_stage`, the load spectrum): centre distance, speed, sense
//! of rotation, torque.

use super::*;

/// [operating]: centre distance and its deviations.
/// `rotation`: the worm's sense of rotation and its source ([`rotation`]).
pub(super) fn operating(
    reader: &Reader,
    parts: &Parts,
    (worm, wheel): (&Worm, &Wheel),
    rotation: (&'static str, String),
    out: &mut GearText,
) -> Result<(), RexsError> {
    let s = parts.stage;
    let a = reader.required(
        s,
        "center_distance",
        Quantity::Length,
        "the centre distance a",
    )?;
    let da = reader
        .number(s, "center_distance_offset", Quantity::Length)?
        .unwrap_or(0.0);
    let width = reader
        .number(s, "width_offset", Quantity::Length)?
        .unwrap_or(0.0);
    let shaft_angle = reader
        .number(s, "intersection_angle_offset", Quantity::Angle)?
        .unwrap_or(0.0);
    let tilt = reader
        .number(s, "inclination_angle_offset", Quantity::Angle)?
        .unwrap_or(0.0);
    out.section("operating");
    out.field("centre_distance_mm", a, "worm_stage.center_distance");
    out.field(
        "centre_distance_error_mm",
        da,
        "worm_stage.center_distance_offset",
    );
    out.field(
        "worm_offset_mm",
        width,
        "worm_stage.width_offset (along the wheel axis)",
    );
    out.field(
        "inclination_deg",
        shaft_angle,
        "worm_stage.intersection_angle_offset (shaft-angle error)",
    );
    if tilt != 0.0 {
        out.warn(format!("worm_stage.inclination_angle_offset = {tilt} deg is not modelled (only the shaft-angle error is)"));
    }
    out.field_text("worm_rotation", rotation.0, Some(&rotation.1));
    let ratio = wheel.teeth as f64 / worm.starts as f64;
    out.note(&format!(
        "ratio z2/z1 = {}; lead angle {} deg; wheel reference radius {} mm; face width {} mm",
        Shown(ratio),
        Shown(worm.lead_angle_deg),
        Shown(wheel.reference_radius),
        Shown(wheel.face_width)
    ));
    Ok(())
}

/// The worm speed with its sign (about the worm shaft's u axis), rpm, and its source.
pub(super) fn worm_speed(
    reader: &Reader,
    parts: &Parts,
) -> Result<Option<(f64, String)>, RexsError> {
    for (c, label) in [(parts.worm_shaft, "shaft"), (Some(parts.worm), "worm_gear")] {
        if let Some(c) = c {
            if let Some(n) = reader.number(c, "rotational_speed", Quantity::Speed)? {
                if n != 0.0 {
                    return Ok(Some((n, format!("{label} [{}].rotational_speed", c.id))));
                }
            }
        }
    }
    Ok(None)
}

/// worm_rotation from the signs of the speed and the hand; default positive.
pub(super) fn rotation(
    reader: &Reader,
    parts: &Parts,
    worm: &Worm,
) -> Result<(&'static str, String), RexsError> {
    Ok(match worm_speed(reader, parts)? {
        Some((n, source)) => {
            let positive = (n > 0.0) == worm.right_hand;
            (
                if positive { "positive" } else { "negative" },
                format!("from the sign of {source} = {n} rpm about the worm axis and the hand"),
            )
        }
        None => (
            "positive",
            "default: the worm speed's sign is not given".to_string(),
        ),
    })
}

/// [conditions]: worm speed and the torque that defines the load.
pub(super) fn conditions(
    reader: &Reader,
    parts: &Parts,
    worm: &Worm,
    out: &mut GearText,
) -> Result<(), RexsError> {
    let (speed, (member, torque, source)) = load(reader, parts, worm)?;
    out.section("conditions");
    out.field(&format!("{member}_torque_nm"), torque, &source);
    out.field("worm_speed_rpm", speed.0, &speed.1);
    driving_warning(reader, parts, out);
    Ok(())
}

/// The file's note when it has the wheel driving.
fn driving_warning(reader: &Reader, parts: &Parts, out: &mut GearText) {
    if let Some(g) = parts.wheel_gear_data {
        if reader.boolean(g, "is_driving_gear") == Some(true) {
            out.warn(
                "the file has the wheel driving; wormwear analyses the worm driving the wheel"
                    .into(),
            );
        }
    }
    if let Some(g) = parts.worm_gear_data {
        let _ = reader.boolean(g, "is_driving_gear");
    }
}

/// [[duty_cycle]] from the model's load spectrum (MODEL §14): one bin per load case, its speed
/// and torque read as `[conditions]` reads them on the master model completed by the case,
/// its time share from the case's `load_duration_fraction` (or its hours from
/// `load_duration`), its oil temperature from a varied `temperature_lubricant`.
pub(super) fn duty_cycle(
    model: &Model,
    info: &StageInfo,
    worm: &Worm,
    out: &mut GearText,
) -> Result<(), RexsError> {
    for case in &model.load_cases {
        let whole = model.with_load_case(case);
        let (reader, parts) = (Reader::new(&whole), Parts::locate(&whole, info)?);
        let (speed, (member, torque, source)) = load(&reader, &parts, worm)?;
        let at = format!("load case {}", case.id);
        out.section("[duty_cycle]");
        out.field(
            &format!("{member}_torque_nm"),
            torque,
            &format!("{at}: {source}"),
        );
        out.field("worm_speed_rpm", speed.0, &format!("{at}: {}", speed.1));
        let (key, value, source) = case_duration(&reader, case)?;
        out.field(key, value, &format!("{at}: {source}"));
        let varied = case
            .components
            .iter()
            .find(|c| c.attribute("temperature_lubricant").is_some());
        if let Some(c) = varied.and_then(|v| whole.component(v.id)) {
            if let Some(t) = reader.number(c, "temperature_lubricant", Quantity::Temperature)? {
                let what = format!("{at}: {} [{}].temperature_lubricant", c.kind, c.id);
                out.field("oil_temperature_c", t, &what);
            }
        }
        if case.id == model.load_cases[0].id {
            driving_warning(&reader, &parts, out);
        }
    }
    Ok(())
}

/// A load case's share of the running time: `load_duration_fraction` (as `time_share`) or
/// `load_duration` (as `hours`) on one of its components.
fn case_duration(
    reader: &Reader,
    case: &LoadCase,
) -> Result<(&'static str, f64, String), RexsError> {
    for c in &case.components {
        if let Some(share) = reader.number(c, "load_duration_fraction", Quantity::Share)? {
            let source = format!("{} [{}].load_duration_fraction", c.kind, c.id);
            return Ok(("time_share", share, source));
        }
        if let Some(hours) = reader.number(c, "load_duration", Quantity::Duration)? {
            let source = format!("{} [{}].load_duration", c.kind, c.id);
            return Ok(("hours", hours, source));
        }
    }
    Err(RexsError::Model(format!(
        "load case {}: no load_duration_fraction or load_duration: each load case of the \
         load spectrum needs its share of the running time",
        case.id
    )))
}

/// The worm speed (rpm, |n|) with its source, and the defining torque ([`torque`]).
#[allow(clippy::type_complexity)]
fn load(
    reader: &Reader,
    parts: &Parts,
    worm: &Worm,
) -> Result<((f64, String), (&'static str, f64, String)), RexsError> {
    let z2 = reader.integer(parts.wheel, "number_of_teeth")?.unwrap_or(1) as f64;
    let ratio = z2 / worm.starts as f64;
    let speed = match worm_speed(reader, parts)? {
        Some((n, source)) => (n.abs(), source),
        None => {
            let wheel_speed = [parts.wheel_shaft, Some(parts.wheel)]
                .into_iter()
                .flatten()
                .map(|c| reader.number(c, "rotational_speed", Quantity::Speed))
                .collect::<Result<Vec<_>, _>>()?
                .into_iter()
                .flatten()
                .find(|n| *n != 0.0);
            match wheel_speed {
                Some(n) => (
                    n.abs() * ratio,
                    "wheel shaft rotational_speed x z2/z1".to_string(),
                ),
                None => {
                    return Err(RexsError::attribute(
                        parts.worm_shaft.unwrap_or(parts.worm),
                        "rotational_speed",
                        "missing: a rotational speed of the worm (or wheel) shaft is needed",
                    ))
                }
            }
        }
    };
    Ok((speed, torque(reader, parts)?))
}

/// The defining torque: "worm" or "wheel", |T| in N m, and its source.
pub(super) fn torque(
    reader: &Reader,
    parts: &Parts,
) -> Result<(&'static str, f64, String), RexsError> {
    for (member, loads) in [("worm", &parts.worm_loads), ("wheel", &parts.wheel_loads)] {
        for l in loads.iter() {
            let defines = reader.boolean(l, "defines_torque").unwrap_or(false);
            if let Some(t) = reader.number(l, "torque_around_u_axis", Quantity::Torque)? {
                if defines && t != 0.0 {
                    return Ok((
                        member,
                        t.abs(),
                        format!(
                            "external_load [{}].torque_around_u_axis (defines_torque)",
                            l.id
                        ),
                    ));
                }
            }
        }
    }
    for (member, data) in [
        ("wheel", parts.wheel_gear_data),
        ("worm", parts.worm_gear_data),
    ] {
        if let Some(g) = data {
            if let Some(t) = reader.number(g, "torque", Quantity::Torque)? {
                if t != 0.0 {
                    return Ok((
                        member,
                        t.abs(),
                        format!("worm_stage_gear_data [{}].torque", g.id),
                    ));
                }
            }
        }
    }
    Err(RexsError::attribute(
        parts.stage,
        "torque",
        "missing: the load is needed: an external_load with defines_torque and \
         torque_around_u_axis on the worm or wheel shaft, or worm_stage_gear_data.torque",
    ))
}
