//! Local isometric frame of a face.
//!
//! The frame of face `f` with vertices `p0, p1, ..` has its origin at `p0`, the real
//! axis `e1` along the first edge `p1 - p0`, the normal `n` along the face's vector area
//! and the imaginary axis `e2 = n x e1`. A point `p` has local coordinates
//! `((p - p0) . e1, (p - p0) . e2)`, written `x + i y` when used as a complex number
//! (the convention of `docs/conventions.md`). For a triangle the map to local coordinates
//! is an isometry of the face onto the plane with the face counter-clockwise; for a
//! non-planar quad it is the orthogonal projection onto the plane through `p0` spanned by
//! `e1` and `e2` (with `n` made orthogonal to `e1`).

use nalgebra::{Point3, Vector2, Vector3};

use crate::{FaceId, Mesh};

/// An orthonormal frame attached to a face. See the module docs for the convention.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaceFrame {
    /// The face's first vertex.
    pub origin: Point3<f64>,
    /// Unit vector along the first edge (the local x axis).
    pub e1: Vector3<f64>,
    /// Unit vector `normal x e1` (the local y axis).
    pub e2: Vector3<f64>,
    /// Unit normal, orthogonal to `e1` and `e2`.
    pub normal: Vector3<f64>,
}

impl FaceFrame {
    /// Local coordinates of `p`.
    pub fn to_local(&self, p: &Point3<f64>) -> Vector2<f64> {
        let d = p - self.origin;
        Vector2::new(d.dot(&self.e1), d.dot(&self.e2))
    }

    /// The point of the face plane with local coordinates `q`.
    pub fn to_world(&self, q: &Vector2<f64>) -> Point3<f64> {
        self.origin + q.x * self.e1 + q.y * self.e2
    }

    /// Local coordinates of a tangent vector (its projection onto the frame's plane).
    pub fn vector_to_local(&self, v: &Vector3<f64>) -> Vector2<f64> {
        Vector2::new(v.dot(&self.e1), v.dot(&self.e2))
    }
}

impl Mesh {
    /// The local frame of `f`: origin at its first vertex, first edge along +x, normal
    /// along +z.
    pub fn face_frame(&self, f: FaceId) -> FaceFrame {
        let h = self.face_halfedge(f);
        let origin = self.position(self.origin(h));
        let e1 = self.halfedge_vector(h).normalize();
        let n = self.face_vector_area(f);
        let normal = (n - n.dot(&e1) * e1).normalize();
        FaceFrame {
            origin,
            e1,
            e2: normal.cross(&e1),
            normal,
        }
    }

    /// Local coordinates of the vertices of `f` in its frame, and their count. The first
    /// is `(0, 0)`, the second `(l, 0)` with `l` the first edge's length.
    pub fn face_local_coordinates(&self, f: FaceId) -> ([Vector2<f64>; 4], usize) {
        let frame = self.face_frame(f);
        let (v, n) = self.face_vertex_array(f);
        let mut out = [Vector2::zeros(); 4];
        for k in 0..n {
            out[k] = frame.to_local(&self.position(v[k]));
        }
        (out, n)
    }
}
