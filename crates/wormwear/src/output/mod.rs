//! Result files: atomic writes, the shared `summary.json`, CSV tables.
//!
//! Every file is written to a temporary sibling and renamed into place, so an interrupted run
//! never leaves a half-written file. `summary.json` is one JSON object; each command adds or
//! replaces its own section and keeps the others.

pub mod cad;
pub mod compare;
pub mod friction;
pub mod geometry;
pub mod ltca;
pub mod owned;
pub mod plot;
pub mod report;
pub mod safety;
pub mod spectrum;
pub mod tca;
pub mod text;
pub mod vtk;
pub mod wear;

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// Error writing results.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error("cannot write {path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("cannot encode {what}: {message}")]
    Encode { what: String, message: String },
    #[error("cannot read {path}: {message}")]
    Read { path: PathBuf, message: String },
    #[error("cannot write {path}: it is a directory, and {what} needs a file there")]
    IsDirectory { path: PathBuf, what: &'static str },
    #[error("cannot write {path}: it is {kind}, not a regular file; give the name of a file")]
    NotRegularFile { path: PathBuf, kind: &'static str },
    /// A drawing of the geometry (a section) could not be computed.
    #[error("geometry drawing")]
    Geometry(#[source] crate::geometry::GeometryError),
}

/// Name of the lock file a run holds in its output directory.
pub const LOCK_FILE: &str = ".wormwear.lock";

/// An exclusive lock on an output directory, held while the value lives. It is an OS file
/// lock, which the system releases when the process ends: a killed run leaves no stale lock.
#[derive(Debug)]
pub struct DirectoryLock {
    _file: std::fs::File,
    /// Temporaries of an interrupted run removed when the lock was taken.
    pub stale_temporaries_removed: usize,
}

/// Why an output directory could not be locked.
#[derive(Debug, thiserror::Error)]
pub enum LockError {
    #[error(
        "another wormwear run is writing into {dir} (it holds {lock}); wait for it to end or \
         choose another output directory"
    )]
    Busy { dir: PathBuf, lock: PathBuf },
    #[error("cannot lock the output directory {path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
}

/// Creates `dir` if needed and takes its lock ([`LOCK_FILE`]); fails at once if another
/// process holds it (two runs into one directory would interleave their files). With the
/// lock, the temporaries a killed run left there are removed.
pub fn lock_directory(dir: &Path) -> Result<DirectoryLock, LockError> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| LockError::Io { path, source }
    };
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    let path = dir.join(LOCK_FILE);
    let file = std::fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(&path)
        .map_err(io(&path))?;
    match file.try_lock() {
        Ok(()) => Ok(DirectoryLock {
            _file: file,
            stale_temporaries_removed: remove_stale_temporaries(dir),
        }),
        Err(std::fs::TryLockError::WouldBlock) => Err(LockError::Busy {
            dir: dir.to_path_buf(),
            lock: path,
        }),
        Err(std::fs::TryLockError::Error(source)) => Err(LockError::Io { path, source }),
    }
}

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> OutputError + '_ {
    move |source| OutputError::Io {
        path: path.to_path_buf(),
        source,
    }
}

pub use crate::wear::cycles_label;

/// A CSV field, quoted when it holds a comma, a quote or a line break. A text (`number`
/// false) that starts like a spreadsheet formula (= + - @, a tab or a carriage return) is
/// prefixed with an apostrophe, so that a spreadsheet shows it instead of evaluating it.
pub fn csv_cell(text: &str, number: bool) -> String {
    let formula = text.starts_with(['=', '+', '-', '@', '\t', '\r']) && !number;
    let text = if formula {
        format!("'{text}")
    } else {
        text.to_string()
    };
    match text.contains([',', '"', '\n', '\r']) {
        true => format!("\"{}\"", text.replace('"', "\"\"")),
        false => text,
    }
}

/// A CSV field of a text (never read as a number: "+1" is a name): [`csv_cell`].
pub fn csv_text(text: &str) -> String {
    csv_cell(text, false)
}

pub use crate::files::not_a_regular_file;

