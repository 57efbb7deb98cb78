//! `wormwear` — command-line interface over the wormwear library.
//!
//! Exit codes: 0 success, 1 computation or output error, 2 invalid input (bad file or arguments).

use anyhow::Context;
use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use wormwear::geometry::{Geometry, GeometrySummary};
use wormwear::input::{self, GearSet, InputError};

mod calibrate_cmd;
mod geometry_cmd;

#[derive(Parser)]
#[command(
    name = "wormwear",
    version,
    about = "Loaded contact and wear of steel-worm / bronze-wheel worm gears",
    after_help = "Examples:\n  \
                  wormwear run examples/gear-1x40-design.toml -o out/1x40      # everything + report.html\n  \
                  wormwear check examples/gear-1x40-design.toml                # validate the input\n  \
                  wormwear ltca examples/gear-k-2x25.toml -o out/k             # loaded contact only\n  \
                  wormwear wear examples/gear-1x40-case-c.toml -o out/c -v     # a life, one line per state\n\n\
                  Exit codes: 0 success, 1 computation or output error, 2 invalid input.\n\
                  Outputs: summary.json, CSV, SVG, report.html, STL and VTK (.vtp) files; see the README."
)]
struct Cli {
    /// Print only errors.
    #[arg(short, long, global = true, conflicts_with = "verbose")]
    quiet: bool,
    /// Print progress as lines on stderr (one per wear state), also when stderr is not a
    /// terminal (CI logs, pipes), where the progress bar stays hidden.
    #[arg(short, long, global = true)]
    verbose: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Validate a gear file and print derived data (lead angle, modules, radii, flank area...).
    #[command(after_help = "Example:\n  wormwear check examples/gear-1x40-design.toml --json")]
    Check {
        /// Gear file (TOML).
        file: PathBuf,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Generate worm and wheel geometry: sections (CSV, SVG), flank grids (CSV), STL, summary.json.
    #[command(
        after_help = "Example:\n  wormwear geometry examples/gear-1x40-design.toml -o out/1x40"
    )]
    Geometry {
        /// Gear file (TOML).
        file: PathBuf,
        /// Output directory (created if needed).
        #[arg(short, long)]
        output: PathBuf,
    },
    /// Loaded tooth contact analysis: load sharing, pressures, transmission error, stiffness.
    #[command(
        after_help = "Example:\n  wormwear ltca examples/gear-1x40-design.toml -o out/1x40 --map-position 5"
    )]
    Ltca {
        /// Gear file (TOML).
        file: PathBuf,
        /// Output directory (created if needed).
        #[arg(short, long)]
        output: PathBuf,
        /// Position whose pressure maps are drawn (0-based).
        #[arg(long, default_value_t = 0)]
        map_position: usize,
    },
    /// Wear over life: Archard wear with the geometry updated step by step, backlash, TE and
    /// pressures over cycles. Writes each completed step as it goes (resumable).
    #[command(
        after_help = "Examples:\n  wormwear wear examples/gear-1x40-design.toml -o out/1x40\n  \
                      wormwear wear examples/gear-1x40-design.toml -o out/1x40 --cycles 180000 --step-cycles 30000\n  \
                      wormwear wear examples/gear-1x40-case-b.toml -o out/b --resume"
    )]
    Wear {
        /// Gear file (TOML) with a [wear] section (or give --cycles).
        file: PathBuf,
        /// Output directory (created if needed).
        #[arg(short, long)]
        output: PathBuf,
        #[command(flatten)]
        life: LifeArgs,
    },
    /// The whole pipeline the file asks for: geometry, unloaded and loaded analyses, ratings,
    /// the life when the file has a [wear] section (or --cycles is given), and report.html.
    #[command(
        after_help = "Examples:\n  wormwear run examples/gear-1x40-design.toml -o out/1x40\n  \
                      wormwear run examples/gear-1x40-case-c.toml -o out/c --no-pitting"
    )]
    Run {
        /// Gear file (TOML).
        file: PathBuf,
        /// Output directory (created if needed).
        #[arg(short, long)]
        output: PathBuf,
        #[command(flatten)]
        life: LifeArgs,
    },
    /// Archard coefficient K (MODEL §10) from wear tests (least squares on V = (K/H) W_asp L)
    /// or from a measured backlash-increase curve (inverse problem through the life
    /// simulation of the file's [wear] schedule). Writes the `calibration` section.
    #[command(after_help = "Examples:\n  \
                      wormwear calibrate examples/gear-1x40-case-c.toml -o out/cal --backlash measured.csv\n  \
                      wormwear calibrate examples/gear-1x40-design.toml -o out/cal --tests tests.csv\n\n\
                      --backlash CSV columns: cycles, backlash_increase_um (tangential at r2).\n\
                      --tests CSV columns: worn_volume_mm3, sliding_length_m, apparent_area_mm2,\n\
                      film_thickness_um (Phi_T h_min), roughness_rq_um, slope_rdq.")]
    Calibrate {
        /// Gear file (TOML): materials, and for --backlash the [wear] schedule.
        file: PathBuf,
        /// Output directory (created if needed).
        #[arg(short, long)]
        output: PathBuf,
        /// Wear tests (CSV).
        #[arg(
            long,
            conflicts_with = "backlash",
            required_unless_present = "backlash"
        )]
        tests: Option<PathBuf>,
        /// Measured backlash increase over cycles (CSV).
        #[arg(long)]
        backlash: Option<PathBuf>,
        /// Ignore the pitting phases of the schedule.
        #[arg(long)]
        no_pitting: bool,
    },
    /// The validation study behind VALIDATION.md: analytic checks, the published studies on the
    /// reference gears, sensitivity to the unpublished inputs, our options against the default.
    /// Resumable: finished jobs are kept in DIR/runs and reused when their inputs are the same.
    #[command(
        after_help = "Example (from the repository root; about two hours on 2 cores):\n  \
                      wormwear validate -o out/validation && cp out/validation/VALIDATION.md .\n  \
                      wormwear validate -o out/smoke --quick      # a minute: the machinery only"
    )]
    Validate {
        /// Output directory (VALIDATION.md, validation.json, runs/).
        #[arg(short, long)]
        output: PathBuf,
        /// Directory of the reference cases.
        #[arg(long, default_value = "examples")]
        examples: PathBuf,
        /// Smoke run: lives cut to a hundredth, no bending.
        #[arg(long)]
        quick: bool,
    },
    /// Unloaded meshing analysis (TCA): kinematic error, no-load pattern, sliding velocities.
    #[command(after_help = "Example:\n  wormwear tca examples/gear-1x40-design.toml -o out/1x40")]
    Tca {
        /// Gear file (TOML).
        file: PathBuf,
        /// Output directory (created if needed).
        #[arg(short, long)]
        output: PathBuf,
    },
}

