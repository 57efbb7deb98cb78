//! Fill-reducing order of a stiffness matrix: METIS nested dissection (Karypis & Kumar, SIAM J.
//! Sci. Comput. 20, 1998) on the node graph, each node's free DOFs kept together.
//!
//! Why not faer's approximate minimum degree: on the 1/40 worm (115 572 unknowns) its factor
//! held 1.23e8 values; nested dissection's separators cut the long helical body into pieces
//! whose fronts are smaller (BENCHMARKS.md, issue 36). The node graph (a third of the DOF
//! graph's vertices, a ninth of its edges) is ordered instead of the DOF graph: the three DOFs
//! of a node have the same neighbours, so nothing is lost and the ordering is ~10 times faster.

use super::FeError;
use metis_sys as metis;
use std::sync::Mutex;

/// METIS's signal traps (SIGABRT, SIGTERM) are process-wide and saved / restored per call: two
/// calls at once (the worm and the wheel are built side by side) could leave METIS's handler
/// installed after both returned. One call at a time keeps the handlers as they were.
static METIS_CALL: Mutex<()> = Mutex::new(());

/// The node of every free DOF, from the free index of every global DOF (`map[3 n + d]`,
/// usize::MAX where prescribed).
pub(super) fn free_dof_nodes(map: &[usize], free: usize) -> Vec<usize> {
    let mut node = vec![0; free];
    for (g, &i) in map.iter().enumerate() {
        if i != usize::MAX {
            node[i] = g / 3;
        }
    }
    node
}

/// A fill-reducing order (new -> old) of the unknowns with `keep[i]` of the symmetric matrix
/// whose lower triangle's pattern is `lower`; `node[i]` is unknown i's mesh node. The kept
/// unknowns of one node come out consecutive, in their own order.
pub(super) fn nested_dissection(
    lower: faer::sparse::SymbolicSparseColMatRef<'_, usize>,
    node: &[usize],
    keep: &[bool],
) -> Result<Vec<usize>, FeError> {
    let mut graph = NodeGraph::new(lower, node, keep)?;
    if graph.members.len() <= 2 {
        return Ok(graph.members.concat());
    }
    let order = graph.order()?;
    Ok(order
        .iter()
        .flat_map(|&v| graph.members[v as usize].iter().copied())
        .collect())
}

/// The graph of the nodes that have kept unknowns, in METIS's compressed form.
struct NodeGraph {
    /// Each vertex's unknowns (ascending).
    members: Vec<Vec<usize>>,
    xadj: Vec<metis::idx_t>,
    adjncy: Vec<metis::idx_t>,
    /// Unknowns per vertex (the separators balance unknowns, not nodes).
    weight: Vec<metis::idx_t>,
}

impl NodeGraph {
    fn new(
        lower: faer::sparse::SymbolicSparseColMatRef<'_, usize>,
        node: &[usize],
        keep: &[bool],
    ) -> Result<Self, FeError> {
        let n = keep.len();
        let mut vertex_of_node = std::collections::HashMap::new();
        let mut vertex = vec![usize::MAX; n];
        let mut members: Vec<Vec<usize>> = Vec::new();
        for i in (0..n).filter(|&i| keep[i]) {
            let v = *vertex_of_node.entry(node[i]).or_insert_with(|| {
                members.push(Vec::new());
                members.len() - 1
            });
            members[v].push(i);
            vertex[i] = v;
        }
        let too_large = |what: &str| {
            FeError::Factorisation(format!("the node graph has too many {what} for METIS"))
        };
        let mut neighbours: Vec<Vec<metis::idx_t>> = vec![Vec::new(); members.len()];
        let (col_ptr, row_idx) = (lower.col_ptr(), lower.row_idx());
        // A node's unknowns share their neighbours: its first unknown's column (rows sorted,
        // a node's unknowns consecutive) gives every edge to a later node once.
        for m in &members {
            let (c, a) = (m[0], vertex[m[0]]);
            let mut last = usize::MAX;
            for &r in &row_idx[col_ptr[c]..col_ptr[c + 1]] {
                let b = vertex[r];
                if b != usize::MAX && b != a && b != last {
                    neighbours[a].push(b as metis::idx_t);
                    neighbours[b].push(a as metis::idx_t);
                    last = b;
                }
            }
        }
        let mut xadj = Vec::with_capacity(members.len() + 1);
        let mut adjncy = Vec::new();
        xadj.push(0);
        for list in &mut neighbours {
            list.sort_unstable();
            list.dedup();
            adjncy.extend_from_slice(list);
            xadj.push(metis::idx_t::try_from(adjncy.len()).map_err(|_| too_large("edges"))?);
        }
        let weight = members.iter().map(|m| m.len() as metis::idx_t).collect();
        if metis::idx_t::try_from(members.len()).is_err() {
            return Err(too_large("nodes"));
        }
        Ok(Self {
            members,
            xadj,
            adjncy,
            weight,
        })
    }

    /// METIS_NodeND with its default options (fixed seed: the same graph gives the same
    /// order). Returns the vertices in elimination order.
    fn order(&mut self) -> Result<Vec<metis::idx_t>, FeError> {
        let mut vertices = self.members.len() as metis::idx_t;
        let mut options = [0 as metis::idx_t; metis::METIS_NOPTIONS as usize];
        let mut perm = vec![0 as metis::idx_t; self.members.len()];
        let mut inverse = vec![0 as metis::idx_t; self.members.len()];
        let _one_at_a_time = METIS_CALL.lock().unwrap_or_else(|e| e.into_inner());
        // SAFETY: the arrays have the lengths METIS reads and writes (options METIS_NOPTIONS;
        // xadj vertices + 1; adjncy xadj[vertices]; weight, perm and inverse `vertices`), the
        // graph is symmetric without self loops (built so above), and METIS keeps no pointer
        // after it returns.
        let status = unsafe {
            metis::METIS_SetDefaultOptions(options.as_mut_ptr());
            options[metis::moptions_et_METIS_OPTION_NUMBERING as usize] = 0;
            metis::METIS_NodeND(
                &mut vertices,
                self.xadj.as_mut_ptr(),
                self.adjncy.as_mut_ptr(),
                self.weight.as_mut_ptr(),
                options.as_mut_ptr(),
                perm.as_mut_ptr(),
                inverse.as_mut_ptr(),
            )
        };
        if status != metis::rstatus_et_METIS_OK {
            return Err(FeError::Factorisation(format!(
                "METIS could not order the stiffness matrix (status {status})"
            )));
        }
        Ok(perm)
    }
}
