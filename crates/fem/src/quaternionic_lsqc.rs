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

use beltrami_mesh::{Mesh, Point3, VertexId};
use faer::sparse::SparseColMat;
use nalgebra::{Quaternion, Vector3};
use num_complex::Complex64;

use crate::assembly::Pattern;
use crate::quaternion::conformal_parts;
use crate::{Elements, FemError};

/// Rows per quadrature point: the quaternion components `(w, i, j, k)`.
pub const ROWS_PER_POINT: usize = 4;

/// The operator `x -> df^- - mu df^+` (module docs) of `elements` (built with
/// `Frame::Face`) for coefficients `mu` per face (`mu1 + i mu2`), on `vertex_count`
/// vertices: `4 Q` rows, `3 vertex_count` columns, followed by the rows of `extra`
/// (e.g. [`NormalConstraint`]). The pattern is sorted once; each
/// [`assemble`](Self::assemble) only recomputes the values for a new `mu`.
#[derive(Debug, Clone)]
pub struct QuaternionicOperator {
    pattern: Pattern,
}

impl QuaternionicOperator {
    /// The pattern for `elements` on `vertex_count` vertices, with the rows of `extra`.
    pub fn new(
        elements: &Elements,
        vertex_count: usize,
        extra: Option<&NormalConstraint>,
    ) -> Result<Self, FemError> {
        let mut positions = Vec::with_capacity(elements.point_count() * 4 * 4 * 3);
        for (q_index, q) in elements.points().iter().enumerate() {
            for v in elements.nodes(q.face) {
                for axis in 0..3 {
                    for c in 0..ROWS_PER_POINT {
                        positions.push((ROWS_PER_POINT * q_index + c, 3 * v.idx() + axis));
                    }
                }
            }
        }
        let first = ROWS_PER_POINT * elements.point_count();
        let mut rows = first;
        if let Some(extra) = extra {
            for r in 0..extra.normals.len() {
                for axis in 0..3 {
                    positions.push((first + r, 3 * r + axis));
                }
            }
            rows += extra.normals.len();
        }
        Ok(Self {
            pattern: Pattern::new(rows, 3 * vertex_count, &positions)?,
        })
    }

    /// The symbolic structure of the operator.
    pub fn symbolic(&self) -> &faer::sparse::SymbolicSparseColMat<usize> {
        self.pattern.symbolic()
    }

    /// The operator for `mu` (one value per face): the same `elements` and `extra` as
    /// [`new`](Self::new).
    pub fn assemble(
        &self,
        elements: &Elements,
        mu: &[Complex64],
        extra: Option<&NormalConstraint>,
    ) -> Result<SparseColMat<usize, f64>, FemError> {
        crate::beltrami::check_len("Beltrami coefficient", elements.face_count(), mu.len())?;
        let mut values = Vec::with_capacity(self.pattern.entry_count());
        for q in elements.points() {
            let normal = q.frame.normal;
            let m = mu[q.face.idx()];
            let coefficient = Quaternion::from_parts(m.re, normal * m.im);
            for k in 0..elements.nodes(q.face).len() {
                let g = q.grad[k];
                for axis in 0..3 {
                    // The residual of the map that moves vertex v by the unit vector of
                    // `axis`: column 3 v + axis of the operator.
                    let e = Vector3::ith(axis, 1.0);
                    let (plus, minus) = conformal_parts(&normal, &(e * g.x), &(e * g.y));
                    let r = minus - coefficient * plus;
                    values.extend([r.w, r.i, r.j, r.k]);
                }
            }
        }
        if let Some(extra) = extra {
            for normal in &extra.normals {
                values.extend(normal.iter());
            }
        }
        self.pattern.assemble(&values)
    }
}

