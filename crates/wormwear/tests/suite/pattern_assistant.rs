//! The contact-pattern assistant (MODEL §17) against an independent truth: a wheel cut with
//! known settings gives a pattern; searched from other settings toward that pattern, the
//! assistant finds the settings it was cut with. And its inputs: what it refuses, by name.

use wormwear::input;
use wormwear::pattern_assistant::{self as assistant, Assistant, PatternError, Target, Which};

/// The design gear cut by a hob identical to the worm but 1 mm oversize (reference, tip and
/// root radii) at a 1 mm larger cutting centre distance (126 mm): a localised pattern, on the
/// example's flank grid (60 x 40 cells, 20 positions).
fn oversize_base() -> String {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/gear-1x40-design.toml"
    );
    let mut doc = input::parse_document(&std::fs::read_to_string(path).unwrap()).unwrap();
    let hob = doc["worm"].clone();
    doc.insert("hob".into(), hob);
    let set = |doc: &mut toml::Table, name: &str, v: f64| {
        input::set_dotted(doc, name, Some(toml::Value::Float(v))).unwrap()
    };
    for r in ["reference_radius_mm", "tip_radius_mm", "root_radius_mm"] {
        let v = doc["worm"][r].as_float().unwrap();
        set(&mut doc, &format!("hob.{r}"), v + 1.0);
    }
    set(&mut doc, "cutting.centre_distance_mm", 126.0);
    input::document_text(&doc).unwrap()
}

fn bounds(list: &[(&str, f64, f64)]) -> Option<Vec<(String, f64, f64)>> {
    Some(
        list.iter()
            .map(|(n, a, b)| (n.to_string(), *a, *b))
            .collect(),
    )
}

const CENTRE: &str = "cutting.centre_distance_mm";
const SWIVEL: &str = "cutting.inclination_deg";

#[test]
fn the_assistant_finds_the_settings_a_wheel_was_cut_with_from_its_pattern() {
    // The truth: the same hob at 125.6 mm, swivelled 0.1 deg.
    let base = oversize_base();
    let (true_centre, true_swivel) = (125.6, 0.1);
    let any = Target {
        centre_across_face: Some(0.5),
        ..Default::default()
    };
    let search = bounds(&[(CENTRE, 125.2, 126.0), (SWIVEL, -0.3, 0.3)]);
    let probe = Assistant::new(
        "base".into(),
        base.clone(),
        any,
        search.clone(),
        Which::NoLoad,
        1,
    )
    .unwrap();
    let truth = probe.evaluate(&[true_centre, true_swivel]).shape.unwrap();
    // Target the centre across the face, the centre up the flank and the extent along the
    // face: the swivel moves the first most, the depth of cut (centre distance) the others.
    let target = Target {
        centre_across_face: Some(truth.centre_across_face),
        centre_up_flank: Some(truth.centre_up_flank),
        extent_along_face: Some(truth.extent_along_face),
        ..Default::default()
    };
    let study = Assistant::new("base".into(), base, target, search, Which::NoLoad, 80).unwrap();
    let outcome = study.run(&|_, _| {}, &|| false).unwrap();
    let (centre, swivel) = (outcome.best.values[0], outcome.best.values[1]);
    eprintln!(
        "from (126, 0) toward (125.6, 0.1): found ({centre:.4} mm, {swivel:.4} deg) in {} \
         evaluations ({}), objective {:.2e} -> {:.2e}",
        outcome.path.len(),
        outcome.stopped,
        outcome.start.objective,
        outcome.best.objective
    );
    // The start is far: a wider pattern nearer the leaving side.
    assert!(
        outcome.start.objective > 1e-3,
        "{}",
        outcome.start.objective
    );
    // Found within what the pattern resolves: the extent along the face steps by a cell
    // (1/60 of the face) every ~0.045 mm of centre distance here; the centre across the face
    // moves 0.065 of the face per 0.1 deg of swivel, and the search stops once each component
    // is within ~0.001 (0.0015 deg of swivel). Measured: 0.013 mm, 0.0027 deg.
    assert!(
        (centre - true_centre).abs() < 0.045,
        "centre distance {centre}"
    );
    assert!((swivel - true_swivel).abs() < 0.005, "swivel {swivel}");
    let best = outcome.best.shape.unwrap();
    assert!((best.centre_across_face - truth.centre_across_face).abs() < 2e-3);
    assert!((best.extent_along_face - truth.extent_along_face).abs() < 1e-9);
    // The best gear file is the gear the search found: the same shape again.
    let text = assistant::best_gear_text(&study, &outcome).unwrap();
    let again =
        wormwear::geometry::Geometry::build(&input::load_from_str(&text).unwrap()).map(|_| ());
    assert!(again.is_ok());
    let reloaded = Assistant::new("best".into(), text, target, None, Which::NoLoad, 1);
    let reloaded = reloaded.unwrap_or_else(|e| panic!("{e}"));
    let starts: Vec<f64> = reloaded.settings.iter().map(|s| s.start).collect();
    assert_eq!(starts[0], centre);
    assert_eq!(starts[1], swivel);
    // The path holds every evaluation, the best among them (its settings rounded to 4 decimals
    // where that costs at most 1e-6 of objective), within the budget and the rounding's one.
    let least = outcome
        .path
        .iter()
        .map(|e| e.objective)
        .fold(f64::INFINITY, f64::min);
    assert!(
        least >= outcome.best.objective - 1e-6,
        "{least} {}",
        outcome.best.objective
    );
    assert!(outcome.path.iter().any(|e| e == &outcome.best));
    assert!(outcome.path.len() <= 80 + 1);
}

