//! One step of QCMC: the least-squares problem (19) of Ho-Lui 2016 in the update of the
//! map, the centres and the radii.
//!
//! With `A(mu) = d/dzbar - mu d/dz` and the current map `g` onto the circle domain
//! `D = unit disk minus the disks B(c_j, r_j)`, the step `delta g` minimizes (eq. 12,
//! `p = 2`)
//!
//! ```text
//! E(delta g) = sum_q w_q |A(mu) (g + delta g)(q)|^2
//! ```
//!
//! over the quadrature points `q` of the elements (weights `w_q`, derivatives in each
//! point's frame), where the update of a vertex is, by its kind (eq. 13-14, 17):
//!
//! | vertex | update | real unknowns |
//! |---|---|---|
//! | interior | `x + i y` | 2 |
//! | on the outer loop | `t i e`, `e = g - 0` (the unit circle's normal) | 1 |
//! | on inner loop `j` | `t i e + delta c_j + delta r_j e`, `e = (g - c_j) / abs(g - c_j)` | 1, plus the loop's 3 |
//! | the normalization vertex (outer loop, at `1`) | `0` | 0 |
//!
//! and `delta c_1 = 0` for the first inner circle (held at the centre). These are the
//! columns of the constraint matrix `K` of section 6.2: a loop vertex's update is
//! tangential, plus the shared motion of its circle. `A(mu) delta g(q) = sum_k a_k
//! delta g_k` with `a_k = d_zbar N_k - mu d_z N_k` is real-linear in the unknowns: the
//! coefficient of unknown `u` is `beta_u = sum_k a_k b_ku` over the face's vertices `k`
//! and the directions `b_ku` (complex numbers above) with which `u` moves them. The
//! minimizer solves the normal equations
//!
//! ```text
//! sum_v Re(conj(beta_u) beta_v) w_q y_v = -Re(conj(beta_u) r_q) w_q,   r_q = A(mu) g (q),
//! ```
//!
//! summed over the points. The unknowns, the pattern and the symbolic Cholesky
//! factorization are fixed; each step refills the values.

use beltrami_core::SolverError;
use beltrami_fem::Elements;
use beltrami_fem::assembly::Pattern;
use beltrami_mesh::VertexId;
use beltrami_sparse::{SolveOptions, SpdSolver};
use faer::sparse::SparseColMat;
use num_complex::Complex64;

use crate::initial::{CircleMap, Loops};

const I: Complex64 = Complex64::new(0.0, 1.0);

/// How a vertex moves in a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    /// Two unknowns from `first`.
    Interior { first: usize },
    /// One tangential unknown `first` on loop `circle`.
    OnLoop { first: usize, circle: usize },
    /// Held (the normalization vertex).
    Held,
}

/// The update of one step: per vertex its move (the tangential part and, for inner
/// loops, the motion of the circle: [`Step::apply`] puts loop vertices back onto the
/// moved circles), per circle the moves of its centre and radius.
#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    /// Per vertex, `delta g` (eq. 17).
    pub vertex: Vec<Complex64>,
    /// Per loop, `delta c`.
    pub center: Vec<Complex64>,
    /// Per loop, `delta r`.
    pub radius: Vec<f64>,
}

impl Step {
    /// The map and circles after a step of size `t`: `c + t delta c`, `r + t delta r`,
    /// `g + t delta g`, loop vertices then projected onto their moved circle (eq. 16).
    pub fn apply(&self, from: &CircleMap, t: f64, loop_of: &[Option<usize>]) -> CircleMap {
        let circles: Vec<_> = from
            .circles
            .iter()
            .enumerate()
            .map(|(j, c)| crate::moebius::PlaneCircle {
                center: c.center + t * self.center[j],
                radius: c.radius + t * self.radius[j],
            })
            .collect();
        let map = from
            .map
            .iter()
            .zip(&self.vertex)
            .zip(loop_of)
            .map(|((g, d), l)| {
                let moved = g + t * d;
                match l {
                    Some(j) => circles[*j].project(moved),
                    None => moved,
                }
            })
            .collect();
        CircleMap { map, circles }
    }
}

/// Which unknowns move what (module docs).
#[derive(Debug, Clone)]
struct Layout {
    kind: Vec<Kind>,
    /// Per loop, the first of the two unknowns of its centre (none for the outer circle
    /// and the first inner one).
    center: Vec<Option<usize>>,
    /// Per loop, the unknown of its radius (none for the outer circle).
    radius: Vec<Option<usize>>,
    loop_of: Vec<Option<usize>>,
    /// Number of unknowns.
    n: usize,
}

