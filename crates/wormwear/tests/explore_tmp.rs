use std::path::Path;
use wormwear::geometry::Geometry;
use wormwear::input;
use wormwear::kinematics;
use wormwear::ltca;
#[test]
#[ignore]
fn explore() {
    let g = input::load(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/gear-1x40-design.toml"),
    )
    .unwrap();
    let geo = Geometry::build(&g).unwrap();
    let tca = kinematics::analyse(&g, &geo).unwrap();
    let st = wormwear::output::wear::read_checkpoint(Path::new("/tmp/wl"))
        .unwrap()
        .unwrap();
    let s = ltca::LtcaSettings::from_gear(&g);
    let t = std::time::Instant::now();
    let l = ltca::analyse_worn(&g, &geo, &tca, &s, None, Some(&st.removal)).unwrap();
    eprintln!("worn LTCA {:.3} s", t.elapsed().as_secs_f64());
    for p in l.positions.iter().step_by(4) {
        eprintln!(
            "pos {}: cells {} widenings {} iterations {} capped {}",
            p.position,
            p.cells.len(),
            p.band_widenings,
            p.residuals.iterations,
            p.residuals.capped
        );
    }
    let t = std::time::Instant::now();
    let w = wormwear::wear::per_cycle(&g, &geo, &tca, &l);
    eprintln!("per_cycle {:.3} s", t.elapsed().as_secs_f64());
    let t = std::time::Instant::now();
    let b = wormwear::wear::Backlash::new(&g, &geo, &tca);
    eprintln!("backlash new {:.3} s", t.elapsed().as_secs_f64());
    let _ = (w, b);
}
