//! [`Mesh::with_points_inserted`]: a mesh with given surface points made vertices, each
//! triangle that holds one split into three about it, and the way back from points of
//! the refined mesh to points of the original.
//!
//! Registration uses it to make a landmark's target point a vertex of the target: a
//! road that sends landmarks to vertices then lands on the point exactly.

use crate::{BuildOptions, FaceId, Mesh, MeshError, Point3, PolygonSoup, Repair, SurfacePoint};

/// A point closer than this (in barycentric coordinates) to an edge of the triangle
/// that holds it is not inserted: the split would make a sliver.
const EDGE_CLEARANCE: f64 = 1e-6;

/// A point within this (in barycentric coordinates) of a corner is that corner.
const AT_CORNER: f64 = 1e-12;

/// A mesh with surface points inserted as vertices ([`Mesh::with_points_inserted`]).
#[derive(Debug, Clone)]
pub struct PointsInserted {
    /// The refined mesh: the original vertices with their ids, the inserted ones after
    /// them; face `f` of the original is face `f` here or one of its pieces.
    pub mesh: Mesh,
    /// The vertex of the refined mesh at each point given, in order: an inserted one, a
    /// corner the point is at, or `None` for a point not inserted (in a face that is not
    /// a triangle or not a face of the mesh, or within `1e-6` of an edge in barycentric
    /// coordinates).
    pub vertices: Vec<Option<crate::VertexId>>,
    /// Per face of `mesh`: its original face and the original coordinates of its three
    /// corners, or `None` for a face that was not split.
    pieces: Vec<Option<(FaceId, [[f64; 3]; 3])>>,
}

impl PointsInserted {
    /// The point of the original mesh that `point` (a point of the refined mesh) is:
    /// `sum_k c_k C_k` over the piece's corners `C_k` (original coordinates).
    pub fn to_original(&self, point: &SurfacePoint) -> SurfacePoint {
        match self.pieces.get(point.face.idx()).copied().flatten() {
            None => *point,
            Some((face, corners)) => {
                let mut coords = [0.0; 4];
                for (c, corner) in point.coords.iter().zip(&corners) {
                    for k in 0..3 {
                        coords[k] += c * corner[k];
                    }
                }
                SurfacePoint { face, coords }
            }
        }
    }
}

impl Mesh {
    /// This mesh with each of `points` made a vertex (module docs): the triangle piece
    /// holding the point is split into three about it (the piece keeps its id, the two
    /// new ones go last), in the order given, so that several points of one face split
    /// it in turn. A point at a corner is that corner; one in a face that is not a
    /// triangle or too near an edge is left out ([`PointsInserted::vertices`]).
    ///
    /// # Errors
    /// [`MeshError::TooLarge`] past `u32::MAX` vertices, and the [`MeshError`] of
    /// building the refined mesh (never for a valid mesh and points inside its faces).
    pub fn with_points_inserted(
        &self,
        points: &[SurfacePoint],
    ) -> Result<PointsInserted, MeshError> {
        let mut positions: Vec<Point3<f64>> = self.positions().to_vec();
        let mut faces: Vec<Vec<u32>> = self
            .faces()
            .map(|f| self.face_vertices(f).map(|v| v.0).collect())
            .collect();
        let mut pieces: Vec<Option<(FaceId, [[f64; 3]; 3])>> = vec![None; faces.len()];
        // The pieces of each original face that was split.
        let mut split: Vec<Vec<usize>> = vec![Vec::new(); faces.len()];
        let mut vertices = Vec::with_capacity(points.len());
        for point in points {
            let f = point.face.idx();
            if faces.get(f).is_none_or(|face| face.len() != 3) {
                vertices.push(None);
                continue;
            }
            let target = [point.coords[0], point.coords[1], point.coords[2]];
            let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
            // The piece holding the point and the point's coordinates in it.
            let candidates: Vec<usize> = if split[f].is_empty() {
                vec![f]
            } else {
                split[f].clone()
            };
            let Some((piece, local)) = candidates
                .iter()
                .map(|&p| {
                    let corners = pieces[p].map_or(identity, |(_, c)| c);
                    (p, local_coordinates(&corners, &target))
                })
                .max_by(|a, b| min3(&a.1).total_cmp(&min3(&b.1)))
            else {
                vertices.push(None);
                continue;
            };
            if let Some(k) = (0..3).find(|&k| local[k] >= 1.0 - AT_CORNER) {
                vertices.push(Some(crate::VertexId(faces[piece][k])));
                continue;
            }
            if min3(&local) < EDGE_CLEARANCE {
                vertices.push(None);
                continue;
            }
            let corners = pieces[piece].map_or(identity, |(_, c)| c);
            let [a, b, c] = [faces[piece][0], faces[piece][1], faces[piece][2]];
            let at = Point3::from(
                self.face_vertices(point.face)
                    .zip(&target)
                    .map(|(v, &c)| self.position(v).coords * c)
                    .sum::<nalgebra::Vector3<f64>>(),
            );
            let new = u32::try_from(positions.len())
                .map_err(|_| MeshError::TooLarge { what: "vertices" })?;
            positions.push(at);
            // The pieces (new, a, b), (new, b, c), (new, c, a) with the corners'
            // original coordinates.
            let pieces_of = [
                ([new, a, b], [target, corners[0], corners[1]]),
                ([new, b, c], [target, corners[1], corners[2]]),
                ([new, c, a], [target, corners[2], corners[0]]),
            ];
            for (k, (face, coords)) in pieces_of.into_iter().enumerate() {
                let id = if k == 0 { piece } else { faces.len() };
                if k == 0 {
                    faces[piece] = face.to_vec();
                    pieces[piece] = Some((FaceId::from_usize(f), coords));
                } else {
                    faces.push(face.to_vec());
                    pieces.push(Some((FaceId::from_usize(f), coords)));
                }
                if !split[f].contains(&id) {
                    split[f].push(id);
                }
            }
            vertices.push(Some(crate::VertexId(new)));
        }
        let mut soup = PolygonSoup::new(positions);
        for face in &faces {
            soup.push_face(face);
        }
        let options = BuildOptions {
            degenerate_area_tolerance: -1.0,
            repair: Repair::NONE,
        };
        let (mesh, _) = Mesh::build(&soup, &options)?;
        Ok(PointsInserted {
            mesh,
            vertices,
            pieces,
        })
    }
}

