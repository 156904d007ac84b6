//! Renumbering a mesh so that neighbouring elements are near each other in memory.
//!
//! Solvers loop over faces and gather and scatter values of the faces' vertices (element
//! assembly, image faces, walks on a target). When a file lists its vertices in
//! scattered order, nearly every such access misses the cache: the shared `g0_koala`
//! has a median distance of 20461 between the largest and smallest vertex index of a
//! face, of 49999 vertices; numbered breadth-first, 375. A registration of it onto a
//! 100K-face remesh then takes a third less time per flow step (0.47 -> 0.30-0.33 s,
//! docs/register.md), its sphere map a quarter less.
//!
//! [`renumber_breadth_first`] numbers the vertices of each component in the order a
//! breadth-first search from its lowest-numbered vertex reaches them (Cuthill-McKee
//! without the degree sort), and the faces by their lowest new vertex index (ties in
//! the old order), and builds the renumbered mesh: every face keeps its corner order and
//! its first corner, so face frames and the barycentric coordinates of surface points
//! carry over unchanged, and the input maps are composed, so that
//! [`VertexMap::to_input`](crate::VertexMap::to_input) and [`Mesh::face_to_input`] still
//! name the file's indices in messages and written files. Solvers use it through
//! `beltrami_core::solve_renumbered`.

use std::collections::VecDeque;

use crate::{BuildOptions, FaceId, Mesh, MeshError, PolygonSoup, VertexId};

/// A new numbering of a mesh's vertices and faces, both ways.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Renumbering {
    /// `old_vertex[new]`.
    old_vertex: Vec<VertexId>,
    /// `new_vertex[old]`.
    new_vertex: Vec<VertexId>,
    /// `old_face[new]`.
    old_face: Vec<FaceId>,
    /// `new_face[old]`.
    new_face: Vec<FaceId>,
}

/// `mesh` renumbered breadth-first, and the numbering (module docs).
///
/// Errors: none for a mesh built by this crate; the rebuild's [`MeshError`] is passed
/// on.
pub fn renumber_breadth_first(mesh: &Mesh) -> Result<(Mesh, Renumbering), MeshError> {
    let numbering = Renumbering::breadth_first(mesh);
    let renumbered = numbering.apply(mesh)?;
    Ok((renumbered, numbering))
}

impl Renumbering {
    /// The breadth-first numbering of `mesh` (module docs).
    fn breadth_first(mesh: &Mesh) -> Self {
        let n = mesh.vertex_count();
        let mut new_vertex = vec![VertexId(u32::MAX); n];
        let mut old_vertex = Vec::with_capacity(n);
        let mut queue = VecDeque::new();
        for start in mesh.vertices() {
            if new_vertex[start.idx()].0 != u32::MAX {
                continue;
            }
            new_vertex[start.idx()] = VertexId(old_vertex.len() as u32);
            old_vertex.push(start);
            queue.push_back(start);
            while let Some(v) = queue.pop_front() {
                for w in mesh.vertex_neighbors(v) {
                    if new_vertex[w.idx()].0 == u32::MAX {
                        new_vertex[w.idx()] = VertexId(old_vertex.len() as u32);
                        old_vertex.push(w);
                        queue.push_back(w);
                    }
                }
            }
        }
        let lowest = |f: FaceId| {
            mesh.face_vertices(f)
                .map(|v| new_vertex[v.idx()].0)
                .min()
                .unwrap_or(0)
        };
        let mut old_face: Vec<FaceId> = mesh.faces().collect();
        // A stable sort keeps the old order among faces of the same lowest vertex.
        old_face.sort_by_key(|&f| lowest(f));
        let mut new_face = vec![FaceId(0); old_face.len()];
        for (new, &old) in old_face.iter().enumerate() {
            new_face[old.idx()] = FaceId(new as u32);
        }
        Self {
            old_vertex,
            new_vertex,
            old_face,
            new_face,
        }
    }

    /// `mesh`, for which this numbering was made, with its vertices and faces in it.
    fn apply(&self, mesh: &Mesh) -> Result<Mesh, MeshError> {
        let positions = self.old_vertex.iter().map(|&v| mesh.position(v)).collect();
        let mut soup = PolygonSoup::new(positions);
        soup.reserve(mesh.face_count(), mesh.halfedge_count());
        let mut corners = Vec::with_capacity(4);
        for &f in &self.old_face {
            corners.clear();
            corners.extend(mesh.face_vertices(f).map(|v| self.new_vertex[v.idx()].0));
            soup.push_face(&corners);
        }
        // The faces were validated when `mesh` was built: accept every area, so that a
        // mesh built with a lower degeneracy threshold is rebuilt too.
        let options = BuildOptions {
            degenerate_area_tolerance: f64::NEG_INFINITY,
            ..BuildOptions::default()
        };
        let (renumbered, _) = Mesh::build(&soup, &options)?;
        let face_to_input = self
            .old_face
            .iter()
            .map(|&f| mesh.face_to_input(f) as u32)
            .collect();
        let vertex_map = mesh
            .vertex_map()
            .renumbered(&self.old_vertex, &self.new_vertex);
        Ok(renumbered.with_input_maps(vertex_map, face_to_input))
    }

