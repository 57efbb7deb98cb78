//! Linear elasticity with 20-node serendipity hexahedra (quadratic, 3 x 3 x 3 Gauss points),
//! sparse direct solve (faer Cholesky). SI units: m, Pa, N.

use faer::linalg::solvers::Solve;
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use faer::{Mat, Side};
use rayon::prelude::*;

/// Natural coordinates of the 20 nodes: 8 corners, then the 12 edge midpoints.
pub const NATURAL: [[f64; 3]; 20] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
    [0.0, -1.0, -1.0],
    [1.0, 0.0, -1.0],
    [0.0, 1.0, -1.0],
    [-1.0, 0.0, -1.0],
    [0.0, -1.0, 1.0],
    [1.0, 0.0, 1.0],
    [0.0, 1.0, 1.0],
    [-1.0, 0.0, 1.0],
    [-1.0, -1.0, 0.0],
    [1.0, -1.0, 0.0],
    [1.0, 1.0, 0.0],
    [-1.0, 1.0, 0.0],
];

/// Shape functions and their natural derivatives at (xi, eta, zeta).
pub fn shape(p: [f64; 3]) -> ([f64; 20], [[f64; 3]; 20]) {
    let mut n = [0.0; 20];
    let mut d = [[0.0; 3]; 20];
    for (k, c) in NATURAL.iter().enumerate() {
        let (x, y, z) = (p[0], p[1], p[2]);
        let (a, b, e) = (c[0], c[1], c[2]);
        if a != 0.0 && b != 0.0 && e != 0.0 {
            let (fx, fy, fz) = (1.0 + x * a, 1.0 + y * b, 1.0 + z * e);
            let s = x * a + y * b + z * e - 2.0;
            n[k] = 0.125 * fx * fy * fz * s;
            d[k] = [
                0.125 * a * fy * fz * (s + fx),
                0.125 * b * fx * fz * (s + fy),
                0.125 * e * fx * fy * (s + fz),
            ];
        } else if a == 0.0 {
            let (fy, fz) = (1.0 + y * b, 1.0 + z * e);
            n[k] = 0.25 * (1.0 - x * x) * fy * fz;
            d[k] = [
                -0.5 * x * fy * fz,
                0.25 * (1.0 - x * x) * b * fz,
                0.25 * (1.0 - x * x) * fy * e,
            ];
        } else if b == 0.0 {
            let (fx, fz) = (1.0 + x * a, 1.0 + z * e);
            n[k] = 0.25 * (1.0 - y * y) * fx * fz;
            d[k] = [
                0.25 * (1.0 - y * y) * a * fz,
                -0.5 * y * fx * fz,
                0.25 * (1.0 - y * y) * fx * e,
            ];
        } else {
            let (fx, fy) = (1.0 + x * a, 1.0 + y * b);
            n[k] = 0.25 * (1.0 - z * z) * fx * fy;
            d[k] = [
                0.25 * (1.0 - z * z) * a * fy,
                0.25 * (1.0 - z * z) * fx * b,
                -0.5 * z * fx * fy,
            ];
        }
    }
    (n, d)
}

/// Isotropic elastic material.
#[derive(Debug, Clone, Copy)]
pub struct Elastic {
    /// Young's modulus, Pa.
    pub youngs_modulus: f64,
    pub poisson_ratio: f64,
}

impl Elastic {
    /// 6 x 6 constitutive matrix (Voigt: xx, yy, zz, yz, xz, xy with engineering shears).
    fn d(&self) -> [[f64; 6]; 6] {
        let (e, v) = (self.youngs_modulus, self.poisson_ratio);
        let lam = e * v / ((1.0 + v) * (1.0 - 2.0 * v));
        let mu = e / (2.0 * (1.0 + v));
        let mut d = [[0.0; 6]; 6];
        for i in 0..3 {
            d[i][..3].fill(lam);
            d[i][i] = lam + 2.0 * mu;
            d[i + 3][i + 3] = mu;
        }
        d
    }
}

/// A mesh of 20-node hexahedra.
#[derive(Debug, Clone)]
pub struct Mesh {
    pub nodes: Vec<[f64; 3]>,
    pub elements: Vec<[usize; 20]>,
}

/// Why a finite-element solve failed.
#[derive(Debug, Clone, thiserror::Error)]
pub enum FeError {
    #[error("element {0} has a non-positive Jacobian (inverted or degenerate)")]
    Jacobian(usize),
    #[error("sparse factorisation failed: {0} (is the model restrained against rigid motion?)")]
    Factorisation(String),
    /// The model is larger than [`MAX_FACTOR_NONZEROS`] allows: refused before the element
    /// stiffnesses and the numeric factorisation are computed.
    #[error("{}", too_large(*unknowns, *nonzeros))]
    TooLarge {
        unknowns: usize,
        /// Nonzeros of the factor from the symbolic analysis; None when refused on the
        /// unknowns alone ([`MAX_UNKNOWNS`]).
        nonzeros: Option<usize>,
    },
}

/// The size limits of one solve (the unknowns, the factor's nonzeros).
#[derive(Debug, Clone, Copy)]
struct SizeLimits {
    unknowns: usize,
    factor_nonzeros: usize,
}

