//! `wormwear` — command-line interface over the wormwear library.
//!
//! Exit codes: 0 success, 1 computation or output error, 2 invalid input (bad file or arguments).

use anyhow::Context;
use args::{CadArgs, LifeArgs};
use clap::{Parser, Subcommand};
use request::{life_request, planned_request, with_cad};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use wormwear::geometry::{Geometry, GeometrySummary};
use wormwear::input::{self, GearSet, InputError};

mod args;
mod calibrate_cmd;
mod compare_cmd;
mod init_cmd;
mod interrupt;
mod pattern_cmd;
mod rating_cmd;
mod request;
mod rexs_cmd;
mod sweep_cmd;

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
    /// Print only errors and warnings: no progress, results or file lists (the ISO/TR 14521
    /// rating's notes on its formulas' ranges are left out too; summary.json keeps them).
    #[arg(short, long, global = true, conflicts_with = "verbose")]
    quiet: bool,
    /// Print progress as lines on stderr, also when stderr is not a terminal (CI logs, pipes),
    /// where the progress bar stays hidden: one line per wear state of a life (wear, run,
    /// rating, calibrate, export-rexs); the other commands have no progress to print.
    #[arg(short, long, global = true)]
    verbose: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Write a new gear file: every section with its keys, units and defaults (the numbers of
    /// the 1/40 reference gear), in the thread profile asked for; prints it without -o.
    #[command(
        after_help = "Example:\n  wormwear init --profile K -o my-gear.toml\n  \
                            wormwear check my-gear.toml"
    )]
    Init {
        /// Thread profile of worm and hob.
        #[arg(long, value_enum, default_value = "a", ignore_case = true)]
        profile: init_cmd::ProfileArg,
        /// Gear file to write (refused if it exists, unless --force).
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Replace an existing file.
        #[arg(long)]
        force: bool,
    },
    /// Compare finished runs: their key results side by side with the differences to the
    /// first, the backlash and wear curves of their lives overlaid (compare.html, compare.csv).
    #[command(after_help = "Example:\n  wormwear compare out/60nm out/90nm -o out/compare")]
    Compare {
        /// Output directories of `run`, `ltca`, `wear` or `rating` (two or more).
        #[arg(required = true, num_args = 2..)]
        runs: Vec<PathBuf>,
        /// Directory for the comparison (created if needed).
        #[arg(short, long)]
        output: PathBuf,
    },
    /// Validate a gear file and print derived data (lead angle, modules, radii, flank area...).
    #[command(after_help = "Example:\n  wormwear check examples/gear-1x40-design.toml --json")]
    Check {
        /// Gear file (TOML).
        file: PathBuf,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Generate worm and wheel geometry: sections (CSV, SVG), flank grids (CSV), STL, summary.json;
    /// with --step the worm and the wheel as STEP solids for CAD.
    #[command(
        after_help = "Examples:\n  wormwear geometry examples/gear-1x40-design.toml -o out/1x40\n  \
                      wormwear geometry examples/gear-1x40-design.toml -o out/1x40 --step --step-teeth 3"
    )]
    Geometry {
        /// Gear file (TOML).
        file: PathBuf,
        /// Output directory (created if needed).
        #[arg(short, long)]
        output: PathBuf,
        #[command(flatten)]
        cad: CadArgs,
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
        #[command(flatten)]
        cad: CadArgs,
    },
    /// The safety table from the model (MODEL §9.1): tooth root, worm deflection, pitting,
    /// wear at the required life, oil temperature, against the [rating] table's allowables and
    /// minimums; runs the loaded analysis, and the life when the file has a [wear] section (or
    /// --cycles is given). Writes rating.csv and summary.json's `rating` section.
    #[command(
        after_help = "Example:\n  wormwear rating examples/gear-1x40-design.toml -o out/rating"
    )]
    Rating {
        /// Gear file (TOML).
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
        #[command(flatten)]
        cad: CadArgs,
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
                      wormwear validate -o out/validation && cp -r out/validation/VALIDATION.md out/validation/validation-figures .\n  \
                      wormwear validate -o out/smoke --quick      # a minute: the machinery only"
    )]
    Validate {
        /// Output directory (VALIDATION.md, validation.json, runs/).
        #[arg(short, long)]
        output: PathBuf,
        /// Directory of the reference cases.
        #[arg(long, default_value = "examples")]
        examples: PathBuf,
        /// Smoke run: lives cut to a hundredth, no bending, one job per table (not its
        /// variants), section (a) without its mesh-refinement rows.
        #[arg(long)]
        quick: bool,
        /// Only these jobs, comma-separated ids as in the report's "Run times" (e.g.
        /// case-a,case-a-forecast): the report leaves out the tables of the others.
        #[arg(long, value_delimiter = ',')]
        jobs: Vec<String>,
    },
    /// A design study: variants of a base gear file (a grid or a list of cases, by dotted
    /// name) run in parallel on the local cores; sweep.csv (one row per variant), sweep.html,
    /// every variant's output in DIR/variants/NAME. Resumable: finished variants with the same
    /// inputs are reused; a failing variant is recorded with its error and the others go on.
    #[command(
        after_help = "Example:\n  wormwear sweep examples/sweep-torque-roughness.toml -o out/sweep\n\n\
                      Sweep file (TOML):\n  \
                      base = \"gear-1x40-design.toml\"   # relative to the sweep file\n  \
                      stages = [\"ltca\", \"wear\"]        # optional (default: as `run`)\n  \
                      cycles = 180000                  # optional: --cycles, step_cycles, step_wear_um, no_pitting\n  \
                      [grid]                           # or [[cases]] with name = \"...\" and values\n  \
                      \"conditions.worm_torque_nm\" = [30.0, 60.0, 90.0]\n  \
                      \"lubricant.composite_roughness_um\" = [0.5, 1.0]"
    )]
    Sweep {
        /// Sweep file (TOML).
        file: PathBuf,
        /// Output directory (created if needed).
        #[arg(short, long)]
        output: PathBuf,
        /// Allow the sweep's `base` outside the sweep file's directory (by default a sweep
        /// file may only read a gear file in its own folder or below).
        #[arg(long)]
        base_anywhere: bool,
    },
    /// Spread and uncertainty (MODEL §17): the inputs a spread file gives ranges or normal
    /// distributions are sampled (a seeded Latin hypercube) and every sample runs as a sweep
    /// variant; spread.csv (one row per sample: inputs, key results) and spread.json (each
    /// result's P10 / P50 / P90, min, max, and its rank correlation with each input).
    /// Resumable as a sweep; the same seed gives the same bytes.
    #[command(
        after_help = "Example:\n  wormwear spread examples/spread-assembly.toml -o out/spread\n\n\
                      Spread file (TOML):\n  \
                      base = \"gear-1x40-design.toml\"   # relative to the spread file\n  \
                      stages = [\"ltca\"]                # default; [\"ltca\", \"wear\"] with cycles\n  \
                      [spread]\n  \
                      samples = 64\n  \
                      seed = 1\n  \
                      [spread.inputs]\n  \
                      \"operating.centre_distance_error_mm\" = [-0.03, 0.03]         # uniform\n  \
                      \"lubricant.composite_roughness_um\" = { mean = 1.0, sd = 0.2, min = 0.5 }  # normal"
    )]
    Spread {
        /// Spread file (TOML).
        file: PathBuf,
        /// Output directory (created if needed).
        #[arg(short, long)]
        output: PathBuf,
    },
    /// The contact-pattern assistant (MODEL §17): searches the cutting settings (cutting centre
    /// distance, hob swivel, hob oversize, or any fields named, within bounds) for those that
    /// bring the no-load (or loaded) pattern closest to a target shape (Nelder–Mead).
    #[command(after_help = pattern_cmd::AFTER_HELP)]
    Pattern(pattern_cmd::PatternArgs),
    /// Take a worm stage from a REXS file (.rexs XML, .rexsj JSON, .rexsz zip; REXS 1.x) and
    /// write it as a commented gear file, then validate it as `check` does.
    #[command(
        after_help = "Examples:\n  wormwear import examples/rexs/worm-stage-zi-2x41.rexs -o zi.toml\n  \
                      wormwear import gearbox.rexsj -o stage.toml --stage 3   # several stages\n\n\
                      Every REXS attribute the import did not use is listed at the end of the file."
    )]
    Import {
        /// REXS file.
        file: PathBuf,
        /// Gear file to write (TOML).
        #[arg(short, long)]
        output: PathBuf,
        /// Component id of the worm stage (needed when the file has several).
        #[arg(long)]
        stage: Option<u64>,
    },
    /// Analyse a gear file and write its stage with the results as REXS (DIR/<name>.rexs), beside
    /// the usual outputs. Results go to the standard's attribute ids where REXS has them, the
    /// others to custom_wormwear_* attributes; `wormwear import` reads the file back.
    #[command(
        name = "export-rexs",
        after_help = "Examples:\n  wormwear export-rexs examples/gear-1x40-design.toml -o out/rexs --no-life\n  \
                      wormwear export-rexs examples/gear-1x40-design.toml -o out/rexs --json"
    )]
    ExportRexs {
        /// Gear file (TOML).
        file: PathBuf,
        /// Output directory (created if needed).
        #[arg(short, long)]
        output: PathBuf,
        /// Write JSON (.rexsj) instead of XML (.rexs).
        #[arg(long)]
        json: bool,
        /// Skip the life even when the file has a [wear] section.
        #[arg(long)]
        no_life: bool,
        #[command(flatten)]
        life: LifeArgs,
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

/// Error classes mapped to exit codes.
pub(crate) enum Failure {
    Input(anyhow::Error),
    Run(anyhow::Error),
}

fn main() -> ExitCode {
    restore_sigpipe();
    interrupt::install();
    let cli = Cli::parse();
    // One run per output directory: the lock lives until the process ends.
    let _lock = match lock_output(&cli) {
        Ok(lock) => lock,
        Err(code) => return code,
    };
    let result = dispatch(&cli);
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Input(e)) => {
            eprintln!("error: {}", wormwear::runner::error_chain(e.as_ref()));
            ExitCode::from(2)
        }
        Err(Failure::Run(e)) => {
            eprintln!("error: {}", wormwear::runner::error_chain(e.as_ref()));
            ExitCode::from(1)
        }
    }
}

