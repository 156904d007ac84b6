//! Points on the surface of a mesh: a face and coordinates with respect to its vertices.
//!
//! # Coordinate conventions
//!
//! A [`SurfacePoint`] stores one weight per face vertex, in the face's vertex order
//! ([`Mesh::face_vertices`]), and its position is the weighted sum of the vertex
//! positions, `X = sum_i coords[i] p_i`, for both kinds of face:
//!
//! - **Triangle** `(p0, p1, p2)`: barycentric coordinates `(l0, l1, l2)`, each in
//!   `[0, 1]`, summing to 1; `coords[3]` is 0.
//! - **Quad** `(p0, p1, p2, p3)`: the bilinear weights of the patch parameter
//!   `(u, v)` in `[0, 1]^2`, `((1-u)(1-v), u(1-v), u v, (1-u) v)`, so the position is the
//!   patch point `X(u, v) = (1-u)(1-v) p0 + u(1-v) p1 + u v p2 + (1-u) v p3`, the surface
//!   the mesh's area and the Q1 element use. The weights sum to 1 and satisfy
//!   `w0 w2 = w1 w3`; `u = w1 + w2` and `v = w2 + w3` recover the parameter.
//!
//! A point on an edge or at a vertex belongs to every face around it; any of them may
//! be used (the coordinates of the other vertices are 0).

use nalgebra::Point3;
use thiserror::Error;

use crate::{FaceId, Mesh, VertexId};

/// How far coordinates may stray outside their range, or their sum from 1, and still pass
/// [`SurfacePoint::validate`]: rounding of a few operations, not a modelling tolerance.
pub const COORDINATE_TOLERANCE: f64 = 1e-9;

/// A point on a mesh: a face and the coordinates of the point with respect to the face's
/// vertices (barycentric for a triangle, bilinear weights for a quad). See the
/// [module docs](self) for the conventions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    /// The face containing the point.
    pub face: FaceId,
    /// Weights of the face's vertices, in face order; the fourth is 0 for a triangle.
    pub coords: [f64; 4],
}

/// Why a [`SurfacePoint`] is not a point of a given mesh.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SurfacePointError {
    /// The face index is not a face of the mesh.
    #[error("surface point on face {face}, but the mesh has only {face_count} faces")]
    FaceOutOfRange {
        /// The face of the point.
        face: FaceId,
        /// Number of faces of the mesh.
        face_count: usize,
    },
    /// A coordinate is NaN or infinite.
    #[error("surface point on face {face} has a non-finite coordinate {coords:?}")]
    NonFinite {
        /// The face of the point.
        face: FaceId,
        /// Its coordinates.
        coords: [f64; 4],
    },
    /// Coordinates that are not barycentric (triangle) or bilinear weights (quad) of a
    /// point inside the face.
    #[error(
        "surface point on face {face} ({degree} vertices) has invalid coordinates {coords:?}: {reason}"
    )]
    InvalidCoordinates {
        /// The face of the point.
        face: FaceId,
        /// Number of vertices of the face.
        degree: usize,
        /// Its coordinates.
        coords: [f64; 4],
        /// What is wrong with them.
        reason: &'static str,
    },
}

impl SurfacePoint {
    /// A point of a triangle from its barycentric coordinates `(l0, l1, l2)`, in face
    /// order.
    pub fn in_triangle(face: FaceId, barycentric: [f64; 3]) -> Self {
        let [a, b, c] = barycentric;
        Self {
            face,
            coords: [a, b, c, 0.0],
        }
    }

    /// A point of a quad from its patch parameter `(u, v)`: weights
    /// `((1-u)(1-v), u(1-v), u v, (1-u) v)`.
    pub fn in_quad(face: FaceId, u: f64, v: f64) -> Self {
        Self {
            face,
            coords: bilinear_weights(u, v),
        }
    }

