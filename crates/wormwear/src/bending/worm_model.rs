//! Worm bending coefficients for the LTCA (MODEL §5.5): FE of the worm (three threads on the
//! core, shaft to the bearings), unit normal loads at a K = Q1 x Q2 grid of the central
//! thread's loaded flank (radius from r_f1 + 0.1 H to r_a1 - 0.1 H, polar angle from -theta_m
//! to theta_m, theta_m = atan(0.5 b2 / (a - r_e2)), §12f), bending = opposite flank free minus
//! blocked, projected on the normals; three thread relations fitted on the averaged
//! free-free / clamped-clamped basis.
//!
//! Supports: both bearings hold the shaft laterally (stiff springs on the mean lateral
//! displacement of a ring of the shaft surface; rotation, tilt and axial sliding free there); the torque and the thrust are reacted at the
//! coupling, a ring of the shaft half a lead beyond the drive-side bearing (axial displacement
//! fixed, stiff tangential springs).

use super::basis::{Basis, WidthFunctions};
use super::fe::{
    free_minus_blocked_and_free, solve_with_springs, CaseDisplacements, Elastic, FeError, Fixed,
    Load, Spring,
};
use super::relation::{cached_core, relation_low_rank, relation_rows, CoreCache};
use super::worm_mesh::{worm_mesh_on, WormBody, WormLattice, WormMesh, WormMeshSettings};
use crate::geometry::{Flank, Geometry};
use crate::input::GearSet;
use crate::ltca::solver::LowRank;
use crate::ltca::{BendingModel, LocalCell};
use faer::Mat;
use nalgebra::{Matrix3, Vector3};

/// Worm bending model (coefficients in m/N).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct WormBending {
    pub basis: Basis,
    /// Core matrices for receivers on the same thread, the thread at -p_x and at +p_x from
    /// the loaded one, m/N.
    #[serde(with = "super::mat_serde")]
    pub same: Mat<f64>,
    #[serde(with = "super::mat_serde")]
    pub before: Mat<f64>,
    #[serde(with = "super::mat_serde")]
    pub after: Mat<f64>,
    pub root_radius: f64,
    pub tip_radius: f64,
    /// Half angle of the zone the wheel reaches, rad.
    pub theta_m: f64,
    /// Axial pitch p_x and signed lead per radian (hand x h), m and m/rad.
    pub pitch: f64,
    pub signed_lead_per_rad: f64,
    /// Axial profile of the loaded flank, (rho, X) pairs at equal steps, m.
    pub profile: Vec<(f64, f64)>,
    /// The fitted self-compliance's relative error against the FE at the loaded thread's root
    /// and tip rows in the middle of the zone, [root, tip]: outside the fit zone (MODEL §5.5:
    /// r_f1 + 0.1 H to r_a1 - 0.1 H) the LTCA extrapolates the height functions, and the
    /// wheel's contact reaches the worm's tip.
    pub edge_fit_errors: [f64; 2],
    #[serde(skip)]
    pub(crate) cores: CoreCache,
}

/// The largest error of the worm's fitted compliance at its thread's root and tip rows
/// ([`WormBending::edge_fit_errors`]) that passes without a warning: above what the default
/// 5 x 13 fit points leave on the examples' gears (K 2/25 +3.5 % / +0.8 %, the 1/40 test
/// lattice +6.1 % / -1.5 %), well below what 7 points leave on the 1/40 gear (+78 % / +28 %,
/// BENCHMARKS.md session 67).
pub const EDGE_FIT_TOLERANCE: f64 = 0.10;

/// A fit data point: lattice indices (along, across) of a node of the central thread's flank
/// and its basis coordinates (r~, theta~).
type DataPoint = (usize, usize, (f64, f64));

