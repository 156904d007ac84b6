//! Hermitian positive definite systems: one solve, or one pattern factored again and
//! again with its symbolic factorization kept.

use crate::check::{check_finite, check_finite_matrix, check_finite_solution, check_len};
use crate::cholesky::{Cholesky, FactorFailure};
use crate::{PlannedCholesky, Scalar, SolveError, SolveOptions, SplitOrder};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};
use faer::{Mat, MatMut, MatRef};
use std::fmt;

/// Solves `M X = R` for a Hermitian positive definite sparse `M` (e.g. a Laplacian with
/// its Dirichlet rows and columns eliminated), by sparse Cholesky `M = P^T L L^H P`.
///
/// Only the lower triangle of `matrix` is read (entries above the diagonal are
/// ignored, so storing both triangles or only the lower one both work). `rhs` has one
/// column per right-hand side. One-shot: the symbolic factorization is not kept; for
/// repeated solves with one pattern use [`SpdSolver`].
///
/// Errors: [`SolveError::NotPositiveDefinite`] when a pivot is `<= 0` (indefinite, or
/// singular with an exact zero pivot), [`SolveError::Singular`] when a pivot is tiny
/// relative to its diagonal (singular with rounding), [`SolveError::NonFiniteSolution`].
pub fn solve_spd<T: Scalar>(
    matrix: SparseColMatRef<'_, usize, T>,
    rhs: MatRef<'_, T>,
    options: SolveOptions,
) -> Result<Mat<T>, SolveError> {
    let n = matrix.nrows();
    check_len("the column count of the matrix", n, matrix.ncols())?;
    check_len("the row count of the right-hand side", n, rhs.nrows())?;
    check_finite_matrix("the matrix", matrix)?;
    for j in 0..rhs.ncols() {
        for i in 0..n {
            if !rhs[(i, j)].finite() {
                return Err(SolveError::NonFinite {
                    what: "the right-hand side",
                    index: i + j * n,
                });
            }
        }
    }
    let mut x = rhs.to_owned();
    if n == 0 {
        return Ok(x);
    }
    let mut solver = SpdSolver::<T>::new(matrix.symbolic(), options)?;
    solver.factorize(matrix)?;
    solver.solve_in_place(x.as_mut())?;
    Ok(x)
}

/// How [`SpdSolver::solve_preconditioned`] went.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Preconditioned {
    /// Whether the residual reached the tolerance (the solution is in `rhs`).
    pub converged: bool,
    /// Conjugate-gradient iterations done.
    pub iterations: usize,
}

/// Repeated solves `M x = r` with Hermitian positive definite matrices `M` of one fixed
/// sparsity pattern (iterative solvers that assemble their own normal equations every
/// step): the symbolic Cholesky factorization (AMD ordering, supernodes) is done once by
/// [`SpdSolver::new`]; [`SpdSolver::factorize`] refactors the values of each new matrix
/// and [`SpdSolver::solve_in_place`] solves with the last factorization, as often as
/// needed.
///
/// Errors are those of [`solve_spd`]: [`SolveError::NotPositiveDefinite`] for a pivot
/// `<= 0`, [`SolveError::Singular`] for a pivot tiny relative to its diagonal (the test of
/// [`SolveOptions::singularity_tolerance`]), [`SolveError::NonFiniteSolution`].
pub struct SpdSolver<T: Scalar> {
    pattern: SymbolicSparseColMat<usize>,
    cholesky: Cholesky<T>,
    options: SolveOptions,
    /// Whether the last factorization succeeded.
    factored: bool,
}

impl<T: Scalar> fmt::Debug for SpdSolver<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SpdSolver")
            .field("n", &self.pattern.nrows())
            .field("nnz", &self.pattern.row_idx().len())
            .field("options", &self.options)
            .finish_non_exhaustive()
    }
}

