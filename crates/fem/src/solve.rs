//! Sparse solves under constraints: weighted least squares through a [`DofMap`],
//! Hermitian positive definite systems, and saddle-point systems.
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
//! # Singularity
//!
//! A problem without a unique solution gives [`SolveError::Singular`] (or
//! [`SolveError::NotPositiveDefinite`] for a matrix given to [`solve_spd`]), never NaNs:
//! the pivots are tested against [`SolveOptions::singularity_tolerance`] and every
//! solution is checked for non-finite values.

mod cholesky;
mod factor_count;
mod nested_dissection;
mod normal;
mod saddle;
mod two_domains;
mod vertex_graph;
mod vertex_separator;

pub use normal::normal_pattern_of_cells;
pub use saddle::{SaddlePointSolution, SaddlePointSolver, solve_saddle_point};
pub use vertex_graph::{pattern_of_unknowns, vertex_graph_pattern};

use crate::dof::{DofMap, Scalar};
use beltrami_mesh::VertexId;
use cholesky::{Cholesky, FactorFailure};
pub use factor_count::{FactorCount, factor_count};
use faer::sparse::{
    FaerError, SparseColMat, SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef,
    Triplet,
};
use faer::{Mat, MatMut, MatRef, Par};
use normal::NormalEquations;
use std::fmt;
use thiserror::Error;

/// Why a solve failed. Indices name the row, column or unknown concerned; `node` names
/// the mesh vertex moved by a reduced unknown when a [`DofMap`] is involved.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SolveError {
    /// A vector or matrix dimension that does not match.
    #[error("{what} is {got}, expected {expected}")]
    Length {
        /// Which dimension.
        what: &'static str,
        /// The dimension required.
        expected: usize,
        /// The dimension given.
        got: usize,
    },
    /// `A` does not have the sparsity pattern the solver was built for.
    #[error("the matrix pattern differs from the solver's pattern in column {col}")]
    PatternMismatch {
        /// First column that differs.
        col: usize,
    },
    /// A NaN or infinite matrix entry.
    #[error("{what} has a non-finite entry at row {row}, column {col}")]
    NonFiniteEntry {
        /// Which matrix.
        what: &'static str,
        /// Row of the entry.
        row: usize,
        /// Column of the entry.
        col: usize,
    },
    /// A NaN or infinite vector entry.
    #[error("{what} is not finite at index {index}")]
    NonFinite {
        /// Which vector.
        what: &'static str,
        /// Index of the entry.
        index: usize,
    },
    /// A weight that is negative or not finite.
    #[error("the weight of row {row} is {weight}; weights must be finite and >= 0")]
    InvalidWeight {
        /// The row.
        row: usize,
        /// Its weight.
        weight: f64,
    },
    /// A reduced unknown that no row of `A` involves (a vertex in no element, or a
    /// column of `A` left empty): the energy does not depend on it.
    #[error("reduced unknown {index}{} appears in no row of the matrix: nothing determines it", node_suffix(.node))]
    Unconstrained {
        /// The reduced unknown.
        index: usize,
        /// The (smallest) vertex it moves.
        node: Option<VertexId>,
    },
    /// The system has no unique solution to working precision: a pivot was not positive,
    /// or `pivot / diagonal` fell below the singularity tolerance. In a least-squares
    /// problem this means the constraints do not pin the solution down (e.g. a
    /// Laplacian without a Dirichlet node, an LSCM energy with fewer than two pins).
    #[error(
        "the system is singular at unknown {index}{} (pivot / diagonal = {ratio:e}): add Dirichlet conditions or pins",
        node_suffix(.node)
    )]
    Singular {
        /// The unknown (row of the factored matrix, or reduced unknown) where
        /// elimination broke down.
        index: usize,
        /// The (smallest) vertex that unknown moves, when a DOF map is involved.
        node: Option<VertexId>,
        /// `pivot / diagonal` at that unknown; 0 when the pivot was not positive.
        ratio: f64,
    },
    /// A matrix given as Hermitian positive definite met a pivot `<= 0`: it is
    /// indefinite or singular.
    #[error("the matrix is not positive definite (pivot <= 0 at row {index})")]
    NotPositiveDefinite {
        /// Row of the matrix where elimination broke down.
        index: usize,
    },
    /// The condition number estimate of a saddle-point system exceeds one over the
    /// singularity tolerance: redundant constraints, or an energy not definite on the
    /// constraint set.
    #[error(
        "the saddle-point system is singular to working precision (condition estimate {estimate:e} > {limit:e})"
    )]
    IllConditioned {
        /// The estimate of `cond_inf` of the equilibrated system.
        estimate: f64,
        /// The largest accepted.
        limit: f64,
    },
    /// An elimination order that is not a permutation: entry `index` is out of range or
    /// repeated.
    #[error("the elimination order is not a permutation (entry {index})")]
    InvalidOrder {
        /// The offending entry.
        index: usize,
    },
    /// [`SpdSolver::solve_in_place`] was called without a successful factorization.
    #[error("no factorization to solve with: factorize a matrix first")]
    NotFactored,
    /// The solution has a NaN or infinite entry.
    #[error("the solution is not finite at index {index}: the system is singular or overflows")]
    NonFiniteSolution {
        /// Index of the entry.
        index: usize,
    },
    /// faer failed (allocation, index overflow).
    #[error("sparse linear algebra failed: {0}")]
    Faer(#[from] FaerError),
}

