//! Finite-element mesh of the wheel: three teeth (the reference tooth and its two neighbours)
//! standing on a rim, built from the generated flank grids (MODEL §5.5 step 1), optionally with
//! the rest of the ring and the web down to the hub.
//!
//! Layers along the face width are node columns of the global flank grid (every `face_step`-th,
//! plus the last), so the flanks are exact there (Hermite theta_w along the column). In each
//! layer, the section in (r, theta) is split into blocks:
//! - the rim, from its inner radius up to the root circle (cut by the hob tip), across the whole
//!   sector, with theta nodes that match the teeth above them;
//! - each tooth, from the root circle to the blank top, between its two flanks; below the flank
//!   bottom (the fillet, not resolved) the boundary continues radially to the root;
//! - with [`WebSettings`] (the bending stage's default), the whole ring: the rim continued round
//!   the wheel from one side cut of the three teeth to the other (graded elements), and the
//!   web under every rim block down to the hub radius, in the layers within the web thickness.
//!
//! Nodes are placed on a half-step lattice of each block's mapping (mid-side nodes follow the
//! curved flanks), and coincident nodes of neighbouring blocks are merged.
//! Coordinates: wheel body frame, m.

use super::fe::{Mesh, NATURAL};
use crate::geometry::placement::wheel_point;
use crate::geometry::{Flank, Geometry, WheelFlank};
use std::collections::HashMap;
use std::f64::consts::PI;

/// Mesh sizes.
#[derive(Debug, Clone, Copy)]
pub struct SectorMeshSettings {
    /// Elements across each tooth.
    pub across: usize,
    /// Elements along the tooth height (root circle to top).
    pub height: usize,
    /// Elements through the rim thickness.
    pub rim: usize,
    /// Elements across each half tooth space in the rim.
    pub space: usize,
    /// Use every `face_step`-th node column of the flank grid as a layer.
    pub face_step: usize,
    /// Rim thickness below the root at the median plane, m.
    pub rim_thickness: f64,
    /// The whole ring (rim all round, web down to the hub, clamped there); None: a three-tooth
    /// sector clamped at the rim's inner surface, side cuts free.
    pub web: Option<WebSettings>,
}

/// The wheel's body below the three teeth: the rim continued all round the wheel (no teeth
/// there) and the web, a disk of the given thickness centred on the median plane, from the
/// rim's inner surface down to the hub radius, where it is clamped (the hub is thick and taken
/// as rigid; its motion on the shaft is added by [`super::wheel_shaft`]).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct WebSettings {
    /// Thickness along the wheel axis, m (rounded to the layers of the mesh; at least the
    /// layer or two nearest the median plane, however thin).
    pub thickness: f64,
    /// Hub radius, m.
    pub hub_radius: f64,
    /// Elements from the rim to the hub.
    pub elements: usize,
    /// Elements around the rest of the ring (the 2 pi - 3 tau outside the three teeth), graded:
    /// a quarter of the mean size next to the teeth, 1.75 times it opposite them.
    pub rest_elements: usize,
}

/// The sector mesh and what the bending stage needs to know about it.
#[derive(Debug, Clone)]
pub struct SectorMesh {
    pub mesh: Mesh,
    /// Nodes to clamp: the rim's inner surface, or the hub surface of the web (whole ring).
    pub inner: Vec<usize>,
    /// Nodes on the two side cuts of the sector (none for the whole ring).
    pub sides: Vec<usize>,
    /// Per tooth (-1, 0, 1): flank nodes of the left-mating flank as (layer, height index, node).
    pub left_flank: Vec<Vec<(usize, usize, usize)>>,
    /// Per tooth: nodes of the right-mating (opposite) flank, same layout.
    pub right_flank: Vec<Vec<(usize, usize, usize)>>,
    /// Node column of the flank grid of each layer.
    pub layer_columns: Vec<usize>,
    /// Root radius at the median plane, m.
    pub root_radius: f64,
}

/// Blocks of a layer's section: 0..3 the teeth, 3..6 the rim under them, 6..10 the rim under
/// the spaces, REST the rest of the ring, REST + 1.. the web under the rim blocks 3..=REST.
const REST: usize = 10;
const WEB_SHIFT: usize = REST - 2;
/// The teeth of the sector: the reference tooth and its two neighbours.
const TEETH: [i32; 3] = [-1, 0, 1];

/// The section of every layer in (r, theta): each block's mapping from its parameters (u across,
/// v radial, both in [0, 1]) and its element counts.
struct Sections<'a> {
    l: &'a WheelFlank,
    r: &'a WheelFlank,
    settings: &'a SectorMeshSettings,
    /// Angular pitch, rad.
    tau: f64,
    hob_tip: f64,
    cutting_centre_distance: f64,
    /// Rim's inner radius, m.
    r_in: f64,
    web: Option<WebSettings>,
}