impl<T: Scalar> SpdSolver<T> {
    /// Symbolic phase for matrices with the pattern `pattern` (square; only its lower
    /// triangle is read).
    pub fn new(
        pattern: SymbolicSparseColMatRef<'_, usize>,
        options: SolveOptions,
    ) -> Result<Self, SolveError> {
        check_len(
            "the column count of the pattern",
            pattern.nrows(),
            pattern.ncols(),
        )?;
        Ok(Self {
            pattern: pattern.to_owned()?,
            cholesky: Cholesky::new(pattern, options)?,
            options,
            factored: false,
        })
    }

    /// [`SpdSolver::new`] eliminating the unknowns in the order `order` (`order[k]` is
    /// the unknown eliminated k-th; a permutation of `0..n`) instead of AMD's. Unknowns
    /// that come in groups (two per mesh vertex) factor faster, and order far faster,
    /// with the AMD order of the groups' graph expanded group by group
    /// ([`amd_order`](crate::amd_order)).
    pub fn with_order(
        pattern: SymbolicSparseColMatRef<'_, usize>,
        order: &[usize],
        options: SolveOptions,
    ) -> Result<Self, SolveError> {
        let n = pattern.nrows();
        check_len("the column count of the pattern", n, pattern.ncols())?;
        check_len("the length of the order", n, order.len())?;
        let inverse = inverse_permutation(order)?;
        Ok(Self {
            pattern: pattern.to_owned()?,
            cholesky: Cholesky::with_ordering(pattern, Some((order, &inverse)), options)?,
            options,
            factored: false,
        })
    }

    /// [`SpdSolver::with_order`] in the order of `split`, whose two sides are factored
    /// at once, one per core, and joined through their separator's dense Schur
    /// complement (`two_domains` module; the same solutions up to rounding). Factored
    /// as a whole, in the same order, when the split has no two sides or a side's
    /// factorization would not eliminate the separator last.
    pub fn with_split_order(
        pattern: SymbolicSparseColMatRef<'_, usize>,
        split: &SplitOrder,
        options: SolveOptions,
    ) -> Result<Self, SolveError> {
        let n = pattern.nrows();
        check_len("the column count of the pattern", n, pattern.ncols())?;
        check_len("the length of the order", n, split.order.len())?;
        Ok(Self {
            pattern: pattern.to_owned()?,
            cholesky: Cholesky::split(pattern, &split.order, split.sides, options)?,
            options,
            factored: false,
        })
    }

    /// The solver of a symbolic factorization planned on its own ([`PlannedCholesky`],
    /// typically computed on another thread while the matrix was assembled): for
    /// matrices with the planned pattern ([`SpdSolver::pattern`]).
    ///
    /// Errors: those of the symbolic factorization of an empty pattern (none planned).
    pub fn from_planned(
        planned: PlannedCholesky<T>,
        options: SolveOptions,
    ) -> Result<Self, SolveError> {
        let cholesky = match planned.cholesky {
            Some(cholesky) => cholesky,
            None => Cholesky::new(planned.pattern.as_ref(), options)?,
        };
        Ok(Self {
            pattern: planned.pattern,
            cholesky,
            options,
            factored: false,
        })
    }

    /// Whether the last [`SpdSolver::factorize`] succeeded: then
    /// [`SpdSolver::solve_preconditioned`] and the direct solves have a factor to use.
    pub fn is_factored(&self) -> bool {
        self.factored
    }

