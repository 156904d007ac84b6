//! A target mesh as the flow's target (Wong-Zhao 2014, sections 4.5 and 5.4): images
//! live on its surface, free vertices move in the tangent plane of the interpolated
//! normal and are projected back by exact closest-point location
//! ([`beltrami_spatial::SurfaceIndex`]); vertices on a boundary or feature curve slide
//! along it, as a polyline of target vertices.

use std::cell::RefCell;
use std::sync::Arc;

use beltrami_core::SolverError;
use beltrami_mesh::parallel::map_chunks_mut;
use beltrami_mesh::{FaceId, Mesh, Point3, SurfacePoint, Vector3, VertexId};
use beltrami_spatial::frame::interpolated_normal;
use beltrami_spatial::{BoundaryMode, MoveOptions, PolylineIndex, SurfaceIndex, boundary};

use crate::target::{Role, TargetGeometry};

/// The rings of free vertices next to the boundary over which the projection correction
/// of a step is spread on a target mesh ([`TargetGeometry::correction_rings`]): on
/// `mc4_face_a` onto `mc4_face_b` remeshed to 100K faces, solving over the whole
/// interior took a third of the step search (5.1 s of 13 s), over 8 rings 0.5 s, with
/// the same result.
pub const CORRECTION_RINGS: usize = 8;

/// A slide that ends closer to the next point of its polyline than this share of its
/// length ends on that point instead ([`TargetCurve::slide`]): left just short of a
/// corner, a vertex would cross it within the smallest step of every later search,
/// where the model's tangent no longer holds; on the corner it takes the tangent of the
/// side it moves to ([`TargetGeometry::curve_corner`]).
pub const CORNER_SNAP: f64 = 0.01;

/// A polyline of target vertices a chain of source vertices slides along, indexed for
/// exact closest points ([`PolylineIndex`]; shared by the clones of a target, one per
/// trial step).
#[derive(Debug, Clone)]
pub struct TargetCurve {
    index: Arc<PolylineIndex>,
}

impl TargetCurve {
    /// The curve through target vertices `vertices`.
    pub fn through(mesh: &Mesh, vertices: &[VertexId], closed: bool) -> Result<Self, SolverError> {
        let points = vertices.iter().map(|&v| mesh.position(v)).collect();
        let index = PolylineIndex::new(points, closed).map_err(spatial_error)?;
        Ok(Self {
            index: Arc::new(index),
        })
    }

    /// Every boundary loop of `mesh`, in `boundary_loop_list` order.
    pub fn boundary_loops(mesh: &Mesh) -> Result<Vec<Self>, SolverError> {
        mesh.boundary_loop_list()
            .iter()
            .map(|l| Self::through(mesh, &l.vertices, true))
            .collect()
    }

    /// The closest point of the curve to `p` and the unit direction of its segment (the
    /// curve's first point and the x axis when it has no segment of positive length).
    pub fn closest(&self, p: &Point3<f64>) -> (Point3<f64>, Vector3<f64>) {
        match self.index.closest(p) {
            Some(on) => (on.position, on.direction),
            None => (
                self.index.points().first().copied().unwrap_or(*p),
                Vector3::x(),
            ),
        }
    }

    /// The tangents `[behind, ahead]` of the curve at `p` when the closest point of the
    /// curve to `p` is a corner of it ([`PolylineIndex::corner`]).
    pub fn corner(&self, p: &Point3<f64>) -> Option<[Vector3<f64>; 2]> {
        let on = self.index.closest(p)?;
        self.index.corner(&on).map(|c| [c.behind, c.ahead])
    }

    /// The point of the curve reached from the closest point to `p` by walking along
    /// the curve by the arc length `d . T`, `T` the tangent there most nearly parallel
    /// to `d` (one of a corner's two; [`PolylineIndex::walk`]), or the next point of the
    /// polyline when the walk ends within [`CORNER_SNAP`] of its length short of it.
    pub fn slide(&self, p: &Point3<f64>, d: &Vector3<f64>) -> Point3<f64> {
        let Some(on) = self.index.closest(p) else {
            return *p;
        };
        let arc = match self.index.corner(&on) {
            Some(corner) => {
                let (behind, ahead) = (d.dot(&corner.behind), d.dot(&corner.ahead));
                if behind.abs() >= ahead.abs() {
                    behind
                } else {
                    ahead
                }
            }
            None => d.dot(&on.direction),
        };
        let end = self.index.walk(&on, arc);
        let points = self.index.points();
        let next = if arc > 0.0 {
            points[(end.segment + 1) % points.len()]
        } else {
            points[end.segment]
        };
        if (next - end.position).norm() <= CORNER_SNAP * arc.abs() {
            next
        } else {
            end.position
        }
    }

