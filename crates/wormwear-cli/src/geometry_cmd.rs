//! `wormwear geometry`: the library writes the files; this reports them.
use std::path::Path;
use wormwear::geometry::Geometry;
use wormwear::input::GearSet;

pub fn write_geometry(
    gear: &GearSet,
    geo: &Geometry,
    file: &Path,
    dir: &Path,
    quiet: bool,
) -> anyhow::Result<()> {
    let files = wormwear::output::geometry::write_geometry(gear, geo, file, dir)?;
    if !quiet {
        for f in &files {
            println!("  wrote {}", f.display());
        }
    }
    Ok(())
}