    /// The pattern of the matrices the solver factors (their lower triangle is read).
    pub fn pattern(&self) -> SymbolicSparseColMatRef<'_, usize> {
        self.pattern.as_ref()
    }

    /// Whether the factorization runs in two sides at once
    /// ([`SpdSolver::with_split_order`]).
    pub fn is_split(&self) -> bool {
        matches!(self.cholesky, Cholesky::Halves(_))
    }

    /// The number of unknowns.
    pub fn len(&self) -> usize {
        self.pattern.nrows()
    }

    /// True when there are no unknowns.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Numeric factorization of `matrix` (the pattern given to [`SpdSolver::new`], lower
    /// triangle read), kept for [`SpdSolver::solve_in_place`].
    pub fn factorize(&mut self, matrix: SparseColMatRef<'_, usize, T>) -> Result<(), SolveError> {
        self.factored = false;
        let n = self.len();
        check_len("the row count of the matrix", n, matrix.nrows())?;
        check_len("the column count of the matrix", n, matrix.ncols())?;
        if let Some(col) = (0..n)
            .find(|&j| matrix.row_idx_of_col_raw(j) != self.pattern.as_ref().row_idx_of_col_raw(j))
        {
            return Err(SolveError::PatternMismatch { col });
        }
        check_finite_matrix("the matrix", matrix)?;
        #[cfg(feature = "cg-compare")]
        let start = std::time::Instant::now();
        let factored = self
            .cholesky
            .factorize(matrix, self.options.tolerance_in::<T>(n));
        #[cfg(feature = "cg-compare")]
        crate::cg_compare::record_factorization(n, start.elapsed().as_secs_f64());
        factored.map_err(|failure| match failure {
            FactorFailure::NonPositivePivot { index } => SolveError::NotPositiveDefinite { index },
            FactorFailure::SmallPivot { index, ratio } => SolveError::Singular {
                index,
                node: None,
                ratio,
            },
        })?;
        self.factored = true;
        Ok(())
    }

    /// Solves `matrix x = rhs` (lower triangle of `matrix` read, the pattern given to
    /// [`SpdSolver::new`]) by conjugate gradients preconditioned with the last successful
    /// factorization, of a nearby matrix: iterative solvers whose matrix changes a little
    /// per step keep one factorization for several steps. Stops once
    /// `|matrix x - rhs| <= tolerance |rhs|` (then `rhs` holds `x`), or gives up (`rhs`
    /// as given: factor `matrix` and solve directly, as [`SpdSolver::solve_reusing`]
    /// does) once `max_iterations` are done or,
    /// earlier, as soon as the mean reduction of the residual per iteration so far
    /// predicts more than `max_iterations`. `x` starts at zero.
    pub fn solve_preconditioned(
        &mut self,
        matrix: SparseColMatRef<'_, usize, T>,
        rhs: &mut [T],
        tolerance: f64,
        max_iterations: usize,
    ) -> Result<Preconditioned, SolveError> {
        self.check_preconditioned(matrix, rhs)?;
        // `beltrami bench cg` measures this loop against faer's on the caller's systems.
        #[cfg(feature = "cg-compare")]
        return crate::cg_compare::solve::<T>(
            &mut self.cholesky,
            matrix,
            rhs,
            tolerance,
            max_iterations,
        );
        #[cfg(not(feature = "cg-compare"))]
        conjugate_gradients(
            &mut self.cholesky,
            matrix,
            rhs,
            None,
            tolerance,
            max_iterations,
        )
    }

    /// [`SpdSolver::solve_preconditioned`] with the iterations started at `start`
    /// instead of zero: the solution of a nearby system (the last step's, in an
    /// iteration whose matrix changes a little per step) leaves a residual of the size
    /// of the change, so that fewer iterations reach `tolerance |rhs|` (the same
    /// criterion). Errors as `solve_preconditioned`, and [`SolveError::Length`] /
    /// [`SolveError::NonFinite`] for a bad `start`.
    pub fn solve_preconditioned_from(
        &mut self,
        matrix: SparseColMatRef<'_, usize, T>,
        rhs: &mut [T],
        start: &[T],
        tolerance: f64,
        max_iterations: usize,
    ) -> Result<Preconditioned, SolveError> {
        check_len("the length of the start", self.len(), start.len())?;
        check_finite("the start", start)?;
        self.check_preconditioned(matrix, rhs)?;
        conjugate_gradients(
            &mut self.cholesky,
            matrix,
            rhs,
            Some(start),
            tolerance,
            max_iterations,
        )
    }

    /// The checks of the preconditioned solves: the sizes of `matrix` and `rhs`, a
    /// finite `rhs` and a factorization to precondition with.
    fn check_preconditioned(
        &self,
        matrix: SparseColMatRef<'_, usize, T>,
        rhs: &[T],
    ) -> Result<(), SolveError> {
        let n = self.len();
        check_len("the length of the right-hand side", n, rhs.len())?;
        check_len("the row count of the matrix", n, matrix.nrows())?;
        check_finite("the right-hand side", rhs)?;
        if self.factored {
            Ok(())
        } else {
            Err(SolveError::NotFactored)
        }
    }

    /// Solves `matrix x = rhs` in place for a matrix near the last one factored: by
    /// [`SpdSolver::solve_preconditioned`] when there is a factorization, and, when
    /// that gives up or there is none, by factoring `matrix` and solving directly.
    /// Returns the conjugate gradients' outcome (not converged: `matrix` was factored).
    pub fn solve_reusing(
        &mut self,
        matrix: SparseColMatRef<'_, usize, T>,
        rhs: &mut [T],
        tolerance: f64,
        max_iterations: usize,
    ) -> Result<Preconditioned, SolveError> {
        self.solve_reusing_from(matrix, rhs, None, tolerance, max_iterations)
    }

    /// [`SpdSolver::solve_reusing`] with the conjugate gradients started at `start`
    /// when given ([`SpdSolver::solve_preconditioned_from`]).
    pub fn solve_reusing_from(
        &mut self,
        matrix: SparseColMatRef<'_, usize, T>,
        rhs: &mut [T],
        start: Option<&[T]>,
        tolerance: f64,
        max_iterations: usize,
    ) -> Result<Preconditioned, SolveError> {
        let outcome = if self.factored {
            match start {
                Some(start) => {
                    self.solve_preconditioned_from(matrix, rhs, start, tolerance, max_iterations)?
                }
                None => self.solve_preconditioned(matrix, rhs, tolerance, max_iterations)?,
            }
        } else {
            Preconditioned {
                converged: false,
                iterations: 0,
            }
        };
        if !outcome.converged {
            self.factorize(matrix)?;
            self.solve_vector_in_place(rhs)?;
        }
        Ok(outcome)
    }

    /// [`SpdSolver::solve_in_place`] for one right-hand side given as a slice: `x` is
    /// overwritten with the solution.
    pub fn solve_vector_in_place(&mut self, x: &mut [T]) -> Result<(), SolveError> {
        self.solve_in_place(column_mut(x))
    }

    /// Overwrites the columns of `rhs` with the solutions of `matrix x = rhs` for the
    /// matrix of the last successful [`SpdSolver::factorize`] (error
    /// [`SolveError::NotFactored`] if there is none).
    pub fn solve_in_place(&mut self, mut rhs: MatMut<'_, T>) -> Result<(), SolveError> {
        check_len(
            "the row count of the right-hand side",
            self.len(),
            rhs.nrows(),
        )?;
        for j in 0..rhs.ncols() {
            for i in 0..rhs.nrows() {
                if !rhs[(i, j)].finite() {
                    return Err(SolveError::NonFinite {
                        what: "the right-hand side",
                        index: i + j * rhs.nrows(),
                    });
                }
            }
        }
        if self.is_empty() {
            return Ok(());
        }
        if !self.factored {
            return Err(SolveError::NotFactored);
        }
        self.cholesky.solve_in_place(rhs.as_mut())?;
        for j in 0..rhs.ncols() {
            for i in 0..rhs.nrows() {
                if !rhs[(i, j)].finite() {
                    return Err(SolveError::NonFiniteSolution {
                        index: i + j * rhs.nrows(),
                    });
                }
            }
        }
        Ok(())
    }
}

