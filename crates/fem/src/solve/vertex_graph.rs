//! The pattern of a mesh's vertex graph, for ordering a factorization before the
//! unknowns are known.

use beltrami_mesh::{Mesh, VertexId};
use faer::sparse::SymbolicSparseColMat;

/// The lower triangle (diagonal included, each column's rows increasing) of the
/// symmetric pattern of `mesh`'s vertex graph: `(v, v)` for every vertex and `(w, v)`,
/// `w > v`, for every edge `{v, w}`. On a triangle mesh it is the pattern of any
/// energy coupling the vertices of each face (the cotangent Laplacian, the conformal
/// energy), before a DOF map drops fixed vertices; an order of it carries over to the
/// unknowns ([`SplitOrder::of_unknowns`](super::SplitOrder::of_unknowns)). On quads the
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
}
