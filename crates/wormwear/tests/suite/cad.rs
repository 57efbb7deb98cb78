//! CAD solids (issue 37): the worm and the wheel as closed B-spline solids, checked against
//! truths they were not built from: envelope points between the fitted ones, the flank grid's
//! own area, the wheel's rotational symmetry (a sector of n teeth is n pitches of the whole),
//! the worn wheel's lost volume against the integral of the flank change, and OpenCASCADE
//! (gmsh's Python package) reading the STEP files: one solid, our volume, our face areas, and
//! the flank grid's envelope points on its surfaces.

use crate::common;

use crate::common::{example, skipped};
use wormwear::cad::section_solid::FaceKind;
use wormwear::cad::wheel::{wheel_part, WheelRequest};
use wormwear::cad::worm::worm_part;
use wormwear::cad::{CadPart, CadRequest};
use wormwear::geometry::{Flank, FlankField, Geometry, GeometrySummary};
use wormwear::input::{BendingKind, GearSet};

fn built(name: &str) -> (GearSet, Geometry) {
    let g = example(name);
    let geo = Geometry::build(&g).unwrap();
    (g, geo)
}

/// The request of a new wheel of `n` teeth.
fn teeth(n: usize) -> WheelRequest<'static> {
    WheelRequest {
        teeth: Some(n),
        change: None,
    }
}

/// A life of `cycles` on the design case without bending, asking for the CAD solids.
fn life_with_cad(cycles: f64, cad: CadRequest) -> wormwear::Results {
    let mut g = example("gear-1x40-design.toml");
    g.bending.kind = BendingKind::None;
    let plan = wormwear::input::WearPlan::with_life(cycles);
    let mut request = wormwear::Request::new([wormwear::Stage::Wear]).with_life(plan);
    request.cad = Some(cad);
    wormwear::run(&g, wormwear::Source::default(), request, &mut |_| Ok(())).unwrap()
}

/// Runs `python3 tests/data/SCRIPT ARGS...` and parses the JSON it prints; None when
/// python3 cannot be started.
fn python_json(script: &str, args: &[&std::path::Path]) -> Option<serde_json::Value> {
    let script = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(script);
    let out = std::process::Command::new("python3")
        .arg(script)
        .args(args)
        .output()
        .ok()?;
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    Some(serde_json::from_slice(&out.stdout).unwrap())
}

fn full_wheel(g: &GearSet, geo: &Geometry) -> CadPart {
    wheel_part(g, geo, WheelRequest::default()).unwrap()
}

#[test]
fn new_flanks_fit_within_a_micrometre_and_the_wheel_flank_has_the_grids_area() {
    for name in ["gear-1x40-design.toml", "gear-k-2x25.toml"] {
        let (g, geo) = built(name);
        let worm = worm_part(&g, &geo).unwrap();
        let wheel = full_wheel(&g, &geo);
        for (part, what) in [(&worm, "worm"), (&wheel, "wheel")] {
            let s = part.summary("x");
            assert!(
                s.fit_check_points > 500,
                "{name} {what}: {}",
                s.fit_check_points
            );
            // The bound is 1 um; the wheel refines its sampling to half of it.
            assert!(
                s.max_fit_deviation_um < if what == "wheel" { 0.5 } else { 1.0 },
                "{name} {what}: {} um",
                s.max_fit_deviation_um
            );
        }
        // The flank grid's cells (areas of the curved surface, summed) against the B-spline
        // flanks integrated by Gauss: two discretisations of one surface.
        let grid = GeometrySummary::new(&g, &geo);
        let s = wheel.summary("wheel.step");
        let z2 = geo.teeth as f64;
        for (ours, theirs) in [
            (s.flank_area_left_mm2 / z2, grid.active_flank_area_left_mm2),
            (
                s.flank_area_right_mm2 / z2,
                grid.active_flank_area_right_mm2,
            ),
        ] {
            assert!(
                (ours / theirs - 1.0).abs() < 1e-3,
                "{name}: {ours} vs {theirs} mm^2"
            );
        }
    }
}

