//! The bending stage's entry point: builds the finite-element bending models of both members
//! from the gear's [`BendingPlan`] (MODEL §5.5) or reads them from the disk cache.
//!
//! Cache: one JSON file per model in the directory `WORMWEAR_CACHE_DIR` (default:
//! `$XDG_CACHE_HOME/wormwear`, else `$HOME/.cache/wormwear`, else the system temporary
//! directory). The file name is a hash of a key that holds everything the coefficients depend
//! on (thread, hob, cutting, wheel blank and body, operating placement and rotation, elastic
//! constants, flank grid, bending settings and the model version); the file stores the full key
//! and is used only when it matches exactly, so a cached model is never stale. Files are
//! written atomically (temporary file, then rename); a cache that cannot be written only costs
//! the next run the FE time.

use super::fe::FeError;
use super::wheel_mesh::{SectorMeshSettings, WebSettings};
use super::wheel_model::WheelBending;
use super::wheel_shaft::WheelShaft;
use super::worm_mesh::{WormBody, WormMeshSettings};
use super::worm_model::{FeBending, MeshPointCompliance, WormBending};
use crate::geometry::Geometry;
use crate::input::{BendingKind, GearSet};
use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};

/// Version of the FE models and their fit: bump when a change alters the coefficients or what
/// a cache entry holds.
const MODEL_VERSION: &str = "fe-bending-6";

/// Version of the worm deflection's compliance (MODEL §9.1): bump when a change alters it.
const DEFLECTION_VERSION: &str = "worm-deflection-3";

/// The deflection compliance's cache file prefix and its name in warnings.
pub(crate) const DEFLECTION_CACHE: (&str, &str) = ("worm-deflection", "worm deflection");

/// The cache key of the worm deflection's compliance: its version and the bending's key.
pub fn deflection_cache_key(gear: &GearSet) -> String {
    serde_json::json!({
        "version": DEFLECTION_VERSION,
        "bending": cache_key(gear),
    })
    .to_string()
}

/// Why the bending stage failed.
#[derive(Debug, thiserror::Error)]
pub enum BendingError {
    #[error("wheel finite-element model")]
    Wheel(#[source] FeError),
    #[error("worm finite-element model")]
    Worm(#[source] FeError),
    /// A model above the FE size limits ([`FeError::TooLarge`]), refused before it is built.
    #[error(
        "bending.mesh_refinement = {refinement}: the {member} finite-element model is too \
         large: {cause}; {}",
        if *refinement > 1 {
            "use a lower bending.mesh_refinement (1 is the default)"
        } else {
            "use bending.model = \"none\" (contact only), or fewer fit points \
             (bending.height_points, width_points, worm_width_points set the mesh's layers)"
        }
    )]
    TooLarge {
        member: &'static str,
        refinement: usize,
        cause: FeError,
    },
}

impl BendingError {
    /// The error of `member`'s FE model built at `refinement`.
    pub(crate) fn of(member: &'static str, refinement: usize, source: FeError) -> Self {
        match (&source, member) {
            (FeError::TooLarge { .. }, _) => Self::TooLarge {
                member,
                refinement,
                cause: source,
            },
            (_, "wheel") => Self::Wheel(source),
            _ => Self::Worm(source),
        }
    }
}

/// Where the model came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Origin {
    Computed,
    Cache,
}

/// The built model with its provenance.
#[derive(Debug, Clone)]
pub struct BuiltBending {
    pub model: FeBending,
    pub origin: Origin,
    /// Cache file (read or written), if any.
    pub cache_file: Option<PathBuf>,
    /// Wall time of the build or the read, s.
    pub seconds: f64,
}

/// Mesh settings of the wheel at a refinement level (1..3) for `width` fit points across the
/// face: layers every `face_step`-th node column, at least two per fit interval. Level 1 is the
/// sector's scale 2 (4 elements across a tooth, 6 along its height): the tooth compliance
/// changes by 6.5 % from scale 1 to 2 and by 1.7 % from 2 to 3 (wheel_fe tests). Below the
/// three teeth: the rim all round the wheel and the web down to the hub (MODEL §5.5: "rim,
/// web, hub, shaft and bearings"), clamped there; the hub's motion on the shaft is
/// [`wheel_shaft`].
pub fn wheel_mesh_settings(gear: &GearSet, refinement: usize, width: usize) -> SectorMeshSettings {
    let s = 2 * refinement.max(1);
    let intervals = (width.max(2) - 1) * s;
    let face_step = (gear.analysis.flank_cells_face / intervals).max(1);
    let body = gear.wheel_body();
    SectorMeshSettings {
        across: 2 * s,
        height: 3 * s,
        rim: s,
        space: s,
        face_step,
        rim_thickness: body.rim_thickness,
        web: Some(WebSettings {
            thickness: body.web_thickness,
            hub_radius: body.hub_radius,
            elements: s + 1,
            rest_elements: (gear.wheel.teeth as usize).saturating_sub(3).clamp(8, 48) * s / 2,
        }),
    }
}

