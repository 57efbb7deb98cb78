//! Wear over life (MODEL §7): per-cycle Archard wear on the flank, its convergence with the
//! number of positions, consistency of the Archard law with the geometry frozen, backlash.

use std::path::Path;
use wormwear::geometry::Geometry;
use wormwear::input::{self, GearSet};
use wormwear::kinematics;
use wormwear::ltca;
use wormwear::wear;

fn example(name: &str) -> GearSet {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(name);
    input::load(&path).unwrap()
}

fn cycle(g: &GearSet) -> (Geometry, kinematics::Tca, wear::CycleWear) {
    let geo = Geometry::build(g).unwrap();
    let tca = kinematics::analyse(g, &geo).unwrap();
    let l = ltca::analyse(g, &geo, &tca).unwrap();
    let w = wear::per_cycle(g, &geo, &tca, &l);
    (geo, tca, w)
}

#[test]
fn per_cycle_wear_converges_with_the_positions() {
    let mut g = example("gear-1x40-design.toml");
    let (geo, tca, w20) = cycle(&g);
    g.analysis.positions = 40;
    let (_, _, w40) = cycle(&g);
    let wf = geo.wheel_flank(tca.loaded_flank);
    let swept = w20.depth.values.iter().filter(|v| **v > 0.0).count();
    let lmin = w20.lambda.values.iter().copied().filter(|v| v.is_finite()).fold(f64::INFINITY, f64::min);
    let lmax = w20.lambda.values.iter().copied().filter(|v| v.is_finite()).fold(0.0, f64::max);
    let u2: Vec<f64> = tca.node_contact.iter().filter(|c| c.reachable && c.u2.is_finite()).map(|c| c.u2.abs()).collect();
    eprintln!(
        "max per-cycle wear: 20 positions {:.4e} m, 40 positions {:.4e} m; nodes worn {swept} of {}; lambda {lmin:.3}..{lmax:.3}; |u2| {:.3}..{:.3} m/s; volume {:.3e} m^3",
        w20.depth.max(), w40.depth.max(), wf.nodes.len(),
        u2.iter().copied().fold(f64::INFINITY, f64::min), u2.iter().copied().fold(0.0, f64::max),
        w20.depth.integral(wf)
    );
    let d = (w40.depth.max() / w20.depth.max() - 1.0).abs();
    assert!(d < 0.05, "20 -> 40 positions changes the max per-cycle wear by {:.2} %", 100.0 * d);
}
