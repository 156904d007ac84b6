//! The checks every solve makes of its inputs and results, as [`SolveError`]s: for
//! solvers built on this crate that check their own inputs the same way.

use crate::{Scalar, SolveError};
use faer::sparse::SparseColMatRef;

/// [`SolveError::Length`] unless `got == expected`; `what` names the dimension.
pub fn check_len(what: &'static str, expected: usize, got: usize) -> Result<(), SolveError> {
    if expected == got {
        Ok(())
    } else {
        Err(SolveError::Length {
            what,
            expected,
            got,
        })
    }
}

/// [`SolveError::NonFiniteEntry`] at the first NaN or infinite entry of `m`.
pub fn check_finite_matrix<T: Scalar>(
    what: &'static str,
    m: SparseColMatRef<'_, usize, T>,
) -> Result<(), SolveError> {
    for col in 0..m.ncols() {
        for (row, v) in m.row_idx_of_col(col).zip(m.val_of_col(col)) {
            if !v.finite() {
                return Err(SolveError::NonFiniteEntry { what, row, col });
            }
        }
    }
    Ok(())
}

/// [`SolveError::NonFinite`] at the first NaN or infinite entry of `v`.
pub fn check_finite<T: Scalar>(what: &'static str, v: &[T]) -> Result<(), SolveError> {
    match v.iter().position(|x| !x.finite()) {
        Some(index) => Err(SolveError::NonFinite { what, index }),
        None => Ok(()),
    }
}

/// [`SolveError::NonFiniteSolution`] at the first NaN or infinite entry of `v`.
pub fn check_finite_solution<T: Scalar>(v: &[T]) -> Result<(), SolveError> {
    match v.iter().position(|x| !x.finite()) {
        Some(index) => Err(SolveError::NonFiniteSolution { index }),
        None => Ok(()),
    }
}
