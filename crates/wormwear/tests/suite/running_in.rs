//! Running-in of the roughness (MODEL §6.1): the law's limits; a worn node's film ratio over its
//! own run-in roughness; a run-in flank rubs less; the constant-roughness limit gives the
//! published model's records byte for byte; bad inputs are refused by name.

use crate::common;
use crate::common::{example, Bench};
use wormwear::friction::MeshContacts;
use wormwear::geometry::FlankField;
use wormwear::input::{self, BendingKind, FilmLoad, GearSet, RunningIn, TorqueBalance};
use wormwear::ltca::{self, FlankChange, LtcaSettings};
use wormwear::wear;

/// The design gear without bending, its lubricant running in to `run_in_um` over `depth_um`
/// (None: no running-in).
fn design(running_in: Option<(f64, f64)>) -> GearSet {
    let mut g = example("gear-1x40-design.toml");
    g.bending.kind = BendingKind::None;
    g.lubricant.running_in = running_in.map(|(r, h)| RunningIn {
        roughness: r * 1e-6,
        depth: h * 1e-6,
    });
    g
}

#[test]
fn the_running_in_law_starts_at_the_initial_roughness_and_ends_at_the_run_in_one() {
    let g = design(Some((0.4, 2.0)));
    let lub = &g.lubricant;
    let (r0, rr, hr) = (lub.composite_roughness, 0.4e-6, 2e-6);
    assert_eq!(lub.roughness_after(0.0), r0);
    assert!((lub.roughness_after(hr) - (rr + (r0 - rr) / std::f64::consts::E)).abs() < 1e-18);
    assert!((lub.roughness_after(50.0 * hr) - rr).abs() < 1e-18);
    // Monotone between.
    let values: Vec<f64> = (0..40)
        .map(|k| lub.roughness_after(k as f64 * 0.25e-6))
        .collect();
    assert!(values.windows(2).all(|w| w[1] < w[0]), "{values:?}");
    // Without running-in, or running in to the roughness it starts from: the initial one.
    for g in [design(None), design(Some((1.0, 2.0)))] {
        assert_eq!(g.lubricant.composite_roughness, 1e-6);
        for h in [0.0, 1e-6, 1e-3] {
            assert_eq!(g.lubricant.roughness_after(h), 1e-6);
        }
    }
}

/// A removal that varies over the flank: deeper toward the wheel's root and one face end, up to
/// `deepest` m.
fn uneven_removal(bench: &Bench, deepest: f64) -> FlankField {
    let wf = bench.geo.wheel_flank(bench.tca.loaded_flank);
    let mut removal = FlankField::zeros(wf);
    for j in 0..=wf.cells_face {
        for i in 0..=wf.cells_height {
            let (s, t) = (
                i as f64 / wf.cells_height as f64,
                j as f64 / wf.cells_face as f64,
            );
            removal.values[j * (wf.cells_height + 1) + i] = deepest * (1.0 - s) * (0.5 + 0.5 * t);
        }
    }
    removal
}

/// The loaded analysis of `g` on the flank `bench` worn by `removal`.
fn worn_analysis(g: &GearSet, bench: &Bench, removal: &FlankField) -> ltca::Ltca {
    let mut settings = LtcaSettings::from_gear(g);
    settings.torque_balance = g.analysis.torque_balance;
    let change = FlankChange {
        removal: Some(removal),
        plastic_set: None,
    };
    ltca::analyse_changed(g, &bench.geo, &bench.tca, &settings, None, change, None).unwrap()
}

/// With frictionless pressures (the roughness then cannot move the load), the film at every
/// swept node is the same with and without running-in, so its film ratio is the constant
/// roughness' times R_q,0 / R_q(h) of that node's own worn depth h.
#[test]
fn a_worn_node_s_film_ratio_is_over_its_own_run_in_roughness() {
    let mut constant = design(None);
    constant.analysis.torque_balance = TorqueBalance::Frictionless;
    let mut running = constant.clone();
    running.lubricant.running_in = Some(RunningIn {
        roughness: 0.3e-6,
        depth: 1.5e-6,
    });
    let bench = Bench::new(&constant);
    let removal = uneven_removal(&bench, 4e-6);
    let (a, b) = (
        worn_analysis(&constant, &bench, &removal),
        worn_analysis(&running, &bench, &removal),
    );
    assert!(a.roughness.is_none());
    let field = b
        .roughness
        .as_ref()
        .expect("a worn, running-in flank has a field");
    for (rq, &h) in field.values.iter().zip(&removal.values) {
        assert_eq!(*rq, running.lubricant.roughness_after(h));
    }
    assert_eq!(
        a.pattern, b.pattern,
        "frictionless pressures do not see the roughness"
    );
    let wa = wear::per_cycle(
        &constant,
        &bench.geo,
        &bench.tca,
        &a,
        FilmLoad::LoadedAnalysis,
    );
    let wb = wear::per_cycle(
        &running,
        &bench.geo,
        &bench.tca,
        &b,
        FilmLoad::LoadedAnalysis,
    );
    let mut checked = 0;
    for k in 0..removal.values.len() {
        let (la, lb) = (wa.lambda.values[k], wb.lambda.values[k]);
        if !la.is_finite() {
            assert!(!lb.is_finite());
            continue;
        }
        assert_eq!(wa.film.values[k], wb.film.values[k]);
        let expected = la * 1e-6 / field.values[k];
        assert!(
            (lb - expected).abs() <= 1e-12 * expected,
            "node {k}: {lb} vs {expected}"
        );
        checked += usize::from(removal.values[k] > 1e-6 && la > 0.0);
    }
    assert!(checked > 100, "{checked} worn swept nodes");
}

