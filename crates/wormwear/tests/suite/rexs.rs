//! REXS import and export: every derived quantity of the hand-written test stages against a
//! hand calculation, both encodings and the zip container, several stages, bad input, and the
//! round trip import -> export -> import.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use wormwear::input::{self, GearSet, Hand, ProfileType, Rotation, Torque};
use wormwear::rexs::{self, import, Encoding, Model, RexsError};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/rexs")
        .join(name)
}

fn zi_example() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/rexs/worm-stage-zi-2x41.rexs")
}

/// The gear file text and the validated gear of a REXS file's only worm stage.
fn imported(path: &Path) -> (import::Imported, GearSet) {
    let model = rexs::read(path).unwrap();
    let imp = import::import(&model, None, "test").unwrap();
    let gear = input::load_from_str(&imp.text)
        .unwrap_or_else(|e| panic!("{e}\n--- gear file ---\n{}", imp.text));
    (imp, gear)
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-300)
}

/// Kinematic viscosity by Ubbelohde-Walther through two points (ASTM D341), mm^2/s.
fn walther(nu40: f64, nu100: f64, t_c: f64) -> f64 {
    let w = |nu: f64| (nu + 0.7f64).log10().log10();
    let x = |t: f64| (t + 273.15f64).log10();
    let slope = (w(nu100) - w(nu40)) / (x(100.0) - x(40.0));
    let wt = w(nu40) + slope * (x(t_c) - x(40.0));
    10f64.powf(10f64.powf(wt)) - 0.7
}

#[test]
fn zi_two_start_stage_gives_the_hand_calculated_gear() {
    let (imp, g) = imported(&zi_example());
    assert!(imp.warnings.is_empty(), "{:?}", imp.warnings);
    let w = &g.worm;
    assert_eq!(w.profile, ProfileType::I);
    assert_eq!(w.starts, 2);
    assert_eq!(w.hand, Hand::Right);
    // m_x = 4 mm: p_x = 4 pi mm; d_m1 = 36 mm; tan(gamma) = z1 m_x / d_m1 = 8 / 36.
    assert!(close(w.axial_pitch, 4e-3 * PI, 1e-15));
    assert!(close(w.reference_radius, 18e-3, 1e-15));
    let gamma = (8.0f64 / 36.0).atan();
    assert!(close(w.lead_angle(), gamma, 1e-14));
    assert!(
        (gamma.to_degrees() - 12.5288).abs() < 5e-5,
        "the file's lead angle"
    );
    // Normal module m_x cos(gamma) = 3.90475 mm as the file states.
    assert!((4.0 * gamma.cos() - 3.90475).abs() < 5e-6);
    // ZI: alpha_0 is the normal pressure angle; tan(alpha_x) = tan(alpha_n) / cos(gamma).
    assert!(close(w.normal_pressure_angle, 20f64.to_radians(), 1e-14));
    let alpha_x = (20f64.to_radians().tan() / gamma.cos()).atan();
    assert!(close(w.axial_pressure_angle, alpha_x, 1e-14));
    assert!(close(w.axial_thickness, 0.5 * 4e-3 * PI, 1e-15));
    // Ratio 41 / 2; d_2 = 164, x2 = (100 - 18 - 82) / 4 = 0; wheel tip 172 / 2.
    assert!(close(g.ratio(), 20.5, 1e-15));
    assert!(close(g.wheel.throat_radius, 86e-3, 1e-15));
    assert!(
        close(g.wheel.outer_radius, 88e-3, 1e-15),
        "default d_a2 + m_x"
    );
    // The hob tip cuts the wheel root: a - d_f2 / 2 = 100 - 77.2.
    assert!(close(g.hob.tip_radius, 22.8e-3, 1e-12));
    // Bearings: worm at x = -80 / +80 from the worm centre, drive side (load at u = 0 of a
    // shaft starting at x = -150) first; wheel at z2 = -40 / +40, fixed end (load at z = +100)
    // last.
    assert_eq!(g.bending.worm_bearings, [-80e-3, 80e-3]);
    assert_eq!(
        g.wheel.bearing_positions.as_deref(),
        Some(&[-40e-3, 40e-3][..])
    );
    assert!(close(g.wheel_body().shaft_radius, 22.5e-3, 1e-15));
    assert!(close(g.bending.worm_shaft_radius, 12e-3, 1e-15));
    // 1000 rpm, T2 = 300 N m, positive rotation of a right-hand worm.
    assert!(close(
        g.conditions.worm_speed,
        1000.0 * 2.0 * PI / 60.0,
        1e-15
    ));
    assert_eq!(g.conditions.torque, Torque::Wheel(300.0));
    assert_eq!(g.rotation, Rotation::Positive);
    // Lubricant at 70 degC: Walther through 220 / 37 mm^2/s, density 1020 kg/m^3 less 7e-4/K.
    let nu = walther(220.0, 37.0, 70.0);
    let eta = nu * 1e-6 * 1020.0 * (1.0 - 7e-4 * 55.0);
    assert!(close(g.lubricant.viscosity, eta, 1e-12));
    assert!(close(g.lubricant.temperature, 343.15, 1e-15));
    // AGMA 925-A03 for a PAG: alpha = 0.0047 eta[mPa s]^0.1572 mm^2/N.
    let alpha = 0.0047 * (eta * 1e3).powf(0.1572) * 1e-6;
    assert!(close(g.lubricant.pressure_viscosity, alpha, 1e-12));
    // Hardness 95 HB of the bronze in GPa; Young's moduli.
    assert!(close(g.wheel_material.hardness, 95.0 * 9.80665e6, 1e-15));
    assert!(close(g.wheel_material.youngs_modulus, 98.1e9, 1e-15));
    assert!(close(g.worm_material.youngs_modulus, 210e9, 1e-15));
}

