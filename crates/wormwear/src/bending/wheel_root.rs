//! The wheel's tooth root stress (MODEL §9.1): a three-tooth FE sector of the wheel with
//! filleted roots ([`super::root_mesh`], clamped at the rim's inner surface) loaded by the
//! loaded contact's pressures at every position, each loaded tooth in turn in the middle; the
//! normal stress across the central tooth's root section (the chord between its fillets' mid
//! points) linearised into membrane and bending parts at fixed face stations; the larger
//! extreme fibre, the largest over the positions and over the stations from one module inside
//! the face ends ([`LoadedSector::root_stresses`]).
//!
//! Why the section stress and not the fillet's peak principal stress: on a worm wheel whose
//! worm tip contact reaches just above the fillet the peak is a local contact stress and does
//! not converge (350, 541, 403, 414 MPa at levels 1-4 on the design case); nor do the sections
//! within a module of the face ends, which follow the face edge's contact load (reported beside
//! it as information). The section stress converges (66.4, 72.2, 73.6, 74.4 MPa).
//!
//! The root must be filleted: at the generated wheel's sharp root corner the elastic stress is
//! singular and no root stress converges (on the design case the largest principal stress at
//! the corner's Gauss points read 94, 140, 98, 157 MPa under four refinements). Each cell's
//! contact force enters as a consistent nodal load (the flank face's shape functions at the
//! cell's point), so no nodal force puts its own singular stress into the tooth.

use super::fe::{element_stress, natural_coordinates, shape, KeptFactor};
use super::fe::{Elastic, FeError, Load};
use super::root_mesh::{fillet_sector_mesh, FilletMeshError, FilletMeshSettings};
use super::root_mesh::{flank_row, FilletSector, Side};
use crate::geometry::placement::{from_wheel_body, wheel_point};
use crate::geometry::{Flank, Geometry, WheelFlank};
use crate::input::GearSet;
use crate::ltca::Ltca;

/// The filleted sector of refinement `level` (1, 2, ...): `level` elements along each half
/// fillet arc, 3 level + 2 across a tooth, 2 level + 2 along its flank, level + 1 through the
/// rim below the fillet band, level + 2 across each root land, 2 level + 6 face layers.
pub fn root_mesh_settings(gear: &GearSet, level: usize, fillet_radius: f64) -> FilletMeshSettings {
    let s = level.max(1);
    FilletMeshSettings {
        fillet_radius,
        fillet: s,
        across: 3 * s + 2,
        height: 2 * s + 2,
        rim: s + 1,
        space: s + 2,
        layers: 2 * s + 6,
        rim_thickness: gear.wheel_body().rim_thickness,
    }
}

/// Root sections read along the face: this many intervals between the face ends, at fixed
/// places whatever the mesh.
const ROOT_STATIONS: usize = 24;

/// The default refinement of the root stress's sector ([`root_mesh_settings`]).
pub const ROOT_LEVEL: usize = 2;

/// Why the root stress could not be computed.
#[derive(Debug, thiserror::Error)]
pub enum RootStressError {
    #[error(transparent)]
    Mesh(#[from] FilletMeshError),
    #[error(transparent)]
    Fe(#[from] FeError),
    #[error(
        "the loaded contact reaches {reach_mm:.3} mm above the root at z = {z_mm:.2} mm, below \
         the root fillet's tangent point ({tangent_mm:.3} mm above the root): \
         rating.root_fillet_radius_mm = {radius_mm} is larger than the flank below the contact \
         allows"
    )]
    ContactOnFillet {
        reach_mm: f64,
        z_mm: f64,
        tangent_mm: f64,
        radius_mm: f64,
    },
}

/// The largest root stress and where it is.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RootStress {
    /// Linearised root stress sigma_m + |sigma_b| (the larger extreme fibre), Pa.
    pub stress: f64,
    /// The position (of the loaded analysis) and the tooth (its index there) in the middle.
    pub position: usize,
    pub tooth: i32,
    /// The section's middle: radius and face coordinate (wheel body frame), m.
    pub r: f64,
    pub z: f64,
    /// Whether the larger fibre stress is on the loaded flank's side (else the opposite one).
    pub tension_on_loaded_side: bool,
}

impl RootStress {
    /// No stress found yet (-infinity, nowhere).
    const NONE: RootStress = RootStress {
        stress: f64::NEG_INFINITY,
        position: 0,
        tooth: 0,
        r: f64::NAN,
        z: f64::NAN,
        tension_on_loaded_side: false,
    };
}

