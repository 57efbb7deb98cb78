//! Wheel bending coefficients for the LTCA (MODEL §5.5): FE of the wheel sector, unit normal
//! loads at a K = Q1 x Q2 grid of the central tooth's loaded flank, bending = opposite flank free
//! minus blocked, projected on the normals; three tooth relations (same tooth, the tooth before,
//! the tooth after) fitted on the free-free function basis; plus, when the model has the whole
//! ring with its web clamped at the hub, the hub's rigid-body motion on the shaft
//! ([`super::wheel_shaft`]) as six more low-rank terms. The worm's bending is not included:
//! the model reports itself as "fe-wheel".

use super::basis::{Basis, WidthFunctions};
use super::fe::{free_minus_blocked, Elastic, FeError};
use super::wheel_mesh::{sector_mesh, SectorMesh, SectorMeshSettings};
use super::wheel_shaft::{wrench, WheelShaft};
use crate::geometry::{Flank, Geometry, WheelFlank};
use crate::input::GearSet;
use crate::ltca::solver::LowRank;
use crate::ltca::{BendingModel, LocalCell};
use faer::Mat;

/// Wheel bending model.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct WheelBending {
    pub basis: Basis,
    /// Core matrices for receivers on the same tooth, the tooth before (k - 1) and after (k + 1)
    /// the loaded one, m/N.
    #[serde(with = "super::mat_serde")]
    pub same: Mat<f64>,
    #[serde(with = "super::mat_serde")]
    pub before: Mat<f64>,
    #[serde(with = "super::mat_serde")]
    pub after: Mat<f64>,
    /// Root radius and blank top as functions of z are needed to map r to r~.
    root_centre_distance: f64,
    hob_tip: f64,
    face_width: f64,
    top: Vec<(f64, f64)>,
    /// Compliance of the hub's rigid-body motion on the shaft at the wheel centre (6 x 6,
    /// row-major, (m, rad) per (N, N m), fixed wheel frame); None: the hub does not move
    /// (sector clamped at the rim or at the hub).
    pub shaft_compliance: Option<Vec<f64>>,
    #[serde(skip)]
    cores: super::relation::CoreCache,
}

/// Fit points (MODEL §5.5): the basis grid mapped to the nearest flank nodes, as (layer,
/// height index) of a sector mesh with `n_layers` layers and height indices up to `max_h`.
fn fit_points(basis: &Basis, (n_layers, max_h): (usize, usize)) -> Vec<(usize, usize)> {
    let grid = basis.grid();
    let pick = |(r, w): (f64, f64)| {
        (
            (w * (n_layers - 1) as f64).round() as usize,
            (r * max_h as f64).round() as usize,
        )
    };
    grid.iter().map(|&p| pick(p)).collect()
}

/// The FE nodes of the fit points on the three teeth (before, loaded, after); usize::MAX
/// where a tooth lacks one.
fn tooth_nodes(m: &SectorMesh, points: &[(usize, usize)]) -> Vec<Vec<usize>> {
    let node = |tooth: usize, (layer, h): (usize, usize)| {
        m.left_flank[tooth]
            .iter()
            .find(|f| f.0 == layer && f.1 == h)
            .map(|f| f.2)
            .unwrap_or(usize::MAX)
    };
    (0..3)
        .map(|t| points.iter().map(|&p| node(t, p)).collect())
        .collect()
}

/// Unit normals of the left flank at the fit points (`nodes` of the loaded tooth), on each of
/// the three teeth in that tooth's orientation (the reference normal rotated by the tooth
/// offset, body frame).
fn tooth_normals(
    m: &SectorMesh,
    wf: &WheelFlank,
    points: &[(usize, usize)],
    nodes: &[usize],
    teeth: u32,
) -> Vec<Vec<nalgebra::Vector3<f64>>> {
    let normal = |n: usize, layer: usize| {
        let p = m.mesh.nodes[n];
        let r = (p[0] * p[0] + p[1] * p[1]).sqrt();
        wf.column_normal(m.layer_columns[layer], r)
    };
    // Normals of the same (r, z) on each tooth, in that tooth's orientation: rotate the
    // reference normal by the tooth offset (body frame).
    let tau = 2.0 * std::f64::consts::PI / teeth as f64;
    (0..3)
        .map(|t| {
            let k = t as f64 - 1.0;
            points
                .iter()
                .zip(nodes)
                .map(|(&(layer, _), &n)| {
                    crate::geometry::placement::from_wheel_body(&normal(n, layer), k * tau)
                })
                .collect()
        })
        .collect()
}

