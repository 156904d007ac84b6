//! The normal equations of a weighted least-squares problem through a [`DofMap`],
//! assembled by precomputed scatter maps instead of sparse-sparse products.
//!
//! # The formulas
//!
//! With `x = K y + x0`, `B = A K` (`m x n`), `W = diag(w)` and `r = b - A x0`:
//!
//! ```text
//! N = B^H W B = sum_i w_i b_i^H b_i,      N[c, d] = sum_i w_i conj(B[i, c]) B[i, d],
//! g = B^H W r = sum_i w_i r_i b_i^H,      g[c]    = sum_i w_i conj(B[i, c]) r_i,
//! ```
//!
//! `b_i` the i-th row of `B`. Only the lower triangle of `N` (`c >= d`) is formed: the
//! Cholesky factorization reads nothing else (faer's symbolic analysis orders the
//! pattern of `N + N^H`, its numeric phase skips entries above the diagonal).
//!
//! # `B` without a product
//!
//! Row `l` of `K` (component `c` of node `i`) has one entry `K[l, j]` per term of node `i`
//! that stores component `c` (module docs of [`crate::dof`]): none for a fixed node, one
//! for the maps of `DofConstraints`, a few in general (a node in a tangent plane of R^3,
//! a node moved by a shared offset). So
//!
//! ```text
//! B[i, j] = sum_l A[i, l] K[l, j]:
//! ```
//!
//! each entry `A[i, l]` adds `A[i, l] K[l, j]` into the entry `B[i, j]` of every `j` of
//! row `l` of `K`, and into none when node unknown `l` is fixed. Several products add into
//! one entry of `B` when their columns of `A` share a reduced unknown (shared nodes, the
//! components of a sliding node, a shared offset). The symbolic phase records, for every
//! pair (entry of `A`, entry of its row of `K`), in the order of the numeric pass (columns
//! `l` of `A`, their entries, then the entries of row `l` of `K`), the entry of `B` it
//! adds into (`b_target`); the numeric refill of `B` is one pass over the values of `A`.
//! The values of `K` are copied row by row at construction (the solver's map does not
//! change).
//!
//! # `N` without a product
//!
//! `B` is stored row by row, each row's entries sorted by reduced column
//! `c_0 < c_1 < ... < c_{r-1}`. Row `i` adds `w_i conj(B[i, c_p]) B[i, c_q]` into
//! `N[c_p, c_q]` for `p >= q` (lower triangle), so the symbolic phase records, for every
//! row and every such pair, the position of `(c_p, c_q)` among the stored values of
//! `N`, at index `p (p + 1) / 2 + q` of the row's block of `pairs`. The numeric phase
//! is then `N[pos] += w_i conj(b_p) b_q` over consecutive positions, and `g` is
//! accumulated in the same pass.
//!
//! The positions of a row depend only on its columns, so a row with the same columns
//! as the row before it shares that row's block (the two real rows of one complex row
//! of a real block form always do): the table holds one block per run of equal rows.
//!
//! The pattern of `N` is built column by column: column `d` of the lower triangle is
//! the union, over the rows `i` having an entry at `d`, of the columns `c >= d` of row
//! `i`, deduplicated with a marker array and sorted (the diagonal comes first). The same
//! sweep fills the positions of the pairs whose smaller column is `d`, through a map
//! from row index to position within the column being built.
//!
//! The indices of the maps are stored as `u32` when they fit (fewer than `2^32` rows,
//! entries of `A` and pairs), which halves their memory and the bandwidth of the
//! numeric phase.

use super::SolveError;
use crate::dof::{DofMap, DofScalar};
use beltrami_mesh::VertexId;
use faer::sparse::{FaerError, SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};

/// An index of the scatter maps.
trait Index: Copy + Ord {
    /// `i` as an index; the caller has checked that it fits (see [`fits_u32`]).
    fn new(i: usize) -> Self;
    fn get(self) -> usize;
}

impl Index for u32 {
    #[inline]
    fn new(i: usize) -> Self {
        debug_assert!(i <= u32::MAX as usize);
        i as u32
    }

    #[inline]
    fn get(self) -> usize {
        self as usize
    }
}

impl Index for usize {
    #[inline]
    fn new(i: usize) -> Self {
        i
    }

    #[inline]
    fn get(self) -> usize {
        self
    }
}

/// True if every index stored in the maps, bounded by `bound`, fits in a `u32`.
fn fits_u32(bound: usize) -> bool {
    bound <= u32::MAX as usize
}

