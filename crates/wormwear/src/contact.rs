//! Contact influence coefficients (MODEL §5.5, §12d): Boussinesq half-space of both bodies.
//!
//! A uniform pressure on a rectangle of half sides (dnu, dzeta) in its tangent plane displaces
//! the surface normally by Love's closed form; the tangential (radial, in-surface) part of the
//! Boussinesq field is applied as a concentrated load; the sum is projected on the normal at the
//! receiving cell: C_ij = (C_ij^n n_j + C_ij^rho) . n_i. Coefficients couple cells of the same
//! tooth contact only. Units: m of normal displacement per Pa of pressure.

use nalgebra::Vector3;
use std::f64::consts::PI;
use std::mem::MaybeUninit;

mod grid;
pub use grid::{lattice, GridInfluence};

/// Elastic constants of the pair used by the half-space coefficients.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElasticPair {
    /// (1 - v1^2)/(pi E1) + (1 - v2^2)/(pi E2), 1/Pa.
    pub normal: f64,
    /// (1 + v1)(1 - 2 v1)/(2 pi E1) - (1 + v2)(1 - 2 v2)/(2 pi E2), 1/Pa (MODEL §12d: E2 in
    /// the second term).
    pub tangential: f64,
    /// Effective modulus E* with 1/E* = (1 - v1^2)/E1 + (1 - v2^2)/E2, Pa (Hertz).
    pub effective_modulus: f64,
}

impl ElasticPair {
    /// Constants for Young's moduli (Pa) and Poisson's ratios of worm (1) and wheel (2).
    pub fn new(e1: f64, v1: f64, e2: f64, v2: f64) -> Self {
        Self {
            normal: (1.0 - v1 * v1) / (PI * e1) + (1.0 - v2 * v2) / (PI * e2),
            tangential: (1.0 + v1) * (1.0 - 2.0 * v1) / (2.0 * PI * e1)
                - (1.0 + v2) * (1.0 - 2.0 * v2) / (2.0 * PI * e2),
            effective_modulus: 1.0 / ((1.0 - v1 * v1) / e1 + (1.0 - v2 * v2) / e2),
        }
    }
}

/// Hertz half-width of a line contact, cylinder on plane (MODEL §12 g): a = sqrt(4 w R /
/// (pi E*)) for the line load w (N/m), relative radius R (m) and effective modulus E* (Pa) of
/// [`ElasticPair`]; m. Zero when w <= 0 or R is not a positive finite radius.
pub fn hertz_half_width(line_load: f64, radius: f64, effective_modulus: f64) -> f64 {
    if line_load <= 0.0 || !(radius > 0.0 && radius.is_finite()) {
        return 0.0;
    }
    (4.0 * line_load * radius / (PI * effective_modulus)).sqrt()
}

/// Love's integral of 1/r over the rectangle [-a, a] x [-b, b] seen from (x, y) (in-plane
/// offsets from the rectangle centre), m. Times `ElasticPair::normal` it is the normal
/// displacement per unit uniform pressure.
#[inline]
pub fn love_rectangle(x: f64, y: f64, a: f64, b: f64) -> f64 {
    // Sum over the corners of  X ln(Y + R) + Y ln(X + R)  with signs, X = x -+ a,
    // Y = y -+ b; the two corners sharing an X (or a Y) are combined into one logarithm of a
    // ratio (4 logarithms instead of 8), each factor kept free of cancellation.
    let (x1, x2, y1, y2) = (x + a, x - a, y + b, y - b);
    let r11 = (x1 * x1 + y1 * y1).sqrt();
    let r12 = (x1 * x1 + y2 * y2).sqrt();
    let r21 = (x2 * x2 + y1 * y1).sqrt();
    let r22 = (x2 * x2 + y2 * y2).sqrt();
    let mut v = 0.0;
    if x1 != 0.0 {
        v += x1 * (t_plus_r(y1, x1, r11) / t_plus_r(y2, x1, r12)).ln();
    }
    if x2 != 0.0 {
        v -= x2 * (t_plus_r(y1, x2, r21) / t_plus_r(y2, x2, r22)).ln();
    }
    if y1 != 0.0 {
        v += y1 * (t_plus_r(x1, y1, r11) / t_plus_r(x2, y1, r21)).ln();
    }
    if y2 != 0.0 {
        v -= y2 * (t_plus_r(x1, y2, r12) / t_plus_r(x2, y2, r22)).ln();
    }
    v
}

