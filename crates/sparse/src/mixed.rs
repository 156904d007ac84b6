//! Positive definite solves in mixed precision: the Cholesky factorization in `f32`,
//! its solutions refined against the matrix in `f64` where they need it.
//!
//! A factor of `f32` entries takes half the memory of one in `f64`, and the numeric
//! factorization and the triangular solves (which read the whole factor and are bound
//! by memory) take less time: on the non-rigid ICP's normal equations of fsaverage5
//! (41K unknowns in dense 4 x 4 blocks, 7.7M factor entries, two sides on two cores)
//! 77 ms -> 36-56 ms a factorization and 16-17 ms -> 11-12 ms a solve of three
//! right-hand sides.
//!
//! The `f32` solution `x_0` of `M x = b` has an error of about `cond(M) eps_32`
//! relative. Iterative refinement (Wilkinson; Higham, *Accuracy and Stability of
//! Numerical Algorithms*, 2nd ed., section 12.1) removes it while that is below one:
//! `r_k = b - M x_k` in `f64`, `d_k = M^-1 r_k` with the `f32` factor, `x_{k+1} = x_k +
//! d_k`, each step multiplying the error by about `cond(M) eps_32`. The first solve
//! after a factorization always refines once and keeps the size of that correction,
//! `|d_0| / |x_1|` (largest entries): it measures how far an unrefined solve of this
//! matrix lands. Later solves refine only when that measure is above the tolerance asked
//! for, and then until their own correction is below it.

use crate::check::{check_finite, check_len};
use crate::{SolveError, SolveOptions, SpdSolver, SplitOrder};
use faer::MatMut;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};

/// Refinement steps of one solve at most: each multiplies the error by about
/// `cond(M) eps_32`, so a matrix that needs more is too ill-conditioned for an `f32`
/// factor ([`SolveError::Refinement`]).
const MAX_REFINEMENTS: usize = 4;

/// Repeated solves with Hermitian positive definite real matrices of one pattern, each
/// factored in `f32` and its solutions refined in `f64` to a relative tolerance (module
/// docs): [`SpdSolver`]'s job at less time per factorization and per solve where the
/// matrix is well enough conditioned that the `f32` solutions need no refinement.
pub struct MixedSpdSolver {
    factor: SpdSolver<f32>,
    /// The values of the last matrix factored, in `f64` (the pattern's order).
    values: Vec<f64>,
    /// The same rounded to `f32`.
    rounded: Vec<f32>,
    /// The right-hand sides of an `f32` solve, columns of `n` stacked (kept between
    /// solves).
    work: Vec<f32>,
    /// `|d_0| / |x_1|` of the first solve after the last factorization, once measured.
    unrefined_error: Option<f64>,
}

impl std::fmt::Debug for MixedSpdSolver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MixedSpdSolver")
            .field("factor", &self.factor)
            .field("unrefined_error", &self.unrefined_error)
            .finish_non_exhaustive()
    }
}

/// How a [`MixedSpdSolver::solve_in_place`] went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Refined {
    /// Refinement steps done (0: the `f32` solution was taken as it is).
    pub steps: usize,
    /// The relative size of the last correction made (the error left is about
    /// `cond(M) eps_32` times it), or the first solve's measure when no step was made.
    pub last_correction: f64,
}

impl MixedSpdSolver {
    /// [`SpdSolver::with_split_order`] for the `f32` factor: the order of `split`, its
    /// two sides factored at once where they exist.
    ///
    /// # Errors
    /// Those of [`SpdSolver::with_split_order`].
    pub fn with_split_order(
        pattern: SymbolicSparseColMatRef<'_, usize>,
        split: &SplitOrder,
        options: SolveOptions,
    ) -> Result<Self, SolveError> {
        let factor = SpdSolver::with_split_order(pattern, split, options)?;
        let stored = pattern.row_idx().len();
        Ok(Self {
            factor,
            values: vec![0.0; stored],
            rounded: vec![0.0; stored],
            work: Vec::new(),
            unrefined_error: None,
        })
    }

    /// The number of unknowns.
    pub fn len(&self) -> usize {
        self.factor.len()
    }

    /// True when there are no unknowns.
    pub fn is_empty(&self) -> bool {
        self.factor.is_empty()
    }

