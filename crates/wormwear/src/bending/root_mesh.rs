//! Finite-element mesh of a three-tooth sector of the wheel with filleted tooth roots, for the
//! tooth root stress (MODEL §9.1).
//!
//! The generated wheel has a sharp root corner (the hob's tip edge is sharp, MODEL §12): a
//! re-entrant corner whose elastic stress is singular, so no root stress converges on it. A
//! real hob's tip edge is rounded; here each tooth foot gets a circular fillet of the given
//! radius in every face layer's plane (z = const): the circle tangent to the tooth's side (the
//! flank, continued radially below its lowest point, as in the bending model's mesh) and to the
//! root circle (the hob's tip torus at that z). It stands for the trochoid a rounded hob tip
//! cuts; the active flank above the tangent point is unchanged.
//!
//! Each layer's section in (r, theta) is split into blocks: per tooth, the tooth (from the
//! fillets' mid points to the top, its sides along the fillet arcs and then the flanks), the rim
//! under it, and the two fillet blocks (under the lower half of each fillet arc, down to the
//! rim's inner surface); and the rim under the spaces. The blocks meet at the arcs' mid points
//! at 45 and 90 degree corners. Elements are graded: `fillet` elements along each half arc and
//! through a band of the fillet radius below the root. Nodes on a half-step lattice of the
//! blocks' mappings; coincident nodes merged. Coordinates: wheel body frame, m.

use super::fe::{Mesh, NATURAL};
use super::wheel_mesh::{lattice_point, Nodes};
use crate::geometry::placement::wheel_point;
use crate::geometry::{Flank, Geometry, WheelFlank};
use std::f64::consts::PI;

/// Mesh sizes of the filleted sector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilletMeshSettings {
    /// Fillet radius, m.
    pub fillet_radius: f64,
    /// Elements along each half of a fillet arc, and through the fillet band of the rim.
    pub fillet: usize,
    /// Elements across each tooth (the first and last `fillet` of them graded to the fillet).
    pub across: usize,
    /// Elements along the tooth's side from the fillet's tangent point to the top.
    pub height: usize,
    /// Elements through the rim below its fillet band.
    pub rim: usize,
    /// Elements across the root land of each space, besides the `fillet` graded ones at each end.
    pub space: usize,
    /// Face layers (node columns of the flank grid, graded towards the face ends).
    pub layers: usize,
    /// Rim thickness below the root at the median plane, m.
    pub rim_thickness: f64,
}

/// Which side of a tooth: `A` the left-mating flank's side (lower u), `C` the right-mating one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    A,
    C,
}

impl Side {
    /// The side carrying the wheel's `flank`.
    pub fn of(flank: Flank) -> Self {
        match flank {
            Flank::Left => Side::A,
            Flank::Right => Side::C,
        }
    }
}

/// The filleted sector mesh and what the root stress needs of it.
#[derive(Debug, Clone)]
pub struct FilletSector {
    pub mesh: Mesh,
    /// The sizes it was built with.
    pub settings: FilletMeshSettings,
    /// Nodes on the rim's inner surface (clamped).
    pub clamped: Vec<usize>,
    /// Per tooth (0, 1, 2) and side (A, C): the tooth block's elements on that flank by
    /// [layer][row] (row 0 at the fillet's mid point).
    pub flank_elements: [[Vec<Vec<usize>>; 2]; 3],
    /// Rows of the tooth block along the fillet arc (the rest are on the flank).
    pub fillet_rows: usize,
    /// The central tooth's root section: per layer, the elements of the tooth block's first
    /// row, side A to side C (their faces v = -1 span the chord between the fillets' mid
    /// points).
    pub root_section: Vec<Vec<usize>>,
    /// Flank-grid node column of each layer.
    pub layer_columns: Vec<usize>,
    /// Face coordinate of each layer, m.
    pub layer_z: Vec<f64>,
    /// Per layer, tooth and side: radius of the fillet's tangent point on the side, m.
    pub tangent_radius: Vec<[[f64; 2]; 3]>,
    /// Per layer: the tooth top radius, m.
    pub top: Vec<f64>,
}

