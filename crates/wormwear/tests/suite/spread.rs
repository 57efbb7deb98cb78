//! Spread and uncertainty (MODEL §17): the sampler's marginals against their distributions
//! (Kolmogorov–Smirnov), percentiles of a known distribution, a linear model's rank
//! correlations against the analytic correlations, a spread of zero-width ranges against the
//! nominal run, one seed one set of bytes, and refusals naming the input.

use std::path::Path;
use wormwear::spread::sampling::{normal_cdf, Distribution};
use wormwear::spread::{sample_variants, stats, Input, Spread};

/// The values of input `k` over the samples.
fn column(inputs: &[Input], samples: usize, seed: u64, k: usize) -> Vec<f64> {
    sample_variants(
        inputs,
        samples,
        seed,
        wormwear::spread::Sampler::LatinHypercube,
    )
    .iter()
    .map(|v| v.values[k].1.as_float().unwrap())
    .collect()
}

/// Kolmogorov–Smirnov's statistic of `values` against the CDF `cdf`.
fn ks(values: &[f64], cdf: impl Fn(f64) -> f64) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len() as f64;
    v.iter()
        .enumerate()
        .map(|(i, &x)| {
            let f = cdf(x);
            (f - i as f64 / n).abs().max(((i + 1) as f64 / n - f).abs())
        })
        .fold(0.0, f64::max)
}

fn input(name: &str, distribution: Distribution) -> Input {
    Input {
        name: name.into(),
        distribution,
    }
}

#[test]
fn the_marginals_follow_their_distributions() {
    let n = 400;
    // KS's critical value at the 1 % level, 1.63 / sqrt(n); a Latin hypercube stratifies
    // every marginal, so it lies far below.
    let critical = 1.63 / (n as f64).sqrt();
    let inputs = [
        input(
            "a",
            Distribution::Uniform {
                min: -0.03,
                max: 0.05,
            },
        ),
        input(
            "b",
            Distribution::Normal {
                mean: 1.0,
                sd: 0.2,
                min: f64::NEG_INFINITY,
                max: f64::INFINITY,
            },
        ),
        input(
            "c",
            Distribution::Normal {
                mean: 1.0,
                sd: 0.2,
                min: 0.8,
                max: 1.5,
            },
        ),
    ];
    let a = column(&inputs, n, 3, 0);
    assert!(ks(&a, |x| ((x + 0.03) / 0.08).clamp(0.0, 1.0)) < critical);
    let b = column(&inputs, n, 3, 1);
    let d = ks(&b, |x| normal_cdf((x - 1.0) / 0.2));
    assert!(d < critical, "normal: D = {d}");
    // The truncated normal: within its bounds, its CDF renormalised over them.
    let c = column(&inputs, n, 3, 2);
    assert!(c.iter().all(|x| (0.8..=1.5).contains(x)));
    let (lo, hi) = (normal_cdf(-1.0), normal_cdf(2.5));
    let d = ks(&c, |x| (normal_cdf((x - 1.0) / 0.2) - lo) / (hi - lo));
    assert!(d < critical, "truncated normal: D = {d}");
    // Against a wrong distribution the statistic says so.
    assert!(ks(&b, |x| normal_cdf((x - 1.1) / 0.2)) > critical);
}

#[test]
fn percentiles_of_a_known_distribution() {
    let inputs = [input(
        "x",
        Distribution::Normal {
            mean: 0.0,
            sd: 1.0,
            min: f64::NEG_INFINITY,
            max: f64::INFINITY,
        },
    )];
    let x = column(&inputs, 2000, 11, 0);
    // Phi^-1(0.1) = -1.2816, Phi^-1(0.5) = 0, Phi^-1(0.9) = 1.2816.
    for (q, expected) in [
        (0.1, -1.2815515655446004),
        (0.5, 0.0),
        (0.9, 1.2815515655446004),
    ] {
        let p = stats::percentile(&x, q).unwrap();
        assert!((p - expected).abs() < 5e-3, "P{}: {p}", q * 100.0);
    }
}

