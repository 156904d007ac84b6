//! Why a remeshing could not be done.

use beltrami_core::SolverError;
use beltrami_mesh::{CutError, FaceId, MeshError};
use beltrami_spatial::SpatialError;
use thiserror::Error;

/// Fewer equilateral triangles than this covering a surface make an edge length
/// [`RemeshError::TooCoarse`] when the remeshed surface cannot be built.
pub const COARSE_FACES: usize = 100;

/// Why a remeshing could not be done. Every variant names the option, face or solver at
/// fault and what to do instead.
#[derive(Debug, Error)]
pub enum RemeshError {
    /// An option is out of its range (a non-positive or non-finite edge length, a
    /// vertex count below 3, a minimum angle that refinement cannot guarantee).
    #[error("option `{option}`: {message}")]
    InvalidOption {
        /// The option's name as the command line spells it.
        option: &'static str,
        /// What is wrong and the accepted range.
        message: String,
    },
    /// Remeshing one connected component of a mesh in several failed
    /// ([`crate::components::remesh_each`]).
    #[error("component {component} (the one with input face {first_face}): {error}")]
    InComponent {
        /// The component's index, in the order of the components' first faces.
        component: usize,
        /// Its first face, as an input index.
        first_face: usize,
        /// Why its remeshing failed.
        #[source]
        error: Box<RemeshError>,
    },
    /// The asked size would make more vertices than the most allowed
    /// ([`crate::RemeshOptions::max_vertices`]), refused before any work.
    #[error(
        "an edge length of {edge_length:e} would make about {estimate:.3e} vertices on this surface (area {area:.4e}), more than the most allowed ({max_vertices}, option `max-vertices`); ask for an edge length of at least about {suggested:.3e}, or allow more vertices"
    )]
    TooFine {
        /// The edge length asked (or derived from the vertex count asked).
        edge_length: f64,
        /// The surface's area.
        area: f64,
        /// The vertices an equilateral mesh of that edge length would have.
        estimate: f64,
        /// The most vertices allowed.
        max_vertices: usize,
        /// The edge length of an equilateral mesh with `max_vertices` vertices.
        suggested: f64,
    },
    /// The mesh is not a single connected surface.
    #[error("remeshing needs one connected surface; this mesh has {components} components")]
    Components {
        /// Number of connected components.
        components: usize,
    },
    /// The parameterizer cannot be used for remeshing (it maps onto the sphere or a
    /// mesh instead of the plane).
    #[error("parameterizer `{solver}` cannot be used for remeshing: {message}")]
    Parameterizer {
        /// The solver's name.
        solver: &'static str,
        /// Why, and what to use instead.
        message: String,
    },
    /// The parameterization failed.
    #[error("parameterizing with `{solver}` failed: {error}")]
    Solve {
        /// The solver's name.
        solver: &'static str,
        /// Its error.
        #[source]
        error: SolverError,
    },
    /// The parameterization folds over: a face has a non-positive area in the plane, so
    /// points of the parameter domain have no single preimage.
    #[error(
        "the map of `{solver}` is not one-to-one: {flipped} faces have non-positive area in the plane (first: face {first}); use a bijective parameterizer such as `tutte`"
    )]
    Flipped {
        /// The solver's name.
        solver: &'static str,
        /// Number of faces with a non-positive signed area.
        flipped: usize,
        /// The first of them.
        first: FaceId,
    },
    /// The boundary of the parameter domain crosses itself (the map overlaps globally).
    #[error(
        "the boundary of the parameter domain of `{solver}` crosses itself (the map overlaps); use a parameterizer with a convex boundary such as `tutte`"
    )]
    Overlap {
        /// The solver's name.
        solver: &'static str,
    },
    /// Cutting the surface into a disk failed.
    #[error(transparent)]
    Cut(#[from] CutError),
    /// Building a mesh failed (the cut or parameter mesh, or the result).
    #[error("building the {what} failed: {error}")]
    Build {
        /// Which mesh.
        what: &'static str,
        /// The validation error.
        #[source]
        error: MeshError,
    },
    /// The asked edge length is too long for the surface: so few triangles of that size
    /// cover it that its triangulation collapses (faces coincide, or none is left).
    #[error(
        "an edge length of {edge_length:e} is too long for this surface (area {area:.4e}: {faces:.2e} equilateral triangles of that side): {error}; ask for an edge length of at most about {suggested:.3e} ({COARSE_FACES} triangles)"
    )]
    TooCoarse {
        /// The edge length asked (or derived from the vertex count asked).
        edge_length: f64,
        /// The surface's area.
        area: f64,
        /// The number of equilateral triangles of side `edge_length` whose area is `area`.
        faces: f64,
        /// The edge length of [`COARSE_FACES`] equilateral triangles of the surface's area.
        suggested: f64,
        /// How the triangulation collapsed.
        #[source]
        error: Box<RemeshError>,
    },
    /// Point location failed.
    #[error(transparent)]
    Spatial(#[from] SpatialError),
    /// The result does not have the input's topology (a bug: please report it with the
    /// mesh and the options).
    #[error("the remeshed surface has {found}, the input {expected}")]
    TopologyChanged {
        /// The input's topology in words.
        expected: String,
        /// The result's.
        found: String,
    },
    /// The size field asks for more vertices than the limit.
    #[error(
        "the asked edge length needs more than {limit} vertices (option `max-vertices`); ask for a longer edge length or raise the limit"
    )]
    TooManyVertices {
        /// The limit.
        limit: usize,
    },
    /// In-place remeshing left faces turned against the surface that were not turned in
    /// the input, after pulling their vertices back.
    #[error(
        "{turned} faces end turned against the surface (first: face {first}) although the input had {input}; try another --max-iters or --reference, or --allow-flips to write the result anyway"
    )]
    Turned {
        /// Faces turned in the result.
        turned: usize,
        /// Faces turned in the input (by the same measure).
        input: usize,
        /// The first face turned in the result but not in the input.
        first: FaceId,
    },
    /// The remeshing was cancelled.
    #[error("cancelled")]
    Cancelled,
}
