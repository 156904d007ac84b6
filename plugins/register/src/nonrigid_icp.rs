//! The optimal-step non-rigid ICP of Amberg, Romdhani and Vetter (CVPR 2007): the
//! placed source deformed onto the target by one affine map per vertex.
//!
//! With `h_i = (v_i, 1)` a source vertex in homogeneous coordinates and `X_i` its 4 x 3
//! affine map (so the vertex moves to `h_i^T X_i`), each round minimizes
//!
//! `E(X) = alpha^2 sum_{edges ij} |G (X_i - X_j)|_F^2 + sum_i w_i^2 |h_i^T X_i - u_i|^2`
//!
//! (their eq. 2-4 without landmarks, `G = diag(1, 1, 1, gamma)` with `gamma = 1`), `u_i`
//! the closest point of the target to the vertex's current image and `w_i` 1, or 0 for a
//! pair whose normals differ by more than 60 degrees (a closest point across a thin
//! fold; far pairs are kept: the stiffness carries them, and leaving them out measured
//! worse, 0.015 -> 0.021 on `g0_spot` at 2.5 median distances). Its normal
//! equations `(alpha^2 L (x) G^2 + blockdiag(w_i^2 h_i h_i^T)) X = blockdiag(w_i^2 h_i)
//! U` (`L` the graph Laplacian of the source's edges) are one sparse symmetric positive
//! definite system of `4n` unknowns with three right-hand sides, of one pattern for
//! every round (the symbolic Cholesky factorization is done once). The stiffness `alpha`
//! falls over the rounds (`STIFFNESS`, times `sqrt(n)` so that a schedule means the same
//! smoothness at any resolution), each held until the maps change little.
//!
//! Positions are taken relative to the placed source's centroid and divided by its
//! root-mean-square radius, so that `gamma = 1` weighs the translations like the linear
//! parts.

use beltrami_mesh::{Mesh, Point3, Vector3};
use beltrami_sparse::{SolveError, SolveOptions, SpdSolver};
use beltrami_spatial::SurfaceIndex;
use faer::Mat;
use faer::sparse::{CreationError, FaerError, SparseColMat, Triplet};

use crate::error::{RegisterError, Side};
use crate::shape::{centroid_and_spread, vertex_normals_at};

/// The stiffness schedule, per `sqrt(n)` (module docs), stiff to supple.
const STIFFNESS: [f64; 6] = [1.0, 0.5, 0.25, 0.12, 0.06, 0.03];

/// Rounds per stiffness at most.
const ROUNDS: usize = 10;

/// A stiffness ends when no vertex's map moves a point of the unit-radius source by
/// more than this.
const SETTLED: f64 = 1e-3;

/// A pair is used only where the normals agree to this cosine (60 degrees).
const NORMAL_AGREEMENT: f64 = 0.5;

