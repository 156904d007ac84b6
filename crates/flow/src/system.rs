//! The least-squares flow system: unknowns, pattern and normal equations.
//!
//! The flow `V` is piecewise linear on the image mesh, `V_i = sum_k c_ik b_ik` at vertex
//! `i` with real unknowns `c_ik` along directions `b_ik` in R^3 (two tangent directions
//! of the target for a [`Role::Free`] vertex, the curve tangent for a [`Role::Curve`]
//! vertex, none for a [`Role::Fixed`] one — the tangent directions are
//! [`orthonormal_basis`] of the target's normal at the image; plus, for a curve with a free offset, one
//! unknown shared by all its vertices along the offset direction). On image face `T`,
//! with frame `(r, s)` and the image triangle's shape-function gradients `grad N_k` in
//! that frame,
//!
//! ```text
//! V_zbar(T) = sum_k g_k (V_k . r + i V_k . s),    g_k = (d_r N_k + i d_s N_k) / 2,
//! ```
//!
//! so `V_zbar(T) = sum_a beta_a c_a` is real-linear in the unknowns, with complex
//! coefficients `beta_a = g_k (b . r + i b . s)`. The flow minimizes (Wong-Zhao 2014,
//! eq. 4.4 and Appendix eq. 6.1-6.9, with the weights of [`crate::flow`])
//!
//! ```text
//! E_V(c) = sum_T w_T |V_zbar(T) - rho_T|^2,
//! ```
//!
//! through its normal equations `sum_b Re(conj(beta_a) beta_b) c_b = Re(conj(beta_a) rho)`,
//! summed face by face into a matrix whose pattern (which unknowns share a face) never
//! changes: the pattern and the symbolic Cholesky factorization are built once.

use beltrami_core::SolverError;
use beltrami_fem::assembly::Pattern;
use beltrami_fem::solve::amd_order;
use beltrami_fem::{Elements, SolveOptions, SpdSolver};
use beltrami_mesh::{FaceId, Point3, Vector3};
use faer::MatMut;
use faer::sparse::SparseColMat;
use num_complex::Complex64;

use crate::measure::{ImageFace, triangle};
use crate::target::{Role, TargetGeometry, orthonormal_basis};

/// Most distinct unknowns of one face: two per vertex and one shared offset per vertex.
const MAX_LOCAL: usize = 9;

/// Where a local unknown of a face comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Source {
    /// Unknown `index` (0 or 1) of face vertex `k`.
    Vertex { k: u8, index: u8 },
    /// The offset of `curve`, shared by the face vertices on it.
    Offset { curve: usize },
}

/// The unknowns of the flow and the factorization of its normal equations.
pub struct FlowSystem {
    roles: Vec<Role>,
    /// First unknown of each vertex (its count is given by its role).
    first: Vec<usize>,
    /// The shared offset unknown of each curve, if the curve has one.
    offset: Vec<Option<usize>>,
    /// Per face, its vertices.
    faces: Vec<[usize; 3]>,
    /// Per face, its distinct unknowns and where each comes from.
    local: Vec<([(usize, Source); MAX_LOCAL], u8)>,
    n: usize,
    /// The normal matrix (lower triangle), refilled in place every step.
    matrix: SparseColMat<usize, f64>,
    /// Per local entry (in assembly order), its index in the matrix's values.
    slots: Vec<usize>,
    solver: SpdSolver<f64>,
    rhs: Vec<f64>,
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
    /// The known flow of the fixed vertices that are pulled towards a goal (zero for
    /// the others): it moves them, and the rest of the flow follows.
    prescribed: Vec<Vector3<f64>>,
    /// The unknowns' directions of every vertex at the current image (refilled by each
    /// solve, so each is computed once per step).
    directions: Vec<[Vector3<f64>; 2]>,
}

/// Relative residual at which a step solved by conjugate gradients with a kept
/// factorization is accepted.
const CG_TOLERANCE: f64 = 1e-7;

/// Conjugate-gradient iterations tried with a kept factorization before refactoring
/// (each costs about a fifth of a factorization).
const CG_ITERATIONS: usize = 4;

impl std::fmt::Debug for FlowSystem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FlowSystem")
            .field("unknowns", &self.n)
            .field("entries", &self.slots.len())
            .field("factorizations", &self.factorizations)
            .finish_non_exhaustive()
    }
}

/// The flow of one step: a vector per vertex and an offset per curve.
#[derive(Debug, Clone, PartialEq)]
pub struct Flow {
    /// `V_i` in R^3.
    pub vertex: Vec<Vector3<f64>>,
    /// The offset of each curve (0 for curves without a free offset).
    pub offset: Vec<f64>,
}

fn unknowns_of(role: Role) -> usize {
    match role {
        Role::Free => 2,
        Role::Curve(_) => 1,
        Role::Fixed => 0,
    }
}

