//! Thread relations of the bending models (MODEL §5.5): the low-rank term that couples the
//! cells of neighbouring wheel teeth or worm threads through the fitted relation blocks (same
//! tooth, the one before, the one after), its positive semi-definite core per pattern of teeth
//! present, cached. Shared by the worm and the wheel models.
use super::basis::Basis;
use crate::ltca::solver::LowRank;
use faer::Mat;

/// The cores of [`relation_low_rank`] per pattern of groups present (their offsets from the
/// first), computed once: a model's positions only ever see a few patterns (2-4 consecutive
/// teeth). Not serialised; a clone starts empty.
#[derive(Debug, Default)]
pub(crate) struct CoreCache(
    std::sync::Mutex<std::collections::HashMap<Vec<i64>, std::sync::Arc<Vec<f64>>>>,
);

impl Clone for CoreCache {
    fn clone(&self) -> Self {
        Self::default()
    }
}

/// The core of the groups `present` (sorted, distinct): blocks same / before / after between
/// neighbours, zero beyond, symmetrised, then projected on the positive semi-definite matrices
/// (negative eigenvalues set to zero). A compliance is positive semi-definite (the strain
/// energy of any load is >= 0); the assembled fits of three teeth are not quite (the 1/40
/// wheel: eigenvalues down to -0.2 % of the largest, from the fits' errors and the relations
/// beyond a neighbour left out), and an indefinite term can stop the contact solver from
/// converging on widened bands. The projection is the nearest PSD matrix in the Frobenius norm.
pub(crate) fn relation_core(
    same: &Mat<f64>,
    before: &Mat<f64>,
    after: &Mat<f64>,
    present: &[i64],
) -> Vec<f64> {
    let k = same.nrows();
    let rank = k * present.len();
    let mut core = nalgebra::DMatrix::<f64>::zeros(rank, rank);
    for (a, &ta) in present.iter().enumerate() {
        for (b, &tb) in present.iter().enumerate() {
            let m = match ta - tb {
                0 => same,
                -1 => before,
                1 => after,
                _ => continue,
            };
            for l in 0..k {
                for c in 0..k {
                    core[(a * k + l, b * k + c)] = m[(l, c)];
                }
            }
        }
    }
    let core = (&core + core.transpose()) * 0.5;
    let eigen = core.symmetric_eigen();
    let clipped =
        nalgebra::DVector::from_iterator(rank, eigen.eigenvalues.iter().map(|&v| v.max(0.0)));
    let v = &eigen.eigenvectors;
    let psd = v * nalgebra::DMatrix::from_diagonal(&clipped) * v.transpose();
    let psd = (&psd + psd.transpose()) * 0.5;
    // Row-major.
    (0..rank * rank)
        .map(|x| psd[(x / rank, x % rank)])
        .collect()
}

/// The rows of a thread-relation term: cells grouped by `group` (tooth or thread index), each
/// row's basis values in F's columns `offset + t k .. offset + (t + 1) k` (t the group's rank
/// among those present, k the basis size), written packed at `packed[i stride + at..][..k]`
/// (row i of rows of `stride` values, [`LowRank::packed`]). Returns the groups present (sorted)
/// and each row's column range in F.
pub(crate) fn relation_rows(
    basis: &Basis,
    groups: &[i64],
    coords: &[(f64, f64)],
    (packed, stride, at): (&mut [f64], usize, usize),
    offset: usize,
) -> (Vec<i64>, Vec<(usize, usize)>) {
    let mut present: Vec<i64> = groups.to_vec();
    present.sort_unstable();
    present.dedup();
    let k = basis.len();
    let mut ranges = Vec::with_capacity(groups.len());
    // The width functions of the previous point, reused while w~ repeats (a slice's cells on
    // the wheel share their face position).
    let mut width: Option<(f64, Vec<f64>)> = None;
    for (i, (&g, &(r, w))) in groups.iter().zip(coords).enumerate() {
        let t = present.binary_search(&g).unwrap_or(0);
        let (a, b) = (offset + t * k, offset + (t + 1) * k);
        ranges.push((a, b));
        // Points outside the fitted zone take the value at its edge: the beam modes grow
        // exponentially outside [0, 1].
        let w = w.clamp(0.0, 1.0);
        if width
            .as_ref()
            .is_none_or(|(at, _)| at.to_bits() != w.to_bits())
        {
            width = Some((w, basis.width_values(w)));
        }
        let hw = width
            .as_ref()
            .map(|(_, hw)| hw.as_slice())
            .unwrap_or_default();
        basis.eval_into(
            r.clamp(0.0, 1.0),
            hw,
            &mut packed[i * stride + at..i * stride + at + k],
        );
    }
    (present, ranges)
}

