//! Affine maps from reduced unknowns to nodal unknowns: `x = K y + x0`.
//!
//! Every solver of the crate states its constraints (Dirichlet values, pinned points,
//! vertices sliding along a line, vertices shared across a seam) per node, and the
//! [`DofMap`] turns them into an affine parametrization of the admissible nodal vectors:
//!
//! ```text
//! x = K y + x0,    x in T^N_full (nodal unknowns),  y in T^n (reduced unknowns, free)
//! ```
//!
//! A least-squares energy `|A x - b|^2` then becomes the unconstrained problem
//! `|A K y - (b - A x0)|^2` in `y` (see [`crate::solve`]).
//!
//! # Two forms
//!
//! - **Complex form**, [`DofMap<Complex64>`] built by [`DofMap::complex`]: one complex
//!   unknown per node, `x[i]` is the image of node `i` as `x + i y`. `K` has entries 0/1
//!   and `x0` holds the fixed values. It keeps complex-linearity, so it handles free,
//!   fixed and shared nodes only (a slide is not complex-linear: `t` must be real).
//! - **Real form**, [`DofMap<f64>`] built by [`DofMap::real`]: two real unknowns per node,
//!   interleaved `[re0, im0, re1, im1, ...]`. It also handles sliding nodes
//!   `x = p + t d` with one real unknown `t`.
//!
//! # Structure of `K`
//!
//! Every row of `K` has at most one nonzero: a nodal unknown is either fixed (empty row)
//! or equal to `coef * y[j] + x0[i]` for one reduced unknown `j`. Hence the columns of
//! `K` have disjoint supports, `K^H K` is diagonal, and [`DofMap::reduce`] (the
//! least-squares inverse of [`DofMap::expand`]) is exact on the range of the map.
//!
//! # Numbering
//!
//! Nodes joined by [`DofConstraints::share`] form a group (union-find, so chains
//! `a ~ b ~ c` make one group); a single node is a group of one. Reduced unknowns are
//! numbered group by group in increasing order of each group's smallest node; a free
//! group of the real form gets two consecutive unknowns (real part, then imaginary
//! part), a sliding group one.

use beltrami_mesh::VertexId;
use faer::sparse::{CreationError, SparseColMat, SparseColMatRef, Triplet};
use num_complex::Complex64;
use std::fmt::Debug;
use std::ops::{Add, AddAssign, Mul, MulAssign, Neg, Sub};
use thiserror::Error;

/// Relative tolerance for geometric coincidences between constraints of one group:
/// two fixed values are the same point, a fixed value lies on a sliding line, two
/// sliding lines are the same line, when they agree to `GEOMETRIC_TOLERANCE * scale`
/// with `scale = max(1, |values involved|)`. Constraints computed by different formulas
/// for the same point differ by rounding only, far below this.
pub const GEOMETRIC_TOLERANCE: f64 = 1e-12;

mod sealed {
    pub trait Sealed {}
    impl Sealed for f64 {}
    impl Sealed for num_complex::Complex64 {}
}

/// The scalar of a DOF map and of the solvers: `f64` (real form, two unknowns per node)
/// or [`Complex64`] (complex form, one unknown per node). Sealed: the two forms are the
/// only ones the constraint semantics are defined for.
pub trait Scalar:
    faer::traits::ComplexField<Real = f64>
    + Copy
    + Debug
    + PartialEq
    + Send
    + Sync
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + MulAssign
    + sealed::Sealed
    + 'static
{
    /// Nodal unknowns per node: 2 for `f64` (`[re, im]`), 1 for `Complex64`.
    const PER_NODE: usize;

    /// `x` embedded in the scalar field (imaginary part 0).
    fn from_f64(x: f64) -> Self;

    /// Complex conjugate (identity for `f64`).
    fn conjugate(self) -> Self;

    /// `|x|^2`.
    fn norm_sqr(self) -> f64;

    /// True if no component is NaN or infinite.
    fn finite(self) -> bool;

    /// The complex position of node `node` read from a full nodal vector `x` of this
    /// form: `x[node]` (complex form) or `x[2 node] + i x[2 node + 1]` (real form).
    /// The caller guarantees `x.len() >= PER_NODE * (node + 1)`.
    fn node_position(x: &[Self], node: usize) -> Complex64;
}

