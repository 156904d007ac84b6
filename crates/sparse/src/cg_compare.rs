//! The conjugate gradients of [`SpdSolver::solve_preconditioned`](crate::SpdSolver::solve_preconditioned)
//! against faer's `matrix_free::conjugate_gradient`, on the systems a caller really
//! solves (feature `cg-compare`, for `beltrami bench cg`).
//!
//! In [`Mode::Compare`] (the default) every call of `solve_preconditioned` first solves
//! its system twice more, on copies, with the same matrix product, the same
//! preconditioner (a solve with the kept factorization), the same relative tolerance
//! and the same iteration limit: once with the solver's own loop and once with faer's;
//! which of the two runs first alternates. Each pair is recorded ([`take`]); the call
//! itself then proceeds as without the feature, so the caller's results are unchanged.
//! In [`Mode::Own`] and [`Mode::Faer`] the call solves with that loop alone, for the
//! caller's results, and records the run ([`take_runs`]): whole flows timed with each.
//! Numeric factorizations are timed in every mode ([`take_factorizations`]): what a
//! solve that gives up costs on top.

use crate::Preconditioned;
use crate::check::check_finite_solution;
use crate::cholesky::Cholesky;
use crate::spd::{column_mut, conjugate_gradients, symmetric_lower_product};
use crate::{Scalar, SolveError};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::matrix_free::conjugate_gradient::{
    CgError, CgParams, conjugate_gradient, conjugate_gradient_scratch,
};
use faer::matrix_free::{InitialGuessStatus, LinOp, Precond};
use faer::sparse::{FaerError, SparseColMatRef};
use faer::{Mat, MatMut, MatRef, Par};
use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::{Mutex, PoisonError};
use std::time::Instant;

/// One conjugate-gradient run on a recorded system.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Run {
    /// Whether the residual reached the tolerance.
    pub converged: bool,
    /// Iterations done.
    pub iterations: usize,
    /// Wall-clock seconds of the whole run (allocations included).
    pub seconds: f64,
}

/// Both runs on one system of a `solve_preconditioned` call.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Comparison {
    /// The number of unknowns.
    pub unknowns: usize,
    /// The iteration limit the caller gave.
    pub max_iterations: usize,
    /// The solver's own loop, which gives up as soon as the mean reduction of the
    /// residual predicts more than `max_iterations`.
    pub own: Run,
    /// faer's `conjugate_gradient`, which runs until the tolerance or the limit.
    pub faer: Run,
    /// When both converged: the largest difference between the two solutions over the
    /// largest entry of the own one.
    pub difference: Option<f64>,
}

/// One timed numeric factorization.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Factorization {
    /// The number of unknowns.
    pub unknowns: usize,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// What `solve_preconditioned` does with its system.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Both loops on copies, recorded; then the own loop for the caller.
    Compare,
    /// The own loop for the caller, recorded.
    Own,
    /// faer's loop for the caller, recorded.
    Faer,
}

static MODE: AtomicU8 = AtomicU8::new(0);
static COMPARISONS: Mutex<Vec<Comparison>> = Mutex::new(Vec::new());
static RUNS: Mutex<Vec<Run>> = Mutex::new(Vec::new());
static FACTORIZATIONS: Mutex<Vec<Factorization>> = Mutex::new(Vec::new());

/// Sets what the following `solve_preconditioned` calls do.
pub fn set_mode(mode: Mode) {
    MODE.store(mode as u8, Ordering::Relaxed);
}

/// The runs of [`Mode::Own`] and [`Mode::Faer`] since the last call.
pub fn take_runs() -> Vec<Run> {
    std::mem::take(&mut *RUNS.lock().unwrap_or_else(PoisonError::into_inner))
}

/// The comparisons recorded since the last call, in the order of the solves.
pub fn take() -> Vec<Comparison> {
    std::mem::take(&mut *COMPARISONS.lock().unwrap_or_else(PoisonError::into_inner))
}

/// The numeric factorizations timed since the last call.
pub fn take_factorizations() -> Vec<Factorization> {
    std::mem::take(
        &mut *FACTORIZATIONS
            .lock()
            .unwrap_or_else(PoisonError::into_inner),
    )
}