/// Squared in-plane distance from a rectangle of half sides (a, b) beyond which Love's
/// integral takes its far-field expansion: six times the larger half side, m^2. The radius is
/// widened by 1e-9 so that centres exactly six half sides apart (abutting equal cells three
/// apart) take the closed form whatever the round-off of their difference: every such pair of
/// a lattice then gets the same number (the two forms differ by up to 2e-4 there).
#[inline]
fn far_field_radius2(a: f64, b: f64) -> f64 {
    const FAR: f64 = 6.0;
    let m = FAR * a.max(b);
    m * m * (1.0 + 1e-9)
}

/// Love's integral with a far-field expansion beyond six times the larger half side
/// ([`far_field_radius2`]): the rectangle's monopole and quadrupole terms,
/// 4ab [1/d + (a^2 (2x^2 - y^2) + b^2 (2y^2 - x^2)) / (6 d^5)], relative error O((a/d)^4)
/// (below 1e-4 there), exact closed form nearer.
#[inline]
pub fn love_rectangle_fast(x: f64, y: f64, a: f64, b: f64) -> f64 {
    let d2 = x * x + y * y;
    if d2 > far_field_radius2(a, b) {
        let d = d2.sqrt();
        let d5 = d2 * d2 * d;
        4.0 * a
            * b
            * (1.0 / d
                + (a * a * (2.0 * x * x - y * y) + b * b * (2.0 * y * y - x * x)) / (6.0 * d5))
    } else {
        love_rectangle(x, y, a, b)
    }
}

/// t + R, R = sqrt(t^2 + s^2), without cancellation for t < 0 (t + R = s^2 / (R - t)).
#[inline]
fn t_plus_r(t: f64, s: f64, r: f64) -> f64 {
    if t >= 0.0 {
        t + r
    } else {
        s * s / (r - t)
    }
}

/// A contact cell: centre, unit normal (out of the wheel, the pressure direction on the worm),
/// in-plane unit axes and half sides. Worm frame, m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactCell {
    pub centre: Vector3<f64>,
    pub normal: Vector3<f64>,
    /// Unit axis across the contact line (nu) and along it (zeta), in the tangent plane.
    pub axis_nu: Vector3<f64>,
    pub axis_zeta: Vector3<f64>,
    pub half_nu: f64,
    pub half_zeta: f64,
}

impl ContactCell {
    /// Area, m^2.
    pub fn area(&self) -> f64 {
        4.0 * self.half_nu * self.half_zeta
    }
}

/// Normal displacement at cell i (along n_i) due to unit pressure on cell j, both bodies, m/Pa
/// (MODEL §5.5). Love's closed form near the source, its far-field expansion beyond six half
/// sides ([`love_rectangle_fast`], relative error below 2e-4 there).
#[inline]
pub fn coefficient(pair: &ElasticPair, i: &ContactCell, j: &ContactCell) -> f64 {
    let d = i.centre - j.centre;
    let nu = d.dot(&j.axis_nu);
    let zeta = d.dot(&j.axis_zeta);
    let normal = pair.normal
        * love_rectangle_fast(nu, zeta, j.half_nu, j.half_zeta)
        * j.normal.dot(&i.normal);
    let r2 = d.norm_squared();
    let tangential = if r2 > 0.0 {
        pair.tangential * j.area() * d.dot(&i.normal) / r2
    } else {
        0.0
    };
    normal + tangential
}

/// Source cells of a block as structure of arrays (centres, normals, in-plane axes, half
/// sides, 1 / (area lever)), for [`far_row`].
#[derive(Debug, Clone)]
struct SourceCells {
    c: [Vec<f64>; 3],
    n: [Vec<f64>; 3],
    u: [Vec<f64>; 3],
    v: [Vec<f64>; 3],
    half_nu: Vec<f64>,
    half_zeta: Vec<f64>,
    inv: Vec<f64>,
}