/// The fit's data points (MODEL §5.5): every corner node of the central thread's flank in the
/// fit zone (radius between 0.1 and 0.9 of the thread height `(r_f1, H)`, m; polar angle within
/// +-`theta_m`, rad).
fn fit_data_points(m: &WormMesh, (rf, thread_height): (f64, f64), theta_m: f64) -> Vec<DataPoint> {
    // Data points: every corner node of the central thread's flank in the fit zone (the
    // lattice puts the fit grid and the points midway between its points there), about
    // four per basis function. The worm's kernel is peaked (local bending of the thread
    // under a point load, over about the thread thickness), and interpolating it through
    // exactly K points oscillates between them (Runge: 36 % error at 5 x 7, worse with
    // more points); least squares on the denser set does not.
    m.loaded[1]
        .iter()
        .filter(|f| f.0 % 2 == 0 && f.1 % 2 == 0)
        .filter_map(|&(li, hi, n)| {
            let x = m.mesh.nodes[n];
            let rho = (x[1] * x[1] + x[2] * x[2]).sqrt();
            let r = (rho - rf) / thread_height;
            let w = x[2].atan2(x[1]) / (2.0 * theta_m) + 0.5;
            let inside =
                (0.1 - 1e-9..=0.9 + 1e-9).contains(&r) && (-1e-9..=1.0 + 1e-9).contains(&w);
            inside.then_some((li, hi, (r, w)))
        })
        .collect()
}

/// The unit normal loads of the fit (node, outward normal of the loaded `flank`), at the
/// central thread's data points (`ids[1]`; a thread's normals are its neighbours'), then at
/// its root and tip rows in the middle of the zone (the check of
/// [`WormBending::edge_fit_errors`]); and the nodes observed: the data points on the three
/// threads (ids[t][l] is observed[t * n + l]), then the two edge nodes.
fn fit_loads(
    m: &WormMesh,
    geo: &Geometry,
    flank: Flank,
    ids: &[Vec<usize>],
) -> (Vec<(usize, Vector3<f64>)>, Vec<usize>) {
    let normal_at = |node: usize| {
        let x = m.mesh.nodes[node];
        (node, geo.worm.outward_normal(flank, x[1], x[2]))
    };
    let mut loads: Vec<(usize, Vector3<f64>)> = ids[1].iter().map(|&n| normal_at(n)).collect();
    let mut observed: Vec<usize> = ids.iter().flatten().copied().collect();
    let rows = m.loaded[1].iter().map(|f| f.1);
    let (root, tip) = (rows.clone().min(), rows.max());
    for row in [root, tip].into_iter().flatten() {
        let mid_zone = m.loaded[1]
            .iter()
            .filter(|f| f.1 == row)
            .map(|&(_, _, n)| (m.mesh.nodes[n][2].atan2(m.mesh.nodes[n][1]).abs(), n))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((_, node)) = mid_zone {
            loads.push(normal_at(node));
            observed.push(node);
        }
    }
    (loads, observed)
}

/// The FE nodes of the data points on the three threads (before, loaded, after), or an error
/// when a neighbouring thread lacks one.
fn thread_nodes(m: &WormMesh, data: &[DataPoint]) -> Result<Vec<Vec<usize>>, FeError> {
    let node = |thread: usize, li: usize, hi: usize| {
        m.loaded[thread]
            .iter()
            .find(|f| f.0 == li && f.1 == hi)
            .map(|f| f.2)
    };
    let ids: Vec<Vec<usize>> = (0..3)
        .map(|t| {
            data.iter()
                .map(|&(li, hi, _)| node(t, li, hi).unwrap_or(usize::MAX))
                .collect()
        })
        .collect();
    if ids.iter().flatten().any(|&n| n == usize::MAX) {
        return Err(FeError::Factorisation(
            "a worm data point has no node on a neighbouring thread".into(),
        ));
    }
    Ok(ids)
}