/// Gives SIGPIPE back its default action (end the process quietly), as Unix tools have: the
/// Rust runtime ignores it, so a print to a closed pipe (`wormwear check FILE | head`) would
/// panic. Output files are written atomically and a life resumes from its checkpoint, so
/// ending on a closed pipe loses nothing.
fn restore_sigpipe() {
    #[cfg(unix)]
    // SAFETY: called first in main, before any thread exists; SIG_DFL is a valid action for
    // SIGPIPE.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// Locks the command's output directory (none for `check` and `import`), and says when an
/// interrupted run's temporary files were removed; exit code 2 when it cannot.
fn lock_output(cli: &Cli) -> Result<Option<wormwear::output::DirectoryLock>, ExitCode> {
    let output = match &cli.command {
        Command::Check { .. } | Command::Import { .. } | Command::Init { .. } => None,
        Command::Geometry { output, .. }
        | Command::Tca { output, .. }
        | Command::Ltca { output, .. }
        | Command::Wear { output, .. }
        | Command::Run { output, .. }
        | Command::Rating { output, .. }
        | Command::Calibrate { output, .. }
        | Command::Sweep { output, .. }
        | Command::Spread { output, .. }
        | Command::ExportRexs { output, .. }
        | Command::Validate { output, .. }
        | Command::Compare { output, .. } => Some(output),
        Command::Pattern(args) => Some(&args.output),
    };
    let lock = match output
        .map(|dir| wormwear::output::lock_directory(dir))
        .transpose()
    {
        Ok(lock) => lock,
        Err(e) => {
            eprintln!("error: {e}");
            return Err(ExitCode::from(2));
        }
    };
    let stale = lock.as_ref().map_or(0, |l| l.stale_temporaries_removed);
    if stale > 0 && !cli.quiet {
        eprintln!("note: removed {stale} temporary file(s) left by an interrupted run");
    }
    Ok(lock)
}

/// Runs the command.
fn dispatch(cli: &Cli) -> Result<(), Failure> {
    match &cli.command {
        Command::Init {
            profile,
            output,
            force,
        } => init_cmd::init(*profile, output.as_deref(), *force, cli.quiet),
        Command::Compare { runs, output } => compare_cmd::compare(runs, output, cli.quiet),
        Command::Check { file, json } => check(file, *json, cli.quiet),
        Command::Geometry { file, output, cad } => geometry(file, output, cad, cli.quiet),
        Command::Tca { file, output } => tca(file, output, cli.quiet),
        Command::Ltca {
            file,
            output,
            map_position,
        } => ltca(file, output, *map_position, cli.quiet),
        Command::Wear {
            file,
            output,
            life,
            cad,
        } => wear(file, output, (life, cad), cli.quiet, cli.verbose),
        Command::Run {
            file,
            output,
            life,
            cad,
        } => run(file, output, (life, cad), cli.quiet, cli.verbose),
        Command::Rating { file, output, life } => {
            rating_cmd::rating(file, output, life, cli.quiet, cli.verbose)
        }
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
            jobs,
        } => validate(output, examples, *quick, jobs, cli.quiet),
        Command::Sweep {
            file,
            output,
            base_anywhere,
        } => sweep_cmd::sweep(file, output, *base_anywhere, cli.quiet),
        Command::Spread { file, output } => sweep_cmd::spread(file, output, cli.quiet),
        Command::Pattern(args) => pattern_cmd::pattern(args, cli.quiet),
        Command::Import {
            file,
            output,
            stage,
        } => rexs_cmd::import(file, output, *stage, cli.quiet),
        Command::ExportRexs {
            file,
            output,
            json,
            no_life,
            life,
        } => rexs_cmd::export(file, output, *json, *no_life, life, cli.quiet, cli.verbose),
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

/// `check`: the file validated, its geometry built and the checks `run` makes before any work
/// passed ([`wormwear::Request::check`]: a load the loaded analysis holds, a life that can
/// end; [`wormwear::Request::check_geometry`]: a load the flanks can carry); the derived data printed (nothing but the warnings, on stderr, when quiet).
fn check(file: &Path, json: bool, quiet: bool) -> Result<(), Failure> {
    let gear = load(file)?;
    let geo = build_geometry(&gear, file)?;
    let request = planned_request(Path::new("."), &gear, &LifeArgs::default(), RUN_STAGES)?;
    request
        .check(&gear)
        .and_then(|()| request.check_geometry(&gear, &geo))
        .map_err(|e| {
            Failure::Input(anyhow::Error::new(e).context(format!("in {}", file.display())))
        })?;
    let summary = GeometrySummary::new(&gear, &geo);
    if quiet {
        for w in &summary.warnings {
            eprintln!("warning: {w}");
        }
        return Ok(());
    }
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

/// Runs `request` on the gear of `file` into `dir`: the library's runner with the CLI's
/// progress (bending line, progress bar or one line per wear state), the life written state by
/// state as it goes, then the other files; prints the warnings.
fn analyse(
    file: &Path,
    gear: &GearSet,
    (dir, force): (&Path, bool),
    request: wormwear::Request,
    quiet: bool,
    verbose: bool,
) -> Result<(wormwear::Results, Vec<PathBuf>), Failure> {
    request::check_held_life(dir, &request, force)?;
    let earlier = request::EarlierOutputs::of(dir, &request);
    let source = wormwear::Source {
        file: file.display().to_string(),
        text: wormwear::files::read_text(file, wormwear::files::INPUT_LIMIT).unwrap_or_default(),
    };
    let life_cycles = request.life.as_ref().map_or(1.0, |p| p.life_cycles);
    let progress = life_progress(quiet || verbose || request.life.is_none());
    let mut writer = wormwear::output::wear::LifeWriter::new(dir);
    if request.life.is_some() {
        interrupt::life_started(dir);
    }
    let mut on_event = |event: wormwear::Event| -> Result<(), wormwear::RunError> {
        match event {
            wormwear::Event::Bending(info) if !quiet => print_bending(info),
            wormwear::Event::WearState(life) => {
                let stopped =
                    |e: wormwear::output::OutputError| wormwear::RunError::Stopped(e.to_string());
                earlier.clear().map_err(stopped)?;
                writer.write_view(life).map_err(stopped)?;
                let line = state_line(life.step.state);
                if verbose {
                    eprintln!("{line}");
                }
                let done = life.step.state.cycles / life_cycles;
                progress.set_position((1000.0 * done).round() as u64);
                progress.set_message(line);
            }
            _ => {}
        }
        Ok(())
    };
    let results =
        wormwear::run(gear, source, request, &mut on_event).map_err(|e| run_failure(e, file))?;
    progress.finish_and_clear();
    let written = earlier
        .clear()
        .and_then(|()| wormwear::output::write_results(&results, dir, true));
    let files = written.map_err(|e| Failure::Run(e.into()))?;
    for w in &results.warnings {
        eprintln!("warning: {w}");
    }
    if let Some(rating) = &results.rating {
        // The formulas' range notes unless quiet; an overload always.
        let shown = |w: &&String| !quiet || w.starts_with(wormwear::rating::OVERLOAD_TAG);
        for w in rating.warnings.iter().filter(shown) {
            eprintln!("warning: rating: {w}");
        }
    }
    Ok((results, files))
}

/// A failed run as the CLI reports it: the input's errors (exit 2) apart from the
/// computation's (1), with the file or option they concern.
fn run_failure(e: wormwear::RunError, file: &Path) -> Failure {
    let context = match &e {
        wormwear::RunError::Geometry(_) => format!("geometry of {}", file.display()),
        wormwear::RunError::Wear(wormwear::wear::WearError::Checkpoint(_)) => {
            "--resume".to_string()
        }
        _ => String::new(),
    };
    let input = e.is_input();
    let error = match context.is_empty() {
        true => anyhow::Error::new(e),
        false => anyhow::Error::new(e).context(context),
    };
    match input {
        true => Failure::Input(error),
        false => Failure::Run(error),
    }
}

/// Where the FE bending model came from (cache or build), on stdout.
fn print_bending(info: &wormwear::runner::BendingInfo) {
    let place = info
        .cache_file
        .as_ref()
        .map(|p| p.display().to_string())
        .unwrap_or_default();
    match info.origin {
        wormwear::bending::model::Origin::Cache => {
            println!("bending (fe): read in {:.3} s from {place}", info.seconds)
        }
        wormwear::bending::model::Origin::Computed => println!(
            "bending (fe): worm and wheel FE models computed in {:.1} s, cached in {place}",
            info.seconds
        ),
    }
}

/// One line on a completed wear state.
fn state_line(state: &wormwear::wear::WearState) -> String {
    let r = state.records.last().expect("record");
    format!(
        "step {} at {} cycles ({}): wear {:.2} um, backlash +{:.2} um, P_max {:.0} MPa",
        r.step,
        wormwear::output::cycles_label(r.cycles),
        r.phase,
        r.max_wear_m * 1e6,
        r.backlash_increase_m * 1e6,
        r.max_pressure_pa / 1e6
    )
}

/// Prints the files written (one line each).
fn print_files(files: &[PathBuf]) {
    for f in files {
        println!("  wrote {}", f.display());
    }
}

fn geometry(file: &Path, dir: &Path, cad: &CadArgs, quiet: bool) -> Result<(), Failure> {
    let gear = load(file)?;
    let mut request = wormwear::Request::new([wormwear::Stage::Geometry]);
    request.cad = cad.request(dir)?;
    let (results, files) = analyse(file, &gear, (dir, false), request, quiet, false)?;
    if !quiet {
        print_files(&files);
        print_geometry(&results, dir);
    }
    Ok(())
}

/// The geometry's one-line result.
fn print_geometry(results: &wormwear::Results, dir: &Path) {
    let s = GeometrySummary::new(&results.gear, &results.geometry);
    println!(
        "geometry written to {}: lead angle {:.3} deg, active flank {:.1} mm^2",
        dir.display(),
        s.lead_angle_deg,
        s.active_flank_area_mm2
    );
}

fn tca(file: &Path, dir: &Path, quiet: bool) -> Result<(), Failure> {
    let gear = load(file)?;
    let request = wormwear::Request::new([wormwear::Stage::Tca]);
    let (results, files) = analyse(file, &gear, (dir, false), request, quiet, false)?;
    if !quiet {
        print_files(&files);
        print_tca(&results);
    }
    Ok(())
}

/// The unloaded analysis's one-line result.
fn print_tca(results: &wormwear::Results) {
    let Some(tca) = &results.tca else { return };
    let s = wormwear::output::tca::TcaSummary::new(tca);
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

/// `--map-position` among the file's positions (a usage error otherwise).
fn check_map_position(file: &Path, gear: &GearSet, map_position: usize) -> Result<(), Failure> {
    let positions = gear.analysis.positions;
    if map_position >= positions {
        return Err(Failure::Input(anyhow::anyhow!(
            "--map-position = {map_position}: {} analyses {positions} positions, numbered 0 to {}",
            file.display(),
            positions.saturating_sub(1)
        )));
    }
    Ok(())
}

fn ltca(file: &Path, dir: &Path, map_position: usize, quiet: bool) -> Result<(), Failure> {
    let gear = load(file)?;
    check_map_position(file, &gear, map_position)?;
    let mut request = wormwear::Request::new([wormwear::Stage::Ltca]);
    request.map_position = map_position;
    let (results, files) = analyse(file, &gear, (dir, false), request, quiet, false)?;
    if !quiet {
        print_files(&files);
        print_ltca(&results);
    }
    Ok(())
}

/// The loaded analysis's one-line result.
fn print_ltca(results: &wormwear::Results) {
    let Some(result) = &results.ltca else { return };
    let (te, p2p) = result.te_stats();
    println!(
        "ltca ({}): T1 {:.2} N m, T2 {:.1} N m ({} torque, eta_z {:.4}); P_max {:.0} MPa, P_mean \
         {:.0} MPa, S0 {:.2}, TE mean {:.3e} rad p2p {:.3e} rad, stiffness {:.3e} N m/rad, up to \
         {} teeth loaded",
        result.bending_model,
        result.worm_torque,
        result.wheel_torque,
        match result.torque_balance {
            wormwear::input::TorqueBalance::Transmitted => "transmitted",
            wormwear::input::TorqueBalance::Frictionless => "frictionless",
        },
        result.mesh_efficiency,
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
            -result.shaft_torsion_compliance
                * result.positions.iter().map(|p| p.normal_wheel_torque).sum::<f64>()
                / result.positions.len().max(1) as f64,
            result.stiffness_without_shaft_torsion_mean()
        );
    }
    if let Some(t) = &results.thermal {
        println!(
            "friction (MODEL §13): mu mean {:.4}, mesh loss {:.1} W, mesh efficiency {:.4}, \
             total {:.4}; oil {:.1} C ({}), viscosity {:.4} Pa s",
            t.friction.mean_coefficient,
            t.friction.mesh_loss_w,
            t.efficiency.mesh_efficiency,
            t.efficiency.total_efficiency,
            t.oil_temperature_k - 273.15,
            t.mode,
            t.viscosity_pa_s
        );
        if let Some(lock) = &t.self_locking {
            println!("{}", rating_cmd::self_locking_line(lock));
        }
    }
    if let Some(s) = &results.spectrum {
        println!("{}", rating_cmd::duty_cycle_lines(s));
    }
}

fn wear(
    file: &Path,
    dir: &Path,
    (args, cad): (&LifeArgs, &CadArgs),
    quiet: bool,
    verbose: bool,
) -> Result<(), Failure> {
    let gear = load(file)?;
    let request = life_request(dir, &gear, args, &[wormwear::Stage::Wear])?;
    let request = with_cad(request, cad, dir, &gear)?;
    let (results, _) = analyse(file, &gear, (dir, args.force), request, quiet, verbose)?;
    finish_life(&results, dir, quiet);
    Ok(())
}

/// The end of a life: warnings, and the result paragraph unless quiet.
fn finish_life(results: &wormwear::Results, dir: &Path, quiet: bool) {
    let Some(life) = &results.life else { return };
    warn_about_the_life(results, life);
    if let (Some(rating), false) = (&results.rating, quiet) {
        print_life(&life.end, rating, dir);
    }
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
        "wear: {} steps to {} cycles; backlash +{:.2} um, mean wear {:.2} um, worn volume {:.3} \
         mm^3, max wear {:.2} um (mesh-dependent); P_max {:.0} -> {:.0} MPa, S0 {:.2} -> {:.2}; \
         results in {}",
        last.step,
        wormwear::output::cycles_label(last.cycles),
        last.backlash_increase_m * 1e6,
        last.mean_wear_m * 1e6,
        last.worn_volume_m3 * 1e9,
        last.max_wear_m * 1e6,
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

/// Warnings on a finished life ([`wormwear::wear::WearState::warnings`], each tagged by
/// its subject: wear limit, wear, pitting, contact).
fn warn_about_the_life(results: &wormwear::Results, life: &wormwear::runner::Life) {
    let Some(tca) = &results.tca else { return };
    let wf = results.geometry.wheel_flank(tca.loaded_flank);
    for w in life.warnings(wf) {
        eprintln!("warning: {w}");
    }
}

/// The stages of `run`: with a life, and without.
const RUN_STAGES: (&[wormwear::Stage], &[wormwear::Stage]) = (
    &wormwear::Stage::ALL,
    &[
        wormwear::Stage::Geometry,
        wormwear::Stage::Tca,
        wormwear::Stage::Ltca,
        wormwear::Stage::Report,
    ],
);

fn run(
    file: &Path,
    dir: &Path,
    (args, cad): (&LifeArgs, &CadArgs),
    quiet: bool,
    verbose: bool,
) -> Result<(), Failure> {
    let gear = load(file)?;
    let request = planned_request(dir, &gear, args, RUN_STAGES)?;
    let request = with_cad(request, cad, dir, &gear)?;
    let (results, files) = analyse(file, &gear, (dir, args.force), request, quiet, verbose)?;
    if !quiet {
        print_geometry(&results, dir);
        print_tca(&results);
        print_ltca(&results);
    }
    finish_life(&results, dir, quiet);
    if !quiet {
        if let Some(table) = &results.safety {
            rating_cmd::print_safety(table);
        }
        if let Some(report) = files.iter().find(|f| f.ends_with("report.html")) {
            println!("report: {}", report.display());
        }
    }
    Ok(())
}

/// K from wear tests or from a backlash curve; writes the `calibration` section.
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
    let section = match (tests, backlash) {
        (Some(path), _) => calibrate_cmd::from_tests(&gear, path, quiet)?,
        (None, Some(path)) => {
            calibrate_cmd::from_backlash(&gear, file, dir, path, no_pitting, quiet, verbose)?
        }
        (None, None) => unreachable!("clap requires --tests or --backlash"),
    };
    wormwear::output::update_summary(dir, "calibration", section)
        .map_err(|e| Failure::Run(e.into()))?;
    Ok(())
}

/// Runs the validation study into `dir` (VALIDATION.md at its root).
fn validate(
    dir: &Path,
    examples: &Path,
    quick: bool,
    only: &[String],
    quiet: bool,
) -> Result<(), Failure> {
    if !examples.join("gear-1x40-design.toml").is_file() {
        return Err(Failure::Input(anyhow::anyhow!(
            "--examples = {}: no gear-1x40-design.toml there (run from the repository root or give the examples directory)",
            examples.display()
        )));
    }
    let settings = wormwear::validation::Settings {
        examples: examples.to_path_buf(),
        quick,
        only: only.to_vec(),
    };
    let path = wormwear::validation::run(&settings, dir, &mut |line| {
        if !quiet {
            eprintln!("{line}");
        }
    })
    .map_err(|e| match e {
        wormwear::validation::ValidationError::Input { .. }
        | wormwear::validation::ValidationError::UnknownJob { .. } => Failure::Input(e.into()),
        _ => Failure::Run(anyhow::Error::new(e).context("validation study")),
    })?;
    if !quiet {
        println!("validation written to {}", path.display());
    }
    Ok(())
}

/// The threads the sweep's variants share.
fn rayon_threads() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}