#[test]
fn a_sector_of_n_teeth_is_n_pitches_of_the_whole_wheel() {
    let (g, geo) = built("gear-1x40-design.toml");
    let whole = full_wheel(&g, &geo).volume_mm3;
    for n in [1, 3] {
        let sector = wheel_part(&g, &geo, teeth(n)).unwrap();
        let share = whole * n as f64 / geo.teeth as f64;
        assert!(
            (sector.volume_mm3 / share - 1.0).abs() < 1e-6,
            "{n} teeth: {} vs {share} mm^3",
            sector.volume_mm3
        );
        // Per band (3: the blank top's kink splits the faces): 5 pieces per tooth, the two
        // sides and the bore arc; then the two end faces.
        assert_eq!(sector.built.solid.face_iter().count(), 3 * (5 * n + 3) + 2);
    }
}

#[test]
fn the_worn_wheel_loses_the_volume_of_its_flank_change() {
    let results = life_with_cad(
        20_000.0,
        CadRequest {
            teeth: Some(3),
            state: None,
        },
    );
    let (g, geo, life) = (
        &results.gear,
        &results.geometry,
        results.life.as_ref().unwrap(),
    );
    let flank = results.tca.as_ref().unwrap().loaded_flank;
    let change = life.end.flank_change();
    let wf = geo.wheel_flank(flank);
    let removed = 3.0 * change.integral(wf) * 1e9;
    assert!(removed > 1.0, "{removed} mm^3");
    // The same sampling without the change: the difference is the change alone.
    let zero = FlankField::zeros(wf);
    let request = |field| WheelRequest {
        teeth: Some(3),
        change: Some((flank, field)),
    };
    let new = wheel_part(g, geo, request(&zero)).unwrap().volume_mm3;
    let worn = results.cad.as_ref().unwrap().worn.as_ref().unwrap();
    assert_eq!(worn.0.step, life.end.step);
    let lost = new - worn.1.volume_mm3;
    eprintln!("lost {lost} mm^3, flank change integral {removed} mm^3");
    assert!(
        (lost / removed - 1.0).abs() < 5e-3,
        "lost {lost} vs worn {removed} mm^3"
    );
    // The worn solid is one valid solid for OpenCASCADE too, of our volume.
    if gmsh_present() {
        let faces = faces_of(&worn.1, |k, i| k.is_flank() && i == 1);
        let answer = read_back(&worn.1, &faces, &[]).unwrap();
        check_answer("worn wheel, 3 teeth", &worn.1, &faces, &answer);
    }
}

#[test]
fn the_step_text_is_one_named_closed_solid_the_same_every_time() {
    let (g, geo) = built("gear-1x40-design.toml");
    let worm = worm_part(&g, &geo).unwrap();
    let text = worm.step_text("worm").unwrap();
    assert!(text.starts_with("ISO-10303-21;"));
    assert!(text.contains("FILE_NAME('worm.step', '2000-01-01T00:00:00', (''), (''),"));
    assert!(text.contains("#7 = PRODUCT('worm','worm','', (#8));"));
    assert_eq!(text.matches("MANIFOLD_SOLID_BREP").count(), 1);
    assert_eq!(text.matches("CLOSED_SHELL").count(), 1);
    assert!(text.contains("SI_UNIT(.MILLI.,.METRE.)"));
    assert_eq!(
        text,
        worm_part(&g, &geo).unwrap().step_text("worm").unwrap()
    );
}

#[test]
fn tooth_counts_outside_the_wheel_are_refused() {
    let (g, geo) = built("gear-1x40-design.toml");
    for n in [0, 41] {
        let err = wheel_part(&g, &geo, teeth(n)).unwrap_err().to_string();
        assert!(err.contains(&format!("is {n}, allowed 1 to 40")), "{err}");
        let request = wormwear::Request {
            cad: Some(CadRequest {
                teeth: Some(n),
                state: None,
            }),
            ..wormwear::Request::new([wormwear::Stage::Geometry])
        };
        assert!(request.check(&g).unwrap_err().is_input());
    }
}