/// The loaded flank's axial profile X(rho) at 33 equal steps from 0.2 thread heights below the
/// root radius to 0.2 above the tip radius `(r_f1, r_a1)`, m.
fn axial_profile_table(geo: &Geometry, flank: Flank, (rf, ra): (f64, f64)) -> Vec<(f64, f64)> {
    let thread_height = ra - rf;
    let steps = 32;
    let (lo, hi) = (rf - 0.2 * thread_height, ra + 0.2 * thread_height);
    (0..=steps)
        .map(|i| {
            let rho = lo + (hi - lo) * i as f64 / steps as f64;
            (rho, geo.worm.axial_profile(flank, rho).0)
        })
        .collect()
}

/// The zone half angle theta_m = atan(0.5 b2 / (a - r_e2)) (MODEL §5.5, §12f), rad; pi/2 when
/// the blank reaches past the worm axis; kept within [0.05, 0.45 pi].
pub fn zone_half_angle(gear: &GearSet) -> f64 {
    let d = gear.operating.centre_distance - gear.wheel.outer_radius;
    let theta = if d <= 0.0 {
        0.5 * std::f64::consts::PI
    } else {
        (0.5 * gear.wheel.face_width / d).atan()
    };
    theta.clamp(0.05, 0.45 * std::f64::consts::PI)
}

impl WormBending {
    /// Builds the model: FE of the worm (`settings`, `body`) with `height` x `width` fit points.
    pub fn build(
        gear: &GearSet,
        geo: &Geometry,
        body: &WormBody,
        settings: &WormMeshSettings,
        height: usize,
        width: usize,
    ) -> Result<Self, FeError> {
        Self::build_with_deflection(gear, geo, body, settings, (height, width)).map(|(m, _)| m)
    }

    /// [`WormBending::build`] and, from the same factorisation, the worm's deflection
    /// compliance at the mesh point (MODEL §9.1; None when the mesh has no flank node in the
    /// mesh zone or no bore node).
    pub fn build_with_deflection(
        gear: &GearSet,
        geo: &Geometry,
        body: &WormBody,
        settings: &WormMeshSettings,
        (height, width): (usize, usize),
    ) -> Result<(Self, Option<MeshPointCompliance>), FeError> {
        let flank = crate::kinematics::loaded_flank(gear);
        let theta_m = zone_half_angle(gear);
        let lattice = WormLattice::aligned(settings, theta_m, height, width);
        let m = worm_mesh_on(&geo.worm, flank, body, settings, &lattice);
        let (rf, ra) = (body.root_radius, body.tip_radius);
        let thread_height = ra - rf;
        let basis = Basis {
            height,
            width,
            kind: WidthFunctions::Averaged,
        };
        let data = fit_data_points(&m, (rf, thread_height), theta_m);
        let k = basis.len();
        if data.len() < k {
            return Err(FeError::Factorisation(format!(
                "the worm mesh has {} flank points in the fit zone, fewer than the {k} basis functions",
                data.len()
            )));
        }
        let ids = thread_nodes(&m, &data)?;
        let material = Elastic {
            youngs_modulus: gear.worm_material.youngs_modulus,
            poisson_ratio: gear.worm_material.poisson_ratio,
        };
        let (loads, observed) = fit_loads(&m, geo, flank, &ids);
        let deflection = deflection_cases(&m, theta_m).ok();
        let plain = deflection
            .as_ref()
            .map_or((&[][..], &[][..]), |(cases, axis)| (&cases[..], &axis[..]));
        let (bending, free) =
            worm_bending_and_free(&m, body, &material, (&loads, &observed), plain)?;
        let compliance = deflection.map(|_| compliance_of(&free));
        let n = data.len();
        let relation = |t: usize| {
            Mat::from_fn(n, n, |l, c| {
                let d = bending[c][t * n + l];
                let nn = loads[l].1;
                -(d[0] * nn[0] + d[1] * nn[1] + d[2] * nn[2])
            })
        };
        let coords: Vec<(f64, f64)> = data.iter().map(|d| d.2).collect();
        let profile = axial_profile_table(geo, flank, (rf, ra));
        let mut model = Self {
            basis,
            same: basis.fit_least_squares(&coords, &relation(1)),
            before: basis.fit_least_squares(&coords, &relation(0)),
            after: basis.fit_least_squares(&coords, &relation(2)),
            root_radius: rf,
            tip_radius: ra,
            theta_m,
            pitch: geo.worm.axial_pitch(),
            signed_lead_per_rad: geo.worm.hand_sign() * geo.worm.lead()
                / (2.0 * std::f64::consts::PI),
            profile,
            edge_fit_errors: [0.0; 2],
            cores: CoreCache::default(),
        };
        model.edge_fit_errors = model.edge_errors(&m, &loads[n..], &bending[n..], 3 * n);
        Ok((model, compliance))
    }

