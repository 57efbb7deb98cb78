//! Element stiffnesses computed once per element shape (MODEL §5.5 step 1).
//!
//! The worm's mesh is a helical sweep of one meridian section and the wheel's a rotation of
//! one tooth's: most elements are rigid motions of others. For an element whose nodes are
//! x_e,i = R x_t,i + c (R a rotation) of a template t, the stiffness of the isotropic material
//! is K_e = Q K_t Q^T with Q = diag(R, ..., R) (its nodal displacements are R times the
//! template's), a 60 x 60 rotation instead of 27 Gauss-point products B^T D B: about thirty
//! times cheaper. Templates are found by the elements' edge lengths (rounded, hashed) and
//! every match is verified node by node, so an element that only resembles another is
//! computed on its own; the rotated matrices equal the directly computed ones to round-off.

use super::{element_stiffness, Elastic, FeError, Mesh};
use rayon::prelude::*;
use std::collections::HashMap;

/// Tolerance of the node-by-node check, relative to the element's size: the coordinates'
/// round-off is ~1e-16 of the model's size, ~1e-14 of an element's.
const MATCH_TOLERANCE: f64 = 1e-11;

/// How an element's stiffness is obtained: computed, or the rotation of a template's.
#[derive(Debug, Clone, Copy)]
enum Source {
    Computed,
    Rotated {
        template: usize,
        rotation: [[f64; 3]; 3],
    },
}

/// The stiffness matrices of a mesh's elements (row-major 60 x 60): those of the templates,
/// computed, and for every other element its template and rotation (module doc), so that the
/// copies take no memory until the assembly reads them.
pub struct ElementStiffnesses {
    sources: Vec<Source>,
    computed: Vec<Option<Vec<f64>>>,
}

impl ElementStiffnesses {
    /// Element e's matrix: the computed one, or its template's rotated into `buffer`.
    pub fn matrix<'a>(&'a self, e: usize, buffer: &'a mut Vec<f64>) -> &'a [f64] {
        match &self.sources[e] {
            Source::Computed => self.computed[e].as_deref().expect("computed"),
            Source::Rotated { template, rotation } => {
                let k = self.computed[*template]
                    .as_deref()
                    .expect("templates are computed");
                buffer.resize(60 * 60, 0.0);
                rotate(k, rotation, buffer);
                buffer
            }
        }
    }

    /// Number of elements whose matrix was computed (the others are rotations).
    pub fn computed(&self) -> usize {
        self.computed.iter().filter(|k| k.is_some()).count()
    }
}

/// The stiffness matrices of all elements: each shape computed once ([`element_stiffness`],
/// in parallel), its rigid copies rotated from it as they are read (module doc).
pub fn element_stiffnesses(mesh: &Mesh, material: &Elastic) -> Result<ElementStiffnesses, FeError> {
    let sources = sources(mesh);
    let computed: Vec<Option<Vec<f64>>> = sources
        .par_iter()
        .enumerate()
        .map(|(e, s)| match s {
            Source::Computed => element_stiffness(mesh, e, material).map(Some),
            Source::Rotated { .. } => Ok(None),
        })
        .collect::<Result<_, _>>()?;
    Ok(ElementStiffnesses { sources, computed })
}

/// Each element's source: the first element with its edge lengths is a template; a later one
/// with the same lengths is its rotation when every node checks (else computed).
fn sources(mesh: &Mesh) -> Vec<Source> {
    let size = |e: usize| {
        let x = element_nodes(mesh, e);
        (1..20).map(|i| distance(x[i], x[0])).fold(0.0, f64::max)
    };
    let largest = (0..mesh.elements.len()).map(size).fold(0.0, f64::max);
    // Lengths rounded to a billionth of the largest element: equal shapes hash alike unless a
    // length falls on a rounding boundary (then it is only computed, not wrong).
    let quantum = (1e-9 * largest).max(f64::MIN_POSITIVE);
    let keys: Vec<Vec<i64>> = (0..mesh.elements.len())
        .into_par_iter()
        .map(|e| signature(&element_nodes(mesh, e), quantum))
        .collect();
    let mut first: HashMap<&[i64], usize> = HashMap::new();
    let mut sources = Vec::with_capacity(keys.len());
    for (e, key) in keys.iter().enumerate() {
        let template = *first.entry(key).or_insert(e);
        let source = (template != e)
            .then(|| rotation_between(mesh, template, e))
            .flatten()
            .map_or(Source::Computed, |rotation| Source::Rotated {
                template,
                rotation,
            });
        sources.push(source);
    }
    sources
}

