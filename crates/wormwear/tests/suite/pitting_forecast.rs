//! Pitting forecast (`wear::forecast`): pits from the fatigue damage of every flank node, and the
//! phases a forecast finds from them. The cell law's own checks (a constant-pressure cell pits
//! at the curve's life; a cell worn faster than it is damaged never pits) are the unit tests of
//! `wormwear::pitting`.

use crate::common;
use crate::common::Bench;
use wormwear::input::{GearSet, Phase, Pitting};
use wormwear::wear;

fn design() -> GearSet {
    common::example("gear-1x40-design.toml")
}

/// The design case on a coarser grid (10 positions, 24 x 30 cells): these tests check the
/// life loop's logic, not the model's convergence, and run many lives.
fn coarse() -> GearSet {
    let mut g = design();
    g.analysis.positions = 10;
    g.analysis.flank_cells_height = 24;
    g.analysis.flank_cells_face = 30;
    g
}

/// A forecast of the design case over 200 000 cycles in 40 000-cycle steps, on a weaker
/// bronze (the pressure-life curve through 340 MPa at 11e6 cycles instead of 425 MPa): its
/// edge cells, at the flow pressure (1 GPa) unworn, spend their lives within it (with the
/// default curve the largest damage reaches 0.49).
fn forecast_plan() -> wear::WearPlan {
    wear::WearPlan {
        step: wear::StepControl::Cycles(40_000.0),
        pitting: Pitting::Forecast,
        pitting_onset_share: 0.005,
        endurance: wormwear::input::Endurance {
            reference_pressure: 340e6,
            ..wormwear::input::Endurance::DEFAULT
        },
        ..wear::WearPlan::with_life(200_000.0)
    }
}

#[test]
fn a_forecast_run_again_with_the_phases_it_found_as_a_schedule_gives_the_same_records() {
    let bench = Bench::new(&coarse());
    let plan = forecast_plan();
    let forecast = bench.simulate(&plan, None, &mut |_| Ok(())).unwrap();
    for r in &forecast.records {
        eprintln!(
            "{:>3} {:>10.1} {:<8} pitted {:.4} damage {:.3} backlash {:.2} um",
            r.step,
            r.cycles,
            r.phase,
            r.pitted_area_fraction,
            r.max_damage,
            r.backlash_increase_m * 1e6
        );
    }
    let pitting: Vec<_> = forecast
        .found_phases
        .iter()
        .filter(|p| matches!(p, Phase::Pitting { .. }))
        .collect();
    assert!(!pitting.is_empty(), "no pitting phase found");
    let r = &forecast.records;
    // Each phase found: the pits cut at its start, no wear through it (the backlash flat).
    let spans = wear::forecast::phase_spans(r);
    let first = spans.iter().find(|s| s.kind == "pitting").unwrap();
    assert!(first.pitted_share_end >= 0.005, "{first:?}");
    let inside: Vec<_> = r
        .iter()
        .filter(|x| x.cycles >= first.start_cycles && x.cycles <= first.end_cycles)
        .collect();
    let after_cut = inside[1];
    assert!(after_cut.pitted_area_fraction > inside[0].pitted_area_fraction);
    assert_eq!(inside.last().unwrap().backlash_m, after_cut.backlash_m);
    assert_eq!(r.last().unwrap().cycles, 200_000.0);

    // The same life with the phases found imposed as a schedule, pits from the damage.
    let schedule = wear::WearPlan {
        pitting: Pitting::Damage,
        phases: forecast.found_phases.clone(),
        ..plan.clone()
    };
    let again = bench.simulate(&schedule, None, &mut |_| Ok(())).unwrap();
    assert_eq!(again.records.len(), forecast.records.len());
    // The same to round-off: a step to a phase's end is end - cycles in the schedule and the
    // cycles to the onset in the forecast, which differ in the last bit.
    for (a, b) in again.records.iter().zip(&forecast.records) {
        let (a, b) = (serde_json::json!(a), serde_json::json!(b));
        assert_close(&a, &b, &format!("state {}", a["step"]));
    }
    assert_close(
        &serde_json::json!(again.removal.values),
        &serde_json::json!(forecast.removal.values),
        "removal",
    );
    // Damage is dimensionless (1: a pit): to 1e-9 absolute.
    for (k, (a, b)) in again.damage.iter().zip(&forecast.damage).enumerate() {
        assert!((a - b).abs() < 1e-9, "damage[{k}]: {a} != {b}");
    }
}

