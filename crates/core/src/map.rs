//! Maps: the images of a mesh's vertices.

use beltrami_mesh::Point3;
use num_complex::Complex64;

pub use beltrami_mesh::SurfacePoint;

/// The images of the vertices of a source mesh, indexed by [`beltrami_mesh::VertexId`].
#[derive(Debug, Clone, PartialEq)]
pub enum Map {
    /// Into the plane: `x + i y` per vertex.
    Planar(Vec<Complex64>),
    /// Into R^3 (the unit sphere, or the surface itself deformed).
    Spatial(Vec<Point3<f64>>),
    /// Onto a target mesh: a surface point per vertex.
    OnMesh(Vec<SurfacePoint>),
}

impl Map {
    /// Number of vertex images.
    pub fn len(&self) -> usize {
        match self {
            Map::Planar(v) => v.len(),
            Map::Spatial(v) => v.len(),
            Map::OnMesh(v) => v.len(),
        }
    }

    /// True if the map has no vertex images.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The planar images, if this is a planar map.
    pub fn as_planar(&self) -> Option<&[Complex64]> {
        match self {
            Map::Planar(v) => Some(v),
            _ => None,
        }
    }

    /// The images in R^3, if this is a spatial map.
    pub fn as_spatial(&self) -> Option<&[Point3<f64>]> {
        match self {
            Map::Spatial(v) => Some(v),
            _ => None,
        }
    }
}