impl Scalar for f64 {
    const PER_NODE: usize = 2;

    #[inline]
    fn from_f64(x: f64) -> Self {
        x
    }

    #[inline]
    fn conjugate(self) -> Self {
        self
    }

    #[inline]
    fn norm_sqr(self) -> f64 {
        self * self
    }

    #[inline]
    fn finite(self) -> bool {
        self.is_finite()
    }

    #[inline]
    fn node_position(x: &[Self], node: usize) -> Complex64 {
        Complex64::new(x[2 * node], x[2 * node + 1])
    }
}

impl Scalar for Complex64 {
    const PER_NODE: usize = 1;

    #[inline]
    fn from_f64(x: f64) -> Self {
        Complex64::new(x, 0.0)
    }

    #[inline]
    fn conjugate(self) -> Self {
        self.conj()
    }

    #[inline]
    fn norm_sqr(self) -> f64 {
        Complex64::norm_sqr(&self)
    }

    #[inline]
    fn finite(self) -> bool {
        self.is_finite()
    }

    #[inline]
    fn node_position(x: &[Self], node: usize) -> Complex64 {
        x[node]
    }
}

/// Why constraints could not become a DOF map, or a vector does not fit one. Every
/// variant names the node (mesh vertex) concerned.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum DofError {
    /// A constraint refers to a node `>= n_nodes`.
    #[error("constraint on vertex {node}, but there are only {n_nodes} nodes")]
    NodeOutOfRange {
        /// The node named by the constraint.
        node: VertexId,
        /// Number of nodes of the map.
        n_nodes: usize,
    },
    /// More nodes than a [`VertexId`] can index.
    #[error("{n_nodes} nodes exceed the u32 vertex index range")]
    TooManyNodes {
        /// Number of nodes asked for.
        n_nodes: usize,
    },
    /// A fixed value, sliding point or sliding direction with a NaN or infinite part.
    #[error("the {what} given for vertex {node} is not finite")]
    NonFinite {
        /// The node.
        node: VertexId,
        /// "fixed value", "sliding point" or "sliding direction".
        what: &'static str,
    },
    /// A sliding direction of length zero.
    #[error("the sliding direction of vertex {node} is zero")]
    ZeroDirection {
        /// The node.
        node: VertexId,
    },
    /// The complex form was asked for with a sliding node; slides are not
    /// complex-linear (the parameter `t` is real): use [`DofMap::real`].
    #[error(
        "vertex {node} slides along a line, which the complex form cannot express: use the real form"
    )]
    SlideInComplexForm {
        /// The sliding node.
        node: VertexId,
    },
    /// Two fixed values for the same node or for two nodes of one share group. (`a` may
    /// also be a node whose two slides met in a point, which fixes its group.)
    #[error("vertices {a} and {b} must coincide but are fixed to {value_a} and {value_b}")]
    ConflictingFixes {
        /// The node whose value was kept so far.
        a: VertexId,
        /// The node whose value disagrees.
        b: VertexId,
        /// Value fixed for `a`.
        value_a: Complex64,
        /// Value fixed for `b`.
        value_b: Complex64,
    },
    /// A node fixed off the line along which it (or a node of its share group) slides.
    #[error(
        "vertex {fixed} is fixed at distance {distance:e} from the line vertex {sliding} slides on, but they must coincide"
    )]
    FixedOffSlideLine {
        /// The fixed node.
        fixed: VertexId,
        /// The sliding node.
        sliding: VertexId,
        /// Distance of the fixed value from the line.
        distance: f64,
    },
    /// Two sliding lines of one group that are parallel but distinct: no point lies on
    /// both. (Non-parallel lines meet in one point, which then fixes the group.)
    #[error("vertices {a} and {b} must coincide but slide on distinct parallel lines")]
    ParallelSlides {
        /// The first sliding node.
        a: VertexId,
        /// The second sliding node.
        b: VertexId,
    },
    /// A vector whose length does not match the map.
    #[error("{what} has length {got}, expected {expected}")]
    Length {
        /// Which vector.
        what: &'static str,
        /// Length required.
        expected: usize,
        /// Length given.
        got: usize,
    },
    /// Building the sparse matrix `K` failed (index overflow or allocation).
    #[error("building the sparse matrix K failed: {0}")]
    Sparse(#[from] CreationError),
}

