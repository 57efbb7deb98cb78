//! The published model is the default (MODEL §12 g-m), each refinement an option: tests of
//! every restored choice against an independent truth, and of every option on and off.

use crate::common;

use crate::common::example;
use std::f64::consts::PI;
use wormwear::geometry::Geometry;
use wormwear::input::{FilmLoad, GearSet, Phase, PitDepth};
use wormwear::kinematics::{self, Tca};
use wormwear::ltca::{self, LtcaSettings};
use wormwear::wear::{self, WearPlan, WearState};

/// The design example without bending (the choices under test do not depend on it).
fn design() -> GearSet {
    let mut g = example("gear-1x40-design.toml");
    g.bending.kind = wormwear::input::BendingKind::None;
    g
}

/// Effective modulus E* of the Hertz line contact, from the materials: 1/E* = sum (1-v^2)/E.
fn effective_modulus(g: &GearSet) -> f64 {
    let (w, h) = (&g.worm_material, &g.wheel_material);
    1.0 / ((1.0 - w.poisson_ratio.powi(2)) / w.youngs_modulus
        + (1.0 - h.poisson_ratio.powi(2)) / h.youngs_modulus)
}

fn prepared(g: &GearSet) -> (Geometry, Tca) {
    let geo = Geometry::build(g).unwrap();
    let tca = kinematics::analyse(g, &geo).unwrap();
    (geo, tca)
}

/// Runs `plan` from `state` without bending, returning the end state and every view's
/// (cycle wear, map flag) in order.
fn life(
    g: &GearSet,
    geo: &Geometry,
    tca: &Tca,
    plan: &WearPlan,
    state: WearState,
) -> (WearState, Vec<(wear::CycleWear, bool)>) {
    let mut views = Vec::new();
    let end = wear::simulate(
        g,
        geo,
        tca,
        &LtcaSettings::from_gear(g),
        None,
        plan,
        state,
        &mut |v| {
            views.push((v.cycle.clone(), v.map));
            Ok(())
        },
    )
    .unwrap();
    (end, views)
}

/// A life of one cycle from the unworn flank: its first record is the unworn state's.
fn unworn_life(g: &GearSet, geo: &Geometry, tca: &Tca) -> WearState {
    let wf = geo.wheel_flank(tca.loaded_flank);
    life(g, geo, tca, &WearPlan::with_life(1.0), WearState::new(wf)).0
}

#[test]
fn the_examples_have_no_relief_and_the_plastic_limit_at_the_hardness() {
    // MODEL §12 i: sharp edges; the contact bounded by the bronze's flow pressure, the
    // wheel's hardness (MODEL §5.7). The defaults and the examples agree; the options, when
    // given, are in force.
    for name in common::EXAMPLES {
        let g = example(name);
        assert_eq!(g.worm.tip_relief.amount, 0.0, "{name}");
        assert_eq!(g.wheel.edge_relief.amount, 0.0, "{name}");
        assert_eq!(
            g.analysis.contact,
            wormwear::input::ContactLaw::Plastic {
                flow_pressure: g.wheel_material.hardness
            },
            "{name}"
        );
        if let Some(w) = &g.wear {
            assert_eq!(w.film_load, FilmLoad::LoadedAnalysis, "{name}");
            assert_eq!(w.pit_depth, PitDepth::Hertz, "{name}");
        }
    }
    let g = design();
    let (geo, tca) = prepared(&g);
    let l = ltca::analyse(&g, &geo, &tca).unwrap();
    assert!(l
        .positions
        .iter()
        .all(|p| p.cells.iter().all(|c| c.relief == 0.0)));
}

