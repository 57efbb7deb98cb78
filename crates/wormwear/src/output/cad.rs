//! Files of the CAD solids (issue 37): `worm.step`, `wheel.step` and after a life
//! `wheel_worn.step` (ISO 10303-21, AP214, mm, the worm frame of MODEL §1: the parts assemble
//! at the operating centre distance), `cad_faces.csv` (every lateral face: part, kind, tooth,
//! band, area, centroid) and summary.json's `cad` section (volumes, flank areas, the fit's
//! deviation).

use super::{to_json, update_summary, write_atomic, OutputError};
use crate::cad::{CadPart, CadSolids, PartSummary, WornFrom};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The worm's STEP file.
pub const WORM_FILE: &str = "worm.step";
/// The new wheel's STEP file.
pub const WHEEL_FILE: &str = "wheel.step";
/// The worn wheel's STEP file.
pub const WORN_FILE: &str = "wheel_worn.step";
/// The table of the solids' faces.
pub const FACES_FILE: &str = "cad_faces.csv";

/// Refuses an output directory where one of the CAD files' paths is a directory (checked
/// before a run, so that a long life is not lost at its end).
pub fn check_targets(dir: &Path) -> Result<(), OutputError> {
    for name in [WORM_FILE, WHEEL_FILE, WORN_FILE, FACES_FILE] {
        let path = dir.join(name);
        if path.is_dir() {
            return Err(OutputError::IsDirectory {
                path,
                what: "the CAD output",
            });
        }
    }
    Ok(())
}

/// summary.json's `cad` section.
#[derive(Debug, serde::Serialize)]
struct CadSection {
    frame: &'static str,
    length_unit: &'static str,
    worm: PartSummary,
    wheel: PartSummary,
    wheel_worn: Option<WornSection>,
    /// Largest fit deviation of the new flanks (worm and wheel), um.
    max_flank_fit_deviation_um: f64,
}

#[derive(Debug, serde::Serialize)]
struct WornSection {
    #[serde(flatten)]
    from: WornFrom,
    #[serde(flatten)]
    part: PartSummary,
}

/// The `cad` section of summary.json.
pub fn summary_value(solids: &CadSolids) -> Result<serde_json::Value, OutputError> {
    to_json("cad", &section(solids))
}

/// The section's content: each part's summary (its faces integrated and its fit measured once).
fn section(solids: &CadSolids) -> CadSection {
    let (worm, wheel) = (
        solids.worm.summary(WORM_FILE),
        solids.wheel.summary(WHEEL_FILE),
    );
    CadSection {
        frame: "worm frame of MODEL §1: x along the worm axis, the wheel centre at y = a; \
                worm and wheel at rotation 0",
        length_unit: "mm",
        max_flank_fit_deviation_um: worm.max_fit_deviation_um.max(wheel.max_fit_deviation_um),
        worm,
        wheel,
        wheel_worn: solids.worn.as_ref().map(|(from, part)| WornSection {
            from: *from,
            part: part.summary(WORN_FILE),
        }),
    }
}

/// Writes the STEP files, the faces' table and the `cad` section into `dir`.
pub fn write_cad(solids: &CadSolids, dir: &Path) -> Result<Vec<PathBuf>, OutputError> {
    check_targets(dir)?;
    let section = section(solids);
    let mut parts: Vec<(&str, &str, &CadPart, &PartSummary)> = vec![
        (WORM_FILE, "worm", &solids.worm, &section.worm),
        (WHEEL_FILE, "wheel", &solids.wheel, &section.wheel),
    ];
    if let (Some((_, part)), Some(worn)) = (&solids.worn, &section.wheel_worn) {
        parts.push((WORN_FILE, "wheel_worn", part, &worn.part));
    }
    let mut files = Vec::new();
    let mut faces = String::from("part,kind,tooth,band,area_mm2,x_mm,y_mm,z_mm\n");
    for (file, name, part, summary) in parts {
        let text = part.step_text(name).map_err(|e| OutputError::Encode {
            what: file.into(),
            message: e.to_string(),
        })?;
        let path = dir.join(file);
        write_atomic(&path, text.as_bytes())?;
        files.push(path);
        for f in &summary.face_list {
            let kind = serde_json::to_value(f.kind).unwrap_or_default();
            let [x, y, z] = f.centroid_mm;
            let _ = writeln!(
                faces,
                "{name},{},{},{},{:.6},{x:.6},{y:.6},{z:.6}",
                kind.as_str().unwrap_or(""),
                f.index,
                f.band,
                f.area_mm2
            );
        }
    }
    let path = dir.join(FACES_FILE);
    write_atomic(&path, faces.as_bytes())?;
    files.push(path);
    update_summary(dir, "cad", to_json("cad", &section)?)?;
    Ok(files)
}