/// Writes `bytes` to `path` atomically (temporary file in the same directory, then rename).
/// Refused where `path` is (or links to) something other than a regular file: a device, a
/// FIFO or a directory is never replaced by a file. Errors name `path`, not the temporary.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    if let Some(kind) = not_a_regular_file(path) {
        return Err(OutputError::NotRegularFile {
            path: path.to_path_buf(),
            kind,
        });
    }
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(io_err(dir))?;
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = dir.join(format!(".{name}.tmp{}", std::process::id()));
    let written = (|| {
        let mut f = std::fs::File::create(&tmp).map_err(io_err(path))?;
        f.write_all(bytes).map_err(io_err(path))?;
        f.sync_all().map_err(io_err(path))?;
        drop(f);
        std::fs::rename(&tmp, path).map_err(io_err(path))
    })();
    if written.is_err() {
        // Leave no partial temporary behind (best effort: the error reported is the first).
        let _ = std::fs::remove_file(&tmp);
    }
    written
}

/// True for the name of a temporary of [`write_atomic`]: `.NAME.tmpPID`.
fn is_atomic_temporary(name: &str) -> bool {
    name.starts_with('.')
        && name.rsplit_once(".tmp").is_some_and(|(head, pid)| {
            head.len() > 1 && !pid.is_empty() && pid.bytes().all(|b| b.is_ascii_digit())
        })
}

/// Removes the temporaries of [`write_atomic`] that a killed run left in `dir` and its
/// immediate subdirectories; returns how many. Call it with the directory's lock held (no
/// other run is writing there).
fn remove_stale_temporaries(dir: &Path) -> usize {
    let mut removed = 0;
    let mut dirs = vec![dir.to_path_buf()];
    if let Ok(entries) = std::fs::read_dir(dir) {
        dirs.extend(
            entries
                .flatten()
                .filter(|e| e.file_type().is_ok_and(|t| t.is_dir()))
                .map(|e| e.path()),
        );
    }
    for d in dirs {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let is_file = e.file_type().is_ok_and(|t| t.is_file());
            if is_file
                && is_atomic_temporary(&e.file_name().to_string_lossy())
                && std::fs::remove_file(e.path()).is_ok()
            {
                removed += 1;
            }
        }
    }
    removed
}

/// Adds or replaces `section` in `dir/summary.json`, keeping the other sections.
pub fn update_summary(
    dir: &Path,
    section: &str,
    value: serde_json::Value,
) -> Result<(), OutputError> {
    let path = dir.join("summary.json");
    let mut root = match crate::files::read_text(&path, crate::files::OWN_FILE_LIMIT) {
        Ok(text) => match serde_json::from_str::<serde_json::Value>(&text) {
            Ok(serde_json::Value::Object(m)) => m,
            _ => serde_json::Map::new(),
        },
        Err(_) => serde_json::Map::new(),
    };
    root.insert(section.to_string(), value);
    let text = serde_json::to_string_pretty(&serde_json::Value::Object(root)).map_err(|e| {
        OutputError::Encode {
            what: "summary.json".into(),
            message: e.to_string(),
        }
    })?;
    write_atomic(&path, text.as_bytes())
}

/// Writes the files of the stages a run was asked for into `dir`, as the CLI's command of
/// the same stages does: the geometry's files (or only its summary section), the unloaded
/// analysis's with the loaded one's, the loaded analysis's, the ratings, the life's (unless
/// `life_written`: a [`wear::LifeWriter`] wrote them while the life ran) and report.html
/// last. Returns the files written.
pub fn write_results(
    results: &crate::Results,
    dir: &Path,
    life_written: bool,
) -> Result<Vec<PathBuf>, OutputError> {
    use crate::Stage;
    let (gear, geo) = (&results.gear, &results.geometry);
    let file = Path::new(&results.source.file);
    let mut files = Vec::new();
    if results.stages.contains(&Stage::Geometry) {
        files.extend(geometry::write_geometry(gear, geo, file, dir)?);
    } else {
        geometry::write_geometry_summary(gear, geo, file, dir)?;
    }
    let loaded = results.stages.contains(&Stage::Ltca);
    if let Some(t) = results.tca.as_ref() {
        if results.stages.contains(&Stage::Tca) || loaded {
            files.extend(tca::write_tca(gear, geo, t, dir)?);
        }
        if let Some(l) = results.ltca.as_ref() {
            files.extend(ltca::write_ltca(
                gear,
                geo,
                t,
                l,
                dir,
                results.map_position,
            )?);
        }
        if let Some(r) = results.rating.as_ref() {
            update_summary(dir, "rating", to_json("rating", r)?)?;
        }
        if let Some(table) = results.safety.as_ref() {
            files.extend(safety::write_safety(table, dir)?);
        }
        if let Some(thermal) = results.thermal.as_ref() {
            update_summary(dir, "friction", to_json("friction", thermal)?)?;
            let wf = geo.wheel_flank(t.loaded_flank);
            files.extend(friction::write_friction(wf, thermal, dir)?);
        }
        if let Some(s) = results.spectrum.as_ref() {
            files.extend(spectrum::write_spectrum(s, dir)?);
        }
        match results.life.as_ref() {
            Some(life) if !life_written => files.extend(wear::write_life(gear, geo, t, life, dir)?),
            _ => {}
        }
    }
    if let Some(solids) = results.cad.as_ref() {
        files.extend(cad::write_cad(solids, dir)?);
    }
    if results.stages.contains(&Stage::Report) {
        let title = results.source.title(gear);
        files.push(report::write_report(dir, &title, &results.source.text)?);
    }
    Ok(files)
}

