//! The wheel's tooth root stress (MODEL §9.1): a three-tooth FE sector of the wheel (the
//! bending model's mesh, clamped at the rim's inner surface, finer) loaded by the loaded
//! contact's pressures at every position, each tooth in turn in the middle; the stresses
//! recovered at the Gauss points of the central tooth's root region; the largest principal
//! stress over them and over the positions.
//!
//! The criterion is the largest principal stress: fatigue cracks at a tooth root start at the
//! fillet's tension side, normal to the largest tensile stress, and the tensile root stress is
//! what gear root allowables (pulsating tension tests on tooth roots) refer to.
//!
//! Status (issue 34): not used by the safety table yet; neither reading converges on the
//! design case under the sector's refinement (levels 1-4):
//! - the largest principal stress at the Gauss points of the root region: 94, 140, 98,
//!   157 MPa, its place jumping between the face middle and the face ends. The contact reaches
//!   1.2 mm above the root (the worm's tip edge at the flow pressure) and its forces, lumped at
//!   the flank nodes, put their own singular stresses into the root;
//! - the linearised stress across the root section (membrane + bending, [`linearised`]):
//!   25.2, 49.5, 59.1, 65.5 MPa, always at the face middle, position 13; the last step is still
//!   +10.7 %. The flank meets the root circle at a corner (the hob's tip is sharp, MODEL §12),
//!   a re-entrant notch whose stress is singular, which slows the section's convergence.
//!
//! Next: a hob tip radius (a filleted root), the pressures as consistent face tractions.

use super::fe::{
    element_stress, natural_coordinates, principal_stresses, solve, Elastic, FeError, Load, Mesh,
};
use super::wheel_mesh::{sector_mesh, SectorMesh, SectorMeshSettings};
use crate::geometry::placement::from_wheel_body;
use crate::geometry::{Flank, Geometry, WheelFlank};
use crate::input::GearSet;
use crate::ltca::Ltca;
use std::collections::HashMap;

/// The sector mesh of refinement `level` (elements across a tooth 2 level, along its height
/// 3 level, through the rim and across a half space level), no web: clamped at the rim.
pub fn root_mesh_settings(gear: &GearSet, level: usize) -> SectorMeshSettings {
    let s = level.max(1);
    let width = gear.bending.width_points.max(2);
    let intervals = (width - 1) * s;
    SectorMeshSettings {
        across: 2 * s,
        height: 3 * s,
        rim: s,
        space: s,
        face_step: (gear.analysis.flank_cells_face / intervals).max(1),
        rim_thickness: gear.wheel_body().rim_thickness,
        web: None,
    }
}

/// The default refinement of the root stress's sector ([`root_mesh_settings`]).
pub const ROOT_LEVEL: usize = 4;

/// The largest root stress and where it is.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct RootStress {
    /// Largest principal stress at the root, Pa.
    pub max_principal: f64,
    /// The position (of the loaded analysis) and the tooth (its index there) in the middle.
    pub position: usize,
    pub tooth: i32,
    /// The Gauss point: radius and face coordinate (wheel body frame), m.
    pub r: f64,
    pub z: f64,
}

impl RootStress {
    /// No stress found yet (-infinity, nowhere).
    const NONE: RootStress = RootStress {
        max_principal: f64::NEG_INFINITY,
        position: 0,
        tooth: 0,
        r: f64::NAN,
        z: f64::NAN,
    };
}

/// Radius of the root circle at face coordinate z: the hob's tip torus, m.
fn root_radius_at(gear: &GearSet, z: f64) -> f64 {
    let tip = gear.hob.tip_radius;
    gear.cutting.centre_distance - (tip * tip - z * z).max(0.0).sqrt()
}

/// The blank top at z (linear between the flank grid's node columns), m.
fn top_at(wf: &WheelFlank, z: f64) -> f64 {
    match wf.z.iter().position(|&zz| zz >= z) {
        Some(0) => wf.r_high[0],
        None => *wf.r_high.last().unwrap_or(&0.0),
        Some(i) => {
            let t = (z - wf.z[i - 1]) / (wf.z[i] - wf.z[i - 1]);
            wf.r_high[i - 1] + t * (wf.r_high[i] - wf.r_high[i - 1])
        }
    }
}

