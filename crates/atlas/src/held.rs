//! Holding vertices of a Laplacian at given values by a penalty on their diagonal
//! entries: one symbolic factorization then serves any set of held vertices (the
//! cones' scale factors, the unit disk's Neumann and Dirichlet problems).

use faer::sparse::SparseColMat;

/// The relative size of the penalty that holds a vertex: its value then follows the
/// right-hand side over the penalized diagonal to about `1 / PENALTY`.
pub(crate) const PENALTY: f64 = 1e10;

/// Per column `j` of `matrix`, the index among its values of the diagonal entry `(j, j)`
/// (the column's first entry where the pattern has none; a Laplacian has every one).
pub(crate) fn diagonal_slots(matrix: &SparseColMat<usize, f64>) -> Vec<usize> {
    let symbolic = matrix.symbolic();
    let (col_ptr, rows) = (symbolic.col_ptr(), symbolic.row_idx());
    (0..matrix.ncols())
        .map(|j| {
            (col_ptr[j]..col_ptr[j + 1])
                .find(|&k| rows[k] == j)
                .unwrap_or(col_ptr[j])
        })
        .collect()
}