/// The conjugate gradients of [`SpdSolver::solve_preconditioned`] (arguments checked
/// there), preconditioned with the factorization `cholesky`, from `start` (zero when
/// `None`).
pub(crate) fn conjugate_gradients<T: Scalar>(
    cholesky: &mut Cholesky<T>,
    matrix: SparseColMatRef<'_, usize, T>,
    rhs: &mut [T],
    start: Option<&[T]>,
    tolerance: f64,
    max_iterations: usize,
) -> Result<Preconditioned, SolveError> {
    let n = rhs.len();
    let zero = T::from_f64(0.0);
    let dot = |a: &[T], b: &[T]| -> T {
        a.iter().zip(b).fold(zero, |acc, (&x, &y)| {
            acc + faer::traits::ComplexField::conj_impl(&x) * y
        })
    };
    let norm = |a: &[T]| dot(a, a).real().sqrt();
    let target = tolerance * norm(rhs);
    let mut residual = rhs.to_vec();
    let mut product = vec![zero; n];
    let mut x = match start {
        Some(start) => {
            symmetric_lower_product(matrix, start, &mut product);
            for (r, p) in residual.iter_mut().zip(&product) {
                *r -= *p;
            }
            start.to_vec()
        }
        None => vec![zero; n],
    };
    let start = norm(&residual);
    if start <= target {
        rhs.copy_from_slice(&x);
        return Ok(Preconditioned {
            converged: true,
            iterations: 0,
        });
    }
    let mut z = residual.clone();
    cholesky.solve_in_place(column_mut(&mut z))?;
    let mut direction = z.clone();
    let mut rz = dot(&residual, &z);
    for iteration in 1..=max_iterations {
        symmetric_lower_product(matrix, &direction, &mut product);
        let alpha = rz / dot(&direction, &product);
        for i in 0..n {
            x[i] += alpha * direction[i];
            residual[i] -= alpha * product[i];
        }
        let r = norm(&residual);
        if r <= target {
            check_finite_solution(&x)?;
            rhs.copy_from_slice(&x);
            return Ok(Preconditioned {
                converged: true,
                iterations: iteration,
            });
        }
        // Mean reduction per iteration so far, and the iterations it predicts.
        let rate = (r / start).powf(1.0 / iteration as f64);
        if rate.is_nan() || rate >= 1.0 || (target / start).ln() / rate.ln() > max_iterations as f64
        {
            return Ok(Preconditioned {
                converged: false,
                iterations: iteration,
            });
        }
        z.copy_from_slice(&residual);
        cholesky.solve_in_place(column_mut(&mut z))?;
        let rz_next = dot(&residual, &z);
        let beta = rz_next / rz;
        rz = rz_next;
        for i in 0..n {
            direction[i] = z[i] + beta * direction[i];
        }
    }
    Ok(Preconditioned {
        converged: false,
        iterations: max_iterations,
    })
}