#[test]
fn za_json_left_hand_with_other_units_and_signs() {
    let (imp, g) = imported(&data("za-1x40-left.rexsj"));
    assert!(imp.warnings.is_empty(), "{:?}", imp.warnings);
    let w = &g.worm;
    assert_eq!(
        (w.profile, w.starts, w.hand),
        (ProfileType::A, 1, Hand::Left)
    );
    // Module from the lead: 15.551 / pi; lead angle atan(m_x / 26 mm... over d_m1 = 52).
    assert!(close(w.axial_pitch, 15.551e-3, 1e-15));
    assert!(close(w.lead_angle(), (15.551 / PI / 52.0f64).atan(), 1e-14));
    assert!(
        close(w.axial_pressure_angle, 21.81f64.to_radians(), 1e-14),
        "ZA: axial"
    );
    // Centre distance 0.125 m, offset 20 um, width offset 0.05 mm, shaft angle 2e-4 rad.
    assert!(close(g.nominal_centre_distance, 0.125, 1e-15));
    assert!(close(g.operating.centre_distance, 0.12502, 1e-12));
    assert!(close(g.operating.offset, 0.05e-3, 1e-12));
    assert!(close(g.operating.inclination, 2e-4, 1e-12));
    // Hob root = tip - depth = 31.95 - 10.9; face width from the effective face width.
    assert!(close(g.hob.root_radius, 21.05e-3, 1e-12));
    assert!(close(g.wheel.face_width, 45e-3, 1e-15));
    // Torque -60000 N mm on the worm; speed -1500 rpm of a left-hand worm: the thread moves
    // towards -x1, as a right-hand worm turning positively.
    assert_eq!(g.conditions.torque, Torque::Worm(60.0));
    assert_eq!(g.rotation, Rotation::Positive);
    assert!(close(g.conditions.worm_speed, 1500.0 * PI / 30.0, 1e-15));
    // Worm axis along global y, worm centre at y = 60: bearings at y = -20 and 140 -> -80 and
    // +80; the motor (u = -60 on a shaft at the origin) is nearer -80.
    assert_eq!(g.bending.worm_bearings, [-80e-3, 80e-3]);
    // 333.15 K; mineral oil of 890 kg/m^3; AGMA 925 mineral-oil coefficients.
    assert!(close(g.lubricant.temperature, 333.15, 1e-15));
    let eta = walther(220.0, 19.0, 60.0) * 1e-6 * 890.0 * (1.0 - 7e-4 * 45.0);
    assert!(close(g.lubricant.viscosity, eta, 1e-12));
    let alpha = 0.010471 * (eta * 1e3).powf(0.1348) * 1e-6;
    assert!(close(g.lubricant.pressure_viscosity, alpha, 1e-12));
    assert!(close(g.wheel_material.hardness, 102.0 * 9.80665e6, 1e-15));
    assert!(imp.text.contains("hand = \"left\""));
}

#[test]
fn zk_stage_takes_its_disc_and_standard_defaults_and_warns_of_a_steel_wheel() {
    let (imp, g) = imported(&data("zk-1x30-placeholder.rexs"));
    assert_eq!(g.worm.profile, ProfileType::K);
    let disc = g.worm.grinding_wheel.as_ref().unwrap();
    assert!(close(disc.radius, 125e-3, 1e-15));
    assert!(close(disc.profile_angle, 20f64.to_radians(), 1e-14));
    // d_2 = 30 x 5 = 150; x2 = (100 - 25 - 75) / 5 = 0: d_a2 = 150 + 2 x 5 = 160, d_e2 = 165.
    assert!(close(g.wheel.throat_radius, 80e-3, 1e-15));
    assert!(close(g.wheel.outer_radius, 82.5e-3, 1e-15));
    // Hob tip: worm tip + 0.2 m_x.
    assert!(close(g.hob.tip_radius, 31e-3, 1e-15));
    assert_eq!(g.conditions.torque, Torque::Wheel(250.0));
    assert!(imp
        .warnings
        .iter()
        .any(|w| w.contains("42CrMo4") && w.contains("not a bronze")));
    assert!(imp.text.contains("# WARNING: the wheel material"));
    // Defaults said in comments; every attribute used or listed.
    assert!(imp
        .text
        .contains("default worm tip + bottom clearance 0.2 m_x"));
    assert!(imp.text.contains("REXS attributes not used by this import"));
}

