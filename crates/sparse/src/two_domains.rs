//! A sparse Cholesky factorization on two cores: one level of domain decomposition
//! (substructuring) over the first split of a nested-dissection order.
//!
//! # The formulas
//!
//! The separator `S` splits the unknowns into sides `A` and `B` that share no entry:
//!
//! ```text
//!       [ M_AA   0     M_AS ]
//!   M = [ 0      M_BB  M_BS ]
//!       [ M_SA   M_SB  M_SS ]
//! ```
//!
//! The principal submatrices `M_A = [M_AA M_AS; M_SA M_SS]` and `M_B` (the same with
//! `B`) are Hermitian positive definite whenever `M` is, and are factored at once, one
//! per core, each eliminating its side before `S` (faer's sparse kernel does not
//! factor independent subtrees at once). The last `|S|` columns of the factor of `M_A`
//! are the Cholesky factor `L_A` of the side's Schur complement
//!
//! ```text
//! T_A = L_A L_A^H = M_SS - M_SA M_AA^-1 M_AS        (likewise T_B),
//! ```
//!
//! so the Schur complement of `M` onto `S` is `T_A + T_B - M_SS`, factored dense. With
//! the side's factor in its elimination order (side first, separator last),
//! `L = [L_11 0; L_21 L_A]`, a solve `M x = b` takes one forward and one backward
//! triangular solve per side, the sides at once:
//!
//! 1. forward, `L [y_1; y_S] = P [b_A; 0]`: since `g_A = M_SA M_AA^-1 b_A = L_21 y_1` and
//!    the separator rows read `L_21 y_1 + L_A y_S = 0`, `g_A = -L_A y_S` (likewise
//!    `g_B`);
//! 2. `(T_A + T_B - M_SS) x_S = b_S - g_A - g_B`;
//! 3. backward: `M_A [x_A; v] = [b_A; T_A x_S + g_A]` has `v = x_S`, and its forward
//!    solve is `[y_1; L_A^H x_S]` (`y_1` kept from step 1), so one backward solve
//!    `L^H [x_A; x_S] = [y_1; L_A^H x_S]` gives `x_A` (likewise `x_B`).
//!
//! The separator's dense work (its elimination in both sides, `T_A` and `T_B`, the
//! factorization of their sum) costs a few times `|S|^3 / 3`, small against the sides
//! when `S` is a nested dissection's top separator (about `sqrt(n)` rows of a planar
//! mesh).

use crate::cholesky::{Factor, FactorFailure, analyse, eliminated};
use crate::factor_count::{column_multiply_subtracts, stored_multiply_subtracts};
use crate::{Kernel, Scalar, SolveError};
use faer::linalg::cholesky::llt::factor::LltError;
use faer::linalg::matmul::triangular::{self, BlockStructure};
use faer::linalg::solvers::{Llt, Solve};
use faer::sparse::linalg::cholesky::{SymbolicCholesky, SymmetricOrdering};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};
use faer::{Accum, Mat, MatMut, MatRef, Par, Side};
use rayon::join;

/// The two sides' factorizations and the separator's dense Schur complement (module
/// docs).
pub(super) struct TwoDomains<T: Scalar> {
    n: usize,
    sides: [SideFactor<T>; 2],
    /// The rows of `S` (numbering of `M`), in elimination order: the separator's
    /// numbering.
    separator: Vec<usize>,
    /// The stored entries of `M_SS` read from the lower triangle of `M`: position among
    /// the values of `M`, row and column in the separator's numbering.
    separator_entries: Vec<(usize, usize, usize)>,
    /// The factorization of `T_A + T_B - M_SS`, after a successful `factorize`.
    schur: Option<Llt<T>>,
}

/// The symbolic phase of [`TwoDomains`]: both sides' submatrices and analyses, before
/// their factors' storage is written, so that a caller can first weigh the order by
/// its cost ([`TwoDomainsPlan::multiply_subtracts_bound`]).
pub(super) struct TwoDomainsPlan {
    n: usize,
    sides: [SidePlan; 2],
    /// As in [`TwoDomains`].
    separator: Vec<usize>,
    separator_entries: Vec<(usize, usize, usize)>,
}

/// One side's submatrix `M_A` and its symbolic analysis ([`SideFactor`] without the
/// factor's storage).
struct SidePlan {
    /// As in [`SideFactor`].
    rows: Vec<usize>,
    own_in_order: Vec<usize>,
    pattern: SymbolicSparseColMat<usize>,
    source: Vec<u32>,
    symbolic: SymbolicCholesky<usize>,
}

