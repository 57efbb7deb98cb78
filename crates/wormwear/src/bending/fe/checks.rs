//! Meshes and decks for the checks of the elements: structured boxes, a CalculiX deck of a mesh and
//! its displacement file read back, element volumes and Jacobians, mirrored connectivity.

use super::*;

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
