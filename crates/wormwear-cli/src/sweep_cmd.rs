//! `wormwear sweep` and `wormwear spread`: variants of a base gear file run in parallel on the
//! local cores, a line per finished variant on stderr.
use super::{interrupt, Failure};
use std::path::Path;

/// Runs a sweep file's variants into `dir`: a line per finished variant on stderr, the rows'
/// table and page at the end. Fails only when no variant succeeds.
pub(crate) fn sweep(
    file: &Path,
    dir: &Path,
    base_anywhere: bool,
    quiet: bool,
) -> Result<(), Failure> {
    use wormwear::sweep::{BaseAccess, SweepError};
    let access = match base_anywhere {
        true => BaseAccess::Anywhere,
        false => BaseAccess::Confined,
    };
    let study = wormwear::sweep::Sweep::load_with(file, access).map_err(|e| match e {
        SweepError::Output(_) => Failure::Run(e.into()),
        _ => Failure::Input(anyhow::Error::new(e).context(format!("in {}", file.display()))),
    })?;
    interrupt::sweep_started(dir);
    if !quiet {
        eprintln!(
            "sweep: {} variants of {} on {} threads",
            study.variants.len(),
            study.base_file,
            super::rayon_threads()
        );
    }
    let on_progress = progress(quiet);
    let rows = wormwear::sweep::run(&study, dir, &on_progress, &|| false)
        .map_err(|e| Failure::Run(anyhow::Error::new(e).context("sweep")))?;
    let failed = rows.iter().filter(|r| !r.ok).count();
    if failed > 0 {
        eprintln!(
            "warning: sweep: {failed} of {} variants failed (their errors are in sweep.csv)",
            rows.len()
        );
    }
    if failed == rows.len() {
        let first = rows.first().map_or(String::new(), |r| {
            format!(
                "; the first, {}: {}",
                r.variant,
                r.error.as_deref().unwrap_or("no message")
            )
        });
        return Err(Failure::Run(anyhow::anyhow!(
            "sweep: every variant failed{first}"
        )));
    }
    if !quiet {
        println!(
            "sweep: {} variants ({failed} failed); results in {} (sweep.csv, sweep.html)",
            rows.len(),
            dir.display()
        );
    }
    Ok(())
}

/// The line on stderr for each finished variant or sample (none when `quiet`).
fn progress(quiet: bool) -> impl Fn(wormwear::sweep::Progress) + Sync {
    move |p: wormwear::sweep::Progress| {
        if quiet {
            return;
        }
        let what = match (&p.row.error, p.reused) {
            (Some(e), _) => format!("failed: {e}"),
            (None, true) => "reused from an earlier run".to_string(),
            (None, false) => format!("done in {:.1} s", p.row.seconds),
        };
        eprintln!("[{}/{}] {}: {what}", p.done, p.total, p.row.variant);
    }
}

/// Runs a spread file's samples into `dir` (MODEL §17): a line per finished sample on stderr,
/// each key result's P10 / P50 / P90 at the end. Fails only when no sample succeeds.
pub(crate) fn spread(file: &Path, dir: &Path, quiet: bool) -> Result<(), Failure> {
    use wormwear::sweep::SweepError;
    let spread = wormwear::spread::Spread::load(file).map_err(|e| match e {
        SweepError::Output(_) => Failure::Run(e.into()),
        _ => Failure::Input(anyhow::Error::new(e).context(format!("in {}", file.display()))),
    })?;
    interrupt::sweep_started(dir);
    if !quiet {
        eprintln!(
            "spread: {} samples of {} inputs of {} (seed {}) on {} threads",
            spread.samples,
            spread.inputs.len(),
            spread.sweep.base_file,
            spread.seed,
            super::rayon_threads()
        );
    }
    let on_progress = progress(quiet);
    let out = wormwear::spread::run(&spread, dir, &on_progress, &|| false)
        .map_err(|e| Failure::Run(anyhow::Error::new(e).context("spread")))?;
    let failed = out.rows.iter().filter(|r| !r.ok).count();
    if failed == out.rows.len() {
        return Err(Failure::Run(anyhow::anyhow!("spread: every sample failed")));
    }
    if failed > 0 {
        eprintln!(
            "warning: spread: {failed} of {} samples failed (spread.csv)",
            out.rows.len()
        );
    }
    if !quiet {
        let summary = wormwear::spread::summary(&spread, &out);
        println!("spread: {} samples; P10 / P50 / P90:", out.rows.len());
        for (name, r) in summary["results"].as_object().into_iter().flatten() {
            let q = |k: &str| r[k].as_f64().map_or("-".into(), |v| format!("{v:.4e}"));
            println!("  {name:<32} {} / {} / {}", q("p10"), q("p50"), q("p90"));
        }
        println!("results in {} (spread.csv, spread.json)", dir.display());
    }
    Ok(())
}