    /// The new id of old vertex `v`.
    pub fn new_vertex(&self, v: VertexId) -> VertexId {
        self.new_vertex[v.idx()]
    }

    /// The old id of new vertex `v`.
    pub fn old_vertex(&self, v: VertexId) -> VertexId {
        self.old_vertex[v.idx()]
    }

    /// The new id of old face `f`.
    pub fn new_face(&self, f: FaceId) -> FaceId {
        self.new_face[f.idx()]
    }

    /// The old id of new face `f`.
    pub fn old_face(&self, f: FaceId) -> FaceId {
        self.old_face[f.idx()]
    }

    /// Values by new vertex id (`values[new]`) put in old order. Panics unless there
    /// is one value per vertex.
    pub fn vertex_values_to_old<T: Clone>(&self, values: &[T]) -> Vec<T> {
        gather(
            &self.new_vertex,
            |v| v.idx(),
            values,
            "one value per vertex",
        )
    }

    /// Values by old vertex id put in new order. Panics unless there is one value per
    /// vertex.
    pub fn vertex_values_to_new<T: Clone>(&self, values: &[T]) -> Vec<T> {
        gather(
            &self.old_vertex,
            |v| v.idx(),
            values,
            "one value per vertex",
        )
    }

    /// Values by old face id put in new order. Panics unless there is one value per
    /// face.
    pub fn face_values_to_new<T: Clone>(&self, values: &[T]) -> Vec<T> {
        gather(&self.old_face, |f| f.idx(), values, "one value per face")
    }

    /// Values by new face id put in old order. Panics unless there is one value per
    /// face.
    pub fn face_values_to_old<T: Clone>(&self, values: &[T]) -> Vec<T> {
        gather(&self.new_face, |f| f.idx(), values, "one value per face")
    }
}

/// `values[index(k)]` for every `k` of `order` (as long as `values`, else a panic with
/// `what`).
fn gather<I: Copy, T: Clone>(
    order: &[I],
    index: impl Fn(I) -> usize,
    values: &[T],
    what: &str,
) -> Vec<T> {
    assert_eq!(values.len(), order.len(), "{what}");
    order.iter().map(|&k| values[index(k)].clone()).collect()
}

