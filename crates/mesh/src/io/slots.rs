//! Output numbering of written meshes: the input's own vertex order when it can be
//! restored.

use nalgebra::{Point3, Vector2};

use super::VertexAttributes;
use crate::{Mesh, VertexId};

/// Where each mesh vertex goes in a written file.
///
/// When the mesh's vertex map preserves order (no vertices merged), the file gets one
/// vertex per input vertex: mesh vertex `v` at slot `to_input(v)` and every unreferenced
/// input vertex at its own slot, so vertex `k` of the output is vertex `k` of the input.
/// Otherwise the slots are the mesh's own vertex ids.
pub(crate) struct OutputSlots {
    slot: Vec<usize>,
    len: usize,
    restores_input: bool,
}

impl OutputSlots {
    /// The slots of `mesh`'s vertices.
    pub(crate) fn new(mesh: &Mesh) -> Self {
        let map = mesh.vertex_map();
        if map.is_order_preserving() {
            Self {
                slot: mesh.vertices().map(|v| map.to_input(v)).collect(),
                len: map.input_len(),
                restores_input: true,
            }
        } else {
            Self {
                slot: (0..mesh.vertex_count()).collect(),
                len: mesh.vertex_count(),
                restores_input: false,
            }
        }
    }

    /// Number of vertices the file gets.
    pub(crate) fn len(&self) -> usize {
        self.len
    }

    /// The slot of mesh vertex `v`.
    #[inline]
    pub(crate) fn slot(&self, v: VertexId) -> usize {
        self.slot[v.idx()]
    }

    /// The input index of the vertex written at `slot`, for error messages.
    pub(crate) fn input_index(&self, mesh: &Mesh, slot: usize) -> usize {
        if self.restores_input {
            slot
        } else {
            mesh.vertex_map().to_input(VertexId(slot as u32))
        }
    }

    /// One value per mesh vertex moved to its slot; slots of unreferenced input vertices
    /// get `T::default()`.
    pub(crate) fn scatter<T: Copy + Default>(&self, values: &[T]) -> Vec<T> {
        let mut out = vec![T::default(); self.len];
        for (v, &value) in values.iter().enumerate() {
            out[self.slot[v]] = value;
        }
        out
    }

    /// The positions to write: `attributes.positions` or the mesh's own, and the
    /// unreferenced input vertices' positions in their slots.
    pub(crate) fn positions(
        &self,
        mesh: &Mesh,
        attributes: &VertexAttributes<'_>,
    ) -> Vec<Point3<f64>> {
        let mut out = self.scatter(attributes.positions.unwrap_or(mesh.positions()));
        if self.restores_input {
            for &(i, p) in mesh.vertex_map().unreferenced() {
                out[i as usize] = p;
            }
        }
        out
    }

    /// The positions, texture coordinates and colors to write, each moved to its slot
    /// ([`OutputSlots::positions`], [`OutputSlots::scatter`]).
    pub(crate) fn vertex_values(
        &self,
        mesh: &Mesh,
        attributes: &VertexAttributes<'_>,
    ) -> VertexValues {
        VertexValues {
            positions: self.positions(mesh, attributes),
            uvs: attributes.uvs.map(|u| self.scatter(u)),
            colors: attributes.colors.map(|c| self.scatter(c)),
        }
    }
}

/// Per-vertex values in output order ([`OutputSlots::vertex_values`]).
pub(crate) struct VertexValues {
    pub(crate) positions: Vec<Point3<f64>>,
    pub(crate) uvs: Option<Vec<Vector2<f64>>>,
    pub(crate) colors: Option<Vec<[f32; 3]>>,
}