/// `vec![value; len]`, reporting a failed allocation instead of aborting (the maps of a
/// large mesh take hundreds of megabytes).
fn try_vec<X: Clone>(len: usize, value: X) -> Result<Vec<X>, FaerError> {
    let mut v = Vec::new();
    v.try_reserve_exact(len)
        .map_err(|_| FaerError::OutOfMemory)?;
    v.resize(len, value);
    Ok(v)
}

/// The scatter maps of one pattern of `A` (module docs).
struct Maps<I> {
    /// For each pair (entry of `A`, entry of its row of `K`), in the order of the numeric
    /// pass (module docs), the entry of `B` it adds into.
    b_target: Vec<I>,
    /// `B` row by row (`m + 1` pointers) ...
    b_row_ptr: Vec<I>,
    /// ... and the reduced column of each entry, increasing within a row.
    b_col: Vec<I>,
    /// For each row of `B`, the start of its block of `pairs` (shared by equal rows).
    pair_start: Vec<I>,
    /// Positions in the values of `N` of the pairs `(p, q)`, `p >= q`, of each block,
    /// at `p (p + 1) / 2 + q`.
    pairs: Vec<I>,
}

/// The two index widths of [`Maps`].
enum AnyMaps {
    Narrow(Maps<u32>),
    Wide(Maps<usize>),
}

/// `N = B^H W B` (lower triangle) and `g = B^H W r`, with their symbolic structure.
pub(super) struct NormalEquations<T: DofScalar> {
    /// `K` row by row: the entries of row `l` (column `l` of `A`) are
    /// `k_values[k_row_ptr[l]..k_row_ptr[l + 1]]`, in increasing column order.
    k_row_ptr: Vec<usize>,
    /// The reduced column of each entry of `k_values`.
    k_col: Vec<usize>,
    k_values: Vec<T>,
    maps: AnyMaps,
    /// Values of `B`, row by row.
    b_values: Vec<T>,
    /// Lower triangle of `N` (`n x n`), columns sorted, diagonal first.
    pattern: SymbolicSparseColMat<usize>,
    values: Vec<T>,
}

impl<T: DofScalar> NormalEquations<T> {
    /// Symbolic phase for matrices with the pattern `a` (`m x dofs.full_len()`, checked
    /// by the caller). Errors: [`SolveError::Unconstrained`] if a reduced unknown appears
    /// in no row of `A`, [`SolveError::Faer`] on allocation or index overflow.
    pub(super) fn new(
        a: SymbolicSparseColMatRef<'_, usize>,
        dofs: &DofMap<T>,
    ) -> Result<Self, SolveError> {
        Self::build(a, dofs, true)
    }

    /// Replaces the values of `K` by those of `dofs`, whose `K` must have the pattern of
    /// the map the equations were built with (same reduced unknowns, same entries):
    /// the scatter maps and the pattern of `N` stay. Returns false, changing nothing,
    /// when the patterns differ.
    pub(super) fn set_k(&mut self, dofs: &DofMap<T>) -> bool {
        let k = dofs.k();
        if k.row_idx().len() != self.k_values.len() || self.k_row_ptr.len() != k.nrows() + 1 {
            return false;
        }
        let mut next = self.k_row_ptr[..k.nrows()].to_vec();
        let mut values = vec![T::from_f64(0.0); self.k_values.len()];
        for j in 0..k.ncols() {
            for (&l, &coef) in k.row_idx_of_col_raw(j).iter().zip(k.val_of_col(j)) {
                if next[l] >= self.k_row_ptr[l + 1] || self.k_col[next[l]] != j {
                    return false;
                }
                values[next[l]] = coef;
                next[l] += 1;
            }
        }
        if next[..] != self.k_row_ptr[1..] {
            return false;
        }
        self.k_values = values;
        true
    }

