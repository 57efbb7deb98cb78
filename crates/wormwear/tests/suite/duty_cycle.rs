//! Duty cycles (MODEL §14): a spectrum of identical bins is the one operating point, Miner's
//! sum against a hand computation from each bin's equivalent pressures, the wear of a frozen
//! flank linear in the shares, and the spectrum's file input.

use crate::common::example;
use wormwear::input::{self, BendingKind, GearSet, StepControl, WearPlan};
use wormwear::{Request, Source, Stage};

/// The design gear without bending (fast), its `[conditions]` replaced by the `[[duty_cycle]]`
/// tables of `bins` (TOML text).
fn design_with(bins: &str) -> GearSet {
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../examples/gear-1x40-design.toml"),
    )
    .unwrap();
    let conditions = "[conditions]\nworm_torque_nm = 60.0\nworm_speed_rpm = 1500.0\n";
    assert!(text.contains(conditions));
    let text = text
        .replace(conditions, bins)
        .replace("[bending]\nmodel = \"fe\"", "[bending]\nmodel = \"none\"");
    input::load_from_str(&text).unwrap()
}

/// A bin's TOML table.
fn bin(torque_nm: f64, rpm: f64, share: f64) -> String {
    format!(
        "[[duty_cycle]]\nworm_torque_nm = {torque_nm:?}\nworm_speed_rpm = {rpm:?}\ntime_share = {share:?}\n\n"
    )
}

/// A life of fixed steps (`steps` of `step` cycles) with the loaded analysis, its safety table
/// and, with a spectrum, the spectrum's figures.
fn run_life(g: &GearSet, step: f64, steps: usize) -> wormwear::Results {
    let plan = WearPlan {
        step: StepControl::Cycles(step),
        max_substep_removal: 0.0,
        ..WearPlan::with_life(step * steps as f64)
    };
    let request = Request::new([Stage::Ltca, Stage::Wear]).with_life(plan);
    wormwear::run(g, Source::default(), request, &mut |_| Ok(())).unwrap()
}

/// Relative difference of two figures (0 when both are 0).
fn rel(a: f64, b: f64) -> f64 {
    if a == b {
        0.0
    } else {
        (a - b).abs() / a.abs().max(b.abs())
    }
}

#[test]
fn a_spectrum_of_two_identical_bins_is_the_one_operating_point() {
    let mut one = example("gear-1x40-design.toml");
    one.bending.kind = BendingKind::None;
    let two = design_with(&(bin(60.0, 1500.0, 0.5) + &bin(60.0, 1500.0, 0.5)));
    assert!(two.has_spectrum() && !one.has_spectrum());
    let (a, b) = (run_life(&one, 40_000.0, 2), run_life(&two, 40_000.0, 2));
    let (ra, rb) = (
        &a.life.as_ref().unwrap().end.records,
        &b.life.as_ref().unwrap().end.records,
    );
    assert_eq!(ra.len(), rb.len());
    for (x, y) in ra.iter().zip(rb) {
        // The wear is the shares' sum 0.5 d + 0.5 d = d: exactly the one point's.
        assert_eq!(x.cycles, y.cycles);
        assert_eq!(x.max_wear_m, y.max_wear_m, "step {}", x.step);
        assert_eq!(x.worn_volume_m3, y.worn_volume_m3, "step {}", x.step);
        assert_eq!(x.backlash_m, y.backlash_m, "step {}", x.step);
        assert_eq!(x.max_pressure_pa, y.max_pressure_pa, "step {}", x.step);
        assert_eq!(x.te_p2p_rad, y.te_p2p_rad, "step {}", x.step);
        assert_eq!(x.friction, y.friction, "step {}", x.step);
        // Miner's sum of two halves: the damage to round-off.
        assert!(rel(x.max_damage, y.max_damage) < 1e-12, "step {}", x.step);
        assert!(x.bins.is_empty() && y.bins.len() == 2);
        for z in &y.bins {
            assert_eq!(z.cycle_share, 0.5);
            assert_eq!(z.max_pressure_pa, x.max_pressure_pa);
            assert_eq!(z.friction, x.friction);
        }
    }
    // The safety table: every row's value the same (S_H's damage-equivalent pressure of the
    // two halves to round-off), and the required cycles counted at the same speed.
    let (ta, tb) = (a.safety.unwrap(), b.safety.unwrap());
    assert_eq!(ta.required_cycles, tb.required_cycles);
    for (x, y) in ta.rows.iter().zip(&tb.rows) {
        assert_eq!(x.symbol, y.symbol);
        match (x.value, y.value) {
            (Some(p), Some(q)) => assert!(rel(p, q) < 1e-12, "{}: {p} vs {q}", x.symbol),
            (p, q) => assert_eq!(p, q, "{}", x.symbol),
        }
    }
    let spectrum = b.spectrum.unwrap();
    let thermal = a.thermal.unwrap();
    assert!(
        rel(
            spectrum.total_efficiency,
            thermal.efficiency.total_efficiency
        ) < 1e-12
    );
    for z in &spectrum.bins {
        assert!((z.wear_share - 0.5).abs() < 1e-12 && (z.damage_share - 0.5).abs() < 1e-12);
    }
}

