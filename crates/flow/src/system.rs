//! The least-squares flow system: unknowns, pattern and normal equations.
//!
//! The flow `V` is piecewise linear on the image mesh, `V_i = sum_k c_ik b_ik` at vertex
//! `i` with real unknowns `c_ik` along directions `b_ik` in R^3: two tangent directions
//! of the target for a [`Role::Free`] vertex ([`orthonormal_basis`] of the target's
//! normal at the image), the curve tangent for a [`Role::Curve`] vertex, none for a
//! [`Role::Fixed`] one; plus, for a curve with a free offset, one unknown shared by all
//! its vertices, each moved along the curve's offset direction at its image. These are
//! the terms of a DOF map `V = K c + V0` of nodes in R^3 ([`beltrami_fem::dof`]), whose
//! origins `V0` are the prescribed flow of fixed vertices pulled towards a goal (zero
//! otherwise). The unknowns and the pattern of `K` are built once; the directions move
//! with the image and are refilled in place every step.
//!
//! On image face `T`, with frame `(r, s)` and the image triangle's shape-function
//! gradients `grad N_k` in that frame,
//!
//! ```text
//! V_zbar(T) = sum_k g_k (V_k . r + i V_k . s),    g_k = (d_r N_k + i d_s N_k) / 2,
//! ```
//!
//! so `V_zbar(T) = sum_a beta_a c_a + sum_k g_k (V0_k . r + i V0_k . s)` is real-linear
//! in the unknowns, with complex coefficients `beta_a = sum_(k, b) g_k (b . r + i b . s)`
//! over the terms `c_a b` of the face's vertices `k` that carry unknown `a` (one term for
//! a vertex's own unknown, up to three for a shared offset). The flow minimizes
//! (Wong-Zhao 2014, eq. 4.4 and Appendix eq. 6.1-6.9, with the weights of
//! [`crate::flow`])
//!
//! ```text
//! E_V(c) = sum_T w_T |V_zbar(T) - rho_T|^2,
//! ```
//!
//! through its normal equations `sum_b Re(conj(beta_a) beta_b) c_b = Re(conj(beta_a) rho')`
//! (`rho' = rho_T` minus the known part of the origins): `K^T A^T W A K` of the DOF map,
//! with `A` the rows `V_zbar(T)`, summed face by face without forming `A` or `K`. The
//! matrix's pattern (which unknowns share a face) never changes: the pattern, the
//! positions of each face's entries in it and the symbolic Cholesky factorization are
//! built once, and every step refills the values in place.

use beltrami_core::SolverError;
use beltrami_fem::assembly::Pattern;
use beltrami_fem::vertex_graph::order_of_unknowns;
use beltrami_fem::{DofBuilder, DofMap, Elements};
use beltrami_mesh::{FaceId, Mesh, Point3, Vector3, VertexId};
use beltrami_sparse::{Kernel, SolveError, SolveOptions, SpdSolver};
use beltrami_sparse::{SplitOrder, fill_reducing_order, two_core_order};
use faer::sparse::SparseColMat;
use num_complex::Complex64;

use crate::measure::{
    ImageFace, TILT_FULL, TILT_START, edges_and_reference, mu_with_corner_moved, triangle,
};
use crate::target::{Role, TargetGeometry, orthonormal_basis};

/// One term of a face: face vertex `k` contributes `g_k (b . r + i b . s)` to the
/// coefficient of local unknown `local`, `b` the direction of term `term` of the DOF map.
#[derive(Debug, Clone, Copy)]
struct FaceTerm {
    k: u8,
    local: u8,
    term: u32,
}

/// The damping each diagonal entry of a damped system gains relative to itself
/// (Marquardt's scaling) when the damping relative to the mean diagonal leaves a pivot
/// singular: a vertex whose faces all stand near a fold constrains one of its two
/// tangent directions only, a rank-one block whose pivot was 4e-11 of its diagonal on
/// the bent genus-4 registration, below the singularity test; this lifts it to about
/// 1e-6. A fixed point still does not move.
const OWN_DAMPING: f64 = 1e-6;

/// The unknowns of the flow and the factorization of its normal equations.
pub struct FlowSystem {
    roles: Vec<Role>,
    /// Per vertex, whether a curve vertex at a corner of its curve moves along the
    /// tangent ahead of the corner (else the one behind): the side its last solved move
    /// pointed to ([`FlowSystem::solve`]).
    ahead: Vec<bool>,
    /// Per vertex, whether a free vertex on the target's boundary is held to it: its
    /// first unknown moves it along the boundary, its second not at all
    /// ([`FlowSystem::solve`]).
    contact: Vec<bool>,
    /// Per vertex, the target boundary's outward direction in the tangent plane at a free
    /// vertex's image where it touches the boundary (refilled every solve).
    outward: Vec<Option<Vector3<f64>>>,
    /// Per vertex, `dE_V/de` along the outward direction of a held vertex (scratch of
    /// [`FlowSystem::solve`]).
    pulls: Vec<f64>,
    /// `V = K c + V0` on the vertices, in R^3 (module docs): the unknowns, their
    /// directions (refilled every step) and the prescribed flow `V0` of fixed vertices.
    dofs: DofMap<f64>,
    /// The shared offset unknown of each curve, if the curve has one.
    offset: Vec<Option<usize>>,
    /// Per face, its vertices.
    faces: Vec<[usize; 3]>,
    /// The distinct unknowns of face `f` are `local[local_ptr[f]..local_ptr[f + 1]]`.
    local_ptr: Vec<usize>,
    local: Vec<usize>,
    /// The terms of face `f` are `face_terms[term_ptr[f]..term_ptr[f + 1]]`.
    term_ptr: Vec<usize>,
    face_terms: Vec<FaceTerm>,
    /// The coefficients `beta` of one face (scratch, as long as the longest local list).
    beta: Vec<Complex64>,
    /// The rates of one face's area against its reference normal along its local
    /// unknowns (scratch of the tilt penalty, as long as `beta`).
    rates: Vec<f64>,
    /// The normal matrix (lower triangle), refilled in place every step.
    matrix: SparseColMat<usize, f64>,
    /// Per local entry (in assembly order), its index in the matrix's values.
    slots: Vec<usize>,
    solver: SpdSolver<f64>,
    rhs: Vec<f64>,
    /// A copy of `rhs` for the conjugate-gradient attempt (scratch).
    trial: Vec<f64>,
    /// `V` as a full nodal vector of the DOF map (scratch).
    flow: Vec<f64>,
    /// Whether the factorization of this run's last matrix is kept for reuse
    /// ([`FlowSystem::forget_factorization`] clears it).
    kept: bool,
    /// Steps to solve directly before trying to reuse the factorization again.
    skip_reuse: usize,
    /// How many steps the next failed reuse makes the solver skip (doubling after each
    /// failure, reset by a success): runs where the matrix keeps changing stop wasting
    /// iterations on it.
    backoff: usize,
    /// Numeric factorizations so far.
    factorizations: usize,
    /// Conjugate-gradient iterations so far (steps solved with a kept factorization).
    cg_iterations: usize,
    /// Whether a fixed vertex has a nonzero prescribed flow (an origin of the map).
    prescribed: bool,
    /// Per unknown, the index of its diagonal entry in the matrix's values.
    diagonal: Vec<usize>,
    /// The damping `lambda / mean(diag)` of [`FlowSystem::set_damping`] (zero: none);
    /// when that leaves a pivot singular, each diagonal entry also gains
    /// [`OWN_DAMPING`] times itself.
    damping: f64,
    /// The weight `c` of [`FlowSystem::set_tilt_penalty`] (zero: none).
    tilt_penalty: f64,
    /// The right-hand side of the last solve, kept for [`FlowSystem::model_decrease`]
    /// (`rhs` holds its solution).
    rhs_before: Vec<f64>,
}

