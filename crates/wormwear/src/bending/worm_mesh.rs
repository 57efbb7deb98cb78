//! Finite-element mesh of the worm: a bored core (root radius over the worm body, shaft radius
//! beyond it, out past both bearings) carrying three threads (the loaded one and its two axial
//! neighbours), built from the generated thread surface (MODEL §5.5 step 1).
//!
//! Helical sweep. A helicoid is invariant under the screw motion (x, phi) -> (x + h t, phi + t),
//! so with the helical coordinate s = x - hand h phi every meridian section (rho, s) is the same
//! plane figure: per axial pitch, a core strip (bore to root) split across into half space,
//! thread foot and half space, and a thread block between the two flank profiles X(rho) from
//! the root to the tip radius. The section's quadratic lattice is swept over phi in [-pi, pi];
//! the seam phi = +pi is glued to phi = -pi, where the lattice is shifted by one lead
//! (s + hand p_z), so the core is closed between the bearings (the seam stays open only within
//! a lead of the two far ends of the mesh, which lie beyond the bearings and carry no load).
//! The body ends are helical, as a thread run-out. Nodes are keyed by their lattice indices
//! (not by coordinates), so the glueing is exact.
//!
//! A small bore (a quarter of the shaft radius; 0.4 % of the second moment of area) keeps the
//! hexahedra off the axis. Frame: thread frame of the worm at rotation 0 (x1 the axis, y1
//! towards the wheel centre), m.

use super::fe::{centre_jacobian, mirrored, Mesh, NATURAL};
use crate::geometry::{Flank, ThreadSurface};
use std::collections::HashMap;
use std::f64::consts::PI;

/// Mesh sizes of the worm model (`layers` and `height` are targets: the lattice aligns the
/// element boundaries with the basis fit grid, [`WormLattice::aligned`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct WormMeshSettings {
    /// Elements around the axis (one full turn).
    pub layers: usize,
    /// Elements across each thread.
    pub across: usize,
    /// Elements along the thread height.
    pub height: usize,
    /// Elements across each half tooth space, in the core.
    pub space: usize,
    /// Radial elements from the shaft radius to the root radius (when the shaft is thinner).
    pub core: usize,
    /// Radial elements from the bore to the shaft radius.
    pub inner: usize,
}

/// Layer angles and thread radii of the lattice: element boundaries aligned with the fit grid
/// of the bending basis, so its points are corner nodes (fitting through points off the grid
/// makes the interpolation between them oscillate).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct WormLattice {
    /// Layer boundaries phi from -pi to pi, increasing, rad.
    pub phi: Vec<f64>,
    /// Element boundaries along the thread height as fractions from the root (0) to the tip (1).
    pub height: Vec<f64>,
}

impl WormLattice {
    /// Uniform layers (about `settings.layers` around) and heights (`settings.height`).
    pub fn uniform(settings: &WormMeshSettings) -> Self {
        let n = settings.layers.max(4);
        let h = settings.height.max(1);
        Self {
            phi: (0..=n)
                .map(|i| -PI + 2.0 * PI * i as f64 / n as f64)
                .collect(),
            height: (0..=h).map(|i| i as f64 / h as f64).collect(),
        }
    }

