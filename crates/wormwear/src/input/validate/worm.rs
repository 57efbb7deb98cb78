//! The worm's thread and the tools that make it (MODEL §1, §2): profile type, starts, lead,
//! thread thickness and radii, the grinding wheel of the K profile, the hob against the worm.

use super::*;

/// The hob must have the worm's axial pitch and hand.
pub(super) fn hob_matches_worm(ck: &mut Checker, wm: &ThreadDef, hb: &ThreadDef) {
    if ((hb.axial_pitch - wm.axial_pitch) / wm.axial_pitch).abs() > 1e-6 {
        ck.fail(
            "hob.axial_module_mm",
            format!(
                "{:.6} (lead {:.6} mm)",
                hb.axial_module() / MM,
                hb.lead() / MM
            ),
            format!(
                "the hob must have the worm's axial pitch (worm.lead_mm / worm.starts, or worm.\
                 axial_module_mm): axial module {:.6} mm (relative difference allowed 1e-6)",
                wm.axial_module() / MM
            ),
        );
    }
    if hb.hand != wm.hand {
        ck.fail(
            "hob.hand",
            format!("{:?}", hb.hand),
            format!("must equal worm.hand ({:?})", wm.hand),
        );
    }
}

pub(super) fn thread(ck: &mut Checker, name: &str, t: &ThreadSpec) -> Option<ThreadDef> {
    let field = |f: &str| format!("{name}.{f}");
    let n_errors = ck.errors.len();
    let profile = profile_choice(ck, &field("profile"), &t.profile);
    let starts = ck.int_range(&field("starts"), t.starts, 1, 10);
    let hand = ck.choice(
        &field("hand"),
        &t.hand,
        &[("right", Hand::Right), ("left", Hand::Left)],
    );
    let axial_pitch = axial_pitch(ck, name, t, starts);
    let (r1, ra, rf) = thread_radii(ck, name, t);
    let (alpha, plane, thickness) = flank_inputs(ck, name, t);
    grinding_wheel_presence(
        ck,
        &field("grinding_wheel"),
        profile,
        t.grinding_wheel.is_some(),
    );
    if ck.errors.len() > n_errors {
        return None;
    }
    let (profile, starts, hand, p_x, r1, ra, rf, alpha, axial_plane, s) = (
        profile?,
        starts?,
        hand?,
        axial_pitch?,
        r1? * MM,
        ra? * MM,
        rf? * MM,
        alpha? * DEG,
        plane?,
        thickness? * MM,
    );
    let lead_angle = lead_angle(ck, name, starts, p_x, r1)?;
    let (alpha_x, alpha_n) = if axial_plane {
        (alpha, (alpha.tan() * lead_angle.cos()).atan())
    } else {
        ((alpha.tan() / lead_angle.cos()).atan(), alpha)
    };
    let fits = thread_space(ck, name, p_x, s, (r1, ra, rf), alpha_x)?;
    let mut def = ThreadDef {
        profile,
        starts: starts as u32,
        hand,
        axial_pitch: p_x,
        reference_radius: r1,
        tip_radius: ra,
        root_radius: rf,
        axial_pressure_angle: alpha_x,
        normal_pressure_angle: alpha_n,
        axial_thickness: s,
        grinding_wheel: None,
        tip_relief: EdgeRelief::SHARP,
        tip_edge_radius: 0.0,
    };
    tip_edges(ck, name, t, &mut def)?;
    if profile == ProfileType::I {
        base_cylinder_below_root(ck, name, &def);
    }
    if let (Some(gw), ProfileType::K | ProfileType::C) = (&t.grinding_wheel, profile) {
        let radii = (r1, ra, rf);
        def.grinding_wheel = Some(grinding_wheel(ck, name, gw, profile, radii, alpha_n)?);
    }
    fits.then_some(def)
}

/// The tip relief and the broken tip edge of `def` from `t`, checked (None: refused).
fn tip_edges(ck: &mut Checker, name: &str, t: &ThreadSpec, def: &mut ThreadDef) -> Option<()> {
    let depth = def.tip_radius - def.root_radius;
    def.tip_relief = edge_relief(
        ck,
        &format!("{name}.tip_relief_um"),
        t.tip_relief_um,
        &format!("{name}.tip_relief_length_mm"),
        t.tip_relief_length_mm,
        (
            0.5 * depth,
            &format!("half the thread depth, {name}.tip_radius_mm - {name}.root_radius_mm"),
        ),
    )?;
    if let Some(radius) = t.tip_edge_radius_mm {
        def.tip_edge_radius = tip_edge_radius(ck, name, radius, def, def.axial_thickness)?;
    }
    Some(())
}