    /// Vertex `v` as a surface point: on the first face of its fan (counter-clockwise
    /// from [`Mesh::vertex_halfedge`]), with weight 1 on `v`. Panics if `v` is not a
    /// vertex of `mesh`.
    pub fn at_vertex(mesh: &Mesh, v: VertexId) -> Self {
        let start = mesh.vertex_halfedge(v);
        // On the boundary the stored halfedge is the boundary one; the next one
        // counter-clockwise leaves `v` along the first face of the fan.
        let h = if mesh.is_boundary_halfedge(start) {
            mesh.twin(mesh.prev(start))
        } else {
            start
        };
        let face = mesh
            .face(h)
            .expect("the first outgoing halfedge of a vertex fan has a face");
        let slot = (h.0 - mesh.face_halfedge(face).0) as usize;
        let mut coords = [0.0; 4];
        coords[slot] = 1.0;
        Self { face, coords }
    }

    /// The patch parameter `(u, v) = (w1 + w2, w2 + w3)` of a point of a quad (for a
    /// triangle the same formula gives `(l1 + l2, l2)`).
    pub fn quad_parameter(&self) -> (f64, f64) {
        let [_, w1, w2, w3] = self.coords;
        (w1 + w2, w2 + w3)
    }

    /// The position `sum_i coords[i] p_i` (the bilinear patch point for a quad).
    ///
    /// The point must belong to `mesh` ([`SurfacePoint::validate`]); a face out of range
    /// panics.
    pub fn position(&self, mesh: &Mesh) -> Point3<f64> {
        let (vertices, n) = mesh.face_vertex_array(self.face);
        let mut sum = nalgebra::Vector3::zeros();
        for (c, &v) in self.coords.iter().zip(&vertices[..n]) {
            sum += *c * mesh.position(v).coords;
        }
        Point3::from(sum)
    }

    /// Checks that the point belongs to `mesh`: the face exists, the coordinates are
    /// finite, and they are barycentric coordinates (triangle: each in `[0, 1]`, summing
    /// to 1, the fourth 0) or bilinear weights (quad: `u, v` in `[0, 1]` and the weights
    /// equal to those of `(u, v)`), all up to [`COORDINATE_TOLERANCE`].
    pub fn validate(&self, mesh: &Mesh) -> Result<(), SurfacePointError> {
        let face = self.face;
        if face.idx() >= mesh.face_count() {
            return Err(SurfacePointError::FaceOutOfRange {
                face,
                face_count: mesh.face_count(),
            });
        }
        let coords = self.coords;
        if coords.iter().any(|c| !c.is_finite()) {
            return Err(SurfacePointError::NonFinite { face, coords });
        }
        let degree = mesh.face_degree(face);
        let invalid = |reason| SurfacePointError::InvalidCoordinates {
            face,
            degree,
            coords,
            reason,
        };
        let in_unit = |x: f64| (-COORDINATE_TOLERANCE..=1.0 + COORDINATE_TOLERANCE).contains(&x);
        if degree == 3 {
            if coords[3] != 0.0 {
                return Err(invalid(
                    "the fourth coordinate of a triangle point must be 0",
                ));
            }
            if !coords[..3].iter().all(|&c| in_unit(c)) {
                return Err(invalid("barycentric coordinates must lie in [0, 1]"));
            }
            if (coords[0] + coords[1] + coords[2] - 1.0).abs() > COORDINATE_TOLERANCE {
                return Err(invalid("barycentric coordinates must sum to 1"));
            }
        } else {
            let (u, v) = self.quad_parameter();
            if !(in_unit(u) && in_unit(v)) {
                return Err(invalid("the quad parameter (u, v) must lie in [0, 1]^2"));
            }
            let expected = bilinear_weights(u, v);
            if coords
                .iter()
                .zip(&expected)
                .any(|(c, e)| (c - e).abs() > COORDINATE_TOLERANCE)
            {
                return Err(invalid(
                    "quad weights must be ((1-u)(1-v), u(1-v), uv, (1-u)v) for one (u, v)",
                ));
            }
        }
        Ok(())
    }
}