/// Row a of the block from column a on, with the far-field form of Love's integral for every
/// pair (the near ones are overwritten by the caller), and the in-plane squared distances.
/// Branch-free over structure-of-arrays data so the compiler vectorises it. Writes every entry
/// of `out` (which may be uninitialised).
#[inline(always)]
fn far_row(
    pair: &ElasticPair,
    s: &SourceCells,
    a: usize,
    scale_i: f64,
    out: &mut [MaybeUninit<f64>],
    dist: &mut [f64],
) {
    let (xi, yi, zi) = (s.c[0][a], s.c[1][a], s.c[2][a]);
    let (nxi, nyi, nzi) = (s.n[0][a], s.n[1][a], s.n[2][a]);
    let m = out.len();
    let (sx, sy, sz) = (&s.c[0][a..], &s.c[1][a..], &s.c[2][a..]);
    let (snx, sny, snz) = (&s.n[0][a..], &s.n[1][a..], &s.n[2][a..]);
    let (sux, suy, suz) = (&s.u[0][a..], &s.u[1][a..], &s.u[2][a..]);
    let (svx, svy, svz) = (&s.v[0][a..], &s.v[1][a..], &s.v[2][a..]);
    let (sa, sb, sinv) = (&s.half_nu[a..], &s.half_zeta[a..], &s.inv[a..]);
    assert!(dist.len() == m && sx.len() == m && sinv.len() == m && svz.len() == m);
    for k in 0..m {
        let d = [xi - sx[k], yi - sy[k], zi - sz[k]];
        let source = FarSource {
            u: [sux[k], suy[k], suz[k]],
            v: [svx[k], svy[k], svz[k]],
            n: [snx[k], sny[k], snz[k]],
            half_nu: sa[k],
            half_zeta: sb[k],
        };
        let (value, d2) = far_entry(pair, d, &source, [nxi, nyi, nzi]);
        dist[k] = d2;
        out[k] = MaybeUninit::new(value * sinv[k] * scale_i);
    }
}

/// A source cell's in-plane axes, normal and half sides, for [`far_entry`].
struct FarSource {
    u: [f64; 3],
    v: [f64; 3],
    n: [f64; 3],
    half_nu: f64,
    half_zeta: f64,
}

/// Far-field coefficient of one pair before the 1 / (area lever) and 1 / lever scalings, and
/// the in-plane squared distance: d = receiver centre - source centre (m), `receiver` its
/// unit normal. Love's monopole and quadrupole terms along the normals plus the tangential
/// Boussinesq term (MODEL §5.5). The one formula of [`far_row`] and [`far_column`], so their
/// numbers agree to the last bit.
#[inline(always)]
fn far_entry(pair: &ElasticPair, d: [f64; 3], s: &FarSource, receiver: [f64; 3]) -> (f64, f64) {
    let [dx, dy, dz] = d;
    let nu = dx * s.u[0] + dy * s.u[1] + dz * s.u[2];
    let zeta = dx * s.v[0] + dy * s.v[1] + dz * s.v[2];
    let (aa, bb) = (s.half_nu, s.half_zeta);
    let d2 = nu * nu + zeta * zeta;
    let dist = d2.sqrt();
    let love = 4.0
        * aa
        * bb
        * (1.0 / dist
            + (aa * aa * (2.0 * nu * nu - zeta * zeta) + bb * bb * (2.0 * zeta * zeta - nu * nu))
                / (6.0 * d2 * d2 * dist));
    let dot_n = s.n[0] * receiver[0] + s.n[1] * receiver[1] + s.n[2] * receiver[2];
    let r2 = dx * dx + dy * dy + dz * dz;
    let tangential =
        pair.tangential * 4.0 * aa * bb * (dx * receiver[0] + dy * receiver[1] + dz * receiver[2])
            / r2;
    (pair.normal * love * dot_n + tangential, d2)
}

/// [`far_row`] compiled for AVX2 + FMA (4 doubles per instruction); chosen at run time.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn far_row_avx2(
    pair: &ElasticPair,
    s: &SourceCells,
    a: usize,
    scale_i: f64,
    out: &mut [MaybeUninit<f64>],
    dist: &mut [f64],
) {
    far_row(pair, s, a, scale_i, out, dist)
}

