//! Landmarks and the alignments they choose: the rotation of the disk's boundary, a
//! rotation or Moebius transformation of the sphere, and the symmetry of the square of
//! a torus. Without landmarks the same freedoms are fixed by a rough spatial match of
//! the two meshes ([`SpatialMatch`]).

use beltrami_core::{Landmark, Position};
use beltrami_mesh::{Mesh, Point3, SurfacePoint, Vector3, VertexId};
use beltrami_spatial::SurfaceIndex;
use nalgebra::{Matrix3, Matrix3x4, Rotation3, Unit};
use num_complex::Complex64;

use crate::error::RegisterError;

/// A checked landmark with its target as a surface point of the target mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Resolved {
    /// Index in the user's slice.
    pub index: usize,
    /// The source vertex.
    pub source: VertexId,
    /// The target point.
    pub target: SurfacePoint,
    /// The target vertex: a [`Position::TargetVertex`], or a point at a vertex.
    pub vertex: Option<VertexId>,
}

/// Checks every landmark and locates point targets on the target mesh; a target vertex
/// ([`Position::TargetVertex`]) stays that vertex.
///
/// # Errors
/// [`RegisterError::Landmark`] for a source or target vertex out of range, a source
/// vertex given twice, a target point with a NaN or infinite coordinate or farther than
/// [`FAR_OFF`] from the target, a destination in the plane, or two landmarks onto one
/// point.
pub(crate) fn resolve(
    source: &Mesh,
    target: &Mesh,
    target_index: &SurfaceIndex<'_>,
    landmarks: &[Landmark],
) -> Result<Vec<Resolved>, RegisterError> {
    let mut seen = vec![usize::MAX; source.vertex_count()];
    let mut out = Vec::with_capacity(landmarks.len());
    for (index, landmark) in landmarks.iter().enumerate() {
        let fail = |reason: String| RegisterError::Landmark {
            index,
            vertex: landmark.vertex,
            reason,
        };
        let s = landmark.vertex;
        if s.idx() >= source.vertex_count() {
            return Err(fail(format!(
                "the source has only {} vertices",
                source.vertex_count()
            )));
        }
        if seen[s.idx()] != usize::MAX {
            return Err(fail(format!(
                "the vertex already has landmark {}",
                seen[s.idx()]
            )));
        }
        seen[s.idx()] = index;
        let (point, vertex) = match landmark.position {
            Position::TargetVertex(v) => {
                if v.idx() >= target.vertex_count() {
                    return Err(fail(format!(
                        "target vertex {v} does not exist: the target has {} vertices",
                        target.vertex_count()
                    )));
                }
                (SurfacePoint::at_vertex(target, v), Some(v))
            }
            Position::Spatial(p) => {
                if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
                    return Err(fail(format!("the target point {p:?} is not finite")));
                }
                let found = target_index.locate(&p)?;
                let diagonal = target.bounding_box().diagonal();
                if found.distance > FAR_OFF * diagonal {
                    return Err(fail(format!(
                        "its point ({}, {}, {}) is {:.4e} from the target, more than {:.0}% of the target's size ({diagonal:.4e}): is it a point of the target mesh, in its units?",
                        p.x,
                        p.y,
                        p.z,
                        found.distance,
                        100.0 * FAR_OFF,
                    )));
                }
                let point = found.point;
                // A point at a vertex is that vertex, whichever of its faces the
                // location chose: a boundary vertex stays on the boundary.
                match at_corner(target, &point) {
                    Some(v) => (SurfacePoint::at_vertex(target, v), Some(v)),
                    None => (point, None),
                }
            }
            Position::Planar(_) => {
                return Err(fail(
                    "its destination is a point of the plane; a map onto a target mesh needs a point of R^3 or a target vertex".into(),
                ));
            }
        };
        out.push(Resolved {
            index,
            source: s,
            target: point,
            vertex,
        });
    }
    one_target_each(target, landmarks, &out)?;
    Ok(out)
}