/// Radius of the root circle at face coordinate z: the hob's tip torus, m.
fn root_radius_at(gear: &GearSet, z: f64) -> f64 {
    let tip = gear.hob.tip_radius;
    gear.cutting.centre_distance - (tip * tip - z * z).max(0.0).sqrt()
}

/// Where flank forces go on the sector: the loaded flank's side of each tooth block.
struct FlankLoads<'a> {
    gear: &'a GearSet,
    wf: &'a WheelFlank,
    sector: &'a FilletSector,
    side: Side,
    /// Angular pitch, rad.
    tau: f64,
}

impl FlankLoads<'_> {
    /// The sector's fillet radius, mm.
    fn radius_mm(&self) -> f64 {
        self.sector.settings.fillet_radius * 1e3
    }

    /// The layer holding face coordinate z and the fraction across it.
    fn layer(&self, z: f64) -> (usize, f64) {
        let lz = &self.sector.layer_z;
        let last = lz.len() - 2;
        let i = lz
            .iter()
            .position(|&v| v > z)
            .map_or(last, |i| i.saturating_sub(1).min(last));
        (i, ((z - lz[i]) / (lz[i + 1] - lz[i])).clamp(0.0, 1.0))
    }

    /// Consistent nodal loads of a force `force` (N, along minus the flank normal) at flank
    /// point (r, z) of sector tooth `tooth` (0, 1, 2): the flank face's shape functions at the
    /// point.
    fn add(
        &self,
        loads: &mut Vec<Load>,
        tooth: usize,
        (r, z): (f64, f64),
        force: f64,
    ) -> Result<(), RootStressError> {
        let s = self.sector;
        let (li, f) = self.layer(z);
        let (side, teeth_shift) = match self.side {
            Side::A => (0, 0.0),
            Side::C => (1, 1.0),
        };
        let tangent = |l: usize| s.tangent_radius[l][tooth][side];
        let (t_r, top) = (
            tangent(li) + f * (tangent(li + 1) - tangent(li)),
            s.top[li] + f * (s.top[li + 1] - s.top[li]),
        );
        if r < t_r {
            let root = root_radius_at(self.gear, z);
            return Err(RootStressError::ContactOnFillet {
                reach_mm: (r - root) * 1e3,
                z_mm: z * 1e3,
                tangent_mm: (t_r - root) * 1e3,
                radius_mm: self.radius_mm(),
            });
        }
        let k = tooth as f64 - 1.0;
        let theta = self.wf.theta_at(r, z).0 + (k + teeth_shift) * self.tau;
        let p = wheel_point(r, theta, z, 0.0);
        let p = [p.x, p.y, p.z];
        let rows = &s.flank_elements[tooth][side][li];
        let x = flank_row(&s.settings, t_r, top, r);
        let guess = (s.fillet_rows + x.floor() as usize).min(rows.len() - 1);
        let face = if side == 0 { -1.0 } else { 1.0 };
        let (e, xi) = [
            guess,
            guess.saturating_sub(1),
            (guess + 1).min(rows.len() - 1),
        ]
        .iter()
        .find_map(|&row| {
            let e = rows[row];
            natural_coordinates(&s.mesh, e, p)
                .filter(|xi| xi[1].abs() <= 1.0 + 1e-6 && xi[2].abs() <= 1.0 + 1e-6)
                .map(|xi| (e, [face, xi[1].clamp(-1.0, 1.0), xi[2].clamp(-1.0, 1.0)]))
        })
        .unwrap_or_else(|| {
            // Off the faces by rounding: the guessed row's nearest face point.
            let v = x.fract() * 2.0 - 1.0;
            (rows[guess], [face, v.clamp(-1.0, 1.0), 2.0 * f - 1.0])
        });
        let normal = from_wheel_body(&self.wf.normal_at(r, z), k * self.tau);
        let (n, _) = shape(xi);
        for (&node, w) in s.mesh.elements[e].iter().zip(n) {
            for d in 0..3 {
                loads.push((node, d, -normal[d] * force * w));
            }
        }
        Ok(())
    }
}

/// Load cases and their (position, tooth in the middle).
type LoadCases = (Vec<Vec<Load>>, Vec<(usize, i32)>);

/// One load case per (position, tooth in the middle): the loaded cells of that tooth and its
/// two neighbours on the sector's three teeth. Returns the cases and their (position, tooth).
fn load_cases(ltca: &Ltca, flank: &FlankLoads) -> Result<LoadCases, RootStressError> {
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
                    flank.add(&mut loads, t as usize, (c.r, c.z), pr * c.cell.area())?;
                }
            }
            cases.push(loads);
            labels.push((p.position, middle));
        }
    }
    Ok((cases, labels))
}