/// Records a numeric factorization of `unknowns` unknowns that took `seconds`.
pub(crate) fn record_factorization(unknowns: usize, seconds: f64) {
    FACTORIZATIONS
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .push(Factorization { unknowns, seconds });
}

/// `solve_preconditioned` after its checks, in the current [`Mode`]: the outcome of the
/// mode's loop for the caller (`rhs` overwritten with `x` when it converged).
pub(crate) fn solve<T: Scalar>(
    cholesky: &mut Cholesky<T>,
    matrix: SparseColMatRef<'_, usize, T>,
    rhs: &mut [T],
    tolerance: f64,
    max_iterations: usize,
) -> Result<Preconditioned, SolveError> {
    let mode = MODE.load(Ordering::Relaxed);
    if mode == Mode::Compare as u8 {
        compare(cholesky, matrix, rhs, tolerance, max_iterations)?;
        return conjugate_gradients(cholesky, matrix, rhs, None, tolerance, max_iterations);
    }
    let run = if mode == Mode::Own as u8 {
        own_run(cholesky, matrix, rhs, tolerance, max_iterations)?
    } else {
        let (run, x) = faer_run(cholesky, matrix, rhs, tolerance, max_iterations)?;
        if run.converged {
            check_finite_solution(&x)?;
            rhs.copy_from_slice(&x);
        }
        run
    };
    RUNS.lock()
        .unwrap_or_else(PoisonError::into_inner)
        .push(run);
    Ok(Preconditioned {
        converged: run.converged,
        iterations: run.iterations,
    })
}

