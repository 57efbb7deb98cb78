//! The analysis settings (MODEL §4, §5): the flank grid, the positions, the local contact mesh
//! and its contact law, the sections, and the bending plan.

use super::*;

/// [analysis] with its defaults; None when a field is invalid (its error recorded).
pub(super) fn analysis_settings(
    ck: &mut Checker,
    a: &AnalysisSpec,
    teeth: Option<u32>,
    face_width: Option<f64>,
) -> Option<Analysis> {
    let height = ck.int_range("analysis.flank_cells_height", a.flank_cells_height, 4, 400);
    let face = ck.int_range("analysis.flank_cells_face", a.flank_cells_face, 4, 400);
    let refinement = ck.int_range(
        "analysis.tip_trace_refinement",
        a.tip_trace_refinement,
        0,
        16,
    );
    let positions = ck.int_range("analysis.positions", a.positions, 4, 720);
    let teeth_each_side = ck.int_range("analysis.teeth_each_side", a.teeth_each_side, 1, 10);
    let marking = ck
        .positive(
            "analysis.marking_thickness_um",
            a.marking_thickness_um,
            1000.0,
            "um",
        )
        .map(|v| v * 1e-6);
    let stl_threads = ck.int_range("analysis.stl_worm_threads", a.stl_worm_threads, 1, 50);
    let stl_teeth = ck.int_range("analysis.stl_wheel_teeth", a.stl_wheel_teeth, 0, 500);
    let contact = contact_settings(ck, a);
    if let (Some(n), Some(z2)) = (stl_teeth, teeth) {
        if n > z2 as i64 {
            let problem = format!("allowed [0, wheel.teeth = {z2}] (0 = all)");
            ck.fail("analysis.stl_wheel_teeth", n, problem);
        }
    }
    let section_offsets = section_offsets(ck, a, face_width);
    let mut analysis = contact?;
    analysis.flank_cells_height = height? as usize;
    analysis.flank_cells_face = face? as usize;
    analysis.tip_trace_refinement = refinement? as usize;
    analysis.positions = positions? as usize;
    analysis.teeth_each_side = teeth_each_side? as usize;
    analysis.marking_thickness = marking?;
    analysis.section_offsets = section_offsets;
    analysis.stl_worm_threads = stl_threads? as usize;
    analysis.stl_wheel_teeth = stl_teeth? as usize;
    Some(analysis)
}

/// The contact law of `[analysis]` (MODEL §5.7): `contact` plastic (default) or elastic,
/// `flow_pressure_mpa`; the former `contact_pressure_cap_mpa` is refused naming them. The flow
/// pressure's default, the wheel's hardness, is filled in by `validate` (NaN here).
pub(super) fn contact_law(ck: &mut Checker, a: &AnalysisSpec) -> Option<ContactLaw> {
    if let Some(v) = a.contact_pressure_cap_mpa {
        ck.fail(
            "analysis.contact_pressure_cap_mpa",
            v,
            "is no longer read: the bronze's plastic limit is now the default (MODEL §5.7); \
             set analysis.flow_pressure_mpa (default: the wheel's hardness) for another bound, \
             or analysis.contact = \"elastic\" for none",
        );
    }
    let flow = a
        .flow_pressure_mpa
        .map(|v| ck.range("analysis.flow_pressure_mpa", v, 10.0, 100_000.0, "MPa"));
    let law = ck.choice(
        "analysis.contact",
        a.contact.as_deref().unwrap_or("plastic"),
        &[("plastic", true), ("elastic", false)],
    );
    match (law, flow) {
        (Some(true), None) => Some(ContactLaw::Plastic {
            flow_pressure: f64::NAN,
        }),
        (Some(true), Some(v)) => v.map(|v| ContactLaw::Plastic {
            flow_pressure: v * 1e6,
        }),
        (Some(false), _) => Some(ContactLaw::Elastic),
        (None, _) => None,
    }
}