#[test]
fn tip_relief_and_pressure_cap_are_options_that_act() {
    // On: the worm's tip relief and the wheel's edge relief ease the cells next to the edges
    // and lower the edge pressures; the cap bounds every pressure. Off (default): neither.
    // The elastic law, where the sharp edges' pressures are the elastic ones.
    let mut g = design();
    g.analysis.contact = wormwear::input::ContactLaw::Elastic;
    let (geo, tca) = prepared(&g);
    let sharp = ltca::analyse(&g, &geo, &tca).unwrap();
    let mut relieved_gear = g.clone();
    relieved_gear.worm.tip_relief.amount = 20e-6;
    relieved_gear.wheel.edge_relief.amount = 20e-6;
    let (geo_r, tca_r) = prepared(&relieved_gear);
    let relieved = ltca::analyse(&relieved_gear, &geo_r, &tca_r).unwrap();
    let eased = relieved
        .positions
        .iter()
        .flat_map(|p| p.cells.iter())
        .filter(|c| c.relief > 0.0)
        .count();
    eprintln!(
        "P_max sharp {:.0} MPa, with 20 um tip and edge reliefs {:.0} MPa ({eased} eased cells)",
        sharp.max_pressure / 1e6,
        relieved.max_pressure / 1e6
    );
    assert!(eased > 0);
    assert!(relieved.max_pressure < 0.9 * sharp.max_pressure);
    // The cap: below the sharp maximum, every pressure at or under it; the load is carried.
    let cap = 800e6;
    assert!(sharp.max_pressure > cap);
    let mut s = LtcaSettings::from_gear(&g);
    s.flow_pressure = cap;
    let capped = ltca::analyse_with(&g, &geo, &tca, &s, None).unwrap();
    let top = capped
        .positions
        .iter()
        .flat_map(|p| p.pressure.iter().copied())
        .fold(0.0, f64::max);
    assert!(top <= cap * (1.0 + 1e-9), "{top:e}");
    for p in &capped.positions {
        assert!(p.torque_residual < 1e-6);
    }
}

#[test]
fn pits_are_cut_0_78_hertz_half_widths_deep() {
    // MODEL §12 g: a = sqrt(4 w R / (pi E*)) with the local line load and relative radius of
    // the passage; the pits of a phase starting at cycle 0 take exactly 0.78 a off every node
    // above the limit. The loaded-band option cuts 0.78 x the band's half-width instead.
    let g = design();
    let (geo, tca) = prepared(&g);
    let wf = geo.wheel_flank(tca.loaded_flank);
    let e_star = effective_modulus(&g);
    let limit = 600e6;
    let mut plan = WearPlan::with_life(1000.0);
    plan.phases = vec![Phase::Pitting {
        until: 1000.0,
        pressure_limit: Some(limit),
        margin: 0.0,
    }];
    for rule in [PitDepth::Hertz, PitDepth::LoadedBand] {
        plan.pit_depth = rule;
        let (end, views) = life(&g, &geo, &tca, &plan, WearState::new(wf));
        let cw = &views[0].0;
        let mut pitted = 0;
        let mut worst: f64 = 0.0;
        for k in 0..wf.nodes.len() {
            let (w, r) = (cw.line_load.values[k], cw.contact_radius.values[k]);
            let a = if w > 0.0 && r > 0.0 {
                (4.0 * w * r / (PI * e_star)).sqrt()
            } else {
                0.0
            };
            if rule == PitDepth::Hertz {
                assert!((cw.hertz_half_width.values[k] - a).abs() <= 1e-12 * a.max(1e-12));
            }
            let expected = 0.78
                * match rule {
                    PitDepth::Hertz => a,
                    PitDepth::LoadedBand => cw.half_width.values[k],
                };
            let cut = end.removal.values[k];
            if end.pitted[k] {
                pitted += 1;
                worst = worst.max((cut - expected).abs() / expected);
            } else {
                assert_eq!(cut, 0.0);
            }
        }
        let deepest = end.removal.max();
        eprintln!(
            "{rule:?}: {pitted} pitted nodes above {:.0} MPa, deepest pit {:.1} um, worst relative error {worst:.1e}",
            limit / 1e6,
            deepest * 1e6
        );
        assert!(pitted > 10);
        assert!(worst < 1e-9);
        // A fraction of a millimetre, as observed (MODEL §12 g).
        assert!(deepest > 50e-6 && deepest < 1e-3);
    }
}

#[test]
fn the_film_uses_the_line_load_and_the_floor_is_an_option() {
    // MODEL §12 h: w from the loaded analysis. The refinement floors w at the Hertz load of the
    // band's peak pressure: a larger load, so nowhere a thicker film and somewhere (where the
    // band is cut by an edge or peaked) a thinner one, hence at least as much wear.
    let g = design();
    let (geo, tca) = prepared(&g);
    let l = ltca::analyse(&g, &geo, &tca).unwrap();
    let plain = wear::per_cycle(&g, &geo, &tca, &l, FilmLoad::LoadedAnalysis);
    let floored = wear::per_cycle(&g, &geo, &tca, &l, FilmLoad::HertzPeakFloor);
    let mut thinner = 0;
    for k in 0..plain.lambda.values.len() {
        let (a, b) = (plain.lambda.values[k], floored.lambda.values[k]);
        if a.is_finite() {
            assert!(b <= a * (1.0 + 1e-12), "node {k}: {b} > {a}");
            if b < 0.98 * a {
                thinner += 1;
            }
            assert!(floored.depth.values[k] >= plain.depth.values[k] * (1.0 - 1e-12));
        }
    }
    eprintln!(
        "film thinner with the floor at {thinner} nodes; max wear per cycle {:.3e} -> {:.3e} m",
        plain.depth.max(),
        floored.depth.max()
    );
    assert!(thinner > 0);
}

