//! Function basis of the bending coefficients (MODEL §5.5, steps 3-4): products
//! f_k(M) = g_a(r~) h_b(w~) of height polynomials g_a(r~) = r~^a and width functions h_b (beam
//! mode shapes: free-free for the wheel, the average of free-free and clamped-clamped for the
//! worm), fitted on a Q1 x Q2 grid of points: [C] = F^-1 [U] F^-T (F: row l = the functions at
//! point l; MODEL's [f]^-T [U] [f]^-1 with points in columns), then any coefficient is
//! C(M_i / M_j) = f(M_i)^T [C] f(M_j). Coordinates are normalised to [0, 1] by the caller
//! (r~ along the height, w~ across the width).
//!
//! The beam eigenvalues are the exact roots of cos(b) cosh(b) = 1 (4.7300, 7.8532, ...); the
//! MODEL's (q - 1/2) pi approximation is allowed but the exact values make the mode shapes satisfy
//! their end conditions exactly (tested).

use faer::linalg::solvers::{Solve, SolveLstsq};
use faer::Mat;

/// Which width functions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum WidthFunctions {
    /// Free-free beam modes (wheel tooth across its face width).
    FreeFree,
    /// Average of free-free and clamped-clamped modes (worm thread along its length).
    Averaged,
}

/// k-th root (k >= 1) of cos(b) cosh(b) = 1, by Newton from (k + 1/2) pi (the first 32 are
/// computed once).
pub fn beam_eigenvalue(k: usize) -> f64 {
    static TABLE: std::sync::OnceLock<Vec<f64>> = std::sync::OnceLock::new();
    let table = TABLE.get_or_init(|| (0..32).map(beam_eigenvalue_newton).collect());
    table
        .get(k)
        .copied()
        .unwrap_or_else(|| beam_eigenvalue_newton(k))
}

fn beam_eigenvalue_newton(k: usize) -> f64 {
    let mut b = (k as f64 + 0.5) * std::f64::consts::PI;
    for _ in 0..50 {
        let f = b.cos() * b.cosh() - 1.0;
        let df = -b.sin() * b.cosh() + b.cos() * b.sinh();
        let step = f / df;
        b -= step;
        if step.abs() < 1e-15 * b {
            break;
        }
    }
    b
}

/// The hyperbolic parts of the mode shapes in a cancellation-free form: with
/// s = (cosh b - cos b) / (sinh b - sin b),
///   cosh(bx) - s sinh(bx) = A + B,  sinh(bx) - s cosh(bx) = A - B,
///   A = e^(bx) (1 - s) / 2,  B = e^(-bx) (1 + s) / 2,
/// where 1 - s = (cos b - sin b - e^-b) / (sinh b - sin b) is formed without subtracting the
/// two nearly equal large terms (for the 12th mode cosh b ~ 1e15: the textbook form loses every
/// digit). This function returns (1 - s, s) of mode k (computed once for the first 32).
fn mode_s(k: usize) -> (f64, f64) {
    static TABLE: std::sync::OnceLock<Vec<(f64, f64)>> = std::sync::OnceLock::new();
    let of = |k: usize| {
        let b = beam_eigenvalue(k);
        let em = (-b).exp();
        // sinh b - sin b = e^b (1 - e^-2b - 2 sin b e^-b) / 2.
        let scaled = 1.0 - em * em - 2.0 * b.sin() * em;
        let one_minus_s = 2.0 * em * (b.cos() - b.sin() - em) / scaled;
        (one_minus_s, 1.0 - one_minus_s)
    };
    let table = TABLE.get_or_init(|| (0..32).map(of).collect());
    table.get(k).copied().unwrap_or_else(|| of(k))
}

/// What the free-free and clamped-clamped modes k share at x: b, A, B and s of
/// [`mode_s`], cos(bx), sin(bx).
struct ModeParts {
    b: f64,
    a: f64,
    bb: f64,
    s: f64,
    c: f64,
    sn: f64,
}

