//! The workspace's build: the Python module's build (`maturin develop` in `scripts/test-all`)
//! must reuse what `cargo test --workspace` compiled. Cargo reuses a dependency only when it is
//! built with the same features; a dependency whose features differ between the two builds is
//! compiled again with everything above it (faer, the wormwear library): about two minutes of
//! the test command on the 2-core box, which the house's 15-minute budget does not hold.

use crate::common::skipped;
use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

/// Each package's enabled features as `cargo tree` resolves them for `args`: "name version"
/// -> "feature,feature", or None where cargo cannot be run here (then the check is skipped).
fn resolved_features(args: &[&str]) -> Option<BTreeMap<String, String>> {
    const TEST: &str =
        "workspace::the_python_module_builds_its_dependencies_with_the_test_builds_features";
    let Some(cargo) = std::env::var_os("CARGO") else {
        skipped(TEST, "not run by cargo (no CARGO in the environment)");
        return None;
    };
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let out = Command::new(cargo)
        .current_dir(root)
        .args([
            "tree",
            "--offline",
            "--locked",
            "--prefix",
            "none",
            "-f",
            "{p}|{f}",
        ])
        .args(args)
        .output();
    let Ok(out) = out else {
        skipped(TEST, "cargo could not be started");
        return None;
    };
    if !out.status.success() {
        let reason = format!(
            "cargo tree failed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        skipped(TEST, reason.trim());
        return None;
    }
    let text = String::from_utf8(out.stdout).unwrap();
    let mut features = BTreeMap::new();
    for line in text.lines() {
        // (blank lines separate the workspace members' trees)
        // (a repeated package's line ends in " (*)")
        let line = line.trim_end().trim_end_matches("(*)");
        let Some((package, enabled)) = line.split_once('|') else {
            continue;
        };
        // "name vX.Y.Z (path)" -> "name vX.Y.Z"
        let package: Vec<&str> = package.split_whitespace().take(2).collect();
        features.insert(package.join(" "), enabled.trim().to_string());
    }
    Some(features)
}

#[test]
fn the_python_module_builds_its_dependencies_with_the_test_builds_features() {
    let Some(test_build) = resolved_features(&["--workspace", "-e", "normal,build,dev"]) else {
        return;
    };
    let Some(module) = resolved_features(&["-p", "wormwear-python", "-e", "normal,build"]) else {
        return;
    };
    let differences: Vec<String> = module
        .iter()
        .filter_map(|(package, features)| {
            let tested = test_build.get(package)?;
            (tested != features)
                .then(|| format!("{package}: test build [{tested}], Python module [{features}]"))
        })
        .collect();
    assert!(
        differences.is_empty(),
        "name these features in python/Cargo.toml, or maturin develop compiles the library \
         again:\n{}",
        differences.join("\n")
    );
    // The check can fail: the module's own dependencies appear in both resolutions.
    assert!(module.keys().any(|p| p.starts_with("faer ")));
    assert!(test_build.keys().any(|p| p.starts_with("faer ")));
}
