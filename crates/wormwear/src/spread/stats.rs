//! The statistics of a spread (MODEL §17): percentiles of a result over the samples, and the
//! rank correlation of a result with an input (Spearman's rho), the sensitivity it reports;
//! with Saltelli's design, each input's first-order and total Sobol indices.

/// The `q`-quantile (0..=1) of `values` (finite ones only; None when there are none): linear
/// interpolation between the order statistics at (n - 1) q (Hyndman & Fan's type 7, the
/// default of R and numpy).
pub fn percentile(values: &[f64], q: f64) -> Option<f64> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let h = (v.len() - 1) as f64 * q.clamp(0.0, 1.0);
    let (lo, hi) = (h.floor() as usize, h.ceil() as usize);
    Some(v[lo] + (h - lo as f64) * (v[hi] - v[lo]))
}

/// The ranks of `values` from 1, ties given their mean rank.
pub fn ranks(values: &[f64]) -> Vec<f64> {
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
    let mut out = vec![0.0; values.len()];
    let mut i = 0;
    while i < order.len() {
        let mut j = i;
        while j + 1 < order.len() && values[order[j + 1]] == values[order[i]] {
            j += 1;
        }
        let mean = 0.5 * (i + j) as f64 + 1.0;
        for &k in &order[i..=j] {
            out[k] = mean;
        }
        i = j + 1;
    }
    out
}

/// Pearson's correlation of two equally long series (None: fewer than 2 points or a constant
/// series).
pub fn pearson(x: &[f64], y: &[f64]) -> Option<f64> {
    let n = x.len().min(y.len());
    if n < 2 {
        return None;
    }
    let (mx, my) = (
        x.iter().sum::<f64>() / n as f64,
        y.iter().sum::<f64>() / n as f64,
    );
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        sxy += (a - mx) * (b - my);
        sxx += (a - mx) * (a - mx);
        syy += (b - my) * (b - my);
    }
    (sxx > 0.0 && syy > 0.0).then(|| sxy / (sxx * syy).sqrt())
}

/// Spearman's rank correlation of the pairs where both are finite (None: fewer than 3 such
/// pairs, or a constant series).
pub fn spearman(x: &[f64], y: &[f64]) -> Option<f64> {
    let (a, b): (Vec<f64>, Vec<f64>) = x
        .iter()
        .zip(y)
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .map(|(a, b)| (*a, *b))
        .unzip();
    if a.len() < 3 {
        return None;
    }
    pearson(&ranks(&a), &ranks(&b))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_interpolate_the_order_statistics() {
        let v: Vec<f64> = (1..=11).map(f64::from).rev().collect();
        assert_eq!(percentile(&v, 0.5), Some(6.0));
        assert_eq!(percentile(&v, 0.1), Some(2.0));
        assert_eq!(percentile(&v, 0.0), Some(1.0));
        assert_eq!(percentile(&v, 1.0), Some(11.0));
        // numpy.percentile([1, 2, 3, 4], 90) = 3.7.
        assert!((percentile(&[4.0, 1.0, 3.0, 2.0], 0.9).unwrap() - 3.7).abs() < 1e-12);
        assert_eq!(percentile(&[f64::NAN], 0.5), None);
    }

    #[test]
    fn ties_share_their_mean_rank_and_a_monotone_map_correlates_fully() {
        assert_eq!(ranks(&[10.0, 20.0, 20.0, 5.0]), vec![2.0, 3.5, 3.5, 1.0]);
        let x: Vec<f64> = (0..20).map(|k| k as f64 * 0.1).collect();
        let y: Vec<f64> = x.iter().map(|v| v.exp()).collect();
        assert!((spearman(&x, &y).unwrap() - 1.0).abs() < 1e-12);
        let z: Vec<f64> = x.iter().map(|v| -v * v * v).collect();
        assert!((spearman(&x, &z).unwrap() + 1.0).abs() < 1e-12);
        assert_eq!(spearman(&x, &[1.0; 20]), None);
    }
}

/// A first-order and a total Sobol index of one input.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SobolIndex {
    pub first: f64,
    pub total: f64,
}

/// Each input's Sobol indices from the outputs `y` of Saltelli's design
/// ([`super::sampling::saltelli`]: blocks A, B, A_B^1, ... of `base` rows): the first-order
/// S_i = (1/N) sum f(B) (f(A_B^i) - f(A)) / V (Saltelli et al. 2010, Table 2 (b)) and the
/// total S_Ti = (1/2N) sum (f(A) - f(A_B^i))^2 / V (Jansen's estimator, ibid. (f)), V the
/// variance of f over A and B. Rows where a needed value is not finite are left out; None
/// where fewer than 2 rows remain or V = 0.
pub fn sobol_indices(y: &[f64], base: usize, dims: usize) -> Vec<Option<SobolIndex>> {
    let block = |k: usize| &y[k * base..(k + 1) * base];
    let (a, b) = (block(0), block(1));
    let both: Vec<f64> = a
        .iter()
        .chain(b)
        .copied()
        .filter(|v| v.is_finite())
        .collect();
    let variance = if both.len() < 2 {
        0.0
    } else {
        let mean = both.iter().sum::<f64>() / both.len() as f64;
        both.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (both.len() - 1) as f64
    };
    (0..dims)
        .map(|i| {
            let ab = block(2 + i);
            let rows: Vec<(f64, f64, f64)> = (0..base)
                .map(|j| (a[j], b[j], ab[j]))
                .filter(|(fa, fb, fab)| fa.is_finite() && fb.is_finite() && fab.is_finite())
                .collect();
            if rows.len() < 2 || variance <= 0.0 {
                return None;
            }
            let n = rows.len() as f64;
            let first = rows
                .iter()
                .map(|(fa, fb, fab)| fb * (fab - fa))
                .sum::<f64>()
                / n;
            let total = rows
                .iter()
                .map(|(fa, _, fab)| (fa - fab).powi(2))
                .sum::<f64>()
                / (2.0 * n);
            Some(SobolIndex {
                first: first / variance,
                total: total / variance,
            })
        })
        .collect()
}
