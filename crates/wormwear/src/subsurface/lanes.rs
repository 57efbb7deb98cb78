//! The stress below many loaded rectangles at one field point (MODEL §8.1), the rectangles
//! [`LANES`] at a time: the same closed form as [`super::love`] (Love's corner functions),
//! written branch-free over structure-of-arrays data so that the compiler evaluates one
//! rectangle per vector lane (compiled for AVX2 + FMA when the CPU has them, chosen at run
//! time, there with fused multiply-adds; the same numbers to round-off either way).
//!
//! Per rectangle the work is arranged for few divisions: each corner's reciprocals share one
//! division where they can, the arctangents of the four corners are combined into one from
//! their numerators and denominators, and the arctangent itself is a polynomial ([`atan_reduced`]),
//! not a library call, so that it vectorises. Coordinates are scaled by the rectangle's half
//! side across the line: the potentials' derivatives that enter the stresses are
//! dimensionless, and the scaled numbers stay near 1.

use super::{Source, Stress};
use nalgebra::{Matrix3, Vector3};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

/// Rectangles per pass (four doubles per AVX2 register).
pub(super) const LANES: usize = 4;

/// The smallest depth of a field point below a source, in half sides across the line (the
/// closed form is singular on the surface).
const MIN_DEPTH: f64 = 1e-6;

/// tan(pi / 8) and tan(3 pi / 8): the bounds of the arctangent's argument reduction
/// ([`argument`]).
const TAN_PI_8: f64 = 0.414_213_562_373_095_03;
const TAN_3PI_8: f64 = 2.414_213_562_373_095;

/// Coefficients c_k of atan(r) = r + r s sum_k c_k s^k, s = r^2, |r| <= tan(pi / 8): the
/// degree-10 polynomial interpolating (atan(r) - r) / r^3 at the Chebyshev nodes of
/// s in [0, tan^2(pi / 8)] (computed with 50-digit arithmetic; the unit test checks the
/// arctangent against the library's to 2 ulp).
const ATAN_COEFFICIENTS: [f64; 11] = [
    -0.333_333_333_333_333_3,
    0.199_999_999_999_955_2,
    -0.142_857_142_846_665_42,
    0.111_111_110_152_563_61,
    -0.090_909_045_781_239_03,
    0.076_921_831_908_260_87,
    -0.066_645_114_473_819_48,
    0.058_581_489_128_022_1,
    -0.050_854_497_379_402_6,
    0.039_231_658_295_587_19,
    -0.019_176_887_119_062_26,
];

/// The corner sum atan(u0) - atan(u1) + atan(u3) - atan(u2), u_k = n_k / d_k with d_k > 0,
/// as one arctangent: the argument of w = (d0 + i n0)(d1 - i n1) (d3 + i n3)(d2 - i n2), whose
/// two pair factors have the pair differences alpha and beta (each in (-pi, pi)) as
/// arguments. Their sum is arg w, plus 2 pi where both are non-negative and arg w is negative,
/// less 2 pi where both are negative and arg w is positive (the sum of two angles of one sign
/// has that sign): exact for any alpha, beta, and no round-off can cross the branch cut where
/// the sum is near zero (both pair factors then have positive real parts).
#[inline(always)]
fn corner_atan_sum<const FUSED: bool>(n: [f64; 4], d: [f64; 4]) -> f64 {
    let m = madd::<FUSED>;
    // (re, im) of each pair factor: z0 conj(z1) and z3 conj(z2).
    let (re_a, im_a) = (m(d[0], d[1], n[0] * n[1]), m(n[0], d[1], -(n[1] * d[0])));
    let (re_b, im_b) = (m(d[3], d[2], n[3] * n[2]), m(n[3], d[2], -(n[2] * d[3])));
    let re = m(re_a, re_b, -(im_a * im_b));
    let im = m(re_a, im_b, im_a * re_b);
    let theta = argument::<FUSED>(re, im);
    let turn = if im_a >= 0.0 && im_b >= 0.0 && theta < 0.0 {
        2.0 * PI
    } else if im_a < 0.0 && im_b < 0.0 && theta > 0.0 {
        -2.0 * PI
    } else {
        0.0
    };
    theta + turn
}