    /// The mean distance of `points` to the curve.
    pub fn mean_distance<'p>(&self, points: impl Iterator<Item = &'p Point3<f64>>) -> f64 {
        let (sum, n) = points.fold((0.0, 0usize), |(s, n), p| {
            (s + (self.closest(p).0 - p).norm(), n + 1)
        });
        if n > 0 { sum / n as f64 } else { f64::INFINITY }
    }
}

/// A target mesh with its curves (curve `c` is `curves[c]`).
#[derive(Clone)]
pub struct MeshTarget<'a> {
    index: &'a SurfaceIndex<'a>,
    curves: Vec<TargetCurve>,
    /// The face each source vertex was last located in: the start of the next search.
    hints: RefCell<Vec<FaceId>>,
    /// The surface points of the images a step starts from ([`TargetGeometry::prepare_step`]);
    /// after [`TargetGeometry::project_all`], those of the points it projected.
    start: RefCell<Vec<SurfacePoint>>,
}

impl std::fmt::Debug for MeshTarget<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MeshTarget")
            .field("faces", &self.index.mesh().face_count())
            .field("curves", &self.curves.len())
            .finish_non_exhaustive()
    }
}

fn spatial_error(error: beltrami_spatial::SpatialError) -> SolverError {
    SolverError::invalid(
        crate::NAME,
        format!("locating a point on the target mesh: {error}"),
    )
}

impl<'a> MeshTarget<'a> {
    /// The target of `index`'s mesh with `curves`.
    pub fn new(index: &'a SurfaceIndex<'a>, curves: Vec<TargetCurve>) -> Self {
        Self {
            index,
            curves,
            hints: RefCell::new(Vec::new()),
            start: RefCell::new(Vec::new()),
        }
    }

    /// The target mesh.
    pub fn mesh(&self) -> &'a Mesh {
        self.index.mesh()
    }

    /// The surface points of `points` (their closest points on the target).
    pub fn locate_all(&self, points: &[Point3<f64>]) -> Result<Vec<SurfacePoint>, SolverError> {
        let located = self.locate(points)?;
        Ok(located.into_iter().map(|l| l.point).collect())
    }

    fn locate(
        &self,
        points: &[Point3<f64>],
    ) -> Result<Vec<beltrami_spatial::Located>, SolverError> {
        let mut hints = self.hints.borrow_mut();
        let located = if hints.len() == points.len() {
            self.index.locate_all_near(points, &hints)
        } else {
            self.index.locate_all(points)
        }
        .map_err(spatial_error)?;
        hints.clear();
        hints.extend(located.iter().map(|l| l.point.face));
        Ok(located)
    }
}