impl SizeLimits {
    /// The limits of the bending models: [`MAX_UNKNOWNS`], [`MAX_FACTOR_NONZEROS`].
    const MODEL: Self = Self {
        unknowns: MAX_UNKNOWNS,
        factor_nonzeros: MAX_FACTOR_NONZEROS,
    };
}

/// The text of [`FeError::TooLarge`].
fn too_large(unknowns: usize, nonzeros: Option<usize>) -> String {
    let limit = format!(
        "{:.2e} nonzeros ({:.1} GB), the most one model may use",
        MAX_FACTOR_NONZEROS as f64,
        MAX_FACTOR_NONZEROS as f64 * 8e-9
    );
    match nonzeros {
        Some(n) => format!(
            "the model has {unknowns} unknowns and its Cholesky factor would hold {:.2e} \
             nonzeros ({:.1} GB), above {limit}",
            n as f64,
            n as f64 * 8e-9
        ),
        None => format!(
            "the model has {unknowns} unknowns (more than {MAX_UNKNOWNS}): its Cholesky factor \
             would hold far more than {limit}"
        ),
    }
}

/// The most nonzeros a model's Cholesky factor may hold: 3.75e8 (3 GB of values). Both FE
/// models are built side by side, so two factors of this size and their element matrices
/// fit in 8 GB. Refinement 1 of the reference gears needs 0.3e8 (wheel) and 1.2e8 (worm);
/// refinement 2 about 1e9 each (8 GB each, and minutes of factorisation), which is refused.
pub const MAX_FACTOR_NONZEROS: usize = 375_000_000;

/// The most unknowns a model may have before its pattern is even built: a 20-node hexahedral
/// mesh of 10^6 unknowns has a factor of several 10^9 nonzeros (4.6e5 unknowns already give
/// 1e9), far above [`MAX_FACTOR_NONZEROS`]; this check costs nothing and keeps the refusal of
/// such meshes from taking gigabytes for their pattern.
pub const MAX_UNKNOWNS: usize = 1_000_000;

/// Element stiffness (60 x 60, row-major) of element `e`: K = sum over the 3 x 3 x 3 Gauss
/// points of B^T D B w det J.
pub fn element_stiffness(mesh: &Mesh, e: usize, material: &Elastic) -> Result<Vec<f64>, FeError> {
    let g = [-(0.6f64).sqrt(), 0.0, (0.6f64).sqrt()];
    let w = [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0];
    let d = material.d();
    let x: Vec<[f64; 3]> = mesh.elements[e].iter().map(|&n| mesh.nodes[n]).collect();
    let mut k = vec![0.0; 60 * 60];
    for (ia, &ga) in g.iter().enumerate() {
        for (ib, &gb) in g.iter().enumerate() {
            for (ic, &gc) in g.iter().enumerate() {
                let (_, dn) = shape([ga, gb, gc]);
                let jac = jacobian(&dn, &x);
                let (inv, det) = inverse(&jac).ok_or(FeError::Jacobian(e))?;
                let b = strain_displacement(&dn, &inv);
                add_btdb(&mut k, &b, &d, w[ia] * w[ib] * w[ic] * det);
            }
        }
    }
    Ok(k)
}

/// Jacobian J_ij = d x_j / d xi_i of the map from natural to physical coordinates.
fn jacobian(dn: &[[f64; 3]; 20], x: &[[f64; 3]]) -> [[f64; 3]; 3] {
    let mut jac = [[0.0; 3]; 3];
    for (nd, xn) in dn.iter().zip(x) {
        for i in 0..3 {
            for j in 0..3 {
                jac[i][j] += nd[i] * xn[j];
            }
        }
    }
    jac
}

/// The inverse of a Jacobian and its determinant; None when the determinant is not positive
/// (an inverted or degenerate element).
fn inverse(jac: &[[f64; 3]; 3]) -> Option<([[f64; 3]; 3], f64)> {
    let det = jac[0][0] * (jac[1][1] * jac[2][2] - jac[1][2] * jac[2][1])
        - jac[0][1] * (jac[1][0] * jac[2][2] - jac[1][2] * jac[2][0])
        + jac[0][2] * (jac[1][0] * jac[2][1] - jac[1][1] * jac[2][0]);
    if det <= 0.0 {
        return None;
    }
    let inv = [
        [
            (jac[1][1] * jac[2][2] - jac[1][2] * jac[2][1]) / det,
            (jac[0][2] * jac[2][1] - jac[0][1] * jac[2][2]) / det,
            (jac[0][1] * jac[1][2] - jac[0][2] * jac[1][1]) / det,
        ],
        [
            (jac[1][2] * jac[2][0] - jac[1][0] * jac[2][2]) / det,
            (jac[0][0] * jac[2][2] - jac[0][2] * jac[2][0]) / det,
            (jac[0][2] * jac[1][0] - jac[0][0] * jac[1][2]) / det,
        ],
        [
            (jac[1][0] * jac[2][1] - jac[1][1] * jac[2][0]) / det,
            (jac[0][1] * jac[2][0] - jac[0][0] * jac[2][1]) / det,
            (jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0]) / det,
        ],
    ];
    Some((inv, det))
}

