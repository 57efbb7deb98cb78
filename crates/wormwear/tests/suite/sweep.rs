//! Design studies (`wormwear::sweep`): variants by dotted name, a failing variant recorded
//! while the others go on, resume of an interrupted sweep, and the runner's results against
//! physics (Hertz scaling of the pressure with the load).

use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use wormwear::input;
use wormwear::runner::LifeOverrides;
use wormwear::sweep::{
    distinct_bending_models, grid_variants, run, BaseAccess, Row, Sweep, Variant, VARIANT_FILE,
};

/// The design example, fast: no bending, 6 positions, a coarser flank grid.
fn fast_base() -> toml::Table {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/gear-1x40-design.toml"),
    )
    .unwrap();
    let mut base = input::parse_document(&text).unwrap();
    for (name, value) in [
        ("bending.model", toml::Value::from("none")),
        ("analysis.positions", toml::Value::from(6)),
        ("analysis.flank_cells_height", toml::Value::from(20)),
        ("analysis.flank_cells_face", toml::Value::from(30)),
    ] {
        input::set_dotted(&mut base, name, Some(value)).unwrap();
    }
    base
}

/// A 2 x 3 grid of torque x roughness whose roughness -1 um is invalid (2 failing variants).
fn torque_roughness_sweep() -> Sweep {
    let grid: toml::Table = toml::from_str(
        r#""conditions.worm_torque_nm" = [30.0, 120.0]
           lubricant.composite_roughness_um = [0.5, -1.0, 1.0]"#,
    )
    .unwrap();
    let (parameters, variants) = grid_variants(&grid).unwrap();
    let stages = ["ltca".to_string()];
    Sweep::new(
        "design (fast)".into(),
        fast_base(),
        parameters,
        variants,
        Some(&stages),
        LifeOverrides::default(),
    )
    .unwrap()
}

#[test]
fn a_grid_expands_every_combination_first_name_slowest() {
    let sweep = torque_roughness_sweep();
    assert_eq!(
        sweep.parameters,
        [
            "conditions.worm_torque_nm",
            "lubricant.composite_roughness_um"
        ]
    );
    let values: Vec<(f64, f64)> = sweep
        .variants
        .iter()
        .map(|v| {
            (
                v.values[0].1.as_float().unwrap(),
                v.values[1].1.as_float().unwrap(),
            )
        })
        .collect();
    assert_eq!(
        values,
        [
            (30.0, 0.5),
            (30.0, -1.0),
            (30.0, 1.0),
            (120.0, 0.5),
            (120.0, -1.0),
            (120.0, 1.0)
        ]
    );
    assert_eq!(sweep.variants[0].name, "v1");
}

#[test]
fn dotted_names_change_the_document_and_bad_ones_are_named() {
    let mut doc = fast_base();
    input::set_dotted(&mut doc, "conditions.worm_torque_nm", Some(50.into())).unwrap();
    let gear = input::load_document(&doc).unwrap();
    assert_eq!(gear.conditions.torque, input::Torque::Worm(50.0));
    // The unchanged document loads as the file it came from.
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/gear-1x40-design.toml"),
    )
    .unwrap();
    assert_eq!(
        input::load_document(&input::parse_document(&text).unwrap()).unwrap(),
        input::load_from_str(&text).unwrap()
    );
    // Through a value, an empty part, an unknown field, a value out of range.
    let err = input::set_dotted(&mut doc, "worm.profile.x", Some(1.into())).unwrap_err();
    assert!(err.to_string().contains("worm.profile is a value"), "{err}");
    let err = input::set_dotted(&mut doc, "worm..profile", Some(1.into())).unwrap_err();
    assert!(err.to_string().contains("worm..profile"), "{err}");
    input::set_dotted(&mut doc, "conditions.worm_torq_nm", Some(5.into())).unwrap();
    let err = input::load_document(&doc).unwrap_err().to_string();
    assert!(err.contains("worm_torq_nm"), "{err}");
    input::set_dotted(&mut doc, "conditions.worm_torq_nm", None).unwrap();
    input::set_dotted(&mut doc, "conditions.worm_torque_nm", Some((-5.0).into())).unwrap();
    let err = input::load_document(&doc).unwrap_err();
    assert_eq!(
        err.field_errors()[0].field,
        "conditions.worm_torque_nm",
        "{err}"
    );
}