/// The smallest of three numbers.
fn min3(x: &[f64; 3]) -> f64 {
    x[0].min(x[1]).min(x[2])
}

/// The coordinates `l` of `point` in the triangle whose corners have (original
/// barycentric) coordinates `corners`: `point = sum_k l_k corners[k]` with
/// `sum_k l_k = 1`, by Cramer's rule on the first two components.
fn local_coordinates(corners: &[[f64; 3]; 3], point: &[f64; 3]) -> [f64; 3] {
    let [p, q, r] = corners;
    let (e1, e2) = ([q[0] - p[0], q[1] - p[1]], [r[0] - p[0], r[1] - p[1]]);
    let d = [point[0] - p[0], point[1] - p[1]];
    let det = e1[0] * e2[1] - e1[1] * e2[0];
    let l1 = (d[0] * e2[1] - d[1] * e2[0]) / det;
    let l2 = (e1[0] * d[1] - e1[1] * d[0]) / det;
    [1.0 - l1 - l2, l1, l2]
}

#[cfg(test)]
mod tests {
    use crate::primitives::{Cells, grid};
    use crate::{FaceId, Mesh, SurfacePoint, VertexId};

    fn at(face: u32, a: f64, b: f64) -> SurfacePoint {
        SurfacePoint {
            face: FaceId(face),
            coords: [a, b, 1.0 - a - b, 0.0],
        }
    }

    #[test]
    fn two_points_in_one_face_split_it_in_turn_and_map_back() {
        let square = Mesh::from_soup(&grid(2, 2, Cells::Triangles)).unwrap();
        let points = [at(3, 0.2, 0.3), at(3, 0.5, 0.25), at(5, 1.0, 0.0)];
        let refined = square.with_points_inserted(&points).unwrap();
        let n = square.vertex_count();
        assert_eq!(
            refined.vertices,
            [
                Some(VertexId::from_usize(n)),
                Some(VertexId::from_usize(n + 1)),
                Some(square.face_vertices(FaceId(5)).next().unwrap()),
            ]
        );
        assert_eq!(refined.mesh.face_count(), square.face_count() + 4);
        assert_eq!(refined.mesh.vertex_count(), n + 2);
        for (point, v) in points.iter().zip(&refined.vertices) {
            let v = v.unwrap();
            let moved = (refined.mesh.position(v) - point.position(&square)).norm();
            assert!(moved < 1e-15, "{moved}");
        }
        // Every piece maps back into its face; the area is kept; a point of a piece
        // maps back to the same position.
        let area = |m: &Mesh| m.faces().map(|f| m.face_area(f)).sum::<f64>();
        assert!((area(&refined.mesh) - area(&square)).abs() < 1e-14);
        for f in refined.mesh.faces() {
            let inside = SurfacePoint {
                face: f,
                coords: [0.2, 0.3, 0.5, 0.0],
            };
            let back = refined.to_original(&inside);
            assert!(back.face.idx() < square.face_count());
            let gap = (back.position(&square) - inside.position(&refined.mesh)).norm();
            assert!(gap < 1e-15, "face {f}: {gap}");
            assert!(back.coords.iter().all(|&c| c >= 0.0));
        }
    }

    #[test]
    fn a_point_on_an_edge_is_left_out() {
        let square = Mesh::from_soup(&grid(2, 2, Cells::Triangles)).unwrap();
        let refined = square.with_points_inserted(&[at(0, 0.5, 0.5)]).unwrap();
        assert_eq!(refined.vertices, [None]);
        assert_eq!(refined.mesh.face_count(), square.face_count());
    }
}
