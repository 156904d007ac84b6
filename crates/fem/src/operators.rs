//! Assembled operators: stiffness (cotangent Laplacian), mass, and the complex
//! derivative operators `D_z`, `D_zbar`.
//!
//! Conventions: matrices act on vertex values indexed by [`beltrami_mesh::VertexId`].
//! The stiffness matrix is `K_ij = integral grad N_i . grad N_j` (positive semi-definite,
//! rows sum to zero); the consistent mass matrix is `M_ij = integral N_i N_j`. For a map
//! `f` given by complex vertex values, `(D_z f)_q = f_z` and `(D_zbar f)_q = f_zbar` at
//! quadrature point `q`, with `f_z = (f_x - i f_y) / 2`, `f_zbar = (f_x + i f_y) / 2` in
//! the point's tangent frame (P1: one point per triangle, Q1: four per quad).

use beltrami_mesh::Mesh;
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use nalgebra::Vector2;
use num_complex::Complex64;

use crate::assembly::Pattern;
use crate::{Elements, FemError, QuadraturePoint};

/// Positions `(row, col)` of all element-matrix entries, face by face, `i` major.
fn element_positions(elements: &Elements) -> Vec<(usize, usize)> {
    let mut positions = Vec::with_capacity(elements.face_count() * 16);
    for f in 0..elements.face_count() {
        let nodes = elements.nodes(beltrami_mesh::FaceId(f as u32));
        for &i in nodes {
            for &j in nodes {
                positions.push((i.idx(), j.idx()));
            }
        }
    }
    positions
}

/// Vertex-by-vertex element matrices assembled into one precomputed pattern: building
/// the pattern sorts once; each matrix afterwards costs one pass over the elements.
#[derive(Debug, Clone)]
pub struct ElementMatrices {
    pattern: Pattern,
}

impl ElementMatrices {
    /// The pattern of all element matrices of `elements` on a mesh with `vertex_count`
    /// vertices.
    pub fn new(vertex_count: usize, elements: &Elements) -> Result<Self, FemError> {
        let positions = element_positions(elements);
        Ok(Self {
            pattern: Pattern::new(vertex_count, vertex_count, &positions)?,
        })
    }

    /// The shared pattern (for symbolic factorizations).
    pub fn pattern(&self) -> &Pattern {
        &self.pattern
    }

    /// Stiffness `K_ij = sum_q w_q grad N_i(q) . grad N_j(q)`. For triangles this is the
    /// cotangent Laplacian: `K_ij = -(cot a_ij + cot b_ij) / 2` for an edge `ij` with
    /// opposite angles `a_ij`, `b_ij`.
    pub fn stiffness(&self, elements: &Elements) -> Result<SparseColMat<usize, f64>, FemError> {
        let mut values = Vec::with_capacity(self.pattern.entry_count());
        for f in 0..elements.face_count() {
            let f = beltrami_mesh::FaceId(f as u32);
            let n = elements.nodes(f).len();
            let points = elements.face_points(f);
            for i in 0..n {
                for j in 0..n {
                    values.push(
                        points
                            .iter()
                            .map(|q| q.weight * q.grad[i].dot(&q.grad[j]))
                            .sum(),
                    );
                }
            }
        }
        self.pattern.assemble(&values)
    }

    /// Consistent mass `M_ij = integral N_i N_j`: for a triangle of area `A` exactly
    /// `A (1 + delta_ij) / 12`; for a quad by the 2x2 Gauss rule (exact when planar).
    pub fn mass(&self, elements: &Elements) -> Result<SparseColMat<usize, f64>, FemError> {
        let mut values = Vec::with_capacity(self.pattern.entry_count());
        for f in 0..elements.face_count() {
            let f = beltrami_mesh::FaceId(f as u32);
            let n = elements.nodes(f).len();
            let points = elements.face_points(f);
            for i in 0..n {
                for j in 0..n {
                    values.push(if n == 3 {
                        let area = points[0].weight;
                        area * if i == j { 2.0 } else { 1.0 } / 12.0
                    } else {
                        points
                            .iter()
                            .map(|q| q.weight * q.shape[i] * q.shape[j])
                            .sum()
                    });
                }
            }
        }
        self.pattern.assemble(&values)
    }
}

/// The stiffness matrix (P1 and Q1), see [`ElementMatrices::stiffness`].
pub fn stiffness_matrix(
    mesh: &Mesh,
    elements: &Elements,
) -> Result<SparseColMat<usize, f64>, FemError> {
    ElementMatrices::new(mesh.vertex_count(), elements)?.stiffness(elements)
}

