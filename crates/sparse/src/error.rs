//! The errors of the solvers.

use faer::sparse::FaerError;
use thiserror::Error;

/// Why a solve failed. Indices name the row, column or unknown concerned; `node` names
/// the mesh vertex (by index) that an unknown moves, when the caller knows it (a least-squares
/// solve through a DOF map in `beltrami-fem`).
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
        node: Option<usize>,
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
        node: Option<usize>,
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
    /// [`SpdSolver::solve_in_place`](crate::SpdSolver::solve_in_place) was called without a successful factorization.
    #[error("no factorization to solve with: factorize a matrix first")]
    NotFactored,
    /// A mixed-precision solve ([`MixedSpdSolver`](crate::MixedSpdSolver)) whose
    /// refinement did not reach its tolerance: the matrix is too ill-conditioned for a
    /// factorization in `f32`.
    #[error(
        "the f32 factorization's solution still changed by {correction:e} (relative) after {steps} refinement steps: the matrix is too ill-conditioned for mixed precision"
    )]
    Refinement {
        /// Refinement steps done.
        steps: usize,
        /// The relative size of the last correction.
        correction: f64,
    },
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

fn node_suffix(node: &Option<usize>) -> String {
    node.map_or_else(String::new, |v| format!(" (vertex {v})"))
}