/// One constraint on one node, as stated by the user.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Constraint {
    Fix(Complex64),
    Slide {
        point: Complex64,
        direction: Complex64,
    },
}

/// Constraints on the nodes of a mesh, collected before building a [`DofMap`].
///
/// Nodes without a constraint are free. The builder only records; validation (node
/// range, finiteness, conflicts) happens in [`DofMap::real`] / [`DofMap::complex`],
/// which know the node count and the form.
///
/// Semantics of several constraints on one group (a node alone or nodes joined by
/// [`share`](Self::share)), all of which must hold at once:
/// - fix + fix: the values must coincide (to [`GEOMETRIC_TOLERANCE`]); the value of the
///   smallest node is kept.
/// - fix + slide: the fixed value must lie on the line; the group is fixed.
/// - slide + slide: the same line keeps the slide; two non-parallel lines fix the group
///   at their intersection (a corner of a square whose sides slide); two distinct
///   parallel lines are an error.
#[derive(Debug, Clone, Default)]
pub struct DofConstraints {
    constraints: Vec<(VertexId, Constraint)>,
    shares: Vec<(VertexId, VertexId)>,
}

impl DofConstraints {
    /// No constraints: every node free.
    pub fn new() -> Self {
        Self::default()
    }

    /// Fixes `node` at `value` (Dirichlet value, pinned point): `x_node = value`.
    pub fn fix(&mut self, node: VertexId, value: Complex64) -> &mut Self {
        self.constraints.push((node, Constraint::Fix(value)));
        self
    }

    /// Lets `node` slide along the line through `point` with direction `direction`:
    /// `x_node = point + t d` with `d = direction / |direction|` and one real unknown
    /// `t` (so `t` is the signed distance from `point`). Real form only.
    pub fn slide(&mut self, node: VertexId, point: Complex64, direction: Complex64) -> &mut Self {
        self.constraints
            .push((node, Constraint::Slide { point, direction }));
        self
    }

    /// Makes `a` and `b` one unknown (a seam: both copies of a cut vertex move
    /// together). Sharing is transitive.
    pub fn share(&mut self, a: VertexId, b: VertexId) -> &mut Self {
        self.shares.push((a, b));
        self
    }
}

/// What a node became in a [`DofMap`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NodeDof {
    /// `x_node = value`: no reduced unknown.
    Fixed {
        /// The value.
        value: Complex64,
    },
    /// Free: complex form `x_node = y[dof]`; real form `re x_node = y[dof]`,
    /// `im x_node = y[dof + 1]`.
    Free {
        /// First reduced unknown of the node.
        dof: usize,
    },
    /// Real form only: `x_node = point + y[dof] * direction`, `|direction| = 1`.
    Sliding {
        /// The reduced unknown `t`.
        dof: usize,
        /// Point of the line (`t = 0`).
        point: Complex64,
        /// Unit direction of the line.
        direction: Complex64,
    },
}