/// Each bad input is refused before any search, naming the field and what is allowed.
#[test]
fn bad_targets_and_settings_are_refused_by_name() {
    let refused = |e: PatternError| e.to_string();
    assert!(refused(Target::parse("centre_acros_face=0.5").unwrap_err())
        .contains("allowed centre_across_face"));
    assert!(refused(Target::parse("centre_across_face=1.5").unwrap_err()).contains("[0, 1]"));
    assert!(refused(Target::parse("extent_along_face=0").unwrap_err()).contains("(0, 1]"));
    assert!(refused(Target::parse("").unwrap_err()).contains("at least one"));
    assert!(refused(Target::parse("centre_up_flank=x").unwrap_err()).contains("not a number"));
    assert!(
        refused(assistant::parse_bounds("cutting.centre_distance_mm=125").unwrap_err())
            .contains("name=min:max")
    );
    let base = oversize_base();
    let target = Target::parse("centre_across_face=0.6").unwrap();
    let try_bounds = |list: &[(&str, f64, f64)], evaluations: usize| {
        Assistant::new(
            "base".into(),
            base.clone(),
            target,
            bounds(list),
            Which::NoLoad,
            evaluations,
        )
        .map(|_| ())
        .map_err(|e| e.to_string())
    };
    let message = try_bounds(&[("cutting.centre_distance", 125.0, 126.0)], 10).unwrap_err();
    assert!(
        message.contains("no numeric field cutting.centre_distance"),
        "{message}"
    );
    assert!(
        message.contains("cutting.centre_distance_mm"),
        "nearest: {message}"
    );
    let message = try_bounds(&[("worm.profile", 0.0, 1.0)], 10).unwrap_err();
    assert!(message.contains("not a number"), "{message}");
    let message = try_bounds(&[(CENTRE, 126.0, 125.5)], 10).unwrap_err();
    assert!(message.contains("min < max"), "{message}");
    let message = try_bounds(&[(CENTRE, 125.2, 125.8)], 10).unwrap_err();
    assert!(
        message.contains("base gear's value 126 lies outside"),
        "{message}"
    );
    // The worm's tip would reach the wheel's root beyond 126 mm: named with the loader's reason.
    let message = try_bounds(&[(CENTRE, 125.5, 126.5)], 10).unwrap_err();
    assert!(
        message.contains("at its max 126.5") && message.contains("hob.tip_radius_mm"),
        "{message}"
    );
    let message = try_bounds(
        &[
            (assistant::HOB_OVERSIZE, 0.0, 1.0),
            ("hob.tip_radius_mm", 31.0, 33.0),
        ],
        10,
    )
    .unwrap_err();
    assert!(message.contains("vary either it or a radius"), "{message}");
    let message = try_bounds(&[(CENTRE, 125.5, 126.0), (CENTRE, 125.5, 126.0)], 10).unwrap_err();
    assert!(message.contains("given twice"), "{message}");
    let message = try_bounds(&[(CENTRE, 125.5, 126.0)], 0).unwrap_err();
    assert!(message.contains("evaluations = 0"), "{message}");
    // A field the base leaves out starts at its default 0 (cutting.offset_mm is written in the
    // example; the operating offset's default is 0 too).
    assert!(try_bounds(&[("operating.worm_offset_mm", -0.1, 0.1)], 10).is_ok());
}

