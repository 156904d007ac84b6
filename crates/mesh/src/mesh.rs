//! The halfedge mesh: connectivity, positions and the basic element queries.
//!
//! # Conventions
//!
//! - Faces are triangles or quads, oriented counter-clockwise seen from the side their
//!   normal points to. The halfedges of face `f` run along its sides in that order and
//!   have consecutive ids, starting at [`Mesh::face_halfedge`]; the first one leaves the
//!   face's first vertex.
//! - `origin(h)` is the vertex a halfedge leaves, `target(h)` the one it enters; `face(h)`
//!   is the face on its left.
//! - Every edge has two halfedges. On a boundary edge the second one is an explicit
//!   *boundary halfedge*, which belongs to a [`BoundaryLoopId`] instead of a face; boundary
//!   halfedges come after all face halfedges and have the surface on their right (seen
//!   from the normal side, the outer boundary of a disk runs clockwise and a hole
//!   counter-clockwise), so a boundary loop is walked with `next` like a face.
//! - The outgoing halfedge stored for a boundary vertex is its boundary halfedge;
//!   circulating from it with `h -> twin(prev(h))` turns counter-clockwise and visits the
//!   incident faces as one contiguous fan.

use std::ops::Range;

use nalgebra::Point3;

use crate::build::{self, BuildOptions, BuildReport};
use crate::{
    BoundaryLoopId, ComponentId, EdgeId, FaceId, HalfedgeId, MeshError, PolygonSoup, VertexId,
    VertexMap,
};

/// The arrays of a mesh, filled by the builder.
pub(crate) struct MeshData {
    pub positions: Vec<Point3<f64>>,
    pub next: Vec<HalfedgeId>,
    pub prev: Vec<HalfedgeId>,
    pub twin: Vec<HalfedgeId>,
    pub origin: Vec<VertexId>,
    pub edge: Vec<EdgeId>,
    /// Face id for face halfedges; `face_count + loop` for boundary halfedges.
    pub face_or_loop: Vec<u32>,
    pub vertex_halfedge: Vec<HalfedgeId>,
    /// Halfedges of face `f` are `face_offsets[f]..face_offsets[f + 1]`.
    pub face_offsets: Vec<u32>,
    pub edge_count: usize,
    pub loop_halfedge: Vec<HalfedgeId>,
    pub face_component: Vec<ComponentId>,
    pub component_count: usize,
    pub vertex_map: VertexMap,
    pub face_to_input: Vec<u32>,
}

/// A validated, consistently oriented, manifold triangle/quad mesh with explicit boundary
/// halfedges. Connectivity is immutable; build one with [`Mesh::build`] or read one with
/// [`crate::io`].
#[derive(Debug, Clone)]
pub struct Mesh {
    positions: Vec<Point3<f64>>,
    next: Vec<HalfedgeId>,
    prev: Vec<HalfedgeId>,
    twin: Vec<HalfedgeId>,
    origin: Vec<VertexId>,
    edge: Vec<EdgeId>,
    face_or_loop: Vec<u32>,
    vertex_halfedge: Vec<HalfedgeId>,
    face_offsets: Vec<u32>,
    edge_halfedge: Vec<HalfedgeId>,
    loop_halfedge: Vec<HalfedgeId>,
    face_component: Vec<ComponentId>,
    component_count: usize,
    vertex_map: VertexMap,
    face_to_input: Vec<u32>,
}

impl Mesh {
    /// Validates a polygon soup and builds the halfedge mesh.
    ///
    /// Fails with a [`MeshError`] naming the first offending element (input indices) for:
    /// unsupported face sizes, out-of-range indices, non-finite coordinates, repeated
    /// vertices, degenerate or duplicate faces (unless repaired, see [`BuildOptions`]),
    /// non-manifold edges or vertices, and non-orientable components. Components with
    /// inconsistently oriented faces are re-oriented to the orientation of the majority of
    /// their faces; [`BuildReport::faces_reoriented`] counts the faces flipped.
    pub fn build(
        soup: &PolygonSoup,
        options: &BuildOptions,
    ) -> Result<(Mesh, BuildReport), MeshError> {
        build::build(soup, options)
    }

