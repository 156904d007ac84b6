//! Sparse assembly into a fixed pattern.
//!
//! Building a compressed-column matrix from triplets sorts the triplets every time, which
//! dominates the cost of a solve on large meshes. A [`Pattern`] sorts the entry positions
//! once (faer's `try_new_from_indices` returns the pattern and the permutation, "argsort")
//! and every later assembly only scatters new values through that permutation
//! (`new_from_argsort`), summing duplicates.

use faer::sparse::{Argsort, Pair, SparseColMat, SymbolicSparseColMat};
use faer::traits::ComplexField;

use crate::FemError;

/// The sparsity pattern of a matrix assembled from a fixed list of entry positions.
#[derive(Debug, Clone)]
pub struct Pattern {
    symbolic: SymbolicSparseColMat<usize>,
    argsort: Argsort<usize>,
    entries: usize,
}

impl Pattern {
    /// The pattern of an `nrows x ncols` matrix with entries at `positions`
    /// (`(row, col)`, duplicates allowed and summed on assembly).
    pub fn new(nrows: usize, ncols: usize, positions: &[(usize, usize)]) -> Result<Self, FemError> {
        let pairs: Vec<Pair<usize, usize>> = positions
            .iter()
            .map(|&(row, col)| Pair { row, col })
            .collect();
        let (symbolic, argsort) = SymbolicSparseColMat::try_new_from_indices(nrows, ncols, &pairs)
            .map_err(|e| FemError::Assembly(format!("{e:?}")))?;
        Ok(Self {
            symbolic,
            argsort,
            entries: positions.len(),
        })
    }

    /// For each of `positions` (the list given to [`Pattern::new`]), the index of its
    /// entry in the values of the assembled matrix: callers that refill one matrix many
    /// times add into `values[slot[k]]` instead of assembling a new matrix.
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

    /// Number of entry positions (before summing duplicates).
    pub fn entry_count(&self) -> usize {
        self.entries
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
        if values.len() != self.entries {
            return Err(FemError::Length {
                what: "assembly values",
                expected: self.entries,
                got: values.len(),
            });
        }
        SparseColMat::new_from_argsort(self.symbolic.clone(), &self.argsort, values)
            .map_err(|e| FemError::Assembly(format!("{e:?}")))
    }
}
