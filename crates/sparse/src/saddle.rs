//! Equality-constrained quadratic minimization through the saddle-point (KKT) system,
//! for constraints a DOF map (`beltrami-fem`) cannot express (general linear
//! relations `C x = d`, e.g. a zero mean or a fixed area-weighted centroid).

use crate::check::{check_finite, check_finite_matrix, check_finite_solution, check_len};
use crate::{Scalar, SolveError, SolveOptions};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::LuError;
use faer::sparse::linalg::lu::{LuRef, NumericLu, SymbolicLu, factorize_symbolic_lu};
use faer::sparse::{
    Argsort, FaerError, Pair, SparseColMat, SparseColMatRef, SymbolicSparseColMat, Triplet,
};
use faer::{Conj, Mat, MatMut, Par};

/// The solution of a saddle-point system: the minimizer and the Lagrange multipliers.
#[derive(Debug, Clone, PartialEq)]
pub struct SaddlePointSolution<T> {
    /// The minimizer `x` (`n`).
    pub x: Vec<T>,
    /// The multipliers `lambda` (one per row of `C`), with `H x + C^H lambda = g`.
    pub multipliers: Vec<T>,
}

/// Solves the saddle-point system
///
/// ```text
/// [ H  C^H ] [   x    ]   [ g ]
/// [ C   0  ] [ lambda ] = [ d ]
/// ```
///
/// by sparse LU with partial pivoting. For `H` Hermitian positive semidefinite and
/// definite on `ker C`, `x` minimizes `x^H H x / 2 - Re(g^H x)` subject to `C x = d`
/// (for a least-squares energy `|A x - b|^2`: `H = A^H A`, `g = A^H b`). `H` (`n x n`)
/// must be stored in full (both triangles); `C` is `p x n`. (`C^H = C^T` in the real
/// case.)
///
/// The system is equilibrated first (rows and columns `i` scaled by
/// `1 / sqrt(max_j |K_ij|)`), then its 1-norm condition number is estimated
/// (Hager-Higham, a few extra solves); an estimate above `1 / tolerance`
/// ([`SolveOptions::singularity_tolerance`], default `8 (n + p) eps`) is
/// [`SolveError::IllConditioned`]: redundant constraints, or an `H` singular on
/// `ker C`. A structurally singular system is [`SolveError::Singular`] with the index
/// into `[x; lambda]`.
pub fn solve_saddle_point<T: Scalar>(
    h: SparseColMatRef<'_, usize, T>,
    g: &[T],
    c: SparseColMatRef<'_, usize, T>,
    d: &[T],
    options: SolveOptions,
) -> Result<SaddlePointSolution<T>, SolveError> {
    let n = h.nrows();
    let p = c.nrows();
    check_len("the column count of H", n, h.ncols())?;
    check_len("the column count of C", n, c.ncols())?;
    check_len("the length of g", n, g.len())?;
    check_len("the length of d", p, d.len())?;
    check_finite_matrix("H", h)?;
    check_finite_matrix("C", c)?;
    check_finite("g", g)?;
    check_finite("d", d)?;
    let size = n + p;
    if size == 0 {
        return Ok(SaddlePointSolution {
            x: Vec::new(),
            multipliers: Vec::new(),
        });
    }

    // Equilibration: s_i = 1 / sqrt(max_j |K_ij|). Scaling symmetrically keeps a
    // Hermitian system Hermitian, and makes the condition estimate measure
    // singularity rather than the relative scale of H and C.
    let mut row_max = vec![0.0_f64; size];
    for j in 0..n {
        for (i, v) in h.row_idx_of_col(j).zip(h.val_of_col(j)) {
            row_max[i] = row_max[i].max(v.norm_sqr().sqrt());
        }
        for (k, v) in c.row_idx_of_col(j).zip(c.val_of_col(j)) {
            let a = v.norm_sqr().sqrt();
            row_max[n + k] = row_max[n + k].max(a);
            row_max[j] = row_max[j].max(a);
        }
    }
    let scale: Vec<f64> = row_max
        .iter()
        .map(|&r| if r > 0.0 { 1.0 / r.sqrt() } else { 1.0 })
        .collect();

    let mut triplets = Vec::with_capacity(h.compute_nnz() + 2 * c.compute_nnz());
    for j in 0..n {
        for (i, &v) in h.row_idx_of_col(j).zip(h.val_of_col(j)) {
            triplets.push(Triplet::new(i, j, v * T::from_f64(scale[i] * scale[j])));
        }
        for (k, &v) in c.row_idx_of_col(j).zip(c.val_of_col(j)) {
            let s = T::from_f64(scale[n + k] * scale[j]);
            triplets.push(Triplet::new(n + k, j, v * s));
            triplets.push(Triplet::new(j, n + k, v.conjugate() * s));
        }
    }
    let kkt = SparseColMat::try_new_from_triplets(size, size, &triplets).map_err(|e| match e {
        faer::sparse::CreationError::Generic(e) => e,
        // Indices are below `size` by construction.
        faer::sparse::CreationError::OutOfBounds { .. } => FaerError::IndexOverflow,
    })?;
    let norm_1 = (0..size)
        .map(|j| {
            kkt.val_of_col(j)
                .iter()
                .map(|v| v.norm_sqr().sqrt())
                .sum::<f64>()
        })
        .fold(0.0, f64::max);

    let symbolic = factorize_symbolic_lu(kkt.symbolic(), Default::default())?;
    let scratch = symbolic
        .factorize_numeric_lu_scratch::<T>(Par::Seq, Default::default())
        .or(symbolic.solve_in_place_scratch::<T>(1, Par::Seq))
        .or(symbolic.solve_transpose_in_place_scratch::<T>(1, Par::Seq));
    let mut buffer = MemBuffer::try_new(scratch).map_err(FaerError::from)?;
    let mut numeric = NumericLu::new();
    let lu = symbolic
        .factorize_numeric_lu(
            &mut numeric,
            kkt.as_ref(),
            Par::Seq,
            MemStack::new(&mut buffer),
            Default::default(),
        )
        .map_err(|e| match e {
            // The index counts columns in the fill-reducing column order.
            LuError::SymbolicSingular { index } => SolveError::Singular {
                index: symbolic.col_perm().arrays().0[index.min(size - 1)],
                node: None,
                ratio: 0.0,
            },
            LuError::Generic(e) => SolveError::Faer(e),
        })?;

    let estimate = norm_1 * inverse_norm_1_estimate(lu, size, &mut buffer);
    let limit = 1.0 / options.tolerance(size);
    if estimate.is_nan() || estimate > limit {
        return Err(SolveError::IllConditioned { estimate, limit });
    }

    let mut z = Mat::<T>::from_fn(size, 1, |i, _| {
        let r = if i < n { g[i] } else { d[i - n] };
        r * T::from_f64(scale[i])
    });
    lu.solve_in_place_with_conj(Conj::No, z.as_mut(), Par::Seq, MemStack::new(&mut buffer));
    let z: Vec<T> = (0..size)
        .map(|i| z[(i, 0)] * T::from_f64(scale[i]))
        .collect();
    if let Some(index) = z.iter().position(|v| !v.finite()) {
        return Err(SolveError::NonFiniteSolution { index });
    }
    Ok(SaddlePointSolution {
        x: z[..n].to_vec(),
        multipliers: z[n..].to_vec(),
    })
}

