//! Why an atlas could not be made.

use beltrami_fem::FemError;
use beltrami_mesh::{CutError, MeshError};
use beltrami_sparse::SolveError;
use thiserror::Error;

/// Why an atlas could not be made. Every variant names the option or face at fault.
#[derive(Debug, Error)]
pub enum AtlasError {
    /// An option is out of its range.
    #[error("option `{option}`: {message}")]
    InvalidOption {
        /// The option's name as the command line spells it.
        option: &'static str,
        /// What is wrong and the accepted range.
        message: String,
    },
    /// The mesh has a face that is not a triangle.
    #[error(
        "face {face} (0-based, in the file's order) has {corners} corners: atlases are made of triangle meshes; split the quads into triangles first"
    )]
    NotTriangles {
        /// The first face that is not a triangle, by its input index.
        face: usize,
        /// Its number of corners.
        corners: usize,
    },
    /// A chart could not be laid flat even as a few faces (a bug: please report it with
    /// the mesh).
    #[error(
        "the chart holding face {face} (0-based, in the file's order; {faces} faces) could not be laid flat without overlap after {splits} splits"
    )]
    Unflattenable {
        /// A face of the chart, by its input index.
        face: usize,
        /// Its number of faces.
        faces: usize,
        /// How often it was split.
        splits: usize,
    },
    /// Cutting a chart open failed.
    #[error("cutting a chart open: {0}")]
    Cut(#[from] CutError),
    /// Building a chart's mesh failed.
    #[error("building a chart: {0}")]
    Mesh(#[from] MeshError),
    /// Assembling a chart's Laplacian failed.
    #[error("assembling a chart's Laplacian: {0}")]
    Fem(#[from] FemError),
    /// A linear solve failed.
    #[error("solving for a chart's scale factors: {0}")]
    Solve(#[from] SolveError),
}