/// One side's submatrix `M_A`, numbered in the elimination order (the side's rows,
/// then the separator's), and its factorization.
struct SideFactor<T: Scalar> {
    /// The row of `M` of each local row (the side's, then the separator's, in the
    /// elimination order).
    rows: Vec<usize>,
    /// The row of `M` of each of the side's own rows, in elimination order: the side's
    /// factor eliminates these first, then the separator in its own numbering.
    own_in_order: Vec<usize>,
    pattern: SymbolicSparseColMat<usize>,
    /// For each stored value of `M_A`, its position among the values of `M`, with
    /// [`CONJUGATED`] set when it is that value's conjugate (read above the diagonal in
    /// this numbering).
    source: Vec<u32>,
    values: Vec<T>,
    factor: Factor<T>,
    /// `L_A`, the factor's last `|S|` rows and columns (lower triangular, separator
    /// numbering), after a successful factorization.
    trailing: Mat<T>,
    /// `T_A = L_A L_A^H` (`|S| x |S|`, both triangles, separator numbering), after a
    /// successful factorization.
    schur_part: Mat<T>,
}

/// The bit of a [`SideFactor`]'s source position that marks a conjugated value.
const CONJUGATED: u32 = 1 << 31;

/// Which side a row of `M` is on, [`SEPARATOR`] for the separator.
const SEPARATOR: u8 = 2;

impl TwoDomainsPlan {
    /// Symbolic phase for `pattern` (lower triangle read) in the nested-dissection order
    /// `order` whose first split has sides of `halves[0]` and `halves[1]` rows, the rest
    /// being their separator: the two sides analysed at once. `None` when the split does
    /// not separate (an entry joins the two sides), a side is empty, or a side's
    /// factorization would not eliminate the separator last: the caller then factors
    /// the whole.
    pub(super) fn new(
        pattern: SymbolicSparseColMatRef<'_, usize>,
        order: &[usize],
        halves: [usize; 2],
        kernel: Kernel,
    ) -> Result<Option<Self>, SolveError> {
        let n = pattern.nrows();
        let [a, b] = halves;
        if a == 0 || b == 0 || a + b > n || order.len() != n {
            return Ok(None);
        }
        let mut side_of = vec![SEPARATOR; n];
        order[..a].iter().for_each(|&i| side_of[i] = 0);
        order[a..a + b].iter().for_each(|&i| side_of[i] = 1);
        let separator = order[a + b..].to_vec();
        let mut separator_index = vec![usize::MAX; n];
        for (k, &i) in separator.iter().enumerate() {
            separator_index[i] = k;
        }
        let mut separator_entries = Vec::new();
        for &j in &separator {
            for p in pattern.col_range(j) {
                let i = pattern.row_idx()[p];
                if i >= j && side_of[i] == SEPARATOR {
                    separator_entries.push((p, separator_index[i], separator_index[j]));
                }
            }
        }
        let by_side =
            |side| SidePlan::new(pattern, order, &side_of, side, &separator_index, kernel);
        let (side_a, side_b) = join(|| by_side(0), || by_side(1));
        let (Some(side_a), Some(side_b)) = (side_a?, side_b?) else {
            return Ok(None);
        };
        Ok(Some(Self {
            n,
            sides: [side_a, side_b],
            separator,
            separator_entries,
        }))
    }

    /// An upper bound of the multiply-subtract count of the whole matrix's
    /// factorization in the plan's order (the quantity of
    /// [`factor_count`](crate::factor_count)): each side's own columns as faer stores
    /// them (exact, or more where its relaxed supernodes hold zeros; they are the
    /// whole factor's columns, since no entry joins the sides and the separator is
    /// eliminated last), and the separator's columns taken dense.
    pub(super) fn multiply_subtracts_bound(&self) -> f64 {
        let sides: f64 = self
            .sides
            .iter()
            .map(|side| stored_multiply_subtracts(&side.symbolic, side.own_in_order.len()))
            .sum();
        let dense: f64 = (0..self.separator.len())
            .map(column_multiply_subtracts)
            .sum();
        sides + dense
    }