#[test]
fn rank_first_pitting_is_evaluated_with_the_model_mean_pressure() {
    // MODEL §12 k: N_LI = 1e6 (1 + 0.86 ln(3 v/3)) exp(28.078 - 4.666 ln(520 P_mean/520)) with
    // the loaded pattern's P_mean and sigma_Hlim = 520 MPa; out of range: None.
    let g = design();
    assert_eq!(g.wheel_material.pitting_limit, 520e6);
    let (geo, tca) = prepared(&g);
    let end = unworn_life(&g, &geo, &tca);
    let r = &end.records[0];
    let d1 = 2.0 * g.worm.reference_radius;
    let gamma = (g.worm.lead() / (PI * d1)).atan();
    let v = d1 / 2.0 * g.conditions.worm_speed / gamma.cos();
    let p = r.mean_pressure_pa / 1e6;
    let expected = 1e6
        * (1.0 + 0.86 * (3.0 * v / 3.0).ln())
        * (28.078 - 4.666 * (520.0 * p / 520.0).ln()).exp();
    let got = r.n_li_model_cycles.unwrap();
    eprintln!("P_mean {p:.1} MPa, v_gm {v:.3} m/s: N_LI {got:.4e} cycles");
    assert!((got / expected - 1.0).abs() < 1e-12);
    assert_eq!(
        wormwear::rating::rank_first_pitting_cycles(0.2, p, 520.0),
        None
    );
    assert_eq!(
        wormwear::rating::rank_first_pitting_cycles(v, 0.0, 520.0),
        None
    );
}

#[test]
fn the_records_carry_the_pressure_exceeded_on_the_area_of_first_pitting() {
    // MODEL §8.1: p_eq,2% (what S_H reads) per state. The unworn state's is the loaded
    // analysis's own, reached by the life's runner and by the analysis alone; it lies below
    // the largest p_eq (2 % of the flank is more than one cell) and above zero.
    let g = design();
    let (geo, tca) = prepared(&g);
    let end = unworn_life(&g, &geo, &tca);
    let r = &end.records[0];
    let alone = ltca::analyse_with(&g, &geo, &tca, &LtcaSettings::from_gear(&g), None).unwrap();
    eprintln!(
        "p_eq,2% {:.1} MPa (analysis alone {:.1}), largest p_eq {:.1} MPa",
        r.equivalent_pressure_first_pitting_pa / 1e6,
        alone.equivalent_pressure_first_pitting / 1e6,
        r.equivalent_pressure_max_pa / 1e6
    );
    let p = r.equivalent_pressure_first_pitting_pa;
    assert!((p / alone.equivalent_pressure_first_pitting - 1.0).abs() < 1e-9);
    assert!(p > 0.0 && p < r.equivalent_pressure_max_pa);
}