fn node_suffix(node: &Option<VertexId>) -> String {
    node.map_or_else(String::new, |v| format!(" (vertex {v})"))
}

/// The default [`SolveOptions::singularity_tolerance`] for `n` unknowns:
/// `8 n eps` (`eps = 2.2e-16`). Rounding leaves a singular matrix with a relative pivot
/// of about `0.13 n eps` (measured on grid Laplacians up to `n = 1e6`), 60 times below.
pub fn default_singularity_tolerance(n: usize) -> f64 {
    8.0 * n.max(1) as f64 * f64::EPSILON
}

/// Options shared by the solvers.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SolveOptions {
    /// Threads for the Cholesky factorizations of the least-squares and SPD solves; 0
    /// and 1 mean sequential; the assembly of the normal equations and the saddle-point
    /// LU are always sequential. On the 2-core machines measured in
    /// `docs/benchmarks.md` a second thread did not pay off, so the default is
    /// sequential.
    pub threads: usize,
    /// Smallest accepted `min_k pivot_k / diagonal_k` of a Cholesky factorization, and
    /// smallest accepted reciprocal condition estimate of a saddle-point system; below
    /// it the system is singular. `None`: [`default_singularity_tolerance`] of the
    /// system's size. Lower it to accept systems that are ill-conditioned but not
    /// singular (long thin domains, strongly graded weights).
    pub singularity_tolerance: Option<f64>,
}

impl SolveOptions {
    /// faer's parallelism for [`SolveOptions::threads`].
    pub fn par(&self) -> Par {
        if self.threads <= 1 {
            Par::Seq
        } else {
            Par::rayon(self.threads)
        }
    }

    fn tolerance(&self, n: usize) -> f64 {
        self.singularity_tolerance
            .unwrap_or_else(|| default_singularity_tolerance(n))
    }
}