    /// [`WormBending::edge_fit_errors`] from the FE bending under the two edge loads
    /// (`edge_loads`: node and outward normal; `edge_bending`: their displacements, the edge
    /// nodes' at `observed_at` and the next).
    fn edge_errors(
        &self,
        m: &WormMesh,
        edge_loads: &[(usize, Vector3<f64>)],
        edge_bending: &[Vec<[f64; 3]>],
        observed_at: usize,
    ) -> [f64; 2] {
        if edge_loads.len() < 2 || edge_bending.len() < 2 {
            return [f64::NAN; 2];
        }
        [0, 1].map(|e| {
            let (node, nn) = edge_loads[e];
            let d = edge_bending[e][observed_at + e];
            let fe = -(d[0] * nn[0] + d[1] * nn[1] + d[2] * nn[2]);
            let x = m.mesh.nodes[node];
            let c = self.coordinates(&Vector3::new(x[0], x[1], x[2]));
            self.basis.coefficient(&self.same, c, c) / fe - 1.0
        })
    }

    /// Basis coordinates (r~, theta~) of a worm-frame point: r~ = (rho - r_f1)/(r_a1 - r_f1),
    /// theta~ = theta/(2 theta_m) + 1/2 with theta the polar angle from y1 (towards the wheel).
    pub fn coordinates(&self, p: &Vector3<f64>) -> (f64, f64) {
        let rho = (p.y * p.y + p.z * p.z).sqrt();
        let phi = p.z.atan2(p.y);
        (
            (rho - self.root_radius) / (self.tip_radius - self.root_radius),
            phi / (2.0 * self.theta_m) + 0.5,
        )
    }

    /// Helical coordinate of the thread through a worm-frame point, in axial pitches: points
    /// on one thread differ by less than a half, on neighbouring threads by about one.
    pub fn thread_coordinate(&self, p: &Vector3<f64>) -> f64 {
        let rho = (p.y * p.y + p.z * p.z).sqrt();
        let phi = p.z.atan2(p.y);
        let x = interpolate(&self.profile, rho);
        (p.x - x - self.signed_lead_per_rad * phi) / self.pitch
    }
}

fn interpolate(table: &[(f64, f64)], x: f64) -> f64 {
    let n = table.len();
    if n == 0 {
        return 0.0;
    }
    if n == 1 {
        return table[0].1;
    }
    let (x0, x1) = (table[0].0, table[n - 1].0);
    let t = ((x - x0) / (x1 - x0) * (n - 1) as f64).clamp(0.0, (n - 1) as f64);
    let i = (t.floor() as usize).min(n - 2);
    let f = t - i as f64;
    table[i].1 + (table[i + 1].1 - table[i].1) * f
}