    /// Layers with corners at phi = -theta_m + 2 theta_m b / (2 (q2 - 1)) (b = 0..2 q2 - 1) and
    /// heights with corners at 0.1 + 0.8 a / (q1 - 1) (MODEL §5.5: r_f + 0.1 H to r_a - 0.1 H):
    /// the fit points and, across the width, the points midway between them are corner nodes.
    /// Away from the zone, layers about twice the size `settings.layers` gives.
    pub fn aligned(settings: &WormMeshSettings, theta_m: f64, q1: usize, q2: usize) -> Self {
        let theta_m = theta_m.clamp(0.05, 0.45 * PI);
        // Two elements per fit interval: corners midway between the fit points carry the
        // extra data of the least-squares fit.
        let per_w = 2;
        let n_zone = per_w * (q2.max(2) - 1);
        // The back of the worm (no loads) only carries the shaft's bending and torsion.
        let back_target = settings.layers.max(4) as f64 * (1.0 - theta_m / PI) / 2.0;
        let n_back = ((back_target / 2.0).round() as usize).max(2);
        let mut phi = Vec::new();
        for i in 0..n_back {
            phi.push(-PI + (PI - theta_m) * i as f64 / n_back as f64);
        }
        for i in 0..n_zone {
            phi.push(-theta_m + 2.0 * theta_m * i as f64 / n_zone as f64);
        }
        for i in 0..=n_back {
            phi.push(theta_m + (PI - theta_m) * i as f64 / n_back as f64);
        }
        let n_h = q1.max(2) - 1;
        let mut height = vec![0.0];
        for i in 0..=n_h {
            height.push(0.1 + 0.8 * i as f64 / n_h as f64);
        }
        height.push(1.0);
        Self { phi, height }
    }
}

/// Worm body dimensions and supports, m (thread frame, x along the axis).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct WormBody {
    pub root_radius: f64,
    pub tip_radius: f64,
    /// Radius of the shaft beyond the body (<= root radius).
    pub shaft_radius: f64,
    /// Half length of the body at root radius (|s| <= this, s the helical coordinate).
    pub body_half_length: f64,
    /// Bearing planes x; the first is on the drive side (torque and thrust taken beyond it).
    pub bearings: [f64; 2],
}

/// The worm mesh and what the bending stage needs to know about it.
#[derive(Debug, Clone)]
pub struct WormMesh {
    pub mesh: Mesh,
    /// Per thread (-1, 0, 1): nodes of the loaded flank as (half-layer index, height half-index
    /// from the root, node). Half-layer li sits at phi = -pi + li pi / layers.
    pub loaded: Vec<Vec<(usize, usize, usize)>>,
    /// Per thread: nodes of the opposite flank, same layout.
    pub opposite: Vec<Vec<(usize, usize, usize)>>,
    /// Outer shaft-surface nodes in each bearing plane (one per half-layer).
    pub bearing_rings: [Vec<usize>; 2],
    /// Outer shaft-surface nodes of the drive-side ring beyond the first bearing (the coupling:
    /// torque and thrust reaction).
    pub drive_ring: Vec<usize>,
    /// Half-layers around the axis (2 x layers).
    pub half_layers: usize,
    /// Height half-steps of the thread (2 x height).
    pub height_steps: usize,
}

/// Builds the worm mesh with uniform layers. `loaded` is the flank the wheel pushes on.
pub fn worm_mesh(
    thread: &ThreadSurface,
    loaded: Flank,
    body: &WormBody,
    settings: &WormMeshSettings,
) -> WormMesh {
    worm_mesh_on(
        thread,
        loaded,
        body,
        settings,
        &WormLattice::uniform(settings),
    )
}

/// The worm's lattice mapped onto the thread: the node of lattice point (ri radial, si along
/// the helical coordinate, li half-layer around the axis) and its position (thread frame, m).
struct ThreadLattice<'a> {
    thread: &'a ThreadSurface,
    lattice: &'a WormLattice,
    body: &'a WormBody,
    /// Axial pitch, lead (m), hand (+-1) and lead / 2 pi.
    p: f64,
    lead: f64,
    hand: f64,
    h: f64,
    n_layers: usize,
    half_layers: usize,
    /// The flank at smaller s first, of thread 0.
    low_flank: Flank,
    high_flank: Flank,
    shaft: f64,
    bore: f64,
    /// Elements in the core, inside the shaft, along the thread height, per half space and
    /// across the thread.
    n_core: usize,
    n_in: usize,
    n_h: usize,
    n_sp: usize,
    n_ac: usize,
    /// Radial indices of the shaft surface and of the root.
    ri_shaft: usize,
    ri_root: usize,
    /// Half-steps per pitch.
    m2: usize,
    /// Axial positions of the two flanks at the root radius, m.
    xl_f: f64,
    xr_f: f64,
    /// The seam: (ri, si, 2N) is (ri, si + shift, 0).
    shift: i64,
}