/// The broken tip edge's radius (mm in, m out; MODEL §2.3), checked: the worm's only (the
/// hob's tip edge is the wheel's root fillet, `rating.root_fillet_radius_mm`), at least 0, and
/// small enough that the two flanks' circles fit on the tip land (each takes
/// R (1 - sin a_x) / cos a_x of it) and touch the flank above the root.
fn tip_edge_radius(
    ck: &mut Checker,
    name: &str,
    radius_mm: f64,
    def: &ThreadDef,
    s: f64,
) -> Option<f64> {
    let field = format!("{name}.tip_edge_radius_mm");
    if name != "worm" {
        ck.fail(
            &field,
            radius_mm,
            "the worm's only: the hob's tip edge makes the wheel's root fillet              (rating.root_fillet_radius_mm for the root stress); remove it",
        );
        return None;
    }
    let alpha = def.axial_pressure_angle;
    let land = s - 2.0 * (def.tip_radius - def.reference_radius) * alpha.tan();
    let per_unit = (1.0 - alpha.sin()) / alpha.cos();
    let by_land = 0.5 * land / per_unit;
    let by_depth = (def.tip_radius - def.root_radius) / (1.0 - alpha.sin());
    let most = by_land.min(by_depth);
    let why = match by_land <= by_depth {
        true => format!(
            "the tip land ({:.3} mm wide) must hold both flanks' circles, each R (1 - sin a_x) /              cos a_x wide",
            land / MM
        ),
        false => "the circle must touch the flank above the root".to_string(),
    };
    let unit = format!("mm ({why})");
    ck.range(&field, radius_mm, 0.0, most / MM, &unit)
        .map(|r| r * MM)
}

/// The pressure angle (deg), whether it is given in the axial plane, and the axial
/// thickness (mm) of a thread, each checked.
pub(super) fn flank_inputs(
    ck: &mut Checker,
    name: &str,
    t: &ThreadSpec,
) -> (Option<f64>, Option<bool>, Option<f64>) {
    let field = |f: &str| format!("{name}.{f}");
    let alpha = ck.range(
        &field("pressure_angle_deg"),
        t.pressure_angle_deg,
        5.0,
        40.0,
        "deg",
    );
    let plane = ck.choice(
        &field("pressure_angle_plane"),
        &t.pressure_angle_plane,
        &[("axial", true), ("normal", false)],
    );
    let s = t.axial_thickness_mm;
    let thickness = ck.positive(&field("axial_thickness_mm"), s, 1000.0, "mm");
    (alpha, plane, thickness)
}

/// A thread profile by name: A, N, I, K, C or ZA, ZN, ZI, ZK, ZC.
pub(super) fn profile_choice(ck: &mut Checker, field: &str, value: &str) -> Option<ProfileType> {
    ck.choice(
        field,
        value,
        &[
            ("A", ProfileType::A),
            ("N", ProfileType::N),
            ("I", ProfileType::I),
            ("K", ProfileType::K),
            ("C", ProfileType::C),
            ("ZA", ProfileType::A),
            ("ZN", ProfileType::N),
            ("ZI", ProfileType::I),
            ("ZK", ProfileType::K),
            ("ZC", ProfileType::C),
        ],
    )
}

/// Profiles K and C need a grinding wheel; the others must not have one.
pub(super) fn grinding_wheel_presence(
    ck: &mut Checker,
    field: &str,
    p: Option<ProfileType>,
    given: bool,
) {
    match (p, given) {
        (Some(ProfileType::K | ProfileType::C), false) => ck.fail(
            field,
            "(missing)",
            "profiles K and C need a [grinding_wheel] table (radius_mm, ...)",
        ),
        (Some(ProfileType::A | ProfileType::N | ProfileType::I), true) => ck.fail(
            field,
            "(given)",
            "a grinding wheel is only used by profiles K and C",
        ),
        _ => {}
    }
}