/// Equal JSON values, numbers to 1e-9 relative or 1e-15 absolute: the records' smallest
/// quantities (the plastic indentation, ~4e-8 m) come from differences of gaps solved to the
/// solver's tolerance, whose round-off (here 6e-17 m) is a femtometre at most; no record's
/// quantity is read at that scale (lengths in m, angles in rad, damage dimensionless; the
/// damage has its own 1e-9 absolute check below).
fn assert_close(a: &serde_json::Value, b: &serde_json::Value, at: &str) {
    use serde_json::Value;
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            assert!(
                (x - y).abs() <= 1e-9 * x.abs().max(y.abs()) + 1e-15,
                "{at}: {x} != {y}"
            );
        }
        (Value::Array(x), Value::Array(y)) => {
            assert_eq!(x.len(), y.len(), "{at}");
            for (k, (x, y)) in x.iter().zip(y).enumerate() {
                assert_close(x, y, &format!("{at}[{k}]"));
            }
        }
        (Value::Object(x), Value::Object(y)) => {
            assert_eq!(x.len(), y.len(), "{at}");
            for (k, v) in x {
                assert_close(v, &y[k], &format!("{at}.{k}"));
            }
        }
        _ => assert_eq!(a, b, "{at}"),
    }
}

#[test]
fn a_forecast_killed_after_a_state_and_resumed_ends_as_the_uninterrupted_one() {
    // The checkpoint holds the damage and the phases found: resume after the first pitting
    // phase has started, with damage on the flank, and compare exactly.
    let bench = Bench::new(&coarse());
    let plan = forecast_plan();
    let straight = bench.simulate(&plan, None, &mut |_| Ok(())).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let write = |writer: &mut wormwear::output::wear::LifeWriter, view: &wear::StepView| {
        writer
            .write_state(&bench.g, &bench.geo, &bench.tca, &plan, view, false)
            .map(|_| ())
            .map_err(|e| wear::WearError::Output(e.to_string()))
    };
    let mut writer = wormwear::output::wear::LifeWriter::new(dir.path());
    let interrupted = bench.simulate(&plan, None, &mut |view| {
        write(&mut writer, view)?;
        let state = view.state;
        if !state.found_phases.is_empty() && state.damage.iter().any(|&d| d > 0.0) {
            return Err(wear::WearError::Output("killed".into()));
        }
        Ok(())
    });
    assert!(interrupted.is_err());
    let saved = wormwear::output::wear::read_checkpoint(dir.path())
        .unwrap()
        .unwrap();
    assert!(!saved.found_phases.is_empty());
    assert!(saved.damage.iter().any(|&d| d > 0.0));
    assert!(saved.records.len() < straight.records.len());
    let mut writer = wormwear::output::wear::LifeWriter::new(dir.path());
    let resumed = bench
        .simulate(&plan, Some(saved), &mut |view| write(&mut writer, view))
        .unwrap();
    assert_eq!(resumed.records, straight.records);
    assert_eq!(resumed.removal, straight.removal);
    assert_eq!(resumed.damage, straight.damage);
    assert_eq!(resumed.found_phases, straight.found_phases);
    // The files: the phases as they happened and the schedule found in summary.json, the
    // damage maps and the damage column of the node table.
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap())
            .unwrap();
    let wear = &summary["wear"];
    assert_eq!(wear["pitting"], "forecast");
    let phases = wear["phases"].as_array().unwrap();
    assert_eq!(phases[0]["kind"], "wear");
    assert!(phases.iter().any(|p| p["kind"] == "pitting"));
    assert_eq!(
        phases.last().unwrap()["end_cycles"].as_f64(),
        Some(200_000.0)
    );
    assert_eq!(
        wear["found_phases"].as_array().unwrap().len(),
        straight.found_phases.len()
    );
    assert!(dir.path().join("wear_damage_map.svg").exists());
    let nodes = std::fs::read_to_string(dir.path().join("wear_map.csv")).unwrap();
    let header: Vec<&str> = nodes.lines().next().unwrap().split(',').collect();
    assert!(
        header.contains(&"damage") && header.contains(&"plastic_set_m"),
        "{header:?}"
    );
    // The nodes' equivalent pressure, each the largest of its cells': over the flank their
    // largest is the pattern's largest, which the last record carries.
    let column = header
        .iter()
        .position(|h| *h == "equivalent_pressure_pa")
        .unwrap();
    let largest = nodes
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(column).unwrap().parse::<f64>().unwrap())
        .fold(0.0, f64::max);
    let record = straight.records.last().unwrap().equivalent_pressure_max_pa;
    assert!(largest > 0.0);
    assert!(
        (largest / record - 1.0).abs() < 1e-9,
        "{largest} against {record}"
    );
}

