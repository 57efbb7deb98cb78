//! Malformed gear files: each gives a clear message naming the field, the value and the allowed
//! range, and nothing panics on any input (property test over random and garbled TOML).

use proptest::prelude::*;
use std::path::Path;
use wormwear::geometry::Geometry;
use wormwear::input::{self, InputError};

fn example_text(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(name);
    std::fs::read_to_string(path).unwrap()
}

fn design() -> String {
    example_text("gear-1x40-design.toml")
}

/// Replaces the first line starting with `key =` inside `[table]` by `replacement`.
fn set(text: &str, table: &str, key: &str, replacement: &str) -> String {
    let mut out = Vec::new();
    let mut current = String::new();
    let mut done = false;
    for line in text.lines() {
        let t = line.trim();
        if t.starts_with('[') {
            current = t.trim_matches(|c| c == '[' || c == ']').to_string();
        }
        let k = t.split('=').next().unwrap_or("").trim();
        if !done && current == table && k == key {
            out.push(replacement.to_string());
            done = true;
        } else {
            out.push(line.to_string());
        }
    }
    assert!(done, "{table}.{key} not found");
    out.join("\n")
}

fn remove(text: &str, table: &str, key: &str) -> String {
    set(text, table, key, "")
}

/// Loads and returns the error message, failing if the file loads.
fn error_of(text: &str) -> String {
    match input::load_from_str(text) {
        Ok(_) => panic!("file was accepted"),
        Err(e) => e.to_string(),
    }
}

fn assert_mentions(message: &str, parts: &[&str]) {
    for p in parts {
        assert!(
            message.contains(p),
            "message does not mention {p:?}:\n{message}"
        );
    }
}