impl TargetGeometry for MeshTarget<'_> {
    fn normal(&self, p: &Point3<f64>) -> Vector3<f64> {
        match self.index.locate(p) {
            Ok(l) => interpolated_normal(self.mesh(), self.index.vertex_normals(), &l.point),
            Err(_) => Vector3::z(),
        }
    }

    fn curve_tangent(&self, curve: usize, p: &Point3<f64>) -> Vector3<f64> {
        self.curves[curve].closest(p).1
    }

    fn curve_corner(&self, curve: usize, p: &Point3<f64>) -> Option<[Vector3<f64>; 2]> {
        self.curves[curve].corner(p)
    }

    /// From the surface point the last projection or step left `vertex` at, while its
    /// image is still there ([`beltrami_spatial::boundary::outward`]).
    fn boundary_outward(&self, vertex: usize, p: &Point3<f64>) -> Option<Vector3<f64>> {
        let mesh = self.mesh();
        if mesh.boundary_loop_count() == 0 {
            return None;
        }
        let start = self.start.borrow();
        let at = start.get(vertex)?;
        let on = boundary::on_boundary(mesh, at)?;
        (at.position(mesh) == *p)
            .then(|| boundary::outward(mesh, on))
            .flatten()
    }

    fn slide(&self, curve: usize, p: &Point3<f64>, d: &Vector3<f64>) -> Point3<f64> {
        self.curves[curve].slide(p, d)
    }

    /// Keeps the surface points of the last [`TargetGeometry::project_all`] where they
    /// are still where `from` says (the accepted step's walk ended there: every free
    /// vertex), and locates only the others (curve vertices, which sit on their
    /// polyline instead, and vertices moved since, by an untangling).
    fn prepare_step(&self, from: &[Point3<f64>]) -> Result<(), SolverError> {
        let mesh = self.mesh();
        let mut start = self.start.borrow_mut();
        if start.len() != from.len() {
            *start = self.locate_all(from)?;
            return Ok(());
        }
        let stale: Vec<usize> = (0..from.len())
            .filter(|&i| start[i].position(mesh) != from[i])
            .collect();
        if stale.is_empty() {
            return Ok(());
        }
        let points: Vec<Point3<f64>> = stale.iter().map(|&i| from[i]).collect();
        let hints: Vec<FaceId> = stale.iter().map(|&i| start[i].face).collect();
        let located = self
            .index
            .locate_all_near(&points, &hints)
            .map_err(spatial_error)?;
        let mut all_hints = self.hints.borrow_mut();
        for (&i, l) in stale.iter().zip(located) {
            start[i] = l.point;
            if let Some(h) = all_hints.get_mut(i) {
                *h = l.point.face;
            }
        }
        Ok(())
    }

    fn curve_count(&self) -> usize {
        self.curves.len()
    }

    /// [`CORRECTION_RINGS`]: the curves are polylines, so a vertex moved along its
    /// segment's tangent stays on the curve, and only those that pass a corner are pulled
    /// back; the correction is sparse and local.
    fn correction_rings(&self) -> Option<usize> {
        Some(CORRECTION_RINGS)
    }

    fn project(&self, role: Role, p: &Point3<f64>) -> Point3<f64> {
        match role {
            Role::Free => self.index.locate(p).map_or(*p, |l| l.position),
            Role::Curve(c) => self.curves[c].closest(p).0,
            Role::Fixed => *p,
        }
    }

    fn project_all(
        &self,
        roles: &[Role],
        from: Option<&[Point3<f64>]>,
        points: &mut [Point3<f64>],
        normals: &mut Vec<Vector3<f64>>,
    ) -> Result<(), SolverError> {
        let surface: Vec<SurfacePoint> = match from {
            // A step: walk every point from where it was by its tangential displacement
            // (its cost grows with the faces crossed, where locating a point far off the
            // surface searches a ball as large as that distance).
            Some(from) => {
                // Taken, not copied: the walk's end replaces it below.
                let mut start = std::mem::take(&mut *self.start.borrow_mut());
                if start.len() != from.len() {
                    start = self.locate_all(from)?;
                }
                let displacements: Vec<Vector3<f64>> =
                    points.iter().zip(from).map(|(p, q)| p - q).collect();
                // A free vertex whose walk meets the target's boundary slides along it
                // by the rest of its move: stopped there, a vertex the flow pushes
                // outwards would not move at all, and the model would be wrong for all
                // of its faces (on `mc4_face_b` onto `mc4_face_a` remeshed to 100K
                // faces, the flow stalled with five such vertices moving by 0 of their
                // modeled moves, the largest of the step).
                let options = MoveOptions {
                    boundary: BoundaryMode::Slide,
                    ..MoveOptions::default()
                };
                self.index
                    .move_all(&mut start, &displacements, &options)
                    .map_err(spatial_error)?;
                let mut hints = self.hints.borrow_mut();
                hints.clear();
                hints.extend(start.iter().map(|p| p.face));
                start
            }
            None => self.locate_all(points)?,
        };
        *self.start.borrow_mut() = surface;
        let kept = self.start.borrow();
        let surface: &[SurfacePoint] = &kept;
        let (mesh, curves) = (self.mesh(), &self.curves);
        let (vertex_normals, threads) = (self.index.vertex_normals(), self.index.threads());
        normals.clear();
        normals.resize(points.len(), Vector3::zeros());
        map_chunks_mut(normals, threads, |offset, chunk| {
            for (normal, s) in chunk.iter_mut().zip(&surface[offset..]) {
                *normal = interpolated_normal(mesh, vertex_normals, s);
            }
        });
        map_chunks_mut(points, threads, |offset, chunk| {
            for ((p, s), &role) in chunk
                .iter_mut()
                .zip(&surface[offset..])
                .zip(&roles[offset..])
            {
                match role {
                    Role::Free => *p = s.position(mesh),
                    Role::Curve(c) => *p = curves[c].closest(p).0,
                    Role::Fixed => {}
                }
            }
        });
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use beltrami_mesh::primitives::{Cells, grid};

    use super::*;

    /// The unit-square grid lifted onto `z = (x^2 + y^2) / 2`, its boundary vertices on
    /// curve 0.
    fn paraboloid(n: usize) -> (Mesh, Vec<Role>) {
        let mut soup = grid(n, n, Cells::Triangles);
        for p in &mut soup.positions {
            p.z = 0.5 * (p.x * p.x + p.y * p.y);
        }
        let mesh = Mesh::from_soup(&soup).expect("a grid is a valid mesh");
        let roles = mesh
            .vertices()
            .map(|v| {
                if mesh.is_boundary_vertex(v) {
                    Role::Curve(0)
                } else {
                    Role::Free
                }
            })
            .collect();
        (mesh, roles)
    }

    #[test]
    fn a_step_starts_from_the_points_the_accepted_walk_reached_or_from_fresh_ones() {
        let (mesh, roles) = paraboloid(12);
        let index = SurfaceIndex::new(&mesh).unwrap();
        let target = MeshTarget::new(&index, TargetCurve::boundary_loops(&mesh).unwrap());
        let mut image: Vec<Point3<f64>> = mesh.positions().to_vec();
        let mut normals = Vec::new();
        target
            .project_all(&roles, None, &mut image, &mut normals)
            .unwrap();
        target.prepare_step(&image).unwrap();
        // A trial step: every point pushed along a smooth field, walked on the surface.
        let mut moved_image: Vec<Point3<f64>> = image
            .iter()
            .map(|p| p + Vector3::new(0.03 * p.y, -0.02 * p.x, 0.0))
            .collect();
        let moved = target.clone();
        moved
            .project_all(&roles, Some(&image), &mut moved_image, &mut normals)
            .unwrap();
        // An untangling moves one interior vertex after the walk.
        let displaced = 5 + 13 * 6;
        assert_eq!(roles[displaced], Role::Free);
        moved_image[displaced] = moved.project(Role::Free, &Point3::new(0.37, 0.61, 0.0));
        moved.prepare_step(&moved_image).unwrap();
        let start = moved.start.borrow();
        let fresh = index.locate_all(&moved_image).unwrap();
        for (i, (s, l)) in start.iter().zip(&fresh).enumerate() {
            s.validate(&mesh).unwrap();
            let (kept, located) = (s.position(&mesh), l.point.position(&mesh));
            assert!(
                (kept - moved_image[i]).norm() < 1e-12 && (kept - located).norm() < 1e-12,
                "vertex {i} ({:?}) starts at {kept} instead of {}",
                roles[i],
                moved_image[i]
            );
        }
    }

    /// A slide goes round a corner by arc length, and one that would end within
    /// [`CORNER_SNAP`] of its length short of a corner ends on it.
    #[test]
    fn a_slide_goes_round_corners_and_ends_on_one_it_nearly_reaches() {
        let square = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
            .map(|(x, y)| Point3::new(x, y, 0.0))
            .to_vec();
        let mut soup = beltrami_mesh::PolygonSoup::new(square);
        soup.push_face(&[0, 1, 2, 3]);
        let mesh = Mesh::from_soup(&soup).unwrap();
        let loops = TargetCurve::boundary_loops(&mesh).unwrap();
        let curve = &loops[0];
        let [behind, ahead] = curve.corner(&Point3::new(1.0, 0.0, 0.0)).unwrap();
        let from = Point3::new(0.5, 0.0, 0.0);
        let turn = if behind.x > 0.0 { ahead } else { -behind };
        let cases = [
            (0.75, Point3::new(1.0, 0.0, 0.0) + turn * 0.25),
            (0.5 * (1.0 - 0.5 * CORNER_SNAP), Point3::new(1.0, 0.0, 0.0)),
            (
                0.5 * (1.0 - 2.0 * CORNER_SNAP),
                Point3::new(0.5 + 0.5 * (1.0 - 2.0 * CORNER_SNAP), 0.0, 0.0),
            ),
        ];
        for (length, expected) in cases {
            let got = curve.slide(&from, &(Vector3::x() * length));
            assert!(
                (got - expected).norm() < 1e-14,
                "{length}: {got} instead of {expected}"
            );
        }
    }

    /// A free point on the target's boundary pushed outwards slides along the boundary
    /// by its move's component along it instead of stopping where it is.
    #[test]
    fn a_free_point_pushed_out_of_the_target_slides_along_its_boundary() {
        let mesh = Mesh::from_soup(&grid(4, 4, Cells::Triangles)).unwrap();
        let index = SurfaceIndex::new(&mesh).unwrap();
        let target = MeshTarget::new(&index, Vec::new());
        let from = vec![Point3::new(0.4, 0.0, 0.0), Point3::new(0.5, 0.5, 0.0)];
        let roles = vec![Role::Free; 2];
        let mut normals = Vec::new();
        let mut start = from.clone();
        target
            .project_all(&roles, None, &mut start, &mut normals)
            .unwrap();
        target.prepare_step(&start).unwrap();
        let mut moved = vec![
            from[0] + Vector3::new(0.1, -0.3, 0.0),
            from[1] + Vector3::new(0.1, -0.3, 0.0),
        ];
        target
            .project_all(&roles, Some(&start), &mut moved, &mut normals)
            .unwrap();
        assert!(
            (moved[0] - Point3::new(0.5, 0.0, 0.0)).norm() < 1e-12,
            "{}",
            moved[0]
        );
        assert!(
            (moved[1] - Point3::new(0.6, 0.2, 0.0)).norm() < 1e-12,
            "{}",
            moved[1]
        );
    }
}