impl<'a> ThreadLattice<'a> {
    fn new(
        thread: &'a ThreadSurface,
        body: &'a WormBody,
        settings: &WormMeshSettings,
        lattice: &'a WormLattice,
    ) -> Self {
        let p = thread.axial_pitch();
        let lead = thread.lead();
        let hand = thread.hand_sign();
        let n_layers = lattice.phi.len() - 1;
        let xa = |flank: Flank, rho: f64| thread.axial_profile(flank, rho).0;
        let (low_flank, high_flank) =
            if xa(Flank::Left, body.root_radius) < xa(Flank::Right, body.root_radius) {
                (Flank::Left, Flank::Right)
            } else {
                (Flank::Right, Flank::Left)
            };
        let shaft = body.shaft_radius.min(body.root_radius);
        let n_core = if shaft < body.root_radius {
            settings.core.max(1)
        } else {
            0
        };
        let (n_in, n_sp, n_ac) = (
            settings.inner.max(1),
            settings.space.max(1),
            settings.across.max(1),
        );
        let ri_shaft = 2 * n_in;
        let m2 = 2 * (2 * n_sp + n_ac);
        Self {
            thread,
            lattice,
            body,
            p,
            lead,
            hand,
            h: lead / (2.0 * PI),
            n_layers,
            half_layers: 2 * n_layers,
            low_flank,
            high_flank,
            shaft,
            bore: 0.25 * shaft,
            n_core,
            n_in,
            n_h: lattice.height.len() - 1,
            n_sp,
            n_ac,
            ri_shaft,
            ri_root: ri_shaft + 2 * n_core,
            m2,
            xl_f: xa(low_flank, body.root_radius),
            xr_f: xa(high_flank, body.root_radius),
            shift: (hand * (lead / p).round()) as i64 * m2 as i64,
        }
    }

    /// Axial position of a flank of thread 0 at radius rho, m.
    fn xa(&self, flank: Flank, rho: f64) -> f64 {
        self.thread.axial_profile(flank, rho).0
    }

    /// Radius of radial index ri: bore to shaft, shaft to root, root to tip on the lattice's
    /// heights, m.
    fn rho_of(&self, ri: usize) -> f64 {
        let (body, shaft, bore) = (self.body, self.shaft, self.bore);
        let (ri_shaft, ri_root) = (self.ri_shaft, self.ri_root);
        if ri <= ri_shaft {
            bore + (shaft - bore) * ri as f64 / ri_shaft as f64
        } else if ri <= ri_root {
            shaft
                + (body.root_radius - shaft) * (ri - ri_shaft) as f64 / (ri_root - ri_shaft) as f64
        } else {
            let height = &self.lattice.height;
            let t = (ri - ri_root) as f64 / 2.0;
            let (i, f) = (t.floor() as usize, t.fract());
            let frac = if i >= self.n_h {
                1.0
            } else {
                height[i] + (height[i + 1] - height[i]) * f
            };
            body.root_radius + (body.tip_radius - body.root_radius) * frac
        }
    }

    /// Helical coordinate s of lattice node (ri, si), m.
    fn s_of(&self, ri: usize, si: i64) -> f64 {
        let (p, m2) = (self.p, self.m2);
        let (xl_f, xr_f) = (self.xl_f, self.xr_f);
        let j = si.div_euclid(m2 as i64);
        let loc = si.rem_euclid(m2 as i64) as usize;
        let base = j as f64 * p;
        let (a0, a1) = (2 * self.n_sp, 2 * self.n_sp + 2 * self.n_ac);
        if loc < a0 {
            base - 0.5 * p + (xl_f + 0.5 * p) * loc as f64 / a0 as f64
        } else if loc <= a1 {
            let rho = self.rho_of(ri);
            let (xl, xr) = if ri > self.ri_root {
                (self.xa(self.low_flank, rho), self.xa(self.high_flank, rho))
            } else {
                (xl_f, xr_f)
            };
            base + xl + (xr - xl) * (loc - a0) as f64 / (a1 - a0) as f64
        } else {
            base + xr_f + (0.5 * p - xr_f) * (loc - a1) as f64 / (m2 - a1) as f64
        }
    }