#[test]
fn examples_are_valid() {
    for name in [
        "gear-1x40-design.toml",
        "gear-1x40-case-a.toml",
        "gear-1x40-case-b.toml",
        "gear-1x40-case-c.toml",
        "gear-k-2x25.toml",
    ] {
        let g = input::load_from_str(&example_text(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(g.warnings.is_empty(), "{name}: {:?}", g.warnings);
    }
}

#[test]
fn unknown_key_is_rejected() {
    let text = set(&design(), "worm", "tip_radius_mm", "tip_radius = 30.95");
    assert_mentions(
        &error_of(&text),
        &["unknown field `tip_radius`", "tip_radius_mm"],
    );
}

#[test]
fn missing_field_is_named() {
    let text = remove(&design(), "wheel", "teeth");
    assert_mentions(&error_of(&text), &["[wheel] is missing the key `teeth`"]);
}

#[test]
fn nan_and_infinity_are_rejected() {
    let text = set(&design(), "worm", "tip_radius_mm", "tip_radius_mm = nan");
    assert_mentions(&error_of(&text), &["worm.tip_radius_mm = NaN", "finite"]);
    let text = set(
        &design(),
        "conditions",
        "worm_speed_rpm",
        "worm_speed_rpm = inf",
    );
    assert_mentions(
        &error_of(&text),
        &["conditions.worm_speed_rpm = inf", "finite"],
    );
}

#[test]
fn negative_and_zero_sizes_are_rejected() {
    let text = set(&design(), "wheel", "face_width_mm", "face_width_mm = -45.0");
    assert_mentions(&error_of(&text), &["wheel.face_width_mm = -45", "> 0"]);
    let text = set(
        &design(),
        "wheel",
        "outer_radius_mm",
        "outer_radius_mm = 0.0",
    );
    assert_mentions(&error_of(&text), &["wheel.outer_radius_mm = 0", "> 0"]);
}

#[test]
fn tip_below_root_is_rejected() {
    let text = set(&design(), "worm", "tip_radius_mm", "tip_radius_mm = 19.0");
    assert_mentions(
        &error_of(&text),
        &[
            "worm.tip_radius_mm = 19",
            "root_radius_mm = 20.06",
            "tip below root",
        ],
    );
}

#[test]
fn pressure_angle_out_of_range() {
    let text = set(
        &design(),
        "worm",
        "pressure_angle_deg",
        "pressure_angle_deg = 60.0",
    );
    assert_mentions(
        &error_of(&text),
        &["worm.pressure_angle_deg = 60", "allowed [5, 40] deg"],
    );
}

#[test]
fn centre_distance_inconsistent_with_radii() {
    let text = set(
        &design(),
        "operating",
        "centre_distance_mm",
        "centre_distance_mm = 140.0",
    );
    assert_mentions(
        &error_of(&text),
        &[
            "operating.centre_distance_mm = 140",
            "profile shift",
            "[-1.5, 1.5]",
        ],
    );
    // Wheel throat above the worm root.
    let text = set(
        &design(),
        "wheel",
        "throat_radius_mm",
        "throat_radius_mm = 106.0",
    );
    assert_mentions(
        &error_of(&text),
        &["wheel.throat_radius_mm = 106", "worm root"],
    );
}

#[test]
fn face_width_beyond_the_worm_reach() {
    let text = set(&design(), "wheel", "face_width_mm", "face_width_mm = 60.0");
    assert_mentions(
        &error_of(&text),
        &[
            "wheel.face_width_mm = 60",
            "larger than the worm can reach",
            "54.1",
        ],
    );
}

#[test]
fn hob_that_cannot_cut_the_wheel() {
    // Tip too small: the worm tip would hit the wheel root.
    let text = set(&design(), "hob", "tip_radius_mm", "tip_radius_mm = 30.0");
    assert_mentions(
        &error_of(&text),
        &[
            "hob.tip_radius_mm = 30",
            "worm tip would hit the wheel root",
        ],
    );
    // Root too high: the hob core would cut the wheel tip.
    let text = set(&design(), "hob", "root_radius_mm", "root_radius_mm = 22.0");
    assert_mentions(
        &error_of(&text),
        &[
            "hob.root_radius_mm = 22",
            "hob root would cut the wheel tip",
        ],
    );
    // Wrong pitch.
    let text = set(&design(), "hob", "lead_mm", "lead_mm = 16.0");
    assert_mentions(&error_of(&text), &["hob.axial_module_mm", "axial pitch"]);
    // Wrong hand.
    let text = set(&design(), "hob", "hand", "hand = \"left\"");
    assert_mentions(&error_of(&text), &["hob.hand", "must equal worm.hand"]);
}

#[test]
fn bad_choices_and_exclusive_fields() {
    let text = set(&design(), "worm", "profile", "profile = \"Q\"");
    assert_mentions(
        &error_of(&text),
        &["worm.profile = \"Q\"", "must be one of A, N, I, K, C"],
    );
    let text = set(
        &design(),
        "worm",
        "lead_mm",
        "lead_mm = 15.551\naxial_module_mm = 4.95",
    );
    assert_mentions(
        &error_of(&text),
        &["give either worm.axial_module_mm or worm.lead_mm"],
    );
    let text = set(
        &design(),
        "conditions",
        "worm_torque_nm",
        "worm_torque_nm = 60.0\nwheel_torque_nm = 2000.0",
    );
    assert_mentions(
        &error_of(&text),
        &["conditions.wheel_torque_nm", "not both"],
    );
    let text = set(&design(), "worm", "profile", "profile = \"K\"");
    assert_mentions(
        &error_of(&text),
        &["worm.grinding_wheel", "profiles K and C need"],
    );
    let text = set(
        &design(),
        "wear",
        "step_wear_um",
        "step_wear_um = 4.0\ndamage_node_reading = \"mean\"",
    );
    assert_mentions(
        &error_of(&text),
        &[
            "wear.damage_node_reading = \"mean\"",
            "must be one of largest, interpolated",
        ],
    );
}

#[test]
fn wear_and_rating_sections_are_checked() {
    // Both step controls at once.
    let text = set(
        &design(),
        "wear",
        "step_wear_um",
        "step_wear_um = 4.0\nstep_cycles = 30000",
    );
    assert_mentions(
        &error_of(&text),
        &["wear.step_cycles", "either wear.step_wear_um", "not both"],
    );
    // A negative life, and one of less than a wheel revolution (1e-300 ran to exit 0).
    let text = set(&design(), "wear", "life_cycles", "life_cycles = -5");
    assert_mentions(&error_of(&text), &["wear.life_cycles = -5", "[1, 1e12]"]);
    let text = set(&design(), "wear", "life_cycles", "life_cycles = 1e-300");
    assert_mentions(
        &error_of(&text),
        &["wear.life_cycles = 1e-300", "[1, 1e12]"],
    );
    // Plans that would never end or fill the disk: a vanishing adaptive step or sub-step, a
    // life of 1e12 states, 100 000 phases, a million map states (the previous build accepted
    // each and ran for hours or wrote ~6 files per state).
    let text = set(&design(), "wear", "step_wear_um", "step_wear_um = 1e-300");
    assert_mentions(
        &error_of(&text),
        &["wear.step_wear_um = 1e-300", "[0.05, 1000] um"],
    );
    let text = set(
        &design(),
        "wear",
        "step_wear_um",
        "step_wear_um = 4.0\nmax_substep_wear_um = 1e-300",
    );
    assert_mentions(
        &error_of(&text),
        &["wear.max_substep_wear_um = 1e-300", "or 0: off"],
    );
    // The step scheme and the error control (`wear::stabilised`).
    let text = set(
        &design(),
        "wear",
        "step_wear_um",
        "step_wear_um = 4.0\nstep_scheme = \"implicit\"",
    );
    assert_mentions(
        &error_of(&text),
        &[
            "wear.step_scheme = \"implicit\"",
            "\"explicit\"",
            "\"stabilised\"",
        ],
    );
    // The stability guard guards the explicit step (5 um by default); the stabilised step
    // needs none (off by default, as given otherwise).
    let guard = |lines: &str| {
        let text = set(&design(), "wear", "step_wear_um", lines);
        input::load_from_str(&text)
            .unwrap()
            .wear
            .unwrap()
            .max_substep_removal
    };
    assert_eq!(guard("step_wear_um = 24.0"), 5.0 * 1e-6);
    assert_eq!(
        guard("step_wear_um = 24.0\nstep_scheme = \"stabilised\""),
        0.0
    );
    assert_eq!(
        guard("step_wear_um = 24.0\nstep_scheme = \"stabilised\"\nmax_substep_wear_um = 8"),
        8.0 * 1e-6
    );
    let text = set(
        &design(),
        "wear",
        "step_wear_um",
        "step_cycles = 10000\nstep_tolerance = 0.01",
    );
    assert_mentions(
        &error_of(&text),
        &["wear.step_tolerance = 0.01", "wear.step_wear_um"],
    );
    let text = set(
        &design(),
        "wear",
        "step_wear_um",
        "step_wear_um = 24.0\nstep_tolerance = 2",
    );
    assert_mentions(
        &error_of(&text),
        &["wear.step_tolerance = 2", "[0.0001, 0.5]"],
    );
    let text = set(
        &set(&design(), "wear", "step_wear_um", "step_cycles = 1"),
        "wear",
        "life_cycles",
        "life_cycles = 1e12",
    );
    assert_mentions(
        &error_of(&text),
        &[
            "wear.step_cycles = 1",
            "1.000e12 states",
            "at least 1e7 cycles per step",
        ],
    );
    let phases: Vec<String> = (1..=100_000)
        .map(|k| format!("{{ kind = \"wear\", until_cycles = {k} }}"))
        .collect();
    let text = set(
        &design(),
        "wear",
        "life_cycles",
        &format!("life_cycles = 1e6\nphases = [{}]", phases.join(", ")),
    );
    assert_mentions(
        &error_of(&text),
        &["wear.phases = 100000 phases", "at most 100 phases"],
    );
    let maps: Vec<String> = (1..=1_000_000).map(|k| k.to_string()).collect();
    let text = set(
        &design(),
        "wear",
        "life_cycles",
        &format!("life_cycles = 1e6\nmap_cycles = [{}]", maps.join(", ")),
    );
    assert_mentions(
        &error_of(&text),
        &[
            "wear.map_cycles = 1000000 entries",
            "at most 200 map states",
            "about 6000000",
        ],
    );
    // Phases out of order and an unknown phase kind.
    let text = set(
        &design(),
        "wear",
        "life_cycles",
        "life_cycles = 1e6\nphases = [ { kind = \"wear\", until_cycles = 5e5 }, \
         { kind = \"pitting\", until_cycles = 2e5 }, { kind = \"rest\", until_cycles = 9e5 } ]",
    );
    let m = error_of(&text);
    assert_mentions(
        &m,
        &[
            "wear.phases[1].until_cycles",
            "increasing order",
            "wear.phases[2].kind",
        ],
    );
    // A wear phase with a pressure limit.
    let text = set(
        &design(),
        "wear",
        "life_cycles",
        "life_cycles = 1e6\nphases = [ { kind = \"wear\", until_cycles = 5e5, pressure_limit_mpa = 500 } ]",
    );
    assert_mentions(
        &error_of(&text),
        &["wear.phases[0].pressure_limit_mpa", "only pitting"],
    );
    // A forecast finds its own pitting phases; pits from the damage take no pressure limit;
    // only a forecast takes an onset share; a life factor must be positive.
    let with = |lines: &str| set(&design(), "wear", "life_cycles", lines);
    assert_mentions(
        &error_of(&with(
            "life_cycles = 1e6\npitting = \"forecast\"\nphases = [ { kind = \"wear\", \
             until_cycles = 5e5 }, { kind = \"pitting\", until_cycles = 6e5 } ]",
        )),
        &["wear.phases[1].kind", "finds its own pitting phases"],
    );
    assert_mentions(
        &error_of(&with(
            "life_cycles = 1e6\npitting = \"damage\"\nphases = [ { kind = \"pitting\", \
             until_cycles = 6e5, pressure_limit_mpa = 500 } ]",
        )),
        &[
            "wear.phases[0].pressure_limit_mpa",
            "take no pressure limit",
        ],
    );
    assert_mentions(
        &error_of(&with("life_cycles = 1e6\npitting_onset_percent = 5")),
        &["wear.pitting_onset_percent = 5", "only a forecast"],
    );
    assert_mentions(
        &error_of(&with("life_cycles = 1e6\npitting = \"foresight\"")),
        &["wear.pitting", "forecast"],
    );
    assert_mentions(
        &error_of(&with(
            "life_cycles = 1e6\npitting = \"forecast\"\npitting_onset_percent = 120",
        )),
        &["wear.pitting_onset_percent = 120"],
    );
    assert_mentions(
        &error_of(&with("life_cycles = 1e6\nendurance = { life_factor = -1 }")),
        &["wear.endurance.life_factor = -1"],
    );
    // A degenerate pressure-life curve (a zero or vanishing exponent, factors at the ends of
    // the doubles) would give infinite or NaN damage: refused, the field and range named.
    for (key, value, range) in [
        ("exponent", "0", "[0.02, 5]"),
        ("exponent", "1e-300", "[0.02, 5]"),
        ("life_factor", "1e-300", "[0.01, 100]"),
        ("reference_pressure_mpa", "1e-300", "[1, 100000] MPa"),
        ("reference_cycles", "1e-300", "[1, 1e15] cycles"),
    ] {
        assert_mentions(
            &error_of(&with(&format!(
                "life_cycles = 1e6\npitting = \"forecast\"\nendurance = {{ {key} = {value} }}"
            ))),
            &[&format!("wear.endurance.{key} = {value}"), range],
        );
    }
    // A valid forecast.
    let g = input::load_from_str(&with(
        "life_cycles = 1e6\npitting = \"forecast\"\npitting_onset_percent = 0.5\n\
         endurance = { life_factor = 0.4 }",
    ))
    .unwrap();
    let plan = g.wear.unwrap();
    assert_eq!(plan.pitting, input::Pitting::Forecast);
    assert!((plan.pitting_onset_share - 0.005).abs() < 1e-15);
    assert_eq!(plan.endurance.life_factor, 0.4);
    // Rating factors and the pressure cap out of range.
    let text = set(
        &design(),
        "rating",
        "friction_size_factor",
        "friction_size_factor = 0.0",
    );
    assert_mentions(
        &error_of(&text),
        &["rating.friction_size_factor = 0", "[0.1, 10]"],
    );
    let text = set(
        &design(),
        "analysis",
        "positions",
        "positions = 20\ncontact_pressure_cap_mpa = 1000.0",
    );
    assert_mentions(
        &error_of(&text),
        &[
            "analysis.contact_pressure_cap_mpa = 1000",
            "analysis.flow_pressure_mpa",
            "contact = \"elastic\"",
        ],
    );
    let text = set(
        &design(),
        "analysis",
        "positions",
        "positions = 20\nflow_pressure_mpa = 1.0",
    );
    assert_mentions(
        &error_of(&text),
        &["analysis.flow_pressure_mpa = 1", "[10, 100000] MPa"],
    );
    let text = set(
        &design(),
        "analysis",
        "positions",
        "positions = 20\ncontact = \"rigid\"",
    );
    assert_mentions(
        &error_of(&text),
        &["analysis.contact = \"rigid\"", "plastic, elastic"],
    );
    // The band at the worm-tip trace: a whole number of times finer, at most 16.
    for bad in ["-1", "17"] {
        let text = set(
            &design(),
            "analysis",
            "positions",
            &format!("positions = 20\ntip_trace_refinement = {bad}"),
        );
        assert_mentions(
            &error_of(&text),
            &[&format!("analysis.tip_trace_refinement = {bad}"), "[0, 16]"],
        );
    }
}

#[test]
fn pointed_thread_and_closed_space() {
    let text = set(&design(), "worm", "tip_radius_mm", "tip_radius_mm = 36.0");
    assert_mentions(&error_of(&text), &["worm.tip_radius_mm = 36", "pointed"]);
    let text = set(
        &design(),
        "worm",
        "axial_thickness_mm",
        "axial_thickness_mm = 16.0",
    );
    assert_mentions(
        &error_of(&text),
        &["worm.axial_thickness_mm = 16", "less than the axial pitch"],
    );
}

#[test]
fn integer_ranges_and_wrong_types() {
    let text = set(&design(), "wheel", "teeth", "teeth = 3");
    assert_mentions(
        &error_of(&text),
        &["wheel.teeth = 3", "allowed integers [10, 500]"],
    );
    let text = set(&design(), "analysis", "positions", "positions = 1");
    assert_mentions(&error_of(&text), &["analysis.positions = 1", "[4, 720]"]);
    let text = set(&design(), "wheel", "teeth", "teeth = \"forty\"");
    assert_mentions(&error_of(&text), &["invalid type", "teeth"]);
}

#[test]
fn syntax_error_gives_the_line() {
    let text = design().replacen("[wheel]", "[wheel", 1);
    let e = input::load_from_str(&text).unwrap_err();
    assert!(matches!(e, InputError::Syntax(_)));
    assert_mentions(&e.to_string(), &["line"]);
}

#[test]
fn several_problems_are_reported_together() {
    let text = set(&design(), "wheel", "face_width_mm", "face_width_mm = -1.0");
    let text = set(
        &text,
        "worm",
        "pressure_angle_deg",
        "pressure_angle_deg = 90.0",
    );
    let e = input::load_from_str(&text).unwrap_err();
    let fields: Vec<&str> = e.field_errors().iter().map(|f| f.field.as_str()).collect();
    assert!(
        fields.contains(&"wheel.face_width_mm") && fields.contains(&"worm.pressure_angle_deg"),
        "{fields:?}"
    );
}

#[test]
fn missing_file_is_an_io_error() {
    let e = input::load(Path::new("/nonexistent/gear.toml")).unwrap_err();
    assert!(matches!(e, InputError::Io { .. }));
    assert_mentions(&e.to_string(), &["/nonexistent/gear.toml"]);
}

/// Numeric values that break naive code.
fn nasty_number() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("nan".to_string()),
        Just("inf".to_string()),
        Just("-inf".to_string()),
        Just("0".to_string()),
        Just("-0.0".to_string()),
        Just("1e308".to_string()),
        Just("-1e308".to_string()),
        Just("1e-300".to_string()),
        Just("9223372036854775807".to_string()),
        Just("-9223372036854775808".to_string()),
        (-1e4f64..1e4).prop_map(|v| format!("{v:.6}")),
        (0.5f64..2.0).prop_map(|f| format!("{f}")),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 160, ..ProptestConfig::default() })]

    /// Arbitrary text never panics the loader.
    #[test]
    fn random_text_never_panics(text in "\\PC{0,400}") {
        let _ = input::load_from_str(&text);
    }

    /// Garbled example files (a numeric value replaced, scaled, or a line dropped or
    /// duplicated) never panic the loader, and any file that validates also builds its geometry
    /// without panicking (it may return an error).
    #[test]
    fn garbled_examples_never_panic(
        which in 0usize..2,
        line_pick in 0usize..10_000,
        action in 0usize..4,
        number in nasty_number(),
        scale in 0.3f64..3.0,
    ) {
        let base = example_text(if which == 0 { "gear-1x40-design.toml" } else { "gear-k-2x25.toml" });
        let lines: Vec<&str> = base.lines().collect();
        let numeric: Vec<usize> = lines
            .iter()
            .enumerate()
            .filter(|(_, l)| l.contains('=') && l.split('=').nth(1).map(|v| v.trim().starts_with(|c: char| c.is_ascii_digit() || c == '-')).unwrap_or(false))
            .map(|(i, _)| i)
            .collect();
        let idx = numeric[line_pick % numeric.len()];
        let mut out: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
        let key = lines[idx].split('=').next().unwrap().trim().to_string();
        match action {
            0 => out[idx] = format!("{key} = {number}"),
            1 => {
                let v: f64 = lines[idx].split('=').nth(1).unwrap().split('#').next().unwrap().trim()
                    .parse().unwrap_or(1.0);
                out[idx] = format!("{key} = {}", v * scale);
            }
            2 => out[idx].clear(),
            _ => out.insert(idx, lines[idx].to_string()),
        }
        let text = out.join("\n");
        if let Ok(gear) = input::load_from_str(&text) {
            let _ = Geometry::build_with_grid(&gear, 4, 4);
        }
    }
}