    /// The factorization of the planned pattern: both sides' storage written at once
    /// (see [`Factor::build`]).
    pub(super) fn into_factors<T: Scalar>(self) -> Result<TwoDomains<T>, SolveError> {
        let [side_a, side_b] = self.sides;
        let (side_a, side_b) = join(|| side_a.into_factor(), || side_b.into_factor());
        Ok(TwoDomains {
            n: self.n,
            sides: [side_a?, side_b?],
            separator: self.separator,
            separator_entries: self.separator_entries,
            schur: None,
        })
    }
}

impl<T: Scalar> TwoDomains<T> {
    /// [`TwoDomainsPlan::new`], then the storage of both sides' factors.
    pub(super) fn new(
        pattern: SymbolicSparseColMatRef<'_, usize>,
        order: &[usize],
        halves: [usize; 2],
        kernel: Kernel,
    ) -> Result<Option<Self>, SolveError> {
        TwoDomainsPlan::new(pattern, order, halves, kernel)?
            .map(TwoDomainsPlan::into_factors)
            .transpose()
    }

    /// Numeric factorization of `matrix` (the pattern given to [`new`](Self::new)): the
    /// two sides at once, then the separator's Schur complement. The pivot test is
    /// [`Factor::factorize`]'s, the separator's pivots taken from the dense factor;
    /// failures name rows of `matrix`.
    pub(super) fn factorize(
        &mut self,
        matrix: SparseColMatRef<'_, usize, T>,
        tolerance: f64,
    ) -> Result<(), FactorFailure> {
        self.schur = None;
        let values = matrix.val();
        let [side_a, side_b] = &mut self.sides;
        let (a, b) = join(
            || side_a.factorize(values, tolerance),
            || side_b.factorize(values, tolerance),
        );
        a?;
        b?;
        let s = self.separator.len();
        let mut schur = &self.sides[0].schur_part + &self.sides[1].schur_part;
        let mut diagonal = vec![0.0; s];
        for &(p, r, c) in &self.separator_entries {
            let v = values[p];
            schur[(r, c)] -= v;
            if r == c {
                diagonal[r] = v.real();
            } else {
                schur[(c, r)] -= v.conjugate();
            }
        }
        let llt = Llt::new(schur.as_ref(), Side::Lower).map_err(|error| match error {
            LltError::NonPositivePivot { index } => FactorFailure::NonPositivePivot {
                index: self.separator[index.min(s.saturating_sub(1))],
            },
        })?;
        let l = llt.L();
        let worst = (0..s)
            .map(|k| (k, l[(k, k)].norm_sqr() / diagonal[k]))
            .min_by(|x, y| x.1.total_cmp(&y.1));
        if let Some((k, ratio)) = worst
            && ratio < tolerance
        {
            return Err(FactorFailure::SmallPivot {
                index: self.separator[k],
                ratio,
            });
        }
        self.schur = Some(llt);
        Ok(())
    }

    /// Solves `M X = B` in place with the last successful factorization (module docs,
    /// steps 1-3).
    pub(super) fn solve_in_place(&mut self, mut rhs: MatMut<'_, T>) -> Result<(), SolveError> {
        let schur = self.schur.as_ref().ok_or(SolveError::NotFactored)?;
        if rhs.nrows() != self.n {
            return Err(SolveError::Length {
                what: "the rows of the right-hand side",
                expected: self.n,
                got: rhs.nrows(),
            });
        }
        let k = rhs.ncols();
        let b = rhs.as_ref();
        let [side_a, side_b] = &mut self.sides;
        // Step 1: the forward solves, g = M_SA M_AA^-1 b_A.
        let (forward_a, forward_b) = join(|| side_a.forward(b), || side_b.forward(b));
        let ((y_a, g_a), (y_b, g_b)) = (forward_a?, forward_b?);
        // Step 2: the separator.
        let mut x_s = Mat::<T>::from_fn(self.separator.len(), k, |r, c| b[(self.separator[r], c)]);
        x_s -= &g_a;
        x_s -= &g_b;
        schur.solve_in_place(x_s.as_mut());
        // Step 3: the backward solves under the separator's solution.
        let (x_a, x_b) = join(
            || side_a.backward(y_a, x_s.as_ref()),
            || side_b.backward(y_b, x_s.as_ref()),
        );
        let (x_a, x_b) = (x_a?, x_b?);
        for (side, x) in [(&*side_a, &x_a), (&*side_b, &x_b)] {
            for (l, &i) in side.own_in_order.iter().enumerate() {
                for c in 0..k {
                    rhs[(i, c)] = x[(l, c)];
                }
            }
        }
        for (r, &i) in self.separator.iter().enumerate() {
            for c in 0..k {
                rhs[(i, c)] = x_s[(r, c)];
            }
        }
        Ok(())
    }
}

