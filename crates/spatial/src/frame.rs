//! Tangent frames at surface points, from interpolated vertex normals.
//!
//! The normal at a surface point is the interpolation of the angle-weighted vertex
//! normals with the point's own coordinates, `n = normalize(sum_i coords[i] N_i)`
//! (barycentric on a triangle, bilinear on a quad), so it varies continuously over the
//! surface and equals the vertex normal at a vertex. Where the sum vanishes (opposite
//! vertex normals across a knife edge) the face normal is used instead.
//!
//! The tangent basis follows the face frame convention of `docs/conventions.md` with
//! `n` in place of the face normal: `e1` is the face's first edge projected onto the
//! tangent plane and normalized, and `e2 = n x e1`, so `(e1, e2, n)` is a positively
//! oriented orthonormal basis and a tangent vector `a e1 + b e2` has local coordinates
//! `a + i b`. If the first edge is within about 6 degrees of `n` (at a sharp feature,
//! where the vertex normals turn far from the face normal), the face edge most
//! orthogonal to `n` is projected instead. On a flat face with
//! vertex normals equal to the face normal the frame is the face frame.

use beltrami_mesh::{Mesh, SurfacePoint};
use nalgebra::{Point3, Vector2, Vector3};

use crate::error::SpatialError;
use crate::index::SurfaceIndex;

/// An orthonormal tangent frame at a point of a surface: see the module docs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TangentFrame {
    /// The surface point's position.
    pub origin: Point3<f64>,
    /// First unit tangent (local x axis).
    pub e1: Vector3<f64>,
    /// Second unit tangent, `normal x e1` (local y axis).
    pub e2: Vector3<f64>,
    /// Unit normal: the interpolated vertex normal.
    pub normal: Vector3<f64>,
}

impl TangentFrame {
    /// The frame at `point` of `mesh`, with `vertex_normals` the unit vertex normals by
    /// vertex id (such as [`Mesh::vertex_normals`]). `point` must belong to `mesh`.
    pub fn at(mesh: &Mesh, vertex_normals: &[Vector3<f64>], point: &SurfacePoint) -> Self {
        let normal = interpolated_normal(mesh, vertex_normals, point);
        let (v, n) = mesh.face_vertex_array(point.face);
        // The tangential part of face edge k and the sine of its angle with the normal.
        let tangential = |k: usize| {
            let e = mesh.position(v[(k + 1) % n]) - mesh.position(v[k]);
            let t = e - e.dot(&normal) * normal;
            let length = e.norm();
            (t, if length > 0.0 { t.norm() / length } else { 0.0 })
        };
        // The first edge unless it is within about 6 degrees of the normal (a sine below
        // 0.1); then the edge most orthogonal to the normal.
        let mut best = tangential(0);
        if best.1 < 0.1 {
            for k in 1..n {
                let candidate = tangential(k);
                if candidate.1 > best.1 {
                    best = candidate;
                }
            }
        }
        let e1 = if best.1 > 0.0 {
            best.0.normalize()
        } else {
            any_orthogonal(&normal)
        };
        Self {
            origin: point.position(mesh),
            e1,
            e2: normal.cross(&e1),
            normal,
        }
    }

    /// Local coordinates `(v . e1, v . e2)` of a vector (its normal part is dropped).
    pub fn to_local(&self, v: &Vector3<f64>) -> Vector2<f64> {
        Vector2::new(v.dot(&self.e1), v.dot(&self.e2))
    }

    /// The tangent vector `a e1 + b e2` with local coordinates `(a, b)`.
    pub fn to_world(&self, local: &Vector2<f64>) -> Vector3<f64> {
        local.x * self.e1 + local.y * self.e2
    }

    /// The tangential part `v - (v . n) n` of a vector.
    pub fn tangential(&self, v: &Vector3<f64>) -> Vector3<f64> {
        v - v.dot(&self.normal) * self.normal
    }
}

/// The unit normal at `point`: `normalize(sum_i coords[i] N_i)` over the face's vertex
/// normals, or the face normal where that sum vanishes.
pub fn interpolated_normal(
    mesh: &Mesh,
    vertex_normals: &[Vector3<f64>],
    point: &SurfacePoint,
) -> Vector3<f64> {
    let (v, n) = mesh.face_vertex_array(point.face);
    let sum: Vector3<f64> = (0..n)
        .map(|k| point.coords[k] * vertex_normals[v[k].idx()])
        .sum();
    let norm = sum.norm();
    if norm > 1e-8 && norm.is_finite() {
        sum / norm
    } else {
        mesh.face_normal(point.face)
    }
}

/// A unit vector orthogonal to the unit vector `n`.
pub(crate) fn any_orthogonal(n: &Vector3<f64>) -> Vector3<f64> {
    // Cross with the coordinate axis least aligned with n.
    let axis = if n.x.abs() <= n.y.abs() && n.x.abs() <= n.z.abs() {
        Vector3::x()
    } else if n.y.abs() <= n.z.abs() {
        Vector3::y()
    } else {
        Vector3::z()
    };
    n.cross(&axis).normalize()
}

impl SurfaceIndex<'_> {
    /// The tangent frame at `point` (see the module docs). Fails if `point` does not
    /// belong to the indexed mesh.
    pub fn frame(&self, point: &SurfacePoint) -> Result<TangentFrame, SpatialError> {
        point.validate(self.mesh())?;
        Ok(TangentFrame::at(self.mesh(), self.vertex_normals(), point))
    }

    /// Per face of `source`, the normal a map of `source` onto the indexed (target) mesh
    /// is judged against: with `images[v]` the image of source vertex `v` located on the
    /// target, the sum over the face's corners of the target's interpolated normal at the
    /// corner's image,
    ///
    /// ```text
    /// N_f = sum_{v in f} n(images[v])        (n: [`interpolated_normal`], unit)
    /// ```
    ///
    /// (not normalized). This is the reference of
    /// `beltrami_fem::ReferenceNormal::PerFace` for registrations and for maps measured
    /// against a target: a face is flipped where its image's area element points against
    /// `N_f` (for a quad, at any of its quadrature points).
    ///
    /// Fails with [`SpatialError::LengthMismatch`] unless there is one image per source
    /// vertex, and with [`SpatialError::InBatch`] naming the first image that is not a
    /// point of the indexed mesh.
    pub fn face_reference_normals(
        &self,
        source: &Mesh,
        images: &[SurfacePoint],
    ) -> Result<Vec<Vector3<f64>>, SpatialError> {
        if images.len() != source.vertex_count() {
            return Err(SpatialError::LengthMismatch {
                what: "images of the source vertices",
                expected: source.vertex_count(),
                found: images.len(),
            });
        }
        let at_vertex = images
            .iter()
            .enumerate()
            .map(|(i, p)| self.normal(p).map_err(|e| e.in_batch(i)))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(source
            .faces()
            .map(|f| source.face_vertices(f).map(|v| at_vertex[v.idx()]).sum())
            .collect())
    }

    /// The interpolated unit normal at `point` (see the module docs). Fails if `point`
    /// does not belong to the indexed mesh.
    pub fn normal(&self, point: &SurfacePoint) -> Result<Vector3<f64>, SpatialError> {
        point.validate(self.mesh())?;
        Ok(interpolated_normal(
            self.mesh(),
            self.vertex_normals(),
            point,
        ))
    }
}