impl FlowSystem {
    /// The unknowns for `roles` (one per source vertex) on `target`, and the symbolic
    /// factorization of the normal equations. Fails when no vertex can move.
    pub fn new<G: TargetGeometry>(
        elements: &Elements,
        target: &G,
        image: &[Point3<f64>],
        roles: Vec<Role>,
        options: SolveOptions,
    ) -> Result<Self, SolverError> {
        let mut first = Vec::with_capacity(roles.len());
        let mut n = 0;
        for &role in &roles {
            first.push(n);
            n += unknowns_of(role);
        }
        let mut offset = vec![None; target.curve_count()];
        for (&role, p) in roles.iter().zip(image) {
            if let Role::Curve(c) = role
                && offset[c].is_none()
                && target.curve_offset_direction(c, p).is_some()
            {
                offset[c] = Some(n);
                n += 1;
            }
        }
        let faces: Vec<[usize; 3]> = (0..elements.face_count())
            .map(|f| triangle(elements, FaceId(f as u32)).map(|v| v.idx()))
            .collect();
        let mut local = Vec::with_capacity(faces.len());
        let mut positions = Vec::new();
        for face in &faces {
            let mut list = [(0, Source::Offset { curve: 0 }); MAX_LOCAL];
            let mut m = 0;
            for (k, &v) in face.iter().enumerate() {
                let role = roles[v];
                for index in 0..unknowns_of(role) {
                    list[m] = (
                        first[v] + index,
                        Source::Vertex {
                            k: k as u8,
                            index: index as u8,
                        },
                    );
                    m += 1;
                }
                if let Role::Curve(c) = role
                    && let Some(o) = offset[c]
                    && !list[..m].iter().any(|&(d, _)| d == o)
                {
                    list[m] = (o, Source::Offset { curve: c });
                    m += 1;
                }
            }
            for a in 0..m {
                for b in 0..=a {
                    let (da, db) = (list[a].0, list[b].0);
                    positions.push((da.max(db), da.min(db)));
                }
            }
            local.push((list, m as u8));
        }
        if n == 0 {
            return Err(SolverError::InvalidInput {
                solver: crate::NAME,
                message: "every vertex is fixed: there is nothing to flow".into(),
            });
        }
        let pattern = Pattern::new(n, n, &positions)?;
        let slots = pattern.value_slots(&positions)?;
        let matrix = pattern.assemble(&vec![0.0; positions.len()])?;
        let order = block_order(&faces, &roles, &first, n)?;
        let solver = SpdSolver::with_order(pattern.symbolic().as_ref(), &order, options)?;
        Ok(Self {
            roles,
            first,
            offset,
            faces,
            local,
            n,
            rhs: vec![0.0; n],
            matrix,
            slots,
            solver,
            skip_reuse: 0,
            backoff: 1,
            factorizations: 0,
            cg_iterations: 0,
            prescribed: Vec::new(),
            directions: Vec::new(),
        })
    }

    /// Sets the known flow of fixed vertices (one vector per vertex, read at
    /// [`Role::Fixed`] vertices only; empty: none). Their known part of `V_zbar` moves to
    /// the right-hand side, `rho_T - sum_fixed g_k (V_k . r + i V_k . s)`.
    pub fn set_prescribed(&mut self, prescribed: &[Vector3<f64>]) {
        self.prescribed.clear();
        self.prescribed.extend_from_slice(prescribed);
    }

    /// The role of every vertex.
    pub fn roles(&self) -> &[Role] {
        &self.roles
    }

    /// The number of real unknowns.
    pub fn unknowns(&self) -> usize {
        self.n
    }

    /// The minimizer of `E_V` for per-face weights `w_T` and targets `rho_T` on the image
    /// faces `faces` of `image`.
    pub fn solve<G: TargetGeometry>(
        &mut self,
        target: &G,
        image: &[Point3<f64>],
        normals: &[Vector3<f64>],
        faces: &[ImageFace],
        weights: &[f64],
        rho: &[Complex64],
    ) -> Result<Flow, SolverError> {
        self.directions.clear();
        self.directions.extend(
            self.roles
                .iter()
                .zip(image.iter().zip(normals))
                .map(|(&role, (p, n))| directions(target, role, p, n)),
        );
        self.rhs.iter_mut().for_each(|r| *r = 0.0);
        let values = self.matrix.val_mut();
        values.iter_mut().for_each(|v| *v = 0.0);
        let mut at = 0;
        for (f, face) in faces.iter().enumerate() {
            let (list, m) = &self.local[f];
            let m = *m as usize;
            let g = dzbar_coefficients(face);
            let w = if g.is_some() { weights[f] } else { 0.0 };
            let g = g.unwrap_or_default();
            let mut beta = [Complex64::default(); MAX_LOCAL];
            for (a, &(_, source)) in list[..m].iter().enumerate() {
                beta[a] = match source {
                    Source::Vertex { k, index } => {
                        let v = self.faces[f][k as usize];
                        let b = self.directions[v][index as usize];
                        g[k as usize] * along(face, &b)
                    }
                    Source::Offset { curve } => {
                        let mut sum = Complex64::default();
                        for (&v, gk) in self.faces[f].iter().zip(&g) {
                            if self.roles[v] == Role::Curve(curve)
                                && let Some(b) = target.curve_offset_direction(curve, &image[v])
                            {
                                sum += gk * along(face, &b);
                            }
                        }
                        sum
                    }
                };
            }
            let mut known = rho[f];
            if !self.prescribed.is_empty() {
                for (&v, gk) in self.faces[f].iter().zip(&g) {
                    if self.roles[v] == Role::Fixed && self.prescribed[v] != Vector3::zeros() {
                        known -= gk * along(face, &self.prescribed[v]);
                    }
                }
            }
            for a in 0..m {
                self.rhs[list[a].0] += w * (beta[a].conj() * known).re;
                for b in 0..=a {
                    values[self.slots[at]] += w * (beta[a].conj() * beta[b]).re;
                    at += 1;
                }
            }
        }
        self.solve_normal_equations()?;
        let mut flow = Flow {
            vertex: vec![Vector3::zeros(); self.roles.len()],
            offset: vec![0.0; self.offset.len()],
        };
        for (c, o) in self.offset.iter().enumerate() {
            if let Some(o) = o {
                flow.offset[c] = self.rhs[*o];
            }
        }
        for (v, &role) in self.roles.iter().enumerate() {
            let mut vec = Vector3::zeros();
            for index in 0..unknowns_of(role) {
                vec += self.rhs[self.first[v] + index] * self.directions[v][index];
            }
            if let Role::Curve(c) = role
                && let Some(b) = target.curve_offset_direction(c, &image[v])
            {
                vec += flow.offset[c] * b;
            }
            if role == Role::Fixed && !self.prescribed.is_empty() {
                vec = self.prescribed[v];
            }
            flow.vertex[v] = vec;
        }
        Ok(flow)
    }
}