/// The argument of re + i im in [-pi, pi]: atan(|im| / |re|) with the argument reduced to
/// |r| <= tan(pi / 8) by atan(t) = pi/2 + atan(-1/t) or pi/4 + atan((t - 1) / (t + 1)),
/// written in |im| and |re| so that one division is left, then its quadrant. Relative error
/// about 1e-16.
#[inline(always)]
pub(super) fn argument<const FUSED: bool>(re: f64, im: f64) -> f64 {
    let (a, b) = (im.abs(), re.abs());
    // t = a / b against tan(pi/8) and tan(3 pi/8), without dividing.
    let (top, bottom, offset) = if a > TAN_3PI_8 * b {
        (-b, a, FRAC_PI_2)
    } else if a > TAN_PI_8 * b {
        (a - b, a + b, FRAC_PI_4)
    } else {
        (a, b, 0.0)
    };
    let first = atan_reduced::<FUSED>(top / bottom, offset);
    let angle = if re < 0.0 { PI - first } else { first };
    angle.copysign(im)
}

/// offset + atan(r) for |r| <= tan(pi / 8) (the polynomial of [`ATAN_COEFFICIENTS`]; the
/// reduction that brings an argument there is [`argument`]'s).
#[inline(always)]
fn atan_reduced<const FUSED: bool>(r: f64, offset: f64) -> f64 {
    // Estrin's scheme: pairs, then pairs of pairs (a shorter chain of dependent operations
    // than Horner's, for the same polynomial).
    let c = &ATAN_COEFFICIENTS;
    let m = madd::<FUSED>;
    let s = r * r;
    let (s2, s4) = (s * s, s * s * (s * s));
    let pairs = [
        m(c[1], s, c[0]),
        m(c[3], s, c[2]),
        m(c[5], s, c[4]),
        m(c[7], s, c[6]),
        m(c[9], s, c[8]),
    ];
    let low = m(m(pairs[3], s2, pairs[2]), s4, m(pairs[1], s2, pairs[0]));
    let high = m(c[10], s2, pairs[4]);
    let p = m(high, s4 * s4, low);
    offset + (r + r * (s * p))
}

/// The natural logarithm of a positive normal number, branch-free and in operations AVX2
/// has for four lanes: x = 2^e m with m in [sqrt(1/2), sqrt(2)) from the bits, ln m =
/// 2 atanh(f), f = (m - 1) / (m + 1), |f| < 0.172, atanh(f) / f a polynomial in f^2
/// ([`ATANH_COEFFICIENTS`]). Relative error about 3e-16 away from x = 1, absolute about 3e-17
/// near it.
#[inline(always)]
pub(super) fn ln<const FUSED: bool>(x: f64) -> f64 {
    const SQRT_HALF: u64 = 0x3fe6_a09e_667f_3bcd;
    const EXPONENT_MASK: u64 = 0xfff0_0000_0000_0000;
    // The exponent for a mantissa in [sqrt(1/2), sqrt(2)), offset by 1024 to stay positive
    // (bit arithmetic modulo 2^64, as the exponent field is).
    let bits = x.to_bits();
    let shifted = bits.wrapping_add(1024 << 52).wrapping_sub(SQRT_HALF);
    // (shifted >> 52) as a double by the 2^52 trick (no 64-bit integer conversion in AVX2).
    let exponent = f64::from_bits((shifted >> 52) | 0x4330_0000_0000_0000)
        - (4_503_599_627_370_496.0 + 1024.0);
    let m = f64::from_bits(
        bits.wrapping_sub(shifted & EXPONENT_MASK)
            .wrapping_add(1024 << 52),
    );
    let f = (m - 1.0) / (m + 1.0);
    let (c, m) = (&ATANH_COEFFICIENTS, madd::<FUSED>);
    let s = f * f;
    let (s2, s4) = (s * s, s * s * (s * s));
    let low = m(m(c[3], s, c[2]), s2, m(c[1], s, c[0]));
    let high = m(m(c[7], s, c[6]), s2, m(c[5], s, c[4]));
    let p = m(high, s4, low);
    m(exponent, std::f64::consts::LN_2, 2.0 * f * p)
}

