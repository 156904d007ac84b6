//! Shared parameterization pieces: Tutte embeddings with a fixed convex boundary, arc
//! length along boundary paths, and meshes with the connectivity of a mesh and the
//! parameter positions as vertices.

use beltrami_fem::{BoundaryMap, EdgeWeights, WeightError, WeightedMeanSystem};
use beltrami_mesh::{BuildOptions, Mesh, Point3, PolygonSoup, Repair, VertexId, parallel};
use beltrami_sparse::SolveOptions;
use num_complex::Complex64;

use crate::error::{RegisterError, Side};

/// `work` on the source and on the target at once, one per core ([`parallel::join`]):
/// the two results, the target's notes after the source's, and the source's error
/// before the target's, as if run one after the other.
pub(crate) fn each_mesh<T: Send>(
    source: &Mesh,
    target: &Mesh,
    notes: &mut Vec<String>,
    work: impl Fn(&Mesh, Side, &mut Vec<String>) -> Result<T, RegisterError> + Sync,
) -> Result<(T, T), RegisterError> {
    let mut target_notes = Vec::new();
    let (on_source, on_target) = parallel::join(
        || work(source, Side::Source, notes),
        || work(target, Side::Target, &mut target_notes),
    );
    let on_source = on_source?;
    notes.extend(target_notes);
    Ok((on_source, on_target?))
}

/// The Tutte weights used for a mesh: Floater's mean-value weights on triangle meshes
/// (positive, so the embedding onto a convex boundary is a bijection), uniform weights
/// when the mesh has quads (mean-value weights can be negative at reflex quad corners).
pub(crate) fn weights_for(mesh: &Mesh) -> Result<EdgeWeights, WeightError> {
    if mesh.quad_count() == 0 {
        EdgeWeights::mean_value(mesh)
    } else {
        Ok(EdgeWeights::uniform(mesh))
    }
}

/// The Tutte embedding of a disk mesh with the boundary values `boundary`: every other
/// vertex at the weighted mean of its neighbours ([`weights_for`]).
pub(crate) fn tutte(
    mesh: &Mesh,
    boundary: &BoundaryMap,
    side: Side,
) -> Result<Vec<Complex64>, RegisterError> {
    let weights = weights_for(mesh).map_err(|error| RegisterError::Weights { side, error })?;
    WeightedMeanSystem::new(&weights, boundary)
        .and_then(|system| system.solve(SolveOptions::default()))
        .map_err(|error| RegisterError::Solve { side, error })
}

/// The fraction of the total length at which each vertex of the closed path `vertices`
/// sits, starting with 0 at `vertices[0]` (the closing edge back to it included in the
/// total). Values are in `[0, 1)` and increasing.
pub(crate) fn arc_fractions(mesh: &Mesh, vertices: &[VertexId]) -> Vec<f64> {
    let mut closed = vertices.to_vec();
    if let Some(&first) = vertices.first() {
        closed.push(first);
    }
    let mut fractions = path_fractions(mesh, &closed);
    fractions.pop();
    fractions
}

/// The fraction of the total length at which each vertex of the open path `vertices`
/// sits: 0 at the first, 1 at the last (evenly spaced for a path of length 0).
pub(crate) fn path_fractions(mesh: &Mesh, vertices: &[VertexId]) -> Vec<f64> {
    let n = vertices.len();
    let mut cumulative = Vec::with_capacity(n);
    let mut total = 0.0;
    for k in 0..n {
        if k > 0 {
            total += (mesh.position(vertices[k]) - mesh.position(vertices[k - 1])).norm();
        }
        cumulative.push(total);
    }
    if total > 0.0 {
        cumulative.iter().map(|s| s / total).collect()
    } else {
        let last = n.saturating_sub(1).max(1) as f64;
        (0..n).map(|k| k as f64 / last).collect()
    }
}

/// A mesh with the faces of `mesh` (same ids, vertex order and first vertices) and the
/// vertex positions `positions`, e.g. a parameterization in the plane z = 0. Every area
/// is accepted: the connectivity is the validated one of `mesh`.
pub(crate) fn domain_mesh(
    mesh: &Mesh,
    positions: Vec<Point3<f64>>,
    side: Side,
) -> Result<Mesh, RegisterError> {
    let mut soup = PolygonSoup::new(positions);
    let mut buf = Vec::with_capacity(4);
    for f in mesh.faces() {
        buf.clear();
        buf.extend(mesh.face_vertices(f).map(|v| v.0));
        soup.push_face(&buf);
    }
    let options = BuildOptions {
        degenerate_area_tolerance: -1.0,
        repair: Repair::NONE,
    };
    Mesh::build(&soup, &options)
        .map(|(m, _)| m)
        .map_err(|error| RegisterError::Mesh { side, error })
}

/// Planar values as points in the plane z = 0.
pub(crate) fn planar_points(values: &[Complex64]) -> Vec<Point3<f64>> {
    values
        .iter()
        .map(|z| Point3::new(z.re, z.im, 0.0))
        .collect()
}

/// The input indices of the vertices of a path of `mesh`, for notes.
pub(crate) fn input_indices(mesh: &Mesh, vertices: &[VertexId]) -> Vec<usize> {
    vertices
        .iter()
        .map(|&v| mesh.vertex_map().to_input(v))
        .collect()
}
