//! Per-corner texture coordinates: the UVs of a mesh with seams.

use beltrami_mesh::{FaceId, Mesh};

/// Texture coordinates given per face corner, as an OBJ file's `f v/t` lines hold them:
/// a vertex on a seam has one UV per chart it belongs to.
///
/// Conventions: `corners[f][k]` is the UV of the `k`-th vertex of face `f` in the
/// order of [`Mesh::face_vertices`]; a chart is counter-clockwise in the UV plane when
/// its faces are counter-clockwise seen from the side their normals point to.
#[derive(Debug, Clone, PartialEq)]
pub struct SeamedUv {
    /// The UV positions (`u` to the right, `v` up).
    pub uvs: Vec<[f64; 2]>,
    /// For each face, the index in [`SeamedUv::uvs`] of each corner's UV.
    pub corners: Vec<[u32; 3]>,
}

impl SeamedUv {
    /// The UVs of the corners of face `f`.
    pub fn face_uvs(&self, f: FaceId) -> [[f64; 2]; 3] {
        self.corners[f.idx()].map(|t| self.uvs[t as usize])
    }

    /// Twice the signed area of face `f` in the UV plane (positive counter-clockwise).
    pub fn signed_double_area(&self, f: FaceId) -> f64 {
        let [a, b, c] = self.face_uvs(f);
        beltrami_mesh::closed_curve::orient(a, b, c)
    }

    /// The seam edges of `mesh`: interior edges whose two faces give either endpoint
    /// different UV indices. Boundary edges of the mesh are not seams.
    pub fn seams(&self, mesh: &Mesh) -> Vec<beltrami_mesh::EdgeId> {
        mesh.edges()
            .filter(|&e| {
                let h = mesh.edge_halfedge(e);
                let t = mesh.twin(h);
                match (mesh.face(h), mesh.face(t)) {
                    (Some(f), Some(g)) => {
                        let uv_at = |face: FaceId, v| {
                            let k = mesh.face_vertices(face).position(|w| w == v);
                            k.map(|k| self.corners[face.idx()][k])
                        };
                        let (a, b) = (mesh.origin(h), mesh.target(h));
                        uv_at(f, a) != uv_at(g, a) || uv_at(f, b) != uv_at(g, b)
                    }
                    _ => false,
                }
            })
            .collect()
    }
}