/// Refuses two landmarks whose targets coincide (within `1e-9` of the target's
/// diagonal, [`coincident`]): a bijection cannot send two source vertices onto one
/// point.
fn one_target_each(
    target: &Mesh,
    landmarks: &[Landmark],
    resolved: &[Resolved],
) -> Result<(), RegisterError> {
    let at: Vec<Point3<f64>> = resolved.iter().map(|m| m.target.position(target)).collect();
    match coincident(&at, SAME_POINT * target.bounding_box().diagonal()) {
        Some((first, second)) => Err(same_point(
            second,
            landmarks[second].vertex,
            first,
            landmarks[first].vertex,
        )),
        None => Ok(()),
    }
}

/// The largest distance of a landmark point from the target, relative to the target's
/// bounding-box diagonal: a point farther off is almost surely of another mesh or in
/// other units, and silently snapping it would hide that.
pub(crate) const FAR_OFF: f64 = 0.05;

/// Two landmark targets closer than this (relative to the target's diagonal) are one
/// point.
pub(crate) const SAME_POINT: f64 = 1e-9;

/// The first pair `(j, i)`, `j < i`, of `points` within `tolerance` of each other, by a
/// sweep in `x`.
pub(crate) fn coincident(points: &[Point3<f64>], tolerance: f64) -> Option<(usize, usize)> {
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| points[a].x.total_cmp(&points[b].x));
    let mut best: Option<(usize, usize)> = None;
    for (k, &a) in order.iter().enumerate() {
        for &b in order[k + 1..]
            .iter()
            .take_while(|&&b| points[b].x - points[a].x <= tolerance)
        {
            if (points[a] - points[b]).norm() <= tolerance {
                let pair = (a.min(b), a.max(b));
                if best.is_none_or(|p| (pair.1, pair.0) < (p.1, p.0)) {
                    best = Some(pair);
                }
            }
        }
    }
    best
}

/// The error of landmark `index` (source vertex `vertex`) going where landmark `first`
/// (source vertex `first_vertex`) goes.
pub(crate) fn same_point(
    index: usize,
    vertex: VertexId,
    first: usize,
    first_vertex: VertexId,
) -> RegisterError {
    RegisterError::Landmark {
        index,
        vertex,
        reason: format!(
            "it goes to the same target point as landmark {first} (source vertex {first_vertex}): a bijection cannot map two vertices onto one point"
        ),
    }
}

/// The vertex of `point`'s face that `point` is at (a coordinate within
/// [`AT_CORNER`] of 1), if any.
fn at_corner(mesh: &Mesh, point: &SurfacePoint) -> Option<VertexId> {
    let (vertices, degree) = mesh.face_vertex_array(point.face);
    (0..degree)
        .find(|&k| point.coords[k] >= 1.0 - AT_CORNER)
        .map(|k| vertices[k])
}

/// Barycentric coordinates this close to 1 put a point at a corner (rounding of the
/// closest-point computation at a vertex is ~1e-16).
const AT_CORNER: f64 = 1e-12;

/// The value of a per-vertex parameterization at a surface point: the coordinates
/// applied to the values of the face's vertices in `mesh` (the target, or its cut).
pub(crate) fn interpolate<T>(mesh: &Mesh, values: &[T], point: &SurfacePoint) -> T
where
    T: Copy + std::ops::Mul<f64, Output = T> + std::ops::Add<Output = T>,
{
    let (vertices, degree) = mesh.face_vertex_array(point.face);
    let mut sum = values[vertices[0].idx()] * point.coords[0];
    for k in 1..degree {
        sum = sum + values[vertices[k].idx()] * point.coords[k];
    }
    sum
}

/// A rough correspondence in space used when no landmark fixes an alignment: both meshes
/// are centred at their area centroids and scaled to the same root-mean-square vertex
/// distance from it (no rotation), and a source vertex's *spatial partner* is the closest
/// point of the target to its moved position. [`SpatialMatch::fitted`] takes the
/// similarity that best carries landmarks onto their targets instead.
pub(crate) struct SpatialMatch {
    source_center: Point3<f64>,
    target_center: Point3<f64>,
    scale: f64,
    /// `s R` for a similarity; any orientation-preserving linear map once refined by
    /// [`SpatialMatch::refined_by_closest_points`].
    linear: Matrix3<f64>,
}