/// Coefficients c_k of atanh(f) / f = sum_k c_k f^(2k) for f^2 <= ((sqrt 2 - 1) / (sqrt 2 + 1))^2:
/// the degree-7 polynomial interpolating it at the Chebyshev nodes of that range (computed
/// with 50-digit arithmetic; the unit test checks the logarithm against the library's).
const ATANH_COEFFICIENTS: [f64; 8] = [
    1.0,
    0.333_333_333_333_338_26,
    0.199_999_999_996_511_7,
    0.142_857_143_803_208_4,
    0.111_110_985_283_630_24,
    0.090_918_158_401_146_64,
    0.076_562_640_741_820_95,
    0.074_048_551_803_276_38,
];

/// a b + c, fused (one rounding) when `FUSED`: the AVX2 + FMA build's, the portable build
/// keeps the two roundings (a fused multiply-add without the hardware is a slow library call).
#[inline(always)]
fn madd<const FUSED: bool>(a: f64, b: f64, c: f64) -> f64 {
    if FUSED {
        a.mul_add(b, c)
    } else {
        a * b + c
    }
}

/// One corner's share of a rectangle's potentials (see [`super::love`]): the rational
/// derivatives, and the numerators and (positive) denominators of the arctangents' arguments.
#[derive(Clone, Copy)]
struct Corner {
    psi_xx: f64,
    psi_zz: f64,
    psi_xy: f64,
    psi_xz: f64,
    psi_yz: f64,
    /// psi_z's corner function is -atan(z_num / z_den), psi1_xx's atan(xx_num / xx_den).
    z_num: f64,
    z_den: f64,
    xx_num: f64,
    xx_den: f64,
    /// psi1_xy's corner function is ln(`rho_plus_z`).
    rho_plus_z: f64,
}

/// The corner functions at offsets (x, y) from a corner and depth z > 0 (scaled lengths),
/// branch-free: t + rho for t < 0 as s2 / (rho - t), free of cancellation, and 1 / (rho (t + rho))
/// as one division either way.
#[inline(always)]
fn corner(x: f64, y: f64, z: f64) -> Corner {
    let (x2, y2, z2) = (x * x, y * y, z * z);
    let rho = (x2 + y2 + z2).sqrt();
    let (xz2, yz2) = (x2 + z2, y2 + z2);
    // 1 / (rho (y + rho)) and 1 / (rho (x + rho)).
    let (num_y, den_y) = if y >= 0.0 {
        (1.0, y + rho)
    } else {
        (rho - y, xz2)
    };
    let (num_x, den_x) = if x >= 0.0 {
        (1.0, x + rho)
    } else {
        (rho - x, yz2)
    };
    // One division for 1 / rho, 1 / (rho den_y), 1 / (rho den_x) and 1 / (rho xz2 yz2).
    let (xz2_yz2, dens) = (xz2 * yz2, den_x * den_y);
    let inverse = 1.0 / (rho * dens * xz2_yz2);
    let over_rho = inverse * dens * xz2_yz2;
    let over_y = num_y * (inverse * den_x * xz2_yz2);
    let over_x = num_x * (inverse * den_y * xz2_yz2);
    let xy = x * y;
    let rho_plus_z = rho + z;
    // rho - z = (x^2 + y^2) / (rho + z); psi1_xx's argument xy (rho - z) / (x^2 rho + z y^2),
    // zero where xy is (its denominator vanishes only at x = y = 0).
    let xx_den = rho_plus_z * (x2 * rho + z * y2);
    let (xx_num, xx_den) = if xx_den > 0.0 {
        (xy * (x2 + y2), xx_den)
    } else {
        (0.0, 1.0)
    };
    Corner {
        psi_xx: x * over_y,
        psi_zz: xy * (xz2 + yz2) * (inverse * dens),
        psi_xy: over_rho,
        psi_xz: z * over_y,
        psi_yz: z * over_x,
        z_num: xy,
        z_den: z * rho,
        xx_num,
        xx_den,
        rho_plus_z,
    }
}