/// Angular weights of a ring's nodes (in order around the axis): half the angle between each
/// node's two neighbours, so sums over the ring are integrals over the circle.
fn ring_weights(m: &WormMesh, ring: &[usize]) -> Vec<(f64, f64)> {
    let phi: Vec<f64> = ring
        .iter()
        .map(|&n| m.mesh.nodes[n][2].atan2(m.mesh.nodes[n][1]))
        .collect();
    let count = phi.len();
    let tau = 2.0 * std::f64::consts::PI;
    (0..count)
        .map(|i| {
            let (a, b) = (phi[(i + count - 1) % count], phi[(i + 1) % count]);
            let span = (b - a).rem_euclid(tau);
            let span = if span == 0.0 { tau } else { span };
            (phi[i], 0.5 * span)
        })
        .collect()
}

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

/// The deflection's load cases (MODEL §9.1): a unit force along each worm-frame axis spread
/// evenly over [`zone_nodes`]; with the bore nodes whose mean displacement is the axis's
/// ([`axis_nodes`]). Err when either set is empty.
pub(super) fn deflection_cases(
    m: &WormMesh,
    theta_m: f64,
) -> Result<(Vec<Vec<Load>>, Vec<usize>), FeError> {
    let zone = zone_nodes(m, theta_m);
    let axis = axis_nodes(m);
    if zone.is_empty() || axis.is_empty() {
        return Err(FeError::Factorisation(
            "the worm mesh has no flank node in the mesh zone or no bore node".into(),
        ));
    }
    let share = 1.0 / zone.len() as f64;
    let cases = (0..3)
        .map(|d| zone.iter().map(|&n| (n, d, share)).collect())
        .collect();
    Ok((cases, axis))
}

/// The compliance from the displacements of the axis nodes under the three
/// [`deflection_cases`], [case][axis node] in m: their mean.
pub(super) fn compliance_of(u: &[Vec<[f64; 3]>]) -> MeshPointCompliance {
    let columns = std::array::from_fn(|j| {
        std::array::from_fn(|i| u[j].iter().map(|x| x[i]).sum::<f64>() / u[j].len() as f64)
    });
    MeshPointCompliance { columns }
}

/// Supports of the worm model (see the module doc). Bearings: stiff springs on the ring's
/// lateral translation, read from the radial displacements as sum w u_r cos(phi) /
/// sum w cos^2(phi) (and sin): a rotation about the axis gives no radial displacement, so
/// torsion is free; springs on each node would also resist the tilt, a ring of the helical
/// lattice not being exactly plane. Coupling: stiff springs on the ring's mean tangential and
/// axial displacements (torque and thrust), leaving its lateral motion and tilt free.
fn supports(m: &WormMesh, body: &WormBody, material: &Elastic) -> (Vec<Fixed>, Vec<Spring>) {
    // Stiff: 100 E r_shaft per support (rigid bearings and coupling).
    let total = 100.0 * material.youngs_modulus * body.shaft_radius;
    let mut springs = Vec::new();
    for ring in &m.bearing_rings {
        let w = ring_weights(m, ring);
        for trig in [f64::cos, f64::sin] {
            let norm: f64 = w.iter().map(|&(phi, wi)| wi * trig(phi).powi(2)).sum();
            springs.push(Spring {
                terms: ring
                    .iter()
                    .zip(&w)
                    .map(|(&n, &(phi, wi))| {
                        let c = wi * trig(phi) / norm;
                        (n, [0.0, c * phi.cos(), c * phi.sin()])
                    })
                    .collect(),
                stiffness: total,
            });
        }
    }
    let w = ring_weights(m, &m.drive_ring);
    let sum: f64 = w.iter().map(|x| x.1).sum();
    springs.push(Spring {
        terms: m
            .drive_ring
            .iter()
            .zip(&w)
            .map(|(&n, &(phi, wi))| (n, [0.0, -phi.sin() * wi / sum, phi.cos() * wi / sum]))
            .collect(),
        stiffness: total,
    });
    springs.push(Spring {
        terms: m
            .drive_ring
            .iter()
            .zip(&w)
            .map(|(&n, &(_, wi))| (n, [wi / sum, 0.0, 0.0]))
            .collect(),
        stiffness: total,
    });
    (Vec::new(), springs)
}

