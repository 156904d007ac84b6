//! Uniform 1-to-4 refinement without smoothing, for refinement studies and benchmarks.

use nalgebra::Point3;

use crate::{Mesh, PolygonSoup};

/// Splits every face into four: a triangle by its edge midpoints, a quad by its edge
/// midpoints and its centroid. New vertices stay on the old faces (no smoothing), so the
/// geometry is unchanged and each level halves the mesh size `h`.
///
/// Numbering: the old vertices keep their mesh ids; then one vertex per edge (edge id
/// order), then one per quad (face order). Each new face keeps the orientation of its
/// parent, and the children of face `f` are faces `4f .. 4f + 3`.
pub fn subdivide(mesh: &Mesh) -> PolygonSoup {
    let nv = mesh.vertex_count();
    let ne = mesh.edge_count();
    let mut positions: Vec<Point3<f64>> = mesh.positions().to_vec();
    positions.reserve(ne + mesh.face_count());
    for e in mesh.edges() {
        let [a, b] = mesh.edge_vertices(e);
        positions.push(nalgebra::center(&mesh.position(a), &mesh.position(b)));
    }
    let mut soup = PolygonSoup::new(Vec::new());
    soup.reserve(4 * mesh.face_count(), 16 * mesh.face_count());
    let mid = |h| (nv + mesh.edge(h).idx()) as u32;
    for f in mesh.faces() {
        let hs: Vec<_> = mesh.face_halfedges(f).collect();
        let v: Vec<u32> = hs.iter().map(|&h| mesh.origin(h).0).collect();
        // m[k] is the midpoint of the side from vertex k to vertex k + 1.
        let m: Vec<u32> = hs.iter().map(|&h| mid(h)).collect();
        if v.len() == 3 {
            soup.push_face(&[v[0], m[0], m[2]]);
            soup.push_face(&[m[0], v[1], m[1]]);
            soup.push_face(&[m[2], m[1], v[2]]);
            soup.push_face(&[m[0], m[1], m[2]]);
        } else {
            let c = positions.len() as u32;
            positions.push(mesh.face_centroid(f));
            soup.push_face(&[v[0], m[0], c, m[3]]);
            soup.push_face(&[m[0], v[1], m[1], c]);
            soup.push_face(&[c, m[1], v[2], m[2]]);
            soup.push_face(&[m[3], c, m[2], v[3]]);
        }
    }
    soup.positions = positions;
    soup
}