/// The filleted sector of refinement `level` solved under every (position, tooth in the
/// middle) load case of `ltca` on the wheel's `flank`.
pub struct LoadedSector {
    kept: std::sync::Arc<KeptSector>,
    material: Elastic,
    side: Side,
    labels: Vec<(usize, i32)>,
    solutions: Vec<Vec<[f64; 3]>>,
}

/// A sector mesh and its factorised stiffness, kept for the next run of the same wheel
/// (a spread's samples move the worm, not the wheel): `key` names all it depends on.
struct KeptSector {
    key: String,
    sector: FilletSector,
    factor: KeptFactor,
}

/// The last sector built in this process (one: a sector's factor takes up to a gigabyte).
static KEPT_SECTOR: std::sync::Mutex<Option<std::sync::Arc<KeptSector>>> =
    std::sync::Mutex::new(None);

/// The sector of `gear`'s wheel at refinement `level` with fillet radius `fillet_radius` (m)
/// and its factorised stiffness: the kept one when its key is the same, else built (and
/// kept). The key holds everything the wheel's flanks, the sector and its stiffness read:
/// the worm, hob, cutting placement, blank and body, the analysis grid, the wheel's
/// elasticity, the level and the fillet; not the operating placement or the load. A new
/// sector passes `check` (its loads fit it) before it is factorised.
fn kept_sector(
    gear: &GearSet,
    geo: &Geometry,
    (level, fillet_radius): (usize, f64),
    material: &Elastic,
    check: &dyn Fn(&FilletSector) -> Result<(), RootStressError>,
) -> Result<std::sync::Arc<KeptSector>, RootStressError> {
    let key = serde_json::json!({
        "worm": gear.worm,
        "hob": gear.hob,
        "cutting": gear.cutting,
        "wheel": gear.wheel,
        "body": format!("{:?}", gear.wheel_body()),
        "nominal_centre_distance": gear.nominal_centre_distance,
        "analysis": gear.analysis,
        "material": [material.youngs_modulus, material.poisson_ratio],
        "level": level,
        "fillet_radius": fillet_radius,
    })
    .to_string();
    // Not held while building: runs of other wheels build theirs side by side (the first
    // runs of one wheel may each build it once).
    {
        let kept = KEPT_SECTOR.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(k) = kept.as_ref().filter(|k| k.key == key) {
            return Ok(k.clone());
        }
    }
    let sector = fillet_sector_mesh(
        geo,
        &root_mesh_settings(gear, level, fillet_radius),
        gear.hob.tip_radius,
        gear.cutting.centre_distance,
    )?;
    check(&sector)?;
    let fixed: Vec<(usize, usize, f64)> = sector
        .clamped
        .iter()
        .flat_map(|&n| (0..3).map(move |d| (n, d, 0.0)))
        .collect();
    let factor = KeptFactor::new(&sector.mesh, material, &fixed)?;
    let built = std::sync::Arc::new(KeptSector {
        key,
        sector,
        factor,
    });
    *KEPT_SECTOR.lock().unwrap_or_else(|e| e.into_inner()) = Some(built.clone());
    Ok(built)
}

/// Lets the kept sector go (its memory with it); the next root stress builds its own.
pub fn forget_kept_sector() {
    *KEPT_SECTOR.lock().unwrap_or_else(|e| e.into_inner()) = None;
}

impl LoadedSector {
    /// Builds (or takes the kept one, [`kept_sector`]) and solves the sector;
    /// `fillet_radius` in m.
    pub fn solve(
        gear: &GearSet,
        geo: &Geometry,
        ltca: &Ltca,
        (flank, level, fillet_radius): (Flank, usize, f64),
    ) -> Result<Self, RootStressError> {
        let material = Elastic {
            youngs_modulus: gear.wheel_material.youngs_modulus,
            poisson_ratio: gear.wheel_material.poisson_ratio,
        };
        let side = Side::of(flank);
        fn loads_on<'a>(
            (gear, geo, flank): (&'a GearSet, &'a Geometry, Flank),
            sector: &'a FilletSector,
        ) -> FlankLoads<'a> {
            FlankLoads {
                gear,
                wf: geo.wheel_flank(flank),
                sector,
                side: Side::of(flank),
                tau: 2.0 * std::f64::consts::PI / geo.teeth as f64,
            }
        }
        let on = (gear, geo, flank);
        let check = |sector: &FilletSector| load_cases(ltca, &loads_on(on, sector)).map(|_| ());
        let kept = kept_sector(gear, geo, (level, fillet_radius), &material, &check)?;
        let (cases, labels) = load_cases(ltca, &loads_on(on, &kept.sector))?;
        let solutions = kept.factor.solve(&cases);
        Ok(Self {
            kept,
            material,
            side,
            labels,
            solutions,
        })
    }

    /// The sector mesh.
    pub fn sector(&self) -> &FilletSector {
        &self.kept.sector
    }
}

