//! Removal of the flipped faces a linear map onto the sphere leaves: each is re-solved
//! locally, in a patch around it, as a Tutte embedding with positive weights.
//!
//! Cotangent weights are negative across edges opposite obtuse angles, so a harmonic
//! map may fold a few faces (module docs of [`super::conformal`]); the projection and
//! the centering may also turn a very obtuse face's flat image inward (module docs of
//! [`super`]). For a flipped face `f`, the patch `P_k` is the set of vertices within
//! `k - 1` edges of `f`'s vertices; the sphere is rotated so that `f`'s image is at the
//! south pole and the vertices of `P_k` are solved in the chart `w = (x + i y) / (1 - z)`
//! with every other vertex held, and the positive weights `max(w_ij, delta)`
//! (`delta` a small share of the mean positive cotangent weight). By Tutte's theorem
//! as extended by M. S. Floater ("One-to-one piecewise linear mappings over
//! triangulations", Math. Comp. 72, 2003) positive weights map the patch one-to-one
//! when the held ring around it is a convex polygon in the chart; near a flip the map
//! is close to conformal, so a ring of a few edges is nearly a circle. Where the ring is
//! not convex enough the face may stay flipped: then `k` grows, up to [`MAX_RINGS`], and
//! the faces still flipped are counted and reported.

use beltrami_fem::EdgeWeights;
use beltrami_mesh::{FaceId, Mesh, Point3, Vector3, VertexId};
use beltrami_sparse::{SolveError, SolveOptions};
use nalgebra::Rotation3;

use super::conformal::{Chart, ChartSystem};
use super::{is_inward, radial_direction};

/// The patches grow to at most this many rings of edges around a flipped face.
pub(super) const MAX_RINGS: usize = 8;

/// The floor `delta` of the weights is this share of the mean positive weight.
const FLOOR_SHARE: f64 = 1e-2;

/// How the untangling went.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Untangled {
    /// Flipped faces before.
    pub flipped: usize,
    /// Patches solved.
    pub patches: usize,
    /// The most rings of a patch solved.
    pub rings: usize,
    /// Faces still flipped after.
    pub remaining: usize,
}

/// Re-solves a patch around every flipped face (module docs) until none is left or the
/// patches reach [`MAX_RINGS`]. `image` holds unit vectors and stays so.
pub(super) fn untangle(
    mesh: &Mesh,
    weights: &EdgeWeights,
    image: &mut [Point3<f64>],
    options: SolveOptions,
) -> Result<Untangled, SolveError> {
    // Each patch solve moves its neighbours' images, so the outcome depends on the
    // order: taken by input index, it does not depend on how the mesh was numbered
    // (a registration renumbers scattered meshes).
    let flipped = |image: &[Point3<f64>]| -> Vec<FaceId> {
        let mut faces: Vec<FaceId> = mesh
            .faces()
            .filter(|&f| is_inward(mesh, image, f))
            .collect();
        faces.sort_by_key(|&f| mesh.face_to_input(f));
        faces
    };
    let mut result = Untangled::default();
    let mut remaining = flipped(image);
    result.flipped = remaining.len();
    if remaining.is_empty() {
        return Ok(result);
    }
    let floor = FLOOR_SHARE * mean_positive_weight(mesh, weights);
    for rings in 1..=MAX_RINGS {
        for &f in &remaining {
            if !is_inward(mesh, image, f) {
                continue;
            }
            let free = patch(mesh, f, rings);
            let axis = radial_direction(mesh, image, f);
            let rotation =
                Rotation3::rotation_between(&axis, &-Vector3::z()).unwrap_or_else(|| {
                    Rotation3::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
                });
            let mut system = ChartSystem::new(weights, floor, |v| free[v.idx()], None, options)?;
            let Some(solved) = system.solve(weights, |v| {
                Chart::South.coordinate(&(rotation * image[v.idx()]))
            })?
            else {
                continue;
            };
            for (&v, &w) in system.free().iter().zip(&solved) {
                image[v.idx()] = rotation.inverse() * Chart::South.point(w);
            }
            result.patches += 1;
            result.rings = rings;
        }
        remaining = flipped(image);
        if remaining.is_empty() {
            break;
        }
    }
    result.remaining = remaining.len();
    Ok(result)
}

/// Per vertex: within `rings - 1` edges of a vertex of `f`.
fn patch(mesh: &Mesh, f: FaceId, rings: usize) -> Vec<bool> {
    let mut inside = vec![false; mesh.vertex_count()];
    let mut front: Vec<VertexId> = mesh.face_vertices(f).collect();
    for &v in &front {
        inside[v.idx()] = true;
    }
    for _ in 1..rings {
        let mut next = Vec::new();
        for &v in &front {
            for u in mesh.vertex_neighbors(v) {
                if !inside[u.idx()] {
                    inside[u.idx()] = true;
                    next.push(u);
                }
            }
        }
        front = next;
    }
    inside
}

/// The mean of the positive weights (1 if there are none).
fn mean_positive_weight(mesh: &Mesh, weights: &EdgeWeights) -> f64 {
    let (sum, count) = mesh
        .vertices()
        .flat_map(|v| weights.row(v))
        .filter(|&(_, w)| w > 0.0)
        .fold((0.0, 0usize), |(s, n), (_, w)| (s + w, n + 1));
    if count > 0 { sum / count as f64 } else { 1.0 }
}