/// The sections of summary.json that [`write_results`] writes for `results` (into an empty
/// directory), by name: `input`, `geometry`, `tca`, `ltca`, `rating`, `friction`, `duty_cycle`,
/// `wear` as the stages ran.
pub fn summary_sections(
    results: &crate::Results,
) -> Result<serde_json::Map<String, serde_json::Value>, OutputError> {
    use crate::Stage;
    let (gear, geo) = (&results.gear, &results.geometry);
    let mut map = serde_json::Map::new();
    let (input, geometry) = geometry::summary_values(gear, geo, Path::new(&results.source.file))?;
    map.insert("input".into(), input);
    map.insert("geometry".into(), geometry);
    if let Some(solids) = results.cad.as_ref() {
        map.insert("cad".into(), cad::summary_value(solids)?);
    }
    let Some(t) = results.tca.as_ref() else {
        return Ok(map);
    };
    if results.stages.contains(&Stage::Tca) || results.stages.contains(&Stage::Ltca) {
        map.insert("tca".into(), tca::summary_value(t)?);
    }
    if let Some(l) = results.ltca.as_ref() {
        let wf = geo.wheel_flank(t.loaded_flank);
        map.insert("ltca".into(), ltca::summary_value(t, wf, l)?);
    }
    if let Some(r) = results.rating.as_ref() {
        let mut rating = to_json("rating", r)?;
        if let (Some(m), Some(table)) = (rating.as_object_mut(), results.safety.as_ref()) {
            m.insert("safety".into(), safety::safety_value(table)?);
        }
        map.insert("rating".into(), rating);
    }
    if let Some(t) = results.thermal.as_ref() {
        map.insert("friction".into(), to_json("friction", t)?);
    }
    if let Some(s) = results.spectrum.as_ref() {
        map.insert("duty_cycle".into(), to_json("duty_cycle", s)?);
    }
    if let Some((life, last)) = results
        .life
        .as_ref()
        .and_then(|l| l.maps.last().map(|m| (l, m)))
    {
        let view = crate::wear::StepView {
            state: &life.end,
            ..last.view()
        };
        map.insert(
            "wear".into(),
            wear::summary_value(gear, geo, t, &life.plan, &view)?,
        );
    }
    Ok(map)
}

/// The measured and the simulated backlash curves of a calibration (MODEL §10), side by side:
/// `calibration_backlash.csv` (cycles, measured and simulated at the measured cycles, um) and
/// `calibration_backlash.svg`. `measured`: (wheel cycles, backlash increase m); `k`: the fit.
pub fn write_calibration_curves(
    dir: &Path,
    measured: &[(f64, f64)],
    records: &[crate::wear::StepRecord],
    k: f64,
) -> Result<(), OutputError> {
    let mut csv = Csv::new(&["cycles", "measured_um", "simulated_um"]);
    for &(c, b) in measured {
        let sim = crate::wear::backlash_at(records, c).unwrap_or(f64::NAN);
        csv.row(&[c, b * 1e6, sim * 1e6]);
    }
    csv.write(&dir.join("calibration_backlash.csv"))?;
    let series = |points: Vec<(f64, f64)>, label: &str, color: usize| crate::plot::Series {
        label: label.into(),
        points,
        color,
        bold: color == 1,
    };
    let simulated = records
        .iter()
        .map(|r| (r.cycles * 1e-6, r.backlash_increase_m * 1e6))
        .collect();
    let measured = measured.iter().map(|s| (s.0 * 1e-6, s.1 * 1e6)).collect();
    crate::plot::line_chart(
        &dir.join("calibration_backlash.svg"),
        &format!("Backlash increase: measured and simulated with K = {k:.3e}"),
        "wheel cycles (millions)",
        "backlash increase (um)",
        &[
            series(simulated, "simulated", 1),
            series(measured, "measured", 0),
        ],
        false,
    )
}