/// The solver's own loop on `x` (the right-hand side, then the solution when it
/// converged), timed.
fn own_run<T: Scalar>(
    cholesky: &mut Cholesky<T>,
    matrix: SparseColMatRef<'_, usize, T>,
    x: &mut [T],
    tolerance: f64,
    max_iterations: usize,
) -> Result<Run, SolveError> {
    let start = Instant::now();
    let outcome = conjugate_gradients(cholesky, matrix, x, None, tolerance, max_iterations)?;
    Ok(Run {
        converged: outcome.converged,
        iterations: outcome.iterations,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Solves `matrix x = rhs` with both loops on copies of `rhs` and records the pair.
fn compare<T: Scalar>(
    cholesky: &mut Cholesky<T>,
    matrix: SparseColMatRef<'_, usize, T>,
    rhs: &[T],
    tolerance: f64,
    max_iterations: usize,
) -> Result<(), SolveError> {
    let own_first = COMPARISONS
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .len()
        .is_multiple_of(2);
    let mut own_x = rhs.to_vec();
    let (own, faer) = if own_first {
        let own = own_run(cholesky, matrix, &mut own_x, tolerance, max_iterations)?;
        (
            own,
            faer_run(cholesky, matrix, rhs, tolerance, max_iterations)?,
        )
    } else {
        let faer = faer_run(cholesky, matrix, rhs, tolerance, max_iterations)?;
        (
            own_run(cholesky, matrix, &mut own_x, tolerance, max_iterations)?,
            faer,
        )
    };
    let (faer, faer_x) = faer;
    let difference = (own.converged && faer.converged).then(|| {
        let largest = own_x.iter().fold(0.0f64, |m, v| m.max(v.norm_sqr().sqrt()));
        let worst = own_x
            .iter()
            .zip(&faer_x)
            .fold(0.0f64, |m, (&a, &b)| m.max((a - b).norm_sqr().sqrt()));
        worst / largest.max(f64::MIN_POSITIVE)
    });
    COMPARISONS
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .push(Comparison {
            unknowns: rhs.len(),
            max_iterations,
            own,
            faer,
            difference,
        });
    Ok(())
}

/// faer's preconditioned conjugate gradients from `x = 0`, and their `x`.
fn faer_run<T: Scalar>(
    cholesky: &mut Cholesky<T>,
    matrix: SparseColMatRef<'_, usize, T>,
    rhs: &[T],
    tolerance: f64,
    max_iterations: usize,
) -> Result<(Run, Vec<T>), SolveError> {
    let start = Instant::now();
    let n = rhs.len();
    let mut x = vec![T::from_f64(0.0); n];
    let operator = Lower { matrix };
    let preconditioner = Factored {
        n,
        cholesky: Mutex::new(cholesky),
        failure: Mutex::new(None),
    };
    let scratch: StackReq = conjugate_gradient_scratch(&preconditioner, &operator, 1, Par::Seq);
    let mut buffer = MemBuffer::try_new(scratch).map_err(|_| FaerError::OutOfMemory)?;
    // From `x = 0`, but faer 0.24 leaves the residual uninitialized when told so
    // (`InitialGuessStatus::Zero`): the default forms `b - A x` first.
    let params = CgParams::<T::Real> {
        initial_guess: InitialGuessStatus::MaybeNonZero,
        abs_tolerance: faer::traits::ComplexField::from_f64_impl(0.0),
        rel_tolerance: faer::traits::ComplexField::from_f64_impl(tolerance),
        max_iters: max_iterations,
        ..Default::default()
    };
    let mut iterations = 0;
    let result = conjugate_gradient(
        column_mut(&mut x),
        &preconditioner,
        &operator,
        MatRef::from_column_major_slice(rhs, n, 1),
        params,
        |_| iterations += 1,
        Par::Seq,
        MemStack::new(&mut buffer),
    );
    if let Some(error) = preconditioner
        .failure
        .into_inner()
        .unwrap_or_else(PoisonError::into_inner)
    {
        return Err(error);
    }
    let converged = match result {
        Ok(info) => {
            iterations = info.iter_count;
            true
        }
        Err(
            CgError::NoConvergence { .. }
            | CgError::NonPositiveDefiniteOperator
            | CgError::NonPositiveDefinitePreconditioner,
        ) => false,
    };
    let run = Run {
        converged,
        iterations,
        seconds: start.elapsed().as_secs_f64(),
    };
    Ok((run, x))
}

/// The Hermitian matrix whose lower triangle `matrix` holds, as faer's operator: the
/// product of the own loop.
#[derive(Debug)]
struct Lower<'a, T: Scalar> {
    matrix: SparseColMatRef<'a, usize, T>,
}

impl<T: Scalar> Lower<'_, T> {
    /// `out = M rhs` for a single column, through contiguous slices.
    fn product(&self, mut out: MatMut<'_, T>, rhs: MatRef<'_, T>) {
        let n = self.matrix.nrows();
        let input: Vec<T>;
        let x = match rhs.col(0).try_as_col_major() {
            Some(col) => col.as_slice(),
            None => {
                input = (0..n).map(|i| rhs[(i, 0)]).collect();
                &input
            }
        };
        if let Some(col) = out.as_mut().col_mut(0).try_as_col_major_mut() {
            symmetric_lower_product(self.matrix, x, col.as_slice_mut());
        } else {
            let mut y = vec![T::from_f64(0.0); n];
            symmetric_lower_product(self.matrix, x, &mut y);
            (0..n).for_each(|i| out[(i, 0)] = y[i]);
        }
    }
}

impl<T: Scalar> LinOp<T> for Lower<'_, T> {
    fn apply_scratch(&self, _rhs_ncols: usize, _par: Par) -> StackReq {
        StackReq::EMPTY
    }

    fn nrows(&self) -> usize {
        self.matrix.nrows()
    }

    fn ncols(&self) -> usize {
        self.matrix.ncols()
    }

    fn apply(&self, out: MatMut<'_, T>, rhs: MatRef<'_, T>, _par: Par, _stack: &mut MemStack) {
        self.product(out, rhs);
    }

    fn conj_apply(
        &self,
        mut out: MatMut<'_, T>,
        rhs: MatRef<'_, T>,
        _par: Par,
        _stack: &mut MemStack,
    ) {
        self.product(out.as_mut(), conjugated(rhs).as_ref());
        for i in 0..out.nrows() {
            out[(i, 0)] = Scalar::conjugate(out[(i, 0)]);
        }
    }
}

