//! The quaternionic least-squares Beltrami operator of maps from a surface into R^3
//! (Gruber-Aulisa 2022, sections 3-4).
//!
//! A map `f: M -> R^3` with vertex images `x_v` has, at a quadrature point with source
//! normal `N` and frame `(e1, e2)`, the derivatives `df(e1) = f_x`, `df(e2) = f_y`
//! (sums of `x_v` times the shape gradients), and the conformal and anticonformal parts
//! `df^+ = (f_x - N f_y) / 2`, `df^- = (f_x + N f_y) / 2` (quaternion products,
//! [`crate::quaternion::conformal_parts`]). `f` has the normal-valued coefficient
//! `mu = mu1 + mu2 N` when `df^- = mu df^+` (Definition 3.3), an equation of four real
//! components that is linear in the `x_v`: the operator here maps the `3 V` coordinates
//! `[x_0, y_0, z_0, x_1, ...]` to the four components `(w, i, j, k)` of
//! `df^- - mu df^+` at every quadrature point (rows `4 q .. 4 q + 4`), and the
//! least-squares map minimizes `sum_q w_q |df^- - mu df^+|^2` (Algorithm 1) under the
//! boundary values. `mu1 + i mu2` is the complex number of a Beltrami field in the face
//! frame (`Frame::Face`): for a map that stays in the source's tangent planes it is the
//! intrinsic Beltrami coefficient.

use beltrami_mesh::Mesh;
use faer::sparse::SparseColMat;
use nalgebra::{Quaternion, Vector3};
use num_complex::Complex64;

use crate::assembly::Pattern;
use crate::quaternion::conformal_parts;
use crate::{Elements, FemError};

/// Rows per quadrature point: the quaternion components `(w, i, j, k)`.
pub const ROWS_PER_POINT: usize = 4;

/// The operator `x -> df^- - mu df^+` (module docs) of `elements` (built with
/// `Frame::Face`) for the coefficients `mu` per face (`mu1 + i mu2`), on `vertex_count`
/// vertices: `4 Q` rows, `3 vertex_count` columns, followed by the rows of `extra`
/// (e.g. [`NormalConstraint`]).
pub fn quaternionic_operator(
    elements: &Elements,
    vertex_count: usize,
    mu: &[Complex64],
    extra: Option<&NormalConstraint>,
) -> Result<SparseColMat<usize, f64>, FemError> {
    if mu.len() != elements.face_count() {
        return Err(FemError::Length {
            what: "Beltrami coefficient",
            expected: elements.face_count(),
            got: mu.len(),
        });
    }
    let mut positions = Vec::with_capacity(elements.point_count() * 4 * 4 * 3);
    let mut values = Vec::with_capacity(positions.capacity());
    for (q_index, q) in elements.points().iter().enumerate() {
        let normal = q.frame.normal;
        let m = mu[q.face.idx()];
        let coefficient = Quaternion::from_parts(m.re, normal * m.im);
        for (k, v) in elements.nodes(q.face).iter().enumerate() {
            let g = q.grad[k];
            for axis in 0..3 {
                // The residual of the map that moves vertex v by the unit vector of
                // `axis`: column 3 v + axis of the operator.
                let e = Vector3::ith(axis, 1.0);
                let (plus, minus) = conformal_parts(&normal, &(e * g.x), &(e * g.y));
                let r = minus - coefficient * plus;
                let components = [r.w, r.i, r.j, r.k];
                for (c, &value) in components.iter().enumerate() {
                    positions.push((ROWS_PER_POINT * q_index + c, 3 * v.idx() + axis));
                    values.push(value);
                }
            }
        }
    }
    let first = ROWS_PER_POINT * elements.point_count();
    let mut rows = first;
    if let Some(extra) = extra {
        for (r, normal) in extra.normals.iter().enumerate() {
            for axis in 0..3 {
                positions.push((first + r, 3 * r + axis));
                values.push(normal[axis]);
            }
        }
        rows += extra.normals.len();
    }
    Pattern::new(rows, 3 * vertex_count, &positions)?.assemble(&values)
}

/// The linearized normal constraint of section 4.1: the displacement of every vertex
/// stays tangent to the source, `<f(x_v) - x_v, N_v> = 0`, as the penalty
/// `(1 / eps) sum_v A_v <f(x_v) - x_v, N_v>^2` (the paper's Lagrange multiplier with its
/// `eps` term eliminated: `rho = -<v, N> / eps`), with `A_v` a third of the areas of the
/// triangles around `v` (a quarter of the quads') and `N_v` the angle-weighted vertex
/// normal. One row per vertex after the `4 Q` rows of the operator.
#[derive(Debug, Clone)]
pub struct NormalConstraint {
    /// `N_v` per vertex.
    pub normals: Vec<Vector3<f64>>,
    /// `<x_v, N_v>` per vertex: the right-hand side.
    pub rhs: Vec<f64>,
    /// `A_v / eps` per vertex: the row weights.
    pub weights: Vec<f64>,
}

impl NormalConstraint {
    /// The constraint of `mesh` with the weight `1 / eps = weight`.
    pub fn new(mesh: &Mesh, weight: f64) -> Self {
        let normals = mesh.vertex_normals();
        let mut areas = vec![0.0; mesh.vertex_count()];
        for f in mesh.faces() {
            let (v, n) = mesh.face_vertex_array(f);
            let share = mesh.face_area(f) / n as f64;
            for v in &v[..n] {
                areas[v.idx()] += share;
            }
        }
        let rhs = mesh
            .positions()
            .iter()
            .zip(&normals)
            .map(|(p, n)| p.coords.dot(n))
            .collect();
        Self {
            normals,
            rhs,
            weights: areas.iter().map(|a| a * weight).collect(),
        }
    }
}

/// The weight of every row of [`quaternionic_operator`]: the quadrature weight of its
/// point, repeated for the four components.
pub fn row_weights(elements: &Elements) -> Vec<f64> {
    elements
        .points()
        .iter()
        .flat_map(|q| [q.weight; ROWS_PER_POINT])
        .collect()
}