/// Where flank forces go on the sector: per tooth (0, 1, 2) its loaded flank's nodes by
/// (layer, height index), the layers' z, the largest height index.
struct FlankNodes<'a> {
    gear: &'a GearSet,
    wf: &'a WheelFlank,
    nodes: Vec<HashMap<(usize, usize), usize>>,
    layer_z: Vec<f64>,
    max_h: usize,
    /// Angular pitch, rad.
    tau: f64,
}

impl<'a> FlankNodes<'a> {
    fn new(gear: &'a GearSet, geo: &'a Geometry, m: &SectorMesh, flank: Flank) -> Self {
        let wf = geo.wheel_flank(flank);
        let lists = match flank {
            Flank::Left => &m.left_flank,
            Flank::Right => &m.right_flank,
        };
        let nodes = lists
            .iter()
            .map(|l| l.iter().map(|&(layer, h, n)| ((layer, h), n)).collect())
            .collect();
        let max_h = lists[1].iter().map(|f| f.1).max().unwrap_or(0);
        let layer_z = m.layer_columns.iter().map(|&j| wf.z[j]).collect();
        Self {
            gear,
            wf,
            nodes,
            layer_z,
            max_h,
            tau: 2.0 * std::f64::consts::PI / geo.teeth as f64,
        }
    }

    /// Nodal forces of a force `p area` into sector tooth `tooth` (0, 1, 2) at flank point
    /// (r, z): along minus the flank normal, shared bilinearly among the four nodes around it
    /// in (layer, height index).
    fn add(&self, loads: &mut Vec<Load>, tooth: usize, (r, z): (f64, f64), force: f64) {
        let root = root_radius_at(self.gear, z);
        let h = ((r - root) / (top_at(self.wf, z) - root)).clamp(0.0, 1.0) * self.max_h as f64;
        let last = self.layer_z.len() - 1;
        let l = match self.layer_z.iter().position(|&lz| lz >= z) {
            Some(0) => 0.0,
            None => last as f64,
            Some(i) => {
                let (a, b) = (self.layer_z[i - 1], self.layer_z[i]);
                (i - 1) as f64 + (z - a) / (b - a)
            }
        };
        let normal = from_wheel_body(&self.wf.normal_at(r, z), (tooth as f64 - 1.0) * self.tau);
        let (l0, h0) = (l.floor() as usize, h.floor() as usize);
        let (tl, th) = (l - l0 as f64, h - h0 as f64);
        let corners = [
            (l0, h0, (1.0 - tl) * (1.0 - th)),
            (l0 + 1, h0, tl * (1.0 - th)),
            (l0, h0 + 1, (1.0 - tl) * th),
            (l0 + 1, h0 + 1, tl * th),
        ];
        let found: Vec<(usize, f64)> = corners
            .iter()
            .filter(|c| c.2 > 0.0)
            .filter_map(|&(a, b, w)| self.nodes[tooth].get(&(a, b)).map(|&n| (n, w)))
            .collect();
        let total: f64 = found.iter().map(|f| f.1).sum();
        for (n, w) in found {
            for d in 0..3 {
                loads.push((n, d, -normal[d] * force * w / total));
            }
        }
    }
}