/// The fit points' basis coordinates at the nodes (r~ = height index / max, w~ = layer / last).
fn fit_coordinates(
    points: &[(usize, usize)],
    (n_layers, max_h): (usize, usize),
) -> Vec<(f64, f64)> {
    points
        .iter()
        .map(|&(layer, h)| {
            (
                h as f64 / max_h as f64,
                layer as f64 / (n_layers - 1) as f64,
            )
        })
        .collect()
}

impl WheelBending {
    /// Builds the model: FE of the sector (`mesh` settings) with `height` x `width` fit points,
    /// and the shaft under the hub when given.
    pub fn build(
        gear: &GearSet,
        geo: &Geometry,
        mesh_settings: &SectorMeshSettings,
        shaft: Option<&WheelShaft>,
        height: usize,
        width: usize,
    ) -> Result<Self, FeError> {
        let m: SectorMesh = sector_mesh(
            geo,
            mesh_settings,
            gear.hob.tip_radius,
            gear.cutting.centre_distance,
        );
        let wf = geo.wheel_flank(Flank::Left);
        let n_layers = m.layer_columns.len();
        let max_h = m.left_flank[1].iter().map(|f| f.1).max().unwrap_or(0);
        let basis = Basis {
            height,
            width,
            kind: WidthFunctions::FreeFree,
        };
        let points = fit_points(&basis, (n_layers, max_h));
        let ids = tooth_nodes(&m, &points);
        let normals = tooth_normals(&m, wf, &points, &ids[1], geo.teeth);
        let material = Elastic {
            youngs_modulus: gear.wheel_material.youngs_modulus,
            poisson_ratio: gear.wheel_material.poisson_ratio,
        };
        let loads: Vec<(usize, nalgebra::Vector3<f64>)> = ids[1]
            .iter()
            .copied()
            .zip(normals[1].iter().copied())
            .collect();
        // Observed: the fit points on the three teeth (ids[t][l] is observed[t * k + l]).
        let observed: Vec<usize> = ids.iter().flatten().copied().collect();
        let bending = bending_displacements(&m, &material, &loads, &observed)?;
        let k = basis.len();
        let relation = |t: usize| {
            Mat::from_fn(k, k, |l, c| {
                let d = bending[c][t * k + l];
                let n = normals[t][l];
                -(d[0] * n[0] + d[1] * n[1] + d[2] * n[2])
            })
        };
        let (u_before, u_same, u_after) = (relation(0), relation(1), relation(2));
        let coords = fit_coordinates(&points, (n_layers, max_h));
        let top: Vec<(f64, f64)> = wf.z.iter().zip(&wf.r_high).map(|(&z, &r)| (z, r)).collect();
        Ok(Self {
            basis,
            same: basis.fit_at(&coords, &u_same),
            before: basis.fit_at(&coords, &u_before),
            after: basis.fit_at(&coords, &u_after),
            root_centre_distance: gear.cutting.centre_distance,
            hob_tip: gear.hob.tip_radius,
            face_width: gear.wheel.face_width,
            top,
            shaft_compliance: shaft.map(|s| {
                let c = s.compliance();
                (0..36).map(|i| c[(i / 6, i % 6)]).collect()
            }),
            cores: Default::default(),
        })
    }

    /// Basis coordinates (r~, w~) of a flank point (r, z): r~ from the root circle to the
    /// blank top (as the sector mesh), w~ = z / b + 1/2.
    pub fn coordinates(&self, r: f64, z: f64) -> (f64, f64) {
        let root =
            self.root_centre_distance - (self.hob_tip * self.hob_tip - z * z).max(0.0).sqrt();
        // Blank top at z: linear interpolation of the node-column values.
        let top = match self.top.iter().position(|&(zz, _)| zz >= z) {
            Some(0) | None => self.top.last().map(|t| t.1).unwrap_or(root + 1e-3),
            Some(i) => {
                let (a, b) = (self.top[i - 1], self.top[i]);
                a.1 + (b.1 - a.1) * (z - a.0) / (b.0 - a.0)
            }
        };
        ((r - root) / (top - root), z / self.face_width + 0.5)
    }
}