#[test]
fn a_stated_operating_viscosity_and_pressure_viscosity_law_are_used() {
    let text = std::fs::read_to_string(data("zk-1x30-placeholder.rexs"))
        .unwrap()
        .replace(
            "<attribute id=\"temperature_lubricant\" unit=\"C\">80</attribute>",
            "<attribute id=\"temperature_lubricant\" unit=\"C\">80</attribute>\n      \
             <attribute id=\"operating_viscosity\" unit=\"mm^2 / s\">41.5</attribute>",
        )
        .replace(
            "<attribute id=\"lubricant_type_iso_6336_2006\" unit=\"none\">mineral_oil</attribute>",
            "<attribute id=\"parameter_k_for_calculation_of_pressure_viscosity_coefficient_agma_925_a03\" \
             unit=\"none\">0.012</attribute>\n      \
             <attribute id=\"parameter_s_for_calculation_of_pressure_viscosity_coefficient_agma_925_a03\" \
             unit=\"none\">0.1</attribute>\n      \
             <attribute id=\"thermal_conductivity\" unit=\"W / (m K)\">0.13</attribute>",
        );
    let model = rexs::parse_bytes(text.as_bytes(), "zk.rexs").unwrap();
    let imp = import::import(&model, None, "zk").unwrap();
    let g = input::load_from_str(&imp.text).unwrap();
    // 41.5 mm^2/s at 80 degC x the default density 900 kg/m^3 less 7e-4/K over 65 K.
    let eta = 41.5e-6 * 900.0 * (1.0 - 7e-4 * 65.0);
    assert!(close(g.lubricant.viscosity, eta, 1e-14));
    // alpha = k eta^s mm^2/N with eta in mPa s.
    let alpha = 0.012 * (eta * 1e3).powf(0.1) * 1e-6;
    assert!(close(g.lubricant.pressure_viscosity, alpha, 1e-12));
    assert!(close(g.lubricant.thermal_conductivity, 0.13, 1e-15));
}

#[test]
fn unused_attributes_are_listed_not_dropped() {
    let (imp, _) = imported(&zi_example());
    for listed in [
        "lubrication_type_din_3996_2019 = dip_lubrication",
        "normal_module = 3.90475",
        "operating_time = 20000",
        "inner_diameter = 25",
    ] {
        assert!(imp.text.contains(listed), "{listed} not listed");
    }
    // A used attribute is not listed.
    assert!(!imp
        .text
        .contains("# worm_stage [3] \"worm stage ZI 2/41\": center_distance"));
}

#[test]
fn xml_json_and_zip_encodings_give_the_same_gear_file() {
    let xml = rexs::read(&zi_example()).unwrap();
    let from_xml = import::import(&xml, None, "same").unwrap().text;
    // Our writers, read back: the model and the gear file are unchanged.
    for encoding in [Encoding::Xml, Encoding::Json] {
        let text = rexs::to_string(&xml, encoding);
        let back = rexs::parse_bytes(text.as_bytes(), "written").unwrap();
        let gear_text = import::import(&back, None, "same").unwrap().text;
        assert_eq!(gear_text, from_xml, "{encoding:?}");
    }
    // Markup characters in names and texts survive both encodings.
    let mut odd = xml.clone();
    odd.components[0].name = "a < b & \"c\" > 'd' – ü".into();
    for encoding in [Encoding::Xml, Encoding::Json] {
        let text = rexs::to_string(&odd, encoding);
        let back = rexs::parse_bytes(text.as_bytes(), "odd").unwrap();
        assert_eq!(
            back.components[0].name, odd.components[0].name,
            "{encoding:?}"
        );
    }
    // A hand-written JSON file reads as well (types from the JSON keys).
    let json = rexs::read(&data("za-1x40-left.rexsj")).unwrap();
    let again = rexs::parse_bytes(rexs::to_string(&json, Encoding::Json).as_bytes(), "j").unwrap();
    assert_eq!(again, json);
    // .rexsz: a zip holding the .rexs.
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let options = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated);
    zip.start_file("stage.rexs", options).unwrap();
    std::io::Write::write_all(&mut zip, std::fs::read(zi_example()).unwrap().as_slice()).unwrap();
    let bytes = zip.finish().unwrap().into_inner();
    let from_zip = rexs::parse_bytes(&bytes, "stage.rexsz").unwrap();
    assert_eq!(from_zip, xml);
}

/// The ZI and ZA stages in one model (the ZA's ids shifted by 1000).
fn two_stage_model() -> Model {
    let mut a = rexs::read(&zi_example()).unwrap();
    let b = rexs::read(&data("za-1x40-left.rexsj")).unwrap();
    for mut c in b.components {
        c.id += 1000;
        for att in &mut c.attributes {
            if let rexs::Value::Reference(id) = &mut att.value {
                *id += 1000;
            }
        }
        a.components.push(c);
    }
    for mut r in b.relations {
        r.id += 1000;
        for x in &mut r.refs {
            x.id += 1000;
        }
        a.relations.push(r);
    }
    a
}

#[test]
fn a_file_with_two_stages_lists_them_and_imports_the_one_chosen() {
    let model = rexs::parse_bytes(
        rexs::to_string(&two_stage_model(), Encoding::Xml).as_bytes(),
        "two.rexs",
    )
    .unwrap();
    let stages = import::worm_stages(&model);
    assert_eq!(stages.iter().map(|s| s.id).collect::<Vec<_>>(), [3, 1003]);
    let err = import::import(&model, None, "two").unwrap_err().to_string();
    assert!(
        err.contains("2 worm stages") && err.contains("--stage 3") && err.contains("--stage 1003"),
        "{err}"
    );
    let zi = import::import(&model, Some(3), "two").unwrap();
    let za = import::import(&model, Some(1003), "two").unwrap();
    assert!(zi.text.contains("profile = \"I\"") && za.text.contains("profile = \"A\""));
    let g = input::load_from_str(&za.text).unwrap();
    assert_eq!(g.worm.hand, Hand::Left);
    assert!(zi
        .text
        .contains("other component(s) of the model are not part of this stage"));
    let err = import::import(&model, Some(7), "two")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("--stage 7") && err.contains("no worm stage"),
        "{err}"
    );
}

