//! Cubic B-spline interpolation of curves and tensor-product surfaces through gridded points
//! (de Boor's knot averaging, clamped ends), for the CAD solids. Points are in mm.
//!
//! A surface's boundary curves depend only on the boundary row of its data (the clamped
//! collocation matrix has e_0 as first and last row), so two faces interpolated through the same
//! boundary points with the same parameters share that boundary curve exactly; the solid builder
//! relies on it.

use nalgebra::{DMatrix, LU};
use truck_modeling::{
    BSplineCurve, BSplineSurface, EuclideanSpace, InnerSpace, KnotVec, Point3, Vector3,
};

/// Interpolation in one parameter direction: the parameters, the clamped knot vector and the
/// factorised collocation matrix A[i][j] = N_j(t_i).
pub struct Interpolant {
    pub params: Vec<f64>,
    pub knots: KnotVec,
    pub degree: usize,
    lu: LU<f64, nalgebra::Dyn, nalgebra::Dyn>,
}

impl Interpolant {
    /// The interpolant through `params` (strictly increasing, from 0 to 1): degree 3, or less
    /// when there are fewer than 4 points; knots by averaging (de Boor, A Practical Guide to
    /// Splines, ch. XIII).
    pub fn new(params: &[f64]) -> Self {
        let n = params.len();
        assert!(n >= 2, "interpolation needs at least two points");
        let degree = 3.min(n - 1);
        let mut knots = vec![params[0]; degree + 1];
        for j in 1..n - degree {
            knots.push(params[j..j + degree].iter().sum::<f64>() / degree as f64);
        }
        knots.extend(std::iter::repeat_n(params[n - 1], degree + 1));
        let knots = KnotVec::from(knots);
        let mut a = DMatrix::zeros(n, n);
        for (i, &t) in params.iter().enumerate() {
            let basis = knots.bspline_basis_functions(degree, t);
            for (j, b) in basis.iter().enumerate() {
                a[(i, j)] = *b;
            }
        }
        Self {
            params: params.to_vec(),
            knots,
            degree,
            lu: a.lu(),
        }
    }

    /// Control points whose curve passes through `points` at the parameters.
    pub fn control_points(&self, points: &[Point3]) -> Vec<Point3> {
        let n = self.params.len();
        let mut rhs = DMatrix::zeros(n, 3);
        for (i, p) in points.iter().enumerate() {
            rhs[(i, 0)] = p.x;
            rhs[(i, 1)] = p.y;
            rhs[(i, 2)] = p.z;
        }
        let c = self
            .lu
            .solve(&rhs)
            .expect("the collocation matrix of distinct parameters is regular");
        (0..n)
            .map(|i| Point3::new(c[(i, 0)], c[(i, 1)], c[(i, 2)]))
            .collect()
    }

    /// The curve through `points`.
    pub fn curve(&self, points: &[Point3]) -> BSplineCurve<Point3> {
        BSplineCurve::new(self.knots.clone(), self.control_points(points))
    }
}

/// Parameters from the mean normalised chord length of several polylines with the same point
/// count (skinning: one parameter set for every station of a face).
pub fn mean_chord_params(rows: &[Vec<Point3>]) -> Vec<f64> {
    let n = rows[0].len();
    let mut params = vec![0.0; n];
    for row in rows {
        let mut cum = vec![0.0; n];
        for i in 1..n {
            cum[i] = cum[i - 1] + (row[i] - row[i - 1]).magnitude();
        }
        let total = cum[n - 1].max(f64::MIN_POSITIVE);
        for i in 0..n {
            params[i] += cum[i] / total / rows.len() as f64;
        }
    }
    params[n - 1] = 1.0;
    params
}

/// Uniform parameters 0, 1/(n-1), ..., 1.
pub fn uniform_params(n: usize) -> Vec<f64> {
    (0..n).map(|i| i as f64 / (n - 1) as f64).collect()
}

/// The tensor-product surface through `grid[v][u]`: first through each row along u, then
/// through each column of those control points along v. Control points indexed [u][v] as truck
/// stores them.
pub fn interpolate_surface(
    u: &Interpolant,
    v: &Interpolant,
    grid: &[Vec<Point3>],
) -> BSplineSurface<Point3> {
    let rows: Vec<Vec<Point3>> = grid.iter().map(|row| u.control_points(row)).collect();
    let nu = u.params.len();
    let control: Vec<Vec<Point3>> = (0..nu)
        .map(|i| {
            let column: Vec<Point3> = rows.iter().map(|r| r[i]).collect();
            v.control_points(&column)
        })
        .collect();
    BSplineSurface::new((u.knots.clone(), v.knots.clone()), control)
}