#[test]
fn bending_section_is_checked() {
    let k = example_text("gear-k-2x25.toml");
    let text = set(&k, "bending", "model", "model = \"beam\"");
    assert_mentions(
        &error_of(&text),
        &["bending.model = \"beam\"", "must be one of none, fe"],
    );
    let text = set(&k, "bending", "model", "model = \"fe\"\nwidth_points = 40");
    assert_mentions(&error_of(&text), &["bending.width_points = 40", "[2, 17]"]);
    let text = set(
        &k,
        "bending",
        "model",
        "model = \"fe\"\nworm_shaft_radius_mm = 30.0",
    );
    assert_mentions(
        &error_of(&text),
        &["bending.worm_shaft_radius_mm = 30", "root radius"],
    );
    let text = set(
        &k,
        "bending",
        "model",
        "model = \"fe\"\nworm_bearing_positions_mm = [-10.0, 10.0]",
    );
    assert_mentions(
        &error_of(&text),
        &["bending.worm_bearing_positions_mm", "outside the worm body"],
    );
    let text = set(
        &k,
        "bending",
        "model",
        "model = \"fe\"\nworm_bearing_positions_mm = [-200.0]",
    );
    assert_mentions(&error_of(&text), &["two positions"]);
}

#[test]
fn wheel_body_is_checked_when_bending_is_on() {
    // The K 2/25 example has bending on and a full wheel body.
    let k = example_text("gear-k-2x25.toml");
    let text = set(&k, "wheel", "hub_radius_mm", "hub_radius_mm = 95.0");
    assert_mentions(
        &error_of(&text),
        &["wheel.hub_radius_mm = 95.0000 mm", "rim's inner radius"],
    );
    let text = set(&k, "wheel", "shaft_radius_mm", "shaft_radius_mm = 36.0");
    assert_mentions(
        &error_of(&text),
        &["wheel.shaft_radius_mm", "must be < wheel.hub_radius_mm"],
    );
    let text = set(
        &k,
        "wheel",
        "bearing_positions_mm",
        "bearing_positions_mm = [10.0, 65.0]",
    );
    assert_mentions(
        &error_of(&text),
        &[
            "wheel.bearing_positions_mm",
            "each side of the hub",
            "25.4000",
        ],
    );
    let text = set(
        &k,
        "wheel",
        "bearing_positions_mm",
        "bearing_positions_mm = [65.0]",
    );
    assert_mentions(
        &error_of(&text),
        &["wheel.bearing_positions_mm", "two positions"],
    );
    let text = set(&k, "wheel", "web_thickness_mm", "web_thickness_mm = 60.0");
    assert_mentions(&error_of(&text), &["wheel.web_thickness_mm", "face width"]);
    // Without bending the body is not used and not checked.
    let off = set(&k, "bending", "model", "model = \"none\"");
    let off = set(&off, "wheel", "hub_radius_mm", "hub_radius_mm = 95.0");
    assert!(wormwear::input::load_from_str(&off).is_ok());
}

