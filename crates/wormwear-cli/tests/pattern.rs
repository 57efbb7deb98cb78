//! `wormwear pattern` end to end: its files, the best gear file a gear file again, and bad
//! targets and bounds refused by name with exit code 2.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_wormwear"))
}

fn design() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/gear-1x40-design.toml")
}

fn pattern(dir: &Path, args: &[&str]) -> Output {
    bin()
        .arg("pattern")
        .arg(design())
        .arg("-o")
        .arg(dir)
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn pattern_writes_the_best_gear_file_its_search_and_the_patterns_before_and_after() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("p");
    let out = pattern(
        &dir,
        &[
            "--target",
            "centre_across_face=0.6",
            "--vary",
            "cutting.inclination_deg=-0.3:0.3",
            "--evaluations",
            "8",
        ],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("cutting.inclination_deg"), "{stdout}");
    for f in ["gear.toml", "pattern.json", "search.csv"] {
        assert!(dir.join(f).is_file(), "{f} missing");
    }
    for side in ["before", "after"] {
        for f in ["summary.json", "tca_pattern.svg", "tca_pattern.csv"] {
            assert!(dir.join(side).join(f).is_file(), "{side}/{f} missing");
        }
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("pattern.json")).unwrap()).unwrap();
    let evaluations = summary["evaluations"].as_u64().unwrap();
    assert!((1..=8).contains(&evaluations), "{evaluations}");
    let csv = std::fs::read_to_string(dir.join("search.csv")).unwrap();
    assert_eq!(csv.lines().count() as u64, evaluations + 1);
    let (start, best) = (
        &summary["start"]["objective"],
        &summary["best"]["objective"],
    );
    assert!(best.as_f64().unwrap() <= start.as_f64().unwrap());
    // The after/ analysis is of the best gear file: its pattern is the best one found.
    let after: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("after/summary.json")).unwrap())
            .unwrap();
    assert_eq!(
        after["tca"]["pattern_shape"]["centre_across_face"],
        summary["best"]["shape"]["centre_across_face"]
    );
    // The best gear file keeps the base's comments and is a valid gear file.
    let gear = std::fs::read_to_string(dir.join("gear.toml")).unwrap();
    assert!(gear.contains("# Reference gear 1"), "comments lost");
    assert!(gear.contains("wormwear pattern"));
    let check = bin()
        .arg("check")
        .arg(dir.join("gear.toml"))
        .output()
        .unwrap();
    assert!(
        check.status.success(),
        "{}",
        String::from_utf8_lossy(&check.stderr)
    );
}

#[test]
fn a_bad_target_or_bound_exits_2_naming_it() {
    let tmp = tempfile::tempdir().unwrap();
    let cases: [(&[&str], &str); 3] = [
        (&["--target", "centre=0.6"], "allowed centre_across_face"),
        (
            &[
                "--target",
                "centre_across_face=0.6",
                "--vary",
                "cutting.centre_distance_mm=125:130",
            ],
            "at its max 130",
        ),
        (
            &[
                "--target",
                "centre_across_face=0.6",
                "--vary",
                "cutting.centre_distanse_mm=124:126",
            ],
            "cutting.centre_distance_mm",
        ),
    ];
    for (k, (args, named)) in cases.iter().enumerate() {
        let out = pattern(&tmp.path().join(k.to_string()), args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(named), "{args:?}: {stderr}");
    }
}
