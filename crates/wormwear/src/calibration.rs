//! Determining the Archard coefficient K (MODEL §10): from wear tests (worn volume, sliding
//! length and the load carried by the asperities, by least squares), and from a measured
//! backlash-versus-cycles curve (inverse problem through the life simulation).

use crate::wear::{StepRecord, WearError};

pub use crate::lubrication::{asperity_area_fraction, asperity_load};

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
    /// The pressure–life curve's life factor fitted with K (a pitting forecast's backlash
    /// curve, [`fit_with_life_factor`]); None when K alone was fitted.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub life_factor: Option<f64>,
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
        life_factor: None,
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

pub use crate::wear::backlash_at;

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
                    life_factor: None,
                },
                records,
            ));
        }
        k *= factor;
    }
}

/// Range of the life factor [`fit_with_life_factor`] searches: a decade either side of
/// the fitted curve, wider than the bronze's scatter band (about 150 MPa wide around
/// 425 MPa, MODEL §8: life factors of 0.4 to 3 with the exponent 0.176).
pub const LIFE_FACTOR_RANGE: (f64, f64) = (0.1, 10.0);

/// Where a backlash curve first stays flat (a pitting phase: no wear, MODEL §8): the cycles
/// of the first point after which the backlash grows by less than 5 % of the curve's mean
/// rate (increase over cycles) up to the next point. None if it never does.
pub fn first_flat(points: &[(f64, f64)]) -> Option<f64> {
    let (first, last) = (points.first()?, points.last()?);
    let mean = (last.1 - first.1) / (last.0 - first.0).max(f64::MIN_POSITIVE);
    points
        .windows(2)
        .find(|w| w[1].0 > w[0].0 && (w[1].1 - w[0].1) <= 0.05 * mean * (w[1].0 - w[0].0))
        .map(|w| w[0].0)
}

/// The first pitting phase's start in a life's records (cycles; None: it has none).
pub fn first_pitting(records: &[StepRecord]) -> Option<f64> {
    records
        .iter()
        .find(|r| r.phase == "pitting")
        .map(|r| r.cycles)
}

/// Why the life factor cannot be fitted.
fn no_life_factor(what: String) -> CalibrationError {
    CalibrationError::Simulation(WearError::Plan(format!(
        "the life factor of the pressure-life curve cannot be fitted: {what}"
    )))
}

/// K and the life factor of the pressure–life curve from a measured backlash curve, for a
/// pitting forecast (MODEL §10, §8). The life factor moves the phases a forecast finds along
/// the life axis; K sets the slopes between them. So the life factor is set to put the
/// forecast's first pitting phase where the measured curve first stays flat ([`first_flat`]),
/// and K by [`fit_to_backlash`] to the points up to there (the first wear phase, where the
/// backlash follows K smoothly: later phases come and go with small changes of K, and a
/// least-squares K over them need not converge), in turn until neither changes by 0.01 %
/// (at most 8 rounds). The residual is over every point. The life factor is solved by the Illinois method in log f over
/// [`LIFE_FACTOR_RANGE`] (the first pitting comes later as f grows; a life without pitting
/// counts as latest). `simulate(K, f)` runs the life. Returns the fit (with its life factor)
/// and the records of the last run.
pub fn fit_with_life_factor(
    measured: &[(f64, f64)],
    k_start: f64,
    simulate: &mut dyn FnMut(f64, f64) -> Result<Vec<StepRecord>, WearError>,
) -> Result<(KFit, Vec<StepRecord>), CalibrationError> {
    let target = first_flat(measured)
        .filter(|&c| c > 0.0)
        .ok_or_else(|| no_life_factor("the measured backlash never stays flat".into()))?;
    let before: Vec<(f64, f64)> = measured
        .iter()
        .copied()
        .filter(|m| m.0 <= target * (1.0 + 1e-12))
        .collect();
    let (mut k, mut f) = (k_start, 1.0);
    let mut records = Vec::new();
    for _ in 0..8 {
        let (fit, _) = fit_to_backlash(&before, k, 1e-6, 20, &mut |k| simulate(k, f))?;
        let k_change = (fit.k / k - 1.0).abs();
        k = fit.k;
        let f_new = solve_life_factor(target, &mut |f| simulate(k, f))?;
        let f_change = (f_new / f - 1.0).abs();
        f = f_new;
        if f_change < 1e-4 && k_change < 1e-4 {
            records = simulate(k, f)?;
            break;
        }
    }
    if records.is_empty() {
        records = simulate(k, f)?;
    }
    let pairs: Vec<(f64, f64)> = measured
        .iter()
        .filter_map(|&(c, b)| backlash_at(&records, c).map(|s| (s, b)))
        .collect();
    if pairs.len() < measured.len() {
        return Err(CalibrationError::LifeEnded {
            k,
            simulated: records.last().map_or(0.0, |r| r.cycles),
            measured: measured.iter().map(|m| m.0).fold(0.0, f64::max),
        });
    }
    let fit = KFit {
        k,
        relative_rms: relative_rms(pairs.into_iter()),
        points: measured.len(),
        life_factor: Some(f),
    };
    Ok((fit, records))
}

