//! Determining the Archard coefficient K (MODEL §10): from wear tests (worn volume, sliding
//! length and the load carried by the asperities, by least squares), and from a measured
//! backlash-versus-cycles curve (inverse problem through the life simulation).

use crate::wear::{StepRecord, WearError};

/// Fraction of the apparent contact area in asperity contact (MODEL §10):
/// A_c / A_0 = (1/2)(1/2)(1 - erf(h / (sqrt(2) sigma))), h the film thickness Phi_T h_min and
/// sigma the composite RMS roughness R_q (both m). 1/4 with no film, tends to 0 as h >> sigma.
pub fn asperity_area_fraction(film_thickness: f64, roughness_rq: f64) -> f64 {
    0.25 * (1.0 - libm::erf(film_thickness / (std::f64::consts::SQRT_2 * roughness_rq)))
}

/// Load carried by the asperities, N (MODEL §10): W_asp = (W_sec / A_c)(A_c / A_0) A_0 with
/// W_sec / A_c = 0.2 E' sqrt(m2 / pi), m2 = Rdq^2 the mean square profile slope. `e_prime` the
/// reduced modulus E' (Pa, MODEL §6), `apparent_area` A_0 (m^2).
pub fn asperity_load(
    e_prime: f64,
    slope_rdq: f64,
    film_thickness: f64,
    roughness_rq: f64,
    apparent_area: f64,
) -> f64 {
    0.2 * e_prime
        * (slope_rdq * slope_rdq / std::f64::consts::PI).sqrt()
        * asperity_area_fraction(film_thickness, roughness_rq)
        * apparent_area
}

/// One wear test (pin-on-disc, twin-disc or gear rig) reduced to MODEL §10's quantities, SI.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WearTest {
    /// Worn volume V, m^3.
    pub worn_volume: f64,
    /// Sliding length L, m.
    pub sliding_length: f64,
    /// Load carried by the asperities W_asp, N ([`asperity_load`]).
    pub asperity_load: f64,
}

/// Result of a least-squares fit of K.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct KFit {
    /// Archard coefficient K (dimensionless).
    pub k: f64,
    /// Root mean square of the relative residuals (V_fit - V) / V.
    pub relative_rms: f64,
    /// Number of data points used.
    pub points: usize,
}

/// Errors of the calibration.
#[derive(Debug, thiserror::Error)]
pub enum CalibrationError {
    #[error("calibration needs at least one data point with a positive {0}")]
    NoData(&'static str),
    #[error("calibration data point {index}: {field} = {value} (must be finite and >= 0)")]
    BadValue {
        index: usize,
        field: &'static str,
        value: f64,
    },
    #[error("the simulated backlash does not grow (it is {0} m at the last measured point): K cannot be fitted")]
    NoSensitivity(f64),
    #[error("life simulation: {0}")]
    Simulation(#[from] WearError),
    /// The geometry, unloaded analysis or bending model the lives need could not be built.
    #[error("life simulation set-up")]
    Setup(#[source] crate::RunError),
    /// The fitted life ends (at a wear limit) before the last measured point, which the fit
    /// then could not use.
    #[error(
        "the simulated life with the fitted K = {k:.4e} ends at {simulated:.4e} cycles (a wear \
         limit: see wear.limits), before the measured point at {measured:.4e} cycles: the \
         measured backlash is beyond the model's wear limits"
    )]
    LifeEnded {
        k: f64,
        simulated: f64,
        measured: f64,
    },
}

/// K from wear tests by least squares through the origin of V = (K / H) W_asp L (MODEL §10):
/// K = H sum(V x) / sum(x^2), x = W_asp L. `hardness` H of the worn member, Pa.
pub fn fit_from_tests(tests: &[WearTest], hardness: f64) -> Result<KFit, CalibrationError> {
    for (index, t) in tests.iter().enumerate() {
        for (field, value) in [
            ("worn_volume", t.worn_volume),
            ("sliding_length", t.sliding_length),
            ("asperity_load", t.asperity_load),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(CalibrationError::BadValue {
                    index,
                    field,
                    value,
                });
            }
        }
    }
    let x: Vec<f64> = tests
        .iter()
        .map(|t| t.asperity_load * t.sliding_length / hardness)
        .collect();
    let sxx: f64 = x.iter().map(|v| v * v).sum();
    if sxx <= 0.0 {
        return Err(CalibrationError::NoData("asperity load x sliding length"));
    }
    let sxv: f64 = x.iter().zip(tests).map(|(x, t)| x * t.worn_volume).sum();
    let k = sxv / sxx;
    Ok(KFit {
        k,
        relative_rms: relative_rms(tests.iter().zip(&x).map(|(t, x)| (k * x, t.worn_volume))),
        points: tests.len(),
    })
}