/// The root stress readings of the loaded sector (MODEL §9.1), each the largest over every
/// position and tooth in the middle.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RootStresses {
    /// Over the sections from one module inside each face end: the root stress of the safety
    /// table.
    pub interior: RootStress,
    /// Over the sections within one module of a face end, where the face edges' contact load
    /// (carried at the flow pressure on a strip one cell wide) makes the section stress depend
    /// on the mesh: information, not converged.
    pub face_ends: RootStress,
}

/// The linearised root stresses ([`LoadedSector::root_stresses`]) of `ltca` on the filleted
/// sector of refinement `level` with fillet radius `fillet_radius` (m), loaded on the wheel's
/// `flank`.
pub fn root_stress(
    gear: &GearSet,
    geo: &Geometry,
    ltca: &Ltca,
    flank: Flank,
    (level, fillet_radius): (usize, f64),
) -> Result<RootStresses, RootStressError> {
    let loaded = LoadedSector::solve(gear, geo, ltca, (flank, level, fillet_radius))?;
    Ok(loaded.root_stresses(gear.worm.axial_pitch / std::f64::consts::PI)?)
}

/// Version of the root stress's cache entries: raise it when the sector or its reading
/// change (the loads are in the key, [`loads_fingerprint`]).
const CACHE_VERSION: u32 = 4;

/// SHA-256 of the loads the sector takes from `ltca` (every loaded cell of every position:
/// tooth, place r and z, area, pressure; the bits of each number): the loaded analysis'
/// results, which the gear file alone does not fix (a change of the model's code or defaults
/// moves them under the same gear).
fn loads_fingerprint(ltca: &Ltca) -> String {
    let mut digest = crate::integrity::RunningDigest::default();
    for p in &ltca.positions {
        digest.update(&format!("position {};", p.position));
        for (c, &pressure) in p.cells.iter().zip(&p.pressure) {
            if pressure > 0.0 {
                digest.update(&format!(
                    "{} {:x} {:x} {:x} {:x};",
                    c.tooth,
                    c.r.to_bits(),
                    c.z.to_bits(),
                    c.cell.area().to_bits(),
                    pressure.to_bits()
                ));
            }
        }
    }
    digest.hex()
}

/// [`root_stress`] from the cache directory `dir` when an entry of the same key is there (the
/// whole gear, K_A and the safety inputs with it, the fingerprint of the loaded analysis'
/// loads, the flank, level and fillet radius), else computed and cached; checksummed like the
/// bending models. Cache problems never fail the run: they come back as warnings.
pub fn root_stress_cached(
    gear: &GearSet,
    geo: &Geometry,
    ltca: &Ltca,
    (flank, level, fillet_radius): (Flank, usize, f64),
    dir: Option<&std::path::Path>,
) -> Result<(RootStresses, Vec<String>), RootStressError> {
    let key = serde_json::json!({
        "version": CACHE_VERSION,
        "gear": gear,
        "loads": loads_fingerprint(ltca),
        "flank": format!("{flank:?}"),
        "level": level,
        "fillet_radius": fillet_radius,
    })
    .to_string();
    super::model::cached(dir, ("root-stress", "root stress"), &key, || {
        root_stress(gear, geo, ltca, flank, (level, fillet_radius))
    })
}

/// A root section at one face station: Gauss points along the chord between the central
/// tooth's fillet mid points as (element, natural point, weight, s in [0, 1] from side A),
/// the section's normal (radial at the chord's middle) and its middle.
struct RootSection {
    points: Vec<(usize, [f64; 3], f64, f64)>,
    normal: [f64; 3],
    middle: [f64; 3],
}

impl LoadedSector {
    /// Body-frame point of element e at natural point xi, m.
    fn point(&self, e: usize, xi: [f64; 3]) -> [f64; 3] {
        let m = &self.kept.sector.mesh;
        let (n, _) = shape(xi);
        std::array::from_fn(|d| {
            m.elements[e]
                .iter()
                .zip(n)
                .map(|(&k, w)| w * m.nodes[k][d])
                .sum()
        })
    }