/// The teeth of the sector: the reference tooth and its two neighbours.
const TEETH: [i32; 3] = [-1, 0, 1];

/// A fillet arc in a layer's plane: centre (planar x = r cos theta, y = r sin theta, m),
/// radius, the arc's angles at the tangent points on the side (t = 0) and on the root circle
/// (t = 1), and the theta that unwraps angles near it.
#[derive(Debug, Clone, Copy)]
struct Arc {
    centre: [f64; 2],
    radius: f64,
    start: f64,
    sweep: f64,
    theta_ref: f64,
    /// Radius of the tangent point on the side, m.
    tangent_r: f64,
}

impl Arc {
    /// (r, theta) at arc parameter t in [0, 1] (0: on the side, 1: on the root circle).
    fn at(&self, t: f64) -> (f64, f64) {
        let a = self.start + t * self.sweep;
        let (x, y) = (
            self.centre[0] + self.radius * a.cos(),
            self.centre[1] + self.radius * a.sin(),
        );
        (x.hypot(y), unwrap(y.atan2(x), self.theta_ref))
    }
}

/// `angle` shifted by whole turns to within half a turn of `reference`, rad.
fn unwrap(angle: f64, reference: f64) -> f64 {
    reference + (angle - reference + PI).rem_euclid(2.0 * PI) - PI
}

/// The fillet of radius `rho` tangent to the side theta = side(r) (planar) and to the root
/// circle of radius `root`, on the side where theta moves away from the tooth by `away`
/// (+1 or -1). None when no tangent circle lies within four radii above the root.
fn fillet(side: &dyn Fn(f64) -> f64, root: f64, rho: f64, away: f64) -> Option<Arc> {
    let point = |r: f64| {
        let t = side(r);
        [r * t.cos(), r * t.sin()]
    };
    let centre = |r: f64| {
        let h = 1e-3 * rho;
        let (p0, p1) = (point(r - h), point(r + h));
        let (tx, ty) = (p1[0] - p0[0], p1[1] - p0[1]);
        let len = tx.hypot(ty);
        let p = point(r);
        // e_theta at p, scaled by the direction away from the tooth.
        let th = side(r);
        let away_dir = [-th.sin() * away, th.cos() * away];
        let mut n = [-ty / len, tx / len];
        if n[0] * away_dir[0] + n[1] * away_dir[1] < 0.0 {
            n = [-n[0], -n[1]];
        }
        [p[0] + rho * n[0], p[1] + rho * n[1]]
    };
    let miss = |r: f64| {
        let c = centre(r);
        c[0].hypot(c[1]) - (root + rho)
    };
    let (mut lo, mut hi) = (root, root + 4.0 * rho);
    if miss(lo) > 0.0 || miss(hi) < 0.0 {
        return None;
    }
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if miss(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let r1 = 0.5 * (lo + hi);
    let c = centre(r1);
    let t1 = point(r1);
    let scale = root / c[0].hypot(c[1]);
    let t2 = [c[0] * scale, c[1] * scale];
    let start = (t1[1] - c[1]).atan2(t1[0] - c[0]);
    let end = (t2[1] - c[1]).atan2(t2[0] - c[0]);
    let sweep = (end - start + PI).rem_euclid(2.0 * PI) - PI;
    Some(Arc {
        centre: c,
        radius: rho,
        start,
        sweep,
        theta_ref: side(root),
        tangent_r: r1,
    })
}

/// Piecewise-linear grading of [0, 1] over `n` elements: the first `ends.0` elements cover the
/// fraction `widths.0`, the last `ends.1` cover `widths.1`, the rest share the remainder
/// evenly; `x` is the element coordinate (0..n), the result the graded parameter.
fn graded(x: f64, n: usize, ends: (usize, usize), widths: (f64, f64)) -> f64 {
    let (na, nb) = (ends.0 as f64, ends.1 as f64);
    let nm = n as f64 - na - nb;
    // An end element no larger than an even one.
    let wa = if ends.0 > 0 {
        widths.0.min(na / n as f64)
    } else {
        0.0
    };
    let wb = if ends.1 > 0 {
        widths.1.min(nb / n as f64)
    } else {
        0.0
    };
    if x <= na && na > 0.0 {
        x / na * wa
    } else if x >= n as f64 - nb && nb > 0.0 {
        1.0 - (n as f64 - x) / nb * wb
    } else {
        wa + (x - na) / nm * (1.0 - wa - wb)
    }
}

/// The flank rows of a tooth block: the first `fillet` of them within two fillet radii above
/// the tangent point (where the contact comes nearest the root), the rest even to the top.
/// Radius (m) at row coordinate `x` (0..height) above the tangent point `tangent_r`.
pub fn flank_radius(s: &FilletMeshSettings, tangent_r: f64, top: f64, x: f64) -> f64 {
    let band = 2.0 * s.fillet_radius / (top - tangent_r);
    let g = graded(x, s.height, (s.fillet.min(s.height - 1), 0), (band, 0.0));
    tangent_r + (top - tangent_r) * g
}

/// The row coordinate (0..height) of radius `r` on the flank: the inverse of
/// [`flank_radius`] (bisection; clamped to the rows).
pub fn flank_row(s: &FilletMeshSettings, tangent_r: f64, top: f64, r: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, s.height as f64);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if flank_radius(s, tangent_r, top, mid) < r {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The blocks of a layer's section.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Block {
    /// Tooth t (0, 1, 2).
    Tooth(usize),
    /// The rim under tooth t, between its fillets' mid points.
    Rim(usize),
    /// The fillet block on side A or C of tooth t.
    Fillet(usize, Side),
    /// The rim under the root land: 0 from the left side cut to tooth 0, 1 and 2 between the
    /// teeth, 3 from tooth 2 to the right side cut.
    Space(usize),
}

const BLOCKS: [Block; 16] = [
    Block::Space(0),
    Block::Fillet(0, Side::A),
    Block::Rim(0),
    Block::Tooth(0),
    Block::Fillet(0, Side::C),
    Block::Space(1),
    Block::Fillet(1, Side::A),
    Block::Rim(1),
    Block::Tooth(1),
    Block::Fillet(1, Side::C),
    Block::Space(2),
    Block::Fillet(2, Side::A),
    Block::Rim(2),
    Block::Tooth(2),
    Block::Fillet(2, Side::C),
    Block::Space(3),
];

/// One layer's section: the sides, root, top and fillets of its three teeth.
struct Layer<'a> {
    l: &'a WheelFlank,
    r: &'a WheelFlank,
    j: usize,
    tau: f64,
    root: f64,
    top: f64,
    r_in: f64,
    arcs: [[Arc; 2]; 3],
    s: &'a FilletMeshSettings,
}