/// The life on the pressure–life curve N(p) = f N_ref (p / p_ref)^(-1 / k), written out.
fn curve_life(curve: &input::Endurance, p: f64) -> f64 {
    curve.life_factor
        * curve.reference_cycles
        * (p / curve.reference_pressure).powf(-1.0 / curve.exponent)
}

#[test]
fn miners_sum_of_a_spectrum_matches_a_hand_computation() {
    let g = design_with(&(bin(30.0, 1500.0, 0.6) + &bin(60.0, 1000.0, 0.4)));
    let results = wormwear::run(
        &g,
        Source::default(),
        Request::new([Stage::Ltca]),
        &mut |_| Ok(()),
    )
    .unwrap();
    let spectrum = results.spectrum.unwrap();
    // The shares of the wheel's cycles: time share x speed, normalised.
    let (c1, c2) = (
        0.6 * 1500.0 / (0.6 * 1500.0 + 0.4 * 1000.0),
        0.4 * 1000.0 / (0.6 * 1500.0 + 0.4 * 1000.0),
    );
    assert!((spectrum.bins[0].cycle_share - c1).abs() < 1e-12);
    assert!((spectrum.bins[1].cycle_share - c2).abs() < 1e-12);
    assert_eq!(spectrum.largest_load_bin, 2);
    assert!((spectrum.mean_worm_speed_rpm - 1300.0).abs() < 1e-9);
    // Each bin analysed alone as a gear of one operating point: its equivalent pressures, per
    // cell of the flank grid, and their p_eq,2%, the figure S_H reads for one point.
    let alone = |torque: f64, rpm: f64| {
        let mut one = example("gear-1x40-design.toml");
        one.bending.kind = BendingKind::None;
        one.conditions.torque = input::Torque::Worm(torque);
        one.conditions.worm_speed = rpm * std::f64::consts::PI / 30.0;
        let request = Request::new([Stage::Ltca]);
        let r = wormwear::run(&one, Source::default(), request, &mut |_| Ok(())).unwrap();
        let flank = r.tca.as_ref().unwrap().loaded_flank;
        let wf = r.geometry.wheel_flank(flank).clone();
        (r.ltca.unwrap(), wf)
    };
    let ((l1, wf), (l2, _)) = (alone(30.0, 1500.0), alone(60.0, 1000.0));
    let (p1, p2) = (
        l1.equivalent_pressure_first_pitting,
        l2.equivalent_pressure_first_pitting,
    );
    assert_eq!(spectrum.bins[0].equivalent_pressure_first_pitting_pa, p1);
    assert_eq!(spectrum.bins[1].equivalent_pressure_first_pitting_pa, p2);
    assert_eq!(
        spectrum.bins[0].equivalent_pressure_max_pa,
        l1.equivalent_pressure_max
    );
    let curve = input::Endurance::DEFAULT;
    // The bins' damage shares: Miner's over their p_eq,2%; each bin's life at its own.
    let (d1, d2) = (c1 / curve_life(&curve, p1), c2 / curve_life(&curve, p2));
    assert!(rel(spectrum.bins[0].damage_share, d1 / (d1 + d2)) < 1e-12);
    assert!(rel(spectrum.bins[1].damage_share, d2 / (d1 + d2)) < 1e-12);
    // The spectrum's: at each cell the constant pressure with the life of Miner's sum of the
    // two bins' cells, then the value whose larger cells hold 2 % of the active area (by hand:
    // the cells sorted by that pressure, their areas added from the top).
    let inverse = |rate: f64| {
        curve.reference_pressure
            * (1.0 / rate / (curve.life_factor * curve.reference_cycles)).powf(-curve.exponent)
    };
    let mut cells: Vec<(f64, f64)> = (0..wf.cell_area.len())
        .filter(|&c| wf.active[c])
        .map(|c| {
            let rate = c1 / curve_life(&curve, l1.equivalent_pattern[c])
                + c2 / curve_life(&curve, l2.equivalent_pattern[c]);
            let p = if rate > 0.0 { inverse(rate) } else { 0.0 };
            (p, wf.cell_area[c])
        })
        .collect();
    cells.sort_by(|a, b| b.0.total_cmp(&a.0));
    let total: f64 = cells.iter().map(|c| c.1).sum();
    let mut above = 0.0;
    let p = cells
        .iter()
        .find(|c| {
            above += c.1;
            above >= 0.02 * total * (1.0 - 1e-12)
        })
        .unwrap()
        .0;
    assert!(
        rel(spectrum.equivalent_pressure_pa, p) < 1e-12,
        "{} vs {p}",
        spectrum.equivalent_pressure_pa
    );
    let life = spectrum.pitting_life_cycles.unwrap();
    assert!(rel(curve_life(&curve, p), life) < 1e-12, "{life}");
    // The largest cell's beside it, on the flow pressure's plateau of the sharp tip edge.
    assert!(spectrum.equivalent_pressure_max_pa > p);
    // S_H reads it at the required cycles, counted at the time-weighted mean speed.
    let table = results.safety.unwrap();
    let row = table.rows.iter().find(|r| r.symbol == "S_H").unwrap();
    assert_eq!(row.value, Some(p * 1e-6));
    let hours = g.rating.safety.required_life_hours.unwrap();
    let cycles = hours * 3600.0 * 1300.0 / 60.0 / 40.0;
    assert!(rel(table.required_cycles.unwrap(), cycles) < 1e-12);
}

