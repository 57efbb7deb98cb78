//! Contact influence coefficients (MODEL §5.5, §12d): Boussinesq half-space of both bodies.
//!
//! A uniform pressure on a rectangle of half sides (dnu, dzeta) in its tangent plane displaces
//! the surface normally by Love's closed form; the tangential (radial, in-surface) part of the
//! Boussinesq field is applied as a concentrated load; the sum is projected on the normal at the
//! receiving cell: C_ij = (C_ij^n n_j + C_ij^rho) . n_i. Coefficients couple cells of the same
//! tooth contact only. Units: m of normal displacement per Pa of pressure.

use nalgebra::Vector3;
use std::f64::consts::PI;

/// Elastic constants of the pair used by the half-space coefficients.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElasticPair {
    /// (1 - v1^2)/(pi E1) + (1 - v2^2)/(pi E2), 1/Pa.
    pub normal: f64,
    /// (1 + v1)(1 - 2 v1)/(2 pi E1) - (1 + v2)(1 - 2 v2)/(2 pi E2), 1/Pa (MODEL §12d: E2 in
    /// the second term).
    pub tangential: f64,
    /// Effective modulus E* with 1/E* = (1 - v1^2)/E1 + (1 - v2^2)/E2, Pa (Hertz).
    pub effective_modulus: f64,
}

impl ElasticPair {
    /// Constants for Young's moduli (Pa) and Poisson's ratios of worm (1) and wheel (2).
    pub fn new(e1: f64, v1: f64, e2: f64, v2: f64) -> Self {
        Self {
            normal: (1.0 - v1 * v1) / (PI * e1) + (1.0 - v2 * v2) / (PI * e2),
            tangential: (1.0 + v1) * (1.0 - 2.0 * v1) / (2.0 * PI * e1)
                - (1.0 + v2) * (1.0 - 2.0 * v2) / (2.0 * PI * e2),
            effective_modulus: 1.0 / ((1.0 - v1 * v1) / e1 + (1.0 - v2 * v2) / e2),
        }
    }
}

/// Love's integral of 1/r over the rectangle [-a, a] x [-b, b] seen from (x, y) (in-plane
/// offsets from the rectangle centre), m. Times `ElasticPair::normal` it is the normal
/// displacement per unit uniform pressure.
#[inline]
pub fn love_rectangle(x: f64, y: f64, a: f64, b: f64) -> f64 {
    // Sum over the corners of  X ln(Y + R) + Y ln(X + R)  with signs, X = x -+ a,
    // Y = y -+ b; the two corners sharing an X (or a Y) are combined into one logarithm of a
    // ratio (4 logarithms instead of 8), each factor kept free of cancellation.
    let (x1, x2, y1, y2) = (x + a, x - a, y + b, y - b);
    let r11 = (x1 * x1 + y1 * y1).sqrt();
    let r12 = (x1 * x1 + y2 * y2).sqrt();
    let r21 = (x2 * x2 + y1 * y1).sqrt();
    let r22 = (x2 * x2 + y2 * y2).sqrt();
    let mut v = 0.0;
    if x1 != 0.0 {
        v += x1 * (t_plus_r(y1, x1, r11) / t_plus_r(y2, x1, r12)).ln();
    }
    if x2 != 0.0 {
        v -= x2 * (t_plus_r(y1, x2, r21) / t_plus_r(y2, x2, r22)).ln();
    }
    if y1 != 0.0 {
        v += y1 * (t_plus_r(x1, y1, r11) / t_plus_r(x2, y1, r21)).ln();
    }
    if y2 != 0.0 {
        v -= y2 * (t_plus_r(x1, y2, r12) / t_plus_r(x2, y2, r22)).ln();
    }
    v
}

/// Love's integral with a far-field expansion beyond `FAR` times the larger half side: the
/// rectangle's monopole and quadrupole terms,
/// 4ab [1/d + (a^2 (2x^2 - y^2) + b^2 (2y^2 - x^2)) / (6 d^5)], relative error O((a/d)^4)
/// (below 1e-4 there), exact closed form nearer.
#[inline]
pub fn love_rectangle_fast(x: f64, y: f64, a: f64, b: f64) -> f64 {
    const FAR: f64 = 6.0;
    let d2 = x * x + y * y;
    let m = a.max(b);
    if d2 > FAR * FAR * m * m {
        let d = d2.sqrt();
        let d5 = d2 * d2 * d;
        4.0 * a
            * b
            * (1.0 / d
                + (a * a * (2.0 * x * x - y * y) + b * b * (2.0 * y * y - x * x)) / (6.0 * d5))
    } else {
        love_rectangle(x, y, a, b)
    }
}

/// t + R, R = sqrt(t^2 + s^2), without cancellation for t < 0 (t + R = s^2 / (R - t)).
#[inline]
fn t_plus_r(t: f64, s: f64, r: f64) -> f64 {
    if t >= 0.0 {
        t + r
    } else {
        s * s / (r - t)
    }
}

