//! Sparse `L L^H` factorization with a reusable symbolic part, reusable buffers and a
//! singularity test on the pivots.
//!
//! faer's high-level `Llt::try_new_with_symbolic` allocates the factor and its scratch
//! on every call; iterative solvers refactor the same pattern every step, so this
//! wrapper keeps both and calls the low-level `SymbolicCholesky::factorize_numeric_llt`.

use crate::nested_dissection::Dissected;
use crate::ordering::{Choice, NESTED_DISSECTION_FROM, choose, dissected, nested_dissection_sure};
use crate::spd::inverse_permutation;
use crate::two_domains::{TwoDomains, TwoDomainsPlan};
use crate::{Kernel, Scalar, SolveError, SolveOptions};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::LltError;
use faer::perm::PermRef;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::supernodal::SupernodalLltRef;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
    factorize_symbolic_cholesky,
};
use faer::sparse::linalg::triangular_solve;
use faer::sparse::{FaerError, SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, Mat, MatMut, Par, Side};

/// Why a numeric factorization failed. Indices are rows of the matrix as given (the
/// fill-reducing permutation undone).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum FactorFailure {
    /// faer met a pivot `<= 0` (or NaN): singular or indefinite.
    NonPositivePivot { index: usize },
    /// Every pivot was positive but `pivot / diagonal < tolerance` at `index`.
    SmallPivot { index: usize, ratio: f64 },
}

/// `A = P^T L L^H P` of a Hermitian matrix whose lower triangle is read: one sparse
/// factorization of the whole matrix, or, for large matrices ordered by nested
/// dissection, two factorizations at once ([`TwoDomains`]).
pub(super) enum Cholesky<T: Scalar> {
    Whole(Box<Factor<T>>),
    Halves(Box<TwoDomains<T>>),
}

impl<T: Scalar> Cholesky<T> {
    /// Symbolic analysis (fill-reducing order, elimination tree, supernodes) of
    /// `pattern` (square; only its lower triangle matters). The order is
    /// [`fill_reducing_order`](crate::fill_reducing_order)'s; below
    /// [`NESTED_DISSECTION_FROM`] rows that is AMD, left to faer. A nested-dissection
    /// order is factored in its two sides at once ([`TwoDomains`]) when its first split
    /// has two sides.
    ///
    /// The two sides are analysed before the order is judged: when the count of their
    /// stored factors, the separator taken dense ([`TwoDomainsPlan::multiply_subtracts_bound`],
    /// at least the exact count), is within the bound where the dissection is taken
    /// outright, the exact count is not needed (0.12 s of one core on the 1M-triangle
    /// disk); otherwise the choice is made as `fill_reducing_order` makes it. The order
    /// taken is the same either way.
    pub(super) fn new(
        pattern: SymbolicSparseColMatRef<'_, usize>,
        options: SolveOptions,
    ) -> Result<Self, SolveError> {
        if pattern.nrows() < NESTED_DISSECTION_FROM {
            return Self::with_ordering(pattern, None, options);
        }
        Self::from_dissection(pattern, dissected(pattern)?, options)
    }

    /// [`Cholesky::new`] with the nested-dissection order `dissected` of `pattern`
    /// computed (at least [`NESTED_DISSECTION_FROM`] rows): the same choice between it
    /// and AMD's order.
    pub(super) fn from_dissection(
        pattern: SymbolicSparseColMatRef<'_, usize>,
        dissected: Dissected,
        options: SolveOptions,
    ) -> Result<Self, SolveError> {
        let n = pattern.nrows();
        let plan = match dissected.halves {
            Some(halves) => TwoDomainsPlan::new(pattern, &dissected.order, halves, options.kernel)?,
            None => None,
        };
        let sure = plan
            .as_ref()
            .is_some_and(|plan| plan.multiply_subtracts_bound() <= nested_dissection_sure(n));
        let choice = if sure {
            Choice::Nested(dissected)
        } else {
            choose(pattern, dissected)?.0
        };
        match (choice, plan) {
            (Choice::Nested(_), Some(plan)) => Ok(Self::Halves(Box::new(plan.into_factors()?))),
            // The order whole: the dissection whose sides could not be planned, or AMD's.
            (Choice::Nested(Dissected { order, .. }) | Choice::Amd(order), _) => {
                Self::split(pattern, &order, None, options)
            }
        }
    }