#[test]
fn a_parse_error_on_a_huge_line_does_not_echo_it_whole() {
    // A 100 000-element array under a wrong key: the error names the key and its line, and
    // cuts the echoed source line instead of printing 200 KB.
    let text = design().replacen(
        "[worm]",
        &format!("[worm]\nbogus = [{}]", vec!["1"; 100_000].join(",")),
        1,
    );
    let line = 1 + text.lines().position(|l| l.starts_with("bogus")).unwrap();
    let at = format!("line {line}");
    let message = error_of(&text);
    assert_mentions(&message, &["bogus", &at, "characters)", "axial_module_mm"]);
    assert!(message.len() < 2_000, "{} characters", message.len());
}

#[test]
fn an_endurance_curve_given_in_part_takes_the_defaults_for_the_rest() {
    // README: `[wear.endurance]` fields default to 425 MPa at 11e6 cycles, exponent 0.176.
    let text = example_text("gear-1x40-case-c.toml").replacen(
        "[rating]",
        "[wear.endurance]\nexponent = 0.2\n\n[rating]",
        1,
    );
    let gear = input::load_from_str(&text).unwrap();
    let e = gear.wear.unwrap().endurance;
    assert_eq!(e.exponent, 0.2);
    assert_eq!(e.reference_pressure, 425e6);
    assert_eq!(e.reference_cycles, 11e6);
}