/// A solve with the kept factorization, as faer's preconditioner (faer applies it
/// through `&self`; the factorization solves through its own scratch).
struct Factored<'a, T: Scalar> {
    n: usize,
    cholesky: Mutex<&'a mut Cholesky<T>>,
    /// The first error of a solve (faer's operators cannot return one).
    failure: Mutex<Option<SolveError>>,
}

impl<T: Scalar> std::fmt::Debug for Factored<'_, T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Factored").field("n", &self.n).finish()
    }
}

impl<T: Scalar> LinOp<T> for Factored<'_, T> {
    fn apply_scratch(&self, _rhs_ncols: usize, _par: Par) -> StackReq {
        StackReq::EMPTY
    }

    fn nrows(&self) -> usize {
        self.n
    }

    fn ncols(&self) -> usize {
        self.n
    }

    fn apply(&self, mut out: MatMut<'_, T>, rhs: MatRef<'_, T>, _par: Par, _stack: &mut MemStack) {
        out.copy_from(rhs);
        let mut cholesky = self.cholesky.lock().unwrap_or_else(PoisonError::into_inner);
        if let Err(error) = cholesky.solve_in_place(out) {
            self.failure
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .get_or_insert(error);
        }
    }

    fn conj_apply(
        &self,
        mut out: MatMut<'_, T>,
        rhs: MatRef<'_, T>,
        par: Par,
        stack: &mut MemStack,
    ) {
        self.apply(out.as_mut(), conjugated(rhs).as_ref(), par, stack);
        for i in 0..out.nrows() {
            out[(i, 0)] = Scalar::conjugate(out[(i, 0)]);
        }
    }
}

impl<T: Scalar> Precond<T> for Factored<'_, T> {}

/// The entrywise conjugate of `m`.
fn conjugated<T: Scalar>(m: MatRef<'_, T>) -> Mat<T> {
    Mat::from_fn(m.nrows(), m.ncols(), |i, j| Scalar::conjugate(m[(i, j)]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{SolveOptions, SpdSolver};
    use faer::sparse::{SparseColMat, Triplet};

    /// The lower triangle of the path Laplacian on `n` vertices plus `shift` times the
    /// identity.
    fn shifted_path(n: usize, shift: f64) -> SparseColMat<usize, f64> {
        let mut triplets = Vec::new();
        for i in 0..n {
            triplets.push(Triplet::new(i, i, 2.0 + shift));
            if i + 1 < n {
                triplets.push(Triplet::new(i + 1, i, -1.0));
            }
        }
        SparseColMat::try_new_from_triplets(n, n, &triplets).unwrap()
    }

    #[test]
    fn both_loops_solve_a_nearby_system_alike_and_each_mode_solves_for_the_caller() {
        let n = 200;
        let (kept, near) = (shifted_path(n, 0.10), shifted_path(n, 0.102));
        let rhs: Vec<f64> = (0..n).map(|k| ((k * 37 % 11) as f64 - 5.0) / 3.0).collect();
        let mut solver = SpdSolver::new(kept.symbolic(), SolveOptions::default()).unwrap();
        solver.factorize(kept.as_ref()).unwrap();
        let mut solutions = Vec::new();
        for mode in [Mode::Compare, Mode::Own, Mode::Faer] {
            set_mode(mode);
            let mut x = rhs.clone();
            let outcome = solver
                .solve_preconditioned(near.as_ref(), &mut x, 1e-10, 10)
                .unwrap();
            assert!(outcome.converged, "{mode:?}: {outcome:?}");
            solutions.push(x);
        }
        set_mode(Mode::Compare);
        let compared = take();
        assert_eq!(compared.len(), 1);
        let c = compared[0];
        assert!(c.own.converged && c.faer.converged, "{c:?}");
        assert_eq!(c.own.iterations, c.faer.iterations);
        assert!(c.difference.is_some_and(|d| d < 1e-12), "{c:?}");
        assert_eq!(take_runs().len(), 2);
        assert_eq!(take_factorizations().len(), 1);
        // The own loop's solution whatever the mode records; faer's agrees to rounding.
        assert_eq!(solutions[0], solutions[1]);
        for (a, b) in solutions[0].iter().zip(&solutions[2]) {
            assert!((a - b).abs() < 1e-12, "{a} {b}");
        }
    }
}
