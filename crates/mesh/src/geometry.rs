//! Geometry of the embedded mesh: lengths, areas, normals, angles, bounding box.
//!
//! Quads need not be planar. A quad `(p0, p1, p2, p3)` is the bilinear patch
//! `X(u, v) = (1-u)(1-v) p0 + u(1-v) p1 + u v p2 + (1-u) v p3` over the unit square, the
//! same surface the Q1 element uses; its area is the 2x2 Gauss integral of
//! `|X_u x X_v|`, exact for planar convex quads (there `X_u x X_v` is affine in `u` and
//! `v`). A non-convex quad folds the bilinear map (the Jacobian changes sign), so its
//! area is taken as the norm of its vector area instead, which is exact when it is
//! planar.

use nalgebra::{Point3, Vector3};

use crate::{EdgeId, FaceId, HalfedgeId, Mesh, VertexId};

/// An axis-aligned bounding box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundingBox {
    /// Smallest coordinates.
    pub min: Point3<f64>,
    /// Largest coordinates.
    pub max: Point3<f64>,
}

impl BoundingBox {
    /// The box around `points`; `None` if there are none.
    pub fn around<'a>(points: impl IntoIterator<Item = &'a Point3<f64>>) -> Option<Self> {
        let mut it = points.into_iter();
        let first = *it.next()?;
        Some(it.fold(
            BoundingBox {
                min: first,
                max: first,
            },
            |b, p| BoundingBox {
                min: b.min.inf(p),
                max: b.max.sup(p),
            },
        ))
    }

    /// Length of the diagonal.
    pub fn diagonal(&self) -> f64 {
        (self.max - self.min).norm()
    }

    /// The squared distance from `p` to the box (0 inside): the sum over the axes of
    /// `max(min_k - p_k, p_k - max_k, 0)^2`. No point of the box is nearer `p`, so a
    /// face whose box lies farther than a distance found elsewhere can be passed over.
    pub fn distance_squared(&self, p: &Point3<f64>) -> f64 {
        (0..3)
            .map(|k| {
                (self.min[k] - p[k])
                    .max(p[k] - self.max[k])
                    .max(0.0)
                    .powi(2)
            })
            .sum()
    }
}

/// Gauss points of the 2-point rule on [0, 1]: 1/2 -+ 1/(2 sqrt 3).
const GAUSS_2: [f64; 2] = [0.211_324_865_405_187_1, 0.788_675_134_594_812_9];

impl Mesh {
    /// Length of edge `e`.
    pub fn edge_length(&self, e: EdgeId) -> f64 {
        self.halfedge_vector(self.edge_halfedge(e)).norm()
    }

    /// Lengths of all edges, by edge id.
    pub fn edge_lengths(&self) -> Vec<f64> {
        self.edges().map(|e| self.edge_length(e)).collect()
    }

    /// Vector area of `f`: half the cross product of two sides (triangle) or of the two
    /// diagonals (quad). Its norm is the area of a planar face; its direction is the
    /// face normal.
    pub fn face_vector_area(&self, f: FaceId) -> Vector3<f64> {
        let (v, n) = self.face_vertex_array(f);
        let p = |k: usize| self.position(v[k]);
        if n == 3 {
            0.5 * (p(1) - p(0)).cross(&(p(2) - p(0)))
        } else {
            0.5 * (p(2) - p(0)).cross(&(p(3) - p(1)))
        }
    }

    /// Unit normal of `f` (direction of its vector area, counter-clockwise orientation).
    pub fn face_normal(&self, f: FaceId) -> Vector3<f64> {
        self.face_vector_area(f).normalize()
    }

    /// Area of `f`: exact for triangles; for quads the area of the bilinear patch by the
    /// 2x2 Gauss rule (exact for planar convex quads), or the norm of the vector area
    /// when the patch folds (a non-convex quad; exact when planar).
    pub fn face_area(&self, f: FaceId) -> f64 {
        let vector_area = self.face_vector_area(f);
        let (v, n) = self.face_vertex_array(f);
        if n == 3 {
            return vector_area.norm();
        }
        let p = |k: usize| self.position(v[k]);
        // The Jacobian X_u x X_v at corner k is the cross product of the corner's sides;
        // the patch folds when one of them turns against the face normal.
        let folded = (0..4).any(|k| {
            let corner = (p((k + 1) % 4) - p(k)).cross(&(p((k + 3) % 4) - p(k)));
            corner.dot(&vector_area) <= 0.0
        });
        if folded {
            return vector_area.norm();
        }
        let (d01, d32, d03, d12) = (p(1) - p(0), p(2) - p(3), p(3) - p(0), p(2) - p(1));
        let mut area = 0.0;
        for &u in &GAUSS_2 {
            for &w in &GAUSS_2 {
                let xu = (1.0 - w) * d01 + w * d32;
                let xv = (1.0 - u) * d03 + u * d12;
                area += 0.25 * xu.cross(&xv).norm();
            }
        }
        area
    }