/// The non-zero basis functions N_{span-p..=span} and their first derivatives at t on the
/// knot span `span` (The NURBS Book, algorithms A2.2 and A2.3, first derivative only).
fn basis_local(knots: &[f64], p: usize, span: usize, t: f64) -> ([f64; 4], [f64; 4]) {
    let mut ndu = [[0.0f64; 4]; 4];
    let (mut left, mut right) = ([0.0f64; 4], [0.0f64; 4]);
    ndu[0][0] = 1.0;
    for j in 1..=p {
        left[j] = t - knots[span + 1 - j];
        right[j] = knots[span + j] - t;
        let mut saved = 0.0;
        for r in 0..j {
            ndu[j][r] = right[r + 1] + left[j - r];
            let temp = ndu[r][j - 1] / ndu[j][r];
            ndu[r][j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j][j] = saved;
    }
    let (mut value, mut derivative) = ([0.0; 4], [0.0; 4]);
    for r in 0..=p {
        value[r] = ndu[r][p];
        if p > 0 {
            let a = if r >= 1 {
                ndu[r - 1][p - 1] / ndu[p][r - 1]
            } else {
                0.0
            };
            let b = if r < p {
                ndu[r][p - 1] / ndu[p][r]
            } else {
                0.0
            };
            derivative[r] = p as f64 * (a - b);
        }
    }
    (value, derivative)
}

/// The knot span of t: the last i with knots[i] <= t < knots[i + 1], clamped to the last
/// non-empty span.
fn find_span(knots: &[f64], p: usize, t: f64) -> usize {
    let n = knots.len() - p - 2;
    if t >= knots[n + 1] {
        return n;
    }
    let i = knots.partition_point(|&k| k <= t);
    (i - 1).clamp(p, n)
}

/// A B-spline surface evaluated on its local spans (cost independent of its size, unlike
/// truck's evaluation, which sums over every control point): point and first derivatives.
pub struct LocalSurface<'a> {
    ku: &'a [f64],
    kv: &'a [f64],
    p: (usize, usize),
    control: &'a [Vec<Point3>],
}

impl<'a> LocalSurface<'a> {
    pub fn new(surface: &'a BSplineSurface<Point3>) -> Self {
        let (ku, kv) = surface.knot_vecs();
        Self {
            ku: ku.as_slice(),
            kv: kv.as_slice(),
            p: surface.degrees(),
            control: surface.control_points(),
        }
    }

    /// The parameter range: ((u0, u1), (v0, v1)).
    pub fn range(&self) -> ((f64, f64), (f64, f64)) {
        let (ku, kv) = (self.ku, self.kv);
        ((ku[0], ku[ku.len() - 1]), (kv[0], kv[kv.len() - 1]))
    }

    /// The knot spans with non-zero length, in u and in v.
    pub fn spans(&self) -> [Vec<(f64, f64)>; 2] {
        let spans = |k: &[f64]| -> Vec<(f64, f64)> {
            k.windows(2)
                .filter(|w| w[1] > w[0])
                .map(|w| (w[0], w[1]))
                .collect()
        };
        [spans(self.ku), spans(self.kv)]
    }

    /// S(u, v), S_u and S_v.
    pub fn eval(&self, u: f64, v: f64) -> (Point3, Vector3, Vector3) {
        let (pu, pv) = self.p;
        let (su, sv) = (find_span(self.ku, pu, u), find_span(self.kv, pv, v));
        let (nu, du) = basis_local(self.ku, pu, su, u);
        let (nv, dv) = basis_local(self.kv, pv, sv, v);
        let (mut s, mut s_u, mut s_v) = (
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(0.0, 0.0, 0.0),
        );
        for a in 0..=pu {
            let row = &self.control[su - pu + a];
            for b in 0..=pv {
                let c = row[sv - pv + b].to_vec();
                s += c * (nu[a] * nv[b]);
                s_u += c * (du[a] * nv[b]);
                s_v += c * (nu[a] * dv[b]);
            }
        }
        (Point3::from_vec(s), s_u, s_v)
    }