/// Symmetric influence block of a group of cells (one tooth): entry (a, b) is
/// [`coefficient`]`(a, b) / (area_b lever_a lever_b)` for b >= a, mirrored below the diagonal
/// (row-major, n x n). The same numbers as calling [`coefficient`] pair by pair; laid out for
/// speed: the far-field branch is computed for a whole row in one branch-free loop over
/// structure-of-arrays data (the compiler vectorises it), then the few near pairs are
/// recomputed with Love's closed form.
pub fn symmetric_block(pair: &ElasticPair, cells: &[ContactCell], levers: &[f64]) -> Vec<f64> {
    symmetric_block_reusing(pair, cells, levers, &vec![None; cells.len()], &[])
}

/// [`symmetric_block`] of cells that are `set` (indices) of a larger group whose rows
/// `known[a]` (the group's row of cell a, all its columns) may already be assembled: a known
/// row is gathered and a near pair with a known row taken from it instead of recomputed
/// (the same numbers). `set` is read only for the known rows.
fn symmetric_block_reusing(
    pair: &ElasticPair,
    cells: &[ContactCell],
    levers: &[f64],
    known: &[Option<&[f64]>],
    set: &[usize],
) -> Vec<f64> {
    let n = cells.len();
    assert_eq!(levers.len(), n);
    assert_eq!(known.len(), n);
    let soa = SourceCells::new(cells, levers);
    let far2 = near_radii2(cells);
    #[cfg(target_arch = "x86_64")]
    let wide = is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma");
    // Every entry is written below (the upper triangle row by row, then the mirror), so the
    // storage is not zeroed first (that cost ~5 % of a wear life).
    let mut matrix: Box<[MaybeUninit<f64>]> = Box::new_uninit_slice(n * n);
    let mut dist2 = vec![0.0; n];
    for a in 0..n {
        let scale_i = 1.0 / levers[a];
        let out = &mut matrix[a * n + a..a * n + n];
        if let Some(row) = known[a] {
            for (o, &i) in out.iter_mut().zip(&set[a..]) {
                *o = MaybeUninit::new(row[i]);
            }
            continue;
        }
        let dist = &mut dist2[..n - a];
        #[cfg(target_arch = "x86_64")]
        if wide {
            // SAFETY: the CPU has AVX2 and FMA (checked above).
            unsafe { far_row_avx2(pair, &soa, a, scale_i, out, dist) };
        } else {
            far_row(pair, &soa, a, scale_i, out, dist);
        }
        #[cfg(not(target_arch = "x86_64"))]
        far_row(pair, &soa, a, scale_i, out, dist);
        // Near pairs: Love's closed form (and the cell's own coefficient).
        let far2 = &far2[a..];
        for (k, (o, d)) in out.iter_mut().zip(dist.iter()).enumerate() {
            if *d <= far2[k] {
                *o = MaybeUninit::new(match known[a + k] {
                    Some(row) => row[set[a]],
                    None => coefficient(pair, &cells[a], &cells[a + k]) * soa.inv[a + k] * scale_i,
                });
            }
        }
    }
    mirror_upper(&mut matrix, n);
    // SAFETY: rows wrote columns a..n (far_row writes all of `out`), the mirror columns 0..b
    // of every row b.
    unsafe { matrix.assume_init() }.into_vec()
}

/// Entries (k, j), k < j, of the block's row j, i.e. the upper triangle's column j (receiver
/// k, source j), with the far-field form of Love's integral for every pair, and the in-plane
/// squared distances. The same arithmetic, term for term, as [`far_row`] gives for row k at
/// column j, so the values are identical to the mirrored ones of [`symmetric_block`].
#[inline(always)]
fn far_column(
    pair: &ElasticPair,
    s: &SourceCells,
    j: usize,
    scale: &[f64],
    out: &mut [f64],
    dist: &mut [f64],
) {
    let m = out.len();
    let (xj, yj, zj) = (s.c[0][j], s.c[1][j], s.c[2][j]);
    let (nxj, nyj, nzj) = (s.n[0][j], s.n[1][j], s.n[2][j]);
    let (uxj, uyj, uzj) = (s.u[0][j], s.u[1][j], s.u[2][j]);
    let (vxj, vyj, vzj) = (s.v[0][j], s.v[1][j], s.v[2][j]);
    let (aa, bb, inv) = (s.half_nu[j], s.half_zeta[j], s.inv[j]);
    let (rx, ry, rz) = (&s.c[0][..m], &s.c[1][..m], &s.c[2][..m]);
    let (rnx, rny, rnz) = (&s.n[0][..m], &s.n[1][..m], &s.n[2][..m]);
    let scale = &scale[..m];
    assert!(dist.len() == m);
    let source = FarSource {
        u: [uxj, uyj, uzj],
        v: [vxj, vyj, vzj],
        n: [nxj, nyj, nzj],
        half_nu: aa,
        half_zeta: bb,
    };
    for k in 0..m {
        let d = [rx[k] - xj, ry[k] - yj, rz[k] - zj];
        let (value, d2) = far_entry(pair, d, &source, [rnx[k], rny[k], rnz[k]]);
        dist[k] = d2;
        out[k] = value * inv * scale[k];
    }
}

