//! Edge weights of the linear maps: for each vertex `i`, weights `w_ij` of its
//! neighbours `j`, which define the weighted-mean condition
//! `sum_j w_ij (x_i - x_j) = 0` of the Tutte and harmonic maps.
//!
//! - **Uniform** (Tutte 1963): `w_ij = 1` for every edge `ij`. Symmetric and positive.
//! - **Mean value** (Floater 2003, "Mean value coordinates", CAGD 20):
//!   `w_ij = (tan(a/2) + tan(b/2)) / |p_i - p_j|`, where `a` and `b` are the angles at
//!   `v_i` between the edge `ij` and the edges of the one-ring next to it, i.e. the
//!   corner angles at `v_i` of the two faces on either side of the edge (triangles or
//!   quads). Positive whenever every corner angle is below `pi` (always on triangles);
//!   not symmetric.
//! - **Cotangent** (Pinkall-Polthier 1993, "Computing discrete minimal surfaces and their
//!   conjugates", Exp. Math. 2): `w_ij = -K_ij` from the finite-element stiffness matrix
//!   `K_ij = integral grad N_i . grad N_j` ([`ElementMatrices::stiffness`]); on triangles
//!   `w_ij = (cot a_ij + cot b_ij) / 2` with `a_ij`, `b_ij` the angles opposite the edge,
//!   on quads the Q1 stiffness, which also couples the diagonally opposite corners of a
//!   quad. Symmetric; negative where the opposite angles add up to more than `pi`
//!   (obtuse triangles), so a harmonic map may flip faces.
//!
//! With symmetric weights the weighted-mean condition is the stationarity condition of
//! the energy `E(x) = (1/2) sum_{edges ij} w_ij |x_i - x_j|^2` (its gradient in `x_i` is
//! `sum_j w_ij (x_i - x_j)`); with cotangent weights `E` is the Dirichlet energy
//! `(1/2) integral |grad f|^2` of the P1/Q1 map, so the solution is the discrete harmonic
//! map. Cotangent and mean-value weights reproduce linear functions on planar meshes
//! exactly (linear precision); uniform weights do not.
//!
//! Each kind has its constructor ([`EdgeWeights::uniform`], [`EdgeWeights::mean_value`],
//! [`EdgeWeights::cotangent`]); a solver picks the one its parameters ask for.

use crate::operators::ElementMatrices;
use crate::{Elements, FemError, Frame};
use beltrami_mesh::{Mesh, VertexId};
use thiserror::Error;

/// Why weights could not be computed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum WeightError {
    /// A weight that is NaN or infinite (an edge of zero length, a degenerate corner).
    #[error("the {kind} weight of vertex {vertex} towards vertex {neighbor} is not finite")]
    NonFinite {
        /// Which weights ("mean-value", ...).
        kind: &'static str,
        /// The vertex whose row holds the weight.
        vertex: VertexId,
        /// The neighbour.
        neighbor: VertexId,
    },
    /// The stiffness matrix could not be computed (a degenerate face).
    #[error(transparent)]
    Fem(#[from] FemError),
}

/// Weights `w_ij` of every vertex `i` towards its neighbours `j`, stored row by row.
#[derive(Debug, Clone, PartialEq)]
pub struct EdgeWeights {
    /// `w_ij = w_ji` by construction.
    symmetric: bool,
    /// Row `i` is `offsets[i]..offsets[i + 1]` of `neighbors` and `values`.
    offsets: Vec<usize>,
    neighbors: Vec<VertexId>,
    values: Vec<f64>,
}

impl EdgeWeights {
    /// `w_ij = 1` for every edge `ij` (Tutte's barycentric weights).
    pub fn uniform(mesh: &Mesh) -> Self {
        let mut offsets = Vec::with_capacity(mesh.vertex_count() + 1);
        let mut neighbors = Vec::with_capacity(2 * mesh.edge_count());
        offsets.push(0);
        for v in mesh.vertices() {
            neighbors.extend(mesh.vertex_neighbors(v));
            offsets.push(neighbors.len());
        }
        Self {
            symmetric: true,
            offsets,
            values: vec![1.0; neighbors.len()],
            neighbors,
        }
    }