/// The error of importing the ZI example with `edit` applied to its text.
fn error_of(edit: impl Fn(&str) -> String) -> String {
    let text = edit(&std::fs::read_to_string(zi_example()).unwrap());
    match rexs::parse_bytes(text.as_bytes(), "bad.rexs") {
        Err(e) => e.to_string(),
        Ok(model) => match import::import(&model, None, "bad.rexs") {
            Err(e) => e.to_string(),
            Ok(i) => panic!("no error; gear file:\n{}", i.text),
        },
    }
}

#[test]
fn bad_files_give_errors_naming_the_component_the_attribute_and_the_need() {
    let e = error_of(|t| t[..t.len() / 2].to_string());
    assert!(
        e.contains("bad.rexs") && e.contains("XML"),
        "truncated: {e}"
    );
    let e = error_of(|t| {
        t.replace(
            "<attribute id=\"length\"",
            "<attribute id=\"length\" id=\"x\"",
        )
    });
    assert!(e.contains("XML at byte"), "duplicate attribute: {e}");
    let e = rexs::parse_bytes(b"{\"modell\": {}}", "x.rexsj")
        .unwrap_err()
        .to_string();
    assert!(e.contains("\"model\""), "{e}");
    let e = rexs::parse_bytes(b"{\"model\": {\"components\": [{\"id\": -1}]}}", "x.rexsj")
        .unwrap_err()
        .to_string();
    assert!(e.contains("components[0]") && e.contains("id"), "{e}");
    let e = rexs::parse_bytes(b"hello", "x").unwrap_err().to_string();
    assert!(e.contains("not a REXS file"), "{e}");
    let e = error_of(|t| t.replace("type=\"stage\"", "type=\"assembly\""));
    assert!(e.contains("no worm stage"), "{e}");
    let e = error_of(|t| {
        t.replace(
            "<attribute id=\"reference_diameter_worm_gear\" unit=\"mm\">36.0",
            "<attribute id=\"reference_diameter_worm_gear\" unit=\"furlong\">36.0",
        )
    });
    assert!(
        e.contains("component 10 (worm_gear)")
            && e.contains("reference_diameter_worm_gear")
            && e.contains("furlong")
            && e.contains("accepted: mm"),
        "{e}"
    );
    let e = error_of(|t| {
        t.replace(
            "<attribute id=\"center_distance\" unit=\"mm\">100.0</attribute>",
            "",
        )
    });
    assert!(
        e.contains("component 3 (worm_stage)")
            && e.contains("center_distance")
            && e.contains("is needed"),
        "{e}"
    );
    let e = error_of(|t| t.replace(">zi</attribute>", ">zz</attribute>"));
    assert!(e.contains("flank_form") && e.contains("zz"), "{e}");
    let e = error_of(|t| t.replace("unit=\"mm\">36.0", "unit=\"mm\">thirty-six"));
    assert!(e.contains("\"thirty-six\" is not a number"), "{e}");
    let e = error_of(|t| {
        t.replace(
            "<attribute id=\"torque_around_u_axis\" unit=\"N m\">300.0</attribute>",
            "",
        )
    });
    assert!(e.contains("the load is needed"), "{e}");
    // A negative quantity is refused naming itself (the probe of issue 38: it read as not
    // given, and the message blamed the 40 degC viscosity).
    let e = error_of(|t| {
        t.replace(
            "<attribute id=\"viscosity_at_100_degree_celsius\" unit=\"mm^2 / s\">",
            "<attribute id=\"viscosity_at_100_degree_celsius\" unit=\"mm^2 / s\">-",
        )
    });
    assert!(
        e.contains("viscosity_at_100_degree_celsius") && e.contains("must be a positive number"),
        "{e}"
    );
    // A missing 100 degC viscosity is named as the one missing.
    let e = error_of(|t| {
        t.replace(
            "<attribute id=\"viscosity_at_100_degree_celsius\" unit=\"mm^2 / s\">37.0</attribute>",
            "",
        )
    });
    assert!(
        e.contains("attribute viscosity_at_100_degree_celsius: missing"),
        "{e}"
    );
}

/// A stage that imports but does not validate: each field's problem names the REXS attribute
/// it came from, and a mistyped 1e300 is not written with 300 digits (issue 38's probe).
#[test]
fn validation_errors_of_an_import_name_the_rexs_attribute() {
    let text = std::fs::read_to_string(zi_example()).unwrap().replace(
        "<attribute id=\"center_distance\" unit=\"mm\">100.0",
        "<attribute id=\"center_distance\" unit=\"mm\">1e300",
    );
    let model = rexs::parse_bytes(text.as_bytes(), "big.rexs").unwrap();
    let imp = import::import(&model, None, "big.rexs").unwrap();
    let err = imp
        .with_sources(input::load_from_str(&imp.text).unwrap_err())
        .to_string();
    assert!(
        err.contains("operating.centre_distance_mm = 1e300")
            && err.contains("(from REXS: worm_stage.center_distance)"),
        "{err}"
    );
    for line in imp
        .text
        .lines()
        .chain(imp.warnings.iter().map(|w| w.as_str()))
    {
        assert!(!line.contains("0000000000000000"), "a long number: {line}");
    }
}