/// The element's 20 node positions, m.
fn element_nodes(mesh: &Mesh, e: usize) -> [[f64; 3]; 20] {
    mesh.elements[e].map(|n| mesh.nodes[n])
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Distances from node 0 to nodes 1..19 and from node 1 to nodes 2..19, in `quantum`s:
/// invariant under rigid motions, different for mirror images only through the check.
fn signature(x: &[[f64; 3]; 20], quantum: f64) -> Vec<i64> {
    let from = |a: usize| (a + 1..20).map(move |i| (distance(x[i], x[a]) / quantum).round() as i64);
    from(0).chain(from(1)).collect()
}

/// An orthonormal frame (columns) of an element: its edge from corner 0 to corner 1, the
/// edge to corner 3 made orthogonal to it, their cross product. None when degenerate.
fn frame(x: &[[f64; 3]; 20]) -> Option<nalgebra::Matrix3<f64>> {
    let v = |i: usize| nalgebra::Vector3::from(x[i]) - nalgebra::Vector3::from(x[0]);
    let e1 = v(1).try_normalize(0.0)?;
    let e2 = (v(3) - e1 * e1.dot(&v(3))).try_normalize(0.0)?;
    Some(nalgebra::Matrix3::from_columns(&[e1, e2, e1.cross(&e2)]))
}

/// The rotation R with x_e,i - x_e,0 = R (x_t,i - x_t,0) for every node (to
/// [`MATCH_TOLERANCE`] of the element's size), if there is one.
fn rotation_between(mesh: &Mesh, template: usize, e: usize) -> Option<[[f64; 3]; 3]> {
    let (xt, xe) = (element_nodes(mesh, template), element_nodes(mesh, e));
    let r = frame(&xe)? * frame(&xt)?.transpose();
    let size = (1..20).map(|i| distance(xe[i], xe[0])).fold(0.0, f64::max);
    let origin = |x: &[[f64; 3]; 20], i: usize| {
        nalgebra::Vector3::from(x[i]) - nalgebra::Vector3::from(x[0])
    };
    let all_match =
        (1..20).all(|i| (origin(&xe, i) - r * origin(&xt, i)).norm() <= MATCH_TOLERANCE * size);
    all_match.then(|| std::array::from_fn(|a| std::array::from_fn(|b| r[(a, b)])))
}

/// out = Q K Q^T for Q = diag(R, ..., R) (20 blocks): every 3 x 3 block (a, b) becomes
/// R K_ab R^T.
fn rotate(k: &[f64], r: &[[f64; 3]; 3], out: &mut [f64]) {
    for a in 0..20 {
        for b in 0..20 {
            let block = |i: usize, j: usize| k[(3 * a + i) * 60 + 3 * b + j];
            // t = K_ab R^T, then R t.
            let t: [[f64; 3]; 3] = std::array::from_fn(|i| {
                std::array::from_fn(|j| (0..3).map(|m| block(i, m) * r[j][m]).sum())
            });
            for i in 0..3 {
                for j in 0..3 {
                    out[(3 * a + i) * 60 + 3 * b + j] = (0..3).map(|m| r[i][m] * t[m][j]).sum();
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const STEEL: Elastic = Elastic {
        youngs_modulus: 206e9,
        poisson_ratio: 0.3,
    };

    /// A curved 20-node hexahedron (corner and mid-side nodes off the straight edges), its
    /// copy turned by 0.7 rad about a skew axis and moved, its mirror image, and a slightly
    /// stretched copy: four elements on 80 nodes.
    fn four_elements() -> Mesh {
        use nalgebra::{Rotation3, Unit, Vector3};
        let mut nodes: Vec<[f64; 3]> = Vec::new();
        let reference = super::super::NATURAL;
        // Curved: a gentle bend and uneven sides, mm.
        let base: Vec<Vector3<f64>> = reference
            .iter()
            .map(|p| {
                Vector3::new(
                    1.3e-3 * p[0] + 0.1e-3 * p[1] * p[1],
                    0.9e-3 * p[1] + 0.05e-3 * p[0] * p[2],
                    1.1e-3 * p[2] - 0.08e-3 * p[0] * p[0],
                )
            })
            .collect();
        let turn =
            Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::new(1.0, 2.0, -0.5)), 0.7);
        let shift = Vector3::new(0.05, -0.02, 0.013);
        type Motion = Box<dyn Fn(&Vector3<f64>) -> Vector3<f64>>;
        let copies: [Motion; 4] = [
            Box::new(|p| *p),
            Box::new(move |p| turn * p + shift),
            Box::new(move |p| Vector3::new(-p.x, p.y, p.z) + shift * 2.0),
            Box::new(move |p| Vector3::new(p.x * (1.0 + 1e-6), p.y, p.z) - shift),
        ];
        let mut elements = Vec::new();
        for copy in &copies {
            let start = nodes.len();
            nodes.extend(base.iter().map(|p| {
                let q = copy(p);
                [q.x, q.y, q.z]
            }));
            elements.push(std::array::from_fn(|i| start + i));
        }
        // The mirror image's orientation is reversed: renumber it to keep a positive Jacobian
        // (swap the corner pairs 1 <-> 3 and 5 <-> 7 and their mid-edges).
        let m = &mut elements[2];
        let perm = [
            0, 3, 2, 1, 4, 7, 6, 5, 11, 10, 9, 8, 15, 14, 13, 12, 16, 19, 18, 17,
        ];
        let old = *m;
        for (i, &p) in perm.iter().enumerate() {
            m[i] = old[p];
        }
        Mesh { nodes, elements }
    }

    #[test]
    fn a_rotated_element_gets_the_rotated_stiffness_and_others_their_own() {
        // The turned copy is recognised and its rotated matrix equals the directly computed
        // one to round-off; the mirror image and the stretched copy are computed on their own
        // (and equal their direct matrices exactly).
        let mesh = four_elements();
        let s = sources(&mesh);
        assert!(matches!(s[0], Source::Computed));
        assert!(
            matches!(s[1], Source::Rotated { template: 0, .. }),
            "{:?}",
            s[1]
        );
        assert!(matches!(s[2], Source::Computed), "{:?}", s[2]);
        assert!(matches!(s[3], Source::Computed), "{:?}", s[3]);
        let all = element_stiffnesses(&mesh, &STEEL).unwrap();
        assert_eq!(all.computed(), 3);
        let mut buffer = Vec::new();
        for e in 0..mesh.elements.len() {
            let k = all.matrix(e, &mut buffer).to_vec();
            let direct = element_stiffness(&mesh, e, &STEEL).unwrap();
            let scale = direct.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let worst = k
                .iter()
                .zip(&direct)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            eprintln!(
                "element {e}: largest difference {:.1e} of the largest entry",
                worst / scale
            );
            assert!(worst <= 1e-13 * scale, "element {e}: {worst:e}");
            if e != 1 {
                assert_eq!(k, direct);
            }
        }
    }
}