/// MODEL §10 with a forecast: a backlash curve the program generated with a known K and life
/// factor (the "measurement") is fitted from another K and the fitted curve (life factor 1);
/// both come back (about 45 lives).
#[test]
#[ignore = "heavy validation: scripts/validate-heavy runs it"]
fn k_and_the_life_factor_are_recovered_from_a_forecast_backlash_curve() {
    let bench = Bench::new(&coarse());
    let plan = forecast_plan();
    let (k_true, f_true) = (1.6e-8, 0.55);
    let mut runs = 0;
    let mut simulate = |k: f64, f: f64| {
        runs += 1;
        let mut b = Bench {
            g: bench.g.clone(),
            geo: bench.geo.clone(),
            tca: bench.tca.clone(),
        };
        b.g.wheel_material.wear_coefficient = k;
        let mut p = plan.clone();
        p.endurance.life_factor = f;
        let r = b.simulate(&p, None, &mut |_| Ok(())).map(|s| s.records);
        if let Ok(r) = &r {
            eprintln!(
                "life {runs}: K {k:.5e} f {f:.5} first pitting {:?} backlash {:.3} um",
                wormwear::calibration::first_pitting(r),
                r.last().unwrap().backlash_increase_m * 1e6
            );
        }
        r
    };
    let truth = simulate(k_true, f_true).unwrap();
    let spans = wear::forecast::phase_spans(&truth);
    assert!(
        spans.iter().any(|s| s.kind == "pitting"),
        "the measured curve has a pitting phase"
    );
    let measured: Vec<(f64, f64)> = truth
        .iter()
        .skip(1)
        .map(|r| (r.cycles, r.backlash_increase_m))
        .collect();
    let (fit, _) =
        wormwear::calibration::fit_with_life_factor(&measured, 2.4e-8, &mut simulate).unwrap();
    let f = fit.life_factor.unwrap();
    println!(
        "K {:.5e} (true {k_true:e}), life factor {f:.5} (true {f_true}), residual {:.2e}, {runs} lives",
        fit.k, fit.relative_rms
    );
    assert!((fit.k / k_true - 1.0).abs() < 1e-3, "{}", fit.k);
    assert!((f / f_true - 1.0).abs() < 1e-3, "{f}");
    assert!(fit.relative_rms < 1e-4, "{}", fit.relative_rms);
    assert!(runs < 80, "{runs} lives");
}

/// A forecast on a bronze that barely wears (wear coefficient 1e-300) reaches its life: the
/// cycles to pit of a node are those without wear, not 0 (the rounded logarithm gave 0, and
/// the forecast stepped 0 cycles for ever; issue 38's probe), and its first pitting phase
/// starts where the damage without wear reaches the onset.
#[test]
fn a_forecast_without_wear_advances_to_its_life() {
    let mut g = coarse();
    g.wheel_material.wear_coefficient = 1e-300;
    let bench = Bench::new(&g);
    let plan = forecast_plan();
    let start = std::time::Instant::now();
    let life = bench.simulate(&plan, None, &mut |_| Ok(())).unwrap();
    let r = &life.records;
    assert_eq!(r.last().unwrap().cycles, 200_000.0);
    assert!(r.len() < 20, "{} states", r.len());
    assert!(r.windows(2).all(|w| w[1].cycles >= w[0].cycles));
    assert!(start.elapsed().as_secs() < 300);
}

