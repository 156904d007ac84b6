//! Where a surface point touches the boundary of its mesh, and which way is out.
//!
//! A point of a face lies on the boundary when its barycentric coordinates put it on a
//! boundary edge or at a boundary vertex, within `VERTEX_TOLERANCE` (the walk of
//! [`crate::motion`] ends exactly there when it slides along the boundary). The outward
//! direction of a boundary edge is `e x n`, `e` the unit edge of the face's halfedge
//! along it (the face lies to its left, counter-clockwise about the face normal `n`):
//! it lies in the face's plane, perpendicular to the edge, away from the face. At a
//! boundary vertex it is the normalized sum of its two boundary edges' outward
//! directions, the bisector of the cone of moves that leave the surface there.

use beltrami_mesh::{HalfedgeId, Mesh, SurfacePoint, VertexId};
use nalgebra::Vector3;

use crate::motion::VERTEX_TOLERANCE;

/// Where a surface point lies on the boundary.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OnBoundary {
    /// At a boundary vertex.
    Vertex(VertexId),
    /// On the boundary edge of face halfedge `h` (its twin is a boundary halfedge), at
    /// fraction `t` from its origin.
    Edge(HalfedgeId, f64),
}

/// Whether `p` is on the boundary of `mesh` (coordinates within `VERTEX_TOLERANCE` of
/// a boundary vertex or edge), and where.
pub fn on_boundary(mesh: &Mesh, p: &SurfacePoint) -> Option<OnBoundary> {
    let (v, n) = mesh.face_vertex_array(p.face);
    if let Some(k) = (0..n).find(|&k| p.coords[k] >= 1.0 - VERTEX_TOLERANCE) {
        return mesh
            .is_boundary_vertex(v[k])
            .then_some(OnBoundary::Vertex(v[k]));
    }
    (0..n).find_map(|j| {
        let next = (j + 1) % n;
        let on_edge = (0..n)
            .filter(|&k| k != j && k != next)
            .all(|k| p.coords[k] <= VERTEX_TOLERANCE);
        let h = HalfedgeId(mesh.face_halfedge(p.face).0 + j as u32);
        (on_edge && mesh.is_boundary_halfedge(mesh.twin(h))).then(|| {
            let (a, b) = (p.coords[j], p.coords[next]);
            OnBoundary::Edge(h, b / (a + b))
        })
    })
}

/// The unit outward direction of the boundary at `on` (module docs); `None` where the
/// faces at it are degenerate (no normal, or a zero-length edge).
pub fn outward(mesh: &Mesh, on: OnBoundary) -> Option<Vector3<f64>> {
    let across = |h: HalfedgeId| -> Option<Vector3<f64>> {
        let face = mesh.face(h)?;
        mesh.halfedge_vector(h)
            .cross(&mesh.face_normal(face))
            .try_normalize(0.0)
    };
    match on {
        OnBoundary::Edge(h, _) => across(h),
        OnBoundary::Vertex(v) => {
            let out = mesh.vertex_halfedge(v);
            let sides = [across(mesh.twin(out)), across(mesh.twin(mesh.prev(out)))];
            match sides {
                [Some(a), Some(b)] => (a + b).try_normalize(1e-12).or(Some(a)),
                [a, b] => a.or(b),
            }
        }
    }
}

/// The unit outward direction of the boundary where `p` touches it, `None` for a point
/// off the boundary.
pub fn outward_at(mesh: &Mesh, p: &SurfacePoint) -> Option<Vector3<f64>> {
    outward(mesh, on_boundary(mesh, p)?)
}

#[cfg(test)]
mod tests {
    use beltrami_mesh::primitives::{Cells, grid};
    use beltrami_mesh::{FaceId, Point3};

    use super::*;

    /// The point of `mesh` at `(x, y)` in the face whose closest point it is.
    fn point_at(mesh: &Mesh, x: f64, y: f64) -> SurfacePoint {
        let p = Point3::new(x, y, 0.0);
        let index = crate::SurfaceIndex::new(mesh).expect("a grid indexes");
        index.locate(&p).expect("on the grid").point
    }

    #[test]
    fn the_outward_direction_of_a_square_points_away_from_each_side_and_corner() {
        let mesh = Mesh::from_soup(&grid(4, 4, Cells::Triangles)).expect("a grid is a mesh");
        let cases = [
            ((0.4, 0.0), Vector3::new(0.0, -1.0, 0.0)),
            ((1.0, 0.55), Vector3::new(1.0, 0.0, 0.0)),
            ((0.3, 1.0), Vector3::new(0.0, 1.0, 0.0)),
            ((0.0, 0.8), Vector3::new(-1.0, 0.0, 0.0)),
            ((1.0, 1.0), Vector3::new(1.0, 1.0, 0.0) / 2f64.sqrt()),
            ((0.0, 0.5), Vector3::new(-1.0, 0.0, 0.0)),
        ];
        for ((x, y), expected) in cases {
            let p = point_at(&mesh, x, y);
            let out = outward_at(&mesh, &p).expect("on the boundary");
            assert!(
                (out - expected).norm() < 1e-12,
                "at ({x}, {y}): {out} instead of {expected}"
            );
        }
    }

    #[test]
    fn a_point_inside_or_near_the_boundary_is_not_on_it() {
        let mesh = Mesh::from_soup(&grid(4, 4, Cells::Triangles)).expect("a grid is a mesh");
        for (x, y) in [(0.5, 0.5), (0.4, 1e-6), (0.25, 0.25)] {
            let p = point_at(&mesh, x, y);
            assert_eq!(on_boundary(&mesh, &p), None, "({x}, {y})");
        }
        let inner = SurfacePoint {
            face: FaceId(0),
            coords: [0.2, 0.3, 0.5, 0.0],
        };
        assert_eq!(outward_at(&mesh, &inner), None);
    }
}