impl ModeParts {
    fn new(k: usize, x: f64) -> Self {
        let b = beam_eigenvalue(k);
        let (one_minus_s, s) = mode_s(k);
        Self {
            b,
            a: 0.5 * (b * x).exp() * one_minus_s,
            bb: 0.5 * (-b * x).exp() * (1.0 + s),
            s,
            c: (b * x).cos(),
            sn: (b * x).sin(),
        }
    }

    /// Free-free mode value.
    fn free_free(&self) -> f64 {
        (self.a + self.bb) + self.c - self.s * self.sn
    }

    /// Clamped-clamped mode value.
    fn clamped_clamped(&self) -> f64 {
        (self.a + self.bb) - self.c + self.s * self.sn
    }
}

/// Free-free mode k >= 1 on [0, 1] and its first three derivatives (textbook form
/// cosh + cos - s (sinh + sin), s = (cosh b - cos b) / (sinh b - sin b)).
pub fn free_free(k: usize, x: f64) -> [f64; 4] {
    let p = ModeParts::new(k, x);
    let (b, a, bb, s, c, sn) = (p.b, p.a, p.bb, p.s, p.c, p.sn);
    [
        p.free_free(),
        b * ((a - bb) - sn - s * c),
        b * b * ((a + bb) - c + s * sn),
        b * b * b * ((a - bb) + sn + s * c),
    ]
}

/// Clamped-clamped mode k >= 1 on [0, 1] and its first three derivatives
/// (cosh - cos - s (sinh - sin), same s).
pub fn clamped_clamped(k: usize, x: f64) -> [f64; 4] {
    let p = ModeParts::new(k, x);
    let (b, a, bb, s, c, sn) = (p.b, p.a, p.bb, p.s, p.c, p.sn);
    [
        p.clamped_clamped(),
        b * ((a - bb) + sn + s * c),
        b * b * ((a + bb) + c - s * sn),
        b * b * b * ((a - bb) - sn - s * c),
    ]
}

/// The basis: Q1 height functions x Q2 width functions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Basis {
    pub height: usize,
    pub width: usize,
    pub kind: WidthFunctions,
}

impl Basis {
    /// Number of functions K = Q1 Q2.
    pub fn len(&self) -> usize {
        self.height * self.width
    }

    /// True for an empty basis.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Width function b at w~ in [0, 1]: 1, 1 - 2w~, then beam modes.
    fn width_function(&self, b: usize, w: f64) -> f64 {
        match b {
            0 => 1.0,
            1 => 1.0 - 2.0 * w,
            _ => match self.kind {
                WidthFunctions::FreeFree => ModeParts::new(b - 1, w).free_free(),
                WidthFunctions::Averaged => {
                    let p = ModeParts::new(b - 1, w);
                    0.5 * (p.free_free() + p.clamped_clamped())
                }
            },
        }
    }

    /// Values of the K functions at (r~, w~), index a * Q2 + b.
    pub fn eval(&self, r: f64, w: f64) -> Vec<f64> {
        let mut out = vec![0.0; self.len()];
        self.eval_into(r, &self.width_values(w), &mut out);
        out
    }

    /// The Q2 width functions at w~.
    pub fn width_values(&self, w: f64) -> Vec<f64> {
        (0..self.width).map(|b| self.width_function(b, w)).collect()
    }

    /// [`Self::eval`] at r~ from the width functions `hw` at w~ ([`Self::width_values`]),
    /// written to `out` (K values): points that share w~ share `hw`.
    pub fn eval_into(&self, r: f64, hw: &[f64], out: &mut [f64]) {
        assert!(hw.len() == self.width && out.len() == self.len());
        for (a, row) in out.chunks_exact_mut(self.width).enumerate() {
            let g = r.powi(a as i32);
            for (o, h) in row.iter_mut().zip(hw) {
                *o = g * h;
            }
        }
    }

