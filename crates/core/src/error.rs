//! Errors of solvers.

use beltrami_fem::{BoundaryError, DofError, FemError, FieldError, WeightError};
use beltrami_mesh::MeshError;
use beltrami_sparse::SolveError;
use thiserror::Error;

use crate::{ConstraintError, OptionError};

/// Why a solve could not be done.
#[derive(Debug, Error)]
pub enum SolverError {
    /// The solver cannot take this problem; the message says why and what to do instead
    /// (e.g. "lscm maps disk-topology meshes; this mesh has genus 1 and no boundary: run
    /// `beltrami cut` first or use beltrami-flow").
    #[error("{solver}: {message}")]
    Unsupported {
        /// The solver's name.
        solver: &'static str,
        /// Why, in plain words, with the way out.
        message: String,
    },
    /// An input of the problem is invalid (a pin on a missing vertex, a field of the
    /// wrong length, ...); the message names the element.
    #[error("{solver}: {message}")]
    InvalidInput {
        /// The solver's name.
        solver: &'static str,
        /// What is wrong, naming the element.
        message: String,
    },
    /// No solver of that name is registered.
    #[error("no solver named `{name}`; available: {available}")]
    UnknownSolver {
        /// The name asked for.
        name: String,
        /// The registered names, comma-separated.
        available: String,
    },
    /// A boundary map cannot be built from the problem (a non-convex polygon, a pin off
    /// the boundary, corners out of order, ...).
    #[error("{solver}: {error}")]
    Boundary {
        /// The solver's name.
        solver: &'static str,
        /// What is wrong, naming the vertex or corner.
        #[source]
        error: BoundaryError,
    },
    /// Edge weights cannot be computed (a non-finite weight, naming the edge).
    #[error("{solver}: {error}")]
    Weights {
        /// The solver's name.
        solver: &'static str,
        /// What is wrong.
        #[source]
        error: WeightError,
    },
    /// An option value was refused (unknown name, wrong type, out of range).
    #[error(transparent)]
    Option(#[from] OptionError),
    /// A constraint is malformed (a missing vertex, a non-finite point, ...).
    #[error("{solver}: {error}")]
    Constraint {
        /// The solver's name.
        solver: &'static str,
        /// What is wrong, naming the constraint and the element.
        #[source]
        error: ConstraintError,
    },
    /// An error of a plugin's own crate or of a crate core does not know (point
    /// location, registration's initial map), kept typed as the source: callers can
    /// `downcast_ref` it.
    #[error("{solver}: {error}")]
    Plugin {
        /// The solver's name.
        solver: &'static str,
        /// The error.
        #[source]
        error: Box<dyn std::error::Error + Send + Sync>,
    },
    /// The solve was cancelled.
    #[error("cancelled")]
    Cancelled,
    /// A mesh operation failed.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// An element computation failed.
    #[error(transparent)]
    Fem(#[from] FemError),
    /// A Beltrami field is invalid.
    #[error(transparent)]
    Field(#[from] FieldError),
    /// The constraints could not be turned into a DOF map.
    #[error(transparent)]
    Dof(#[from] DofError),
    /// A linear solve failed.
    #[error(transparent)]
    Solve(#[from] SolveError),
}

impl SolverError {
    /// [`SolverError::Unsupported`]: `solver` cannot take this problem; `message` says
    /// why, in plain words, with the way out.
    pub fn unsupported(solver: &'static str, message: impl Into<String>) -> Self {
        SolverError::Unsupported {
            solver,
            message: message.into(),
        }
    }

    /// [`SolverError::InvalidInput`]: an input of `solver`'s problem is invalid;
    /// `message` says what is wrong, naming the element.
    pub fn invalid(solver: &'static str, message: impl Into<String>) -> Self {
        SolverError::InvalidInput {
            solver,
            message: message.into(),
        }
    }

    /// [`SolverError::Plugin`]: `error` of a plugin's own crate or of a crate core does
    /// not know, met by `solver`, kept typed as the source.
    pub fn plugin(
        solver: &'static str,
        error: impl std::error::Error + Send + Sync + 'static,
    ) -> Self {
        SolverError::Plugin {
            solver,
            error: Box::new(error),
        }
    }
}

impl From<beltrami_fem::quaternionic_lsqc::SpaceError> for SolverError {
    fn from(e: beltrami_fem::quaternionic_lsqc::SpaceError) -> Self {
        use beltrami_fem::quaternionic_lsqc::SpaceError;
        match e {
            SpaceError::Fem(e) => e.into(),
            SpaceError::Dof(e) => e.into(),
            SpaceError::Solve(e) => e.into(),
        }
    }
}