/// `inverse[order[k]] = k`; [`SolveError::InvalidOrder`] names the first entry of `order`
/// that is out of range or repeated.
pub(crate) fn inverse_permutation(order: &[usize]) -> Result<Vec<usize>, SolveError> {
    let n = order.len();
    let mut inverse = vec![usize::MAX; n];
    for (k, &i) in order.iter().enumerate() {
        if i >= n || inverse[i] != usize::MAX {
            return Err(SolveError::InvalidOrder { index: k });
        }
        inverse[i] = k;
    }
    Ok(inverse)
}

/// `y = M x` for a Hermitian `M` given by its lower triangle (entries above the diagonal
/// are ignored).
pub(crate) fn symmetric_lower_product<T: Scalar>(
    m: SparseColMatRef<'_, usize, T>,
    x: &[T],
    y: &mut [T],
) {
    y.iter_mut().for_each(|v| *v = T::from_f64(0.0));
    for j in 0..m.ncols() {
        for (i, &v) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
            if i > j {
                y[i] += v * x[j];
                y[j] += faer::traits::ComplexField::conj_impl(&v) * x[i];
            } else if i == j {
                y[i] += v * x[j];
            }
        }
    }
}

pub(crate) fn column_mut<T>(v: &mut [T]) -> MatMut<'_, T> {
    let n = v.len();
    MatMut::from_column_major_slice_mut(v, n, 1)
}