    /// Angle of half-layer li about the axis, rad.
    fn phi_of(&self, li: usize) -> f64 {
        let phi = &self.lattice.phi;
        let (i, odd) = (li / 2, li % 2 == 1);
        if i >= self.n_layers {
            PI
        } else if odd {
            0.5 * (phi[i] + phi[i + 1])
        } else {
            phi[i]
        }
    }

    /// Position of lattice node (ri, si, li), thread frame, m.
    fn position(&self, ri: usize, si: i64, li: usize) -> [f64; 3] {
        let (rho, phi) = (self.rho_of(ri), self.phi_of(li));
        [
            self.s_of(ri, si) + self.hand * self.h * phi,
            rho * phi.cos(),
            rho * phi.sin(),
        ]
    }

    /// The lattice point the seam glues (ri, si, li) to.
    fn canonical(&self, ri: usize, si: i64, li: usize) -> (usize, i64, usize) {
        if li == self.half_layers {
            (ri, si + self.shift, 0)
        } else {
            (ri, si, li)
        }
    }
}

/// The mesh's nodes by lattice point, added when first used.
#[derive(Default)]
struct LatticeNodes {
    points: Vec<[f64; 3]>,
    index: HashMap<(usize, i64, usize), usize>,
}

impl LatticeNodes {
    fn at(&mut self, lattice: &ThreadLattice, ri: usize, si: i64, li: usize) -> usize {
        let key = lattice.canonical(ri, si, li);
        let points = &mut self.points;
        *self.index.entry(key).or_insert_with(|| {
            points.push(lattice.position(key.0, key.1, key.2));
            points.len() - 1
        })
    }

    fn find(&self, lattice: &ThreadLattice, ri: usize, si: i64, li: usize) -> Option<usize> {
        self.index.get(&lattice.canonical(ri, si, li)).copied()
    }
}

/// The threads of the model: the central one and its two neighbours.
const THREADS: [i64; 3] = [-1, 0, 1];

/// Builds the worm mesh on the given lattice (layers and thread heights); `settings` gives
/// the element counts across and in the core.
pub fn worm_mesh_on(
    thread: &ThreadSurface,
    loaded: Flank,
    body: &WormBody,
    settings: &WormMeshSettings,
    lattice: &WormLattice,
) -> WormMesh {
    let t = ThreadLattice::new(thread, body, settings, lattice);
    let (p, lead, m2) = (t.p, t.lead, t.m2);
    let mut nodes = LatticeNodes::default();
    // Pitches spanned: the bearings with 2 leads and a pitch of margin on the outside (the
    // drive ring, half a lead out, must lie where the seam is glued).
    let x_lo = body.bearings[0].min(body.bearings[1]) - 2.0 * lead - p;
    let x_hi = body.bearings[0].max(body.bearings[1]) + 2.0 * lead + p;
    let j_lo = (x_lo / p).floor() as i64;
    let j_hi = (x_hi / p).ceil() as i64;
    let mut elements = Vec::new();
    for j in j_lo..j_hi {
        let si0 = j * m2 as i64;
        let body_pitch = (j as f64 * p).abs() <= body.body_half_length;
        add_block(&t, &mut nodes, &mut elements, (0, t.n_in), (si0, m2 / 2));
        if body_pitch && t.n_core > 0 {
            add_block(
                &t,
                &mut nodes,
                &mut elements,
                (t.ri_shaft, t.n_core),
                (si0, m2 / 2),
            );
        }
        if THREADS.contains(&j) && body_pitch {
            let across = (si0 + 2 * t.n_sp as i64, t.n_ac);
            add_block(&t, &mut nodes, &mut elements, (t.ri_root, t.n_h), across);
        }
    }
    for e in &mut elements {
        let x: [[f64; 3]; 20] = std::array::from_fn(|a| nodes.points[e[a]]);
        if centre_jacobian(&x) < 0.0 {
            *e = mirrored(*e);
        }
    }
    let (loc_low, loc_high) = (2 * t.n_sp, 2 * t.n_sp + 2 * t.n_ac);
    let (loc_loaded, loc_opposite) = if loaded == t.low_flank {
        (loc_low, loc_high)
    } else {
        (loc_high, loc_low)
    };
    let outward = if body.bearings[0] < body.bearings[1] {
        -1.0
    } else {
        1.0
    };
    WormMesh {
        loaded: flank_nodes(&t, &nodes, loc_loaded),
        opposite: flank_nodes(&t, &nodes, loc_opposite),
        bearing_rings: [
            shaft_ring(&t, &nodes, body.bearings[0]),
            shaft_ring(&t, &nodes, body.bearings[1]),
        ],
        drive_ring: shaft_ring(&t, &nodes, body.bearings[0] + outward * 0.5 * lead),
        half_layers: t.half_layers,
        height_steps: 2 * t.n_h,
        mesh: Mesh {
            nodes: nodes.points,
            elements,
        },
    }
}

