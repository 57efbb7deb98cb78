//! Sampling the uncertain inputs of a spread (MODEL §17): Latin hypercube points in the unit
//! cube from a seeded ChaCha8 stream (the same seed gives the same points on every machine),
//! or Saltelli's design from a scrambled Sobol sequence for the Sobol indices,
//! and each input's distribution mapping a unit coordinate to its value (uniform over a range,
//! or a normal distribution truncated to bounds, by its inverse CDF).

use rand_chacha::rand_core::{RngCore, SeedableRng};

/// A uniform number in [0, 1) from 53 random bits.
fn unit(rng: &mut rand_chacha::ChaCha8Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// `samples` Latin hypercube points in `dims` dimensions, seeded by `seed`: in every dimension
/// each of the `samples` equal strata of [0, 1) holds exactly one point, at a uniform place
/// inside it; the strata are paired across dimensions by independent random permutations.
/// Row k is sample k.
pub fn latin_hypercube(samples: usize, dims: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut points = vec![vec![0.0; dims]; samples];
    for d in 0..dims {
        let mut strata: Vec<usize> = (0..samples).collect();
        // Fisher–Yates.
        for i in (1..samples).rev() {
            let j = (rng.next_u64() % (i as u64 + 1)) as usize;
            strata.swap(i, j);
        }
        for (k, point) in points.iter_mut().enumerate() {
            point[d] = (strata[k] as f64 + unit(&mut rng)) / samples as f64;
        }
    }
    points
}

/// Saltelli's design for the first-order and total Sobol indices (Saltelli et al., "Variance
/// based sensitivity analysis of model output", Comput. Phys. Commun. 181, 2010, 259-270): two
/// matrices A and B of `base` points each, from one Owen-scrambled Sobol sequence in 2 `dims`
/// dimensions (A its first `dims` coordinates, B the others; `seed` picks the scrambling), then
/// for each input i the matrix A_B^i: A with its column i from B. Rows: A, B, A_B^1, ...,
/// A_B^dims, `base` each: `base` (`dims` + 2) points in (0, 1). `base` at most 2^16 and
/// `dims` at most 128 (the sequence's 256 dimensions).
pub fn saltelli(base: usize, dims: usize, seed: u64) -> Vec<Vec<f64>> {
    // The sequence's values are multiples of 2^-24 in [0, 1): the middle of their interval.
    let unit = |k: usize, d: usize| {
        let scramble = (seed ^ (seed >> 32)) as u32;
        f64::from(sobol_burley::sample(k as u32, d as u32, scramble)) + 0.5 / (1u64 << 24) as f64
    };
    let a: Vec<Vec<f64>> = (0..base)
        .map(|k| (0..dims).map(|d| unit(k, d)).collect())
        .collect();
    let b: Vec<Vec<f64>> = (0..base)
        .map(|k| (0..dims).map(|d| unit(k, dims + d)).collect())
        .collect();
    let mut rows = a.clone();
    rows.extend(b.iter().cloned());
    for i in 0..dims {
        rows.extend(a.iter().zip(&b).map(|(ra, rb)| {
            let mut r = ra.clone();
            r[i] = rb[i];
            r
        }));
    }
    rows
}

/// How one input varies.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[serde(tag = "distribution", rename_all = "kebab-case")]
pub enum Distribution {
    /// Uniform over [min, max] (a zero-width range: the value itself).
    Uniform { min: f64, max: f64 },
    /// Normal with `mean` and standard deviation `sd`, truncated to [min, max] (infinite:
    /// untruncated).
    Normal {
        mean: f64,
        sd: f64,
        min: f64,
        max: f64,
    },
}

impl Distribution {
    /// The value at unit coordinate `u` in [0, 1): the inverse of the distribution's CDF.
    pub fn value(&self, u: f64) -> f64 {
        match *self {
            Distribution::Uniform { min, max } => min + u * (max - min),
            Distribution::Normal { mean, sd, min, max } => {
                if sd == 0.0 {
                    return mean;
                }
                let (a, b) = (normal_cdf((min - mean) / sd), normal_cdf((max - mean) / sd));
                let p = (a + u * (b - a)).clamp(1e-300, 1.0 - 1e-16);
                (mean + sd * normal_quantile(p)).clamp(min, max)
            }
        }
    }

    /// The nominal value of the input: the range's middle, or the mean.
    pub fn centre(&self) -> f64 {
        match *self {
            Distribution::Uniform { min, max } => 0.5 * (min + max),
            Distribution::Normal { mean, .. } => mean,
        }
    }
}

/// The standard normal CDF, Phi(x) = erfc(-x / sqrt 2) / 2.
pub fn normal_cdf(x: f64) -> f64 {
    0.5 * libm::erfc(-x / std::f64::consts::SQRT_2)
}

/// The standard normal quantile Phi^-1(p), 0 < p < 1: Acklam's rational approximation
/// (relative error 1.15e-9) refined by one Halley step on [`normal_cdf`] (to round-off).
pub fn normal_quantile(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969683028665376e1,
        2.209460984245205e2,
        -2.759285104469687e2,
        1.38357751867269e2,
        -3.066479806614716e1,
        2.506628277459239,
    ];
    const B: [f64; 5] = [
        -5.447609879822406e1,
        1.615858368580409e2,
        -1.556989798598866e2,
        6.680131188771972e1,
        -1.328068155288572e1,
    ];
    const C: [f64; 6] = [
        -7.784894002430293e-3,
        -3.223964580411365e-1,
        -2.400758277161838,
        -2.549732539343734,
        4.374664141464968,
        2.938163982698783,
    ];
    const D: [f64; 4] = [
        7.784695709041462e-3,
        3.224671290700398e-1,
        2.445134137142996,
        3.754408661907416,
    ];
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    let x = if p < 0.02425 {
        tail((-2.0 * p.ln()).sqrt())
    } else if p > 1.0 - 0.02425 {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    };
    // Halley's step on Phi(x) - p.
    let e = normal_cdf(x) - p;
    let u = e * (2.0 * std::f64::consts::PI).sqrt() * (0.5 * x * x).exp();
    x - u / (1.0 + 0.5 * x * u)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_stratum_holds_one_point_in_every_dimension() {
        let n = 50;
        let points = latin_hypercube(n, 3, 7);
        for d in 0..3 {
            let mut strata: Vec<usize> =
                points.iter().map(|p| (p[d] * n as f64) as usize).collect();
            strata.sort();
            assert_eq!(strata, (0..n).collect::<Vec<_>>());
        }
        assert_eq!(points, latin_hypercube(n, 3, 7));
        assert_ne!(points, latin_hypercube(n, 3, 8));
    }

    #[test]
    fn the_quantile_inverts_the_cdf() {
        for p in [1e-12, 1e-6, 0.01, 0.0243, 0.1, 0.5, 0.9, 0.99, 1.0 - 1e-9] {
            let x = normal_quantile(p);
            assert!((normal_cdf(x) / p - 1.0).abs() < 1e-12, "{p}: {x}");
        }
        // Tabled quantiles.
        assert!((normal_quantile(0.975) - 1.959963984540054).abs() < 1e-12);
        assert!((normal_quantile(0.9) - 1.2815515655446004).abs() < 1e-12);
    }
}
