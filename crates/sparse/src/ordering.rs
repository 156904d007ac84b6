//! Fill-reducing elimination orders: approximate minimum degree, nested dissection, and
//! the two-sided orders that factor on two cores.

use crate::SolveError;
use crate::check::check_len;
use crate::factor_count::{FactorCount, factor_count};
use crate::nested_dissection;
use faer::sparse::{FaerError, SymbolicSparseColMatRef};

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
pub(crate) enum Choice {
    Nested(nested_dissection::Dissected),
    Amd(Vec<usize>),
}

/// [`fill_reducing_order`]'s choice from [`NESTED_DISSECTION_FROM`] rows, with the
/// exact count of the factor in the order taken.
pub(crate) fn chosen_order(
    pattern: SymbolicSparseColMatRef<'_, usize>,
) -> Result<(Choice, FactorCount), SolveError> {
    choose(pattern, dissected(pattern)?)
}

/// The multiply-subtract count up to which the nested-dissection order of `n` rows is
/// taken without computing AMD's: [`NESTED_DISSECTION_SURE`]` n^(3/2)`.
pub(crate) fn nested_dissection_sure(n: usize) -> f64 {
    NESTED_DISSECTION_SURE * (n as f64).powf(1.5)
}

/// [`chosen_order`] with the nested-dissection order `dissected` of `pattern` computed.
pub(crate) fn choose(
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
pub(crate) fn dissected(
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
/// [`SpdSolver::with_split_order`](crate::SpdSolver::with_split_order) factors the two sides at once, one per core, when no
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
    /// The order of a system with `k` unknowns per row of this order's (unknown
    /// `k r + j` for row `r`, `j < k`: a vertex's coordinates, a vertex's affine map),
    /// each row's unknowns eliminated together in its place and the sides `k` times
    /// as long. A graph's order carries over so: the blocks' pattern is the graph's with
    /// each entry a dense `k x k` block, and it is cheaper to order the graph.
    pub fn in_blocks(&self, k: usize) -> SplitOrder {
        SplitOrder {
            order: self.order.iter().flat_map(|&r| k * r..k * r + k).collect(),
            sides: self.sides.map(|[a, b]| [k * a, k * b]),
        }
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

/// The order [`SpdSolver::with_split_order`](crate::SpdSolver::with_split_order) factors fastest for `pattern` on two cores:
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
/// the others 60%), whose first split [`SpdSolver::with_split_order`](crate::SpdSolver::with_split_order) factors as two
/// sides on two cores. Multilevel separators cost about 2.5 times as much as the level
/// sets of [`nested_dissection_order`] (0.2-0.3 s on 50K-vertex meshes) but the order is
/// computed once for a factorization repeated at every step of a flow, and they are
/// often much smaller: on the scan `g0_koala` the first has 182 vertices against the
/// level sets' 352, which made the two-core factorization worth it there (`|S|^3` 0.08
/// of the whole's count instead of 0.59).
///
/// Inside the sides, further multilevel separators factor the flow's 50K-vertex graphs
/// with 16-45% fewer multiply-subtracts than AMD did (docs/benchmarks.md, "Fill-reducing orders against METIS");
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