#[test]
fn a_linear_models_rank_correlations_are_its_correlations() {
    // y = 2 x1 + x2 with x1 uniform on [0, 1] and x2 uniform on [0, 3]: the correlations are
    // a_i sigma_i / sigma_y = 2 / sqrt 13 and 3 / sqrt 13 (sigma_i = width / sqrt 12); the
    // rank correlations of this near-Gaussian sum lie within 0.02 of them.
    let inputs = [
        input("x1", Distribution::Uniform { min: 0.0, max: 1.0 }),
        input("x2", Distribution::Uniform { min: 0.0, max: 3.0 }),
    ];
    let n = 4000;
    let (x1, x2) = (column(&inputs, n, 5, 0), column(&inputs, n, 5, 1));
    let y: Vec<f64> = x1.iter().zip(&x2).map(|(a, b)| 2.0 * a + b).collect();
    let r1 = stats::spearman(&x1, &y).unwrap();
    let r2 = stats::spearman(&x2, &y).unwrap();
    assert!((r1 - 2.0 / 13f64.sqrt()).abs() < 0.02, "{r1}");
    assert!((r2 - 3.0 / 13f64.sqrt()).abs() < 0.02, "{r2}");
    // An input the model does not read has none.
    let inputs3 = [
        inputs[0].clone(),
        inputs[1].clone(),
        input("x3", Distribution::Uniform { min: 0.0, max: 1.0 }),
    ];
    let x3 = column(&inputs3, n, 5, 2);
    let y3: Vec<f64> = column(&inputs3, n, 5, 0)
        .iter()
        .zip(column(&inputs3, n, 5, 1))
        .map(|(a, b)| 2.0 * a + b)
        .collect();
    assert!(stats::spearman(&x3, &y3).unwrap().abs() < 0.05);
}

/// A folder with a fast copy of the design gear (no bending, a coarse grid, no FE root stress)
/// and a spread file over it with `inputs` and `samples`.
fn fast_spread(dir: &Path, inputs: &str, samples: usize) -> std::path::PathBuf {
    let design = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/gear-1x40-design.toml"),
    )
    .unwrap();
    let gear = design
        .replace("[bending]\nmodel = \"fe\"", "[bending]\nmodel = \"none\"")
        .replace("flank_cells_height = 40", "flank_cells_height = 20")
        .replace("flank_cells_face = 60", "flank_cells_face = 30")
        .replace("positions = 20", "positions = 6")
        .replace("root_stress_allowable_mpa = 100.0", "")
        .replace("root_fillet_radius_mm = 1.0", "");
    std::fs::write(dir.join("fast.toml"), gear).unwrap();
    let file = dir.join("spread.toml");
    std::fs::write(
        &file,
        format!("base = \"fast.toml\"\n[spread]\nsamples = {samples}\nseed = 4\n[spread.inputs]\n{inputs}"),
    )
    .unwrap();
    file
}

#[test]
fn zero_width_ranges_give_the_nominal_run_and_one_seed_one_set_of_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let file = fast_spread(
        dir.path(),
        "\"operating.centre_distance_error_mm\" = [0.0, 0.0]\n\"operating.worm_offset_mm\" = [0.0, 0.0]\n",
        3,
    );
    let spread = Spread::load(&file).unwrap();
    let out = wormwear::spread::run(&spread, &dir.path().join("a"), &|_| {}, &|| false).unwrap();
    // The nominal run of the base, as a gear of its own.
    let gear = wormwear::input::load(&dir.path().join("fast.toml")).unwrap();
    let request = wormwear::Request::new([wormwear::Stage::Ltca]);
    let nominal =
        wormwear::run(&gear, wormwear::Source::default(), request, &mut |_| Ok(())).unwrap();
    let l = nominal.ltca.unwrap();
    let at = |name: &str| {
        wormwear::spread::RESULTS
            .iter()
            .position(|(n, _)| *n == name)
            .unwrap()
    };
    let wf = nominal
        .geometry
        .wheel_flank(nominal.tca.as_ref().unwrap().loaded_flank);
    let loaded: Vec<bool> = l.pattern.iter().map(|p| *p > 0.0).collect();
    let entry = nominal.tca.as_ref().unwrap().entry_at_low_z;
    let shape = wormwear::kinematics::pattern_shape::PatternShape::of(wf, &loaded, entry).unwrap();
    for results in &out.results {
        assert_eq!(results[at("max_pressure_pa")], l.max_pressure);
        assert_eq!(results[at("pressure_patch_max_pa")], l.pressure_patch_max);
        assert_eq!(results[at("te_p2p_rad")], l.te_stats().1);
        assert_eq!(
            results[at("mesh_efficiency")],
            nominal.thermal.as_ref().unwrap().efficiency.mesh_efficiency
        );
        assert_eq!(
            results[at("pattern_centre_across_face")],
            shape.centre_across_face
        );
    }
    // A fixed field is set in every sample and is not an input.
    let fixed = fast_spread(
        dir.path(),
        "\"operating.worm_offset_mm\" = [-0.05, 0.05]\n[spread.fixed]\n\"analysis.positions\" = 4\n",
        2,
    );
    let with_fixed = Spread::load(&fixed).unwrap();
    assert_eq!(with_fixed.inputs.len(), 1);
    for v in &with_fixed.sweep.variants {
        assert_eq!(
            v.values[1],
            ("analysis.positions".to_string(), toml::Value::Integer(4))
        );
    }
    // A sampled spread: again into another directory, the same bytes; another seed differs.
    let file = fast_spread(
        dir.path(),
        "\"operating.worm_offset_mm\" = [-0.05, 0.05]\n",
        3,
    );
    let spread = Spread::load(&file).unwrap();
    for name in ["b", "c"] {
        wormwear::spread::run(&spread, &dir.path().join(name), &|_| {}, &|| false).unwrap();
    }
    for f in ["spread.csv", "spread.json"] {
        let read = |d: &str| std::fs::read(dir.path().join(d).join(f)).unwrap();
        assert_eq!(read("b"), read("c"), "{f}");
    }
    let other = std::fs::read_to_string(&file)
        .unwrap()
        .replace("seed = 4", "seed = 5");
    std::fs::write(&file, other).unwrap();
    let reseeded = Spread::load(&file).unwrap();
    assert_ne!(reseeded.sweep.variants, spread.sweep.variants);
}