impl SidePlan {
    /// The submatrix of side `side` (`0` or `1`) and the separator, and its symbolic
    /// factorization in `order` restricted to it (one thread); `None` when an entry of
    /// `pattern` joins the two sides or the factorization would not eliminate the
    /// separator last, in its own order.
    ///
    /// The submatrix is stored numbered in that order (its lower triangle: an entry of
    /// `M`'s lower triangle that falls above the diagonal there is stored conjugated at
    /// the mirror position), so that faer factors it as numbered and its numeric phase
    /// reads the values as they are instead of permuting a copy at every factorization.
    fn new(
        pattern: SymbolicSparseColMatRef<'_, usize>,
        order: &[usize],
        side_of: &[u8],
        side: u8,
        separator_index: &[usize],
        kernel: Kernel,
    ) -> Result<Option<Self>, SolveError> {
        let other = 1 - side;
        let n = pattern.nrows();
        // The global order lists this side's rows, then the separator's.
        let rows: Vec<usize> = order
            .iter()
            .copied()
            .filter(|&i| side_of[i] != other)
            .collect();
        let mut local = vec![usize::MAX; n];
        for (l, &i) in rows.iter().enumerate() {
            local[i] = l;
        }
        let m = rows.len();
        // The entries (column, row, source: the position among M's values, with
        // CONJUGATED) of the lower triangle in the local numbering, placed column by
        // column.
        let mut entries = Vec::new();
        for &j in &rows {
            for p in pattern.col_range(j) {
                let i = pattern.row_idx()[p];
                if side_of[i] == other {
                    if side_of[j] == side {
                        return Ok(None);
                    }
                    // An entry of the other side's block of a separator column.
                    continue;
                }
                if i < j {
                    // Above M's diagonal: not read.
                    continue;
                }
                let (a, b) = (local[i], local[j]);
                // Positions from CONJUGATED on cannot be packed (matrices of more than
                // 2^31 stored values): the caller factors the whole.
                let Ok(p) = u32::try_from(p) else {
                    return Ok(None);
                };
                if p >= CONJUGATED {
                    return Ok(None);
                }
                entries.push(if a >= b {
                    (b, a, p)
                } else {
                    (a, b, p | CONJUGATED)
                });
            }
        }
        let mut col_ptr = vec![0usize; m + 1];
        for &(c, ..) in &entries {
            col_ptr[c + 1] += 1;
        }
        for c in 0..m {
            col_ptr[c + 1] += col_ptr[c];
        }
        let mut next = col_ptr[..m].to_vec();
        let mut cells = vec![(0usize, 0u32); entries.len()];
        for (c, r, source) in entries {
            cells[next[c]] = (r, source);
            next[c] += 1;
        }
        for c in 0..m {
            cells[col_ptr[c]..col_ptr[c + 1]].sort_unstable_by_key(|&(r, _)| r);
        }
        let row_idx = cells.iter().map(|&(r, _)| r).collect();
        let source: Vec<u32> = cells.iter().map(|&(_, source)| source).collect();
        let sub = SymbolicSparseColMat::new_checked(m, m, col_ptr, None, row_idx);
        let upper = sub.as_ref().transpose().to_col_major()?;
        let symbolic = analyse(
            upper.as_ref(),
            Side::Upper,
            SymmetricOrdering::Identity,
            kernel,
        )?;
        drop(upper);
        let s = rows.iter().filter(|&&i| side_of[i] != side).count();
        let first = m - s;
        // The separator comes last in `order`, in its own numbering; faer must keep it
        // there.
        if (0..s).any(|r| {
            let l = eliminated(&symbolic, first + r);
            l >= m || side_of[rows[l]] == side || separator_index[rows[l]] != r
        }) {
            return Ok(None);
        }
        let own_in_order = (0..first).map(|k| rows[eliminated(&symbolic, k)]).collect();
        Ok(Some(Self {
            rows,
            own_in_order,
            pattern: sub,
            source,
            symbolic,
        }))
    }

