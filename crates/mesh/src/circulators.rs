//! Circulators: ordered walks around a vertex and along a boundary loop.
//!
//! Around a vertex the walk turns counter-clockwise (seen from the normal side) with
//! `h -> twin(prev(h))`. It starts at [`Mesh::vertex_halfedge`], which on the boundary is
//! the outgoing boundary halfedge, so the faces of a boundary vertex come out as one
//! contiguous fan. Face circulators are on [`Mesh`] itself ([`Mesh::face_vertices`],
//! [`Mesh::face_halfedges`]) because a face's halfedges are consecutive.

use crate::{BoundaryLoopId, FaceId, HalfedgeId, Mesh, VertexId};

/// Outgoing halfedges of a vertex, counter-clockwise. See [`Mesh::outgoing_halfedges`].
#[derive(Clone)]
pub struct OutgoingHalfedges<'a> {
    mesh: &'a Mesh,
    start: HalfedgeId,
    current: Option<HalfedgeId>,
}

impl Iterator for OutgoingHalfedges<'_> {
    type Item = HalfedgeId;

    fn next(&mut self) -> Option<HalfedgeId> {
        let h = self.current?;
        let n = self.mesh.twin(self.mesh.prev(h));
        self.current = (n != self.start).then_some(n);
        Some(h)
    }
}

/// Halfedges of a boundary loop in order. See [`Mesh::loop_halfedges`].
#[derive(Clone)]
pub struct LoopHalfedges<'a> {
    mesh: &'a Mesh,
    start: HalfedgeId,
    current: Option<HalfedgeId>,
}

impl Iterator for LoopHalfedges<'_> {
    type Item = HalfedgeId;

    fn next(&mut self) -> Option<HalfedgeId> {
        let h = self.current?;
        let n = self.mesh.next(h);
        self.current = (n != self.start).then_some(n);
        Some(h)
    }
}

impl Mesh {
    /// Outgoing halfedges of `v` in counter-clockwise order, boundary halfedge first on
    /// the boundary.
    pub fn outgoing_halfedges(&self, v: VertexId) -> OutgoingHalfedges<'_> {
        let start = self.vertex_halfedge(v);
        OutgoingHalfedges {
            mesh: self,
            start,
            current: Some(start),
        }
    }

    /// The neighbouring vertices of `v` (one-ring), counter-clockwise.
    pub fn vertex_neighbors(&self, v: VertexId) -> impl Iterator<Item = VertexId> + '_ {
        self.outgoing_halfedges(v).map(|h| self.target(h))
    }

    /// The faces around `v`, counter-clockwise; consecutive faces share an edge (on the
    /// boundary they form one open fan).
    pub fn vertex_faces(&self, v: VertexId) -> impl Iterator<Item = FaceId> + '_ {
        self.outgoing_halfedges(v).filter_map(|h| self.face(h))
    }

    /// Number of edges at `v`.
    pub fn vertex_degree(&self, v: VertexId) -> usize {
        self.outgoing_halfedges(v).count()
    }

    /// The boundary halfedges of loop `b` in order.
    pub fn loop_halfedges(&self, b: BoundaryLoopId) -> LoopHalfedges<'_> {
        let start = self.loop_halfedge(b);
        LoopHalfedges {
            mesh: self,
            start,
            current: Some(start),
        }
    }

    /// The vertices of loop `b` in order (each boundary halfedge's origin).
    pub fn loop_vertices(&self, b: BoundaryLoopId) -> impl Iterator<Item = VertexId> + '_ {
        self.loop_halfedges(b).map(|h| self.origin(h))
    }
}
