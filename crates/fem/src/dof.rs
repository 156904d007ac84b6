//! Affine maps from reduced unknowns to nodal values: `x = K y + x0`.
//!
//! Every solver of the crate states its constraints per node (Dirichlet values, pinned
//! points, vertices sliding along a line or moving in a tangent plane, vertices shared
//! across a seam, offsets shared by the vertices of a curve), and the [`DofMap`] turns
//! them into an affine parametrization of the admissible nodal vectors:
//!
//! ```text
//! x_i = x0_i + sum_k y_{j(i,k)} b_ik,    x_i in T^d (node i),  y in T^n (reduced unknowns, free)
//! ```
//!
//! that is `x = K y + x0`. A least-squares energy `|A x - b|^2` then becomes the
//! unconstrained problem `|A K y - (b - A x0)|^2` in `y` (see [`crate::least_squares`]).
//!
//! # Nodes, unknowns and terms
//!
//! The value of a node lies in `T^d`: `d = 2` real components for a planar node, `d = 3`
//! for a spatial one, or `d = 1` complex component (the complex form of a planar node).
//! A full nodal vector `x` holds the nodes one after the other, `d` entries each:
//! `x = [x_0, x_1, ...]`, `x_i = [x_i,0, ..., x_i,d-1]` (for planar real nodes
//! `[re0, im0, re1, im1, ...]`).
//!
//! Node `i` has an origin `x0_i` and one direction `b_ik in T^d` per unknown `j(i,k)` that
//! moves it; each product `y_{j(i,k)} b_ik` is a *term* of the node. By the number of its
//! own directions a node is
//!
//! | node | directions | value |
//! |---|---|---|
//! | fixed | none | `x0_i` |
//! | sliding along a line | 1 | `x0_i + y_j b` |
//! | in a plane (a tangent plane in R^3) | 2 | `x0_i + y_j u + y_(j+1) v` |
//! | free | `d` coordinate axes | `x0_i + sum_c y_(j+c) e_c` |
//!
//! An unknown may move several nodes, each along its own direction: the offset of a
//! curve (the free radius of an annulus) moves every node of the curve along the curve's
//! normal there; a seam (the copies of a cut vertex) is a set of unknowns moving all
//! copies along the same directions. The directions at one node must be linearly
//! independent ([`DofError::DependentDirections`]); then `K` has full column rank, and
//! the least-squares problem in `y` is as well posed as the one in `x`.
//!
//! [`DofBuilder`] states nodes and unknowns in this general form. [`DofConstraints`]
//! states the planar constraints of the parametrization solvers (fix, slide, share), and
//! [`DofMap::real`] / [`DofMap::complex`] resolve them into a builder.
//!
//! # `K`
//!
//! `K` is `d N x n` (`N` nodes, `n` unknowns), stored by columns. Column `j` holds, for
//! every node `i` that unknown `j` moves, the components of `b_ij` in rows
//! `d i .. d i + d`: all `d` of them, explicit zeros included, so that a direction can
//! change without changing the pattern ([`DofMap::set_direction`]: a tangent plane
//! follows the target's normal). The coordinate-axis unknowns of a free node
//! ([`DofBuilder::free`]) are the exception: they store their single `1`. A row of `K`
//! (component `c` of node `i`) has one entry per term of node `i` that stores component
//! `c`: at most one for the maps of [`DofConstraints`] (free, fixed, sliding and shared
//! nodes), several in general (a node in a tangent plane of R^3, a node moved by a shared
//! offset as well).
//!
//! # Numbering
//!
//! Unknowns are numbered in the order the builder declares them
//! ([`DofBuilder::free`] declares `d` consecutive unknowns, one per axis;
//! [`DofBuilder::span`] one per direction, in order). Terms are numbered node by node, and
//! within a node in increasing order of their unknowns ([`DofMap::terms`]).
//! [`DofMap::real`] and [`DofMap::complex`] declare the unknowns group by group (a node
//! alone, or the nodes joined by [`DofConstraints::share`]), in increasing order of each
//! group's smallest node: a free group gets two consecutive unknowns in the real form
//! (real part, then imaginary part) and one in the complex form, a sliding group one.
//!
//! # `K^H A^H W A K` without a product
//!
//! [`crate::least_squares::LeastSquaresSolver`] forms the normal equations
//! `K^H A^H W A K y = K^H A^H W (b - A x0)` without a sparse-sparse product: every entry
//! `A[r, l]` adds `A[r, l] K[l, j]` into `B[r, j]` of `B = A K`, once per entry of row `l`
//! of `K` (the target entry of `B` of each such pair is found once per pattern), and
//! `B^H W B` is summed row by row of `B` into the precomputed positions of its lower
//! triangle (the `least_squares::normal` module). Solvers that assemble their own normal
//! equations (the Beltrami flow) do the same face by face: the local unknowns of an
//! element are the unknowns of its nodes' terms, the coefficient of unknown `j` is the
//! sum over the element's nodes `i` of the element's row acting on `b_ij`.

use beltrami_mesh::VertexId;
use beltrami_sparse::{Scalar, SolveError, SolveOptions, solve_spd};
use faer::MatRef;
use faer::sparse::{CreationError, SparseColMat, SparseColMatRef, SymbolicSparseColMat, Triplet};
use num_complex::Complex64;
use std::ops::Range;
use thiserror::Error;

/// Relative tolerance for geometric coincidences: two fixed values of one group are the
/// same point, a fixed value lies on a sliding line, two sliding lines are the same line,
/// when they agree to `GEOMETRIC_TOLERANCE * scale` with
/// `scale = max(1, |values involved|)`; directions at one node are dependent when one of
/// them is within `GEOMETRIC_TOLERANCE` times its length of the span of the others.
/// Constraints computed by different formulas for the same point differ by rounding
/// only, far below this.
pub const GEOMETRIC_TOLERANCE: f64 = 1e-12;