/// One load case per (position, tooth in the middle): the loaded cells of that tooth and its
/// two neighbours on the sector's three teeth. Returns the cases and their (position, tooth).
fn load_cases(ltca: &Ltca, flank: &FlankNodes) -> (Vec<Vec<Load>>, Vec<(usize, i32)>) {
    let mut cases = Vec::new();
    let mut labels = Vec::new();
    for p in &ltca.positions {
        let mut teeth: Vec<i32> = p
            .cells
            .iter()
            .zip(&p.pressure)
            .filter(|(_, &pr)| pr > 0.0)
            .map(|(c, _)| c.tooth)
            .collect();
        teeth.sort_unstable();
        teeth.dedup();
        for &middle in &teeth {
            let mut loads = Vec::new();
            for (c, &pr) in p.cells.iter().zip(&p.pressure) {
                let t = c.tooth - middle + 1;
                if pr > 0.0 && (0..3).contains(&t) {
                    flank.add(&mut loads, t as usize, (c.r, c.z), pr * c.cell.area());
                }
            }
            cases.push(loads);
            labels.push((p.position, middle));
        }
    }
    (cases, labels)
}

/// The Gauss points of the root region of the central tooth: elements whose centre lies
/// within the central tooth's pitch, from 0.3 of the tooth height below the root circle to
/// 0.25 above it, and that carry no loaded node (a nodal force's own singular stress is not
/// the root's); as (element, natural point).
fn root_points(
    gear: &GearSet,
    m: &SectorMesh,
    (centre_angle, tau): (f64, f64),
    loaded: &[usize],
) -> Vec<(usize, [f64; 3])> {
    let height = gear.wheel.throat_radius - root_radius_at(gear, 0.0);
    let edge = gear.worm.axial_pitch / std::f64::consts::PI;
    let clearance = 0.15 * height;
    let g = (0.6f64).sqrt();
    let natural = [-g, 0.0, g];
    let mut points = Vec::new();
    for (e, nodes) in m.mesh.elements.iter().enumerate() {
        let c: [f64; 3] = std::array::from_fn(|d| {
            nodes[..8].iter().map(|&n| m.mesh.nodes[n][d]).sum::<f64>() / 8.0
        });
        let r = c[0].hypot(c[1]);
        let angle = c[1].atan2(c[0]);
        let off = (angle - centre_angle + std::f64::consts::PI)
            .rem_euclid(2.0 * std::f64::consts::PI)
            - std::f64::consts::PI;
        let above = r - root_radius_at(gear, c[2]);
        if off.abs() > 0.5 * tau
            || c[2].abs() > 0.5 * gear.wheel.face_width - edge
            || !(-0.3 * height..=0.25 * height).contains(&above)
            || loaded.iter().any(|&n| {
                let q = m.mesh.nodes[n];
                (q[0] - c[0]).hypot(q[1] - c[1]).hypot(q[2] - c[2]) < clearance
            })
        {
            continue;
        }
        for a in natural {
            for b in natural {
                for cc in natural {
                    points.push((e, [a, b, cc]));
                }
            }
        }
    }
    points
}

/// The angle of the central tooth (its loaded and opposite flank nodes' mean direction), rad.
fn central_tooth_angle(m: &SectorMesh) -> f64 {
    let (mut x, mut y) = (0.0, 0.0);
    for &(_, _, n) in m.left_flank[1].iter().chain(&m.right_flank[1]) {
        let p = m.mesh.nodes[n];
        let r = p[0].hypot(p[1]);
        x += p[0] / r;
        y += p[1] / r;
    }
    y.atan2(x)
}

/// The sector of refinement `level` solved under every (position, tooth in the middle) load
/// case of `ltca` on the wheel's `flank`: its mesh, material, cases, their labels and
/// displacements.
struct LoadedSector {
    mesh: SectorMesh,
    material: Elastic,
    cases: Vec<Vec<Load>>,
    labels: Vec<(usize, i32)>,
    solutions: Vec<Vec<[f64; 3]>>,
}

impl LoadedSector {
    fn solve(
        gear: &GearSet,
        geo: &Geometry,
        ltca: &Ltca,
        flank: Flank,
        level: usize,
    ) -> Result<Self, FeError> {
        let mesh = sector_mesh(
            geo,
            &root_mesh_settings(gear, level),
            gear.hob.tip_radius,
            gear.cutting.centre_distance,
        );
        let nodes = FlankNodes::new(gear, geo, &mesh, flank);
        let (cases, labels) = load_cases(ltca, &nodes);
        let fixed: Vec<(usize, usize, f64)> = mesh
            .inner
            .iter()
            .flat_map(|&n| (0..3).map(move |d| (n, d, 0.0)))
            .collect();
        let material = Elastic {
            youngs_modulus: gear.wheel_material.youngs_modulus,
            poisson_ratio: gear.wheel_material.poisson_ratio,
        };
        let solutions = solve(&mesh.mesh, &material, &fixed, &cases)?;
        Ok(Self {
            mesh,
            material,
            cases,
            labels,
            solutions,
        })
    }

