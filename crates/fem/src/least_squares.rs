//! Weighted least squares through a [`DofMap`], on the sparse Cholesky of
//! `beltrami-sparse`.
//!
//! # Least squares through a DOF map
//!
//! [`LeastSquaresSolver`] minimizes over the reduced unknowns `y`
//!
//! ```text
//! E(y) = | W^(1/2) (A x - b) |^2 = sum_i w_i |(A x - b)_i|^2,    x = K y + x0,
//! ```
//!
//! with `A` sparse (`m x N`), `W = diag(w)`, `w_i >= 0`, through the normal equations
//!
//! ```text
//! (B^H W B) y = B^H W (b - A x0),    B = A K,
//! ```
//!
//! solved by a sparse Cholesky factorization (`B^H W B` is Hermitian positive
//! semidefinite; it is definite exactly when the constraints determine the minimizer).
//! The patterns of `B` and of the normal matrix (lower triangle), the maps that scatter
//! the values of `A` into them, and the symbolic factorization are computed once, at
//! construction; [`LeastSquaresSolver::solve`] only refills values (iterative solvers
//! call it every step with new values in the same pattern). No sparse-sparse product
//! is formed: a row of `K` has one entry per term of its node (at most one for the maps
//! of `DofConstraints`, a few in general), so each entry of `A` scatters into a few
//! precomputed entries of `B`, and `B^H W B` is summed row by row of `B` into
//! precomputed positions (`normal` module: formulas and construction of the maps).
//!
//! The normal equations square the condition number of `W^(1/2) A K`; they are the
//! right tool here because finite-element energies are well scaled, and the factor is
//! several times cheaper than a sparse QR.
//!
//! A problem whose constraints do not determine the minimizer gives
//! [`SolveError::Singular`] naming the unknown and the vertex it moves, never NaNs.

mod normal;

pub use normal::normal_pattern_of_cells;

use crate::dof::{DofMap, DofScalar};
use beltrami_sparse::check::{check_finite, check_finite_matrix, check_finite_solution, check_len};
use beltrami_sparse::{
    PlannedCholesky, Preconditioned, SolveError, SolveOptions, SpdSolver, solve_saddle_point,
};
use faer::sparse::{
    SparseColMat, SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef, Triplet,
};
use normal::NormalEquations;
use std::fmt;

/// `error` of factoring a semidefinite energy's matrix in `dofs`' reduced unknowns (the
/// normal equations `B^H W B`, a conformal energy) with the vertex its unknown moves:
/// a pivot `<= 0` of a semidefinite matrix can only be a zero pivot perturbed by
/// rounding, so it is reported as [`SolveError::Singular`] too.
pub fn singular_at_node<T: DofScalar>(error: SolveError, dofs: &DofMap<T>) -> SolveError {
    let node = |index: usize| dofs.dof_node(index).map(|v| v.idx());
    match error {
        SolveError::NotPositiveDefinite { index } => SolveError::Singular {
            index,
            node: node(index),
            ratio: 0.0,
        },
        SolveError::Singular { index, ratio, .. } => SolveError::Singular {
            index,
            node: node(index),
            ratio,
        },
        other => other,
    }
}

/// Weighted sparse least squares through an affine DOF map, with the symbolic work
/// done once per pattern (module docs: formulas).
///
/// ```text
/// minimize  sum_i w_i |(A x - b)_i|^2   over y,   x = K y + x0
/// normal equations:  (K^H A^H W A K) y = K^H A^H W (b - A x0)
/// ```
///
/// `T = f64` with a real-form [`DofMap`] (`A` acts on `[re0, im0, ...]`), or
/// `T = Complex64` with a complex-form map (`A` complex, `B^H W B` Hermitian).
pub struct LeastSquaresSolver<T: DofScalar> {
    dofs: DofMap<T>,
    options: SolveOptions,
    /// Pattern of `A` (`m x N`) the solver was built for.
    a_pattern: SymbolicSparseColMat<usize>,
    /// `B = A K`, `B^H W B` (lower triangle) and the maps filling them.
    normal: NormalEquations<T>,
    /// `None` when every unknown is fixed (`n = 0`): then `x = x0`.
    cholesky: Option<SpdSolver<T>>,
    /// `b - A x0` (`m`).
    residual: Vec<T>,
    /// Right-hand side, then solution, of the normal equations (`n`).
    y: Vec<T>,
    /// The solution `y` of the last solve, where the next
    /// [`solve_into_reusing`](Self::solve_into_reusing) starts its conjugate gradients.
    last: Option<Vec<T>>,
}