    /// [`Cholesky::new`] in the order `order` (a permutation of the rows) whose first
    /// `sides[0]` and next `sides[1]` rows are two sides no entry joins, the rest their
    /// separator: factored in the two sides at once ([`TwoDomains`]) where that works,
    /// else as a whole in `order`.
    pub(super) fn split(
        pattern: SymbolicSparseColMatRef<'_, usize>,
        order: &[usize],
        sides: Option<[usize; 2]>,
        options: SolveOptions,
    ) -> Result<Self, SolveError> {
        // The inverse also checks that the order is a permutation before either path.
        let inverse = inverse_permutation(order)?;
        if let Some(sides) = sides
            && let Some(two) = TwoDomains::new(pattern, order, sides, options.kernel)?
        {
            return Ok(Self::Halves(Box::new(two)));
        }
        Self::with_ordering(pattern, Some((order, &inverse)), options)
    }

    /// [`Cholesky::new`] with the elimination order `order` (`order[k]` is the row
    /// eliminated k-th) instead of AMD, when given, factored as a whole.
    pub(super) fn with_ordering(
        pattern: SymbolicSparseColMatRef<'_, usize>,
        order: Option<(&[usize], &[usize])>,
        options: SolveOptions,
    ) -> Result<Self, SolveError> {
        let ordering = match order {
            Some((forward, inverse)) => {
                SymmetricOrdering::Custom(PermRef::new_checked(forward, inverse, pattern.nrows()))
            }
            None => SymmetricOrdering::Amd,
        };
        Ok(Self::Whole(Box::new(Factor::build(
            pattern,
            Side::Lower,
            ordering,
            options,
        )?)))
    }

    /// Numeric factorization of `matrix` (the pattern given at construction, lower
    /// triangle read) and the pivot test of [`Factor::factorize`].
    pub(super) fn factorize(
        &mut self,
        matrix: SparseColMatRef<'_, usize, T>,
        tolerance: f64,
    ) -> Result<(), FactorFailure> {
        match self {
            Self::Whole(factor) => factor.factorize(matrix, tolerance),
            Self::Halves(two) => two.factorize(matrix, tolerance),
        }
    }

    /// Solves `A X = B` in place with the last successful factorization.
    pub(super) fn solve_in_place(&mut self, rhs: MatMut<'_, T>) -> Result<(), SolveError> {
        match self {
            Self::Whole(factor) => factor.solve_in_place(rhs),
            Self::Halves(two) => two.solve_in_place(rhs),
        }
    }
}

/// One sparse `L L^H` factorization of a whole matrix (faer's simplicial or supernodal
/// kernel, as its symbolic analysis chooses).
pub(super) struct Factor<T: Scalar> {
    symbolic: SymbolicCholesky<usize>,
    values: Vec<T>,
    /// Diagonal of the last matrix factored, in its own order.
    diagonal: Vec<f64>,
    buffer: MemBuffer,
    /// Right-hand-side columns the buffer holds room for.
    buffer_columns: usize,
    par: Par,
}

impl<T: Scalar> Factor<T> {
    /// Symbolic analysis of `pattern` in the elimination order `ordering` (AMD's,
    /// the rows as numbered, or given), of which `pattern` holds the triangle `side`:
    /// the matrices factored give their lower triangle, but faer analyses the pattern
    /// as numbered (`SymmetricOrdering::Identity`) only from its upper triangle. The
    /// factor's storage is written now, so that
    /// the kernel's first touch of its pages (which it clears) falls here, where a
    /// caller may have planned it ([`PlannedCholesky`](crate::PlannedCholesky)), rather
    /// than in the first numeric factorization.
    pub(super) fn build(
        pattern: SymbolicSparseColMatRef<'_, usize>,
        side: Side,
        ordering: SymmetricOrdering<'_, usize>,
        options: SolveOptions,
    ) -> Result<Self, SolveError> {
        Self::with_storage(
            analyse(pattern, side, ordering, options.kernel)?,
            options.par(),
        )
    }

    /// The factorization of `symbolic`'s pattern, its storage written now (see
    /// [`Factor::build`]).
    pub(super) fn with_storage(
        symbolic: SymbolicCholesky<usize>,
        par: Par,
    ) -> Result<Self, SolveError> {
        let n = symbolic.nrows();
        let req = Self::scratch(&symbolic, 1, par);
        let mut values = Vec::new();
        values
            .try_reserve_exact(symbolic.len_val())
            .map_err(|_| FaerError::OutOfMemory)?;
        values.resize(symbolic.len_val(), T::from_f64(0.0));
        Ok(Self {
            values,
            diagonal: vec![0.0; n],
            buffer: MemBuffer::try_new(req).map_err(|_| FaerError::OutOfMemory)?,
            buffer_columns: 1,
            par,
            symbolic,
        })
    }