/// Stress at (x, y, z) (scaled by the half side across the line; z the depth, > 0) of a
/// pressure 2 pi on the rectangle |x'| <= 1, |y'| <= b, in its frame, but for tau_xy's
/// (1 - 2 nu) psi1_xy term, and the argument of that psi1_xy's logarithm.
#[inline(always)]
fn rectangle<const FUSED: bool>(x: f64, y: f64, z: f64, b: f64, nu: f64) -> ([f64; 6], f64) {
    let c = [
        corner(x + 1.0, y + b, z),
        corner(x - 1.0, y + b, z),
        corner(x + 1.0, y - b, z),
        corner(x - 1.0, y - b, z),
    ];
    let sum = |f: fn(&Corner) -> f64| f(&c[0]) - f(&c[1]) - f(&c[2]) + f(&c[3]);
    let atan = corner_atan_sum::<FUSED>;
    let psi_z = -atan(c.map(|c| c.z_num), c.map(|c| c.z_den));
    let psi1_xx = atan(c.map(|c| c.xx_num), c.map(|c| c.xx_den));
    let (psi_xx, psi_zz) = (sum(|c| c.psi_xx), sum(|c| c.psi_zz));
    let (psi_xy, psi_xz, psi_yz) = (sum(|c| c.psi_xy), sum(|c| c.psi_xz), sum(|c| c.psi_yz));
    // Laplace's equation: psi_yy = -psi_xx - psi_zz, psi1_yy = -psi1_xx - psi_z.
    let psi_yy = -psi_xx - psi_zz;
    let psi1_yy = -psi1_xx - psi_z;
    let m = 1.0 - 2.0 * nu;
    let stress = [
        2.0 * nu * psi_z - z * psi_xx - m * psi1_xx,
        2.0 * nu * psi_z - z * psi_yy - m * psi1_yy,
        psi_z - z * psi_zz,
        -z * psi_xy,
        -z * psi_xz,
        -z * psi_yz,
    ];
    let log_argument = (c[0].rho_plus_z * c[3].rho_plus_z) / (c[1].rho_plus_z * c[2].rho_plus_z);
    (stress, log_argument)
}

/// [`LANES`] source rectangles, lane by lane: centre, frame (across, along, outward normal),
/// the inverse of the half side across the line, the aspect ratio (along / across), the
/// pressure over 2 pi (Pa) and the rotation of the source's frame into the field's
/// (row-major).
#[derive(Debug, Clone, Copy)]
struct Pass {
    centre: [[f64; LANES]; 3],
    across: [[f64; LANES]; 3],
    along: [[f64; LANES]; 3],
    normal: [[f64; LANES]; 3],
    inverse_half_across: [f64; LANES],
    aspect: [f64; LANES],
    scale: [f64; LANES],
    rotation: [[f64; LANES]; 9],
}

/// Source rectangles in passes of [`LANES`], the last padded with unloaded copies; `len`
/// sources.
#[derive(Debug, Clone, Default)]
pub(super) struct Batch {
    passes: Vec<Pass>,
    len: usize,
}

impl Batch {
    /// The sources, each with its rotation into the field's frame, padded.
    #[cfg(test)]
    pub(super) fn new(sources: &[(Source, Matrix3<f64>)]) -> Self {
        let mut batch = Self::default();
        for (source, rotation) in sources {
            batch.push(source, rotation);
        }
        batch
    }

    /// Adds a source with the rotation of its frame into the field's. A new pass starts with
    /// the source in every lane, unloaded but for the first (the padding).
    pub(super) fn push(&mut self, s: &Source, rotation: &Matrix3<f64>) {
        let lane = self.len % LANES;
        if lane == 0 {
            self.passes.push(Pass {
                centre: [[0.0; LANES]; 3],
                across: [[0.0; LANES]; 3],
                along: [[0.0; LANES]; 3],
                normal: [[0.0; LANES]; 3],
                inverse_half_across: [0.0; LANES],
                aspect: [0.0; LANES],
                scale: [0.0; LANES],
                rotation: [[0.0; LANES]; 9],
            });
        }
        let Some(p) = self.passes.last_mut() else {
            return;
        };
        let lanes = if lane == 0 { 0..LANES } else { lane..lane + 1 };
        for l in lanes {
            for i in 0..3 {
                p.centre[i][l] = s.centre[i];
                p.across[i][l] = s.axis_nu[i];
                p.along[i][l] = s.axis_zeta[i];
                p.normal[i][l] = s.normal[i];
            }
            p.inverse_half_across[l] = 1.0 / s.half_nu;
            p.aspect[l] = s.half_zeta / s.half_nu;
            for (i, r) in p.rotation.iter_mut().enumerate() {
                r[l] = rotation[(i / 3, i % 3)];
            }
        }
        p.scale[lane] = s.pressure / (2.0 * PI);
        self.len += 1;
    }