/// The scalar of a DOF map: `f64` (real components: two per planar node in the real
/// form, three per spatial node) or [`Complex64`] (the complex form, one unknown per
/// planar node), with how a node's planar position sits in a nodal vector of that form.
pub trait DofScalar: Scalar {
    /// Nodal unknowns per planar node: 2 for `f64` (`[re, im]`), 1 for `Complex64`.
    const PER_NODE: usize;

    /// The complex position of node `node` read from a full nodal vector `x` of this
    /// form: `x[node]` (complex form) or `x[2 node] + i x[2 node + 1]` (real form).
    /// The caller guarantees `x.len() >= PER_NODE * (node + 1)`.
    fn node_position(x: &[Self], node: usize) -> Complex64;

    /// Writes the complex position `z` into node `node` of a full nodal vector `x` of
    /// this form, the inverse of [`DofScalar::node_position`]. The caller guarantees
    /// `x.len() >= PER_NODE * (node + 1)`.
    fn set_node_position(x: &mut [Self], node: usize, z: Complex64);
}

impl DofScalar for f64 {
    const PER_NODE: usize = 2;

    #[inline]
    fn node_position(x: &[Self], node: usize) -> Complex64 {
        Complex64::new(x[2 * node], x[2 * node + 1])
    }

    #[inline]
    fn set_node_position(x: &mut [Self], node: usize, z: Complex64) {
        x[2 * node] = z.re;
        x[2 * node + 1] = z.im;
    }
}

impl DofScalar for Complex64 {
    const PER_NODE: usize = 1;

    #[inline]
    fn node_position(x: &[Self], node: usize) -> Complex64 {
        x[node]
    }

    #[inline]
    fn set_node_position(x: &mut [Self], node: usize, z: Complex64) {
        x[node] = z;
    }
}

