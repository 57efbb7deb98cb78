//! The contact coefficients and both solvers of the LTCA against Hertz theory (MODEL §5.4-5.5):
//! sphere on a plane and long cylinder on a plane, same code as the gear analysis.

use nalgebra::Vector3;
use std::f64::consts::PI;
use wormwear::contact::{coefficient, ContactCell, ElasticPair};
use wormwear::ltca::solver::{solve, Block, Problem, SolverKind, SolverSettings};

fn pair() -> ElasticPair {
    ElasticPair::new(203e9, 0.29, 110e9, 0.29)
}

/// Flat cells on a regular nx x ny grid of cell size (2 hx, 2 hy) centred at the origin.
fn flat_cells(nx: usize, ny: usize, hx: f64, hy: f64) -> Vec<ContactCell> {
    let mut cells = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let x = (i as f64 - (nx as f64 - 1.0) / 2.0) * 2.0 * hx;
            let y = (j as f64 - (ny as f64 - 1.0) / 2.0) * 2.0 * hy;
            cells.push(ContactCell {
                centre: Vector3::new(x, y, 0.0),
                normal: Vector3::z(),
                axis_nu: Vector3::x(),
                axis_zeta: Vector3::y(),
                half_nu: hx,
                half_zeta: hy,
            });
        }
    }
    cells
}

/// Problem in forces: K_ij = C_ij / S_j (displacement per unit force), q = cell forces.
fn problem(cells: &[ContactCell], gap: impl Fn(&Vector3<f64>) -> f64, load: f64) -> Problem {
    let n = cells.len();
    let p = pair();
    let mut matrix = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            matrix[i * n + j] = coefficient(&p, &cells[i], &cells[j]) / cells[j].area();
        }
    }
    Problem {
        blocks: vec![Block {
            start: 0,
            size: n,
            matrix,
        }],
        low_rank: None,
        separation: cells.iter().map(|c| gap(&c.centre)).collect(),
        load,
        upper: None,
    }
}

#[test]
fn sphere_on_a_plane_matches_hertz() {
    let (radius, load) = (10e-3, 100.0);
    let e_star = pair().effective_modulus;
    let a = (3.0 * load * radius / (4.0 * e_star)).cbrt();
    let p0 = 3.0 * load / (2.0 * PI * a * a);
    let n = 40;
    let h = 1.4 * a / n as f64; // half cell: 2.8 a / n cells -> 28 cells across the diameter
    let cells = flat_cells(n, n, h, h);
    let pb = problem(&cells, |c| (c.x * c.x + c.y * c.y) / (2.0 * radius), load);
    for kind in [SolverKind::ConjugateGradient, SolverKind::FixedPoint] {
        let settings = SolverSettings {
            kind,
            tolerance: 1e-9,
            max_iterations: 200_000,
        };
        let sol = solve(&pb, &settings, None).unwrap();
        let area = cells[0].area();
        let pmax = sol.q.iter().copied().fold(0.0, f64::max) / area;
        let m2: f64 = sol
            .q
            .iter()
            .zip(&cells)
            .map(|(q, c)| q * (c.centre.x.powi(2) + c.centre.y.powi(2)))
            .sum();
        let a_num = (2.5 * m2 / load).sqrt();
        let across = (2.0 * a / (2.0 * h)) as usize;
        eprintln!(
            "{kind:?}: p_max {:.4} GPa (Hertz {:.4}), a {:.4} mm (Hertz {:.4}), approach {:.4e} m (Hertz {:.4e}), {} it, {across} cells across",
            pmax / 1e9, p0 / 1e9, a_num * 1e3, a * 1e3, sol.approach, a * a / radius, sol.residuals.iterations
        );
        assert!(across >= 20);
        assert!(
            (pmax / p0 - 1.0).abs() < 0.02,
            "{kind:?}: p_max {pmax:e} vs {p0:e}"
        );
        assert!(
            (a_num / a - 1.0).abs() < 0.02,
            "{kind:?}: a {a_num:e} vs {a:e}"
        );
        // Rigid approach delta = a^2 / R.
        assert!((sol.approach / (a * a / radius) - 1.0).abs() < 0.02);
        assert!(sol.residuals.load < 1e-12 && sol.residuals.min_load >= 0.0);
    }
}

#[test]
fn long_cylinder_on_a_plane_matches_line_contact_hertz() {
    let (radius, load) = (10e-3, 2000.0);
    let e_star = pair().effective_modulus;
    let length = 20e-3;
    let w = load / length;
    let b = (4.0 * w * radius / (PI * e_star)).sqrt();
    let (nx, ny) = (34, 21);
    let hx = 1.4 * b / nx as f64;
    let hy = length / (2.0 * ny as f64);
    let cells = flat_cells(nx, ny, hx, hy);
    let pb = problem(&cells, |c| c.x * c.x / (2.0 * radius), load);
    let settings = SolverSettings::default();
    let sol = solve(&pb, &settings, None).unwrap();
    // Central row: its own line load w_c, then plane-strain Hertz for w_c.
    let row = ny / 2;
    let q_row: Vec<(f64, f64)> = (0..nx)
        .map(|i| (cells[row * nx + i].centre.x, sol.q[row * nx + i]))
        .collect();
    let wc: f64 = q_row.iter().map(|(_, q)| q).sum::<f64>() / (2.0 * hy);
    let bc = (4.0 * wc * radius / (PI * e_star)).sqrt();
    let p0c = 2.0 * wc / (PI * bc);
    let pmax = q_row.iter().map(|(_, q)| *q).fold(0.0, f64::max) / cells[0].area();
    let m2: f64 = q_row.iter().map(|(x, q)| q * x * x).sum::<f64>()
        / q_row.iter().map(|(_, q)| q).sum::<f64>();
    let b_num = 2.0 * m2.sqrt();
    let across = (2.0 * bc / (2.0 * hx)) as usize;
    eprintln!(
        "cylinder centre row: w {:.1} N/mm (mean {:.1}), p_max {:.4} GPa (Hertz {:.4}), b {:.4} mm (Hertz {:.4}), {across} cells across, {} it",
        wc / 1e3, w / 1e3, pmax / 1e9, p0c / 1e9, b_num * 1e3, bc * 1e3, sol.residuals.iterations
    );
    assert!(across >= 20);
    assert!((pmax / p0c - 1.0).abs() < 0.02, "p_max {pmax:e} vs {p0c:e}");
    assert!((b_num / bc - 1.0).abs() < 0.02, "b {b_num:e} vs {bc:e}");
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
    let cells = flat_cells(n, n, h, h);
    let area = cells[0].area();
    let elastic_problem = problem(&cells, |c| (c.x * c.x + c.y * c.y) / (2.0 * radius), load);
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
