//! Whether a flat disk overlaps itself: its folded faces.
//!
//! A map of a disk whose faces all keep their orientation is one-to-one exactly when its
//! boundary curve is simple (the degree of the map at a point is the winding number of
//! the boundary about it). So a chart is checked in two steps: every face's signed area
//! is positive (here), and no two boundary segments that are not neighbours along the
//! curve meet ([`beltrami_mesh::closed_curve::crosses_itself`]; touching counts: two
//! surface points would share a texel).

use beltrami_mesh::Mesh;
use beltrami_mesh::closed_curve::orient;

/// The faces of `mesh` whose image under the flat positions `uv` (per vertex) has a
/// non-positive (or undefined) signed area.
pub fn folded_faces(mesh: &Mesh, uv: &[[f64; 2]]) -> usize {
    mesh.faces()
        .filter(|&f| {
            let (v, _) = mesh.face_vertex_array(f);
            let area2 = orient(uv[v[0].idx()], uv[v[1].idx()], uv[v[2].idx()]);
            area2 <= 0.0 || area2.is_nan()
        })
        .count()
}
