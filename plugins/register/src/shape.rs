//! The source's shape matched on the target: a bijective non-rigid alignment.
//!
//! From the initial map (the common parameter domain's composition; the template is
//! fitted on the other core while the registration goes on) and the map `f` the match
//! starts from (the initial map itself, the landmarks exact):
//!
//! 1. the similarity that best carries the source's vertices onto their images under
//!    the initial map (`SpatialMatch::fitted`, Umeyama 1991), refined by an affine
//!    closest-point fit, places the source in the target's frame; a source in place
//!    ([`Placement::InPlace`], the register option `in-place`) is taken where it is;
//! 2. the placed source is deformed onto the target by the optimal-step non-rigid ICP
//!    of Amberg, Romdhani and Vetter (CVPR 2007; module `nonrigid_icp`): a template
//!    `T_i` per source vertex, near the target and smooth, but not a bijection (in
//!    place, with the schedule's supple end only: `IN_PLACE_SCHEDULE`);
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

use crate::affine_alignment::{apply, closest_point_affine, spread_vertices};
use crate::error::RegisterError;
use crate::feature_match::Channel;
use crate::landmarks::SpatialMatch;
use crate::nonrigid_icp::{
    ALIGNED_SCHEDULE, IN_PLACE_SCHEDULE, NormalEquations, Schedule, nonrigid_icp,
};

/// Rounds at most of the affine closest-point fit that places the source before the
/// non-rigid ICP. Where the two shapes differ (`g0_spot` onto its deformation) the fit
/// goes on sliding the source along the target by small steps for as long as it is let
/// (28 rounds of 30), which the non-rigid ICP's stiff levels, next, do better.
/// Registration by shape with at most 5, 10, 15 and 30 rounds: `g0_spot` 0.01405,
/// 0.01404, 0.01399 and 0.01413 from the truth; fsaverage5 pial onto white 1.368,
/// 1.345, 1.352 and 1.352 mm (white onto pial and the right hemisphere's pairs settle
/// within 10 rounds: the same figures from 10 on).
const PLACEMENT_ROUNDS: usize = 10;

/// Where the shape match takes the source from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Placement {
    /// Placed by the similarity of the initial map's images and an affine
    /// closest-point fit, then deformed with the whole stiffness schedule.
    Aligned,
    /// Taken where it is (both meshes in one frame, the source near its
    /// correspondence: two surfaces of one scan), deformed with the supple end of the
    /// schedule only.
    InPlace,
}

impl Placement {
    /// The non-rigid ICP's stiffness schedule of this placement.
    pub(crate) fn schedule(self) -> &'static Schedule {
        match self {
            Self::Aligned => &ALIGNED_SCHEDULE,
            Self::InPlace => &IN_PLACE_SCHEDULE,
        }
    }
}

/// The source placed in the target's frame (an affine map, then the non-rigid ICP's
/// template) and its coordinate fields on both meshes.
pub(crate) struct Shape {
    /// The placed source, per source vertex.
    placed: Vec<Point3<f64>>,
    /// The target's root-mean-square distance from its centroid.
    scale: f64,
}

impl Shape {
    /// The placed source (module docs): [`Placement::Aligned`], the similarity that
    /// best carries the source's vertices onto their images `points` on `target`,
    /// refined by an affine closest-point fit (rounds of: each sampled source vertex's
    /// closest point on the target, pairs beyond `TRIM` median distances dropped, the
    /// least-squares affine map of the rest) while it lowers the trimmed mean distance;
    /// [`Placement::InPlace`], the source as it is; then deformed by the non-rigid ICP
    /// (which asks `stopped` before each round; its rounds solved with `equations`, of
    /// `source`). `None` when the images do not fix a similarity (every image on a line)
    /// for an alignment.
    ///
    /// # Errors
    /// [`RegisterError::Spatial`] when a closest point cannot be found,
    /// [`RegisterError::Solve`] when a non-rigid ICP system cannot be solved,
    /// [`RegisterError::Stopped`] when `stopped` says so.
    pub(crate) fn new(
        source: &Mesh,
        target: &Mesh,
        index: &SurfaceIndex<'_>,
        equations: &mut NormalEquations,
        points: &[SurfacePoint],
        placement: Placement,
        stopped: &dyn Fn() -> bool,
    ) -> Result<Option<Self>, RegisterError> {
        let (_, scale) = centroid_and_spread(target.positions());
        if placement == Placement::InPlace {
            let placed = nonrigid_icp(
                source,
                equations,
                index,
                source.positions(),
                placement.schedule(),
                stopped,
            )?;
            return Ok((scale > 0.0).then_some(Self { placed, scale }));
        }
        let picked = spread_vertices(source);
        let samples: Vec<Point3<f64>> = picked.iter().map(|&v| source.position(v)).collect();
        let images: Vec<Point3<f64>> = picked
            .iter()
            .map(|&v| points[v.idx()].position(target))
            .collect();
        let Some(similarity) = SpatialMatch::fitted(&samples, &images) else {
            return Ok(None);
        };
        let alignment = closest_point_affine(
            &samples,
            index,
            similarity.as_affine(),
            similarity.scale(),
            PLACEMENT_ROUNDS,
        )?;
        let affine: Vec<Point3<f64>> = source
            .positions()
            .iter()
            .map(|p| apply(&alignment, p))
            .collect();
        let placed = nonrigid_icp(
            source,
            equations,
            index,
            &affine,
            placement.schedule(),
            stopped,
        )?;
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
        let shape = Shape::new(
            &source,
            &target,
            &index,
            &mut NormalEquations::new(&source, &ALIGNED_SCHEDULE).unwrap(),
            &points,
            Placement::Aligned,
            &|| false,
        )
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