#[test]
fn named_choices_are_case_insensitive_as_documented() {
    let upper = input::load_from_str(&design()).unwrap();
    let lower =
        input::load_from_str(&set(&design(), "worm", "profile", "profile = \"a\"")).unwrap();
    assert_eq!(lower.worm.profile, upper.worm.profile);
    assert!(format!("{:?}", lower.worm.profile) == "A");
}

#[test]
fn ten_thousand_sections_are_refused_at_once() {
    let offsets = vec!["0.0"; 10_000].join(", ");
    let text = set(
        &design(),
        "analysis",
        "section_offsets_mm",
        &format!("section_offsets_mm = [{offsets}]"),
    );
    let start = std::time::Instant::now();
    let message = error_of(&text);
    assert_mentions(
        &message,
        &["analysis.section_offsets_mm", "10000 offsets", "at most 50"],
    );
    // One message for the list, not one per offset.
    assert!(message.len() < 2_000, "{}", message.len());
    eprintln!("rejected in {:.3} s", start.elapsed().as_secs_f64());
}

#[test]
fn errors_name_the_input_that_causes_them() {
    // A vanishing speed (1e-300 rpm ended a life in a solver message): refused with its range.
    let text = design().replace("worm_speed_rpm = 1500.0", "worm_speed_rpm = 1e-300");
    assert_mentions(
        &error_of(&text),
        &["conditions.worm_speed_rpm = 1e-300", "[0.001, 20000] rpm"],
    );
    // A throat radius far below the wheel's reference radius: named itself (the previous
    // build blamed the face width, "must be < 0.000 mm").
    let text = design().replace("throat_radius_mm = 103.94", "throat_radius_mm = 3.0");
    let message = error_of(&text);
    assert_mentions(
        &message,
        &["wheel.throat_radius_mm = 3", "must be >= 89.101 mm"],
    );
    assert!(!message.contains("face_width"), "{message}");
    // A dotted key 20 000 levels deep: the parser's recursion limit, with the line (the
    // previous build: "recursion limit" alone).
    let deep = vec!["a"; 20_000].join(".");
    let text = format!("{}\n{deep} = 1\n", design());
    let line = text.lines().count();
    assert_mentions(
        &error_of(&text),
        &[
            &format!("line {line} nests 20000 levels deep"),
            "dotted keys",
        ],
    );
    // A vanishing face width: the bounds derived from it in scientific notation, not 300
    // digits.
    let text = design().replace("face_width_mm = 45.0", "face_width_mm = 1e-300");
    let message = error_of(&text);
    assert!(
        message.len() < 2000 && message.contains("e-301"),
        "{message}"
    );
}