/// An affine DOF map `x = K y + x0` (module docs: forms, structure, numbering).
///
/// `T = f64` is the real form (`x` has `2 n_nodes` entries `[re0, im0, ...]`),
/// `T = Complex64` the complex form (`x` has `n_nodes` entries).
#[derive(Debug, Clone)]
pub struct DofMap<T: Scalar> {
    n_nodes: usize,
    node_dofs: Vec<NodeDof>,
    /// For each row of `K` (full unknown): its reduced unknown and coefficient, or
    /// `None` if fixed. The same information as `k`, kept row-wise for `expand`.
    rows: Vec<Option<(usize, T)>>,
    /// A representative node (the smallest) of each reduced unknown.
    dof_nodes: Vec<VertexId>,
    /// `sum_i |K_ij|^2` for each column `j`: the diagonal of `K^H K`.
    col_norm_sqr: Vec<f64>,
    k: SparseColMat<usize, T>,
    x0: Vec<T>,
}

/// The admissible set of one group, intersected constraint by constraint.
#[derive(Debug, Clone, Copy)]
enum GroupSet {
    Free,
    Line {
        point: Complex64,
        direction: Complex64,
        node: VertexId,
    },
    Point {
        value: Complex64,
        node: VertexId,
    },
}

/// `a.re b.im - a.im b.re`: the 2D cross product.
fn cross(a: Complex64, b: Complex64) -> f64 {
    a.re * b.im - a.im * b.re
}

/// Distance of `v` from the line `point + t direction` (`|direction| = 1`).
fn line_distance(v: Complex64, point: Complex64, direction: Complex64) -> f64 {
    cross(direction, v - point).abs()
}

fn scale_of(values: &[Complex64]) -> f64 {
    values.iter().fold(1.0_f64, |s, v| s.max(v.norm()))
}

impl GroupSet {
    /// Intersects the set with the constraint `c` of `node`.
    fn meet(self, node: VertexId, c: Constraint) -> Result<Self, DofError> {
        let incoming = match c {
            Constraint::Fix(value) => GroupSet::Point { value, node },
            Constraint::Slide { point, direction } => GroupSet::Line {
                point,
                direction,
                node,
            },
        };
        Ok(match (self, incoming) {
            (GroupSet::Free, s) | (s, GroupSet::Free) => s,
            (GroupSet::Point { value: va, node: a }, GroupSet::Point { value: vb, node: b }) => {
                if (va - vb).norm() > GEOMETRIC_TOLERANCE * scale_of(&[va, vb]) {
                    return Err(DofError::ConflictingFixes {
                        a,
                        b,
                        value_a: va,
                        value_b: vb,
                    });
                }
                self
            }
            (
                GroupSet::Point { value, node: fixed },
                GroupSet::Line {
                    point,
                    direction,
                    node: sliding,
                },
            )
            | (
                GroupSet::Line {
                    point,
                    direction,
                    node: sliding,
                },
                GroupSet::Point { value, node: fixed },
            ) => {
                let distance = line_distance(value, point, direction);
                if distance > GEOMETRIC_TOLERANCE * scale_of(&[value, point]) {
                    return Err(DofError::FixedOffSlideLine {
                        fixed,
                        sliding,
                        distance,
                    });
                }
                GroupSet::Point { value, node: fixed }
            }
            (
                GroupSet::Line {
                    point: pa,
                    direction: da,
                    node: a,
                },
                GroupSet::Line {
                    point: pb,
                    direction: db,
                    node: b,
                },
            ) => {
                let sin = cross(da, db);
                if sin.abs() <= GEOMETRIC_TOLERANCE {
                    if line_distance(pb, pa, da) > GEOMETRIC_TOLERANCE * scale_of(&[pa, pb]) {
                        return Err(DofError::ParallelSlides { a, b });
                    }
                    self
                } else {
                    // pa + s da = pb + t db  =>  s = cross(pb - pa, db) / cross(da, db).
                    let s = cross(pb - pa, db) / sin;
                    GroupSet::Point {
                        value: pa + da * s,
                        node: a,
                    }
                }
            }
        })
    }
}