/// The consistent mass matrix, see [`ElementMatrices::mass`].
pub fn mass_matrix(mesh: &Mesh, elements: &Elements) -> Result<SparseColMat<usize, f64>, FemError> {
    ElementMatrices::new(mesh.vertex_count(), elements)?.mass(elements)
}

/// The lumped (row-sum) mass: one value per vertex, `m_i = sum_j M_ij = integral N_i`.
/// For triangles it is a third of the area of the incident faces.
pub fn lumped_mass(mesh: &Mesh, elements: &Elements) -> Vec<f64> {
    let mut m = vec![0.0; mesh.vertex_count()];
    for q in elements.points() {
        for (k, &v) in elements.nodes(q.face).iter().enumerate() {
            m[v.idx()] += q.weight * q.shape[k];
        }
    }
    m
}

/// The cotangent Laplacian of a triangle mesh from its angles,
/// `L_ij = -(cot a_ij + cot b_ij) / 2`, `L_ii = -sum_j L_ij`: the same matrix as the P1
/// stiffness, computed independently (used to check it). Quads are rejected.
pub fn cotan_laplacian(mesh: &Mesh) -> Result<SparseColMat<usize, f64>, FemError> {
    let mut positions = Vec::with_capacity(mesh.face_count() * 9);
    let mut values = Vec::with_capacity(mesh.face_count() * 9);
    for f in mesh.faces() {
        if mesh.face_degree(f) != 3 {
            return Err(FemError::Length {
                what: "cotan_laplacian face vertices (triangles only)",
                expected: 3,
                got: mesh.face_degree(f),
            });
        }
        for h in mesh.face_halfedges(f) {
            // The angle at the corner opposite edge h is at the origin of prev(h).
            let corner = mesh.prev(h);
            let a = mesh.halfedge_vector(corner);
            let b = -mesh.halfedge_vector(mesh.prev(corner));
            let cot = a.dot(&b) / a.cross(&b).norm();
            let (i, j) = (mesh.origin(h).idx(), mesh.target(h).idx());
            for (r, c, v) in [
                (i, j, -0.5 * cot),
                (j, i, -0.5 * cot),
                (i, i, 0.5 * cot),
                (j, j, 0.5 * cot),
            ] {
                positions.push((r, c));
                values.push(v);
            }
        }
    }
    Pattern::new(mesh.vertex_count(), mesh.vertex_count(), &positions)?.assemble(&values)
}

/// The complex derivative operators at the quadrature points of a mesh.
#[derive(Debug, Clone)]
pub struct ComplexDerivatives {
    /// `D_z`: quadrature points x vertices, `(D_z)_{q,k} = (d_x N_k - i d_y N_k) / 2`.
    pub dz: SparseColMat<usize, Complex64>,
    /// `D_zbar`: quadrature points x vertices, `(D_zbar)_{q,k} = (d_x N_k + i d_y N_k) / 2`.
    pub dzbar: SparseColMat<usize, Complex64>,
    /// Quadrature weights (area elements), one per row.
    pub weights: Vec<f64>,
}

/// `D_z` and `D_zbar` of `elements` (rows in the order of [`Elements::points`]).
pub fn complex_derivatives(
    mesh: &Mesh,
    elements: &Elements,
) -> Result<ComplexDerivatives, FemError> {
    let dz = point_vertex_matrix(mesh, elements, |q, k| d_z(q.grad[k]))?;
    let dzbar = point_vertex_matrix(mesh, elements, |q, k| d_zbar(q.grad[k]))?;
    Ok(ComplexDerivatives {
        dz,
        dzbar,
        weights: elements.points().iter().map(|q| q.weight).collect(),
    })
}

/// `(d_x N - i d_y N) / 2` of a shape function with gradient `g`.
fn d_z(g: Vector2<f64>) -> Complex64 {
    Complex64::new(0.5 * g.x, -0.5 * g.y)
}

/// `(d_x N + i d_y N) / 2` of a shape function with gradient `g`.
fn d_zbar(g: Vector2<f64>) -> Complex64 {
    Complex64::new(0.5 * g.x, 0.5 * g.y)
}