    /// Distance from `point` to the surface, by Gauss-Newton from the parameter `hint` (kept
    /// inside the parameter range): for a point within a few micrometres of the surface it
    /// converges in a few steps. mm.
    pub fn distance(&self, point: Point3, hint: (f64, f64)) -> f64 {
        let ((u0, u1), (v0, v1)) = self.range();
        let (mut u, mut v) = hint;
        for _ in 0..20 {
            let (s, s_u, s_v) = self.eval(u, v);
            let d = s - point;
            let (a, b, c) = (s_u.dot(s_u), s_u.dot(s_v), s_v.dot(s_v));
            let (g_u, g_v) = (s_u.dot(d), s_v.dot(d));
            let det = a * c - b * b;
            let (du, dv) = ((c * g_u - b * g_v) / det, (a * g_v - b * g_u) / det);
            u = (u - du).clamp(u0, u1);
            v = (v - dv).clamp(v0, v1);
            if du.abs() + dv.abs() < 1e-13 {
                break;
            }
        }
        (self.eval(u, v).0 - point).magnitude()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use truck_modeling::{ParametricCurve, ParametricSurface};

    #[test]
    fn a_cubic_is_reproduced_exactly_and_points_are_interpolated() {
        // Cubic interpolation reproduces cubics: a cubic space curve through 7 points at
        // uneven parameters is recovered everywhere to rounding.
        let f = |t: f64| Point3::new(t, t * t - 0.3 * t, 2.0 * t * t * t - t);
        let params = [0.0, 0.1, 0.25, 0.5, 0.6, 0.85, 1.0];
        let it = Interpolant::new(&params);
        let c = it.curve(&params.map(f));
        for k in 0..=50 {
            let t = k as f64 / 50.0;
            assert!((c.subs(t) - f(t)).magnitude() < 1e-12, "t = {t}");
        }
    }

    #[test]
    fn the_interpolation_error_of_a_circle_falls_as_the_fourth_power() {
        let error = |n: usize| {
            let params = uniform_params(n);
            let pts: Vec<Point3> = params
                .iter()
                .map(|t| Point3::new(t.cos(), t.sin(), 0.0))
                .collect();
            let c = Interpolant::new(&params).curve(&pts);
            (0..200)
                .map(|k| {
                    let t = (k as f64 + 0.5) / 200.0;
                    (c.subs(t).to_vec().magnitude() - 1.0).abs()
                })
                .fold(0.0, f64::max)
        };
        let ratio = error(9) / error(17);
        assert!(ratio > 12.0 && ratio < 20.0, "{ratio}");
    }

    #[test]
    fn a_surface_passes_through_its_grid_and_its_boundary_is_the_boundary_curve() {
        let f = |u: f64, v: f64| Point3::new(u, v, (3.0 * u).sin() * (2.0 * v).cos());
        let (pu, pv) = (
            uniform_params(6),
            mean_chord_params(&[vec![
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(0.2, 0.0, 0.0),
                Point3::new(0.7, 0.0, 0.0),
                Point3::new(1.0, 0.0, 0.0),
            ]]),
        );
        let grid: Vec<Vec<Point3>> = pv
            .iter()
            .map(|&v| pu.iter().map(|&u| f(u, v)).collect())
            .collect();
        let (iu, iv) = (Interpolant::new(&pu), Interpolant::new(&pv));
        let s = interpolate_surface(&iu, &iv, &grid);
        for (j, &v) in pv.iter().enumerate() {
            for (i, &u) in pu.iter().enumerate() {
                assert!((s.subs(u, v) - grid[j][i]).magnitude() < 1e-12);
            }
        }
        let local = LocalSurface::new(&s);
        for (u, v) in [(0.0, 0.0), (0.3, 0.7), (1.0, 0.45), (0.61, 1.0)] {
            let (p, s_u, s_v) = local.eval(u, v);
            assert!((p - s.subs(u, v)).magnitude() < 1e-12);
            assert!((s_u - s.uder(u, v)).magnitude() < 1e-10);
            assert!((s_v - s.vder(u, v)).magnitude() < 1e-10);
        }
        let off = s.subs(0.4, 0.55) + s.uder(0.4, 0.55).cross(s.vder(0.4, 0.55)).normalize() * 1e-3;
        assert!((local.distance(off, (0.5, 0.5)) - 1e-3).abs() < 1e-9);
        let column: Vec<Point3> = grid.iter().map(|r| r[0]).collect();
        let edge = iv.curve(&column);
        for k in 0..=20 {
            let v = k as f64 / 20.0;
            assert!((s.subs(0.0, v) - edge.subs(v)).magnitude() < 1e-13);
        }
    }
}
