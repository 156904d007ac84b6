//! Errors of the finite-element layer.

use beltrami_mesh::{FaceId, VertexId};
use thiserror::Error;

/// Why an element quantity could not be computed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum FemError {
    /// The global frame was asked for but the mesh does not lie in the plane z = 0.
    #[error("the global frame needs a mesh in the plane z = 0, but vertex {vertex} has z = {z:e}")]
    NotPlanar {
        /// The first vertex off the plane (mesh index).
        vertex: VertexId,
        /// Its z coordinate.
        z: f64,
    },
    /// An element whose Jacobian vanishes at a quadrature point.
    #[error("face {face} is degenerate in the chosen frame (Jacobian determinant {det:e})")]
    DegenerateElement {
        /// The face.
        face: FaceId,
        /// The Jacobian determinant found.
        det: f64,
    },
    /// A per-vertex or per-face array of the wrong length.
    #[error("{what} has {got} values but {expected} were expected")]
    Length {
        /// Which input.
        what: &'static str,
        /// The length required.
        expected: usize,
        /// The length given.
        got: usize,
    },
    /// A non-finite value in a map or field.
    #[error("{what} is not finite at index {index}")]
    NonFinite {
        /// Which input.
        what: &'static str,
        /// Index of the value.
        index: usize,
    },
    /// Reference corner angles that do not make a polygon: their sum is not `pi` (a
    /// triangle) or `2 pi` (a quad), or a quad with them has a side of length `<= 0`.
    #[error(
        "the reference angles of face {face} make no {what} (angle sum {sum:.6} rad); give angles in (0, pi) summing to pi for a triangle, 2 pi for a quad"
    )]
    ReferenceAngles {
        /// The face.
        face: FaceId,
        /// `triangle` or `convex quad`.
        what: &'static str,
        /// The sum of its angles.
        sum: f64,
    },
    /// Building a sparse matrix failed (index overflow or allocation).
    #[error("sparse matrix assembly failed: {0}")]
    Assembly(String),
}