    /// [`new`](Self::new), with `u32` indices only if `narrow` (tests build both
    /// widths).
    fn build(
        a: SymbolicSparseColMatRef<'_, usize>,
        dofs: &DofMap<T>,
        narrow: bool,
    ) -> Result<Self, SolveError> {
        let (m, n) = (a.nrows(), dofs.reduced_len());
        // K row by row (a transpose of its columns, each row's columns increasing).
        let k = dofs.k();
        let mut k_row_ptr = vec![0usize; a.ncols() + 1];
        for &l in k.row_idx() {
            k_row_ptr[l + 1] += 1;
        }
        for l in 0..a.ncols() {
            k_row_ptr[l + 1] += k_row_ptr[l];
        }
        let mut next = k_row_ptr[..a.ncols()].to_vec();
        let zero = T::from_f64(0.0);
        let mut k_col = vec![0usize; k.row_idx().len()];
        let mut k_values = vec![zero; k.row_idx().len()];
        for j in 0..n {
            for (&l, &coef) in k.row_idx_of_col_raw(j).iter().zip(k.val_of_col(j)) {
                k_col[next[l]] = j;
                k_values[next[l]] = coef;
                next[l] += 1;
            }
        }
        drop(next);
        let k_rows = KRows {
            ptr: &k_row_ptr,
            col: &k_col,
        };
        // Products of each row of A that reach B: they bound the entries of B, the
        // targets and the pairs of each row, hence every index the maps store.
        let mut row_len = vec![0usize; m];
        for l in 0..a.ncols() {
            let r = k_rows.len(l);
            if r > 0 {
                for i in a.row_idx_of_col(l) {
                    row_len[i] += r;
                }
            }
        }
        let pair_bound = row_len
            .iter()
            .try_fold(0usize, |sum, &r| sum.checked_add(r.checked_mul(r + 1)? / 2))
            .ok_or(FaerError::IndexOverflow)?;
        let bound = pair_bound.max(a.row_idx().len()).max(m).max(n);
        let (maps, pattern) = if narrow && fits_u32(bound) {
            let (maps, pattern) = Maps::<u32>::new(a, k_rows, &row_len, dofs)?;
            (AnyMaps::Narrow(maps), pattern)
        } else {
            let (maps, pattern) = Maps::<usize>::new(a, k_rows, &row_len, dofs)?;
            (AnyMaps::Wide(maps), pattern)
        };
        let b_len = match &maps {
            AnyMaps::Narrow(maps) => maps.b_col.len(),
            AnyMaps::Wide(maps) => maps.b_col.len(),
        };
        Ok(Self {
            k_row_ptr,
            k_col,
            k_values,
            maps,
            b_values: try_vec(b_len, zero)?,
            values: try_vec(pattern.row_idx().len(), zero)?,
            pattern,
        })
    }

    /// The pattern of the lower triangle of `N`.
    pub(super) fn pattern(&self) -> SymbolicSparseColMatRef<'_, usize> {
        self.pattern.as_ref()
    }

    /// `N` as last assembled (lower triangle).
    pub(super) fn matrix(&self) -> SparseColMatRef<'_, usize, T> {
        SparseColMatRef::new(self.pattern.as_ref(), &self.values)
    }

    /// Numeric phase: refills `B` from `a` (the pattern given to [`new`](Self::new)),
    /// then `N` and `rhs = B^H W residual` (`residual = b - A x0`, `m`; `rhs`, `n`).
    pub(super) fn assemble(
        &mut self,
        a: SparseColMatRef<'_, usize, T>,
        weights: Option<&[f64]>,
        residual: &[T],
        rhs: &mut [T],
    ) {
        let out = Output {
            b_values: &mut self.b_values,
            values: &mut self.values,
            rhs,
        };
        let k = (&self.k_row_ptr[..], &self.k_values[..]);
        match &self.maps {
            AnyMaps::Narrow(maps) => maps.assemble(k, a, weights, residual, out),
            AnyMaps::Wide(maps) => maps.assemble(k, a, weights, residual, out),
        }
    }
}

