//! Errors of the initial bijection.

use beltrami_core::SolverError;
use beltrami_fem::{BoundaryError, DofError, FemError, WeightError};
use beltrami_mesh::{CutError, MeshError, VertexId};
use beltrami_sparse::SolveError;
use beltrami_spatial::SpatialError;
use thiserror::Error;

use crate::topology::Shape;

/// Which of the two meshes an error is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// The source mesh (the one whose vertices are mapped).
    Source,
    /// The target mesh (the one they are mapped onto).
    Target,
}

impl std::fmt::Display for Side {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Side::Source => "source",
            Side::Target => "target",
        })
    }
}

/// Why no initial map could be built. Topology errors come before any work
/// ([`crate::check_topology`]); landmark errors name the landmark's index in the given
/// slice and its vertex (an index of the mesh, which is the input index when the file had
/// no unreferenced or merged vertices).
#[derive(Debug, Error)]
pub enum RegisterError {
    /// The two meshes have different topologies.
    #[error(
        "the meshes have different topologies: the source is {source_shape}, the target is {target_shape}; a bijection needs the same genus and number of boundary loops"
    )]
    TopologyMismatch {
        /// What the source is.
        source_shape: Shape,
        /// What the target is.
        target_shape: Shape,
    },
    /// A topology the initial map does not handle.
    #[error(
        "the {side} is {shape}; the initial map supports one connected surface (any genus, any number of boundary loops)"
    )]
    Unsupported {
        /// Which mesh.
        side: Side,
        /// What it is.
        shape: Shape,
    },
    /// Features that cannot be matched: on a topology whose road does not match them,
    /// or fields that do not fit the meshes.
    #[error("features: {reason}")]
    Features {
        /// Why.
        reason: String,
    },
    /// A landmark that cannot be honoured or names a vertex that does not exist.
    #[error("landmark {index} (source vertex {vertex}): {reason}")]
    Landmark {
        /// Its index in the landmark slice.
        index: usize,
        /// Its source vertex.
        vertex: VertexId,
        /// What is wrong.
        reason: String,
    },
    /// A closed torus whose cut did not give the four sides of a square (only very coarse
    /// meshes, whose edge graph has no loop crossing the shortest loop once).
    #[error(
        "the {side} torus could not be cut into a square along two loops crossing once (the mesh is too coarse: refine it)"
    )]
    NoSquare {
        /// Which mesh.
        side: Side,
    },
    /// The target's cut graph, drawn after the source's, does not cut the target in the
    /// same pattern (the two meshes are too different in space for the placement).
    #[error(
        "matching the cuts of the two meshes: {reason}; add landmarks (at least three, spread over the surface, and one on each boundary loop) so that the meshes can be placed onto each other"
    )]
    Seams {
        /// What did not match.
        reason: String,
    },
    /// Cutting a mesh into a disk failed.
    #[error("cutting the {side}: {error}")]
    Cut {
        /// Which mesh.
        side: Side,
        /// The cut error.
        error: CutError,
    },
    /// Edge weights of a Tutte embedding could not be computed.
    #[error("weights of the {side}: {error}")]
    Weights {
        /// Which mesh.
        side: Side,
        /// The weight error.
        error: WeightError,
    },
    /// A boundary map could not be built.
    #[error("boundary of the {side}: {error}")]
    Boundary {
        /// Which mesh.
        side: Side,
        /// The boundary error.
        error: BoundaryError,
    },
    /// A linear system (a Tutte embedding, a map's rebuild from its coefficient, the
    /// shape template's equations) could not be solved.
    #[error("a linear system of the {side}: {error}")]
    Solve {
        /// Which mesh.
        side: Side,
        /// The solve error.
        error: SolveError,
    },
    /// The fixed vertices of a landmark-matching map could not be laid out as unknowns.
    #[error("unknowns of the {side}: {error}")]
    Dofs {
        /// Which mesh.
        side: Side,
        /// The DOF error.
        error: DofError,
    },
    /// The spherical initialization failed.
    #[error("sphere map of the {side}: {error}")]
    Sphere {
        /// Which mesh.
        side: Side,
        /// The solver error.
        error: SolverError,
    },
    /// Building a parameter-domain mesh failed.
    #[error("parameter mesh of the {side}: {error}")]
    Mesh {
        /// Which mesh.
        side: Side,
        /// The mesh error.
        error: MeshError,
    },
    /// The finite elements of a mesh could not be set up (a degenerate face).
    #[error("finite elements of the {side}: {error}")]
    Elements {
        /// Which mesh.
        side: Side,
        /// The element error.
        error: FemError,
    },
    /// Point location failed.
    #[error("point location: {0}")]
    Spatial(#[from] SpatialError),
    /// Measuring the initial map failed (a degenerate source face).
    #[error("measuring the initial map: {0}")]
    Measure(#[from] FemError),
    /// The landmark-matching map in a parameter domain still folds faces after its
    /// smoothing steps.
    #[error(
        "matching the landmarks on the {domain}: {flipped} source faces still fold after {steps} smoothing steps; landmarks that are close to one another on one mesh and far apart on the other, or in another order around each other, cannot be matched without folds at this resolution: check them, or refine the source around them"
    )]
    LandmarkFolds {
        /// The parameter domain.
        domain: &'static str,
        /// Faces still flipped.
        flipped: usize,
        /// Steps taken.
        steps: usize,
    },
    /// Landmarks whose images are not at their targets at the end.
    #[error(
        "{count} of {total} landmarks are not exact: the farthest, landmark {index} (source vertex {vertex}), ends {distance:.4e} from its target ({relative:.2e} of the target's size). Check that the landmarks can be matched by a bijection (same order around each other on both meshes), or keep the map with `--allow-missed-landmarks` (option `allow-missed-landmarks`)"
    )]
    LandmarksMissed {
        /// Landmarks missed.
        count: usize,
        /// Landmarks given.
        total: usize,
        /// The farthest one's index.
        index: usize,
        /// Its source vertex (input index).
        vertex: usize,
        /// Its distance from its target.
        distance: f64,
        /// That distance relative to the target's bounding-box diagonal.
        relative: f64,
    },
    /// Two feature curves that meet on one mesh and not on the other.
    #[error(
        "feature curves {first} and {second} meet at {side} vertex {vertex} but not on the {other}: a bijection maps meeting curves to meeting curves"
    )]
    Curves {
        /// The first curve (index among the curves).
        first: usize,
        /// The second curve.
        second: usize,
        /// The mesh on which they meet.
        side: &'static str,
        /// A vertex on both.
        vertex: VertexId,
        /// The mesh on which they do not.
        other: &'static str,
    },
    /// The registration was stopped (a Ctrl-C, or the flow beside the shape template
    /// failed) while the shape template was being fitted.
    #[error("stopped while fitting the shape template")]
    Stopped,
    /// Flipped faces remain after the flow and its untangling, and the solve was not
    /// asked to allow them.
    #[error(
        "{count} source faces are flipped on the target after the flow (input indices {faces}); {why}. Refine the source where they are, add landmarks, or allow the flips (`--allow-flips`, option `allow-flips`) to keep the map"
    )]
    Flipped {
        /// How many faces are flipped.
        count: usize,
        /// The first of them (input indices), as a list.
        faces: String,
        /// Why, from the target's normals at the faces' corners.
        why: String,
    },
}