/// On the same worn flank, a flank whose roughness has run in carries less on its asperities:
/// the asperity share, the mean friction and the mesh loss fall, and more so the smoother it
/// has run in; the pressures carry the friction's moments (the default torque balance).
#[test]
fn a_run_in_flank_rubs_less() {
    let bench = Bench::new(&design(None));
    let removal = uneven_removal(&bench, 6e-6);
    let friction = |g: &GearSet| {
        let l = worn_analysis(g, &bench, &removal);
        MeshContacts::new(g, &bench.geo, &bench.tca, &l).friction(&g.lubricant, &g.friction)
    };
    let runs: Vec<_> = [None, Some((0.7, 1.0)), Some((0.4, 1.0))]
        .into_iter()
        .map(|r| friction(&design(r)))
        .collect();
    for w in runs.windows(2) {
        assert!(
            w[1].asperity_share < w[0].asperity_share,
            "{} {}",
            w[0].asperity_share,
            w[1].asperity_share
        );
        assert!(w[1].mean_coefficient < w[0].mean_coefficient);
        assert!(w[1].mesh_loss_w < w[0].mesh_loss_w);
    }
    // Running in to the initial roughness changes nothing.
    let same = friction(&design(Some((1.0, 1.0))));
    assert_eq!(same.mesh_loss_w, runs[0].mesh_loss_w);
    assert_eq!(same.position_loss_w, runs[0].position_loss_w);
}

/// A short life of `g` (40 000 cycles, the design's schedule otherwise).
fn short_life(g: &GearSet) -> wear::WearState {
    let plan = wear::WearPlan::with_life(40_000.0);
    Bench::new(g)
        .simulate(&plan, None, &mut |_| Ok(()))
        .unwrap()
}

#[test]
fn the_constant_roughness_limit_gives_the_published_records_byte_for_byte() {
    let published = short_life(&design(None));
    let limit = short_life(&design(Some((1.0, 2.0))));
    let text = |s: &wear::WearState| serde_json::to_string(&s.records).unwrap();
    assert_eq!(text(&published), text(&limit));
    assert_eq!(published.removal, limit.removal);
    for r in &published.records {
        assert_eq!((r.roughness_mean_m, r.roughness_min_m), (1e-6, 1e-6));
    }
    // Running in: the unworn state has the initial roughness, the worn ones less, the least
    // where the flank has worn most, and the least no lower than the run-in value.
    let run_in = short_life(&design(Some((0.4, 1.0))));
    let first = &run_in.records[0];
    assert_eq!(
        (first.roughness_mean_m, first.roughness_min_m),
        (1e-6, 1e-6)
    );
    let last = run_in.records.last().unwrap();
    assert!(run_in.records.len() > 2 && last.max_wear_m > 1e-6);
    assert!(last.roughness_min_m < last.roughness_mean_m && last.roughness_mean_m < 1e-6);
    assert!(last.roughness_min_m >= 0.4e-6);
    assert_ne!(text(&published), text(&run_in));
}

#[test]
fn bad_running_in_is_refused_naming_the_field() {
    let edit = |lines: &str| common::design_with("lubricant", lines);
    let refused = |lines: &str| input::load_from_str(&edit(lines)).unwrap_err().to_string();
    // The design file's composite roughness is the default 1 um unless it says otherwise.
    let m = refused("run_in_roughness_um = 1.5\nrunning_in_depth_um = 2.0");
    assert!(
        m.contains("lubricant.run_in_roughness_um") && m.contains("above the initial"),
        "{m}"
    );
    let m = refused("run_in_roughness_um = 0.5\nrunning_in_depth_um = 0.0");
    assert!(
        m.contains("lubricant.running_in_depth_um") && m.contains("> 0"),
        "{m}"
    );
    let m = refused("run_in_roughness_um = -0.5\nrunning_in_depth_um = 2.0");
    assert!(
        m.contains("lubricant.run_in_roughness_um") && m.contains("-0.5"),
        "{m}"
    );
    let m = refused("run_in_roughness_um = 0.5");
    assert!(
        m.contains("lubricant.run_in_roughness_um") && m.contains("running_in_depth_um"),
        "{m}"
    );
    let m = refused("running_in_depth_um = 2.0");
    assert!(
        m.contains("lubricant.running_in_depth_um") && m.contains("run_in_roughness_um"),
        "{m}"
    );
    let g = input::load_from_str(&edit(
        "run_in_roughness_um = 0.5\nrunning_in_depth_um = 2.0",
    ))
    .unwrap();
    assert_eq!(
        g.lubricant.running_in,
        Some(RunningIn {
            roughness: 0.5e-6,
            depth: 2e-6
        })
    );
}