/// The bilinear weights `((1-u)(1-v), u(1-v), u v, (1-u) v)` of the quad parameter
/// `(u, v)`.
pub fn bilinear_weights(u: f64, v: f64) -> [f64; 4] {
    [(1.0 - u) * (1.0 - v), u * (1.0 - v), u * v, (1.0 - u) * v]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::PolygonSoup;
    use crate::primitives::{Cells, grid};

    fn mixed() -> Mesh {
        // A quad (0, 1, 4, 3) beside two triangles on [0, 2] x [0, 1], the quad bent up.
        let positions = vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(2.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.5),
            Point3::new(1.0, 1.0, 0.0),
            Point3::new(2.0, 1.0, 0.0),
        ];
        let mut soup = PolygonSoup::new(positions);
        soup.push_face(&[0, 1, 4, 3]);
        soup.push_face(&[1, 2, 5]);
        soup.push_face(&[1, 5, 4]);
        Mesh::from_soup(&soup).unwrap()
    }

    #[test]
    fn triangle_position_is_the_barycentric_combination() {
        let mesh = mixed();
        let p = SurfacePoint::in_triangle(FaceId(1), [0.2, 0.3, 0.5]);
        p.validate(&mesh).unwrap();
        let x = p.position(&mesh);
        assert!((x - Point3::new(0.2 + 0.6 + 1.0, 0.5, 0.0)).norm() < 1e-15);
    }

    #[test]
    fn quad_position_is_the_bilinear_patch() {
        let mesh = mixed();
        let (u, v) = (0.3, 0.8);
        let p = SurfacePoint::in_quad(FaceId(0), u, v);
        p.validate(&mesh).unwrap();
        let (pu, pv) = p.quad_parameter();
        assert!((pu - u).abs() < 1e-15 && (pv - v).abs() < 1e-15);
        // X(u, v) with p3 lifted: z = (1-u) v 0.5.
        let x = p.position(&mesh);
        let expected = Point3::new(u, v, (1.0 - u) * v * 0.5);
        assert!((x - expected).norm() < 1e-15);
    }

    #[test]
    fn at_vertex_has_the_vertex_position() {
        let mesh = Mesh::from_soup(&grid(3, 2, Cells::Triangles)).unwrap();
        for v in mesh.vertices() {
            let p = SurfacePoint::at_vertex(&mesh, v);
            p.validate(&mesh).unwrap();
            assert_eq!(p.position(&mesh), mesh.position(v));
            assert!(mesh.face_vertices(p.face).any(|w| w == v));
        }
        let mesh = mixed();
        for v in mesh.vertices() {
            let p = SurfacePoint::at_vertex(&mesh, v);
            p.validate(&mesh).unwrap();
            assert_eq!(p.position(&mesh), mesh.position(v));
        }
    }

    #[test]
    fn validation_names_the_problem() {
        let mesh = mixed();
        let err = SurfacePoint::in_triangle(FaceId(7), [1.0, 0.0, 0.0])
            .validate(&mesh)
            .unwrap_err();
        assert!(matches!(
            err,
            SurfacePointError::FaceOutOfRange { face_count: 3, .. }
        ));
        assert!(err.to_string().contains("f7"));
        let err = SurfacePoint::in_triangle(FaceId(1), [f64::NAN, 0.0, 1.0])
            .validate(&mesh)
            .unwrap_err();
        assert!(matches!(err, SurfacePointError::NonFinite { .. }));
        let err = SurfacePoint::in_triangle(FaceId(1), [0.5, 0.6, 0.0])
            .validate(&mesh)
            .unwrap_err();
        assert!(err.to_string().contains("sum to 1"), "{err}");
        let err = SurfacePoint::in_triangle(FaceId(1), [-0.5, 1.5, 0.0])
            .validate(&mesh)
            .unwrap_err();
        assert!(err.to_string().contains("[0, 1]"), "{err}");
        let err = SurfacePoint {
            face: FaceId(1),
            coords: [0.5, 0.25, 0.25, 0.1],
        }
        .validate(&mesh)
        .unwrap_err();
        assert!(err.to_string().contains("fourth"), "{err}");
        // Weights summing to 1 that are not bilinear.
        let err = SurfacePoint {
            face: FaceId(0),
            coords: [0.5, 0.0, 0.5, 0.0],
        }
        .validate(&mesh)
        .unwrap_err();
        assert!(err.to_string().contains("(1-u)(1-v)"), "{err}");
        let err = SurfacePoint::in_quad(FaceId(0), 1.5, 0.5)
            .validate(&mesh)
            .unwrap_err();
        assert!(err.to_string().contains("[0, 1]^2"), "{err}");
    }
}