#[test]
fn a_sweep_records_failing_variants_goes_on_and_resumes_where_it_stopped() {
    let sweep = torque_roughness_sweep();
    let dir = tempfile::tempdir().unwrap();
    // First run, interrupted: every variant after the first two events of the run stops.
    let events = AtomicUsize::new(0);
    let interrupt = || events.fetch_add(1, Ordering::SeqCst) >= 2;
    let rows = run(&sweep, dir.path(), &|_| {}, &interrupt).unwrap();
    assert_eq!(rows.len(), 6);
    let interrupted = rows
        .iter()
        .filter(|r| {
            r.error
                .as_deref()
                .is_some_and(|e| e.contains("interrupted"))
        })
        .count();
    assert!(interrupted >= 2, "{rows:#?}");
    // Run again: the variants that finished are reused, the others run; the invalid
    // roughness fails with its field named and the others go on.
    let reused = AtomicUsize::new(0);
    let progress = |p: wormwear::sweep::Progress| {
        if p.reused {
            reused.fetch_add(1, Ordering::SeqCst);
        }
    };
    let rows = run(&sweep, dir.path(), &progress, &|| false).unwrap();
    let ok_before = 6 - interrupted - 2;
    assert_eq!(reused.load(Ordering::SeqCst), ok_before);
    let failed: Vec<&Row> = rows.iter().filter(|r| !r.ok).collect();
    assert_eq!(failed.len(), 2, "{rows:#?}");
    for r in &failed {
        let e = r.error.as_deref().unwrap();
        assert!(e.contains("lubricant.composite_roughness_um"), "{e}");
        assert!(r.max_pressure_pa.is_none());
    }
    // A third run reuses all four, with the same rows; a changed variant file is run again.
    let again = run(&sweep, dir.path(), &|_| {}, &|| false).unwrap();
    assert_eq!(strip_times(&again), strip_times(&rows));
    let record = dir.path().join("variants/v1").join(VARIANT_FILE);
    let text = std::fs::read_to_string(&record).unwrap();
    std::fs::write(&record, text.replacen("\"ok\":true", "\"ok\":false", 1)).unwrap();
    let reused = AtomicUsize::new(0);
    let progress = |p: wormwear::sweep::Progress| {
        if p.reused {
            reused.fetch_add(1, Ordering::SeqCst);
        }
    };
    run(&sweep, dir.path(), &progress, &|| false).unwrap();
    assert_eq!(reused.load(Ordering::SeqCst), 3, "v1 tampered: run again");
    // The table and the page.
    let csv = std::fs::read_to_string(dir.path().join("sweep.csv")).unwrap();
    assert_eq!(csv.lines().count(), 7, "{csv}");
    assert!(csv.starts_with(
        "variant,conditions.worm_torque_nm,lubricant.composite_roughness_um,ok,max_pressure_pa"
    ));
    assert!(dir.path().join("sweep.html").is_file());
    assert!(dir.path().join("variants/v4/ltca_positions.csv").is_file());
    // Physics: in an elastic line contact the peak pressure grows as the square root of the
    // load, so four times the torque would give about twice v1's peak, above the bronze's
    // flow pressure (the wheel hardness, 1 GPa, MODEL §5.7): v4 stops at it, v1 stays below.
    let p = |name: &str| {
        rows.iter()
            .find(|r| r.variant == name)
            .unwrap()
            .max_pressure_pa
            .unwrap()
    };
    let flow = 1e9;
    assert!(
        p("v1") < flow && 2.0 * p("v1") > flow,
        "P_max v1 {}",
        p("v1")
    );
    assert!((p("v4") / flow - 1.0).abs() < 1e-9, "P_max v4 {}", p("v4"));
    // The roughness enters the loaded analysis through the friction (MODEL §5.2, §13): the
    // smoother flank (v1, 0.5 um) loses less, so its wheel carries a little more of the worm
    // torque.
    assert!(p("v1") > p("v3"), "{} vs {}", p("v1"), p("v3"));
}