impl Layer<'_> {
    /// theta of side `side` of sector tooth t at radius rr (the flank, continued radially below
    /// its lowest point), rad.
    fn side(&self, t: usize, side: Side, rr: f64) -> f64 {
        let k = TEETH[t] as f64;
        match side {
            Side::A => self.l.column_theta(self.j, rr.max(self.l.r_low[self.j])).0 + k * self.tau,
            Side::C => {
                self.r.column_theta(self.j, rr.max(self.r.r_low[self.j])).0 + (k + 1.0) * self.tau
            }
        }
    }

    fn arc(&self, t: usize, side: Side) -> &Arc {
        &self.arcs[t][side as usize]
    }

    /// Radial coordinate at v of a rim block whose top is at radius `top`: the last `fillet`
    /// rows in a band of one fillet radius below the top, the rest even down to the inner
    /// surface.
    fn rim_radius(&self, top: f64, v: f64) -> f64 {
        let n = self.s.rim + self.s.fillet;
        let band = self.s.fillet_radius / (top - self.r_in);
        self.r_in + (top - self.r_in) * graded(v * n as f64, n, (0, self.s.fillet), (0.0, band))
    }

    /// Graded u across tooth t (and the rim under it): the first and last `fillet` elements
    /// within about the fillet's half arc's width.
    fn tooth_u(&self, t: usize, u: f64) -> f64 {
        let (ma, mc) = (self.arc(t, Side::A).at(0.5), self.arc(t, Side::C).at(0.5));
        let width = 0.5 * (ma.0 + mc.0) * (mc.1 - ma.1).abs();
        let w = 0.7 * self.s.fillet_radius / width;
        let n = self.s.across;
        graded(u * n as f64, n, (self.s.fillet, self.s.fillet), (w, w))
    }

    /// (r, theta) of tooth t's side at v (0 at the fillet's mid point; the first `fillet` rows
    /// along the arc up to the tangent point, then along the side to the top).
    fn tooth_side(&self, t: usize, side: Side, v: f64) -> (f64, f64) {
        let n = self.s.fillet + self.s.height;
        let x = v * n as f64;
        let nf = self.s.fillet as f64;
        let arc = self.arc(t, side);
        if x <= nf {
            arc.at(0.5 * (1.0 - x / nf))
        } else {
            let rr = flank_radius(self.s, arc.tangent_r, self.top, x - nf);
            (rr, self.side(t, side, rr))
        }
    }

    /// Half the root land of a space (between the fillets' tangent points on the root circle;
    /// the same in every space), rad.
    fn half_land(&self) -> f64 {
        0.5 * (self.arc(1, Side::A).at(1.0).1 - self.arc(0, Side::C).at(1.0).1)
    }

    /// (r, theta) of `block` at (u, v).
    fn section(&self, block: Block, u: f64, v: f64) -> (f64, f64) {
        match block {
            Block::Tooth(t) => {
                let g = self.tooth_u(t, u);
                let (a, c) = (
                    self.tooth_side(t, Side::A, v),
                    self.tooth_side(t, Side::C, v),
                );
                (a.0 + (c.0 - a.0) * g, a.1 + (c.1 - a.1) * g)
            }
            Block::Rim(t) => {
                let g = self.tooth_u(t, u);
                let (a, c) = (self.arc(t, Side::A).at(0.5), self.arc(t, Side::C).at(0.5));
                let top = (a.0 + (c.0 - a.0) * g, a.1 + (c.1 - a.1) * g);
                (self.rim_radius(top.0, v), top.1)
            }
            Block::Fillet(t, side) => {
                let arc = self.arc(t, side);
                let top = match side {
                    Side::A => arc.at(1.0 - 0.5 * u),
                    Side::C => arc.at(0.5 + 0.5 * u),
                };
                (self.rim_radius(top.0, v), top.1)
            }
            Block::Space(sp) => {
                let half = self.half_land();
                let (a, c, ends) = match sp {
                    0 => {
                        let c = self.arc(0, Side::A).at(1.0).1;
                        (c - half, c, (0, self.s.fillet))
                    }
                    3 => {
                        let a = self.arc(2, Side::C).at(1.0).1;
                        (a, a + half, (self.s.fillet, 0))
                    }
                    k => (
                        self.arc(k - 1, Side::C).at(1.0).1,
                        self.arc(k, Side::A).at(1.0).1,
                        (self.s.fillet, self.s.fillet),
                    ),
                };
                let n = self.dims(block).0;
                let w = 0.5 * self.s.fillet_radius / (self.root * (c - a).abs());
                let g = graded(u * n as f64, n, ends, (w, w));
                (self.rim_radius(self.root, v), a + (c - a) * g)
            }
        }
    }

    /// Elements of a block (around, radial).
    fn dims(&self, block: Block) -> (usize, usize) {
        let s = self.s;
        let rim = s.rim + s.fillet;
        match block {
            Block::Tooth(_) => (s.across, s.fillet + s.height),
            Block::Rim(_) => (s.across, rim),
            Block::Fillet(..) => (s.fillet, rim),
            Block::Space(0) | Block::Space(3) => (s.fillet + s.space.div_ceil(2), rim),
            Block::Space(_) => (2 * s.fillet + s.space, rim),
        }
    }

    /// Body-frame point of `block` at (u, v), m.
    fn point(&self, block: Block, u: f64, v: f64) -> [f64; 3] {
        let (rr, th) = self.section(block, u, v);
        let p = wheel_point(rr, th, self.l.z[self.j], 0.0);
        [p.x, p.y, p.z]
    }
}