/// Relative residual at which a step solved by conjugate gradients with a kept
/// factorization is accepted.
const CG_TOLERANCE: f64 = 1e-7;

/// Conjugate-gradient iterations tried with a kept factorization before refactoring
/// (each costs about a fifth of a factorization).
const CG_ITERATIONS: usize = 4;

/// The share of the largest vertex move from which a corner vertex that turned to its
/// other side makes [`FlowSystem::solve`] solve again: a wrong side errs in the model
/// by as much as the vertex moves, so only the large movers limit the step search; the
/// others take their new side in the next step. On `mc4_face_b` onto `mc4_face_a`
/// remeshed to 100K faces, solving again for every turned vertex cost 186
/// conjugate-gradient iterations over 100 steps (a third more time in the solves), for
/// those above half the largest move 85, with the same result.
const CORNER_RESOLVE_SHARE: f64 = 0.5;

/// The most conjugate-gradient iterations a solve again after corner vertices turned
/// tries before refactoring ([`FlowSystem::solve`]): past it a factorization costs less.
const CG_TURNED_ITERATIONS: usize = 5 * CG_ITERATIONS;

impl std::fmt::Debug for FlowSystem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FlowSystem")
            .field("unknowns", &self.dofs.reduced_len())
            .field("entries", &self.slots.len())
            .field("factorizations", &self.factorizations)
            .finish_non_exhaustive()
    }
}

/// The flow of one step: a vector per vertex and an offset per curve.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Flow {
    /// `V_i` in R^3.
    pub vertex: Vec<Vector3<f64>>,
    /// The offset of each curve (0 for curves without a free offset).
    pub offset: Vec<f64>,
}

/// What a step's flow is solved at ([`FlowSystem::solve`]): the source's elements, the
/// target, the images of the source vertices with the target's normals there, the
/// image faces measured at them, and per face the weight `w_T` and target `rho_T` of
/// `E_V`.
pub struct FlowInput<'a, G> {
    /// The source mesh's elements.
    pub elements: &'a Elements,
    /// The target the images live on.
    pub target: &'a G,
    /// The image of every source vertex.
    pub image: &'a [Point3<f64>],
    /// The target's normal at every image.
    pub normals: &'a [Vector3<f64>],
    /// The image faces ([`crate::measure::image_faces`]).
    pub faces: &'a [ImageFace],
    /// `w_T` per face.
    pub weights: &'a [f64],
    /// `rho_T` per face.
    pub rho: &'a [Complex64],
}

impl<G> Clone for FlowInput<'_, G> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<G> Copy for FlowInput<'_, G> {}

/// The coordinate axes, the directions the DOF map is built with; every solve refills
/// them with the directions of the current image before assembling.
const AXES: [[f64; 3]; 2] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

impl FlowSystem {
    /// The unknowns for `roles` (one per source vertex) on `target`, and the symbolic
    /// factorization of the normal equations. Fails when no vertex can move.
    ///
    /// The DOF map declares, vertex by vertex, two unknowns for a free vertex and one
    /// for a curve vertex, then one unknown per curve with a free offset (in the order
    /// its first vertex comes) moving every vertex of the curve: the offsets come after
    /// all vertex unknowns, and each vertex's own unknowns come before its offset.
    pub fn new<G: TargetGeometry>(
        elements: &Elements,
        target: &G,
        image: &[Point3<f64>],
        roles: Vec<Role>,
        options: SolveOptions,
    ) -> Result<Self, SolverError> {
        let faces = triangles(elements);
        let order = VertexOrder::of_triangles(&faces, roles.len())?;
        Self::build(faces, target, image, roles, (options, &order))
    }

    /// [`FlowSystem::new`] with the unknowns ordered after `order`, a
    /// [`VertexOrder`] of the elements' vertices (computed once, it serves any roles).
    pub fn with_vertex_order<G: TargetGeometry>(
        elements: &Elements,
        target: &G,
        image: &[Point3<f64>],
        roles: Vec<Role>,
        options: SolveOptions,
        order: &VertexOrder,
    ) -> Result<Self, SolverError> {
        let faces = triangles(elements);
        Self::build(faces, target, image, roles, (options, order))
    }

    /// [`FlowSystem::with_vertex_order`] on the elements' `faces` ([`triangles`]).
    fn build<G: TargetGeometry>(
        faces: Vec<[usize; 3]>,
        target: &G,
        image: &[Point3<f64>],
        roles: Vec<Role>,
        (options, order): (SolveOptions, &VertexOrder),
    ) -> Result<Self, SolverError> {
        let (dofs, offset) = declare_unknowns(target, image, &roles)?;
        let n = dofs.reduced_len();
        if n == 0 {
            return Err(SolverError::invalid(
                crate::NAME,
                "every vertex is fixed: there is nothing to flow",
            ));
        }
        let FaceLayout {
            local_ptr,
            local,
            term_ptr,
            face_terms,
            mut positions,
        } = FaceLayout::new(&faces, &dofs)?;
        let longest = local_ptr.windows(2).map(|w| w[1] - w[0]).max().unwrap_or(0);
        let faces_end = positions.len();
        positions.extend((0..n).map(|i| (i, i)));
        let pattern = Pattern::new(n, n, &positions)?;
        let mut slots = pattern.slots().to_vec();
        let diagonal = slots.split_off(faces_end);
        let matrix = pattern.assemble(&vec![0.0; positions.len()])?;
        if order.0.order.len() != roles.len() {
            return Err(SolverError::invalid(
                crate::NAME,
                format!(
                    "the vertex order has {} vertices for {}",
                    order.0.order.len(),
                    roles.len()
                ),
            ));
        }
        let order = order_of_unknowns(&order.0, &dofs)?;
        // A free vertex's two unknowns make a dense block: supernodes at any size
        // (`g0_spot`'s 5,860 unknowns, where faer would factor column by column: the
        // flow's solves in a registration 0.24-0.32 s -> 0.10-0.13 s).
        let options = SolveOptions {
            kernel: Kernel::Supernodal,
            ..options
        };
        let solver = SpdSolver::with_split_order(pattern.symbolic().as_ref(), &order, options)?;
        Ok(Self {
            ahead: vec![false; roles.len()],
            contact: vec![false; roles.len()],
            outward: vec![None; roles.len()],
            pulls: vec![0.0; roles.len()],
            roles,
            flow: vec![0.0; dofs.full_len()],
            dofs,
            offset,
            faces,
            local_ptr,
            local,
            term_ptr,
            face_terms,
            beta: vec![Complex64::default(); longest],
            rates: vec![0.0; longest],
            rhs: vec![0.0; n],
            trial: vec![0.0; n],
            matrix,
            slots,
            solver,
            kept: false,
            skip_reuse: 0,
            backoff: 1,
            factorizations: 0,
            cg_iterations: 0,
            prescribed: false,
            diagonal,
            damping: 0.0,
            tilt_penalty: 0.0,
            rhs_before: Vec::new(),
        })
    }