    /// The side's factorization: the factor's storage written now (one thread).
    fn into_factor<T: Scalar>(self) -> Result<SideFactor<T>, SolveError> {
        let s = self.rows.len() - self.own_in_order.len();
        Ok(SideFactor {
            values: vec![T::from_f64(0.0); self.source.len()],
            factor: Factor::with_storage(self.symbolic, Par::Seq)?,
            rows: self.rows,
            own_in_order: self.own_in_order,
            pattern: self.pattern,
            source: self.source,
            trailing: Mat::zeros(s, s),
            schur_part: Mat::zeros(s, s),
        })
    }
}

impl<T: Scalar> SideFactor<T> {
    /// Factors `M_A` from the values of `M`, then forms `T_A = L_A L_A^H` from the
    /// factor's last `|S|` columns (the separator, in its own order).
    fn factorize(&mut self, values: &[T], tolerance: f64) -> Result<(), FactorFailure> {
        for (v, &source) in self.values.iter_mut().zip(&self.source) {
            let value = values[(source & !CONJUGATED) as usize];
            *v = if source & CONJUGATED != 0 {
                value.conjugate()
            } else {
                value
            };
        }
        let matrix = SparseColMatRef::new(self.pattern.as_ref(), &self.values);
        let rows = &self.rows;
        self.factor
            .factorize(matrix, tolerance)
            .map_err(|failure| match failure {
                FactorFailure::NonPositivePivot { index } => {
                    FactorFailure::NonPositivePivot { index: rows[index] }
                }
                FactorFailure::SmallPivot { index, ratio } => FactorFailure::SmallPivot {
                    index: rows[index],
                    ratio,
                },
            })?;
        self.trailing = self.factor.trailing_factor(self.trailing.nrows());
        let l = &self.trailing;
        // Only the lower triangle of the product is computed (half the work), then
        // mirrored: T_A is Hermitian.
        triangular::matmul(
            self.schur_part.as_mut(),
            BlockStructure::TriangularLower,
            Accum::Replace,
            l.as_ref(),
            BlockStructure::TriangularLower,
            l.adjoint(),
            BlockStructure::TriangularUpper,
            T::from_f64(1.0),
            Par::Seq,
        );
        let t = &mut self.schur_part;
        for c in 1..t.ncols() {
            for r in 0..c {
                t[(r, c)] = t[(c, r)].conjugate();
            }
        }
        Ok(())
    }

    /// Step 1 for this side: `y = L^-1 P [b_A; 0]` (the side's rows of `b`, zero on
    /// the separator; `y` in elimination order) and `g_A = M_SA M_AA^-1 b_A`, which is
    /// `L_21 y_1 = -L_A y_S` since the separator rows of `L y = P [b_A; 0]` read
    /// `L_21 y_1 + L_A y_S = 0`.
    fn forward(&mut self, b: MatRef<'_, T>) -> Result<(Mat<T>, Mat<T>), SolveError> {
        let (own, s, k) = (self.own_in_order.len(), self.trailing.nrows(), b.ncols());
        let mut y = Mat::<T>::from_fn(own + s, k, |l, c| {
            self.own_in_order
                .get(l)
                .map_or(T::from_f64(0.0), |&i| b[(i, c)])
        });
        self.factor.lower_solve_in_place(y.as_mut())?;
        let mut g = Mat::<T>::zeros(s, k);
        triangular::matmul(
            g.as_mut(),
            BlockStructure::Rectangular,
            Accum::Replace,
            self.trailing.as_ref(),
            BlockStructure::TriangularLower,
            y.as_ref().subrows(own, s),
            BlockStructure::Rectangular,
            T::from_f64(-1.0),
            Par::Seq,
        );
        Ok((y, g))
    }