impl Layout {
    fn new(vertex_count: usize, loops: &Loops, held: VertexId) -> Self {
        let loop_of = loops.loop_of(vertex_count);
        let mut n = 0;
        let kind: Vec<Kind> = (0..vertex_count)
            .map(|i| {
                if i == held.idx() {
                    Kind::Held
                } else if let Some(circle) = loop_of[i] {
                    n += 1;
                    Kind::OnLoop {
                        first: n - 1,
                        circle,
                    }
                } else {
                    n += 2;
                    Kind::Interior { first: n - 2 }
                }
            })
            .collect();
        let mut center = vec![None; loops.len()];
        let mut radius = vec![None; loops.len()];
        for j in 1..loops.len() {
            if j > 1 {
                center[j] = Some(n);
                n += 2;
            }
            radius[j] = Some(n);
            n += 1;
        }
        Self {
            kind,
            center,
            radius,
            loop_of,
            n,
        }
    }

    /// Calls `term(u, b)` for every unknown `u` moving vertex `v`, with its direction
    /// `b` (`e` is the unit normal of the vertex's circle at its image).
    fn terms(&self, v: VertexId, e: Complex64, mut term: impl FnMut(usize, Complex64)) {
        match self.kind[v.idx()] {
            Kind::Interior { first } => {
                term(first, Complex64::new(1.0, 0.0));
                term(first + 1, I);
            }
            Kind::OnLoop { first, .. } => term(first, I * e),
            Kind::Held => {}
        }
        if let Some(j) = self.loop_of[v.idx()] {
            if let Some(c) = self.center[j] {
                term(c, Complex64::new(1.0, 0.0));
                term(c + 1, I);
            }
            if let Some(u) = self.radius[j] {
                term(u, e);
            }
        }
    }
}

/// The unknowns of a step, the pattern of its normal equations and their factorization.
pub struct StepSystem {
    layout: Layout,
    /// The unknowns of quadrature point `q` are `local[local_ptr[q]..local_ptr[q + 1]]`,
    /// in the order [`Layout::terms`] meets them.
    local_ptr: Vec<usize>,
    local: Vec<usize>,
    /// Per point, the matrix slots of its lower-triangle pairs `(a, b)`, `b <= a`, in
    /// the order `a` then `b`.
    slot_ptr: Vec<usize>,
    slots: Vec<usize>,
    matrix: SparseColMat<usize, f64>,
    solver: SpdSolver<f64>,
    rhs: Vec<f64>,
}

impl std::fmt::Debug for StepSystem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StepSystem")
            .field("unknowns", &self.rhs.len())
            .field("entries", &self.slots.len())
            .finish_non_exhaustive()
    }
}

impl StepSystem {
    /// The unknowns (module docs) for `loops` with `held` fixed, the pattern and the
    /// symbolic factorization.
    pub fn new(
        elements: &Elements,
        vertex_count: usize,
        loops: &Loops,
        held: VertexId,
        options: SolveOptions,
    ) -> Result<Self, SolverError> {
        let layout = Layout::new(vertex_count, loops, held);
        let n = layout.n;
        let mut local_ptr = vec![0];
        let mut local = Vec::new();
        let mut slot_ptr = vec![0];
        let mut positions = Vec::new();
        let zero = Complex64::new(0.0, 0.0);
        for q in elements.points() {
            let start = local.len();
            for &v in elements.nodes(q.face) {
                layout.terms(v, zero, |u, _| {
                    if !local[start..].contains(&u) {
                        local.push(u);
                    }
                });
            }
            let l = &local[start..];
            for a in 0..l.len() {
                for b in 0..=a {
                    positions.push((l[a].max(l[b]), l[a].min(l[b])));
                }
            }
            local_ptr.push(local.len());
            slot_ptr.push(positions.len());
        }
        let pattern = Pattern::new(n, n, &positions)?;
        Ok(Self {
            slots: pattern.slots().to_vec(),
            matrix: pattern.assemble(&vec![0.0; positions.len()])?,
            solver: SpdSolver::new(pattern.symbolic().as_ref(), options)?,
            layout,
            local_ptr,
            local,
            slot_ptr,
            rhs: vec![0.0; n],
        })
    }

