//! `wormwear import` (REXS -> gear file) and `wormwear export-rexs` (gear file + results ->
//! REXS): argument handling and printing over `wormwear::rexs`.

use crate::{analyse, life_request, load, Failure, LifeArgs};
use anyhow::Context;
use std::path::Path;
use wormwear::rexs;

/// Reads a REXS file, writes the gear file of its worm stage, then validates it as `check`
/// would. An invalid result is kept (for editing) and reported with exit code 2.
pub fn import(file: &Path, output: &Path, stage: Option<u64>, quiet: bool) -> Result<(), Failure> {
    if let Some(kind) = wormwear::output::not_a_regular_file(output) {
        return Err(Failure::Input(anyhow::anyhow!(
            "-o {}: it is {kind}, not a regular file; give the gear file's name",
            output.display()
        )));
    }
    let model = rexs::read(file).map_err(|e| Failure::Input(e.into()))?;
    let imported =
        rexs::import::import(&model, stage, &file.display().to_string()).map_err(|e| {
            Failure::Input(anyhow::Error::new(e).context(format!("in {}", file.display())))
        })?;
    if let Some(dir) = output.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("creating {}", dir.display()))
            .map_err(Failure::Run)?;
    }
    wormwear::output::write_atomic(output, imported.text.as_bytes())
        .map_err(|e| Failure::Run(e.into()))?;
    for w in &imported.warnings {
        eprintln!("warning: {w}");
    }
    let stage_line = format!(
        "worm stage {} \"{}\" (worm {}, wheel {})",
        imported.stage.id, imported.stage.name, imported.stage.worm, imported.stage.wheel
    );
    match wormwear::input::load(output) {
        Ok(_) => {
            if !quiet {
                println!("{}: {stage_line} -> {} (valid)", file.display(), output.display());
            }
            Ok(())
        }
        Err(e) => Err(Failure::Input(anyhow::Error::new(imported.with_sources(e)).context(format!(
            "{stage_line} was written to {}, but it does not validate; edit it and run `wormwear check`",
            output.display()
        )))),
    }
}

/// Runs the loaded analysis (and the life when the file has one, unless `no_life`), writes
/// the usual outputs into `dir` and the stage with its results as `dir/<stem>.rexs` (or
/// `.rexsj` with `json`).
pub fn export(
    file: &Path,
    dir: &Path,
    json: bool,
    no_life: bool,
    life: &LifeArgs,
    quiet: bool,
    verbose: bool,
) -> Result<(), Failure> {
    use wormwear::Stage;
    let gear = load(file)?;
    let stages = [Stage::Geometry, Stage::Tca, Stage::Ltca];
    let request = match !no_life && (gear.wear.is_some() || life.overrides().asks_for_life()) {
        true => life_request(
            dir,
            &gear,
            life,
            &[Stage::Geometry, Stage::Tca, Stage::Ltca, Stage::Wear],
        )?,
        false => wormwear::Request::new(stages),
    };
    let (results, _) = analyse(file, &gear, (dir, life.force), request, quiet, verbose)?;
    let model = rexs::export::stage_model(&gear, Some(&results), &rexs::export::utc_now())
        .map_err(|e| Failure::Run(e.into()))?;
    let (encoding, extension) = match json {
        true => (rexs::Encoding::Json, "rexsj"),
        false => (rexs::Encoding::Xml, "rexs"),
    };
    let stem = file
        .file_stem()
        .map_or("stage".into(), |s| s.to_string_lossy().into_owned());
    let path = dir.join(format!("{stem}.{extension}"));
    wormwear::output::write_atomic(&path, rexs::to_string(&model, encoding).as_bytes())
        .map_err(|e| Failure::Run(e.into()))?;
    if !quiet {
        println!("REXS {}: {}", model.version, path.display());
    }
    Ok(())
}