#[test]
fn the_area_reading_of_first_pitting_is_the_miner_sum_of_the_states_area_pressure() {
    // MODEL §8.1: the forecast reads p_eq,2%. Each wear step adds its cycles over the life of
    // the starting state's p_eq,2% on the pressure–life curve (written here from the curve's
    // own power law); a pitting phase holds the sum; first pitting is where the sum reaches 1,
    // within the step that crosses it. A curve shifted so that it is crossed in a short life.
    let g = design();
    let (geo, tca) = prepared(&g);
    let wf = geo.wheel_flank(tca.loaded_flank);
    let mut plan = WearPlan::with_life(40_000.0);
    plan.step = wormwear::wear::StepControl::Cycles(10_000.0);
    plan.phases = vec![
        Phase::Wear { until: 20_000.0 },
        Phase::Pitting {
            until: 30_000.0,
            pressure_limit: Some(1e12),
            margin: 0.0,
        },
        Phase::Wear { until: 40_000.0 },
    ];
    let (p_ref, n_ref, b) = (800e6, 15_000.0, 0.176);
    plan.endurance = wormwear::input::Endurance {
        reference_pressure: p_ref,
        reference_cycles: n_ref,
        exponent: b,
        life_factor: 1.0,
    };
    let (end, _) = life(&g, &geo, &tca, &plan, WearState::new(wf));
    let records = &end.records;
    let life_at = |p: f64| n_ref * (p / p_ref).powf(-1.0 / b);
    let (mut sum, mut crossing) = (0.0, None);
    for w in records.windows(2) {
        let (a, r) = (&w[0], &w[1]);
        let rate = match a.phase.as_str() {
            "pitting" => 0.0,
            _ => 1.0 / life_at(a.equivalent_pressure_first_pitting_pa),
        };
        if sum < 1.0 && sum + (r.cycles - a.cycles) * rate >= 1.0 {
            crossing = Some(a.cycles + (1.0 - sum) / rate);
        }
        sum += (r.cycles - a.cycles) * rate;
        eprintln!(
            "{:>6.0} cycles, {}: p_eq,2% {:.1} MPa, sum {:.4} (record {:.4})",
            r.cycles,
            r.phase,
            a.equivalent_pressure_first_pitting_pa / 1e6,
            sum,
            r.area_damage
        );
        assert!((r.area_damage - sum).abs() <= 1e-12 * sum.max(1.0));
        if a.phase == "pitting" {
            assert_eq!(r.area_damage, a.area_damage);
        }
    }
    assert_eq!(records[0].area_damage, 0.0);
    assert!(records.iter().any(|r| r.phase == "pitting"));
    let first = wormwear::wear::forecast::area_first_pitting_cycles(records, &plan.endurance);
    let (got, expected) = (first.expect("not crossed"), crossing.unwrap());
    assert!(
        (got / expected - 1.0).abs() < 1e-12,
        "{got} against {expected}"
    );
    // A duty cycle: each bin at its share of the cycles, from its own p_eq,2%.
    let bin = |share: f64, p: f64| wormwear::wear::spectrum::BinRecord {
        cycle_share: share,
        worm_torque_nm: 0.0,
        wheel_torque_nm: 0.0,
        max_pressure_pa: 0.0,
        pressure_patch_max_pa: 0.0,
        equivalent_pressure_max_pa: 0.0,
        equivalent_pressure_first_pitting_pa: p,
        max_wear_per_cycle_m: 0.0,
        worn_volume_per_cycle_m3: 0.0,
        friction: Default::default(),
    };
    let mut duty = records[1].clone();
    duty.phase = "wear".into();
    duty.bins = vec![bin(0.25, 900e6), bin(0.75, 500e6)];
    let rate = wormwear::wear::forecast::area_damage_rate(&duty, &plan.endurance);
    let expected = 0.25 / life_at(900e6) + 0.75 / life_at(500e6);
    assert!(
        (rate / expected - 1.0).abs() < 1e-12,
        "{rate} against {expected}"
    );
    // Not crossed: none.
    plan.endurance.reference_cycles = 1e9;
    let records: Vec<_> = records
        .iter()
        .map(|r| wormwear::wear::StepRecord {
            area_damage: r.area_damage * n_ref / 1e9,
            ..r.clone()
        })
        .collect();
    assert_eq!(
        wormwear::wear::forecast::area_first_pitting_cycles(&records, &plan.endurance),
        None
    );
}

#[test]
fn a_uniform_angular_recession_is_all_rigid_lag() {
    // MODEL §12 j: a flank worn by the same angle everywhere (normal depth delta x lever)
    // lags the wheel by delta and changes nothing else: the TE drops by delta at every
    // position, the rigid lag is delta, the TE relative to it is the unworn TE.
    let g = design();
    let (geo, tca) = prepared(&g);
    let wf = geo.wheel_flank(tca.loaded_flank);
    let unworn = unworn_life(&g, &geo, &tca);
    let delta = 2e-5;
    let mut state = WearState::new(wf);
    for (k, n) in wf.nodes.iter().enumerate() {
        let lever = kinematics::GapEvaluator::lever(&n.position(), &n.normal_vec());
        state.removal.values[k] = delta * lever;
    }
    state.cycles = 1.0;
    let (worn, _) = life(&g, &geo, &tca, &WearPlan::with_life(1.0), state);
    let (a, b) = (&unworn.records[0], &worn.records[0]);
    eprintln!(
        "TE mean {:.9e} -> {:.9e} rad; lag {:.9e}; relative {:.9e}; p2p {:.6e} / {:.6e}",
        a.te_mean_rad,
        b.te_mean_rad,
        b.rigid_lag_rad,
        b.te_mean_relative_rad,
        a.te_p2p_rad,
        b.te_p2p_relative_rad
    );
    // Exact but for the linear interpolation of the nodes' removal at the cells (delta x lever
    // is smooth: second order in the 0.27 mm node spacing) and the solver's tolerance.
    assert!((b.rigid_lag_rad / delta - 1.0).abs() < 1e-9);
    assert!((b.te_mean_rad - (a.te_mean_rad - delta)).abs() < 1e-4 * delta);
    assert!((b.te_mean_relative_rad - a.te_mean_rad).abs() < 1e-5 * a.te_mean_rad.abs());
    assert!((b.te_p2p_relative_rad - a.te_p2p_rad).abs() < 1e-4 * a.te_p2p_rad);
    assert_eq!(a.rigid_lag_rad, 0.0);
    assert_eq!(a.te_mean_relative_rad, a.te_mean_rad);
}