    /// Damps every later solve: the step minimizes `E_V(c) + lambda |c|^2` with
    /// `lambda = relative * mean(diag)` of the normal matrix, a Levenberg-Marquardt
    /// step. It makes the normal equations definite when nothing fixes the target's
    /// conformal automorphisms (a disk sliding on a target mesh's boundary with no pin:
    /// its Moebius motions have `V_zbar ~ 0` and a singular or indefinite matrix in
    /// rounding), and picks the step of least length along them. A fixed point of the
    /// flow does not move: the damped step vanishes exactly where the undamped one does
    /// (both where the right-hand side does).
    pub fn set_damping(&mut self, relative: f64) {
        self.damping = relative;
    }

    /// Adds to every later solve, for each image face tilted from its reference normal
    /// `n` (the sum of its corners' target normals) by more than where its measure
    /// starts turning to the target's plane (cosine `c_f` below `c_0 = 0.4`, see
    /// [`crate::measure::image_face`]), the term `lambda_f (dA_f / A_f)^2` with
    /// `A_f = (e_1 x e_2) . n` its signed area against `n`, `dA_f` its change under `V`
    /// to first order, and `lambda_f = c w_f ((c_0 - c_f) / c_0)^2` (`w_f` the face's
    /// flow weight). Such a face's `mu` turns nonlinear in `V` (its frame tilts towards
    /// the target's plane), so the Gauss-Newton model does not see it fold and steps
    /// must stop short of it; the term makes the step keep its area against `n`. It is
    /// positive semidefinite, so the step stays a descent direction of the model.
    pub fn set_tilt_penalty(&mut self, c: f64) {
        self.tilt_penalty = c;
    }

    /// Sets the known flow of fixed vertices (one vector per vertex, read at
    /// [`Role::Fixed`] vertices only; missing entries: zero): the origins `V0` of the
    /// DOF map. Their known part of `V_zbar` moves to the right-hand side,
    /// `rho_T - sum_fixed g_k (V_k . r + i V_k . s)`.
    pub fn set_prescribed(&mut self, prescribed: &[Vector3<f64>]) -> Result<(), SolverError> {
        self.prescribed = false;
        for (v, &role) in self.roles.iter().enumerate() {
            if role == Role::Fixed {
                let value = prescribed.get(v).copied().unwrap_or_else(Vector3::zeros);
                self.dofs
                    .set_origin(VertexId::from_usize(v), value.as_slice())?;
                self.prescribed |= value != Vector3::zeros();
            }
        }
        Ok(())
    }

    /// `Q = c^T b` of the last solve (`H c = b` its normal equations, damping and tilt
    /// penalty included in `H`): the Gauss-Newton model of `E` along the flow,
    /// `sum_T w_T |t V_zbar - rho_T|^2` less its value at `t = 0`, is
    /// `t^2 c^T H c - 2 t c^T b = -(2 t - t^2) Q`, so a step of size `t` is predicted to
    /// lower `E` by `(2 t - t^2) Q` (to first order in `t`, `2 t Q`, the slope of `E`
    /// itself, the weights being its Gauss-Newton weights; [`crate::flow`]).
    pub fn model_decrease(&self) -> f64 {
        self.rhs_before
            .iter()
            .zip(&self.rhs)
            .map(|(b, c)| b * c)
            .sum()
    }

    /// The role of every vertex.
    pub fn roles(&self) -> &[Role] {
        &self.roles
    }

    /// The number of real unknowns.
    pub fn unknowns(&self) -> usize {
        self.dofs.reduced_len()
    }

    /// The DOF map of the flow, `V = K c + V0` (directions of the last solve).
    pub fn dofs(&self) -> &DofMap<f64> {
        &self.dofs
    }

    /// The minimizer of `E_V` for per-face weights `w_T` and targets `rho_T` on the image
    /// faces `faces` of `image`, written into `flow`.
    ///
    /// A curve vertex at a corner of its curve ([`TargetGeometry::curve_corner`]) moves
    /// along one side's tangent, and the step slides it along that side only if the
    /// solved move points into it: a move along the tangent behind with a positive
    /// coefficient would leave along the segment ahead, a first-order error of the model
    /// for every face at the vertex. Where the solved move points out of the side it was
    /// solved on, the vertex takes the other side, and when it moves by at least
    /// `CORNER_RESOLVE_SHARE` of the largest move the system is solved once more (a
    /// vertex that points out of both sides keeps its second one: its best move is to
    /// stay, and the model errs for it alone).
    ///
    /// A free vertex whose image lies on the target's boundary
    /// ([`TargetGeometry::boundary_outward`]) and whose solved move points outwards
    /// would slide along the boundary, its outward part lost: a contact, which the model
    /// honours by holding the vertex's move along the boundary (its second unknown has
    /// no direction, and a diagonal entry that keeps the matrix definite). A held
    /// vertex is let go where it pulls inwards: where `E_V` falls as it moves inwards
    /// from the solution, `dE_V/de > 0` along its outward direction `o`,
    /// `dE_V/de = 2 sum_T w_T Re(conj(g_k (o . r + i o . s)) (V_zbar(T) - rho_T))` over
    /// its faces (corner `k`; the plain coefficients, also on faces edge-on to the
    /// target). Either change makes a solve again as a corner's turn does, and lasts
    /// into the next steps while the vertex stays on the boundary.
    pub fn solve<G: TargetGeometry>(
        &mut self,
        at: FlowInput<'_, G>,
        flow: &mut Flow,
    ) -> Result<(), SolverError> {
        self.solve_on_sides(at, flow, 0)?;
        let large = CORNER_RESOLVE_SHARE * flow.vertex.iter().map(|v| v.norm()).fold(0.0, f64::max);
        let turned = self.turn_corner_sides(at, flow, large) + self.touch_boundary(at, flow, large);
        if turned > 0 {
            self.solve_on_sides(at, flow, turned)?;
        }
        Ok(())
    }

    /// Turns every curve vertex at a corner whose move in `flow` points out of the side
    /// it was solved on to the other side; how many of them move by at least `large`
    /// ([`CORNER_RESOLVE_SHARE`] of the largest move). Only these call for a solve
    /// again; the others keep their new side, in that solve when there is one, else from
    /// the next step on.
    fn turn_corner_sides<G: TargetGeometry>(
        &mut self,
        at: FlowInput<'_, G>,
        flow: &Flow,
        large: f64,
    ) -> usize {
        let mut turned = 0;
        for (v, &role) in self.roles.iter().enumerate() {
            if let Role::Curve(c) = role
                && let Some([behind, ahead]) = at.target.curve_corner(c, &at.image[v])
            {
                let along = flow.vertex[v].dot(if self.ahead[v] { &ahead } else { &behind });
                if (self.ahead[v] && along < 0.0) || (!self.ahead[v] && along > 0.0) {
                    self.ahead[v] = !self.ahead[v];
                    if flow.vertex[v].norm() >= large {
                        turned += 1;
                    }
                }
            }
        }
        turned
    }

    /// Holds every free vertex on the target's boundary whose move in `flow` points
    /// outwards, and lets go every held one that pulls inwards ([`FlowSystem::solve`]);
    /// how many of them move by at least `large` (as [`FlowSystem::turn_corner_sides`]).
    fn touch_boundary<G>(&mut self, at: FlowInput<'_, G>, flow: &Flow, large: f64) -> usize {
        self.outward_pulls(at, flow);
        let mut changed = 0;
        for v in 0..self.roles.len() {
            let Some(outward) = self.outward[v] else {
                continue;
            };
            let change = if self.contact[v] {
                self.pulls[v] > 0.0
            } else {
                flow.vertex[v].dot(&outward) > 0.0
            };
            if change {
                self.contact[v] = !self.contact[v];
                if flow.vertex[v].norm() >= large {
                    changed += 1;
                }
            }
        }
        changed
    }