/// The loaded analysis' settings of [analysis] (the grid and output fields left at zero for
/// [`analysis_settings`] to fill).
pub(super) fn contact_settings(ck: &mut Checker, a: &AnalysisSpec) -> Option<Analysis> {
    let slice_step = ck.int_range("analysis.contact_slice_step", a.contact_slice_step, 1, 20);
    let columns = ck.int_range("analysis.contact_columns", a.contact_columns, 3, 200);
    let contact = contact_law(ck, a);
    let across = a.pressure_patch_across_mm;
    let across = ck.range(
        "analysis.pressure_patch_across_mm",
        across,
        0.01,
        100.0,
        "mm",
    );
    let along = a.pressure_patch_along_mm;
    let along = ck.range(
        "analysis.pressure_patch_along_mm",
        along,
        0.01,
        1000.0,
        "mm",
    );
    let unit = "Hertz half-widths";
    let band = ck.range(
        "analysis.contact_band_factor",
        a.contact_band_factor,
        1.0,
        50.0,
        unit,
    );
    let direction = ck.choice(
        "analysis.pressure_direction",
        a.pressure_direction.as_deref().unwrap_or("worm-flank"),
        &[
            ("worm-flank", PressureDirection::WormFlank),
            ("wheel-flank", PressureDirection::WheelFlank),
        ],
    );
    let torque_balance = ck.choice(
        "analysis.torque_balance",
        a.torque_balance.as_deref().unwrap_or("transmitted"),
        &[
            ("transmitted", TorqueBalance::Transmitted),
            ("frictionless", TorqueBalance::Frictionless),
        ],
    );
    let band_growth = ck.choice(
        "analysis.contact_band_growth",
        a.contact_band_growth.as_deref().unwrap_or("extend"),
        &[("widen", BandGrowth::Widen), ("extend", BandGrowth::Extend)],
    );
    use super::SolverKind;
    let solver = ck.choice(
        "analysis.solver",
        &a.solver,
        &[
            ("conjugate-gradient", SolverKind::ConjugateGradient),
            ("fixed-point", SolverKind::FixedPoint),
        ],
    );
    Some(Analysis {
        flank_cells_height: 0,
        flank_cells_face: 0,
        tip_trace_refinement: 0,
        positions: 0,
        teeth_each_side: 0,
        marking_thickness: 0.0,
        section_offsets: Vec::new(),
        stl_worm_threads: 0,
        stl_wheel_teeth: 0,
        contact_slice_step: slice_step? as usize,
        contact_columns: columns? as usize,
        contact_band_factor: band?,
        contact: contact?,
        pressure_patch_across: across? * 1e-3,
        pressure_patch_along: along? * 1e-3,
        solver: solver?,
        pressure_direction: direction?,
        torque_balance: torque_balance?,
        contact_band_growth: band_growth?,
    })
}

/// The offsets of the drawn sections, m: the file's (inside the face width, at most 50),
/// else -b/4, 0, b/4.
pub(super) fn section_offsets(
    ck: &mut Checker,
    a: &AnalysisSpec,
    face_width: Option<f64>,
) -> Vec<f64> {
    // Each section is a profile computation and a plot: a few dozen is plenty.
    const MAX_SECTIONS: usize = 50;
    if let Some(v) = a
        .section_offsets_mm
        .as_ref()
        .filter(|v| v.len() > MAX_SECTIONS)
    {
        ck.fail(
            "analysis.section_offsets_mm",
            format!("{} offsets", v.len()),
            format!("at most {MAX_SECTIONS} sections"),
        );
    }
    match (&a.section_offsets_mm, face_width) {
        (Some(v), Some(b)) if v.len() <= MAX_SECTIONS => v
            .iter()
            .enumerate()
            .filter_map(|(i, &z)| {
                ck.range(
                    &format!("analysis.section_offsets_mm[{i}]"),
                    z,
                    -0.5 * b / MM,
                    0.5 * b / MM,
                    "mm (inside wheel.face_width_mm)",
                )
                .map(|z| z * MM)
            })
            .collect(),
        (None, Some(b)) => vec![-0.25 * b, 0.0, 0.25 * b],
        _ => vec![],
    }
}

