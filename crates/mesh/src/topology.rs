//! Topology: boundary loops, connected components, Euler characteristic and genus.
//!
//! For a component with `V` vertices, `E` edges, `F` faces and `b` boundary loops,
//! `chi = V - E + F = 2 - 2g - b`, which gives the genus `g`. Quads count as one face
//! each; the formula holds for any polygonal cell decomposition.

use crate::{BoundaryLoopId, ComponentId, Mesh, VertexId};

/// One boundary loop: its vertices in order and its length.
#[derive(Debug, Clone, PartialEq)]
pub struct BoundaryLoop {
    /// The loop's id.
    pub id: BoundaryLoopId,
    /// Its vertices in the order of its boundary halfedges, with the surface on the right.
    pub vertices: Vec<VertexId>,
    /// Sum of its edge lengths.
    pub length: f64,
}

/// Counts and invariants of one connected component.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Component {
    /// The component's id.
    pub id: ComponentId,
    /// Number of vertices.
    pub vertices: usize,
    /// Number of edges.
    pub edges: usize,
    /// Number of faces.
    pub faces: usize,
    /// Number of boundary loops.
    pub boundary_loops: usize,
    /// `V - E + F`.
    pub euler_characteristic: i64,
    /// `(2 - chi - b) / 2`.
    pub genus: i64,
}

impl Component {
    /// True if the component has no boundary.
    pub fn is_closed(&self) -> bool {
        self.boundary_loops == 0
    }
    /// True if the component is a topological disk (genus 0, one boundary loop).
    pub fn is_disk(&self) -> bool {
        self.genus == 0 && self.boundary_loops == 1
    }
}

impl Mesh {
    /// `V - E + F` of the whole mesh.
    pub fn euler_characteristic(&self) -> i64 {
        self.vertex_count() as i64 - self.edge_count() as i64 + self.face_count() as i64
    }

    /// True if the mesh has no boundary.
    pub fn is_closed(&self) -> bool {
        self.boundary_loop_count() == 0
    }

    /// True if the mesh is one topological disk: one component, genus 0, one boundary loop.
    pub fn is_disk(&self) -> bool {
        let c = self.components();
        c.len() == 1 && c[0].is_disk()
    }

    /// Genus of a single-component mesh; `None` with several components (ask
    /// [`Mesh::components`]).
    pub fn genus(&self) -> Option<i64> {
        let c = self.components();
        (c.len() == 1).then(|| c[0].genus)
    }

    /// Counts, Euler characteristic and genus of every connected component.
    pub fn components(&self) -> Vec<Component> {
        let mut out: Vec<Component> = (0..self.component_count())
            .map(|c| Component {
                id: ComponentId(c as u32),
                vertices: 0,
                edges: 0,
                faces: 0,
                boundary_loops: 0,
                euler_characteristic: 0,
                genus: 0,
            })
            .collect();
        for f in self.faces() {
            out[self.face_component(f).idx()].faces += 1;
        }
        let component_of_halfedge = |h| {
            let h = match self.face(h) {
                Some(_) => h,
                None => self.twin(h),
            };
            self.face(h).map(|f| self.face_component(f).idx())
        };
        for v in self.vertices() {
            if let Some(c) = component_of_halfedge(self.vertex_halfedge(v)) {
                out[c].vertices += 1;
            }
        }
        for e in self.edges() {
            if let Some(c) = component_of_halfedge(self.edge_halfedge(e)) {
                out[c].edges += 1;
            }
        }
        for b in self.boundary_loops() {
            if let Some(c) = component_of_halfedge(self.loop_halfedge(b)) {
                out[c].boundary_loops += 1;
            }
        }
        for c in &mut out {
            c.euler_characteristic = c.vertices as i64 - c.edges as i64 + c.faces as i64;
            c.genus = (2 - c.euler_characteristic - c.boundary_loops as i64) / 2;
        }
        out
    }

    /// Number of vertices of every boundary loop, by loop id.
    pub fn boundary_loop_sizes(&self) -> Vec<usize> {
        self.boundary_loops()
            .map(|b| self.loop_halfedges(b).count())
            .collect()
    }

    /// Every boundary loop with its ordered vertices and length.
    pub fn boundary_loop_list(&self) -> Vec<BoundaryLoop> {
        self.boundary_loops()
            .map(|b| BoundaryLoop {
                id: b,
                vertices: self.loop_vertices(b).collect(),
                length: self
                    .loop_halfedges(b)
                    .map(|h| self.halfedge_vector(h).norm())
                    .sum(),
            })
            .collect()
    }
}