impl FlowSystem {
    /// Numeric factorizations and conjugate-gradient iterations so far.
    pub fn work(&self) -> (usize, usize) {
        (self.factorizations, self.cg_iterations)
    }

    /// Solves the assembled normal equations in place of `rhs`: by conjugate gradients
    /// preconditioned with the kept factorization when there is one (the matrix changes
    /// little between late steps), else — or when that does not converge within
    /// [`CG_ITERATIONS`] — by factoring the new matrix. After a failed reuse the next
    /// 1, 2, 4, .. steps factor directly.
    fn solve_normal_equations(&mut self) -> Result<(), SolverError> {
        if self.factorizations > 0 && self.skip_reuse == 0 {
            let mut x = self.rhs.clone();
            let outcome = self.solver.solve_preconditioned(
                self.matrix.as_ref(),
                &mut x,
                CG_TOLERANCE,
                CG_ITERATIONS,
            )?;
            self.cg_iterations += outcome.iterations;
            if outcome.converged {
                self.backoff = 1;
                self.rhs = x;
                return Ok(());
            }
            self.skip_reuse = self.backoff;
            self.backoff *= 2;
        } else {
            self.skip_reuse = self.skip_reuse.saturating_sub(1);
        }
        self.solver.factorize(self.matrix.as_ref())?;
        self.factorizations += 1;
        let n = self.rhs.len();
        self.solver
            .solve_in_place(MatMut::from_column_major_slice_mut(&mut self.rhs, n, 1))?;
        Ok(())
    }
}

/// An elimination order of the unknowns: AMD on the graph of the vertices (an edge per
/// triangle side), each vertex's unknowns together, the shared offsets last (they couple
/// to a whole curve). Ordering the vertex graph is about four times cheaper than the
/// unknowns' graph, and keeps each vertex's pair in one supernode.
fn block_order(
    faces: &[[usize; 3]],
    roles: &[Role],
    first: &[usize],
    n: usize,
) -> Result<Vec<usize>, SolverError> {
    let nv = roles.len();
    let mut positions = Vec::with_capacity(nv + 3 * faces.len());
    positions.extend((0..nv).map(|v| (v, v)));
    for f in faces {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            positions.push((a.max(b), a.min(b)));
        }
    }
    let graph = Pattern::new(nv, nv, &positions)?;
    let vertices = amd_order(graph.symbolic().as_ref())?;
    let mut order = Vec::with_capacity(n);
    for v in vertices {
        order.extend(first[v]..first[v] + unknowns_of(roles[v]));
    }
    let vertex_unknowns = order.len();
    order.extend(vertex_unknowns..n);
    Ok(order)
}

/// The directions of the unknowns of a vertex with `role` at `p`, where the target's
/// normal is `normal` (unused entries zero).
fn directions<G: TargetGeometry>(
    target: &G,
    role: Role,
    p: &Point3<f64>,
    normal: &Vector3<f64>,
) -> [Vector3<f64>; 2] {
    match role {
        Role::Free => orthonormal_basis(normal),
        Role::Curve(c) => [target.curve_tangent(c, p), Vector3::zeros()],
        Role::Fixed => [Vector3::zeros(); 2],
    }
}

/// A vector of R^3 as the complex number of its components along the face's `(r, s)`.
#[inline]
fn along(face: &ImageFace, b: &Vector3<f64>) -> Complex64 {
    Complex64::new(b.dot(&face.r), b.dot(&face.s))
}

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