/// The residual `df^- - mu df^+` of the map `image` at every quadrature point of
/// `elements`, its four components `(w, i, j, k)` each times the square root of the
/// point's weight: the squared norm is the distortion `QC_mu(image)` of section 4 (the
/// operator's rows applied to the image, without assembling them).
pub fn quaternionic_residual(
    elements: &Elements,
    image: &[Point3<f64>],
    mu: &[Complex64],
) -> Result<Vec<f64>, FemError> {
    crate::beltrami::check_len("Beltrami coefficient", elements.face_count(), mu.len())?;
    let derivatives = crate::beltrami::spatial_derivatives(elements, image.len(), image)?;
    let mut r = Vec::with_capacity(ROWS_PER_POINT * elements.point_count());
    for (q, d) in elements.points().iter().zip(derivatives) {
        let normal = q.frame.normal;
        let m = mu[q.face.idx()];
        let coefficient = Quaternion::from_parts(m.re, normal * m.im);
        let (plus, minus) = conformal_parts(&normal, &d.dx, &d.dy);
        let residual = (minus - coefficient * plus) * q.weight.sqrt();
        r.extend([residual.w, residual.i, residual.j, residual.k]);
    }
    Ok(r)
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

/// The weight of every row of [`QuaternionicOperator`]: the quadrature weight of its
/// point, repeated for the four components.
pub fn row_weights(elements: &Elements) -> Vec<f64> {
    elements
        .points()
        .iter()
        .flat_map(|q| [q.weight; ROWS_PER_POINT])
        .collect()
}

/// The linearized area constraint of section 4.2: the first variation of the area at
/// the source vanishes, `int_M <d1_M, dv> dS = 0` for the displacement `v = f - 1_M`,
/// i.e. the single linear equation `<c, x> = <c, p>` on the `3 V` image coordinates `x`
/// (`p` the source positions), with
///
/// ```text
/// c_j = sum_q w_q sum_a g_j,a dX(e_a),   dX(e_a) = sum_i p_i g_i,a,
/// ```
///
/// `g_j` the shape gradient of vertex `j` in the point's frame `(e1, e2)`. On the
/// surface's own elements `dX(e_a) = e_a` and `c_j = int grad phi_j`, the area gradient
/// (the integrated mean-curvature normal, `<c, p> = 2 A`); on reference elements
/// ([`crate::Elements::with_reference_angles`]) `dX` is the map from the reference
/// shapes. One multiplier for the whole surface, eliminated by
/// [`crate::LeastSquaresSolver::solve_with_equality`].
#[derive(Debug, Clone)]
pub struct AreaConstraint {
    /// `c` (`3 V`, ordered `[x_0, y_0, z_0, x_1, ...]`).
    pub gradient: Vec<f64>,
    /// `<c, p>`: the right-hand side.
    pub value: f64,
}

impl AreaConstraint {
    /// The constraint of `elements` at the source positions `positions`.
    pub fn new(elements: &Elements, positions: &[beltrami_mesh::Point3<f64>]) -> Self {
        let mut gradient = vec![0.0; 3 * positions.len()];
        for q in elements.points() {
            let nodes = elements.nodes(q.face);
            let (mut d1, mut d2) = (Vector3::zeros(), Vector3::zeros());
            for (k, v) in nodes.iter().enumerate() {
                d1 += positions[v.idx()].coords * q.grad[k].x;
                d2 += positions[v.idx()].coords * q.grad[k].y;
            }
            for (k, v) in nodes.iter().enumerate() {
                let c = (d1 * q.grad[k].x + d2 * q.grad[k].y) * q.weight;
                for axis in 0..3 {
                    gradient[3 * v.idx() + axis] += c[axis];
                }
            }
        }
        let value = positions
            .iter()
            .enumerate()
            .map(|(v, p)| {
                (0..3)
                    .map(|axis| gradient[3 * v + axis] * p[axis])
                    .sum::<f64>()
            })
            .sum();
        Self { gradient, value }
    }
}

/// Why a [`SpaceSystem`] could not be built or solved.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpaceError {
    /// An element quantity or the operator failed.
    #[error(transparent)]
    Fem(#[from] FemError),
    /// The held vertices could not be turned into a DOF map.
    #[error(transparent)]
    Dof(#[from] crate::DofError),
    /// The least-squares solve failed.
    #[error(transparent)]
    Solve(#[from] beltrami_sparse::SolveError),
}

/// The least-squares quasiconformal map into R^3 of a coefficient `mu` per face
/// (Algorithm 1): [`QuaternionicOperator`] on `elements`, held vertices, the optional
/// normal penalty ([`NormalConstraint`]) and area equality ([`AreaConstraint`]). The
/// symbolic factorization is built once; each [`solve`](Self::solve) refills the
/// operator's values for a new `mu` (the QC iteration solves one per iteration).
#[derive(Debug)]
pub struct SpaceSystem {
    elements: Elements,
    operator: QuaternionicOperator,
    normal: Option<NormalConstraint>,
    area: Option<AreaConstraint>,
    solver: crate::LeastSquaresSolver<f64>,
    weights: Vec<f64>,
    rhs: Vec<f64>,
}

impl SpaceSystem {
    /// The system of `elements` on `vertex_count` vertices, `held` vertices at their
    /// points, the other vertices free.
    pub fn new(
        elements: Elements,
        vertex_count: usize,
        held: &[(VertexId, Point3<f64>)],
        normal: Option<NormalConstraint>,
        area: Option<AreaConstraint>,
        options: beltrami_sparse::SolveOptions,
    ) -> Result<Self, SpaceError> {
        let operator = QuaternionicOperator::new(&elements, vertex_count, normal.as_ref())?;
        let mut builder = crate::DofBuilder::<f64>::new(vertex_count, 3)?;
        let mut is_held = vec![false; vertex_count];
        for &(v, p) in held {
            builder.origin(v, &[p.x, p.y, p.z])?;
            is_held[v.idx()] = true;
        }
        for v in (0..vertex_count).filter(|&v| !is_held[v]) {
            builder.free(&[VertexId(v as u32)])?;
        }
        let solver = crate::LeastSquaresSolver::new(
            operator.symbolic().as_ref(),
            &builder.build()?,
            options,
        )?;
        let mut weights = row_weights(&elements);
        let mut rhs = vec![0.0; weights.len()];
        if let Some(normal) = &normal {
            weights.extend(&normal.weights);
            rhs.extend(&normal.rhs);
        }
        Ok(Self {
            elements,
            operator,
            normal,
            area,
            solver,
            weights,
            rhs,
        })
    }

    /// The elements the system was built on.
    pub fn elements(&self) -> &Elements {
        &self.elements
    }

    /// The minimizer for `mu` (one value per face, in the elements' frames): the image of
    /// every vertex.
    pub fn solve(&mut self, mu: &[Complex64]) -> Result<Vec<Point3<f64>>, SpaceError> {
        let operator = self
            .operator
            .assemble(&self.elements, mu, self.normal.as_ref())?;
        let x = match &self.area {
            Some(area) => self.solver.solve_with_equality(
                operator.as_ref(),
                Some(&self.weights),
                &self.rhs,
                &area.gradient,
                area.value,
            )?,
            None => self
                .solver
                .solve(operator.as_ref(), Some(&self.weights), &self.rhs)?,
        };
        Ok(x.chunks_exact(3)
            .map(|c| Point3::new(c[0], c[1], c[2]))
            .collect())
    }

    /// [`quaternionic_residual`] of `image` on the system's elements.
    pub fn residual(
        &self,
        mu: &[Complex64],
        image: &[Point3<f64>],
    ) -> Result<Vec<f64>, SpaceError> {
        Ok(quaternionic_residual(&self.elements, image, mu)?)
    }
}

/// Why `held` held vertices with the given constraints leave a map into space
/// undetermined, or `None` when they fix it. `QC_mu` is zero for the zero map and for
/// every translate and dilate of a map (it is homogeneous and sees only derivatives):
/// three held vertices fix those; the normal penalty alone fixes them (it pins every
/// vertex to its tangent plane); the area equality fixes the scale, so that one held
/// vertex then fixes the rest (Gruber-Aulisa 2022, section 4.2).
pub fn undetermined(held: usize, normal: bool, area: bool, closed: bool) -> Option<String> {
    if held >= 3 || normal || (area && held >= 1) {
        return None;
    }
    Some(format!(
        "a map into space needs vertices held at points of R^3 (the boundary of a boundary map, `--boundary given --boundary-map MAP`, or pins), the normal constraint, or the area constraint with one held vertex: the distortion is zero for the zero map, and {held} held vertices{} do not fix the image{}",
        if area {
            " with the area constraint"
        } else {
            ""
        },
        if closed {
            "; this surface has no boundary, so pin a vertex (`--pin v0`) or add --normal-constraint"
        } else {
            ""
        }
    ))
}