/// The wheel's shaft under the hub ([`GearSet::wheel_body`]: radius, hub width, bearings), steel
/// with the worm's elastic constants.
pub fn wheel_shaft(gear: &GearSet) -> WheelShaft {
    let body = gear.wheel_body();
    WheelShaft {
        radius: body.shaft_radius,
        hub_half_width: body.hub_half_width,
        bearings: body.bearings,
        youngs_modulus: gear.worm_material.youngs_modulus,
        poisson_ratio: gear.worm_material.poisson_ratio,
    }
}

/// Mesh settings of the worm at a refinement level (1..3).
pub fn worm_mesh_settings(refinement: usize) -> WormMeshSettings {
    let s = refinement.max(1);
    WormMeshSettings {
        layers: 24 * s,
        across: 2 * s,
        height: 4 * s,
        space: s,
        core: s,
        inner: 2 * s,
    }
}

/// The worm body of the gear's bending plan.
pub fn worm_body(gear: &GearSet) -> WormBody {
    let b = &gear.bending;
    WormBody {
        root_radius: gear.worm.root_radius,
        tip_radius: gear.worm.tip_radius,
        shaft_radius: b.worm_shaft_radius.min(gear.worm.root_radius),
        body_half_length: 0.5 * b.worm_body_length,
        bearings: b.worm_bearings,
    }
}

/// Builds both members' bending models (no cache).
pub fn compute(gear: &GearSet, geo: &Geometry) -> Result<FeBending, BendingError> {
    compute_with_deflection(gear, geo).map(|(model, _)| model)
}

/// [`compute`] and the worm's deflection compliance (MODEL §9.1) from the worm model's own
/// factorisation (None when its mesh has no flank node in the mesh zone or no bore node).
pub fn compute_with_deflection(
    gear: &GearSet,
    geo: &Geometry,
) -> Result<(FeBending, Option<MeshPointCompliance>), BendingError> {
    let b = &gear.bending;
    let wheel_settings = wheel_mesh_settings(gear, b.mesh_refinement, b.width_points);
    let worm_settings = worm_mesh_settings(b.mesh_refinement);
    let body = worm_body(gear);
    // The two members are independent: build them side by side.
    let (wheel, worm) = rayon::join(
        || {
            WheelBending::build(
                gear,
                geo,
                &wheel_settings,
                Some(&wheel_shaft(gear)),
                b.height_points,
                b.width_points,
            )
        },
        || {
            WormBending::build_with_deflection(
                gear,
                geo,
                &body,
                &worm_settings,
                (b.height_points, b.worm_width_points),
            )
        },
    );
    let refinement = b.mesh_refinement;
    // The wheel's error first when both fail, as before the deflection came along.
    let wheel = wheel.map_err(|e| BendingError::of("wheel", refinement, e))?;
    let (worm, deflection) = worm.map_err(|e| BendingError::of("worm", refinement, e))?;
    Ok((FeBending { wheel, worm }, deflection))
}

/// The cache key: everything the coefficients depend on, as JSON text.
pub fn cache_key(gear: &GearSet) -> String {
    let key = serde_json::json!({
        "version": MODEL_VERSION,
        "worm": gear.worm,
        "hob": gear.hob,
        "cutting": gear.cutting,
        "wheel": gear.wheel,
        "operating": gear.operating,
        "rotation": gear.rotation,
        "worm_elastic": [gear.worm_material.youngs_modulus, gear.worm_material.poisson_ratio],
        "wheel_elastic": [gear.wheel_material.youngs_modulus, gear.wheel_material.poisson_ratio],
        "grid": [
            gear.analysis.flank_cells_height,
            gear.analysis.flank_cells_face,
            gear.analysis.tip_trace_refinement,
        ],
        "bending": gear.bending,
    });
    key.to_string()
}

/// The cache directory (see the module doc).
pub fn cache_dir() -> PathBuf {
    if let Some(d) = std::env::var_os("WORMWEAR_CACHE_DIR").filter(|d| !d.is_empty()) {
        return PathBuf::from(d);
    }
    if let Some(d) = std::env::var_os("XDG_CACHE_HOME").filter(|d| !d.is_empty()) {
        return PathBuf::from(d).join("wormwear");
    }
    if let Some(d) = std::env::var_os("HOME").filter(|d| !d.is_empty()) {
        return PathBuf::from(d).join(".cache").join("wormwear");
    }
    std::env::temp_dir().join("wormwear-cache")
}

#[derive(serde::Serialize, serde::Deserialize)]
struct CacheFile<T> {
    key: String,
    model: T,
}

/// The cache file of `key` in `dir`: `{prefix}-{hash of the key}.json`.
pub(crate) fn cache_path(dir: &Path, prefix: &str, key: &str) -> PathBuf {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    key.hash(&mut h);
    dir.join(format!("{prefix}-{:016x}.json", h.finish()))
}

