//! Discrete harmonic 1-forms on a planar triangle mesh and the quadratic differentials
//! they define (Weber, Myles, Zorin 2012, section 4.1, eq. 7, 8, 10).
//!
//! A holomorphic quadratic differential `phi` is encoded by the 1-form
//! `h = v_x dx + v_y dy` with `v_x + i v_y = conj(phi)`: `phi_zbar = 0` is `dh = 0` and
//! `delta h = 0` (eq. 7). `h` is discretized by one real value per edge (eq. 10:
//! `h_ij + h_jk + h_ki = 0` on every triangle, `sum_i w_ij h_ij = 0` with cotangent
//! weights at every interior vertex `j`), and the per-face value of eq. 8,
//!
//! ```text
//! psi_T = (1 / 6 A_T) (h_ij r_ij + h_jk r_jk + h_ki r_ki),   r_ij = t_j - t_i,
//! ```
//!
//! with `t_i` the complex form of the edge normal opposite `i` (`grad f = sum f_i t_i /
//! 2 A_T`), is the constant `v_x + i v_y = conj(phi_T)` of the face. (The extraction of
//! the paper names this value `phi_T`; with the paper's own `h = Re(phi) dx - Im(phi)
//! dy` it is the conjugate, which is what `mu = k conj(phi) / |phi| = k psi / |psi|`
//! needs.) For `h = du` eq. 8 gives `psi_T = u_x + i u_y`, the gradient of `u` on the
//! face, so `psi = 2 d u / d zbar` (checked in the tests).
//!
//! # Parametrization
//!
//! On a planar mesh of genus 0 with `b` boundary loops, a closed 1-form is `du` (a
//! function `u` per vertex) plus a combination of `b - 1` closed forms `g_j` that are
//! not exact, one per inner loop (period 1 around loop `j`, 0 around the others). The
//! unknowns are therefore `x = (u_0, ..., u_{V-1}, c_1, ..., c_{b-1})` with
//! `h = du + sum_j c_j g_j`: the closedness conditions of eq. 10 hold by construction,
//! and the co-closedness conditions at interior vertices stay as linear constraints
//! `C x = 0`, together with `u_{v0} = 0` (`du` does not see constants). A triangle's
//! closed form is fixed by its `psi_T`, so `psi = 0` everywhere only for `h = 0`.
//!
//! `g_j` is the Poincare dual of a path in the dual graph from a face next to inner
//! loop `j` to a face next to the outer loop: `+-1` on the edges the path crosses
//! (including the two boundary edges where it starts and ends), 0 elsewhere. Every face
//! on the path has one edge where the path enters and one where it leaves, with opposite
//! signs in the face's counter-clockwise order, so `dg_j = 0`.

use std::collections::VecDeque;

use beltrami_fem::{EdgeWeights, Elements};
use beltrami_mesh::{FaceId, HalfedgeId, Mesh, VertexId};
use beltrami_sparse::{SaddlePointSolver, SolveError};
use num_complex::Complex64;

/// The space of discrete harmonic 1-forms of a planar triangle mesh, parametrized as in
/// the module docs, with the map from the unknowns to the per-face values `psi`.
#[derive(Debug)]
pub struct HarmonicForms {
    vertex_count: usize,
    generators: usize,
    /// Face `f`'s `psi_f = sum coefficients[k].1 x[coefficients[k].0]` over
    /// `offsets[f]..offsets[f + 1]`.
    offsets: Vec<usize>,
    coefficients: Vec<(usize, Complex64)>,
    /// Entries of `C` (row, column, value).
    constraints: Vec<(usize, usize, f64)>,
    constraint_rows: usize,
}