/// Union-find root with path halving.
fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// Checks a constraint's node range and values, and normalizes a slide direction.
fn validate(
    node: VertexId,
    c: Constraint,
    n_nodes: usize,
) -> Result<(usize, Constraint), DofError> {
    let i = node.idx();
    if i >= n_nodes {
        return Err(DofError::NodeOutOfRange { node, n_nodes });
    }
    let finite = |v: Complex64, what| {
        if v.is_finite() {
            Ok(())
        } else {
            Err(DofError::NonFinite { node, what })
        }
    };
    match c {
        Constraint::Fix(value) => {
            finite(value, "fixed value")?;
            Ok((i, c))
        }
        Constraint::Slide { point, direction } => {
            finite(point, "sliding point")?;
            finite(direction, "sliding direction")?;
            let len = direction.norm();
            if len == 0.0 {
                return Err(DofError::ZeroDirection { node });
            }
            Ok((
                i,
                Constraint::Slide {
                    point,
                    direction: direction / len,
                },
            ))
        }
    }
}

/// Resolves the constraints into one [`NodeDof`] per node for the given form.
/// Returns the per-node result and the representative node of each reduced unknown.
fn resolve(
    n_nodes: usize,
    constraints: &DofConstraints,
    complex_form: bool,
) -> Result<(Vec<NodeDof>, Vec<VertexId>), DofError> {
    if u32::try_from(n_nodes).is_err() {
        return Err(DofError::TooManyNodes { n_nodes });
    }
    let mut parent: Vec<usize> = (0..n_nodes).collect();
    for &(a, b) in &constraints.shares {
        for node in [a, b] {
            if node.idx() >= n_nodes {
                return Err(DofError::NodeOutOfRange { node, n_nodes });
            }
        }
        let ra = find(&mut parent, a.idx());
        let rb = find(&mut parent, b.idx());
        // The smaller index becomes the root, so the root is the group's smallest node.
        let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
        parent[hi] = lo;
    }
    for i in 0..n_nodes {
        parent[i] = find(&mut parent, i);
    }

    // Validate, then sort by node (stable: call order within a node) so that the
    // intersection order, and thus which value is kept, does not depend on call order
    // across nodes.
    let mut list = Vec::with_capacity(constraints.constraints.len());
    for &(node, c) in &constraints.constraints {
        let (i, c) = validate(node, c, n_nodes)?;
        if complex_form && matches!(c, Constraint::Slide { .. }) {
            return Err(DofError::SlideInComplexForm { node });
        }
        list.push((i, c));
    }
    list.sort_by_key(|&(i, _)| i);

    let mut sets = vec![GroupSet::Free; n_nodes];
    for (i, c) in list {
        let root = parent[i];
        sets[root] = sets[root].meet(VertexId::from_usize(i), c)?;
    }

    // Number the reduced unknowns at each root (roots are visited in increasing order
    // and a root is its group's smallest node), then copy to the members.
    let mut node_dofs = vec![NodeDof::Free { dof: 0 }; n_nodes];
    let mut dof_nodes = Vec::new();
    for i in 0..n_nodes {
        let root = parent[i];
        if root != i {
            node_dofs[i] = node_dofs[root];
            continue;
        }
        let dof = dof_nodes.len();
        node_dofs[i] = match sets[i] {
            GroupSet::Point { value, .. } => NodeDof::Fixed { value },
            GroupSet::Free => {
                let count = if complex_form { 1 } else { 2 };
                dof_nodes.extend(std::iter::repeat_n(VertexId::from_usize(i), count));
                NodeDof::Free { dof }
            }
            GroupSet::Line {
                point, direction, ..
            } => {
                dof_nodes.push(VertexId::from_usize(i));
                NodeDof::Sliding {
                    dof,
                    point,
                    direction,
                }
            }
        };
    }
    Ok((node_dofs, dof_nodes))
}