/// The life factor whose forecast starts its first pitting phase at `target` cycles.
fn solve_life_factor(
    target: f64,
    simulate: &mut dyn FnMut(f64) -> Result<Vec<StepRecord>, WearError>,
) -> Result<f64, CalibrationError> {
    // Signed log-distance of the first pitting from the target (a life without one: latest).
    let mut miss = |x: f64| -> Result<f64, CalibrationError> {
        let records = simulate(x.exp())?;
        Ok(first_pitting(&records).map_or(10.0, |c| (c.max(1.0) / target).ln()))
    };
    let (a, b) = (LIFE_FACTOR_RANGE.0.ln(), LIFE_FACTOR_RANGE.1.ln());
    let (ya, yb) = (miss(a)?, miss(b)?);
    if ya > 0.0 || yb < 0.0 {
        return Err(no_life_factor(format!(
            "the first flat part of the measured curve ({target:.4e} cycles) is outside the \
             forecast's first pitting for life factors {} to {}",
            LIFE_FACTOR_RANGE.0, LIFE_FACTOR_RANGE.1
        )));
    }
    let x = crate::geometry::roots::illinois(
        miss,
        (a, ya),
        (b, yb),
        |_, y, width| y.abs() < 1e-9 || width < 1e-4,
        60,
    )?;
    Ok(x.exp())
}

/// [`fit_to_backlash`] through the gear's life simulation (MODEL §10): the geometry, unloaded
/// analysis and bending model are built once (the bending model reported to `on_event`), then
/// each run is the life of `plan` from the unworn flank with the wheel's wear coefficient set
/// to the trial K; `on_run(run, K, records)` is told each. A pitting forecast's plan fits the
/// curve's life factor with K ([`fit_with_life_factor`]). Returns the fit, the records of the
/// last (best) run and the number of runs.
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
    let mut simulate = |k: f64, life_factor: f64| {
        let mut g = gear.clone();
        g.wheel_material.wear_coefficient = k;
        let mut plan = plan.clone();
        plan.endurance.life_factor = life_factor;
        runs += 1;
        let end = crate::wear::simulate(
            &g,
            &geo,
            &tca,
            &settings,
            bending
                .as_ref()
                .map(|b| b as &dyn crate::ltca::BendingModel),
            &plan,
            crate::wear::WearState::new(geo.wheel_flank(tca.loaded_flank)),
            &mut |_| Ok(()),
        )?;
        on_run(runs, k, &end.records);
        Ok(end.records)
    };
    let k_start = gear.wheel_material.wear_coefficient;
    let (fit, records) = if plan.pitting == crate::input::Pitting::Forecast {
        fit_with_life_factor(measured, k_start, &mut simulate)?
    } else {
        let f = plan.endurance.life_factor;
        fit_to_backlash(measured, k_start, 1e-3, 10, &mut |k| simulate(k, f))?
    };
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
