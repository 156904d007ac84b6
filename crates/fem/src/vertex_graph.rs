//! The pattern of a mesh's vertex graph, for ordering a factorization before the
//! unknowns are known.

use crate::dof::{DofMap, DofScalar};
use beltrami_mesh::{Mesh, VertexId};
use beltrami_sparse::check::check_len;
use beltrami_sparse::{SolveError, SplitOrder};
use faer::sparse::{SymbolicSparseColMat, SymbolicSparseColMatRef};

/// The lower triangle (diagonal included, each column's rows increasing) of the
/// symmetric pattern of `mesh`'s vertex graph: `(v, v)` for every vertex and `(w, v)`,
/// `w > v`, for every edge `{v, w}`. On a triangle mesh it is the pattern of any
/// energy coupling the vertices of each face (the cotangent Laplacian, the conformal
/// energy), before a DOF map drops fixed vertices; an order of it carries over to the
/// unknowns ([`order_of_unknowns`]). On quads the
/// diagonals of a face are not edges.
///
/// One pass over the vertices' neighbours, written in place: no list of pairs to sort.
pub fn vertex_graph_pattern(mesh: &Mesh) -> SymbolicSparseColMat<usize> {
    let n = mesh.vertex_count();
    let mut col_ptr = Vec::with_capacity(n + 1);
    let mut rows = Vec::with_capacity(n + mesh.edge_count());
    col_ptr.push(0);
    for v in 0..n {
        let start = rows.len();
        rows.push(v);
        rows.extend(
            mesh.vertex_neighbors(VertexId::from_usize(v))
                .map(|w| w.idx())
                .filter(|&w| w > v),
        );
        rows[start + 1..].sort_unstable();
        col_ptr.push(rows.len());
    }
    SymbolicSparseColMat::new_checked(n, n, col_ptr, None, rows)
}

/// `vertex_graph` (the lower triangle of a pattern of `dofs`' nodes, as
/// [`vertex_graph_pattern`] gives it) carried over to `dofs`' reduced unknowns, when each
/// node has at most one unknown and the unknowns are numbered in the order of their
/// nodes, each once (the complex form with fixed nodes: a fixed node's row and column
/// are dropped, the others renumbered, their order kept); `None` otherwise, and when
/// the pattern is not of `dofs`' nodes. On a triangle mesh this is the pattern
/// [`normal_pattern_of_cells`](crate::least_squares::normal_pattern_of_cells) gives from the faces, in
/// one pass over the graph.
pub fn pattern_of_unknowns<T: DofScalar>(
    vertex_graph: SymbolicSparseColMatRef<'_, usize>,
    dofs: &DofMap<T>,
) -> Option<SymbolicSparseColMat<usize>> {
    let nodes = dofs.n_nodes();
    if vertex_graph.nrows() != nodes || vertex_graph.ncols() != nodes {
        return None;
    }
    let mut unknown = vec![usize::MAX; nodes];
    let mut next = 0;
    for (v, slot) in unknown.iter_mut().enumerate() {
        let mut terms = dofs.node_terms(VertexId::from_usize(v)).ok()?;
        if let Some((_, term)) = terms.next() {
            if term.dof != next || terms.next().is_some() {
                return None;
            }
            *slot = next;
            next += 1;
        }
    }
    let n = dofs.reduced_len();
    if next != n {
        return None;
    }
    let mut col_ptr = Vec::with_capacity(n + 1);
    let mut rows = Vec::with_capacity(vertex_graph.row_idx().len());
    col_ptr.push(0);
    for v in (0..nodes).filter(|&v| unknown[v] != usize::MAX) {
        let start = rows.len();
        rows.extend(
            vertex_graph
                .row_idx_of_col(v)
                .map(|w| unknown.get(w).copied().unwrap_or(usize::MAX))
                .filter(|&c| c != usize::MAX),
        );
        // Sorted in, sorted out (the renumbering keeps the order); a pattern given
        // with unsorted rows is declined.
        if !rows[start..].is_sorted_by(|a, b| a < b) {
            return None;
        }
        col_ptr.push(rows.len());
    }
    Some(SymbolicSparseColMat::new_checked(n, n, col_ptr, None, rows))
}