/// Overrides of the file's [wear] section.
#[derive(clap::Args, Debug, Clone)]
struct LifeArgs {
    /// Wheel cycles to simulate (overrides wear.life_cycles).
    #[arg(long)]
    cycles: Option<f64>,
    /// Fixed steps of this many wheel cycles (overrides the file's step).
    #[arg(long, conflicts_with = "step_wear_um")]
    step_cycles: Option<f64>,
    /// Adaptive steps removing at most this depth, um (overrides the file's step).
    #[arg(long)]
    step_wear_um: Option<f64>,
    /// Ignore the pitting phases of the schedule (wear all along).
    #[arg(long)]
    no_pitting: bool,
    /// Continue from the checkpoint in the output directory.
    #[arg(long)]
    resume: bool,
}

/// Error classes mapped to exit codes.
enum Failure {
    Input(anyhow::Error),
    Run(anyhow::Error),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // One run per output directory: the lock lives until the process ends.
    let output = match &cli.command {
        Command::Check { .. } => None,
        Command::Geometry { output, .. }
        | Command::Tca { output, .. }
        | Command::Ltca { output, .. }
        | Command::Wear { output, .. }
        | Command::Run { output, .. }
        | Command::Calibrate { output, .. }
        | Command::Validate { output, .. } => Some(output),
    };
    let lock = match output
        .map(|dir| wormwear::output::lock_directory(dir))
        .transpose()
    {
        Ok(lock) => lock,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let stale = lock.as_ref().map_or(0, |l| l.stale_temporaries_removed);
    if stale > 0 && !cli.quiet {
        eprintln!("note: removed {stale} temporary file(s) left by an interrupted run");
    }
    let result = match &cli.command {
        Command::Check { file, json } => check(file, *json),
        Command::Geometry { file, output } => geometry(file, output, cli.quiet),
        Command::Tca { file, output } => tca(file, output, cli.quiet),
        Command::Ltca {
            file,
            output,
            map_position,
        } => ltca(file, output, *map_position, cli.quiet),
        Command::Wear { file, output, life } => wear(file, output, life, cli.quiet, cli.verbose),
        Command::Run { file, output, life } => run(file, output, life, cli.quiet, cli.verbose),
        Command::Calibrate {
            file,
            output,
            tests,
            backlash,
            no_pitting,
        } => calibrate(
            file,
            output,
            tests.as_deref(),
            backlash.as_deref(),
            *no_pitting,
            cli.quiet,
            cli.verbose,
        ),
        Command::Validate {
            output,
            examples,
            quick,
        } => validate(output, examples, *quick, cli.quiet),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Input(e)) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
        Err(Failure::Run(e)) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}

/// Loads and validates a gear file; input problems map to exit code 2.
fn load(file: &Path) -> Result<GearSet, Failure> {
    input::load(file).map_err(|e: InputError| {
        Failure::Input(anyhow::Error::new(e).context(format!("in {}", file.display())))
    })
}

/// Builds the geometry; a gear that validates but cannot be generated is an input problem too.
fn build_geometry(gear: &GearSet, file: &Path) -> Result<Geometry, Failure> {
    Geometry::build(gear).map_err(|e| {
        Failure::Input(anyhow::Error::new(e).context(format!("geometry of {}", file.display())))
    })
}

fn check(file: &Path, json: bool) -> Result<(), Failure> {
    let gear = load(file)?;
    let geo = build_geometry(&gear, file)?;
    let summary = GeometrySummary::new(&gear, &geo);
    if json {
        let text = serde_json::to_string_pretty(&summary)
            .context("encoding JSON")
            .map_err(Failure::Run)?;
        println!("{text}");
        return Ok(());
    }
    println!("{}: valid", file.display());
    if !gear.title.is_empty() {
        println!("  {}", gear.title);
    }
    let value = serde_json::to_value(&summary).map_err(|e| Failure::Run(e.into()))?;
    if let serde_json::Value::Object(map) = value {
        for (k, v) in map {
            match v {
                serde_json::Value::Number(n) => {
                    let x = n.as_f64().unwrap_or(f64::NAN);
                    if n.is_i64() || n.is_u64() {
                        println!("  {k:<32} {n}");
                    } else {
                        println!("  {k:<32} {x:.6}");
                    }
                }
                serde_json::Value::Array(a) if a.is_empty() => {}
                serde_json::Value::Array(a) => {
                    for w in a {
                        println!("  warning: {}", w.as_str().unwrap_or_default());
                    }
                }
                serde_json::Value::Null => println!("  {k:<32} -"),
                other => println!("  {k:<32} {}", other.to_string().trim_matches('"')),
            }
        }
    }
    Ok(())
}

fn geometry(file: &Path, dir: &Path, quiet: bool) -> Result<(), Failure> {
    let gear = load(file)?;
    let geo = build_geometry(&gear, file)?;
    geometry_cmd::write_geometry(&gear, &geo, file, dir, quiet).map_err(Failure::Run)?;
    if !quiet {
        let s = GeometrySummary::new(&gear, &geo);
        println!(
            "geometry written to {}: lead angle {:.3} deg, active flank {:.1} mm^2",
            dir.display(),
            s.lead_angle_deg,
            s.active_flank_area_mm2
        );
    }
    Ok(())
}

fn tca(file: &Path, dir: &Path, quiet: bool) -> Result<(), Failure> {
    let gear = load(file)?;
    let geo = build_geometry(&gear, file)?;
    let result = wormwear::kinematics::analyse(&gear, &geo)
        .map_err(|e| Failure::Run(anyhow::Error::new(e).context("unloaded meshing analysis")))?;
    wormwear::output::geometry::write_geometry_summary(&gear, &geo, file, dir)
        .map_err(|e| Failure::Run(e.into()))?;
    let files = wormwear::output::tca::write_tca(&gear, &geo, &result, dir)
        .map_err(|e| Failure::Run(e.into()))?;
    for w in &result.warnings {
        eprintln!("warning: {w}");
    }
    if !quiet {
        for f in &files {
            println!("  wrote {}", f.display());
        }
        let s = wormwear::output::tca::TcaSummary::new(&result);
        println!(
            "tca: kinematic error mean {:.3e} rad, p2p {:.3e} rad; pattern {:.1} % of the flank; \
             sliding max {:.2} m/s, pitch {:.3} m/s",
            s.kinematic_error_mean_rad,
            s.kinematic_error_p2p_rad,
            100.0 * s.pattern_area_fraction,
            s.max_sliding_speed_m_s,
            s.sliding_speed_at_pitch_m_s
        );
    }
    Ok(())
}

/// The bending model the file asks for (`[bending] model`), from the cache or the FE build.
fn bending_model(
    gear: &wormwear::input::GearSet,
    geo: &wormwear::geometry::Geometry,
    quiet: bool,
) -> Result<Option<wormwear::bending::worm_model::FeBending>, Failure> {
    let (built, warnings) = wormwear::bending::model::build(gear, geo).map_err(|e| {
        Failure::Run(anyhow::Error::new(e).context("bending influence coefficients"))
    })?;
    for w in &warnings {
        eprintln!("warning: {w}");
    }
    Ok(built.map(|b| {
        if !quiet {
            let place = b
                .cache_file
                .as_ref()
                .map(|p| p.display().to_string())
                .unwrap_or_default();
            match b.origin {
                wormwear::bending::model::Origin::Cache => {
                    println!("bending (fe): read in {:.3} s from {place}", b.seconds)
                }
                wormwear::bending::model::Origin::Computed => println!(
                    "bending (fe): worm and wheel FE models computed in {:.1} s, cached in {place}",
                    b.seconds
                ),
            }
        }
        b.model
    }))
}

fn ltca(file: &Path, dir: &Path, map_position: usize, quiet: bool) -> Result<(), Failure> {
    let gear = load(file)?;
    let positions = gear.analysis.positions;
    if map_position >= positions {
        return Err(Failure::Input(anyhow::anyhow!(
            "--map-position = {map_position}: {} analyses {positions} positions, numbered 0 to {}",
            file.display(),
            positions.saturating_sub(1)
        )));
    }
    let geo = build_geometry(&gear, file)?;
    let tca = wormwear::kinematics::analyse(&gear, &geo)
        .map_err(|e| Failure::Run(anyhow::Error::new(e).context("unloaded meshing analysis")))?;
    let bending = bending_model(&gear, &geo, quiet)?;
    let result = wormwear::ltca::analyse_with(
        &gear,
        &geo,
        &tca,
        &wormwear::ltca::LtcaSettings::from_gear(&gear),
        bending
            .as_ref()
            .map(|b| b as &dyn wormwear::ltca::BendingModel),
    )
    .map_err(|e| Failure::Run(anyhow::Error::new(e).context("loaded tooth contact analysis")))?;
    wormwear::output::geometry::write_geometry_summary(&gear, &geo, file, dir)
        .map_err(|e| Failure::Run(e.into()))?;
    wormwear::output::tca::write_tca(&gear, &geo, &tca, dir).map_err(|e| Failure::Run(e.into()))?;
    let files = wormwear::output::ltca::write_ltca(&gear, &geo, &tca, &result, dir, map_position)
        .map_err(|e| Failure::Run(e.into()))?;
    write_rating(&gear, dir, quiet)?;
    for w in &tca.warnings {
        eprintln!("warning: {w}");
    }
    for w in &result.warnings {
        eprintln!("warning: loaded analysis: {w}");
    }
    if !quiet {
        for f in &files {
            println!("  wrote {}", f.display());
        }
        let (te, p2p) = result.te_stats();
        println!(
            "ltca ({}): P_max {:.0} MPa, P_mean {:.0} MPa, S0 {:.2}, TE mean {:.3e} rad p2p {:.3e} rad, \
             stiffness {:.3e} N m/rad, up to {} teeth loaded",
            result.bending_model,
            result.max_pressure / 1e6,
            result.mean_pressure / 1e6,
            result.s0,
            te,
            p2p,
            result.stiffness_mean(),
            result.max_teeth_in_contact()
        );
        if result.shaft_torsion_compliance > 0.0 {
            println!(
                "  of which the wheel shaft's torsion: TE {:.3e} rad; stiffness without it {:.3e} N m/rad",
                -result.shaft_torsion_compliance * result.wheel_torque,
                result.stiffness_without_shaft_torsion_mean()
            );
        }
    }
    Ok(())
}

/// The file's life plan with the command-line overrides applied.
fn life_plan(gear: &GearSet, args: &LifeArgs) -> Result<wormwear::input::WearPlan, Failure> {
    use wormwear::input::{Phase, StepControl, WearPlan};
    let bad = |m: String| Failure::Input(anyhow::anyhow!(m));
    let mut plan = match (&gear.wear, args.cycles) {
        (Some(p), _) => p.clone(),
        (None, Some(_)) => WearPlan::with_life(0.0),
        (None, None) => {
            return Err(bad(
                "the file has no [wear] section: add one (life_cycles, step_wear_um or step_cycles) or give --cycles".into(),
            ))
        }
    };
    if let Some(c) = args.cycles {
        if !(c.is_finite() && c > 0.0 && c <= 1e12) {
            return Err(bad(format!(
                "--cycles = {c}: must be a number of cycles in (0, 1e12]"
            )));
        }
        plan.life_cycles = c;
    }
    if let Some(c) = args.step_cycles {
        if !(c.is_finite() && c > 0.0 && c <= 1e12) {
            return Err(bad(format!(
                "--step-cycles = {c}: must be a number of cycles in (0, 1e12]"
            )));
        }
        plan.step = StepControl::Cycles(c);
    }
    if let Some(d) = args.step_wear_um {
        if !(d.is_finite() && d > 0.0 && d <= 1000.0) {
            return Err(bad(format!(
                "--step-wear-um = {d}: must be a depth in (0, 1000] um"
            )));
        }
        plan.step = StepControl::MaxRemoval(d * 1e-6);
    }
    if args.no_pitting {
        plan.phases.retain(|p| matches!(p, Phase::Wear { .. }));
    }
    Ok(plan)
}

fn wear(
    file: &Path,
    dir: &Path,
    args: &LifeArgs,
    quiet: bool,
    verbose: bool,
) -> Result<(), Failure> {
    let gear = load(file)?;
    let plan = life_plan(&gear, args)?;
    wormwear::wear::check_plan_can_end(&gear, &plan)
        .map_err(|e| Failure::Input(anyhow::Error::new(e).context("life plan")))?;
    let geo = build_geometry(&gear, file)?;
    let tca = wormwear::kinematics::analyse(&gear, &geo)
        .map_err(|e| Failure::Run(anyhow::Error::new(e).context("unloaded meshing analysis")))?;
    let bending = bending_model(&gear, &geo, quiet)?;
    let wf = geo.wheel_flank(tca.loaded_flank);
    let inputs = wormwear::output::wear::life_inputs(&gear, &plan);
    let state = if args.resume {
        match wormwear::output::wear::read_resume(dir) {
            Ok(Some((s, stored))) => {
                check_resume(dir, &s, stored.as_ref(), &inputs, plan.life_cycles)?;
                s
            }
            Ok(None) => {
                return Err(Failure::Input(anyhow::anyhow!(
                    "--resume: no {} in {}",
                    wormwear::output::wear::CHECKPOINT,
                    dir.display()
                )))
            }
            Err(e) => return Err(Failure::Input(anyhow::Error::new(e).context("--resume"))),
        }
    } else {
        wormwear::wear::WearState::new(wf)
    };
    wormwear::output::geometry::write_geometry_summary(&gear, &geo, file, dir)
        .map_err(|e| Failure::Run(e.into()))?;
    let rating = write_rating(&gear, dir, quiet)?;
    let progress = life_progress(quiet || verbose);
    // Tables, summary and curves grow with the number of states: rewrite them at most every
    // two seconds (and at log-spaced states and the last); the checkpoint goes out every state.
    let mut tables_written = std::time::Instant::now();
    let mut writer = wormwear::output::wear::LifeWriter::new(dir).with_inputs(inputs);
    let mut on_state = |view: &wormwear::wear::StepView| -> Result<(), wormwear::wear::WearError> {
        let tables = tables_written.elapsed().as_secs_f64() >= 2.0;
        writer
            .write_state(&gear, &geo, &tca, &plan, view, tables)
            .map_err(|e| wormwear::wear::WearError::Output(e.to_string()))?;
        if tables {
            tables_written = std::time::Instant::now();
        }
        let r = view.state.records.last().expect("record");
        let line = format!(
            "step {} at {} cycles ({}): wear {:.2} um, backlash +{:.2} um, P_max {:.0} MPa",
            r.step,
            wormwear::output::cycles_label(r.cycles),
            r.phase,
            r.max_wear_m * 1e6,
            r.backlash_increase_m * 1e6,
            r.max_pressure_pa / 1e6
        );
        if verbose {
            eprintln!("{line}");
        }
        progress.set_position((1000.0 * r.cycles / plan.life_cycles).round() as u64);
        progress.set_message(line);
        Ok(())
    };
    let settings = wormwear::ltca::LtcaSettings::from_gear(&gear);
    let end = wormwear::wear::simulate(
        &gear,
        &geo,
        &tca,
        &settings,
        bending
            .as_ref()
            .map(|b| b as &dyn wormwear::ltca::BendingModel),
        &plan,
        state,
        &mut on_state,
    )
    .map_err(|e| match e {
        // A checkpoint of another gear (wrong directory for --resume) is a usage problem.
        wormwear::wear::WearError::Checkpoint(_) => {
            Failure::Input(anyhow::Error::new(e).context("--resume"))
        }
        wormwear::wear::WearError::Plan(_) => {
            Failure::Input(anyhow::Error::new(e).context("life plan"))
        }
        _ => Failure::Run(anyhow::Error::new(e).context("wear simulation")),
    })?;
    progress.finish_and_clear();
    warn_about_the_life(&end);
    if !quiet {
        print_life(&end, &rating, dir);
    }
    Ok(())
}

/// A progress bar over the life's cycles (permille), or a hidden one.
fn life_progress(hidden: bool) -> indicatif::ProgressBar {
    if hidden {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(1000);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {bar:30} {percent:>3}% {msg}",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar
}

/// The one-paragraph result of a life and the standard's ratings, on stdout.
fn print_life(end: &wormwear::wear::WearState, rating: &wormwear::rating::Rating, dir: &Path) {
    let first = end.records.first().expect("record");
    let last = end.records.last().expect("record");
    println!(
        "wear: {} steps to {} cycles; max wear {:.2} um, worn volume {:.3} mm^3, backlash +{:.2} um; \
         P_max {:.0} -> {:.0} MPa, S0 {:.2} -> {:.2}; results in {}",
        last.step,
        wormwear::output::cycles_label(last.cycles),
        last.max_wear_m * 1e6,
        last.worn_volume_m3 * 1e9,
        last.backlash_increase_m * 1e6,
        first.max_pressure_pa / 1e6,
        last.max_pressure_pa / 1e6,
        first.contact_area_fraction,
        last.contact_area_fraction,
        dir.display()
    );
    println!(
        "rating (ISO/TR 14521): efficiency {:.3}, worm torque {:.2} N m, sigma_Hm {:.0} MPa, N_LI {:.3e} cycles",
        rating.efficiency, rating.worm_torque_nm, rating.sigma_hm_mpa, rating.n_li_cycles
    );
}

/// Warnings on a finished life: the wear limit it stopped at, loaded analyses off the
/// frictionless power balance, contact on worn-through material.
fn warn_about_the_life(end: &wormwear::wear::WearState) {
    if let Some(why) = &end.stopped {
        eprintln!("warning: wear limit: {why}");
    }
    if let Some(r) = end
        .records
        .iter()
        .find(|r| r.power_balance.abs() > wormwear::ltca::POWER_BALANCE_LIMIT)
    {
        eprintln!(
            "warning: wear: from {} cycles the loaded analyses depart from the frictionless \
             power balance by {:+.1} % (more than {} %): the load sits at non-conjugate points \
             (the wheel's face edge under a misalignment) and the model's torques, TE and wear \
             there are unreliable (power_balance in wear_steps.csv)",
            wormwear::output::cycles_label(r.cycles),
            100.0 * r.power_balance,
            100.0 * wormwear::ltca::POWER_BALANCE_LIMIT
        );
    }
    if let Some(r) = end.records.iter().find(|r| r.worn_through_loaded) {
        eprintln!(
            "warning: wear: from {} cycles the loaded pattern reaches flank nodes whose tooth is \
             worn through (contact computed on material that is gone; see wear.limits in \
             summary.json)",
            wormwear::output::cycles_label(r.cycles)
        );
    }
}

/// Writes the ratings and prints why any of them is null (outside its formula's range).
fn write_rating(
    gear: &GearSet,
    dir: &Path,
    quiet: bool,
) -> Result<wormwear::rating::Rating, Failure> {
    let rating = wormwear::output::write_rating(gear, dir).map_err(|e| Failure::Run(e.into()))?;
    if !quiet {
        for w in &rating.warnings {
            eprintln!("warning: rating: {w}");
        }
    }
    Ok(rating)
}

/// A checkpoint may be resumed only with the inputs it was computed with and towards a life
/// at least as long as the cycles it reached.
fn check_resume(
    dir: &Path,
    state: &wormwear::wear::WearState,
    stored: Option<&serde_json::Value>,
    inputs: &serde_json::Value,
    life_cycles: f64,
) -> Result<(), Failure> {
    let checkpoint = dir.join(wormwear::output::wear::CHECKPOINT);
    let Some(stored) = stored else {
        return Err(Failure::Input(anyhow::anyhow!(
            "--resume: {} holds no record of the inputs it was computed with (written by an \
             earlier version): its states cannot be checked against this input file; run \
             without --resume into a new directory",
            checkpoint.display()
        )));
    };
    let changes = wormwear::output::wear::input_changes(stored, inputs);
    if !changes.is_empty() {
        let shown: Vec<&str> = changes.iter().take(12).map(String::as_str).collect();
        let more = changes.len().saturating_sub(shown.len());
        return Err(Failure::Input(anyhow::anyhow!(
            "--resume: the inputs differ from those {} was computed with ({} difference{}, \
             checkpoint -> now):\n  {}{}\nresume with the original inputs, or run without \
             --resume into a new directory",
            checkpoint.display(),
            changes.len(),
            if changes.len() == 1 { "" } else { "s" },
            shown.join("\n  "),
            if more > 0 {
                format!("\n  ... and {more} more")
            } else {
                String::new()
            }
        )));
    }
    if life_cycles < state.cycles {
        return Err(Failure::Input(anyhow::anyhow!(
            "--resume: the life asked for ({life_cycles:e} cycles) ends before the checkpoint's \
             state ({:e} cycles, step {}); ask for at least that many cycles",
            state.cycles,
            state.step
        )));
    }
    Ok(())
}

fn run(
    file: &Path,
    dir: &Path,
    args: &LifeArgs,
    quiet: bool,
    verbose: bool,
) -> Result<(), Failure> {
    let gear = load(file)?;
    let with_life = gear.wear.is_some() || args.cycles.is_some();
    if with_life {
        // Check the overrides before any work.
        life_plan(&gear, args)?;
    }
    geometry(file, dir, quiet)?;
    ltca(file, dir, 0, quiet)?;
    if with_life {
        wear(file, dir, args, quiet, verbose)?;
    }
    let text = std::fs::read_to_string(file).unwrap_or_default();
    let title = if gear.title.is_empty() {
        file.display().to_string()
    } else {
        gear.title.clone()
    };
    let report = wormwear::output::report::write_report(dir, &title, &text)
        .map_err(|e| Failure::Run(e.into()))?;
    if !quiet {
        println!("report: {}", report.display());
    }
    Ok(())
}

fn calibrate(
    file: &Path,
    dir: &Path,
    tests: Option<&Path>,
    backlash: Option<&Path>,
    no_pitting: bool,
    quiet: bool,
    verbose: bool,
) -> Result<(), Failure> {
    let gear = load(file)?;
    let hardness = gear.wheel_material.hardness;
    let section = if let Some(path) = tests {
        let data = calibrate_cmd::tests_from_csv(&gear, path).map_err(Failure::Input)?;
        let fit = wormwear::calibration::fit_from_tests(&data, hardness).map_err(|e| {
            Failure::Input(anyhow::Error::new(e).context(path.display().to_string()))
        })?;
        if !quiet {
            println!(
                "K = {:.4e} from {} wear tests (relative rms residual {:.3})",
                fit.k, fit.points, fit.relative_rms
            );
        }
        serde_json::json!({
            "method": "wear tests",
            "data": path.display().to_string(),
            "k": fit.k,
            "relative_rms": fit.relative_rms,
            "points": fit.points,
        })
    } else {
        let path = backlash.expect("clap requires --tests or --backlash");
        let measured = calibrate_cmd::backlash_from_csv(path).map_err(Failure::Input)?;
        let last = measured.iter().map(|m| m.0).fold(0.0, f64::max);
        let args = LifeArgs {
            cycles: Some(last.max(1.0)),
            step_cycles: None,
            step_wear_um: None,
            no_pitting,
            resume: false,
        };
        let plan = life_plan(&gear, &args)?;
        let geo = build_geometry(&gear, file)?;
        let tca = wormwear::kinematics::analyse(&gear, &geo).map_err(|e| {
            Failure::Run(anyhow::Error::new(e).context("unloaded meshing analysis"))
        })?;
        let settings = wormwear::ltca::LtcaSettings::from_gear(&gear);
        let bending = bending_model(&gear, &geo, quiet)?;
        let k_start = gear.wheel_material.wear_coefficient;
        let mut runs = 0;
        let mut simulate = |k: f64| {
            let mut g = gear.clone();
            g.wheel_material.wear_coefficient = k;
            runs += 1;
            let wf = geo.wheel_flank(tca.loaded_flank);
            let end = wormwear::wear::simulate(
                &g,
                &geo,
                &tca,
                &settings,
                bending
                    .as_ref()
                    .map(|b| b as &dyn wormwear::ltca::BendingModel),
                &plan,
                wormwear::wear::WearState::new(wf),
                &mut |_| Ok(()),
            )?;
            if verbose {
                let b = end.records.last().map_or(0.0, |r| r.backlash_increase_m);
                eprintln!(
                    "run {runs}: K = {k:.5e}, backlash +{:.2} um at {} cycles",
                    b * 1e6,
                    wormwear::output::cycles_label(last)
                );
            }
            Ok(end.records)
        };
        let (fit, records) =
            wormwear::calibration::fit_to_backlash(&measured, k_start, 1e-3, 10, &mut simulate)
                .map_err(|e| match e {
                    wormwear::calibration::CalibrationError::Simulation(_) => {
                        Failure::Run(anyhow::Error::new(e))
                    }
                    _ => Failure::Input(anyhow::Error::new(e).context(path.display().to_string())),
                })?;
        // Measured and fitted curves side by side.
        let mut csv = wormwear::output::Csv::new(&["cycles", "measured_um", "simulated_um"]);
        let simulated: Vec<(f64, f64)> = records
            .iter()
            .map(|r| (r.cycles, r.backlash_increase_m))
            .collect();
        for &(c, b) in &measured {
            let sim = wormwear::calibration::backlash_at(&records, c).unwrap_or(f64::NAN);
            csv.row(&[c, b * 1e6, sim * 1e6]);
        }
        csv.write(&dir.join("calibration_backlash.csv"))
            .map_err(|e| Failure::Run(e.into()))?;
        let chart = |points: Vec<(f64, f64)>, label: &str, color: usize| wormwear::plot::Series {
            label: label.into(),
            points,
            color,
            bold: color == 1,
        };
        wormwear::plot::line_chart(
            &dir.join("calibration_backlash.svg"),
            &format!(
                "Backlash increase: measured and simulated with K = {:.3e}",
                fit.k
            ),
            "wheel cycles (millions)",
            "backlash increase (um)",
            &[
                chart(
                    simulated.iter().map(|s| (s.0 * 1e-6, s.1 * 1e6)).collect(),
                    "simulated",
                    1,
                ),
                chart(
                    measured.iter().map(|s| (s.0 * 1e-6, s.1 * 1e6)).collect(),
                    "measured",
                    0,
                ),
            ],
            false,
        )
        .map_err(|e| Failure::Run(e.into()))?;
        if !quiet {
            println!(
                "K = {:.4e} from the backlash curve ({} points, {runs} life runs from K = {k_start:.3e}; relative rms residual {:.3})",
                fit.k, fit.points, fit.relative_rms
            );
        }
        serde_json::json!({
            "method": "backlash curve",
            "data": path.display().to_string(),
            "k": fit.k,
            "k_start": k_start,
            "relative_rms": fit.relative_rms,
            "points": fit.points,
            "life_runs": runs,
        })
    };
    wormwear::output::update_summary(dir, "calibration", section)
        .map_err(|e| Failure::Run(e.into()))?;
    Ok(())
}

/// Runs the validation study into `dir` (VALIDATION.md at its root).
fn validate(dir: &Path, examples: &Path, quick: bool, quiet: bool) -> Result<(), Failure> {
    if !examples.join("gear-1x40-design.toml").is_file() {
        return Err(Failure::Input(anyhow::anyhow!(
            "--examples = {}: no gear-1x40-design.toml there (run from the repository root or give the examples directory)",
            examples.display()
        )));
    }
    let settings = wormwear::validation::Settings {
        examples: examples.to_path_buf(),
        quick,
    };
    let path = wormwear::validation::run(&settings, dir, &mut |line| {
        if !quiet {
            eprintln!("{line}");
        }
    })
    .map_err(|e| match e {
        wormwear::validation::ValidationError::Input { .. } => Failure::Input(e.into()),
        _ => Failure::Run(anyhow::Error::new(e).context("validation study")),
    })?;
    if !quiet {
        println!("validation written to {}", path.display());
    }
    Ok(())
}