    /// The largest stress over every load case and every `candidate`: `stress(u, candidate)`
    /// gives the stress (Pa) under the displacements `u` and its place (r, z; m).
    fn largest<T>(
        &self,
        candidates: &[T],
        stress: impl Fn(&[[f64; 3]], &T) -> Result<(f64, f64, f64), FeError>,
    ) -> Result<RootStress, FeError> {
        let mut best = RootStress::NONE;
        for (u, &(position, tooth)) in self.solutions.iter().zip(&self.labels) {
            for candidate in candidates {
                let (s, r, z) = stress(u, candidate)?;
                if s > best.max_principal {
                    best = RootStress {
                        max_principal: s,
                        position,
                        tooth,
                        r,
                        z,
                    };
                }
            }
        }
        Ok(best)
    }
}

/// The largest principal stress at the central tooth's root over every position and tooth of
/// `ltca` (MODEL §9.1), on the sector of refinement `level` loaded on the wheel's `flank`.
pub fn root_stress(
    gear: &GearSet,
    geo: &Geometry,
    ltca: &Ltca,
    flank: Flank,
    level: usize,
) -> Result<RootStress, FeError> {
    let loaded = LoadedSector::solve(gear, geo, ltca, flank, level)?;
    let mut loaded_nodes: Vec<usize> = loaded.cases.iter().flatten().map(|l| l.0).collect();
    loaded_nodes.sort_unstable();
    loaded_nodes.dedup();
    let m = &loaded.mesh;
    let tau = 2.0 * std::f64::consts::PI / geo.teeth as f64;
    let points = root_points(gear, m, (central_tooth_angle(m), tau), &loaded_nodes);
    loaded.largest(&points, |u, &(e, xi)| {
        let s = principal_stresses(element_stress(&m.mesh, e, &loaded.material, u, xi)?)[0];
        let (n, _) = super::fe::shape(xi);
        let x: [f64; 3] = std::array::from_fn(|d| {
            m.mesh.elements[e]
                .iter()
                .zip(n)
                .map(|(&k, w)| w * m.mesh.nodes[k][d])
                .sum()
        });
        Ok((s, x[0].hypot(x[1]), x[2]))
    })
}

/// A root section of the central tooth at one face layer: the chord between its two flanks'
/// nodes on the root circle, sampled at Gauss-Legendre points, each located in its element.
struct RootSection {
    /// (element, natural point, weight on [0, 1], position s in [0, 1] from the left flank).
    points: Vec<(usize, [f64; 3], f64, f64)>,
    /// Unit normal of the section (radial at the chord's middle), wheel body frame.
    normal: [f64; 3],
    /// Face coordinate of the layer, m.
    z: f64,
    radius: f64,
}

/// Gauss-Legendre points and weights on [0, 1] (8 points).
fn gauss_legendre_8() -> [(f64, f64); 8] {
    let x = [
        0.183_434_642_495_649_8,
        0.525_532_409_916_329,
        0.796_666_477_413_626_7,
        0.960_289_856_497_536_3,
    ];
    let w = [
        0.362_683_783_378_362,
        0.313_706_645_877_887_3,
        0.222_381_034_453_374_5,
        0.101_228_536_290_376_3,
    ];
    std::array::from_fn(|k| {
        let (i, sign) = if k < 4 { (3 - k, -1.0) } else { (k - 4, 1.0) };
        (0.5 + 0.5 * sign * x[i], 0.5 * w[i])
    })
}