/// Estimate of `|K^{-1}|_1` from an LU factorization: Hager's method with Higham's
/// refinements (the algorithm of LAPACK's `xLACN2`). Each step solves with `K` and
/// `K^H`; the estimate is a lower bound, usually within a factor 3. Infinite when a
/// solve gives non-finite values (a zero pivot).
fn inverse_norm_1_estimate<T: Scalar>(
    lu: LuRef<'_, usize, T>,
    size: usize,
    buffer: &mut MemBuffer,
) -> f64 {
    let solve = |v: &mut Mat<T>, adjoint: bool, buffer: &mut MemBuffer| {
        let rhs: MatMut<'_, T> = v.as_mut();
        if adjoint {
            lu.solve_transpose_in_place_with_conj(Conj::Yes, rhs, Par::Seq, MemStack::new(buffer));
        } else {
            lu.solve_in_place_with_conj(Conj::No, rhs, Par::Seq, MemStack::new(buffer));
        }
    };
    let norm_1 = |v: &Mat<T>| (0..size).map(|i| v[(i, 0)].norm_sqr().sqrt()).sum::<f64>();
    // sign(v) = v / |v|, and 1 where v = 0.
    let sign = |v: T| {
        let a = v.norm_sqr().sqrt();
        if a > 0.0 {
            v * T::from_f64(1.0 / a)
        } else {
            T::from_f64(1.0)
        }
    };

    // A solve that met a zero pivot leaves infinities or NaNs: the matrix is singular.
    let finite = |v: &Mat<T>| (0..size).all(|i| v[(i, 0)].finite());
    let mut x = Mat::<T>::from_fn(size, 1, |_, _| T::from_f64(1.0 / size as f64));
    solve(&mut x, false, buffer);
    if !finite(&x) {
        return f64::INFINITY;
    }
    let mut estimate = norm_1(&x);
    let mut last = usize::MAX;
    for _ in 0..5 {
        let mut z = Mat::<T>::from_fn(size, 1, |i, _| sign(x[(i, 0)]));
        solve(&mut z, true, buffer);
        if !finite(&z) {
            return f64::INFINITY;
        }
        let j = (0..size)
            .map(|i| (i, z[(i, 0)].norm_sqr()))
            .fold(
                (0, -1.0),
                |best, cur| if cur.1 > best.1 { cur } else { best },
            )
            .0;
        if j == last {
            break;
        }
        last = j;
        x = Mat::<T>::from_fn(size, 1, |i, _| T::from_f64(if i == j { 1.0 } else { 0.0 }));
        solve(&mut x, false, buffer);
        if !finite(&x) {
            return f64::INFINITY;
        }
        let next = norm_1(&x);
        if next <= estimate {
            break;
        }
        estimate = next;
    }
    // Higham's safeguard against matrices that fool the iteration: the alternating
    // vector x_i = (-1)^i (1 + i / (size - 1)).
    let mut alt = Mat::<T>::from_fn(size, 1, |i, _| {
        let magnitude = 1.0 + i as f64 / (size.max(2) - 1) as f64;
        T::from_f64(if i % 2 == 0 { magnitude } else { -magnitude })
    });
    solve(&mut alt, false, buffer);
    if !finite(&alt) {
        return f64::INFINITY;
    }
    estimate.max(2.0 * norm_1(&alt) / (3.0 * size as f64))
}

