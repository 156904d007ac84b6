//! [`Mesh::punctured`]: a mesh with one face taken out, for parameterizations of closed
//! surfaces through a chart that misses that face (a stereographic projection from it,
//! a Tutte embedding with its corners as the boundary).

use crate::{BuildOptions, FaceId, Mesh, MeshError, PolygonSoup, Repair};

impl Mesh {
    /// This mesh without face `removed`: the other faces in order (face `f` becomes
    /// `f - 1` past `removed`) over the same positions. A closed genus-0 surface becomes
    /// a disk whose boundary is the removed face's loop.
    ///
    /// Vertex ids are kept when every vertex has a face besides `removed` (always on a
    /// closed manifold surface); a vertex of that face alone is dropped, which the
    /// result's [`Mesh::vertex_map`] shows (it is the identity exactly when ids are
    /// kept). Faces are accepted whatever their area: they were checked when this mesh
    /// was built.
    ///
    /// # Errors
    /// The [`MeshError`] of building the rest (a mesh that is non-manifold without the
    /// face, which a valid mesh never is).
    pub fn punctured(&self, removed: FaceId) -> Result<Mesh, MeshError> {
        let mut soup = PolygonSoup::new(self.positions().to_vec());
        soup.reserve(self.face_count().saturating_sub(1), 4 * self.face_count());
        let mut corners = Vec::with_capacity(4);
        for f in self.faces().filter(|&f| f != removed) {
            corners.clear();
            corners.extend(self.face_vertices(f).map(|v| v.0));
            soup.push_face(&corners);
        }
        let options = BuildOptions {
            degenerate_area_tolerance: -1.0,
            repair: Repair::NONE,
        };
        Mesh::build(&soup, &options).map(|(mesh, _)| mesh)
    }
}

#[cfg(test)]
mod tests {
    use crate::primitives::{Cells, grid, icosphere};
    use crate::{FaceId, Mesh};

    #[test]
    fn a_punctured_sphere_is_a_disk_with_the_same_vertices() {
        let sphere = Mesh::from_soup(&icosphere(2)).unwrap();
        let disk = sphere.punctured(FaceId(7)).unwrap();
        assert!(disk.vertex_map().is_identity());
        assert_eq!(disk.vertex_count(), sphere.vertex_count());
        assert_eq!(disk.face_count(), sphere.face_count() - 1);
        assert_eq!(disk.boundary_loop_count(), 1);
        let removed: Vec<_> = sphere.face_vertices(FaceId(7)).collect();
        assert!(removed.iter().all(|&v| disk.is_boundary_vertex(v)));
        assert_eq!(
            disk.face_vertices(FaceId(7)).collect::<Vec<_>>(),
            sphere.face_vertices(FaceId(8)).collect::<Vec<_>>()
        );
    }

    #[test]
    fn a_corner_of_the_removed_face_alone_is_dropped() {
        // The square's corner (1, 0) lies on face 2 alone (its cell's other triangle
        // misses it): without that face the vertex is gone.
        let square = Mesh::from_soup(&grid(2, 2, Cells::Triangles)).unwrap();
        let rest = square.punctured(FaceId(2)).unwrap();
        assert!(!rest.vertex_map().is_identity());
        assert_eq!(rest.vertex_count(), square.vertex_count() - 1);
    }
}