impl SpatialMatch {
    /// The centring and scaling of `source` onto `target`.
    pub(crate) fn new(source: &Mesh, target: &Mesh) -> Self {
        let (source_center, source_radius) = center_and_radius(source);
        let (target_center, target_radius) = center_and_radius(target);
        let scale = if source_radius > 0.0 {
            target_radius / source_radius
        } else {
            1.0
        };
        Self {
            source_center,
            target_center,
            scale,
            linear: Matrix3::identity() * scale,
        }
    }

    /// The similarity `p -> c_t + s R (p - c_s)` minimizing the squared distances of the
    /// moved points `from` to the points `to` (Umeyama 1991: centroids, `R` by Kabsch,
    /// `s = sum (R a_i) . b_i / sum |a_i|^2` for the centred pairs), or `None` for fewer
    /// than three pairs or pairs on one line.
    pub(crate) fn fitted(from: &[Point3<f64>], to: &[Point3<f64>]) -> Option<Self> {
        let n = from.len();
        if n < 3 || to.len() != n {
            return None;
        }
        let mean = |ps: &[Point3<f64>]| {
            Point3::from(ps.iter().map(|p| p.coords).sum::<Vector3<f64>>() / n as f64)
        };
        let (source_center, target_center) = (mean(from), mean(to));
        let pairs: Vec<(Vector3<f64>, Vector3<f64>)> = from
            .iter()
            .zip(to)
            .map(|(a, b)| (a - source_center, b - target_center))
            .collect();
        let extent: f64 = pairs.iter().map(|(a, _)| a.norm_squared()).sum();
        let spread = pairs
            .iter()
            .flat_map(|(a, _)| pairs.iter().map(move |(b, _)| a.cross(b).norm_squared()))
            .fold(0.0, f64::max);
        if extent.is_nan() || extent <= 0.0 || spread <= 1e-6 * extent * extent {
            return None;
        }
        let rotation = best_rotation(&pairs);
        let scale = pairs
            .iter()
            .map(|(a, b)| (rotation * a).dot(b))
            .sum::<f64>()
            / extent;
        (scale > 0.0).then_some(Self {
            source_center,
            target_center,
            scale,
            linear: rotation * scale,
        })
    }

    /// The scale factor `s` of the similarity (before any refinement).
    pub(crate) fn scale(&self) -> f64 {
        self.scale
    }

    /// The match refined by closest points (`crate::affine_alignment`): from this
    /// placement, the affine map that best carries `source`'s vertices onto their
    /// closest points on the target of `index`.
    ///
    /// # Errors
    /// [`RegisterError::Spatial`] when a closest point cannot be found.
    pub(crate) fn refined_by_closest_points(
        self,
        source: &Mesh,
        index: &SurfaceIndex<'_>,
    ) -> Result<Self, RegisterError> {
        let samples: Vec<Point3<f64>> = crate::affine_alignment::spread_vertices(source)
            .into_iter()
            .map(|v| source.position(v))
            .collect();
        let m = crate::affine_alignment::closest_point_affine(
            &samples,
            index,
            self.as_affine(),
            self.scale,
            crate::affine_alignment::ROUNDS,
        )?;
        let linear: Matrix3<f64> = m.fixed_view::<3, 3>(0, 0).into_owned();
        Ok(Self {
            target_center: Point3::from(linear * self.source_center.coords + m.column(3)),
            linear,
            ..self
        })
    }

    /// The match as an affine map `p -> M (p, 1)`.
    pub(crate) fn as_affine(&self) -> Matrix3x4<f64> {
        let linear = self.linear;
        let shift = self.target_center.coords - linear * self.source_center.coords;
        let mut m = Matrix3x4::zeros();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&linear);
        m.set_column(3, &shift);
        m
    }

    /// A source position moved into the target's frame.
    pub(crate) fn to_target(&self, p: &Point3<f64>) -> Point3<f64> {
        self.target_center + self.linear * (p - self.source_center)
    }
}

fn center_and_radius(mesh: &Mesh) -> (Point3<f64>, f64) {
    let mut weighted = Vector3::zeros();
    let mut area = 0.0;
    for f in mesh.faces() {
        let a = mesh.face_area(f);
        weighted += mesh.face_centroid(f).coords * a;
        area += a;
    }
    let center = if area > 0.0 {
        Point3::from(weighted / area)
    } else {
        Point3::origin()
    };
    let n = mesh.vertex_count().max(1) as f64;
    let squares: f64 = mesh
        .positions()
        .iter()
        .map(|p| (p - center).norm_squared())
        .sum();
    (center, (squares / n).sqrt())
}