#[test]
fn the_patch_pressure_converges_where_the_maximum_does_not() {
    // At the worm's sharp tip edge the local maximum grows like the square root of the
    // refinement across the line (an integrable edge singularity); the mean over the stated
    // patch (0.5 mm across by 1 mm along) does not. The elastic law: the plastic one bounds
    // the edge (`the_plastic_limit_makes_the_peaks_mesh_converged`). Frictionless pressures
    // (the contact alone: with the transmitted torque the friction at the singular edge moves
    // the patch by 3.7 % between 11 and 41 cells, the torque by less).
    let mut g = design();
    g.analysis.torque_balance = wormwear::input::TorqueBalance::Frictionless;
    let (geo, tca) = prepared(&g);
    let run = |columns: usize| {
        let mut s = LtcaSettings::from_gear(&g);
        s.columns = columns;
        s.flow_pressure = f64::INFINITY;
        ltca::analyse_with(&g, &geo, &tca, &s, None).unwrap()
    };
    let (coarse, fine) = (run(11), run(41));
    let raw = fine.max_pressure / coarse.max_pressure;
    let patch = fine.pressure_patch_max / coarse.pressure_patch_max;
    eprintln!(
        "11 -> 41 cells across: P_max {:.0} -> {:.0} MPa (x{raw:.3}), patch {:.0} -> {:.0} MPa (x{patch:.3})",
        coarse.max_pressure / 1e6,
        fine.max_pressure / 1e6,
        coarse.pressure_patch_max / 1e6,
        fine.pressure_patch_max / 1e6
    );
    assert!(raw > 1.5, "the edge is not singular here: {raw}");
    assert!((patch - 1.0).abs() < 0.03, "{patch}");
    // The patch mean is a mean: never above the cells' maximum, and it is the mean of the
    // pressure over an area when the patch sees a uniform field (checked on a flat band).
    assert!(
        coarse.pressure_patch_max
            <= coarse
                .positions
                .iter()
                .map(|p| p.max_pressure)
                .fold(0.0, f64::max)
                * (1.0 + 1e-12)
    );
}

#[test]
fn the_patch_pressure_is_never_above_the_flow_pressure_it_averages() {
    // Issue 58: at 200 N m the plastic band's cells (at the flow pressure, 1 GPa) differ in
    // width from column to column; placed at column x own width across the line they overlapped,
    // and a patch mean reached 1.0022 GPa with no cell above 1 GPa.
    let mut g = design();
    g.conditions.torque = wormwear::input::Torque::Worm(200.0);
    let (geo, tca) = prepared(&g);
    let l = ltca::analyse(&g, &geo, &tca).unwrap();
    let largest = l
        .positions
        .iter()
        .map(|p| p.max_pressure)
        .fold(0.0, f64::max);
    let flow = g.wheel_material.hardness;
    assert_eq!(largest, flow, "the flow pressure binds at 200 N m");
    assert!(
        l.pressure_patch_max <= largest,
        "{} Pa over cells of at most {largest} Pa",
        l.pressure_patch_max
    );
    // The band at the flow pressure is wider than the patch: its mean is the flow pressure.
    assert!(
        l.pressure_patch_max > (1.0 - 1e-9) * flow,
        "{}",
        l.pressure_patch_max
    );
}