/// Why constraints could not become a DOF map, or a vector does not fit one. Every
/// variant about a node names it (the mesh vertex).
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
    /// More nodes than a [`VertexId`] can index (or whose components overflow `usize`).
    #[error("{n_nodes} nodes exceed the u32 vertex index range")]
    TooManyNodes {
        /// Number of nodes asked for.
        n_nodes: usize,
    },
    /// A map whose nodes have no component.
    #[error("nodes need at least one component; got dimension 0")]
    ZeroDimension,
    /// A value given for a node with a number of components other than the map's.
    #[error("the {what} given for vertex {node} has {got} components, expected {expected}")]
    Components {
        /// The node.
        node: VertexId,
        /// "origin" or "direction".
        what: &'static str,
        /// The map's components per node.
        expected: usize,
        /// Components given.
        got: usize,
    },
    /// A fixed value, origin, sliding point or direction with a NaN or infinite part.
    #[error("the {what} given for vertex {node} is not finite")]
    NonFinite {
        /// The node.
        node: VertexId,
        /// "fixed value", "sliding point", "sliding direction", "origin" or "direction".
        what: &'static str,
    },
    /// A sliding direction of length zero.
    #[error("the sliding direction of vertex {node} is zero")]
    ZeroDirection {
        /// The node.
        node: VertexId,
    },
    /// An unknown declared without nodes: nothing would depend on it.
    #[error("unknown {dof} moves no vertex")]
    NoNodes {
        /// The unknown.
        dof: usize,
    },
    /// A node listed twice in one unknown.
    #[error("vertex {node} is listed twice in unknown {dof}")]
    RepeatedNode {
        /// The node.
        node: VertexId,
        /// The unknown.
        dof: usize,
    },
    /// The directions of the unknowns moving one node are linearly dependent (one of them
    /// is within [`GEOMETRIC_TOLERANCE`] of the span of the others, or zero, or there are
    /// more directions than components): `K` would not have full column rank.
    #[error("the directions of the unknowns moving vertex {node} are linearly dependent")]
    DependentDirections {
        /// The node.
        node: VertexId,
    },
    /// A term index `>=` the number of terms of the map.
    #[error("term {term} does not exist: the map has {terms} terms")]
    TermOutOfRange {
        /// The term asked for.
        term: usize,
        /// Number of terms of the map.
        terms: usize,
    },
    /// A new direction for a coordinate-axis term of a free node
    /// ([`DofBuilder::free`]): its `K` entry is a structural `1`.
    #[error(
        "unknown {dof} moves vertex {node} along a coordinate axis (a free node): its direction cannot change"
    )]
    AxisDirection {
        /// The node.
        node: VertexId,
        /// The unknown.
        dof: usize,
    },
    /// [`DofMap::node_dof`] asked about a node that is not fixed, free or sliding in the
    /// sense of [`NodeDof`] (a node of a spatial map, in a tangent plane, moved by a shared
    /// offset, ...): read its terms instead ([`DofMap::terms`]).
    #[error(
        "vertex {node} is not fixed, free or sliding in the plane: read its terms (DofMap::terms)"
    )]
    GeneralNode {
        /// The node.
        node: VertexId,
    },
    /// Complex positions asked of a map whose nodes are not planar in its scalar
    /// (`dim != DofScalar::PER_NODE`).
    #[error("the map has {dim} components per node: complex positions exist for planar maps only")]
    NotPlanar {
        /// The map's components per node.
        dim: usize,
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
    /// Building a sparse matrix (`K^H K` for [`DofMap::reduce`]) failed (index overflow or
    /// allocation).
    #[error("building a sparse matrix failed: {0}")]
    Sparse(#[from] CreationError),
    /// [`DofMap::reduce`] could not solve `K^H K y = K^H (x - x0)`: directions set by
    /// [`DofMap::set_direction`] made `K` rank deficient.
    #[error("reducing a nodal vector failed: {0}")]
    Reduce(SolveError),
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

/// A node moved by an unknown, as declared: the axis `c` of a free node's unknown (`K`
/// stores its single `1`), or `None` for a general direction (`K` stores all components).
#[derive(Debug, Clone, Copy)]
struct Member {
    node: usize,
    axis: Option<usize>,
}

/// The general statement of a DOF map: per node an origin, and unknowns each moving one
/// or several nodes along per-node directions (module docs). Build the map with
/// [`DofBuilder::build`].
///
/// A node no unknown moves stays at its origin (fixed); every origin starts at zero.
/// Each method validates its input at once (node range, components, finiteness, a node
/// listed twice) and, on error, leaves the builder as it was; the independence of the
/// directions at each node is checked by [`build`](Self::build), which sees them all.
///
/// ```
/// use beltrami_fem::dof::DofBuilder;
/// use beltrami_mesh::VertexId;
///
/// // Four nodes in R^3: node 0 fixed at (1, 0, 0), node 1 free, node 2 in the plane
/// // z = 2, node 3 on a line through the origin, and one offset moving nodes 2 and 3
/// // along the z axis.
/// let mut builder = DofBuilder::<f64>::new(4, 3).unwrap();
/// builder.origin(VertexId(0), &[1.0, 0.0, 0.0]).unwrap();
/// let free = builder.free(&[VertexId(1)]).unwrap();
/// let plane = builder
///     .span(VertexId(2), &[0.0, 0.0, 2.0], [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
///     .unwrap();
/// let line = builder.span(VertexId(3), &[0.0; 3], [[1.0, 1.0, 0.0]]).unwrap();
/// let offset = builder
///     .unknown([(VertexId(2), [0.0, 0.0, 1.0]), (VertexId(3), [0.0, 0.0, 1.0])])
///     .unwrap();
/// assert_eq!((free, plane, line, offset), (0..3, 3..5, 5..6, 6));
/// let dofs = builder.build().unwrap();
/// let x = dofs.expand(&[1.0, 2.0, 3.0, 0.5, 0.25, 2.0, 1.0]).unwrap();
/// assert_eq!(x, [1.0, 0.0, 0.0, 1.0, 2.0, 3.0, 0.5, 0.25, 3.0, 2.0, 2.0, 1.0]);
/// ```
#[derive(Debug, Clone)]
pub struct DofBuilder<T: DofScalar> {
    n_nodes: usize,
    dim: usize,
    /// `x0`, `dim` entries per node.
    x0: Vec<T>,
    /// The members of unknown `j` are `members[member_ptr[j]..member_ptr[j + 1]]`.
    member_ptr: Vec<usize>,
    members: Vec<Member>,
    /// The direction of each member, `dim` entries each.
    directions: Vec<T>,
}

impl<T: DofScalar> DofBuilder<T> {
    /// `n_nodes` nodes with `dim` components of `T` each (`dim = 2` or `3` real
    /// components, `1` complex), all fixed at the origin `0` until stated otherwise.
    /// Errors: [`DofError::ZeroDimension`], [`DofError::TooManyNodes`].
    pub fn new(n_nodes: usize, dim: usize) -> Result<Self, DofError> {
        if dim == 0 {
            return Err(DofError::ZeroDimension);
        }
        let full = n_nodes
            .checked_mul(dim)
            .filter(|_| u32::try_from(n_nodes).is_ok())
            .ok_or(DofError::TooManyNodes { n_nodes })?;
        Ok(Self {
            n_nodes,
            dim,
            x0: vec![T::from_f64(0.0); full],
            member_ptr: vec![0],
            members: Vec::new(),
            directions: Vec::new(),
        })
    }

    /// Number of nodes.
    pub fn n_nodes(&self) -> usize {
        self.n_nodes
    }

    /// Components of `T` per node.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Number of unknowns declared so far (the index the next one gets).
    pub fn unknowns(&self) -> usize {
        self.member_ptr.len() - 1
    }

    /// Sets the origin `x0_node` (`dim` components).
    pub fn origin(&mut self, node: VertexId, value: &[T]) -> Result<&mut Self, DofError> {
        let i = check_node(node, self.n_nodes)?;
        check_value(node, "origin", self.dim, value)?;
        self.x0[self.dim * i..self.dim * (i + 1)].copy_from_slice(value);
        Ok(self)
    }

    /// The nodes move together anywhere in `T^dim`: `dim` new unknowns, unknown
    /// `first + c` moving every node of `nodes` along the coordinate axis `e_c` (`K` entry
    /// `1`). One node is a free node; several are the copies of a seam vertex (identical
    /// directions; their origins may differ, by a period for instance). Returns the new
    /// unknowns `first..first + dim`.
    pub fn free(&mut self, nodes: &[VertexId]) -> Result<Range<usize>, DofError> {
        let first = self.unknowns();
        for c in 0..self.dim {
            let start = self.members.len();
            let pushed = nodes
                .iter()
                .try_for_each(|&node| self.push_member(node, None, Some(c)));
            if let Err(e) = self.close(start, pushed) {
                self.truncate(first);
                return Err(e);
            }
        }
        Ok(first..first + self.dim)
    }

    /// A new unknown `y_j` moving each of `members` (node, direction with `dim`
    /// components) along its direction: `x_node += y_j direction`. One member slides a
    /// node along a line; members with different directions share an offset (the radius
    /// of a circle moves its nodes along their own normals). Returns `j`.
    ///
    /// Directions may be refilled later with the same pattern
    /// ([`DofMap::set_direction`]); all their components are stored in `K`.
    pub fn unknown<D: AsRef<[T]>>(
        &mut self,
        members: impl IntoIterator<Item = (VertexId, D)>,
    ) -> Result<usize, DofError> {
        let j = self.unknowns();
        self.declare(members)?;
        Ok(j)
    }

    /// Node `node` at `origin` plus one new unknown per direction:
    /// `x_node = origin + sum_k y_(first + k) directions[k]`. No direction fixes the node,
    /// one makes it slide along a line, two move it in a plane (the tangent plane of a
    /// surface in R^3), `dim` independent ones free it in a basis of its own. Returns the
    /// new unknowns `first..first + k`.
    pub fn span<D: AsRef<[T]>>(
        &mut self,
        node: VertexId,
        origin: &[T],
        directions: impl IntoIterator<Item = D>,
    ) -> Result<Range<usize>, DofError> {
        let i = check_node(node, self.n_nodes)?;
        check_value(node, "origin", self.dim, origin)?;
        let first = self.unknowns();
        for direction in directions {
            if let Err(e) = self.declare([(node, direction)]) {
                self.truncate(first);
                return Err(e);
            }
        }
        self.x0[self.dim * i..self.dim * (i + 1)].copy_from_slice(origin);
        Ok(first..self.unknowns())
    }

    /// Appends one unknown moving `members` along their directions; on error the
    /// builder is unchanged.
    fn declare<D: AsRef<[T]>>(
        &mut self,
        members: impl IntoIterator<Item = (VertexId, D)>,
    ) -> Result<(), DofError> {
        let start = self.members.len();
        let pushed = members.into_iter().try_for_each(|(node, direction)| {
            self.push_member(node, Some(direction.as_ref()), None)
        });
        self.close(start, pushed)
    }

    /// Appends a member of the unknown being declared: along `direction`, or along the
    /// coordinate axis `axis` when `direction` is `None`.
    fn push_member(
        &mut self,
        node: VertexId,
        direction: Option<&[T]>,
        axis: Option<usize>,
    ) -> Result<(), DofError> {
        let i = check_node(node, self.n_nodes)?;
        match direction {
            Some(direction) => {
                check_value(node, "direction", self.dim, direction)?;
                self.directions.extend_from_slice(direction);
            }
            None => self.directions.extend(
                (0..self.dim).map(|k| T::from_f64(if Some(k) == axis { 1.0 } else { 0.0 })),
            ),
        }
        self.members.push(Member { node: i, axis });
        Ok(())
    }

    /// Ends the declaration of the unknown whose members start at `start`: checks that it
    /// moves a node and no node twice, then records it; on error (or an error `pushed`
    /// while adding the members) forgets its members.
    fn close(&mut self, start: usize, pushed: Result<(), DofError>) -> Result<(), DofError> {
        let dof = self.unknowns();
        let checked = pushed.and_then(|()| match self.members.len() - start {
            0 => Err(DofError::NoNodes { dof }),
            1 => Ok(()),
            _ => {
                let mut nodes: Vec<usize> = self.members[start..].iter().map(|m| m.node).collect();
                nodes.sort_unstable();
                match nodes.windows(2).find(|w| w[0] == w[1]) {
                    Some(w) => Err(DofError::RepeatedNode {
                        node: VertexId::from_usize(w[0]),
                        dof,
                    }),
                    None => Ok(()),
                }
            }
        });
        match checked {
            Ok(()) => self.member_ptr.push(self.members.len()),
            Err(_) => {
                self.members.truncate(start);
                self.directions.truncate(self.dim * start);
            }
        }
        checked
    }

    /// Forgets the unknowns from `unknowns` on.
    fn truncate(&mut self, unknowns: usize) {
        self.member_ptr.truncate(unknowns + 1);
        let members = self.member_ptr[unknowns];
        self.members.truncate(members);
        self.directions.truncate(self.dim * members);
    }

    /// The DOF map: `K` (module docs), `x0`, and the terms of every node. Errors:
    /// [`DofError::DependentDirections`] for a node whose directions are dependent.
    pub fn build(self) -> Result<DofMap<T>, DofError> {
        let (dim, n_nodes, n) = (self.dim, self.n_nodes, self.unknowns());
        // Terms node by node, each node's in increasing order of their unknowns: a
        // counting sort of the members, visited unknown by unknown.
        let mut term_ptr = vec![0usize; n_nodes + 1];
        for m in &self.members {
            term_ptr[m.node + 1] += 1;
        }
        for i in 0..n_nodes {
            term_ptr[i + 1] += term_ptr[i];
        }
        let mut next = term_ptr[..n_nodes].to_vec();
        let mut terms = vec![
            TermInfo {
                dof: 0,
                slot: 0,
                axis: None,
            };
            self.members.len()
        ];
        let mut directions = vec![T::from_f64(0.0); self.directions.len()];
        let mut member_term = vec![0usize; self.members.len()];
        for j in 0..n {
            let (start, end) = (self.member_ptr[j], self.member_ptr[j + 1]);
            for (m, &Member { node, axis }) in (start..end).zip(&self.members[start..end]) {
                let t = next[node];
                next[node] += 1;
                terms[t] = TermInfo {
                    dof: j,
                    slot: 0,
                    axis,
                };
                directions[dim * t..dim * (t + 1)]
                    .copy_from_slice(&self.directions[dim * m..dim * (m + 1)]);
                member_term[m] = t;
            }
        }
        let mut scratch = Vec::new();
        for i in 0..n_nodes {
            let range = dim * term_ptr[i]..dim * term_ptr[i + 1];
            if !independent(&directions[range], dim, &mut scratch) {
                return Err(DofError::DependentDirections {
                    node: VertexId::from_usize(i),
                });
            }
        }

        // K column by column, the rows of a column in increasing node order.
        let mut col_ptr = Vec::with_capacity(n + 1);
        col_ptr.push(0);
        let nnz = self
            .members
            .iter()
            .map(|m| if m.axis.is_some() { 1 } else { dim })
            .sum();
        let mut row_idx = Vec::with_capacity(nnz);
        let mut values = Vec::with_capacity(nnz);
        let mut dof_nodes = Vec::with_capacity(n);
        let mut row_entries = vec![0u8; dim * n_nodes];
        let mut column: Vec<usize> = Vec::new();
        for j in 0..n {
            column.clear();
            column.extend(self.member_ptr[j]..self.member_ptr[j + 1]);
            column.sort_unstable_by_key(|&m| self.members[m].node);
            dof_nodes.push(VertexId::from_usize(self.members[column[0]].node));
            for &m in &column {
                let Member { node, axis } = self.members[m];
                let t = member_term[m];
                terms[t].slot = values.len();
                let components = match axis {
                    Some(c) => c..c + 1,
                    None => 0..dim,
                };
                for c in components {
                    row_idx.push(dim * node + c);
                    values.push(directions[dim * t + c]);
                    row_entries[dim * node + c] = row_entries[dim * node + c].saturating_add(1);
                }
            }
            col_ptr.push(row_idx.len());
        }
        let symbolic = SymbolicSparseColMat::new_checked(dim * n_nodes, n, col_ptr, None, row_idx);
        Ok(DofMap {
            n_nodes,
            dim,
            term_ptr,
            terms,
            directions,
            dof_nodes,
            diagonal: row_entries.iter().all(|&r| r <= 1),
            k: SparseColMat::new(symbolic, values),
            x0: self.x0,
        })
    }
}

fn check_node(node: VertexId, n_nodes: usize) -> Result<usize, DofError> {
    let i = node.idx();
    if i < n_nodes {
        Ok(i)
    } else {
        Err(DofError::NodeOutOfRange { node, n_nodes })
    }
}

fn check_value<T: DofScalar>(
    node: VertexId,
    what: &'static str,
    dim: usize,
    value: &[T],
) -> Result<(), DofError> {
    if value.len() != dim {
        return Err(DofError::Components {
            node,
            what,
            expected: dim,
            got: value.len(),
        });
    }
    if value.iter().all(|v| v.finite()) {
        Ok(())
    } else {
        Err(DofError::NonFinite { node, what })
    }
}

/// Whether the directions (`dim` components each, one after the other) are linearly
/// independent: modified Gram-Schmidt leaves each direction, once its components along
/// the previous ones are removed, longer than [`GEOMETRIC_TOLERANCE`] times its length.
/// `scratch` holds the orthonormalized directions.
fn independent<T: DofScalar>(directions: &[T], dim: usize, scratch: &mut Vec<T>) -> bool {
    let k = directions.len() / dim;
    if k > dim {
        return false;
    }
    scratch.clear();
    scratch.extend_from_slice(directions);
    for a in 0..k {
        let (done, rest) = scratch.split_at_mut(dim * a);
        let v = &mut rest[..dim];
        let length_sqr: f64 = v.iter().map(|x| x.norm_sqr()).sum();
        for q in done.chunks_exact(dim) {
            let along = q
                .iter()
                .zip(v.iter())
                .fold(T::from_f64(0.0), |s, (&q, &v)| s + q.conjugate() * v);
            for (v, &q) in v.iter_mut().zip(q) {
                *v -= along * q;
            }
        }
        let left_sqr: f64 = v.iter().map(|x| x.norm_sqr()).sum();
        if left_sqr.is_nan() || left_sqr <= GEOMETRIC_TOLERANCE * GEOMETRIC_TOLERANCE * length_sqr {
            return false;
        }
        let scale = T::from_f64(1.0 / left_sqr.sqrt());
        v.iter_mut().for_each(|x| *x *= scale);
    }
    true
}

/// What a planar node became in a [`DofMap`] built from [`DofConstraints`], read by
/// [`DofMap::node_dof`].
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
    /// Real form only: `x_node = point + y[dof] * direction` (`|direction| = 1` for the
    /// slides of [`DofConstraints`]).
    Sliding {
        /// The reduced unknown `t`.
        dof: usize,
        /// Point of the line (`t = 0`).
        point: Complex64,
        /// Direction of the line.
        direction: Complex64,
    },
}

/// One term `y_dof b` of a node's value (module docs), read by [`DofMap::term`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DofTerm<'a, T> {
    /// The reduced unknown `j`.
    pub dof: usize,
    /// The direction `b` (`dim` components).
    pub direction: &'a [T],
}