/// The elements of one block of one pitch on every layer: radial indices from `ri0` with `nr`
/// elements, helical from `si0` with `ns` elements.
fn add_block(
    t: &ThreadLattice,
    nodes: &mut LatticeNodes,
    elements: &mut Vec<[usize; 20]>,
    (ri0, nr): (usize, usize),
    (si0, ns): (i64, usize),
) {
    for l in 0..t.n_layers {
        for ir in 0..nr {
            for is in 0..ns {
                let mut e = [0usize; 20];
                for (a, c) in NATURAL.iter().enumerate() {
                    let si = si0 + (2 * is) as i64 + 1 + c[0] as i64;
                    let ri = (ri0 as i64 + (2 * ir) as i64 + 1 + c[1] as i64) as usize;
                    let li = (2 * l as i64 + 1 + c[2] as i64) as usize;
                    e[a] = nodes.at(t, ri, si, li);
                }
                elements.push(e);
            }
        }
    }
}

/// Per thread, the flank nodes at helical offset `loc` in the pitch: (half-layer, height
/// half-index from the root, node).
fn flank_nodes(
    t: &ThreadLattice,
    nodes: &LatticeNodes,
    loc: usize,
) -> Vec<Vec<(usize, usize, usize)>> {
    THREADS
        .iter()
        .map(|&j| {
            let mut out = Vec::new();
            for li in 0..t.half_layers {
                for hi in 0..=2 * t.n_h {
                    if let Some(id) =
                        nodes.find(t, t.ri_root + hi, j * t.m2 as i64 + loc as i64, li)
                    {
                        out.push((li, hi, id));
                    }
                }
            }
            out
        })
        .collect()
}

/// Outer shaft surface nodes nearest to the plane x = x0, one per half-layer.
fn shaft_ring(t: &ThreadLattice, nodes: &LatticeNodes, x0: f64) -> Vec<usize> {
    let (p, m2) = (t.p, t.m2 as i64);
    (0..t.half_layers)
        .filter_map(|li| {
            let phi = t.phi_of(li);
            let s_target = x0 - t.hand * t.h * phi;
            let j = (s_target / p).floor() as i64;
            ((j - 1) * m2..(j + 2) * m2)
                .filter_map(|si| nodes.find(t, t.ri_shaft, si, li).map(|id| (si, id)))
                .min_by(|a, b| {
                    let da = (t.s_of(t.ri_shaft, a.0) - s_target).abs();
                    let db = (t.s_of(t.ri_shaft, b.0) - s_target).abs();
                    da.total_cmp(&db)
                })
                .map(|(_, id)| id)
        })
        .collect()
}