/// Bending displacements of the worm (MODEL §5.5 step 2): for each load case a unit force
/// into the central thread (along -n) at the given node, FE displacement of the `observed`
/// nodes with the thread's opposite flank free minus blocked. Index: [case][observed k], m/N.
pub fn worm_bending_displacements(
    m: &WormMesh,
    body: &WormBody,
    material: &Elastic,
    loads: &[(usize, Vector3<f64>)],
    observed: &[usize],
) -> Result<Vec<Vec<[f64; 3]>>, FeError> {
    worm_bending_and_free(m, body, material, (loads, observed), (&[], &[]))
        .map(|(bending, _)| bending)
}

/// [`worm_bending_displacements`] and, from the same factorisation, the worm model's
/// displacements with its supports alone (as [`worm_displacements`]) under the load cases
/// `plain.0` at the nodes `plain.1`, [case][k] in m.
pub fn worm_bending_and_free(
    m: &WormMesh,
    body: &WormBody,
    material: &Elastic,
    bending: (&[(usize, Vector3<f64>)], &[usize]),
    plain: (&[Vec<Load>], &[usize]),
) -> Result<(CaseDisplacements, CaseDisplacements), FeError> {
    let (fixed, springs) = supports(m, body, material);
    let blocked: Vec<usize> = m.opposite[1].iter().map(|f| f.2).collect();
    free_minus_blocked_and_free(
        &m.mesh,
        material,
        (&fixed, &springs),
        &blocked,
        bending,
        plain,
    )
}

/// Displacements of the worm model under arbitrary nodal loads with its supports (no
/// blocking), for checks. Index: [case][node], m.
pub fn worm_displacements(
    m: &WormMesh,
    body: &WormBody,
    material: &Elastic,
    loads: &[Vec<Load>],
) -> Result<Vec<Vec<[f64; 3]>>, FeError> {
    let (fixed, springs) = supports(m, body, material);
    solve_with_springs(&m.mesh, material, &fixed, &springs, loads)
}

impl WormBending {
    /// Thread groups and basis coordinates of the cells.
    fn groups(&self, cells: &[LocalCell]) -> (Vec<i64>, Vec<(f64, f64)>) {
        let first = cells
            .first()
            .map(|c| self.thread_coordinate(&c.cell.centre))
            .unwrap_or(0.0);
        let groups = cells
            .iter()
            .map(|c| (self.thread_coordinate(&c.cell.centre) - first).round() as i64)
            .collect();
        let coords = cells
            .iter()
            .map(|c| self.coordinates(&c.cell.centre))
            .collect();
        (groups, coords)
    }
}

impl BendingModel for WormBending {
    fn name(&self) -> &'static str {
        "fe-worm"
    }

    fn coefficients(&self, cells: &[LocalCell]) -> LowRank {
        let (groups, coords) = self.groups(cells);
        relation_low_rank(
            &self.basis,
            &self.same,
            &self.before,
            &self.after,
            &groups,
            &coords,
            &self.cores,
        )
    }
}

/// Both members: the finite-element bending of MODEL §5.5 (wheel sector and worm). The LTCA
/// reports it as "fe".
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct FeBending {
    pub wheel: super::wheel_model::WheelBending,
    pub worm: WormBending,
}