/// [`far_column`] compiled for AVX2 + FMA; chosen at run time.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn far_column_avx2(
    pair: &ElasticPair,
    s: &SourceCells,
    j: usize,
    scale: &[f64],
    out: &mut [f64],
    dist: &mut [f64],
) {
    far_column(pair, s, j, scale, out, dist)
}

/// The symmetric influence block of [`symmetric_block`] assembled on demand (MODEL §5.5): a
/// row the first time a solver reads it, or the sub-block of a set of cells. The solvers read
/// the rows of the cells that carry load (the block is symmetric, so a product K x needs the
/// rows of x's non-zero entries) and, in the screened solve, the sub-block of its candidate
/// cells; over a wear life those are a fraction of the band. Every entry is the number
/// [`symmetric_block`] gives (computed with the lower-index cell as the receiver).
/// Thread-safe.
#[derive(Debug, Clone)]
pub struct InfluenceRows {
    pair: ElasticPair,
    cells: Vec<ContactCell>,
    levers: Vec<f64>,
    soa: SourceCells,
    far2: Vec<f64>,
    /// 1 / lever of each cell, 1/m.
    scale: Vec<f64>,
    rows: Vec<std::sync::OnceLock<Box<[f64]>>>,
    /// The first sub-block handed out: rows assembled later take their near pairs inside it
    /// from there instead of recomputing Love's closed form (the same numbers).
    known: std::sync::OnceLock<KnownBlock>,
}

/// A sub-block of [`InfluenceRows`]: each cell's position in it (None: outside) and its
/// entries, row-major, shared with the solver that reads it.
#[derive(Debug, Clone)]
struct KnownBlock {
    position: Vec<Option<u32>>,
    size: usize,
    values: std::sync::Arc<Vec<f64>>,
}

impl KnownBlock {
    /// Entry (a, b) in the group's indices, if both cells are in the sub-block.
    #[inline]
    fn entry(&self, a: usize, b: usize) -> Option<f64> {
        let (pa, pb) = (self.position[a]?, self.position[b]?);
        Some(self.values[pa as usize * self.size + pb as usize])
    }
}

impl InfluenceRows {
    /// The block of a group of cells (one tooth) with their levers (m); nothing is assembled
    /// yet.
    pub fn new(pair: &ElasticPair, cells: &[ContactCell], levers: &[f64]) -> Self {
        assert_eq!(levers.len(), cells.len());
        Self {
            pair: *pair,
            cells: cells.to_vec(),
            levers: levers.to_vec(),
            soa: SourceCells::new(cells, levers),
            far2: near_radii2(cells),
            scale: levers.iter().map(|l| 1.0 / l).collect(),
            rows: (0..cells.len())
                .map(|_| std::sync::OnceLock::new())
                .collect(),
            known: std::sync::OnceLock::new(),
        }
    }

    /// Number of cells (rows and columns).
    pub fn len(&self) -> usize {
        self.cells.len()
    }

    /// True for a block without cells.
    pub fn is_empty(&self) -> bool {
        self.cells.is_empty()
    }

    /// Row j (= column j), assembled on first use; units of [`symmetric_block`].
    pub fn row(&self, j: usize) -> &[f64] {
        self.rows[j].get_or_init(|| self.assemble_row(j))
    }

    /// Number of rows assembled so far.
    pub fn assembled(&self) -> usize {
        self.rows.iter().filter(|r| r.get().is_some()).count()
    }