#[test]
fn the_damage_warning_counts_a_row_of_damaged_nodes_as_the_area_between_its_neighbours() {
    // A row of nodes at damage 1.5 (height index 3 of the coarse grid, every face node). The
    // area it stands for is half of each cell row beside it, rows 2 and 3 (a node's dual
    // area): computed here from the cell areas, the forecast's onset share. Counting every
    // cell that touches a damaged node would take both rows whole, twice that.
    // (evenly spaced rows: a row of the band at the worm-tip trace holds a quarter of that)
    let mut g = coarse();
    g.analysis.tip_trace_refinement = 0;
    let geo = wormwear::geometry::Geometry::build(&g).unwrap();
    let tca = wormwear::kinematics::analyse(&g, &geo).unwrap();
    let wf = geo.wheel_flank(tca.loaded_flank);
    let ni = wf.cells_height;
    let shares = wear::forecast::node_shares(wf);
    assert!((shares.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    let mut state = wear::WearState::new(wf);
    state.damage = vec![0.0; wf.nodes.len()];
    for j in 0..=wf.cells_face {
        state.damage[j * (ni + 1) + 3] = 1.5;
    }
    let rows: f64 = (0..wf.cells_face)
        .flat_map(|j| [j * ni + 2, j * ni + 3])
        .filter(|&c| wf.active[c])
        .map(|c| wf.cell_area[c])
        .sum();
    let expected = 100.0 * 0.5 * rows / wf.active_area();
    let warning = |state: &wear::WearState, onset: f64| {
        state
            .warnings(wf, onset, &wormwear::input::Endurance::DEFAULT)
            .into_iter()
            .find(|w| w.contains("fatigue damage of 1"))
            .expect("a damage warning")
    };
    let at_two = warning(&state, 0.02);
    let nodes = format!("{} flank nodes", wf.cells_face + 1);
    let share = format!("about {expected:.2} % of the active flank");
    assert!(at_two.contains(&nodes), "{at_two}");
    assert!(at_two.contains(&share), "{at_two} (expected {share})");
    assert!(at_two.contains("largest 1.500"), "{at_two}");
    // The row (about 2.5 % of the flank) is first pitting at the default 2 %, and below a
    // forecast's onset share of 5 %: the warning reads the life's own onset.
    assert!(expected > 2.0 && expected < 5.0, "{expected}");
    assert!(at_two.contains("first pitting (2 % of the flank, A_p10, or more)"));
    let at_five = warning(&state, 0.05);
    assert!(
        at_five
            .contains("less than first pitting (5.00 % of the flank, wear.pitting_onset_percent)"),
        "{at_five}"
    );
    // No records: no note on the curve's data. A state whose largest p_eq lies above the
    // curve's highest tested pressure (709 MPa at 0.6e6 cycles, MODEL §8) adds it; one within
    // does not.
    assert!(!at_two.contains("extrapolates"), "{at_two}");
    let record = |cycles: f64, p: f64| wear::StepRecord {
        cycles,
        equivalent_pressure_max_pa: p,
        ..Default::default()
    };
    state.records = vec![record(0.0, 650e6), record(2e4, 1080e6), record(4e4, 700e6)];
    let noted = warning(&state, 0.02);
    assert!(
        noted.ends_with(
            "; the damage of nodes loaded above 709 MPa, the curve's highest tested pressure, \
             extrapolates it (the life's largest p_eq 1080 MPa, at 20 000 cycles)"
        ),
        "{noted}"
    );
    state.records = vec![record(0.0, 650e6), record(2e4, 700e6)];
    assert_eq!(warning(&state, 0.02), at_two);
}

#[test]
fn the_interpolated_node_reading_damages_no_node_more_than_the_largest_of_its_cells() {
    // One 40 000-cycle step of the coarse design case with the weak bronze: the same loaded
    // analysis and wear, each node's stress read from its cells as the largest or as their
    // mean (the interpolation). The mean is at most the largest, and the damage grows with the
    // stress at the same wear and layer: no node is more damaged interpolated, and at the
    // sharp tip's trace, where the pattern falls off across a row, some node is less.
    let bench = Bench::new(&coarse());
    let mut plan = forecast_plan();
    plan.life_cycles = 40_000.0;
    let damage = |reading| {
        let plan = wear::WearPlan {
            damage_node_reading: reading,
            ..plan.clone()
        };
        bench.simulate(&plan, None, &mut |_| Ok(())).unwrap().damage
    };
    let largest = damage(wormwear::input::NodeReading::Largest);
    let interpolated = damage(wormwear::input::NodeReading::Interpolated);
    assert_eq!(largest.len(), interpolated.len());
    assert!(largest.iter().any(|&d| d > 0.0));
    for (k, (l, i)) in largest.iter().zip(&interpolated).enumerate() {
        assert!(*i <= *l * (1.0 + 1e-12), "node {k}: {i} > {l}");
    }
    assert!(largest.iter().zip(&interpolated).any(|(l, i)| *i < 0.9 * l));
}