    /// Builds a mesh with default options (no repair) and discards the report.
    pub fn from_soup(soup: &PolygonSoup) -> Result<Mesh, MeshError> {
        Self::build(soup, &BuildOptions::default()).map(|(mesh, _)| mesh)
    }

    pub(crate) fn from_data(d: MeshData) -> Self {
        let mut edge_halfedge = vec![HalfedgeId(u32::MAX); d.edge_count];
        // Face halfedges come first, so the stored halfedge of an edge is a face halfedge
        // whenever the edge has a face on either side.
        for (h, e) in d.edge.iter().enumerate().rev() {
            edge_halfedge[e.idx()] = HalfedgeId(h as u32);
        }
        Self {
            positions: d.positions,
            next: d.next,
            prev: d.prev,
            twin: d.twin,
            origin: d.origin,
            edge: d.edge,
            face_or_loop: d.face_or_loop,
            vertex_halfedge: d.vertex_halfedge,
            face_offsets: d.face_offsets,
            edge_halfedge,
            loop_halfedge: d.loop_halfedge,
            face_component: d.face_component,
            component_count: d.component_count,
            vertex_map: d.vertex_map,
            face_to_input: d.face_to_input,
        }
    }

    // ---- counts and ranges ----

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }
    /// Number of halfedges, boundary halfedges included.
    pub fn halfedge_count(&self) -> usize {
        self.next.len()
    }
    /// Number of undirected edges.
    pub fn edge_count(&self) -> usize {
        self.edge_halfedge.len()
    }
    /// Number of faces.
    pub fn face_count(&self) -> usize {
        self.face_offsets.len() - 1
    }
    /// Number of boundary loops.
    pub fn boundary_loop_count(&self) -> usize {
        self.loop_halfedge.len()
    }
    /// Number of connected components.
    pub fn component_count(&self) -> usize {
        self.component_count
    }
    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.faces().filter(|&f| self.face_degree(f) == 3).count()
    }
    /// Number of quads.
    pub fn quad_count(&self) -> usize {
        self.faces().filter(|&f| self.face_degree(f) == 4).count()
    }

    /// All vertex ids.
    pub fn vertices(&self) -> impl ExactSizeIterator<Item = VertexId> + use<> {
        (0..self.vertex_count() as u32).map(VertexId)
    }
    /// All halfedge ids (face halfedges first, then boundary halfedges).
    pub fn halfedges(&self) -> impl ExactSizeIterator<Item = HalfedgeId> + use<> {
        (0..self.halfedge_count() as u32).map(HalfedgeId)
    }
    /// All edge ids.
    pub fn edges(&self) -> impl ExactSizeIterator<Item = EdgeId> + use<> {
        (0..self.edge_count() as u32).map(EdgeId)
    }
    /// All face ids.
    pub fn faces(&self) -> impl ExactSizeIterator<Item = FaceId> + use<> {
        (0..self.face_count() as u32).map(FaceId)
    }
    /// All boundary loop ids.
    pub fn boundary_loops(&self) -> impl ExactSizeIterator<Item = BoundaryLoopId> + use<> {
        (0..self.boundary_loop_count() as u32).map(BoundaryLoopId)
    }

    // ---- positions and index maps ----

    /// Position of vertex `v`.
    #[inline]
    pub fn position(&self, v: VertexId) -> Point3<f64> {
        self.positions[v.idx()]
    }
    /// All vertex positions, indexed by [`VertexId`].
    pub fn positions(&self) -> &[Point3<f64>] {
        &self.positions
    }

    /// The same mesh (connectivity, ids, input maps) with the vertices at `positions`
    /// (indexed by [`VertexId`]), e.g. a surface laid out in the plane. Connectivity
    /// and orientation are combinatorial and stay valid; the geometry is not checked
    /// beyond finiteness, so faces may be degenerate or turned over in the new layout.
    ///
    /// Errors: [`MeshError::PositionCount`] unless there is one position per vertex,
    /// [`MeshError::NonFiniteCoordinate`] (naming the input index) for a NaN or
    /// infinite coordinate.
    pub fn with_positions(&self, positions: Vec<Point3<f64>>) -> Result<Mesh, MeshError> {
        if positions.len() != self.positions.len() {
            return Err(MeshError::PositionCount {
                expected: self.positions.len(),
                got: positions.len(),
            });
        }
        if let Some(v) = positions
            .iter()
            .position(|p| !p.coords.iter().all(|x| x.is_finite()))
        {
            let p = positions[v];
            return Err(MeshError::NonFiniteCoordinate {
                vertex: self.vertex_map.to_input(VertexId(v as u32)),
                x: p.x,
                y: p.y,
                z: p.z,
            });
        }
        Ok(Mesh {
            positions,
            ..self.clone()
        })
    }
    /// The same mesh with other input maps (a renumbering's composed ones).
    pub(crate) fn with_input_maps(self, vertex_map: VertexMap, face_to_input: Vec<u32>) -> Mesh {
        Mesh {
            vertex_map,
            face_to_input,
            ..self
        }
    }

    /// The map between input vertex indices and mesh vertices.
    pub fn vertex_map(&self) -> &VertexMap {
        &self.vertex_map
    }
    /// The input index of face `f` (faces dropped by a repair shift later indices).
    pub fn face_to_input(&self, f: FaceId) -> usize {
        self.face_to_input[f.idx()] as usize
    }

    // ---- halfedges ----

    /// The next halfedge around the same face or boundary loop.
    #[inline]
    pub fn next(&self, h: HalfedgeId) -> HalfedgeId {
        self.next[h.idx()]
    }
    /// The previous halfedge around the same face or boundary loop.
    #[inline]
    pub fn prev(&self, h: HalfedgeId) -> HalfedgeId {
        self.prev[h.idx()]
    }
    /// The opposite halfedge of the same edge.
    #[inline]
    pub fn twin(&self, h: HalfedgeId) -> HalfedgeId {
        self.twin[h.idx()]
    }
    /// The vertex `h` leaves.
    #[inline]
    pub fn origin(&self, h: HalfedgeId) -> VertexId {
        self.origin[h.idx()]
    }
    /// The vertex `h` enters.
    #[inline]
    pub fn target(&self, h: HalfedgeId) -> VertexId {
        self.origin[self.twin[h.idx()].idx()]
    }
    /// The edge of `h`.
    #[inline]
    pub fn edge(&self, h: HalfedgeId) -> EdgeId {
        self.edge[h.idx()]
    }
    /// The face on the left of `h`, or `None` for a boundary halfedge.
    #[inline]
    pub fn face(&self, h: HalfedgeId) -> Option<FaceId> {
        let f = self.face_or_loop[h.idx()];
        ((f as usize) < self.face_count()).then_some(FaceId(f))
    }
    /// The boundary loop of a boundary halfedge, or `None` for a face halfedge.
    #[inline]
    pub fn boundary_loop(&self, h: HalfedgeId) -> Option<BoundaryLoopId> {
        let f = self.face_or_loop[h.idx()] as usize;
        f.checked_sub(self.face_count())
            .map(|b| BoundaryLoopId(b as u32))
    }
    /// True for a boundary halfedge (one with no face).
    #[inline]
    pub fn is_boundary_halfedge(&self, h: HalfedgeId) -> bool {
        self.face_or_loop[h.idx()] as usize >= self.face_count()
    }
    /// The vector from `origin(h)` to `target(h)`.
    #[inline]
    pub fn halfedge_vector(&self, h: HalfedgeId) -> nalgebra::Vector3<f64> {
        self.position(self.target(h)) - self.position(self.origin(h))
    }

    // ---- vertices ----

    /// An outgoing halfedge of `v`: the boundary one if `v` is on the boundary.
    #[inline]
    pub fn vertex_halfedge(&self, v: VertexId) -> HalfedgeId {
        self.vertex_halfedge[v.idx()]
    }
    /// True if `v` lies on a boundary loop.
    #[inline]
    pub fn is_boundary_vertex(&self, v: VertexId) -> bool {
        self.is_boundary_halfedge(self.vertex_halfedge(v))
    }

    // ---- faces ----

    /// The first halfedge of `f` (it leaves the face's first vertex).
    #[inline]
    pub fn face_halfedge(&self, f: FaceId) -> HalfedgeId {
        HalfedgeId(self.face_offsets[f.idx()])
    }
    /// The halfedges of `f` in order (consecutive ids).
    #[inline]
    pub fn face_halfedges(&self, f: FaceId) -> impl ExactSizeIterator<Item = HalfedgeId> + use<> {
        self.face_range(f).map(HalfedgeId)
    }
    /// The vertices of `f` in counter-clockwise order, starting at its first vertex.
    #[inline]
    pub fn face_vertices(&self, f: FaceId) -> impl ExactSizeIterator<Item = VertexId> + Clone + '_ {
        self.origin[self.face_range_usize(f)].iter().copied()
    }
    /// The vertices of a triangle or quad as a small array and its length.
    #[inline]
    pub fn face_vertex_array(&self, f: FaceId) -> ([VertexId; 4], usize) {
        let corners = &self.origin[self.face_range_usize(f)];
        let n = corners.len();
        // Element by element: a copy of a slice of unknown length calls `memmove`,
        // which showed up at 2-4% of a registration (surface points, walks, normals).
        let fourth = if n == 4 { corners[3] } else { VertexId(0) };
        ([corners[0], corners[1], corners[2], fourth], n)
    }
    /// Number of vertices of `f` (3 or 4).
    #[inline]
    pub fn face_degree(&self, f: FaceId) -> usize {
        (self.face_offsets[f.idx() + 1] - self.face_offsets[f.idx()]) as usize
    }
    /// The component `f` belongs to.
    #[inline]
    pub fn face_component(&self, f: FaceId) -> ComponentId {
        self.face_component[f.idx()]
    }

    fn face_range(&self, f: FaceId) -> Range<u32> {
        self.face_offsets[f.idx()]..self.face_offsets[f.idx() + 1]
    }
    fn face_range_usize(&self, f: FaceId) -> Range<usize> {
        self.face_offsets[f.idx()] as usize..self.face_offsets[f.idx() + 1] as usize
    }

    // ---- edges ----

    /// A halfedge of `e`: a face halfedge whenever `e` has a face.
    #[inline]
    pub fn edge_halfedge(&self, e: EdgeId) -> HalfedgeId {
        self.edge_halfedge[e.idx()]
    }
    /// The two endpoints of `e`.
    #[inline]
    pub fn edge_vertices(&self, e: EdgeId) -> [VertexId; 2] {
        let h = self.edge_halfedge(e);
        [self.origin(h), self.target(h)]
    }
    /// The faces on both sides of `e`; the second is `None` on a boundary edge.
    #[inline]
    pub fn edge_faces(&self, e: EdgeId) -> [Option<FaceId>; 2] {
        let h = self.edge_halfedge(e);
        [self.face(h), self.face(self.twin(h))]
    }
    /// True if `e` has a face on one side only.
    #[inline]
    pub fn is_boundary_edge(&self, e: EdgeId) -> bool {
        let h = self.edge_halfedge(e);
        self.is_boundary_halfedge(self.twin(h))
    }

    // ---- boundary loops ----

    /// The first boundary halfedge of loop `b`.
    #[inline]
    pub fn loop_halfedge(&self, b: BoundaryLoopId) -> HalfedgeId {
        self.loop_halfedge[b.idx()]
    }
}