/// The cached value for `key`: None when there is no entry or it is of another key; an error
/// (the reason) when the entry cannot be trusted: unreadable, or its checksum fails.
pub(crate) fn read_cache<T: serde::de::DeserializeOwned>(
    path: &Path,
    key: &str,
) -> Result<Option<T>, String> {
    let text = match crate::files::read_text(path, crate::files::OWN_FILE_LIMIT) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(e.to_string()),
    };
    let file: CacheFile<T> = crate::integrity::open(&text).map_err(|e| e.to_string())?;
    Ok((file.key == key).then_some(file.model))
}

/// The value of `key` from the cache directory `dir` (entry `{prefix}-{hash}.json`) when an
/// entry of that key is there and its checksum holds, else `compute`d and written there.
/// Cache problems never fail the run: they come back as warnings naming `what`.
pub(crate) fn cached<T, E>(
    dir: Option<&Path>,
    (prefix, what): (&str, &str),
    key: &str,
    compute: impl FnOnce() -> Result<T, E>,
) -> Result<(T, Vec<String>), E>
where
    T: serde::Serialize + serde::de::DeserializeOwned,
{
    let path = dir.map(|d| cache_path(d, prefix, key));
    let mut warnings = Vec::new();
    match path.as_deref().map(|p| read_cache(p, key)) {
        Some(Ok(Some(value))) => return Ok((value, warnings)),
        Some(Err(reason)) => warnings.push(format!(
            "{what} cache entry not used ({reason}): recomputed"
        )),
        _ => {}
    }
    let value = compute()?;
    if let Some(p) = &path {
        if let Err(e) = write_cache(p, key, &value) {
            warnings.push(format!("{what} not cached in {}: {e}", p.display()));
        }
    }
    Ok((value, warnings))
}

/// Writes a cache entry atomically (temporary file, then rename), sealed with its checksum.
pub(crate) fn write_cache<T: serde::Serialize>(
    path: &Path,
    key: &str,
    model: &T,
) -> std::io::Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let text = crate::integrity::seal(&CacheFile {
        key: key.to_string(),
        model,
    })
    .map_err(std::io::Error::other)?;
    let tmp = path.with_extension(format!("tmp{}", std::process::id()));
    std::fs::write(&tmp, text)?;
    std::fs::rename(&tmp, path)
}

/// The bending model the gear asks for: None for `model = "none"`; for "fe" the cached
/// models when the key matches, else the FE build (then cached). Cache problems never fail
/// the run: they are returned as a warning beside the model.
pub fn build(
    gear: &GearSet,
    geo: &Geometry,
) -> Result<(Option<BuiltBending>, Vec<String>), BendingError> {
    if gear.bending.kind == BendingKind::None {
        return Ok((None, Vec::new()));
    }
    build_in(gear, geo, Some(&cache_dir())).map(|(b, w)| (Some(b), w))
}

/// The worm's fit points up and across the thread (`bending.height_points`,
/// `bending.worm_width_points`).
fn fit_points(gear: &GearSet) -> (usize, usize) {
    (gear.bending.height_points, gear.bending.worm_width_points)
}

/// As [`build`] for "fe" with an explicit cache directory (None: no cache).
pub fn build_in(
    gear: &GearSet,
    geo: &Geometry,
    dir: Option<&Path>,
) -> Result<(BuiltBending, Vec<String>), BendingError> {
    let start = std::time::Instant::now();
    let key = cache_key(gear);
    let path = dir.map(|d| cache_path(d, "bending", &key));
    let mut warnings = Vec::new();
    let cached = match path.as_deref().map(|p| read_cache::<FeBending>(p, &key)) {
        Some(Ok(model)) => model,
        Some(Err(reason)) => {
            warnings.push(format!(
                "bending cache entry {} not used ({reason}): rebuilt",
                path.as_deref()
                    .map_or(String::new(), |p| p.display().to_string())
            ));
            None
        }
        None => None,
    };
    if let Some(model) = cached {
        let fit = model.edge_fit_warning(fit_points(gear));
        return Ok((
            BuiltBending {
                model,
                origin: Origin::Cache,
                cache_file: path,
                seconds: start.elapsed().as_secs_f64(),
            },
            fit.into_iter().collect(),
        ));
    }
    let (model, deflection) = compute_with_deflection(gear, geo)?;
    warnings.extend(model.edge_fit_warning(fit_points(gear)));
    if let Some(p) = &path {
        if let Err(e) = write_cache(p, &key, &model) {
            warnings.push(format!(
                "bending coefficients not cached in {}: {e}",
                p.display()
            ));
        }
    }
    // The deflection came from the same factorisation: cached for the ratings, which would
    // otherwise factor the worm model again.
    if let (Some(d), Some(compliance)) = (dir, deflection) {
        let key = deflection_cache_key(gear);
        let p = cache_path(d, DEFLECTION_CACHE.0, &key);
        if let Err(e) = write_cache(&p, &key, &compliance) {
            warnings.push(format!(
                "{} not cached in {}: {e}",
                DEFLECTION_CACHE.1,
                p.display()
            ));
        }
    }
    Ok((
        BuiltBending {
            model,
            origin: Origin::Computed,
            cache_file: path,
            seconds: start.elapsed().as_secs_f64(),
        },
        warnings,
    ))
}