/// A contact cell: centre, unit normal (out of the wheel, the pressure direction on the worm),
/// in-plane unit axes and half sides. Worm frame, m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactCell {
    pub centre: Vector3<f64>,
    pub normal: Vector3<f64>,
    /// Unit axis across the contact line (nu) and along it (zeta), in the tangent plane.
    pub axis_nu: Vector3<f64>,
    pub axis_zeta: Vector3<f64>,
    pub half_nu: f64,
    pub half_zeta: f64,
}

impl ContactCell {
    /// Area, m^2.
    pub fn area(&self) -> f64 {
        4.0 * self.half_nu * self.half_zeta
    }
}

/// Normal displacement at cell i (along n_i) due to unit pressure on cell j, both bodies, m/Pa
/// (MODEL §5.5). Love's closed form near the source, its far-field expansion beyond six half
/// sides ([`love_rectangle_fast`], relative error below 2e-4 there).
#[inline]
pub fn coefficient(pair: &ElasticPair, i: &ContactCell, j: &ContactCell) -> f64 {
    let d = i.centre - j.centre;
    let nu = d.dot(&j.axis_nu);
    let zeta = d.dot(&j.axis_zeta);
    let normal = pair.normal
        * love_rectangle_fast(nu, zeta, j.half_nu, j.half_zeta)
        * j.normal.dot(&i.normal);
    let r2 = d.norm_squared();
    let tangential = if r2 > 0.0 {
        pair.tangential * j.area() * d.dot(&i.normal) / r2
    } else {
        0.0
    };
    normal + tangential
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn love_rectangle_centre_of_a_square_is_the_closed_form() {
        // Centre of a square of side 2a: 8 a ln(1 + sqrt 2) (Love).
        let a = 1e-3;
        let v = love_rectangle(0.0, 0.0, a, a);
        assert!((v / (8.0 * a * (1.0 + 2f64.sqrt()).ln()) - 1.0).abs() < 1e-14);
        // Far field: integral of 1/r -> area / distance.
        let (x, y) = (0.3, 0.4);
        let far = love_rectangle(x, y, a, 2.0 * a);
        assert!((far / (8.0 * a * a / 0.5) - 1.0).abs() < 1e-5);
        // Symmetry and positivity.
        let (u, v) = (
            love_rectangle(0.7e-3, -0.2e-3, a, a),
            love_rectangle(-0.7e-3, 0.2e-3, a, a),
        );
        assert!((u / v - 1.0).abs() < 1e-12);
        assert!(love_rectangle(-50.0 * a, 3.0 * a, a, 0.1 * a) > 0.0);
    }

    #[test]
    fn love_rectangle_matches_numerical_integration() {
        // Integral of 1/r over the rectangle by midpoint quadrature on a fine grid, for
        // receivers outside (all sides) and on an edge (integrable singularity).
        let (a, b) = (0.6e-3, 1.7e-3);
        let quad = |x: f64, y: f64| {
            let n = 1200;
            let (hx, hy) = (2.0 * a / n as f64, 2.0 * b / n as f64);
            let mut s = 0.0;
            for i in 0..n {
                for j in 0..n {
                    let u = -a + (i as f64 + 0.5) * hx - x;
                    let v = -b + (j as f64 + 0.5) * hy - y;
                    s += hx * hy / (u * u + v * v).sqrt();
                }
            }
            s
        };
        for &(x, y) in &[
            (2.3e-3, -0.4e-3),
            (0.6e-3, 0.9e-3),
            (-1.1e-3, 2.2e-3),
            (0.0, 5e-3),
        ] {
            let exact = love_rectangle(x, y, a, b);
            let q = quad(x, y);
            assert!((q / exact - 1.0).abs() < 2e-3, "({x}, {y}): {q} vs {exact}");
        }
    }

    #[test]
    fn far_field_expansion_matches_the_closed_form() {
        // Just beyond the switch (6 half sides) for square and elongated cells, all directions.
        let mut worst: f64 = 0.0;
        for &(a, b) in &[(1e-4, 1e-4), (5e-5, 1.1e-3), (1.1e-3, 5e-5)] {
            let m = f64::max(a, b);
            for k in 0..24 {
                let t = k as f64 * std::f64::consts::PI / 12.0;
                for &dist in &[6.01 * m, 9.0 * m, 30.0 * m] {
                    let (x, y) = (dist * t.cos(), dist * t.sin());
                    let exact = love_rectangle(x, y, a, b);
                    worst = worst.max((love_rectangle_fast(x, y, a, b) / exact - 1.0).abs());
                }
            }
        }
        assert!(worst < 2e-4, "far-field relative error {worst:e}");
    }

    #[test]
    fn love_rectangle_is_stable_far_along_the_negative_axes() {
        // Far points in the negative directions must agree with the positive ones (no
        // cancellation in ln(t + R) for t -> -inf).
        let (a, b) = (1e-5, 3e-3);
        for &(x, y) in &[(-0.05, 0.0), (0.0, -0.05), (-0.03, -0.04)] {
            let v = love_rectangle(x, y, a, b);
            let w = love_rectangle(-x, -y, a, b);
            assert!((v / w - 1.0).abs() < 1e-9, "{x} {y}: {v} vs {w}");
        }
    }
}
