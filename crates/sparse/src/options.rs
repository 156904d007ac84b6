//! The options every solver takes.

use crate::Scalar;
use faer::Par;

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
    /// Which of faer's numeric Cholesky kernels factors the SPD systems.
    pub kernel: Kernel,
}

/// The numeric kernel of a sparse Cholesky factorization. faer's simplicial kernel
/// eliminates one column at a time; its supernodal kernel eliminates runs of columns
/// with the same structure below the diagonal (supernodes) as dense blocks.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Kernel {
    /// faer's choice: supernodal when the factorization's flop count is at least 40
    /// per stored entry of the factor, else simplicial.
    #[default]
    Auto,
    /// Supernodal at any size: for systems with several unknowns per mesh vertex, whose
    /// every vertex makes a dense block and a supernode at least as wide. The flow's
    /// system on `g0_spot` (2 unknowns per vertex, 5,860 rows, below faer's ratio):
    /// 10.8 ms -> 3.1 ms a factorization; a scalar system of 1,761 rows (one unknown per
    /// vertex) 0.68 -> 0.74 ms.
    Supernodal,
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

    pub(crate) fn tolerance(&self, n: usize) -> f64 {
        self.singularity_tolerance
            .unwrap_or_else(|| default_singularity_tolerance(n))
    }

    /// [`SolveOptions::tolerance`] for a factorization in the scalar `T`: by default
    /// [`Scalar::TOLERANCE_PER_UNKNOWN`] times `n` (for `f64`,
    /// [`default_singularity_tolerance`]).
    pub(crate) fn tolerance_in<T: Scalar>(&self, n: usize) -> f64 {
        self.singularity_tolerance
            .unwrap_or_else(|| n.max(1) as f64 * T::TOLERANCE_PER_UNKNOWN)
    }
}
