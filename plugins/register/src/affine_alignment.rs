//! The affine map that best places one surface onto another by closest points: the
//! iterative closest point method (Besl and McKay 1992) with an affine map per round
//! and the farthest pairs left out.
//!
//! From a starting placement `M_0` (a similarity), each round takes every sample's
//! closest point on the target, drops the pairs farther apart than [`TRIM`] median
//! distances (folds and parts the other shape lacks), and fits the affine map
//! minimizing `sum_i |M (a_i, 1) - b_i|^2` over the rest. Rounds go on while the mean
//! kept distance falls by at least a thousandth, and a fit is kept only while it
//! scales every direction within [`MAX_SHEAR`] of the similarity's scale and keeps the
//! orientation, so that closest points cannot flatten the source onto a part of the
//! target.

use beltrami_mesh::{Mesh, Point3, VertexId};
use beltrami_spatial::SurfaceIndex;
use nalgebra::{Matrix3, Matrix3x4, Matrix4, Matrix4x3, Vector4};

use crate::error::RegisterError;

/// Source vertices used to fit the alignment at most (evenly picked).
const FIT_SAMPLES: usize = 2048;

/// Rounds at most of a placement that is final (the spatial correspondence of a
/// registration without landmarks, the placed source whose arcs draw a cut graph).
pub(crate) const ROUNDS: usize = 30;

/// Pairs farther apart than this many times the median distance are left out of a fit.
const TRIM: f64 = 2.5;

/// A fit is kept only while its singular values stay within this factor of the
/// similarity's scale.
const MAX_SHEAR: f64 = 2.0;

/// Up to [`FIT_SAMPLES`] vertices of `mesh`, evenly picked by index.
pub(crate) fn spread_vertices(mesh: &Mesh) -> Vec<VertexId> {
    let step = mesh.vertex_count().div_ceil(FIT_SAMPLES).max(1);
    mesh.vertices().step_by(step).collect()
}

/// The affine map placing `samples` on the surface of `index`, refined from `start`
/// (module docs) in at most `rounds` rounds; `scale` is the starting similarity's
/// scale factor.
///
/// # Errors
/// [`RegisterError::Spatial`] when a closest point cannot be found.
pub(crate) fn closest_point_affine(
    samples: &[Point3<f64>],
    index: &SurfaceIndex<'_>,
    start: Matrix3x4<f64>,
    scale: f64,
    rounds: usize,
) -> Result<Matrix3x4<f64>, RegisterError> {
    let mut alignment = start;
    let mut best = f64::INFINITY;
    for _ in 0..rounds {
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
        match affine_fit(samples, &partners, &kept) {
            Some(next) if within_shear(&next, scale) => alignment = next,
            _ => break,
        }
    }
    Ok(alignment)
}

/// `M (p, 1)`.
pub(crate) fn apply(m: &Matrix3x4<f64>, p: &Point3<f64>) -> Point3<f64> {
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