/// The core of `present` groups from `cache` ([`relation_core`], computed once per pattern),
/// row-major.
pub(crate) fn cached_core(
    same: &Mat<f64>,
    before: &Mat<f64>,
    after: &Mat<f64>,
    present: &[i64],
    cache: &CoreCache,
) -> std::sync::Arc<Vec<f64>> {
    let pattern: Vec<i64> = present.iter().map(|g| g - present[0]).collect();
    if let Some(c) = cache.0.lock().ok().and_then(|m| m.get(&pattern).cloned()) {
        return c;
    }
    let c = std::sync::Arc::new(relation_core(same, before, after, present));
    if let Ok(mut m) = cache.0.lock() {
        m.insert(pattern, c.clone());
    }
    c
}

/// Thread-relation low-rank term of one member alone ([`relation_rows`], [`cached_core`]).
pub(crate) fn relation_low_rank(
    basis: &Basis,
    same: &Mat<f64>,
    before: &Mat<f64>,
    after: &Mat<f64>,
    groups: &[i64],
    coords: &[(f64, f64)],
    cache: &CoreCache,
) -> LowRank {
    let mut present: Vec<i64> = groups.to_vec();
    present.sort_unstable();
    present.dedup();
    let (rank, k) = (basis.len() * present.len(), basis.len());
    let mut packed = vec![0.0; groups.len() * k];
    let (present, rows) = relation_rows(basis, groups, coords, (&mut packed, k, 0), 0);
    let core = cached_core(same, before, after, &present, cache);
    let ranges = rows.into_iter().map(|r| [r, (0, 0), (0, 0)]).collect();
    LowRank::packed(rank, packed, k, core.as_ref().clone(), ranges)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relation_cores_are_positive_semi_definite_and_unchanged_when_they_are() {
        // A PSD "same" block with neighbour blocks that make the assembled three-group matrix
        // indefinite: the projection removes the negative part only (nearest PSD matrix); a
        // PSD assembly (no neighbours) comes back as it was.
        let k = 4;
        let same = Mat::<f64>::from_fn(k, k, |i, j| if i == j { 2.0 + i as f64 } else { 0.3 });
        let strong = Mat::<f64>::from_fn(k, k, |i, j| if i == j { 2.5 } else { 0.0 });
        let none = Mat::<f64>::zeros(k, k);
        let present = [0, 1, 2];
        let eig = |c: &[f64]| {
            let n = (c.len() as f64).sqrt() as usize;
            nalgebra::DMatrix::from_row_slice(n, n, c).symmetric_eigenvalues()
        };
        let projected = relation_core(&same, &strong, &strong, &present);
        let raw_min = {
            let mut m = nalgebra::DMatrix::<f64>::zeros(3 * k, 3 * k);
            for a in 0..3 {
                for b in 0..3 {
                    let blk = match a as i64 - b as i64 {
                        0 => &same,
                        -1 | 1 => &strong,
                        _ => continue,
                    };
                    for l in 0..k {
                        for c in 0..k {
                            m[(a * k + l, b * k + c)] = blk[(l, c)];
                        }
                    }
                }
            }
            m.symmetric_eigenvalues().min()
        };
        assert!(raw_min < -0.1, "the test matrix is indefinite: {raw_min}");
        assert!(eig(&projected).min() > -1e-12);
        let kept = relation_core(&same, &none, &none, &present);
        for a in 0..3 {
            for l in 0..k {
                for c in 0..k {
                    let v = kept[(a * k + l) * 3 * k + a * k + c];
                    assert!((v - same[(l, c)]).abs() < 1e-12);
                }
            }
        }
    }
}