    fn scratch(symbolic: &SymbolicCholesky<usize>, rhs_columns: usize, par: Par) -> StackReq {
        symbolic
            .factorize_numeric_llt_scratch::<T>(par, Default::default())
            .or(symbolic.solve_in_place_scratch::<T>(rhs_columns, par))
    }

    /// Numeric factorization of `matrix` (same pattern as at construction, lower
    /// triangle read), then the pivot test: with `d_k = |L_kk|^2` the k-th pivot in
    /// elimination order and `a_k` the matching diagonal entry of `matrix`, the matrix
    /// is declared singular when `min_k d_k / a_k < tolerance`.
    ///
    /// Why this test: `d_k / a_k` is invariant under diagonal scaling, lies in (0, 1],
    /// and is bounded below by `1 / cond`; for a singular matrix rounding leaves a pivot
    /// of about `n eps` relative to its diagonal (measured: `0.13 n eps` on grid
    /// Laplacians with no Dirichlet node up to n = 1e6), while pinned Laplacians keep
    /// every ratio above `1e-2` (a ratio is about one over the effective resistance to
    /// the pinned set, not one over the condition number).
    pub(super) fn factorize(
        &mut self,
        matrix: SparseColMatRef<'_, usize, T>,
        tolerance: f64,
    ) -> Result<(), FactorFailure> {
        for (j, d) in self.diagonal.iter_mut().enumerate() {
            *d = matrix
                .row_idx_of_col(j)
                .zip(matrix.val_of_col(j))
                .find(|&(i, _)| i == j)
                .map_or(0.0, |(_, v)| v.real());
        }
        let result = self.symbolic.factorize_numeric_llt::<T>(
            &mut self.values,
            matrix,
            Side::Lower,
            Default::default(),
            self.par,
            MemStack::new(&mut self.buffer),
            Default::default(),
        );
        let forward = |k: usize| eliminated(&self.symbolic, k);
        if let Err(LltError::NonPositivePivot { index }) = result {
            // faer 0.24 reports the pivot 1-based from the simplicial kernel and
            // 0-based from the supernodal one.
            let k = match self.symbolic.raw() {
                SymbolicCholeskyRaw::Simplicial(_) => index.saturating_sub(1),
                SymbolicCholeskyRaw::Supernodal(_) => index,
            };
            let last = self.diagonal.len().saturating_sub(1);
            return Err(FactorFailure::NonPositivePivot {
                index: forward(k.min(last)),
            });
        }
        let (mut worst, mut worst_ratio) = (0, f64::INFINITY);
        let mut visit = |k: usize, l_kk: T| {
            let ratio = l_kk.norm_sqr() / self.diagonal[forward(k)];
            if ratio < worst_ratio {
                (worst, worst_ratio) = (k, ratio);
            }
        };
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(s) => {
                // The diagonal entry is stored first in each column of L.
                for (k, &start) in s.col_ptr()[..s.nrows()].iter().enumerate() {
                    visit(k, self.values[start]);
                }
            }
            SymbolicCholeskyRaw::Supernodal(s) => {
                let l = SupernodalLltRef::new(s, &self.values);
                for si in 0..s.n_supernodes() {
                    let node = l.supernode(si);
                    let block = node.val();
                    for c in 0..block.ncols() {
                        visit(node.start() + c, block[(c, c)]);
                    }
                }
            }
        }
        if worst_ratio < tolerance {
            return Err(FactorFailure::SmallPivot {
                index: forward(worst),
                ratio: worst_ratio,
            });
        }
        Ok(())
    }

    /// Solves `A X = B` in place with the last successful factorization.
    pub(super) fn solve_in_place(&mut self, rhs: MatMut<'_, T>) -> Result<(), SolveError> {
        self.reserve_columns(rhs.ncols())?;
        LltRef::new(&self.symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            rhs,
            self.par,
            MemStack::new(&mut self.buffer),
        );
        Ok(())
    }
}

impl<T: Scalar> Factor<T> {
    /// Makes the buffer hold the scratch of solves with `columns` right-hand sides.
    fn reserve_columns(&mut self, columns: usize) -> Result<(), SolveError> {
        if columns > self.buffer_columns {
            // Grows only for more right-hand sides than ever before.
            self.buffer = MemBuffer::try_new(Self::scratch(&self.symbolic, columns, self.par))
                .map_err(|_| FaerError::OutOfMemory)?;
            self.buffer_columns = columns;
        }
        Ok(())
    }