/// The lower triangle (diagonal included, each column's rows increasing) of the pattern
/// of the normal equations `K^H A^H W A K` of a matrix `A` whose rows each couple the
/// nodes of one cell (the quadrature points of a face couple all its vertices), built
/// without `A`: an entry `(c, d)`, `c >= d`, wherever reduced unknowns `c` and `d` are
/// unknowns of nodes of one cell (a node's unknowns are those of its terms in `dofs`;
/// a fixed node has none). Cheap enough to compute, with the symbolic factorization of
/// the pattern, on another thread while `A` is assembled
/// ([`super::LeastSquaresSolver::with_planned`]).
///
/// Errors: [`SolveError::Length`] for a node beyond `dofs`' nodes.
pub fn normal_pattern_of_cells<T: DofScalar, C: IntoIterator<Item = VertexId>>(
    cells: impl Iterator<Item = C> + Clone,
    dofs: &DofMap<T>,
) -> Result<SymbolicSparseColMat<usize>, SolveError> {
    let n = dofs.reduced_len();
    // The reduced unknowns of every node, looked up once instead of once per cell
    // corner: those of node `v` are `node_unknowns[node_ptr[v]..node_ptr[v + 1]]`.
    let mut node_ptr = Vec::with_capacity(dofs.n_nodes() + 1);
    let mut node_unknowns = Vec::with_capacity(n);
    node_ptr.push(0);
    for v in 0..dofs.n_nodes() {
        if let Ok(terms) = dofs.terms(VertexId::from_usize(v)) {
            node_unknowns.extend(terms.filter_map(|t| dofs.term(t).map(|term| term.dof)));
        }
        node_ptr.push(node_unknowns.len());
    }
    let mut unknowns = Vec::new();
    // Each cell's couplings `(c, d)`, `c >= d`, go to column `d`: counted in a first
    // pass over the cells, written in a second (no list of pairs is kept), then each
    // column's rows are sorted and deduplicated in place.
    let mut visit = |cells: &mut dyn Iterator<Item = C>,
                     each: &mut dyn FnMut(usize, usize)|
     -> Result<(), SolveError> {
        for cell in cells {
            unknowns.clear();
            for node in cell {
                let v = node.idx();
                if v >= dofs.n_nodes() {
                    return Err(SolveError::Length {
                        what: "the node index of a cell",
                        expected: dofs.n_nodes(),
                        got: v,
                    });
                }
                unknowns.extend_from_slice(&node_unknowns[node_ptr[v]..node_ptr[v + 1]]);
            }
            for (p, &c) in unknowns.iter().enumerate() {
                for &d in &unknowns[..=p] {
                    each(c.min(d), c.max(d));
                }
            }
        }
        Ok(())
    };
    let mut col_ptr = vec![0usize; n + 1];
    visit(&mut cells.clone(), &mut |col, _| col_ptr[col + 1] += 1)?;
    for j in 0..n {
        col_ptr[j + 1] += col_ptr[j];
    }
    let mut next = col_ptr[..n].to_vec();
    let mut rows = vec![0usize; col_ptr[n]];
    visit(&mut cells.clone(), &mut |col, row| {
        rows[next[col]] = row;
        next[col] += 1;
    })?;
    drop(next);
    // A column's distinct rows are written from its new start, which never passes its
    // old one.
    let mut end = 0;
    for j in 0..n {
        let column = col_ptr[j]..col_ptr[j + 1];
        rows[column.clone()].sort_unstable();
        col_ptr[j] = end;
        let start = end;
        for k in column {
            let i = rows[k];
            if end == start || rows[end - 1] != i {
                rows[end] = i;
                end += 1;
            }
        }
    }
    col_ptr[n] = end;
    rows.truncate(end);
    Ok(SymbolicSparseColMat::new_checked(n, n, col_ptr, None, rows))
}

/// The pattern of `K` row by row: the columns of row `l` are `col[ptr[l]..ptr[l + 1]]`.
#[derive(Clone, Copy)]
struct KRows<'a> {
    ptr: &'a [usize],
    col: &'a [usize],
}

impl KRows<'_> {
    /// The reduced unknowns of row `l` of `K`.
    fn row(&self, l: usize) -> &[usize] {
        &self.col[self.ptr[l]..self.ptr[l + 1]]
    }

    /// The number of entries of row `l`.
    fn len(&self, l: usize) -> usize {
        self.ptr[l + 1] - self.ptr[l]
    }
}

/// The arrays a numeric assembly writes.
struct Output<'a, T> {
    b_values: &'a mut [T],
    values: &'a mut [T],
    rhs: &'a mut [T],
}

/// The pattern of `B` row by row, as [`Maps::new`] builds it.
struct BRows<I> {
    /// `m + 1` pointers into `col`.
    row_ptr: Vec<I>,
    /// The reduced column of each entry, increasing within a row.
    col: Vec<I>,
    /// For each row, the start of its block of pairs (shared by a run of equal rows).
    pair_start: Vec<I>,
    /// True for the first row of each run of rows with equal columns (a leader).
    leader: Vec<bool>,
    /// The length of the blocks of pairs together: `r (r + 1) / 2` per leader of `r`
    /// entries.
    pair_len: usize,
}

/// `B` column by column, leaders only (the other rows repeat their columns): for each
/// reduced column `d`, the `(row, entry of B)` having it are
/// `entries[ptr[d]..ptr[d + 1]]`, rows increasing.
struct LeaderColumns<I> {
    ptr: Vec<usize>,
    entries: Vec<(I, I)>,
}