/// A value as JSON for the section `what` of summary.json.
fn to_json(what: &str, value: &impl serde::Serialize) -> Result<serde_json::Value, OutputError> {
    serde_json::to_value(value).map_err(|e| OutputError::Encode {
        what: what.into(),
        message: e.to_string(),
    })
}

/// Writes the `rating` section of summary.json (MODEL §9) and returns the ratings.
pub fn write_rating(
    gear: &crate::input::GearSet,
    dir: &Path,
) -> Result<crate::rating::Rating, OutputError> {
    let r = crate::rating::rate(gear);
    let value = serde_json::to_value(&r).map_err(|e| OutputError::Encode {
        what: "rating".into(),
        message: e.to_string(),
    })?;
    update_summary(dir, "rating", value)?;
    Ok(r)
}

/// A table of the flank grid's cells, face column by face column: i (up the height), j
/// (across the face), the cell centre's r_mm and z_mm, then `columns` with the values
/// `values(k)` of cell k.
pub(crate) fn flank_cell_table(
    wf: &crate::geometry::WheelFlank,
    columns: &[&str],
    values: impl Fn(usize) -> Vec<f64>,
) -> Csv {
    let header: Vec<&str> = ["i", "j", "r_mm", "z_mm"]
        .into_iter()
        .chain(columns.iter().copied())
        .collect();
    let mut csv = Csv::new(&header);
    for j in 0..wf.cells_face {
        for i in 0..wf.cells_height {
            let k = j * wf.cells_height + i;
            let c = &wf.cells[k];
            let mut row = vec![i as f64, j as f64, c.r * 1e3, c.z * 1e3];
            row.extend(values(k));
            csv.row(&row);
        }
    }
    csv
}

/// A CSV table built in memory and written atomically.
#[derive(Debug, Clone)]
pub struct Csv {
    text: String,
    columns: usize,
    header: Vec<String>,
    /// The numbers of the rows added with [`Csv::row`], at full precision, row after row.
    numbers: Vec<f64>,
}

impl Csv {
    /// Table with a header row (column names carry their units, e.g. `r_mm`).
    pub fn new(header: &[&str]) -> Self {
        Self {
            text: header.join(",") + "\n",
            columns: header.len(),
            header: header.iter().map(|h| h.to_string()).collect(),
            numbers: Vec::new(),
        }
    }

    /// The column names.
    pub fn header(&self) -> &[String] {
        &self.header
    }

    /// The numbers of each column at full precision (the file rounds them to 11 digits);
    /// rows with a label ([`Csv::labelled_row`]) are not among them.
    pub fn columns(&self) -> Vec<Vec<f64>> {
        (0..self.columns)
            .map(|k| {
                self.numbers
                    .iter()
                    .skip(k)
                    .step_by(self.columns.max(1))
                    .copied()
                    .collect()
            })
            .collect()
    }

    /// The table as CSV text, as written.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// Appends a row of numbers (must match the header length); whole numbers (indices,
    /// counts) are written as integers, the rest with 11 significant digits, and no value
    /// (NaN or infinite; null in summary.json) as `NaN`.
    pub fn row(&mut self, values: &[f64]) {
        assert_eq!(values.len(), self.columns);
        self.numbers.extend_from_slice(values);
        for (k, v) in values.iter().enumerate() {
            if k > 0 {
                self.text.push(',');
            }
            if v.fract() == 0.0 && v.abs() < 1e15 {
                let _ = write!(self.text, "{}", *v as i64);
            } else {
                push_number(&mut self.text, *v);
            }
        }
        self.text.push('\n');
    }

    /// Appends a row whose first cell is a label.
    pub fn labelled_row(&mut self, label: &str, values: &[f64]) {
        self.text.push_str(label);
        for v in values {
            self.text.push(',');
            push_number(&mut self.text, *v);
        }
        self.text.push('\n');
    }

    /// Writes the table atomically.
    pub fn write(&self, path: &Path) -> Result<(), OutputError> {
        write_atomic(path, self.text.as_bytes())
    }
}

