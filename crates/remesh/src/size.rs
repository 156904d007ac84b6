//! The asked edge length per surface vertex ([`SizeField`]).

use beltrami_mesh::Mesh;

use crate::SizeField;

/// The asked edge length at every vertex of `mesh` for the asked length `edge_length`.
///
/// For [`SizeField::Curvature`], the normal curvature across an interior edge `e` with
/// dihedral angle `theta_e` (between the normals of its two faces) is taken as
/// `k_e = theta_e / d_e`, `d_e` the distance between the two face centroids (the
/// turning of the normal per unit length); a vertex takes the largest `k_e` of its
/// edges, and the mean `kbar` weighs vertices by their area (a third of each incident
/// triangle, a quarter of each quad). The chord of length `h` of a curve of curvature
/// `k` deviates from it by about `h^2 k / 8`, so `h = L sqrt(kbar / k)` keeps the
/// deviation of the asked length at the mean curvature everywhere, clamped to
/// `[L / 4, L]`.
pub fn vertex_sizes(mesh: &Mesh, field: SizeField, edge_length: f64) -> Vec<f64> {
    let n = mesh.vertex_count();
    if field == SizeField::Uniform {
        return vec![edge_length; n];
    }
    let mut curvature = vec![0.0f64; n];
    for e in mesh.edges() {
        let [Some(f), Some(g)] = mesh.edge_faces(e) else {
            continue;
        };
        let (nf, ng) = (mesh.face_normal(f), mesh.face_normal(g));
        let theta = nf.cross(&ng).norm().atan2(nf.dot(&ng));
        let d = (mesh.face_centroid(f) - mesh.face_centroid(g)).norm();
        if d > 0.0 {
            for v in mesh.edge_vertices(e) {
                curvature[v.idx()] = curvature[v.idx()].max(theta / d);
            }
        }
    }
    let mut area = vec![0.0f64; n];
    for f in mesh.faces() {
        let share = mesh.face_area(f) / mesh.face_degree(f) as f64;
        for v in mesh.face_vertices(f) {
            area[v.idx()] += share;
        }
    }
    let total: f64 = area.iter().sum();
    let mean = curvature.iter().zip(&area).map(|(k, a)| k * a).sum::<f64>() / total;
    curvature
        .iter()
        .map(|&k| {
            if k > 0.0 && mean > 0.0 {
                (edge_length * (mean / k).sqrt()).clamp(edge_length / 4.0, edge_length)
            } else {
                edge_length
            }
        })
        .collect()
}
