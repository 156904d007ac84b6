//! Equality-constrained quadratic minimization through the saddle-point (KKT) system,
//! for constraints a [`DofMap`](crate::dof::DofMap) cannot express (general linear
//! relations `C x = d`, e.g. a zero mean or a fixed area-weighted centroid).

use super::{SolveError, SolveOptions, check_finite, check_finite_matrix, check_len};
use crate::dof::Scalar;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::LuError;
use faer::sparse::linalg::lu::{LuRef, NumericLu, factorize_symbolic_lu};
use faer::sparse::{FaerError, SparseColMat, SparseColMatRef, Triplet};
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
