//! The composition: each source vertex's image in the common parameter domain is
//! located in the target's parameterization, and the face and coordinates found there are
//! the surface point on the target.
//!
//! The target's parameterization is a mesh with the target's faces (same ids, vertex
//! order and first vertex; for a torus the faces of the cut target) and the parameter
//! positions as vertices: z = 0 in the plane, the unit-sphere positions for genus 0.
//! A point located in face `f` of that mesh with coordinates `c` is the point of target
//! face `f` with the same coordinates, since the parameterization is affine on each
//! triangle (bilinear on each quad).
//!
//! In the plane the source's images lie inside the target's domain by construction, so
//! the exact closest point of [`SurfaceIndex`] is the containing face at distance 0. On
//! the sphere the target's parameter mesh is a polyhedron inscribed in the sphere and
//! the source's images lie on the sphere, slightly outside it; they are located along
//! the ray from the centre ([`radial`]), a bijection between the sphere and a
//! polyhedron that is star-shaped about the origin, instead of by the closest point,
//! which is not injective near edges.

use beltrami_fem::distortion::measure_surface;
use beltrami_fem::{DistortionStats, ReferenceNormal};
use beltrami_mesh::{FaceId, Mesh, Point3, SurfacePoint, Vector3};
use beltrami_spatial::SurfaceIndex;

use crate::error::RegisterError;

/// Barycentric coordinates this far below zero still count as inside a triangle (and are
/// clamped to zero).
const INSIDE_TOLERANCE: f64 = 1e-12;

/// Faces a radial walk crosses at most before falling back to the closest point.
const MAX_WALK: usize = 256;

/// Locates `points` in the parameter mesh `domain` (exact closest points) and returns
/// them as surface points of the mesh with the same faces, together with the largest
/// distance from a point to the domain (0 when every point is inside it).
pub(crate) fn locate(
    domain: &Mesh,
    points: &[Point3<f64>],
) -> Result<(Vec<SurfacePoint>, f64), RegisterError> {
    let index = SurfaceIndex::new(domain)?;
    let located = index.locate_all(points)?;
    let gap = located.iter().map(|l| l.distance).fold(0.0, f64::max);
    Ok((located.into_iter().map(|l| l.point).collect(), gap))
}

/// Locates points of the unit sphere in the inscribed polyhedron indexed by `index`
/// along rays from the origin: the closest point gives a start face, from which a walk
/// crosses the edge opposite the most negative coordinate until all of the ray's
/// barycentric coordinates are non-negative. Quads (no planar face to intersect) and
/// walks that do not end keep the closest point. Returns the points and how many fell
/// back.
pub(crate) fn locate_radial(
    index: &SurfaceIndex<'_>,
    points: &[Point3<f64>],
) -> Result<(Vec<SurfacePoint>, usize), RegisterError> {
    let domain = index.mesh();
    let located = index.locate_all(points)?;
    let mut fallbacks = 0;
    let out = points
        .iter()
        .zip(located)
        .map(|(p, l)| {
            radial(domain, &p.coords, l.point.face).unwrap_or_else(|| {
                fallbacks += 1;
                l.point
            })
        })
        .collect();
    Ok((out, fallbacks))
}

/// The point where the ray from the origin through `direction` meets the triangles of
/// `domain`, walking from face `start` (module docs). The ray meets triangle `(a, b, c)`
/// at `t p = l_0 a + l_1 b + l_2 c` with `l_0 : l_1 : l_2 = p.(b x c) : p.(c x a) :
/// p.(a x b)`, whose sum `2 p.n` (`n` the vector area) is positive on a face turned
/// towards `p`.
fn radial(domain: &Mesh, direction: &Vector3<f64>, start: FaceId) -> Option<SurfacePoint> {
    let mut face = start;
    for _ in 0..MAX_WALK {
        let (vertices, degree) = domain.face_vertex_array(face);
        if degree != 3 {
            return None;
        }
        let [a, b, c] = [0, 1, 2].map(|k| domain.position(vertices[k]).coords);
        let l = [
            direction.dot(&b.cross(&c)),
            direction.dot(&c.cross(&a)),
            direction.dot(&a.cross(&b)),
        ];
        let sum = l[0] + l[1] + l[2];
        if sum.is_nan() || sum <= 0.0 {
            return None;
        }
        let w = l.map(|x| x / sum);
        let (k, &lowest) = w.iter().enumerate().min_by(|x, y| x.1.total_cmp(y.1))?;
        if lowest >= -INSIDE_TOLERANCE {
            let w = w.map(|x| x.max(0.0));
            let total = w[0] + w[1] + w[2];
            return Some(SurfacePoint::in_triangle(face, w.map(|x| x / total)));
        }
        // The edge opposite corner k leaves corner k + 1.
        let h = domain.face_halfedges(face).nth((k + 1) % 3)?;
        face = domain.face(domain.twin(h))?;
    }
    None
}

/// The distortion of the map on the target (`|mu|` statistics and flipped faces): the map measured
/// by `beltrami_fem::distortion::measure_surface` with the target's normals at the
/// images as the reference ([`SurfaceIndex::face_reference_normals`]: per face, the sum
/// of the target's interpolated vertex normals at the images of its corners). A face is
/// flipped where the image's area element at one of its quadrature points has a
/// non-positive component along that normal (the fem kernel
/// `beltrami_fem::beltrami::image_derivatives`): a triangle by its image triangle, a
/// quad by its four Gauss points (not by its four corner triangles). A collapsed image
/// counts as flipped. `beltrami distortion SOURCE OUT --target TARGET` counts the same.
pub(crate) fn distortion(
    source: &Mesh,
    target_index: &SurfaceIndex<'_>,
    points: &[SurfacePoint],
    positions: &[Point3<f64>],
) -> Result<DistortionStats, RegisterError> {
    let normals = target_index.face_reference_normals(source, points)?;
    let measured = measure_surface(source, positions, ReferenceNormal::PerFace(&normals))?;
    Ok(measured.stats)
}

/// The map's [`distortion`] and the source faces whose image is flipped against the
/// target's normals (its rule), each with the largest angle in degrees between the
/// target's face normals at its corners' images: near 180 when the face's corners land
/// on the two sides of a fold of the target that is finer than the source face.
pub(crate) fn flipped_faces(
    source: &Mesh,
    target_index: &SurfaceIndex<'_>,
    points: &[SurfacePoint],
    positions: &[Point3<f64>],
) -> Result<(DistortionStats, Vec<(FaceId, f64)>), RegisterError> {
    let normals = target_index.face_reference_normals(source, points)?;
    let measured = measure_surface(source, positions, ReferenceNormal::PerFace(&normals))?;
    let target = target_index.mesh();
    let flipped = source
        .faces()
        .zip(&measured.flipped)
        .filter(|&(_, &flipped)| flipped)
        .map(|(f, _)| {
            let corners: Vec<_> = source
                .face_vertices(f)
                .map(|v| target.face_normal(points[v.idx()].face))
                .collect();
            let mut widest: f64 = 0.0;
            for (i, a) in corners.iter().enumerate() {
                for b in &corners[i + 1..] {
                    widest = widest.max(a.angle(b).to_degrees());
                }
            }
            (f, widest)
        })
        .collect();
    Ok((measured.stats, flipped))
}