    /// Per held vertex, `dE_V/de` along its outward direction at the solution `flow`,
    /// into `pulls` ([`FlowSystem::solve`]; half of it: only the sign matters).
    fn outward_pulls<G>(&mut self, at: FlowInput<'_, G>, flow: &Flow) {
        if !self.contact.iter().any(|&c| c) {
            return;
        }
        let pulls = &mut self.pulls;
        pulls.iter_mut().for_each(|p| *p = 0.0);
        let (faces, weights, rho) = (at.faces, at.weights, at.rho);
        for (f, (face, corners)) in faces.iter().zip(&self.faces).enumerate() {
            if !corners.iter().any(|&v| self.contact[v]) {
                continue;
            }
            let Some(g) = dzbar_coefficients(face) else {
                continue;
            };
            let residual = corners
                .iter()
                .zip(&g)
                .map(|(&v, gk)| gk * along(face, flow.vertex[v].as_slice()))
                .sum::<Complex64>()
                - rho[f];
            for (&v, gk) in corners.iter().zip(&g) {
                if let (true, Some(out)) = (self.contact[v], self.outward[v]) {
                    let beta = gk * along(face, out.as_slice());
                    pulls[v] += weights[f] * (beta.conj() * residual).re;
                }
            }
        }
    }

    /// The two unknowns of free vertex `v` (the second is the held one while `v` is
    /// held to the boundary).
    fn free_unknowns(&self, v: usize) -> Result<[usize; 2], SolverError> {
        let mut terms = self.dofs.node_terms(VertexId::from_usize(v))?;
        match (terms.next(), terms.next()) {
            (Some((_, first)), Some((_, second))) => Ok([first.dof, second.dof]),
            _ => Err(SolverError::invalid(
                crate::NAME,
                format!("free vertex {v} does not have two flow unknowns"),
            )),
        }
    }

    /// [`FlowSystem::solve`] with the corner sides as they are; `turned` vertices took
    /// the other side since the last solve of the same step (0 for a new step).
    fn solve_on_sides<G: TargetGeometry>(
        &mut self,
        at: FlowInput<'_, G>,
        flow: &mut Flow,
        turned: usize,
    ) -> Result<(), SolverError> {
        self.refill_directions(at.target, at.image, at.normals)?;
        self.assemble_normal_equations(at);
        let values = self.matrix.val_mut();
        if self.damping > 0.0 {
            let mean =
                self.diagonal.iter().map(|&d| values[d]).sum::<f64>() / self.diagonal.len() as f64;
            let lambda = self.damping * mean;
            for &d in &self.diagonal {
                values[d] += lambda;
            }
        }
        for v in 0..self.roles.len() {
            if self.contact[v] {
                // The held unknown has no direction, so its row and column are empty:
                // the diagonal entry of its vertex's other unknown keeps the scale.
                let [along, held] = self.free_unknowns(v)?;
                let values = self.matrix.val_mut();
                values[self.diagonal[held]] = values[self.diagonal[along]];
            }
        }
        self.rhs_before.clear();
        self.rhs_before.extend_from_slice(&self.rhs);
        match self.solve_normal_equations(turned) {
            Err(SolverError::Solve(SolveError::Singular { .. })) if self.damping > 0.0 => {
                let values = self.matrix.val_mut();
                for &d in &self.diagonal {
                    values[d] *= 1.0 + OWN_DAMPING;
                }
                self.solve_normal_equations(turned)?;
            }
            outcome => outcome?,
        }
        self.dofs.expand_into(&self.rhs, &mut self.flow)?;
        flow.vertex.clear();
        flow.vertex.extend(
            self.flow
                .chunks_exact(3)
                .map(|v| Vector3::new(v[0], v[1], v[2])),
        );
        flow.offset.clear();
        flow.offset
            .extend(self.offset.iter().map(|o| o.map_or(0.0, |o| self.rhs[o])));
        Ok(())
    }

    /// Fills the right-hand side and the normal matrix (lower triangle) of `E_V` at
    /// `at`, face by face, with the tilt penalty ([`FlowSystem::set_tilt_penalty`]):
    /// face `T` with weight `w_T`, coefficients `beta_a` of its local unknowns in
    /// `V_zbar(T)` and known part `rho_T` (less the prescribed flow's share) adds
    /// `w_T Re(conj(beta_a) rho_T)` to the right-hand side and
    /// `w_T Re(conj(beta_a) beta_b)` to the matrix. The directions are those
    /// [`FlowSystem::refill_directions`] stated for `at`.
    fn assemble_normal_equations<G: TargetGeometry>(&mut self, at: FlowInput<'_, G>) {
        let FlowInput {
            elements,
            target,
            image,
            normals,
            faces,
            weights,
            rho,
        } = at;
        self.rhs.iter_mut().for_each(|r| *r = 0.0);
        let values = self.matrix.val_mut();
        values.iter_mut().for_each(|v| *v = 0.0);
        let (x0, directions) = (self.dofs.x0(), self.dofs.directions());
        let mut at = 0;
        for (f, face) in faces.iter().enumerate() {
            let list = &self.local[self.local_ptr[f]..self.local_ptr[f + 1]];
            let m = list.len();
            let g = dzbar_coefficients(face);
            let w = if g.is_some() { weights[f] } else { 0.0 };
            let g = g.unwrap_or_default();
            let beta = &mut self.beta[..m];
            beta.iter_mut().for_each(|b| *b = Complex64::default());
            // Where the face's frame tilts towards the target's plane, its mu depends on
            // the target's normals at its corners, which turn as the corners move over
            // a curved target: a first-order term the model's `g_k` leaves out (on
            // `face50k` onto `disk_hand`, a face across a fold whose measure rose
            // linearly along every step the model said would lower it). There the rate
            // of mu is taken by central differences of the measure itself, each corner
            // moved on the target with the normal there, and turned into the rate of
            // V_zbar that composition gives it (`crate::flow`, item 1).
            let tilted = (w > 0.0 && face.facing() <= TILT_FULL)
                .then(|| tilt_rate_scale(face, image, &self.faces[f]))
                .flatten();
            for t in &self.face_terms[self.term_ptr[f]..self.term_ptr[f + 1]] {
                let b = &directions[3 * t.term as usize..3 * t.term as usize + 3];
                beta[t.local as usize] += match tilted {
                    Some((to_flow, h)) => {
                        let (k, b) = (t.k as usize, Vector3::new(b[0], b[1], b[2]));
                        let from = image[self.faces[f][k]];
                        let mu = |d: Vector3<f64>| {
                            let to = target.project(Role::Free, &(from + d));
                            let face_id = FaceId::from_usize(f);
                            let moved = (to, target.normal(&to));
                            mu_with_corner_moved(elements, normals, image, face_id, k, moved)
                        };
                        (mu(b * h) - mu(-b * h)) / (2.0 * h) * to_flow
                    }
                    None => g[t.k as usize] * along(face, b),
                };
            }
            let mut known = rho[f];
            if self.prescribed {
                for (&v, gk) in self.faces[f].iter().zip(&g) {
                    let v0 = &x0[3 * v..3 * v + 3];
                    if v0.iter().any(|&c| c != 0.0) {
                        known -= gk * along(face, v0);
                    }
                }
            }
            let first_slot = at;
            for a in 0..m {
                self.rhs[list[a]] += w * (beta[a].conj() * known).re;
                for b in 0..=a {
                    values[self.slots[at]] += w * (beta[a].conj() * beta[b]).re;
                    at += 1;
                }
            }
            let tilt = (TILT_START - face.facing()) / TILT_START;
            if self.tilt_penalty > 0.0 && w > 0.0 && tilt > 0.0 {
                let terms = &self.face_terms[self.term_ptr[f]..self.term_ptr[f + 1]];
                let gamma = &mut self.rates[..m];
                if let Some(area) =
                    area_rates(self.faces[f], terms, directions, image, normals, gamma)
                {
                    let lambda = self.tilt_penalty * w * tilt * tilt / (area * area);
                    let mut at = first_slot;
                    for a in 0..m {
                        for b in 0..=a {
                            values[self.slots[at]] += lambda * gamma[a] * gamma[b];
                            at += 1;
                        }
                    }
                }
            }
        }
    }