#[test]
fn a_zero_wheel_tip_diameter_reads_as_not_given_and_its_default_names_the_attribute() {
    // The JSON ZA 1/40 stage with the wheel's tip diameter 0: the default d_a2 is used, which
    // the file's hob root cuts by 37 nm. The previous build's refusal named the default rule
    // and not the attribute that was 0 (probe: "unclear").
    let text = std::fs::read_to_string(data("za-1x40-left.rexsj")).unwrap();
    let given = "\"floating_point\": 207.88";
    assert!(text.contains(given));
    let text = text.replace(given, "\"floating_point\": 0");
    let model = rexs::parse_bytes(text.as_bytes(), "zero.rexsj").unwrap();
    let imp = import::import(&model, None, "zero.rexsj").unwrap();
    let err = imp
        .with_sources(input::load_from_str(&imp.text).unwrap_err())
        .to_string();
    assert!(
        err.contains("hob.root_radius_mm")
            && err.contains("worm_wheel.tip_diameter_worm_gear not given (absent or 0)"),
        "{err}"
    );
}

/// Two gears are the same when their validated data agree to round-off (relative 1e-11;
/// the export writes 12 significant digits): the stage, not the title nor the settings of an
/// analysis (grid, life plan, rating factors), which REXS does not carry. Wheel-body values
/// are compared as the model uses them (a default written out is the same gear).
fn assert_same_gear(a: &GearSet, b: &GearSet) {
    let effective = |g: &GearSet| {
        let mut g = g.clone();
        let body = g.wheel_body();
        g.wheel.rim_thickness = Some(body.rim_thickness);
        g.wheel.web_thickness = Some(body.web_thickness);
        g.wheel.hub_radius = Some(body.hub_radius);
        g.wheel.shaft_radius = Some(body.shaft_radius);
        g.wheel.bearing_positions = Some(body.bearings.to_vec());
        g
    };
    let (a, b) = (&effective(a), &effective(b));
    fn walk(a: &serde_json::Value, b: &serde_json::Value, path: &str) {
        use serde_json::Value as J;
        match (a, b) {
            (J::Number(x), J::Number(y)) => {
                let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
                assert!(
                    (x - y).abs() <= 1e-11 * x.abs().max(y.abs()),
                    "{path}: {x} vs {y}"
                );
            }
            (J::Object(x), J::Object(y)) => {
                assert_eq!(
                    x.keys().collect::<Vec<_>>(),
                    y.keys().collect::<Vec<_>>(),
                    "{path}"
                );
                for (k, v) in x {
                    let skipped = ["title", "warnings", "analysis", "wear", "rating"];
                    if path.is_empty() && skipped.contains(&k.as_str()) {
                        continue;
                    }
                    walk(v, &y[k], &format!("{path}.{k}"));
                }
            }
            (J::Array(x), J::Array(y)) => {
                assert_eq!(x.len(), y.len(), "{path}");
                for (i, (u, v)) in x.iter().zip(y).enumerate() {
                    walk(u, v, &format!("{path}[{i}]"));
                }
            }
            _ => assert_eq!(a, b, "{path}"),
        }
    }
    walk(
        &serde_json::to_value(a).unwrap(),
        &serde_json::to_value(b).unwrap(),
        "",
    );
}

#[test]
fn import_export_import_gives_the_same_gear() {
    for path in [
        zi_example(),
        data("za-1x40-left.rexsj"),
        data("zk-1x30-placeholder.rexs"),
    ] {
        let (_, first) = imported(&path);
        for encoding in [Encoding::Xml, Encoding::Json] {
            let model = rexs::export::stage_model(&first, None, "2026-11-24T00:00:00Z").unwrap();
            let text = rexs::to_string(&model, encoding);
            let back = rexs::parse_bytes(text.as_bytes(), "exported").unwrap();
            let imp = import::import(&back, None, "exported").unwrap();
            let second = input::load_from_str(&imp.text).unwrap();
            assert_same_gear(&first, &second);
        }
    }
    // The edge breaks (MODEL §2.3) travel as custom attributes.
    let (_, mut first) = imported(&zi_example());
    first.worm.tip_edge_radius = 0.5e-3;
    first.wheel.face_edge_chamfer = 0.8e-3;
    // So does the running-in of the roughness (MODEL §6.1).
    first.lubricant.running_in = Some(input::RunningIn {
        roughness: 0.4e-6,
        depth: 2e-6,
    });
    let model = rexs::export::stage_model(&first, None, "2026-11-24T00:00:00Z").unwrap();
    let text = rexs::to_string(&model, Encoding::Xml);
    let back = rexs::parse_bytes(text.as_bytes(), "exported").unwrap();
    let imp = import::import(&back, None, "exported").unwrap();
    let second = input::load_from_str(&imp.text).unwrap();
    assert_eq!(second.worm.tip_edge_radius, 0.5e-3);
    let run_in = second.lubricant.running_in.expect("the running-in travels");
    assert!((run_in.roughness - 0.4e-6).abs() < 1e-18 && (run_in.depth - 2e-6).abs() < 1e-18);
    assert_same_gear(&first, &second);
}