impl<T: Scalar> DofMap<T> {
    /// Assembles `K`, `x0` and the row table from resolved node constraints.
    /// `entries(node, node_dof)` gives, for each of the node's unknowns in order,
    /// `(reduced unknown and coefficient, or None if fixed; x0 value)`; only the first
    /// `T::PER_NODE` pairs are used.
    fn assemble(
        node_dofs: Vec<NodeDof>,
        dof_nodes: Vec<VertexId>,
        entries: impl Fn(VertexId, &NodeDof) -> Result<[(Option<(usize, T)>, T); 2], DofError>,
    ) -> Result<Self, DofError> {
        let n_nodes = node_dofs.len();
        let full = n_nodes * T::PER_NODE;
        let n = dof_nodes.len();
        let mut rows = Vec::with_capacity(full);
        let mut x0 = Vec::with_capacity(full);
        let mut triplets = Vec::with_capacity(full);
        let mut col_norm_sqr = vec![0.0; n];
        for (i, nd) in node_dofs.iter().enumerate() {
            for (entry, value) in entries(VertexId::from_usize(i), nd)?
                .into_iter()
                .take(T::PER_NODE)
            {
                if let Some((j, coef)) = entry {
                    triplets.push(Triplet::new(rows.len(), j, coef));
                    col_norm_sqr[j] += coef.norm_sqr();
                }
                rows.push(entry);
                x0.push(value);
            }
        }
        let k = SparseColMat::try_new_from_triplets(full, n, &triplets)?;
        Ok(Self {
            n_nodes,
            node_dofs,
            rows,
            dof_nodes,
            col_norm_sqr,
            k,
            x0,
        })
    }

    /// Number of nodes.
    pub fn n_nodes(&self) -> usize {
        self.n_nodes
    }

    /// Length of a full nodal vector `x`: `n_nodes` (complex form) or `2 n_nodes`
    /// (real form). The number of rows of `K`.
    pub fn full_len(&self) -> usize {
        self.rows.len()
    }

    /// Number of reduced unknowns `y`: the number of columns of `K`.
    pub fn reduced_len(&self) -> usize {
        self.dof_nodes.len()
    }

    /// `K` (`full_len x reduced_len`, at most one nonzero per row).
    pub fn k(&self) -> SparseColMatRef<'_, usize, T> {
        self.k.as_ref()
    }

    /// `x0` (`full_len`): the fixed values, and the sliding points of sliding nodes.
    pub fn x0(&self) -> &[T] {
        &self.x0
    }

    /// What `node` became.
    pub fn node_dof(&self, node: VertexId) -> Result<NodeDof, DofError> {
        self.node_dofs
            .get(node.idx())
            .copied()
            .ok_or(DofError::NodeOutOfRange {
                node,
                n_nodes: self.n_nodes,
            })
    }

    /// The smallest node that reduced unknown `dof` moves (to name it in messages).
    /// `None` if `dof >= reduced_len()`.
    pub fn dof_node(&self, dof: usize) -> Option<VertexId> {
        self.dof_nodes.get(dof).copied()
    }

    /// `x = K y + x0`.
    pub fn expand(&self, y: &[T]) -> Result<Vec<T>, DofError> {
        let mut x = vec![T::from_f64(0.0); self.full_len()];
        self.expand_into(y, &mut x)?;
        Ok(x)
    }

    /// `x = K y + x0`, written into `x` (no allocation).
    pub fn expand_into(&self, y: &[T], x: &mut [T]) -> Result<(), DofError> {
        check_len("y", self.reduced_len(), y.len())?;
        check_len("x", self.full_len(), x.len())?;
        for ((xi, row), x0) in x.iter_mut().zip(&self.rows).zip(&self.x0) {
            *xi = match *row {
                Some((j, coef)) => coef * y[j] + *x0,
                None => *x0,
            };
        }
        Ok(())
    }

    /// The least-squares inverse of [`expand`](Self::expand):
    /// `y = (K^H K)^{-1} K^H (x - x0)`. Exact (`expand(reduce(x)) = x`) when `x`
    /// satisfies the constraints; otherwise the nearest admissible `y` (shared nodes are
    /// averaged, a sliding node is projected on its line). Use it to start an iterative
    /// solver from a given map.
    pub fn reduce(&self, x: &[T]) -> Result<Vec<T>, DofError> {
        check_len("x", self.full_len(), x.len())?;
        let mut y = vec![T::from_f64(0.0); self.reduced_len()];
        for ((xi, row), x0) in x.iter().zip(&self.rows).zip(&self.x0) {
            if let Some((j, coef)) = *row {
                y[j] += coef.conjugate() * (*xi - *x0);
            }
        }
        for (yj, norm) in y.iter_mut().zip(&self.col_norm_sqr) {
            // Every column of K has at least one nonzero of modulus 1 (a 1 or a unit
            // direction component pair), so the norm is positive.
            *yj *= T::from_f64(1.0 / norm);
        }
        Ok(y)
    }

    /// The image of `node` as a complex number, read from a full vector `x`.
    pub fn node_position(&self, x: &[T], node: VertexId) -> Result<Complex64, DofError> {
        check_len("x", self.full_len(), x.len())?;
        if node.idx() >= self.n_nodes {
            return Err(DofError::NodeOutOfRange {
                node,
                n_nodes: self.n_nodes,
            });
        }
        Ok(T::node_position(x, node.idx()))
    }

    /// All node images of a full vector `x` as complex numbers (the identity for the
    /// complex form, pairs `[re, im]` joined for the real form).
    pub fn positions(&self, x: &[T]) -> Result<Vec<Complex64>, DofError> {
        check_len("x", self.full_len(), x.len())?;
        Ok((0..self.n_nodes).map(|i| T::node_position(x, i)).collect())
    }
}