/// Our faces of `kinds` with their centroids and areas, for the reader.
fn faces_of(
    part: &CadPart,
    keep: impl Fn(FaceKind, usize) -> bool,
) -> Vec<(FaceKind, [f64; 3], f64)> {
    part.face_summaries()
        .into_iter()
        .filter(|f| keep(f.kind, f.index))
        .map(|f| (f.kind, f.centroid_mm, f.area_mm2))
        .collect()
}

/// The reader's answer for `part` written as STEP, with the faces and the points (each with the
/// indices of the faces it may lie on). None when gmsh is absent.
fn read_back(
    part: &CadPart,
    faces: &[(FaceKind, [f64; 3], f64)],
    points: &[([f64; 3], Vec<usize>)],
) -> Option<serde_json::Value> {
    let dir = tempfile::tempdir().unwrap();
    let step = dir.path().join("part.step");
    std::fs::write(&step, part.step_text("part").unwrap()).unwrap();
    let request = serde_json::json!({
        "faces": faces.iter().map(|f| serde_json::json!({"centroid": f.1, "area": f.2})).collect::<Vec<_>>(),
        "points": points.iter().map(|p| p.0).collect::<Vec<_>>(),
        "point_faces": points.iter().map(|p| p.1.clone()).collect::<Vec<_>>(),
    });
    let request_path = dir.path().join("request.json");
    std::fs::write(&request_path, request.to_string()).unwrap();
    python_json("step_reader.py", &[&step, &request_path])
}

fn gmsh_present() -> bool {
    std::process::Command::new("python3")
        .args(["-c", "import gmsh"])
        .output()
        .is_ok_and(|o| o.status.success())
}

/// Checks the reader's answer: one solid of our volume, our face areas, points on the faces.
fn check_answer(
    what: &str,
    part: &CadPart,
    faces: &[(FaceKind, [f64; 3], f64)],
    answer: &serde_json::Value,
) {
    assert_eq!(answer["solids"], 1, "{what}");
    // OpenCASCADE's mesher fills the solid with tetrahedra: its boundary is closed and valid.
    assert!(
        answer["tetrahedra"].as_u64().unwrap() > 1000,
        "{what}: {}",
        answer["tetrahedra"]
    );
    let volume = answer["volume"].as_f64().unwrap();
    assert!(
        (volume / part.volume_mm3 - 1.0).abs() < 1e-4,
        "{what}: {volume} vs {} mm^3",
        part.volume_mm3
    );
    for (i, f) in faces.iter().enumerate() {
        let area = answer["areas"][i].as_f64().unwrap();
        assert!(
            (area / f.2 - 1.0).abs() < 1e-5,
            "{what} {:?}: {area} vs {} mm^2",
            f.0,
            f.2
        );
        assert!(
            answer["centroid_gaps"][i].as_f64().unwrap() < 1e-3,
            "{what}: face {i} not found"
        );
    }
    let worst = answer["distances"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d.as_f64().unwrap())
        .fold(0.0, f64::max);
    assert!(
        worst < 1e-3,
        "{what}: a flank point is {worst} mm off the read surface"
    );
    eprintln!(
        "{what}: OpenCASCADE volume {volume:.3} mm^3 (ours {:.3}), worst flank point {:.4} um, \
         {} tetrahedra",
        part.volume_mm3,
        worst * 1e3,
        answer["tetrahedra"]
    );
}

#[test]
fn opencascade_reads_one_solid_with_our_volume_areas_and_flank_points() {
    reads_back_as_one_solid(
        "gear-1x40-design.toml",
        "cad::opencascade_reads_one_solid_with_our_volume_areas_and_flank_points",
    );
}

/// The same on the K 2/25 gear (another profile, two threads).
#[test]
#[ignore = "heavy validation: scripts/validate-heavy runs it"]
fn opencascade_reads_the_k_gears_solids_with_our_volume_areas_and_flank_points() {
    reads_back_as_one_solid(
        "gear-k-2x25.toml",
        "cad::opencascade_reads_the_k_gears_solids_with_our_volume_areas_and_flank_points",
    );
}