    /// The root section at face coordinate z (in the layer holding it; the tooth block's first
    /// row's bottom faces span the chord), 3 Gauss points per element.
    fn section(&self, z: f64) -> Option<RootSection> {
        let lz = &self.kept.sector.layer_z;
        let last = lz.len() - 2;
        let li = lz
            .iter()
            .position(|&v| v > z)
            .map_or(last, |i| i.saturating_sub(1).min(last));
        let zeta = (2.0 * (z - lz[li]) / (lz[li + 1] - lz[li]) - 1.0).clamp(-1.0, 1.0);
        let row = &self.kept.sector.root_section[li];
        let (&first, &last) = (row.first()?, row.last()?);
        let (pa, pb) = (
            self.point(first, [-1.0, -1.0, zeta]),
            self.point(last, [1.0, -1.0, zeta]),
        );
        let chord: [f64; 3] = std::array::from_fn(|d| pb[d] - pa[d]);
        let length2: f64 = chord.iter().map(|c| c * c).sum();
        let along = |x: [f64; 3]| (0..3).map(|d| (x[d] - pa[d]) * chord[d]).sum::<f64>() / length2;
        let middle: [f64; 3] = std::array::from_fn(|d| 0.5 * (pa[d] + pb[d]));
        let radius = middle[0].hypot(middle[1]);
        let g = (0.6f64).sqrt();
        let mut points = Vec::new();
        for &e in row {
            let (s0, s1) = (
                along(self.point(e, [-1.0, -1.0, zeta])),
                along(self.point(e, [1.0, -1.0, zeta])),
            );
            for (a, w) in [(-g, 5.0 / 18.0), (0.0, 8.0 / 18.0), (g, 5.0 / 18.0)] {
                let xi = [a, -1.0, zeta];
                points.push((e, xi, w * (s1 - s0), along(self.point(e, xi))));
            }
        }
        Some(RootSection {
            points,
            normal: [middle[0] / radius, middle[1] / radius, 0.0],
            middle,
        })
    }

    /// The linearised stress of a section under the displacements `u` (ASME BPVC VIII-2
    /// Annex 5-A stress linearisation): the normal stress's membrane part sigma_m = mean of
    /// sigma and bending part sigma_b = 6 mean of sigma (s - 1/2); returns (sigma_m, sigma_b),
    /// Pa.
    fn linearised(&self, u: &[[f64; 3]], section: &RootSection) -> Result<(f64, f64), FeError> {
        let n = section.normal;
        let (mut membrane, mut bending) = (0.0, 0.0);
        for &(e, xi, w, s) in &section.points {
            let t = element_stress(&self.kept.sector.mesh, e, &self.material, u, xi)?;
            let sigma = [[t[0], t[5], t[4]], [t[5], t[1], t[3]], [t[4], t[3], t[2]]];
            let normal: f64 = (0..3)
                .map(|i| (0..3).map(|j| n[i] * sigma[i][j] * n[j]).sum::<f64>())
                .sum();
            membrane += w * normal;
            bending += 6.0 * w * normal * (s - 0.5);
        }
        Ok((membrane, bending))
    }

    /// The linearised root stress sigma_m + |sigma_b| (the larger extreme fibre) of the
    /// central tooth at [`ROOT_STATIONS`] + 1 face stations evenly spread between the face ends
    /// (fixed places whatever the mesh), over every load case; stations nearer a face end than
    /// `edge` (m) go to the face-end reading.
    pub fn root_stresses(&self, edge: f64) -> Result<RootStresses, FeError> {
        let lz = &self.kept.sector.layer_z;
        let (z_lo, z_hi) = (lz[0], lz[lz.len() - 1]);
        let (mut interior, mut face_ends) = (RootStress::NONE, RootStress::NONE);
        for k in 0..=ROOT_STATIONS {
            let z = z_lo + (z_hi - z_lo) * k as f64 / ROOT_STATIONS as f64;
            let Some(section) = self.section(z) else {
                continue;
            };
            let best = if z < z_lo + edge || z > z_hi - edge {
                &mut face_ends
            } else {
                &mut interior
            };
            for (u, &(position, tooth)) in self.solutions.iter().zip(&self.labels) {
                let (membrane, bending) = self.linearised(u, &section)?;
                let value = membrane + bending.abs();
                if value > best.stress {
                    let c = section.middle;
                    *best = RootStress {
                        stress: value,
                        position,
                        tooth,
                        r: c[0].hypot(c[1]),
                        z: c[2],
                        tension_on_loaded_side: (bending < 0.0) == (self.side == Side::A),
                    };
                }
            }
        }
        Ok(RootStresses {
            interior,
            face_ends,
        })
    }
}