#[test]
fn geometry_failures_name_the_inputs_to_change() {
    // Files that validate but cannot be generated (issue 16): an involute worm whose base
    // radius lies above its root (5 deg), a 4-start worm and hob on the 1/40 blank.
    let involute = design()
        .replace("profile = \"A\"", "profile = \"I\"")
        .replace("pressure_angle_deg = 21.81", "pressure_angle_deg = 5.0");
    let four_starts = design()
        .replace("starts = 1", "starts = 4")
        .replace("lead_mm = 15.551", "lead_mm = 62.204");
    for (text, parts) in [
        (
            involute,
            &[
                "worm:",
                "[worm] profile",
                "pressure_angle_deg",
                "root_radius_mm",
            ][..],
        ),
        (
            four_starts,
            &["[hob] starts", "wheel.teeth", "outer_radius_mm"][..],
        ),
    ] {
        let gear = input::load_from_str(&text).unwrap();
        let message = match Geometry::build(&gear) {
            Ok(_) => panic!("generated"),
            Err(e) => e.to_string(),
        };
        assert_mentions(&message, parts);
    }
}

/// A problem that a change of one field causes in another names the field changed (issue 38's
/// probe: 10 starts were reported as a thickness above the pitch, a 4.5 mm face width as section
/// offsets out of range, without naming starts or the face width).
#[test]
fn relations_name_the_fields_they_depend_on() {
    let cases = [
        ("worm", "starts", "starts = 10", "worm.starts"),
        ("worm", "starts", "starts = 2", "worm.starts"),
        ("hob", "lead_mm", "lead_mm = 16.551", "worm.lead_mm"),
        (
            "worm",
            "axial_thickness_mm",
            "axial_thickness_mm = 0.7775",
            "worm.axial_thickness_mm",
        ),
        (
            "cutting",
            "centre_distance_mm",
            "centre_distance_mm = 1250.0",
            "cutting.centre_distance_mm",
        ),
        ("wheel", "teeth", "teeth = 400", "wheel.teeth"),
        (
            "wheel",
            "face_width_mm",
            "face_width_mm = 4.5",
            "wheel.face_width_mm",
        ),
        (
            "wheel",
            "outer_radius_mm",
            "outer_radius_mm = 1100.0",
            "wheel.outer_radius_mm",
        ),
        ("worm", "lead_mm", "lead_mm = 155.51", "worm.lead_mm"),
        (
            "wheel",
            "face_width_mm",
            "face_width_mm = 5.0",
            "wheel.face_width_mm",
        ),
    ];
    // A relief length's bound names what sets it (a face width of 1e-300 mm gave "allowed
    // [0.01, 2.5e-301] mm" and nothing else).
    let text = set(
        &design(),
        "wheel",
        "face_width_mm",
        "face_width_mm = 2.0\nedge_relief_length_mm = 1.0",
    );
    let message = error_of(&text);
    let relief = message
        .lines()
        .find(|l| l.contains("wheel.edge_relief_length_mm"))
        .unwrap_or_else(|| panic!("{message}"));
    assert!(
        relief.contains("a quarter of wheel.face_width_mm"),
        "{relief}"
    );
    for (table, key, line, field) in cases {
        let message = error_of(&set(&design(), table, key, line));
        // Named in a problem of another field (its own line is not the point).
        let others: Vec<&str> = message
            .lines()
            .filter(|l| !l.trim_start().starts_with(&format!("- {table}.{key}")))
            .collect();
        assert!(
            others.iter().any(|l| l.contains(field)),
            "{line}: no other problem names {field}:\n{message}"
        );
    }
}