/// Errors of the filleted mesh.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum FilletMeshError {
    #[error(
        "no root fillet of radius {radius_mm:.3} mm fits the tooth foot at z = {z_mm:.2} mm (the \
         circle tangent to the flank and the root circle lies more than four radii above the \
         root); a smaller rating.root_fillet_radius_mm is needed"
    )]
    NoFillet { radius_mm: f64, z_mm: f64 },
}

/// Builds the filleted three-tooth sector of the wheel from its flank grids; the root circle
/// is the hob's tip torus (`hob_tip`, `cutting_centre_distance`, m).
pub fn fillet_sector_mesh(
    geo: &Geometry,
    s: &FilletMeshSettings,
    hob_tip: f64,
    cutting_centre_distance: f64,
) -> Result<FilletSector, FilletMeshError> {
    let l = geo.wheel_flank(Flank::Left);
    let r = geo.wheel_flank(Flank::Right);
    let nj = l.cells_face;
    let count = s.layers.clamp(1, nj);
    let mut columns: Vec<usize> = (0..=count)
        .map(|i| {
            // Graded towards the face ends (end layers a fifth of the mean), where the contact
            // reaches the face edges.
            let u = i as f64 / count as f64;
            ((u - 0.8 * (2.0 * PI * u).sin() / (2.0 * PI)) * nj as f64).round() as usize
        })
        .collect();
    columns.dedup();
    let root_at = |z: f64| cutting_centre_distance - (hob_tip * hob_tip - z * z).max(0.0).sqrt();
    let r_in = root_at(0.0) - s.rim_thickness;
    let tau = 2.0 * PI / geo.teeth as f64;
    let layers = columns
        .iter()
        .map(|&j| layer(l, r, j, tau, (root_at(l.z[j]), r_in), s))
        .collect::<Result<Vec<_>, _>>()?;
    let mut out = FilletSector {
        mesh: Mesh {
            nodes: Vec::new(),
            elements: Vec::new(),
        },
        settings: *s,
        clamped: Vec::new(),
        flank_elements: Default::default(),
        fillet_rows: s.fillet,
        root_section: vec![Vec::new(); columns.len() - 1],
        layer_z: columns.iter().map(|&j| l.z[j]).collect(),
        layer_columns: columns.clone(),
        tangent_radius: layers
            .iter()
            .map(|ly| std::array::from_fn(|t| [ly.arcs[t][0].tangent_r, ly.arcs[t][1].tangent_r]))
            .collect(),
        top: layers.iter().map(|ly| ly.top).collect(),
    };
    for list in out.flank_elements.iter_mut().flatten() {
        *list = vec![Vec::new(); columns.len() - 1];
    }
    let mut nodes = Nodes::default();
    for (li, pair) in layers.windows(2).enumerate() {
        for block in BLOCKS {
            layer_block(&pair[0], &pair[1], li, block, &mut nodes, &mut out);
        }
    }
    out.mesh.nodes = nodes.points;
    out.clamped.sort_unstable();
    out.clamped.dedup();
    Ok(out)
}

