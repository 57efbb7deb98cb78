//! Love's closed form of the stress below a uniformly loaded rectangle (MODEL §8.1; Love
//! 1929; K. L. Johnson, Contact Mechanics, 1985, §3.2 and §3.3): the corner functions of the
//! potentials' derivatives, one rectangle at a time. The reference for [`super::lanes`], which
//! evaluates the same sums many rectangles at a time.

use super::Stress;
use std::f64::consts::PI;

/// Corner sums of Love's potentials' derivatives for a unit pressure on one rectangle.
#[derive(Debug, Clone, Copy, Default)]
struct Potentials {
    psi_z: f64,
    psi_xx: f64,
    psi_zz: f64,
    psi_xy: f64,
    psi_xz: f64,
    psi_yz: f64,
    psi1_xx: f64,
    psi1_xy: f64,
}

/// t + R with R = sqrt(t^2 + s2), without cancellation for t < 0 (t + R = s2 / (R - t)).
#[inline]
fn t_plus_r(t: f64, s2: f64, r: f64) -> f64 {
    if t >= 0.0 {
        t + r
    } else {
        s2 / (r - t)
    }
}

/// The corner functions at offsets (X, Y) from a corner and depth z > 0: for each derivative
/// D of psi or psi1, a function whose mixed derivative d^2/dXdY is D's integrand (module doc).
/// The transcendental ones are left as their arguments, combined over the corners by
/// [`rectangle_potentials`]: psi_z's is -atan(`psi_z_tan`), psi1_xx's atan(`psi1_xx_tan`),
/// psi1_xy's ln(`psi1_xy_exp`).
#[inline]
fn corner(x: f64, y: f64, z: f64) -> Corner {
    let (x2, y2, z2) = (x * x, y * y, z * z);
    let rho = (x2 + y2 + z2).sqrt();
    let y_plus = t_plus_r(y, x2 + z2, rho);
    let x_plus = t_plus_r(x, y2 + z2, rho);
    let xy = x * y;
    // rho - z = (x^2 + y^2) / (rho + z), free of cancellation deep below the surface.
    let rho_minus_z = (x2 + y2) / (rho + z);
    Corner {
        rational: Potentials {
            psi_z: 0.0,
            psi_xx: x / (rho * y_plus),
            psi_zz: xy / rho * (1.0 / (x2 + z2) + 1.0 / (y2 + z2)),
            psi_xy: 1.0 / rho,
            psi_xz: z / (rho * y_plus),
            psi_yz: z / (rho * x_plus),
            psi1_xx: 0.0,
            psi1_xy: 0.0,
        },
        psi_z_tan: xy / (z * rho),
        psi1_xx_tan: if xy == 0.0 {
            0.0
        } else {
            xy * rho_minus_z / (x2 * rho + z * y2)
        },
        psi1_xy_exp: rho + z,
    }
}

/// A corner's functions ([`corner`]): the rational ones, and the arguments of the others.
struct Corner {
    rational: Potentials,
    psi_z_tan: f64,
    psi1_xx_tan: f64,
    psi1_xy_exp: f64,
}

/// atan(u) - atan(v) for any u, v as one arctangent (the difference lies in (-pi, pi)):
/// atan((u - v) / (1 + uv)), shifted by pi where 1 + uv < 0 (a plain arctangent with the
/// quadrant by hand: glibc's atan2 costs twice its atan).
#[inline]
fn atan_difference(u: f64, v: f64) -> f64 {
    let (num, den) = (u - v, 1.0 + u * v);
    if den > 0.0 {
        (num / den).atan()
    } else if den < 0.0 {
        (num / den).atan() + PI.copysign(num)
    } else {
        (0.5 * PI).copysign(num)
    }
}

/// The potentials' derivatives of a unit pressure on the rectangle |x'| <= a, |y'| <= b at the
/// point (x, y) of its plane and depth z > 0: the corners with signs (+ - - +), the
/// arctangents of each pair of corners with one X combined into one, the logarithms into one.
fn rectangle_potentials(x: f64, y: f64, z: f64, a: f64, b: f64) -> Potentials {
    let c = [
        corner(x + a, y + b, z),
        corner(x - a, y + b, z),
        corner(x + a, y - b, z),
        corner(x - a, y - b, z),
    ];
    let sum = |f: fn(&Potentials) -> f64| {
        f(&c[0].rational) - f(&c[1].rational) - f(&c[2].rational) + f(&c[3].rational)
    };
    let atans = |f: fn(&Corner) -> f64| {
        atan_difference(f(&c[0]), f(&c[1])) + atan_difference(f(&c[3]), f(&c[2]))
    };
    Potentials {
        psi_z: -atans(|c| c.psi_z_tan),
        psi_xx: sum(|p| p.psi_xx),
        psi_zz: sum(|p| p.psi_zz),
        psi_xy: sum(|p| p.psi_xy),
        psi_xz: sum(|p| p.psi_xz),
        psi_yz: sum(|p| p.psi_yz),
        psi1_xx: atans(|c| c.psi1_xx_tan),
        psi1_xy: ((c[0].psi1_xy_exp * c[3].psi1_xy_exp) / (c[1].psi1_xy_exp * c[2].psi1_xy_exp))
            .ln(),
    }
}

/// Stress at (x, y, z) (m; z the depth into the body, > 0) of a uniform pressure `p` (Pa,
/// pressing on the body) on the rectangle |x'| <= a, |y'| <= b of the surface, in the
/// rectangle's frame, for Poisson's ratio `nu` (Love's closed form, module doc). Pa.
pub fn rectangle_stress(x: f64, y: f64, z: f64, a: f64, b: f64, nu: f64, p: f64) -> Stress {
    let d = rectangle_potentials(x, y, z, a, b);
    // Laplace's equation: psi_yy = -psi_xx - psi_zz, psi1_yy = -psi1_xx - psi1_zz with
    // psi1_zz = psi_z.
    let psi_yy = -d.psi_xx - d.psi_zz;
    let psi1_yy = -d.psi1_xx - d.psi_z;
    let k = p / (2.0 * PI);
    let m = 1.0 - 2.0 * nu;
    [
        k * (2.0 * nu * d.psi_z - z * d.psi_xx - m * d.psi1_xx),
        k * (2.0 * nu * d.psi_z - z * psi_yy - m * psi1_yy),
        k * (d.psi_z - z * d.psi_zz),
        -k * (m * d.psi1_xy + z * d.psi_xy),
        -k * z * d.psi_xz,
        -k * z * d.psi_yz,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_combined_arctangent_is_the_difference_of_two_in_every_quadrant() {
        let values = [-1e6, -3.0, -1.0, -0.2, 0.0, 0.2, 1.0, 3.0, 1e6];
        for u in values {
            for v in values {
                let d = atan_difference(u, v);
                assert!((d - (u.atan() - v.atan())).abs() < 1e-12, "{u} {v}: {d}");
            }
        }
    }
}