    /// Numeric factorization of `matrix` in `f32` (the pattern given at construction,
    /// lower triangle read); `matrix` is kept in `f64` for the refinement.
    ///
    /// # Errors
    /// Those of [`SpdSolver::factorize`]; [`SolveError::NonFinite`] also for a value
    /// beyond the range of `f32` (about `3.4e38`).
    pub fn factorize(&mut self, matrix: SparseColMatRef<'_, usize, f64>) -> Result<(), SolveError> {
        self.unrefined_error = None;
        check_len(
            "the stored entries of the matrix",
            self.values.len(),
            matrix.val().len(),
        )?;
        check_finite("the matrix", matrix.val())?;
        for ((kept, rounded), &value) in self
            .values
            .iter_mut()
            .zip(&mut self.rounded)
            .zip(matrix.val())
        {
            *kept = value;
            *rounded = value as f32;
        }
        check_finite("the matrix rounded to f32", &self.rounded)?;
        self.factor
            .factorize(SparseColMatRef::new(matrix.symbolic(), &self.rounded))
    }

    /// Overwrites the columns of `rhs` with the solutions of `M x = rhs` for the last
    /// matrix factored: the `f32` solution, refined (module docs) unless the first
    /// solve of this factorization measured its correction at most `tolerance`, until
    /// the relative size of a correction (its largest entry over the solution's, per
    /// column) is at most `tolerance`.
    ///
    /// # Errors
    /// [`SolveError::NotFactored`] without a factorization, [`SolveError::NonFinite`]
    /// for a non-finite right-hand side, [`SolveError::NonFiniteSolution`], and
    /// [`SolveError::Refinement`] when four steps leave a correction above
    /// `tolerance` (the matrix is too ill-conditioned for an `f32` factor).
    pub fn solve_in_place(
        &mut self,
        mut rhs: MatMut<'_, f64>,
        tolerance: f64,
    ) -> Result<Refined, SolveError> {
        let n = self.len();
        check_len("the row count of the right-hand side", n, rhs.nrows())?;
        if !self.factor.is_factored() {
            return Err(SolveError::NotFactored);
        }
        let columns = rhs.ncols();
        for j in 0..columns {
            for i in 0..n {
                if !rhs[(i, j)].is_finite() {
                    return Err(SolveError::NonFinite {
                        what: "the right-hand side",
                        index: i + j * n,
                    });
                }
            }
        }
        if let Some(error) = self.unrefined_error
            && error <= tolerance
        {
            // The f32 solution as it is, through the kept buffer.
            self.work.clear();
            for j in 0..columns {
                self.work.extend((0..n).map(|i| rhs[(i, j)] as f32));
            }
            check_finite("the right-hand side rounded to f32", &self.work)?;
            self.solve_work(columns)?;
            for j in 0..columns {
                for i in 0..n {
                    rhs[(i, j)] = f64::from(self.work[i + j * n]);
                }
            }
            return Ok(Refined {
                steps: 0,
                last_correction: error,
            });
        }
        let mut b = vec![0.0; n * columns];
        for j in 0..columns {
            for i in 0..n {
                b[i + j * n] = rhs[(i, j)];
            }
        }
        let mut x = self.solve_rounded(&b, columns)?;
        let mut refined = Refined {
            steps: 0,
            last_correction: self.unrefined_error.unwrap_or(f64::INFINITY),
        };
        loop {
            if refined.steps == MAX_REFINEMENTS {
                return Err(SolveError::Refinement {
                    steps: MAX_REFINEMENTS,
                    correction: refined.last_correction,
                });
            }
            let residual = self.residual(&b, &x, columns);
            let correction = self.solve_rounded(&residual, columns)?;
            x.iter_mut().zip(&correction).for_each(|(a, d)| *a += d);
            refined.steps += 1;
            refined.last_correction = relative_size(&correction, &x, n);
            if self.unrefined_error.is_none() {
                self.unrefined_error = Some(refined.last_correction);
            }
            if refined.last_correction <= tolerance {
                break;
            }
        }
        for j in 0..columns {
            for i in 0..n {
                rhs[(i, j)] = x[i + j * n];
            }
        }
        Ok(refined)
    }

    /// `M^-1 b` with the `f32` factor, columns of `n` stacked.
    fn solve_rounded(&mut self, b: &[f64], columns: usize) -> Result<Vec<f64>, SolveError> {
        self.work.clear();
        self.work.extend(b.iter().map(|&v| v as f32));
        check_finite("the right-hand side rounded to f32", &self.work)?;
        self.solve_work(columns)?;
        Ok(self.work.iter().map(|&v| f64::from(v)).collect())
    }