/// With no settings named, the defaults: the cutting centre distance, the swivel and the
/// oversize, each bound the hob cannot generate narrowed toward the base (and said).
#[test]
fn the_default_settings_are_narrowed_to_what_the_hob_generates() {
    let base = oversize_base();
    let target = Target::parse("centre_across_face=0.6").unwrap();
    let study = Assistant::new("base".into(), base, target, None, Which::NoLoad, 10).unwrap();
    let names: Vec<&str> = study.settings.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, [CENTRE, SWIVEL, assistant::HOB_OVERSIZE]);
    // 126 + 0.2 m_x exceeds what the 1 mm larger hob tip allows (126 mm): narrowed, noted.
    let centre = &study.settings[0];
    assert_eq!(centre.max, 126.0);
    assert!(
        study.notes.iter().any(|n| n.starts_with(CENTRE)),
        "{:?}",
        study.notes
    );
    for s in &study.settings {
        assert!(
            s.min <= s.start && s.start <= s.max && s.min < s.max,
            "{s:?}"
        );
    }
}

/// The loaded pattern's search reads the pattern the full loaded analysis reports: the shape
/// of its best settings equals summary.json's `ltca.pattern_shape` of a run of the best gear
/// file through the pipeline (the design gear without bending, a short budget).
#[test]
fn the_loaded_search_reads_the_pattern_the_loaded_analysis_reports() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/gear-1x40-design.toml"
    );
    // (evenly spaced rows, the grid the assistant reads the pattern on: the default band at
    // the worm-tip trace would report it at the band's resolution)
    let text = std::fs::read_to_string(path)
        .unwrap()
        .replace("model = \"fe\"", "model = \"none\"")
        .replace("[analysis]", "[analysis]\ntip_trace_refinement = 0");
    let target = Target::parse("centre_across_face=0.6").unwrap();
    let vary = bounds(&[(SWIVEL, -0.3, 0.3)]);
    let study = Assistant::new("design".into(), text, target, vary, Which::Loaded, 4).unwrap();
    let outcome = study.run(&|_, _| {}, &|| false).unwrap();
    assert!(outcome.path.len() <= 5, "{}", outcome.path.len());
    assert!(outcome.best.objective <= outcome.start.objective);
    let best = assistant::best_gear_text(&study, &outcome).unwrap();
    let gear = input::load_from_str(&best).unwrap();
    let source = wormwear::Source {
        file: "best".into(),
        text: best,
    };
    let request = wormwear::Request::new([wormwear::Stage::Ltca]);
    let results = wormwear::run(&gear, source, request, &mut |_| Ok(())).unwrap();
    let (tca, ltca) = (
        results.tca.as_ref().unwrap(),
        results.ltca.as_ref().unwrap(),
    );
    let wf = results.geometry.wheel_flank(tca.loaded_flank);
    let reported = wormwear::output::ltca::LtcaSummary::new(tca, wf, ltca).pattern_shape;
    assert_eq!(reported, outcome.best.shape);
}
