//! The source's shape matched on the target: a bijective non-rigid alignment.
//!
//! After the conformal registration `f` (a bijection, the landmarks exact):
//!
//! 1. the similarity that best carries the source's vertices onto their images
//!    (`SpatialMatch::fitted`, Umeyama 1991), refined by an affine closest-point fit,
//!    places the source in the target's frame;
//! 2. the placed source is deformed onto the target by the optimal-step non-rigid ICP
//!    of Amberg, Romdhani and Vetter (CVPR 2007; module `nonrigid_icp`): a template
//!    `T_i` per source vertex, near the target and smooth, but not a bijection;
//! 3. the three coordinates of `T_i` at the source's vertices and of `y_j` at the
//!    target's are matched as fields (module `feature_match`), both divided by the
//!    target's root-mean-square distance from its centroid: each image is pulled
//!    towards where the template lies on the target, the pull smoothed and made a
//!    Beltrami coefficient with `|mu| < 1`, so that the map stays a bijection.
//!
//! The distance reported is the mean over source vertices of `|T_i - f(x_i)|`, in the
//! target's units, before and after.

use beltrami_mesh::{Mesh, Point3, SurfacePoint, Vector3};
use beltrami_spatial::SurfaceIndex;
use nalgebra::{Matrix3, Matrix3x4, Matrix4, Matrix4x3, Vector4};

use crate::error::RegisterError;
use crate::feature_match::Channel;
use crate::landmarks::SpatialMatch;
use crate::nonrigid_icp::nonrigid_icp;

/// Source vertices used to fit the alignment at most (evenly picked).
const FIT_SAMPLES: usize = 2048;

/// Rounds of the affine closest-point fit at most.
const ICP_ROUNDS: usize = 30;

/// Pairs farther apart than this many times the median distance are left out of an
/// affine fit (folds and parts the other shape lacks).
const TRIM: f64 = 2.5;

/// An affine fit is kept only while its singular values stay within this factor of the
/// similarity's scale: the closest-point fit must not flatten the source.
const MAX_SHEAR: f64 = 2.0;

/// The source placed in the target's frame (an affine map, then the non-rigid ICP's
/// template) and its coordinate fields on both meshes.
pub(crate) struct Shape {
    /// The placed source, per source vertex.
    placed: Vec<Point3<f64>>,
    /// The target's root-mean-square distance from its centroid.
    scale: f64,
}

impl Shape {
    /// The placed source (module docs): the similarity that best carries the source's
    /// vertices onto their images `points` on `target`, refined by an affine
    /// closest-point fit (rounds of: each sampled source vertex's closest point on the
    /// target, pairs beyond `TRIM` median distances dropped, the least-squares affine
    /// map of the rest) while it lowers the trimmed mean distance, then deformed by the
    /// non-rigid ICP. `None` when the images do not fix a similarity (every image on a
    /// line).
    ///
    /// # Errors
    /// [`RegisterError::Spatial`] when a closest point cannot be found,
    /// [`RegisterError::Solve`] when a non-rigid ICP system cannot be solved.
    pub(crate) fn new(
        source: &Mesh,
        target: &Mesh,
        index: &SurfaceIndex<'_>,
        points: &[SurfacePoint],
    ) -> Result<Option<Self>, RegisterError> {
        let step = source.vertex_count().div_ceil(FIT_SAMPLES).max(1);
        let samples: Vec<Point3<f64>> = source
            .vertices()
            .step_by(step)
            .map(|v| source.position(v))
            .collect();
        let images: Vec<Point3<f64>> = source
            .vertices()
            .step_by(step)
            .map(|v| points[v.idx()].position(target))
            .collect();
        let Some(similarity) = SpatialMatch::fitted(&samples, &images) else {
            return Ok(None);
        };
        let mut alignment = similarity.as_affine();
        let mut best = f64::INFINITY;
        for _ in 0..ICP_ROUNDS {
            let moved: Vec<Point3<f64>> = samples.iter().map(|p| apply(&alignment, p)).collect();
            let closest = index.locate_all(&moved)?;
            let mut distances: Vec<f64> = closest.iter().map(|l| l.distance).collect();
            let median = median(&mut distances);
            let kept: Vec<bool> = closest
                .iter()
                .map(|l| l.distance <= TRIM * median)
                .collect();
            let count = kept.iter().filter(|&&k| k).count().max(1);
            let mean = closest
                .iter()
                .zip(&kept)
                .filter(|(_, k)| **k)
                .map(|(l, _)| l.distance)
                .sum::<f64>()
                / count as f64;
            if mean >= best * (1.0 - 1e-3) {
                break;
            }
            best = mean;
            let partners: Vec<Point3<f64>> = closest.iter().map(|l| l.position).collect();
            match affine_fit(&samples, &partners, &kept) {
                Some(next) if within_shear(&next, similarity.scale()) => alignment = next,
                _ => break,
            }
        }
        let (_, scale) = centroid_and_spread(target.positions());
        let affine: Vec<Point3<f64>> = source
            .positions()
            .iter()
            .map(|p| apply(&alignment, p))
            .collect();
        let placed = nonrigid_icp(source, index, &affine)?;
        Ok((scale > 0.0).then_some(Self { placed, scale }))
    }

