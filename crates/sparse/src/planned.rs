//! The symbolic factorization computed ahead of the values.

use crate::check::check_len;
use crate::cholesky::Cholesky;
use crate::nested_dissection;
use crate::ordering::NESTED_DISSECTION_FROM;
use crate::spd::inverse_permutation;
use crate::{Scalar, SolveError, SolveOptions, SplitOrder};
use faer::sparse::{SymbolicSparseColMat, SymbolicSparseColMatRef};
use std::fmt;

/// The symbolic Cholesky factorization of a pattern, computed on its own, so that a
/// caller can compute it on another thread while it assembles the matrices
/// (`LeastSquaresSolver::with_planned` of `beltrami-fem`): on a large mesh the order and the symbolic
/// analysis take about as long as assembling.
///
/// The elimination order is [`fill_reducing_order`](crate::fill_reducing_order)'s; a nested-dissection order is
/// factored in its first split's two sides at once (`two_domains` module). The
/// factor's storage is allocated and written here: the kernel clears every page a
/// process touches for the first time, and the factor is the largest block of a solve
/// (0.6 GB on the 1M-triangle disk).
pub struct PlannedCholesky<T: Scalar> {
    /// The pattern planned for.
    pub(crate) pattern: SymbolicSparseColMat<usize>,
    /// `None` when the pattern has no rows.
    pub(crate) cholesky: Option<Cholesky<T>>,
}

impl<T: Scalar> fmt::Debug for PlannedCholesky<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("PlannedCholesky")
            .field("n", &self.pattern.nrows())
            .field(
                "two_sides",
                &matches!(self.cholesky, Some(Cholesky::Halves(_))),
            )
            .finish_non_exhaustive()
    }
}

impl<T: Scalar> PlannedCholesky<T> {
    /// The symbolic factorization of the square pattern `pattern` (only its lower
    /// triangle matters), for factorizations with `options`' threads.
    pub fn new(
        pattern: SymbolicSparseColMat<usize>,
        options: SolveOptions,
    ) -> Result<Self, SolveError> {
        let n = pattern.nrows();
        check_len("the column count of the pattern", n, pattern.ncols())?;
        let cholesky = if n > 0 {
            Some(Cholesky::new(pattern.as_ref(), options)?)
        } else {
            None
        };
        Ok(Self { pattern, cholesky })
    }

    /// [`PlannedCholesky::new`] with the nested-dissection order of the pattern given
    /// (`split`, computed elsewhere: on the vertex graph while the DOF map was made,
    /// carried over to the unknowns by `beltrami-fem`), judged as `new` judges its own: from
    /// [`NESTED_DISSECTION_FROM`] rows it is taken when its factor is cheap enough, else
    /// AMD's order is computed too and the cheaper taken; below, `split` is not used and
    /// the order is AMD's.
    ///
    /// Errors: as [`PlannedCholesky::new`]; [`SolveError::InvalidOrder`] when `split`'s
    /// order is not a permutation of the rows, [`SolveError::Length`] when its sides
    /// are longer than the order.
    pub fn with_dissection(
        pattern: SymbolicSparseColMat<usize>,
        split: SplitOrder,
        options: SolveOptions,
    ) -> Result<Self, SolveError> {
        let n = pattern.nrows();
        check_len("the column count of the pattern", n, pattern.ncols())?;
        check_len("the length of the order", n, split.order.len())?;
        if let Some([a, b]) = split.sides {
            check_len("the sides of the order", n, n.max(a + b))?;
        }
        inverse_permutation(&split.order)?;
        let cholesky = if n >= NESTED_DISSECTION_FROM {
            let dissected = nested_dissection::Dissected {
                order: split.order,
                halves: split.sides,
            };
            Some(Cholesky::from_dissection(
                pattern.as_ref(),
                dissected,
                options,
            )?)
        } else if n > 0 {
            Some(Cholesky::new(pattern.as_ref(), options)?)
        } else {
            None
        };
        Ok(Self { pattern, cholesky })
    }

    /// The number of unknowns.
    pub fn len(&self) -> usize {
        self.pattern.nrows()
    }

    /// True when there are no unknowns.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The pattern planned for.
    pub fn pattern(&self) -> SymbolicSparseColMatRef<'_, usize> {
        self.pattern.as_ref()
    }

    /// True when this plan was made for exactly `pattern` (same size, same entries):
    /// then [`SpdSolver::from_planned`](crate::SpdSolver::from_planned) takes it for
    /// that pattern's matrices.
    pub fn is_for(&self, pattern: SymbolicSparseColMatRef<'_, usize>) -> bool {
        self.pattern.nrows() == pattern.nrows()
            && self.pattern.col_ptr() == pattern.col_ptr()
            && self.pattern.row_idx() == pattern.row_idx()
    }
}