/// Strain-displacement matrix B (6 x 60, Voigt order xx, yy, zz, yz, xz, xy) from the natural
/// derivatives of the shape functions and the inverse Jacobian: dN/dx_j = sum_i inv[j][i]
/// dN/dxi_i.
fn strain_displacement(dn: &[[f64; 3]; 20], inv: &[[f64; 3]; 3]) -> [[f64; 60]; 6] {
    let mut b = [[0.0; 60]; 6];
    for (n, nd) in dn.iter().enumerate() {
        let dx = [
            inv[0][0] * nd[0] + inv[0][1] * nd[1] + inv[0][2] * nd[2],
            inv[1][0] * nd[0] + inv[1][1] * nd[1] + inv[1][2] * nd[2],
            inv[2][0] * nd[0] + inv[2][1] * nd[1] + inv[2][2] * nd[2],
        ];
        let c0 = 3 * n;
        b[0][c0] = dx[0];
        b[1][c0 + 1] = dx[1];
        b[2][c0 + 2] = dx[2];
        b[3][c0 + 1] = dx[2];
        b[3][c0 + 2] = dx[1];
        b[4][c0] = dx[2];
        b[4][c0 + 2] = dx[0];
        b[5][c0] = dx[1];
        b[5][c0 + 1] = dx[0];
    }
    b
}

/// K += B^T D B weight (K row-major 60 x 60).
fn add_btdb(k: &mut [f64], b: &[[f64; 60]; 6], d: &[[f64; 6]; 6], weight: f64) {
    let mut db = [[0.0; 60]; 6];
    for i in 0..6 {
        for j in 0..6 {
            if d[i][j] != 0.0 {
                for col in 0..60 {
                    db[i][col] += d[i][j] * b[j][col];
                }
            }
        }
    }
    for r in 0..60 {
        for i in 0..6 {
            let bri = b[i][r];
            if bri != 0.0 {
                let row = &mut k[r * 60..(r + 1) * 60];
                for (col, v) in row.iter_mut().enumerate() {
                    *v += bri * db[i][col] * weight;
                }
            }
        }
    }
}

/// Prescribed displacement of one degree of freedom (node, direction 0..3, value m).
pub type Fixed = (usize, usize, f64);
/// Nodal force (node, direction, value N).
pub type Load = (usize, usize, f64);

/// Grounded spring on a linear combination of nodal displacements: stiffness k (N/m) times
/// (sum_i d_i . u_(node_i))^2 / 2 is added to the energy, i.e. k v v^T to the stiffness. One
/// term: a spring on one node along d (a bearing's radial support); many: a soft constraint on
/// a mean displacement (the torque reaction on the mean tangential displacement of a ring,
/// which leaves its lateral motion and tilt free).
#[derive(Debug, Clone)]
pub struct Spring {
    pub terms: Vec<(usize, [f64; 3])>,
    pub stiffness: f64,
}

/// Solves K u = f with the prescribed displacements eliminated; returns the displacement of
/// every node (m). Several load cases share one factorisation.
pub fn solve(
    mesh: &Mesh,
    material: &Elastic,
    fixed: &[Fixed],
    loads: &[Vec<Load>],
) -> Result<Vec<Vec<[f64; 3]>>, FeError> {
    solve_with_springs(mesh, material, fixed, &[], loads)
}

/// As [`solve`], with grounded springs added to the stiffness.
pub fn solve_with_springs(
    mesh: &Mesh,
    material: &Elastic,
    fixed: &[Fixed],
    springs: &[Spring],
    loads: &[Vec<Load>],
) -> Result<Vec<Vec<[f64; 3]>>, FeError> {
    let elements = element_stiffnesses(mesh, material)?;
    let solution = solve_assembled(mesh, &elements, fixed, springs, loads)?;
    Ok((0..loads.len())
        .map(|c| (0..mesh.nodes.len()).map(|n| solution.at(c, n)).collect())
        .collect())
}

/// Stiffness matrices of all elements (row-major 60 x 60 each), computed in parallel.
pub fn element_stiffnesses(mesh: &Mesh, material: &Elastic) -> Result<Vec<Vec<f64>>, FeError> {
    (0..mesh.elements.len())
        .into_par_iter()
        .map(|e| element_stiffness(mesh, e, material))
        .collect()
}

/// Lower triangle of the free-free stiffness in compressed columns, assembled in place: the
/// pattern comes from the node graph (nodes sharing an element or a spring), so no triplet list
/// is built or sorted. Rows of each column are sorted; `position` finds an entry.
struct LowerPattern {
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
}

impl LowerPattern {
    fn new(mesh: &Mesh, springs: &[Spring], map: &[usize], free: usize) -> Self {
        let nn = mesh.nodes.len();
        let mut adjacent: Vec<Vec<u32>> = vec![Vec::new(); nn];
        for e in &mesh.elements {
            for &a in e {
                adjacent[a].extend(e.iter().map(|&b| b as u32));
            }
        }
        for spring in springs {
            for &(a, _) in &spring.terms {
                adjacent[a].extend(spring.terms.iter().map(|&(b, _)| b as u32));
            }
        }
        adjacent.par_iter_mut().for_each(|list| {
            list.sort_unstable();
            list.dedup();
        });
        let mut col_ptr = Vec::with_capacity(free + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for (n, list) in adjacent.iter().enumerate() {
            for d in 0..3 {
                let g = 3 * n + d;
                if map[g] == usize::MAX {
                    continue;
                }
                for &m in list {
                    for dd in 0..3 {
                        let gr = 3 * m as usize + dd;
                        if gr >= g && map[gr] != usize::MAX {
                            row_idx.push(map[gr]);
                        }
                    }
                }
                col_ptr.push(row_idx.len());
            }
        }
        Self { col_ptr, row_idx }
    }

    /// The pattern as faer's symbolic matrix (n x n, lower triangle).
    fn symbolic(&self, n: usize) -> faer::sparse::SymbolicSparseColMatRef<'_, usize> {
        faer::sparse::SymbolicSparseColMatRef::new_checked(n, n, &self.col_ptr, None, &self.row_idx)
    }