#[test]
fn export_writes_the_results_under_the_standard_ids() {
    // The ZA stage, coarse and without bending: its loaded analysis takes a second.
    let (imp, _) = imported(&data("za-1x40-left.rexsj"));
    let text = imp.text.replace("model = \"fe\"", "model = \"none\"")
        + "\n[analysis]\nflank_cells_height = 16\nflank_cells_face = 24\npositions = 6\n";
    let gear = input::load_from_str(&text).unwrap();
    let source = wormwear::Source {
        file: "za.toml".into(),
        text: text.clone(),
    };
    let mut plan = wormwear::input::WearPlan::with_life(20_000.0);
    plan.step = wormwear::input::StepControl::Cycles(10_000.0);
    let request = wormwear::Request::new([
        wormwear::Stage::Geometry,
        wormwear::Stage::Tca,
        wormwear::Stage::Ltca,
        wormwear::Stage::Wear,
    ])
    .with_life(plan);
    let results = wormwear::run(&gear, source, request, &mut |_| Ok(())).unwrap();
    let model = rexs::export::stage_model(&gear, Some(&results), "2026-11-24T00:00:00Z").unwrap();
    let stage = model
        .components
        .iter()
        .find(|c| c.kind == "worm_stage")
        .unwrap();
    let value = |id: &str| match &stage.attribute(id).unwrap_or_else(|| panic!("{id}")).value {
        rexs::Value::Float(x) => *x,
        other => panic!("{id}: {other}"),
    };
    let rating = results.rating.as_ref().unwrap();
    let ltca = results.ltca.as_ref().unwrap();
    assert!(close(
        value("gear_efficiency_in_reducer_din_3996_2019"),
        rating.mesh_efficiency,
        1e-11
    ));
    assert!(close(
        value("mean_hertzian_stress_din_3996_2019"),
        rating.sigma_hm_mpa,
        1e-11
    ));
    assert!(close(
        value("maximum_hertzian_stress_ltca_worm_stage"),
        ltca.max_pressure * 1e-6,
        1e-11
    ));
    assert!(close(
        value("contact_ratio_ltca_worm_stage"),
        100.0 * ltca.s0,
        1e-11
    ));
    assert!(close(
        value("safety_factor_pitting_din_3996_2019"),
        rating.pitting_safety,
        1e-11
    ));
    assert!(stage
        .attributes
        .iter()
        .any(|a| a.id.starts_with("custom_wormwear_")));
    // The safety table from the model (MODEL §9.1): the worm's deflection; no safety without
    // the [rating] limits.
    let safety = results.safety.as_ref().unwrap();
    let deflection = safety.rows.iter().find(|r| r.symbol == "S_delta").unwrap();
    assert!(close(
        value("custom_wormwear_worm_deflection_mesh_point"),
        deflection.value.unwrap(),
        1e-11
    ));
    assert!(stage
        .attribute("custom_wormwear_safety_deflection_model")
        .is_none());
    // With results the file still re-imports to the same gear.
    let back = rexs::parse_bytes(rexs::to_string(&model, Encoding::Xml).as_bytes(), "x").unwrap();
    let again = input::load_from_str(&import::import(&back, None, "x").unwrap().text).unwrap();
    assert_same_gear(&gear, &again);
}

#[test]
fn json_values_of_the_wrong_type_are_kept_and_refused_only_where_needed() {
    let text = std::fs::read_to_string(data("za-1x40-left.rexsj")).unwrap();
    // null on an attribute the import does not need: listed, the gear imports.
    let unused = text.replace(
        "{\"id\": \"u_coordinate_on_shaft\", \"unit\": \"mm\", \"floating_point\": -60.0}",
        "{\"id\": \"transmits_torque\", \"unit\": \"none\", \"boolean\": null}",
    );
    assert_ne!(unused, text);
    let model = rexs::parse_bytes(unused.as_bytes(), "x.rexsj").unwrap();
    let imp = import::import(&model, None, "x").unwrap();
    assert!(
        imp.text.contains("transmits_torque = boolean: null"),
        "{}",
        imp.text
    );
    // null where the import needs the value: an error naming the attribute.
    let needed = text.replace("\"enum\": \"za\"}", "\"enum\": null}");
    let model = rexs::parse_bytes(needed.as_bytes(), "x.rexsj").unwrap();
    let e = import::import(&model, None, "x").unwrap_err().to_string();
    assert!(e.contains("flank_form") && e.contains("null"), "{e}");
}

#[test]
fn units_the_importer_does_not_know_are_refused_where_used_only() {
    // An unknown unit on an attribute the import does not use is listed, not an error.
    let text = std::fs::read_to_string(zi_example()).unwrap().replace(
        "<attribute id=\"width\" unit=\"mm\">15.0",
        "<attribute id=\"width\" unit=\"inch-ish\">15.0",
    );
    let model = rexs::parse_bytes(text.as_bytes(), "x").unwrap();
    let imp = import::import(&model, None, "x").unwrap();
    assert!(imp.text.contains("width = 15.0 [inch-ish]"));
    let _: Option<RexsError> = None;
}