impl HarmonicForms {
    /// The forms of `mesh` (triangles in the plane z = 0; `elements` in the global
    /// frame). The outer loop is the longest; `weights` are the cotangent weights.
    pub fn new(mesh: &Mesh, elements: &Elements, weights: &EdgeWeights) -> Self {
        let v_count = mesh.vertex_count();
        let loops = mesh.boundary_loop_list();
        let outer = loops
            .iter()
            .enumerate()
            .fold((0, f64::NEG_INFINITY), |best, (i, l)| {
                if l.length > best.1 {
                    (i, l.length)
                } else {
                    best
                }
            })
            .0;
        let generators: Vec<Vec<f64>> = loops
            .iter()
            .enumerate()
            .filter(|&(i, _)| i != outer)
            .map(|(_, l)| dual_path_form(mesh, l.id, loops[outer].id))
            .collect();
        let halfedge_value = |g: &[f64], h: HalfedgeId| {
            let e = mesh.edge(h);
            if mesh.edge_halfedge(e) == h {
                g[e.idx()]
            } else {
                -g[e.idx()]
            }
        };

        let mut offsets = Vec::with_capacity(mesh.face_count() + 1);
        let mut coefficients = Vec::with_capacity(3 * mesh.face_count());
        offsets.push(0);
        for q in elements.points() {
            let nodes = elements.nodes(q.face);
            let grad = |v: VertexId| {
                let k = nodes.iter().position(|&n| n == v).unwrap_or(0);
                Complex64::new(q.grad[k].x, q.grad[k].y)
            };
            for (k, v) in nodes.iter().enumerate() {
                coefficients.push((v.idx(), Complex64::new(q.grad[k].x, q.grad[k].y)));
            }
            // eq. 8 on a face: (1/3) sum over its halfedges of h(he) (grad_head - grad_tail).
            for (j, g) in generators.iter().enumerate() {
                let psi: Complex64 = mesh
                    .face_halfedges(q.face)
                    .map(|he| {
                        halfedge_value(g, he) * (grad(mesh.target(he)) - grad(mesh.origin(he)))
                    })
                    .sum::<Complex64>()
                    / 3.0;
                if psi != Complex64::new(0.0, 0.0) {
                    coefficients.push((v_count + j, psi));
                }
            }
            offsets.push(coefficients.len());
        }

        // Co-closedness at interior vertices: sum_w w_vw h(v -> w) = 0, and the gauge.
        let mut constraints = Vec::new();
        let mut row = 0;
        for v in mesh.vertices() {
            if mesh.is_boundary_vertex(v) {
                continue;
            }
            let mut diagonal = 0.0;
            for (w, weight) in weights.row(v) {
                constraints.push((row, w.idx(), weight));
                diagonal -= weight;
            }
            constraints.push((row, v.idx(), diagonal));
            for (j, g) in generators.iter().enumerate() {
                let delta: f64 = mesh
                    .outgoing_halfedges(v)
                    .map(|he| {
                        let w = mesh.target(he);
                        let weight = weights
                            .row(v)
                            .find(|&(n, _)| n == w)
                            .map_or(0.0, |(_, x)| x);
                        weight * halfedge_value(g, he)
                    })
                    .sum();
                if delta != 0.0 {
                    constraints.push((row, v_count + j, delta));
                }
            }
            row += 1;
        }
        let gauge = loops[outer].vertices[0];
        constraints.push((row, gauge.idx(), 1.0));
        row += 1;
        Self {
            vertex_count: v_count,
            generators: generators.len(),
            offsets,
            coefficients,
            constraints,
            constraint_rows: row,
        }
    }

    /// Number of unknowns: one per vertex and one per inner boundary loop.
    pub fn unknowns(&self) -> usize {
        self.vertex_count + self.generators
    }

    /// Number of non-exact generators (inner boundary loops).
    pub fn generator_count(&self) -> usize {
        self.generators
    }

    /// The per-face values `psi_T = conj(phi_T)` (eq. 8) of the form with unknowns `x`.
    pub fn psi(&self, x: &[f64]) -> Vec<Complex64> {
        self.offsets
            .windows(2)
            .map(|r| {
                self.coefficients[r[0]..r[1]]
                    .iter()
                    .map(|&(j, c)| c * x[j])
                    .sum()
            })
            .collect()
    }

    fn face(&self, f: usize) -> &[(usize, Complex64)] {
        &self.coefficients[self.offsets[f]..self.offsets[f + 1]]
    }
}

