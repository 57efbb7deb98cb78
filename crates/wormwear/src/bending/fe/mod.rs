//! Linear elasticity with 20-node serendipity hexahedra (quadratic, 3 x 3 x 3 Gauss points),
//! sparse direct solve (faer Cholesky). SI units: m, Pa, N.
//!
//! Rooms: here the element (shape functions, stiffness), the material, the mesh, the errors and
//! size limits, and the solves a model calls; `system` the assembled system and its
//! factorisation; `checks` boxes, CalculiX decks and element measures for the tests.

use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use faer::{Mat, Side};
use rayon::prelude::*;

mod checks;
mod congruence;
mod ordering;
mod system;

pub use checks::*;
pub use congruence::{element_stiffnesses, ElementStiffnesses};
use ordering::*;
pub(crate) use system::KeptFactor;
use system::*;

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

/// Stress at the natural point `xi` of element `e` from the nodal displacements `u` (m, every
/// node of the mesh): sigma = D B u_e, Voigt order xx, yy, zz, yz, xz, xy, Pa.
pub fn element_stress(
    mesh: &Mesh,
    e: usize,
    material: &Elastic,
    u: &[[f64; 3]],
    xi: [f64; 3],
) -> Result<[f64; 6], FeError> {
    let x: Vec<[f64; 3]> = mesh.elements[e].iter().map(|&n| mesh.nodes[n]).collect();
    let (_, dn) = shape(xi);
    let (inv, _) = inverse(&jacobian(&dn, &x)).ok_or(FeError::Jacobian(e))?;
    let b = strain_displacement(&dn, &inv);
    let mut strain = [0.0; 6];
    for (k, &n) in mesh.elements[e].iter().enumerate() {
        for d in 0..3 {
            let un = u[n][d];
            for (i, row) in b.iter().enumerate() {
                strain[i] += row[3 * k + d] * un;
            }
        }
    }
    let d = material.d();
    let mut stress = [0.0; 6];
    for (i, si) in stress.iter_mut().enumerate() {
        *si = (0..6).map(|j| d[i][j] * strain[j]).sum();
    }
    Ok(stress)
}

/// The natural coordinates of the physical point `p` (m) in element `e`, by Newton's method on
/// x(xi) = sum N_i(xi) x_i from the element's centre; None when it does not converge or the
/// point lies outside the element (beyond 1e-6 of its natural cube).
pub fn natural_coordinates(mesh: &Mesh, e: usize, p: [f64; 3]) -> Option<[f64; 3]> {
    let x: Vec<[f64; 3]> = mesh.elements[e].iter().map(|&n| mesh.nodes[n]).collect();
    let mut xi = [0.0; 3];
    for _ in 0..30 {
        let (n, dn) = shape(xi);
        let mut r = p;
        for (w, xn) in n.iter().zip(&x) {
            for d in 0..3 {
                r[d] -= w * xn[d];
            }
        }
        let (inv, _) = inverse(&jacobian(&dn, &x))?;
        // dxi_i = sum_j (J^-T)_ij r_j with J_ij = dx_j / dxi_i: inv[j][i] = d xi_i / d x_j.
        let step: [f64; 3] = std::array::from_fn(|i| (0..3).map(|j| inv[j][i] * r[j]).sum());
        for i in 0..3 {
            xi[i] += step[i];
        }
        if step.iter().all(|s| s.abs() < 1e-12) {
            return xi.iter().all(|v| v.abs() <= 1.0 + 1e-6).then_some(xi);
        }
        if xi.iter().any(|v| v.abs() > 3.0) {
            return None;
        }
    }
    None
}

/// The principal stresses of a Voigt stress (xx, yy, zz, yz, xz, xy), largest first, Pa.
pub fn principal_stresses(s: [f64; 6]) -> [f64; 3] {
    let m = nalgebra::Matrix3::new(s[0], s[5], s[4], s[5], s[1], s[3], s[4], s[3], s[2]);
    let mut v: Vec<f64> = m.symmetric_eigenvalues().iter().copied().collect();
    v.sort_by(|a, b| b.total_cmp(a));
    [v[0], v[1], v[2]]
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

/// Bending displacements by the free / blocked technique (MODEL §5.5 step 2): for each load
/// case a unit force into the member (along -n) at a node; the displacement with the loaded
/// tooth's opposite flank free minus that with its `blocked` nodes fixed (removes the local
/// contact deformation, keeps the bending), at the `observed` nodes. Both runs come from one
/// factorisation (`system::solve_free_minus_blocked`). Index: [case][observed k], m/N.
pub fn free_minus_blocked(
    mesh: &Mesh,
    material: &Elastic,
    supports: (&[Fixed], &[Spring]),
    blocked: &[usize],
    loads: &[(usize, nalgebra::Vector3<f64>)],
    observed: &[usize],
) -> Result<Vec<Vec<[f64; 3]>>, FeError> {
    let no_plain: &[Vec<Load>] = &[];
    free_minus_blocked_and_free(
        mesh,
        material,
        supports,
        blocked,
        (loads, observed),
        (no_plain, &[]),
    )
    .map(|(bending, _)| bending)
}

/// Displacements of several load cases at a set of nodes, [case][node], m (or m/N).
pub type CaseDisplacements = Vec<Vec<[f64; 3]>>;

/// [`free_minus_blocked`] and, from the same factorisation, the free run alone (the supports
/// only, nothing blocked) under the load cases `plain`, at the nodes `plain_observed`:
/// [case][k], m. The worm's bending model and its deflection share one factorisation so. Only
/// the observed nodes are solved for (the backward substitution skips what they do not need).
pub fn free_minus_blocked_and_free(
    mesh: &Mesh,
    material: &Elastic,
    (fixed, springs): (&[Fixed], &[Spring]),
    blocked: &[usize],
    (loads, observed): (&[(usize, nalgebra::Vector3<f64>)], &[usize]),
    (plain, plain_observed): (&[Vec<Load>], &[usize]),
) -> Result<(CaseDisplacements, CaseDisplacements), FeError> {
    let mut cases: Vec<Vec<Load>> = loads
        .iter()
        .map(|(n, nrm)| (0..3).map(|d| (*n, d, -nrm[d])).collect())
        .collect();
    let bending_cases = cases.len();
    cases.extend_from_slice(plain);
    let wanted: Vec<usize> = observed.iter().chain(plain_observed).copied().collect();
    let solution = solve_free_minus_blocked(
        mesh,
        material,
        fixed,
        springs,
        blocked,
        Cases {
            loads: &cases,
            difference: bending_cases,
            observed: Some(&wanted),
        },
        SizeLimits::MODEL,
    )?;
    let at = |c: usize, nodes: &[usize]| nodes.iter().map(|&n| solution.at(c, n)).collect();
    let bending = (0..bending_cases).map(|c| at(c, observed)).collect();
    let free = (bending_cases..cases.len())
        .map(|c| at(c, plain_observed))
        .collect();
    Ok((bending, free))
}
