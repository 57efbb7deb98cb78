//! Mesh orders of the transmission error (MODEL §16): the loaded TE over one tooth pitch is
//! periodic at the mesh frequency; the amplitudes of its orders 1..k of that frequency, with
//! the unloaded kinematic error's beside them, are the form NVH engineers read. Radians of
//! wheel rotation throughout.

use super::Ltca;

/// Amplitudes of the mesh orders 1..k of a periodic signal sampled at n equally spaced instants
/// over one period (one tooth pitch), in the signal's units: 2 |c_h| with
/// c_h = (1/n) sum_j x_j exp(-2 pi i h j / n), for h = 1..k, k the largest order below n / 2
/// (an even n's order n / 2 is left out: its phase is not resolved). A sampled
/// a cos(2 pi h t + phi) gives a at order h and nothing at the others.
pub fn mesh_order_amplitudes(samples: &[f64]) -> Vec<f64> {
    let n = samples.len();
    let k = n.saturating_sub(1) / 2;
    (1..=k)
        .map(|h| {
            let (re, im) = samples
                .iter()
                .enumerate()
                .fold((0.0, 0.0), |(re, im), (j, x)| {
                    let phase = 2.0 * std::f64::consts::PI * (h * j % n) as f64 / n as f64;
                    (re + x * phase.cos(), im - x * phase.sin())
                });
            2.0 * re.hypot(im) / n as f64
        })
        .collect()
}

/// The mesh orders of one loaded analysis (MODEL §16): amplitudes at orders 1, 2, ..., k of the
/// mesh frequency, k the largest below half the positions per pitch, rad.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TeOrders {
    /// Of the loaded transmission error.
    pub loaded_rad: Vec<f64>,
    /// Of the unloaded kinematic error of the same flank.
    pub unloaded_rad: Vec<f64>,
}

impl TeOrders {
    /// From the loaded TE and the unloaded kinematic error at the positions, in their order
    /// over one pitch, rad.
    pub fn of(loaded: &[f64], unloaded: &[f64]) -> Self {
        Self {
            loaded_rad: mesh_order_amplitudes(loaded),
            unloaded_rad: mesh_order_amplitudes(unloaded),
        }
    }
}

impl Ltca {
    /// The mesh orders of the loaded TE and of the unloaded kinematic error (the TE plus the
    /// rigid approach at each position: the KE of the flank the unloaded analysis saw, the
    /// unworn one in a life, whose states record their worn flank's), MODEL §16.
    pub fn te_orders(&self) -> TeOrders {
        let loaded: Vec<f64> = self
            .positions
            .iter()
            .map(|p| p.transmission_error)
            .collect();
        let unloaded: Vec<f64> = self
            .positions
            .iter()
            .map(|p| p.transmission_error + p.approach)
            .collect();
        TeOrders::of(&loaded, &unloaded)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn sampled(n: usize, f: impl Fn(f64) -> f64) -> Vec<f64> {
        (0..n).map(|j| f(j as f64 / n as f64)).collect()
    }

    #[test]
    fn a_sampled_harmonic_gives_its_amplitude_at_its_order_alone() {
        for n in [20, 21] {
            let x = sampled(n, |t| 3.0 + 2.0 * (2.0 * PI * 3.0 * t + 0.7).cos());
            let a = mesh_order_amplitudes(&x);
            assert_eq!(a.len(), if n == 20 { 9 } else { 10 });
            for (h, v) in a.iter().enumerate() {
                let expected = if h + 1 == 3 { 2.0 } else { 0.0 };
                assert!((v - expected).abs() < 1e-12, "n {n}, order {}: {v}", h + 1);
            }
        }
        // A constant (the mean TE) has no order.
        assert!(mesh_order_amplitudes(&[5.0; 20])
            .iter()
            .all(|&a| a.abs() < 1e-12));
    }

    #[test]
    fn the_orders_carry_the_signals_variance_parseval() {
        // An odd count resolves every order: the variance is the sum of a_h^2 / 2.
        let x = sampled(21, |t| (7.0 * t).sin() + (t * t * 13.0).cos() - 4.0 * t);
        let mean = x.iter().sum::<f64>() / x.len() as f64;
        let variance = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / x.len() as f64;
        let power: f64 = mesh_order_amplitudes(&x).iter().map(|a| a * a / 2.0).sum();
        assert!(
            (power / variance - 1.0).abs() < 1e-12,
            "{power} vs {variance}"
        );
    }
}