/// Bending displacements of the wheel model (MODEL §5.5 step 2): for each load case, a unit
/// force into the central tooth (along -n) at the given node, the FE displacement of the
/// `observed` nodes with the tooth's opposite flank free minus that with it blocked (removes
/// the local contact and keeps the bending). The mesh's `inner` nodes are clamped (the hub
/// surface of the whole ring, or the rim's inner surface of a bare sector). Index:
/// [case][observed k], m/N.
pub fn bending_displacements(
    m: &SectorMesh,
    material: &Elastic,
    loads: &[(usize, nalgebra::Vector3<f64>)],
    observed: &[usize],
) -> Result<Vec<Vec<[f64; 3]>>, FeError> {
    let fixed: Vec<(usize, usize, f64)> = m
        .inner
        .iter()
        .flat_map(|&n| (0..3).map(move |d| (n, d, 0.0)))
        .collect();
    let blocked: Vec<usize> = m.right_flank[1].iter().map(|f| f.2).collect();
    free_minus_blocked(&m.mesh, material, (&fixed, &[]), &blocked, loads, observed)
}

impl BendingModel for WheelBending {
    fn name(&self) -> &'static str {
        "fe-wheel"
    }

    fn rigid_rotation_compliance(&self) -> f64 {
        // Torsion about the axis: the (theta_z, M_z) entry of the shaft compliance.
        self.shaft_compliance
            .as_ref()
            .and_then(|s| s.get(35).copied())
            .unwrap_or(0.0)
    }

    fn coefficients(&self, cells: &[LocalCell]) -> LowRank {
        let (groups, coords) = self.groups(cells);
        // Symmetrised core (reciprocity; the before/after fits are each other's transposes up to
        // the sector's end effects).
        let teeth = super::relation::relation_low_rank(
            &self.basis,
            &self.same,
            &self.before,
            &self.after,
            &groups,
            &coords,
            &self.cores,
        );
        match &self.shaft_compliance {
            Some(s) if s.len() == 36 => with_rigid_body(teeth, s, cells),
            _ => teeth,
        }
    }
}

impl WheelBending {
    /// Tooth groups and basis coordinates of the cells.
    pub(crate) fn groups(&self, cells: &[LocalCell]) -> (Vec<i64>, Vec<(f64, f64)>) {
        (
            cells.iter().map(|c| c.tooth as i64).collect(),
            cells.iter().map(|c| self.coordinates(c.r, c.z)).collect(),
        )
    }

    /// The hub moves on its shaft (six rigid-body terms).
    pub(crate) fn has_shaft(&self) -> bool {
        self.shaft_compliance
            .as_ref()
            .is_some_and(|s| s.len() == 36)
    }

    /// Core of the teeth present (cached).
    pub(crate) fn teeth_core(&self, present: &[i64]) -> std::sync::Arc<Vec<f64>> {
        super::relation::cached_core(&self.same, &self.before, &self.after, present, &self.cores)
    }

    /// Writes each cell's wrench g_i = (n_i, M_i x n_i) (fixed wheel frame) at columns
    /// `offset..offset + 6` of its row of `f` (row length `stride`).
    pub(crate) fn write_wrenches(
        &self,
        cells: &[LocalCell],
        f: &mut [f64],
        stride: usize,
        offset: usize,
    ) {
        for (i, c) in cells.iter().enumerate() {
            let g = wrench(&c.wheel_centre, &c.wheel_normal);
            f[i * stride + offset..i * stride + offset + 6].copy_from_slice(g.as_slice());
        }
    }
}

/// Appends the hub's rigid-body motion to the teeth's low-rank term: six more columns, row i
/// the wrench g_i = (n_i, M_i x n_i) of cell i in the fixed wheel frame, core the shaft
/// compliance S, so C_ij += g_i^T S g_j (MODEL §5.5: bending of the wheel's environment).
pub fn with_rigid_body(teeth: LowRank, compliance: &[f64], cells: &[LocalCell]) -> LowRank {
    let (k0, rank) = (teeth.rank, teeth.rank + 6);
    let mut f = vec![0.0; cells.len() * rank];
    let mut ranges = Vec::with_capacity(cells.len());
    for (i, c) in cells.iter().enumerate() {
        f[i * rank..i * rank + k0].copy_from_slice(&teeth.dense_row(i));
        let g = wrench(&c.wheel_centre, &c.wheel_normal);
        f[i * rank + k0..(i + 1) * rank].copy_from_slice(g.as_slice());
        let [r0, _, _] = teeth
            .ranges
            .get(i)
            .copied()
            .unwrap_or([(0, k0), (0, 0), (0, 0)]);
        ranges.push([r0, (k0, rank), (0, 0)]);
    }
    let mut core = vec![0.0; rank * rank];
    for r in 0..k0 {
        core[r * rank..r * rank + k0].copy_from_slice(&teeth.core[r * k0..(r + 1) * k0]);
    }
    for r in 0..6 {
        for c in 0..6 {
            core[(k0 + r) * rank + k0 + c] = compliance[r * 6 + c];
        }
    }
    LowRank::new(rank, f, core, ranges)
}