/// The placed source `placed` (per source vertex) deformed onto the target of `index`
/// (module docs).
///
/// # Errors
/// [`RegisterError::Spatial`] when a closest point cannot be found, and
/// [`RegisterError::Solve`] when a round's system cannot be solved.
pub(crate) fn nonrigid_icp(
    source: &Mesh,
    index: &SurfaceIndex<'_>,
    placed: &[Point3<f64>],
) -> Result<Vec<Point3<f64>>, RegisterError> {
    let n = source.vertex_count();
    let (centre, radius) = centroid_and_spread(placed);
    if radius.is_nan() || radius <= 0.0 {
        return Ok(placed.to_vec());
    }
    let to_unit = |p: &Point3<f64>| (p.coords - centre) / radius;
    let from_unit = |x: &Vector3<f64>| Point3::from(x * radius + centre);
    let homogeneous: Vec<[f64; 4]> = placed
        .iter()
        .map(|p| {
            let x = to_unit(p);
            [x.x, x.y, x.z, 1.0]
        })
        .collect();
    let edges: Vec<(usize, usize)> = source
        .edges()
        .map(|e| {
            let [a, b] = source.edge_vertices(e);
            (a.idx(), b.idx())
        })
        .collect();
    let mut degree = vec![0.0; n];
    for &(a, b) in &edges {
        degree[a] += 1.0;
        degree[b] += 1.0;
    }
    let target = index.mesh();
    let solve_error = |error| RegisterError::Solve {
        side: Side::Source,
        error,
    };
    let mut images: Vec<Vector3<f64>> = placed.iter().map(to_unit).collect();
    let mut solver: Option<SpdSolver<f64>> = None;
    for stiffness in STIFFNESS {
        let alpha2 = (stiffness * stiffness) * n as f64;
        for _ in 0..ROUNDS {
            let positions: Vec<Point3<f64>> = images.iter().map(from_unit).collect();
            let closest = index.locate_all(&positions)?;
            let normals = vertex_normals_at(source, &positions);
            let weights: Vec<f64> = closest
                .iter()
                .zip(&normals)
                .map(|(l, normal)| {
                    if target.face_normal(l.point.face).dot(normal) >= NORMAL_AGREEMENT {
                        1.0
                    } else {
                        0.0
                    }
                })
                .collect();
            // Every block's 16 entries are written, zero weights too, so that the
            // pattern is that of every round.
            let mut triplets = Vec::with_capacity(16 * (n + 2 * edges.len()));
            for (i, h) in homogeneous.iter().enumerate() {
                for r in 0..4 {
                    for c in 0..4 {
                        let stiff = if r == c { alpha2 * degree[i] } else { 0.0 };
                        triplets.push(Triplet::new(
                            4 * i + r,
                            4 * i + c,
                            stiff + weights[i] * h[r] * h[c],
                        ));
                    }
                }
            }
            for &(a, b) in &edges {
                for r in 0..4 {
                    for c in 0..4 {
                        let value = if r == c { -alpha2 } else { 0.0 };
                        triplets.push(Triplet::new(4 * a + r, 4 * b + c, value));
                        triplets.push(Triplet::new(4 * b + r, 4 * a + c, value));
                    }
                }
            }
            let matrix =
                SparseColMat::try_new_from_triplets(4 * n, 4 * n, &triplets).map_err(|e| {
                    solve_error(SolveError::Faer(match e {
                        CreationError::Generic(e) => e,
                        // Indices are below 4n by construction.
                        CreationError::OutOfBounds { .. } => FaerError::IndexOverflow,
                    }))
                })?;
            let mut rhs = Mat::<f64>::zeros(4 * n, 3);
            for (i, h) in homogeneous.iter().enumerate() {
                if weights[i] == 0.0 {
                    continue;
                }
                let u = to_unit(&closest[i].position);
                for r in 0..4 {
                    for c in 0..3 {
                        rhs[(4 * i + r, c)] += weights[i] * h[r] * u[c];
                    }
                }
            }
            let spd = match &mut solver {
                Some(spd) => spd,
                None => solver.insert(
                    SpdSolver::new(matrix.symbolic(), SolveOptions::default())
                        .map_err(solve_error)?,
                ),
            };
            spd.factorize(matrix.as_ref()).map_err(solve_error)?;
            spd.solve_in_place(rhs.as_mut()).map_err(solve_error)?;
            let mut moved: f64 = 0.0;
            for (i, h) in homogeneous.iter().enumerate() {
                let image =
                    Vector3::from_fn(|c, _| (0..4).map(|r| h[r] * rhs[(4 * i + r, c)]).sum());
                moved = moved.max((image - images[i]).norm());
                images[i] = image;
            }
            if moved < SETTLED {
                break;
            }
        }
    }
    Ok(images.iter().map(from_unit).collect())
}

#[cfg(test)]
#[path = "../tests/fixtures/blob.rs"]
mod fixtures;

#[cfg(test)]
mod tests {
    use super::*;
    use fixtures::{blob_pair, deform};

    #[test]
    fn a_deformed_blob_is_followed_to_its_deformation() {
        // The blob onto a finer mesh of it under `deform`: the source where it is lies
        // 0.155 from the truth on average, the template 0.031.
        let (source, target) = blob_pair(3);
        let index = SurfaceIndex::new(&target).unwrap();
        let truth: Vec<Point3<f64>> = source.positions().iter().map(deform).collect();
        let error = |at: &[Point3<f64>]| {
            at.iter()
                .zip(&truth)
                .map(|(a, b)| (a - b).norm())
                .sum::<f64>()
                / at.len() as f64
        };
        let start = error(source.positions());
        let template = nonrigid_icp(&source, &index, source.positions()).unwrap();
        let end = error(&template);
        eprintln!("deformed blob: the template {start:.4} -> {end:.4} from the truth");
        assert!(
            end < 0.3 * start,
            "mean distance to the truth {start} -> {end}"
        );
    }
}
