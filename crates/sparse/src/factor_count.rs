//! The size and cost of a sparse Cholesky factor for a given elimination order, exactly,
//! without forming the factor.
//!
//! For the symmetric pattern `A` (read as `pattern + pattern^T`) eliminated in the
//! order `P`, column `j` of `L` (`P A P^T = L L^H`) holds `c_j` entries, the diagonal
//! included; the counts come from the elimination tree of `P A P^T` (Gilbert, Ng,
//! Peyton 1994; faer's `prefactorize_symbolic_cholesky`) in time about proportional to
//! the entries of `L`, a small part of the symbolic analysis. The factorization's
//! multiply-subtract count is `sum_j r_j (r_j + 1) / 2` with `r_j = c_j - 1` the
//! entries below the diagonal: eliminating column `j` updates the lower triangle of an
//! `r_j x r_j` block. That is the quantity AMD estimates for its own order
//! (`n_mult_subs_ldl`), so the two compare directly.

use crate::SolveError;
use crate::spd::inverse_permutation;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::simplicial::{
    prefactorize_symbolic_cholesky, prefactorize_symbolic_cholesky_scratch,
};
use faer::sparse::linalg::cholesky::{SymbolicCholesky, SymbolicCholeskyRaw};
use faer::sparse::{FaerError, SymbolicSparseColMatRef};

/// The entries and operations of a Cholesky factor (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FactorCount {
    /// Entries of `L`, the diagonal included: `sum_j c_j`.
    pub entries: usize,
    /// Multiply-subtract operations of the factorization: `sum_j r_j (r_j + 1) / 2`.
    pub multiply_subtracts: f64,
}

/// The factor's [`FactorCount`] of the square pattern `pattern + pattern^T` eliminated
/// in `order` (`order[k]` is the row eliminated `k`-th).
///
/// Errors: [`SolveError::InvalidOrder`] when `order` is not a permutation of the rows,
/// [`SolveError::Faer`] when memory runs out.
pub fn factor_count(
    pattern: SymbolicSparseColMatRef<'_, usize>,
    order: &[usize],
) -> Result<FactorCount, SolveError> {
    let n = pattern.nrows();
    crate::check::check_len("the length of the order", n, order.len())?;
    let inverse = inverse_permutation(order)?;
    // The upper triangle of P A P^T, by a counting pass: an entry (i, j), i != j, read
    // in either triangle, goes to column max(p_i, p_j) at row min(p_i, p_j). Rows stay
    // unsorted and may repeat; the elimination tree and the counts allow both.
    let permuted = |i: usize, j: usize| {
        let (a, b) = (inverse[i], inverse[j]);
        (a.min(b), a.max(b))
    };
    let mut col_ptr = vec![0usize; n + 1];
    for j in 0..n {
        for i in pattern.row_idx_of_col(j).filter(|&i| i != j) {
            col_ptr[permuted(i, j).1 + 1] += 1;
        }
    }
    for j in 0..n {
        col_ptr[j + 1] += col_ptr[j];
    }
    let mut next = col_ptr[..n].to_vec();
    let mut row_idx = vec![0usize; col_ptr[n]];
    for j in 0..n {
        for i in pattern.row_idx_of_col(j).filter(|&i| i != j) {
            let (row, col) = permuted(i, j);
            row_idx[next[col]] = row;
            next[col] += 1;
        }
    }
    let upper = SymbolicSparseColMatRef::new_unsorted_checked(n, n, &col_ptr, None, &row_idx);
    let mut etree = vec![0isize; n];
    let mut counts = vec![0usize; n];
    let mut buffer = MemBuffer::try_new(prefactorize_symbolic_cholesky_scratch::<usize>(
        n,
        row_idx.len(),
    ))
    .map_err(|_| FaerError::OutOfMemory)?;
    prefactorize_symbolic_cholesky(&mut etree, &mut counts, upper, MemStack::new(&mut buffer));
    Ok(FactorCount {
        entries: counts.iter().sum(),
        multiply_subtracts: counts
            .iter()
            .map(|&c| column_multiply_subtracts(c.saturating_sub(1)))
            .sum(),
    })
}

