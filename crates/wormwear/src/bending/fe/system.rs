//! The sparse linear system of a run and its direct solution (faer Cholesky): the DOF bookkeeping,
//! the stiffness assembled in place on the node graph's lower-triangle pattern, the prescribed
//! displacements moved to the right-hand sides, and the free-minus-blocked solve from one
//! factorisation with its size limits checked before anything large is built.

use super::*;

/// The size limits of one solve (the unknowns, the factor's nonzeros).
#[derive(Debug, Clone, Copy)]
pub(super) struct SizeLimits {
    pub(super) unknowns: usize,
    pub(super) factor_nonzeros: usize,
}

impl SizeLimits {
    /// The limits of the bending models: [`MAX_UNKNOWNS`], [`MAX_FACTOR_NONZEROS`].
    pub(super) const MODEL: Self = Self {
        unknowns: MAX_UNKNOWNS,
        factor_nonzeros: MAX_FACTOR_NONZEROS,
    };
    /// No limits (the solves of the checks and the ratings, whose meshes the models bound).
    pub(super) const NONE: Self = Self {
        unknowns: usize::MAX,
        factor_nonzeros: usize::MAX,
    };
}

/// The text of [`FeError::TooLarge`].
pub(super) fn too_large(unknowns: usize, nonzeros: Option<usize>) -> String {
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

/// Lower triangle of the free-free stiffness in compressed columns, assembled in place: the
/// pattern comes from the node graph (nodes sharing an element or a spring), so no triplet list
/// is built or sorted. Rows of each column are sorted; `position` finds an entry.
pub(super) struct LowerPattern {
    pub(super) col_ptr: Vec<usize>,
    pub(super) row_idx: Vec<usize>,
}

impl LowerPattern {
    pub(super) fn new(mesh: &Mesh, springs: &[Spring], map: &[usize], free: usize) -> Self {
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
    pub(super) fn symbolic(&self, n: usize) -> faer::sparse::SymbolicSparseColMatRef<'_, usize> {
        faer::sparse::SymbolicSparseColMatRef::new_checked(n, n, &self.col_ptr, None, &self.row_idx)
    }

    #[inline]
    pub(super) fn position(&self, row: usize, col: usize) -> usize {
        let (a, b) = (self.col_ptr[col], self.col_ptr[col + 1]);
        let p = a + self.row_idx[a..b].partition_point(|&r| r < row);
        assert!(p < b && self.row_idx[p] == row, "entry outside the pattern");
        p
    }
}

/// Solves with element stiffnesses already computed (shared by runs on the same mesh).
pub(super) fn solve_assembled(
    mesh: &Mesh,
    elements: &ElementStiffnesses,
    fixed: &[Fixed],
    springs: &[Spring],
    loads: &[Vec<Load>],
) -> Result<Solution, FeError> {
    let system = assemble(mesh, elements, fixed, springs, loads);
    let factor = system.fill_reducing_order()?;
    Ok(Solution {
        x: factor
            .factorize(system.matrix, system.rhs.ncols())?
            .solve(system.rhs, 0, None),
        map: system.map,
        prescribed: system.prescribed,
        difference_cases: 0,
    })
}

/// The assembled linear system of one run: the free-free stiffness (lower triangle, free-DOF
/// numbering), the right-hand sides of the load cases (N), and the DOF bookkeeping.
pub(super) struct System {
    pub(super) matrix: SparseColMat<usize, f64>,
    pub(super) rhs: Mat<f64>,
    /// Free-DOF index of every global DOF (usize::MAX where prescribed).
    pub(super) map: Vec<usize>,
    pub(super) prescribed: Vec<Option<f64>>,
}

impl System {
    /// The fill-reducing order of the system's matrix (nothing blocked), no size limit.
    fn fill_reducing_order(&self) -> Result<BlockedLast, FeError> {
        let free = self.matrix.nrows();
        let node = free_dof_nodes(&self.map, free);
        BlockedLast::ordered(
            self.matrix.symbolic(),
            &node,
            &vec![false; free],
            SizeLimits::NONE,
        )
    }
}

/// Assembles the stiffness with the prescribed displacements eliminated (moved to the
/// right-hand sides) and the springs added.
pub(super) fn assemble(
    mesh: &Mesh,
    elements: &ElementStiffnesses,
    fixed: &[Fixed],
    springs: &[Spring],
    loads: &[Vec<Load>],
) -> System {
    let dofs = Dofs::new(mesh, fixed);
    let pattern = LowerPattern::new(mesh, springs, &dofs.map, dofs.free);
    fill(mesh, elements, springs, loads, dofs, pattern)
}

/// The DOF bookkeeping of one run: the prescribed value of every global DOF and its free index.
pub(super) struct Dofs {
    pub(super) prescribed: Vec<Option<f64>>,
    /// Free-DOF index of every global DOF (usize::MAX where prescribed).
    pub(super) map: Vec<usize>,
    pub(super) free: usize,
}

impl Dofs {
    pub(super) fn new(mesh: &Mesh, fixed: &[Fixed]) -> Self {
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

/// The load cases' right-hand sides on the free DOFs (N; loads on prescribed DOFs dropped).
fn load_vectors(loads: &[Vec<Load>], map: &[usize], free: usize) -> Mat<f64> {
    let mut rhs = Mat::<f64>::zeros(free, loads.len());
    for (c, case) in loads.iter().enumerate() {
        for &(n, d, v) in case {
            let g = 3 * n + d;
            if map[g] != usize::MAX {
                rhs[(map[g], c)] += v;
            }
        }
    }
    rhs
}

/// The stiffness values on `pattern` and the right-hand sides (see [`assemble`]).
pub(super) fn fill(
    mesh: &Mesh,
    elements: &ElementStiffnesses,
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
    let mut rhs = load_vectors(loads, &map, free);
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
    let mut buffer = Vec::new();
    for (index, e) in mesh.elements.iter().enumerate() {
        let k = elements.matrix(index, &mut buffer);
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
/// blocked DOFs B are ordered last (nested dissection for the others, R), so with A = L L^T the leading
/// block L_RR of L is the Cholesky factor of the blocked run's matrix A_RR. Forward
/// substitution y = L^-1 f serves both runs (its R part does not see f_B); the free run is
/// L^-T y and the blocked run L^-T [y_R; 0] (x_R = A_RR^-1 f_R, x_B = 0, its loads on blocked
/// nodes vanishing as they do for prescribed DOFs), so their difference is L^-T [0; y_B]: one
/// factorisation and two triangular solves instead of two factorisations and four. The
/// prescribed displacements are the same in both runs, so the difference is zero there.
/// Of the load cases ([`Cases`]), the first get this difference, the others the free run
/// alone, K^-1 f, from the same factor (the worm's deflection, MODEL §9.1).
///
/// The size is checked before anything large is computed: the unknowns against
/// [`MAX_UNKNOWNS`], then the factor's nonzeros from the symbolic analysis against
/// [`MAX_FACTOR_NONZEROS`] ([`FeError::TooLarge`]); only then the element stiffnesses.
pub(super) fn solve_free_minus_blocked(
    mesh: &Mesh,
    material: &Elastic,
    fixed: &[Fixed],
    springs: &[Spring],
    blocked: &[usize],
    cases: Cases<'_>,
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
    let map = &dofs.map;
    let wanted: Option<Vec<usize>> = cases.observed.map(|nodes| {
        nodes
            .iter()
            .flat_map(|&n| (0..3).map(move |d| map[3 * n + d]))
            .filter(|&i| i != usize::MAX)
            .collect()
    });
    let system = fill(mesh, &elements, springs, cases.loads, dofs, pattern);
    drop(elements);
    let count = system.rhs.ncols();
    let x = factor.factorize(system.matrix, count)?.solve(
        system.rhs,
        cases.difference,
        wanted.as_deref(),
    );
    Ok(Solution {
        x,
        map: system.map,
        prescribed: system.prescribed,
        difference_cases: cases.difference,
    })
}

/// The load cases of [`solve_free_minus_blocked`]: the first `difference` of `loads` get the
/// free-minus-blocked difference, the others the free run alone; with `observed` (nodes) only
/// those nodes' displacements are computed exactly (the others are NaN).
pub(super) struct Cases<'a> {
    pub(super) loads: &'a [Vec<Load>],
    pub(super) difference: usize,
    pub(super) observed: Option<&'a [usize]>,
}

/// The symbolic Cholesky factor of a run's free-free stiffness with the blocked DOFs ordered
/// last ([`order_blocked_last`]), see [`solve_free_minus_blocked`].
pub(super) struct BlockedLast {
    /// New -> old and old -> new free-DOF order.
    pub(super) forward: Vec<usize>,
    pub(super) inverse: Vec<usize>,
    /// The unknowns before the blocked ones.
    pub(super) unblocked: usize,
    pub(super) symbolic: faer::sparse::linalg::cholesky::SymbolicCholesky<usize>,
}

impl BlockedLast {
    /// Orders and analyses `pattern` with the `blocked` nodes' free DOFs last; refuses a
    /// factor above `limits.factor_nonzeros`.
    pub(super) fn analyse(
        pattern: &LowerPattern,
        dofs: &Dofs,
        blocked: &[usize],
        limits: SizeLimits,
    ) -> Result<Self, FeError> {
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
        let node = free_dof_nodes(&dofs.map, free);
        Self::ordered(pattern.symbolic(free), &node, &is_blocked, limits)
    }

    /// Orders the lower-triangle pattern `lower` ([`order_blocked_last`]: `node` the mesh node
    /// of every unknown, the `last` ones at the end) and analyses it.
    pub(super) fn ordered(
        lower: faer::sparse::SymbolicSparseColMatRef<'_, usize>,
        node: &[usize],
        last: &[bool],
        limits: SizeLimits,
    ) -> Result<Self, FeError> {
        use faer::sparse::linalg::cholesky::{
            factorize_symbolic_cholesky, CholeskySymbolicParams, SymmetricOrdering,
        };
        let free = last.len();
        let (forward, inverse, unblocked) = order_blocked_last(lower, node, last)?;
        let perm = faer::perm::PermRef::new_checked(&forward, &inverse, free);
        let symbolic = factorize_symbolic_cholesky(
            lower,
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

    /// The numeric factor L of `matrix` on this order, with a work buffer large enough for
    /// the solves of up to `cases` right-hand sides at once.
    pub(super) fn factorize(
        &self,
        matrix: SparseColMat<usize, f64>,
        cases: usize,
    ) -> Result<Factor<'_>, FeError> {
        use faer::dyn_stack::{MemBuffer, MemStack};
        let symbolic = &self.symbolic;
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
        Ok(Factor {
            order: self,
            values,
            mem,
        })
    }
}

/// The numeric Cholesky factor of a [`BlockedLast`] order.
pub(super) struct Factor<'a> {
    order: &'a BlockedLast,
    values: Vec<f64>,
    mem: faer::dyn_stack::MemBuffer,
}

impl Factor<'_> {
    /// The solution of every case of `rhs` (free-DOF numbering, at most the `cases` of
    /// [`BlockedLast::factorize`]): for the first `difference_cases` the free run minus the
    /// blocked run, L^-T [0; y_B] with y = L^-1 f; for the others K^-1 f. With `wanted` (free
    /// DOFs) only those are exact, the backward substitution skipping the supernodes they do
    /// not depend on, and the skipped rows are NaN.
    pub(super) fn solve(
        &mut self,
        rhs: Mat<f64>,
        difference_cases: usize,
        wanted: Option<&[usize]>,
    ) -> Mat<f64> {
        solve_factored(
            self.order,
            &self.values,
            &mut self.mem,
            rhs,
            (difference_cases, wanted),
        )
    }

    /// The factor's values, for a [`KeptFactor`].
    fn into_values(self) -> Vec<f64> {
        self.values
    }
}

/// [`Factor::solve`] on an order, its factor's values and a work buffer.
fn solve_factored(
    order: &BlockedLast,
    values: &[f64],
    mem: &mut faer::dyn_stack::MemBuffer,
    rhs: Mat<f64>,
    (difference_cases, wanted): (usize, Option<&[usize]>),
) -> Mat<f64> {
    use faer::sparse::linalg::cholesky::{supernodal::SupernodalLltRef, SymbolicCholeskyRaw};
    let (free, cases) = (rhs.nrows(), rhs.ncols());
    let symbolic = &order.symbolic;
    let par = faer::get_global_parallelism();
    let mut y = Mat::<f64>::from_fn(free, cases, |i, c| rhs[(order.forward[i], c)]);
    drop(rhs);
    let supernodal = match symbolic.raw() {
        SymbolicCholeskyRaw::Supernodal(s) => Some((s, SupernodalLltRef::new(s, values))),
        SymbolicCholeskyRaw::Simplicial(_) => None,
    };
    match supernodal {
        Some((_, l)) => forward_sparse(l, y.as_mut(), par),
        None => lower_solve(symbolic, values, y.as_mut(), false, par, mem),
    }
    for c in 0..difference_cases.min(cases) {
        for i in 0..order.unblocked {
            y[(i, c)] = 0.0;
        }
    }
    match (supernodal, wanted) {
        (Some((s, l)), Some(rows)) => {
            let needed = supernodes_on_paths(s, rows.iter().map(|&i| order.inverse[i]));
            backward_on(l, y.as_mut(), &needed, par);
        }
        _ => lower_solve(symbolic, values, y.as_mut(), true, par, mem),
    }
    Mat::<f64>::from_fn(free, cases, |i, c| y[(order.inverse[i], c)])
}

/// A system factorised once and kept for the load cases of many runs (the same mesh,
/// material and supports, all prescribed displacements zero): the root stress's sector over
/// the samples of a spread.
pub(crate) struct KeptFactor {
    order: BlockedLast,
    values: Vec<f64>,
    map: Vec<usize>,
    prescribed: Vec<Option<f64>>,
}

impl KeptFactor {
    /// Assembles, orders and factorises `mesh` with `material` held at `fixed` (every value
    /// zero: a load's right-hand side is then the load alone).
    pub(crate) fn new(
        mesh: &Mesh,
        material: &crate::bending::fe::Elastic,
        fixed: &[Fixed],
    ) -> Result<Self, FeError> {
        if fixed.iter().any(|f| f.2 != 0.0) {
            return Err(FeError::Factorisation(
                "a kept factorisation holds its supports at zero displacement".into(),
            ));
        }
        let elements = super::element_stiffnesses(mesh, material)?;
        let system = assemble(mesh, &elements, fixed, &[], &[]);
        let order = system.fill_reducing_order()?;
        let values = order.factorize(system.matrix, 1)?.into_values();
        Ok(Self {
            order,
            values,
            map: system.map,
            prescribed: system.prescribed,
        })
    }

    /// The displacements of every node under each load case, [case][node], m.
    pub(crate) fn solve(&self, loads: &[Vec<Load>]) -> Vec<Vec<[f64; 3]>> {
        let free = self.order.forward.len();
        let rhs = load_vectors(loads, &self.map, free);
        let par = faer::get_global_parallelism();
        let scratch = self
            .order
            .symbolic
            .solve_in_place_scratch::<f64>(loads.len().max(1), par);
        let mut mem = faer::dyn_stack::MemBuffer::new(scratch);
        let x = solve_factored(&self.order, &self.values, &mut mem, rhs, (0, None));
        // Every prescribed displacement is zero (checked in `new`).
        let at = |c: usize, n: usize| {
            [0, 1, 2].map(|d| match self.prescribed[3 * n + d] {
                Some(v) => v,
                None => x[(self.map[3 * n + d], c)],
            })
        };
        let nodes = self.prescribed.len() / 3;
        (0..loads.len())
            .map(|c| (0..nodes).map(|n| at(c, n)).collect())
            .collect()
    }
}

/// Fill-reducing order with the `last` unknowns at the end: nested dissection of the matrix
/// without them ([`nested_dissection`], `node` the mesh node of every unknown), then them in
/// their own order. Returns (forward: new -> old, inverse: old -> new, the number of unknowns
/// before the last ones).
pub(super) fn order_blocked_last(
    matrix: faer::sparse::SymbolicSparseColMatRef<'_, usize>,
    node: &[usize],
    last: &[bool],
) -> Result<(Vec<usize>, Vec<usize>, usize), FeError> {
    let n = last.len();
    let keep: Vec<bool> = last.iter().map(|&l| !l).collect();
    let mut forward = nested_dissection(matrix, node, &keep)?;
    let m = forward.len();
    forward.extend((0..n).filter(|&i| last[i]));
    let mut inverse = vec![0; n];
    for (new, &old) in forward.iter().enumerate() {
        inverse[old] = new;
    }
    Ok((forward, inverse, m))
}

/// In place, on the permuted unknowns: rhs <- L^-1 rhs, or L^-T rhs when `transpose`.
pub(super) fn lower_solve(
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

/// A work matrix for the updates of `k` cases by any supernode of `l` (its longest pattern).
fn update_buffer(
    l: faer::sparse::linalg::cholesky::supernodal::SupernodalLltRef<'_, usize, f64>,
    k: usize,
) -> Mat<f64> {
    let longest = (0..l.symbolic().n_supernodes())
        .map(|s| l.supernode(s).pattern().len())
        .max()
        .unwrap_or(0);
    Mat::<f64>::zeros(longest, k)
}

/// Forward substitution rhs <- L^-1 rhs on a supernodal factor that skips the supernodes where
/// every case is still zero (their updates are zero): a load case on one node only touches
/// the supernodes on its path to the root of the elimination tree. The same operations as
/// faer's `l_solve_with_conj` on the others, so the same numbers.
fn forward_sparse(
    l: faer::sparse::linalg::cholesky::supernodal::SupernodalLltRef<'_, usize, f64>,
    mut x: faer::MatMut<'_, f64>,
    par: faer::Par,
) {
    use faer::linalg::{matmul::matmul_with_conj, triangular_solve};
    use faer::reborrow::{Reborrow, ReborrowMut};
    use faer::{Accum, Conj};
    let k = x.ncols();
    let symbolic = l.symbolic();
    let mut buffer = update_buffer(l, k);
    for s in 0..symbolic.n_supernodes() {
        let node = l.supernode(s);
        let size = node.val().ncols();
        let start = node.start();
        let zero = (0..k).all(|j| (start..start + size).all(|i| x[(i, j)] == 0.0));
        if zero {
            continue;
        }
        let (top, bottom) = node.val().split_at_row(size);
        let mut x_top = x.rb_mut().subrows_mut(start, size);
        triangular_solve::solve_lower_triangular_in_place_with_conj(
            top,
            Conj::No,
            x_top.rb_mut(),
            par,
        );
        let pattern = node.pattern();
        let mut tmp = buffer.as_mut().subrows_mut(0, pattern.len());
        matmul_with_conj(
            tmp.rb_mut(),
            Accum::Replace,
            bottom,
            Conj::No,
            x_top.rb(),
            Conj::No,
            1.0,
            par,
        );
        for j in 0..k {
            for (idx, &i) in pattern.iter().enumerate() {
                x[(i, j)] -= tmp[(idx, j)];
            }
        }
    }
}

/// The supernodes a backward substitution must compute for the rows `rows` (permuted
/// numbering) to be exact: theirs and every ancestor's (a supernode's rows below its diagonal
/// block belong to its ancestors; the parent holds the first of them).
fn supernodes_on_paths(
    symbolic: &faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky<usize>,
    rows: impl Iterator<Item = usize>,
) -> Vec<bool> {
    let n = symbolic.n_supernodes();
    let begin = symbolic.supernode_begin();
    let of_row = |r: usize| begin[..n].partition_point(|&b| b <= r) - 1;
    let mut needed = vec![false; n];
    for r in rows {
        needed[of_row(r)] = true;
    }
    for s in 0..n {
        if needed[s] {
            if let Some(&first) = symbolic.supernode(s).pattern().first() {
                needed[of_row(first)] = true;
            }
        }
    }
    needed
}

/// Backward substitution rhs <- L^-T rhs on the `needed` supernodes only
/// ([`supernodes_on_paths`]); the others' rows are set to NaN. The same operations as faer's
/// `l_transpose_solve_with_conj` on the needed ones, so the same numbers there.
fn backward_on(
    l: faer::sparse::linalg::cholesky::supernodal::SupernodalLltRef<'_, usize, f64>,
    mut x: faer::MatMut<'_, f64>,
    needed: &[bool],
    par: faer::Par,
) {
    use faer::linalg::{matmul::matmul_with_conj, triangular_solve};
    use faer::reborrow::{Reborrow, ReborrowMut};
    use faer::{Accum, Conj};
    let k = x.ncols();
    let symbolic = l.symbolic();
    let mut buffer = update_buffer(l, k);
    for s in (0..symbolic.n_supernodes()).rev() {
        let node = l.supernode(s);
        let size = node.val().ncols();
        let start = node.start();
        if !needed[s] {
            x.rb_mut().subrows_mut(start, size).fill(f64::NAN);
            continue;
        }
        let (top, bottom) = node.val().split_at_row(size);
        let pattern = node.pattern();
        let mut tmp = buffer.as_mut().subrows_mut(0, pattern.len());
        for j in 0..k {
            for (idx, &i) in pattern.iter().enumerate() {
                tmp[(idx, j)] = x[(i, j)];
            }
        }
        let mut x_top = x.rb_mut().subrows_mut(start, size);
        matmul_with_conj(
            x_top.rb_mut(),
            Accum::Add,
            bottom.transpose(),
            Conj::No,
            tmp.rb(),
            Conj::No,
            -1.0,
            par,
        );
        triangular_solve::solve_upper_triangular_in_place_with_conj(
            top.transpose(),
            Conj::No,
            x_top.rb_mut(),
            par,
        );
    }
}

/// Displacements of every load case in the free-DOF numbering of one run.
#[derive(Debug)]
pub(super) struct Solution {
    /// free DOFs x cases, m.
    pub(super) x: Mat<f64>,
    pub(super) map: Vec<usize>,
    pub(super) prescribed: Vec<Option<f64>>,
    /// The first cases are free-minus-blocked differences, zero where prescribed.
    pub(super) difference_cases: usize,
}

impl Solution {
    /// Displacement of a node under case c, m.
    pub(super) fn at(&self, c: usize, n: usize) -> [f64; 3] {
        let mut u = [0.0; 3];
        for (d, ud) in u.iter_mut().enumerate() {
            let g = 3 * n + d;
            *ud = match self.prescribed[g] {
                Some(_) if c < self.difference_cases => 0.0,
                Some(v) => v,
                None => self.x[(self.map[g], c)],
            };
        }
        u
    }
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
        let cases = || Cases {
            loads: &loads,
            difference: 1,
            observed: None,
        };
        let solve =
            |limits| solve_free_minus_blocked(&mesh, &STEEL, &fixed, &[], &[], cases(), limits);
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

    /// The nested dissection order of a clamped cube's stiffness pattern: a permutation of the
    /// unknowns with each node's unknowns consecutive, the same on every call, and a factor no
    /// fuller than faer's approximate minimum degree gives (the reason for it).
    #[test]
    fn nested_dissection_keeps_nodes_together_and_fills_less_than_minimum_degree() {
        use faer::sparse::linalg::cholesky::{
            factorize_symbolic_cholesky, CholeskySymbolicParams, SymmetricOrdering,
        };
        let (mesh, lattice) = box_mesh((0.01, 0.01, 0.01), (8, 8, 8), |p| p);
        let fixed: Vec<Fixed> = lattice
            .iter()
            .enumerate()
            .filter(|(_, ijk)| ijk[2] == 0)
            .flat_map(|(k, _)| (0..3).map(move |d| (k, d, 0.0)))
            .collect();
        let dofs = Dofs::new(&mesh, &fixed);
        let pattern = LowerPattern::new(&mesh, &[], &dofs.map, dofs.free);
        let node = free_dof_nodes(&dofs.map, dofs.free);
        let keep = vec![true; dofs.free];
        let order = nested_dissection(pattern.symbolic(dofs.free), &node, &keep).unwrap();
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..dofs.free).collect::<Vec<_>>());
        for pair in order.windows(2) {
            if node[pair[0]] == node[pair[1]] {
                assert_eq!(pair[1], pair[0] + 1, "a node's unknowns in their own order");
            }
        }
        let runs = order
            .windows(2)
            .filter(|p| node[p[0]] != node[p[1]])
            .count()
            + 1;
        let nodes = node.iter().collect::<std::collections::HashSet<_>>().len();
        assert_eq!(runs, nodes, "each node's unknowns together");
        let again = nested_dissection(pattern.symbolic(dofs.free), &node, &keep).unwrap();
        assert_eq!(order, again);
        let nonzeros = |ordering| {
            factorize_symbolic_cholesky(
                pattern.symbolic(dofs.free),
                Side::Lower,
                ordering,
                CholeskySymbolicParams::default(),
            )
            .unwrap()
            .len_val()
        };
        let (forward, inverse, _) =
            order_blocked_last(pattern.symbolic(dofs.free), &node, &vec![false; dofs.free])
                .unwrap();
        let perm = faer::perm::PermRef::new_checked(&forward, &inverse, dofs.free);
        let (nd, amd) = (
            nonzeros(SymmetricOrdering::Custom(perm)),
            nonzeros(SymmetricOrdering::Amd),
        );
        assert!(
            nd < amd,
            "nested dissection {nd} nonzeros, minimum degree {amd}"
        );
    }

    /// The solves that skip supernodes: the forward substitution that skips all-zero
    /// supernodes gives faer's numbers bit for bit, and a backward substitution restricted to
    /// the supernodes some wanted rows depend on gives the full solve's numbers there, bit for
    /// bit, and NaN elsewhere (never a silent wrong value).
    #[test]
    fn solves_on_the_elimination_tree_paths_equal_the_full_solves_where_wanted() {
        use faer::sparse::linalg::cholesky::{supernodal::SupernodalLltRef, SymbolicCholeskyRaw};
        let (mesh, lattice) = box_mesh((0.04, 0.01, 0.01), (16, 4, 4), |p| p);
        let fixed: Vec<Fixed> = lattice
            .iter()
            .enumerate()
            .filter(|(_, ijk)| ijk[0] == 0)
            .flat_map(|(k, _)| (0..3).map(move |d| (k, d, 0.0)))
            .collect();
        let at_x = |i: usize| -> Vec<usize> {
            (0..lattice.len())
                .filter(|&k| lattice[k][0] == i && lattice[k][1] == 0)
                .collect()
        };
        let blocked = at_x(16);
        // Single-node loads near the blocked face (difference cases) and one spread load (a
        // plain case); observed nodes at the tip and halfway.
        let mut loads: Vec<Vec<Load>> = at_x(30).iter().map(|&n| vec![(n, 1, -1.0)]).collect();
        let difference = loads.len();
        loads.push(at_x(20).iter().map(|&n| (n, 2, 0.5)).collect());
        let observed: Vec<usize> = at_x(32).into_iter().chain(at_x(8)).collect();
        let dofs = Dofs::new(&mesh, &fixed);
        let pattern = LowerPattern::new(&mesh, &[], &dofs.map, dofs.free);
        let factor = BlockedLast::analyse(&pattern, &dofs, &blocked, SizeLimits::NONE).unwrap();
        let elements = element_stiffnesses(&mesh, &STEEL).unwrap();
        let map = &dofs.map.clone();
        let system = fill(&mesh, &elements, &[], &loads, dofs, pattern);
        let wanted: Vec<usize> = observed
            .iter()
            .flat_map(|&n| (0..3).map(move |d| map[3 * n + d]))
            .filter(|&i| i != usize::MAX)
            .collect();
        let mut numeric = factor
            .factorize(system.matrix.clone(), loads.len())
            .unwrap();
        let full = numeric.solve(system.rhs.clone(), difference, None);
        let some = numeric.solve(system.rhs.clone(), difference, Some(&wanted));
        let mut skipped = 0;
        for c in 0..loads.len() {
            for i in 0..full.nrows() {
                if wanted.contains(&i) {
                    assert_eq!(some[(i, c)].to_bits(), full[(i, c)].to_bits());
                    assert!(full[(i, c)] != 0.0);
                } else if some[(i, c)].is_nan() {
                    skipped += 1;
                }
            }
        }
        assert!(skipped > 0, "the restricted solve skipped no supernode");
        // The forward substitution against faer's.
        let SymbolicCholeskyRaw::Supernodal(symbolic) = factor.symbolic.raw() else {
            panic!("a supernodal factor expected on this size");
        };
        let l = SupernodalLltRef::new(symbolic, &numeric.values);
        let par = faer::Par::Seq;
        let mut ours = Mat::<f64>::from_fn(full.nrows(), loads.len(), |i, c| {
            system.rhs[(factor.forward[i], c)]
        });
        let mut theirs = ours.clone();
        forward_sparse(l, ours.as_mut(), par);
        lower_solve(
            &factor.symbolic,
            &numeric.values,
            theirs.as_mut(),
            false,
            par,
            &mut numeric.mem,
        );
        for c in 0..loads.len() {
            for i in 0..full.nrows() {
                assert_eq!(ours[(i, c)].to_bits(), theirs[(i, c)].to_bits());
            }
        }
    }
}