#[test]
fn damaged_files_never_panic() {
    // Truncations and byte substitutions of the three test stages, in both encodings: every
    // one gives a model or an error, and every imported gear file validates or is refused.
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let sources = [
        std::fs::read(zi_example()).unwrap(),
        std::fs::read(data("za-1x40-left.rexsj")).unwrap(),
        std::fs::read(data("zk-1x30-placeholder.rexs")).unwrap(),
    ];
    let junk = b"<>&\"'{}[],:0-9.e+ \\/\x00\xff";
    for bytes in &sources {
        for k in 0..600 {
            let mut b = bytes.clone();
            if k % 3 == 0 {
                b.truncate((next() as usize) % b.len());
            } else {
                for _ in 0..1 + k % 5 {
                    let i = (next() as usize) % b.len();
                    b[i] = junk[(next() as usize) % junk.len()];
                }
            }
            if let Ok(model) = rexs::parse_bytes(&b, "damaged") {
                if let Ok(imp) = import::import(&model, None, "damaged") {
                    let _ = input::load_from_str(&imp.text);
                }
            }
        }
    }
}

#[test]
fn a_zip_with_two_rexs_files_names_them_instead_of_importing_one() {
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let options = zip::write::SimpleFileOptions::default();
    let text = std::fs::read(zi_example()).unwrap();
    for name in ["first.rexs", "second.rexs"] {
        zip.start_file(name, options).unwrap();
        std::io::Write::write_all(&mut zip, &text).unwrap();
    }
    let bytes = zip.finish().unwrap().into_inner();
    let err = rexs::parse_bytes(&bytes, "two.rexsz")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("2 REXS files") && err.contains("first.rexs, second.rexs"),
        "{err}"
    );
}

#[test]
fn a_zip_member_larger_than_a_rexs_file_may_be_is_not_inflated() {
    // 257 MiB of zeros deflate to a few hundred kB: the member is refused by its declared
    // size, and by the bytes actually inflated when the declared size is wrong.
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let options = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated)
        .large_file(false);
    zip.start_file("stage.rexs", options).unwrap();
    let block = vec![0u8; 1 << 20];
    for _ in 0..257 {
        std::io::Write::write_all(&mut zip, &block).unwrap();
    }
    let bytes = zip.finish().unwrap().into_inner();
    assert!(bytes.len() < 2 << 20, "{} bytes", bytes.len());
    let err = rexs::parse_bytes(&bytes, "bomb.rexsz")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("stage.rexs") && err.contains("more than the 268435456 bytes"),
        "{err}"
    );
}

#[test]
fn a_count_outside_its_range_is_named_with_its_value_not_called_missing() {
    // Issue 58: number_of_teeth -41 or 0 read "missing: the number of starts z1 is needed",
    // 1e308 became worm.starts = 9223372036854775807.
    let worm = "<attribute id=\"number_of_teeth\" unit=\"none\">2</attribute>";
    let wheel = "<attribute id=\"number_of_teeth\" unit=\"none\">41</attribute>";
    for (from, to, expected) in [
        (
            worm,
            "-41",
            "-41: the number of starts z1 must be from 1 to 10",
        ),
        (worm, "0", "0: the number of starts z1 must be from 1 to 10"),
        (worm, "1e308", "too large for a count"),
        (
            wheel,
            "0",
            "0: the number of wheel teeth z2 must be from 1 to 500",
        ),
    ] {
        let e = error_of(|t| {
            let with = from
                .replace(">2<", &format!(">{to}<"))
                .replace(">41<", &format!(">{to}<"));
            t.replacen(from, &with, 1)
        });
        assert!(
            e.contains("number_of_teeth") && e.contains(expected),
            "{to}: {e}"
        );
    }
}

#[test]
fn deeply_nested_json_is_named_as_such() {
    // Issue 58: a 200 000-deep array was "expected XML ..., JSON ... or a zip", and a deep
    // object a bare "recursion limit exceeded".
    let depth = 200_000;
    let array = format!("{}{}", "[".repeat(depth), "]".repeat(depth));
    let err = rexs::parse_bytes(array.as_bytes(), "x")
        .unwrap_err()
        .to_string();
    assert!(err.contains("a JSON array"), "{err}");
    let object = format!("{}1{}", "{\"model\":".repeat(depth), "}".repeat(depth));
    let err = rexs::parse_bytes(object.as_bytes(), "x")
        .unwrap_err()
        .to_string();
    assert!(err.contains("nested deeper than 128 levels"), "{err}");
}

/// The duty-cycle example (MODEL §14) with its bins as `edit` makes them.
fn spectrum_gear(edit: impl Fn(&str) -> String) -> GearSet {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/gear-1x40-duty-cycle.toml");
    input::load_from_str(&edit(&std::fs::read_to_string(path).unwrap())).unwrap()
}