/// The `points x vertices` matrix with `value(q, k)` at the row of quadrature point `q`
/// and the column of node `k` of `q`'s face, for every point and node.
///
/// Built column by column in one counting pass: the points are visited in row order,
/// so every column receives its rows already increasing and nothing is sorted. (A
/// general triplet assembly keeps a position list, a copy of it and a permutation: three
/// times the memory of the matrix, which at a million faces costs more than the
/// arithmetic.) The nodes of a face are distinct vertices of a mesh, so no entry repeats.
fn point_vertex_matrix(
    mesh: &Mesh,
    elements: &Elements,
    value: impl Fn(&QuadraturePoint, usize) -> Complex64,
) -> Result<SparseColMat<usize, Complex64>, FemError> {
    let (rows, cols) = (elements.point_count(), mesh.vertex_count());
    let mut col_ptr = vec![0usize; cols + 1];
    for q in elements.points() {
        for v in elements.nodes(q.face) {
            col_ptr[v.idx() + 1] += 1;
        }
    }
    for c in 0..cols {
        col_ptr[c + 1] += col_ptr[c];
    }
    let nnz = col_ptr[cols];
    let mut next = col_ptr[..cols].to_vec();
    let mut row_idx = vec![0usize; nnz];
    let mut values = vec![Complex64::new(0.0, 0.0); nnz];
    for (row, q) in elements.points().iter().enumerate() {
        for (k, v) in elements.nodes(q.face).iter().enumerate() {
            let slot = &mut next[v.idx()];
            row_idx[*slot] = row;
            values[*slot] = value(q, k);
            *slot += 1;
        }
    }
    let symbolic = SymbolicSparseColMat::new_checked(rows, cols, col_ptr, None, row_idx);
    Ok(SparseColMat::new(symbolic, values))
}

/// The real `2m x 2n` form of a complex `m x n` matrix: entry `a + i b` at `(r, c)`
/// becomes the block `[a -b; b a]` at rows `2r, 2r+1` and columns `2c, 2c+1`, so that
/// real vectors interleave `[re_0, im_0, re_1, im_1, ..]`.
pub fn real_block_form(
    m: &SparseColMat<usize, Complex64>,
) -> Result<SparseColMat<usize, f64>, FemError> {
    let mut positions = Vec::with_capacity(4 * m.compute_nnz());
    let mut values = Vec::with_capacity(4 * m.compute_nnz());
    for c in 0..m.ncols() {
        let rows = m.row_idx_of_col_raw(c);
        let vals = m.val_of_col(c);
        for (&r, z) in rows.iter().zip(vals) {
            for (dr, dc, v) in [(0, 0, z.re), (0, 1, -z.im), (1, 0, z.im), (1, 1, z.re)] {
                positions.push((2 * r + dr, 2 * c + dc));
                values.push(v);
            }
        }
    }
    Pattern::new(2 * m.nrows(), 2 * m.ncols(), &positions)?.assemble(&values)
}

/// Multiplies a complex sparse matrix by a vector of vertex values.
pub fn apply(m: &SparseColMat<usize, Complex64>, x: &[Complex64]) -> Vec<Complex64> {
    let mut y = vec![Complex64::new(0.0, 0.0); m.nrows()];
    for (c, &xc) in x.iter().enumerate().take(m.ncols()) {
        for (&r, &v) in m.row_idx_of_col_raw(c).iter().zip(m.val_of_col(c)) {
            y[r] += v * xc;
        }
    }
    y
}

/// The weighted squared residual `sum_q w_q |(A x)_q|^2 = |W^(1/2) A x|^2` of an
/// operator with a row per quadrature point (`weights[q]` the point's weight): the
/// least-squares energy of LSCM (`A = D_zbar`) and of a QC map (`A = D_zbar - mu D_z`).
pub fn weighted_residual(
    m: &SparseColMat<usize, Complex64>,
    x: &[Complex64],
    weights: &[f64],
) -> f64 {
    apply(m, x)
        .iter()
        .zip(weights)
        .map(|(r, w)| w * r.norm_sqr())
        .sum()
}

/// The operator `A = D_zbar - diag(mu_q) D_z` (quadrature points x vertices) of the
/// elements, `mu_q = mu[f]` at every quadrature point of face `f`: `(A x)_q` is
/// `f_zbar(q) - mu_f f_z(q)` of the map with vertex values `x`, in the elements' frame.
pub fn beltrami_operator(
    mesh: &Mesh,
    elements: &Elements,
    mu: &[Complex64],
) -> Result<SparseColMat<usize, Complex64>, FemError> {
    crate::beltrami::check_len("Beltrami coefficient", elements.face_count(), mu.len())?;
    point_vertex_matrix(mesh, elements, |q, k| {
        d_zbar(q.grad[k]) - mu[q.face.idx()] * d_z(q.grad[k])
    })
}