    /// `Y = L^-1 Y` in place, the rows of `Y` in elimination order (row `k` the one
    /// eliminated `k`-th, [`Factor::eliminated`]): the forward half of a solve, without
    /// the permutation.
    pub(super) fn lower_solve_in_place(&mut self, rhs: MatMut<'_, T>) -> Result<(), SolveError> {
        self.reserve_columns(rhs.ncols())?;
        let stack = MemStack::new(&mut self.buffer);
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(sym) => {
                let l = SparseColMatRef::new(sym.factor(), &self.values);
                triangular_solve::solve_lower_triangular_in_place(l, Conj::No, rhs, self.par);
            }
            SymbolicCholeskyRaw::Supernodal(sym) => {
                SupernodalLltRef::new(sym, &self.values).l_solve_with_conj(
                    Conj::No,
                    rhs,
                    self.par,
                    stack,
                );
            }
        }
        Ok(())
    }

    /// `Y = L^-H Y` in place, the rows of `Y` in elimination order: the backward half
    /// of a solve, without the permutation.
    pub(super) fn lower_adjoint_solve_in_place(
        &mut self,
        rhs: MatMut<'_, T>,
    ) -> Result<(), SolveError> {
        self.reserve_columns(rhs.ncols())?;
        let stack = MemStack::new(&mut self.buffer);
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(sym) => {
                let l = SparseColMatRef::new(sym.factor(), &self.values);
                triangular_solve::solve_lower_triangular_transpose_in_place(
                    l,
                    Conj::Yes,
                    rhs,
                    self.par,
                );
            }
            SymbolicCholeskyRaw::Supernodal(sym) => {
                SupernodalLltRef::new(sym, &self.values).l_transpose_solve_with_conj(
                    Conj::Yes,
                    rhs,
                    self.par,
                    stack,
                );
            }
        }
        Ok(())
    }

    /// Whether faer chose its supernodal kernel (else the simplicial one).
    #[cfg(test)]
    pub(super) fn is_supernodal(&self) -> bool {
        matches!(self.symbolic.raw(), SymbolicCholeskyRaw::Supernodal(_))
    }

    /// The last `s` rows and columns of `L` in elimination order, as a dense
    /// lower-triangular `s x s` matrix (zeros above the diagonal). With the matrix
    /// `[A B^H; B C]`, `B` and `C` of `s` rows, this is the Cholesky factor of the Schur
    /// complement `C - B A^-1 B^H`.
    pub(super) fn trailing_factor(&self, s: usize) -> Mat<T> {
        let n = self.diagonal.len();
        let first = n - s;
        let mut l = Mat::<T>::zeros(s, s);
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(sym) => {
                for j in first..n {
                    for p in sym.col_ptr()[j]..sym.col_ptr()[j + 1] {
                        l[(sym.row_idx()[p] - first, j - first)] = self.values[p];
                    }
                }
            }
            SymbolicCholeskyRaw::Supernodal(sym) => {
                let factor = SupernodalLltRef::new(sym, &self.values);
                for si in 0..sym.n_supernodes() {
                    let node = factor.supernode(si);
                    let (start, block) = (node.start(), node.val());
                    let width = block.ncols();
                    // Rows of the block: the supernode's own columns, then its pattern.
                    for c in first.saturating_sub(start)..width {
                        let j = start + c - first;
                        for r in c..width {
                            l[(start + r - first, j)] = block[(r, c)];
                        }
                        for (q, &i) in node.pattern().iter().enumerate() {
                            l[(i - first, j)] = block[(width + q, c)];
                        }
                    }
                }
            }
        }
        l
    }
}

/// The symbolic analysis of [`Factor::build`], without the factor's storage, for
/// faer's numeric `kernel`.
pub(super) fn analyse(
    pattern: SymbolicSparseColMatRef<'_, usize>,
    side: Side,
    ordering: SymmetricOrdering<'_, usize>,
    kernel: Kernel,
) -> Result<SymbolicCholesky<usize>, SolveError> {
    let params = CholeskySymbolicParams {
        supernodal_flop_ratio_threshold: match kernel {
            Kernel::Auto => SupernodalThreshold::AUTO,
            Kernel::Supernodal => SupernodalThreshold::FORCE_SUPERNODAL,
        },
        ..Default::default()
    };
    Ok(factorize_symbolic_cholesky(
        pattern, side, ordering, params,
    )?)
}

/// The row of the matrix `symbolic` eliminates `k`-th.
pub(super) fn eliminated(symbolic: &SymbolicCholesky<usize>, k: usize) -> usize {
    match symbolic.perm() {
        Some(perm) => perm.arrays().0[k],
        None => k,
    }
}
