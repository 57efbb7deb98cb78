//! `wormwear init`: a new gear file with every section, its units and defaults.

use crate::Failure;
use anyhow::{anyhow, Context};
use std::path::Path;
use wormwear::input::ProfileType;

/// The thread profile of the new file.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum ProfileArg {
    /// ZA: straight edge in the axial plane.
    A,
    /// ZN: straight edge in the normal plane.
    N,
    /// ZI: involute helicoid.
    I,
    /// ZK: ground by a biconical wheel.
    K,
    /// ZC: ground by a wheel with a circular-arc profile.
    C,
}

impl From<ProfileArg> for ProfileType {
    fn from(p: ProfileArg) -> Self {
        match p {
            ProfileArg::A => ProfileType::A,
            ProfileArg::N => ProfileType::N,
            ProfileArg::I => ProfileType::I,
            ProfileArg::K => ProfileType::K,
            ProfileArg::C => ProfileType::C,
        }
    }
}

/// Writes the template to `output` (refused when the file exists, unless `force`), or prints it.
pub fn init(
    profile: ProfileArg,
    output: Option<&Path>,
    force: bool,
    quiet: bool,
) -> Result<(), Failure> {
    let text = wormwear::input::template::gear_template(profile.into());
    let Some(path) = output else {
        print!("{text}");
        return Ok(());
    };
    if path.is_dir() {
        return Err(Failure::Input(anyhow!(
            "-o {}: is a directory; give the gear file's name, e.g. {}/gear.toml",
            path.display(),
            path.display()
        )));
    }
    if let Some(kind) = wormwear::output::not_a_regular_file(path) {
        return Err(Failure::Input(anyhow!(
            "-o {}: it is {kind}, not a regular file; give the gear file's name",
            path.display()
        )));
    }
    // A link (even one to nothing) is there: replaced only with --force.
    if path.symlink_metadata().is_ok() && !force {
        return Err(Failure::Input(anyhow!(
            "-o {}: the file exists; give another name or --force to replace it",
            path.display()
        )));
    }
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("creating {}", dir.display()))
            .map_err(Failure::Run)?;
    }
    wormwear::output::write_atomic(path, text.as_bytes()).map_err(|e| Failure::Run(e.into()))?;
    if !quiet {
        println!(
            "wrote {} (profile {profile:?}); next: wormwear check {} && wormwear run {} -o out",
            path.display(),
            path.display(),
            path.display()
        );
    }
    Ok(())
}
