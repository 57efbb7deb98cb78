//! The worm (`worm_gear`) and its grinding disc (MODEL §1, §2): profile, starts, module, lead,
//! thread thickness and radii.

use super::*;

/// The worm thread as imported (lengths in mm, angles in degrees).
pub(super) struct Worm {
    pub(super) profile: char,
    pub(super) starts: i64,
    pub(super) right_hand: bool,
    pub(super) axial_module: f64,
    pub(super) reference_radius: f64,
    pub(super) tip_radius: f64,
    pub(super) root_radius: f64,
    pub(super) pressure_angle: f64,
    pub(super) normal_plane: bool,
    pub(super) axial_thickness: f64,
    pub(super) lead_angle_deg: f64,
    pub(super) grinding: Option<Grinding>,
}

/// Grinding disc of ZK/ZC worms, mm and degrees.
#[derive(Clone, Copy)]
pub(super) struct Grinding {
    pub(super) radius: f64,
    pub(super) profile_angle: Option<f64>,
    pub(super) profile_radius: Option<f64>,
}

pub(super) fn profile_of(reader: &Reader, c: &Component) -> Result<char, RexsError> {
    let form = reader.text(c, "flank_form").ok_or_else(|| {
        RexsError::attribute(
            c,
            "flank_form",
            "missing: the flank form (za, zn, zi, zk, zc) is needed",
        )
    })?;
    match form.to_ascii_lowercase().as_str() {
        "za" => Ok('A'),
        "zn" => Ok('N'),
        "zi" => Ok('I'),
        "zk" => Ok('K'),
        "zc" => Ok('C'),
        other => Err(RexsError::attribute(
            c,
            "flank_form",
            format!("\"{other}\" is not a worm flank form (za, zn, zi, zk, zc)"),
        )),
    }
}

/// [worm]: form, starts, module, diameters, pressure angle and its plane, hand.
pub(super) fn worm_thread(
    reader: &Reader,
    parts: &Parts,
    out: &mut GearText,
) -> Result<Worm, RexsError> {
    let (worm, sources) = read_worm(reader, parts)?;
    out.section("worm");
    let form = worm.profile.to_string();
    out.field_text("profile", &form, Some("worm_gear.flank_form"));
    out.line(
        "starts",
        worm.starts.to_string(),
        Some("worm_gear.number_of_teeth"),
    );
    let hand = if worm.right_hand { "right" } else { "left" };
    out.field_text("hand", hand, Some(&sources.hand));
    out.field("axial_module_mm", worm.axial_module, &sources.module);
    let diameter = |what: &str| format!("worm_gear.{what}_diameter_worm_gear / 2");
    out.field(
        "reference_radius_mm",
        worm.reference_radius,
        &diameter("reference"),
    );
    out.field("tip_radius_mm", worm.tip_radius, &diameter("tip"));
    out.field("root_radius_mm", worm.root_radius, &diameter("root"));
    let alpha_note = "worm_gear.pressure_angle_worm_gear (alpha_0)";
    out.field("pressure_angle_deg", worm.pressure_angle, alpha_note);
    let plane = if worm.normal_plane { "normal" } else { "axial" };
    let plane_note = "as the flank form implies (DIN 3975: ZA axial, ZN/ZI/ZK/ZC normal)";
    out.field_text("pressure_angle_plane", plane, Some(plane_note));
    out.field(
        "axial_thickness_mm",
        worm.axial_thickness,
        &sources.thickness,
    );
    // The broken tip edge wormwear wrote (MODEL §2.3; REXS has no attribute for it).
    let tip_edge = custom(reader, parts.worm, "tip_edge_radius", Quantity::Length)?;
    if let Some(r) = tip_edge {
        out.field(
            "tip_edge_radius_mm",
            r,
            &format!("{CUSTOM_PREFIX}tip_edge_radius"),
        );
    }
    out.note(&format!(
        "lead angle atan(z1 m_x / d_m1) = {} deg; tip relief: wormwear's default",
        Shown(worm.lead_angle_deg)
    ));
    if let Some(g) = sources.lead_angle {
        if (g.abs() - worm.lead_angle_deg).abs() > 0.01 {
            out.warn(format!(
                "worm_gear.lead_angle_worm_gear = {} deg does not match atan(z1 m_x / d_m1) = \
                 {} deg; the module and the diameter are used",
                Shown(g),
                Shown(worm.lead_angle_deg)
            ));
        }
    }
    if let Some(g) = worm.grinding {
        write_grinding(out, "worm", g);
    }
    Ok(worm)
}

/// Where the worm's values came from, for the comments.
pub(super) struct WormSources {
    pub(super) hand: String,
    pub(super) module: String,
    pub(super) thickness: String,
    /// The file's lead angle, degrees (signed).
    pub(super) lead_angle: Option<f64>,
}

