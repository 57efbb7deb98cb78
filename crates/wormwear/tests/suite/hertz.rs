//! The contact coefficients and both solvers of the LTCA against Hertz theory (MODEL §5.4-5.5):
//! sphere on a plane and long cylinder on a plane, same code as the gear analysis.

use std::f64::consts::PI;
use wormwear::contact::{ElasticPair, InfluenceRows};
use wormwear::ltca::solver::{
    solve, Block, BlockMatrix, Problem, SolverKind, SolverSettings, GRID_CELLS,
};
use wormwear::validation::analytic;

fn pair() -> ElasticPair {
    analytic::steel_on_bronze()
}

#[test]
fn sphere_on_a_plane_matches_hertz() {
    // 40 x 40 cells over 2.8 a: 28 cells across the Hertz diameter (validation::analytic).
    for kind in [SolverKind::ConjugateGradient, SolverKind::FixedPoint] {
        let (got, hertz) = analytic::hertz_sphere(kind);
        eprintln!(
            "{kind:?}: p_max {:.4} GPa (Hertz {:.4}), a {:.4} mm (Hertz {:.4}), approach {:.4e} m (Hertz {:.4e})",
            got[0] / 1e9, hertz[0] / 1e9, got[1] * 1e3, hertz[1] * 1e3, got[2], hertz[2]
        );
        assert!((got[0] / hertz[0] - 1.0).abs() < 0.02, "{kind:?}: p_max");
        assert!((got[1] / hertz[1] - 1.0).abs() < 0.02, "{kind:?}: a");
        // Rigid approach delta = a^2 / R.
        assert!((got[2] / hertz[2] - 1.0).abs() < 0.02, "{kind:?}: approach");
    }
}

#[test]
fn long_cylinder_on_a_plane_matches_line_contact_hertz() {
    // Central row of a 20 mm long cylinder: plane-strain Hertz for the row's own line load.
    let (got, hertz) = analytic::hertz_cylinder();
    eprintln!(
        "cylinder centre row: p_max {:.4} GPa (Hertz {:.4}), b {:.4} mm (Hertz {:.4})",
        got[0] / 1e9,
        hertz[0] / 1e9,
        got[1] * 1e3,
        hertz[1] * 1e3
    );
    assert!((got[0] / hertz[0] - 1.0).abs() < 0.02, "p_max");
    assert!((got[1] / hertz[1] - 1.0).abs() < 0.02, "b");
}

#[test]
fn pressure_cap_gives_an_elastic_perfectly_plastic_contact() {
    // Sphere on a plane with the pressure capped at 0.8 p0 (Hertz): the load is still carried,
    // no cell exceeds the cap, cells at the cap penetrate (plastic flow: negative gap) while
    // the others satisfy the elastic complementarity, the load spreads out and the approach
    // increases. A cap above p0 changes nothing.
    let (radius, load) = (10e-3, 100.0);
    let e_star = pair().effective_modulus;
    let a = (3.0 * load * radius / (4.0 * e_star)).cbrt();
    let p0 = 3.0 * load / (2.0 * PI * a * a);
    let n = 30;
    let h = 1.6 * a / n as f64;
    let cells = analytic::flat_cells(n, n, h, h);
    let area = cells[0].area();
    let elastic_problem =
        analytic::flat_problem(&cells, |c| (c.x * c.x + c.y * c.y) / (2.0 * radius), load);
    let settings = SolverSettings {
        tolerance: 1e-9,
        ..SolverSettings::default()
    };
    let elastic = solve(&elastic_problem, &settings, None).unwrap();
    let with_cap = |cap: f64| {
        let mut pb = elastic_problem.clone();
        pb.upper = Some(vec![cap * area; cells.len()]);
        solve(&pb, &settings, None).unwrap()
    };
    let high = with_cap(1.1 * p0);
    let worst = elastic
        .q
        .iter()
        .zip(&high.q)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    assert!(
        worst < 1e-6 * load,
        "a cap above p0 changed the solution by {worst:e} N"
    );
    let cap = 0.8 * p0;
    let plastic = with_cap(cap);
    let total: f64 = plastic.q.iter().sum();
    assert!((total / load - 1.0).abs() < 1e-12);
    let capped = plastic.q.iter().filter(|&&q| q >= cap * area).count();
    let loaded = |q: &[f64]| q.iter().filter(|&&q| q > 0.0).count();
    eprintln!(
        "cap 0.8 p0: {capped} plastic cells, loaded cells {} (elastic {}), approach {:.4e} m (elastic {:.4e}), residuals {:?}",
        loaded(&plastic.q),
        loaded(&elastic.q),
        plastic.approach,
        elastic.approach,
        plastic.residuals
    );
    assert!(capped > 0 && plastic.residuals.capped == capped);
    for (q, y) in plastic.q.iter().zip(&plastic.gap) {
        assert!(*q <= cap * area * (1.0 + 1e-12));
        if *q >= cap * area {
            assert!(
                *y <= 1e-9 * plastic.approach,
                "capped cell with an open gap {y:e}"
            );
        }
    }
    assert!(plastic.residuals.complementarity < 1e-8);
    assert!(plastic.residuals.min_gap > -1e-8);
    // The load spreads outwards (second moment of the load about the axis) and the bodies come
    // closer.
    let spread = |q: &[f64]| -> f64 {
        q.iter()
            .zip(&cells)
            .map(|(q, c)| q * (c.centre.x.powi(2) + c.centre.y.powi(2)))
            .sum()
    };
    assert!(spread(&plastic.q) > spread(&elastic.q));
    assert!(plastic.approach > elastic.approach);
}