impl FeBending {
    /// A warning when the worm's fit is off its FE by more than [`EDGE_FIT_TOLERANCE`] at the
    /// thread's root or tip row; `(height, width)`: the gear's `bending.height_points` and
    /// `bending.worm_width_points`, named in it.
    pub fn edge_fit_warning(&self, (height, width): (usize, usize)) -> Option<String> {
        let [root, tip] = self.worm.edge_fit_errors;
        if !(root.abs() > EDGE_FIT_TOLERANCE || tip.abs() > EDGE_FIT_TOLERANCE) {
            return None;
        }
        Some(format!(
            "bending: the worm's fitted compliance is {:+.1} % off its FE at the thread's root \
             and {:+.1} % at its tip, outside the fit zone (0.1 to 0.9 of the thread height, \
             MODEL §5.5) where the loaded analysis extrapolates the fit: the contact there, the \
             worm's pressures and TE peak-to-peak carry that error; the default fit points \
             (bending.height_points 5, bending.worm_width_points 13; here {height} and {width}) \
             hold it within 10 % on the examples' gears",
            100.0 * root,
            100.0 * tip
        ))
    }
}

impl BendingModel for FeBending {
    fn name(&self) -> &'static str {
        "fe"
    }

    fn rigid_rotation_compliance(&self) -> f64 {
        self.wheel.rigid_rotation_compliance()
    }

    /// Both members' terms written straight into one packed F (each row: its wheel tooth's
    /// functions, the wheel hub's rigid body, its worm thread's; the cores block-diagonal):
    /// one allocation per position, of the non-zero values only (a dense F was zeroed, filled
    /// and packed: memory traffic that two threads shared, issue 55).
    fn coefficients(&self, cells: &[LocalCell]) -> LowRank {
        let (wheel_groups, wheel_coords) = self.wheel.groups(cells);
        let (worm_groups, worm_coords) = self.worm.groups(cells);
        let count = |g: &[i64]| {
            let mut v = g.to_vec();
            v.sort_unstable();
            v.dedup();
            v.len()
        };
        let teeth = self.wheel.basis.len() * count(&wheel_groups);
        let hub = if self.wheel.has_shaft() { 6 } else { 0 };
        let threads = self.worm.basis.len() * count(&worm_groups);
        let rank = teeth + hub + threads;
        let (k_wheel, k_worm) = (self.wheel.basis.len(), self.worm.basis.len());
        let width = k_wheel + hub + k_worm;
        let mut packed = vec![0.0; cells.len() * width];
        let (wheel_present, wheel_rows) = relation_rows(
            &self.wheel.basis,
            &wheel_groups,
            &wheel_coords,
            (&mut packed, width, 0),
            0,
        );
        if hub > 0 {
            self.wheel
                .write_wrenches(cells, &mut packed, width, k_wheel);
        }
        let (worm_present, worm_rows) = relation_rows(
            &self.worm.basis,
            &worm_groups,
            &worm_coords,
            (&mut packed, width, k_wheel + hub),
            teeth + hub,
        );
        let mut core = vec![0.0; rank * rank];
        let mut place = |block: &[f64], size: usize, at: usize| {
            for r in 0..size {
                core[(at + r) * rank + at..(at + r) * rank + at + size]
                    .copy_from_slice(&block[r * size..(r + 1) * size]);
            }
        };
        place(&self.wheel.teeth_core(&wheel_present), teeth, 0);
        if let Some(s) = self.wheel.shaft_compliance.as_deref().filter(|_| hub > 0) {
            place(s, 6, teeth);
        }
        place(&self.worm.threads_core(&worm_present), threads, teeth + hub);
        let ranges = (0..cells.len())
            .map(|i| {
                let shaft = if hub > 0 {
                    (teeth, teeth + hub)
                } else {
                    (0, 0)
                };
                [wheel_rows[i], shaft, worm_rows[i]]
            })
            .collect();
        LowRank::packed(rank, packed, width, core, ranges)
    }
}

impl WormBending {
    /// Core of the threads present (cached).
    fn threads_core(&self, present: &[i64]) -> std::sync::Arc<Vec<f64>> {
        cached_core(&self.same, &self.before, &self.after, present, &self.cores)
    }
}

/// Which flank of the worm the wheel loads (for callers building meshes by hand).
pub fn worm_loaded_flank(gear: &GearSet) -> Flank {
    crate::kinematics::loaded_flank(gear)
}