#[test]
fn friction_and_heat_balance_inputs_are_checked_by_name() {
    // A viscosity that would grow with the temperature (beta* < 0), an unknown temperature
    // mode, a negative housing area, a cooler that cannot be a heat flow, and friction
    // constants out of range: each named with its value and range.
    let with = |lubricant: &str, housing: &str| {
        let text = without_safety_inputs()
            .replace("[lubricant]\n", &format!("[lubricant]\n{lubricant}\n"));
        format!("{text}\n[housing]\n{housing}\n")
    };
    let e = error_of(&set(
        &design(),
        "lubricant",
        "thermo_viscosity_k",
        "thermo_viscosity_k = -3200",
    ));
    assert_mentions(&e, &["lubricant.thermo_viscosity_k", "-3200"]);
    let e = error_of(&with("temperature = \"hot\"", ""));
    assert_mentions(&e, &["lubricant.temperature", "hot", "balance"]);
    let e = error_of(&with("", "area_m2 = -1.0"));
    assert_mentions(&e, &["housing.area_m2", "-1"]);
    let e = error_of(&with("", "cooler_w = -5.0\nheat_transfer_w_m2k = 0.0"));
    assert_mentions(&e, &["housing.cooler_w", "housing.heat_transfer_w_m2k"]);
    let e = error_of(&with(
        "boundary_friction = 1.0\nsummit_density_radius_roughness = 0.0",
        "",
    ));
    assert_mentions(
        &e,
        &[
            "lubricant.boundary_friction",
            "1",
            "0.999",
            "lubricant.summit_density_radius_roughness",
        ],
    );
    // A negative summit product, and a roughness beyond Greenwood & Tripp's summits (sigma /
    // beta at most 0.1): each named with its value and the range.
    let e = error_of(&with(
        "summit_density_radius_roughness = -0.05\nsummit_roughness_radius = 0.5",
        "",
    ));
    assert_mentions(
        &e,
        &[
            "lubricant.summit_density_radius_roughness",
            "-0.05",
            "lubricant.summit_roughness_radius",
            "0.5",
            "0.1",
        ],
    );
    // The published model's torque reading is an option; anything else is named.
    let e = error_of(&set(
        &design(),
        "analysis",
        "flank_cells_height",
        "flank_cells_height = 40\ntorque_balance = \"frictionfree\"",
    ));
    assert_mentions(
        &e,
        &["analysis.torque_balance", "frictionfree", "transmitted"],
    );
    let e = error_of(&set(
        &design(),
        "analysis",
        "flank_cells_height",
        "flank_cells_height = 40\ncontact_band_growth = \"grow\"",
    ));
    assert_mentions(
        &e,
        &["analysis.contact_band_growth", "grow", "widen", "extend"],
    );
    let e = error_of(&with(
        "eyring_stress_mpa = 0.0\nlimiting_shear_coefficient = -0.1",
        "",
    ));
    assert_mentions(
        &e,
        &[
            "lubricant.eyring_stress_mpa",
            "lubricant.limiting_shear_coefficient",
        ],
    );
    // And the defaults validate: a balance with the default housing is a valid file.
    let gear =
        input::load_from_str(&with("temperature = \"balance\"", "ambient_c = 25.0")).unwrap();
    assert!(gear.housing.balance && (gear.housing.ambient - 298.15).abs() < 1e-12);
    assert!(gear.housing.area > 0.0 && gear.housing.heat_transfer > 0.0);
}

/// The design example without its safety inputs and its housing (the tests add their own).
fn without_safety_inputs() -> String {
    let mut text = design();
    for key in [
        "required_life_h",
        "root_stress_allowable_mpa",
        "root_fillet_radius_mm",
        "deflection_limit_um",
        "oil_temperature_limit_c",
    ] {
        text = remove(&text, "rating", key);
    }
    let housing = text
        .find("\n[housing]")
        .expect("the design example's housing");
    text[..housing].to_string()
}