#[test]
fn a_bad_spread_file_is_refused_naming_the_input() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, usize, &[&str]); 10] = [
        ("\"operating.worm_offset_mm\" = [-0.05, 0.05]\n[spread.fixed]\n\"operating.worm_offset_mm\" = 0.0\n", 4, &["spread.fixed.\"operating.worm_offset_mm\"", "also an input"]),
        ("\"operating.worm_offset_mm\" = [-0.05, 0.05]\n[spread.fixed]\n\"bending.modle\" = \"none\"\n", 4, &["spread.fixed", "modle"]),
        (
            "\"operating.centre_distance_eror_mm\" = [-0.03, 0.03]\n",
            4,
            &[
                "no field operating.centre_distance_eror_mm, and the gear file does not take it",
                "operating.centre_distance_error_mm",
            ],
        ),
        (
            "\"worm.profile\" = [0.0, 1.0]\n",
            4,
            &["worm.profile", "not a number"],
        ),
        (
            "\"operating.worm_offset_mm\" = [0.05, -0.05]\n",
            4,
            &["inverted range"],
        ),
        (
            "\"operating.worm_offset_mm\" = [0.05]\n",
            4,
            &["[min, max]"],
        ),
        (
            "\"operating.worm_offset_mm\" = { mean = 0.0, sd = -1.0 }\n",
            4,
            &["sd must be >= 0"],
        ),
        (
            "\"operating.worm_offset_mm\" = { mean = 0.2, sd = 0.1, max = 0.1 }\n",
            4,
            &["the mean 0.2 must lie within"],
        ),
        (
            "\"operating.worm_offset_mm\" = [-0.05, 0.05]\n",
            0,
            &["spread.samples = 0", "[2, 4096]"],
        ),
        (
            "\"operating.worm_offset_mm\" = [-0.05, 0.05]\n",
            5000,
            &["spread.samples = 5000"],
        ),
    ];
    // A field the base leaves at its default is an input where the gear file takes it.
    let absent = "\"lubricant.boundary_friction\" = [0.07, 0.12]\n";
    let spread = Spread::load(&fast_spread(dir.path(), absent, 4)).unwrap();
    assert_eq!(spread.inputs[0].name, "lubricant.boundary_friction");
    let beyond = "\"lubricant.boundary_friction\" = [1.5, 2.5]\n";
    let message = Spread::load(&fast_spread(dir.path(), beyond, 4))
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("does not take it at the input's centre")
            && message.contains("lubricant.boundary_friction = 2"),
        "{message}"
    );
    for (inputs, samples, parts) in cases {
        let file = fast_spread(dir.path(), inputs, samples);
        let message = match Spread::load(&file) {
            Ok(_) => panic!("accepted: {inputs}"),
            Err(e) => e.to_string(),
        };
        for p in parts {
            assert!(message.contains(p), "{p:?} not in {message}");
        }
    }
}

