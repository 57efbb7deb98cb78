//! `wormwear pattern`: the contact-pattern assistant (MODEL §17), a line per evaluation on
//! stderr, the best settings and where the files went on stdout.
use super::Failure;
use std::path::{Path, PathBuf};
use wormwear::pattern_assistant::{self as assistant, Assistant, PatternError, Target, Which};

/// The command's help after the options.
pub(crate) const AFTER_HELP: &str = "Examples:\n  \
    wormwear pattern examples/gear-1x40-design.toml --target centre_across_face=0.6 -o out/pattern\n  \
    wormwear pattern gear.toml --target centre_across_face=0.65,extent_along_face=0.5 \\\n      \
    --vary cutting.centre_distance_mm=125.2:126 --vary cutting.inclination_deg=-0.3:0.3 -o out/p\n\n\
    Target components (shares in [0, 1], any of them): centre_across_face (0 at the entering \
    side, 1 at the leaving side), centre_up_flank (0 at the flank's lower limit), \
    extent_along_face, extent_up_flank.\n\
    Settings: any numeric gear-file field by dotted name, and hob.oversize_mm (the hob's \
    reference, tip and root radii grow together). Default: cutting.centre_distance_mm +/- 0.2 \
    m_x, cutting.inclination_deg (the hob swivel) +/- 0.5 deg, hob.oversize_mm 0 to 0.2 m_x.\n\
    Writes gear.toml (the best settings, the base's comments kept), pattern.json, search.csv, \
    before/ and after/ (the analyses with the pattern's map).";

/// The options of `wormwear pattern`.
#[derive(clap::Args, Debug)]
pub(crate) struct PatternArgs {
    /// Gear file (TOML): the base gear, whose settings the search starts from.
    pub(crate) file: PathBuf,
    /// The target shape: name=value pairs separated by commas (see below).
    #[arg(long)]
    pub(crate) target: String,
    /// A setting to search and its bounds, name=min:max, in the field's units (repeat for
    /// several; default: see below).
    #[arg(long = "vary", value_name = "NAME=MIN:MAX")]
    pub(crate) vary: Vec<String>,
    /// Target the loaded pattern (the loaded analysis at the file's load, with its bending;
    /// slower) instead of the no-load pattern of a marking test.
    #[arg(long)]
    pub(crate) loaded: bool,
    /// Evaluations (analyses) the search may spend.
    #[arg(long, default_value_t = assistant::DEFAULT_EVALUATIONS)]
    pub(crate) evaluations: usize,
    /// Output directory (created if needed).
    #[arg(short, long)]
    pub(crate) output: PathBuf,
}

/// Runs the search and writes its files into the output directory.
pub(crate) fn pattern(args: &PatternArgs, quiet: bool) -> Result<(), Failure> {
    let in_file = |e: PatternError| {
        let context = format!("in {}", args.file.display());
        match e {
            PatternError::Output(_) => Failure::Run(e.into()),
            _ => Failure::Input(anyhow::Error::new(e).context(context)),
        }
    };
    let study = prepare(args).map_err(in_file)?;
    if !quiet {
        eprintln!(
            "pattern: the {} pattern of {} toward {}, searching {} within {} evaluations",
            study.which.name(),
            study.base_file,
            assistant::target_text(&study.target),
            study
                .settings
                .iter()
                .map(|s| format!("{} [{}, {}]", s.name, s.min, s.max))
                .collect::<Vec<_>>()
                .join(", "),
            study.evaluations
        );
        for note in &study.notes {
            eprintln!("note: {note}");
        }
    }
    let on_evaluation = |k: usize, e: &assistant::Evaluation| {
        if !quiet {
            eprintln!(
                "[{k}] objective {:.3e}: {}",
                e.objective,
                assistant::shape_text(e)
            );
        }
    };
    let outcome = study.run(&on_evaluation, &|| false).map_err(in_file)?;
    let files = assistant::write(&study, &outcome, &args.output)
        .map_err(|e| Failure::Run(anyhow::Error::new(e).context("pattern")))?;
    if !quiet {
        report(&study, &outcome, &args.output, files.len());
    }
    Ok(())
}

/// The search of the command line's options, checked.
fn prepare(args: &PatternArgs) -> Result<Assistant, PatternError> {
    let text = wormwear::files::read_text(&args.file, wormwear::files::INPUT_LIMIT)
        .map_err(|e| PatternError::Base(format!("cannot read {}: {e}", args.file.display())))?;
    let target = Target::parse(&args.target)?;
    let bounds = match args.vary.is_empty() {
        true => None,
        false => Some(
            args.vary
                .iter()
                .map(|v| assistant::parse_bounds(v))
                .collect::<Result<Vec<_>, _>>()?,
        ),
    };
    let which = if args.loaded {
        Which::Loaded
    } else {
        Which::NoLoad
    };
    let file = args.file.display().to_string();
    Assistant::new(file, text, target, bounds, which, args.evaluations)
}

/// The start and the best on stdout, with where the files went.
fn report(study: &Assistant, outcome: &assistant::Outcome, dir: &Path, files: usize) {
    println!(
        "pattern: {} evaluations ({}); objective {:.3e} -> {:.3e}",
        outcome.path.len(),
        outcome.stopped,
        outcome.start.objective,
        outcome.best.objective
    );
    println!("  before: {}", assistant::shape_text(&outcome.start));
    println!("  after:  {}", assistant::shape_text(&outcome.best));
    for (s, v) in study.settings.iter().zip(&outcome.best.values) {
        println!("  {:<32} {} -> {v:.6}", s.name, s.start);
    }
    println!(
        "{files} files in {} (gear.toml: the best settings; pattern.json, search.csv, before/, after/)",
        dir.display()
    );
}