impl<I: Index> Maps<I> {
    /// The maps and the lower pattern of `N` (module docs). `k_rows` is the pattern of
    /// `K` row by row, `row_len[i]` the number of products (entry of row `i` of `A`, entry
    /// of its row of `K`).
    fn new<T: DofScalar>(
        a: SymbolicSparseColMatRef<'_, usize>,
        k_rows: KRows<'_>,
        row_len: &[usize],
        dofs: &DofMap<T>,
    ) -> Result<(Self, SymbolicSparseColMat<usize>), SolveError> {
        let n = dofs.reduced_len();
        let (a_row_end, b_col) = Self::product_columns(a, k_rows, row_len)?;
        let total = b_col.len();
        let b = Self::merge_rows(b_col, a_row_end)?;
        let b_target = Self::product_targets(a, k_rows, &b, total)?;
        let columns = Self::leader_columns(&b, dofs)?;
        let (pairs, pattern) = Self::lower_pattern(&b, &columns, n)?;
        Ok((
            Self {
                b_target,
                b_row_ptr: b.row_ptr,
                b_col: b.col,
                pair_start: b.pair_start,
                pairs,
            },
            pattern,
        ))
    }

    /// The reduced columns of the products reaching `B`, row by row: row `i`'s are
    /// `b_col[a_row_end[i] - row_len[i]..a_row_end[i]]`, unsorted and with repeats.
    /// Returns `(a_row_end, b_col)`.
    fn product_columns(
        a: SymbolicSparseColMatRef<'_, usize>,
        k_rows: KRows<'_>,
        row_len: &[usize],
    ) -> Result<(Vec<usize>, Vec<I>), SolveError> {
        let mut a_row_end = try_vec(a.nrows(), 0usize)?;
        let mut total = 0;
        for (end, &r) in a_row_end.iter_mut().zip(row_len) {
            total += r;
            *end = total;
        }
        let mut b_col = try_vec(total, I::new(0))?;
        let mut next: Vec<usize> = a_row_end.iter().zip(row_len).map(|(e, r)| e - r).collect();
        for l in 0..a.ncols() {
            for i in a.row_idx_of_col(l) {
                for &j in k_rows.row(l) {
                    b_col[next[i]] = I::new(j);
                    next[i] += 1;
                }
            }
        }
        Ok((a_row_end, b_col))
    }

    /// Sorts each row of `b_col` (ending at `a_row_end`) and merges its repeated columns
    /// in place, which leaves the columns of `B` row by row in the same buffer (merging
    /// only moves entries left). A row with the columns of the previous row shares its
    /// block of pairs; only the first row of a run (a leader) is swept later.
    fn merge_rows(mut b_col: Vec<I>, a_row_end: Vec<usize>) -> Result<BRows<I>, SolveError> {
        let m = a_row_end.len();
        let mut b_row_ptr = try_vec(m + 1, I::new(0))?;
        let mut pair_start = try_vec(m, I::new(0))?;
        let mut leader = vec![false; m];
        let (mut pair_len, mut read, mut end) = (0usize, 0usize, 0usize);
        for i in 0..m {
            let row_start = end;
            b_col[read..a_row_end[i]].sort_unstable();
            for t in read..a_row_end[i] {
                let j = b_col[t];
                if end == row_start || b_col[end - 1] != j {
                    b_col[end] = j;
                    end += 1;
                }
            }
            read = a_row_end[i];
            b_row_ptr[i + 1] = I::new(end);
            let previous = if i > 0 { b_row_ptr[i - 1].get() } else { 0 };
            if i > 0 && end > row_start && b_col[previous..row_start] == b_col[row_start..end] {
                pair_start[i] = pair_start[i - 1];
            } else {
                let r = end - row_start;
                pair_start[i] = I::new(pair_len);
                pair_len += r * (r + 1) / 2;
                leader[i] = true;
            }
        }
        drop(a_row_end);
        b_col.truncate(end);
        b_col.shrink_to_fit();
        Ok(BRows {
            row_ptr: b_row_ptr,
            col: b_col,
            pair_start,
            leader,
            pair_len,
        })
    }

    /// The entry of `B` each of the `total` products adds into: its reduced column
    /// within its row, in the order of the numeric pass.
    fn product_targets(
        a: SymbolicSparseColMatRef<'_, usize>,
        k_rows: KRows<'_>,
        b: &BRows<I>,
        total: usize,
    ) -> Result<Vec<I>, SolveError> {
        let mut b_target = try_vec(total, I::new(0))?;
        let mut target = 0;
        for l in 0..a.ncols() {
            for i in a.row_idx_of_col(l) {
                let (start, end) = (b.row_ptr[i].get(), b.row_ptr[i + 1].get());
                for &j in k_rows.row(l) {
                    let j = I::new(j);
                    let p = b.col[start..end].partition_point(|&c| c < j);
                    b_target[target] = I::new(start + p);
                    target += 1;
                }
            }
        }
        Ok(b_target)
    }