impl Sections<'_> {
    /// Root circle at z (hob tip torus), m.
    fn root_at(&self, z: f64) -> f64 {
        self.cutting_centre_distance - (self.hob_tip * self.hob_tip - z * z).max(0.0).sqrt()
    }

    /// theta of the left-mating flank of space k on column j at radius rr, continued radially
    /// below the flank bottom.
    fn th_left(&self, j: usize, rr: f64, k: i32) -> f64 {
        let l = self.l;
        l.column_theta(j, rr.max(l.r_low[j])).0 + k as f64 * self.tau
    }

    /// theta of the right-mating flank of space k + 1 (tooth k spans between the two).
    fn th_right(&self, j: usize, rr: f64, k: i32) -> f64 {
        let r = self.r;
        r.column_theta(j, rr.max(r.r_low[j])).0 + (k + 1) as f64 * self.tau
    }

    /// (r, theta) of block `block` at (u, v) on column j: the web, the rest of the ring, or the
    /// sector's blocks.
    fn section(&self, j: usize, block: usize, u: f64, v: f64) -> (f64, f64) {
        match (block, self.web) {
            (b, Some(w)) if b > REST => {
                let (_, th) = self.ring(j, b - WEB_SHIFT, u, 0.0);
                (w.hub_radius + (self.r_in - w.hub_radius) * v, th)
            }
            (b, _) => self.ring(j, b, u, v),
        }
    }

    /// Whole ring: block REST is the rim from the right side cut (mid space 1/2) round to the
    /// left one (mid space -2/-1) plus 2 pi, graded (u -> u - A sin(2 pi u) / (2 pi)).
    fn ring(&self, j: usize, block: usize, u: f64, v: f64) -> (f64, f64) {
        match block {
            REST => {
                let root = self.root_at(self.l.z[j]);
                let rr = self.r_in + (root - self.r_in) * v;
                let a = 0.5 * (self.th_right(j, root, 1) + self.th_left(j, root, 2));
                let c = 0.5 * (self.th_right(j, root, -2) + self.th_left(j, root, -1));
                let th = if u >= 1.0 {
                    c
                } else {
                    let g = u - 0.75 * (2.0 * PI * u).sin() / (2.0 * PI);
                    a + (c + 2.0 * PI - a) * g
                };
                (rr, th)
            }
            b => self.sector(j, b, u, v),
        }
    }

    /// The sector's blocks: the teeth, the rim under them and under the spaces.
    fn sector(&self, j: usize, block: usize, u: f64, v: f64) -> (f64, f64) {
        let z = self.l.z[j];
        let root = self.root_at(z);
        let top = self.l.r_high[j].min(self.r.r_high[j]);
        match block {
            // Teeth: blocks 0..3.
            b if b < 3 => {
                let k = TEETH[b];
                let rr = root + (top - root) * v;
                let (a, c) = (self.th_left(j, rr, k), self.th_right(j, rr, k));
                (rr, a + (c - a) * u)
            }
            // Rim under the teeth: blocks 3..6 (theta nodes match the tooth feet).
            b if b < 6 => {
                let k = TEETH[b - 3];
                let rr = self.r_in + (root - self.r_in) * v;
                let (a, c) = (self.th_left(j, root, k), self.th_right(j, root, k));
                (rr, a + (c - a) * u)
            }
            // Rim under the spaces: block 6 + s for s = 0..4: left half of space -1, spaces
            // between teeth (-1/0, 0/1) and right half of space 2.
            b => {
                let s = b - 6;
                let rr = self.r_in + (root - self.r_in) * v;
                let (a, c) = match s {
                    0 => (
                        0.5 * (self.th_right(j, root, -2) + self.th_left(j, root, -1)),
                        self.th_left(j, root, -1),
                    ),
                    1 => (self.th_right(j, root, -1), self.th_left(j, root, 0)),
                    2 => (self.th_right(j, root, 0), self.th_left(j, root, 1)),
                    _ => (
                        self.th_right(j, root, 1),
                        0.5 * (self.th_right(j, root, 1) + self.th_left(j, root, 2)),
                    ),
                };
                (rr, a + (c - a) * u)
            }
        }
    }

    /// Elements of a block (around, radial).
    fn dims(&self, block: usize) -> (usize, usize) {
        let settings = self.settings;
        let rest = self.web.map_or(1, |w| w.rest_elements.max(2));
        let around = |b: usize| match b {
            b if b < 6 => settings.across,
            REST => rest,
            _ => settings.space,
        };
        match block {
            b if b < 3 => (settings.across, settings.height),
            b if b <= REST => (around(b), settings.rim),
            b => (
                around(b - WEB_SHIFT),
                self.web.map_or(1, |w| w.elements.max(1)),
            ),
        }
    }

    /// Body-frame point of block `block` at (u, v) on column j, m.
    fn point(&self, j: usize, block: usize, u: f64, v: f64) -> [f64; 3] {
        let (rr, th) = self.section(j, block, u, v);
        let p = wheel_point(rr, th, self.l.z[j], 0.0);
        [p.x, p.y, p.z]
    }
}