/// Bending settings with their defaults (see [`BendingSpec`]).
pub(super) fn bending_plan(
    ck: &mut Checker,
    b: &BendingSpec,
    worm: &ThreadSpec,
    wheel: &WheelSpec,
    operating: &OperatingSpec,
) -> Option<BendingPlan> {
    let kind = ck.choice(
        "bending.model",
        b.model.as_deref().unwrap_or("none"),
        &[("none", BendingKind::None), ("fe", BendingKind::Fe)],
    );
    let height = ck.int_range("bending.height_points", b.height_points.unwrap_or(5), 2, 9);
    let width = ck.int_range("bending.width_points", b.width_points.unwrap_or(7), 2, 17);
    let worm_width = ck.int_range(
        "bending.worm_width_points",
        b.worm_width_points.unwrap_or(13),
        2,
        21,
    );
    let refinement = ck.int_range(
        "bending.mesh_refinement",
        b.mesh_refinement.unwrap_or(1),
        1,
        3,
    );
    let rf = worm.root_radius_mm;
    let shaft = match b.worm_shaft_radius_mm {
        Some(v) => ck.positive(
            "bending.worm_shaft_radius_mm",
            v,
            rf.max(1e-9),
            "mm (at most the worm root radius)",
        ),
        None => Some(0.75 * rf),
    };
    let body = worm_body_length(ck, b.worm_body_length_mm, worm, wheel, operating);
    let bearings = worm_bearings(ck, b.worm_bearing_positions_mm.as_deref(), body, rf);
    Some(BendingPlan {
        kind: kind?,
        height_points: height? as usize,
        width_points: width? as usize,
        worm_width_points: worm_width? as usize,
        mesh_refinement: refinement? as usize,
        worm_shaft_radius: shaft? * MM,
        worm_body_length: body? * MM,
        worm_bearings: bearings?,
    })
}

/// The worm body's length (`bending.worm_body_length_mm`, mm): given, or by default the chord
/// of the wheel's outer circle at the worm's tip radius, at least twice the face width.
fn worm_body_length(
    ck: &mut Checker,
    given: Option<f64>,
    worm: &ThreadSpec,
    wheel: &WheelSpec,
    operating: &OperatingSpec,
) -> Option<f64> {
    let reach = operating.centre_distance_mm - worm.tip_radius_mm;
    let default_body = 2.0
        * (wheel.outer_radius_mm.powi(2) - reach.powi(2))
            .max(0.0)
            .sqrt();
    let default_body = default_body.max(2.0 * wheel.face_width_mm);
    match given {
        Some(v) => ck.positive("bending.worm_body_length_mm", v, 10_000.0, "mm"),
        None => Some(default_body),
    }
}

/// The worm's bearing positions (`bending.worm_bearing_positions_mm`, m): two, outside the
/// body of length `body` (mm); by default two root radii `rf` (mm) beyond its ends.
fn worm_bearings(
    ck: &mut Checker,
    given: Option<&[f64]>,
    body: Option<f64>,
    rf: f64,
) -> Option<[f64; 2]> {
    match (given, body) {
        (Some(v), _) if v.len() != 2 => {
            ck.fail(
                "bending.worm_bearing_positions_mm",
                format!("{v:?}"),
                "must hold two positions (drive side first)",
            );
            None
        }
        (Some(v), Some(body)) => {
            let (lo, hi) = (v[0].min(v[1]), v[0].max(v[1]));
            if !(lo.is_finite() && hi.is_finite()) || lo > -0.5 * body || hi < 0.5 * body {
                ck.fail(
                    "bending.worm_bearing_positions_mm",
                    format!("{v:?}"),
                    format!(
                        "the bearings must lie outside the worm body, beyond +/- {:.1} mm",
                        0.5 * body
                    ),
                );
                None
            } else {
                Some([v[0] * MM, v[1] * MM])
            }
        }
        (None, Some(body)) => {
            let x = 0.5 * body + 2.0 * rf;
            Some([-x * MM, x * MM])
        }
        _ => None,
    }
}