    /// The block on the cells `set` (local indices, ascending): row-major set.len()^2, the
    /// entries of [`symmetric_block`] of the whole group at those rows and columns. Rows
    /// assembled before are read, not recomputed; the first sub-block is kept, and rows
    /// assembled afterwards read their near pairs inside it.
    pub fn sub_block(&self, set: &[usize]) -> std::sync::Arc<Vec<f64>> {
        assert!(set.windows(2).all(|w| w[0] < w[1]));
        let cells: Vec<ContactCell> = set.iter().map(|&i| self.cells[i]).collect();
        let levers: Vec<f64> = set.iter().map(|&i| self.levers[i]).collect();
        let known: Vec<Option<&[f64]>> = set
            .iter()
            .map(|&i| self.rows[i].get().map(|row| &row[..]))
            .collect();
        let values = std::sync::Arc::new(symmetric_block_reusing(
            &self.pair, &cells, &levers, &known, set,
        ));
        if self.known.get().is_none() {
            let mut position = vec![None; self.len()];
            for (p, &i) in set.iter().enumerate() {
                position[i] = u32::try_from(p).ok();
            }
            let _ = self.known.set(KnownBlock {
                position,
                size: set.len(),
                values: values.clone(),
            });
        }
        values
    }

    fn assemble_row(&self, j: usize) -> Box<[f64]> {
        let n = self.len();
        let (pair, soa) = (&self.pair, &self.soa);
        let mut out = vec![0.0; n];
        let mut dist = vec![0.0; n];
        {
            let (lower, upper) = out.split_at_mut(j);
            let (dist_lower, dist_upper) = dist.split_at_mut(j);
            // SAFETY: MaybeUninit<f64> has the layout of f64; the values are initialised.
            let upper: &mut [MaybeUninit<f64>] =
                unsafe { std::slice::from_raw_parts_mut(upper.as_mut_ptr().cast(), upper.len()) };
            #[cfg(target_arch = "x86_64")]
            if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") {
                // SAFETY: the CPU has AVX2 and FMA (checked here).
                unsafe {
                    far_row_avx2(pair, soa, j, self.scale[j], upper, dist_upper);
                    far_column_avx2(pair, soa, j, &self.scale, lower, dist_lower);
                }
            } else {
                far_row(pair, soa, j, self.scale[j], upper, dist_upper);
                far_column(pair, soa, j, &self.scale, lower, dist_lower);
            }
            #[cfg(not(target_arch = "x86_64"))]
            {
                far_row(pair, soa, j, self.scale[j], upper, dist_upper);
                far_column(pair, soa, j, &self.scale, lower, dist_lower);
            }
        }
        // Near pairs: Love's closed form, the lower index as the receiver (as the sub-block
        // handed out computed it, where both cells are in it).
        let cells = &self.cells;
        let known = self.known.get().filter(|k| k.position[j].is_some());
        for k in 0..n {
            let (receiver, source) = if k < j { (k, j) } else { (j, k) };
            if dist[k] <= self.far2[source] {
                out[k] = match known.and_then(|b| b.entry(j, k)) {
                    Some(value) => value,
                    None => {
                        coefficient(pair, &cells[receiver], &cells[source])
                            * soa.inv[source]
                            * self.scale[receiver]
                    }
                };
            }
        }
        out.into_boxed_slice()
    }
}

/// Squared in-plane radius around each source cell inside which its coefficients take Love's
/// closed form ([`far_field_radius2`]; the far-field expansion beyond), m^2.
fn near_radii2(cells: &[ContactCell]) -> Vec<f64> {
    cells
        .iter()
        .map(|c| far_field_radius2(c.half_nu, c.half_zeta))
        .collect()
}

impl SourceCells {
    /// The cells' data as structure of arrays, with 1 / (area lever) of each cell.
    fn new(cells: &[ContactCell], levers: &[f64]) -> Self {
        let col = |f: &dyn Fn(&ContactCell) -> f64| -> Vec<f64> { cells.iter().map(f).collect() };
        let xyz = |f: &dyn Fn(&ContactCell) -> Vector3<f64>| -> [Vec<f64>; 3] {
            [0, 1, 2].map(|k| cells.iter().map(|c| f(c)[k]).collect())
        };
        SourceCells {
            c: xyz(&|c| c.centre),
            n: xyz(&|c| c.normal),
            u: xyz(&|c| c.axis_nu),
            v: xyz(&|c| c.axis_zeta),
            half_nu: col(&|c| c.half_nu),
            half_zeta: col(&|c| c.half_zeta),
            inv: cells
                .iter()
                .zip(levers)
                .map(|(c, l)| 1.0 / (c.area() * l))
                .collect(),
        }
    }
}