#[test]
fn safety_table_inputs_are_checked_by_name_and_converted_to_si() {
    // Each bad value named with its field and value, all reported at once; good ones in SI.
    let with = |lines: &str| {
        without_safety_inputs().replace("[rating]\n", &format!("[rating]\n{lines}\n"))
    };
    let e = error_of(&with(
        "required_life_h = -5.0\napplication_factor = 0.5\ndeflection_limit_um = 0.0\n\
         oil_temperature_limit_c = 400.0\nminimum_safety_wear = 0.0\nstarts_per_hour = -1.0\n\
         root_fillet_radius_mm = -1.0",
    ));
    assert_mentions(
        &e,
        &[
            "rating.required_life_h",
            "-5",
            "rating.application_factor",
            "0.5",
            "rating.deflection_limit_um",
            "rating.oil_temperature_limit_c",
            "400",
            "rating.minimum_safety_wear",
            "rating.starts_per_hour",
            "rating.root_fillet_radius_mm",
        ],
    );
    let gear = input::load_from_str(&with(
        "required_life_h = 2000.0\nroot_stress_allowable_mpa = 80.0\nroot_fillet_radius_mm = 0.8\n\
         deflection_limit_um = 40.0\n\
         thickness_loss_limit_mm = 0.5\nmass_loss_limit_g = 30.0\noil_temperature_limit_c = 90.0\n\
         application_factor = 1.25\nminimum_safety_pitting = 1.5",
    ))
    .unwrap();
    let s = gear.rating.safety;
    assert_eq!(s.required_life_hours, Some(2000.0));
    assert_eq!(s.root_stress_allowable, Some(80e6));
    assert!((s.root_fillet_radius.unwrap() - 0.8e-3).abs() < 1e-18);
    assert!((s.deflection_limit.unwrap() - 40e-6).abs() < 1e-18);
    assert!((s.thickness_loss_limit.unwrap() - 0.5e-3).abs() < 1e-18);
    assert!((s.mass_loss_limit.unwrap() - 0.03).abs() < 1e-15);
    assert!((s.oil_temperature_limit.unwrap() - 363.15).abs() < 1e-12);
    assert_eq!((s.application_factor, s.minimum[2]), (1.25, 1.5));
}

#[test]
fn unknown_keys_are_all_reported_at_once_with_their_lines() {
    // Two misspelled keys in two tables, one of them a required key: both named with their
    // lines in one error, then the key that is now missing; a well-formed file is unaffected.
    let text = design()
        .replacen("worm_torque_nm = 60.0", "worm_torqe_nm = 60.0", 1)
        .replacen("\nface_width_mm", "\nface_widht_mm", 1);
    let line_of = |key: &str| text.lines().position(|l| l.starts_with(key)).unwrap() + 1;
    let e = error_of(&text);
    assert_mentions(
        &e,
        &[
            "unknown field `worm_torqe_nm`",
            &format!("line {}", line_of("worm_torqe_nm")),
            "unknown field `face_widht_mm`",
            &format!("line {}", line_of("face_widht_mm")),
            "[wheel] is missing the key `face_width_mm`",
        ],
    );
    assert!(input::load_from_str(&design()).is_ok());
}

#[test]
fn missing_keys_and_tables_are_all_reported_at_once_with_their_tables_lines() {
    // Two keys left out of [worm] and [hob], two of [wheel], and the whole [cutting] table:
    // every one named in one error, with the line of its table's header.
    let mut text = design();
    for (table, key) in [
        ("worm", "reference_radius_mm"),
        ("hob", "reference_radius_mm"),
        ("wheel", "teeth"),
        ("wheel", "face_width_mm"),
        ("cutting", "centre_distance_mm"),
        ("cutting", "offset_mm"),
        ("cutting", "inclination_deg"),
    ] {
        text = remove(&text, table, key);
    }
    let text = text.replace("[cutting]\n", "\n");
    let line_of = |header: &str| {
        text.lines()
            .position(|l| l.starts_with(header))
            .map(|k| k + 1)
            .unwrap()
    };
    let e = error_of(&text);
    for expected in [
        format!(
            "line {}: [worm] is missing the key `reference_radius_mm`",
            line_of("[worm]")
        ),
        format!(
            "line {}: [hob] is missing the key `reference_radius_mm`",
            line_of("[hob]")
        ),
        format!(
            "line {}: [wheel] is missing the key `teeth`",
            line_of("[wheel]")
        ),
        format!(
            "line {}: [wheel] is missing the key `face_width_mm`",
            line_of("[wheel]")
        ),
        "the file has no [cutting] table".to_string(),
    ] {
        assert!(e.contains(&expected), "no {expected:?} in:\n{e}");
    }
    // A complete file is unaffected.
    assert!(input::load_from_str(&design()).is_ok());
}

#[test]
fn an_oil_temperature_outside_the_viscosity_data_is_warned() {
    // Issue 58: 250 C and -30 C passed without a word.
    for (t, warned) in [("250.0", true), ("-30.0", true), ("59.85", false)] {
        let text = set(
            &design(),
            "lubricant",
            "temperature_c",
            &format!("temperature_c = {t}"),
        );
        let g = input::load_from_str(&text).unwrap();
        let warning = g
            .warnings
            .iter()
            .find(|w| w.contains("lubricant.temperature_c"));
        assert_eq!(warning.is_some(), warned, "{t}: {:?}", g.warnings);
        // A run says it too (the CLI prints the results' warnings; they were in
        // summary.json's geometry section alone).
        let request = wormwear::Request::new([wormwear::Stage::Geometry]);
        let results = wormwear::run(&g, Default::default(), request, &mut |_| Ok(())).unwrap();
        let said = results
            .warnings
            .iter()
            .any(|w| w.starts_with("input: lubricant.temperature_c"));
        assert_eq!(said, warned, "{t}: {:?}", results.warnings);
    }
}