#[test]
fn a_duty_cycle_goes_out_as_a_load_spectrum_and_comes_back() {
    // Three bins, one given by its wheel torque and one with its own oil temperature; the
    // other worm rotation (a negative speed in the load cases).
    let gear = spectrum_gear(|t| {
        t.replace(
            "worm_torque_nm = 60.0\nworm_speed_rpm = 1000.0",
            "wheel_torque_nm = 1800.0\nworm_speed_rpm = 1000.0\noil_temperature_c = 75.0",
        )
        .replace(
            "worm_rotation = \"positive\"",
            "worm_rotation = \"negative\"",
        )
    });
    assert_eq!(gear.duty_cycle.len(), 3);
    for encoding in [Encoding::Xml, Encoding::Json] {
        let model = rexs::export::stage_model(&gear, None, "2026-11-27T00:00:00Z").unwrap();
        assert_eq!(model.load_cases.len(), 3);
        // The varied attributes are in the load cases only (REXS: not in the master model).
        for c in &model.components {
            for varied in [
                "rotational_speed",
                "torque_around_u_axis",
                "load_duration_fraction",
            ] {
                if c.kind == "shaft" && c.name == "worm shaft" || c.kind == "external_load" {
                    assert!(c.attribute(varied).is_none(), "{} {varied}", c.kind);
                }
            }
        }
        let text = rexs::to_string(&model, encoding);
        let back = rexs::parse_bytes(text.as_bytes(), "exported").unwrap();
        // XML carries no value types (its scalars come back as text): the cases' ids and
        // attributes there, the whole cases through JSON.
        let ids = |m: &Model| -> Vec<(u64, Vec<(u64, String)>)> {
            m.load_cases
                .iter()
                .map(|c| {
                    let attrs = c.components.iter().flat_map(|x| {
                        x.attributes
                            .iter()
                            .map(move |a| (x.id, format!("{} {}", a.id, a.value)))
                    });
                    (c.id, attrs.collect())
                })
                .collect()
        };
        assert_eq!(ids(&back), ids(&model));
        if matches!(encoding, Encoding::Json) {
            assert_eq!(back.load_cases, model.load_cases);
        }
        let imp = import::import(&back, None, "exported").unwrap();
        let second = input::load_from_str(&imp.text)
            .unwrap_or_else(|e| panic!("{e}\n--- gear file ---\n{}", imp.text));
        assert_eq!(second.rotation, Rotation::Negative);
        assert_eq!(second.conditions, gear.conditions);
        assert_eq!(second.duty_cycle.len(), 3);
        for (a, b) in gear.duty_cycle.iter().zip(&second.duty_cycle) {
            assert_eq!(a.conditions.torque, b.conditions.torque);
            assert!(close(
                a.conditions.worm_speed,
                b.conditions.worm_speed,
                1e-12
            ));
            assert!(close(a.time_share, b.time_share, 1e-12));
            assert!(close(a.oil_temperature, b.oil_temperature, 1e-12));
        }
    }
}

#[test]
fn a_load_spectrum_varying_the_torque_over_hours_is_read_on_the_master_model() {
    // A hand-made spectrum on the ZA stage: the speed stays in the master model, each load
    // case varies the defining torque and gives its hours (load_duration, in minutes for one).
    let mut model = rexs::read(&data("za-1x40-left.rexsj")).unwrap();
    let load = model
        .components
        .iter()
        .find(|c| {
            c.kind == "external_load"
                && c.attribute("defines_torque").map(|a| a.value.to_string()) == Some("true".into())
        })
        .map(|c| c.id)
        .expect("the stage's defining load");
    let unit = model
        .components
        .iter()
        .find(|c| c.kind == "gear_unit")
        .unwrap()
        .id;
    let case = |id: u64, torque: f64, duration: (f64, &str)| rexs::LoadCase {
        id,
        components: vec![
            rexs::Component {
                id: load,
                kind: "external_load".into(),
                name: String::new(),
                attributes: vec![rexs::Attribute {
                    id: "torque_around_u_axis".into(),
                    unit: "N m".into(),
                    value: rexs::Value::Float(torque),
                }],
            },
            rexs::Component {
                id: unit,
                kind: "gear_unit".into(),
                name: String::new(),
                attributes: vec![rexs::Attribute {
                    id: "load_duration".into(),
                    unit: duration.1.into(),
                    value: rexs::Value::Float(duration.0),
                }],
            },
        ],
    };
    model.load_cases = vec![case(1, 40.0, (300.0, "h")), case(2, 80.0, (6000.0, "min"))];
    let text = rexs::to_string(&model, Encoding::Json);
    let back = rexs::parse_bytes(text.as_bytes(), "spectrum.rexsj").unwrap();
    let imp = import::import(&back, None, "spectrum").unwrap();
    let gear = input::load_from_str(&imp.text).unwrap();
    let (_, single) = imported(&data("za-1x40-left.rexsj"));
    assert_eq!(gear.duty_cycle.len(), 2);
    // 300 h and 100 h: shares 0.75 and 0.25; the speed is the master model's.
    assert!(close(gear.duty_cycle[0].time_share, 0.75, 1e-12));
    assert!(close(gear.duty_cycle[1].time_share, 0.25, 1e-12));
    for b in &gear.duty_cycle {
        assert_eq!(b.conditions.worm_speed, single.conditions.worm_speed);
    }
    let member = |t: Torque| match t {
        Torque::Worm(_) => "worm",
        Torque::Wheel(_) => "wheel",
    };
    let magnitude = |t: Torque| match t {
        Torque::Worm(x) | Torque::Wheel(x) => x,
    };
    assert_eq!(
        member(gear.duty_cycle[0].conditions.torque),
        member(single.conditions.torque)
    );
    assert_eq!(magnitude(gear.duty_cycle[0].conditions.torque), 40.0);
    assert_eq!(magnitude(gear.duty_cycle[1].conditions.torque), 80.0);
    // A load case without its duration is refused, naming it.
    model.load_cases[1].components.pop();
    let err = import::import(&model, None, "spectrum")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("load case 2") && err.contains("load_duration_fraction"),
        "{err}"
    );
}