impl<T: DofScalar> fmt::Debug for LeastSquaresSolver<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("LeastSquaresSolver")
            .field("rows", &self.a_pattern.nrows())
            .field("full_len", &self.a_pattern.ncols())
            .field("reduced_len", &self.y.len())
            .field("normal_nnz", &self.normal.pattern().row_idx().len())
            .field("options", &self.options)
            .finish_non_exhaustive()
    }
}

impl<T: DofScalar> LeastSquaresSolver<T> {
    /// Symbolic phase for matrices `A` with the pattern `a_pattern`
    /// (`m x dofs.full_len()`): the patterns of `B = A K` and of the lower triangle of
    /// `B^H W B`, the maps scattering `A` into them, and the symbolic Cholesky
    /// factorization (AMD ordering) of the latter.
    ///
    /// Errors: [`SolveError::Length`] if `A` has not `dofs.full_len()` columns,
    /// [`SolveError::Unconstrained`] if a reduced unknown appears in no row of `A`.
    pub fn new(
        a_pattern: SymbolicSparseColMatRef<'_, usize>,
        dofs: &DofMap<T>,
        options: SolveOptions,
    ) -> Result<Self, SolveError> {
        Self::build(a_pattern, dofs, options, || Ok(None))
    }

    /// [`new`](Self::new) with the symbolic factorization `planned()` returns, called
    /// once the scatter maps are built: a [`PlannedCholesky`] of the normal equations'
    /// pattern ([`normal_pattern_of_cells`] gives it from the cells alone), typically
    /// computed on another thread while the caller assembled `A`. A plan for any other
    /// pattern is set aside and the symbolic factorization computed here, as by
    /// [`new`](Self::new).
    ///
    /// Errors as [`new`](Self::new), and those of `planned()`.
    pub fn with_planned(
        a_pattern: SymbolicSparseColMatRef<'_, usize>,
        dofs: &DofMap<T>,
        options: SolveOptions,
        planned: impl FnOnce() -> Result<PlannedCholesky<T>, SolveError>,
    ) -> Result<Self, SolveError> {
        Self::build(a_pattern, dofs, options, || planned().map(Some))
    }

    /// The symbolic phase, with the symbolic factorization `planned()` gives when it
    /// is for the normal equations' pattern.
    fn build(
        a_pattern: SymbolicSparseColMatRef<'_, usize>,
        dofs: &DofMap<T>,
        options: SolveOptions,
        planned: impl FnOnce() -> Result<Option<PlannedCholesky<T>>, SolveError>,
    ) -> Result<Self, SolveError> {
        check_len("the column count of A", dofs.full_len(), a_pattern.ncols())?;
        let m = a_pattern.nrows();
        let n = dofs.reduced_len();
        let a_pattern = a_pattern.to_owned()?;
        let normal = NormalEquations::new(a_pattern.as_ref(), dofs)?;
        let planned = planned()?.filter(|planned| planned.is_for(normal.pattern()));
        let cholesky = match planned {
            Some(planned) if n > 0 => Some(SpdSolver::from_planned(planned, options)?),
            _ if n > 0 => Some(SpdSolver::new(normal.pattern(), options)?),
            _ => None,
        };
        let zero = T::from_f64(0.0);
        Ok(Self {
            dofs: dofs.clone(),
            options,
            a_pattern,
            normal,
            cholesky,
            residual: vec![zero; m],
            y: vec![zero; n],
            last: None,
        })
    }