/// A term as stored: its unknown, the index of its first entry in the values of `K`, and
/// the axis of a free node's unknown (`K` stores only that component).
#[derive(Debug, Clone, Copy)]
struct TermInfo {
    dof: usize,
    slot: usize,
    axis: Option<usize>,
}

/// An affine DOF map `x = K y + x0` (module docs: nodes and terms, `K`, numbering).
///
/// `T = f64` with `dim` real components per node (the real form of a planar map,
/// `dim = 2`, or spatial nodes, `dim = 3`), or `T = Complex64` with one complex component
/// per node (the complex form). Built by [`DofBuilder::build`], [`DofMap::real`] or
/// [`DofMap::complex`]. The origins and the directions can be refilled in place
/// ([`DofMap::set_origin`], [`DofMap::set_direction`]): the pattern of `K`, the
/// numbering and the terms stay.
#[derive(Debug, Clone)]
pub struct DofMap<T: DofScalar> {
    n_nodes: usize,
    dim: usize,
    /// The terms of node `i` are `terms[term_ptr[i]..term_ptr[i + 1]]`.
    term_ptr: Vec<usize>,
    terms: Vec<TermInfo>,
    /// The direction of each term, `dim` entries each (also in the values of `k`).
    directions: Vec<T>,
    /// The smallest node each reduced unknown moves (to name it in messages).
    dof_nodes: Vec<VertexId>,
    /// Whether every row of `K` has at most one entry, so that `K^H K` is diagonal.
    diagonal: bool,
    k: SparseColMat<usize, T>,
    x0: Vec<T>,
}

