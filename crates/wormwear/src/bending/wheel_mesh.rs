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
use crate::geometry::{Flank, Geometry};
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

/// Builds the sector mesh of the wheel from its flank grids.
pub fn sector_mesh(
    geo: &Geometry,
    settings: &SectorMeshSettings,
    hob_tip: f64,
    cutting_centre_distance: f64,
) -> SectorMesh {
    let l = geo.wheel_flank(Flank::Left);
    let r = geo.wheel_flank(Flank::Right);
    let tau = 2.0 * PI / geo.teeth as f64;
    let nj = l.cells_face;
    let mut layers: Vec<usize> = (0..=nj).step_by(settings.face_step.max(1)).collect();
    if *layers.last().unwrap_or(&0) != nj {
        layers.push(nj);
    }
    // Root circle at z (hob tip torus) and the rim's inner radius.
    let root_at = |z: f64| cutting_centre_distance - (hob_tip * hob_tip - z * z).max(0.0).sqrt();
    let root0 = root_at(0.0);
    let r_in = root0 - settings.rim_thickness;
    // theta of the left-mating flank of space k and of the right-mating flank of space k + 1
    // (tooth k spans between them), continued radially below the flank bottom.
    let th_left =
        |j: usize, rr: f64, k: i32| l.column_theta(j, rr.max(l.r_low[j])).0 + k as f64 * tau;
    let th_right =
        |j: usize, rr: f64, k: i32| r.column_theta(j, rr.max(r.r_low[j])).0 + (k + 1) as f64 * tau;
    let mut nodes: Vec<[f64; 3]> = Vec::new();
    let mut index: HashMap<(i64, i64, i64), usize> = HashMap::new();
    let mut node_at = |p: [f64; 3]| -> usize {
        let key = (
            (p[0] * 1e9).round() as i64,
            (p[1] * 1e9).round() as i64,
            (p[2] * 1e9).round() as i64,
        );
        *index.entry(key).or_insert_with(|| {
            nodes.push(p);
            nodes.len() - 1
        })
    };
    let mut elements = Vec::new();
    let mut inner = Vec::new();
    let mut sides = Vec::new();
    // Layers in the web: those whose middle lies within half its thickness of the median plane
    // (the web's faces snap to layer boundaries), and at least the layer(s) nearest that plane:
    // a web thinner than a layer is modelled one layer thick (it snapped to none, and the
    // rim, joined to the hub by nothing, made the stiffness matrix singular).
    let web = settings
        .web
        .filter(|w| w.hub_radius < r_in && w.thickness > 0.0);
    let middle = |j0: usize, j1: usize| (0.5 * (l.z[j0] + l.z[j1])).abs();
    let nearest = layers
        .windows(2)
        .map(|p| middle(p[0], p[1]))
        .fold(f64::INFINITY, f64::min);
    let in_web = |j0: usize, j1: usize| {
        web.is_some_and(|w| {
            let m = middle(j0, j1);
            m < 0.5 * w.thickness || m <= nearest * (1.0 + 1e-9)
        })
    };
    let mut left_flank = vec![Vec::new(); 3];
    let mut right_flank = vec![Vec::new(); 3];
    // Section point of a block at parameters (u across in [0, 1], v radial in [0, 1]) in layer
    // position w (fractional layer index, for the half-step between layers).
    let teeth = [-1i32, 0, 1];
    // Interpolate between two node columns for the mid-layer (half-step) points: layers are
    // node columns; a mid-layer point is the average of the two adjacent layers' points at the
    // same block parameters (quadratic accuracy along z is enough for the stiffness).
    let section = |j: usize, block: usize, u: f64, v: f64| -> (f64, f64) {
        let z = l.z[j];
        let root = root_at(z);
        let top = l.r_high[j].min(r.r_high[j]);
        match block {
            // Teeth: blocks 0..3.
            b if b < 3 => {
                let k = teeth[b];
                let rr = root + (top - root) * v;
                let (a, c) = (th_left(j, rr, k), th_right(j, rr, k));
                (rr, a + (c - a) * u)
            }
            // Rim under the teeth: blocks 3..6 (theta nodes match the tooth feet).
            b if b < 6 => {
                let k = teeth[b - 3];
                let rr = r_in + (root - r_in) * v;
                let (a, c) = (th_left(j, root, k), th_right(j, root, k));
                (rr, a + (c - a) * u)
            }
            // Rim under the spaces: block 6 + s for s = 0..4: left half of space -1, spaces
            // between teeth (-1/0, 0/1) and right half of space 2.
            b => {
                let s = b - 6;
                let rr = r_in + (root - r_in) * v;
                let (a, c) = match s {
                    0 => (
                        0.5 * (th_right(j, root, -2) + th_left(j, root, -1)),
                        th_left(j, root, -1),
                    ),
                    1 => (th_right(j, root, -1), th_left(j, root, 0)),
                    2 => (th_right(j, root, 0), th_left(j, root, 1)),
                    _ => (
                        th_right(j, root, 1),
                        0.5 * (th_right(j, root, 1) + th_left(j, root, 2)),
                    ),
                };
                (rr, a + (c - a) * u)
            }
        }
    };
    // Whole ring: block REST is the rim from the right side cut (mid space 1/2) round to the
    // left one (mid space -2/-1) plus 2 pi, graded (u -> u - A sin(2 pi u) / (2 pi)); web
    // blocks REST + 1 .. lie under the rim blocks 3 ..= REST, with their theta nodes.
    const REST: usize = 10;
    const WEB_SHIFT: usize = REST - 2;
    let section = |j: usize, block: usize, u: f64, v: f64| -> (f64, f64) {
        match block {
            REST => {
                let z = l.z[j];
                let root = root_at(z);
                let rr = r_in + (root - r_in) * v;
                let a = 0.5 * (th_right(j, root, 1) + th_left(j, root, 2));
                let c = 0.5 * (th_right(j, root, -2) + th_left(j, root, -1));
                let th = if u >= 1.0 {
                    c
                } else {
                    let g = u - 0.75 * (2.0 * PI * u).sin() / (2.0 * PI);
                    a + (c + 2.0 * PI - a) * g
                };
                (rr, th)
            }
            b => section(j, b, u, v),
        }
    };
    let section = |j: usize, block: usize, u: f64, v: f64| -> (f64, f64) {
        match (block, web) {
            (b, Some(w)) if b > REST => {
                let (_, th) = section(j, b - WEB_SHIFT, u, 0.0);
                (w.hub_radius + (r_in - w.hub_radius) * v, th)
            }
            (b, _) => section(j, b, u, v),
        }
    };
    let dims = |block: usize| -> (usize, usize) {
        let rest = web.map_or(1, |w| w.rest_elements.max(2));
        let around = |b: usize| match b {
            b if b < 6 => settings.across,
            REST => rest,
            _ => settings.space,
        };
        match block {
            b if b < 3 => (settings.across, settings.height),
            b if b <= REST => (around(b), settings.rim),
            b => (around(b - WEB_SHIFT), web.map_or(1, |w| w.elements.max(1))),
        }
    };
    for (li, win) in layers.windows(2).enumerate() {
        let (j0, j1) = (win[0], win[1]);
        let blocks = match (web, in_web(j0, j1)) {
            (None, _) => REST,
            (Some(_), false) => REST + 1,
            (Some(_), true) => 2 * REST - 1,
        };
        for block in 0..blocks {
            let (nu, nv) = dims(block);
            for iv in 0..nv {
                for iu in 0..nu {
                    let mut e = [0usize; 20];
                    for (a, c) in NATURAL.iter().enumerate() {
                        let u = (iu as f64 + 0.5 + 0.5 * c[0]) / nu as f64;
                        let v = (iv as f64 + 0.5 + 0.5 * c[1]) / nv as f64;
                        let point = |j: usize| {
                            let (rr, th) = section(j, block, u, v);
                            let p = wheel_point(rr, th, l.z[j], 0.0);
                            [p.x, p.y, p.z]
                        };
                        let p = if c[2] < 0.0 {
                            point(j0)
                        } else if c[2] > 0.0 {
                            point(j1)
                        } else {
                            let (pa, pb) = (point(j0), point(j1));
                            [
                                (pa[0] + pb[0]) / 2.0,
                                (pa[1] + pb[1]) / 2.0,
                                (pa[2] + pb[2]) / 2.0,
                            ]
                        };
                        let id = node_at(p);
                        e[a] = id;
                        // Bookkeeping: inner surface, side cuts, left flank of each tooth.
                        // Clamped: the hub (web bottom) with a web, else the rim's inner
                        // surface.
                        let clamped = match web {
                            Some(_) => block > REST,
                            None => block >= 3,
                        };
                        if clamped && v == 0.0 {
                            inner.push(id);
                        }
                        if web.is_none() && ((block == 6 && u == 0.0) || (block == 9 && u == 1.0)) {
                            sides.push(id);
                        }
                        if c[2] < 0.0 {
                            let hi = (v * nv as f64 * 2.0).round() as usize;
                            if let (true, Some(flank)) = (u == 0.0, left_flank.get_mut(block)) {
                                flank.push((li, hi, id));
                            }
                            if let (true, Some(flank)) = (u == 1.0, right_flank.get_mut(block)) {
                                flank.push((li, hi, id));
                            }
                        }
                    }
                    // (u, v, z) ~ (-x, -y, z) near the line of centres: right-handed.
                    let f = e;
                    elements.push(f);
                }
            }
        }
    }
    inner.sort_unstable();
    inner.dedup();
    sides.sort_unstable();
    sides.dedup();
    // The last layer's flank nodes (far face) are not first corners of any element: register
    // them from the mapping.
    let last = layers.len() - 1;
    for b in 0..3 {
        let j = layers[last];
        let nv = dims(b).1;
        for hi in 0..=2 * nv {
            let v = hi as f64 / (2 * nv) as f64;
            for (u, flank) in [(0.0, &mut left_flank[b]), (1.0, &mut right_flank[b])] {
                let (rr, th) = section(j, b, u, v);
                let p = wheel_point(rr, th, l.z[j], 0.0);
                let key = (
                    (p.x * 1e9).round() as i64,
                    (p.y * 1e9).round() as i64,
                    (p.z * 1e9).round() as i64,
                );
                if let Some(&id) = index.get(&key) {
                    flank.push((last, hi, id));
                }
            }
        }
    }
    for f in left_flank.iter_mut().chain(right_flank.iter_mut()) {
        f.sort_unstable();
        f.dedup();
    }
    SectorMesh {
        mesh: Mesh { nodes, elements },
        inner,
        sides,
        left_flank,
        right_flank,
        layer_columns: layers,
        root_radius: root0,
    }
}