/// The closed, non-exact 1-form dual to a shortest dual path from inner loop `from` to
/// the outer loop `to` (module docs), one value per edge along the edge's first
/// halfedge ([`Mesh::edge_halfedge`]).
fn dual_path_form(
    mesh: &Mesh,
    from: beltrami_mesh::BoundaryLoopId,
    to: beltrami_mesh::BoundaryLoopId,
) -> Vec<f64> {
    let mut form = vec![0.0; mesh.edge_count()];
    let mut set = |h: HalfedgeId, value: f64| {
        let e = mesh.edge(h);
        form[e.idx()] = if mesh.edge_halfedge(e) == h {
            value
        } else {
            -value
        };
    };
    // parent[f] = the halfedge of the parent face through which f was reached.
    let mut parent: Vec<Option<HalfedgeId>> = vec![None; mesh.face_count()];
    let mut seen = vec![false; mesh.face_count()];
    let mut queue = VecDeque::new();
    let mut start_of: Vec<Option<HalfedgeId>> = vec![None; mesh.face_count()];
    for b in mesh.loop_halfedges(from) {
        let inside = mesh.twin(b);
        if let Some(f) = mesh.face(inside)
            && !seen[f.idx()]
        {
            seen[f.idx()] = true;
            start_of[f.idx()] = Some(b);
            queue.push_back(f);
        }
    }
    let exit = |f: FaceId| {
        mesh.face_halfedges(f)
            .find(|&he| mesh.boundary_loop(mesh.twin(he)) == Some(to))
    };
    while let Some(f) = queue.pop_front() {
        if let Some(out) = exit(f) {
            // Leave through the outer boundary: +1 on the halfedge in the face left.
            set(out, 1.0);
            let mut face = f;
            while let Some(via) = parent[face.idx()] {
                // `via` is in the parent face, crossing into `face`.
                set(via, 1.0);
                face = mesh.face(via).unwrap_or(face);
            }
            if let Some(b) = start_of[face.idx()] {
                // Enter from the hole: +1 on the boundary halfedge (hole side).
                set(b, 1.0);
            }
            return form;
        }
        for he in mesh.face_halfedges(f) {
            if let Some(n) = mesh.face(mesh.twin(he))
                && !seen[n.idx()]
            {
                seen[n.idx()] = true;
                parent[n.idx()] = Some(he);
                queue.push_back(n);
            }
        }
    }
    form
}

/// The h-step of Algorithm 1: the harmonic form minimizing the least-squares Beltrami
/// energy (eq. 11) for a fixed map, `s` and `k`,
///
/// ```text
/// E(x) = sum_m A_m | a_m - b_m psi_m(x) |^2,   a_m = f_zbar,   b_m = k s_m f_z,
/// ```
///
/// subject to the co-closedness constraints. `x` is real, so `E` is a real quadratic
/// form: `H_jl = sum_m A_m |b_m|^2 Re(conj(Q_mj) Q_ml)`, `g_j = sum_m A_m Re(a_m
/// conj(b_m Q_mj))`, and the minimizer solves `[H C^T; C 0] [x; lambda] = [g; 0]`. The
/// pattern and its symbolic LU are built once and reused every step.
#[derive(Debug)]
pub struct FormStep {
    solver: SaddlePointSolver<f64>,
    c_values: Vec<f64>,
    h_values: Vec<f64>,
    g: Vec<f64>,
    d: Vec<f64>,
}

impl FormStep {
    /// The symbolic phase for `forms`.
    pub fn new(forms: &HarmonicForms) -> Result<Self, SolveError> {
        let mut h_positions = Vec::new();
        for f in 0..forms.offsets.len() - 1 {
            for &(j, _) in forms.face(f) {
                for &(l, _) in forms.face(f) {
                    h_positions.push((j, l));
                }
            }
        }
        let c_positions: Vec<(usize, usize)> =
            forms.constraints.iter().map(|&(r, c, _)| (r, c)).collect();
        let solver = SaddlePointSolver::new(
            forms.unknowns(),
            &h_positions,
            forms.constraint_rows,
            &c_positions,
        )?;
        Ok(Self {
            solver,
            c_values: forms.constraints.iter().map(|&(_, _, v)| v).collect(),
            h_values: vec![0.0; h_positions.len()],
            g: vec![0.0; forms.unknowns()],
            d: vec![0.0; forms.constraint_rows],
        })
    }

    /// The minimizer `x` for per-face `a`, `b` and areas.
    pub fn solve(
        &mut self,
        forms: &HarmonicForms,
        a: &[Complex64],
        b: &[Complex64],
        areas: &[f64],
    ) -> Result<Vec<f64>, SolveError> {
        self.g.iter_mut().for_each(|g| *g = 0.0);
        let mut slot = 0;
        for (f, ((&a, &b), &area)) in a.iter().zip(b).zip(areas).enumerate() {
            let row = forms.face(f);
            let weight = area * b.norm_sqr();
            for &(j, qj) in row {
                self.g[j] += area * (a * (b * qj).conj()).re;
                for &(_, ql) in row {
                    self.h_values[slot] = weight * (qj.conj() * ql).re;
                    slot += 1;
                }
            }
        }
        Ok(self
            .solver
            .solve(&self.h_values, &self.c_values, &self.g, &self.d)?
            .x)
    }
}