impl<T: DofScalar> DofMap<T> {
    /// Number of nodes.
    pub fn n_nodes(&self) -> usize {
        self.n_nodes
    }

    /// Components of `T` per node: 1 for the complex form, 2 for the real form, 3 for
    /// spatial nodes.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Length of a full nodal vector `x`: `dim * n_nodes`. The number of rows of `K`.
    pub fn full_len(&self) -> usize {
        self.x0.len()
    }

    /// Number of reduced unknowns `y`: the number of columns of `K`.
    pub fn reduced_len(&self) -> usize {
        self.dof_nodes.len()
    }

    /// `K` (`full_len x reduced_len`; module docs for its entries).
    pub fn k(&self) -> SparseColMatRef<'_, usize, T> {
        self.k.as_ref()
    }

    /// `x0` (`full_len`): the origins of the nodes (the fixed values, the points of the
    /// sliding lines, ...).
    pub fn x0(&self) -> &[T] {
        &self.x0
    }

    fn node_index(&self, node: VertexId) -> Result<usize, DofError> {
        check_node(node, self.n_nodes)
    }

    /// The origin `x0_node` (`dim` components).
    pub fn origin(&self, node: VertexId) -> Result<&[T], DofError> {
        let i = self.node_index(node)?;
        Ok(&self.x0[self.dim * i..self.dim * (i + 1)])
    }

    /// Sets the origin `x0_node` (`dim` components, finite): a known value that moves,
    /// such as the prescribed displacement of a fixed node.
    pub fn set_origin(&mut self, node: VertexId, value: &[T]) -> Result<(), DofError> {
        let i = self.node_index(node)?;
        check_value(node, "origin", self.dim, value)?;
        self.x0[self.dim * i..self.dim * (i + 1)].copy_from_slice(value);
        Ok(())
    }

    /// The terms of `node`, as indices for [`term`](Self::term) and
    /// [`set_direction`](Self::set_direction): consecutive, node after node, in
    /// increasing order of their unknowns.
    pub fn terms(&self, node: VertexId) -> Result<Range<usize>, DofError> {
        let i = self.node_index(node)?;
        Ok(self.term_ptr[i]..self.term_ptr[i + 1])
    }

    /// The terms of `node` with their indices, `(t, term)`, in increasing order of their
    /// unknowns.
    pub fn node_terms(
        &self,
        node: VertexId,
    ) -> Result<impl Iterator<Item = (usize, DofTerm<'_, T>)> + '_, DofError> {
        let range = self.terms(node)?;
        Ok(range.map(|t| {
            (
                t,
                DofTerm {
                    dof: self.terms[t].dof,
                    direction: &self.directions[self.dim * t..self.dim * (t + 1)],
                },
            )
        }))
    }

    /// The directions of all terms, `dim` components each, term after term (term `t` at
    /// `dim t..dim (t + 1)`): for loops over many terms whose indices they hold.
    pub fn directions(&self) -> &[T] {
        &self.directions
    }

    /// Term `t` (`None` if `t` is not a term): its unknown and its direction.
    pub fn term(&self, t: usize) -> Option<DofTerm<'_, T>> {
        let info = self.terms.get(t)?;
        Some(DofTerm {
            dof: info.dof,
            direction: &self.directions[self.dim * t..self.dim * (t + 1)],
        })
    }

    /// Sets the direction of term `t` (`dim` components, finite), in the stored
    /// directions and in `K`: a tangent basis that follows the target, the normal of a
    /// curve that moves. The pattern of `K` does not change. The independence of a node's
    /// directions is not checked again (hot loops call this every step): dependent
    /// directions make a least-squares problem singular, which its solver reports.
    /// Errors: [`DofError::TermOutOfRange`], [`DofError::AxisDirection`] for a free
    /// node's axis, [`DofError::Components`], [`DofError::NonFinite`].
    pub fn set_direction(&mut self, t: usize, direction: &[T]) -> Result<(), DofError> {
        let info = *self.terms.get(t).ok_or(DofError::TermOutOfRange {
            term: t,
            terms: self.terms.len(),
        })?;
        if info.axis.is_some()
            || direction.len() != self.dim
            || !direction.iter().all(|v| v.finite())
        {
            // The node whose terms hold t, to name it (looked up on errors only: hot
            // loops call this for every term).
            let node = VertexId::from_usize(self.term_ptr.partition_point(|&p| p <= t) - 1);
            if info.axis.is_some() {
                return Err(DofError::AxisDirection {
                    node,
                    dof: info.dof,
                });
            }
            check_value(node, "direction", self.dim, direction)?;
        }
        let dim = self.dim;
        self.directions[dim * t..dim * (t + 1)].copy_from_slice(direction);
        self.k.val_mut()[info.slot..info.slot + dim].copy_from_slice(direction);
        Ok(())
    }

    /// The nodes reduced unknown `dof` moves, in increasing order (`None` if `dof >=
    /// reduced_len()`).
    pub fn unknown_nodes(&self, dof: usize) -> Option<impl Iterator<Item = VertexId> + '_> {
        if dof >= self.reduced_len() {
            return None;
        }
        let dim = self.dim;
        let rows = self.k.as_ref().row_idx_of_col_raw(dof);
        Some(
            rows.iter()
                .enumerate()
                .filter(move |&(e, &row)| e == 0 || rows[e - 1] / dim != row / dim)
                .map(move |(_, &row)| VertexId::from_usize(row / dim)),
        )
    }

    /// What a planar `node` became, in the vocabulary of [`DofConstraints`]: fixed, free
    /// (the coordinate axes) or sliding (the real form's single direction). Errors:
    /// [`DofError::NodeOutOfRange`]; [`DofError::GeneralNode`] for a node of a
    /// non-planar map or with other terms (read those with [`terms`](Self::terms)).
    pub fn node_dof(&self, node: VertexId) -> Result<NodeDof, DofError> {
        let i = self.node_index(node)?;
        let (start, end) = (self.term_ptr[i], self.term_ptr[i + 1]);
        let terms = &self.terms[start..end];
        let planar = self.dim == T::PER_NODE;
        let origin = || T::node_position(&self.x0, i);
        match terms {
            [] if planar => Ok(NodeDof::Fixed { value: origin() }),
            [first, ..]
                if planar
                    && terms.len() == self.dim
                    && terms
                        .iter()
                        .enumerate()
                        .all(|(c, t)| t.axis == Some(c) && t.dof == first.dof + c) =>
            {
                Ok(NodeDof::Free { dof: first.dof })
            }
            [term] if planar && T::PER_NODE == 2 && term.axis.is_none() => Ok(NodeDof::Sliding {
                dof: term.dof,
                point: origin(),
                direction: T::node_position(&self.directions, start),
            }),
            _ => Err(DofError::GeneralNode { node }),
        }
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

    /// `x = K y + x0`, written into `x` (no allocation): `x0`, then the columns of `K`
    /// in increasing order.
    pub fn expand_into(&self, y: &[T], x: &mut [T]) -> Result<(), DofError> {
        check_len("y", self.reduced_len(), y.len())?;
        check_len("x", self.full_len(), x.len())?;
        x.copy_from_slice(&self.x0);
        let k = self.k.as_ref();
        for (j, &yj) in y.iter().enumerate() {
            for (&row, &coef) in k.row_idx_of_col_raw(j).iter().zip(k.val_of_col(j)) {
                x[row] += coef * yj;
            }
        }
        Ok(())
    }

    /// The least-squares inverse of [`expand`](Self::expand):
    /// `y = (K^H K)^{-1} K^H (x - x0)`. Exact (`expand(reduce(x)) = x`) when `x`
    /// satisfies the constraints; otherwise the nearest admissible `y` (shared nodes are
    /// averaged, a sliding node is projected on its line, a node in a plane on the
    /// plane). Use it to start an iterative solver from a given map.
    ///
    /// When every row of `K` has at most one entry (the maps of [`DofConstraints`]),
    /// `K^H K` is diagonal and `y_j = K_j^H (x - x0) / |K_j|^2`; otherwise `K^H K` (summed
    /// node by node over the pairs of its terms, `sum_i <b_ij, b_ij'>`) is factored by a
    /// sparse Cholesky factorization. Errors: [`DofError::Length`], and
    /// [`DofError::Reduce`] when refilled directions made `K` rank deficient.
    pub fn reduce(&self, x: &[T]) -> Result<Vec<T>, DofError> {
        check_len("x", self.full_len(), x.len())?;
        let dim = self.dim;
        let n = self.reduced_len();
        let zero = T::from_f64(0.0);
        // K^H (x - x0), node by node.
        let mut y = vec![zero; n];
        for i in 0..self.n_nodes {
            let residual = |c: usize| x[dim * i + c] - self.x0[dim * i + c];
            for t in self.term_ptr[i]..self.term_ptr[i + 1] {
                let info = self.terms[t];
                let b = &self.directions[dim * t..dim * (t + 1)];
                y[info.dof] += match info.axis {
                    Some(c) => residual(c),
                    None => (0..dim).fold(zero, |s, c| s + b[c].conjugate() * residual(c)),
                };
            }
        }
        if self.diagonal {
            let k = self.k.as_ref();
            let norm_sqr: Vec<f64> = (0..n)
                .map(|j| k.val_of_col(j).iter().map(|v| v.norm_sqr()).sum())
                .collect();
            // A column refilled to zero leaves K^H K singular: the factorization below
            // reports it.
            if norm_sqr.iter().all(|&norm| norm > 0.0) {
                for (yj, norm) in y.iter_mut().zip(&norm_sqr) {
                    *yj *= T::from_f64(1.0 / norm);
                }
                return Ok(y);
            }
        }
        // K^H K (lower triangle), node by node over the pairs of its terms (increasing
        // unknowns, so the pair (a, b), b <= a, is below the diagonal).
        let mut triplets = Vec::new();
        for i in 0..self.n_nodes {
            let (start, end) = (self.term_ptr[i], self.term_ptr[i + 1]);
            for a in start..end {
                let ba = &self.directions[dim * a..dim * (a + 1)];
                for b in start..=a {
                    let bb = &self.directions[dim * b..dim * (b + 1)];
                    let value = (0..dim).fold(zero, |s, c| s + ba[c].conjugate() * bb[c]);
                    triplets.push(Triplet::new(self.terms[a].dof, self.terms[b].dof, value));
                }
            }
        }
        let gram = SparseColMat::try_new_from_triplets(n, n, &triplets)?;
        let solution = solve_spd(
            gram.as_ref(),
            MatRef::from_column_major_slice(&y, n, 1),
            SolveOptions::default(),
        )
        .map_err(DofError::Reduce)?;
        Ok((0..n).map(|j| solution[(j, 0)]).collect())
    }

    /// The image of `node` as a complex number, read from a full vector `x` of a planar
    /// map (`dim = DofScalar::PER_NODE`; else [`DofError::NotPlanar`]).
    pub fn node_position(&self, x: &[T], node: VertexId) -> Result<Complex64, DofError> {
        self.check_planar()?;
        check_len("x", self.full_len(), x.len())?;
        let i = self.node_index(node)?;
        Ok(T::node_position(x, i))
    }

    /// All node images of a full vector `x` of a planar map as complex numbers (the
    /// identity for the complex form, pairs `[re, im]` joined for the real form).
    pub fn positions(&self, x: &[T]) -> Result<Vec<Complex64>, DofError> {
        self.check_planar()?;
        check_len("x", self.full_len(), x.len())?;
        Ok((0..self.n_nodes).map(|i| T::node_position(x, i)).collect())
    }

    fn check_planar(&self) -> Result<(), DofError> {
        if self.dim == T::PER_NODE {
            Ok(())
        } else {
            Err(DofError::NotPlanar { dim: self.dim })
        }
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

/// The groups of nodes joined by shares, each with the admissible set its constraints
/// leave: group `g` is `nodes[ptr[g]..ptr[g + 1]]` (increasing), with set `sets[g]`;
/// groups come in increasing order of their smallest node.
struct Groups {
    nodes: Vec<VertexId>,
    ptr: Vec<usize>,
    sets: Vec<GroupSet>,
}

/// Resolves the constraints into groups for the given form.
fn resolve(
    n_nodes: usize,
    constraints: &DofConstraints,
    complex_form: bool,
) -> Result<Groups, DofError> {
    let mut parent: Vec<usize> = (0..n_nodes).collect();
    for &(a, b) in &constraints.shares {
        for node in [a, b] {
            check_node(node, n_nodes)?;
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

    // Roots are visited in increasing order, and a root is its group's smallest node.
    let mut group = vec![0usize; n_nodes];
    let mut ptr = vec![0usize];
    let mut group_sets = Vec::new();
    for i in 0..n_nodes {
        if parent[i] == i {
            group[i] = group_sets.len();
            group_sets.push(sets[i]);
            ptr.push(0);
        }
        ptr[group[parent[i]] + 1] += 1;
    }
    for g in 0..group_sets.len() {
        ptr[g + 1] += ptr[g];
    }
    let mut next = ptr[..group_sets.len()].to_vec();
    let mut nodes = vec![VertexId(0); n_nodes];
    for i in 0..n_nodes {
        let g = group[parent[i]];
        nodes[next[g]] = VertexId::from_usize(i);
        next[g] += 1;
    }
    Ok(Groups {
        nodes,
        ptr,
        sets: group_sets,
    })
}

impl<T: DofScalar> DofMap<T> {
    /// The planar map of `constraints` in the form of `T`: the groups of [`resolve`],
    /// declared on a [`DofBuilder`] in their order.
    fn planar(
        n_nodes: usize,
        constraints: &DofConstraints,
        complex_form: bool,
    ) -> Result<Self, DofError> {
        let mut builder = DofBuilder::new(n_nodes, T::PER_NODE)?;
        let groups = resolve(n_nodes, constraints, complex_form)?;
        let zero = T::from_f64(0.0);
        let components = |z: Complex64| {
            let mut value = [zero; 2];
            T::set_node_position(&mut value, 0, z);
            value
        };
        for (g, set) in groups.sets.iter().enumerate() {
            let members = &groups.nodes[groups.ptr[g]..groups.ptr[g + 1]];
            let origin = match *set {
                GroupSet::Free => None,
                GroupSet::Point { value, .. } => Some(value),
                GroupSet::Line { point, .. } => Some(point),
            };
            if let Some(origin) = origin {
                let origin = components(origin);
                for &node in members {
                    builder.origin(node, &origin[..T::PER_NODE])?;
                }
            }
            match *set {
                GroupSet::Free => {
                    builder.free(members)?;
                }
                GroupSet::Point { .. } => {}
                GroupSet::Line { direction, .. } => {
                    let direction = components(direction);
                    let direction = &direction[..T::PER_NODE];
                    builder.unknown(members.iter().map(|&node| (node, direction)))?;
                }
            }
        }
        builder.build()
    }
}

impl DofMap<f64> {
    /// The real form: `x = [re0, im0, re1, im1, ...]` (`2 n_nodes` real unknowns).
    ///
    /// - free node: `re x = y[dof]`, `im x = y[dof + 1]` (the axes, [`DofBuilder::free`]);
    /// - fixed node: `x = value` (empty rows of `K`, `x0 = [re, im]`);
    /// - sliding node: `x = p + t d`: rows `[d.re, d.im]` in the column of `t`,
    ///   `x0 = [p.re, p.im]`;
    /// - shared nodes: the same columns.
    pub fn real(n_nodes: usize, constraints: &DofConstraints) -> Result<Self, DofError> {
        Self::planar(n_nodes, constraints, false)
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
        Self::planar(n_nodes, constraints, true)
    }
}