/// A CSV number with 11 significant digits; no value (NaN or infinite) as `NaN`.
fn push_number(text: &mut String, v: f64) {
    if v.is_finite() {
        let _ = write!(text, "{v:.10e}");
    } else {
        text.push_str(NO_VALUE);
    }
}

/// How the CSV tables write no value (a quantity outside its formula's range, an unloaded
/// cell): `NaN`, where summary.json writes null.
pub const NO_VALUE: &str = "NaN";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_value_is_nan_in_a_table_whether_nan_or_infinite() {
        let mut csv = Csv::new(&["a", "b", "c"]);
        csv.row(&[f64::NAN, f64::INFINITY, -f64::INFINITY]);
        csv.labelled_row("x", &[f64::INFINITY, 1.5]);
        assert_eq!(csv.text(), "a,b,c\nNaN,NaN,NaN\nx,NaN,1.5000000000e0\n");
    }

    #[test]
    fn a_table_keeps_its_numbers_exactly_and_writes_them_rounded() {
        let mut csv = Csv::new(&["i", "x_m"]);
        let xs = [0.1 + 0.2, std::f64::consts::PI * 1e-7, -2.5e9];
        for (i, x) in xs.iter().enumerate() {
            csv.row(&[i as f64, *x]);
        }
        assert_eq!(csv.header(), ["i", "x_m"]);
        assert_eq!(csv.columns(), vec![vec![0.0, 1.0, 2.0], xs.to_vec()]);
        for (line, x) in csv.text().lines().skip(1).zip(xs) {
            let written: f64 = line.split(',').nth(1).unwrap().parse().unwrap();
            assert!((written / x - 1.0).abs() < 1e-10, "{line}");
        }
    }

    #[test]
    fn cycle_labels_read_easily() {
        assert_eq!(cycles_label(180000.0), "180 000");
        assert_eq!(cycles_label(999.0), "999");
        assert_eq!(cycles_label(0.0), "0");
        assert_eq!(cycles_label(19e6), "19 million");
        assert_eq!(cycles_label(1.25e6), "1.25 million");
        assert_eq!(cycles_label(6_812_345.0), "6.812 million");
    }

    #[test]
    fn summary_sections_are_merged() {
        let dir = std::env::temp_dir().join(format!("wormwear-out-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        update_summary(&dir, "a", serde_json::json!({"x": 1})).unwrap();
        update_summary(&dir, "b", serde_json::json!({"y": 2})).unwrap();
        update_summary(&dir, "a", serde_json::json!({"x": 3})).unwrap();
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap())
                .unwrap();
        assert_eq!(v["a"]["x"], 3);
        assert_eq!(v["b"]["y"], 2);
        // No temporary files left behind.
        let leftovers = std::fs::read_dir(&dir).unwrap().filter(|e| {
            e.as_ref()
                .unwrap()
                .file_name()
                .to_string_lossy()
                .contains(".tmp")
        });
        assert_eq!(leftovers.count(), 0);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

#[cfg(test)]
mod lock_tests {
    use super::*;

    #[test]
    fn a_locked_directory_refuses_a_second_lock_until_the_first_is_dropped() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("new").join("out");
        let first = lock_directory(&out).unwrap();
        assert!(out.is_dir());
        let second = lock_directory(&out).unwrap_err();
        assert!(matches!(second, LockError::Busy { .. }));
        assert!(second.to_string().contains("another wormwear run"));
        drop(first);
        assert!(lock_directory(&out).is_ok());
    }

    #[test]
    fn stale_temporaries_go_when_the_lock_is_taken_and_nothing_else_does() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::create_dir_all(d.join("runs")).unwrap();
        let stale = [".summary.json.tmp4242", "runs/.case-b.json.tmp7"];
        let kept = [".notes.tmpx", "keep.json.tmp12", ".tmp12", "summary.json"];
        for f in stale.iter().chain(&kept) {
            std::fs::write(d.join(f), b"x").unwrap();
        }
        let lock = lock_directory(d).unwrap();
        assert_eq!(lock.stale_temporaries_removed, 2);
        for f in stale {
            assert!(!d.join(f).exists(), "{f}");
        }
        for f in kept {
            assert!(d.join(f).exists(), "{f}");
        }
    }

    #[test]
    fn a_failed_atomic_write_leaves_no_temporary() {
        // The target is a directory: the final rename fails.
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("summary.json");
        std::fs::create_dir(&target).unwrap();
        assert!(write_atomic(&target, b"{}").is_err());
        let names: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, vec!["summary.json".to_string()]);
    }
}