#[test]
fn map_cycles_stop_the_life_there_and_mark_the_states() {
    let g = design();
    let (geo, tca) = prepared(&g);
    let wf = geo.wheel_flank(tca.loaded_flank);
    let mut plan = WearPlan::with_life(30_000.0);
    plan.step = wear::StepControl::Cycles(10_000.0);
    plan.max_substep_removal = 0.0;
    plan.map_cycles = Some(vec![0.0, 5_000.0, 12_000.0]);
    let (end, views) = life(&g, &geo, &tca, &plan, WearState::new(wf));
    let cycles: Vec<f64> = end.records.iter().map(|r| r.cycles).collect();
    let maps: Vec<f64> = end
        .records
        .iter()
        .zip(&views)
        .filter(|(_, v)| v.1)
        .map(|(r, _)| r.cycles)
        .collect();
    assert_eq!(cycles, vec![0.0, 5_000.0, 12_000.0, 22_000.0, 30_000.0]);
    assert_eq!(maps, vec![0.0, 5_000.0, 12_000.0]);
    // Both counts: records and loaded analyses (no guard split here: one per record).
    assert_eq!(end.records.last().unwrap().loaded_analyses, 5);
    // With the stability guard a step costs a loaded analysis per sub-step.
    plan.max_substep_removal = 2e-6;
    let (end, _) = life(&g, &geo, &tca, &plan, WearState::new(wf));
    let substeps: usize = end.records.iter().skip(1).map(|r| r.substeps).sum();
    assert!(substeps > 4);
    assert_eq!(end.records.last().unwrap().loaded_analyses, 1 + substeps);
}

#[test]
fn a_life_warns_where_its_area_reading_rests_on_the_curve_beyond_its_data() {
    // MODEL §8: the CuSn12 curve's points reach 709 MPa (0.6e6 cycles). The design gear's
    // running-in starts with p_eq,2% near the flow pressure (its sharp edges, MODEL §5.7): the
    // first steps' lives on the curve are extrapolated, and the warning gives their share of
    // the area sum, recomputed here from the records with the curve's power law. A curve
    // whose data reach beyond every state's p_eq,2% gives none.
    let g = design();
    let (geo, tca) = prepared(&g);
    let wf = geo.wheel_flank(tca.loaded_flank);
    let mut plan = WearPlan::with_life(20_000.0);
    plan.step = wormwear::wear::StepControl::Cycles(10_000.0);
    let (end, _) = life(&g, &geo, &tca, &plan, WearState::new(wf));
    let records = &end.records;
    let life_at = |p: f64| 11e6 * (p / 425e6).powf(-1.0 / 0.176);
    let (mut sum, mut beyond) = (0.0, 0.0);
    for w in records.windows(2) {
        let p = w[0].equivalent_pressure_first_pitting_pa;
        let damage = (w[1].cycles - w[0].cycles) / life_at(p);
        sum += damage;
        if life_at(p) < 0.6e6 {
            beyond += damage;
        }
        eprintln!("{:>6.0} cycles: p_eq,2% {:.1} MPa", w[0].cycles, p / 1e6);
    }
    assert!(
        beyond > 0.0,
        "the unworn p_eq,2% within the data: {records:?}"
    );
    let said = |curve: &wormwear::input::Endurance| -> Option<String> {
        let w = end.warnings(wf, plan.pitting_onset_share, curve);
        w.into_iter().find(|w| w.contains("extrapolates the curve"))
    };
    let text = said(&plan.endurance).expect("a warning");
    eprintln!("{text}");
    assert!(
        text.starts_with(&format!(
            "pitting: {:.0} % of the area reading's Miner sum ({:.3} at 20 000 cycles)",
            100.0 * beyond / sum,
            sum
        )),
        "{text}: {beyond} of {sum}"
    );
    assert!(
        text.contains("against 709 MPa at its shortest tested life"),
        "{text}"
    );
    // Where the flank at or above each state's p_eq,2% lay mostly on the edges, the life says
    // in how many states (the sharp design gear: its worm tip's trace and face ends).
    let on_edges = records
        .iter()
        .filter(|r| r.first_pitting_edge_share > wormwear::ltca::EDGE_READING_SHARE)
        .count();
    assert!(on_edges > 0, "{records:?}");
    let edges = end.warnings(wf, plan.pitting_onset_share, &plan.endurance);
    let edges = edges
        .iter()
        .find(|w| w.contains("lay on the flank's edges"));
    let prefix = format!(
        "pitting: in {on_edges} of the life's {} states,",
        records.len()
    );
    assert!(edges.is_some_and(|w| w.starts_with(&prefix)), "{edges:?}");
    let higher = wormwear::input::Endurance {
        reference_pressure: 1500e6,
        ..plan.endurance
    };
    assert_eq!(said(&higher), None);
}