/// The sphere (R 10 mm, 100 N) on n x n cells over +-1.4 Hertz radii: cells, the problem as
/// the program builds it, Hertz's a (m) and p0 (Pa).
fn sphere(n: usize) -> (Vec<wormwear::contact::ContactCell>, Problem, f64, f64) {
    let (radius, load) = (10e-3, 100.0);
    let e_star = pair().effective_modulus;
    let a = (3.0 * load * radius / (4.0 * e_star)).cbrt();
    let p0 = 3.0 * load / (2.0 * PI * a * a);
    let h = 1.4 * a / n as f64;
    let cells = analytic::flat_cells(n, n, h, h);
    let problem =
        analytic::flat_problem(&cells, |c| (c.x * c.x + c.y * c.y) / (2.0 * radius), load);
    (cells, problem, a, p0)
}

#[test]
fn the_fft_operator_gives_the_assembled_blocks_solution() {
    // 40 x 40 cells form a lattice: the program applies the block by FFT. The same problem
    // with the block assembled (the gear's operator) gives the same loads and approach to the
    // solver's tolerance, and the gaps each reports satisfy the other's operator.
    let (cells, fft, _, _) = sphere(40);
    assert!(matches!(fft.blocks[0].matrix, BlockMatrix::Grid(_)));
    let levers = vec![1.0; cells.len()];
    let mut assembled = fft.clone();
    assembled.blocks = vec![Block {
        start: 0,
        size: cells.len(),
        matrix: BlockMatrix::Lazy(Box::new(InfluenceRows::new(&pair(), &cells, &levers))),
    }];
    let settings = SolverSettings {
        tolerance: 1e-13,
        ..SolverSettings::default()
    };
    let by_fft = solve(&fft, &settings, None).unwrap();
    let by_blocks = solve(&assembled, &settings, None).unwrap();
    let worst = by_fft
        .q
        .iter()
        .zip(&by_blocks.q)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    let peak = by_blocks.q.iter().copied().fold(0.0, f64::max);
    eprintln!(
        "FFT {} / assembled {} iterations; largest load difference {:.1e} of the peak; approach {:.1e}",
        by_fft.residuals.iterations,
        by_blocks.residuals.iterations,
        worst / peak,
        by_fft.approach / by_blocks.approach - 1.0
    );
    assert!(worst < 1e-9 * peak, "{worst:e}");
    assert!((by_fft.approach / by_blocks.approach - 1.0).abs() < 1e-11);
    // Products with a load on every cell agree to round-off.
    let (mut u, mut v) = (vec![0.0; cells.len()], vec![0.0; cells.len()]);
    fft.apply(&by_blocks.q, &mut u);
    assembled.apply(&by_blocks.q, &mut v);
    let scale = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(u
        .iter()
        .zip(&v)
        .all(|(x, y)| (x - y).abs() <= 1e-13 * scale));
}

#[test]
fn the_sphere_converges_to_hertz_on_grids_only_the_fft_operator_can_hold() {
    // 32 x 32 to 128 x 128 cells (16 384: the dense block would need 2.1 GB): the peak
    // pressure converges to Hertz's p0, its error falling with each halving of the cell (1.3e-3,
    // 4.1e-4, 9.9e-5), and the rigid approach stays within 2e-4 of a^2 / R.
    let mut errors = Vec::new();
    for n in [32, 64, 128] {
        let (cells, problem, a, p0) = sphere(n);
        assert!(matches!(problem.blocks[0].matrix, BlockMatrix::Grid(_)));
        let sol = solve(&problem, &SolverSettings::default(), None).unwrap();
        let p_max = sol.q.iter().copied().fold(0.0, f64::max) / cells[0].area();
        let approach = sol.approach / (a * a / 10e-3);
        eprintln!(
            "{n} x {n}: p_max / p0 {:.6}, approach / (a^2/R) {approach:.6}",
            p_max / p0
        );
        errors.push(((p_max / p0 - 1.0).abs(), (approach - 1.0).abs()));
    }
    for w in errors.windows(2) {
        assert!(w[1].0 < 0.5 * w[0].0, "{errors:?}");
    }
    assert!(errors[2].0 < 2e-4, "{errors:?}");
    assert!(errors.iter().all(|e| e.1 < 2e-4), "{errors:?}");
}

#[test]
fn small_or_irregular_groups_keep_the_assembled_block() {
    // Below GRID_CELLS the assembled block is as fast; cells off a lattice (one moved) cannot
    // be convolved.
    let (_, small, _, _) = sphere(16);
    assert!(matches!(small.blocks[0].matrix, BlockMatrix::Lazy(_)));
    let (mut cells, _, _, _) = sphere(24);
    assert!(cells.len() >= GRID_CELLS);
    cells[100].centre.y += 1e-3 * cells[0].half_nu;
    let block = Block::influence(0, &pair(), &cells, &vec![1.0; cells.len()]);
    assert!(matches!(block.matrix, BlockMatrix::Lazy(_)));
}
