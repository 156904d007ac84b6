//! Polygon soups: the unvalidated input from which a [`crate::Mesh`] is built.

use nalgebra::Point3;

/// Vertex positions and faces as lists of vertex indices, before any validation.
///
/// Faces are stored flat (`indices` with `offsets`), so a soup of a million faces is three
/// allocations, not a million. Indices are 0-based and refer to `positions`; nothing is
/// checked until [`crate::Mesh::build`] runs.
#[derive(Debug, Clone, PartialEq)]
pub struct PolygonSoup {
    /// Vertex positions in R^3 (a planar mesh has z = 0).
    pub positions: Vec<Point3<f64>>,
    indices: Vec<u32>,
    offsets: Vec<usize>,
}

impl Default for PolygonSoup {
    /// An empty soup: no positions, no faces.
    fn default() -> Self {
        Self::new(Vec::new())
    }
}

impl PolygonSoup {
    /// An empty soup with the given vertex positions.
    pub fn new(positions: Vec<Point3<f64>>) -> Self {
        Self {
            positions,
            indices: Vec::new(),
            offsets: vec![0],
        }
    }

    /// A soup of triangles.
    pub fn from_triangles(positions: Vec<Point3<f64>>, triangles: &[[u32; 3]]) -> Self {
        let mut soup = Self::new(positions);
        soup.reserve(triangles.len(), 3 * triangles.len());
        for t in triangles {
            soup.push_face(t);
        }
        soup
    }

    /// A soup of quads.
    pub fn from_quads(positions: Vec<Point3<f64>>, quads: &[[u32; 4]]) -> Self {
        let mut soup = Self::new(positions);
        soup.reserve(quads.len(), 4 * quads.len());
        for q in quads {
            soup.push_face(q);
        }
        soup
    }

    /// Reserves room for `faces` more faces with `corners` more vertex indices in total.
    pub fn reserve(&mut self, faces: usize, corners: usize) {
        self.offsets.reserve(faces);
        self.indices.reserve(corners);
    }

    /// Appends `other`'s positions after this soup's and its faces after this soup's,
    /// their vertex indices as they are: they name vertices of the joined soup (the
    /// parts of one file read at once).
    pub(crate) fn append(&mut self, other: PolygonSoup) {
        let base = self.indices.len();
        self.positions.extend(other.positions);
        self.indices.extend(other.indices);
        self.offsets
            .extend(other.offsets[1..].iter().map(|&offset| base + offset));
    }

    /// Appends a face given by its vertex indices (any count; the builder rejects sizes
    /// other than 3 and 4 with [`crate::MeshError::UnsupportedFaceSize`]).
    pub fn push_face(&mut self, vertices: &[u32]) {
        self.indices.extend_from_slice(vertices);
        self.offsets.push(self.indices.len());
    }

    /// Whether the faces look 1-based: no face uses vertex 0 and some face uses vertex
    /// `vertex_count()`, one past the last, as when indices written from 1 are read as
    /// 0-based. Error messages about an index out of range add this as a hint.
    pub fn looks_one_based(&self) -> bool {
        let n = self.positions.len();
        !self.indices.contains(&0) && self.indices.iter().any(|&i| i as usize == n)
    }

    /// Number of faces.
    pub fn face_count(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Number of vertex positions.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// The vertex indices of face `i`.
    pub fn face(&self, i: usize) -> &[u32] {
        &self.indices[self.offsets[i]..self.offsets[i + 1]]
    }

    /// Iterates over the faces in order.
    pub fn faces(&self) -> impl ExactSizeIterator<Item = &[u32]> + '_ {
        self.offsets.windows(2).map(|w| &self.indices[w[0]..w[1]])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faces_that_skip_vertex_zero_and_reach_the_count_look_one_based() {
        let positions = vec![Point3::origin(); 3];
        let one_based = PolygonSoup::from_triangles(positions.clone(), &[[1, 2, 3]]);
        assert!(one_based.looks_one_based());
        let zero_based = PolygonSoup::from_triangles(positions.clone(), &[[0, 1, 2]]);
        assert!(!zero_based.looks_one_based());
        let out_of_range = PolygonSoup::from_triangles(positions, &[[1, 2, 7]]);
        assert!(!out_of_range.looks_one_based());
    }
}
