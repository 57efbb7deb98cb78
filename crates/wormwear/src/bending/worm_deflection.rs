//! The worm's deflection at the mesh point (MODEL §9.1): the worm FE model with its shaft and
//! bearings (the bending model's mesh and supports) under a force on the loaded flank of the
//! central thread where the wheel meshes, read as the lateral displacement of the shaft's axis
//! in the mesh plane. Its 3 x 3 compliance is computed once per gear and kept in the bending
//! cache directory, checksummed like the bending models.

use super::fe::FeError;
use super::model::{
    cache_dir, deflection_cache_key, worm_body, worm_mesh_settings, BendingError, DEFLECTION_CACHE,
};
use super::worm_mesh::{worm_mesh_on, WormLattice};
use super::worm_model::{compliance_of, deflection_cases, worm_displacements, zone_half_angle};
use crate::geometry::Geometry;
use crate::input::GearSet;
use std::path::Path;

pub use super::worm_model::MeshPointCompliance;

/// The compliance from the FE model (no cache). The bending model's build computes it too,
/// from its own factorisation, and caches it ([`super::model::build_in`]).
pub fn compute(gear: &GearSet, geo: &Geometry) -> Result<MeshPointCompliance, FeError> {
    let b = &gear.bending;
    let settings = worm_mesh_settings(b.mesh_refinement);
    let body = worm_body(gear);
    let theta_m = zone_half_angle(gear);
    let lattice = WormLattice::aligned(&settings, theta_m, b.height_points, b.worm_width_points);
    let flank = crate::kinematics::loaded_flank(gear);
    let m = worm_mesh_on(&geo.worm, flank, &body, &settings, &lattice);
    let (cases, axis) = deflection_cases(&m, theta_m)?;
    let material = super::fe::Elastic {
        youngs_modulus: gear.worm_material.youngs_modulus,
        poisson_ratio: gear.worm_material.poisson_ratio,
    };
    let u = worm_displacements(&m, &body, &material, &cases)?;
    let at_axis: Vec<Vec<[f64; 3]>> = u
        .iter()
        .map(|case| axis.iter().map(|&n| case[n]).collect())
        .collect();
    Ok(compliance_of(&at_axis))
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
    let key = deflection_cache_key(gear);
    let refinement = gear.bending.mesh_refinement;
    super::model::cached(dir, DEFLECTION_CACHE, &key, || {
        compute(gear, geo).map_err(|e| BendingError::of("worm", refinement, e))
    })
}