    /// States the directions of the current image in the DOF map: the tangent basis of
    /// the target's normal at a free vertex ([`orthonormal_basis`]), the curve tangent at
    /// a curve vertex (of its side at a corner), and the curve's offset direction there
    /// (zero where the target has none).
    fn refill_directions<G: TargetGeometry>(
        &mut self,
        target: &G,
        image: &[Point3<f64>],
        normals: &[Vector3<f64>],
    ) -> Result<(), SolverError> {
        for (v, (&role, (p, normal))) in
            self.roles.iter().zip(image.iter().zip(normals)).enumerate()
        {
            let first = self.dofs.terms(VertexId::from_usize(v))?.start;
            match role {
                Role::Free => {
                    self.outward[v] = target
                        .boundary_outward(v, p)
                        .and_then(|o| (o - normal * normal.dot(&o)).try_normalize(1e-6));
                    let basis = match self.outward[v] {
                        Some(out) if self.contact[v] => [normal.cross(&out), Vector3::zeros()],
                        _ => {
                            self.contact[v] = false;
                            orthonormal_basis(normal)
                        }
                    };
                    for (t, b) in basis.iter().enumerate() {
                        self.dofs.set_direction(first + t, b.as_slice())?;
                    }
                }
                Role::Curve(c) => {
                    let tangent = match target.curve_corner(c, p) {
                        Some([_, ahead]) if self.ahead[v] => ahead,
                        Some([behind, _]) => behind,
                        None => target.curve_tangent(c, p),
                    };
                    self.dofs.set_direction(first, tangent.as_slice())?;
                    if self.offset[c].is_some() {
                        let b = target
                            .curve_offset_direction(c, p)
                            .unwrap_or_else(Vector3::zeros);
                        self.dofs.set_direction(first + 1, b.as_slice())?;
                    }
                }
                Role::Fixed => {}
            }
        }
        Ok(())
    }
}

impl FlowSystem {
    /// Numeric factorizations and conjugate-gradient iterations so far.
    pub fn work(&self) -> (usize, usize) {
        (self.factorizations, self.cg_iterations)
    }

    /// Makes the next solve factor its matrix, as the first solve of a new system
    /// does: a flow started again from another map (after an untangling) keeps the
    /// unknowns, the pattern and the symbolic factorization, but the last run's factor
    /// belongs to a matrix of another map.
    pub fn forget_factorization(&mut self) {
        self.kept = false;
        self.skip_reuse = 0;
        self.backoff = 1;
    }

    /// Solves the assembled normal equations in place of `rhs`: by conjugate gradients
    /// preconditioned with the kept factorization when there is one (the matrix changes
    /// little between late steps), else — or when that does not converge within
    /// [`CG_ITERATIONS`] — by factoring the new matrix. After a failed reuse the next
    /// 1, 2, 4, .. steps factor directly.
    ///
    /// A solve again after `turned > 0` large movers at corners took the other side
    /// (or, on the target's boundary, were held or let go) differs from the matrix just
    /// solved in the rows and columns of the vertices that changed, a perturbation of
    /// rank two to four times their number, which conjugate gradients
    /// preconditioned with the kept factorization resolve in as many iterations more.
    /// It is tried with `2 turned` more (the small movers that turned with them are
    /// not counted), up to [`CG_TURNED_ITERATIONS`], and leaves the reuse schedule of
    /// the steps as it is.
    fn solve_normal_equations(&mut self, turned: usize) -> Result<(), SolverError> {
        if self.kept && turned > 0 {
            self.trial.copy_from_slice(&self.rhs);
            let iterations = (CG_ITERATIONS + 2 * turned).min(CG_TURNED_ITERATIONS);
            let outcome = self.solver.solve_preconditioned(
                self.matrix.as_ref(),
                &mut self.trial,
                CG_TOLERANCE,
                iterations,
            )?;
            self.cg_iterations += outcome.iterations;
            if outcome.converged {
                std::mem::swap(&mut self.rhs, &mut self.trial);
                return Ok(());
            }
        } else if self.kept && self.skip_reuse == 0 {
            self.trial.copy_from_slice(&self.rhs);
            let outcome = self.solver.solve_preconditioned(
                self.matrix.as_ref(),
                &mut self.trial,
                CG_TOLERANCE,
                CG_ITERATIONS,
            )?;
            self.cg_iterations += outcome.iterations;
            if outcome.converged {
                self.backoff = 1;
                std::mem::swap(&mut self.rhs, &mut self.trial);
                return Ok(());
            }
            self.skip_reuse = self.backoff;
            self.backoff *= 2;
        } else if turned == 0 {
            self.skip_reuse = self.skip_reuse.saturating_sub(1);
        }
        // A failed factorization leaves the solver without one: the next solve must not
        // take the old factor as kept.
        self.kept = false;
        self.solver.factorize(self.matrix.as_ref())?;
        self.factorizations += 1;
        self.kept = true;
        self.solver.solve_vector_in_place(&mut self.rhs)?;
        Ok(())
    }
}

/// The signed area `A = (e_1 x e_2) . n` of the image triangle `corners` against its
/// reference normal `n` (the sum of its corners' normals), when positive, and its rate
/// along each of the face's local unknowns (`terms`, with their `directions`) in
/// `rates`: a corner moving by `d` changes the edges `e_1 = p_1 - p_0`,
/// `e_2 = p_2 - p_0` by `(-d, -d)`, `(d, 0)` or `(0, d)`, and `A` by
/// `(de_1 x e_2 + e_1 x de_2) . n`.
fn area_rates(
    corners: [usize; 3],
    terms: &[FaceTerm],
    directions: &[f64],
    image: &[Point3<f64>],
    normals: &[Vector3<f64>],
    rates: &mut [f64],
) -> Option<f64> {
    let (e1, e2, n) = edges_and_reference(corners, image, normals);
    let area = e1.cross(&e2).dot(&n);
    if area <= 0.0 {
        return None;
    }
    rates.iter_mut().for_each(|r| *r = 0.0);
    for t in terms {
        let d = &directions[3 * t.term as usize..3 * t.term as usize + 3];
        let d = Vector3::new(d[0], d[1], d[2]);
        let (de1, de2) = match t.k {
            0 => (-d, -d),
            1 => (d, Vector3::zeros()),
            _ => (Vector3::zeros(), d),
        };
        rates[t.local as usize] += (de1.cross(&e2) + e1.cross(&de2)).dot(&n);
    }
    Some(area)
}

/// Vertex count from which the flow's normal equations may be factored in two sides at
/// once ([`two_core_order`]); below it one thread factors the whole.
const TWO_SIDES_FROM: usize = 20_000;

