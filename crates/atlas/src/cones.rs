//! Cone singularities placed greedily where the conformal scale is most extreme
//! (Ben-Chen, Gotsman and Bunin 2008, "Conformal flattening by curvature prescription
//! and metric scaling", section 4).
//!
//! A conformal flattening multiplies the surface's lengths by `e^u`; with the
//! curvature of the flat metric zero away from the cones, `u` solves the discrete
//! Yamabe equation `L u = -Omega` at every vertex that is neither a cone nor on the
//! boundary (`L` the positive semi-definite cotan Laplacian, `Omega` the angle
//! defect), with `u = 0` at the cones and on the boundary (no area distortion there;
//! Springborn, Schroeder and Pinkall 2008 and Sawhney and Crane 2017 use the same
//! linearization). The curvature a cone takes is whatever is left there; the greedy
//! rule adds the next cone at the vertex of largest `|u|`, until the map's predicted
//! L2 stretch `sqrt(mean_A(e^{-2u}) mean_A(e^{2u}))` (see [`crate::stretch`](mod@crate::stretch)) is at
//! most the goal or the count is reached.
//!
//! A closed surface with no cone yet first gets the scale of the metric of constant
//! curvature (`L u = -(Omega - Omega_total a_i / A)`, one vertex held), and its first
//! cone where that scale deviates most from its mean. A closed surface of genus 0 gets
//! at least two cones (its cut is a path between them), of genus `g >= 2` at least one
//! (the Yamabe equation without one has no solution); a torus needs none.
//!
//! The boundary (and a closed chart's first cone) is held by a penalty
//! `P = 1e10 max_i L_ii` on the diagonal of one factored matrix; every later cone costs
//! one solve with that factorization, the cones held exactly through the Woodbury
//! identity (`u = u0 - G_S (G_SS)^{-1} u0_S`, `G` the factored matrix's inverse, `S`
//! the cones added).

use beltrami_fem::operators::cotan_laplacian;
use beltrami_mesh::{Mesh, VertexId};
use beltrami_sparse::{SolveOptions, SpdSolver};
use faer::Mat;
use faer::sparse::SparseColMat;

use crate::AtlasError;
use crate::held::{PENALTY, diagonal_slots};

/// Cones of a chart and the log scale factor of its flattening.
#[derive(Debug, Clone, PartialEq)]
pub struct Cones {
    /// The cone vertices, in the order they were placed.
    pub vertices: Vec<VertexId>,
    /// The log scale factor `u` of every vertex (0 at the cones and on the boundary).
    pub scale: Vec<f64>,
    /// The predicted L2 stretch of the flattening with these cones.
    pub predicted_stretch: f64,
}

/// How many cones to place.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConeGoal {
    /// Stop once the predicted L2 stretch is at most this.
    pub stretch: f64,
    /// Never place more than this many cones.
    pub max_cones: usize,
}

/// Places cones on `mesh` (one connected triangle mesh) greedily until `goal` is met
/// (see the module docs).
pub fn place_cones(mesh: &Mesh, goal: ConeGoal) -> Result<Cones, AtlasError> {
    let mut system = ScaleSystem::new(mesh)?;
    let closed = mesh.boundary_loop_count() == 0;
    let euler = mesh.vertex_count() as i64 - mesh.edge_count() as i64 + mesh.face_count() as i64;
    let min_cones = match (closed, euler) {
        (true, 2) => 2,
        (true, e) if e < 0 => 1,
        _ => 0,
    };
    let mut cones = Vec::new();
    let mut fixed: Vec<bool> = mesh
        .vertices()
        .map(|v| mesh.is_boundary_vertex(v))
        .collect();
    if closed {
        let u = system.constant_curvature_scale()?;
        if min_cones == 0 {
            let predicted = system.predicted_stretch(&u);
            if predicted <= goal.stretch || goal.max_cones == 0 {
                return Ok(Cones {
                    vertices: cones,
                    scale: u,
                    predicted_stretch: predicted,
                });
            }
        }
        let mean = system.area_mean(&u);
        let first = extreme(&u, &fixed, mean);
        fixed[first.idx()] = true;
        cones.push(first);
    }
    // One factorization with the boundary (and a closed chart's first cone) held; each
    // further cone is one more solve: with `G` the inverse of that matrix and `S` the
    // added cones, `u = u0 - G_S (G_SS)^{-1} u0_S` is the solution with `S` held too
    // (the limit of the penalty, by the Woodbury identity).
    system.factor(&fixed)?;
    let rhs: Vec<f64> = system
        .defect
        .iter()
        .zip(&fixed)
        .map(|(&d, &f)| if f { 0.0 } else { -d })
        .collect();
    let base = system.solve_factored(&rhs)?;
    let mut added: Vec<usize> = Vec::new();
    let mut columns: Vec<Vec<f64>> = Vec::new();
    loop {
        let u = held_at(&base, &added, &columns);
        let predicted = system.predicted_stretch(&u);
        let done = cones.len() >= min_cones
            && (predicted <= goal.stretch || cones.len() >= goal.max_cones);
        if done || fixed.iter().all(|&f| f) {
            return Ok(Cones {
                vertices: cones,
                scale: u,
                predicted_stretch: predicted,
            });
        }
        let next = extreme(&u, &fixed, 0.0);
        fixed[next.idx()] = true;
        cones.push(next);
        let mut unit = vec![0.0; u.len()];
        unit[next.idx()] = 1.0;
        columns.push(system.solve_factored(&unit)?);
        added.push(next.idx());
    }
}