/// OpenCASCADE reads the wheel and the worm of the example `name` as one solid each, of our
/// volume and face areas, with the flanks' points on its faces (`test`: the name a skip is
/// logged under).
fn reads_back_as_one_solid(name: &str, test: &str) {
    if !gmsh_present() {
        skipped(test, "gmsh's Python package (OpenCASCADE) is absent");
        return;
    }
    let (g, geo) = built(name);
    let wheel = full_wheel(&g, &geo);
    // The reference space's flanks (tooth 0) and the grid's cell centres: envelope points
    // of the analysis grid, which the CAD sections did not sample.
    let faces = faces_of(&wheel, |k, i| k.is_flank() && i == 0);
    let mut points = Vec::new();
    for (flank, kind) in [
        (Flank::Left, FaceKind::FlankLeft),
        (Flank::Right, FaceKind::FlankRight),
    ] {
        let on: Vec<usize> = (0..faces.len()).filter(|&i| faces[i].0 == kind).collect();
        for c in geo.wheel_flank(flank).cells.iter().step_by(7) {
            let p = g.operating.wheel_to_worm(&c.position()) * 1e3;
            points.push(([p.x, p.y, p.z], on.clone()));
        }
    }
    let answer = read_back(&wheel, &faces, &points).unwrap();
    check_answer(&format!("{name} wheel"), &wheel, &faces, &answer);
    // The worm: its flank faces and points of its helicoids over the body.
    let worm = worm_part(&g, &geo).unwrap();
    let faces = faces_of(&worm, |k, i| k.is_flank() && i == 0);
    let (rf, ra) = (g.worm.root_radius, g.worm.tip_radius);
    let half = 0.45 * g.bending.worm_body_length;
    let mut points = Vec::new();
    for (flank, kind) in [
        (Flank::Left, FaceKind::FlankLeft),
        (Flank::Right, FaceKind::FlankRight),
    ] {
        let on: Vec<usize> = (0..faces.len()).filter(|&i| faces[i].0 == kind).collect();
        for a in 0..13 {
            let rho = rf + (ra - rf) * (a as f64 + 0.37) / 13.0;
            for b in 0..40 {
                let p = geo.worm.flank_point(flank, rho, 0.0, 0);
                let x = -half + 2.0 * half * (b as f64 + 0.29) / 40.0;
                let phi = (x - p.x) / (geo.worm.hand_sign() * geo.worm.lead_per_rad());
                let q = geo.worm.flank_point(flank, rho, phi, 0) * 1e3;
                points.push(([q.x, q.y, q.z], on.clone()));
            }
        }
    }
    let answer = read_back(&worm, &faces, &points).unwrap();
    check_answer(&format!("{name} worm"), &worm, &faces, &answer);
}

#[test]
fn the_worn_wheel_shows_the_asked_map_state_or_the_last_with_a_warning() {
    let run = |state| {
        life_with_cad(
            20_000.0,
            CadRequest {
                teeth: Some(1),
                state,
            },
        )
    };
    let asked = run(Some(2));
    let (from, _) = asked.cad.as_ref().unwrap().worn.as_ref().unwrap();
    let map = asked
        .life
        .as_ref()
        .unwrap()
        .maps
        .iter()
        .find(|m| m.state.step == 2)
        .unwrap();
    assert_eq!((from.step, from.cycles), (2, map.state.cycles));
    assert!(from.cycles < asked.life.as_ref().unwrap().end.cycles);
    let missing = run(Some(999));
    let (from, _) = missing.cad.as_ref().unwrap().worn.as_ref().unwrap();
    assert_eq!(from.step, missing.life.as_ref().unwrap().end.step);
    assert!(
        missing
            .warnings
            .iter()
            .any(|w| w.contains("no map state at wear step 999")),
        "{:?}",
        missing.warnings
    );
}

