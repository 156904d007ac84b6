//! Errors of the spatial queries.
//!
//! Each variant names what was wrong (the point, the face, the surface point); the batch
//! functions wrap the error of one item in [`SpatialError::InBatch`] with its index.

use beltrami_mesh::{FaceId, SurfacePointError};
use thiserror::Error;

/// Why a spatial query could not be answered.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SpatialError {
    /// A query point with a NaN or infinite coordinate.
    #[error("query point ({x}, {y}, {z}) has a non-finite coordinate")]
    NonFinitePoint {
        /// x coordinate.
        x: f64,
        /// y coordinate.
        y: f64,
        /// z coordinate.
        z: f64,
    },

    /// A displacement with a NaN or infinite component.
    #[error("displacement ({x}, {y}, {z}) has a non-finite component")]
    NonFiniteDisplacement {
        /// x component.
        x: f64,
        /// y component.
        y: f64,
        /// z component.
        z: f64,
    },

    /// A face hint that is not a face of the indexed mesh.
    #[error("hint face {face} is not a face of the mesh ({face_count} faces)")]
    HintOutOfRange {
        /// The hint.
        face: FaceId,
        /// Number of faces of the mesh.
        face_count: usize,
    },

    /// A surface point that does not belong to the indexed mesh.
    #[error(transparent)]
    InvalidSurfacePoint(#[from] SurfacePointError),

    /// Two slices of a batch call with different lengths.
    #[error("{what}: expected {expected} entries, got {found}")]
    LengthMismatch {
        /// Which argument.
        what: &'static str,
        /// Its required length.
        expected: usize,
        /// Its actual length.
        found: usize,
    },

    /// A search radius that is negative, NaN or infinite.
    #[error("search radius {radius} is not a finite non-negative number")]
    InvalidRadius {
        /// The radius.
        radius: f64,
    },

    /// The mesh needs more kd-tree samples than a `u32` item index can address.
    #[error("the mesh is too large to index: {samples} samples exceed u32::MAX")]
    TooLarge {
        /// Number of samples the index needed.
        samples: usize,
    },

    /// The error of one item of a batch call.
    #[error("item {index}: {source}")]
    InBatch {
        /// Index of the item in the batch.
        index: usize,
        /// What was wrong with it.
        source: Box<SpatialError>,
    },
}

impl SpatialError {
    /// Wraps the error of item `index` of a batch.
    pub(crate) fn in_batch(self, index: usize) -> Self {
        SpatialError::InBatch {
            index,
            source: Box::new(self),
        }
    }
}

/// Checks that a point is finite.
pub(crate) fn check_point(p: &nalgebra::Point3<f64>) -> Result<(), SpatialError> {
    if p.coords.iter().all(|c| c.is_finite()) {
        Ok(())
    } else {
        Err(SpatialError::NonFinitePoint {
            x: p.x,
            y: p.y,
            z: p.z,
        })
    }
}

/// Checks that a displacement is finite.
pub(crate) fn check_displacement(d: &nalgebra::Vector3<f64>) -> Result<(), SpatialError> {
    if d.iter().all(|c| c.is_finite()) {
        Ok(())
    } else {
        Err(SpatialError::NonFiniteDisplacement {
            x: d.x,
            y: d.y,
            z: d.z,
        })
    }
}