    /// The three coordinate channels (module docs), per source vertex and per target
    /// vertex (the vertices of the target's chart).
    pub(crate) fn channels(&self, target: &Mesh) -> Vec<Channel> {
        (0..3)
            .map(|axis| Channel {
                source: self.placed.iter().map(|p| p[axis] / self.scale).collect(),
                target: target
                    .positions()
                    .iter()
                    .map(|p| p[axis] / self.scale)
                    .collect(),
                standardize: false,
            })
            .collect()
    }

    /// The mean distance from each aligned source vertex to its image.
    pub(crate) fn distance(&self, source: &Mesh, target: &Mesh, points: &[SurfacePoint]) -> f64 {
        let total: f64 = source
            .vertices()
            .map(|v| (self.placed[v.idx()] - points[v.idx()].position(target)).norm())
            .sum();
        total / source.vertex_count().max(1) as f64
    }
}

/// The mean of `points` and their root-mean-square distance from it (0 for none).
pub(crate) fn centroid_and_spread(points: &[Point3<f64>]) -> (Vector3<f64>, f64) {
    let n = points.len().max(1) as f64;
    let centroid = points.iter().map(|p| p.coords).sum::<Vector3<f64>>() / n;
    let spread = (points
        .iter()
        .map(|p| (p.coords - centroid).norm_squared())
        .sum::<f64>()
        / n)
        .sqrt();
    (centroid, spread)
}

/// Angle-weighted vertex normals of the source's faces over the positions `at`.
pub(crate) fn vertex_normals_at(source: &Mesh, at: &[Point3<f64>]) -> Vec<Vector3<f64>> {
    let mut sum = vec![Vector3::zeros(); source.vertex_count()];
    for f in source.faces() {
        let (vs, degree) = source.face_vertex_array(f);
        for k in 0..degree {
            let p = at[vs[k].idx()];
            let (a, b) = (
                at[vs[(k + 1) % degree].idx()] - p,
                at[vs[(k + degree - 1) % degree].idx()] - p,
            );
            let normal = a.cross(&b);
            let length = normal.norm();
            if length > 0.0 {
                sum[vs[k].idx()] += normal / length * a.angle(&b);
            }
        }
    }
    sum.into_iter()
        .map(|s| s.try_normalize(0.0).unwrap_or_default())
        .collect()
}

fn apply(m: &Matrix3x4<f64>, p: &Point3<f64>) -> Point3<f64> {
    Point3::from(m * Vector4::new(p.x, p.y, p.z, 1.0))
}

/// The median of `values` (reordered), 0 for none.
fn median(values: &mut [f64]) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    let middle = values.len() / 2;
    *values.select_nth_unstable_by(middle, f64::total_cmp).1
}

/// The affine map `M` minimizing `sum_i |M (a_i, 1) - b_i|^2` over the pairs marked
/// `kept` (normal equations, 4 x 4 Cholesky), `None` when they do not fix one.
fn affine_fit(from: &[Point3<f64>], to: &[Point3<f64>], kept: &[bool]) -> Option<Matrix3x4<f64>> {
    let mut normal = Matrix4::<f64>::zeros();
    let mut right = Matrix4x3::<f64>::zeros();
    for ((a, b), _) in from.iter().zip(to).zip(kept).filter(|(_, k)| **k) {
        let h = Vector4::new(a.x, a.y, a.z, 1.0);
        normal += h * h.transpose();
        right += h * b.coords.transpose();
    }
    let solved = normal.cholesky()?.solve(&right).transpose();
    solved.iter().all(|x| x.is_finite()).then_some(solved)
}

/// Whether the linear part of `m` scales every direction by `[scale / MAX_SHEAR, scale
/// MAX_SHEAR]` and keeps the orientation.
fn within_shear(m: &Matrix3x4<f64>, scale: f64) -> bool {
    let linear: Matrix3<f64> = m.fixed_view::<3, 3>(0, 0).into_owned();
    if linear.determinant() <= 0.0 {
        return false;
    }
    linear
        .singular_values()
        .iter()
        .all(|&s| s >= scale / MAX_SHEAR && s <= scale * MAX_SHEAR)
}

#[cfg(test)]
mod tests {
    use super::*;
    use beltrami_mesh::primitives;

    #[test]
    fn a_similar_copy_is_aligned_exactly() {
        // The target is the source turned, scaled by 2 and moved; the registration is
        // the identity of vertices, so the aligned source lies on the target and every
        // coordinate channel agrees at the images.
        let source = Mesh::from_soup(&primitives::icosphere(2)).unwrap();
        let mut soup = primitives::icosphere(2);
        let rotation = nalgebra::Rotation3::from_euler_angles(0.2, 0.9, -0.4);
        for p in &mut soup.positions {
            *p = Point3::from(rotation * p.coords * 2.0 + Vector3::new(1.0, -3.0, 0.5));
        }
        let target = Mesh::from_soup(&soup).unwrap();
        let points: Vec<SurfacePoint> = target
            .vertices()
            .map(|v| SurfacePoint::at_vertex(&target, v))
            .collect();
        let index = SurfaceIndex::new(&target).unwrap();
        let shape = Shape::new(&source, &target, &index, &points)
            .unwrap()
            .unwrap();
        assert!(shape.distance(&source, &target, &points) < 1e-9);
        let channels = shape.channels(&target);
        assert_eq!(channels.len(), 3);
        for channel in &channels {
            for v in source.vertices() {
                assert!((channel.source[v.idx()] - channel.target[v.idx()]).abs() < 1e-9);
            }
        }
    }
}