    /// The kept buffer (`columns` right-hand sides) overwritten with its solutions.
    fn solve_work(&mut self, columns: usize) -> Result<(), SolveError> {
        let n = self.len();
        self.factor
            .solve_in_place(MatMut::from_column_major_slice_mut(
                &mut self.work,
                n,
                columns,
            ))
    }

    /// `b - M x` in `f64`, columns of `n` stacked: one pass over the lower triangle of
    /// `M` for every column (the matrix is read once).
    fn residual(&self, b: &[f64], x: &[f64], columns: usize) -> Vec<f64> {
        let n = self.len();
        let matrix = SparseColMatRef::new(self.factor.pattern(), &self.values);
        let mut residual = b.to_vec();
        for j in 0..n {
            for (i, &v) in matrix.row_idx_of_col(j).zip(matrix.val_of_col(j)) {
                if i < j {
                    continue;
                }
                for c in 0..columns {
                    let (x_i, x_j) = (x[i + c * n], x[j + c * n]);
                    residual[i + c * n] -= v * x_j;
                    if i > j {
                        residual[j + c * n] -= v * x_i;
                    }
                }
            }
        }
        residual
    }
}

/// The largest ratio over the columns of `correction`'s largest entry to `x`'s (0 for a
/// zero correction; columns of `n` stacked).
fn relative_size(correction: &[f64], x: &[f64], n: usize) -> f64 {
    let largest = |v: &[f64]| v.iter().fold(0.0f64, |m, a| m.max(a.abs()));
    correction
        .chunks(n.max(1))
        .zip(x.chunks(n.max(1)))
        .map(|(d, x)| {
            let size = largest(d);
            if size == 0.0 { 0.0 } else { size / largest(x) }
        })
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::two_core_order;
    use faer::Mat;
    use faer::sparse::{SparseColMat, Triplet};

    /// The lower triangle of `alpha L + D` on a `k x k` grid graph (`L` its graph
    /// Laplacian, `D` a diagonal with entries in `[0.01, 1.01]`, or none): its
    /// condition number grows like `alpha k^2 / 0.01`.
    fn grid_system(k: usize, alpha: f64, diagonal_term: bool) -> SparseColMat<usize, f64> {
        let n = k * k;
        let mut triplets = Vec::new();
        let mut diagonal: Vec<f64> = (0..n)
            .map(|i| {
                if diagonal_term {
                    0.01 + ((i * 37) % 101) as f64 / 100.0
                } else {
                    0.0
                }
            })
            .collect();
        for r in 0..k {
            for c in 0..k {
                let i = r * k + c;
                for (rr, cc) in [(r + 1, c), (r, c + 1)] {
                    if rr < k && cc < k {
                        let j = rr * k + cc;
                        triplets.push(Triplet::new(j, i, -alpha));
                        diagonal[i] += alpha;
                        diagonal[j] += alpha;
                    }
                }
            }
        }
        triplets.extend(
            diagonal
                .iter()
                .enumerate()
                .map(|(i, &d)| Triplet::new(i, i, d)),
        );
        SparseColMat::try_new_from_triplets(n, n, &triplets).unwrap()
    }

    /// The solver of `matrix`'s pattern factored as a whole in the rows' order.
    fn whole_solver(matrix: &SparseColMat<usize, f64>) -> MixedSpdSolver {
        let order = SplitOrder {
            order: (0..matrix.nrows()).collect(),
            sides: None,
        };
        MixedSpdSolver::with_split_order(matrix.symbolic(), &order, SolveOptions::default())
            .unwrap()
    }

    /// The solution of the `f64` solver, to compare with.
    fn exact(matrix: &SparseColMat<usize, f64>, rhs: &Mat<f64>) -> Mat<f64> {
        crate::solve_spd(matrix.as_ref(), rhs.as_ref(), SolveOptions::default()).unwrap()
    }

    /// The largest difference of a column's entries over the column's largest entry.
    fn largest_difference(a: &Mat<f64>, b: &Mat<f64>) -> f64 {
        let mut worst = 0.0f64;
        for j in 0..a.ncols() {
            let scale = (0..a.nrows()).fold(0.0f64, |m, i| m.max(b[(i, j)].abs()));
            for i in 0..a.nrows() {
                worst = worst.max((a[(i, j)] - b[(i, j)]).abs() / scale);
            }
        }
        worst
    }

    #[test]
    fn an_ill_conditioned_system_is_refined_to_the_f64_solution() {
        // Condition about 1e6: an f32 solve alone is off by about 1e-2 relative.
        let matrix = grid_system(40, 1e1, true);
        let n = matrix.nrows();
        let rhs = Mat::<f64>::from_fn(n, 3, |i, j| ((i * (j + 3)) as f64 * 0.37).sin());
        let mut solver = whole_solver(&matrix);
        solver.factorize(matrix.as_ref()).unwrap();
        for _ in 0..2 {
            let mut x = rhs.clone();
            let refined = solver.solve_in_place(x.as_mut(), 1e-10).unwrap();
            assert!(refined.steps >= 2, "{refined:?}");
            assert!(refined.last_correction <= 1e-10, "{refined:?}");
            let difference = largest_difference(&x, &exact(&matrix, &rhs));
            assert!(difference < 1e-9, "{difference:e} from the f64 solution");
        }
    }

    #[test]
    fn a_well_conditioned_system_is_refined_only_in_its_first_solve() {
        let matrix = grid_system(30, 1e-2, true);
        let n = matrix.nrows();
        let split = two_core_order(matrix.symbolic()).unwrap();
        let mut solver =
            MixedSpdSolver::with_split_order(matrix.symbolic(), &split, SolveOptions::default())
                .unwrap();
        solver.factorize(matrix.as_ref()).unwrap();
        let rhs = Mat::<f64>::from_fn(n, 2, |i, j| ((i + 5 * j) as f64 * 0.11).cos());
        let mut first = rhs.clone();
        let measured = solver.solve_in_place(first.as_mut(), 1e-5).unwrap();
        assert_eq!(measured.steps, 1);
        assert!(measured.last_correction < 1e-5, "{measured:?}");
        let mut second = rhs.clone();
        let unrefined = solver.solve_in_place(second.as_mut(), 1e-5).unwrap();
        assert_eq!(unrefined.steps, 0);
        // Unrefined, the f32 solution is within the first solve's measure, not at f64's
        // precision; refined, it is.
        let exact = exact(&matrix, &rhs);
        let off = largest_difference(&second, &exact);
        assert!(off < 1e-5 && off > 1e-12, "{off:e}");
        assert!(largest_difference(&first, &exact) < 1e-9);
        // The unrefined path checks its right-hand sides as the refined one does.
        for bad in [f64::NAN, 1e300] {
            let mut beyond = rhs.clone();
            beyond[(7, 1)] = bad;
            assert!(matches!(
                solver.solve_in_place(beyond.as_mut(), 1e-5),
                Err(SolveError::NonFinite { .. })
            ));
        }
        // A new factorization measures again.
        solver.factorize(matrix.as_ref()).unwrap();
        let mut again = rhs.clone();
        assert_eq!(
            solver.solve_in_place(again.as_mut(), 1e-5).unwrap().steps,
            1
        );
    }

    #[test]
    fn a_matrix_beyond_f32_is_an_error_and_a_solve_needs_a_factorization() {
        let matrix = grid_system(4, 1.0, true);
        let n = matrix.nrows();
        let mut solver = whole_solver(&matrix);
        let mut rhs = Mat::<f64>::zeros(n, 1);
        assert!(matches!(
            solver.solve_in_place(rhs.as_mut(), 1e-6),
            Err(SolveError::NotFactored)
        ));
        let mut huge = matrix.clone();
        huge.val_mut()[0] = 1e300;
        assert!(matches!(
            solver.factorize(huge.as_ref()),
            Err(SolveError::NonFinite { .. })
        ));
        assert!(matches!(
            solver.solve_in_place(rhs.as_mut(), 1e-6),
            Err(SolveError::NotFactored)
        ));
    }

    #[test]
    fn a_singular_matrix_fails_at_f32_precision() {
        // The graph Laplacian alone (no diagonal term) is singular.
        let matrix = grid_system(20, 1.0, false);
        let mut solver = whole_solver(&matrix);
        let failed = solver.factorize(matrix.as_ref());
        assert!(
            matches!(
                failed,
                Err(SolveError::Singular { .. } | SolveError::NotPositiveDefinite { .. })
            ),
            "{failed:?}"
        );
    }
}
