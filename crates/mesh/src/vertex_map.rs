//! The correspondence between input indices (the file's order) and mesh indices.

use nalgebra::Point3;

use crate::VertexId;

/// Marks an input vertex that has no mesh vertex.
const NONE: u32 = u32::MAX;

/// Maps between the input's vertex indices and the halfedge mesh's [`VertexId`]s.
///
/// The halfedge mesh leaves out vertices that no face uses, and (when asked to repair)
/// merges vertices at exactly the same position. Mesh vertices keep the input's relative
/// order, so without unreferenced or merged vertices both numberings are the identity.
/// User-facing indices (pins, landmarks, correspondence files, written meshes) always
/// refer to the input's 0-based order; convert with [`VertexMap::to_input`] and
/// [`VertexMap::from_input`].
#[derive(Debug, Clone, PartialEq)]
pub struct VertexMap {
    to_input: Vec<u32>,
    from_input: Vec<u32>,
    unreferenced: Vec<(u32, Point3<f64>)>,
}

impl VertexMap {
    /// The identity map on `n` vertices.
    pub fn identity(n: usize) -> Self {
        let ids: Vec<u32> = (0..n as u32).collect();
        Self {
            to_input: ids.clone(),
            from_input: ids,
            unreferenced: Vec::new(),
        }
    }

    /// Builds the map from `from_input[i]` (mesh vertex of input vertex `i`, or `None`),
    /// the input index of every mesh vertex, and the positions of unreferenced vertices.
    pub(crate) fn new(
        to_input: Vec<u32>,
        from_input: Vec<u32>,
        unreferenced: Vec<(u32, Point3<f64>)>,
    ) -> Self {
        Self {
            to_input,
            from_input,
            unreferenced,
        }
    }

    /// The map of the same input onto the mesh vertices renumbered by `old_vertex[new]`
    /// (and its inverse `new_vertex[old]`).
    pub(crate) fn renumbered(&self, old_vertex: &[VertexId], new_vertex: &[VertexId]) -> Self {
        Self {
            to_input: old_vertex.iter().map(|v| self.to_input[v.idx()]).collect(),
            from_input: self
                .from_input
                .iter()
                .map(|&v| {
                    if v == NONE {
                        NONE
                    } else {
                        new_vertex[v as usize].0
                    }
                })
                .collect(),
            unreferenced: self.unreferenced.clone(),
        }
    }

    /// Number of vertices in the input.
    pub fn input_len(&self) -> usize {
        self.from_input.len()
    }

    /// The input index of mesh vertex `v` (for merged vertices, the first of them).
    pub fn to_input(&self, v: VertexId) -> usize {
        self.to_input[v.idx()] as usize
    }

    /// The mesh vertex of input vertex `i`; `None` if `i` is out of range or unreferenced.
    pub fn from_input(&self, i: usize) -> Option<VertexId> {
        match self.from_input.get(i) {
            Some(&v) if v != NONE => Some(VertexId(v)),
            _ => None,
        }
    }

    /// Input vertices that no face uses, with their positions (kept so that written
    /// meshes can reproduce the input's numbering).
    pub fn unreferenced(&self) -> &[(u32, Point3<f64>)] {
        &self.unreferenced
    }

    /// True when input and mesh numberings coincide.
    pub fn is_identity(&self) -> bool {
        self.to_input.len() == self.from_input.len()
            && self
                .to_input
                .iter()
                .enumerate()
                .all(|(i, &j)| i as u32 == j)
    }

    /// True when every input vertex has its own mesh vertex or is unreferenced, i.e. no
    /// vertices were merged, so a writer can restore the input numbering exactly.
    pub fn is_order_preserving(&self) -> bool {
        self.to_input.len() + self.unreferenced.len() == self.from_input.len()
    }
}

pub(crate) const NO_VERTEX: u32 = NONE;