/// Whether the thread has material at its tip and space at its root (straight-line
/// estimates from the axial thickness `s` and pressure angle `alpha_x` at r1; SI), each
/// failure recorded; None when the thickness is not even below the pitch.
pub(super) fn thread_space(
    ck: &mut Checker,
    name: &str,
    p_x: f64,
    s: f64,
    (r1, ra, rf): (f64, f64, f64),
    alpha_x: f64,
) -> Option<bool> {
    let field = |f: &str| format!("{name}.{f}");
    if s >= p_x {
        ck.fail(
            &field("axial_thickness_mm"),
            s / MM,
            format!(
                "must be less than the axial pitch {:.4} mm ({name}.lead_mm / {name}.starts, or \
                 pi {name}.axial_module_mm)",
                p_x / MM
            ),
        );
        return None;
    }
    // Straight-line estimate of the thread thickness at the tip and of the space at the root.
    let tip_thickness = s - 2.0 * (ra - r1) * alpha_x.tan();
    if tip_thickness <= 0.0 {
        ck.fail(
            &field("tip_radius_mm"),
            ra / MM,
            format!(
                "the thread is pointed below its tip: with this thickness and pressure angle \
                 ({name}.axial_thickness_mm, {name}.pressure_angle_deg) the tip radius must be < \
                 {:.4} mm",
                (r1 + 0.5 * s / alpha_x.tan()) / MM
            ),
        );
    }
    let root_space = p_x - s - 2.0 * (r1 - rf) * alpha_x.tan();
    if root_space <= 0.0 {
        ck.fail(
            &field("root_radius_mm"),
            rf / MM,
            format!(
                "the thread space closes above the root: with this pitch, thickness and \
                 pressure angle ({name}.lead_mm / {name}.starts, {name}.axial_thickness_mm, \
                 {name}.pressure_angle_deg) the root radius must be > {:.4} mm",
                (r1 - 0.5 * (p_x - s) / alpha_x.tan()) / MM
            ),
        );
    }
    Some(tip_thickness > 0.0 && root_space > 0.0)
}

/// The lead angle at the reference radius, rad; None (recorded) above 45 degrees.
pub(super) fn lead_angle(
    ck: &mut Checker,
    name: &str,
    starts: i64,
    p_x: f64,
    r1: f64,
) -> Option<f64> {
    let lead_angle = (starts as f64 * p_x / (2.0 * PI * r1)).atan();
    if lead_angle > 45.0 * DEG {
        ck.fail(
            &format!("{name}.reference_radius_mm"),
            r1 / MM,
            format!(
                "lead angle {:.2} deg exceeds 45 deg: with this lead ({name}.starts and \
                 {name}.axial_module_mm or {name}.lead_mm) the reference radius must be >= \
                 {:.4} mm",
                lead_angle / DEG,
                starts as f64 * p_x / (2.0 * PI) / MM
            ),
        );
        return None;
    }
    Some(lead_angle)
}

/// Profile I is an involute helicoid: its root must lie above the base cylinder.
pub(super) fn base_cylinder_below_root(ck: &mut Checker, name: &str, def: &ThreadDef) {
    let (rb, rf) = (def.base_radius(), def.root_radius);
    if rb >= rf {
        ck.fail(
            &format!("{name}.root_radius_mm"),
            rf / MM,
            format!(
                "profile I needs the root above the base cylinder: must be > base radius {:.4} mm",
                rb / MM
            ),
        );
    }
}

/// The axial pitch p_x of a thread, m, from its axial module or its lead (one of the two).
pub(super) fn axial_pitch(
    ck: &mut Checker,
    name: &str,
    t: &ThreadSpec,
    starts: Option<i64>,
) -> Option<f64> {
    let field = |f: &str| format!("{name}.{f}");
    match (t.axial_module_mm, t.lead_mm, starts) {
        (Some(_), Some(_), _) => {
            ck.fail(
                &field("lead_mm"),
                t.lead_mm.unwrap_or_default(),
                format!(
                    "give either {} or {}, not both",
                    field("axial_module_mm"),
                    field("lead_mm")
                ),
            );
            None
        }
        (None, None, _) => {
            ck.fail(
                &field("axial_module_mm"),
                "(missing)",
                format!("give {} or {}", field("axial_module_mm"), field("lead_mm")),
            );
            None
        }
        (Some(m), None, _) => ck
            .range(&field("axial_module_mm"), m, 0.1, 100.0, "mm")
            .map(|m| m * PI * MM),
        (None, Some(l), Some(z)) => ck
            .range(&field("lead_mm"), l, 0.1, 5000.0, "mm")
            .map(|l| l * MM / z as f64),
        (None, Some(_), None) => None,
    }
}