/// The rotation `R` minimizing `sum_i |R a_i - b_i|^2` (Kabsch: `R = V diag(1, 1, d) U^T`
/// from the SVD `U S V^T` of `sum_i a_i b_i^T`, `d = det(V U^T)`), or the identity when
/// the SVD fails.
pub(crate) fn best_rotation(pairs: &[(Vector3<f64>, Vector3<f64>)]) -> Matrix3<f64> {
    let mut h = Matrix3::zeros();
    for (a, b) in pairs {
        h += a * b.transpose();
    }
    let svd = h.svd(true, true);
    match (svd.u, svd.v_t) {
        (Some(u), Some(v_t)) => {
            let v = v_t.transpose();
            let d = (v * u.transpose()).determinant().signum();
            v * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, d)) * u.transpose()
        }
        _ => Matrix3::identity(),
    }
}

/// The smallest rotation taking the unit vector `a` to the unit vector `b` (a half turn
/// about an axis orthogonal to `a` when they are opposite).
pub(crate) fn rotation_between(a: &Vector3<f64>, b: &Vector3<f64>) -> Matrix3<f64> {
    Rotation3::rotation_between(a, b)
        .unwrap_or_else(|| {
            let helper = if a.x.abs() < 0.9 {
                Vector3::x()
            } else {
                Vector3::y()
            };
            Rotation3::from_axis_angle(&Unit::new_normalize(a.cross(&helper)), std::f64::consts::PI)
        })
        .into_inner()
}

/// A Moebius transformation of the unit sphere, `z -> (m00 z + m01) / (m10 z + m11)` in
/// the stereographic coordinate `z = (x + i y) / (1 - z_3)` from the north pole, kept in
/// homogeneous form so that the pole (`z = infinity`) needs no special case.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Moebius {
    m: [[Complex64; 2]; 2],
}

impl Moebius {
    /// The transformation taking `from[k]` to `to[k]` (three distinct unit vectors each),
    /// or `None` when points coincide. Built as `B^-1 A` with `A` taking `from` to
    /// `0, 1, infinity` (the cross-ratio map) and `B` the same for `to`.
    pub(crate) fn through(from: [Vector3<f64>; 3], to: [Vector3<f64>; 3]) -> Option<Self> {
        let a = cross_ratio_map(from)?;
        let b = cross_ratio_map(to)?;
        // The adjugate inverts up to a scalar, which a homogeneous map ignores.
        let b_inv = [[b[1][1], -b[0][1]], [-b[1][0], b[0][0]]];
        let mut m = [[Complex64::new(0.0, 0.0); 2]; 2];
        for (i, row) in m.iter_mut().enumerate() {
            for (j, entry) in row.iter_mut().enumerate() {
                *entry = b_inv[i][0] * a[0][j] + b_inv[i][1] * a[1][j];
            }
        }
        Some(Self { m })
    }

    /// The image of a unit vector.
    pub(crate) fn apply(&self, p: &Vector3<f64>) -> Vector3<f64> {
        let [w0, w1] = homogeneous(p);
        let a = self.m[0][0] * w0 + self.m[0][1] * w1;
        let b = self.m[1][0] * w0 + self.m[1][1] * w1;
        from_homogeneous(a, b)
    }
}

/// Homogeneous stereographic coordinates `[w0 : w1]` with `w0 / w1 = (x + i y) / (1 -
/// z)`, taken as `(1 + z) / (x - i y)` on the upper half to stay away from `0 / 0`.
fn homogeneous(p: &Vector3<f64>) -> [Complex64; 2] {
    if p.z <= 0.0 {
        [Complex64::new(p.x, p.y), Complex64::new(1.0 - p.z, 0.0)]
    } else {
        [Complex64::new(1.0 + p.z, 0.0), Complex64::new(p.x, -p.y)]
    }
}

