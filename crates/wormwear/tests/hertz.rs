//! The contact coefficients and both solvers of the LTCA against Hertz theory (MODEL §5.4-5.5):
//! sphere on a plane and long cylinder on a plane, same code as the gear analysis.

use std::f64::consts::PI;
use wormwear::contact::ElasticPair;
use wormwear::ltca::solver::{solve, SolverKind, SolverSettings};
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