/// `vertex_order`, an order of `dofs`' nodes (an order of the vertex graph: cheaper to order than
/// the unknowns' graph, and ready before the DOF map is) carried over to its reduced
/// unknowns: the unknowns that move one node alone take that node's place, the
/// unknowns shared by several nodes go last, in increasing order (with the separator
/// when there are sides); a fixed node has none. The sides' lengths are counted
/// again in unknowns.
///
/// Errors: [`SolveError::Length`] when the order is not as long as `dofs` has nodes
/// or its sides are longer, [`SolveError::InvalidOrder`] for a node out of range.
pub fn order_of_unknowns<T: DofScalar>(
    vertex_order: &SplitOrder,
    dofs: &DofMap<T>,
) -> Result<SplitOrder, SolveError> {
    let nodes = dofs.n_nodes();
    check_len("the length of the order", nodes, vertex_order.order.len())?;
    let n = dofs.reduced_len();
    let shared: Vec<bool> = (0..n)
        .map(|j| dofs.unknown_nodes(j).is_some_and(|nodes| nodes.count() > 1))
        .collect();
    let [a, b] = vertex_order.sides.unwrap_or([nodes, 0]);
    check_len("the sides of the order", nodes, nodes.max(a + b))?;
    let mut order = Vec::with_capacity(n);
    let mut ends = [0; 2];
    for (part, range) in [0..a, a..a + b, a + b..nodes].into_iter().enumerate() {
        for (k, &v) in vertex_order.order[range.clone()].iter().enumerate() {
            let terms =
                dofs.node_terms(VertexId::from_usize(v))
                    .map_err(|_| SolveError::InvalidOrder {
                        index: range.start + k,
                    })?;
            order.extend(terms.map(|(_, t)| t.dof).filter(|&j| !shared[j]));
        }
        if let Some(end) = ends.get_mut(part) {
            *end = order.len();
        }
    }
    order.extend((0..n).filter(|&j| shared[j]));
    Ok(SplitOrder {
        order,
        sides: vertex_order.sides.map(|_| [ends[0], ends[1] - ends[0]]),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_mesh::primitives::{Cells, grid};

    #[test]
    fn the_pattern_holds_each_vertex_and_each_edge_once() {
        // A 4 x 3 grid of squares split into triangles: 20 vertices, 43 edges.
        let mesh = Mesh::from_soup(&grid(4, 3, Cells::Triangles)).unwrap();
        let pattern = vertex_graph_pattern(&mesh);
        assert_eq!(pattern.nrows(), mesh.vertex_count());
        assert_eq!(
            pattern.row_idx().len(),
            mesh.vertex_count() + mesh.edge_count()
        );
        for e in mesh.edges() {
            let [a, b] = mesh.edge_vertices(e).map(|v| v.idx());
            let (low, high) = (a.min(b), a.max(b));
            assert!(pattern.row_idx_of_col(low).any(|r| r == high), "{a}-{b}");
        }
        for v in 0..pattern.ncols() {
            let column: Vec<usize> = pattern.row_idx_of_col(v).collect();
            assert_eq!(column[0], v);
            assert!(
                column.windows(2).all(|w| w[0] < w[1]),
                "column {v}: {column:?}"
            );
        }
    }

    #[test]
    fn carried_to_the_unknowns_the_graph_is_the_faces_pattern() {
        use crate::dof::DofConstraints;
        use crate::least_squares::normal_pattern_of_cells;
        use beltrami_mesh::FaceId;
        use num_complex::Complex64;
        let mesh = Mesh::from_soup(&grid(9, 7, Cells::Triangles)).unwrap();
        let mut constraints = DofConstraints::new();
        constraints.fix(VertexId::from_usize(0), Complex64::new(0.0, 0.0));
        constraints.fix(VertexId::from_usize(33), Complex64::new(1.0, 0.0));
        let dofs = DofMap::complex(mesh.vertex_count(), &constraints).unwrap();
        let graph = vertex_graph_pattern(&mesh);
        let carried = pattern_of_unknowns(graph.as_ref(), &dofs).expect("one unknown per node");
        let faces = (0..mesh.face_count()).map(|f| mesh.face_vertices(FaceId::from_usize(f)));
        let from_faces = normal_pattern_of_cells(faces, &dofs).unwrap();
        assert_eq!(carried.col_ptr(), from_faces.col_ptr());
        assert_eq!(carried.row_idx(), from_faces.row_idx());
        // Two nodes sharing an unknown, or a graph of other nodes: declined.
        let mut shared = DofConstraints::new();
        shared.share(VertexId::from_usize(1), VertexId::from_usize(2));
        let shared = DofMap::complex(mesh.vertex_count(), &shared).unwrap();
        assert!(pattern_of_unknowns(graph.as_ref(), &shared).is_none());
        let other = DofMap::<Complex64>::complex(10, &DofConstraints::new()).unwrap();
        assert!(pattern_of_unknowns(graph.as_ref(), &other).is_none());
    }
}