    /// `B` column by column, leaders only. Fails with [`SolveError::Unconstrained`] on
    /// the first reduced unknown no row of `B` has.
    fn leader_columns<T: DofScalar>(
        b: &BRows<I>,
        dofs: &DofMap<T>,
    ) -> Result<LeaderColumns<I>, SolveError> {
        let n = dofs.reduced_len();
        let m = b.leader.len();
        let mut bt_ptr = vec![0usize; n + 1];
        for i in (0..m).filter(|&i| b.leader[i]) {
            for c in &b.col[b.row_ptr[i].get()..b.row_ptr[i + 1].get()] {
                bt_ptr[c.get() + 1] += 1;
            }
        }
        if let Some(index) = (0..n).find(|&j| bt_ptr[j + 1] == 0) {
            return Err(SolveError::Unconstrained {
                index,
                node: dofs.dof_node(index).map(|v| v.idx()),
            });
        }
        for j in 0..n {
            bt_ptr[j + 1] += bt_ptr[j];
        }
        let mut bt = try_vec(bt_ptr[n], (I::new(0), I::new(0)))?;
        let mut next = bt_ptr[..n].to_vec();
        for i in (0..m).filter(|&i| b.leader[i]) {
            let (start, end) = (b.row_ptr[i].get(), b.row_ptr[i + 1].get());
            for (e, c) in (start..end).zip(&b.col[start..end]) {
                bt[next[c.get()]] = (I::new(i), I::new(e));
                next[c.get()] += 1;
            }
        }
        Ok(LeaderColumns {
            ptr: bt_ptr,
            entries: bt,
        })
    }

    /// The lower pattern of `N` (`n x n`) and the positions of the pairs, column by
    /// column: column `d` is the union of the columns `c >= d` of the leaders having
    /// `d`, sorted; the pairs whose smaller column is `d` get their positions in it.
    /// Returns `(pairs, pattern)`.
    fn lower_pattern(
        b: &BRows<I>,
        columns: &LeaderColumns<I>,
        n: usize,
    ) -> Result<(Vec<I>, SymbolicSparseColMat<usize>), SolveError> {
        let (b_row_ptr, b_col) = (&b.row_ptr, &b.col);
        let mut col_ptr = Vec::with_capacity(n + 1);
        col_ptr.push(0usize);
        // At most one entry per pair of a leader: reserving that much (address space,
        // untouched beyond the final length) avoids copies on growth.
        let mut row_idx: Vec<usize> = Vec::new();
        row_idx
            .try_reserve_exact(b.pair_len)
            .map_err(|_| FaerError::OutOfMemory)?;
        let mut pairs = try_vec(b.pair_len, I::new(0))?;
        // `mark[c] == d`: row c is already in column d; `slot[c]`: its position there.
        let mut mark = vec![usize::MAX; n];
        let mut slot = vec![0usize; n];
        for d in 0..n {
            let column = &columns.entries[columns.ptr[d]..columns.ptr[d + 1]];
            let begin = row_idx.len();
            for &(i, e) in column {
                // Entries from e on have columns >= d.
                for c in &b_col[e.get()..b_row_ptr[i.get() + 1].get()] {
                    let c = c.get();
                    if mark[c] != d {
                        mark[c] = d;
                        row_idx.push(c);
                    }
                }
            }
            row_idx[begin..].sort_unstable();
            for (position, &c) in row_idx.iter().enumerate().skip(begin) {
                slot[c] = position;
            }
            for &(i, e) in column {
                let (i, e) = (i.get(), e.get());
                let q = e - b_row_ptr[i].get();
                let block = b.pair_start[i].get();
                for (p, c) in b_col[e..b_row_ptr[i + 1].get()]
                    .iter()
                    .enumerate()
                    .map(|(t, c)| (q + t, c))
                {
                    pairs[block + p * (p + 1) / 2 + q] = I::new(slot[c.get()]);
                }
            }
            col_ptr.push(row_idx.len());
        }
        row_idx.shrink_to_fit();
        let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        Ok((pairs, pattern))
    }