/// Saltelli's design's estimators against functions whose Sobol indices are known exactly: a
/// linear model of uniform inputs (S_i = S_Ti = a_i^2 / sum a_j^2) and Ishigami's function
/// (Ishigami & Homma 1990; its indices in closed form, e.g. Saltelli et al., Global
/// Sensitivity Analysis: The Primer, 2008, §3.5: an interaction of x1 and x3, and x3 with no
/// first-order effect).
#[test]
fn sobol_indices_recover_a_linear_model_and_ishigamis_function() {
    use wormwear::spread::sampling::saltelli;
    let n = 4096;
    let rows = saltelli(n, 3, 5);
    assert_eq!(rows.len(), n * 5);
    // The A_B^i rows are A's with column i from B.
    for i in 0..3 {
        for j in [0, 17, n - 1] {
            let (a, b, ab) = (&rows[j], &rows[n + j], &rows[(2 + i) * n + j]);
            for d in 0..3 {
                assert_eq!(ab[d], if d == i { b[d] } else { a[d] });
            }
        }
    }
    let coefficients = [1.0, 2.0, 3.0];
    let y: Vec<f64> = rows
        .iter()
        .map(|x| (0..3).map(|d| coefficients[d] * x[d]).sum())
        .collect();
    let sum: f64 = coefficients.iter().map(|a| a * a).sum();
    for (index, a) in stats::sobol_indices(&y, n, 3).iter().zip(coefficients) {
        let index = index.unwrap();
        let exact = a * a / sum;
        // (Measured errors: below 2e-4.)
        assert!((index.first - exact).abs() < 2e-3, "{index:?} vs {exact}");
        assert!((index.total - exact).abs() < 2e-3, "{index:?} vs {exact}");
    }
    // Ishigami, a = 7, b = 0.1, x uniform on [-pi, pi].
    let (a, b, pi) = (7.0, 0.1, std::f64::consts::PI);
    let y: Vec<f64> = rows
        .iter()
        .map(|u| {
            let x: Vec<f64> = u.iter().map(|v| -pi + 2.0 * pi * v).collect();
            x[0].sin() + a * x[1].sin().powi(2) + b * x[2].powi(4) * x[0].sin()
        })
        .collect();
    let v1 = 0.5 * (1.0 + b * pi.powi(4) / 5.0).powi(2);
    let v2 = a * a / 8.0;
    let v13 = 8.0 * b * b * pi.powi(8) / 225.0;
    let v = v1 + v2 + v13;
    let exact = [(v1 / v, (v1 + v13) / v), (v2 / v, v2 / v), (0.0, v13 / v)];
    for (index, (first, total)) in stats::sobol_indices(&y, n, 3).iter().zip(exact) {
        let index = index.unwrap();
        // (Measured errors: first-order up to 0.014 at 4096 base points, totals 1e-3; the
        // first-order estimator's variance is the larger, Saltelli et al. 2010 §4.)
        assert!((index.first - first).abs() < 0.025, "{index:?} vs {first}");
        assert!((index.total - total).abs() < 0.005, "{index:?} vs {total}");
    }
    // Another seed, other points; a constant result has no indices.
    assert_ne!(saltelli(8, 3, 6), saltelli(8, 3, 5));
    assert!(stats::sobol_indices(&vec![1.0; 5 * 8], 8, 3)
        .iter()
        .all(Option::is_none));
}

#[test]
fn a_spread_with_the_sobol_sampler_runs_saltellis_design_and_reports_the_indices() {
    let dir = tempfile::tempdir().unwrap();
    let file = fast_spread(
        dir.path(),
        "\"operating.worm_offset_mm\" = [-0.05, 0.05]\n\"conditions.worm_torque_nm\" = [50.0, 70.0]\n",
        2,
    );
    let text = std::fs::read_to_string(&file)
        .unwrap()
        .replace("seed = 4", "seed = 4\nsampler = \"sobol\"");
    std::fs::write(&file, text).unwrap();
    let spread = Spread::load(&file).unwrap();
    assert_eq!(spread.sweep.variants.len(), 2 * (2 + 2));
    let out = wormwear::spread::run(&spread, &dir.path().join("o"), &|_| {}, &|| false).unwrap();
    assert!(out.rows.iter().all(|r| r.ok), "{:#?}", out.rows);
    assert!(dir.path().join("o/spread.html").is_file());
    assert!(dir
        .path()
        .join("o/plots/mesh_efficiency_sensitivity.svg")
        .is_file());
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("o/spread.json")).unwrap())
            .unwrap();
    assert_eq!(json["sampler"], "sobol");
    assert_eq!(json["runs"], 8);
    // Percentiles over A and B (4 independent runs), indices for each input (of a result that
    // varies: the largest pressure sits at the flow pressure in every run).
    assert_eq!(json["results"]["mesh_efficiency"]["count"], 4);
    let indices = &json["sobol_indices"]["mesh_efficiency"];
    for name in ["operating.worm_offset_mm", "conditions.worm_torque_nm"] {
        assert!(indices[name]["total"].is_number(), "{indices}");
    }
    // Refused: an unknown sampler, and more runs than allowed (2 inputs: 4 runs a sample).
    for (sampler, samples, part) in [
        ("halton", 4, "unknown sampler"),
        ("sobol", 1100, "[2, 1024]"),
    ] {
        let text = std::fs::read_to_string(&file)
            .unwrap()
            .replace("\"sobol\"", &format!("{sampler:?}"))
            .replace("samples = 2", &format!("samples = {samples}"));
        std::fs::write(&file, text).unwrap();
        let message = Spread::load(&file).unwrap_err().to_string();
        assert!(message.contains(part), "{message}");
        // Back to the Sobol sampler and 2 samples for the next case.
        let text = std::fs::read_to_string(&file)
            .unwrap()
            .replace(&format!("{sampler:?}"), "\"sobol\"")
            .replace(&format!("samples = {samples}"), "samples = 2");
        std::fs::write(&file, text).unwrap();
    }
}