/// A saddle-point system `[H C^H; C 0] [x; lambda] = [g; d]` whose pattern stays fixed
/// while its values change, as in an iteration that solves one constrained quadratic
/// problem per step: the pattern of the KKT matrix, the scatter of the entries into it
/// and the symbolic LU factorization (fill-reducing column order, elimination tree) are
/// computed once in [`SaddlePointSolver::new`]; each [`SaddlePointSolver::solve`] refills
/// the values and repeats only the numeric LU with partial pivoting.
///
/// The minimization it solves is the one of [`solve_saddle_point`]. Unlike that
/// one-shot function, it neither equilibrates nor estimates the condition number (each
/// estimate costs a dozen extra solves per step); a singular system shows as a
/// [`SolveError::Singular`] from the numeric factorization or as
/// [`SolveError::NonFiniteSolution`].
pub struct SaddlePointSolver<T: Scalar> {
    /// Unknowns `n` (rows of `H`) and constraints `p` (rows of `C`).
    n: usize,
    p: usize,
    h_entries: usize,
    c_entries: usize,
    symbolic: SymbolicSparseColMat<usize>,
    argsort: Argsort<usize>,
    lu: SymbolicLu<usize>,
    numeric: NumericLu<usize, T>,
    buffer: MemBuffer,
    /// KKT values in entry order: `H`, then `C`, then `C^H`.
    values: Vec<T>,
}

impl<T: Scalar> std::fmt::Debug for SaddlePointSolver<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SaddlePointSolver")
            .field("n", &self.n)
            .field("p", &self.p)
            .field("nnz", &self.symbolic.row_idx().len())
            .finish_non_exhaustive()
    }
}