    /// The fitting points: a uniform Q1 x Q2 grid of (r~, w~) in [0, 1]^2 (index a * Q2 + b).
    pub fn grid(&self) -> Vec<(f64, f64)> {
        let t = |k: usize, n: usize| {
            if n == 1 {
                0.5
            } else {
                k as f64 / (n - 1) as f64
            }
        };
        (0..self.height)
            .flat_map(|a| (0..self.width).map(move |b| (t(a, self.height), t(b, self.width))))
            .collect()
    }

    /// [f]: row l = the functions at grid point l.
    pub fn matrix(&self) -> Mat<f64> {
        let pts = self.grid();
        let k = self.len();
        Mat::from_fn(k, k, |l, m| self.eval(pts[l].0, pts[l].1)[m])
    }

    /// Core matrix from the K x K displacement matrix U (displacement at point l due to a unit
    /// load at point m), so that f(M_l)^T C f(M_m) = U_lm: with F the matrix whose row l holds
    /// the functions at point l, U = F C F^T, so C = F^-1 U F^-T (the MODEL's
    /// [f]^-T [U] [f]^-1, whose [f] has the points in its columns).
    pub fn fit(&self, u: &Mat<f64>) -> Mat<f64> {
        self.fit_at(&self.grid(), u)
    }

    /// As [`Self::fit`] with the K fitting points given (r~, w~), e.g. the mesh nodes nearest
    /// to the grid.
    pub fn fit_at(&self, points: &[(f64, f64)], u: &Mat<f64>) -> Mat<f64> {
        let k = self.len();
        let f = Mat::from_fn(k, k, |l, m| self.eval(points[l].0, points[l].1)[m]);
        let lu = f.partial_piv_lu();
        // X = F^-1 U, then C^T = F^-1 X^T.
        let x = lu.solve(u);
        let ct = lu.solve(x.transpose());
        ct.transpose().to_owned()
    }

    /// Core matrix fitted by least squares to displacements at n >= K points (U: n x n,
    /// displacement at point l due to a unit load at point m): C = P U P^T with P the
    /// pseudo-inverse of F (n x K, the functions at the points), from its singular value
    /// decomposition with singular values below 1e-6 of the largest dropped. The beam modes
    /// and monomials are far from orthogonal (condition ~1e9 at 5 x 13): without the
    /// truncation, C picks up huge components along directions F nearly annihilates, which
    /// cancel at the data points but turn the LTCA's compliance matrix numerically indefinite.
    pub fn fit_least_squares(&self, points: &[(f64, f64)], u: &Mat<f64>) -> Mat<f64> {
        let k = self.len();
        let n = points.len();
        let f = Mat::from_fn(n, k, |l, m| self.eval(points[l].0, points[l].1)[m]);
        let p = match f.thin_svd() {
            Ok(svd) => {
                let s = svd.S().column_vector();
                let smax = (0..s.nrows()).map(|i| s[i]).fold(0.0, f64::max);
                // P = V S^+ U^T.
                let vs = Mat::from_fn(k, s.nrows(), |i, j| {
                    if s[j] > 1e-6 * smax {
                        svd.V()[(i, j)] / s[j]
                    } else {
                        0.0
                    }
                });
                &vs * svd.U().transpose()
            }
            Err(_) => f.qr().solve_lstsq(Mat::<f64>::identity(n, n)),
        };
        let pu = &p * u;
        &pu * p.transpose()
    }

    /// Coefficient between two points: f(a)^T C f(b).
    pub fn coefficient(&self, core: &Mat<f64>, a: (f64, f64), b: (f64, f64)) -> f64 {
        let (fa, fb) = (self.eval(a.0, a.1), self.eval(b.0, b.1));
        let mut s = 0.0;
        for (i, x) in fa.iter().enumerate() {
            for (j, y) in fb.iter().enumerate() {
                s += x * core[(i, j)] * y;
            }
        }
        s
    }

    /// 2-norm condition number of [f] (from its singular values).
    pub fn condition_number(&self) -> f64 {
        let s = self.matrix().singular_values().unwrap_or_default();
        let max = s.iter().copied().fold(0.0, f64::max);
        let min = s.iter().copied().fold(f64::INFINITY, f64::min);
        max / min
    }
}