    /// The numeric phase of [`NormalEquations::assemble`]; `k` is `K` row by row
    /// (pointers and values).
    fn assemble<T: DofScalar>(
        &self,
        (k_row_ptr, k_values): (&[usize], &[T]),
        a: SparseColMatRef<'_, usize, T>,
        weights: Option<&[f64]>,
        residual: &[T],
        out: Output<'_, T>,
    ) {
        let zero = T::from_f64(0.0);
        let Output {
            b_values,
            values,
            rhs,
        } = out;

        // B = A K: entry k of A (column l) adds A_k K[l, j] into the target of each
        // entry of row l of K.
        b_values.fill(zero);
        let (a_pattern, a_values) = (a.symbolic(), a.val());
        let mut targets = self.b_target.iter();
        for l in 0..a_pattern.ncols() {
            let k_row = &k_values[k_row_ptr[l]..k_row_ptr[l + 1]];
            if k_row.is_empty() {
                continue;
            }
            for &a_k in &a_values[a_pattern.col_range(l)] {
                for (&coef, target) in k_row.iter().zip(targets.by_ref()) {
                    b_values[target.get()] += a_k * coef;
                }
            }
        }

        // N and rhs, row by row of B.
        values.fill(zero);
        rhs.fill(zero);
        for (i, &r_i) in residual.iter().enumerate() {
            let w = weights.map_or(1.0, |w| w[i]);
            let (start, end) = (self.b_row_ptr[i].get(), self.b_row_ptr[i + 1].get());
            let row = &b_values[start..end];
            let block = self.pair_start[i].get();
            let positions = &self.pairs[block..block + row.len() * (row.len() + 1) / 2];
            let w_r = r_i * T::from_f64(w);
            let mut t = 0;
            for (p, (&b_p, c_p)) in row.iter().zip(&self.b_col[start..end]).enumerate() {
                let w_conj_b_p = b_p.conjugate() * T::from_f64(w);
                rhs[c_p.get()] += b_p.conjugate() * w_r;
                for &b_q in &row[..p] {
                    values[positions[t].get()] += w_conj_b_p * b_q;
                    t += 1;
                }
                // The diagonal as w |b_p|^2: exactly real, as the factorization expects.
                values[positions[t].get()] += T::from_f64(w * b_p.norm_sqr());
                t += 1;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dof::{DofBuilder, DofConstraints};
    use beltrami_mesh::VertexId;
    use faer::Mat;
    use faer::sparse::{SparseColMat, Triplet};
    use num_complex::Complex64;

    /// A reproducible value in [-1, 1) (splitmix64).
    fn noise(state: &mut u64) -> f64 {
        *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = *state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    /// Two rows per element of three nodes, both with entries at every unknown of the
    /// three nodes, like a real block form: rows `2 e` and `2 e + 1` have the same
    /// columns (one block of pairs for both).
    fn element_rows<T: DofScalar>(
        n_nodes: usize,
        elements: &[[usize; 3]],
        value: impl Fn(&mut u64) -> T,
    ) -> SparseColMat<usize, T> {
        let mut state = 7;
        let mut triplets = Vec::new();
        for (e, nodes) in elements.iter().enumerate() {
            for row in [2 * e, 2 * e + 1] {
                for &v in nodes {
                    for c in 0..T::PER_NODE {
                        triplets.push(Triplet::new(row, T::PER_NODE * v + c, value(&mut state)));
                    }
                }
            }
        }
        SparseColMat::try_new_from_triplets(2 * elements.len(), T::PER_NODE * n_nodes, &triplets)
            .unwrap()
    }

    /// `B^H W B` and `B^H W r` from dense matrices.
    fn dense<T: DofScalar>(
        a: &SparseColMat<usize, T>,
        dofs: &DofMap<T>,
        w: &[f64],
        r: &[T],
    ) -> (Mat<T>, Vec<T>) {
        let b = a.to_dense() * dofs.k().to_dense();
        let (m, n) = (b.nrows(), b.ncols());
        let mut normal = Mat::<T>::zeros(n, n);
        let mut rhs = vec![T::from_f64(0.0); n];
        for i in 0..m {
            let w_i = T::from_f64(w[i]);
            for c in 0..n {
                rhs[c] += b[(i, c)].conjugate() * w_i * r[i];
                for d in 0..n {
                    normal[(c, d)] += b[(i, c)].conjugate() * w_i * b[(i, d)];
                }
            }
        }
        (normal, rhs)
    }

    fn check<T: DofScalar>(dofs: &DofMap<T>, value: impl Fn(&mut u64) -> T + Copy) {
        // Element [2, 5, 6] holds both shared nodes 2 and 6: their entries merge.
        let elements = [
            [0, 1, 2],
            [1, 2, 3],
            [2, 3, 4],
            [3, 4, 5],
            [5, 6, 7],
            [0, 7, 3],
            [2, 5, 6],
        ];
        let a = element_rows(8, &elements, value);
        let mut state = 11;
        let w: Vec<f64> = (0..a.nrows()).map(|_| 1.5 + noise(&mut state)).collect();
        let r: Vec<T> = (0..a.nrows()).map(|_| value(&mut state)).collect();
        let (expected, expected_rhs) = dense(&a, dofs, &w, &r);
        let scale = (0..expected.ncols())
            .flat_map(|d| (0..expected.nrows()).map(move |c| (c, d)))
            .map(|(c, d)| expected[(c, d)].norm_sqr().sqrt())
            .fold(0.0, f64::max);
        for narrow in [true, false] {
            let mut normal = NormalEquations::build(a.symbolic(), dofs, narrow).unwrap();
            assert_eq!(matches!(normal.maps, AnyMaps::Narrow(_)), narrow);
            let mut rhs = vec![T::from_f64(0.0); dofs.reduced_len()];
            normal.assemble(a.as_ref(), Some(&w), &r, &mut rhs);
            let got = normal.matrix();
            for d in 0..got.ncols() {
                let rows: Vec<usize> = got.row_idx_of_col(d).collect();
                // Sorted lower triangle, diagonal first.
                assert_eq!(rows[0], d);
                assert!(rows.windows(2).all(|p| p[0] < p[1]));
                for (c, &v) in rows.iter().zip(got.val_of_col(d)) {
                    assert!((v - expected[(*c, d)]).norm_sqr().sqrt() <= 1e-14 * scale);
                }
            }
            // Every nonzero of the lower triangle is in the pattern.
            let stored: usize = got.compute_nnz();
            let lower = (0..expected.ncols())
                .flat_map(|d| (d..expected.nrows()).map(move |c| (c, d)))
                .filter(|&(c, d)| expected[(c, d)].norm_sqr() > 0.0)
                .count();
            assert_eq!(stored, lower);
            for (g, e) in rhs.iter().zip(&expected_rhs) {
                assert!((*g - *e).norm_sqr().sqrt() <= 1e-14 * scale);
            }
        }
        // The pattern from the cells alone is the normal equations' own.
        let cells = elements.map(|e| e.map(|v| VertexId(v as u32)));
        let from_cells = normal_pattern_of_cells(cells.iter().copied(), dofs).unwrap();
        let normal = NormalEquations::new(a.symbolic(), dofs).unwrap();
        assert_eq!(from_cells.col_ptr(), normal.pattern().col_ptr());
        assert_eq!(from_cells.row_idx(), normal.pattern().row_idx());
        let beyond = normal_pattern_of_cells([[VertexId(1), VertexId(8)]].into_iter(), dofs);
        assert!(matches!(beyond, Err(SolveError::Length { got: 8, .. })));
    }

    fn constraints() -> DofConstraints {
        let mut cons = DofConstraints::new();
        cons.fix(VertexId(0), Complex64::new(1.0, 2.0))
            .share(VertexId(2), VertexId(6));
        cons
    }

    #[test]
    fn scatter_maps_reproduce_the_dense_normal_equations_real() {
        let mut cons = constraints();
        cons.slide(
            VertexId(4),
            Complex64::new(0.0, 1.0),
            Complex64::new(3.0, 4.0),
        );
        let dofs = DofMap::real(8, &cons).unwrap();
        check(&dofs, noise);
    }

    #[test]
    fn scatter_maps_reproduce_the_dense_normal_equations_complex() {
        let dofs = DofMap::complex(8, &constraints()).unwrap();
        check(&dofs, |s| Complex64::new(noise(s), noise(s)));
    }

    /// A general map, several entries per row of `K`: node 1 in a plane spanned by two
    /// oblique directions, node 4 on a line and, with node 6, moved by an offset along
    /// different directions, node 0 fixed, the others free.
    #[test]
    fn scatter_maps_reproduce_the_dense_normal_equations_with_general_bases() {
        let mut b = DofBuilder::<f64>::new(8, 2).unwrap();
        b.origin(VertexId(0), &[1.0, 2.0]).unwrap();
        b.span(VertexId(1), &[0.5, 0.0], [[1.0, 0.5], [-0.3, 1.0]])
            .unwrap();
        for i in [2, 3, 5, 7] {
            b.free(&[VertexId(i)]).unwrap();
        }
        b.span(VertexId(4), &[0.0, 1.0], [[0.6, 0.8]]).unwrap();
        b.unknown([(VertexId(4), [0.8, -0.6]), (VertexId(6), [1.0, 1.0])])
            .unwrap();
        let dofs = b.build().unwrap();
        let k = dofs.k();
        let row_entries = (0..dofs.reduced_len())
            .flat_map(|j| k.row_idx_of_col_raw(j).iter().copied())
            .filter(|&row| row == 8)
            .count();
        assert_eq!(row_entries, 2);
        check(&dofs, noise);
    }
}