impl<T: Scalar> SaddlePointSolver<T> {
    /// Symbolic phase for `H` (`n x n`, both triangles) with entries at `h_positions`
    /// and `C` (`p x n`) with entries at `c_positions` (`(row, col)`; duplicates are
    /// summed on every solve).
    ///
    /// Errors: [`SolveError::Length`] for a position outside its matrix,
    /// [`SolveError::Faer`] if faer cannot build the pattern or its factorization.
    pub fn new(
        n: usize,
        h_positions: &[(usize, usize)],
        p: usize,
        c_positions: &[(usize, usize)],
    ) -> Result<Self, SolveError> {
        let outside = |what, limit: usize, got: usize| SolveError::Length {
            what,
            expected: limit,
            got,
        };
        let mut pairs = Vec::with_capacity(h_positions.len() + 2 * c_positions.len());
        for &(row, col) in h_positions {
            if row >= n || col >= n {
                return Err(outside("an index of H", n, row.max(col)));
            }
            pairs.push(Pair { row, col });
        }
        for &(row, col) in c_positions {
            if row >= p {
                return Err(outside("a row index of C", p, row));
            }
            if col >= n {
                return Err(outside("a column index of C", n, col));
            }
            pairs.push(Pair { row: n + row, col });
        }
        for &(row, col) in c_positions {
            pairs.push(Pair {
                row: col,
                col: n + row,
            });
        }
        let size = n + p;
        let (symbolic, argsort) = SymbolicSparseColMat::try_new_from_indices(size, size, &pairs)
            .map_err(|e| match e {
                faer::sparse::CreationError::Generic(e) => SolveError::Faer(e),
                faer::sparse::CreationError::OutOfBounds { row, col } => SolveError::Length {
                    what: "a KKT index",
                    expected: size,
                    got: row.max(col),
                },
            })?;
        let lu = factorize_symbolic_lu(symbolic.as_ref(), Default::default())?;
        let scratch = lu
            .factorize_numeric_lu_scratch::<T>(Par::Seq, Default::default())
            .or(lu.solve_in_place_scratch::<T>(1, Par::Seq));
        let buffer = MemBuffer::try_new(scratch).map_err(FaerError::from)?;
        Ok(Self {
            n,
            p,
            h_entries: h_positions.len(),
            c_entries: c_positions.len(),
            symbolic,
            argsort,
            lu,
            numeric: NumericLu::new(),
            buffer,
            values: vec![T::from_f64(0.0); pairs.len()],
        })
    }

    /// Numeric phase: `x` and `lambda` for the values `h_values` and `c_values` (in the
    /// order of the positions given to [`new`](Self::new)) and right-hand sides `g`
    /// (`n`), `d` (`p`).
    pub fn solve(
        &mut self,
        h_values: &[T],
        c_values: &[T],
        g: &[T],
        d: &[T],
    ) -> Result<SaddlePointSolution<T>, SolveError> {
        let (n, p) = (self.n, self.p);
        check_len("the number of H values", self.h_entries, h_values.len())?;
        check_len("the number of C values", self.c_entries, c_values.len())?;
        check_len("the length of g", n, g.len())?;
        check_len("the length of d", p, d.len())?;
        check_finite("H", h_values)?;
        check_finite("C", c_values)?;
        check_finite("g", g)?;
        check_finite("d", d)?;
        let (h_part, rest) = self.values.split_at_mut(self.h_entries);
        let (c_part, ch_part) = rest.split_at_mut(self.c_entries);
        h_part.copy_from_slice(h_values);
        c_part.copy_from_slice(c_values);
        for (dst, v) in ch_part.iter_mut().zip(c_values) {
            *dst = v.conjugate();
        }
        let kkt =
            SparseColMat::new_from_argsort(self.symbolic.clone(), &self.argsort, &self.values)?;
        let size = n + p;
        let lu = self
            .lu
            .factorize_numeric_lu(
                &mut self.numeric,
                kkt.as_ref(),
                Par::Seq,
                MemStack::new(&mut self.buffer),
                Default::default(),
            )
            .map_err(|e| match e {
                LuError::SymbolicSingular { index } => SolveError::Singular {
                    index: self.lu.col_perm().arrays().0[index.min(size - 1)],
                    node: None,
                    ratio: 0.0,
                },
                LuError::Generic(e) => SolveError::Faer(e),
            })?;
        let mut z = Mat::<T>::from_fn(size, 1, |i, _| if i < n { g[i] } else { d[i - n] });
        lu.solve_in_place_with_conj(
            Conj::No,
            z.as_mut(),
            Par::Seq,
            MemStack::new(&mut self.buffer),
        );
        let z: Vec<T> = (0..size).map(|i| z[(i, 0)]).collect();
        check_finite_solution(&z)?;
        Ok(SaddlePointSolution {
            x: z[..n].to_vec(),
            multipliers: z[n..].to_vec(),
        })
    }
}