/// Heavy (about a minute: OpenCASCADE's boolean intersection of B-spline solids): run with
/// `cargo test -p wormwear --test suite cad:: -- --ignored`.
#[test]
#[ignore]
fn the_worm_and_the_wheel_assemble_touching_without_overlap() {
    if !gmsh_present() {
        skipped(
            "cad::assemble",
            "gmsh's Python package (OpenCASCADE) is absent",
        );
        return;
    }
    // At rotation 0 the unloaded mesh touches on the contact line (conjugate flanks) and
    // nowhere overlaps: the placement in the worm frame is the gear set's.
    let (g, geo) = built("gear-1x40-design.toml");
    let dir = tempfile::tempdir().unwrap();
    let worm = dir.path().join("worm.step");
    let wheel = dir.path().join("wheel.step");
    std::fs::write(
        &worm,
        worm_part(&g, &geo).unwrap().step_text("worm").unwrap(),
    )
    .unwrap();
    let sector = wheel_part(&g, &geo, teeth(3)).unwrap();
    std::fs::write(&wheel, sector.step_text("wheel").unwrap()).unwrap();
    let answer = python_json("step_assembly.py", &[&worm, &wheel]).unwrap();
    let (common, distance) = (
        answer["intersection"].as_f64().unwrap(),
        answer["distance"].as_f64().unwrap(),
    );
    eprintln!("common volume {common:.2e} mm^3, distance {distance:.2e} mm");
    // A 1 um interference over the contact line would be ~1e-2 mm^3.
    assert!(common.abs() < 1e-3, "the parts overlap by {common} mm^3");
    assert!(distance < 1e-3, "the parts are {distance} mm apart");
}

/// OpenCASCADE reads the worm with a 1 mm broken tip edge as one solid of our volume, with our
/// flank and edge areas, the helicoids' points on its flanks and the analytic circle's points
/// (swept along the helix) on its edge faces.
#[test]
fn opencascade_reads_the_rounded_worm_with_its_edge_on_the_circle() {
    if !gmsh_present() {
        skipped(
            "cad::opencascade_reads_the_rounded_worm",
            "gmsh's Python package (OpenCASCADE) is absent",
        );
        return;
    }
    let (mut g, geo) = built("gear-1x40-design.toml");
    let radius = 1e-3;
    g.worm.tip_edge_radius = radius;
    let worm = worm_part(&g, &geo).unwrap();
    let faces = faces_of(&worm, |k, _| k == FaceKind::Edge || k.is_flank());
    let (rf, ra) = (g.worm.tip_radius - 10e-3, g.worm.tip_radius);
    let screw = geo.worm.hand_sign() * geo.worm.lead_per_rad();
    let half = 0.45 * g.bending.worm_body_length;
    let mut points = Vec::new();
    for (flank, kind) in [
        (Flank::Left, FaceKind::FlankLeft),
        (Flank::Right, FaceKind::FlankRight),
    ] {
        let (x_tip, slope) = geo.worm.axial_profile(flank, ra);
        let side = if x_tip < 0.0 { 1.0 } else { -1.0 };
        let norm = (1.0 + slope * slope).sqrt();
        let (c_x, c_rho) = (x_tip - slope * radius + side * radius * norm, ra - radius);
        let tangent = c_rho + radius * side * slope / norm;
        let flanks: Vec<usize> = (0..faces.len()).filter(|&i| faces[i].0 == kind).collect();
        let edges: Vec<usize> = (0..faces.len())
            .filter(|&i| faces[i].0 == FaceKind::Edge)
            .collect();
        for b in 0..30 {
            let x = -half + 2.0 * half * (b as f64 + 0.29) / 30.0;
            let at = |x_axial: f64, rho: f64| {
                let phi = (x - x_axial) / screw;
                [x * 1e3, rho * phi.cos() * 1e3, rho * phi.sin() * 1e3]
            };
            for a in 0..8 {
                let rho = rf + (tangent - rf) * (a as f64 + 0.37) / 8.0;
                points.push((
                    at(geo.worm.axial_profile(flank, rho).0, rho),
                    flanks.clone(),
                ));
                // On the circle, between the tangent point and the tip.
                let rho = tangent + (ra - tangent) * (a as f64 + 0.41) / 8.0;
                let circle = c_x - side * (radius * radius - (rho - c_rho).powi(2)).sqrt();
                points.push((at(circle, rho), edges.clone()));
            }
        }
    }
    let answer = read_back(&worm, &faces, &points).unwrap();
    check_answer("design worm, 1 mm tip edge", &worm, &faces, &answer);
}

