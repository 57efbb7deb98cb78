//! Function basis of the bending coefficients (MODEL §5.5): beam modes, exact fit at the grid,
//! reproduction of fields in the span of the basis away from the grid, conditioning.

use faer::Mat;
use wormwear::bending::basis::{
    beam_eigenvalue, clamped_clamped, free_free, Basis, WidthFunctions,
};

#[test]
fn beam_eigenvalues_are_the_textbook_ones() {
    // Roots of cos b cosh b = 1 (free-free and clamped-clamped beams).
    for (k, expected) in [
        (1, 4.730_040_744_862_704),
        (2, 7.853_204_624_095_838),
        (3, 10.995_607_838_001_67),
    ] {
        assert!(
            (beam_eigenvalue(k) - expected).abs() < 1e-12,
            "k = {k}: {}",
            beam_eigenvalue(k)
        );
    }
    // Close to the MODEL's approximation (q - 1/2) pi for q = k + 1.
    assert!((beam_eigenvalue(4) / (4.5 * std::f64::consts::PI) - 1.0).abs() < 1e-6);
}

#[test]
fn mode_shapes_satisfy_their_end_conditions() {
    for k in 1..=5 {
        // Round-off: the shapes are differences of terms of size cosh(b) (1.6e7 for k = 5).
        let b = beam_eigenvalue(k);
        let scale = b.powi(3) * b.cosh() * 1e-3;
        for x in [0.0, 1.0] {
            let ff = free_free(k, x);
            assert!(
                ff[2].abs() < 1e-9 * scale && ff[3].abs() < 1e-9 * scale,
                "free-free k = {k}: {ff:?}"
            );
            // (1e-12 x b^3 cosh b: the terms cancel to round-off, nothing more.)
            let cc = clamped_clamped(k, x);
            assert!(
                cc[0].abs() < 1e-12 * b.cosh() && cc[1].abs() < 1e-12 * b * b.cosh(),
                "clamped k = {k}: {cc:?}"
            );
        }
        // Orthogonality of different free-free modes (trapezoid rule, fine grid).
        if k > 1 {
            let n = 20_000;
            let dot: f64 = (0..=n)
                .map(|i| {
                    let x = i as f64 / n as f64;
                    let w = if i == 0 || i == n { 0.5 } else { 1.0 };
                    w * free_free(k, x)[0] * free_free(k - 1, x)[0]
                })
                .sum::<f64>()
                / n as f64;
            assert!(
                dot.abs() < 1e-6,
                "modes {k} and {} not orthogonal: {dot:e}",
                k - 1
            );
        }
    }
}

/// A smooth "displacement" kernel built from basis functions: U(a, b) = sum c_ij f_i(a) f_j(b).
fn kernel_in_span(basis: &Basis, a: (f64, f64), b: (f64, f64)) -> f64 {
    let (fa, fb) = (basis.eval(a.0, a.1), basis.eval(b.0, b.1));
    let mut s = 0.0;
    for (i, x) in fa.iter().enumerate() {
        for (j, y) in fb.iter().enumerate() {
            let c = 1.0 / (1.0 + (i as f64 - j as f64).abs())
                * if (i + j) % 3 == 0 { -0.5 } else { 1.0 };
            s += x * c * y;
        }
    }
    s
}

#[test]
fn fit_reproduces_the_grid_and_the_span_of_the_basis() {
    for kind in [WidthFunctions::FreeFree, WidthFunctions::Averaged] {
        let basis = Basis {
            height: 5,
            width: 7,
            kind,
        };
        // Two solves with [f]: round-off grows with its condition number (2.4e3 free-free,
        // 3.7e5 averaged on the uniform 5 x 7 grid).
        let cond = basis.condition_number();
        let tol = cond * 1e-12;
        let pts = basis.grid();
        let k = basis.len();
        // Any U at the grid is reproduced exactly.
        let u = Mat::from_fn(k, k, |l, m| {
            1.0 / (1.0 + ((pts[l].0 - pts[m].0).powi(2) + (pts[l].1 - pts[m].1).powi(2)).sqrt())
        });
        let core = basis.fit(&u);
        let mut worst: f64 = 0.0;
        for l in 0..k {
            for m in 0..k {
                worst = worst.max((basis.coefficient(&core, pts[l], pts[m]) - u[(l, m)]).abs());
            }
        }
        assert!(
            worst < tol,
            "{kind:?}: grid reproduction error {worst:e} (cond {cond:e})"
        );
        // A kernel in the span of the basis is reproduced everywhere, also off the grid.
        let u = Mat::from_fn(k, k, |l, m| kernel_in_span(&basis, pts[l], pts[m]));
        let core = basis.fit(&u);
        let mut worst: f64 = 0.0;
        let mut scale: f64 = 0.0;
        for &a in &[(0.13, 0.71), (0.5, 0.05), (0.92, 0.33)] {
            for &b in &[(0.37, 0.58), (0.66, 0.91), (0.02, 0.49)] {
                let exact = kernel_in_span(&basis, a, b);
                scale = scale.max(exact.abs());
                worst = worst.max((basis.coefficient(&core, a, b) - exact).abs());
            }
        }
        assert!(
            worst < tol * scale.max(1.0),
            "{kind:?}: off-grid error {worst:e}"
        );
        eprintln!("{kind:?} 5 x 7 basis: condition number {cond:.3e}");
        assert!(
            cond < 1e6,
            "{kind:?}: basis matrix badly conditioned ({cond:e})"
        );
    }
}