    /// Per vertex, the loop it lies on.
    pub fn loop_of(&self) -> &[Option<usize>] {
        &self.layout.loop_of
    }

    /// `E = sum_q w_q |A(mu) g (q)|^2` of the map `map` (module docs), `mu` per face in
    /// the elements' frame.
    pub fn energy(elements: &Elements, mu: &[Complex64], map: &[Complex64]) -> f64 {
        elements
            .points()
            .iter()
            .map(|q| {
                let m = mu[q.face.idx()];
                let r: Complex64 = elements
                    .nodes(q.face)
                    .iter()
                    .enumerate()
                    .map(|(k, v)| coefficient(q.grad[k], m) * map[v.idx()])
                    .sum();
                q.weight * r.norm_sqr()
            })
            .sum()
    }

    /// The step from `state` (module docs) and the energy of `state`.
    pub fn step(
        &mut self,
        elements: &Elements,
        mu: &[Complex64],
        state: &CircleMap,
    ) -> Result<(Step, f64), SolverError> {
        let directions: Vec<Complex64> = state
            .map
            .iter()
            .zip(&self.layout.loop_of)
            .map(|(g, l)| match l {
                Some(j) => {
                    let d = g - state.circles[*j].center;
                    d / d.norm()
                }
                None => Complex64::new(0.0, 0.0),
            })
            .collect();
        self.matrix.val_mut().fill(0.0);
        self.rhs.fill(0.0);
        let mut energy = 0.0;
        let mut beta = Vec::new();
        for (p, q) in elements.points().iter().enumerate() {
            let local = &self.local[self.local_ptr[p]..self.local_ptr[p + 1]];
            beta.clear();
            beta.resize(local.len(), Complex64::new(0.0, 0.0));
            let m = mu[q.face.idx()];
            let mut r = Complex64::new(0.0, 0.0);
            for (k, v) in elements.nodes(q.face).iter().enumerate() {
                let a = coefficient(q.grad[k], m);
                r += a * state.map[v.idx()];
                self.layout.terms(*v, directions[v.idx()], |u, b| {
                    if let Some(x) = local.iter().position(|&x| x == u) {
                        beta[x] += a * b;
                    }
                });
            }
            let w = q.weight;
            energy += w * r.norm_sqr();
            let values = self.matrix.val_mut();
            let slots = &self.slots[self.slot_ptr[p]..self.slot_ptr[p + 1]];
            let mut s = 0;
            for a in 0..local.len() {
                self.rhs[local[a]] -= w * (beta[a].conj() * r).re;
                for b in 0..=a {
                    values[slots[s]] += w * (beta[a].conj() * beta[b]).re;
                    s += 1;
                }
            }
        }
        self.solver.factorize(self.matrix.as_ref())?;
        self.solver.solve_vector_in_place(&mut self.rhs)?;
        let y = &self.rhs;
        let mut step = Step {
            vertex: vec![Complex64::new(0.0, 0.0); state.map.len()],
            center: vec![Complex64::new(0.0, 0.0); state.circles.len()],
            radius: vec![0.0; state.circles.len()],
        };
        for j in 0..state.circles.len() {
            if let Some(c) = self.layout.center[j] {
                step.center[j] = Complex64::new(y[c], y[c + 1]);
            }
            if let Some(u) = self.layout.radius[j] {
                step.radius[j] = y[u];
            }
        }
        for (i, d) in step.vertex.iter_mut().enumerate() {
            let e = directions[i];
            *d = match self.layout.kind[i] {
                Kind::Interior { first } => Complex64::new(y[first], y[first + 1]),
                Kind::OnLoop { first, circle } => {
                    y[first] * I * e + step.center[circle] + step.radius[circle] * e
                }
                Kind::Held => Complex64::new(0.0, 0.0),
            };
        }
        Ok((step, energy))
    }
}

/// `a_k = d_zbar N_k - mu d_z N_k` for the gradient `(d_x N_k, d_y N_k)` of a shape
/// function: `d_z = (d_x - i d_y) / 2`, `d_zbar = (d_x + i d_y) / 2`.
fn coefficient(grad: nalgebra::Vector2<f64>, mu: Complex64) -> Complex64 {
    let dz = Complex64::new(0.5 * grad.x, -0.5 * grad.y);
    let dzbar = Complex64::new(0.5 * grad.x, 0.5 * grad.y);
    dzbar - mu * dz
}