fn relative_rms(pairs: impl Iterator<Item = (f64, f64)>) -> f64 {
    let (mut s, mut n) = (0.0, 0);
    for (fit, measured) in pairs {
        if measured > 0.0 {
            s += ((fit - measured) / measured).powi(2);
            n += 1;
        }
    }
    if n > 0 {
        (s / n as f64).sqrt()
    } else {
        0.0
    }
}

/// Backlash increase of the records at `cycles`, linear between records (m); None beyond them.
pub fn backlash_at(records: &[StepRecord], cycles: f64) -> Option<f64> {
    let k = records.iter().position(|r| r.cycles >= cycles)?;
    if k == 0 {
        return Some(records[0].backlash_increase_m);
    }
    let (a, b) = (&records[k - 1], &records[k]);
    let t = if b.cycles > a.cycles {
        (cycles - a.cycles) / (b.cycles - a.cycles)
    } else {
        1.0
    };
    Some(a.backlash_increase_m + t * (b.backlash_increase_m - a.backlash_increase_m))
}

/// K from a measured backlash increase curve, `measured` = (wheel cycles, backlash increase m,
/// tangential at r2 as on test rigs), by the inverse problem: `simulate(K)` runs the life (to at
/// least the last measured cycles) and returns its records; K is scaled by the least-squares
/// factor sum(b_meas b_sim) / sum(b_sim^2) until it changes by less than `tolerance` (relative;
/// the backlash is nearly proportional to K, so this converges in a few runs). Starts from
/// `k_start`; at most `max_runs` simulations. Returns the fit and the records of the last run.
pub fn fit_to_backlash(
    measured: &[(f64, f64)],
    k_start: f64,
    tolerance: f64,
    max_runs: usize,
    simulate: &mut dyn FnMut(f64) -> Result<Vec<StepRecord>, WearError>,
) -> Result<(KFit, Vec<StepRecord>), CalibrationError> {
    for (index, &(c, b)) in measured.iter().enumerate() {
        for (field, value) in [("cycles", c), ("backlash", b)] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(CalibrationError::BadValue {
                    index,
                    field,
                    value,
                });
            }
        }
    }
    if !measured.iter().any(|&(_, b)| b > 0.0) {
        return Err(CalibrationError::NoData("backlash increase"));
    }
    let mut k = k_start;
    let mut runs = 0;
    loop {
        let records = simulate(k)?;
        runs += 1;
        let pairs: Vec<(f64, f64)> = measured
            .iter()
            .filter_map(|&(c, b)| backlash_at(&records, c).map(|s| (s, b)))
            .collect();
        let sss: f64 = pairs.iter().map(|(s, _)| s * s).sum();
        if sss <= 0.0 {
            return Err(CalibrationError::NoSensitivity(
                pairs.last().map_or(0.0, |p| p.0),
            ));
        }
        let factor = pairs.iter().map(|(s, b)| s * b).sum::<f64>() / sss;
        if (factor - 1.0).abs() < tolerance || runs >= max_runs {
            let simulated = records.last().map_or(0.0, |r| r.cycles);
            let measured_end = measured.iter().map(|m| m.0).fold(0.0, f64::max);
            if pairs.len() < measured.len() {
                return Err(CalibrationError::LifeEnded {
                    k,
                    simulated,
                    measured: measured_end,
                });
            }
            return Ok((
                KFit {
                    k,
                    relative_rms: relative_rms(pairs.into_iter()),
                    points: measured.len(),
                },
                records,
            ));
        }
        k *= factor;
    }
}