    /// Floater's mean-value weights `w_ij = (tan(a/2) + tan(b/2)) / |p_i - p_j|` with
    /// `a`, `b` the corner angles at `v_i` of the faces left and right of the edge `ij`
    /// (module docs). On a boundary vertex the missing face contributes nothing.
    ///
    /// Fails with [`WeightError::NonFinite`] at an edge of zero length.
    pub fn mean_value(mesh: &Mesh) -> Result<Self, WeightError> {
        Self::from_rows(mesh, false, |v, row| {
            for h in mesh.outgoing_halfedges(v) {
                let j = mesh.target(h);
                // corner_angle(h) is the angle at v between h and the other edge of the
                // face on h's left; next(twin(h)) leaves v in the face on h's right, and
                // its corner angle is the angle between that face's other edge and h.
                let left = mesh
                    .face(h)
                    .map_or(0.0, |_| (mesh.corner_angle(h) / 2.0).tan());
                let twin = mesh.twin(h);
                let right = mesh
                    .face(twin)
                    .map_or(0.0, |_| (mesh.corner_angle(mesh.next(twin)) / 2.0).tan());
                let w = (left + right) / mesh.halfedge_vector(h).norm();
                if !w.is_finite() {
                    return Err(WeightError::NonFinite {
                        kind: "mean-value",
                        vertex: v,
                        neighbor: j,
                    });
                }
                row.push((j, w));
            }
            Ok(())
        })
    }

    /// Cotangent weights `w_ij = -K_ij` from the P1/Q1 stiffness matrix in the face
    /// frames (module docs). Fails like [`Elements::new`] on a degenerate face.
    pub fn cotangent(mesh: &Mesh) -> Result<Self, WeightError> {
        let elements = Elements::new(mesh, Frame::Face)?;
        let stiffness =
            ElementMatrices::new(mesh.vertex_count(), &elements)?.stiffness(&elements)?;
        Self::from_rows(mesh, true, |v, row| {
            // K is symmetric, so column i holds row i.
            let i = v.idx();
            let rows = stiffness.row_idx_of_col_raw(i);
            let values = stiffness.val_of_col(i);
            for (&j, &k) in rows.iter().zip(values) {
                if j == i {
                    continue;
                }
                let neighbor = VertexId::from_usize(j);
                if !k.is_finite() {
                    return Err(WeightError::NonFinite {
                        kind: "cotangent",
                        vertex: v,
                        neighbor,
                    });
                }
                row.push((neighbor, -k));
            }
            Ok(())
        })
    }

    /// Builds the rows vertex by vertex; `fill(v, row)` appends `(j, w_vj)` to `row`.
    /// `symmetric` says whether the kind is symmetric by construction.
    fn from_rows(
        mesh: &Mesh,
        symmetric: bool,
        mut fill: impl FnMut(VertexId, &mut Vec<(VertexId, f64)>) -> Result<(), WeightError>,
    ) -> Result<Self, WeightError> {
        let mut offsets = Vec::with_capacity(mesh.vertex_count() + 1);
        let mut row = Vec::new();
        let mut neighbors = Vec::with_capacity(2 * mesh.edge_count());
        let mut values = Vec::with_capacity(2 * mesh.edge_count());
        offsets.push(0);
        for v in mesh.vertices() {
            row.clear();
            fill(v, &mut row)?;
            for &(j, w) in &row {
                neighbors.push(j);
                values.push(w);
            }
            offsets.push(neighbors.len());
        }
        Ok(Self {
            symmetric,
            offsets,
            neighbors,
            values,
        })
    }

    /// True if `w_ij = w_ji` by construction (uniform and cotangent weights), so the
    /// weighted-mean system is symmetric.
    pub fn is_symmetric(&self) -> bool {
        self.symmetric
    }

    /// Number of vertices (rows).
    pub fn vertex_count(&self) -> usize {
        self.offsets.len() - 1
    }

    /// The neighbours `j` of `v` with their weights `w_vj`.
    pub fn row(&self, v: VertexId) -> impl ExactSizeIterator<Item = (VertexId, f64)> + '_ {
        let range = self.offsets[v.idx()]..self.offsets[v.idx() + 1];
        self.neighbors[range.clone()]
            .iter()
            .copied()
            .zip(self.values[range].iter().copied())
    }

    /// Number of negative weights `w_ij < 0` among the rows of `vertices`.
    pub fn negative_count(&self, vertices: impl IntoIterator<Item = VertexId>) -> usize {
        vertices
            .into_iter()
            .map(|v| self.row(v).filter(|&(_, w)| w < 0.0).count())
            .sum()
    }
}