/// Nodes merged where they coincide (to a nanometre).
#[derive(Default)]
pub(super) struct Nodes {
    pub(super) points: Vec<[f64; 3]>,
    index: HashMap<(i64, i64, i64), usize>,
}

impl Nodes {
    fn key(p: [f64; 3]) -> (i64, i64, i64) {
        (
            (p[0] * 1e9).round() as i64,
            (p[1] * 1e9).round() as i64,
            (p[2] * 1e9).round() as i64,
        )
    }

    /// The node at p, added when new.
    pub(super) fn at(&mut self, p: [f64; 3]) -> usize {
        let points = &mut self.points;
        *self.index.entry(Self::key(p)).or_insert_with(|| {
            points.push(p);
            points.len() - 1
        })
    }

    /// The node at p if there is one.
    fn find(&self, p: [f64; 3]) -> Option<usize> {
        self.index.get(&Self::key(p)).copied()
    }
}

/// What the element loop gathers besides the elements: the clamped and side-cut nodes and the
/// flank nodes of each tooth.
#[derive(Default)]
struct Marks {
    inner: Vec<usize>,
    sides: Vec<usize>,
    left_flank: Vec<Vec<(usize, usize, usize)>>,
    right_flank: Vec<Vec<(usize, usize, usize)>>,
}

/// Builds the sector mesh of the wheel from its flank grids.
pub fn sector_mesh(
    geo: &Geometry,
    settings: &SectorMeshSettings,
    hob_tip: f64,
    cutting_centre_distance: f64,
) -> SectorMesh {
    let l = geo.wheel_flank(Flank::Left);
    let nj = l.cells_face;
    let mut layers: Vec<usize> = (0..=nj).step_by(settings.face_step.max(1)).collect();
    if *layers.last().unwrap_or(&0) != nj {
        layers.push(nj);
    }
    let mut sections = Sections {
        l,
        r: geo.wheel_flank(Flank::Right),
        settings,
        tau: 2.0 * PI / geo.teeth as f64,
        hob_tip,
        cutting_centre_distance,
        r_in: 0.0,
        web: None,
    };
    let root0 = sections.root_at(0.0);
    sections.r_in = root0 - settings.rim_thickness;
    sections.web = settings
        .web
        .filter(|w| w.hub_radius < sections.r_in && w.thickness > 0.0);
    let mut nodes = Nodes::default();
    let mut marks = Marks {
        left_flank: vec![Vec::new(); 3],
        right_flank: vec![Vec::new(); 3],
        ..Default::default()
    };
    let mut elements = Vec::new();
    let web_layers = web_layers(&sections, &layers);
    for (li, win) in layers.windows(2).enumerate() {
        let blocks = match (sections.web, web_layers[li]) {
            (None, _) => REST,
            (Some(_), false) => REST + 1,
            (Some(_), true) => 2 * REST - 1,
        };
        for block in 0..blocks {
            layer_block(
                &sections,
                (li, win[0], win[1]),
                block,
                &mut nodes,
                &mut marks,
                &mut elements,
            );
        }
    }
    marks.inner.sort_unstable();
    marks.inner.dedup();
    marks.sides.sort_unstable();
    marks.sides.dedup();
    last_layer_flanks(&sections, &layers, &nodes, &mut marks);
    for f in marks
        .left_flank
        .iter_mut()
        .chain(marks.right_flank.iter_mut())
    {
        f.sort_unstable();
        f.dedup();
    }
    SectorMesh {
        mesh: Mesh {
            nodes: nodes.points,
            elements,
        },
        inner: marks.inner,
        sides: marks.sides,
        left_flank: marks.left_flank,
        right_flank: marks.right_flank,
        layer_columns: layers,
        root_radius: root0,
    }
}