fn strip_times(rows: &[Row]) -> Vec<Row> {
    rows.iter()
        .map(|r| Row {
            seconds: 0.0,
            ..r.clone()
        })
        .collect()
}

#[test]
fn sweep_files_give_their_errors_with_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let base = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/gear-1x40-design.toml");
    let write = |text: &str| {
        let path = dir.path().join("s.toml");
        std::fs::write(
            &path,
            format!("base = {:?}\n{text}", base.display().to_string()),
        )
        .unwrap();
        path
    };
    let cases = [
        (
            "[grid]\n\"conditions.worm_torque_nm\" = 5.0\n",
            "must be a list",
        ),
        ("[grid]\n", "names no parameter"),
        ("stages = [\"lcta\"]\n[grid]\na = [1]\n", "not a stage"),
        ("", "give the variants as [grid]"),
        (
            "[[cases]]\nname = \"a\"\n[[cases]]\nname = \"a\"\n",
            "two variants are named",
        ),
        ("[[cases]]\nname = \"../x\"\n", "a folder name"),
        ("tuning = 1\n[grid]\na = [1]\n", "unknown field"),
        // Life overrides out of range are refused when the sweep is read, not variant by
        // variant when it runs.
        (
            "cycles = -5\n[grid]\n\"conditions.worm_torque_nm\" = [60.0]\n",
            "cycles = -5: must be a number of cycles",
        ),
        (
            "cycles = 1e12\nstep_cycles = 1\n[grid]\n\"conditions.worm_torque_nm\" = [60.0]\n",
            "more than the 1e5 a run may take",
        ),
        // A life override where the stages run no life is refused, not ignored (the probe
        // of issue 38 found cycles = -5 accepted beside stages = ["ltca"]).
        (
            "stages = [\"ltca\"]\ncycles = -5\n[grid]\n\"conditions.worm_torque_nm\" = [60.0]\n",
            "cycles is a life override, but the stages (ltca) have no life",
        ),
    ];
    for (text, message) in cases {
        let err = Sweep::load_with(&write(text), BaseAccess::Anywhere)
            .unwrap_err()
            .to_string();
        assert!(err.contains(message), "{text}: {err}");
    }
    // A list of cases, with names.
    // The base lies outside the sweep file's folder: refused by default, read when allowed.
    let err = Sweep::load(&write("[grid]\n\"conditions.worm_torque_nm\" = [60.0]\n"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("outside the sweep file's directory"), "{err}");
    // A base that cannot be read is named as the sweep file wrote it.
    for base in ["missing.toml", "."] {
        let path = dir.path().join("b.toml");
        std::fs::write(&path, format!("base = {base:?}\n[grid]\na = [1]\n")).unwrap();
        let err = Sweep::load(&path).unwrap_err().to_string();
        assert!(
            err.starts_with(&format!("base = {base:?}: cannot read")),
            "{err}"
        );
    }
    let sweep = Sweep::load_with(&write(
        "[[cases]]\nname = \"light\"\nconditions.worm_torque_nm = 20.0\n[[cases]]\n\"conditions.worm_speed_rpm\" = 750.0\n",
    ), BaseAccess::Anywhere)
    .unwrap();
    assert_eq!(
        sweep.variants,
        [
            Variant {
                name: "light".into(),
                values: vec![("conditions.worm_torque_nm".into(), 20.0.into())]
            },
            Variant {
                name: "c2".into(),
                values: vec![("conditions.worm_speed_rpm".into(), 750.0.into())]
            }
        ]
    );
    assert_eq!(
        sweep.parameters,
        ["conditions.worm_torque_nm", "conditions.worm_speed_rpm"]
    );
}