/// The median over faces of the difference between the largest and the smallest index
/// of a face's vertices: how far apart in memory the values of one face's vertices lie
/// (module docs). 0 for a mesh without faces.
pub fn index_spread(mesh: &Mesh) -> usize {
    let mut spread: Vec<u32> = mesh
        .faces()
        .map(|f| {
            let (lo, hi) = mesh
                .face_vertices(f)
                .fold((u32::MAX, 0), |(lo, hi), v| (lo.min(v.0), hi.max(v.0)));
            hi - lo
        })
        .collect();
    if spread.is_empty() {
        return 0;
    }
    let middle = spread.len() / 2;
    *spread.select_nth_unstable(middle).1 as usize
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::primitives::{Cells, grid, scattered, torus};
    use crate::{BoundaryLoopId, SurfacePoint};
    use nalgebra::{Point3, Vector3};

    #[test]
    fn a_scattered_grid_comes_back_compact_with_its_faces_and_input_indices() {
        let mut soup = scattered(&grid(40, 30, Cells::Triangles));
        // An unreferenced input vertex, last.
        let unreferenced = soup.vertex_count();
        soup.positions.push(Point3::new(9.0, 9.0, 9.0));
        let mesh = Mesh::from_soup(&soup).unwrap();
        let (renumbered, numbering) = renumber_breadth_first(&mesh).unwrap();
        let (before, after) = (index_spread(&mesh), index_spread(&renumbered));
        assert!(before > 300, "scattered spread {before}");
        // A breadth-first front of a 41 x 31 grid is at most one diagonal long.
        assert!(after <= 2 * 41, "renumbered spread {after}");
        assert_eq!(renumbered.vertex_count(), mesh.vertex_count());
        assert_eq!(renumbered.edge_count(), mesh.edge_count());
        assert_eq!(renumbered.boundary_loop_count(), 1);
        for f in renumbered.faces() {
            let old = numbering.old_face(f);
            assert_eq!(numbering.new_face(old), f);
            // The same corners in the same order, from the same first corner.
            let corners: Vec<VertexId> = mesh
                .face_vertices(old)
                .map(|v| numbering.new_vertex(v))
                .collect();
            assert_eq!(renumbered.face_vertices(f).collect::<Vec<_>>(), corners);
            assert_eq!(renumbered.face_to_input(f), mesh.face_to_input(old));
            let point = SurfacePoint {
                face: f,
                coords: [0.2, 0.3, 0.5, 0.0],
            };
            let before = SurfacePoint { face: old, ..point };
            assert_eq!(point.position(&renumbered), before.position(&mesh));
        }
        let (map, old_map) = (renumbered.vertex_map(), mesh.vertex_map());
        for v in renumbered.vertices() {
            let old = numbering.old_vertex(v);
            assert_eq!(numbering.new_vertex(old), v);
            assert_eq!(renumbered.position(v), mesh.position(old));
            assert_eq!(map.to_input(v), old_map.to_input(old));
            assert_eq!(map.from_input(map.to_input(v)), Some(v));
        }
        assert_eq!(map.from_input(unreferenced), None);
        assert_eq!(map.unreferenced(), old_map.unreferenced());
        assert!(map.is_order_preserving());
        let ids: Vec<usize> = mesh.vertices().map(|v| v.idx()).collect();
        let moved = numbering.vertex_values_to_new(&ids);
        assert_eq!(moved[0], numbering.old_vertex(VertexId(0)).idx());
        assert_eq!(numbering.vertex_values_to_old(&moved), ids);
        let faces: Vec<usize> = mesh.faces().map(|f| f.idx()).collect();
        let moved = numbering.face_values_to_new(&faces);
        assert_eq!(moved[0], numbering.old_face(FaceId(0)).idx());
        assert_eq!(numbering.face_values_to_old(&moved), faces);
        assert_eq!(
            renumbered.loop_vertices(BoundaryLoopId(0)).count(),
            mesh.loop_vertices(BoundaryLoopId(0)).count()
        );
    }

    #[test]
    fn every_component_is_numbered_in_one_stretch() {
        let first = scattered(&torus(12, 8, 3.0, 1.0, Cells::Quads));
        let second = torus(10, 6, 3.0, 1.0, Cells::Triangles);
        // The second torus beside the first, its vertices after the first's.
        let offset = first.vertex_count() as u32;
        let mut positions = first.positions.clone();
        positions.extend(
            second
                .positions
                .iter()
                .map(|p| p + Vector3::new(10.0, 0.0, 0.0)),
        );
        let mut both = PolygonSoup::new(positions);
        for face in first.faces() {
            both.push_face(face);
        }
        for face in second.faces() {
            let corners: Vec<u32> = face.iter().map(|&v| v + offset).collect();
            both.push_face(&corners);
        }
        let mesh = Mesh::from_soup(&both).unwrap();
        let (renumbered, _) = renumber_breadth_first(&mesh).unwrap();
        assert_eq!(renumbered.component_count(), 2);
        assert_eq!(renumbered.quad_count(), mesh.quad_count());
        // Per component: the lowest and highest vertex id and the number of vertices.
        let mut stretch = [(u32::MAX, 0, 0); 2];
        let mut seen = vec![false; renumbered.vertex_count()];
        for f in renumbered.faces() {
            let s = &mut stretch[renumbered.face_component(f).idx()];
            for v in renumbered.face_vertices(f) {
                s.0 = s.0.min(v.0);
                s.1 = s.1.max(v.0);
                if !std::mem::replace(&mut seen[v.idx()], true) {
                    s.2 += 1;
                }
            }
        }
        for (lo, hi, count) in stretch {
            assert_eq!((hi - lo + 1) as usize, count, "one stretch of ids");
        }
    }

    #[test]
    fn a_scattered_soup_is_the_same_surface_renumbered() {
        // 7919 vertices (a prime count: any stride below it permutes them).
        let positions: Vec<Point3<f64>> = (0..7919)
            .map(|i| Point3::new(i as f64, (i % 7) as f64, 0.0))
            .collect();
        let mut soup = PolygonSoup::new(positions.clone());
        soup.push_face(&[0, 1, 2]);
        soup.push_face(&[7918, 5, 3]);
        let out = scattered(&soup);
        let mut seen = vec![false; 7919];
        for p in &out.positions {
            let i = p.x as usize;
            assert!(!std::mem::replace(&mut seen[i], true), "vertex {i} twice");
        }
        for (face, moved) in soup.faces().zip(out.faces()) {
            for (&v, &w) in face.iter().zip(moved) {
                assert_eq!(out.positions[w as usize], positions[v as usize]);
            }
        }
        assert_ne!(out.faces().next(), soup.faces().next());
    }

    #[test]
    fn the_spread_is_the_median_of_the_faces_index_ranges() {
        // Faces with index ranges 2, 2 and 3 (input vertices 4 to 8 are unreferenced,
        // so input 9 is mesh vertex 4).
        let positions = (0..10)
            .map(|i| Point3::new(i as f64, (i * i % 7) as f64, 0.0))
            .collect();
        let mut soup = PolygonSoup::new(positions);
        soup.push_face(&[0, 1, 2]);
        soup.push_face(&[2, 1, 3]);
        soup.push_face(&[3, 1, 9]);
        let mesh = Mesh::from_soup(&soup).unwrap();
        assert_eq!(index_spread(&mesh), 2);
    }
}