/// The inverse stereographic projection of `a / b`:
/// `(2 Re(a conj b), 2 Im(a conj b), |a|^2 - |b|^2) / (|a|^2 + |b|^2)`.
fn from_homogeneous(a: Complex64, b: Complex64) -> Vector3<f64> {
    let ab = a * b.conj();
    let (na, nb) = (a.norm_sqr(), b.norm_sqr());
    let s = na + nb;
    Vector3::new(2.0 * ab.re / s, 2.0 * ab.im / s, (na - nb) / s)
}

/// The homogeneous matrix of `z -> ((z - z1)(z2 - z3)) / ((z - z3)(z2 - z1))`, which takes
/// `z1, z2, z3` to `0, 1, infinity`; with `[p, q] = p_0 q_1 - p_1 q_0` the rows are
/// `[z2, z3] (b1, -a1)` and `[z2, z1] (b3, -a3)` for `z_k = a_k / b_k`.
fn cross_ratio_map(points: [Vector3<f64>; 3]) -> Option<[[Complex64; 2]; 2]> {
    let [p1, p2, p3] = points.map(|p| homogeneous(&p));
    let bracket = |p: [Complex64; 2], q: [Complex64; 2]| p[0] * q[1] - p[1] * q[0];
    let c1 = bracket(p2, p3);
    let c3 = bracket(p2, p1);
    let scale = (p1[0].norm() + p1[1].norm()) * (p2[0].norm() + p2[1].norm());
    if c1.norm() <= 1e-12 * scale
        || c3.norm() <= 1e-12 * scale
        || bracket(p1, p3).norm() <= 1e-12 * scale
    {
        return None;
    }
    Some([[c1 * p1[1], -c1 * p1[0]], [c3 * p3[1], -c3 * p3[0]]])
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_mesh::primitives;

    #[test]
    fn a_point_at_a_target_vertex_is_that_vertex() {
        // Every vertex of a bumpy disk, boundary ones included, given by its position:
        // whichever face the location picks, the landmark keeps the vertex (so a
        // boundary vertex stays on the boundary).
        let mut soup = primitives::disk(3);
        for p in &mut soup.positions {
            p.z = 0.2 * (3.0 * p.x).sin() * p.y;
        }
        let target = Mesh::from_soup(&soup).unwrap();
        let source = Mesh::from_soup(&primitives::disk(2)).unwrap();
        let index = SurfaceIndex::new(&target).unwrap();
        for v in target.vertices() {
            let marks = [Landmark {
                vertex: VertexId(0),
                position: Position::Spatial(target.position(v)),
            }];
            let resolved = resolve(&source, &target, &index, &marks).unwrap();
            assert_eq!(resolved[0].vertex, Some(v));
            assert_eq!(resolved[0].target.position(&target), target.position(v));
        }
        // A point inside a face stays a point.
        let f = target.faces().next().unwrap();
        let inside = [Landmark {
            vertex: VertexId(0),
            position: Position::Spatial(target.face_centroid(f)),
        }];
        assert_eq!(
            resolve(&source, &target, &index, &inside).unwrap()[0].vertex,
            None
        );
    }

    #[test]
    fn the_fitted_similarity_recovers_a_rotation_scale_and_shift() {
        let rotation = Rotation3::from_euler_angles(0.3, -1.1, 2.0).into_inner();
        let shift = Vector3::new(4.0, -2.0, 0.5);
        let from = [
            Point3::new(0.5, -11.3, 37.9),
            Point3::new(-16.8, -15.9, 11.5),
            Point3::new(19.7, -19.1, 10.2),
            Point3::new(1.0, 2.0, 3.0),
        ];
        let to: Vec<Point3<f64>> = from
            .iter()
            .map(|p| Point3::from(rotation * p.coords * 1.7 + shift))
            .collect();
        for n in [3, 4] {
            let fit = SpatialMatch::fitted(&from[..n], &to[..n]).unwrap();
            for (p, q) in from.iter().zip(&to) {
                assert!((fit.to_target(p) - q).norm() < 1e-9, "{n} points");
            }
        }
        let line = [
            Point3::origin(),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(2.0, 0.0, 0.0),
        ];
        assert!(SpatialMatch::fitted(&line, &line).is_none(), "collinear");
    }
}