/// The multiply-subtracts of eliminating a column with `below` entries under its
/// diagonal: `r (r + 1) / 2`, the lower triangle of an `r x r` update.
pub(super) fn column_multiply_subtracts(below: usize) -> f64 {
    let below = below as f64;
    below * (below + 1.0) / 2.0
}

/// The multiply-subtract count (`sum_j r_j (r_j + 1) / 2`, as in [`FactorCount`]) of
/// the first `columns` columns of the factor as faer stores it (`symbolic`): exact for
/// a simplicial factor; a supernodal factor stores each supernode's columns with the
/// union of their rows, so where faer's relaxation merged columns of different
/// structure the zeros it stores count too, and the result is at least the exact count.
pub(super) fn stored_multiply_subtracts(symbolic: &SymbolicCholesky<usize>, columns: usize) -> f64 {
    match symbolic.raw() {
        SymbolicCholeskyRaw::Simplicial(s) => s.col_ptr()[..=columns.min(s.nrows())]
            .windows(2)
            .map(|w| column_multiply_subtracts(w[1] - w[0] - 1))
            .sum(),
        SymbolicCholeskyRaw::Supernodal(s) => (0..s.n_supernodes())
            .map(|node| {
                let (begin, end) = (s.supernode_begin()[node], s.supernode_end()[node]);
                let below_block = s.supernode(node).pattern().len();
                // Column `begin + k` stores the rest of the diagonal block and the
                // supernode's rows below it.
                (begin..end.min(columns))
                    .map(|j| column_multiply_subtracts(end - 1 - j + below_block))
                    .sum::<f64>()
            })
            .sum(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Side;
    use faer::perm::PermRef;
    use faer::sparse::SymbolicSparseColMat;
    use faer::sparse::linalg::SupernodalThreshold;
    use faer::sparse::linalg::cholesky::{
        CholeskySymbolicParams, SymmetricOrdering, factorize_symbolic_cholesky,
    };

    /// The lower triangle (diagonal included) of the pattern with the given edges.
    fn pattern(n: usize, edges: &[(usize, usize)]) -> SymbolicSparseColMat<usize> {
        let mut columns: Vec<Vec<usize>> = (0..n).map(|j| vec![j]).collect();
        for &(a, b) in edges {
            columns[a.min(b)].push(a.max(b));
        }
        let mut col_ptr = vec![0];
        let mut row_idx = Vec::new();
        for mut column in columns {
            column.sort_unstable();
            row_idx.extend(column);
            col_ptr.push(row_idx.len());
        }
        SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx)
    }

    #[test]
    fn a_path_has_no_fill_and_a_star_fills_only_when_its_centre_goes_first() {
        let n = 50;
        // A path in its own order: one entry below each diagonal but the last.
        let path: Vec<_> = (1..n).map(|i| (i - 1, i)).collect();
        let natural: Vec<usize> = (0..n).collect();
        let count = factor_count(pattern(n, &path).as_ref(), &natural).unwrap();
        assert_eq!(count.entries, 2 * n - 1);
        assert_eq!(count.multiply_subtracts, (n - 1) as f64);
        // A star: its centre eliminated last leaves the leaves' columns with one entry
        // below the diagonal; first, it joins every leaf to every other (a dense factor).
        let star: Vec<_> = (1..n).map(|i| (0, i)).collect();
        let star = pattern(n, &star);
        let centre_last: Vec<usize> = (1..n).chain([0]).collect();
        let count = factor_count(star.as_ref(), &centre_last).unwrap();
        assert_eq!(count.entries, 2 * n - 1);
        let count = factor_count(star.as_ref(), &natural).unwrap();
        assert_eq!(count.entries, n * (n + 1) / 2);
        let dense: f64 = (0..n).map(|r| (r * (r + 1) / 2) as f64).sum();
        assert_eq!(count.multiply_subtracts, dense);
    }

    /// faer's symbolic analysis of `pattern` in `order`, simplicial or supernodal.
    fn analysed(
        pattern: SymbolicSparseColMatRef<'_, usize>,
        order: &[usize],
        threshold: SupernodalThreshold,
    ) -> SymbolicCholesky<usize> {
        let inverse = inverse_permutation(order).unwrap();
        factorize_symbolic_cholesky(
            pattern,
            Side::Lower,
            SymmetricOrdering::Custom(PermRef::new_checked(order, &inverse, order.len())),
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: threshold,
                ..Default::default()
            },
        )
        .unwrap()
    }

    #[test]
    fn the_stored_count_is_exact_for_simplicial_factors_and_bounds_supernodal_ones() {
        // A 30 x 30 grid with diagonals in a scattered order (plenty of fill, supernodes
        // of varied structure for faer's relaxation to merge).
        let (start, neighbours) = crate::vertex_separator::tests::grid(30, false);
        let edges: Vec<(usize, usize)> = (0..start.len() - 1)
            .flat_map(|v| {
                neighbours[start[v]..start[v + 1]]
                    .iter()
                    .map(move |&w| (v, w as usize))
            })
            .filter(|&(v, w)| v < w)
            .collect();
        let grid = pattern(start.len() - 1, &edges);
        let n = grid.nrows();
        let order: Vec<usize> = (0..n).map(|i| (i * 37) % n).collect();
        let exact = factor_count(grid.as_ref(), &order)
            .unwrap()
            .multiply_subtracts;
        let simplicial = analysed(grid.as_ref(), &order, SupernodalThreshold::FORCE_SIMPLICIAL);
        assert!(matches!(
            simplicial.raw(),
            SymbolicCholeskyRaw::Simplicial(_)
        ));
        assert_eq!(stored_multiply_subtracts(&simplicial, n), exact);
        let supernodal = analysed(grid.as_ref(), &order, SupernodalThreshold::FORCE_SUPERNODAL);
        assert!(matches!(
            supernodal.raw(),
            SymbolicCholeskyRaw::Supernodal(_)
        ));
        let stored = stored_multiply_subtracts(&supernodal, n);
        assert!(
            (exact..1.2 * exact).contains(&stored),
            "stored {stored}, exact {exact}"
        );
        // A prefix of the columns: the same sums cut at the same column.
        let half = n / 2;
        let SymbolicCholeskyRaw::Simplicial(columns) = simplicial.raw() else {
            unreachable!()
        };
        let prefix: f64 = (0..half)
            .map(|j| {
                let below = (columns.col_ptr()[j + 1] - columns.col_ptr()[j] - 1) as f64;
                below * (below + 1.0) / 2.0
            })
            .sum();
        assert_eq!(stored_multiply_subtracts(&simplicial, half), prefix);
        let stored_half = stored_multiply_subtracts(&supernodal, half);
        assert!(prefix <= stored_half && stored_half < stored);
    }

    #[test]
    fn entries_read_in_either_triangle_count_alike() {
        // The 4-cycle, stored in the lower triangle, then in the upper one.
        let edges = [(0, 1), (1, 2), (2, 3), (0, 3)];
        let lower = pattern(4, &edges);
        let upper = lower.as_ref().transpose().to_col_major().unwrap();
        let order = [0, 1, 2, 3];
        // Eliminating 0 joins 1 and 3: one fill entry, 4 + 4 + 1 = 9 entries.
        let count = factor_count(lower.as_ref(), &order).unwrap();
        assert_eq!(count.entries, 9);
        assert_eq!(factor_count(upper.as_ref(), &order).unwrap(), count);
        assert!(matches!(
            factor_count(lower.as_ref(), &[0, 1, 1, 3]),
            Err(SolveError::InvalidOrder { index: 2 })
        ));
    }
}