/// Mirrors the upper triangle of the n x n row-major `matrix` (rows written from their
/// diagonal on) into the lower one, tile by tile (cache-friendly transpose).
fn mirror_upper(matrix: &mut [MaybeUninit<f64>], n: usize) {
    const TILE: usize = 32;
    for b0 in (0..n).step_by(TILE) {
        for a0 in (0..b0 + TILE).step_by(TILE) {
            for b in b0..(b0 + TILE).min(n) {
                // Row b, columns a0..min(a0 + TILE, b): contiguous writes, reads down column b
                // of the rows above (all in the tile).
                let (above, row_b) = matrix.split_at_mut(b * n);
                let end = (a0 + TILE).min(b);
                if end <= a0 {
                    continue;
                }
                for (k, v) in row_b[a0..end].iter_mut().enumerate() {
                    // SAFETY: row a0 + k < b was written from its diagonal on, column b
                    // included.
                    *v = MaybeUninit::new(unsafe { above[(a0 + k) * n + b].assume_init() });
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_block_assembly_gives_the_pairwise_coefficients() {
        // Cells of a curved band: 12 slices x 7 columns on a cylinder, sizes varying, normals
        // and in-plane axes from the surface; one block vs coefficient() pair by pair.
        let pair = ElasticPair::new(203e9, 0.29, 110e9, 0.29);
        let (radius, mut cells, mut levers) = (0.1, Vec::new(), Vec::new());
        for s in 0..12 {
            for c in 0..7 {
                let phi = 0.002 * c as f64 + 0.0003 * s as f64;
                let z = 0.0008 * s as f64;
                let normal = Vector3::new(phi.cos(), phi.sin(), 0.0);
                let axis_nu = Vector3::new(-phi.sin(), phi.cos(), 0.0);
                cells.push(ContactCell {
                    centre: normal * radius + Vector3::new(0.0, 0.0, z),
                    normal,
                    axis_nu,
                    axis_zeta: normal.cross(&axis_nu),
                    half_nu: 1e-4 * (1.0 + 0.05 * c as f64),
                    half_zeta: 4e-4 * (1.0 + 0.02 * s as f64),
                });
                levers.push(0.09 + 0.001 * c as f64);
            }
        }
        let n = cells.len();
        let block = symmetric_block(&pair, &cells, &levers);
        let mut far = 0;
        for a in 0..n {
            for b in a..n {
                let direct = coefficient(&pair, &cells[a], &cells[b])
                    / (cells[b].area() * levers[a] * levers[b]);
                let got = block[a * n + b];
                assert!(
                    (got - direct).abs() <= 1e-12 * direct.abs(),
                    "({a}, {b}): {got} vs {direct}"
                );
                assert_eq!(block[b * n + a], got);
                let d = cells[a].centre - cells[b].centre;
                if d.norm() > 6.0 * cells[b].half_zeta {
                    far += 1;
                }
            }
        }
        assert!(
            far > n * n / 4,
            "the test must exercise the far-field branch: {far}"
        );
        // Rows assembled on demand, in any order, and sub-blocks are the same numbers to the
        // last bit.
        let lazy = InfluenceRows::new(&pair, &cells, &levers);
        for j in (0..n).rev().step_by(7).chain([0, n / 2, n - 1]) {
            assert_eq!(lazy.row(j), &block[j * n..(j + 1) * n], "row {j}");
        }
        assert!(lazy.assembled() < n);
        let set: Vec<usize> = (0..n).filter(|i| i % 3 != 1 && i % 5 != 0).collect();
        let sub = lazy.sub_block(&set);
        for (a, &i) in set.iter().enumerate() {
            for (b, &j) in set.iter().enumerate() {
                assert_eq!(sub[a * set.len() + b], block[i * n + j], "({i}, {j})");
            }
        }
        // The sub-block above was cut after some rows were assembled (it read those); rows
        // assembled after a sub-block read their near pairs inside it: still the same numbers,
        // for rows inside and outside the set.
        let after = InfluenceRows::new(&pair, &cells, &levers);
        let _ = after.sub_block(&set);
        for j in 0..n {
            assert_eq!(
                after.row(j),
                &block[j * n..(j + 1) * n],
                "row {j} after a sub-block"
            );
        }
    }

    #[test]
    fn love_rectangle_centre_of_a_square_is_the_closed_form() {
        // Centre of a square of side 2a: 8 a ln(1 + sqrt 2) (Love).
        let a = 1e-3;
        let v = love_rectangle(0.0, 0.0, a, a);
        assert!((v / (8.0 * a * (1.0 + 2f64.sqrt()).ln()) - 1.0).abs() < 1e-14);
        // Far field: integral of 1/r -> area / distance.
        let (x, y) = (0.3, 0.4);
        let far = love_rectangle(x, y, a, 2.0 * a);
        assert!((far / (8.0 * a * a / 0.5) - 1.0).abs() < 1e-5);
        // Symmetry and positivity.
        let (u, v) = (
            love_rectangle(0.7e-3, -0.2e-3, a, a),
            love_rectangle(-0.7e-3, 0.2e-3, a, a),
        );
        assert!((u / v - 1.0).abs() < 1e-12);
        assert!(love_rectangle(-50.0 * a, 3.0 * a, a, 0.1 * a) > 0.0);
    }

    #[test]
    fn love_rectangle_matches_numerical_integration() {
        // Integral of 1/r over the rectangle by midpoint quadrature on a fine grid, for
        // receivers outside (all sides) and on an edge (integrable singularity).
        let (a, b) = (0.6e-3, 1.7e-3);
        let quad = |x: f64, y: f64| {
            let n = 1200;
            let (hx, hy) = (2.0 * a / n as f64, 2.0 * b / n as f64);
            let mut s = 0.0;
            for i in 0..n {
                for j in 0..n {
                    let u = -a + (i as f64 + 0.5) * hx - x;
                    let v = -b + (j as f64 + 0.5) * hy - y;
                    s += hx * hy / (u * u + v * v).sqrt();
                }
            }
            s
        };
        for &(x, y) in &[
            (2.3e-3, -0.4e-3),
            (0.6e-3, 0.9e-3),
            (-1.1e-3, 2.2e-3),
            (0.0, 5e-3),
        ] {
            let exact = love_rectangle(x, y, a, b);
            let q = quad(x, y);
            assert!((q / exact - 1.0).abs() < 2e-3, "({x}, {y}): {q} vs {exact}");
        }
    }

    #[test]
    fn far_field_expansion_matches_the_closed_form() {
        // Just beyond the switch (6 half sides) for square and elongated cells, all directions.
        let mut worst: f64 = 0.0;
        for &(a, b) in &[(1e-4, 1e-4), (5e-5, 1.1e-3), (1.1e-3, 5e-5)] {
            let m = f64::max(a, b);
            for k in 0..24 {
                let t = k as f64 * std::f64::consts::PI / 12.0;
                for &dist in &[6.01 * m, 9.0 * m, 30.0 * m] {
                    let (x, y) = (dist * t.cos(), dist * t.sin());
                    let exact = love_rectangle(x, y, a, b);
                    worst = worst.max((love_rectangle_fast(x, y, a, b) / exact - 1.0).abs());
                }
            }
        }
        assert!(worst < 2e-4, "far-field relative error {worst:e}");
    }

    #[test]
    fn love_rectangle_is_stable_far_along_the_negative_axes() {
        // Far points in the negative directions must agree with the positive ones (no
        // cancellation in ln(t + R) for t -> -inf).
        let (a, b) = (1e-5, 3e-3);
        for &(x, y) in &[(-0.05, 0.0), (0.0, -0.05), (-0.03, -0.04)] {
            let v = love_rectangle(x, y, a, b);
            let w = love_rectangle(-x, -y, a, b);
            assert!((v / w - 1.0).abs() < 1e-9, "{x} {y}: {v} vs {w}");
        }
    }
}