/// The section of layer j with its fillets.
fn layer<'a>(
    l: &'a WheelFlank,
    r: &'a WheelFlank,
    j: usize,
    tau: f64,
    (root, r_in): (f64, f64),
    s: &'a FilletMeshSettings,
) -> Result<Layer<'a>, FilletMeshError> {
    let placeholder = Arc {
        centre: [0.0; 2],
        radius: 0.0,
        start: 0.0,
        sweep: 0.0,
        theta_ref: 0.0,
        tangent_r: 0.0,
    };
    let mut ly = Layer {
        l,
        r,
        j,
        tau,
        root,
        top: l.r_high[j].min(r.r_high[j]),
        r_in,
        arcs: [[placeholder; 2]; 3],
        s,
    };
    let mut arcs = [[placeholder; 2]; 3];
    for (t, pair) in arcs.iter_mut().enumerate() {
        let (a, c) = (ly.side(t, Side::A, root), ly.side(t, Side::C, root));
        let toward_c = (c - a).signum();
        for (side, away) in [(Side::A, -toward_c), (Side::C, toward_c)] {
            let f = |rr: f64| ly.side(t, side, rr);
            pair[side as usize] =
                fillet(&f, root, s.fillet_radius, away).ok_or(FilletMeshError::NoFillet {
                    radius_mm: s.fillet_radius * 1e3,
                    z_mm: l.z[j] * 1e3,
                })?;
        }
    }
    ly.arcs = arcs;
    Ok(ly)
}