    /// The vertex nearest to `point` (Euclidean distance; the first of equal ones), or
    /// `None` for a mesh without vertices. A linear scan: for many queries build a
    /// `beltrami_spatial::SurfaceIndex` instead.
    pub fn nearest_vertex(&self, point: &Point3<f64>) -> Option<VertexId> {
        self.vertices().min_by(|&a, &b| {
            let (da, db) = (
                (self.position(a) - point).norm_squared(),
                (self.position(b) - point).norm_squared(),
            );
            da.total_cmp(&db)
        })
    }

    /// Sum of all face areas.
    pub fn total_area(&self) -> f64 {
        self.faces().map(|f| self.face_area(f)).sum()
    }

    /// Centroid (vertex average) of `f`.
    pub fn face_centroid(&self, f: FaceId) -> Point3<f64> {
        let (v, n) = self.face_vertex_array(f);
        let sum: Vector3<f64> = v[..n].iter().map(|&v| self.position(v).coords).sum();
        Point3::from(sum / n as f64)
    }

    /// The interior angle of a face at the origin of face halfedge `h`, between `h` and
    /// the reverse of `prev(h)`, in radians, in `(0, 2 pi)`: measured counter-clockwise
    /// about the face normal, so a reflex corner of a non-convex quad has an angle above
    /// pi. Computed as `atan2((a x b) . n, a . b)`, accurate for angles near 0 and pi.
    pub fn corner_angle(&self, h: HalfedgeId) -> f64 {
        let a = self.halfedge_vector(h);
        let b = -self.halfedge_vector(self.prev(h));
        let cross = a.cross(&b);
        let sin = match self.face(h) {
            // Triangles are convex: the unsigned sine avoids a normal computation.
            Some(f) if self.face_degree(f) == 4 => cross.dot(&self.face_vector_area(f).normalize()),
            _ => cross.norm(),
        };
        let angle = sin.atan2(a.dot(&b));
        if angle < 0.0 {
            angle + std::f64::consts::TAU
        } else {
            angle
        }
    }

    /// Angle-weighted vertex normal: the sum over incident faces of the corner angle at
    /// `v` times the face normal, normalized.
    pub fn vertex_normal(&self, v: VertexId) -> Vector3<f64> {
        let sum: Vector3<f64> = self
            .outgoing_halfedges(v)
            .filter_map(|h| {
                self.face(h)
                    .map(|f| self.corner_angle(h) * self.face_normal(f))
            })
            .sum();
        sum.normalize()
    }

    /// Angle-weighted normals of all vertices, by vertex id.
    pub fn vertex_normals(&self) -> Vec<Vector3<f64>> {
        let mut sum = vec![Vector3::zeros(); self.vertex_count()];
        for f in self.faces() {
            let n = self.face_normal(f);
            for h in self.face_halfedges(f) {
                sum[self.origin(h).idx()] += self.corner_angle(h) * n;
            }
        }
        sum.into_iter().map(|s| s.normalize()).collect()
    }

    /// The discrete curvature at `v` from its corner angles: at an interior vertex the
    /// angle defect `2 pi - sum theta` (the integrated Gaussian curvature of its dual
    /// cell), at a boundary vertex the turning angle `pi - sum theta` (the integrated
    /// geodesic curvature of the boundary there, positive where the surface is convex
    /// at its boundary). By Gauss-Bonnet the sum over all vertices is `2 pi chi`.
    pub fn angle_defect(&self, v: VertexId) -> f64 {
        let sum: f64 = self
            .outgoing_halfedges(v)
            .filter(|&h| self.face(h).is_some())
            .map(|h| self.corner_angle(h))
            .sum();
        let full = if self.is_boundary_vertex(v) {
            std::f64::consts::PI
        } else {
            std::f64::consts::TAU
        };
        full - sum
    }

    /// The barycentric area of every vertex, by vertex id: the area of each face split
    /// equally among its corners. The areas sum to the mesh's area.
    pub fn vertex_areas(&self) -> Vec<f64> {
        let mut areas = vec![0.0; self.vertex_count()];
        for f in self.faces() {
            let share = self.face_area(f) / self.face_degree(f) as f64;
            for v in self.face_vertices(f) {
                areas[v.idx()] += share;
            }
        }
        areas
    }

    /// Bounding box of the mesh's vertices.
    pub fn bounding_box(&self) -> BoundingBox {
        // A built mesh has at least one face and so at least three vertices.
        BoundingBox::around(self.positions()).expect("a mesh has vertices")
    }
}