    #[inline]
    fn position(&self, row: usize, col: usize) -> usize {
        let (a, b) = (self.col_ptr[col], self.col_ptr[col + 1]);
        let p = a + self.row_idx[a..b].partition_point(|&r| r < row);
        debug_assert!(p < b && self.row_idx[p] == row, "entry outside the pattern");
        p
    }
}

/// Solves with element stiffnesses already computed (shared by runs on the same mesh).
fn solve_assembled(
    mesh: &Mesh,
    elements: &[Vec<f64>],
    fixed: &[Fixed],
    springs: &[Spring],
    loads: &[Vec<Load>],
) -> Result<Solution, FeError> {
    let system = assemble(mesh, elements, fixed, springs, loads);
    let llt = system
        .matrix
        .sp_cholesky(Side::Lower)
        .map_err(|e| FeError::Factorisation(format!("{e:?}")))?;
    Ok(Solution {
        x: llt.solve(&system.rhs),
        map: system.map,
        prescribed: system.prescribed,
    })
}

/// The assembled linear system of one run: the free-free stiffness (lower triangle, free-DOF
/// numbering), the right-hand sides of the load cases (N), and the DOF bookkeeping.
struct System {
    matrix: SparseColMat<usize, f64>,
    rhs: Mat<f64>,
    /// Free-DOF index of every global DOF (usize::MAX where prescribed).
    map: Vec<usize>,
    prescribed: Vec<Option<f64>>,
}

/// Assembles the stiffness with the prescribed displacements eliminated (moved to the
/// right-hand sides) and the springs added.
fn assemble(
    mesh: &Mesh,
    elements: &[Vec<f64>],
    fixed: &[Fixed],
    springs: &[Spring],
    loads: &[Vec<Load>],
) -> System {
    let dofs = Dofs::new(mesh, fixed);
    let pattern = LowerPattern::new(mesh, springs, &dofs.map, dofs.free);
    fill(mesh, elements, springs, loads, dofs, pattern)
}

/// The DOF bookkeeping of one run: the prescribed value of every global DOF and its free index.
struct Dofs {
    prescribed: Vec<Option<f64>>,
    /// Free-DOF index of every global DOF (usize::MAX where prescribed).
    map: Vec<usize>,
    free: usize,
}

impl Dofs {
    fn new(mesh: &Mesh, fixed: &[Fixed]) -> Self {
        let ndof = 3 * mesh.nodes.len();
        let mut prescribed = vec![None; ndof];
        for &(n, d, v) in fixed {
            prescribed[3 * n + d] = Some(v);
        }
        let mut map = vec![usize::MAX; ndof];
        let mut free = 0;
        for (i, p) in prescribed.iter().enumerate() {
            if p.is_none() {
                map[i] = free;
                free += 1;
            }
        }
        Self {
            prescribed,
            map,
            free,
        }
    }
}

/// The stiffness values on `pattern` and the right-hand sides (see [`assemble`]).
fn fill(
    mesh: &Mesh,
    elements: &[Vec<f64>],
    springs: &[Spring],
    loads: &[Vec<Load>],
    dofs: Dofs,
    pattern: LowerPattern,
) -> System {
    let Dofs {
        prescribed,
        map,
        free,
    } = dofs;
    let mut values = vec![0.0; pattern.row_idx.len()];
    let ncase = loads.len();
    let mut rhs = Mat::<f64>::zeros(free, ncase);
    for (c, case) in loads.iter().enumerate() {
        for &(n, d, v) in case {
            let g = 3 * n + d;
            if map[g] != usize::MAX {
                rhs[(map[g], c)] += v;
            }
        }
    }
    // Stiffness entry (free row fr, global column gc): into the matrix (lower triangle) when
    // the column is free, onto the right-hand sides when it is prescribed.
    let mut scatter = |fr: usize, gc: usize, v: f64| match prescribed[gc] {
        Some(u) => {
            for case in 0..ncase {
                rhs[(fr, case)] -= v * u;
            }
        }
        None => {
            let fc = map[gc];
            if fc <= fr {
                values[pattern.position(fr, fc)] += v;
            }
        }
    };
    for (e, k) in mesh.elements.iter().zip(elements) {
        let dofs: Vec<usize> = e
            .iter()
            .flat_map(|&n| [3 * n, 3 * n + 1, 3 * n + 2])
            .collect();
        for (r, &gr) in dofs.iter().enumerate() {
            let fr = map[gr];
            if fr == usize::MAX {
                continue;
            }
            for (c, &gc) in dofs.iter().enumerate() {
                scatter(fr, gc, k[r * 60 + c]);
            }
        }
    }
    for spring in springs {
        let dofs: Vec<(usize, f64)> = spring
            .terms
            .iter()
            .flat_map(|&(n, d)| (0..3).map(move |c| (3 * n + c, d[c])))
            .filter(|&(_, w)| w != 0.0)
            .collect();
        for &(gr, wr) in &dofs {
            let fr = map[gr];
            if fr == usize::MAX {
                continue;
            }
            for &(gc, wc) in &dofs {
                scatter(fr, gc, spring.stiffness * wr * wc);
            }
        }
    }
    let symbolic =
        SymbolicSparseColMat::new_checked(free, free, pattern.col_ptr, None, pattern.row_idx);
    System {
        matrix: SparseColMat::<usize, f64>::new(symbolic, values),
        rhs,
        map,
        prescribed,
    }
}