/// The FE bending models a sweep builds before its variants run side by side: one per cache
/// key (the torque does not enter it, the hob does), none without FE bending or without a
/// loaded stage, none for invalid variants.
#[test]
fn a_sweep_builds_each_bending_model_once_before_its_variants() {
    let mut base = fast_base();
    input::set_dotted(&mut base, "bending.model", Some("fe".into())).unwrap();
    let grid: toml::Table = toml::from_str(
        r#""conditions.worm_torque_nm" = [30.0, 60.0, -1.0]
           "hob.tip_radius_mm" = [31.95, 31.5]"#,
    )
    .unwrap();
    let (parameters, variants) = grid_variants(&grid).unwrap();
    let sweep_of = |base: &toml::Table, stages: &[&str]| {
        let stages: Vec<String> = stages.iter().map(|s| s.to_string()).collect();
        let (p, v) = (parameters.clone(), variants.clone());
        Sweep::new(
            "fe".into(),
            base.clone(),
            p,
            v,
            Some(&stages),
            LifeOverrides::default(),
        )
        .unwrap()
    };
    let all = |_: &Variant| true;
    let models = distinct_bending_models(&sweep_of(&base, &["ltca"]), &all);
    assert_eq!(models.len(), 2, "two hobs, any torque");
    assert_ne!(models[0].hob, models[1].hob);
    let only_first = |v: &Variant| v.name == "v1";
    assert_eq!(
        distinct_bending_models(&sweep_of(&base, &["ltca"]), &only_first).len(),
        1
    );
    assert!(distinct_bending_models(&sweep_of(&base, &["tca"]), &all).is_empty());
    assert!(distinct_bending_models(&sweep_of(&fast_base(), &["ltca"]), &all).is_empty());
}

/// Lives overlap each state's writing with the next state's analysis on the thread pool
/// (issue 55): a sweep with more lives than the pool has threads holds every thread with a
/// life, and must still finish (a life waiting for its analysis keeps its pool working), each
/// life as it runs alone (the same rows on the global pool as on one thread, and as a sweep of
/// that variant alone).
#[test]
fn lives_in_a_sweep_holding_every_pool_thread_finish_as_they_run_alone() {
    let count = rayon::current_num_threads() + 1;
    let torques: Vec<String> = (0..count)
        .map(|k| format!("{:.1}", 30.0 + 30.0 * k as f64 / count as f64))
        .collect();
    let grid: toml::Table = toml::from_str(&format!(
        r#""conditions.worm_torque_nm" = [{}]"#,
        torques.join(", ")
    ))
    .unwrap();
    let (parameters, variants) = grid_variants(&grid).unwrap();
    let stages = ["wear".to_string()];
    let overrides = LifeOverrides {
        cycles: Some(3e4),
        step_cycles: Some(1e4),
        ..Default::default()
    };
    let sweep = |variants: Vec<Variant>| {
        Sweep::new(
            "design (fast lives)".into(),
            fast_base(),
            parameters.clone(),
            variants,
            Some(&stages),
            overrides,
        )
        .unwrap()
    };
    let rows_of = |sweep: &Sweep| {
        let dir = tempfile::tempdir().unwrap();
        strip_times(&run(sweep, dir.path(), &|_| {}, &|| false).unwrap())
    };
    let on_one_thread = |sweep: &Sweep| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        pool.install(|| rows_of(sweep))
    };
    let all = sweep(variants.clone());
    let rows = rows_of(&all);
    assert_eq!(rows.len(), count);
    for r in &rows {
        assert!(r.ok, "{r:#?}");
        assert!(r.max_wear_end_m.unwrap() > 0.0, "{r:#?}");
        assert_eq!(r.life_cycles, Some(3e4), "{r:#?}");
    }
    assert_eq!(on_one_thread(&all), rows);
    let last = count - 1;
    let alone = on_one_thread(&sweep(variants[last..].to_vec()));
    assert_eq!(alone[0].max_wear_end_m, rows[last].max_wear_end_m);
    assert_eq!(
        alone[0].backlash_increase_end_m,
        rows[last].backlash_increase_end_m
    );
}