    /// Stress at `point` (m) from every source, in the field's frame (each source's tensor
    /// rotated by its rotation), for Poisson's ratio `nu`. Pa.
    pub(super) fn stress_at(&self, point: &Vector3<f64>, nu: f64) -> Stress {
        if self.passes.is_empty() {
            return [0.0; 6];
        }
        #[cfg(target_arch = "x86_64")]
        if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") {
            // SAFETY: the CPU has AVX2 and FMA (checked above).
            return unsafe { self.stress_at_avx2(point, nu) };
        }
        self.stress_at_lanes::<false>(point, nu)
    }

    /// [`Batch::stress_at`] compiled for AVX2 + FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn stress_at_avx2(&self, point: &Vector3<f64>, nu: f64) -> Stress {
        self.stress_at_lanes::<true>(point, nu)
    }

    /// [`Batch::stress_at`], one pass at a time; `FUSED`: with fused multiply-adds.
    #[inline(always)]
    fn stress_at_lanes<const FUSED: bool>(&self, point: &Vector3<f64>, nu: f64) -> Stress {
        let mut sum = [[0.0; LANES]; 6];
        let points = [[point[0]; LANES], [point[1]; LANES], [point[2]; LANES]];
        for pass in &self.passes {
            pass.add_stress::<FUSED>(&points, nu, &mut sum);
        }
        let mut out = [0.0; 6];
        for (o, lanes) in out.iter_mut().zip(&sum) {
            *o = lanes.iter().sum();
        }
        out
    }

    /// The stress at each of `points` (m) from every source, as [`Batch::stress_at`] point
    /// by point (Pa), with the last pass's loaded lanes of all the points packed together
    /// instead of each point's padding lanes left idle.
    pub(super) fn stress_at_points(&self, points: &[Vector3<f64>], nu: f64) -> Vec<Stress> {
        #[cfg(target_arch = "x86_64")]
        if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") {
            // SAFETY: the CPU has AVX2 and FMA (checked above).
            return unsafe { self.stress_at_points_avx2(points, nu) };
        }
        self.stress_at_points_lanes::<false>(points, nu)
    }

    /// [`Batch::stress_at_points`] compiled for AVX2 + FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn stress_at_points_avx2(&self, points: &[Vector3<f64>], nu: f64) -> Vec<Stress> {
        self.stress_at_points_lanes::<true>(points, nu)
    }

    /// [`Batch::stress_at_points`]: the full passes point by point, then the remainder's
    /// (point, source) pairs four to a pass.
    #[inline(always)]
    fn stress_at_points_lanes<const FUSED: bool>(
        &self,
        points: &[Vector3<f64>],
        nu: f64,
    ) -> Vec<Stress> {
        let remainder = self.len % LANES;
        let full = if remainder == 0 {
            &self.passes[..]
        } else {
            &self.passes[..self.passes.len() - 1]
        };
        // Plain loops, no closures: a closure is not compiled with the caller's target
        // features, and its fused multiply-adds would become library calls.
        let mut out: Vec<Stress> = vec![[0.0; 6]; points.len()];
        for (o, point) in out.iter_mut().zip(points) {
            let mut sum = [[0.0; LANES]; 6];
            let lanes = [[point[0]; LANES], [point[1]; LANES], [point[2]; LANES]];
            for pass in full {
                pass.add_stress::<FUSED>(&lanes, nu, &mut sum);
            }
            for (value, component) in o.iter_mut().zip(&sum) {
                *value = component.iter().sum();
            }
        }
        let Some(last) = self.passes.last().filter(|_| remainder > 0) else {
            return out;
        };
        let mut pairs = Vec::with_capacity(points.len() * remainder);
        for p in 0..points.len() {
            for j in 0..remainder {
                pairs.push((p, j));
            }
        }
        for chunk in pairs.chunks(LANES) {
            let mut packed = *last;
            let mut lanes = [[0.0; LANES]; 3];
            for l in 0..LANES {
                // Lanes past the pairs repeat the first pair, unloaded.
                let (p, j) = chunk.get(l).copied().unwrap_or(chunk[0]);
                packed.copy_lane(l, last, j, l < chunk.len());
                for (axis, value) in lanes.iter_mut().zip(points[p].iter()) {
                    axis[l] = *value;
                }
            }
            let mut sum = [[0.0; LANES]; 6];
            packed.add_stress::<FUSED>(&lanes, nu, &mut sum);
            for (l, &(p, _)) in chunk.iter().enumerate() {
                for (o, component) in out[p].iter_mut().zip(&sum) {
                    *o += component[l];
                }
            }
        }
        out
    }
}

