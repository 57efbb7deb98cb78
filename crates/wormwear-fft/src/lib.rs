//! Forward and inverse FFT plans in double precision, built by rustfft's and realfft's
//! planners. The functions are not generic, so the planners' algorithms are compiled in this
//! crate only; callers use the plans through their trait objects.

use std::sync::Arc;

pub use realfft::num_complex::Complex;
pub use realfft::{ComplexToReal, RealToComplex};
pub use rustfft::Fft;

/// Forward and inverse plans of the real-to-complex transform of `len` real values (any
/// length; `len / 2 + 1` complex values on the spectrum side).
pub fn real_plans(len: usize) -> (Arc<dyn RealToComplex<f64>>, Arc<dyn ComplexToReal<f64>>) {
    let mut planner = realfft::RealFftPlanner::<f64>::new();
    (planner.plan_fft_forward(len), planner.plan_fft_inverse(len))
}

/// Forward and inverse plans of the complex transform of `len` values (unnormalised, as
/// rustfft's).
pub fn complex_plans(len: usize) -> (Arc<dyn Fft<f64>>, Arc<dyn Fft<f64>>) {
    let mut planner = rustfft::FftPlanner::<f64>::new();
    (planner.plan_fft_forward(len), planner.plan_fft_inverse(len))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_real_transform_and_its_inverse_return_the_signal_times_its_length() {
        for len in [1, 6, 7, 31, 64] {
            let (forward, inverse) = real_plans(len);
            let signal: Vec<f64> = (0..len).map(|i| ((i * 7 + 3) % 11) as f64 - 4.5).collect();
            let mut input = signal.clone();
            let mut spectrum = forward.make_output_vec();
            forward.process(&mut input, &mut spectrum).unwrap();
            // The zero frequency is the sum.
            let sum: f64 = signal.iter().sum();
            assert!((spectrum[0].re - sum).abs() < 1e-12 * (1.0 + sum.abs()));
            let mut back = inverse.make_output_vec();
            inverse.process(&mut spectrum, &mut back).unwrap();
            for (b, s) in back.iter().zip(&signal) {
                assert!((b / len as f64 - s).abs() < 1e-12, "{len}: {b} vs {s}");
            }
        }
    }

    #[test]
    fn a_complex_transform_of_a_shifted_impulse_is_a_unit_phasor() {
        let len = 12;
        let (forward, inverse) = complex_plans(len);
        let mut x = vec![Complex::new(0.0, 0.0); len];
        x[1] = Complex::new(1.0, 0.0);
        forward.process(&mut x);
        for (k, v) in x.iter().enumerate() {
            let angle = -2.0 * std::f64::consts::PI * k as f64 / len as f64;
            assert!((v.re - angle.cos()).abs() < 1e-12 && (v.im - angle.sin()).abs() < 1e-12);
        }
        inverse.process(&mut x);
        assert!((x[1].re - len as f64).abs() < 1e-12 && x[0].norm() < 1e-12);
    }
}