/// Declares the flow's unknowns for `roles` on `target` (the order of
/// [`FlowSystem::new`]): two per free vertex, one per curve vertex, then one per curve
/// with a free offset at `image`, in the order its first vertex comes. Returns the DOF
/// map and each curve's offset unknown.
fn declare_unknowns<G: TargetGeometry>(
    target: &G,
    image: &[Point3<f64>],
    roles: &[Role],
) -> Result<(DofMap<f64>, Vec<Option<usize>>), SolverError> {
    let mut builder = DofBuilder::<f64>::new(roles.len(), 3)?;
    let origin = [0.0; 3];
    for (v, &role) in roles.iter().enumerate() {
        let count = match role {
            Role::Free => 2,
            Role::Curve(_) => 1,
            Role::Fixed => 0,
        };
        builder.span(VertexId::from_usize(v), &origin, &AXES[..count])?;
    }
    let mut offset = vec![None; target.curve_count()];
    for (&role, p) in roles.iter().zip(image) {
        if let Role::Curve(c) = role
            && offset[c].is_none()
            && target.curve_offset_direction(c, p).is_some()
        {
            let members = roles
                .iter()
                .enumerate()
                .filter(|&(_, &r)| r == role)
                .map(|(v, _)| (VertexId::from_usize(v), AXES[1]));
            offset[c] = Some(builder.unknown(members)?);
        }
    }
    Ok((builder.build()?, offset))
}

/// The local unknowns of each face in the order its vertices' terms name them (each
/// vertex's own unknowns, then an offset not met yet), and its terms. A face has at
/// most 6 local unknowns and terms (two per vertex; a shared offset replaces a vertex's
/// own), so at most 21 lower-triangle entries.
struct FaceLayout {
    /// The local unknowns of face `f` are `local[local_ptr[f]..local_ptr[f + 1]]`.
    local_ptr: Vec<usize>,
    local: Vec<usize>,
    /// The terms of face `f` are `face_terms[term_ptr[f]..term_ptr[f + 1]]`.
    term_ptr: Vec<usize>,
    face_terms: Vec<FaceTerm>,
    /// The lower-triangle entries `(row, column)` the faces fill, face after face, each
    /// face's local pairs `(a, b)`, `b <= a`, in order; room is reserved for the
    /// diagonal after them.
    positions: Vec<(usize, usize)>,
}

impl FaceLayout {
    /// The layout of `faces` with the unknowns of `dofs`.
    fn new(faces: &[[usize; 3]], dofs: &DofMap<f64>) -> Result<Self, SolverError> {
        let n = dofs.reduced_len();
        let mut local_ptr = Vec::with_capacity(faces.len() + 1);
        let mut term_ptr = Vec::with_capacity(faces.len() + 1);
        local_ptr.push(0);
        term_ptr.push(0);
        let mut local = Vec::with_capacity(6 * faces.len());
        let mut face_terms = Vec::with_capacity(6 * faces.len());
        let mut positions = Vec::with_capacity(21 * faces.len() + n);
        for face in faces {
            let start = local.len();
            for (k, &v) in face.iter().enumerate() {
                for (term, t) in dofs.node_terms(VertexId::from_usize(v))? {
                    let at = match local[start..].iter().position(|&d| d == t.dof) {
                        Some(at) => at,
                        None => {
                            local.push(t.dof);
                            local.len() - start - 1
                        }
                    };
                    let term = u32::try_from(term).map_err(|_| {
                        SolverError::invalid(
                            crate::NAME,
                            format!("{term} flow terms exceed the u32 index range"),
                        )
                    })?;
                    // At most three vertices with two terms each: the casts are exact.
                    face_terms.push(FaceTerm {
                        k: k as u8,
                        local: at as u8,
                        term,
                    });
                }
            }
            let list = &local[start..];
            for a in 0..list.len() {
                for b in 0..=a {
                    let (da, db) = (list[a], list[b]);
                    positions.push((da.max(db), da.min(db)));
                }
            }
            local_ptr.push(local.len());
            term_ptr.push(face_terms.len());
        }
        Ok(Self {
            local_ptr,
            local,
            term_ptr,
            face_terms,
            positions,
        })
    }
}

/// The vertices of each of the elements' triangles.
pub(crate) fn triangles(elements: &Elements) -> Vec<[usize; 3]> {
    (0..elements.face_count())
        .map(|f| triangle(elements, FaceId(f as u32)).map(|v| v.idx()))
        .collect()
}

/// A fill-reducing elimination order of a mesh's vertex graph (an edge per triangle
/// side), from which [`FlowSystem::with_vertex_order`] orders its unknowns: the
/// unknowns that move one vertex only with their vertex, the shared ones (offsets,
/// coupled to a whole curve) last in increasing order. Ordering the vertex graph is
/// about four times cheaper than the unknowns' graph, and keeps each vertex's pair in
/// one supernode. It does not depend on the vertices' roles, so a caller may compute it
/// while it builds the initial map (on two cores the hand's disk map overlaps its
/// 0.18-s order with its 0.19-s initial map).
///
/// From `TWO_SIDES_FROM` (20,000) vertices the order is [`two_core_order`]'s, and its two
/// sides, if it has them, carry over to the unknowns (the shared ones join the
/// separator); below, it is [`fill_reducing_order`]'s, one whole.
#[derive(Debug, Clone)]
pub struct VertexOrder(SplitOrder);

impl VertexOrder {
    /// The order of the vertex graph of `mesh` (a triangle mesh: the flow's source).
    pub fn of(mesh: &Mesh) -> Result<Self, SolverError> {
        let faces: Vec<[usize; 3]> = mesh
            .faces()
            .map(|f| {
                let (v, _) = mesh.face_vertex_array(f);
                [v[0].idx(), v[1].idx(), v[2].idx()]
            })
            .collect();
        Self::of_triangles(&faces, mesh.vertex_count())
    }

    fn of_triangles(faces: &[[usize; 3]], nv: usize) -> Result<Self, SolverError> {
        let mut positions = Vec::with_capacity(nv + 3 * faces.len());
        positions.extend((0..nv).map(|v| (v, v)));
        for f in faces {
            for k in 0..3 {
                let (a, b) = (f[k], f[(k + 1) % 3]);
                positions.push((a.max(b), a.min(b)));
            }
        }
        let graph = Pattern::new(nv, nv, &positions)?;
        let order = if nv >= TWO_SIDES_FROM {
            two_core_order(graph.symbolic().as_ref())?
        } else {
            SplitOrder {
                order: fill_reducing_order(graph.symbolic().as_ref())?,
                sides: None,
            }
        };
        Ok(Self(order))
    }
}

/// A vector of R^3 (three components) as the complex number of its components along
/// the face's `(r, s)`.
#[inline]
fn along(face: &ImageFace, b: &[f64]) -> Complex64 {
    let b = Vector3::new(b[0], b[1], b[2]);
    Complex64::new(b.dot(&face.r), b.dot(&face.s))
}

/// For a face whose frame tilts with its corners: `1 / ((1 - |mu|^2) theta)`, which
/// turns a rate of its `mu` into the rate of `V_zbar` that composition gives it
/// (`crate::flow`, item 1: `d mu = (1 - |mu|^2) theta d tau`), and the difference step
/// `h` for its corners ([`TILT_DIFFERENCE`] of its longest edge); `None` where
/// `|mu| >= 1` or `f_z = 0`.
fn tilt_rate_scale(
    face: &ImageFace,
    image: &[Point3<f64>],
    corners: &[usize; 3],
) -> Option<(Complex64, f64)> {
    let mu = face.mu();
    let shrink = 1.0 - mu.norm_sqr();
    let fz = face.derivatives.fz;
    if shrink <= 0.0 || fz.norm_sqr() == 0.0 {
        return None;
    }
    let [a, b, c] = corners.map(|v| image[v]);
    let longest = (b - a).norm().max((c - b).norm()).max((a - c).norm());
    (longest > 0.0).then(|| (fz / (shrink * fz.conj()), TILT_DIFFERENCE * longest))
}