#[test]
fn the_wear_of_a_frozen_flank_is_linear_in_the_shares() {
    // One fixed step of 20 000 cycles without sub-steps: the flank is frozen over it, so the
    // removal is the step's cycles times the shares' sum of each bin's wear of a cycle; bins at
    // one speed run their time shares of the cycles.
    let removal = |g: &GearSet| {
        let r = run_life(g, 20_000.0, 1);
        r.life.unwrap().end.removal.values
    };
    let light = removal(&design_with(&bin(30.0, 1500.0, 1.0)));
    let heavy = removal(&design_with(&bin(70.0, 1500.0, 1.0)));
    let peak = light.iter().chain(&heavy).copied().fold(0.0, f64::max);
    assert!(peak > 0.0);
    for s in [0.25, 0.6] {
        let mixed = removal(&design_with(
            &(bin(30.0, 1500.0, s) + &bin(70.0, 1500.0, 1.0 - s)),
        ));
        let worst = mixed
            .iter()
            .zip(light.iter().zip(&heavy))
            .map(|(m, (a, b))| (m - (s * a + (1.0 - s) * b)).abs())
            .fold(0.0, f64::max);
        assert!(
            worst <= 1e-12 * peak,
            "share {s}: off by {worst:e} m of {peak:e}"
        );
    }
}

#[test]
fn a_one_bin_spectrum_is_the_gear_of_its_conditions() {
    let one = example("gear-1x40-design.toml");
    let mut spectrum = design_with(&bin(60.0, 1500.0, 1.0));
    spectrum.bending.kind = one.bending.kind;
    assert_eq!(spectrum, one);
    let hours = design_with(
        "[[duty_cycle]]\nworm_torque_nm = 60.0\nworm_speed_rpm = 1500.0\nhours = 300.0\n",
    );
    assert!(!hours.has_spectrum());
    assert_eq!(hours.conditions, one.conditions);
}

#[test]
fn the_example_spectrum_has_its_three_bins() {
    let g = example("gear-1x40-duty-cycle.toml");
    assert_eq!(g.duty_cycle.len(), 3);
    let shares: Vec<f64> = g.duty_cycle.iter().map(|b| b.time_share).collect();
    assert_eq!(shares, vec![0.5, 0.3, 0.2]);
    // The gear's own conditions are the bin of the largest load (90 N m at 500 rpm).
    assert_eq!(g.conditions.torque, input::Torque::Worm(90.0));
    assert!(g.warnings.is_empty(), "{:?}", g.warnings);
}