/// `base - G_S (G_SS)^{-1} base_S`: the scale with the vertices `added` held at zero
/// too, from the columns `G e_s` of the held system's inverse.
fn held_at(base: &[f64], added: &[usize], columns: &[Vec<f64>]) -> Vec<f64> {
    let k = added.len();
    let mut u = base.to_vec();
    if k == 0 {
        return u;
    }
    let mut matrix: Vec<Vec<f64>> = added
        .iter()
        .map(|&i| columns.iter().map(|g| g[i]).collect())
        .collect();
    let mut alpha: Vec<f64> = added.iter().map(|&i| base[i]).collect();
    // Gaussian elimination with partial pivoting (k is at most the cone budget).
    for c in 0..k {
        let pivot = (c..k)
            .max_by(|&a, &b| matrix[a][c].abs().total_cmp(&matrix[b][c].abs()))
            .unwrap_or(c);
        matrix.swap(c, pivot);
        alpha.swap(c, pivot);
        let pivot_row = matrix[c].clone();
        for r in c + 1..k {
            let factor = matrix[r][c] / pivot_row[c];
            for (x, p) in matrix[r][c..].iter_mut().zip(&pivot_row[c..]) {
                *x -= factor * p;
            }
            alpha[r] -= factor * alpha[c];
        }
    }
    for c in (0..k).rev() {
        let tail: f64 = (c + 1..k).map(|j| matrix[c][j] * alpha[j]).sum();
        alpha[c] = (alpha[c] - tail) / matrix[c][c];
    }
    for (g, a) in columns.iter().zip(&alpha) {
        for (x, gi) in u.iter_mut().zip(g) {
            *x -= a * gi;
        }
    }
    u
}

/// The free vertex where `|u - center|` is largest.
fn extreme(u: &[f64], fixed: &[bool], center: f64) -> VertexId {
    let best = (0..u.len())
        .filter(|&i| !fixed[i])
        .max_by(|&a, &b| (u[a] - center).abs().total_cmp(&(u[b] - center).abs()))
        .unwrap_or(0);
    VertexId::from_usize(best)
}

/// The Yamabe system of one chart with a fixed pattern.
struct ScaleSystem {
    laplacian: SparseColMat<usize, f64>,
    /// Index of each diagonal entry in the values of `laplacian`.
    diagonal: Vec<usize>,
    penalty: f64,
    solver: SpdSolver<f64>,
    defect: Vec<f64>,
    area: Vec<f64>,
}

impl ScaleSystem {
    fn new(mesh: &Mesh) -> Result<Self, AtlasError> {
        let laplacian = cotan_laplacian(mesh)?;
        let symbolic = laplacian.symbolic();
        let diagonal = diagonal_slots(&laplacian);
        let values = laplacian.val();
        let largest = diagonal.iter().map(|&k| values[k]).fold(0.0, f64::max);
        let solver = SpdSolver::new(symbolic, SolveOptions::default())?;
        Ok(Self {
            diagonal,
            penalty: PENALTY * largest.max(f64::MIN_POSITIVE),
            solver,
            defect: mesh.vertices().map(|v| mesh.angle_defect(v)).collect(),
            area: mesh.vertex_areas(),
            laplacian,
        })
    }

    /// The scale of the metric of constant curvature on a closed surface, with vertex
    /// 0 held at zero (the right-hand side sums to zero, so holding one vertex only
    /// fixes the additive constant).
    fn constant_curvature_scale(&mut self) -> Result<Vec<f64>, AtlasError> {
        let total: f64 = self.defect.iter().sum();
        let area: f64 = self.area.iter().sum();
        let rhs: Vec<f64> = self
            .defect
            .iter()
            .zip(&self.area)
            .map(|(&d, &a)| -(d - total * a / area))
            .collect();
        let mut fixed = vec![false; rhs.len()];
        fixed[0] = true;
        self.solve_held(&fixed, &rhs)
    }

    fn solve_held(&mut self, fixed: &[bool], rhs: &[f64]) -> Result<Vec<f64>, AtlasError> {
        self.factor(fixed)?;
        self.solve_factored(rhs)
    }

    /// Factors `L` with the vertices `fixed` held (the penalty on their diagonal).
    fn factor(&mut self, fixed: &[bool]) -> Result<(), AtlasError> {
        let mut matrix = self.laplacian.clone();
        let values = matrix.val_mut();
        for (i, &f) in fixed.iter().enumerate() {
            if f {
                values[self.diagonal[i]] += self.penalty;
            }
        }
        self.solver.factorize(matrix.as_ref())?;
        Ok(())
    }

    /// Solves with the last factorization.
    fn solve_factored(&mut self, rhs: &[f64]) -> Result<Vec<f64>, AtlasError> {
        let mut x = Mat::from_fn(rhs.len(), 1, |i, _| rhs[i]);
        self.solver.solve_in_place(x.as_mut())?;
        Ok((0..rhs.len()).map(|i| x[(i, 0)]).collect())
    }

    fn area_mean(&self, u: &[f64]) -> f64 {
        let total: f64 = self.area.iter().sum();
        u.iter().zip(&self.area).map(|(u, a)| u * a).sum::<f64>() / total
    }

    /// `sqrt(mean_A(e^{-2u}) mean_A(e^{2u}))`, the L2 stretch of a conformal map with
    /// log scale `u` (see [`crate::stretch`]).
    fn predicted_stretch(&self, u: &[f64]) -> f64 {
        let total: f64 = self.area.iter().sum();
        let (mut shrink, mut grow) = (0.0, 0.0);
        for (&u, &a) in u.iter().zip(&self.area) {
            shrink += a * (-2.0 * u).exp();
            grow += a * (2.0 * u).exp();
        }
        (shrink * grow).sqrt() / total
    }
}