/// The elements of one block between layers `a` and `b` (layer index li), with the clamped
/// nodes, the tooth flanks' elements and the central tooth's root section marked.
fn layer_block(
    a: &Layer,
    b: &Layer,
    li: usize,
    block: Block,
    nodes: &mut Nodes,
    out: &mut FilletSector,
) {
    let (nu, nv) = a.dims(block);
    for iv in 0..nv {
        for iu in 0..nu {
            let mut e = [0usize; 20];
            for (k, c) in NATURAL.iter().enumerate() {
                let (_, v, p) = lattice_point(c, (iu, iv), (nu, nv), |layer, u, v| {
                    [a, b][layer].point(block, u, v)
                });
                e[k] = nodes.at(p);
                if v == 0.0 && !matches!(block, Block::Tooth(_)) {
                    out.clamped.push(e[k]);
                }
            }
            let element = out.mesh.elements.len();
            out.mesh.elements.push(e);
            mark(block, (iu, iv), nu, li, element, out);
        }
    }
}

/// Records a tooth block's flank elements and the central tooth's root section.
fn mark(
    block: Block,
    (iu, iv): (usize, usize),
    nu: usize,
    li: usize,
    element: usize,
    out: &mut FilletSector,
) {
    if let Block::Tooth(t) = block {
        if t == 1 && iv == 0 {
            out.root_section[li].push(element);
        }
        for (side, edge) in [(Side::A, 0), (Side::C, nu - 1)] {
            if iu == edge {
                out.flank_elements[t][side as usize][li].push(element);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fillet_of_a_straight_radial_side_is_a_quarter_circle_tangent_to_both() {
        // Side theta = 0.1 (radial line); the space at smaller theta.
        let side = |_: f64| 0.1;
        let (root, rho) = (0.09, 0.001);
        let arc = fillet(&side, root, rho, -1.0).expect("a fillet");
        // Centre at distance root + rho from the axis and rho from the radial line.
        let c = arc.centre;
        assert!((c[0].hypot(c[1]) - (root + rho)).abs() < 1e-12);
        let normal = [-(0.1f64).sin(), (0.1f64).cos()];
        assert!(((c[0] * normal[0] + c[1] * normal[1]).abs() - rho).abs() < 1e-9);
        // Tangent points: on the side at the centre's foot, on the root circle.
        let (r0, t0) = arc.at(0.0);
        assert!((t0 - 0.1).abs() < 1e-12);
        assert!((r0 - (root + rho) * (1.0 - (rho / (root + rho)).powi(2)).sqrt()).abs() < 1e-9);
        let (r1, t1) = arc.at(1.0);
        assert!((r1 - root).abs() < 1e-12 && t1 < 0.1);
        // Every arc point lies in the space, at least root and no more than the side.
        for k in 0..=10 {
            let (rr, th) = arc.at(k as f64 / 10.0);
            assert!(rr >= root - 1e-12 && th <= 0.1 + 1e-12);
        }
        // Sweep near a quarter turn (exactly one for a straight root).
        assert!((arc.sweep.abs() - PI / 2.0).abs() < 0.02);
    }

    #[test]
    fn grading_is_monotone_and_keeps_its_ends() {
        for &(n, ends, w) in &[
            (8, (2, 2), (0.05, 0.05)),
            (5, (0, 2), (0.0, 0.1)),
            (6, (2, 0), (0.5, 0.0)),
        ] {
            let mut last = -1.0;
            for k in 0..=2 * n {
                let g = graded(k as f64 / 2.0, n, ends, w);
                assert!(g > last);
                last = g;
            }
            assert_eq!(graded(0.0, n, ends, w), 0.0);
            assert!((graded(n as f64, n, ends, w) - 1.0).abs() < 1e-15);
        }
    }
}