/// The free run (`fixed` only) minus the blocked run (also the `blocked` nodes held at zero)
/// of the same mesh and loads, from ONE Cholesky factorisation (MODEL §5.5 step 2). The
/// blocked DOFs B are ordered last (AMD order for the others, R), so with A = L L^T the leading
/// block L_RR of L is the Cholesky factor of the blocked run's matrix A_RR. Forward
/// substitution y = L^-1 f serves both runs (its R part does not see f_B); the free run is
/// L^-T y and the blocked run L^-T [y_R; 0] (x_R = A_RR^-1 f_R, x_B = 0, its loads on blocked
/// nodes vanishing as they do for prescribed DOFs), so their difference is L^-T [0; y_B]: one
/// factorisation and two triangular solves instead of two factorisations and four. The
/// prescribed displacements are the same in both runs, so the difference is zero there.
///
/// The size is checked before anything large is computed: the unknowns against
/// [`MAX_UNKNOWNS`], then the factor's nonzeros from the symbolic analysis against
/// [`MAX_FACTOR_NONZEROS`] ([`FeError::TooLarge`]); only then the element stiffnesses.
fn solve_free_minus_blocked(
    mesh: &Mesh,
    material: &Elastic,
    fixed: &[Fixed],
    springs: &[Spring],
    blocked: &[usize],
    loads: &[Vec<Load>],
    limits: SizeLimits,
) -> Result<Solution, FeError> {
    let dofs = Dofs::new(mesh, fixed);
    if dofs.free > limits.unknowns {
        return Err(FeError::TooLarge {
            unknowns: dofs.free,
            nonzeros: None,
        });
    }
    let pattern = LowerPattern::new(mesh, springs, &dofs.map, dofs.free);
    let factor = BlockedLast::analyse(&pattern, &dofs, blocked, limits)?;
    let elements = element_stiffnesses(mesh, material)?;
    let system = fill(mesh, &elements, springs, loads, dofs, pattern);
    drop(elements);
    let x = factor.difference(system.matrix, system.rhs)?;
    let mut prescribed = system.prescribed;
    for p in prescribed.iter_mut().flatten() {
        *p = 0.0;
    }
    Ok(Solution {
        x,
        map: system.map,
        prescribed,
    })
}

/// The symbolic Cholesky factor of a run's free-free stiffness with the blocked DOFs ordered
/// last ([`order_blocked_last`]), see [`solve_free_minus_blocked`].
struct BlockedLast {
    /// New -> old and old -> new free-DOF order.
    forward: Vec<usize>,
    inverse: Vec<usize>,
    /// The unknowns before the blocked ones.
    unblocked: usize,
    symbolic: faer::sparse::linalg::cholesky::SymbolicCholesky<usize>,
}

impl BlockedLast {
    /// Orders and analyses `pattern`; refuses a factor above `limits.factor_nonzeros`.
    fn analyse(
        pattern: &LowerPattern,
        dofs: &Dofs,
        blocked: &[usize],
        limits: SizeLimits,
    ) -> Result<Self, FeError> {
        use faer::sparse::linalg::cholesky::{
            factorize_symbolic_cholesky, CholeskySymbolicParams, SymmetricOrdering,
        };
        let free = dofs.free;
        let mut is_blocked = vec![false; free];
        for &n in blocked {
            for d in 0..3 {
                let g = 3 * n + d;
                if dofs.map[g] != usize::MAX {
                    is_blocked[dofs.map[g]] = true;
                }
            }
        }
        let (forward, inverse, unblocked) =
            order_blocked_last(pattern.symbolic(free), &is_blocked)?;
        let perm = faer::perm::PermRef::new_checked(&forward, &inverse, free);
        let symbolic = factorize_symbolic_cholesky(
            pattern.symbolic(free),
            Side::Lower,
            SymmetricOrdering::Custom(perm),
            CholeskySymbolicParams::default(),
        )
        .map_err(|e| FeError::Factorisation(format!("{e:?}")))?;
        if symbolic.len_val() > limits.factor_nonzeros {
            return Err(FeError::TooLarge {
                unknowns: free,
                nonzeros: Some(symbolic.len_val()),
            });
        }
        Ok(Self {
            forward,
            inverse,
            unblocked,
            symbolic,
        })
    }