/// The solids draw the edge breaks (the worm's rounded tip edge, the wheel's face chamfers):
/// a run asking for them says nothing about sharp edges.
#[test]
fn solids_of_a_gear_with_edge_breaks_draw_them_without_a_warning() {
    let mut g = common::example("gear-1x40-design.toml");
    g.worm.tip_edge_radius = 0.5e-3;
    g.wheel.face_edge_chamfer = 0.5e-3;
    let request = wormwear::Request {
        cad: Some(CadRequest {
            teeth: Some(1),
            state: None,
        }),
        ..wormwear::Request::new([wormwear::Stage::Geometry])
    };
    let r = wormwear::run(&g, wormwear::Source::default(), request, &mut |_| Ok(())).unwrap();
    assert!(r.cad.is_some());
    assert!(
        !r.warnings.iter().any(|w| w.contains("sharp")),
        "{:?}",
        r.warnings
    );
}

/// The flank area of `flank` per unit face width at z (m), from the grid's cells of the
/// column holding z.
fn flank_area_per_z(geo: &Geometry, flank: Flank, z: f64) -> f64 {
    let wf = geo.wheel_flank(flank);
    let j = wf.z.partition_point(|&zj| zj <= z).clamp(1, wf.cells_face) - 1;
    let area: f64 = (0..wf.cells_height)
        .map(|i| wf.cell_area[j * wf.cells_height + i])
        .sum();
    area / (wf.z[j + 1] - wf.z[j])
}

/// A 45 deg face-end chamfer of width c takes off each flank, at each face end, the integral of
/// its depth (|z| - (b/2 - c)) over the flank area (midpoint rule on 2 000 strips with the
/// grid's area per unit z), to first order in c: the curvature of the flank's transverse
/// profile adds a share of order c kappa, so the ratio lost / integral is 1 + k c, and its
/// extrapolation from c = 1 and 2 mm to c = 0 is 1. The solids' volumes are their B-spline
/// meshes', sampled at other stations with and without the chamfer: a few 1e-6 of the sector,
/// 1-2 % of a 0.5 mm chamfer's loss (so that one is checked within 3 %). The chamfered wheel is
/// one solid for OpenCASCADE, of our volume.
#[test]
fn the_face_chamfers_take_their_depth_times_the_flank_area_off_the_wheel() {
    let (mut g, geo) = built("gear-1x40-design.toml");
    let sharp = wheel_part(&g, &geo, teeth(3)).unwrap().volume_mm3;
    let half = 0.5 * geo.blank.face_width;
    let mut ratios = Vec::new();
    for width in [0.5e-3, 1.0e-3, 2.0e-3] {
        g.wheel.face_edge_chamfer = width;
        let part = wheel_part(&g, &geo, teeth(3)).unwrap();
        let n = 2000;
        let h = width / n as f64;
        let expected: f64 = (0..n)
            .map(|k| {
                let depth = h * (k as f64 + 0.5);
                let z = half - width + depth;
                [Flank::Left, Flank::Right]
                    .iter()
                    .map(|&f| flank_area_per_z(&geo, f, z) + flank_area_per_z(&geo, f, -z))
                    .sum::<f64>()
                    * depth
                    * h
            })
            .sum::<f64>()
            * 3.0
            * 1e9;
        let lost = sharp - part.volume_mm3;
        eprintln!(
            "chamfer {} mm: lost {lost:.3} mm^3, expected {expected:.3} mm^3",
            width * 1e3
        );
        ratios.push(lost / expected);
        assert!(part.max_fit_deviation_mm() < 1e-3);
        if gmsh_present() && width == 1.0e-3 {
            let faces = faces_of(&part, |k, i| k.is_flank() && i == 1);
            let answer = read_back(&part, &faces, &[]).unwrap();
            check_answer("chamfered wheel, 3 teeth", &part, &faces, &answer);
        }
    }
    // The flanks' transverse curvature radii are tens of mm: c kappa is a few percent at most.
    let limit = 2.0 * ratios[1] - ratios[2];
    assert!(
        (limit - 1.0).abs() < 1e-2 && ratios.iter().all(|r| (r - 1.0).abs() < 0.04),
        "lost / first-order integral {ratios:?} at 0.5 / 1 / 2 mm, at c -> 0 {limit}"
    );
    assert!((ratios[0] - 1.0).abs() < 0.03, "{ratios:?}");
}