/// [`fit_to_backlash`] through the gear's life simulation (MODEL §10): the geometry, unloaded
/// analysis and bending model are built once (the bending model reported to `on_event`), then
/// each run is the life of `plan` from the unworn flank with the wheel's wear coefficient set
/// to the trial K; `on_run(run, K, records)` is told each. Returns the fit, the records of the
/// last run and the number of runs.
pub fn fit_life_to_backlash(
    gear: &crate::input::GearSet,
    plan: &crate::input::WearPlan,
    measured: &[(f64, f64)],
    on_event: &mut dyn FnMut(crate::Event) -> Result<(), crate::RunError>,
    on_run: &mut dyn FnMut(usize, f64, &[StepRecord]),
) -> Result<(KFit, Vec<StepRecord>, usize), CalibrationError> {
    use crate::RunError;
    let setup = CalibrationError::Setup;
    let geo = crate::geometry::Geometry::build(gear).map_err(|e| setup(RunError::Geometry(e)))?;
    let tca = crate::kinematics::analyse(gear, &geo).map_err(|e| setup(RunError::Tca(e)))?;
    let mut warnings = Vec::new();
    let (bending, _) =
        crate::runner::bending_model(gear, &geo, &mut warnings, on_event).map_err(setup)?;
    let settings = crate::ltca::LtcaSettings::from_gear(gear);
    let mut runs = 0;
    let mut simulate = |k: f64| {
        let mut g = gear.clone();
        g.wheel_material.wear_coefficient = k;
        runs += 1;
        let end = crate::wear::simulate(
            &g,
            &geo,
            &tca,
            &settings,
            bending
                .as_ref()
                .map(|b| b as &dyn crate::ltca::BendingModel),
            plan,
            crate::wear::WearState::new(geo.wheel_flank(tca.loaded_flank)),
            &mut |_| Ok(()),
        )?;
        on_run(runs, k, &end.records);
        Ok(end.records)
    };
    let k_start = gear.wheel_material.wear_coefficient;
    let (fit, records) = fit_to_backlash(measured, k_start, 1e-3, 10, &mut simulate)?;
    Ok((fit, records, runs))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn asperity_contact_is_a_quarter_without_film_and_vanishes_with_a_thick_one() {
        assert!((asperity_area_fraction(0.0, 1e-6) - 0.25).abs() < 1e-15);
        // h = sqrt(2) sigma: erf(1) = 0.8427007929.
        let f = asperity_area_fraction(2f64.sqrt() * 1e-6, 1e-6);
        assert!((f - 0.25 * (1.0 - 0.842_700_792_949_714_9)).abs() < 1e-12);
        assert!(asperity_area_fraction(10e-6, 1e-6) < 1e-20);
        // W_sec / A_c = 0.2 E' sqrt(m2 / pi): with no film, a quarter of it times A_0.
        let w = asperity_load(2e11, 0.1, 0.0, 1e-6, 1e-4);
        assert!((w - 0.2 * 2e11 * (0.01 / std::f64::consts::PI).sqrt() * 0.25 * 1e-4).abs() < 1e-3);
    }

    #[test]
    fn tests_generated_with_a_known_k_give_it_back() {
        let (k, h) = (3.1e-8, 1e9);
        let tests: Vec<WearTest> = [(120.0, 900.0), (80.0, 2500.0), (300.0, 400.0)]
            .iter()
            .map(|&(w, l)| WearTest {
                worn_volume: k / h * w * l,
                sliding_length: l,
                asperity_load: w,
            })
            .collect();
        let fit = fit_from_tests(&tests, h).unwrap();
        assert!((fit.k / k - 1.0).abs() < 1e-12);
        assert!(fit.relative_rms < 1e-12);
        // Scatter: +10 % on one test moves K between the two and leaves a residual.
        let mut noisy = tests.clone();
        noisy[0].worn_volume *= 1.1;
        let fit = fit_from_tests(&noisy, h).unwrap();
        assert!(fit.k > k && fit.k < 1.1 * k && fit.relative_rms > 0.01);
        // Bad data are named.
        noisy[1].sliding_length = f64::NAN;
        let e = fit_from_tests(&noisy, h).unwrap_err().to_string();
        assert!(
            e.contains("data point 1") && e.contains("sliding_length"),
            "{e}"
        );
        assert!(fit_from_tests(&[], h).is_err());
    }
}