    /// Takes `dofs` as the solver's map and keeps the symbolic phase (scatter maps,
    /// pattern and symbolic Cholesky factorization of the normal equations) when its
    /// `K` has the pattern of the current map: a map whose fixed values, slide points
    /// and slide directions move between solves (a boundary sliding along a curve,
    /// re-linearized at every step) but whose unknowns stay. Otherwise the symbolic
    /// phase is redone for the new pattern. Returns whether it was kept.
    pub fn update_dofs(&mut self, dofs: &DofMap<T>) -> Result<bool, SolveError> {
        check_len(
            "the length of the new map",
            self.dofs.full_len(),
            dofs.full_len(),
        )?;
        let same_columns = dofs.reduced_len() == self.dofs.reduced_len();
        if same_columns && self.normal.set_k(dofs) {
            self.dofs = dofs.clone();
            return Ok(true);
        }
        *self = Self::new(self.a_pattern.as_ref(), dofs, self.options)?;
        Ok(false)
    }

    /// The DOF map the solver was built with.
    pub fn dofs(&self) -> &DofMap<T> {
        &self.dofs
    }

    /// The pattern of `A` the solver accepts.
    pub fn pattern(&self) -> SymbolicSparseColMatRef<'_, usize> {
        self.a_pattern.as_ref()
    }

    /// Numeric phase: the minimizer `x = K y + x0` of `sum_i w_i |(A x - b)_i|^2`,
    /// returned as a full nodal vector (`dofs.full_len()`). `weights = None` means
    /// `w_i = 1`. `a` must have exactly the pattern given to [`new`](Self::new) (same
    /// column pointers and row indices); only its values change between calls.
    pub fn solve(
        &mut self,
        a: SparseColMatRef<'_, usize, T>,
        weights: Option<&[f64]>,
        b: &[T],
    ) -> Result<Vec<T>, SolveError> {
        let mut x = vec![T::from_f64(0.0); self.dofs.full_len()];
        self.solve_into(a, weights, b, &mut x)?;
        Ok(x)
    }

    /// [`solve`](Self::solve) writing the minimizer into `x` (`dofs.full_len()`);
    /// nothing is allocated.
    pub fn solve_into(
        &mut self,
        a: SparseColMatRef<'_, usize, T>,
        weights: Option<&[f64]>,
        b: &[T],
        x: &mut [T],
    ) -> Result<(), SolveError> {
        self.check_inputs(a, weights, b)?;
        check_len("the length of x", self.dofs.full_len(), x.len())?;
        self.assemble(a, weights, b);
        self.factored_solve()?;
        self.keep_solution();
        self.expand_solution(x)
    }

    /// [`solve_into`](Self::solve_into) for a matrix `A` (or weights) near the last
    /// one factored, as in iterations whose system changes a little per step: the
    /// normal equations are solved by conjugate gradients preconditioned with the kept
    /// factorization (`SpdSolver::solve_preconditioned`) to the relative residual
    /// `tolerance` within `max_iterations`, and factored anew (as `solve_into` does)
    /// only when that fails or nothing is factored yet. The iterations start from the
    /// last solve's solution (`SpdSolver::solve_reusing_from`), whose residual is of
    /// the size of the change of the system. Returns the conjugate-gradient iterations
    /// done and whether it factored.
    pub fn solve_into_reusing(
        &mut self,
        a: SparseColMatRef<'_, usize, T>,
        weights: Option<&[f64]>,
        b: &[T],
        x: &mut [T],
        tolerance: f64,
        max_iterations: usize,
    ) -> Result<Preconditioned, SolveError> {
        self.check_inputs(a, weights, b)?;
        check_len("the length of x", self.dofs.full_len(), x.len())?;
        self.assemble(a, weights, b);
        let outcome = match &mut self.cholesky {
            Some(cholesky) => cholesky
                .solve_reusing_from(
                    self.normal.matrix(),
                    &mut self.y,
                    self.last.as_deref(),
                    tolerance,
                    max_iterations,
                )
                .map_err(|error| singular_at_node(error, &self.dofs))?,
            None => Preconditioned {
                converged: false,
                iterations: 0,
            },
        };
        self.keep_solution();
        self.expand_solution(x)?;
        Ok(outcome)
    }

    /// Keeps the solution `y` just found as the next reusing solve's start.
    fn keep_solution(&mut self) {
        match &mut self.last {
            Some(last) => last.copy_from_slice(&self.y),
            None => self.last = Some(self.y.clone()),
        }
    }

    /// Factors the assembled normal equations and solves them in place of `y` (nothing
    /// when every unknown is fixed).
    fn factored_solve(&mut self) -> Result<(), SolveError> {
        if let Some(cholesky) = &mut self.cholesky {
            cholesky
                .factorize(self.normal.matrix())
                .map_err(|error| singular_at_node(error, &self.dofs))?;
            cholesky.solve_vector_in_place(&mut self.y)?;
        }
        Ok(())
    }

    /// The full nodal vector of the solution `y` in `x` (its length checked by the
    /// caller, so the expansion cannot fail; mapped for completeness).
    fn expand_solution(&self, x: &mut [T]) -> Result<(), SolveError> {
        self.dofs
            .expand_into(&self.y, x)
            .map_err(|_| SolveError::Length {
                what: "the length of x",
                expected: self.dofs.full_len(),
                got: x.len(),
            })
    }

    /// The normal equations of `A`, `W`, `b` in `y`: the matrix `K^H A^H W A K` and,
    /// in `self.y`, the right-hand side `K^H A^H W (b - A x0)` (only the columns with a
    /// nonzero `x0`, the fixed and sliding node unknowns, contribute to `A x0`).
    fn assemble(&mut self, a: SparseColMatRef<'_, usize, T>, weights: Option<&[f64]>, b: &[T]) {
        self.residual.copy_from_slice(b);
        let zero = T::from_f64(0.0);
        for (l, &x0) in self.dofs.x0().iter().enumerate() {
            if x0 != zero {
                let minus_x0 = -x0;
                for (i, &a_il) in a.row_idx_of_col(l).zip(a.val_of_col(l)) {
                    self.residual[i] += a_il * minus_x0;
                }
            }
        }
        self.normal
            .assemble(a, weights, &self.residual, &mut self.y);
    }

    /// [`solve`](Self::solve) under one more linear equality on the full vector,
    /// `<c, x> = d` (`c^H x` in the complex case). In the reduced unknowns it reads
    /// `<K^H c, y> = d - <c, x0>`. When the normal matrix `M = K^H A^H W A K` is
    /// definite, the rank-one border is eliminated with its Cholesky factorization and
    /// one extra solve, so a dense constraint row (a total area) costs no fill: with
    /// `y_u = M^-1 g` and `z = M^-1 K^H c`,
    ///
    /// ```text
    /// y = y_u - z (<K^H c, y_u> - d + <c, x0>) / <K^H c, z>.
    /// ```
    ///
    /// When `M` is singular (the equality is what fixes the solution: a closed surface
    /// held at one vertex, whose scale only the area fixes) the saddle-point system of
    /// `M` and the border is solved instead ([`solve_saddle_point`]).
    ///
    /// Errors as [`solve`](Self::solve); [`SolveError::Unconstrained`] (index
    /// `dofs.reduced_len()`) when `c` does not involve the unknowns (`K^H c = 0`);
    /// [`SolveError::IllConditioned`] when neither `M` nor the border fixes the
    /// solution.
    pub fn solve_with_equality(
        &mut self,
        a: SparseColMatRef<'_, usize, T>,
        weights: Option<&[f64]>,
        b: &[T],
        c: &[T],
        d: T,
    ) -> Result<Vec<T>, SolveError> {
        self.check_inputs(a, weights, b)?;
        check_len("the length of c", self.dofs.full_len(), c.len())?;
        check_finite("c", c)?;
        check_finite("d", std::slice::from_ref(&d))?;
        let n = self.y.len();
        let zero = T::from_f64(0.0);
        let dot = |u: &[T], v: &[T]| {
            u.iter()
                .zip(v)
                .fold(zero, |acc, (a, b)| acc + a.conjugate() * *b)
        };
        let k = self.dofs.k();
        let kc: Vec<T> = (0..n)
            .map(|j| {
                k.row_idx_of_col(j)
                    .zip(k.val_of_col(j))
                    .fold(zero, |acc, (i, &kij)| acc + kij.conjugate() * c[i])
            })
            .collect();
        if kc.iter().all(|&v| v == zero) {
            return Err(SolveError::Unconstrained {
                index: n,
                node: None,
            });
        }
        let reduced_d = d - dot(c, self.dofs.x0());
        self.assemble(a, weights, b);
        let Some(cholesky) = &mut self.cholesky else {
            unreachable!("K^H c has an entry, so there is an unknown")
        };
        match cholesky.factorize(self.normal.matrix()) {
            Ok(()) => {
                let mut z = kc.clone();
                cholesky.solve_vector_in_place(&mut self.y)?;
                cholesky.solve_vector_in_place(&mut z)?;
                let t = (dot(&kc, &self.y) - reduced_d)
                    * faer::traits::ComplexField::recip_impl(&dot(&kc, &z));
                for (y, z) in self.y.iter_mut().zip(&z) {
                    *y -= *z * t;
                }
            }
            Err(_) => {
                let lower = self.normal.matrix();
                let mut triplets = Vec::with_capacity(2 * lower.compute_nnz());
                for j in 0..n {
                    for (i, &v) in lower.row_idx_of_col(j).zip(lower.val_of_col(j)) {
                        triplets.push(Triplet::new(i, j, v));
                        if i != j {
                            triplets.push(Triplet::new(j, i, v.conjugate()));
                        }
                    }
                }
                let h = SparseColMat::try_new_from_triplets(n, n, &triplets).map_err(|_| {
                    SolveError::Length {
                        what: "the normal matrix",
                        expected: n,
                        got: n,
                    }
                })?;
                let border: Vec<Triplet<usize, usize, T>> = kc
                    .iter()
                    .enumerate()
                    .filter(|(_, v)| **v != zero)
                    .map(|(j, v)| Triplet::new(0, j, v.conjugate()))
                    .collect();
                let c_row = SparseColMat::try_new_from_triplets(1, n, &border).map_err(|_| {
                    SolveError::Length {
                        what: "the constraint row",
                        expected: n,
                        got: n,
                    }
                })?;
                let solution = solve_saddle_point(
                    h.as_ref(),
                    &self.y,
                    c_row.as_ref(),
                    &[reduced_d],
                    self.options,
                )?;
                self.y = solution.x;
            }
        }
        check_finite_solution(&self.y)?;
        let mut x = vec![zero; self.dofs.full_len()];
        self.dofs
            .expand_into(&self.y, &mut x)
            .map_err(|_| SolveError::Length {
                what: "the length of x",
                expected: self.dofs.full_len(),
                got: x.len(),
            })?;
        Ok(x)
    }

    fn check_inputs(
        &self,
        a: SparseColMatRef<'_, usize, T>,
        weights: Option<&[f64]>,
        b: &[T],
    ) -> Result<(), SolveError> {
        let pattern = self.a_pattern.as_ref();
        check_len("the row count of A", pattern.nrows(), a.nrows())?;
        check_len("the column count of A", pattern.ncols(), a.ncols())?;
        if let Some(col) =
            (0..pattern.ncols()).find(|&j| a.row_idx_of_col_raw(j) != pattern.row_idx_of_col_raw(j))
        {
            return Err(SolveError::PatternMismatch { col });
        }
        check_finite_matrix("A", a)?;
        check_len("the length of b", pattern.nrows(), b.len())?;
        check_finite("b", b)?;
        if let Some(w) = weights {
            check_len("the number of weights", pattern.nrows(), w.len())?;
            if let Some(row) = w.iter().position(|&w| !(w.is_finite() && w >= 0.0)) {
                return Err(SolveError::InvalidWeight {
                    row,
                    weight: w[row],
                });
            }
        }
        Ok(())
    }
}