/// The error message of a design file whose `[conditions]` is replaced by `bins`.
fn refusal(bins: &str, keep_conditions: bool) -> String {
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../examples/gear-1x40-design.toml"),
    )
    .unwrap();
    let conditions = "[conditions]\nworm_torque_nm = 60.0\nworm_speed_rpm = 1500.0\n";
    let text = match keep_conditions {
        true => text + "\n" + bins,
        false => text.replace(conditions, bins),
    };
    match input::load_from_str(&text) {
        Ok(_) => panic!("accepted:\n{bins}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn a_bad_spectrum_is_refused_naming_the_field() {
    let cases: Vec<(String, bool, Vec<&str>)> = vec![
        (bin(30.0, 1500.0, 0.5) + &bin(60.0, 1000.0, 0.4), false, vec!["duty_cycle.time_share", "sum to 0.9", "must sum to 1"]),
        (bin(30.0, 1500.0, 0.5), true, vec!["duty_cycle", "[conditions]", "not both"]),
        (bin(30.0, 1500.0, 0.5) + "[[duty_cycle]]\nworm_torque_nm = 60.0\nworm_speed_rpm = 1000.0\nhours = 20.0\n", false, vec!["duty_cycle[2]", "time_share", "hours"]),
        (bin(30.0, 1500.0, 0.5) + &bin(-60.0, 1000.0, 0.5), false, vec!["duty_cycle[2].worm_torque_nm", "-60"]),
        (bin(30.0, 0.0, 0.5) + &bin(60.0, 1000.0, 0.5), false, vec!["duty_cycle[1].worm_speed_rpm", "rpm"]),
        (bin(30.0, 1500.0, 0.0) + &bin(60.0, 1000.0, 1.0), false, vec!["duty_cycle[1].time_share", "> 0"]),
        ("[[duty_cycle]]\nworm_torque_nm = 30.0\nwheel_torque_nm = 900.0\nworm_speed_rpm = 1500.0\ntime_share = 1.0\n".into(), false, vec!["duty_cycle[1].wheel_torque_nm", "not both"]),
        ("[[duty_cycle]]\nworm_speed_rpm = 1500.0\ntime_share = 1.0\n".into(), false, vec!["duty_cycle[1].worm_torque_nm", "(missing)"]),
        (String::new(), false, vec!["conditions", "(missing)", "[[duty_cycle]]"]),
        (bin(30.0, 1500.0, 0.5) + &bin(60.0, 1000.0, 0.5 + 1e-8), false, vec!["duty_cycle.time_share", "must sum to 1"]),
        ("[[duty_cycle]]\nworm_torque_nm = 30.0\nworm_speed_rpm = 1500.0\nhours = 0.0\n\n[[duty_cycle]]\nworm_torque_nm = 60.0\nworm_speed_rpm = 1000.0\nhours = 10.0\n".into(), false, vec!["duty_cycle[1].hours", "> 0"]),
        ("[[duty_cycle]]\nworm_torque_nm = 30.0\nworm_speed_rpm = 1500.0\nhours = 5.0\n\n[[duty_cycle]]\nworm_torque_nm = 60.0\nworm_speed_rpm = 1000.0\nhours = -5.0\n".into(), false, vec!["duty_cycle[2].hours", "-5"]),
        (bin(30.0, 1500.0, 1.0).replace("time_share", "oil_temperature_c = 300.0\ntime_share"), false, vec!["duty_cycle[1].oil_temperature_c", "300"]),
        ((0..51).map(|_| bin(30.0, 1500.0, 1.0 / 51.0)).collect(), false, vec!["duty_cycle", "51 bins", "at most 50"]),
    ];
    let cases = cases.into_iter().chain([(
        bin(30.0, 1500.0, 0.5) + "[[duty_cycle]]\nworm_torque_nm = 60.0\ntime_share = 0.5\n",
        false,
        vec!["duty_cycle[2] is missing the key `worm_speed_rpm`"],
    )]);
    for (bins, keep, parts) in cases {
        let message = refusal(&bins, keep);
        for p in parts {
            assert!(
                message.contains(p),
                "{p:?} not in:\n{message}\nfor:\n{bins}"
            );
        }
    }
    // An empty spectrum (a key before the first table).
    let design = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../examples/gear-1x40-design.toml"),
    )
    .unwrap()
    .replace(
        "[conditions]\nworm_torque_nm = 60.0\nworm_speed_rpm = 1500.0\n",
        "",
    );
    let message = input::load_from_str(&format!("duty_cycle = []\n{design}"))
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("duty_cycle = (no bins)") && message.contains("empty spectrum"),
        "{message}"
    );
    // A bin's own oil temperature with the heat balance, which finds it.
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../examples/gear-1x40-design.toml"),
    )
    .unwrap()
    .replace(
        "temperature_c = 59.85",
        "temperature_c = 59.85\ntemperature = \"balance\"",
    )
    .replace(
        "[conditions]\nworm_torque_nm = 60.0\nworm_speed_rpm = 1500.0\n",
        &bin(30.0, 1500.0, 1.0).replace("time_share", "oil_temperature_c = 70.0\ntime_share"),
    );
    let message = input::load_from_str(&text).unwrap_err().to_string();
    assert!(
        message.contains("duty_cycle[1].oil_temperature_c") && message.contains("balance"),
        "{message}"
    );
}