    /// Step 3 for this side, from step 1's `y`: with the separator's solution `x_S`,
    /// the separator rows of the forward solve of `M_A [x_A; x_S] = [b_A; T_A x_S + g_A]`
    /// are `L_A^H x_S` (the rest is `y_1` again), and the backward solve gives `x_A`,
    /// returned in elimination order (the rows of [`SideFactor::own_in_order`]).
    fn backward(&mut self, mut y: Mat<T>, x_s: MatRef<'_, T>) -> Result<Mat<T>, SolveError> {
        let own = self.own_in_order.len();
        let s = self.trailing.nrows();
        triangular::matmul(
            y.as_mut().subrows_mut(own, s),
            BlockStructure::Rectangular,
            Accum::Replace,
            self.trailing.adjoint(),
            BlockStructure::TriangularUpper,
            x_s,
            BlockStructure::Rectangular,
            T::from_f64(1.0),
            Par::Seq,
        );
        self.factor.lower_adjoint_solve_in_place(y.as_mut())?;
        Ok(y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::factor_count;
    use crate::ordering::dissected;
    use faer::sparse::{SparseColMat, Triplet};
    use num_complex::Complex64;

    /// The lower triangle of a Hermitian matrix on the `k x k` triangulated grid:
    /// `-w_e` on each edge `e` (complex, `|w_e| <= 1`, pointing in varied directions),
    /// `shift + sum |w_e|` on the diagonal, so positive definite for `shift > 0` and
    /// singular (the constant vector's rotations aside) for `shift = 0` with real
    /// weights. `components` copies side by side without an edge between them.
    fn grid(
        k: usize,
        shift: f64,
        complex: bool,
        components: usize,
    ) -> SparseColMat<usize, Complex64> {
        let per = k * k;
        let n = per * components;
        let mut diagonal = vec![shift; n];
        let mut triplets = Vec::new();
        let mut seed = 1u64;
        for c in 0..components {
            let id = |i: usize, j: usize| c * per + i + k * j;
            for j in 0..k {
                for i in 0..k {
                    for (di, dj) in [(1, 0), (0, 1), (1, 1)] {
                        if i + di < k && j + dj < k {
                            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
                            let t = (seed >> 33) as f64 / (1u64 << 31) as f64;
                            let w = if complex {
                                Complex64::from_polar(0.5 + 0.5 * t, 6.0 * t)
                            } else {
                                Complex64::new(0.5 + 0.5 * t, 0.0)
                            };
                            let (a, b) = (id(i, j), id(i + di, j + dj));
                            diagonal[a] += w.norm();
                            diagonal[b] += w.norm();
                            triplets.push(Triplet::new(b, a, -w));
                        }
                    }
                }
            }
        }
        triplets.extend((0..n).map(|i| Triplet::new(i, i, Complex64::new(diagonal[i], 0.0))));
        SparseColMat::try_new_from_triplets(n, n, &triplets).unwrap()
    }

    /// The two-domain factorization of `m` in its nested-dissection order.
    fn split(m: &SparseColMat<usize, Complex64>) -> TwoDomains<Complex64> {
        split_with(m, Kernel::Auto)
    }

    /// [`split`] with the sides analysed for `kernel`.
    fn split_with(m: &SparseColMat<usize, Complex64>, kernel: Kernel) -> TwoDomains<Complex64> {
        let dissection = dissected(m.symbolic()).unwrap();
        let halves = dissection.halves.expect("a split");
        TwoDomains::new(m.symbolic(), &dissection.order, halves, kernel)
            .unwrap()
            .expect("the split separates")
    }

    /// `max |M x - b| / max |b|` with `M` given by its lower triangle.
    fn residual(m: &SparseColMat<usize, Complex64>, x: &Mat<Complex64>, b: &Mat<Complex64>) -> f64 {
        let mut worst: f64 = 0.0;
        for c in 0..b.ncols() {
            let mut r: Vec<Complex64> = (0..b.nrows()).map(|i| -b[(i, c)]).collect();
            for j in 0..m.ncols() {
                for (i, v) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
                    r[i] += v * x[(j, c)];
                    if i != j {
                        r[j] += v.conj() * x[(i, c)];
                    }
                }
            }
            worst = r.iter().map(|z| z.norm()).fold(worst, f64::max);
        }
        worst / b.norm_max()
    }

    #[test]
    fn the_plans_count_bounds_the_whole_factors_closely() {
        // The exact count of the whole matrix's factor in the dissection's order, against
        // the plan's: the sides' stored factors and the separator taken dense.
        let m = grid(120, 0.05, true, 1);
        let dissection = dissected(m.symbolic()).unwrap();
        let halves = dissection.halves.expect("a split");
        let plan = TwoDomainsPlan::new(m.symbolic(), &dissection.order, halves, Kernel::Auto)
            .unwrap()
            .expect("the split separates");
        let exact = factor_count(m.symbolic(), &dissection.order)
            .unwrap()
            .multiply_subtracts;
        let bound = plan.multiply_subtracts_bound();
        assert!(
            (exact..1.1 * exact).contains(&bound),
            "bound {bound:e}, exact {exact:e}"
        );
    }

    #[test]
    fn the_two_sides_and_the_separator_solve_a_hermitian_system() {
        let m = grid(40, 0.05, true, 1);
        let mut two = split(&m);
        let (n, s) = (m.nrows(), two.separator.len());
        let [a, b] = [
            two.sides[0].own_in_order.len(),
            two.sides[1].own_in_order.len(),
        ];
        assert!(
            s > 0 && s < 120 && a + b + s == n,
            "sides {a}, {b}, separator {s}"
        );
        let rhs = Mat::from_fn(n, 3, |i, c| {
            Complex64::new((i * (c + 1)) as f64 % 7.0, c as f64 - 1.0)
        });
        // Twice, as iterative solvers refactor one pattern.
        for _ in 0..2 {
            two.factorize(m.as_ref(), 1e-12).unwrap();
            let mut x = rhs.clone();
            two.solve_in_place(x.as_mut()).unwrap();
            let r = residual(&m, &x, &rhs);
            assert!(r < 1e-12, "residual {r:e}");
        }
    }

    #[test]
    fn sides_with_simplicial_and_supernodal_factors_solve_alike() {
        // faer factors sparse small sides column by column (simplicial) and larger ones
        // by supernodes, and small ones by supernodes when asked; the forward and
        // backward halves of both kernels are used.
        for (k, kernel, supernodal) in [
            (17, Kernel::Auto, false),
            (17, Kernel::Supernodal, true),
            (150, Kernel::Auto, true),
        ] {
            let m = grid(k, 0.05, true, 1);
            let mut two = split_with(&m, kernel);
            assert!(
                two.sides
                    .iter()
                    .all(|side| side.factor.is_supernodal() == supernodal),
                "grid {k}"
            );
            two.factorize(m.as_ref(), 1e-12).unwrap();
            let rhs = Mat::from_fn(m.nrows(), 2, |i, c| {
                Complex64::new(1.0 + (i % 5) as f64, c as f64 - (i % 3) as f64)
            });
            let mut x = rhs.clone();
            two.solve_in_place(x.as_mut()).unwrap();
            let r = residual(&m, &x, &rhs);
            assert!(r < 1e-12, "grid {k}: residual {r:e}");
        }
    }

    #[test]
    fn two_components_are_solved_without_a_separator() {
        let m = grid(12, 0.5, false, 2);
        let mut two = split(&m);
        assert!(two.separator.is_empty());
        two.factorize(m.as_ref(), 1e-12).unwrap();
        let rhs = Mat::from_fn(m.nrows(), 1, |i, _| Complex64::new(1.0 + i as f64, -2.0));
        let mut x = rhs.clone();
        two.solve_in_place(x.as_mut()).unwrap();
        assert!(residual(&m, &x, &rhs) < 1e-12);
    }

    #[test]
    fn a_singular_matrix_fails_at_a_row_of_the_matrix() {
        // Real weights and no shift: the constant vector is in the kernel.
        let m = grid(30, 0.0, false, 1);
        let mut two = split(&m);
        let mut x = Mat::<Complex64>::zeros(m.nrows(), 1);
        assert!(matches!(
            two.solve_in_place(x.as_mut()),
            Err(SolveError::NotFactored)
        ));
        match two.factorize(m.as_ref(), 1e-10) {
            Err(FactorFailure::SmallPivot { index, ratio }) => {
                assert!(index < m.nrows() && ratio < 1e-10, "{index} {ratio:e}");
            }
            Err(FactorFailure::NonPositivePivot { index }) => assert!(index < m.nrows()),
            Ok(()) => panic!("a singular matrix passed the pivot test"),
        }
        assert!(matches!(
            two.solve_in_place(x.as_mut()),
            Err(SolveError::NotFactored)
        ));
    }

    #[test]
    fn a_split_with_an_entry_between_the_sides_is_declined() {
        let m = grid(20, 0.5, false, 1);
        // Rows in plain order cut after the first row of the grid: rows 0 and 20 are
        // joined by an edge, but 0 is on one side and 20 on the other.
        let order: Vec<usize> = (0..m.nrows()).collect();
        let two = TwoDomains::<Complex64>::new(m.symbolic(), &order, [20, 20], Kernel::Auto);
        assert!(two.unwrap().is_none());
    }
}
