//! Sparse assembly into a fixed pattern.
//!
//! Building a compressed-column matrix from triplets sorts the triplets every time, which
//! dominates the cost of a solve on large meshes. A [`Pattern`] sorts the entry positions
//! once and records, for each position, the index of its entry among the matrix's
//! values (its *slot*); every later assembly only adds new values into their slots,
//! summing duplicates.
//!
//! The positions are bucketed by column (a counting sort, linear in their number) and
//! only each column's few distinct rows are sorted.

use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use faer::traits::ComplexField;

use crate::FemError;

/// The sparsity pattern of a matrix assembled from a fixed list of entry positions.
#[derive(Debug, Clone)]
pub struct Pattern {
    symbolic: SymbolicSparseColMat<usize>,
    /// Per position given to [`Pattern::new`], the index of its entry in the values.
    slots: Vec<usize>,
}

impl Pattern {
    /// The pattern of an `nrows x ncols` matrix with entries at `positions`
    /// (`(row, col)`, duplicates allowed and summed on assembly). Fails on a position
    /// outside the matrix, naming it.
    pub fn new(nrows: usize, ncols: usize, positions: &[(usize, usize)]) -> Result<Self, FemError> {
        let mut col_ptr = vec![0usize; ncols + 1];
        for (k, &(row, col)) in positions.iter().enumerate() {
            if row >= nrows || col >= ncols {
                return Err(FemError::Assembly(format!(
                    "entry {k} at ({row}, {col}) lies outside the {nrows} x {ncols} matrix"
                )));
            }
            col_ptr[col + 1] += 1;
        }
        for c in 0..ncols {
            col_ptr[c + 1] += col_ptr[c];
        }
        // The positions' indices bucketed by column, each bucket in input order.
        let mut next = col_ptr.clone();
        let mut by_column = vec![0usize; positions.len()];
        for (k, &(_, col)) in positions.iter().enumerate() {
            by_column[next[col]] = k;
            next[col] += 1;
        }
        // Per row, the last column it was met in and its rank among that column's rows.
        let mut met_in = vec![usize::MAX; nrows];
        let mut rank = vec![0usize; nrows];
        let mut slots = vec![0usize; positions.len()];
        let mut row_idx = Vec::with_capacity(positions.len());
        let mut new_col_ptr = Vec::with_capacity(ncols + 1);
        new_col_ptr.push(0);
        for c in 0..ncols {
            let start = row_idx.len();
            let bucket = &by_column[col_ptr[c]..col_ptr[c + 1]];
            for &k in bucket {
                let row = positions[k].0;
                if met_in[row] != c {
                    met_in[row] = c;
                    row_idx.push(row);
                }
            }
            row_idx[start..].sort_unstable();
            for (i, &row) in row_idx[start..].iter().enumerate() {
                rank[row] = start + i;
            }
            for &k in bucket {
                slots[k] = rank[positions[k].0];
            }
            new_col_ptr.push(row_idx.len());
        }
        let symbolic = SymbolicSparseColMat::new_checked(nrows, ncols, new_col_ptr, None, row_idx);
        Ok(Self { symbolic, slots })
    }

    /// For each of `positions`, the index of its entry in the values of the assembled
    /// matrix: callers that refill one matrix many times add into `values[slot[k]]`
    /// instead of assembling a new matrix. Fails on a position not in the pattern.
    pub fn value_slots(&self, positions: &[(usize, usize)]) -> Result<Vec<usize>, FemError> {
        let col_ptr = self.symbolic.col_ptr();
        let rows = self.symbolic.row_idx();
        positions
            .iter()
            .map(|&(row, col)| {
                let range = col_ptr.get(col).copied().zip(col_ptr.get(col + 1).copied());
                let found = range.and_then(|(start, end)| {
                    rows[start..end].binary_search(&row).ok().map(|k| start + k)
                });
                found.ok_or_else(|| {
                    FemError::Assembly(format!("({row}, {col}) is not in the pattern"))
                })
            })
            .collect()
    }

    /// The slots ([`Pattern::value_slots`]) of the positions given to [`Pattern::new`],
    /// without searching for them.
    pub fn slots(&self) -> &[usize] {
        &self.slots
    }

    /// Number of entry positions (before summing duplicates).
    pub fn entry_count(&self) -> usize {
        self.slots.len()
    }

    /// The symbolic structure (for symbolic factorizations reused across assemblies).
    pub fn symbolic(&self) -> &SymbolicSparseColMat<usize> {
        &self.symbolic
    }

    /// The matrix with `values[k]` added at `positions[k]` of [`Pattern::new`].
    pub fn assemble<T: ComplexField>(
        &self,
        values: &[T],
    ) -> Result<SparseColMat<usize, T>, FemError> {
        if values.len() != self.slots.len() {
            return Err(FemError::Length {
                what: "assembly values",
                expected: self.slots.len(),
                got: values.len(),
            });
        }
        let mut summed = vec![T::zero_impl(); self.symbolic.row_idx().len()];
        for (&slot, value) in self.slots.iter().zip(values) {
            summed[slot] += value;
        }
        Ok(SparseColMat::new(self.symbolic.clone(), summed))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Positions of a `rows x cols` matrix from a fixed linear congruential sequence,
    /// with many duplicates.
    fn scattered(rows: usize, cols: usize, count: usize) -> Vec<(usize, usize)> {
        let mut state: u64 = 12345;
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) as usize
        };
        (0..count).map(|_| (next() % rows, next() % cols)).collect()
    }

    #[test]
    fn assembly_sums_every_position_into_its_entry() {
        let (rows, cols) = (50, 40);
        let positions = scattered(rows, cols, 3000);
        let values: Vec<f64> = (0..positions.len()).map(|k| 1.0 + k as f64).collect();
        let pattern = Pattern::new(rows, cols, &positions).unwrap();
        let matrix = pattern.assemble(&values).unwrap();
        let mut dense = vec![vec![0.0; cols]; rows];
        for (&(r, c), &v) in positions.iter().zip(&values) {
            dense[r][c] += v;
        }
        let symbolic = matrix.symbolic();
        let (col_ptr, row_idx) = (symbolic.col_ptr(), symbolic.row_idx());
        let mut stored = 0;
        for c in 0..cols {
            let column = &row_idx[col_ptr[c]..col_ptr[c + 1]];
            assert!(column.windows(2).all(|w| w[0] < w[1]), "column {c}");
            let occupied = (0..rows).filter(|&r| dense[r][c] != 0.0).count();
            assert_eq!(column.len(), occupied, "column {c}");
            for (k, &r) in column.iter().enumerate() {
                assert_eq!(matrix.val()[col_ptr[c] + k], dense[r][c], "({r}, {c})");
            }
            stored += column.len();
        }
        assert_eq!(stored, matrix.val().len());
        assert_eq!(pattern.slots(), pattern.value_slots(&positions).unwrap());
        assert_eq!(pattern.entry_count(), positions.len());
    }

    #[test]
    fn a_position_outside_the_matrix_is_named() {
        let error = Pattern::new(3, 3, &[(0, 0), (1, 2), (3, 1)]).unwrap_err();
        assert!(error.to_string().contains("entry 2 at (3, 1)"), "{error}");
        assert!(Pattern::new(3, 3, &[(0, 3)]).is_err());
        let empty = Pattern::new(2, 2, &[]).unwrap();
        assert_eq!(empty.assemble::<f64>(&[]).unwrap().val().len(), 0);
    }
}