    /// Factorises `matrix` and returns the free run minus the blocked run of every case of
    /// `rhs` (free-DOF numbering): L^-T [0; y_B] with y = L^-1 f.
    fn difference(
        &self,
        matrix: SparseColMat<usize, f64>,
        rhs: Mat<f64>,
    ) -> Result<Mat<f64>, FeError> {
        use faer::dyn_stack::{MemBuffer, MemStack};
        let symbolic = &self.symbolic;
        let (free, cases) = (rhs.nrows(), rhs.ncols());
        let par = faer::get_global_parallelism();
        let mut values = vec![0.0; symbolic.len_val()];
        let mut mem = MemBuffer::new(
            symbolic
                .factorize_numeric_llt_scratch::<f64>(par, Default::default())
                .or(symbolic.solve_in_place_scratch::<f64>(cases, par)),
        );
        symbolic
            .factorize_numeric_llt(
                &mut values,
                matrix.as_ref(),
                Side::Lower,
                faer::linalg::cholesky::llt::factor::LltRegularization::default(),
                par,
                MemStack::new(&mut mem),
                Default::default(),
            )
            .map_err(|e| FeError::Factorisation(format!("{e:?}")))?;
        drop(matrix);
        let mut y = Mat::<f64>::from_fn(free, cases, |i, c| rhs[(self.forward[i], c)]);
        drop(rhs);
        lower_solve(symbolic, &values, y.as_mut(), false, par, &mut mem);
        for c in 0..cases {
            for i in 0..self.unblocked {
                y[(i, c)] = 0.0;
            }
        }
        lower_solve(symbolic, &values, y.as_mut(), true, par, &mut mem);
        Ok(Mat::<f64>::from_fn(free, cases, |i, c| {
            y[(self.inverse[i], c)]
        }))
    }
}

/// Fill-reducing order with the `last` unknowns at the end: AMD on the matrix without them,
/// then them in their own order. Returns (forward: new -> old, inverse: old -> new, the number
/// of unknowns before the last ones).
fn order_blocked_last(
    matrix: faer::sparse::SymbolicSparseColMatRef<'_, usize>,
    last: &[bool],
) -> Result<(Vec<usize>, Vec<usize>, usize), FeError> {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::sparse::linalg::amd;
    let n = last.len();
    let mut local = vec![usize::MAX; n];
    let kept: Vec<usize> = (0..n).filter(|&i| !last[i]).collect();
    for (k, &i) in kept.iter().enumerate() {
        local[i] = k;
    }
    let (col_ptr, row_idx) = (matrix.col_ptr(), matrix.row_idx());
    let mut ptr = Vec::with_capacity(kept.len() + 1);
    let mut rows = Vec::new();
    ptr.push(0);
    for &c in &kept {
        rows.extend(
            row_idx[col_ptr[c]..col_ptr[c + 1]]
                .iter()
                .filter(|&&r| !last[r])
                .map(|&r| local[r]),
        );
        ptr.push(rows.len());
    }
    let m = kept.len();
    let nnz = rows.len();
    let pattern = SymbolicSparseColMat::new_checked(m, m, ptr, None, rows);
    let (mut fwd, mut inv) = (vec![0usize; m], vec![0usize; m]);
    let mut mem = MemBuffer::new(amd::order_scratch::<usize>(m, nnz));
    amd::order(
        &mut fwd,
        &mut inv,
        pattern.as_ref(),
        amd::Control::default(),
        MemStack::new(&mut mem),
    )
    .map_err(|e| FeError::Factorisation(format!("{e:?}")))?;
    let mut forward: Vec<usize> = fwd.iter().map(|&k| kept[k]).collect();
    forward.extend((0..n).filter(|&i| last[i]));
    let mut inverse = vec![0; n];
    for (new, &old) in forward.iter().enumerate() {
        inverse[old] = new;
    }
    Ok((forward, inverse, m))
}

/// In place, on the permuted unknowns: rhs <- L^-1 rhs, or L^-T rhs when `transpose`.
fn lower_solve(
    symbolic: &faer::sparse::linalg::cholesky::SymbolicCholesky<usize>,
    values: &[f64],
    rhs: faer::MatMut<'_, f64>,
    transpose: bool,
    par: faer::Par,
    mem: &mut faer::dyn_stack::MemBuffer,
) {
    use faer::sparse::linalg::cholesky::{supernodal::SupernodalLltRef, SymbolicCholeskyRaw};
    use faer::sparse::linalg::triangular_solve;
    use faer::Conj;
    let stack = faer::dyn_stack::MemStack::new(mem);
    match symbolic.raw() {
        SymbolicCholeskyRaw::Simplicial(s) => {
            let l = faer::sparse::SparseColMatRef::<'_, usize, f64>::new(s.factor(), values);
            if transpose {
                triangular_solve::solve_lower_triangular_transpose_in_place(l, Conj::No, rhs, par);
            } else {
                triangular_solve::solve_lower_triangular_in_place(l, Conj::No, rhs, par);
            }
        }
        SymbolicCholeskyRaw::Supernodal(s) => {
            let l = SupernodalLltRef::new(s, values);
            if transpose {
                l.l_transpose_solve_with_conj(Conj::No, rhs, par, stack);
            } else {
                l.l_solve_with_conj(Conj::No, rhs, par, stack);
            }
        }
    }
}

/// Displacements of every load case in the free-DOF numbering of one run.
#[derive(Debug)]
struct Solution {
    /// free DOFs x cases, m.
    x: Mat<f64>,
    map: Vec<usize>,
    prescribed: Vec<Option<f64>>,
}

impl Solution {
    /// Displacement of a node under case c, m.
    fn at(&self, c: usize, n: usize) -> [f64; 3] {
        let mut u = [0.0; 3];
        for (d, ud) in u.iter_mut().enumerate() {
            let g = 3 * n + d;
            *ud = match self.prescribed[g] {
                Some(v) => v,
                None => self.x[(self.map[g], c)],
            };
        }
        u
    }
}