impl Pass {
    /// Lane `to` becomes lane `from` of `source`, loaded or not.
    #[inline(always)]
    fn copy_lane(&mut self, to: usize, source: &Pass, from: usize, loaded: bool) {
        for i in 0..3 {
            self.centre[i][to] = source.centre[i][from];
            self.across[i][to] = source.across[i][from];
            self.along[i][to] = source.along[i][from];
            self.normal[i][to] = source.normal[i][from];
        }
        self.inverse_half_across[to] = source.inverse_half_across[from];
        self.aspect[to] = source.aspect[from];
        self.scale[to] = if loaded { source.scale[from] } else { 0.0 };
        for (r, s) in self.rotation.iter_mut().zip(&source.rotation) {
            r[to] = s[from];
        }
    }

    /// The pass's stresses at `points` (one per lane, m) in the field's frame, added lane by
    /// lane to `sum`.
    #[inline(always)]
    fn add_stress<const FUSED: bool>(
        &self,
        points: &[[f64; LANES]; 3],
        nu: f64,
        sum: &mut [[f64; LANES]; 6],
    ) {
        // Component-major, so that each component's lanes are contiguous.
        let mut local = [[0.0; LANES]; 6];
        let mut log_argument = [0.0; LANES];
        for l in 0..LANES {
            let d = [
                points[0][l] - self.centre[0][l],
                points[1][l] - self.centre[1][l],
                points[2][l] - self.centre[2][l],
            ];
            let dot = |a: &[[f64; LANES]; 3]| {
                madd::<FUSED>(d[0], a[0][l], madd::<FUSED>(d[1], a[1][l], d[2] * a[2][l]))
            };
            let inverse = self.inverse_half_across[l];
            let x = dot(&self.across) * inverse;
            let y = dot(&self.along) * inverse;
            let z = (-dot(&self.normal) * inverse).max(MIN_DEPTH);
            let (stress, argument) = rectangle::<FUSED>(x, y, z, self.aspect[l], nu);
            for (component, value) in local.iter_mut().zip(stress) {
                component[l] = value;
            }
            log_argument[l] = argument;
        }
        // psi1_xy's part of tau_xy.
        let m = 1.0 - 2.0 * nu;
        for l in 0..LANES {
            local[3][l] = madd::<FUSED>(-m, ln::<FUSED>(log_argument[l]), local[3][l]);
        }
        for l in 0..LANES {
            let s = |k: usize| local[k][l];
            let t = [[s(0), s(3), s(4)], [s(3), s(1), s(5)], [s(4), s(5), s(2)]];
            let q = |i: usize, j: usize| self.rotation[3 * i + j][l];
            // R S R^T, upper triangle.
            let mut rs = [[0.0; 3]; 3];
            for (i, row) in rs.iter_mut().enumerate() {
                for (j, v) in row.iter_mut().enumerate() {
                    *v = madd::<FUSED>(
                        q(i, 0),
                        t[0][j],
                        madd::<FUSED>(q(i, 1), t[1][j], q(i, 2) * t[2][j]),
                    );
                }
            }
            let e = |i: usize, j: usize| {
                madd::<FUSED>(
                    rs[i][0],
                    q(j, 0),
                    madd::<FUSED>(rs[i][1], q(j, 1), rs[i][2] * q(j, 2)),
                )
            };
            let rotated = [e(0, 0), e(1, 1), e(2, 2), e(0, 1), e(0, 2), e(1, 2)];
            for (k, v) in rotated.into_iter().enumerate() {
                sum[k][l] = madd::<FUSED>(self.scale[l], v, sum[k][l]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::love;
    use super::*;
    use crate::contact::ContactCell;

    /// A tensor given in frame `from` (columns) rotated into frame `to`: R S R^T, R = to^T from.
    fn rotate(s: &Stress, rotation: &Matrix3<f64>) -> Stress {
        let m = Matrix3::new(s[0], s[3], s[4], s[3], s[1], s[5], s[4], s[5], s[2]);
        let r = rotation * m * rotation.transpose();
        [
            r[(0, 0)],
            r[(1, 1)],
            r[(2, 2)],
            r[(0, 1)],
            r[(0, 2)],
            r[(1, 2)],
        ]
    }

    /// A cell of a curved surface: centre on the sphere of radius `radius` (m) about the
    /// origin's -z side, frame turned by `turn` about the normal, half sides (m).
    fn cell(angle: (f64, f64), radius: f64, turn: f64, half: (f64, f64)) -> ContactCell {
        let normal = Vector3::new(angle.0.sin(), angle.1.sin(), 1.0).normalize();
        let seed = Vector3::new(turn.cos(), turn.sin(), 0.0);
        let axis_nu = (seed - normal * seed.dot(&normal)).normalize();
        ContactCell {
            centre: normal * radius - Vector3::new(0.0, 0.0, radius),
            normal,
            axis_nu,
            axis_zeta: normal.cross(&axis_nu),
            half_nu: half.0,
            half_zeta: half.1,
        }
    }

    #[test]
    fn a_batch_sums_loves_rectangles_rotated_into_the_field_frame() {
        // Sources on a curved surface, each in its own tangent plane, pressures of both signs
        // of size; field points below, beside and far away: the batch against the reference
        // closed form one rectangle at a time (love::rectangle_stress), rotated by nalgebra.
        let radius = 0.02;
        let cells: Vec<ContactCell> = (0..11)
            .map(|k| {
                let k = k as f64;
                cell(
                    (0.004 * (k - 5.0), 0.003 * (k % 3.0)),
                    radius,
                    0.2 * k,
                    (1e-4 * (1.0 + 0.1 * k), 3e-4 * (1.0 + 0.05 * k)),
                )
            })
            .collect();
        let field = cells[4];
        let to =
            Matrix3::from_columns(&[field.axis_nu, field.axis_zeta, -field.normal]).transpose();
        let sources: Vec<(Source, Matrix3<f64>)> = cells
            .iter()
            .enumerate()
            .map(|(k, c)| {
                (
                    Source::of(c, 1e8 * (1.0 + k as f64)),
                    to * Matrix3::from_columns(&[c.axis_nu, c.axis_zeta, -c.normal]),
                )
            })
            .collect();
        let batch = Batch::new(&sources);
        let nu = 0.35;
        for (depth, beside) in [
            (1e-5, 0.0),
            (1e-4, 0.0),
            (3e-4, 2e-4),
            (5e-3, 0.0),
            (1e-4, 3e-3),
        ] {
            let point = field.centre - field.normal * depth + field.axis_nu * beside;
            let mut reference = [0.0; 6];
            for (s, rotation) in &sources {
                let d = point - s.centre;
                let local = love::rectangle_stress(
                    d.dot(&s.axis_nu),
                    d.dot(&s.axis_zeta),
                    (-d.dot(&s.normal)).max(1e-6 * s.half_nu),
                    s.half_nu,
                    s.half_zeta,
                    nu,
                    s.pressure,
                );
                for (r, v) in reference.iter_mut().zip(rotate(&local, rotation)) {
                    *r += v;
                }
            }
            let ours = batch.stress_at(&point, nu);
            let size = reference.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            // Several points at once, the remainder's lanes packed: the same stresses.
            let others = [
                point,
                point - field.normal * 1e-4,
                point + field.axis_zeta * 2e-4,
            ];
            for (one, many) in others.iter().zip(batch.stress_at_points(&others, nu)) {
                let single = batch.stress_at(one, nu);
                for (a, b) in single.iter().zip(&many) {
                    assert!((a - b).abs() < 1e-13 * size, "{single:?} vs {many:?}");
                }
            }
            // The portable build of the same passes, without fused multiply-adds.
            let portable = batch.stress_at_lanes::<false>(&point, nu);
            for (a, b) in ours.iter().zip(&portable) {
                assert!((a - b).abs() < 1e-13 * size, "{ours:?} vs {portable:?}");
            }
            for (a, b) in ours.iter().zip(&reference) {
                assert!(
                    (a - b).abs() < 1e-12 * size,
                    "depth {depth}: {ours:?} vs {reference:?}"
                );
            }
        }
    }

    #[test]
    fn one_rectangle_is_loves_everywhere_below_beside_and_far() {
        // Points spread over every region round a rectangle (inside, beside each edge, by the
        // corners, far, from 1e-6 to 300 half sides deep), aspect ratios 0.01 to 100: the
        // vector form against the reference one rectangle at a time, to 1e-11 of the pressure.
        let mut seed: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut uniform = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let nu = 0.3;
        for _ in 0..20_000 {
            let b = 10f64.powf(4.0 * uniform() - 2.0);
            let u: [f64; 4] = std::array::from_fn(|_| uniform());
            let x = (2.0 * u[0] - 1.0) * 10f64.powf(3.0 * u[1] - 1.0);
            let y = (2.0 * u[2] - 1.0) * b * 10f64.powf(3.0 * u[3] - 1.0);
            let z = 10f64.powf(8.5 * uniform() - 6.0);
            let (stress, argument) = rectangle::<true>(x, y, z, b, nu);
            let mut ours = stress.map(|v| v / (2.0 * PI));
            ours[3] -= (1.0 - 2.0 * nu) * ln::<true>(argument) / (2.0 * PI);
            let reference = love::rectangle_stress(x, y, z, 1.0, b, nu, 1.0);
            for (a, r) in ours.iter().zip(&reference) {
                assert!(
                    (a - r).abs() < 1e-11,
                    "x {x} y {y} z {z} b {b}: {ours:?} vs {reference:?}"
                );
            }
        }
    }

    #[test]
    fn the_polynomial_arctangent_is_the_librarys_to_two_ulp() {
        let mut worst: f64 = 0.0;
        for k in -4000..=4000 {
            for u in [
                k as f64 * 1e-3,
                (k as f64 * 1e-2).powi(3),
                1.0 / (k as f64 * 1e-3),
            ] {
                let (ours, libm) = (argument::<false>(1.0, u), u.atan());
                if libm != 0.0 {
                    worst = worst.max(((ours - libm) / libm).abs());
                }
            }
        }
        assert!(worst < 2.0 * f64::EPSILON, "relative error {worst:e}");
        assert_eq!(argument::<false>(0.0, 1.0), FRAC_PI_2);
        assert_eq!(argument::<false>(0.0, -1.0), -FRAC_PI_2);
        assert_eq!(argument::<false>(1.0, 0.0), 0.0);
        assert_eq!(argument::<false>(-1.0, 0.0), PI);
        assert!((argument::<false>(-1.0, -1.0) + 3.0 * FRAC_PI_4).abs() < 1e-15);
    }

    #[test]
    fn the_combined_arctangent_is_the_corner_sum_in_every_quadrant() {
        let values: [f64; 12] = [
            -1e6, -3.0, -1.0, -0.4, -0.2, 0.0, 0.2, 0.45, 1.0, 2.5, 3.0, 1e6,
        ];
        let pairs: [(f64, f64); 5] = [
            (1e6, -1e6),
            (-3.0, 0.2),
            (0.0, 0.0),
            (2.5, -1.0),
            (-0.4, -3.0),
        ];
        for u in values {
            for v in values {
                for (w, x) in pairs {
                    let d = [1.0, 0.3, 7.0, 2.0];
                    let sum = corner_atan_sum::<false>([u * d[0], v * d[1], x * d[2], w * d[3]], d);
                    let expected = u.atan() - v.atan() + w.atan() - x.atan();
                    assert!((sum - expected).abs() < 4e-15, "{u} {v} {w} {x}: {sum}");
                }
            }
        }
    }

    #[test]
    fn the_series_logarithm_is_the_librarys() {
        for k in 1..20000 {
            for x in [
                k as f64 * 1e-3,
                1.0 + (k as f64 - 1e4) * 1e-9,
                (k as f64 * 1e-3).powi(9),
            ] {
                let (ours, libm) = (ln::<false>(x), x.ln());
                assert!(
                    (ours - libm).abs() <= 2.0 * f64::EPSILON * libm.abs().max(1e-1),
                    "ln {x}: {ours} vs {libm}"
                );
            }
        }
    }
}