/// The corner a broken tip edge takes off one flank's thread, in the axial section: between the
/// flank's tangent line at the tip, the tip line rho = r_a and the circle of radius R tangent
/// to both, as integral of rho dA (m^3): by the x-extent between line and circle at each rho
/// (midpoint rule on 20 000 strips).
fn corner_moment(g: &GearSet, geo: &Geometry, flank: Flank, radius: f64) -> f64 {
    let ra = g.worm.tip_radius;
    let (x_tip, slope) = geo.worm.axial_profile(flank, ra);
    let side = if x_tip < 0.0 { 1.0 } else { -1.0 };
    let norm = (1.0 + slope * slope).sqrt();
    let (c_x, c_rho) = (x_tip - slope * radius + side * radius * norm, ra - radius);
    // The tangent point: the foot of the centre on the flank line.
    let tangent = c_rho + radius * side * slope / norm;
    let n = 20_000;
    let h = (ra - tangent) / n as f64;
    (0..n)
        .map(|k| {
            let rho = tangent + h * (k as f64 + 0.5);
            let line = x_tip + slope * (rho - ra);
            let circle = c_x - side * (radius * radius - (rho - c_rho).powi(2)).sqrt();
            rho * (circle - line).abs() * h
        })
        .sum()
}

/// A broken tip edge of radius R takes off the worm body, per thread and flank, the corner's
/// integral of rho dA in the axial section over |p_z / 2 pi| per unit length (a helicoid's
/// transverse area element rho drho dphi is rho drho dx / |p_z / 2 pi|); the edge becomes a face
/// of its own, the flanks end at the tangent points, and R -> 0 gives the sharp solid.
#[test]
fn a_rounded_tip_edge_takes_its_corner_off_the_worm_solid() {
    let (mut g, geo) = built("gear-1x40-design.toml");
    let sharp = worm_part(&g, &geo).unwrap();
    let screw = geo.worm.lead_per_rad().abs();
    let length_mm = g.bending.worm_body_length * 1e3;
    for radius in [0.5e-3, 1.0e-3] {
        g.worm.tip_edge_radius = radius;
        let round = worm_part(&g, &geo).unwrap();
        let corners: f64 = [Flank::Left, Flank::Right]
            .iter()
            .map(|&f| corner_moment(&g, &geo, f, radius))
            .sum();
        let expected = corners / screw * 1e6 * length_mm * geo.worm.starts() as f64;
        let lost = sharp.volume_mm3 - round.volume_mm3;
        assert!(
            (lost / expected - 1.0).abs() < 1e-4,
            "R {} mm: lost {lost} mm^3, expected {expected} mm^3",
            radius * 1e3
        );
        let edges = round
            .face_summaries()
            .iter()
            .filter(|f| f.kind == FaceKind::Edge)
            .count();
        assert_eq!(edges, 2 * geo.worm.starts() as usize, "R {radius}");
    }
    g.worm.tip_edge_radius = 1e-9;
    let tiny = worm_part(&g, &geo).unwrap();
    assert!((tiny.volume_mm3 / sharp.volume_mm3 - 1.0).abs() < 1e-9);
    g.worm.tip_edge_radius = 0.0;
    let again = worm_part(&g, &geo).unwrap();
    assert_eq!(
        again.step_text("worm").unwrap(),
        sharp.step_text("worm").unwrap()
    );
}