/// Structured mesh of the box [0, lx] x [0, ly] x [0, lz] with nx x ny x nz elements; `map`
/// moves every node (e.g. to distort or bend the box). Also returns the lattice index of every
/// node (half-element steps).
pub fn box_mesh(
    (lx, ly, lz): (f64, f64, f64),
    (nx, ny, nz): (usize, usize, usize),
    map: impl Fn([f64; 3]) -> [f64; 3],
) -> (Mesh, Vec<[usize; 3]>) {
    let (mx, my, mz) = (2 * nx + 1, 2 * ny + 1, 2 * nz + 1);
    let mut index = vec![usize::MAX; mx * my * mz];
    let mut nodes = Vec::new();
    let mut lattice = Vec::new();
    for k in 0..mz {
        for j in 0..my {
            for i in 0..mx {
                let odd = (i % 2) + (j % 2) + (k % 2);
                if odd <= 1 {
                    index[(k * my + j) * mx + i] = nodes.len();
                    let p = [
                        lx * i as f64 / (mx - 1) as f64,
                        ly * j as f64 / (my - 1) as f64,
                        lz * k as f64 / (mz - 1) as f64,
                    ];
                    nodes.push(map(p));
                    lattice.push([i, j, k]);
                }
            }
        }
    }
    let mut elements = Vec::new();
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let mut e = [0; 20];
                for (a, c) in NATURAL.iter().enumerate() {
                    let (li, lj, lk) = (
                        (2 * i as i64 + 1 + c[0] as i64) as usize,
                        (2 * j as i64 + 1 + c[1] as i64) as usize,
                        (2 * k as i64 + 1 + c[2] as i64) as usize,
                    );
                    e[a] = index[(lk * my + lj) * mx + li];
                }
                elements.push(e);
            }
        }
    }
    (Mesh { nodes, elements }, lattice)
}

/// CalculiX / Abaqus input deck of a linear static analysis of `mesh` (C3D20 elements, whose
/// node order is this module's), for independent checks. Units as given (SI).
pub fn calculix_deck(mesh: &Mesh, material: &Elastic, fixed: &[Fixed], loads: &[Load]) -> String {
    use std::fmt::Write;
    let mut s = String::from("*HEADING\nwormwear FE check\n*NODE, NSET=NALL\n");
    for (i, p) in mesh.nodes.iter().enumerate() {
        let _ = writeln!(s, "{}, {:.12e}, {:.12e}, {:.12e}", i + 1, p[0], p[1], p[2]);
    }
    s.push_str("*ELEMENT, TYPE=C3D20, ELSET=EALL\n");
    for (e, nodes) in mesh.elements.iter().enumerate() {
        let ids: Vec<String> = nodes.iter().map(|n| (n + 1).to_string()).collect();
        // 20 nodes: 15 on the first line, the rest on a continuation line.
        let _ = writeln!(
            s,
            "{}, {},\n{}",
            e + 1,
            ids[..15].join(", "),
            ids[15..].join(", ")
        );
    }
    let _ = write!(
        s,
        "*MATERIAL, NAME=M\n*ELASTIC\n{:.12e}, {:.12e}\n*SOLID SECTION, ELSET=EALL, MATERIAL=M\n*STEP\n*STATIC\n*BOUNDARY\n",
        material.youngs_modulus, material.poisson_ratio
    );
    for &(n, d, v) in fixed {
        let _ = writeln!(s, "{}, {}, {}, {:.12e}", n + 1, d + 1, d + 1, v);
    }
    s.push_str("*CLOAD\n");
    for &(n, d, v) in loads {
        let _ = writeln!(s, "{}, {}, {:.12e}", n + 1, d + 1, v);
    }
    s.push_str("*NODE PRINT, NSET=NALL\nU\n*END STEP\n");
    s
}

/// Reads the nodal displacements of a CalculiX `.dat` file written by `*NODE PRINT ... U`.
pub fn read_calculix_displacements(dat: &str, nodes: usize) -> Option<Vec<[f64; 3]>> {
    let mut u = vec![[f64::NAN; 3]; nodes];
    let mut in_block = false;
    for line in dat.lines() {
        if line.contains("displacements") {
            in_block = true;
            continue;
        }
        if !in_block {
            continue;
        }
        let parts: Vec<&str> = line.split_whitespace().collect();
        if parts.len() == 4 {
            let id: usize = parts[0].parse().ok()?;
            let vals: Vec<f64> = parts[1..]
                .iter()
                .map(|v| v.parse().ok())
                .collect::<Option<_>>()?;
            if id >= 1 && id <= nodes {
                u[id - 1] = [vals[0], vals[1], vals[2]];
            }
        }
    }
    u.iter().all(|v| v[0].is_finite()).then_some(u)
}

