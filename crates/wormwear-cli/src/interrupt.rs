//! Ctrl-C (SIGINT): the run stops at once, says where it stopped and how to continue, and exits
//! with 130 (128 + SIGINT), as a shell expects. The files written so far are whole (atomic
//! writes; a life's records and checkpoint are sealed), so stopping loses at most the state in
//! progress.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// What is running, for what an interruption says.
enum Running {
    /// A life writing its checkpoint into the folder.
    Life(PathBuf),
    /// A sweep writing its variants into the folder.
    Sweep(PathBuf),
}

static RUNNING: Mutex<Option<Running>> = Mutex::new(None);

/// Installs the handler (once, first in `main`); without it (a handler already set by an
/// embedding program) SIGINT keeps its default action.
pub(crate) fn install() {
    let _ = ctrlc::set_handler(|| {
        let said = match RUNNING.lock().as_deref() {
            Ok(Some(Running::Life(dir))) => life_stopped(dir),
            Ok(Some(Running::Sweep(dir))) => format!(
                "the finished variants are kept in {}; run the same command again to finish \
                 the sweep (it reuses them):\n  {}",
                dir.display(),
                command_line(false)
            ),
            _ => "the outputs may be incomplete".to_string(),
        };
        eprintln!("\ninterrupted: {said}");
        std::process::exit(130);
    });
}

/// A life runs into `dir` from now on.
pub(crate) fn life_started(dir: &Path) {
    if let Ok(mut r) = RUNNING.lock() {
        *r = Some(Running::Life(dir.to_path_buf()));
    }
}

/// A sweep runs into `dir` from now on.
pub(crate) fn sweep_started(dir: &Path) {
    if let Ok(mut r) = RUNNING.lock() {
        *r = Some(Running::Sweep(dir.to_path_buf()));
    }
}

/// Where a life stopped: the state its checkpoint in `dir` holds (what --resume continues
/// from), and the command line that continues it (this one, with --resume).
fn life_stopped(dir: &Path) -> String {
    match wormwear::output::wear::read_checkpoint(dir) {
        Ok(Some(state)) => format!(
            "the life's last saved state is step {} ({:.0} cycles) in {}; continue it with the \
             same options and --resume:\n  {}",
            state.step,
            state.cycles,
            dir.display(),
            command_line(true)
        ),
        Ok(None) => format!(
            "no state of the life was saved in {} yet: run the command again (nothing to \
             resume)",
            dir.display()
        ),
        Err(e) => format!("the checkpoint in {} cannot be read ({e})", dir.display()),
    }
}

/// This process's command line, with `--resume` (added once) when `resume`, each argument
/// quoted for a POSIX shell where it needs it.
fn command_line(resume: bool) -> String {
    let mut args: Vec<String> = std::env::args().collect();
    if let Some(first) = args.first_mut() {
        *first = "wormwear".to_string();
    }
    if resume && !args.iter().any(|a| a == "--resume") {
        args.push("--resume".to_string());
    }
    args.iter().map(|a| quoted(a)).collect::<Vec<_>>().join(" ")
}

/// `a` as a POSIX shell word: as is when it holds only safe characters, else in single quotes.
fn quoted(a: &str) -> String {
    let safe = |c: char| c.is_ascii_alphanumeric() || "-_./=:,+@%".contains(c);
    match !a.is_empty() && a.chars().all(safe) {
        true => a.to_string(),
        false => format!("'{}'", a.replace('\'', "'\\''")),
    }
}