fn check_len(what: &'static str, expected: usize, got: usize) -> Result<(), DofError> {
    if expected == got {
        Ok(())
    } else {
        Err(DofError::Length {
            what,
            expected,
            got,
        })
    }
}

impl DofMap<f64> {
    /// The real form: `x = [re0, im0, re1, im1, ...]` (`2 n_nodes` real unknowns).
    ///
    /// - free node: `re x = y[dof]`, `im x = y[dof + 1]`;
    /// - fixed node: `x = value` (empty rows of `K`, `x0 = [re, im]`);
    /// - sliding node: `x = p + t d`: rows `[d.re, d.im]` in the column of `t`,
    ///   `x0 = [p.re, p.im]`;
    /// - shared nodes: the same columns.
    pub fn real(n_nodes: usize, constraints: &DofConstraints) -> Result<Self, DofError> {
        let (node_dofs, dof_nodes) = resolve(n_nodes, constraints, false)?;
        Self::assemble(node_dofs, dof_nodes, |_, nd| {
            Ok(match *nd {
                NodeDof::Fixed { value } => [(None, value.re), (None, value.im)],
                NodeDof::Free { dof } => [(Some((dof, 1.0)), 0.0), (Some((dof + 1, 1.0)), 0.0)],
                NodeDof::Sliding {
                    dof,
                    point,
                    direction,
                } => [
                    (Some((dof, direction.re)), point.re),
                    (Some((dof, direction.im)), point.im),
                ],
            })
        })
    }
}

impl DofMap<Complex64> {
    /// The complex form: `x[i]` is the image of node `i` (`n_nodes` complex unknowns).
    ///
    /// - free node: `x = y[dof]` (`K` entry 1);
    /// - fixed node: `x = value` (empty row of `K`, `x0 = value`);
    /// - shared nodes: the same column.
    ///
    /// A sliding node is [`DofError::SlideInComplexForm`].
    pub fn complex(n_nodes: usize, constraints: &DofConstraints) -> Result<Self, DofError> {
        let (node_dofs, dof_nodes) = resolve(n_nodes, constraints, true)?;
        let zero = Complex64::new(0.0, 0.0);
        let one = Complex64::new(1.0, 0.0);
        Self::assemble(node_dofs, dof_nodes, |node, nd| match *nd {
            NodeDof::Fixed { value } => Ok([(None, value), (None, zero)]),
            NodeDof::Free { dof } => Ok([(Some((dof, one)), zero), (None, zero)]),
            // `resolve` already rejected slides in the complex form, with this error.
            NodeDof::Sliding { .. } => Err(DofError::SlideInComplexForm { node }),
        })
    }
}