/// Volume of element `e` (Gauss integration of det J), m^3.
pub fn element_volume(mesh: &Mesh, e: usize) -> f64 {
    let g = [-(0.6f64).sqrt(), 0.0, (0.6f64).sqrt()];
    let w = [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0];
    let x: Vec<[f64; 3]> = mesh.elements[e].iter().map(|&n| mesh.nodes[n]).collect();
    let mut v = 0.0;
    for (ia, &ga) in g.iter().enumerate() {
        for (ib, &gb) in g.iter().enumerate() {
            for (ic, &gc) in g.iter().enumerate() {
                let (_, dn) = shape([ga, gb, gc]);
                let mut j = [[0.0; 3]; 3];
                for (nd, xn) in dn.iter().zip(&x) {
                    for i in 0..3 {
                        for k in 0..3 {
                            j[i][k] += nd[i] * xn[k];
                        }
                    }
                }
                let det = j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1])
                    - j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0])
                    + j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0]);
                v += w[ia] * w[ib] * w[ic] * det;
            }
        }
    }
    v
}

/// Jacobian determinant of element `nodes` (20 corner/mid-side coordinates) at its centre.
pub fn centre_jacobian(x: &[[f64; 3]; 20]) -> f64 {
    let (_, dn) = shape([0.0, 0.0, 0.0]);
    let mut jac = [[0.0; 3]; 3];
    for (nd, xn) in dn.iter().zip(x) {
        for i in 0..3 {
            for j in 0..3 {
                jac[i][j] += nd[i] * xn[j];
            }
        }
    }
    jac[0][0] * (jac[1][1] * jac[2][2] - jac[1][2] * jac[2][1])
        - jac[0][1] * (jac[1][0] * jac[2][2] - jac[1][2] * jac[2][0])
        + jac[0][2] * (jac[1][0] * jac[2][1] - jac[1][1] * jac[2][0])
}

/// The element with its third natural coordinate reversed (mirror numbering): turns a
/// left-handed node order into a right-handed one.
pub fn mirrored(e: [usize; 20]) -> [usize; 20] {
    let mut out = e;
    for (a, c) in NATURAL.iter().enumerate() {
        let b = NATURAL
            .iter()
            .position(|d| d[0] == c[0] && d[1] == c[1] && d[2] == -c[2])
            .unwrap_or(a);
        out[b] = e[a];
    }
    out
}

/// Bending displacements by the free / blocked technique (MODEL §5.5 step 2): for each load
/// case a unit force into the member (along -n) at a node; the displacement with the loaded
/// tooth's opposite flank free minus that with its `blocked` nodes fixed (removes the local
/// contact deformation, keeps the bending), at the `observed` nodes. Both runs come from one
/// factorisation ([`solve_free_minus_blocked`]). Index: [case][observed k], m/N.
pub fn free_minus_blocked(
    mesh: &Mesh,
    material: &Elastic,
    fixed: &[Fixed],
    springs: &[Spring],
    blocked: &[usize],
    loads: &[(usize, nalgebra::Vector3<f64>)],
    observed: &[usize],
) -> Result<Vec<Vec<[f64; 3]>>, FeError> {
    let cases: Vec<Vec<Load>> = loads
        .iter()
        .map(|(n, nrm)| (0..3).map(|d| (*n, d, -nrm[d])).collect())
        .collect();
    let difference = solve_free_minus_blocked(
        mesh,
        material,
        fixed,
        springs,
        blocked,
        &cases,
        SizeLimits::MODEL,
    )?;
    Ok((0..cases.len())
        .map(|c| observed.iter().map(|&n| difference.at(c, n)).collect())
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    const STEEL: Elastic = Elastic {
        youngs_modulus: 210e9,
        poisson_ratio: 0.3,
    };

    /// A clamped cantilever box: its fixed DOFs and one tip load case.
    fn cantilever(n: usize) -> (Mesh, Vec<Fixed>, Vec<Vec<Load>>) {
        let (mesh, lattice) = box_mesh((0.04, 0.01, 0.01), (4 * n, n, n), |p| p);
        let fixed = lattice
            .iter()
            .enumerate()
            .filter(|(_, ijk)| ijk[0] == 0)
            .flat_map(|(k, _)| (0..3).map(move |d| (k, d, 0.0)))
            .collect();
        let tip = lattice.iter().position(|ijk| ijk[0] == 8 * n).unwrap();
        (mesh, fixed, vec![vec![(tip, 1, -1.0)]])
    }

    #[test]
    fn a_model_whose_factor_exceeds_the_limit_is_refused_before_it_is_built() {
        let (mesh, fixed, loads) = cantilever(2);
        let unlimited = SizeLimits {
            unknowns: usize::MAX,
            factor_nonzeros: usize::MAX,
        };
        let solve =
            |limits| solve_free_minus_blocked(&mesh, &STEEL, &fixed, &[], &[], &loads, limits);
        assert!(solve(unlimited).is_ok());
        // The factor holds more nonzeros than the lower triangle of the matrix.
        let dofs = Dofs::new(&mesh, &fixed);
        let nnz_lower = LowerPattern::new(&mesh, &[], &dofs.map, dofs.free)
            .row_idx
            .len();
        match solve(SizeLimits {
            factor_nonzeros: nnz_lower,
            ..unlimited
        }) {
            Err(FeError::TooLarge {
                nonzeros: Some(n), ..
            }) => assert!(n > nnz_lower),
            other => panic!("expected TooLarge with the factor's size, got {other:?}"),
        }
        match solve(SizeLimits {
            unknowns: dofs.free - 1,
            ..unlimited
        }) {
            Err(FeError::TooLarge {
                unknowns,
                nonzeros: None,
            }) => assert_eq!(unknowns, dofs.free),
            other => panic!("expected TooLarge on the unknowns, got {other:?}"),
        }
    }
}