/// The reference, tip and root radii of a thread, mm, each checked and in order.
pub(super) fn thread_radii(
    ck: &mut Checker,
    name: &str,
    t: &ThreadSpec,
) -> (Option<f64>, Option<f64>, Option<f64>) {
    let field = |f: &str| format!("{name}.{f}");
    let r1 = ck.positive(
        &field("reference_radius_mm"),
        t.reference_radius_mm,
        2000.0,
        "mm",
    );
    let ra = ck.positive(&field("tip_radius_mm"), t.tip_radius_mm, 2000.0, "mm");
    let rf = ck.positive(&field("root_radius_mm"), t.root_radius_mm, 2000.0, "mm");
    if let (Some(r1), Some(ra), Some(rf)) = (r1, ra, rf) {
        if ra <= rf {
            ck.fail(
                &field("tip_radius_mm"),
                ra,
                format!(
                    "must be greater than {} = {rf} mm (tip below root)",
                    field("root_radius_mm")
                ),
            );
        } else if r1 <= rf || r1 >= ra {
            ck.fail(
                &field("reference_radius_mm"),
                r1,
                format!("must lie strictly between the root ({rf} mm) and tip ({ra} mm) radii"),
            );
        }
    }
    (r1, ra, rf)
}

/// The grinding wheel of a K or C thread (MODEL §2.2), checked against the thread's radii
/// (`radii` = reference, tip, root, m) and with its defaults (profile angle: the thread's
/// normal pressure angle `alpha_n`, rad; axis distance r1 + R_g).
pub(super) fn grinding_wheel(
    ck: &mut Checker,
    name: &str,
    gw: &GrindingWheelSpec,
    profile: ProfileType,
    radii: (f64, f64, f64),
    alpha_n: f64,
) -> Option<GrindingWheel> {
    let (r1, ra, rf) = radii;
    let gfield = |f: &str| format!("{name}.grinding_wheel.{f}");
    let rg = ck.range(
        &gfield("radius_mm"),
        gw.radius_mm,
        (ra - rf) / MM * 1.5,
        2000.0,
        "mm",
    );
    let angle = match gw.profile_angle_deg {
        Some(v) => ck
            .range(&gfield("profile_angle_deg"), v, 5.0, 40.0, "deg")
            .map(|v| v * DEG),
        None => Some(alpha_n),
    };
    let dist = match (gw.axis_distance_mm, rg) {
        (Some(d), Some(rg)) => ck
            .range(
                &gfield("axis_distance_mm"),
                d,
                (r1 / MM + rg) - 0.5 * (ra - rf) / MM,
                (r1 / MM + rg) + 0.5 * (ra - rf) / MM,
                "mm (reference radius + grinding-wheel radius +/- half the thread height)",
            )
            .map(|d| d * MM),
        (None, Some(rg)) => Some(r1 + rg * MM),
        _ => None,
    };
    let rho0 = match (profile, gw.profile_radius_mm) {
        (ProfileType::C, Some(v)) => ck
            .range(
                &gfield("profile_radius_mm"),
                v,
                2.0 * (ra - rf) / MM,
                10_000.0,
                "mm",
            )
            .map(|v| Some(v * MM)),
        (ProfileType::C, None) => {
            ck.fail(
                &gfield("profile_radius_mm"),
                "(missing)",
                "profile C needs the arc radius rho_0",
            );
            None
        }
        (_, Some(v)) => {
            ck.fail(
                &gfield("profile_radius_mm"),
                v,
                "only profile C has a circular-arc wheel",
            );
            None
        }
        (_, None) => Some(None),
    };
    Some(GrindingWheel {
        radius: rg? * MM,
        axis_distance: dist?,
        profile_angle: angle?,
        profile_radius: rho0?,
    })
}