/// The worm's attributes, read and checked.
pub(super) fn read_worm(reader: &Reader, parts: &Parts) -> Result<(Worm, WormSources), RexsError> {
    let c = parts.worm;
    let profile = profile_of(reader, c)?;
    let starts = reader.count(c, "number_of_teeth", "the number of starts z1", 10)?;
    let length = |id: &str, what: &str| reader.required(c, id, Quantity::Length, what);
    let d1 = length(
        "reference_diameter_worm_gear",
        "the reference diameter d_m1",
    )?;
    let da = length("tip_diameter_worm_gear", "the tip diameter d_a1")?;
    let df = length("root_diameter_worm_gear", "the root diameter d_f1")?;
    let alpha_what = "the pressure angle alpha_0";
    let alpha = reader.required(c, "pressure_angle_worm_gear", Quantity::Angle, alpha_what)?;
    let gamma_file = reader.number(c, "lead_angle_worm_gear", Quantity::Angle)?;
    let (m_x, module) = axial_module(reader, c, starts, gamma_file)?;
    let (thickness, thickness_source) =
        match custom(reader, c, "axial_thickness", Quantity::Length)? {
            Some(t) => (t, format!("{CUSTOM_PREFIX}axial_thickness")),
            None => (
                0.5 * std::f64::consts::PI * m_x,
                "default: half the axial pitch, p_x / 2 (DIN 3975; REXS has no thread thickness)"
                    .into(),
            ),
        };
    let grinding = match profile {
        'K' | 'C' => Some(grinding_disc(reader, parts, profile)?),
        _ => None,
    };
    let hand = match gamma_file {
        Some(g) => format!("sign of worm_gear.lead_angle_worm_gear = {g} deg (positive: right)"),
        None => "default: REXS gives no lead angle, so no hand".into(),
    };
    let worm = Worm {
        profile,
        starts,
        right_hand: gamma_file.is_none_or(|g| g >= 0.0),
        axial_module: m_x,
        reference_radius: 0.5 * d1,
        tip_radius: 0.5 * da,
        root_radius: 0.5 * df,
        pressure_angle: alpha,
        normal_plane: profile != 'A',
        axial_thickness: thickness,
        lead_angle_deg: (starts as f64 * m_x / d1).atan().to_degrees(),
        grinding,
    };
    let sources = WormSources {
        hand,
        module,
        thickness: thickness_source,
        lead_angle: gamma_file,
    };
    Ok((worm, sources))
}

/// The axial module and the attribute it came from.
pub(super) fn axial_module(
    reader: &Reader,
    c: &Component,
    starts: i64,
    gamma: Option<f64>,
) -> Result<(f64, String), RexsError> {
    let z1 = starts as f64;
    if let Some(m) = reader.positive(c, "axial_module", Quantity::Length)? {
        return Ok((m, "worm_gear.axial_module".into()));
    }
    if let Some(p) = reader.positive(c, "lead", Quantity::Length)? {
        return Ok((
            p / (z1 * std::f64::consts::PI),
            "worm_gear.lead / (z1 pi)".into(),
        ));
    }
    if let Some(p) = reader.positive(c, "axial_pitch", Quantity::Length)? {
        return Ok((
            p / std::f64::consts::PI,
            "worm_gear.axial_pitch / pi".into(),
        ));
    }
    if let (Some(m_n), Some(g)) = (
        reader.positive(c, "normal_module", Quantity::Length)?,
        gamma,
    ) {
        return Ok((
            m_n / g.to_radians().cos(),
            "worm_gear.normal_module / cos(lead_angle_worm_gear)".into(),
        ));
    }
    Err(RexsError::attribute(
        c,
        "axial_module",
        "missing: the axial module is needed (or lead, axial_pitch, or normal_module with \
         lead_angle_worm_gear)",
    ))
}

/// The worm's grinding disc (ZK, ZC): radius from grinding_disk_diameter, profile angle and
/// (ZC) profile radius.
pub(super) fn grinding_disc(
    reader: &Reader,
    parts: &Parts,
    profile: char,
) -> Result<Grinding, RexsError> {
    let Some(d) = parts.disc else {
        return Err(RexsError::attribute(
            parts.worm,
            "flank_form",
            format!(
                "profile Z{profile} needs its grinding disc: a worm_grinding_disc_tool \
                 (grinding_disk_diameter) linked to the worm's flanks by a manufacturing_step \
                 relation"
            ),
        ));
    };
    let diameter = reader.required(
        d,
        "grinding_disk_diameter",
        Quantity::Length,
        "the grinding disc diameter",
    )?;
    let profile_angle = reader.positive(d, "pressure_angle_worm_gear", Quantity::Angle)?;
    let profile_radius = reader.positive(d, "profile_radius_zc_disc", Quantity::Length)?;
    if profile == 'C' && profile_radius.is_none() {
        return Err(RexsError::attribute(
            d,
            "profile_radius_zc_disc",
            "missing: a ZC worm needs the disc's profile radius",
        ));
    }
    Ok(Grinding {
        radius: 0.5 * diameter,
        profile_angle,
        profile_radius: if profile == 'C' { profile_radius } else { None },
    })
}

pub(super) fn write_grinding(out: &mut GearText, member: &str, g: Grinding) {
    out.section(&format!("{member}.grinding_wheel"));
    out.field(
        "radius_mm",
        g.radius,
        "worm_grinding_disc_tool.grinding_disk_diameter / 2",
    );
    match g.profile_angle {
        Some(a) => out.field(
            "profile_angle_deg",
            a,
            "worm_grinding_disc_tool.pressure_angle_worm_gear",
        ),
        None => out.note("profile_angle_deg: default, the thread's normal pressure angle"),
    }
    if let Some(r) = g.profile_radius {
        out.field(
            "profile_radius_mm",
            r,
            "worm_grinding_disc_tool.profile_radius_zc_disc",
        );
    }
}
