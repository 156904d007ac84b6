//! Errors raised while building a halfedge mesh from a polygon soup.
//!
//! Every variant names the offending element by its **input** index (0-based, in the order
//! of the polygon soup, which for files is the file's own order), so that a user can find
//! it in the file they gave.

use thiserror::Error;

/// Why a polygon soup could not become a halfedge mesh.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MeshError {
    /// The soup has no faces at all.
    #[error("the mesh has no faces")]
    NoFaces,

    /// A face with fewer than 3 or more than 4 vertices.
    #[error("face {face} has {size} vertices; only triangles and quads are supported")]
    UnsupportedFaceSize {
        /// Input face index.
        face: usize,
        /// Number of vertices of that face.
        size: usize,
    },

    /// A face refers to a vertex that does not exist.
    #[error("face {face} refers to vertex {index}, but there are only {vertex_count} vertices")]
    VertexIndexOutOfRange {
        /// Input face index.
        face: usize,
        /// The vertex index it used (0-based).
        index: usize,
        /// Number of vertices in the soup.
        vertex_count: usize,
    },

    /// New positions for a mesh ([`crate::Mesh::with_positions`]) that are not one per
    /// vertex.
    #[error("{got} positions for a mesh of {expected} vertices")]
    PositionCount {
        /// Number of mesh vertices.
        expected: usize,
        /// Number of positions given.
        got: usize,
    },

    /// A coordinate that is NaN or infinite.
    #[error("vertex {vertex} has a non-finite coordinate ({x}, {y}, {z})")]
    NonFiniteCoordinate {
        /// Input vertex index.
        vertex: usize,
        /// x coordinate.
        x: f64,
        /// y coordinate.
        y: f64,
        /// z coordinate.
        z: f64,
    },

    /// A coordinate so large in magnitude that areas overflow (see
    /// [`crate::MAX_COORDINATE`]).
    #[error(
        "vertex {vertex} has the coordinate {value:e}, which overflows the geometry (face areas and their squares would exceed the largest f64): every coordinate must lie within +-{max:e}; scale the mesh down"
    )]
    CoordinateOverflow {
        /// Input vertex index.
        vertex: usize,
        /// The coordinate of largest magnitude of that vertex.
        value: f64,
        /// The largest magnitude accepted.
        max: f64,
    },

    /// Vertices so close together that face areas underflow to zero (see
    /// [`crate::MIN_EXTENT`]).
    #[error(
        "the vertices span a bounding box of diagonal {diagonal:e}, so small that the geometry underflows (face areas and their squares round to zero): the diagonal must be at least {min:e}; scale the mesh up"
    )]
    ExtentUnderflow {
        /// The bounding-box diagonal of the input vertices.
        diagonal: f64,
        /// The smallest diagonal accepted.
        min: f64,
    },

    /// The coordinates are so large against the mesh's extent that rounding moves
    /// vertices by a noticeable part of it ([`crate::PRECISION_BITS`]).
    #[error(
        "the vertices lie up to {magnitude:e} from the origin but span a bounding box of diagonal only {diagonal:e}: coordinates there are up to {spacing:e} apart, too coarse for the mesh's size (vertices round onto one another, faces fold); translate the mesh near the origin (subtract its centroid) first"
    )]
    PrecisionLoss {
        /// The bounding-box diagonal of the input vertices.
        diagonal: f64,
        /// The largest coordinate magnitude.
        magnitude: f64,
        /// The spacing of `f64` values there.
        spacing: f64,
    },

    /// A degenerate-area tolerance that is NaN or plus infinity.
    #[error(
        "the degenerate-area tolerance must be a number below infinity (negative accepts every face), got {value}"
    )]
    InvalidTolerance {
        /// The tolerance given.
        value: f64,
    },

    /// A face that lists the same vertex twice.
    #[error("face {face} uses vertex {vertex} more than once")]
    RepeatedVertex {
        /// Input face index.
        face: usize,
        /// The repeated input vertex index.
        vertex: usize,
    },

    /// A face whose area is at most the threshold.
    #[error(
        "face {face} is degenerate: area {area:e} <= {threshold:e} (tolerance x squared bounding-box diagonal)"
    )]
    DegenerateFace {
        /// Input face index.
        face: usize,
        /// Its area (norm of the polygon vector area).
        area: f64,
        /// The threshold used.
        threshold: f64,
    },

    /// A quad whose bilinear patch folds (concave or self-crossing, seen along its mean
    /// normal): measures of it cannot agree.
    #[error(
        "face {face} is a quad that folds at its vertex {vertex} (concave or self-crossing, seen along its mean normal): split it into two triangles along the diagonal through vertex {vertex}"
    )]
    FoldedQuad {
        /// Input face index.
        face: usize,
        /// The input vertex at the first corner where the patch turns over.
        vertex: usize,
    },

    /// A face with the same vertex set as an earlier face.
    #[error("face {face} duplicates face {first} (same vertices)")]
    DuplicateFace {
        /// Input index of the later face.
        face: usize,
        /// Input index of the earlier face with the same vertices.
        first: usize,
    },

    /// An edge shared by more than two faces.
    #[error("edge ({a}, {b}) is non-manifold: it is shared by faces {faces:?}")]
    NonManifoldEdge {
        /// One endpoint (input vertex index).
        a: usize,
        /// Other endpoint (input vertex index).
        b: usize,
        /// Input indices of all faces on the edge.
        faces: Vec<usize>,
    },

    /// A vertex whose incident faces form more than one fan (a "bowtie" or pinch).
    #[error(
        "vertex {vertex} is non-manifold: its faces form {fans} separate fans (a pinch or bowtie)"
    )]
    NonManifoldVertex {
        /// Input vertex index.
        vertex: usize,
        /// Number of fans found around it (at least 2).
        fans: usize,
    },

    /// The faces of a component cannot be oriented consistently (a Moebius strip or Klein bottle).
    #[error(
        "the surface is non-orientable: faces {face} and {neighbor} cannot be oriented consistently across edge ({a}, {b})"
    )]
    NonOrientable {
        /// Input face index where the conflict closed.
        face: usize,
        /// The neighbouring input face.
        neighbor: usize,
        /// Shared edge endpoint (input vertex index).
        a: usize,
        /// Shared edge endpoint (input vertex index).
        b: usize,
    },

    /// More elements than a `u32` index can address.
    #[error("the mesh is too large: {what} exceed u32::MAX")]
    TooLarge {
        /// Which elements overflowed.
        what: &'static str,
    },
}
