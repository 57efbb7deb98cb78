//! The worm's deflection at the mesh point (MODEL §9.1): the worm FE model with its shaft and
//! bearings (the bending model's mesh and supports) under a force on the loaded flank of the
//! central thread where the wheel meshes, read as the lateral displacement of the shaft's axis
//! in the mesh plane. Its 3 x 3 compliance is computed once per gear and kept in the bending
//! cache directory, checksummed like the bending models.

use super::fe::{FeError, Load};
use super::model::{cache_dir, worm_body, worm_mesh_settings, BendingError};
use super::worm_mesh::{worm_mesh_on, WormLattice, WormMesh};
use super::worm_model::{worm_displacements, zone_half_angle};
use crate::geometry::Geometry;
use crate::input::GearSet;
use nalgebra::{Matrix3, Vector3};
use std::path::Path;

/// Version of the compliance's computation: bump when a change alters it.
const VERSION: &str = "worm-deflection-2";

/// Compliance of the worm's axis at the mesh plane (x1 = 0): column j the displacement (worm
/// frame x, y, z; m) of the axis under a unit force (N) along worm-frame axis j spread evenly
/// over the loaded flank's nodes of the central thread in the mesh zone.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MeshPointCompliance {
    pub columns: [[f64; 3]; 3],
}

impl MeshPointCompliance {
    /// Lateral deflection of the axis (perpendicular to x1) under the force `f` (worm frame,
    /// N), m.
    pub fn lateral_deflection(&self, f: &Vector3<f64>) -> f64 {
        let c = Matrix3::from_fn(|i, j| self.columns[j][i]);
        let d = c * f;
        d.y.hypot(d.z)
    }
}

/// The nodes the mesh force is spread over: the central thread's loaded flank within the mesh
/// zone (|phi| <= theta_m about y1, towards the wheel) on the middle half of the thread height.
fn zone_nodes(m: &WormMesh, theta_m: f64) -> Vec<usize> {
    let half = m.height_steps as f64;
    m.loaded[1]
        .iter()
        .filter(|&&(_, h, n)| {
            let x = m.mesh.nodes[n];
            let phi = x[2].atan2(x[1]);
            let t = h as f64 / half;
            phi.abs() <= theta_m && (0.25..=0.75).contains(&t)
        })
        .map(|f| f.2)
        .collect()
}

/// The bore's nodes nearest the mesh plane x1 = 0, one per half-layer (the axis's
/// displacement there is their mean).
fn axis_nodes(m: &WormMesh) -> Vec<usize> {
    let bore = m
        .mesh
        .nodes
        .iter()
        .map(|x| x[1].hypot(x[2]))
        .fold(f64::INFINITY, f64::min);
    let mut best: Vec<Option<(f64, usize)>> = vec![None; m.half_layers];
    for (i, x) in m.mesh.nodes.iter().enumerate() {
        if (x[1].hypot(x[2]) - bore).abs() > 1e-9 * bore.max(1e-3) {
            continue;
        }
        let phi = x[2].atan2(x[1]);
        let tau = 2.0 * std::f64::consts::PI;
        let li =
            (((phi + 0.5 * tau) / tau * m.half_layers as f64).round() as usize) % m.half_layers;
        if best[li].is_none_or(|(d, _)| x[0].abs() < d) {
            best[li] = Some((x[0].abs(), i));
        }
    }
    best.into_iter().flatten().map(|(_, i)| i).collect()
}

/// The compliance from the FE model (no cache).
pub fn compute(gear: &GearSet, geo: &Geometry) -> Result<MeshPointCompliance, FeError> {
    let b = &gear.bending;
    let settings = worm_mesh_settings(b.mesh_refinement);
    let body = worm_body(gear);
    let theta_m = zone_half_angle(gear);
    let lattice = WormLattice::aligned(&settings, theta_m, b.height_points, b.worm_width_points);
    let flank = crate::kinematics::loaded_flank(gear);
    let m = worm_mesh_on(&geo.worm, flank, &body, &settings, &lattice);
    let zone = zone_nodes(&m, theta_m);
    let axis = axis_nodes(&m);
    if zone.is_empty() || axis.is_empty() {
        return Err(FeError::Factorisation(
            "the worm mesh has no flank node in the mesh zone or no bore node".into(),
        ));
    }
    let share = 1.0 / zone.len() as f64;
    let cases: Vec<Vec<Load>> = (0..3)
        .map(|d| zone.iter().map(|&n| (n, d, share)).collect())
        .collect();
    let material = super::fe::Elastic {
        youngs_modulus: gear.worm_material.youngs_modulus,
        poisson_ratio: gear.worm_material.poisson_ratio,
    };
    let u = worm_displacements(&m, &body, &material, &cases)?;
    let columns = std::array::from_fn(|j| {
        std::array::from_fn(|i| axis.iter().map(|&n| u[j][n][i]).sum::<f64>() / axis.len() as f64)
    });
    Ok(MeshPointCompliance { columns })
}

/// The compliance for the gear: from the cache directory when an entry of the same key is
/// there, else computed (and cached). Cache problems never fail the run: they come back as
/// warnings.
pub fn mesh_point_compliance(
    gear: &GearSet,
    geo: &Geometry,
) -> Result<(MeshPointCompliance, Vec<String>), BendingError> {
    compliance_in(gear, geo, Some(&cache_dir()))
}

/// As [`mesh_point_compliance`] with an explicit cache directory (None: no cache).
pub fn compliance_in(
    gear: &GearSet,
    geo: &Geometry,
    dir: Option<&Path>,
) -> Result<(MeshPointCompliance, Vec<String>), BendingError> {
    let key = serde_json::json!({
        "version": VERSION,
        "bending": super::model::cache_key(gear),
    })
    .to_string();
    let refinement = gear.bending.mesh_refinement;
    super::model::cached(dir, ("worm-deflection", "worm deflection"), &key, || {
        compute(gear, geo).map_err(|e| BendingError::of("worm", refinement, e))
    })
}
