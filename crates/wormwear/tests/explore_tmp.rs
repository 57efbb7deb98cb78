use std::path::Path;
use wormwear::geometry::Geometry;
use wormwear::input;
use wormwear::kinematics;
use wormwear::ltca;
#[test]
#[ignore]
fn explore() {
    let g = input::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/gear-1x40-design.toml")).unwrap();
    let geo = Geometry::build(&g).unwrap();
    let tca = kinematics::analyse(&g, &geo).unwrap();
    let st = wormwear::output::wear::read_checkpoint(Path::new("/tmp/w1")).unwrap().unwrap();
    let s = ltca::LtcaSettings::from_gear(&g);
    let l = ltca::analyse_worn(&g, &geo, &tca, &s, None, Some(&st.removal)).unwrap();
    let wf = geo.wheel_flank(tca.loaded_flank);
    let cw = wormwear::wear::per_cycle(&g, &geo, &tca, &l);
    eprintln!("node depth {:e} lambda {}", cw.depth.values[51*41+3], cw.lambda.values[51*41+3]);
    let (pi, p) = l.positions.iter().enumerate().max_by(|a, b| a.1.max_pressure.partial_cmp(&b.1.max_pressure).unwrap()).unwrap();
    let (ci, _) = p.pressure.iter().enumerate().max_by(|a, b| a.1.partial_cmp(b.1).unwrap()).unwrap();
    let c = &p.cells[ci];
    eprintln!("max {:.0} MPa at position {pi} tooth {} slice {} column {} r {:.3} z {:.3} relief {:.2} um removal {:.2} um widen {}", p.max_pressure/1e6, c.tooth, c.slice, c.column, c.r*1e3, c.z*1e3, c.relief*1e6, st.removal.at_above(wf, c.r, c.z, Some(&tca.tip_trace.iter().map(|t| t.1).collect::<Vec<_>>()))*1e6, p.band_widenings);
    let row: Vec<String> = p.cells.iter().zip(&p.pressure).filter(|(cc,_)| cc.tooth==c.tooth && cc.slice==c.slice).map(|(cc,pp)| format!("[{} r{:.3} rem{:.1} e{:.2} p{:.0}]", cc.column, cc.r*1e3, st.removal.at_above(wf, cc.r, cc.z, Some(&tca.tip_trace.iter().map(|t| t.1).collect::<Vec<_>>()))*1e6, cc.separation*cc.lever*1e6, pp/1e6)).collect();
    eprintln!("across: {}", row.join(" "));
    let j = c.slice;
    let col: Vec<String> = (0..=wf.cells_height).map(|i| format!("{:.1}@{:.2}", st.removal.node(i, j)*1e6, wf.node(i,j).r*1e3)).collect();
    eprintln!("column {j} removal: {}", col.join(" "));
}