/// The root sections of the central tooth, one per face layer with both flanks' root nodes.
fn root_sections(m: &SectorMesh) -> Vec<RootSection> {
    let at_root = |list: &[(usize, usize, usize)], layer: usize| {
        list.iter().find(|f| f.0 == layer && f.1 == 0).map(|f| f.2)
    };
    let mut sections = Vec::new();
    for layer in 0..m.layer_columns.len() {
        let (Some(a), Some(b)) = (
            at_root(&m.left_flank[1], layer),
            at_root(&m.right_flank[1], layer),
        ) else {
            continue;
        };
        let (pa, pb) = (m.mesh.nodes[a], m.mesh.nodes[b]);
        let mid: [f64; 3] = std::array::from_fn(|d| 0.5 * (pa[d] + pb[d]));
        let radius = mid[0].hypot(mid[1]);
        let normal = [mid[0] / radius, mid[1] / radius, 0.0];
        let mut points = Vec::new();
        for (s, w) in gauss_legendre_8() {
            let p: [f64; 3] = std::array::from_fn(|d| pa[d] + s * (pb[d] - pa[d]));
            if let Some((e, xi)) = locate(&m.mesh, p) {
                points.push((e, xi, w, s));
            }
        }
        if points.len() == 8 {
            sections.push(RootSection {
                points,
                normal,
                z: mid[2],
                radius,
            });
        }
    }
    sections
}

/// The element holding `p` and its natural coordinates there (elements whose bounding box
/// holds the point, first that inverts).
fn locate(mesh: &Mesh, p: [f64; 3]) -> Option<(usize, [f64; 3])> {
    mesh.elements.iter().enumerate().find_map(|(e, nodes)| {
        let inside = (0..3).all(|d| {
            let (lo, hi) = nodes
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &n| {
                    (lo.min(mesh.nodes[n][d]), hi.max(mesh.nodes[n][d]))
                });
            let pad = 1e-9 * (hi - lo).abs().max(1e-6);
            p[d] >= lo - pad && p[d] <= hi + pad
        });
        if !inside {
            return None;
        }
        natural_coordinates(mesh, e, p).map(|xi| (e, xi))
    })
}

/// The linearised root stress of one section under the displacements `u` (ASME BPVC VIII-2
/// Annex 5-A stress linearisation): the normal stress across the chord's membrane part
/// sigma_m = integral sigma ds and bending part sigma_b = 6 integral sigma (s - 1/2) ds; the
/// larger extreme fibre sigma_m + |sigma_b|, Pa.
fn linearised(
    m: &SectorMesh,
    material: &Elastic,
    u: &[[f64; 3]],
    section: &RootSection,
) -> Result<f64, FeError> {
    let n = section.normal;
    let (mut membrane, mut bending) = (0.0, 0.0);
    for &(e, xi, w, s) in &section.points {
        let t = element_stress(&m.mesh, e, material, u, xi)?;
        let sigma = [[t[0], t[5], t[4]], [t[5], t[1], t[3]], [t[4], t[3], t[2]]];
        let normal: f64 = (0..3)
            .map(|i| (0..3).map(|j| n[i] * sigma[i][j] * n[j]).sum::<f64>())
            .sum();
        membrane += w * normal;
        bending += 6.0 * w * normal * (s - 0.5);
    }
    Ok(membrane + bending.abs())
}

/// The largest linearised root stress ([`linearised`]) over the central tooth's root sections,
/// every position and tooth of `ltca` (MODEL §9.1), on the sector of refinement `level`.
pub fn linearised_root_stress(
    gear: &GearSet,
    geo: &Geometry,
    ltca: &Ltca,
    flank: Flank,
    level: usize,
) -> Result<RootStress, FeError> {
    let loaded = LoadedSector::solve(gear, geo, ltca, flank, level)?;
    let sections = root_sections(&loaded.mesh);
    loaded.largest(&sections, |u, section| {
        let s = linearised(&loaded.mesh, &loaded.material, u, section)?;
        Ok((s, section.radius, section.z))
    })
}