/// Whether each layer is in the web: those whose middle lies within half its thickness of the
/// median plane (the web's faces snap to layer boundaries), and at least the layer(s) nearest
/// that plane: a web thinner than a layer is modelled one layer thick (it snapped to none, and
/// the rim, joined to the hub by nothing, made the stiffness matrix singular).
fn web_layers(sections: &Sections, layers: &[usize]) -> Vec<bool> {
    let l = sections.l;
    let middle = |j0: usize, j1: usize| (0.5 * (l.z[j0] + l.z[j1])).abs();
    let nearest = layers
        .windows(2)
        .map(|p| middle(p[0], p[1]))
        .fold(f64::INFINITY, f64::min);
    layers
        .windows(2)
        .map(|p| {
            sections.web.is_some_and(|w| {
                let m = middle(p[0], p[1]);
                m < 0.5 * w.thickness || m <= nearest * (1.0 + 1e-9)
            })
        })
        .collect()
}

/// The elements of one block of the layer between columns j0 and j1 (layer index li): nodes on
/// a half-step lattice of the block's mapping (mid-layer points the average of the two
/// layers' points at the same parameters: quadratic accuracy along z is enough for the
/// stiffness), with the clamped, side-cut and flank nodes marked.
fn layer_block(
    sections: &Sections,
    (li, j0, j1): (usize, usize, usize),
    block: usize,
    nodes: &mut Nodes,
    marks: &mut Marks,
    elements: &mut Vec<[usize; 20]>,
) {
    let web = sections.web;
    let (nu, nv) = sections.dims(block);
    for iv in 0..nv {
        for iu in 0..nu {
            let mut e = [0usize; 20];
            for (a, c) in NATURAL.iter().enumerate() {
                let (u, v, p) = lattice_point(c, (iu, iv), (nu, nv), |layer, u, v| {
                    sections.point([j0, j1][layer], block, u, v)
                });
                let id = nodes.at(p);
                e[a] = id;
                // Clamped: the hub (web bottom) with a web, else the rim's inner surface.
                let clamped = match web {
                    Some(_) => block > REST,
                    None => block >= 3,
                };
                if clamped && v == 0.0 {
                    marks.inner.push(id);
                }
                if web.is_none() && ((block == 6 && u == 0.0) || (block == 9 && u == 1.0)) {
                    marks.sides.push(id);
                }
                if c[2] < 0.0 {
                    let hi = (v * nv as f64 * 2.0).round() as usize;
                    if let (true, Some(flank)) = (u == 0.0, marks.left_flank.get_mut(block)) {
                        flank.push((li, hi, id));
                    }
                    if let (true, Some(flank)) = (u == 1.0, marks.right_flank.get_mut(block)) {
                        flank.push((li, hi, id));
                    }
                }
            }
            // (u, v, z) ~ (-x, -y, z) near the line of centres: right-handed.
            elements.push(e);
        }
    }
}

/// Natural node `c` of element (iu, iv) of a block of nu x nv elements between two layers:
/// its parameters (u, v) on the block's half-step lattice and its point, `point(layer, u, v)`
/// on the layer below (0) or above (1), or their mean at mid-layer. m.
pub(super) fn lattice_point(
    c: &[f64; 3],
    (iu, iv): (usize, usize),
    (nu, nv): (usize, usize),
    point: impl Fn(usize, f64, f64) -> [f64; 3],
) -> (f64, f64, [f64; 3]) {
    let u = (iu as f64 + 0.5 + 0.5 * c[0]) / nu as f64;
    let v = (iv as f64 + 0.5 + 0.5 * c[1]) / nv as f64;
    let p = if c[2] < 0.0 {
        point(0, u, v)
    } else if c[2] > 0.0 {
        point(1, u, v)
    } else {
        let (pa, pb) = (point(0, u, v), point(1, u, v));
        [
            (pa[0] + pb[0]) / 2.0,
            (pa[1] + pb[1]) / 2.0,
            (pa[2] + pb[2]) / 2.0,
        ]
    };
    (u, v, p)
}

/// The last layer's flank nodes (far face) are not first corners of any element: registered
/// from the mapping.
fn last_layer_flanks(sections: &Sections, layers: &[usize], nodes: &Nodes, marks: &mut Marks) {
    let last = layers.len() - 1;
    let j = layers[last];
    for b in 0..3 {
        let nv = sections.dims(b).1;
        for hi in 0..=2 * nv {
            let v = hi as f64 / (2 * nv) as f64;
            for (u, flank) in [
                (0.0, &mut marks.left_flank[b]),
                (1.0, &mut marks.right_flank[b]),
            ] {
                if let Some(id) = nodes.find(sections.point(j, b, u, v)) {
                    flank.push((last, hi, id));
                }
            }
        }
    }
}