fn check_len(what: &'static str, expected: usize, got: usize) -> Result<(), SolveError> {
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

fn check_finite_matrix<T: Scalar>(
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

fn check_finite<T: Scalar>(what: &'static str, v: &[T]) -> Result<(), SolveError> {
    match v.iter().position(|x| !x.finite()) {
        Some(index) => Err(SolveError::NonFinite { what, index }),
        None => Ok(()),
    }
}

fn check_finite_solution<T: Scalar>(v: &[T]) -> Result<(), SolveError> {
    match v.iter().position(|x| !x.finite()) {
        Some(index) => Err(SolveError::NonFiniteSolution { index }),
        None => Ok(()),
    }
}

fn column_mut<T>(v: &mut [T]) -> MatMut<'_, T> {
    let n = v.len();
    MatMut::from_column_major_slice_mut(v, n, 1)
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
pub struct LeastSquaresSolver<T: Scalar> {
    dofs: DofMap<T>,
    options: SolveOptions,
    /// Pattern of `A` (`m x N`) the solver was built for.
    a_pattern: SymbolicSparseColMat<usize>,
    /// `B = A K`, `B^H W B` (lower triangle) and the maps filling them.
    normal: NormalEquations<T>,
    /// `None` when every unknown is fixed (`n = 0`): then `x = x0`.
    cholesky: Option<Cholesky<T>>,
    /// `b - A x0` (`m`).
    residual: Vec<T>,
    /// Right-hand side, then solution, of the normal equations (`n`).
    y: Vec<T>,
}

impl<T: Scalar> fmt::Debug for LeastSquaresSolver<T> {
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

impl<T: Scalar> LeastSquaresSolver<T> {
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
        let planned = planned()?.and_then(|planned| planned.for_pattern(normal.pattern()));
        let cholesky = match planned {
            Some(cholesky) => Some(cholesky),
            None if n > 0 => Some(Cholesky::new(normal.pattern(), options.par())?),
            None => None,
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
        if let Some(cholesky) = &mut self.cholesky {
            let tolerance = self.options.tolerance(self.y.len());
            cholesky
                .factorize(self.normal.matrix(), tolerance)
                .map_err(|failure| match failure {
                    // B^H W B is semidefinite by construction: a non-positive pivot can
                    // only be a zero one perturbed by rounding.
                    FactorFailure::NonPositivePivot { index } => SolveError::Singular {
                        index,
                        node: self.dofs.dof_node(index),
                        ratio: 0.0,
                    },
                    FactorFailure::SmallPivot { index, ratio } => SolveError::Singular {
                        index,
                        node: self.dofs.dof_node(index),
                        ratio,
                    },
                })?;
            cholesky.solve_in_place(column_mut(&mut self.y))?;
            check_finite_solution(&self.y)?;
        }
        // Lengths were checked above, so expansion cannot fail; map for completeness.
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
        let tolerance = self.options.tolerance(n);
        match cholesky.factorize(self.normal.matrix(), tolerance) {
            Ok(()) => {
                let mut z = kc.clone();
                cholesky.solve_in_place(column_mut(&mut self.y))?;
                cholesky.solve_in_place(column_mut(&mut z))?;
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

/// Solves `M X = R` for a Hermitian positive definite sparse `M` (e.g. a Laplacian with
/// its Dirichlet rows and columns eliminated), by sparse Cholesky `M = P^T L L^H P`.
///
/// Only the lower triangle of `matrix` is read (entries above the diagonal are
/// ignored, so storing both triangles or only the lower one both work). `rhs` has one
/// column per right-hand side. One-shot: the symbolic factorization is not kept; for
/// repeated solves with one pattern use [`LeastSquaresSolver`].
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
            cholesky: Cholesky::new(pattern, options.par())?,
            options,
            factored: false,
        })
    }

    /// [`SpdSolver::new`] eliminating the unknowns in the order `order` (`order[k]` is
    /// the unknown eliminated k-th; a permutation of `0..n`) instead of AMD's. Unknowns
    /// that come in groups (two per mesh vertex) factor faster, and order far faster,
    /// with the AMD order of the groups' graph expanded group by group
    /// ([`amd_order`]).
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
            cholesky: Cholesky::with_ordering(pattern, Some((order, &inverse)), options.par())?,
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
            cholesky: Cholesky::split(pattern, &split.order, split.sides, options.par())?,
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
            None => Cholesky::new(planned.pattern.as_ref(), options.par())?,
        };
        Ok(Self {
            pattern: planned.pattern,
            cholesky,
            options,
            factored: false,
        })
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
        self.cholesky
            .factorize(matrix, self.options.tolerance(n))
            .map_err(|failure| match failure {
                FactorFailure::NonPositivePivot { index } => {
                    SolveError::NotPositiveDefinite { index }
                }
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
    /// unspecified: factor `matrix` and solve directly) once `max_iterations` are done or,
    /// earlier, as soon as the mean reduction of the residual per iteration so far
    /// predicts more than `max_iterations`. `x` starts at zero.
    pub fn solve_preconditioned(
        &mut self,
        matrix: SparseColMatRef<'_, usize, T>,
        rhs: &mut [T],
        tolerance: f64,
        max_iterations: usize,
    ) -> Result<Preconditioned, SolveError> {
        let n = self.len();
        check_len("the length of the right-hand side", n, rhs.len())?;
        check_len("the row count of the matrix", n, matrix.nrows())?;
        check_finite("the right-hand side", rhs)?;
        if !self.factored {
            return Err(SolveError::NotFactored);
        }
        let zero = T::from_f64(0.0);
        let dot = |a: &[T], b: &[T]| -> T {
            a.iter().zip(b).fold(zero, |acc, (&x, &y)| {
                acc + faer::traits::ComplexField::conj_impl(&x) * y
            })
        };
        let norm = |a: &[T]| faer::traits::ComplexField::real_part_impl(&dot(a, a)).sqrt();
        let target = tolerance * norm(rhs);
        let mut residual = rhs.to_vec();
        let mut x = vec![zero; n];
        let start = norm(&residual);
        if start <= target {
            rhs.copy_from_slice(&x);
            return Ok(Preconditioned {
                converged: true,
                iterations: 0,
            });
        }
        let mut z = residual.clone();
        self.cholesky.solve_in_place(column_mut(&mut z))?;
        let mut direction = z.clone();
        let mut rz = dot(&residual, &z);
        let mut product = vec![zero; n];
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
            if rate.is_nan()
                || rate >= 1.0
                || (target / start).ln() / rate.ln() > max_iterations as f64
            {
                return Ok(Preconditioned {
                    converged: false,
                    iterations: iteration,
                });
            }
            z.copy_from_slice(&residual);
            self.cholesky.solve_in_place(column_mut(&mut z))?;
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

/// `inverse[order[k]] = k`; [`SolveError::InvalidOrder`] names the first entry of `order`
/// that is out of range or repeated.
fn inverse_permutation(order: &[usize]) -> Result<Vec<usize>, SolveError> {
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

/// Unknown count from which [`fill_reducing_order`] considers nested dissection.
pub const NESTED_DISSECTION_FROM: usize = 100_000;

/// Multiply-subtract count over `n^(3/2)` up to which [`fill_reducing_order`] takes a
/// nested-dissection order without computing AMD's to compare (AMD took longer than
/// the dissection on two cores: 1.3 s against 1.0 s on the 1M-triangle disk). Exact
/// counts ([`factor_count`]) of the vertex graphs of 140K-850K-vertex meshes, nested
/// dissection against AMD: 12.8 / 34.0 (the 1M-triangle disk), 13.8 / 16.0 and
/// 14.9 / 23.7 (`disk_hand` subdivided once and twice), 20.4 / 22.2 and 21.8 / 31.0
/// (`g0_bunny_closed` subdivided once and twice), 29.7 / 12.3 (`g0_koala` subdivided
/// once): at most 16, the dissection was ahead on every mesh measured; beyond, both
/// are computed and the cheaper taken.
const NESTED_DISSECTION_SURE: f64 = 16.0;

/// The elimination order the solvers use for the symmetric pattern
/// `pattern + pattern^T`: `order[k]` is the row to eliminate k-th.
///
/// AMD ([`amd_order`]) below [`NESTED_DISSECTION_FROM`] rows. From there the
/// nested-dissection order ([`nested_dissection_order`], on two cores), kept when its
/// factorization costs at most `16 n^(3/2)` multiply-subtracts (counted exactly, as a
/// planar mesh's factor grows under a good order); else AMD's is computed too, and the
/// order with the smaller count is taken. On large meshes with regular structure
/// (generated disks and grids, subdivided scans) the dissection halves the operations
/// of the numeric factorization; on scans at their original resolution AMD may stay
/// ahead.
pub fn fill_reducing_order(
    pattern: SymbolicSparseColMatRef<'_, usize>,
) -> Result<Vec<usize>, SolveError> {
    check_len(
        "the column count of the pattern",
        pattern.nrows(),
        pattern.ncols(),
    )?;
    if pattern.nrows() < NESTED_DISSECTION_FROM {
        return amd_order(pattern);
    }
    Ok(match chosen_order(pattern)?.0 {
        Choice::Nested(dissected) => dissected.order,
        Choice::Amd(order) => order,
    })
}

/// Which order [`fill_reducing_order`] took for a pattern of at least
/// [`NESTED_DISSECTION_FROM`] rows.
enum Choice {
    Nested(nested_dissection::Dissected),
    Amd(Vec<usize>),
}

/// [`fill_reducing_order`]'s choice from [`NESTED_DISSECTION_FROM`] rows, with the
/// exact count of the factor in the order taken.
fn chosen_order(
    pattern: SymbolicSparseColMatRef<'_, usize>,
) -> Result<(Choice, FactorCount), SolveError> {
    choose(pattern, dissected(pattern)?)
}

/// The multiply-subtract count up to which the nested-dissection order of `n` rows is
/// taken without computing AMD's: [`NESTED_DISSECTION_SURE`]` n^(3/2)`.
fn nested_dissection_sure(n: usize) -> f64 {
    NESTED_DISSECTION_SURE * (n as f64).powf(1.5)
}

/// [`chosen_order`] with the nested-dissection order `dissected` of `pattern` computed.
fn choose(
    pattern: SymbolicSparseColMatRef<'_, usize>,
    dissected: nested_dissection::Dissected,
) -> Result<(Choice, FactorCount), SolveError> {
    let nested = factor_count(pattern, &dissected.order)?;
    if nested.multiply_subtracts <= nested_dissection_sure(pattern.nrows()) {
        return Ok((Choice::Nested(dissected), nested));
    }
    let amd = amd_order(pattern)?;
    let minimum = factor_count(pattern, &amd)?;
    Ok(if minimum.multiply_subtracts < nested.multiply_subtracts {
        (Choice::Amd(amd), minimum)
    } else {
        (Choice::Nested(dissected), nested)
    })
}

/// The symbolic Cholesky factorization of a pattern, computed on its own, so that a
/// caller can compute it on another thread while it assembles the matrices
/// ([`LeastSquaresSolver::with_planned`]): on a large mesh the order and the symbolic
/// analysis take about as long as assembling.
///
/// The elimination order is [`fill_reducing_order`]'s; a nested-dissection order is
/// factored in its first split's two sides at once (`two_domains` module). The
/// factor's storage is allocated and written here: the kernel clears every page a
/// process touches for the first time, and the factor is the largest block of a solve
/// (0.6 GB on the 1M-triangle disk).
pub struct PlannedCholesky<T: Scalar> {
    /// The pattern planned for.
    pattern: SymbolicSparseColMat<usize>,
    /// `None` when the pattern has no rows.
    cholesky: Option<Cholesky<T>>,
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
            Some(Cholesky::new(pattern.as_ref(), options.par())?)
        } else {
            None
        };
        Ok(Self { pattern, cholesky })
    }

    /// [`PlannedCholesky::new`] with the nested-dissection order of the pattern given
    /// (`split`, computed elsewhere: on the vertex graph while the DOF map was made,
    /// carried over by [`SplitOrder::of_unknowns`]), judged as `new` judges its own: from
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
                options.par(),
            )?)
        } else if n > 0 {
            Some(Cholesky::new(pattern.as_ref(), options.par())?)
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

    /// The factorization when it was planned for exactly `pattern`.
    fn for_pattern(self, pattern: SymbolicSparseColMatRef<'_, usize>) -> Option<Cholesky<T>> {
        let same = self.pattern.nrows() == pattern.nrows()
            && self.pattern.col_ptr() == pattern.col_ptr()
            && self.pattern.row_idx() == pattern.row_idx();
        if same { self.cholesky } else { None }
    }
}

/// The nested-dissection order of the symmetric pattern `pattern + pattern^T`
/// (`nested_dissection` module: separators from breadth-first searches, minimum degree
/// inside parts of at most 256 rows): `order[k]` is the row to eliminate k-th.
pub fn nested_dissection_order(
    pattern: SymbolicSparseColMatRef<'_, usize>,
) -> Result<Vec<usize>, SolveError> {
    dissected(pattern).map(|d| d.order)
}

/// [`nested_dissection_order`] with its first split: two sides no entry joins and their
/// separator ([`SplitOrder`]).
pub fn nested_dissection_split(
    pattern: SymbolicSparseColMatRef<'_, usize>,
) -> Result<SplitOrder, SolveError> {
    dissected(pattern).map(SplitOrder::from)
}

/// [`nested_dissection_order`] with its first split.
fn dissected(
    pattern: SymbolicSparseColMatRef<'_, usize>,
) -> Result<nested_dissection::Dissected, SolveError> {
    dissected_to(pattern, nested_dissection::Depth::Full)
}

/// The dissection of `pattern + pattern^T`, as deep as `depth`.
fn dissected_to(
    pattern: SymbolicSparseColMatRef<'_, usize>,
    depth: nested_dissection::Depth,
) -> Result<nested_dissection::Dissected, SolveError> {
    let n = pattern.nrows();
    check_len("the column count of the pattern", n, pattern.ncols())?;
    Ok(nested_dissection::nested_dissection(
        n,
        pattern.col_ptr(),
        pattern.row_idx(),
        depth,
    ))
}

/// An elimination order made of two sides and the separator between them: `order[k]`
/// is the row eliminated `k`-th; with `sides = Some([a, b])`, `order[..a]` are one
/// side's rows, `order[a..a + b]` the other's, and `order[a + b..]` is the separator.
/// [`SpdSolver::with_split_order`] factors the two sides at once, one per core, when no
/// entry of the matrix joins them (else the whole, in `order`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SplitOrder {
    /// `order[k]` is the row eliminated `k`-th.
    pub order: Vec<usize>,
    /// The lengths of the two sides at the front of `order`; `None` when nothing splits
    /// the rows (then only `order` counts).
    pub sides: Option<[usize; 2]>,
}

impl SplitOrder {
    /// This order of `dofs`' nodes (an order of the vertex graph: cheaper to order than
    /// the unknowns' graph, and ready before the DOF map is) carried over to its reduced
    /// unknowns: the unknowns that move one node alone take that node's place, the
    /// unknowns shared by several nodes go last, in increasing order (with the separator
    /// when there are sides); a fixed node has none. The sides' lengths are counted
    /// again in unknowns.
    ///
    /// Errors: [`SolveError::Length`] when the order is not as long as `dofs` has nodes
    /// or its sides are longer, [`SolveError::InvalidOrder`] for a node out of range.
    pub fn of_unknowns<T: Scalar>(&self, dofs: &DofMap<T>) -> Result<SplitOrder, SolveError> {
        let nodes = dofs.n_nodes();
        check_len("the length of the order", nodes, self.order.len())?;
        let n = dofs.reduced_len();
        let shared: Vec<bool> = (0..n)
            .map(|j| dofs.unknown_nodes(j).is_some_and(|nodes| nodes.count() > 1))
            .collect();
        let [a, b] = self.sides.unwrap_or([nodes, 0]);
        check_len("the sides of the order", nodes, nodes.max(a + b))?;
        let mut order = Vec::with_capacity(n);
        let mut ends = [0; 2];
        for (part, range) in [0..a, a..a + b, a + b..nodes].into_iter().enumerate() {
            for (k, &v) in self.order[range.clone()].iter().enumerate() {
                let terms = dofs.node_terms(VertexId::from_usize(v)).map_err(|_| {
                    SolveError::InvalidOrder {
                        index: range.start + k,
                    }
                })?;
                order.extend(terms.map(|(_, t)| t.dof).filter(|&j| !shared[j]));
            }
            if let Some(end) = ends.get_mut(part) {
                *end = order.len();
            }
        }
        order.extend((0..n).filter(|&j| shared[j]));
        Ok(SplitOrder {
            order,
            sides: self.sides.map(|_| [ends[0], ends[1] - ends[0]]),
        })
    }
}

impl From<nested_dissection::Dissected> for SplitOrder {
    fn from(dissected: nested_dissection::Dissected) -> Self {
        Self {
            order: dissected.order,
            sides: dissected.halves,
        }
    }
}

/// Largest `|S|^3` of the first separator `S`, relative to the multiply-subtract count
/// of the whole factorization (AMD's estimate below [`NESTED_DISSECTION_FROM`] rows,
/// else the exact count of [`fill_reducing_order`]'s order), at which
/// [`two_core_order`] splits. The sides' factors shrink
/// the sparse work by about half, but they run about 1.4x slower at once than alone on
/// the 2-core machine (shared memory), and the separator's dense work (its elimination
/// in both sides, their Schur complements, its own factorization) grows like `|S|^3`.
/// Measured on the flow's vertex graphs of 35K-53K vertices, numeric factorization
/// whole in AMD's order against two sides at once: `|S|^3 / count` 0.05-0.19 (the
/// remeshes of `g2_eight`, `g1_kitten`, `disk_hand`, `mc4_face_a`, and
/// `g0_bunny_closed`) gained 10-25%; 0.25 (a generated torus, whose separators are
/// two loops) lost 30-40%, 0.59 (the scan `g0_koala`, where AMD does well, split by the
/// level sets' 352-vertex separator) lost 12%; its multilevel separator (182 vertices,
/// 0.08) gains 40% (docs/register.md).
const SEPARATOR_CUBE_SHARE: f64 = 0.22;

/// The order [`SpdSolver::with_split_order`] factors fastest for `pattern` on two cores:
/// two sides factored at once where the first separator `S` is small against the
/// whole factorization (`|S|^3` at most 0.22 of its multiply-subtract count), else
/// [`fill_reducing_order`]'s order whole. Below [`NESTED_DISSECTION_FROM`] rows the
/// split is [`first_split_order`]'s (multilevel separators); from there, where
/// [`fill_reducing_order`] takes nested dissection, that order's own first split.
pub fn two_core_order(
    pattern: SymbolicSparseColMatRef<'_, usize>,
) -> Result<SplitOrder, SolveError> {
    let n = pattern.nrows();
    check_len("the column count of the pattern", n, pattern.ncols())?;
    let (choice, count) = if n >= NESTED_DISSECTION_FROM {
        let (choice, count) = chosen_order(pattern)?;
        (choice, count.multiply_subtracts)
    } else {
        let amd = amd_order_with_count(pattern)?;
        (Choice::Amd(amd.order), amd.n_mult_subs_ldl)
    };
    let small = |[a, b]: [usize; 2]| {
        let separator = (n - a - b) as f64;
        separator.powi(3) <= SEPARATOR_CUBE_SHARE * count
    };
    Ok(match choice {
        Choice::Nested(dissected) => match dissected.halves {
            Some(sides) if small(sides) => dissected.into(),
            _ => SplitOrder {
                order: dissected.order,
                sides: None,
            },
        },
        Choice::Amd(order) => {
            let first = dissected_to(pattern, nested_dissection::Depth::Multilevel)?;
            match first.halves {
                Some(sides) if small(sides) => first.into(),
                _ => SplitOrder { order, sides: None },
            }
        }
    })
}

/// The nested dissection of `pattern + pattern^T` by multilevel separators (the
/// `vertex_separator` module's; the first one leaves each side at most 52% of the rows,
/// the others 60%), whose first split [`SpdSolver::with_split_order`] factors as two
/// sides on two cores. Multilevel separators cost about 2.5 times as much as the level
/// sets of [`nested_dissection_order`] (0.2-0.3 s on 50K-vertex meshes) but the order is
/// computed once for a factorization repeated at every step of a flow, and they are
/// often much smaller: on the scan `g0_koala` the first has 182 vertices against the
/// level sets' 352, which made the two-core factorization worth it there (`|S|^3` 0.08
/// of the whole's count instead of 0.59).
///
/// Inside the sides, further multilevel separators factor the flow's 50K-vertex graphs
/// with 16-45% fewer multiply-subtracts than AMD did (docs/benchmarks.md, 2026-11-28);
/// on a 150 x 150 grid with diagonals, fewer than AMD on the whole grid (test
/// `the_first_split_separates_two_balanced_sides_dissected_further`).
pub fn first_split_order(
    pattern: SymbolicSparseColMatRef<'_, usize>,
) -> Result<SplitOrder, SolveError> {
    dissected_to(pattern, nested_dissection::Depth::Multilevel).map(SplitOrder::from)
}

/// The approximate minimum degree order of the symmetric pattern `pattern + pattern^T`
/// (faer's AMD): `order[k]` is the row to eliminate k-th.
pub fn amd_order(pattern: SymbolicSparseColMatRef<'_, usize>) -> Result<Vec<usize>, SolveError> {
    amd_order_with_count(pattern).map(|count| count.order)
}

/// An AMD order and AMD's own estimate of the factor's cost in that order.
struct AmdOrder {
    order: Vec<usize>,
    /// Multiply-subtract operations of the `L D L^T` factorization.
    n_mult_subs_ldl: f64,
}

/// [`amd_order`] with AMD's estimate of the factor's cost in that order.
fn amd_order_with_count(
    pattern: SymbolicSparseColMatRef<'_, usize>,
) -> Result<AmdOrder, SolveError> {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::sparse::linalg::amd;
    let n = pattern.nrows();
    check_len("the column count of the pattern", n, pattern.ncols())?;
    let (mut forward, mut inverse) = (vec![0usize; n], vec![0usize; n]);
    let nnz = pattern.row_idx().len();
    let mut buffer = MemBuffer::try_new(amd::order_maybe_unsorted_scratch::<usize>(n, nnz))
        .map_err(|_| FaerError::OutOfMemory)?;
    let count = amd::order_maybe_unsorted(
        &mut forward,
        &mut inverse,
        pattern,
        Default::default(),
        MemStack::new(&mut buffer),
    )?;
    Ok(AmdOrder {
        order: forward,
        n_mult_subs_ldl: count.n_mult_subs_ldl,
    })
}

/// `y = M x` for a Hermitian `M` given by its lower triangle (entries above the diagonal
/// are ignored).
fn symmetric_lower_product<T: Scalar>(m: SparseColMatRef<'_, usize, T>, x: &[T], y: &mut [T]) {
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