/// The difference step of [`tilt_rate_scale`], relative to the face's longest edge.
const TILT_DIFFERENCE: f64 = 1e-6;

/// `g_k = (d_r N_k + i d_s N_k) / 2` of the image triangle, or `None` when it is
/// degenerate. With `q_k` its vertices in the frame and `D = (q_1 - q_0) x (q_2 - q_0)`
/// twice its signed area, `grad N_k = J (q_(k+2) - q_(k+1)) / D`, `J` the rotation by
/// +90 degrees.
fn dzbar_coefficients(face: &ImageFace) -> Option<[Complex64; 3]> {
    let q = &face.local;
    let e1 = q[1] - q[0];
    let e2 = q[2] - q[0];
    let d = e1.x * e2.y - e1.y * e2.x;
    if d == 0.0 || !d.is_finite() {
        return None;
    }
    Some(std::array::from_fn(|k| {
        let e = q[(k + 2) % 3] - q[(k + 1) % 3];
        0.5 * Complex64::new(-e.y, e.x) / d
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::image_faces;
    use crate::target::{Annulus, INNER, OUTER, UnitDisk};
    use beltrami_fem::Frame;
    use beltrami_mesh::{Mesh, primitives};

    /// The annulus `0.4 <= |z| <= 1` with a free inner radius, one vertex of the outer
    /// circle fixed: the flow's unknowns as a DOF map, and one solve.
    #[test]
    fn the_flow_is_a_dof_map_with_a_shared_radius() {
        let mesh = Mesh::from_soup(&primitives::annulus(0.4, 3, 12)).unwrap();
        let elements = Elements::new(&mesh, Frame::Global).unwrap();
        let image = mesh.positions().to_vec();
        let radius = |p: &Point3<f64>| p.x.hypot(p.y);
        let mut roles: Vec<Role> = image
            .iter()
            .map(|p| match radius(p) {
                r if (r - 1.0).abs() < 1e-9 => Role::Curve(OUTER),
                r if (r - 0.4).abs() < 1e-9 => Role::Curve(INNER),
                _ => Role::Free,
            })
            .collect();
        let pin = roles.iter().position(|&r| r == Role::Curve(OUTER)).unwrap();
        roles[pin] = Role::Fixed;
        let target = Annulus {
            inner_radius: 0.4,
            free_inner: true,
        };
        let options = SolveOptions::default();
        let mut system =
            FlowSystem::new(&elements, &target, &image, roles.clone(), options).unwrap();
        let count = |role: Role| roles.iter().filter(|&&r| r == role).count();
        let (free, outer, inner) = (
            count(Role::Free),
            count(Role::Curve(OUTER)),
            count(Role::Curve(INNER)),
        );
        assert_eq!(outer, 11);
        assert_eq!(inner, 12);
        let n = system.unknowns();
        assert_eq!(n, 2 * free + outer + inner + 1);
        // The radius is the last unknown and moves every inner vertex.
        let dofs = system.dofs();
        let on_inner: Vec<VertexId> = (0..roles.len())
            .filter(|&v| roles[v] == Role::Curve(INNER))
            .map(VertexId::from_usize)
            .collect();
        assert_eq!(
            dofs.unknown_nodes(n - 1).unwrap().collect::<Vec<_>>(),
            on_inner
        );
        assert_eq!(dofs.terms(VertexId::from_usize(pin)).unwrap().len(), 0);

        // One step towards mu = 0.2 everywhere: inner vertices move by their tangent
        // and the common radial offset, outer ones along the circle, the fixed one by
        // its prescribed flow.
        let normals = vec![Vector3::z(); image.len()];
        let mut faces = Vec::new();
        image_faces(&elements, &normals, &image, &mut faces, 1);
        let weights = vec![1.0; faces.len()];
        let rho = vec![Complex64::new(0.2, 0.0); faces.len()];
        let pulled = Vector3::new(0.0, 0.01, 0.0);
        let mut prescribed = vec![Vector3::zeros(); image.len()];
        prescribed[pin] = pulled;
        system.set_prescribed(&prescribed).unwrap();
        let mut flow = Flow::default();
        system
            .solve(
                FlowInput {
                    elements: &elements,
                    target: &target,
                    image: &image,
                    normals: &normals,
                    faces: &faces,
                    weights: &weights,
                    rho: &rho,
                },
                &mut flow,
            )
            .unwrap();
        let offset = flow.offset[INNER];
        assert!(offset.abs() > 1e-6, "the radius did not move: {offset}");
        assert_eq!(flow.offset[OUTER], 0.0);
        for (v, p) in image.iter().enumerate() {
            let radial = Vector3::new(p.x, p.y, 0.0) / radius(p);
            let along_radius = flow.vertex[v].dot(&radial);
            match roles[v] {
                Role::Curve(INNER) => assert!((along_radius - offset).abs() < 1e-14),
                Role::Curve(_) => assert!(along_radius.abs() < 1e-14),
                Role::Fixed => assert_eq!(flow.vertex[v], pulled),
                Role::Free => assert_eq!(flow.vertex[v].z, 0.0),
            }
        }

        // A factorization that fails is not kept: the next solve factors again instead
        // of running conjugate gradients with a factor the solver no longer has (a
        // genus-3 registration once ended with "no factorization to solve with").
        assert!(system.kept);
        let matrix = system.matrix.clone();
        system.matrix.val_mut().fill(f64::NAN);
        system.skip_reuse = 1;
        assert!(system.solve_normal_equations(0).is_err());
        assert!(!system.kept);
        system.matrix = matrix;
        system.skip_reuse = 0;
        let before = system.factorizations;
        system.solve_normal_equations(0).unwrap();
        assert_eq!(system.factorizations, before + 1);
        assert!(system.rhs.iter().all(|x| x.is_finite()));
    }

    /// The tilt penalty keeps the area against the reference normal of faces tilted
    /// steeply to it, and leaves a system without such faces as it is.
    #[test]
    fn the_tilt_penalty_holds_the_area_of_tilted_faces_only() {
        let n = 8;
        let mesh = Mesh::from_soup(&primitives::grid(n, n, primitives::Cells::Triangles)).unwrap();
        let elements = Elements::new(&mesh, Frame::Face).unwrap();
        let flat = mesh.positions().to_vec();
        let mut roles = vec![Role::Free; flat.len()];
        roles[0] = Role::Fixed;
        roles[n] = Role::Fixed;
        // The centre vertex lifted by 0.3 over cells of 1/8: its six faces stand about
        // 70 degrees from the target's normal z.
        let lifted = {
            let mut image = flat.clone();
            image[n / 2 + (n + 1) * (n / 2)].z = 0.3;
            image
        };
        let normals = vec![Vector3::z(); flat.len()];
        let solve = |image: &[Point3<f64>], penalty: f64| {
            let mut system = FlowSystem::new(
                &elements,
                &UnitDisk,
                image,
                roles.clone(),
                SolveOptions::default(),
            )
            .unwrap();
            system.set_tilt_penalty(penalty);
            let mut faces = Vec::new();
            image_faces(&elements, &normals, image, &mut faces, 1);
            let weights = vec![1.0; faces.len()];
            let rho: Vec<Complex64> = (0..faces.len())
                .map(|f| Complex64::new(0.3, 0.1 * (f % 5) as f64))
                .collect();
            let mut flow = Flow::default();
            system
                .solve(
                    FlowInput {
                        elements: &elements,
                        target: &UnitDisk,
                        image,
                        normals: &normals,
                        faces: &faces,
                        weights: &weights,
                        rho: &rho,
                    },
                    &mut flow,
                )
                .unwrap();
            (faces, flow.vertex)
        };
        // The largest relative rate of the area against z over the tilted faces.
        let tilted_rate = |image: &[Point3<f64>], faces: &[ImageFace], v: &[Vector3<f64>]| {
            let mut largest = 0.0f64;
            for (f, face) in faces.iter().enumerate() {
                if face.facing() >= TILT_START {
                    continue;
                }
                let [a, b, c] = triangle(&elements, FaceId::from_usize(f)).map(|x| x.idx());
                let (e1, e2) = (image[b] - image[a], image[c] - image[a]);
                let (d1, d2) = (v[b] - v[a], v[c] - v[a]);
                let area = e1.cross(&e2).z;
                let rate = (d1.cross(&e2) + e1.cross(&d2)).z;
                largest = largest.max((rate / area).abs());
            }
            largest
        };
        let (faces, free) = solve(&lifted, 0.0);
        let tilted = faces.iter().filter(|f| f.facing() < TILT_START).count();
        assert_eq!(tilted, 6);
        let (_, held) = solve(&lifted, 100.0);
        let (before, after) = (
            tilted_rate(&lifted, &faces, &free),
            tilted_rate(&lifted, &faces, &held),
        );
        assert!(
            before > 0.1,
            "the unpenalized flow barely tilts them: {before}"
        );
        assert!(after < 0.2 * before, "{before} -> {after}");
        // Nothing tilted: the penalty changes nothing.
        let (_, plain) = solve(&flat, 0.0);
        let (_, penalized) = solve(&flat, 10.0);
        assert_eq!(plain, penalized);
    }

    /// A curve vertex on a corner of a target mesh's boundary moves along the side its
    /// solved move points into, whichever way the goal pushes it.
    #[test]
    fn a_vertex_on_a_corner_moves_along_the_side_it_moves_into() {
        use crate::mesh_target::{MeshTarget, TargetCurve};
        use beltrami_spatial::SurfaceIndex;
        let n = 6;
        let mesh = Mesh::from_soup(&primitives::grid(n, n, primitives::Cells::Triangles)).unwrap();
        let elements = Elements::new(&mesh, Frame::Face).unwrap();
        let index = SurfaceIndex::new(&mesh).unwrap();
        let target = MeshTarget::new(&index, TargetCurve::boundary_loops(&mesh).unwrap());
        let image = mesh.positions().to_vec();
        // The corners (0, 0) and (0, 1) held; the corner (1, 0) free to slide.
        let held = [VertexId::from_usize(0), VertexId::from_usize((n + 1) * n)];
        let roles = crate::setup::curve_roles(&mesh, &held, |_| 0);
        let corner = n;
        assert_eq!(image[corner], Point3::new(1.0, 0.0, 0.0));
        let [behind, ahead] = target.curve_corner(0, &image[corner]).unwrap();
        let normals = vec![Vector3::z(); image.len()];
        let mut faces = Vec::new();
        image_faces(&elements, &normals, &image, &mut faces, 1);
        let weights = vec![1.0; faces.len()];
        let mut sides = Vec::new();
        for sign in [1.0, -1.0] {
            let mut system = FlowSystem::new(
                &elements,
                &target,
                &image,
                roles.clone(),
                SolveOptions::default(),
            )
            .unwrap();
            let rho = vec![Complex64::new(0.3, 0.2) * sign; faces.len()];
            let mut flow = Flow::default();
            system
                .solve(
                    FlowInput {
                        elements: &elements,
                        target: &target,
                        image: &image,
                        normals: &normals,
                        faces: &faces,
                        weights: &weights,
                        rho: &rho,
                    },
                    &mut flow,
                )
                .unwrap();
            let v = flow.vertex[corner];
            assert!(v.norm() > 1e-3, "{v}");
            let (forward, back) = (v.dot(&ahead), v.dot(&behind));
            let side = if (v - ahead * forward).norm() < 1e-12 && forward > 0.0 {
                "ahead"
            } else if (v - behind * back).norm() < 1e-12 && back < 0.0 {
                "behind"
            } else {
                panic!("{v} moves along neither side it points into: {behind} / {ahead}")
            };
            sides.push(side);
        }
        assert_ne!(sides[0], sides[1]);
    }

    #[test]
    fn a_free_vertex_on_the_boundary_is_held_to_it_while_it_pulls_outwards() {
        use crate::mesh_target::{MeshTarget, TargetCurve};
        use beltrami_spatial::SurfaceIndex;
        let n = 4;
        let mesh = Mesh::from_soup(&primitives::grid(n, n, primitives::Cells::Triangles)).unwrap();
        let elements = Elements::new(&mesh, Frame::Face).unwrap();
        let index = SurfaceIndex::new(&mesh).unwrap();
        let target = MeshTarget::new(&index, TargetCurve::boundary_loops(&mesh).unwrap());
        // Every vertex held but the middle of the bottom side, a free vertex on the
        // target's boundary (outwards is -y there).
        let free = n / 2;
        let mut roles = vec![Role::Fixed; mesh.vertex_count()];
        roles[free] = Role::Free;
        let mut image = mesh.positions().to_vec();
        let mut normals = Vec::new();
        target
            .project_all(&roles, None, &mut image, &mut normals)
            .unwrap();
        assert_eq!(image[free], Point3::new(0.5, 0.0, 0.0));
        let mut faces = Vec::new();
        image_faces(&elements, &normals, &image, &mut faces, 1);
        let weights = vec![1.0; faces.len()];
        let mut system =
            FlowSystem::new(&elements, &target, &image, roles, SolveOptions::default()).unwrap();
        // The targets `rho` that the move `wanted` of the free vertex meets exactly.
        let solve = |system: &mut FlowSystem, wanted: Vector3<f64>| {
            let rho: Vec<Complex64> = (0..faces.len())
                .map(|f| {
                    let g = dzbar_coefficients(&faces[f]).unwrap();
                    let corners = triangle(&elements, FaceId::from_usize(f));
                    corners
                        .iter()
                        .zip(g)
                        .filter(|(v, _)| v.idx() == free)
                        .map(|(_, g)| g * along(&faces[f], wanted.as_slice()))
                        .sum()
                })
                .collect();
            let mut flow = Flow::default();
            system
                .solve(
                    FlowInput {
                        elements: &elements,
                        target: &target,
                        image: &image,
                        normals: &normals,
                        faces: &faces,
                        weights: &weights,
                        rho: &rho,
                    },
                    &mut flow,
                )
                .unwrap();
            flow.vertex[free]
        };
        let (outwards, inwards) = (Vector3::new(0.1, -0.1, 0.0), Vector3::new(0.1, 0.1, 0.0));
        let held = solve(&mut system, outwards);
        assert!(
            (held - Vector3::new(0.1, 0.0, 0.0)).norm() < 1e-9,
            "pulled outwards, it moves along the boundary only: {held}"
        );
        let let_go = solve(&mut system, inwards);
        assert!(
            (let_go - inwards).norm() < 1e-9,
            "pulled inwards, it is let go and moves freely: {let_go}"
        );
        let held_again = solve(&mut system, outwards);
        assert!((held_again - held).norm() < 1e-9, "{held_again} / {held}");
    }
}
