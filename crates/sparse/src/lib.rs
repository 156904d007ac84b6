#![warn(missing_docs)]
//! # beltrami-sparse
//!
//! The sparse direct solvers under every beltrami solver, on faer's sparse kernels:
//! nothing here knows about meshes; matrices are faer's compressed-column matrices of
//! `f64`, [`Complex64`](num_complex::Complex64) or `f32` ([`Scalar`]).
//!
//! One entry point per job:
//!
//! | job | entry point |
//! |---|---|
//! | one Hermitian positive definite solve `M X = R` | [`solve_spd`] |
//! | the same pattern factored again and again (a flow's steps) | [`SpdSolver`] |
//! | the same in `f32`, its solutions refined in `f64` where needed | [`MixedSpdSolver`] |
//! | the symbolic work done on another thread, ahead of the values | [`PlannedCholesky`] |
//! | a fill-reducing elimination order | [`fill_reducing_order`] (AMD or nested dissection, whichever factors cheaper) |
//! | the order that factors fastest on two cores | [`two_core_order`] ([`SplitOrder`]) |
//! | the cost of a factorization in an order, before doing it | [`factor_count`] |
//! | an energy under linear equality constraints `[H C^H; C 0]` | [`solve_saddle_point`], [`SaddlePointSolver`] |
//!
//! Least squares under a mesh's constraints (a DOF map) are built on these in
//! `beltrami-fem` (`LeastSquaresSolver`).
//!
//! # Singularity
//!
//! A system without a unique solution gives [`SolveError::Singular`] or
//! [`SolveError::NotPositiveDefinite`], never NaNs: every pivot is tested against
//! [`SolveOptions::singularity_tolerance`] relative to its diagonal, and every solution
//! is checked for non-finite values.
//!
//! # Orders
//!
//! Below [`NESTED_DISSECTION_FROM`] unknowns the order is faer's approximate minimum
//! degree. From there nested dissection (separators from breadth-first level sets,
//! minimum degree inside parts of at most 256 rows) is taken when its factor costs at
//! most `16 n^(3/2)` multiply-subtracts, else whichever of the two is cheaper by exact
//! count. On two cores the first separator of a dissection splits the factorization into
//! two sides factored at once (module `two_domains`: one level of substructuring), when
//! the separator is small against the whole.

#[cfg(feature = "cg-compare")]
pub mod cg_compare;
pub mod check;
mod cholesky;
mod error;
mod factor_count;
mod mixed;
mod nested_dissection;
mod options;
mod ordering;
mod planned;
mod saddle;
mod scalar;
mod spd;
mod two_domains;
mod vertex_separator;

pub use error::SolveError;
pub use factor_count::{FactorCount, factor_count};
pub use mixed::{MixedSpdSolver, Refined};
pub use options::{Kernel, SolveOptions, default_singularity_tolerance};
pub use ordering::{
    NESTED_DISSECTION_FROM, SplitOrder, amd_order, fill_reducing_order, first_split_order,
    nested_dissection_order, nested_dissection_split, two_core_order,
};
pub use planned::PlannedCholesky;
pub use saddle::{SaddlePointSolution, SaddlePointSolver, solve_saddle_point};
pub use scalar::Scalar;
pub use spd::{Preconditioned, SpdSolver, solve_spd};
